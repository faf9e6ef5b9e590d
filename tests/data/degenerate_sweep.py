# ruff: noqa: E741  (l is the paper's name for the state)
"""The exactly degenerate states on the four shared tops, against references.

For each top: random directions on every exactly degenerate set (the four so(3)
blocks, the self-dual and anti-self-dual subspaces, the six single components
and the three coordinate planes, the equilibrium subspaces V± where the doubles
have them, block states 1e-6 off their separatrix) solved by ``top.solve``;
``max |l − l_ref| / |l0|`` on [0, 100] against heyoka's Taylor integrator in
long double (``longdouble_ref.py``, the ``c_ij`` from ``a, b`` in long double),
beside gauss16 (dt = 1e-3) and the long-double flow of the doubles' ``c_ij`` (what
the rounding of the data alone does) against the same reference, and ``solve``
against that flow of the doubles (the data it solves); the accuracy bound is
``max(1e-10, 10 × max(gauss16's error, the rounding's))``.
Then: block states on their separatrix to rounding (1 − m ~ 1e-17) against a
40-digit mpmath integration of the Euler top (long double loses ~1e-4 there);
the scaling law ``l(t; s l0) = s l(s t; l0)`` at s = 1e-150, 1e150; ``a``
shifted by ±1e6, 1e9; ``b = α a + β``; the Euler frequencies of self-dual states
against the genus-2 frequencies of their neighbours; the cost of the
transverse monodromy.

Run: ``python tests/data/degenerate_sweep.py`` (about a minute; needs heyoka and
mpmath). Output: ``tests/data/degenerate_sweep.txt``.
"""

from __future__ import annotations

import math
import os
import platform
import sys
import time

import mpmath
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

from longdouble_ref import reference  # noqa: E402
from test_degenerate import (  # noqa: E402
    BLOCKS,
    NAMES,
    POS,
    _euler_field,
    _near_separatrix,
    _nu_perp_classes,
    _second_difference,
    block_state,
    c_pairs,
    self_dual_state,
)

import manakov  # noqa: E402

SEED = 20261201
PER_SET = 5


def _sets(top: manakov.ManakovTop, rng: np.random.Generator) -> dict[str, list[np.ndarray]]:
    out: dict[str, list[np.ndarray]] = {}
    for blk in BLOCKS:
        out[f"block {''.join(str(i + 1) for i in blk)}"] = [
            block_state(blk, rng.normal(size=3)) for _ in range(PER_SET)
        ]
    out["self-dual"] = [self_dual_state(rng.normal(size=3), 1) for _ in range(PER_SET)]
    out["anti-self-dual"] = [self_dual_state(rng.normal(size=3), -1) for _ in range(PER_SET)]
    comps = []
    for q in range(6):
        l = np.zeros(6)
        l[q] = rng.normal()
        comps.append(l)
    out["single components"] = comps
    planes = []
    for qa, qb in ((0, 5), (1, 4), (2, 3)):
        for _ in range(2):
            l = np.zeros(6)
            l[qa], l[qb] = rng.normal(size=2)
            planes.append(l)
    out["coordinate planes"] = planes
    a = np.asarray(top.a)
    bb = [_second_difference(a, top.c, t) for t in ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))]
    if bb[0] * bb[1] * bb[2] * bb[3] > 0 and min(np.diff(np.sort(a))) > 1e-3:
        vs = []
        for sign in (1, -1):
            r = sign * math.sqrt(bb[1] * bb[2] / (bb[0] * bb[3]))
            for _ in range(2):
                xi, eta, zeta = rng.normal(size=3)
                vs.append(
                    np.array(
                        [xi * bb[1], eta * bb[2], zeta, zeta * r, -eta * bb[3] * r, xi * bb[3] * r]
                    )
                )
        out["V± (3-dim equilibria)"] = vs
    out["blocks 1e-6 off the separatrix"] = [_near_separatrix(top, blk, 1e-6) for blk in BLOCKS]
    return out


def main() -> None:
    lines: list[str] = []

    def say(s: str = "") -> None:
        print(s)
        lines.append(s)

    say(f"# tests/data/degenerate_sweep.py, seed {SEED}; {platform.machine()}, {platform.node()}")
    say(f"# manakov {manakov.__version__}, numpy {np.__version__}")
    rng = np.random.default_rng(SEED)
    t = np.linspace(0.0, 100.0, 201)
    worst_ratio = 0.0
    failures = 0
    say("\n## 1. Exactly degenerate states, [0, 100], against long double")
    say(
        "top | set | states | kinds | max err solve | max err gauss16 | "
        "max effect of rounding c | max err solve against the doubles' flow | all within bound"
    )
    for name in NAMES:
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        for what, states in _sets(top, rng).items():
            es, eg, ec, esd, kinds, ok = 0.0, 0.0, 0.0, 0.0, set(), True
            for l0 in states:
                sol = top.solve(l0)
                kinds.add(sol.kind)
                ref = np.asarray(reference(top.a, top.b, l0, t), dtype=float)
                ref_c = np.asarray(reference(top.a, top.b, l0, t, c=c_pairs(top)), dtype=float)
                scale = np.linalg.norm(l0)
                e_s = float(np.max(np.abs(sol.l(t) - ref))) / scale
                g16 = top.integrate(l0, 100.0, t_eval=t, dt=1e-3).l
                e_g = float(np.max(np.abs(g16 - ref))) / scale
                e_c = float(np.max(np.abs(ref_c - ref))) / scale
                e_sd = float(np.max(np.abs(sol.l(t) - ref_c))) / scale
                es, eg, ec, esd = max(es, e_s), max(eg, e_g), max(ec, e_c), max(esd, e_sd)
                bound = max(1e-10, 10 * max(e_g, e_c))
                worst_ratio = max(worst_ratio, e_s / bound)
                if e_s > bound:
                    ok = False
                    failures += 1
            say(
                f"{name} | {what} | {len(states)} | {','.join(sorted(kinds))} | "
                f"{es:.1e} | {eg:.1e} | {ec:.1e} | {esd:.1e} | {'yes' if ok else 'NO'}"
            )
    say(f"worst err/bound: {worst_ratio:.2e}; states over the bound: {failures}")

    say("\n## 2. Block states on the separatrix to rounding (1 - m ~ 1e-17), [0, 20]")
    say("top | block | 1 - m | max |M - M_mpmath| (closed form) | long double | gauss16")
    mpmath.mp.dps = 40
    for name in NAMES:
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        for blk in BLOCKS:
            l0 = _near_separatrix(top, blk, 0.0)
            sol = top.solve(l0)
            e = sol.euler
            f = _euler_field([mpmath.mpf(float(x)) for x in e.W])
            ref = mpmath.odefun(
                f, 0, [mpmath.mpf(float(x)) for x in e.M0], tol=mpmath.mpf(10) ** -30
            )
            ts = np.array([0.0, 5.0, 10.0, 15.0, 20.0])
            # the same data as the mpmath integration: the doubles' c_ij
            ld = np.asarray(reference(top.a, top.b, l0, ts, c=c_pairs(top)), dtype=float)
            g16 = top.integrate(l0, 20.0, t_eval=ts, dt=1e-3).l
            i, j, k = blk

            def m_of(l: np.ndarray, i: int = i, j: int = j, k: int = k) -> np.ndarray:
                return np.array([l[POS[(j, k)]], -l[POS[(i, k)]], l[POS[(i, j)]]])

            ec = el = eg = 0.0
            for n, tt in enumerate(ts):
                mr = np.array([float(x) for x in ref(tt)])
                ec = max(ec, float(np.max(np.abs(m_of(sol.l(tt)) - mr))))
                el = max(el, float(np.max(np.abs(m_of(ld[n]) - mr))))
                eg = max(eg, float(np.max(np.abs(m_of(g16[n]) - mr))))
            say(f"{name} | {blk} | {e.m1:.1e} | {ec:.1e} | {el:.1e} | {eg:.1e}")

    say("\n## 3. Scaling law l(t; s l0) = s l(s t; l0), t in [0, 10]")
    say("top | s | kind | max |l(t/s; s l0) - s l(t; l0)| / (s |l0|) | frequencies ratio - s")
    for name in NAMES:
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        tt = np.linspace(0.0, 10.0, 21)
        states = [
            np.asarray(p.l0, float),
            block_state((0, 2, 3), np.array([0.3, 0.9, -0.4])),
            self_dual_state(np.array([0.5, -0.2, 0.7]), -1),
            np.array([0.0, 0.0, 0.8, 0.0, 0.0, 0.0]),
        ]
        for s in (1e-150, 1e150):
            for l0 in states:
                base = top.solve(l0)
                scaled = top.solve(s * l0)
                err = np.max(np.abs(scaled.l(tt / s) - s * base.l(tt))) / (s * np.linalg.norm(l0))
                fb = base.frequencies
                fr = (
                    np.max(np.abs(scaled.frequencies / fb / s - 1.0))
                    if np.all(fb > 0)
                    else float("nan")
                )
                say(f"{name} | {s:.0e} | {base.kind} | {err:.1e} | {fr:.1e}")

    say("\n## 4. a shifted: the top of the shifted doubles against gauss16 (dt 1e-3), [0, 20]")
    say("top | shift | kind | frame kappa | max err / |l0|")
    for name in NAMES:
        p = manakov.problem(name)
        for shift in (1e6, -1e6, 1e9):
            top = manakov.ManakovTop(np.asarray(p.a) + shift, p.b)
            sol = top.solve(p.l0)
            tt = np.linspace(0.0, 20.0, 41)
            g16 = top.integrate(p.l0, 20.0, t_eval=tt, dt=1e-3).l
            err = np.max(np.abs(sol.l(tt) - g16)) / np.linalg.norm(p.l0)
            say(f"{name} | {shift:g} | {sol.kind} | {sol.frame['kappa']:.6g} | {err:.1e}")

    say("\n## 5. b = alpha a + beta: the spherical top")
    for name in NAMES:
        p = manakov.problem(name)
        for alpha, beta in ((0.7, 0.2), (-3.0, 1e3), (1e-4, -2.0)):
            top = manakov.ManakovTop(p.a, alpha * np.asarray(p.a) + beta)
            l0 = rng.normal(size=6)
            sol = top.solve(l0)
            spread = float(np.ptp(c_pairs(top)))
            say(
                f"{name} | alpha {alpha:g}, beta {beta:g} | {sol.kind} | spread of the "
                f"doubles' c_ij {spread:.1e} | map status "
                f"{manakov.tori.STATUS_NAMES[int(manakov.frequency_map(top, l0).status)]}"
            )

    say("\n## 6. Self-dual Euler frequencies (nu_perp, nu_E) and the frequency map at distance eps")
    say("top | sign | (nu_perp, nu_E) | eps: max(|nu2 - nu_E|, dist(nu1, ±nu_perp + Z nu_E))/nu_E")
    for name in ("generic", "physical", "wide"):
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        for sign in (1, -1):
            m = rng.normal(size=3)
            sol = top.solve(self_dual_state(m, sign))
            t0 = time.perf_counter()
            nu_perp, nu_e = sol.frequencies
            dt_ms = 1e3 * (time.perf_counter() - t0)
            dq = rng.normal(size=3)
            dq /= np.linalg.norm(dq)
            cols = []
            for eps in (1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-12):
                mm = m + eps * dq / 2
                nn = sign * (m - eps * dq / 2)
                l = np.array([mm[2], -mm[1], nn[0], mm[0], nn[1], nn[2]])
                fm = manakov.frequency_map(top, l)
                if int(fm.status) != manakov.tori.OK:
                    cols.append(f"{eps:g}: {manakov.tori.STATUS_NAMES[int(fm.status)]}")
                    continue
                nu1, nu2 = fm.nu
                dev = max(abs(nu2 - nu_e), _nu_perp_classes(nu1, nu_perp, nu_e)) / nu_e
                cols.append(f"{eps:g}: {dev:.1e}")
            say(
                f"{name} | {sign:+d} | ({nu_perp:.10f}, {nu_e:.10f}) in {dt_ms:.1f} ms | "
                + "; ".join(cols)
            )

    with open(os.path.join(HERE, "degenerate_sweep.txt"), "w") as fh:
        fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
