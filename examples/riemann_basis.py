"""Picture of the homology basis of a genus-2 curve with complex branch points.

Draws the branch points, the spanning tree of segments whose loops c_1..c_4
generate the homology (each loop runs along its segment on one sheet and back
on the other), and prints the canonical basis (a_i, b_i) = M (c_j), the
intersection matrix and the period matrix tau, with its asymmetry (the claim
checked by tests/test_examples.py). Writes docs/riemann_basis.png by default.

Run:  python examples/riemann_basis.py [--out FILE]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import manakov

#: The curve drawn in docs/riemann.md: the curve (8) of a top with complex d_j.
D = (0.9 + 0.7j, -1.3 + 0.4j, 0.5 - 1.1j)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(Path(__file__).parents[1] / "docs" / "riemann_basis.png"))
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()

    h = manakov.KotterCurve(*D).surface
    e = h.branch_points
    a, b = h.periods
    tau_raw = np.linalg.solve(a, b)
    asym = np.max(np.abs(tau_raw - tau_raw.T)) / np.max(np.abs(tau_raw))
    print("branch points d_0..d_4:", np.round(e, 4))
    print("tree loops c_j (edges):", [tuple(int(v) for v in ed) for ed in h.cycle_edges])
    print("intersection matrix C = (c_i . c_j):\n", h.intersection_matrix)
    print("M, rows a1 a2 b1 b2 in terms of c_j:\n", h.symplectic_basis)
    print("tau:\n", np.round(h.tau, 6))
    print("eta(d_j) rows [a|b] (last: infinity):\n", h.branch_chars)
    print("K = [a|b]:", np.concatenate(h.riemann_constant_char))
    print(f"tau asymmetry (relative): {asym:.2e}")
    if args.no_plot:
        return

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 6))
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for j, (p, q) in enumerate(h.cycle_edges):
        z0, z1 = e[p], e[q]
        mid, half = (z0 + z1) / 2, (z1 - z0) / 2
        t = np.linspace(0, 2 * np.pi, 200)
        # A thin loop around the segment: the lift runs on one sheet along
        # the upper side and returns on the other sheet.
        loop = mid + half * (1.08 * np.cos(t) + 0.12j * np.sin(t))
        ax.plot(loop.real, loop.imag, color=colours[j], lw=1.5)
        ax.plot([z0.real, z1.real], [z0.imag, z1.imag], color=colours[j], lw=0.8, ls="--")
        ax.annotate(
            f"$c_{j + 1}$",
            (mid.real, mid.imag),
            textcoords="offset points",
            xytext=(6, 6),
            color=colours[j],
            fontsize=13,
        )
        arrow = mid + half * (0.0 + 0.12j)
        ax.annotate(
            "",
            xy=(arrow.real + 0.05 * half.real, arrow.imag + 0.05 * half.imag),
            xytext=(arrow.real, arrow.imag),
            arrowprops={"arrowstyle": "->", "color": colours[j]},
        )
    ax.plot(e.real, e.imag, "ko")
    for k, z in enumerate(e):
        ax.annotate(f"$d_{k}$", (z.real, z.imag), textcoords="offset points", xytext=(-14, -14))
    m = h.symplectic_basis
    names = ["a_1", "a_2", "b_1", "b_2"]
    rows = []
    for i in range(4):
        terms = [
            f"{'+' if c > 0 else '-'}{'' if abs(c) == 1 else abs(c)}c_{j + 1}"
            for j, c in enumerate(m[i])
            if c
        ]
        rows.append(f"${names[i]} = {' '.join(terms).lstrip('+')}$")
    ax.set_title(
        "Curve (8), d = " + ", ".join(f"{d:.1f}" for d in D) + "\n" + ",   ".join(rows),
        fontsize=10,
    )
    ax.set_aspect("equal")
    ax.set_xlabel("Re x")
    ax.set_ylabel("Im x")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
