# ruff: noqa: E741  (l is the paper's name for the state)
"""States near the singular set h1^2 = 4 h0^2 (m = +-n), quoted in docs/kotter.md.

Run: ``python tests/data/kotter_singular_sweep.py [N] [SEED]`` (default N = 200,
SEED = 5). States n = +-m + rho |m| v (m, v random, |v| = 1), whose relative
distance to the singular set is delta = (h1^2 - 4 h0^2)/h1^2 ~ rho^2, in three
families of N states per rho:

* the four shared tops (N/4 each);
* random tops, a and b standard normal;
* random tops with a pinched pair, a_2 = a_1 + 10^U(-5, -2) (the curve (8) then has two
  nearly coinciding branch points d_1, d_2 besides the large d_4 of the singular set).

For each rho: the range of delta, how many states reduce, the median and largest
round trip l -> manakov.kotter -> manakov.from_kotter -> l (relative to max|l|), the
largest mismatch of the consistency check of the corrected (42) (|g - g42|/|g42|,
refused above 1e-6), and the first messages of those that raise. The documented threshold is
``NEAR_SINGULAR_RTOL`` = 1e-10 (closer states may raise) and ``DEGENERATE_RTOL`` =
1e-12 (closer states always raise).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import manakov

RHOS = (1e-2, 1e-3, 1e-4, 3e-5, 1e-5, 5e-6, 2e-6, 1e-6)


def near_singular_state(rng: np.random.Generator, rho: float) -> np.ndarray:
    m = rng.normal(size=3)
    v = rng.normal(size=3)
    v /= np.linalg.norm(v)
    n = rng.choice([-1, 1]) * m + rho * np.linalg.norm(m) * v
    return np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])


def distance(l: np.ndarray) -> float:
    m, n = np.array([l[3], -l[1], l[0]]), l[[2, 4, 5]]
    return float(np.sum((m - n) ** 2) * np.sum((m + n) ** 2) / np.sum(l**2) ** 2)


def tops(family: str, rng: np.random.Generator, count: int):
    if family == "shared":
        for i in range(count):
            p = manakov.problem(manakov.problem_names()[i % 4])
            yield p.a, p.b
        return
    for _ in range(count):
        a = np.sort(rng.normal(size=4))
        if family == "pinched":
            a[1] = a[0] + 10 ** rng.uniform(-5, -2)
        yield a, rng.normal(size=4)


def main() -> None:
    N = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    for family in ("shared", "random", "pinched"):
        print(f"{family} tops, {N} states per rho")
        for rho in RHOS:
            errs, raised, deltas, mis42 = [], [], [], []
            for a, b in tops(family, rng, N):
                l = near_singular_state(rng, rho)
                deltas.append(distance(l))
                try:
                    k = manakov.kotter(a, b, l)
                    back = manakov.from_kotter(a, b, k)
                except ValueError as e:
                    raised.append((deltas[-1], str(e)[:150]))
                    continue
                errs.append(np.max(np.abs(back - l)) / np.max(np.abs(l)))
                # the consistency check of the corrected (42): |g - g42|/|g42|
                g42 = np.sqrt(complex(k.h[0]) / k.K) / (1 - k.eps * k.P0)
                mis42.append(abs(k.g - g42) / abs(g42))
            e = np.array(errs) if errs else np.array([np.nan])
            m42 = np.max(mis42) if mis42 else np.nan
            print(
                f"  rho {rho:.0e}  delta {min(deltas):.1e} .. {max(deltas):.1e}: "
                f"reduced {len(errs)}/{N}, round trip median {np.median(e):.1e}, "
                f"max {e.max():.1e}; (42) mismatch max {m42:.1e}; raised {len(raised)}"
            )
            for dl, msg in raised[:2]:
                print(f"      delta {dl:.2e}: {msg}")
    print(f"{time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
