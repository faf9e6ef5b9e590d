"""How far rounding the coefficients c_ij to double moves a stiff top's trajectory.

The Theorem takes the top's c_ij (normalized) in double; the long-double reference of
``closed_u_long_double.py`` takes them exact from the double a, b. On the first random
(stiff) state of that script (seed 2211: a spacing 2.5e-2, |c| up to 190, |U| ~ 99)
this prints, at t = 0, 10, 100, the distance (max norm over |l0|) between heyoka in
long double with exact c and with c rounded to double (the differences c_kj - c_ik
then formed in long double), and the Theorem against both: the Theorem's remaining
error there is of the size of that rounding, not of U.

Run: ``python tests/data/closed_u_c_rounding.py`` (about a minute). Output committed as
``tests/data/closed_u_c_rounding.txt``.
"""

from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import closed_u_long_double as m  # noqa: E402

import manakov  # noqa: E402


def main() -> None:
    a, b, l0 = m.random_states(1, 2211)[0]
    sol = manakov.ManakovTop(a, b).solve(l0)
    n0 = np.linalg.norm(l0)
    ts = np.array([0.0, 10.0, 100.0], m.LD)
    exact = m.propagate(a, b, l0, ts, m.LD).astype(float)
    c = {}
    for i, j in m.PAIRS:
        c[(i, j)] = c[(j, i)] = float((b[i] - b[j]) / (a[i] - a[j]))
    pars = [
        m.LD(c[(k, j)]) - m.LD(c[(i, k)]) for i, j in m.PAIRS for k in range(4) if k not in (i, j)
    ]
    ta = m._TA["ld"]
    ta.pars[:] = pars
    ta.state[:] = [m.LD(float(v)) for v in l0]
    ta.time = m.LD(0)
    rounded = np.asarray(ta.propagate_grid(ts)[-1]).astype(float)
    th = sol.l(ts.astype(float))

    def dist(x, y):
        return " ".join(f"{v:8.1e}" for v in np.max(np.abs(x - y), axis=1) / n0)

    print(f"t = {' '.join(f'{float(t):8g}' for t in ts)}")
    print(f"c rounded vs exact c : {dist(rounded, exact)}")
    print(f"Theorem vs exact c   : {dist(th, exact)}")
    print(f"Theorem vs rounded c : {dist(th, rounded)}")


if __name__ == "__main__":
    main()
