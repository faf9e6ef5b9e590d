"""The top: vector field (1), bracket (3), Hamiltonian (4)-(5), integrals (6)-(7), so(n).

Every reference here is an independent numpy/mpmath computation written in this
file; the integrator used for the erratum evidence is scipy's, not ours.
"""

# The state is called l, as in the paper.
# ruff: noqa: E741
from __future__ import annotations

import itertools

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import manakov

PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]

# Vector field, bracket, Hamiltonian: a few roundings of O(1) products -> 1e-14
# relative to the size of the terms.
RTOL_FIELD = 1e-14
# Conservation along 100 time units of Gauss steps (~300-500 steps): roundoff
# grows like sqrt(steps) * eps ~ 2e-15; 2e-14 of the integral's term scale
# leaves a factor ~10 for the constants.
CONSERVATION_TOL = 2e-14
# The printed H3 of (7) changes by O(1) (0.55 on 'generic' over t = 5): any
# change above 1e-3 is far beyond the integrator's error.
PRINTED_H3_MIN_CHANGE = 1e-3
# scipy DOP853 at rtol = atol = 1e-13 over t = 5 keeps true integrals to ~1e-12.
SCIPY_CONSERVATION_TOL = 1e-10
# c_ij of (2): two differences and one quotient, each rounded: <= 1.5 eps = 3.3e-16.
RTOL_C = 1e-15
# The integrals are sums of six O(1) products with O(1) coefficients: a few
# roundings of the largest term, ~1e-15; 1e-14 relative (1e-15 absolute near 0).
RTOL_INTEGRALS = 1e-14
ATOL_INTEGRALS = 1e-15
# (15) against 40-digit mpmath: the double-precision integrals carry ~1e-15 of
# the scale s^2 h1; the printed (7) is off by O(1) (> 1e-3 of that scale).
RTOL_15 = 1e-14
PRINTED_15_MIN_ERROR = 1e-3
# A general Frahm top over t = 20 (~100-200 gauss16 steps): roundoff ~ sqrt(steps) eps
# times the term scale; 1e-13 of max(1, |I|) leaves a factor ~10.
FRAHM_CONSERVATION_TOL = 1e-13
# Manakov's integrals by an exact polynomial fit on k+1 nodes in numpy: the
# Vandermonde solve loses a few digits, 1e-10 relative.
RTOL_MANAKOV_FIT = 1e-10
# tr (l + lambda A)^k holds products of up to n entries: roundoff ~ n sqrt(steps) eps.
SO_N_CONSERVATION_TOL = 1e-13
# The lambda-terms [l, B] + [A, omega] of the so(n) Lax equation: differences of O(n)
# products of rounded c, a, b, l: 1e-13 of their size.
LAX_TERM_TOL = 1e-13


# --- independent numpy implementation -------------------------------------


def np_matrix(l, n):
    iu = np.triu_indices(n, 1)
    L = np.zeros(l.shape[:-1] + (n, n))
    L[..., iu[0], iu[1]] = l
    L[..., iu[1], iu[0]] = -l
    return L


def np_c(a, b):
    n = len(a)
    c = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            if i != j:
                c[i, j] = (b[i] - b[j]) / (a[i] - a[j])
    return c


def np_vector_field(c, l, n):
    """(1) literally: l_dot_ij = sum_k (l_ik w_kj - w_ik l_kj), w = c * l."""
    L = np_matrix(l, n)
    W = c * L
    D = L @ W - W @ L
    iu = np.triu_indices(n, 1)
    return D[..., iu[0], iu[1]]


def np_poisson(l, n):
    """(3) literally."""
    L = np_matrix(l, n)
    d = np.eye(n)
    pairs = list(zip(*np.triu_indices(n, 1)))
    P = np.zeros((len(pairs), len(pairs)))
    for p, (i, j) in enumerate(pairs):
        for q, (k, m) in enumerate(pairs):
            P[p, q] = L[i, m] * d[j, k] - L[i, k] * d[j, m] + L[j, k] * d[i, m] - L[j, m] * d[i, k]
    return P


def complement(j, k):
    return [x for x in range(4) if x not in (j, k)]


def np_integrals_printed(a, l):
    """H2, H3 of (7) AS PRINTED: sum (a_j + a_k) l_jk^2, sum a_j a_k l_jk^2."""
    h2 = sum((a[j] + a[k]) * l[..., p] ** 2 for p, (j, k) in enumerate(PAIRS))
    h3 = sum(a[j] * a[k] * l[..., p] ** 2 for p, (j, k) in enumerate(PAIRS))
    return h2, h3


def np_integrals_corrected(a, l):
    """H0 (6) as printed; H1; H2, H3 with the complementary pair {l, m}."""
    h0 = l[..., 0] * l[..., 5] + l[..., 3] * l[..., 2] + (-l[..., 1]) * l[..., 4]
    h1 = np.sum(l**2, axis=-1)
    h2 = sum(sum(a[complement(j, k)]) * l[..., p] ** 2 for p, (j, k) in enumerate(PAIRS))
    h3 = sum(np.prod(a[complement(j, k)]) * l[..., p] ** 2 for p, (j, k) in enumerate(PAIRS))
    return h0, h1, h2, h3


def term_scales(a, c, l):
    """Sum of |terms| of each integral: the natural size against which roundoff is measured."""
    x = l**2
    comp = [complement(j, k) for j, k in PAIRS]
    return {
        "H0": abs(l[0] * l[5]) + abs(l[3] * l[2]) + abs(l[1] * l[4]),
        "H1": np.sum(x),
        "H2": sum(abs(sum(a[cp])) * x[p] for p, cp in enumerate(comp)),
        "H3": sum(abs(np.prod(a[cp])) * x[p] for p, cp in enumerate(comp)),
        "H": 0.5 * sum(abs(c[j, k]) * x[p] for p, (j, k) in enumerate(PAIRS)),
    }


# --- (1), (3), (4), (5) ------------------------------------------------------


def test_vector_field_matches_numpy(reference_problem):
    p = reference_problem
    top = manakov.ManakovTop(p.a, p.b)
    rng = np.random.default_rng(7)
    ls = np.vstack([p.l0, rng.normal(size=(20, 6))])
    c = np_c(p.a, p.b)
    want = np_vector_field(c, ls, 4)
    got = top.vector_field(ls)
    scale = np.max(np.abs(c)) * np.sum(ls**2, axis=1, keepdims=True)
    assert np.all(np.abs(got - want) <= RTOL_FIELD * scale)


def test_c_matches_formula_2(reference_problem):
    p = reference_problem
    top = manakov.ManakovTop(p.a, p.b)
    np.testing.assert_allclose(top.c, np_c(p.a, p.b), rtol=RTOL_C, atol=0)
    assert np.array_equal(top.c, top.c.T) and np.all(np.diag(top.c) == 0)


def test_near_degenerate_c12_is_correctly_rounded():
    """c12 = (b1 - b2)/(a1 - a2) of the given doubles, to the last bit (mpmath at 50 digits)."""
    p = manakov.problem("near_degenerate")
    top = manakov.ManakovTop(p.a, p.b)
    with mp.workdps(50):
        exact = (mp.mpf(p.b[0]) - mp.mpf(p.b[1])) / (mp.mpf(p.a[0]) - mp.mpf(p.a[1]))
        assert top.c[0, 1] == float(exact)
        # Against the decimal inputs the conditioning |a1|/|a1 - a2| = 1e6 costs
        # 6 of 16 digits: 1e-16 * 1e6 * (a few) < 1e-9.
        decimal = (mp.mpf("0.3") - mp.mpf("0.300002")) / (mp.mpf("1.0") - mp.mpf("1.000001"))
        assert abs(top.c[0, 1] - float(decimal)) < 1e-9 * 2


def test_poisson_tensor_matches_formula_3():
    rng = np.random.default_rng(3)
    for n in (3, 4, 5):
        l = rng.normal(size=n * (n - 1) // 2)
        got = manakov.poisson_tensor(l)
        # Every entry of (3) is 0 or +-l_q (at most one delta term survives): exact.
        np.testing.assert_array_equal(got, np_poisson(l, n))
        assert np.array_equal(got, -got.T)


def test_equation_1_is_the_hamiltonian_flow_5_of_4_sign_included(reference_problem):
    """l_dot_q = {H, l_q} = sum_p dH/dl_p P[p, q] with P of (3) and H of (4); + sign as printed."""
    p = reference_problem
    top = manakov.ManakovTop(p.a, p.b)
    c = np_c(p.a, p.b)
    rng = np.random.default_rng(11)
    for l in [p.l0, *rng.normal(size=(5, 6))]:
        grad_h = np.array([c[j, k] * l[q] for q, (j, k) in enumerate(PAIRS)])  # dH/dl of (4)
        xh = grad_h @ np_poisson(l, 4)
        f = top.vector_field(l)
        scale = np.max(np.abs(c)) * np.sum(l**2)
        assert np.max(np.abs(xh - f)) <= RTOL_FIELD * scale
        # The opposite sign would be wrong by 2|f|, far above roundoff:
        assert np.max(np.abs(-xh - f)) > 1e3 * RTOL_FIELD * scale


def test_hamiltonian_is_formula_4(reference_problem):
    p = reference_problem
    top = manakov.ManakovTop(p.a, p.b)
    c = np_c(p.a, p.b)
    want = 0.5 * sum(c[j, k] * p.l0[q] ** 2 for q, (j, k) in enumerate(PAIRS))
    assert top.hamiltonian(p.l0) == pytest.approx(want, rel=RTOL_FIELD)


# --- integrals (6)-(7) -----------------------------------------------------


def test_integrals_match_numpy_corrected_forms(reference_problem):
    p = reference_problem
    top = manakov.ManakovTop(p.a, p.b)
    ints = top.integrals(p.l0)
    assert list(ints) == ["H0", "H1", "H2", "H3", "H"]
    want = np_integrals_corrected(p.a, p.l0)
    for name, w in zip(("H0", "H1", "H2", "H3"), want):
        assert ints[name] == pytest.approx(w, rel=RTOL_INTEGRALS, abs=ATOL_INTEGRALS)


def test_every_integral_is_conserved(reference_problem):
    """Along our gauss16 trajectory to t = 100, measured with the numpy forms of this file."""
    p = reference_problem
    top = manakov.ManakovTop(p.a, p.b)
    tr = top.integrate(p.l0, 100.0, sample_every=1.0)
    c = np_c(p.a, p.b)
    scales = term_scales(p.a, c, p.l0)
    h0, h1, h2, h3 = np_integrals_corrected(p.a, tr.l)
    h = 0.5 * sum(c[j, k] * tr.l[:, q] ** 2 for q, (j, k) in enumerate(PAIRS))
    for name, v in zip(("H0", "H1", "H2", "H3", "H"), (h0, h1, h2, h3, h)):
        drift = np.max(np.abs(v - v[0])) / scales[name]
        assert drift <= CONSERVATION_TOL, (p.name, name, drift)


def _scipy_generic(t_end):
    p = manakov.problem("generic")
    c = np_c(p.a, p.b)
    sol = solve_ivp(
        lambda t, y: np_vector_field(c, y, 4),
        (0, t_end),
        p.l0,
        method="DOP853",
        rtol=1e-13,
        atol=1e-13,
    )
    return p, sol.y.T


def test_erratum_7_printed_h3_is_not_conserved():
    """(7) as printed, H3 = sum a_j a_k l_jk^2, changes by O(1) along a scipy solution."""
    p, ys = _scipy_generic(5.0)
    _, h3_printed = np_integrals_printed(p.a, ys)
    change = abs(h3_printed[-1] - h3_printed[0])
    assert change > PRINTED_H3_MIN_CHANGE
    # ... while the corrected forms are conserved along the same solution.
    for v in np_integrals_corrected(p.a, ys):
        assert np.max(np.abs(v - v[0])) < SCIPY_CONSERVATION_TOL


def test_erratum_7_printed_h2_is_conserved_but_a_combination():
    """Printed H2 = sum (a_j + a_k) l_jk^2 is conserved: it equals e1 H1 - H2_corrected."""
    p, ys = _scipy_generic(5.0)
    h2_printed, _ = np_integrals_printed(p.a, ys)
    _, h1, h2, _ = np_integrals_corrected(p.a, ys)
    assert np.max(np.abs(h2_printed - h2_printed[0])) < SCIPY_CONSERVATION_TOL
    np.testing.assert_allclose(h2_printed, np.sum(p.a) * h1 - h2, rtol=RTOL_INTEGRALS)


def schottky_f(a, l, s):
    """f(s) = sum_j l_j(s)^2 from (12)-(13) with l_j(s) = sqrt(s_j4) m_j + sqrt(s_kl) n_j."""
    L = {}
    for q, (i, j) in enumerate(PAIRS):
        L[i, j], L[j, i] = l[q], -l[q]
    total = mp.mpf(0)
    for j, k, m in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):  # cyclic (j, k, l), 0-based
        mj, nj = L[k, m], L[j, 3]
        sj4 = (s - a[j]) * (s - a[3])
        skl = (s - a[k]) * (s - a[m])
        total += (mp.sqrt(sj4) * mj + mp.sqrt(skl) * nj) ** 2
    return total


@pytest.mark.parametrize("s", [4.0, 5.5, 10.0])
def test_generating_function_15_holds_with_corrected_7_and_fails_as_printed(s):
    """(15): f(s) = h1 s^2 - h2 s + h3 + 2 h0 sqrt(G(s)); s > max a_i so every root is real."""
    p = manakov.problem("generic")
    rng = np.random.default_rng(5)
    for l in [p.l0, *rng.normal(size=(3, 6))]:
        with mp.workdps(40):
            a = [mp.mpf(x) for x in p.a]
            f = schottky_f(a, [mp.mpf(x) for x in l], mp.mpf(s))
            g = mp.sqrt(mp.fprod(mp.mpf(s) - x for x in a))
            top = manakov.ManakovTop(p.a, p.b)
            h = top.integrals(l)
            corrected = h["H1"] * s**2 - h["H2"] * s + h["H3"] + 2 * h["H0"] * g
            h2p, h3p = np_integrals_printed(p.a, l)
            printed = h["H1"] * s**2 - h2p * s + h3p + 2 * h["H0"] * g
            scale = float(mp.fabs(f)) + s**2 * h["H1"]
            assert abs(float(f - corrected)) <= RTOL_15 * scale
            assert abs(float(f - printed)) > PRINTED_15_MIN_ERROR * scale


def test_integrals_of_a_frahm_top_are_casimirs_and_energy():
    rng = np.random.default_rng(2)
    c = rng.normal(size=(4, 4))
    c = c + c.T
    top = manakov.FrahmTop(c)
    tr = top.integrate(rng.normal(size=6), 20.0, sample_every=1.0)
    for name in ("H0", "H1", "H"):
        v = tr.integrals[name]
        assert np.max(np.abs(v - v[0])) <= FRAHM_CONSERVATION_TOL * max(1.0, abs(v[0]))


# --- so(n) ---------------------------------------------------------------


def np_manakov_integrals(a, l, n):
    """Coefficients of lambda^j in tr (l + lambda A)^k, by exact polynomial fit on k+1 nodes."""
    L = np_matrix(l, n)
    A = np.diag(a)
    out = {}
    for k in range(2, n + 1):
        lams = np.arange(k + 1, dtype=float) - k / 2
        vals = [np.trace(np.linalg.matrix_power(L + lam * A, k)) for lam in lams]
        coef = np.linalg.solve(np.vander(lams, k + 1, increasing=True), vals)
        for j in range(k - 1):
            if (k - j) % 2 == 0:
                out[(k, j)] = coef[j]
    return out


@pytest.mark.parametrize("n", [3, 5, 6])
def test_so_n_vector_field_and_manakov_integrals(n):
    rng = np.random.default_rng(n)
    a = np.sort(rng.uniform(0, 3, n)) + np.arange(n) * 0.2
    b = rng.normal(size=n)
    top = manakov.ManakovTop(a, b)
    l0 = rng.normal(size=n * (n - 1) // 2)
    c = np_c(a, b)
    f = top.vector_field(l0)
    np.testing.assert_allclose(
        f, np_vector_field(c, l0, n), rtol=0, atol=RTOL_FIELD * np.abs(c).max() * np.sum(l0**2) * n
    )
    labels = top.manakov_integral_labels()
    want = np_manakov_integrals(a, l0, n)
    assert sorted(labels) == sorted(want)
    got = top.manakov_integrals(l0)
    for i, lab in enumerate(labels):
        assert got[i] == pytest.approx(want[lab], rel=RTOL_MANAKOV_FIT, abs=RTOL_MANAKOV_FIT)
    tr = top.integrate(l0, 20.0, sample_every=1.0)
    vals = top.manakov_integrals(tr.l)
    scale = np.max(np.abs(vals), axis=0) + 1.0
    drift = np.max(np.abs(vals - vals[0]), axis=0) / scale
    assert np.all(drift <= SO_N_CONSERVATION_TOL), drift


def test_so4_manakov_integrals_are_functions_of_h0_to_h3():
    """n = 4: the k = 3, j = 1 coefficient is 3 tr(l^2 A) = -3 * printed H2; k = 2: -2 H1."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    vals = dict(zip(top.manakov_integral_labels(), top.manakov_integrals(p.l0)))
    h2p, _ = np_integrals_printed(p.a, p.l0)
    assert vals[(2, 0)] == pytest.approx(-2 * np.sum(p.l0**2), rel=RTOL_INTEGRALS)
    assert vals[(3, 1)] == pytest.approx(-3 * h2p, rel=RTOL_INTEGRALS)


# --- hypothesis -------------------------------------------------------------

finite = st.floats(-3, 3, allow_nan=False, allow_infinity=False)


@st.composite
def tops(draw):
    gaps = draw(st.lists(st.floats(0.05, 2.0), min_size=4, max_size=4))
    a = np.cumsum(gaps) + draw(st.floats(-2, 2))
    b = np.array(draw(st.lists(finite, min_size=4, max_size=4)))
    l = np.array(draw(st.lists(finite, min_size=6, max_size=6)))
    return a, b, l


@settings(max_examples=200, deadline=None)
@given(tops())
def test_property_field_flow_and_conservation_laws(data):
    a, b, l = data
    top = manakov.ManakovTop(a, b)
    c = np_c(a, b)
    f = top.vector_field(l)
    scale = (np.abs(c).max() + 1) * (np.sum(l**2) + 1)
    assert np.max(np.abs(f - np_vector_field(c, l, 4))) <= RTOL_FIELD * scale
    grad_h = np.array([c[j, k] * l[q] for q, (j, k) in enumerate(PAIRS)])
    assert np.max(np.abs(grad_h @ np_poisson(l, 4) - f)) <= RTOL_FIELD * scale
    # dI/dt = grad I . f = 0 for each corrected integral (gradients written out).
    comp = [complement(j, k) for j, k in PAIRS]
    grads = {
        "H0": np.array([l[5], -l[4], l[3], l[2], -l[1], l[0]]),
        "H1": 2 * l,
        "H2": np.array([2 * sum(a[cp]) * l[q] for q, cp in enumerate(comp)]),
        "H3": np.array([2 * np.prod(a[cp]) * l[q] for q, cp in enumerate(comp)]),
    }
    amax = np.max(np.abs(a)) + 1
    for name, g in grads.items():
        bound = RTOL_FIELD * 10 * scale * amax**2 * np.sum(np.abs(l))
        assert abs(g @ f) <= bound, name


def test_to_from_matrix_round_trip():
    rng = np.random.default_rng(0)
    l = rng.normal(size=(3, 2, 10))
    m = manakov.to_matrix(l)
    assert m.shape == (3, 2, 5, 5)
    np.testing.assert_array_equal(m, -np.swapaxes(m, -1, -2))
    np.testing.assert_array_equal(manakov.from_matrix(m), l)
    for i, j in itertools.combinations(range(5), 2):
        assert m[0, 0, i, j] == l[0, 0, list(itertools.combinations(range(5), 2)).index((i, j))]
    with pytest.raises(ValueError):
        manakov.from_matrix(np.ones((4, 4)))


@st.composite
def so_n_tops(draw):
    n = draw(st.integers(3, 7))
    gaps = draw(st.lists(st.floats(0.05, 2.0), min_size=n, max_size=n))
    a = np.cumsum(gaps)
    b = np.array(draw(st.lists(finite, min_size=n, max_size=n)))
    l = np.array(draw(st.lists(finite, min_size=n * (n - 1) // 2, max_size=n * (n - 1) // 2)))
    return n, a, b, l


@settings(max_examples=100, deadline=None)
@given(so_n_tops())
def test_property_so_n_lax_pair_and_field(data):
    """(1)-(2) on so(n) is the Lax equation d/dt (l + λA) = [l + λA, ω + λB]: the λ-terms
    [l, B] + [A, ω] vanish identically when c is (2); and (1) matches numpy."""
    n, a, b, l = data
    top = manakov.ManakovTop(a, b)
    L = np_matrix(l, n)
    W = top.c * L
    A, B = np.diag(a), np.diag(b)
    lam_term = L @ B - B @ L + A @ W - W @ A
    cmax = np.abs(top.c).max() + 1
    scale = cmax * (np.abs(a).max() + np.abs(b).max() + 1) * (np.abs(l).max() + 1)
    assert np.max(np.abs(lam_term)) <= LAX_TERM_TOL * scale
    f = top.vector_field(l)
    want = np_vector_field(np_c(a, b), l, n)
    assert np.max(np.abs(f - want)) <= RTOL_FIELD * n * cmax * (np.sum(l**2) + 1)


@pytest.mark.parametrize("n", [16, 17])
def test_large_n_paths_match_numpy(n):
    """n <= 16 uses a stack copy of the skew matrix, n > 16 index arithmetic: both are (1)."""
    rng = np.random.default_rng(n)
    a = np.arange(n, dtype=float) + rng.uniform(0, 0.5, n)
    b = rng.normal(size=n)
    top = manakov.ManakovTop(a, b)
    l = rng.normal(size=(3, n * (n - 1) // 2))
    c = np_c(a, b)
    want = np_vector_field(c, l, n)
    scale = n * np.abs(c).max() * np.max(np.abs(l)) ** 2
    assert np.max(np.abs(top.vector_field(l) - want)) <= RTOL_FIELD * scale
