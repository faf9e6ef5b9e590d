# The state is called l, as in the paper: E741 does not apply.
# ruff: noqa: E741
"""The ``manakov`` command line.

Subcommands (``manakov <command> --help`` shows each with an example):

``simulate``
    Integrate a top (2) on so(n); write the trajectory to ``.npz`` (arrays ``t``,
    ``l``, ``a``, ``b`` and one array per integral), ``.csv`` (columns t, l..,
    integrals..) or, with ``-o -``, CSV on standard output; and, when matplotlib
    is importable, a PNG with l(t) and the relative drift of every integral.
``kotter``
    The reduction of a state of a top on so(4) (equations (11)-(42)): the
    curve (8) with its branch points d_j, the divisor (z1, y1), (z2, y2), eps, g,
    and the round trip l -> Kötter -> l; a PNG of the branch points and the
    divisor.
``theta``
    Values of the theta functions (34)-(36) at a point.
``theorem``
    l(t) from theta functions (9)-(10) against integration, as a PNG.
``frequency-map``
    Frequencies of the invariant tori over a slice of states, as a PNG.
``fluid-simulate``, ``fluid-theorem``
    A rigid body in an ideal fluid (Kirchhoff's equations) and the Clebsch case
    in theta functions; see ``manakov._cli_fluid``.

Every command that takes a top takes it in one of three ways: a built-in
problem name (``manakov.problem_names()``; ``--l0`` may replace its state),
``--a --b --l0``, or ``--problem-file`` (JSON or TOML with the keys of
problems.json: ``a``, ``b``, ``l0``, or a ``tops`` table of them, picked by the
problem name).

Ctrl-C stops any command within a fraction of a second with status 130 and one
line on stderr; the long ones keep their work: ``simulate`` writes the samples
computed so far (to ``<output stem>.partial<suffix>``, marked partial),
``theorem`` and ``frequency-map`` the figure of what was computed (to
``<output stem>.partial.png``). A closed output pipe (``manakov ... | head``)
ends the command quietly.

Adding a subcommand: write ``_add_<name>(parser)`` and ``_run_<name>(args) -> int``
and add one :class:`Command` to :data:`COMMANDS` (description, example and the
two functions); errors raised as ValueError, RuntimeError or OSError become
``manakov: error: ...`` and status 2.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from . import __version__, _cli_fluid, problem_names
from ._checks import _show
from .integrate import (
    ADAPTIVE_METHODS,
    DEFAULT_MAX_STEPS,
    MAX_SAMPLES,
    METHODS,
    Trajectory,
    gauss_steps,
)
from .problems import Problem, as_problem, read_problem
from .top import ManakovTop, state_dim

#: Default t_end of ``manakov simulate``: 1000 time units of 'generic' run in
#: about 10 ms of integration.
DEFAULT_T_END = 1000.0
#: Default number of samples of ``manakov simulate``, at most: fewer when the
#: step is longer than ``t_end / (samples - 1)``, so that the samples never force
#: a smaller step than the method's (they did: 20001 samples of 'physical' cut
#: its step from 0.1 to 0.05).
DEFAULT_SAMPLES = 20001
#: Exit status after Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130
#: Exit status when the reader of standard output went away (128 + SIGPIPE).
EXIT_BROKEN_PIPE = 141


class Interrupted(Exception):
    """Ctrl-C during a run, with the line to print (partial output already written)."""


@dataclass(frozen=True)
class Command:
    """One subcommand: its help line, description, example and two functions."""

    name: str
    help: str
    description: str
    example: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


def _floats(text: str) -> list[float]:
    try:
        return [float(x) for x in text.replace(",", " ").split()]
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas: {e}") from e


def _complexes(text: str) -> list[complex]:
    try:
        return [complex(x.replace("i", "j")) for x in text.replace(",", " ").split()]
    except ValueError as e:
        raise argparse.ArgumentTypeError(
            f"expected complex numbers separated by commas (like 0.3+1.1j): {e}"
        ) from e


def _add_top_arguments(p: argparse.ArgumentParser, n_hint: str) -> None:
    p.add_argument(
        "problem",
        nargs="?",
        help=f"built-in problem: {', '.join(problem_names())} (with --problem-file: the "
        "name of a top in the file's 'tops' table)",
    )
    p.add_argument("--a", type=_floats, help="a_1..a_n, comma separated")
    p.add_argument("--b", type=_floats, help="b_1..b_n, comma separated")
    p.add_argument("--l0", type=_floats, help=f"initial state, {n_hint} numbers")
    p.add_argument(
        "--problem-file",
        type=Path,
        default=None,
        metavar="FILE",
        help="a top and state from a JSON or TOML file with the keys of problems.json "
        "(a, b, l0; or a 'tops' table of them)",
    )


def _problem_from_args(args: argparse.Namespace) -> Problem:
    """The top and state the user named: a problem, a file, or --a/--b/--l0."""
    if args.problem_file is not None:
        if args.a is not None or args.b is not None:
            raise ValueError("give either --problem-file or --a/--b/--l0, not both")
        pr = read_problem(args.problem_file, args.problem)
    elif args.problem is not None:
        if args.a is not None or args.b is not None:
            raise ValueError("give either a problem name or --a/--b/--l0, not both")
        pr = as_problem(args.problem)
    else:
        if args.a is None or args.b is None or args.l0 is None:
            raise ValueError("give a problem name, --problem-file, or all of --a, --b and --l0")
        a, b, l0 = (np.asarray(x, dtype=float) for x in (args.a, args.b, args.l0))
        return Problem("custom", a, b, l0, "")
    if args.l0 is not None:
        pr = pr._replace(l0=np.asarray(args.l0, dtype=float))
    return pr


def _top_from_args(args: argparse.Namespace) -> tuple[ManakovTop, np.ndarray, str]:
    pr = _problem_from_args(args)
    top = ManakovTop(pr.a, pr.b)
    l0 = np.asarray(pr.l0, dtype=float)
    if l0.shape != (state_dim(top.n),):
        raise ValueError(
            f"--l0 must have {state_dim(top.n)} numbers for n = {top.n}, got {l0.size}"
        )
    return top, l0, pr.name


def _add_progress_arguments(p: argparse.ArgumentParser) -> None:
    show = p.add_mutually_exclusive_group()
    show.add_argument(
        "--progress", action="store_true", help="always show the progress bar (on stderr)"
    )
    show.add_argument("--no-progress", action="store_true", help="never show the progress bar")


def _progress(args: argparse.Namespace) -> bool | None:
    """The library's ``progress``: a bar when asked, none when asked or quiet, else
    automatic (on a terminal, for a long run)."""
    if getattr(args, "quiet", False) or args.no_progress:
        return False
    return True if args.progress else None


# --------------------------------------------------------------------- simulate


def _add_simulate(sim: argparse.ArgumentParser) -> None:
    _add_top_arguments(sim, "n(n-1)/2")
    sim.add_argument(
        "--t-end", type=float, default=DEFAULT_T_END, help="final time, > 0 (default %(default)s)"
    )
    sim.add_argument(
        "--dt",
        type=float,
        default=None,
        help="largest step of a Gauss method, initial step of dopri5/dop853 "
        "(default: the method's default; adaptive for dopri5/dop853)",
    )
    sim.add_argument("--method", choices=METHODS, default="gauss16")
    sim.add_argument(
        "--max-steps",
        type=int,
        default=DEFAULT_MAX_STEPS,
        help="step budget of the run (default %(default)s)",
    )
    sim.add_argument(
        "--samples",
        type=int,
        default=None,
        help=f"number of samples, >= 2 (default: {DEFAULT_SAMPLES}, or fewer so that "
        "the sample spacing is at least the step)",
    )
    sim.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        help="output file, .npz or .csv, or '-' for CSV on standard output "
        "(default: <problem>.npz)",
    )
    sim.add_argument("--no-plot", action="store_true", help="do not write the PNG")
    _add_progress_arguments(sim)
    sim.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")


def _columns(n: int, integrals: Sequence[str]) -> list[str]:
    names = [f"l{i + 1}{j + 1}" for i in range(n) for j in range(i + 1, n)]
    return ["t", *names, *integrals]


def _write(
    path: Path | None,
    t: np.ndarray,
    l: np.ndarray,
    integrals: dict[str, np.ndarray],
    a: np.ndarray,
    b: np.ndarray,
    *,
    partial: bool = False,
    stream: TextIO | None = None,
) -> None:
    """Write the samples: ``path`` .npz or .csv, or CSV to ``stream`` when ``path`` is None."""
    if path is not None and path.suffix == ".npz":
        arrays: dict[str, Any] = {"t": t, "l": l, "a": a, "b": b, "partial": np.array(partial)}
        arrays.update(integrals)
        np.savez(path, **arrays)
        return
    if path is not None and path.suffix != ".csv":
        raise ValueError(f"output must end in .npz or .csv, got {path.name!r}")
    cols = _columns(len(a), list(integrals))
    header = ",".join(cols)
    if partial:
        header = "# partial: interrupted, samples up to t = " + f"{t[-1]:.17g}\n" + header
    data = np.column_stack([t, l, *integrals.values()])
    target: TextIO | Path = path if path is not None else (stream or sys.stdout)
    np.savetxt(target, data, delimiter=",", header=header, comments="", fmt="%.17g")


#: What to install for the figures (the optional dependency group).
PLOT_EXTRA_HINT = "matplotlib is not installed: pip install 'manakov[plot]' for the figure"


def _have_matplotlib() -> bool:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def _try_plot(draw: Callable[[], None]) -> bool:
    """Draw a figure; False (and no figure) when matplotlib is not installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    draw()
    return True


def _sample_times(t_end: float, samples: int | None, dt: float, explicit: bool) -> np.ndarray:
    if samples is None:
        samples = DEFAULT_SAMPLES
        if not explicit:
            # Never more sample intervals than the steps the method takes over
            # [0, t_end] (the core's count): one step of at most dt per interval.
            samples = max(2, min(samples, gauss_steps([t_end], dt) + 1))
    elif samples < 2:
        raise ValueError(f"--samples must be >= 2, got {samples}")
    elif samples > MAX_SAMPLES:
        raise ValueError(
            f"--samples must be at most {MAX_SAMPLES:.0e} (the samples of one run), got {samples}"
        )
    return np.linspace(0.0, t_end, samples)


def _run_simulate(args: argparse.Namespace) -> int:
    top, l0, name = _top_from_args(args)
    a, b = top.a, top.b
    t_end = float(args.t_end)
    if not (math.isfinite(t_end) and t_end > 0):
        raise ValueError(
            f"--t-end must be finite and > 0, got {t_end} (the state at t = 0 is --l0)"
        )
    explicit = args.method in ADAPTIVE_METHODS
    if args.dt is not None and not (args.dt > 0 and math.isfinite(args.dt)):
        raise ValueError(f"--dt must be finite and > 0, got {args.dt}")
    dt = args.dt if args.dt is not None else top.default_dt(l0, args.method)
    times = _sample_times(t_end, args.samples, dt, explicit)
    to_stdout = args.output is not None and str(args.output) == "-"
    out = None if to_stdout else (args.output or Path(f"{name}.npz"))
    if out is not None:
        if out.suffix not in (".npz", ".csv"):
            raise ValueError(f"output must end in .npz or .csv, got {out.name!r}")
        # Fail before a long run, not after it.
        if not out.parent.is_dir():
            raise ValueError(f"cannot write {out}: {out.parent} is not a directory")
    # With CSV on stdout, the report goes to stderr.
    report = sys.stderr if to_stdout else sys.stdout
    start = time.perf_counter()
    try:
        tr = top.integrate(
            l0,
            t_end,
            t_eval=times,
            dt=args.dt,
            method=args.method,
            max_steps=args.max_steps,
            progress=_progress(args),
        )
    except KeyboardInterrupt as e:
        part: Trajectory | None = getattr(e, "partial", None)
        t = part.t if part is not None else np.empty(0)
        where = "no samples" if t.size == 0 else f"{t.size} samples up to t = {t[-1]:.6g}"
        if part is None or t.size == 0:
            raise Interrupted(f"interrupted: {where}") from None
        if out is None:
            _write(None, t, part.l, part.integrals, a, b, partial=True, stream=sys.stdout)
            raise Interrupted(f"interrupted: {where}") from None
        partial = out.with_name(out.stem + ".partial" + out.suffix)
        _write(partial, t, part.l, part.integrals, a, b, partial=True)
        raise Interrupted(f"interrupted: wrote {where} to {partial} (partial)") from None
    elapsed = time.perf_counter() - start
    _write(out, tr.t, tr.l, tr.integrals, a, b, stream=sys.stdout)
    step = t_end / tr.steps if tr.steps else float("nan")
    kind = "mean step" if explicit else "step"
    png = out.with_suffix(".png") if out is not None else None
    title = f"{name}: {tr.method}, {kind} {step:.3g}, {tr.steps} steps to t = {t_end:g}"
    plotted = (
        png is not None
        and not args.no_plot
        and _try_plot(lambda: _plots().plot_trajectory(png, top, tr, title=title))
    )
    if not args.quiet:
        print(f"{name}: a = {a.tolist()}, b = {b.tolist()}", file=report)
        print(
            f"integrated to t = {t_end:g} with {tr.method}: {tr.steps} steps, "
            f"{kind} {step:.4g} ({tr.t.size} samples), in {elapsed:.3f} s",
            file=report,
        )
        for k, v in tr.max_drift().items():
            print(f"  max relative drift of {k:>2}: {v:.2e}", file=report)
        if out is not None:
            print(f"wrote {out}" + (f" and {png}" if plotted else ""), file=report)
    return 0


def _plots() -> Any:
    """The figures module (imports matplotlib only when a figure is drawn)."""
    from . import plots

    return plots


# ----------------------------------------------------------------------- kotter


def _add_kotter(p: argparse.ArgumentParser) -> None:
    _add_top_arguments(p, "6")
    p.add_argument("--plot", type=Path, default=None, help="write a PNG of the curve's data")


def _run_kotter(args: argparse.Namespace) -> int:
    from .reduction import from_kotter, kotter

    top, l0, name = _top_from_args(args)
    if top.n != 4:
        raise ValueError(f"the reduction is for tops on so(4) (n = 4), got n = {top.n}")
    k = kotter(top.a, top.b, l0)
    back = from_kotter(top.a, top.b, k)
    err = float(np.max(np.abs(back - l0)) / max(float(np.max(np.abs(l0))), 1e-300))
    lines = [
        f"{name}: a = {top.a.tolist()}, b = {top.b.tolist()}",
        f"l = {l0.tolist()}",
        "integrals (6)-(7): h0..h3 = " + ", ".join(_show(x) for x in k.h),
        "roots of F (19): s = " + ", ".join(_show(x) for x in k.s),
        "curve (8): y^2 = x (x - d1)(x - d2)(x - d3)(x - d4), d4 = d1 d2 d3",
        "  d = " + ", ".join(_show(x) for x in k.d) + f", d4 = {_show(np.prod(k.d))}",
        "divisor (37): (z1, y1) = " + f"({_show(k.z1)}, {_show(k.y1)})",
        "              (z2, y2) = " + f"({_show(k.z2)}, {_show(k.y2)})",
        f"eps (41) = {_show(k.eps)}, g (42) = {_show(k.g)}, P0 = {_show(k.P0)}",
        "xi (22) = " + ", ".join(_show(x) for x in k.xi),
        "eta (22) = " + ", ".join(_show(x) for x in k.eta),
        f"round trip l -> Kotter -> l: max relative error {err:.2e}",
    ]
    print("\n".join(lines))
    if args.plot is not None:
        if _try_plot(lambda: _plots().plot_kotter(args.plot, k, name)):
            print(f"wrote {args.plot}")
        else:
            print("matplotlib is not installed: no plot", file=sys.stderr)
    return 0


# ------------------------------------------------------------------------ theta


def _add_theta(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--tau",
        type=_complexes,
        required=True,
        help="period matrix, g*g complex entries row by row (symmetric, Im tau > 0)",
    )
    p.add_argument("--z", type=_complexes, required=True, help="the point, g complex numbers")
    p.add_argument(
        "--char",
        default=None,
        help="one characteristic: a FLINT index, a label of (35) such as theta12, or "
        "'a1 a2;b1 b2' (default: all 4^g)",
    )
    p.add_argument(
        "--log-scale",
        action="store_true",
        help="print Omega and L with theta = exp(L) Omega (never overflows)",
    )


def _parse_char(text: str | None) -> Any:
    if text is None:
        return None
    if text.strip().isdigit():
        return int(text)
    if ";" in text:
        a, b = text.split(";")
        return (tuple(int(x) for x in a.replace(",", " ").split()),) + (
            tuple(int(x) for x in b.replace(",", " ").split()),
        )
    return text


def _run_theta(args: argparse.Namespace) -> int:
    from .theta import characteristics, theta, theta_all

    m = len(args.tau)
    g = math.isqrt(m)
    if g * g != m:
        raise ValueError(f"--tau needs g*g entries (row by row), got {m}")
    tau = np.array(args.tau, dtype=complex).reshape(g, g)
    z = np.array(args.z, dtype=complex)
    if args.char is not None:
        char = _parse_char(args.char)
        if args.log_scale:
            om, log = theta(z, tau, char, log_scale=True)
            print(f"Omega = {_show(om)}, L = {float(log):.17g}")
        else:
            print(_show(theta(z, tau, char)))
        return 0
    if args.log_scale:
        vals, log = theta_all(z, tau, log_scale=True)
        print(f"# theta = exp(L) Omega, L = {float(log):.17g}")
    else:
        vals = theta_all(z, tau)
    print("# index  a  b  value")
    for idx, ((a, b), v) in enumerate(zip(characteristics(g), vals)):
        print(f"{idx:>3}  {''.join(map(str, a))} {''.join(map(str, b))}  {_show(v)}")
    return 0


def _add_theorem(p: argparse.ArgumentParser) -> None:
    _add_top_arguments(p, "6")
    p.add_argument("-o", "--output", default=None, help="PNG path (default: <problem>-theorem.png)")
    p.add_argument("--t-end", type=float, default=100.0, help="end time (default 100)")
    p.add_argument("--samples", type=int, default=201, help="comparison times (default 201)")
    p.add_argument(
        "--dt", type=float, default=1e-3, help="gauss16 step of the comparison (default 1e-3)"
    )
    _add_progress_arguments(p)


def _run_theorem(args: argparse.Namespace) -> int:
    pr = _problem_from_args(args)
    out = Path(args.output or f"{pr.name}-theorem.png")
    if not out.parent.is_dir():
        raise ValueError(f"cannot write {out}: {out.parent} is not a directory")
    if args.samples > MAX_SAMPLES:
        raise ValueError(f"--samples must be at most {MAX_SAMPLES:.0e}, got {args.samples}")
    if not _have_matplotlib():
        raise ValueError(f"{PLOT_EXTRA_HINT} (theorem draws its comparison)")
    try:
        err = _plots().plot_theorem(
            pr, out, t_end=args.t_end, samples=args.samples, dt=args.dt, progress=_progress(args)
        )
    except KeyboardInterrupt as e:
        part = getattr(e, "partial", None)
        where = getattr(e, "partial_path", None)
        if part is None or where is None:
            raise Interrupted("interrupted: no comparison samples yet") from None
        raise Interrupted(
            f"interrupted: wrote the comparison at {part.t.size} samples up to "
            f"t = {part.t[-1]:.6g} to {where} (partial)"
        ) from None
    print(f"{pr.name}: max |l_theta - l_int| / |l0| on [0, {args.t_end:g}] = {err:.3g}")
    print(f"wrote {out}")
    return 0


def _add_frequency_map(p: argparse.ArgumentParser) -> None:
    _add_top_arguments(p, "6")
    p.add_argument("--grid", type=int, default=64, help="states per side of the slice (default 64)")
    p.add_argument(
        "-o", "--output", default=None, help="PNG path (default: <problem>-frequency-map.png)"
    )
    p.add_argument(
        "--max-order", type=int, default=5, help="resonances k1 nu1 + k2 nu2 = 0, |k1|+|k2| <= this"
    )
    _add_progress_arguments(p)


def _counts(fm: Any) -> str:
    return ", ".join(f"{k}: {v}" for k, v in fm.counts().items())


def _run_frequency_map(args: argparse.Namespace) -> int:
    if args.grid < 2:
        raise ValueError(f"--grid must be >= 2, got {args.grid}")
    pr = _problem_from_args(args)
    out = Path(args.output or f"{pr.name}-frequency-map.png")
    if not out.parent.is_dir():
        raise ValueError(f"cannot write {out}: {out.parent} is not a directory")
    if not _have_matplotlib():
        return _frequency_map_data(args, pr, out.with_suffix(".npz"))
    try:
        fm = _plots().plot_frequency_map(
            pr, args.grid, out, max_order=args.max_order, progress=_progress(args)
        )
    except KeyboardInterrupt as e:
        part = getattr(e, "partial", None)
        where = getattr(e, "partial_path", None)
        if part is None or where is None:
            raise Interrupted("interrupted: no states done yet") from None
        raise Interrupted(
            f"interrupted: wrote the map of {part.status.size} states ({_counts(part)}) "
            f"to {where} (partial)"
        ) from None
    print(f"{pr.name}: {fm.status.size} states ({_counts(fm)})")
    print(f"wrote {out}")
    return 0


def _frequency_map_data(args: argparse.Namespace, pr: Problem, path: Path) -> int:
    """Without matplotlib: the map's data (no figure) to ``path``, and the hint."""
    from .tori import casimir_slice, frequency_map

    print(f"{PLOT_EXTRA_HINT}; writing the map's data to {path}", file=sys.stderr)
    phi, ct, states = casimir_slice(pr.l0, args.grid)
    try:
        fm = frequency_map(ManakovTop(pr.a, pr.b), states, progress=_progress(args))
    except KeyboardInterrupt as e:
        part = getattr(e, "partial", None)
        if part is None:
            raise Interrupted("interrupted: no states done yet") from None
        where = path.with_suffix(".partial.npz")
        np.savez(where, phi=phi, ct=ct, nu=part.nu, status=part.status)
        raise Interrupted(
            f"interrupted: wrote the map of {part.status.size} states ({_counts(part)}) "
            f"to {where} (partial)"
        ) from None
    np.savez(path, phi=phi, ct=ct, nu=fm.nu, status=fm.status)
    print(f"{pr.name}: {fm.status.size} states ({_counts(fm)})")
    print(f"wrote {path}")
    return 0


# --------------------------------------------------------------------- registry

COMMANDS: tuple[Command, ...] = (
    Command(
        "simulate",
        "integrate a top and write its trajectory",
        "Integrate Frahm's equations (1) for Manakov's top (2). State order "
        "(l12, l13, l14, l23, l24, l34) for n = 4 (upper triangle, row by row, in general). "
        "Ctrl-C writes the samples computed so far to <output stem>.partial<suffix> and "
        "exits with status 130.",
        "manakov simulate generic --t-end 100 -o generic.npz\n"
        "  manakov simulate --a 1,2,3 --b 0.5,-1,2 --l0 1,0.5,-0.2 --method dop853 -o - | head",
        _add_simulate,
        _run_simulate,
    ),
    Command(
        "kotter",
        "reduce a state of an so(4) top to its curve and divisor",
        "The Schottky-Kötter reduction (11)-(42) of a state: the integrals h0..h3, the "
        "roots s_p of F (19), the curve (8) with branch points d_j, the divisor "
        "(z1, y1), (z2, y2), eps (41) and g (42), Kötter's xi, eta (22), and the error of "
        "the round trip l -> Kötter -> l. --plot draws the branch points and the divisor.",
        "manakov kotter generic --plot generic-curve.png\n"
        "  manakov kotter --a 0,1,2,3.5 --b 0,1,4,12.25 --l0 1,0.2,0.3,-0.4,0.5,0.6",
        _add_kotter,
        _run_kotter,
    ),
    Command(
        "theta",
        "theta functions with half-integer characteristics at a point",
        "theta[a;b](z, tau) = sum_n exp(i pi (n+a/2)^T tau (n+a/2) + 2 pi i (n+a/2)^T (z+b/2)) "
        "((34)-(36)), all 4^g characteristics in FLINT's order or one of them.",
        "manakov theta --tau '0.3+1.1j,0.1+0.4j,0.1+0.4j,-0.2+1.3j' --z '0.2+0.1j,0.7-0.3j'\n"
        "  manakov theta --tau ... --z ... --char theta12",
        _add_theta,
        _run_theta,
    ),
    Command(
        "theorem",
        "l(t) from theta functions (9)-(10) against integration, as a PNG",
        "The Theorem (9)-(10): l(t) as quotients of genus-2 theta functions at "
        "v = v0 + U t (docs/theorem.md), plotted against gauss16, with their "
        "difference on a log scale. Ctrl-C writes the figure of the samples computed so "
        "far to <output stem>.partial.png and exits with status 130.",
        "manakov theorem physical -o physical-theorem.png\n"
        "  manakov theorem generic --t-end 1000 --samples 2001\n"
        "  manakov theorem --a 0.1,0.9,2.3,3.1 --b 0.4,-0.6,1.1,2.5 --l0 0.7,-0.2,0.6,1,-0.5,0.3",
        _add_theorem,
        _run_theorem,
    ),
    Command(
        "frequency-map",
        "frequencies of the invariant tori over a slice of states, as a PNG",
        "The frequencies (nu1, nu2) of the real Liouville tori from the Theorem "
        "(docs/tori.md) over a grid of states at fixed Casimirs h0, h1; the colour is "
        "nu1/nu2, with the resonance lines k1 nu1 + k2 nu2 = 0 overlaid. Ctrl-C writes "
        "the map of the states done so far to <output stem>.partial.png and exits with "
        "status 130.",
        "manakov frequency-map generic --grid 128 -o generic-fmap.png\n"
        "  manakov frequency-map --problem-file mytop.toml --grid 96",
        _add_frequency_map,
        _run_frequency_map,
    ),
    Command(
        "fluid-simulate",
        "integrate a rigid body in an ideal fluid and write its motion in space",
        "Integrate Kirchhoff's equations dM/dt = M x dH/dM + p x dH/dp, dp/dt = p x dH/dM "
        "for H = (M^T A M + 2 M^T B p + p^T C p)/2, with the body's rotation R and position "
        "x in space (docs/clebsch.md). Writes t, M, p, R, x and the integrals (.npz or .csv) "
        "and a PNG of the path, the body's axes, M, p and the drift of the integrals. "
        "Ctrl-C writes the samples so far to <output stem>.partial<suffix>, status 130.",
        "manakov fluid-simulate clebsch_generic --t-end 60 -o clebsch.npz\n"
        "  manakov fluid-simulate --A 1,2,3 --B 0,0,0 --C 2,1,3 --M0 1,0,0.5 --p0 0,1,0.2",
        _cli_fluid.add_simulate,
        _cli_fluid.run_simulate,
    ),
    Command(
        "fluid-theorem",
        "M(t), p(t) of a Clebsch body from theta functions against integration, as a PNG",
        "The Clebsch case in closed form: the body's field is linearly conjugate to a "
        "Manakov top's, and M(t), p(t) are the Theorem's theta quotients at v0 + U t mapped "
        "back (docs/clebsch.md); plotted against gauss16, with their difference.",
        "manakov fluid-theorem clebsch_generic -o clebsch-theorem.png",
        _cli_fluid.add_theorem,
        _cli_fluid.run_theorem,
    ),
)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="manakov",
        description="The four-dimensional free rigid body (Manakov's top).",
        epilog="Run 'manakov <command> --help' for each command's options and an example.",
    )
    ap.add_argument("--version", action="version", version=f"manakov {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="command")
    for cmd in COMMANDS:
        p = sub.add_parser(
            cmd.name,
            help=cmd.help,
            description=cmd.description,
            epilog="example:\n  " + cmd.example,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        cmd.add_arguments(p)
    return ap


def _quiet_broken_pipe() -> int:
    # The reader closed the pipe (e.g. `| head`): send what is still buffered to
    # /dev/null, so that the interpreter's flush at exit does not complain.
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return EXIT_BROKEN_PIPE


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``manakov`` console script; returns the exit status.

    Examples
    --------
    >>> from manakov.cli import main
    >>> main(["kotter", "generic"])  # doctest: +ELLIPSIS
    generic: a = [0.3, 1.1, 2.0, 3.7], b = [0.5, -0.2, 1.4, 0.9]
    l = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2]
    ...
    """
    try:
        ap = _parser()
        args = ap.parse_args(argv)
        if args.command is None:
            # `manakov` or `python -m manakov` alone: the version and the commands.
            print(f"manakov {__version__}")
            print("commands: " + ", ".join(c.name for c in COMMANDS))
            print("run 'manakov <command> --help' for its options and an example")
            return 0
        run = {c.name: c.run for c in COMMANDS}[args.command]
        try:
            status = run(args)
            sys.stdout.flush()
            return status
        except (Interrupted, _cli_fluid.FluidInterrupted) as e:
            print(f"manakov: {e}", file=sys.stderr)
            return EXIT_INTERRUPTED
        except BrokenPipeError:
            return _quiet_broken_pipe()
        except (ValueError, RuntimeError, OSError) as e:
            print(f"manakov: error: {e}", file=sys.stderr)
            return 2
    except KeyboardInterrupt:
        print("manakov: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
