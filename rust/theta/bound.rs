//! A proven tail bound for the theta series (docs/theta.md, section "Tail bound").
//!
//! For a lattice `Λ ⊂ R^g` in which distinct points are at least `ρ` apart
//! (`ρ` ≤ the shortest nonzero vector), any translate `v + Λ`, an integer
//! `p ≥ 0` and `R ≥ ρ/2`,
//!
//! ```text
//! Σ_{x ∈ v+Λ, |x| ≥ R} |x|^p e^{-|x|²}
//!     ≤ e^{κ} g (2/ρ)^g ∫_{R-ρ/2}^∞ r^{g-1} (r + ρ/2)^p e^{-r²} dr,   κ = g ρ² / (4 (g+2)).
//! ```
//!
//! Proof (the ball-packing argument of Deconinck, Heil, Bobenko, van Hoeij,
//! Schmies, *Computing Riemann theta functions*, Math. Comp. 73 (2004)
//! 1417–1442, Thm. 2, made explicit with Jensen's inequality): the balls
//! `B(x, ρ/2)` are disjoint and lie in `|y| ≥ R - ρ/2`. On each, by convexity of
//! `exp`, the average of `e^{-|y|²}` is at least `exp(-avg|y|²) = e^{-|x|²-κ}`
//! (the mean of `|y-x|²` over a ball of radius `ρ/2` is `g ρ²/(4(g+2))`), and
//! `|x| ≤ |y| + ρ/2`; so each term is at most `e^κ` times the ball average of
//! `(|y|+ρ/2)^p e^{-|y|²}`. Sum over the disjoint balls and integrate in polar
//! coordinates (`|S^{g-1}| = g·vol(B^g)`).

/// Upper bounds for `I_k(s) = ∫_s^∞ t^k e^{-t²} dt`, `k = 0..=kmax`, `s ≥ 0`.
///
/// `I_0 ≤ min(√π/2, e^{-s²}/(2s))` (from `t/s ≥ 1` on the range), `I_1 = e^{-s²}/2`,
/// `I_k = (k-1)/2 · I_{k-2} + s^{k-1} e^{-s²}/2` (integration by parts); all
/// coefficients are positive, so upper bounds propagate.
fn gaussian_moment_tails(s: f64, out: &mut [f64]) {
    let e = (-s * s).exp();
    let half_sqrt_pi = 0.5 * std::f64::consts::PI.sqrt();
    let i0 = if s > 0.0 {
        half_sqrt_pi.min(e / (2.0 * s))
    } else {
        half_sqrt_pi
    };
    let mut spow = 1.0; // s^{k-1}
    for k in 0..out.len() {
        out[k] = match k {
            0 => i0,
            1 => 0.5 * e,
            _ => {
                spow *= s;
                0.5 * (k as f64 - 1.0) * out[k - 2] + 0.5 * spow * e
            }
        };
    }
}

/// Largest polynomial degree: `g - 1 + p ≤ MAX_GENUS - 1 + 2`.
const MAX_DEGREE: usize = super::MAX_GENUS + 1;

/// The bound of the module documentation: an upper bound for
/// `Σ_{x ∈ v+Λ, |x| ≥ r} |x|^p e^{-|x|²}` for every translate `v` of a lattice
/// whose points are at least `rho` apart; valid for `r ≥ rho/2`, `+∞` otherwise.
pub fn tail_bound(g: usize, rho: f64, r: f64, p: u32) -> f64 {
    if r < 0.5 * rho || rho <= 0.0 || g == 0 {
        return f64::INFINITY;
    }
    let deg = g - 1 + p as usize;
    if deg > MAX_DEGREE {
        return f64::INFINITY;
    }
    // Coefficients of r^{g-1} (r + ρ/2)^p, lowest degree first.
    let mut poly = [0.0; MAX_DEGREE + 1];
    poly[g - 1] = 1.0;
    for step in 0..p as usize {
        let top = g + step; // current degree + 1
        for k in (0..=top).rev() {
            let lower = if k > 0 { poly[k - 1] } else { 0.0 };
            poly[k] = 0.5 * rho * poly[k] + lower;
        }
    }
    let mut moments = [0.0; MAX_DEGREE + 1];
    gaussian_moment_tails(r - 0.5 * rho, &mut moments[..=deg]);
    let integral: f64 = poly[..=deg].iter().zip(&moments).map(|(c, m)| c * m).sum();
    let kappa = g as f64 * rho * rho / (4.0 * (g as f64 + 2.0));
    kappa.exp() * g as f64 * (2.0 / rho).powi(g as i32) * integral
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn moments_match_closed_forms() {
        let s: f64 = 2.0;
        let mut m = [0.0; 4];
        gaussian_moment_tails(s, &mut m);
        // I_1 = e^{-s²}/2 exactly; I_3 = (s²+1) e^{-s²}/2
        assert_relative_eq!(m[1], 0.5 * (-4.0f64).exp(), max_relative = 1e-15);
        assert_relative_eq!(m[3], 0.5 * 5.0 * (-4.0f64).exp(), max_relative = 1e-15);
        // I_0 = √π/2 erfc(2) = 0.004155...; the bound e^{-4}/4 = 0.004579 is above it.
        assert!(m[0] >= 0.5 * std::f64::consts::PI.sqrt() * 4.677_734_981_047_266e-3);
        assert!(m[0] <= 1.11 * 0.5 * std::f64::consts::PI.sqrt() * 4.677_734_981_047_266e-3);
    }

    /// The bound is an upper bound for the genus-1 lattice sum, computed directly.
    #[test]
    fn bound_dominates_direct_genus_one_tails() {
        for &(spacing, shift) in &[(1.0, 0.0), (0.7, 0.3), (2.5, 0.49), (1.7724, 0.25)] {
            for &r in &[0.9, 1.5, 2.5, 3.0, 4.0, 5.5] {
                if r < 0.5 * spacing {
                    continue;
                }
                for p in 0..=2u32 {
                    let mut direct = 0.0;
                    for n in -200i32..=200 {
                        let x: f64 = (n as f64 + shift) * spacing;
                        if x.abs() >= r {
                            direct += x.abs().powi(p as i32) * (-x * x).exp();
                        }
                    }
                    let b = tail_bound(1, spacing, r, p);
                    assert!(b >= direct, "spacing {spacing} shift {shift} r {r} p {p}");
                }
            }
        }
        assert_eq!(tail_bound(2, 1.0, 0.4, 0), f64::INFINITY);
        // a smaller spacing is also a valid (weaker) lattice constant
        assert!(tail_bound(1, 0.5, 3.0, 0) > 0.0);
    }

    /// Genus 2: a skewed lattice with basis (1.3, 0), (0.55, 1.1), shortest vector 1.21…
    #[test]
    fn bound_dominates_direct_genus_two_tails() {
        let (b1, b2) = ([1.3, 0.0], [0.55, 1.1]);
        let rho = (0.55f64 * 0.55 + 1.1 * 1.1).sqrt().min(1.3);
        for &shift in &[[0.0, 0.0], [0.3, -0.2], [0.5, 0.5]] {
            for &r in &[1.0, 2.0, 3.0, 4.5] {
                for p in 0..=2u32 {
                    let mut direct = 0.0;
                    for n1 in -40i32..=40 {
                        for n2 in -40i32..=40 {
                            let x = shift[0] + n1 as f64 * b1[0] + n2 as f64 * b2[0];
                            let y = shift[1] + n1 as f64 * b1[1] + n2 as f64 * b2[1];
                            let d = (x * x + y * y).sqrt();
                            if d >= r {
                                direct += d.powi(p as i32) * (-d * d).exp();
                            }
                        }
                    }
                    let b = tail_bound(2, rho, r, p);
                    assert!(b >= direct, "r {r} p {p}: {b} < {direct}");
                    assert!(
                        b <= 1e3 * direct.max(1e-300),
                        "r {r} p {p}: {b} vs {direct}"
                    );
                }
            }
        }
    }
}
