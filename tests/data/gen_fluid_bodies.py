"""Writes python/manakov/data/fluid_bodies.json: the reference bodies in an ideal fluid.

Four Clebsch bodies (``C_i = κ + θ A_j A_k``, Clebsch's condition to rounding;
the values are the doubles of that formula, written with 17 digits so the file
holds them exactly), one of them near the degenerate case ``C1 = C2``, and one
body of each other case for the command line. Run from the repository root:

    python tests/data/gen_fluid_bodies.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parents[2] / "python" / "manakov" / "data" / "fluid_bodies.json"


def clebsch_c(A, theta, kappa):
    A = [float(x) for x in A]
    return [kappa + theta * A[1] * A[2], kappa + theta * A[2] * A[0], kappa + theta * A[0] * A[1]]


def main() -> None:
    bodies = {
        "clebsch_generic": {
            "case": "clebsch",
            "A": [0.7, 1.3, 2.2],
            "C": clebsch_c([0.7, 1.3, 2.2], 0.6, 1.5),
            "M0": [0.4, -0.7, 0.9],
            "p0": [0.8, 0.3, -0.5],
            "note": "generic Clebsch body: C_i = 1.5 + 0.6 A_j A_k",
        },
        "clebsch_wide": {
            "case": "clebsch",
            "A": [0.05, 1.0, 20.0],
            "C": clebsch_c([0.05, 1.0, 20.0], 0.3, 7.0),
            "M0": [1.0, 0.5, -0.25],
            "p0": [0.75, -1.5, 0.1],
            "note": "A spread over two and a half decades: C_i = 7 + 0.3 A_j A_k",
        },
        "clebsch_isotropic": {
            "case": "clebsch",
            "A": [1.0, 1.0, 1.0],
            "C": [1.0, 2.5, 4.0],
            "M0": [0.5, 0.5, 0.5],
            "p0": [1.0, -0.5, 0.2],
            "note": "equal A_i: Clebsch's condition holds for every C (a_i = -C_i/A)",
        },
        "clebsch_near_degenerate": {
            "case": "clebsch",
            "A": [1.0, 1.000001, 2.0],
            "C": clebsch_c([1.0, 1.000001, 2.0], 0.8, 0.5),
            "M0": [0.6, -0.9, 0.4],
            "p0": [0.2, 1.1, -0.3],
            "note": "A1 close to A2, so C1 - C2 = 1.6e-6: near Kirchhoff's axisymmetric case, "
            "where the genus-2 curve degenerates",
        },
        "kirchhoff": {
            "case": "kirchhoff",
            "A": [1.0, 0.6],
            "B": [0.3, -0.2],
            "C": [1.4, 2.1],
            "M0": [0.5, -0.4, 0.8],
            "p0": [0.9, 0.2, -0.6],
            "note": "a body symmetric about its third axis (Kirchhoff's case, integral M3)",
        },
        "lyapunov_steklov": {
            "case": "lyapunov_steklov",
            "b": [0.7, 1.3, 2.1],
            "eps": 0.37,
            "kappa": 2.0,
            "M0": [0.4, -0.7, 0.9],
            "p0": [0.8, 0.3, -0.5],
            "note": "Lyapunov-Steklov case; the Casimir term kappa = 2 makes the energy positive",
        },
        "general": {
            "case": "general",
            "A": [[1.2, 0.1, -0.2], [0.1, 0.9, 0.15], [-0.2, 0.15, 1.6]],
            "B": [[0.2, -0.1, 0.05], [0.3, -0.15, 0.1], [0.0, 0.2, 0.1]],
            "C": [[2.0, 0.3, 0.1], [0.3, 1.5, -0.2], [0.1, -0.2, 2.5]],
            "M0": [0.4, -0.7, 0.9],
            "p0": [0.8, 0.3, -0.5],
            "note": "a general body (no symmetry, no known extra integral): chaotic motion",
        },
    }
    data = {
        "about": (
            "Reference bodies in an ideal fluid. H = 1/2 (M^T A M + 2 M^T B p + p^T C p); "
            "Kirchhoff's equations dM/dt = M x dH/dM + p x dH/dp, dp/dt = p x dH/dM. "
            "Clebsch bodies list the diagonals A_i, C_i (B = 0); Kirchhoff's lists "
            "(axes 1 and 2, axis 3) of A, B, C; Lyapunov-Steklov's its b, eps and the "
            "Casimir term kappa (C + kappa I). Written by tests/data/gen_fluid_bodies.py."
        ),
        "bodies": bodies,
    }
    for b in bodies.values():
        for key in ("A", "B", "C"):
            if key in b:
                b[key] = np.asarray(b[key], dtype=float).tolist()
    # One line per field, like problems.json (json.dumps writes every number on
    # a line of its own with indent=2).
    lines = ["{", f'  "about": {json.dumps(data["about"])},', '  "bodies": {']
    names = list(bodies)
    for n, name in enumerate(names):
        fields = [f'      "{k}": {json.dumps(v)}' for k, v in bodies[name].items()]
        close = "    }" + ("," if n + 1 < len(names) else "")
        lines += [f'    "{name}": {{', ",\n".join(fields), close]
    lines += ["  }", "}"]
    text = "\n".join(lines) + "\n"
    assert json.loads(text) == data
    OUT.write_text(text)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
