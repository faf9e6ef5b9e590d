# ruff: noqa: E741  (l is the paper's name for the state)
"""The precise evaluation of the Theorem, ``Solution.l(t, precise=True)``.

Its constants are polished in double-double against the conditions that define
them and the quotients summed in double-double, so ``l(t)`` is the correctly
rounded state up to the error of the lattice rates (~1e-19 relative), where the
double evaluation is off by a few units of rounding from ``t = 0`` on
(docs/theorem.md, "Precise evaluation").
"""

from __future__ import annotations

import sys
import textwrap

import numpy as np
import pytest
from _refs import longdouble_ref
from _sigint import STOP_WITHIN_S, sigint_after

import manakov

# Largest error of the precise l(t) against the long-double reference, relative to
# |l0|, on the slow shared tops at t <= 100: half an ulp of |l0| is 1.1e-16 |l0|
# for the largest component; measured 2.5e-17 ('physical') and 3.3e-17 ('wide').
PRECISE_LD_RTOL = 1e-16


@pytest.mark.parametrize("name", ["physical", "wide"])
def test_precise_theorem_is_at_least_as_accurate_as_gauss16(name):
    """On the slow shared tops, where gauss16 at a quarter of its default step stays
    within an ulp or two for a hundred time units and the double evaluation of the
    Theorem does not (1e-15 ... 3e-15 |l0| from t = 0 on), the precise evaluation is
    within half an ulp of |l0| of the long-double reference and below gauss16's
    error."""
    ld = longdouble_ref()
    p = manakov.problem(name)
    top = manakov.ManakovTop(p.a, p.b)
    l0 = np.asarray(p.l0, float)
    sol = top.solve(l0)
    t = np.array([0.0, 10.0, 100.0])
    ref = ld.reference(p.a, p.b, l0, t)
    n0 = np.linalg.norm(l0)

    def err(x):
        return (np.max(np.abs(np.asarray(x, np.longdouble) - ref), axis=1) / n0).astype(float)

    residual, correction = sol.precise_residual
    assert residual <= 1e-17 and 1e-17 < correction < 1e-13, (residual, correction)
    e_precise = err(sol.l(t, precise=True))
    e_double = err(sol.l(t))
    e_g16 = err(top.integrate(l0, 100.0, t_eval=t, dt=top.default_dt(l0) / 4).l)
    assert np.all(e_precise <= PRECISE_LD_RTOL), e_precise
    # at t = 0 both give l0 itself
    assert np.all(e_precise[1:] <= e_g16[1:]), (e_precise, e_g16)
    # the double evaluation is the one that is not at the floor
    assert np.max(e_double) > PRECISE_LD_RTOL, e_double


def test_precise_l_at_zero_is_l0_and_scales_exactly():
    """``l(0) = l0`` to the bit; ``l(t; s l0) = s l(s t; l0)`` exactly for a power of
    two ``s`` (the normalization moves the state by powers of two only)."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    l0 = np.asarray(p.l0, float)
    sol = top.solve(l0)
    np.testing.assert_array_equal(sol.l(0.0, precise=True), l0)
    s = 2.0**40
    big = top.solve(s * l0)
    t = np.array([0.3, 7.0])
    np.testing.assert_array_equal(big.l(t / s, precise=True), s * sol.l(t, precise=True))


def test_precise_l_is_time_reversible_to_the_bit():
    """Frahm's (1) is quadratic in ``l``: ``-l(-t)`` solves it too, so
    ``l(t; -l0) = -l(-t; l0)``. The two sides come from two set-ups (the constants of
    ``l0`` and of ``-l0``); correctly rounded, they agree to the bit. The double
    evaluation, a few ulp off, does not (it differs on every one of these states)."""
    rng = np.random.default_rng(3)
    t = np.array([0.5, 3.0, 17.0])
    double_differs = 0
    for _ in range(8):
        a = np.sort(rng.normal(size=4) * 2)
        b, l0 = rng.normal(size=4), rng.normal(size=6)
        top = manakov.ManakovTop(a, b)
        fwd, back = top.solve(l0), top.solve(-l0)
        assert fwd.kind == back.kind == "genus2"
        np.testing.assert_array_equal(back.l(t, precise=True), -fwd.l(-t, precise=True))
        double_differs += int(np.any(back.l(t) != -fwd.l(-t)))
    assert double_differs >= 6, double_differs


def test_precise_l_shapes_and_input_checks():
    p = manakov.problem("generic")
    l0 = np.asarray(p.l0, float)
    t = np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])
    t_copy = t.copy()
    sol = manakov.ManakovTop(p.a, p.b).solve(l0)
    assert sol.l(1.0, precise=True).shape == (6,)
    out = sol.l(t, precise=True)
    assert out.shape == (2, 3, 6)
    np.testing.assert_array_equal(t, t_copy)
    np.testing.assert_allclose(out, sol.l(t), rtol=0, atol=1e-13)
    with pytest.raises(ValueError, match="t"):
        sol.l([1.0, np.nan], precise=True)


def test_precise_l_of_the_other_kinds():
    """A constant motion's precise ``l(t)`` is ``l0``; an Euler motion has none (its
    elliptic functions are evaluated in double) and says so."""
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    rest = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.5])
    sol = top.solve(rest)
    assert sol.kind == "equilibrium"
    np.testing.assert_array_equal(sol.l([0.0, 5.0], precise=True), [rest, rest])
    euler = np.array([0.3, -0.8, 0.0, 0.5, 0.0, 0.0])
    sol = top.solve(euler)
    assert sol.kind == "euler"
    with pytest.raises(manakov.ClosedFormError, match="no precise evaluation"):
        sol.l(1.0, precise=True)


# 2e5 precise times: far more than a second on any machine (~0.2 ms a time per core).
INTERRUPT_CHILD = textwrap.dedent(
    """
    import sys, time
    import numpy as np
    import manakov
    p = manakov.problem("wide")
    sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    t = np.linspace(0.0, 100.0, 200000)
    print("ready", flush=True)
    t0 = time.perf_counter()
    try:
        sol.l(t, precise=True)
    except KeyboardInterrupt:
        print("interrupted", time.perf_counter() - t0, flush=True)
        sys.exit(130)
    print("finished", time.perf_counter() - t0, flush=True)
    """
)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("after", [0.01, 1.0])
def test_sigint_stops_the_polish_and_a_long_precise_batch(after):
    """Ctrl-C during the polish (after 10 ms: it takes ~35 ms) and during the
    evaluation (after 1 s) stops the call within 0.5 s."""
    line, stopped, proc = sigint_after(INTERRUPT_CHILD, after)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, (line, out, err)
    assert line.startswith("interrupted"), (line, out, err)
    assert stopped < STOP_WITHIN_S, f"stopped {stopped:.3f} s after SIGINT"
    assert "Traceback" not in err


@pytest.mark.parametrize("precise", [False, True])
def test_a_refusal_in_the_normalized_frame_says_whose_times_it_names(precise):
    """A state of size 2^-30 is solved in the normalized frame (``t' = T t``,
    ``T = 2^-30``); beyond the phase horizon the refusal names the frame's time and
    says so, instead of a time the user never passed."""
    p = manakov.problem("generic")
    sol = manakov.ManakovTop(p.a, p.b).solve(np.asarray(p.l0, float) * 2.0**-30)
    assert sol.time_scale == 2.0**-30
    with pytest.raises(manakov.ClosedFormError, match="horizon") as info:
        sol.l(1e21, precise=precise)
    assert "normalized frame, T t with T = time_scale = 9.3" in str(info.value)
