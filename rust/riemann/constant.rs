//! What needs theta functions on the curve (built on first use): the theta
//! plan of `τ`, the vector of Riemann constants `K` and, for genus 2, the
//! calibration of the inversion's theta quotients.
//!
//! # The vector of Riemann constants in closed form
//!
//! With the base point `P0` a Weierstrass point (`∞` for odd `n`, `e_1` for
//! even `n`), `K` is a half period, and its characteristic is fixed by the
//! characteristics `η(w)` of the other `2g + 1` Weierstrass points `w` alone,
//! in any canonical basis:
//!
//! * Riemann's vanishing theorem (in this crate's convention
//!   `θ(u(D) + K) = 0` for every effective `D` of degree `g − 1`) and
//!   Riemann's singularity theorem: the order of vanishing of `θ` at
//!   `u(D) + K` is `h⁰(D)` (Mumford, *Tata Lectures on Theta I*, Thm. II.3.1
//!   and §II.3; Griffiths–Harris, *Principles*, p. 348).
//! * For `D = w_1 + … + w_m + (g − 1 − m) P0` with distinct Weierstrass points
//!   `w_i ≠ P0`, `u(D) = η(w_1) + … + η(w_m)` is a half period and
//!   `h⁰(D) = 1 + ⌊(g − 1 − m)/2⌋` (`2 P0` is the `g¹₂`; an effective divisor of
//!   degree `≤ g` on a hyperelliptic curve is `r g¹₂ + F` with `F` free of
//!   conjugate pairs and `h⁰ = r + 1`; Mumford, *Tata Lectures on Theta II*,
//!   IIIa, §2).
//! * `θ(z + (b + τa)/2)` is a nonzero multiple of `θ[a;b](z)`, and
//!   `θ[a;b](−z) = (−1)^{a·b} θ[a;b](z)`: the order of vanishing at 0 of
//!   `θ[χ]`, `χ = K + η(w_1) + … + η(w_m)`, has the parity `a·b` of `χ`.
//!
//! Hence `e(K) ≡ 1 + ⌊(g − 1)/2⌋` and, for `g ≥ 2`, `e(K + η(w)) ≡ 1 + ⌊(g − 2)/2⌋`
//! (mod 2) for each of the `2g + 1` points `w ≠ P0`, `e([a;b]) = a·b`. These
//! conditions have exactly one solution: two solutions `K`, `K + δ` give
//! `e(δ) + B(δ, K) = 0` and `B(δ, η(w)) = 0` for all `w` (`e(χ + δ) = e(χ) +
//! e(δ) + B(χ, δ)` with the symplectic form `B`), and the `η(w)` span the
//! half periods, so `δ = 0`; in genus 1, `K` is the one odd characteristic.
//! (In genus 2: `K` is odd and so is each `K + η(w)`: these are the six odd
//! characteristics.) So `K` needs no theta function and no threshold; the
//! `η(w)` are read off the lattice coordinates of `u(w)` (integral to
//! ~1e-14). A numerical search — keep the characteristics whose theta is
//! rounding-sized on the Abel image of the curve — cannot tell vanishing from
//! small when the curve is nearly pinched (`Im τ_ii` of 10 and more makes a
//! theta with `a_i = 1` smaller than `exp(−π Im τ_ii / 4)` everywhere); the
//! closed form is checked against the theta function at one divisor, relative
//! to the thetas with the same `a` (which share that scale).

use super::*;
use std::cmp::Ordering;

/// The closed-form `K` is accepted when
/// `|θ[K](z)| ≤ K_CHECK_RTOL · max_b |θ[a_K; b](z)|` at the Abel image `z` of a
/// fixed divisor of degree `g − 1`: the thetas with the same `a` share the
/// scale `exp(iπ (n + a/2)ᵀτ(n + a/2))` of their dominant terms, so the vanishing
/// one is rounding-sized against them (~1e-15) while a wrong characteristic is
/// O(1) against them, however small all of them are.
const K_CHECK_RTOL: f64 = 1e-8;

/// Relative tolerance of the numerical calibration of the even-degree inversion
/// (constant quotients over four divisors).
const K_SEARCH_RTOL: f64 = 1e-8;

/// Absolute tolerance of the theta sums used here (see `crate::theta`).
const THETA_TOL: f64 = 1e-15;

/// `e([a;b]) = a·b mod 2` for the FLINT index of a characteristic in genus `g`.
fn parity_bit(g: usize, idx: usize) -> u32 {
    let mask = (1usize << g) - 1;
    ((idx >> g) & mask & idx).count_ones() % 2
}

/// The characteristic (FLINT index) of the vector of Riemann constants from
/// those of the Weierstrass points other than the base point (module docs):
/// the unique `χ` with `e(χ) = 1 + ⌊(g − 1)/2⌋` and, for `g ≥ 2`,
/// `e(χ + η) = 1 + ⌊(g − 2)/2⌋` mod 2 for every `η` of `etas`. `None` unless
/// exactly one characteristic qualifies (the `η` are then not those of a
/// hyperelliptic curve's Weierstrass points).
pub(super) fn riemann_char_from_etas(g: usize, etas: &[usize]) -> Option<usize> {
    let e0 = ((1 + (g - 1) / 2) % 2) as u32;
    let e1 = if g >= 2 {
        ((1 + (g - 2) / 2) % 2) as u32
    } else {
        0
    };
    let mut found = None;
    for chi in 0..(1usize << (2 * g)) {
        if parity_bit(g, chi) != e0 {
            continue;
        }
        if g >= 2 && etas.iter().any(|&eta| parity_bit(g, chi ^ eta) != e1) {
            continue;
        }
        if found.is_some() {
            return None;
        }
        found = Some(chi);
    }
    found
}

impl HyperellipticCurve {
    pub(super) fn derived(&self) -> Result<&Derived> {
        self.derived_with(None)
    }

    /// The derived data, built on first use with `plan` for its theta values
    /// where that is a plan for this curve's `τ` (else with its own).
    fn derived_with(&self, plan: Option<&ThetaPlan>) -> Result<&Derived> {
        self.derived
            .get_or_init(|| {
                let plan = match plan {
                    Some(p) if p.genus() == self.g && p.is_for(&self.tau_flat) => {
                        p.clone().with_parallel(true)
                    }
                    _ => ThetaPlan::new(&self.tau_flat, self.g, THETA_TOL, 0)?,
                };
                self.build_derived(plan)
            })
            .as_ref()
            .map_err(|e| e.clone())
    }

    pub(super) fn test_point(&self, j: usize, l: usize) -> (C, C) {
        // Fixed, generic points at the scale of the branch points.
        let w = C::new(
            0.31 + 0.23 * j as f64 - 0.17 * l as f64,
            0.57 - 0.19 * j as f64 + 0.29 * l as f64,
        );
        let x = self.center + w * (1.3 * self.radius);
        (x, self.y_int(x, if (j + l) % 2 == 0 { 1 } else { -1 }))
    }

    /// [`Self::riemann_constant`] with `plan` for the theta values of its
    /// check where the derived data are not built yet: a plan for this
    /// curve's `τ` (checked; else the curve builds its own) with a tolerance
    /// of at most 1e-15, e.g. the Theorem's set-up's, which saves building a
    /// second plan for the same `τ`. `K` is the same half period either way.
    pub(crate) fn riemann_constant_with(&self, plan: &ThetaPlan) -> Result<&[C]> {
        Ok(&self.derived_with(Some(plan))?.k)
    }

    fn build_derived(&self, plan: ThetaPlan) -> Result<Derived> {
        let g = self.g;
        // η(w) of the Weierstrass points other than the base point (∞ for odd
        // n, e_1 for even n).
        let first = if self.e.len() % 2 == 1 { 0 } else { 1 };
        let mut etas = Vec::with_capacity(self.e.len());
        for k in first..self.e.len() {
            let (a, b) = self.branch_char(k)?;
            etas.push(crate::theta::char_index(&a, &b)?);
        }
        let kidx = riemann_char_from_etas(g, &etas).ok_or(Error::NoConvergence {
            what: "Riemann constant (the characteristics of the branch points fix none)",
            tol: CHAR_TOL,
            reached: f64::NAN,
            iterations: 1,
        })?;
        // Check: θ[K] vanishes at the Abel image of a divisor of degree g − 1,
        // relative to the thetas with the same a (module docs).
        let mut z = vec![C::new(0.0, 0.0); g];
        for l in 0..g.saturating_sub(1) {
            let (x, y) = self.test_point(0, l);
            let u = self.normalise(&self.abel_unnormalised(x, y)?);
            for i in 0..g {
                z[i] += u[i];
            }
        }
        let (vals, _) = plan.theta_all(&z)?;
        let a_mask = ((1usize << g) - 1) << g;
        let same_a = (0..vals.len())
            .filter(|&c| c & a_mask == kidx & a_mask)
            .map(|c| vals[c].norm())
            .fold(0.0, f64::max);
        let rel = vals[kidx].norm() / same_a;
        if !matches!(
            rel.partial_cmp(&K_CHECK_RTOL),
            Some(Ordering::Less | Ordering::Equal)
        ) {
            return Err(Error::NoConvergence {
                what: "Riemann constant (theta[K] does not vanish on the Abel image of the curve)",
                tol: K_CHECK_RTOL,
                reached: rel,
                iterations: 1,
            });
        }
        let found = [kidx];
        let k_char = crate::theta::char_from_index(g, found[0]);
        let k = self.half_period(&k_char.0, &k_char.1);
        Ok(Derived {
            plan,
            k_char,
            k,
            calib: OnceLock::new(),
        })
    }

    /// The calibration of the Jacobi inversion start ([`Derived::calib`]),
    /// built on the first inversion: a curve that is only integrated over
    /// (periods, Abel map, `K`) never needs it.
    pub(super) fn calibration(&self) -> Result<&Calibration> {
        let d = self.derived()?;
        d.calib
            .get_or_init(|| self.build_calibration(&d.plan, &d.k))
            .as_ref()
            .map_err(|e| e.clone())
    }

    fn build_calibration(&self, plan: &ThetaPlan, k: &[C]) -> Result<Calibration> {
        let g = self.g;
        let mut calib = Vec::new();
        if g == 2 && self.e.len() == 5 {
            let (x1, y1) = self.test_point(0, 0);
            let (x2, y2) = self.test_point(1, 1);
            let u1 = self.normalise(&self.abel_unnormalised(x1, y1)?);
            let u2 = self.normalise(&self.abel_unnormalised(x2, y2)?);
            let v: Vec<C> = (0..2).map(|i| u1[i] + u2[i] + k[i]).collect();
            let (vals, _) = plan.theta_all(&v)?;
            for j in 0..5 {
                let (a, b) = self.branch_char(j)?;
                let idx = crate::theta::char_index(&a, &b)?;
                let ratio = vals[0] / vals[idx];
                calib.push(Some((
                    (x1 - self.e[j]) * (x2 - self.e[j]) * ratio * ratio,
                    idx,
                    0,
                )));
            }
        } else if g == 2 && self.e.len() == 6 {
            calib = self.calibrate_even(plan, k)?;
        }
        Ok(calib)
    }

    /// Degree 6: for each `j = 1..5` the pair of characteristics `(num, den)`
    /// with `(x1−e_j)(x2−e_j)/((x1−e_0)(x2−e_0)) · θ[den](v)²/θ[num](v)²`
    /// constant (relative [`K_SEARCH_RTOL`]) over four fixed divisors.
    fn calibrate_even(&self, plan: &ThetaPlan, k: &[C]) -> Result<Calibration> {
        let mut divs = Vec::new();
        for t in 0..4 {
            let (x1, y1) = self.test_point(t, 0);
            let (x2, y2) = self.test_point(t + 1, 1);
            let u1 = self.normalise(&self.abel_unnormalised(x1, y1)?);
            let u2 = self.normalise(&self.abel_unnormalised(x2, y2)?);
            let v: Vec<C> = (0..2).map(|i| u1[i] + u2[i] + k[i]).collect();
            let (vals, _) = plan.theta_all(&v)?;
            divs.push((x1, x2, vals));
        }
        let e0 = self.e[0];
        let mut out = vec![None];
        for j in 1..6 {
            let ej = self.e[j];
            let f: Vec<C> = divs
                .iter()
                .map(|(x1, x2, _)| (x1 - ej) * (x2 - ej) / ((x1 - e0) * (x2 - e0)))
                .collect();
            let mut found = None;
            'search: for num in 0..16 {
                for den in 0..16 {
                    if num == den {
                        continue;
                    }
                    let r: Vec<C> = divs
                        .iter()
                        .zip(&f)
                        .map(|((_, _, vals), fj)| {
                            let q = vals[den] / vals[num];
                            fj * q * q
                        })
                        .collect();
                    let r0 = r[0];
                    if !is_finite_c(r0) || r0.norm() == 0.0 {
                        continue;
                    }
                    if r.iter()
                        .all(|ri| (ri - r0).norm() <= K_SEARCH_RTOL * r0.norm())
                    {
                        found = Some((r0, num, den));
                        break 'search;
                    }
                }
            }
            out.push(found);
        }
        Ok(out)
    }

    /// The vector of Riemann constants `K` for the base point `P0`: the half
    /// period `(b + τa)/2` with `θ(u(P_1) + … + u(P_{g−1}) + K) = 0` for all
    /// points (g = 2: `θ(u(P) + K) = 0` for every `P`). Its characteristic is
    /// the closed form in the characteristics `η(w)` of the Weierstrass points
    /// (module docs: Riemann's vanishing and singularity theorems), checked at
    /// one divisor (built on first use).
    ///
    /// Errors: no characteristic or one that fails the check (inaccurate
    /// periods), the theta plan.
    pub fn riemann_constant(&self) -> Result<&[C]> {
        Ok(&self.derived()?.k)
    }

    /// The characteristic `[a; b]` of [`Self::riemann_constant`]
    /// (`K = (b + τa)/2`); its errors.
    pub fn riemann_constant_char(&self) -> Result<(Vec<u8>, Vec<u8>)> {
        Ok(self.derived()?.k_char.clone())
    }

    /// The theta plan of `τ` (built once).
    pub fn theta_plan(&self) -> Result<&ThetaPlan> {
        Ok(&self.derived()?.plan)
    }
}
