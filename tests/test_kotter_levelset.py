# ruff: noqa: E741  (l is the paper's name for the state)
"""Issue 9: roots of F on their own branch, one branch per level set, batch errors.

Reference values: roots of F (19) and F'(s_p) from mpmath at 50 digits
(``mpmath.polyroots`` on the quartic formed in mpmath from the state); the
trajectories from the package's integrator are only the *input* of the
continuity checks, whose bounds (|z'| dt) come from finite differences of the
map along the vector field, not from the samples themselves.
"""

from __future__ import annotations

import re
import sys
from functools import cache
from pathlib import Path

import mpmath
import numpy as np
import pytest

import manakov

from conftest import PROBLEM_NAMES

sys.path.insert(0, str(Path(__file__).parent / "data"))
import kotter_singular_conditioning as near  # noqa: E402

# Neighbouring samples of a smooth curve t -> z(t) differ by |z'| dt up to the
# second-order term (dt = 0.01 here); 2 leaves room for it, while a jump to another
# branch (the involution image, a swapped or sign-flipped constant) is O(|z|), i.e.
# hundreds of |z'| dt.
JUMP_FACTOR = 2.0
# Kötter's quadrics (11) relative to |xi|^2 + |eta|^2 (and |d||xi|^2 + |eta|^2/|d| for
# the third): the claim.
QUADRIC_TOL = 1e-13
# s_p, sigma_p and F'(s_p) against mpmath: they are computed in double-double and
# rounded once (docs/kotter.md §3), so they are correctly rounded up to the DD error
# (~1e-30): 4 ulps of a complex number allow for the rounding of both components.
ROOT_TOL = 4 * np.finfo(float).eps
FPRIME_TOL = 4 * np.finfo(float).eps
# Round trip l -> Kötter -> l on random tops and states (issue 9): the claim.
ROUND_TRIP_MAX = 1e-12
ROUND_TRIP_BULK = 1e-13
# The round trip with the level-set constants in double-double: 1.9e-15 at most over
# the 10^4 states of tests/data/kotter_roundtrip_random10k.py; 1e-14 is five times
# that, and 30 times below what the double-precision constants left on the hard
# states below (3e-13 ... 3.5e-12).
ROUND_TRIP_DD = 1e-14

T_END = 200.0
N_SAMPLES = 20001


@cache
def _trajectory(name: str, t_end: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    t = np.linspace(0.0, t_end, n)
    x = np.asarray(top.integrate(p.l0, t_end, t_eval=t).l)
    return t, x


def _divisor_rates(ls: manakov.LevelSet, x: np.ndarray, v: np.ndarray):
    """d/dt of z1 + z2, z1 z2 and g by central differences of the map along the flow."""
    h = 1e-6 * np.abs(x).max() / np.abs(v).max()
    kp, km = ls.kotter(x + h * v), ls.kotter(x - h * v)
    ds1 = ((kp.z1 + kp.z2) - (km.z1 + km.z2)) / (2 * h)
    ds2 = (kp.z1 * kp.z2 - km.z1 * km.z2) / (2 * h)
    dg = (kp.g - km.g) / (2 * h)
    return ds1, ds2, dg


def _max_jump_ratio(x: np.ndarray, dx: np.ndarray, dt: float) -> float:
    jump = np.abs(np.diff(x))
    bound = np.maximum(np.abs(dx[1:]), np.abs(dx[:-1])) * dt
    return float(np.max(jump / bound))


@pytest.mark.parametrize(
    "name, t_end, n",
    [(nm, 20.0, 2001) for nm in PROBLEM_NAMES]
    + [pytest.param(nm, T_END, N_SAMPLES, marks=pytest.mark.slow) for nm in PROBLEM_NAMES],
)
def test_level_set_divisor_continuous_along_trajectory(name: str, t_end: float, n: int) -> None:
    p = manakov.problem(name)
    t, x = _trajectory(name, t_end, n)
    dt = t[1] - t[0]
    v = manakov.ManakovTop(p.a, p.b).vector_field(x)
    ls = manakov.LevelSet(p.a, p.b, p.l0)
    k = ls.kotter(x)
    assert np.all(k.ok)
    ds1, ds2, dg = _divisor_rates(ls, x, v)
    # the rates of each point from those of the symmetric functions
    dz1 = (ds1 * k.z1 - ds2) / (k.z1 - k.z2)
    dz2 = (ds2 - ds1 * k.z2) / (k.z1 - k.z2)
    d5 = np.concatenate([[0], ls.d, [np.prod(ls.d)]])
    dy1 = k.y1 * np.sum(0.5 / (k.z1[:, None] - d5), -1) * dz1
    dy2 = k.y2 * np.sum(0.5 / (k.z2[:, None] - d5), -1) * dz2
    ratios = {
        "z1": _max_jump_ratio(k.z1, dz1, dt),
        "z2": _max_jump_ratio(k.z2, dz2, dt),
        "y1": _max_jump_ratio(k.y1, dy1, dt),
        "y2": _max_jump_ratio(k.y2, dy2, dt),
        "g": _max_jump_ratio(k.g, dg, dt),
    }
    print(name, {kk: f"{vv:.4f}" for kk, vv in ratios.items()})
    assert max(ratios.values()) <= JUMP_FACTOR, ratios
    # the involution image (g, y) -> (-g, -y) is never the nearer neighbour
    assert np.all(np.abs(np.diff(k.g)) < np.abs(k.g[1:] + k.g[:-1]))
    # quadrics (11)
    s2 = np.sum(np.abs(k.xi) ** 2 + np.abs(k.eta) ** 2, -1)
    s3 = np.sum(np.abs(k.d) * np.abs(k.xi) ** 2 + np.abs(k.eta) ** 2 / np.abs(k.d), -1)
    q1 = np.abs(np.sum(k.xi**2 + k.eta**2, -1)) / s2
    q2 = np.abs(np.sum(k.xi * k.eta, -1)) / s2
    q3 = np.abs(np.sum(k.d * k.xi**2 + k.eta**2 / k.d, -1)) / s3
    assert max(q1.max(), q2.max(), q3.max()) <= QUADRIC_TOL


def test_per_state_kotter_jumps_where_level_set_does_not() -> None:
    """The one-off ``kotter`` orders and normalises state by state: on 'generic' its
    ``z1`` leaves the |z'| dt bound (the two points trade places), so the continuity
    test above can fail. The bound uses the larger rate of the two points."""
    p = manakov.problem("generic")
    t, x = _trajectory("generic", 20.0, 2001)
    v = manakov.ManakovTop(p.a, p.b).vector_field(x)
    ls = manakov.LevelSet(p.a, p.b, p.l0)
    kl = ls.kotter(x)
    ds1, ds2, _ = _divisor_rates(ls, x, v)
    dz1 = (ds1 * kl.z1 - ds2) / (kl.z1 - kl.z2)
    dz2 = (ds2 - ds1 * kl.z2) / (kl.z1 - kl.z2)
    rate = np.maximum(np.abs(dz1), np.abs(dz2))
    k = manakov.kotter(p.a, p.b, x)
    ratio = _max_jump_ratio(k.z1, rate, t[1] - t[0])
    print(f"per-state kotter: largest jump of z1 = {ratio:.1f} |z'| dt")
    assert ratio > 10 * JUMP_FACTOR


def _mp_roots(a: np.ndarray, l: np.ndarray) -> list:
    """Roots of F (19) and F'(s_p) = prod_{q != p} (s_p - s_q) in mpmath from the state."""
    mpmath.mp.dps = 50
    L = [mpmath.mpf(float(x)) for x in l]
    _, h0, num = near.quartic([mpmath.mpf(float(x)) for x in a], L)
    h1 = sum(x * x for x in L)
    assert abs(num[0] - (h1**2 - 4 * h0**2)) < mpmath.mpf(10) ** -40
    roots = near.polyroots(num, 200)
    out = []
    for r in roots:
        fp = mpmath.fprod(r - q for q in roots if q is not r)
        out.append((complex(r), complex(fp)))
    return out


def test_roots_and_fprime_on_own_branch_against_mpmath() -> None:
    """s_p and F'(s_p) (from f' f~/(h1^2 - 4h0^2)) against 50-digit mpmath, on random
    tops and states including clustered roots (the merged quartic loses u/delta there)."""
    rng = np.random.default_rng(97)
    worst_s = worst_fp = 0.0
    for _ in range(60):
        a = np.sort(rng.normal(size=4))
        l = rng.normal(size=6)
        k = manakov.kotter(a, rng.normal(size=4), l)
        ref = _mp_roots(a, l)
        for sp, fp in zip(k.s, k.sqrt_fprime**2):
            r, rfp = min(ref, key=lambda rr: abs(rr[0] - sp))
            worst_s = max(worst_s, abs(sp - r) / max(abs(r), 1.0))
            worst_fp = max(worst_fp, abs(fp - rfp) / abs(rfp))
    print(f"roots {worst_s:.1e}, F' {worst_fp:.1e}")
    assert worst_s <= ROOT_TOL
    assert worst_fp <= FPRIME_TOL


@cache
def _random_round_trips() -> np.ndarray:
    """A smaller version of ``tests/data/kotter_roundtrip_random10k.py`` (another seed)."""
    rng = np.random.default_rng(4242)
    errs = []
    for _ in range(1000):
        a = np.sort(rng.normal(size=4))
        b = rng.normal(size=4)
        l = rng.normal(size=6)
        k = manakov.kotter(a, b, l)
        back = manakov.from_kotter(a, b, k)
        errs.append(np.max(np.abs(back - l)) / np.max(np.abs(l)))
    return np.array(errs)


def test_round_trip_random_tops_distribution() -> None:
    e = _random_round_trips()
    print(f"median {np.median(e):.1e}, 99.9% {np.percentile(e, 99.9):.1e}, max {e.max():.1e}")
    assert np.mean(e <= ROUND_TRIP_BULK) >= 0.999
    assert np.percentile(e, 99.9) <= ROUND_TRIP_DD


def test_round_trip_random_tops_max_claim() -> None:
    """Issue 9: max <= 1e-12 (was 2.5e-12 on this draw with double-precision constants)."""
    assert _random_round_trips().max() <= ROUND_TRIP_MAX


def test_batch_error_names_the_row_and_mask_gives_status() -> None:
    p = manakov.problem("generic")
    m = np.array([0.3, -0.2, 0.5])
    self_dual = np.array([m[2], -m[1], m[0], m[0], m[1], m[2]])  # n = m
    x = np.stack([p.l0, self_dual, p.l0])
    with pytest.raises(ValueError, match="row 1 of 3"):
        manakov.kotter(p.a, p.b, x)
    k = manakov.kotter(p.a, p.b, x, errors="mask")
    assert k.ok.tolist() == [True, False, True]
    assert np.all(np.isnan(k.d[1])) and k.curve[1] is None
    assert np.all(np.isfinite(k.d[[0, 2]]))
    with pytest.raises(ValueError, match="errors must be"):
        manakov.kotter(p.a, p.b, x, errors="ignore")
    with pytest.raises(ValueError, match="failed"):
        manakov.from_kotter(p.a, p.b, k)


def test_from_kotter_refuses_another_top() -> None:
    p, q = manakov.problem("generic"), manakov.problem("physical")
    k = manakov.kotter(p.a, p.b, p.l0)
    with pytest.raises(ValueError, match="another top"):
        manakov.from_kotter(q.a, q.b, k)
    with pytest.raises(ValueError, match="another top"):
        manakov.from_kotter(p.a, q.b, k)
    np.testing.assert_allclose(manakov.from_kotter(p.a, p.b, k), p.l0, rtol=0, atol=1e-12)


def test_level_set_refuses_states_off_it() -> None:
    p = manakov.problem("generic")
    ls = manakov.LevelSet(p.a, p.b, p.l0)
    with pytest.raises(ValueError, match="not on this level set"):
        ls.kotter(p.l0 * 1.01)
    k = ls.kotter(p.l0)
    np.testing.assert_array_equal(k.d, manakov.kotter(p.a, p.b, p.l0).d)
    with pytest.raises(ValueError, match="shape"):
        manakov.LevelSet(p.a, p.b, np.stack([p.l0, p.l0]))


def test_extreme_scales_raise_or_stay_finite() -> None:
    """Issue 11, fuzz item 4: no silent NaN/inf."""
    from manakov import reduction

    p = manakov.problem("generic")
    l = np.array([-0.715, -0.715, -1.5, -1.5, -1.5, -9.726])
    k = manakov.kotter(p.a, p.b, l * 1e40)
    assert np.all(np.isfinite(k.sigma)) and np.all(np.isfinite(k.l_p))
    # sigma and d are scale-free, l_p scales like l
    k1 = manakov.kotter(p.a, p.b, l)
    np.testing.assert_allclose(k.d, k1.d, rtol=1e-12)
    np.testing.assert_allclose(k.l_p, k1.l_p * 1e40, rtol=1e-12)
    with pytest.raises(ValueError, match="divided differences"):
        reduction.lax_pair(
            [8e-321, 0, 5.55e-320, 3.27e-320], [-2.69, 0.557, 0.557, 0], [1, 0, 0, 0, 0, 0], 9.86j
        )
    with pytest.raises(ValueError, match="overflows"):
        reduction.schottky(p.a, np.full(6, 1e308), 1.0 + 1j)


def test_top_level_set_shorthand() -> None:
    p = manakov.problem("wide")
    top = manakov.ManakovTop(p.a, p.b)
    ls = top.level_set(p.l0)
    assert isinstance(ls, manakov.LevelSet)
    np.testing.assert_array_equal(
        ls.kotter(p.l0).d, manakov.LevelSet(p.a, p.b, p.l0).kotter(p.l0).d
    )
    k = top.kotter(np.stack([p.l0, p.l0]), errors="mask")
    assert k.ok.tolist() == [True, True]


# A draw (rounded to 8 digits) with one branch point |d_1| ~ 5e5: the points'
# polish fitted (xi, eta) absolutely, leaving the small xi_1 1e-12 off relatively, and
# (23), whose alpha_1 .. delta_1 are large there, made that a 1.8e-12 round trip (5e-13 now). The
# polish now fits in the norm of (23) (KotterCurve::points_from_xi_eta_fit).
LARGE_D1_STATES = [
    (
        [-1.40841259, -1.03519574, -0.62996586, -0.27727842],
        [0.76288476, 1.03981227, -1.84771868, 0.08167655],
        [0.89224407, -0.35589042, 0.21760193, 0.17909782, 0.30094468, 0.85154148],
    ),
]


@pytest.mark.parametrize("a, b, l", LARGE_D1_STATES)
def test_round_trip_with_a_large_branch_point(a: list, b: list, l: list) -> None:
    k = manakov.kotter(a, b, l)
    assert np.max(np.abs(k.d)) > 1e5
    back = manakov.from_kotter(a, b, k)
    assert np.max(np.abs(back - np.asarray(l))) / np.max(np.abs(l)) <= ROUND_TRIP_MAX


# The worst states of two draws (seed 4242: the test draw above; seed 31, 3000 draws)
# with the level-set constants in double precision: round trips 2.5e-12, 3.9e-13 and
# 6.6e-13, 3.6e-13, 2.1e-13, with one branch point |d_j| of 1e5 ... 2e7 (or one of
# 0.05: d -> 1/d). The third quadric (11) of the rounded constants holds only as well
# as s_p, sigma_p, F'(s_p) agree with each other, amplified by ~sqrt|d_j|; F' in double
# was off by a few ulps (docs/kotter.md, "Accuracy").
HARD_STATES = [
    (  # seed 4242, draw 730: |d_1| = 1.2e7
        [-1.585310933410371, -1.0457401246649016, -0.133361592904932, 1.0419437783331729],
        [0.268619510169844, 0.12830276341593336, 0.33814396712432726, -0.7807598190389048],
        [
            0.8399234568268651,
            0.9994274853880986,
            0.14975644527013487,
            0.4971976793654091,
            -0.8884535144343967,
            -1.3770246476765315,
        ],
    ),
    (  # seed 31, draw 1262: |d_1| = 2.7e5
        [-1.219078220659279, -0.6109137319068842, -0.017926948688871992, 0.9908760256034481],
        [-0.386314196665051, -0.9396082406744147, 0.055524189401636156, -0.036999526176942694],
        [
            -1.110336424806169,
            0.6263706944691108,
            1.570285972165918,
            1.888479658008894,
            -0.5767942906525974,
            -1.4628604244011545,
        ],
    ),
    (  # seed 31, draw 284: |d_1| = 2.0e7
        [-1.0210777349805473, -0.4957004383440669, -0.37399158873708366, 0.17387383834553874],
        [0.35108993683067014, 0.2776454139353398, 1.5314138751827404, -1.8011621284432207],
        [
            -0.5979447986119144,
            -1.3537228356781994,
            -0.36379363001727794,
            0.537539038822212,
            1.5263325437681967,
            -0.13230344166239907,
        ],
    ),
    (  # seed 31, draw 1098: max |d_j| = 0.053
        [-1.0708902707020018, -1.0392997411954243, 0.2376968173875089, 1.2246834296498113],
        [-0.001963583834326358, -0.8435937952335179, 0.6952230824442729, -0.12179652755464762],
        [
            -0.7023745256600957,
            0.8599611755672486,
            1.8623135824239314,
            -1.5450523917822985,
            -0.9494693340188126,
            -1.5268351417029142,
        ],
    ),
]


@pytest.mark.parametrize("a, b, l", HARD_STATES)
def test_hard_states_round_trip_at_roundoff(a: list, b: list, l: list) -> None:
    """s_p, F'(s_p) correctly rounded (against 50-digit mpmath) and the round trip at
    roundoff on the states the double-precision constants lost 2e-13 ... 2.5e-12 on."""
    k = manakov.kotter(a, b, l)
    for sp, fp in zip(k.s, k.sqrt_fprime**2):
        r, rfp = min(_mp_roots(np.asarray(a), np.asarray(l)), key=lambda rr: abs(rr[0] - sp))
        assert abs(sp - r) <= ROOT_TOL * abs(r)
        # F' = (sqrt F')^2 adds one rounding of its own
        assert abs(fp - rfp) <= FPRIME_TOL * abs(rfp)
    back = manakov.from_kotter(a, b, k)
    err = np.max(np.abs(back - np.asarray(l))) / np.max(np.abs(l))
    print(f"|d| max {np.max(np.abs(k.d)):.1e}, min {np.min(np.abs(k.d)):.1e}: round trip {err:.1e}")
    assert err <= ROUND_TRIP_DD


# Near the singular set h1^2 = 4 h0^2 (issue 9). delta = (h1^2 - 4 h0^2)/h1^2, the
# relative size of the quantity that vanishes there; the states n = +-m + rho |m| v
# have delta ~ rho^2. The package's documented thresholds (docs/kotter.md, "Near the
# singular set"): below NEAR_SINGULAR_RTOL a state may raise, below DEGENERATE_RTOL
# every state does.
NEAR_SINGULAR_RTOL = 1e-10
DEGENERATE_RTOL = 1e-12
# d_j are rounded once from the double-double constants: a few ulps.
D_TOL = 4 * np.finfo(float).eps
# z_i against 80-digit mpmath, in units of their condition number in the state times
# u (kappa_out u, from mpmath finite differences of the same state): the data (xi,
# eta) reach the inverse map rounded to double, and z is as sensitive to that as to
# the rounding of l. Measured worst 4.8 over 48 states of the four tops.
Z_COND_FACTOR = 8.0


@pytest.mark.parametrize("name", PROBLEM_NAMES)
def test_near_singular_set_reduces_at_roundoff(name: str) -> None:
    """delta from 1e-4 down to 1e-10 (rho 1e-2 ... 1e-5): every state reduces, the
    round trip is at roundoff, d_j are correctly rounded and z_i follow their
    conditioning, against an independent 80-digit mpmath reduction. (Before issue 9
    was closed these states raised from rho = 1e-4 on: 'no pair of points reproduces
    them'.)"""
    p = manakov.problem(name)
    rng = np.random.default_rng(19)
    u = np.finfo(float).eps / 2
    for rho in (1e-2, 1e-3, 1e-4, 1e-5):
        for _ in range(2):
            m = rng.normal(size=3)
            v = rng.normal(size=3)
            v /= np.linalg.norm(v)
            n = rng.choice([-1, 1]) * m + rho * np.linalg.norm(m) * v
            l = np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])
            mm, nn = np.array([l[3], -l[1], l[0]]), l[[2, 4, 5]]
            delta = np.sum((mm - nn) ** 2) * np.sum((mm + nn) ** 2) / np.sum(l**2) ** 2
            assert delta >= NEAR_SINGULAR_RTOL / 2
            k = manakov.kotter(p.a, p.b, l)
            back = manakov.from_kotter(p.a, p.b, k)
            err = np.max(np.abs(back - l)) / np.max(np.abs(l))
            ref = near.analyse(p.a, l)
            d_err = max(abs(k.d[j] - ref["d"][j]) / abs(ref["d"][j]) for j in range(3))
            z_ref = sorted(ref["z"], key=abs)
            z_got = sorted([k.z1, k.z2], key=abs)
            z_err = max(abs(z_got[i] - z_ref[i]) / abs(z_ref[i]) for i in range(2))
            print(
                f"delta {delta:.0e}: |d_4| {abs(ref['d4']):.0e}, round trip {err:.1e} "
                f"(floor {ref['floor']:.1e}), d {d_err:.1e}, z {z_err:.1e} "
                f"(kappa u {ref['kappa'] * u:.1e})"
            )
            assert err <= ROUND_TRIP_DD
            assert d_err <= D_TOL
            assert z_err <= Z_COND_FACTOR * ref["kappa"] * u + D_TOL


# A state of the near_degenerate top at delta = 4.0e-12 (tests/data/kotter_singular_sweep.py,
# seed 5), closer than NEAR_SINGULAR_RTOL: there the reduction may raise, naming the
# distance. The inverse map of the curve failed on it while the roots of F were polished
# by one double-double step; with the polish carried to convergence it reduces and
# round-trips.
BELOW_THRESHOLD_STATE = [
    -1.2028637427359297,
    0.6684849012179198,
    0.6114108374158704,
    0.6114102776813882,
    -0.6684850382383362,
    -1.2028666987849503,
]


def test_states_closer_than_the_threshold_raise_naming_it() -> None:
    p = manakov.problem("near_degenerate")
    try:
        k = manakov.kotter(p.a, p.b, BELOW_THRESHOLD_STATE)
    except ValueError as e:
        assert re.search(r"relative distance .* from the singular set h1\^2 = 4 h0\^2", str(e))
    else:
        back = manakov.from_kotter(p.a, p.b, k)
        size = np.max(np.abs(BELOW_THRESHOLD_STATE))
        assert np.max(np.abs(back - BELOW_THRESHOLD_STATE)) <= ROUND_TRIP_DD * size
    # below DEGENERATE_RTOL, every state: delta ~ 1e-14 on each shared top
    rng = np.random.default_rng(23)
    for name in PROBLEM_NAMES:
        q = manakov.problem(name)
        m = rng.normal(size=3)
        n = m + 1e-7 * np.linalg.norm(m) * rng.normal(size=3) / np.sqrt(3)
        l = np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])
        with pytest.raises(ValueError, match=r"h1\^2 - 4 h0\^2 = .* vanishes"):
            manakov.kotter(q.a, q.b, l)
