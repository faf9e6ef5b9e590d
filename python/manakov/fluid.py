"""A rigid body in an ideal fluid: Kirchhoff's equations, the integrable cases,
and the Clebsch case in genus-2 theta functions.

State convention
----------------
The impulsive couple ``M`` and the impulsive force ``p`` in the body frame,
each of shape ``(..., 3)``. The energy is a positive definite quadratic form

.. math::

    H = \\tfrac12 (M^T A M + 2 M^T B p + p^T C p),

``A``, ``C`` symmetric, ``B`` any 3 × 3 (21 coefficients: the body's inertia
and the fluid's added masses), and the motion is Kirchhoff's

.. math::

    \\dot M = M \\times \\partial H/\\partial M + p \\times \\partial H/\\partial p,
    \\qquad \\dot p = p \\times \\partial H/\\partial M

(G. Kirchhoff, J. Reine Angew. Math. 71 (1870) 237–262), with the Casimirs
``p·p`` and ``M·p`` and the energy ``H`` conserved. ``ω = ∂H/∂M`` is the
angular velocity and ``v = ∂H/∂p`` the velocity of the body's origin.

The Clebsch case (``A``, ``C`` diagonal, ``B = 0``,
``(C2 − C3)/A1 + (C3 − C1)/A2 + (C1 − C2)/A3 = 0``) is linearly conjugate to a
Manakov top on so(4) (the Möbius image of the contraction ``a4 → ∞`` of the
top), so :meth:`KirchhoffBody.solve` gives ``M(t)``, ``p(t)`` as quotients of
genus-2 theta functions with arguments linear in ``t``: docs/clebsch.md.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import Any, Callable, NamedTuple

import numpy as np

from . import _core
from ._checks import _finite_result, _float_array
from ._core import ClosedFormError
from .solution import Solution
from .top import DEFAULT_MAX_STEPS, DEFAULT_RTOL, MAX_SAMPLES, METHODS, ManakovTop
from .tori import FrequencyMap
from .tori import frequency_map as _frequency_map

__all__ = [
    "CASES",
    "CLEBSCH_RTOL",
    "DT_SCALE",
    "ClebschSolution",
    "FluidProblem",
    "FluidTrajectory",
    "KirchhoffBody",
    "SpaceTrajectory",
    "fluid_problem",
    "fluid_problem_names",
    "plot_clebsch_theorem",
    "plot_motion",
    "plot_space_trajectory",
]

#: The integrable cases :class:`KirchhoffBody` knows by name (``"general"``: none).
CASES = ("general", "clebsch", "kirchhoff", "lyapunov_steklov")

#: Methods for Kirchhoff's equations: those of the top but Taylor's (so(4) only).
_METHODS = tuple(m for m in METHODS if m != "taylor")
_EXPLICIT = ("dopri5", "dop853")

#: Default Gauss step in units of ``1/Ω``, ``Ω = ‖Q'‖₂ |(M0, p0)|`` (``Q'`` the
#: energy matrix without its Casimir parts, :attr:`KirchhoffBody.rate_scale`).
#: gauss16 at ``1/Ω`` is at roundoff: ≤ 6.7e-14 against a 20× smaller step on 8
#: random dense bodies (t = 2) and the seven reference bodies (t = 20), with 11–16
#: stage sweeps per step; at ``1.5/Ω`` up to 1.8e-10 (tests/data/fluid_step_study.py).
#: gauss4 and gauss6 keep the so(4) top's ratios to gauss16.
DT_SCALE = {"gauss4": 0.007, "gauss6": 0.03, "gauss16": 1.0}

#: Clebsch's condition must hold to this fraction of ``Σ |C_j − C_k|/A_i`` (the
#: core's ``fluid::clebsch::CLEBSCH_RTOL``): coefficients computed in floating
#: point violate it by a few ulps; a larger violation is another body, which the
#: closed form would silently replace by its nearest Clebsch body.
CLEBSCH_RTOL = 1e-12

_CYC = ((0, 1, 2), (1, 2, 0), (2, 0, 1))


def _scalar(x: Any, what: str) -> float:
    arr = np.asarray(x)
    if arr.ndim != 0 or arr.dtype.kind not in "biuf":
        raise ValueError(f"{what} must be a real scalar, got {x!r}")
    v = float(arr)
    if not math.isfinite(v):
        raise ValueError(f"{what} must be finite, got {v}")
    return v


def _matrix(x: Any, what: str) -> np.ndarray:
    arr = _float_array(x, what)
    if arr.shape != (3, 3):
        raise ValueError(f"{what} must have shape (3, 3), got {arr.shape}")
    out = np.array(arr, dtype=float, order="C")
    out.setflags(write=False)
    return out


def _vector3(x: Any, what: str) -> np.ndarray:
    arr = _float_array(x, what)
    if arr.shape != (3,):
        raise ValueError(f"{what} must have shape (3,), got {arr.shape}")
    return np.array(arr, dtype=float)


def _pair(x: Any, what: str) -> tuple[float, float]:
    arr = _float_array(x, what)
    if arr.shape != (2,):
        raise ValueError(f"{what} must have shape (2,) (axes 1, 2 and axis 3), got {arr.shape}")
    return float(arr[0]), float(arr[1])


def _states(M: Any, p: Any, names: tuple[str, str] = ("M", "p")) -> tuple[np.ndarray, tuple]:
    """``(M, p)`` broadcast to a C-contiguous (N, 6) array and the leading shape."""
    Ma, pa = _float_array(M, names[0]), _float_array(p, names[1])
    for name, arr in zip(names, (Ma, pa)):
        if arr.ndim == 0 or arr.shape[-1] != 3:
            raise ValueError(f"{name} must have shape (..., 3), got {arr.shape}")
    try:
        lead = np.broadcast_shapes(Ma.shape[:-1], pa.shape[:-1])
    except ValueError:
        raise ValueError(
            f"{names[0]} and {names[1]} do not broadcast: shapes {Ma.shape}, {pa.shape}"
        ) from None
    y = np.concatenate(
        [np.broadcast_to(Ma, lead + (3,)), np.broadcast_to(pa, lead + (3,))], axis=-1
    )
    return np.ascontiguousarray(y.reshape(-1, 6)), lead


def _split(y: np.ndarray, lead: tuple) -> tuple[np.ndarray, np.ndarray]:
    y = y.reshape(lead + (6,))
    return np.ascontiguousarray(y[..., :3]), np.ascontiguousarray(y[..., 3:])


def _out(values: np.ndarray, lead: tuple) -> Any:
    values = _finite_result(values, "this state: rescale M and p")
    res = values.reshape(lead)
    return res[()] if res.ndim == 0 else res


@dataclass(frozen=True)
class FluidTrajectory:
    """A sampled solution of Kirchhoff's equations.

    Attributes
    ----------
    t : ndarray, shape (S,)
        Sample times.
    M, p : ndarray, shape (S, 3)
        The impulsive couple and force at the sample times (body frame).
    integrals : dict of str to ndarray (S,)
        :meth:`KirchhoffBody.integrals` along the samples.
    method : str
    dt : float
        The largest step (Gauss methods) or the initial step (explicit; 0 = automatic).
    steps, evals : int
        Steps taken and vector-field evaluations.

    Examples
    --------
    >>> import manakov
    >>> pr = manakov.fluid_problem("clebsch_generic")
    >>> tr = pr.body.integrate(pr.M0, pr.p0, 10.0, sample_every=1.0)
    >>> tr.M.shape, tr.p.shape, max(tr.max_drift().values()) < 1e-13
    ((11, 3), (11, 3), True)
    """

    t: np.ndarray
    M: np.ndarray
    p: np.ndarray
    integrals: dict[str, np.ndarray]
    method: str
    dt: float
    steps: int
    evals: int

    def relative_drift(self) -> dict[str, np.ndarray]:
        """``|I(t) − I(t0)| / |I(t0)|`` for each integral (absolute if ``I(t0) = 0``).

        Returns
        -------
        dict of str to ndarray, shape (S,)
        """
        out = {}
        for name, v in self.integrals.items():
            if v.size == 0:
                out[name] = np.zeros(0)
                continue
            ref = abs(v[0]) if v[0] != 0 else 1.0
            out[name] = np.abs(v - v[0]) / ref
        return out

    def max_drift(self) -> dict[str, float]:
        """The largest relative drift of each integral.

        Returns
        -------
        dict of str to float
        """
        return {k: float(np.max(v, initial=0.0)) for k, v in self.relative_drift().items()}


@dataclass(frozen=True)
class SpaceTrajectory:
    """The body's motion in space (:meth:`KirchhoffBody.motion_in_space`).

    Attributes
    ----------
    t : ndarray, shape (S,)
    M, p : ndarray, shape (S, 3)
        Impulsive couple and force in the body frame.
    R : ndarray, shape (S, 3, 3)
        The rotation body → space: a body vector ``u`` is ``R @ u`` in space.
    x : ndarray, shape (S, 3)
        The position of the body's origin in space.
    method : str
    dt : float
    steps, evals : int

    Examples
    --------
    >>> import numpy as np, manakov
    >>> pr = manakov.fluid_problem("clebsch_generic")
    >>> sp = pr.body.motion_in_space(pr.M0, pr.p0, 5.0, sample_every=0.5)
    >>> P = sp.impulse()
    >>> sp.x.shape, bool(np.abs(P - P[0]).max() < 1e-12)
    ((11, 3), True)
    """

    t: np.ndarray
    M: np.ndarray
    p: np.ndarray
    R: np.ndarray
    x: np.ndarray
    method: str
    dt: float
    steps: int
    evals: int

    def impulse(self) -> np.ndarray:
        """The impulse in space, ``P = R p`` (constant along the motion), shape (S, 3)."""
        return np.einsum("sij,sj->si", self.R, self.p)

    def moment(self) -> np.ndarray:
        """The moment of the impulse about the space origin, ``K = R M + x × P``
        (constant along the motion), shape (S, 3)."""
        return np.einsum("sij,sj->si", self.R, self.M) + np.cross(self.x, self.impulse())


class KirchhoffBody:
    """A rigid body in an ideal fluid with ``H = ½ (Mᵀ A M + 2 Mᵀ B p + pᵀ C p)``.

    Parameters
    ----------
    A, C : array_like, shape (3, 3)
        Symmetric (to 8 ulps).
    B : array_like, shape (3, 3)
        The coupling ``∂²H/∂M_i ∂p_j = B_ij``.

    Raises
    ------
    ValueError
        Wrong shapes, non-finite values, ``A`` or ``C`` not symmetric, or
        ``[[A, B], [Bᵀ, C]]`` not positive definite (the message gives its
        eigenvalues; ``H + ½ κ p·p + μ M·p`` has the same motion and may be).

    Notes
    -----
    The integrable cases are recognised from the coefficients (:attr:`case`):
    ``"clebsch"`` (``A``, ``C`` diagonal, ``B = 0``, Clebsch's condition to
    ``CLEBSCH_RTOL``), ``"kirchhoff"`` (diagonal, two axes alike), and
    ``"lyapunov_steklov"`` when made by :meth:`lyapunov_steklov`. The named
    constructors :meth:`clebsch`, :meth:`kirchhoff`, :meth:`lyapunov_steklov`
    build them from their parameters and add their extra integral to
    :meth:`integrals`.

    Examples
    --------
    >>> import manakov
    >>> import numpy as np
    >>> A, C = np.diag([0.7, 1.3, 2.2]), np.diag([3.216, 2.424, 2.046])
    >>> body = manakov.KirchhoffBody(A, np.zeros((3, 3)), C)
    >>> body.case
    'clebsch'
    >>> ints = body.integrals([0.4, -0.7, 0.9], [0.8, 0.3, -0.5])
    >>> print({k: round(float(v), 6) for k, v in ints.items()})
    {'pp': 0.98, 'Mp': -0.34, 'H': 2.65945, 'F': 1.6142}
    """

    def __init__(self, A: Any, B: Any, C: Any) -> None:
        self._A, self._B, self._C = _matrix(A, "A"), _matrix(B, "B"), _matrix(C, "C")
        self._core = _core.KirchhoffCore(self._A, self._B, self._C)
        self._case = "general"
        self._axis = -1
        self._clebsch: Any = None
        self._steklov: tuple[np.ndarray, float] | None = None
        self._detect()

    def _detect(self) -> None:
        A, B, C = self._A, self._B, self._C
        off = ~np.eye(3, dtype=bool)
        if np.any(A[off] != 0) or np.any(B[off] != 0) or np.any(C[off] != 0):
            return
        a, b, c = np.diag(A), np.diag(B), np.diag(C)
        for k in range(3):
            i, j = [m for m in range(3) if m != k]
            if a[i] == a[j] and b[i] == b[j] and c[i] == c[j]:
                self._case, self._axis = "kirchhoff", k
                return
        if np.all(b == 0):
            try:
                self._clebsch = _core.ClebschCore(a, c)
            except ValueError:
                return
            self._case = "clebsch"

    # -- named constructors ---------------------------------------------------

    @classmethod
    def clebsch(cls, A: Any, C: Any) -> KirchhoffBody:
        """Clebsch's integrable case: ``A = diag(A_i)``, ``B = 0``, ``C = diag(C_i)`` with
        ``(C2 − C3)/A1 + (C3 − C1)/A2 + (C1 − C2)/A3 = 0``.

        The solutions of Clebsch's condition are ``C_i = κ + θ A_j A_k``
        (``(i, j, k)`` cyclic; for ``A1 = A2 = A3`` every ``C``). The extra integral
        (A. Clebsch, *Über die Bewegung eines Körpers in einer Flüssigkeit*,
        Math. Ann. 3 (1871) 238–262) is

        ``F = Σ M_i² − Σ a_i p_i²``,  ``a_j − a_k = (C_k − C_j)/A_i``, ``Σ a_i = 0``,

        which is ``Σ M_i² − θ Σ A_i p_i²`` up to a multiple of the Casimir ``p·p``.
        :meth:`solve` gives the motion in theta functions.

        Parameters
        ----------
        A, C : array_like, shape (3,)
            Positive (the energy must be positive definite; ``C + κ`` has the same
            motion). Clebsch's condition must hold to ``CLEBSCH_RTOL = 1e-12`` of
            the sum of its terms' moduli.

        Returns
        -------
        KirchhoffBody

        Raises
        ------
        ValueError
            Clebsch's condition fails; ``C_j = C_k`` (then ``A_j = A_k``: the
            axisymmetric case, elliptic, use :meth:`kirchhoff`); all ``C`` equal;
            a non-positive energy.
        """
        a, c = _vector3(A, "A"), _vector3(C, "C")
        conj = _core.ClebschCore(a, c)
        body = cls(np.diag(a), np.zeros((3, 3)), np.diag(c))
        body._case, body._clebsch = "clebsch", conj
        return body

    @classmethod
    def kirchhoff(cls, A: Any, B: Any, C: Any) -> KirchhoffBody:
        """Kirchhoff's integrable case: a body symmetric about its third axis,
        ``A = diag(A1, A1, A3)``, ``B = diag(B1, B1, B3)``, ``C = diag(C1, C1, C3)``.

        The extra integral is ``M3`` (G. Kirchhoff, *Über die Bewegung eines
        Rotationskörpers in einer Flüssigkeit*, J. Reine Angew. Math. 71 (1870)
        237–262): ``Ṁ3 = B1 (M1 p2 − M2 p1) + B1 (p1 M2 − p2 M1) = 0``.

        Parameters
        ----------
        A, B, C : array_like, shape (2,)
            ``(value on axes 1 and 2, value on axis 3)``.

        Returns
        -------
        KirchhoffBody
        """
        (a1, a3), (b1, b3), (c1, c3) = _pair(A, "A"), _pair(B, "B"), _pair(C, "C")
        body = cls(np.diag([a1, a1, a3]), np.diag([b1, b1, b3]), np.diag([c1, c1, c3]))
        body._case, body._axis, body._clebsch = "kirchhoff", 2, None
        return body

    @classmethod
    def lyapunov_steklov(
        cls, b: Any, eps: float, *, kappa: float = 0.0, mu: float = 0.0
    ) -> KirchhoffBody:
        """The Lyapunov–Steklov integrable case:
        ``H = ½ Σ_i (b_i M_i² + 2ε b_j b_k M_i p_i + ε² b_i (b_j − b_k)² p_i²)``
        ``+ ½ κ p·p + μ M·p`` (``(i, j, k)`` cyclic), with the extra integral

        ``F = ½ Σ_i (M_i² − 2ε b_i M_i p_i + ε² (b_j − b_k)² p_i²)``

        (V. A. Steklov, *Über die Bewegung eines festen Körpers in einer
        Flüssigkeit*, Math. Ann. 42 (1893) 273–294; A. M. Lyapunov, *A new case of
        integrability of the equations of motion of a rigid body in a fluid*
        (1893); the explicit solution: Yu. N. Fedorov, B. Basak, Regul. Chaotic
        Dyn. 16 (2011) 374–395; their notation may differ). The tests establish
        this form: ``F`` is conserved along the motion, and not when the sign of
        ``ε`` in ``H`` is flipped. The Casimir terms ``κ``, ``μ`` do not change the motion;
        they make the energy positive definite where the bare form is not.

        Parameters
        ----------
        b : array_like, shape (3,)
            Positive.
        eps : float
        kappa, mu : float, keyword-only
            Casimir terms: ``C → C + κ I``, ``B → B + μ I``.

        Returns
        -------
        KirchhoffBody

        Raises
        ------
        ValueError
            A non-positive energy (the message gives its eigenvalues; raise ``kappa``).
        """
        bb = _vector3(b, "b")
        e, k, m = _scalar(eps, "eps"), _scalar(kappa, "kappa"), _scalar(mu, "mu")
        Bd = np.array([e * bb[j] * bb[k2] for _, j, k2 in _CYC]) + m
        Cd = np.array([e * e * bb[i] * (bb[j] - bb[k2]) ** 2 for i, j, k2 in _CYC]) + k
        body = cls(np.diag(bb), np.diag(Bd), np.diag(Cd))
        body._case, body._clebsch, body._steklov = "lyapunov_steklov", None, (bb, e)
        return body

    # -- properties ---------------------------------------------------------

    @property
    def A(self) -> np.ndarray:  # noqa: N802 (the field's names)
        """``A = ∂²H/∂M²`` (read-only)."""
        return self._A

    @property
    def B(self) -> np.ndarray:  # noqa: N802
        """``B_ij = ∂²H/∂M_i ∂p_j`` (read-only)."""
        return self._B

    @property
    def C(self) -> np.ndarray:  # noqa: N802
        """``C = ∂²H/∂p²`` (read-only)."""
        return self._C

    @property
    def case(self) -> str:
        """The integrable case, one of :data:`CASES`."""
        return self._case

    @property
    def rate_scale(self) -> float:
        """``‖Q'‖₂``: the spectral norm of ``[[A, B − μI], [Bᵀ − μI, C − κI]]``
        (``μ = tr B/3``, ``κ`` the midpoint of the spectrum of ``C``: the Casimir
        parts, which do not move the body, removed). ``‖Q'‖₂ |(M, p)|`` bounds
        the rate of the motion; the default steps scale with its inverse."""
        return float(self._core.rate_scale)

    def __repr__(self) -> str:
        return (
            f"KirchhoffBody(case={self._case!r}, A={self._A.tolist()}, "
            f"B={self._B.tolist()}, C={self._C.tolist()})"
        )

    # -- the field ----------------------------------------------------------

    def vector_field(self, M: Any, p: Any) -> tuple[np.ndarray, np.ndarray]:
        """Kirchhoff's equations: ``(Ṁ, ṗ) = (M × ω + p × v, p × ω)``,
        ``ω = ∂H/∂M = A M + B p``, ``v = ∂H/∂p = Bᵀ M + C p``.

        Parameters
        ----------
        M, p : array_like, shape (..., 3)
            Broadcast against each other.

        Returns
        -------
        (ndarray, ndarray)
            ``Ṁ``, ``ṗ`` of the broadcast shape.

        Raises
        ------
        ValueError
            Wrong shapes, complex or non-finite input, or an overflowing result.
        """
        y, lead = _states(M, p)
        f = _finite_result(self._core.vector_field(y), "this state: rescale M and p")
        return _split(f, lead)

    def hamiltonian(self, M: Any, p: Any) -> Any:
        """The energy ``H = ½ (Mᵀ A M + 2 Mᵀ B p + pᵀ C p)``.

        Parameters
        ----------
        M, p : array_like, shape (..., 3)

        Returns
        -------
        float or ndarray
        """
        y, lead = _states(M, p)
        return _out(self._core.hamiltonian(y), lead)

    def integrals(self, M: Any, p: Any) -> dict[str, Any]:
        """The conserved quantities, by name.

        ``"pp"`` = ``p·p`` and ``"Mp"`` = ``M·p`` (the Casimirs of e(3)*), ``"H"``;
        and the case's own: ``"F"`` (Clebsch's, see :meth:`clebsch`; or
        Lyapunov–Steklov's, see :meth:`lyapunov_steklov`), ``"M1"``/``"M2"``/``"M3"``
        (Kirchhoff's, the component along the symmetry axis).

        Parameters
        ----------
        M, p : array_like, shape (..., 3)

        Returns
        -------
        dict of str to float or ndarray
        """
        y, lead = _states(M, p)
        cas = _core.kirchhoff_casimirs(y)
        out: dict[str, Any] = {"pp": _out(cas[:, 0], lead), "Mp": _out(cas[:, 1], lead)}
        out["H"] = _out(self._core.hamiltonian(y), lead)
        Mv, pv = y[:, :3], y[:, 3:]
        with np.errstate(over="ignore", invalid="ignore"):
            if self._case == "clebsch":
                a = self._clebsch.body_a
                out["F"] = _out(np.sum(Mv * Mv, axis=1) - pv * pv @ a, lead)
            elif self._case == "kirchhoff":
                out[f"M{self._axis + 1}"] = _out(Mv[:, self._axis].copy(), lead)
            elif self._case == "lyapunov_steklov" and self._steklov is not None:
                b, e = self._steklov
                w = np.array([(b[j] - b[k]) ** 2 for _, j, k in _CYC])
                f = 0.5 * np.sum(Mv * Mv - 2 * e * b * Mv * pv + e * e * w * pv * pv, axis=1)
                out["F"] = _out(f, lead)
        return out

    # -- integration --------------------------------------------------------

    def time_scale(self, M0: Any, p0: Any) -> float:
        """``1/Ω``, ``Ω = ‖Q'‖₂ |(M0, p0)|`` (:attr:`rate_scale`); ``inf`` if ``Ω = 0``.

        Parameters
        ----------
        M0, p0 : array_like, shape (3,)

        Returns
        -------
        float
        """
        y, _ = _states(M0, p0, ("M0", "p0"))
        big = float(np.max(np.abs(y), initial=0.0))
        norm = big * float(np.linalg.norm(y / big)) if big > 0 else 0.0
        with np.errstate(over="ignore"):
            omega = float(np.float64(self.rate_scale) * np.float64(norm))
        return math.inf if omega == 0 else 1.0 / omega

    def default_dt(self, M0: Any, p0: Any, method: str = "gauss16") -> float:
        """The default step of ``method``: ``DT_SCALE[method] / Ω`` (0, automatic, for the
        explicit methods; 1 if ``Ω = 0``).

        Parameters
        ----------
        M0, p0 : array_like, shape (3,)
        method : str

        Returns
        -------
        float
        """
        _check_method(method)
        ts = self.time_scale(M0, p0)
        if method in _EXPLICIT:
            return 0.0
        if not math.isfinite(ts):
            return 1.0
        dt = DT_SCALE[method] * ts
        if not dt > 0:
            raise ValueError("M0, p0 are too large: the time scale 1/Ω underflows; rescale them")
        return dt

    def _step(self, y0: np.ndarray, method: str, dt: Any) -> float:
        _check_method(method)
        if dt is None:
            return self.default_dt(y0[:3], y0[3:], method)
        dtf = _scalar(dt, "dt")
        if dtf <= 0:
            raise ValueError(f"dt must be > 0, got {dtf}")
        return dtf

    def integrate(
        self,
        M0: Any,
        p0: Any,
        t_end: float,
        *,
        dt: float | None = None,
        t_eval: Any = None,
        sample_every: float | None = None,
        method: str = "gauss16",
        rtol: float | None = None,
        atol: float = 1e-12,
        progress: Callable[[float], None] | None = None,
        chunks: int = 1,
        max_steps: int = DEFAULT_MAX_STEPS,
    ) -> FluidTrajectory:
        """Integrate Kirchhoff's equations from ``(M0, p0)`` at t = 0 to ``t_end``.

        The same integrators and conventions as :meth:`manakov.FrahmTop.integrate`:
        Gauss methods take equal steps of at most ``dt`` between sample times and
        keep ``p·p``, ``M·p``, ``H`` (and every other quadratic integral) to
        roundoff; the explicit ``dopri5``, ``dop853`` follow ``rtol``, ``atol``.

        Parameters
        ----------
        M0, p0 : array_like, shape (3,)
        t_end : float, >= 0
        dt : float, optional
            Largest Gauss step (default :meth:`default_dt`); initial step of the
            explicit methods (default automatic).
        t_eval : array_like, optional
            Sorted sample times in [0, t_end].
        sample_every : float, optional
            Sample at 0, sample_every, ... and t_end (default: 1001 samples).
        method : {"gauss16", "gauss6", "gauss4", "dopri5", "dop853"}
        rtol, atol : float
            Tolerances of the explicit methods (default ``rtol`` 1e-12, at least
            ``100 eps``); ignored by the Gauss methods.
        progress : callable, optional
            Called with the fraction done after each chunk.
        chunks : int
            Split the run into this many calls to the core.
        max_steps : int
            Step budget of the whole run, checked before the first step for
            Gauss methods.

        Returns
        -------
        FluidTrajectory

        Raises
        ------
        ValueError
            Bad shapes or values, a run over ``max_steps``.
        manakov.ConvergenceError
            A Gauss step whose stage equations do not converge (``dt`` too large).
        KeyboardInterrupt
            Ctrl-C: the call stops within milliseconds; ``err.partial`` holds the
            :class:`FluidTrajectory` of the samples computed before it (also for
            ``ConvergenceError`` and an explicit method's ``max_steps``).
        """
        y, lead = _states(M0, p0, ("M0", "p0"))
        if lead != ():
            raise ValueError(f"M0 and p0 must have shape (3,), got {np.shape(M0)}, {np.shape(p0)}")
        y0 = y[0]
        times = _sample_times(t_end, t_eval, sample_every)
        dtf = self._step(y0, method, dt)
        rt, at = _tolerances(method, rtol, atol)
        budget = _max_steps(max_steps)
        n_chunks = _chunks(chunks)
        _core.check_budget(method, 0.0, times, dtf, budget)
        out: list[np.ndarray] = []
        steps = evals = 0

        def trajectory(partial: bool = False) -> FluidTrajectory:
            ys = np.concatenate(out) if out else np.empty((0, 6))
            Ms, ps = np.ascontiguousarray(ys[:, :3]), np.ascontiguousarray(ys[:, 3:])
            try:
                integrals = self.integrals(Ms, ps)
            except ValueError:
                if not partial:
                    raise
                integrals = {}
            return FluidTrajectory(
                t=times[: ys.shape[0]].copy(),
                M=Ms,
                p=ps,
                integrals=integrals,
                method=method,
                dt=dtf,
                steps=int(steps),
                evals=int(evals),
            )

        if times.size:
            pieces = np.array_split(times, min(n_chunks, times.size))
            yc, t0 = y0, 0.0
            for piece in pieces:
                ys, s, e, err = self._core.integrate(
                    yc, t0, piece, method, dtf, rt, at, budget - steps
                )
                out.append(ys)
                steps, evals = steps + s, evals + e
                if err is not None:
                    err.partial = trajectory(partial=True)  # type: ignore[attr-defined]
                    raise err
                yc, t0 = ys[-1], float(piece[-1])
                if progress is not None:
                    progress(t0 / float(times[-1]) if times[-1] > 0 else 1.0)
        return trajectory()

    def integrate_many(
        self,
        M0s: Any,
        p0s: Any,
        t_end: float,
        *,
        dt: float | None = None,
        t_eval: Any = None,
        sample_every: float | None = None,
        method: str = "gauss16",
        rtol: float | None = None,
        atol: float = 1e-12,
        parallel: bool = True,
        max_steps: int = DEFAULT_MAX_STEPS,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Integrate a batch of initial states in one call, GIL released.

        Parameters
        ----------
        M0s, p0s : array_like, shape (..., 3)
            Broadcast against each other.
        t_end, dt, t_eval, sample_every, method, rtol, atol, max_steps
            As in :meth:`integrate`; ``dt`` defaults to the smallest default step
            over the batch.
        parallel : bool
            Split the batch over threads (rayon). Results equal :meth:`integrate`
            state by state, bit for bit.

        Returns
        -------
        t : ndarray, shape (S,)
        M, p : ndarray, shape (..., S, 3)

        Raises
        ------
        ValueError, manakov.ConvergenceError, KeyboardInterrupt
            As :meth:`integrate` (no partial result).
        """
        y, lead = _states(M0s, p0s, ("M0s", "p0s"))
        times = _sample_times(t_end, t_eval, sample_every)
        _check_method(method)
        if dt is None:
            if y.shape[0] == 0:
                dtf = 1.0
            else:
                big = np.max(np.abs(y), axis=1, keepdims=True)
                safe = np.where(big > 0, big, 1.0)
                with np.errstate(over="ignore"):
                    norms = big[:, 0] * np.linalg.norm(y / safe, axis=1)
                k = int(np.argmax(norms))
                dtf = self.default_dt(y[k, :3], y[k, 3:], method)
        else:
            dtf = self._step(np.zeros(6), method, dt)
        rt, at = _tolerances(method, rtol, atol)
        budget = _max_steps(max_steps)
        ys, _ = self._core.integrate_many(
            y, 0.0, times, method, dtf, rt, at, budget, bool(parallel)
        )
        ys = ys.reshape(lead + (times.size, 6))
        return times, np.ascontiguousarray(ys[..., :3]), np.ascontiguousarray(ys[..., 3:])

    def motion_in_space(
        self,
        M0: Any,
        p0: Any,
        t_end: float,
        *,
        R0: Any = None,
        x0: Any = None,
        dt: float | None = None,
        t_eval: Any = None,
        sample_every: float | None = None,
        method: str = "gauss16",
        rtol: float | None = None,
        atol: float = 1e-12,
        max_steps: int = DEFAULT_MAX_STEPS,
    ) -> SpaceTrajectory:
        """The body's position and orientation in space, by quadrature of its velocities.

        Integrates Kirchhoff's equations together with ``Ṙ = R ω̂`` and ``ẋ = R v``
        (``ω = ∂H/∂M``, ``v = ∂H/∂p``; ``ω̂ u = ω × u``; ``R`` the rotation body →
        space, ``x`` the position of the body's origin). The impulse ``P = R p``
        and its moment ``K = R M + x × P`` stay constant
        (:meth:`SpaceTrajectory.impulse`, :meth:`SpaceTrajectory.moment`); a Gauss
        method keeps ``R Rᵀ = I`` and ``P`` to roundoff.

        Parameters
        ----------
        M0, p0 : array_like, shape (3,)
        t_end : float
        R0 : array_like, shape (3, 3), optional
            Initial rotation (default the identity); orthogonal to 1e-12.
        x0 : array_like, shape (3,), optional
            Initial position (default 0).
        dt, t_eval, sample_every, method, rtol, atol, max_steps
            As in :meth:`integrate`.

        Returns
        -------
        SpaceTrajectory

        Raises
        ------
        ValueError, manakov.ConvergenceError, KeyboardInterrupt
            As :meth:`integrate` (``err.partial`` is the :class:`SpaceTrajectory` so far).
        """
        y, lead = _states(M0, p0, ("M0", "p0"))
        if lead != ():
            raise ValueError(f"M0 and p0 must have shape (3,), got {np.shape(M0)}, {np.shape(p0)}")
        R = np.eye(3) if R0 is None else _matrix(R0, "R0")
        if np.max(np.abs(R @ R.T - np.eye(3))) > 1e-12 or np.linalg.det(R) < 0:
            raise ValueError("R0 must be a rotation (orthogonal to 1e-12, det +1)")
        x = np.zeros(3) if x0 is None else _vector3(x0, "x0")
        s0 = np.ascontiguousarray(np.concatenate([y[0], R.ravel(), x]))
        times = _sample_times(t_end, t_eval, sample_every)
        dtf = self._step(y[0], method, dt)
        rt, at = _tolerances(method, rtol, atol)
        budget = _max_steps(max_steps)
        _core.check_budget(method, 0.0, times, dtf, budget)
        ss, steps, evals, err = self._core.integrate_space(
            s0, 0.0, times, method, dtf, rt, at, budget
        )
        tr = SpaceTrajectory(
            t=times[: ss.shape[0]].copy(),
            M=np.ascontiguousarray(ss[:, :3]),
            p=np.ascontiguousarray(ss[:, 3:6]),
            R=np.ascontiguousarray(ss[:, 6:15].reshape(-1, 3, 3)),
            x=np.ascontiguousarray(ss[:, 15:]),
            method=method,
            dt=dtf,
            steps=int(steps),
            evals=int(evals),
        )
        if err is not None:
            err.partial = tr  # type: ignore[attr-defined]
            raise err
        return tr

    # -- the Clebsch case in theta functions --------------------------------

    def _require_clebsch(self, what: str) -> Any:
        if self._case != "clebsch":
            raise ValueError(
                f"{what} is defined for the Clebsch case only (this body's case is "
                f"{self._case!r}); see KirchhoffBody.clebsch"
            )
        return self._clebsch

    @property
    def conjugate_top(self) -> ManakovTop:
        """The Manakov top whose field is linearly conjugate to this Clebsch body's.

        ``a = α``, ``b = β`` of docs/clebsch.md: ``α_i = λ/(a_i − σ)`` and 0 (the
        image of ``a4 = ∞``), ``β_i = (√(α1 α2 α3)/λ) b_i α_i`` and 0, in ascending
        order of ``α``; :meth:`to_so4` maps states.
        """
        conj = self._require_clebsch("conjugate_top")
        return ManakovTop(conj.alpha, conj.beta)

    def to_so4(self, M: Any, p: Any) -> np.ndarray:
        """The state ``l = L(M, p)`` of :attr:`conjugate_top` (Clebsch case).

        ``m_j = M_j/√α_j``, ``n_j = √λ p_j/√(α_k α_l)`` with ``m = (l23, l31, l12)``,
        ``n = (l14, l24, l34)`` before the indices are put in ascending order of
        ``α`` (docs/clebsch.md). The conjugate top's flow of ``l`` is ``L`` of
        this body's flow, at the same times.

        Parameters
        ----------
        M, p : array_like, shape (..., 3)

        Returns
        -------
        ndarray, shape (..., 6)
        """
        conj = self._require_clebsch("to_so4")
        y, lead = _states(M, p)
        return conj.to_so4(y).reshape(lead + (6,))

    def from_so4(self, l: Any) -> tuple[np.ndarray, np.ndarray]:  # noqa: E741
        """``(M, p) = L⁻¹ l``, the inverse of :meth:`to_so4` (Clebsch case).

        Parameters
        ----------
        l : array_like, shape (..., 6)

        Returns
        -------
        (ndarray, ndarray)
            ``M``, ``p`` of shape (..., 3).
        """
        conj = self._require_clebsch("from_so4")
        arr = _float_array(l, "l")
        if arr.ndim == 0 or arr.shape[-1] != 6:
            raise ValueError(f"l must have shape (..., 6), got {arr.shape}")
        lead = arr.shape[:-1]
        y = conj.to_body(np.ascontiguousarray(arr.reshape(-1, 6)))
        return _split(y, lead)

    def solve(self, M0: Any, p0: Any) -> ClebschSolution:
        """The motion through ``(M0, p0)`` in genus-2 theta functions (Clebsch case).

        ``(M, p)(t) = L⁻¹ l(t)``, ``l(t)`` the Theorem (9)–(10) of the conjugate
        Manakov top (:attr:`conjugate_top`) through ``L(M0, p0)``: quotients of
        theta functions with characteristics whose argument ``v0 + U t`` is
        linear in ``t`` (docs/clebsch.md, docs/theorem.md).

        Parameters
        ----------
        M0, p0 : array_like, shape (3,)

        Returns
        -------
        ClebschSolution

        Raises
        ------
        ValueError
            Not a Clebsch body, or invalid ``M0``, ``p0``. ``M0·p0 = 0`` (the
            conjugate top's ``h0 = 0``) is not singular by itself, and the states
            on the conjugate top's exact degenerate sets (``p0 = 0``; ``M0``,
            ``p0`` on two axes) are solved in its closed form.

        Notes
        -----
        A valid state whose conjugate top's closed form cannot be built gets a
        solution of kind ``"integrated"`` (``solution.kind``; the reason in its
        ``repr``), whose :meth:`ClebschSolution.state` is an integration of the
        conjugate top's (1), as :meth:`manakov.ManakovTop.solve` gives.
        """
        self._require_clebsch("solve")
        y, lead = _states(M0, p0, ("M0", "p0"))
        if lead != ():
            raise ValueError(f"M0 and p0 must have shape (3,), got {np.shape(M0)}, {np.shape(p0)}")
        return ClebschSolution(self, y[0, :3], y[0, 3:])

    def frequency_map(
        self,
        M0s: Any,
        p0s: Any,
        *,
        client: Any = None,
        chunk_size: int | None = None,
        progress: bool | None = None,
    ) -> FrequencyMap:
        """Frequencies ``(ν1, ν2)`` of the real tori through many states (Clebsch case).

        :func:`manakov.frequency_map` of :attr:`conjugate_top` at ``L(M, p)``:
        the conjugacy keeps time, so the frequencies are the body's.

        Parameters
        ----------
        M0s, p0s : array_like, shape (..., 3)
        client, chunk_size, progress
            As :func:`manakov.frequency_map`.

        Returns
        -------
        FrequencyMap
        """
        self._require_clebsch("frequency_map")
        return _frequency_map(
            self.conjugate_top,
            self.to_so4(M0s, p0s),
            client=client,
            chunk_size=chunk_size,
            progress=progress,
        )


class ClebschSolution:
    """The motion of a Clebsch body in theta functions (:meth:`KirchhoffBody.solve`).

    ``(M, p)(t) = L⁻¹ l(t)`` with ``l(t)`` the :class:`manakov.Solution` of the
    conjugate Manakov top: ``u0``, ``U``, ``tau``, ``curve``, ``frequencies`` are
    those of the body (the conjugacy keeps time). Where the conjugate state lies
    on one of the top's exact degenerate sets (``p0 = 0``: Euler's top; ``M0``,
    ``p0`` on two axes: an so(3) block) that solution is the top's closed form
    (``solution.kind``, docs/degenerate.md): :meth:`state` and
    :attr:`frequencies` work as for every kind, while ``u0``, ``U``, ``tau``,
    ``curve`` and :meth:`quotient` raise ``AttributeError`` naming the kind.

    Parameters
    ----------
    body : KirchhoffBody
        A Clebsch body.
    M0, p0 : array_like, shape (3,)

    Examples
    --------
    >>> import numpy as np, manakov
    >>> pr = manakov.fluid_problem("clebsch_generic")
    >>> sol = pr.body.solve(pr.M0, pr.p0)
    >>> print(np.round(sol.M(0.0), 12), np.round(sol.p(0.0), 12))
    [ 0.4 -0.7  0.9] [ 0.8  0.3 -0.5]
    >>> print(sol.frequencies.round(6))
    [0.39201  0.199898]
    """

    __slots__ = ("_body", "_M0", "_p0", "_solution")

    def __init__(self, body: KirchhoffBody, M0: Any, p0: Any) -> None:
        top = body.conjugate_top
        self._body = body
        self._M0, self._p0 = _vector3(M0, "M0"), _vector3(p0, "p0")
        for x in (self._M0, self._p0):
            x.setflags(write=False)
        l0 = body.to_so4(self._M0, self._p0)
        try:
            self._solution = Solution(top.a, top.b, l0)
        except (ValueError, ClosedFormError) as err:
            # p0 = 0 (Euler's top) never gets here: its conjugate state lies in an
            # so(3) block, which Solution solves in closed form.
            M0a, p0a = self._M0, self._p0
            hint = ""
            if abs(M0a @ p0a) <= 1e-13 * np.linalg.norm(M0a) * np.linalg.norm(p0a):
                # h0 = 0 alone is a regular level set of the top (its reduction takes
                # the limit there); this only translates the top's wording.
                hint = "M0·p0 = 0 is the conjugate top's h0 = 0; "
            # A valid body state the top cannot solve stays a ClosedFormError.
            kind = ClosedFormError if isinstance(err, ClosedFormError) else ValueError
            raise kind(
                f"no genus-2 solution through M0 = {M0a.tolist()}, p0 = {p0a.tolist()}: "
                f"{hint}the conjugate Manakov top says: {err}"
            ) from None

    @property
    def body(self) -> KirchhoffBody:
        """The body."""
        return self._body

    @property
    def M0(self) -> np.ndarray:  # noqa: N802
        """The initial couple (read-only)."""
        return self._M0

    @property
    def p0(self) -> np.ndarray:
        """The initial force (read-only)."""
        return self._p0

    @property
    def solution(self) -> Solution:
        """The conjugate top's :class:`manakov.Solution` (its ``l`` is ``L(M, p)``)."""
        return self._solution

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """``(M(t), p(t))`` from the theta quotients.

        Parameters
        ----------
        t : float or array_like

        Returns
        -------
        (ndarray, ndarray)
            Each of shape ``t.shape + (3,)``.

        Raises
        ------
        ValueError
            Non-finite ``t``.
        ClosedFormError
            As :meth:`manakov.Solution.l`.

        Warns
        -----
        IntegratedValuesWarning
            As :meth:`manakov.Solution.l`: the values are those of an integration
            of the conjugate top's (1) where its closed form cannot be built
            (``solution.kind == "integrated"``) or is off.
        """
        tt = _float_array(t, "t")
        l = self._solution.l(tt.reshape(-1))  # noqa: E741
        return self._body.from_so4(l.reshape(tt.shape + (6,)))

    def M(self, t: Any) -> np.ndarray:  # noqa: N802
        """``M(t)``, shape ``t.shape + (3,)``."""
        return self.state(t)[0]

    def p(self, t: Any) -> np.ndarray:
        """``p(t)``, shape ``t.shape + (3,)``."""
        return self.state(t)[1]

    @property
    def u0(self) -> np.ndarray:
        """``u0``: the argument is ``v(t) = u0 + K + U t``."""
        return self._solution.u0

    @property
    def U(self) -> np.ndarray:  # noqa: N802
        """``U``, the velocity of the argument of the theta functions."""
        return self._solution.U

    @property
    def tau(self) -> np.ndarray:
        """The period matrix of the curve."""
        return self._solution.tau

    @property
    def curve(self) -> Any:
        """The genus-2 curve ``y² = Π_{j=0}^{4} (x − d_j)`` of the level set."""
        return self._solution.curve

    @property
    def frequencies(self) -> np.ndarray:
        """``(ν1, ν2) ≥ 0`` in cycles per unit time (docs/tori.md)."""
        return self._solution.frequencies

    @property
    def rotation_number(self) -> float:
        """``ν1/ν2``."""
        return self._solution.rotation_number

    def angles(self, t: Any) -> np.ndarray:
        """Torus angles ``(ν1 t, ν2 t) mod 1``, shape ``(..., 2)``."""
        return self._solution.angles(t)

    def quotient(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The theta quotients of ``(M, p)``: ``(idx, num, den)`` with
        ``y_q = Re(Σ_m num[q, m] θ[idx[m]](v) / Σ_m den[m] θ[idx[m]](v))``,
        ``y = (M1, M2, M3, p1, p2, p3)``, ``v = u0 + K + U t`` (theta indices in the
        package's characteristic order; :meth:`manakov.Solution.quotient` of the
        conjugate top with its numerators mapped by ``L⁻¹``, a real linear map).

        Returns
        -------
        idx : ndarray, int64, shape (8,)
        num : ndarray, complex, shape (6, 8)
        den : ndarray, complex, shape (8,)
        """
        idx, num, den = self._solution.quotient()
        # Columns of L⁻¹: the images of the unit vectors of l.
        T = np.stack([np.concatenate(self._body.from_so4(e)) for e in np.eye(6)], axis=1)
        return idx, T @ num, den

    def __repr__(self) -> str:
        return f"ClebschSolution({self._solution!r})"


# -- argument checks shared by the integrators ---------------------------------


def _check_method(method: Any) -> None:
    if not isinstance(method, str) or method not in _METHODS:
        raise ValueError(f"unknown method {method!r}; known: {', '.join(_METHODS)}")


def _chunks(chunks: Any) -> int:
    if isinstance(chunks, bool) or not isinstance(chunks, (int, np.integer)) or chunks < 1:
        raise ValueError(f"chunks must be an integer >= 1, got {chunks!r}")
    return int(chunks)


def _max_steps(max_steps: Any) -> int:
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)):
        raise ValueError(f"max_steps must be an integer, got {max_steps!r}")
    if not 1 <= max_steps <= 10**11:
        raise ValueError(f"max_steps must be in [1, 10^11], got {max_steps}")
    return int(max_steps)


def _tolerances(method: str, rtol: Any, atol: Any) -> tuple[float, float]:
    if method not in _EXPLICIT:
        return 0.0, 0.0
    rt = DEFAULT_RTOL[method] if rtol is None else _scalar(rtol, "rtol")
    return rt, _scalar(atol, "atol")


def _sample_times(t_end: Any, t_eval: Any, sample_every: Any) -> np.ndarray:
    t_end_f = _scalar(t_end, "t_end")
    if t_end_f < 0:
        raise ValueError(f"t_end must be >= 0, got {t_end_f}")
    if t_eval is not None and sample_every is not None:
        raise ValueError("give at most one of t_eval and sample_every")
    if t_eval is not None:
        te = _float_array(t_eval, "t_eval")
        if te.ndim != 1:
            raise ValueError(f"t_eval must be 1-d, got shape {te.shape}")
        if te.size and (np.any(np.diff(te) < 0) or te[0] < 0 or te[-1] > t_end_f):
            raise ValueError("t_eval must be sorted and lie in [0, t_end]")
        return np.array(te, dtype=np.float64, order="C", copy=True)
    if sample_every is not None:
        every = _scalar(sample_every, "sample_every")
        if every <= 0:
            raise ValueError(f"sample_every must be > 0, got {every}")
        with np.errstate(over="ignore"):
            ratio = float(np.float64(t_end_f) / np.float64(every)) * (1 + 1e-12)
        if not ratio <= MAX_SAMPLES:
            raise ValueError(
                f"sample_every = {every} gives more than {MAX_SAMPLES:.0e} samples "
                f"on [0, {t_end_f}]"
            )
        k = math.floor(ratio)
        times = np.arange(k + 1, dtype=float) * every
        times = times[times <= t_end_f]
        if times[-1] < t_end_f:
            times = np.append(times, t_end_f)
        return times
    return np.linspace(0.0, t_end_f, 1001)


# -- the reference bodies ------------------------------------------------------


class FluidProblem(NamedTuple):
    """A reference body in an ideal fluid with an initial state.

    Examples
    --------
    >>> import manakov
    >>> pr = manakov.fluid_problem("clebsch_generic")
    >>> pr.name, pr.body.case
    ('clebsch_generic', 'clebsch')
    """

    name: str
    body: KirchhoffBody
    M0: np.ndarray
    p0: np.ndarray
    note: str


@lru_cache(maxsize=1)
def _bodies() -> dict[str, Any]:
    text = resources.files("manakov").joinpath("data/fluid_bodies.json").read_text()
    return json.loads(text)["bodies"]  # type: ignore[no-any-return]


def fluid_problem_names() -> list[str]:
    """Names of the built-in reference bodies (``data/fluid_bodies.json``).

    Returns
    -------
    list of str
        Four Clebsch bodies (``clebsch_generic``, ``clebsch_wide``,
        ``clebsch_isotropic``, ``clebsch_near_degenerate``), then ``kirchhoff``,
        ``lyapunov_steklov`` and ``general``.

    Examples
    --------
    >>> import manakov
    >>> for name in manakov.fluid_problem_names():
    ...     print(name)
    clebsch_generic
    clebsch_wide
    clebsch_isotropic
    clebsch_near_degenerate
    kirchhoff
    lyapunov_steklov
    general
    """
    return list(_bodies())


def fluid_problem(name: str) -> FluidProblem:
    """The built-in reference body ``name`` (see :func:`fluid_problem_names`).

    Parameters
    ----------
    name : str

    Returns
    -------
    FluidProblem
        ``(name, body, M0, p0, note)``.

    Raises
    ------
    ValueError
        If there is no body of that name.

    Examples
    --------
    >>> import manakov
    >>> fp = manakov.fluid_problem(manakov.fluid_problem_names()[0])
    >>> print(fp.M0, fp.p0)
    [ 0.4 -0.7  0.9] [ 0.8  0.3 -0.5]
    """
    bodies = _bodies()
    if name not in bodies:
        raise ValueError(f"unknown body {name!r}; known: {', '.join(bodies)}")
    d = bodies[name]
    case = d["case"]
    if case == "clebsch":
        body = KirchhoffBody.clebsch(d["A"], d["C"])
    elif case == "kirchhoff":
        body = KirchhoffBody.kirchhoff(d["A"], d["B"], d["C"])
    elif case == "lyapunov_steklov":
        body = KirchhoffBody.lyapunov_steklov(d["b"], d["eps"], kappa=d.get("kappa", 0.0))
    else:
        body = KirchhoffBody(d["A"], d["B"], d["C"])
    return FluidProblem(
        name=name,
        body=body,
        M0=np.array(d["M0"], dtype=float),
        p0=np.array(d["p0"], dtype=float),
        note=d.get("note", ""),
    )


# -- figures -----------------------------------------------------------------


def plot_motion(
    body: KirchhoffBody,
    M0: Any,
    p0: Any,
    path: str,
    *,
    t_end: float = 50.0,
    samples: int = 2001,
    frames: int = 12,
) -> SpaceTrajectory:
    """Plot a body moving in the fluid, as a PNG.

    Three panels: the path of the body's origin in space with the body's axes
    (``R e_1, R e_2, R e_3``, drawn at ``frames`` instants) and the constant impulse
    ``P = R p``; ``M(t)`` and ``p(t)`` in the body frame; the drift of the
    integrals, of ``P`` and of its moment ``K = R M + x × P`` on a log scale.

    Parameters
    ----------
    body : KirchhoffBody
    M0, p0 : array_like, shape (3,)
    path : str
        The PNG file to write.
    t_end : float
        End time (> 0).
    samples : int
        Sample times in ``[0, t_end]`` (≥ 2).
    frames : int
        How many instants show the body's axes.

    Returns
    -------
    SpaceTrajectory
        The motion that was plotted.

    Examples
    --------
    >>> import os, tempfile, manakov
    >>> from manakov.fluid import plot_motion
    >>> fp = manakov.fluid_problem(manakov.fluid_problem_names()[0])
    >>> path = os.path.join(tempfile.mkdtemp(), "motion.png")
    >>> tr = plot_motion(fp.body, fp.M0, fp.p0, path, t_end=5.0, samples=51)
    >>> os.path.exists(path)
    True
    """
    t_end_f = _scalar(t_end, "t_end")
    if not t_end_f > 0:
        raise ValueError(f"t_end must be > 0, got {t_end_f}")
    if int(samples) < 2:
        raise ValueError(f"samples must be >= 2, got {samples}")
    t = np.linspace(0.0, t_end_f, int(samples))
    tr = body.motion_in_space(M0, p0, t_end_f, t_eval=t)
    plot_space_trajectory(body, tr, path, frames=frames)
    return tr


def plot_space_trajectory(
    body: KirchhoffBody, tr: SpaceTrajectory, path: str, *, frames: int = 12
) -> None:
    """Plot a computed :class:`SpaceTrajectory` of ``body`` as in :func:`plot_motion`.

    Parameters
    ----------
    body : KirchhoffBody
    tr : SpaceTrajectory
        From :meth:`KirchhoffBody.motion_in_space` (at least 2 samples).
    path : str
        The PNG file to write.
    frames : int
        How many instants show the body's axes.

    Examples
    --------
    >>> import os, tempfile, manakov
    >>> from manakov.fluid import plot_space_trajectory
    >>> fp = manakov.fluid_problem(manakov.fluid_problem_names()[0])
    >>> tr = fp.body.motion_in_space(fp.M0, fp.p0, 5.0, sample_every=0.1)
    >>> path = os.path.join(tempfile.mkdtemp(), "space.png")
    >>> plot_space_trajectory(fp.body, tr, path)
    >>> os.path.exists(path)
    True
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if tr.t.size < 2:
        raise ValueError(f"the trajectory needs at least 2 samples, got {tr.t.size}")
    t = tr.t
    P, K = tr.impulse(), tr.moment()
    fig = plt.figure(figsize=(13, 4.6))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    ax.plot(*tr.x.T, "k-", lw=0.8)
    span = float(np.max(np.ptp(tr.x, axis=0))) or 1.0
    size = 0.06 * span
    for k in np.linspace(0, t.size - 1, max(int(frames), 1)).astype(int):
        for i, col in enumerate(("tab:red", "tab:green", "tab:blue")):
            e = tr.R[k][:, i] * size
            ax.plot(*np.stack([tr.x[k], tr.x[k] + e]).T, color=col, lw=1.2)
    if np.any(P[0]):
        ax.quiver(*tr.x[0], *(P[0] / np.linalg.norm(P[0]) * 2 * size), color="k", lw=1.5)
    ax.set_box_aspect(tuple(np.maximum(np.ptp(tr.x, axis=0), 1e-3 * span)))
    ax.set_title("origin's path, body axes (r, g, b), impulse P", fontsize=9)
    ax.set_xlabel("x1")
    ax.set_ylabel("x2")
    ax.set_zlabel("x3")
    ax2 = fig.add_subplot(1, 3, 2)
    for i in range(3):
        ax2.plot(t, tr.M[:, i], label=f"M{i + 1}")
        ax2.plot(t, tr.p[:, i], "--", label=f"p{i + 1}")
    ax2.set_xlabel("t")
    ax2.set_title("body frame: M (solid), p (dashed)", fontsize=9)
    ax2.legend(ncol=2, fontsize=7)
    ax3 = fig.add_subplot(1, 3, 3)
    ints = body.integrals(tr.M, tr.p)
    for name, v in ints.items():
        scale = max(abs(float(v[0])), 1e-300)
        d = np.maximum.accumulate(np.abs(v - v[0]) / scale)
        ax3.semilogy(t, np.maximum(d, 1e-17), label=name)
    for name, v in (("P", P), ("K", K)):
        d = np.max(np.abs(v - v[0]), axis=1) / max(float(np.max(np.abs(v[0]))), 1e-300)
        ax3.semilogy(t, np.maximum(np.maximum.accumulate(d), 1e-17), ":", label=name)
    ax3.set_xlabel("t")
    ax3.set_title("running maximum of the relative drift", fontsize=9)
    ax3.legend(fontsize=7)
    step = (float(t[-1]) - float(t[0])) / tr.steps if tr.steps else float("nan")
    fig.suptitle(
        f"{body.case} body in an ideal fluid, {tr.method}, mean step {step:.3g}", fontsize=10
    )
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_clebsch_theorem(
    name: str,
    path: str,
    *,
    t_end: float = 100.0,
    samples: int = 201,
) -> float:
    """Plot ``M(t), p(t)`` of a reference Clebsch body from theta functions against
    gauss16 integration (at a tenth of its default step), and their difference on a
    log scale, as a PNG.

    Parameters
    ----------
    name : str
        A Clebsch body of :func:`fluid_problem_names`.
    path : str
        The PNG file to write.
    t_end : float
        End time (> 0).
    samples : int
        Number of times in ``[0, t_end]`` (≥ 2).

    Returns
    -------
    float
        ``max_t |y_theta − y_int| / max |y0|``.

    Examples
    --------
    >>> import os, tempfile, manakov
    >>> from manakov.fluid import plot_clebsch_theorem
    >>> name = manakov.fluid_problem_names()[0]
    >>> path = os.path.join(tempfile.mkdtemp(), "clebsch.png")
    >>> err = plot_clebsch_theorem(name, path, t_end=10.0, samples=21)
    >>> bool(err < 1e-8), os.path.exists(path)
    (True, True)
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pr = fluid_problem(name)
    t_end_f = _scalar(t_end, "t_end")
    if not t_end_f > 0:
        raise ValueError(f"t_end must be > 0, got {t_end_f}")
    if int(samples) < 2:
        raise ValueError(f"samples must be >= 2, got {samples}")
    sol = pr.body.solve(pr.M0, pr.p0)
    t = np.linspace(0.0, t_end_f, int(samples))
    dt = pr.body.default_dt(pr.M0, pr.p0) / 10
    tr = pr.body.integrate(pr.M0, pr.p0, t_end_f, t_eval=t, dt=dt)
    M, p = sol.state(t)
    y_th, y_int = np.hstack([M, p]), np.hstack([tr.M, tr.p])
    scale = float(np.max(np.abs(np.r_[pr.M0, pr.p0])))
    diff = np.max(np.abs(y_th - y_int), axis=1) / scale
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    names = ["M1", "M2", "M3", "p1", "p2", "p3"]
    for q in range(6):
        ax1.plot(t, y_th[:, q], label=names[q])
        ax1.plot(t, y_int[:, q], "k:", lw=0.8)
    ax1.set_ylabel("theta quotients (lines), gauss16 (dotted)")
    ax1.legend(ncol=6, fontsize=7)
    nu = sol.frequencies
    ax1.set_title(f"{name}: nu = ({nu[0]:.8f}, {nu[1]:.8f}); {sol.solution!r}"[:110], fontsize=8)
    ax2.semilogy(t, np.maximum(diff, 1e-18))
    ax2.set_xlabel("t")
    ax2.set_ylabel("max |y_theta - y_int| / max |y0|")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return float(diff.max())
