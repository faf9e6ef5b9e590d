# ruff: noqa: E741  (l is the paper's name for the state)
"""The reduction near the singular set h1^2 = 4 h0^2: conditioning and round trips.

Run: ``python tests/data/kotter_singular_conditioning.py [N] [SEED]`` (default
N = 4 states per distance and top, SEED = 5). Quoted in docs/kotter.md, "Near the
singular set".

The distance is delta = (h1^2 - 4 h0^2)/h1^2 = |m - n|^2 |m + n|^2/(|m|^2 + |n|^2)^2,
the relative size of the quantity that vanishes on the singular set; the states are
n = +-m + rho |m| v (m, v random, |v| = 1), for which delta ~ rho^2.

For each state, independently of the package (mpmath, 80 digits, from the formulas
of docs/kotter.md: the quartic (19) by ``mpmath.polyroots``, the corrected
(20)-(26), the closed forms (30)-(31) for the points, (27)-(28) and (37) for the
way back):

* kappa_out: the componentwise relative condition number of the reduction's outputs
  (d_j, z_i, g) in the state, max over the outputs o of sum_i |do/dl_i| |l_i|/|o| (finite
  differences of size 1e-25 in each component), so that kappa_out * u bounds what
  rounding the state alone does to them;
* floor: the round trip when the per-state representation the package returns
  (z_i, the offsets z_i - d_j, g) and the coefficients alpha_j .. delta_j of (23) are
  rounded to double and mapped back exactly on the exact curve: the error that
  storing them in double precision carries, whatever the algorithm;
* the package's own round trip l -> manakov.kotter -> manakov.from_kotter -> l.
"""

from __future__ import annotations

import inspect
import sys

import mpmath
import numpy as np

import manakov

mpmath.mp.dps = 80
I = mpmath.mpc(0, 1)
CYC = ((0, 1, 2), (1, 2, 0), (2, 0, 1))
U = 2.0**-53


def _order(roots):
    """The package's documented root order (docs/kotter.md §3)."""
    cr = [complex(r) for r in roots]
    scale = max(1.0, max(abs(c) for c in cr))
    real = [abs(c.imag) <= 1e-12 * scale for c in cr]
    if all(real):
        return [roots[i] for i in sorted(range(4), key=lambda i: -cr[i].real)]
    i1 = max((i for i in range(4) if not real[i]), key=lambda i: (cr[i].imag, cr[i].real))
    rest = [i for i in range(4) if i != i1]
    i2 = min(rest, key=lambda i: abs(cr[i] - cr[i1].conjugate()))
    rest = [i for i in rest if i != i2]
    i3, i4 = sorted(rest, key=lambda i: (0.0 if real[i] else cr[i].imag, cr[i].real), reverse=True)
    return [roots[i1], roots[i2], roots[i3], roots[i4]]


def quartic(A, L):
    """Schottky's P(s) = h1 s^2 - h2 s + h3, h0, and the numerator P^2 - 4 h0^2 G of F
    (19), all coefficients descending, in mpmath from mpf lists ``A`` (a) and ``L`` (l)."""
    m = [L[3], -L[1], L[0]]
    n = [L[2], L[4], L[5]]
    h0 = sum(m[j] * n[j] for j in range(3))
    P = [mpmath.mpf(0)] * 3
    for j, k, ll in CYC:
        for (p, q), c in (((j, 3), m[j] ** 2), ((k, ll), n[j] ** 2)):
            P[0] += c
            P[1] -= c * (A[p] + A[q])
            P[2] += c * A[p] * A[q]
    G = [mpmath.mpf(1)]
    for x in A:
        G = [*G, mpmath.mpf(0)]
        for i in range(len(G) - 1, 0, -1):
            G[i] -= x * G[i - 1]
    P2 = [sum(P[i] * P[k - i] for i in range(3) if 0 <= k - i <= 2) for k in range(5)]
    num = [P2[i] - 4 * h0**2 * G[i] for i in range(5)]
    return P, h0, num


def polyroots(coeffs, steps: int) -> list:
    """Roots of the polynomial with descending ``coeffs`` (mpmath >= 1.4 deprecates
    descending coefficients unless asc= is given)."""
    if "asc" in inspect.signature(mpmath.polyroots).parameters:
        return list(mpmath.polyroots(coeffs[::-1], maxsteps=steps, extraprec=steps, asc=True))
    return list(mpmath.polyroots(coeffs, maxsteps=steps, extraprec=steps))


def constants(a, l):
    """s_p, u, v, d_j, alpha_j..delta_j of (19)-(26) at 80 digits."""
    A = [mpmath.mpf(x) for x in a]
    L = [mpmath.mpf(x) for x in l]
    m = [L[3], -L[1], L[0]]
    n = [L[2], L[4], L[5]]
    P, h0, num = quartic(A, L)
    s = _order(polyroots(num, 800))
    sig = [-(P[0] * x * x + P[1] * x + P[2]) / (2 * h0) for x in s]
    sfp = [mpmath.sqrt(mpmath.fprod(s[p] - s[q] for q in range(4) if q != p)) for p in range(4)]
    u = [[mpmath.sqrt((s[p] - A[j]) * (s[p] - A[3])) / sfp[p] for j in range(3)] for p in range(4)]
    v = [[sig[p] / (u[p][j] * sfp[p]) / sfp[p] for j in range(3)] for p in range(4)]
    dd = [[None] * 3 for _ in range(3)]
    for p, q, r in CYC:
        for j in range(3):
            dd[p][j] = u[q][j] * v[r][j] - u[r][j] * v[q][j]
    d, abgd = [], []
    for j in range(3):
        d3 = dd[2][j]
        mi, pl = dd[0][j] - I * dd[1][j], dd[0][j] + I * dd[1][j]
        sd = mi / d3 if abs(mi) >= abs(pl) else -d3 / pl
        d.append(sd * sd)
        u1, v1, u2, v2 = u[0][j], v[0][j], u[1][j], v[1][j]
        abgd.append(
            (
                (v2 + I * v1) / (2 * d3),
                (v2 - I * v1) / (2 * d3),
                -(u2 + I * u1) / (2 * d3),
                -(u2 - I * u1) / (2 * d3),
            )
        )
    xi = [u[0][j] * m[j] + v[0][j] * n[j] + I * (u[1][j] * m[j] + v[1][j] * n[j]) for j in range(3)]
    eta = [
        u[0][j] * m[j] + v[0][j] * n[j] - I * (u[1][j] * m[j] + v[1][j] * n[j]) for j in range(3)
    ]
    return d, abgd, xi, eta


def _curve(d):
    D = [mpmath.mpc(0), *d, d[0] * d[1] * d[2]]
    ct = [1 / ((D[j] - D[k]) * (D[j] - D[ll])) for j, k, ll in ((1, 2, 3), (2, 3, 1), (3, 1, 2))]
    sc = [mpmath.sqrt((D[j + 1] - D[4]) * ct[j]) for j in range(3)]
    return D, ct, sc


def points(d, xi, eta):
    """z1, z2, g^2 from the closed forms (30a), (30b) (exact at 80 digits)."""
    D, ct, sc = _curve(d)
    X = [xi[j] / sc[j] for j in range(3)]
    Y = [eta[j] / sc[j] for j in range(3)]
    g2 = sum(ct[j] * Y[j] ** 2 for j in range(3)) / D[4]
    s1 = D[4] + sum(ct[j] * X[j] ** 2 for j in range(3)) / g2
    s2 = sum(ct[j] * D[j + 1] * X[j] ** 2 for j in range(3)) / g2
    sq = mpmath.sqrt(s1 * s1 - 4 * s2)
    return (s1 + sq) / 2, (s1 - sq) / 2, g2


def xi_eta_back(d, z, zd, g, branch):
    """(27)-(28), (37): xi_j = sqrt(c_j) g P_kl, eta_j = sqrt(c_j) g P_j4, with the roots of
    the offsets zd and a branch (sheet signs of r_4, and eps_j of the P_j)."""
    D, ct, sc = _curve(d)
    s1, s2, eps = branch
    r = [[mpmath.sqrt(x) for x in zd[i]] for i in range(2)]
    r[0][4] *= s1
    r[1][4] *= s2

    def pjk(j, k):
        rest = [mm for mm in range(5) if mm not in (j, k)]
        a_ = r[1][j] * r[1][k] * mpmath.fprod(r[0][mm] for mm in rest)
        b_ = r[0][j] * r[0][k] * mpmath.fprod(r[1][mm] for mm in rest)
        return eps[j] * eps[k] * (a_ - b_) / (z[0] - z[1])

    xi = [sc[j] * g * pjk(k + 1, ll + 1) for j, k, ll in CYC]
    eta = [sc[j] * g * pjk(j + 1, 4) for j, _, _ in CYC]
    return xi, eta


def state_back(abgd, xi, eta):
    m = [abgd[j][0] * xi[j] + abgd[j][1] * eta[j] for j in range(3)]
    n = [abgd[j][2] * xi[j] + abgd[j][3] * eta[j] for j in range(3)]
    return [m[2], -m[1], n[0], m[0], n[1], n[2]]


def branches():
    for s1 in (1, -1):
        for s2 in (1, -1):
            for bits in range(8):
                e = [1 if bits & (1 << b) == 0 else -1 for b in range(3)]
                yield s1, s2, [e[0] * e[1] * e[2], e[0], e[1], e[2], 1]


def rounded(x):
    return mpmath.mpc(complex(x))


def analyse(a, l):
    """kappa_out, the floor, and the reference d_j, z_i, g of one state (at 80 digits
    whatever the caller's mpmath precision)."""
    with mpmath.workdps(80):
        return _analyse(a, l)


def _analyse(a, l):
    d, abgd, xi, eta = constants(a, l)
    z1, z2, g2 = points(d, xi, eta)
    g = mpmath.sqrt(g2)
    D = [mpmath.mpc(0), *d, d[0] * d[1] * d[2]]
    zd = [[z1 - x for x in D], [z2 - x for x in D]]
    scale = max(abs(x) for x in xi + eta)
    best = None
    for br in branches():
        bx, be = xi_eta_back(d, (z1, z2), zd, g, br)
        res = max(abs(bx[j] - xi[j]) + abs(be[j] - eta[j]) for j in range(3)) / scale
        if best is None or res < best[0]:
            best = (res, br)
    assert best[0] < 1e-30, best[0]
    br = best[1]
    # The round trip through the per-state representation rounded to double
    # (points, offsets, g) and the rounded linear map (23), on the exact curve.
    # (The curve's own rounding is not a per-state error: the package fits the
    # points on its rounded curve, so that they reproduce the data there.)
    zr = (rounded(z1), rounded(z2))
    zdr = [[rounded(x) for x in zd[i]] for i in range(2)]
    bx, be = xi_eta_back(d, zr, zdr, rounded(g), br)
    lb = state_back([[rounded(x) for x in row] for row in abgd], bx, be)
    lmax = max(abs(x) for x in l)
    floor = max(float(abs(lb[i] - l[i])) for i in range(6)) / lmax
    # kappa_out: the componentwise relative condition number, max over the outputs o
    # of sum_i |do/dl_i| |l_i| / |o| (rounding perturbs each l_i by up to u |l_i|),
    # by finite differences in each component
    out0 = [*d, z1, z2, g]
    h = mpmath.mpf("1e-25")
    sens = [mpmath.mpf(0)] * 6
    for i in range(6):
        if l[i] == 0:
            continue
        lp = [mpmath.mpf(x) for x in l]
        lp[i] *= 1 + h
        dp, _, xp, ep = constants(a, lp)
        z1p, z2p, g2p = points(dp, xp, ep)
        if abs(z1p - z1) > abs(z2p - z1):
            z1p, z2p = z2p, z1p
        gp = mpmath.sqrt(g2p)
        if abs(gp - g) > abs(gp + g):
            gp = -gp
        out1 = [*dp, z1p, z2p, gp]
        for o in range(6):
            sens[o] += abs(out1[o] - out0[o]) / abs(out0[o]) / h
    kappa = float(max(sens))
    return {
        "kappa": kappa,
        "floor": floor,
        "d": [complex(x) for x in d],
        "z": [complex(z1), complex(z2)],
        "g": complex(g),
        "d4": complex(D[4]),
    }


def main() -> None:
    N = int(sys.argv[1]) if len(sys.argv) > 1 else 4
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    rng = np.random.default_rng(seed)
    print(
        "top              delta   max|d_j|  |d_4|    kappa_out*u (max)  floor (max)  "
        "package round trip (max)"
    )
    for name in manakov.problem_names():
        p = manakov.problem(name)
        for rho in (1e-2, 1e-3, 1e-4, 1e-5):
            rows = []
            for _ in range(N):
                m = rng.normal(size=3)
                sgn = rng.choice([-1, 1])
                v = rng.normal(size=3)
                v /= np.linalg.norm(v)
                n = sgn * m + rho * np.linalg.norm(m) * v
                l = np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])
                mm, nn = np.array([l[3], -l[1], l[0]]), l[[2, 4, 5]]
                delta = np.sum((mm - nn) ** 2) * np.sum((mm + nn) ** 2) / np.sum(l**2) ** 2
                r = analyse(p.a, l)
                k = manakov.kotter(p.a, p.b, l)
                back = manakov.from_kotter(p.a, p.b, k)
                rt = np.max(np.abs(back - l)) / np.max(np.abs(l))
                dmax = max(abs(x) for x in r["d"])
                rows.append((delta, dmax, abs(r["d4"]), r["kappa"] * U, r["floor"], rt))
            r = np.array(rows)
            print(
                f"{name:16s} {np.median(r[:, 0]):.0e}  {r[:, 1].max():.1e}  {r[:, 2].max():.1e}  "
                f"{r[:, 3].max():.1e}            {r[:, 4].max():.1e}      {r[:, 5].max():.1e}"
            )


if __name__ == "__main__":
    main()
