"""A frequency map: the rotation number ν1/ν2 over a slice of initial states.

Every state of the slice has the Casimirs h0, h1 of the problem's l0 (the
direction of p = m + n moves over its sphere, q = m - n stays); each gets the
frequencies of its real torus from the Theorem (docs/tori.md). Resonance lines
k1 ν1 + k2 ν2 = 0 are overlaid. Writes frequency_map_<problem>.png.

    python examples/frequency_map.py [problem] [grid]
"""

import sys
import time

import numpy as np

import manakov
from manakov import tori
from manakov.plots import plot_frequency_map

name = sys.argv[1] if len(sys.argv) > 1 else "generic"
grid = int(sys.argv[2]) if len(sys.argv) > 2 else 32
path = f"frequency_map_{name}.png"

start = time.perf_counter()
fm = plot_frequency_map(name, grid, path, progress=grid >= 128)
elapsed = time.perf_counter() - start
print(f"{name}: {grid}x{grid} states in {elapsed:.2f} s ({1e6 * elapsed / grid**2:.0f} us/state)")
print("status:", fm.counts())
print(f"wrote {path}")

# The map (level-set route: the velocities by the chain rule at auxiliary
# divisors) agrees with the solution objects of single states (theta route)
# to the accuracy of the reduction's constants.
p = manakov.problem(name)
top = manakov.ManakovTop(p.a, p.b)
_, _, states = tori.casimir_slice(p.l0, grid)
rng = np.random.default_rng(0)
worst = 0.0
for i, j in rng.integers(0, grid, (5, 2)):
    if fm.status[i, j] != tori.OK:
        continue
    nu = top.solve(states[i, j]).frequencies
    worst = max(worst, float(np.max(np.abs(fm.nu[i, j] - nu)) / np.max(nu)))
print(f"max relative difference map vs solve: {worst:.1e}")
