"""Frequencies next to a transversally hyperbolic so(3)-block orbit: the fit
against the genus-2 torus, where both answer.

Next to such an orbit (docs/degenerate.md §12) the frequency map answers from
the fits of ``1/ν2`` and ``(ν1 ∓ ν_E)/ν2`` in ``ln(1/σ)`` and ``x = σ²`` through
node states ``σ = 1e-3 … 8e-3`` out, with the slope ``2/λ`` of the orbit's own
monodromy. The states that need it lie closer in than the level set's route
reaches; an integration cannot check them (a trajectory in double moves
between tori whose ``ν2`` differ by ``~ε/δ²`` relative), and their own
solution often has no ``U`` for an Abel-map check.

So the fit is checked where the level set's route answers on its own: for
each state of the harsh draw (tests/data/every_state_harsh.py, seed 20261125)
that the map answers by the fit, the states on the same line at
``σ = 3e-5, 1e-4, 3e-4`` (closer in than the nodes, 1.2 … 3.5 units of
``ln(1/σ)`` beyond them) are given to the fit directly and to the genus-2
torus (``sol.torus``, not the map, which would fall back to the fit); the two
frequency pairs must span the same module (a unimodular integer matrix,
entries up to 8) to the reported relative error.

Run (about half an hour on one core; ``PART PARTS`` takes every PARTS-th state):
    python tests/data/hyperbolic_block_check.py [N [PART PARTS]]
"""

from __future__ import annotations

import itertools
import pathlib
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from every_state_harsh import draw  # noqa: E402

import manakov  # noqa: E402

PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
HOLD_OUT = [3e-5, 1e-4, 3e-4]


def nearest_block(l0):
    """Relative distance to the nearest block, the block state and the rest."""
    n = np.linalg.norm(l0)
    best = None
    for out in range(4):
        perp = [q for q, (i, j) in enumerate(PAIRS) if out in (i, j)]
        d = np.linalg.norm(l0[perp]) / n
        if best is None or d < best[0]:
            lb = l0.copy()
            lb[perp] = 0.0
            best = (d, lb, l0 - lb)
    return best


def module_error(f, g):
    """Smallest relative max-norm distance of ``g`` from ``M f``, ``M`` unimodular
    with entries up to 8."""
    best = np.inf
    r = range(-8, 9)
    for p, q, s, t in itertools.product(r, r, r, r):
        if abs(p * t - q * s) != 1:
            continue
        h = np.array([p * f[0] + q * f[1], s * f[0] + t * f[1]])
        best = min(best, float(np.max(np.abs(np.abs(h) - g) / np.abs(g))))
    return best


def exponent_reference(i: int = 744) -> None:
    """The transverse exponent of the block orbit next to harsh draw ``i`` (the
    Rust test's reference): the 6 × 6 variational equations of (1) over one
    period with scipy's DOP853 (the package integrates the 3 × 3 transverse
    system with a Magnus method), ``λ = ν_E ln|μ|``, ``μ`` the largest multiplier."""
    from scipy.integrate import solve_ivp

    rng = np.random.default_rng(20261125)
    for _ in range(i + 1):
        a, b, l0 = draw(rng)
    top = manakov.ManakovTop(a, b)
    _, lb, _ = nearest_block(l0)
    nu_e = manakov.frequency_map(top, lb[None, :]).frequencies[0][1]
    s = np.linalg.norm(lb)

    def rhs(_t, y):
        v = y[6:].reshape(6, 6)
        # (1) is quadratic: its Jacobian times v is (f(l + v) - f(l - v))/2 exactly
        jv = [
            (top.vector_field(y[:6] + v[:, j]) - top.vector_field(y[:6] - v[:, j])) / 2
            for j in range(6)
        ]
        return np.concatenate([top.vector_field(y[:6]), np.stack(jv, axis=1).ravel()])

    for rtol in (1e-12, 1e-13):
        sol = solve_ivp(
            rhs,
            (0, s / nu_e),
            np.concatenate([lb / s, np.eye(6).ravel()]),
            method="DOP853",
            rtol=rtol,
            atol=rtol * 1e-2,
        )
        mu = np.max(np.abs(np.linalg.eigvals(sol.y[6:, -1].reshape(6, 6))))
        print(f"draw {i}: lambda = {np.log(mu) * nu_e!r} (DOP853, rtol {rtol:g})")


def main(n: int = 10000, part: int = 0, parts: int = 1) -> None:
    """States ``i < n`` with ``i % parts == part`` (the draw is the same)."""
    warnings.simplefilter("ignore")
    if part == 0:
        exponent_reference()
    rng = np.random.default_rng(20261125)
    names = manakov.tori.STATUS_NAMES
    t0 = time.time()
    rows = []
    for i in range(n):
        a, b, l0 = draw(rng)
        if i % parts != part:
            continue
        top = manakov.ManakovTop(a, b)
        d, lb, lp = nearest_block(l0)
        if not d <= 1e-2:
            continue
        fm = manakov.frequency_map(top, np.array([l0, lb]))
        if names[int(fm.status[0])] != "ok" or names[int(fm.status[1])] != "ok":
            continue
        if fm.frequencies[1][0] != 0.0:
            continue  # the block orbit is elliptic (or the state is answered otherwise)
        sol = top.solve(l0)
        if sol.kind == "genus2":
            try:
                _ = sol.torus
                continue  # the map's answer is the genus-2 torus itself
            except manakov.ClosedFormError:
                pass
        try:
            own = sol._motion.near_euler_frequencies()
        except manakov.ClosedFormError:
            continue
        if not np.array_equal(np.asarray(own), fm.frequencies[0]):
            continue
        errs = []
        for s in HOLD_OUT:
            ls = lb + lp * (s / d)
            # the genus-2 torus alone (the map would fall back to the fit itself)
            hold = top.solve(ls)
            try:
                torus = np.asarray(hold.torus.frequencies)
            except (manakov.ClosedFormError, ValueError, AttributeError):
                # refused, or no genus-2 solution at all (kind 'integrated')
                errs.append(("genus-2 refuses", s))
                continue
            try:
                f = np.asarray(hold._motion.near_euler_frequencies())
            except Exception as e:  # noqa: BLE001
                errs.append((f"fit refuses: {str(e)[:60]}", s))
                continue
            errs.append((module_error(f, torus), s))
        rows.append((i, d, fm.frequencies[0], errs))
        cells = "  ".join(
            f"{s:.0e}: {e:.1e}" if isinstance(e, float) else f"{s:.0e}: {e}" for e, s in errs
        )
        print(
            f"{i:5d} delta {d:.1e} nu ({fm.frequencies[0][0]:.10g}, "
            f"{fm.frequencies[0][1]:.10g})  {cells}",
            flush=True,
        )
    vals = [e for *_, errs in rows for e, _ in errs if isinstance(e, float)] or [np.nan]
    print(
        f"\n{len(rows)} states answered by the fit next to a hyperbolic block orbit; "
        f"{len(vals)} hold-out comparisons: median {np.median(vals):.1e}, "
        f"max {np.max(vals):.1e}"
    )
    print(f"wall time {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:4]))
