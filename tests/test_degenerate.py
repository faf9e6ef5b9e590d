# ruff: noqa: E741  (l is the paper's name for the state)
"""The states the genus-2 Theorem does not cover, solved in closed form
(docs/degenerate.md): Jacobi's elliptic functions against mpmath, the Euler
tops of the so(3) blocks and of the self-dual states against integration,
constant solutions, the invariances (scale of l, shift of a, b = α a + β), the
dispatcher's kinds and errors, and the frequencies of Euler motions against the
genus-2 frequencies of their neighbours.

References: gauss16 (the package's integrator) and, where heyoka is installed,
heyoka's Taylor integrator in long double (``tests/data/longdouble_ref.py``, the
``c_ij`` from ``a, b`` in long double); the accuracy bound against it is
``max(1e-10, 10 × max(gauss16's error, the effect of rounding the c_ij))``.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from _refs import longdouble_ref

import manakov
from manakov import _core, tori

PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
POS = {p: q for q, p in enumerate(PAIRS)}
BLOCKS = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
NAMES = ("generic", "physical", "wide", "near_degenerate")

#: The bound's floor: a closed form within this of the reference passes
#: whatever gauss16 reaches (gauss16 itself reaches ~1e-14 here).
FLOOR = 1e-10
#: ... and otherwise within this factor of the larger of gauss16's own error and
#: what the rounding of the c_ij to doubles alone does to l(t) (the reference is
#: the top of the exact a, b; every double-precision solver, gauss16 included,
#: solves the top of the rounded c_ij, and near a separatrix the two differ by up
#: to 2e-9 on [0, 100]).
GAUSS_FACTOR = 10.0


def c_pairs(top: manakov.ManakovTop) -> np.ndarray:
    return np.array([top.c[i, j] for i, j in PAIRS])


def block_state(blk: tuple[int, int, int], vals: np.ndarray) -> np.ndarray:
    i, j, k = blk
    l = np.zeros(6)
    l[POS[(i, j)]], l[POS[(i, k)]], l[POS[(j, k)]] = vals
    return l


def self_dual_state(m: np.ndarray, sign: int) -> np.ndarray:
    n = sign * m
    return np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])


def _gauss16(top: manakov.ManakovTop, l0: np.ndarray, t: np.ndarray) -> np.ndarray:
    return top.integrate(l0, float(t[-1]), t_eval=t, dt=1e-3).l


def _errors(top: manakov.ManakovTop, l0: np.ndarray, t: np.ndarray) -> tuple[float, float, str]:
    """``(error of solve, yardstick)`` against the long-double reference of the exact
    top (``c_ij`` of (2) from ``a, b`` in long double), relative to ``|l0|``, and the
    solution's kind. The yardstick is the larger of gauss16's error and the
    distance to the long-double flow of the doubles' ``c_ij`` (the rounding of the
    data, see :data:`GAUSS_FACTOR`)."""
    ld = longdouble_ref()
    sol = top.solve(l0)
    ref = np.asarray(ld.reference(top.a, top.b, l0, t), dtype=float)
    ref_doubles = np.asarray(ld.reference(top.a, top.b, l0, t, c=c_pairs(top)), dtype=float)
    scale = float(np.linalg.norm(l0))
    e_sol = float(np.max(np.abs(sol.l(t) - ref))) / scale
    e_g16 = float(np.max(np.abs(_gauss16(top, l0, t) - ref))) / scale
    e_data = float(np.max(np.abs(ref_doubles - ref))) / scale
    return e_sol, max(e_g16, e_data), sol.kind


def _assert_bound(e_sol: float, yardstick: float, what: str) -> None:
    assert e_sol <= max(FLOOR, GAUSS_FACTOR * yardstick), (
        f"{what}: {e_sol:.2e} (gauss16 or the rounding of c: {yardstick:.2e})"
    )


# --- Jacobi's elliptic functions against mpmath ---------------------------------------

#: sn, cn, dn on [-K, K]: a few roundings of values of size 1 (measured <= 1.1e-15).
JACOBI_ATOL = 2e-15


@pytest.mark.parametrize("m1", [1.0, 0.9, 0.5, 0.1, 1e-3, 1e-8, 1e-12, 1e-16, 1e-30, 0.0])
def test_jacobi_functions_match_mpmath(m1: float) -> None:
    mpmath.mp.dps = 60
    m = 1.0 - m1
    mm = 1 - mpmath.mpf(m1)
    rng = np.random.default_rng(int(1e6 * m1) % 1000 + 7)
    if m1 == 0.0:
        kk = math.inf
        u = rng.uniform(-30.0, 30.0, 40)
    else:
        kk = float(mpmath.ellipk(mm))
        u = np.concatenate([rng.uniform(-kk, kk, 40), [0.0, kk, -kk, 0.5 * kk, kk * (1 - 1e-9)]])
    sn, cn, dn, am = _core.jacobi_ellipj(u, m, m1)
    for k, x in enumerate(u):
        ref = [mpmath.ellipfun(f, mpmath.mpf(float(x)), m=mm) for f in ("sn", "cn", "dn")]
        for got, want in zip((sn[k], cn[k], dn[k]), ref):
            assert abs(got - float(want)) <= JACOBI_ATOL, (m1, x, got, want)
        # am: sn = sin am, cn = cos am, continuous (|am| ~ |u| for small m).
        assert abs(math.sin(am[k]) - sn[k]) <= JACOBI_ATOL
    if m1 > 0.0:
        k_got, f = _core.jacobi_ellipf(np.array([0.3, 1.2, -2.0, 4.0]), m, m1)
        assert abs(k_got - kk) <= 4e-16 * kk
        for phi, got in zip((0.3, 1.2, -2.0, 4.0), f):
            want = float(mpmath.ellipf(mpmath.mpf(phi), mm))
            assert abs(got - want) <= 4e-15 * max(1.0, abs(want)), (m1, phi)


def test_jacobi_large_arguments_lose_only_the_reduction() -> None:
    # u up to 4K·10: the reduction modulo 4K costs ε|u| (as for sin).
    mpmath.mp.dps = 60
    m1 = 0.25
    mm = 1 - mpmath.mpf(m1)
    kk = float(mpmath.ellipk(mm))
    u = np.linspace(-40 * kk, 40 * kk, 31)
    sn, cn, dn, _ = _core.jacobi_ellipj(u, 1 - m1, m1)
    for k, x in enumerate(u):
        want = float(mpmath.ellipfun("sn", mpmath.mpf(float(x)), m=mm))
        assert abs(sn[k] - want) <= 4 * np.finfo(float).eps * (1 + abs(x))


def test_jacobi_bad_parameters_raise() -> None:
    with pytest.raises(ValueError, match="elliptic parameter"):
        _core.jacobi_ellipj(np.zeros(1), 1.5, -0.5)
    with pytest.raises(ValueError, match="do not add up"):
        _core.jacobi_ellipj(np.zeros(1), 0.5, 0.6)
    with pytest.raises(ValueError, match="u"):
        _core.jacobi_ellipj(np.array([np.nan]), 0.5, 0.5)


# --- kinds -------------------------------------------------------------------------


def test_kinds_and_attributes() -> None:
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    cases = {
        "genus2": p.l0,
        "rest": np.zeros(6),
        "equilibrium": np.array([0.0, 0.7, 0.0, 0.0, -1.2, 0.0]),
        "euler": block_state((0, 1, 3), np.array([0.3, -0.8, 0.5])),
        "spherical": None,
    }
    for kind, l0 in cases.items():
        if kind == "spherical":
            sol = manakov.ManakovTop(p.a, 0.7 * np.asarray(p.a) + 0.2).solve(p.l0)
        else:
            sol = top.solve(l0)
        assert sol.kind == kind
        assert sol.kind in manakov.solution.KINDS
        assert sol.l(0.0).shape == (6,) and sol.l(np.zeros((2, 3))).shape == (2, 3, 6)
        assert sol.frequencies.shape == (2,)
        assert repr(sol).startswith("Solution(")
        if kind == "genus2":
            assert sol.U.shape == (2,)
            assert 0.0 <= sol.self_check <= 1e-10
            assert 0.0 <= sol.velocity_check <= 1e-6
            assert sol.drift_defect <= max(sol.self_check, sol.velocity_check)
            with pytest.raises(AttributeError, match="kind 'genus2'"):
                _ = sol.euler
        else:
            for attr in (
                "U",
                "tau",
                "u0",
                "curve",
                "torus",
                "constants",
                "calibration",
                "self_check",
                "velocity_check",
                "drift_defect",
            ):
                with pytest.raises(AttributeError, match=f"kind '{kind}'"):
                    getattr(sol, attr)
            with pytest.raises(AttributeError, match=f"kind '{kind}'"):
                sol.abel(p.l0)
            assert not hasattr(sol, "tau")
        if kind in ("rest", "spherical", "equilibrium"):
            assert np.array_equal(sol.l(np.linspace(0, 50, 7)), np.tile(sol.l0, (7, 1)))
            assert np.array_equal(sol.frequencies, [0.0, 0.0])
    e = top.solve(cases["euler"]).euler
    assert e.subalgebra == "block 124" and e.regime == "elliptic"
    assert 0.0 < e.m < 1.0 and abs(e.m + e.m1 - 1.0) < 1e-15


def test_nothing_passed_in_is_modified_and_bad_input_raises() -> None:
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0 = block_state((0, 1, 2), np.array([0.3, -0.8, 0.5]))
    keep = l0.copy()
    sol = top.solve(l0)
    sol.l(np.array([1.0, 2.0]))
    assert np.array_equal(l0, keep)
    with pytest.raises(ValueError, match="t"):
        sol.l(np.inf)
    with pytest.raises(ValueError, match="l0"):
        top.solve(np.array([np.nan, 0, 0, 0, 0, 0]))


# --- accuracy sweeps on the four shared tops -----------------------------------------


def _sweep_states(name: str, rng: np.random.Generator) -> list[tuple[str, np.ndarray]]:
    """Random directions on every exactly degenerate set of the top: the four
    so(3) blocks, both self-dual subspaces, the single components and the three
    coordinate planes (equilibria), and block states 1e-6 (relative) off their
    separatrix."""
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    states: list[tuple[str, np.ndarray]] = []
    for blk in BLOCKS:
        for _ in range(2):
            states.append((f"block {blk}", block_state(blk, rng.normal(size=3))))
        states.append((f"block {blk} 1e-6 off its separatrix", _near_separatrix(top, blk, 1e-6)))
    for sign in (1, -1):
        for _ in range(2):
            states.append((f"self-dual {sign:+d}", self_dual_state(rng.normal(size=3), sign)))
    for q in range(6):
        l = np.zeros(6)
        l[q] = rng.normal()
        states.append((f"component {q}", l))
    for qa, qb in ((0, 5), (1, 4), (2, 3)):
        l = np.zeros(6)
        l[qa], l[qb] = rng.normal(size=2)
        states.append((f"plane {qa}{qb}", l))
    return states


def _near_separatrix(
    top: manakov.ManakovTop, blk: tuple[int, int, int], delta: float
) -> np.ndarray:
    """A state of the block with ``(W_s − W_b) M_s² = (W_b − W_r) M_r² (1 + δ)``,
    rounded to doubles (``δ = 0``: on the separatrix to rounding, ``1 − m ~ 1e-17``)."""
    c = c_pairs(top)
    i, j, k = blk
    w = -np.array([c[POS[(j, k)]], c[POS[(i, k)]], c[POS[(i, j)]]])
    lo, b, hi = np.argsort(w)
    mm = np.zeros(3)
    mm[b] = 0.8
    mm[hi] = 1.0
    mm[lo] = math.sqrt((w[hi] - w[b]) / (w[b] - w[lo]) * (1 + delta))
    return block_state(blk, np.array([mm[2], -mm[1], mm[0]]))


@pytest.mark.parametrize("name", NAMES)
def test_exactly_degenerate_states_against_long_double(name: str) -> None:
    pytest.importorskip("heyoka")
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    rng = np.random.default_rng(4242 + NAMES.index(name))
    t = np.linspace(0.0, 100.0, 201)
    for what, l0 in _sweep_states(name, rng):
        e_sol, yardstick, kind = _errors(top, l0, t)
        assert kind in ("euler", "equilibrium"), (what, kind)
        _assert_bound(e_sol, yardstick, f"{name} {what} ({kind})")


@pytest.mark.parametrize("name", NAMES)
def test_exactly_degenerate_states_match_gauss16(name: str) -> None:
    # Without heyoka: gauss16 at dt = 1e-3 as the reference on [0, 20]. Near a
    # separatrix gauss16 itself errs by up to 2e-10 there (the closed form by
    # 1e-13 against the long-double reference, measured): 1e-12 elsewhere.
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    rng = np.random.default_rng(77 + NAMES.index(name))
    t = np.linspace(0.0, 20.0, 41)
    for what, l0 in _sweep_states(name, rng):
        sol = top.solve(l0)
        err = np.max(np.abs(sol.l(t) - _gauss16(top, l0, t))) / np.linalg.norm(l0)
        tol = 1e-9 if "separatrix" in what else 1e-12
        assert err <= tol, f"{name} {what}: {err:.2e}"


def _euler_field(w: list) -> object:
    """``Ṁ = M × (W∘M)`` for mpmath."""

    def f(_t: object, m: list) -> list:
        return [
            (w[2] - w[1]) * m[1] * m[2],
            (w[0] - w[2]) * m[2] * m[0],
            (w[1] - w[0]) * m[0] * m[1],
        ]

    return f


def test_states_on_the_separatrix_to_rounding_match_a_40_digit_integration() -> None:
    # 1 − m ~ 1e-17: the motion lingers ~2K/ω ≈ 20/ω near the unstable axis, so
    # any integrator's rounding is amplified ~1/k' ~ 1e8 per passage (long
    # double reaches 1e-4 by t = 20). The closed form has no such growth: it is
    # checked against mpmath's Taylor integrator of the Euler top at 40 digits.
    mpmath.mp.dps = 40
    for name in ("generic", "wide"):
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        for blk in ((0, 1, 2), (1, 2, 3)):
            l0 = _near_separatrix(top, blk, 0.0)
            sol = top.solve(l0)
            e = sol.euler
            assert sol.kind == "euler" and e.m1 < 1e-14
            w = [mpmath.mpf(float(x)) for x in e.W]
            f = _euler_field(w)
            ref = mpmath.odefun(
                f, 0, [mpmath.mpf(float(x)) for x in e.M0], tol=mpmath.mpf(10) ** -30
            )
            # M = (l_jk, −l_ik, l_ij) in the block's (normalized = user) frame.
            i, j, k = blk
            for t in (5.0, 12.0, 20.0):
                l = sol.l(t)
                m_cf = np.array([l[POS[(j, k)]], -l[POS[(i, k)]], l[POS[(i, j)]]])
                m_ref = np.array([float(x) for x in ref(t)])
                assert np.max(np.abs(m_cf - m_ref)) < 1e-14 * np.linalg.norm(l0), (name, blk, t)


def test_exact_separatrix_states() -> None:
    # a = (0, 1, 2, 3), b = a³: c_ij = a_i² + a_i a_j + a_j² are integers; the
    # block {1, 2, 3} has W = −(c23, c13, c12) = −(7, 4, 1), equally spaced, so
    # |l23| = |l12| is exactly on its separatrix.
    a = np.array([0.0, 1.0, 2.0, 3.0])
    top = manakov.ManakovTop(a, a**3)
    for l0 in ([0.5, 0.25, 0, 0.5, 0, 0], [0.5, -0.75, 0, -0.5, 0, 0]):
        sol = top.solve(np.array(l0))
        assert sol.kind == "separatrix"
        assert sol.euler.regime == "separatrix"
        assert np.array_equal(sol.frequencies, [0.0, 0.0])
        fm = tori.frequency_map(top, np.array(l0))
        assert fm.status == tori.SEPARATRIX and np.isnan(fm.nu).all()
        # The middle axis is hyperbolic with rate λ = √((W_s − W_b)(W_b − W_r)) |M|:
        # a reference of any precision leaves the separatrix after ~ln(1/u)/λ, so
        # compare on λ t ≤ 20 (long-double rounding grows to ~5e-11 there).
        lam = 3.0 * np.linalg.norm(l0)
        t = np.linspace(0.0, 20.0 / lam, 81)
        g16 = _gauss16(top, np.array(l0), t)
        assert np.max(np.abs(sol.l(t) - g16)) / np.linalg.norm(l0) < 1e-8
    # One ulp off the separatrix: an elliptic motion with tiny 1 − m.
    sol = top.solve(np.array([0.5, 0.25, 0, np.nextafter(0.5, 1.0), 0, 0]))
    assert sol.kind == "euler" and sol.euler.m1 < 1e-15


def test_nearly_axisymmetric_self_dual_tops() -> None:
    # The self-dual top has W_1 − W_2 = −p3 (a_2 − a_1)(a_3 − a_4) (p3 of the cubic
    # interpolant of b): on 'near_degenerate' (a_2 − a_1 = 1e-6) it is nearly
    # axisymmetric, m = k² ~ 1e-7 … 1e-5, and the elliptic form tends to the
    # uniform rotation without loss (no division by W_1 − W_2).
    p = manakov.problem("near_degenerate")
    top = manakov.ManakovTop(p.a, p.b)
    t = np.linspace(0.0, 30.0, 61)
    for m in ([0.5, -0.3, 0.8], [0.9, 0.1, 0.2], [0.1, 0.2, 0.9]):
        l0 = self_dual_state(np.array(m), 1)
        sol = top.solve(l0)
        assert sol.kind == "euler" and sol.euler.m < 1e-4
        err = np.max(np.abs(sol.l(t) - _gauss16(top, l0, t))) / np.linalg.norm(l0)
        assert err < 1e-12, (m, err)


def test_extreme_component_ratios() -> None:
    # Components 1e-100 … 1e-300 beside O(1) ones (their squares underflow):
    # solved, on the Euler orbit they are on, as gauss16 has them (relative to
    # |l0|; near the middle axis a tiny component grows like cosh(λ t), and the
    # closed form keeps it to its absolute, not relative, accuracy).
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    t = np.linspace(0.0, 20.0, 41)
    for l0 in (
        [1e-170, 1.0, 0, 0, 0, 0],
        [1.0, 1e-300, 0, 0, 0, 0],
        [0, 0, 0, 1.0, 1e-200, 0],
        [0.3, 1e-150, 0, -0.7, 0, 0],
    ):
        l0 = np.array(l0, float)
        sol = top.solve(l0)
        assert sol.kind == "euler", (l0, sol.kind)
        err = np.max(np.abs(sol.l(t) - _gauss16(top, l0, t))) / np.linalg.norm(l0)
        assert err < 1e-13, (l0, err)
        fm = tori.frequency_map(top, l0)
        assert fm.status == tori.OK


# --- invariances --------------------------------------------------------------------

#: Two solutions of one motion, one through normalized data: the genus-2 route's
#: accuracy on [0, 10] (measured ~1e-13).
SAME_MOTION = 1e-11


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("s", [1e-150, 1e150])
def test_scaled_states_follow_the_scaling_law(name: str, s: float) -> None:
    # l(t; s l0) = s l(s t; l0): the flow (1) is homogeneous of degree 2.
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    t = np.linspace(0.0, 10.0, 21)
    states = [
        np.asarray(p.l0, float),
        block_state((0, 2, 3), np.array([0.3, 0.9, -0.4])),
        self_dual_state(np.array([0.5, -0.2, 0.7]), -1),
        np.array([0.0, 0.0, 0.8, 0.0, 0.0, 0.0]),
    ]
    for l0 in states:
        base = top.solve(l0)
        scaled = top.solve(s * l0)
        assert scaled.kind == base.kind
        lhs = scaled.l(t / s)
        rhs = s * base.l(t)
        err = np.max(np.abs(lhs - rhs)) / (s * np.linalg.norm(l0))
        assert err <= SAME_MOTION, (name, s, base.kind, err)
        if base.kind == "genus2":
            ratio = scaled.frequencies / base.frequencies
            assert np.allclose(ratio, s, rtol=1e-11)


@pytest.mark.parametrize("shift", [1e6, -1e6, 1e9])
def test_shifted_a_solves_the_same_motion(shift: float) -> None:
    # c_ij = (b_i − b_j)/(a_i − a_j) of the shifted doubles: the same flow up to
    # the rounding of a + shift; gauss16 of that top is the reference.
    for name in NAMES:
        p = manakov.problem(name)
        top = manakov.ManakovTop(np.asarray(p.a) + shift, p.b)
        sol = top.solve(p.l0)
        assert sol.kind == "genus2" and sol.frame["kappa"] != 0.0
        t = np.linspace(0.0, 20.0, 41)
        err = np.max(np.abs(sol.l(t) - _gauss16(top, np.asarray(p.l0), t)))
        assert err / np.linalg.norm(p.l0) < 1e-10, (name, shift)


#: |l(t; a, b) - l(t; a, b + a/4)| / |l0| at t = 1e4 for the same flow given by two
#: tops: the phase follows the unrounded c of each (measured: identical to the bit
#: on the six stiff tops below; without the rounding errors of c, up to 6.9e-12).
SAME_FLOW_RTOL = 1e-14


def test_b_plus_a_quarter_is_the_same_flow_to_long_times() -> None:
    # b -> b + mu a adds mu to every c_ij (errata: c -> c + mu leaves (1) unchanged).
    # With a, b on a 2^-30 grid, b + a/4 is exact, so both tops are the same flow;
    # their rounded c differ (c + 1/4 rounds differently), their exact c do not.
    rng = np.random.default_rng(5)
    for trial in range(6):
        sp = 10 ** rng.uniform(-1.0, 0.3, 3)
        sp[trial % 3] = 10 ** rng.uniform(-2, -1.3)  # stiff: |c| up to ~600
        a = np.cumsum(np.concatenate([[rng.uniform(-1, 1)], sp]))
        a, b = np.round(a * 2**30) / 2**30, np.round(rng.normal(size=4) * 3 * 2**30) / 2**30
        b2 = b + 0.25 * a
        assert np.array_equal(b2 - 0.25 * a, b)
        l0 = rng.normal(size=6)
        t = np.array([0.0, 100.0, 1e4])
        s1 = manakov.ManakovTop(a, b).solve(l0)
        s2 = manakov.ManakovTop(a, b2).solve(l0)
        diff = np.max(np.abs(s1.l(t) - s2.l(t))) / np.linalg.norm(l0)
        assert diff <= SAME_FLOW_RTOL, (trial, diff)


def test_b_affine_in_a_is_the_spherical_top() -> None:
    rng = np.random.default_rng(5)
    for name in NAMES:
        p = manakov.problem(name)
        for alpha, beta in ((0.7, 0.2), (-3.0, 1e3), (1e-4, -2.0)):
            b = alpha * np.asarray(p.a) + beta
            top = manakov.ManakovTop(p.a, b)
            l0 = rng.normal(size=6)
            sol = top.solve(l0)
            assert sol.kind == "spherical"
            assert np.array_equal(sol.l(3.0), l0)
            fm = tori.frequency_map(top, l0)
            assert fm.status == tori.EQUILIBRIUM
            # The doubles' own flow moves at the rounding of c: |dl/dt| is at
            # most spread(c) |l|² (two terms of (1) per component).
            spread = np.ptp(c_pairs(top))
            g16 = top.integrate(l0, 10.0, t_eval=np.array([0.0, 10.0]), dt=1e-2).l
            drift = np.max(np.abs(g16[-1] - l0))
            assert drift <= 2 * 10.0 * spread * np.dot(l0, l0) + 1e-15, (alpha, beta, drift)


def _second_difference(a: np.ndarray, c: np.ndarray, t: tuple[int, int, int]) -> float:
    """b[i,j,k] = (c_jk − c_ij)/(a_k − a_i) over the pair of the triple farthest apart."""
    best = (0.0, 0.0)
    for i, k in ((t[0], t[1]), (t[0], t[2]), (t[1], t[2])):
        j = next(x for x in t if x not in (i, k))
        if abs(a[k] - a[i]) > best[0]:
            best = (abs(a[k] - a[i]), (c[j, k] - c[i, j]) / (a[k] - a[i]))
    return best[1]


def test_equilibria_of_the_three_dimensional_families() -> None:
    # V± (docs/degenerate.md §2): z = ζ(1, r), x = ξ(B2, B4 r), y = η(B3, −B4 r),
    # r = ±√(B2 B3/(B1 B4)); B_m = b[i,j,k] from the c_ij (the widest pair).
    for name in ("generic", "physical"):
        p = manakov.problem(name)
        a = np.asarray(p.a)
        top = manakov.ManakovTop(p.a, p.b)
        c = top.c

        bb = [_second_difference(a, c, t) for t in ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))]
        assert bb[0] * bb[1] * bb[2] * bb[3] > 0
        for sign in (1, -1):
            r = sign * math.sqrt(bb[1] * bb[2] / (bb[0] * bb[3]))
            xi, eta, zeta = 0.3, -0.7, 1.1
            l0 = np.array(
                [xi * bb[1], eta * bb[2], zeta, zeta * r, -eta * bb[3] * r, xi * bb[3] * r]
            )
            sol = top.solve(l0)
            assert sol.kind == "equilibrium", (name, sign)
            assert np.max(np.abs(top.vector_field(l0))) < 1e-14


# --- frequencies of Euler motions -------------------------------------------------


def _nu_perp_classes(nu1: float, nu_perp: float, nu_e: float) -> float:
    """Distance of ν1 from the class ±ν_⊥ + Z ν_E."""
    best = math.inf
    for s in (1.0, -1.0):
        x = (nu1 - s * nu_perp) / nu_e
        best = min(best, abs(x - round(x)) * nu_e)
    return best


@pytest.mark.parametrize("name", ["generic", "physical"])
def test_neighbours_of_self_dual_states_tend_to_the_euler_frequencies(name: str) -> None:
    # The genus-2 frequencies at distance ε from m = ±n tend to (|ν_⊥ + k ν_E|, ν_E),
    # linearly in ε (measured; docs/degenerate.md §5).
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    rng = np.random.default_rng(31 + len(name))
    for sign in (1, -1):
        m = rng.normal(size=3)
        l0 = self_dual_state(m, sign)
        sol = top.solve(l0)
        assert sol.kind == "euler"
        nu_perp, nu_e = sol.frequencies
        assert 0.0 <= nu_perp <= 0.5 * nu_e
        fm = tori.frequency_map(top, l0)
        assert fm.status == tori.OK and np.array_equal(fm.nu, sol.frequencies)
        dq = rng.normal(size=3)
        dq /= np.linalg.norm(dq)
        dev = []
        for eps in (1e-2, 1e-3):
            mm = m + eps * dq / 2
            nn = sign * (m - eps * dq / 2)
            l = np.array([mm[2], -mm[1], nn[0], mm[0], nn[1], nn[2]])
            nb = tori.frequency_map(top, l)
            assert nb.status == tori.OK
            nu1, nu2 = nb.nu
            dev.append(max(abs(nu2 - nu_e), _nu_perp_classes(nu1, nu_perp, nu_e)) / nu_e)
        # O(ε): a tenth of the distance, a tenth of the deviation (with margin).
        assert dev[1] < 0.3 * dev[0] + 1e-9 and dev[1] < 1e-2, dev


def test_neighbours_of_an_elliptic_block_orbit_tend_to_the_euler_frequencies() -> None:
    # 'generic', block {1, 2, 3} at (l12, l13, l23) = (0.6, -0.4, 0.8): transversally
    # elliptic (found by trial); the neighbours converge like ε².
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    for vals in ([0.6, -0.4, 0.8], [0.2, 0.9, -0.5], [1.0, 0.3, 0.3]):
        l0 = block_state((0, 1, 2), np.array(vals))
        nu_perp, nu_e = top.solve(l0).frequencies
        if nu_perp == 0.0:  # transversally hyperbolic: no limit to check
            continue
        for eps in (1e-3,):
            l = l0.copy()
            l[[2, 4, 5]] = eps * np.array([0.3, -0.5, 0.8])
            nb = tori.frequency_map(top, l)
            assert nb.status == tori.OK
            nu1, nu2 = nb.nu
            assert abs(nu2 - nu_e) < 1e-4 * nu_e
            assert _nu_perp_classes(nu1, nu_perp, nu_e) < 1e-4 * nu_e


def test_frequency_map_through_degenerate_states_has_no_hole() -> None:
    # A line of states through a self-dual state and an so(3) block state: the
    # centre (the line's only exactly degenerate state) maps with status ok.
    # Its neighbours are genus-2 states (their accuracy near these sets is the
    # genus-2 route's, docs/degenerate.md §4).
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    sd = self_dual_state(np.array([0.7, -0.4, 0.5]), 1)
    blk = block_state((0, 1, 2), np.array([0.6, -0.4, 0.8]))
    d = np.array([0.3, -0.2, 0.5, 0.1, 0.4, -0.6])
    for center in (sd, blk):
        s = np.concatenate([-np.logspace(-1, -3, 3), [0.0], np.logspace(-3, -1, 3)])
        fm = tori.frequency_map(top, center + s[:, None] * d)
        assert fm.status[3] == tori.OK and np.isfinite(fm.nu[3]).all()
        assert (fm.status == tori.OK).all(), fm.counts()
