"""Bit-level checksum of the package's main outputs, for refactors that must not
change a single bit.

Prints one SHA-256 per output (over the raw float64 bytes):
- l(t) of the Theorem on the 'generic' top at 10^6 times in [0, 1e6];
- theta_all at 10^5 points of the shared theta benchmark (problems.json);
- a 64 x 64 frequency map on the Casimir slice of 'generic' (frequencies and statuses);
- the gauss16 integration of 'generic' to t = 1000 (samples every 1.0).

Run: python tests/data/same_bits_checksum.py
Compare the output before and after a change; any difference is a changed bit.
"""

from __future__ import annotations

import hashlib

import numpy as np

import manakov
from manakov import tori


def digest(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()[:32]


def main() -> None:
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    sol = top.solve(p.l0)
    t = np.linspace(0.0, 1e6, 10**6)
    print("l(t)      ", digest(sol.l(t)))

    tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
    rng = np.random.default_rng(20261125)
    z = rng.uniform(0.0, 1.0, (10**5, 2)) + 1j * rng.uniform(-0.5, 0.5, (10**5, 2))
    print("theta_all ", digest(manakov.theta_all(z, tau)))

    _, _, states = tori.casimir_slice(p.l0, 64)
    fm = manakov.frequency_map(top, states)
    nu, status = fm[0], fm[1]
    print("freq map  ", digest(np.asarray(nu)), digest(np.asarray(status)))

    tr = top.integrate(p.l0, 1000.0, sample_every=1.0)
    print("gauss16   ", digest(tr.l))


if __name__ == "__main__":
    main()
