"""Kirchhoff's equations for a rigid body in an ideal fluid (``manakov.KirchhoffBody``).

References are independent of the package: the field and the integrals in
numpy from their formulas, scipy's DOP853, and closed-form motions (a
translation, a steady rotation).
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import manakov
from manakov.fluid import DT_SCALE

#: Must-show: p·p, M·p and H kept to this over t = 1e4 (gauss16, default step),
#: each relative to the size of its terms (p·p, |M||p|, H: H > 0 bounds
#: ½ yᵀ|Q|y for a positive definite Q up to its condition number, which is
#: O(10) for the bodies drawn here).
CONSERVATION_RTOL = 1e-13
#: Agreement with scipy DOP853 (rtol = atol = 1e-13, its error ~1e-12 on these
#: horizons) relative to max |y|.
DOP853_RTOL = 1e-11
#: A random dense body's motion is chaotic: on the third body of the seed-7 draw
#: below, gauss16 at its default step and at a tenth of it differ by 3e-15 at
#: t = 2, 1.6e-11 at t = 5 and 8e-8 at t = 10 (rounding amplified, not the
#: step's error). Agreement on random bodies is asked up to this time.
CHAOS_HORIZON = 2.0
#: The integrable reference bodies are compared on [0, INTEGRABLE_HORIZON]:
#: DOP853's own global error at rtol = 1e-13 grows to 1.6e-11 on [0, 100]
#: (clebsch_generic, against the closed form; gauss16 there: 1.2e-13).
INTEGRABLE_HORIZON = 20.0
#: Refusals (bad arguments, budgets) return within this time.
REFUSAL_SECONDS = 0.1


def random_body(rng: np.random.Generator) -> manakov.KirchhoffBody:
    """A body with a dense positive definite energy ``Q = G Gᵀ/2 + I/2``."""
    g = rng.normal(size=(6, 6))
    q = 0.5 * g @ g.T + 0.5 * np.eye(6)
    return manakov.KirchhoffBody(q[:3, :3], q[:3, 3:], q[3:, 3:])


def field_numpy(body: manakov.KirchhoffBody, y: np.ndarray) -> np.ndarray:
    """Kirchhoff's equations from the formula, in numpy."""
    M, p = y[:3], y[3:]
    w = body.A @ M + body.B @ p
    v = body.B.T @ M + body.C @ p
    return np.concatenate([np.cross(M, w) + np.cross(p, v), np.cross(p, w)])


def scaled_drift(body, tr) -> dict[str, float]:
    """max |I(t) − I(0)| over the scale of each integral's terms."""
    M, p = tr.M, tr.p
    scales = {
        "pp": float(np.sum(p[0] ** 2)),
        "Mp": float(np.linalg.norm(M[0]) * np.linalg.norm(p[0])),
        "H": float(body.hamiltonian(M[0], p[0])),
    }
    return {
        k: float(np.max(np.abs(tr.integrals[k] - tr.integrals[k][0]))) / s
        for k, s in scales.items()
    }


# --- the field ----------------------------------------------------------------


def test_field_energy_and_casimirs_are_kirchhoffs():
    rng = np.random.default_rng(1)
    for _ in range(10):
        body = random_body(rng)
        y = rng.normal(size=6)
        dM, dp = body.vector_field(y[:3], y[3:])
        np.testing.assert_allclose(
            np.concatenate([dM, dp]), field_numpy(body, y), rtol=1e-13, atol=1e-14
        )
        Q = np.block([[body.A, body.B], [body.B.T, body.C]])
        assert body.hamiltonian(y[:3], y[3:]) == pytest.approx(0.5 * y @ Q @ y, rel=1e-14)
        ints = body.integrals(y[:3], y[3:])
        assert ints["pp"] == pytest.approx(y[3:] @ y[3:], rel=1e-15)
        assert ints["Mp"] == pytest.approx(y[:3] @ y[3:], rel=1e-14)
        # The field is the Lie–Poisson flow of H on e(3)*: dI/dt = ∇I · f = 0 for
        # the Casimirs and H.
        f = field_numpy(body, y)
        assert abs(2 * y[3:] @ f[3:]) < 1e-13 * np.abs(f).max() * np.abs(y).max()
        assert abs(f[:3] @ y[3:] + y[:3] @ f[3:]) < 1e-13 * np.abs(f).max() * np.abs(y).max()
        assert abs((Q @ y) @ f) < 1e-13 * np.abs(Q @ y).max() * np.abs(f).max()


def test_broadcasting_shapes_and_read_only_inputs():
    body = random_body(np.random.default_rng(2))
    M = np.random.default_rng(3).normal(size=(4, 5, 3))
    p = np.array([0.3, -0.2, 0.5])
    M.setflags(write=False)
    dM, dp = body.vector_field(M, p)
    assert dM.shape == dp.shape == (4, 5, 3)
    one = body.vector_field(M[1, 2], p)
    np.testing.assert_array_equal(dM[1, 2], one[0])
    h = body.hamiltonian(M, p)
    assert h.shape == (4, 5)
    assert isinstance(body.hamiltonian(M[0, 0], p), float)
    # Non-contiguous and integer input.
    dM2, _ = body.vector_field(M[:, ::2, :], p)
    np.testing.assert_array_equal(dM2, dM[:, ::2, :])
    body.vector_field([1, 2, 3], [0, 1, 0])
    ints = body.integrals(M, p)
    assert set(ints) == {"pp", "Mp", "H"} and ints["H"].shape == (4, 5)


@pytest.mark.parametrize(
    "args, match",
    [
        ((np.eye(3), np.zeros((3, 3)), -np.eye(3)), "positive definite.*kappa"),
        ((np.eye(3), np.eye(3), np.eye(3)), "positive definite"),
        ((np.array([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]), np.zeros((3, 3)), np.eye(3)), "symmetric"),
        ((np.eye(2), np.zeros((3, 3)), np.eye(3)), r"shape \(3, 3\)"),
        ((np.eye(3) * np.nan, np.zeros((3, 3)), np.eye(3)), "finite"),
        ((np.eye(3) * 1j, np.zeros((3, 3)), np.eye(3)), "real"),
    ],
)
def test_bad_bodies_raise_value_error(args, match):
    with pytest.raises(ValueError, match=match):
        manakov.KirchhoffBody(*args)


def test_bad_states_raise_value_error():
    body = random_body(np.random.default_rng(4))
    with pytest.raises(ValueError, match="shape"):
        body.vector_field([1, 2], [1, 2, 3])
    with pytest.raises(ValueError, match="broadcast"):
        body.vector_field(np.ones((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError, match="finite"):
        body.hamiltonian([np.inf, 0, 0], [1, 0, 0])
    with pytest.raises(ValueError, match="overflows"):
        body.vector_field([1e200, 0, 0], [1e200, 1e200, 0])
    with pytest.raises(ValueError, match=r"shape \(3,\)"):
        body.integrate(np.ones((2, 3)), np.ones(3), 1.0)


# --- integration --------------------------------------------------------------


def test_casimirs_and_energy_kept_over_1e4_on_random_bodies():
    rng = np.random.default_rng(20261201)
    worst = {"pp": 0.0, "Mp": 0.0, "H": 0.0}
    for _ in range(4):
        body = random_body(rng)
        M0, p0 = rng.normal(size=3), rng.normal(size=3)
        tr = body.integrate(M0, p0, 1e4, sample_every=10.0)
        assert tr.method == "gauss16" and tr.dt == pytest.approx(body.default_dt(M0, p0))
        for k, v in scaled_drift(body, tr).items():
            worst[k] = max(worst[k], v)
    assert max(worst.values()) <= CONSERVATION_RTOL, worst


@pytest.mark.parametrize("name", manakov.fluid_problem_names())
def test_case_integrals_are_conserved(name):
    pr = manakov.fluid_problem(name)
    tr = pr.body.integrate(pr.M0, pr.p0, 1e3, sample_every=1.0)
    extra = {"clebsch": "F", "lyapunov_steklov": "F", "kirchhoff": "M3"}.get(pr.body.case)
    names = {"pp", "Mp", "H"} | ({extra} if extra else set())
    assert set(tr.integrals) == names
    for k in names:
        v = tr.integrals[k]
        # Relative to the size of the integral's terms: |y|².
        scale = np.sum(pr.M0**2) + np.sum(pr.p0**2)
        assert np.max(np.abs(v - v[0])) <= 1e-13 * scale, (k, np.max(np.abs(v - v[0])))


def test_the_case_integrals_are_not_conserved_by_other_bodies():
    """The extra integrals are specific: perturbing the body breaks them (so the
    test above can fail)."""
    pr = manakov.fluid_problem("clebsch_generic")
    A = np.diag(pr.body.A).copy()
    C = np.diag(pr.body.C).copy()
    a = pr.body._clebsch.body_a
    off = manakov.KirchhoffBody(np.diag(A), np.zeros((3, 3)), np.diag(C * [1.0, 1.0, 1.01]))
    assert off.case == "general"
    tr = off.integrate(pr.M0, pr.p0, 50.0, sample_every=1.0)
    F = np.sum(tr.M**2, axis=1) - tr.p**2 @ a
    assert np.max(np.abs(F - F[0])) > 1e-4
    st = manakov.fluid_problem("lyapunov_steklov")
    b, eps = st.body._steklov
    wrong = manakov.KirchhoffBody.lyapunov_steklov(b, -eps, kappa=2.0)
    tr = wrong.integrate(st.M0, st.p0, 50.0, sample_every=1.0)
    w = np.array([(b[1] - b[2]) ** 2, (b[2] - b[0]) ** 2, (b[0] - b[1]) ** 2])
    F = 0.5 * np.sum(tr.M**2 - 2 * eps * b * tr.M * tr.p + eps**2 * w * tr.p**2, axis=1)
    assert np.max(np.abs(F - F[0])) > 1e-4


def test_cases_are_recognised():
    assert random_body(np.random.default_rng(5)).case == "general"
    k = manakov.KirchhoffBody(
        np.diag([1.0, 2.0, 1.0]), np.diag([0.1, 0.3, 0.1]), np.diag([2, 1, 2.0])
    )
    assert k.case == "kirchhoff"
    assert "M2" in k.integrals([1, 2, 3], [0, 1, 0])
    c = manakov.KirchhoffBody(
        np.diag([0.7, 1.3, 2.2]),
        np.zeros((3, 3)),
        np.diag(manakov.fluid_problem("clebsch_generic").body.C.diagonal()),
    )
    assert c.case == "clebsch"
    with pytest.raises(ValueError, match="Clebsch's condition"):
        manakov.KirchhoffBody.clebsch([0.7, 1.3, 2.2], [3.2, 2.4, 2.0])
    with pytest.raises(ValueError, match="axisymmetric"):
        manakov.KirchhoffBody.clebsch([1.0, 1.0, 2.0], [2.0, 2.0, 1.0])
    with pytest.raises(ValueError, match="positive definite"):
        manakov.KirchhoffBody.lyapunov_steklov([0.7, 1.3, 2.1], 0.37)


def test_clebsch_condition_tolerance_is_the_documented_one():
    from manakov.fluid import CLEBSCH_RTOL

    A = np.array([0.7, 1.3, 2.2])
    C = 1.5 + 0.6 * np.array([A[1] * A[2], A[2] * A[0], A[0] * A[1]])
    terms = np.array([(C[1] - C[2]) / A[0], (C[2] - C[0]) / A[1], (C[0] - C[1]) / A[2]])
    scale = np.sum(np.abs(terms))
    for factor, ok in ((0.5, True), (2.0, False)):
        # Move C1 so that the condition is off by factor * CLEBSCH_RTOL of its terms.
        dC = factor * CLEBSCH_RTOL * scale / (1 / A[2] - 1 / A[1])
        C2 = C.copy()
        C2[0] += dC
        if ok:
            assert manakov.KirchhoffBody.clebsch(A, C2).case == "clebsch"
        else:
            with pytest.raises(ValueError, match="Clebsch's condition"):
                manakov.KirchhoffBody.clebsch(A, C2)


def test_gauss16_agrees_with_scipy_dop853():
    rng = np.random.default_rng(7)
    cases = [
        (random_body(rng), rng.normal(size=3), rng.normal(size=3), CHAOS_HORIZON) for _ in range(3)
    ]
    for name in ("clebsch_generic", "kirchhoff", "lyapunov_steklov"):
        pr = manakov.fluid_problem(name)
        cases.append((pr.body, pr.M0, pr.p0, INTEGRABLE_HORIZON))
    for body, M0, p0, T in cases:
        t = np.linspace(0.0, T, 21)
        tr = body.integrate(M0, p0, T, t_eval=t)
        ref = solve_ivp(
            lambda _, y, b=body: field_numpy(b, y),
            (0.0, T),
            np.concatenate([M0, p0]),
            method="DOP853",
            rtol=1e-13,
            atol=1e-13,
            t_eval=t,
        ).y.T
        err = np.max(np.abs(np.hstack([tr.M, tr.p]) - ref)) / np.max(np.abs(ref))
        assert err <= DOP853_RTOL, (body.case, err)


def test_default_step_is_at_roundoff():
    """DT_SCALE: gauss16 at the default step against a 10× smaller step."""
    pr = manakov.fluid_problem("clebsch_generic")
    body = pr.body
    dt = body.default_dt(pr.M0, pr.p0)
    assert dt == pytest.approx(
        DT_SCALE["gauss16"] / (body.rate_scale * np.linalg.norm(np.r_[pr.M0, pr.p0]))
    )
    a = body.integrate(pr.M0, pr.p0, 20.0, t_eval=[20.0])
    b = body.integrate(pr.M0, pr.p0, 20.0, t_eval=[20.0], dt=dt / 10)
    assert np.max(np.abs(a.M - b.M)) < 1e-14 * 20


def test_integrate_many_equals_integrate_bit_for_bit():
    body = random_body(np.random.default_rng(8))
    rng = np.random.default_rng(9)
    M0s, p0s = rng.normal(size=(7, 3)), rng.normal(size=(7, 3))
    for method in ("gauss16", "dop853"):
        for parallel in (False, True):
            t, Ms, ps = body.integrate_many(
                M0s, p0s, 5.0, sample_every=1.0, dt=0.05, method=method, parallel=parallel
            )
            assert Ms.shape == (7, t.size, 3)
            for k in range(7):
                one = body.integrate(M0s[k], p0s[k], 5.0, sample_every=1.0, dt=0.05, method=method)
                np.testing.assert_array_equal(Ms[k], one.M)
                np.testing.assert_array_equal(ps[k], one.p)


def test_budget_is_refused_before_any_work():
    body = random_body(np.random.default_rng(10))
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="max_steps"):
        body.integrate([1, 0, 0], [0, 1, 0], 1e9, max_steps=1000)
    with pytest.raises(ValueError, match="max_steps"):
        body.integrate_many(np.ones((3, 3)), np.ones(3), 1e9, max_steps=1000)
    assert time.perf_counter() - t0 < REFUSAL_SECONDS
    with pytest.raises(ValueError, match="unknown method"):
        body.integrate([1, 0, 0], [0, 1, 0], 1.0, method="taylor")


def test_a_failed_step_carries_the_samples_reached():
    body = random_body(np.random.default_rng(11))
    with pytest.raises(manakov.ConvergenceError) as err:
        body.integrate([1, 0, 0], [0, 1, 0], 10.0, t_eval=[0.0, 0.001, 10.0], dt=5.0)
    part = err.value.partial  # type: ignore[attr-defined]
    assert isinstance(part, manakov.FluidTrajectory)
    assert part.t.size == 2 and part.M.shape == (2, 3)


_CHILD = r"""
import sys, time
import numpy as np
import manakov
pr = manakov.fluid_problem("general")
print("READY", flush=True)
try:
    if sys.argv[1] == "integrate":
        pr.body.integrate(pr.M0, pr.p0, 1e9, t_eval=[1.0, 1e9], max_steps=10**11)
    else:
        pr.body.integrate_many(np.tile(pr.M0, (8, 1)), pr.p0, 1e8, t_eval=[1e8], max_steps=10**11)
    print("FINISHED", flush=True)
except KeyboardInterrupt as err:
    samples = err.partial.t.size if hasattr(err, "partial") else -1
    print("INTERRUPTED", time.monotonic(), samples, flush=True)
"""


@pytest.mark.parametrize("what", ["integrate", "integrate_many"])
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
    assert float(fields[1]) - t_sig < 0.5
    if what == "integrate":
        assert int(fields[2]) == 1  # the sample at t = 1 is kept in err.partial


# --- the body in space --------------------------------------------------------


def test_motion_in_space_keeps_impulse_and_moment():
    pr = manakov.fluid_problem("general")
    R0 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    tr = pr.body.motion_in_space(pr.M0, pr.p0, 50.0, R0=R0, x0=[1.0, 2.0, 3.0], sample_every=0.5)
    np.testing.assert_array_equal(tr.R[0], R0)
    np.testing.assert_array_equal(tr.x[0], [1.0, 2.0, 3.0])
    P, K = tr.impulse(), tr.moment()
    assert np.max(np.abs(P - P[0])) < 1e-13
    assert np.max(np.abs(K - K[0])) < 1e-11
    assert np.max(np.abs(np.einsum("sij,skj->sik", tr.R, tr.R) - np.eye(3))) < 1e-13
    # The (M, p) part is the body's own integration.
    own = pr.body.integrate(pr.M0, pr.p0, 50.0, sample_every=0.5, dt=tr.dt)
    np.testing.assert_allclose(tr.M, own.M, rtol=0, atol=1e-12)


def test_motion_in_space_closed_forms():
    # No coupling, isotropic A: M fixed, the body turns about M at the rate A|M|.
    body = manakov.KirchhoffBody(2.0 * np.eye(3), np.zeros((3, 3)), np.diag([1.0, 2.0, 3.0]))
    M0 = np.array([0.0, 0.0, 0.5])
    tr = body.motion_in_space(M0, [0.0, 0.0, 0.0], 3.0, sample_every=0.5)
    for t, R in zip(tr.t, tr.R):
        c, s = np.cos(t), np.sin(t)
        np.testing.assert_allclose(R, [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-14)
    assert np.max(np.abs(tr.x)) == 0.0
    # M = 0, p along a principal axis: steady translation x = t C p.
    tr = body.motion_in_space([0.0, 0.0, 0.0], [0.0, 0.7, 0.0], 4.0, sample_every=1.0)
    np.testing.assert_allclose(tr.x, np.outer(tr.t, [0.0, 1.4, 0.0]), atol=1e-14)
    with pytest.raises(ValueError, match="rotation"):
        body.motion_in_space(M0, [0, 0, 1], 1.0, R0=np.diag([1.0, 1.0, -1.0]))


# --- the reference bodies -----------------------------------------------------


def test_reference_bodies_load():
    names = manakov.fluid_problem_names()
    assert names[:4] == [
        "clebsch_generic",
        "clebsch_wide",
        "clebsch_isotropic",
        "clebsch_near_degenerate",
    ]
    for n in names:
        pr = manakov.fluid_problem(n)
        assert pr.M0.shape == pr.p0.shape == (3,)
        assert pr.body.case == (
            n if n in ("kirchhoff", "lyapunov_steklov", "general") else "clebsch"
        )
    with pytest.raises(ValueError, match="unknown body"):
        manakov.fluid_problem("nope")


def test_reference_bodies_match_their_generator():
    import json
    import subprocess
    import sys

    script = Path(__file__).parent / "data" / "gen_fluid_bodies.py"
    path = Path(manakov.__file__).parent / "data" / "fluid_bodies.json"
    before = path.read_text()
    subprocess.run([sys.executable, str(script)], check=True, capture_output=True)
    assert path.read_text() == before
    assert json.loads(before)["bodies"]


# --- fuzzing -------------------------------------------------------------------


#: Documented exceptions; a Rust panic (PanicException, a BaseException) fails.
ALLOWED = (ValueError, manakov.ConvergenceError, manakov.ClosedFormError)
#: Cases per property (MANAKOV_FUZZ_SLOW=1: 3000, as tests/test_fuzz.py widens its runs).
FUZZ_EXAMPLES = 3000 if os.environ.get("MANAKOV_FUZZ_SLOW") else 60
FUZZ = settings(
    max_examples=FUZZ_EXAMPLES,
    deadline=None,
    derandomize=True,
    suppress_health_check=list(HealthCheck),
)

_finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
_any = st.floats(width=64)
_exp = st.integers(-300, 300)


def _call(fn, *args, **kw):
    try:
        # documented: values of an integration standing in for a closed form
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", manakov.IntegratedValuesWarning)
            return fn(*args, **kw)
    except ALLOWED:
        return None
    except BaseException as e:  # noqa: BLE001 - a panic is a BaseException
        raise AssertionError(f"undocumented {type(e).__name__}: {e}") from e


@FUZZ
@given(st.lists(_any, min_size=27, max_size=27), st.lists(_any, min_size=6, max_size=6), _exp)
def test_fuzz_bodies_and_states(entries, state, e):
    """Any A, B, C (scaled by 10^e, NaN and infinities included) and any state:
    a body or ValueError; then finite results or ValueError/ConvergenceError."""
    with np.errstate(all="ignore"):  # the inputs themselves may overflow to inf
        m = np.array(entries).reshape(3, 3, 3) * 10.0**e
        sym = [0.5 * m[0] + 0.5 * m[0].T, m[1], 0.5 * m[2] + 0.5 * m[2].T]
    body = _call(manakov.KirchhoffBody, *sym)
    if body is None:
        return
    y = np.array(state)
    y_copy = y.copy()
    for fn in (body.vector_field, body.hamiltonian, body.integrals):
        out = _call(fn, y[:3], y[3:])
        if out is not None:
            vals = list(out.values()) if isinstance(out, dict) else out
            vals = vals if isinstance(vals, (list, tuple)) else [vals]
            assert all(np.all(np.isfinite(v)) for v in vals)
    tr = _call(body.integrate, y[:3], y[3:], 1.0, max_steps=10**5)
    if tr is not None:
        assert np.all(np.isfinite(tr.M)) and np.all(np.isfinite(tr.p))
    np.testing.assert_array_equal(y, y_copy)


@FUZZ
@given(
    st.lists(st.floats(1e-3, 1e3), min_size=3, max_size=3),
    st.floats(-10, 10),
    st.floats(0, 1e3),
    st.lists(_finite.filter(lambda x: abs(x) < 1e6), min_size=6, max_size=6),
    st.integers(-100, 100),
)
def test_fuzz_clebsch(A, theta, kappa, state, e):
    """Clebsch bodies over wide scales (C_i = κ + θ A_j A_k, then all times 10^e):
    the conjugacy and the closed form give finite values or documented errors."""
    A = np.array(A) * 10.0**e
    C = kappa * 10.0**e + theta * np.array([A[1] * A[2], A[2] * A[0], A[0] * A[1]]) / 10.0**e
    body = _call(manakov.KirchhoffBody.clebsch, A, C)
    if body is None:
        return
    y = np.array(state)
    sol = _call(body.solve, y[:3], y[3:])
    if sol is None:
        return
    out = _call(sol.state, [0.0, 1.0, 10.0])
    if out is not None:
        assert np.all(np.isfinite(out[0])) and np.all(np.isfinite(out[1]))
