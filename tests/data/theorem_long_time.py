"""Issue 10, long times: |l_theta(t) - l_int(t)| / |l0| at t = 1e4 and t = 1e6 on the
four shared problems (l_int: gauss16 at dt = 1e-2; the t = 1e6 run takes 1e8 steps,
minutes per problem). Output committed as tests/data/theorem_long_time.txt.

Run: python tests/data/theorem_long_time.py [problem ...]
"""

from __future__ import annotations

import sys
import time

import numpy as np

import manakov


def main(names: list[str]) -> None:
    for name in names:
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        sol = top.solve(p.l0)
        t = np.array([0.0, 1e4, 1e6])
        t0 = time.time()
        l_int = top.integrate(p.l0, 1e6, t_eval=t, dt=1e-2, max_steps=2 * 10**8).l
        dt = time.time() - t0
        err = np.max(np.abs(sol.l(t) - l_int), axis=1) / np.linalg.norm(p.l0)
        print(
            f"{name}: t=1e4 {err[1]:.2e}  t=1e6 {err[2]:.2e}  (integration {dt:.0f} s)", flush=True
        )


if __name__ == "__main__":
    main(sys.argv[1:] or ["generic", "physical", "wide", "near_degenerate"])
