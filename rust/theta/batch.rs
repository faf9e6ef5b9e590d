//! Genus-2 batch kernel for the values (no derivatives), vectorised across points.
//!
//! For a fixed τ the quadratic factor `C(j) = exp(iπ/4 jᵀτ'j)` is tabulated once
//! (plan time) on the union of the summation ellipsoids of all reduced points
//! (`|w_r| ≤ 1/2`); a term of point `p` is then `C(j) X1_p(j1) X2_p(j2)` with
//! `Xk_p(j) = exp(iπ j z_{r,k})` from per-point power tables. The class sums are
//! accumulated row by row for `LANES` points at once (structure of arrays), so
//! the innermost loop is a plain vectorisable multiply-add over points. The
//! union region has ~30% more terms than one ellipsoid; the extra terms are
//! genuine terms of the series, so accuracy is unchanged.

use super::{sum, ThetaPlan};
use crate::numeric::compensated::split;
use num_complex::Complex64;

/// Points per chunk.
pub(super) const LANES: usize = 16;

/// Largest table kept in a plan (entries of `C`; 1 MiB).
const MAX_TABLE: usize = 1 << 16;

/// Rounding margin on `|w_r| ≤ 1/2` when building the union region.
const W_MARGIN: f64 = 0.51;

pub(super) type Lane = [f64; LANES];

/// A [`Lane`] aligned to a cache line. The tables are read with 64-byte vector
/// loads; with the 32-byte alignment the allocator happened to give, every such
/// load straddled two cache lines (measured: the row sums ran ~1.2× slower).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub(super) struct ALane(pub(super) Lane);

impl std::ops::Deref for ALane {
    type Target = Lane;
    fn deref(&self) -> &Lane {
        &self.0
    }
}

impl std::ops::DerefMut for ALane {
    fn deref_mut(&mut self) -> &mut Lane {
        &mut self.0
    }
}

const AZERO: ALane = ALane([0.0; LANES]);

/// `want` mask of [`Batch2::eval_chunk`] selecting all 16 characteristics.
pub(super) const ALL: u16 = 0xffff;

/// `i^u` as (re, im), `u = 0..4`.
const UNIT: [(f64, f64); 4] = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];

/// Plan-time data of the batch kernel.
#[derive(Debug, Clone)]
pub(super) struct Batch2 {
    j1lo: i64,
    j2lo: i64,
    n1: usize,
    n2: usize,
    /// Per `j1` index: inclusive `j2` index range (empty if `lo > hi`).
    rows: Vec<(usize, usize)>,
    cre: Vec<f64>,
    cim: Vec<f64>,
}

/// Scratch for one chunk (power tables and class sums).
#[derive(Debug, Clone, Default)]
pub(super) struct BatchScratch {
    x1re: Vec<ALane>,
    x1im: Vec<ALane>,
    x2re: Vec<ALane>,
    x2im: Vec<ALane>,
    /// The 16 values, `out_re[idx][p] + i out_im[idx][p]` (FLINT order).
    pub(super) out_re: Vec<ALane>,
    pub(super) out_im: Vec<ALane>,
}

/// Reduced points of one chunk, one lane per point (unused lanes hold zeros).
#[derive(Debug, Clone, Default)]
#[repr(C, align(64))]
pub(super) struct ChunkIn {
    /// `Re z_r`, `Im z_r` per coordinate.
    pub(super) zre: [Lane; 2],
    pub(super) zim: [Lane; 2],
    /// `w_r = (Im τ)^{-1} Im z_r`.
    pub(super) wr: [Lane; 2],
    /// `φ/π` of the reduction prefactor `exp(iφ)`.
    pub(super) phase: Lane,
    /// `L`.
    pub(super) logs: Lane,
    /// `(-1)^{a·p}` for `a = 0..4` and `(-1)^{b·q}` for `b = 0..4` (bit masks as in FLINT's index).
    pub(super) sa: [Lane; 4],
    pub(super) sb: [Lane; 4],
}

impl ChunkIn {
    /// Lane `p` from the reduced point `red`.
    #[inline(always)]
    pub(super) fn set(&mut self, p: usize, red: &super::reduce::Reduced) {
        for i in 0..2 {
            self.zre[i][p] = red.zr[i].re;
            self.zim[i][p] = red.zr[i].im;
            self.wr[i][p] = red.wr[i];
        }
        self.phase[p] = red.phase;
        self.logs[p] = red.log_scale;
        self.set_signs(p, red.pbits, red.qbits);
    }

    /// The signs `(-1)^{a·p}`, `(-1)^{b·q}` of lane `p` from the parity bit
    /// masks (`p_1` in bit 1, `p_2` in bit 0, as in FLINT's index).
    #[inline(always)]
    pub(super) fn set_signs(&mut self, p: usize, pbits: usize, qbits: usize) {
        let sign = |bits: usize, bit: usize| 1.0 - 2.0 * ((bits >> bit) & 1) as f64;
        self.set_sign_lanes(
            p,
            [sign(pbits, 1), sign(pbits, 0)],
            [sign(qbits, 1), sign(qbits, 0)],
        );
    }

    /// The signs of lane `p` from `sp = ((-1)^{p_1}, (-1)^{p_2})` and `sq`
    /// likewise: `sa[h] = (-1)^{h·p}` with `h = (h_1, h_2)` the bits (1, 0) of
    /// the index `h` (plain products, so it vectorises across lanes).
    #[inline(always)]
    pub(super) fn set_sign_lanes(&mut self, p: usize, sp: [f64; 2], sq: [f64; 2]) {
        self.sa[0][p] = 1.0;
        self.sa[1][p] = sp[1];
        self.sa[2][p] = sp[0];
        self.sa[3][p] = sp[0] * sp[1];
        self.sb[0][p] = 1.0;
        self.sb[1][p] = sq[1];
        self.sb[2][p] = sq[0];
        self.sb[3][p] = sq[0] * sq[1];
    }
}

impl Batch2 {
    /// `None` unless g = 2, the table is small and `Xk` cannot overflow.
    pub(super) fn build(plan: &ThetaPlan) -> Option<Batch2> {
        if plan.g != 2 {
            return None;
        }
        let (d1, d2, l21) = (plan.ldl_d[0], plan.ldl_d[1], plan.ldl_l[2]);
        // Values only: the truncation radius of order 0 suffices whatever
        // order the plan was built for.
        let rq = plan.rq_values;
        let ext = |k: usize| 2.0 * ((rq * plan.yinv[k * 2 + k]).sqrt() + W_MARGIN);
        let j1lo = sum::floor_i64(-ext(0)) - 1;
        let j2lo = sum::floor_i64(-ext(1)) - 1;
        let n1 = (2 * (-j1lo) + 1) as usize;
        let n2 = (2 * (-j2lo) + 1) as usize;
        if n1 * n2 > MAX_TABLE {
            return None;
        }
        let jmax = (-j1lo).max(-j2lo) as f64;
        let imz = (0..2)
            .map(|k| W_MARGIN * (plan.y[k * 2].abs() + plan.y[k * 2 + 1].abs()))
            .fold(0.0, f64::max);
        // |Xk| ≤ exp(π |j| |Im z_r|) and |C| ≥ exp(-π/4 jᵀYj): keep both in range.
        let cmin = 0.25
            * std::f64::consts::PI
            * jmax
            * jmax
            * (plan.y[0] + plan.y[3] + 2.0 * plan.y[1].abs());
        if std::f64::consts::PI * jmax * imz > 300.0 || cmin > 600.0 {
            return None;
        }
        let mut rows = Vec::with_capacity(n1);
        for a in 0..n1 {
            let j1 = j1lo + a as i64;
            let h = 0.5 * j1 as f64;
            let umin = (h.abs() - W_MARGIN).max(0.0);
            let rem = rq - d1 * umin * umin;
            if rem < 0.0 {
                rows.push((1, 0));
                continue;
            }
            let hw = 2.0 * (rem / d2).sqrt();
            // centre 2(-l21 u1 - w2) over u1 ∈ h ± margin, w2 ∈ ±margin
            let c_at = |u1: f64, w2: f64| 2.0 * (-l21 * u1 - w2);
            let corners = [
                c_at(h - W_MARGIN, -W_MARGIN),
                c_at(h - W_MARGIN, W_MARGIN),
                c_at(h + W_MARGIN, -W_MARGIN),
                c_at(h + W_MARGIN, W_MARGIN),
            ];
            let cmin = corners.iter().copied().fold(f64::INFINITY, f64::min);
            let cmax = corners.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let lo = (sum::ceil_i64(cmin - hw) - j2lo).max(0);
            let hi = (sum::floor_i64(cmax + hw) - j2lo).min(n2 as i64 - 1);
            if lo > hi {
                rows.push((1, 0));
            } else {
                rows.push((lo as usize, hi as usize));
            }
        }
        let pi = std::f64::consts::PI;
        let mut cre = Vec::with_capacity(n1 * n2);
        let mut cim = Vec::with_capacity(n1 * n2);
        for a in 0..n1 {
            for b in 0..n2 {
                let j = [j1lo + a as i64, j2lo + b as i64];
                let (mut re, mut im) = (0.0, 0.0);
                for i in 0..2 {
                    for k in 0..2 {
                        let jj = (j[i] * j[k]) as f64;
                        re -= plan.y[i * 2 + k] * jj;
                        // jj·X'_ik mod 8 with the large part exact (|jj| < 2^26)
                        let (hi, lo) = split(plan.x[i * 2 + k]);
                        let t = jj * hi;
                        im += (t - 8.0 * (t / 8.0).round()) + jj * lo;
                    }
                }
                let c = Complex64::new(0.25 * pi * re, 0.25 * pi * im).exp();
                cre.push(c.re);
                cim.push(c.im);
            }
        }
        Some(Batch2 {
            j1lo,
            j2lo,
            n1,
            n2,
            rows,
            cre,
            cim,
        })
    }

    pub(super) fn scratch(&self) -> BatchScratch {
        BatchScratch {
            x1re: vec![AZERO; self.n1],
            x1im: vec![AZERO; self.n1],
            x2re: vec![AZERO; self.n2],
            x2im: vec![AZERO; self.n2],
            out_re: vec![AZERO; 16],
            out_im: vec![AZERO; 16],
        }
    }

    /// The 16 values of [`LANES`] reduced points (`sc.out_re`, `sc.out_im`, FLINT
    /// order): class sums from the table, then the Walsh–Hadamard combination with
    /// the reduction factors (`θ = exp(L) Ω` if `scaled`, else `Ω`). The per-point
    /// exponentials are evaluated for all lanes at once (`sincos_pi`, `exp_lanes`).
    ///
    /// Only the characteristics whose bit is set in `want` (bit `idx`) are
    /// written; the class sums are shared by all of them.
    pub(super) fn eval_chunk(
        &self,
        plan: &ThetaPlan,
        inp: &ChunkIn,
        scaled: bool,
        want: u16,
        sc: &mut BatchScratch,
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX-512F and FMA (checked just above).
                unsafe { self.chunk_avx512(plan, inp, scaled, want, sc) };
                return;
            }
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { self.chunk_avx2(plan, inp, scaled, want, sc) };
                return;
            }
        }
        self.chunk_body::<false>(plan, inp, scaled, want, sc);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,fma")]
    unsafe fn chunk_avx512(
        &self,
        plan: &ThetaPlan,
        inp: &ChunkIn,
        scaled: bool,
        want: u16,
        sc: &mut BatchScratch,
    ) {
        self.chunk_body::<true>(plan, inp, scaled, want, sc);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn chunk_avx2(
        &self,
        plan: &ThetaPlan,
        inp: &ChunkIn,
        scaled: bool,
        want: u16,
        sc: &mut BatchScratch,
    ) {
        self.chunk_body::<true>(plan, inp, scaled, want, sc);
    }

    #[inline(always)]
    fn chunk_body<const FMA: bool>(
        &self,
        plan: &ThetaPlan,
        inp: &ChunkIn,
        scaled: bool,
        want: u16,
        sc: &mut BatchScratch,
    ) {
        let pi = std::f64::consts::PI;
        let y = &plan.y;
        // u_k = exp(iπ z_k) per lane; the normalisation exp(-π w_rᵀYw_r) goes into X1
        let (c1, s1) = sincos_pi(&inp.zre[0]);
        let (c2, s2) = sincos_pi(&inp.zre[1]);
        let e1 = exp_lanes(&std::array::from_fn(|p| -pi * inp.zim[0][p]));
        let e2 = exp_lanes(&std::array::from_fn(|p| -pi * inp.zim[1][p]));
        let norm = exp_lanes(&std::array::from_fn(|p| {
            let (w0, w1) = (inp.wr[0][p], inp.wr[1][p]);
            -pi * (y[0] * w0 * w0 + (y[1] + y[2]) * w0 * w1 + y[3] * w1 * w1)
        }));
        let mut u1 = [[0.0; LANES]; 2];
        let mut u2 = [[0.0; LANES]; 2];
        for p in 0..LANES {
            u1[0][p] = e1[p] * c1[p];
            u1[1][p] = e1[p] * s1[p];
            u2[0][p] = e2[p] * c2[p];
            u2[1][p] = e2[p] * s2[p];
        }
        fill_powers(&u1, self.j1lo, &norm, &mut sc.x1re, &mut sc.x1im);
        fill_powers(&u2, self.j2lo, &[1.0; LANES], &mut sc.x2re, &mut sc.x2im);
        // Class sums on the stack: no aliasing with the power tables, so the
        // row loops need no runtime overlap checks.
        let mut sre = [AZERO; 16];
        let mut sim = [AZERO; 16];
        self.rows_body::<FMA>(sc, &mut sre, &mut sim);
        // factor exp(iπ φ/π) (· exp(L)) common to the 16 values of a point
        let (mut fr, mut fi) = sincos_pi(&inp.phase);
        if scaled {
            let el = exp_lanes(&inp.logs);
            for p in 0..LANES {
                fr[p] *= el[p];
                fi[p] *= el[p];
            }
        }
        // θ[a;b] = i^{u(a,b)} (-1)^{a·p + b·q} f Σ_h (-1)^{h·b} S[a + 2h]
        for a in 0..4 {
            if (want >> (4 * a)) & 0xf == 0 {
                continue;
            }
            let r = &plan.class_of[4 * a..4 * a + 4];
            let mut vre = [[0.0; LANES]; 4];
            let mut vim = [[0.0; LANES]; 4];
            for p in 0..LANES {
                let (s0r, s1r, s2r, s3r) = (sre[r[0]][p], sre[r[1]][p], sre[r[2]][p], sre[r[3]][p]);
                let (s0i, s1i, s2i, s3i) = (sim[r[0]][p], sim[r[1]][p], sim[r[2]][p], sim[r[3]][p]);
                let (p0r, p1r, p2r, p3r) = (s0r + s1r, s0r - s1r, s2r + s3r, s2r - s3r);
                let (p0i, p1i, p2i, p3i) = (s0i + s1i, s0i - s1i, s2i + s3i, s2i - s3i);
                vre[0][p] = p0r + p2r;
                vre[1][p] = p1r + p3r;
                vre[2][p] = p0r - p2r;
                vre[3][p] = p1r - p3r;
                vim[0][p] = p0i + p2i;
                vim[1][p] = p1i + p3i;
                vim[2][p] = p0i - p2i;
                vim[3][p] = p1i - p3i;
            }
            for b in 0..4 {
                let idx = (a << 2) | b;
                if (want >> idx) & 1 == 0 {
                    continue;
                }
                let unit = UNIT[(plan.unit_pow[idx] & 3) as usize];
                let (sa, sb) = (&inp.sa[a], &inp.sb[b]);
                for p in 0..LANES {
                    let sg = sa[p] * sb[p];
                    let wr = (vre[b][p] * fr[p] - vim[b][p] * fi[p]) * sg;
                    let wi = (vre[b][p] * fi[p] + vim[b][p] * fr[p]) * sg;
                    sc.out_re[idx][p] = unit.0 * wr - unit.1 * wi;
                    sc.out_im[idx][p] = unit.0 * wi + unit.1 * wr;
                }
            }
        }
    }

    /// Row by row, class by class: `acc = Σ_{j2 ≡ c} C(j1, j2) X2(j2)` over all
    /// lanes, then `S[4 (j1 mod 4) + c] += X1(j1) acc`.
    ///
    /// `FMA`: fused multiply-adds (the copies compiled for CPUs with FMA);
    /// they round once instead of twice, a difference of a few ulp of the
    /// largest term in the sums.
    #[inline(always)]
    fn rows_body<const FMA: bool>(
        &self,
        sc: &BatchScratch,
        sre: &mut [ALane; 16],
        sim: &mut [ALane; 16],
    ) {
        for (a, &(lo, hi)) in self.rows.iter().enumerate() {
            if lo > hi {
                continue;
            }
            let j1 = self.j1lo + a as i64;
            let base = ((j1 & 3) as usize) * 4;
            let crow_re = &self.cre[a * self.n2..(a + 1) * self.n2];
            let crow_im = &self.cim[a * self.n2..(a + 1) * self.n2];
            for first in lo..(lo + 4).min(hi + 1) {
                let cls = ((self.j2lo + first as i64) & 3) as usize;
                let mut acc_re = [0.0; LANES];
                let mut acc_im = [0.0; LANES];
                let mut b = first;
                while b <= hi {
                    let (cr, ci) = (crow_re[b], crow_im[b]);
                    let (xr, xi) = (&sc.x2re[b], &sc.x2im[b]);
                    if FMA {
                        for p in 0..LANES {
                            acc_re[p] = cr.mul_add(xr[p], (-ci).mul_add(xi[p], acc_re[p]));
                            acc_im[p] = cr.mul_add(xi[p], ci.mul_add(xr[p], acc_im[p]));
                        }
                    } else {
                        for p in 0..LANES {
                            acc_re[p] += cr * xr[p] - ci * xi[p];
                            acc_im[p] += cr * xi[p] + ci * xr[p];
                        }
                    }
                    b += 4;
                }
                let (yr, yi) = (&sc.x1re[a], &sc.x1im[a]);
                let r = base + cls;
                if FMA {
                    for p in 0..LANES {
                        sre[r][p] =
                            acc_re[p].mul_add(yr[p], (-acc_im[p]).mul_add(yi[p], sre[r][p]));
                        sim[r][p] = acc_re[p].mul_add(yi[p], acc_im[p].mul_add(yr[p], sim[r][p]));
                    }
                } else {
                    for p in 0..LANES {
                        sre[r][p] += acc_re[p] * yr[p] - acc_im[p] * yi[p];
                        sim[r][p] += acc_re[p] * yi[p] + acc_im[p] * yr[p];
                    }
                }
            }
        }
    }
}

/// `x[j - lo] = scale · u^j` for all lanes, `j = lo..lo+len` (`lo ≤ 0`), by
/// products outward from `j = 0` (phases stay small near the centre).
#[inline(always)]
fn fill_powers(u: &[Lane; 2], lo: i64, scale: &Lane, re: &mut [ALane], im: &mut [ALane]) {
    let zero = (-lo) as usize;
    // 1/u = conj(u) / |u|²
    let mut inv = [[0.0; LANES]; 2];
    for p in 0..LANES {
        let n2 = u[0][p] * u[0][p] + u[1][p] * u[1][p];
        inv[0][p] = u[0][p] / n2;
        inv[1][p] = -u[1][p] / n2;
    }
    re[zero] = ALane(*scale);
    im[zero] = AZERO;
    for k in zero + 1..re.len() {
        let (pr, pi) = (re[k - 1], im[k - 1]);
        for p in 0..LANES {
            re[k][p] = pr[p] * u[0][p] - pi[p] * u[1][p];
            im[k][p] = pr[p] * u[1][p] + pi[p] * u[0][p];
        }
    }
    for k in (0..zero).rev() {
        let (pr, pi) = (re[k + 1], im[k + 1]);
        for p in 0..LANES {
            re[k][p] = pr[p] * inv[0][p] - pi[p] * inv[1][p];
            im[k][p] = pr[p] * inv[1][p] + pi[p] * inv[0][p];
        }
    }
}

/// `1.5·2^52`: adding and subtracting it rounds a double of magnitude below 2^51
/// to the nearest integer (ties to even) with plain arithmetic, which vectorises.
const MAGIC: f64 = 6_755_399_441_055_744.0;

/// Taylor coefficients of `sin t / t` and `cos t` in `t²` (truncation below
/// 1e-18 for `|t| ≤ π/2`).
const SIN_C: [f64; 12] = [
    1.0,
    -0.16666666666666666,
    0.008333333333333333,
    -0.0001984126984126984,
    2.7557319223985893e-06,
    -2.505210838544172e-08,
    1.6059043836821613e-10,
    -7.647163731819816e-13,
    2.8114572543455206e-15,
    -8.22063524662433e-18,
    1.9572941063391263e-20,
    -3.868170170630684e-23,
];
const COS_C: [f64; 12] = [
    1.0,
    -0.5,
    0.041666666666666664,
    -0.001388888888888889,
    2.48015873015873e-05,
    -2.755731922398589e-07,
    2.08767569878681e-09,
    -1.1470745597729725e-11,
    4.779477332387385e-14,
    -1.5619206968586225e-16,
    4.110317623312165e-19,
    -8.896791392450574e-22,
];
/// `1/k!`, k = 0..13: Taylor series of `exp r`, truncation below 1e-17 relative
/// for `|r| ≤ ln2/2`.
const EXP_C: [f64; 14] = [
    1.0,
    1.0,
    0.5,
    0.16666666666666666,
    0.041666666666666664,
    0.008333333333333333,
    0.001388888888888889,
    0.0001984126984126984,
    2.48015873015873e-05,
    2.7557319223985893e-06,
    2.755731922398589e-07,
    2.505210838544172e-08,
    2.08767569878681e-09,
    1.6059043836821613e-10,
];

#[inline(always)]
fn horner<const N: usize>(c: &[f64; N], x: f64) -> f64 {
    let mut acc = c[N - 1];
    for k in (0..N - 1).rev() {
        acc = acc * x + c[k];
    }
    acc
}

/// `(cos πx, sin πx)` per lane: `x = n + r`, `|r| ≤ 1/2` exactly, then Taylor
/// polynomials in `t = πr` and the sign `(-1)^n`. A few ulp, like the
/// library functions it replaces (it is written so that it vectorises). For
/// `|x| ≥ 2^51` (where `x` has no fractional digits worth the name) `r` is 0.
#[inline(always)]
fn sincos_pi(x: &Lane) -> (Lane, Lane) {
    let mut c = [0.0; LANES];
    let mut s = [0.0; LANES];
    for p in 0..LANES {
        let big = x[p].abs() >= 2_251_799_813_685_248.0;
        let n = if big { x[p] } else { (x[p] + MAGIC) - MAGIC };
        let r = x[p] - n;
        let h = 0.5 * n;
        let hn = if big { h } else { (h + MAGIC) - MAGIC };
        let sign = 1.0 - 4.0 * (h - hn).abs();
        let t = std::f64::consts::PI * r;
        let t2 = t * t;
        c[p] = sign * horner(&COS_C, t2);
        s[p] = sign * t * horner(&SIN_C, t2);
    }
    (c, s)
}

/// `exp x` per lane: `x = k ln2 + r` (Cody–Waite, `|r| ≤ ln2/2`), Taylor polynomial,
/// times `2^k` built from the exponent bits in two halves (so subnormal results
/// and `k = 1024` stay correct); `+∞` above the double range, 0 far below it.
#[inline(always)]
fn exp_lanes(x: &Lane) -> Lane {
    const LN2_HI: f64 = 0.693_147_180_369_123_8; // 0x3fe62e42fee00000: k·LN2_HI exact
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let mut out = [0.0; LANES];
    for p in 0..LANES {
        let xc = x[p].clamp(-746.0, 710.0);
        let k = (xc * std::f64::consts::LOG2_E + MAGIC) - MAGIC;
        let r = (xc - k * LN2_HI) - k * LN2_LO;
        let k1 = (0.5 * k + MAGIC) - MAGIC;
        let k2 = k - k1;
        let pow2 = |e: f64| f64::from_bits(((e + 1023.0) + MAGIC).to_bits() << 52);
        let v = horner(&EXP_C, r) * pow2(k1) * pow2(k2);
        out[p] = if x[p] > 709.782_712_893_384 {
            f64::INFINITY
        } else {
            v
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane functions replace libm in the kernel: a few ulp is what the
    /// sums can absorb (they amplify input errors by |j| ≲ 20 anyway).
    const LANE_RTOL: f64 = 4.0 * f64::EPSILON;

    /// The three compiled copies of the chunk kernel (baseline, AVX2, AVX-512,
    /// as far as this CPU has them) give the same values to a few ulps: the AVX
    /// copies fuse the row sums' multiply-adds (`mul_add`), the baseline rounds
    /// each product (largest difference seen 4.4e-16 relative; asserted 1e-15).
    #[test]
    fn compiled_copies_of_the_chunk_kernel_agree() {
        let tau = [
            Complex64::new(0.3, 1.1),
            Complex64::new(0.1, 0.4),
            Complex64::new(0.1, 0.4),
            Complex64::new(-0.2, 1.3),
        ];
        let plan = ThetaPlan::new(&tau, 2, 1e-15, 0).unwrap();
        let b2 = Batch2::build(&plan).unwrap();
        let mut inp = ChunkIn::default();
        for p in 0..LANES {
            let t = p as f64;
            let red = plan
                .reduce2::<false>([
                    Complex64::new((0.37 * t).sin() * 3.0, (0.71 * t).cos() * 2.5),
                    Complex64::new((0.53 * t).cos() * 2.0, (0.29 * t).sin() * 1.5),
                ])
                .unwrap();
            inp.set(p, &red);
        }
        let mut base = b2.scratch();
        b2.chunk_body::<false>(&plan, &inp, true, ALL, &mut base);
        let mut variants = Vec::new();
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                let mut sc = b2.scratch();
                // SAFETY: feature checked just above.
                unsafe { b2.chunk_avx2(&plan, &inp, true, ALL, &mut sc) };
                variants.push(sc);
            }
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("fma") {
                let mut sc = b2.scratch();
                // SAFETY: feature checked just above.
                unsafe { b2.chunk_avx512(&plan, &inp, true, ALL, &mut sc) };
                variants.push(sc);
            }
        }
        for sc in &variants {
            for idx in 0..16 {
                for p in 0..LANES {
                    let scale = (0..16)
                        .map(|i| base.out_re[i][p].hypot(base.out_im[i][p]))
                        .fold(0.0, f64::max);
                    let d = (sc.out_re[idx][p] - base.out_re[idx][p])
                        .hypot(sc.out_im[idx][p] - base.out_im[idx][p]);
                    // same operations; only the vector width differs (sum order is per lane)
                    assert!(d <= 1e-15 * scale, "idx {idx} lane {p}: {d:e}");
                }
            }
        }
    }

    #[test]
    fn sincos_pi_matches_std() {
        let xs: Vec<f64> = (0..4000)
            .map(|i| -37.3 + i as f64 * 0.01873)
            .chain([0.0, 0.5, -0.5, 1.0, 2.5, 1e6 + 0.25, 3.0e15, -7.0e15])
            .collect();
        for chunk in xs.chunks(LANES) {
            let mut x = [0.0; LANES];
            x[..chunk.len()].copy_from_slice(chunk);
            let (c, s) = sincos_pi(&x);
            for p in 0..chunk.len() {
                // reference: reduce exactly first, then std on |r| ≤ 1/2
                let n = x[p].round();
                let r = x[p] - n;
                let sign = if (n / 2.0).fract() == 0.0 { 1.0 } else { -1.0 };
                let t = std::f64::consts::PI * r;
                assert!(
                    (c[p] - sign * t.cos()).abs() <= LANE_RTOL,
                    "cos at {}",
                    x[p]
                );
                assert!(
                    (s[p] - sign * t.sin()).abs() <= LANE_RTOL,
                    "sin at {}",
                    x[p]
                );
            }
        }
    }

    #[test]
    fn exp_lanes_matches_std_and_handles_the_range_ends() {
        let xs: Vec<f64> = (0..3000)
            .map(|i| -740.0 + i as f64 * 0.4831)
            .chain([
                0.0, 1e-300, -1e-300, 709.78, 709.8, 800.0, -745.0, -760.0, -0.3465,
            ])
            .collect();
        for chunk in xs.chunks(LANES) {
            let mut x = [0.0; LANES];
            x[..chunk.len()].copy_from_slice(chunk);
            let e = exp_lanes(&x);
            for p in 0..chunk.len() {
                let want = x[p].exp();
                if want.is_infinite() {
                    assert_eq!(e[p], f64::INFINITY, "at {}", x[p]);
                } else if want < 1e-300 {
                    assert!(e[p] >= 0.0 && e[p] < 1e-300, "at {}", x[p]);
                } else {
                    assert!(
                        (e[p] - want).abs() <= LANE_RTOL * want,
                        "at {}: {} vs {want}",
                        x[p],
                        e[p]
                    );
                }
            }
        }
    }
}
