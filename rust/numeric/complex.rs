//! Complex helpers with the crate's conventions: the principal square root
//! (one branch cut for every layer) and Smith's division.

use num_complex::Complex64;

/// Principal square root, `−π/2 < arg √w ≤ π/2`, with `√(−x) = +i√x` for
/// `x > 0` whatever the sign of the zero imaginary part (so every layer cuts
/// `(−∞, 0)` on the same side).
///
/// Computed as `t = √((|w| + |Re w|)/2)` (Kahan's formulation), which is
/// accurate to a few ulps in both components, unlike the polar form.
/// `|w| = √(Re w² + Im w²)` directly while the sum of squares is a normal
/// double (error ≤ 1 ulp, as `hypot`'s), else `hypot`: libm's `hypot` costs
/// ~250 instructions and was 40 % of the reduction's per-state time.
#[inline]
pub fn sqrt_principal(w: Complex64) -> Complex64 {
    let (re, im) = (w.re, w.im + 0.0); // + 0.0 maps −0.0 to +0.0: one cut side
    if re == 0.0 && im == 0.0 {
        return Complex64::new(0.0, 0.0);
    }
    let modulus = Complex64::new(re, im).modulus();
    let t = ((modulus + re.abs()) / 2.0).sqrt();
    if re >= 0.0 {
        Complex64::new(t, im / (2.0 * t))
    } else {
        Complex64::new(im.abs() / (2.0 * t), t.copysign(im))
    }
}

/// `|z|` as `√(Re z² + Im z²)` while the sum of squares is a normal double
/// (error ≤ 1 ulp, as `hypot`'s), else libm's `hypot` (which costs ~250
/// instructions: the moduli of the tolerance tests of the reduction and of the
/// curve were ~7 % of a frequency map's time).
pub trait Modulus {
    fn modulus(self) -> f64;
}

impl Modulus for Complex64 {
    #[inline(always)]
    fn modulus(self) -> f64 {
        let s = self.re * self.re + self.im * self.im;
        if s.is_normal() && s < f64::MAX {
            s.sqrt()
        } else {
            self.re.hypot(self.im)
        }
    }
}

/// `a / b` by Smith's algorithm: no intermediate `|b|²`, so quotients of
/// numbers near the ends of the double range (`1/(1e-200)`, whose `|b|²`
/// underflows to 0 in the textbook formula) stay finite when the result is.
pub fn cdiv(a: Complex64, b: Complex64) -> Complex64 {
    if b.re.abs() >= b.im.abs() {
        if b.re == 0.0 {
            return a / b; // b = 0: the IEEE result (inf/NaN), caught by the callers
        }
        let r = b.im / b.re;
        let den = b.re + b.im * r;
        Complex64::new((a.re + a.im * r) / den, (a.im - a.re * r) / den)
    } else {
        let r = b.re / b.im;
        let den = b.re * r + b.im;
        Complex64::new((a.re * r + a.im) / den, (a.im * r - a.re) / den)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    #[test]
    fn sqrt_principal_branch() {
        assert_eq!(sqrt_principal(c(4.0, 0.0)), c(2.0, 0.0));
        assert_eq!(sqrt_principal(c(-4.0, 0.0)), c(0.0, 2.0));
        // The signed zero does not move a negative real to the other side of the cut.
        assert_eq!(sqrt_principal(c(-4.0, -0.0)), c(0.0, 2.0));
        assert_eq!(sqrt_principal(c(0.0, 0.0)), c(0.0, 0.0));
        // (1 − 2i)² = −3 − 4i, exactly
        assert_eq!(sqrt_principal(c(-3.0, -4.0)), c(1.0, -2.0));
        // |w|² overflows: hypot takes over
        assert_eq!(sqrt_principal(c(1e300, 0.0)), c(1e150, 0.0));
    }

    #[test]
    fn cdiv_stays_finite_where_the_textbook_quotient_does_not() {
        // (7 + 5i)/(3 − 2i) = (11 + 29i)/13
        let q = cdiv(c(7.0, 5.0), c(3.0, -2.0));
        assert!((q - c(11.0 / 13.0, 29.0 / 13.0)).norm() < 4.0 * f64::EPSILON);
        // |b|² = 2e-400 underflows to 0 in the textbook formula
        let q = cdiv(c(1.0, 0.0), c(1e-200, 1e-200));
        assert!((q - c(5e199, -5e199)).norm() < 4.0 * f64::EPSILON * 1e200);
        assert!(!cdiv(c(1.0, 0.0), c(0.0, 0.0)).re.is_finite());
    }
}
