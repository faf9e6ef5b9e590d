"""Frequencies from the closed orbits of the commuting flows against the genus-2
torus, where both answer.

The frequency map's last route (docs/degenerate.md §11) finds the lattice of
times ``(t1, t2)`` after which the flows of ``H`` and of the second Hamiltonian
of Manakov's family bring a state back to itself, by integration in
double-double, and takes ``ν = Λ⁻¹ e1``. It uses neither the curve nor theta
functions, so the genus-2 torus (``sol.torus``) is an independent reference.

Part 1: every STRIDE-th state of the harsh draw (tests/data/every_state_harsh.py,
seed 20261125) whose genus-2 torus is answered is given to the closed-orbit
route directly; the two frequency pairs must span the same module (a unimodular
integer matrix, first column up to 1024) to the reported relative error (max norm).
Part 2: every state of the draw (or of ``N``) that the map answers only by
this route, with its frequencies and time.

Run (about half an hour; ``N`` limits the draw):
    python tests/data/closed_orbit_check.py [N [STRIDE]]
"""

from __future__ import annotations

import pathlib
import sys
import time
import warnings
from collections import Counter

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from every_state_harsh import draw  # noqa: E402

import manakov  # noqa: E402

#: the bound the frequency map states for its interpolated and fitted routes
BOUND = 5e-11
#: largest first-column entry of the unimodular matrices searched: the harsh draw's
#: frequencies differ by up to 1e5, and bases by matrices with entries like 400
WIDTH = 1024


def module_error(f, g) -> float:
    """Smallest relative (max-norm) miss of ``g`` by ``M f``, ``M`` unimodular with
    first column up to WIDTH (the second the nearest integers)."""
    f, g = np.asarray(f, float), np.abs(np.asarray(g, float))
    rows = []
    for gi in g:
        p = np.arange(-WIDTH, WIDTH + 1)[:, None]
        sign = np.array([1.0, -1.0])[None, :]
        q = np.round((sign * gi - p * f[0]) / f[1])
        e = np.abs(np.abs(p * f[0] + q * f[1]) - gi) / np.max(g)
        rows.append((np.broadcast_to(p, q.shape).ravel(), q.ravel(), e.ravel()))
    (p1, q1, e1), (p2, q2, e2) = rows
    # the best few candidates of each row, paired where unimodular
    best = np.inf
    for i in np.argsort(e1)[:64]:
        for j in np.argsort(e2)[:64]:
            if abs(p1[i] * q2[j] - q1[i] * p2[j]) == 1:
                best = min(best, max(e1[i], e2[j]))
    return float(best)


def main(n: int = 10_000, stride: int = 50) -> None:
    warnings.simplefilter("ignore")
    rng = np.random.default_rng(20261125)
    t0 = time.time()
    errs: list[float] = []
    refused: Counter[str] = Counter()
    worse: list[tuple[int, float]] = []
    only: list[str] = []
    for i in range(n):
        a, b, l0 = draw(rng)
        top = manakov.ManakovTop(a, b)
        sol = top.solve(l0)
        try:
            g = np.asarray(sol.torus.frequencies)
        except (manakov.ClosedFormError, ValueError, AttributeError):
            g = None
        if g is None:
            fm = manakov.frequency_map(top, l0[None, :])
            if manakov.tori.STATUS_NAMES[int(fm.status[0])] != "ok":
                continue
            try:
                _ = sol._motion.near_euler_frequencies()
                continue  # answered next to an Euler subspace or a plane
            except (manakov.ClosedFormError, ValueError):
                pass
            s = time.time()
            nu = np.asarray(sol._motion.closed_orbit_frequencies())
            only.append(
                f"  {i:5d}  nu = ({nu[0]:.12e}, {nu[1]:.12e})  map nu = "
                f"({fm.nu[0][0]:.12e}, {fm.nu[0][1]:.12e})  {time.time() - s:5.1f} s"
            )
            continue
        if i % stride:
            continue
        try:
            nu = np.asarray(sol._motion.closed_orbit_frequencies())
        except (manakov.ClosedFormError, ValueError) as e:
            refused[str(e).split(":")[1].strip()[:60]] += 1
            continue
        err = module_error(nu, np.abs(g))
        errs.append(err)
        if err > BOUND:
            worse.append((i, err))
    e = np.array(errs)
    print(f"part 1: every {stride}-th state of {n} whose genus-2 torus answers")
    print(f"  compared {len(e)}: median {np.median(e):.1e}, max {np.max(e):.1e}")
    print(f"  beyond {BOUND:.0e}: {len(worse)} {worse}")
    print(f"  closed-orbit route refused: {sum(refused.values())} {dict(refused)}")
    print(f"part 2: states of {n} the map answers only from closed orbits: {len(only)}")
    print("\n".join(only))
    print(f"time {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:3]))
