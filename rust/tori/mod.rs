//! Real Liouville tori of the Manakov top: the lattice of periods of `l(u)`,
//! the real torus that carries a motion, its frequencies, and frequency maps.
//!
//! By the Theorem (9)–(10), `l` is a rational function of the quotients
//! `P_L = C_L θ[χ_L](v)/θ(v)` (`v = u + K`) for the seven labels
//! `L ∈ {0, 23, 31, 12, 14, 24, 34}`, and `u = u0 + U t` moves on a straight
//! line in `C²`. With the package's theta convention (README),
//! `θ[a;b](v + m + τn) = (−1)^{a·m + b·n} e(v, n) θ[a;b](v)` with a factor
//! `e(v, n) = exp(−iπ nᵀτn − 2πi nᵀv)` common to all characteristics, so the
//! quotient `θ[a;b]/θ[0;0]` picks up the sign `(−1)^{a·m + b·n}`. Hence
//! `λ = m + τn` is a period of `l` iff `a_L·m + b_L·n ≡ 0 (mod 2)` for every
//! characteristic `χ_L = [a_L; b_L]` that enters `l` (sufficiency is the sign
//! rule; necessity is in docs/tori.md). These `λ` form the lattice `Λ'`,
//! `2Λ ⊂ Λ' ⊂ Λ = Z² + τZ²`.
//!
//! The real torus through `u0` is the closure of `u0 + U t` modulo `Λ'`. Its
//! real tangent plane `P` is spanned (over R) by `U` and the velocity `U'` of
//! a second commuting flow of the Manakov family. `Λ' ∩ P` is a lattice of
//! rank 2; [`real_torus`] finds it exactly (the integer kernel of the
//! projection of `Λ'` onto the complement of `P`), reduces it, and writes
//! `U = ν1 λ1 + ν2 λ2`.
//!
//! **Basis convention** (intrinsic, so that maps are continuous wherever the
//! torus family is): Lagrange–Gauss reduction in the polarisation metric
//! `‖z‖² = z^H (Im τ)^{-1} z`, which is invariant under symplectic changes of
//! the homology basis; `‖λ1‖ ≤ ‖λ2‖`, `|⟨λ1, λ2⟩| ≤ ‖λ1‖²/2`; the signs of
//! `λ1`, `λ2` are chosen so that `ν1 ≥ 0`, `ν2 ≥ 0`.
//!
//! Next to an so(3) block, where the pinched curve defeats the genus-2
//! route, and next to the self-dual states, where `F` (19) is not defined,
//! [`near_euler`] interpolates the frequencies between the Euler orbit and
//! the tori of states farther out; next to a transversally hyperbolic block
//! orbit [`near_hyperbolic`] fits them in `ln(1/σ)` with the orbit's own
//! exponent; next to a coordinate plane of equilibria [`near_plane`] takes
//! them from the equilibrium's linearization; where every one of these
//! refuses, [`closed_orbits`] finds the lattice of the two commuting flows'
//! periods by integration in double-double.
//!
//! [`map_states`] runs a per-state function over a batch in parallel (rayon),
//! in waves between which the caller's [`Cancel`] is checked; the results do
//! not depend on the number of threads or on how the batch is split.

pub mod closed_orbits;
pub mod motion;
pub mod near_euler;
pub mod near_hyperbolic;
pub mod near_plane;
pub mod solve;
#[cfg(test)]
mod tests;

use std::fmt;

use num_complex::Complex64;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;
use crate::so4;

/// A point of `C²`.
pub type C2 = [Complex64; 2];
/// A 2×2 period matrix, `tau[i][j] = τ_ij`.
pub type Tau = [[Complex64; 2]; 2];
/// A half-integer characteristic `[a1 a2; b1 b2]` as the bits `(a1, a2, b1, b2)`
/// (the package's theta order: index = bits a1 a2 b1 b2).
pub type Char = [u8; 4];
/// Integer coordinates `(m1, m2, n1, n2)` of the lattice point `λ = m + τ n`.
pub type Coords = [i64; 4];

/// The largest denominator accepted in the kernel of the projection of `Λ`
/// onto the complement of the real plane. The kernel's entries are rationals
/// whose denominators divide small minors of the integer matrix of the real
/// structure in the homology basis (entries 0, ±1, ±2 for the bases the
/// Riemann-surface layer builds); 64 leaves a wide margin and keeps the
/// enumeration over `[0, 2D)²` below 2¹⁴ points.
pub const MAX_DENOMINATOR: i64 = 64;

/// Tolerance for recognising the kernel entries as rationals `p/D`. `U`, `U'`
/// carry the solution's relative error (~1e-12); the entries are ratios of
/// 2×2 minors of O(1) size, so their error is ~1e-11. 1e-7 is far above that
/// and far below the spacing 1/D² ≥ 2.4e-4 between distinct candidates.
pub const RATIONAL_TOL: f64 = 1e-7;

/// Below this sine of the angle between `U` and `U'` (in the polarisation
/// metric) the two flows do not span a plane within the solution's accuracy.
pub const PLANE_TOL: f64 = 1e-8;

/// Largest accepted distance of `U` from the plane of the reduced basis,
/// relative to `‖U‖` (the plane contains `U` by construction; a failure means
/// non-finite or inconsistent input).
pub const RESIDUAL_TOL: f64 = 1e-9;

pub use crate::error::TorusFailure;

impl fmt::Display for TorusFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TorusFailure::NonFinite => write!(f, "tau, U or U' is not finite"),
            TorusFailure::ImagTauNotPositive => write!(f, "Im tau is not positive definite"),
            TorusFailure::DegeneratePlane { sin_angle } => write!(
                f,
                "the two flows do not span a real plane (sin of their angle {sin_angle:e})"
            ),
            TorusFailure::NoRealLattice { residual } => write!(
                f,
                "the lattice of periods meets the real plane of the flows in no rank-2 lattice \
                 (kernel not rational: residual {residual:e} at denominators <= {MAX_DENOMINATOR})"
            ),
        }
    }
}

impl From<TorusFailure> for Error {
    fn from(failure: TorusFailure) -> Error {
        Error::NoRealTorus { failure }
    }
}

/// The real torus carrying a motion and its frequencies.
#[derive(Debug, Clone, PartialEq)]
pub struct RealTorus {
    /// The reduced basis `λ1, λ2` of `Λ' ∩ P` as points of `C²`.
    pub lambda: [C2; 2],
    /// Their integer coordinates `(m1, m2, n1, n2)`, `λ = m + τ n`.
    pub coords: [Coords; 2],
    /// `(ν1, ν2)`, `U = ν1 λ1 + ν2 λ2` (cycles per unit time).
    pub nu: [f64; 2],
}

/// The lattice point `m + τ n` of coordinates `x = (m1, m2, n1, n2)`.
pub fn lattice_point(tau: &Tau, x: &Coords) -> C2 {
    let (m1, m2, n1, n2) = (x[0] as f64, x[1] as f64, x[2] as f64, x[3] as f64);
    [
        tau[0][0] * n1 + tau[0][1] * n2 + m1,
        tau[1][0] * n1 + tau[1][1] * n2 + m2,
    ]
}

/// The sign `(−1)^{a·m + b·n}` that `θ[a;b](v)/θ[0;0](v)` picks up under
/// `v → v + m + τ n`, as `+1` or `−1`.
pub fn quotient_sign(chi: &Char, x: &Coords) -> i32 {
    let s = (chi[0] as i64) * x[0]
        + (chi[1] as i64) * x[1]
        + (chi[2] as i64) * x[2]
        + (chi[3] as i64) * x[3];
    if s.rem_euclid(2) == 0 {
        1
    } else {
        -1
    }
}

/// Whether `m + τ n` is a period of every quotient `θ[χ]/θ`, `χ ∈ chars`.
pub fn is_period(chars: &[Char], x: &Coords) -> bool {
    chars.iter().all(|c| quotient_sign(c, x) == 1)
}

/// The classes of `Λ'` modulo `2Λ`: the residues `r ∈ {0,1}⁴` with
/// `a·r_m + b·r_n ≡ 0 (mod 2)` for every `χ = [a;b]` in `chars`.
pub fn period_residues(chars: &[Char]) -> Vec<[u8; 4]> {
    (0u8..16)
        .map(|k| [(k >> 3) & 1, (k >> 2) & 1, (k >> 1) & 1, k & 1])
        .filter(|r| is_period(chars, &r.map(|v| v as i64)))
        .collect()
}

/// `(Re z1, Re z2, Im z1, Im z2)`.
fn real4(z: &C2) -> [f64; 4] {
    [z[0].re, z[1].re, z[0].im, z[1].im]
}

/// The polarisation metric `Re(z^H (Im τ)^{-1} w)` on `R⁴ = C²`, i.e.
/// `blockdiag(H, H)` with `H = (Im τ)^{-1}` in the coordinates of [`real4`].
struct Metric {
    h: [[f64; 2]; 2],
}

impl Metric {
    fn new(tau: &Tau) -> Option<Metric> {
        let (p, q, r) = (
            tau[0][0].im,
            0.5 * (tau[0][1].im + tau[1][0].im),
            tau[1][1].im,
        );
        let det = p * r - q * q;
        if !(p > 0.0 && det > 0.0) {
            return None;
        }
        Some(Metric {
            h: [[r / det, -q / det], [-q / det, p / det]],
        })
    }

    fn dot(&self, x: &[f64; 4], y: &[f64; 4]) -> f64 {
        let h = &self.h;
        let half = |a: f64, b: f64, c: f64, d: f64| {
            a * (h[0][0] * c + h[0][1] * d) + b * (h[1][0] * c + h[1][1] * d)
        };
        half(x[0], x[1], y[0], y[1]) + half(x[2], x[3], y[2], y[3])
    }

    fn norm2(&self, x: &[f64; 4]) -> f64 {
        self.dot(x, x)
    }
}

fn axpy(a: f64, x: &[f64; 4], y: &[f64; 4]) -> [f64; 4] {
    std::array::from_fn(|k| y[k] + a * x[k])
}

/// `y − Σ ⟨e_i, y⟩ e_i` over orthonormal `es`.
fn reject(g: &Metric, es: &[[f64; 4]], y: &[f64; 4]) -> [f64; 4] {
    es.iter().fold(*y, |acc, e| axpy(-g.dot(e, &acc), e, &acc))
}

/// The real torus of the motion `u0 + U t` on `C²/Λ'`.
///
/// `tau` is the period matrix, `u` the velocity `U` of the motion, `u2` the
/// velocity `U'` of a second commuting flow on the same level set, and
/// `chars` the characteristics `χ_L` of the quotients that enter `l`. See the
/// module documentation for the method and the basis convention.
pub fn real_torus(
    tau: &Tau,
    u: &C2,
    u2: &C2,
    chars: &[Char],
) -> std::result::Result<RealTorus, TorusFailure> {
    real_torus_with_rates(tau, u, u2, chars, None)
}

/// [`real_torus`] with the lattice coordinates `w = (X1, X2, Y1, Y2)` of `U`
/// (`U = X + τY`) where they are known more accurately than `U` and `τ`
/// (the closed form's lattice rates, [`crate::solution::dubrovin`]): the
/// lattice basis is found from `U`, `U'` and `τ` as there, and `ν` from
/// `w = ν1 c1 + ν2 c2` in the integer coordinates `c1`, `c2` of `λ1`, `λ2`,
/// with no rounding of `τ` in it. Near pinched curves (branch points spread
/// over 1e16, `τ` with entries of very different sizes) the metric's normal
/// equations in `C²` lose up to 1e-11 of `ν` that `w` carries.
pub fn real_torus_with_rates(
    tau: &Tau,
    u: &C2,
    u2: &C2,
    chars: &[Char],
    w: Option<&[f64; 4]>,
) -> std::result::Result<RealTorus, TorusFailure> {
    let finite = |z: &Complex64| z.re.is_finite() && z.im.is_finite();
    if !(tau.iter().flatten().all(finite) && u.iter().all(finite) && u2.iter().all(finite)) {
        return Err(TorusFailure::NonFinite);
    }
    let g = Metric::new(tau).ok_or(TorusFailure::ImagTauNotPositive)?;
    let p1 = real4(u);
    let [_, _, q1, q2] = plane_basis(&g, &p1, &real4(u2))?;
    let k = Kernel::new(tau, &g, &q1, &q2)?;
    let (x1, x2) = k.lattice_basis(chars)?;
    let (mut a, mut b) = (
        (x1, real4(&lattice_point(tau, &x1))),
        (x2, real4(&lattice_point(tau, &x2))),
    );
    gauss_reduce(&g, &mut a, &mut b);
    // U = ν1 λ1 + ν2 λ2 by the normal equations in the metric (the plane
    // contains U by construction: the residual checks it), or in the integer
    // lattice coordinates where those of U are given.
    let mut nu = fit_two(|x, y| g.dot(x, y), &a.1, &b.1, &p1)?;
    if let Some(w) = w {
        let dot = |x: &[f64; 4], y: &[f64; 4]| (0..4).map(|k| x[k] * y[k]).sum::<f64>();
        nu = fit_two(dot, &a.0.map(|v| v as f64), &b.0.map(|v| v as f64), w)?;
    }
    for (k, v) in [&mut a, &mut b].into_iter().enumerate() {
        if nu[k] < 0.0 {
            nu[k] = -nu[k];
            v.0 = v.0.map(|c| -c);
        }
    }
    let (c1, c2) = (a.0, b.0);
    Ok(RealTorus {
        lambda: [lattice_point(tau, &c1), lattice_point(tau, &c2)],
        coords: [c1, c2],
        nu,
    })
}

/// `(ν1, ν2)` with `p = ν1 x + ν2 y` by least squares in the inner product
/// `dot`, with the residual relative to `|p|` against [`RESIDUAL_TOL`].
fn fit_two<D: Fn(&[f64; 4], &[f64; 4]) -> f64>(
    dot: D,
    x: &[f64; 4],
    y: &[f64; 4],
    p: &[f64; 4],
) -> std::result::Result<[f64; 2], TorusFailure> {
    let (g11, g12, g22) = (dot(x, x), dot(x, y), dot(y, y));
    let (r1, r2) = (dot(x, p), dot(y, p));
    let gd = g11 * g22 - g12 * g12;
    let nu = [(g22 * r1 - g12 * r2) / gd, (g11 * r2 - g12 * r1) / gd];
    let fit = axpy(-nu[1], y, &axpy(-nu[0], x, p));
    let residual = (dot(&fit, &fit) / dot(p, p)).sqrt();
    if residual.is_nan() || residual > RESIDUAL_TOL {
        return Err(TorusFailure::NoRealLattice { residual });
    }
    Ok(nu)
}

/// An orthonormal basis `(e1, e2, q1, q2)` of `R⁴` in the metric
/// `g`: `(e1, e2)` of the plane `P` of the flows `p1`, `p2`, `(q1, q2)` of its
/// complement.
///
/// Errors: the flows do not span a plane (sin of their angle ≤ [`PLANE_TOL`]).
fn plane_basis(
    g: &Metric,
    p1: &[f64; 4],
    p2: &[f64; 4],
) -> std::result::Result<[[f64; 4]; 4], TorusFailure> {
    let n1 = g.norm2(p1).sqrt();
    let n2 = g.norm2(p2).sqrt();
    if !(n1 > 0.0 && n2 > 0.0) {
        return Err(TorusFailure::DegeneratePlane { sin_angle: 0.0 });
    }
    let e1 = p1.map(|v| v / n1);
    let r2 = reject(g, &[e1], p2);
    let sin_angle = g.norm2(&r2).sqrt() / n2;
    if sin_angle.is_nan() || sin_angle <= PLANE_TOL {
        return Err(TorusFailure::DegeneratePlane { sin_angle });
    }
    let e2 = r2.map(|v| v / (sin_angle * n2));
    let mut basis = vec![e1, e2];
    for _ in 0..2 {
        // The unit vector with the largest component off the current span.
        let best = (0..4)
            .map(|k| {
                let mut y = [0.0; 4];
                y[k] = 1.0;
                reject(g, &basis, &y)
            })
            .max_by(|a, b| g.norm2(a).total_cmp(&g.norm2(b)))
            .unwrap_or([0.0; 4]);
        let nb = g.norm2(&best).sqrt();
        basis.push(best.map(|v| v / nb));
    }
    Ok([basis[0], basis[1], basis[2], basis[3]])
}

/// The integer kernel of the projection of `Λ` off the plane: the lattice
/// points `x` whose image lies in `P` satisfy `x_piv = R x_free` (pivot on
/// the best-conditioned pair of columns of `M`, the components off `P` of the
/// generators `1, 1, τ·1, τ·2`), with `R = Ri / d` rational.
struct Kernel {
    pi: usize,
    pj: usize,
    fk: usize,
    fl: usize,
    d: i64,
    ri: [[i64; 2]; 2],
    /// The smallest residual of `d R` from integers over the denominators tried.
    best_res: f64,
}

impl Kernel {
    /// Errors: no denominator `≤ MAX_DENOMINATOR` makes `R` integral to
    /// [`RATIONAL_TOL`] (or the projection is singular).
    fn new(
        tau: &Tau,
        g: &Metric,
        q1: &[f64; 4],
        q2: &[f64; 4],
    ) -> std::result::Result<Kernel, TorusFailure> {
        let unit = |k: usize| {
            let mut x = [0i64; 4];
            x[k] = 1;
            x
        };
        let gens: [[f64; 4]; 4] = std::array::from_fn(|k| real4(&lattice_point(tau, &unit(k))));
        let m: [[f64; 4]; 2] = [
            std::array::from_fn(|k| g.dot(q1, &gens[k])),
            std::array::from_fn(|k| g.dot(q2, &gens[k])),
        ];
        let pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
        let minor = |i: usize, j: usize| m[0][i] * m[1][j] - m[0][j] * m[1][i];
        let &(pi, pj) = pairs
            .iter()
            .max_by(|a, b| minor(a.0, a.1).abs().total_cmp(&minor(b.0, b.1).abs()))
            .unwrap_or(&(0, 1));
        let free: Vec<usize> = (0..4).filter(|&k| k != pi && k != pj).collect();
        let (fk, fl) = (free[0], free[1]);
        let det = minor(pi, pj);
        if det == 0.0 || !det.is_finite() {
            return Err(TorusFailure::NoRealLattice {
                residual: f64::INFINITY,
            });
        }
        // Mp^{-1} = [[m1j, −m0j], [−m1i, m0i]]/det; R = −Mp^{-1} Mf.
        let r: [[f64; 2]; 2] = std::array::from_fn(|row| {
            std::array::from_fn(|col| {
                let f = [fk, fl][col];
                let (a, b) = (m[0][f], m[1][f]);
                if row == 0 {
                    -(m[1][pj] * a - m[0][pj] * b) / det
                } else {
                    -(-m[1][pi] * a + m[0][pi] * b) / det
                }
            })
        });
        // The smallest denominator making R integral.
        let mut best_res = f64::INFINITY;
        let mut found = None;
        for d in 1..=MAX_DENOMINATOR {
            let res = r
                .iter()
                .flatten()
                .map(|&v| {
                    let dv = d as f64 * v;
                    (dv - dv.round()).abs() / dv.abs().max(1.0)
                })
                .fold(0.0f64, f64::max);
            best_res = best_res.min(res);
            if res <= RATIONAL_TOL {
                found = Some(d);
                break;
            }
        }
        let d = found.ok_or(TorusFailure::NoRealLattice { residual: best_res })?;
        let ri: [[i64; 2]; 2] = r.map(|row| row.map(|v| (d as f64 * v).round() as i64));
        Ok(Kernel {
            pi,
            pj,
            fk,
            fl,
            d,
            ri,
            best_res,
        })
    }

    /// The lattice point with free coordinates `f`, if it is integral and a
    /// period of the quotients (`chars`).
    fn full(&self, chars: &[Char], f: [i64; 2]) -> Option<Coords> {
        let (ri, d) = (&self.ri, self.d);
        let s0 = ri[0][0] * f[0] + ri[0][1] * f[1];
        let s1 = ri[1][0] * f[0] + ri[1][1] * f[1];
        if s0 % d != 0 || s1 % d != 0 {
            return None;
        }
        let mut x = [0i64; 4];
        x[self.pi] = s0 / d;
        x[self.pj] = s1 / d;
        x[self.fk] = f[0];
        x[self.fl] = f[1];
        is_period(chars, &x).then_some(x)
    }

    /// A basis of `Λ' ∩ P`: the free coordinates `x_free ∈ Z²` with
    /// `D | Ri x_free` and `x ∈ Λ'` form a lattice containing `2D Z²`, reduced
    /// to Hermite normal form.
    fn lattice_basis(&self, chars: &[Char]) -> std::result::Result<(Coords, Coords), TorusFailure> {
        let span = 2 * self.d;
        let mut h = Hnf2::new(span);
        for f0 in 0..span {
            for f1 in 0..span {
                if (f0, f1) != (0, 0) && self.full(chars, [f0, f1]).is_some() {
                    h.add([f0, f1]);
                }
            }
        }
        let [b1, b2] = h.basis();
        match (self.full(chars, b1), self.full(chars, b2)) {
            (Some(x1), Some(x2)) => Ok((x1, x2)),
            // Unreachable: HNF rows are integer combinations of members.
            _ => Err(TorusFailure::NoRealLattice {
                residual: self.best_res,
            }),
        }
    }
}

/// [`real_torus`] for characteristics given by a caller: entries other than
/// 0 or 1 are an invalid argument, and the failure an [`Error::NoRealTorus`].
pub fn real_torus_checked(tau: &Tau, u: &C2, u2: &C2, chars: &[Char]) -> Result<RealTorus> {
    if let Some(bad) = chars.iter().flatten().find(|&&v| v > 1) {
        return Err(Error::InvalidArgument {
            what: "characteristics",
            reason: format!("entries must be 0 or 1, got {bad}"),
        });
    }
    Ok(real_torus(tau, u, u2, chars)?)
}

/// Lagrange–Gauss reduction of the pair `(a, b)` (coordinates, real image) in
/// the metric `g`: afterwards `‖a‖ ≤ ‖b‖` and `|⟨a, b⟩| ≤ ‖a‖²/2`. (Exact
/// ties, `‖a‖ = ‖b‖`, happen on a set of measure zero of a torus family.)
fn gauss_reduce(g: &Metric, a: &mut (Coords, [f64; 4]), b: &mut (Coords, [f64; 4])) {
    let sub = |b: &mut (Coords, [f64; 4]), a: &(Coords, [f64; 4]), q: i64| {
        b.0 = std::array::from_fn(|k| b.0[k] - q * a.0[k]);
        b.1 = axpy(-(q as f64), &a.1, &b.1);
    };
    if g.norm2(&a.1) > g.norm2(&b.1) {
        std::mem::swap(a, b);
    }
    // Each pass strictly shortens b (or stops); 200 passes bound the
    // loop far beyond the O(log) passes a lattice of bounded entries needs.
    for _ in 0..200 {
        let q = (g.dot(&a.1, &b.1) / g.norm2(&a.1)).round();
        if q != 0.0 {
            sub(b, a, q as i64);
        }
        if g.norm2(&b.1) < g.norm2(&a.1) {
            std::mem::swap(a, b);
        } else {
            break;
        }
    }
}

/// Hermite normal form of a rank-2 lattice `L` with `span·Z² ⊂ L ⊂ Z²`, built
/// by adding generators: rows `(p, q)` and `(0, s)`, `0 < p, s`, `0 ≤ q < s`.
struct Hnf2 {
    p: i64,
    q: i64,
    s: i64,
}

fn egcd(a: i64, b: i64) -> (i64, i64, i64) {
    if b == 0 {
        (a.abs(), a.signum(), 0)
    } else {
        let (g, x, y) = egcd(b, a.rem_euclid(b));
        (g, y, x - (a.div_euclid(b)) * y)
    }
}

impl Hnf2 {
    fn new(span: i64) -> Self {
        Hnf2 {
            p: span,
            q: 0,
            s: span,
        }
    }

    fn add(&mut self, v: [i64; 2]) {
        // Combine (p, q) and v on the first coordinate; the leftover
        // second-coordinate vector joins (0, s).
        let (gcd, x, y) = egcd(self.p, v[0]);
        let (p, q) = (gcd, x * self.q + y * v[1]);
        let (ap, av) = (self.p / gcd, v[0] / gcd);
        // av·(p, q)_old − ap·v has first coordinate 0.
        let t = av * self.q - ap * v[1];
        self.s = egcd(self.s, t).0.max(1);
        self.p = p;
        self.q = q.rem_euclid(self.s);
    }

    fn basis(&self) -> [[i64; 2]; 2] {
        [[self.p, self.q], [0, self.s]]
    }
}

/// The status codes of a frequency map, defined once: each row gives the
/// variant's doc, its name, its code and its short name; [`Status`],
/// [`STATUS_NAMES`] and [`Status::ALL`] are generated from it, so that codes
/// and names cannot drift apart.
macro_rules! status_table {
    ($($(#[doc = $doc:literal])+ $variant:ident = $code:literal, $name:literal;)+) => {
        /// Status of one state in a frequency map (the `status` array of
        /// `manakov.frequency_map`; the codes are part of the API).
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[repr(u8)]
        pub enum Status {
            $($(#[doc = $doc])+ $variant = $code,)+
        }

        /// Short names of the status codes, indexed by code.
        pub const STATUS_NAMES: [&str; [$($code),+].len()] = [$($name),+];

        impl Status {
            /// Every status, in the order of its code.
            pub const ALL: [Status; [$($code),+].len()] = [$(Status::$variant),+];

            /// The short name of the status ([`STATUS_NAMES`]).
            pub fn name(self) -> &'static str {
                STATUS_NAMES[self as usize]
            }
        }
    };
}

status_table! {
    /// Frequencies computed.
    Ok = 0, "ok";
    /// `h1² = 4 h0²`: `F(s)` of (19) is undefined (the level set is singular),
    /// and the interpolation next to the self-dual states
    /// ([`near_euler`]) does not hold either.
    SingularCasimirs = 1, "h1^2 = 4 h0^2";
    /// Two branch points `d_j` of (8) coincide (a repeated root of `F` (19) and
    /// a root of `F` at an `a_j` included): the genus drops, a separatrix or a
    /// degenerate torus. (`h0 = 0` alone is a regular level set.)
    CoincidingBranchPoints = 2, "coinciding branch points";
    /// The divisor of the initial state has a point at infinity.
    DivisorAtInfinity = 3, "divisor at infinity";
    /// An iteration of the solution did not converge.
    NoConvergence = 4, "no convergence";
    /// `l0 = 0`.
    ZeroState = 5, "zero state";
    /// A non-finite entry in the state.
    NonFinite = 6, "non-finite state";
    /// The top's flow and the second flow do not span a real plane.
    DegeneratePlane = 7, "degenerate plane";
    /// No rank-2 lattice of periods in the real plane (not a compact torus).
    NoRealLattice = 8, "no real lattice";
    /// Any other refusal of the solution (its message names the reason).
    Singular = 9, "singular";
    /// The theta-quotient gradients at `v0` do not determine the velocity `U`.
    DegenerateGradients = 10, "degenerate gradients";
    /// The solution's theta quotients reproduce `l0` but solve Frahm's
    /// equations (1) at `v0` for no velocity: its set-up is wrong at this
    /// state (one of the Theorem's outliers), so are its frequencies.
    InconsistentQuotients = 11, "inconsistent quotients";
    /// The state is at rest: an equilibrium of (1) (a stationary rotation),
    /// or any state of a spherical top (all `c_ij` equal).
    Equilibrium = 12, "equilibrium";
    /// The state lies on the separatrix of an Euler top (an so(3) block or a
    /// self-dual state): its motion is asymptotic, with no period.
    Separatrix = 13, "separatrix";
}

// The codes are the indices of the table (so that `STATUS_NAMES[code]` is the name).
const _: () = {
    let mut i = 0;
    while i < Status::ALL.len() {
        assert!(Status::ALL[i] as usize == i);
        i += 1;
    }
};

impl From<TorusFailure> for Status {
    fn from(f: TorusFailure) -> Status {
        match f {
            TorusFailure::NonFinite => Status::NonFinite,
            TorusFailure::ImagTauNotPositive => Status::Singular,
            TorusFailure::DegeneratePlane { .. } => Status::DegeneratePlane,
            TorusFailure::NoRealLattice { .. } => Status::NoRealLattice,
        }
    }
}

/// The result for one state of a map: a status and `(ν1, ν2)`. When the
/// status is not [`Status::Ok`] the frequencies are NaN (the status says why).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapEntry {
    pub status: Status,
    pub nu: [f64; 2],
}

impl MapEntry {
    /// A failed entry.
    pub fn failed(status: Status) -> Self {
        MapEntry {
            status,
            nu: [f64::NAN; 2],
        }
    }
}

/// States per task of the thread pool: ~64 × 0.3 ms ≈ 20 ms of work, so a
/// wave of tasks ends (and `cancel` is polled) every few tens of milliseconds.
pub const BLOCK: usize = 64;

/// Run `per_state` over `states` in parallel, in order.
///
/// The work goes in waves of `BLOCK` states per thread; between waves the
/// calling thread checks `cancel` (so a Python caller sees Ctrl-C), and
/// within a wave each block checks the shared flag. The result of a state
/// depends only on that state.
pub fn map_states<S, T, F>(states: &[S], per_state: F, cancel: &Cancel) -> Result<Vec<T>>
where
    S: Sync,
    T: Send,
    F: Fn(&S) -> T + Sync,
{
    let wave = BLOCK * rayon::current_num_threads().max(1);
    let mut out = crate::numeric::alloc::try_with_capacity("states", states.len())?;
    for part in states.chunks(wave) {
        cancel.check()?;
        let res: Result<Vec<Vec<T>>> = part
            .par_chunks(BLOCK)
            .map(|block| {
                cancel.check()?;
                Ok(block.iter().map(&per_state).collect())
            })
            .collect();
        out.extend(res?.into_iter().flatten());
    }
    cancel.check()?;
    Ok(out)
}

/// What [`frequencies_of_state`] needs of the Theorem's solution at one
/// state: the period matrix, the velocity `U` of the top, the velocity `U'`
/// of the second flow, and the characteristics of the quotients in `l`.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowData {
    pub tau: Tau,
    pub u: C2,
    pub u2: C2,
    pub chars: Vec<Char>,
    /// The lattice coordinates `(X1, X2, Y1, Y2)` of `u` (`U = X + τY`) where
    /// the closed form gave them ([`real_torus_with_rates`]).
    pub w: Option<[f64; 4]>,
}

/// `b'` of the second commuting flow (see `docs/tori.md` §2): with the cubic
/// interpolant `b_i = p0 + p1 a_i + p2 a_i² + p3 a_i³`, `a³` if
/// `|p2| > |p3| max|a|` (the top's flow is mostly the `a²` flow), else `a²`.
pub fn second_flow_b(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    let v = nalgebra::Matrix4::from_fn(|i, j| a[i].powi(j as i32));
    let p = v
        .lu()
        .solve(&nalgebra::Vector4::from_column_slice(b))
        .unwrap_or_else(nalgebra::Vector4::zeros);
    let s = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if p[2].abs() > p[3].abs() * s {
        a.map(|x| x * x * x)
    } else {
        a.map(|x| x * x)
    }
}

/// The status and frequencies of one state.
///
/// `solve(l0)` runs the Theorem and returns [`FlowData`]; its errors become
/// status codes by `classify`. Nothing here panics or raises.
pub fn frequencies_of_state<S, K>(l0: &[f64; 6], solve: S, classify: K) -> MapEntry
where
    S: Fn(&[f64; 6]) -> Result<FlowData>,
    K: Fn(&Error) -> Status,
{
    if l0.iter().any(|v| !v.is_finite()) {
        return MapEntry::failed(Status::NonFinite);
    }
    if l0.iter().all(|&v| v == 0.0) {
        return MapEntry::failed(Status::ZeroState);
    }
    let [hp, hm] = so4::casimir_factors(l0);
    // The solution's own test (it would refuse the state): this pre-check only
    // saves its set-up and reports the status of the singular level set.
    if so4::near_self_dual(hp, hm) {
        return MapEntry::failed(Status::SingularCasimirs);
    }
    let d = match solve(l0) {
        Ok(d) => d,
        Err(e) => return MapEntry::failed(classify(&e)),
    };
    match real_torus_with_rates(&d.tau, &d.u, &d.u2, &d.chars, d.w.as_ref()) {
        Ok(t) => MapEntry {
            status: Status::Ok,
            nu: t.nu,
        },
        Err(f) => MapEntry::failed(f.into()),
    }
}
