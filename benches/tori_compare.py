"""Frequencies of a real torus: the Theorem vs integration + NAFF, in one process.

For the shared 'generic' top:

* the package: ``manakov.frequency_map`` on a Casimir slice of states (the
  whole chain per state: reduction, curve, periods, Abel map, theta
  quotients, U, the second flow U', the lattice Λ' ∩ P, reduction, ν), on one
  core (RAYON_NUM_THREADS=1, set before the package loads);
* the classical way: integrate (1) with gauss16 over 500 periods of the slower
  frequency, then NAFF (tests/naff.py: Hann² window, FFT, Newton refinement)
  on one component until both generators are resolved; ν from a least-squares
  fit of the matched lines k1 ν1 + k2 ν2.

Prints per-state times (medians), the frequency difference between the two
(which is the NAFF error: the Theorem's ν are exact up to rounding of U), and
the ratio.

Run:  python benches/tori_compare.py            (about a minute)
      python benches/tori_compare.py --quick
"""

from __future__ import annotations

import os
import sys

os.environ["RAYON_NUM_THREADS"] = "1"  # one core (read when the pool starts)

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

import manakov  # noqa: E402
from manakov import tori  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from naff import naff  # noqa: E402


def median_time(fn, repeats):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def integrate_naff(top, l0, nu_ref, periods=500):
    """ν from gauss16 + NAFF of l12; the reference ν only names the lines."""
    nu1, nu2 = nu_ref
    T = periods / min(nu1, nu2)
    dt = 0.2  # resolves the lines of 'generic' above 1e-6 (up to ~2 cycles per unit time)
    tr = top.integrate(l0, T, sample_every=dt, method="gauss16")
    lines, amps = naff(tr.l[:, 0], dt, max_lines=40, rel_threshold=1e-6)
    k = np.arange(-20, 21)
    rows, freqs = [], []
    for f, amp in zip(lines, amps):
        # The fit uses the well-resolved lines (≥ 1e-4 of the largest): weak
        # lines next to strong ones carry the leakage error of the window.
        if f == 0.0 or amp < 1e-4 * amps[0]:
            continue
        comb = k[:, None] * nu1 + k[None, :] * nu2
        i = np.unravel_index(np.argmin(np.abs(comb - f)), comb.shape)
        rows.append([k[i[0]], k[i[1]]])
        freqs.append(f)
    fit = np.linalg.lstsq(np.array(rows, float), np.array(freqs), rcond=None)[0]
    return fit


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    grid = 8 if args.quick else 16
    repeats = 3 if args.quick else 5

    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    _, _, states = tori.casimir_slice(p.l0, grid)
    states = states.reshape(-1, 6)
    tori.frequency_map(top, states[:4])  # warm-up
    t_map = median_time(lambda: tori.frequency_map(top, states), repeats) / len(states)
    fm = tori.frequency_map(top, p.l0)
    nu = fm.nu
    print(f"'generic': nu = ({nu[0]:.15g}, {nu[1]:.15g}), status {tori.STATUS_NAMES[fm.status]}")
    print(
        f"theta frequencies, one core: {1e6 * t_map:8.1f} us per state "
        f"(median of {repeats}, {len(states)} states)"
    )

    t0 = time.perf_counter()
    fit = integrate_naff(top, p.l0, nu)
    t_naff = time.perf_counter() - t0
    err = float(np.max(np.abs(fit - nu)) / np.max(nu))
    print(f"gauss16 + NAFF (500 slow periods):   {1e3 * t_naff:8.1f} ms per state")
    print(f"  NAFF nu = ({fit[0]:.15g}, {fit[1]:.15g}); max |dnu|/nu = {err:.1e}")
    print(f"ratio (integration + NAFF) / theta: {t_naff / t_map:,.0f}x")


if __name__ == "__main__":
    main()
