"""Genus-2 theta benchmark: manakov vs python-flint vs numpy, in one process.

The shared batch of problems.json ("benchmark" -> "theta"): tau as given and
10^5 points z with real parts uniform in [0, 1) and imaginary parts uniform in
[-0.5, 0.5] (seeded). Every method computes the 16 values theta[a;b](z, tau)
(FLINT order) at each point. Prints the per-point time (median of repeats), the
maximum error relative to the largest of the 16 values at each point (truth:
python-flint at 200 bits on a subset), and the speed ratios.

All methods run on one core (BLAS threads set to 1 before numpy is imported).

Run:  python benches/theta_compare.py            (about a minute)
      python benches/theta_compare.py --quick    (fewer points and repeats)
"""

from __future__ import annotations

import os

# One core for every method (the comparison is per core): numpy's BLAS would
# otherwise use all cores for the separable variant's matrix products.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import itertools  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from flint import acb, acb_mat, ctx  # noqa: E402

import manakov  # noqa: E402

SEED = 20261121


def load_batch(n: int) -> tuple[np.ndarray, np.ndarray]:
    setup = manakov.benchmark_setup("theta")
    tau = np.array([[complex(*entry) for entry in row] for row in setup["tau"]])
    rng = np.random.default_rng(SEED)
    z = rng.uniform(0.0, 1.0, (n, 2)) + 1j * rng.uniform(-0.5, 0.5, (n, 2))
    return tau, z


def flint_all(z: np.ndarray, tau: np.ndarray, prec: int) -> np.ndarray:
    old = ctx.prec
    ctx.prec = prec
    try:
        t = acb_mat([[acb(x.real, x.imag) for x in row] for row in tau])
        out = np.empty((len(z), 16), complex)
        for i, zi in enumerate(z):
            res = t.theta(acb_mat([[acb(x.real, x.imag)] for x in zi]))
            out[i] = [complex(res[0, k]) for k in range(16)]
        return out
    finally:
        ctx.prec = old


#: Box of the numpy sums: |n_k| <= NMAX. Omitted terms are below
#: exp(-pi * 0.78 * 4.5^2 + 2 pi * 4.5 * 0.5 * 2) ~ 1e-13 relative to theta ~ 1
#: for this tau (smallest eigenvalue of Im tau 0.78) and |Im z| <= 0.5.
NMAX = 5


def numpy_brute(z: np.ndarray, tau: np.ndarray, chunk: int = 2000) -> np.ndarray:
    """Vectorised direct sum: one complex exponential per (point, term)."""
    n = np.array(list(itertools.product(range(-NMAX, NMAX + 1), repeat=2)), float)
    out = np.empty((len(z), 16), complex)
    chars = manakov.characteristics(2)
    for start in range(0, len(z), chunk):
        zc = z[start : start + chunk]
        for a in ((0, 0), (0, 1), (1, 0), (1, 1)):
            m = n + np.array(a) / 2
            quad = np.exp(1j * np.pi * np.einsum("ki,ij,kj->k", m, tau, m))
            e = quad[None, :] * np.exp(2j * np.pi * zc @ m.T)
            for idx, (aa, b) in enumerate(chars):
                if aa == a:
                    sign = np.exp(1j * np.pi * (m @ np.array(b, float)))
                    out[start : start + chunk, idx] = e @ sign
    return out


def numpy_separable(z: np.ndarray, tau: np.ndarray, chunk: int = 20000) -> np.ndarray:
    """Separable variant: exp(2 pi i m1 z1) and exp(2 pi i m2 z2) as 1-D factors,
    the cross term exp(i pi m^T tau m) as a small matrix; theta = A1 (C o S_b) A2^T."""
    k = np.arange(-NMAX, NMAX + 1, dtype=float)
    out = np.empty((len(z), 16), complex)
    for start in range(0, len(z), chunk):
        zc = z[start : start + chunk]
        for a1, a2 in itertools.product((0, 1), repeat=2):
            m1, m2 = k + a1 / 2, k + a2 / 2
            c = np.exp(
                1j
                * np.pi
                * (
                    tau[0, 0] * m1[:, None] ** 2
                    + 2 * tau[0, 1] * m1[:, None] * m2[None, :]
                    + tau[1, 1] * m2[None, :] ** 2
                )
            )
            f1 = np.exp(2j * np.pi * zc[:, :1] * m1[None, :])
            f2 = np.exp(2j * np.pi * zc[:, 1:] * m2[None, :])
            for b1, b2 in itertools.product((0, 1), repeat=2):
                s = np.exp(1j * np.pi * (b1 * m1[:, None] + b2 * m2[None, :]))
                idx = 8 * a1 + 4 * a2 + 2 * b1 + b2
                out[start : start + chunk, idx] = np.einsum("nk,nk->n", f1 @ (c * s), f2)
    return out


def timed(fn, repeats: int) -> tuple[float, np.ndarray]:
    """Median wall time of ``repeats`` calls after one untimed warm-up call."""
    times = []
    result = fn()
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def max_rel_error(got: np.ndarray, truth: np.ndarray) -> float:
    scale = np.max(np.abs(truth), axis=1)
    return float(np.max(np.max(np.abs(got - truth), axis=1) / scale))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer points and repeats")
    args = parser.parse_args()
    n = 10**4 if args.quick else 10**5
    n_flint = 50 if args.quick else 200
    n_truth = 50 if args.quick else 200
    repeats = 3 if args.quick else 7
    tau, z = load_batch(10**5)
    z = z[:n]
    sub = z[:n_truth]

    truth = flint_all(sub, tau, 200)

    rows = []
    t, vals = timed(lambda: manakov.theta_all(z, tau), repeats)
    rows.append(("manakov.theta_all", t / n, max_rel_error(vals[:n_truth], truth), n))
    t, vals = timed(lambda: flint_all(z[:n_flint], tau, 53), max(1, repeats // 2))
    rows.append(
        (
            "python-flint acb_mat.theta (prec 53)",
            t / n_flint,
            max_rel_error(vals[:n_truth], truth[:n_flint]),
            n_flint,
        )
    )
    t, vals = timed(lambda: numpy_brute(z, tau), max(1, repeats // 2))
    rows.append(("numpy brute force", t / n, max_rel_error(vals[:n_truth], truth), n))
    t, vals = timed(lambda: numpy_separable(z, tau), repeats)
    rows.append(("numpy separable", t / n, max_rel_error(vals[:n_truth], truth), n))

    base = rows[0][1]
    print(f"tau = {tau.tolist()}")
    print(f"points: {n} (errors on the first {n_truth}; truth: python-flint at 200 bits)")
    print(
        f"{'method':40s} {'points':>7s} {'us/point':>10s} {'x manakov':>10s} {'max rel err':>12s}"
    )
    for name, per, err, npts in rows:
        print(f"{name:40s} {npts:7d} {per * 1e6:10.3f} {per / base:10.1f} {err:12.2e}")
    print(
        f"goals: >= 1000x flint: {rows[1][1] / base:.0f}x; "
        f">= 10x separable numpy: {rows[3][1] / base:.1f}x; "
        f"error <= 1e-13: {rows[0][2]:.2e}"
    )


if __name__ == "__main__":
    main()
