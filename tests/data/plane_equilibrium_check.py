"""Frequencies next to a coordinate-plane equilibrium: the interpolation (or the
fit) against the genus-2 torus, where both answer.

The coordinate planes ``(l12, l34)``, ``(l13, l24)``, ``(l14, l23)`` are equilibria
of (1). Next to one that is elliptic in both directions the frequency map
interpolates between the normal modes and node states ``σ = 1e-3 … 8e-3`` out;
next to one that is a saddle in one direction and elliptic in the other it fits
``1/ν2`` and ``(ν1 ∓ ω/2π)/ν2`` in ``ln(1/σ)`` with the slope ``4/λ``
(docs/degenerate.md §11). The states that need it lie closer in than the level
set's route reaches.

So the answer is checked where the level set's route answers on its own: for
each state of the harsh draw (tests/data/every_state_harsh.py, seed 20261125)
whose genus-2 torus is refused and that the plane's route answers, the states
on the same line at ``σ = 1e-6, 1e-5, 3e-5, 1e-4`` (closer in than the nodes)
are given to the plane's route directly and to the genus-2 torus
(``sol.torus``); the two frequency pairs must span the same module (a
unimodular integer matrix, entries up to 8) to the reported relative error
(max norm). Also listed: which of the map's answers the plane's route gives, and where
the map answers by another route, that route's miss of the plane's module.

Run (a few minutes; ``PART PARTS`` takes every PARTS-th state):
    python tests/data/plane_equilibrium_check.py [N [PART PARTS]]
"""

from __future__ import annotations

import itertools
import pathlib
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from every_state_harsh import draw  # noqa: E402

import manakov  # noqa: E402

#: the coordinate planes, as state indices (order 12, 13, 14, 23, 24, 34)
PLANES = [(0, 5), (1, 4), (2, 3)]
HOLD_OUT = [1e-6, 1e-5, 3e-5, 1e-4]
#: the plane's route is tried up to this relative distance
NEAR = 1e-2


def nearest_plane(l0):
    """Relative distance to the nearest coordinate plane and the plane state."""
    n = np.linalg.norm(l0)
    best = None
    for plane in PLANES:
        lp = np.zeros(6)
        lp[list(plane)] = l0[list(plane)]
        d = np.linalg.norm(l0 - lp) / n
        if best is None or d < best[0]:
            best = (d, lp)
    return best


def module_error(f, g):
    """Smallest relative max-norm distance of ``g`` from ``M f``, ``M`` unimodular
    with entries up to 8."""
    best = np.inf
    r = range(-8, 9)
    scale = float(np.max(np.abs(g)))
    for p, q, s, t in itertools.product(r, r, r, r):
        if abs(p * t - q * s) != 1:
            continue
        h = np.array([p * f[0] + q * f[1], s * f[0] + t * f[1]])
        best = min(best, float(np.max(np.abs(np.abs(h) - g)) / scale))
    return best


def main(n: int = 10_000, part: int = 0, parts: int = 1) -> None:
    warnings.simplefilter("ignore")
    rng = np.random.default_rng(20261125)
    t0 = time.time()
    answered = compared = 0
    worst = 0.0
    errs: list[float] = []
    for i in range(n):
        a, b, l0 = draw(rng)
        if i % parts != part:
            continue
        d, lp = nearest_plane(l0)
        if not 0.0 < d <= NEAR:
            continue
        top = manakov.ManakovTop(a, b)
        sol = top.solve(l0)
        try:
            _ = sol.torus
            continue  # the genus-2 route answers: the plane's is not needed
        except (manakov.ClosedFormError, ValueError, AttributeError):
            pass  # refused, or no closed form at all (kind 'integrated')
        try:
            nu = np.array(sol._motion.near_plane_frequencies())
        except manakov.ClosedFormError:
            continue
        fm = manakov.frequency_map(top, l0[None, :])
        # where the map answers by another route (an so(3) block's), the two
        # must span the same module as well
        same = bool(np.array_equal(fm.nu[0], nu))
        other = "" if same else f"  other route's: {module_error(nu, np.asarray(fm.nu[0])):8.1e}"
        answered += 1
        row = []
        for sigma in HOLD_OUT:
            ls = lp + (l0 - lp) * (sigma / d)
            s2 = top.solve(ls)
            try:
                g = np.array(s2.torus.frequencies)
                f = np.array(s2._motion.near_plane_frequencies())
            except (manakov.ClosedFormError, ValueError, AttributeError):
                row.append("    -   ")
                continue
            e = module_error(f, g)
            errs.append(e)
            worst = max(worst, e)
            compared += 1
            row.append(f"{e:8.1e}")
        print(
            f"{i:5d}  δ = {d:8.2e}  map = plane's: {str(same):5s}  ν = "
            f"({nu[0]:.10g}, {nu[1]:.10g})  miss at σ = {HOLD_OUT}: {' '.join(row)}{other}",
            flush=True,
        )
    print(
        f"states answered by the plane's route: {answered}; comparisons: {compared}; "
        f"miss median {np.median(errs) if errs else float('nan'):.1e}, max {worst:.1e} "
        f"({time.time() - t0:.0f} s)"
    )


if __name__ == "__main__":
    args = [int(x) for x in sys.argv[1:]]
    main(*args)
