//! Jacobi's elliptic functions `sn, cn, dn` and the amplitude `am` for a real
//! argument and a parameter `0 ≤ m ≤ 1`, the complete and incomplete elliptic
//! integrals of the first kind, for the Euler-top closed forms
//! ([`super::euler`]).
//!
//! The parameter is given together with its complement `m1 = 1 − m`, so that
//! `k' = √m1` keeps its digits near the separatrix `m → 1`, where every
//! quantity of the motion depends on `k'` (`K ≈ ln(4/k')`).
//!
//! **Method.** `K(m) = π / (2 AGM(1, k'))` and the functions by the descending
//! Landen (arithmetic–geometric mean) transformation, DLMF 22.20(ii)
//! (Abramowitz–Stegun 16.4): `a_0 = 1`, `b_0 = k'`, `c_0 = k`,
//! `a_{n+1} = (a_n + b_n)/2`, `b_{n+1} = √(a_n b_n)`, `c_{n+1} = c_n²/(4 a_{n+1})`
//! (the form of `(a_n − b_n)/2` that does not cancel), until `c_N ≤ ε a_N`;
//! then `φ_N = 2^N a_N u`, `φ_{n−1} = (φ_n + arcsin(c_n sin φ_n / a_n))/2`,
//! `sn u = sin φ_0`, `cn u = cos φ_0`. `dn u = √(cn² u + k'² sn² u)` (a sum of
//! squares: no cancellation). The argument is first reduced to `[0, K/2]` by
//! the quarter-period identities (DLMF 22.4.3, 22.6.1): on `(K/2, K]` with
//! `w = K − u`, `sn u = cn w/dn w`, `cn u = k' sn w/dn w`, `dn u = k'/dn w`, so
//! that `cn` keeps its relative accuracy near its zero at `K`.
//! The incomplete integral `F(φ|m) = sin φ R_F(cos²φ, cos²φ + m1 sin²φ, 1)`
//! (DLMF 19.25.5) with Carlson's duplication algorithm for `R_F`
//! (B. C. Carlson, Numer. Algorithms 10 (1995) 13–26; DLMF 19.36.1).
//!
//! `m = 1` (`k' = 0`): `sn = tanh`, `cn = dn = sech`, `am = gd`, `K = ∞`.
//! `m = 0`: `sn = sin`, `cn = cos`, `dn = 1`, `K = π/2` (the AGM stops at once).

use crate::error::{Error, Result};

/// Largest number of AGM steps: for `k' ≥ 1e-308` the AGM needs at most ~16
/// steps to reach `c_N ≤ ε a_N` (quadratic convergence after
/// `log2 ln(1/k')` steps); 32 leaves a wide margin.
const AGM_MAX: usize = 32;

/// Tolerance of `m + m1 = 1`: both are given by the caller from the same
/// data, each with a few roundings.
const COMPLEMENT_TOL: f64 = 16.0 * f64::EPSILON;

/// Jacobi's elliptic functions for one parameter: the AGM table is built once
/// and serves every argument.
#[derive(Debug, Clone)]
pub struct Jacobi {
    m: f64,
    kc: f64,
    quarter: f64,
    a: [f64; AGM_MAX + 1],
    /// `b_n` of the AGM (`b_n/a_n = √(1 − (c_n/a_n)²)` exactly).
    b: [f64; AGM_MAX + 1],
    c: [f64; AGM_MAX + 1],
    n: usize,
    /// `2^N a_N`: `φ_N = 2^N a_N u`.
    scale: f64,
}

impl Jacobi {
    /// The functions of parameter `m = k²` with complement `m1 = 1 − m`
    /// (both given: `m1` carries `k'` to full relative accuracy near `m = 1`).
    ///
    /// Errors: `m`, `m1` outside `[0, 1]`, not finite, or `m + m1` not 1.
    pub fn new(m: f64, m1: f64) -> Result<Self> {
        if !(0.0..=1.0).contains(&m) || !(0.0..=1.0).contains(&m1) {
            return Err(Error::InvalidArgument {
                what: "elliptic parameter",
                reason: format!("m = {m:e}, 1 - m = {m1:e} must lie in [0, 1]"),
            });
        }
        if (m + m1 - 1.0).abs() > COMPLEMENT_TOL {
            return Err(Error::InvalidArgument {
                what: "elliptic parameter",
                reason: format!("m = {m:e} and 1 - m = {m1:e} do not add up to 1"),
            });
        }
        Self::build(m, m1.sqrt())
    }

    /// The functions of parameter `m` with `k' = √(1 − m)` given directly
    /// (so that a `k'` below `1e-154`, whose square underflows, keeps its
    /// digits; such a `k'` arises within `1e-154` of a separatrix).
    ///
    /// Errors: `m` outside `[0, 1]`, `k'` outside `[0, 1]`, not finite, or
    /// `m + k'²` not 1.
    pub fn with_kc(m: f64, kc: f64) -> Result<Self> {
        if !(0.0..=1.0).contains(&m) || !(0.0..=1.0).contains(&kc) {
            return Err(Error::InvalidArgument {
                what: "elliptic parameter",
                reason: format!("m = {m:e}, k' = {kc:e} must lie in [0, 1]"),
            });
        }
        if (m + kc * kc - 1.0).abs() > COMPLEMENT_TOL {
            return Err(Error::InvalidArgument {
                what: "elliptic parameter",
                reason: format!("m = {m:e} and k'^2 = {:e} do not add up to 1", kc * kc),
            });
        }
        Self::build(m, kc)
    }

    fn build(m: f64, kc: f64) -> Result<Self> {
        let mut a = [0.0; AGM_MAX + 1];
        let mut b = [0.0; AGM_MAX + 1];
        let mut c = [0.0; AGM_MAX + 1];
        a[0] = 1.0;
        b[0] = kc;
        c[0] = m.sqrt();
        let mut n = 0;
        if kc > 0.0 {
            while c[n] > f64::EPSILON * a[n] && n < AGM_MAX {
                let an = 0.5 * (a[n] + b[n]);
                b[n + 1] = (a[n] * b[n]).sqrt();
                c[n + 1] = c[n] * c[n] / (4.0 * an);
                a[n + 1] = an;
                n += 1;
            }
        }
        let quarter = if kc > 0.0 {
            std::f64::consts::FRAC_PI_2 / a[n]
        } else {
            f64::INFINITY
        };
        Ok(Jacobi {
            m,
            kc,
            quarter,
            a,
            b,
            c,
            n,
            scale: a[n] * (n as f64).exp2(),
        })
    }

    /// The parameter `m = k²`.
    pub fn m(&self) -> f64 {
        self.m
    }

    /// `k' = √(1 − m)`.
    pub fn kc(&self) -> f64 {
        self.kc
    }

    /// The quarter period `K(m)` (`∞` at `m = 1`).
    pub fn quarter_period(&self) -> f64 {
        self.quarter
    }

    /// `(sn, cn)` on `[0, K]` by the descending AGM (`u ≥ 0`, finite).
    #[inline]
    fn sn_cn_agm(&self, u: f64) -> (f64, f64) {
        let n = self.n;
        let mut phi = self.scale * u;
        for j in (1..=n).rev() {
            let x = self.c[j] / self.a[j];
            let r = if x < 1e-4 {
                // arcsin y = y + y³/6 + O(y⁵): below ε for |y| < 1e-4 (the
                // last AGM levels, where c_j/a_j falls quadratically).
                let y = x * phi.sin();
                y + y * y * y / 6.0
            } else if x < 0.9 {
                // |y| ≤ 0.9: arcsin amplifies the rounding of y by ≤ 2.3.
                (x * phi.sin()).asin()
            } else {
                // arcsin(x sin φ) as atan2(x sin φ, √(1 − x² sin²φ)) with
                // 1 − x² sin²φ = (b_j/a_j)² + x² cos²φ: near m = 1, x is
                // within 2k' of 1 and arcsin of a rounded x sin φ ≈ 1 would
                // lose ε/k' of the phase; the sum of squares keeps it.
                let (s, c) = phi.sin_cos();
                let w = self.b[j] / self.a[j];
                (x * s).atan2((w * w + x * x * c * c).sqrt())
            };
            phi = 0.5 * (phi + r);
        }
        phi.sin_cos()
    }

    /// `(sn, cn, dn)` for `0 ≤ v ≤ K`, reduced to `[0, K/2]`.
    #[inline]
    fn quarter_values(&self, v: f64) -> (f64, f64, f64) {
        let half = 0.5 * self.quarter;
        if v <= half {
            let (s, c) = self.sn_cn_agm(v);
            // dn = √(cn² + k'² sn²) ≤ 1 (hypot: k' sn may be below 1e-154).
            (s, c, c.hypot(self.kc * s).min(1.0))
        } else {
            let w = (self.quarter - v).max(0.0);
            let (s, c) = self.sn_cn_agm(w);
            let d = c.hypot(self.kc * s).min(1.0);
            (c / d, self.kc * s / d, (self.kc / d).min(1.0))
        }
    }

    /// `(sn, cn, dn)(u)` for `u` in `[−2K, 2K]` (`m < 1`).
    #[inline]
    fn reduced(&self, r: f64) -> (f64, f64, f64) {
        let (sign, v) = if r < 0.0 { (-1.0, -r) } else { (1.0, r) };
        if v <= self.quarter {
            let (s, c, d) = self.quarter_values(v);
            (sign * s, c, d)
        } else {
            // sn(2K − v) = sn v, cn(2K − v) = −cn v, dn(2K − v) = dn v.
            let (s, c, d) = self.quarter_values((2.0 * self.quarter - v).max(0.0));
            (sign * s, -c, d)
        }
    }

    /// `(sn u, cn u, dn u)`.
    ///
    /// For `m < 1` the argument is reduced modulo the period `4K`; the
    /// reduction costs `ε |u|` absolute, as any evaluation at large `u` does.
    /// Non-finite `u` gives NaN.
    pub fn sncndn(&self, u: f64) -> (f64, f64, f64) {
        if self.kc == 0.0 {
            let s = u.tanh();
            let c = 1.0 / u.cosh();
            return (s, c, c);
        }
        let p = 4.0 * self.quarter;
        let r = u - p * (u / p).round();
        self.reduced(r)
    }

    /// `(sn, cn, dn)` at the phase `x` in periods: `u = 4K x` (`m < 1`). The
    /// phase is reduced modulo 1 exactly, so a caller that keeps the phase in
    /// periods (as [`super::euler`] does) loses no digits at large times.
    pub fn sncndn_phase(&self, x: f64) -> (f64, f64, f64) {
        let f = x - x.round();
        self.reduced(4.0 * self.quarter * f)
    }

    /// The amplitude `am u`: `sn = sin am`, `cn = cos am`, continuous and
    /// increasing in `u`, `am(u + 2K) = am u + π` (`am = gd` at `m = 1`).
    pub fn am(&self, u: f64) -> f64 {
        if self.kc == 0.0 {
            return u.sinh().atan();
        }
        let p = 4.0 * self.quarter;
        let n = (u / p).round();
        let (s, c, _) = self.reduced(u - p * n);
        s.atan2(c) + 2.0 * std::f64::consts::PI * n
    }

    /// The incomplete integral of the first kind `F(φ|m) = ∫_0^φ dθ/√(1 − m sin²θ)`,
    /// the inverse of [`Jacobi::am`]: `F(φ + nπ) = F(φ) + 2nK` (`m < 1`).
    ///
    /// Errors: `φ` not finite, or `|φ| ≥ π/2` at `m = 1` (the integral diverges).
    pub fn f(&self, phi: f64) -> Result<f64> {
        if !phi.is_finite() {
            return Err(Error::NonFinite {
                what: "amplitude phi",
                index: 0,
            });
        }
        let pi = std::f64::consts::PI;
        let n = (phi / pi).round();
        let r = phi - n * pi;
        if self.kc == 0.0 && (n != 0.0 || r.abs() >= 0.5 * pi) {
            return Err(Error::InvalidArgument {
                what: "amplitude phi",
                reason: format!("F(phi | 1) diverges at |phi| >= pi/2, got phi = {phi}"),
            });
        }
        let (s, c) = r.sin_cos();
        let y = c.hypot(self.kc * s);
        if y * y == 0.0 {
            // cos φ and k' both below 1e-154: F(±π/2) = ±K to that precision.
            return Ok(s.signum() * self.quarter + 2.0 * n * self.quarter);
        }
        let base = s * carlson_rf(c * c, y * y, 1.0)?;
        Ok(if n == 0.0 {
            base
        } else {
            base + 2.0 * n * self.quarter
        })
    }
}

impl Jacobi {
    /// The argument `u ∈ (−2K, 2K]` with `(sn u, cn u, dn u) = (sn, cn, dn)`
    /// (values of one point, `sn² + cn² = 1`, `dn² + m sn² = 1`), from the
    /// values themselves: `u = sn R_F(cn², dn², 1)` for `cn ≥ 0`,
    /// `sign(sn) 2K − sn R_F(cn², dn², 1)` for `cn < 0`. Unlike
    /// `F(atan2(sn, cn))` it needs no amplitude: near `u = ±K` with `k'`
    /// tiny, `F` changes by `ε/dn` per ulp of the amplitude (by `ln(δ/k')`
    /// for `cos φ = δ ≫ k'`), while `cn` and `dn` carry the point exactly.
    /// Where `cn²` and `dn²` underflow, `R_F(x, y, 1) = ln(4/(√x + √y))`
    /// (to `O((x + y) ln)`, below `1e-300`).
    ///
    /// Errors: non-finite or out-of-range values.
    pub fn arg_from(&self, sn: f64, cn: f64, dn: f64) -> Result<f64> {
        let ok = |v: f64| v.is_finite() && v.abs() <= 1.0 + 4.0 * f64::EPSILON;
        if !(ok(sn) && ok(cn) && ok(dn)) || dn < 0.0 {
            return Err(Error::InvalidArgument {
                what: "elliptic function values",
                reason: format!("sn = {sn:e}, cn = {cn:e}, dn = {dn:e} are not of one point"),
            });
        }
        let (x, y) = (cn * cn, dn * dn);
        let rf = if x + y < 1e-300 {
            (4.0 / (cn.abs() + dn)).ln()
        } else {
            carlson_rf(x, y, 1.0)?
        };
        let base = sn * rf;
        if cn >= 0.0 {
            Ok(base)
        } else {
            let k2 = 2.0 * self.quarter;
            Ok(if sn < 0.0 { -k2 - base } else { k2 - base })
        }
    }
}

/// Carlson's symmetric integral `R_F(x, y, z) = ½ ∫_0^∞ dt/√((t+x)(t+y)(t+z))`
/// for `x, y, z ≥ 0`, at most one zero (DLMF 19.16.1), by the duplication
/// algorithm with the seventh-order series (Carlson 1995, eqs. (2.2)–(2.5)).
///
/// Errors: a negative or non-finite argument, or two zero arguments.
pub fn carlson_rf(x: f64, y: f64, z: f64) -> Result<f64> {
    let args = [x, y, z];
    if args.iter().any(|v| !v.is_finite() || *v < 0.0)
        || args.iter().filter(|v| **v == 0.0).count() > 1
    {
        return Err(Error::InvalidArgument {
            what: "R_F arguments",
            reason: format!("need x, y, z >= 0, finite, at most one zero; got {args:?}"),
        });
    }
    let (mut x, mut y, mut z) = (x, y, z);
    let a0 = (x + y + z) / 3.0;
    // Carlson's stopping rule with r = ε: the truncation error of the series
    // is below ε once 4^{-n} Q < |A_n|.
    let mut q = (3.0 * f64::EPSILON).powf(-1.0 / 6.0)
        * (a0 - x).abs().max((a0 - y).abs()).max((a0 - z).abs());
    let mut a = a0;
    for _ in 0..64 {
        if q < a.abs() {
            break;
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sy * sz + sz * sx;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        a = 0.25 * (a + lam);
        q *= 0.25;
    }
    let dx = (a - x) / a;
    let dy = (a - y) / a;
    let dz = -(dx + dy);
    let e2 = dx * dy - dz * dz;
    let e3 = dx * dy * dz;
    let series = 1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0;
    Ok(series / a.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn limits_m0_and_m1() {
        let j = Jacobi::new(0.0, 1.0).unwrap();
        assert_relative_eq!(j.quarter_period(), std::f64::consts::FRAC_PI_2);
        for &u in &[0.0, 0.3, 1.7, -2.9, 40.0] {
            let (s, c, d) = j.sncndn(u);
            // The reduction modulo 2π costs ε |u|, as it does for sin itself.
            let tol = 2e-16 * (1.0 + u.abs());
            assert!(
                (s - u.sin()).abs() < tol && (c - u.cos()).abs() < tol,
                "u = {u}"
            );
            assert_eq!(d, 1.0);
        }
        let j = Jacobi::new(1.0, 0.0).unwrap();
        assert!(j.quarter_period().is_infinite());
        let (s, c, d) = j.sncndn(0.7);
        assert_relative_eq!(s, 0.7f64.tanh(), max_relative = 1e-15);
        assert_relative_eq!(c, 1.0 / 0.7f64.cosh(), max_relative = 1e-15);
        assert_eq!(c, d);
    }

    #[test]
    fn identities_hold_across_parameters() {
        for &m1 in &[1.0, 0.9, 0.5, 0.1, 1e-3, 1e-8, 1e-16, 1e-40] {
            let m = 1.0 - m1;
            let j = Jacobi::new(m, m1).unwrap();
            for k in -40..=40 {
                let u = 0.173 * k as f64 * j.quarter_period().min(50.0) / 3.0;
                let (s, c, d) = j.sncndn(u);
                // A few roundings of values of size 1.
                assert!((s * s + c * c - 1.0).abs() < 1e-15, "m1 {m1}: sn²+cn²");
                assert!(
                    (d * d + m * s * s - 1.0).abs() < 1e-15,
                    "m1 {m1}: dn²+m sn²"
                );
                // am and F are inverse; F' = 1/dn, so an ulp of am moves
                // F by ε/dn (large near u = K as m → 1).
                let phi = j.am(u);
                let back = j.f(phi).unwrap();
                let tol = 4.0 * f64::EPSILON * (1.0 + u.abs()) / d;
                assert!(
                    (back - u).abs() <= tol,
                    "m1 {m1}: F(am u) = u: u={u} back={back} phi={phi} d={d} K={}",
                    j.quarter_period()
                );
            }
        }
    }

    #[test]
    fn arg_from_inverts_sncndn() {
        for &m1 in &[1.0, 0.5, 1e-8, 1e-30, 1e-300] {
            let j = Jacobi::with_kc(1.0 - m1, m1.sqrt()).unwrap();
            let k = j.quarter_period();
            for frac in [-1.9, -1.0, -0.7, -0.2, 0.0, 0.3, 0.99, 1.0, 1.5, 2.0] {
                let u = frac * k;
                let (s, c, d) = j.sncndn(u);
                let back = j.arg_from(s, c, d).unwrap();
                // The point, not the argument, is what must come back: near
                // ±K with k' tiny many arguments share the doubles (s, c, d).
                let (s2, c2, d2) = j.sncndn(back);
                let tol = 1e-14;
                assert!(
                    (s2 - s).abs() < tol && (c2 - c).abs() < tol,
                    "m1 {m1}, u = {u}"
                );
                // dn relative to itself: its logarithmic derivative is at most
                // 1 in size (m sn cn/dn ≤ 1), so an argument good to ε K
                // leaves it good to that.
                let tol_d = 4.0 * f64::EPSILON * (1.0 + k) * d + 1e-300;
                assert!((d2 - d).abs() <= tol_d, "m1 {m1}, u = {u}: dn");
            }
        }
    }

    #[test]
    fn rf_special_values() {
        // R_F(0, 1, 2) = K(1/2)/√... : R_F(0, y, y) = π/(2√y) (DLMF 19.20.1).
        assert_relative_eq!(
            carlson_rf(0.0, 4.0, 4.0).unwrap(),
            std::f64::consts::PI / 4.0,
            max_relative = 1e-15
        );
        assert_relative_eq!(
            carlson_rf(2.0, 2.0, 2.0).unwrap(),
            2f64.sqrt().recip(),
            max_relative = 1e-15
        );
        assert!(carlson_rf(0.0, 0.0, 1.0).is_err());
        assert!(carlson_rf(-1.0, 1.0, 1.0).is_err());
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(Jacobi::new(1.1, -0.1).is_err());
        assert!(Jacobi::new(0.5, 0.6).is_err());
        assert!(Jacobi::new(f64::NAN, 0.5).is_err());
    }
}
