# ruff: noqa: E741, E743  (l is the paper's name for the state)
"""One solution for every state: the Theorem (9)–(10) in genus-2 theta functions,
and the closed forms where it degenerates.

``ManakovTop.solve(l0)`` returns a :class:`Solution` of one of the kinds of
:data:`KINDS`, chosen by exact tests on the state (docs/degenerate.md):

* ``"genus2"``: the Theorem. With ``v = u + K`` (``u`` the Abel map of the
  divisor, base point ∞, ``K`` the vector of Riemann constants)

  .. math::

      P_L = C_L \\frac{\\theta[\\chi_L](v)}{\\theta(v)} \\;(34), \\quad
      \\xi_j = \\sqrt{c_j}\\, g P_{kl}, \\; \\eta_j = \\sqrt{c_j}\\, g P_{j4} \\;(37), \\quad
      g = \\frac{G}{1 - \\varepsilon P_0} \\;(42,\\ \\text{corrected}),

  and ``l`` linear in ``ξ, η`` by (22)–(23), so that

  .. math::

      l_q(t) = \\frac{\\sum_L w_{qL}\\, \\theta[\\chi_L](v(t))}
                    {\\theta(v(t)) - \\varepsilon C_0\\, \\theta[\\chi_0](v(t))}, \\qquad
      v(t) = v_0 + U t,

  (9)–(10) as they truly read; ``U`` comes from the equations of motion (1).
* ``"euler"``: a state in an so(3) block (three components exactly zero) or
  self-dual (``n = ±m``) moves as a three-dimensional Euler top, solved in
  Jacobi's elliptic functions ``sn, cn, dn`` (trigonometric when axisymmetric);
  ``"separatrix"``: the same on the Euler top's separatrix (``tanh``, ``sech``).
* ``"rest"`` (``l0 = 0``), ``"spherical"`` (all ``c_ij`` equal, ``b = α a + β``),
  ``"equilibrium"`` (``l̇ = 0`` by (1)): ``l(t) = l0``.
* ``"integrated"``: a genus-2 state whose closed form cannot be built in double
  precision (a step of the reduction refuses it; the message says which): ``l(t)``
  is an integration of (1) in double-double, confirmed by one with every step halved, at every
  call, with an :class:`IntegratedValuesWarning`.

Every kind works from normalized data: ``l0/s``, ``a' = (a − κ)/σ``,
``c' = (c − μ)/λ`` (powers of two and exact shifts, the identity for moderate
data), and ``l(t) = s l'(T t)`` with the time scale ``T = s λ`` (the flow is
homogeneous in ``l`` and blind to a common shift of the ``c_ij``).
"""

from __future__ import annotations

import warnings
from typing import Any, NamedTuple

import numpy as np

from . import _core
from ._checks import _angles, _float_array, _one_state, _show, _states
from ._torus import Torus
from .riemann import HyperellipticCurve

__all__ = ["KINDS", "LABELS", "EulerMotion", "IntegratedValuesWarning", "Solution"]

#: Labels of the Wurzelfunktionen (27)–(28) entering (37) and (42), in the
#: order of :attr:`Solution.constants` and :attr:`Solution.characteristics`.
LABELS: tuple[str, ...] = ("P0", "P23", "P31", "P12", "P14", "P24", "P34")

#: The kinds of :attr:`Solution.kind`.


class IntegratedValuesWarning(UserWarning):
    """:meth:`Solution.l` returned values of an integration of (1) in double-double,
    confirmed by one with every step halved: for the kind ``"integrated"`` (no closed
    form), or where a genus-2 closed form disagreed with it (the message says why,
    and by how much)."""


KINDS: tuple[str, ...] = (
    "genus2",
    "rest",
    "spherical",
    "equilibrium",
    "euler",
    "separatrix",
    "integrated",
)

_WHY = {
    "rest": "l0 = 0, the state does not move",
    "spherical": "all c_ij are equal (b = alpha a + beta): every state is at rest",
    "equilibrium": "l0 is a stationary rotation (dl/dt = 0 by (1))",
    "euler": "l0 lies in an invariant so(3) and moves as an Euler top (elliptic functions)",
    "separatrix": "l0 lies in an invariant so(3), on the Euler top's separatrix",
    "integrated": "its closed form could not be built; l(t) is an integration of (1)",
}

#: What the one-state calls of the solution point to for many states.
_MANY_STATES = "manakov.frequency_map (frequencies) or top.integrate (trajectories)"


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


class EulerMotion(NamedTuple):
    """The Euler top of a solution of kind ``"euler"`` or ``"separatrix"``
    (normalized frame: ``l0/s``, ``c'``).

    ``Ṁ = M × (W∘M)``, i.e. ``Ṁ_1 = (W_3 − W_2) M_2 M_3`` and cyclically.

    Attributes
    ----------
    subalgebra : str
        ``"block 123"`` … ``"block 234"`` (``M = (l_jk, −l_ik, l_ij)``,
        ``W = −(c_jk, c_ik, c_ij)``), ``"self-dual"`` or ``"anti-self-dual"``
        (``n = ±m``, ``M = m``, ``W_j = −(c_kl + c_j4)``).
    W, M0 : ndarray, shape (3,)
    regime : str
        ``"elliptic"``, ``"axisymmetric"`` (trigonometric) or ``"separatrix"``.
    m, m1, omega : float
        The parameter ``m = k²``, ``1 − m`` and ``ω`` of
        ``M_b = X sn(ωt + u0 | m)`` (normalized time).

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> sol = manakov.ManakovTop(p.a, p.b).solve([0.7, -0.2, 0.0, 0.6, 0.0, 0.0])
    >>> sol.kind, sol.euler.subalgebra, sol.euler.regime
    ('euler', 'block 123', 'elliptic')
    """

    subalgebra: str
    W: np.ndarray
    M0: np.ndarray
    regime: str
    m: float
    m1: float
    omega: float


class Solution:
    """The solution through ``l0`` of the Manakov top with parameters ``a, b``.

    Usually made by :meth:`manakov.ManakovTop.solve`. :attr:`kind` says which
    representation holds (:data:`KINDS`); :meth:`l`, :attr:`frequencies`,
    :attr:`rotation_number` and :meth:`angles` work for every kind.

    Parameters
    ----------
    a, b : array_like, shape (4,)
        The parameters of (2).
    l0 : array_like, shape (6,)
        The initial state ``(l12, l13, l14, l23, l24, l34)``, any finite scale.

    Raises
    ------
    ValueError
        Invalid ``a``, ``b``, ``l0`` (shapes, non-finite values, repeated
        ``a_i``): only invalid input.

    Notes
    -----
    **Every valid state.** It gets a solution. Where the closed form cannot be built (a
    level set on which the Theorem's coordinates are singular to working
    precision: ``h1² = 4h0²`` off the exactly self-dual states, coinciding branch points, a
    repeated root of F (19), the divisor of ``l0`` at infinity, an iteration of the
    reduction that did not converge) it is of kind ``"integrated"``: the ``repr``
    names the step, :meth:`l` is an integration of (1) in double-double, confirmed
    with every step halved, at every call, with an ``IntegratedValuesWarning``, and
    there are no frequencies. A closed form that fails its self-check
    (:attr:`self_check` above 1e-10 or :attr:`velocity_check` above 1e-6, theta
    quotients that fit (1) at ``v0`` for no velocity, or level-set constants that
    fail the reduction's consistency checks) is returned marked
    (:attr:`self_check_passed` is False): its :meth:`l` is then certified by an
    integration at every call, or replaced by it where it is off, and what depends
    on its phase (:attr:`U`, :attr:`u0`, :attr:`constants`, the quotients) is
    refused with ``ClosedFormError``. Its :attr:`torus` and :attr:`frequencies`,
    which use none of the quotients' constants (only ``U``, ``U'`` and the
    curve), are those of :func:`manakov.frequency_map`: the level set's closed
    form where the map takes it unchecked, else given only where the Abel images
    of integrated states vouch for ``U`` and ``U'``, or lie on a line whose slope
    is the velocity (:attr:`torus`).

    **Frames.** The solution is built on normalized data: ``l0' = l0/s``,
    ``a' = (a − κ)/σ``, ``c' = (c − μ)/λ`` (:attr:`state_scale`,
    :attr:`frame`), with ``l(t) = s l'(T t)``, ``T = s λ``
    (:attr:`time_scale`). Scales are powers of two and shifts exact, so the
    normalized data are the given ones moved exactly; for moderate data
    (``max |l0_q|``, the geometric mean of the largest and smallest nonzero
    ``|a_i|`` and the half-spread of ``c`` in ``[2^-16, 2^16]``, no clustered
    ``a`` or ``c``) the frame is the identity.
    The genus-2 attributes (:attr:`tau`, :attr:`U`, :attr:`u0`,
    :attr:`riemann_constant`, :attr:`curve`, :attr:`constants`, …) are those
    of the normalized problem: ``u(t) = u0 + U T t``. :meth:`l`,
    :attr:`frequencies`, :attr:`torus` (its frequencies) and :meth:`abel`
    (its argument) are in the user's frame.

    **Genus 2.** Branches (``√c_j``, the roots of ``F``, the sheets, the sign
    of ``g``) are fixed once from ``l0``. ``l(v)`` is periodic only under a
    sublattice of the period lattice, so ``v(t)`` is never reduced modulo the
    lattice itself: in lattice coordinates ``v = x + τ y`` the real
    ``x(t), y(t)`` are reduced modulo 2 (an even lattice vector multiplies
    every ``θ[χ]`` by one common factor), with the products of the rates and
    ``t`` split error-free, so that ``l(10**6)`` costs and keeps what ``l(1)``
    does.

    Attributes that exist for one kind only (the genus-2 ones, :attr:`euler`)
    raise ``AttributeError`` naming the kind on the others.

    Examples
    --------
    >>> import numpy as np, manakov
    >>> p = manakov.problem("generic")
    >>> sol = manakov.ManakovTop(p.a, p.b).solve(p.l0)
    >>> sol.kind
    'genus2'
    >>> bool(np.abs(sol.l(0.0) - p.l0).max() < 1e-12)
    True
    >>> print(sol.frequencies.round(6))
    [0.264922 0.278362]
    """

    __slots__ = ("_a", "_b", "_l0", "_motion", "_core", "_curve", "_torus", "_freq")

    def __init__(self, a: Any, b: Any, l0: Any) -> None:
        aa = _float_array(a, "a").astype(float)
        bb = _float_array(b, "b").astype(float)
        for name, arr in (("a", aa), ("b", bb)):
            if arr.shape != (4,):
                raise ValueError(f"{name} must have shape (4,), got {arr.shape}")
        ll = _one_state(l0, 6, "l0", "solve", _MANY_STATES)
        self._a, self._b, self._l0 = _frozen(aa.copy()), _frozen(bb.copy()), _frozen(ll.copy())
        self._motion = _core.MotionCore(self._a, self._b, self._l0)
        self._core = self._motion.genus2()
        self._curve: HyperellipticCurve | None = None
        self._torus: Torus | None = None
        self._freq: np.ndarray | None = None

    @property
    def kind(self) -> str:
        """The representation of the motion, one of :data:`KINDS`.

        ``"genus2"``: the Theorem (9)–(10); ``"euler"``: an Euler top in an
        so(3) block or a self-dual state (elliptic functions);
        ``"separatrix"``: the same on its separatrix; ``"integrated"``: a
        genus-2 state whose closed form could not be built (a step of the
        reduction refused it), whose :meth:`l` is an integration of (1) in
        double-double confirmed by one with every step halved, at every call; ``"rest"``,
        ``"spherical"``, ``"equilibrium"``: ``l(t) = l0``.
        """
        return str(self._motion.kind)

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

    @property
    def state_scale(self) -> float:
        """``s``: the normalized state is ``l0/s`` (a power of two)."""
        return float(self._motion.state_scale)

    @property
    def time_scale(self) -> float:
        """``T = s λ``: ``l(t) = s l'(T t)`` (a power of two)."""
        return float(self._motion.time_scale)

    @property
    def frame(self) -> dict[str, Any]:
        """The normalized top: ``a' = (a − κ)/σ`` and ``c' = (c − μ)/λ``
        (state order), with ``kappa, sigma, mu, lambda``."""
        a, c, (kappa, sigma, mu, lam) = self._motion.frame()
        return {
            "a": _frozen(a),
            "c": _frozen(c),
            "kappa": kappa,
            "sigma": sigma,
            "mu": mu,
            "lambda": lam,
        }

    def _genus2(self, what: str, checked: bool = False) -> Any:
        if self._core is None:
            kind = self.kind
            raise AttributeError(
                f"{what} exists for a genus-2 solution only; this one is of kind "
                f"'{kind}' ({_WHY.get(kind, kind)})"
            )
        if checked and self._core.certify_every is not None:
            raise _core.ClosedFormError(
                f"no trustworthy {what}: {self._core.certify_every}; of this solution only "
                "l(t) is returned, where an integration of (1) certifies it"
            )
        return self._core

    @property
    def self_check_passed(self) -> bool:
        """Whether the closed form passed its checks: the self-check
        (:attr:`self_check` at most 1e-10 and :attr:`velocity_check` at most 1e-6),
        the fit of its theta quotients to (1) at ``v0``, and the reduction's
        consistency checks (the structure (38)/(40) of ``H0``, the corrected (42));
        True for the closed forms of the other kinds, False for ``"integrated"``
        (no closed form).

        Where it did not, the solution is kept for its :meth:`l` only: each call
        integrates (1) from ``l0`` to the requested times (Gauss–Legendre order 16
        at its default step, in double and, where that disagrees, in double-double)
        and returns the closed form's values where the two agree to 5e-11
        ``|l0|`` at every requested time, else the integration's own where it is
        confirmed (:meth:`l`, Notes), else raises ``ClosedFormError``. The
        self-check's points spread over the whole torus, and a closed form that
        misses some of them can still be right along the part of the motion that is
        evaluated (docs/degenerate.md, "Solutions that fail the self-check").
        """
        if self._core is None:
            return self.kind != "integrated"
        return self._core.certify_every is None

    def l(self, t: Any, precise: bool = False) -> np.ndarray:
        """The state at time(s) ``t``.

        By the Theorem (9)–(10) for a genus-2 state, Jacobi's elliptic
        functions for an Euler top, ``l0`` for the constant kinds, an
        integration of (1) for the kind ``"integrated"`` (Notes).

        Parameters
        ----------
        t : float or array_like
            Times (any real; ``|t|`` up to ~1e15 keeps the phase exact).
        precise : bool, default False
            Evaluate the Theorem to the floating-point floor: its constants
            (``τ``, the phase ``v0``, the weights of the quotients) polished in
            double-double against the conditions that define them, and the theta
            quotients summed in double-double (Notes). About 0.04 s once per
            solution and ~0.2 ms per time and thread, against ~0.1 µs; genus-2 and
            constant kinds only.

        Returns
        -------
        ndarray
            Shape ``(6,)`` for scalar ``t``, ``(..., 6)`` for an array.

        Raises
        ------
        ValueError
            Non-finite ``t``.
        ClosedFormError
            With ``precise=True``: for the Euler and integrated kinds, for a
            genus-2 solution whose ``U`` is not the closed form or which failed its
            self-check, where the polished constants leave a residual above
            1e-17 in their defining conditions, and beyond the precise phase
            horizon (where ``1e-18 |t| |dl/dt|``, the lattice rates' accuracy
            times the speed, exceeds 1e-6 ``|l0|``).
            Otherwise: where the closed form cannot be trusted at ``t`` and no integration
            could stand in for it (below); and, for any kind with a moving phase,
            beyond its phase horizon: where the rounding of the velocity alone
            (4 ulp) moves ``l(t)`` by more than 1e-6 ``|l0|`` (e.g. ``|t| ~ 1e12``
            on a top and state of unit size), the phase is no longer determined by
            double precision.

        Warns
        -----
        IntegratedValuesWarning
            The values returned are those of an integration of (1), not of the
            closed form (below); :attr:`integrated_calls` counts such calls.

        Notes
        -----
        For the kind ``"integrated"`` every call integrates (1) from ``l0`` to the
        requested times, in double-double at the default step and again with every
        step halved until two successive runs agree to 5e-12 ``|l0|`` (within 2e5
        steps in all), and returns the finest run's values, with an
        :class:`IntegratedValuesWarning`; otherwise ``ClosedFormError``.

        A genus-2 closed form is checked against an integration of (1) from ``l0``
        (Gauss–Legendre order 16 at its default step, in double and, where that
        disagrees, in double-double) where it cannot vouch for itself:

        * when its drift defect ``δ`` (:attr:`drift_defect`) is above rounding
          (1e-12), at the times where the drift ``δ |t| |dl/dt| / |l0|`` of its
          phase may exceed 5e-11 (the first such call integrates; later calls
          within the certified ``|t|`` do not);
        * at every call and every requested time, when it failed its self-check
          (:attr:`self_check_passed` False).

        Where the two agree to 5e-11 ``|l0|`` at every requested time, the closed
        form's values are returned. Where they do not, the closed form is the one
        that is off if the same integration in double-double with every step
        halved agrees with the one at the default step to 5e-12 ``|l0|`` (order 16:
        the half step's truncation error is 2^-16 of the default step's; where they
        differ by more, the steps are halved again until two successive runs agree,
        as long as each halving shrinks the difference at least fourfold):
        then the finest run's values are returned, at every requested time of that
        direction of time, with an :class:`IntegratedValuesWarning`. Otherwise, or
        where the integrations would take more than 2e6 steps (in double-double 5e4
        for the first run, 2e5 for all runs together), ``ClosedFormError``.

        With ``precise=True`` the constants are fixed by Gauss–Newton in
        double-double: at twelve points ``v0 + U t_k`` of the torus (``U`` in
        closed form, its lattice rates already in double-double) the quotients
        must be real, keep the integrals (6)–(7) of ``l0`` and obey Frahm's
        equations (1), and at ``t = 0`` give ``l0``. The double set-up leaves these
        conditions ~1e-15 off; the polished constants leave 1e-23 … 1e-20 on the
        shared tops, and ``l(t)`` is then within about half an ulp of ``|l0|`` of a
        long-double reference up to ``t = 100``, where the double evaluation is off
        by 1e-15 … 3e-15 ``|l0|`` and Gauss–Legendre order 16 by ~2e-16 at best
        (docs/theorem.md, "Precise evaluation").
        """
        tt = _float_array(t, "t")
        if precise:
            return self._motion.l_precise(np.ascontiguousarray(tt.reshape(-1))).reshape(
                tt.shape + (6,)
            )
        before = self.integrated_calls
        out = self._motion.l(np.ascontiguousarray(tt.reshape(-1)))
        if self.integrated_calls != before:
            warnings.warn(
                f"l(t) of this state is an integration: {self._motion.stand_ins[1]}",
                IntegratedValuesWarning,
                stacklevel=2,
            )
        return out.reshape(tt.shape + (6,))

    @property
    def precise_residual(self) -> tuple[float, float]:
        """``(residual, correction)`` of the constants behind ``l(t, precise=True)``.

        ``residual``: the largest scaled defect the polished constants leave in the
        conditions that define them (real quotients, the integrals (6)–(7) of
        ``l0``, Frahm's (1) along ``U``, ``l(0) = l0``; at most 1e-17, else the
        precise evaluation is refused). ``correction``: the largest change the
        polish made to a constant of the double set-up (absolute for ``τ`` and the
        lattice coordinates of ``v0``, relative for the weights of the quotients).
        The first access runs the polish (about 0.04 s); it is kept.

        Raises
        ------
        ClosedFormError
            For every kind but ``"genus2"`` (a constant motion's precise ``l(t)`` is
            ``l0`` and needs no constants), and as ``l(t, precise=True)`` for a
            genus-2 solution with no precise evaluation.
        """
        r, c = self._motion.precise_polish()
        return float(r), float(c)

    @property
    def integrated_calls(self) -> int:
        """How many calls of :meth:`l` returned values of an integration of (1)
        (each also warns, :class:`IntegratedValuesWarning`): every call for the kind
        ``"integrated"``, those where it stood in for the closed form for
        ``"genus2"`` (:meth:`l`, Notes), none for the other kinds."""
        return int(self._motion.stand_in_calls)

    def abel(self, l: Any) -> np.ndarray:
        """The Abel image ``u(P1) + u(P2)`` (modulo the lattice) of states ``l``
        on the same level set, with the branches of ``l0``'s reduction (genus 2).

        ``l`` is in the user's frame; the image is on the normalized curve:
        along a trajectory ``abel(l(t)) ≡ u0 + U T t`` modulo the lattice
        (``T`` = :attr:`time_scale`).

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
        core = self._genus2("abel")
        flat, lead = _states(l, 6, "l")
        s = self.state_scale
        out = np.empty((flat.shape[0], 2), dtype=complex)
        for i, x in enumerate(flat):
            out[i] = core.abel(np.ascontiguousarray(x / s))
        return out.reshape(lead + (2,))

    @property
    def u0(self) -> np.ndarray:
        """``u0 = u(P1) + u(P2)`` at ``t = 0`` (Abel map, base point ∞; ``v0 = u0 + K``).

        ``ClosedFormError`` where :attr:`self_check_passed` is False."""
        return _frozen(self._genus2("u0", checked=True).u0)

    @property
    def U(self) -> np.ndarray:  # noqa: N802 (the paper's name)
        """``U``: ``u = u0 + U t'`` in the normalized time ``t' = T t``, from (1).

        ``ClosedFormError`` where :attr:`self_check_passed` is False."""
        return _frozen(self._genus2("U", checked=True).rate)

    @property
    def tau(self) -> np.ndarray:
        """The period matrix ``τ`` of the curve (8) in :attr:`curve`'s basis."""
        return _frozen(self._genus2("tau").tau)

    @property
    def riemann_constant(self) -> np.ndarray:
        """The vector of Riemann constants ``K`` (``v = u + K``)."""
        return _frozen(self._genus2("riemann_constant").riemann_constant)

    @property
    def curve(self) -> HyperellipticCurve:
        """The curve (8), ``y² = Π_{j=0}^{4} (x − d_j)``, with its homology basis."""
        core = self._genus2("curve")
        if self._curve is None:
            self._curve = HyperellipticCurve(core.branch_points)
        return self._curve

    @property
    def characteristics(self) -> dict[str, tuple[tuple[int, int], tuple[int, int]]]:
        """``χ_L = ([a1, a2], [b1, b2])`` for :data:`LABELS`: ``χ_j = η(d_j)``,
        ``χ_jk = χ_j + χ_k`` (mod 2)."""
        ch = self._genus2("characteristics").characteristics
        return {
            lab: ((int(r[0]), int(r[1])), (int(r[2]), int(r[3])))
            for lab, r in zip(LABELS, ch, strict=True)
        }

    @property
    def constants(self) -> dict[str, complex]:
        """``C_L`` of (34), ``P_L = C_L θ[χ_L](v)/θ(v)``, for :data:`LABELS`."""
        core = self._genus2("constants", checked=True)
        return {lab: complex(c) for lab, c in zip(LABELS, core.constants, strict=True)}

    @property
    def calibration(self) -> np.ndarray:
        """``|C_L − P_L(l0) θ(v0)/θ[χ_L](v0)| / |C_L|`` (``C_L`` from an auxiliary divisor)."""
        return _frozen(self._genus2("calibration").calibration)

    @property
    def self_check(self) -> float:
        """The largest relative defect of the quotients' shape found by the genus-2
        solution's own check when it was built.

        At ``t = 0`` and at points spread over the torus the quotients (9)–(10) must
        give a real state with the integrals (6)–(7) of ``l0``, and ``l(0) = l0``;
        defects are relative to ``|l0|`` and to the scales of the integrals. A
        solution is only returned when this is at most 1e-10 (correct set-ups leave
        ~1e-15 … 1e-11). Checked on the normalized data. Their motion is checked by
        :attr:`velocity_check`.
        """
        return float(self._genus2("self_check").self_check)

    @property
    def velocity_check(self) -> float:
        """The largest defect of Frahm's equations (1) for the quotients moving along
        ``U``, at the points of :attr:`self_check`, relative to the largest speed
        ``|dl/dt|`` met there.

        A solution is only returned when this is at most 1e-6. Generic states leave
        ~1e-15 … 1e-12; near an equilibrium or an so(3) block, where the motion is
        slow, up to ~1e-7 (the rounding of (1) at a state accurate to rounding,
        relative to a small speed). A wrong constant leaves O(1).
        """
        return float(self._genus2("velocity_check").velocity_check)

    @property
    def drift_defect(self) -> float:
        """The relative defect ``δ`` whose drift ``δ |t| |dl/dt| / |l0|`` :meth:`l`
        bounds (docs/degenerate.md, "The drift check").

        Where ``U`` is the closed form it is :attr:`velocity_check`: the phase runs at
        the frequencies of ``l0``'s own torus, so a defect of the quotients' shape
        stays where it is, while one of their motion drifts. Where ``U`` is the
        quotients' fit it is the larger of :attr:`self_check` and
        :attr:`velocity_check`.
        """
        return float(self._genus2("drift_defect").drift_defect)

    @property
    def torus(self) -> Torus:
        """The real torus of a genus-2 motion (docs/tori.md): a reduced basis
        ``λ1, λ2`` of the periods of ``l`` in the real plane of ``U`` and a
        second commuting flow (normalized frame), and ``(ν1, ν2)`` with
        ``U T = ν1 λ1 + ν2 λ2`` (cycles per unit of the user's time).

        The frequencies come from the lattice coordinates of ``U`` in closed
        form, in double-double where the branch points of (8) spread over more
        than two orders of magnitude; they are those of
        :func:`manakov.frequency_map` to the bit. Where the branch points spread
        over at most 1e14 both take the level set's closed form, and the torus is
        refused only where the map reports a failure; beyond that both take the
        solution's ``U``, with the checks below.

        Raises
        ------
        ClosedFormError
            The torus of this (valid) state could not be verified: the theta
            quotients' second flow disagrees with its closed form, no real
            lattice fits, or the self-check's velocity defect
            (:attr:`velocity_check`) is above 1e-10, which ``U`` and the
            frequencies would carry, or ``U`` is the theta quotients' fit at
            ``v0`` next to a pinched curve (where its closed form refused; the
            quotients then hardly depend on one direction of ``u``, and the fit
            can be off along it), or the solution failed its self-check
            (:attr:`self_check_passed` is False: its constants are in doubt,
            though the frequencies use none of them), and the Abel images of
            integrated states do not vouch for ``U`` to 5e-11 and ``U'`` to 1e-8
            either (at three of thirteen times one to four periods out, at two
            integration steps; where ``U'`` cannot be checked, the lattice basis
            it fixes must be integral to 1e-7; docs/degenerate.md §10), nor lie
            on a line to those bounds (at seven of the thirteen times at least,
            whose slope, the velocity the images move at, the frequencies then
            rest on; :attr:`U`, which :meth:`l` uses, stays as it is). The
            message names the step.
        """
        # Even a solution that failed its self-check has the frequency map's torus
        # (the level set's closed form, or U and U' the Abel images vouch for or
        # move at).
        self._genus2("torus")
        if self._torus is None:
            lam, coords, nu, _ = self._motion.torus()
            self._torus = Torus(_frozen(lam), _frozen(coords), _frozen(nu))
        return self._torus

    @property
    def euler(self) -> EulerMotion:
        """The Euler top of a solution of kind ``"euler"`` or ``"separatrix"``."""
        e = self._motion.euler()
        if e is None:
            kind = self.kind
            raise AttributeError(
                f"euler exists for the kinds 'euler' and 'separatrix' only; this solution is "
                f"of kind '{kind}'"
            )
        sub, w, m0, regime, (m, m1, omega) = e
        return EulerMotion(sub, _frozen(np.array(w)), _frozen(np.array(m0)), regime, m, m1, omega)

    @property
    def frequencies(self) -> np.ndarray:
        """``(ν1, ν2) ≥ 0`` in cycles per unit time.

        * ``"genus2"``: ``U T = ν1 λ1 + ν2 λ2`` on the reduced basis of :attr:`torus`.
          Where the torus is refused for a state within 1e-2 (relative) of an
          so(3) block whose Euler orbit is transversally elliptic, or within
          1e-3 of a self-dual state: the interpolation (in the squared distance
          next to a block, in the distance itself next to the self-dual states)
          between that orbit's ``(ν_⊥, ν_E)`` and the tori of four states
          farther out (1e-3 … 8e-3 from a block, 1e-5 … 8e-5 from the self-dual
          states, or at least eight times the state's distance), in the reduced
          basis of the nearest of them, given only where its bound is at most
          5e-11 (docs/degenerate.md §11). Next to a block whose orbit is
          transversally hyperbolic: ``1/ν2`` and ``(ν1 ∓ ν_E)/ν2`` fitted in
          ``ln(1/σ)`` (``σ`` the distance; slope ``2/λ`` for ``1/ν2``, ``λ`` the
          orbit's exponent) to the tori of seven states farther out, under the
          same bound. Next to a coordinate plane of equilibria: the same from
          the equilibrium's normal modes or saddle rates. Where all of these
          refuse: the frequencies' definition, ``ν = Λ⁻¹ e1`` for the lattice
          ``Λ`` of times ``(t1, t2)`` after which the flows of ``H`` and of a
          second Hamiltonian of Manakov's family bring ``l0`` back to itself,
          from closed orbits integrated in double-double and checked against
          half steps to 1e-12 (a reduced basis of the same module, which may
          differ from the torus's). :func:`manakov.frequency_map` gives the same
          numbers. Otherwise the torus's ``ClosedFormError``.
        * ``"integrated"`` (``l(t)`` by a confirmed integration): the same
          routes where they apply (within ~1e-6 of the self-dual states,
          where ``h1² = 4 h0²`` to rounding, the motion is of this kind);
          otherwise ``ClosedFormError``.
        * ``"euler"``: the orbit is closed (a 1-torus); ``ν2 = ν_E = ω/(4K)``, its
          frequency, and ``ν1 = ν_⊥ ∈ [0, ν_E/2]``, the rotation number of the
          linearized motion off the invariant so(3) along the orbit (the angle
          ``θ ∈ [0, π]`` of its monodromy over one period, ``ν_⊥ = θ ν_E/(2π)``).
          The genus-2 tori near the orbit have frequencies tending to
          ``(|ν_⊥ + k ν_E|, ν_E)`` for an integer ``k`` of their reduced basis
          (docs/degenerate.md §5). If the orbit is transversally hyperbolic
          (possible for so(3) blocks), ``ν1 = 0``: no tori shrink onto it.
        * ``"separatrix"``: ``(0, 0)``: no period (the limit of both).
        * ``"rest"``, ``"spherical"``, ``"equilibrium"``: ``(0, 0)``.
        """
        if self._freq is not None:
            return self._freq
        if self._core is not None:
            try:
                return self.torus.frequencies
            except _core.ClosedFormError as refused:
                return self._near_euler(refused)
        try:
            # An Euler motion integrates its transverse monodromy once (0.1-10 ms).
            self._freq = _frozen(np.array(self._motion.closed_form_frequencies()))
        except _core.ClosedFormError as refused:
            if self.kind != "integrated":
                raise
            return self._near_euler(refused)
        return self._freq

    def _near_euler(self, refused: Exception) -> np.ndarray:
        """The frequencies interpolated next to an Euler subspace or a coordinate
        plane, else those of the closed orbits of the commuting flows, kept; else
        the original refusal, which names its cause."""
        try:
            nu = self._motion.near_euler_frequencies()
        except _core.ClosedFormError:
            try:
                nu = self._motion.closed_orbit_frequencies()
            except _core.ClosedFormError:
                raise refused from None
        self._freq = _frozen(np.array(nu))
        return self._freq

    @property
    def rotation_number(self) -> float:
        """``ν1/ν2`` (``inf`` when ``ν2 = 0 < ν1``, NaN when both vanish)."""
        n1, n2 = (float(v) for v in self.frequencies)
        if n2 != 0.0:
            return n1 / n2
        return float("inf") if n1 != 0.0 else float("nan")

    def angles(self, t: Any) -> np.ndarray:
        """Torus angles ``(ν1 t, ν2 t) mod 1`` from the initial point, shape ``(..., 2)``.

        Raises ValueError for ``t`` not real or not finite, or ``|ν t|`` beyond
        2^52 cycles (the angle is not determined in double precision).
        """
        return _angles(t, self.frequencies)

    def quotient(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(idx, num, den)``: ``l_q = Re(Σ_m num[q, m] θ[idx[m]](v) / Σ_m den[m] θ[idx[m]](v))``
        (theta indices in the package's characteristic order; normalized frame)."""
        return self._genus2("quotient", checked=True).quotient()

    def __repr__(self) -> str:
        if self._core is not None:
            d = ", ".join(_show(x, 6) for x in self._core.branch_points)
            if self._core.certify_every is not None:
                return (
                    f"Solution(curve: y^2 = prod (x - d_j), d = [{d}]; self-check failed: "
                    "l(t) certified by an integration at each call)"
                )
            u = ", ".join(_show(x, 12) for x in self._core.rate)
            return f"Solution(curve: y^2 = prod (x - d_j), d = [{d}]; U = [{u}])"
        e = self._motion.euler()
        if e is not None:
            sub, w, _, regime, (m, _, _) = e
            return f"Solution(kind={self.kind!r}, {sub}, {regime}, m = {m:.12g})"
        if self.kind == "integrated":
            return f"Solution(kind='integrated', {self._motion.stand_ins[1]})"
        return f"Solution(kind={self.kind!r}, l = {self._l0.tolist()})"
