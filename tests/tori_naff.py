"""The frequency check of issue 13 against integration, shared by the tests
(tests/test_tori_solution.py) and the 100-state run
(tests/data/tori_naff_random100.py).

Frahm's equations (1) are integrated with gauss16 (no Abel map, no theta
functions) and each component's spectral lines are found with the test-side
NAFF (tests/naff.py). Every line with amplitude ≥ ``LINE_FLOOR`` of the
component's largest must be ``k1 ν1 + k2 ν2`` (``|k| ≤ K_MAX``) to
``LINE_RTOL`` relative to ``max(ν1, ν2)``, and the ``k`` found must span Z²
(both generators present, up to GL(2, Z)).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from naff import naff

# The figures.
LINE_RTOL = 1e-8
K_MAX = 20
LINE_FLOOR = 1e-6
# Slow periods in the NAFF window (the issue asks ≥ 500). At 500, NAFF's own
# error on the weakest lines (amplitude ~1e-6 beside lines 10^6 larger) reached
# 1.8e-8 on a random state — the tool's limit, not the frequencies' (the same
# state passes at 1000); 1000 periods keep the reference below the 1e-8 asked.
PERIODS = 1000


def match(nu, nu1, nu2):
    """The ``k`` (``|k| ≤ K_MAX``) with ``k1 ν1 + k2 ν2`` nearest to ``nu``, and
    the distance relative to ``max(ν1, ν2)``."""
    k = np.arange(-K_MAX, K_MAX + 1)
    comb = k[:, None] * nu1 + k[None, :] * nu2
    i = np.unravel_index(np.argmin(np.abs(comb - nu)), comb.shape)
    return (int(k[i[0]]), int(k[i[1]])), float(abs(comb[i] - nu) / max(nu1, nu2))


def generate_z2(ks) -> bool:
    """Whether the integer vectors ``ks`` span Z² (gcd of the 2 × 2 minors is 1)."""
    g = 0
    for i in range(len(ks)):
        for j in range(i + 1, len(ks)):
            g = int(np.gcd(g, abs(ks[i][0] * ks[j][1] - ks[i][1] * ks[j][0])))
            if g == 1:
                return True
    return False


@dataclass
class LineCheck:
    """Per line: component, frequency, amplitude relative to the component's
    largest, nearest ``k`` and its relative distance."""

    lines: list[tuple[int, float, float, tuple[int, int], float]] = field(default_factory=list)
    samples: int = 0
    dt: float = 0.0

    @property
    def worst(self) -> float:
        return max((ln[4] for ln in self.lines), default=0.0)

    @property
    def worst_line(self):
        return max(self.lines, key=lambda ln: ln[4]) if self.lines else None

    @property
    def ks(self) -> list[tuple[int, int]]:
        return [ln[3] for ln in self.lines]

    @property
    def generated(self) -> bool:
        return generate_z2(sorted(set(self.ks)))


def sampling(top, l0, nu, components) -> float:
    """The sampling step: 0.4 / the highest frequency with a line ≥ 1e-8 of the
    largest, from the spectrum of a short run (40 slow periods)."""
    nu1, nu2 = nu
    slow = min(nu1, nu2)
    T0 = 40 / slow
    dt0 = 1 / (40 * max(nu1, nu2))
    short = top.integrate(l0, T0, sample_every=dt0, method="gauss16").l
    fmax = 0.0
    for c in components:
        x = short[:, c] * np.sin(np.pi * np.arange(short.shape[0]) / (short.shape[0] - 1)) ** 4
        F = np.abs(np.fft.rfft(x - x.mean()))
        f = np.fft.rfftfreq(x.size, dt0)
        fmax = max(fmax, f[np.flatnonzero(F >= 1e-8 * F.max()).max()])
    return 0.4 / max(fmax, max(nu1, nu2))


def check_lines(top, l0, nu, components, periods=PERIODS) -> LineCheck:
    """Integrate ``l0`` for ``periods`` slow periods, NAFF each component and
    match every line of amplitude ≥ ``LINE_FLOOR`` to ``k·ν``."""
    nu1, nu2 = nu
    dt = sampling(top, l0, nu, components)
    T = periods / min(nu1, nu2)
    tr = top.integrate(l0, T, sample_every=dt, method="gauss16")
    out = LineCheck(samples=tr.l.shape[0], dt=dt)
    for c in components:
        lines, amps = naff(tr.l[:, c], dt, max_lines=150, rel_threshold=LINE_FLOOR)
        for line, amp in zip(lines, amps):
            if amp < LINE_FLOOR * amps[0] or line == 0.0:
                continue
            k, err = match(line, nu1, nu2)
            out.lines.append((c, float(line), float(amp / amps[0]), k, err))
    return out
