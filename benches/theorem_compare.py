"""Theta-function solution vs gauss16 integration of the same time points, in one process.

For the 'generic' top: the cost of ``sol.l(t)`` at N times (after one ``solve``)
against ``top.integrate(l0, t_end, t_eval=t)`` with gauss16 at dt = 1e-2 for the
same N times spread over [0, t_end]. The integration cost grows with t_end, the
theta cost does not; the break-even t_end is where they cross (printed from the
measured per-time and per-unit-time costs). Medians of 5 repeats.

Run: python benches/theorem_compare.py
"""

from __future__ import annotations

import time

import numpy as np

import manakov


def median_time(f, repeats: int = 5) -> float:
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def main() -> None:
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    t_setup = median_time(lambda: top.solve(p.l0), 20)
    sol = top.solve(p.l0)
    n = 1000
    print(f"solve set-up: {t_setup * 1e6:.0f} us")
    print(f"{'t_end':>8} {'theta [ms]':>11} {'gauss16 [ms]':>13} {'ratio int/theta':>16}")
    per_unit = []
    for t_end in (10.0, 100.0, 1000.0):
        t = np.linspace(0.0, t_end, n)
        th = median_time(lambda t=t: sol.l(t))
        it = median_time(lambda t=t, t_end=t_end: top.integrate(p.l0, t_end, t_eval=t, dt=1e-2))
        per_unit.append(it / t_end)
        print(f"{t_end:8g} {th * 1e3:11.2f} {it * 1e3:13.2f} {it / th:16.1f}")
    big = np.full(10**5, 1.0)
    th1 = median_time(lambda: sol.l(big))
    th6 = median_time(lambda: sol.l(big * 1e6))
    print(
        f"l(t) per time, 1e5 times: t=1: {th1 / 1e5 * 1e9:.0f} ns, t=1e6: {th6 / 1e5 * 1e9:.0f} ns"
    )
    c_theta = th1 / 1e5 * n
    print(
        f"break-even t_end for {n} sample times: {c_theta / np.median(per_unit):.3g} "
        f"(integration {np.median(per_unit) * 1e3:.3f} ms per unit time)"
    )


if __name__ == "__main__":
    main()
