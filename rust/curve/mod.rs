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

use num_complex::Complex64;

use crate::error::{Error, Result};
use crate::numeric::complex::{cdiv, sqrt_principal};

/// Floor of the relative weights of the Gauss–Newton polish of the points
/// (a fraction of the largest of the six targets): below it a component is
/// fitted absolutely.
const REL_FLOOR: f64 = 1e-8;

/// Relative residual (2-norm of the relative residuals of the six data) at
/// which the Levenberg–Marquardt phase of the inverse map's polish hands over
/// to Gauss–Newton, whose quadratic convergence then reaches rounding in one
/// or two steps.
const LM_HANDOVER: f64 = 1e-12;

/// Relative residual `|y² − R(z)| / Π_j (|z| + |d_j|)` above which a point is
/// rejected as not lying on the curve. `Π_j (|z| + |d_j|)` bounds the size of
/// the terms of `R(z)`, so rounding in any reasonable computation of `y`
/// leaves a residual of a few units of 1e-16; 1e-8 rejects a wrong `y` (or a
/// wrong curve) while accepting points carried through long computations.
pub const ON_CURVE_RTOL: f64 = 1e-8;

/// Default relative tolerance of the consistency check in
/// [`KotterCurve::points_from_xi_eta`]: the reconstructed points must
/// reproduce the given `(ξ, η)` to `rtol · max|(ξ, η)|`. Exact data (from
/// [`KotterCurve::xi_eta`]) come back to ~1e-14; 1e-8 leaves room for `(ξ, η)`
/// computed elsewhere while rejecting data off Kötter's quadrics (11).
pub const INVERSE_RTOL: f64 = 1e-8;

/// Offsets `zd_j` given with a point must agree with `z − d_j` to
/// `OFFSET_RTOL · (|z| + max_m |d_m|)`: the accurate offsets
/// `t + (d_b − d_j)` and the rounded `z − d_j` differ by a few roundings of
/// numbers of that size; anything larger is an inconsistent point.
pub const OFFSET_RTOL: f64 = 16.0 * f64::EPSILON;

/// Two branch points closer than this (relative to their size) are treated as
/// coinciding: `d_4 = d_1 d_2 d_3` is a rounded product, so `d_4 = d_1` when
/// `d_2 d_3 = 1` only up to a few ulps.
const REPEATED_RTOL: f64 = 8.0 * f64::EPSILON;

/// `|z1 − z2|` (relative to `max(|z1|, |z2|)`, not to 1: the curve has no
/// preferred scale) below which the inverse reports
/// the double root `z1 == z2` instead of a pair: a discriminant `(z1 − z2)²`
/// that is zero in exact arithmetic comes out ~1e-16 after rounding, i.e.
/// `|z1 − z2|` ~1e-8, and the error of the recovered pair grows like
/// `u/|z1 − z2|²`, reaching O(1e-4) relative at 1e-6: below that the two
/// points are not resolved.
const NEAR_DOUBLE_ROOT: f64 = 1e-6;

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

/// A start for the inverse map of (37) ([`KotterCurve::points_from_xi_eta_fit`]):
/// the abscissas, their offsets `z_i − d_j` from this curve's branch points and
/// `g²`, in the units of the data (not scaled).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InverseStart {
    pub z: [Complex64; 2],
    pub zd: [[Complex64; 5]; 2],
    pub g2: Complex64,
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
                let scale = d[i].norm().max(d[j].norm());
                if (d[i] - d[j]).norm() <= REPEATED_RTOL * scale {
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
        let scale: f64 = self.d.iter().map(|dj| z.norm() + dj.norm()).product();
        let resid = (y * y - self.r(z)).norm();
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
        let dmax = self.d.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for j in 0..5 {
            let err = (p.zd[j] - (p.z - self.d[j])).norm();
            if err.is_nan() || err > OFFSET_RTOL * (p.z.norm() + dmax) {
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
        let scale: f64 = self.d.iter().map(|dj| p.z.norm() + dj.norm()).product();
        let r: Complex64 = p.zd.iter().product();
        let resid = (p.y * p.y - r).norm();
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

    /// [`KotterCurve::wurzel`] for points given with their offsets
    /// ([`CurvePoint`]): the roots `√(z_i − d_j)` are taken from the offsets,
    /// so points close to branch points keep full accuracy.
    ///
    /// Errors: as [`KotterCurve::wurzel`], and offsets inconsistent with `z`.
    pub fn wurzel_points(
        &self,
        p1: &CurvePoint,
        p2: &CurvePoint,
        eps: Option<[i8; 5]>,
    ) -> Result<Wurzel> {
        self.check_curve_point("point (z1, y1, zd1)", p1)?;
        self.check_curve_point("point (z2, y2, zd2)", p2)?;
        self.wurzel_unchecked(p1, p2, eps)
    }

    fn wurzel_unchecked(
        &self,
        p1: &CurvePoint,
        p2: &CurvePoint,
        eps: Option<[i8; 5]>,
    ) -> Result<Wurzel> {
        let (z1, z2) = (p1.z, p2.z);
        let eps = match eps {
            None => [1.0; 5],
            Some(e) => check_eps(e)?,
        };
        let r1 = self.roots_from_offsets(&p1.zd, p1.y);
        let r2 = self.roots_from_offsets(&p2.zd, p2.y);
        // z1 == z2: the telescoped (28) is the tangent limit when the two points
        // are the same point of the curve (same roots, none zero); with
        // y1 = -y2 it is a pole, at a branch point 0/0.
        if z1 == z2 && (r1 != r2 || r1.iter().any(|&v| v == Complex64::new(0.0, 0.0))) {
            return Err(Error::InvalidArgument {
                what: "points (z1, z2)",
                reason: format!(
                    "z1 == z2 == {z1} on different sheets or at a branch point: P_jk (28) \
                     divides by z1 - z2 (a pole, or 0/0 at a branch point); the same point \
                     twice (y1 == y2) is its tangent limit"
                ),
            });
        }
        Ok(wurzel_from_roots(&r1, &r2, z1 - z2, &eps))
    }

    /// [`KotterCurve::xi_eta`] for points given with their offsets
    /// ([`CurvePoint`], [`KotterCurve::wurzel_points`]).
    pub fn xi_eta_points(
        &self,
        p1: &CurvePoint,
        p2: &CurvePoint,
        g: Complex64,
        eps: Option<[i8; 5]>,
        sqrt_c: Option<[Complex64; 3]>,
    ) -> Result<([Complex64; 3], [Complex64; 3])> {
        check_finite_c("g", &[g])?;
        let sc = self.sqrt_c_checked(sqrt_c)?;
        let w = self.wurzel_points(p1, p2, eps)?;
        Ok(xi_eta_of(&w, &sc, g))
    }

    /// The Wurzelfunktionen (27)–(28) of the points `(z1, y1)`, `(z2, y2)` in
    /// the branch `eps` (`None` = all `+1`; see the module docs):
    /// `P_j = eps_j √((z1 − d_j)(z2 − d_j))` with `Π P_j = y1 y2`, and
    /// `P_jk = P_j P_k/(z1 − z2) · (√R(z1)/((z1 − d_j)(z1 − d_k)) − √R(z2)/((z2 − d_j)(z2 − d_k)))`
    /// with `√R(z_i) = y_i`, evaluated in the division-free product form.
    ///
    /// Errors: non-finite input, a point off the curve, `z1 == z2` ((28)
    /// divides by `z1 − z2`), `eps` not in `{±1}⁵` with product `+1`.
    pub fn wurzel(
        &self,
        z1: Complex64,
        y1: Complex64,
        z2: Complex64,
        y2: Complex64,
        eps: Option<[i8; 5]>,
    ) -> Result<Wurzel> {
        self.check_point("point (z1, y1)", z1, y1)?;
        self.check_point("point (z2, y2)", z2, y2)?;
        self.wurzel_unchecked(&self.point(z1, y1), &self.point(z2, y2), eps)
    }

    /// Kötter's vectors (37): `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`,
    /// `(j, k, l)` cyclic, from the points, `g` and the branch `eps`.
    /// `sqrt_c = None` takes `√c_j = sqrt_principal(c_j)`.
    #[allow(clippy::too_many_arguments)]
    pub fn xi_eta(
        &self,
        z1: Complex64,
        y1: Complex64,
        z2: Complex64,
        y2: Complex64,
        g: Complex64,
        eps: Option<[i8; 5]>,
        sqrt_c: Option<[Complex64; 3]>,
    ) -> Result<([Complex64; 3], [Complex64; 3])> {
        check_finite_c("g", &[g])?;
        let sc = self.sqrt_c_checked(sqrt_c)?;
        let w = self.wurzel(z1, y1, z2, y2, eps)?;
        Ok(xi_eta_of(&w, &sc, g))
    }

    fn sqrt_c_checked(&self, sqrt_c: Option<[Complex64; 3]>) -> Result<[Complex64; 3]> {
        let c = self.c();
        match sqrt_c {
            None => Ok(c.map(sqrt_principal)),
            Some(sc) => {
                check_finite_c("sqrt_c", &sc)?;
                for i in 0..3 {
                    let err = (sc[i] * sc[i] - c[i]).norm();
                    if err.is_nan() || err > ON_CURVE_RTOL * c[i].norm() {
                        return Err(Error::InvalidArgument {
                            what: "sqrt_c",
                            reason: format!(
                                "sqrt_c[{i}]^2 = {} differs from c_{} = {} (33)",
                                sc[i] * sc[i],
                                i + 1,
                                c[i]
                            ),
                        });
                    }
                }
                Ok(sc)
            }
        }
    }

    /// The inverse of (37): from `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`
    /// (`j = 1, 2, 3`, `(j, k, l)` cyclic) recover `g`, the points
    /// `(z1, y1)`, `(z2, y2)` and the branch `eps` of the `P_j`.
    ///
    /// With `X_j = ξ_j/√c_j = g P_kl`, `Y_j = η_j/√c_j = g P_j4`:
    ///
    /// * `g² = Σ_j c̃_j Y_j² / d_4` by (30a) `Σ c̃_j P_j4² = d_4`;
    /// * `z1 + z2 = d_4 + Σ_j c̃_j X_j² / g²` and `z1 z2 = Σ_j c̃_j d_j X_j² / g²`
    ///   (the second is (30b) with `P_0² = z1 z2`), so `z1`, `z2` are the roots
    ///   of `U(x) = x² − (z1 + z2) x + z1 z2`;
    /// * `y_i = ±y(z_i)`, and the signs together with `eps` are the choice
    ///   (among the 32 candidates, `eps_4 = +1`) that reproduces `(X, Y)`.
    ///
    /// `g` is determined only up to sign: `(g, y1, y2)` and `(−g, −y1, −y2)`
    /// give the same `(ξ, η)` (the hyperelliptic involution flips every
    /// `P_jk`). The sign of `g` is the one nearer `g_ref` if given, otherwise
    /// that of `sqrt_principal(g²)`; the `y_i` follow.
    ///
    /// Errors: non-finite input; `g² = 0`; `z1 = z2` (a double root of `U`,
    /// where (28) is undefined); data that the reconstruction does not
    /// reproduce to `rtol · max|(ξ, η)|` (not on Kötter's quadrics (11), or a
    /// `sqrt_c` branch inconsistent with the data).
    pub fn points_from_xi_eta(
        &self,
        xi: [Complex64; 3],
        eta: [Complex64; 3],
        sqrt_c: Option<[Complex64; 3]>,
        g_ref: Option<Complex64>,
        rtol: f64,
    ) -> Result<WurzelPoints> {
        self.points_from_xi_eta_fit(xi, eta, sqrt_c, g_ref, rtol, None)
    }

    /// [`KotterCurve::points_from_xi_eta`] with the polish fitting
    /// `(ξ, η)` in the norm of a downstream linear map: `lmap = [α, β, γ, δ]`
    /// weighs the residuals `r_ξj, r_ηj` as `α_j r_ξj + β_j r_ηj` and
    /// `γ_j r_ξj + δ_j r_ηj` ((23): the error the points cause in `m_j, n_j`).
    /// Without it each component is fitted relative to its own size.
    ///
    /// Data computed in floating point lie off the quadrics (11) by a few
    /// ulps of their largest terms; the polish has to move some component by
    /// that much, and `lmap` makes it move the ones `l` is least sensitive to.
    pub fn points_from_xi_eta_fit(
        &self,
        xi: [Complex64; 3],
        eta: [Complex64; 3],
        sqrt_c: Option<[Complex64; 3]>,
        g_ref: Option<Complex64>,
        rtol: f64,
        lmap: Option<&[[Complex64; 3]; 4]>,
    ) -> Result<WurzelPoints> {
        self.points_from_xi_eta_start(xi, eta, sqrt_c, g_ref, rtol, lmap, None)
    }

    /// [`KotterCurve::points_from_xi_eta_fit`] from a given start instead of
    /// the closed form (30) (the polish, the branch search and the checks are
    /// the same). The reduction passes the closed form evaluated in
    /// double-double on its unrounded curve: near the singular set
    /// `h1² = 4h0²` the double-precision closed form cancels by `|d_4|/|z|`
    /// (1e13 and more) and puts a point thousands of units off, across a pair of
    /// branch points a few units apart (docs/kotter.md, "Near the singular set").
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn points_from_xi_eta_start(
        &self,
        xi: [Complex64; 3],
        eta: [Complex64; 3],
        sqrt_c: Option<[Complex64; 3]>,
        g_ref: Option<Complex64>,
        rtol: f64,
        lmap: Option<&[[Complex64; 3]; 4]>,
        start: Option<&InverseStart>,
    ) -> Result<WurzelPoints> {
        check_finite_c("xi", &xi)?;
        check_finite_c("eta", &eta)?;
        if let Some(gr) = g_ref {
            check_finite_c("g_ref", &[gr])?;
        }
        if !rtol.is_finite() || rtol <= 0.0 {
            return Err(Error::InvalidArgument {
                what: "rtol",
                reason: format!("must be finite and positive, got {rtol}"),
            });
        }
        let sc = self.sqrt_c_checked(sqrt_c)?;
        let ct = self.c_tilde();
        let d = &self.d;
        // (37) is homogeneous in g: solve for the data scaled to max|·| = 1
        // (so that g² neither overflows nor underflows) and scale g back.
        let scale = xi
            .iter()
            .chain(eta.iter())
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        let x: [Complex64; 3] = std::array::from_fn(|i| xi[i] / scale / sc[i]);
        let yv: [Complex64; 3] = std::array::from_fn(|i| eta[i] / scale / sc[i]);

        let g2 = match start {
            Some(s) => s.g2 / (scale * scale),
            None => (0..3).map(|i| ct[i] * yv[i] * yv[i]).sum::<Complex64>() / d[4],
        };
        if scale == 0.0
            || g2 == Complex64::new(0.0, 0.0)
            || !(g2.re.is_finite() && g2.im.is_finite())
        {
            return Err(Error::InvalidArgument {
                what: "xi, eta",
                reason: "g^2 = sum_j c~_j (eta_j/sqrt c_j)^2 / d_4 vanishes (30a): \
                         no point pair has these Wurzelfunktionen"
                    .into(),
            });
        }
        let sum1 = (0..3).map(|i| ct[i] * x[i] * x[i]).sum::<Complex64>() / g2 + d[4];
        let sum2 = CYCLIC
            .iter()
            .enumerate()
            .map(|(i, &(j, _, _))| ct[i] * d[j] * x[i] * x[i])
            .sum::<Complex64>()
            / g2;
        let ((z1, z2), (zd1, zd2)) = match start {
            Some(s) => ((s.z[0], s.z[1]), (s.zd[0], s.zd[1])),
            None => {
                let (z1, z2) = quadratic_roots(sum1, sum2)?;
                ((z1, z2), (self.offsets(z1), self.offsets(z2)))
            }
        };

        let mut g = sqrt_principal(g2);
        if let Some(gr) = g_ref {
            if (gr.conj() * g).re < 0.0 {
                g = -g;
            }
        }
        let target: [Complex64; 6] = [x[0], x[1], x[2], yv[0], yv[1], yv[2]];
        let canonical_y = |zd: &[Complex64; 5]| {
            zd.iter()
                .fold(Complex64::new(1.0, 0.0), |acc, &v| acc * sqrt_principal(v))
        };
        let yc1 = canonical_y(&zd1);
        let yc2 = canonical_y(&zd2);
        let mut best = WurzelPoints {
            z1,
            y1: yc1,
            z2,
            y2: yc2,
            g,
            eps: [1; 5],
            residual: f64::INFINITY,
            zd1,
            zd2,
        };
        for s1 in [1.0, -1.0] {
            for s2 in [1.0, -1.0] {
                let (y1, y2) = (yc1 * s1, yc2 * s2);
                let r1 = self.roots_from_offsets(&zd1, y1);
                let r2 = self.roots_from_offsets(&zd2, y2);
                let w = wurzel_from_roots(&r1, &r2, z1 - z2, &[1.0; 5]);
                for bits in 0..8u8 {
                    let e = |b: u8| if bits & (1 << b) == 0 { 1.0 } else { -1.0 };
                    let eps = [e(0) * e(1) * e(2), e(0), e(1), e(2), 1.0];
                    let mut resid = 0.0f64;
                    for (i, &(j, k, l)) in CYCLIC.iter().enumerate() {
                        let pkl = g * eps[k] * eps[l] * w.pjk[k][l];
                        let pj4 = g * eps[j] * w.pjk[j][4];
                        resid = nan_max(resid, ((target[i] - pkl) * sc[i]).norm());
                        resid = nan_max(resid, ((target[i + 3] - pj4) * sc[i]).norm());
                    }
                    if resid < best.residual {
                        best = WurzelPoints {
                            z1,
                            y1,
                            z2,
                            y2,
                            g,
                            eps: eps.map(|v| v as i8),
                            residual: resid,
                            zd1,
                            zd2,
                        };
                    }
                }
            }
        }
        let mut b = self.refine(best, &target, &sc, lmap);
        b.g *= scale;
        b.residual *= scale;
        // A polish from a far start may end on the involution image of the
        // start's sheet, (−g, −y1, −y2), which has the same (ξ, η): the
        // documented sign of g (nearer g_ref) is restored.
        if let Some(gr) = g_ref {
            if (gr.conj() * b.g).re < 0.0 {
                b.g = -b.g;
                b.y1 = -b.y1;
                b.y2 = -b.y2;
            }
        }
        if (b.z1 - b.z2).norm() <= NEAR_DOUBLE_ROOT * b.z1.norm().max(b.z2.norm()) {
            // A discriminant that vanishes in exact arithmetic is ~1e-16 after
            // rounding, so z1 - z2 ~ 1e-8: the data sit at z1 == z2, and no
            // pair closer than NEAR_DOUBLE_ROOT can be resolved from them.
            Err(Error::InvalidArgument {
                what: "xi, eta",
                reason: format!(
                    "they give (nearly) z1 == z2 (|z1 - z2| = {:e} at z = {}): P_jk (28) is \
                     singular there and the two points cannot be resolved",
                    (b.z1 - b.z2).norm(),
                    b.z1,
                ),
            })
        } else if b.residual <= rtol * scale {
            Ok(b)
        } else {
            Err(Error::InvalidArgument {
                what: "xi, eta",
                reason: format!(
                    "no pair of points reproduces them: best residual {:e} > rtol {rtol:e} * \
                     max|(xi, eta)| {scale:e}; (xi, eta) are not on Koetter's quadrics (11) \
                     of this curve, or sqrt_c has another branch",
                    b.residual
                ),
            })
        }
    }
}

impl KotterCurve {
    /// Gauss–Newton polish of `(z1, z2, g)` for [`KotterCurve::points_from_xi_eta`].
    ///
    /// The closed form goes through `Σ c̃_j X_j²`, whose terms cancel heavily
    /// when the `P_kl` are nearly equal (points far out or close together) or
    /// when two branch points nearly coincide (`c̃_j ~ 1/(d_j − d_k)`); that
    /// costs up to ~1e3 over the conditioning of the map itself, and more for
    /// clustered branch points. Least-squares Newton steps on the six
    /// equations `X = g P_kl`, `Y = g P_j4` recover the intrinsic accuracy.
    ///
    /// Each point is parametrised by the local uniformizing parameter at its
    /// nearest branch point `d_b`: `w = r_b(z) = √(z − d_b)` (with its
    /// branch), `z = d_b + w²`. In `w` the map is holomorphic and regular
    /// through the branch point, whereas in `z` it has a square-root
    /// singularity there: a closed-form `z` whose error is comparable to its
    /// distance from `d_b` (a point 5e-11 from `d_1` when `d_1, d_2` are 3e-5
    /// apart) is outside the basin of Newton's method in `z`, not in `w`.
    /// The offsets are then `zd_j = w² + (d_b − d_j)`, accurate to a few ulps
    /// ([`CurvePoint`]). The other roots are continued holomorphically,
    /// `r_j(z + δ) = r_j(z) √(1 + δ/(z − d_j))`, so a step never crosses a
    /// cut of the principal roots; the final branch is expressed again as
    /// `eps` relative to the canonical roots.
    fn refine(
        &self,
        start: WurzelPoints,
        target: &[Complex64; 6],
        sc: &[Complex64; 3],
        lmap: Option<&[[Complex64; 3]; 4]>,
    ) -> WurzelPoints {
        let d = self.d;
        let zero = Complex64::new(0.0, 0.0);
        let nearest = |zd: &[Complex64; 5]| -> usize {
            (0..5).fold(0, |b, j| if zd[j].norm() < zd[b].norm() { j } else { b })
        };
        let (b1, b2) = (nearest(&start.zd1), nearest(&start.zd2));
        // d_b − d_j: exactly 0 at j = b, so zd_b = w² exactly.
        let dd1: [Complex64; 5] = std::array::from_fn(|j| d[b1] - d[j]);
        let dd2: [Complex64; 5] = std::array::from_fn(|j| d[b2] - d[j]);
        // The scale on which the map varies in w: the square root of the
        // distance from d_b to the next branch point.
        let wscale = |dd: &[Complex64; 5]| -> f64 {
            dd.iter()
                .filter(|v| v.norm() > 0.0)
                .map(|v| v.norm())
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        };
        let (ws1, ws2) = (wscale(&dd1), wscale(&dd2));
        let d12 = d[b1] - d[b2];
        let dz_of = |w1: Complex64, w2: Complex64| d12 + (w1 * w1 - w2 * w2);
        let eps_f = start.eps.map(f64::from);
        // The branch of the start, folded into the roots of the first point:
        // P_j = (eps_j r_j(z1)) r_j(z2).
        let mut r1 = self.roots_from_offsets(&start.zd1, start.y1);
        for j in 0..5 {
            r1[j] *= eps_f[j];
        }
        let mut r2 = self.roots_from_offsets(&start.zd2, start.y2);
        let mut g = start.g;
        let resid_of = |f: &[Complex64; 6]| -> f64 {
            (0..6)
                .map(|i| ((target[i] - f[i]) * sc[i % 3]).norm())
                .fold(0.0, nan_max)
        };
        // Newton works on relative residuals: (23) maps ξ, η to l with
        // coefficients α_j … δ_j that grow where ξ_j is small (one |d_j| of
        // 1e5 … 1e6 makes a component 100× smaller than the largest), so an
        // absolute fit left that component 1e-12 off relatively and the round
        // trip l → l 3e-12 off. A floor keeps an exactly vanishing one finite.
        let tmax = target.iter().fold(0.0f64, |m, v| m.max(v.norm()));
        let wt: [f64; 6] = std::array::from_fn(|i| 1.0 / target[i].norm().max(REL_FLOOR * tmax));
        // The rows the polish minimises: a residual (or Jacobian column) in the
        // P-space of the six targets, mapped to l-space by `lmap` (through
        // ξ = √c P), else weighted relatively.
        let rows = |v: &[Complex64; 6], in_l: bool| -> [Complex64; 6] {
            match lmap {
                Some([al, be, ga, de]) if in_l => std::array::from_fn(|q| {
                    let j = q % 3;
                    let (x, y) = (sc[j] * v[j], sc[j] * v[j + 3]);
                    if q < 3 {
                        al[j] * x + be[j] * y
                    } else {
                        ga[j] * x + de[j] * y
                    }
                }),
                _ => std::array::from_fn(|i| v[i] * wt[i]),
            }
        };
        let obj_of = |f: &[Complex64; 6], in_l: bool| -> f64 {
            let r: [Complex64; 6] = std::array::from_fn(|i| target[i] - f[i]);
            rows(&r, in_l).iter().map(|v| v.norm()).fold(0.0, nan_max)
        };
        let six = |r1: &[Complex64; 5], r2: &[Complex64; 5], g: Complex64| {
            let dz = dz_of(r1[b1], r2[b2]);
            let w = wurzel_from_roots(r1, r2, dz, &[1.0; 5]);
            let mut f = [zero; 6];
            for (i, &(j, k, l)) in CYCLIC.iter().enumerate() {
                f[i] = g * w.pjk[k][l];
                f[i + 3] = g * w.pjk[j][4];
            }
            f
        };
        // Move the point's parameter w = r[b] to w + dw: r_b = w + dw, the other
        // roots continued along t = w² → (w + dw)².
        let moved = |r: &[Complex64; 5], b: usize, dd: &[Complex64; 5], dw: Complex64| {
            let w = r[b];
            let dt = (2.0 * w + dw) * dw;
            let t = w * w;
            std::array::from_fn(|j| {
                if j == b {
                    w + dw
                } else {
                    r[j] * sqrt_principal(1.0 + dt / (t + dd[j]))
                }
            })
        };
        let mut f = six(&r1, &r2, g);
        let mut improved = false;
        // Two phases. First Levenberg–Marquardt, fitting each component
        // relative to its size (in the 2-norm), from the closed-form start,
        // which near the singular set h1² = 4h0² can be far off (the closed form
        // cancels by ~|d_4|/|z| there, and a point may sit between two branch
        // points that nearly coincide); skipped when the start is already within
        // LM_HANDOVER. Then Gauss–Newton to rounding, in the metric of (23) when
        // `lmap` is given (it moves the components `l` is least sensitive to; see
        // `points_from_xi_eta_fit`), else relative again (max-norm). The metric
        // of (23) is not used from a far start: its α_j … δ_j are large and nearly
        // dependent near the singular set, and the Gauss–Newton step ran off
        // along the wrong direction.
        #[derive(Clone, Copy, PartialEq)]
        enum Phase {
            Lm,
            Gn,
            GnL,
        }
        let last = if lmap.is_some() {
            (Phase::GnL, 6)
        } else {
            (Phase::Gn, 8)
        };
        for (phase, iterations) in [(Phase::Lm, 40), last] {
            let in_l = phase == Phase::GnL;
            let sq_of = |f: &[Complex64; 6]| -> f64 {
                let r: [Complex64; 6] = std::array::from_fn(|i| target[i] - f[i]);
                rows(&r, false).iter().map(|v| v.norm_sqr()).sum()
            };
            let cost = |f: &[Complex64; 6]| {
                if phase == Phase::Lm {
                    sq_of(f)
                } else {
                    obj_of(f, in_l)
                }
            };
            let mut obj = cost(&f);
            // a start already within reach of Gauss–Newton skips LM
            if phase == Phase::Lm && obj <= LM_HANDOVER * LM_HANDOVER {
                continue;
            }
            let mut mu = 1e-3;
            for _ in 0..iterations {
                if g == zero || dz_of(r1[b1], r2[b2]) == zero {
                    break;
                }
                let (h1, h2) = (1e-7 * ws1, 1e-7 * ws2);
                let mut jac = nalgebra::SMatrix::<Complex64, 6, 3>::zeros();
                let c = |x: f64| Complex64::new(x, 0.0);
                let fp1 = six(&moved(&r1, b1, &dd1, c(h1)), &r2, g);
                let fm1 = six(&moved(&r1, b1, &dd1, c(-h1)), &r2, g);
                let fp2 = six(&r1, &moved(&r2, b2, &dd2, c(h2)), g);
                let fm2 = six(&r1, &moved(&r2, b2, &dd2, c(-h2)), g);
                let mut rhs = nalgebra::SVector::<Complex64, 6>::zeros();
                let col0 = rows(
                    &std::array::from_fn(|i| (fp1[i] - fm1[i]) / (2.0 * h1)),
                    in_l,
                );
                let col1 = rows(
                    &std::array::from_fn(|i| (fp2[i] - fm2[i]) / (2.0 * h2)),
                    in_l,
                );
                let col2 = rows(&std::array::from_fn(|i| f[i] / g), in_l);
                let res = rows(&std::array::from_fn(|i| target[i] - f[i]), in_l);
                for i in 0..6 {
                    jac[(i, 0)] = col0[i];
                    jac[(i, 1)] = col1[i];
                    jac[(i, 2)] = col2[i];
                    rhs[i] = res[i];
                }
                // nalgebra's SVD never returns on a NaN entry and panics on an
                // infinite one (curves of scale 1e27 and beyond overflow here):
                // only finite systems are solved.
                let finite = |v: &Complex64| v.re.is_finite() && v.im.is_finite();
                if !(jac.iter().all(finite) && rhs.iter().all(finite)) {
                    break;
                }
                // Columns scaled to unit norm: the solve's cut-off 1e-14 is absolute
                // on the singular values, and the columns differ by the curve's
                // scale (|dP/dw| against |P/g|: 1e-20 against 1 at |d| ~ 1e4), so
                // unscaled a whole direction was dropped and the polish stalled.
                let mut colscale = [1.0f64; 3];
                for (cidx, cs) in colscale.iter_mut().enumerate() {
                    let nrm = jac.column(cidx).norm();
                    if nrm > 0.0 && nrm.is_finite() {
                        *cs = nrm;
                        for i in 0..6 {
                            jac[(i, cidx)] /= nrm;
                        }
                    }
                }
                let try_step = |step: &nalgebra::SVector<Complex64, 3>, lam: f64| {
                    let s: [Complex64; 3] = std::array::from_fn(|i| step[i] / colscale[i] * lam);
                    let nr1 = moved(&r1, b1, &dd1, s[0]);
                    let nr2 = moved(&r2, b2, &dd2, s[1]);
                    let ng = g + s[2];
                    let nf = six(&nr1, &nr2, ng);
                    (ng, nr1, nr2, nf, cost(&nf))
                };
                let mut accepted = None;
                if phase == Phase::Lm {
                    // (JᴴJ + μ I) δ = Jᴴ r on the unit-norm columns; μ grows
                    // until the step decreases the sum of squares, and shrinks
                    // after a success.
                    let jh = jac.adjoint();
                    let (a, b) = (jh * jac, jh * rhs);
                    for _ in 0..12 {
                        let m = a + nalgebra::Matrix3::<Complex64>::identity() * c(mu);
                        let Some(step) = m.lu().solve(&b) else {
                            mu *= 4.0;
                            continue;
                        };
                        let next = try_step(&step, 1.0);
                        if !next.4.is_nan() && next.4 < obj {
                            accepted = Some(next);
                            mu = (mu / 3.0).max(1e-15);
                            break;
                        }
                        mu *= 4.0;
                    }
                } else {
                    let Ok(step) = jac.svd(true, true).solve(&rhs, 1e-14) else {
                        break;
                    };
                    // The full step, else up to three halvings of it; none
                    // decreasing the objective ends the phase (converged to
                    // rounding, or stuck).
                    let mut lam = 1.0;
                    for _ in 0..4 {
                        let next = try_step(&step, lam);
                        if !next.4.is_nan() && next.4 < obj {
                            accepted = Some(next);
                            break;
                        }
                        lam *= 0.5;
                    }
                }
                let Some(next) = accepted else {
                    break;
                };
                (g, r1, r2, f, obj) = next;
                improved = true;
                // LM hands over to Gauss–Newton once the relative residuals are
                // at 1e-12: a step or two from rounding.
                if phase == Phase::Lm && obj <= LM_HANDOVER * LM_HANDOVER {
                    break;
                }
            }
        }
        if !improved {
            return start;
        }
        let resid = resid_of(&f);
        let (w1, w2) = (r1[b1], r2[b2]);
        let zd1: [Complex64; 5] = std::array::from_fn(|j| w1 * w1 + dd1[j]);
        let zd2: [Complex64; 5] = std::array::from_fn(|j| w2 * w2 + dd2[j]);
        let (z1, z2) = (d[b1] + w1 * w1, d[b2] + w2 * w2);
        // Express the continued roots as (y_i, eps) relative to the canonical roots.
        // Π_j eps_j = +1, so the product of the branch-folded roots is y1.
        let y1: Complex64 = r1.iter().product();
        let y2: Complex64 = r2.iter().product();
        let c1 = self.roots_from_offsets(&zd1, y1);
        let c2 = self.roots_from_offsets(&zd2, y2);
        // The sign of each continued root relative to the canonical one (a
        // root at a branch point is 0 on both: its sign is immaterial).
        let sign = |r: Complex64, c: Complex64| -> i8 {
            if c == zero || (r / c).re >= 0.0 {
                1
            } else {
                -1
            }
        };
        let mut eps: [i8; 5] = std::array::from_fn(|j| sign(r1[j], c1[j]) * sign(r2[j], c2[j]));
        if eps.iter().map(|&e| i32::from(e)).product::<i32>() < 0 {
            // Only possible with a root exactly 0: flip the sign of the P_j
            // nearest zero, the one the data determine least.
            let j = (0..5).fold(0, |m, j| {
                if (c1[j] * c2[j]).norm() < (c1[m] * c2[m]).norm() {
                    j
                } else {
                    m
                }
            });
            eps[j] = -eps[j];
        }
        if eps[4] < 0 {
            eps = eps.map(|e| -e);
            eps[0] = -eps[0];
        }
        WurzelPoints {
            z1,
            y1,
            z2,
            y2,
            g,
            eps,
            residual: resid,
            zd1,
            zd2,
        }
    }
}

/// (37) from the Wurzelfunktionen: `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`.
fn xi_eta_of(w: &Wurzel, sc: &[Complex64; 3], g: Complex64) -> ([Complex64; 3], [Complex64; 3]) {
    let mut xi = [Complex64::new(0.0, 0.0); 3];
    let mut eta = xi;
    for (i, &(j, k, l)) in CYCLIC.iter().enumerate() {
        xi[i] = sc[i] * g * w.pjk[k][l];
        eta[i] = sc[i] * g * w.pjk[j][4];
    }
    (xi, eta)
}

/// `max` that propagates NaN (`f64::max` drops it), so that a NaN anywhere in
/// a residual makes the residual NaN and the check fail.
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Checks a branch vector: entries `±1`, product `+1`.
fn check_eps(e: [i8; 5]) -> Result<[f64; 5]> {
    if e.iter().any(|&v| v != 1 && v != -1) {
        return Err(Error::InvalidArgument {
            what: "eps",
            reason: format!("entries must be +1 or -1, got {e:?}"),
        });
    }
    if e.iter().map(|&v| v as i32).product::<i32>() != 1 {
        return Err(Error::InvalidArgument {
            what: "eps",
            reason: format!(
                "the product of the signs must be +1 (so that P_0 ... P_4 = y1 y2), got {e:?}"
            ),
        });
    }
    Ok(e.map(f64::from))
}

/// The roots of `x² − s x + p`, the one of larger modulus first, computed
/// without cancellation (`z1 = (s ± √(s² − 4p))/2` with the sign that adds
/// moduli, `z2 = p/z1`).
fn quadratic_roots(s: Complex64, p: Complex64) -> Result<(Complex64, Complex64)> {
    let sq = sqrt_principal(s * s - 4.0 * p);
    let q = if (s.conj() * sq).re >= 0.0 {
        s + sq
    } else {
        s - sq
    };
    let z1 = q / 2.0;
    // A double root: the two points have the same z (|q| ≥ |sq| makes q = 0 imply sq = 0).
    if sq.norm() <= 4.0 * f64::EPSILON * z1.norm() || z1 == Complex64::new(0.0, 0.0) {
        return Err(Error::InvalidArgument {
            what: "xi, eta",
            reason: format!(
                "they give z1 == z2 == {z1} (a double root of x^2 - (z1+z2) x + z1 z2): \
                 P_jk (28) is undefined there"
            ),
        });
    }
    Ok((z1, p / z1))
}

/// `(A − B)/(z1 − z2)` for one factor of (28), `A − B = ±(r1 − r2)` with
/// `r_i² = z_i − d_j`: telescoped, `(r1 − r2)/(z1 − z2) = 1/(r1 + r2)`, when
/// the two roots lie on the same side (`|r1 + r2| ≥ |r1 − r2|`: no
/// cancellation, and finite at `z1 = z2`); the plain quotient otherwise
/// (then `r1 − r2` does not cancel).
fn factor_quotient(r1: Complex64, r2: Complex64, dz: Complex64) -> Complex64 {
    let sum = r1 + r2;
    // |r1 + r2| ≥ |r1 − r2| ⇔ Re(r1 conj r2) ≥ 0 (no modulus: libm's hypot was
    // the largest cost of the inverse map)
    if (r1 * r2.conj()).re >= 0.0 && sum != Complex64::new(0.0, 0.0) {
        cdiv(Complex64::new(1.0, 0.0), sum)
    } else {
        cdiv(r1 - r2, dz)
    }
}

/// (27)–(28) from the canonical roots of the two points, in the branch `eps`.
///
/// `P_jk = eps_j eps_k (a − b)/(z1 − z2)` with `a = Π_i A_i`, `b = Π_i B_i`,
/// `A = (r_j(z2), r_k(z2), r_m(z1) …)`, `B = (r_j(z1), r_k(z1), r_m(z2) …)`
/// (`m ∉ {j, k}`), is evaluated as the telescoped sum
/// `Σ_i A_1 … A_{i−1} · (A_i − B_i)/(z1 − z2) · B_{i+1} … B_5`, each quotient
/// by [`factor_quotient`]: for two points on one sheet with `z1 ≈ z2` the
/// difference `a − b` loses `u/|z1 − z2|`, the telescoped form does not, and
/// at `z1 = z2` (same `y`) it is the tangent limit (`dz` is not used then).
fn wurzel_from_roots(
    r1: &[Complex64; 5],
    r2: &[Complex64; 5],
    dz: Complex64,
    eps: &[f64; 5],
) -> Wurzel {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    let p: [Complex64; 5] = std::array::from_fn(|j| eps[j] * r1[j] * r2[j]);
    let mut pjk = [[zero; 5]; 5];
    for j in 0..5 {
        for k in (j + 1)..5 {
            // factors in the order j, k, then the complement
            let mut idx = [j, k, 0, 0, 0];
            for (n, m) in (2..).zip((0..5).filter(|&m| m != j && m != k)) {
                idx[n] = m;
            }
            let fa: [Complex64; 5] =
                std::array::from_fn(|i| if i < 2 { r2[idx[i]] } else { r1[idx[i]] });
            let fb: [Complex64; 5] =
                std::array::from_fn(|i| if i < 2 { r1[idx[i]] } else { r2[idx[i]] });
            // (A_i − B_i)/(z1 − z2): for i < 2, A − B = r2 − r1 = −(r1 − r2)
            let q: [Complex64; 5] = std::array::from_fn(|i| {
                let m = idx[i];
                let v = factor_quotient(r1[m], r2[m], dz);
                if i < 2 {
                    -v
                } else {
                    v
                }
            });
            let mut suffix = [one; 6];
            for i in (0..5).rev() {
                suffix[i] = suffix[i + 1] * fb[i];
            }
            let mut prefix = one;
            let mut sum = zero;
            let mut size_t = 0.0;
            for i in 0..5 {
                let term = prefix * q[i] * suffix[i + 1];
                sum += term;
                size_t += term.re.abs() + term.im.abs();
                prefix *= fa[i];
            }
            // The plain difference (a − b)/(z1 − z2) rounds to u (|a| + |b|)/|z1 − z2|,
            // the telescoped sum to u Σ|terms|: take the one with the smaller bound
            // (far-apart points: the plain form, whose terms do not cancel).
            let (a, b) = (prefix, suffix[0]);
            // both bounds from above without a modulus (1-norm over ∞-norm, each
            // within √2 of the modulus): hypot was the largest cost here
            let l1 = |z: Complex64| z.re.abs() + z.im.abs();
            let size_p = (l1(a) + l1(b)) / dz.re.abs().max(dz.im.abs());
            let val = if dz != zero && size_p.is_finite() && size_p < size_t {
                cdiv(a - b, dz)
            } else {
                sum
            };
            let v = eps[j] * eps[k] * val;
            pjk[j][k] = v;
            pjk[k][j] = v;
        }
    }
    Wurzel { p, pjk }
}

#[cfg(test)]
mod tests;
