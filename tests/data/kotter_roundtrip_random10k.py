# ruff: noqa: E741  (l is the paper's name for the state)
"""Round trip l -> Kötter -> l on 10^4 random tops and states (issue 9, "Must show").

Run: ``python tests/data/kotter_roundtrip_random10k.py [N] [SEED]`` (default
N = 10000, SEED = 20261123, a seed that no test uses). Each draw takes ``a``,
``b``, ``l0`` standard normal with ``a`` sorted, maps ``l0`` to Kötter
coordinates and back with :func:`manakov.kotter` / :func:`manakov.from_kotter`,
and prints the distribution of the relative error ``max|l' - l| / max|l|``
and every exception with its message. The documented singular states
(docs/kotter.md, "Degenerate and bad input") may raise; anything else is a
spurious exception and is listed as such.
"""

import sys
import time

import numpy as np

import manakov

N = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000
SEED = int(sys.argv[2]) if len(sys.argv) > 2 else 20261123

rng = np.random.default_rng(SEED)
errs, raised = [], []
t0 = time.perf_counter()
for i in range(N):
    a = np.sort(rng.normal(size=4))
    b = rng.normal(size=4)
    l = rng.normal(size=6)
    try:
        k = manakov.kotter(a, b, l)
        back = manakov.from_kotter(a, b, k)
    except (ValueError, manakov.ConvergenceError) as e:
        raised.append((i, type(e).__name__, str(e)[:160]))
        continue
    errs.append(np.max(np.abs(back - l)) / np.max(np.abs(l)))
e = np.array(errs)
print(f"N = {N}, seed = {SEED}, {time.perf_counter() - t0:.1f} s")
print(f"round trips: {len(e)}, raised: {len(raised)}")
for q in (50, 90, 99, 99.9):
    print(f"  {q:5}th percentile: {np.percentile(e, q):.2e}")
print(f"  max: {e.max():.2e}")
for thr in (1e-14, 1e-13, 1e-12, 1e-10):
    print(f"  > {thr:.0e}: {np.sum(e > thr)} ({100 * np.mean(e > thr):.3f} %)")
print(f"  <= 1e-13: {100 * np.mean(e <= 1e-13):.3f} %")
for i, name, msg in raised:
    print(f"  raised #{i}: {name}: {msg}")
