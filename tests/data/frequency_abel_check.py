# ruff: noqa: E741  (l is the paper's name for the state)
"""Frequencies vouched for by the Abel map of integrated states, against a long-double
trajectory.

Where the theta quotients' own velocity check leaves a defect above 1e-10 (next to
pinched curves), ``frequency_map`` and ``sol.frequencies`` give the frequencies only if
the Abel images of integrated states (phases of one to four periods of the fastest
lattice coordinate in quarter periods, integrated at the default step and at half of it;
three of the thirteen phases in each run) lie on ``u0 + U t`` to 5e-11 of the phase
advanced (and those of the second flow on ``u0 + U' t`` to 1e-8: ``U'`` only fixes the
real plane); so does it where the quotients' second flow at ``v0`` disagrees with the
closed form, and where ``U`` is the quotients' least-squares fit at ``v0`` rather than
the closed form (next to a pinched curve the fit is undetermined along a direction the
quotients hardly see, whatever their velocity check says). This script takes every state
of the harsh draw of ``every_state_harsh.py`` (seed 20261125) whose frequency-map status
is ``ok`` and whose solution passed its self-check with a velocity check above 1e-10, or
has branch points spread over more than 1e14 (there the map takes the solution's route:
the theta quotients or the Abel images vouch for ``U``), or whose solution failed its
self-check (it is kept for its ``l(t)``, which an integration certifies at every call;
its frequencies are the map's: the level set's closed form up to a spread of 1e14,
beyond it only where the Abel images vouch for ``U`` and ``U'``, whatever the theta
quotients' constants), integrates it with heyoka in 80-bit long double over 20 periods
(201 samples), takes the Abel image of every sample (``sol.abel``; samples whose image
misses the lattice by more than 1e-8 are set aside: points next to branch points), and
fits the slope of the unwrapped images: the true velocity in lattice coordinates. ``U``
is the rate the frequencies are the coordinates of (``U T = ν1 λ1 + ν2 λ2`` on
``sol.torus``). Reported per state: ``max|U - U_fit|`` relative to the largest lattice
rate; then median and maximum for the three groups. The long-double trajectory is not a
reference beyond its own accuracy: on these states (components spanning up to twelve
orders of magnitude) its rounding is amplified as double's is
(``every_state_harsh.py``), and its error over 20 periods enters the slope; where the
comparison exceeds 1e-10, or the long-double trajectory leaves too few images that fit,
it is repeated with heyoka in quadruple precision (``real128``, tolerance 1e-32), and
that figure counts; where that leaves more than 5e-11 (half the bound) or too few
images, the images' own scatter may be what is left, which enters the slope divided by
the span: the fit is repeated in quadruple precision over 100 periods (1001 samples),
and that figure counts.

A fourth group: states whose torus is refused (a pinched curve next to an so(3) block)
and whose frequencies are interpolated between the block's Euler orbit and states farther
out (docs/degenerate.md §11). With no torus there is no ``U`` of the frequencies; instead
each lattice coordinate of the images' slope must be a half-integer combination of the
frequencies (``near_block_error``), with the same escalation to quadruple precision.

Run: ``python tests/data/frequency_abel_check.py [N]`` (N draws, default 10000;
about fifteen minutes on two cores). Output committed as ``tests/data/frequency_abel_check.txt``.
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
SAMPLES_PER_PERIOD = 10  # 201 samples over 20 periods
ABEL_MISS = 1e-8  # a sample's image this far from the lattice point is set aside
MIN_FRACTION = 0.5  # at least half the samples must give images that fit
# Where the 20-period fits leave more than LONG_FROM (half the frequencies' bound of
# 1e-10), or too few images, the fit is repeated in quadruple precision over
# LONG_PERIODS: the images' scatter enters the slope divided by the span.
LONG_FROM = 5e-11
LONG_PERIODS = 100.0


def lattice(tau, z):
    y = np.linalg.solve(tau.imag, z.imag)
    return z.real - tau.real @ y, y


def spread(sol):
    """``max|d| / min|d_i - d_j|`` of the branch points: beyond 1e14 the frequency
    map takes the solution's route, where the theta quotients check U and U'."""
    d = np.asarray(sol._core.branch_points)
    sep = min(abs(d[i] - d[j]) for i in range(len(d)) for j in range(i + 1, len(d)))
    return float(np.max(np.abs(d)) / sep) if sep > 0 else np.inf


def torus_rate(sol):
    """``U`` as the frequencies give it: ``U T = ν1 λ1 + ν2 λ2`` on the torus's reduced
    basis (``sol.torus``), in the normalized time. It is ``sol.U`` where that is the
    closed form; where the solution failed its self-check (``sol.U`` raises) it is the
    rate the frequencies are the coordinates of."""
    t = sol.torus
    nu, lam = t.frequencies, np.asarray(t.lambdas)
    return (nu[0] * lam[0] + nu[1] * lam[1]) / sol.time_scale


def abel_offsets(top, sol, l0, u, fp, periods):
    """The Abel images of a trajectory of ``l0`` by heyoka in ``fp`` over ``periods``
    of the fastest lattice coordinate of ``u`` (``SAMPLES_PER_PERIOD`` samples each),
    as offsets from ``u0 + u t`` in lattice coordinates reduced modulo 1: ``(x, y)``
    of ``u``, the largest lattice rate, the number of samples, and the normalized
    times and offsets of the images the Abel map gives."""
    x, y = lattice(sol.tau, u)
    rate = max(np.max(np.abs(x)), np.max(np.abs(y)))
    samples = int(SAMPLES_PER_PERIOD * periods) + 1
    t_user = np.linspace(0.0, periods / rate / sol.time_scale, samples)
    ref = np.asarray(propagate(top.a, top.b, l0, t_user, fp), dtype=float)
    u0 = sol.abel(np.asarray(l0, dtype=float))
    times, offsets = [], []
    for t, l in zip(t_user * sol.time_scale, ref):
        try:
            w = sol.abel(l)
        except (ValueError, manakov.ClosedFormError):
            continue
        dx, dy = lattice(sol.tau, w - u0 - u * t)
        times.append(t)
        offsets.append(np.concatenate([dx - np.round(dx), dy - np.round(dy)]))
    return (x, y), rate, samples, np.array(times), np.array(offsets)


def fitted_error(top, sol, l0, fp=LD, periods: float = PERIODS):
    """max|U - U_fit| / (largest lattice rate), ``U`` of :func:`torus_rate`, and the
    samples used (None if too few); the trajectory by heyoka in ``fp`` (long double, or
    ``heyoka.real128``). The images are taken relative to that of ``l0``, and a sample
    is set aside where its image is off the others' median by ``ABEL_MISS``."""
    u = torus_rate(sol)
    _, rate, samples, times, offsets = abel_offsets(top, sol, l0, u, fp, periods)
    if len(times) == 0:
        return None, 0
    # Images are set aside by their distance from the median offset, not from that of
    # l0: an image of l0 off by a constant shifts the whole line, not its slope.
    centre = np.median(offsets, axis=0)
    near = np.max(np.abs(offsets - centre), axis=1) < ABEL_MISS
    keep, miss = list(times[near]), list(offsets[near])
    if len(keep) < MIN_FRACTION * (samples - 1):
        return None, len(keep)
    tt = np.array(keep)
    design = np.vstack([np.ones_like(tt), tt]).T
    coef, *_ = np.linalg.lstsq(design, np.array(miss), rcond=None)
    return float(np.max(np.abs(coef[1])) / rate), len(keep)


def near_block_error(top, sol, l0, fp=LD, periods: float = PERIODS):
    """For a state whose torus is refused and whose frequencies are interpolated next
    to an so(3) block: each lattice coordinate of the velocity (the slope of the Abel
    images, per unit of the user's time) must be a combination ``(p ν1 + q ν2)/2`` with
    integers ``|p|, |q| <= 8``; the largest miss relative to the largest coordinate,
    and the samples used (None if too few, or no ``U`` to unwrap the images with). The
    images are unwrapped along ``sol.U`` (off by up to ~1e-9 here, which the fitted
    slope absorbs); the line is fitted robustly (images farther than
    ``max(ABEL_MISS, 3 x median)`` from the last fit set aside, six rounds)."""
    try:
        u = np.asarray(sol.U)
    except manakov.ClosedFormError:
        return None, 0
    nu = np.asarray(sol.frequencies)
    (x, y), _, samples, tt, off = abel_offsets(top, sol, l0, u, fp, periods)
    if len(tt) == 0:
        return None, 0
    design = np.vstack([np.ones_like(tt), tt]).T
    keep = np.ones(len(tt), bool)
    for _ in range(6):
        coef, *_ = np.linalg.lstsq(design[keep], off[keep], rcond=None)
        miss = np.max(np.abs(off - design @ coef), axis=1)
        keep = miss < max(ABEL_MISS, 3.0 * float(np.median(miss)))
    if np.sum(keep) < MIN_FRACTION * (samples - 1):
        return None, int(np.sum(keep))
    coef, *_ = np.linalg.lstsq(design[keep], off[keep], rcond=None)
    slope = (np.concatenate([x, y]) + coef[1]) * sol.time_scale
    k = np.arange(-8, 9)
    combos = (k[:, None] * nu[0] + k[None, :] * nu[1]).ravel() / 2.0
    worst = max(float(np.min(np.abs(c - combos))) for c in slope)
    return worst / float(np.max(np.abs(slope))), int(np.sum(keep))


def torus_refused(sol) -> bool:
    """Whether ``sol.torus`` refuses (the frequencies then come from the interpolation
    next to an so(3) block)."""
    try:
        _ = sol.torus
    except manakov.ClosedFormError:
        return True
    return False


def main(n: int = 10_000) -> None:
    rng = np.random.default_rng(SEED)
    t0 = time.time()
    print(
        f"machine: {platform.machine()} {os.cpu_count()} cpus; manakov {manakov.__version__}; "
        f"harsh draw, seed {SEED}, {n} states"
    )
    errs, errs_spread, errs_failed, errs_near, skipped, checked = [], [], [], [], 0, 0
    for i in range(n):
        a, b, l0 = draw(rng)
        top = manakov.ManakovTop(a, b)
        fm = manakov.frequency_map(top, l0[None, :])
        if manakov.tori.STATUS_NAMES[int(fm.status[0])] != "ok":
            continue
        sol = top.solve(l0)
        if sol.kind != "genus2":
            continue
        near = torus_refused(sol)
        failed = not sol.self_check_passed
        if not near and not failed and sol.velocity_check <= 1e-10 and spread(sol) <= 1e14:
            continue
        checked += 1
        mark = " (self-check failed)" if failed else ""
        fit = fitted_error
        if near:
            mark += " (torus refused: interpolated next to a block)"
            fit = near_block_error
        e, used = fit(top, sol, l0)
        e_ld, quad = e, ""
        if e is None or e > 1e-10:
            # the long-double trajectory may be the one that is off (too far off for
            # its images to fit, or off by more than the bound): quadruple precision
            eq, used_q = fit(top, sol, l0, hy.real128)
            if eq is None:
                quad = f"; in quadruple precision only {used_q} Abel images"
            else:
                quad = f"; in quadruple precision {eq:.1e} ({used_q} samples)"
                e = eq
        if e is None or e > LONG_FROM:
            el, used_l = fit(top, sol, l0, hy.real128, LONG_PERIODS)
            if el is None:
                quad += f"; over {LONG_PERIODS:.0f} periods only {used_l} Abel images"
            else:
                quad += f"; over {LONG_PERIODS:.0f} periods {el:.1e} ({used_l} samples)"
                e = el
        if e is None:
            skipped += 1
            print(
                f"draw {i:5d}: velocity check {sol.velocity_check:.1e}, spread "
                f"{spread(sol):.0e}{mark}; only {used} Abel images in long double{quad}"
            )
            continue
        ld = "too few images" if e_ld is None else f"{e_ld:.1e} ({used} samples)"
        if near:
            errs_near.append(e)
        elif failed:
            errs_failed.append(e)
        else:
            (errs if sol.velocity_check > 1e-10 else errs_spread).append(e)
        print(
            f"draw {i:5d}: velocity check {sol.velocity_check:.1e}, spread {spread(sol):.0e}"
            f"{mark}; "
            f"U against the long-double Abel fit {ld}{quad}",
            flush=True,
        )
    print(
        f"\n{checked} states ok with a velocity check above 1e-10, branch points spread over "
        "more than 1e14, a failed self-check, or a refused torus;"
    )
    took = time.time() - t0
    print(f"{skipped} with too few Abel images to fit ({took:.0f} s)")
    for what, v in (
        ("velocity check above 1e-10 (the Abel-map check vouched for U)", errs),
        (
            "velocity check at most 1e-10, spread above 1e14 (the closed form, or the Abel "
            "images where U is the thetas' fit, vouched for U)",
            errs_spread,
        ),
        (
            "solution failed its self-check (its l(t) certified by integration; U the "
            "level set's closed form, or vouched for by the Abel images)",
            errs_failed,
        ),
        (
            "torus refused, frequencies interpolated next to an so(3) block (each lattice "
            "rate of the Abel images' slope against the nearest combination (p nu1 + "
            "q nu2)/2, relative to the largest)",
            errs_near,
        ),
    ):
        e = np.array(v)
        if len(e) == 0:
            print(f"  {what}: none")
            continue
        print(
            f"  {what}: fitted {len(e)}, U error median {np.median(e):.1e}, "
            f"max {np.max(e):.1e}, above 1e-10: {int(np.sum(e > 1e-10))}"
        )


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:2]))
