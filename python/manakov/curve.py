"""The genus-2 curve (8) and Weierstrass' Wurzelfunktionen (27)-(28).

The curve of the paper is

.. math::
    y^2 = R(x) = \\prod_{j=0}^{4} (x - d_j), \\qquad d_0 = 0, \\quad d_4 = d_1 d_2 d_3 \\quad (8)

with complex branch points in general. A point of the curve is a pair
``(z, y)`` with ``y**2 == R(z)``: the point carries its ``y`` (its sheet).

Square-root conventions (all of them; see ``docs/curve.md``)
------------------------------------------------------------
* ``sqrt`` is the principal square root, ``-pi/2 < arg sqrt(w) <= pi/2``; a
  negative real ``w`` gives ``+1j*sqrt(-w)`` whatever the sign of the zero
  imaginary part.
* Canonical roots of a point ``(z, y)``: ``r_j(z) = sqrt(z - d_j)`` for
  ``j = 0..3`` and ``r_4(z) = +-sqrt(z - d_4)``, the sign making
  ``prod_j r_j(z) == y``.
* Canonical sheet: ``KotterCurve.y(x) = prod_j sqrt(x - d_j)``; the other sheet
  is ``-y(x)``.
* Wurzelfunktionen (27) in the branch ``eps`` (five signs, product ``+1``,
  default all ``+1``): ``P_j = eps_j r_j(z1) r_j(z2)``, so that
  ``P_j**2 = (z1 - d_j)(z2 - d_j)`` and ``P_0 P_1 P_2 P_3 P_4 = y1 y2``.
  The 16 admissible ``eps`` are all sign choices compatible with that product;
  the canonical choice jumps where a point crosses a cut
  ``z in d_j + (-inf, 0]``, and a continuous choice along a trajectory is
  carried by ``eps`` (``points_from_wurzel`` returns it).
* (28) fixes the ``P_jk`` from the ``P_j`` and ``sqrt(R(z_i)) = y_i``.

Offsets ``zd``
--------------
A double ``z`` fixes ``z - d_j`` only to an absolute ``u |z|`` (``u`` the unit
roundoff), so a point very close to a branch point loses relative accuracy in
``sqrt(z - d_j)`` and hence in (27)-(28). :meth:`KotterCurve.points_from_wurzel`
therefore also returns the offsets ``zd[..., i-1, j] = z_i - d_j`` (``j = 0..4``)
to full relative accuracy, and :meth:`KotterCurve.wurzel` and
:meth:`KotterCurve.xi_eta` accept them (``zd=``) and take the roots from them.
Offsets must agree with ``z - d_j`` to rounding (else ``ValueError``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core
from ._checks import _finite_result

__all__ = ["CurvePoints", "KotterCurve", "Wurzel", "INVERSE_RTOL"]

#: Default relative tolerance of the consistency check of
#: :meth:`KotterCurve.points_from_wurzel`: the recovered points must reproduce
#: ``(xi, eta)`` to ``rtol * max|(xi, eta)|``. Exact data come back to ~1e-14;
#: 1e-8 admits data computed elsewhere and rejects data off Kötter's quadrics (11).
INVERSE_RTOL = 1e-8


def _c(x: Any) -> np.ndarray:
    return np.asarray(x, dtype=np.complex128)


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


def _scalar_or(a: np.ndarray, scalar: bool) -> Any:
    return a[()] if scalar else _frozen(a)


def _finite(values: np.ndarray) -> np.ndarray:
    return _finite_result(values, "this x: |x| is too large")


#: Why a curve's constant or a point evaluation is not representable.
_RANGE = (
    "this curve or these points: the value does not fit in a double (the curve's "
    "scale, with d_4 = d1 d2 d3 and products of up to five differences z - d_j, must "
    "keep every such product between ~1e-308 and ~1e308)"
)


def _in_range(values: np.ndarray) -> np.ndarray:
    return _finite_result(np.asarray(values), _RANGE)


def _zd_rows(zd: Any, shape: tuple[int, ...]) -> np.ndarray | None:
    """Offsets of shape (..., 2, 5) broadcast to ``shape`` and flattened to rows of 10."""
    if zd is None:
        return None
    z = _c(zd)
    if z.shape[-2:] != (2, 5):
        raise ValueError(f"zd must have trailing shape (2, 5), got {z.shape}")
    z = np.broadcast_to(z, (*shape, 2, 5))
    return np.ascontiguousarray(z.reshape(-1, 10))


def _eps_rows(eps: Any, shape: tuple[int, ...]) -> np.ndarray | None:
    if eps is None:
        return None
    e = np.asarray(eps)
    if e.shape[-1:] != (5,):
        raise ValueError(f"eps must have last axis of length 5, got shape {e.shape}")
    if not np.all((e == 1) | (e == -1)):
        raise ValueError("eps entries must be +1 or -1")
    e = np.broadcast_to(e, (*shape, 5))
    return np.ascontiguousarray(e.reshape(-1, 5), dtype=np.int8)


def _point_rows(
    values: tuple[Any, ...], eps: Any, zd: Any
) -> tuple[tuple[int, ...], list[np.ndarray], np.ndarray | None, np.ndarray | None]:
    """Broadcast point data with ``eps`` (..., 5) and ``zd`` (..., 2, 5); flatten to rows.

    Returns the common leading shape, the flattened complex ``values``, and the
    rows of ``eps`` and ``zd`` (``None`` where not given).
    """
    arrs = np.broadcast_arrays(*(_c(v) for v in values))
    shape = arrs[0].shape
    if eps is not None:
        shape = np.broadcast_shapes(shape, np.shape(eps)[:-1])
    if zd is not None:
        shape = np.broadcast_shapes(shape, np.shape(zd)[:-2])
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape).reshape(-1)) for a in arrs]
    return shape, flat, _eps_rows(eps, shape), _zd_rows(zd, shape)


@dataclass(frozen=True)
class Wurzel:
    """The Wurzelfunktionen of point pairs, (27)-(28).

    Attributes
    ----------
    P : ndarray, complex, shape (..., 5)
        ``P_j = eps_j sqrt((z1 - d_j)(z2 - d_j))`` (27), ``j = 0..4``, with
        ``prod_j P_j = y1 y2``.
    Pjk : ndarray, complex, shape (..., 5, 5)
        ``P_jk = P_j P_k/(z1 - z2) (y1/((z1 - d_j)(z1 - d_k)) - y2/((z2 - d_j)(z2 - d_k)))``
        (28); symmetric, zero diagonal.

    Examples
    --------
    >>> import manakov
    >>> curve = manakov.KotterCurve(1.0 + 0.5j, 2.0 - 0.3j, -1.5 + 0.2j)
    >>> z1, z2 = 0.3 + 0.2j, -1.0 + 0.7j
    >>> w = curve.wurzel(z1, curve.y(z1), z2, curve.y(z2, sheet=-1))
    >>> w.P.shape, w.Pjk.shape
    ((5,), (5, 5))
    """

    P: np.ndarray
    Pjk: np.ndarray


@dataclass(frozen=True)
class CurvePoints:
    """Points of the curve, factor ``g`` and branch ``eps`` recovered from (37).

    Attributes
    ----------
    z1, y1, z2, y2 : complex or ndarray
        The two points; ``z1`` is the root of ``x**2 - (z1+z2) x + z1 z2`` of
        larger modulus (the pair is unordered: (27)-(28) are symmetric).
    g : complex or ndarray
        The factor of (37): ``xi_j = sqrt(c_j) g P_kl``, ``eta_j = sqrt(c_j) g P_j4``.
    eps : ndarray of int8, shape (..., 5)
        The branch of the Wurzelfunktionen (product +1, normalised to
        ``eps[..., 4] == 1``): ``curve.wurzel(z1, y1, z2, y2, eps=eps)``
        reproduces the data.
    residual : float or ndarray
        ``max |(xi, eta) - (xi, eta)(z1, y1, z2, y2, g, eps)|``.
    zd : ndarray, complex, shape (..., 2, 5)
        The offsets ``zd[..., i-1, j] = z_i - d_j`` (``j = 0..4``, ``d_0 = 0``,
        ``d_4 = d1 d2 d3``) to full relative accuracy (the polish works in the
        offset from the nearest branch point). Pass them on as
        ``curve.xi_eta(..., zd=pts.zd)`` or ``curve.wurzel(..., zd=pts.zd)`` to keep
        that accuracy for points close to a branch point, where the bare ``z_i``
        fix ``z_i - d_j`` only to ``u |z_i|``.

    Examples
    --------
    >>> import manakov
    >>> curve = manakov.KotterCurve(1.0 + 0.5j, 2.0 - 0.3j, -1.5 + 0.2j)
    >>> z1, z2 = 0.3 + 0.2j, -1.0 + 0.7j
    >>> y1, y2 = curve.y(z1), curve.y(z2, sheet=-1)
    >>> xi, eta = curve.xi_eta(z1, y1, z2, y2, 1.2)
    >>> pts = curve.points_from_wurzel(xi, eta, g_ref=1.2)
    >>> print(sorted([round(complex(pts.z1).real, 9), round(complex(pts.z2).real, 9)]))
    [-1.0, 0.3]
    """

    z1: Any
    y1: Any
    z2: Any
    y2: Any
    g: Any
    eps: np.ndarray
    residual: Any
    zd: np.ndarray


class KotterCurve:
    """The genus-2 curve (8) ``y**2 = R(x) = prod_{j=0}^4 (x - d_j)``.

    Parameters
    ----------
    d1, d2, d3 : complex
        Branch points; ``d_0 = 0`` and ``d_4 = d1 d2 d3`` (8).

    Raises
    ------
    ValueError
        If a ``d_j`` is not finite, or two of ``d_0 .. d_4`` coincide (the
        genus drops; ``d_j = 0`` coincides with ``d_0``, ``d_k d_l = 1`` makes
        ``d_4 = d_j``). The message names the pair.

    Notes
    -----
    The identities (29)-(33) of the paper, with
    ``c~_j = 1/((d_j - d_k)(d_j - d_l))``, ``c_j = (d_j - d_4) c~_j`` (33),
    ``(j, k, l)`` cyclic in ``(1, 2, 3)``, hold for :meth:`wurzel` in every
    branch ``eps``, except that the right-hand side of (29) carries the factor
    :attr:`kappa` ``= prod_{m=1}^3 (d_m - d_4)`` (see ``docs/errata.md``).

    Examples
    --------
    >>> import numpy as np, manakov
    >>> curve = manakov.KotterCurve(1.0 + 0.5j, 2.0 - 0.3j, -1.5 + 0.2j)
    >>> print(np.round(curve.branch_points, 6))
    [ 0.   +0.j    1.   +0.5j   2.   -0.3j  -1.5  +0.2j  -3.365-0.62j]
    >>> z = 0.3 + 0.2j
    >>> bool(abs(curve.y(z) ** 2 - curve.R(z)) < 1e-14)
    True
    """

    __slots__ = ("_d", "_c", "_ct", "_kappa", "_surface")

    def __init__(self, d1: complex, d2: complex, d3: complex) -> None:
        d = _c([d1, d2, d3])
        if d.shape != (3,):
            raise ValueError("d1, d2, d3 must be scalars")
        self._d = _frozen(_core.curve_branch_points(d))
        c, ct, kappa = _core.curve_constants(d)
        self._c = _frozen(c)
        self._ct = _frozen(ct)
        self._kappa = complex(kappa[0])
        self._surface: Any = None

    def _d123(self) -> np.ndarray:
        return np.ascontiguousarray(self._d[1:4])

    @property
    def branch_points(self) -> np.ndarray:
        """``(d_0, d_1, d_2, d_3, d_4) = (0, d1, d2, d3, d1 d2 d3)``, read-only."""
        return self._d

    @property
    def d(self) -> tuple[complex, complex, complex]:
        """``(d1, d2, d3)``."""
        return (complex(self._d[1]), complex(self._d[2]), complex(self._d[3]))

    @property
    def c(self) -> np.ndarray:
        """``c_j = (d_j - d_4)/((d_j - d_k)(d_j - d_l))`` (33), ``j = 1, 2, 3``.

        The curve's constants, not the top's ``c_ij`` of (2). Raises
        ``ValueError`` when a value does not fit in a double.
        """
        return _in_range(self._c)

    @property
    def c_tilde(self) -> np.ndarray:
        """``c~_j = 1/((d_j - d_k)(d_j - d_l))`` (33), ``j = 1, 2, 3``.

        Raises ``ValueError`` when a value does not fit in a double (it is
        evaluated as ``1/(d_j - d_k) * 1/(d_j - d_l)``, so ``|d| ~ 1e-100`` is fine).
        """
        return _in_range(self._ct)

    @property
    def kappa(self) -> complex:
        """``kappa = prod_{m=1}^3 (d_m - d_4) = -R'(d_4)/d_4``, the factor of (29) corrected.

        Raises ``ValueError`` when it does not fit in a double (``|kappa| ~ |d_4|^3``
        overflows once ``|d1 d2 d3|`` passes ~1e102).
        """
        return complex(_in_range(np.asarray(self._kappa)))

    @property
    def surface(self) -> Any:
        """The curve (8) as a :class:`manakov.HyperellipticCurve` (built once).

        Its branch points are ``(d_0, .., d_4)`` in this order, so
        ``surface.branch_char(j)`` is ``eta(d_j)``; the base point of its Abel
        map is ``infinity``.
        """
        if self._surface is None:
            # Imported here: riemann sits above curve in the import graph.
            from .riemann import HyperellipticCurve

            self._surface = HyperellipticCurve(self._d)
        return self._surface

    def __repr__(self) -> str:
        d1, d2, d3 = self.d
        return f"KotterCurve(d1={d1!r}, d2={d2!r}, d3={d3!r})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, KotterCurve):
            return NotImplemented
        return bool(np.array_equal(self._d, other._d))

    def __hash__(self) -> int:
        return hash(self.d)

    def R(self, x: Any) -> Any:
        """``R(x) = prod_{j=0}^4 (x - d_j)`` (8), elementwise; scalar in, scalar out.

        Parameters
        ----------
        x : complex or array_like

        Returns
        -------
        complex or ndarray, complex, shape of ``x``

        Raises
        ------
        ValueError
            Non-finite ``x``, or ``R(x)`` overflows.
        """
        xa = _c(x)
        r, _ = _core.curve_eval(self._d123(), xa.reshape(-1))
        return _scalar_or(_finite(r).reshape(xa.shape), xa.ndim == 0)

    def y(self, x: Any, *, sheet: int = 1) -> Any:
        """A square root of ``R(x)``: ``sheet * prod_{j=0}^4 sqrt(x - d_j)``.

        Parameters
        ----------
        x : complex or array_like
        sheet : {1, -1}, keyword-only
            ``+1`` is the canonical sheet (product of principal roots), ``-1`` the other.

        Returns
        -------
        complex or ndarray, complex, shape of ``x``

        Raises
        ------
        ValueError
            Non-finite ``x``, ``sheet`` not +-1, or ``y(x)`` overflows.
        """
        if sheet not in (1, -1):
            raise ValueError(f"sheet must be +1 or -1, got {sheet!r}")
        xa = _c(x)
        _, y = _core.curve_eval(self._d123(), xa.reshape(-1))
        return _scalar_or(sheet * _finite(y).reshape(xa.shape), xa.ndim == 0)

    def wurzel(
        self, z1: Any, y1: Any, z2: Any, y2: Any, *, eps: Any = None, zd: Any = None
    ) -> Wurzel:
        """Weierstrass' Wurzelfunktionen (27)-(28) of the point pairs ``(z1, y1), (z2, y2)``.

        .. math::
            P_j = \\epsilon_j \\sqrt{(z_1 - d_j)(z_2 - d_j)} \\quad (27), \\qquad
            P_{jk} = \\frac{P_j P_k}{z_1 - z_2}\\left(\\frac{y_1}{(z_1-d_j)(z_1-d_k)}
                   - \\frac{y_2}{(z_2-d_j)(z_2-d_k)}\\right) \\quad (28)

        with ``sqrt(R(z_i)) = y_i`` and ``P_j = eps_j r_j(z1) r_j(z2)`` (canonical
        roots, see the module docstring), so that ``prod_j P_j = y1 y2``. (28) is
        evaluated in the equivalent division-free form
        ``P_jk = eps_j eps_k (r_j(z2) r_k(z2) rho_jk(z1) - r_j(z1) r_k(z1) rho_jk(z2))/(z1 - z2)``,
        ``rho_jk = prod_{m not in {j, k}} r_m``, which is finite at branch points.

        Parameters
        ----------
        z1, y1, z2, y2 : complex or array_like
            Points of the curve; broadcast together.
        eps : array_like of {+1, -1}, shape (..., 5), optional, keyword-only
            Branch of the ``P_j`` (product must be +1); default all +1.
        zd : array_like, complex, shape (..., 2, 5), optional, keyword-only
            Offsets ``zd[..., i-1, j] = z_i - d_j`` (e.g. ``CurvePoints.zd``); the
            roots ``sqrt(z_i - d_j)`` are taken from them (full accuracy near
            branch points). Default: formed from ``z1, z2``.

        Returns
        -------
        Wurzel
            ``P`` of shape ``(..., 5)``, ``Pjk`` of shape ``(..., 5, 5)``.

        Raises
        ------
        ValueError
            Non-finite input, a point off the curve (``|y**2 - R(z)|`` above
            1e-8 of the size of the terms of ``R``), ``z1 == z2`` where (28)
            divides by zero (the same ``z`` on different sheets or at a branch
            point; the same point twice is the tangent limit), an invalid ``eps``,
            offsets ``zd`` of the wrong shape or inconsistent with ``z1, z2``, or a
            result outside the double range.
        """
        shape, (z1f, y1f, z2f, y2f), e, zr = _point_rows((z1, y1, z2, y2), eps, zd)
        p, pjk = _core.curve_wurzel(self._d123(), z1f, y1f, z2f, y2f, e, zr)
        p, pjk = _in_range(p), _in_range(pjk)
        return Wurzel(P=_frozen(p.reshape(*shape, 5)), Pjk=_frozen(pjk.reshape(*shape, 5, 5)))

    def xi_eta(
        self,
        z1: Any,
        y1: Any,
        z2: Any,
        y2: Any,
        g: Any,
        *,
        eps: Any = None,
        sqrt_c: Any = None,
        zd: Any = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Kötter's vectors from points of the curve, (37).

        .. math:: \\xi_j = \\sqrt{c_j}\\, g\\, P_{kl}, \\qquad \\eta_j = \\sqrt{c_j}\\, g\\, P_{j4}

        with ``(j, k, l)`` cyclic in ``(1, 2, 3)`` and ``c_j`` of (33).

        Parameters
        ----------
        z1, y1, z2, y2, g : complex or array_like
            Points and factor, broadcast together.
        eps : array_like, shape (..., 5), optional, keyword-only
            Branch of the Wurzelfunktionen, as in :meth:`wurzel`.
        sqrt_c : array_like, shape (3,), optional, keyword-only
            The square roots of ``c_j`` to use; default the principal roots.
        zd : array_like, complex, shape (..., 2, 5), optional, keyword-only
            Offsets ``z_i - d_j`` as in :meth:`wurzel` (e.g. ``CurvePoints.zd``).

        Returns
        -------
        xi, eta : ndarray, complex, shape (..., 3)

        Raises
        ------
        ValueError
            As :meth:`wurzel`, and a non-finite ``g`` or an invalid ``sqrt_c``;
            a result outside the double range (the curve's scale; see ``c``).
        """
        shape, (z1f, y1f, z2f, y2f, gf), e, zr = _point_rows((z1, y1, z2, y2, g), eps, zd)
        sc = None if sqrt_c is None else np.ascontiguousarray(_c(sqrt_c).reshape(-1))
        xi, eta = _core.curve_xi_eta(self._d123(), z1f, y1f, z2f, y2f, gf, e, sc, zr)
        xi, eta = _in_range(xi), _in_range(eta)
        return _frozen(xi.reshape(*shape, 3)), _frozen(eta.reshape(*shape, 3))

    def points_from_wurzel(
        self,
        xi: Any,
        eta: Any,
        *,
        sqrt_c: Any = None,
        g_ref: Any = None,
        rtol: float = INVERSE_RTOL,
    ) -> CurvePoints:
        """Invert (37): points ``(z1, y1), (z2, y2)``, ``g`` and branch ``eps`` from ``xi, eta``.

        Given ``xi_j = sqrt(c_j) g P_kl`` and ``eta_j = sqrt(c_j) g P_j4``
        (``j = 1, 2, 3``, ``(j, k, l)`` cyclic), put ``X_j = xi_j/sqrt(c_j)``,
        ``Y_j = eta_j/sqrt(c_j)``. Then

        * ``g**2 = sum_j c~_j Y_j**2 / d_4``  (from (30a): ``sum c~_j P_j4**2 = d_4``),
        * ``z1 + z2 = d_4 + sum_j c~_j X_j**2 / g**2``,
          ``z1 z2 = sum_j c~_j d_j X_j**2 / g**2``  ((30b), ``P_0**2 = z1 z2``),

        so ``z1, z2`` are the roots of ``x**2 - (z1 + z2) x + z1 z2``;
        ``y_i = +-y(z_i)`` and ``eps`` are the choice that reproduces the data,
        and a Gauss-Newton step on the six equations polishes ``(z1, z2, g)``
        (the sums above cancel when the ``P_kl`` are nearly equal). See
        ``docs/curve.md`` for the derivation.

        ``(g, y1, y2)`` and ``(-g, -y1, -y2)`` give the same ``(xi, eta)``; the
        sign of ``g`` is that nearer ``g_ref`` if given, else that of the
        principal ``sqrt(g**2)``.

        **The pair is unordered.** (27)-(28), and with them ``(xi, eta)``, are
        symmetric in the two points, so the data cannot tell which point was
        "first": ``(z1, y1)`` is the root of ``x**2 - (z1 + z2) x + z1 z2`` of
        larger modulus (then polished), whatever order produced ``xi, eta``. Compare
        pairs as sets (or use :class:`manakov.LevelSet`, which orders each sample's
        pair to follow the previous one along a trajectory).

        Parameters
        ----------
        xi, eta : array_like, complex, shape (..., 3)
        sqrt_c : array_like, shape (3,), optional, keyword-only
            The square roots of ``c_j`` used to make ``xi, eta``; default principal.
        g_ref : complex or array_like, optional, keyword-only
            Selects the sign of ``g`` (e.g. ``g = 1/(1 - eps P_0)`` of (42)).
        rtol : float, keyword-only
            The recovered points must reproduce ``(xi, eta)`` to
            ``rtol * max|(xi, eta)|``.

        Returns
        -------
        CurvePoints

        Raises
        ------
        ValueError
            Non-finite input, ``g**2 = 0``, ``z1 == z2`` (a double root, where
            (28) is undefined), or data that no point pair reproduces (not on
            Kötter's quadrics (11) of this curve, or another branch of ``sqrt_c``).
        """
        xa, ea = _c(xi), _c(eta)
        if xa.shape[-1:] != (3,) or ea.shape[-1:] != (3,):
            raise ValueError(
                f"xi and eta must have last axis of length 3, got {xa.shape} and {ea.shape}"
            )
        shape = np.broadcast_shapes(xa.shape[:-1], ea.shape[:-1])
        if g_ref is not None:
            shape = np.broadcast_shapes(shape, np.shape(g_ref))
        scalar = len(shape) == 0
        xr = np.ascontiguousarray(np.broadcast_to(xa, (*shape, 3)).reshape(-1, 3))
        er = np.ascontiguousarray(np.broadcast_to(ea, (*shape, 3)).reshape(-1, 3))
        gr = None
        if g_ref is not None:
            gr = np.ascontiguousarray(np.broadcast_to(_c(g_ref), shape).reshape(-1))
        sc = None if sqrt_c is None else np.ascontiguousarray(_c(sqrt_c).reshape(-1))
        pts, eps, res, zd = _core.curve_points_from_xi_eta(
            self._d123(), xr, er, sc, gr, float(rtol)
        )
        cols = [pts[:, i].reshape(shape) for i in range(5)]
        return CurvePoints(
            z1=_scalar_or(cols[0], scalar),
            y1=_scalar_or(cols[1], scalar),
            z2=_scalar_or(cols[2], scalar),
            y2=_scalar_or(cols[3], scalar),
            g=_scalar_or(cols[4], scalar),
            eps=_frozen(eps.reshape(*shape, 5)),
            residual=res.reshape(shape)[()] if scalar else _frozen(res.reshape(shape)),
            zd=_frozen(zd.reshape(*shape, 2, 5)),
        )
