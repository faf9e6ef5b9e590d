"""Run every benchmark with short settings and write the one table the docs quote.

This script is the single source of every performance figure in README.md and on the
documentation site. It runs

* the criterion benches (``cargo bench``, one bench file after the other, short
  warm-up and measurement times), reading criterion's own estimates (medians);
* the comparisons with peers in ``benches/*.py`` (scipy, heyoka, python-flint, numpy,
  integration + NAFF), each in one process with its ``--quick`` settings, keeping
  their output verbatim;

and writes ``docs/_generated/benchmarks.md`` (the machine, the library versions, the
criterion table and each comparison's output) and ``docs/_generated/benchmarks_summary.md``
(a few headline figures read from those outputs, which README.md quotes unchanged;
``tests/test_readme.py`` checks that it does). The machine block records the CPU
model, its SIMD features, the core count, the load average before and after the run
and the date: figures from a shared or loaded machine are noisy, and say so.

    python benches/run_all.py                 # everything (about 10 minutes on 2 cores)
    python benches/run_all.py --update-readme # and copy the summary into README.md
    python benches/run_all.py --skip-criterion   # the Python comparisons only

Nothing here is a test: it never fails on a slow result, only on a benchmark that
does not run or an output it cannot read.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "_generated"
README = ROOT / "README.md"
BEGIN = "<!-- benchmarks-summary: begin (written by benches/run_all.py) -->"
END = "<!-- benchmarks-summary: end -->"

#: Criterion bench files, in the order of the paper's chain.
CRITERION = ("dynamics", "theta", "riemann", "curve", "kotter", "solution", "tori")
#: Short criterion settings (seconds): enough for a stable median of the fast
#: kernels, short enough that the whole run stays at a few minutes on 2 cores.
CRITERION_ARGS = ("--warm-up-time", "0.5", "--measurement-time", "1.5", "--noplot")

#: The comparisons with peers: (script, arguments). Each prints its own table.
COMPARISONS = (
    ("compare_scipy.py", ("--quick",)),
    ("compare_heyoka.py", ("--quick",)),
    ("theta_compare.py", ("--quick",)),
    ("riemann_compare.py", ("--quick",)),
    ("theorem_compare.py", ()),
    ("precise_compare.py", ("--quick",)),
    ("tori_compare.py", ("--quick",)),
    ("fluid_compare.py", ("--quick",)),
)

#: SIMD features worth naming: the batch integrators and the theta kernel pick
#: AVX2/FMA kernels at run time; AVX-512 is reported because readers compare with it.
#: Headline ratios read from the comparisons' output: (script, pattern, what).
RATIOS = (
    (
        "compare_scipy.py",
        r"speed-up ([0-9.,]+x)",
        "gauss16 vs scipy DOP853 (rtol 1e-12), 'generic'",
    ),
    (
        "compare_heyoka.py",
        r"batch 1000: .*?: ([0-9.]+x) faster excluding",
        "fastest as-accurate run vs heyoka at tol = eps, 1000 states, one thread",
    ),
    (
        "theta_compare.py",
        r"goals, one core:\s+>= 1000x flint: ([0-9.]+x)",
        "theta_all vs python-flint `acb_mat.theta`, one core",
    ),
    (
        "tori_compare.py",
        r"ratio \(integration \+ NAFF\) / theta: ([0-9.,]+x)",
        "frequencies vs gauss16 + NAFF, one core",
    ),
)

SIMD_FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512vl")


def _cmd_output(cmd: list[str]) -> str:
    try:
        return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "not available"


def _version(module: str) -> str:
    from importlib import metadata

    try:
        return metadata.version(module)
    except metadata.PackageNotFoundError:
        return "not installed"


def machine() -> dict[str, str]:
    """The machine and the software the figures come from."""
    model, flags = platform.processor() or "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name") and model in ("unknown", "", "x86_64"):
                model = line.split(":", 1)[1].strip()
            if line.startswith("flags"):
                flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    simd = ", ".join(f for f in SIMD_FLAGS if f in flags) or "none reported"
    return {
        "CPU": model,
        "SIMD features": simd,
        "cores (os.cpu_count)": str(os.cpu_count()),
        "OS": f"{platform.system()} {platform.release()}",
        "Python": platform.python_version(),
        "manakov": _version("manakov"),
        "numpy": _version("numpy"),
        "scipy": _version("scipy"),
        "python-flint": _version("python-flint"),
        "heyoka": _version("heyoka"),
        "rustc": _cmd_output(["rustc", "--version"]),
    }


def load() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "not available"


def _fmt_time(ns: float) -> str:
    for unit, scale in (("s", 1e9), ("ms", 1e6), ("µs", 1e3)):
        if ns >= scale:
            return f"{ns / scale:.3g} {unit}"
    return f"{ns:.3g} ns"


def run_criterion(bench: str, since: float) -> list[dict]:
    """Run one criterion bench file; return its results (medians) from criterion's JSON."""
    print(f"cargo bench --bench {bench}", flush=True)
    subprocess.run(
        ["cargo", "bench", "--quiet", "--bench", bench, "--", *CRITERION_ARGS],
        cwd=ROOT,
        check=True,
        stdout=subprocess.DEVNULL,
    )
    rows = []
    for meta in sorted((ROOT / "target" / "criterion").glob("**/new/benchmark.json")):
        if meta.stat().st_mtime < since:
            continue  # an older run of another bench
        info = json.loads(meta.read_text())
        est = json.loads((meta.parent / "estimates.json").read_text())
        median = float(est["median"]["point_estimate"])  # ns per iteration
        elements = (info.get("throughput") or {}).get("Elements")
        rows.append(
            {
                "bench": bench,
                "id": info["full_id"],
                "median_ns": median,
                "elements": int(elements) if elements else None,
            }
        )
    if not rows:
        raise SystemExit(f"cargo bench --bench {bench} wrote no criterion estimates")
    return rows


def run_comparison(script: str, args: tuple[str, ...]) -> tuple[str, float]:
    print(f"python benches/{script} {' '.join(args)}", flush=True)
    t0 = time.perf_counter()
    out = subprocess.run(
        [sys.executable, str(ROOT / "benches" / script), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return out.rstrip(), time.perf_counter() - t0


def _find(pattern: str, text: str, what: str) -> str:
    m = re.search(pattern, text, re.M)
    if m is None:
        raise SystemExit(f"could not read {what} from the output (pattern {pattern!r})")
    return m.group(1)


def summary(crit: list[dict], comp: dict[str, str], mach: dict[str, str], when: str) -> str:
    """The headline figures, each read from a row of the full tables."""
    by_id = {r["id"]: r for r in crit}

    def per(cid: str) -> str:
        r = by_id.get(cid)
        if r is None:
            return "not run"
        n = r["elements"] or 1
        return _fmt_time(r["median_ns"] / n)

    rows = [
        ("one evaluation of Frahm's equations (1), so(4)", per("rhs/so4_fast_path"), "criterion"),
        ("one gauss16 step", per("step/gauss/gauss16"), "criterion"),
        ("the 16 genus-2 theta values at one point", per("theta_g2_one_point/all16"), "criterion"),
        ("genus-2 period matrix (degree 5)", per("riemann/period_matrix_deg5/20"), "criterion"),
        ("Theorem set-up, `top.solve`", per("solution/setup_generic"), "criterion"),
        ("frequencies of one state (frequency map)", per("tori/state_frequencies/64"), "criterion"),
    ]
    # A figure of a bench that did not run (--skip-criterion) is left out, and
    # the header says so, rather than a row reading "not run".
    rows = [r for r in rows if r[1] != "not run"]
    for script, pattern, what in RATIOS:
        if script in comp:
            rows.append((what, f"{_find(pattern, comp[script], what)} faster", script))
    lines = [
        f"Measured {when} on {mach['CPU']} ({mach['cores (os.cpu_count)']} cores; "
        f"SIMD: {mach['SIMD features']}; load average {comp.get('_load', '?')}); "
        "short settings, one run: expect ±20 % on a shared machine."
        + ("" if crit else " The criterion benches of the Rust core were not run for this table."),
        "",
        "| what | time per item, or ratio | from |",
        "|---|---|---|",
    ]
    lines += [f"| {a} | {b} | `{c}` |" for a, b, c in rows]
    return "\n".join(lines) + "\n"


def full_page(crit, comp, times, mach, when, load_before, load_after) -> str:
    out = [
        "<!-- Written by benches/run_all.py; do not edit by hand. -->",
        "",
        "### The machine",
        "",
        "| | |",
        "|---|---|",
        f"| date (UTC) | {when} |",
    ]
    out += [f"| {k} | {v} |" for k, v in mach.items()]
    out += [
        f"| load average (1, 5, 15 min) before | {load_before} |",
        f"| load average (1, 5, 15 min) after | {load_after} |",
        "",
    ]
    if crit:
        out += [
            "### Criterion benches (Rust core, one thread unless the bench says otherwise)",
            "",
            "`cargo bench --bench <name> -- " + " ".join(CRITERION_ARGS) + "`; medians.",
            "",
            "| bench | median per iteration | items per iteration | per item |",
            "|---|---|---|---|",
        ]
        for r in crit:
            n = r["elements"]
            per = _fmt_time(r["median_ns"] / n) if n else "—"
            out.append(f"| `{r['id']}` | {_fmt_time(r['median_ns'])} | {n or '—'} | {per} |")
        out.append("")
    for script, args in COMPARISONS:
        if script not in comp:
            continue
        out += [
            f"### `python benches/{' '.join((script, *args))}`",
            "",
            f"Wall time of the script: {times[script]:.0f} s.",
            "",
            "```text",
            comp[script],
            "```",
            "",
        ]
    return "\n".join(out)


def update_readme(text: str) -> None:
    readme = README.read_text(encoding="utf-8")
    if BEGIN not in readme or END not in readme:
        raise SystemExit(f"README.md has no {BEGIN!r} ... {END!r} block")
    head, rest = readme.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    README.write_text(f"{head}{BEGIN}\n{text}{END}{tail}", encoding="utf-8")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--skip-criterion", action="store_true")
    ap.add_argument("--skip-python", action="store_true")
    ap.add_argument("--update-readme", action="store_true")
    args = ap.parse_args()

    when = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M")
    mach, load_before = machine(), load()
    since = time.time() - 1.0
    crit: list[dict] = []
    if not args.skip_criterion:
        for bench in CRITERION:
            crit += run_criterion(bench, since)
            since = time.time() - 1.0
    comp: dict[str, str] = {}
    times: dict[str, float] = {}
    if not args.skip_python:
        for script, sargs in COMPARISONS:
            comp[script], times[script] = run_comparison(script, sargs)
    load_after = load()
    comp["_load"] = f"{load_before.split(',')[0]} before, {load_after.split(',')[0]} after"

    OUT.mkdir(parents=True, exist_ok=True)
    page = full_page(crit, comp, times, mach, when, load_before, load_after)
    (OUT / "benchmarks.md").write_text(page + "\n", encoding="utf-8")
    summ = summary(crit, comp, mach, when)
    (OUT / "benchmarks_summary.md").write_text(summ, encoding="utf-8")
    print(summ)
    if args.update_readme:
        update_readme(summ)


if __name__ == "__main__":
    main()
