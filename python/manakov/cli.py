"""The ``manakov`` command line.

``manakov simulate generic`` integrates a built-in reference top (see
``manakov.problem_names()``); ``manakov simulate --a ... --b ... --l0 ...``
integrates any Manakov top (2) on so(n). The trajectory is written to ``.npz``
(arrays ``t``, ``l``, ``a``, ``b`` and one array per integral) or ``.csv``
(columns t, l.., integrals..), and, when matplotlib is importable, a PNG with
l(t) and the relative drift of every integral is written next to it.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from . import problem, problem_names
from ._progress import ProgressBar
from .top import DEFAULT_MAX_STEPS, METHODS, ManakovTop, Trajectory, state_dim

#: Default t_end of ``manakov simulate``: 1000 time units of 'generic' run in
#: about 10 ms of integration.
DEFAULT_T_END = 1000.0
#: The l(t) panel of the PNG shows at most this initial stretch (oscillations
#: have periods of a few time units; a longer window is a solid band).
PLOT_WINDOW = 40.0
#: Runs longer than this many steps are split into chunks to drive the progress bar.
PROGRESS_MIN_STEPS = 200_000
PROGRESS_CHUNKS = 50


def _floats(text: str) -> list[float]:
    try:
        return [float(x) for x in text.replace(",", " ").split()]
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas: {e}") from e


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="manakov", description="The four-dimensional free rigid body (Manakov's top)."
    )
    sub = ap.add_subparsers(dest="command", required=True)
    sim = sub.add_parser(
        "simulate",
        help="integrate a top and write its trajectory",
        description="Integrate Frahm's equations (1) for Manakov's top (2). State order "
        "(l12, l13, l14, l23, l24, l34) for n = 4 (upper triangle, row by row, in general).",
    )
    sim.add_argument("problem", nargs="?", help=f"built-in problem: {', '.join(problem_names())}")
    sim.add_argument("--a", type=_floats, help="a_1..a_n, comma separated")
    sim.add_argument("--b", type=_floats, help="b_1..b_n, comma separated")
    sim.add_argument("--l0", type=_floats, help="initial state, n(n-1)/2 numbers")
    sim.add_argument(
        "--t-end", type=float, default=DEFAULT_T_END, help="final time (default %(default)s)"
    )
    sim.add_argument("--dt", type=float, default=None, help="step (default: the method's default)")
    sim.add_argument("--method", choices=METHODS, default="gauss16")
    sim.add_argument(
        "--max-steps",
        type=int,
        default=DEFAULT_MAX_STEPS,
        help="step budget of the run (default %(default)s)",
    )
    sim.add_argument(
        "--samples", type=int, default=20001, help="number of samples (default %(default)s)"
    )
    sim.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        help="output file, .npz or .csv (default: <problem>.npz)",
    )
    sim.add_argument("--no-plot", action="store_true", help="do not write the PNG")
    sim.add_argument("--progress", action="store_true", help="always show the progress bar")
    sim.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    return ap


def _write(path: Path, tr: Trajectory, a: np.ndarray, b: np.ndarray) -> None:
    if path.suffix == ".npz":
        arrays: dict[str, Any] = {"t": tr.t, "l": tr.l, "a": a, "b": b}
        arrays.update(tr.integrals)
        np.savez(path, **arrays)
    elif path.suffix == ".csv":
        n = len(a)
        names = [f"l{i + 1}{j + 1}" for i in range(n) for j in range(i + 1, n)]
        cols = ["t", *names, *tr.integrals]
        data = np.column_stack([tr.t, tr.l, *tr.integrals.values()])
        np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.17g")
    else:
        raise ValueError(f"output must end in .npz or .csv, got {path.name!r}")


def _plot(path: Path, tr: Trajectory, title: str) -> bool:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    n = int(round((1 + math.sqrt(1 + 8 * tr.l.shape[1])) / 2))
    names = [f"$l_{{{i + 1}{j + 1}}}$" for i in range(n) for j in range(i + 1, n)]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 7), constrained_layout=True)
    window = tr.t <= tr.t[0] + PLOT_WINDOW
    for k in range(tr.l.shape[1]):
        ax1.plot(tr.t[window], tr.l[window, k], lw=0.9, label=names[k])
    ax1.set_ylabel("angular momentum l(t)")
    ax1.set_xlabel("t" + (f" (first {PLOT_WINDOW:g} time units)" if not window.all() else ""))
    ax1.legend(ncol=min(6, len(names)), fontsize=8, loc="upper right")
    ax1.set_title(title)
    floor = np.finfo(float).eps / 4
    for name, d in tr.relative_drift().items():
        ax2.semilogy(tr.t[1:], np.maximum(np.maximum.accumulate(d[1:]), floor), lw=1, label=name)
    ax2.axhline(np.finfo(float).eps, color="gray", ls=":", lw=0.8)
    ax2.text(tr.t[-1], np.finfo(float).eps, " machine eps", va="bottom", ha="right", fontsize=8)
    ax2.set_ylabel("max over [0, t] of |I - I(0)| / |I(0)|")
    ax2.set_xlabel("t")
    ax2.legend(ncol=5, fontsize=8, loc="upper left")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def simulate(args: argparse.Namespace) -> int:
    if args.problem is not None:
        if args.a is not None or args.b is not None:
            raise ValueError("give either a problem name or --a/--b/--l0, not both")
        p = problem(args.problem)
        a, b = p.a, p.b
        l0 = np.asarray(args.l0, dtype=float) if args.l0 is not None else p.l0
        name = p.name
    else:
        if args.a is None or args.b is None or args.l0 is None:
            raise ValueError("give a problem name, or all of --a, --b and --l0")
        a, b, l0 = (np.asarray(x, dtype=float) for x in (args.a, args.b, args.l0))
        name = "custom"
    top = ManakovTop(a, b)
    if l0.shape != (state_dim(top.n),):
        raise ValueError(
            f"--l0 must have {state_dim(top.n)} numbers for n = {top.n}, got {l0.size}"
        )
    if not (args.samples >= 2):
        raise ValueError(f"--samples must be >= 2, got {args.samples}")
    t_end = float(args.t_end)
    dt = args.dt if args.dt is not None else top.default_dt(l0, args.method)
    if not (dt > 0) and args.method != "dopri5":
        raise ValueError(f"--dt must be > 0, got {dt}")
    if not (t_end >= 0) or not math.isfinite(t_end):
        raise ValueError(f"--t-end must be finite and >= 0, got {t_end}")
    t_eval = np.linspace(0.0, t_end, args.samples)
    est_steps = t_end / dt if dt > 0 else t_end * 100
    long_run = est_steps >= PROGRESS_MIN_STEPS or args.progress
    bar = ProgressBar(f"simulate {name}", force=args.progress and not args.quiet)
    if args.quiet:
        bar.enabled = False
    out = args.output if args.output is not None else Path(f"{name}.npz")
    # Fail before a long run, not after it.
    if not out.parent.is_dir():
        raise ValueError(f"cannot write {out}: {out.parent} is not a directory")
    start = time.perf_counter()
    tr = top.integrate(
        l0,
        t_end,
        t_eval=t_eval,
        dt=args.dt,
        method=args.method,
        chunks=PROGRESS_CHUNKS if long_run else 1,
        progress=bar.update if long_run else None,
        max_steps=args.max_steps,
    )
    elapsed = time.perf_counter() - start
    bar.close()
    _write(out, tr, a, b)
    png = out.with_suffix(".png")
    plotted = (
        False
        if args.no_plot
        else _plot(png, tr, f"{name}: {tr.method}, dt = {tr.dt:.3g}, {tr.steps} steps")
    )
    if not args.quiet:
        print(f"{name}: a = {a.tolist()}, b = {b.tolist()}")
        print(
            f"integrated to t = {t_end:g} with {tr.method} (dt = {tr.dt:.4g}): "
            f"{tr.steps} steps in {elapsed:.3f} s"
        )
        for k, v in tr.max_drift().items():
            print(f"  max relative drift of {k:>2}: {v:.2e}")
        print(f"wrote {out}" + (f" and {png}" if plotted else ""))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``manakov`` console script; returns the exit status."""
    ap = _parser()
    args = ap.parse_args(argv)
    try:
        if args.command == "simulate":
            return simulate(args)
    except (ValueError, RuntimeError, OSError) as e:
        print(f"manakov: error: {e}", file=sys.stderr)
        return 2
    ap.error(f"unknown command {args.command!r}")
    return 2  # pragma: no cover


if __name__ == "__main__":
    sys.exit(main())
