//! Batches of points, as the Python layer hands them over: chunks between
//! cancellation checks, the route of the Abel map chosen by the caller (tests
//! compare the routes), and the finiteness checks of the inputs.

use super::*;
use crate::numeric::alloc::{items_per_check, try_map, try_vec, try_with_capacity};
use crate::numeric::cancel::Cancel;
use crate::theta::MAX_REDUCTION;

/// Points per chunk between two cancellation checks: ~2 ms of Abel
/// integrals (the 0.5 s promised for Ctrl-C leaves ample room).
const CHUNK: usize = 1024;

/// Rows per cancellation check of the inversion (~1 ms of Newton on the
/// Abel map).
const INVERT_CHUNK: usize = 256;

/// The route of the Abel map of a batch ([`HyperellipticCurve::abel_many`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AbelRoute {
    /// The best-conditioned route per point ([`HyperellipticCurve::abel`]).
    Best,
    /// The ray from infinity.
    Infinity,
    /// The segment from branch point `k` (0-based).
    Branch(usize),
}

/// `NonFinite` naming the first non-finite entry of `v`.
fn check_finite_c(what: &'static str, v: &[C]) -> Result<()> {
    match v.iter().position(|z| !is_finite_c(*z)) {
        Some(index) => Err(Error::NonFinite { what, index }),
        None => Ok(()),
    }
}

impl HyperellipticCurve {
    /// `y(x, sheet)` at each `x` ([`HyperellipticCurve::y`]); `cancel` is
    /// checked about every millisecond.
    ///
    /// Errors: a non-finite `x`; an `x` so large that `y` overflows.
    pub fn y_many(&self, x: &[C], sheet: i8, cancel: &Cancel) -> Result<Vec<C>> {
        check_finite_c("x", x)?;
        try_map("y", x, items_per_check(50.0), cancel, |&v| {
            let y = self.y(v, sheet);
            if !is_finite_c(y) {
                return Err(Error::InvalidArgument {
                    what: "x",
                    reason: format!(
                        "y(x) overflows at x = {}: |y|^2 = |R(x)| ~ |x|^{} is beyond the \
                         double range",
                        crate::error::cnum(v),
                        self.e.len()
                    ),
                });
            }
            Ok(y)
        })
    }

    /// The Abel map of the points `(x_i, y_i)`, row-major `(N, g)`, along
    /// `route`; `cancel` is checked every `CHUNK` points.
    ///
    /// Errors: `x`, `y` of different lengths; those of the Abel map for a point.
    pub fn abel_many(&self, x: &[C], y: &[C], route: AbelRoute, cancel: &Cancel) -> Result<Vec<C>> {
        let (g, n) = (self.g, x.len());
        if y.len() != n {
            return Err(Error::Shape {
                what: "y",
                expected: format!("({n},)"),
                got: format!("({},)", y.len()),
            });
        }
        let mut out = try_vec("u", n * g, C::new(0.0, 0.0))?;
        for (k, chunk) in out.chunks_mut(CHUNK * g).enumerate() {
            cancel.check()?;
            let lo = k * CHUNK;
            let hi = (lo + CHUNK).min(n);
            let via = match route {
                AbelRoute::Best => {
                    self.abel_batch(&x[lo..hi], &y[lo..hi], chunk)?;
                    continue;
                }
                AbelRoute::Infinity => None,
                AbelRoute::Branch(k) => Some(k),
            };
            for i in lo..hi {
                let u = self.abel_via(x[i], y[i], via)?;
                chunk[(i - lo) * g..(i - lo + 1) * g].copy_from_slice(&u);
            }
        }
        Ok(out)
    }

    /// [`HyperellipticCurve::abel_near_branch`] of the points `(e_k + dx_i, y_i)`,
    /// row-major `(N, g)`; `cancel` is checked every `CHUNK` points.
    pub fn abel_near_branch_many(
        &self,
        k: usize,
        dx: &[C],
        y: &[C],
        cancel: &Cancel,
    ) -> Result<Vec<C>> {
        let n = dx.len();
        if y.len() != n {
            return Err(Error::Shape {
                what: "y",
                expected: format!("({n},)"),
                got: format!("({},)", y.len()),
            });
        }
        let mut out = try_with_capacity("u", n * self.g)?;
        for (i, (&d, &w)) in dx.iter().zip(y).enumerate() {
            if i % CHUNK == 0 {
                cancel.check()?;
            }
            out.extend(self.abel_near_branch(k, d, w)?);
        }
        Ok(out)
    }

    /// The rows of `z` (row-major `(N, g)`) reduced modulo the lattice;
    /// `cancel` is checked about every millisecond.
    ///
    /// Errors: a non-finite entry; lattice coordinates beyond
    /// [`MAX_REDUCTION`] (there a double has no fractional part, so the
    /// reduced point is not determined to any digit: the bound of the theta
    /// functions' own reduction).
    pub fn reduce_many(&self, z: &[C], cancel: &Cancel) -> Result<Vec<C>> {
        check_finite_c("z", z)?;
        let g = self.g.max(1);
        let mut out = try_with_capacity("z", z.len())?;
        for (i, row) in z.chunks(g).enumerate() {
            if i % items_per_check(100.0) == 0 {
                cancel.check()?;
            }
            let (alpha, beta) = self.lattice_coordinates(row);
            if let Some(c) = alpha
                .iter()
                .chain(&beta)
                .find(|c| c.is_nan() || c.abs() > MAX_REDUCTION)
            {
                return Err(Error::InvalidArgument {
                    what: "z",
                    reason: format!(
                        "row {i} has a lattice coordinate {}: beyond {MAX_REDUCTION:e} a \
                         double has no fractional part, so z modulo the lattice is not \
                         determined",
                        crate::error::num(*c)
                    ),
                });
            }
            out.extend(self.reduce(row));
        }
        Ok(out)
    }

    /// [`HyperellipticCurve::invert`] of the rows of `u` (row-major `(N, 2)`):
    /// `(x, y)`, each row-major `(N, 2)`; `cancel` is checked every
    /// `INVERT_CHUNK` rows.
    pub fn invert_many(&self, u: &[C], cancel: &Cancel) -> Result<(Vec<C>, Vec<C>)> {
        let n = u.len() / self.g.max(1);
        let mut xs = try_with_capacity("x", 2 * n)?;
        let mut ys = try_with_capacity("y", 2 * n)?;
        for (i, row) in u.chunks(self.g).enumerate() {
            if i % INVERT_CHUNK == 0 {
                cancel.check()?;
            }
            let [(x1, y1), (x2, y2)] = self.invert(row)?;
            xs.extend([x1, x2]);
            ys.extend([y1, y2]);
        }
        Ok((xs, ys))
    }
}
