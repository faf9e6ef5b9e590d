# The state is called l, as in the paper: E741 does not apply.
# ruff: noqa: E741
"""Integration of Frahm's equations (1): methods, defaults, sample times and the run.

The Python side of the core's ``integrate`` layer (``rust/integrate/``).
:meth:`manakov.FrahmTop.integrate` and :meth:`~manakov.FrahmTop.integrate_many`
call :func:`run`; this module knows the top only through its coefficients
``c``, its state length and its integrals, so it imports nothing above
``_checks`` (the top imports it, not the other way round).

The calls follow the package's convention (``docs/conventions.md``): states on
the last axis with any leading axes, a :class:`Trajectory` result whose arrays
gain those axes, ``progress`` as ``None``/``True``/``False``/a callable, Ctrl-C
within a fraction of a second, and ``err.partial`` on an error after the run
started.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from ._checks import _float_array, _states
from ._progress import Progress

__all__ = [
    "ADAPTIVE_METHODS",
    "BATCH_CHUNK",
    "DEFAULT_MAX_STEPS",
    "DEFAULT_RTOL",
    "DEFAULT_SAMPLES",
    "DT_SCALE",
    "MAX_SAMPLES",
    "METHODS",
    "Trajectory",
    "gauss_steps",
    "run",
    "sample_times",
]

#: Integration methods: Gauss–Legendre collocation with 2, 3 and 8 stages
#: (orders 4, 6, 16), the explicit adaptive Dormand–Prince pairs 5(4) and 8(5,3),
#: and Taylor's method (so(4) only; order and step from ``rtol``, Jorba & Zou 2005).
METHODS = ("gauss4", "gauss6", "gauss16", "dopri5", "dop853", "taylor")
#: The adaptive methods: their step follows from ``rtol`` (and ``atol``), not ``dt``.
ADAPTIVE_METHODS = ("dopri5", "dop853", "taylor")

#: Default ``rtol`` of each adaptive method. Taylor's method at machine epsilon
#: (order 20) is its most accurate setting and, per unit of accuracy, its fastest
#: batch kernel (``docs/dynamics.md``); the Dormand–Prince pairs keep 1e-12.
DEFAULT_RTOL = {"dopri5": 1e-12, "dop853": 1e-12, "taylor": float(np.finfo(float).eps)}

#: Default step of each Gauss method in units of the top's time scale
#: ``1/Ω``, ``Ω = (max c_ij - min c_ij) · ‖l0‖`` (a bound on the Lipschitz
#: constant of (1) on the orbit). Chosen on the shared 'generic' top so that the error at
#: t = 100 is ~1e-13 (gauss16: dt = 0.34, three steps per unit time) and the
#: stage iteration converges in ~15 sweeps; see ``docs/dynamics.md``.
DT_SCALE = {"gauss4": 0.01, "gauss6": 0.044, "gauss16": 1.5}

#: Default number of samples when neither ``t_eval`` nor ``sample_every`` is given
#: (and ``t_end > 0``; ``t_end = 0`` has the one sample ``l0``).
DEFAULT_SAMPLES = 1001

#: Most samples ``sample_every`` may ask for: 10^8 sample times are 0.8 GB, and
#: the so(4) states at them 4.8 GB per trajectory.
MAX_SAMPLES = 10**8

#: Default step budget of one call to ``integrate``/``integrate_many`` (per
#: trajectory): 10^8 steps bound a run to minutes (gauss16 ~1.3 µs a step on
#: 'generic', dop853 ~0.3 µs) while leaving a 10x margin over runs of 10^7
#: steps. Runs are interruptible (Ctrl-C). Pass ``max_steps`` (up to 10^11)
#: for longer runs.
DEFAULT_MAX_STEPS = 10**8

#: The core's hard cap on ``max_steps`` (``integrate::MAX_STEPS``).
_MAX_STEPS_CAP = 10**11

#: States per call to the core in a batch run: the unit of work that an
#: interruption keeps (``err.partial``). Large enough that the thread pool stays
#: busy (32 of the Taylor kernel's tasks of 128 trajectories, 1024 gauss16 lane
#: groups), so the pause between calls is a small part of each; the lanes are
#: independent, so the split changes no result.
BATCH_CHUNK = 4096

#: A Gauss run of at least this many steps (all trajectories) shows the progress
#: bar by default on a terminal: about a second at ~1 µs a step.
PROGRESS_MIN_STEPS = 10**6


@dataclass(frozen=True)
class Trajectory:
    """A sampled solution of (1), for one initial state or a batch.

    For one initial state the arrays have the shapes below; for a batch of
    initial states with leading shape ``B`` (``l0`` of shape ``B + (m,)``) every
    per-trajectory array gains the leading axes ``B``, as every result of the
    package does (``docs/conventions.md``).

    Unpacks as ``t, l`` (``t, l = top.integrate_many(...)`` reads as the tuple
    that call once returned); use the attributes for the rest.

    Attributes
    ----------
    t : ndarray, shape (S,)
        Sample times (shared by the batch).
    l : ndarray, shape (..., S, n(n-1)/2)
        States at the sample times.
    integrals : dict of str to ndarray (..., S)
        The top's integrals along the samples (see ``FrahmTop.integrals``).
    method : str
    dt : float
        The largest step (Gauss methods) or the initial step (explicit; 0 = automatic);
        for a batch, the one step of all its trajectories.
    steps : int
        Steps taken, summed over the trajectories of a batch.
    evals : int or None
        Vector-field evaluations of one trajectory; ``None`` for a batch (its
        kernels do not count them).
    ok : bool or ndarray of bool, shape (...)
        Which trajectories are complete. All true in a returned trajectory; in
        ``err.partial`` of an interrupted run false: there, one trajectory holds
        the samples up to the interruption (``t`` is shorter), and a batch holds
        the trajectories finished before it, with NaN states and integrals where
        ``ok`` is false.

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> tr = manakov.ManakovTop(p.a, p.b).integrate(p.l0, 10.0, sample_every=1.0)
    >>> tr.t.shape, tr.l.shape, tr.ok
    ((11,), (11, 6), True)
    >>> max(tr.max_drift().values()) < 1e-13
    True
    """

    t: np.ndarray
    l: np.ndarray
    integrals: dict[str, np.ndarray]
    method: str
    dt: float
    steps: int
    evals: int | None
    ok: Any = field(default=True)

    def __iter__(self) -> Iterator[np.ndarray]:
        """``t`` and ``l``, so that ``t, l = trajectory`` unpacks."""
        return iter((self.t, self.l))

    def relative_drift(self) -> dict[str, np.ndarray]:
        """``|I(t) - I(t0)| / |I(t0)|`` for each integral (absolute if ``I(t0) = 0``).

        Returns
        -------
        dict of str to ndarray, shape (..., S)
        """
        out = {}
        for name, v in self.integrals.items():
            if v.shape[-1] == 0:
                out[name] = np.zeros(v.shape)
                continue
            v0 = v[..., :1]
            ref = np.where(v0 != 0, np.abs(v0), 1.0)
            out[name] = np.abs(v - v0) / ref
        return out

    def max_drift(self) -> dict[str, Any]:
        """The largest relative drift ``max_t |I(t) - I(t0)| / |I(t0)|`` of each integral.

        Returns
        -------
        dict of str to float or ndarray, shape (...)
            A float for one trajectory, an array over the batch's leading axes
            (NaN where ``ok`` is false in a partial batch).
        """
        out: dict[str, Any] = {}
        for k, v in self.relative_drift().items():
            m = np.max(v, axis=-1, initial=0.0)
            out[k] = float(m) if m.ndim == 0 else m
        return out


def check_method(method: Any) -> None:
    """Raise ValueError unless ``method`` is one of :data:`METHODS`."""
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"unknown method {method!r}; known: {', '.join(METHODS)}")


def _scalar(x: Any, what: str) -> float:
    arr = np.asarray(x)
    if arr.ndim != 0 or arr.dtype.kind not in "biuf":
        raise ValueError(f"{what} must be a real scalar, got {x!r}")
    v = float(arr)
    if not math.isfinite(v):
        raise ValueError(f"{what} must be finite, got {v}")
    return v


def _positive_int(x: Any, what: str) -> int:
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < 1:
        raise ValueError(f"{what} must be an integer >= 1, got {x!r}")
    return int(x)


def sample_times(t_end: Any, t_eval: Any = None, sample_every: Any = None) -> np.ndarray:
    """The sample times of a run to ``t_end`` (checked), as :meth:`FrahmTop.integrate` takes them.

    Parameters
    ----------
    t_end : float, >= 0
    t_eval : array_like, optional
        Sorted times in ``[0, t_end]`` (copied).
    sample_every : float, optional
        ``0, sample_every, 2 sample_every, ...`` and ``t_end``.

    Returns
    -------
    ndarray, shape (S,)
        ``t_eval``; or the grid of ``sample_every``; or, with neither,
        :data:`DEFAULT_SAMPLES` evenly spaced times, or the one time 0 when
        ``t_end = 0`` (the run's one sample is then ``l0``).

    Raises
    ------
    ValueError
        ``t_end`` negative or not finite, both ``t_eval`` and ``sample_every``,
        unsorted ``t_eval`` or outside ``[0, t_end]``, ``t_eval`` of more than
        :data:`MAX_SAMPLES` points, ``sample_every <= 0`` or
        more than :data:`MAX_SAMPLES` samples.

    Examples
    --------
    >>> from manakov.integrate import sample_times
    >>> print(sample_times(1.0, sample_every=0.25))
    [0.   0.25 0.5  0.75 1.  ]
    """
    t_end_f = _scalar(t_end, "t_end")
    if t_end_f < 0:
        raise ValueError(f"t_end must be >= 0, got {t_end_f}")
    if t_eval is not None and sample_every is not None:
        raise ValueError("give at most one of t_eval and sample_every")
    if t_eval is not None:
        # The sample cap before any conversion or work (a view of 1e9 zeros
        # would otherwise be copied, then integrated, then fail on the output).
        size = np.size(t_eval)
        if size > MAX_SAMPLES:
            raise ValueError(
                f"t_eval has {size} samples, more than MAX_SAMPLES = {MAX_SAMPLES:.0e} "
                "of one call; split the run"
            )
        te = _float_array(t_eval, "t_eval")
        if te.ndim != 1:
            raise ValueError(f"t_eval must be 1-d, got shape {te.shape}")
        if te.size and (np.any(np.diff(te) < 0) or te[0] < 0 or te[-1] > t_end_f):
            raise ValueError("t_eval must be sorted and lie in [0, t_end]")
        # A copy: the trajectory never shares memory with the caller's array.
        return np.array(te, dtype=np.float64, order="C", copy=True)
    if t_end_f == 0:
        return np.zeros(1)
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
    return np.linspace(0.0, t_end_f, DEFAULT_SAMPLES)


def gauss_steps(times: Any, dt: float, t0: float = 0.0) -> int:
    """The number of steps a Gauss method takes from ``t0`` through ``times``.

    Each sample interval of positive length is covered by equal steps of at most
    ``dt``, ``ceil(Δt / dt)`` of them (a ratio within 1e-9 of an integer counts
    as that integer, so 1.0 / 0.1 is 10 steps): the count of the core, which
    also checks ``max_steps`` with it.

    Parameters
    ----------
    times : array_like, shape (S,)
        Sorted sample times, ``>= t0``.
    dt : float, > 0
    t0 : float

    Returns
    -------
    int

    Raises
    ------
    ValueError
        Unsorted or non-finite times, ``dt`` not finite and positive.

    Examples
    --------
    >>> from manakov.integrate import gauss_steps
    >>> gauss_steps([0.0, 1.0, 2.5], 0.1)
    25
    """
    te = np.ascontiguousarray(_float_array(times, "times").reshape(-1))
    return int(_core.gauss_steps(float(t0), te, float(dt)))


def _max_steps(max_steps: Any) -> int:
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)):
        raise ValueError(f"max_steps must be an integer, got {max_steps!r}")
    if not 1 <= max_steps <= _MAX_STEPS_CAP:
        raise ValueError(f"max_steps must be in [1, 10^11], got {max_steps}")
    return int(max_steps)


def _tolerances(method: str, rtol: Any, atol: Any) -> tuple[float, float]:
    """``rtol``, ``atol`` of an adaptive method (checked; ``rtol = None`` is the
    method's :data:`DEFAULT_RTOL`); Gauss methods ignore them."""
    if method not in ADAPTIVE_METHODS:
        return 0.0, 0.0
    rt = DEFAULT_RTOL[method] if rtol is None else _scalar(rtol, "rtol")
    return rt, _scalar(atol, "atol")


def _step(dt: Any) -> float:
    dtf = _scalar(dt, "dt")
    if dtf <= 0:
        raise ValueError(f"dt must be > 0, got {dtf}")
    return dtf


def run(
    top: Any,
    l0: Any,
    t_end: Any,
    *,
    dt: Any,
    t_eval: Any,
    sample_every: Any,
    method: str,
    rtol: Any,
    atol: Any,
    progress: Any,
    chunks: Any,
    max_steps: Any,
    parallel: bool,
    chunk_size: Any,
) -> Trajectory:
    """The integration behind :meth:`FrahmTop.integrate` and ``integrate_many``.

    ``top`` provides ``c`` (its coefficients), ``dim``, ``integrals(l)``,
    ``_batch_default_dt(states, method)`` and ``_refuse_default_step``. Everything is
    checked before the first step (and before the first progress report).

    Examples
    --------
    >>> import manakov
    >>> from manakov.integrate import run
    >>> p = manakov.problem("generic")
    >>> top = manakov.ManakovTop(p.a, p.b)
    >>> tr = run(top, p.l0, 10.0, dt=None, t_eval=None, sample_every=1.0, method="gauss16",
    ...          rtol=None, atol=1e-12, progress=False, chunks=1, max_steps=10**8,
    ...          parallel=True, chunk_size=None)
    >>> tr.l.shape
    (11, 6)
    """
    flat, lead = _states(l0, top.dim, "l0")
    times = sample_times(t_end, t_eval, sample_every)
    check_method(method)
    n_chunks = _positive_int(chunks, "chunks")
    if lead != () and n_chunks != 1:
        raise ValueError(
            f"chunks = {n_chunks} splits the time span of one state's run; a batch "
            "(l0 of shape (..., m)) is split over its states by chunk_size"
        )
    size = BATCH_CHUNK if chunk_size is None else _positive_int(chunk_size, "chunk_size")
    if dt is None:
        # One step for the whole batch: the smallest default over its members.
        dtf = top._batch_default_dt(flat, method) if flat.size else 1.0
    else:
        dtf = _step(dt)
    rt, at = _tolerances(method, rtol, atol)
    budget = _max_steps(max_steps)
    if times.size and flat.shape[0] and dt is None:
        top._refuse_default_step(flat, method, dtf, float(times[-1]), budget)
    # The whole run's budget (per trajectory), before the first step.
    _core.check_budget(method, 0.0, times, dtf, budget)
    long = (
        method not in ADAPTIVE_METHODS
        and times.size > 0
        and gauss_steps(times, dtf) * flat.shape[0] >= PROGRESS_MIN_STEPS
    )
    with Progress(progress, "integrate", long=long) as report:
        if lead == ():
            return _run_one(top, flat[0], times, method, dtf, rt, at, budget, n_chunks, report)
        return _run_batch(
            top, flat, lead, times, method, dtf, rt, at, budget, bool(parallel), size, report
        )


def _run_one(
    top: Any,
    y0: np.ndarray,
    times: np.ndarray,
    method: str,
    dt: float,
    rtol: float,
    atol: float,
    budget: int,
    n_chunks: int,
    report: Progress,
) -> Trajectory:
    out: list[np.ndarray] = []
    steps = evals = 0

    def trajectory(complete: bool) -> Trajectory:
        ls = np.concatenate(out) if out else np.empty((0, top.dim))
        try:
            integrals = top.integrals(ls)
        except ValueError:
            if complete:
                raise
            # The samples before a failure may overflow the integrals: keep the
            # samples, without integrals.
            integrals = {}
        return Trajectory(
            t=times[: ls.shape[0]].copy(),
            l=ls,
            integrals=integrals,
            method=method,
            dt=dt,
            steps=int(steps),
            evals=int(evals),
            ok=complete,
        )

    total = times.size
    if total:
        y, t0, done = y0, 0.0, 0
        for piece in np.array_split(times, min(n_chunks, total)):
            base = done
            tick = (lambda k, base=base: report((base + k) / total)) if report.active else None
            ys, s, e, err = _core.integrate(
                top.c, y, t0, piece, method, dt, rtol, atol, budget - steps, tick
            )
            out.append(ys)
            steps, evals = steps + s, evals + e
            done += ys.shape[0]
            if err is not None:
                # Ctrl-C, max_steps, a failed step or the progress callable's own
                # exception: the samples reached so far ride on it (``err.partial``).
                err.partial = trajectory(complete=False)  # type: ignore[attr-defined]
                raise err
            y, t0 = ys[-1], float(piece[-1])
            report(done / total)
    report(1.0)
    return trajectory(complete=True)


def _run_batch(
    top: Any,
    flat: np.ndarray,
    lead: tuple[int, ...],
    times: np.ndarray,
    method: str,
    dt: float,
    rtol: float,
    atol: float,
    budget: int,
    parallel: bool,
    size: int,
    report: Progress,
) -> Trajectory:
    rows, m, nt = flat.shape[0], top.dim, times.size
    # The core's own checks (tolerances, method, budget) on no states: a refused
    # call raises here, before any work and without a partial result.
    _core.integrate_many(top.c, flat[:0], 0.0, times, method, dt, rtol, atol, budget, parallel)
    spans = [(i, min(i + size, rows)) for i in range(0, rows, size)]
    out: np.ndarray | None = None  # with one call, that call's array is the result
    if len(spans) > 1:
        try:
            out = np.empty((rows, nt, m))
        except MemoryError:
            raise ValueError(
                f"invalid output size: cannot allocate {rows} x {nt} samples of {m} doubles"
            ) from None
    done = np.zeros(rows, dtype=bool)
    steps = 0
    total = max(rows * nt, 1)

    def trajectory(ls: np.ndarray) -> Trajectory:
        ok = done.reshape(lead)
        if done.all():
            integrals = {k: np.asarray(v) for k, v in top.integrals(ls).items()}
        else:
            # Integrals of the finished trajectories; NaN for the others.
            ls[~done] = np.nan
            part = top.integrals(ls[done])
            integrals = {}
            for k, v in part.items():
                full = np.full((rows, nt), np.nan)
                full[done] = v
                integrals[k] = full
        return Trajectory(
            t=times,
            l=ls.reshape(lead + (nt, m)),
            integrals={k: v.reshape(lead + (nt,)) for k, v in integrals.items()},
            method=method,
            dt=dt,
            steps=int(steps),
            evals=None,
            ok=ok,
        )

    for i, j in spans:
        base = i * nt
        tick = (lambda k, base=base: report((base + k) / total)) if report.active else None
        try:
            ys, s = _core.integrate_many(
                top.c, flat[i:j], 0.0, times, method, dt, rtol, atol, budget, parallel, tick
            )
        except BaseException as err:
            # Ctrl-C, an explicit method out of max_steps, a failed step or the
            # progress callable's exception: the trajectories of the calls before
            # this one ride on it (``err.partial``; possibly none).
            try:
                kept = out if out is not None else np.full((rows, nt, m), np.nan)
            except MemoryError:
                raise err from None
            err.partial = trajectory(kept)  # type: ignore[attr-defined]
            raise
        if out is None:
            out = ys
        else:
            out[i:j] = ys
        done[i:j] = True
        steps += s
        report(j * nt / total)
    report(1.0)
    if out is None:  # no states
        out = np.empty((0, nt, m))
    return trajectory(out)
