"""The ``manakov`` subcommands of the body in a fluid (registered in ``cli.py``).

``fluid-simulate``
    Integrate Kirchhoff's equations for a reference body
    (``manakov.fluid_problem_names()``) or any ``--A --B --C``, with the body's
    rotation and position in space; write ``.npz`` (``t, M, p, R, x`` and one
    array per integral) or ``.csv``, and a PNG of the motion in space.
``fluid-theorem``
    ``M(t), p(t)`` of a Clebsch body from theta functions against integration,
    as a PNG.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from .fluid import (
    KirchhoffBody,
    SpaceTrajectory,
    fluid_problem,
    fluid_problem_names,
    plot_clebsch_theorem,
    plot_space_trajectory,
)
from .top import DEFAULT_MAX_STEPS, METHODS

#: Default end time and number of samples of ``fluid-simulate``.
DEFAULT_T_END = 100.0
DEFAULT_SAMPLES = 2001


class FluidInterrupted(Exception):
    """Ctrl-C during a run, with the line to print (partial output already written)."""


def _floats(text: str) -> list[float]:
    try:
        return [float(x) for x in text.replace(",", " ").split()]
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas: {e}") from e


def add_simulate(p: argparse.ArgumentParser) -> None:
    p.add_argument("body", nargs="?", help=f"reference body: {', '.join(fluid_problem_names())}")
    for m in ("A", "B", "C"):
        p.add_argument(f"--{m}", type=_floats, help=f"{m}: 3 numbers (diagonal) or 9 (row by row)")
    p.add_argument("--M0", type=_floats, help="initial impulsive couple, 3 numbers")
    p.add_argument("--p0", type=_floats, help="initial impulsive force, 3 numbers")
    p.add_argument("--t-end", type=float, default=DEFAULT_T_END, help="end time (default 100)")
    p.add_argument("--dt", type=float, default=None, help="largest step (Gauss methods)")
    p.add_argument("--method", choices=[m for m in METHODS if m != "taylor"], default="gauss16")
    p.add_argument("--samples", type=int, default=DEFAULT_SAMPLES, help="sample times (2001)")
    p.add_argument("--max-steps", type=int, default=DEFAULT_MAX_STEPS, help="step budget")
    p.add_argument("-o", "--output", type=Path, default=None, help=".npz or .csv")
    p.add_argument("--no-plot", action="store_true", help="do not write the PNG")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")


def _matrix(values: list[float] | None, what: str) -> np.ndarray:
    if values is None:
        raise ValueError(f"--{what} is required with a custom body")
    if len(values) == 3:
        return np.diag(values)
    if len(values) == 9:
        return np.array(values).reshape(3, 3)
    raise ValueError(f"--{what} takes 3 numbers (diagonal) or 9 (row by row), got {len(values)}")


def _body_from_args(args: argparse.Namespace) -> tuple[KirchhoffBody, np.ndarray, np.ndarray, str]:
    custom = any(getattr(args, m) is not None for m in ("A", "B", "C"))
    if args.body is not None:
        if custom:
            raise ValueError("give a reference body or --A/--B/--C, not both")
        pr = fluid_problem(args.body)
        M0 = pr.M0 if args.M0 is None else np.array(args.M0)
        p0 = pr.p0 if args.p0 is None else np.array(args.p0)
        return pr.body, M0, p0, args.body
    if not custom:
        raise ValueError(
            f"name a reference body ({', '.join(fluid_problem_names())}) or give --A, --B, --C"
        )
    body = KirchhoffBody(_matrix(args.A, "A"), _matrix(args.B, "B"), _matrix(args.C, "C"))
    if args.M0 is None or args.p0 is None:
        raise ValueError("a custom body needs --M0 and --p0")
    return body, np.array(args.M0), np.array(args.p0), "body"


def _write(path: Path, tr: SpaceTrajectory, body: KirchhoffBody, *, partial: bool) -> None:
    ints = body.integrals(tr.M, tr.p) if tr.t.size else {}
    if path.suffix == ".npz":
        arrays: dict[str, Any] = {
            "t": tr.t,
            "M": tr.M,
            "p": tr.p,
            "R": tr.R,
            "x": tr.x,
            "A": body.A,
            "B": body.B,
            "C": body.C,
            "partial": np.array(partial),
        }
        arrays.update(ints)
        np.savez(path, **arrays)
        return
    cols = ["t", "M1", "M2", "M3", "p1", "p2", "p3", "x1", "x2", "x3"]
    cols += [f"R{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)] + list(ints)
    header = ",".join(cols)
    if partial:
        header = f"# partial: interrupted, samples up to t = {tr.t[-1]:.17g}\n" + header
    data = np.column_stack([tr.t, tr.M, tr.p, tr.x, tr.R.reshape(-1, 9), *ints.values()])
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.17g")


def run_simulate(args: argparse.Namespace) -> int:
    body, M0, p0, name = _body_from_args(args)
    t_end = float(args.t_end)
    if not (math.isfinite(t_end) and t_end > 0):
        raise ValueError(f"--t-end must be finite and > 0, got {t_end}")
    if args.samples < 2:
        raise ValueError(f"--samples must be >= 2, got {args.samples}")
    out = args.output or Path(f"{name}.npz")
    if out.suffix not in (".npz", ".csv"):
        raise ValueError(f"output must end in .npz or .csv, got {out.name!r}")
    if not out.parent.is_dir():
        raise ValueError(f"cannot write {out}: {out.parent} is not a directory")
    t = np.linspace(0.0, t_end, args.samples)
    start = time.perf_counter()
    try:
        tr = body.motion_in_space(
            M0, p0, t_end, t_eval=t, dt=args.dt, method=args.method, max_steps=args.max_steps
        )
    except KeyboardInterrupt as err:
        part = getattr(err, "partial", None)
        if part is None or part.t.size == 0:
            raise FluidInterrupted("interrupted: no samples") from None
        path = out.with_name(out.stem + ".partial" + out.suffix)
        _write(path, part, body, partial=True)
        raise FluidInterrupted(
            f"interrupted: wrote {part.t.size} samples up to t = {part.t[-1]:.6g} to {path} "
            "(partial)"
        ) from None
    elapsed = time.perf_counter() - start
    _write(out, tr, body, partial=False)
    png = out.with_suffix(".png")
    plotted = False
    if not args.no_plot:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            pass
        else:
            plot_space_trajectory(body, tr, str(png))
            plotted = True
    if not args.quiet:
        ints = body.integrals(tr.M, tr.p)
        P, K = tr.impulse(), tr.moment()
        m0, q0 = [float(x) for x in M0], [float(x) for x in p0]
        print(f"{name} ({body.case} case): M0 = {m0}, p0 = {q0}")
        step = t_end / tr.steps if tr.steps else float("nan")
        forced = (
            f" (the {args.samples} samples force it below the step {tr.dt:.4g})"
            if tr.method.startswith("gauss") and step < 0.999 * tr.dt
            else ""
        )
        print(
            f"integrated to t = {t_end:g} with {tr.method}: {tr.steps} steps, mean step "
            f"{step:.4g}{forced}, in {elapsed:.3f} s; the origin moved "
            f"{float(np.linalg.norm(tr.x[-1] - tr.x[0])):.4g}"
        )
        for k, v in ints.items():
            ref = abs(float(v[0])) or 1.0
            print(f"  max relative drift of {k:>2}: {float(np.max(np.abs(v - v[0]))) / ref:.2e}")
        for k, v in (("P = R p", P), ("K = R M + x × P", K)):
            ref = float(np.max(np.abs(v[0]))) or 1.0
            print(f"  max relative drift of {k}: {float(np.max(np.abs(v - v[0]))) / ref:.2e}")
        print(f"wrote {out}" + (f" and {png}" if plotted else ""))
    return 0


def add_theorem(p: argparse.ArgumentParser) -> None:
    clebsch = [n for n in fluid_problem_names() if n.startswith("clebsch")]
    p.add_argument("body", choices=clebsch, help="a reference Clebsch body")
    p.add_argument("-o", "--output", default=None, help="PNG path (default: <body>-theorem.png)")
    p.add_argument("--t-end", type=float, default=100.0, help="end time (default 100)")
    p.add_argument("--samples", type=int, default=201, help="sample times (default 201)")


def run_theorem(args: argparse.Namespace) -> int:
    out = Path(args.output or f"{args.body}-theorem.png")
    err = plot_clebsch_theorem(args.body, str(out), t_end=args.t_end, samples=args.samples)
    pr = fluid_problem(args.body)
    sol = pr.body.solve(pr.M0, pr.p0)
    nu = sol.frequencies
    print(f"{args.body}: {sol!r}")
    print(f"frequencies nu = ({nu[0]:.12g}, {nu[1]:.12g}) cycles per unit time")
    print(f"max |y_theta - y_int| / max|y0| on [0, {args.t_end:g}] = {err:.3g}")
    print(f"wrote {out}")
    sys.stdout.flush()
    return 0
