# ruff: noqa: E741  (l is the paper's name for the state)
"""Independent mpmath reference for ``U`` in closed form (docs/theorem.md, "U in closed form").

Nothing here imports the package in the computations: the level-set constants come
from the 80-digit mpmath reduction of ``kotter_singular_conditioning.constants``
(quartic (19) by ``mpmath.polyroots``, the corrected (20)-(26)), and:

* ``velocity(a, b, l, p)``: ``V = A U`` from Dubrovin's equations at the half period
  ``D_p = d_0 + d_p`` of the curve (8): the state ``l(D_p)`` of (27)-(28), (37), (23)
  with ``g = G = sqrt(h0/K)``; Frahm's equations (1) there, mapped by (20), (22), give
  ``d(xi, eta)/dt``; each label ``P_jk`` that vanishes at ``D_p`` gives
  ``d_q V0 - V1 = -2 (d/dt)(sqrt(c) g P_jk) / (sqrt(c) G r_j(0) r_k(0) r_j(d_p) r_k(d_p))``,
  ``q`` the fifth index. Three equations, two unknowns: returns ``V`` from two and
  the relative residual of the third (zero to the working precision when the
  derivation is right).
* ``loop_periods(e, edges)``: the loop periods of the tree edges of a curve
  ``y^2 = prod (x - e_k)`` (``-2i int x^i / prod phi_k dt / sqrt(1 - t^2)`` on each edge,
  ``mpmath.quad``), up to one sign per loop (the caller matches it).
* ``lattice_rates(P, V)``: the real ``(X1, X2, Y1, Y2)`` with ``V = A X + B Y``.

Run ``python tests/data/closed_u_reference.py`` to print, for the four shared tops,
the residual of the third equation at every half period, the spread of ``V`` over
the four half periods, and the package's ``U`` against ``X + tau Y`` of the exact
``V`` and the exact periods (in the package's homology basis).
"""

from __future__ import annotations

import sys
from pathlib import Path

import mpmath as mp

sys.path.insert(0, str(Path(__file__).parent))
from kotter_singular_conditioning import CYC, constants  # noqa: E402

#: Working precision of the reference (decimal digits).
DPS = 60
PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
#: (xi_1, xi_2, xi_3, eta_1, eta_2, eta_3) <-> P_23, P_31, P_12, P_14, P_24, P_34
LABELS = [(2, 3), (3, 1), (1, 2), (1, 4), (2, 4), (3, 4)]


def field(a, b, l):
    """Frahm's (1), l_dot_ij = sum_k l_ik l_kj (c_kj - c_ik), c_ij = (b_i-b_j)/(a_i-a_j)."""
    A = [mp.mpf(x) for x in a]
    B = [mp.mpf(x) for x in b]

    def c(i, j):
        return (B[i] - B[j]) / (A[i] - A[j])

    L = {}
    for q, (i, j) in enumerate(PAIRS):
        L[(i, j)], L[(j, i)] = l[q], -l[q]
    out = []
    for i, j in PAIRS:
        out.append(
            sum(L[(i, k)] * L[(k, j)] * (c(k, j) - c(i, k)) for k in range(4) if k not in (i, j))
        )
    return out


def level(a, l):
    """d_j, (alpha..delta)_j, u, v of (20) (p = 1, 2), h0 and K of the corrected (40)."""
    d, abgd, _, _ = constants(a, l)
    L = [mp.mpf(x) for x in l]
    m = [L[3], -L[1], L[0]]
    n = [L[2], L[4], L[5]]
    h0 = sum(m[j] * n[j] for j in range(3))
    d4 = d[0] * d[1] * d[2]
    kap = mp.fprod(dm - d4 for dm in d)
    ct = [1 / ((d[j] - d[k]) * (d[j] - d[ll])) for j, k, ll in CYC]
    K = kap * sum(ct[j] * d[j] * abgd[j][1] * abgd[j][3] for j in range(3))
    return {"d": d, "abgd": abgd, "h0": h0, "K": K, "ct": ct, "d4": d4}


def velocity(a, b, l, p, lv=None):
    """(V, residual of the third equation, |l(D_p)|) at the half period d_0 + d_p."""
    lv = lv or level(a, l)
    d, abgd, ct = lv["d"], lv["abgd"], lv["ct"]
    D = [mp.mpc(0), *d, lv["d4"]]
    sc = [mp.sqrt((D[j + 1] - D[4]) * ct[j]) for j in range(3)]
    G = mp.sqrt(lv["h0"] / lv["K"])
    r0 = [mp.sqrt(-D[m]) for m in range(5)]
    rp = [mp.sqrt(D[p] - D[m]) for m in range(5)]
    comp = [mp.mpc(0)] * 6
    eqs = []
    for i, (j, k) in enumerate(LABELS):
        if p in (j, k):
            o = k if j == p else j
            comp[i] = (
                sc[i % 3]
                * G
                * r0[o]
                * r0[p]
                * mp.fprod(rp[m] for m in range(5) if m not in (o, p))
                / D[p]
            )
        else:
            q = next(m for m in range(5) if m not in (0, p, j, k))
            eqs.append((i, q, sc[i % 3] * G * r0[j] * r0[k] * rp[j] * rp[k]))
    xi, eta = comp[:3], comp[3:]
    m = [abgd[j][0] * xi[j] + abgd[j][1] * eta[j] for j in range(3)]
    n = [abgd[j][2] * xi[j] + abgd[j][3] * eta[j] for j in range(3)]
    lst = [m[2], -m[1], n[0], m[0], n[1], n[2]]
    ld = field(a, b, lst)
    md = [ld[3], -ld[1], ld[0]]
    nd = [ld[2], ld[4], ld[5]]
    rows = []
    for i, q, fac in eqs:
        j = i % 3
        al, be, ga, de = abgd[j]
        det = al * de - be * ga
        # the inverse of (23)
        cdot = (de * md[j] - be * nd[j]) / det if i < 3 else (-ga * md[j] + al * nd[j]) / det
        rows.append((D[q], -2 * cdot / fac))
    (d1, r1), (d2, r2), (d3, r3) = rows
    v0 = (r1 - r2) / (d1 - d2)
    v1 = d1 * v0 - r1
    res = abs(d3 * v0 - v1 - r3) / max(abs(d3 * v0), abs(v1), abs(r3))
    size = mp.sqrt(sum(abs(x) ** 2 for x in lst))
    return [v0, v1], res, size


def loop_periods(e, edges):
    """Loop periods of the tree edges p -> q: (2, len(edges)) list, one sign per loop open."""
    out = [[None] * len(edges) for _ in range(2)]
    for c, (p, q) in enumerate(edges):
        ep, eq = e[p], e[q]
        h, mid = (eq - ep) / 2, (ep + eq) / 2
        others = [e[k] for k in range(len(e)) if k not in (p, q)]
        rots = []
        for ek in others:
            # the point of the segment nearest e_k: sqrt(c w)/sqrt(c) is continuous on it
            tt = min(1, max(-1, -mp.re((mid - ek) * mp.conj(h)) / abs(h) ** 2))
            pnear = mid + h * tt - ek
            rots.append(mp.conj(pnear) / abs(pnear))
        cuts = {mp.mpf(0), mp.pi}
        for ek in others:
            tt = mp.re((ek - mid) * mp.conj(h)) / abs(h) ** 2
            if -1 < tt < 1:
                cuts.add(mp.acos(tt))
        for power in (0, 1):

            def f(th, power=power, mid=mid, h=h, others=others, rots=rots):
                x = mid + h * mp.cos(th)
                den = mp.mpc(1)
                for ek, rot in zip(others, rots):
                    den *= mp.sqrt(rot * (x - ek)) / mp.sqrt(rot)
                return x**power / den

            out[power][c] = -2j * mp.quad(f, sorted(cuts), maxdegree=14)
    return out


def lattice_rates(P, V):
    """Real (X1, X2, Y1, Y2) with V = A X + B Y, P = [A B] as a 2 x 4 list."""
    M = mp.matrix(4, 4)
    for k in range(4):
        for i in range(2):
            M[i, k] = mp.re(P[i][k])
            M[2 + i, k] = mp.im(P[i][k])
    r = mp.matrix([mp.re(V[0]), mp.re(V[1]), mp.im(V[0]), mp.im(V[1])])
    return [x for x in mp.lu_solve(M, r)]


def exact_rates(a, b, l, edges, symplectic, cycle_periods):
    """(X, Y) of the top (a, b) on the level set of l in the homology basis given by the
    tree ``edges``, the symplectic matrix (rows a1, a2, b1, b2 in the loops) and the
    package's loop periods (which fix only the sign of each loop), all at ``DPS`` digits
    on the exact curve; and V (the sign of V against ``cycle_periods`` is not fixed here)."""
    with mp.workdps(DPS):
        lv = level(a, l)
        d = lv["d"]
        e = [mp.mpc(0), *d, lv["d4"]]
        L = loop_periods(e, edges)
        sg = []
        for k in range(len(edges)):
            dot = sum(mp.conj(L[i][k]) * complex(cycle_periods[i][k]) for i in range(2))
            sg.append(1 if mp.re(dot) > 0 else -1)
        P = [
            [sum(symplectic[r][k] * sg[k] * L[i][k] for k in range(4)) for r in range(4)]
            for i in range(2)
        ]
        V, _, _ = velocity(a, b, l, 4, lv)
        return lattice_rates(P, V), P, V


def main() -> None:
    import numpy as np

    import manakov

    mp.mp.dps = DPS
    for name in manakov.problem_names():
        pr = manakov.problem(name)
        a, b, l = (np.asarray(x, float) for x in (pr.a, pr.b, pr.l0))
        lv = level(a, l)
        vs, res = [], []
        for p in (1, 2, 3, 4):
            v, r, _ = velocity(a, b, l, p, lv)
            vs.append(v)
            res.append(r)
        spread = max(
            min(max(abs(v[i] - s * vs[0][i]) for i in range(2)) for s in (1, -1)) for v in vs[1:]
        ) / max(abs(vs[0][0]), abs(vs[0][1]))
        sol = manakov.ManakovTop(a, b).solve(l)
        c = sol.curve
        w, _, _ = exact_rates(a, b, l, c.cycle_edges, c.symplectic_basis, c.cycle_periods)
        # the sign of V: that of the package's U
        x = np.array([float(t) for t in w])
        u_ref = x[:2] + sol.tau @ x[2:]
        s = 1.0 if np.real(np.vdot(u_ref, sol.U)) > 0 else -1.0
        err = np.max(np.abs(sol.U - s * u_ref)) / np.max(np.abs(u_ref))
        print(
            f"{name:16s} third equation max {float(max(res)):.1e}  "
            f"spread over p {float(spread):.1e}  "
            f"package U vs X + tau Y (exact) {err:.1e}"
        )


if __name__ == "__main__":
    main()
