# ruff: noqa: E741  (l is the paper's name for the state)
"""Round trips on random states, quoted in docs/kotter.md ("Accuracy").

Run: ``python tests/data/kotter_random_stats.py``. For each shared top's ``a``,
draws 400 states with standard normal entries (``numpy.random.default_rng(0)``),
maps each to Kötter coordinates and back, and prints how many succeed, the
median and largest relative round-trip error, and the states that raise
(other than the documented degenerate cases: a repeated root of F, h1^2 = 4 h0^2).
"""

import numpy as np

import manakov

N = 400
for name in manakov.problem_names():
    p = manakov.problem(name)
    rng = np.random.default_rng(0)
    errs, fails, skipped = [], [], 0
    for _ in range(N):
        l = rng.normal(size=6)
        try:
            k = manakov.kotter(p.a, p.b, l)
        except ValueError as e:
            if "repeated root" in str(e) or "vanishes" in str(e):
                skipped += 1
            else:
                fails.append((l, str(e)[:120]))
            continue
        back = manakov.from_kotter(p.a, p.b, k)
        errs.append(np.max(np.abs(back - l)) / np.max(np.abs(l)))
    e = np.array(errs)
    print(
        f"{name:16s} ok {len(e)}/{N - skipped} (skipped {skipped} degenerate)  "
        f"median {np.median(e):.1e}  max {e.max():.1e}  >1e-12: {np.sum(e > 1e-12)}"
    )
    for l, msg in fails:
        print("   fails:", np.array2string(l, precision=8), msg)
