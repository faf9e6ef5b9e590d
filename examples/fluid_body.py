"""A rigid body moving in an ideal fluid: the Clebsch case in theta functions.

For a reference Clebsch body (default ``clebsch_generic``): ``M(t), p(t)`` from the
genus-2 theta functions against gauss16 integration on [0, 100] (a PNG of both and
their difference), the frequencies of the torus, and the body's motion in space —
the path of its origin and its axes, with the impulse ``P = R p`` and its moment
``K = R M + x × P``, which stay constant (a second PNG).

    python examples/fluid_body.py [body] [t_end_in_space]
"""

import sys

import numpy as np

import manakov
from manakov.fluid import plot_clebsch_theorem, plot_motion

name = sys.argv[1] if len(sys.argv) > 1 else "clebsch_generic"
t_space = float(sys.argv[2]) if len(sys.argv) > 2 else 60.0
pr = manakov.fluid_problem(name)
print(f"{name}: {pr.note}")
print(f"A = {np.diag(pr.body.A)}, C = {np.diag(pr.body.C)}")
print(f"conjugate Manakov top: a = {pr.body.conjugate_top.a}, b = {pr.body.conjugate_top.b}")

sol = pr.body.solve(pr.M0, pr.p0)
print(f"{sol!r}")
print(f"frequencies nu = {sol.frequencies}, rotation number {sol.rotation_number:.10f}")
err = plot_clebsch_theorem(name, f"{name}_theorem.png")
print(f"wrote {name}_theorem.png; max |y_theta - y_int| / max|y0| on [0, 100]: {err:.2e}")

tr = plot_motion(pr.body, pr.M0, pr.p0, f"{name}_in_space.png", t_end=t_space)
P, K = tr.impulse(), tr.moment()
dP = float(np.max(np.abs(P - P[0])) / np.max(np.abs(P[0])))
dK = float(np.max(np.abs(K - K[0])) / np.max(np.abs(K[0])))
print(f"wrote {name}_in_space.png; the origin moved {np.linalg.norm(tr.x[-1] - tr.x[0]):.3f}")
print(f"impulse drift: {dP:.2e}; moment drift: {dK:.2e}")
