"""Integration: Gauss coefficients, conservation, accuracy, sampling, batches, errors."""

# ruff: noqa: E741
from __future__ import annotations

import json
import time
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


@pytest.mark.parametrize("l0", [[np.nan, 0, 0, 0, 0, 0], [1.0, 2.0], [[1.0] * 5] * 2])
def test_bad_initial_state_raises_value_error(l0):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError):
        top.integrate(l0, 1.0)
    with pytest.raises(ValueError):
        top.integrate_many(np.full((2, 5), 1.0), 1.0)


# --- batch kernels (issue 12) -------------------------------------------------

# Must-show: every trajectory's integrals drift <= 1e-13 relative at t = 1e4 with
# gauss16 in batch mode (the single-trajectory claim, DRIFT_CLAIM, per member).
BATCH_DRIFT_CLAIM = 1e-13


def _random_states(n: int, seed: int, norm: float) -> np.ndarray:
    d = np.random.default_rng(seed).standard_normal((n, 6))
    return d / np.linalg.norm(d, axis=1)[:, None] * norm


@pytest.mark.parametrize("method", ["gauss16", "dop853", "taylor"])
@pytest.mark.parametrize("rows", [1, 3, 7, 1001])
def test_integrate_many_matches_integrate_bit_for_bit(method, rows):
    """The trajectory-lane kernels (4 states per vector) give integrate's results
    exactly, also for batch sizes that are not multiples of the lane width."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0s = _random_states(rows, rows, 1.0) * np.random.default_rng(0).uniform(0.5, 2, (rows, 1))
    te = [0.0, 0.4, 0.4, 1.0, 2.5]
    kw = {"t_eval": te, "method": method}
    # Taylor's method also without a cap on its step (dt is its largest step), so
    # that 0.4 and 1.0 are dense-output samples inside steps.
    for dt in (0.3, None) if method == "taylor" else (0.3,):
        for parallel in (False, True):
            t, ls = top.integrate_many(l0s, 2.5, parallel=parallel, dt=dt, **kw)
            np.testing.assert_array_equal(t, te)
            for i in range(rows) if rows < 50 else range(0, rows, 97):
                tr = top.integrate(l0s[i], 2.5, dt=dt, **kw)
                np.testing.assert_array_equal(ls[i], tr.l)


def _batch_drift(top, l0s, t_end, method="gauss16"):
    _, ls = top.integrate_many(l0s, t_end, sample_every=t_end / 10, method=method)
    a = top.a
    # Each integral relative to the sum of the magnitudes of its terms, so that an
    # integral that is small by cancellation (H0 of a random state) is not amplified.
    ints = top.integrals(ls)
    x2 = ls**2
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    comp = [tuple(sorted({0, 1, 2, 3} - set(pq))) for pq in pairs]
    scales = {
        "H0": np.abs(ls[..., 0] * ls[..., 5])
        + np.abs(ls[..., 3] * ls[..., 2])
        + np.abs(ls[..., 1] * ls[..., 4]),
        "H1": x2.sum(-1),
        "H2": (x2 * np.array([abs(a[u] + a[v]) for u, v in comp])).sum(-1),
        "H3": (x2 * np.array([abs(a[u] * a[v]) for u, v in comp])).sum(-1),
        "H": 0.5 * (x2 * np.abs(top.c[np.triu_indices(4, 1)])).sum(-1),
    }
    return max(float(np.max(np.abs(v - v[..., :1]) / scales[k][..., :1])) for k, v in ints.items())


def test_batch_drift_gauss16_to_1e4():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0s = _random_states(8, 5, float(np.linalg.norm(p.l0)))
    assert _batch_drift(top, l0s, 1e4) <= BATCH_DRIFT_CLAIM


def test_batch_drift_taylor_to_1e4():
    """Taylor's method at its default rtol = eps keeps the integrals of every member to
    roundoff too (measured 8.4e-15 on 64 states; it is explicit, so this is the
    compensated step's doing, not the scheme's)."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0s = _random_states(8, 5, float(np.linalg.norm(p.l0)))
    assert _batch_drift(top, l0s, 1e4, method="taylor") <= BATCH_DRIFT_CLAIM


@pytest.mark.slow
def test_batch_drift_gauss16_to_1e4_many_states():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0s = _random_states(64, 6, float(np.linalg.norm(p.l0)))
    assert _batch_drift(top, l0s, 1e4) <= BATCH_DRIFT_CLAIM


# --- Taylor's method (issue 12) -------------------------------------------------

# Taylor's method at rtol = eps on 'generic' against the 38-digit mpmath reference:
# measured 1.4e-15 at t = 10 and 1.8e-14 at t = 100 (800 steps, roundoff-limited;
# gauss16's default gives ~1e-13 at t = 100); bounds with a factor ~7-10 to spare.
TAYLOR_T10_ERROR = 1e-14
TAYLOR_T100_ERROR = 2e-13
# At rtol = 1e-10 (order 13) the truncation shows: measured 5e-12 at t = 10, well
# above the eps run, so the tolerance is honoured and matters.
TAYLOR_LOOSE_T10_MIN = 1e-13
# A dense-output sample (the step's polynomial inside the step) against a run that
# ends on the sample time (steps of different lengths): measured <= 2.2e-16 at t <= 10.
TAYLOR_DENSE_ROUNDOFF = 1e-14
# l -> s l, t -> t / s maps solutions to solutions; the method's relative step
# control and scaled coefficients make it exact to roundoff (measured 9.5e-16 at s = 1e6).
TAYLOR_SCALE_ROUNDOFF = 1e-14
# An explicit method, but at rtol = eps its truncation is far below roundoff, and the
# compensated update keeps the integrals to roundoff: measured 3.3e-16 at t = 100 and
# 4.1e-15 at t = 1e4 (8e4 steps). A term computed with other constants than the rest
# once made Σ l² drift linearly (1.4e-13 at t = 1e4), which the 1e4 bound catches.
TAYLOR_T100_DRIFT = 1e-14
TAYLOR_T1E4_DRIFT = DRIFT_CLAIM


def test_taylor_against_the_mpmath_reference():
    ref = _reference()
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 100.0, t_eval=[10.0, 100.0], method="taylor")
    assert tr.method == "taylor" and tr.steps > 0
    assert np.max(np.abs(tr.l[0] - ref[10.0])) < TAYLOR_T10_ERROR
    assert np.max(np.abs(tr.l[1] - ref[100.0])) < TAYLOR_T100_ERROR
    assert max(tr.max_drift().values()) < TAYLOR_T100_DRIFT
    loose = top.integrate(p.l0, 10.0, t_eval=[10.0], method="taylor", rtol=1e-10)
    assert TAYLOR_LOOSE_T10_MIN < np.max(np.abs(loose.l[0] - ref[10.0])) < 1e3 * 1e-10


def test_taylor_integrals_stay_at_roundoff_to_1e4():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 1e4, sample_every=10.0, method="taylor")
    assert max(tr.max_drift().values()) <= TAYLOR_T1E4_DRIFT, tr.max_drift()


def test_taylor_dense_output_matches_runs_that_end_on_the_sample():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 10.0, sample_every=0.01, method="taylor")
    assert tr.steps < tr.t.size / 5  # most samples are inside steps
    for i in (1, 137, 500, 999, 1000):
        one = top.integrate(p.l0, tr.t[i], t_eval=[tr.t[i]], method="taylor")
        assert np.max(np.abs(tr.l[i] - one.l[-1])) < TAYLOR_DENSE_ROUNDOFF


def test_taylor_is_invariant_under_scaling():
    ref = _reference()[10.0]
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    for s in (1e-6, 1e6, 1e12):
        tr = top.integrate(p.l0 * s, 10.0 / s, t_eval=[10.0 / s], method="taylor")
        assert np.max(np.abs(tr.l[-1] / s - ref)) < TAYLOR_SCALE_ROUNDOFF, s


@pytest.mark.parametrize("rtol", [1e-17, 0.0, -1.0, 2e-3, float("nan"), float("inf")])
def test_taylor_tolerance_out_of_range_is_a_value_error(rtol):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="rtol"):
        top.integrate(p.l0, 1.0, method="taylor", rtol=rtol)
    with pytest.raises(ValueError, match="rtol"):
        top.integrate_many(np.array([p.l0]), 1.0, method="taylor", rtol=rtol)


def test_taylor_is_for_so4_only():
    top = manakov.FrahmTop(manakov.ManakovTop([0, 1, 2, 3, 5], [1, 0, 2, 4, 3]).c)
    l0 = np.linspace(-1, 1, 10)
    with pytest.raises(ValueError, match="so\\(4\\)"):
        top.integrate(l0, 1.0, method="taylor")
    with pytest.raises(ValueError, match="so\\(4\\)"):
        top.integrate_many(l0[None], 1.0, method="taylor")


def test_taylor_run_out_of_budget_keeps_the_partial_trajectory():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="max_steps") as info:
        top.integrate(p.l0, 100.0, sample_every=1.0, method="taylor", max_steps=300)
    part = info.value.partial
    assert isinstance(part, manakov.Trajectory) and 0 < part.t.size < 101
    full = top.integrate(p.l0, 100.0, sample_every=1.0, method="taylor")
    np.testing.assert_array_equal(part.l, full.l[: part.t.size])
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate_many(np.tile(p.l0, (5, 1)), 100.0, method="taylor", max_steps=300)


def test_taylor_does_not_modify_its_inputs():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0s = _random_states(5, 3, 1.0)
    te = np.array([0.0, 0.5, 1.0])
    keep = (l0s.copy(), te.copy())
    top.integrate_many(l0s, 1.0, t_eval=te, method="taylor")
    top.integrate(l0s[0], 1.0, t_eval=te, method="taylor")
    np.testing.assert_array_equal(l0s, keep[0])
    np.testing.assert_array_equal(te, keep[1])


# --- budgets, sizes and argument checks (issue 11) ----------------------------

# A refused run must fail before doing the work: well under 0.1 s (the bound).
REFUSAL_SECONDS = 0.1


def _refused(fn, match):
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=match):
        fn()
    return time.perf_counter() - t0


@pytest.mark.parametrize("method", ["gauss16", "dop853", "taylor"])
def test_over_budget_sample_spacing_is_refused_at_once(method):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    dt = 0.3 if method == "gauss16" else None
    el = _refused(
        lambda: top.integrate(p.l0, 1e5, sample_every=1.0, max_steps=10**4, dt=dt, method=method),
        "sample spacing",
    )
    assert el < REFUSAL_SECONDS
    el = _refused(
        lambda: top.integrate_many(
            np.tile(p.l0, (8, 1)), 1e5, sample_every=1.0, max_steps=10**4, dt=dt, method=method
        ),
        "sample spacing",
    )
    assert el < REFUSAL_SECONDS
    # Samples 0.1 apart at dt = 0.3: 1000 intervals need 1000 steps although
    # t_end / dt is only 334.
    el = _refused(
        lambda: top.integrate(p.l0, 100.0, sample_every=0.1, dt=0.3, max_steps=500),
        "sample spacing",
    )
    assert el < REFUSAL_SECONDS


def test_over_budget_huge_l0_is_refused_at_once():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    big = p.l0 * 1e12
    assert _refused(lambda: top.integrate(big, 100.0), r"huge \|l0\|") < REFUSAL_SECONDS
    assert (
        _refused(lambda: top.integrate_many(np.tile(big, (3, 1)), 100.0), r"huge \|l0\|")
        < REFUSAL_SECONDS
    )


def test_over_budget_dt_is_refused_at_once_and_before_progress():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    seen = []
    el = _refused(
        lambda: top.integrate(
            p.l0, 1000.0, dt=1e-3, chunks=10, progress=seen.append, max_steps=2000
        ),
        "dt:",
    )
    assert el < REFUSAL_SECONDS and seen == []


def test_huge_batch_output_is_a_value_error_not_an_abort():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    # 10^5 states x 10^6 + 1 samples x 6 doubles = 4.8 TB: refused before allocating.
    l0s = np.tile(p.l0, (10**5, 1))
    el = _refused(
        lambda: top.integrate_many(l0s, 1e6, sample_every=1.0, method="dop853", max_steps=10**11),
        "cannot allocate",
    )
    assert el < 1.0  # includes building the 8 MB sample grid


def test_explicit_run_out_of_budget_keeps_the_partial_trajectory():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="max_steps") as info:
        top.integrate(p.l0, 100.0, sample_every=1.0, method="dop853", max_steps=300)
    part = info.value.partial
    assert isinstance(part, manakov.Trajectory) and 0 < part.t.size < 101
    full = top.integrate(p.l0, 100.0, sample_every=1.0, method="dop853")
    np.testing.assert_array_equal(part.l, full.l[: part.t.size])
    np.testing.assert_array_equal(part.t, full.t[: part.t.size])


def test_trajectory_t_is_a_copy_of_t_eval():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    te = np.array([0.0, 0.5, 1.0])
    tr = top.integrate(p.l0, 1.0, t_eval=te)
    assert tr.t is not te and not np.shares_memory(tr.t, te)
    np.testing.assert_array_equal(tr.t, te)


@pytest.mark.parametrize("method", ["gauss16", "dop853", "dopri5", "taylor"])
def test_default_dt_refuses_non_finite_l0_for_every_method(method):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="finite"):
        top.default_dt(np.array([np.inf, 0, 0, 0, 0, 0]), method)


def test_tiny_sample_every_is_a_value_error():
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="samples"):
        top.integrate(p.l0, 1e300, sample_every=1e-300)


@pytest.mark.parametrize("chunks", [0, -3, 1.5, True, "2"])
def test_chunks_must_be_a_positive_integer(chunks):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError, match="chunks"):
        top.integrate(p.l0, 1.0, chunks=chunks)


@pytest.mark.parametrize("method", ["gauss4", "gauss6", "gauss16"])
def test_gauss_methods_ignore_rtol_atol_as_documented(method):
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    a = top.integrate(p.l0, 1.0, method=method, rtol=-5, atol=float("nan"))
    b = top.integrate(p.l0, 1.0, method=method)
    np.testing.assert_array_equal(a.l, b.l)
    _, ls = top.integrate_many(p.l0[None], 1.0, method=method, rtol=-5)
    np.testing.assert_array_equal(ls[0], b.l)


def test_overflowing_a_difference_is_refused():
    with pytest.raises(ValueError, match="overflows"):
        manakov.ManakovTop([1e308, -1e308, 3, 4], [1, 2, 3, 4])


@pytest.mark.parametrize("bad", [["1", "2", "3", "4"], [b"1", b"2", b"3", b"4"]])
def test_strings_are_not_numbers(bad):
    with pytest.raises(ValueError, match="numeric"):
        manakov.ManakovTop(bad, [1.0, 2.0, 3.0, 4.0])
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    with pytest.raises(ValueError):
        top.integrate(p.l0, "10")


# --- Ctrl-C (issue 11) --------------------------------------------------------

# Must-show: a long integrate / integrate_many stops within 0.5 s of SIGINT.
SIGINT_LATENCY = 0.5

_CHILD = r"""
import os, sys, threading, time
import numpy as np
import manakov

p = manakov.problem("generic")
top = manakov.ManakovTop(p.a, p.b)
what = sys.argv[1]
ntasks = lambda: len(os.listdir("/proc/self/task"))
top.integrate_many(np.tile(p.l0, (8, 1)), 1.0)  # starts rayon's pool beforehand
before = ntasks()
print("READY", flush=True)
try:
    if what == "integrate":
        top.integrate(p.l0, 1e9, t_eval=[1.0, 1e9], max_steps=10**11)
    else:
        parallel = what != "integrate_many_serial"
        method = "taylor" if what == "integrate_many_taylor" else "gauss16"
        l0s = np.tile(p.l0, (64, 1))
        top.integrate_many(
            l0s, 1e7, t_eval=[1e7], max_steps=10**11, parallel=parallel, method=method
        )
    print("FINISHED", flush=True)
except KeyboardInterrupt as err:
    t = time.monotonic()
    samples = err.partial.t.size if hasattr(err, "partial") else -1
    time.sleep(0.1)
    print("INTERRUPTED", t, ntasks() - before, threading.active_count(), samples, flush=True)
"""


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
@pytest.mark.parametrize(
    "what", ["integrate", "integrate_many", "integrate_many_serial", "integrate_many_taylor"]
)
def test_sigint_stops_a_long_run_within_half_a_second(what):
    import signal
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-c", _CHILD, what], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().strip() == "READY"
        time.sleep(0.5)
        t_sig = time.monotonic()
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=30)
    finally:
        proc.kill()
    fields = out.split()
    assert fields[0] == "INTERRUPTED", out
    t_stop, extra_threads, py_threads, samples = (
        float(fields[1]),
        int(fields[2]),
        int(fields[3]),
        int(fields[4]),
    )
    assert t_stop - t_sig < SIGINT_LATENCY
    assert extra_threads <= 0 and py_threads == 1  # nothing left running
    if what == "integrate":
        assert samples == 1  # the sample at t = 1 was reached and is kept


# --- invariance under c_ij -> c_ij + k (issue 9) ------------------------------

# Must-show: gauss16's error at t = 100 on 'generic' with every c_ij shifted by +100
# is within 2x of the unshifted error, each against the exact flow of its own top.
SHIFT_ERROR_RATIO = 2.0


def test_gauss16_is_invariant_under_a_shift_of_every_c():
    """(1) depends on c only through c_kj - c_ik (omega -> omega + k l, [l, l] = 0).
    The shifted doubles c_ij + 100 are a slightly different top (rounding), so each
    run is measured against the 38-digit flow of the top it was given."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    ref = json.loads((DATA / "reference_generic.json").read_text())["states"]["100"]
    ref = np.array([float(x) for x in ref])
    data = json.loads((DATA / "reference_generic_shifted.json").read_text())
    ref_s = np.array([float(x) for x in data["state"]])
    c_s = np.zeros((4, 4))
    for key, v in data["c_shifted"].items():
        i, j = int(key[0]), int(key[1])
        c_s[i, j] = c_s[j, i] = v
    # The stored shifted doubles are what the package forms from c + 100.
    iu = np.triu_indices(4, 1)
    np.testing.assert_array_equal(c_s[iu], (top.c + 100.0)[iu])
    shifted = manakov.FrahmTop(c_s)
    assert shifted.default_dt(p.l0) == pytest.approx(top.default_dt(p.l0), rel=1e-13)
    err = np.max(np.abs(top.integrate(p.l0, 100.0, t_eval=[100.0]).l[-1] - ref))
    l_s = shifted.integrate(p.l0, 100.0, t_eval=[100.0]).l[-1]
    err_s = np.max(np.abs(l_s - ref_s))
    assert err_s <= SHIFT_ERROR_RATIO * err, (err_s, err)
    # Issue 9's observation: against the *unshifted* flow the shifted run looks several
    # times worse; that is the rounding of c + 100 (a different top), not the stepping.
    assert np.max(np.abs(l_s - ref)) > SHIFT_ERROR_RATIO * err


def test_nearly_equal_a_over_budget_names_the_cause():
    p = manakov.problem("generic")
    top = manakov.ManakovTop([0.3, 0.3 + 1e-6, 2.0, 3.7], p.b)  # c12 ~ -7e5
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"nearly equal a_i.*move the a_i apart"):
        top.integrate(p.l0, 1000.0)
    assert time.perf_counter() - t0 < REFUSAL_SECONDS


def test_integrate_many_with_a_state_near_the_double_limit_raises_cleanly():
    # Slow-fuzz reproducer: the batch default step overflowed |l0| with a
    # RuntimeWarning (an error under pytest) before the ValueError naming the cause.
    top = manakov.ManakovTop([0.3, 1.1, 2.0, 3.7], [0.5, -0.2, 1.4, 0.9])
    l0s = np.array([[0.0, 0.0, 0.0, 0.0, 1.7e308, 1.7e308]])
    with pytest.raises(ValueError, match="too large"):
        top.integrate_many(l0s, 1.0, method="gauss16", max_steps=1)
