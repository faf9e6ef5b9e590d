# The paper's index names (j, k, l cyclic): E741 does not apply.
# ruff: noqa: E741
"""The Schottky–Kötter chain of the Clebsch body, contracted from so(4).

An independent implementation of docs/clebsch.md §2 (no package code; the
constants of the level set in mpmath at 50 digits, rounded at the end): the
contraction ``a4 → ∞`` of Schottky's vector (12), its square (14)–(15), the
quartic (19), the isotropic vectors (20), Kötter's ξ, η (22), Δ (25) and the
constants d_j (26) of the curve (8), for a body with parameters ``a_i``
(``a_j − a_k = (C_k − C_j)/A_i``) and a state ``(M, p)``.

Convention: the homogeneous offset of the point at infinity is
``s − a4 := −1``, so that

    λ_j(s) = √(a_j − s) M_j + √((s − a_k)(s − a_l)) p_j,
    λ(s)·λ(s) = h1 s² − h2 s + h3 + 2 h0 √G(s),   G(s) = −Π_{i=1}^{3} (s − a_i),
    h1 = p·p,  h2 = M·M + Σ_j (a_k + a_l) p_j²,  h3 = Σ_j a_j M_j² + Σ_j a_k a_l p_j²,  h0 = M·p,
    F(s) = [(h1 s² − h2 s + h3)² − 4 h0² G(s)] / h1²       (monic: G is cubic)

with ``√((s − a_k)(s − a_l)) := √G(s)/√(a_j − s)`` for one branch of ``√G``.
Run as a script it prints the checks of tests/test_fluid_clebsch.py for the
reference bodies.
"""

from __future__ import annotations

import inspect

import mpmath as mp
import numpy as np

CYC = ((0, 1, 2), (1, 2, 0), (2, 0, 1))


def _horner(coef, x):
    """The polynomial with descending ``coef`` at ``x`` (mpmath >= 1.4 deprecates
    descending coefficients in polyval)."""
    acc = 0
    for c in coef:
        acc = acc * x + c
    return acc


def integrals(a, M, p):
    """``(h0, h1, h2, h3)`` of the contracted (15)."""
    a, M, p = (np.asarray(x, dtype=float) for x in (a, M, p))
    h1 = p @ p
    h2 = M @ M + sum((a[k] + a[l]) * p[j] ** 2 for j, k, l in CYC)
    h3 = a @ (M * M) + sum(a[k] * a[l] * p[j] ** 2 for j, k, l in CYC)
    return np.array([M @ p, h1, h2, h3])


def G(a, s):
    """``G(s) = −Π (s − a_i)``: ``G(s)`` of (15) with ``s − a4 := −1``."""
    s = np.asarray(s, dtype=complex)
    return -np.prod([s - ai for ai in a], axis=0)


def schottky(a, M, p, s, sqrt_g=None):
    """The contracted vector (12) ``λ(s)`` (shape (3,)), ``√G(s)`` principal by default."""
    s = complex(s)
    q = np.sqrt(G(a, s)) if sqrt_g is None else sqrt_g
    out = np.empty(3, dtype=complex)
    for j in range(3):
        r = np.sqrt(complex(a[j] - s))
        out[j] = r * M[j] + (q / r) * p[j]
    return out


def quartic(a, h):
    """Monic coefficients (highest first) of the contracted F (19)."""
    h0, h1, h2, h3 = h
    P = np.array([h1, -h2, h3])
    g = np.poly(np.asarray(a, dtype=float))  # Π (s − a_i), so G = −g
    num = np.polyadd(np.polymul(P, P), 4 * h0 * h0 * g)
    return num / (h1 * h1)


def order_roots(r, scale):
    """The package's order (docs/kotter.md §3): s1 the non-real root of largest
    imaginary part, s2 = conj(s1), then the remaining one of larger imaginary part
    (then real part); all real: descending."""
    r = np.asarray(r, dtype=complex)
    tol = 1e-12 * scale
    nonreal = [x for x in r if abs(x.imag) > tol]
    if not nonreal:
        return np.sort(r.real)[::-1].astype(complex)
    s1 = max(nonreal, key=lambda x: x.imag)
    rest = list(r)
    rest.pop(int(np.argmin(np.abs(np.array(rest) - s1))))
    i2 = int(np.argmin(np.abs(np.array(rest) - np.conj(s1))))
    rest.pop(i2)
    s3, s4 = sorted(rest, key=lambda x: (x.imag, x.real), reverse=True)
    return np.array([s1, np.conj(s1), s3, s4])


def reduce(a, M, p, dps: int = 50):
    """The contracted chain at one state: roots, σ_p, F'(s_p), l^(p), ξ, η, Δ, d.

    The roots of F and everything after them are computed in mpmath at ``dps``
    digits from the doubles ``a, M, p`` (a quartic's roots on different
    branches of f lose digits in double precision, docs/kotter.md §3), then
    rounded. Returns a dict with ``h``, ``s``, ``sigma``, ``fprime``, ``u``,
    ``v`` (4, 3), ``l_p`` (4, 3), ``xi``, ``eta``, ``Delta`` (3, 3), ``sqrt_d``, ``d``.
    """
    with mp.workdps(dps):
        a = [mp.mpf(float(x)) for x in a]
        M = [mp.mpf(float(x)) for x in M]
        p = [mp.mpf(float(x)) for x in p]
        h1 = sum(x * x for x in p)
        h2 = sum(x * x for x in M) + sum((a[k] + a[l]) * p[j] ** 2 for j, k, l in CYC)
        h3 = sum(a[j] * M[j] ** 2 for j in range(3)) + sum(
            a[k] * a[l] * p[j] ** 2 for j, k, l in CYC
        )
        h0 = sum(M[j] * p[j] for j in range(3))
        # F h1² = (h1 s² − h2 s + h3)² + 4 h0² Π (s − a_i)   (G = −Π (s − a_i))
        P = [h1, -h2, h3]
        sq = [sum(P[i] * P[k - i] for i in range(3) if 0 <= k - i < 3) for k in range(5)]
        g = [mp.mpf(1), -(a[0] + a[1] + a[2]), a[0] * a[1] + a[1] * a[2] + a[2] * a[0]]
        g.append(-a[0] * a[1] * a[2])
        num = [sq[0], sq[1] + 4 * h0**2 * g[0], sq[2] + 4 * h0**2 * g[1]]
        num += [sq[3] + 4 * h0**2 * g[2], sq[4] + 4 * h0**2 * g[3]]
        coef = [c / h1**2 for c in num]
        # mpmath >= 1.4 deprecates descending coefficients unless asc= is given
        if "asc" in inspect.signature(mp.polyroots).parameters:
            roots = mp.polyroots(coef[::-1], maxsteps=200, extraprec=2 * dps, asc=True)
        else:
            roots = mp.polyroots(coef, maxsteps=200, extraprec=2 * dps)
        scale = max(1.0, float(max(abs(x) for x in a)))
        order = order_roots(np.array([complex(r) for r in roots]), scale)
        s = [min(roots, key=lambda r, o=o: abs(complex(r) - o)) for o in order]
        # Pair conjugate roots exactly (s2 = conj(s1) for a real state).
        if abs(mp.im(s[0])) > 0:
            s[1] = mp.conj(s[0])
        dcoef = [c * (4 - i) for i, c in enumerate(coef[:-1])]
        fp = [_horner(dcoef, x) for x in s]
        sigma = [-(h1 * x * x - h2 * x + h3) / (2 * h0) for x in s]
        sqf = [mp.sqrt(x) for x in fp]
        u = [[mp.sqrt(a[j] - s[q]) / sqf[q] for j in range(3)] for q in range(4)]
        v = [[sigma[q] / mp.sqrt(a[j] - s[q]) / sqf[q] for j in range(3)] for q in range(4)]
        lp = [[u[q][j] * M[j] + v[q][j] * p[j] for j in range(3)] for q in range(4)]
        xi = [lp[0][j] + 1j * lp[1][j] for j in range(3)]
        eta = [lp[0][j] - 1j * lp[1][j] for j in range(3)]
        Delta = [[u[q][j] * v[r][j] - u[r][j] * v[q][j] for j in range(3)] for _, q, r in CYC]
        sqrt_d = [(Delta[0][j] - 1j * Delta[1][j]) / Delta[2][j] for j in range(3)]

        return {
            "h": np.array([float(h0), float(h1), float(h2), float(h3)]),
            "s": np.array([complex(x) for x in s]),
            "sigma": np.array([complex(x) for x in sigma]),
            "fprime": np.array([complex(x) for x in fp]),
            "u": np.array([[complex(x) for x in row] for row in u]),
            "v": np.array([[complex(x) for x in row] for row in v]),
            "l_p": np.array([[complex(x) for x in row] for row in lp]),
            "xi": np.array([complex(x) for x in xi]),
            "eta": np.array([complex(x) for x in eta]),
            "Delta": np.array([[complex(x) for x in row] for row in Delta]),
            "sqrt_d": np.array([complex(x) for x in sqrt_d]),
            "d": np.array([complex(x * x) for x in sqrt_d]),
        }


def xi_eta(red, M, p):
    """ξ, η of another state ``(M, p)`` with the constants of ``red`` (linear in the state)."""
    lp = red["u"] * np.asarray(M)[None, :] + red["v"] * np.asarray(p)[None, :]
    return lp[0] + 1j * lp[1], lp[0] - 1j * lp[1]


def quadrics(d, xi, eta):
    """Kötter's quadrics (11) at ``(ξ, η)``, relative to the size of their terms."""
    q1 = np.sum(xi * xi + eta * eta) / np.sum(np.abs(xi) ** 2 + np.abs(eta) ** 2)
    q2 = np.sum(xi * eta) / np.sum(np.abs(xi * eta))
    t3 = d * xi * xi + eta * eta / d
    q3 = np.sum(t3) / np.sum(np.abs(t3))
    return np.array([q1, q2, q3])


def same_up_to_branches(d1, d2):
    """The largest over ``j`` of the smallest relative distance between ``d1_j`` and
    ``±d2_j^{±1}``. The branch choices of the chain act per component: the sign
    of ``l_j^(1)`` alone maps ``d_j → 1/d_j`` (it flips ``Δ_j^(2)`` and
    ``Δ_j^(3)`` of (25), and ``(Δ1 + iΔ2)/(−Δ3) = 1/√d_j`` by (26)), the order
    of ``s3, s4`` maps ``d → −d`` (docs/kotter.md §3)."""
    d1, d2 = np.asarray(d1), np.asarray(d2)
    images = np.stack([d2, -d2, 1 / d2, -1 / d2])
    return float(np.max(np.min(np.abs(d1[None, :] - images) / np.abs(images), axis=0)))


if __name__ == "__main__":
    import manakov

    for name in manakov.fluid_problem_names()[:4]:
        pr = manakov.fluid_problem(name)
        conj = pr.body._clebsch
        a = conj.body_a
        red = reduce(a, pr.M0, pr.p0)
        tr = pr.body.integrate(pr.M0, pr.p0, 20.0, sample_every=0.5)
        worst = max(
            np.max(np.abs(quadrics(red["d"], *xi_eta(red, m, q)))) for m, q in zip(tr.M, tr.p)
        )
        print(f"{name}: d = {np.round(red['d'], 6)}, quadrics (11) along [0, 20]: {worst:.1e}")
