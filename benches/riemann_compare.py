"""Genus-2 period matrix and Abel map: manakov vs Sage's RiemannSurface, in one process.

Times, on seeded random genus-2 curves with complex branch points (degree 5):

* ``HyperellipticCurve(e)`` (canonical basis, periods, tau) — per curve;
* ``.abel(x, y)`` on a batch of 500 points — per point;
* ``.invert(u)`` on 100 divisors — per call;

and, if Sage or passagemath is importable, ``RiemannSurface(y^2 - f).riemann_matrix()``
(its default, heuristic method) and ``abel_jacobi`` on a few divisors, with the
ratios. Without Sage it prints times recorded on another machine (Sage 10.8 /
passagemath 10.8: 0.19-0.31 s per genus-2 period matrix heuristically, 1.18 s
rigorously; abel_jacobi 0.01-0.08 s per divisor).

Run:  python benches/riemann_compare.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import manakov

#: Recorded times of Sage's RiemannSurface (seconds).
SAGE_ANCHOR = {
    "period matrix (heuristic)": (0.19, 0.31),
    "period matrix (rigorous)": (1.18, 1.18),
    "abel_jacobi per divisor": (0.01, 0.08),
}


def _median_time(fn, repeats: int) -> float:
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def _curves(n: int, seed: int = 20261123) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [2 * (rng.uniform(-1, 1, 5) + 1j * rng.uniform(-1, 1, 5)) for _ in range(n)]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    # Many short repeats, median: the machine may be shared (noisy neighbours
    # inflate a long batch's mean; the median of short ones is robust).
    reps = 21 if args.quick else 101
    curves = _curves(20)

    t_period = _median_time(lambda: [manakov.HyperellipticCurve(e) for e in curves], reps) / len(
        curves
    )
    h = manakov.HyperellipticCurve(curves[0])
    rng = np.random.default_rng(1)
    npts = 500
    x = 3 * (rng.uniform(-1, 1, npts) + 1j * rng.uniform(-1, 1, npts))
    y = h.y(x) * rng.choice([-1, 1], npts)
    t_abel = _median_time(lambda: h.abel(x, y), reps) / npts
    u = h.abel(x[:200].reshape(-1, 2), y[:200].reshape(-1, 2)).sum(-2)
    t_inv = _median_time(lambda: h.invert(u), reps) / len(u)

    print("manakov.HyperellipticCurve, genus 2, degree 5, complex branch points")
    print(f"  period matrix   {t_period * 1e6:9.1f} us per curve")
    print(f"  abel (batched)  {t_abel * 1e6:9.2f} us per point")
    print(f"  invert          {t_inv * 1e6:9.1f} us per divisor")

    try:
        from sage.all import QQ, PolynomialRing, RiemannSurface  # type: ignore[import-not-found]
    except ImportError:
        # Times from another machine: printed for orientation, with no ratio
        # (a ratio across machines would be a figure this run did not measure).
        print("\nSage/passagemath not importable here; Sage 10.8 times recorded on")
        print("another machine (not comparable with the times above):")
        for what, (lo, hi) in SAGE_ANCHOR.items():
            print(f"  Sage {what:28s} {lo:.2f}-{hi:.2f} s")
        return
    # Sage needs exact coefficients: the branch points rounded to Gaussian
    # rationals (a nearby curve, the same amount of work).
    ring = PolynomialRing(QQ, "i")
    gi = ring.gen()
    k = ring.quotient(gi**2 + 1, "I")
    pr = PolynomialRing(k, ["x", "y"])
    xx, yy = pr.gens()
    t_sage = []
    for e in curves[:3]:
        f = pr(1)
        for ek in e:
            f *= xx - (QQ(round(ek.real, 6)) + QQ(round(ek.imag, 6)) * k.gen())
        t0 = time.perf_counter()
        RiemannSurface(yy**2 - f).riemann_matrix()
        t_sage.append(time.perf_counter() - t0)
    ts = float(np.median(t_sage))
    ratio = f"{ts / t_period:,.0f}x"
    print(f"\nSage RiemannSurface.riemann_matrix {ts:.3f} s per curve -> ratio {ratio}")


if __name__ == "__main__":
    main()
