# ruff: noqa: E741
"""Reference state at t = 100 of the 'generic' top with every c_ij shifted by +100.

The flow (1) depends on c only through differences c_kj - c_ik, so adding the same
constant to every c_ij does not change it (omega -> omega + k l, [l, l] = 0). But
c_ij + 100 rounded to a double is not c_ij + 100: the shifted doubles are a slightly
different top (|delta c| ~ 7e-15). An integrator can only be asked to follow the
top it is given, so the reference here is the exact flow of the shifted doubles.

Independent of the package: c from (2) in plain Python floats (the same IEEE
operations the package performs: (b_i - b_j) / (a_i - a_j)), shifted by 100.0 in
floats, then converted exactly to mpmath and integrated with mpmath's Taylor
solver (``mpmath.odefun``) at 38 digits; a 30-digit run must agree to 1e-24.

Run from the repository root (a few minutes):
    python tests/data/gen_reference_shifted.py
writes tests/data/reference_generic_shifted.json.
"""

from __future__ import annotations

import json
import pathlib

import mpmath as mp

ROOT = pathlib.Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "python" / "manakov" / "data" / "problems.json"
OUT = pathlib.Path(__file__).resolve().parent / "reference_generic_shifted.json"
PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
SHIFT = 100.0
T = 100


def shifted_c() -> dict[tuple[int, int], float]:
    top = json.loads(PROBLEMS.read_text())["tops"]["generic"]
    a = [float(x) for x in top["a"]]
    b = [float(x) for x in top["b"]]
    return {
        (i, j): (b[i] - b[j]) / (a[i] - a[j]) + SHIFT for i in range(4) for j in range(4) if i != j
    }


def solve(dps: int) -> list:
    mp.mp.dps = dps
    top = json.loads(PROBLEMS.read_text())["tops"]["generic"]
    l0 = [mp.mpf(float(x)) for x in top["l0"]]
    c = {k: mp.mpf(v) for k, v in shifted_c().items()}

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
                lik, lkj = entry(l, i, k), entry(l, k, j)
                s += lik * c[(k, j)] * lkj - c[(i, k)] * lik * lkj
            out.append(s)
        return out

    return mp.odefun(rhs, 0, l0)(T)


def main() -> None:
    lo = solve(30)
    hi = solve(38)
    diff = max(abs(x - y) for x, y in zip(lo, hi))
    assert diff < mp.mpf("1e-24"), diff
    data = {
        "about": f"generic top with c_ij + {SHIFT} rounded to doubles, state at t = {T} "
        f"from mpmath.odefun at 38 digits (30-digit run agrees to {mp.nstr(diff, 3)}); "
        f"generator: {pathlib.Path(__file__).name}",
        "c_shifted": {f"{i}{j}": v for (i, j), v in shifted_c().items() if i < j},
        "state": [mp.nstr(x, 30) for x in hi],
    }
    OUT.write_text(json.dumps(data, indent=1) + "\n")
    print(f"wrote {OUT}; agreement {mp.nstr(diff, 3)}")


if __name__ == "__main__":
    main()
