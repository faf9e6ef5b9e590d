# ruff: noqa: E741  (l is the paper's name for the state)
"""The Schottky-Koetter reduction of single states at 60 digits (mpmath), against
the package's ``manakov.kotter``: roots of F (19), ``d_j`` (26), ``xi``, ``eta``
(22), component by component.

Written from the paper's formulas and the conventions of docs/kotter.md, it
does not use the package for any step of the reduction: ``h`` (6)-(7) from the
state (complementary-pair ``h2``, ``h3``), the monic quartic (19) and its roots
by ``mpmath.polyroots``, ``l^(p) = l(s_p)/sqrt(F'(s_p))`` (20),
``Delta`` (25) corrected, ``sqrt(d_j)`` (26), ``xi``, ``eta`` (22). The root
order is the documented one (docs/kotter.md); where the package labels the
roots otherwise (it takes a conjugate pair of imaginary part below 1e-12 of
the root for real roots, which 60 digits still resolve), the comparison says
so instead of comparing different labellings.

Small components of ``xi``, ``eta`` are compared to their own size: near an
equilibrium ``l_ij E_ij + l_kl E_kl`` the points of the curve lie within 1e-13
of branch points, and the inverse map of (37) needs each component to a few
ulps of itself, not of ``max |(xi, eta)|``.

Run: python tests/data/kotter_mpmath_state.py [DRAW ...]
(draws of every_state_harsh.py, seed 20261125; default 316 29 172 273)
"""

from __future__ import annotations

import sys
from pathlib import Path

import mpmath as mp
import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).resolve().parent))
from every_state_harsh import draw  # noqa: E402

mp.mp.dps = 60
CYC = ((0, 1, 2), (1, 2, 0), (2, 0, 1))
PAIRS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def state(i: int, seed: int = 20261125):
    rng = np.random.default_rng(seed)
    for _ in range(i + 1):
        a, b, l0 = draw(rng)
    return a, b, l0


def reduce_mp(a, l0):
    A = [mp.mpf(float(x)) for x in a]
    l = [mp.mpf(float(x)) for x in l0]
    l12, l13, l14, l23, l24, l34 = l
    m = [l23, -l13, l12]
    n = [l14, l24, l34]
    h0 = l12 * l34 + l23 * l14 - l13 * l24
    h1 = sum(x * x for x in l)

    def comp(j, k):
        return [x for x in range(4) if x not in (j, k)]

    h2 = sum((A[comp(j, k)[0]] + A[comp(j, k)[1]]) * l[q] ** 2 for q, (j, k) in enumerate(PAIRS))
    h3 = sum((A[comp(j, k)[0]] * A[comp(j, k)[1]]) * l[q] ** 2 for q, (j, k) in enumerate(PAIRS))
    g = [mp.mpf(1)]
    for x in A:
        # G(s) = prod (s - a_m), highest power first
        g = [
            (g[i] if i < len(g) else 0) - (x * g[i - 1] if i >= 1 else 0) for i in range(len(g) + 1)
        ]
    p = [h1, -h2, h3]
    pp = [sum(p[i] * p[k - i] for i in range(3) if 0 <= k - i < 3) for k in range(5)]
    fc = [(pp[k] - 4 * h0**2 * g[k]) / (h1**2 - 4 * h0**2) for k in range(5)]
    try:
        roots = mp.polyroots(fc[::-1], maxsteps=500, extraprec=800, asc=True)
    except TypeError:  # mpmath before 1.4: descending coefficients only
        roots = mp.polyroots(fc, maxsteps=500, extraprec=800)
    # documented order: s1 the non-real root of largest Im, s2 its conjugate,
    # s3 the remaining one of larger Im (then Re), s4; all real: descending
    scale = max(1, max(abs(complex(x)) for x in roots))
    # at 60 digits a conjugate pair of imaginary part 1e-40 of the root is
    # still resolved; below that the roots are real
    nonreal = [x for x in roots if abs(mp.im(x)) > 1e-40 * scale]
    if nonreal:
        s1 = max(nonreal, key=lambda x: (mp.im(x), mp.re(x)))
        rest = [x for x in roots if x is not s1]
        s2 = min(rest, key=lambda x: abs(x - mp.conj(s1)))
        rest = [x for x in rest if x is not s2]
        s3, s4 = sorted(rest, key=lambda x: (mp.im(x), mp.re(x)), reverse=True)
        s = [s1, mp.conj(s1), s3, s4]
    else:
        s = sorted((mp.re(x) for x in roots), reverse=True)
    fd = [4 * fc[0], 3 * fc[1], 2 * fc[2], fc[3]]

    def uv(sp):
        fp = mp.mpf(0)
        for c in fd:  # Horner, highest power first
            fp = fp * sp + c
        sf = mp.sqrt(fp)
        rt = [mp.sqrt((sp - A[j]) * (sp - A[3])) for (j, _, _) in CYC]
        sig = -(h1 * sp * sp - h2 * sp + h3) / (2 * h0)
        return [x / sf for x in rt], [sig / x / sf for x in rt]

    w = [uv(x) for x in s[:3]]
    D = [None] * 3
    for pq, q, r in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        D[pq] = [w[q][0][j] * w[r][1][j] - w[r][0][j] * w[q][1][j] for j in range(3)]
    d = [((D[0][j] - 1j * D[1][j]) / D[2][j]) ** 2 for j in range(3)]
    L = [[w[pq][0][j] * m[j] + w[pq][1][j] * n[j] for j in range(3)] for pq in range(2)]
    xi = [L[0][j] + 1j * L[1][j] for j in range(3)]
    eta = [L[0][j] - 1j * L[1][j] for j in range(3)]
    return s, d, xi, eta


def rel(x, ref) -> float:
    return float(abs(mp.mpc(x) - ref) / abs(ref)) if ref != 0 else float(abs(mp.mpc(x)))


def main(draws: list[int]) -> None:
    for i in draws:
        a, b, l0 = state(i)
        s, d, xi, eta = reduce_mp(a, l0)
        try:
            k = manakov.kotter(a, b, l0)
        except ValueError as e:
            print(f"draw {i}: the package refuses: {str(e)[:100]}")
            continue
        order = max(rel(k.s[p], s[p]) for p in range(4))
        if order > 1e-8:
            print(f"draw {i}: the package labels the roots otherwise ({order:.1e})")
            continue
        print(f"draw {i}: roots {order:.1e}")
        # d and its conjugate describe the same real curve (x -> conj(x) or
        # -conj(x), docs/kotter.md); the branches of (25) may pick either
        dconj = all(rel(k.d[j], mp.conj(d[j])) < rel(k.d[j], d[j]) for j in range(3))
        dref = [mp.conj(x) for x in d] if dconj else d
        print(
            "   d   ",
            " ".join(f"{rel(k.d[j], dref[j]):.1e}" for j in range(3)),
            "(against conj(d))" if dconj else "",
        )
        print("   xi  ", " ".join(f"{rel(k.xi[j], xi[j]):.1e}" for j in range(3)))
        print("   eta ", " ".join(f"{rel(k.eta[j], eta[j]):.1e}" for j in range(3)))
        print(
            "   |xi_j|/max  ",
            " ".join(f"{float(abs(x)) / float(max(abs(y) for y in xi + eta)):.1e}" for x in xi),
        )


if __name__ == "__main__":
    main([int(x) for x in sys.argv[1:]] or [316, 29, 172, 273])
