# ruff: noqa: E741  (l is the paper's name for the state)
"""Where the double evaluation of the Theorem loses its last digits: the constants.

For the shared tops 'physical' and 'wide', the quotients (9)-(10) as the package
builds them (``sol.quotient()``: theta indices, weights of N_q and D; ``sol.tau``,
``v0 = sol.u0 + sol.riemann_constant``, ``sol.U``) are evaluated in long double
(numpy's ``clongdouble``, a theta series of 21 x 21 terms) on 101 times in
[0, 100] and compared with heyoka's long-double trajectory (``longdouble_ref.py``).
Their error is then fitted, by least squares, by first-order changes of the
constants: tau (6 real parameters), v0 (4), U (4), a complex factor on each
weight column (14), the Jacobian by differences in long double. Printed: the
largest error before; after the fit with every constant; without tau; without U;
and at t = 0 the difference between this long-double evaluation and the
package's double one (the rounding of the evaluation itself).

Run: ``python tests/data/constant_error_fit.py`` (about 15 s). Output committed as
``tests/data/constant_error_fit.txt``; quoted in docs/theorem.md ("Precise
evaluation").
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path

import numpy as np

import manakov
from manakov.theta import characteristics

sys.path.insert(0, str(Path(__file__).resolve().parent))
from longdouble_ref import reference  # noqa: E402

LD, CLD = np.longdouble, np.clongdouble
PI = LD("3.14159265358979323846264338327950288")
N = 10
CH = characteristics(2)
N1, N2 = (x.ravel().astype(LD) for x in np.meshgrid(np.arange(-N, N + 1), np.arange(-N, N + 1)))
STEP = LD("1e-9")


def theta_ld(i, z, tau):
    (a1, a2), (b1, b2) = CH[i]
    p1, p2 = N1 + LD(a1) / 2, N2 + LD(a2) / 2
    q = tau[0, 0] * p1 * p1 + 2 * tau[0, 1] * p1 * p2 + tau[1, 1] * p2 * p2
    w = p1 * (z[0] + LD(b1) / 2) + p2 * (z[1] + LD(b2) / 2)
    return np.sum(np.exp(1j * PI * q + 2j * PI * w))


def fit_top(name: str) -> None:
    p = manakov.problem(name)
    a, b, l0 = (np.asarray(x, float) for x in (p.a, p.b, p.l0))
    sol = manakov.ManakovTop(a, b).solve(l0)
    idx, num, den = sol.quotient()
    tau0 = sol.tau.astype(CLD)
    v00 = (sol.u0 + sol.riemann_constant).astype(CLD)
    u0 = sol.U.astype(CLD)
    nw, dw = num.astype(CLD), den.astype(CLD)

    def model(t, dp):
        dp = [LD(x) for x in dp]
        v = [v00[i] + dp[2 * i] + 1j * dp[2 * i + 1] for i in range(2)]
        v = [v[i] + (u0[i] + dp[4 + 2 * i] + 1j * dp[5 + 2 * i]) * t for i in range(2)]
        tau = tau0.copy()
        tau[0, 0] += dp[22] + 1j * dp[23]
        tau[0, 1] += dp[24] + 1j * dp[25]
        tau[1, 0] = tau[0, 1]
        tau[1, 1] += dp[26] + 1j * dp[27]
        th = np.array([theta_ld(int(i), v, tau) for i in idx])
        f = np.array([CLD(1)] + [1 + dp[6 + 2 * m] + 1j * dp[7 + 2 * m] for m in range(1, 8)])
        th = th * f
        d = np.sum(dw * th)
        return np.array([(np.sum(nw[q] * th) / d).real for q in range(6)])

    ts = np.linspace(0, 100, 101)
    ref = reference(a, b, l0, ts)
    n0 = np.linalg.norm(l0)
    npar = 28
    rows, err = [], []
    for k, t in enumerate(ts):
        base = model(LD(t), [0] * npar)
        err.extend(((base - ref[k]) / n0).astype(float))
        cols = []
        for j in range(npar):
            dp = [0] * npar
            dp[j] = STEP
            cols.append(((model(LD(t), dp) - base) / STEP / n0).astype(float))
        rows.extend(np.array(cols).T)
    jac, e = np.array(rows), np.array(err)

    def after(sel):
        x, *_ = np.linalg.lstsq(jac[:, sel], e, rcond=1e-10)
        return float(np.max(np.abs(e - jac[:, sel] @ x)))

    every = list(range(npar))
    no_tau = [j for j in every if j < 22]
    no_u = [j for j in every if not 4 <= j < 8]
    at0 = float(np.max(np.abs(model(LD(0), [0] * npar) - sol.l(0.0).astype(LD))) / n0)
    print(
        f"{name:9s} before {np.max(np.abs(e)):.1e}; fitted: every constant "
        f"{after(every):.1e}, without tau {after(no_tau):.1e}, without U {after(no_u):.1e}; "
        f"long double - double evaluation at t = 0: {at0:.1e}"
    )


def main() -> None:
    print(
        f"machine: {platform.machine()} {os.cpu_count()} cpus; manakov {manakov.__version__}; "
        "largest |l - l_ref| / |l0| over 101 times in [0, 100]"
    )
    for name in ["physical", "wide"]:
        fit_top(name)


if __name__ == "__main__":
    main()
