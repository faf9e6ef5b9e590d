//! Taylor's method for the so(4) field (1), vector lanes across trajectories.
//!
//! **Coefficients.** The field is quadratic: each component of `l̇` is two
//! products `l_a l_b` times constants (`s_q` below, the `c_kj − c_ik` of (1)
//! with their signs). With `x(t + τ) = Σ_n X_n τ^n`, the coefficients follow
//! from the Cauchy products of the series,
//!
//! `X_{n+1,k} = (s_{2k} P_{2k,n} + s_{2k+1} P_{2k+1,n}) / (n + 1)`,
//! `P_{q,n} = Σ_{j=0..n} X_{j,a_q} X_{n−j,b_q}`,
//!
//! twelve products per order, `6 p (p + 1)` multiply–adds for order `p`
//! (automatic differentiation of a polynomial field: R. E. Moore, *Interval
//! Analysis*, 1966; A. Jorba, M. Zou, *A software package for the numerical
//! integration of ODEs by means of high-order Taylor methods*, Exp. Math. 14
//! (2005) 99–117). The series is computed in the scaled time `σ = τ / h_s`
//! (`h_s` the lane's previous step), so the coefficients stay of the size of
//! the state whatever `|l|` is, instead of growing like `(|l| Δc)^n`.
//!
//! **Order and step** (Jorba & Zou §3.2, as used by heyoka: F. Biscani, D. Izzo,
//! MNRAS 504 (2021) 2614): for a relative tolerance `ε`, the order is
//! `p = ⌈−ln ε / 2 + 1⌉` and the step `h = ρ e^{−2} e^{−0.7/(p−1)}`, with the
//! radius of convergence estimated from the last two coefficients,
//! `ρ = min((‖x‖/‖X_{p−1}‖)^{1/(p−1)}, (‖x‖/‖X_p‖)^{1/p})` (max norms; relative,
//! so the method is invariant under `l → s l`, `t → t / s`). Each lane keeps
//! its own step; a lane whose trajectory is done is refilled with the next one.
//!
//! **Samples** are dense output: the step's Taylor polynomial evaluated at the
//! sample time (no step is shortened for a sample but the last one, which ends
//! exactly on the last sample time).
//!
//! **Same bits everywhere.** Every lane does its own arithmetic only (steps
//! are per lane), so a trajectory gives the same bits in any lane of any group:
//! `integrate` (one lane used) and `integrate_many` agree bit for bit. The
//! AVX2 copy uses FMA instructions and the baseline copy `f64::mul_add`, both
//! one rounding, so the CPU does not change the result either.

// Index loops mirror the subscripts of the formulas (n orders; k components; w lanes).
#![allow(clippy::needless_range_loop)]

use super::batch::{Lanes, V, W};
use crate::error::{Error, Result};
use crate::numeric::cancel::{Cancel, CHECK_EVERY};
use crate::numeric::compensated;

/// so(4) state length.
const M: usize = 6;
/// Highest order: `p(ε = f64::EPSILON) = ⌈18.02 + 1⌉ = 20`.
pub const MAX_ORDER: usize = 20;

/// Smallest relative tolerance: machine epsilon (a tighter one would only
/// raise the order past the rounding of the sums).
pub const TOL_MIN: f64 = f64::EPSILON;
/// Largest relative tolerance, `1e-3` (order 5): below that order the step is
/// no longer set by the series' radius of convergence but by its first terms.
pub const TOL_MAX: f64 = 1e-3;

/// The products `l_a l_b` of (1), two per component (`2k`, `2k + 1` for
/// component `k`), components ordered `(l12, l13, l14, l23, l24, l34)`.
const PRODUCTS: [(usize, usize); 12] = [
    (1, 3),
    (2, 4),
    (0, 3),
    (2, 5),
    (0, 4),
    (1, 5),
    (0, 1),
    (4, 5),
    (3, 5),
    (0, 2),
    (1, 2),
    (3, 4),
];

/// The order for a relative tolerance `tol` (Jorba & Zou: `⌈−ln ε / 2 + 1⌉`).
pub fn order(tol: f64) -> usize {
    ((-tol.ln() / 2.0 + 1.0).ceil() as usize).clamp(2, MAX_ORDER)
}

/// The signed constants `s_q` of the products (see [`PRODUCTS`]): `l̇_k =
/// s_{2k} l_a l_b + s_{2k+1} l_a' l_b'`, from the `c_ij` of (1) (the same
/// differences as `so4::vector_field4`).
fn product_coefficients(c: &[f64; 6]) -> [f64; 12] {
    let [c12, c13, c14, c23, c24, c34] = *c;
    [
        -(c23 - c13),
        -(c24 - c14),
        c23 - c12,
        -(c34 - c14),
        c24 - c12,
        c34 - c13,
        -(c13 - c12),
        -(c34 - c24),
        c34 - c23,
        -(c14 - c12),
        -(c14 - c13),
        -(c24 - c23),
    ]
}

/// Options of the Taylor lane group.
#[derive(Clone, Copy, Debug)]
pub(super) struct TaylorOpts {
    /// Relative tolerance `ε` per step, in [`TOL_MIN`, `TOL_MAX`].
    pub tol: f64,
    /// Largest step (0: none).
    pub h_max: f64,
    /// Step budget of each trajectory.
    pub max_steps: u64,
}

/// Progress of a group run, kept up to date while it runs (so that a failed or
/// interrupted single-trajectory run can return the samples it reached).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Progress {
    /// Accepted steps of the trajectories finished so far.
    pub steps: u64,
    /// Samples written for trajectory 0.
    pub samples0: usize,
}

/// Taylor's method on the trajectories `y0s` (row-major, `rows · 6`, any
/// number of rows) through the sorted `times` (all `≥ t0`), `W` at a time with
/// refill, writing `(rows, times.len(), 6)` into `out`.
#[allow(clippy::too_many_arguments)]
pub(super) fn taylor_group(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    o: TaylorOpts,
    out: &mut [f64],
    progress: &mut Progress,
    cancel: &Cancel,
) -> Result<()> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            return unsafe { taylor_group_avx2(c, y0s, t0, times, o, out, progress, cancel) };
        }
    }
    taylor_group_body::<V>(c, y0s, t0, times, o, out, progress, cancel)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[allow(clippy::too_many_arguments)]
unsafe fn taylor_group_avx2(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    o: TaylorOpts,
    out: &mut [f64],
    progress: &mut Progress,
    cancel: &Cancel,
) -> Result<()> {
    taylor_group_body::<super::batch::avx::F64x4>(c, y0s, t0, times, o, out, progress, cancel)
}

/// `X[n][k][w]`: coefficient `n` of component `k` of lane `w`, in scaled time.
type Coeffs = [[V; M]; MAX_ORDER + 1];

/// Taylor's method on the lane group (see [`taylor_group`]): record the
/// samples the lanes have reached and refill finished lanes, the series, the
/// step of each lane, the samples inside the step (dense output), the update
/// of the state and of the time. Every step is `#[inline(always)]`: the body
/// is instantiated inside the AVX2 `#[target_feature]` copy, and its steps
/// must be compiled with the same features.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn taylor_group_body<L: Lanes>(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    o: TaylorOpts,
    out: &mut [f64],
    progress: &mut Progress,
    cancel: &Cancel,
) -> Result<()> {
    let Some(&t_last) = times.last() else {
        return Ok(());
    };
    let run = TaylorRun::<L>::new(c, y0s, t0, times, t_last, o);
    let mut sink = Samples {
        out,
        per: times.len() * M,
        progress,
        cancel,
    };
    // The series stays out of the lane-state struct: with it inside (an array
    // indexed by the order at run time) the kernel ran ~30 % slower (256
    // states to t = 500, interleaved runs of both builds); outside, as fast as
    // the former single body (~4 % faster).
    let mut x: Coeffs = [[[0.0; W]; M]; MAX_ORDER + 1];
    let mut lanes = TaylorLanes::new(t0);
    let mut since_check = 0u32;
    loop {
        if !lanes.record_and_refill(&mut x, &run, &mut sink) {
            return Ok(());
        }
        since_check += 1;
        if since_check == CHECK_EVERY {
            since_check = 0;
            cancel.check()?;
        }
        lanes.series(&mut x, &run);
        let step = lanes.step_sizes(&x, &run)?;
        lanes.dense_output(&x, &run, &step, &mut sink);
        compensated_update::<L>(&mut x, &mut lanes.comp, run.p, &step.sigma, &step.h, &run.s);
        lanes.advance_time(&x, &run, &step)?;
    }
}

/// What a run of the lane group does not change: the trajectories, the sample
/// times, the tolerance's order and step factor, and the field's constants.
struct TaylorRun<'a, L: Lanes> {
    y0s: &'a [f64],
    times: &'a [f64],
    t0: f64,
    t_last: f64,
    o: TaylorOpts,
    rows: usize,
    ns: usize,
    /// The order `p`.
    p: usize,
    /// The constants `s_q` of the products, on every lane.
    s: [L; 12],
    /// `max |s_q|`, for the time scale of a fresh lane.
    smax: f64,
    /// The step factor: `h = ρ · safety`.
    safety: f64,
    /// `1/n` (0 for `n = 0`).
    inv: [f64; MAX_ORDER + 1],
}

impl<'a, L: Lanes> TaylorRun<'a, L> {
    #[inline(always)]
    fn new(
        c: &[f64; 6],
        y0s: &'a [f64],
        t0: f64,
        times: &'a [f64],
        t_last: f64,
        o: TaylorOpts,
    ) -> Self {
        let rows = y0s.len() / M;
        let ns = times.len();
        let p = order(o.tol);
        let sq = product_coefficients(c);
        let s = sq.map(L::splat);
        // Fresh lanes start from the time scale 1 / (‖x‖ max|s_q|), a bound on the
        // Lipschitz constant of (1) up to a factor of order one.
        let smax = sq.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // Jorba & Zou's h = ρ e^{-2}, with heyoka's e^{-0.7/(p-1)} for the estimate
        // of ρ from two coefficients. (A step ρ ε^{1/p}, whose last kept term is
        // exactly ε, is 1.2x longer at ε = eps but measured no faster at equal
        // error: the larger steps need the next tighter ε.)
        let safety = (-2.0 - 0.7 / (p as f64 - 1.0)).exp();
        let inv: [f64; MAX_ORDER + 1] =
            std::array::from_fn(|n| if n == 0 { 0.0 } else { 1.0 / n as f64 });
        TaylorRun {
            y0s,
            times,
            t0,
            t_last,
            o,
            rows,
            ns,
            p,
            s,
            smax,
            safety,
            inv,
        }
    }
}

/// Where the samples go: `out` (`(rows, times.len(), 6)`, `per` values per
/// trajectory), with the progress of the run and the cancellation token's count.
struct Samples<'a> {
    out: &'a mut [f64],
    per: usize,
    progress: &'a mut Progress,
    cancel: &'a Cancel,
}

impl Samples<'_> {
    /// The row of sample `s` of trajectory `j`.
    #[inline(always)]
    fn row(&mut self, j: usize, s: usize) -> &mut [f64] {
        let per = self.per;
        &mut self.out[j * per + s * M..j * per + (s + 1) * M]
    }

    /// Counts a sample written for trajectory `j`, whose next sample is `idx`.
    #[inline(always)]
    fn written(&mut self, j: usize, idx: usize) {
        self.cancel.advance(1);
        if j == 0 {
            self.progress.samples0 = idx;
        }
    }
}

/// The state of the `W` lanes, each carrying one trajectory at a time.
struct TaylorLanes {
    // Time of each lane as an unevaluated sum t + t_lo (two-sum after every
    // step): a plain t += h loses half an ulp of t per step, and over 700 steps
    // to t = 100 that random walk in time alone put ~1e-12 into l.
    t: [f64; W],
    t_lo: [f64; W],
    // Compensation of the state update (the low bits lost in x + δ), as in
    // the Gauss steppers (Kahan).
    comp: [[f64; W]; M],
    // Scaled-time unit of each lane: its previous (unclamped) step.
    hs: [f64; W],
    /// The next sample of each lane.
    idx: [usize; W],
    /// Accepted steps of each lane's trajectory.
    taken: [u64; W],
    /// Each lane's trajectory (`None`: idle).
    traj: [Option<usize>; W],
    /// The next trajectory to load.
    next: usize,
}

/// The step of each lane ([`TaylorLanes::step_sizes`]).
struct LaneSteps {
    /// The scaled-time unit the coefficients were computed in.
    unit: V,
    /// The step in scaled time.
    sigma: V,
    /// The step in time.
    h: V,
    /// The step ends on the last sample time.
    last: [bool; W],
}

impl TaylorLanes {
    #[inline(always)]
    fn new(t0: f64) -> Self {
        TaylorLanes {
            t: [t0; W],
            t_lo: [0.0f64; W],
            comp: [[0.0f64; W]; M],
            hs: [1.0f64; W],
            idx: [0usize; W],
            taken: [0u64; W],
            traj: [None; W],
            next: 0usize,
        }
    }

    /// Samples at the lanes' current times; refill finished lanes. Returns
    /// whether any lane still has a trajectory.
    #[inline(always)]
    fn record_and_refill<L: Lanes>(
        &mut self,
        x: &mut Coeffs,
        run: &TaylorRun<L>,
        sink: &mut Samples,
    ) -> bool {
        let mut any = false;
        for w in 0..W {
            loop {
                let Some(j) = self.traj[w] else {
                    if self.next == run.rows {
                        break;
                    }
                    self.load(x, w, run);
                    continue;
                };
                if self.idx[w] < run.ns
                    && (run.times[self.idx[w]] - self.t[w]) - self.t_lo[w] <= 0.0
                {
                    let s = self.idx[w];
                    let dst = sink.row(j, s);
                    for k in 0..M {
                        dst[k] = x[0][k][w] + self.comp[k][w];
                    }
                    self.idx[w] += 1;
                    sink.written(j, self.idx[w]);
                    continue;
                }
                if self.idx[w] == run.ns {
                    sink.progress.steps += self.taken[w];
                    self.traj[w] = None;
                    for k in 0..M {
                        x[0][k][w] = 0.0;
                    }
                    continue;
                }
                break;
            }
            any |= self.traj[w].is_some();
        }
        any
    }

    /// Loads the next trajectory into lane `w`, with the time scale of a
    /// fresh lane.
    #[inline(always)]
    fn load<L: Lanes>(&mut self, x: &mut Coeffs, w: usize, run: &TaylorRun<L>) {
        let next = self.next;
        let y0 = &run.y0s[next * M..(next + 1) * M];
        let mut ymax = 0.0f64;
        for k in 0..M {
            x[0][k][w] = y0[k];
            ymax = ymax.max(y0[k].abs());
        }
        let scale = ymax * run.smax;
        self.hs[w] = if scale > 0.0 && scale.is_finite() {
            1.0 / scale
        } else {
            1.0
        };
        self.t[w] = run.t0;
        self.t_lo[w] = 0.0;
        for k in 0..M {
            self.comp[k][w] = 0.0;
        }
        self.idx[w] = 0;
        self.taken[w] = 0;
        self.traj[w] = Some(next);
        self.next += 1;
    }

    /// The coefficients `X_1 … X_p` of every lane in its scaled time.
    #[inline(always)]
    fn series<L: Lanes>(&self, x: &mut Coeffs, run: &TaylorRun<L>) {
        let hs = &self.hs;
        let fac: [L; MAX_ORDER + 1] = std::array::from_fn(|n| {
            let f: V = std::array::from_fn(|w| hs[w] * run.inv[n]);
            L::load(&f)
        });
        let s = &run.s;
        // The orders of ε in [1e-16, 1e-13] with constant loop bounds, which
        // LLVM unrolls completely (the loop overhead of the short sums of the
        // low orders was a third of the step).
        match run.p {
            16 => coefficients_const::<L, 16>(x, s, &fac),
            17 => coefficients_const::<L, 17>(x, s, &fac),
            18 => coefficients_const::<L, 18>(x, s, &fac),
            19 => coefficients_const::<L, 19>(x, s, &fac),
            20 => coefficients_const::<L, 20>(x, s, &fac),
            _ => coefficients::<L>(x, run.p, s, &fac),
        }
    }

    /// The radius of convergence of each lane's series in its scaled time,
    /// from the last two coefficients: ρ̃ = 2^min(log2(xn/n1)/(p-1),
    /// log2(xn/n2)/p) (max norms).
    #[inline(always)]
    fn radius(x: &Coeffs, p: usize) -> V {
        let (mut xn, mut n1, mut n2) = ([0.0f64; W], [0.0f64; W], [0.0f64; W]);
        for k in 0..M {
            for w in 0..W {
                xn[w] = xn[w].max(x[0][k][w].abs());
                n1[w] = n1[w].max(x[p - 1][k][w].abs());
                n2[w] = n2[w].max(x[p][k][w].abs());
            }
        }
        // ρ̃ = 2^min(log2(xn/n1)/(p-1), log2(xn/n2)/p), all lanes at once
        // (branch-free, so that it vectorises: per lane, the logarithms and
        // the power were a tenth of the step).
        let (inv_p1, inv_p) = (1.0 / (p as f64 - 1.0), 1.0 / p as f64);
        let lg: V = std::array::from_fn(|w| log2_ratio(xn[w], n1[w]) * inv_p1);
        let lg2: V = std::array::from_fn(|w| log2_ratio(xn[w], n2[w]) * inv_p);
        std::array::from_fn(|w| exp2_approx(lg[w].min(lg2[w])))
    }

    /// The step of each lane (Jorba & Zou, cut to the last sample time, at
    /// most `h_max`) and the next step's scale; errors on a zero or NaN step.
    #[inline(always)]
    fn step_sizes<L: Lanes>(&mut self, x: &Coeffs, run: &TaylorRun<L>) -> Result<LaneSteps> {
        let (o, safety) = (run.o, run.safety);
        // Step of each lane, in scaled time (σ) and in time (h); `unit` is the
        // scale the coefficients were computed in.
        let unit = self.hs;
        let mut sigma = [0.0f64; W];
        let mut h = [0.0f64; W];
        let mut last = [false; W];
        let rho = Self::radius(x, run.p);
        for w in 0..W {
            if self.traj[w].is_none() {
                continue;
            }
            let mut hw = self.hs[w] * (safety * rho[w]);
            if o.h_max > 0.0 {
                hw = hw.min(o.h_max);
            }
            if hw.is_nan() || hw <= 0.0 {
                return Err(Error::NoConvergence {
                    what: "Taylor step (step size zero or NaN: the state overflowed; rescale l)",
                    tol: o.tol,
                    reached: hw,
                    iterations: self.taken[w] as usize,
                });
            }
            let remaining = (run.t_last - self.t[w]) - self.t_lo[w];
            if hw >= remaining {
                last[w] = true;
                h[w] = remaining;
            } else {
                h[w] = hw;
            }
            sigma[w] = h[w] / unit[w];
            // The next step's scale: this step before it was cut to the end,
            // growing at most 2^10-fold (a terminating series, ρ̃ = ∞, must not
            // make the next coefficients overflow).
            self.hs[w] *= (safety * rho[w]).min(1024.0);
        }
        Ok(LaneSteps {
            unit,
            sigma,
            h,
            last,
        })
    }

    /// Dense output: samples strictly inside the step, from the step's
    /// Taylor polynomial.
    #[inline(always)]
    fn dense_output<L: Lanes>(
        &mut self,
        x: &Coeffs,
        run: &TaylorRun<L>,
        step: &LaneSteps,
        sink: &mut Samples,
    ) {
        let (comp, p) = (&self.comp, run.p);
        for w in 0..W {
            let Some(j) = self.traj[w] else { continue };
            while self.idx[w] < run.ns {
                let s = self.idx[w];
                let dt = (run.times[s] - self.t[w]) - self.t_lo[w];
                if !(dt < step.h[w] || (step.last[w] && run.times[s] < run.t_last)) {
                    break;
                }
                let tau = dt / step.unit[w];
                let dst = sink.row(j, s);
                for k in 0..M {
                    let mut acc = x[p][k][w];
                    for n in (1..p).rev() {
                        acc = acc.mul_add(tau, x[n][k][w]);
                    }
                    dst[k] = x[0][k][w] + acc.mul_add(tau, comp[k][w]);
                }
                self.idx[w] += 1;
                sink.written(j, self.idx[w]);
            }
        }
    }

    /// After the state update: checks each lane's state, moves its time to
    /// the step's end (two-sum) and counts the step against the budget.
    #[inline(always)]
    fn advance_time<L: Lanes>(
        &mut self,
        x: &Coeffs,
        run: &TaylorRun<L>,
        step: &LaneSteps,
    ) -> Result<()> {
        let o = run.o;
        for w in 0..W {
            if self.traj[w].is_none() {
                continue;
            }
            if !(0..M).all(|k| x[0][k][w].is_finite()) {
                return Err(Error::NoConvergence {
                    what: "Taylor step (state overflowed or became NaN; rescale l)",
                    tol: o.tol,
                    reached: f64::NAN,
                    iterations: self.taken[w] as usize,
                });
            }
            if step.last[w] {
                self.t[w] = run.t_last;
                self.t_lo[w] = 0.0;
            } else {
                let (s, e) = compensated::two_sum(self.t[w], step.h[w]);
                self.t[w] = s;
                self.t_lo[w] += e;
            }
            self.taken[w] += 1;
            if self.taken[w] > o.max_steps {
                return Err(super::explicit::too_many_steps(o.max_steps));
            }
        }
        Ok(())
    }
}

/// The Taylor coefficients `X_1 … X_p` of every lane from `X_0` (the state), in
/// scaled time: `X_{n+1} = fac_{n+1} (s_{2k} P_{2k,n} + s_{2k+1} P_{2k+1,n})`
/// with `fac_n = h_s / n`.
#[inline(always)]
fn coefficients<L: Lanes>(x: &mut Coeffs, p: usize, s: &[L; 12], fac: &[L; MAX_ORDER + 1]) {
    let p = p.min(MAX_ORDER);
    for n in 0..p {
        // Three calls written out, so that each pass's component indices are
        // constants (a loop over the passes indexed the loads at run time).
        let [r0, r1, r2] = [
            cauchy4::<L>(x, n, PASSES[0]),
            cauchy4::<L>(x, n, PASSES[1]),
            cauchy4::<L>(x, n, PASSES[2]),
        ];
        let mut acc = [L::splat(0.0); 12];
        for (pass, r) in PASSES.iter().zip([r0, r1, r2]) {
            for i in 0..4 {
                acc[pass[i]] = r[i];
            }
        }
        for k in 0..M {
            let v = s[2 * k + 1].fma(acc[2 * k + 1], s[2 * k].mul(acc[2 * k]));
            fac[n + 1].mul(v).store(&mut x[n + 1][k]);
        }
    }
}

/// [`coefficients`] for a fixed order `P`.
#[inline(always)]
fn coefficients_const<L: Lanes, const P: usize>(
    x: &mut Coeffs,
    s: &[L; 12],
    fac: &[L; MAX_ORDER + 1],
) {
    coefficients::<L>(x, P, s, fac)
}

/// The twelve products in three passes of four (indices into [`PRODUCTS`]),
/// grouped so that a pass reads few distinct components.
const PASSES: [[usize; 4]; 3] = [[2, 0, 4, 1], [3, 5, 6, 9], [7, 8, 10, 11]];

/// The Cauchy products `P_{q,n} = Σ_{j=0..n} X_{j,a_q} X_{n−j,b_q}` of four
/// products `q`. The sum over `j` is split into even and odd `j` (two
/// accumulators per product, added at the end): eight independent FMA chains
/// cover the FMA latency, and eight accumulators with the operands fit in the
/// 16 vector registers of AVX2 (twelve accumulators in one pass spilled, and
/// the store-to-load latency in their chains made the loop 2x slower).
#[inline(always)]
fn cauchy4<L: Lanes>(x: &Coeffs, n: usize, qs: [usize; 4]) -> [L; 4] {
    let pr = qs.map(|q| PRODUCTS[q]);
    let mut even = [L::splat(0.0); 4];
    let mut odd = [L::splat(0.0); 4];
    let n = n.min(MAX_ORDER);
    let mut j = 0;
    while j < n {
        let (u0, v0) = (&x[j], &x[n - j]);
        let (u1, v1) = (&x[j + 1], &x[n - j - 1]);
        for i in 0..4 {
            even[i] = L::load(&u0[pr[i].0]).fma(L::load(&v0[pr[i].1]), even[i]);
            odd[i] = L::load(&u1[pr[i].0]).fma(L::load(&v1[pr[i].1]), odd[i]);
        }
        j += 2;
    }
    if j == n {
        let (u, v) = (&x[j], &x[0]);
        for i in 0..4 {
            even[i] = L::load(&u[pr[i].0]).fma(L::load(&v[pr[i].1]), even[i]);
        }
    }
    std::array::from_fn(|i| even[i].add(odd[i]))
}

/// `a · b = p + e` exactly (FMA).
#[inline(always)]
fn two_prod<L: Lanes>(a: L, b: L) -> (L, L) {
    let p = a.mul(b);
    (p, a.fma(b, p.neg()))
}

/// `a + b = s + e` exactly: [`crate::numeric::compensated::two_sum`] on vector lanes.
#[inline(always)]
fn two_sum<L: Lanes>(a: L, b: L) -> (L, L) {
    let s = a.add(b);
    let bb = s.sub(a);
    (s, a.sub(s.sub(bb)).add(b.sub(bb)))
}

/// The step `x ← x + δ`, `δ = Σ_{n≥1} X_n σ^n`, carrying the state as the
/// unevaluated sum `x + comp`.
///
/// Roundoff, not truncation, limits Taylor's method at `ε = eps` over t ~ 100,
/// and most of it is in the leading term `h f(x)` (`|h f| ~ |x| / 3` at these
/// steps, so its 1–2 ulps of rounding are ~0.5 ulp of `x` per step). That term
/// is computed in double-double here: the products by two-prod, `f(x + comp)`
/// to first order in `comp`, and `h f` by two-prod; the rest, `σ² (X_2 + σ X_3
/// + …)` (~2 % of `x`), in plain Horner; the sum with `x` by two-sum, whose
/// error goes to `comp`. The per-step error drops to ~0.1 ulp of `x`.
///
/// The constants `s_q` are the rounded differences of the `c_ij` in every
/// term. (Their exact differences, hi + lo, in the leading term only made the
/// polynomial the expansion of no single field: Σ l², a Casimir of every field
/// (1), then drifted linearly, 1.4e-13 over 8·10^4 steps, against 1e-15 now.)
#[inline(always)]
fn compensated_update<L: Lanes>(
    x: &mut Coeffs,
    comp: &mut [V; M],
    p: usize,
    sigma: &V,
    h: &V,
    s: &[L; 12],
) {
    let sv = L::load(sigma);
    let hv = L::load(h);
    let y: [L; M] = std::array::from_fn(|k| L::load(&x[0][k]));
    let cy: [L; M] = std::array::from_fn(|k| L::load(&comp[k]));
    for k in 0..M {
        // f_k(x + comp) = Σ_q s_q (a b + a cb + ca b), q = 2k, 2k + 1, in hi + lo.
        let mut f_hi = L::splat(0.0);
        let mut f_lo = L::splat(0.0);
        for q in [2 * k, 2 * k + 1] {
            let (ia, ib) = PRODUCTS[q];
            let (pp, pe) = two_prod(y[ia], y[ib]);
            let pl = pe.add(y[ia].fma(cy[ib], cy[ia].mul(y[ib])));
            let (t, te) = two_prod(s[q], pp);
            let tl = te.add(s[q].mul(pl));
            let (sum, se) = two_sum(f_hi, t);
            f_hi = sum;
            f_lo = f_lo.add(se.add(tl));
        }
        let (d, de) = two_prod(hv, f_hi);
        let d_lo = de.add(hv.mul(f_lo));
        // σ² (X_2 + σ (X_3 + …)).
        let mut acc = L::load(&x[p][k]);
        for n in (2..p).rev() {
            acc = acc.fma(sv, L::load(&x[n][k]));
        }
        let tail = acc.mul(sv).mul(sv);
        let (dd, dde) = two_sum(d, tail);
        // δ = dd + low; x + δ = new + comp with |comp| ≲ ulp(new).
        let low = dde.add(d_lo.add(cy[k]));
        let (u, ue) = two_sum(dd, low);
        let (new, ne) = two_sum(y[k], u);
        ne.add(ue).store(&mut comp[k]);
        new.store(&mut x[0][k]);
    }
}

/// `log2(xn / nm)`, to ~1e-6 absolute, branch-free: `+∞` (as 2^1100) when
/// `nm = 0` (the series has no term of that order), and the ratio is clamped
/// to the normal range. The step size needs no more accuracy.
#[inline(always)]
fn log2_ratio(xn: f64, nm: f64) -> f64 {
    let r = (xn / nm).clamp(f64::MIN_POSITIVE, f64::MAX);
    let v = log2_approx(r);
    if nm > 0.0 {
        v
    } else {
        1100.0
    }
}

/// `log2 x` for a normal `x > 0`, to ~1e-6 absolute.
#[inline(always)]
fn log2_approx(x: f64) -> f64 {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    // ln m = 2 atanh t, t = (m - 1)/(m + 1) ∈ [0, 1/3): the series to t^9
    // leaves 2 t^11 / 11 < 1.1e-6.
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let ln_m = 2.0 * t * (1.0 + t2 * (1.0 / 3.0 + t2 * (0.2 + t2 * (1.0 / 7.0 + t2 / 9.0))));
    e as f64 + ln_m * std::f64::consts::LOG2_E
}

/// `2^y` to ~1e-7 relative, `y` clamped to [-1022, 1023] (NaN gives NaN).
#[inline(always)]
fn exp2_approx(y: f64) -> f64 {
    let y = y.clamp(-1022.0, 1023.0);
    let k = y.floor();
    let f = (y - k) * std::f64::consts::LN_2;
    // e^f on [0, ln 2): Taylor to f^8, remainder < (ln 2)^9 / 9! < 1.1e-7.
    let mut e = 1.0 / 40320.0;
    for d in [5040.0, 720.0, 120.0, 24.0, 6.0, 2.0, 1.0, 1.0] {
        e = e * f + 1.0 / d;
    }
    // y = NaN: k = NaN casts to 0, and e is NaN.
    e * f64::from_bits(((k as i64 + 1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::so4::{vector_field4, FrahmTop};

    fn top() -> FrahmTop {
        FrahmTop::manakov(&[0.3, 1.1, 2.0, 3.7], &[0.5, -0.2, 1.4, 0.9]).unwrap()
    }

    /// The products and constants reproduce the field (1): `X_1 = f(x)` when
    /// the scale `h_s` is 1.
    #[test]
    fn first_coefficient_is_the_field() {
        let top = top();
        let c = top.c4().unwrap();
        let l = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];
        let mut x: Coeffs = [[[0.0; W]; M]; MAX_ORDER + 1];
        for k in 0..M {
            x[0][k] = [l[k]; W];
        }
        let s = product_coefficients(c);
        let fac: [V; MAX_ORDER + 1] =
            std::array::from_fn(|n| [if n == 0 { 0.0 } else { 1.0 / n as f64 }; W]);
        coefficients::<V>(&mut x, 3, &s.map(|v| [v; W]), &fac);
        let f = vector_field4(c, &l);
        for k in 0..M {
            assert!(
                (x[1][k][0] - f[k]).abs() <= 1e-15 * f[k].abs().max(1.0),
                "{k}"
            );
        }
        // X_2 = f'(x) f(x) / 2, by a central difference of f along f.
        let e = 1e-5;
        let plus: [f64; 6] = std::array::from_fn(|k| l[k] + e * f[k]);
        let minus: [f64; 6] = std::array::from_fn(|k| l[k] - e * f[k]);
        let (fp, fm) = (vector_field4(c, &plus), vector_field4(c, &minus));
        for k in 0..M {
            // The field is quadratic: the central difference is exact up to rounding.
            let want = (fp[k] - fm[k]) / (4.0 * e);
            assert!(
                (x[2][k][0] - want).abs() < 1e-9,
                "{k}: {} vs {want}",
                x[2][k][0]
            );
        }
    }

    #[test]
    fn fast_log2_and_exp2() {
        for &v in &[1e-300, 0.1, 0.75, 1.0, 1.5, 3.0, 1e10, 1e300] {
            let l = log2_approx(v);
            // the series' remainder, 1.1e-6 / ln 2
            assert!((l - v.log2()).abs() < 2e-6, "{v}: {l}");
        }
        for &y in &[-1000.0, -3.3, -0.5, 0.0, 0.25, 1.0, 7.9, 500.0] {
            let e = exp2_approx(y);
            let want = 2f64.powf(y);
            // the series' remainder, 1.1e-7
            assert!(((e - want) / want).abs() < 2e-7, "{y}: {e} vs {want}");
        }
        assert_eq!(log2_ratio(1.0, 0.0), 1100.0);
        assert_eq!(log2_ratio(0.0, 1.0), -1022.0);
        assert!(exp2_approx(f64::NAN).is_nan());
        assert_eq!(exp2_approx(1100.0), 2f64.powi(1023));
    }

    #[test]
    fn order_from_tolerance() {
        assert_eq!(order(f64::EPSILON), 20);
        assert_eq!(order(1e-15), 19);
        assert_eq!(order(1e-14), 18);
        assert_eq!(order(TOL_MAX), 5);
    }

    /// The AVX2 kernel (chosen at run time on this machine) and the baseline
    /// one give the same bits.
    #[test]
    fn baseline_and_dispatched_kernels_agree() {
        let top = top();
        let c = top.c4().unwrap();
        let y0s: Vec<f64> = (0..5 * M)
            .map(|i| ((i * 7919) % 13) as f64 / 6.5 - 1.0)
            .collect();
        let times = [0.0, 0.5, 0.5, 2.0, 3.3];
        let n = 5 * times.len() * M;
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        let o = TaylorOpts {
            tol: f64::EPSILON,
            h_max: 0.0,
            max_steps: 1 << 20,
        };
        let never = Cancel::never();
        let (mut pa, mut pb) = (Progress::default(), Progress::default());
        taylor_group(c, &y0s, 0.0, &times, o, &mut a, &mut pa, &never).unwrap();
        taylor_group_body::<V>(c, &y0s, 0.0, &times, o, &mut b, &mut pb, &never).unwrap();
        assert_eq!(pa.steps, pb.steps);
        assert!(
            a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{a:?} vs {b:?}"
        );
        assert!(a.iter().any(|&x| x != 0.0));
    }
}
