# The state is called l, as in the paper (and ω, c, a, b): E741 does not apply.
# ruff: noqa: E741
"""The Euler–Frahm top on so(4) and so(n) and Manakov's integrable case.

The Python side of the core's ``so4`` layer (``rust/so4/``). The tops' methods
also reach the layers above it: ``integrate`` (:mod:`manakov.integrate`),
``kotter``/``level_set`` (:mod:`manakov.reduction`) and ``solve``
(:mod:`manakov.solution`).

State convention
----------------
An angular momentum ``l`` in so(n) is a skew matrix, ``l_ji = -l_ij``. Arrays
hold its strict upper triangle row by row, so the last axis has length
``n(n-1)/2``; for n = 4 it is ordered ``(l12, l13, l14, l23, l24, l34)``. Every
function that takes states broadcasts over leading axes; a single state in
gives scalars out (``docs/conventions.md``; ``solve`` and ``level_set`` take
one state and say so).

Equations (numbers are those of Perelomov's paper)
---------------------------------------------------
* (1) ``l̇_ij = Σ_k (l_ik ω_kj - ω_ik l_kj)``, ``ω_ij = c_ij l_ij``;
* (2) ``c_ij = (b_i - b_j)/(a_i - a_j)``;
* (3) ``{l_ij, l_km} = l_im δ_jk - l_ik δ_jm + l_jk δ_im - l_jm δ_ik``;
* (4) ``H = ½ Σ_{j<k} c_jk l_jk²``; (5) ``l̇_jk = {H, l_jk}`` (sign as printed holds);
* (6) ``H0 = l12 l34 + l23 l14 + l31 l24``; (7), corrected (see ``docs/errata.md``):
  ``H1 = Σ l_jk²``, ``H2 = Σ (a_l + a_m) l_jk²``, ``H3 = Σ a_l a_m l_jk²`` with
  ``{l, m} = {1,2,3,4} \\ {j, k}``.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from . import _core
from . import integrate as _integrate
from ._checks import _finite_result, _float_array, _n_from_dim, _out, _states, state_dim
from .integrate import (
    ADAPTIVE_METHODS,
    DEFAULT_MAX_STEPS,
    DEFAULT_RTOL,
    DEFAULT_SAMPLES,
    DT_SCALE,
    MAX_SAMPLES,
    METHODS,
    Trajectory,
    check_method,
)
from .reduction import Kotter
from .reduction import LevelSet as _LevelSet
from .reduction import from_kotter as _from_kotter
from .reduction import kotter as _kotter
from .solution import Solution

__all__ = [
    "DEFAULT_MAX_STEPS",
    "DEFAULT_RTOL",
    "DEFAULT_SAMPLES",
    "DT_SCALE",
    "MAX_SAMPLES",
    "FrahmTop",
    "ManakovTop",
    "Trajectory",
    "METHODS",
    "poisson_tensor",
    "to_matrix",
    "from_matrix",
    "state_dim",
]


def to_matrix(l: Any) -> np.ndarray:
    """The skew matrices of states ``l``: ``L_ij = l_ij``, ``L_ji = -l_ij`` (``i < j``).

    Parameters
    ----------
    l : array_like, real, shape (..., n(n-1)/2)
        Strict upper triangles, row by row.

    Returns
    -------
    ndarray, shape (..., n, n)

    Raises
    ------
    ValueError
        A last axis that is not ``n(n-1)/2``, complex or non-finite values.

    Examples
    --------
    >>> import manakov
    >>> print(manakov.to_matrix([1, 2, 3, 4, 5, 6]))
    [[ 0.  1.  2.  3.]
     [-1.  0.  4.  5.]
     [-2. -4.  0.  6.]
     [-3. -5. -6.  0.]]
    """
    arr = _float_array(l, "l")
    if arr.ndim == 0:
        raise ValueError("l must have at least one axis")
    n = _n_from_dim(arr.shape[-1])
    iu = np.triu_indices(n, 1)
    out = np.zeros(arr.shape[:-1] + (n, n))
    out[..., iu[0], iu[1]] = arr
    out[..., iu[1], iu[0]] = -arr
    return out


def from_matrix(m: Any, *, check: bool = True) -> np.ndarray:
    """The state vectors ``l_ij = m_ij`` (``i < j``, row by row) of skew matrices ``m``.

    Parameters
    ----------
    m : array_like, real, shape (..., n, n)
    check : bool, keyword-only
        Require ``m`` to be skew, ``m_ji = -m_ij``, to 8 ulps of its largest entry.

    Returns
    -------
    ndarray, shape (..., n(n-1)/2)

    Raises
    ------
    ValueError
        Not square, complex or non-finite values, or (with ``check``) not skew.

    Examples
    --------
    >>> import manakov
    >>> m = manakov.to_matrix([1, 2, 3, 4, 5, 6])
    >>> print(manakov.from_matrix(m))
    [1. 2. 3. 4. 5. 6.]
    """
    arr = _float_array(m, "m")
    if arr.ndim < 2 or arr.shape[-1] != arr.shape[-2]:
        raise ValueError(f"m must have shape (..., n, n), got {arr.shape}")
    if check:
        scale = np.max(np.abs(arr), initial=0.0)
        # Halved before adding so entries near the double limit cannot overflow.
        half = 0.5 * arr
        asym_half = np.max(np.abs(half + np.swapaxes(half, -1, -2)), initial=0.0)
        if asym_half > 4 * np.finfo(float).eps * scale:
            raise ValueError(f"m must be skew-symmetric; max |m + m^T| / 2 = {asym_half:e}")
    n = arr.shape[-1]
    iu = np.triu_indices(n, 1)
    return arr[..., iu[0], iu[1]].copy()


def poisson_tensor(l: Any) -> np.ndarray:
    """The Lie–Poisson tensor (3) of so(n) at ``l``: ``P[..., p, q] = {l_p, l_q}``.

    ``{l_ij, l_km} = l_im δ_jk - l_ik δ_jm + l_jk δ_im - l_jm δ_ik`` (3), for
    state indices ``p = (ij)``, ``q = (km)`` (``i < j``, ``k < m``). For any
    function ``F``, ``{F, l_q} = Σ_p ∂F/∂l_p P[p, q]``.

    Parameters
    ----------
    l : array_like, shape (..., n(n-1)/2)

    Returns
    -------
    ndarray, shape (..., n(n-1)/2, n(n-1)/2)

    Raises
    ------
    ValueError
        A last axis that is not ``n(n-1)/2`` (n >= 2), complex or non-finite values.

    Examples
    --------
    >>> import numpy as np, manakov
    >>> P = manakov.poisson_tensor([0.8, -0.3, 0.5, 1.1, -0.7, 0.2])
    >>> P.shape, bool(np.allclose(P, -P.T))
    ((6, 6), True)
    """
    arr = _float_array(l, "l")
    if arr.ndim == 0:
        raise ValueError("l must have shape (..., n(n-1)/2)")
    m = arr.shape[-1]
    _n_from_dim(m)
    flat, lead = _states(arr, m)
    return _core.poisson_tensor(flat).reshape(lead + (m, m))


class FrahmTop:
    """The Euler–Frahm top (1) on so(n) with symmetric coefficients ``c_ij = 1/I_ij``.

    Parameters
    ----------
    c : array_like, shape (n, n)
        Symmetric (to 8 ulps), finite; ``n >= 3``. The diagonal is not used.

    Raises
    ------
    ValueError
        If ``c`` is not square, not finite, not symmetric, or ``n < 3``.

    Examples
    --------
    >>> import numpy as np, manakov
    >>> c = np.array([[0, 1, 2, 3], [1, 0, 4, 5], [2, 4, 0, 6], [3, 5, 6, 0]], dtype=float)
    >>> top = manakov.FrahmTop(c)
    >>> tr = top.integrate([0.8, -0.3, 0.5, 1.1, -0.7, 0.2], 10.0, sample_every=1.0)
    >>> tr.l.shape, max(tr.max_drift().values()) < 1e-13
    ((11, 6), True)
    """

    def __init__(self, c: Any) -> None:
        carr = _float_array(c, "c")
        if carr.ndim != 2 or carr.shape[0] != carr.shape[1] or carr.shape[0] < 3:
            raise ValueError(f"c must have shape (n, n) with n >= 3, got {carr.shape}")
        carr = np.array(carr, dtype=float, order="C")
        _core.check_c(carr)
        carr.setflags(write=False)
        self._c = carr

    @property
    def c(self) -> np.ndarray:
        """The coefficients ``c_ij`` (read-only)."""
        return self._c

    @property
    def n(self) -> int:
        """The dimension ``n`` of the body."""
        return int(self._c.shape[0])

    @property
    def dim(self) -> int:
        """Length ``n(n-1)/2`` of the state."""
        return state_dim(self.n)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={self.n})"

    def vector_field(self, l: Any) -> np.ndarray:
        """The right-hand side of (1): ``l̇ = [l, ω]``, ``ω_ij = c_ij l_ij``.

        Parameters
        ----------
        l : array_like, shape (..., n(n-1)/2)

        Returns
        -------
        ndarray, same shape as ``l``

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l``, or a result that overflows.
        """
        flat, lead = _states(l, self.dim)
        return _finite_result(_core.vector_field(self._c, flat)).reshape(lead + (self.dim,))

    def hamiltonian(self, l: Any) -> Any:
        """The energy (4), ``H = ½ Σ_{j<k} c_jk l_jk²``.

        Parameters
        ----------
        l : array_like, shape (..., n(n-1)/2)

        Returns
        -------
        float or ndarray, shape ``l.shape[:-1]``

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l``, or a result that overflows.
        """
        flat, lead = _states(l, self.dim)
        return _out(_core.hamiltonian(self._c, flat), lead)

    def integrals(self, l: Any) -> dict[str, Any]:
        """Conserved quantities of (1) for any symmetric ``c``.

        ``H1 = Σ_{j<k} l_jk²`` (7) (the Casimir ``-½ tr l²``), ``H`` (4), and for
        n = 4 also the Casimir ``H0 = l12 l34 + l23 l14 + l31 l24`` (6).

        Parameters
        ----------
        l : array_like, shape (..., n(n-1)/2)

        Returns
        -------
        dict of str to float or ndarray
            Keys ``"H0"`` (n = 4 only), ``"H1"``, ``"H"``; values of shape ``l.shape[:-1]``.

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l``, or a result that overflows.
        """
        flat, lead = _states(l, self.dim)
        out: dict[str, Any] = {}
        if self.n == 4:
            with np.errstate(over="ignore", invalid="ignore"):
                h0 = flat[:, 0] * flat[:, 5] + flat[:, 3] * flat[:, 2] - flat[:, 1] * flat[:, 4]
            out["H0"] = _out(h0, lead)
        with np.errstate(over="ignore", invalid="ignore"):
            h1 = np.einsum("ij,ij->i", flat, flat)
        out["H1"] = _out(h1, lead)
        out["H"] = _out(_core.hamiltonian(self._c, flat), lead)
        return out

    # -- integration ---------------------------------------------------------

    def time_scale(self, l0: Any) -> Any:
        """``1/Ω``, ``Ω = (max_{i≠j} c_ij - min_{i≠j} c_ij) · ‖l0‖₂``; ``inf`` if Ω = 0.

        ``Ω`` bounds ``|c_kj - c_ik| · ‖l‖``, the Lipschitz constant of (1) on the orbit.

        Parameters
        ----------
        l0 : array_like, real, shape (..., n(n-1)/2)

        Returns
        -------
        float or ndarray, shape ``l0.shape[:-1]``

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l0``.
        """
        flat, lead = _states(l0, self.dim, "l0")
        out = np.array([self._time_scale(x) for x in flat]).reshape(lead)
        return float(out) if out.ndim == 0 else out

    def _time_scale(self, l0: np.ndarray) -> float:
        n, c = self.n, self._c
        off = c[~np.eye(n, dtype=bool)]
        spread = float(np.max(off) - np.min(off)) if off.size else 0.0
        big = float(np.max(np.abs(l0), initial=0.0))
        # ‖l0‖ scaled by its largest entry, so that squaring cannot overflow.
        norm = big * float(np.linalg.norm(l0 / big)) if big > 0 else 0.0
        with np.errstate(over="ignore"):
            omega = float(np.float64(spread) * np.float64(norm))
        return math.inf if omega == 0 else 1.0 / omega

    def default_dt(self, l0: Any, method: str = "gauss16") -> Any:
        """The default step of ``method`` for this top from ``l0``: ``DT_SCALE[method] / Ω``.

        ``Ω`` as in :meth:`time_scale`; 1 if ``Ω = 0``; 0 (automatic) for explicit methods.

        Parameters
        ----------
        l0 : array_like, real, shape (..., n(n-1)/2)
        method : str
            One of :data:`METHODS`.

        Returns
        -------
        float or ndarray, shape ``l0.shape[:-1]``

        Raises
        ------
        ValueError
            Unknown ``method``, wrong last axis, complex or non-finite ``l0`` (for
            every method), or a step that underflows.
        """
        check_method(method)
        flat, lead = _states(l0, self.dim, "l0")
        out = np.array([self._default_dt(x, method) for x in flat]).reshape(lead)
        return float(out) if out.ndim == 0 else out

    def _default_dt(self, l0: np.ndarray, method: str) -> float:
        ts = self._time_scale(l0)
        if method in ADAPTIVE_METHODS:
            return 0.0
        if not math.isfinite(ts):
            return 1.0
        dt = DT_SCALE[method] * ts
        if not dt > 0:
            raise ValueError("l0 is too large: its time scale 1/Ω underflows; rescale l0")
        return dt

    def _batch_default_dt(self, flat: np.ndarray, method: str) -> float:
        """The one default step of states ``flat`` (N, m): the smallest of their
        defaults, that of the largest ``|l0|`` (the default is
        ``DT_SCALE / ((max c - min c) |l0|)``)."""
        if flat.shape[0] == 1:
            return self._default_dt(flat[0], method)
        big = np.max(np.abs(flat), axis=1, keepdims=True)
        safe = np.where(big > 0, big, 1.0)
        # Only the argmax is used: a norm overflowing to inf still picks the
        # largest state, whose default step then names the cause.
        with np.errstate(over="ignore"):
            norms = big[:, 0] * np.linalg.norm(flat / safe, axis=1)
        return self._default_dt(flat[int(np.argmax(norms))], method)

    def _refuse_default_step(
        self, l0s: np.ndarray, method: str, dt: float, t_end: float, budget: int
    ) -> None:
        """Name the cause when the *default* step needs more than ``budget`` steps.

        The default step is ``DT_SCALE / Ω``, ``Ω = (max c - min c) |l0|``: either a
        huge ``|l0|`` or a large spread of the ``c_ij`` (for Manakov's top, nearly
        equal ``a_i``) makes it small.
        """
        if method in ADAPTIVE_METHODS or not t_end / dt > budget:
            return
        off = self._c[~np.eye(self.n, dtype=bool)]
        spread = float(np.max(off) - np.min(off))
        big = float(np.max(np.abs(l0s), initial=0.0))
        need = (
            f"the default {method} step is DT_SCALE / Omega = {dt:.3g}, Omega = "
            f"(max c - min c) |l0| with max c - min c = {spread:.3g} and largest |l0| "
            f"entry {big:.3g}, so t_end = {t_end:.3g} needs {t_end / dt:.3g} steps, more "
            f"than max_steps = {budget}"
        )
        if spread > big:
            raise ValueError(
                f"a large spread of the c_ij{self._spread_origin()}: {need}. The fast "
                "motion this top carries needs steps of about 1/Omega: shorten t_end, "
                "raise max_steps, pass a larger dt (less accurate), or move the a_i apart"
            )
        raise ValueError(
            f"a huge |l0|: {need}. The motion's time scale is 1/|l0|: rescale the state "
            "(l -> l/s, t -> s t), pass a larger dt, or raise max_steps"
        )

    def _spread_origin(self) -> str:
        return ""

    def integrate(
        self,
        l0: Any,
        t_end: float,
        *,
        dt: float | None = None,
        t_eval: Any = None,
        sample_every: float | None = None,
        method: str = "gauss16",
        rtol: float | None = None,
        atol: float = 1e-12,
        progress: bool | Callable[[float], object] | None = None,
        chunks: int = 1,
        max_steps: int = DEFAULT_MAX_STEPS,
        parallel: bool = True,
        chunk_size: int | None = None,
    ) -> Trajectory:
        """Integrate (1) from ``l0`` at t = 0 to ``t_end``, keeping samples only.

        Gauss methods take equal steps of at most ``dt`` between consecutive
        sample times (so every sample lands on its time) and solve each step to
        machine precision: the quadratic integrals H0–H3 and H are conserved to
        roundoff, which grows like the square root of the number of steps.

        Broadcasts over leading axes: ``l0`` of shape ``(..., n(n-1)/2)`` is a
        batch, run with the GIL released on all cores (as :meth:`integrate_many`),
        and every array of the result gains its leading axes.

        Parameters
        ----------
        l0 : array_like, shape (..., n(n-1)/2)
            One initial state, or a batch.
        t_end : float, >= 0
            ``t_end = 0`` gives the one sample ``l0`` at t = 0 (unless ``t_eval``
            asks for more).
        dt : float, optional
            Largest step of a Gauss method (default: ``default_dt``; for a batch
            the smallest over its states); initial step of ``dopri5``/``dop853``
            (default automatic); largest step of ``taylor`` (default: none).
        t_eval : array_like, optional
            Sorted sample times in [0, t_end].
        sample_every : float, optional
            Sample at 0, sample_every, 2 sample_every, ..., and t_end.
            Default (neither given): 1001 evenly spaced samples.
        method : {"gauss16", "gauss6", "gauss4", "dopri5", "dop853", "taylor"}
            ``taylor`` is Taylor's method for so(4) (see Notes).
        rtol, atol : float
            Tolerances of ``dopri5`` and ``dop853`` (default ``rtol`` 1e-12): each
            step keeps its error estimate below ``atol + rtol |l|`` componentwise.
            ``rtol`` must be at least ``100 eps`` (about 2.2e-14, scipy's floor; a
            smaller relative target is below the rounding of a step) and ``atol``
            >= 0; otherwise ValueError. For ``taylor``, ``rtol`` is the relative
            error per step ``ε`` (default and smallest: ``eps``; at most 1e-3) and
            ``atol`` is ignored. Gauss methods ignore both (they are neither used
            nor checked).
        progress : bool or callable, optional
            ``True``: a progress bar on stderr; ``False``: none; a callable: called
            with the fraction of samples written (0 to 1, non-decreasing; at most
            every ~20 ms and once at the end). Default: a bar on a terminal for a
            Gauss run of at least 10^6 steps. Watching does not change the run.
        chunks : int
            Split one state's run into this many calls to the core, at sample
            times (an integer >= 1, capped at the number of samples). Not needed
            for ``progress``; results agree with one call to roundoff, not bit for
            bit (each call starts its step control afresh). One state only.
        max_steps : int
            Step budget of each trajectory (default :data:`DEFAULT_MAX_STEPS`, at
            most 10^11). Checked before the first step: more sample intervals than
            ``max_steps`` (each needs a step), or for Gauss methods more steps than
            ``max_steps`` (known in advance), is refused with a ValueError naming
            the cause (the sample spacing, a huge ``|l0|`` behind the default step,
            or ``dt``). Explicit methods stop once they exceed it.
        parallel : bool
            Split a batch over threads (rayon).
        chunk_size : int, optional
            States per call to the core in a batch (default
            :data:`~manakov.integrate.BATCH_CHUNK`): what an interruption keeps.

        Returns
        -------
        Trajectory
            ``t`` (S,), ``l`` (..., S, n(n-1)/2), ``integrals``, ``steps``, ...

        Raises
        ------
        ValueError
            Bad shapes, non-finite values, ``t_end`` < 0 or NaN, ``dt`` <= 0,
            an unknown ``method``, ``rtol`` below ``100 eps`` or ``atol`` < 0 for
            an explicit method, ``chunks`` or ``chunk_size`` not an integer >= 1,
            ``progress`` not a bool or callable, an output too large to allocate,
            or a run over ``max_steps`` (refused before any step, or for an
            explicit method when it runs out).
        manakov.ConvergenceError
            A Gauss step whose stage equations do not converge (``dt`` too large).
        KeyboardInterrupt
            Ctrl-C (SIGINT) during the run: the call stops within a few
            milliseconds; no thread outlives it.

        Notes
        -----
        ``taylor`` expands ``l(t + τ) = Σ_n X_n τ^n`` by the recurrence of the
        quadratic field (1), ``X_{n+1,ij} = Σ_k (c_kj - c_ik) Σ_{m=0..n} X_{m,ik}
        X_{n-m,kj} / (n + 1)`` (twelve Cauchy products per order), with the order
        ``p = ceil(-ln ε / 2 + 1)`` and the step ``h = ρ e^-2 e^(-0.7/(p-1))``, ``ρ``
        the radius of convergence estimated from ``X_{p-1}`` and ``X_p`` relative to
        ``|l|`` (A. Jorba, M. Zou, Exp. Math. 14 (2005) 99–117; F. Biscani, D. Izzo,
        MNRAS 504 (2021) 2614). Samples are its dense output (the step's polynomial
        at the sample time). The leading term ``h f(l)`` is summed in double-double
        and the state carried with a compensation, so at ``rtol = eps`` the error is
        roundoff: 1.8e-14 at t = 100 on 'generic', integrals kept to ~4e-15 over
        t = 1e4 (``docs/dynamics.md``). Looser ``rtol`` lowers the order and the
        integrals drift; ``gauss16`` conserves them at any step.

        For so(4) with ``gauss16``, ``dop853`` or ``taylor`` a batch runs on a
        kernel whose vector lanes carry different trajectories (4 per AVX2
        register); the results equal those of each state alone, bit for bit
        (``docs/dynamics.md``).

        An error raised after the run started (KeyboardInterrupt, an explicit
        method's ``max_steps``, ConvergenceError, the ``progress`` callable's own)
        carries what was computed as ``err.partial``, a :class:`Trajectory` with
        ``ok`` false: one state's samples up to that point (possibly none), or a
        batch's trajectories finished before it (NaN elsewhere)::

            try:
                tr = top.integrate(l0, 1e7)
            except KeyboardInterrupt as err:
                tr = err.partial  # the samples before Ctrl-C
        """
        return _integrate.run(
            self,
            l0,
            t_end,
            dt=dt,
            t_eval=t_eval,
            sample_every=sample_every,
            method=method,
            rtol=rtol,
            atol=atol,
            progress=progress,
            chunks=chunks,
            max_steps=max_steps,
            parallel=parallel,
            chunk_size=chunk_size,
        )

    def integrate_many(
        self,
        l0s: Any,
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
        progress: bool | Callable[[float], object] | None = None,
        chunk_size: int | None = None,
    ) -> Trajectory:
        """Integrate a batch of initial states in one call, GIL released: :meth:`integrate`.

        The batch spelling of :meth:`integrate`, which broadcasts over leading
        axes itself: the same arguments (except ``chunks``), the same result, bit
        for bit.

        Parameters
        ----------
        l0s : array_like, shape (..., n(n-1)/2)
        t_end, dt, t_eval, sample_every, method, rtol, atol, max_steps, progress
            As in :meth:`integrate`; ``dt`` defaults to the smallest default
            step over the batch, ``max_steps`` is the budget of each trajectory.
        parallel : bool
            Split the batch over threads (rayon).
        chunk_size : int, optional
            As in :meth:`integrate`.

        Returns
        -------
        Trajectory
            ``t`` (S,) and ``l`` (..., S, n(n-1)/2), ... (``t, l = ...`` unpacks).

        Raises
        ------
        ValueError, manakov.ConvergenceError, KeyboardInterrupt
            As :meth:`integrate` (with ``err.partial``).
        """
        return _integrate.run(
            self,
            l0s,
            t_end,
            dt=dt,
            t_eval=t_eval,
            sample_every=sample_every,
            method=method,
            rtol=rtol,
            atol=atol,
            progress=progress,
            chunks=1,
            max_steps=max_steps,
            parallel=parallel,
            chunk_size=chunk_size,
        )


class ManakovTop(FrahmTop):
    """Manakov's integrable top: (1) with ``c_ij = (b_i - b_j)/(a_i - a_j)`` (2).

    Parameters
    ----------
    a, b : array_like, shape (n,)
        ``n >= 3``, finite, ``a_i`` distinct.

    Raises
    ------
    ValueError
        Lengths differ, ``n < 3``, non-finite values, or ``a_i == a_j``
        (the message names the pair).

    Notes
    -----
    ``c_ij`` is the correctly rounded quotient of the exact differences of the
    given doubles when ``a_i``, ``a_j`` are close (Sterbenz's lemma); the
    loss of digits in the near-degenerate case is the conditioning of (2),
    ``|a_i| / |a_i - a_j|``, applied to the rounding of the inputs.

    Examples
    --------
    >>> import manakov
    >>> top = manakov.ManakovTop([0.3, 1.1, 2.0, 3.7], [0.5, -0.2, 1.4, 0.9])
    >>> print(round(top.c[0, 1], 6))  # c_12 = (b_1 - b_2)/(a_1 - a_2)  (2)
    -0.875
    >>> ints = top.integrals([0.8, -0.3, 0.5, 1.1, -0.7, 0.2])
    >>> print({k: round(float(v), 6) for k, v in ints.items()})
    {'H0': 0.5, 'H1': 2.72, 'H2': 10.878, 'H3': 7.3026, 'H': 0.931856}
    """

    def __init__(self, a: Any, b: Any) -> None:
        aa = _float_array(a, "a")
        bb = _float_array(b, "b")
        if aa.ndim != 1 or bb.ndim != 1:
            raise ValueError(f"a and b must be 1-d, got shapes {aa.shape}, {bb.shape}")
        if aa.shape != bb.shape:
            raise ValueError(f"a and b must have the same length, got {aa.size} and {bb.size}")
        aa = np.array(aa, dtype=float)
        bb = np.array(bb, dtype=float)
        c = _core.manakov_c(aa, bb)
        super().__init__(c)
        aa.setflags(write=False)
        bb.setflags(write=False)
        self._a, self._b = aa, bb

    @property
    def a(self) -> np.ndarray:
        """The ``a_i`` of (2) (read-only)."""
        return self._a

    @property
    def b(self) -> np.ndarray:
        """The ``b_i`` of (2) (read-only)."""
        return self._b

    def integrals(self, l: Any) -> dict[str, Any]:
        """The integrals of motion, by name.

        For n = 4: ``H0`` (6), ``H1``, ``H2``, ``H3`` (7, corrected: the printed
        ``H3 = Σ a_j a_k l_jk²`` is not conserved; the conserved forms use the
        complementary pair ``{l, m} = {1,2,3,4} \\ {j, k}``,
        ``H2 = Σ (a_l + a_m) l_jk²``, ``H3 = Σ a_l a_m l_jk²``), and ``H`` (4).
        For n ≠ 4: ``H1``, ``H`` and Manakov's integrals ``"I{k}_{j}"``, the
        coefficient of ``λ^j`` in ``tr (l + λ diag(a))^k``.

        Parameters
        ----------
        l : array_like, shape (..., n(n-1)/2)

        Returns
        -------
        dict of str to float or ndarray
            Values of shape ``l.shape[:-1]``.

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l``, or a result that overflows.
        """
        flat, lead = _states(l, self.dim)
        if self.n == 4:
            h = _core.so4_integrals(self._a, flat)
            out = {f"H{i}": _out(h[:, i], lead) for i in range(4)}
            out["H"] = _out(_core.hamiltonian(self._c, flat), lead)
            return out
        out = super().integrals(l)
        vals = _core.manakov_integrals(self._a, flat)
        for i, (k, j) in enumerate(self.manakov_integral_labels()):
            out[f"I{k}_{j}"] = _out(vals[:, i], lead)
        return out

    def manakov_integral_labels(self) -> list[tuple[int, int]]:
        """Labels ``(k, j)`` of :meth:`manakov_integrals`.

        ``k = 2..n``, ``j <= k - 2``, ``k - j`` even (the others vanish or are constant).

        Returns
        -------
        list of (int, int)
        """
        return [tuple(x) for x in _core.manakov_integral_labels(self.n)]  # type: ignore[misc]

    def manakov_integrals(self, l: Any) -> np.ndarray:
        """Manakov's integrals: the coefficients of ``λ^j`` in ``tr (l + λ A)^k``, ``A = diag(a)``.

        Conserved by (1)–(2) for every n because (1) is the Lax equation
        ``d/dt (l + λA) = [l + λA, ω + λB]``, ``B = diag(b)`` [Ma 1977].

        Parameters
        ----------
        l : array_like, shape (..., n(n-1)/2)

        Returns
        -------
        ndarray, shape (..., K), ordered as :meth:`manakov_integral_labels`

        Raises
        ------
        ValueError
            Wrong last axis, complex or non-finite ``l``, or a result that overflows.
        """
        flat, lead = _states(l, self.dim)
        vals = _finite_result(_core.manakov_integrals(self._a, flat))
        return vals.reshape(lead + (vals.shape[1],))

    def kotter(self, l: Any, *, errors: str = "raise") -> Kotter:
        """Schottky–Kötter coordinates of the state(s) ``l`` (n = 4 only).

        Shorthand for :func:`manakov.kotter` ``(self.a, self.b, l)``: the roots of
        F (19), Kötter's vectors ξ, η (22), the curve constants d (26), and the two
        points of the curve (8) with g, such that ξ_j = √c_j g P_kl, η_j = √c_j g P_j4
        (37), (42). See ``docs/kotter.md``.

        For one-off use: each state gets its own level set's constants and
        branch choices (documented root order, principal square roots, the
        point of larger modulus first), which can change between samples of a
        trajectory; there use :meth:`level_set`.

        Parameters
        ----------
        l : array_like, shape (..., 6)
        errors : {"raise", "mask"}, keyword-only
            As :func:`manakov.kotter`.

        Returns
        -------
        manakov.Kotter

        Raises
        ------
        ValueError
            ``n != 4``, and as :func:`manakov.kotter`.
        """
        self._require_so4("kotter")
        return _kotter(self._a, self._b, l, errors=errors)

    def level_set(self, l0: Any) -> _LevelSet:
        """The level set of ``l0`` with Kötter's constants fixed once (n = 4 only).

        Shorthand for :class:`manakov.LevelSet` ``(self.a, self.b, l0)``; its
        ``kotter(l)`` maps states of the level set to divisors that move
        continuously along a trajectory.

        Raises
        ------
        ValueError
            ``n != 4``, and as :class:`manakov.LevelSet`.
        """
        self._require_so4("level_set")
        return _LevelSet(self._a, self._b, l0)

    def from_kotter(self, k: Kotter) -> np.ndarray:
        """Map Schottky–Kötter coordinates back to the state l (n = 4 only).

        Shorthand for :func:`manakov.from_kotter` ``(self.a, self.b, k)``: rebuilds
        ξ, η from the curve points and g by (37) and inverts (23).

        Parameters
        ----------
        k : manakov.Kotter
            As returned by :meth:`kotter`.

        Returns
        -------
        ndarray, shape (..., 6)

        Raises
        ------
        ValueError
            ``n != 4``, and as :func:`manakov.from_kotter`.
        """
        self._require_so4("from_kotter")
        return _from_kotter(self._a, self._b, k)

    def _spread_origin(self) -> str:
        # The pair with the largest |c_ij| and how close its a_i are.
        n = self.n
        iu = np.triu_indices(n, 1)
        k = int(np.argmax(np.abs(self._c[iu])))
        i, j = int(iu[0][k]), int(iu[1][k])
        gap = abs(float(self._a[i] - self._a[j]))
        return (
            f" (c{i + 1}{j + 1} = {self._c[i, j]:.3g} = (b{i + 1} - b{j + 1}) / "
            f"(a{i + 1} - a{j + 1}) with a{i + 1} - a{j + 1} = {gap:.3g}: nearly equal a_i)"
        )

    def solve(self, l0: Any) -> Solution:
        """The explicit solution through ``l0``: the Theorem (9)–(10), ``l(t)`` as
        theta quotients, or the closed form where it degenerates.

        Parameters
        ----------
        l0 : array_like, shape (6,)
            Any finite scale (the input is normalized, docs/degenerate.md).

        Returns
        -------
        manakov.solution.Solution
            ``.kind`` (``"genus2"``, ``"euler"``, ``"separatrix"``,
            ``"equilibrium"``, ``"spherical"``, ``"rest"``, ``"integrated"``),
            ``.l(t)``, ``.frequencies``; for ``"genus2"`` also ``.u0``, ``.U``,
            ``.tau``, ``.curve``, ``.characteristics``, ``.constants``, ``.abel(l)``.

        Raises
        ------
        ValueError
            Not an so(4) top, or invalid ``l0`` (shape, non-finite values).

        Notes
        -----
        Every valid state gets a solution. Where the closed form cannot be built
        (a level set on which the Theorem's coordinates are singular to working
        precision; the ``repr`` names the step) it is of kind ``"integrated"``: its
        ``l(t)`` is an integration of (1) in double-double, confirmed with every
        step halved, at every call, with an ``IntegratedValuesWarning``; it has
        no frequencies. A closed form that fails its self-check
        (``Solution.self_check`` above 1e-10 or ``Solution.velocity_check`` above
        1e-6) is returned marked (``Solution.self_check_passed`` False): its
        ``l(t)`` is certified by an integration at every call, or replaced by it
        where it is off, and its phase is refused (docs/degenerate.md §10).
        """
        self._require_so4("solve")
        return Solution(self.a, self.b, l0)

    def _require_so4(self, what: str) -> None:
        if self.n != 4:
            raise ValueError(f"{what} is defined for so(4) only (n = 4), this top has n = {self.n}")

    def __repr__(self) -> str:
        return f"ManakovTop(a={self._a.tolist()}, b={self._b.tolist()})"
