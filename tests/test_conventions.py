# The state is called l, as in the paper: E741 does not apply.
# ruff: noqa: E741
"""The one API convention (docs/conventions.md), checked across neighbouring calls.

Result objects with shared attribute names, broadcasting over leading axes (or one
wording where a call takes one state), ``progress`` as True/False/None/a callable,
``client`` checked, ``t_end = 0``, ``err.partial`` on an interruption, and numbers in
messages with the digits that matter. Each test names the trip-up it pins down.
"""

from __future__ import annotations

import io
import math
import re
import sys

import numpy as np
import pytest

import manakov
from manakov import tori


@pytest.fixture
def generic():
    p = manakov.problem("generic")
    return manakov.ManakovTop(p.a, p.b), p.l0


def _states(l0, shape, seed=0):
    """States near ``l0`` (so on regular level sets), of leading shape ``shape``."""
    rng = np.random.default_rng(seed)
    return l0 + 0.05 * rng.normal(size=shape + (6,))


# --- result objects -----------------------------------------------------------


def test_integrate_many_returns_a_trajectory_with_the_names_of_integrate(generic):
    # integrate returned a Trajectory, integrate_many a bare (t, l) tuple.
    top, l0 = generic
    l0s = _states(l0, (2, 3))
    many = top.integrate_many(l0s, 2.0, sample_every=0.5)
    one = top.integrate(l0s[1, 2], 2.0, sample_every=0.5)
    assert isinstance(many, manakov.Trajectory) and isinstance(one, manakov.Trajectory)
    np.testing.assert_array_equal(many.t, one.t)
    assert many.l.shape == (2, 3, 5, 6) and one.l.shape == (5, 6)
    np.testing.assert_array_equal(many.l[1, 2], one.l)
    assert set(many.integrals) == set(one.integrals)
    for k, v in many.integrals.items():
        assert v.shape == (2, 3, 5)
        np.testing.assert_array_equal(v[1, 2], one.integrals[k])
    assert many.ok.shape == (2, 3) and many.ok.all() and one.ok is True
    assert many.method == one.method and many.steps > one.steps and many.evals is None
    drift = many.max_drift()
    assert all(v.shape == (2, 3) for v in drift.values())
    # The old tuple still unpacks (documented).
    t, l = many
    assert t is many.t and l is many.l


def test_frequency_map_and_kotter_share_ok_and_the_torus_names(generic):
    top, l0 = generic
    states = _states(l0, (2, 2))
    states[1, 1] = 0.0  # the rest state: a status, not an exception
    fm = manakov.frequency_map(top, states)
    assert fm.ok.shape == (2, 2) and fm.ok.tolist() == [[True, True], [True, False]]
    np.testing.assert_array_equal(fm.frequencies, fm.nu)
    sol = top.solve(states[0, 1])
    # The same names as Torus/Solution: frequencies, rotation_number.
    np.testing.assert_allclose(fm.frequencies[0, 1], sol.frequencies, rtol=1e-9)
    assert fm.rotation_number[0, 1] == pytest.approx(sol.rotation_number, rel=1e-9)
    assert np.isnan(fm.rotation_number[1, 1])
    k = manakov.kotter(top.a, top.b, states, errors="mask")
    np.testing.assert_array_equal(k.ok, fm.ok)
    nu, status = fm  # still unpacks
    assert nu.shape == (2, 2, 2) and status.shape == (2, 2)


# --- broadcasting, and one wording where a call takes one state -----------------


def test_integrate_broadcasts_over_leading_axes_bit_for_bit(generic):
    # integrate(np.ones((2, 6)), 10.) raised "l0 must have shape (6,)".
    top, l0 = generic
    l0s = _states(l0, (2, 2), seed=1)
    for method in ("gauss16", "dop853"):
        batch = top.integrate(l0s, 3.0, sample_every=1.0, method=method)
        assert batch.l.shape == (2, 2, 4, 6)
        for idx in np.ndindex(2, 2):
            np.testing.assert_array_equal(
                batch.l[idx], top.integrate(l0s[idx], 3.0, sample_every=1.0, method=method).l
            )


def test_shape_messages_use_one_wording(generic):
    # "l0 must have shape (6,)" against "l0 must have shape (..., 6)" for neighbouring calls.
    top, l0 = generic
    broadcast = "must have shape (..., 6) (states on the last axis), got shape (5,)"
    for call in (
        lambda x: top.integrate(x, 1.0),
        lambda x: top.integrate_many(x, 1.0),
        top.vector_field,
        top.integrals,
        lambda x: manakov.kotter(top.a, top.b, x),
        lambda x: manakov.frequency_map(top, x),
        top.default_dt,
    ):
        with pytest.raises(ValueError) as e:
            call(np.ones(5))
        assert broadcast in str(e.value)
    for call, name in (
        (top.solve, "solve"),
        (top.level_set, "LevelSet"),
        (lambda x: tori.casimir_slice(x, 4), "casimir_slice"),
    ):
        with pytest.raises(ValueError) as e:
            call(np.stack([l0, l0]))
        text = str(e.value)
        assert "l0 must be one state of shape (6,), got shape (2, 6)" in text
        assert f"{name} takes one state and does not broadcast over leading axes" in text


def test_time_scale_and_default_step_broadcast(generic):
    top, l0 = generic
    l0s = _states(l0, (3,))
    dts = top.default_dt(l0s)
    assert dts.shape == (3,)
    assert [top.default_dt(x) for x in l0s] == dts.tolist()
    assert isinstance(top.default_dt(l0), float) and isinstance(top.time_scale(l0), float)


def test_solution_abel_broadcasts(generic):
    top, l0 = generic
    sol = top.solve(l0)
    ls = top.integrate(l0, 1.0, sample_every=0.5).l
    u = sol.abel(ls)
    assert u.shape == (3, 2)
    np.testing.assert_array_equal(u[1], sol.abel(ls[1]))


# --- progress -------------------------------------------------------------------


def test_progress_true_draws_a_bar_instead_of_a_type_error(generic, capsys):
    # top.integrate(l0, 10.0, progress=True) raised "'bool' object is not callable".
    top, l0 = generic
    top.integrate(l0, 10.0, progress=True)
    assert "100.0%" in capsys.readouterr().err
    top.integrate(l0, 10.0, progress=False)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("method", ["gauss16", "dop853", "taylor"])
def test_progress_callable_sees_the_run_and_changes_no_bit(generic, method):
    top, l0 = generic
    seen: list[float] = []
    # ~0.1-0.5 s of work: the core's poll reports every 20 ms, without splitting the run.
    watched = top.integrate(l0, 5e4, sample_every=1.0, method=method, progress=seen.append)
    plain = top.integrate(l0, 5e4, sample_every=1.0, method=method)
    np.testing.assert_array_equal(watched.l, plain.l)
    assert seen[-1] == 1.0 and seen == sorted(seen) and len(set(seen)) == len(seen)
    assert len(seen) >= 3 and 0 < seen[1] < 1


def test_progress_of_a_batch_and_of_a_frequency_map(generic):
    top, l0 = generic
    seen: list[float] = []
    top.integrate_many(_states(l0, (5,)), 10.0, chunk_size=2, progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0 and len(seen) >= 3
    seen.clear()
    # frequency_map(progress=callable) once drew a bar and never called it.
    manakov.frequency_map(top, _states(l0, (30,)), chunk_size=10, progress=seen.append)
    assert seen == [1 / 3, 2 / 3, 1.0]


@pytest.mark.parametrize("bad", ["yes", 1, 0.5])
def test_progress_other_than_bool_or_callable_is_a_value_error(generic, bad):
    top, l0 = generic
    for call in (
        lambda: top.integrate(l0, 1.0, progress=bad),
        lambda: top.integrate_many(l0[None], 1.0, progress=bad),
        lambda: manakov.frequency_map(top, l0, progress=bad),
    ):
        with pytest.raises(ValueError, match="progress must be True, False, None or a callable"):
            call()


def test_a_progress_bar_is_drawn_only_on_a_terminal_unless_forced():
    from manakov._progress import Progress

    class Tty(io.StringIO):
        def isatty(self):
            return True

    old = sys.stderr
    try:
        sys.stderr = Tty()
        with Progress(None, "x", long=True) as p:
            p(0.5)
        assert "50.0%" in sys.stderr.getvalue()
        sys.stderr = io.StringIO()
        with Progress(None, "x", long=True) as p:
            p(0.5)
        assert sys.stderr.getvalue() == ""
    finally:
        sys.stderr = old


# --- client, t_end = 0 ------------------------------------------------------------


@pytest.mark.parametrize("client", ["notaclient", 3, object()])
def test_client_is_checked_with_a_value_error_naming_it(generic, client):
    # frequency_map(top, s, client="notaclient") raised AttributeError: ... 'submit'.
    top, l0 = generic
    with pytest.raises(ValueError, match="client must be a dask.distributed.Client") as e:
        manakov.frequency_map(top, l0[None], client=client)
    assert repr(client) in str(e.value)


def test_t_end_zero_is_the_initial_state_once(generic):
    # top.integrate(l0, 0.0) returned 1001 identical samples.
    top, l0 = generic
    for method in ("gauss16", "dop853", "taylor"):
        tr = top.integrate(l0, 0.0, method=method)
        np.testing.assert_array_equal(tr.t, [0.0])
        np.testing.assert_array_equal(tr.l, [l0])
        assert tr.steps == 0
    batch = top.integrate_many(_states(l0, (2,)), 0.0)
    assert batch.l.shape == (2, 1, 6)
    assert top.integrate(l0, 0.0, sample_every=0.5).t.tolist() == [0.0]


# --- Ctrl-C keeps the work ------------------------------------------------------


def _interrupt_after(fraction):
    def progress(f):
        if f >= fraction:
            raise KeyboardInterrupt

    return progress


def test_an_interrupted_batch_keeps_its_finished_trajectories(generic):
    # Only integrate attached .partial to the interruption.
    top, l0 = generic
    l0s = _states(l0, (3, 2))
    full = top.integrate_many(l0s, 20.0, sample_every=1.0)
    with pytest.raises(KeyboardInterrupt) as e:
        top.integrate_many(
            l0s, 20.0, sample_every=1.0, chunk_size=2, progress=_interrupt_after(0.5)
        )
    part = e.value.partial
    assert isinstance(part, manakov.Trajectory) and part.l.shape == (3, 2, 21, 6)
    # Whole calls of two states each are kept: the first one or two (the progress
    # callable runs between calls and from the core's poll within one).
    done = part.ok.reshape(-1)
    k = int(done.sum())
    assert k in (2, 4) and done[:k].all()
    flat, ref = part.l.reshape(6, 21, 6), full.l.reshape(6, 21, 6)
    np.testing.assert_array_equal(flat[:k], ref[:k])
    assert np.isnan(flat[k:]).all() and np.isnan(part.integrals["H"].reshape(6, 21)[k:]).all()
    np.testing.assert_array_equal(
        part.integrals["H"].reshape(6, 21)[:k], full.integrals["H"].reshape(6, 21)[:k]
    )


def test_an_interrupted_single_run_keeps_its_samples(generic):
    top, l0 = generic
    full = top.integrate(l0, 5e4, sample_every=1.0)
    with pytest.raises(KeyboardInterrupt) as e:
        top.integrate(l0, 5e4, sample_every=1.0, progress=_interrupt_after(0.2))
    part = e.value.partial
    assert part.ok is False and 0 < part.t.size < full.t.size
    np.testing.assert_array_equal(part.l, full.l[: part.t.size])


def test_an_interrupted_frequency_map_keeps_its_finished_chunks(generic):
    top, l0 = generic
    states = _states(l0, (4, 5))
    full = manakov.frequency_map(top, states)
    with pytest.raises(KeyboardInterrupt) as e:
        manakov.frequency_map(top, states, chunk_size=8, progress=_interrupt_after(0.4))
    part = e.value.partial
    assert isinstance(part, manakov.FrequencyMap) and part.status.shape == (4, 5)
    flat_status, flat_nu = part.status.reshape(-1), part.nu.reshape(-1, 2)
    np.testing.assert_array_equal(flat_nu[:8], full.nu.reshape(-1, 2)[:8])
    assert (flat_status[8:] == tori.NOT_COMPUTED).all() and np.isnan(flat_nu[8:]).all()
    assert part.counts() == {"ok": 8, "not computed": 12}


def test_an_exception_of_the_progress_callable_stops_the_run_and_keeps_the_work(generic):
    top, l0 = generic

    class Enough(Exception):
        pass

    def stop(f):
        if f > 0.3:
            raise Enough

    with pytest.raises(Enough) as e:
        top.integrate(l0, 5e4, sample_every=1.0, progress=stop)
    assert 0 < e.value.partial.t.size < 50001


# --- numbers in messages ----------------------------------------------------------

#: A run of this many zeros after a decimal point is printed rounding noise.
NOISE_DIGITS = re.compile(r"\.0{8,}")


def test_the_rest_state_is_refused_without_a_nan_distance(generic):
    # "relative distance (h1^2 - 4 h0^2)/h1^2 = NaN <= 1e-12".
    top, _ = generic
    with pytest.raises(ValueError) as e:
        manakov.kotter(top.a, top.b, np.zeros(6))
    text = str(e.value)
    assert "nan" not in text.lower() and "l = 0" in text and "rest state" in text


def test_a_repeated_root_prints_with_ten_digits_and_no_noise(generic):
    # "repeated root s = 1.4070413458937996-0.000...0006256420825295136i".
    top, _ = generic
    with pytest.raises(ValueError) as e:
        manakov.kotter(top.a, top.b, [1.0, 0, 0, 0, 0, 0.5])
    text = str(e.value)
    m = re.search(r"repeated root s = (\S+) \(\|s_\d - s_\d\| = (\S+)\)", text)
    assert m, text
    root, sep = m.group(1), float(m.group(2))
    # A double root is known to about its computed separation: the digits below it
    # (and an imaginary part below it) are noise and are not printed.
    assert not NOISE_DIGITS.search(text) and "i" not in root and "j" not in root
    last_digit = 10.0 ** (
        math.floor(math.log10(abs(float(root)))) - len(re.sub(r"\D", "", root)) + 1
    )
    assert sep / 10 <= last_digit <= sep * 10, (root, sep)
