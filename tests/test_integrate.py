"""Integration: Gauss coefficients, conservation, accuracy, sampling, batches, errors."""

# ruff: noqa: E741
from __future__ import annotations

import json
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import manakov
from manakov import _core

DATA = Path(__file__).resolve().parent / "data"
STAGES = {"gauss4": 2, "gauss6": 3, "gauss16": 8}
# Must-show: relative drift of every integral on 'generic' to t = 1e4 with the default.
DRIFT_CLAIM = 1e-13
# Our default's error at t = 100 against the 38-digit reference: measured ~1e-13
# (roundoff-limited); 1e-12 leaves a factor ~10.
T100_ERROR_BOUND = 1e-12
# Observed order log2(err(h)/err(h/2)) within this of the theoretical order
# (asymptotic regime, error constants still change slightly between h and h/2).
ORDER_SLACK = 0.5
# gauss16 with dt = 0.1 to t = 10 (100 steps): roundoff only, ~sqrt(100) eps on O(1) values.
GAUSS16_ROUNDOFF = 1e-14
# dopri5 controls the error per step; over t = 10 the global error is a modest multiple of tol.
DOPRI5_GLOBAL_FACTOR = 100
# An explicit method's drift of the quadratic integrals at rtol = 1e-8 over t = 100: well
# above roundoff (~1e-15), measured 7e-7; 1e-10 shows it is not conserved.
DOPRI5_MIN_DRIFT = 1e-10
# Our DOP853 and scipy's differ in controller details (e.g. the first step).
DOP853_STEP_COUNT_RTOL = 0.15
DOP853_ERROR_BOUND = 1e-8  # both at rtol = atol = 1e-10 over t = 10
DOP853_ERROR_RATIO = 10  # errors within a factor 10 of each other
# Two runs of the same Gauss method and step to the same time that differ only in
# sampling / chunking: only the Kahan carry is restarted, so they agree to roundoff.
SAMPLING_ROUNDOFF = 1e-14
CHUNKING_ROUNDOFF = 1e-13


def mp_gauss(s, dps=50):
    """Independent Gauss-Legendre data by Golub-Welsch: the nodes on [-1, 1] are the
    eigenvalues of the Legendre Jacobi matrix (off-diagonal k / sqrt(4k^2 - 1)), the
    weights 2 v_0^2 from its normalised eigenvectors; mapped to [0, 1]."""
    with mp.workdps(dps):
        jac = mp.matrix(s, s)
        for k in range(1, s):
            jac[k - 1, k] = jac[k, k - 1] = k / mp.sqrt(4 * k * k - 1)
        evals, evecs = mp.eigsy(jac)
        order = sorted(range(s), key=lambda i: evals[i])
        c = [(1 + evals[i]) / 2 for i in order]
        b = [evecs[0, i] ** 2 for i in order]  # 2 v0^2 on [-1, 1], halved on [0, 1]
        # a_ij = integral_0^{c_i} ell_j(t) dt, by mpmath quadrature of the Lagrange basis.
        a = []
        for ci in c:
            row = []
            for j in range(s):

                def ell(t, j=j):
                    return mp.fprod((t - c[k]) / (c[j] - c[k]) for k in range(s) if k != j)

                row.append(mp.quad(ell, [0, ci]))
            a.append(row)
        return c, b, a


@pytest.mark.parametrize("method", list(STAGES))
def test_gauss_coefficients_are_correct_to_the_last_bit(method):
    s = STAGES[method]
    c, b, mu = _core.gauss_tableau(method)
    cm, bm, am = mp_gauss(s)
    with mp.workdps(50):
        for i in range(s):
            assert c[i] == float(cm[i]), ("c", i)
            assert b[i] == float(bm[i]), ("b", i)
        for i in range(s):
            for j in range(s):
                # Symplecticity mu_ij + mu_ji = 1 held exactly ...
                assert mu[i, j] + mu[j, i] == 1.0
                exact = am[i][j] / bm[j]
                if exact >= 0.5:
                    # ... the entry >= 1/2 of each pair is the nearest double ...
                    assert mu[i, j] == float(exact), (i, j)
                else:
                    # ... and its partner 1 - (that double) is within one of its ulps.
                    assert abs(mu[i, j] - exact) <= np.spacing(mu[j, i])


def test_gauss_tables_generator_is_reproducible(tmp_path):
    """The committed Rust table is what the committed generator writes."""
    import runpy

    # The tests run from a checkout (.ci/test runs pytest at its root), so the Rust source
    # is always beside them; a missing file is a failure, not a skip.
    src = Path(__file__).resolve().parents[1] / "rust" / "integrate" / "gauss_tables.rs"
    assert src.is_file(), f"{src} missing: tests must run from a source checkout"
    gen = runpy.run_path(str(DATA / "gen_gauss_tables.py"))
    out = tmp_path / "gauss_tables.rs"
    gen["main"](out)
    assert out.read_text() == src.read_text()


def _reference():
    ref = json.loads((DATA / "reference_generic.json").read_text())
    return {float(t): np.array([float(x) for x in v]) for t, v in ref["states"].items()}


def test_default_drift_on_generic_to_1e4_is_below_1e_13():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 1e4, sample_every=1.0)
    assert tr.method == "gauss16"
    drift = tr.max_drift()
    assert set(drift) == {"H0", "H1", "H2", "H3", "H"}
    assert max(drift.values()) <= DRIFT_CLAIM, drift


def test_default_error_at_t100_beats_scipy_dop853():
    """Against the 38-digit mpmath reference: our default vs scipy DOP853 at rtol = atol = 1e-12."""
    ref = _reference()
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 100.0, t_eval=[10.0, 100.0])
    err = np.max(np.abs(tr.l[-1] - ref[100.0]))
    c = top.c
    iu = np.triu_indices(4, 1)

    def rhs(t, y):
        L = np.zeros((4, 4))
        L[iu] = y
        L = L - L.T
        W = c * L
        return (L @ W - W @ L)[iu]

    sol = solve_ivp(rhs, (0, 100), p.l0, method="DOP853", rtol=1e-12, atol=1e-12)
    err_scipy = np.max(np.abs(sol.y[:, -1] - ref[100.0]))
    assert err <= err_scipy
    assert err < T100_ERROR_BOUND


@pytest.mark.parametrize("method,order,dt", [("gauss4", 4, 0.1), ("gauss6", 6, 0.2)])
def test_observed_order(method, order, dt):
    ref = _reference()[10.0]
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    errs = []
    for h in (dt, dt / 2):
        tr = top.integrate(p.l0, 10.0, t_eval=[10.0], dt=h, method=method)
        errs.append(np.max(np.abs(tr.l[-1] - ref)))
    observed = np.log2(errs[0] / errs[1])
    assert abs(observed - order) < ORDER_SLACK, observed


def test_gauss16_reaches_roundoff_against_mpmath():
    ref = _reference()[10.0]
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 10.0, t_eval=[10.0], dt=0.1)
    assert np.max(np.abs(tr.l[-1] - ref)) < GAUSS16_ROUNDOFF


def test_dopri5_agrees_with_reference_at_its_tolerance():
    ref = _reference()[10.0]
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    for tol in (1e-8, 1e-11):
        tr = top.integrate(p.l0, 10.0, t_eval=[10.0], method="dopri5", rtol=tol, atol=tol)
        assert np.max(np.abs(tr.l[-1] - ref)) < DOPRI5_GLOBAL_FACTOR * tol
    # An explicit method does not conserve the quadratic integrals: they drift.
    tr = top.integrate(p.l0, 100.0, method="dopri5", rtol=1e-8, atol=1e-8)
    assert max(tr.max_drift().values()) > DOPRI5_MIN_DRIFT


def test_dop853_matches_scipy_dop853():
    """Same tableau and control as scipy's DOP853: similar step counts and errors at 1e-10."""
    ref = _reference()[10.0]
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 10.0, t_eval=[10.0], method="dop853", rtol=1e-10, atol=1e-10)
    sol = solve_ivp(
        lambda t, y: top.vector_field(y), (0, 10.0), p.l0, method="DOP853", rtol=1e-10, atol=1e-10
    )
    scipy_steps = sol.nfev // 12
    assert abs(tr.steps - scipy_steps) <= DOP853_STEP_COUNT_RTOL * scipy_steps, (
        tr.steps,
        scipy_steps,
    )
    err = np.max(np.abs(tr.l[-1] - ref))
    err_scipy = np.max(np.abs(sol.y[:, -1] - ref))
    assert err < DOP853_ERROR_BOUND and err_scipy < DOP853_ERROR_BOUND
    assert 1 / DOP853_ERROR_RATIO < err / err_scipy < DOP853_ERROR_RATIO


def test_sampling_lands_on_the_requested_times():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    te = np.array([0.0, 0.3, 0.3, 1.7, 2.0])
    tr = top.integrate(p.l0, 2.0, t_eval=te)
    np.testing.assert_array_equal(tr.t, te)
    assert tr.l.shape == (5, 6)
    np.testing.assert_array_equal(tr.l[0], p.l0)
    np.testing.assert_array_equal(tr.l[1], tr.l[2])
    tr = top.integrate(p.l0, 2.5, sample_every=1.0)
    np.testing.assert_array_equal(tr.t, [0.0, 1.0, 2.0, 2.5])
    tr = top.integrate(p.l0, 3.0)
    assert tr.t.shape == (1001,) and tr.t[-1] == 3.0
    # Sampling does not change the trajectory beyond roundoff (grid differs).
    a = top.integrate(p.l0, 2.0, t_eval=[2.0], dt=0.05)
    b = top.integrate(p.l0, 2.0, sample_every=0.1, dt=0.05)
    assert np.max(np.abs(a.l[-1] - b.l[-1])) < SAMPLING_ROUNDOFF


def test_chunked_run_matches_single_run():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    seen = []
    a = top.integrate(p.l0, 50.0, sample_every=1.0)
    b = top.integrate(p.l0, 50.0, sample_every=1.0, chunks=7, progress=seen.append)
    np.testing.assert_array_equal(a.t, b.t)
    assert np.max(np.abs(a.l - b.l)) < CHUNKING_ROUNDOFF
    assert len(seen) == 7 and seen[-1] == 1.0


def test_integrate_many_equals_single_runs():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    rng = np.random.default_rng(1)
    l0s = rng.normal(size=(2, 3, 6))
    for parallel in (False, True):
        t, ls = top.integrate_many(l0s, 5.0, sample_every=1.0, dt=0.2, parallel=parallel)
        assert ls.shape == (2, 3, 6, 6)
        for idx in np.ndindex(2, 3):
            tr = top.integrate(l0s[idx], 5.0, sample_every=1.0, dt=0.2)
            np.testing.assert_array_equal(ls[idx], tr.l)


def test_too_large_dt_raises_convergence_error():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(manakov.ConvergenceError):
        top.integrate(p.l0, 10.0, t_eval=[10.0], dt=10.0)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"t_end": -1.0},
        {"t_end": float("nan")},
        {"t_end": float("inf")},
        {"t_end": 1.0, "dt": 0.0},
        {"t_end": 1.0, "dt": -0.1},
        {"t_end": 1.0, "dt": float("nan")},
        {"t_end": 1.0, "method": "rk4"},
        {"t_end": 1.0, "t_eval": [0.5, 0.2]},
        {"t_end": 1.0, "t_eval": [0.5, 2.0]},
        {"t_end": 1.0, "t_eval": [[0.5]]},
        {"t_end": 1.0, "sample_every": 0.0},
        {"t_end": 1.0, "sample_every": 0.5, "t_eval": [0.5]},
        {"t_end": 1e300, "dt": 1e-300},
        {"t_end": 1.0, "method": "dopri5", "rtol": 0.0, "atol": 0.0},
        {"t_end": 1.0, "method": "dopri5", "rtol": -1.0},
        {"t_end": 1.0, "method": "dop853", "atol": float("nan")},
    ],
)
def test_bad_integration_arguments_raise_value_error(kwargs):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    t_end = kwargs.pop("t_end")
    with pytest.raises(ValueError):
        top.integrate(p.l0, t_end, **kwargs)


# scipy's floor on rtol: an error target below ~100 ulps of the state is below the rounding
# of one step.
RTOL_FLOOR = 100 * np.finfo(float).eps


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
@pytest.mark.parametrize(
    ("rtol", "atol"),
    [(1e-300, 1e-300), (0.0, 1e-12), (1e-16, 1e-16), (RTOL_FLOOR * (1 - 2**-20), 1e-12)],
)
def test_rtol_below_the_floor_is_a_value_error(method, rtol, atol):
    """rtol = atol = 1e-300 once overflowed the error norm and was reported as a
    ConvergenceError "state became non-finite"; every rtol below 100 eps is refused up
    front, for both entry points."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="rtol"):
        top.integrate(p.l0, 1.0, method=method, rtol=rtol, atol=atol)
    with pytest.raises(ValueError, match="rtol"):
        top.integrate_many(np.array([p.l0]), 1.0, method=method, rtol=rtol, atol=atol)


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
@pytest.mark.parametrize("atol", [0.0, 1e-300])
def test_rtol_at_the_floor_with_tiny_atol_integrates(method, atol):
    """At the floor (and with atol from 0 to tiny, on a state with zero components) the
    explicit methods run and stay on the energy surface (H conserved to 1e-12 relative,
    the drift bound of the explicit methods at this tolerance over t = 1)."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0 = np.array([0.0, 1.0, 0.0, 0.5, 0.0, -0.3])
    tr = top.integrate(l0, 1.0, method=method, rtol=RTOL_FLOOR, atol=atol, t_eval=[0.0, 1.0])
    h = top.hamiltonian(tr.l)
    assert np.all(np.isfinite(tr.l)) and abs(h[1] - h[0]) <= 1e-12 * abs(h[0])


@pytest.mark.parametrize("l0", [[np.nan, 0, 0, 0, 0, 0], [1.0, 2.0], [[1.0] * 6] * 2])
def test_bad_initial_state_raises_value_error(l0):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError):
        top.integrate(l0, 1.0)
    with pytest.raises(ValueError):
        top.integrate_many(np.full((2, 5), 1.0), 1.0)
