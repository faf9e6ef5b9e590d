"""Real tori, frequencies and frequency maps (manakov.tori); docs/tori.md."""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from _tori_work import mix, pid, slow_mix

import manakov
from manakov import tori

# The characteristics of P_0, P_23, P_31, P_12, P_14, P_24, P_34 on the 'simple'
# curve (docs/theta_quotients.md, found there with an independent Abel map).
SIMPLE = np.array(
    [
        [1, 0, 0, 0],
        [0, 0, 0, 1],
        [1, 1, 0, 1],
        [1, 1, 0, 0],
        [1, 0, 0, 1],
        [0, 1, 0, 1],
        [0, 1, 0, 0],
    ]
)


def _quotient_sign(chi, x):
    a1, a2, b1, b2 = chi
    m1, m2, n1, n2 = x
    return (-1) ** ((a1 * m1 + a2 * m2 + b1 * n1 + b2 * n2) % 2)


# --- the real torus, on constructed lattices -------------------------------


def test_real_torus_of_a_diagonal_period_matrix():
    # τ = i diag(1.3, 0.8), real U, U': the plane is R², Λ ∩ R² = Z², and the
    # table's a-parts (10, 00, 11, 11, 10, 01, 01) leave Λ' ∩ R² = 2 Z².
    t = manakov.real_torus([[1.3j, 0], [0, 0.8j]], [0.37, 0.52], [-0.2, 0.9], SIMPLE)
    assert t.coords.tolist() == [[2, 0, 0, 0], [0, 2, 0, 0]]
    np.testing.assert_allclose(t.frequencies, [0.185, 0.26], rtol=1e-15)
    assert t.rotation_number == pytest.approx(0.185 / 0.26, rel=1e-15)
    np.testing.assert_allclose(t.angles([0.0, 10.0]), [[0, 0], [0.85, 0.6]], atol=1e-13)
    assert not t.lambdas.flags.writeable


def test_real_torus_on_random_planes_through_lattice_points():
    # An independent numpy check: the basis is in Λ' (sign rule), lies in the
    # plane, is Gauss-reduced in the metric (Im τ)^-1, orients ν ≥ 0, and the
    # two lattice points that spanned the plane are integer combinations of it.
    rng = np.random.default_rng(5)
    for _ in range(20):
        b = rng.normal(size=(2, 2))
        tau = rng.uniform(-0.5, 0.5, (2, 2)) + 1j * (b @ b.T + 0.3 * np.eye(2))
        tau = (tau + tau.T) / 2
        xs = []
        for _ in range(2):
            x = rng.integers(-2, 3, 4)
            if any(_quotient_sign(c, x) < 0 for c in SIMPLE):
                x = 2 * x
            xs.append(x)
        lam = [x[:2] + tau @ x[2:] for x in xs]
        if abs(np.linalg.det(np.array([np.r_[v.real, v.imag] for v in lam])[:, :2])) < 1e-3:
            continue
        U = 0.3 * lam[0] - 0.7 * lam[1]
        U2 = 1.1 * lam[0] + 0.2 * lam[1]
        t = manakov.real_torus(tau, U, U2, SIMPLE)
        H = np.linalg.inv(tau.imag)

        def dot(z, w, H=H):
            return float(np.real(np.conj(z) @ H @ w))

        for x, v in zip(t.coords, t.lambdas):
            assert all(_quotient_sign(c, x) == 1 for c in SIMPLE)
            np.testing.assert_allclose(v, x[:2] + tau @ x[2:], atol=1e-14)
        l1, l2 = t.lambdas
        assert dot(l1, l1) <= dot(l2, l2) * (1 + 1e-12)
        assert abs(dot(l1, l2)) <= 0.5 * dot(l1, l1) * (1 + 1e-12)
        assert np.all(t.frequencies >= 0)
        np.testing.assert_allclose(t.frequencies @ t.lambdas, U, atol=1e-13)
        c = np.array(t.coords, dtype=float).T
        for x in xs:
            k = np.linalg.lstsq(c, x, rcond=None)[0]
            np.testing.assert_allclose(k, np.round(k), atol=1e-9)
            np.testing.assert_allclose(c @ np.round(k), x, atol=1e-9)


def test_real_torus_rejects_bad_input():
    tau = [[1.3j, 0], [0, 0.8j]]
    with pytest.raises(ValueError, match="real plane"):
        manakov.real_torus(tau, [0.37, 0.52], [0.74, 1.04], SIMPLE)
    with pytest.raises(ValueError, match="rank-2"):
        manakov.real_torus(tau, [0.3 + 0.14j, 0.5 - 0.7j], [-0.2 + 0.39j, 0.9 + 0.11j], SIMPLE)
    with pytest.raises(ValueError, match="characteristics"):
        manakov.real_torus(tau, [1, 0], [0, 1], [[2, 0, 0, 0]])
    with pytest.raises(ValueError, match="tau"):
        manakov.real_torus([[1j, 0]], [1, 0], [0, 1], SIMPLE)
    with pytest.raises(ValueError, match="not finite"):
        manakov.real_torus(tau, [np.nan, 0], [0, 1], SIMPLE)


def test_status_names_match_the_constants():
    assert tori.STATUS_NAMES[tori.OK] == "ok"
    assert tori.STATUS_NAMES[tori.SINGULAR_CASIMIRS] == "h1^2 = 4 h0^2"
    assert tori.STATUS_NAMES[tori.COINCIDING_BRANCH_POINTS] == "coinciding branch points"
    assert tori.STATUS_NAMES[tori.DIVISOR_AT_INFINITY] == "divisor at infinity"
    assert tori.STATUS_NAMES[tori.NO_CONVERGENCE] == "no convergence"
    assert tori.STATUS_NAMES[tori.ZERO_STATE] == "zero state"
    assert tori.STATUS_NAMES[tori.NON_FINITE] == "non-finite state"
    assert tori.STATUS_NAMES[tori.DEGENERATE_PLANE] == "degenerate plane"
    assert tori.STATUS_NAMES[tori.NO_REAL_LATTICE] == "no real lattice"
    assert tori.STATUS_NAMES[tori.SINGULAR] == "singular"
    assert tori.STATUS_NAMES[tori.DEGENERATE_GRADIENTS] == "degenerate gradients"
    assert tori.STATUS_NAMES[tori.INCONSISTENT_QUOTIENTS] == "inconsistent quotients"
    assert tori.STATUS_NAMES[tori.EQUILIBRIUM] == "equilibrium"
    assert tori.STATUS_NAMES[tori.SEPARATRIX] == "separatrix"
    # The states an interrupted map did not reach: one past the core's codes.
    assert tori.STATUS_NAMES[tori.NOT_COMPUTED] == "not computed"
    assert tori.NOT_COMPUTED == 14
    assert len(tori.STATUS_NAMES) == 15


def test_casimir_slice_keeps_h0_and_h1():
    p = manakov.problem("generic")
    _, _, states = tori.casimir_slice(p.l0, 7)
    top = manakov.ManakovTop(p.a, p.b)
    h = top.integrals(states)
    h_ref = top.integrals(p.l0)
    # Sums of a few O(1) products: roundoff.
    np.testing.assert_allclose(h["H0"], h_ref["H0"], rtol=1e-13)
    np.testing.assert_allclose(h["H1"], h_ref["H1"], rtol=1e-13)
    assert np.ptp(h["H"]) > 0.1  # the slice crosses many tori


# --- the chunk engine, with a test-side function ---------------------------


def _local(states, chunk):
    parts = tori._run_chunks(
        mix, (1.7,), states, client=None, chunk_size=chunk, progress=False, label="t"
    )
    return np.concatenate(parts)


def test_chunks_do_not_change_results():
    states = np.random.default_rng(1).normal(size=(1001, 6))
    ref = mix(1.7, states)
    for chunk in (1, 7, 1000, 5000):
        assert np.array_equal(_local(states, chunk), ref)


def test_progress_bar_draws_when_forced(capsys):
    states = np.random.default_rng(1).normal(size=(100, 6))
    tori._run_chunks(mix, (1.0,), states, client=None, chunk_size=10, progress=True, label="map")
    err = capsys.readouterr().err
    assert "map [" in err and "100.0%" in err


def test_no_client_does_not_import_dask():
    code = (
        "import sys, numpy as np, manakov\n"
        "from manakov import tori\n"
        "p = manakov.problem('generic')\n"
        "top = manakov.ManakovTop(p.a, p.b)\n"
        "fm = manakov.frequency_map(top, np.tile(p.l0, (3, 1)))\n"
        "assert (fm.status == 0).all()\n"
        "tori._run_chunks(lambda s, x: x, (0,), np.zeros((5, 6)), client=None,"
        " chunk_size=2, progress=False, label='x')\n"
        "print('dask' in sys.modules, 'distributed' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_dask_chunks_equal_the_local_run_bit_for_bit(client):
    states = np.random.default_rng(2).normal(size=(10_000, 6))
    local = _local(states, 10_000)
    parts = tori._run_chunks(
        mix, (1.7,), states, client=client, chunk_size=997, progress=False, label="t"
    )
    assert np.array_equal(np.concatenate(parts), local)
    # Both workers took part.
    pids = tori._run_chunks(
        pid, (0,), states, client=client, chunk_size=500, progress=False, label="p"
    )
    assert len(set(pids)) == 2


def test_a_killed_worker_is_retried_and_the_result_is_complete(client):
    states = np.random.default_rng(3).normal(size=(2000, 6))
    local = _local(states, 2000)
    victim = sorted(client.run(os.getpid).values())[0]
    killed = {}

    def kill():
        killed["t"] = time.perf_counter()
        os.kill(victim, signal.SIGKILL)

    timer = threading.Timer(0.4, kill)
    start = time.perf_counter()
    timer.start()
    # 40 chunks of 0.05 s on two workers: ~1 s, so the kill lands mid-map.
    parts = tori._run_chunks(
        slow_mix, (1.7,), states, client=client, chunk_size=50, progress=False, label="k"
    )
    end = time.perf_counter()
    timer.join()
    assert start < killed["t"] < end
    assert np.array_equal(np.concatenate(parts), local)
    client.wait_for_workers(2, timeout=60)
    assert victim not in client.run(os.getpid).values()


def test_an_interrupted_dask_map_keeps_its_chunks_and_cancels_the_rest(client):
    # Ctrl-C (here: the progress callable) during a map on a cluster: the chunks
    # finished so far ride on the exception, and the queued tasks are cancelled.
    states = np.random.default_rng(4).normal(size=(2000, 6))
    local = _local(states, 2000)

    def stop(fraction):
        if fraction >= 0.2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as e:
        tori._run_chunks(
            slow_mix, (1.7,), states, client=client, chunk_size=50, progress=stop, label="i"
        )
    done = e.value.chunks_done
    assert len(done) == 40 and 8 <= sum(c is not None for c in done) < 40
    for k, chunk in enumerate(done):
        if chunk is not None:
            assert np.array_equal(chunk, local[50 * k : 50 * (k + 1)])
    deadline = time.perf_counter() + 10
    while client.processing() and any(client.processing().values()):
        assert time.perf_counter() < deadline, client.processing()
        time.sleep(0.05)
