"""Every real state, near each degenerate set: sweeps at distances 10^-1 ... 10^-16
and exactly 0, against the long-double reference.

For each of the four shared tops and a few random directions, states at relative
distance delta from:
- h0 = 0 (rank-2 states, Moser's case): a random simple bivector u ^ v plus
  delta |l| times a random unit state;
- m = +n and m = -n (self-dual, anti-self-dual: one so(3) factor at rest):
  n = +-m + delta |m| e with a random unit e;
- each so(3) block {1,2,3}, {1,2,4}, {1,3,4}, {2,3,4}: the three components outside
  the block set to delta |l| times a random unit vector;
- each single component (an eigen-rotation): the other five set to delta times a
  random unit vector.
Each state: the error of ``top.solve(l0).l(t)`` on [0, T], T = min(100, 1e3 x
time_scale) (as in every_state_harsh.py), against heyoka in long double, and the
bound max(1e-10, 10 x gauss16's error). Prints one line per family and distance:
how many solved within the bound, how many silently wrong (none may be), how many
refused (with the first reason), and how many of the returned ones came from the
confirmed integration that stands in for the closed form (``integrated``).

Run: python tests/data/every_state_sweeps.py [N_DIRECTIONS]   (default 3)
"""

from __future__ import annotations

import sys
import warnings
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).resolve().parent))
import longdouble_ref  # noqa: E402
from every_state_harsh import ABS_FLOOR, GAUSS_FACTOR, NUMBER, err, window  # noqa: E402

DISTANCES = [10.0**-k for k in range(1, 17)] + [0.0]
# so(3) blocks by the state indices (l12, l13, l14, l23, l24, l34) inside them
BLOCKS = {"123": [0, 1, 3], "124": [0, 2, 4], "134": [1, 2, 5], "234": [3, 4, 5]}
PAIRS = ["12", "13", "14", "23", "24", "34"]


def mn_to_l(m: np.ndarray, n: np.ndarray) -> np.ndarray:
    """(l12, l13, l14, l23, l24, l34) from m = (l23, l31, l12), n = (l14, l24, l34)."""
    return np.array([m[2], -m[1], n[0], m[0], n[1], n[2]])


def unit(rng: np.random.Generator, k: int) -> np.ndarray:
    v = rng.normal(size=k)
    return v / np.linalg.norm(v)


def families(rng: np.random.Generator):
    """(family, base direction data) -> a function of delta giving a state."""
    out = {}
    # a simple bivector u ^ v (rank 2, h0 = 0 exactly) plus delta |l| w
    u, v = rng.normal(size=4), rng.normal(size=4)
    wedge = np.array(
        [u[i] * v[j] - u[j] * v[i] for i, j in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]]
    )
    wedge /= np.linalg.norm(wedge)
    w = unit(rng, 6)

    def rank2(delta: float) -> np.ndarray:
        return wedge + delta * w

    out["h0=0"] = rank2
    m, e = unit(rng, 3), unit(rng, 3)
    out["m=+n"] = lambda d: mn_to_l(m, m + d * e)
    out["m=-n"] = lambda d: mn_to_l(m, -m + d * e)
    for name, idx in BLOCKS.items():
        inside = unit(rng, 3)
        outside = unit(rng, 3)

        def block(d: float, idx=idx, inside=inside, outside=outside) -> np.ndarray:
            v = np.zeros(6)
            v[idx] = inside
            rest = [q for q in range(6) if q not in idx]
            v[rest] = d * outside
            return v

        out["so3 " + name] = block
    for q, pq in enumerate(PAIRS):
        other = unit(rng, 5)

        def single(d: float, q=q, other=other) -> np.ndarray:
            v = np.zeros(6)
            v[q] = 1.0
            v[[r for r in range(6) if r != q]] = d * other
            return v

        out["l" + pq] = single
    return out


def main(n_dir: int = 3) -> None:
    rng = np.random.default_rng(20261126)
    stats: dict[tuple[str, float], Counter] = defaultdict(Counter)
    first_reason: dict[tuple[str, float], str] = {}
    worst: dict[tuple[str, float], float] = defaultdict(float)
    for name in manakov.problem_names():
        p = manakov.problem(name)
        top = manakov.ManakovTop(p.a, p.b)
        for _ in range(n_dir):
            for fam, make in families(rng).items():
                for d in DISTANCES:
                    l0 = make(d)
                    key = (fam, d)
                    t = window(top, l0)
                    norm = float(np.linalg.norm(l0))
                    ref = longdouble_ref.reference(p.a, p.b, l0, t)
                    g16 = err(top.integrate(l0, t[-1], t_eval=t).l, ref, norm)
                    bound = max(ABS_FLOOR, GAUSS_FACTOR * g16)
                    try:
                        sol = top.solve(l0)
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore", manakov.IntegratedValuesWarning)
                            e = err(sol.l(t), ref, norm)
                        if sol.integrated_calls:
                            stats[key]["integrated"] += 1
                    except Exception as ex:  # noqa: BLE001 - each refusal is recorded
                        stats[key]["refused"] += 1
                        first_reason.setdefault(
                            key, f"{type(ex).__name__}: {NUMBER.sub('#', str(ex))[:70]}"
                        )
                        continue
                    worst[key] = max(worst[key], e / bound)
                    stats[key]["solved" if e <= bound else "SILENTLY WRONG"] += 1
    fams = list(dict.fromkeys(k[0] for k in stats))
    total = Counter()
    for fam in fams:
        print(fam)
        for d in DISTANCES:
            c = stats[(fam, d)]
            total.update(c)
            line = f"  {d:7.0e}: solved {c['solved']:3d}, wrong {c['SILENTLY WRONG']:2d}, "
            line += f"refused {c['refused']:3d}  worst err/bound {worst[(fam, d)]:.1e}"
            if c["integrated"]:
                line += f"  (integrated: {c['integrated']})"
            if (fam, d) in first_reason:
                line += f"  [{first_reason[(fam, d)]}]"
            print(line)
    print("total:", dict(total))


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:2]))
