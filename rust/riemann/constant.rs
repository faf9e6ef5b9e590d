//! What needs theta functions on the curve (built on first use): the theta
//! plan of `τ`, the vector of Riemann constants `K` (the even characteristic
//! whose theta vanishes on the Abel images of `g − 1` points) and, for
//! genus 2, the calibration of the inversion's theta quotients.

use super::*;

/// A characteristic `[a; b]` is taken as the Riemann constant when
/// `|θ[a;b](z)| ≤ K_SEARCH_RTOL · max_χ |θ[χ](z)|` at every test divisor: the
/// vanishing values are rounding-sized (~1e-15), the others O(1e-2) or larger.
const K_SEARCH_RTOL: f64 = 1e-8;

/// Absolute tolerance of the theta sums used here (see `crate::theta`).
const THETA_TOL: f64 = 1e-15;

impl HyperellipticCurve {
    pub(super) fn derived(&self) -> Result<&Derived> {
        self.derived
            .get_or_init(|| self.build_derived())
            .as_ref()
            .map_err(|e| e.clone())
    }

    fn test_point(&self, j: usize, l: usize) -> (C, C) {
        // Fixed, generic points at the scale of the branch points.
        let w = C::new(
            0.31 + 0.23 * j as f64 - 0.17 * l as f64,
            0.57 - 0.19 * j as f64 + 0.29 * l as f64,
        );
        let x = self.center + w * (1.3 * self.radius);
        (x, self.y(x, if (j + l) % 2 == 0 { 1 } else { -1 }))
    }

    fn build_derived(&self) -> Result<Derived> {
        let g = self.g;
        let plan = ThetaPlan::new(&self.tau_flat, g, THETA_TOL, 0)?;
        let nchar = 1usize << (2 * g);
        let mut alive = vec![true; nchar];
        for j in 0..3 {
            let mut z = vec![C::new(0.0, 0.0); g];
            for l in 0..g.saturating_sub(1) {
                let (x, y) = self.test_point(j, l);
                let u = self.normalise(&self.abel_unnormalised(x, y)?);
                for i in 0..g {
                    z[i] += u[i];
                }
            }
            let (vals, _) = plan.theta_all(&z)?;
            let big = vals.iter().map(|v| v.norm()).fold(0.0, f64::max);
            for (c, v) in vals.iter().enumerate() {
                if v.norm() > K_SEARCH_RTOL * big {
                    alive[c] = false;
                }
            }
        }
        let found: Vec<usize> = (0..nchar).filter(|&c| alive[c]).collect();
        if found.len() != 1 {
            return Err(Error::NoConvergence {
                what: "Riemann constant (characteristics vanishing on the theta divisor)",
                tol: K_SEARCH_RTOL,
                reached: found.len() as f64,
                iterations: 3,
            });
        }
        let k_char = crate::theta::char_from_index(g, found[0]);
        let k = self.half_period(&k_char.0, &k_char.1);
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
            calib = self.calibrate_even(&plan, &k)?;
        }
        Ok(Derived {
            plan,
            k_char,
            k,
            calib,
        })
    }

    /// Degree 6: for each `j = 1..5` the pair of characteristics `(num, den)`
    /// with `(x1−e_j)(x2−e_j)/((x1−e_0)(x2−e_0)) · θ[den](v)²/θ[num](v)²`
    /// constant (relative [`K_SEARCH_RTOL`]) over four fixed divisors.
    fn calibrate_even(&self, plan: &ThetaPlan, k: &[C]) -> Result<Vec<Option<(C, usize, usize)>>> {
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
    /// points (g = 2: `θ(u(P) + K) = 0` for every `P`), found among the `4^g`
    /// half periods by evaluating theta at three fixed divisors (built on
    /// first use).
    ///
    /// Errors: those of the search (no half period qualifies, the theta plan).
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
