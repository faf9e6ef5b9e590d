# ruff: noqa: E741  (l is the paper's name for the state)
"""The precise evaluation of the Theorem next to the degenerate sets.

On the three shared tops with distinct spacings ('generic', 'physical', 'wide'),
states at distances 1e-1 ... 1e-8 (relative, in a random direction) from h0 = 0
(a rank-2 state u ^ v), from a self-dual state (m = n) and from an so(3) block
(l12, l13, l23 only); those solved by the genus-2 Theorem are compared at
t = 1, 10, 30 with heyoka's long-double reference (``longdouble_ref.py``):
``sol.l(t, precise=True)``, ``sol.l(t)`` and gauss16 at a quarter of its default
step, the largest error relative to |l0|. A refused precise evaluation
(``ClosedFormError``) is listed with its reason.

Run: ``python tests/data/precise_degenerate.py`` (about a minute). Output
committed as ``tests/data/precise_degenerate.txt``.
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path

import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).resolve().parent))
from longdouble_ref import reference  # noqa: E402

POS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
DISTANCES = [1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8]
TIMES = np.array([0.0, 1.0, 10.0, 30.0])


def wedge(u, v):
    return np.array([u[i] * v[j] - u[j] * v[i] for i, j in POS])


def self_dual(m):
    return np.array([m[2], -m[1], m[0], m[0], m[1], m[2]])


def main() -> None:
    rng = np.random.default_rng(11)
    print(
        f"machine: {platform.machine()} {os.cpu_count()} cpus; manakov {manakov.__version__}; "
        f"seed 11; errors at t = 1, 10, 30 against the long-double reference, / |l0|"
    )
    print(f"{'top':9s} {'near':8s} {'dist':>6s} {'precise':>9s} {'double':>9s} {'gauss16':>9s}")
    rows = []
    for name in ["generic", "physical", "wide"]:
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        for near in ["h0", "selfdual", "block"]:
            for d in DISTANCES:
                if near == "h0":
                    base = wedge(rng.normal(size=4), rng.normal(size=4))
                elif near == "selfdual":
                    base = self_dual(rng.normal(size=3))
                else:
                    base = np.zeros(6)
                    base[[0, 1, 3]] = rng.normal(size=3)
                l0 = base / np.linalg.norm(base) + d * rng.normal(size=6) / np.sqrt(6)
                sol = top.solve(l0)
                head = f"{name:9s} {near:8s} {d:6.0e}"
                if sol.kind != "genus2":
                    print(f"{head} kind {sol.kind}")
                    continue
                ref = reference(p.a, p.b, l0, TIMES)
                n0 = np.linalg.norm(l0)

                def err(x, ref=ref, n0=n0):
                    return float(np.max(np.abs(np.asarray(x, np.longdouble) - ref)) / n0)

                try:
                    e_p = err(sol.l(TIMES, precise=True))
                    why = ""
                except manakov.ClosedFormError as exc:
                    e_p, why = float("nan"), f"  refused: {exc}"
                e_d = err(sol.l(TIMES))
                e_g = err(top.integrate(l0, 30.0, t_eval=TIMES, dt=top.default_dt(l0) / 4).l)
                print(f"{head} {e_p:9.1e} {e_d:9.1e} {e_g:9.1e}{why}", flush=True)
                rows.append((e_p, e_d, e_g))
    r = np.array(rows)
    ok = ~np.isnan(r[:, 0])
    print()
    print(
        f"{len(r)} genus-2 states, {int(ok.sum())} with a precise evaluation: precise max "
        f"{np.nanmax(r[:, 0]):.1e}; double max {r[:, 1].max():.1e}; gauss16 max "
        f"{r[:, 2].max():.1e}; precise > gauss16 on {int(np.sum(r[ok, 0] > r[ok, 2]))}"
    )


if __name__ == "__main__":
    main()
