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
from ._progress import ProgressBar
from ._torus import Torus, real_torus, second_flow_b, torus_of_state
from .problems import problem
from .top import ManakovTop

__all__ = [
    "STATUS_NAMES",
    "OK",
    "FrequencyMap",
    "Torus",
    "real_torus",
    "second_flow_b",
    "torus_of_state",
    "frequency_map",
    "casimir_slice",
    "plot_frequency_map",
]

#: Names of the status codes of :func:`frequency_map`, indexed by code.
STATUS_NAMES: tuple[str, ...] = tuple(_core.tori_status_names())

#: The status code of a state whose frequencies were computed.
OK = 0
#: ``h1² = 4 h0²``: ``F(s)`` of (19) is undefined; the level set is singular.
SINGULAR_CASIMIRS = 1
#: Two branch points of (8) coincide (``h0 = 0`` and a repeated root of ``F``
#: (19) included): genus drops; a separatrix or a degenerate torus.
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

    Attributes
    ----------
    nu : ndarray, shape (..., 2)
        ``(ν1, ν2)`` per state (cycles per unit time); NaN exactly where
        ``status != OK``.
    status : ndarray, uint8, shape (...)
        A code of :data:`STATUS_NAMES` per state.
    """

    nu: np.ndarray
    status: np.ndarray

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


def _run_chunks(
    fn: Callable[..., Any],
    args: Sequence[Any],
    states: np.ndarray,
    *,
    client: Any,
    chunk_size: int,
    progress: bool | None,
    label: str,
) -> list[Any]:
    """``[fn(*args, states[i:j]) for each chunk]`` in order, locally or on ``client``.

    Without a client the chunks run one after another in this process (the
    function parallelises within a chunk); dask is not imported. With a
    ``dask.distributed`` client every chunk is a task; a task lost with its
    worker is rerun by the scheduler, so the list is complete and in order.
    """
    n = states.shape[0]
    spans = _split(n, chunk_size)
    show = n >= PROGRESS_MIN_STATES if progress is None else bool(progress)
    bar = ProgressBar(label, force=bool(progress)) if show else None
    out: list[Any] = [None] * len(spans)
    try:
        if client is None:
            done = 0
            for k, (i, j) in enumerate(spans):
                out[k] = fn(*args, states[i:j])
                done += j - i
                if bar is not None:
                    bar.update(done / n)
        else:
            from distributed import as_completed  # only with a client

            futures = [
                client.submit(
                    fn, *args, states[i:j], pure=False, key=f"{label}-{k}-{os.urandom(6).hex()}"
                )
                for k, (i, j) in enumerate(spans)
            ]
            index = {f.key: k for k, f in enumerate(futures)}
            done = 0
            for fut in as_completed(futures):
                k = index[fut.key]
                out[k] = fut.result()
                done += spans[k][1] - spans[k][0]
                if bar is not None:
                    bar.update(done / n)
    finally:
        if bar is not None:
            bar.close()
    return out


def frequency_map(
    top: Any,
    states: Any,
    *,
    client: Any = None,
    chunk_size: int | None = None,
    progress: bool | None = None,
) -> FrequencyMap:
    """Frequencies ``(ν1, ν2)`` of the real tori through many initial states.

    For each state ``l0`` the frequencies come from its level set alone: the
    reduction's constants (19)–(26), (40)–(41), the curve (8) and its period
    matrix ``τ``, the characteristics of ``l``, and the velocities ``U`` of
    the top and ``U'`` of a second commuting flow (the Manakov top with
    ``b'`` of :func:`second_flow_b`), both by the chain rule of (1) through
    ``l`` as a function of a divisor (27)–(28), (37), (42), (23), taken at
    auxiliary divisors (docs/theorem.md, docs/tori.md §2). No theta function
    and no Abel map of ``l0`` enter. Then ``U = ν1 λ1 + ν2 λ2`` on the
    reduced basis of :func:`real_torus` (:func:`torus_of_state` and
    ``sol.torus`` give the same torus through the Theorem's solution; the
    frequencies agree to 2.4e-15 (median) and 4e-12 (max) relative on the
    100 random states of ``tests/data/tori_naff_random100.py``).

    Parameters
    ----------
    top : ManakovTop
        The top (its ``a`` and ``b``).
    states : array_like, real, shape (..., 6)
        Initial states ``(l12, l13, l14, l23, l24, l34)``. Not modified.
    client : distributed.Client, optional
        Run the chunks as tasks on this dask cluster. Results are identical
        to the local run, bit for bit, and in order. Without a client the
        work runs in this process across all cores, and dask is not imported.
    chunk_size : int, optional
        States per chunk (default :data:`LOCAL_CHUNK` locally,
        :data:`DASK_CHUNK` with a client).
    progress : bool, optional
        Show a progress bar on stderr; by default shown on a terminal for
        maps of at least :data:`PROGRESS_MIN_STATES` states.

    Returns
    -------
    FrequencyMap
        ``nu`` of shape (..., 2) and ``status`` of shape (...). A state on a
        singular level set (``h1² = 4h0²``, coinciding branch points, ...)
        gets its code of :data:`STATUS_NAMES` and NaN frequencies; no exception
        is raised for it. (Codes 3, 10 and 11 belong to the solution's route,
        ``sol.torus``; the map meets them only where it falls back on that
        route, when the auxiliary divisors do not agree; no such state is known.)

    Raises
    ------
    ValueError
        If ``states`` does not have shape (..., 6) or is not real, or
        ``chunk_size`` is not a positive integer.
    KeyboardInterrupt
        On Ctrl-C (locally).
    """
    a = np.ascontiguousarray(np.asarray(top.a, dtype=float))
    b = np.ascontiguousarray(np.asarray(top.b, dtype=float))
    arr = np.asarray(states)
    if np.iscomplexobj(arr) or arr.dtype == object or arr.ndim == 0 or arr.shape[-1] != 6:
        raise ValueError(f"states must be a real array of shape (..., 6), got {arr.shape}")
    lead = arr.shape[:-1]
    flat = np.ascontiguousarray(arr.reshape(-1, 6), dtype=float)
    default = LOCAL_CHUNK if client is None else DASK_CHUNK
    size = default if chunk_size is None else chunk_size
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
        raise ValueError(f"chunk_size must be a positive integer, got {chunk_size!r}")
    parts = _run_chunks(
        _frequency_chunk,
        (a, b),
        flat,
        client=client,
        chunk_size=int(size),
        progress=progress,
        label="frequency map",
    )
    if parts:
        nu = np.concatenate([p.nu for p in parts])
        status = np.concatenate([p.status for p in parts])
    else:
        nu, status = np.empty((0, 2)), np.empty(0, dtype=np.uint8)
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
    """
    x = np.asarray(l0, dtype=float)
    if x.shape != (6,) or not np.all(np.isfinite(x)):
        raise ValueError(f"l0 must be a finite array of shape (6,), got {x!r}")
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


def plot_frequency_map(
    problem_name: str,
    grid: int,
    path: str | os.PathLike[str],
    *,
    client: Any = None,
    max_order: int = 5,
    progress: bool | None = None,
    dpi: int = 120,
) -> FrequencyMap:
    """Plot the rotation number ``ν1/ν2`` over a Casimir slice of a shared problem.

    The slice is :func:`casimir_slice` of the problem's ``l0`` (so every
    state has the problem's ``h0``, ``h1``); the colour is ``ν1/ν2``, singular
    states are grey, and the resonances ``k1 ν1 + k2 ν2 = 0`` with
    ``|k1| + |k2| ≤ max_order`` are drawn as contour lines ``ν1/ν2 = −k2/k1``.

    Parameters
    ----------
    problem_name : str
        A name of :func:`manakov.problem_names`.
    grid : int
        Points per axis; the map has ``grid²`` states.
    path : str or PathLike
        Where to write the PNG.
    client : distributed.Client, optional
        Passed to :func:`frequency_map`.
    max_order : int
        Largest ``|k1| + |k2|`` of the resonance lines drawn.
    progress : bool, optional
        Passed to :func:`frequency_map`.
    dpi : int
        Resolution of the PNG.

    Returns
    -------
    FrequencyMap
        The map, of shape (grid, grid).
    """
    from fractions import Fraction

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    pr = problem(problem_name)
    top = ManakovTop(pr.a, pr.b)
    phi, ct, states = casimir_slice(pr.l0, grid)
    fm = frequency_map(top, states, client=client, progress=progress)
    ok = fm.status == OK
    ratio = np.full(ok.shape, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio[ok] = fm.nu[..., 0][ok] / fm.nu[..., 1][ok]
    fig, ax = plt.subplots(figsize=(7, 5.5))
    ax.set_facecolor("0.6")
    masked = np.ma.masked_invalid(ratio)
    norm = None
    good = ratio[np.isfinite(ratio) & (ratio > 0)]
    if good.size:
        # Log scale between the 1st and 99th percentiles: the rotation number
        # spans decades near separatrices (one frequency goes to zero).
        lo, hi = np.percentile(good, [1, 99])
        if hi > lo:
            norm = LogNorm(vmin=lo, vmax=hi)
    mesh = ax.pcolormesh(phi, ct, masked, shading="nearest", cmap="viridis", norm=norm)
    fig.colorbar(mesh, ax=ax, label="rotation number ν1/ν2")
    if good.size:
        lo, hi = float(good.min()), float(good.max())
        levels = sorted(
            {
                float(Fraction(k2, k1))
                for k1 in range(1, max_order + 1)
                for k2 in range(1, max_order + 1 - k1)
                if lo < k2 / k1 < hi
            }
        )
        if levels:
            ax.contour(phi, ct, masked, levels=levels, colors="w", linewidths=0.6)
    ax.set_xlabel("φ (direction of p = m + n)")
    ax.set_ylabel("cos ϑ")
    counts = fm.counts()
    ax.set_title(
        f"{problem_name}: ν1/ν2 at fixed h0, h1, {grid}×{grid}; resonances |k| ≤ {max_order}"
        + (
            "" if counts.get("ok", 0) == ok.size else f" (grey: {ok.size - int(ok.sum())} singular)"
        ),
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(os.fspath(path), dpi=dpi)
    plt.close(fig)
    return fm
