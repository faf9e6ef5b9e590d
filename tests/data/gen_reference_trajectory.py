# ruff: noqa: E741
"""Reference states of the shared 'generic' top at t = 10 and t = 100, at 38 digits.

Independent of the package: the vector field (1) with c from (2) is written
here in mpmath, and integrated with mpmath's Taylor-series ODE solver
(``mpmath.odefun``) at 38 significant digits; a second run at 30 digits must
agree to 1e-24, which bounds the error of the stored values.

Run from the repository root (takes a few minutes):
    python tests/data/gen_reference_trajectory.py
writes tests/data/reference_generic.json.
"""

from __future__ import annotations

import json
import pathlib

import mpmath as mp

ROOT = pathlib.Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "python" / "manakov" / "data" / "problems.json"
OUT = pathlib.Path(__file__).resolve().parent / "reference_generic.json"
PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
TIMES = (10, 100)


def solve(dps: int) -> dict[int, list]:
    mp.mp.dps = dps
    top = json.loads(PROBLEMS.read_text())["tops"]["generic"]
    # The decimal inputs are rounded to doubles first: the package sees doubles.
    a = [mp.mpf(float(x)) for x in top["a"]]
    b = [mp.mpf(float(x)) for x in top["b"]]
    l0 = [mp.mpf(float(x)) for x in top["l0"]]
    c = {(i, j): (b[i] - b[j]) / (a[i] - a[j]) for i in range(4) for j in range(4) if i != j}

    def entry(l, i, k):
        if i == k:
            return mp.mpf(0)
        return l[PAIRS.index((i, k))] if i < k else -l[PAIRS.index((k, i))]

    def rhs(t, l):
        out = []
        for i, j in PAIRS:
            s = mp.mpf(0)
            for k in range(4):
                if k in (i, j):
                    continue
                # (1): l_ik w_kj - w_ik l_kj with w = c l
                lik, lkj = entry(l, i, k), entry(l, k, j)
                s += lik * c[(k, j)] * lkj - c[(i, k)] * lik * lkj
            out.append(s)
        return out

    f = mp.odefun(rhs, 0, l0)
    return {t: f(t) for t in TIMES}


def main() -> None:
    lo = solve(30)
    hi = solve(38)
    diff = max(abs(x - y) for t in TIMES for x, y in zip(lo[t], hi[t]))
    assert diff < mp.mpf("1e-24"), diff
    data = {
        "about": "generic top, states at t = 10 and t = 100 from mpmath.odefun at 38 digits "
        f"(30-digit run agrees to {mp.nstr(diff, 3)}); generator: {pathlib.Path(__file__).name}",
        "states": {str(t): [mp.nstr(x, 30) for x in hi[t]] for t in TIMES},
    }
    OUT.write_text(json.dumps(data, indent=1) + "\n")
    print(f"wrote {OUT}; agreement {mp.nstr(diff, 3)}")


if __name__ == "__main__":
    main()
