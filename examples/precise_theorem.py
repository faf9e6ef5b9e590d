"""The Theorem (9)-(10) evaluated to the last bit: ``sol.l(t, precise=True)``.

The double evaluation of the theta quotients is a few units of rounding off from
t = 0 on (its constants are); the precise one polishes the constants in
double-double and sums the thetas in double-double. This script evaluates both on
[0, t_end], prints the largest difference and whether l(0) is l0 to the bit, and
plots the difference per component on a log scale (it is the double evaluation's
error: the precise one is within half an ulp of a long-double reference,
docs/theorem.md).

    python examples/precise_theorem.py [problem] [out.png] [t_end]
"""

import sys

import numpy as np

import manakov

name = sys.argv[1] if len(sys.argv) > 1 else "wide"
path = sys.argv[2] if len(sys.argv) > 2 else "precise-theorem.png"
t_end = float(sys.argv[3]) if len(sys.argv) > 3 else 100.0

p = manakov.problem(name)
l0 = np.asarray(p.l0, dtype=float)
sol = manakov.ManakovTop(p.a, p.b).solve(l0)
t = np.linspace(0.0, t_end, 201)
precise = sol.l(t, precise=True)
double = sol.l(t)
diff = np.abs(double - precise) / np.linalg.norm(l0)
residual, correction = sol.precise_residual
print(f"{name}: polished constants leave a residual {residual:.1e} (moved by {correction:.1e})")
print(f"l(0) == l0 to the bit: {bool(np.all(precise[0] == l0))}")
print(f"precise vs double on [0, {t_end:g}]: {diff.max():.2e}")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:  # the plot is optional
    sys.exit(0)
fig, ax = plt.subplots(figsize=(7, 3.5))
labels = ["l12", "l13", "l14", "l23", "l24", "l34"]
shown = np.where(diff > 0, diff, np.nan)  # equal values (a difference of 0) not drawn
for q in range(6):
    ax.semilogy(t, shown[:, q], ".", ms=3, label=labels[q])
ax.axhline(np.finfo(float).eps / 2, color="k", lw=0.8, ls="--", label="u = 2^-53")
ax.set_xlabel("t")
ax.set_ylabel("|l_double - l_precise| / |l0|")
ax.set_title(f"'{name}': the double evaluation of the Theorem against the precise one")
ax.legend(ncol=4, fontsize=7)
fig.tight_layout()
fig.savefig(path, dpi=120)
print(f"wrote {path}")
