//! Gauss–Legendre collocation (`gauss4`, `gauss6`, `gauss16`): the stage
//! equations solved by fixed-point iteration until the increments stop
//! decreasing, the compensated update, and the stepping through the sample
//! times (Antoñana, Makazaga & Murua 2017; see the module docs).

use super::{substeps, Method, Trajectory, VectorField};
use crate::error::{Error, Result};
use crate::numeric::cancel::{Cancel, CHECK_EVERY};

/// Fixed-point iterations allowed per Gauss step. Convergence is linear with
/// ratio ~ h·‖∂f‖; at the default steps ~10–20 iterations reach roundoff.
pub const MAX_FIXED_POINT_ITER: usize = 100;

/// A Gauss step whose iteration stalls with increments above this fraction of
/// the state's size did not converge (a converged iteration stalls at roundoff,
/// ~1e-16 of it): the step is too large for fixed-point iteration.
pub const STALL_RTOL: f64 = 1e-8;

/// Whether a Gauss step of size `h` may start from the stages of the previous
/// step (size `last_h`, 0 before the first step). Only between normal sizes with
/// a finite ratio: with a subnormal `h` the products `h b_j` underflow, and a
/// ratio `h / last_h` can overflow; both once made NaN stages.
pub(super) fn reuse_stages(last_h: f64, h: f64) -> bool {
    last_h.is_normal() && h.is_normal() && (h / last_h).is_finite()
}

/// Stopping rule of the stage iteration: stop once the increments stop
/// decreasing (Antoñana, Makazaga & Murua 2017). Roundoff makes converged
/// increments wobble, so an increment that fails to beat the smallest so far
/// ends the iteration only once that smallest one is at roundoff level
/// (`ROUNDOFF_RTOL`); above it, two failures in a row are needed.
pub(super) struct StopRule {
    best: f64,
    stalls: u32,
    pub(super) iterations: usize,
}

/// Increments below this fraction of the state's size are roundoff: 10^4 ulps.
const ROUNDOFF_RTOL: f64 = 1e4 * f64::EPSILON;

impl StopRule {
    pub(super) fn new() -> Self {
        StopRule {
            best: f64::INFINITY,
            stalls: 0,
            iterations: 0,
        }
    }

    /// Records one iteration's largest increment; `Ok(true)` means stop.
    pub(super) fn update(&mut self, dmax: f64, ymax: f64) -> Result<bool> {
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
pub(super) trait Stepper {
    fn step<F: VectorField>(&mut self, f: &F, y: &mut [f64], h: f64) -> Result<()>;
    fn evals(&self) -> u64;
}

/// Gauss–Legendre stepper on fixed-size arrays (`S` stages, state dimension
/// `M`), stored component-major (`[component][stage]`) so that the stage sums
/// and the vector field run across the `S` stages as SIMD lanes
/// ([`VectorField::eval_lanes`]). Used for so(4), `M = 6`.
pub(super) struct GaussFixed<const S: usize, const M: usize> {
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
    pub(super) fn new(b: &[f64; S], mu: &[[f64; S]; S], e: &[[f64; S]; S]) -> Self {
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

impl<const S: usize, const M: usize> GaussFixed<S, M> {
    /// The stages' starting guess: `f(y)` on the first step (or after a step
    /// size that cannot be rescaled), the previous step's collocation
    /// polynomial extrapolated when `h` repeats, else the previous stages
    /// rescaled by `h / last_h`.
    #[inline(always)]
    fn start_stages<F: VectorField>(&mut self, f: &F, y: &[f64; M], h: f64, hb: &[f64; S]) {
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
        self.start_stages(f, y, h, &hb);
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
pub(super) struct GaussDyn {
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
    pub(super) fn new(method: Method, m: usize) -> Option<Self> {
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

/// Steps a Gauss method through the sample times, counting steps and evaluations.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_gauss<S: Stepper, F: VectorField>(
    mut g: S,
    f: &F,
    y: &mut [f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut Trajectory,
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
                    out.steps += 1;
                    since_check += 1;
                    if since_check == CHECK_EVERY {
                        since_check = 0;
                        cancel.check()?;
                    }
                }
                t = tk;
            }
            out.y.extend_from_slice(y);
            cancel.advance(1);
        }
        Ok(())
    })();
    out.evals += g.evals();
    res
}
