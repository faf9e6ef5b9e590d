"""Real Liouville tori: the lattice of periods of l, frequencies, frequency maps.

By the Theorem (9)–(10) ``l`` is a rational function of the quotients
``P_L = C_L θ[χ_L](v)/θ(v)``, ``v = u + K``, and ``u = u0 + U t``. A lattice
vector ``λ = m + τ n`` changes ``θ[a;b]/θ`` by the sign ``(−1)^{a·m + b·n}``,
so the periods of ``l`` form the lattice

    Λ' = {m + τ n : a_L·m + b_L·n ≡ 0 (mod 2) for every χ_L = [a_L; b_L] in l},

``2Λ ⊂ Λ' ⊂ Λ = Z² + τ Z²``. The real torus of a motion is the closure of
``u0 + U t`` modulo ``Λ'``; its tangent plane is spanned over R by ``U`` and the
velocity ``U'`` of a second commuting flow of the Manakov family, and
``Λ' ∩ span_R(U, U')`` has a basis ``λ1, λ2``. The frequencies are
``U = ν1 λ1 + ν2 λ2`` (cycles per unit time). The basis is Lagrange–Gauss
reduced in the polarisation metric ``‖z‖² = z^H (Im τ)^{-1} z`` (invariant under
changes of the homology basis), ``‖λ1‖ ≤ ‖λ2‖``, with signs making
``ν1, ν2 ≥ 0``. Derivations and choices: ``docs/tori.md``.

Frequency maps run the whole chain per state in Rust, in parallel, with the
GIL released; with a ``dask.distributed`` client the states are split in
chunks and computed on its workers, bit for bit as locally.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, Callable, NamedTuple

import numpy as np

from . import _core
from ._checks import _last_axis, _one_state
from ._progress import Progress
from ._torus import Torus, real_torus, second_flow_b, torus_of_state

__all__ = [
    "STATUS_NAMES",
    "OK",
    "NOT_COMPUTED",
    "EQUILIBRIUM",
    "SEPARATRIX",
    "LOCAL_CHUNK",
    "DASK_CHUNK",
    "PROGRESS_MIN_STATES",
    "FrequencyMap",
    "Torus",
    "real_torus",
    "second_flow_b",
    "torus_of_state",
    "frequency_map",
    "casimir_slice",
]

#: The status codes of the core's frequency map, indexed by code.
_CORE_STATUS_NAMES: tuple[str, ...] = tuple(_core.tori_status_names())
#: A state an interrupted map did not reach (only in ``err.partial``): one past
#: the core's codes, so it can never be one of them.
NOT_COMPUTED = len(_CORE_STATUS_NAMES)
#: Names of the status codes of :func:`frequency_map`, indexed by code.
STATUS_NAMES: tuple[str, ...] = (*_CORE_STATUS_NAMES, "not computed")

#: The status code of a state whose frequencies were computed.
OK = 0
#: ``h1² = 4 h0²``: ``F(s)`` of (19) is undefined; the level set is singular.
SINGULAR_CASIMIRS = 1
#: Two branch points of (8) coincide (a repeated root of ``F`` (19) and a root
#: of ``F`` at an ``a_j`` included): genus drops; a separatrix or a degenerate
#: torus. (``h0 = 0`` alone is a regular level set: docs/degenerate.md §8.)
COINCIDING_BRANCH_POINTS = 2
#: The divisor of the initial state has a point at infinity (the solution's
#: route, ``sol.torus``; the map works on the level set and needs no divisor).
DIVISOR_AT_INFINITY = 3
#: An iteration of the solution did not reach its tolerance.
NO_CONVERGENCE = 4
#: ``l0 = 0``.
ZERO_STATE = 5
#: The state has a NaN or infinite entry.
NON_FINITE = 6
#: The top's flow and the second flow do not span a real plane.
DEGENERATE_PLANE = 7
#: The lattice of periods meets the plane in no rank-2 lattice.
NO_REAL_LATTICE = 8
#: Any other refusal.
SINGULAR = 9
#: The theta-quotient gradients at the initial divisor do not determine the
#: velocity ``U`` (the solution's route).
DEGENERATE_GRADIENTS = 10
#: The solution's theta quotients reproduce the state but solve (1) for no
#: velocity: its set-up is wrong there (one of the Theorem's outliers), so
#: would its frequencies be (the solution's route).
INCONSISTENT_QUOTIENTS = 11
#: The state is at rest: an equilibrium of (1) (a stationary rotation), or any
#: state of a spherical top (all ``c_ij`` equal). NaN frequencies: the
#: neighbouring tori tend to the linearized motion's frequencies instead.
EQUILIBRIUM = 12
#: The state lies on the separatrix of an Euler top (an so(3) block or a
#: self-dual state): its motion is asymptotic, with no period.
SEPARATRIX = 13

#: States per chunk without a client: the unit between progress updates and
#: Ctrl-C checks of the Python loop (the Rust core also polls within a chunk).
#: See docs/tori.md for the measurement behind both defaults.
LOCAL_CHUNK = 4096
#: States per dask task: the measured per-task overhead (scheduling, shipping
#: the chunk and the result: 9-15 ms on a LocalCluster) stays about 1 % of the
#: ~1.3 s a chunk takes on one core at ~40 us per state (docs/tori.md).
DASK_CHUNK = 32768
#: Above this many states the progress bar is shown by default (on a terminal).
PROGRESS_MIN_STATES = 20000


class FrequencyMap(NamedTuple):
    """Result of :func:`frequency_map` (unpacks as ``nu, status``).

    Every array has the leading shape of the states it was computed from
    (``docs/conventions.md``).

    Attributes
    ----------
    nu : ndarray, shape (..., 2)
        ``(ν1, ν2)`` per state (cycles per unit time); NaN exactly where
        ``status != OK``. Also :attr:`frequencies`, the name of
        :attr:`Torus.frequencies` and ``Solution.frequencies``.
    status : ndarray, uint8, shape (...)
        A code of :data:`STATUS_NAMES` per state (:data:`NOT_COMPUTED` only in
        the ``err.partial`` of an interrupted map).

    Examples
    --------
    >>> import manakov
    >>> from manakov.tori import casimir_slice
    >>> p = manakov.problem("generic")
    >>> fm = manakov.frequency_map(manakov.ManakovTop(p.a, p.b), casimir_slice(p.l0, 4)[2])
    >>> fm.nu.shape, fm.status.shape, fm.counts()
    ((4, 4, 2), (4, 4), {'ok': 16})
    """

    nu: np.ndarray
    status: np.ndarray

    @property
    def frequencies(self) -> np.ndarray:
        """``(ν1, ν2)`` per state: :attr:`nu`, by the name :class:`Torus` uses."""
        return self.nu

    @property
    def ok(self) -> Any:
        """Which states have frequencies (``status == OK``), as ``Kotter.ok``."""
        ok = np.asarray(self.status) == OK
        return bool(ok) if ok.ndim == 0 else ok

    @property
    def rotation_number(self) -> Any:
        """``ν1/ν2`` per state (``inf`` where ``ν2 = 0``, NaN where not :attr:`ok`),
        as :attr:`Torus.rotation_number`."""
        nu = np.asarray(self.nu)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(nu[..., 1] != 0, nu[..., 0] / nu[..., 1], np.inf)
        r = np.where(np.asarray(self.status) == OK, r, np.nan)
        return float(r) if r.ndim == 0 else r

    def counts(self) -> dict[str, int]:
        """How many states have each status (names of :data:`STATUS_NAMES`)."""
        vals, cnt = np.unique(self.status, return_counts=True)
        return {STATUS_NAMES[int(v)]: int(c) for v, c in zip(vals, cnt)}


def _frequency_chunk(a: np.ndarray, b: np.ndarray, states: np.ndarray) -> FrequencyMap:
    """One chunk of a frequency map (module level, so dask can ship it)."""
    nu, status = _core.frequency_map(a, b, np.ascontiguousarray(states, dtype=float))
    return FrequencyMap(nu, status)


def _split(n: int, chunk: int) -> list[tuple[int, int]]:
    return [(i, min(i + chunk, n)) for i in range(0, n, chunk)]


def _check_client(client: Any) -> None:
    """``client`` is None or a ``dask.distributed.Client`` (else ValueError naming it)."""
    if client is None:
        return
    try:
        from distributed import Client
    except ImportError:
        raise ValueError(
            f"client must be a dask.distributed.Client, got {client!r} "
            f"({type(client).__name__}); dask.distributed is not installed "
            "(pip install 'manakov[dask]')"
        ) from None
    if not isinstance(client, Client):
        raise ValueError(
            f"client must be a dask.distributed.Client or None, got {client!r} "
            f"({type(client).__name__})"
        )


def _run_chunks(
    fn: Callable[..., Any],
    args: Sequence[Any],
    states: np.ndarray,
    *,
    client: Any,
    chunk_size: int,
    progress: Any,
    label: str,
) -> list[Any]:
    """``[fn(*args, states[i:j]) for each chunk]`` in order, locally or on ``client``.

    Without a client the chunks run one after another in this process (the
    function parallelises within a chunk); dask is not imported. With a
    ``dask.distributed`` client every chunk is a task; a task lost with its
    worker is rerun by the scheduler, so the list is complete and in order.
    ``progress`` as in :func:`frequency_map`.

    An exception (Ctrl-C included) carries the chunks finished before it as
    ``err.chunks_done`` (the list, ``None`` for a chunk not finished); the tasks
    still queued on ``client`` are cancelled.
    """
    n = states.shape[0]
    spans = _split(n, chunk_size)
    out: list[Any] = [None] * len(spans)
    futures: list[Any] = []
    with Progress(progress, label, long=n >= PROGRESS_MIN_STATES) as report:
        try:
            if client is None:
                done = 0
                for k, (i, j) in enumerate(spans):
                    out[k] = fn(*args, states[i:j])
                    done += j - i
                    report(done / n)
            else:
                from distributed import as_completed  # only with a client

                futures = [
                    client.submit(
                        fn,
                        *args,
                        states[i:j],
                        pure=False,
                        key=f"{label}-{k}-{os.urandom(6).hex()}",
                    )
                    for k, (i, j) in enumerate(spans)
                ]
                index = {f.key: k for k, f in enumerate(futures)}
                done = 0
                for fut in as_completed(futures):
                    k = index[fut.key]
                    out[k] = fut.result()
                    done += spans[k][1] - spans[k][0]
                    report(done / n)
        except BaseException as err:
            if futures:
                client.cancel([f for k, f in enumerate(futures) if out[k] is None])
            err.chunks_done = out  # type: ignore[attr-defined]
            raise
        report(1.0)
    return out


def frequency_map(
    top: Any,
    states: Any,
    *,
    client: Any = None,
    chunk_size: int | None = None,
    progress: bool | Callable[[float], object] | None = None,
) -> FrequencyMap:
    """Frequencies ``(ν1, ν2)`` of the real tori through many initial states.

    For each state ``l0`` the frequencies come from its level set alone: the
    reduction's constants (19)–(26), (40)–(41), the curve (8) and its period
    matrix ``τ``, the characteristics of ``l``, and the velocities ``U`` of
    the top and ``U'`` of a second commuting flow (the Manakov top with
    ``b'`` of :func:`second_flow_b`), both in closed form from Dubrovin's
    equations at the half periods ``d_0 + d_p`` of the curve, where ``l`` as a
    function of a divisor (27)–(28), (37), (42), (23) and its rate under (1) are
    explicit (docs/theorem.md, docs/tori.md §2). No theta function and no Abel
    map of ``l0`` enter. Then ``U = ν1 λ1 + ν2 λ2`` on the reduced basis of
    :func:`real_torus` (:func:`torus_of_state` and ``sol.torus`` give the same
    torus through the Theorem's solution, from the same closed form: the
    frequencies are equal to the last bit on the 10^4 states of
    ``tests/data/closed_u_frequencies.py``).

    Each state is first normalized and classified, as :meth:`ManakovTop.solve`
    does (docs/degenerate.md): an exactly self-dual or so(3)-block state (an
    Euler top, a closed orbit) gets status ``ok`` with ``(ν1, ν2) = (ν_⊥, ν_E)``,
    the transverse rotation number and the Euler frequency (the limit of the
    neighbouring tori's frequencies up to ``ν1 → |ν_⊥ + k ν_E|``); an equilibrium
    of (1) or any state of a spherical top gets :data:`EQUILIBRIUM`, an Euler
    top's separatrix :data:`SEPARATRIX`; genus-2 states are computed on the
    normalized data, their frequencies in the user's time. Where the genus-2
    route refuses a state within 1e-2 (relative) of an so(3) block whose Euler
    orbit is transversally elliptic (a pinched curve), or within 1e-3 of a
    self-dual state (``h1² = 4 h0²`` to rounding), the frequencies are
    interpolated between that orbit's ``(ν_⊥, ν_E)`` and the tori of four states
    farther out (in the squared distance next to a block, in the distance next
    to the self-dual states), and given (``ok``) only where the interpolation's
    bound is at most 5e-11 (docs/degenerate.md §11). Next to a block whose orbit
    is transversally hyperbolic (growth ``e^{λ t}`` off it), ``1/ν2`` and
    ``(ν1 ∓ ν_E)/ν2`` are linear in ``ln(1/σ)`` (``σ`` the distance), with the
    slope ``2/λ`` for ``1/ν2``; they are fitted to the tori of seven states
    farther out and given under the same bound. Next to a coordinate plane of
    equilibria (``(l12, l34)``, ``(l13, l24)``, ``(l14, l23)``) they come from the
    equilibrium's normal modes or saddle rates alike. Where all of these refuse,
    ``ν = Λ⁻¹ e1`` for the lattice ``Λ`` of times ``(t1, t2)`` after which the
    flows of ``H`` and of a second Hamiltonian of Manakov's family bring the state
    back to itself, from closed orbits integrated in double-double (up to 6·10⁴
    steps, about 6 s, then again at half steps) and checked against the half
    steps to 1e-12.

    Parameters
    ----------
    top : ManakovTop
        The top (its ``a`` and ``b``).
    states : array_like, real, shape (..., 6)
        Initial states ``(l12, l13, l14, l23, l24, l34)``, any leading shape.
        Not modified. A NaN or infinite state gets its status code, not an
        exception.
    client : distributed.Client, optional
        Run the chunks as tasks on this dask cluster. Results are identical
        to the local run, bit for bit, and in order. Without a client the
        work runs in this process across all cores, and dask is not imported.
    chunk_size : int, optional
        States per chunk (default :data:`LOCAL_CHUNK` locally,
        :data:`DASK_CHUNK` with a client): the unit of progress and of what an
        interruption keeps.
    progress : bool or callable, optional
        ``True``: a progress bar on stderr; ``False``: none; a callable: called
        with the fraction of states done after each chunk. Default: a bar on a
        terminal for maps of at least :data:`PROGRESS_MIN_STATES` states.

    Returns
    -------
    FrequencyMap
        ``nu`` of shape (..., 2) and ``status`` of shape (...) (also ``ok``,
        ``frequencies``, ``rotation_number``). A state on a singular level set
        (``h1² = 4h0²``, coinciding branch points, ...) gets its code of
        :data:`STATUS_NAMES` and NaN frequencies; no exception is raised for it.
        (Codes 3, 10 and 11 belong to the solution's route, ``sol.torus``; the
        map meets them only where it falls back on that route, when neither
        the closed form nor the chain rule at auxiliary divisors gives the
        velocities; no such state is known.)

    Raises
    ------
    ValueError
        ``states`` not of shape (..., 6) or not real, ``chunk_size`` not a
        positive integer, ``client`` not a ``dask.distributed.Client``, or
        ``progress`` not a bool or callable.
    TypeError
        ``top`` is not a Manakov top.
    KeyboardInterrupt
        On Ctrl-C, within a fraction of a second (locally). It carries the map
        of the chunks finished before it as ``err.partial``, a
        :class:`FrequencyMap` of the full shape whose other states have status
        :data:`NOT_COMPUTED` and NaN frequencies; so does any other exception
        raised during the map (the ``progress`` callable's, a lost cluster).

    Examples
    --------
    >>> import manakov
    >>> from manakov.tori import casimir_slice
    >>> p = manakov.problem("generic")
    >>> top = manakov.ManakovTop(p.a, p.b)
    >>> fm = manakov.frequency_map(top, casimir_slice(p.l0, 8)[2])
    >>> fm.nu.shape, fm.counts()
    ((8, 8, 2), {'ok': 64})
    """
    if not (hasattr(top, "a") and hasattr(top, "b")):
        raise TypeError(f"top must be a ManakovTop (with its a and b), got {type(top).__name__}")
    a = np.ascontiguousarray(np.asarray(top.a, dtype=float))
    b = np.ascontiguousarray(np.asarray(top.b, dtype=float))
    if a.shape != (4,) or b.shape != (4,):
        raise ValueError(
            f"top must be a Manakov top on so(4): a and b of shape (4,), got {a.shape}, {b.shape}"
        )
    arr = np.asarray(states)
    # NaN and infinity are allowed (they get a status): only the type and the
    # shape are checked.
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"states must be a real numeric array, got dtype {arr.dtype}")
    _last_axis(arr, 6, "states")
    lead = arr.shape[:-1]
    flat = np.ascontiguousarray(arr.reshape(-1, 6), dtype=float)
    _check_client(client)
    default = LOCAL_CHUNK if client is None else DASK_CHUNK
    size = default if chunk_size is None else chunk_size
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
        raise ValueError(f"chunk_size must be a positive integer, got {chunk_size!r}")
    try:
        parts = _run_chunks(
            _frequency_chunk,
            (a, b),
            flat,
            client=client,
            chunk_size=int(size),
            progress=progress,
            label="frequency map",
        )
    except BaseException as err:
        done = getattr(err, "chunks_done", None)
        if done is not None:
            err.partial = _assemble(done, flat.shape[0], int(size), lead)  # type: ignore[attr-defined]
        raise
    return _assemble(parts, flat.shape[0], int(size), lead)


def _assemble(
    parts: Sequence[FrequencyMap | None], n: int, size: int, lead: tuple[int, ...]
) -> FrequencyMap:
    """The map of shape ``lead`` from its chunks (:data:`NOT_COMPUTED` for ``None``)."""
    nu = np.full((n, 2), np.nan)
    status = np.full(n, NOT_COMPUTED, dtype=np.uint8)
    for (i, j), part in zip(_split(n, size), parts):
        if part is not None:
            nu[i:j], status[i:j] = part.nu, part.status
    return FrequencyMap(nu.reshape(*lead, 2), status.reshape(lead))


def casimir_slice(l0: Any, grid: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 2-D grid of states with the Casimirs ``h0``, ``h1`` of ``l0``.

    With ``m_j = l_kl``, ``n_j = l_j4`` (11)–(12), ``h1 = |m|² + |n|²`` and
    ``h0 = m·n`` (6), so ``p = m + n`` and ``q = m − n`` lie on spheres of
    radii ``√(h1 ± 2h0)``. The slice keeps ``q`` of ``l0`` and moves the
    direction of ``p`` over the sphere on an equal-area grid
    ``(φ, cos ϑ) ∈ [−π, π) × (−1, 1)``.

    Parameters
    ----------
    l0 : array_like, shape (6,)
    grid : int
        Points per axis (≥ 2).

    Returns
    -------
    phi : ndarray, shape (grid,)
    cos_theta : ndarray, shape (grid,)
    states : ndarray, shape (grid, grid, 6)
        ``states[i, j]`` at ``cos ϑ = cos_theta[i]``, ``φ = phi[j]``.

    Examples
    --------
    >>> import manakov
    >>> from manakov.tori import casimir_slice
    >>> phi, cos_theta, states = casimir_slice(manakov.problem("generic").l0, 8)
    >>> states.shape
    (8, 8, 6)
    """
    x = _one_state(l0, 6, "l0", "casimir_slice")
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 2:
        raise ValueError(f"grid must be an integer >= 2, got {grid!r}")
    l12, l13, l14, l23, l24, l34 = x
    m = np.array([l23, -l13, l12])  # m_j = l_kl, (j,k,l) cyclic: l31 = -l13
    n = np.array([l14, l24, l34])
    p, q = m + n, m - n
    rp = float(np.linalg.norm(p))
    phi = -np.pi + 2 * np.pi * (np.arange(grid) + 0.5) / grid
    ct = -1 + 2 * (np.arange(grid) + 0.5) / grid
    st = np.sqrt(1 - ct**2)
    P = rp * np.stack(
        [
            st[:, None] * np.cos(phi)[None, :],
            st[:, None] * np.sin(phi)[None, :],
            np.broadcast_to(ct[:, None], (grid, grid)),
        ],
        axis=-1,
    )
    M = (P + q) / 2
    N = (P - q) / 2
    states = np.stack([M[..., 2], -M[..., 1], N[..., 0], M[..., 0], N[..., 1], N[..., 2]], axis=-1)
    return phi, ct, states
