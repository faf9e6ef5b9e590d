"""manakov.HyperellipticCurve: periods, tau, Abel map, Riemann constant, inversion.

Independent references:

* ``tests/data/abel_ref.py`` (mpmath, 30 digits, real branch points, its own
  homology basis): the period lattice must be the same lattice (our cycles are
  integer symplectic combinations of the reference's) and the Abel integrals
  must agree modulo that lattice.
* Basis-free identities: Riemann's bilinear relations; genus 1: ``j(tau)``
  (mpmath ``jtheta``) against the j-invariant of the branch points' cross
  ratio; genus 2: the theta-constant invariants I3, I5, I10 (weight-0
  Siegel modular functions, hence independent of the basis) unchanged under a
  Moebius map of the branch points (an isomorphic curve); the theta divisor
  ``theta(u(P) + K) = 0``; the Wurzelfunktionen (27)-(28) as theta quotients
  (34) with the characteristics of the branch points (docs/theta_quotients.md).
"""

from __future__ import annotations

import itertools
import sys
from functools import lru_cache
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import manakov
from manakov import HyperellipticCurve

sys.path.insert(0, str(Path(__file__).parent / "data"))
import abel_ref  # noqa: E402

#: Random curves of genus 2 per degree (5 and 6): 2 x 100 = 200 curves.
N_CURVES = 100

#: tau symmetric (raw A^{-1} B, before symmetrising), relative to |tau|.
#: Measured <= ~1e-15; the issue asks 1e-14.
SYM_RTOL = 1e-14

#: Riemann's first bilinear relation A B^T - B A^T = 0, relative to |A||B|;
#: the issue asks 1e-13.
BILINEAR_RTOL = 1e-13

#: Genus 1: j(tau) against the j-invariant of the cubic/quartic, relative.
J_RTOL = 1e-12

#: Genus 2: theta-constant invariants before/after a Moebius map (issue: 1e-11).
INVARIANT_RTOL = 1e-11

#: Near-degenerate curves: the same checks at 1e-12 relative (issue).
NEAR_RTOL = 1e-12

#: Abel map by two different routes, modulo the lattice (issue: 1e-13).
PATH_ATOL = 1e-13

#: theta(u(P) + K) relative to the largest of the 16 theta values (issue: 1e-13).
THETA_DIVISOR_RTOL = 1e-13

#: Jacobi inversion round trip, on x relative to the scale of the branch points
#: (issue: 1e-12 away from the theta divisor).
INVERT_RTOL = 1e-12

#: Agreement with the mpmath reference (periods as lattices, Abel integrals
#: modulo the lattice), relative to the period size.
REF_RTOL = 1e-13

#: (34) quotients constant over divisors, relative (docs/theta_quotients.md
#: measured <= 2.4e-13 with the reference Abel map; wrong characteristics spread
#: by >= 7e-2).
CONST_RTOL = 1e-10

#: A half period's doubled lattice coordinates are integers to this (tree
#: sums of half periods, ~1e-15).
HALF_PERIOD_ATOL = 1e-12

RNG_SEED = 20261123


def _rand_c(rng, size, r=2.0):
    return r * (rng.uniform(-1, 1, size) + 1j * rng.uniform(-1, 1, size))


def _random_curves(deg: int, n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed + deg)
    return [_rand_c(rng, deg) for _ in range(n)]


def _raw_tau(h: HyperellipticCurve) -> np.ndarray:
    a, b = h.periods
    return np.linalg.solve(a, b)


def _even_theta_invariants(tau: np.ndarray) -> np.ndarray:
    th = manakov.theta_all(np.zeros(2), tau)
    even = [i for i in range(16) if manakov.parity(i) == 1]
    t = th[even]
    s8 = np.sum(t**8)
    return np.array([np.sum(t**24) / s8**3, np.sum(t**40) / s8**5, np.prod(t**4) / s8**5])


def _moebius(e: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Images of the branch points (and of infinity for odd n) under x -> (ax+b)/(cx+d).

    A branch point sent to infinity is dropped (it becomes the branch point at
    infinity of the odd-degree image)."""
    a, b, c, d = m
    pts = list(e)
    out = []
    for x in pts:
        den = c * x + d
        if den != 0:
            out.append((a * x + b) / den)
    if len(e) % 2 == 1 and c != 0:
        out.append(a / c)
    return np.array(out)


def _check_siegel(h: HyperellipticCurve, rtol_sym: float) -> None:
    t = _raw_tau(h)
    assert np.max(np.abs(t - t.T)) <= rtol_sym * np.max(np.abs(t))
    assert np.all(np.linalg.eigvalsh(h.tau.imag) > 0)
    a, b = h.periods
    rel = np.max(np.abs(a @ b.T - b @ a.T)) / (np.max(np.abs(a)) * np.max(np.abs(b)))
    assert rel <= BILINEAR_RTOL, rel
    # Second relation: i (A B^H - B A^H) is Hermitian positive definite.
    hm = 1j * (a @ b.conj().T - b @ a.conj().T)
    assert np.max(np.abs(hm - hm.conj().T)) <= BILINEAR_RTOL * np.max(np.abs(hm))
    assert np.all(np.linalg.eigvalsh((hm + hm.conj().T) / 2) > 0)


# ---------------------------------------------------------------------------
# period matrix


@pytest.mark.parametrize("deg", [5, 6])
def test_tau_symmetric_and_bilinear_relations_random_genus2(deg):
    for e in _random_curves(deg, N_CURVES, RNG_SEED):
        _check_siegel(HyperellipticCurve(e), SYM_RTOL)


@pytest.mark.parametrize("n", [3, 4, 7, 8, 9, 10])
def test_tau_symmetric_other_genera(n):
    for e in _random_curves(n, 20, RNG_SEED):
        h = HyperellipticCurve(e)
        assert h.genus == (n - 1) // 2
        _check_siegel(h, SYM_RTOL)


def test_intersection_matrix_is_canonical_after_reduction():
    for n in range(3, 11):
        for e in _random_curves(n, 10, RNG_SEED + 1):
            h = HyperellipticCurve(e)
            g = h.genus
            c = h.intersection_matrix
            m = h.symplectic_basis
            j = np.block([[np.zeros((g, g)), np.eye(g)], [-np.eye(g), np.zeros((g, g))]])
            assert np.array_equal(m @ c @ m.T, j)
            assert abs(round(np.linalg.det(m))) == 1
            # The geometric C is checked independently of the reduction by the
            # bilinear relation of the raw loop periods: P C^{-1} P^T = 0.
            p = h.cycle_periods
            rel = p @ np.linalg.inv(c).T @ p.T
            assert np.max(np.abs(rel)) <= BILINEAR_RTOL * np.max(np.abs(p)) ** 2


def test_collinear_tree_is_the_chain_with_one_sign():
    """Real sorted branch points: loops around consecutive intervals meet once,
    all with the same sign (the pattern stated in abel_ref.py)."""
    h = HyperellipticCurve([0.0, 1.0, 2.5, 4.0, 7.0])
    edges = [tuple(sorted(map(int, ed))) for ed in h.cycle_edges]
    assert sorted(edges) == [(0, 1), (1, 2), (2, 3), (3, 4)]
    c = h.intersection_matrix
    order = np.argsort([ed[0] for ed in edges])
    c = c[np.ix_(order, order)]
    signs = {int(c[k, k + 1]) for k in range(3)}
    assert len(signs) == 1 and signs <= {1, -1}
    assert np.count_nonzero(c) == 6


def _j_of_tau(tau: complex) -> complex:
    with mp.workdps(30):
        q = mp.exp(1j * mp.pi * mp.mpc(tau))
        t2, t3, t4 = (mp.jtheta(k, 0, q) for k in (2, 3, 4))
        return complex(32 * (t2**8 + t3**8 + t4**8) ** 3 / (t2 * t3 * t4) ** 8)


def _j_of_roots(e) -> complex:
    e = [mp.mpc(complex(x)) for x in e]
    if len(e) == 3:
        lam = (e[2] - e[0]) / (e[1] - e[0])
    else:
        lam = ((e[2] - e[0]) * (e[3] - e[1])) / ((e[2] - e[1]) * (e[3] - e[0]))
    return complex(256 * (lam**2 - lam + 1) ** 3 / (lam**2 * (lam - 1) ** 2))


@pytest.mark.parametrize("n", [3, 4])
def test_genus1_j_invariant(n):
    for e in _random_curves(n, 20, RNG_SEED + 2):
        h = HyperellipticCurve(e)
        jt, je = _j_of_tau(h.tau[0, 0]), _j_of_roots(e)
        assert abs(jt - je) <= J_RTOL * abs(je)


def _random_moebius(rng) -> np.ndarray:
    while True:
        m = _rand_c(rng, 4, 1.0)
        if abs(m[0] * m[3] - m[1] * m[2]) > 0.3:
            return m


def _invariants_agree(e1, e2, rtol, normwise=False):
    """I3, I5, I10 agree entrywise to rtol, or (near-degenerate curves) to
    rtol times the largest of them: there I10 ~ discriminant -> 0 (one even theta
    constant ~ sqrt(gap)), and its entrywise accuracy is that of the theta
    constants, not of tau."""
    i1 = _even_theta_invariants(HyperellipticCurve(e1).tau)
    i2 = _even_theta_invariants(HyperellipticCurve(e2).tau)
    scale = np.max(np.abs(i1)) if normwise else np.abs(i1)
    assert np.all(np.abs(i1 - i2) <= rtol * scale), (i1, i2)


@pytest.mark.parametrize("deg", [5, 6])
def test_theta_constant_invariants_under_moebius(deg):
    rng = np.random.default_rng(RNG_SEED + 3)
    for e in _random_curves(deg, 40, RNG_SEED + 4):
        _invariants_agree(e, _moebius(e, _random_moebius(rng)), INVARIANT_RTOL)


@pytest.mark.parametrize("deg", [5, 6])
def test_theta_constant_invariants_branch_point_to_infinity(deg):
    """Send e_1 to infinity (degree 6 -> 5, and 5 -> 5 with infinity made finite)."""
    rng = np.random.default_rng(RNG_SEED + 5)
    for e in _random_curves(deg, 20, RNG_SEED + 6):
        a, b = _rand_c(rng, 2, 1.0)
        m = np.array([a, b, 1.0, -e[0]])  # c x + d vanishes at e_1
        if abs(a * (-e[0]) - b) < 0.3:
            continue
        e2 = _moebius(e, m)
        assert len(e2) == 5  # e_1 -> infinity; for odd deg, infinity -> a (finite)
        _invariants_agree(e, e2, INVARIANT_RTOL)


@pytest.mark.parametrize("gap", [1e-3, 1e-6])
@pytest.mark.parametrize("deg", [5, 6])
def test_near_degenerate_pairs(gap, deg):
    rng = np.random.default_rng(RNG_SEED + 7)
    for e in _random_curves(deg, 10, RNG_SEED + 8):
        e = e.copy()
        e[1] = e[0] + gap * np.exp(2j * np.pi * rng.uniform())
        h = HyperellipticCurve(e)
        _check_siegel(h, NEAR_RTOL)
        _invariants_agree(e, _moebius(e, _random_moebius(rng)), NEAR_RTOL, normwise=True)
        _check_theta_divisor(h, rng, 4)


@pytest.mark.parametrize("dist", [1e-3, 1e-6])
def test_branch_point_near_a_segment(dist):
    rng = np.random.default_rng(RNG_SEED + 9)
    for e in _random_curves(5, 10, RNG_SEED + 10):
        e = e.copy()
        t = rng.uniform(0.2, 0.8)
        nrm = 1j * (e[1] - e[0]) / abs(e[1] - e[0])
        e[2] = e[0] + t * (e[1] - e[0]) + dist * nrm
        h = HyperellipticCurve(e)
        _check_siegel(h, NEAR_RTOL)
        _invariants_agree(e, _moebius(e, _random_moebius(rng)), NEAR_RTOL, normwise=True)
        _check_theta_divisor(h, rng, 4)


# ---------------------------------------------------------------------------
# Abel map, Riemann constant, characteristics


def _check_theta_divisor(h, rng, npts):
    k = h.riemann_constant
    x = _rand_c(rng, npts, 3.0)
    sheet = rng.choice([-1, 1], npts)
    y = np.array([h.y(xx, sheet=int(s)) for xx, s in zip(x, sheet)])
    u = h.abel(x, y)
    th = manakov.theta_all(u + k, h.tau)
    assert np.all(np.abs(th[:, 0]) <= THETA_DIVISOR_RTOL * np.max(np.abs(th), axis=-1))


@pytest.mark.parametrize("deg", [5, 6])
def test_theta_vanishes_on_abel_image_plus_k(deg):
    rng = np.random.default_rng(RNG_SEED + 11)
    for e in _random_curves(deg, 30, RNG_SEED + 12):
        _check_theta_divisor(HyperellipticCurve(e), rng, 10)


def test_theta_divisor_at_large_x_and_near_branch_points():
    rng = np.random.default_rng(RNG_SEED + 13)
    for e in _random_curves(5, 10, RNG_SEED + 14):
        h = HyperellipticCurve(e)
        x = np.concatenate(
            [
                _rand_c(rng, 4, 1e6),
                e + 1e-9 * np.exp(2j * np.pi * rng.uniform(size=5)),
            ]
        )
        y = h.y(x) * rng.choice([-1, 1], x.size)
        th = manakov.theta_all(h.abel(x, y) + h.riemann_constant, h.tau)
        assert np.all(np.abs(th[:, 0]) <= THETA_DIVISOR_RTOL * np.max(np.abs(th), axis=-1))


@pytest.mark.parametrize("deg", [5, 6])
def test_abel_path_independent(deg):
    """The ray from infinity and the segments from two branch points agree mod the lattice."""
    rng = np.random.default_rng(RNG_SEED + 15)
    for e in _random_curves(deg, 20, RNG_SEED + 16):
        h = HyperellipticCurve(e)
        x = _rand_c(rng, 6, 2.5)
        y = h.y(x) * rng.choice([-1, 1], 6)
        u0 = h._abel(x, y, -1)
        for k in (0, deg - 1):
            d = h.reduce(h._abel(x, y, k) - u0)
            assert np.max(np.abs(d)) <= PATH_ATOL


@pytest.mark.parametrize("deg", [5, 6])
def test_branch_points_are_the_stated_half_periods(deg):
    rng = np.random.default_rng(RNG_SEED + 17)
    for e in _random_curves(deg, 20, RNG_SEED + 18):
        h = HyperellipticCurve(e)
        g = h.genus
        ub = h.abel_branch_points
        hp = h.branch_half_periods
        chars = h.branch_chars
        # u(e_k) is (b + tau a)/2 modulo the lattice.
        assert np.max(np.abs(h.reduce(ub - hp[: len(e)]))) <= HALF_PERIOD_ATOL
        # The 2g+2 characteristics (with infinity) are distinct and sum to 0.
        rows = chars if deg % 2 == 1 else np.vstack([chars, np.zeros(2 * g, np.uint8)])
        if deg % 2 == 1:
            assert len({tuple(r) for r in rows}) == len(rows)
            assert np.all(rows.sum(axis=0) % 2 == 0)
        # The tree sums against the ray from infinity: 1e-4 from e_k, the
        # segment from e_k (u(e_k) + a short integral) and the ray from
        # infinity (no tree involved) agree modulo the lattice. (Closer, the
        # ray's x(t) - e_k = X + t^2 (c - e_k) cancels: its error grows like
        # eps/sqrt|x - e_k|; the segment from e_k is the route used there.)
        for k in range(len(e)):
            x = np.array([e[k] + 1e-4 * np.exp(2j * np.pi * rng.uniform())])
            y = h.y(x)
            d = h.reduce(h._abel(x, y, -1) - h._abel(x, y, k))
            assert np.max(np.abs(d)) <= PATH_ATOL


def test_riemann_constant_is_odd_sum_of_branch_chars_genus2():
    """Degree 5: K is an odd characteristic and equals eta(e_i)+eta(e_j)+eta(e_k)
    for some three branch points (classically e1+e3+e5 in the chain basis)."""
    for e in _random_curves(5, 20, RNG_SEED + 19):
        h = HyperellipticCurve(e)
        a, b = h.riemann_constant_char
        assert (a @ b) % 2 == 1
        ch = h.branch_chars[:5].astype(int)
        kk = np.concatenate([a, b]).astype(int)
        assert any(
            np.array_equal((ch[i] + ch[j] + ch[k]) % 2, kk)
            for i, j, k in itertools.combinations(range(5), 3)
        )


# ---------------------------------------------------------------------------
# Jacobi inversion


@pytest.mark.parametrize("deg", [5, 6])
def test_inversion_round_trip(deg):
    rng = np.random.default_rng(RNG_SEED + 20)
    for e in _random_curves(deg, 30, RNG_SEED + 21):
        h = HyperellipticCurve(e)
        x = _rand_c(rng, (5, 2), 2.5)
        y = h.y(x) * rng.choice([-1, 1], (5, 2))
        u = h.abel(x, y).sum(axis=-2)
        xi, yi = h.invert(u)
        for r in range(5):
            direct = np.abs(xi[r] - x[r]).max()
            swapped = np.abs(xi[r][::-1] - x[r]).max()
            perm = slice(None) if direct <= swapped else slice(None, None, -1)
            assert np.max(np.abs(xi[r][perm] - x[r])) <= INVERT_RTOL * np.max(np.abs(e))
            assert np.allclose(yi[r][perm], y[r], rtol=1e-9)
        assert np.max(np.abs(h.reduce(h.abel(xi, yi).sum(-2) - u))) <= PATH_ATOL


def test_inversion_on_theta_divisor_is_a_value_error():
    h6 = HyperellipticCurve(_random_curves(6, 1, RNG_SEED + 22)[0])
    x = 0.3 + 0.7j
    with pytest.raises(ValueError, match="theta divisor"):
        h6.invert(h6.abel(x, h6.y(x)) + h6.abel(x, -h6.y(x)))  # P + iota P
    h = HyperellipticCurve(_random_curves(5, 1, RNG_SEED + 22)[0])
    with pytest.raises(ValueError, match="theta divisor"):
        h.invert(np.zeros(2))  # P + iota P
    x = 0.3 + 0.7j
    with pytest.raises(ValueError, match="theta divisor"):
        h.invert(h.abel(x, h.y(x)))  # P + infinity


# ---------------------------------------------------------------------------
# the independent mpmath reference (real branch points)

REF_CURVES = {"simple": (1.0, 2.0, 3.0), "generic": (3.19671, -1.85468, -14.10493)}


def _lattice_coords(per: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Real coordinates of v (g,) on the 2g period columns of per (g, 2g)."""
    m = np.vstack([per.real, per.imag])
    return np.linalg.solve(m, np.concatenate([v.real, v.imag]))


@lru_cache(maxsize=4)
def _ref(name):
    d = REF_CURVES[name]
    a_mat, b_mat, _, _ = abel_ref.periods(d)
    per = np.array([[complex(m[i, j]) for m in (a_mat, b_mat) for j in range(2)] for i in range(2)])
    return d, per


@pytest.mark.parametrize("name", list(REF_CURVES))
def test_periods_span_the_reference_lattice(name):
    d, per_ref = _ref(name)
    h = manakov.KotterCurve(*d).surface
    a, b = h.periods
    per = np.hstack([a, b])
    n = np.array([_lattice_coords(per_ref, per[:, j]) for j in range(4)])
    assert np.max(np.abs(n - np.round(n))) <= REF_RTOL * 1e2  # integer change of basis
    n = np.round(n).astype(int)
    j = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.eye(2), np.zeros((2, 2))]])
    assert np.array_equal(n @ j @ n.T, j)  # symplectic: both bases canonical
    assert np.max(np.abs(per - per_ref @ n.T)) <= REF_RTOL * np.max(np.abs(per))
    i_ref = _even_theta_invariants(np.linalg.solve(per_ref[:, :2], per_ref[:, 2:]))
    assert np.all(np.abs(_even_theta_invariants(h.tau) - i_ref) <= INVARIANT_RTOL * np.abs(i_ref))


@pytest.mark.parametrize("name", list(REF_CURVES))
def test_abel_agrees_with_reference_mod_lattice(name):
    d, per_ref = _ref(name)
    h = manakov.KotterCurve(*d).surface
    a, _ = h.periods
    e = [float(v) for v in abel_ref.branch_points(d)]
    scale = max(abs(v) for v in e)
    rng = np.random.default_rng(RNG_SEED + 23)
    for _ in range(6):
        x = complex(rng.uniform(-scale, scale), rng.choice([-1, 1]) * rng.uniform(0.1, 1) * scale)
        sigma = int(rng.choice([-1, 1]))
        y = sigma * complex(abel_ref.y_principal(x, abel_ref.branch_points(d)))
        ref = np.array([complex(v) for v in abel_ref.abel_unnormalised(d, x, sigma)])
        ours = a @ h.abel(x, y)
        c = _lattice_coords(per_ref, ours - ref)
        assert np.max(np.abs(c - np.round(c))) <= REF_RTOL * 1e2


# ---------------------------------------------------------------------------
# (34)-(35) through the API on complex curves


def _complex_kotter_curves():
    rng = np.random.default_rng(RNG_SEED + 24)
    return [tuple(_rand_c(rng, 3, 1.5)) for _ in range(4)]


@pytest.mark.parametrize("d", _complex_kotter_curves())
def test_34_quotients_constant_on_complex_curves(d):
    """(P_j theta(v)/theta[eta(d_j)](v))^2 and (P_jk theta(v)/theta[eta(d_j)+eta(d_k)](v))^2
    are constant over divisors, v = u + K; no other characteristic is.

    Squared: on complex curves the canonical branch of the P_j (principal roots,
    eps = +1) jumps across the cuts z in d_j + (-inf, 0], so the quotient itself
    is constant only up to the sign eps_j of the branch (docs/curve.md)."""
    kc = manakov.KotterCurve(*d)
    h = kc.surface
    rng = np.random.default_rng(RNG_SEED + 25)
    ndiv = 12
    x = _rand_c(rng, (ndiv, 2), 2.0)
    y = h.y(x) * rng.choice([-1, 1], (ndiv, 2))
    v = h.abel(x, y).sum(-2) + h.riemann_constant
    th = manakov.theta_all(v, h.tau)
    w = kc.wurzel(x[:, 0], y[:, 0], x[:, 1], y[:, 1])
    ch = h.branch_chars.astype(int)

    def spread(vals, idx):
        q = (vals * th[:, 0] / th[:, idx]) ** 2
        return np.max(np.abs(q - q[0])) / np.abs(q[0])

    def index(c):
        return int(c @ (1 << np.arange(3, -1, -1)))

    for j in range(5):
        idx = index(ch[j])
        assert spread(w.P[:, j], idx) <= CONST_RTOL
        assert all(spread(w.P[:, j], o) > 1e-3 for o in range(16) if o != idx)
    for j, k in itertools.combinations(range(5), 2):
        idx = index((ch[j] + ch[k]) % 2)
        assert spread(w.Pjk[:, j, k], idx) <= CONST_RTOL


# ---------------------------------------------------------------------------
# API and bad input


def test_api_shapes_scalars_and_read_only():
    h = HyperellipticCurve([0, 1 + 0.3j, -0.7 + 1.1j, 2 - 0.5j, 0.4 - 1.3j])
    assert h.genus == 2 and h.base_point == "infinity"
    assert isinstance(h.y(0.5), complex)
    assert h.abel(0.5, h.y(0.5)).shape == (2,)
    x = np.full((3, 4), 0.5 + 0.1j)
    assert h.abel(x, h.y(x)).shape == (3, 4, 2)
    for arr in (h.tau, h.periods[0], h.branch_points, h.riemann_constant):
        assert not arr.flags.writeable
    e = np.array([0, 1, 2, 3, 4, 5], dtype=complex)
    e0 = e.copy()
    h6 = HyperellipticCurve(e)
    assert np.array_equal(e, e0) and h6.base_point == 0
    x = np.array([0.5 + 0.5j])
    xc = x.copy()
    h.abel(x, h.y(x))
    assert np.array_equal(x, xc)
    assert manakov.KotterCurve(1.0, 2.0, 3.0).surface.genus == 2


@pytest.mark.parametrize(
    "e, match",
    [
        ([0, 1, 1, 2, 3], "coincide"),
        ([0, 1, np.nan, 2, 3], "finite"),
        ([0, 1, np.inf, 2, 3], "finite"),
        ([0, 1], "shape"),
        (np.zeros((2, 3)), "1-d"),
        (list(range(15)), "shape"),
        (["a", "b", "c"], "numeric"),
        ([0, 1, 2, 1e130, 5], "too large"),
    ],
)
def test_bad_branch_points(e, match):
    with pytest.raises(ValueError, match=match):
        HyperellipticCurve(e)


def test_bad_points_and_u():
    h = HyperellipticCurve([0, 1 + 0.3j, -0.7 + 1.1j, 2 - 0.5j, 0.4 - 1.3j])
    with pytest.raises(ValueError, match="not on the curve"):
        h.abel(0.5, 2 * h.y(0.5))
    with pytest.raises(ValueError, match="finite"):
        h.abel(np.nan, 0.0)
    with pytest.raises(ValueError, match="shape"):
        h.abel([0.5, 0.6], [h.y(0.5)] * 3)
    with pytest.raises(ValueError, match="shape"):
        h.invert(np.zeros(3))
    with pytest.raises(ValueError):
        h.invert(np.array([np.nan, 0.0]))
    with pytest.raises(ValueError, match="sheet"):
        h.y(0.5, sheet=2)
    # Large |x|: fine while y ~ x^(5/2) is a finite double, then a ValueError.
    big = 1e100 * (0.6 + 0.8j)
    th = manakov.theta_all(h.abel(big, h.y(big)) + h.riemann_constant, h.tau)
    assert abs(th[0]) <= THETA_DIVISOR_RTOL * np.max(np.abs(th))
    # y itself overflows there (|y|^2 ~ 1e1000): refused by y, not returned as inf.
    with pytest.raises(ValueError, match="overflows"):
        h.y(1e200)
    with pytest.raises(ValueError, match="too large"):
        h.abel(1e200, 1e250)
    with pytest.raises(ValueError, match="branch point"):
        h.abel(h.branch_points[1], 1.0)
    # At a branch point, y = 0 is the point; its image is the stated half period.
    u = h.abel(h.branch_points[1], 0.0)
    assert np.max(np.abs(h.reduce(u - h.branch_half_periods[1]))) <= HALF_PERIOD_ATOL
    h3 = HyperellipticCurve(np.arange(7.0) + 0.5j * np.arange(7.0) ** 2)
    with pytest.raises(ValueError, match="genus 2"):
        h3.invert(np.zeros(3))
    with pytest.raises(ValueError, match="shape"):
        h3.invert(np.zeros(2))


def _local_integral_mp(e: np.ndarray, k: int, dx: complex, w_end: complex) -> list:
    """``int_{e_k}^{e_k + dx} x^i dx / y`` (i = 0, 1) by mpmath at 40 digits, in the
    local parameter ``x = e_k + s^2``: ``y = s w(s)`` with ``w^2 = prod_{m != k}
    (x - e_m)``, ``w`` continued from ``w_end`` at ``s = sqrt(dx)`` (``|dx|`` is far
    below the distances to the other branch points, so ``w`` stays near its value
    at ``s = 0``)."""
    with mp.workdps(40):
        ek = mp.mpc(e[k])
        others = [mp.mpc(v) for j, v in enumerate(e) if j != k]
        s_end = mp.sqrt(mp.mpc(dx))
        w_ref = mp.mpc(w_end)

        def w(s):
            r = mp.sqrt(mp.fprod(ek + s * s - em for em in others))
            return r if abs(r - w_ref) <= abs(r + w_ref) else -r

        return [
            mp.quad(lambda t, i=i: 2 * s_end * (ek + (t * s_end) ** 2) ** i / w(t * s_end), [0, 1])
            for i in range(2)
        ]


@pytest.mark.parametrize("r", [1e-3, 1e-8, 1e-13])
def test_abel_near_branch_against_mpmath_local_integral(r):
    """``abel_near_branch(k, dx, y) = u(e_k) + A^{-1} int_{e_k}^{e_k+dx} omega`` with
    the integral from mpmath (40 digits) in the local parameter, on both sheets,
    to REF_RTOL modulo the lattice, down to |dx| = 1e-13 where the double
    ``x = e_k + dx`` has lost the offset to ~1e-3 relative."""
    e = np.array([0, 1 + 0.3j, -0.7 + 1.1j, 2 - 0.5j, 0.4 - 1.3j])
    h = HyperellipticCurve(e)
    a_per, _ = h.periods
    scale = np.max(np.abs(h.tau))
    for k in (1, 3):
        ek = h.branch_points[k]
        for phi in (0.3, 2.1):
            dx = r * np.exp(1j * phi)
            with mp.workdps(40):
                w_end = complex(
                    mp.sqrt(mp.fprod(mp.mpc(ek) + mp.mpc(dx) - mp.mpc(v) for v in np.delete(e, k)))
                )
                s = complex(mp.sqrt(mp.mpc(dx)))
            for sheet in (1, -1):
                y = sheet * s * w_end
                got = h.abel_near_branch(k, dx, y)
                integral = np.array([complex(v) for v in _local_integral_mp(e, k, dx, w_end)])
                want = h.abel_branch_points[k] + sheet * np.linalg.solve(a_per, integral)
                err = np.max(np.abs(h.reduce(got - want)))
                assert err <= REF_RTOL * scale, (k, phi, sheet, err)


def test_abel_near_branch_shapes_and_bad_input():
    h = HyperellipticCurve([0, 1 + 0.3j, -0.7 + 1.1j, 2 - 0.5j, 0.4 - 1.3j])
    dx = np.array([[1e-4, 1e-4j], [-1e-4, 2e-4]])
    ek = h.branch_points[2]
    y = h.y(ek + dx)
    u = h.abel_near_branch(2, dx, y)
    assert u.shape == (2, 2, 2)
    # Where the offset is well above roundoff of x, it agrees with abel.
    assert np.max(np.abs(h.reduce(u - h.abel(ek + dx, y)))) <= REF_RTOL * np.max(np.abs(h.tau))
    for k in (-1, 5, 1.0, True):
        with pytest.raises(ValueError, match="k must be"):
            h.abel_near_branch(k, 1e-4, h.y(h.branch_points[0] + 1e-4))
    with pytest.raises(ValueError, match="not on the curve"):
        h.abel_near_branch(2, 1e-4, 2 * h.y(ek + 1e-4))
    with pytest.raises(ValueError, match="finite"):
        h.abel_near_branch(2, np.nan, 0.0)
    with pytest.raises(ValueError, match="shape"):
        h.abel_near_branch(2, [1e-4, 2e-4], [0.1, 0.2, 0.3])
