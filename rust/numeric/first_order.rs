//! Complex numbers with their first-order rounding error ("compensated"
//! arithmetic): a value `hi + lo` where `hi` is what double arithmetic gives
//! and `lo` its error to first order in the unit roundoff `u`, itself
//! computed in plain double.
//!
//! Why: a double-double product costs four error-free products and two
//! accurate DD sums per complex product, most of it spent on terms of order
//! `u²` that a sum of a few hundred smooth terms does not need. Here every
//! operation keeps the error-free part of the double result (by [`two_sum`]
//! and an exact product) and propagates the incoming `lo` terms linearly:
//! `(a + α)(b + β) = ab + (aβ + αb) + αβ`, the last dropped. The result is
//! accurate to `O(u²)` relative per operation, as in the compensated Horner
//! scheme of Graillat, Langlois and Louvet, *Algorithms for accurate,
//! validated and fast polynomial evaluation*, Japan J. Indust. Appl. Math. 26
//! (2009), and the Dot2 of Ogita, Rump and Oishi (SIAM J. Sci. Comput. 26,
//! 2005).
//!
//! The exact product is a parameter ([`ExactProd`]).

use num_complex::Complex64;

use super::compensated::{two_sum, ExactProd};

type C = Complex64;

/// A complex value `hi + lo`, `lo` the first-order error of `hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Cc {
    pub hi: C,
    pub lo: C,
}

impl Cc {
    pub const ZERO: Cc = Cc {
        hi: C::new(0.0, 0.0),
        lo: C::new(0.0, 0.0),
    };

    /// `hi + lo` from a double and its rounding error.
    pub fn new(hi: C, lo: C) -> Cc {
        Cc { hi, lo }
    }

    /// `self + b`: the double sum with its exact error.
    #[inline(always)]
    pub fn add(self, b: Cc) -> Cc {
        let (re, ere) = two_sum(self.hi.re, b.hi.re);
        let (im, eim) = two_sum(self.hi.im, b.hi.im);
        Cc {
            hi: C::new(re, im),
            lo: C::new(ere, eim) + self.lo + b.lo,
        }
    }

    /// `self − b`.
    #[inline(always)]
    pub fn sub(self, b: Cc) -> Cc {
        self.add(Cc {
            hi: -b.hi,
            lo: -b.lo,
        })
    }

    /// `self · b`: the double product with its error to first order.
    #[inline(always)]
    pub fn mul<M: ExactProd>(self, b: Cc) -> Cc {
        let (hi, err) = cmul_err::<M>(self.hi, b.hi);
        Cc {
            hi,
            lo: err + self.hi * b.lo + self.lo * b.hi,
        }
    }

    /// `self · (t + t_lo)` for a real factor given with its low part.
    #[inline(always)]
    pub fn mul_real<M: ExactProd>(self, t: f64, t_lo: f64) -> Cc {
        let (re, ere) = M::two_prod(self.hi.re, t);
        let (im, eim) = M::two_prod(self.hi.im, t);
        Cc {
            hi: C::new(re, im),
            lo: C::new(ere, eim) + self.hi * t_lo + self.lo * t,
        }
    }
}

/// `a b` in double and its error `a b − fl(a b)` to first order (each real
/// product exact, the two sums with their exact errors).
#[inline(always)]
pub(crate) fn cmul_err<M: ExactProd>(a: C, b: C) -> (C, C) {
    let (p1, e1) = M::two_prod(a.re, b.re);
    let (p2, e2) = M::two_prod(a.im, b.im);
    let (p3, e3) = M::two_prod(a.re, b.im);
    let (p4, e4) = M::two_prod(a.im, b.re);
    let (re, ere) = two_sum(p1, -p2);
    let (im, eim) = two_sum(p3, p4);
    (C::new(re, im), C::new(ere + (e1 - e2), eim + (e3 + e4)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::compensated::{Fused, Veltkamp};
    use crate::numeric::dd::{Cdd, Dd};

    fn cdd(z: Cc) -> Cdd {
        Cdd::from_parts(z.hi, z.lo)
    }

    /// A chain of products and sums agrees with the same chain in
    /// double-double to `O(u²)`, and both exact products give the same bits.
    #[test]
    fn products_and_sums_agree_with_double_double() {
        let zs = [
            C::new(0.7, -1.3),
            C::new(-2.1, 0.4),
            C::new(1.0 / 3.0, 5.0 / 7.0),
            C::new(1e3, -1e-3),
        ];
        let (mut a, mut b) = (Cc::new(zs[0], C::new(0.0, 0.0)), Cdd::new(zs[0]));
        for z in &zs[1..] {
            let zc = Cc::new(*z, C::new(1e-17, -2e-17));
            a = a.mul::<Veltkamp>(zc).add(zc);
            let bz = cdd(zc);
            b = b.mul(bz).add(bz);
            let d = cdd(a).sub(b).to_c().norm();
            assert!(d <= 1e-30 * b.to_c().norm().max(1.0), "{d:e}");
        }
        let x = Cc::new(C::new(0.1, 0.2), C::new(3e-18, 0.0));
        let y = x.mul_real::<Veltkamp>(0.3, 1e-17);
        let yd = cdd(x).mul_dd(Dd::sum(0.3, 1e-17));
        assert!(cdd(y).sub(yd).to_c().norm() <= 1e-32);
        for (p, q) in [(0, 3), (1, 2), (2, 3)] {
            assert_eq!(
                cmul_err::<Fused>(zs[p], zs[q]),
                cmul_err::<Veltkamp>(zs[p], zs[q])
            );
        }
    }
}
