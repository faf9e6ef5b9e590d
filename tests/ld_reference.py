"""Reference trajectories of Frahm's equations (1) in 80-bit long double.

heyoka's Taylor integrator (Biscani & Izzo, MNRAS 504 (2021)) with
``fp_type=np.longdouble`` (64-bit significand, unit roundoff 5.4e-20) and
tolerance 1e-19: independent of the package and about three digits more precise
than double. The coefficients are the top's ``c_ij`` as the package computes them
(doubles, converted exactly): the reference is the flow of the data the
package solves. One compiled integrator serves every top (the ``c_ij`` are
runtime parameters). Needs the ``bench`` extra (heyoka).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

# State order (l12, l13, l14, l23, l24, l34); PAIRS[q] = (i, j), 0-based, i < j.
PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
REF_TOL = 1e-19


@lru_cache(maxsize=1)
def _integrator() -> Any:
    import heyoka as hy

    x = hy.make_vars(*[f"l{i + 1}{j + 1}" for i, j in PAIRS])
    index = {p: q for q, p in enumerate(PAIRS)}

    def entry(i: int, j: int) -> Any:
        if i == j:
            return 0.0
        return x[index[(i, j)]] if i < j else -x[index[(j, i)]]

    def omega(i: int, j: int) -> Any:
        if i == j:
            return 0.0
        return hy.par[index[(min(i, j), max(i, j))]] * entry(i, j)

    rhs = []
    for i, j in PAIRS:
        # (1): l'_ij = sum_k (l_ik w_kj - w_ik l_kj), w_ij = c_ij l_ij
        terms = [
            entry(i, k) * omega(k, j) - omega(i, k) * entry(k, j)
            for k in range(4)
            if k not in (i, j)
        ]
        rhs.append(hy.sum(terms))
    return hy.taylor_adaptive(
        list(zip(x, rhs)),
        [np.longdouble(0)] * 6,
        fp_type=np.longdouble,
        tol=np.longdouble(REF_TOL),
        pars=[np.longdouble(0)] * 6,
        compact_mode=True,
    )


def reference(c: Any, l0: Any, t: Any) -> np.ndarray:
    """``l(t)`` at the sorted times ``t >= 0`` from ``l(0) = l0`` for the top with
    ``c_ij`` (state order, doubles), as long double, shape ``(len(t), 6)``."""
    import heyoka as hy

    ta = _integrator()
    ta.time = np.longdouble(0)
    ta.state[:] = np.asarray(l0, dtype=np.longdouble)
    ta.pars[:] = np.asarray(c, dtype=np.longdouble)
    res = ta.propagate_grid(np.asarray(t, dtype=np.longdouble), max_delta_t=np.longdouble(np.inf))
    if res[0] != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"heyoka stopped early: {res[0]}")
    return np.asarray(res[-1], dtype=np.longdouble)
