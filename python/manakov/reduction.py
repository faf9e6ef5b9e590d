# ruff: noqa: E741  (l is the paper's name for the state)
"""Schottky's l(s) and Kötter's reduction: from a state l to the curve (8) and back.

The chain, with the paper's equation numbers (details and every convention in
``docs/kotter.md``; corrected formulas in ``docs/errata.md``):

* Schottky's vector (12) ``l_j(s) = sqrt(s_j4) m_j + sqrt(s_kl) n_j`` with
  ``m_j = l_kl``, ``n_j = l_j4`` (13), and its square (14) with its closed form (15)
  ``f(s) = h1 s^2 - h2 s + h3 + 2 h0 sqrt(G(s))`` (with the complementary-pair
  ``h2``, ``h3``);
* the quartic ``F(s)`` (19), its roots ``s_p`` and the isotropic vectors
  ``l^(p) = l(s_p)/sqrt(F'(s_p))`` (20)-(21);
* Kötter's ``xi = l^(1) + i l^(2)``, ``eta = l^(1) - i l^(2)`` (22), the linear
  map (23)-(24) back to ``(m, n)``, the constants ``d_j`` (25)-(26) of the
  quadrics (11);
* ``H0`` on the quadrics (38)-(40), ``eps`` and ``g`` (41)-(42) (corrected);
* the points ``(z1, y1), (z2, y2)`` of the curve ``y^2 = prod_{j=0}^4 (x - d_j)``
  (8) with ``xi_j = sqrt(c_j) g P_kl``, ``eta_j = sqrt(c_j) g P_j4`` (37).

The state is ordered ``l = (l12, l13, l14, l23, l24, l34)``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core
from ._checks import _finite_result, _float_array, _one_state
from ._checks import _states as _top_states
from .curve import KotterCurve

__all__ = [
    "STATE_RANGE",
    "Kotter",
    "LevelSet",
    "from_kotter",
    "integrals",
    "kotter",
    "lax_pair",
    "quartic",
    "schottky",
]


#: Range of ``max |l_ij|`` accepted by :func:`kotter`. The coefficients of F (19)
#: are quartic in l, so they overflow near 1e77 and underflow (to a spurious
#: self-dual state) near 1e-77; 1e-60 .. 1e60 keeps ~1e17 of headroom either side.
STATE_RANGE = (1e-60, 1e60)


def _check_a(a: Any, what: str = "a") -> np.ndarray:
    """``a`` (or ``b``) as a real, finite float array of shape (4,)."""
    arr = _float_array(a, what)
    if arr.shape != (4,):
        raise ValueError(f"{what} must have shape (4,), got {arr.shape}")
    return np.ascontiguousarray(arr)


def _check_b(b: Any) -> np.ndarray:
    return _check_a(b, "b")


def _states(l: Any) -> tuple[np.ndarray, tuple[int, ...]]:
    """``l`` as real, finite C-contiguous rows of 6 and its leading shape."""
    return _top_states(l, 6)


def integrals(a: Any, l: Any) -> np.ndarray:
    """The integrals ``(h0, h1, h2, h3)`` in the form consistent with (15).

    ``h0 = l12 l34 + l23 l14 + l31 l24`` (6), ``h1 = sum l_jk^2`` (7), and
    ``h2 = sum_{j<k} (a_l + a_m) l_jk^2``, ``h3 = sum_{j<k} a_l a_m l_jk^2``
    with ``{l, m}`` the complement of ``{j, k}`` (the pairs printed in (7),
    ``a_j + a_k`` and ``a_j a_k``, do not give (15); see docs/errata.md).

    Parameters
    ----------
    a : array_like, shape (4,)
        Manakov parameters ``a_i`` (2).
    l : array_like, shape (..., 6)
        States ``(l12, l13, l14, l23, l24, l34)``.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    ValueError
        Wrong shapes, complex or non-finite input, or a result that overflows.

    Examples
    --------
    >>> from manakov.reduction import integrals
    >>> p_a = [0.3, 1.1, 2.0, 3.7]
    >>> print(integrals(p_a, [0.8, -0.3, 0.5, 1.1, -0.7, 0.2]).round(6))
    [ 0.5     2.72   10.878   7.3026]
    """
    a = _check_a(a)
    flat, shape = _states(l)
    return _finite_result(np.asarray(_core.so4_integrals(a, flat))).reshape(shape + (4,))


def schottky(a: Any, l: Any, s: Any, *, sqrt_g: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """Schottky's vectors ``l(s)`` (12) and ``m(s)`` (17).

    ``l_j(s) = sqrt(s_j4) m_j + sqrt(s_kl) n_j``, ``m_j(s) = sqrt(s_kl) m_j + sqrt(s_j4) n_j``,
    ``s_jk = (s - a_j)(s - a_k)``, ``(j, k, l)`` cyclic. Branch: ``sqrt(s_j4)``
    principal and ``sqrt(s_kl) = sqrt_g / sqrt(s_j4)``, so that
    ``sqrt(s_j4) sqrt(s_kl) = sqrt(G(s))`` for every ``j`` (needed for the
    cross term ``2 h0 sqrt(G)`` of (15)).

    Parameters
    ----------
    a : array_like, shape (4,)
    l : array_like, shape (..., 6)
    s : complex array_like, broadcastable with ``l``'s leading axes
    sqrt_g : complex array_like, optional, keyword-only
        The branch of ``sqrt(G(s))``, ``G(s) = prod_j (s - a_j)``; default the
        principal root of ``G(s)``.

    Returns
    -------
    (ndarray, ndarray), each of shape (..., 3), complex

    Raises
    ------
    ValueError
        Wrong shapes, complex or non-finite ``a``, ``l``, non-finite ``s``
        or ``sqrt_g``, ``G(s)`` overflowing, or ``s = a_j``.

    Examples
    --------
    >>> import numpy as np
    >>> from manakov.reduction import schottky
    >>> a = [0.3, 1.1, 2.0, 3.7]
    >>> ls, ms = schottky(a, [0.8, -0.3, 0.5, 1.1, -0.7, 0.2], 5.0)
    >>> ls.shape, ms.shape
    ((3,), (3,))
    """
    a = _check_a(a)
    flat, lshape = _states(l)
    l = flat.reshape(lshape + (6,))
    s, sqrt_g = _s_and_sqrt_g(a, s, sqrt_g)
    shape = np.broadcast_shapes(l.shape[:-1], s.shape, sqrt_g.shape)
    lb = np.ascontiguousarray(np.broadcast_to(l, shape + (6,)).reshape(-1, 6))
    sb = np.ascontiguousarray(np.broadcast_to(s, shape).reshape(-1))
    gb = np.ascontiguousarray(np.broadcast_to(sqrt_g, shape).reshape(-1))
    lv, mv = _core.kotter_schottky(a, lb, sb, gb)
    return np.asarray(lv).reshape(shape + (3,)), np.asarray(mv).reshape(shape + (3,))


def _s_and_sqrt_g(a: np.ndarray, s: Any, sqrt_g: Any) -> tuple[np.ndarray, np.ndarray]:
    """``s`` and the branch of ``sqrt(G(s))`` (default principal), both finite."""
    s = np.asarray(s, dtype=complex)
    if not np.all(np.isfinite(s)):
        raise ValueError("s must be finite; it contains NaN or infinity")
    if sqrt_g is None:
        with np.errstate(over="ignore", invalid="ignore"):
            sqrt_g = np.sqrt(np.prod(s[..., None] - a, axis=-1))
        if not np.all(np.isfinite(sqrt_g)):
            raise ValueError("G(s) = prod_j (s - a_j) overflows (is not finite) for this s")
    return s, np.asarray(sqrt_g, dtype=complex)


def _skew3(v: np.ndarray) -> np.ndarray:
    out = np.zeros(v.shape[:-1] + (3, 3), dtype=v.dtype)
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = v[..., 2], -v[..., 1], v[..., 0]
    return out - np.swapaxes(out, -1, -2)


def lax_pair(
    a: Any, b: Any, l: Any, s: Any, *, sqrt_g: Any = None
) -> tuple[np.ndarray, np.ndarray]:
    """The Lax pair ``L(s)``, ``M_b(s)`` of (16)-(18) for the top ``(a, b)``, corrected.

    ``L = [[0, l3, -l2], [-l3, 0, l1], [l2, -l1, 0]]`` from Schottky's ``l(s)`` (12),
    and ``M_b`` the same antisymmetric matrix built from

    ``m_b(s) = -tau [p2 m(s) + p3 (e2 m(s) + m^[w3](s)) / (e1 - s)]``,

    so that ``dL/dt = [L, M_b]`` (16) along the flow (1)-(2) on either branch of
    ``sqrt(G)``. Here ``b_i = p0 + p1 a_i + p2 a_i^2 + p3 a_i^3`` is the cubic
    interpolant of ``b`` over ``a`` (``p3`` the third divided difference),
    ``m(s)`` is the vector (17), ``m^[X](s)`` the same built from an
    antisymmetric ``X`` instead of ``l`` (``m^[X]_j = sqrt(s_kl) X_kl +
    sqrt(s_j4) X_j4``), ``(w3)_ij = (a_i^2 + a_i a_j + a_j^2) l_ij`` the angular
    velocity of the top with ``b = a^3``, ``e1 = sum a_i``,
    ``e2 = sum_{i<j} a_i a_j``, and
    ``tau = sqrt(s_14) sqrt(s_24) sqrt(s_34) sqrt(G) / ((s - a4) G(s)) = +-1``.
    The printed ``M(s)`` (17)-(18), which does not involve ``b``, is the case
    ``b = a^2`` (``p2 = 1, p3 = 0``) on the branch ``tau = -1``; for a general
    ``b`` it does not give the flow (see docs/errata.md).

    Parameters
    ----------
    a, b : array_like, shape (4,)
        Manakov parameters (2), ``a`` distinct.
    l : array_like, shape (..., 6)
    s : complex array_like, broadcastable with ``l``'s leading axes
    sqrt_g : complex array_like, optional, keyword-only
        The branch of ``sqrt(G(s))`` (default principal); must square to ``G(s)``.

    Returns
    -------
    (ndarray, ndarray), each of shape (..., 3, 3), complex

    Raises
    ------
    ValueError
        Bad shapes or non-finite input, repeated ``a``, ``s = a_j``,
        ``sqrt_g**2 != G(s)``, or ``s = e1`` when ``p3 != 0`` (a pole of ``M_b``).

    Examples
    --------
    >>> import numpy as np
    >>> from manakov.reduction import lax_pair
    >>> a, b = [0.3, 1.1, 2.0, 3.7], [0.5, -0.2, 1.4, 0.9]
    >>> L, M = lax_pair(a, b, [0.8, -0.3, 0.5, 1.1, -0.7, 0.2], 5.0)
    >>> L.shape, bool(np.allclose(L, -L.T))
    ((3, 3), True)
    """
    a = _check_a(a)
    b = _check_b(b)
    flat, lshape = _states(l)
    l = flat.reshape(lshape + (6,))
    s, sqrt_g = _s_and_sqrt_g(a, s, sqrt_g)
    lv, _ = schottky(a, l, s, sqrt_g=sqrt_g)
    shape = lv.shape[:-1]
    lb = np.ascontiguousarray(np.broadcast_to(l, shape + (6,)).reshape(-1, 6))
    sb = np.ascontiguousarray(np.broadcast_to(s, shape).reshape(-1))
    gb = np.ascontiguousarray(np.broadcast_to(sqrt_g, shape).reshape(-1))
    mb = np.asarray(_core.kotter_lax_m(a, b, lb, sb, gb)).reshape(shape + (3,))
    return _skew3(lv), _skew3(mb)


def quartic(a: Any, h: Any) -> np.ndarray:
    """Coefficients of ``F(s)`` (19), monic, highest power first.

    ``F(s) = [(h1 s^2 - h2 s + h3)^2 - 4 h0^2 G(s)] / (h1^2 - 4 h0^2)``,
    ``G(s) = prod_j (s - a_j)``.

    Parameters
    ----------
    a : array_like, shape (4,)
        Manakov parameters ``a_i`` (2).
    h : array_like, shape (..., 4)
        Integrals ``(h0, h1, h2, h3)`` as returned by :func:`integrals`.

    Returns
    -------
    ndarray, shape (..., 5)
        Coefficients of ``s^4, s^3, ..., s^0``.

    Raises
    ------
    ValueError
        If ``h1^2 = 4 h0^2`` (a self-dual or anti-self-dual state): (19) is not
        defined; wrong shapes, complex or non-finite input, or an overflow.

    Examples
    --------
    >>> from manakov.reduction import integrals, quartic
    >>> a = [0.3, 1.1, 2.0, 3.7]
    >>> h = integrals(a, [0.8, -0.3, 0.5, 1.1, -0.7, 0.2])
    >>> print(quartic(a, h).round(6))
    [  1.        -8.13896   22.247285 -22.917349   7.952921]
    """
    a = _check_a(a)
    flat, shape = _top_states(h, 4, "h")
    out = _finite_result(np.asarray(_core.kotter_quartic(a, flat)))
    return out.reshape(shape + (5,))


@dataclass(frozen=True, eq=False)  # fields are arrays: no elementwise __eq__
class Kotter:
    """A state in Schottky-Kötter coordinates (fields carry the paper's names).

    For one state every field has the shape given below; for a batch of states
    with leading shape ``S`` every field gains the leading axes ``S`` (scalars
    become arrays of shape ``S``).

    Array fields are read-only, like the curve's outputs; ``dataclasses.replace``
    works (a writable array passed in is copied and frozen, the caller's array is
    left alone).

    Attributes
    ----------
    h : ndarray (4,)
        ``(h0, h1, h2, h3)`` (6)-(7), complementary-pair ``h2``, ``h3``.
    s : ndarray (4,) complex
        Roots ``s_1 .. s_4`` of ``F`` (19): ``s1`` the non-real root of largest
        imaginary part, ``s2`` the root nearest ``conj(s1)``, ``s3`` the
        remaining one of larger imaginary part (then real part), ``s4`` the
        last; all real: descending.
    sigma : ndarray (4,) complex
        The branch of ``sqrt(G(s_p))`` with ``f(s_p) = 0``:
        ``sigma_p = -(h1 s_p^2 - h2 s_p + h3)/(2 h0)``.
    sqrt_fprime : ndarray (4,) complex
        ``sqrt(F'(s_p))``, principal.
    l_p : ndarray (4, 3) complex
        ``l^(p) = l(s_p)/sqrt(F'(s_p))`` (20); ``l_p[p-1]`` is ``l^(p)``. At
        ``h0 = 0``, where ``F'(s_p) = 0``, (20) is normalised by its limit
        ``sqrt(F'(s_p)/|h0|)`` instead (and ``sqrt_fprime`` is that root): a
        common factor on ``l^(p)``, ``xi``, ``eta``, ``g`` and on ``alpha .. delta``,
        ``Delta``, ``K``, ``A``, ``B``, ``abgd39`` that leaves every relation
        (11)-(42) as it is (each is homogeneous in it); see docs/degenerate.md.
        So is it for ``0 < |h0| < 1e-100 h1``, where the paper's normalisation
        leaves the double range.
    Delta : ndarray (3, 3) complex
        ``Delta[p-1, j-1] = Delta_j^(p)`` (25), corrected (a determinant).
    xi, eta : ndarray (3,) complex
        Kötter's vectors (22).
    sqrt_d, d : ndarray (3,) complex
        ``sqrt(d_j)`` and ``d_j`` (26).
    alpha, beta, gamma, delta : ndarray (3,) complex
        (23): ``m_j = alpha_j xi_j + beta_j eta_j``,
        ``n_j = gamma_j xi_j + delta_j eta_j`` ((24) corrected).
    A, B : ndarray (3,) complex
        (38): on the quadrics (11), ``H0 = sum_j A_j (xi_j^2 - eta_j^2) + B_j xi_j eta_j``
        (the unique representative of that form; holds as printed).
    abgd39 : ndarray (4,) complex
        The constants ``(alpha, beta, gamma, delta)`` of (39):
        ``A_j = alpha + beta d_j + gamma/d_j``, ``B_j = delta (d_j + 1/d_j)``, in closed
        form with ``K``, ``eps`` below, ``kappa`` and ``e1 = d1 + d2 + d3``:
        ``beta = -K/kappa``, ``gamma = eps^2 d4^2 K/kappa``, ``delta = 2 eps d4 K/kappa``,
        ``alpha = K/(2 kappa) (kappa eps^2 + (e1 - d4)(1 - eps^2 d4^2))``.
    eps, K : complex
        (40) corrected: ``H0 = K g^2 (1 - eps P_0)^2`` with
        ``K = kappa sum_j c~_j d_j beta_j delta_j`` and
        ``2 K eps = kappa sum_j c~_j (alpha_j delta_j + beta_j gamma_j)``,
        ``kappa = prod_{m=1}^3 (d_m - d4)``, ``c~_j`` of (33).
    P0 : complex
        ``P_0 = sqrt(z1 z2)`` (27) in the curve's branch, ``eps_0 sqrt(z1) sqrt(z2)``
        of the points.
    g : complex
        The factor of (37); (42) corrected: ``g = sqrt(h0/K) / (1 - eps P_0)``.
    z1, y1, z2, y2 : complex
        The two points of the curve (8), ``y_i^2 = R(z_i)``.
    branch : ndarray (5,) int8
        The signs of the Wurzelfunktionen ``P_0 .. P_4`` (see ``docs/curve.md``).
    curve : KotterCurve or ndarray of KotterCurve
        The curve (8) with these ``d_j``; for a batch an object array of
        shape ``S`` (``None`` entries if ``manakov.KotterCurve`` is unavailable).
    ok : bool or ndarray of bool
        Which states were reduced (all ``True`` unless ``errors="mask"`` was
        passed to :func:`kotter`; the fields of a failed row are NaN and its
        ``curve`` is ``None``).
    a, b : ndarray (4,) or None
        The top the states belong to; :func:`from_kotter` refuses a ``Kotter``
        of another top.
    zd : ndarray (2, 5) complex or None
        The offsets of the points from the branch points,
        ``zd[i-1, j] = z_i - d_j`` (``d_0 = 0``, ``d_4 = d1 d2 d3``), to full
        relative accuracy. A double ``z_i`` fixes ``z_i - d_j`` only to
        ``u |z_i|`` absolutely, which near a branch point is a large relative
        error in the roots ``sqrt(z_i - d_j)`` of (27)-(28) (on the
        ``near_degenerate`` top a point comes within 4e-9 of ``d_1``);
        :func:`from_kotter` uses ``zd`` when it is not ``None``. Set it to
        ``None`` when replacing ``z1`` or ``z2``.

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> k = manakov.kotter(p.a, p.b, p.l0)
    >>> print(k.h.round(6))
    [ 0.5     2.72   10.878   7.3026]
    >>> print(round(k.z1.real, 6), round(k.z2.real, 6))
    -2.087489 0.002384
    """

    h: np.ndarray
    s: np.ndarray
    sigma: np.ndarray
    sqrt_fprime: np.ndarray
    l_p: np.ndarray
    Delta: np.ndarray
    xi: np.ndarray
    eta: np.ndarray
    sqrt_d: np.ndarray
    d: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray
    delta: np.ndarray
    A: np.ndarray
    B: np.ndarray
    abgd39: np.ndarray
    eps: Any
    K: Any
    P0: Any
    g: Any
    z1: Any
    y1: Any
    z2: Any
    y2: Any
    branch: np.ndarray
    curve: Any
    zd: Any = None
    ok: Any = True
    a: Any = None
    b: Any = None

    def __post_init__(self) -> None:
        # Read-only like the curve's outputs: a Kotter describes one level set and
        # its points, and editing one field in place would silently desynchronise it
        # from the others. Arrays passed in writable (dataclasses.replace) are
        # copied first, so the caller's array is neither frozen nor aliased.
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray) and v.flags.writeable:
                v = np.array(v, copy=True)
                v.setflags(write=False)
                object.__setattr__(self, f.name, v)


_FIELD_SHAPES = {
    "h": (4,),
    "s": (4,),
    "sigma": (4,),
    "sqrt_fprime": (4,),
    "l_p": (4, 3),
    "Delta": (3, 3),
    "xi": (3,),
    "eta": (3,),
    "sqrt_d": (3,),
    "d": (3,),
    "alpha": (3,),
    "beta": (3,),
    "gamma": (3,),
    "delta": (3,),
    "A": (3,),
    "B": (3,),
    "abgd39": (4,),
    "eps": (),
    "K": (),
    "P0": (),
    "g": (),
    "z1": (),
    "y1": (),
    "z2": (),
    "y2": (),
    "branch": (5,),
    "zd": (2, 5),
    "ok": (),
}


def _make_curve(d: np.ndarray) -> Any:
    if not np.all(np.isfinite(d)):
        return None  # a row that failed with errors="mask"
    return KotterCurve(complex(d[0]), complex(d[1]), complex(d[2]))


def _check_range(flat: np.ndarray) -> None:
    size = np.max(np.abs(flat), axis=1, initial=0.0)
    bad = (size > 0) & ((size < STATE_RANGE[0]) | (size > STATE_RANGE[1]))
    if np.any(bad):
        raise ValueError(
            f"l has max |l_ij| = {size[bad][0]:e}, outside [{STATE_RANGE[0]:e}, "
            f"{STATE_RANGE[1]:e}] where the integrals (~|l|^2) and the coefficients of "
            "F (19) (~|l|^4) neither overflow nor underflow: rescale l"
        )


def _errors_mask(errors: str) -> bool:
    if errors not in ("raise", "mask"):
        raise ValueError(f'errors must be "raise" or "mask", got {errors!r}')
    return errors == "mask"


# The core normalises (20) by sqrt(F'(s_p)/|h0|), finite at h0 = 0 where
# F'(s_p) = 0 (docs/degenerate.md); the fields are reported in the paper's
# normalisation sqrt(F'(s_p)) wherever |h0| >= _PAPER_H0_MIN h1: each field is
# multiplied by sqrt(|h0|) to this power (the relations (11)-(42) are homogeneous
# in it). Below that the paper's normalisation leaves the double range (Delta
# ~ 1/h0, K ~ h0^2), and the limit normalisation is reported, as at h0 = 0.
_PAPER_H0_MIN = 1e-100
_PAPER_POWER = {
    "sqrt_fprime": 1,
    "l_p": -1,
    "xi": -1,
    "eta": -1,
    "Delta": -2,
    "alpha": 1,
    "beta": 1,
    "gamma": 1,
    "delta": 1,
    "A": 2,
    "B": 2,
    "abgd39": 2,
    "K": 2,
    "g": -1,
}


def _build(
    a: np.ndarray, b: np.ndarray, flat: np.ndarray, shape: tuple[int, ...], raw: Any
) -> Kotter:
    fields: dict[str, Any] = {}
    h = np.asarray(raw["h"]).reshape(shape + (4,))
    h0 = np.abs(h[..., 0])
    paper = np.isfinite(h0) & (h0 >= _PAPER_H0_MIN * h[..., 1]) & (h0 > 0)
    w = np.where(paper, np.sqrt(np.where(paper, h0, 1.0)), 1.0)
    for name, fshape in _FIELD_SHAPES.items():
        arr = np.asarray(raw[name]).reshape(shape + fshape)
        if name in _PAPER_POWER:
            arr = arr * (w ** _PAPER_POWER[name]).reshape(w.shape + (1,) * len(fshape))
        if arr.ndim == 0:
            arr = arr[()]
        else:
            arr.setflags(write=False)  # fresh from the core: frozen without a copy
        fields[name] = arr
    d_all = np.asarray(raw["d"])
    curves = [_make_curve(dd) for dd in d_all]
    if shape == ():
        fields["curve"] = curves[0]
    else:
        carr = np.empty(len(curves), dtype=object)
        carr[:] = curves
        carr = carr.reshape(shape)
        carr.setflags(write=False)
        fields["curve"] = carr
    fields["a"] = a.copy()
    fields["b"] = b.copy()
    if shape == ():
        fields["ok"] = bool(fields["ok"])
    return Kotter(**fields)


def kotter(a: Any, b: Any, l: Any, *, errors: str = "raise") -> Kotter:
    """Schottky-Kötter coordinates of states ``l`` of the top ``(a, b)``.

    Computes (12)-(26), (38)-(42) and the points of the curve (37) for each
    state; see :class:`Kotter` for the fields and ``docs/kotter.md`` for every
    convention. Only ``a`` and the state enter: ``b`` (checked, and recorded
    in the result with ``a``) fixes the time evolution, not the reduction.

    For one-off use: each state gets the constants of its own level set, with
    the branch choices documented in docs/kotter.md (roots of F ordered as in
    :class:`Kotter`, principal ``sqrt(F'(s_p))``, ``sqrt(c_j)`` and
    ``sqrt(h0/K)``). Along a trajectory these choices can flip between samples
    (the divisor then jumps to its hyperelliptic-involution image); use
    :class:`LevelSet` there, which fixes them once per level set.

    Parameters
    ----------
    a, b : array_like, shape (4,)
        Manakov parameters (2), ``a`` distinct.
    l : array_like, shape (..., 6)
        States ``(l12, l13, l14, l23, l24, l34)``.
    errors : {"raise", "mask"}, keyword-only
        ``"raise"`` (default): the first state that cannot be reduced raises,
        with its row index (in the flattened batch) in the message. ``"mask"``:
        such rows get NaN fields, ``curve`` ``None`` and ``Kotter.ok`` false.

    Returns
    -------
    Kotter

    Raises
    ------
    ValueError
        Non-finite input; ``max |l_ij|`` outside :data:`STATE_RANGE` (rescale
        l); repeated ``a_i``; ``h1^2 = 4 h0^2`` (``F`` (19) undefined), which
        includes every state with ``(h1^2 - 4 h0^2)/h1^2 <= 1e-12``; ``h0 = 0``
        with the double roots of ``F`` (the roots of ``h1 s^2 - h2 s + h3``)
        coinciding or at an ``a_j`` (an equilibrium, an so(3) block, a
        separatrix; other rank-2 states reduce, docs/degenerate.md); repeated
        roots of ``F``; a root of ``F`` at some ``a_j``; coinciding branch points ``d_j`` of
        the curve (its genus drops); ``z1 = z2``; ``1 - eps P_0 = 0``. States
        with ``1e-12 < (h1^2 - 4 h0^2)/h1^2 < 1e-10`` usually reduce but may
        raise, naming that distance; every state farther from the singular
        set reduces (docs/kotter.md, "Near the singular set").

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> k = manakov.kotter(p.a, p.b, p.l0)
    >>> print(k.d.real.round(6))  # d_1, d_2, d_3 of (26): real for this state
    [  3.196708  -1.854681 -14.10493 ]
    """
    a = _check_a(a)
    b = _check_b(b)
    mask = _errors_mask(errors)
    flat, shape = _states(l)
    _check_range(flat)
    raw = _core.kotter_batch(a, flat, None, mask)
    return _build(a, b, flat, shape, raw)


class LevelSet:
    """One level set of the top ``(a, b)``: Kötter's constants fixed once, from ``l0``.

    The constants of the reduction (the roots ``s_p`` of F (19) and their
    order, ``sigma_p``, ``sqrt(F'(s_p))``, ``d_j`` (26), ``alpha_j .. delta_j``
    (24), ``K``, ``eps`` (40)-(41)) depend only on ``a`` and the integrals, so
    they belong to the level set, not to the state. :func:`kotter` recomputes
    them (and makes its branch choices) state by state; on curves whose
    ``c_j`` are negative reals carrying a rounding-noise imaginary part, those
    choices flip between neighbouring samples of a trajectory and the divisor
    jumps to its hyperelliptic-involution image. ``LevelSet.kotter`` computes
    them once from ``l0`` and maps every state with the same ones: ``xi, eta``
    (22) are then linear in ``l`` and ``g = sqrt(h0/K)/(1 - eps P_0)`` (42)
    a fixed branch, so the divisor moves continuously along a trajectory.

    Parameters
    ----------
    a, b : array_like, shape (4,)
        Manakov parameters (2), ``a`` distinct.
    l0 : array_like, shape (6,)
        A state on the level set (its integrals ``h`` fix it).

    Raises
    ------
    ValueError
        As :func:`kotter` for ``l0``.

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> ls = manakov.LevelSet(p.a, p.b, p.l0)
    >>> k = ls.kotter(p.l0)
    >>> bool(abs(k.z1 - k.z2) > 0)
    True
    """

    def __init__(self, a: Any, b: Any, l0: Any) -> None:
        self._a = _check_a(a)
        self._b = _check_b(b)
        one = _one_state(l0, 6, "l0", "LevelSet", "LevelSet(a, b, l0).kotter(l) for states on it")
        flat = one[None]
        _check_range(flat)
        self._l0 = flat[0].copy()
        self._l0.setflags(write=False)
        # the constants once (also validates l0); kept as the Kotter of l0
        self._k0 = _build(
            self._a, self._b, flat[0], (), _core.kotter_batch(self._a, flat, self._l0, False)
        )

    @property
    def a(self) -> np.ndarray:
        """The top's ``a``."""
        return self._a.copy()

    @property
    def b(self) -> np.ndarray:
        """The top's ``b``."""
        return self._b.copy()

    @property
    def l0(self) -> np.ndarray:
        """The state that fixed the constants (read-only)."""
        return self._l0

    @property
    def h(self) -> np.ndarray:
        """The integrals ``(h0, h1, h2, h3)`` of the level set."""
        return np.asarray(self._k0.h)

    @property
    def d(self) -> np.ndarray:
        """The branch points ``d_1, d_2, d_3`` (26) of the level set's curve (8)."""
        return np.asarray(self._k0.d)

    @property
    def curve(self) -> KotterCurve:
        """The level set's curve (8)."""
        c: KotterCurve = self._k0.curve
        return c

    def kotter(self, l: Any, *, errors: str = "raise") -> Kotter:
        """Kötter coordinates of states ``l`` on this level set, with its fixed constants.

        Same fields as :func:`manakov.kotter`; every constant field equals that
        of ``l0``. For a batch, the rows are taken as consecutive samples (of a
        trajectory, in time order): each row's pair of points is ordered to
        follow the previous successful row (the pair is unordered; ``xi, eta``,
        ``g`` and ``branch`` do not depend on the order).

        Parameters
        ----------
        l : array_like, shape (..., 6)
            States on the level set.
        errors : {"raise", "mask"}, keyword-only
            ``"raise"``: the first failing row raises (its index in the
            message); ``"mask"``: failing rows are NaN and ``Kotter.ok`` false.

        Raises
        ------
        ValueError
            A state not on the level set (integrals differing by more than
            1e-6 relative), or as :func:`manakov.kotter`.
        """
        mask = _errors_mask(errors)
        flat, shape = _states(l)
        _check_range(flat)
        raw = _core.kotter_batch(self._a, flat, self._l0, mask)
        return _build(self._a, self._b, flat, shape, raw)

    def __repr__(self) -> str:
        return f"LevelSet(a={self._a.tolist()}, b={self._b.tolist()}, l0={self._l0.tolist()})"


def from_kotter(a: Any, b: Any, k: Kotter) -> np.ndarray:
    """The state ``l`` from Kötter coordinates: the inverse of :func:`kotter`.

    Uses only the curve's points (with their offsets ``zd`` from the branch
    points when ``k.zd`` is not ``None``), ``g`` and the branch of the ``P_j``
    (with the level set's constants ``d_j`` and ``alpha_j .. delta_j``):
    ``xi_j = sqrt(c_j) g P_kl``, ``eta_j = sqrt(c_j) g P_j4`` (37), then (23)
    ``m_j = alpha_j xi_j + beta_j eta_j``, ``n_j = gamma_j xi_j + delta_j eta_j``.

    Parameters
    ----------
    a, b : array_like, shape (4,)
        Manakov parameters (2) (checked; the map uses the constants stored in ``k``).
    k : Kotter
        As returned by :func:`kotter`, possibly with other points, ``g`` or branch.

    Returns
    -------
    ndarray, shape (..., 6)

    Raises
    ------
    ValueError
        Points off the curve, offsets ``zd`` inconsistent with ``z1, z2``,
        ``z1 = z2``, ``g = 0``, a bad branch, or data that give a complex state.
    TypeError
        ``k`` is not a :class:`Kotter`.

    Examples
    --------
    >>> import numpy as np, manakov
    >>> p = manakov.problem("generic")
    >>> back = manakov.from_kotter(p.a, p.b, manakov.kotter(p.a, p.b, p.l0))
    >>> bool(np.abs(back - p.l0).max() < 1e-12)
    True
    """
    a = _check_a(a)
    b = _check_b(b)
    if not isinstance(k, Kotter):
        raise TypeError(f"k must be a manakov.Kotter, got {type(k).__name__}")
    for name, mine, theirs in (("a", a, k.a), ("b", b, k.b)):
        if theirs is not None and not np.array_equal(np.asarray(theirs, dtype=float), mine):
            raise ValueError(
                f"k comes from another top: its {name} = {np.asarray(theirs).tolist()}, "
                f"this top's {name} = {mine.tolist()}"
            )
    if not np.all(np.asarray(k.ok)):
        raise ValueError("k has rows that failed (Kotter.ok is False): nothing to invert there")
    if np.any(np.asarray(k.g) == 0):
        raise ValueError("g = 0: g = 1/(1 - eps P_0) (42) never vanishes")
    z1 = np.asarray(k.z1, dtype=complex)
    shape = z1.shape

    def c2(x: Any) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(x, dtype=complex).reshape(-1, 3))

    def c1(x: Any) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(x, dtype=complex).reshape(-1))

    br = np.ascontiguousarray(np.asarray(k.branch, dtype=np.int8).reshape(-1, 5))
    zd = None
    if k.zd is not None:
        zd = np.asarray(k.zd, dtype=complex)
        if zd.shape != shape + (2, 5):
            raise ValueError(f"k.zd must have shape {shape + (2, 5)}, got {zd.shape}")
        zd = np.ascontiguousarray(zd.reshape(-1, 2, 5))
    out = _core.kotter_from_points(
        c2(k.alpha),
        c2(k.beta),
        c2(k.gamma),
        c2(k.delta),
        c2(k.d),
        c1(k.z1),
        c1(k.y1),
        c1(k.z2),
        c1(k.y2),
        c1(k.g),
        br,
        zd,
    )
    return np.asarray(out).reshape(shape + (6,))
