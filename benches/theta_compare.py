"""Genus-2 theta benchmark: manakov vs python-flint vs numpy, in one process.

The shared batch of problems.json ("benchmark" -> "theta"): tau as given and
10^5 points z with real parts uniform in [0, 1) and imaginary parts uniform in
[-0.5, 0.5] (seeded). Every method computes the 16 values theta[a;b](z, tau)
(FLINT order) at each point. Prints the per-point time (median of repeats), the
maximum error relative to the largest of the 16 values at each point (truth:
python-flint at 200 bits on a subset), and the speed ratios.

Two comparisons, each printed as its own table:

* one core: manakov with ``parallel=False``, numpy with its BLAS pinned to one
  thread (OPENBLAS/OMP/MKL_NUM_THREADS=1, set before numpy is imported);
* all cores: manakov with its default ``parallel=True`` (rayon, all cores) and
  numpy with its BLAS threads left at their default, measured in a child process
  started without those variables (they must be set before numpy is imported).

python-flint is single-threaded either way; its one-core time is used in both.

Run:  python benches/theta_compare.py            (about 15 s)
      python benches/theta_compare.py --quick    (fewer points and repeats)
"""

from __future__ import annotations

import os
import sys

_BLAS_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
_CHILD_FLAG = "--all-cores-child"
_CHILD = _CHILD_FLAG in sys.argv
if not _CHILD:
    # One core for every method of the first comparison: numpy's BLAS would
    # otherwise use all cores for the matrix products of both numpy variants.
    for _var in _BLAS_VARS:
        os.environ[_var] = "1"

import argparse  # noqa: E402
import itertools  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from flint import acb, acb_mat, ctx  # noqa: E402

import manakov  # noqa: E402
from manakov.theta import DEFAULT_TOL  # noqa: E402

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


def measure(
    z: np.ndarray, tau: np.ndarray, *, parallel: bool, repeats: int, n_truth: int, tol: float
) -> list[tuple[str, float, np.ndarray, int]]:
    """(name, seconds per point, values on the first n_truth points, points) for
    manakov and the two numpy sums."""
    n = len(z)
    rows = []
    t, vals = timed(lambda: manakov.theta_all(z, tau, tol=tol, parallel=parallel), repeats)
    rows.append(("manakov.theta_all", t / n, vals[:n_truth], n))
    t, vals = timed(lambda: numpy_brute(z, tau), max(1, repeats // 2))
    rows.append((f"numpy brute force (box |n| <= {NMAX})", t / n, vals[:n_truth], n))
    t, vals = timed(lambda: numpy_separable(z, tau), repeats)
    rows.append(("numpy separable (same box, BLAS products)", t / n, vals[:n_truth], n))
    return rows


def to_json(vals: np.ndarray) -> list:
    return np.stack([vals.real, vals.imag], axis=-1).tolist()


def from_json(data: list) -> np.ndarray:
    arr = np.asarray(data, float)
    return arr[..., 0] + 1j * arr[..., 1]


def print_table(title: str, rows: list, truth: np.ndarray) -> None:
    base = rows[0][1]
    print(title)
    head = f"{'points':>7s} {'us/point':>10s} {'x manakov':>10s} {'max rel err':>12s}"
    print(f"  {'method':44s} {head}")
    for name, per, vals, npts in rows:
        err = max_rel_error(vals, truth[: len(vals)])
        print(f"  {name:44s} {npts:7d} {per * 1e6:10.3f} {per / base:10.1f} {err:12.2e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer points and repeats")
    parser.add_argument(
        "--tol",
        type=float,
        default=DEFAULT_TOL,
        help=f"manakov's truncation tolerance (default: the package default, {DEFAULT_TOL:g})",
    )
    parser.add_argument(_CHILD_FLAG, action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    n = 10**4 if args.quick else 10**5
    n_flint = 50 if args.quick else 200
    n_truth = 50 if args.quick else 200
    repeats = 3 if args.quick else 7
    tau, z = load_batch(10**5)
    z = z[:n]

    if args.all_cores_child:
        rows = measure(z, tau, parallel=True, repeats=repeats, n_truth=n_truth, tol=args.tol)
        json.dump([(name, per, to_json(vals), npts) for name, per, vals, npts in rows], sys.stdout)
        return

    truth = flint_all(z[:n_truth], tau, 200)
    one = measure(z, tau, parallel=False, repeats=repeats, n_truth=n_truth, tol=args.tol)
    t, vals = timed(lambda: flint_all(z[:n_flint], tau, 53), max(1, repeats // 2))
    flint_row = ("python-flint acb_mat.theta (prec 53)", t / n_flint, vals[:n_truth], n_flint)
    one.insert(1, flint_row)

    env = {k: v for k, v in os.environ.items() if k not in _BLAS_VARS}
    cmd = [sys.executable, os.path.abspath(__file__), _CHILD_FLAG, "--tol", repr(args.tol)]
    if args.quick:
        cmd.append("--quick")
    child = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    all_cores = [
        (name, per, from_json(vals), npts) for name, per, vals, npts in json.loads(child.stdout)
    ]
    all_cores.insert(1, ("python-flint (1 thread; time from above)",) + flint_row[1:])

    print(f"tau = {tau.tolist()}")
    print(
        f"points: {n} (errors on the first {n_truth}; truth: python-flint at 200 bits); "
        f"manakov tol = {args.tol:g}; cores: {os.cpu_count()}"
    )
    print_table("one core (manakov parallel=False; numpy BLAS threads = 1):", one, truth)
    print_table("all cores (manakov parallel=True; numpy BLAS threads default):", all_cores, truth)
    err = max(max_rel_error(one[0][2], truth), max_rel_error(all_cores[0][2], truth))
    print(
        f"goals, one core:  >= 1000x flint: {one[1][1] / one[0][1]:.0f}x; "
        f">= 10x separable numpy: {one[3][1] / one[0][1]:.1f}x"
    )
    print(
        f"goals, all cores: >= 1000x flint: {all_cores[1][1] / all_cores[0][1]:.0f}x; "
        f">= 10x separable numpy: {all_cores[3][1] / all_cores[0][1]:.1f}x"
    )
    print(f"manakov max rel error: {err:.2e} (goal <= 1e-13)")


if __name__ == "__main__":
    main()
