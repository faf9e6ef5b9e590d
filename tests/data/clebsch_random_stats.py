"""The Clebsch closed form against integration on random bodies and states.

1000 draws (seed 20261202; ``test_closed_form_on_random_states`` takes the
first 100): ``A_i ~ U(0.2, 2)``, ``θ ~ U(−1, 1)``, ``C_i = κ + θ A_j A_k`` with
``κ = |θ| max A_j A_k + U(0.2, 1)``
(so ``C > 0``), ``M, p`` standard normal. Error: ``max_t |y_theta − y_int| / max|y0|``
over 101 times in [0, T], ``y_int`` gauss16 at a quarter of the default step
(its own error ~1e-14 there); with the largest ``Solution.self_check`` and
``Solution.velocity_check`` of the conjugate top's solutions (a draw refused by
them or by the drift check of ``l(t)``, ``ClosedFormError``, is
counted as raised). Without arguments: T = 100 and T = 20, written to
``clebsch_random_stats.txt`` next to this file (about 4 s); with arguments
only printed:

    python tests/data/clebsch_random_stats.py [N [T]]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import manakov

SEED = 20261202


def draw(rng: np.random.Generator):
    A = rng.uniform(0.2, 2.0, size=3)
    theta = rng.uniform(-1.0, 1.0)
    prods = np.array([A[1] * A[2], A[2] * A[0], A[0] * A[1]])
    kappa = abs(theta) * prods.max() + rng.uniform(0.2, 1.0)
    C = kappa + theta * prods
    return A, C, rng.normal(size=3), rng.normal(size=3)


def error_and_check(
    A, C, M0, p0, T: float, samples: int = 101
) -> tuple[float, tuple[float, float]]:
    """The error on [0, T] and the conjugate top's ``Solution.self_check`` and
    ``Solution.velocity_check``."""
    body = manakov.KirchhoffBody.clebsch(A, C)
    sol = body.solve(M0, p0)
    t = np.linspace(0.0, T, samples)
    tr = body.integrate(M0, p0, T, t_eval=t, dt=body.default_dt(M0, p0) / 4)
    M, p = sol.state(t)
    scale = max(np.max(np.abs(M0)), np.max(np.abs(p0)))
    err = float(max(np.max(np.abs(M - tr.M)), np.max(np.abs(p - tr.p))) / scale)
    return err, (sol.solution.self_check, sol.solution.velocity_check)


def error(A, C, M0, p0, T: float, samples: int = 101) -> float:
    return error_and_check(A, C, M0, p0, T, samples)[0]


def run(n: int, T: float) -> str:
    rng = np.random.default_rng(SEED)
    errs, checks, failed = [], [], []
    t0 = time.perf_counter()
    for i in range(n):
        A, C, M0, p0 = draw(rng)
        try:
            err, check = error_and_check(A, C, M0, p0, T)
        except (ValueError, manakov.ClosedFormError) as e:
            failed.append((i, f"{type(e).__name__}: {str(e)[:160]}"))
            continue
        errs.append(err)
        checks.append(check)
    el = time.perf_counter() - t0
    e, c = np.array(errs), np.array(checks)
    lines = [
        f"{n} random Clebsch bodies and states (seed {SEED}), [0, {T:g}], 101 times; "
        f"error max_t |y_theta - y_int| / max|y0|",
        f"solved: {e.size}, raised: {len(failed)}",
        f"median {np.median(e):.2e}, 99% {np.quantile(e, 0.99):.2e}, "
        f"99.9% {np.quantile(e, 0.999):.2e}, max {e.max():.2e}",
        f"<= 1e-10: {np.mean(e <= 1e-10) * 100:.1f} % ({int(np.sum(e <= 1e-10))} of {n}); "
        f"<= 1e-12: {np.mean(e <= 1e-12) * 100:.1f} %",
        f"worst draws: {', '.join(str(int(i)) for i in np.argsort(e)[::-1][:5])}",
        f"self_check of the conjugate top's solution: median {np.median(c[:, 0]):.2e}, "
        f"max {c[:, 0].max():.2e} (refused above 1e-10 with ClosedFormError); "
        f"velocity_check: median {np.median(c[:, 1]):.2e}, max {c[:, 1].max():.2e} "
        f"(refused above 1e-6)",
        f"time {el:.1f} s",
    ]
    lines += [f"raised at draw {i}: {m}" for i, m in failed]
    return "\n".join(lines) + "\n"


def main() -> None:
    if len(sys.argv) > 1:
        n = int(sys.argv[1])
        T = float(sys.argv[2]) if len(sys.argv) > 2 else 100.0
        print(run(n, T), end="")
        return
    text = run(1000, 100.0) + "\n" + run(1000, 20.0)
    print(text, end="")
    (Path(__file__).parent / "clebsch_random_stats.txt").write_text(text)


if __name__ == "__main__":
    main()
