//! Normalized input: the invariances of Frahm's equations (1) used, not
//! suffered (docs/degenerate.md §1).
//!
//! * **Scale of `l`.** (1) is homogeneous of degree 2: if `l(t)` solves it,
//!   so does `s l(s t)`. Hence `l(t; s l0) = s l(s t; l0)` for every `s ≠ 0`.
//! * **Affine change of `a`.** `c_ij = (b_i − b_j)/(a_i − a_j)` (2) is unchanged
//!   by `a → (a − κ)/σ` together with `b → (b − β)/σ`; the Kötter reduction
//!   depends on `a` only through the level set of the same flow, so the
//!   normalized top has the same motion.
//! * **Shift and scale of `c`.** Adding `μ` to every `c_ij` adds `μ l_ij` to
//!   `ω_ij`, and `[l, μ l] = 0`: the flow is unchanged (`H` gains `μ H1/2`, a
//!   Casimir). Scaling `c` by `1/λ` scales time: `l_c(t) = l_{c'}(λ t)` for
//!   `c' = (c − μ)/λ` (in `b`: `b → b − μ a − β`, then `/λ`).
//!
//! Together: `l(t; a, c, l0) = s · l(T t; a', c', l0/s)` with the time scale
//! `T = s λ`. Every scale here is a **power of two** and every shift is taken
//! only where it is exact (Sterbenz's lemma: `x − y` is exact for `y/2 ≤ x ≤ 2y`),
//! so the normalized data are the user's data exactly, moved, and the time
//! scale is exact. Where the data are already moderate the normalization is
//! the identity (so the generic genus-2 path sees the user's numbers, bit for
//! bit): `l0` is scaled only if `max |l0_q|` lies outside `[2^-16, 2^16]`, `a`
//! only if the geometric mean of its largest and smallest nonzero modulus
//! (after the shift) does, `c` only if its half-spread does; `a` is
//! shifted only when its values cluster (`spread ≤ max |a_i| / 16`, e.g. `a`
//! shifted by 1e6), `c` only when the `c_ij` cluster (e.g. `b ≈ α a + β`).

use crate::error::{Error, Result};
use crate::numeric::compensated::two_sum;
use crate::so4;

/// Scales are left at 1 when the quantity lies in `[2^-WINDOW, 2^WINDOW]`:
/// the genus-2 path is exercised and accurate there (without normalization
/// it refused from `|l0| ~ 1e-80` and `1e76` on), and the identity keeps its
/// bits.
pub const WINDOW: i32 = 16;

/// Values count as clustered, and are shifted, when their spread is at most
/// this fraction of their largest modulus: then more than four bits of every
/// value are common to all, and the vector field (1) or the reduction's sums
/// would carry that common part as rounding.
pub const CLUSTER_FRACTION: f64 = 1.0 / 16.0;

/// A top counts as **spherical** (all `c_ij` equal: no flow) when every two
/// `c_ij`, `c_kl` differ by at most this many times the sum of their rounding
/// bounds `β_ij = u [(|b_i| + |b_j|) + |c_ij| (|a_i| + |a_j|)] / |a_i − a_j|`
/// (`u = 2^-53`). Why 8: for `b_i = fl(α a_i + β)` each `b_i` carries at most
/// two roundings (`u (|α a_i| + |b_i|)` each, `|α| ≈ |c_ij|`), so
/// `|δc_ij| ≤ 2 β_ij + 3u |c_ij|` including the rounding of the quotient and
/// of `a_i − a_j`, and `|c_ij − c_kl| ≤ 2(β_ij + β_kl) + 6u|c| ≤ 8(β_ij + β_kl)`
/// since `β_ij ≥ u |c_ij|`. A top whose `c_ij` differ by more is not
/// spherical: it is normalized to `c'` of unit spread and solved as such.
pub const SPHERICAL_ULPS: f64 = 8.0;

/// The normalized top: `a' = (a − κ)/σ`, `c' = (c − μ)/λ` (state order),
/// exact; and whether the top is spherical.
#[derive(Debug, Clone, PartialEq)]
pub struct TopFrame {
    /// `a' = (a − κ)/σ`.
    pub a: [f64; 4],
    /// `c' = (c − μ)/λ`, state order `(12, 13, 14, 23, 24, 34)`.
    pub c4: [f64; 6],
    /// The rounding errors of `c'`: `c' + c4_lo` is `(c_exact − μ)/λ` to
    /// first order, `c_exact = (b_i − b_j)/(a_i − a_j)` exact in the double
    /// `a, b` ([`c_rounding`]). Zero for the spherical top.
    pub c4_lo: [f64; 6],
    /// The user's `c` (2), state order.
    pub c4_user: [f64; 6],
    pub kappa: f64,
    pub sigma: f64,
    pub mu: f64,
    pub lambda: f64,
    /// All `c_ij` equal to their rounding ([`SPHERICAL_ULPS`]): `l` is constant.
    pub spherical: bool,
}

/// The power of two `2^e` nearest to `h > 0` in the sense of `e = round(log2 h)`,
/// or 1 when `h` lies in the window `[2^-WINDOW, 2^WINDOW]`.
fn pow2_scale(h: f64) -> f64 {
    if !(h > 0.0 && h.is_finite()) {
        return 1.0;
    }
    // Clamped so that 2^e stays a normal, finite double.
    let e = h.log2().round().clamp(-1022.0, 1023.0);
    if e.abs() <= f64::from(WINDOW) {
        1.0
    } else {
        // 2^e is exact; e within ±1100 for finite h.
        e.exp2()
    }
}

/// The scale of the shifted `a` that [`TopFrame`] brings to 1: the geometric
/// mean `√(max |a_i| · min |a_i|)` of the largest and the smallest nonzero
/// `|a_i|`. The roots of `F` (19) lie near the `a_i`, and the reduction keeps
/// its digits while they are moderate at both ends: centring their logarithmic
/// range on 1 leaves a uniformly scaled `a` (`a × 1e±12`) at `O(1)`, and leaves a
/// top with one far `a_i` as it is. Bringing the largest to 1 instead squeezed
/// the others (the Manakov top `a = (−0.42, −0.06, 0.48, 1e8)` of the Clebsch
/// contraction was refused: after `a / 2^26` two roots of `F` near the small
/// `a_i` met at 7e-10).
fn a_scale(a: &[f64; 4]) -> f64 {
    let hi = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let lo = a
        .iter()
        .filter(|v| **v != 0.0)
        .fold(f64::INFINITY, |m, v| m.min(v.abs()));
    // Both factors are within the double range, and so is their geometric mean
    // taken as a product of square roots (no overflow of hi · lo).
    hi.sqrt() * lo.sqrt()
}

/// `c_exact − c` for each pair of the state order, `c = fl((b_i − b_j)/(a_i − a_j))`
/// the double of (2) and `c_exact` the exact quotient of the doubles `a, b`.
///
/// The frequencies of the motion are linear in `c`, so rounding `c` shifts them
/// by ~ε relative and the Theorem's phase by ~ε |U| t: on stiff tops (|U| ~ 100)
/// that is ~1e-12 |l0| at t = 100, more than the integrators' error. The closed
/// form of `U` takes `c + c_lo` in double-double instead. With `n = b_i − b_j`,
/// `d = a_i − a_j` as exact sums `n_h + n_l`, `d_h + d_l`: `n_h − c d_h` is exact
/// (one fused multiply-add: the remainder of a correctly rounded quotient is a
/// double), and `c_lo = (n_h − c d_h + n_l − c d_l)/d_h` to first order.
pub fn c_rounding(a: &[f64; 4], b: &[f64; 4], c4: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|q| {
        let (i, j) = so4::PAIRS4[q];
        let (nh, nl) = two_sum(b[i], -b[j]);
        let (dh, dl) = two_sum(a[i], -a[j]);
        let c = c4[q];
        let r = (-c).mul_add(dh, nh) + (nl - c * dl);
        let lo = r / dh;
        if lo.is_finite() {
            lo
        } else {
            0.0
        }
    })
}

/// A shift `κ` for which every `x_i − κ` is exact, when the values cluster
/// ([`CLUSTER_FRACTION`]), else 0.
fn exact_shift(x: &[f64]) -> f64 {
    let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let big = lo.abs().max(hi.abs());
    let spread = hi - lo;
    if spread.is_nan() || spread > CLUSTER_FRACTION * big || big == 0.0 {
        return 0.0;
    }
    let mid = 0.5 * lo + 0.5 * hi;
    // Sterbenz: x − mid is exact when mid/2 ≤ x ≤ 2 mid (same sign).
    let ok = x
        .iter()
        .all(|&v| (v >= 0.5 * mid && v <= 2.0 * mid) || (v <= 0.5 * mid && v >= 2.0 * mid));
    if ok {
        mid
    } else {
        0.0
    }
}

impl TopFrame {
    /// The frame of the top `(a, b)`.
    ///
    /// Errors: those of (2) ([`so4::manakov_c`]: non-finite, repeated `a_i`,
    /// overflow).
    pub fn new(a: &[f64; 4], b: &[f64; 4]) -> Result<Self> {
        let c = so4::manakov_c(a, b)?;
        let c4u = [c[1], c[2], c[3], c[6], c[7], c[11]];
        let kappa = exact_shift(a);
        let a_shift = a.map(|v| v - kappa);
        let sigma = pow2_scale(a_scale(&a_shift));
        let a_n = a_shift.map(|v| v / sigma);

        // Spherical: all c_ij equal to their rounding.
        let mut beta = [0.0; 6];
        for (q, &(i, j)) in so4::PAIRS4.iter().enumerate() {
            beta[q] = f64::EPSILON
                * 0.5
                * ((b[i].abs() + b[j].abs()) + c4u[q].abs() * (a[i].abs() + a[j].abs()))
                / (a[i] - a[j]).abs();
        }
        let spherical = (0..6).all(|p| {
            (0..6).all(|q| (c4u[p] - c4u[q]).abs() <= SPHERICAL_ULPS * (beta[p] + beta[q]))
        });
        let (mu, lambda, c_n, c_n_lo) = if spherical {
            (0.0, 1.0, c4u, [0.0; 6])
        } else {
            let mu = exact_shift(&c4u);
            let shifted = c4u.map(|v| v - mu);
            let lambda = pow2_scale(shifted.iter().fold(0.0f64, |m, v| m.max(v.abs())));
            // both maps exact (μ: Sterbenz, λ: a power of two), so the rounding
            // errors map with the scale alone
            let lo = c_rounding(a, b, &c4u).map(|v| v / lambda);
            (mu, lambda, shifted.map(|v| v / lambda), lo)
        };
        for (what, v) in [("a", &a_n[..]), ("c", &c_n[..])] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(Error::InvalidArgument {
                    what: "top",
                    reason: format!("the normalized {what} is not finite"),
                });
            }
        }
        Ok(TopFrame {
            a: a_n,
            c4: c_n,
            c4_lo: c_n_lo,
            c4_user: c4u,
            kappa,
            sigma,
            mu,
            lambda,
            spherical,
        })
    }

    /// Whether the frame leaves `a` and `c` as given (no shift, no scale).
    pub fn is_identity(&self) -> bool {
        self.kappa == 0.0 && self.sigma == 1.0 && self.mu == 0.0 && self.lambda == 1.0
    }

    /// `b'` of the second commuting flow on the normalized top (see
    /// [`crate::tori::second_flow_b`], the same rule): with
    /// `c'_ij = p1 + p2 (a_i + a_j) + p3 (a_i² + a_i a_j + a_j²)`, `a'³` if
    /// `|p2| > |p3| max|a'|`, else `a'²`; `p2, p3` from divided differences of
    /// `c'` (second differences of `b'`).
    pub fn second_flow_b(&self) -> [f64; 4] {
        if self.second_flow_power() == 3 {
            self.a.map(|x| x * x * x)
        } else {
            self.a.map(|x| x * x)
        }
    }

    /// The power `k` of `b' = a'^k` in [`Self::second_flow_b`]: 3 or 2.
    pub fn second_flow_power(&self) -> i32 {
        let a = &self.a;
        let c = &self.c4;
        // b[1,2,3] = (c23 − c12)/(a3 − a1), b[2,3,4] = (c34 − c23)/(a4 − a2).
        let b123 = (c[3] - c[0]) / (a[2] - a[0]);
        let b234 = (c[5] - c[3]) / (a[3] - a[1]);
        let p3 = (b234 - b123) / (a[3] - a[0]);
        let p2 = b123 - p3 * (a[0] + a[1] + a[2]);
        let s = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if p2.abs() > p3.abs() * s {
            3
        } else {
            2
        }
    }
}

/// The power of two `s` by which `l0` is divided (1 when `max |l0_q|` lies in
/// `[2^-WINDOW, 2^WINDOW]`); `l0/s` is exact (barring subnormal components,
/// whose relative size is below `2^-1000` of the largest and does not enter
/// the motion at double precision).
pub fn state_scale(l0: &[f64; 6]) -> f64 {
    pow2_scale(l0.iter().fold(0.0f64, |m, v| m.max(v.abs())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c_rounding_is_the_remainder_of_the_quotient() {
        // c_12 = (1 - 0)/(0 - 3) = -1/3, c_14 = (1 - 0.3)/(0 - 7), ...: the exact
        // quotients of the doubles, from the DD division, minus their doubles.
        let a = [0.0, 3.0, 2.0, 7.0];
        let b = [1.0, 0.0, 0.1, 0.3];
        let c = so4::manakov_c(&a, &b).unwrap();
        let c4 = [c[1], c[2], c[3], c[6], c[7], c[11]];
        let lo = c_rounding(&a, &b, &c4);
        for (q, &(i, j)) in so4::PAIRS4.iter().enumerate() {
            let n = crate::numeric::dd::Dd::sum(b[i], -b[j]);
            let d = crate::numeric::dd::Dd::sum(a[i], -a[j]);
            let exact = n.div(d);
            // c4 is the quotient of the rounded differences: it may be an ulp
            // off the rounded exact quotient (pair 2: 0.7/-7), and lo covers that.
            let miss = (exact.hi - c4[q]) + (exact.lo - lo[q]);
            assert!(miss.abs() <= 1e-30 * c4[q].abs(), "pair {q}: {miss:e}");
        }
        assert!(lo[0] != 0.0, "1/3 is not a double");
        // the normalized frame carries them, scaled like c
        let f = TopFrame::new(&a, &b).unwrap();
        assert_eq!(f.c4_lo, lo.map(|v| v / f.lambda));
    }

    #[test]
    fn moderate_data_are_left_alone() {
        for (a, b, _) in crate::solution::tests::TOPS {
            let f = TopFrame::new(&a, &b).unwrap();
            assert!(f.is_identity(), "{a:?}");
            assert!(!f.spherical);
            assert_eq!(f.a, a);
        }
    }

    #[test]
    fn shifts_are_exact_and_keep_c() {
        let (a, b, _) = crate::solution::tests::TOPS[3];
        let a6 = a.map(|v| v + 1e6);
        let f = TopFrame::new(&a6, &b).unwrap();
        assert!(f.kappa != 0.0);
        for i in 0..4 {
            for j in 0..4 {
                // Differences of a' are those of the given doubles, exactly.
                assert_eq!((f.a[i] - f.a[j]) * f.sigma, a6[i] - a6[j]);
            }
        }
        assert_eq!(f.c4, f.c4_user.map(|v| (v - f.mu) / f.lambda));
    }

    #[test]
    fn b_affine_in_a_is_spherical() {
        let mut seed = 99u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for k in 0..2000 {
            let shift = [0.0, 1e3, 1e6, -1e9][k % 4];
            let scale = [1.0, 1e-3, 1e4][k % 3];
            let a = [rnd(), rnd(), rnd(), rnd()].map(|v| shift + scale * v);
            let (alpha, beta) = (rnd() * 10f64.powi((k % 7) as i32 - 3), rnd() * 1e3);
            let b = a.map(|v| alpha * v + beta);
            let f = TopFrame::new(&a, &b).unwrap();
            assert!(f.spherical, "a = {a:?}, b = {b:?}");
            // A relative perturbation of 1e-9 of the spread of b is not rounding.
            let spread = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut b2 = b;
            b2[k % 4] += 1e-9 * spread.max(1e-300) + 1e-9 * (alpha * scale).abs();
            let f2 = TopFrame::new(&a, &b2).unwrap();
            assert!(!f2.spherical, "a = {a:?}, b = {b2:?}");
            // Its normalized c has a half-spread in [1/2, 2) (power-of-two λ) or is moderate.
            let h = f2.c4.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(h > 0.0 && h.is_finite());
        }
    }

    #[test]
    fn a_is_scaled_by_the_geometric_mean_of_its_ends() {
        // One far a_i (the Manakov top of the Clebsch contraction, a4 = 1e8): the
        // geometric mean 7.7e2 lies in the window, the top is left as it is.
        let b = [-3.216, -2.424, -2.046, 0.0];
        let f = TopFrame::new(&[-0.42, -0.06, 0.48, 1e8], &b).unwrap();
        assert_eq!(f.sigma, 1.0);
        // A uniformly scaled a: its normalized geometric mean is within a factor
        // √2 of 1, and the differences are the given ones scaled exactly.
        for (a, b, _) in crate::solution::tests::TOPS {
            for scale in [1e-12, 1e12] {
                let (a_s, b_s) = (a.map(|v| v * scale), b.map(|v| v * scale));
                let f = TopFrame::new(&a_s, &b_s).unwrap();
                let g = a_scale(&f.a);
                assert!((0.7..=1.42).contains(&g), "{a_s:?}: {g}");
                assert_eq!(f.a.map(|v| v * f.sigma), a_s.map(|v| v - f.kappa));
            }
        }
    }

    #[test]
    fn state_scale_is_a_power_of_two_outside_the_window() {
        assert_eq!(state_scale(&[1.0, 0.0, 0.0, 0.0, 0.0, 3.0]), 1.0);
        let s = state_scale(&[1e-150, 0.0, 0.0, 0.0, 0.0, 3e-150]);
        assert_eq!(s, 2f64.powi((3e-150f64.log2()).round() as i32));
        assert!(state_scale(&[1e150; 6]) > 1e149);
    }
}
