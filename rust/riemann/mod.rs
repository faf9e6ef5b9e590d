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

// Index loops over g ≤ 6 coordinates mirror the formulas.
#![allow(clippy::needless_range_loop)]

pub mod basis;
pub mod quad;

#[cfg(test)]
mod tests;

use std::sync::OnceLock;

use nalgebra::DMatrix;
use num_complex::Complex64;

use crate::curve::sqrt_principal;
use crate::error::{Error, Result};
use crate::theta::ThetaPlan;
use quad::{nodes_for, Piece, SegmentSqrt};

type C = Complex64;

/// Largest genus accepted (the theta layer's limit).
pub const MAX_GENUS: usize = crate::theta::MAX_GENUS;

/// Two branch points closer than this relative to their modulus are one
/// (the curve is singular to double precision).
const REPEATED_RTOL: f64 = 8.0 * f64::EPSILON;

/// Largest `|e_k|` accepted: `R(x)` for `|x|` of that size and `n ≤ 14` stays
/// far below the double range (`(1e20)^14 = 1e280`).
pub const MAX_ABS_BRANCH_POINT: f64 = 1e20;

/// Relative tolerance of "the point is on the curve": `|y² − R(x)| ≤
/// ON_CURVE_RTOL · Π_k (|x| + |e_k|)`, the right-hand scale being that of the
/// rounding errors of `R(x)` evaluated from its expanded coefficients. Loose
/// enough for points computed elsewhere, tight enough to catch a wrong `y`.
pub const ON_CURVE_RTOL: f64 = 1e-8;

/// Largest distance of `2·β` (the lattice coordinates of a half period) from
/// integers accepted when a characteristic is read off: the half periods are
/// computed to ~1e-14, a wrong identification would be off by O(1).
const CHAR_TOL: f64 = 1e-6;

/// A characteristic `[a; b]` is taken as the Riemann constant when
/// `|θ[a;b](z)| ≤ K_SEARCH_RTOL · max_χ |θ[χ](z)|` at every test divisor: the
/// vanishing values are rounding-sized (~1e-15), the others O(1e-2) or larger.
const K_SEARCH_RTOL: f64 = 1e-8;

/// Absolute tolerance of the theta sums used here (see `crate::theta`).
const THETA_TOL: f64 = 1e-15;

/// `u` is on the theta divisor when `|θ(u + K)| ≤ THETA_DIVISOR_RTOL ·
/// max_χ |θ[χ](u + K)|`: then the divisor `z1 + z2` is special (contains `∞`
/// or a pair `P + ιP`) and inversion is not unique. Values closer than this
/// lose digits like `1/|θ|` in the quotient start; Newton still needs a
/// well-separated, non-special divisor.
pub const THETA_DIVISOR_RTOL: f64 = 1e-8;

/// Newton on the Abel map stops at this max-norm residual in the normalised
/// coordinates (`u` is O(1) after reduction; the Abel map itself is good to
/// a few 1e-15).
const INVERT_ATOL: f64 = 2e-14;

/// Largest accepted final residual of the inversion before it is reported as
/// non-convergence.
pub const INVERT_MAX_RESIDUAL: f64 = 1e-11;

/// Newton iterations of the inversion.
const INVERT_MAX_ITER: usize = 40;

/// A hyperelliptic curve `y² = Π (x − e_k)` with its canonical homology basis,
/// periods and Abel map (module docs for the conventions).
#[derive(Debug)]
pub struct HyperellipticCurve {
    e: Vec<C>,
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
    derived: OnceLock<std::result::Result<Derived, Error>>,
}

/// Theta plan, Riemann constant and inversion calibration (built on first use).
#[derive(Debug)]
struct Derived {
    plan: ThetaPlan,
    k_char: (Vec<u8>, Vec<u8>),
    k: Vec<C>,
    /// For the inversion start (g = 2, odd n): `c_j² = (x1−e_j)(x2−e_j) θ(v)²/θ[η_j](v)²`
    /// and the index of `η_j`, for every branch point `j`.
    calib: Vec<(C, usize)>,
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
    /// The curve with finite branch points `e_1 … e_n`, `n = 2g+1` or `2g+2`,
    /// `1 ≤ g ≤` [`MAX_GENUS`].
    ///
    /// Errors: wrong count, non-finite or too large entries, coinciding branch
    /// points ([`Error::RepeatedBranchPoints`]), a geometry the quadrature
    /// cannot resolve (branch points closer than rounding to a segment between
    /// others), and — as a guard, never seen — a period matrix that is not in
    /// the Siegel space.
    pub fn new(branch_points: &[C]) -> Result<Self> {
        let n = branch_points.len();
        if !(3..=2 * MAX_GENUS + 2).contains(&n) {
            return Err(Error::Shape {
                what: "branch_points",
                expected: format!("(n,) with 3 <= n <= {}", 2 * MAX_GENUS + 2),
                got: format!("({n},)"),
            });
        }
        if let Some(index) = branch_points.iter().position(|&v| !is_finite_c(v)) {
            return Err(Error::NonFinite {
                what: "branch_points",
                index,
            });
        }
        if let Some(k) = branch_points
            .iter()
            .position(|v| v.norm() > MAX_ABS_BRANCH_POINT)
        {
            return Err(Error::InvalidArgument {
                what: "branch_points",
                reason: format!(
                    "|e[{k}]| = {:e} exceeds {MAX_ABS_BRANCH_POINT:e} (R(x) would overflow); rescale x",
                    branch_points[k].norm()
                ),
            });
        }
        for i in 0..n {
            for j in (i + 1)..n {
                let scale = branch_points[i].norm().max(branch_points[j].norm());
                if (branch_points[i] - branch_points[j]).norm() <= REPEATED_RTOL * scale {
                    return Err(Error::RepeatedBranchPoints {
                        i,
                        j,
                        value: branch_points[i],
                    });
                }
            }
        }
        let e = branch_points.to_vec();
        let g = (n - 1) / 2;
        let center = e.iter().sum::<C>() / n as f64;
        let radius = e.iter().map(|v| (v - center).norm()).fold(0.0, f64::max);

        let tree = basis::spanning_tree(&e)?;
        let mut this = HyperellipticCurve {
            e,
            g,
            center,
            radius,
            tree,
            cycle_edges: Vec::new(),
            edge_periods: Vec::new(),
            intersection: Vec::new(),
            symplectic: Vec::new(),
            a: DMatrix::zeros(g, g),
            b: DMatrix::zeros(g, g),
            a_inv: DMatrix::zeros(g, g),
            tau: DMatrix::zeros(g, g),
            tau_flat: Vec::new(),
            im_tau_inv: DMatrix::zeros(g, g),
            u_branch: Vec::new(),
            u_inf: vec![C::new(0.0, 0.0); g],
            derived: OnceLock::new(),
        };
        this.build()?;
        Ok(this)
    }

    fn build(&mut self) -> Result<()> {
        let (n, g) = (self.e.len(), self.g);
        // Periods and end directions of every tree edge.
        let mut dirs: Vec<(C, C)> = Vec::with_capacity(self.tree.len());
        let mut periods = Vec::with_capacity(self.tree.len());
        for &(p, q) in &self.tree {
            let (per, dp, dq) = self.edge_period(p, q)?;
            periods.push(per);
            dirs.push((dp, dq));
        }
        // Odd n: the 2g edges of the tree on the finite branch points are a
        // basis. Even n: the 2g+1 edges satisfy one relation; drop a leaf edge
        // (then the tree spans 2g+1 of the 2g+2 branch points, a basis).
        let mut cycle_edges: Vec<usize> = (0..self.tree.len()).collect();
        if n % 2 == 0 {
            let mut deg = vec![0usize; n];
            for &(p, q) in &self.tree {
                deg[p] += 1;
                deg[q] += 1;
            }
            let leaf = (0..self.tree.len())
                .rev()
                .find(|&i| deg[self.tree[i].0] == 1 || deg[self.tree[i].1] == 1)
                .ok_or_else(|| Error::InvalidArgument {
                    what: "branch_points",
                    reason: "tree without a leaf".into(),
                })?;
            cycle_edges.remove(leaf);
        }
        let m = 2 * g;
        let mut c = vec![vec![0i64; m]; m];
        for i in 0..m {
            for j in 0..m {
                if i == j {
                    continue;
                }
                let (ei, ej) = (self.tree[cycle_edges[i]], self.tree[cycle_edges[j]]);
                let shared = [ei.0, ei.1].into_iter().find(|&v| v == ej.0 || v == ej.1);
                if let Some(v) = shared {
                    let di = if v == ei.0 {
                        dirs[cycle_edges[i]].0
                    } else {
                        dirs[cycle_edges[i]].1
                    };
                    let dj = if v == ej.0 {
                        dirs[cycle_edges[j]].0
                    } else {
                        dirs[cycle_edges[j]].1
                    };
                    let s = (di.conj() * dj).im;
                    c[i][j] = if s > 0.0 { 1 } else { -1 };
                }
            }
        }
        let msym = basis::symplectic_reduction(&c)?;
        let mut a = DMatrix::<C>::zeros(g, g);
        let mut b = DMatrix::<C>::zeros(g, g);
        for j in 0..m {
            for (k, &ce) in cycle_edges.iter().enumerate() {
                let coef = msym[j][k] as f64;
                if coef == 0.0 {
                    continue;
                }
                for i in 0..g {
                    let v = periods[ce][i] * coef;
                    if j < g {
                        a[(i, j)] += v;
                    } else {
                        b[(i, j - g)] += v;
                    }
                }
            }
        }
        let a_inv = a
            .clone()
            .try_inverse()
            .ok_or_else(|| Error::InvalidArgument {
                what: "branch_points",
                reason: "the a-period matrix is singular (inaccurate periods)".into(),
            })?;
        let mut tau = &a_inv * &b;
        // Symmetrise: τ is symmetric to rounding (the bilinear relations); the
        // asymmetry is part of the accuracy tests, not hidden by this step,
        // which uses the raw A, B.
        let raw = tau.clone();
        for i in 0..g {
            for j in 0..g {
                tau[(i, j)] = 0.5 * (raw[(i, j)] + raw[(j, i)]);
            }
        }
        let im = DMatrix::<f64>::from_fn(g, g, |i, j| tau[(i, j)].im);
        let chol = nalgebra::Cholesky::new(im.clone()).ok_or_else(|| {
            let ev = nalgebra::SymmetricEigen::new(im.clone());
            Error::ImagNotPositiveDefinite {
                min_eig: ev.eigenvalues.min(),
            }
        })?;
        self.im_tau_inv = chol.inverse();
        self.tau_flat = (0..g * g).map(|k| tau[(k / g, k % g)]).collect();
        self.cycle_edges = cycle_edges;
        self.intersection = c;
        self.symplectic = msym;
        self.a = a;
        self.b = b;
        self.a_inv = a_inv;
        self.tau = tau;
        self.edge_periods = periods;
        self.base_points()?;
        Ok(())
    }

    /// `(∮ ω over the loop of edge p→q, direction at p, direction at q)`.
    ///
    /// On the edge `x = m + h t`, `t ∈ [−1, 1]`, the branch
    /// `Y(t) = i h √(1 − t²) Π_{k≠p,q} φ_k(t)` (continuous `φ_k² = x − e_k`)
    /// satisfies `Y² = R`. The loop runs `p → q` on `Y` and back on `−Y`:
    /// `∮ ω_i = 2 ∫ x^{i−1} dx / Y = −2i ∫_{−1}^{1} x^{i−1}/Πφ_k dt/√(1−t²)`.
    /// The directions (docs/riemann.md) are the tangents of the lifted loop in
    /// the local coordinate `√(x − e_v)` at each end, up to a factor common to
    /// all edges at that end.
    fn edge_period(&self, p: usize, q: usize) -> Result<(Vec<C>, C, C)> {
        let g = self.g;
        let mid = 0.5 * (self.e[p] + self.e[q]);
        let h = 0.5 * (self.e[q] - self.e[p]);
        let others: Vec<usize> = (0..self.e.len()).filter(|&k| k != p && k != q).collect();
        let segs: Vec<SegmentSqrt> = others
            .iter()
            .map(|&k| SegmentSqrt::new(mid - self.e[k] - h, 2.0 * h))
            .collect();
        let unrot: C = segs.iter().map(|s| s.unrot()).product();
        let prod_at = |t: f64| -> C {
            others
                .iter()
                .zip(&segs)
                .map(|(&k, s)| s.rotated(mid - self.e[k] + h * t))
                .product::<C>()
        };
        let i_unit = C::new(0.0, 1.0);
        let dp = i_unit * h * unrot * prod_at(-1.0);
        let dq = -i_unit * h * unrot * prod_at(1.0);
        let lr = basis::edge_quality(&self.e, p, q);
        let nc = nodes_for(lr);
        let mut per = vec![C::new(0.0, 0.0); g];
        if nc <= quad::CHEB_MAX as f64 {
            let rule = quad::cheb_rule(nc as usize);
            for (&t, &w) in rule.nodes.iter().zip(&rule.weights) {
                let x = mid + h * t;
                let f = C::new(w, 0.0) / prod_at(t);
                let mut xp = f;
                for i in 0..g {
                    per[i] += xp;
                    xp *= x;
                }
            }
            let fac = -2.0 * i_unit / unrot;
            per.iter_mut().for_each(|v| *v *= fac);
        } else {
            // A branch point near an end: two halves from the ends to the
            // middle, composite Gauss–Legendre (the bisection follows the
            // nearby singularity).
            let y_mid = i_unit * h * unrot * prod_at(0.0);
            let from_p = self.path_from_branch(p, mid, y_mid)?;
            let from_q = self.path_from_branch(q, mid, y_mid)?;
            for i in 0..g {
                per[i] = 2.0 * (from_p[i] - from_q[i]);
            }
        }
        Ok((per, dp, dq))
    }

    /// Fills `u_branch` (tree paths from `P0`) and, for even `n`, `u_inf`.
    fn base_points(&mut self) -> Result<()> {
        let (n, g) = (self.e.len(), self.g);
        let zero = vec![C::new(0.0, 0.0); g];
        // The ray to ∞ starts at the branch point farthest from the centre and
        // points away from it: every other branch point lies in the disc of
        // that radius, i.e. behind the ray's start.
        let r = (0..n)
            .max_by(|&i, &j| {
                (self.e[i] - self.center)
                    .norm()
                    .total_cmp(&(self.e[j] - self.center).norm())
            })
            .unwrap_or(0);
        let d = (self.e[r] - self.center) / (self.e[r] - self.center).norm();
        let len = 2.0
            * self
                .e
                .iter()
                .map(|v| (v - self.e[r]).norm())
                .fold(0.0, f64::max);
        let xr = self.e[r] + d * len;
        let yr = self.y(xr, 1);
        let part1 = self.path_from_branch(r, xr, yr)?;
        let (part2, lam) = self.to_infinity(self.e[r], xr, yr)?;
        let ray: Vec<C> = (0..g).map(|i| part1[i] + part2[i]).collect(); // ∫_{e_r}^{∞} ω
        let root = if n % 2 == 1 { r } else { 0 };
        let mut u = vec![zero.clone(); n];
        let mut done = vec![false; n];
        u[root] = if n % 2 == 1 {
            ray.iter().map(|v| -v).collect()
        } else {
            zero.clone()
        };
        done[root] = true;
        let mut stack = vec![root];
        while let Some(v) = stack.pop() {
            for (ei, &(p, q)) in self.tree.iter().enumerate() {
                let half: Vec<C> = self.edge_periods[ei].iter().map(|x| 0.5 * x).collect();
                if p == v && !done[q] {
                    u[q] = (0..g).map(|i| u[p][i] + half[i]).collect();
                    done[q] = true;
                    stack.push(q);
                } else if q == v && !done[p] {
                    u[p] = (0..g).map(|i| u[q][i] - half[i]).collect();
                    done[p] = true;
                    stack.push(p);
                }
            }
        }
        if n % 2 == 0 {
            // ∫_{P0}^{∞_λ} = u(e_r) + ray; u(∞−) = −u(∞+) (P0 is a Weierstrass point).
            let s = if lam.re > 0.0 { 1.0 } else { -1.0 };
            self.u_inf = (0..g).map(|i| s * (u[r][i] + ray[i])).collect();
        }
        self.u_branch = u;
        Ok(())
    }

    /// `∫_{e_k}^{(x, y)} ω` (unnormalised) along the straight segment, on the
    /// sheet of `y`. With `x(σ) = e + (x − e)σ²`, `y = σ q Π_{m≠k} φ_m`,
    /// `q² = x − e`: `dx/y = 2 q dσ / Π φ_m(σ²)`, analytic on `[0, 1]`.
    fn path_from_branch(&self, k: usize, x: C, y: C) -> Result<Vec<C>> {
        let g = self.g;
        let ek = self.e[k];
        let dx = x - ek;
        let mut out = vec![C::new(0.0, 0.0); g];
        if dx == C::new(0.0, 0.0) {
            return Ok(out);
        }
        let q = sqrt_principal(dx);
        let mut sing: Vec<C> = Vec::with_capacity(2 * self.e.len());
        let mut segs: Vec<(C, SegmentSqrt)> = Vec::with_capacity(self.e.len());
        for (m, &em) in self.e.iter().enumerate() {
            if m == k {
                continue;
            }
            let a = ek - em;
            segs.push((a, SegmentSqrt::new(a, dx)));
            let s = sqrt_principal(-a / dx);
            sing.push(s);
            sing.push(-s);
        }
        let unrot: C = segs.iter().map(|(_, s)| s.unrot()).product();
        let y1 = q * unrot * segs.iter().map(|(a, s)| s.rotated(a + dx)).product::<C>();
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let integrand = |s: f64, w: f64, acc: &mut [C]| {
            let s2 = s * s;
            let prod: C = segs.iter().map(|(a, sg)| sg.rotated(a + dx * s2)).product();
            let xs = ek + dx * s2;
            let mut f = C::new(w, 0.0) / prod;
            for v in acc.iter_mut() {
                *v += f;
                f *= xs;
            }
        };
        // Singularities ±√t_m come in pairs: the ellipse of [−1, 1] decides.
        let lr = sing
            .iter()
            .step_by(2)
            .map(|&z| quad::focal_half_sum(z))
            .fold(f64::INFINITY, f64::min)
            .acosh();
        let nn = nodes_for(lr);
        if nn <= quad::GL_MAX as f64 {
            quad::integrate_even(nn as usize, &mut out, integrand);
        } else {
            let mut pieces: Vec<Piece> = Vec::new();
            quad::plan_pieces(&sing, &mut pieces)?;
            quad::integrate(&pieces, &mut out, integrand);
        }
        let fac = 2.0 * sign * q / unrot;
        out.iter_mut().for_each(|v| *v *= fac);
        Ok(out)
    }

    /// `(∫_{(x, y)}^{∞_λ} ω, λ)` along the ray from `c` through `x` (unnormalised).
    /// With `X = x − c`, `x(τ) = c + X/τ²`, `y = τ^{−n} Π ψ_m(τ²)`,
    /// `ψ_m² = X + τ²(c − e_m)`:
    /// `∫_x^∞ ω_i = (2X/s) ∫_0^1 (cτ² + X)^{i−1} τ^{n−2i−1} / Πψ_m dτ`, `s = ±1`
    /// the sheet. `λ = s Πψ_m(0) / X^{g+1}` is `±1` for even `n` (which of
    /// `∞±` the ray reaches) and meaningless for odd `n`.
    fn to_infinity(&self, c: C, x: C, y: C) -> Result<(Vec<C>, C)> {
        let (n, g) = (self.e.len(), self.g);
        let xx = x - c;
        let mut sing: Vec<C> = Vec::with_capacity(2 * n);
        let mut segs: Vec<(C, SegmentSqrt)> = Vec::with_capacity(n);
        for &em in &self.e {
            let b = c - em;
            segs.push((b, SegmentSqrt::new(xx, b)));
            if b != C::new(0.0, 0.0) {
                let s = sqrt_principal(-xx / b);
                sing.push(s);
                sing.push(-s);
            }
        }
        let unrot: C = segs.iter().map(|(_, s)| s.unrot()).product();
        let y1 = unrot * segs.iter().map(|(b, s)| s.rotated(xx + b)).product::<C>();
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let y0 = unrot * segs.iter().map(|(_, s)| s.rotated(xx)).product::<C>();
        let lam = sign * y0 / xx.powi(g as i32 + 1);
        let mut out = vec![C::new(0.0, 0.0); g];
        let integrand = |t: f64, w: f64, acc: &mut [C]| {
            let t2 = t * t;
            let prod: C = segs.iter().map(|(b, sg)| sg.rotated(xx + b * t2)).product();
            let xs = c * t2 + xx;
            let inv = C::new(w, 0.0) / prod;
            // (cτ² + X)^{i−1} τ^{n−2i−1}: powers of xs up, of τ² down from τ^{n−3}.
            let mut tp = t.powi(n as i32 - 2 * g as i32 - 1);
            let mut tps = [0.0f64; MAX_GENUS + 1];
            for i in (0..g).rev() {
                tps[i] = tp;
                tp *= t2;
            }
            let mut xp = inv;
            for (i, v) in acc.iter_mut().enumerate() {
                *v += xp * tps[i];
                xp *= xs;
            }
        };
        let lr = if n % 2 == 1 {
            sing.iter()
                .step_by(2)
                .map(|&z| quad::focal_half_sum(z))
                .fold(f64::INFINITY, f64::min)
                .acosh()
        } else {
            0.0
        };
        let nn = nodes_for(lr);
        if n % 2 == 1 && nn <= quad::GL_MAX as f64 {
            quad::integrate_even(nn as usize, &mut out, integrand);
        } else {
            let mut pieces: Vec<Piece> = Vec::new();
            quad::plan_pieces(&sing, &mut pieces)?;
            quad::integrate(&pieces, &mut out, integrand);
        }
        let fac = 2.0 * sign * xx / unrot;
        out.iter_mut().for_each(|v| *v *= fac);
        Ok((out, lam))
    }
}

/// Rows at least this long are split over rayon's pool in [`HyperellipticCurve::abel_batch`]
/// (~1 ms of work, well above the pool's wake-up cost).
const PARALLEL_MIN_POINTS: usize = 1024;

impl HyperellipticCurve {
    /// The genus `g`.
    pub fn genus(&self) -> usize {
        self.g
    }

    /// The finite branch points `e_1 … e_n` as given.
    pub fn branch_points(&self) -> &[C] {
        &self.e
    }

    /// Whether `∞` is a branch point (odd `n`); then `P0 = ∞`, else `P0 = e_1`.
    pub fn infinity_is_branch_point(&self) -> bool {
        self.e.len() % 2 == 1
    }

    /// `R(x) = Π (x − e_k)`.
    pub fn r(&self, x: C) -> C {
        self.e.iter().map(|&ek| x - ek).product()
    }

    /// `y` on sheet `sheet = ±1`: `sheet · Π_k √(x − e_k)` with principal
    /// roots (`sheet = +1` is the canonical sheet of `crate::curve`). Any
    /// `sheet ≤ 0` means `−1`.
    pub fn y(&self, x: C, sheet: i8) -> C {
        let y: C = self.e.iter().map(|&ek| sqrt_principal(x - ek)).product();
        if sheet > 0 {
            y
        } else {
            -y
        }
    }

    /// `(A, B)`: `A_ij = ∮_{a_j} ω_i`, `B_ij = ∮_{b_j} ω_i`, `ω_i = x^{i−1} dx/y`.
    pub fn periods(&self) -> (&DMatrix<C>, &DMatrix<C>) {
        (&self.a, &self.b)
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
        DMatrix::from_fn(g, 2 * g, |i, j| self.edge_periods[self.cycle_edges[j]][i])
    }

    /// Checks that `(x, y)` lies on the curve to [`ON_CURVE_RTOL`].
    pub fn check_point(&self, x: C, y: C) -> Result<()> {
        if !is_finite_c(x) || !is_finite_c(y) {
            return Err(Error::InvalidArgument {
                what: "point",
                reason: format!("x = {x}, y = {y} must be finite"),
            });
        }
        let scale: f64 = self.e.iter().map(|ek| x.norm() + ek.norm()).product();
        let dev = (y * y - self.r(x)).norm();
        if dev.is_nan() || dev > ON_CURVE_RTOL * scale {
            return Err(Error::InvalidArgument {
                what: "point",
                reason: format!(
                    "(x, y) = ({x}, {y}) is not on the curve: |y² − R(x)| = {dev:e} > \
                     {ON_CURVE_RTOL:e} · Π(|x| + |e_k|) = {:e}",
                    ON_CURVE_RTOL * scale
                ),
            });
        }
        Ok(())
    }

    /// `(|z−1| + |z+1|)/2` of the route's worst singularity (larger is
    /// better): branch routes and, for odd `n`, the ray from `∞` have even
    /// integrands with paired singularities `±z` (ellipse of `[−1, 1]`); the
    /// ray for even `n` has singularities `z` on `[0, 1]`, mapped.
    fn route_quality(&self, route: Route, x: C) -> f64 {
        match route {
            Route::Branch(k) => {
                let dx = x - self.e[k];
                self.e
                    .iter()
                    .enumerate()
                    .filter(|&(m, _)| m != k)
                    .map(|(_, &em)| quad::focal_half_sum(sqrt_principal((em - self.e[k]) / dx)))
                    .fold(f64::INFINITY, f64::min)
            }
            Route::Infinity => {
                let xx = x - self.center;
                let odd = self.e.len() % 2 == 1;
                self.e
                    .iter()
                    .map(|&em| {
                        let z = sqrt_principal(xx / (em - self.center));
                        if odd {
                            quad::focal_half_sum(z)
                        } else {
                            quad::focal_half_sum(2.0 * z - 1.0)
                                .min(quad::focal_half_sum(-2.0 * z - 1.0))
                        }
                    })
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }

    /// `∫_{P0}^{(x, y)} ω`, unnormalised, along the best route (no point check).
    fn abel_unnormalised(&self, x: C, y: C) -> Result<Vec<C>> {
        let mut best = (Route::Infinity, self.route_quality(Route::Infinity, x));
        for k in 0..self.e.len() {
            if x == self.e[k] {
                return Ok(self.u_branch[k].clone());
            }
            let q = self.route_quality(Route::Branch(k), x);
            if q > best.1 {
                best = (Route::Branch(k), q);
            }
        }
        match best.0 {
            Route::Branch(k) => {
                let v = self.path_from_branch(k, x, y)?;
                Ok((0..self.g).map(|i| self.u_branch[k][i] + v[i]).collect())
            }
            Route::Infinity => {
                let (v, lam) = self.to_infinity(self.center, x, y)?;
                let s = if self.e.len() % 2 == 1 || lam.re > 0.0 {
                    1.0
                } else {
                    -1.0
                };
                Ok((0..self.g).map(|i| s * self.u_inf[i] - v[i]).collect())
            }
        }
    }

    /// The integral `∫_{(x0,y0)}^{(x, y)} ω` (unnormalised) along a path
    /// through `∞` or the branch point `k` (`route = Some(k)`), for tests of
    /// path independence.
    pub fn abel_via(&self, x: C, y: C, route: Option<usize>) -> Result<Vec<C>> {
        self.check_point(x, y)?;
        let raw = match route {
            Some(k) if k < self.e.len() => {
                let v = self.path_from_branch(k, x, y)?;
                (0..self.g).map(|i| self.u_branch[k][i] + v[i]).collect()
            }
            Some(k) => {
                return Err(Error::InvalidArgument {
                    what: "route",
                    reason: format!("branch point index {k} out of range"),
                })
            }
            None => {
                let (v, lam) = self.to_infinity(self.center, x, y)?;
                let s = if self.e.len() % 2 == 1 || lam.re > 0.0 {
                    1.0
                } else {
                    -1.0
                };
                (0..self.g)
                    .map(|i| s * self.u_inf[i] - v[i])
                    .collect::<Vec<C>>()
            }
        };
        Ok(self.normalise(&raw))
    }

    fn normalise(&self, raw: &[C]) -> Vec<C> {
        let g = self.g;
        (0..g)
            .map(|i| (0..g).map(|j| self.a_inv[(i, j)] * raw[j]).sum())
            .collect()
    }

    /// The Abel map `u(P) = A^{-1} ∫_{P0}^{P} ω` of `P = (x, y)` (`y` picks the
    /// sheet), `P0 = ∞` (odd `n`) or `e_1` (even `n`), modulo the lattice.
    ///
    /// Errors: `(x, y)` not on the curve to [`ON_CURVE_RTOL`], non-finite input.
    pub fn abel(&self, x: C, y: C) -> Result<Vec<C>> {
        self.check_point(x, y)?;
        Ok(self.normalise(&self.abel_unnormalised(x, y)?))
    }

    /// [`Self::abel`] of `N` points into `out` (row-major `(N, g)`); rayon for
    /// large batches.
    pub fn abel_batch(&self, x: &[C], y: &[C], out: &mut [C]) -> Result<()> {
        let g = self.g;
        if x.len() != y.len() || out.len() != x.len() * g {
            return Err(Error::Shape {
                what: "abel_batch",
                expected: format!("x, y of equal length N and out of N*{g}"),
                got: format!("{}, {}, {}", x.len(), y.len(), out.len()),
            });
        }
        let one = |(i, row): (usize, &mut [C])| -> Result<()> {
            let u = self.abel(x[i], y[i])?;
            row.copy_from_slice(&u);
            Ok(())
        };
        if x.len() >= PARALLEL_MIN_POINTS {
            use rayon::prelude::*;
            out.par_chunks_mut(g).enumerate().try_for_each(one)
        } else {
            out.chunks_mut(g).enumerate().try_for_each(one)
        }
    }

    /// Real lattice coordinates `(α, β)` of `z = α + τ β`.
    pub fn lattice_coordinates(&self, z: &[C]) -> (Vec<f64>, Vec<f64>) {
        let g = self.g;
        let beta: Vec<f64> = (0..g)
            .map(|i| (0..g).map(|j| self.im_tau_inv[(i, j)] * z[j].im).sum())
            .collect();
        let alpha: Vec<f64> = (0..g)
            .map(|i| z[i].re - (0..g).map(|j| self.tau[(i, j)].re * beta[j]).sum::<f64>())
            .collect();
        (alpha, beta)
    }

    /// `z` reduced modulo `Z^g + τ Z^g` to `α + τβ` with `α, β ∈ [−1/2, 1/2]`.
    pub fn reduce(&self, z: &[C]) -> Vec<C> {
        let g = self.g;
        let (alpha, beta) = self.lattice_coordinates(z);
        (0..g)
            .map(|i| {
                let mut v = z[i] - alpha[i].round();
                for j in 0..g {
                    v -= self.tau[(i, j)] * beta[j].round();
                }
                v
            })
            .collect()
    }

    /// The characteristic `[a; b]` of a half period `z ≡ (b + τa)/2`.
    pub fn half_period_char(&self, z: &[C]) -> Result<(Vec<u8>, Vec<u8>)> {
        let (alpha, beta) = self.lattice_coordinates(z);
        let mut a = Vec::with_capacity(self.g);
        let mut b = Vec::with_capacity(self.g);
        for i in 0..self.g {
            let (ta, tb) = (2.0 * beta[i], 2.0 * alpha[i]);
            if (ta - ta.round()).abs() > CHAR_TOL || (tb - tb.round()).abs() > CHAR_TOL {
                return Err(Error::InvalidArgument {
                    what: "half period",
                    reason: format!("2β = {ta}, 2α = {tb} are not integers: not a half period"),
                });
            }
            a.push((ta.round() as i64).rem_euclid(2) as u8);
            b.push((tb.round() as i64).rem_euclid(2) as u8);
        }
        Ok((a, b))
    }

    /// The half period `(b + τ a)/2` of a characteristic.
    pub fn half_period(&self, a: &[u8], b: &[u8]) -> Vec<C> {
        let g = self.g;
        (0..g)
            .map(|i| {
                let mut v = C::new(0.5 * f64::from(b[i]), 0.0);
                for j in 0..g {
                    v += 0.5 * self.tau[(i, j)] * f64::from(a[j]);
                }
                v
            })
            .collect()
    }

    /// `u(e_k)` (0-based `k`, unreduced; `k = n` is `∞` for odd `n`, `u = 0`).
    pub fn abel_branch_point(&self, k: usize) -> Result<Vec<C>> {
        if k < self.e.len() {
            Ok(self.normalise(&self.u_branch[k]))
        } else if k == self.e.len() && self.e.len() % 2 == 1 {
            Ok(vec![C::new(0.0, 0.0); self.g])
        } else {
            Err(Error::InvalidArgument {
                what: "k",
                reason: format!(
                    "branch point index {k} out of range 0..{} ({} for ∞ when n is odd)",
                    self.e.len(),
                    self.e.len()
                ),
            })
        }
    }

    /// `η(e_k)`: `u(e_k) ≡ (b + τ a)/2` modulo the lattice, for the 0-based
    /// index `k` (`e_{k+1}`); `k = n` is `∞` for odd `n` (`η(∞) = 0`, the base
    /// point). Empty vectors for an index out of range
    /// ([`Self::try_branch_char`] gives the error).
    pub fn branch_char(&self, k: usize) -> (Vec<u8>, Vec<u8>) {
        self.try_branch_char(k).unwrap_or_default()
    }

    /// [`Self::branch_char`] with an error for an index out of range.
    pub fn try_branch_char(&self, k: usize) -> Result<(Vec<u8>, Vec<u8>)> {
        self.half_period_char(&self.abel_branch_point(k)?)
    }

    /// The half period `(b + τa)/2` of `η(e_k)` (reduced representative).
    pub fn branch_half_period(&self, k: usize) -> Result<Vec<C>> {
        let (a, b) = self.try_branch_char(k)?;
        Ok(self.half_period(&a, &b))
    }

    fn derived(&self) -> Result<&Derived> {
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
                let (a, b) = self.try_branch_char(j)?;
                let idx = crate::theta::char_index(&a, &b)?;
                let ratio = vals[0] / vals[idx];
                calib.push(((x1 - self.e[j]) * (x2 - self.e[j]) * ratio * ratio, idx));
            }
        }
        Ok(Derived {
            plan,
            k_char,
            k,
            calib,
        })
    }

    /// The vector of Riemann constants `K` for the base point `P0`: the half
    /// period `(b + τa)/2` with `θ(u(P_1) + … + u(P_{g−1}) + K) = 0` for all
    /// points (g = 2: `θ(u(P) + K) = 0` for every `P`), found among the `4^g`
    /// half periods by evaluating theta at three fixed divisors (built on
    /// first use). Empty if that search failed; [`Self::try_riemann_constant`]
    /// gives the error.
    pub fn riemann_constant(&self) -> &[C] {
        self.try_riemann_constant().unwrap_or(&[])
    }

    /// [`Self::riemann_constant`] with the error of the search.
    pub fn try_riemann_constant(&self) -> Result<&[C]> {
        Ok(&self.derived()?.k)
    }

    /// The characteristic `[a; b]` of [`Self::riemann_constant`]
    /// (`K = (b + τa)/2`); empty vectors if the search failed.
    pub fn riemann_constant_char(&self) -> (Vec<u8>, Vec<u8>) {
        self.try_riemann_constant_char().unwrap_or_default()
    }

    /// [`Self::riemann_constant_char`] with the error of the search.
    pub fn try_riemann_constant_char(&self) -> Result<(Vec<u8>, Vec<u8>)> {
        Ok(self.derived()?.k_char.clone())
    }

    /// The theta plan of `τ` (built once).
    pub fn theta_plan(&self) -> Result<&ThetaPlan> {
        Ok(&self.derived()?.plan)
    }

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
        if self.g != 2 || self.e.len() != 5 {
            return Err(Error::InvalidArgument {
                what: "invert",
                reason: format!(
                    "implemented for genus 2 with 5 finite branch points, got g = {}, n = {}",
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
                     the divisor is special (contains ∞ or a pair P + ιP), not unique",
                    vals[0].norm() / big
                ),
            });
        }
        // The two branch points farthest apart give the best-conditioned
        // linear solve for x1 + x2 and x1 x2.
        let (mut jb, mut kb, mut dist) = (0, 1, 0.0);
        for j in 0..5 {
            for k in (j + 1)..5 {
                if (self.e[j] - self.e[k]).norm() > dist {
                    (jb, kb, dist) = (j, k, (self.e[j] - self.e[k]).norm());
                }
            }
        }
        let q = |j: usize| {
            let (c, idx) = d.calib[j];
            let r = vals[idx] / vals[0];
            c * r * r
        };
        let (ej, ek) = (self.e[jb], self.e[kb]);
        let s = ej + ek - (q(jb) - q(kb)) / (ej - ek);
        let p = q(jb) + ej * s - ej * ej;
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
        let (mut y1, mut y2) = (self.y(x1, 1), self.y(x2, 1));
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
        y1 *= best.1;
        y2 *= best.2;
        self.newton(u.as_slice(), &mut x1, &mut y1, &mut x2, &mut y2)?;
        Ok([(x1, y1), (x2, y2)])
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
                let yn = self.y(xn, 1);
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
