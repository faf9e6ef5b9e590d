"""The theta API: shapes, dtypes, exceptions, the exponential split, and the
proven truncation bound checked against python-flint's certified values."""

from __future__ import annotations

import numpy as np
import pytest
from flint import acb, acb_mat, ctx

import manakov
from manakov import _core, theta, theta_all, theta_jet

BENCH_TAU = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
Z0 = np.array([0.2 + 0.1j, 0.7 - 0.3j])
#: flint's balls at 200 bits: radii far below double precision, so the midpoint is the
#: truth for our purpose (1e-30 is 14 orders below what is compared).
FLINT_RADIUS_MAX = 1e-30
#: The project's theta accuracy claim (test_theta.AGREE): 1e-13 relative to the largest
#: of the values.
AGREE = 1e-13
#: log of the scale, pi y^T Y^{-1} y ~ 1e3, against an independent numpy solve: a few ulps
#: of the 2x2 solve and the quadratic form.
LOG_SCALE_RTOL = 1e-13
#: theta_all of the non-overflowing points against the log_scale split product
#: om * exp(log) at the same points: the same sums, rounding of exp(log) only (~100 ulps).
SPLIT_PRODUCT_RTOL = 1e-14
#: The truncation radius is not vacuous: the largest observed error is at least 1e-3 of
#: tol (measured 0.008-0.03, so the bound is within ~100x of the truth).
BOUND_SHARPNESS_MIN = 1e-3


def flint_theta(z, tau, prec: int = 200) -> np.ndarray:
    old = ctx.prec
    ctx.prec = prec
    try:
        t = acb_mat([[acb(complex(x).real, complex(x).imag) for x in r] for r in tau])
        zz = acb_mat([[acb(complex(x).real, complex(x).imag)] for x in z])
        res = t.theta(zz)
        out = np.array([complex(res[0, i]) for i in range(res.ncols())])
        if np.all(np.isfinite(out)):
            # certified: the balls' radii are far below anything compared here
            rad = max(float(res[0, i].rad()) for i in range(res.ncols()))
            assert rad < FLINT_RADIUS_MAX * np.max(np.abs(out))
        return out
    finally:
        ctx.prec = old


# --- shapes and dtypes ------------------------------------------------------------


def test_leading_shapes_and_scalar_out():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(3, 4, 2)) + 1j * rng.normal(size=(3, 4, 2)) * 0.3
    out = theta_all(z, BENCH_TAU)
    assert out.shape == (3, 4, 16)
    for i in range(3):
        for j in range(4):
            np.testing.assert_array_equal(out[i, j], theta_all(z[i, j], BENCH_TAU))
    assert theta_all(Z0, BENCH_TAU).shape == (16,)
    one = theta(Z0, BENCH_TAU)
    assert isinstance(one, complex)
    assert theta(z, BENCH_TAU, 5).shape == (3, 4)
    assert theta(z, BENCH_TAU, 5, derivs=(0, 1)).shape == (3, 4)
    v, g, h = theta_jet(z, BENCH_TAU, "theta0")
    assert v.shape == (3, 4) and g.shape == (3, 4, 2) and h.shape == (3, 4, 2, 2)
    v, g, h = theta_jet(z, BENCH_TAU, all_chars=True)
    assert v.shape == (3, 4, 16) and g.shape == (3, 4, 16, 2) and h.shape == (3, 4, 16, 2, 2)
    assert theta_all(np.zeros((0, 2)), BENCH_TAU).shape == (0, 16)


def test_dtypes_readonly_noncontiguous_inputs_unchanged():
    big = np.zeros((5, 4), complex)
    big[:, ::2] = np.array([[0.1 + 0.2j, -0.3j]] * 5)
    z = big[:, ::2]  # non-contiguous view
    assert not z.flags["C_CONTIGUOUS"]
    tau = np.asfortranarray(BENCH_TAU.copy())
    tau.setflags(write=False)
    zc = z.copy()
    res = theta_all(z, tau)
    np.testing.assert_array_equal(res, theta_all(np.ascontiguousarray(zc), BENCH_TAU))
    np.testing.assert_array_equal(z, zc)
    # real and integer inputs are converted
    assert np.allclose(theta_all([0, 0], BENCH_TAU), theta_all([0j, 0j], BENCH_TAU), rtol=0, atol=0)
    assert np.all(np.isfinite(theta_all([[0.25, 0.5]], np.array([[1j, 0], [0, 1j]]))))


def test_genus_one_and_three_shapes():
    assert theta_all([0.1], [[1j]]).shape == (4,)
    assert theta_all([0.1], 1j).shape == (4,)  # a 0-d tau is genus 1
    tau3 = np.eye(3) * 1.2j + 0.1j * (np.ones((3, 3)) - np.eye(3))
    assert theta_all(np.zeros(3), tau3).shape == (64,)
    assert len(manakov.characteristics(3)) == 64


# --- exceptions ----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("tau", "match"),
    [
        (np.array([[1j, 0.1j], [0.2j, 1j]]), "symmetric"),
        (np.array([[1j, 2j], [2j, 1j]]), r"smallest eigenvalue is -1(\.0)?e0"),
        (np.array([[-1j, 0], [0, 1j]]), "smallest eigenvalue"),
        (np.array([[np.nan, 0], [0, 1j]]), "finite"),
        (np.array([[np.inf * 1j, 0], [0, 1j]]), "finite"),
        (np.ones((2, 3)) * 1j, "shape"),
        (np.ones((2, 2, 2)) * 1j, "shape"),
        (np.eye(7) * 1j, "genus|1..=6"),
        (np.zeros((2, 2)), "smallest eigenvalue"),
    ],
)
def test_bad_tau_raises_value_error(tau, match):
    with pytest.raises(ValueError, match=match):
        theta_all(np.zeros(tau.shape[0] if tau.ndim == 2 else 2), tau)


@pytest.mark.parametrize(
    "z",
    [
        np.array([np.nan, 0.0]),
        np.array([0.0, complex(0, np.inf)]),
        np.zeros(3),
        np.zeros((4, 1)),
        np.array(0.5),
    ],
)
def test_bad_z_raises_value_error(z):
    with pytest.raises(ValueError):
        theta_all(z, BENCH_TAU)


@pytest.mark.parametrize(
    "char",
    [16, -1, "theta99", ((0, 2), (0, 0)), ((0,), (0,)), ((0, 0, 0), (0, 0, 0)), "x", 1.5, True],
)
def test_unknown_characteristic_raises_value_error(char):
    with pytest.raises(ValueError):
        theta(Z0, BENCH_TAU, char)


@pytest.mark.parametrize("derivs", [(2,), (0, 0, 1), (-1,)])
def test_bad_derivs_raise_value_error(derivs):
    with pytest.raises(ValueError):
        theta(Z0, BENCH_TAU, derivs=derivs)


@pytest.mark.parametrize("tol", [0.0, -1e-3, 1.0, np.nan])
def test_bad_tol_raises_value_error(tol):
    with pytest.raises(ValueError):
        theta_all(Z0, BENCH_TAU, tol=tol)


def test_far_too_ill_conditioned_tau_is_refused_not_hung():
    with pytest.raises(ValueError, match="terms"):
        theta_all(Z0, np.eye(2) * 1e-9j)


def test_overflow_raises_and_log_scale_does_not():
    z = np.array([0.1 + 300j, 0.2 - 250j])
    with pytest.raises(OverflowError, match="log_scale"):
        theta_all(z, BENCH_TAU)
    om, log = theta_all(z, BENCH_TAU, log_scale=True)
    assert np.all(np.isfinite(om)) and np.isfinite(log) and log > 709
    # L = pi y^T Y^{-1} y, computed independently
    y = z.imag
    assert log == pytest.approx(np.pi * y @ np.linalg.solve(BENCH_TAU.imag, y), rel=LOG_SCALE_RTOL)
    # at moderate Im z the split product equals flint's theta
    z_small = np.array([0.1 + 3j, 0.2 - 2.5j])
    om, log = theta_all(z_small, BENCH_TAU, log_scale=True)
    ref = flint_theta(z_small, BENCH_TAU)
    assert np.max(np.abs(om * np.exp(log) - ref)) <= AGREE * np.max(np.abs(ref))


def test_overflow_in_a_large_batch():
    """Batches of >= 64 points scale inside the vectorised kernel; one overflowing
    point must still raise, and log_scale must still work."""
    z = np.zeros((100, 2), complex)
    z[:, 0] = np.linspace(0, 1, 100) + 0.1j
    z[57] = [0.1 + 300j, 0.2 - 250j]
    with pytest.raises(OverflowError, match="log_scale"):
        theta_all(z, BENCH_TAU)
    om, log = theta_all(z, BENCH_TAU, log_scale=True)
    assert np.all(np.isfinite(om)) and log.shape == (100,) and log[57] > 709
    ok = np.delete(np.arange(100), 57)
    np.testing.assert_allclose(
        theta_all(z[ok], BENCH_TAU),
        om[ok] * np.exp(log[ok])[:, None],
        rtol=SPLIT_PRODUCT_RTOL,
        atol=0,
    )


def test_parallel_batches_equal_serial_and_errors_propagate():
    """Batches of >= 4096 points are split over threads: every point is computed by
    the same code, so the results must be bitwise equal to the one-core run, and a bad
    point in a late chunk must still raise (values, derivatives, log_scale)."""
    rng = np.random.default_rng(7)
    z = rng.uniform(0, 1, (5000, 2)) + 1j * rng.uniform(-2, 2, (5000, 2))
    for kwargs in ({}, {"log_scale": True}):
        par = theta_all(z, BENCH_TAU, **kwargs)
        ser = theta_all(z, BENCH_TAU, parallel=False, **kwargs)
        for p, s in zip(par if kwargs else [par], ser if kwargs else [ser]):
            assert np.array_equal(p, s)
    jp = theta_jet(z, BENCH_TAU, all_chars=True)
    js = theta_jet(z, BENCH_TAU, all_chars=True, parallel=False)
    for p, s in zip(jp, js):
        assert np.array_equal(p, s)
    bad = z.copy()
    bad[4900, 1] = np.nan
    with pytest.raises(ValueError, match="z"):
        theta_all(bad, BENCH_TAU)
    with pytest.raises(ValueError, match="z"):
        theta(bad, BENCH_TAU, derivs=(0,))
    big = z.copy()
    big[4999] = [0.1 + 300j, 0.2 - 250j]
    with pytest.raises(OverflowError, match="log_scale"):
        theta_all(big, BENCH_TAU)


def test_value_error_not_panic_for_huge_imag_z():
    with pytest.raises(ValueError):
        theta_all(np.array([0.0, 1e300j]), BENCH_TAU, log_scale=True)


# --- the proven truncation bound against flint ------------------------------------


def normalised_flint(z, tau):
    y = np.asarray(z).imag
    log = np.pi * y @ np.linalg.solve(tau.imag, y)
    return flint_theta(z, tau) * np.exp(-log)


#: Rounding error of the sum itself (about 1e-16 of the sum of |terms| <= ~4);
#: added to tol when checking the truncation bound.
ROUNDING = 1e-15


@pytest.mark.parametrize("tol", [1e-3, 1e-6, 1e-9, 1e-12])
def test_truncation_error_within_tol_against_flint(tol):
    """Points in the fundamental cell (no z reduction), reduced and skewed tau:
    |Omega - Omega_flint| <= tol (+ rounding) for every characteristic. The
    largest observed error is also reported to show the bound is not vacuous."""
    rng = np.random.default_rng(int(-np.log10(tol)))
    worst_ratio = 0.0
    checked = 0
    for k in range(30):
        q, _ = np.linalg.qr(rng.normal(size=(2, 2)))
        y = q @ np.diag(rng.uniform(0.5, 2.0, 2)) @ q.T
        x = rng.uniform(-0.5, 0.5, (2, 2))
        tau = (x + x.T) / 2 + 1j * (y + y.T) / 2
        if k % 3 == 0:
            u = np.array([[1, 1], [0, 1]]) if k % 2 else np.array([[2, 1], [1, 1]])
            tau = u @ tau @ u.T
        z = rng.uniform(-0.5, 0.5, 2) + tau.imag @ rng.uniform(-0.45, 0.45, 2) * 1j
        om, _ = theta_all(z, tau, tol=tol, log_scale=True)
        radius, rho, bound, _, _ = _core.theta_plan_info(np.ascontiguousarray(tau), tol, 0)
        assert bound <= tol
        ref = normalised_flint(z, tau)
        if not np.all(np.isfinite(ref)):
            continue  # python-flint 0.9 returns indeterminate balls for some skewed tau
        checked += 1
        err = np.max(np.abs(om - ref))
        assert err <= tol + ROUNDING
        worst_ratio = max(worst_ratio, err / tol)
    assert checked >= 20
    # the radius is not so generous that nothing is ever truncated
    if tol >= 1e-9:
        assert worst_ratio > BOUND_SHARPNESS_MIN


def test_derivative_truncation_within_tol():
    """order 2 plans bound the gradient and Hessian truncation too; compared with a
    converged default-tol jet (itself checked against flint in test_theta.py)."""
    rng = np.random.default_rng(3)
    for tol in (1e-4, 1e-8):
        z = rng.uniform(-0.5, 0.5, 2) + 1j * BENCH_TAU.imag @ rng.uniform(-0.4, 0.4, 2)
        v, g, h, _ = theta_jet(z, BENCH_TAU, all_chars=True, tol=tol, log_scale=True)
        v0, g0, h0, _ = theta_jet(z, BENCH_TAU, all_chars=True, log_scale=True)
        for a, b in ((v, v0), (g, g0), (h, h0)):
            assert np.max(np.abs(a - b)) <= tol + AGREE


# --- fuzzing the API with bad and unusual inputs -----------------------------------------


@pytest.mark.parametrize("lead", [(0,), (3, 0), (0, 4)])
def test_zero_size_batches_behave_like_numpy(lead):
    z = np.zeros(lead + (2,), complex)
    assert theta_all(z, BENCH_TAU).shape == lead + (16,)
    om, log = theta_all(z, BENCH_TAU, log_scale=True)
    assert om.shape == lead + (16,) and log.shape == lead
    assert theta(z, BENCH_TAU, 3).shape == lead
    assert theta(z, BENCH_TAU, 3, derivs=(0, 1)).shape == lead
    v, g, h = theta_jet(z, BENCH_TAU)
    assert v.shape == lead and g.shape == lead + (2,) and h.shape == lead + (2, 2)
    v, g, h = theta_jet(z, BENCH_TAU, all_chars=True)
    assert v.shape == lead + (16,) and g.shape == lead + (16, 2) and h.shape == lead + (16, 2, 2)


@pytest.mark.parametrize("fn", [theta, theta_all, theta_jet])
def test_genus_zero_is_a_clear_value_error(fn):
    with pytest.raises(ValueError, match="genus"):
        fn(np.zeros(0), np.zeros((0, 0)))
    with pytest.raises(ValueError, match="genus"):
        fn(np.zeros((3, 0)), np.zeros((0, 0)))


@pytest.mark.parametrize("g", [7, 31, 32, 40, 70])
def test_large_genus_is_refused_before_allocating(g):
    """The binding computed 4^g = 1 << 2g before the genus was checked: a shift overflow
    (masked in release builds: 4^31 -> 2^62 entries) for g >= 32."""
    with pytest.raises(ValueError, match="genus"):
        theta_all(np.zeros((2, g)), 1j * np.eye(g))
    with pytest.raises(ValueError, match="genus"):
        _core.theta_jet(np.zeros((2, g), complex), 1j * np.eye(g), 1e-15, 0, True, False)


@pytest.mark.parametrize("z", [np.array(["a", "b"]), [object(), 1.0], {"a": 1}])
def test_non_numeric_z_or_tau_is_a_clear_value_error(z):
    with pytest.raises(ValueError, match="z must be numeric"):
        theta_all(z, BENCH_TAU)
    with pytest.raises(ValueError, match="tau must be numeric"):
        theta_all(Z0, np.array([["a", "b"], ["c", "d"]]))


@pytest.mark.parametrize("shift", [8.0, 2.0**60, 1e20, 1e300, -1e300])
def test_huge_real_tau_reduces_exactly(shift):
    """theta[a;b](z, tau + 8K) = theta[a;b](z, tau) for integer K: the series only sees
    Re tau through exp(i pi m^T Re tau m) with m in Z^g/2. Entries of Re tau beyond the
    int64 range (|Re tau| >= 2^63) once saturated in the reduction Re tau = Re tau' + 2S and
    gave O(1) wrong values silently. Every shift here is a multiple of 8 as a double, and
    Re tau = shift exactly when tau = 1j Im tau + shift."""
    assert float(np.fmod(shift, 8.0)) == 0.0
    tau0 = 1j * BENCH_TAU.imag
    tau = tau0 + shift
    assert np.all(tau.real == shift)  # the shift is exact in the input
    np.testing.assert_allclose(
        theta_all(Z0, tau),
        theta_all(Z0, tau0),
        rtol=0,
        atol=AGREE * np.max(np.abs(theta_all(Z0, tau0))),
    )


def test_positive_definite_im_tau_beyond_the_factorisable_range_is_explained():
    """Im tau = 1e300 * BENCH_TAU.imag is positive definite, but its factorisation overflows;
    the message must not claim it is not positive definite."""
    with pytest.raises(ValueError) as info:
        theta_all(Z0, 1j * 1e300 * BENCH_TAU.imag)
    assert "must be positive definite" not in str(info.value)
    assert "factoris" in str(info.value)


@pytest.mark.parametrize("tol", ["a", 1j, None, np.array([1e-3, 1e-4])])
def test_tol_of_the_wrong_kind_is_an_exception_not_a_crash(tol):
    with pytest.raises((TypeError, ValueError), match="tol"):
        theta_all(Z0, BENCH_TAU, tol=tol)


@pytest.mark.parametrize("tol", [1e-300, 5e-324])
def test_tiny_tol_terminates_with_values_at_the_default_accuracy(tol):
    """The radius grows like sqrt(log(1/tol)): even the smallest double is a finite plan."""
    ref = theta_all(Z0, BENCH_TAU)
    np.testing.assert_allclose(
        theta_all(Z0, BENCH_TAU, tol=tol), ref, rtol=0, atol=AGREE * np.max(np.abs(ref))
    )


@pytest.mark.parametrize(
    "z",
    [
        np.array([0.1, 0.2], dtype=np.float32),
        np.array([0.1 + 0.2j, 0.3j], dtype=np.complex64),
        np.array([1, 0], dtype=np.int8),
        np.array([True, False]),
        [0.1, 0.2],
        (0.1, 0.2),
    ],
)
def test_any_numeric_dtype_or_sequence_equals_complex128(z):
    want = theta_all(np.asarray(z).astype(np.complex128), BENCH_TAU)
    np.testing.assert_array_equal(theta_all(z, BENCH_TAU), want)
    assert theta_all(z, BENCH_TAU).dtype == np.complex128


def test_fuzzed_bad_inputs_never_warn_or_return_nan():
    """Each combination either raises ValueError/OverflowError or returns finite values
    (pytest turns warnings into errors)."""
    rng = np.random.default_rng(12)
    specials = [np.nan, np.inf, -np.inf, 1e308, -1e308, 1e-308, 0.0, 1e16, 4.6e15]
    for _ in range(300):
        z = rng.normal(size=2) + 1j * rng.normal(size=2)
        tau = BENCH_TAU.copy()
        for _ in range(rng.integers(1, 3)):
            v = specials[rng.integers(len(specials))]
            if rng.integers(2):
                z[rng.integers(2)] = v * (1j if rng.integers(2) else 1)
            else:
                i, k = rng.integers(2), rng.integers(2)
                tau[i, k] = tau[k, i] = tau[i, k] + v * (1j if rng.integers(2) else 1)
        for log_scale in (False, True):
            try:
                out = theta_all(z, tau, log_scale=log_scale)
            except (ValueError, OverflowError) as exc:
                assert str(exc)
                continue
            vals = out[0] if log_scale else out
            assert np.all(np.isfinite(vals)), (z, tau)


@pytest.mark.parametrize("derivs", [1, (0.5,), ("0",), None])
def test_derivs_of_the_wrong_type_name_the_argument(derivs):
    with pytest.raises(TypeError, match="derivs must be a sequence of integers"):
        theta(Z0, BENCH_TAU, derivs=derivs)
