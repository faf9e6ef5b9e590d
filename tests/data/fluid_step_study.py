"""The default gauss16 step of Kirchhoff's equations (``DT_SCALE`` in manakov.fluid).

For steps ``s/Ω`` (``Ω = ‖Q'‖₂ |y0|``, ``KirchhoffBody.rate_scale``), the error
against gauss16 at a tenth of the smallest step, relative to ``max|y|``, and the
stage sweeps per step, on 8 random dense bodies (``Q = GGᵀ/2 + I/2``, seed 3)
at t = 2 (their motion is chaotic: at t = 20 rounding is amplified to O(1) on
half of them) and on the seven reference bodies at t = 20:

    python tests/data/fluid_step_study.py
"""

from __future__ import annotations

import numpy as np

import manakov

SCALES = (0.5, 0.75, 1.0, 1.5, 2.0)
T_RANDOM, T = 2.0, 20.0


def random_body(rng):
    g = rng.normal(size=(6, 6))
    q = 0.5 * g @ g.T + 0.5 * np.eye(6)
    return manakov.KirchhoffBody(q[:3, :3], q[:3, 3:], q[3:, 3:])


def main() -> None:
    rng = np.random.default_rng(3)
    cases = [
        (f"random {i} (t = 2)", random_body(rng), rng.normal(size=3), rng.normal(size=3), T_RANDOM)
        for i in range(8)
    ]
    for name in manakov.fluid_problem_names():
        pr = manakov.fluid_problem(name)
        cases.append((name, pr.body, pr.M0, pr.p0, T))
    print(f"{'body':26s}" + "".join(f"{f's={s:g}':>18s}" for s in SCALES))
    worst = dict.fromkeys(SCALES, 0.0)
    for name, body, M0, p0, T_end in cases:
        om = 1.0 / body.time_scale(M0, p0)
        ref = body.integrate(M0, p0, T_end, t_eval=[T_end], dt=min(SCALES) / om / 10)
        yr = np.r_[ref.M[-1], ref.p[-1]]
        cells = []
        for s in SCALES:
            tr = body.integrate(M0, p0, T_end, t_eval=[T_end], dt=s / om)
            e = np.max(np.abs(np.r_[tr.M[-1], tr.p[-1]] - yr)) / np.max(np.abs(yr))
            worst[s] = max(worst[s], e)
            cells.append(f"{e:9.1e} ({tr.evals / tr.steps / 8:4.1f})")
        print(f"{name:26s}" + "".join(f"{c:>18s}" for c in cells))
    print("worst" + " " * 21 + "".join(f"{worst[s]:18.1e}" for s in SCALES))
    print("(error at the end time; in parentheses: stage sweeps per step)")


if __name__ == "__main__":
    main()
