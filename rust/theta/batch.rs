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

use super::{split, sum, ThetaPlan};
use num_complex::Complex64;

/// Points per chunk.
pub(super) const LANES: usize = 16;

/// Largest table kept in a plan (entries of `C`; 1 MiB).
const MAX_TABLE: usize = 1 << 16;

/// Rounding margin on `|w_r| ≤ 1/2` when building the union region.
const W_MARGIN: f64 = 0.51;

type Lane = [f64; LANES];

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
    x1re: Vec<Lane>,
    x1im: Vec<Lane>,
    x2re: Vec<Lane>,
    x2im: Vec<Lane>,
    /// Class sums, `sre[r][p] + i sim[r][p]` for class `r` and lane `p`.
    pub(super) sre: Vec<Lane>,
    pub(super) sim: Vec<Lane>,
}

impl Batch2 {
    /// `None` unless g = 2, the table is small and `Xk` cannot overflow.
    pub(super) fn build(plan: &ThetaPlan) -> Option<Batch2> {
        if plan.g != 2 {
            return None;
        }
        let (d1, d2, l21) = (plan.ldl_d[0], plan.ldl_d[1], plan.ldl_l[2]);
        let rq = plan.rq;
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
            x1re: vec![[0.0; LANES]; self.n1],
            x1im: vec![[0.0; LANES]; self.n1],
            x2re: vec![[0.0; LANES]; self.n2],
            x2im: vec![[0.0; LANES]; self.n2],
            sre: vec![[0.0; LANES]; 16],
            sim: vec![[0.0; LANES]; 16],
        }
    }

    /// Class sums `S[r]` (r = 4 (j1 mod 4) + (j2 mod 4)), normalised by
    /// `exp(-π w_rᵀYw_r)`, for `LANES` reduced points, into `sc.sre`, `sc.sim`.
    pub(super) fn class_sums(
        &self,
        plan: &ThetaPlan,
        zr: &[[Complex64; 2]; LANES],
        wr: &[[f64; 2]; LANES],
        sc: &mut BatchScratch,
    ) {
        let pi = std::f64::consts::PI;
        // u_k = exp(iπ z_k) per lane, the normalisation exp(-π w_rᵀYw_r) folded into X1
        let mut u1 = [[0.0; LANES]; 2];
        let mut u2 = [[0.0; LANES]; 2];
        let mut norm = [0.0; LANES];
        for p in 0..LANES {
            let mut quad = 0.0;
            for i in 0..2 {
                for k in 0..2 {
                    quad += plan.y[i * 2 + k] * wr[p][i] * wr[p][k];
                }
            }
            norm[p] = (-pi * quad).exp();
            let a = (Complex64::i() * pi * zr[p][0]).exp();
            let b = (Complex64::i() * pi * zr[p][1]).exp();
            u1[0][p] = a.re;
            u1[1][p] = a.im;
            u2[0][p] = b.re;
            u2[1][p] = b.im;
        }
        #[cfg(target_arch = "x86_64")]
        {
            if false && std::is_x86_feature_detected!("avx512f") {
                // SAFETY: the CPU supports AVX-512F (checked just above).
                unsafe { self.kernel_avx512(sc, &u1, &u2, &norm) };
                return;
            }
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 (checked just above).
                unsafe { self.kernel_avx2(sc, &u1, &u2, &norm) };
                return;
            }
        }
        self.kernel_generic(sc, &u1, &u2, &norm);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn kernel_avx512(
        &self,
        sc: &mut BatchScratch,
        u1: &[Lane; 2],
        u2: &[Lane; 2],
        norm: &Lane,
    ) {
        fill_powers(u1, self.j1lo, norm, &mut sc.x1re, &mut sc.x1im);
        fill_powers(u2, self.j2lo, &[1.0; LANES], &mut sc.x2re, &mut sc.x2im);
        self.rows_body(sc);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn kernel_avx2(
        &self,
        sc: &mut BatchScratch,
        u1: &[Lane; 2],
        u2: &[Lane; 2],
        norm: &Lane,
    ) {
        fill_powers(u1, self.j1lo, norm, &mut sc.x1re, &mut sc.x1im);
        fill_powers(u2, self.j2lo, &[1.0; LANES], &mut sc.x2re, &mut sc.x2im);
        self.rows_body(sc);
    }

    fn kernel_generic(&self, sc: &mut BatchScratch, u1: &[Lane; 2], u2: &[Lane; 2], norm: &Lane) {
        fill_powers(u1, self.j1lo, norm, &mut sc.x1re, &mut sc.x1im);
        fill_powers(u2, self.j2lo, &[1.0; LANES], &mut sc.x2re, &mut sc.x2im);
        self.rows_body(sc);
    }

    /// Row by row, class by class: `acc = Σ_{j2 ≡ c} C(j1, j2) X2(j2)` over all
    /// lanes, then `S[4 (j1 mod 4) + c] += X1(j1) acc`.
    #[inline(always)]
    fn rows_body(&self, sc: &mut BatchScratch) {
        for v in sc.sre.iter_mut().chain(sc.sim.iter_mut()) {
            *v = [0.0; LANES];
        }
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
                    for p in 0..LANES {
                        acc_re[p] += cr * xr[p] - ci * xi[p];
                        acc_im[p] += cr * xi[p] + ci * xr[p];
                    }
                    b += 4;
                }
                let (yr, yi) = (&sc.x1re[a], &sc.x1im[a]);
                let r = base + cls;
                for p in 0..LANES {
                    sc.sre[r][p] += acc_re[p] * yr[p] - acc_im[p] * yi[p];
                    sc.sim[r][p] += acc_re[p] * yi[p] + acc_im[p] * yr[p];
                }
            }
        }
    }
}

/// `x[j - lo] = scale · u^j` for all lanes, `j = lo..lo+len` (`lo ≤ 0`), by
/// products outward from `j = 0` (phases stay small near the centre).
#[inline(always)]
fn fill_powers(u: &[Lane; 2], lo: i64, scale: &Lane, re: &mut [Lane], im: &mut [Lane]) {
    let zero = (-lo) as usize;
    // 1/u = conj(u) / |u|²
    let mut inv = [[0.0; LANES]; 2];
    for p in 0..LANES {
        let n2 = u[0][p] * u[0][p] + u[1][p] * u[1][p];
        inv[0][p] = u[0][p] / n2;
        inv[1][p] = -u[1][p] / n2;
    }
    re[zero] = *scale;
    im[zero] = [0.0; LANES];
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
