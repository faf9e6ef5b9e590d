"""manakov's integrators against heyoka (Taylor's method, LLVM-compiled) in one process.

Set-up (issue 12): the shared 'generic' top (its a, b; the c_ij of (2) rounded to
doubles, the same coefficients for every solver).

* single trajectory: the 'generic' l0 to t = 1e4 (end point only);
* batches of 100, 1000, 1e4 random states to t = 100: directions drawn from a
  seeded standard normal and scaled to |l0| of 'generic', so that every member
  has the time scale of the shared problem (and manakov's batch default step is
  the single-trajectory one).

Accuracy: the error of a run is the largest relative error max|l - ref| / max|ref|
over the states at the end time, against heyoka's Taylor integrator in 80-bit long
double (tolerance eps_ld ~ 1e-19) on the same double coefficients, i.e. a reference
~1e3 times tighter than any double run. For batches the reference covers the first
--ref-states states (long double runs are scalar and slow).

Equal accuracy: heyoka runs at tolerance eps (its most accurate setting, as in the
issue) and looser; manakov runs gauss16 at a ladder of steps dt and its Taylor method
(method="taylor") at a ladder of tolerances; the ratio row pairs heyoka at tol = eps
with the fastest manakov run, any method, whose error is not larger. heyoka's
batch mode uses one SIMD lane per trajectory (batch size 4 = AVX2 doubles),
looping over the batch on one thread; its compile time (LLVM, caches cleared and the
disk cache disabled) is reported separately and added in the "incl. compile" ratio.
Times are medians of --repeats runs.

    python benches/compare_heyoka.py                  # everything (a few minutes)
    python benches/compare_heyoka.py --quick          # sizes 100, 1000; 3 repeats
    python benches/compare_heyoka.py --threads        # also 1 vs 2 threads on 1e4
"""

# ruff: noqa: E741
from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

import manakov

try:
    import heyoka as hy
except ImportError as exc:  # pragma: no cover - optional bench dependency
    raise SystemExit("heyoka is not installed: pip install 'manakov[bench]'") from exc

EPS = float(np.finfo(float).eps)
SEED = 20261123
DT_LADDER = (0.343, 0.3, 0.25, 0.2)
TOL_LADDER = (EPS, 1e-15, 1e-14)
# manakov's Taylor method: its order is ceil(-ln tol / 2 + 1) (20, 19, 18, 17, 16).
TAYLOR_LADDER = (EPS, 1e-15, 1e-14, 3e-14, 1e-13)
BATCH = 4  # heyoka SIMD batch size: 4 doubles per AVX2 register
CPU_TIME = False


def median_time(fn, repeats: int):
    """Median wall time, or process CPU time with --cpu-time (steadier on a shared
    machine, where other jobs take turns on the cores; one thread only)."""
    times, out = [], None
    clock = time.process_time if CPU_TIME else time.perf_counter
    for _ in range(repeats):
        t0 = clock()
        out = fn()
        times.append(clock() - t0)
    return statistics.median(times), out


def heyoka_system(c: np.ndarray, fp=float):
    """Frahm's field (1) for so(4), the expressions of rust/so4 (vector_field4_lanes)."""
    x = hy.make_vars("l12", "l13", "l14", "l23", "l24", "l34")
    l12, l13, l14, l23, l24, l34 = x

    def d(i, j, k, m):
        return fp(c[i, j]) - fp(c[k, m]) if fp is not float else float(c[i, j] - c[k, m])

    rhs = [
        -(l13 * l23 * d(1, 2, 0, 2) + l14 * l24 * d(1, 3, 0, 3)),
        l12 * l23 * d(1, 2, 0, 1) - l14 * l34 * d(2, 3, 0, 3),
        l12 * l24 * d(1, 3, 0, 1) + l13 * l34 * d(2, 3, 0, 2),
        -(l12 * l13 * d(0, 2, 0, 1) + l24 * l34 * d(2, 3, 1, 3)),
        l23 * l34 * d(2, 3, 1, 2) - l12 * l14 * d(0, 3, 0, 1),
        -(l13 * l14 * d(0, 3, 0, 2) + l23 * l24 * d(1, 3, 1, 2)),
    ]
    return list(zip(x, rhs))


def reference(sys_ld, l0s: np.ndarray, t_end: float) -> np.ndarray:
    ld = np.longdouble
    ta = hy.taylor_adaptive(
        sys_ld, [ld(0)] * 6, tol=np.finfo(ld).eps, fp_type=ld, compact_mode=True
    )
    out = np.empty(l0s.shape)
    for i, y in enumerate(l0s):
        ta.state[:] = [ld(float(v)) for v in y]
        ta.time = ld(0)
        ta.propagate_until(ld(t_end))
        out[i] = ta.state.astype(float)
    return out


def rel_err(got: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(got[: ref.shape[0]] - ref)) / np.max(np.abs(ref)))


def heyoka_compile(sys, batch: bool, tol: float) -> tuple[float, object]:
    hy.llvm_state.clear_memcache()
    t0 = time.perf_counter()
    if batch:
        ta = hy.taylor_adaptive_batch(sys, np.zeros((6, BATCH)), tol=tol)
    else:
        ta = hy.taylor_adaptive(sys, [0.0] * 6, tol=tol)
    return time.perf_counter() - t0, ta


def heyoka_batch_run(ta, l0s: np.ndarray, t_end: float) -> np.ndarray:
    n = l0s.shape[0]
    pad = (-n) % BATCH
    y = np.vstack([l0s, np.repeat(l0s[-1:], pad, axis=0)]) if pad else l0s
    out = np.empty_like(y)
    zeros = np.zeros(BATCH)
    for k in range(0, y.shape[0], BATCH):
        ta.state[:] = y[k : k + BATCH].T
        ta.set_time(zeros)
        ta.propagate_until(t_end)
        out[k : k + BATCH] = ta.state.T
    return out[:n]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="sizes 100, 1000; 3 repeats")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--ref-states", type=int, default=100)
    ap.add_argument("--threads", action="store_true", help="1 vs 2 threads on 1e4 states")
    ap.add_argument("--no-single", action="store_true")
    ap.add_argument("--cpu-time", action="store_true", help="time one-thread runs in CPU time")
    ap.add_argument("--sizes", default=None, help="comma-separated batch sizes")
    args = ap.parse_args()
    global CPU_TIME
    CPU_TIME = args.cpu_time
    repeats = 3 if args.quick else args.repeats
    sizes = (100, 1000) if args.quick else (100, 1000, 10_000)
    if args.sizes:
        sizes = tuple(int(x) for x in args.sizes.split(","))
    hy.llvm_state.set_diskcache_enabled(False)

    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    sys = heyoka_system(top.c)
    sys_ld = heyoka_system(top.c, np.longdouble)
    print(f"machine: {os.cpu_count()} cpus; heyoka {hy.__version__}; manakov {manakov.__version__}")
    print(f"manakov default gauss16 step on 'generic': {top.default_dt(p.l0):.4f}")

    if not args.no_single:
        t_end = 1e4
        ref = reference(sys_ld, p.l0[None, :], t_end)
        print(f"\nsingle trajectory, 'generic' to t = {t_end:g}")
        print(f"{'solver':34s} {'time [s]':>9s} {'error':>9s}")
        rows_m = []
        for label, kw in manakov_settings():
            tm, tr = median_time(
                lambda kw=kw: top.integrate(p.l0, t_end, t_eval=[t_end], **kw), repeats
            )
            e = rel_err(tr.l[-1:], ref)
            rows_m.append((tm, e, label))
            print(f"{'manakov ' + label:34s} {tm:9.4f} {e:9.1e}")
        rows_h = []
        for tol in TOL_LADDER:
            tc, ta = heyoka_compile(sys, False, tol)

            def run(ta=ta):
                ta.state[:] = p.l0
                ta.time = 0.0
                ta.propagate_until(t_end)
                return ta.state.copy()

            th, y = median_time(run, repeats)
            e = rel_err(y[None, :], ref)
            rows_h.append((th, e, tol, tc))
            print(f"{f'heyoka tol={tol:.1e}':34s} {th:9.4f} {e:9.1e}   compile {tc:.3f} s")
        report(rows_m, rows_h, "single")

    for n in sizes:
        rng = np.random.default_rng(SEED + n)
        d = rng.standard_normal((n, 6))
        l0s = d / np.linalg.norm(d, axis=1)[:, None] * np.linalg.norm(p.l0)
        t_end = 100.0
        ref = reference(sys_ld, l0s[: args.ref_states], t_end)
        print(f"\nbatch of {n} random states to t = {t_end:g}, one thread")
        print(f"{'solver':34s} {'time [s]':>9s} {'error':>9s}")
        rows_m = []
        for label, kw in manakov_settings():
            tm, (_, ls) = median_time(
                lambda kw=kw, l0s=l0s, t_end=t_end: top.integrate_many(
                    l0s, t_end, t_eval=[t_end], parallel=False, **kw
                ),
                repeats,
            )
            e = rel_err(ls[:, -1], ref)
            rows_m.append((tm, e, label))
            print(f"{'manakov ' + label:34s} {tm:9.4f} {e:9.1e}")
        rows_h = []
        for tol in TOL_LADDER:
            tc, ta = heyoka_compile(sys, True, tol)
            th, y = median_time(
                lambda ta=ta, l0s=l0s, t_end=t_end: heyoka_batch_run(ta, l0s, t_end), repeats
            )
            e = rel_err(y, ref)
            rows_h.append((th, e, tol, tc))
            print(f"{f'heyoka batch tol={tol:.1e}':34s} {th:9.4f} {e:9.1e}   compile {tc:.3f} s")
        report(rows_m, rows_h, f"batch {n}")

    if args.threads:
        CPU_TIME = False  # wall time: CPU time would add up the threads
        n = 10_000
        rng = np.random.default_rng(SEED + n)
        d = rng.standard_normal((n, 6))
        l0s = d / np.linalg.norm(d, axis=1)[:, None] * np.linalg.norm(p.l0)
        print()
        for method in ("gauss16", "taylor"):
            t1, _ = median_time(
                lambda m=method: top.integrate_many(
                    l0s, 100.0, t_eval=[100.0], method=m, parallel=False
                ),
                repeats,
            )
            t2, _ = median_time(
                lambda m=method: top.integrate_many(
                    l0s, 100.0, t_eval=[100.0], method=m, parallel=True
                ),
                repeats,
            )
            print(
                f"1e4 states to t = 100, {method} (default step/tolerance): 1 thread "
                f"{t1:.3f} s, rayon pool ({os.cpu_count()} cpus) {t2:.3f} s, "
                f"speed-up {t1 / t2:.2f}x"
            )


def manakov_settings():
    """(label, keyword arguments) of the manakov runs: gauss16 at each step of
    DT_LADDER, Taylor's method at each tolerance of TAYLOR_LADDER."""
    out = [(f"gauss16 dt={dt}", {"method": "gauss16", "dt": dt}) for dt in DT_LADDER]
    out += [(f"taylor tol={tol:.1e}", {"method": "taylor", "rtol": tol}) for tol in TAYLOR_LADDER]
    return out


def report(rows_m, rows_h, what: str) -> None:
    """Ratio at equal or better accuracy: heyoka at tol = eps against the fastest
    manakov run, any method, whose error is not larger."""
    th, eh, tol, tc = rows_h[0]
    ok = [r for r in rows_m if r[1] <= eh]
    if not ok:
        print(f"  {what}: no manakov run as accurate as heyoka at tol = eps ({eh:.1e})")
        return
    tm, em, label = min(ok)
    print(
        f"  {what}: fastest manakov run at least as accurate as heyoka tol=eps: "
        f"{label} (error {em:.1e}, {tm:.4f} s) vs heyoka (error {eh:.1e}, {th:.4f} s): "
        f"{th / tm:.2f}x faster excluding heyoka's compile time, "
        f"{(th + tc) / tm:.2f}x including it"
    )


if __name__ == "__main__":
    main()
