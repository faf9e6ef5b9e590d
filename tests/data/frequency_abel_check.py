# ruff: noqa: E741  (l is the paper's name for the state)
"""Frequencies vouched for by the Abel map of integrated states, against a long-double
trajectory.

Where the theta quotients' own velocity check leaves a defect above 1e-10 (next to
pinched curves), ``frequency_map`` and ``sol.frequencies`` give the frequencies only
if the Abel images of integrated states (phases of one to four periods of the
fastest lattice coordinate, integrated at the default step and at half of it; three
of the seven phases in each run) lie on ``u0 + U t`` to 1e-10 of the phase
advanced, for ``U`` and for the second flow's ``U'``; so does it where the
quotients' second flow at ``v0`` disagrees with the closed form, and where ``U`` is
the quotients' least-squares fit at ``v0`` rather than the closed form (next to a
pinched curve the fit is undetermined along a direction the quotients hardly see,
whatever their velocity check says). This script takes
every state of the harsh draw of ``every_state_harsh.py`` (seed 20261125) whose
frequency-map status is ``ok`` and whose solution passed its self-check with a
velocity check above 1e-10, or has branch points spread over more than 1e14 (there
the map takes the solution's route: the theta quotients or the Abel images vouch for
``U``), integrates it with heyoka in 80-bit long double over 20 periods (201
samples), takes the Abel image of every sample (``sol.abel``; samples whose image
misses the lattice by more than 1e-8 are set aside: points next to branch points),
and fits the slope of the unwrapped images: the true velocity in lattice
coordinates. Reported per state: ``max|U - U_fit|`` relative to the largest lattice
rate; then median and maximum for the two groups. The long-double trajectory is not
a reference beyond its own accuracy: on these states (components spanning up to
twelve orders of magnitude) its rounding is amplified as double's is
(``every_state_harsh.py``), and its error over 20 periods enters the slope; where
the comparison exceeds 1e-10 it is repeated with heyoka in quadruple precision
(``real128``, tolerance 1e-32), and that figure counts.

Run: ``python tests/data/frequency_abel_check.py [N]`` (N draws, default 10000;
about three minutes). Output committed as ``tests/data/frequency_abel_check.txt``.
"""

from __future__ import annotations

import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).resolve().parent))
from closed_u_long_double import LD, hy, propagate  # noqa: E402
from every_state_harsh import draw  # noqa: E402

SEED = 20261125
PERIODS = 20.0
SAMPLES = 201
ABEL_MISS = 1e-8  # a sample's image this far from the lattice point is set aside
MIN_SAMPLES = 100


def lattice(tau, z):
    y = np.linalg.solve(tau.imag, z.imag)
    return z.real - tau.real @ y, y


def spread(sol):
    """``max|d| / min|d_i - d_j|`` of the branch points: beyond 1e14 the frequency
    map takes the solution's route, where the theta quotients check U and U'."""
    d = np.asarray(sol._core.branch_points)
    sep = min(abs(d[i] - d[j]) for i in range(len(d)) for j in range(i + 1, len(d)))
    return float(np.max(np.abs(d)) / sep) if sep > 0 else np.inf


def fitted_error(top, sol, l0, fp=LD):
    """max|U - U_fit| / (largest lattice rate), and the samples used (None if too few);
    the trajectory by heyoka in ``fp`` (long double, or ``heyoka.real128``)."""
    x, y = lattice(sol.tau, sol.U)
    rate = max(np.max(np.abs(x)), np.max(np.abs(y)))
    t_user = np.linspace(0.0, PERIODS / rate / sol.time_scale, SAMPLES)
    ref = np.asarray(propagate(top.a, top.b, l0, t_user, fp), dtype=float)
    keep, miss = [], []
    for t, l in zip(t_user * sol.time_scale, ref):
        try:
            w = sol.abel(l)
        except (ValueError, manakov.ClosedFormError):
            continue
        dx, dy = lattice(sol.tau, w - sol.u0 - sol.U * t)
        r = np.concatenate([dx - np.round(dx), dy - np.round(dy)])
        if np.max(np.abs(r)) < ABEL_MISS:
            keep.append(t)
            miss.append(r)
    if len(keep) < MIN_SAMPLES:
        return None, len(keep)
    tt = np.array(keep)
    design = np.vstack([np.ones_like(tt), tt]).T
    coef, *_ = np.linalg.lstsq(design, np.array(miss), rcond=None)
    return float(np.max(np.abs(coef[1])) / rate), len(keep)


def main(n: int = 10_000) -> None:
    rng = np.random.default_rng(SEED)
    t0 = time.time()
    print(
        f"machine: {platform.machine()} {os.cpu_count()} cpus; manakov {manakov.__version__}; "
        f"harsh draw, seed {SEED}, {n} states"
    )
    errs, errs_spread, skipped, checked = [], [], 0, 0
    for i in range(n):
        a, b, l0 = draw(rng)
        top = manakov.ManakovTop(a, b)
        fm = manakov.frequency_map(top, l0[None, :])
        if manakov.tori.STATUS_NAMES[int(fm.status[0])] != "ok":
            continue
        sol = top.solve(l0)
        if sol.kind != "genus2" or not sol.self_check_passed:
            continue
        if sol.velocity_check <= 1e-10 and spread(sol) <= 1e14:
            continue
        checked += 1
        e, used = fitted_error(top, sol, l0)
        if e is None:
            skipped += 1
            print(
                f"draw {i:5d}: velocity check {sol.velocity_check:.1e}, spread "
                f"{spread(sol):.0e}; only {used} Abel images"
            )
            continue
        e_ld, quad = e, ""
        if e > 1e-10:
            # the long-double trajectory may be the one that is off: quadruple precision
            eq, used_q = fitted_error(top, sol, l0, hy.real128)
            if eq is None:
                quad = f"; in quadruple precision only {used_q} Abel images"
            else:
                quad = f"; in quadruple precision {eq:.1e} ({used_q} samples)"
                e = eq
        (errs if sol.velocity_check > 1e-10 else errs_spread).append(e)
        print(
            f"draw {i:5d}: velocity check {sol.velocity_check:.1e}, spread {spread(sol):.0e}; "
            f"U against the long-double Abel fit {e_ld:.1e} ({used} samples){quad}",
            flush=True,
        )
    print(f"\n{checked} states ok with a velocity check above 1e-10 or branch points spread")
    took = time.time() - t0
    print(f"over more than 1e14; {skipped} with too few Abel images to fit ({took:.0f} s)")
    for what, v in (
        ("velocity check above 1e-10 (the Abel-map check vouched for U)", errs),
        (
            "velocity check at most 1e-10, spread above 1e14 (the closed form, or the Abel "
            "images where U is the thetas' fit, vouched for U)",
            errs_spread,
        ),
    ):
        e = np.array(v)
        print(
            f"  {what}: fitted {len(e)}, U error median {np.median(e):.1e}, "
            f"max {np.max(e):.1e}, above 1e-10: {int(np.sum(e > 1e-10))}"
        )


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:2]))
