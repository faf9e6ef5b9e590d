//! The lattice sums: class sums `S[r] = Σ_{j ≡ r (mod 4)} E(j)` (and the
//! weighted sums `Σ j_k E`, `Σ j_k j_l E` for derivatives) over the ellipsoid
//! `Q(j/2 + w_r) < R²/π`, with the normalised terms
//!
//! ```text
//! E(j) = exp( iπ/4 jᵀτ'j + iπ jᵀz_r + π w_rᵀ Y w_r ),   |E(j)| = exp(-π Q(j/2 + w_r)).
//! ```
//!
//! Terms come from multiplicative recurrences: along the inner coordinate
//! `E(j + e_g) = E(j) A(j)`, `A(j + e_g) = A(j) exp(iπ τ'_gg / 2)`, so a term costs
//! two complex products and no exponential.

use super::{ThetaPlan, Workspace};
use num_complex::Complex64;

type C = Complex64;

impl ThetaPlan {
    /// `iπ/4 jᵀτ'j + iπ jᵀz_r + π w_rᵀYw_r`, real part written as `-π Q(j/2 + w_r)`
    /// so that it is computed without cancellation.
    fn log_term(&self, j: &[i64], zr: &[C], wr: &[f64]) -> C {
        let g = self.g;
        let mut re = 0.0;
        let mut im = 0.0;
        for i in 0..g {
            let ui = 0.5 * j[i] as f64 + wr[i];
            let ji = j[i] as f64;
            for k in 0..g {
                let uk = 0.5 * j[k] as f64 + wr[k];
                re -= self.y[i * g + k] * ui * uk;
                im += 0.25 * self.x[i * g + k] * ji * j[k] as f64;
            }
            im += ji * zr[i].re;
        }
        let pi = std::f64::consts::PI;
        C::new(pi * re, pi * im)
    }

    /// `E(j + e_k)/E(j) = exp(iπ/4 τ'_kk (2 j_k + 1) + iπ/2 Σ_{l≠k} τ'_kl j_l + iπ z_k)`.
    fn ratio(&self, k: usize, j: &[i64], zr: &[C]) -> C {
        let g = self.g;
        let mut s = 0.25 * self.tau[k * g + k] * (2.0 * j[k] as f64 + 1.0) + zr[k];
        for l in 0..g {
            if l != k {
                s += 0.5 * self.tau[k * g + l] * j[l] as f64;
            }
        }
        (C::i() * std::f64::consts::PI * s).exp()
    }

    /// Genus 2: walk a cursor `(j1, k)` along the row centres, carrying `E`,
    /// `A = E(j1,k+1)/E(j1,k)`, `Ainv = E(j1,k-1)/E(j1,k)` and the row-step ratio,
    /// all updated by constant factors `q_kl = exp(iπ τ'_kl/2)`; each row is then
    /// swept up and down from its centre. Starting at the centre of the
    /// ellipsoid keeps the one directly computed term (and its phase) small.
    pub(super) fn sum_g2<const ORDER: usize>(&self, zr: &[C], wr: &[f64], ws: &mut Workspace) {
        let (d1, d2, l21) = (self.ldl_d[0], self.ldl_d[1], self.ldl_l[2]);
        let rq = self.rq;
        let (q11, q12, q22) = (self.qmat[0], self.qmat[1], self.qmat[3]);
        let (q12i, q22i) = (self.qinv[1], self.qinv[3]);
        let h1 = (rq / d1).sqrt();
        let j1min = ceil_i64(2.0 * (-h1 - wr[0]));
        let j1max = floor_i64(2.0 * (h1 - wr[0]));
        let j1c = round_i64(-2.0 * wr[0]).clamp(j1min.min(j1max), j1max.max(j1min));
        // centre and half-width (in j2 units) of row j1
        let row = |j1: i64| -> (f64, f64) {
            let u1 = 0.5 * j1 as f64 + wr[0];
            let rem = rq - d1 * u1 * u1;
            let c = 2.0 * (-l21 * u1 - wr[1]);
            (
                c,
                if rem >= 0.0 {
                    2.0 * (rem / d2).sqrt()
                } else {
                    -1.0
                },
            )
        };
        // (cursor target, lo, hi) of row j1; empty rows have lo > hi.
        let bounds_of = |j1: i64| -> (i64, i64, i64) {
            let (c, hw) = row(j1);
            if hw < 0.0 {
                (0, 1, 0)
            } else {
                (round_i64(c), ceil_i64(c - hw), floor_i64(c + hw))
            }
        };
        // Rows are short (~10 terms): computing all bounds first lets the square
        // roots overlap instead of sitting on each row's critical path.
        const MAX_ROWS: usize = 96;
        let nrows = (j1max - j1min + 1).max(0) as usize;
        let mut table = [(0i64, 1i64, 0i64); MAX_ROWS];
        let precomputed = nrows <= MAX_ROWS;
        if precomputed {
            for (r, slot) in table[..nrows].iter_mut().enumerate() {
                *slot = bounds_of(j1min + r as i64);
            }
        }
        let bounds = |j1: i64| {
            if precomputed {
                table[(j1 - j1min) as usize]
            } else {
                bounds_of(j1)
            }
        };
        let kc = round_i64(row(j1c).0);
        let e0 = self.log_term(&[j1c, kc], zr, wr).exp();
        let a0 = self.ratio(1, &[j1c, kc], zr);
        let ainv0 = q22 / a0;
        let bup = self.ratio(0, &[j1c, kc], zr);
        let bdown = q11 / bup;

        for dir in [1i64, -1] {
            let (q12s, q12si) = if dir == 1 { (q12, q12i) } else { (q12i, q12) };
            let (mut e, mut a, mut ainv, mut bs) =
                (e0, a0, ainv0, if dir == 1 { bup } else { bdown });
            let mut k = kc;
            let mut j1 = j1c;
            if dir == -1 {
                // first row of the downward pass is j1c - 1
                e *= bs;
                bs *= q11;
                a *= q12s;
                ainv *= q12si;
                j1 -= 1;
            }
            while (dir == 1 && j1 <= j1max) || (dir == -1 && j1 >= j1min) {
                let (target, lo, hi) = bounds(j1);
                if lo <= hi {
                    while k < target {
                        e *= a;
                        a *= q22;
                        ainv *= q22i;
                        bs *= q12s;
                        k += 1;
                    }
                    while k > target {
                        e *= ainv;
                        a *= q22i;
                        ainv *= q22;
                        bs *= q12si;
                        k -= 1;
                    }
                    let mut r0 = [C::new(0.0, 0.0); 4];
                    let mut r1 = [C::new(0.0, 0.0); 4];
                    let mut r2 = [C::new(0.0, 0.0); 4];
                    // Upward sweep k..=hi and downward sweep k-1..=lo run interleaved:
                    // two independent product chains hide the multiply latency.
                    if ORDER == 0 {
                        // Unrolled by 4 so that the class of every term is static:
                        // accu[i] collects offsets ≡ i (mod 4) from k, accd[i] from k-1 down.
                        let (nu, nd) = (hi - k + 1, k - lo);
                        let (mut tu, mut au) = (e, a);
                        let (mut td, mut ad) = (e * ainv, ainv * q22);
                        let mut accu = [C::new(0.0, 0.0); 4];
                        let mut accd = [C::new(0.0, 0.0); 4];
                        let both4 = (nu.min(nd).max(0) / 4) * 4;
                        let mut i = 0;
                        while i < both4 {
                            for slot in 0..4 {
                                accu[slot] += tu;
                                accd[slot] += td;
                                tu *= au;
                                au *= q22;
                                td *= ad;
                                ad *= q22;
                            }
                            i += 4;
                        }
                        sweep_tail(&mut accu, tu, au, q22, nu - both4);
                        sweep_tail(&mut accd, td, ad, q22, nd - both4);
                        for slot in 0..4 {
                            r0[((k + slot as i64) & 3) as usize] += accu[slot];
                            r0[((k - 1 - slot as i64) & 3) as usize] += accd[slot];
                        }
                    } else {
                        let (mut tu, mut au, mut ju) = (e, a, k);
                        let (mut td, mut ad, mut jd) = (e * ainv, ainv * q22, k - 1);
                        let both = (hi - k + 1).min(k - lo);
                        for _ in 0..both {
                            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, tu, ju);
                            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, td, jd);
                            tu *= au;
                            au *= q22;
                            td *= ad;
                            ad *= q22;
                            ju += 1;
                            jd -= 1;
                        }
                        while ju <= hi {
                            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, tu, ju);
                            tu *= au;
                            au *= q22;
                            ju += 1;
                        }
                        while jd >= lo {
                            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, td, jd);
                            td *= ad;
                            ad *= q22;
                            jd -= 1;
                        }
                    }
                    let base = ((j1 & 3) as usize) * 4;
                    let j1f = j1 as f64;
                    for cls in 0..4 {
                        let r = base + cls;
                        ws.s0[r] += r0[cls];
                        if ORDER >= 1 {
                            ws.s1[2 * r] += r0[cls] * j1f;
                            ws.s1[2 * r + 1] += r1[cls];
                            if ORDER >= 2 {
                                ws.s2[4 * r] += r0[cls] * (j1f * j1f);
                                let mixed = r1[cls] * j1f;
                                ws.s2[4 * r + 1] += mixed;
                                ws.s2[4 * r + 2] += mixed;
                                ws.s2[4 * r + 3] += r2[cls];
                            }
                        }
                    }
                }
                // step to the next row
                e *= bs;
                bs *= q11;
                a *= q12s;
                ainv *= q12si;
                j1 += dir;
            }
        }
    }

    /// Any genus: enumerate the outer coordinates `j_1..j_{g-1}` over the
    /// ellipsoid (Fincke–Pohst style, from the factorisation of `Q`); each inner
    /// row starts from a directly computed term at its lower end and is swept
    /// upward with the recurrence (no division, so no overflow for large `Im τ`).
    pub(super) fn sum_generic<const ORDER: usize>(&self, zr: &[C], wr: &[f64], ws: &mut Workspace) {
        let mut j = vec![0i64; self.g];
        self.level::<ORDER>(0, 0.0, &mut j, zr, wr, ws);
    }

    fn level<const ORDER: usize>(
        &self,
        i: usize,
        partial: f64,
        j: &mut [i64],
        zr: &[C],
        wr: &[f64],
        ws: &mut Workspace,
    ) {
        let g = self.g;
        let rem = self.rq - partial;
        if rem < 0.0 {
            return;
        }
        let t: f64 = (0..i)
            .map(|k| self.ldl_l[i * g + k] * (0.5 * j[k] as f64 + wr[k]))
            .sum();
        let h = (rem / self.ldl_d[i]).sqrt();
        let lo = ceil_i64(2.0 * (-t - h - wr[i]));
        let hi = floor_i64(2.0 * (-t + h - wr[i]));
        if i + 1 < g {
            for v in lo..=hi {
                j[i] = v;
                let dv = 0.5 * v as f64 + wr[i] + t;
                self.level::<ORDER>(i + 1, partial + self.ldl_d[i] * dv * dv, j, zr, wr, ws);
            }
            return;
        }
        if lo > hi {
            return;
        }
        j[i] = lo;
        let mut e = self.log_term(j, zr, wr).exp();
        let mut a = self.ratio(i, j, zr);
        let q = self.qmat[i * g + i];
        let mut r0 = [C::new(0.0, 0.0); 4];
        let mut r1 = [C::new(0.0, 0.0); 4];
        let mut r2 = [C::new(0.0, 0.0); 4];
        for v in lo..=hi {
            let cls = (v & 3) as usize;
            r0[cls] += e;
            if ORDER >= 1 {
                let vf = v as f64;
                r1[cls] += e * vf;
                if ORDER >= 2 {
                    r2[cls] += e * (vf * vf);
                }
            }
            e *= a;
            a *= q;
        }
        let mut base = 0usize;
        for &jk in &j[..g - 1] {
            base = 4 * (base + (jk & 3) as usize);
        }
        for cls in 0..4 {
            let r = base + cls;
            ws.s0[r] += r0[cls];
            if ORDER >= 1 {
                for k in 0..g - 1 {
                    ws.s1[r * g + k] += r0[cls] * j[k] as f64;
                }
                ws.s1[r * g + g - 1] += r1[cls];
                if ORDER >= 2 {
                    for k in 0..g - 1 {
                        for l in 0..g - 1 {
                            ws.s2[(r * g + k) * g + l] += r0[cls] * (j[k] as f64 * j[l] as f64);
                        }
                        let mixed = r1[cls] * j[k] as f64;
                        ws.s2[(r * g + k) * g + g - 1] += mixed;
                        ws.s2[(r * g + g - 1) * g + k] += mixed;
                    }
                    ws.s2[(r * g + g - 1) * g + g - 1] += r2[cls];
                }
            }
        }
    }
}

/// The rest of a sweep of `n` terms (any `n`; nothing for `n ≤ 0`) starting at
/// slot 0: `acc[i mod 4] += t_i`, `t_{i+1} = t_i a_i`, `a_{i+1} = a_i q`.
#[inline(always)]
fn sweep_tail(acc: &mut [C; 4], mut t: C, mut a: C, q: C, n: i64) {
    let mut i = 0;
    while i < n {
        acc[(i & 3) as usize] += t;
        t *= a;
        a *= q;
        i += 1;
    }
}

#[inline(always)]
fn accumulate<const ORDER: usize>(r0: &mut [C; 4], r1: &mut [C; 4], r2: &mut [C; 4], t: C, j: i64) {
    let cls = (j & 3) as usize;
    r0[cls] += t;
    if ORDER >= 1 {
        let jf = j as f64;
        r1[cls] += t * jf;
        if ORDER >= 2 {
            r2[cls] += t * (jf * jf);
        }
    }
}

/// `floor` without a libm call (the baseline x86-64 target has no `roundsd`);
/// exact for |x| < 2^62, which the caller guarantees (|x| is a few hundred).
#[inline(always)]
pub(super) fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    // branch-free: the comparison is data dependent (signs of reduced coordinates)
    t - i64::from((t as f64) > x)
}

/// `ceil` without a libm call, see [`floor_i64`].
#[inline(always)]
pub(super) fn ceil_i64(x: f64) -> i64 {
    -floor_i64(-x)
}

/// Nearest integer (ties up) without a libm call, see [`floor_i64`].
#[inline(always)]
pub(super) fn round_i64(x: f64) -> i64 {
    floor_i64(x + 0.5)
}
