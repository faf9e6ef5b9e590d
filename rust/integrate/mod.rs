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

mod batch;
mod dop853;
pub mod taylor;
#[rustfmt::skip]
pub mod gauss_tables;

use rayon::prelude::*;

use crate::error::{check_finite, Error, Result};
pub use crate::numeric::cancel::Cancel;
use crate::numeric::cancel::{poll_during, CHECK_EVERY};
use crate::numeric::tol::min_step;

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

/// An integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Method {
    /// 2-stage Gauss–Legendre collocation, order 4.
    Gauss4,
    /// 3-stage Gauss–Legendre collocation, order 6.
    Gauss6,
    /// 8-stage Gauss–Legendre collocation, order 16 (IRKGL16).
    Gauss16,
    /// Dormand–Prince 5(4), explicit, adaptive.
    Dopri5,
    /// Dormand–Prince 8(5,3) (DOP853), explicit, adaptive.
    Dop853,
    /// Taylor's method of order `⌈−ln rtol / 2 + 1⌉` with Jorba–Zou step
    /// control (so(4) only; see [`taylor`]).
    Taylor,
}

impl Method {
    /// All method names, as accepted by [`Method::from_name`].
    pub const NAMES: [&'static str; 6] =
        ["gauss4", "gauss6", "gauss16", "dopri5", "dop853", "taylor"];

    /// Parses `"gauss4"`, `"gauss6"`, `"gauss16"`, `"dopri5"`, `"dop853"` or `"taylor"`.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "gauss4" => Ok(Method::Gauss4),
            "gauss6" => Ok(Method::Gauss6),
            "gauss16" => Ok(Method::Gauss16),
            "dopri5" => Ok(Method::Dopri5),
            "dop853" => Ok(Method::Dop853),
            "taylor" => Ok(Method::Taylor),
            _ => Err(Error::InvalidArgument {
                what: "method",
                reason: format!("unknown method {name:?}; known: {}", Self::NAMES.join(", ")),
            }),
        }
    }

    /// The method's name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Gauss4 => "gauss4",
            Method::Gauss6 => "gauss6",
            Method::Gauss16 => "gauss16",
            Method::Dopri5 => "dopri5",
            Method::Dop853 => "dop853",
            Method::Taylor => "taylor",
        }
    }

    /// Number of stages of a Gauss method (`None` for explicit methods).
    pub fn stages(self) -> Option<usize> {
        match self {
            Method::Gauss4 => Some(2),
            Method::Gauss6 => Some(3),
            Method::Gauss16 => Some(8),
            Method::Dopri5 | Method::Dop853 | Method::Taylor => None,
        }
    }

    /// The stage predictor `E` (row-major `s × s`) of a Gauss method.
    pub fn gauss_predictor(self) -> Option<Vec<f64>> {
        use gauss_tables::*;
        match self {
            Method::Gauss4 => Some(E2.concat()),
            Method::Gauss6 => Some(E3.concat()),
            Method::Gauss16 => Some(E8.concat()),
            Method::Dopri5 | Method::Dop853 | Method::Taylor => None,
        }
    }

    /// The Gauss tableau `(c, b, μ)` (`μ` row-major `s × s`), `None` for explicit methods.
    pub fn gauss_tableau(self) -> Option<(&'static [f64], &'static [f64], Vec<f64>)> {
        use gauss_tables::*;
        match self {
            Method::Gauss4 => Some((&C2, &B2, MU2.concat())),
            Method::Gauss6 => Some((&C3, &B3, MU3.concat())),
            Method::Gauss16 => Some((&C8, &B8, MU8.concat())),
            Method::Dopri5 | Method::Dop853 | Method::Taylor => None,
        }
    }
}

/// Smallest `rtol` of the explicit methods, `100 ε` (scipy's floor): a relative error
/// target per step below ~100 ulps of the state is below the rounding of the step
/// itself, and `rtol = atol = 1e-300` made the error norm overflow.
pub const RTOL_MIN: f64 = 100.0 * f64::EPSILON;

/// `x / sc` in the error norms, with `0 / 0 = 0`: with `atol = 0` a component that is
/// exactly zero has scale 0, and it contributes nothing to the norm.
pub(crate) fn scaled(x: f64, sc: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x / sc
    }
}

/// Starting step (HNW I, II.4, first part) from `d0 = ‖y‖` and `d1 = ‖f(y)‖` in the
/// error norm with scale `atol + rtol |y_i|`: `0.01 d0/d1`, or `1e-6` when either is
/// tiny — and also when `d1` overflowed (a component with zero scale and nonzero
/// derivative, or a tiny `atol`), where the formula would give 0; the step controller
/// adapts from there.
pub(crate) fn starting_step(y: &[f64], f0: &[f64], atol: f64, rtol: f64) -> f64 {
    let m = y.len().max(1) as f64;
    let (mut d0, mut d1) = (0.0f64, 0.0f64);
    for (&yi, &fi) in y.iter().zip(f0) {
        let sc = atol + rtol * yi.abs();
        d0 += scaled(yi, sc).powi(2);
        d1 += scaled(fi, sc).powi(2);
    }
    let (d0, d1) = ((d0 / m).sqrt(), (d1 / m).sqrt());
    let h = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    if h.is_finite() && h > 0.0 {
        h
    } else {
        1e-6
    }
}

/// Integration options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The method.
    pub method: Method,
    /// Gauss methods: the largest step. `dopri5`, `dop853`: the initial step (0 =
    /// automatic). `taylor`: the largest step (0 = none).
    pub dt: f64,
    /// Relative tolerance of `dopri5` and `dop853`, at least [`RTOL_MIN`]; of
    /// `taylor`, in [`taylor::TOL_MIN`, `taylor::TOL_MAX`] (ignored by the Gauss
    /// methods).
    pub rtol: f64,
    /// `dopri5` absolute tolerance.
    pub atol: f64,
    /// The largest number of steps one call may take, over all sample times
    /// (at most [`MAX_STEPS`]). Gauss methods check it before the first step,
    /// explicit methods while stepping; either way the call fails with
    /// `InvalidArgument` instead of running for hours.
    pub max_steps: u64,
}

impl Options {
    /// Checks `dt`, `rtol`, `atol`, `max_steps`.
    pub fn validate(&self) -> Result<()> {
        if self.max_steps == 0 || self.max_steps as f64 > MAX_STEPS {
            return Err(Error::InvalidArgument {
                what: "max_steps",
                reason: format!("must be in [1, {MAX_STEPS:e}], got {}", self.max_steps),
            });
        }
        let gauss = self.method.stages().is_some();
        if !self.dt.is_finite() || self.dt < 0.0 || (gauss && self.dt == 0.0) {
            return Err(Error::InvalidArgument {
                what: "dt",
                reason: format!("must be finite and > 0, got {}", self.dt),
            });
        }
        for (what, v) in [("rtol", self.rtol), ("atol", self.atol)] {
            if !v.is_finite() || v < 0.0 {
                return Err(Error::InvalidArgument {
                    what,
                    reason: format!("must be finite and >= 0, got {v}"),
                });
            }
        }
        if self.method == Method::Taylor {
            if !(taylor::TOL_MIN..=taylor::TOL_MAX).contains(&self.rtol) {
                return Err(Error::InvalidArgument {
                    what: "rtol",
                    reason: format!(
                        "must be in [eps = {:e}, {:e}] for taylor (it sets the order, \
                         20 at eps), got {:e}",
                        taylor::TOL_MIN,
                        taylor::TOL_MAX,
                        self.rtol
                    ),
                });
            }
        } else if !gauss && self.rtol < RTOL_MIN {
            return Err(Error::InvalidArgument {
                what: "rtol",
                reason: format!(
                    "must be >= 100 eps = {RTOL_MIN:e} for the explicit methods (a smaller \
                     relative error per step is below rounding), got {:e}",
                    self.rtol
                ),
            });
        }
        Ok(())
    }
}

/// A sampled trajectory: `t[k]` and the state `y[k·dim .. (k+1)·dim]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Sample times.
    pub t: Vec<f64>,
    /// States at the sample times, row-major `(samples, dim)`.
    pub y: Vec<f64>,
    /// Number of accepted steps taken.
    pub steps: u64,
    /// Number of vector-field evaluations.
    pub evals: u64,
}

/// Hard cap on [`Options::max_steps`] (10^11 steps is ~a day of computing);
/// below 2^53, so step counts held in f64 are exact.
pub const MAX_STEPS: f64 = 1e11;

/// Fixed-point iterations allowed per Gauss step. Convergence is linear with
/// ratio ~ h·‖∂f‖; at the default steps ~10–20 iterations reach roundoff.
pub const MAX_FIXED_POINT_ITER: usize = 100;

/// A Gauss step whose iteration stalls with increments above this fraction of
/// the state's size did not converge (a converged iteration stalls at roundoff,
/// ~1e-16 of it): the step is too large for fixed-point iteration.
pub const STALL_RTOL: f64 = 1e-8;

/// Number of equal Gauss substeps of at most `dt` covering `span`; a ratio within
/// 1e-9 of an integer is taken as that integer, so 1.0 / 0.1 gives 10 steps, not 11.
fn substeps(span: f64, dt: f64) -> f64 {
    let r = span / dt;
    let k = r.round();
    if (r - k).abs() <= 1e-9 * k.max(1.0) {
        k.max(1.0)
    } else {
        r.ceil().max(1.0)
    }
}

/// Whether a Gauss step of size `h` may start from the stages of the previous
/// step (size `last_h`, 0 before the first step). Only between normal sizes with
/// a finite ratio: with a subnormal `h` the products `h b_j` underflow, and a
/// ratio `h / last_h` can overflow; both once made NaN stages.
fn reuse_stages(last_h: f64, h: f64) -> bool {
    last_h.is_normal() && h.is_normal() && (h / last_h).is_finite()
}

/// The error of an explicit method that needs more than its step budget.
fn too_many_steps(budget: u64) -> Error {
    Error::InvalidArgument {
        what: "rtol/atol",
        reason: format!(
            "more steps needed than the remaining budget of {budget} (max_steps); \
             loosen rtol/atol, shorten t_end or raise max_steps"
        ),
    }
}

/// Checks the sample times: finite, `t0 ≤ t[0] ≤ t[1] ≤ …`.
pub fn check_sample_times(t0: f64, times: &[f64]) -> Result<()> {
    check_finite("t_eval", times)?;
    if !t0.is_finite() {
        return Err(Error::NonFinite {
            what: "t0",
            index: 0,
        });
    }
    let mut prev = t0;
    for (i, &t) in times.iter().enumerate() {
        if t < prev {
            return Err(Error::InvalidArgument {
                what: "t_eval",
                reason: format!(
                    "sample times must be sorted and >= t0 = {t0}; entry {i} = {t} follows {prev}"
                ),
            });
        }
        prev = t;
    }
    Ok(())
}

/// Stopping rule of the stage iteration: stop once the increments stop
/// decreasing (Antoñana, Makazaga & Murua 2017). Roundoff makes converged
/// increments wobble, so an increment that fails to beat the smallest so far
/// ends the iteration only once that smallest one is at roundoff level
/// (`ROUNDOFF_RTOL`); above it, two failures in a row are needed.
struct StopRule {
    best: f64,
    stalls: u32,
    iterations: usize,
}

/// Increments below this fraction of the state's size are roundoff: 10^4 ulps.
const ROUNDOFF_RTOL: f64 = 1e4 * f64::EPSILON;

impl StopRule {
    fn new() -> Self {
        StopRule {
            best: f64::INFINITY,
            stalls: 0,
            iterations: 0,
        }
    }

    /// Records one iteration's largest increment; `Ok(true)` means stop.
    fn update(&mut self, dmax: f64, ymax: f64) -> Result<bool> {
        self.iterations += 1;
        if !dmax.is_finite() {
            return Err(Error::NoConvergence {
                what: "Gauss stage iteration (state became non-finite; reduce dt)",
                tol: 0.0,
                reached: dmax,
                iterations: self.iterations,
            });
        }
        if dmax == 0.0 {
            return Ok(true);
        }
        if dmax < self.best {
            self.best = dmax;
            self.stalls = 0;
            return Ok(false).and_then(|s| self.cap(s, ymax));
        }
        self.stalls += 1;
        let stop = self.stalls >= 2 || self.best <= ROUNDOFF_RTOL * ymax;
        self.cap(stop, ymax)
    }

    fn cap(&self, stop: bool, ymax: f64) -> Result<bool> {
        if !(stop || self.iterations >= MAX_FIXED_POINT_ITER) {
            return Ok(false);
        }
        if self.best > STALL_RTOL * ymax.max(f64::MIN_POSITIVE) {
            return Err(Error::NoConvergence {
                what: "Gauss stage iteration (step too large; reduce dt)",
                tol: STALL_RTOL * ymax,
                reached: self.best,
                iterations: self.iterations,
            });
        }
        Ok(true)
    }
}

/// One step of a Gauss method on `y`, advanced in place.
trait Stepper {
    fn step<F: VectorField>(&mut self, f: &F, y: &mut [f64], h: f64) -> Result<()>;
    fn evals(&self) -> u64;
}

/// Gauss–Legendre stepper on fixed-size arrays (`S` stages, state dimension
/// `M`), stored component-major (`[component][stage]`) so that the stage sums
/// and the vector field run across the `S` stages as SIMD lanes
/// ([`VectorField::eval_lanes`]). Used for so(4), `M = 6`.
struct GaussFixed<const S: usize, const M: usize> {
    b: [f64; S],
    /// `mu_t[j][i] = μ_ij`: column `j` contiguous over the stages `i`.
    mu_t: [[f64; S]; S],
    e_t: [[f64; S]; S],
    /// `L[k][i] = h b_i f_k(Y_i)`; after a step, the source of the next guess.
    l: [[f64; S]; M],
    /// Kahan compensation of the update.
    comp: [f64; M],
    last_h: f64,
    evals: u64,
}

fn transpose<const S: usize>(a: &[[f64; S]; S]) -> [[f64; S]; S] {
    let mut t = [[0.0; S]; S];
    for i in 0..S {
        for j in 0..S {
            t[j][i] = a[i][j];
        }
    }
    t
}

impl<const S: usize, const M: usize> GaussFixed<S, M> {
    fn new(b: &[f64; S], mu: &[[f64; S]; S], e: &[[f64; S]; S]) -> Self {
        GaussFixed {
            b: *b,
            mu_t: transpose(mu),
            e_t: transpose(e),
            l: [[0.0; S]; M],
            comp: [0.0; M],
            last_h: 0.0,
            evals: 0,
        }
    }
}

impl<const S: usize, const M: usize> Stepper for GaussFixed<S, M> {
    fn evals(&self) -> u64 {
        self.evals
    }

    #[inline]
    fn step<F: VectorField>(&mut self, f: &F, y: &mut [f64], h: f64) -> Result<()> {
        let len = y.len();
        let y: &mut [f64; M] = y.try_into().map_err(|_| Error::Shape {
            what: "state",
            expected: format!("({M},)"),
            got: format!("({len},)"),
        })?;
        let mut hb = [0.0; S];
        for i in 0..S {
            hb[i] = h * self.b[i];
        }
        if !reuse_stages(self.last_h, h) {
            // First step: every stage starts from f(y).
            let mut fbuf = [0.0; M];
            f.eval(y, &mut fbuf);
            self.evals += 1;
            for k in 0..M {
                for i in 0..S {
                    self.l[k][i] = hb[i] * fbuf[k];
                }
            }
        } else if h == self.last_h {
            // Predictor: extrapolate the previous step's collocation polynomial,
            // f at the new nodes = Σ_j ℓ_j(1 + c_i) f(Y_j), with f(Y_j) = L_j / (h b_j);
            // h cancels (same h), so L_j / b_j is carried and h b_j never divides.
            for k in 0..M {
                let mut fj = [0.0; S];
                for j in 0..S {
                    fj[j] = self.l[k][j] / self.b[j];
                }
                let mut acc = [0.0; S];
                for j in 0..S {
                    for i in 0..S {
                        acc[i] += self.e_t[j][i] * fj[j];
                    }
                }
                for i in 0..S {
                    self.l[k][i] = self.b[i] * acc[i];
                }
            }
        } else {
            // L ∝ h: rescale the previous stages.
            let r = h / self.last_h;
            for lk in self.l.iter_mut() {
                for x in lk.iter_mut() {
                    *x *= r;
                }
            }
        }
        self.last_h = h;
        let ymax = y.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let mut rule = StopRule::new();
        let mut ys = [[0.0; S]; M];
        let mut fs = [[0.0; S]; M];
        loop {
            // Y_i = y + Σ_j μ_ij L_j, all stages at once.
            for k in 0..M {
                let mut acc = [y[k]; S];
                for j in 0..S {
                    let ljk = self.l[k][j];
                    for i in 0..S {
                        acc[i] += self.mu_t[j][i] * ljk;
                    }
                }
                ys[k] = acc;
            }
            f.eval_lanes(&ys, &mut fs);
            let mut dmax = [0.0f64; S];
            for k in 0..M {
                for i in 0..S {
                    let new = hb[i] * fs[k][i];
                    dmax[i] = dmax[i].max((new - self.l[k][i]).abs());
                    self.l[k][i] = new;
                }
            }
            self.evals += S as u64;
            let dmax = dmax.iter().fold(0.0f64, |a, &b| a.max(b));
            if rule.update(dmax, ymax)? {
                break;
            }
        }
        // Compensated update y += Σ_i L_i (Kahan): comp carries the lost low bits.
        for k in 0..M {
            let mut sum = self.comp[k];
            for i in 0..S {
                sum += self.l[k][i];
            }
            let new = y[k] + sum;
            self.comp[k] = (y[k] - new) + sum;
            y[k] = new;
        }
        // f64::max ignores NaN, so the stop rule cannot see one: check the result.
        if !y.iter().all(|v| v.is_finite()) {
            return Err(Error::NoConvergence {
                what: "Gauss step (state overflowed or became NaN; reduce dt or rescale l)",
                tol: 0.0,
                reached: f64::NAN,
                iterations: rule.iterations,
            });
        }
        Ok(())
    }
}

/// Gauss–Legendre stepper for any state dimension, scratch allocated once.
struct GaussDyn {
    s: usize,
    m: usize,
    b: &'static [f64],
    mu: Vec<f64>,
    e: Vec<f64>,
    l: Vec<f64>,
    fj: Vec<f64>,
    ystage: Vec<f64>,
    fbuf: Vec<f64>,
    comp: Vec<f64>,
    last_h: f64,
    evals: u64,
}

impl GaussDyn {
    fn new(method: Method, m: usize) -> Option<Self> {
        let (_, b, mu) = method.gauss_tableau()?;
        let e = method.gauss_predictor()?;
        let s = b.len();
        Some(GaussDyn {
            s,
            m,
            b,
            mu,
            e,
            l: vec![0.0; s * m],
            fj: vec![0.0; s * m],
            ystage: vec![0.0; s * m],
            fbuf: vec![0.0; m],
            comp: vec![0.0; m],
            last_h: 0.0,
            evals: 0,
        })
    }
}

impl Stepper for GaussDyn {
    fn evals(&self) -> u64 {
        self.evals
    }

    fn step<F: VectorField>(&mut self, f: &F, y: &mut [f64], h: f64) -> Result<()> {
        let (s, m) = (self.s, self.m);
        if !reuse_stages(self.last_h, h) {
            f.eval(y, &mut self.fbuf);
            self.evals += 1;
            for i in 0..s {
                let hb = h * self.b[i];
                for k in 0..m {
                    self.l[i * m + k] = hb * self.fbuf[k];
                }
            }
        } else if h == self.last_h {
            // Predictor, as in GaussFixed.
            for j in 0..s {
                for k in 0..m {
                    self.fj[j * m + k] = self.l[j * m + k] / self.b[j];
                }
            }
            for i in 0..s {
                for k in 0..m {
                    let acc: f64 = (0..s).map(|j| self.e[i * s + j] * self.fj[j * m + k]).sum();
                    self.l[i * m + k] = self.b[i] * acc;
                }
            }
        } else {
            let r = h / self.last_h;
            self.l.iter_mut().for_each(|x| *x *= r);
        }
        self.last_h = h;
        let ymax = y.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let mut rule = StopRule::new();
        loop {
            for i in 0..s {
                let yi = &mut self.ystage[i * m..(i + 1) * m];
                yi.copy_from_slice(y);
                for j in 0..s {
                    let muij = self.mu[i * s + j];
                    let lj = &self.l[j * m..(j + 1) * m];
                    for k in 0..m {
                        yi[k] += muij * lj[k];
                    }
                }
            }
            let mut dmax = 0.0f64;
            for i in 0..s {
                f.eval(&self.ystage[i * m..(i + 1) * m], &mut self.fbuf);
                let hb = h * self.b[i];
                let li = &mut self.l[i * m..(i + 1) * m];
                for k in 0..m {
                    let new = hb * self.fbuf[k];
                    dmax = dmax.max((new - li[k]).abs());
                    li[k] = new;
                }
            }
            self.evals += s as u64;
            if rule.update(dmax, ymax)? {
                break;
            }
        }
        for k in 0..m {
            let mut sum = self.comp[k];
            for i in 0..s {
                sum += self.l[i * m + k];
            }
            let new = y[k] + sum;
            self.comp[k] = (y[k] - new) + sum;
            y[k] = new;
        }
        // f64::max ignores NaN, so the stop rule cannot see one: check the result.
        if !y.iter().all(|v| v.is_finite()) {
            return Err(Error::NoConvergence {
                what: "Gauss step (state overflowed or became NaN; reduce dt or rescale l)",
                tol: 0.0,
                reached: f64::NAN,
                iterations: rule.iterations,
            });
        }
        Ok(())
    }
}

// Dormand–Prince 5(4) tableau (Dormand & Prince 1980, Table 2; HNW I, Table II.5.2).
/// Nodes; the field is autonomous, so only the tests use them.
#[cfg_attr(not(test), allow(dead_code))]
const DP_C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const DP_A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// 5th-order weights (= last row of A: first same as last).
const DP_B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// 4th-order embedded weights.
const DP_BHAT: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];

/// Dormand–Prince 5(4) stepper with its scratch space.
struct Dopri5 {
    m: usize,
    k: Vec<f64>,
    ytmp: Vec<f64>,
    h: f64,
    fsal_valid: bool,
    evals: u64,
    rtol: f64,
    atol: f64,
}

impl Dopri5 {
    fn new(m: usize, opts: &Options) -> Self {
        Dopri5 {
            m,
            k: vec![0.0; 7 * m],
            ytmp: vec![0.0; m],
            h: opts.dt,
            fsal_valid: false,
            evals: 0,
            rtol: opts.rtol,
            atol: opts.atol,
        }
    }

    /// Advances `y` from `t` to exactly `t_target` with adaptive steps; returns the number
    /// of steps, failing once more than `budget` are needed.
    fn advance<F: VectorField>(
        &mut self,
        f: &F,
        y: &mut [f64],
        t: &mut f64,
        t_target: f64,
        budget: u64,
        cancel: &Cancel,
    ) -> Result<u64> {
        let m = self.m;
        let mut steps = 0u64;
        let mut attempts = 0u32;
        if !self.fsal_valid {
            f.eval(y, &mut self.k[0..m]);
            self.evals += 1;
            self.fsal_valid = true;
        }
        if self.h == 0.0 {
            self.h = starting_step(y, &self.k[0..m], self.atol, self.rtol);
        }
        while *t < t_target {
            let remaining = t_target - *t;
            let last = self.h >= remaining;
            let h = if last { remaining } else { self.h };
            attempts = attempts.wrapping_add(1);
            if attempts % CHECK_EVERY == 0 {
                cancel.check()?;
            }
            if h <= min_step(*t) && !last {
                return Err(Error::NoConvergence {
                    what: "dopri5 step size underflow",
                    tol: self.rtol,
                    reached: h,
                    iterations: steps as usize,
                });
            }
            for st in 1..7 {
                for i in 0..m {
                    let mut acc = 0.0;
                    for (j, &aij) in DP_A[st].iter().enumerate().take(st) {
                        acc += aij * self.k[j * m + i];
                    }
                    self.ytmp[i] = y[i] + h * acc;
                }
                let (_, tail) = self.k.split_at_mut(st * m);
                f.eval(&self.ytmp, &mut tail[..m]);
            }
            self.evals += 6;
            // ytmp holds the 5th-order solution (stage 7 point); error = h Σ (b - b̂) k.
            let mut err = 0.0f64;
            for i in 0..m {
                let mut e = 0.0;
                for j in 0..7 {
                    e += (DP_B[j] - DP_BHAT[j]) * self.k[j * m + i];
                }
                let sc = self.atol + self.rtol * y[i].abs().max(self.ytmp[i].abs());
                err += scaled(h * e, sc).powi(2);
            }
            let err = (err / m as f64).sqrt();
            if !err.is_finite() {
                return Err(Error::NoConvergence {
                    what: "dopri5 (state became non-finite)",
                    tol: self.rtol,
                    reached: err,
                    iterations: steps as usize,
                });
            }
            // Step-size factor 0.9·err^(-1/5), limited to [0.2, 10] (HNW I, (4.13)).
            let fac = (0.9 * err.max(1e-300).powf(-0.2)).clamp(0.2, 10.0);
            if err <= 1.0 {
                y.copy_from_slice(&self.ytmp);
                self.k.copy_within(6 * m..7 * m, 0);
                *t = if last { t_target } else { *t + h };
                steps += 1;
                if !last {
                    self.h = h * fac;
                } else {
                    self.h = self.h.max(h * fac.min(1.0));
                }
            } else {
                self.h = h * fac.min(1.0);
            }
            if steps > budget {
                return Err(too_many_steps(budget));
            }
        }
        Ok(steps)
    }
}

/// Checks, before any work, that a run from `t0` through the sample `times` fits
/// in `max_steps`, and names the cause when it does not.
///
/// Every sample interval of positive length needs at least one step, whatever the
/// method: more such intervals than `max_steps` is refused as a matter of sample
/// spacing. A Gauss method's step count is known in advance (`⌈Δt/dt⌉` per
/// interval): over budget, the cause is `dt` when `(t_end − t0)/dt` alone exceeds
/// the budget, else the sample spacing (intervals shorter than `dt` still cost a
/// step each). The explicit methods' count depends on the error control; they are
/// checked while stepping.
pub fn check_budget(method: Method, t0: f64, times: &[f64], dt: f64, max_steps: u64) -> Result<()> {
    let gauss = method.stages().is_some();
    let (mut intervals, mut total, mut prev) = (0.0f64, 0.0f64, t0);
    for &tk in times {
        let span = tk - prev;
        if span > 0.0 {
            intervals += 1.0;
            if gauss {
                total += substeps(span, dt);
            }
        }
        prev = tk;
    }
    let budget = max_steps as f64;
    if intervals > budget {
        return Err(Error::InvalidArgument {
            what: "max_steps",
            reason: format!(
                "the sample spacing: {intervals:e} sample intervals each need at least one \
                 step, more than max_steps = {max_steps}; sample less often (fewer t_eval \
                 points or a larger sample_every) or raise max_steps"
            ),
        });
    }
    if gauss && total > budget {
        let by_dt = (prev - t0) / dt;
        let reason = if by_dt > budget {
            format!(
                "dt: (t_end - t0) / dt = {:e} / {dt:e} = {by_dt:e} steps, more than \
                 max_steps = {max_steps}; increase dt, shorten t_end or raise max_steps",
                prev - t0
            )
        } else {
            format!(
                "the sample spacing: {intervals:e} sample intervals at steps of at most \
                 dt = {dt:e} need {total:e} steps (each interval at least one), more than \
                 max_steps = {max_steps}, although (t_end - t0) / dt is only {by_dt:e}; \
                 sample less often or raise max_steps"
            )
        };
        return Err(Error::InvalidArgument {
            what: "max_steps",
            reason,
        });
    }
    Ok(())
}

/// A zeroed output buffer of `n` doubles, allocated fallibly: a size the machine
/// cannot hold is an `InvalidArgument` (ValueError), not an abort.
fn alloc_output(n: Option<usize>) -> Result<Vec<f64>> {
    let err = |n: Option<usize>| Error::InvalidArgument {
        what: "output size",
        reason: format!(
            "cannot allocate {} bytes for the samples; sample less often or integrate \
             fewer states per call",
            n.map_or(f64::INFINITY, |n| n as f64 * 8.0)
        ),
    };
    let n = n
        .filter(|&n| n <= isize::MAX as usize / 8)
        .ok_or_else(|| err(n))?;
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| err(Some(n)))?;
    v.resize(n, 0.0);
    Ok(v)
}

/// Integrates `ẏ = f(y)` from `y0` at time `t0`, recording the state at each of
/// `times` (sorted, `≥ t0`); see the module docs for the methods and sampling.
///
/// Errors: `Shape` if `y0` has the wrong length; `NonFinite`; `InvalidArgument`
/// for bad options or unsorted times or too many steps; `NoConvergence` if a
/// Gauss step cannot be solved (step too large) or `dopri5` fails.
pub fn integrate<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
) -> Result<Trajectory> {
    integrate_with(f, y0, t0, times, opts, &Cancel::never())
}

/// [`integrate`], stopping with `Error::Interrupted` once `cancel` is cancelled.
pub fn integrate_with<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    cancel: &Cancel,
) -> Result<Trajectory> {
    let (tr, res) = integrate_partial(f, y0, t0, times, opts, cancel)?;
    res.map(|()| tr)
}

/// [`integrate_with`] that keeps what was computed: the outer `Err` is a refused
/// call (bad arguments, over budget: nothing was computed); otherwise the
/// trajectory holds the samples reached (all of them when the inner result is
/// `Ok`, those before the failure or interruption when it is `Err`).
pub fn integrate_partial<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    cancel: &Cancel,
) -> Result<(Trajectory, Result<()>)> {
    let m = f.dim();
    if y0.len() != m {
        return Err(Error::Shape {
            what: "l0",
            expected: format!("({m},)"),
            got: format!("({},)", y0.len()),
        });
    }
    check_finite("l0", y0)?;
    opts.validate()?;
    check_sample_times(t0, times)?;
    check_budget(opts.method, t0, times, opts.dt, opts.max_steps)?;
    taylor_coefficients(f, opts.method)?;
    let mut y = alloc_output(times.len().checked_mul(m))?;
    y.clear();
    let mut out = Trajectory {
        t: Vec::new(),
        y,
        steps: 0,
        evals: 0,
    };
    let res = integrate_into(
        f,
        y0,
        t0,
        times,
        opts,
        &mut out.y,
        &mut out.steps,
        &mut out.evals,
        cancel,
    );
    out.t = times[..out.y.len() / m.max(1)].to_vec();
    Ok((out, res))
}

/// The loop of [`integrate`], appending samples to `ys` (validated inputs).
#[allow(clippy::too_many_arguments)]
fn integrate_into<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    ys: &mut Vec<f64>,
    steps: &mut u64,
    evals: &mut u64,
    cancel: &Cancel,
) -> Result<()> {
    let m = f.dim();
    if opts.method == Method::Taylor {
        let c = taylor_coefficients(f, opts.method)?.ok_or_else(taylor_so4_only)?;
        // One trajectory in a lane group of its own (the other lanes idle), so
        // that it gives the bits of integrate_many.
        let start = ys.len();
        let n = times.len() * m;
        ys.try_reserve_exact(n)
            .map_err(|_| Error::InvalidArgument {
                what: "output size",
                reason: "cannot allocate the samples of one trajectory".into(),
            })?;
        ys.resize(start + n, 0.0);
        let mut progress = taylor::Progress::default();
        let res = taylor::taylor_group(
            c,
            y0,
            t0,
            times,
            taylor_opts(opts),
            &mut ys[start..],
            &mut progress,
            cancel,
        );
        ys.truncate(start + progress.samples0 * m);
        *steps += progress.steps;
        *evals += progress.steps * taylor::order(opts.rtol) as u64;
        return res;
    }
    let mut y = y0.to_vec();
    let mut t = t0;
    if opts.method.stages().is_some() {
        use gauss_tables::*;
        let dt = opts.dt;
        match (opts.method, m) {
            (Method::Gauss4, 6) => run_gauss(
                GaussFixed::<2, 6>::new(&B2, &MU2, &E2),
                f,
                &mut y,
                t0,
                times,
                dt,
                ys,
                steps,
                evals,
                cancel,
            ),
            (Method::Gauss6, 6) => run_gauss(
                GaussFixed::<3, 6>::new(&B3, &MU3, &E3),
                f,
                &mut y,
                t0,
                times,
                dt,
                ys,
                steps,
                evals,
                cancel,
            ),
            (Method::Gauss16, 6) => run_gauss(
                GaussFixed::<8, 6>::new(&B8, &MU8, &E8),
                f,
                &mut y,
                t0,
                times,
                dt,
                ys,
                steps,
                evals,
                cancel,
            ),
            (method, _) => {
                let g = GaussDyn::new(method, m).ok_or_else(|| Error::InvalidArgument {
                    what: "method",
                    reason: "not a Gauss method".into(),
                })?;
                run_gauss(g, f, &mut y, t0, times, dt, ys, steps, evals, cancel)
            }
        }
    } else if opts.method == Method::Dop853 {
        let mut d = dop853::Dop853::new(m, opts.dt, opts.rtol, opts.atol);
        let res = (|| {
            for &tk in times {
                *steps += d.advance(f, &mut y, &mut t, tk, opts.max_steps - *steps, cancel)?;
                ys.extend_from_slice(&y);
            }
            Ok(())
        })();
        *evals += d.evals;
        res
    } else {
        let mut d = Dopri5::new(m, opts);
        let res = (|| {
            for &tk in times {
                *steps += d.advance(f, &mut y, &mut t, tk, opts.max_steps - *steps, cancel)?;
                ys.extend_from_slice(&y);
            }
            Ok(())
        })();
        *evals += d.evals;
        res
    }
}

/// Steps a Gauss method through the sample times, counting steps and evaluations.
#[allow(clippy::too_many_arguments)]
fn run_gauss<S: Stepper, F: VectorField>(
    mut g: S,
    f: &F,
    y: &mut [f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    ys: &mut Vec<f64>,
    steps: &mut u64,
    evals: &mut u64,
    cancel: &Cancel,
) -> Result<()> {
    let mut t = t0;
    let mut since_check = 0u32;
    let res = (|| {
        for &tk in times {
            let span = tk - t;
            if span > 0.0 {
                let n = substeps(span, dt);
                let h = span / n;
                // n ≤ MAX_STEPS < 2^53, so the count is exact.
                for _ in 0..n as u64 {
                    g.step(f, y, h)?;
                    *steps += 1;
                    since_check += 1;
                    if since_check == CHECK_EVERY {
                        since_check = 0;
                        cancel.check()?;
                    }
                }
                t = tk;
            }
            ys.extend_from_slice(y);
        }
        Ok(())
    })();
    *evals += g.evals();
    res
}

/// Trajectories per rayon task of the dop853 and Taylor batch kernels: 8 lane
/// groups, so a lane freed by a finished trajectory is refilled from the same task.
const DOP853_TASK: usize = 8 * LANES;

/// Most trajectories per rayon task of the Taylor batch kernel: 32 lane groups.
/// A lane idles from its task's last trajectory on until the slowest lane ends
/// (trajectories to t = 100 take 264-924 steps on the 1000-state benchmark
/// batch): lane utilisation 94.6 % with tasks of 32 trajectories, 98.6 % with
/// 128. Smaller tasks only to give every thread four (see [`taylor_task`]).
const TAYLOR_TASK: usize = 32 * LANES;

/// The Taylor task size for `rows` trajectories: [`TAYLOR_TASK`], or less (down
/// to [`DOP853_TASK`]) so that a parallel run has four tasks per thread. The
/// lanes are independent, so the split does not change any result.
fn taylor_task(rows: usize, parallel: bool) -> usize {
    if !parallel {
        return TAYLOR_TASK;
    }
    let per = rows / (4 * rayon::current_num_threads().max(1));
    (per / LANES * LANES).clamp(DOP853_TASK, TAYLOR_TASK)
}

fn taylor_so4_only() -> Error {
    Error::InvalidArgument {
        what: "method",
        reason: "taylor is implemented for the so(4) top only (n = 4)".into(),
    }
}

/// The so(4) coefficients of `f` when `method` is Taylor's (which needs them),
/// `None` for other methods; an error for Taylor's method on another field.
fn taylor_coefficients<F: VectorField>(f: &F, method: Method) -> Result<Option<&[f64; 6]>> {
    if method != Method::Taylor {
        return Ok(None);
    }
    f.so4_coefficients().map(Some).ok_or_else(taylor_so4_only)
}

fn taylor_opts(opts: &Options) -> taylor::TaylorOpts {
    taylor::TaylorOpts {
        tol: opts.rtol,
        h_max: opts.dt,
        max_steps: opts.max_steps,
    }
}

/// Integrates a batch of initial states `y0s` (row-major, `(batch, dim)`) with the
/// same options and sample times; returns the states row-major
/// `(batch, samples, dim)` and the total number of steps. With `parallel`, the
/// batch is split over rayon's thread pool.
///
/// For the so(4) top with gauss16 or dop853 the batch runs on the trajectory-lane
/// kernels (see the module docs); the results are those of [`integrate`] state by
/// state, bit for bit. The budget and the output size are checked before any work.
pub fn integrate_many<F: VectorField>(
    f: &F,
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    parallel: bool,
) -> Result<(Vec<f64>, u64)> {
    integrate_many_with(f, y0s, t0, times, opts, parallel, &Cancel::never())
}

/// [`integrate_many`], stopping with `Error::Interrupted` once `cancel` is cancelled.
pub fn integrate_many_with<F: VectorField>(
    f: &F,
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    parallel: bool,
    cancel: &Cancel,
) -> Result<(Vec<f64>, u64)> {
    let m = f.dim();
    if m == 0 || y0s.len() % m != 0 {
        return Err(Error::Shape {
            what: "l0s",
            expected: format!("(batch, {m})"),
            got: format!("{} entries", y0s.len()),
        });
    }
    check_finite("l0s", y0s)?;
    opts.validate()?;
    check_sample_times(t0, times)?;
    check_budget(opts.method, t0, times, opts.dt, opts.max_steps)?;
    taylor_coefficients(f, opts.method)?;
    let rows = y0s.len() / m;
    let per = times.len() * m;
    let mut out = alloc_output(rows.checked_mul(per))?;
    if out.is_empty() {
        return Ok((out, 0));
    }
    let lanes = f.so4_coefficients().filter(|_| {
        matches!(
            opts.method,
            Method::Gauss16 | Method::Dop853 | Method::Taylor
        )
    });
    // One task's worth of work runs on the calling thread: no pool, no poller thread.
    let task = match (lanes, opts.method) {
        (Some(_), Method::Gauss16) => LANES,
        (Some(_), Method::Taylor) => taylor_task(rows, parallel),
        (Some(_), _) => DOP853_TASK,
        (None, _) => 1,
    };
    let parallel = parallel && rows > task;
    let mut run = || -> Result<u64> {
        let steps: Vec<u64> = match lanes {
            Some(c) if opts.method == Method::Gauss16 => {
                let group = |(y0, o): (&[f64], &mut [f64])| -> Result<u64> {
                    let n = batch::gauss16_group(c, y0, t0, times, opts.dt, o, cancel)?;
                    Ok(n * (y0.len() / m) as u64)
                };
                let (gy, go) = (LANES * m, LANES * per);
                if parallel {
                    y0s.par_chunks(gy)
                        .zip(out.par_chunks_mut(go))
                        .map(group)
                        .collect::<Result<_>>()?
                } else {
                    y0s.chunks(gy)
                        .zip(out.chunks_mut(go))
                        .map(group)
                        .collect::<Result<_>>()?
                }
            }
            Some(c) if opts.method == Method::Taylor => {
                let to = taylor_opts(opts);
                let group = |(y0, o): (&[f64], &mut [f64])| -> Result<u64> {
                    let mut progress = taylor::Progress::default();
                    taylor::taylor_group(c, y0, t0, times, to, o, &mut progress, cancel)?;
                    Ok(progress.steps)
                };
                let (gy, go) = (task * m, task * per);
                if parallel {
                    y0s.par_chunks(gy)
                        .zip(out.par_chunks_mut(go))
                        .map(group)
                        .collect::<Result<_>>()?
                } else {
                    y0s.chunks(gy)
                        .zip(out.chunks_mut(go))
                        .map(group)
                        .collect::<Result<_>>()?
                }
            }
            Some(c) => {
                let o8 = batch::Dop853Opts {
                    h0: opts.dt,
                    rtol: opts.rtol,
                    atol: opts.atol,
                    max_steps: opts.max_steps,
                };
                let group = |(y0, o): (&[f64], &mut [f64])| {
                    batch::dop853_group(c, y0, t0, times, o8, o, cancel)
                };
                let (gy, go) = (DOP853_TASK * m, DOP853_TASK * per);
                if parallel {
                    y0s.par_chunks(gy)
                        .zip(out.par_chunks_mut(go))
                        .map(group)
                        .collect::<Result<_>>()?
                } else {
                    y0s.chunks(gy)
                        .zip(out.chunks_mut(go))
                        .map(group)
                        .collect::<Result<_>>()?
                }
            }
            None => {
                let one = |(y0, chunk): (&[f64], &mut [f64])| -> Result<u64> {
                    let mut ys = Vec::new();
                    ys.try_reserve_exact(per)
                        .map_err(|_| Error::InvalidArgument {
                            what: "output size",
                            reason: "cannot allocate the scratch of one trajectory".into(),
                        })?;
                    let (mut steps, mut evals) = (0, 0);
                    integrate_into(
                        f, y0, t0, times, opts, &mut ys, &mut steps, &mut evals, cancel,
                    )?;
                    chunk.copy_from_slice(&ys);
                    Ok(steps)
                };
                if parallel {
                    y0s.par_chunks(m)
                        .zip(out.par_chunks_mut(per))
                        .map(one)
                        .collect::<Result<_>>()?
                } else {
                    y0s.chunks(m)
                        .zip(out.chunks_mut(per))
                        .map(one)
                        .collect::<Result<_>>()?
                }
            }
        };
        Ok(steps.iter().sum())
    };
    let steps = if parallel {
        poll_during(cancel, run)
    } else {
        run()
    }?;
    Ok((out, steps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::so4::{integrals4, FrahmTop};
    use approx::assert_relative_eq;

    const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
    const B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];
    const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];

    /// Harmonic oscillator ẋ = v, v̇ = -x: exact solution known.
    struct Osc;
    impl VectorField for Osc {
        fn dim(&self) -> usize {
            2
        }
        fn eval(&self, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    fn opts(method: Method, dt: f64) -> Options {
        Options {
            method,
            dt,
            rtol: 1e-10,
            atol: 1e-10,
            max_steps: MAX_STEPS as u64,
        }
    }

    /// rtol below 100 ε is refused for the explicit methods (rtol = atol = 1e-300 once
    /// overflowed the error norm and failed as "state became non-finite"); the Gauss
    /// methods ignore rtol. At the floor with atol = 0 and a zero component (0/0 in the
    /// norms before) dopri5 and dop853 run and stay on the circle.
    #[test]
    fn rtol_floor_and_zero_scale_components() {
        for m in [Method::Dopri5, Method::Dop853] {
            for (rtol, atol) in [(1e-300, 1e-300), (0.0, 1e-12), (RTOL_MIN * 0.999, 1.0)] {
                let o = Options {
                    rtol,
                    atol,
                    ..opts(m, 0.0)
                };
                match integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o) {
                    Err(Error::InvalidArgument { what: "rtol", .. }) => {}
                    other => panic!("{m:?} {rtol}: {other:?}"),
                }
            }
            for atol in [0.0, 1e-300] {
                let o = Options {
                    rtol: RTOL_MIN,
                    atol,
                    ..opts(m, 0.0)
                };
                let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o).unwrap();
                let r2 = tr.y[0] * tr.y[0] + tr.y[1] * tr.y[1];
                // the explicit methods' per-step error at rtol = 100 ε over t = 1
                assert!((r2 - 1.0).abs() < 1e-12, "{m:?} atol {atol}: r² = {r2}");
            }
        }
        let o = Options {
            rtol: 0.0,
            atol: 0.0,
            ..opts(Method::Gauss6, 0.1)
        };
        assert!(integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o).is_ok());
    }

    #[test]
    fn tableaux_satisfy_collocation_conditions() {
        for m in [Method::Gauss4, Method::Gauss6, Method::Gauss16] {
            let (c, b, mu) = m.gauss_tableau().unwrap();
            let s = b.len();
            for i in 0..s {
                for j in 0..s {
                    // Symplecticity held exactly in floating point.
                    assert_eq!(mu[i * s + j] + mu[j * s + i], 1.0);
                }
            }
            for k in 1..=2 * s {
                let q: f64 = (0..s).map(|i| b[i] * c[i].powi(k as i32 - 1)).sum();
                assert_relative_eq!(q, 1.0 / k as f64, max_relative = 1e-14);
            }
        }
    }

    #[test]
    fn gauss_orders_on_the_oscillator() {
        // Error ratio for halving dt ≈ 2^p.
        for (m, p, dt) in [
            (Method::Gauss4, 4.0, 0.2),
            (Method::Gauss6, 6.0, 0.4),
            (Method::Dopri5, 5.0, 0.0),
        ] {
            let err = |dt: f64| {
                let mut o = opts(m, dt);
                if m == Method::Dopri5 {
                    o.rtol = dt;
                    o.atol = dt;
                }
                let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &[2.0], &o).unwrap();
                ((tr.y[0] - 2f64.cos()).powi(2) + (tr.y[1] + 2f64.sin()).powi(2)).sqrt()
            };
            if m == Method::Dopri5 {
                // Tolerance proportionality: error shrinks with tol.
                assert!(err(1e-10) < 1e-8 && err(1e-6) < 1e-4);
                continue;
            }
            let ratio = err(dt) / err(dt / 2.0);
            assert!(
                (ratio.log2() - p).abs() < 0.3,
                "{m:?}: observed order {}",
                ratio.log2()
            );
        }
    }

    #[test]
    fn dopri5_tableau_satisfies_order_conditions() {
        for i in 0..7 {
            let s: f64 = DP_A[i].iter().sum();
            assert!((s - DP_C[i]).abs() < 1e-14, "row {i}");
        }
        for k in 0..5 {
            let s: f64 = (0..7).map(|i| DP_B[i] * DP_C[i].powi(k)).sum();
            assert_relative_eq!(s, 1.0 / (k as f64 + 1.0), max_relative = 1e-14);
        }
        for k in 0..4 {
            let s: f64 = (0..7).map(|i| DP_BHAT[i] * DP_C[i].powi(k)).sum();
            assert_relative_eq!(s, 1.0 / (k as f64 + 1.0), max_relative = 1e-14);
        }
    }

    #[test]
    fn dop853_is_eighth_order_on_the_oscillator() {
        // Fixed steps through the sampling: with huge tolerances no step is
        // rejected, and steps of 0.1 land on the samples.
        let err = |h: f64| {
            let times: Vec<f64> = (1..=(2.0 / h).round() as usize)
                .map(|k| k as f64 * h)
                .collect();
            let o = Options {
                method: Method::Dop853,
                dt: h,
                rtol: 1e3,
                atol: 1e3,
                max_steps: MAX_STEPS as u64,
            };
            let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &times, &o).unwrap();
            let n = tr.y.len();
            (tr.y[n - 2] - 2f64.cos()).abs()
        };
        let ratio = err(0.2) / err(0.1);
        assert!((ratio.log2() - 8.0).abs() < 0.5, "order {}", ratio.log2());
    }

    #[test]
    fn gauss16_is_exact_to_roundoff_on_the_oscillator() {
        let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &[10.0], &opts(Method::Gauss16, 0.5)).unwrap();
        assert!((tr.y[0] - 10f64.cos()).abs() < 1e-13);
        assert_eq!(tr.steps, 20);
    }

    #[test]
    fn gauss_keeps_the_integrals_on_generic() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        let times: Vec<f64> = (1..=100).map(|k| k as f64).collect();
        for m in [Method::Gauss4, Method::Gauss6, Method::Gauss16] {
            let tr = integrate(&top, &L0, 0.0, &times, &opts(m, 0.05)).unwrap();
            let h0 = integrals4(&A, &L0);
            let last: [f64; 6] = tr.y[tr.y.len() - 6..].try_into().unwrap();
            let h = integrals4(&A, &last);
            for i in 0..4 {
                // Roundoff only: ~2000 steps, sqrt growth → a few 1e-15.
                assert_relative_eq!(h[i], h0[i], max_relative = 1e-13);
            }
        }
    }

    #[test]
    fn bad_options_are_errors() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        for dt in [0.0, -1.0, f64::NAN] {
            assert!(integrate(&top, &L0, 0.0, &[1.0], &opts(Method::Gauss6, dt)).is_err());
        }
        assert!(integrate(&top, &L0, 0.0, &[2.0, 1.0], &opts(Method::Gauss6, 0.1)).is_err());
        assert!(integrate(&top, &L0, 0.0, &[1e300], &opts(Method::Gauss6, 1e-300)).is_err());
        assert!(matches!(
            integrate(&top, &L0, 0.0, &[10.0], &opts(Method::Gauss6, 10.0)),
            Err(Error::NoConvergence { .. })
        ));
    }

    #[test]
    fn batch_matches_single_runs() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        let mut y0s = L0.to_vec();
        y0s.extend(L0.iter().map(|x| 0.5 * x));
        let times = [0.0, 1.0, 2.0];
        let o = opts(Method::Gauss6, 0.1);
        for parallel in [false, true] {
            let (ys, _) = integrate_many(&top, &y0s, 0.0, &times, &o, parallel).unwrap();
            for (b, y0) in y0s.chunks(6).enumerate() {
                let tr = integrate(&top, y0, 0.0, &times, &o).unwrap();
                assert_eq!(&ys[b * 18..(b + 1) * 18], &tr.y[..]);
            }
        }
    }

    /// Pseudo-random states (seeded LCG), entries in [-1, 1).
    fn states(seed: u64, rows: usize) -> Vec<f64> {
        let mut s = seed;
        (0..rows * 6)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            })
            .collect()
    }

    /// The lane kernels (gauss16, dop853) give exactly the single-trajectory
    /// results, for batch sizes that are not multiples of the lane width, with
    /// repeated and zero-length sample intervals.
    #[test]
    fn lane_kernels_match_single_runs_bit_for_bit() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        let times = [0.0, 0.7, 0.7, 2.0, 3.5];
        for rows in [1usize, 3, 7, 37] {
            let y0s = states(rows as u64, rows);
            for (m, dt) in [
                (Method::Gauss16, 0.3),
                (Method::Dop853, 0.0),
                (Method::Taylor, 0.0),
                (Method::Taylor, 0.3),
            ] {
                let o = opts(m, dt);
                for parallel in [false, true] {
                    let (ys, steps) =
                        integrate_many(&top, &y0s, 0.0, &times, &o, parallel).unwrap();
                    let mut want_steps = 0;
                    for (b, y0) in y0s.chunks(6).enumerate() {
                        let tr = integrate(&top, y0, 0.0, &times, &o).unwrap();
                        let got = &ys[b * 30..(b + 1) * 30];
                        let same = got
                            .iter()
                            .zip(&tr.y)
                            .all(|(x, y)| x.to_bits() == y.to_bits());
                        assert!(same, "{m:?} rows {rows} state {b}: {got:?} vs {:?}", tr.y);
                        want_steps += tr.steps;
                    }
                    assert_eq!(steps, want_steps, "{m:?} rows {rows}");
                }
            }
        }
    }

    /// A cancelled token stops every path with `Interrupted`.
    #[test]
    fn cancelled_runs_stop() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        let c = Cancel::never();
        c.cancel();
        let y0s = states(5, 9);
        for (m, dt) in [
            (Method::Gauss16, 0.3),
            (Method::Dop853, 0.0),
            (Method::Gauss6, 0.01),
            (Method::Dopri5, 0.0),
            (Method::Taylor, 0.0),
        ] {
            let o = opts(m, dt);
            let r = integrate_with(&top, &L0, 0.0, &[1e3], &o, &c);
            assert_eq!(r.unwrap_err(), Error::Interrupted, "{m:?}");
            for parallel in [false, true] {
                let r = integrate_many_with(&top, &y0s, 0.0, &[1e3], &o, parallel, &c);
                assert_eq!(r.unwrap_err(), Error::Interrupted, "{m:?}");
            }
        }
    }

    /// Taylor's method: its tolerance range is checked, it refuses any field but
    /// so(4)'s, and it stays on the flow: against gauss16 at a small step (a
    /// different method, converged to roundoff) on 'generic''s l0 to t = 10.
    #[test]
    fn taylor_checks_and_agrees_with_gauss16() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        for rtol in [0.0, f64::EPSILON / 2.0, 2e-3, f64::NAN] {
            let o = Options {
                rtol,
                ..opts(Method::Taylor, 0.0)
            };
            match integrate(&top, &L0, 0.0, &[1.0], &o) {
                Err(Error::InvalidArgument { what: "rtol", .. }) => {}
                other => panic!("rtol {rtol}: {other:?}"),
            }
        }
        let o = Options {
            rtol: f64::EPSILON,
            ..opts(Method::Taylor, 0.0)
        };
        for r in [
            integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o).map(|_| ()),
            integrate_many(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o, false).map(|_| ()),
        ] {
            assert!(matches!(
                r,
                Err(Error::InvalidArgument { what: "method", .. })
            ));
        }
        let times = [0.0, 2.5, 10.0];
        let tr = integrate(&top, &L0, 0.0, &times, &o).unwrap();
        let g = integrate(&top, &L0, 0.0, &times, &opts(Method::Gauss16, 0.02)).unwrap();
        for (a, b) in tr.y.iter().zip(&g.y) {
            // both at roundoff: ~100-500 steps, O(1) state
            assert!((a - b).abs() < 1e-13, "{a} vs {b}");
        }
        assert_eq!(&tr.y[..6], &L0[..], "the sample at t0 is the initial state");
        assert_eq!(tr.evals, tr.steps * taylor::order(f64::EPSILON) as u64);
    }

    /// Over-budget runs are refused before any work, naming the cause.
    #[test]
    fn budget_is_checked_first_and_names_the_cause() {
        let spacing: Vec<f64> = (1..=100).map(f64::from).collect();
        let e = check_budget(Method::Dop853, 0.0, &spacing, 0.0, 50).unwrap_err();
        assert!(e.to_string().contains("sample spacing"), "{e}");
        let e = check_budget(Method::Gauss16, 0.0, &[1e6], 0.1, 1000).unwrap_err();
        assert!(e.to_string().contains("dt:"), "{e}");
        // 100 intervals of 1 at dt = 0.6: 200 steps, although 100 / 0.6 < 170.
        let e = check_budget(Method::Gauss16, 0.0, &spacing, 0.6, 170).unwrap_err();
        assert!(e.to_string().contains("sample spacing"), "{e}");
        assert!(check_budget(Method::Gauss16, 0.0, &spacing, 0.6, 200).is_ok());
    }

    /// An output that cannot be allocated is an error, not an abort.
    #[test]
    fn huge_output_is_an_error() {
        assert!(alloc_output(None).is_err());
        assert!(alloc_output(Some(usize::MAX / 4)).is_err());
        assert_eq!(alloc_output(Some(3)).unwrap(), vec![0.0; 3]);
    }

    #[test]
    fn subnormal_steps_restart_the_stages() {
        // A subnormal h once made 0/0 (h b_j) in the predictor and an infinite
        // ratio h / last_h on the next normal step.
        let top = FrahmTop::manakov(&A, &B).unwrap();
        let times = [1e-320, 2e-320, 1.0];
        for m in [Method::Gauss4, Method::Gauss16] {
            let tr = integrate(&top, &L0, 0.0, &times, &opts(m, 0.05)).unwrap();
            assert_eq!(&tr.y[..6], &L0[..], "a subnormal step cannot move l");
            let direct = integrate(&top, &L0, 0.0, &[1.0], &opts(m, 0.05)).unwrap();
            for k in 0..6 {
                // Same step on [0, 1]; only the restart of the stage guess differs.
                assert!((tr.y[12 + k] - direct.y[k]).abs() < 1e-14);
            }
        }
        let osc = integrate(
            &Osc,
            &[1.0, 0.0],
            0.0,
            &[5e-324, 1.0],
            &opts(Method::Gauss6, 0.1),
        );
        assert!(osc.unwrap().y.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn step_budget_counts_every_sample_of_a_call() {
        let top = FrahmTop::manakov(&A, &B).unwrap();
        let times: Vec<f64> = (1..=100).map(f64::from).collect();
        for m in [Method::Dopri5, Method::Dop853, Method::Gauss6] {
            let mut o = opts(m, if m == Method::Gauss6 { 0.1 } else { 0.0 });
            let full = integrate(&top, &L0, 0.0, &times, &o).unwrap();
            // Each sample interval needs fewer steps than the budget, the call more.
            o.max_steps = full.steps / 2;
            let err = integrate(&top, &L0, 0.0, &times, &o).unwrap_err();
            assert!(err.to_string().contains("max_steps"), "{err}");
            o.max_steps = full.steps;
            assert_eq!(integrate(&top, &L0, 0.0, &times, &o).unwrap().y, full.y);
        }
        let mut o = opts(Method::Gauss6, 0.1);
        o.max_steps = 0;
        assert!(o.validate().is_err());
    }
}
