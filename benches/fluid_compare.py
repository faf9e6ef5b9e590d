"""Kirchhoff's equations: manakov's integrators against scipy's DOP853 and heyoka, in one process.

Set-ups (the reference bodies of ``manakov.fluid_problem``):

* ``clebsch_generic`` (integrable) from its ``M0, p0`` to t = 1e3, end point only;
* ``general`` (no symmetry, chaotic) from its ``M0, p0`` to t = 100, end point only
  (rounding is amplified ~1e4 over this horizon, the same for every solver);
* a batch of 1000 random states of ``clebsch_generic`` (standard normal ``M0, p0``
  scaled to the norm of its ``(M0, p0)``) to t = 100, one thread.

Accuracy: the error of a run is ``max |y − ref| / max |ref|`` at the end time,
against heyoka's Taylor integrator in 80-bit long double (tolerance
``eps_ld ~ 1e-19``) on the same double coefficients (for the batch, its first
--ref-states states). Every solver runs a ladder of settings: manakov gauss16 at
several steps (its default ``DT_SCALE/Ω`` and smaller) and dop853 at several
tolerances, scipy DOP853 (numpy right-hand side, rtol = atol) at several
tolerances, heyoka at tol = eps and looser. "Equal accuracy": for each target
error, the fastest run of each solver whose error is at most the target, and the
ratio of its time to manakov's. heyoka's compile time (LLVM; caches cleared, disk
cache off) is reported separately. Times are medians of --repeats runs (scipy:
--scipy-repeats).

    python benches/fluid_compare.py            # everything (~2 min)
    python benches/fluid_compare.py --quick    # 1 repeat, no batch
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

import manakov
from manakov.fluid import DT_SCALE

try:
    import heyoka as hy
except ImportError as exc:  # pragma: no cover - optional bench dependency
    raise SystemExit("heyoka is not installed: pip install 'manakov[bench]'") from exc

EPS = float(np.finfo(float).eps)
SEED = 20261203
BATCH = 4  # heyoka SIMD batch size (4 doubles per AVX2 register)
DT_FACTORS = (1.0, 0.75, 0.5, 0.35)  # gauss16 steps, times the default
RTOLS = (1e-10, 1e-11, 1e-12, 1e-13)  # dop853 (manakov and scipy)
HEYOKA_TOLS = (EPS, 1e-15, 1e-14, 1e-13, 1e-12, 1e-10)
TARGETS = (1e-9, 1e-11, 1e-12, 1e-13)


def median_time(fn, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def heyoka_system(body: manakov.KirchhoffBody, fp=float):
    """Kirchhoff's equations with the body's coefficients (zeros left out)."""
    x = hy.make_vars("M1", "M2", "M3", "p1", "p2", "p3")
    M, p = x[:3], x[3:]
    A, B, C = body.A, body.B, body.C

    def lin(row_m, row_p):
        terms = [fp(float(c)) * v for c, v in zip(row_m, M) if c != 0]
        terms += [fp(float(c)) * v for c, v in zip(row_p, p) if c != 0]
        return hy.sum(terms) if terms else hy.expression(fp(0.0))

    w = [lin(A[i], B[i]) for i in range(3)]
    v = [lin(B[:, i], C[i]) for i in range(3)]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    mw, pv, pw = cross(M, w), cross(p, v), cross(p, w)
    rhs = [mw[i] + pv[i] for i in range(3)] + pw
    return list(zip(x, rhs))


def reference(body, y0s: np.ndarray, t_end: float) -> np.ndarray:
    ld = np.longdouble
    ta = hy.taylor_adaptive(
        heyoka_system(body, ld), [ld(0)] * 6, tol=np.finfo(ld).eps, fp_type=ld, compact_mode=True
    )
    out = np.empty(y0s.shape)
    for i, y in enumerate(y0s):
        ta.state[:] = [ld(float(v)) for v in y]
        ta.time = ld(0)
        ta.propagate_until(ld(t_end))
        out[i] = ta.state.astype(float)
    return out


def rel_err(got: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(got[: ref.shape[0]] - ref)) / np.max(np.abs(ref)))


def field_numpy(body):
    A, B, C = body.A, body.B, body.C

    def f(_, y):
        M, p = y[:3], y[3:]
        w = A @ M + B @ p
        v = B.T @ M + C @ p
        return np.concatenate([np.cross(M, w) + np.cross(p, v), np.cross(p, w)])

    return f


def heyoka_compile(sys, batch: bool, tol: float):
    hy.llvm_state.clear_memcache()
    t0 = time.perf_counter()
    if batch:
        ta = hy.taylor_adaptive_batch(sys, np.zeros((6, BATCH)), tol=tol)
    else:
        ta = hy.taylor_adaptive(sys, [0.0] * 6, tol=tol)
    return time.perf_counter() - t0, ta


def heyoka_batch_run(ta, y0s: np.ndarray, t_end: float) -> np.ndarray:
    n = y0s.shape[0]
    pad = (-n) % BATCH
    y = np.vstack([y0s, np.repeat(y0s[-1:], pad, axis=0)]) if pad else y0s
    out = np.empty_like(y)
    zeros = np.zeros(BATCH)
    for k in range(0, y.shape[0], BATCH):
        ta.state[:] = y[k : k + BATCH].T
        ta.set_time(zeros)
        ta.propagate_until(t_end)
        out[k : k + BATCH] = ta.state.T
    return out[:n]


def line(label: str, t: float, e: float, extra: str = "") -> None:
    print(f"{label:42s} {t * 1e3:10.2f} {e:9.1e} {extra}")


def report(rows: list[tuple[str, str, float, float]]) -> None:
    """rows: (solver, setting, time, error). Per target, the fastest run of each solver."""
    solvers = ["manakov gauss16", "manakov dop853", "scipy DOP853", "heyoka"]
    print(f"\n  {'target':>8s}  " + "  ".join(f"{s:>24s}" for s in solvers))
    for target in TARGETS:
        best = {}
        for s in solvers:
            ok = [(t, e, lab) for (sv, lab, t, e) in rows if sv == s and e <= target]
            best[s] = min(ok) if ok else None
        ref = best["manakov gauss16"]
        cells = []
        for s in solvers:
            b = best[s]
            if b is None:
                cells.append(f"{'—':>24s}")
                continue
            ratio = f" ({b[0] / ref[0]:.1f}x)" if ref is not None else ""
            cells.append(f"{b[0] * 1e3:13.2f} ms{ratio:>8s}")
        print(f"  {target:8.0e}  " + "  ".join(cells))
    print("  (fastest run with error <= target; in parentheses: time / manakov gauss16)")


def single(name: str, t_end: float, repeats: int, scipy_repeats: int) -> None:
    pr = manakov.fluid_problem(name)
    body = pr.body
    y0 = np.r_[pr.M0, pr.p0]
    ref = reference(body, y0[None, :], t_end)
    sys = heyoka_system(body)
    dt0 = body.default_dt(pr.M0, pr.p0)
    print(f"\n{name} ({body.case}), one trajectory to t = {t_end:g}; default dt {dt0:.4f}")
    print(f"{'solver':42s} {'time [ms]':>10s} {'error':>9s} {'steps':>9s}")
    rows = []
    for f in DT_FACTORS:
        tm, tr = median_time(
            lambda f=f: body.integrate(pr.M0, pr.p0, t_end, t_eval=[t_end], dt=f * dt0), repeats
        )
        e = rel_err(np.hstack([tr.M, tr.p])[-1:], ref)
        rows.append(("manakov gauss16", f"dt={f:g}x default", tm, e))
        line(f"manakov gauss16 dt = {f:g} x default", tm, e, f"{tr.steps:9d}")
    for rt in RTOLS:
        tm, tr = median_time(
            lambda rt=rt: body.integrate(
                pr.M0, pr.p0, t_end, t_eval=[t_end], method="dop853", rtol=rt, atol=rt
            ),
            repeats,
        )
        e = rel_err(np.hstack([tr.M, tr.p])[-1:], ref)
        rows.append(("manakov dop853", f"rtol={rt:.0e}", tm, e))
        line(f"manakov dop853 rtol = atol = {rt:.0e}", tm, e, f"{tr.steps:9d}")
    f = field_numpy(body)
    for rt in RTOLS:
        tm, sol = median_time(
            lambda rt=rt: solve_ivp(
                f, (0.0, t_end), y0, method="DOP853", rtol=rt, atol=rt, t_eval=[t_end]
            ),
            scipy_repeats,
        )
        e = rel_err(sol.y.T, ref)
        rows.append(("scipy DOP853", f"rtol={rt:.0e}", tm, e))
        line(f"scipy DOP853 rtol = atol = {rt:.0e}", tm, e, f"{sol.nfev:9d} evals")
    for tol in HEYOKA_TOLS:
        tc, ta = heyoka_compile(sys, False, tol)

        def run(ta=ta):
            ta.state[:] = y0
            ta.time = 0.0
            ta.propagate_until(t_end)
            return ta.state.copy()

        th, y = median_time(run, repeats)
        e = rel_err(y[None, :], ref)
        rows.append(("heyoka", f"tol={tol:.1e}", th, e))
        line(f"heyoka tol = {tol:.1e}", th, e, f"  compile {tc:.2f} s")
    report(rows)


def batch(n: int, t_end: float, repeats: int, ref_states: int) -> None:
    pr = manakov.fluid_problem("clebsch_generic")
    body = pr.body
    rng = np.random.default_rng(SEED)
    d = rng.standard_normal((n, 6))
    y0s = d / np.linalg.norm(d, axis=1)[:, None] * np.linalg.norm(np.r_[pr.M0, pr.p0])
    ref = reference(body, y0s[:ref_states], t_end)
    sys = heyoka_system(body)
    big = int(np.argmax(np.linalg.norm(y0s, axis=1)))
    dt0 = body.default_dt(y0s[big, :3], y0s[big, 3:])
    print(f"\nbatch of {n} random states of clebsch_generic to t = {t_end:g}, one thread")
    print(f"{'solver':42s} {'time [ms]':>10s} {'error':>9s}")
    rows = []
    for f in DT_FACTORS:
        tm, (_, Ms, ps) = median_time(
            lambda f=f: body.integrate_many(
                y0s[:, :3], y0s[:, 3:], t_end, t_eval=[t_end], dt=f * dt0, parallel=False
            ),
            repeats,
        )
        e = rel_err(np.hstack([Ms[:, -1], ps[:, -1]]), ref)
        rows.append(("manakov gauss16", f"dt={f:g}x", tm, e))
        line(f"manakov gauss16 dt = {f:g} x default", tm, e)
    for tol in HEYOKA_TOLS:
        tc, ta = heyoka_compile(sys, True, tol)
        th, y = median_time(lambda ta=ta: heyoka_batch_run(ta, y0s, t_end), repeats)
        e = rel_err(y, ref)
        rows.append(("heyoka", f"tol={tol:.1e}", th, e))
        line(f"heyoka batch tol = {tol:.1e}", th, e, f"  compile {tc:.2f} s")
    report(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1 repeat, no batch")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--scipy-repeats", type=int, default=1)
    ap.add_argument("--ref-states", type=int, default=50)
    args = ap.parse_args()
    repeats = 1 if args.quick else args.repeats
    hy.llvm_state.set_diskcache_enabled(False)
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus; "
        f"heyoka {hy.__version__}; manakov {manakov.__version__}; gauss16 DT_SCALE "
        f"{DT_SCALE['gauss16']}"
    )
    single("clebsch_generic", 1e3, repeats, args.scipy_repeats)
    single("general", 100.0, repeats, args.scipy_repeats)
    if not args.quick:
        batch(1000, 100.0, repeats, args.ref_states)


if __name__ == "__main__":
    main()
