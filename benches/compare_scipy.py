"""manakov's integrators against scipy's DOP853 on the shared 'generic' top, in one process.

The set-up is the shared benchmark (problems.json, "integration"): 'generic' to
t_end = 1e4, sampled every 1.0. For each solver the script reports the median
wall time over --repeats runs, time per step, the largest relative drift of
each integral over the run, the error of the state at t = 100 against the
38-digit mpmath reference (tests/data/reference_generic.json), and the speed
ratio to scipy DOP853 (rtol = atol = 1e-12, numpy right-hand side).

    python benches/compare_scipy.py            # full run (scipy takes ~10-20 s per repeat)
    python benches/compare_scipy.py --quick    # t_end = 1e3, 1 scipy repeat
"""

# ruff: noqa: E741
from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import manakov

ROOT = Path(__file__).resolve().parents[1]
NAMES = ("H0", "H1", "H2", "H3", "H")


def reference_at_100() -> np.ndarray:
    ref = json.loads((ROOT / "tests" / "data" / "reference_generic.json").read_text())
    return np.array([float(x) for x in ref["states"]["100"]])


def drifts(top: manakov.ManakovTop, ls: np.ndarray) -> dict[str, float]:
    ints = top.integrals(ls)
    return {k: float(np.max(np.abs(v - v[0])) / abs(v[0])) for k, v in ints.items()}


def timed(fn, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="t_end = 1e3 and 1 scipy repeat")
    ap.add_argument("--repeats", type=int, default=5, help="repeats of the manakov runs")
    ap.add_argument("--scipy-repeats", type=int, default=3)
    args = ap.parse_args()

    setup = manakov.benchmark_setup("integration")
    p = manakov.problem(setup["top"])
    t_end = 1e3 if args.quick else float(setup["t_end"])
    every = float(setup["sample_every"])
    scipy_repeats = 1 if args.quick else args.scipy_repeats
    top = manakov.ManakovTop(p.a, p.b)
    t_eval = np.arange(0.0, t_end + every / 2, every)
    i100 = int(np.argmin(np.abs(t_eval - 100.0)))
    ref100 = reference_at_100()

    c = top.c
    iu = np.triu_indices(4, 1)

    def rhs(t, y):
        L = np.zeros((4, 4))
        L[iu] = y
        L = L - L.T
        W = c * L
        return (L @ W - W @ L)[iu]

    rows = []

    def scipy_run():
        return solve_ivp(
            rhs, (0.0, t_end), p.l0, method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t_eval
        )

    t_scipy, sol = timed(scipy_run, scipy_repeats)
    ls = sol.y.T
    rows.append(
        (
            "scipy DOP853 (tol 1e-12)",
            t_scipy,
            sol.t.size,
            sol.nfev // 12,
            drifts(top, ls),
            float(np.max(np.abs(ls[i100] - ref100))),
        )
    )

    configs = [
        ("manakov gauss16 (default)", {}),
        ("manakov gauss6 (default dt)", {"method": "gauss6"}),
        ("manakov dop853 (tol 1e-12)", {"method": "dop853", "rtol": 1e-12, "atol": 1e-12}),
        ("manakov dopri5 (tol 1e-12)", {"method": "dopri5", "rtol": 1e-12, "atol": 1e-12}),
    ]
    for label, kw in configs:

        def run(kw=kw):
            return top.integrate(p.l0, t_end, t_eval=t_eval, **kw)

        run()  # warm-up
        t_run, tr = timed(run, args.repeats)
        rows.append(
            (
                label,
                t_run,
                tr.t.size,
                tr.steps,
                tr.max_drift(),
                float(np.max(np.abs(tr.l[i100] - ref100))),
            )
        )

    # Batch: integrate_many over 8 initial conditions, serial vs rayon-parallel.
    rng = np.random.default_rng(0)
    l0s = p.l0 * (1 + 0.1 * rng.normal(size=(8, 6)))
    dt = top.default_dt(p.l0)
    batch = {}
    for parallel in (False, True):

        def runb(parallel=parallel):
            return top.integrate_many(l0s, t_end, t_eval=t_eval, dt=dt, parallel=parallel)

        runb()
        batch[parallel], _ = timed(runb, args.repeats)

    print(
        f"'generic' top, t_end = {t_end:g}, samples every {every:g}; medians of "
        f"{args.repeats} runs (scipy: {scipy_repeats})"
    )
    head = (
        f"{'solver':28s} {'time [s]':>9s} {'steps':>8s} {'us/step':>8s} "
        + " ".join(f"{'drift ' + n:>9s}" for n in NAMES)
        + f" {'err t=100':>10s} {'speed-up':>9s}"
    )
    print(head)
    print("-" * len(head))
    for label, t_run, _, steps, d, e100 in rows:
        per = 1e6 * t_run / steps if steps else float("nan")
        print(
            f"{label:28s} {t_run:9.4f} {steps:8d} {per:8.2f} "
            + " ".join(f"{d[n]:9.1e}" for n in NAMES)
            + f" {e100:10.1e} {t_scipy / t_run:8.0f}x"
        )
    print()
    print(
        f"scipy DOP853 steps: {rows[0][3]} (nfev // 12); the step count is estimated from "
        f"nfev as DOP853 uses 12 evaluations per step"
    )
    d = rows[1]
    print(
        f"default gauss16: max drift {max(d[4].values()):.1e} (claim <= 1e-13: "
        f"{'yes' if max(d[4].values()) <= 1e-13 else 'NO'}), error at t=100 {d[5]:.1e} vs scipy "
        f"{rows[0][5]:.1e} ({'no worse' if d[5] <= rows[0][5] else 'WORSE'}), speed-up "
        f"{t_scipy / d[1]:.0f}x (claim >= 300x: {'yes' if t_scipy / d[1] >= 300 else 'NO'})"
    )
    print(
        f"integrate_many, 8 initial states: serial {batch[False]:.4f} s, "
        f"parallel (rayon) {batch[True]:.4f} s, ratio {batch[False] / batch[True]:.2f}"
    )


if __name__ == "__main__":
    main()
