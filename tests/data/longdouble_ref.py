"""Reference trajectories of Frahm's equations (1) in 80-bit long double.

heyoka's Taylor integrator (Biscani & Izzo, MNRAS 504 (2021)) with
``fp_type=np.longdouble`` (64-bit significand, unit roundoff 5.4e-20) and
tolerance 1e-19: an integrator independent of the package, about three digits
more precise than double, used as the reference for the package's solutions and
integrators. The c_ij enter as runtime parameters, so one compiled integrator
serves every top.

``reference_quad`` is the same integrator in IEEE quadruple precision
(``heyoka.real128``, 113-bit significand, tolerance 1e-32): on states whose
components span many orders of magnitude the long-double reference itself is
off (by up to 0.5 |l0| on the harsh draw of ``every_state_harsh.py``), and the
quadruple one decides. About 10x slower.

Used by the committed data scripts (``every_state_harsh.py``,
``every_state_sweeps.py``, ``degenerate_sweep.py``) and by
``tests/test_degenerate.py``; needs heyoka (the ``test`` and ``bench`` extras).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

# State order (l12, l13, l14, l23, l24, l34); PAIRS[q] = (i, j), 0-based, i < j.
PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
REF_TOL = 1e-19
REF_TOL_QUAD = "1e-32"


@lru_cache(maxsize=1)
def _integrator():
    return _make_integrator(np.longdouble, np.longdouble(REF_TOL))


@lru_cache(maxsize=1)
def _integrator_quad():
    import heyoka as hy

    return _make_integrator(hy.real128, hy.real128(REF_TOL_QUAD))


def _make_integrator(fp, tol):
    import heyoka as hy

    x = hy.make_vars(*[f"l{i + 1}{j + 1}" for i, j in PAIRS])
    index = {p: q for q, p in enumerate(PAIRS)}

    def L(i, j):
        if i == j:
            return 0.0
        return x[index[(i, j)]] if i < j else -x[index[(j, i)]]

    def W(i, j):
        if i == j:
            return 0.0
        q = index[(min(i, j), max(i, j))]
        return hy.par[q] * L(i, j)

    rhs = []
    for i, j in PAIRS:
        # (1): l'_ij = sum_k (l_ik w_kj - w_ik l_kj), w_ij = c_ij l_ij
        terms = []
        for k in range(4):
            if k in (i, j):
                continue
            terms.append(L(i, k) * W(k, j) - W(i, k) * L(k, j))
        rhs.append(hy.sum(terms))
    return hy.taylor_adaptive(
        list(zip(x, rhs)),
        np.array([fp(0)] * 6),
        fp_type=fp,
        tol=tol,
        pars=np.array([fp(0)] * 6),
        compact_mode=True,
    )


def c_pairs(a, b) -> np.ndarray:
    """c_ij of (2) in long double, in the state order."""
    a = np.asarray(a, dtype=np.longdouble)
    b = np.asarray(b, dtype=np.longdouble)
    return np.array([(b[i] - b[j]) / (a[i] - a[j]) for i, j in PAIRS], dtype=np.longdouble)


def reference(a, b, l0, t, c=None) -> np.ndarray:
    """l(t) at the sorted times ``t`` (t[0] >= 0) from l(0) = l0, as long double (len(t), 6).

    ``c``: the c_ij (state order) to integrate instead of those of (2) from ``a, b``
    in long double, e.g. the doubles a solver works with (converted exactly): the
    difference of the two references is what the rounding of the c_ij alone does to
    l(t), large where the motion is ill-conditioned (near a separatrix).
    """
    ta = _integrator()
    ta.time = np.longdouble(0)
    ta.state[:] = np.asarray(l0, dtype=np.longdouble)
    ta.pars[:] = c_pairs(a, b) if c is None else np.asarray(c, dtype=np.longdouble)
    t = np.asarray(t, dtype=np.longdouble)
    res = ta.propagate_grid(t, max_delta_t=np.longdouble(np.inf))
    outcome = res[0]
    import heyoka as hy

    if outcome != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"heyoka stopped early: {outcome}")
    return np.asarray(res[-1], dtype=np.longdouble)


def reference_quad(a, b, l0, t) -> np.ndarray:
    """``reference`` in quadruple precision (``heyoka.real128``); c_ij of (2) from
    ``a, b`` at 50 digits (mpmath). Returned as long double (len(t), 6)."""
    import heyoka as hy
    import mpmath as mp

    q = hy.real128
    ta = _integrator_quad()
    ta.time = q(0)
    ta.state[:] = np.array([q(repr(float(v))) for v in l0])
    with mp.workdps(50):
        af = [mp.mpf(float(v)) for v in a]
        bf = [mp.mpf(float(v)) for v in b]
        c = [mp.nstr((bf[i] - bf[j]) / (af[i] - af[j]), 40) for i, j in PAIRS]
    ta.pars[:] = np.array([q(v) for v in c])
    res = ta.propagate_grid(np.array([q(repr(float(v))) for v in t]), max_delta_t=q("inf"))
    if res[0] != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"heyoka stopped early: {res[0]}")
    return np.array([[np.longdouble(str(v)) for v in row] for row in res[-1]])
