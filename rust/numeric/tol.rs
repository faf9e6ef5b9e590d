//! Thresholds shared by several layers, each with the reason for its value.

/// The smallest step an explicit integrator (dopri5, dop853, also in the
/// batch kernels) may take at time `t` before it reports a step-size
/// underflow: `1e-14 · max(|t|, 1)`, about 50 ulps of `t`. Below it `t + h`
/// moves `t` by a few roundings only, so the error control has lost the step.
#[inline(always)]
pub fn min_step(t: f64) -> f64 {
    1e-14 * t.abs().max(1.0)
}

/// A state lies on the singular level sets `h0 = 0` or `h1² = 4h0²` (within
/// the rounding of its integrals) when `|h0| ≤ SINGULAR_SET_RTOL · |l|²` or
/// `|h1² − 4h0²| ≤ SINGULAR_SET_RTOL · (h1² + 4h0²)`: the integrals are rounded
/// sums of products of size `|l|²`. The Theorem (`crate::solution`) refuses
/// such states before the reduction, and the frequency maps (`crate::tori`)
/// give them their status without setting up the solution.
pub const SINGULAR_SET_RTOL: f64 = 1e-13;

/// The reduction's floor near the singular level set `h1² = 4h0²`
/// (`crate::kotter`): `|h1² − 4h0²| ≤ REDUCTION_FLOOR_RTOL · h1²` is treated
/// as `h1² = 4h0²` (the denominator of (19) vanishes). (`h0 = 0` is not
/// singular for the reduction: it takes the limit there, `kotter::pairs`.)
/// From the state, `h1² − 4h0² = |m − n|² |m + n|²` is exact to
/// a few ulps; the bound is where the double-double level-set constants run
/// out of digits: at `(h1² − 4h0²)/h1² = 4e-12` 2 of 600 random states fail
/// (the inverse map of the curve); with the bound removed, 5 of 80 states of
/// the shared tops fail at 1e-14, and at 1e-16 64 of 80 fail while the others
/// round-trip to only 5e-9 (`tests/data/kotter_singular_sweep.py`; the
/// guaranteed range ends at `kotter::NEAR_SINGULAR_RTOL`).
pub const REDUCTION_FLOOR_RTOL: f64 = 1e-12;
