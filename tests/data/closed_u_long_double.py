# ruff: noqa: E741  (l is the paper's name for the state)
"""U in closed form and the Theorem's l(t) against a long-double trajectory.

For the four shared tops and N random states (seeded; every third one stiff: one
spacing of a in [1e-2, 5e-2], all c_ij up to 1e3), heyoka's Taylor integrator in
80-bit long double (``fp_type=np.longdouble``, tolerance eps_ld ~ 1.1e-19; the twelve
coefficients c_kj - c_ik of (1) computed exactly from the double a, b and rounded
once) gives l(t) on a grid of S times in [0, T]. Then:

1. **U against the Abel fit.** ``sol.abel(l(t_k))``, unwrapped modulo the lattice
   (the nearest lattice vector to ``abel - u0 - U t``; the lattice shifts, up to
   ~1e5 periods, and ``U t`` formed in long double), fitted by least squares in t:
   the slope is ``X + tau Y`` of the true lattice rates (the Abel map normalises
   with the package's own periods, so a period error would show here as well).
   Reported: ``max|U - U_fit| / max|U_fit|``, its median and maximum.
2. **The Theorem against gauss16.** ``|l(t) - l_ref(t)| / |l0|`` (max norm, against
   the long-double values themselves) at t = 100 and t = T for ``sol.l`` (``th``),
   ``sol.l(t, precise=True)`` (``pr``) and ``top.integrate`` with gauss16 at
   ``dt = top.default_dt(l0)/4`` (``g16``); with ``--f128``, also against heyoka in
   quad precision (``real128``, tolerance 1e-32) at t = 100, which shows the
   long-double reference's own error.

Run: ``python tests/data/closed_u_long_double.py [--n 100] [--seed 2211] [--f128]
[--cache DIR]``
(about an hour for 100 states on one core: the stiff states take 1-3 min of long
double each; with ``--f128`` another 20 minutes). Output committed as
``tests/data/closed_u_long_double.txt``.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import platform
import time
from fractions import Fraction

import numpy as np

import manakov

try:
    import heyoka as hy
except ImportError as exc:  # pragma: no cover - bench dependency
    raise SystemExit("heyoka is not installed: pip install 'manakov[bench]'") from exc

LD = np.longdouble
PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]


def system():
    """(1) with the twelve coefficients c_kj - c_ik as parameters."""
    x = hy.make_vars("l12", "l13", "l14", "l23", "l24", "l34")
    L = {}
    for q, (i, j) in enumerate(PAIRS):
        L[(i, j)], L[(j, i)] = x[q], -x[q]
    rhs, npar = [], 0
    for i, j in PAIRS:
        terms = []
        for k in range(4):
            if k in (i, j):
                continue
            terms.append(L[(i, k)] * L[(k, j)] * hy.par[npar])
            npar += 1
        rhs.append(hy.sum(terms))
    return list(zip(x, rhs))


def coefficients(a, b, conv):
    """c_kj - c_ik exactly (fractions) from the doubles a, b, as hi + lo in ``conv``."""
    A = [Fraction(float(v)) for v in a]
    B = [Fraction(float(v)) for v in b]

    def c(i, j):
        return (B[i] - B[j]) / (A[i] - A[j])

    out = []
    for i, j in PAIRS:
        for k in range(4):
            if k in (i, j):
                continue
            v = c(k, j) - c(i, k)
            hi = float(v)
            out.append(conv(hi) + conv(float(v - Fraction(hi))))
    return out


_TA: dict = {}


def propagate(a, b, l0, ts, fp):
    """l(ts) by heyoka in ``fp`` (np.longdouble or heyoka.real128)."""
    key = "ld" if fp is LD else "f128"
    if key not in _TA:
        tol = np.finfo(LD).eps if fp is LD else hy.real128("1e-32")
        _TA[key] = hy.taylor_adaptive(
            system(), [fp(0)] * 6, tol=tol, fp_type=fp, compact_mode=True, pars=[fp(0)] * 12
        )
    ta = _TA[key]
    ta.pars[:] = coefficients(a, b, fp)
    ta.state[:] = [fp(float(v)) for v in l0]
    ta.time = fp(0)
    grid = np.array([fp(float(t)) for t in ts]) if fp is not LD else np.asarray(ts, LD)
    out = ta.propagate_grid(grid)[-1]
    if fp is LD:
        return np.asarray(out, LD)
    # quad values to long double (not to double: the comparisons are below an ulp)
    return np.array([[LD(str(v)) for v in row] for row in out])


def cached(cache, key, compute, *arrays):
    """``compute()``, kept in ``cache`` (a directory) under ``key`` and a hash of the
    exact bytes of ``arrays`` when a cache is given: the same computation, only not
    repeated when the Theorem side of this script is re-run."""
    if not cache:
        return compute()
    h = hashlib.sha256()
    for v in arrays:
        h.update(np.ascontiguousarray(v, float).tobytes())
    path = os.path.join(cache, h.hexdigest()[:32] + key + ".npy")
    if os.path.exists(path):
        return np.load(path)
    out = compute()
    os.makedirs(cache, exist_ok=True)
    # written whole, then renamed: another run sharing the cache never reads half a file
    tmp = f"{path}.{os.getpid()}.tmp.npy"
    np.save(tmp, out)
    os.replace(tmp, path)
    return out


def propagate_cached(a, b, l0, ts, cache):
    """``propagate`` in long double, through :func:`cached`."""
    return cached(cache, "", lambda: propagate(a, b, l0, ts, LD), a, b, l0, ts)


def random_states(n, seed):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        stiff = len(out) % 3 == 0
        sp = 10 ** rng.uniform(-1.0, 0.3, 3)
        if stiff:
            sp[rng.integers(3)] = 10 ** rng.uniform(-2.0, np.log10(0.05))
        a = np.cumsum(np.concatenate([[rng.uniform(-1, 1)], sp]))
        b = rng.normal(size=4) * 10 ** rng.uniform(-0.5, 1.0)
        c = [(b[i] - b[j]) / (a[i] - a[j]) for i, j in PAIRS]
        if max(abs(x) for x in c) > 1e3:
            continue
        l0 = rng.normal(size=6)
        try:
            manakov.ManakovTop(a, b).solve(l0)
        except (ValueError, manakov.ClosedFormError):
            continue
        out.append((a, b, l0))
    return out


def lattice(tau, z):
    y = np.linalg.solve(tau.imag, z.imag)
    return z.real - tau.real @ y, y


def abel_fit(sol, ts, ls):
    """(U_fit, largest distance of an unwrapped sample from its lattice point)."""
    u = np.array([sol.abel(l) for l in ls])
    x, y = lattice(sol.tau, (u - sol.u0[None, :] - ts[:, None] * sol.U[None, :]).T)
    nx, ny = np.round(x), np.round(y)
    resid = max(np.max(np.abs(x - nx)), np.max(np.abs(y - ny)))
    tau = sol.tau.astype(np.clongdouble)
    shift = nx.T.astype(np.clongdouble) + ny.T.astype(np.clongdouble) @ tau.T
    pred = (
        sol.u0.astype(np.clongdouble)[None, :]
        + ts.astype(LD)[:, None] * sol.U.astype(np.clongdouble)[None, :]
    )
    delta = (u.astype(np.clongdouble) - shift - pred).astype(complex)
    design = np.vstack([np.ones_like(ts), ts]).T
    coef, *_ = np.linalg.lstsq(design, delta, rcond=None)
    return sol.U + coef[1], resid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=2211)
    ap.add_argument("--t-end", type=float, default=1e4)
    ap.add_argument("--samples", type=int, default=4001)
    ap.add_argument("--f128", action="store_true", help="also quad precision at t = 100")
    ap.add_argument(
        "--cache",
        default="",
        help="directory keeping the long-double trajectories and the gauss16 results "
        "(clear it when the integrators change)",
    )
    args = ap.parse_args()
    print(
        f"machine: {platform.machine()} {os.cpu_count()} cpus; heyoka {hy.__version__}; "
        f"manakov {manakov.__version__}; seed {args.seed}; T = {args.t_end:g}, "
        f"{args.samples} samples"
    )
    states = [
        (np.asarray(p.a, float), np.asarray(p.b, float), np.asarray(p.l0, float))
        for p in (manakov.problem(n) for n in manakov.problem_names())
    ] + random_states(args.n, args.seed)
    names = list(manakov.problem_names()) + [f"random {i}" for i in range(args.n)]
    ts = np.linspace(0.0, args.t_end, args.samples)
    i100 = int(np.argmin(np.abs(ts - 100.0)))
    assert ts[i100] == 100.0, "the grid must contain t = 100"
    print(
        f"{'state':16s} {'min da':>7s} {'max|c|':>7s} {'|U|':>7s} {'U err':>8s} "
        f"{'th 100':>8s} {'g16 100':>8s} {'th T':>8s} {'g16 T':>8s} {'pr 100':>8s} {'pr T':>8s}"
        + (
            f" {'th/f128':>8s} {'ld/f128':>8s} {'g16/f128':>8s} {'pr/f128':>8s}"
            if args.f128
            else ""
        )
    )
    rows = []
    for name, (a, b, l0) in zip(names, states):
        top = manakov.ManakovTop(a, b)
        sol = top.solve(l0)
        t0 = time.time()
        ref = propagate_cached(a, b, l0, ts, args.cache)
        t_ld = time.time() - t0
        ls = ref.astype(float)
        u_fit, resid = abel_fit(sol, ts, ls)
        u_err = float(np.max(np.abs(sol.U - u_fit)) / np.max(np.abs(u_fit)))
        tq = np.array([100.0, args.t_end])
        g16 = cached(
            args.cache,
            "_g16",
            lambda top=top, l0=l0, tq=tq: (
                top.integrate(l0, args.t_end, t_eval=tq, dt=top.default_dt(l0) / 4).l
            ),
            a,
            b,
            l0,
            tq,
        )
        th = sol.l(tq)
        pr = sol.l(tq, precise=True)
        n0 = np.linalg.norm(l0)
        # against the long-double values themselves (not rounded to double)
        rq = np.vstack([ref[i100], ref[-1]])

        def err(x, rq=rq, n0=n0):
            return (np.max(np.abs(np.asarray(x, LD) - rq), axis=1) / n0).astype(float)

        e_th, e_g, e_pr = err(th), err(g16), err(pr)
        da = float(np.min(np.diff(a)))
        cmax = float(np.max(np.abs(top.c)))
        line = (
            f"{name:16s} {da:7.1e} {cmax:7.1e} {np.max(np.abs(sol.U)):7.2f} {u_err:8.1e} "
            f"{e_th[0]:8.1e} {e_g[0]:8.1e} {e_th[1]:8.1e} {e_g[1]:8.1e} "
            f"{e_pr[0]:8.1e} {e_pr[1]:8.1e}"
        )
        row = [u_err, e_th[0], e_g[0], e_th[1], e_g[1], resid, t_ld, e_pr[0], e_pr[1]]
        if args.f128:
            q = cached(
                args.cache,
                "_f128",
                lambda a=a, b=b, l0=l0: propagate(a, b, l0, [0.0, 100.0], hy.real128),
                a,
                b,
                l0,
            )[-1]
            e_q = [
                float(np.max(np.abs(np.asarray(v, LD) - q)) / n0)
                for v in (th[0], ref[i100], g16[0])
            ]
            line += f" {e_q[0]:8.1e} {e_q[1]:8.1e} {e_q[2]:8.1e}"
            row += e_q
            e_pq = float(np.max(np.abs(np.asarray(pr[0], LD) - q)) / n0)
            line += f" {e_pq:8.1e}"
            row += [e_pq]
        print(line, flush=True)
        rows.append(row)
    r = np.array(rows)
    print()
    print(f"U against the Abel fit: median {np.median(r[:, 0]):.1e}, max {np.max(r[:, 0]):.1e}")
    print(f"  (largest unwrapping residual {np.max(r[:, 5]):.1e} periods)")
    for col, t in ((1, "100"), (3, f"{args.t_end:g}")):
        worse = np.flatnonzero(r[:, col] > r[:, col + 1])
        print(
            f"t = {t}: Theorem median {np.median(r[:, col]):.1e} max {np.max(r[:, col]):.1e}; "
            f"gauss16 median {np.median(r[:, col + 1]):.1e} max {np.max(r[:, col + 1]):.1e}; "
            f"Theorem > gauss16 on {len(worse)} of {len(r)}"
            + (f": {', '.join(names[i] for i in worse)}" if len(worse) else "")
        )
    for col, t in ((7, "100"), (8, f"{args.t_end:g}")):
        g = 2 if col == 7 else 4
        worse = np.flatnonzero(r[:, col] > r[:, g])
        print(
            f"t = {t}: precise Theorem median {np.median(r[:, col]):.1e} max "
            f"{np.max(r[:, col]):.1e}; > gauss16 on {len(worse)} of {len(r)}"
            + (f": {', '.join(names[i] for i in worse)}" if len(worse) else "")
        )
    if args.f128:
        worse = np.flatnonzero(r[:, 9] > r[:, 11])
        print(
            f"t = 100 against real128: Theorem median {np.median(r[:, 9]):.1e} max "
            f"{np.max(r[:, 9]):.1e}; long double median {np.median(r[:, 10]):.1e} max "
            f"{np.max(r[:, 10]):.1e}; gauss16 median {np.median(r[:, 11]):.1e} max "
            f"{np.max(r[:, 11]):.1e}; precise Theorem median {np.median(r[:, 12]):.1e} "
            f"max {np.max(r[:, 12]):.1e}; Theorem > gauss16 on {len(worse)} of {len(r)}"
            + (f": {', '.join(names[i] for i in worse)}" if len(worse) else "")
        )
        worse = np.flatnonzero(r[:, 12] > r[:, 11])
        print(
            f"t = 100 against real128: precise Theorem > gauss16 on {len(worse)} of {len(r)}"
            + (f": {', '.join(names[i] for i in worse)}" if len(worse) else "")
        )
    print(
        f"long-double integration: {np.sum(r[:, 6]):.0f} s in all"
        + (" (trajectories found in --cache are loaded, not integrated)" if args.cache else "")
    )


if __name__ == "__main__":
    main()
