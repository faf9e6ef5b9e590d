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
from ._checks import _float_array
from ._torus import Torus, torus_of_state
from .riemann import HyperellipticCurve

__all__ = ["LABELS", "Solution", "plot_theorem"]

#: Labels of the Wurzelfunktionen (27)–(28) entering (37) and (42), in the
#: order of :attr:`Solution.constants` and :attr:`Solution.characteristics`.
LABELS: tuple[str, ...] = ("P0", "P23", "P31", "P12", "P14", "P24", "P34")


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
        ll = _float_array(l0, "l0").astype(float)
        for name, arr, n in (("a", aa, 4), ("b", bb, 4), ("l0", ll, 6)):
            if arr.shape != (n,):
                raise ValueError(f"{name} must have shape ({n},), got {arr.shape}")
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
        """The Abel image ``u(P1) + u(P2)`` (modulo the lattice) of a state ``l``
        on the same level set, with the branches of ``l0``'s reduction.

        Along a trajectory ``abel(l(t)) ≡ u0 + U t`` modulo the lattice.

        Parameters
        ----------
        l : array_like, shape (6,)

        Returns
        -------
        ndarray, complex, shape (2,)
        """
        ll = _float_array(l, "l").astype(float)
        if ll.shape != (6,):
            raise ValueError(f"l must have shape (6,), got {ll.shape}")
        return self._core.abel(np.ascontiguousarray(ll))

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


def _show(x: complex, digits: int) -> str:
    """``x`` to ``digits`` significant digits, without a real or imaginary part
    below the shown precision (rounding noise such as ``3.19+7e-32j``)."""
    x = complex(x)
    cut = abs(x) * 10.0 ** (-digits)
    re = x.real if abs(x.real) > cut else 0.0
    im = x.imag if abs(x.imag) > cut else 0.0
    if im == 0.0:
        return f"{re:.{digits}g}"
    if re == 0.0:
        return f"{im:.{digits}g}j"
    return f"{complex(re, im):.{digits}g}"


def plot_theorem(
    problem_name: str,
    path: str,
    *,
    t_end: float = 100.0,
    samples: int = 201,
    dt: float = 1e-3,
) -> float:
    """Plot ``l(t)`` from the theta quotients against gauss16 integration, and
    their difference on a log scale, as a PNG.

    Parameters
    ----------
    problem_name : str
        A name of :func:`manakov.problem_names`.
    path : str
        The PNG file to write.
    t_end : float
        End time (> 0).
    samples : int
        Number of times in ``[0, t_end]`` (≥ 2).
    dt : float
        The gauss16 step.

    Returns
    -------
    float
        ``max_t |l_theta − l_int| / |l0|``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .problems import problem

    if not (t_end > 0 and np.isfinite(t_end)):
        raise ValueError(f"t_end must be finite and > 0, got {t_end}")
    if int(samples) < 2:
        raise ValueError(f"samples must be >= 2, got {samples}")
    p = problem(problem_name)
    sol = Solution(p.a, p.b, p.l0)
    t = np.linspace(0.0, float(t_end), int(samples))
    c = _core.manakov_c(np.asarray(p.a, float), np.asarray(p.b, float))
    l_int, _, _, err = _core.integrate(
        c, np.asarray(p.l0, float), 0.0, t, "gauss16", float(dt), 0.0, 0.0, 10**9
    )
    if err is not None:
        raise err
    l_int = np.asarray(l_int).reshape(len(t), 6)
    l_th = sol.l(t)
    diff = np.max(np.abs(l_th - l_int), axis=1) / np.linalg.norm(p.l0)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    names = ["l12", "l13", "l14", "l23", "l24", "l34"]
    for q in range(6):
        ax1.plot(t, l_th[:, q], label=names[q])
        ax1.plot(t, l_int[:, q], "k:", lw=0.8)
    ax1.set_ylabel("l(t): theta quotients (lines), gauss16 (dotted)")
    ax1.legend(ncol=6, fontsize=7)
    ax1.set_title(f"{problem_name}: {sol!r}"[:110], fontsize=8)
    ax2.semilogy(t, np.maximum(diff, 1e-18))
    ax2.set_xlabel("t")
    ax2.set_ylabel("max |l_theta - l_int| / |l0|")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return float(diff.max())
