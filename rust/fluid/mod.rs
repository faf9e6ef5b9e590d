//! A rigid body in an ideal fluid: Kirchhoff's equations on e(3), and the
//! Clebsch case solved through the genus-2 solution of the Manakov top.
//!
//! **Kirchhoff's equations.** The state is the impulsive couple `M` and the
//! impulsive force `p` in the body frame, `y = (M1, M2, M3, p1, p2, p3)`. The
//! energy is a positive definite quadratic form
//!
//! ```text
//! H = ½ (Mᵀ A M + 2 Mᵀ B p + pᵀ C p),   A, C symmetric, B any 3 × 3,
//! ```
//!
//! (21 coefficients), and the motion is
//!
//! ```text
//! Ṁ = M × ∂H/∂M + p × ∂H/∂p,   ṗ = p × ∂H/∂M,   ∂H/∂M = A M + B p,  ∂H/∂p = Bᵀ M + C p
//! ```
//!
//! (G. Kirchhoff, *Über die Bewegung eines Rotationskörpers in einer
//! Flüssigkeit*, J. Reine Angew. Math. 71 (1870) 237–262). It is the
//! Lie–Poisson flow of `H` on e(3)*; `p·p` and `M·p` are its Casimirs, so
//! with `H` three quadratic invariants that the Gauss–Legendre integrators keep
//! to roundoff. [`KirchhoffBody`] implements [`VectorField`], so every
//! integrator of [`crate::integrate`] runs it.
//!
//! **The body in space.** `∂H/∂M = ω` is the angular velocity and
//! `∂H/∂p = v` the velocity of the body's origin, both in the body frame. With
//! `R` the rotation body → space and `x` the origin's position,
//! `Ṙ = R ω̂`, `ẋ = R v` ([`SpaceMotion`]); then `R p` and `R M + x × R p`
//! are constant (the impulse and its moment in space).
//!
//! **The Clebsch case** ([`clebsch`]): `A`, `C` diagonal, `B = 0` and Clebsch's
//! condition `(C2 − C3)/A1 + (C3 − C1)/A2 + (C1 − C2)/A3 = 0`. Its vector
//! field is linearly conjugate to that of a Manakov top (1)–(2) — a
//! Möbius image of the contraction `a4 → ∞` of the top — so the theta-function
//! solution of [`crate::solution`] solves it exactly (docs/clebsch.md).

// Index loops mirror the subscripts of the formulas.
#![allow(clippy::needless_range_loop)]

pub mod clebsch;
#[cfg(test)]
mod tests;

use nalgebra::{Matrix3, Matrix6};

use crate::error::{check_finite, Error, Result};
use crate::integrate::VectorField;
use crate::so4::SYMMETRY_RTOL;

/// Length of the state `(M, p)`.
pub const DIM: usize = 6;

/// Length of the state of [`SpaceMotion`]: `(M, p)`, `R` row-major, `x`.
pub const SPACE_DIM: usize = 18;

/// A rigid body in an ideal fluid with the energy
/// `H = ½ (Mᵀ A M + 2 Mᵀ B p + pᵀ C p)`.
#[derive(Debug, Clone, PartialEq)]
pub struct KirchhoffBody {
    /// `A` row-major.
    a: [f64; 9],
    /// `B` row-major (`∂²H/∂M_i ∂p_j = B_ij`).
    b: [f64; 9],
    /// `C` row-major.
    c: [f64; 9],
    /// `A`, `B`, `C` diagonal: the field skips the zero products.
    diagonal: bool,
}

impl KirchhoffBody {
    /// A body from `A`, `B`, `C` (3 × 3, row-major).
    ///
    /// Errors: `Shape` (not 9 entries each), `NonFinite`, `NotSymmetric` (`A`
    /// or `C` off symmetry by more than `SYMMETRY_RTOL` of its entries), and
    /// `InvalidArgument` if the 6 × 6 matrix `[[A, B], [Bᵀ, C]]` is not
    /// positive definite (the message gives its smallest eigenvalue and notes
    /// that `H + κ p·p + μ M·p` has the same motion).
    pub fn new(a: &[f64], b: &[f64], c: &[f64]) -> Result<Self> {
        let take = |what: &'static str, x: &[f64]| -> Result<[f64; 9]> {
            let arr: [f64; 9] = x.try_into().map_err(|_| Error::Shape {
                what,
                expected: "(3, 3)".into(),
                got: format!("{} entries", x.len()),
            })?;
            check_finite(what, &arr)?;
            Ok(arr)
        };
        let (a, b, c) = (take("A", a)?, take("B", b)?, take("C", c)?);
        for (what, m) in [("A", &a), ("C", &c)] {
            let mut max_asym: f64 = 0.0;
            let mut bad = false;
            for i in 0..3 {
                for j in i + 1..3 {
                    let (x, y) = (m[3 * i + j], m[3 * j + i]);
                    let d = (x - y).abs();
                    max_asym = max_asym.max(d);
                    bad |= d > SYMMETRY_RTOL * x.abs().max(y.abs());
                }
            }
            if bad {
                return Err(Error::NotSymmetric { what, max_asym });
            }
        }
        let diagonal = (0..3).all(|i| {
            (0..3).all(|j| {
                i == j || (a[3 * i + j] == 0.0 && b[3 * i + j] == 0.0 && c[3 * i + j] == 0.0)
            })
        });
        let body = KirchhoffBody { a, b, c, diagonal };
        let (lo, hi) = scaled_eigen_range(&body.energy_matrix());
        if !(hi.is_finite() && body.rate_scale().is_finite()) {
            return Err(Error::InvalidArgument {
                what: "A, B, C",
                reason: format!(
                    "the energy's eigenvalues overflow the double range (largest {hi:e}); \
                     rescale A, B, C (H -> H/s rescales time, t -> s t)"
                ),
            });
        }
        // A form whose smallest eigenvalue is rounding noise of the largest is
        // not positive definite in any sense the motion could rely on.
        if lo.is_nan() || lo <= 4.0 * f64::EPSILON * hi {
            return Err(Error::InvalidArgument {
                what: "A, B, C",
                reason: format!(
                    "the energy [[A, B], [B^T, C]] must be positive definite; its \
                     eigenvalues range from {lo:e} to {hi:e}. Adding Casimirs, \
                     H + kappa p.p + mu M.p (C -> C + 2 kappa I, B -> B + mu I), \
                     leaves the motion unchanged and may make it positive"
                ),
            });
        }
        Ok(body)
    }

    /// `A` row-major.
    pub fn a(&self) -> &[f64; 9] {
        &self.a
    }
    /// `B` row-major.
    pub fn b(&self) -> &[f64; 9] {
        &self.b
    }
    /// `C` row-major.
    pub fn c(&self) -> &[f64; 9] {
        &self.c
    }

    /// The symmetric 6 × 6 matrix `[[A, B], [Bᵀ, C]]` of `H = ½ yᵀ Q y`
    /// (`A`, `C` symmetrised).
    pub fn energy_matrix(&self) -> Matrix6<f64> {
        let mut q = Matrix6::zeros();
        for i in 0..3 {
            for j in 0..3 {
                // Halved before adding: entries near the double limit do not overflow.
                q[(i, j)] = 0.5 * self.a[3 * i + j] + 0.5 * self.a[3 * j + i];
                q[(3 + i, 3 + j)] = 0.5 * self.c[3 * i + j] + 0.5 * self.c[3 * j + i];
                q[(i, 3 + j)] = self.b[3 * i + j];
                q[(3 + j, i)] = self.b[3 * i + j];
            }
        }
        q
    }

    /// The rate scale `‖Q'‖₂` of the field: the spectral norm of
    /// `[[A, B − μI], [Bᵀ − μI, C − κI]]` with the Casimir parts removed
    /// (`μ = tr B / 3`, `κ` the midpoint of the spectrum of `C`), which do not
    /// move the body. `‖Q'‖₂ |y|` bounds the Lipschitz constant of the field on
    /// the orbit up to a factor 2; the default steps of the integrators scale
    /// with its inverse.
    pub fn rate_scale(&self) -> f64 {
        let mu = (self.b[0] + self.b[4] + self.b[8]) / 3.0;
        let mut q = self.energy_matrix();
        let cm: Matrix3<f64> = q.fixed_view::<3, 3>(3, 3).into_owned();
        let sc = cm.amax();
        let kappa = if sc > 0.0 && sc.is_finite() {
            let ce = (cm / sc).symmetric_eigenvalues();
            0.5 * (ce.max() + ce.min()) * sc
        } else {
            0.0
        };
        for i in 0..3 {
            q[(i, 3 + i)] -= mu;
            q[(3 + i, i)] -= mu;
            q[(3 + i, 3 + i)] -= kappa;
        }
        let (lo, hi) = scaled_eigen_range(&q);
        hi.max(-lo)
    }

    /// `ω = ∂H/∂M = A M + B p` and `v = ∂H/∂p = Bᵀ M + C p`.
    #[inline(always)]
    pub fn velocities(&self, y: &[f64; 6]) -> ([f64; 3], [f64; 3]) {
        let mut w = [[0.0; 1]; 3];
        let mut v = [[0.0; 1]; 3];
        let ys: [[f64; 1]; 6] = std::array::from_fn(|k| [y[k]]);
        self.velocities_lanes(&ys, &mut w, &mut v);
        (w.map(|x| x[0]), v.map(|x| x[0]))
    }

    /// [`KirchhoffBody::velocities`] for `S` states stored component-major.
    #[inline(always)]
    fn velocities_lanes<const S: usize>(
        &self,
        y: &[[f64; S]; 6],
        w: &mut [[f64; S]; 3],
        v: &mut [[f64; S]; 3],
    ) {
        let (a, b, c) = (&self.a, &self.b, &self.c);
        if self.diagonal {
            for k in 0..3 {
                let (akk, bkk, ckk) = (a[4 * k], b[4 * k], c[4 * k]);
                for i in 0..S {
                    w[k][i] = akk * y[k][i] + bkk * y[3 + k][i];
                    v[k][i] = bkk * y[k][i] + ckk * y[3 + k][i];
                }
            }
            return;
        }
        for k in 0..3 {
            for i in 0..S {
                let (m, p) = ([y[0][i], y[1][i], y[2][i]], [y[3][i], y[4][i], y[5][i]]);
                w[k][i] = a[3 * k] * m[0]
                    + a[3 * k + 1] * m[1]
                    + a[3 * k + 2] * m[2]
                    + (b[3 * k] * p[0] + b[3 * k + 1] * p[1] + b[3 * k + 2] * p[2]);
                v[k][i] = b[k] * m[0]
                    + b[3 + k] * m[1]
                    + b[6 + k] * m[2]
                    + (c[3 * k] * p[0] + c[3 * k + 1] * p[1] + c[3 * k + 2] * p[2]);
            }
        }
    }

    /// Kirchhoff's equations at `S` states stored component-major
    /// (`y[k][i]` is component `k` of state `i`).
    #[inline(always)]
    pub fn vector_field_lanes<const S: usize>(&self, y: &[[f64; S]; 6], out: &mut [[f64; S]; 6]) {
        let mut w = [[0.0; S]; 3];
        let mut v = [[0.0; S]; 3];
        self.velocities_lanes(y, &mut w, &mut v);
        for i in 0..S {
            let (m1, m2, m3) = (y[0][i], y[1][i], y[2][i]);
            let (p1, p2, p3) = (y[3][i], y[4][i], y[5][i]);
            let (w1, w2, w3) = (w[0][i], w[1][i], w[2][i]);
            let (v1, v2, v3) = (v[0][i], v[1][i], v[2][i]);
            // Ṁ = M × ω + p × v,  ṗ = p × ω.
            out[0][i] = (m2 * w3 - m3 * w2) + (p2 * v3 - p3 * v2);
            out[1][i] = (m3 * w1 - m1 * w3) + (p3 * v1 - p1 * v3);
            out[2][i] = (m1 * w2 - m2 * w1) + (p1 * v2 - p2 * v1);
            out[3][i] = p2 * w3 - p3 * w2;
            out[4][i] = p3 * w1 - p1 * w3;
            out[5][i] = p1 * w2 - p2 * w1;
        }
    }

    /// Kirchhoff's equations at one state.
    #[inline(always)]
    pub fn vector_field(&self, y: &[f64; 6]) -> [f64; 6] {
        let ys: [[f64; 1]; 6] = std::array::from_fn(|k| [y[k]]);
        let mut out = [[0.0; 1]; 6];
        self.vector_field_lanes(&ys, &mut out);
        out.map(|x| x[0])
    }

    /// The energy `H = ½ (Mᵀ A M + 2 Mᵀ B p + pᵀ C p)`, as `½ (M·ω + p·v)`.
    pub fn hamiltonian(&self, y: &[f64; 6]) -> f64 {
        let (w, v) = self.velocities(y);
        0.5 * ((y[0] * w[0] + y[1] * w[1] + y[2] * w[2])
            + (y[3] * v[0] + y[4] * v[1] + y[5] * v[2]))
    }
}

/// The smallest eigenvalue and the largest modulus of the eigenvalues of a
/// symmetric 6 × 6 matrix, computed on the matrix scaled to entries ≤ 1 (so the
/// iteration never sees an overflowed square) and scaled back.
fn scaled_eigen_range(q: &Matrix6<f64>) -> (f64, f64) {
    let s = q.amax();
    if s == 0.0 || !s.is_finite() {
        return (0.0, if s == 0.0 { 0.0 } else { f64::INFINITY });
    }
    let eig = (q / s).symmetric_eigenvalues();
    let (lo, hi) = eig.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &e| {
        (lo.min(e), hi.max(e.abs()))
    });
    (lo * s, hi * s)
}

/// The Casimirs of e(3)*: `(p·p, M·p)`.
pub fn casimirs(y: &[f64; 6]) -> [f64; 2] {
    [
        y[3] * y[3] + y[4] * y[4] + y[5] * y[5],
        y[0] * y[3] + y[1] * y[4] + y[2] * y[5],
    ]
}

impl VectorField for KirchhoffBody {
    fn dim(&self) -> usize {
        DIM
    }

    #[inline(always)]
    fn eval(&self, y: &[f64], dy: &mut [f64]) {
        // The integrators call eval with slices of dim() = 6 entries.
        if let (Ok(y6), Ok(o6)) = (<&[f64; 6]>::try_from(y), <&mut [f64; 6]>::try_from(dy)) {
            *o6 = self.vector_field(y6);
        }
    }

    #[inline(always)]
    fn eval_lanes<const S: usize, const M: usize>(
        &self,
        y: &[[f64; S]; M],
        out: &mut [[f64; S]; M],
    ) {
        if let (Ok(y6), Ok(o6)) = (
            <&[[f64; S]; 6]>::try_from(&y[..]),
            <&mut [[f64; S]; 6]>::try_from(&mut out[..]),
        ) {
            self.vector_field_lanes(y6, o6);
        }
    }
}

/// Kirchhoff's equations with the body's rotation `R` (body → space) and the
/// position `x` of its origin: `Ṙ = R ω̂`, `ẋ = R v`, `ω = ∂H/∂M`, `v = ∂H/∂p`.
///
/// State `(M, p, R11, R12, …, R33, x1, x2, x3)` ([`SPACE_DIM`] = 18). The
/// space-frame impulse `P = R p` and its moment `K = R M + x × P` are constant
/// along the motion; a Gauss method keeps `R Rᵀ` and `P` (quadratic
/// invariants) to roundoff.
#[derive(Debug, Clone, Copy)]
pub struct SpaceMotion<'a> {
    /// The body.
    pub body: &'a KirchhoffBody,
}

impl VectorField for SpaceMotion<'_> {
    fn dim(&self) -> usize {
        SPACE_DIM
    }

    fn eval(&self, y: &[f64], dy: &mut [f64]) {
        if y.len() != SPACE_DIM || dy.len() != SPACE_DIM {
            return;
        }
        let mut s = [0.0; 6];
        s.copy_from_slice(&y[..6]);
        dy[..6].copy_from_slice(&self.body.vector_field(&s));
        let (w, v) = self.body.velocities(&s);
        let r = &y[6..15];
        // Ṙ = R ω̂ with ω̂ u = ω × u: (R ω̂)_ij = Σ_k R_ik ε_klj ω_l = (r_i × ω)_j,
        // r_i the i-th row of R.
        for i in 0..3 {
            let (r1, r2, r3) = (r[3 * i], r[3 * i + 1], r[3 * i + 2]);
            dy[6 + 3 * i] = r2 * w[2] - r3 * w[1];
            dy[6 + 3 * i + 1] = r3 * w[0] - r1 * w[2];
            dy[6 + 3 * i + 2] = r1 * w[1] - r2 * w[0];
        }
        for i in 0..3 {
            dy[15 + i] = r[3 * i] * v[0] + r[3 * i + 1] * v[1] + r[3 * i + 2] * v[2];
        }
    }
}
