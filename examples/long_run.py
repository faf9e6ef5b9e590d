"""Integrate the 'generic' top for a long time and watch the integrals.

Gauss-Legendre collocation conserves every quadratic invariant of (1)-(2) up to
roundoff: the relative drift of H0..H3 and H stays near machine precision.

    python examples/long_run.py [t_end]
"""

import sys

import manakov

t_end = float(sys.argv[1]) if len(sys.argv) > 1 else 1e5
p = manakov.problem("generic")
top = manakov.ManakovTop(p.a, p.b)
tr = top.integrate(p.l0, t_end, sample_every=t_end / 1000)
print(f"t_end = {t_end:g}, method {tr.method}, dt = {tr.dt:.4g}, {tr.steps} steps")
for name, drift in tr.max_drift().items():
    print(f"  max relative drift of {name:>2}: {drift:.2e}")
