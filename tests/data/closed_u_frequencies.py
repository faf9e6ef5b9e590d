"""``manakov.frequency_map`` (the level set alone) against ``sol.frequencies`` (the solution).

Both take the velocities of the top's flow and of the second flow in closed form
(docs/theorem.md, "U in closed form"): the map from the reduction's constants and the
curve, the solution with its own sign convention and the theta quotients' fit at v0
as a guard. N_TOPS random tops (every third stiff: one spacing of a in [1e-2, 5e-2],
all c_ij up to 1e3), N_STATES standard-normal states each, seeded.

Reported: the relative distance ``max|nu_map - nu_sol| / max|nu_sol|`` over the states
both routes accept (median, 99th percentile, max, the count above 1e-14), and the
states only one route refuses.

Run: ``python tests/data/closed_u_frequencies.py [N_TOPS] [N_STATES] [SEED]`` (default
100 x 100, seed 3301; about a minute). Output committed as
``tests/data/closed_u_frequencies.txt``.
"""

from __future__ import annotations

import os
import platform
import sys
import time

import numpy as np

import manakov


def random_top(rng, stiff):
    while True:
        sp = 10 ** rng.uniform(-1.0, 0.3, 3)
        if stiff:
            sp[rng.integers(3)] = 10 ** rng.uniform(-2.0, np.log10(0.05))
        a = np.cumsum(np.concatenate([[rng.uniform(-1, 1)], sp]))
        b = rng.normal(size=4) * 10 ** rng.uniform(-0.5, 1.0)
        c = [(b[i] - b[j]) / (a[i] - a[j]) for i in range(4) for j in range(i + 1, 4)]
        if max(abs(x) for x in c) <= 1e3:
            return a, b


def main() -> None:
    n_tops = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    n_states = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 3301
    rng = np.random.default_rng(seed)
    print(
        f"machine: {platform.machine()} {os.cpu_count()} cpus; manakov {manakov.__version__}; "
        f"{n_tops} tops x {n_states} states, seed {seed}"
    )
    rel, only_map, only_sol, both_refused = [], 0, 0, 0
    t0 = time.time()
    for i in range(n_tops):
        a, b = random_top(rng, i % 3 == 0)
        top = manakov.ManakovTop(a, b)
        states = rng.normal(size=(n_states, 6))
        fm = manakov.frequency_map(top, states)
        for l0, nu, st in zip(states, fm.nu, fm.status):
            try:
                ref = top.solve(l0).frequencies
            except (ValueError, manakov.ClosedFormError):
                ref = None
            if st != 0 or ref is None:
                if st != 0 and ref is None:
                    both_refused += 1
                elif st != 0:
                    only_map += 1
                else:
                    only_sol += 1
                continue
            rel.append(np.max(np.abs(nu - ref)) / np.max(np.abs(ref)))
    r = np.array(rel)
    print(
        f"agreement over {len(r)} states: median {np.median(r):.1e}, 99% "
        f"{np.quantile(r, 0.99):.1e}, max {np.max(r):.1e}; above 1e-14: {np.sum(r > 1e-14)}; "
        f"exactly equal: {np.sum(r == 0)}"
    )
    print(
        f"refused by both: {both_refused}; only by the map: {only_map}; only by the "
        f"solution: {only_sol}  ({time.time() - t0:.0f} s)"
    )


if __name__ == "__main__":
    main()
