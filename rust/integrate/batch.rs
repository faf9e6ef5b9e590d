//! Batch kernels for so(4): vector lanes carry different trajectories.
//!
//! The state of `W` trajectories is stored structure-of-arrays, `y[k][w]` =
//! component `k` of trajectory `w`, so every arithmetic operation of a step is
//! one `W`-wide vector operation. `W = 4` doubles fill an AVX2 register.
//!
//! **Same results as one trajectory at a time.** Every lane performs exactly the
//! floating-point operations of the single-trajectory stepper, in the same
//! order (Rust never contracts `a * b + c` into an FMA, and the so(4) field is
//! evaluated by the same expressions), so `integrate_many` is bit-for-bit equal
//! to `integrate` state by state (tests below and `tests/test_integrate.py`):
//!
//! - **gauss16** (`gauss16_group`): the step size sequence depends only on the
//!   sample times and `dt`, so the `W` lanes step in lockstep. Each lane keeps its
//!   own stopping rule of the stage iteration; a lane that has converged is
//!   frozen (a blend keeps its stages), and the group stops when the slowest
//!   lane has converged. Samples land on their times exactly, as for one
//!   trajectory. A sweep runs stage by stage (`gauss16_sweep`): the 6 components
//!   of `Y_i` for the 4 lanes are 6 vector registers from the stage sum through
//!   the field and the increment, and the stages alternate between two buffers.
//! - **dop853** (`dop853_group`, in [`super::batch_dop853`]): each lane keeps its own time, step size, next
//!   sample and step count; a rejected step is masked by the per-lane control
//!   (the lane keeps its state and retries with a smaller step). A lane whose
//!   trajectory has reached its last sample is refilled with the next trajectory
//!   of the group, so lanes do not idle while a slower trajectory finishes.
//!   Samples are hit by shortening the step to the sample time, per lane, as in
//!   the single-trajectory method (no interpolation: a dense-output sample would
//!   differ from `integrate` by the interpolation error).
//!
//! **Dispatch.** Each kernel is compiled twice, for the baseline target (SSE2 on
//! x86-64) and inside a `#[target_feature(enable = "avx2,fma")]` function, and
//! the AVX2 copy is chosen at run time with `is_x86_feature_detected!`. dop853 is
//! plain Rust on `[f64; W]` arrays written so that LLVM vectorises them. The
//! gauss16 sweep is written once over the [`Lanes`] operations: plain arrays in
//! the baseline copy, `core::arch` AVX intrinsics in the AVX2 copy (left to
//! itself, LLVM shuffled the lanes of the field evaluation, turned the running
//! maximum into masked stores and spilled the stage arrays: 1.4× slower). No
//! FMA is emitted (it would change the rounding, and the results would no longer
//! match `integrate`).

// Index loops mirror the subscripts of the formulas (i, j stages; k components; w lanes).
#![allow(clippy::needless_range_loop)]

use super::gauss::reuse_stages;
use super::gauss_tables::{B8, E8, MU8};
use super::{substeps, StopRule};
use crate::error::{Error, Result};
use crate::numeric::cancel::{Cancel, CHECK_EVERY};
use crate::so4::vector_field4_lanes;

/// Trajectories per vector group (f64 lanes of an AVX2 register).
pub const W: usize = 4;
/// Stages of gauss16.
const S: usize = 8;
/// so(4) state length.
pub(super) const M: usize = 6;

/// Runs `body` compiled for AVX2+FMA when the CPU has them, else the baseline.
macro_rules! dispatch {
    ($avx2:ident, $body:ident, ($($arg:expr),*)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                return unsafe { $avx2($($arg),*) };
            }
        }
        $body($($arg),*)
    }};
}
pub(super) use dispatch;

/// gauss16 on up to `W` trajectories `y0s` (row-major, `rows · 6`) through
/// `times` with the step `dt`, writing `(rows, times.len(), 6)` into `out`;
/// returns the steps of one trajectory.
pub(super) fn gauss16_group(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            return unsafe { gauss16_group_avx2(c, y0s, t0, times, dt, out, cancel) };
        }
    }
    gauss16_group_body::<V>(c, y0s, t0, times, dt, out, cancel)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gauss16_group_avx2(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    gauss16_group_body::<avx::F64x4>(c, y0s, t0, times, dt, out, cancel)
}

/// One vector of `W` lanes.
pub(super) type V = [f64; W];

/// The state of a gauss16 lane group.
struct Gauss16Lanes {
    /// `y[k][w]`.
    y: [V; M],
    /// Kahan compensation of the update, per component and lane.
    comp: [V; M],
    /// `L[i][k][w] = h b_i f_k(Y_i)` of lane `w`: stage-major, so that the
    /// components of one stage are contiguous for the fused sweep.
    l: [[V; M]; S],
    last_h: f64,
}

#[inline(always)]
fn gauss16_group_body<L: Lanes>(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    let rows = y0s.len() / M;
    let per = times.len() * M;
    // Unused lanes hold the zero state: f(0) = 0, so their iteration stops at once.
    let mut g = Gauss16Lanes {
        y: [[0.0; W]; M],
        comp: [[0.0; W]; M],
        l: [[[0.0; W]; M]; S],
        last_h: 0.0,
    };
    for (w, y0) in y0s.chunks_exact(M).enumerate() {
        for k in 0..M {
            g.y[k][w] = y0[k];
        }
    }
    let mut t = t0;
    let mut steps = 0u64;
    let mut since_check = 0u32;
    for (s, &tk) in times.iter().enumerate() {
        let span = tk - t;
        if span > 0.0 {
            let n = substeps(span, dt);
            let h = span / n;
            // n ≤ MAX_STEPS < 2^53 (checked by the caller), so the count is exact.
            for _ in 0..n as u64 {
                gauss16_step::<L>(c, &mut g, h)?;
                since_check += 1;
                if since_check == CHECK_EVERY {
                    since_check = 0;
                    cancel.check()?;
                }
            }
            steps += n as u64;
            t = tk;
        }
        for w in 0..rows {
            let o = &mut out[w * per + s * M..w * per + (s + 1) * M];
            for k in 0..M {
                o[k] = g.y[k][w];
            }
        }
        cancel.advance(rows as u64);
    }
    Ok(steps)
}

/// One sweep of the stage iteration on every lane: `Y_i = y + Σ_j μ_ij L_j`,
/// `L'_i = h b_i f(Y_i)` into `lnew`; returns the largest `|L'_i - L_i|` of
/// each lane. A lane whose iteration has stopped (`active` lane clear) keeps
/// its stages. Stage by stage, so that the 6 components of `Y_i` stay in
/// registers from the sums through the field (one broadcast of `μ_ij` serves
/// all 6 components).
#[inline(always)]
fn gauss16_sweep<L: Lanes>(
    d: &[L; 12],
    y: &[V; M],
    l: &[[V; M]; S],
    hb: &[f64; S],
    active: L,
    lnew: &mut [[V; M]; S],
) -> V {
    let mut dm = L::splat(0.0);
    for i in 0..S {
        // The sum in the order of the single-trajectory stepper: y, then j = 0, 1, ….
        let mut acc: [L; M] = std::array::from_fn(|k| L::load(&y[k]));
        for j in 0..S {
            let mu = L::splat(MU8[i][j]);
            for k in 0..M {
                acc[k] = acc[k].add(mu.mul(L::load(&l[j][k])));
            }
        }
        let f = field4(d, &acc);
        let hbi = L::splat(hb[i]);
        for k in 0..M {
            let new = hbi.mul(f[k]);
            let old = L::load(&l[i][k]);
            dm = dm.max_of(new.sub(old).abs());
            L::select(active, new, old).store(&mut lnew[i][k]);
        }
    }
    let mut out = [0.0; W];
    dm.store(&mut out);
    out
}

/// The differences `c_kj − c_ik` of (1), in the order [`field4`] uses them.
fn field4_diffs(c: &[f64; 6]) -> [f64; 12] {
    let [c12, c13, c14, c23, c24, c34] = *c;
    [
        c23 - c13,
        c24 - c14,
        c23 - c12,
        c34 - c14,
        c24 - c12,
        c34 - c13,
        c13 - c12,
        c34 - c24,
        c14 - c12,
        c34 - c23,
        c14 - c13,
        c24 - c23,
    ]
}

/// [`vector_field4_lanes`] on one lane vector: the same expressions, operation
/// for operation, so the results agree bit for bit (the lane-kernel tests
/// compare against `integrate`, which uses `vector_field4_lanes`).
#[inline(always)]
fn field4<L: Lanes>(d: &[L; 12], l: &[L; M]) -> [L; M] {
    let [l12, l13, l14, l23, l24, l34] = *l;
    [
        l13.mul(l23).mul(d[0]).add(l14.mul(l24).mul(d[1])).neg(),
        l12.mul(l23).mul(d[2]).sub(l14.mul(l34).mul(d[3])),
        l12.mul(l24).mul(d[4]).add(l13.mul(l34).mul(d[5])),
        l12.mul(l13).mul(d[6]).add(l24.mul(l34).mul(d[7])).neg(),
        l23.mul(l34).mul(d[9]).sub(l12.mul(l14).mul(d[8])),
        l13.mul(l14).mul(d[10]).add(l23.mul(l24).mul(d[11])).neg(),
    ]
}

/// The stages' starting guess on every lane (as `GaussFixed::start_stages`).
#[inline(always)]
fn gauss16_start_stages(c: &[f64; 6], g: &mut Gauss16Lanes, h: f64, hb: &[f64; S]) {
    if !reuse_stages(g.last_h, h) {
        let mut f0 = [[0.0; W]; M];
        vector_field4_lanes(c, &g.y, &mut f0);
        for i in 0..S {
            for k in 0..M {
                for w in 0..W {
                    g.l[i][k][w] = hb[i] * f0[k][w];
                }
            }
        }
    } else if h == g.last_h {
        // Predictor (see GaussFixed): f at the new nodes from the previous
        // collocation polynomial, carried as L_j / b_j.
        let mut fj = [[[0.0; W]; M]; S];
        for j in 0..S {
            for k in 0..M {
                for w in 0..W {
                    fj[j][k][w] = g.l[j][k][w] / B8[j];
                }
            }
        }
        for i in 0..S {
            let mut acc = [[0.0; W]; M];
            for j in 0..S {
                let e = E8[i][j];
                for k in 0..M {
                    for w in 0..W {
                        acc[k][w] += e * fj[j][k][w];
                    }
                }
            }
            for k in 0..M {
                for w in 0..W {
                    g.l[i][k][w] = B8[i] * acc[k][w];
                }
            }
        }
    } else {
        let r = h / g.last_h;
        for x in g.l.iter_mut().flatten().flatten() {
            *x *= r;
        }
    }
}

/// One gauss16 step of size `h` on every lane; the operations of each lane are
/// those of `GaussFixed::<8, 6>::step`, in the same order.
#[inline(always)]
fn gauss16_step<L: Lanes>(c: &[f64; 6], g: &mut Gauss16Lanes, h: f64) -> Result<()> {
    let mut hb = [0.0; S];
    for i in 0..S {
        hb[i] = h * B8[i];
    }
    gauss16_start_stages(c, g, h, &hb);
    g.last_h = h;
    let mut ymax = [0.0f64; W];
    for w in 0..W {
        for k in 0..M {
            ymax[w] = ymax[w].max(g.y[k][w].abs());
        }
    }
    let mut rules: [StopRule; W] = std::array::from_fn(|_| StopRule::new());
    let mut active = [true; W];
    let d = field4_diffs(c).map(L::splat);
    // Two buffers, alternating (Jacobi: the new stages must not overwrite the
    // old ones while later stages still read them). A lane whose
    // iteration has stopped keeps its stages (the lanes share the sweeps, the
    // stopped ones are frozen by a blend), so every lane ends exactly where a
    // single-trajectory step would.
    let mut other = [[[0.0; W]; M]; S];
    // Sign bit set in the lanes still iterating (no closure here: a Lanes
    // method must be inlined into the AVX2 function to get its instructions).
    let lanes =
        |active: &[bool; W]| -> V { std::array::from_fn(|w| if active[w] { -1.0 } else { 0.0 }) };
    // Unrolled twice, so that both buffers sit at fixed addresses.
    loop {
        let dm = gauss16_sweep(&d, &g.y, &g.l, &hb, L::load(&lanes(&active)), &mut other);
        if stopped(&mut rules, &ymax, dm, &mut active)? {
            g.l = other;
            break;
        }
        let dm = gauss16_sweep(&d, &g.y, &other, &hb, L::load(&lanes(&active)), &mut g.l);
        if stopped(&mut rules, &ymax, dm, &mut active)? {
            break;
        }
    }
    let iterations = rules.iter().map(|r| r.iterations).max().unwrap_or(0);
    // Compensated update y += Σ_i L_i (Kahan), per lane.
    for k in 0..M {
        for w in 0..W {
            let mut sum = g.comp[k][w];
            for i in 0..S {
                sum += g.l[i][k][w];
            }
            let y = g.y[k][w];
            let new = y + sum;
            g.comp[k][w] = (y - new) + sum;
            g.y[k][w] = new;
        }
    }
    if !g.y.iter().flatten().all(|v| v.is_finite()) {
        return Err(Error::NoConvergence {
            what: "Gauss step (state overflowed or became NaN; reduce dt or rescale l)",
            tol: 0.0,
            reached: f64::NAN,
            iterations,
        });
    }
    Ok(())
}

/// The `W`-lane vector operations of the gauss16 kernel. Two implementations:
/// plain arrays (the baseline build; LLVM vectorises them as it can) and AVX2
/// registers (`avx::F64x4`, explicit instructions, so that the stage sums and
/// the field stay in registers). Both are IEEE operations lane by lane, with
/// no FMA in the gauss16 kernel, so they give the same bits. The Taylor kernel
/// (`taylor.rs`) uses [`Lanes::fma`]: one rounding in both copies (the baseline
/// calls `f64::mul_add`, correctly rounded), so again the same bits.
pub(super) trait Lanes: Copy {
    fn splat(x: f64) -> Self;
    fn load(a: &V) -> Self;
    fn store(self, a: &mut V);
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    /// `-x` (sign flip).
    fn neg(self) -> Self;
    fn abs(self) -> Self;
    /// `if d > m { d } else { m }` lane by lane (`m` = self): skips a NaN `d`, as
    /// `f64::max` does in the single-trajectory stepper.
    fn max_of(self, d: Self) -> Self;
    /// `a` where `mask`'s sign bit is set, else `b`, lane by lane.
    fn select(mask: Self, a: Self, b: Self) -> Self;
    /// `self · b + c` with one rounding.
    fn fma(self, b: Self, c: Self) -> Self;
}

impl Lanes for V {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        [x; W]
    }
    #[inline(always)]
    fn load(a: &V) -> Self {
        *a
    }
    #[inline(always)]
    fn store(self, a: &mut V) {
        *a = self;
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        std::array::from_fn(|w| self[w] + o[w])
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        std::array::from_fn(|w| self[w] - o[w])
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        std::array::from_fn(|w| self[w] * o[w])
    }
    #[inline(always)]
    fn neg(self) -> Self {
        std::array::from_fn(|w| -self[w])
    }
    #[inline(always)]
    fn abs(self) -> Self {
        std::array::from_fn(|w| self[w].abs())
    }
    #[inline(always)]
    fn max_of(self, d: Self) -> Self {
        std::array::from_fn(|w| if d[w] > self[w] { d[w] } else { self[w] })
    }
    #[inline(always)]
    fn select(mask: Self, a: Self, b: Self) -> Self {
        std::array::from_fn(|w| {
            if mask[w].is_sign_negative() {
                a[w]
            } else {
                b[w]
            }
        })
    }
    #[inline(always)]
    fn fma(self, b: Self, c: Self) -> Self {
        std::array::from_fn(|w| self[w].mul_add(b[w], c[w]))
    }
}

/// AVX2 registers for [`Lanes`]. The methods are `#[inline(always)]` and only
/// ever run inlined into `gauss16_group_avx2`, which is entered only on a CPU
/// with AVX2 (checked at run time), so the AVX instructions are always available.
#[cfg(target_arch = "x86_64")]
pub(super) mod avx {
    use super::{Lanes, V};
    use std::arch::x86_64::*;

    #[derive(Clone, Copy)]
    pub(in crate::integrate) struct F64x4(__m256d);

    // SAFETY (every unsafe block below): AVX is available, see the module docs;
    // loads and stores go through references to `[f64; 4]`, valid for 32 bytes
    // (unaligned access instructions).
    impl Lanes for F64x4 {
        #[inline(always)]
        fn splat(x: f64) -> Self {
            F64x4(unsafe { _mm256_set1_pd(x) })
        }
        #[inline(always)]
        fn load(a: &V) -> Self {
            F64x4(unsafe { _mm256_loadu_pd(a.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, a: &mut V) {
            unsafe { _mm256_storeu_pd(a.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            F64x4(unsafe { _mm256_add_pd(self.0, o.0) })
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            F64x4(unsafe { _mm256_sub_pd(self.0, o.0) })
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            F64x4(unsafe { _mm256_mul_pd(self.0, o.0) })
        }
        #[inline(always)]
        fn neg(self) -> Self {
            F64x4(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
        }
        #[inline(always)]
        fn abs(self) -> Self {
            F64x4(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
        }
        #[inline(always)]
        fn max_of(self, d: Self) -> Self {
            // MAXPD returns its second operand unless the first is greater
            // (so also when either is NaN): exactly `if d > m { d } else { m }`.
            F64x4(unsafe { _mm256_max_pd(d.0, self.0) })
        }
        #[inline(always)]
        fn select(mask: Self, a: Self, b: Self) -> Self {
            F64x4(unsafe { _mm256_blendv_pd(b.0, a.0, mask.0) })
        }
        #[inline(always)]
        fn fma(self, b: Self, c: Self) -> Self {
            // FMA is available wherever AVX2 is used here (both are checked).
            F64x4(unsafe { _mm256_fmadd_pd(self.0, b.0, c.0) })
        }
    }
}

/// Records a sweep's increments in each active lane's stopping rule;
/// `Ok(true)` once every lane has stopped.
#[inline(always)]
fn stopped(rules: &mut [StopRule; W], ymax: &V, dm: V, active: &mut [bool; W]) -> Result<bool> {
    let mut all = true;
    for w in 0..W {
        if active[w] {
            if rules[w].update(dm[w], ymax[w])? {
                active[w] = false;
            } else {
                all = false;
            }
        }
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::so4::FrahmTop;

    /// The AVX2 kernel (chosen at run time on this machine) and the baseline
    /// one (plain arrays, what a CPU without AVX2 runs) give the same bits.
    #[test]
    fn gauss16_baseline_and_dispatched_kernels_agree() {
        let top = FrahmTop::manakov(&[0.3, 1.1, 2.0, 3.7], &[0.5, -0.2, 1.4, 0.9]).unwrap();
        let c = top.c4().unwrap();
        let y0s: Vec<f64> = (0..3 * M)
            .map(|i| ((i * 7919) % 13) as f64 / 6.5 - 1.0)
            .collect();
        let times = [0.5, 0.5, 2.0, 3.3];
        let n = y0s.len() / M * times.len() * M;
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        let never = Cancel::never();
        let sa = gauss16_group(c, &y0s, 0.0, &times, 0.3, &mut a, &never).unwrap();
        let sb = gauss16_group_body::<V>(c, &y0s, 0.0, &times, 0.3, &mut b, &never).unwrap();
        assert_eq!(sa, sb);
        assert!(
            a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{a:?} vs {b:?}"
        );
        assert!(a.iter().any(|&x| x != 0.0));
    }
}
