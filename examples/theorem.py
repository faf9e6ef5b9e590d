"""The Theorem (9)-(10): l(t) from theta functions against gauss16 integration.

Writes a PNG with l(t) from the theta quotients (lines) and from integration
(dots), and their difference on a log scale; prints the largest difference.

    python examples/theorem.py [problem] [out.png] [t_end]
"""

import sys

from manakov.plots import plot_theorem

name = sys.argv[1] if len(sys.argv) > 1 else "generic"
path = sys.argv[2] if len(sys.argv) > 2 else "theorem.png"
t_end = float(sys.argv[3]) if len(sys.argv) > 3 else 100.0
err = plot_theorem(name, path, t_end=t_end)
print(f"{name}: wrote {path}; max |l_theta - l_int| / |l0| on [0, {t_end:g}]: {err:.2e}")
