"""Hyperelliptic curves with complex branch points: homology basis, periods,
Abel-Jacobi map, Riemann constant and Jacobi inversion.

The curve is

.. math::
    y^2 = R(x) = \\prod_{k=1}^{n} (x - e_k), \\qquad n = 2g + 1 \\text{ or } 2g + 2,

with distinct finite branch points ``e_k`` anywhere in the complex plane; for
odd ``n``, ``infinity`` is a branch point too. The paper's curve (8) is the case
``n = 5``, ``e = (0, d1, d2, d3, d4)`` (:attr:`manakov.KotterCurve.surface`).

Conventions (``docs/riemann.md``)
---------------------------------
* Sheets: ``y(x, sheet=1) = prod_k sqrt(x - e_k)`` (principal roots; the
  canonical sheet of :class:`manakov.KotterCurve`), ``sheet=-1`` its negative.
  A point is ``(x, y)`` with ``y**2 == R(x)``: its ``y`` fixes the sheet.
* Differentials ``omega_i = x**(i-1) dx / y``, ``i = 1..g``. Periods
  ``A[i, j] = oint_{a_j} omega_i``, ``B[i, j] = oint_{b_j} omega_i`` over a
  canonical basis (``a_i . b_j = delta_ij``), ``tau = A^{-1} B`` (symmetric,
  ``Im tau`` positive definite).
* Abel map ``u(P) = A^{-1} int_{P0}^{P} omega``, base point ``P0 = infinity``
  for odd ``n`` and ``P0 = e_1`` (``branch_points[0]``) for even ``n``; defined
  modulo the lattice ``Z^g + tau Z^g``. A divisor's image is the sum over its
  points.
* Characteristics are those of :func:`manakov.theta`: ``[a; b]`` with
  ``a, b in {0, 1}^g`` is the half period ``(b + tau a)/2``.

Method: Molin & Neurohr, Math. Comp. 88 (2019) (arXiv:1707.07249): spanning
tree of straight segments, Gauss-Chebyshev periods, intersection numbers from
the geometry, symplectic reduction; Abel integrals on straight paths with the
endpoint square root removed, Gauss-Legendre with node counts from the
Bernstein ellipse of the nearest other branch point.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _core

__all__ = ["HyperellipticCurve", "ON_CURVE_RTOL"]

#: Relative tolerance of "the point is on the curve": ``|y**2 - R(x)| <=
#: ON_CURVE_RTOL * prod_k (|x| + |e_k|)`` (the rounding scale of ``R`` from its
#: expanded coefficients). A point beyond it raises ``ValueError``.
ON_CURVE_RTOL = 1e-8


def _c(x: Any, what: str) -> np.ndarray:
    arr = np.asarray(x)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_):
        raise ValueError(f"{what} must be a numeric array, got dtype {arr.dtype}")
    return np.asarray(arr, dtype=np.complex128)


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


class HyperellipticCurve:
    """The hyperelliptic curve ``y**2 = prod_k (x - e_k)``.

    Parameters
    ----------
    branch_points : array_like, complex, shape (n,)
        The finite branch points ``e_1 .. e_n``, ``n = 2g + 1`` or ``2g + 2``,
        ``1 <= g <= 6``; distinct and finite, in any position in the plane.

    Raises
    ------
    ValueError
        Wrong shape or count, NaN or infinity, ``|e_k|`` so large that
        ``y ~ x**(n/2)`` leaves the double range (``2**(2000/n)``, about
        ``1e120`` for ``n = 5``), two branch points coinciding (to rounding),
        or a configuration the quadrature cannot resolve (a branch point
        within rounding of a segment between two others). The message says
        which.

    Notes
    -----
    Branch points larger than ``1e20`` are handled in the coordinate
    ``x / 2**k`` (exactly; the periods, the Abel map and the points are
    converted), so ``tau`` and the Abel map do not depend on the scale of
    ``x``. Clusters of branch points (pairs ``1e-30`` apart relative to the
    others, a branch point ``1e30`` times farther out than the rest, as near
    the pinched level sets of the top) are resolved.

    The homology basis is built from a spanning tree of straight segments
    between branch points, chosen to keep the other branch points far from
    each segment; it does not depend on the branch points being real or
    sorted (``docs/riemann.md`` has a picture).

    Examples
    --------
    >>> import numpy as np, manakov
    >>> e = [-1.3 + 0.2j, -0.4 - 0.7j, 0.3 + 0.5j, 1.1 - 0.1j, 2.0 + 0.9j]
    >>> C = manakov.HyperellipticCurve(e)
    >>> C.genus, C.base_point
    (2, 'infinity')
    >>> bool(np.allclose(C.tau, C.tau.T)), bool(np.all(np.linalg.eigvalsh(C.tau.imag) > 0))
    (True, True)
    """

    __slots__ = ("_core", "_e")

    def __init__(self, branch_points: Any) -> None:
        e = _c(branch_points, "branch_points")
        if e.ndim != 1:
            raise ValueError(f"branch_points must be 1-d, got shape {e.shape}")
        self._e = _frozen(e.copy())
        self._core = _core.HyperellipticCore(self._e)

    # -- basic data ---------------------------------------------------------
    @property
    def genus(self) -> int:
        """The genus ``g``."""
        return int(self._core.genus)

    @property
    def branch_points(self) -> np.ndarray:
        """The finite branch points ``e_1 .. e_n`` (read-only)."""
        return self._e

    @property
    def base_point(self) -> str | int:
        """``"infinity"`` (odd ``n``) or ``0`` (even ``n``: ``P0 = e_1``)."""
        return "infinity" if self._e.size % 2 == 1 else 0

    def __repr__(self) -> str:
        return f"HyperellipticCurve(genus={self.genus}, branch_points={self._e.tolist()})"

    def R(self, x: Any) -> Any:
        """``R(x) = prod_k (x - e_k)``; scalar in, scalar out.

        Raises
        ------
        ValueError
            Non-finite ``x``, or ``R(x)`` beyond the double range.
        """
        xa = _c(x, "x")
        if not np.all(np.isfinite(xa)):
            raise ValueError("x must be finite (no NaN or infinity)")
        with np.errstate(over="ignore", invalid="ignore"):
            out = np.prod(xa[..., None] - self._e, axis=-1)
        if not np.all(np.isfinite(out)):
            raise ValueError(
                f"R(x) overflows: |R(x)| ~ |x|^{self._e.size} is beyond the double range "
                f"for |x| up to {np.max(np.abs(xa)):.3e}"
            )
        return out[()] if out.ndim == 0 else out

    def y(self, x: Any, *, sheet: int = 1) -> Any:
        """``y`` on a sheet: ``sheet * prod_k sqrt(x - e_k)`` (principal roots).

        Parameters
        ----------
        x : complex or array_like
        sheet : {1, -1}

        Returns
        -------
        complex or ndarray
        """
        if sheet not in (1, -1):
            raise ValueError(f"sheet must be 1 or -1, got {sheet!r}")
        xa = _c(x, "x")
        flat = np.ascontiguousarray(xa.reshape(-1))
        out = self._core.y(flat, int(sheet)).reshape(xa.shape)
        return out[()] if out.ndim == 0 else out

    # -- periods --------------------------------------------------------------
    @property
    def periods(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)``: ``A[i, j] = oint_{a_j} x**i dx/y``, ``B[i, j] = oint_{b_j} x**i dx/y``."""
        a, b = self._core.periods()
        return _frozen(a), _frozen(b)

    @property
    def tau(self) -> np.ndarray:
        """The period matrix ``tau = A^{-1} B`` (symmetric, ``Im tau > 0``)."""
        return _frozen(self._core.tau())

    @property
    def cycle_edges(self) -> np.ndarray:
        """``(2g, 2)`` branch-point indices of the tree edges whose loops ``c_j``
        generate the homology (``docs/riemann.md``)."""
        return _frozen(self._core.cycle_edges())

    @property
    def cycle_periods(self) -> np.ndarray:
        """``(g, 2g)`` periods ``oint_{c_j} omega_i`` of the tree loops."""
        return _frozen(self._core.cycle_periods())

    @property
    def intersection_matrix(self) -> np.ndarray:
        """``(2g, 2g)`` intersection numbers ``c_i . c_j`` of the tree loops."""
        return _frozen(self._core.intersection_matrix())

    @property
    def symplectic_basis(self) -> np.ndarray:
        """``M`` with ``(a_1..a_g, b_1..b_g) = M (c_1..c_2g)`` and ``M C M^T = J``."""
        return _frozen(self._core.symplectic_basis())

    # -- Abel map -----------------------------------------------------------------
    def abel(self, x: Any, y: Any) -> np.ndarray:
        """Abel-Jacobi map ``u(P) = A^{-1} int_{P0}^{P} omega`` of points ``P = (x, y)``.

        Parameters
        ----------
        x, y : complex or array_like, broadcastable
            Points of the curve; ``y`` picks the sheet (``y**2 = R(x)`` to
            :data:`ON_CURVE_RTOL`).

        Returns
        -------
        ndarray, complex, shape (..., g)
            Modulo the lattice ``Z^g + tau Z^g`` (not reduced; see
            :meth:`reduce`). Base point :attr:`base_point`.

        Raises
        ------
        ValueError
            A point not on the curve, NaN or infinity.
        """
        return self._abel(x, y, None)

    def _abel(self, x: Any, y: Any, route: int | None) -> np.ndarray:
        xa, ya = np.broadcast_arrays(_c(x, "x"), _c(y, "y"))
        shape = xa.shape
        out = self._core.abel(
            np.ascontiguousarray(xa.reshape(-1)), np.ascontiguousarray(ya.reshape(-1)), route
        )
        return out.reshape(*shape, self.genus)

    def abel_near_branch(self, k: int, dx: Any, y: Any) -> np.ndarray:
        """Abel map of points ``(e_k + dx, y)`` close to the branch point ``e_k``.

        ``u(P) = u(e_k) + A^{-1} int_{e_k}^{P} omega``, the integral taken in the
        local parameter ``s = sqrt(x - e_k)`` (``x = e_k + s^2``). Given the offset
        ``dx`` to full relative accuracy, the result keeps roundoff where
        :meth:`abel` of the double ``x = e_k + dx`` loses about
        ``eps |x| / |dx|``: use it for points a computation produced as offsets
        from a branch point (``z - d_j`` in the reduction, for instance).

        Parameters
        ----------
        k : int
            0-based index into :attr:`branch_points`.
        dx, y : complex or array_like, broadcastable
            Offsets ``x - e_k`` and the ``y`` of the points (``y`` picks the sheet;
            ``y**2 = R(e_k + dx)`` to :data:`ON_CURVE_RTOL`).

        Returns
        -------
        ndarray, complex, shape (..., g)
            As :meth:`abel`: modulo the lattice, base point :attr:`base_point`.

        Raises
        ------
        ValueError
            ``k`` out of range, a point not on the curve, NaN or infinity.
        """
        n = len(self.branch_points)
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < n:
            raise ValueError(f"k must be an integer in [0, {n}), got {k!r}")
        da, ya = np.broadcast_arrays(_c(dx, "dx"), _c(y, "y"))
        shape = da.shape
        out = self._core.abel_near_branch(
            int(k), np.ascontiguousarray(da.reshape(-1)), np.ascontiguousarray(ya.reshape(-1))
        )
        return out.reshape(*shape, self.genus)

    def abel_divisor(self, x: Any, y: Any) -> np.ndarray:
        """Abel image of divisors ``sum_j (x_j, y_j)``.

        :meth:`abel` summed over the last axis of ``x, y`` (the points of each divisor).
        """
        u = self.abel(x, y)
        if u.ndim < 2:
            raise ValueError("x, y must have a last axis holding the points of each divisor")
        return u.sum(axis=-2)

    def reduce(self, z: Any) -> np.ndarray:
        """``z`` modulo the lattice: ``alpha + tau beta`` with ``alpha, beta in [-1/2, 1/2]``."""
        za = _c(z, "z")
        g = self.genus
        if za.ndim == 0 or za.shape[-1] != g:
            raise ValueError(f"z must have shape (..., {g}), got {za.shape}")
        out = self._core.reduce(np.ascontiguousarray(za.reshape(-1, g)))
        return out.reshape(za.shape)

    # -- Riemann constant and characteristics -----------------------------------------
    @property
    def riemann_constant(self) -> np.ndarray:
        """The vector of Riemann constants ``K`` for the base point ``P0``.

        ``K = (b + tau a)/2`` is the half period with
        ``theta(u(P_1) + ... + u(P_{g-1}) + K) = 0`` for all points; for
        ``g = 2``: ``theta(u(P) + K) = 0`` for every ``P`` (the theta divisor).
        """
        return _frozen(self._core.riemann_constant())

    @property
    def riemann_constant_char(self) -> tuple[np.ndarray, np.ndarray]:
        """``(a, b)`` of :attr:`riemann_constant`, ``K = (b + tau a)/2``."""
        ab = self._core.riemann_constant_char()
        g = self.genus
        return _frozen(ab[:g]), _frozen(ab[g:])

    @property
    def branch_chars(self) -> np.ndarray:
        """``eta(e_k)`` as rows ``[a | b]`` (uint8, shape ``(n or n+1, 2g)``).

        Row ``k`` is the characteristic of ``u(e_{k+1}) = (b + tau a)/2`` mod the
        lattice; for odd ``n`` the last row is ``infinity`` (zero: the base point).
        """
        return _frozen(self._core.branch_chars())

    def branch_char(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """``(a, b)`` of ``eta(e_{k+1})``.

        0-based ``k``; ``k = n`` is ``infinity`` for odd ``n``.
        """
        rows = self._core.branch_chars()
        if not (0 <= k < rows.shape[0]):
            raise ValueError(f"k must be in 0..{rows.shape[0] - 1}, got {k}")
        g = self.genus
        return _frozen(rows[k, :g]), _frozen(rows[k, g:])

    @property
    def branch_half_periods(self) -> np.ndarray:
        """``(b + tau a)/2`` for every row of :attr:`branch_chars`, shape ``(rows, g)``."""
        ch = self._core.branch_chars().astype(np.float64)
        g = self.genus
        tau = self._core.tau()
        return _frozen((ch[:, g:] + ch[:, :g] @ tau.T) / 2)

    @property
    def abel_branch_points(self) -> np.ndarray:
        """``u(e_k)`` for every finite branch point (``(n, g)``, unreduced)."""
        return _frozen(self._core.abel_branch_points())

    # -- Jacobi inversion ------------------------------------------------------------
    def invert(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        """Jacobi inversion (``g = 2``, ``n = 5`` or ``6``): the divisor ``P1 + P2`` with
        ``u(P1) + u(P2) = u`` modulo the lattice.

        Parameters
        ----------
        u : array_like, complex, shape (..., 2)

        Returns
        -------
        x, y : ndarray, complex, shape (..., 2)
            The two points ``(x[..., i], y[..., i])`` with their sheets.

        Raises
        ------
        ValueError
            ``u`` on the theta divisor (``theta(u + K) = 0``: the divisor
            contains a pair ``P + iota P``, and is not unique, or the base point),
            a curve of genus other than 2, wrong shape, NaN.
        manakov.ConvergenceError
            Newton on the Abel map did not converge.

        Notes
        -----
        Start from the theta quotients (34):
        ``(x1 - e_j)(x2 - e_j) = c_j theta[eta(e_j)](v)**2 / theta(v)**2``,
        ``v = u + K`` (``n = 5``; for ``n = 6`` the quotients
        ``(x1 - e_j)(x2 - e_j)/((x1 - e_1)(x2 - e_1))`` with characteristics found
        numerically), then Newton on the Abel map.
        """
        ua = _c(u, "u")
        g = self.genus
        if ua.ndim == 0 or ua.shape[-1] != g:
            raise ValueError(f"u must have shape (..., {g}), got {ua.shape}")
        x, y = self._core.invert(np.ascontiguousarray(ua.reshape(-1, g)))
        return x.reshape(ua.shape), y.reshape(ua.shape)
