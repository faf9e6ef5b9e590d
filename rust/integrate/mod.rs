//! Time integration of the top: Gauss–Legendre collocation (symplectic, keeps
//! every quadratic invariant — H0–H3 and H are all quadratic in `l`), an
//! explicit adaptive reference method, and sampled trajectories.
//!
//! **Gauss methods** (`gauss4`, `gauss6`, `gauss16`: 2, 3 and 8 stages, orders
//! 4, 6 and 16). The stage equations `Y_i = y + Σ_j a_ij h f(Y_j)` are solved
//! by fixed-point iteration on `L_i = h b_i f(Y_i)`, written with
//! `μ_ij = a_ij / b_j` as `Y_i = y + Σ_j μ_ij L_j`, and iterated until the
//! increments stop decreasing (so to machine precision); the update
//! `y_{n+1} = y_n + Σ_i L_i` uses compensated (Kahan) summation. This is the
//! scheme of M. Antoñana, J. Makazaga, A. Murua, *Reducing and monitoring
//! round-off error propagation for symplectic implicit Runge–Kutta schemes*,
//! Numer. Algorithms 76 (2017) 861–880 (IRKGL16). The coefficients are the
//! doubles nearest to 60-digit values, with `μ_ij + μ_ji = 1` exact, generated
//! by `tests/data/gen_gauss_tables.py`. The roundoff in the invariants then grows
//! like the square root of the number of steps.
//!
//! **Explicit method** (`dopri5`): the Dormand–Prince 5(4) pair with FSAL and
//! standard error-per-step control (J. R. Dormand, P. J. Prince, *A family of
//! embedded Runge–Kutta formulae*, J. Comput. Appl. Math. 6 (1980) 19–26;
//! Hairer, Nørsett, Wanner, *Solving ODEs I*, II.5 and II.4 for the control),
//! for comparison; and **`dop853`**, the Dormand–Prince 8(5,3) pair in the
//! form published by Hairer, Nørsett & Wanner (Solving ODEs I, II.10), the
//! method of scipy's `DOP853`.
//!
//! **Sampling.** The state is recorded only at given sample times; between two
//! consecutive sample times a Gauss method takes `n = ⌈Δt / dt⌉` equal steps of
//! size `Δt / n ≤ dt`, so a sample lands exactly on its time and memory is
//! `O(samples)`: a step allocates nothing (see `tests/alloc.rs`).
//!
//! **Batches.** [`integrate_many`] runs so(4) batches with gauss16, dop853 and Taylor on
//! the lane kernels of `batch.rs` and `taylor.rs` (each vector lane a different trajectory,
//! [`LANES`] at a time), bit-for-bit equal to [`integrate`] state by state, in
//! parallel over lane groups with rayon.
//!
//! **Budgets and cancellation.** Step budgets and output sizes are checked before
//! any work or allocation ([`check_budget`]); the `_with` variants take a
//! [`Cancel`] token and check it every
//! [`CHECK_EVERY`](crate::numeric::cancel::CHECK_EVERY) steps (well under a
//! millisecond of work), returning `Error::Interrupted`.

// Index loops mirror the subscripts of the formulas (i, j stages; k components).
#![allow(clippy::needless_range_loop)]

//!
//! # Files
//!
//! `options.rs`: methods, options, budgets; `gauss.rs`: the Gauss steppers;
//! `explicit.rs`: what the explicit methods share; `dopri5.rs`, `dop853.rs`:
//! the explicit steppers; `driver.rs`: the entry points; `batch.rs`,
//! `taylor.rs`: the trajectory-lane kernels.

mod batch;
mod batch_dop853;
mod dop853;
mod dopri5;
mod driver;
mod explicit;
mod gauss;
pub(crate) mod gauss_dd;
mod options;
pub mod taylor;
#[rustfmt::skip]
pub mod gauss_tables;

pub use crate::numeric::cancel::Cancel;
pub use driver::{
    integrate, integrate_many, integrate_many_with, integrate_partial, integrate_with,
};
pub use gauss::{MAX_FIXED_POINT_ITER, STALL_RTOL};
pub use options::{
    check_budget, check_sample_times, gauss_steps, Method, Options, Trajectory, MAX_STEPS, RTOL_MIN,
};

use gauss::StopRule;
use options::substeps;

/// Trajectories per vector group of the batch kernels (f64 lanes of AVX2).
pub const LANES: usize = batch::W;

use crate::so4::FrahmTop;

/// An autonomous vector field `ẏ = f(y)` on `R^dim`.
pub trait VectorField: Sync {
    /// The dimension of the state.
    fn dim(&self) -> usize;
    /// Writes `f(y)` into `dy`; both have length [`VectorField::dim`].
    fn eval(&self, y: &[f64], dy: &mut [f64]);

    /// For the so(4) top (1), its six `c_ij` (`i < j`): batches then run on the
    /// trajectory-lane kernels. `None` (the default) for any other field.
    fn so4_coefficients(&self) -> Option<&[f64; 6]> {
        None
    }

    /// Evaluates `f` at `S` states at once, stored component-major:
    /// `y[k][i]` is component `k` of state `i`. The default gathers each state
    /// and calls [`VectorField::eval`]; a field may override it to run the
    /// states as SIMD lanes.
    #[inline(always)]
    fn eval_lanes<const S: usize, const M: usize>(
        &self,
        y: &[[f64; S]; M],
        out: &mut [[f64; S]; M],
    ) {
        for i in 0..S {
            let mut yi = [0.0; M];
            for k in 0..M {
                yi[k] = y[k][i];
            }
            let mut o = [0.0; M];
            self.eval(&yi, &mut o);
            for k in 0..M {
                out[k][i] = o[k];
            }
        }
    }
}

impl VectorField for FrahmTop {
    fn dim(&self) -> usize {
        FrahmTop::dim(self)
    }
    #[inline(always)]
    fn eval(&self, y: &[f64], dy: &mut [f64]) {
        self.vector_field(y, dy)
    }

    fn so4_coefficients(&self) -> Option<&[f64; 6]> {
        self.c4()
    }

    #[inline(always)]
    fn eval_lanes<const S: usize, const M: usize>(
        &self,
        y: &[[f64; S]; M],
        out: &mut [[f64; S]; M],
    ) {
        if let (Some(c), Ok(y6), Ok(o6)) = (
            self.c4(),
            <&[[f64; S]; 6]>::try_from(&y[..]),
            <&mut [[f64; S]; 6]>::try_from(&mut out[..]),
        ) {
            crate::so4::vector_field4_lanes(c, y6, o6);
            return;
        }
        for i in 0..S {
            let mut yi = [0.0; M];
            for k in 0..M {
                yi[k] = y[k][i];
            }
            let mut o = [0.0; M];
            self.vector_field(&yi, &mut o);
            for k in 0..M {
                out[k][i] = o[k];
            }
        }
    }
}

#[cfg(test)]
mod tests;
