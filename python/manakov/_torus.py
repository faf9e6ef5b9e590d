"""The real torus of a motion on C²/Λ' (a leaf of the import graph: only ``_core``).

``solution`` (``sol.torus``) and ``tori`` (frequency maps) both build on it; see
``manakov.tori`` and ``docs/tori.md`` for the mathematics and the basis convention.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from . import _core
from ._checks import _angles

__all__ = ["Torus", "real_torus", "second_flow_b", "torus_of_state"]


class Torus(NamedTuple):
    """The real torus of a motion.

    Attributes
    ----------
    lambdas : ndarray, complex, shape (2, 2)
        Rows ``λ1``, ``λ2`` in ``C²``: a reduced basis of ``Λ' ∩ span_R(U, U')``.
    coords : ndarray, int64, shape (2, 4)
        Their lattice coordinates ``(m1, m2, n1, n2)``, ``λ = m + τ n``.
    frequencies : ndarray, shape (2,)
        ``(ν1, ν2) ≥ 0`` with ``U = ν1 λ1 + ν2 λ2`` (cycles per unit time).

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> torus = manakov.ManakovTop(p.a, p.b).solve(p.l0).torus
    >>> print(torus.frequencies.round(6), round(torus.rotation_number, 6))
    [0.264922 0.278362] 0.951716
    """

    lambdas: np.ndarray
    coords: np.ndarray
    frequencies: np.ndarray

    @property
    def rotation_number(self) -> float:
        """``ν1/ν2`` (``inf`` on the resonance ``ν2 = 0``)."""
        n1, n2 = (float(v) for v in self.frequencies)
        return n1 / n2 if n2 != 0.0 else math.inf

    def angles(self, t: Any) -> np.ndarray:
        """Torus angles ``(ν1 t, ν2 t) mod 1`` measured from the initial point.

        Parameters
        ----------
        t : array_like, real
            Times.

        Returns
        -------
        ndarray, shape (..., 2)
            Angles in ``[0, 1)`` (cycles).

        Raises
        ------
        ValueError
            ``t`` not real numbers, or not finite, or ``|ν t|`` beyond 2^52
            cycles (the angle is not determined in double precision).
        """
        return _angles(t, self.frequencies)


def real_torus(tau: Any, U: Any, U2: Any, characteristics: Any) -> Torus:
    """The real torus carrying the motion ``u0 + U t`` modulo the periods of l.

    Parameters
    ----------
    tau : array_like, complex, shape (2, 2)
        The period matrix (``Im τ`` positive definite).
    U : array_like, complex, shape (2,)
        The velocity of the motion in ``C²``.
    U2 : array_like, complex, shape (2,)
        The velocity of a second commuting flow on the same level set
        (the same curve and divisor), R-linearly independent of ``U``.
    characteristics : array_like of {0, 1}, shape (k, 4)
        The characteristics ``[a1 a2; b1 b2]`` of the quotients ``θ[χ]/θ``
        that enter l; they define the lattice ``Λ'`` of periods of l.

    Returns
    -------
    Torus

    Raises
    ------
    ValueError
        If the inputs have the wrong shape, are not finite, ``Im τ`` is not
        positive definite, ``U`` and ``U2`` do not span a real plane, or the
        plane meets ``Λ'`` in no rank-2 lattice.

    Examples
    --------
    >>> import manakov
    >>> from manakov.tori import real_torus, torus_of_state
    >>> p = manakov.problem("generic")
    >>> sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    >>> _, U2 = torus_of_state(p.a, p.b, p.l0)
    >>> chars = [sum(c, ()) for c in sol.characteristics.values()]
    >>> torus = real_torus(sol.tau, sol.U, U2, chars)
    >>> print(torus.frequencies.round(6))
    [0.264922 0.278362]
    """
    t = np.ascontiguousarray(np.asarray(tau, dtype=complex))
    u = np.ascontiguousarray(np.asarray(U, dtype=complex))
    u2 = np.ascontiguousarray(np.asarray(U2, dtype=complex))
    for name, v, shape in (("tau", t, (2, 2)), ("U", u, (2,)), ("U2", u2, (2,))):
        if v.shape != shape:
            raise ValueError(f"{name} must have shape {shape}, got {v.shape}")
    ch = np.asarray(characteristics)
    if ch.ndim != 2 or ch.shape[1] != 4 or not np.all((ch == 0) | (ch == 1)):
        raise ValueError(f"characteristics must be (k, 4) of 0/1, got {ch!r}")
    lam, coords, nu = _core.real_torus(t, u, u2, np.ascontiguousarray(ch, dtype=np.uint8))
    return Torus(_readonly(lam), _readonly(coords), _readonly(nu))


def _readonly(x: np.ndarray) -> np.ndarray:
    x.setflags(write=False)
    return x


def second_flow_b(a: Any, b: Any) -> np.ndarray:
    """``b'`` of the second commuting flow that spans the real torus with the top's.

    ``c_ij = (b_i − b_j)/(a_i − a_j)`` (2) is linear in ``b``; with the cubic
    interpolant ``b_i = p0 + p1 a_i + p2 a_i² + p3 a_i³`` the top's flow is
    ``p2 X_{a²} + p3 X_{a³}`` (``b = 1`` and ``b = a`` give no flow on the level
    set). The second flow is ``b' = a²`` unless the ``a²`` part dominates,
    ``|p2| > |p3| max|a|``, in which case ``b' = a³``: either way the two
    velocities are far from parallel.

    Parameters
    ----------
    a, b : array_like, shape (4,)

    Returns
    -------
    ndarray, shape (4,)

    Examples
    --------
    >>> from manakov.tori import second_flow_b
    >>> print(second_flow_b([0.3, 1.1, 2.0, 3.7], [0.5, -0.2, 1.4, 0.9]))
    [2.7000e-02 1.3310e+00 8.0000e+00 5.0653e+01]
    """
    aa = np.asarray(a, dtype=float)
    bb = np.asarray(b, dtype=float)
    p = np.linalg.solve(np.vander(aa, 4, increasing=True), bb)
    s = float(np.max(np.abs(aa)))
    return aa**3 if abs(p[2]) > abs(p[3]) * s else aa**2


def torus_of_state(a: Any, b: Any, l0: Any) -> tuple[Torus, np.ndarray]:
    """The real torus through ``l0`` of the top ``(a, b)`` and the second velocity ``U'``.

    Runs the Theorem's set-up for ``l0`` (``ManakovTop(a, b).solve(l0)``), takes
    ``U'`` of the second flow (:func:`second_flow_b`) from the same equations
    with Frahm's vector field (1) of that flow on the right-hand side, and
    returns :func:`real_torus` of ``(τ, U, U')``.

    Parameters
    ----------
    a, b : array_like, shape (4,)
    l0 : array_like, shape (6,)

    Returns
    -------
    torus : Torus
    U2 : ndarray, complex, shape (2,)
        ``U'`` fixes only the real plane in which the lattice basis is found
        (as integer vectors); the frequencies are the coordinates of ``U``.
        Where ``U'`` is the theta quotients' least-squares fit next to a
        pinched curve, the Abel images of integrated states vouch for it to
        1e-8 (relative), for ``U`` to 5e-11 (or give the velocity they move at,
        to the same bounds); where its flow is beyond their budget, the
        integrality of the lattice basis (to 1e-7) stands in.

    Raises
    ------
    ValueError
        On a singular level set (the solution's message names the case) or
        when the lattice of periods has no rank-2 part in the real plane.
    ClosedFormError
        The torus of this (valid) state could not be verified (as
        :attr:`Solution.torus <manakov.Solution.torus>`; the message names the step).

    Examples
    --------
    >>> import manakov
    >>> from manakov.tori import torus_of_state
    >>> p = manakov.problem("generic")
    >>> torus, U2 = torus_of_state(p.a, p.b, p.l0)
    >>> print(torus.frequencies.round(6))
    [0.264922 0.278362]
    """
    arr = [np.ascontiguousarray(np.asarray(x, dtype=float)) for x in (a, b, l0)]
    lam, coords, nu, u2 = _core.torus_of_state(*arr)
    return Torus(_readonly(lam), _readonly(coords), _readonly(nu)), _readonly(u2)
