"""Independent mpmath reference: periods and Abel map of the curve (8) (tests only).

The curve is ``y^2 = R(x) = x (x - d1)(x - d2)(x - d3)(x - d4)``, ``d4 = d1 d2 d3``,
with REAL branch points, sorted ``e1 < e2 < e3 < e4 < e5`` (and ``infinity``).
Nothing here imports the package.

Homology basis (stated once, used everywhere)
---------------------------------------------
``y_+(x)`` is the branch of ``y`` on the upper half plane given by the product of
principal roots, ``y_+(x) = prod_m sqrt(x - e_m)``; on the real axis (from above)
``y_+(x) = i^{#{m: e_m > x}} sqrt|R(x)|``. ``J_k = int_{e_k}^{e_{k+1}} omega / y_+``
(along the upper side of the real axis), ``omega = (1, x) dx``.

``c_k`` (k = 1..4) is the loop around ``[e_k, e_{k+1}]`` that runs along the
upper side from ``e_k`` to ``e_{k+1}`` on the sheet ``y_+`` and back below on the
other sheet (the half turn around ``e_{k+1}`` flips the sign of the boundary
value), so ``int_{c_k} omega = 2 J_k``. Adjacent loops meet once, in the upper
half plane, all with the same sign ``s = c_k . c_{k+1}``; non-adjacent loops
are disjoint. The canonical basis is

    a1 = c1,  a2 = c3,  b1 = s (c2 + c4),  b2 = s c4

(``a_i . b_j = delta_ij``, ``a . a = b . b = 0``). The sign ``s = +-1`` is the
one for which ``Im tau > 0`` (the other gives ``-tau``); it is returned.

Periods: ``A[i, j] = int_{a_j} omega_i``, ``B[i, j] = int_{b_j} omega_i``,
``tau = A^{-1} B``. Abel map with base point ``infinity``, normalised:
``u(P) = A^{-1} int_infinity^P omega`` along ``infinity -> e5`` on the real axis
(sheet ``y_+ > 0``) and then the straight segment ``e5 -> x`` with ``y`` continued
along it (for ``Im x != 0`` the product of principal roots is continuous on the
segment, so ``y = sigma * prod_m sqrt(x(t) - e_m)``, ``sigma = +-1``).
"""

from __future__ import annotations

from functools import lru_cache

import mpmath as mp

#: Working precision (decimal digits) of the reference quadratures.
DPS = 30
#: Largest accepted quadrature error estimate (relative): far below the 1e-15
#: of the double-precision theta values the tests compare with.
QUAD_TOL = mp.mpf(10) ** -20


def branch_points(d: tuple[float, float, float]) -> list[mp.mpf]:
    """Sorted real branch points ``0, d1, d2, d3, d1 d2 d3`` (exact products)."""
    with mp.workdps(DPS):
        d1, d2, d3 = (mp.mpf(x) for x in d)
        return sorted([mp.mpf(0), d1, d2, d3, d1 * d2 * d3])


def y_principal(x, e):
    """``prod_m sqrt(x - e_m)``, principal roots (the branch ``y_+`` on Im x > 0)."""
    out = mp.mpc(1)
    for em in e:
        out *= mp.sqrt(mp.mpc(x) - em)
    return out


def _interval_integral(e, k: int, power: int):
    """``J_k = int_{e_k}^{e_{k+1}} x^power dx / y_+`` (0-based k), upper side.

    ``x = e_k + D sin^2 phi`` removes both square-root end singularities.
    """
    lo, hi = e[k], e[k + 1]
    dlt = hi - lo
    n_above = len(e) - (k + 1)  # branch points > x on (e_k, e_{k+1})
    phase = mp.mpc(0, 1) ** n_above

    def f(phi):
        s = mp.sin(phi)
        x = lo + dlt * s * s
        rest = mp.mpf(1)
        for m, em in enumerate(e):
            if m not in (k, k + 1):
                rest *= mp.sqrt(abs(x - em))
        # dx / sqrt|(x - lo)(hi - x)| = 2 dphi
        return 2 * x**power / rest

    return mp.quad(f, [0, mp.pi / 2]) / phase


def _tail_integral(e, power: int):
    """``int_{e5}^{inf} x^power dx / y``, ``y > 0`` (x = e5 + t^2)."""
    e5 = e[-1]

    def f(t):
        x = e5 + t * t
        rest = mp.mpf(1)
        for em in e[:-1]:
            rest *= mp.sqrt(x - em)
        return 2 * x**power / rest

    return mp.quad(f, [0, 1, mp.inf])


@lru_cache(maxsize=8)
def periods(d: tuple[float, float, float]):
    """``(A, B, tau, s)`` in the basis of the module docstring (mpmath matrices)."""
    with mp.workdps(DPS):
        e = branch_points(d)
        jj = [[_interval_integral(e, k, p) for k in range(4)] for p in (0, 1)]
        c = [[2 * jj[p][k] for k in range(4)] for p in (0, 1)]
        best = None
        for s in (1, -1):
            a_mat = mp.matrix([[c[p][0], c[p][2]] for p in (0, 1)])
            b_mat = mp.matrix([[s * (c[p][1] + c[p][3]), s * c[p][3]] for p in (0, 1)])
            tau = mp.inverse(a_mat) * b_mat
            im = [[mp.im(tau[i, j]) for j in range(2)] for i in range(2)]
            if im[0][0] > 0 and im[0][0] * im[1][1] - im[0][1] * im[1][0] > 0:
                best = (a_mat, b_mat, tau, s)
        if best is None:
            raise RuntimeError("no sign s gives Im tau > 0")
        return best


@lru_cache(maxsize=8)
def _base(d: tuple[float, float, float]):
    """``int_infinity^{e5} omega`` on the sheet ``y > 0`` of ``x > e5``."""
    with mp.workdps(DPS):
        e = branch_points(d)
        return [-_tail_integral(e, p) for p in (0, 1)]


def abel_unnormalised(d: tuple[float, float, float], x: complex, sigma: int):
    """``int_infinity^P omega`` for ``P = (x, sigma * y_principal(x))``, Im x != 0."""
    with mp.workdps(DPS):
        e = branch_points(d)
        x = mp.mpc(x)
        if mp.im(x) == 0:
            raise ValueError("the segment e5 -> x needs Im x != 0")
        e5 = e[-1]
        w = x - e5
        sw = mp.sqrt(w)
        # Split the segment where it passes closest to the other branch points
        # (near-singular integrand there); t^2 = projection of e_m - e5 on w.
        cuts = {mp.mpf(0), mp.mpf(1)}
        for em in e[:-1]:
            t2 = mp.re((em - e5) * mp.conj(w)) / abs(w) ** 2
            if 0 < t2 < 1:
                cuts.add(mp.sqrt(t2))
        nodes = sorted(cuts)
        out = []
        for p in (0, 1):
            # x(t) = e5 + t^2 w: dx = 2 t w dt, sqrt(x(t) - e5) = t sqrt(w).
            def f(t, p=p):
                xt = e5 + t * t * w
                rest = mp.mpc(1)
                for em in e[:-1]:
                    rest *= mp.sqrt(xt - em)
                return 2 * w * xt**p / (sw * rest)

            val, err = mp.quad(f, nodes, error=True, maxdegree=10)
            if err > QUAD_TOL * (1 + abs(val)):
                raise RuntimeError(f"Abel integral to {x}: quadrature error {err}")
            out.append(_base(d)[p] + sigma * val)
        return out


def abel(d: tuple[float, float, float], x: complex, sigma: int) -> list[complex]:
    """Normalised Abel map ``u(P) = A^{-1} int_infinity^P omega`` as two complexes."""
    with mp.workdps(DPS):
        a_mat = periods(d)[0]
        v = mp.inverse(a_mat) * mp.matrix(abel_unnormalised(d, x, sigma))
        return [complex(v[0]), complex(v[1])]


def tau_complex(d: tuple[float, float, float]) -> list[list[complex]]:
    """``tau`` rounded to complex128."""
    tau = periods(d)[2]
    return [[complex(tau[i, j]) for j in range(2)] for i in range(2)]
