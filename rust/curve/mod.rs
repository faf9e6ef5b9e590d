//! The genus-2 curve (8), Weierstrass' Wurzelfunktionen (27)–(28), their
//! identities (29)–(33), and the inverse map from Kötter's (ξ, η) (37) back to
//! the points of the curve.
//!
//! # The curve
//!
//! `y² = R(x) = Π_{j=0}^{4} (x − d_j)`, `d_0 = 0`, `d_4 = d_1 d_2 d_3` (8). The
//! `d_j` are complex in general. A point of the curve is a pair `(z, y)` with
//! `y² = R(z)`; the point carries its `y` explicitly (its sheet).
//!
//! # Square-root conventions (all of them)
//!
//! * `sqrt_principal(w)` is the principal square root, `−π < arg w ≤ π`, so
//!   `−π/2 < arg √w ≤ π/2`; a negative real `w` (with either sign of zero in
//!   its imaginary part) gives `+i√|w|`. Cut: `w ∈ (−∞, 0)`.
//! * The canonical roots of a point `(z, y)`: `r_j(z) = sqrt_principal(z − d_j)`
//!   for `j = 0, 1, 2, 3`, and `r_4(z) = ±sqrt_principal(z − d_4)` with the
//!   sign for which `Π_{j=0}^{4} r_j(z)` is the given `y` (the sign whose
//!   product lies on the same side as `y`: `Re(conj(Π r) · y) ≥ 0`; at a branch
//!   point `y = 0` this gives `+`). So `r_j(z)² = z − d_j` for every `j` and
//!   `Π_j r_j(z) = y` exactly, for either sheet.
//! * The canonical sheet `y(x) = Π_{j=0}^{4} sqrt_principal(x − d_j)`
//!   ([`KotterCurve::y`]); the other sheet is `−y(x)`.
//! * The Wurzelfunktionen (27) of a pair of points, with a branch `eps ∈ {±1}⁵`
//!   with `Π eps_j = +1` (default all `+1`):
//!   `P_j = eps_j r_j(z1) r_j(z2)`, hence `P_j² = (z1 − d_j)(z2 − d_j)` and
//!   **`P_0 P_1 P_2 P_3 P_4 = y1 y2`**. The 16 admissible `eps` are all the
//!   sign choices of the `P_j` compatible with that product; which one a
//!   trajectory needs is not a property of the two points (the `P_j` are
//!   double-valued on the symmetric square of the curve), so it is an explicit
//!   argument and [`KotterCurve::points_from_xi_eta`] returns it.
//! * (28) then fixes the `P_jk`: `P_jk = eps_j eps_k (a − b)/(z1 − z2)` with
//!   `a = r_j(z2) r_k(z2) ρ_jk(z1)`, `b = r_j(z1) r_k(z1) ρ_jk(z2)`,
//!   `ρ_jk(z) = Π_{m ∉ {j,k}} r_m(z)`. This is (28) with
//!   `√R(z_i) = y_i = Π_m r_m(z_i)` cancelled against the denominators, so it
//!   has no division by `z_i − d_j` and is the continuous extension of (28) to
//!   points at branch points.
//!
//! # Identities (checked in the tests; see `docs/curve.md`)
//!
//! With `(j, k, l)` a cyclic permutation of `(1, 2, 3)`,
//! `c̃_j = 1/((d_j − d_k)(d_j − d_l))`, `c_j = (d_j − d_4) c̃_j` (33):
//! (30), (31), (32) hold as printed; (29) holds with the right-hand side
//! multiplied by `κ = Π_{m=1}^{3} (d_m − d_4)` (erratum). The inverse map uses
//! (30a), (31b) and the two identities
//! `Σ_j c̃_j P_kl² = z1 + z2 − d_4`, `Σ_j c̃_j d_j P_kl² = z1 z2` (30b).

mod inverse;
mod polish;
mod wurzel;

pub(crate) use inverse::InverseStart;
pub use inverse::INVERSE_RTOL;

use crate::numeric::complex::Modulus;
use num_complex::Complex64;

use crate::error::{Error, Result};
use crate::numeric::complex::{cdiv, sqrt_principal};

/// Relative residual `|y² − R(z)| / Π_j (|z| + |d_j|)` above which a point is
/// rejected as not lying on the curve. `Π_j (|z| + |d_j|)` bounds the size of
/// the terms of `R(z)`, so rounding in any reasonable computation of `y`
/// leaves a residual of a few units of 1e-16; 1e-8 rejects a wrong `y` (or a
/// wrong curve) while accepting points carried through long computations.
pub const ON_CURVE_RTOL: f64 = 1e-8;

/// Offsets `zd_j` given with a point must agree with `z − d_j` to
/// `OFFSET_RTOL · (|z| + max_m |d_m|)`: the accurate offsets
/// `t + (d_b − d_j)` and the rounded `z − d_j` differ by a few roundings of
/// numbers of that size; anything larger is an inconsistent point.
pub const OFFSET_RTOL: f64 = 16.0 * f64::EPSILON;

/// Two branch points closer than this (relative to their size) are treated as
/// coinciding: `d_4 = d_1 d_2 d_3` is a rounded product, so `d_4 = d_1` when
/// `d_2 d_3 = 1` only up to a few ulps.
const REPEATED_RTOL: f64 = 8.0 * f64::EPSILON;

/// The cyclic permutations `(j, k, l)` of `(1, 2, 3)`, in the order `j = 1, 2, 3`.
pub const CYCLIC: [(usize, usize, usize); 3] = [(1, 2, 3), (2, 3, 1), (3, 1, 2)];

/// The genus-2 curve (8) `y² = R(x) = Π_{j=0}^{4} (x − d_j)`, `d_0 = 0`,
/// `d_4 = d_1 d_2 d_3`, with distinct (complex) branch points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KotterCurve {
    d: [Complex64; 5],
}

/// The Wurzelfunktionen of a pair of points: `p[j] = P_j` (27) and
/// `pjk[j][k] = P_jk` (28), `j, k = 0..4`; `pjk` is symmetric with zero
/// diagonal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wurzel {
    /// `P_0 … P_4`, with `Π P_j = y1 y2`.
    pub p: [Complex64; 5],
    /// `P_jk`, symmetric, `P_jj = 0`.
    pub pjk: [[Complex64; 5]; 5],
}

/// A pair of points of the curve, the factor `g` and the branch `eps` of the
/// Wurzelfunktionen, as recovered by [`KotterCurve::points_from_xi_eta`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WurzelPoints {
    /// First point: the root of `U(x) = x² − (z1+z2) x + z1 z2` of larger
    /// modulus in the closed form, then polished (the pair is unordered).
    pub z1: Complex64,
    /// Its `y`, `y1² = R(z1)`.
    pub y1: Complex64,
    /// Second point.
    pub z2: Complex64,
    /// Its `y`.
    pub y2: Complex64,
    /// The factor of (37): `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`.
    pub g: Complex64,
    /// The branch of the `P_j` (see the module docs), normalised to `eps[4] = +1`.
    pub eps: [i8; 5],
    /// Largest deviation `|(ξ, η) − (ξ, η)(z1, y1, z2, y2, g, eps)|`.
    pub residual: f64,
    /// `zd1[j] = z1 − d_j`, `j = 0..4`, to full relative accuracy (see
    /// [`CurvePoint`]): a point close to a branch point is not resolved by
    /// `z1` alone.
    pub zd1: [Complex64; 5],
    /// `zd2[j] = z2 − d_j`.
    pub zd2: [Complex64; 5],
}

/// A point `(z, y)` of the curve together with its offsets
/// `zd[j] = z − d_j` from the branch points, `j = 0..4`.
///
/// Why the offsets: a double-precision `z` fixes `z − d_j` only to an
/// absolute `u |z|` (u the unit roundoff), i.e. to a relative `u |z| / |z − d_j|`,
/// and the roots `√(z − d_j)` of (27)–(28) inherit it. A point 4e-9 from a
/// branch point (as on the `near_degenerate` top, whose `d_1, d_2` are 3.8e-5
/// apart and trap the point between them) loses eight digits in `√(z − d_j)`.
/// Carried separately (computed as `t + (d_b − d_j)` from the offset `t`
/// to the nearest branch point `d_b`), the offsets are accurate to a few ulps
/// relative. [`KotterCurve::point`] fills them in plainly from `z`;
/// [`KotterCurve::points_from_xi_eta`] returns accurate ones.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// The abscissa.
    pub z: Complex64,
    /// Its `y`, `y² = R(z)` (the sheet).
    pub y: Complex64,
    /// `zd[j] = z − d_j`, `j = 0..4`.
    pub zd: [Complex64; 5],
}

fn check_finite_c(what: &'static str, x: &[Complex64]) -> Result<()> {
    match x
        .iter()
        .position(|v| !(v.re.is_finite() && v.im.is_finite()))
    {
        Some(index) => Err(Error::NonFinite { what, index }),
        None => Ok(()),
    }
}

impl KotterCurve {
    /// The curve (8) with `d_0 = 0`, `d_4 = d1 d2 d3`.
    ///
    /// Errors: [`Error::NonFinite`] for a NaN or infinite `d_j`;
    /// [`Error::RepeatedBranchPoints`] when two of `d_0 … d_4` coincide (then
    /// the curve is singular and its genus drops below 2). `d_j = 0` coincides
    /// with `d_0`; `d_j d_k = 1` makes `d_4 = d_l`.
    pub fn new(d1: Complex64, d2: Complex64, d3: Complex64) -> Result<Self> {
        check_finite_c("d (d1, d2, d3)", &[d1, d2, d3])?;
        let d4 = d1 * d2 * d3;
        check_finite_c("d4 = d1 d2 d3", &[d4])?;
        let d = [Complex64::new(0.0, 0.0), d1, d2, d3, d4];
        for i in 0..5 {
            for j in (i + 1)..5 {
                let scale = d[i].modulus().max(d[j].modulus());
                if (d[i] - d[j]).modulus() <= REPEATED_RTOL * scale {
                    return Err(Error::RepeatedBranchPoints { i, j, value: d[i] });
                }
            }
        }
        Ok(KotterCurve { d })
    }

    /// The branch points `(d_0, d_1, d_2, d_3, d_4) = (0, d1, d2, d3, d1 d2 d3)`.
    pub fn branch_points(&self) -> [Complex64; 5] {
        self.d
    }

    /// `R(x) = Π_{j=0}^{4} (x − d_j)` (8).
    pub fn r(&self, x: Complex64) -> Complex64 {
        self.d
            .iter()
            .fold(Complex64::new(1.0, 0.0), |acc, dj| acc * (x - dj))
    }

    /// The canonical sheet `y(x) = Π_{j=0}^{4} sqrt_principal(x − d_j)`, a
    /// square root of `R(x)`; the other sheet is `−y(x)`.
    pub fn y(&self, x: Complex64) -> Complex64 {
        self.d.iter().fold(Complex64::new(1.0, 0.0), |acc, dj| {
            acc * sqrt_principal(x - dj)
        })
    }

    /// `c̃_j = 1/((d_j − d_k)(d_j − d_l))` (33), `j = 1, 2, 3`, `(j, k, l)` cyclic.
    pub fn c_tilde(&self) -> [Complex64; 3] {
        let d = &self.d;
        // as 1/(d_j − d_k) · 1/(d_j − d_l): the product of two differences can
        // underflow (|d| ~ 1e-160) where c̃_j itself is representable
        let one = Complex64::new(1.0, 0.0);
        CYCLIC.map(|(j, k, l)| cdiv(one, d[j] - d[k]) * cdiv(one, d[j] - d[l]))
    }

    /// `c_j = (d_j − d_4)/((d_j − d_k)(d_j − d_l))` (33) — the curve's
    /// constants, not the top's `c_ij` of (2).
    pub fn c(&self) -> [Complex64; 3] {
        let d = &self.d;
        CYCLIC.map(|(j, k, l)| cdiv(cdiv(d[j] - d[4], d[j] - d[k]), d[j] - d[l]))
    }

    /// `κ = Π_{m=1}^{3} (d_m − d_4) = −R'(d_4)/d_4`, the factor missing from
    /// the right-hand side of (29) as printed (see `docs/errata.md`).
    pub fn kappa(&self) -> Complex64 {
        let d = &self.d;
        (d[1] - d[4]) * (d[2] - d[4]) * (d[3] - d[4])
    }

    /// Checks that `(z, y)` is a finite point of the curve (to [`ON_CURVE_RTOL`]).
    pub fn check_point(&self, what: &'static str, z: Complex64, y: Complex64) -> Result<()> {
        check_finite_c(what, &[z, y])?;
        let scale: f64 = self.d.iter().map(|dj| z.modulus() + dj.modulus()).product();
        let resid = (y * y - self.r(z)).modulus();
        // A NaN residual (overflow of huge inputs) is rejected too.
        if resid.is_nan() || resid > ON_CURVE_RTOL * scale {
            return Err(Error::InvalidArgument {
                what,
                reason: format!(
                    "the point ({z}, {y}) is not on the curve y^2 = R(x): \
                     |y^2 - R(z)| = {resid:e} > {ON_CURVE_RTOL:e} * {scale:e}"
                ),
            });
        }
        Ok(())
    }

    /// The canonical roots `r_j(z)`, `j = 0..4`, of a point `(z, y)`:
    /// `r_j(z)² = z − d_j`, `Π_j r_j(z) = y` (see the module docs). The point
    /// is not checked; see [`KotterCurve::check_point`].
    pub fn roots(&self, z: Complex64, y: Complex64) -> [Complex64; 5] {
        self.roots_from_offsets(&self.offsets(z), y)
    }

    /// The offsets `z − d_j`, `j = 0..4`, computed plainly from `z`.
    pub fn offsets(&self, z: Complex64) -> [Complex64; 5] {
        self.d.map(|dj| z - dj)
    }

    /// The point `(z, y)` with the plain offsets [`KotterCurve::offsets`]
    /// (not checked; see [`KotterCurve::check_curve_point`]).
    pub fn point(&self, z: Complex64, y: Complex64) -> CurvePoint {
        CurvePoint {
            z,
            y,
            zd: self.offsets(z),
        }
    }

    /// The canonical roots `r_j = sqrt_principal(zd_j)` (`j = 0..3`) and
    /// `r_4 = ±sqrt_principal(zd_4)` with `Π_j r_j = y`, from the offsets
    /// `zd_j = z − d_j` (see [`KotterCurve::roots`]).
    pub fn roots_from_offsets(&self, zd: &[Complex64; 5], y: Complex64) -> [Complex64; 5] {
        let mut r = zd.map(sqrt_principal);
        let prod = r[0] * r[1] * r[2] * r[3] * r[4];
        if (prod.conj() * y).re < 0.0 {
            r[4] = -r[4];
        }
        r
    }

    /// Checks a point given with offsets: finite, `zd_j` consistent with
    /// `z − d_j` (to [`OFFSET_RTOL`]) and on the curve, `y² = Π_j zd_j` (to
    /// [`ON_CURVE_RTOL`], as [`KotterCurve::check_point`]).
    pub fn check_curve_point(&self, what: &'static str, p: &CurvePoint) -> Result<()> {
        check_finite_c(what, &[p.z, p.y])?;
        check_finite_c(what, &p.zd)?;
        let dmax = self.d.iter().map(|v| v.modulus()).fold(0.0, f64::max);
        for j in 0..5 {
            let err = (p.zd[j] - (p.z - self.d[j])).modulus();
            if err.is_nan() || err > OFFSET_RTOL * (p.z.modulus() + dmax) {
                return Err(Error::InvalidArgument {
                    what,
                    reason: format!(
                        "the offset zd[{j}] = {} is not z - d_{j} = {} (|difference| = {err:e}): \
                         offsets inconsistent with z",
                        p.zd[j],
                        p.z - self.d[j]
                    ),
                });
            }
        }
        let scale: f64 = self
            .d
            .iter()
            .map(|dj| p.z.modulus() + dj.modulus())
            .product();
        let r: Complex64 = p.zd.iter().product();
        let resid = (p.y * p.y - r).modulus();
        if resid.is_nan() || resid > ON_CURVE_RTOL * scale {
            return Err(Error::InvalidArgument {
                what,
                reason: format!(
                    "the point ({}, {}) is not on the curve y^2 = R(x): \
                     |y^2 - R(z)| = {resid:e} > {ON_CURVE_RTOL:e} * {scale:e}",
                    p.z, p.y
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
