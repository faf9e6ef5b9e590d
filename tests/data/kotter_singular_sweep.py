# ruff: noqa: E741  (l is the paper's name for the state)
"""States near the singular set h1^2 = 4 h0^2 (m = +-n), quoted in docs/kotter.md.

Run: ``python tests/data/kotter_singular_sweep.py``. For each shared top and each
relative distance rho, 20 states n = +-m + rho |m| v (m, v random, seed 5): how many
reduce, the worst round-trip error, and the first error message.
"""

import numpy as np

import manakov

rng = np.random.default_rng(5)
for name in manakov.problem_names():
    p = manakov.problem(name)
    for rel in [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]:
        errs = []
        fails = []
        for _ in range(20):
            m = rng.normal(size=3)
            sgn = rng.choice([-1, 1])
            v = rng.normal(size=3)
            v /= np.linalg.norm(v)
            n = sgn * m + rel * np.linalg.norm(m) * v
            l = np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])
            try:
                k = manakov.kotter(p.a, p.b, l)
                back = manakov.from_kotter(p.a, p.b, k)
                errs.append(np.abs(back - l).max() / np.abs(l).max())
            except Exception as e:
                fails.append(str(e)[:100])
        print(name, rel, f"max {max(errs) if errs else np.nan:.1e}", len(fails), fails[:1])
