"""The curve (8), the Wurzelfunktionen (27)-(28), identities (29)-(33), inverse of (37).

Reference values come from an independent numpy implementation of (27)-(28)
*as printed* (written here, not calling the package) and from mpmath at 40
digits. Each identity of the paper is checked as printed; (29) fails as
printed and is checked in its corrected form (docs/errata.md).
"""

from __future__ import annotations

import itertools

import mpmath
import numpy as np
import pytest

import manakov
from manakov import KotterCurve

CYCLIC = ((1, 2, 3), (2, 3, 1), (3, 1, 2))

#: Elementwise quantities (R, y, c_j, P_j**2, prod P_j) computed by the package
#: and by numpy with the same few (<= 10) rounded operations on O(1) numbers:
#: agreement to a few tens of ulps.
ROUNDING_RTOL = 1e-14

#: Same, for products of ~10 factors each carrying a few ulps (P_j**2, prod P_j, y**2).
PRODUCT_RTOL = 1e-13

#: Failure margin: a misprinted identity misses by an O(1) factor (for (29) the
#: factor kappa); 1e-3 is far above rounding and far below the misprint.
MISPRINT_MARGIN = 1e-3

#: Package vs the independent numpy evaluation of (27)-(28) as printed,
#: relative to the size of the terms of (28): both are a few dozen rounded
#: operations on O(1) numbers, and the printed form divides by z - d_j for
#: points kept >= 0.05 away from the branch points (amplification <= ~1e2).
NUMPY_RTOL = 1e-12

#: Package vs mpmath at 40 digits: the package's own rounding only (the
#: division-free form of (28) has no cancellation for separated points).
MPMATH_RTOL = 1e-13

#: An identity evaluated in mpmath at 40 digits holds to this relative
#: accuracy if it is exact (a misprint gives an O(1) discrepancy).
EXACT_RTOL = 1e-30

#: Identities evaluated on the package's double-precision P, P_jk, relative to
#: the sum of the moduli of their terms (~20 rounded factors per term, and the
#: cancellation in P_jk for separated points is <= ~1e2).
IDENTITY_RTOL = 1e-11

#: Backward error of the inverse map: recovered points reproduce (xi, eta) to
#: this fraction of max|(xi, eta)| (a few rounding errors after the
#: Gauss-Newton polish; worst seen in the Rust stats run: 9.4e-15).
BACKWARD_RTOL = 1e-13

#: Forward error of the round trip in units of the first-order bound
#: u * |(xi, eta)| / sigma_min(J), J the Jacobian of (z1, z2, g) -> (xi, eta):
#: the inverse is as accurate as the map's conditioning allows (worst ratio
#: seen over 100 000 random draws in the Rust stats run: 18, 29 in an earlier
#: run). In absolute terms that is a median error of 2e-15 and 99 % below 3e-13.
STABILITY_FACTOR = 100.0

#: The ~1e-12 round trip in absolute terms, for the seeded cases of
#: test_inverse_round_trip (99 % of random draws are below 3e-13; the tail is
#: governed by STABILITY_FACTOR, not by this number).
ROUNDTRIP_SEEDED_RTOL = 1e-12

#: Round trips of single, well-separated example pairs (|z1 - z2| >= 1, O(1)
#: values): the inverse reproduces them to ~1e-15; 1e-12 is the claim.
EXAMPLE_RTOL = 1e-12
# Points 1e-3 apart recovered from their Wurzelfunktionen: (28) divides by z1 - z2
# (rounding ~u/delta in the data) and the inverse amplifies by ~1/delta, ~1e-10; 1e-8
# leaves a factor 100 for the constants.
CLOSE_PAIR_TOL = 1e-8
# Machine epsilon (2^-52 = 2.22e-16, written rounded down) in the first-order forward
# error bound eps |F| sqrt(6) / sigma_min(J) of the inverse map.
EPS_DOUBLE = 2.2e-16
# The forward error may exceed that first-order bound by the constant of the backward
# error (a few units of rounding): a factor 10.
FORWARD_BOUND_FACTOR = 10


# ----------------------------------------------------------------------------
# Independent numpy implementation (does not call the package).
# ----------------------------------------------------------------------------


def np_branch_points(d1, d2, d3):
    return np.array([0, d1, d2, d3, d1 * d2 * d3], dtype=complex)


def np_sqrt(w):
    """Principal root with Im(w) = -0.0 mapped to +0.0 (one side of the cut)."""
    w = np.asarray(w, dtype=complex)
    return np.sqrt(w.real + 1j * (w.imag + 0.0))


def np_y(d, z):
    return np.prod([np_sqrt(z - dj) for dj in d], axis=0)


def np_wurzel(d, z1, y1, z2, y2, eps=(1, 1, 1, 1, 1)):
    """(27)-(28) as printed. P_j = eps_j r_j(z1) r_j(z2) with r_j principal for
    j < 4 and r_4 = y/(r_0 r_1 r_2 r_3) (valid off the branch points)."""
    r1 = [np_sqrt(z1 - d[j]) for j in range(4)]
    r2 = [np_sqrt(z2 - d[j]) for j in range(4)]
    r1.append(y1 / (r1[0] * r1[1] * r1[2] * r1[3]))
    r2.append(y2 / (r2[0] * r2[1] * r2[2] * r2[3]))
    P = np.array([eps[j] * r1[j] * r2[j] for j in range(5)])
    Pjk = np.zeros((5, 5), dtype=complex)
    for j in range(5):
        for k in range(5):
            if j != k:
                Pjk[j, k] = (
                    P[j]
                    * P[k]
                    / (z1 - z2)
                    * (y1 / ((z1 - d[j]) * (z1 - d[k])) - y2 / ((z2 - d[j]) * (z2 - d[k])))
                )
    return P, Pjk


def c_lists(d):
    """c_j, c~_j (33) as lists (element type kept: complex or mpmath.mpc)."""
    ct = [1 / ((d[j] - d[k]) * (d[j] - d[m])) for j, k, m in CYCLIC]
    c = [(d[j] - d[4]) * ct[i] for i, (j, _, _) in enumerate(CYCLIC)]
    return c, ct


def np_c(d):
    c, ct = c_lists(d)
    return np.array(c, dtype=complex), np.array(ct, dtype=complex)


def all_eps():
    """The 16 sign vectors with product +1."""
    out = []
    for e in itertools.product((1, -1), repeat=4):
        out.append((int(np.prod(e)), *e))
    return out


def rand_c(rng, lo, hi, size=None):
    return rng.uniform(lo, hi, size) + 1j * rng.uniform(lo, hi, size)


def random_setup(rng, *, sep=0.1, bp_dist=0.05):
    """A curve with separated branch points and a pair of points on it."""
    while True:
        d1, d2, d3 = rand_c(rng, -2, 2, 3)
        d = np_branch_points(d1, d2, d3)
        if min(abs(a - b) for a, b in itertools.combinations(d, 2)) < sep:
            continue
        z1, z2 = rand_c(rng, -3, 3, 2)
        if abs(z1 - z2) < sep or min(abs(z1 - d)) < bp_dist or min(abs(z2 - d)) < bp_dist:
            continue
        y1 = np_y(d, z1) * rng.choice([1, -1])
        y2 = np_y(d, z2) * rng.choice([1, -1])
        return (d1, d2, d3), d, (z1, y1, z2, y2)


# ----------------------------------------------------------------------------
# The curve (8)
# ----------------------------------------------------------------------------


def test_branch_points_and_R():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    d = np_branch_points(2.0, 3.0, -0.5 + 1j)
    np.testing.assert_array_equal(k.branch_points, d)
    assert k.d == (2.0, 3.0, -0.5 + 1j)
    x = np.array([0.3 - 0.7j, 5.0, -2.0 + 1j])
    np.testing.assert_allclose(k.R(x), np.prod([x - dj for dj in d], axis=0), rtol=ROUNDING_RTOL)
    for dj in d:
        assert k.R(dj) == 0
    # y is a square root of R on both sheets, equal to the product of principal roots.
    np.testing.assert_allclose(k.y(x) ** 2, k.R(x), rtol=PRODUCT_RTOL)
    np.testing.assert_allclose(k.y(x), np_y(d, x), rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(k.y(x, sheet=-1), -np_y(d, x), rtol=ROUNDING_RTOL)
    assert isinstance(k.R(0.5), complex)
    assert np.shape(k.y(0.5)) == ()


def test_constants_33():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    d = np_branch_points(2.0, 3.0, -0.5 + 1j)
    c, ct = np_c(d)
    np.testing.assert_allclose(k.c, c, rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(k.c_tilde, ct, rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(k.kappa, np.prod(d[1:4] - d[4]), rtol=ROUNDING_RTOL)


@pytest.mark.parametrize(
    ("d", "pair"),
    [
        ((0.0, 2.0, 3.0), "d0 and d1"),
        ((2.0, 0.0, 3.0), "d0 and d2"),
        ((2.0, 3.0, 2.0), "d1 and d3"),
        ((1.5 + 1j, 1.5 + 1j, 3.0), "d1 and d2"),
        ((7.0, 3.0, 1 / 3), "d1 and d4"),  # d2 d3 = 1: d4 = d1
        ((0.5, 2.0, 1.0), "d2 and d4"),  # d1 d3 = 0.5: d4 = d2 ... d1 d2 d3 = 1.0
    ],
)
def test_repeated_branch_points(d, pair):
    if pair == "d2 and d4":
        # d4 = 0.5 * 2 * 1 = 1.0 = d3, not d2: name the actual coincidence.
        pair = "d3 and d4"
    with pytest.raises(ValueError, match=pair):
        KotterCurve(*d)


@pytest.mark.parametrize("bad", [np.nan, np.inf, complex(0, np.nan)])
def test_non_finite_branch_points(bad):
    with pytest.raises(ValueError, match="finite"):
        KotterCurve(1.0, bad, 3.0)


def test_curve_is_frozen_and_comparable():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    with pytest.raises(ValueError):
        k.branch_points[0] = 1.0
    with pytest.raises(AttributeError):
        k.foo = 1  # type: ignore[attr-defined]
    assert k == KotterCurve(2.0, 3.0, -0.5 + 1j)
    assert k != KotterCurve(2.0, 3.0, -0.5 + 2j)
    assert "KotterCurve" in repr(k)


# ----------------------------------------------------------------------------
# Wurzelfunktionen (27)-(28) and the sign convention
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(40))
def test_wurzel_matches_printed_27_28(seed):
    rng = np.random.default_rng(seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng)
    k = KotterCurve(*dd)
    eps = all_eps()[seed % 16]
    w = k.wurzel(z1, y1, z2, y2, eps=eps)
    P, Pjk = np_wurzel(d, z1, y1, z2, y2, eps)
    np.testing.assert_allclose(w.P, P, rtol=NUMPY_RTOL, atol=0)
    for j in range(5):
        for m in range(5):
            if j == m:
                assert w.Pjk[j, m] == 0
                continue
            scale = abs(P[j] * P[m] / (z1 - z2)) * (
                abs(y1 / ((z1 - d[j]) * (z1 - d[m]))) + abs(y2 / ((z2 - d[j]) * (z2 - d[m])))
            )
            assert abs(w.Pjk[j, m] - Pjk[j, m]) <= NUMPY_RTOL * scale
    np.testing.assert_array_equal(w.Pjk, w.Pjk.T)


@pytest.mark.parametrize("seed", range(40))
def test_sign_convention_27(seed):
    """P_j**2 = (z1 - d_j)(z2 - d_j) and prod_j P_j = y1 y2 in every branch eps."""
    rng = np.random.default_rng(1000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng, bp_dist=0.0)
    k = KotterCurve(*dd)
    for eps in all_eps():
        P = k.wurzel(z1, y1, z2, y2, eps=eps).P
        np.testing.assert_allclose(P**2, (z1 - d) * (z2 - d), rtol=PRODUCT_RTOL)
        np.testing.assert_allclose(np.prod(P), y1 * y2, rtol=PRODUCT_RTOL)
    # Default branch: P_j = sqrt(z1 - d_j) sqrt(z2 - d_j) (principal) for j < 4.
    P = k.wurzel(z1, y1, z2, y2).P
    np.testing.assert_allclose(P[:4], np_sqrt(z1 - d[:4]) * np_sqrt(z2 - d[:4]), rtol=ROUNDING_RTOL)


def test_wurzel_mpmath():
    mpmath.mp.dps = 40
    rng = np.random.default_rng(7)
    for _ in range(5):
        dd, d, (z1, y1, z2, y2) = random_setup(rng)
        k = KotterCurve(*dd)
        w = k.wurzel(z1, y1, z2, y2)
        D = [mpmath.mpc(x) for x in d]
        Z1, Z2 = mpmath.mpc(z1), mpmath.mpc(z2)
        # mpmath roots with the same branch: principal for j < 4, r_4 fixed by y.
        Y1 = mpmath.sqrt(mpmath.fprod(Z1 - x for x in D))
        Y2 = mpmath.sqrt(mpmath.fprod(Z2 - x for x in D))
        Y1 = Y1 if abs(Y1 - y1) < abs(Y1 + y1) else -Y1
        Y2 = Y2 if abs(Y2 - y2) < abs(Y2 + y2) else -Y2
        r1 = [mpmath.sqrt(Z1 - D[j]) for j in range(4)]
        r2 = [mpmath.sqrt(Z2 - D[j]) for j in range(4)]
        r1.append(Y1 / mpmath.fprod(r1))
        r2.append(Y2 / mpmath.fprod(r2))
        P = [r1[j] * r2[j] for j in range(5)]
        for j in range(5):
            assert abs(complex(P[j]) - w.P[j]) <= MPMATH_RTOL * abs(complex(P[j]))
            for m in range(j + 1, 5):
                v = (
                    P[j]
                    * P[m]
                    / (Z1 - Z2)
                    * (Y1 / ((Z1 - D[j]) * (Z1 - D[m])) - Y2 / ((Z2 - D[j]) * (Z2 - D[m])))
                )
                assert abs(complex(v) - w.Pjk[j, m]) <= MPMATH_RTOL * max(abs(complex(v)), 1.0)


def test_wurzel_at_branch_point_is_the_limit_of_28():
    """(28) as printed is 0/0 at z1 = d_j; the package returns the limit."""
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    d = k.branch_points
    z2 = -1.0 + 0.5j
    y2 = k.y(z2)
    w = k.wurzel(d[2], 0.0, z2, y2)
    assert np.all(np.isfinite(w.Pjk))
    assert w.P[2] == 0
    # Approach the branch point along z1 = d_2 + t on the canonical sheet.
    for t in (1e-4, 1e-6):
        z1 = d[2] + t * (0.6 + 0.8j)
        wt = k.wurzel(z1, k.y(z1), z2, y2)
        # P_jk is analytic in the local parameter sqrt(z1 - d_2): O(sqrt t) convergence,
        # up to the sign flips of the P_j that contain r_2 (j = 2 or k = 2).
        err = np.abs(np.abs(wt.Pjk) - np.abs(w.Pjk)).max()
        assert err <= 50 * np.sqrt(t) * np.abs(w.Pjk).max()


# ----------------------------------------------------------------------------
# Identities (29)-(33)
# ----------------------------------------------------------------------------


def lhs_29(d, c, Pjk, s):
    terms = []
    for i, (j, k, m) in enumerate(CYCLIC):
        terms.append(c[i] * Pjk[k, m] ** 2 / ((s - d[k]) * (s - d[m])))
        terms.append(c[i] * Pjk[j, 4] ** 2 / ((s - d[j]) * (s - d[4])))
    return sum(terms), sum(abs(t) for t in terms)


def identities(d, P, Pjk):
    """(value, expected, scale) of (30a), (30b), (31a), (31b), (32) as printed."""
    c, ct = c_lists(d)
    rows = {
        "30a": ([ct[i] * Pjk[j, 4] ** 2 for i, (j, k, m) in enumerate(CYCLIC)], d[4]),
        "30b": ([d[j] * ct[i] * Pjk[k, m] ** 2 for i, (j, k, m) in enumerate(CYCLIC)], P[0] ** 2),
        "31a": ([c[i] * Pjk[j, 4] * Pjk[k, m] for i, (j, k, m) in enumerate(CYCLIC)], 0.0),
        "31b": ([ct[i] * Pjk[j, 4] * Pjk[k, m] for i, (j, k, m) in enumerate(CYCLIC)], -P[0]),
        "32": (
            [
                c[i] * (Pjk[j, 4] ** 2 / d[j] + d[j] * Pjk[k, m] ** 2)
                for i, (j, k, m) in enumerate(CYCLIC)
            ],
            0.0,
        ),
    }
    return {
        name: (sum(terms), expected, sum(abs(t) for t in terms) + abs(expected))
        for name, (terms, expected) in rows.items()
    }


@pytest.mark.parametrize("seed", range(30))
def test_identities_30_to_33_as_printed(seed):
    rng = np.random.default_rng(2000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng, bp_dist=0.0)
    k = KotterCurve(*dd)
    for eps in all_eps():
        w = k.wurzel(z1, y1, z2, y2, eps=eps)
        for name, (v, expected, scale) in identities(d, w.P, w.Pjk).items():
            assert abs(v - expected) <= IDENTITY_RTOL * scale, (name, v, expected)


@pytest.mark.parametrize("seed", range(30))
def test_identity_29_printed_fails_corrected_holds(seed):
    """(29) as printed, RHS = s/prod_{j=1}^4 (s - d_j), is off by the constant
    kappa = prod_{m=1}^3 (d_m - d_4); corrected, it holds for every pair and s."""
    rng = np.random.default_rng(3000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng, bp_dist=0.0)
    k = KotterCurve(*dd)
    c, _ = np_c(d)
    kappa = np.prod(d[1:4] - d[4])
    w = k.wurzel(z1, y1, z2, y2, eps=all_eps()[seed % 16])
    for s in rand_c(rng, -3, 3, 4):
        lhs, scale = lhs_29(d, c, w.Pjk, s)
        printed = s / np.prod(s - d[1:5])
        assert abs(lhs - printed) > MISPRINT_MARGIN * abs(printed)  # the printed form fails ...
        assert abs(lhs - kappa * printed) <= IDENTITY_RTOL * scale  # ... the corrected holds


def test_identities_exact_in_mpmath():
    """At 40 digits the identities hold to 1e-30: exact, not approximate. The
    printed (29) misses by an O(1) factor, the corrected one holds exactly."""
    mpmath.mp.dps = 40
    rng = np.random.default_rng(11)
    for _ in range(4):
        dd, d, (z1, y1, z2, y2) = random_setup(rng)
        D = [mpmath.mpc(x) for x in d]
        # d_4 = d_1 d_2 d_3 exactly: (32) holds only on the curve (8), not for
        # five arbitrary branch points (the double-rounded d_4 misses by 1e-15).
        D[4] = D[1] * D[2] * D[3]
        Z1, Z2 = mpmath.mpc(z1), mpmath.mpc(z2)
        Y1 = mpmath.fprod(mpmath.sqrt(Z1 - x) for x in D) * (1 if y1 == np_y(d, z1) else -1)
        Y2 = mpmath.fprod(mpmath.sqrt(Z2 - x) for x in D) * (1 if y2 == np_y(d, z2) else -1)
        r1 = [mpmath.sqrt(Z1 - D[j]) for j in range(4)]
        r2 = [mpmath.sqrt(Z2 - D[j]) for j in range(4)]
        r1.append(Y1 / mpmath.fprod(r1))
        r2.append(Y2 / mpmath.fprod(r2))
        P = [r1[j] * r2[j] for j in range(5)]
        Pjk = mpmath.matrix(5, 5)
        for j in range(5):
            for m in range(5):
                if j != m:
                    Pjk[j, m] = (
                        P[j]
                        * P[m]
                        / (Z1 - Z2)
                        * (Y1 / ((Z1 - D[j]) * (Z1 - D[m])) - Y2 / ((Z2 - D[j]) * (Z2 - D[m])))
                    )
        ct = [1 / ((D[j] - D[k]) * (D[j] - D[m])) for j, k, m in CYCLIC]
        c = [(D[j] - D[4]) * ct[i] for i, (j, _, _) in enumerate(CYCLIC)]
        for name, (v, expected, scale) in identities(D, P, Pjk).items():
            assert abs(v - expected) <= EXACT_RTOL * scale, name
        kappa = (D[1] - D[4]) * (D[2] - D[4]) * (D[3] - D[4])
        s = mpmath.mpc(0.37, -0.81)
        lhs, scale = lhs_29(D, c, Pjk, s)
        printed = s / mpmath.fprod(s - D[j] for j in range(1, 5))
        assert abs(lhs - printed) > MISPRINT_MARGIN * abs(printed)
        assert abs(lhs - kappa * printed) <= EXACT_RTOL * scale
        # The identities behind the inverse map.
        sum_ct = sum(ct[i] * Pjk[k, m] ** 2 for i, (j, k, m) in enumerate(CYCLIC))
        assert abs(sum_ct - (Z1 + Z2 - D[4])) <= EXACT_RTOL * (abs(sum_ct) + abs(Z1) + abs(Z2) + 1)
        sum_c = sum(c[i] * Pjk[k, m] ** 2 for i, (j, k, m) in enumerate(CYCLIC))
        assert abs(sum_c - P[4] ** 2) <= EXACT_RTOL * (abs(sum_c) + abs(P[4] ** 2))


def test_31b_encodes_the_product_convention():
    """With prod P_j = -y1 y2 (one P_j flipped) (31b) fails: the sign convention
    prod_j P_j = y1 y2 is the one under which (31b) holds as printed."""
    rng = np.random.default_rng(5)
    dd, d, (z1, y1, z2, y2) = random_setup(rng)
    P, Pjk = np_wurzel(d, z1, y1, z2, y2, eps=(-1, 1, 1, 1, 1))  # product -1
    v, expected, scale = identities(d, P, Pjk)["31b"]
    assert abs(v + expected) <= IDENTITY_RTOL * scale  # = +P_0 instead of -P_0
    assert abs(v - expected) > 0.1 * abs(expected)


# ----------------------------------------------------------------------------
# The inverse of (37)
# ----------------------------------------------------------------------------


def np_xi_eta(d, z1, y1, z2, y2, g, eps=(1, 1, 1, 1, 1)):
    """(37) with the printed (27)-(28) and principal sqrt(c_j)."""
    _, Pjk = np_wurzel(d, z1, y1, z2, y2, eps)
    c, _ = np_c(d)
    sc = np_sqrt(c)
    xi = np.array([sc[i] * g * Pjk[k, m] for i, (j, k, m) in enumerate(CYCLIC)])
    eta = np.array([sc[i] * g * Pjk[j, 4] for i, (j, k, m) in enumerate(CYCLIC)])
    return xi, eta


def np_error_bound(d, z1, y1, z2, y2, g, eps):
    """First-order error bound of the inverse, u |data| sqrt(6) / sigma_min(J),
    with J by central differences of the independent np_xi_eta (y continued to
    the nearer sheet); returned for (z, y1, y2)."""

    def near(y, yref):
        return y if abs(y - yref) <= abs(y + yref) else -y

    def data(a, b, gg):
        xi, eta = np_xi_eta(d, a, near(np_y(d, a), y1), b, near(np_y(d, b), y2), gg, eps)
        return np.concatenate([xi, eta])

    f0 = data(z1, z2, g)
    h = 1e-6 * min(abs(z1 - z2), 1.0)
    J = np.stack(
        [
            (data(z1 + h, z2, g) - data(z1 - h, z2, g)) / (2 * h),
            (data(z1, z2 + h, g) - data(z1, z2 - h, g)) / (2 * h),
            f0 / g,
        ],
        axis=1,
    )
    smin = np.linalg.svd(J, compute_uv=False).min()
    dz = np.finfo(float).eps * np.abs(f0).max() * np.sqrt(6) / smin
    dy = [abs(y * np.sum(1 / (z - d)) / 2) * dz for z, y in ((z1, y1), (z2, y2))]
    return dz, dy[0], dy[1]


@pytest.mark.parametrize("seed", range(60))
def test_inverse_round_trip(seed):
    rng = np.random.default_rng(4000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng)
    k = KotterCurve(*dd)
    g = rand_c(rng, -2, 2)
    eps = all_eps()[seed % 16]
    xi, eta = np_xi_eta(d, z1, y1, z2, y2, g, eps)
    back = k.points_from_wurzel(xi, eta, g_ref=g)
    # Backward error: the recovered data reproduce (xi, eta) (independent numpy evaluation).
    xb, eb = np_xi_eta(d, back.z1, back.y1, back.z2, back.y2, back.g, back.eps)
    scale = max(np.abs(xi).max(), np.abs(eta).max())
    # (np_xi_eta evaluates the printed (28), which adds its own rounding: NUMPY_RTOL.)
    assert np.abs(np.concatenate([xb - xi, eb - eta])).max() <= NUMPY_RTOL * scale
    assert back.residual <= BACKWARD_RTOL * scale
    # Forward error, against the conditioning of the map.
    if abs(back.z1 - z1) > abs(back.z1 - z2):
        bz1, by1, bz2, by2 = back.z2, back.y2, back.z1, back.y1
    else:
        bz1, by1, bz2, by2 = back.z1, back.y1, back.z2, back.y2
    bound = np_error_bound(d, z1, y1, z2, y2, g, eps)
    assert abs(bz1 - z1) <= STABILITY_FACTOR * bound[0]
    assert abs(bz2 - z2) <= STABILITY_FACTOR * bound[0]
    assert abs(by1 - y1) <= STABILITY_FACTOR * bound[1]
    assert abs(by2 - y2) <= STABILITY_FACTOR * bound[2]
    assert abs(back.g - g) <= STABILITY_FACTOR * bound[0]
    # For these seeded cases that is the ~1e-12 claim in absolute terms.
    assert max(abs(bz1 - z1), abs(bz2 - z2)) <= ROUNDTRIP_SEEDED_RTOL * max(abs(z1), abs(z2), 1)
    # eps has product +1 and eps_4 = +1.
    assert np.prod(back.eps) == 1 and back.eps[4] == 1


def test_inverse_conditioning():
    """The forward accuracy of the inverse is limited by the conditioning of the
    map (z1, z2, g) -> (xi, eta): the error stays within a small multiple of
    the first-order bound u * max|data| / sigma_min(J), J from mpmath."""
    mpmath.mp.dps = 30
    # A close pair where the closed form alone lost ~1e3 (see docs/curve.md).
    dd = (1.029627572199283 - 1.3311031225677727j, 0.7022816292886392, 1.5832645368274945)
    z1, z2 = -1.224239410265079 + 1.6897892468994373j, -1.4507124128772808 + 1.9677591098918146j
    g = -1.3603481117180565
    d = np_branch_points(*dd)
    k = KotterCurve(*dd)
    y1, y2 = -np_y(d, z1), np_y(d, z2)
    xi, eta = np_xi_eta(d, z1, y1, z2, y2, g)
    back = k.points_from_wurzel(xi, eta, g_ref=g)
    D = [mpmath.mpc(x) for x in d]
    c = [(D[j] - D[4]) / ((D[j] - D[kk]) * (D[j] - D[ll])) for j, kk, ll in CYCLIC]

    def fwd(Z1, Z2, G):
        r1 = [mpmath.sqrt(Z1 - x) for x in D]
        r2 = [mpmath.sqrt(Z2 - x) for x in D]
        r1[4] *= -1  # the sheet of y1 = -y(z1)

        def pjk(a, b):
            rho1 = mpmath.fprod(r1[m] for m in range(5) if m not in (a, b))
            rho2 = mpmath.fprod(r2[m] for m in range(5) if m not in (a, b))
            return (r2[a] * r2[b] * rho1 - r1[a] * r1[b] * rho2) / (Z1 - Z2)

        return [mpmath.sqrt(c[i]) * G * pjk(kk, ll) for i, (_, kk, ll) in enumerate(CYCLIC)] + [
            mpmath.sqrt(c[i]) * G * pjk(j, 4) for i, (j, _, _) in enumerate(CYCLIC)
        ]

    Z = [mpmath.mpc(z1), mpmath.mpc(z2), mpmath.mpc(g)]
    F0 = fwd(*Z)
    h = mpmath.mpf("1e-12")  # difference step at 30 digits: truncation ~1e-12 relative
    J = mpmath.matrix(6, 3)
    for col in range(3):
        Zh = list(Z)
        Zh[col] += h
        F = fwd(*Zh)
        for i in range(6):
            J[i, col] = (F[i] - F0[i]) / h
    sigma_min = min(mpmath.svd_c(J, compute_uv=False))
    bound_z = float(EPS_DOUBLE * max(abs(f) for f in F0) * np.sqrt(6) / sigma_min)
    err_z = max(abs(back.z1 - z1), abs(back.z2 - z2))
    if abs(back.z1 - z1) > abs(back.z1 - z2):
        err_z = max(abs(back.z2 - z1), abs(back.z1 - z2))
    assert err_z <= FORWARD_BOUND_FACTOR * bound_z
    assert back.residual <= BACKWARD_RTOL * max(np.abs(xi).max(), np.abs(eta).max())


def test_inverse_g_sign_and_involution():
    rng = np.random.default_rng(99)
    dd, d, (z1, y1, z2, y2) = random_setup(rng)
    k = KotterCurve(*dd)
    g = 0.7 - 1.1j
    xi, eta = np_xi_eta(d, z1, y1, z2, y2, g)
    a = k.points_from_wurzel(xi, eta, g_ref=g)
    b = k.points_from_wurzel(xi, eta, g_ref=-g)
    assert abs(a.g - g) < EXAMPLE_RTOL and abs(b.g + g) < EXAMPLE_RTOL
    # (-g, -y1, -y2): the hyperelliptic involution on both points.
    assert abs(a.z1 - b.z1) < EXAMPLE_RTOL and abs(a.y1 + b.y1) < EXAMPLE_RTOL * max(abs(a.y1), 1)
    # Default: the principal sqrt(g**2).
    c = k.points_from_wurzel(xi, eta)
    assert c.g.real > 0 or (c.g.real == 0 and c.g.imag > 0)
    np.testing.assert_allclose(c.g**2, g**2, rtol=EXAMPLE_RTOL)


def test_inverse_continuity_across_cuts():
    """Along a path whose points cross the cuts of the principal roots, the
    canonical P_j jump; eps * canonical (what xi, eta see) stays continuous and
    the recovered eps jumps exactly where the canonical roots do."""
    k = KotterCurve(1.0 + 0.5j, 2.0 - 0.3j, -1.5 + 0.2j)
    d = k.branch_points
    t = np.linspace(0.0, 1.0, 201)
    z1 = -2.5 + 0.5j - 1.0j * t  # crosses Im z = Im d_0 = 0 at t = 0.5 (cut of sqrt(z))
    z2 = 1.5 + 1.5j + 0.2 * t
    # A continuous y along the path by continuation (nearest sheet step to step).
    y1 = np.empty_like(z1)
    y2 = np.empty_like(z2)
    y1[0], y2[0] = np_y(d, z1[0]), np_y(d, z2[0])
    for i in range(1, t.size):
        a, b = np_y(d, z1[i]), np_y(d, z2[i])
        y1[i] = a if abs(a - y1[i - 1]) < abs(a + y1[i - 1]) else -a
        y2[i] = b if abs(b - y2[i - 1]) < abs(b + y2[i - 1]) else -b
    g = 1.2 + 0.1j
    xi, eta = k.xi_eta(z1, y1, z2, y2, g)  # canonical branch: jumps at the cut
    back = k.points_from_wurzel(xi, eta, g_ref=g)
    assert back.eps.shape == (201, 5)
    w = k.wurzel(back.z1, back.y1, back.z2, back.y2, eps=back.eps)
    c, _ = np_c(d)
    sc = np_sqrt(c)
    xb = np.stack([sc[i] * back.g * w.Pjk[:, kk, ll] for i, (_, kk, ll) in enumerate(CYCLIC)], -1)
    # Package evaluation of the recovered data: the backward error plus the
    # package's own rounding of xi (same order): within 2 * BACKWARD_RTOL.
    np.testing.assert_allclose(xb, xi, rtol=0, atol=2 * BACKWARD_RTOL * np.abs(xi).max())


# ----------------------------------------------------------------------------
# Bad input and API
# ----------------------------------------------------------------------------


def test_bad_points():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    z1, z2 = 0.3 + 0.2j, -1.0 + 0.5j
    y1, y2 = k.y(z1), k.y(z2)
    with pytest.raises(ValueError, match="not on the curve"):
        k.wurzel(z1, 1.01 * y1, z2, y2)
    with pytest.raises(ValueError, match="z1 == z2"):
        k.wurzel(z1, y1, z1, -y1)
    with pytest.raises(ValueError, match="finite"):
        k.wurzel(z1, y1, np.nan, y2)
    with pytest.raises(ValueError, match="product"):
        k.wurzel(z1, y1, z2, y2, eps=[1, 1, 1, 1, -1])
    with pytest.raises(ValueError, match="eps"):
        k.wurzel(z1, y1, z2, y2, eps=[1, 1, 1, 2, 2])
    with pytest.raises(ValueError, match="eps"):
        k.wurzel(z1, y1, z2, y2, eps=[1, 1, 1])
    with pytest.raises(ValueError, match="sheet"):
        k.y(z1, sheet=2)
    with pytest.raises(ValueError, match="finite"):
        k.R([0.5, np.nan])
    with pytest.raises(ValueError, match="finite"):
        k.y(np.inf)


def test_bad_inverse_input():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    z1, z2 = 0.3 + 0.2j, -1.0 + 0.5j
    xi, eta = k.xi_eta(z1, k.y(z1), z2, k.y(z2), 1.3)
    with pytest.raises(ValueError, match="vanishes"):
        k.points_from_wurzel(np.zeros(3), np.zeros(3))
    bad = np.array(xi)
    bad[0] *= 1.1
    with pytest.raises(ValueError, match="quadrics"):
        k.points_from_wurzel(bad, eta)
    with pytest.raises(ValueError, match="finite"):
        k.points_from_wurzel(xi, [np.nan, 0, 0])
    with pytest.raises(ValueError, match="length 3"):
        k.points_from_wurzel(xi[:2], eta[:2])
    with pytest.raises(ValueError, match="sqrt_c"):
        k.points_from_wurzel(xi, eta, sqrt_c=[1, 1, 1])
    # Another branch of sqrt(c_1): consistent data for it, not for the default.
    sc = np_sqrt(k.c) * np.array([-1, 1, 1])
    xi2, eta2 = k.xi_eta(z1, k.y(z1), z2, k.y(z2), 1.3, sqrt_c=sc)
    ok = k.points_from_wurzel(xi2, eta2, sqrt_c=sc)
    assert ok.residual < BACKWARD_RTOL * max(np.abs(xi2).max(), np.abs(eta2).max())


def limit_pjk(d, z, y):
    """P_jk at z1 = z2 = z, y1 = y2 = y (canonical branch): the limit of (28),
    P_j P_k d/dz[y/((z - d_j)(z - d_k))] = y (R'/(2R) - 1/(z - d_j) - 1/(z - d_k))."""
    log_deriv = sum(1 / (z - dj) for dj in d) / 2
    return {
        (j, k): y * (log_deriv - 1 / (z - d[j]) - 1 / (z - d[k]))
        for j in range(5)
        for k in range(5)
        if j != k
    }


def test_inverse_double_root():
    """z1 == z2, where (28) is undefined: the limit data (both points equal) are
    rejected with a message naming it, never a NaN."""
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    d = k.branch_points
    z = 0.4 + 0.3j
    pl = limit_pjk(d, z, np_y(d, z))
    sc = np_sqrt(k.c)
    xi = np.array([sc[i] * pl[(kk, ll)] for i, (_, kk, ll) in enumerate(CYCLIC)])
    eta = np.array([sc[i] * pl[(j, 4)] for i, (j, _, _) in enumerate(CYCLIC)])
    # The limit data satisfy the quadrics (11) (a check of the limit formula).
    c, ct = np_c(d)
    X, Y = xi / sc, eta / sc
    assert abs(np.sum(c * (X**2 + Y**2))) < IDENTITY_RTOL * np.sum(np.abs(c * (X**2 + Y**2)))
    with pytest.raises(ValueError, match="z1 == z2"):
        k.points_from_wurzel(xi, eta)
    # Close but distinct points (1e-3) are resolved. (Much closer pairs cannot
    # even be *encoded* accurately: (28) divides by z1 - z2.)
    z2 = z + 1e-3 * (0.6 - 0.8j)
    xi2, eta2 = k.xi_eta(z, k.y(z), z2, k.y(z2), 1.0)
    back = k.points_from_wurzel(xi2, eta2)
    # The data carry the rounding of (28)'s division by z1 - z2 (~u/delta) and
    # the inverse amplifies by ~1/delta: error ~u/delta**2 ~ 1e-10.
    assert min(abs(back.z1 - z), abs(back.z2 - z)) < CLOSE_PAIR_TOL


def test_shapes_broadcasting_and_scalars():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    z1 = np.array([[0.3 + 0.2j, 0.1 - 1j, 2.5 + 0.1j]])  # (1, 3)
    z2 = np.array([[-1.0 + 0.5j], [1.7 - 0.4j]])  # (2, 1)
    y1, y2 = k.y(z1), k.y(z2, sheet=-1)
    w = k.wurzel(z1, y1, z2, y2)
    assert w.P.shape == (2, 3, 5) and w.Pjk.shape == (2, 3, 5, 5)
    w11 = k.wurzel(z1[0, 1], y1[0, 1], z2[1, 0], y2[1, 0])
    assert w11.P.shape == (5,) and w11.Pjk.shape == (5, 5)
    np.testing.assert_array_equal(w.P[1, 1], w11.P)
    np.testing.assert_array_equal(w.Pjk[1, 1], w11.Pjk)
    assert not w.P.flags.writeable
    # eps broadcast against the points.
    e = np.array(all_eps()[:2])[:, None, :]  # (2, 1, 5)
    we = k.wurzel(z1, y1, z2, y2, eps=e)
    np.testing.assert_array_equal(we.P[0], w.P[0])
    xi, eta = k.xi_eta(z1, y1, z2, y2, 1.5)
    assert xi.shape == (2, 3, 3) and eta.shape == (2, 3, 3)
    back = k.points_from_wurzel(xi, eta)
    assert back.z1.shape == (2, 3) and back.eps.shape == (2, 3, 5)
    one = k.points_from_wurzel(xi[0, 0], eta[0, 0])
    assert np.shape(one.z1) == () and one.eps.shape == (5,)
    assert isinstance(complex(one.g), complex)


def test_inputs_not_modified_and_non_contiguous():
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    z = np.array([0.3 + 0.2j, 9.0, -1.0 + 0.5j, 9.0, 0.7 - 0.1j, 9.0])
    z1, z2 = z[0::2], np.array([1.1 - 0.2j, 2.2 + 0.4j, -0.3 - 0.9j])
    y1, y2 = k.y(z1), k.y(z2)
    z_copy = z.copy()
    w = k.wurzel(z1, y1, z2, y2)
    np.testing.assert_array_equal(z, z_copy)
    wc = k.wurzel(np.ascontiguousarray(z1), y1, z2, y2)
    np.testing.assert_array_equal(w.P, wc.P)
    xi, eta = k.xi_eta(z1, y1, z2, y2, 1.0)
    xi_f = np.asfortranarray(np.array(xi))
    copy = xi_f.copy()
    k.points_from_wurzel(xi_f, eta)
    np.testing.assert_array_equal(xi_f, copy)


def test_exports():
    assert manakov.KotterCurve is KotterCurve
    assert manakov.Wurzel is manakov.curve.Wurzel
    assert manakov.CurvePoints is manakov.curve.CurvePoints


@pytest.mark.parametrize("seed", range(10))
def test_37_xi_eta_lie_on_koetter_quadrics_11(seed):
    """(37) maps every point pair and g onto the three quadrics (11): the first
    is the s**-2 coefficient of (29), the second (31a), the third (32)."""
    rng = np.random.default_rng(5000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng)
    k = KotterCurve(*dd)
    g = rand_c(rng, -2, 2)
    xi, eta = k.xi_eta(z1, y1, z2, y2, g, eps=all_eps()[seed % 16])
    dj = d[1:4]
    for terms in (xi**2 + eta**2, xi * eta, dj * xi**2 + eta**2 / dj):
        assert abs(terms.sum()) <= IDENTITY_RTOL * np.abs(terms).sum()
    # And (37) itself, against the independent numpy evaluation.
    xn, en = np_xi_eta(d, z1, y1, z2, y2, g, all_eps()[seed % 16])
    scale = max(np.abs(xn).max(), np.abs(en).max())
    np.testing.assert_allclose(xi, xn, rtol=0, atol=NUMPY_RTOL * scale)
    np.testing.assert_allclose(eta, en, rtol=0, atol=NUMPY_RTOL * scale)


@pytest.mark.parametrize(
    ("dd", "z1", "z2"),
    [
        # Real branch points, real points between them: z - d_j < 0 for some j, i.e.
        # on the cuts of the principal roots (sqrt of a negative real is +i sqrt).
        ((1.0, 2.5, 4.0), 1.7, 3.2),
        ((1.0, 2.5, 4.0), -0.6, 12.0),
        ((-0.5, 0.8, 3.0), -0.2, 0.4),
        # Real d_j, complex points.
        ((0.3, 1.9, -2.2), 0.5 + 0.5j, -1.0 - 0.25j),
    ],
)
@pytest.mark.parametrize("sheets", [(1, 1), (1, -1)])
def test_real_branch_points_and_points_on_cuts(dd, z1, z2, sheets):
    k = KotterCurve(*dd)
    d = k.branch_points
    assert np.all(d.imag == 0)
    y1, y2 = k.y(z1, sheet=sheets[0]), k.y(z2, sheet=sheets[1])
    w = k.wurzel(z1, y1, z2, y2)
    P, Pjk = np_wurzel(d, complex(z1), y1, complex(z2), y2)
    np.testing.assert_allclose(w.P, P, rtol=NUMPY_RTOL)
    np.testing.assert_allclose(w.Pjk, Pjk, rtol=0, atol=NUMPY_RTOL * np.abs(Pjk).max())
    for name, (v, expected, scale) in identities(d, w.P, w.Pjk).items():
        assert abs(v - expected) <= IDENTITY_RTOL * scale, name
    g = 0.9
    xi, eta = k.xi_eta(z1, y1, z2, y2, g)
    back = k.points_from_wurzel(xi, eta, g_ref=g)
    assert back.residual <= BACKWARD_RTOL * max(np.abs(xi).max(), np.abs(eta).max())
    assert {round(back.z1.real, 9), round(back.z2.real, 9)} == {
        round(complex(z1).real, 9),
        round(complex(z2).real, 9),
    }


@pytest.mark.parametrize("seed", range(10))
def test_wurzel_symmetries(seed):
    """Choices the result must not depend on: the order of the two points; and
    the hyperelliptic involution on both points, (y1, y2) -> (-y1, -y2), which
    leaves every P_j and flips every P_jk (so it is the same as g -> -g in (37))."""
    rng = np.random.default_rng(6000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng, bp_dist=0.0)
    k = KotterCurve(*dd)
    eps = all_eps()[seed % 16]
    w = k.wurzel(z1, y1, z2, y2, eps=eps)
    swapped = k.wurzel(z2, y2, z1, y1, eps=eps)
    scale = np.abs(w.Pjk).max()
    np.testing.assert_allclose(swapped.P, w.P, rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(swapped.Pjk, w.Pjk, rtol=0, atol=IDENTITY_RTOL * scale)
    inv = k.wurzel(z1, -y1, z2, -y2, eps=eps)
    np.testing.assert_allclose(inv.P, w.P, rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(inv.Pjk, -w.Pjk, rtol=0, atol=IDENTITY_RTOL * scale)


@pytest.mark.parametrize("scale", [1e-170, 1e-20, 1e20, 1e300])
def test_inverse_is_homogeneous_in_g(scale):
    """(37) is linear in g: scaling (xi, eta) by s scales g by s and leaves the
    points, even where g**2 would under- or overflow."""
    k = KotterCurve(2.0, 3.0, -0.5 + 1j)
    z1, z2 = 0.3 + 0.2j, -1.0 + 0.5j
    y1, y2 = k.y(z1), k.y(z2, sheet=-1)
    xi, eta = k.xi_eta(z1, y1, z2, y2, 0.8 + 0.3j)
    ref = k.points_from_wurzel(xi, eta)
    b = k.points_from_wurzel(np.asarray(xi) * scale, np.asarray(eta) * scale)
    for a, r in ((b.z1, ref.z1), (b.z2, ref.z2), (b.y1, ref.y1), (b.y2, ref.y2)):
        assert abs(a - r) <= EXAMPLE_RTOL * max(abs(r), 1)
    assert abs(b.g / scale - ref.g) <= EXAMPLE_RTOL * abs(ref.g)
    np.testing.assert_array_equal(b.eps, ref.eps)


# ----------------------------------------------------------------------------
# Offsets zd = z_i - d_j (accuracy near branch points)
# ----------------------------------------------------------------------------

#: Offsets returned by points_from_wurzel are t + (d_b - d_j) with t the offset to the
#: nearest branch point: they differ from the rounded z - d_j by a few roundings of
#: numbers of size |z| + max|d_j| (the Rust OFFSET_RTOL, 16 ulps).
OFFSET_RTOL = 16 * np.finfo(float).eps


@pytest.mark.parametrize("seed", range(8))
def test_points_from_wurzel_offsets(seed):
    """CurvePoints.zd (shape (..., 2, 5)) agree with z_i - d_j to rounding, and (37)
    evaluated from them (xi_eta(..., zd=)) reproduces the data as the bare points do
    (separated points: both to NUMPY_RTOL of the independent numpy data); wurzel with and
    without zd agree to rounding there."""
    rng = np.random.default_rng(7000 + seed)
    dd, d, (z1, y1, z2, y2) = random_setup(rng)
    k = KotterCurve(*dd)
    g = rand_c(rng, -2, 2, 3)
    eps = all_eps()[seed % 16]
    data = [np_xi_eta(d, z1, y1, z2, y2, gi, eps) for gi in g]
    xi = np.array([x for x, _ in data])
    eta = np.array([e for _, e in data])
    pts = k.points_from_wurzel(xi, eta, g_ref=g)
    assert pts.zd.shape == (3, 2, 5)
    zz = np.stack([pts.z1[:, None] - d, pts.z2[:, None] - d], axis=1)
    size = np.maximum(np.abs(pts.z1), np.abs(pts.z2))[:, None, None] + np.abs(d).max()
    assert np.all(np.abs(pts.zd - zz) <= OFFSET_RTOL * size)
    args = (pts.z1, pts.y1, pts.z2, pts.y2, pts.g)
    xz, ez = k.xi_eta(*args, eps=pts.eps, zd=pts.zd)
    scale = max(np.abs(xi).max(), np.abs(eta).max())
    assert np.abs(np.concatenate([xz - xi, ez - eta])).max() <= NUMPY_RTOL * scale
    w0 = k.wurzel(pts.z1, pts.y1, pts.z2, pts.y2, eps=pts.eps)
    w1 = k.wurzel(pts.z1, pts.y1, pts.z2, pts.y2, eps=pts.eps, zd=pts.zd)
    assert np.abs(w1.Pjk - w0.Pjk).max() <= NUMPY_RTOL * np.abs(w0.Pjk).max()
    # One pair: scalar points, zd of shape (2, 5), accepted back as such.
    one = k.points_from_wurzel(xi[0], eta[0], g_ref=g[0])
    assert one.zd.shape == (2, 5)
    x1, e1 = k.xi_eta(one.z1, one.y1, one.z2, one.y2, one.g, eps=one.eps, zd=one.zd)
    assert x1.shape == (3,) and np.abs(x1 - xi[0]).max() <= NUMPY_RTOL * scale


def test_bad_offsets():
    k = KotterCurve(0.5 + 0.3j, -1.2 + 0.1j, 2.0 - 0.4j)
    z1, z2 = 0.7 + 1.1j, -1.5 + 0.4j
    y1, y2 = k.y(z1), k.y(z2)
    d = np.asarray(k.branch_points)
    zd = np.stack([z1 - d, z2 - d])
    k.wurzel(z1, y1, z2, y2, zd=zd)  # consistent: accepted
    with pytest.raises(ValueError, match="shape"):
        k.wurzel(z1, y1, z2, y2, zd=zd[:, :4])
    bad = zd.copy()
    bad[1, 2] += 1e-6
    with pytest.raises(ValueError, match="offset"):
        k.wurzel(z1, y1, z2, y2, zd=bad)
    with pytest.raises(ValueError, match="offset"):
        k.xi_eta(z1, y1, z2, y2, 1.0, zd=bad)
    bad[1, 2] = np.nan
    with pytest.raises(ValueError):
        k.xi_eta(z1, y1, z2, y2, 1.0, zd=bad)
    zd_copy = zd.copy()
    k.xi_eta(z1, y1, z2, y2, 1.0, zd=zd)
    np.testing.assert_array_equal(zd, zd_copy)


# Close points on one sheet (issue 9): the telescoped (28) against 50-digit mpmath;
# the claim, relative to max |P_jk|.
CLOSE_POINTS_TOL = 1e-13


def _mp_pjk(d: tuple[complex, complex, complex], z1: complex, y1, z2: complex, y2) -> np.ndarray:
    """(28) at 50 digits with the canonical roots (module docs of rust/curve)."""
    D = [mpmath.mpc(0)] + [mpmath.mpc(x) for x in d]
    D.append(D[1] * D[2] * D[3])

    def roots(z, y):
        r = [mpmath.sqrt(mpmath.mpc(z) - dj) for dj in D]
        if mpmath.re(mpmath.conj(mpmath.fprod(r)) * y) < 0:
            r[4] = -r[4]
        return r

    r1, r2 = roots(z1, y1), roots(z2, y2)
    out = np.zeros((5, 5), dtype=complex)
    for j, k in itertools.combinations(range(5), 2):
        rest = [m for m in range(5) if m not in (j, k)]
        a = r2[j] * r2[k] * mpmath.fprod(r1[m] for m in rest)
        b = r1[j] * r1[k] * mpmath.fprod(r2[m] for m in rest)
        out[j, k] = out[k, j] = complex((a - b) / (mpmath.mpc(z1) - mpmath.mpc(z2)))
    return out


@pytest.mark.parametrize("gap", [1e-8, 1e-12])
def test_wurzel_close_points_same_sheet_against_mpmath(gap: float) -> None:
    mpmath.mp.dps = 50
    d = (1.3 + 0.4j, -0.7 + 0.2j, 0.5 - 1.1j)
    curve = KotterCurve(*d)
    rng = np.random.default_rng(11)
    worst = 0.0
    for _ in range(20):
        z1 = complex(*rng.normal(size=2))
        z2 = z1 + gap * np.exp(2j * np.pi * rng.random())
        y1 = complex(curve.y(z1))
        # y2 continued from y1 along the segment (at 50 digits)
        D = [0] + list(d) + [d[0] * d[1] * d[2]]
        y2mp = mpmath.mpc(y1) * mpmath.fprod(
            mpmath.sqrt(1 + (mpmath.mpc(z2) - mpmath.mpc(z1)) / (mpmath.mpc(z1) - dj)) for dj in D
        )
        y2 = complex(y2mp)
        ref = _mp_pjk(d, z1, mpmath.mpc(y1), z2, mpmath.mpc(y2))
        got = curve.wurzel(z1, y1, z2, y2).Pjk
        worst = max(worst, np.abs(got - ref).max() / np.abs(ref).max())
    print(f"gap {gap:.0e}: worst relative error {worst:.1e}")
    assert worst <= CLOSE_POINTS_TOL


def test_wurzel_same_point_is_tangent_limit() -> None:
    mpmath.mp.dps = 50
    d = (1.3 + 0.4j, -0.7 + 0.2j, 0.5 - 1.1j)
    curve = KotterCurve(*d)
    z = 0.3 - 0.8j
    y = complex(curve.y(z))
    got = curve.wurzel(z, y, z, y).Pjk
    # the limit: (28) at a gap of 1e-30 in 50 digits (the O(gap) term is far below 1e-16)
    D = [0] + list(d) + [d[0] * d[1] * d[2]]
    z2 = mpmath.mpc(z) + mpmath.mpf(10) ** -30
    y2 = mpmath.mpc(y) * mpmath.fprod(mpmath.sqrt(1 + (z2 - mpmath.mpc(z)) / (z - dj)) for dj in D)
    mpmath.mp.dps = 50
    ref = np.zeros((5, 5), dtype=complex)
    r1 = [mpmath.sqrt(mpmath.mpc(z) - dj) for dj in [mpmath.mpc(x) for x in D]]
    if mpmath.re(mpmath.conj(mpmath.fprod(r1)) * y) < 0:
        r1[4] = -r1[4]
    r2 = [mpmath.sqrt(z2 - dj) for dj in [mpmath.mpc(x) for x in D]]
    if mpmath.re(mpmath.conj(mpmath.fprod(r2)) * y2) < 0:
        r2[4] = -r2[4]
    for j, k in itertools.combinations(range(5), 2):
        rest = [m for m in range(5) if m not in (j, k)]
        a = r2[j] * r2[k] * mpmath.fprod(r1[m] for m in rest)
        b = r1[j] * r1[k] * mpmath.fprod(r2[m] for m in rest)
        ref[j, k] = ref[k, j] = complex((a - b) / (mpmath.mpc(z) - z2))
    assert np.abs(got - ref).max() / np.abs(ref).max() <= CLOSE_POINTS_TOL
    # the same z on the other sheet is a pole of (28)
    with pytest.raises(ValueError, match="different sheets"):
        curve.wurzel(z, y, z, -y)


# Issue 11, fuzz items 1, 4, 5: extreme scales. The inverse map's round trip, relative
# to the size of the points: what the closed form plus the Gauss-Newton polish reach at
# every scale where the curve's products stay in the double range (measured <= 1.2e-13).
SCALE_ROUND_TRIP_TOL = 1e-12


@pytest.mark.parametrize("scale", [1e-5, 1e-2, 1.0, 1e2, 1e3, 1e4, 1e6])
def test_points_from_wurzel_round_trip_at_every_scale(scale: float) -> None:
    curve = KotterCurve(scale, (2 + 1j) * scale, 3 * scale)
    rng = np.random.default_rng(3)
    for _ in range(10):
        z1, z2 = (rng.normal(size=2) + 1j * rng.normal(size=2)) * scale
        g = 1.3 - 0.2j
        xi, eta = curve.xi_eta(z1, curve.y(z1), z2, curve.y(z2), g)
        r = curve.points_from_wurzel(xi, eta, g_ref=g)
        # the pair is unordered (docstring): compare as sets
        err = min(abs(r.z1 - z1) + abs(r.z2 - z2), abs(r.z1 - z2) + abs(r.z2 - z1))
        assert err <= SCALE_ROUND_TRIP_TOL * max(abs(z1), abs(z2))
        assert abs(r.g - g) <= SCALE_ROUND_TRIP_TOL * abs(g)


@pytest.mark.parametrize("scale", [1e27, 1e40, 1e60])
def test_points_from_wurzel_huge_curves_raise_not_hang(scale: float) -> None:
    curve = KotterCurve(scale, 2 * scale, 3 * scale)
    with pytest.raises(ValueError):
        curve.points_from_wurzel([1, 1, 1], [1, 1, 1])


def test_curve_constants_at_tiny_and_huge_scales() -> None:
    # c~_j scales like 1/s^2: the value at d = s (1, 2+i, 3) from the unit curve's
    c1 = KotterCurve(1.0, 2 + 1j, 3.0).c_tilde
    tiny = KotterCurve(1e-100, 2e-100 + 1e-100j, 3e-100)
    np.testing.assert_allclose(tiny.c_tilde, c1 * 1e200, rtol=1e-14)
    xi, eta = tiny.xi_eta(1e-100, tiny.y(1.5e-100), 2.5e-100, tiny.y(2.5e-100), 1.0)
    assert np.all(np.isfinite(xi)) and np.all(np.isfinite(eta))
    huge = KotterCurve(1e34, (2 + 1j) * 1e34, 3e34)
    with pytest.raises(ValueError, match="does not fit in a double"):
        _ = huge.kappa
