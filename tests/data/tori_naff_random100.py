"""Issue 13, Must-show: the Theorem's frequencies against integration + NAFF on
100 random states.

Random a (sorted uniform in [0, 5]), b (normal), l0 (normal), seed 1313 (the
tests use other seeds), the draw of tests/data/theorem_random_stats.py. For
each state: (ν1, ν2) from ``manakov.frequency_map`` (the level-set route: no
theta function, no Abel map of the state), and for comparison
``sol.frequencies`` of ``solve`` (the theta route); Frahm's equations (1)
integrated with gauss16 for RUN_PERIODS slow periods; the test-side NAFF on all six
components (tests/tori_naff.py, tests/naff.py). Per state it records the worst
relative line error (every line ≥ 1e-6 of its component's largest must be
k1 ν1 + k2 ν2, |k| ≤ 20, to 1e-8 of max ν) and whether the k's span Z². As a
cross-check of the Theorem side it also records max over t in [0, 20] of
|sol.l(t) − l_int(t)| / |l0| (gauss16, dt = 2e-3). States on which ``solve``
raises its documented singular ValueError are counted by reason, and so are
states whose torus (``sol.frequencies``) refuses: then the script records how
far ``sol.l`` is from the integration.

Run (minutes to an hour; niced, in the background):
    nohup nice -n 15 python tests/data/tori_naff_random100.py [N] > /tmp/naff100.log &
Writes tests/data/tori_naff_random100.txt (one row per state as it goes, then
the summary). ``--diagnose I ...`` reruns failing states with 2× and 4× longer
windows and appends the result.
"""

from __future__ import annotations

import pathlib
import sys
import time
from collections import Counter

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from tori_naff import LINE_RTOL, PERIODS, check_lines  # noqa: E402

import manakov  # noqa: E402

SEED = 1313
# 2000 slow periods (the issue asks >= 500): at 1000, state 70's line
# 4 nu1 - 5 nu2 (amplitude 4e-6, ~5 cycles in the window) was resolved by the
# NAFF only to 1.5e-8; at 2000 and 4000 periods it fits to 1.5e-10 and 2.8e-12
# (the --diagnose rows of the previous run), i.e. the miss was the window's.
RUN_PERIODS = 2 * PERIODS
OUT = pathlib.Path(__file__).with_suffix(".txt")
COMPONENTS = (0, 1, 2, 3, 4, 5)


def theorem_error(top, sol, l0) -> float:
    t = np.linspace(0.0, 20.0, 41)
    l_int = top.integrate(l0, 20.0, t_eval=t, dt=2e-3).l
    return float(np.max(np.abs(sol.l(t) - l_int)) / np.linalg.norm(l0))


def main(n: int = 100) -> None:
    raised: Counter[str] = Counter()
    refused: Counter[str] = Counter()
    rows = []
    start = time.perf_counter()
    with OUT.open("w") as f:
        f.write(
            "# i  nu1  nu2  worst_line_rtol  generators  lines  samples  theorem_err  "
            "map_vs_solve  worst_line(component, nu, amp, k)  seconds\n"
        )
        for i, (a, b, l0) in enumerate(draw(n)):
            top = manakov.ManakovTop(a, b)
            t0 = time.perf_counter()
            fm = manakov.frequency_map(top, l0)
            if int(fm.status) != manakov.tori.OK:
                name = manakov.tori.STATUS_NAMES[int(fm.status)]
                refused[name] += 1
                f.write(f"{i:3d}  frequency_map status {int(fm.status)} ({name})\n")
                f.flush()
                continue
            nu = np.asarray(fm.nu)
            try:
                sol = top.solve(l0)
            except (ValueError, manakov.ClosedFormError) as e:
                raised[str(e)[:70]] += 1
                f.write(f"{i:3d}  solve raised: {e}\n")
                f.flush()
                continue
            routes = float(np.max(np.abs(nu - sol.frequencies)) / np.max(nu))
            res = check_lines(top, l0, nu, COMPONENTS, periods=RUN_PERIODS)
            terr = theorem_error(top, sol, l0)
            dt = time.perf_counter() - t0
            wl = res.worst_line
            rows.append((res.worst, res.generated, terr, i, routes))
            f.write(
                f"{i:3d}  {nu[0]:.15g}  {nu[1]:.15g}  {res.worst:.2e}  {res.generated}  "
                f"{len(res.lines)}  {res.samples}  {terr:.1e}  {routes:.1e}  "
                f"({wl[0]}, {wl[1]:.15g}, {wl[2]:.1e}, {wl[3]})  {dt:.0f}\n"
            )
            f.flush()
            print(i, f"{res.worst:.1e}", res.generated, f"{dt:.0f}s", flush=True)
        worst = np.array([r[0] for r in rows])
        gens = np.array([r[1] for r in rows])
        terr = np.array([r[2] for r in rows])
        routes = np.array([r[4] for r in rows])
        bad = np.flatnonzero((worst > LINE_RTOL) | ~gens)
        summary = [
            f"# states: {n} (seed {SEED}), solved: {len(rows)}, raised: {sum(raised.values())}",
            f"#   raised by reason: {dict(raised)}",
            f"# frequency_map status not ok: {sum(refused.values())} {dict(refused)}",
            f"# NAFF: {RUN_PERIODS} slow periods, components {COMPONENTS}, all lines >= 1e-6",
            f"# worst line error (rel. to max nu): median {np.median(worst):.1e}, "
            f"max {worst.max():.1e}; <= {LINE_RTOL:g}: {np.sum(worst <= LINE_RTOL)}/{len(rows)}",
            f"# both generators present: {int(gens.sum())}/{len(rows)}",
            f"# theorem vs gauss16 on [0, 20]: median {np.median(terr):.1e}, max {terr.max():.1e}",
            f"# frequency_map vs sol.frequencies (rel.): median {np.median(routes):.1e}, "
            f"max {routes.max():.1e}",
            f"# failing states: {[rows[j][3] for j in bad]}",
            f"# wall time: {time.perf_counter() - start:.0f} s",
        ]
        f.write("\n".join(summary) + "\n")
    print("\n".join(summary))


def draw(n: int):
    rng = np.random.default_rng(SEED)
    for _ in range(n):
        a = np.sort(rng.uniform(0.0, 5.0, 4))
        b = rng.normal(size=4)
        l0 = rng.normal(size=6)
        yield a, b, l0


def diagnose(states: list[int]) -> None:
    """A failing state again with longer windows: if its worst line converges
    to k·ν as the window grows, the 1e-8 miss was the NAFF's (a weak line with
    few cycles in the window), not the Theorem's. Appends to the .txt."""
    all_states = list(draw(max(states) + 1))
    with OUT.open("a") as f:
        for i in states:
            a, b, l0 = all_states[i]
            top = manakov.ManakovTop(a, b)
            nu = np.asarray(manakov.frequency_map(top, l0).nu)
            parts = []
            for periods in (RUN_PERIODS, 2 * RUN_PERIODS):
                res = check_lines(top, l0, nu, COMPONENTS, periods=periods)
                parts.append(f"{periods} periods {res.worst:.1e} at k = {res.worst_line[3]}")
            line = f"# diagnosis of state {i}: worst line error at " + "; ".join(parts)
            f.write(line + "\n")
            print(line)


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--diagnose":
        diagnose([int(v) for v in sys.argv[2:]])
    else:
        main(int(sys.argv[1]) if len(sys.argv) > 1 else 100)
