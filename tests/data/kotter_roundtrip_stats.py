"""Round-trip statistics quoted in docs/kotter.md.

Run: ``python tests/data/kotter_roundtrip_stats.py``. For each shared top,
integrates (1) with DOP853 (rtol = atol = 1e-13, the reference right-hand side of
``kotter_ref.py``) at 81 times on [0, 20], maps every state to Kötter coordinates
and back, and prints the relative round-trip error and the third-quadric residual.
"""

import sys
from pathlib import Path

import numpy as np

import manakov

sys.path.insert(0, str(Path(__file__).parent))
import kotter_ref as ref  # noqa: E402

T = np.linspace(0, 20, 81)
for name in manakov.problem_names():
    p = manakov.problem(name)
    X = ref.trajectory(p.a, p.b, p.l0, T)
    k = manakov.kotter(p.a, p.b, X)
    back = manakov.from_kotter(p.a, p.b, k)
    err = np.max(np.abs(back - X), axis=-1) / np.max(np.abs(X), axis=-1)
    q3 = np.max(np.abs(np.sum(k.d * k.xi**2 + k.eta**2 / k.d, -1)))
    print(
        f"{name:16s} max {err.max():.1e} median {np.median(err):.1e}  "
        f"|Q3| max {q3:.1e}  d = {np.round(k.d[0], 4)}"
    )
