# The state is called l, as in the paper: E741 does not apply.
# ruff: noqa: E741
"""Figures: a trajectory, a reduction, the Theorem against integration, a frequency map.

No layer of the core of its own: the figures draw on the whole chain (the top,
its integration, the reduction, the solution and the tori), so this module sits
at the top of the import graph. matplotlib is needed (``pip install
'manakov[plot]'``) and imported only when a figure is drawn.

Choices every figure follows: axes span the data's real extent (a part of a
complex number below ``10^-10`` of its size is rounding noise and is not
plotted, so no axis is ever scaled to it); curves are sampled densely (the
Theorem's ``l(t)``, or a rerun of the integration sampled finely) rather than
joined by straight lines between sparse samples; titles are wrapped to fit.

The two long figures (:func:`plot_theorem`, :func:`plot_frequency_map`) keep
their work on an interruption: the figure of what was computed is written to
``partial_path`` (default ``<stem>.partial<suffix>``), and the exception carries
``err.partial`` (the partial result) and ``err.partial_path``.
"""

from __future__ import annotations

import math
import os
import textwrap
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ._checks import _show
from .integrate import DEFAULT_MAX_STEPS, Trajectory, gauss_steps
from .problems import Problem, as_problem
from .reduction import Kotter
from .top import ManakovTop
from .tori import NOT_COMPUTED, OK, FrequencyMap, casimir_slice, frequency_map

__all__ = [
    "PLOT_WINDOW",
    "THEOREM_WINDOW",
    "plot_frequency_map",
    "plot_kotter",
    "plot_theorem",
    "plot_trajectory",
]

#: The l(t) panel of a trajectory shows at most this initial stretch (its
#: oscillations have periods of a few time units; a longer window is a solid band).
PLOT_WINDOW = 40.0
#: The l(t) panel of the Theorem's figure shows at most this initial stretch.
THEOREM_WINDOW = 100.0
#: Points per time scale ``1/Ω`` (:meth:`FrahmTop.time_scale`) of a dense curve:
#: the fastest oscillation of (1) has a period of a few ``1/Ω``, so 12 points per
#: ``1/Ω`` draw it smooth at any figure width.
POINTS_PER_TIME_SCALE = 12
#: Bounds on the points of a dense curve.
DENSE_POINTS = (2001, 200_001)
#: A real or imaginary part below this fraction of ``|x|`` is rounding noise.
NOISE_RTOL = 1e-10
#: The core's cap on ``max_steps``.
_MAX_STEPS_CAP = 10**11


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _partial_path(path: str | os.PathLike[str], partial_path: Any) -> Path:
    if partial_path is not None:
        return Path(partial_path)
    p = Path(path)
    return p.with_name(p.stem + ".partial" + p.suffix)


def _dense_times(top: ManakovTop, l0: np.ndarray, t_end: float) -> np.ndarray:
    scale = top.time_scale(l0)
    lo, hi = DENSE_POINTS
    want = POINTS_PER_TIME_SCALE * t_end / scale if math.isfinite(scale) else lo
    return np.linspace(0.0, t_end, int(min(max(want, lo), hi)))


def _wrap(text: str, width: int) -> str:
    return "\n".join(textwrap.wrap(text, width))


# --------------------------------------------------------------------- trajectory


def plot_trajectory(
    path: str | os.PathLike[str],
    top: ManakovTop,
    tr: Trajectory,
    *,
    title: str,
    window: float = PLOT_WINDOW,
    dpi: int = 110,
) -> None:
    """l(t) over the first ``window`` time units and the drift of every integral.

    The l(t) panel is a rerun of the same method from ``tr.l[0]`` over the window,
    sampled densely (the run's own samples can be one step apart, 0.3 time units
    for gauss16, which draws a polyline); the drift panel is the run's own samples,
    ``max over [0, t]`` of ``|I - I(0)| / |I(0)|`` on a log scale.

    Parameters
    ----------
    path : str or PathLike
        The PNG to write.
    top : ManakovTop
    tr : Trajectory
        One trajectory from ``top.integrate`` (at least two samples).
    title : str
    window : float
    dpi : int

    Examples
    --------
    >>> import os, tempfile, manakov
    >>> from manakov.plots import plot_trajectory
    >>> p = manakov.problem("generic")
    >>> top = manakov.ManakovTop(p.a, p.b)
    >>> tr = top.integrate(p.l0, 20.0, sample_every=1.0)
    >>> path = os.path.join(tempfile.mkdtemp(), "generic.png")
    >>> plot_trajectory(path, top, tr, title="generic", window=10.0)
    >>> os.path.exists(path)
    True
    """
    plt = _pyplot()
    t, l = tr.t, tr.l
    n = int(round((1 + math.sqrt(1 + 8 * l.shape[-1])) / 2))
    names = [f"$l_{{{i + 1}{j + 1}}}$" for i in range(n) for j in range(i + 1, n)]
    w = min(float(t[-1]), window)
    dense = _dense_times(top, l[0], w)
    rerun = top.integrate(
        l[0],
        w,
        t_eval=dense,
        method=tr.method,
        dt=tr.dt if tr.dt > 0 else None,
        max_steps=_MAX_STEPS_CAP,
        progress=False,
    )
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 7), constrained_layout=True)
    for k in range(l.shape[-1]):
        ax1.plot(rerun.t, rerun.l[:, k], lw=1.0, label=names[k])
    ax1.set_xlim(0.0, w)
    ax1.set_ylabel("angular momentum $l(t)$")
    ax1.set_xlabel("t" + (f" (the first {w:g} time units)" if w < t[-1] else ""))
    ax1.legend(
        ncol=min(8, len(names)),
        fontsize=8,
        loc="lower center",
        bbox_to_anchor=(0.5, 1.0),
        frameon=False,
    )
    fig.suptitle(_wrap(title, 100), fontsize=11)
    eps = np.finfo(float).eps
    floor = eps / 4
    for name, d in tr.relative_drift().items():
        ax2.semilogy(t[1:], np.maximum(np.maximum.accumulate(d[1:]), floor), lw=1, label=name)
    ax2.axhline(eps, color="gray", ls=":", lw=0.8)
    ax2.text(t[-1], eps, " machine eps", va="bottom", ha="right", fontsize=8)
    ax2.set_xlim(0.0, float(t[-1]))
    ax2.set_ylabel("max over [0, t] of $|I - I(0)| / |I(0)|$")
    ax2.set_xlabel("t")
    ax2.legend(ncol=5, fontsize=8, loc="upper left")
    fig.savefig(os.fspath(path), dpi=dpi)
    plt.close(fig)


# ------------------------------------------------------------------------ kotter


def _clean(z: Any) -> complex:
    """``z`` without a real or imaginary part below ``NOISE_RTOL |z|``."""
    z = complex(z)
    cut = abs(z) * NOISE_RTOL
    return complex(z.real if abs(z.real) > cut else 0.0, z.imag if abs(z.imag) > cut else 0.0)


def _stagger(xs: np.ndarray, span: float) -> list[int]:
    """Label rows (0, 1, 2, ...) so that labels of points closer than 6 % of the
    plotted span sit at different heights."""
    order = np.argsort(xs)
    rows = [0] * len(xs)
    last: dict[int, float] = {}
    for i in order:
        row = 0
        while row in last and xs[i] - last[row] < 0.06 * span:
            row += 1
        rows[i] = row
        last[row] = xs[i]
    return rows


def plot_kotter(path: str | os.PathLike[str], k: Kotter, name: str, *, dpi: int = 110) -> None:
    """The branch points ``d_0``–``d_4`` of the curve (8) and the divisor ``z1, z2``.

    When every point lies on the real (or the imaginary) axis, as for states of
    the shared problems, the figure is that axis on a symmetric-log scale (the
    points span decades, from a ``z`` near 0 to ``d_4 = d1 d2 d3``), with the
    intervals where ``R(x) = x Π (x - d_j) > 0`` drawn thick (there ``y`` is
    real: the real ovals of the curve); otherwise it is the complex plane with
    axes from the points' extent. The values, to 6 digits, are printed above.

    Parameters
    ----------
    path : str or PathLike
    k : Kotter
        The reduction of one state (:func:`manakov.kotter`).
    name : str
        Shown in the title.
    dpi : int

    Examples
    --------
    >>> import os, tempfile, manakov
    >>> from manakov.plots import plot_kotter
    >>> p = manakov.problem("generic")
    >>> path = os.path.join(tempfile.mkdtemp(), "kotter.png")
    >>> plot_kotter(path, manakov.kotter(p.a, p.b, p.l0), "generic")
    >>> os.path.exists(path)
    True
    """
    plt = _pyplot()
    d = [_clean(x) for x in np.concatenate([[0.0], np.asarray(k.d), [np.prod(k.d)]])]
    zs = [_clean(k.z1), _clean(k.z2)]
    pts = d + zs
    labels = [f"$d_{j}$" for j in range(5)] + ["$z_1$", "$z_2$"]
    on_real = all(p.imag == 0 for p in pts)
    on_imag = all(p.real == 0 for p in pts)
    values = (
        "   ".join(f"d{j} = {_show(x, 6)}" for j, x in enumerate(d))
        + "\n"
        + f"z1 = {_show(zs[0], 6)} (y1 = {_show(_clean(k.y1), 6)})   "
        + f"z2 = {_show(zs[1], 6)} (y2 = {_show(_clean(k.y2), 6)})"
    )
    title = f"{name}: branch points of the curve (8) and the divisor of l"
    if on_real or on_imag:
        fig, ax = plt.subplots(figsize=(10, 3.8), constrained_layout=True)
        xs = np.array([p.real if on_real else p.imag for p in pts])
        big = float(np.max(np.abs(xs)))
        # Linear within two decades below the largest point, logarithmic beyond.
        lin = 10.0 ** (math.floor(math.log10(big)) - 2) if big > 0 else 1.0
        ax.set_xscale("symlog", linthresh=lin, linscale=0.6)
        lo_x, hi_x = float(xs.min()), float(xs.max())
        # Pad by a third of a decade in the log part (a fraction of lin near 0).
        lo_lim = lo_x * 2.0 if lo_x < -lin else lo_x - lin
        hi_lim = hi_x * 2.0 if hi_x > lin else hi_x + lin
        ax.set_xlim(lo_lim, hi_lim)
        if on_real:
            # The real ovals: R(x) > 0 between consecutive real branch points.
            br = np.sort(xs[:5])
            edges = np.concatenate([[lo_lim], br, [hi_lim]])
            for lo, hi in zip(edges[:-1], edges[1:]):
                mid = 0.5 * (lo + hi)
                if np.prod(mid - br) > 0:
                    ax.plot([lo, hi], [0, 0], color="C0", lw=5, alpha=0.3, solid_capstyle="butt")
            ax.plot([], [], color="C0", lw=5, alpha=0.3, label="R(x) > 0 (y real)")
        ax.axhline(0.0, color="0.3", lw=0.8)
        ax.scatter(xs[:5], np.zeros(5), marker="x", s=70, color="C0", zorder=3, label="$d_j$")
        ax.scatter(xs[5:], np.zeros(2), marker="o", s=40, color="C1", zorder=3, label="$z_1, z_2$")
        # Label rows from the plotted position (the symlog transform).
        pos = np.sign(xs) * np.log10(1 + np.abs(xs) / lin)
        rows = _stagger(pos, float(np.ptp(pos)) or 1.0)
        for x, lab, row in zip(xs, labels, rows):
            ax.annotate(
                lab,
                (x, 0.0),
                textcoords="offset points",
                xytext=(0, 9 + 15 * row),
                ha="center",
                fontsize=10,
            )
        ax.set_ylim(-0.8, 2.4)
        ax.set_yticks([])
        ax.text(
            0.01, 0.97, values, transform=ax.transAxes, va="top", family="monospace", fontsize=8
        )
        axis = (
            "Re x (every point on the real axis)"
            if on_real
            else "Im x (every point on the imaginary axis)"
        )
        ax.set_xlabel(f"{axis}; symmetric log scale, linear for |x| < {lin:g}")
        ax.legend(loc="lower left", fontsize=8, ncol=3)
    else:
        fig, ax = plt.subplots(figsize=(8, 6.5), constrained_layout=True)
        re = np.array([p.real for p in pts])
        im = np.array([p.imag for p in pts])
        ax.scatter(re[:5], im[:5], marker="x", s=70, label="$d_0 .. d_4$")
        ax.scatter(re[5:], im[5:], marker="o", s=40, label="$z_1, z_2$")
        span = max(float(np.ptp(re)), float(np.ptp(im)), 1e-300)
        for axis_set, vals in ((ax.set_xlim, re), (ax.set_ylim, im)):
            mid = 0.5 * (float(vals.max()) + float(vals.min()))
            half = 0.5 * max(float(np.ptp(vals)), 0.2 * span) + 0.08 * span
            axis_set(mid - half, mid + half)
        for x, y, lab, row in zip(re, im, labels, _stagger(re, span)):
            ax.annotate(lab, (x, y), textcoords="offset points", xytext=(6, 6 + 12 * row))
        ax.set_xlabel("Re x")
        ax.set_ylabel("Im x")
        ax.legend(fontsize=8, loc="lower right")
        ax.text(
            0.01, 0.99, values, transform=ax.transAxes, va="top", family="monospace", fontsize=7
        )
    ax.set_title(_wrap(title, 90), fontsize=11)
    fig.savefig(os.fspath(path), dpi=dpi)
    plt.close(fig)


# ----------------------------------------------------------------------- theorem


def plot_theorem(
    problem: str | Problem,
    path: str | os.PathLike[str],
    *,
    t_end: float = 100.0,
    samples: int = 201,
    dt: float = 1e-3,
    progress: Any = None,
    partial_path: str | os.PathLike[str] | None = None,
    dpi: int = 110,
) -> float:
    """Plot ``l(t)`` from the theta quotients (9)–(10) against gauss16 integration,
    and their difference on a log scale, as a PNG.

    The top panel draws the Theorem's ``l(t)`` densely over the first
    :data:`THEOREM_WINDOW` time units with the integration's samples as dots;
    the bottom panel is ``max_q |l_theta,q - l_int,q| / |l0|`` at every sample
    time in ``[0, t_end]``.

    Parameters
    ----------
    problem : str or Problem
        A name of :func:`manakov.problem_names`, or any top and state
        (:class:`manakov.Problem`, e.g. from :func:`manakov.problems.read_problem`).
    path : str or PathLike
        The PNG file to write.
    t_end : float
        End time (> 0).
    samples : int
        Number of comparison times in ``[0, t_end]`` (>= 2).
    dt : float
        The gauss16 step.
    progress : bool or callable, optional
        Of the integration, as in :meth:`manakov.FrahmTop.integrate`.
    partial_path : str or PathLike, optional
        Where an interrupted run writes the figure of the samples reached
        (default ``<stem>.partial<suffix>`` of ``path``).
    dpi : int

    Returns
    -------
    float
        ``max_t |l_theta − l_int| / |l0|``.

    Raises
    ------
    ValueError
        Bad ``t_end``, ``samples`` or ``dt``, a run over 10^11 steps, or a state
        the Theorem does not cover (the message names why).
    KeyboardInterrupt
        Ctrl-C during the integration: the figure of the samples reached is
        written first; ``err.partial`` is the integration's partial
        :class:`~manakov.Trajectory`, ``err.partial_path`` the figure.

    Examples
    --------
    >>> import os, tempfile
    >>> from manakov.plots import plot_theorem
    >>> path = os.path.join(tempfile.mkdtemp(), "theorem.png")
    >>> err = plot_theorem("generic", path, t_end=10.0, samples=41)
    >>> bool(err < 1e-10), os.path.exists(path)
    (True, True)
    """
    pr = as_problem(problem)
    if not (t_end > 0 and np.isfinite(t_end)):
        raise ValueError(f"t_end must be finite and > 0, got {t_end}")
    if isinstance(samples, bool) or int(samples) != samples or samples < 2:
        raise ValueError(f"samples must be an integer >= 2, got {samples}")
    top = ManakovTop(pr.a, pr.b)
    sol = top.solve(pr.l0)
    _pyplot()  # before the run: no matplotlib fails now; an interrupted run draws at once
    t = np.linspace(0.0, float(t_end), int(samples))
    steps = gauss_steps(t, dt)
    budget = min(max(DEFAULT_MAX_STEPS, steps), _MAX_STEPS_CAP)
    try:
        tr = top.integrate(
            pr.l0, t_end, t_eval=t, dt=dt, method="gauss16", max_steps=budget, progress=progress
        )
    except BaseException as err:
        part = getattr(err, "partial", None)
        if isinstance(part, Trajectory) and part.t.size >= 2:
            where = _partial_path(path, partial_path)
            _theorem_figure(where, pr, top, sol, part, dt, float(t_end), dpi)
            err.partial_path = where  # type: ignore[attr-defined]
        raise
    return _theorem_figure(Path(path), pr, top, sol, tr, dt, float(t_end), dpi)


def _theorem_figure(
    path: Path,
    pr: Problem,
    top: ManakovTop,
    sol: Any,
    tr: Trajectory,
    dt: float,
    t_end: float,
    dpi: int,
) -> float:
    plt = _pyplot()
    t, l_int = tr.t, tr.l
    norm = float(np.linalg.norm(pr.l0))
    diff = np.max(np.abs(sol.l(t) - l_int), axis=1) / norm
    w = min(t_end, THEOREM_WINDOW)
    dense = _dense_times(top, pr.l0, w)
    l_th = sol.l(dense)
    names = [f"$l_{{{i}{j}}}$" for i, j in ((1, 2), (1, 3), (1, 4), (2, 3), (2, 4), (3, 4))]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 7.5), constrained_layout=True)
    for q in range(6):
        ax1.plot(dense, l_th[:, q], lw=1.0, color=f"C{q}", label=names[q])
        inside = t <= w
        ax1.plot(t[inside], l_int[inside, q], ".", ms=3.5, color="k")
    ax1.plot([], [], ".", ms=4, color="k", label="gauss16")
    ax1.set_xlim(0.0, w)
    ax1.set_ylabel("$l(t)$: theta quotients (lines), gauss16 (dots)")
    ax1.set_xlabel("t" + (f" (the first {w:g} time units)" if w < t_end else ""))
    ax1.legend(ncol=7, fontsize=8, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False)
    done = "" if tr.ok else f" (interrupted: samples up to t = {t[-1]:.6g} of {t_end:g})"
    d = ", ".join(_show(x, 5) for x in sol.curve.branch_points)
    u = ", ".join(_show(x, 5) for x in sol.U)
    fig.suptitle(
        _wrap(
            f"{pr.name}: l(t) from the theta functions (9)-(10) against gauss16, dt = {dt:g}"
            + done,
            100,
        )
        + "\n"
        + _wrap(f"curve (8): d = ({d});  U = ({u})", 120),
        fontsize=10,
    )
    floor = float(np.min(diff[diff > 0])) if np.any(diff > 0) else np.finfo(float).eps
    ax2.semilogy(t, np.maximum(diff, floor), lw=1)
    ax2.set_xlim(0.0, t_end)
    ax2.set_xlabel("t")
    ax2.set_ylabel("$\\max_q |l_{\\theta,q} - l_{\\mathrm{int},q}| / |l_0|$")
    fig.savefig(os.fspath(path), dpi=dpi)
    plt.close(fig)
    return float(diff.max())


# ----------------------------------------------------------------- frequency map


def plot_frequency_map(
    problem: str | Problem,
    grid: int,
    path: str | os.PathLike[str],
    *,
    client: Any = None,
    max_order: int = 5,
    progress: Any = None,
    partial_path: str | os.PathLike[str] | None = None,
    dpi: int = 120,
) -> FrequencyMap:
    """Plot the rotation number ``ν1/ν2`` over a Casimir slice of a problem's state.

    The slice is :func:`manakov.tori.casimir_slice` of the problem's ``l0`` (so
    every state has its ``h0``, ``h1``); the colour is ``ν1/ν2`` on a log scale,
    states on a singular level set are grey, and the resonances
    ``k1 ν1 + k2 ν2 = 0`` with ``|k1| + |k2| ≤ max_order`` are drawn as contour
    lines ``ν1/ν2 = −k2/k1``, except across a jump of ``ν1/ν2`` (where the
    reduced basis of the torus changes, the ratio is discontinuous and a contour
    would only trace the jump).

    Parameters
    ----------
    problem : str or Problem
        A name of :func:`manakov.problem_names`, or any top and state
        (:class:`manakov.Problem`).
    grid : int
        Points per axis; the map has ``grid²`` states.
    path : str or PathLike
        Where to write the PNG.
    client : distributed.Client, optional
        Passed to :func:`manakov.frequency_map`.
    max_order : int
        Largest ``|k1| + |k2|`` of the resonance lines drawn.
    progress : bool or callable, optional
        Passed to :func:`manakov.frequency_map`.
    partial_path : str or PathLike, optional
        Where an interrupted map writes the figure of the states done (default
        ``<stem>.partial<suffix>`` of ``path``).
    dpi : int

    Returns
    -------
    FrequencyMap
        The map, of shape (grid, grid).

    Raises
    ------
    ValueError
        As :func:`manakov.tori.casimir_slice` and :func:`manakov.frequency_map`.
    KeyboardInterrupt
        Ctrl-C: the figure of the states done is written first; ``err.partial``
        is the partial :class:`~manakov.FrequencyMap`, ``err.partial_path`` the
        figure.

    Examples
    --------
    >>> import os, tempfile
    >>> from manakov.plots import plot_frequency_map
    >>> path = os.path.join(tempfile.mkdtemp(), "map.png")
    >>> fm = plot_frequency_map("generic", 8, path, progress=False)
    >>> fm.nu.shape, os.path.exists(path)
    ((8, 8, 2), True)
    """
    pr = as_problem(problem)
    top = ManakovTop(pr.a, pr.b)
    phi, ct, states = casimir_slice(pr.l0, grid)
    _pyplot()  # before the map: no matplotlib fails now; an interrupted map draws at once
    try:
        fm = frequency_map(top, states, client=client, progress=progress)
    except BaseException as err:
        part = getattr(err, "partial", None)
        if isinstance(part, FrequencyMap):
            where = _partial_path(path, partial_path)
            _frequency_figure(where, pr.name, grid, phi, ct, part, max_order, dpi)
            err.partial_path = where  # type: ignore[attr-defined]
        raise
    _frequency_figure(Path(path), pr.name, grid, phi, ct, fm, max_order, dpi)
    return fm


#: Neighbouring cells whose rotation numbers differ by more than this factor lie
#: on a jump of the torus basis: no resonance contour is drawn through them.
JUMP_FACTOR = 1.5


def _frequency_figure(
    path: Path,
    name: str,
    grid: int,
    phi: np.ndarray,
    ct: np.ndarray,
    fm: FrequencyMap,
    max_order: int,
    dpi: int,
) -> None:
    plt = _pyplot()
    from matplotlib.colors import ListedColormap, LogNorm

    ratio = np.asarray(fm.rotation_number, dtype=float)
    ratio[~np.isfinite(ratio)] = np.nan
    fig, ax = plt.subplots(figsize=(7.5, 6), constrained_layout=True)
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
    missing = np.asarray(fm.status) == NOT_COMPUTED
    if missing.any():
        ax.pcolormesh(
            phi,
            ct,
            np.ma.masked_where(~missing, np.ones(missing.shape)),
            shading="nearest",
            cmap=ListedColormap(["white"]),
        )
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
            ax.contour(phi, ct, _without_jumps(ratio), levels=levels, colors="w", linewidths=0.6)
    ax.set_xlabel("φ (direction of p = m + n)")
    ax.set_ylabel("cos ϑ")
    n_ok = int(np.sum(np.asarray(fm.status) == OK))
    notes = []
    singular = ratio.size - n_ok - int(missing.sum())
    if singular:
        notes.append(f"grey: {singular} singular")
    if missing.any():
        notes.append(f"white: {int(missing.sum())} not computed (interrupted)")
    ax.set_title(
        _wrap(f"{name}: rotation number ν1/ν2 at fixed h0, h1, {grid}×{grid} states", 70)
        + "\n"
        + f"white lines: resonances k1 ν1 + k2 ν2 = 0, |k1| + |k2| ≤ {max_order}"
        + (f"; {', '.join(notes)}" if notes else ""),
        fontsize=9,
    )
    fig.savefig(os.fspath(path), dpi=dpi)
    plt.close(fig)


def _without_jumps(ratio: np.ndarray) -> np.ma.MaskedArray:
    """``ratio`` masked at cells next to a jump by more than :data:`JUMP_FACTOR`."""
    with np.errstate(divide="ignore", invalid="ignore"):
        lr = np.log(ratio)
    bad = ~np.isfinite(lr)
    jump = np.zeros(ratio.shape, dtype=bool)
    limit = math.log(JUMP_FACTOR)
    for axis in (0, 1):
        step = np.abs(np.diff(lr, axis=axis)) > limit
        lo = [slice(None)] * 2
        hi = [slice(None)] * 2
        lo[axis], hi[axis] = slice(None, -1), slice(1, None)
        jump[tuple(lo)] |= step
        jump[tuple(hi)] |= step
    return np.ma.masked_array(ratio, mask=bad | jump)
