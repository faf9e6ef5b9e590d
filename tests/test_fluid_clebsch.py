# The paper's index names (j, k, l cyclic): E741 does not apply.
# ruff: noqa: E741
"""The Clebsch case in theta functions (docs/clebsch.md).

The conjugacy to a Manakov top is checked in exact rational arithmetic with no
package code; the closed form against the package's gauss16 integration (no
theta function on that side); the frequencies against a NAFF of integrated
trajectories (tests/naff.py); the contracted Schottky–Kötter chain by an
independent numpy implementation (tests/data/clebsch_contracted_chain.py); and
the contraction a4 → ∞ of the Manakov top against the closed form.
"""

from __future__ import annotations

import random
import sys
from fractions import Fraction
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import manakov

sys.path.insert(0, str(Path(__file__).parent / "data"))
import clebsch_contracted_chain as chain  # noqa: E402
import clebsch_random_stats as random_stats  # noqa: E402
import tori_naff  # noqa: E402

CLEBSCH = ["clebsch_generic", "clebsch_wide", "clebsch_isotropic", "clebsch_near_degenerate"]
CYC = ((0, 1, 2), (1, 2, 0), (2, 0, 1))

#: Must-show: closed form against integration on [0, 100] (201 times), relative
#: to max |y0|. The gauss16 reference at a tenth of the default step is good to
#: ~1e-14 there.
CLOSED_FORM_RTOL = 1e-11
#: Must-show on random states (tests/data/clebsch_random_stats.py runs 1000).
RANDOM_RTOL = 1e-10
#: Of those 100, draws whose l(t) the drift check refuses (docs/degenerate.md,
#: "Near the pinched sets"): draw 1, self-check defect 2.1e-12, at t = 48.
RANDOM_REFUSED_MAX = 1
#: The conjugate top's own check (manakov.Solution.self_check) on the four bodies:
#: they leave ≤ 1.3e-14; the Solution refuses only above 1e-10, so this bound sees
#: a loss of conditioning of the conjugacy long before a refusal would.
SELF_CHECK_MAX = 1e-12
#: Frequencies: every NAFF line ≥ 1e-6 of its component's largest is k·ν to this,
#: relative to max ν (tests/tori_naff.py).
LINE_RTOL = tori_naff.LINE_RTOL
#: The package's conjugacy X(L y) = L X_Kirchhoff(y), relative to |X|: the
#: rounding of α, β and of the field (a few ulps, amplified by the near pair's
#: gap on clebsch_near_degenerate).
CONJUGACY_RTOL = 1e-13


# --- the conjugacy, exactly ----------------------------------------------------


def _frahm_field(c, l):
    """Frahm's (1), l̇_ij = Σ_k l_ik l_kj (c_kj − c_ik), on 4 × 4 matrices (any field)."""
    n = 4
    out = [[0] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            out[i][j] = sum(l[i][k] * l[k][j] * (c[k][j] - c[i][k]) for k in range(n))
    return out


def _kirchhoff_diag(A, C, M, p):
    w = [A[i] * M[i] for i in range(3)]
    v = [C[i] * p[i] for i in range(3)]

    def cross(x, y):
        return [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]

    mw, pv, pw = cross(M, w), cross(p, v), cross(p, w)
    return [mw[i] + pv[i] for i in range(3)], pw


def _L(r, mu, M, p):
    """The map of docs/clebsch.md with α_j = r_j², λ = μ², as a 4 × 4 skew matrix
    (index 3 the image of ∞): X_kl = M_j/r_j, X_j4 = μ p_j/(r_k r_l)."""
    X = [[Fraction(0)] * 4 for _ in range(4)]
    for j, k, l in CYC:  # noqa: E741
        X[k][l], X[l][k] = M[j] / r[j], -M[j] / r[j]
        n = mu * p[j] / (r[k] * r[l])
        X[j][3], X[3][j] = n, -n
    return X


def test_conjugacy_is_exact_in_rational_arithmetic():
    """X_{α,β}(L y) = L X_Kirchhoff(y) with α_i = λ/(a_i − σ), α4 = 0,
    β_i = (ρ/λ) b_i α_i, β4 = 0, ρ = √(α1α2α3), A_i = (b_j − b_k)/(a_j − a_k), C_i = −b_i:
    an identity of polynomials, checked exactly at random rational points (√α_j = r_j
    and √λ = μ rational). Also the package's gauge of β (β_p = β_q = 0 on a pair,
    β4 = −ρ A_k, β_k = ρ (A_p − A_k)(α_q − α_k)/α_q) differs from this β by an affine
    function of α, which does not change (1)."""
    rnd = random.Random(5)

    def q():
        return Fraction(rnd.randint(-40, 40), rnd.randint(1, 13))

    for _ in range(25):
        r = [Fraction(rnd.randint(1, 30), rnd.randint(1, 9)) for _ in range(3)]
        mu, sigma = Fraction(rnd.randint(1, 20), rnd.randint(1, 7)), q()
        al = [x * x for x in r]
        lam = mu * mu
        if len(set(al)) < 3:
            continue
        a = [sigma + lam / x for x in al]
        b = [q() for _ in range(3)]
        A = [(b[j] - b[k]) / (a[j] - a[k]) for _, j, k in CYC]
        C = [-x for x in b]
        rho = r[0] * r[1] * r[2]
        alpha = al + [Fraction(0)]
        beta = [rho / lam * b[i] * al[i] for i in range(3)] + [Fraction(0)]
        c = [
            [(beta[i] - beta[j]) / (alpha[i] - alpha[j]) if i != j else 0 for j in range(4)]
            for i in range(4)
        ]
        M, p = [q() for _ in range(3)], [q() for _ in range(3)]
        lhs = _frahm_field(c, _L(r, mu, M, p))
        dM, dp = _kirchhoff_diag(A, C, M, p)
        assert lhs == _L(r, mu, dM, dp)
        # The package's gauge on the pair (p, q) = (1, 2), k = 0.
        k, pp, qq = 0, 1, 2
        g = [Fraction(0)] * 4
        g[3] = -rho * A[k]
        g[k] = rho * (A[pp] - A[k]) * (al[qq] - al[k]) / al[qq]
        g2k = rho * (A[qq] - A[k]) * (al[pp] - al[k]) / al[pp]
        assert g[k] == g2k  # the two expressions agree (Clebsch's condition)
        diff = [g[i] - beta[i] for i in range(4)]
        # Affine in α: the slope through (α_p, ·), (α_q, ·) predicts the other two.
        slope = (diff[pp] - diff[qq]) / (alpha[pp] - alpha[qq])
        for i in (k, 3):
            assert diff[i] == diff[pp] + slope * (alpha[i] - alpha[pp])


@pytest.mark.parametrize("name", CLEBSCH)
def test_package_conjugacy(name):
    pr = manakov.fluid_problem(name)
    body, top = pr.body, pr.body.conjugate_top
    assert top.a[0] == 0.0 and np.all(np.diff(top.a) > 0) and top.a[-1] == 1.0
    rng = np.random.default_rng(1)
    for _ in range(20):
        M, p = rng.normal(size=3), rng.normal(size=3)
        lhs = top.vector_field(body.to_so4(M, p))
        rhs = body.to_so4(*body.vector_field(M, p))
        assert np.max(np.abs(lhs - rhs)) <= CONJUGACY_RTOL * np.max(np.abs(rhs))
        back = body.from_so4(body.to_so4(M, p))
        np.testing.assert_allclose(np.concatenate(back), np.r_[M, p], rtol=4e-16, atol=0)


@pytest.mark.parametrize("name", CLEBSCH)
def test_direction_of_U_is_the_image_of_mu_c(name):
    """The top's μ_b = Σ α_i + p2/p3 (docs/theorem.md, the direction of U) is the
    Möbius image λ/(μ_c − σ) of the body's μ_c = a1 + a2 + a3 + q1/q2,
    b = −C = q0 + q1 a + q2 a²."""
    body = manakov.fluid_problem(name).body
    conj = body._clebsch
    a, b = conj.body_a, -np.diag(body.C)
    q = np.linalg.solve(np.vander(a, 3, increasing=True), b)
    sigma, lam = conj.mobius
    top = body.conjugate_top
    p = np.linalg.solve(np.vander(top.a, 4, increasing=True), top.b)
    mu_b = top.a.sum() + p[2] / p[3]
    if abs(q[2]) < 1e-14 * np.max(np.abs(q)):  # b linear in a: μ_c = ∞, μ_b = 0
        assert abs(mu_b) < 1e-14
        return
    mu_c = a.sum() + q[1] / q[2]
    assert mu_b == pytest.approx(lam / (mu_c - sigma), rel=1e-12, abs=1e-14)


# --- the closed form ---------------------------------------------------------


@pytest.mark.parametrize("name", CLEBSCH)
def test_closed_form_matches_integration_on_0_100(name):
    pr = manakov.fluid_problem(name)
    body = pr.body
    sol = body.solve(pr.M0, pr.p0)
    t = np.linspace(0.0, 100.0, 201)
    tr = body.integrate(pr.M0, pr.p0, 100.0, t_eval=t, dt=body.default_dt(pr.M0, pr.p0) / 10)
    M, p = sol.state(t)
    scale = max(np.max(np.abs(pr.M0)), np.max(np.abs(pr.p0)))
    err = max(np.max(np.abs(M - tr.M)), np.max(np.abs(p - tr.p))) / scale
    assert err <= CLOSED_FORM_RTOL, err
    assert sol.solution.self_check <= SELF_CHECK_MAX, sol.solution.self_check
    assert sol.solution.velocity_check <= SELF_CHECK_MAX, sol.solution.velocity_check
    np.testing.assert_allclose(sol.M(0.0), pr.M0, rtol=0, atol=1e-14 * scale)
    assert sol.M(t).shape == (201, 3) and sol.p(2.5).shape == (3,)
    # (M, p) is a quotient of theta functions of v0 + U t (the explicit form).
    idx, num, den = sol.quotient()
    for tk in (0.0, 7.5):
        v = sol.solution.u0 + sol.solution.riemann_constant + sol.U * tk
        chars = [manakov.CHARACTERISTICS[i] for i in idx]
        vals = [manakov.theta(v, sol.tau, char=c, log_scale=True) for c in chars]
        logs = np.array([complex(lg) for _, lg in vals])
        top = logs.real.max()
        th = np.array([complex(x) * np.exp(lg - top) for (x, _), lg in zip(vals, logs)])
        y = (num @ th / (den @ th)).real
        np.testing.assert_allclose(y, np.concatenate(sol.state(tk)), rtol=0, atol=1e-12 * scale)


def test_closed_form_on_random_states():
    """100 of the 1000 draws of tests/data/clebsch_random_stats.py (its own run:
    on [0, 100] 999 of 1000 returned, all within 1e-10, one refused by the drift
    check of l(t); on [0, 20] all 1000 within 1e-10)."""
    rng = np.random.default_rng(random_stats.SEED)
    errs, refused = [], 0
    for _ in range(100):
        try:
            errs.append(random_stats.error(*random_stats.draw(rng), 100.0))
        except manakov.ClosedFormError:
            refused += 1
    assert max(errs) <= RANDOM_RTOL, max(errs)
    assert refused <= RANDOM_REFUSED_MAX, refused


class _BodyAsTop:
    """The integrate(l0, T, sample_every=, method=).l interface of tests/tori_naff.py."""

    def __init__(self, body):
        self.body = body

    def integrate(self, y0, T, sample_every, method):
        tr = self.body.integrate(y0[:3], y0[3:], T, sample_every=sample_every, method=method)
        return SimpleNamespace(l=np.hstack([tr.M, tr.p]))


@pytest.mark.parametrize(
    "name",
    [
        "clebsch_generic",
        pytest.param("clebsch_wide", marks=pytest.mark.slow),  # ~1 min: ν1/ν2 = 39
        "clebsch_isotropic",
        "clebsch_near_degenerate",
    ],
)
def test_frequencies_match_naff_of_the_integration(name):
    pr = manakov.fluid_problem(name)
    sol = pr.body.solve(pr.M0, pr.p0)
    nu = sol.frequencies
    fm = pr.body.frequency_map(pr.M0, pr.p0)
    assert fm.status == 0 and np.max(np.abs(fm.nu - nu)) <= 1e-12 * nu.max()
    chk = tori_naff.check_lines(_BodyAsTop(pr.body), np.r_[pr.M0, pr.p0], nu, range(6))
    assert chk.generated, chk.ks
    assert chk.worst <= LINE_RTOL, chk.worst_line


# --- the contracted chain ------------------------------------------------------


def _original_top(body, M, p):
    """The conjugate top and state with the image of ∞ at index 4 (the index
    Schottky's vector (12) singles out), as the contraction has it."""
    conj = body._clebsch
    order = np.asarray(conj.order)
    al, be = np.empty(4), np.empty(4)
    al[order], be[order] = conj.alpha, conj.beta
    iu = np.triu_indices(4, 1)
    Ls = np.zeros((4, 4))
    Ls[iu] = body.to_so4(M, p)
    Ls -= Ls.T
    Lo = np.empty((4, 4))
    Lo[np.ix_(order, order)] = Ls
    return al, be, Lo[iu]


@pytest.mark.parametrize("name", CLEBSCH)
def test_contracted_chain(name):
    pr = manakov.fluid_problem(name)
    body = pr.body
    a = body._clebsch.body_a
    lam = body._clebsch.mobius[1]
    sigma = body._clebsch.mobius[0]
    red = chain.reduce(a, pr.M0, pr.p0)
    # (15) contracted: λ(s)² = h1 s² − h2 s + h3 + 2 h0 √G(s) at random s.
    rng = np.random.default_rng(3)
    h0, h1, h2, h3 = red["h"]
    for s in rng.normal(size=5) + 1j * rng.normal(size=5):
        q = np.sqrt(chain.G(a, s))
        lv = chain.schottky(a, pr.M0, pr.p0, s, q)
        assert abs(lv @ lv - (h1 * s * s - h2 * s + h3 + 2 * h0 * q)) < 1e-12 * (1 + abs(s)) ** 2
    # (21): l^(p) isotropic, Σ_p (l_k^(p))² = 0; the roots are those of F.
    lp = red["l_p"]
    assert np.max(np.abs(np.sum(lp * lp, axis=1))) < 1e-12 * np.max(np.abs(lp)) ** 2
    assert np.max(np.abs(np.sum(lp * lp, axis=0))) < 1e-12 * np.max(np.abs(lp)) ** 2
    # The Möbius image: f_e3(s) = (λ/t²) f_so4(t), s = σ + λ/t, for the conjugate
    # state with ∞ at index 4; the roots of F map to those of the so(4) F (19).
    al, be, lo = _original_top(body, pr.M0, pr.p0)
    k = manakov.kotter(al, be, lo)
    t_roots = lam / (red["s"] - sigma)
    assert np.max(np.min(np.abs(t_roots[:, None] - k.s[None, :]), axis=1)) < 1e-12 * np.max(
        np.abs(k.s)
    )
    for t in rng.normal(size=3) + 1j * rng.normal(size=3):
        ls, _ = manakov.reduction.schottky(al, lo, t)
        f4 = lam / t**2 * (ls @ ls)
        s = sigma + lam / t
        q = np.sqrt(chain.G(a, s))
        # On one of the two branches of √G(s) (which one follows the principal
        # roots on either side).
        f3 = [v @ v for v in (chain.schottky(a, pr.M0, pr.p0, s, x) for x in (q, -q))]
        assert min(abs(x - f4) for x in f3) < 1e-12 * (abs(f4) + abs(h0 * q))
    # The constants of the curve (8): the so(4) reduction's d_j up to the branch
    # choices acting on each j (d_j → ±d_j^{±1}).
    assert chain.same_up_to_branches(red["d"], k.d) < 1e-11
    # Kötter's quadrics (11) along the integrated motion with the constants of t = 0.
    tr = body.integrate(pr.M0, pr.p0, 20.0, sample_every=0.5)
    worst = max(
        np.max(np.abs(chain.quadrics(red["d"], *chain.xi_eta(red, m, q))))
        for m, q in zip(tr.M, tr.p)
    )
    assert worst < 1e-13, worst


def test_contraction_of_the_manakov_top():
    """The Manakov top a = (a1, a2, a3, a4), b = (b1, b2, b3, 0) with the state
    M = −(l23, l31, l12), p = l_i4/√a4 tends to the Clebsch body A_i =
    (b_j − b_k)/(a_j − a_k), C_i = −b_i as a4 → ∞, at the rate 1/a4: the
    trajectory, the frequencies and the reduction's roots and d_j (docs/clebsch.md §4)."""
    pr = manakov.fluid_problem("clebsch_generic")
    body = pr.body
    a3, b3 = body._clebsch.body_a, -np.diag(body.C)
    sol = body.solve(pr.M0, pr.p0)
    t = np.linspace(0.0, 20.0, 41)
    Mc, pc = sol.state(t)
    red = chain.reduce(a3, pr.M0, pr.p0)
    rows = []
    for k in range(2, 9):
        a4 = 10.0**k
        top = manakov.ManakovTop(np.r_[a3, a4], np.r_[b3, 0.0])
        m, n = -pr.M0, pr.p0 * np.sqrt(a4)
        l0 = np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])
        lt = top.integrate(l0, 20.0, t_eval=t).l
        M = -np.stack([lt[:, 3], -lt[:, 1], lt[:, 0]], axis=1)
        p = lt[:, [2, 4, 5]] / np.sqrt(a4)
        e_traj = max(np.max(np.abs(M - Mc)), np.max(np.abs(p - pc)))
        nu = top.solve(l0).frequencies
        e_nu = np.max(np.abs(nu - sol.frequencies)) / np.max(sol.frequencies)
        kk = manakov.kotter(top.a, top.b, l0)
        e_s = np.max(np.abs(np.sort_complex(kk.s) - np.sort_complex(red["s"])))
        e_d = chain.same_up_to_branches(red["d"], kk.d)
        rows.append([a4 * e_traj, a4 * e_nu, a4 * e_s, a4 * e_d])
    rows = np.array(rows)
    # Each error times a4 settles to a constant: rate exactly 1/a4 (to 1 % from
    # a4 = 1e3 on; at 1e8 the trajectory error is 6e-7, far above rounding).
    for col in rows.T:
        assert np.max(np.abs(col[1:] / col[-1] - 1)) < 0.01, col
    # The opposite sign, M = +(l23, l31, l12), follows the time-reversed motion.
    a4 = 1e8
    top = manakov.ManakovTop(np.r_[a3, a4], np.r_[b3, 0.0])
    n = pr.p0 * np.sqrt(a4)
    m = pr.M0
    lt = top.integrate(np.array([m[2], -m[1], n[0], m[0], n[1], n[2]]), 20.0, t_eval=t).l
    assert np.max(np.abs(np.stack([lt[:, 3], -lt[:, 1], lt[:, 0]], 1) - Mc)) > 0.1


@pytest.mark.parametrize("name", CLEBSCH)
def test_states_with_M_dot_p_zero_are_solved(name):
    """``M·p = 0`` is the conjugate top's ``h0 = 0``, a regular level set whose
    reduction takes its limit (rust/kotter/pairs.rs): generic such states are
    solved, and their closed form follows the integration as any other state's."""
    pr = manakov.fluid_problem(name)
    body = pr.body
    t = np.linspace(0.0, 20.0, 101)
    # Exactly M·p = 0 in doubles (products and sums of these entries are exact).
    for M0, p0 in (([1.0, 2.0, 0.0], [2.0, -1.0, 3.0]), ([0.5, 0.0, -1.0], [1.0, 0.75, 0.5])):
        M0, p0 = np.array(M0), np.array(p0)
        assert M0 @ p0 == 0.0
        sol = body.solve(M0, p0)
        tr = body.integrate(M0, p0, 20.0, t_eval=t, dt=body.default_dt(M0, p0) / 10)
        M, p = sol.state(t)
        scale = max(np.max(np.abs(M0)), np.max(np.abs(p0)))
        err = max(np.max(np.abs(M - tr.M)), np.max(np.abs(p - tr.p))) / scale
        assert err <= RANDOM_RTOL, err


@pytest.mark.parametrize("name", CLEBSCH)
def test_states_on_the_conjugate_tops_exact_sets_take_its_closed_form(name):
    """``M``, ``p`` on two axes (the conjugate state in an so(3) block) and ``p0 = 0``
    (Euler's top): the conjugate top's solution is its closed form (an Euler top in
    Jacobi's elliptic functions, or an equilibrium; docs/degenerate.md), which
    follows Kirchhoff's equations; the genus-2 attributes name the kind."""
    body = manakov.fluid_problem(name).body
    t = np.linspace(0.0, 20.0, 101)
    for M0, p0 in (([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), ([1.0, 0.5, 0.0], [0.0, 0.0, 0.0])):
        M0, p0 = np.array(M0), np.array(p0)
        sol = body.solve(M0, p0)
        kind = sol.solution.kind
        assert kind in ("euler", "equilibrium"), kind
        tr = body.integrate(M0, p0, 20.0, t_eval=t, dt=body.default_dt(M0, p0) / 10)
        M, p = sol.state(t)
        scale = max(np.max(np.abs(M0)), np.max(np.abs(p0)))
        err = max(np.max(np.abs(M - tr.M)), np.max(np.abs(p - tr.p))) / scale
        assert err <= CLOSED_FORM_RTOL, (M0, p0, err)
        with pytest.raises(AttributeError, match=f"kind '{kind}'"):
            _ = sol.U


def test_a_failed_self_check_is_not_turned_into_a_value_error(monkeypatch):
    """A conjugate top's solution refused by its own check (ClosedFormError) reaches
    the caller as it is: it is no statement about the state."""

    def refuse(*args):
        raise manakov.ClosedFormError("no trustworthy solution: self-check 1e-3")

    monkeypatch.setattr(manakov.fluid, "Solution", refuse)
    pr = manakov.fluid_problem("clebsch_generic")
    with pytest.raises(manakov.ClosedFormError, match="self-check"):
        pr.body.solve(pr.M0, pr.p0)


# --- refusals ----------------------------------------------------------------


def test_solve_refuses_other_bodies_and_singular_states():
    gen = manakov.fluid_problem("general")
    with pytest.raises(ValueError, match="Clebsch case only"):
        gen.body.solve(gen.M0, gen.p0)
    with pytest.raises(ValueError, match="Clebsch case only"):
        _ = gen.body.conjugate_top
    body = manakov.fluid_problem("clebsch_generic").body
    # 1e-13 off M·p = 0 beside two axes: a genus-2 state of the conjugate top
    # whose roots of F meet at a branch point of sqrt(G); found in the local
    # parameter there (docs/degenerate.md, "Near the pinched sets"), it is solved.
    M0, p0 = np.array([1.0, 1e-13, 0.0]), np.array([0.0, 1.0, 0.0])
    t = np.linspace(0.0, 20.0, 41)
    M, p = body.solve(M0, p0).state(t)
    tr = body.integrate(M0, p0, 20.0, t_eval=t, dt=body.default_dt(M0, p0) / 4)
    assert max(np.max(np.abs(M - tr.M)), np.max(np.abs(p - tr.p))) <= RANDOM_RTOL
    with pytest.raises(ValueError, match="finite"):
        body.solve([np.nan, 0, 0], [0, 1, 0])
    with pytest.raises(ValueError, match=r"shape \(3,\)"):
        body.solve(np.ones((2, 3)), [0, 1, 0])
