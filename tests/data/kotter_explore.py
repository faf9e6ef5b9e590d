# ruff: noqa: E741, B007, E501  (l is the paper's name for the state)
"""Exploration: check the Schottky-Koetter formulas (12)-(42) as printed, numerically.

Pure numpy/scipy, independent of the package. Run: python tests/data/kotter_explore.py
It prints, for each formula, the residual as printed and, where it fails, the
residual of the corrected form pinned down here (see docs/errata.md).
"""

import sys
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from kotter_ref import (  # noqa: E402  (the shared independent reference)
    CYC,
    integrals,
    skew3,
)
from kotter_ref import F_coeffs as Fcoef  # noqa: E402
from kotter_ref import frahm_rhs as rhs  # noqa: E402
from kotter_ref import l_of_s as lvec  # noqa: E402
from kotter_ref import m_of_s as mvec  # noqa: E402
from kotter_ref import s_pair as sq  # noqa: E402


def main():
    a = np.array([0.3, 1.1, 2.0, 3.7])
    b = np.array([0.5, -0.2, 1.4, 0.9])
    l0 = np.array([0.8, -0.3, 0.5, 1.1, -0.7, 0.2])
    f = rhs(a, b)
    sol = solve_ivp(f, (0, 5), l0, method="DOP853", rtol=1e-13, atol=1e-13, dense_output=True)
    ts = np.linspace(0, 5, 11)
    traj = sol.sol(ts).T
    print("== (7) conservation along the flow")
    for pr in (True, False):
        H = np.array([integrals(a, x, printed=pr) for x in traj])
        print(" printed" if pr else " complementary", np.ptp(H, axis=0))
    hc = integrals(a, l0)
    hp = integrals(a, l0, printed=True)
    print("== (15) closed form at random s")
    rng = np.random.default_rng(1)
    for s in rng.normal(size=3) + 1j * rng.normal(size=3):
        sqG = np.prod(
            [
                np.sqrt(complex(sq(s, a, j, 3))) * np.sqrt(complex(sq(s, a, k, ll)))
                for j, k, ll in CYC[:1]
            ]
        )
        # consistent branch: sqrt(s_kl) := sqG/sqrt(s_j4) for all j
        lv = lvec(s, a, l0, sqG)
        fs = lv @ lv
        for name, h in (("corrected", hc), ("printed", hp)):
            h0, h1, h2, h3 = h
            print(f"  {name}: |f - (15)| =", abs(fs - (h1 * s * s - h2 * s + h3 + 2 * h0 * sqG)))
        # time independence
        fl = [lvec(s, a, x, sqG) @ lvec(s, a, x, sqG) for x in traj]
        print("  f(s) ptp along flow:", np.ptp(np.abs(fl)))
    print("== (16) Lax pair sign")
    s = 0.7 + 0.4j
    sqG = np.sqrt(complex(sq(s, a, 0, 3))) * np.sqrt(complex(sq(s, a, 1, 2)))
    for x in traj[:3]:
        dl = f(0, x)
        Ld = skew3(lvec(s, a, dl, sqG))
        L = skew3(lvec(s, a, x, sqG))
        M = skew3(mvec(s, a, x, sqG))
        print(
            "  |Ldot-[L,M]|",
            np.abs(Ld - (L @ M - M @ L)).max(),
            " |Ldot-[M,L]|",
            np.abs(Ld - (M @ L - L @ M)).max(),
        )
    # scale of M: m(s) vs s-dependent factor
    print("== (19) F(s) and roots")
    Fc = Fcoef(a, hc)
    roots = np.roots(Fc)
    print("  roots", roots)
    h0, h1, h2, h3 = hc
    for sp in roots:
        Pp = h1 * sp * sp - h2 * sp + h3
        sg = -Pp / (2 * h0)
        G = np.prod(sp - a)
        print(
            "  sigma^2 - G =",
            abs(sg * sg - G),
            " f on branch sigma:",
            abs(lvec(sp, a, l0, sg) @ lvec(sp, a, l0, sg)),
            " principal sqrt(G) == sigma?",
            np.isclose(np.sqrt(G), sg),
        )
    return a, b, l0, traj, hc, roots


if __name__ == "__main__":
    main()
