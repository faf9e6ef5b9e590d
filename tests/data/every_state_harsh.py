"""Every real state: the Theorem (``top.solve``) on a harsh random draw, against
an independent long-double reference.

The draw (seed 20261125 unless given; no test uses it): each component of l0
log-uniform in [1e-6, 1e6] with a random sign; a with log-uniform spacings in
[1e-3, 1e3] from a_1 uniform in [-1, 1]; b likewise, each spacing with a random
sign. Time window [0, T], T = min(100, 1e3 * time_scale), time_scale =
1 / (|l0| (max c_ij - min c_ij)) (the rate of (1) is at most that spread times
|l|^2), 51 equally spaced times.

Reference: heyoka's Taylor integrator in 80-bit long double, tolerance 1e-19
(``longdouble_ref.py``). For each state: the error of gauss16 at its default dt
and of ``top.solve(l0).l(t)``, both max |l - l_ref| / |l0| over the window. A
state is *solved* when the Theorem's error is at most
max(1e-10, 10 x gauss16's error); *silently wrong* when it is not and no
exception was raised. Also the ``frequency_map`` status of each state, and
whether the values came from the closed form or from the confirmed integration
that stands in for it where it cannot be built or is off
(``sol.integrated_calls``, ``IntegratedValuesWarning``).

Where gauss16's error exceeds 1e-10 the long-double reference itself may be
off (its rounding, 2048x smaller than double's, is amplified the same way), and
such a state's bound is loose. There the Theorem's values, where returned, are
also compared with heyoka in quadruple precision (``reference_quad``,
tolerance 1e-32), and that error is reported separately.

Run: python tests/data/every_state_harsh.py [N] [SEED]  (about 0.1 s per state)
Writes a summary to stdout and the per-state records to every_state_harsh.npz
in the current directory.
"""

from __future__ import annotations

import re
import sys
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).resolve().parent))
import longdouble_ref  # noqa: E402

ABS_FLOOR = 1e-10
GAUSS_FACTOR = 10.0
N_TIMES = 51
# Numbers in messages are replaced by '#' so that refusals group by their reason.
NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?([-+](\d+\.?\d*)([eE][-+]?\d+)?j)?")


def draw(rng: np.random.Generator):
    l0 = 10.0 ** rng.uniform(-6, 6, 6) * rng.choice([-1.0, 1.0], 6)
    a = rng.uniform(-1, 1) + np.concatenate([[0.0], np.cumsum(10.0 ** rng.uniform(-3, 3, 3))])
    b = rng.uniform(-1, 1) + np.concatenate(
        [[0.0], np.cumsum(10.0 ** rng.uniform(-3, 3, 3) * rng.choice([-1.0, 1.0], 3))]
    )
    return a, b, l0


def window(top: manakov.ManakovTop, l0: np.ndarray) -> np.ndarray:
    cs = np.asarray(top.c)[np.triu_indices(4, 1)]
    spread = float(np.max(cs) - np.min(cs))
    scale = np.inf if spread == 0 else 1.0 / (np.linalg.norm(l0) * spread)
    return np.linspace(0.0, min(100.0, 1e3 * scale), N_TIMES)


def err(lt, ref, norm):
    return float(np.max(np.abs(np.asarray(lt, dtype=np.longdouble) - ref)) / norm)


def main(n: int = 10_000, seed: int = 20261125) -> None:
    rng = np.random.default_rng(seed)
    rec = {
        k: []
        for k in (
            "err",
            "g16",
            "bound",
            "solved",
            "silent",
            "raised",
            "status",
            "err_quad",
            "integrated",
        )
    }
    reasons: Counter[str] = Counter()
    statuses: Counter[str] = Counter()
    kinds: Counter[str] = Counter()
    t_start = time.time()
    for _ in range(n):
        a, b, l0 = draw(rng)
        top = manakov.ManakovTop(a, b)
        t = window(top, l0)
        norm = float(np.linalg.norm(l0))
        ref = longdouble_ref.reference(a, b, l0, t)
        g16 = err(top.integrate(l0, t[-1], t_eval=t).l, ref, norm)
        bound = max(ABS_FLOOR, GAUSS_FACTOR * g16)
        e, raised, eq, integrated = np.nan, "", np.nan, False
        try:
            sol = top.solve(l0)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", manakov.IntegratedValuesWarning)
                lt = sol.l(t)
            integrated = sol.integrated_calls > 0
            e = err(lt, ref, norm)
            if g16 > ABS_FLOOR:
                eq = err(lt, longdouble_ref.reference_quad(a, b, l0, t), norm)
            kinds[getattr(sol, "kind", "genus2")] += 1
        except Exception as ex:  # noqa: BLE001 - every refusal is recorded with its reason
            raised = f"{type(ex).__name__}: {NUMBER.sub('#', str(ex))[:80]}"
            reasons[raised] += 1
        fm = manakov.frequency_map(top, l0[None, :])
        st = manakov.tori.STATUS_NAMES[int(fm.status[0])]
        statuses[st] += 1
        rec["err"].append(e)
        rec["err_quad"].append(eq)
        rec["integrated"].append(integrated)
        rec["g16"].append(g16)
        rec["bound"].append(bound)
        rec["solved"].append(not raised and e <= bound)
        rec["silent"].append(not raised and not e <= bound)
        rec["raised"].append(raised)
        rec["status"].append(st)
    elapsed = time.time() - t_start
    solved = np.array(rec["solved"])
    silent = np.array(rec["silent"])
    errs = np.array(rec["err"])
    print(f"N = {n}, seed = {seed}, {elapsed:.0f} s")
    print(
        f"solved (error <= max({ABS_FLOOR:g}, {GAUSS_FACTOR:g} x gauss16)): "
        f"{solved.sum()} = {100 * solved.mean():.2f} %"
    )
    by_int = solved & np.array(rec["integrated"])
    print(
        f"  by the closed form: {solved.sum() - by_int.sum()} = "
        f"{100 * (solved.mean() - by_int.mean()):.2f} %; by the confirmed integration "
        f"standing in for it: {by_int.sum()} = {100 * by_int.mean():.2f} %"
    )
    print(f"silently wrong: {silent.sum()}")
    print(f"raised: {sum(reasons.values())}")
    ok = errs[np.isfinite(errs)]
    if ok.size:
        print(
            f"Theorem error where it returned: median {np.median(ok):.1e}, "
            f"99% {np.quantile(ok, 0.99):.1e}, max {ok.max():.1e}"
        )
    g = np.array(rec["g16"])
    print(f"gauss16 error: median {np.median(g):.1e}, max {g.max():.1e}")
    q = np.array(rec["err_quad"])
    q = q[np.isfinite(q)]
    if q.size:
        print(
            f"where gauss16 is off by more than {ABS_FLOOR:g} ({q.size} returned): the Theorem "
            f"against quadruple precision: median {np.median(q):.1e}, max {q.max():.1e}, "
            f"{int(np.sum(q > ABS_FLOOR))} above {ABS_FLOOR:g}"
        )
    print("solution kinds:", dict(kinds))
    for r, k in reasons.most_common():
        print(f"  {k:6d}  {r}")
    print("frequency_map statuses:", dict(statuses))
    for i in np.flatnonzero(silent)[:20]:
        print(f"  silently wrong #{i}: error {errs[i]:.2e} > bound {rec['bound'][i]:.2e}")
    np.savez("every_state_harsh.npz", **{k: np.array(v) for k, v in rec.items()})


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:3]))
