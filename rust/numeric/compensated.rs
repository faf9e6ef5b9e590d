//! Error-free transformations of doubles: a sum or product and its exact
//! rounding error, `a ∘ b = s + e` (T. J. Dekker, *A floating-point technique
//! for extending the available precision*, Numer. Math. 18 (1971) 224–242;
//! D. E. Knuth, *TAOCP* vol. 2, 4.2.2). The building blocks of the
//! double-double numbers ([`super::dd`]) and of the compensated sums in the
//! theta reduction.
//!
//! None of them uses `f64::mul_add`: without the `fma` target feature (the
//! default x86-64 target) that is a library call of ~9 ns, several times the
//! cost of these few flops. Rust never contracts `a * b + c` into an FMA, so
//! the results are the same bits on every target.

/// `a + b = s + e` exactly (Knuth's two-sum, no condition on the sizes).
#[inline]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a + b = s + e` exactly, for `|a| ≥ |b|` (or `a = 0`) (Dekker).
#[inline]
pub fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// Veltkamp's splitting `a = hi + lo` into two 26-bit halves (valid for
/// `|a| < 2^995`): `hi·n` and `lo·n` are exact for integers `|n| < 2^26`.
#[inline]
pub fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

/// `a b = p + e` exactly (Dekker's product, from [`split`]).
#[inline]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// An error-free product `a b = p + e`, as a parameter: Dekker's from
/// Veltkamp's split everywhere, or one fused multiply-add where the caller
/// runs in code compiled for it (`#[target_feature(enable = "fma")]`, chosen
/// at run time). Both give the same bits: the product's error is exact either
/// way (for `|a|, |b| < 2^995` and no underflow).
pub(crate) trait ExactProd {
    fn two_prod(a: f64, b: f64) -> (f64, f64);
}

/// Dekker's product from Veltkamp's split (17 flops, any CPU).
pub(crate) struct Veltkamp;

impl ExactProd for Veltkamp {
    #[inline(always)]
    fn two_prod(a: f64, b: f64) -> (f64, f64) {
        two_prod(a, b)
    }
}

/// The product's error by one fused multiply-add. Only for callers compiled
/// with the `fma` target feature: elsewhere `mul_add` is a library call.
pub(crate) struct Fused;

impl ExactProd for Fused {
    #[inline(always)]
    fn two_prod(a: f64, b: f64) -> (f64, f64) {
        let p = a * b;
        (p, a.mul_add(b, -p))
    }
}

/// `Σ x_i y_i` in twice the working precision, rounded once (the Dot2
/// algorithm of Ogita, Rump and Oishi, SIAM J. Sci. Comput. 26 (2005)):
/// error-free products by `fma`, error-free sums by [`two_sum`], the errors
/// summed and added at the end. Accurate to a few ulps of the result plus `u²`
/// of the terms, however much they cancel.
pub fn dot2(x: &[f64], y: &[f64]) -> f64 {
    let (mut s, mut c) = (0.0f64, 0.0f64);
    for (&a, &b) in x.iter().zip(y) {
        let p = a * b;
        let ep = a.mul_add(b, -p);
        let (t, es) = two_sum(s, p);
        s = t;
        c += ep + es;
    }
    s + c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The errors are exact: checked on cases whose exact result is known.
    #[test]
    fn error_free_transformations_are_exact() {
        // 1 + 2^-60: the sum rounds to 1, the error is 2^-60 exactly
        assert_eq!(two_sum(1.0, 2f64.powi(-60)), (1.0, 2f64.powi(-60)));
        assert_eq!(two_sum(2f64.powi(-60), 1.0), (1.0, 2f64.powi(-60)));
        assert_eq!(fast_two_sum(1.0, 2f64.powi(-60)), (1.0, 2f64.powi(-60)));
        // (1 + 2^-30)² = 1 + 2^-29 + 2^-60: the last term is the product's error
        let x = 1.0 + 2f64.powi(-30);
        assert_eq!(two_prod(x, x), (1.0 + 2f64.powi(-29), 2f64.powi(-60)));
        // split: hi has at most 26 significant bits and hi + lo = a
        let a = std::f64::consts::PI;
        let (hi, lo) = split(a);
        assert_eq!(hi + lo, a);
        assert_eq!((hi * 2f64.powi(24)).fract(), 0.0);
    }
}
