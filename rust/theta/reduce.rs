//! The reduction of `z` to the fundamental cell, `z = z_r + p + τ'q`, and
//! what it contributes: the exponent `L = π (Im z)ᵀ (Im τ)^{-1} (Im z)`, the
//! phase `exp(iφ)` and the parities of `p`, `q` (the signs of the
//! characteristics); for genus 2 written out, and for a block of points given
//! by lattice coordinates vectorised across the block.

use super::selected::{LatticeLanes, BLOCK};
use super::{batch, pi, sum, ThetaPlan, MAX_GENUS};
use crate::error::{Error, Result};
use crate::numeric::compensated::{split, two_sum};
use num_complex::Complex64;

/// Largest `|Re z_k|` and `|(Im τ)^{-1} Im z|_k` accepted: beyond 2^52 a double
/// has no fractional part, so θ is not determined to any digit.
pub const MAX_REDUCTION: f64 = 4.5e15;

/// The nearest integer to the reduced real part `re` of an entry `z_re` of z,
/// refused beyond [`MAX_REDUCTION`], where double precision no longer fixes it.
#[inline(always)]
fn integer_part(re: f64, z_re: f64) -> Result<f64> {
    if re.abs() > MAX_REDUCTION {
        return Err(Error::InvalidArgument {
            what: "z",
            reason: format!("Re z has an entry {z_re:e}: theta is not determined"),
        });
    }
    Ok(sum::round_i64(re) as f64)
}

/// A reduced point: `z = z_r + p + τ'q` and what the reduction contributes.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Reduced {
    pub(super) zr: [Complex64; MAX_GENUS],
    pub(super) wr: [f64; MAX_GENUS],
    pub(super) q: [f64; MAX_GENUS],
    pub(super) log_scale: f64,
    /// `exp(iφ)`, `φ = -π qᵀX'q - 2π qᵀ Re z_r` (left at 1 by the batch kernel's
    /// reduction, which evaluates it for 16 points at once from `phase`).
    pub(super) prefactor: Complex64,
    /// `φ/π` (genus 2 only).
    pub(super) phase: f64,
    /// Parities of `p` and `q` as bit masks (coordinate k at bit g-1-k).
    pub(super) pbits: usize,
    pub(super) qbits: usize,
}

impl ThetaPlan {
    /// The reduction `z = z_r + p + τ'q` and the factors it contributes.
    pub(super) fn reduce(&self, z: &[Complex64]) -> Result<Reduced> {
        if self.g == 2 && z.len() == 2 {
            return self.reduce2::<true>([z[0], z[1]]);
        }
        let g = self.g;
        for (k, c) in z.iter().enumerate() {
            if !(c.re.is_finite() && c.im.is_finite()) {
                return Err(Error::NonFinite {
                    what: "z",
                    index: k,
                });
            }
        }
        // Reduction z = z_r + p + τ' q, q = round((Im τ)^{-1} Im z), p = round(Re(z - τ'q)).
        let mut zr = [Complex64::new(0.0, 0.0); MAX_GENUS];
        let mut q = [0.0f64; MAX_GENUS];
        let mut p = [0.0f64; MAX_GENUS];
        let mut w = [0.0f64; MAX_GENUS];
        for i in 0..g {
            w[i] = (0..g).map(|k| self.yinv[i * g + k] * z[k].im).sum();
            if w[i].abs() > MAX_REDUCTION {
                return Err(Error::InvalidArgument {
                    what: "z",
                    reason: format!(
                        "(Im tau)^-1 Im z has an entry {:e}: theta is not representable",
                        w[i]
                    ),
                });
            }
            q[i] = sum::round_i64(w[i]) as f64;
        }
        let shifted = q[..g].iter().any(|&v| v != 0.0);
        for i in 0..g {
            // z - τ'q with exact products and compensated sums: z_r is then
            // correctly rounded, not off by eps·|τ q| (which would cost 2π|m|·eps|τq|).
            let (re, im) = if shifted {
                let xrow: [f64; MAX_GENUS] =
                    std::array::from_fn(|k| if k < g { self.x[i * g + k] } else { 0.0 });
                let yrow: [f64; MAX_GENUS] =
                    std::array::from_fn(|k| if k < g { self.y[i * g + k] } else { 0.0 });
                (
                    residual(z[i].re, &xrow[..g], &q[..g]),
                    residual(z[i].im, &yrow[..g], &q[..g]),
                )
            } else {
                (z[i].re, z[i].im)
            };
            p[i] = integer_part(re, z[i].re)?;
            zr[i] = Complex64::new(re - p[i], im);
        }
        let mut wr = [0.0f64; MAX_GENUS];
        for i in 0..g {
            wr[i] = (0..g).map(|k| self.yinv[i * g + k] * zr[k].im).sum();
        }
        // L = π (Im z)ᵀ (Im τ)^{-1} (Im z) = π (q + w_r)ᵀ Y (q + w_r); the first form
        // has no cancellation between large terms.
        let mut log_scale = 0.0;
        for i in 0..g {
            log_scale += pi() * z[i].im * (q[i] + wr[i]);
        }
        let log_scale = finite_log_scale(log_scale)?;
        // φ = -π qᵀX'q - 2π qᵀ Re z_r, the quadratic part reduced mod 2 exactly.
        let mut phi = 0.0;
        if shifted {
            phi -= pi() * quad_mod2(&self.x, &q[..g], g);
            for i in 0..g {
                phi -= 2.0 * pi() * q[i] * zr[i].re;
            }
        }
        let prefactor = if shifted {
            Complex64::from_polar(1.0, phi)
        } else {
            Complex64::new(1.0, 0.0)
        };
        let (mut pbits, mut qbits) = (0usize, 0usize);
        for k in 0..g {
            pbits |= ((p[k] as i64 & 1) as usize) << (g - 1 - k);
            qbits |= ((q[k] as i64 & 1) as usize) << (g - 1 - k);
        }
        Ok(Reduced {
            zr,
            wr,
            q,
            log_scale,
            prefactor,
            phase: 0.0,
            pbits,
            qbits,
        })
    }

    /// [`ThetaPlan::reduce`] written out for genus 2 (same operations, fixed size);
    /// `PREFACTOR = false` leaves `prefactor = 1` and only records `phase`.
    pub(super) fn reduce2<const PREFACTOR: bool>(&self, z: [Complex64; 2]) -> Result<Reduced> {
        for (k, c) in z.iter().enumerate() {
            if !(c.re.is_finite() && c.im.is_finite()) {
                return Err(Error::NonFinite {
                    what: "z",
                    index: k,
                });
            }
        }
        let (yi, x, y) = (&self.yinv, &self.x, &self.y);
        let w = [
            yi[0] * z[0].im + yi[1] * z[1].im,
            yi[2] * z[0].im + yi[3] * z[1].im,
        ];
        for wk in w {
            if wk.abs() > MAX_REDUCTION {
                return Err(Error::InvalidArgument {
                    what: "z",
                    reason: format!(
                        "(Im tau)^-1 Im z has an entry {wk:e}: theta is not representable"
                    ),
                });
            }
        }
        let q = [sum::round_i64(w[0]) as f64, sum::round_i64(w[1]) as f64];
        let shifted = q[0] != 0.0 || q[1] != 0.0;
        let mut red = Reduced::default();
        let mut p = [0.0; 2];
        for i in 0..2 {
            let (re, im) = if shifted {
                (
                    residual(z[i].re, &x[2 * i..2 * i + 2], &q),
                    residual(z[i].im, &y[2 * i..2 * i + 2], &q),
                )
            } else {
                (z[i].re, z[i].im)
            };
            p[i] = integer_part(re, z[i].re)?;
            red.zr[i] = Complex64::new(re - p[i], im);
        }
        let (zr0, zr1) = (red.zr[0].im, red.zr[1].im);
        red.wr[0] = yi[0] * zr0 + yi[1] * zr1;
        red.wr[1] = yi[2] * zr0 + yi[3] * zr1;
        red.q[0] = q[0];
        red.q[1] = q[1];
        let log_scale = pi() * z[0].im * (q[0] + red.wr[0]) + pi() * z[1].im * (q[1] + red.wr[1]);
        red.log_scale = finite_log_scale(log_scale)?;
        red.prefactor = Complex64::new(1.0, 0.0);
        if shifted {
            red.phase = -quad_mod2(x, &q, 2) - 2.0 * (q[0] * red.zr[0].re + q[1] * red.zr[1].re);
            if PREFACTOR {
                red.prefactor = Complex64::from_polar(1.0, pi() * red.phase);
            }
        }
        red.pbits = ((p[0] as i64 & 1) << 1 | (p[1] as i64 & 1)) as usize;
        red.qbits = ((q[0] as i64 & 1) << 1 | (q[1] as i64 & 1)) as usize;
        Ok(red)
    }

    /// [`ThetaPlan::reduce2`] (without the prefactor) for a point given by real
    /// lattice coordinates, `z = x + τ y`, written straight into lane `lane`
    /// of the batch kernel's input (no [`Reduced`] is built and copied):
    /// `q = round(y)`, `y_r = y − q`, so `(Im τ)^{-1} Im z_r = y_r` exactly
    /// and no solve with `Im τ` is needed. `Re τ = Re τ' + 2S` with `S`
    /// integer, so replacing `τ'` by `τ` in `z = z_r + p + τ'q` moves `p` by
    /// the even vector `2Sq` and `qᵀX'q` by the even `2qᵀSq`: the parities
    /// and the phase mod 2 are unchanged.
    #[inline(always)]
    pub(super) fn reduce2_lattice_into(
        &self,
        x: [f64; 2],
        y: [f64; 2],
        inp: &mut batch::ChunkIn,
        lane: usize,
    ) -> Result<()> {
        for (k, v) in x.iter().chain(y.iter()).enumerate() {
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    what: "lattice coordinates",
                    index: k,
                });
            }
        }
        if y[0].abs().max(y[1].abs()) > MAX_REDUCTION {
            return Err(Error::InvalidArgument {
                what: "z",
                reason: format!("lattice coordinate y = {y:?}: theta is not representable"),
            });
        }
        let (rt, it) = (&self.re_tau, &self.y);
        let q = [sum::round_i64(y[0]) as f64, sum::round_i64(y[1]) as f64];
        let yr = [y[0] - q[0], y[1] - q[1]];
        let mut p = [0.0; 2];
        let mut zr_re = [0.0; 2];
        for i in 0..2 {
            let re = x[i] + rt[2 * i] * yr[0] + rt[2 * i + 1] * yr[1];
            let im = it[2 * i] * yr[0] + it[2 * i + 1] * yr[1];
            p[i] = integer_part(re, re)?;
            zr_re[i] = re - p[i];
            inp.zre[i][lane] = zr_re[i];
            inp.zim[i][lane] = im;
            inp.wr[i][lane] = yr[i];
        }
        let imz = [it[0] * y[0] + it[1] * y[1], it[2] * y[0] + it[3] * y[1]];
        inp.logs[lane] = finite_log_scale(pi() * (imz[0] * y[0] + imz[1] * y[1]))?;
        inp.phase[lane] = if q[0] != 0.0 || q[1] != 0.0 {
            let xq = &self.x;
            let quad = if q[0].abs() <= 1.0 && q[1].abs() <= 1.0 {
                // q_i q_k ∈ {−1, 0, 1}: the products are exact.
                q[0] * q[0] * xq[0] + q[0] * q[1] * (xq[1] + xq[2]) + q[1] * q[1] * xq[3]
            } else {
                quad_mod2(xq, &q, 2)
            };
            -quad - 2.0 * (q[0] * zr_re[0] + q[1] * zr_re[1])
        } else {
            0.0
        };
        inp.set_signs(
            lane,
            ((p[0] as i64 & 1) << 1 | (p[1] as i64 & 1)) as usize,
            ((q[0] as i64 & 1) << 1 | (q[1] as i64 & 1)) as usize,
        );
        Ok(())
    }

    /// Lanes `0..m` of the batch kernel's input from the lattice coordinates
    /// `lanes`: [`ThetaPlan::reduce2_lattice_into`] lane by lane, or, when
    /// every coordinate lies in `[−1, 1]` and `Re τ` keeps `Re z` far inside
    /// the representable range, the same arithmetic for all lanes at once
    /// ([`ThetaPlan::reduce2_bounded`]).
    pub(super) fn reduce2_lattice_lanes(
        &self,
        lanes: &LatticeLanes,
        m: usize,
        inp: &mut batch::ChunkIn,
    ) -> Result<()> {
        // NaN fails the comparison, so non-finite blocks take the checked path.
        let bounded =
            (lanes.x.iter().chain(&lanes.y).flatten()).fold(true, |ok, v| ok & (v.abs() <= 1.0));
        // |Re z| ≤ |x| + Σ_k |Re τ_ik| |y_r,k| ≤ 1 + (|Re τ_i1| + |Re τ_i2|)/2: well
        // within the range the per-point path checks (`integer_part`; half of it,
        // so that rounding cannot cross it), or that path decides.
        let rt = &self.re_tau;
        let re_ok = (0..2)
            .all(|i| 1.0 + 0.5 * (rt[2 * i].abs() + rt[2 * i + 1].abs()) <= 0.5 * MAX_REDUCTION);
        if !(bounded && re_ok) {
            if m < BLOCK {
                *inp = batch::ChunkIn::default();
            }
            for p in 0..m {
                let x = [lanes.x[0][p], lanes.x[1][p]];
                let y = [lanes.y[0][p], lanes.y[1][p]];
                self.reduce2_lattice_into(x, y, inp, p)?;
            }
            return Ok(());
        }
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2 (checked just above).
                unsafe { self.reduce2_bounded_avx2(lanes, inp) };
                return Ok(());
            }
        }
        self.reduce2_bounded(lanes, inp);
        Ok(())
    }

    /// [`ThetaPlan::reduce2_bounded`] compiled for AVX2 (rounding by
    /// `vroundpd`, four lanes per instruction; no FMA, so the same bits).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn reduce2_bounded_avx2(&self, lanes: &LatticeLanes, inp: &mut batch::ChunkIn) {
        self.reduce2_bounded(lanes, inp);
    }

    /// [`ThetaPlan::reduce2_lattice_into`] for all lanes, given `|x|, |y| ≤ 1`:
    /// then `q = round(y) ∈ {−1, 0, 1}`, nothing can overflow, and the
    /// rounding `floor(v + 1/2)`, the parities `v − 2 floor(v/2)` and the
    /// signs are plain arithmetic on every lane.
    #[inline(always)]
    pub(super) fn reduce2_bounded(&self, lanes: &LatticeLanes, inp: &mut batch::ChunkIn) {
        // Fixed-size copies: no bounds checks in the loop, so it vectorises.
        let four = |v: &[f64]| -> [f64; 4] { std::array::from_fn(|k| v[k]) };
        let (rt, it, xq) = (four(&self.re_tau), four(&self.y), four(&self.x));
        let parity = |v: f64| v - 2.0 * (0.5 * v).floor();
        for p in 0..BLOCK {
            let y = [lanes.y[0][p], lanes.y[1][p]];
            let q = [(y[0] + 0.5).floor(), (y[1] + 0.5).floor()];
            let yr = [y[0] - q[0], y[1] - q[1]];
            let mut zr_re = [0.0; 2];
            let mut sp = [0.0; 2];
            for i in 0..2 {
                let re = lanes.x[i][p] + rt[2 * i] * yr[0] + rt[2 * i + 1] * yr[1];
                let pi_ = (re + 0.5).floor();
                zr_re[i] = re - pi_;
                sp[i] = 1.0 - 2.0 * parity(pi_);
                inp.zre[i][p] = zr_re[i];
                inp.zim[i][p] = it[2 * i] * yr[0] + it[2 * i + 1] * yr[1];
                inp.wr[i][p] = yr[i];
            }
            let imz = [it[0] * y[0] + it[1] * y[1], it[2] * y[0] + it[3] * y[1]];
            inp.logs[p] = (pi() * (imz[0] * y[0] + imz[1] * y[1])).max(0.0);
            // q_i q_k ∈ {−1, 0, 1}: the products are exact.
            let quad = q[0] * q[0] * xq[0] + q[0] * q[1] * (xq[1] + xq[2]) + q[1] * q[1] * xq[3];
            let phase = -quad - 2.0 * (q[0] * zr_re[0] + q[1] * zr_re[1]);
            inp.phase[p] = if q[0] != 0.0 || q[1] != 0.0 {
                phase
            } else {
                0.0
            };
            let sq = [1.0 - 2.0 * parity(q[0]), 1.0 - 2.0 * parity(q[1])];
            inp.set_sign_lanes(p, sp, sq);
        }
    }
}

/// `base - Σ_k coef_k q_k` for integers `q_k`, with exact products (for
/// `|q_k| < 2^26`) and a compensated sum: error ≈ eps·|result|.
fn residual(base: f64, coef: &[f64], q: &[f64]) -> f64 {
    let (mut s, mut comp) = (base, 0.0);
    for (&c, &n) in coef.iter().zip(q) {
        let (hi, lo) = if n.abs() < 6.7e7 { split(c) } else { (c, 0.0) };
        for t in [-(hi * n), -(lo * n)] {
            let (s2, e) = two_sum(s, t);
            s = s2;
            comp += e;
        }
    }
    s + comp
}

/// `qᵀ X q mod 2` for integers `q`: each `q_i q_k X_ik` is split so that the
/// large part is exact and reduced mod 2 exactly (falls back to plain
/// arithmetic for `|q| ≥ 2^13`, where nothing is accurate anyway).
fn quad_mod2(x: &[f64], q: &[f64], g: usize) -> f64 {
    let mut total = 0.0;
    for i in 0..g {
        for k in 0..g {
            let pq = q[i] * q[k];
            if pq.abs() < 6.7e7 {
                let (hi, lo) = split(x[i * g + k]);
                let t = pq * hi;
                total += rem2(t) + pq * lo;
            } else {
                total += pq * x[i * g + k];
            }
        }
    }
    total
}

/// `x − 2 round(x/2) ∈ [−1, 1]`, exact. The nearest integer comes from the
/// `1.5·2^52` trick (ties to even; either tie is exact here) instead of a libm
/// call, which the baseline x86-64 target needs for `round`; beyond `2^51`
/// the trick no longer gives the nearest integer, and libm is used.
#[inline(always)]
pub fn rem2(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    let h = 0.5 * x;
    let n = if h.abs() < 2_251_799_813_685_248.0 {
        (h + MAGIC) - MAGIC
    } else {
        h.round()
    };
    x - 2.0 * n
}

/// `L` clamped at 0 (it is `≥ 0` up to rounding); an overflowed `L` (Im z and Im τ
/// near the double range) would turn into NaN values downstream, so it is refused.
fn finite_log_scale(log_scale: f64) -> Result<f64> {
    if log_scale.is_finite() {
        Ok(log_scale.max(0.0))
    } else {
        Err(Error::InvalidArgument {
            what: "z",
            reason: "L = pi Im(z)^T (Im tau)^-1 Im(z) overflows the double range: theta is not \
                     representable, not even with log_scale"
                .into(),
        })
    }
}
