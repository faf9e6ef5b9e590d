"""Genus-2 theta functions: quasi-periodicity and parity, checked numerically.

python examples/theta_identities.py
"""

import numpy as np

import manakov

tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
z = np.array([0.21 + 0.05j, -0.37 + 0.11j])
th = manakov.theta_all(z, tau)  # 16 values, FLINT order (bits a1 a2 b1 b2)

# z -> z + tau n multiplies theta[a;b] by exp(-i pi n.tau.n - 2 pi i n.z) (-1)^{b.n}
n = np.array([1, -1])
shifted = manakov.theta_all(z + tau @ n, tau)
factor = np.exp(-1j * np.pi * n @ tau @ n - 2j * np.pi * n @ z)
chars = manakov.characteristics(2)
signs = np.array([(-1.0) ** int(np.dot(b, n)) for a, b in chars])
err = np.max(np.abs(shifted - signs * factor * th)) / np.max(np.abs(shifted))
print(f"quasi-periodicity under z -> z + tau n, relative error: {err:.1e}")

odd = [i for i, ch in enumerate(chars) if manakov.parity(ch) == -1]
at_zero = manakov.theta_all(np.zeros(2), tau)
print("odd characteristics (FLINT indices):", odd)
print("max |theta_odd(0)|:", np.max(np.abs(at_zero[odd])))
