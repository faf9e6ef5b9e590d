"""The Theorem (9)-(10) as code: ``top.solve(l0)`` against integration (docs/theorem.md).

References are independent of the theta side: the gauss16 integrator of (1)
and the Abel map of the states it produces; for ``U`` in closed form, the mpmath
reference ``tests/data/closed_u_reference.py``.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest
from former_outliers import EPS41_OTHER_COMBINATION

import manakov

sys.path.insert(0, str(Path(__file__).parent / "data"))
import closed_u_reference as closed_ref  # noqa: E402

#: Issue 10: max over 201 times in [0, 100] of |l_theta - l_int| / |l0|. The
#: gauss16 reference at dt = 1e-3 is good to ~3e-14 there (roundoff of 1e5 steps).
SHORT_RTOL = 1e-11
#: Issue 10 at t = 1e4 (gauss16 at dt = 1e-2, itself good to ~1e-11).
T1E4_RTOL = 1e-9
#: Issue 10 for random states on [0, 20].
RANDOM_RTOL = 1e-10
#: The confirmed integration in double-double against gauss16 in double at
#: dt = 1e-3 on a well-conditioned state over |t| <= 3: both are accurate to
#: ~1e-15 there; a hundredfold margin.
INTEGRATED_RTOL = 1e-13
#: sol.abel(l_int(t)) - u0 - U t lies in the period lattice to this (lattice
#: coordinates; Abel integrals ~1e-15, integration ~1e-14 over [0, 2]).
AFFINE_TOL = 1e-12
#: Slope of the unwrapped Abel image against U, relative.
SLOPE_RTOL = 1e-12


def _params() -> list:
    return ["generic", "physical", "wide", "near_degenerate"]


def _lattice(tau: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real (x, y) with z = x + tau y."""
    y = np.linalg.solve(tau.imag, z.imag)
    return z.real - tau.real @ y, y


@pytest.mark.parametrize("name", _params())
def test_theorem_matches_integration_on_0_100(name: str) -> None:
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    sol = top.solve(p.l0)
    t = np.linspace(0.0, 100.0, 201)
    l_int = top.integrate(p.l0, 100.0, t_eval=t, dt=1e-3).l
    err = np.max(np.abs(sol.l(t) - l_int)) / np.linalg.norm(p.l0)
    assert err <= SHORT_RTOL, err


@pytest.mark.slow
@pytest.mark.parametrize("name", ["generic", "physical", "wide"])
def test_theorem_matches_integration_at_1e4(name: str) -> None:
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    sol = top.solve(p.l0)
    tr = top.integrate(p.l0, 1e4, t_eval=np.array([0.0, 1e4]), dt=1e-2)
    err = np.max(np.abs(sol.l(1e4) - tr.l[-1])) / np.linalg.norm(p.l0)
    assert err <= T1E4_RTOL, err


@pytest.mark.parametrize("name", ["generic", "physical", "wide", "near_degenerate"])
def test_abel_image_is_affine_with_slope_U(name: str) -> None:
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    sol = top.solve(p.l0)
    t = np.linspace(0.0, 2.0, 21)
    l_int = top.integrate(p.l0, 2.0, t_eval=t, dt=1e-3).l
    u = np.array([sol.abel(li) for li in l_int])
    assert np.allclose(u[0], sol.u0, rtol=0, atol=1e-13)
    tau = sol.tau
    x, y = _lattice(tau, (u - sol.u0[None, :] - t[:, None] * sol.U[None, :]).T)
    assert np.max(np.abs(x - np.round(x))) <= AFFINE_TOL
    assert np.max(np.abs(y - np.round(y))) <= AFFINE_TOL
    # unwrap by the lattice vectors and fit the slope (least squares, independent of U)
    uw = u - (np.round(x).T + np.round(y).T @ tau.T)
    a = np.vstack([np.ones_like(t), t]).T
    coef, *_ = np.linalg.lstsq(a, uw, rcond=None)
    slope = coef[1]
    assert np.max(np.abs(slope - sol.U)) <= SLOPE_RTOL * np.max(np.abs(sol.U))


def test_shapes_and_attributes() -> None:
    p = manakov.problem("generic")
    sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    assert sol.l(0.5).shape == (6,)
    assert sol.l(np.zeros((3, 4))).shape == (3, 4, 6)
    np.testing.assert_allclose(sol.l(0.0), p.l0, rtol=0, atol=1e-13)
    assert sol.U.shape == (2,) and sol.u0.shape == (2,) and sol.tau.shape == (2, 2)
    np.testing.assert_allclose(sol.tau, sol.curve.tau, rtol=0, atol=1e-14)
    assert "U = [" in repr(sol) and "d = [" in repr(sol)


@pytest.mark.parametrize("name", ["generic", "wide"])
def test_repr_shows_the_branch_points_without_rounding_noise(name: str) -> None:
    # generic's d_j are real with ~1e-32 imaginary noise, wide's imaginary.
    p = manakov.problem(name)
    sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    shown = repr(sol).split("d = [")[1].split("]")[0].split(", ")
    d = sol.curve.branch_points
    assert len(shown) == len(d)
    for text, x in zip(shown, d):
        assert "e-" not in text, text
        assert abs(complex(text) - x) <= 1e-5 * max(abs(x), 1.0), (text, x)
    ch = sol.characteristics
    # chi_jk = chi_j + chi_k: P23 + P31 = P12 + 2 chi_3 ... check one closed relation
    s = [(ch["P23"][0][i] + ch["P31"][0][i] + ch["P12"][0][i]) % 2 for i in range(2)]
    assert len(set(map(tuple, [v[0] + v[1] for v in ch.values()]))) == 7
    assert s in ([0, 0], [1, 1], [0, 1], [1, 0])
    assert set(sol.constants) == set(manakov.solution.LABELS)
    with pytest.raises(ValueError):
        sol.l(np.nan)


def test_characteristics_are_branch_point_half_periods() -> None:
    """chi_j = eta(d_j) from the curve's own Abel map of the branch points."""
    p = manakov.problem("physical")
    sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    curve = sol.curve
    eta = [curve.branch_char(j) for j in range(5)]

    def add(j: int, k: int) -> tuple:
        return tuple(
            tuple(int((eta[j][s][i] + eta[k][s][i]) % 2) for i in range(2)) for s in range(2)
        )

    ch = sol.characteristics
    assert ch["P0"] == tuple(tuple(int(v) for v in eta[0][s]) for s in range(2))
    assert ch["P23"] == add(2, 3) and ch["P31"] == add(3, 1) and ch["P12"] == add(1, 2)
    assert ch["P14"] == add(1, 4) and ch["P24"] == add(2, 4) and ch["P34"] == add(3, 4)


@pytest.mark.parametrize(
    "l0, kind",
    [
        (np.zeros(6), "rest"),
        (np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]), "equilibrium"),
        # m = n (self-dual): l = (m3, -m2, n1, m1, n2, n3) with m = n = (0.3, 0.5, 0.7)
        (np.array([0.7, -0.5, 0.3, 0.3, 0.5, 0.7]), "euler"),
    ],
)
def test_states_the_theorem_does_not_cover_get_their_kind(l0: np.ndarray, kind: str) -> None:
    # Once refused (l0 = 0, an equilibrium, h1^2 = 4 h0^2); now solved in closed
    # form (docs/degenerate.md, tests/test_degenerate.py).
    p = manakov.problem("generic")
    sol = manakov.ManakovTop(p.a, p.b).solve(l0)
    assert sol.kind == kind
    with pytest.raises(AttributeError, match=f"kind '{kind}'"):
        _ = sol.U


def test_singular_genus2_states_name_the_reason() -> None:
    # n = (1 + 2^-30) m: within 1e-13 of h1^2 = 4 h0^2 but not exactly self-dual,
    # so a genus-2 state on the Theorem's singular set: a valid state without a
    # closed form (kind "integrated", not ValueError), saying why, with
    # h1^2 - 4 h0^2 from its exact factors h1 - 2 h0 = 0.83 * 2^-60 and
    # h1 + 2 h0 = 3.32 (not the 0 that the difference h1^2 - 4 h0^2 cancels to).
    # Its l(t) is the confirmed integration, with a warning; its frequencies are
    # the interpolation from the self-dual Euler orbit (docs/degenerate.md §11).
    p = manakov.problem("generic")
    e = 1 + 2**-30
    l0 = np.array([0.7, -0.5, 0.3 * e, 0.3, 0.5 * e, 0.7 * e])
    top = manakov.ManakovTop(p.a, p.b)
    sol = top.solve(l0)
    assert sol.kind == "integrated" and not sol.self_check_passed
    assert re.search(r"h1\^2 - 4 h0\^2 = 2\.39\d*e-18 vanishes", repr(sol)), repr(sol)
    t = np.linspace(-2.0, 3.0, 11)
    with pytest.warns(manakov.IntegratedValuesWarning, match="vanishes"):
        lt = sol.l(t)
    assert sol.integrated_calls == 1
    # backwards in time: the flow of -c, the top (a, -b)
    back = manakov.ManakovTop(p.a, -np.asarray(p.b))
    ref = np.vstack(
        [
            back.integrate(l0, 2.0, t_eval=-t[t < 0][::-1], dt=1e-3).l[::-1],
            top.integrate(l0, 3.0, t_eval=t[t >= 0], dt=1e-3).l,
        ]
    )
    assert np.max(np.abs(lt - ref)) / np.linalg.norm(l0) <= INTEGRATED_RTOL
    fm = manakov.frequency_map(top, l0[None, :])
    assert manakov.tori.STATUS_NAMES[int(fm.status[0])] == "ok"
    assert np.array_equal(sol.frequencies, fm.nu[0])


def test_random_states_small() -> None:
    """The default-run version of tests/data/theorem_random_stats.py (seed differs);
    that script's 1000-state draw reaches 1e-10 on 99.8 % (docs/theorem.md)."""
    rng = np.random.default_rng(20261123)
    ok = 0
    for _ in range(12):
        a = np.sort(rng.uniform(0.0, 5.0, 4))
        b = rng.normal(size=4)
        l0 = rng.normal(size=6)
        top = manakov.ManakovTop(a, b)
        sol = top.solve(l0)
        t = np.linspace(0.0, 20.0, 41)
        l_int = top.integrate(l0, 20.0, t_eval=t, dt=2e-3).l
        err = np.max(np.abs(sol.l(t) - l_int)) / np.linalg.norm(l0)
        assert err <= RANDOM_RTOL, (a, b, l0, err)
        ok += 1
    assert ok == 12


#: (9)-(10) as printed misses l0 by O(1) (the test asks for > 10 % of |l0|).
PRINTED_MISS = 0.1
#: The corrected form reproduces l0 at t = 0 (rounding of the chain, 1e-14 measured).
AT_L0_RTOL = 1e-12


@pytest.mark.parametrize("name", ["generic", "physical", "wide"])
def test_9_10_printed_fails_corrected_holds_at_l0(name: str) -> None:
    """(9)-(10) printed: m_j = g (alpha_j f_kl + beta_j f_j4), n_j = g (gamma_j f_kl +
    delta_j f_j4) with f = theta[chi]/theta (no sqrt(c_j), no C_L); corrected: the
    same with f_L -> sqrt(c_j) C_L theta[chi_L]/theta. Both at v0, against l0."""
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    sol = top.solve(p.l0)
    k = top.kotter(p.l0)
    v0 = sol.u0 + sol.riemann_constant
    vals = manakov.theta_all(v0, sol.tau)
    ch = sol.characteristics
    th = vals[manakov.char_index([0, 0], [0, 0])]

    def q(label: str) -> complex:
        a, b = ch[label]
        return complex(vals[manakov.char_index(a, b)] / th)

    sc = np.sqrt(k.curve.c.astype(complex))
    cl = sol.constants
    kl = ["P23", "P31", "P12"]
    j4 = ["P14", "P24", "P34"]

    def state(corrected: bool) -> np.ndarray:
        m = np.zeros(3, complex)
        n = np.zeros(3, complex)
        for j in range(3):
            f1, f2 = q(kl[j]), q(j4[j])
            if corrected:
                f1, f2 = sc[j] * cl[kl[j]] * f1, sc[j] * cl[j4[j]] * f2
            m[j] = k.g * (k.alpha[j] * f1 + k.beta[j] * f2)
            n[j] = k.g * (k.gamma[j] * f1 + k.delta[j] * f2)
        return np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])

    scale = np.linalg.norm(p.l0)
    assert np.max(np.abs(state(False) - p.l0)) / scale > PRINTED_MISS
    assert np.max(np.abs(state(True) - p.l0)) / scale <= AT_L0_RTOL


# Random draws (a, b, l0 rounded to 8 digits) that used to fail: the first five were O(1)
# wrong from t ~ 1 on (the principal roots of (41) gave -1/(d4 eps) for eps, errata (41));
# the others have a nearly symmetric pair a_i ~ a_j (|U| ~ 30 .. 90) and branch points
# spread over 1e4 .. 1e9, where the single auxiliary divisor at the scale of the largest
# d_j lost 1e-10 of the C_L and U from unit-scaled xi, eta rows lost 1e-12 (1e-9 .. 2e-8
# of l at t = 20).
HARD_STATES = EPS41_OTHER_COMBINATION + [
    (
        [1.43653805, 1.67005671, 3.59982397, 4.0155284],
        [-1.95421118, -0.96886624, 0.66431291, 0.78986721],
        [0.73656422, -0.07086533, 0.45512082, 0.65302144, -0.07787127, 1.02730197],
    ),
    (
        [1.23170525, 3.53534416, 3.60983757, 3.67318223],
        [-1.11441348, -0.87778348, -0.86154831, 0.30921605],
        [-0.9121277, 0.12558428, 0.41142057, -0.74805318, 0.13387618, 1.67751912],
    ),
    (
        [0.83079265, 0.83740855, 1.55193176, 1.80762749],
        [-0.45125704, 0.79594225, -0.77408269, -0.93524993],
        [-1.45055552, 0.25858471, -0.05315905, -0.07711326, -0.40985213, 1.43788468],
    ),
    (
        [1.9539871, 1.99276701, 4.9184025, 4.96550024],
        [0.04313994, -1.0522692, 0.56622262, 0.26597436],
        [0.80836298, -0.25255993, 1.28179273, -0.58746697, 0.10462028, -1.28271228],
    ),
    (
        [0.6330243, 1.03663747, 3.14332767, 3.14592385],
        [-0.43113831, -0.60744538, -0.11556798, 0.68207463],
        [1.06781736, 0.19226591, -0.24098777, -0.01293266, 1.83246313, 0.8854083],
    ),
]


@pytest.mark.parametrize("a, b, l0", HARD_STATES)
def test_former_outliers(a: list, b: list, l0: list) -> None:
    top = manakov.ManakovTop(a, b)
    sol = top.solve(l0)
    t = np.linspace(0.0, 20.0, 41)
    l_int = top.integrate(l0, 20.0, t_eval=t, dt=2e-3).l
    err = np.max(np.abs(sol.l(t) - l_int)) / np.linalg.norm(l0)
    assert err <= RANDOM_RTOL


# --- U in closed form up to one scalar (docs/theorem.md, "The direction of U") ---

# Relative distance of V = A U from the line (1, M(mu_b)): U comes from the theta
# fit, M from the roots of F, eps and d_4 alone; agreement to ~1e-14 is measured
# on the shared tops (near_degenerate 1e-11: its constants, docs/kotter.md).
DIRECTION_RTOL = 1e-10


def _mobius_through(s, m):
    """Coefficients (alpha, beta, gamma, delta) of x = (alpha s + beta)/(gamma s + delta)
    with x(s_i) = m_i, i = 0, 1, 2 (null vector of a 3 x 4 system)."""
    rows = np.array([[si, 1.0, -mi * si, -mi] for si, mi in zip(s, m)], complex)
    return np.linalg.svd(rows)[2][-1].conj()


def _direction_check(a, b, l0):
    top = manakov.ManakovTop(a, b)
    k = top.kotter(l0)
    sol = top.solve(l0)
    s, eps = np.asarray(k.s), complex(k.eps)
    d4 = complex(np.prod(k.d))
    al, be, ga, de = _mobius_through(s[:3], [1 / eps, -1 / eps, -d4 * eps])
    # the fourth root goes to d_4 eps: the cross-ratio of the roots is (41)
    m4 = (al * s[3] + be) / (ga * s[3] + de)
    p = np.linalg.solve(np.vander(np.asarray(a, float), 4, increasing=True), b)
    # the top's flow is p2 X(a^2) + p3 X(a^3) = flow of H_mu at mu_b = e1 + p2/p3
    num = al * (p[3] * np.sum(a) + p[2]) + be * p[3]
    den = ga * (p[3] * np.sum(a) + p[2]) + de * p[3]
    A, _ = sol.curve.periods
    V = A @ sol.U
    miss = abs(V[1] * den - V[0] * num) / (np.linalg.norm(V) * np.hypot(abs(num), abs(den)))
    return abs(m4 - d4 * eps) / abs(d4 * eps), miss


@pytest.mark.parametrize("name", ["generic", "physical", "wide", "near_degenerate"])
def test_U_points_along_the_mobius_image_of_mu_b(name: str) -> None:
    p = manakov.problem(name)
    m4, miss = _direction_check(np.array(p.a), np.array(p.b), np.array(p.l0))
    assert m4 <= DIRECTION_RTOL
    assert miss <= DIRECTION_RTOL


def test_U_points_along_the_mobius_image_of_mu_b_on_random_states() -> None:
    rng = np.random.default_rng(2718)
    misses = []
    for _ in range(40):
        a = np.sort(rng.uniform(0.0, 5.0, 4))
        b = rng.normal(size=4)
        l0 = rng.normal(size=6)
        m4, miss = _direction_check(a, b, l0)
        misses.append(max(m4, miss))
    # measured on this draw: median 8.3e-14, max 2.2e-12
    assert max(misses) <= DIRECTION_RTOL


# --- U in closed form (docs/theorem.md, "U in closed form") ---

#: sol.U against X + tau Y of the 60-digit reference (exact V and exact periods of the
#: unrounded curve, in the package's homology basis): the issue's bound. The package
#: computes (X, Y) in double-double and rounds once; measured 0 (the same double) on
#: the four tops and the two random states here.
CLOSED_U_RTOL = 1e-15
#: The reference's own identities at 60 digits (third equation at each half period,
#: spread over the four half periods): exact up to the working precision.
IDENTITY_TOL = 1e-45

CLOSED_U_STATES = [
    (manakov.problem(n).a, manakov.problem(n).b, manakov.problem(n).l0)
    for n in ("generic", "physical", "wide", "near_degenerate")
] + [
    # a random state and a stiff one (a spacing 0.02, c up to 65)
    (
        [-0.62, 0.35, 1.41, 2.03],
        [0.81, -1.22, 0.47, 1.95],
        [0.37, -1.12, 0.58, 0.91, -0.44, 1.27],
    ),
    (
        [0.1, 0.12, 0.9, 2.4],
        [1.3, 0.0, -0.7, 0.6],
        [0.8, 0.3, -1.1, 0.5, 0.9, -0.2],
    ),
]


@pytest.mark.parametrize("a, b, l0", CLOSED_U_STATES)
def test_closed_form_identities_hold_in_the_reference(a, b, l0) -> None:
    """The derivation itself, package-free: at every half period d_0 + d_p the three
    vanishing labels give three consistent equations, and the four half periods give
    one V (up to the sign of their branches)."""
    with mpmath.workdps(closed_ref.DPS):
        lv = closed_ref.level(a, l0)
        vs = []
        for p in (1, 2, 3, 4):
            v, res, _ = closed_ref.velocity(a, b, l0, p, lv)
            assert res <= IDENTITY_TOL, (p, res)
            vs.append(v)
        scale = max(abs(vs[0][0]), abs(vs[0][1]))
        for v in vs[1:]:
            dev = min(max(abs(v[i] - s * vs[0][i]) for i in range(2)) for s in (1, -1))
            assert dev <= IDENTITY_TOL * scale


@pytest.mark.parametrize("a, b, l0", CLOSED_U_STATES)
def test_U_is_the_closed_form_of_the_reference(a, b, l0) -> None:
    sol = manakov.ManakovTop(a, b).solve(l0)
    c = sol.curve
    w, _, _ = closed_ref.exact_rates(a, b, l0, c.cycle_edges, c.symplectic_basis, c.cycle_periods)
    x = np.array([float(t) for t in w])
    u_ref = x[:2] + sol.tau @ x[2:]
    # the reference fixes no sign (the involution); the package's is that of the motion
    s = 1.0 if np.real(np.vdot(u_ref, sol.U)) > 0 else -1.0
    err = np.max(np.abs(sol.U - s * u_ref)) / np.max(np.abs(u_ref))
    assert err <= CLOSED_U_RTOL, err


#: frequency_map (the level set alone) and sol.frequencies (the solution): the issue's
#: bound; both take U, U' in closed form, measured equal to the last bit here.
FREQUENCY_AGREEMENT_RTOL = 1e-14


def test_frequency_map_and_solution_frequencies_agree() -> None:
    rng = np.random.default_rng(2207)
    a = np.sort(rng.uniform(0.0, 4.0, 4))
    b = rng.normal(size=4)
    top = manakov.ManakovTop(a, b)
    states = rng.normal(size=(60, 6))
    fm = manakov.frequency_map(top, states)
    ok = fm.status == 0
    assert ok.sum() >= 55
    for l0, nu in zip(states[ok], fm.nu[ok]):
        ref = top.solve(l0).frequencies
        assert np.max(np.abs(nu - ref)) <= FREQUENCY_AGREEMENT_RTOL * np.max(np.abs(ref))


def test_U_keeps_the_real_structure_exactly() -> None:
    """On 'wide' (imaginary branch points) the real torus is the one of real U: the
    lattice rates Y vanish by symmetry and are imposed exactly, so U = X has no
    imaginary part at all (it carried ~1e-15 before, a drift off the real torus)."""
    p = manakov.problem("wide")
    sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    assert np.all(sol.U.imag == 0.0), sol.U
