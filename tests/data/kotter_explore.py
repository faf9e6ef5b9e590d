# ruff: noqa: E741, B007, E501  (l is the paper's name for the state)
"""Exploration: check the Schottky-Koetter formulas (12)-(42) as printed, numerically.

Pure numpy/scipy, independent of the package. Run: python tests/data/kotter_explore.py
It prints, for each formula, the residual as printed and, where it fails, the
residual of the corrected form pinned down here (see docs/errata.md).
"""

import itertools

import numpy as np
from scipy.integrate import solve_ivp

CYC = [(0, 1, 2), (1, 2, 0), (2, 0, 1)]  # (j,k,l) cyclic, 0-based


def full(l):
    m = np.zeros((4, 4))
    m[0, 1], m[0, 2], m[0, 3], m[1, 2], m[1, 3], m[2, 3] = l
    return m - m.T


def cmat(a, b):
    c = np.zeros((4, 4))
    for i in range(4):
        for j in range(4):
            if i != j:
                c[i, j] = (b[i] - b[j]) / (a[i] - a[j])
    return c


def rhs(a, b):
    c = cmat(a, b)

    def f(t, y):
        L = full(y)
        W = c * L
        # (1) literally: ldot_ij = sum_k (l_ik w_kj - w_ik l_kj)
        D = L @ W - W @ L
        return np.array([D[0, 1], D[0, 2], D[0, 3], D[1, 2], D[1, 3], D[2, 3]])

    return f


def mn(l):
    L = full(l)
    m = np.array([L[k, ll] for (j, k, ll) in CYC])
    n = np.array([L[j, 3] for (j, k, ll) in CYC])
    return m, n


def integrals(a, l, printed=False):
    L = full(l)
    h0 = L[0, 1] * L[2, 3] + L[1, 2] * L[0, 3] + L[2, 0] * L[1, 3]
    h1 = h2 = h3 = 0.0
    for j, k in itertools.combinations(range(4), 2):
        lo, mo = [x for x in range(4) if x not in (j, k)]
        h1 += L[j, k] ** 2
        if printed:
            h2 += (a[j] + a[k]) * L[j, k] ** 2
            h3 += a[j] * a[k] * L[j, k] ** 2
        else:
            h2 += (a[lo] + a[mo]) * L[j, k] ** 2
            h3 += a[lo] * a[mo] * L[j, k] ** 2
    return h0, h1, h2, h3


def sq(s, a, j, k):
    return (s - a[j]) * (s - a[k])


def lvec(s, a, l, sqG):
    """l(s) (12) with sqrt(s_j4) principal and sqrt(s_kl) = sqG / sqrt(s_j4)."""
    m, n = mn(l)
    out = []
    for j, k, ll in CYC:
        r = np.sqrt(complex(sq(s, a, j, 3)))
        out.append(r * m[j] + sqG / r * n[j])
    return np.array(out)


def mvec(s, a, l, sqG):
    m, n = mn(l)
    out = []
    for j, k, ll in CYC:
        r = np.sqrt(complex(sq(s, a, j, 3)))
        out.append(sqG / r * m[j] + r * n[j])
    return np.array(out)


def skew3(v):
    return np.array([[0, v[2], -v[1]], [-v[2], 0, v[0]], [v[1], -v[0], 0]])


def Fcoef(a, h):
    h0, h1, h2, h3 = h
    P = np.array([h1, -h2, h3])
    G = np.poly(a)
    num = np.polysub(np.polymul(P, P), 4 * h0**2 * G)
    return num / (h1**2 - 4 * h0**2)


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
