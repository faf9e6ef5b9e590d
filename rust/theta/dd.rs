//! Genus-2 theta functions and their gradients in double-double, for the
//! precise evaluation of the Theorem (`crate::solution::precise`).
//!
//! The series of the module docs, each term `exp(2πi w)` with
//! `w = ½ mᵀτm + mᵀz` (`m = n + a/2`) in DD ([`crate::numeric::dd_fn`]): the
//! first of each row of lattice points directly, the others by a two-product
//! recurrence; the characteristic `b` contributes `i^{jᵀb}`, `j = 2m`,
//! exactly. The terms kept are those within `e^-CUT` of the largest one:
//! `π (m − c)ᵀ Im τ (m − c) ≤ CUT`, `c = −(Im τ)⁻¹ Im z` the centre of the
//! Gaussian, row by row. No reduction of `z`
//! is made here: the caller passes a `z` reduced modulo twice the lattice
//! (where the quotients are unchanged), so the terms stay moderate.
//!
//! Slow (~0.1 µs a lattice point, ~1000 points for the eight thetas of the
//! Theorem) and meant for evaluations one by one: the double kernels of this
//! module are the fast path.

use crate::numeric::dd::Cdd;
use crate::numeric::dd_fn::{exp_2pi_i, TWO_PI};

/// Terms below `e^-CUT` times the largest are left out: `e^-85` ≈ 1.2e-37,
/// far below the DD rounding of the sum (~1e-32 of its largest term).
const CUT: f64 = 85.0;

/// A theta value and its gradient in `z`.
pub(crate) type JetDd = (Cdd, [Cdd; 2]);

/// `θ[a;b](z, τ)` and `∇_z θ[a;b]` for the characteristics `chars` (genus 2),
/// `τ = [[t[0], t[1]], [t[1], t[2]]]`. Returned in the order of `chars`;
/// `None` where the box of lattice points exceeds `budget` (checked before
/// any term is formed) or `Im τ` is not positive definite.
pub(crate) fn theta_jet_dd(
    chars: &[([u8; 2], [u8; 2])],
    t: &[Cdd; 3],
    z: &[Cdd; 2],
    budget: usize,
) -> Option<Vec<JetDd>> {
    let it = [t[0].im.to_f64(), t[1].im.to_f64(), t[2].im.to_f64()];
    let det = it[0] * it[2] - it[1] * it[1];
    // (Im τ)⁻¹
    let inv = [it[2] / det, -it[1] / det, it[0] / det];
    let zi = [z[0].im.to_f64(), z[1].im.to_f64()];
    let c = [
        -(inv[0] * zi[0] + inv[1] * zi[1]),
        -(inv[1] * zi[0] + inv[2] * zi[1]),
    ];
    if det.is_nan() || det <= 0.0 || it[0] <= 0.0 {
        return None;
    }
    let r = [
        (CUT / std::f64::consts::PI * inv[0]).sqrt(),
        (CUT / std::f64::consts::PI * inv[2]).sqrt(),
    ];
    // the box's side per coordinate, with the margins of the loops below
    let side = |k: usize| 2.0 * r[k] + 4.0;
    let points = 4.0 * side(0) * side(1);
    if points.is_nan() || points > budget as f64 || !c[0].is_finite() || !c[1].is_finite() {
        return None;
    }
    let mut out: Vec<JetDd> = vec![(Cdd::ZERO, [Cdd::ZERO; 2]); chars.len()];
    let q22 = exp_2pi_i(t[2]);
    for a in [[0u8, 0], [0, 1], [1, 0], [1, 1]] {
        let wanted: Vec<usize> = (0..chars.len()).filter(|&k| chars[k].0 == a).collect();
        if wanted.is_empty() {
            continue;
        }
        let ha = [f64::from(a[0]) / 2.0, f64::from(a[1]) / 2.0];
        let lo0 = (c[0] - r[0] - ha[0]).floor() as i64;
        let hi0 = (c[0] + r[0] - ha[0]).ceil() as i64;
        for n0 in lo0..=hi0 {
            let m0 = n0 as f64 + ha[0];
            let d0 = m0 - c[0];
            // The row of the ellipse π (m − c)ᵀ Im τ (m − c) ≤ CUT at this m0.
            let rest = CUT / std::f64::consts::PI - d0 * d0 * (it[0] - it[1] * it[1] / it[2]);
            if rest.is_nan() || rest < 0.0 {
                continue;
            }
            let half = (rest / it[2]).sqrt();
            let mid = c[1] - it[1] * d0 / it[2];
            let n1lo = (mid - half - ha[1]).floor() as i64;
            let n1hi = (mid + half - ha[1]).ceil() as i64;
            let m1 = n1lo as f64 + ha[1];
            // The row's first term directly, the others by the recurrence
            // term(m1 + 1) = term(m1) ρ, ρ(m1 + 1) = ρ(m1) e^{2πi τ22}, with
            // ρ(m1) = exp(2πi (τ22 (m1 + ½) + τ12 m0 + z1)): two products a
            // term instead of an exponential (the relative error grows by a
            // few u² a step, over at most a few dozen steps).
            let mut term = exp_2pi_i(phase(t, z, [m0, m1]));
            let mut rho = exp_2pi_i(t[2].mul_f64(m1 + 0.5).add(t[1].mul_f64(m0)).add(z[1]));
            for n1 in n1lo..=n1hi {
                let m = [m0, n1 as f64 + ha[1]];
                let j = [2 * n0 + i64::from(a[0]), 2 * n1 + i64::from(a[1])];
                for &k in &wanted {
                    let b = chars[k].1;
                    let turns = (j[0] * i64::from(b[0]) + j[1] * i64::from(b[1])).rem_euclid(4);
                    let s = quarter_turns(term, turns);
                    let e = &mut out[k];
                    e.0 = e.0.add(s);
                    e.1[0] = e.1[0].add(s.mul_f64(m[0]));
                    e.1[1] = e.1[1].add(s.mul_f64(m[1]));
                }
                term = term.mul(rho);
                rho = rho.mul(q22);
            }
        }
    }
    // ∂/∂z_k brings down 2πi m_k
    for e in &mut out {
        e.1 = e.1.map(|g| g.mul_dd(TWO_PI).mul_i());
    }
    Some(out)
}

/// `w = ½ mᵀτm + mᵀz` of the term at `m` (the products by the half-integers
/// `m` are exact).
fn phase(t: &[Cdd; 3], z: &[Cdd; 2], m: [f64; 2]) -> Cdd {
    t[0].mul_f64(0.5 * m[0] * m[0])
        .add(t[1].mul_f64(m[0] * m[1]))
        .add(t[2].mul_f64(0.5 * m[1] * m[1]))
        .add(z[0].mul_f64(m[0]))
        .add(z[1].mul_f64(m[1]))
}

/// `i^k · x`, exactly.
fn quarter_turns(x: Cdd, k: i64) -> Cdd {
    match k {
        0 => x,
        1 => x.mul_i(),
        2 => x.neg(),
        _ => x.mul_i().neg(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::theta::{char_from_index, ThetaPlan};
    use num_complex::Complex64 as C;

    /// The series with one DD exponential per term, over a generous box.
    fn direct_jets(chars: &[([u8; 2], [u8; 2])], t: &[Cdd; 3], z: &[Cdd; 2]) -> Vec<JetDd> {
        let mut out: Vec<JetDd> = vec![(Cdd::ZERO, [Cdd::ZERO; 2]); chars.len()];
        for (k, (a, b)) in chars.iter().enumerate() {
            for n0 in -14i64..=14 {
                for n1 in -14i64..=14 {
                    let m = [
                        n0 as f64 + f64::from(a[0]) / 2.0,
                        n1 as f64 + f64::from(a[1]) / 2.0,
                    ];
                    let j = [2 * n0 + i64::from(a[0]), 2 * n1 + i64::from(a[1])];
                    let turns = (j[0] * i64::from(b[0]) + j[1] * i64::from(b[1])).rem_euclid(4);
                    let s = quarter_turns(exp_2pi_i(phase(t, z, m)), turns);
                    let e = &mut out[k];
                    e.0 = e.0.add(s);
                    e.1[0] = e.1[0].add(s.mul_f64(m[0]));
                    e.1[1] = e.1[1].add(s.mul_f64(m[1]));
                }
            }
        }
        for e in &mut out {
            e.1 = e.1.map(|g| g.mul_dd(TWO_PI).mul_i());
        }
        out
    }

    /// The DD thetas agree with the double ones to their rounding, for all
    /// sixteen characteristics, with the gradients by the heat of the series.
    #[test]
    fn dd_thetas_meet_the_double_ones() {
        let tau = [
            C::new(0.1, 1.2),
            C::new(0.3, -0.2),
            C::new(0.3, -0.2),
            C::new(-0.4, 0.9),
        ];
        let z = [C::new(0.13, 0.21), C::new(-0.37, 0.4)];
        let plan = ThetaPlan::new(&tau, 2, 1e-16, 1).unwrap();
        let jet = plan.jet(&z, 1).unwrap();
        let chars: Vec<([u8; 2], [u8; 2])> = (0..16)
            .map(|k| {
                let (a, b) = char_from_index(2, k);
                ([a[0], a[1]], [b[0], b[1]])
            })
            .collect();
        let t = [Cdd::new(tau[0]), Cdd::new(tau[1]), Cdd::new(tau[3])];
        let zd = [Cdd::new(z[0]), Cdd::new(z[1])];
        let got = theta_jet_dd(&chars, &t, &zd, 1_000_000).unwrap();
        // the recurrence against one exponential a term, to DD accuracy
        let direct = direct_jets(&chars, &t, &zd);
        let big = direct.iter().fold(0.0f64, |m, e| m.max(e.0.to_c().norm()));
        for ((v, g), (dv, dg)) in got.iter().zip(&direct) {
            assert!(v.sub(*dv).to_c().norm() <= 1e-29 * big);
            for i in 0..2 {
                assert!(g[i].sub(dg[i]).to_c().norm() <= 1e-28 * big);
            }
        }
        assert!(theta_jet_dd(&chars, &t, &zd, 100).is_none());
        let scale = jet.log_scale.exp();
        for (k, (v, g)) in got.iter().enumerate() {
            let want = jet.values[k] * scale;
            assert!(
                (v.to_c() - want).norm() <= 1e-14 * want.norm().max(1.0),
                "{k}"
            );
            for i in 0..2 {
                let gw = jet.gradient[2 * k + i] * scale;
                assert!(
                    (g[i].to_c() - gw).norm() <= 1e-13 * gw.norm().max(1.0),
                    "{k} {i}"
                );
            }
        }
    }
}
