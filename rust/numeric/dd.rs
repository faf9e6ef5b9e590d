//! Double-double ("DD") arithmetic (the reduction's level-set constants).
//!
//! A DD number is an unevaluated sum `hi + lo` with `|lo| ≤ ulp(hi)/2`,
//! carrying about 106 bits. The error-free transformations are those of
//! [`super::compensated`] (Knuth's `two_sum`, Dekker's `fast_two_sum` and
//! Dekker's product, without FMA); the operations are the "accurate" sum and
//! the product of Joldes, Muller and Popescu, *Tight and rigorous error bounds
//! for basic building blocks of double-word arithmetic*, ACM TOMS 44 (2017),
//! Algorithms 6 and 12 (relative errors ≤ 3u² and ≤ 5u²), and divisions by one
//! correction step of the double quotient.
//!
//! Why: the reduction's round trip needs the roots `s_p`, `σ_p` and `F'(s_p)`
//! consistent with each other to better than double precision when a branch
//! point `d_j` is large (`docs/kotter.md`, "Accuracy"); they are computed in DD
//! once per level set and rounded to double at the end. The Euler tops of the
//! degenerate states (`crate::solution::euler`) evaluate `Δ = Σ (W_i − W_b) M_i²`
//! in DD: its sign and size decide the separatrix and `1 − m`.

use num_complex::Complex64;

#[cfg(any(test, target_arch = "x86_64"))]
use super::compensated::Fused;
use super::compensated::{fast_two_sum, two_sum, ExactProd, Veltkamp};
use super::complex::{cdiv, sqrt_principal};

/// A real double-double number `hi + lo`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dd {
    pub hi: f64,
    pub lo: f64,
}

impl Dd {
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    pub fn new(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    /// `a + b` of two doubles, exactly.
    pub fn sum(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_sum(a, b);
        Dd { hi, lo }
    }

    /// `a b` of two doubles, exactly.
    pub fn prod(a: f64, b: f64) -> Dd {
        Dd::prod_m::<Veltkamp>(a, b)
    }

    #[inline(always)]
    fn prod_m<M: ExactProd>(a: f64, b: f64) -> Dd {
        let (hi, lo) = M::two_prod(a, b);
        Dd { hi, lo }
    }

    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    pub fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    pub fn add(self, b: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = fast_two_sum(s, e + t);
        let (hi, lo) = fast_two_sum(s, e + f);
        Dd { hi, lo }
    }

    pub fn sub(self, b: Dd) -> Dd {
        self.add(b.neg())
    }

    pub fn mul(self, b: Dd) -> Dd {
        self.mul_m::<Veltkamp>(b)
    }

    #[inline(always)]
    fn mul_m<M: ExactProd>(self, b: Dd) -> Dd {
        let (p, e) = M::two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = fast_two_sum(p, e);
        Dd { hi, lo }
    }

    pub fn mul_f64(self, b: f64) -> Dd {
        self.mul_f64_m::<Veltkamp>(b)
    }

    #[inline(always)]
    fn mul_f64_m<M: ExactProd>(self, b: f64) -> Dd {
        let (p, e) = M::two_prod(self.hi, b);
        let (hi, lo) = fast_two_sum(p, e + self.lo * b);
        Dd { hi, lo }
    }

    /// `self / b`: the double quotient, corrected once by the DD residual.
    pub fn div(self, b: Dd) -> Dd {
        let q1 = self.hi / b.hi;
        let r = self.sub(b.mul_f64(q1));
        let q2 = r.hi / b.hi;
        let r = r.sub(b.mul_f64(q2));
        let q3 = r.hi / b.hi;
        let (hi, lo) = fast_two_sum(q1, q2);
        Dd { hi, lo }.add(Dd::new(q3))
    }
}

/// A complex double-double number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Cdd {
    pub re: Dd,
    pub im: Dd,
}

impl Cdd {
    pub const ZERO: Cdd = Cdd {
        re: Dd::ZERO,
        im: Dd::ZERO,
    };

    pub fn new(z: Complex64) -> Cdd {
        Cdd {
            re: Dd::new(z.re),
            im: Dd::new(z.im),
        }
    }

    /// `hi + lo` from a double and its low part (as stored by the constants).
    pub fn from_parts(hi: Complex64, lo: Complex64) -> Cdd {
        Cdd {
            re: Dd::sum(hi.re, lo.re),
            im: Dd::sum(hi.im, lo.im),
        }
    }

    pub fn conj(self) -> Cdd {
        Cdd {
            re: self.re,
            im: self.im.neg(),
        }
    }

    /// `i · self`, exactly.
    pub fn mul_i(self) -> Cdd {
        Cdd {
            re: self.im.neg(),
            im: self.re,
        }
    }

    pub fn real(x: Dd) -> Cdd {
        Cdd {
            re: x,
            im: Dd::ZERO,
        }
    }

    /// The double nearest (to within an ulp) to the DD value.
    pub fn to_c(self) -> Complex64 {
        Complex64::new(self.re.to_f64(), self.im.to_f64())
    }

    pub fn neg(self) -> Cdd {
        Cdd {
            re: self.re.neg(),
            im: self.im.neg(),
        }
    }

    pub fn add(self, b: Cdd) -> Cdd {
        Cdd {
            re: self.re.add(b.re),
            im: self.im.add(b.im),
        }
    }

    pub fn sub(self, b: Cdd) -> Cdd {
        Cdd {
            re: self.re.sub(b.re),
            im: self.im.sub(b.im),
        }
    }

    /// `self + x` for a real double `x`.
    pub fn add_f64(self, x: f64) -> Cdd {
        Cdd {
            re: self.re.add(Dd::new(x)),
            im: self.im,
        }
    }

    pub fn mul(self, b: Cdd) -> Cdd {
        #[cfg(target_arch = "x86_64")]
        if has_fma() {
            // SAFETY: the CPU supports FMA (checked just above).
            return unsafe { fused::mul(self, b) };
        }
        self.mul_m::<Veltkamp>(b)
    }

    #[inline(always)]
    fn mul_m<M: ExactProd>(self, b: Cdd) -> Cdd {
        Cdd {
            re: self.re.mul_m::<M>(b.re).sub(self.im.mul_m::<M>(b.im)),
            im: self.re.mul_m::<M>(b.im).add(self.im.mul_m::<M>(b.re)),
        }
    }

    pub fn mul_dd(self, x: Dd) -> Cdd {
        Cdd {
            re: self.re.mul(x),
            im: self.im.mul(x),
        }
    }

    pub fn mul_f64(self, x: f64) -> Cdd {
        Cdd {
            re: self.re.mul_f64(x),
            im: self.im.mul_f64(x),
        }
    }

    pub fn div_dd(self, x: Dd) -> Cdd {
        Cdd {
            re: self.re.div(x),
            im: self.im.div(x),
        }
    }

    /// `self · z` for a double `z`.
    pub fn mul_c(self, z: Complex64) -> Cdd {
        self.mul_c_m::<Veltkamp>(z)
    }

    #[inline(always)]
    fn mul_c_m<M: ExactProd>(self, z: Complex64) -> Cdd {
        Cdd {
            re: self
                .re
                .mul_f64_m::<M>(z.re)
                .sub(self.im.mul_f64_m::<M>(z.im)),
            im: self
                .re
                .mul_f64_m::<M>(z.im)
                .add(self.im.mul_f64_m::<M>(z.re)),
        }
    }

    /// `self / b`: the double quotient `q0` corrected by the DD residual,
    /// `q0 + (self − b q0)/b` (the correction, ~u of `q0`, needs only double
    /// precision).
    pub fn div(self, b: Cdd) -> Cdd {
        #[cfg(target_arch = "x86_64")]
        if has_fma() {
            // SAFETY: the CPU supports FMA (checked just above).
            return unsafe { fused::div(self, b) };
        }
        self.div_m::<Veltkamp>(b)
    }

    #[inline(always)]
    fn div_m<M: ExactProd>(self, b: Cdd) -> Cdd {
        // Smith's quotient: no |b|², which under- or overflows long before the
        // quotient does (the reduction meets g² ~ 1e-53 and d_4 ~ 1e19)
        let bc = b.to_c();
        let q0 = cdiv(self.to_c(), bc);
        let corr = cdiv(self.sub(b.mul_c_m::<M>(q0)).to_c(), bc);
        Cdd {
            re: Dd::sum(q0.re, corr.re),
            im: Dd::sum(q0.im, corr.im),
        }
    }

    /// `1 / self`.
    pub fn recip(self) -> Cdd {
        Cdd::new(Complex64::new(1.0, 0.0)).div(self)
    }

    /// The principal square root (the branch of
    /// [`sqrt_principal`] applied to the leading double, which
    /// decides the side of the cut): one Newton step
    /// `r = r0 + (z − r0²)/(2 r0)` from the double root `r0`, with `r0²`
    /// formed exactly, doubles the number of correct digits.
    pub fn sqrt(self) -> Cdd {
        #[cfg(target_arch = "x86_64")]
        if has_fma() {
            // SAFETY: the CPU supports FMA (checked just above).
            return unsafe { fused::sqrt(self) };
        }
        self.sqrt_m::<Veltkamp>()
    }

    #[inline(always)]
    fn sqrt_m<M: ExactProd>(self) -> Cdd {
        let r0 = sqrt_principal(self.to_c());
        if r0 == Complex64::new(0.0, 0.0) {
            return Cdd::ZERO;
        }
        let sq = Cdd {
            re: Dd::prod_m::<M>(r0.re, r0.re).sub(Dd::prod_m::<M>(r0.im, r0.im)),
            im: Dd::prod_m::<M>(r0.re, r0.im).mul_f64(2.0),
        };
        let corr = cdiv(self.sub(sq).to_c(), 2.0 * r0);
        Cdd {
            re: Dd::sum(r0.re, corr.re),
            im: Dd::sum(r0.im, corr.im),
        }
    }
}

/// Whether the CPU has FMA (cached by the standard library after the first
/// query): the complex DD operations then take their exact products in one
/// instruction each instead of Dekker's seventeen, with the same bits.
#[cfg(target_arch = "x86_64")]
#[inline]
fn has_fma() -> bool {
    std::is_x86_feature_detected!("fma")
}

/// The complex DD operations compiled with FMA (the exact products by
/// [`Fused`]).
#[cfg(target_arch = "x86_64")]
mod fused {
    use super::{Cdd, Fused};

    #[target_feature(enable = "fma")]
    pub(super) unsafe fn mul(a: Cdd, b: Cdd) -> Cdd {
        a.mul_m::<Fused>(b)
    }

    #[target_feature(enable = "fma")]
    pub(super) unsafe fn div(a: Cdd, b: Cdd) -> Cdd {
        a.div_m::<Fused>(b)
    }

    #[target_feature(enable = "fma")]
    pub(super) unsafe fn sqrt(a: Cdd) -> Cdd {
        a.sqrt_m::<Fused>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FMA copies of the complex operations give the bits of Dekker's
    /// products (both exact), on values spread over many binades.
    #[test]
    fn fused_and_dekker_products_agree_to_the_bit() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let m = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            m * 2f64.powi(((seed >> 3) % 60) as i32 - 30)
        };
        for _ in 0..2000 {
            let mut z = || Cdd {
                re: Dd::sum(next(), 1e-17 * next()),
                im: Dd::sum(next(), 1e-17 * next()),
            };
            let (a, b) = (z(), z());
            assert_eq!(a.mul_m::<Fused>(b), a.mul_m::<Veltkamp>(b));
            assert_eq!(a.div_m::<Fused>(b), a.div_m::<Veltkamp>(b));
            assert_eq!(a.sqrt_m::<Fused>(), a.sqrt_m::<Veltkamp>());
            #[cfg(target_arch = "x86_64")]
            if has_fma() {
                assert_eq!(a.mul(b), a.mul_m::<Veltkamp>(b));
            }
        }
    }

    /// Exact references: products and quotients of small integers scaled by
    /// powers of two, and identities whose DD residual must be ~u² of the terms.
    #[test]
    fn dd_operations_are_double_double_accurate() {
        let u2 = f64::EPSILON * f64::EPSILON;
        let third = Dd::new(1.0).div(Dd::new(3.0));
        // 3 * (1/3) - 1 to ~u²
        let r = third.mul_f64(3.0).sub(Dd::new(1.0));
        assert!(r.to_f64().abs() < 4.0 * u2, "{r:?}");
        // (1 + 2^-60)² = 1 + 2^-59 + 2^-120: the 2^-59 survives, which a double loses
        let x = Dd::sum(1.0, 2f64.powi(-60));
        let x2 = x.mul(x).sub(Dd::new(1.0));
        assert_eq!(x2.hi, 2f64.powi(-59));
        // complex: (1 + i 2^-40)(1 - i 2^-40) = 1 + 2^-80
        let z = Cdd {
            re: Dd::new(1.0),
            im: Dd::new(2f64.powi(-40)),
        };
        let zc = Cdd {
            re: Dd::new(1.0),
            im: Dd::new(-(2f64.powi(-40))),
        };
        let p = z.mul(zc);
        assert_eq!(p.re.sub(Dd::new(1.0)).hi, 2f64.powi(-80));
        assert_eq!(p.im.to_f64(), 0.0);
        // sqrt: (sqrt z)² − z ~ u² |z|, principal branch
        for w in [
            Complex64::new(2.0, 0.0),
            Complex64::new(-3.0, 1e-3),
            Complex64::new(-3.0, -1e-3),
            Complex64::new(1e-5, 7.0),
        ] {
            let zz = Cdd::new(w);
            let r = zz.sqrt();
            let back = r.mul(r).sub(zz).to_c();
            assert!(back.norm() < 8.0 * u2 * w.norm(), "{w} {back}");
            assert!(r.re.hi >= 0.0);
        }
        // division: (7 + 5i)/(3 - 2i) = (11 + 29i)/13
        let q = Cdd::new(Complex64::new(7.0, 5.0)).div(Cdd::new(Complex64::new(3.0, -2.0)));
        let e = q
            .mul(Cdd::new(Complex64::new(13.0, 0.0)))
            .sub(Cdd::new(Complex64::new(11.0, 29.0)))
            .to_c();
        assert!(e.norm() < 64.0 * u2, "{e}");
    }
}
