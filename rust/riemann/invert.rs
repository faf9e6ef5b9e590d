//! Jacobi inversion for genus 2 (`n = 5`): the divisor `{P1, P2}` with
//! `u(P1) + u(P2) = u`, started from the theta quotients (34) and polished
//! by Newton's method on the Abel map.

use super::*;

/// Newton on the Abel map stops at this max-norm residual in the normalised
/// coordinates (`u` is O(1) after reduction; the Abel map itself is good to
/// a few 1e-15).
const INVERT_ATOL: f64 = 2e-14;

/// Largest accepted final residual of the inversion before it is reported as
/// non-convergence.
pub const INVERT_MAX_RESIDUAL: f64 = 1e-11;

/// Newton iterations of the inversion.
const INVERT_MAX_ITER: usize = 40;

impl HyperellipticCurve {
    /// Jacobi inversion (g = 2, n = 5): the divisor `(x1, y1) + (x2, y2)` with
    /// `u(P1) + u(P2) ≡ u` modulo the lattice.
    ///
    /// Start: `(x1 − e_j)(x2 − e_j) = c_j θ[η(e_j)](v)² / θ(v)²`, `v = u + K`
    /// ((34) of Perelomov; `c_j` calibrated at a fixed divisor), from two
    /// branch points; then Newton on the Abel map.
    ///
    /// Errors: `u` on the theta divisor (`θ(u + K) ≈ 0`, [`THETA_DIVISOR_RTOL`]):
    /// the divisor is special and not unique ([`Error::InvalidArgument`]);
    /// Newton not reaching [`INVERT_MAX_RESIDUAL`] ([`Error::NoConvergence`]).
    pub fn invert(&self, u: &[C]) -> Result<[(C, C); 2]> {
        self.check_invert_args(u)?;
        let d = self.derived()?;
        let u = self.reduce(u);
        let v: Vec<C> = (0..2).map(|i| u[i] + d.k[i]).collect();
        let (vals, _) = d.plan.theta_all(&v)?;
        let big = vals.iter().map(|z| z.norm()).fold(0.0, f64::max);
        if vals[0].norm() <= THETA_DIVISOR_RTOL * big {
            return Err(Error::InvalidArgument {
                what: "u",
                reason: format!(
                    "u lies on the theta divisor (|θ(u + K)| = {:e} of the largest theta value): \
                     the divisor contains a pair P + ιP (not unique) or the base point \
                     (∞ for odd n, e_1 for even n)",
                    vals[0].norm() / big
                ),
            });
        }
        let (p, s) = self.symmetric_start(self.calibration()?, &vals)?;
        let disc = sqrt_principal(s * s - 4.0 * p);
        let mut x1 = 0.5 * (s + disc);
        let mut x2 = 0.5 * (s - disc);
        if !is_finite_c(x1) || !is_finite_c(x2) {
            return Err(Error::NoConvergence {
                what: "Jacobi inversion start",
                tol: INVERT_MAX_RESIDUAL,
                reached: f64::INFINITY,
                iterations: 0,
            });
        }
        let (mut y1, mut y2) = (self.y_int(x1, 1), self.y_int(x2, 1));
        let (s1, s2) = self.start_sheets(&u, (x1, y1), (x2, y2))?;
        y1 *= s1;
        y2 *= s2;
        self.newton(u.as_slice(), &mut x1, &mut y1, &mut x2, &mut y2)?;
        Ok([self.point_out(x1, y1), self.point_out(x2, y2)])
    }

    /// Genus 2, two finite entries of `u`.
    fn check_invert_args(&self, u: &[C]) -> Result<()> {
        if self.g != 2 {
            return Err(Error::InvalidArgument {
                what: "invert",
                reason: format!(
                    "implemented for genus 2 (5 or 6 finite branch points), got g = {}, n = {}",
                    self.g,
                    self.e.len()
                ),
            });
        }
        if u.len() != 2 {
            return Err(Error::Shape {
                what: "u",
                expected: "(2,)".into(),
                got: format!("({},)", u.len()),
            });
        }
        if let Some(index) = u.iter().position(|&v| !is_finite_c(v)) {
            return Err(Error::NonFinite { what: "u", index });
        }
        Ok(())
    }

    /// `(p, s) = (x1 x2, x1 + x2)` from the calibrated theta quotients `vals`
    /// at `u + K`: linear equations, odd `n`: `p − e_j s + e_j² = q_j`; even
    /// `n`: `p − e_j s + e_j² = q_j (p − e_0 s + e_0²)`. The pair of equations
    /// with the largest (relative) determinant is used.
    fn symmetric_start(&self, calib: &[Option<(C, usize, usize)>], vals: &[C]) -> Result<(C, C)> {
        let e0 = self.e[0];
        let rows: Vec<(C, C, C)> = calib
            .iter()
            .enumerate()
            .filter_map(|(j, cal)| {
                let (c, num, den) = (*cal)?;
                let r = vals[num] / vals[den];
                let q = c * r * r;
                let ej = self.e[j];
                let row = if self.e.len() % 2 == 1 {
                    (C::new(1.0, 0.0), -ej, q - ej * ej)
                } else {
                    (1.0 - q, q * e0 - ej, q * e0 * e0 - ej * ej)
                };
                (is_finite_c(row.0) && is_finite_c(row.1) && is_finite_c(row.2)).then_some(row)
            })
            .collect();
        let mut best_pair = None;
        let mut best_det = 0.0;
        for i in 0..rows.len() {
            for j in (i + 1)..rows.len() {
                let (a1, b1, c1) = rows[i];
                let (a2, b2, c2) = rows[j];
                let det = a1 * b2 - a2 * b1;
                let scale = (a1.norm() + b1.norm()) * (a2.norm() + b2.norm());
                let rel = det.norm() / scale;
                if rel > best_det {
                    best_det = rel;
                    best_pair = Some(((c1 * b2 - c2 * b1) / det, (a1 * c2 - a2 * c1) / det));
                }
            }
        }
        best_pair.ok_or(Error::NoConvergence {
            what: "Jacobi inversion start (no usable theta quotients)",
            tol: INVERT_MAX_RESIDUAL,
            reached: f64::INFINITY,
            iterations: 0,
        })
    }

    /// The sheets `(±1, ±1)` of the start points (given on the canonical
    /// sheet) whose Abel images sum closest to `u` modulo the lattice.
    fn start_sheets(&self, u: &[C], (x1, y1): (C, C), (x2, y2): (C, C)) -> Result<(f64, f64)> {
        let u1 = self.normalise(&self.abel_unnormalised(x1, y1)?);
        let u2 = self.normalise(&self.abel_unnormalised(x2, y2)?);
        let mut best = (f64::INFINITY, 1.0, 1.0);
        for s1 in [1.0, -1.0] {
            for s2 in [1.0, -1.0] {
                let r: Vec<C> = (0..2).map(|i| s1 * u1[i] + s2 * u2[i] - u[i]).collect();
                let r = self.reduce(&r);
                let m = r[0].norm().max(r[1].norm());
                if m < best.0 {
                    best = (m, s1, s2);
                }
            }
        }
        Ok((best.1, best.2))
    }

    fn newton(&self, u: &[C], x1: &mut C, y1: &mut C, x2: &mut C, y2: &mut C) -> Result<()> {
        let mut res = f64::INFINITY;
        for it in 0..INVERT_MAX_ITER {
            let u1 = self.normalise(&self.abel_unnormalised(*x1, *y1)?);
            let u2 = self.normalise(&self.abel_unnormalised(*x2, *y2)?);
            let r: Vec<C> = (0..2).map(|i| u1[i] + u2[i] - u[i]).collect();
            let r = self.reduce(&r);
            res = r[0].norm().max(r[1].norm());
            if res <= INVERT_ATOL {
                return Ok(());
            }
            // du/dx_i = A^{-1} (1, x_i)/y_i.
            let c1 = self.normalise(&[C::new(1.0, 0.0) / *y1, *x1 / *y1]);
            let c2 = self.normalise(&[C::new(1.0, 0.0) / *y2, *x2 / *y2]);
            let det = c1[0] * c2[1] - c2[0] * c1[1];
            if det.norm() == 0.0 || !is_finite_c(det) {
                break;
            }
            let d1 = -(c2[1] * r[0] - c2[0] * r[1]) / det;
            let d2 = -(-c1[1] * r[0] + c1[0] * r[1]) / det;
            for (x, y, dx) in [(&mut *x1, &mut *y1, d1), (&mut *x2, &mut *y2, d2)] {
                let xn = *x + dx;
                let yn = self.y_int(xn, 1);
                // Continue the sheet: y' = R'(x)/(2y) = (y/2) Σ 1/(x − e_k).
                let dy = 0.5
                    * *y
                    * self
                        .e
                        .iter()
                        .map(|&ek| C::new(1.0, 0.0) / (*x - ek))
                        .sum::<C>();
                let pred = *y + dy * dx;
                *y = if (yn - pred).norm() <= (yn + pred).norm() {
                    yn
                } else {
                    -yn
                };
                *x = xn;
            }
            if !is_finite_c(*x1) || !is_finite_c(*x2) {
                break;
            }
            let _ = it;
        }
        if res <= INVERT_MAX_RESIDUAL {
            return Ok(());
        }
        Err(Error::NoConvergence {
            what: "Jacobi inversion (Newton on the Abel map)",
            tol: INVERT_MAX_RESIDUAL,
            reached: res,
            iterations: INVERT_MAX_ITER,
        })
    }
}
