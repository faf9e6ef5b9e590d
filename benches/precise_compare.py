"""The precise Theorem against the integrators that reach its accuracy, in one process.

``sol.l(t, precise=True)`` is within half an ulp of ``|l0|`` of the true state on the
shared tops up to t = 100 (``tests/data/closed_u_long_double.txt``, the ``pr``
columns); in double precision no integrator is (gauss16 at a quarter of its default
step stays 1e-16 ... 1e-13 off, ``g16``). Its peer is therefore an integration in
extended precision: heyoka's Taylor integrator in 80-bit long double (tolerance
eps_ld ~ 1.1e-19, the reference of those tables; LLVM compile time excluded, the
integrator is built once). Also timed: the double Theorem and gauss16 at dt/4.

For each shared top with distinct spacings: the wall time to l(t) at 101 times in
[0, T] from a fresh ``solve`` (so the precise column includes the polish of the
constants, ~35 ms), for T = 100 and T = 1e4. The integrations' cost grows with T,
the Theorem's does not: over [0, 100] the long-double integration is the faster of
the two, over [0, 1e4] the precise Theorem. (At T = 1e4 neither is at half an ulp
any more: the precise phase carries the lattice rates' ~1e-19 relative error times
|U t|, the long-double trajectory its own accumulated error.) Medians of --repeats
runs, one process.

    python benches/precise_compare.py            # 5 repeats
    python benches/precise_compare.py --quick    # 3 repeats
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "data"))
try:
    import heyoka  # noqa: F401
    from longdouble_ref import reference
except ImportError as exc:  # pragma: no cover - optional bench dependency
    raise SystemExit("heyoka is not installed: pip install 'manakov[bench]'") from exc


def median_time(f, repeats: int) -> float:
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        out.append(time.perf_counter() - t0)
    return statistics.median(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    repeats = 3 if args.quick else args.repeats
    print("101 times in [0, T] from a fresh solve; wall time in ms (median)")
    print(
        f"{'top':9s} {'T':>6s} {'precise':>9s} {'heyoka ld':>10s} {'ld/precise':>11s} "
        f"{'theorem':>9s} {'gauss16/4':>10s}"
    )
    generic = manakov.problem("generic")
    reference(generic.a, generic.b, [1.0] * 6, [0.0])  # builds the integrator once
    for t_end in (100.0, 1e4):
        t = np.linspace(0.0, t_end, 101)
        ratios = []
        for name in ("generic", "physical", "wide"):
            p = manakov.problem(name)
            top = manakov.ManakovTop(p.a, p.b)
            l0 = np.asarray(p.l0, float)
            dt = top.default_dt(l0) / 4

            def precise(top=top, l0=l0, t=t):
                return top.solve(l0).l(t, precise=True)

            def long_double(p=p, l0=l0, t=t):
                return reference(p.a, p.b, l0, t)

            def theorem(top=top, l0=l0, t=t):
                return top.solve(l0).l(t)

            def gauss16(top=top, l0=l0, t=t, dt=dt, t_end=t_end):
                return top.integrate(l0, t_end, t_eval=t, dt=dt)

            t_pr, t_ld, t_th, t_g = (
                median_time(f, repeats) for f in (precise, long_double, theorem, gauss16)
            )
            ratios.append(t_ld / t_pr)
            print(
                f"{name:9s} {t_end:6g} {t_pr * 1e3:9.1f} {t_ld * 1e3:10.1f} "
                f"{t_ld / t_pr:10.2f}x {t_th * 1e3:9.2f} {t_g * 1e3:10.1f}"
            )
        print(
            f"T = {t_end:g}: heyoka in long double / precise Theorem, median over the tops: "
            f"{np.median(ratios):.2f}x"
        )


if __name__ == "__main__":
    main()
