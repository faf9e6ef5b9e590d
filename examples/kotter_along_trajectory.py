"""Follow the Schottky-Kotter coordinates of a state along its trajectory.

The curve constants d_j are integrals of motion; the two points (z1, z2) move on
the curve (8); mapping them back gives l again.

    python examples/kotter_along_trajectory.py [problem]
"""

import sys

import numpy as np

import manakov

name = sys.argv[1] if len(sys.argv) > 1 else "generic"
p = manakov.problem(name)
top = manakov.ManakovTop(p.a, p.b)
tr = top.integrate(p.l0, 20.0, sample_every=0.5)
k = top.kotter(tr.l)  # a batch: every field gains the leading axis of tr.l
spread = np.max(np.abs(k.d - k.d[0]), axis=0) / np.max(np.abs(k.d[0]))
back = top.from_kotter(k)
print(f"{name}: d = {np.round(k.d[0], 6)}")
print(f"  spread of d_j along the trajectory (relative): {np.max(spread):.1e}")
print(f"  round trip l -> (z1, y1, z2, y2, g) -> l: {np.max(np.abs(back - tr.l)):.1e}")
print(f"  z1(t) for the first times: {np.round(k.z1[:3], 6)}")
