//! Hyperelliptic curves `y² = R(x) = Π_{k=1}^{n} (x − e_k)` with complex
//! branch points: a canonical homology basis, the period matrices, `τ`, the
//! Abel–Jacobi map, the vector of Riemann constants, the half-period
//! characteristics of the branch points and (genus 2, `n = 5`) Jacobi
//! inversion. Method and conventions: docs/riemann.md.
//!
//! # Conventions
//!
//! * `n = 2g + 1` or `2g + 2` finite branch points `e_1 … e_n` (0-based
//!   index `k` means `e_{k+1}`); for odd `n`, `∞` is a branch point too.
//! * Sheets: `y(x, +1) = Π_k √(x − e_k)` (principal roots, the canonical sheet
//!   of `crate::curve`), `y(x, −1) = −y(x, +1)`. A point is `(x, y)` with
//!   `y² = R(x)`; its `y` fixes the sheet.
//! * Differentials `ω_i = x^{i−1} dx / y`, `i = 1..g`; periods
//!   `A_ij = ∮_{a_j} ω_i`, `B_ij = ∮_{b_j} ω_i`, `τ = A^{-1} B` (symmetric,
//!   `Im τ > 0`) for a canonical basis, `a_i · b_j = δ_ij`.
//! * Abel map `u(P) = A^{-1} ∫_{P_0}^{P} ω` with `P_0 = ∞` for odd `n` and
//!   `P_0 = e_1` (index 0) for even `n`; defined modulo the lattice
//!   `Z^g + τ Z^g`.
//! * Characteristics follow `crate::theta`: `[a; b] ∈ {0,1}^g × {0,1}^g` is the
//!   half period `(b + τ a)/2`, and `θ(z + (b + τa)/2)` is a nonzero multiple of
//!   `θ[a;b](z)`.
//!
//! # Method
//!
//! Molin & Neurohr, *Computing period matrices and the Abel–Jacobi map of
//! superelliptic curves*, Math. Comp. 88 (2019) 847–888 (arXiv:1707.07249),
//! specialised to square roots: a spanning tree of straight segments between
//! branch points ([`basis::spanning_tree`]), the loop around each tree edge as
//! a cycle, its period by Gauss–Chebyshev quadrature, the intersection
//! numbers of the loops from the local picture at the shared branch point,
//! and a symplectic reduction to a canonical basis. Abel integrals run along
//! straight segments from a branch point (`x = e + (x − e)σ²`) or along a ray
//! from infinity (`x = c + (x − c)/τ²`), with composite Gauss–Legendre
//! quadrature ([`quad`]).

//!
//! # Scale
//!
//! The curve has no preferred scale: `x = λ ξ`, `y = λ^{n/2} η` maps it to
//! `η² = Π (ξ − e_k/λ)`, the differentials `x^{i−1} dx/y = λ^{i − n/2} ξ^{i−1} dξ/η`
//! scale row by row, so `τ = A^{-1}B` and the normalised Abel map are the same.
//! A curve with some `|e_k| > MAX_ABS_BRANCH_POINT` (`R(x)` would leave the
//! double range; near a pinched level set of the top the branch points spread
//! over 30 and more orders of magnitude) is built with `λ = 2^k`, `k` even and
//! `max |e_k| / λ` of order 1: a power of two scales every operation exactly,
//! so the internal computation is that of the scaled curve to the bit, and
//! points and periods are converted at the public methods (`x`, `dx` by `λ`,
//! `y` by `λ^{n/2}`, period rows by `λ^{i − n/2}`). Curves within the bound are
//! built as given (`k = 0`).

// Index loops over g ≤ 6 coordinates mirror the formulas.
#![allow(clippy::needless_range_loop)]

pub mod basis;
pub mod quad;

mod abel;
mod constant;
mod invert;
mod many;
mod periods;
mod periods_dd;

pub use invert::INVERT_MAX_RESIDUAL;
pub use many::AbelRoute;

#[cfg(test)]
mod tests;

use std::sync::OnceLock;

use nalgebra::DMatrix;
use num_complex::Complex64;

use crate::error::{Error, Result};
use crate::numeric::complex::sqrt_principal;
use crate::numeric::complex::Modulus;
use crate::theta::ThetaPlan;
use quad::{focal_half_sum_sqrt, nodes_for, Piece, SegmentSqrt, SqrtProduct};

type C = Complex64;

/// Largest genus accepted (the theta layer's limit).
pub const MAX_GENUS: usize = crate::theta::MAX_GENUS;

/// Most finite branch points (`2 MAX_GENUS + 2`): the size of the per-point
/// stack buffers.
const MAX_N: usize = 2 * MAX_GENUS + 2;

/// One unnormalised or normalised Abel vector on the stack (first `g` entries).
type Row = [C; MAX_GENUS];

const ZERO_ROW: Row = [C::new(0.0, 0.0); MAX_GENUS];

/// Largest `|e_k|` handled in the coordinate `x` as given: `R(x)` for `|x|` of
/// that size and `n ≤ 14` stays far below the double range
/// (`(1e20)^14 = 1e280`). Curves with larger branch points are built in the
/// coordinate `x / 2^k` (module docs, "Scale").
pub const MAX_ABS_BRANCH_POINT: f64 = 1e20;

/// The exponent `k n / 2` of the factor `2^{k n/2}` that carries `y` between
/// the user's coordinate and the curve's internal one must stay in the double
/// range: `|e_k|` up to `2^(2 MAX_Y_SCALE_EXP / n)` (`≈ 1e120` for `n = 5`).
const MAX_Y_SCALE_EXP: i32 = 1000;

/// Relative tolerance of "the point is on the curve": `|y² − R(x)| ≤
/// ON_CURVE_RTOL · Π_k (|x| + |e_k|)`, the right-hand scale being that of the
/// rounding errors of `R(x)` evaluated from its expanded coefficients. Loose
/// enough for points computed elsewhere, tight enough to catch a wrong `y`.
pub const ON_CURVE_RTOL: f64 = 1e-8;

/// Largest distance of `2·β` (the lattice coordinates of a half period) from
/// integers accepted when a characteristic is read off: the half periods are
/// computed to ~1e-14, a wrong identification would be off by O(1).
const CHAR_TOL: f64 = 1e-6;

/// `u` is on the theta divisor when `|θ(u + K)| ≤ THETA_DIVISOR_RTOL ·
/// max_χ |θ[χ](u + K)|`: then the divisor `z1 + z2` is special (contains `∞`
/// or a pair `P + ιP`) and inversion is not unique. Values closer than this
/// lose digits like `1/|θ|` in the quotient start; Newton still needs a
/// well-separated, non-special divisor.
pub const THETA_DIVISOR_RTOL: f64 = 1e-8;

/// A hyperelliptic curve `y² = Π (x − e_k)` with its canonical homology basis,
/// periods and Abel map (module docs for the conventions).
#[derive(Debug, Clone)]
pub struct HyperellipticCurve {
    /// The branch points in the internal coordinate `x / 2^k` (module docs,
    /// "Scale"); everything below is in that coordinate unless named `_user`.
    e: Vec<C>,
    /// The branch points as given.
    e_user: Vec<C>,
    /// `k` of the internal coordinate `x / 2^k` (even; 0 unless some
    /// `|e_k| > MAX_ABS_BRANCH_POINT`).
    scale_exp: i32,
    /// `(A, B)` of the user's coordinate: row `i` of the internal periods times
    /// `2^{k(i + 1 − n/2)}` (`x^i dx/y` scales by `λ^{i + 1 − n/2}`, `λ = 2^k`).
    a_user: DMatrix<C>,
    b_user: DMatrix<C>,
    g: usize,
    center: C,
    radius: f64,
    tree: Vec<(usize, usize)>,
    cycle_edges: Vec<usize>,
    edge_periods: Vec<Vec<C>>,
    intersection: Vec<Vec<i64>>,
    symplectic: Vec<Vec<i64>>,
    a: DMatrix<C>,
    b: DMatrix<C>,
    a_inv: DMatrix<C>,
    tau: DMatrix<C>,
    tau_flat: Vec<C>,
    im_tau_inv: DMatrix<f64>,
    /// `∫_{P0}^{e_k} ω` (unnormalised), along tree paths.
    u_branch: Vec<Vec<C>>,
    /// Even `n`: `∫_{P0}^{∞+} ω` (unnormalised), `∞±` where `y/x^{g+1} → ±1`.
    u_inf: Vec<C>,
    /// `|e_k|`, `|e_k − e_m|` (row-major `n × n`) and `|e_k − center|`: the
    /// per-point route choice and point check need only distances to `x`.
    e_abs: Vec<f64>,
    e_dist: Vec<f64>,
    c_dist: Vec<f64>,
    derived: OnceLock<std::result::Result<Derived, Error>>,
}

/// The calibration of the Jacobi inversion start: per branch point `j`,
/// `(c_j, num, den)` or `None` ([`Derived`]'s `calib`).
type Calibration = Vec<Option<(C, usize, usize)>>;

/// Theta plan, Riemann constant and inversion calibration (built on first use).
#[derive(Debug, Clone)]
struct Derived {
    plan: ThetaPlan,
    k_char: (Vec<u8>, Vec<u8>),
    k: Vec<C>,
    /// For the inversion start (g = 2): `(c_j, num, den)` with
    /// `f_j(D) = c_j (θ[num](v)/θ[den](v))²`, `v = u(D) + K`, where
    /// `f_j = (x1−e_j)(x2−e_j)` for odd `n` (then `num = η(e_j)`, `den = 0`, (34))
    /// and `f_j = (x1−e_j)(x2−e_j)/((x1−e_1)(x2−e_1))`, `j ≥ 1`, for even `n`
    /// (characteristics found numerically). `None` where none was found.
    calib: OnceLock<std::result::Result<Calibration, Error>>,
}

fn is_finite_c(v: C) -> bool {
    v.re.is_finite() && v.im.is_finite()
}

/// Which route an Abel integral takes.
#[derive(Debug, Clone, Copy)]
enum Route {
    Branch(usize),
    Infinity,
}

impl HyperellipticCurve {
    /// The genus `g`.
    pub fn genus(&self) -> usize {
        self.g
    }

    /// The finite branch points `e_1 … e_n` as given.
    pub fn branch_points(&self) -> &[C] {
        &self.e_user
    }

    /// The spread of the branch points: `max_k |e_k| / min_{i<j} |e_i − e_j|`,
    /// the ratio of the curve's largest scale to its smallest. Periods
    /// computed in double are accurate to ~ε relative to the largest period,
    /// so the periods of the smallest cycles, and what is solved from all of
    /// them together, lose up to this factor.
    pub fn spread(&self) -> f64 {
        let e = &self.e_user;
        let big = e.iter().fold(0.0f64, |m, z| m.max(z.norm()));
        let mut sep = f64::INFINITY;
        for i in 0..e.len() {
            for j in (i + 1)..e.len() {
                sep = sep.min((e[i] - e[j]).norm());
            }
        }
        big / sep
    }

    /// `x` (or an offset `dx`) in the internal coordinate `x / 2^k`.
    #[inline]
    fn x_in(&self, x: C) -> C {
        if self.scale_exp == 0 {
            x
        } else {
            x * 2f64.powi(-self.scale_exp)
        }
    }

    /// `y` in the internal coordinate `y / 2^{k n/2}`.
    #[inline]
    fn y_in(&self, y: C) -> C {
        if self.scale_exp == 0 {
            y
        } else {
            y * 2f64.powi(-self.scale_exp * self.e.len() as i32 / 2)
        }
    }

    /// An internal point `(x, y)` in the user's coordinate.
    #[inline]
    fn point_out(&self, x: C, y: C) -> (C, C) {
        if self.scale_exp == 0 {
            (x, y)
        } else {
            (
                x * 2f64.powi(self.scale_exp),
                y * 2f64.powi(self.scale_exp * self.e.len() as i32 / 2),
            )
        }
    }

    /// The factor `λ^{i + 1 − n/2}` of row `i` of the periods (user over internal).
    fn period_row_scale(&self, i: usize) -> f64 {
        if self.scale_exp == 0 {
            1.0
        } else {
            let twice = self.scale_exp * (2 * (i as i32 + 1) - self.e.len() as i32);
            2f64.powi(twice / 2)
        }
    }

    /// Whether `∞` is a branch point (odd `n`); then `P0 = ∞`, else `P0 = e_1`.
    pub fn infinity_is_branch_point(&self) -> bool {
        self.e.len() % 2 == 1
    }

    /// `R(x) = Π (x − e_k)`.
    pub fn r(&self, x: C) -> C {
        self.e_user.iter().map(|&ek| x - ek).product()
    }

    /// `y` on sheet `sheet = ±1`: `sheet · Π_k √(x − e_k)` with principal
    /// roots (`sheet = +1` is the canonical sheet of `crate::curve`). Any
    /// `sheet ≤ 0` means `−1`.
    pub fn y(&self, x: C, sheet: i8) -> C {
        let y: C = self
            .e_user
            .iter()
            .map(|&ek| sqrt_principal(x - ek))
            .product();
        if sheet > 0 {
            y
        } else {
            -y
        }
    }

    /// [`Self::y`] in the internal coordinate.
    fn y_int(&self, x: C, sheet: i8) -> C {
        let y: C = self.e.iter().map(|&ek| sqrt_principal(x - ek)).product();
        if sheet > 0 {
            y
        } else {
            -y
        }
    }

    /// `(A, B)`: `A_ij = ∮_{a_j} ω_i`, `B_ij = ∮_{b_j} ω_i`, `ω_i = x^{i−1} dx/y`.
    pub fn periods(&self) -> (&DMatrix<C>, &DMatrix<C>) {
        (&self.a_user, &self.b_user)
    }

    /// `τ = A^{-1} B` (symmetrised; `Im τ` positive definite).
    pub fn tau(&self) -> &DMatrix<C> {
        &self.tau
    }

    /// `τ` row-major, as `crate::theta` takes it.
    pub fn tau_row_major(&self) -> &[C] {
        &self.tau_flat
    }

    /// The tree edges `(p, q)` (0-based branch point indices) whose loops are
    /// the cycles `c_1 … c_{2g}`.
    pub fn cycle_edges(&self) -> Vec<(usize, usize)> {
        self.cycle_edges.iter().map(|&i| self.tree[i]).collect()
    }

    /// All edges of the spanning tree (for even `n` one more than the cycles).
    pub fn tree(&self) -> &[(usize, usize)] {
        &self.tree
    }

    /// Intersection numbers `c_i · c_j` of the tree loops (from the geometry).
    pub fn intersection_matrix(&self) -> &[Vec<i64>] {
        &self.intersection
    }

    /// `M` with `(a_1..a_g, b_1..b_g) = M (c_1..c_{2g})`, `M C Mᵀ = J`.
    pub fn symplectic_basis(&self) -> &[Vec<i64>] {
        &self.symplectic
    }

    /// The periods `∮_{c_j} ω_i` of the tree loops (column `j`), `g × 2g`.
    pub fn cycle_periods(&self) -> DMatrix<C> {
        let g = self.g;
        DMatrix::from_fn(g, 2 * g, |i, j| {
            self.edge_periods[self.cycle_edges[j]][i] * self.period_row_scale(i)
        })
    }
}
