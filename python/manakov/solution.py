# ruff: noqa: E741, E743  (l is the paper's name for the state)
"""The Theorem (9)–(10): ``l(t)`` as genus-2 theta quotients with a linear argument.

``ManakovTop.solve(l0)`` returns a :class:`Solution`. The recipe, equation by
equation with Perelomov's numbers and the errata rows, is docs/theorem.md; in
short, with ``v = u + K`` (``u`` the Abel map of the divisor, base point ∞,
``K`` the vector of Riemann constants)

.. math::

    P_L = C_L \\frac{\\theta[\\chi_L](v)}{\\theta(v)} \\;(34), \\quad
    \\xi_j = \\sqrt{c_j}\\, g P_{kl}, \\; \\eta_j = \\sqrt{c_j}\\, g P_{j4} \\;(37), \\quad
    g = \\frac{G}{1 - \\varepsilon P_0} \\;(42,\\ \\text{corrected}),

and ``l`` linear in ``ξ, η`` by (22)–(23), so that

.. math::

    l_q(t) = \\frac{\\sum_L w_{qL}\\, \\theta[\\chi_L](v(t))}
                  {\\theta(v(t)) - \\varepsilon C_0\\, \\theta[\\chi_0](v(t))}, \\qquad
    v(t) = v_0 + U t,

(9)–(10) as they truly read. ``U`` comes from the equations of motion (1) at
``v0``, not from a fit to a trajectory.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _core
from ._checks import _float_array, _one_state, _show, _states
from ._torus import Torus, torus_of_state
from .riemann import HyperellipticCurve

__all__ = ["LABELS", "Solution"]

#: Labels of the Wurzelfunktionen (27)–(28) entering (37) and (42), in the
#: order of :attr:`Solution.constants` and :attr:`Solution.characteristics`.
LABELS: tuple[str, ...] = ("P0", "P23", "P31", "P12", "P14", "P24", "P34")


#: What the one-state calls of the solution point to for many states.
_MANY_STATES = "manakov.frequency_map (frequencies) or top.integrate (trajectories)"


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


class Solution:
    """The explicit solution through ``l0`` of the Manakov top with parameters ``a, b``.

    Usually made by :meth:`manakov.ManakovTop.solve`.

    Parameters
    ----------
    a, b : array_like, shape (4,)
        The parameters of (2).
    l0 : array_like, shape (6,)
        The initial state ``(l12, l13, l14, l23, l24, l34)``.

    Raises
    ------
    ValueError
        The reduction is singular at ``l0``; the message names why: ``l0 = 0``,
        ``h0 = 0`` (branch points ``d_0 = 0`` and ``d_j`` coincide),
        ``h1² = 4h0²`` (self-dual state, ``F`` (19) undefined), coinciding
        branch points ``d_j``, or the divisor of ``l0`` at infinity
        (``θ(v0) = 0``; the solution exists, start at another time); and the
        errors of the reduction (:func:`manakov.kotter`).

    Notes
    -----
    Branches (``√c_j``, the roots of ``F``, the sheets, the sign of ``g``) are
    fixed once from ``l0``. ``l(v)`` is periodic only under a sublattice of the
    period lattice, so ``v(t)`` is never reduced modulo the lattice itself:
    in lattice coordinates ``v = x + τ y`` the real ``x(t), y(t)`` are reduced
    modulo 2 (an even lattice vector multiplies every ``θ[χ]`` by one common
    factor), with the products of the rates and ``t`` split error-free, so that
    ``l(10**6)`` costs and keeps what ``l(1)`` does.
    """

    __slots__ = ("_a", "_b", "_l0", "_core", "_curve", "_torus")

    def __init__(self, a: Any, b: Any, l0: Any) -> None:
        aa = _float_array(a, "a").astype(float)
        bb = _float_array(b, "b").astype(float)
        for name, arr in (("a", aa), ("b", bb)):
            if arr.shape != (4,):
                raise ValueError(f"{name} must have shape (4,), got {arr.shape}")
        ll = _one_state(l0, 6, "l0", "solve", _MANY_STATES)
        self._a, self._b, self._l0 = _frozen(aa.copy()), _frozen(bb.copy()), _frozen(ll.copy())
        self._core = _core.SolutionCore(self._a, self._b, self._l0)
        self._curve: HyperellipticCurve | None = None
        self._torus: Torus | None = None

    @property
    def a(self) -> np.ndarray:
        """``a`` (read-only)."""
        return self._a

    @property
    def b(self) -> np.ndarray:
        """``b`` (read-only)."""
        return self._b

    @property
    def l0(self) -> np.ndarray:
        """The initial state (read-only)."""
        return self._l0

    def l(self, t: Any) -> np.ndarray:
        """The state at time(s) ``t`` from the theta quotients (9)–(10).

        Parameters
        ----------
        t : float or array_like
            Times (any real; ``|t|`` up to ~1e15 keeps the phase exact).

        Returns
        -------
        ndarray
            Shape ``(6,)`` for scalar ``t``, ``(..., 6)`` for an array.

        Raises
        ------
        ValueError
            Non-finite ``t``.
        """
        tt = _float_array(t, "t")
        out = self._core.l(np.ascontiguousarray(tt.reshape(-1)))
        return out.reshape(tt.shape + (6,))

    def abel(self, l: Any) -> np.ndarray:
        """The Abel image ``u(P1) + u(P2)`` (modulo the lattice) of states ``l``
        on the same level set, with the branches of ``l0``'s reduction.

        Along a trajectory ``abel(l(t)) ≡ u0 + U t`` modulo the lattice.

        Parameters
        ----------
        l : array_like, shape (..., 6)

        Returns
        -------
        ndarray, complex, shape (..., 2)

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l``, or a state the reduction
            of ``l0``'s level set refuses (the message names why).
        """
        flat, lead = _states(l, 6, "l")
        out = np.empty((flat.shape[0], 2), dtype=complex)
        for i, x in enumerate(flat):
            out[i] = self._core.abel(np.ascontiguousarray(x))
        return out.reshape(lead + (2,))

    @property
    def u0(self) -> np.ndarray:
        """``u0 = u(P1) + u(P2)`` at ``t = 0`` (Abel map, base point ∞; ``v0 = u0 + K``)."""
        return _frozen(self._core.u0)

    @property
    def U(self) -> np.ndarray:  # noqa: N802 (the paper's name)
        """``U``: ``u(t) = u0 + U t``, from the equations of motion (1)."""
        return _frozen(self._core.rate)

    @property
    def tau(self) -> np.ndarray:
        """The period matrix ``τ`` of the curve (8) in :attr:`curve`'s basis."""
        return _frozen(self._core.tau)

    @property
    def riemann_constant(self) -> np.ndarray:
        """The vector of Riemann constants ``K`` (``v = u + K``)."""
        return _frozen(self._core.riemann_constant)

    @property
    def curve(self) -> HyperellipticCurve:
        """The curve (8), ``y² = Π_{j=0}^{4} (x − d_j)``, with its homology basis."""
        if self._curve is None:
            self._curve = HyperellipticCurve(self._core.branch_points)
        return self._curve

    @property
    def characteristics(self) -> dict[str, tuple[tuple[int, int], tuple[int, int]]]:
        """``χ_L = ([a1, a2], [b1, b2])`` for :data:`LABELS`: ``χ_j = η(d_j)``,
        ``χ_jk = χ_j + χ_k`` (mod 2)."""
        ch = self._core.characteristics
        return {
            lab: ((int(r[0]), int(r[1])), (int(r[2]), int(r[3])))
            for lab, r in zip(LABELS, ch, strict=True)
        }

    @property
    def constants(self) -> dict[str, complex]:
        """``C_L`` of (34), ``P_L = C_L θ[χ_L](v)/θ(v)``, for :data:`LABELS`."""
        return {lab: complex(c) for lab, c in zip(LABELS, self._core.constants, strict=True)}

    @property
    def calibration(self) -> np.ndarray:
        """``|C_L − P_L(l0) θ(v0)/θ[χ_L](v0)| / |C_L|`` (``C_L`` from an auxiliary divisor)."""
        return _frozen(self._core.calibration)

    @property
    def self_check(self) -> float:
        """The largest relative defect found by the solution's own check when it was built.

        At ``t = 0`` and at three points of the torus the quotients (9)–(10) must give
        a real state with the integrals (6)–(7) of ``l0``, whose velocity along ``U``
        is Frahm's (1), and ``l(0) = l0``; defects are relative to ``|l0|``, to the
        largest speed ``|dl/dt|`` met at those points and to the scales of the
        integrals. A solution is only returned when this is at most 1e-10
        (correct set-ups leave ~1e-15 … 1e-11).
        """
        return float(self._core.self_check)

    @property
    def torus(self) -> Torus:
        """The real torus of the motion (docs/tori.md): a reduced basis ``λ1, λ2``
        of the periods of ``l`` in the real plane of ``U`` and a second
        commuting flow, and ``(ν1, ν2)`` with ``U = ν1 λ1 + ν2 λ2``."""
        if self._torus is None:
            self._torus = torus_of_state(self._a, self._b, self._l0)[0]
        return self._torus

    @property
    def frequencies(self) -> np.ndarray:
        """``(ν1, ν2) ≥ 0`` in cycles per unit time, ``U = ν1 λ1 + ν2 λ2``."""
        return self.torus.frequencies

    @property
    def rotation_number(self) -> float:
        """``ν1/ν2``."""
        return self.torus.rotation_number

    def angles(self, t: Any) -> np.ndarray:
        """Torus angles ``(ν1 t, ν2 t) mod 1`` from the initial point, shape ``(..., 2)``."""
        return self.torus.angles(t)

    def quotient(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(idx, num, den)``: ``l_q = Re(Σ_m num[q, m] θ[idx[m]](v) / Σ_m den[m] θ[idx[m]](v))``
        (theta indices in the package's characteristic order)."""
        return self._core.quotient()

    def __repr__(self) -> str:
        d = ", ".join(_show(x, 6) for x in self._core.branch_points)
        u = ", ".join(_show(x, 12) for x in self._core.rate)
        return f"Solution(curve: y^2 = prod (x - d_j), d = [{d}]; U = [{u}])"
