//! Elementary functions in double-double: `exp` of a real DD number and
//! `exp(2πi w)` of a complex one, for the theta series of the precise
//! evaluation of the Theorem (`crate::theta::dd`).
//!
//! The methods are the textbook ones (Muller, *Elementary Functions*, 3rd ed.,
//! ch. 11): for `exp`, `x = k ln 2 + r`, `r` scaled by `2^-10`, a Taylor
//! series of `e^r − 1` and ten squarings of `1 + s` carried as `s ↦ 2s + s²`
//! (no cancellation); for the circular functions the argument is taken in
//! **turns**, so that its reduction modulo 1 and to an eighth of a turn is
//! exact, and only `|2π r| ≤ π/4` enters the Taylor series. Relative errors
//! are a few `u²` (`u = 2^-53`), measured against 40-digit values in the tests.

use super::dd::{Cdd, Dd};

/// `ln 2` in DD.
const LN2: Dd = Dd {
    hi: std::f64::consts::LN_2,
    lo: 2.319_046_813_846_299_6e-17,
};

/// `2π` in DD.
pub(crate) const TWO_PI: Dd = Dd {
    hi: std::f64::consts::TAU,
    lo: 2.449_293_598_294_706_4e-16,
};

/// Squarings after the argument is scaled by `2^-SQUARINGS`.
const SQUARINGS: i32 = 10;

/// Taylor terms of `e^r − 1` for `|r| ≤ ln2/2 · 2^-10`: the tenth term is
/// below `1e-36`.
const EXP_TERMS: usize = 10;

/// Taylor terms of `sin` and `cos` for `|x| ≤ π/4`: `(π/4)^29/29!` ≈ 1e-34.
const TRIG_TERMS: usize = 15;

/// `x · 2^e`, exactly (both parts scaled by a power of two; no overflow in
/// the range used here).
fn ldexp(x: Dd, e: i32) -> Dd {
    let s = 2f64.powi(e);
    Dd {
        hi: x.hi * s,
        lo: x.lo * s,
    }
}

/// `e^x` in DD. Below `e^-745` it is 0; above `e^709` it is `+∞`.
pub(crate) fn exp(x: Dd) -> Dd {
    if x.hi < -745.0 {
        return Dd::ZERO;
    }
    if x.hi > 709.0 {
        return Dd::new(f64::INFINITY);
    }
    let k = (x.hi / LN2.hi).round();
    let r = ldexp(x.sub(LN2.mul_f64(k)), -SQUARINGS);
    // s = e^r − 1 by Horner on r (1 + r/n (1 + r/(n−1) (…))) − 1
    let mut s = Dd::ZERO;
    for n in (1..=EXP_TERMS).rev() {
        s = r.mul(Dd::new(1.0).add(s)).div(Dd::new(n as f64));
    }
    for _ in 0..SQUARINGS {
        s = s.mul_f64(2.0).add(s.mul(s));
    }
    // 2^k with k possibly beyond the exponent range of one factor
    let k = k as i32;
    let y = Dd::new(1.0).add(s);
    ldexp(ldexp(y, k / 2), k - k / 2)
}

/// `(sin x, cos x)` for `|x| ≤ π/4` by their Taylor series.
fn sin_cos_small(x: Dd) -> (Dd, Dd) {
    let x2 = x.mul(x);
    // sin x = x (1 − x²/(2·3) (1 − x²/(4·5) (…))), cos likewise
    let (mut s, mut c) = (Dd::new(1.0), Dd::new(1.0));
    for n in (1..TRIG_TERMS).rev() {
        let ds = (2 * n * (2 * n + 1)) as f64;
        let dc = ((2 * n - 1) * (2 * n)) as f64;
        s = Dd::new(1.0).sub(x2.mul(s).div(Dd::new(ds)));
        c = Dd::new(1.0).sub(x2.mul(c).div(Dd::new(dc)));
    }
    (x.mul(s), c)
}

/// `(sin 2πφ, cos 2πφ)` for `φ` in turns: `φ` reduced modulo 1 and to the
/// nearest quarter exactly (subtracting integers and quarters from a DD
/// number is exact), so only `|2π r| ≤ π/4` is evaluated.
pub(crate) fn sin_cos_turns(phi: Dd) -> (Dd, Dd) {
    let whole = phi.hi.round();
    let f = phi.sub(Dd::new(whole));
    let q = (4.0 * f.hi).round();
    let r = f.sub(Dd::new(q / 4.0));
    let (s, c) = sin_cos_small(TWO_PI.mul(r));
    // rotate by q quarter turns
    match (q as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, s.neg()),
        2 => (s.neg(), c.neg()),
        _ => (c.neg(), s),
    }
}

/// `exp(2πi w)` for a complex DD `w`: `e^{−2π Im w} (cos 2π Re w + i sin 2π Re w)`.
pub(crate) fn exp_2pi_i(w: Cdd) -> Cdd {
    let m = exp(TWO_PI.mul(w.im).neg());
    let (s, c) = sin_cos_turns(w.re);
    Cdd {
        re: m.mul(c),
        im: m.mul(s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `|x − (hi + lo)|` relative, `x` given as a 40-digit string split into
    /// its double and the double of the rest.
    fn rel(x: Dd, hi: f64, lo: f64) -> f64 {
        (x.sub(Dd::sum(hi, lo)).to_f64() / hi).abs()
    }

    // Reference values: mpmath at 50 digits (printed as hi, lo doubles).
    #[test]
    fn exp_meets_forty_digit_values() {
        // e^0.3
        let e = exp(Dd::new(0.3));
        let want = (1.349_858_807_576_003_2, -9.447_314_673_432_387e-17);
        assert!(rel(e, want.0, want.1) < 1e-31, "{e:?}");
        // e^-20.5, e^37.25: the reduction by k ln 2
        let e = exp(Dd::new(-20.5));
        let want = (1.250_152_866_386_742_6e-9, 6.448_235_878_237_776e-26);
        assert!(rel(e, want.0, want.1) < 1e-31, "{e:?}");
        let e = exp(Dd::new(37.25));
        let want = (1.504_767_666_846_084e16, 0.439_172_453_695_712_34);
        assert!(rel(e, want.0, want.1) < 1e-31, "{e:?}");
    }

    #[test]
    fn sine_and_cosine_in_turns_meet_forty_digit_values() {
        // 2π · 0.3 and 2π · (−7.1234)
        let (s, c) = sin_cos_turns(Dd::new(0.3));
        assert!(rel(s, 0.951_056_516_295_153_6, -4.853_158_876_183_457e-17) < 1e-31);
        assert!(rel(c, -0.309_016_994_374_947_34, -1.751_852_518_386_914e-17) < 1e-31);
        let (s, c) = sin_cos_turns(Dd::new(-7.1234));
        assert!(rel(s, -0.699_962_556_739_481_8, -5.882_868_031_408_607e-18) < 1e-31);
        assert!(rel(c, 0.714_179_542_666_077_5, 2.174_671_133_016_239_6e-17) < 1e-31);
    }
}
