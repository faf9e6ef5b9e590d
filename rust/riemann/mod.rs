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

use crate::error::{Error, Result};
use crate::numeric::complex::sqrt_principal;
use crate::theta::ThetaPlan;
use quad::{abs_fast, focal_half_sum_sqrt, nodes_for, sqrt_fast, Piece, SegmentSqrt, SqrtProduct};

type C = Complex64;

/// Largest genus accepted (the theta layer's limit).
pub const MAX_GENUS: usize = crate::theta::MAX_GENUS;

/// Most finite branch points (`2 MAX_GENUS + 2`): the size of the per-point
/// stack buffers.
const MAX_N: usize = 2 * MAX_GENUS + 2;

/// One unnormalised or normalised Abel vector on the stack (first `g` entries).
type Row = [C; MAX_GENUS];

const ZERO_ROW: Row = [C::new(0.0, 0.0); MAX_GENUS];

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
#[derive(Debug, Clone)]
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
    /// `|e_k|`, `|e_k − e_m|` (row-major `n × n`) and `|e_k − center|`: the
    /// per-point route choice and point check need only distances to `x`.
    e_abs: Vec<f64>,
    e_dist: Vec<f64>,
    c_dist: Vec<f64>,
    derived: OnceLock<std::result::Result<Derived, Error>>,
}

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
    calib: Vec<Option<(C, usize, usize)>>,
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
        let e_abs = e.iter().map(|&v| v.norm()).collect();
        let e_dist = (0..n * n).map(|i| (e[i / n] - e[i % n]).norm()).collect();
        let c_dist = e.iter().map(|&v| (v - center).norm()).collect();
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
            e_abs,
            e_dist,
            c_dist,
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
            let from_p = self.path_from_branch(p, mid, y_mid, None)?;
            let from_q = self.path_from_branch(q, mid, y_mid, None)?;
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
        let part1 = self.path_from_branch(r, xr, yr, None)?;
        let (part2, lam) = self.to_infinity(self.e[r], xr, yr, None)?;
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
    /// `fhs`: the route's focal half sum ([`Self::branch_quality`]) if the
    /// caller has it.
    fn path_from_branch(&self, k: usize, x: C, y: C, known: Option<(&[f64], f64)>) -> Result<Row> {
        self.path_from_branch_dx(k, x - self.e[k], y, known)
    }

    /// [`Self::path_from_branch`] with the offset `dx = x − e_k` given: near
    /// `e_k` a double `x` fixes `dx` only to `u |x|` absolute, and the
    /// integral (in the local parameter `√dx`) inherits `u |x| / |dx|`
    /// relative; an offset carried separately keeps it to roundoff.
    fn path_from_branch_dx(
        &self,
        k: usize,
        dx: C,
        y: C,
        known: Option<(&[f64], f64)>,
    ) -> Result<Row> {
        let n = self.e.len();
        let ek = self.e[k];
        let x = ek + dx;
        let mut out = ZERO_ROW;
        if dx == C::new(0.0, 0.0) {
            return Ok(out);
        }
        let mut dist_buf = [0.0; MAX_N];
        let (dist, fhs) = match known {
            Some(v) => v,
            None => {
                for (d, &em) in dist_buf.iter_mut().zip(&self.e) {
                    *d = abs_fast(x - em);
                }
                (&dist_buf[..n], self.branch_quality(k, &dist_buf[..n]))
            }
        };
        let q = sqrt_fast(dx);
        // Stack buffers: this is the per-point hot path. Factor m ≠ k is
        // a_m + s² dx, a_m = e_k − e_m, with |a_m| = |e_k − e_m| and
        // |a_m + dx| = |x − e_m|.
        let (mut a, b) = ([dx; MAX_N], [dx; MAX_N]);
        let (mut abs_a, mut abs_e) = ([0.0; MAX_N], [0.0; MAX_N]);
        let mut ns = 0;
        for (m, &em) in self.e.iter().enumerate() {
            if m == k {
                continue;
            }
            a[ns] = ek - em;
            abs_a[ns] = self.e_dist[k * n + m];
            abs_e[ns] = dist[m];
            ns += 1;
        }
        let prod = SqrtProduct::new(&a[..ns], &b[..ns], &abs_a[..ns], &abs_e[..ns]);
        let unrot = prod.unrot();
        let y1 = q * unrot * prod.rotated(1.0);
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let acc = &mut out[..self.g];
        let integrand = |s: f64, w: f64, acc: &mut [C]| {
            let s2 = s * s;
            let xs = ek + dx * s2;
            let mut f = prod.inv_rotated(s2) * w;
            for v in acc.iter_mut() {
                *v += f;
                f *= xs;
            }
        };
        // Singularities ±√t_m come in pairs: the ellipse of [−1, 1] decides.
        let nn = nodes_for(fhs.acosh());
        if nn <= quad::GL_MAX as f64 {
            quad::integrate_even(nn as usize, acc, integrand);
        } else {
            let mut sing = [C::new(0.0, 0.0); 2 * MAX_N];
            for (i, &am) in a[..ns].iter().enumerate() {
                let s = sqrt_fast(-am / dx);
                sing[2 * i] = s;
                sing[2 * i + 1] = -s;
            }
            let mut pieces: Vec<Piece> = Vec::new();
            quad::plan_pieces(&sing[..2 * ns], &mut pieces)?;
            quad::integrate(&pieces, acc, integrand);
        }
        let fac = 2.0 * sign * q / unrot;
        acc.iter_mut().for_each(|v| *v *= fac);
        Ok(out)
    }

    /// `(∫_{(x, y)}^{∞_λ} ω, λ)` along the ray from `c` through `x` (unnormalised).
    /// With `X = x − c`, `x(τ) = c + X/τ²`, `y = τ^{−n} Π ψ_m(τ²)`,
    /// `ψ_m² = X + τ²(c − e_m)`:
    /// `∫_x^∞ ω_i = (2X/s) ∫_0^1 (cτ² + X)^{i−1} τ^{n−2i−1} / Πψ_m dτ`, `s = ±1`
    /// the sheet. `λ = s Πψ_m(0) / X^{g+1}` is `±1` for even `n` (which of
    /// `∞±` the ray reaches); for odd `n` it is meaningless and returned as 1.
    /// `fhs`: the route's focal half sum (odd `n`, [`Self::infinity_quality`]
    /// for `c` the centre) if the caller has it.
    fn to_infinity(&self, c: C, x: C, y: C, known: Option<(&[f64], f64)>) -> Result<(Row, C)> {
        let (n, g) = (self.e.len(), self.g);
        let odd = n % 2 == 1;
        let xx = x - c;
        let ax = abs_fast(xx);
        let mut dist_buf = [0.0; MAX_N];
        let dist = match known {
            Some((d, _)) => d,
            None => {
                for (d, &em) in dist_buf.iter_mut().zip(&self.e) {
                    *d = abs_fast(x - em);
                }
                &dist_buf[..n]
            }
        };
        // Factor m is X + τ² (c − e_m): |X| and |X + c − e_m| = |x − e_m|.
        let mut b = [xx; MAX_N];
        for (bm, &em) in b.iter_mut().zip(&self.e) {
            *bm = c - em;
        }
        let a = [xx; MAX_N];
        let prod = SqrtProduct::new(&a[..n], &b[..n], &[ax; MAX_N][..n], dist);
        let unrot = prod.unrot();
        let y1 = unrot * prod.rotated(1.0);
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let lam = if odd {
            C::new(1.0, 0.0)
        } else {
            let y0 = unrot * prod.rotated(0.0);
            sign * y0 / xx.powi(g as i32 + 1)
        };
        let mut out = ZERO_ROW;
        let acc = &mut out[..g];
        // τ^{n−2i−1} for i = 1..g: τ^{n−2g−1} (τ⁰ or τ¹) times falling powers of τ².
        let t_odd = !odd;
        let integrand = |t: f64, w: f64, acc: &mut [C]| {
            let t2 = t * t;
            let xs = c * t2 + xx;
            let inv = prod.inv_rotated(t2) * w;
            let mut tp = if t_odd { t } else { 1.0 };
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
        let lr = if odd {
            match known {
                Some((_, fhs)) => fhs,
                None => {
                    let mut best = f64::INFINITY;
                    for (&bm, &dm) in b[..n].iter().zip(dist) {
                        let ab = abs_fast(bm);
                        if ab > 0.0 {
                            best = best.min(focal_half_sum_sqrt(ax / ab, dm / ab));
                        }
                    }
                    best
                }
            }
            .acosh()
        } else {
            0.0
        };
        let nn = nodes_for(lr);
        if odd && nn <= quad::GL_MAX as f64 {
            quad::integrate_even(nn as usize, acc, integrand);
        } else {
            let mut sing = [C::new(0.0, 0.0); 2 * MAX_N];
            let mut ns = 0;
            for &bm in &b[..n] {
                if bm != C::new(0.0, 0.0) {
                    let s = sqrt_fast(-xx / bm);
                    sing[ns] = s;
                    sing[ns + 1] = -s;
                    ns += 2;
                }
            }
            let mut pieces: Vec<Piece> = Vec::new();
            quad::plan_pieces(&sing[..ns], &mut pieces)?;
            quad::integrate(&pieces, acc, integrand);
        }
        let fac = 2.0 * sign * xx / unrot;
        acc.iter_mut().for_each(|v| *v *= fac);
        Ok((out, lam))
    }
}

/// Branch points tried as the start of an Abel path (the nearest ones).
const ROUTE_CANDIDATES: usize = 3;

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

    /// Checks that `(x, y)` lies on the curve to [`ON_CURVE_RTOL`]:
    /// `|y² − R(x)| ≤ ON_CURVE_RTOL · Π_k (|x| + |e_k|)`, evaluated divided by
    /// `|R(x)|` as `|q² − 1| ≤ ON_CURVE_RTOL · Π_k (|x| + |e_k|)/|x − e_k|` with
    /// `q = y / Π_k √(x − e_k)` (factor by factor, so nothing overflows before
    /// `y` itself does).
    pub fn check_point(&self, x: C, y: C) -> Result<()> {
        if !is_finite_c(x) || !is_finite_c(y) {
            return Err(Error::InvalidArgument {
                what: "point",
                reason: format!("x = {x}, y = {y} must be finite"),
            });
        }
        let mut dist = [0.0; MAX_N];
        for (d, &em) in dist.iter_mut().zip(&self.e) {
            *d = abs_fast(x - em);
        }
        self.check_point_with(x, y, &dist[..self.e.len()])
    }

    /// [`Self::check_point`] for finite `x, y` given `dist[k] = |x − e_k|`.
    /// Where `|R(x)|` and `|y|²` are well inside the double range the ratio
    /// `q² = y²/R(x)` is formed directly (one complex product chain instead
    /// of `n` square roots); otherwise factor by factor.
    fn check_point_with(&self, x: C, y: C, dist: &[f64]) -> Result<()> {
        if let Some(k) = self.e.iter().position(|&ek| x == ek) {
            let scale: f64 = self.e.iter().map(|ek| x.norm() + ek.norm()).product();
            if y.norm() > (ON_CURVE_RTOL * scale).sqrt() {
                return Err(Error::InvalidArgument {
                    what: "point",
                    reason: format!("x = e[{k}] is a branch point: y must be 0, got {y}"),
                });
            }
            return Ok(());
        }
        let ax = abs_fast(x);
        let mut bound = ON_CURVE_RTOL;
        let mut r = C::new(1.0, 0.0);
        for ((&ek, &aek), &d) in self.e.iter().zip(&self.e_abs).zip(dist) {
            r *= x - ek;
            bound *= (ax + aek) / d;
        }
        let (rn, yn) = (r.norm_sqr(), y.norm_sqr());
        let dev = if rn > 1e-200 && rn < 1e200 && yn < 1e200 {
            (crate::numeric::complex::cdiv(y * y, r) - 1.0).norm()
        } else {
            let mut q = y;
            for &ek in &self.e {
                q /= sqrt_principal(x - ek);
            }
            if !is_finite_c(q) {
                return Err(Error::InvalidArgument {
                    what: "point",
                    reason: format!(
                        "x = {x}: |x| is too large for y = R(x)^(1/2) in double precision"
                    ),
                });
            }
            (q * q - 1.0).norm()
        };
        if dev > bound {
            return Err(Error::InvalidArgument {
                what: "point",
                reason: format!(
                    "(x, y) = ({x}, {y}) is not on the curve: |y² − R(x)| / |R(x)| = {dev:e} > \
                     {ON_CURVE_RTOL:e} · Π(|x| + |e_k|)/|R(x)| = {bound:e}"
                ),
            });
        }
        Ok(())
    }

    /// Focal half sum `(|z−1| + |z+1|)/2` of the worst singularity of the
    /// route from `e_k` (larger is better): the integrand is even with
    /// singularities `±√w_m`, `w_m = (e_m − e_k)/(x − e_k)`, and
    /// [`focal_half_sum_sqrt`] needs only `|w_m|` and `|w_m − 1|`, i.e. the
    /// distances `|e_m − e_k|` (per curve) and `dist[m] = |x − e_m|`.
    fn branch_quality(&self, k: usize, dist: &[f64]) -> f64 {
        let n = self.e.len();
        let dk = dist[k];
        let row = &self.e_dist[k * n..(k + 1) * n];
        let mut best = f64::INFINITY;
        for m in 0..n {
            if m != k {
                best = best.min(focal_half_sum_sqrt(row[m] / dk, dist[m] / dk));
            }
        }
        best
    }

    /// As [`Self::branch_quality`] for the ray from the centre `c` through
    /// `x`: singularities at `τ² = w_m`, `w_m = (x − c)/(e_m − c)`. Odd `n`:
    /// even integrand, pairs `±√w_m` (ellipse of `[−1, 1]`). Even `n`: the
    /// integrand on `[0, 1]` has singularities `±√w_m`, mapped to `[−1, 1]` by
    /// `2z − 1`: `(|2z − 2| + |2z|)/2 = |z| + |z − 1|`, so the worse of `±√w`
    /// gives `|z| + min(|z − 1|, |z + 1|)`, where `|z ∓ 1|` are the roots of
    /// `a² + b² = 2|w| + 2`, `ab = |w − 1|`. A branch point at `c` imposes
    /// nothing (its factor is constant along the ray).
    fn infinity_quality(&self, x: C, dist: &[f64]) -> f64 {
        let dc = abs_fast(x - self.center);
        let odd = self.e.len() % 2 == 1;
        let mut best = f64::INFINITY;
        for (&cm, &dm) in self.c_dist.iter().zip(dist) {
            if cm == 0.0 {
                continue;
            }
            let (aw, aw1) = (dc / cm, dm / cm);
            let v = if odd {
                focal_half_sum_sqrt(aw, aw1)
            } else {
                let sum = (2.0 * (aw + 1.0 + aw1)).sqrt();
                let diff = (2.0 * (aw + 1.0 - aw1)).max(0.0).sqrt();
                (aw.sqrt() + 0.5 * (sum - diff)).max(1.0)
            };
            best = best.min(v);
        }
        best
    }

    /// `∫_{P0}^{(x, y)} ω`, unnormalised, along the best route (no point check).
    fn abel_unnormalised(&self, x: C, y: C) -> Result<Row> {
        let n = self.e.len();
        let mut dist = [0.0; MAX_N];
        for (d, &em) in dist.iter_mut().zip(&self.e) {
            *d = abs_fast(x - em);
        }
        self.abel_raw(x, y, &dist[..n])
    }

    /// [`Self::abel_unnormalised`] given `dist[m] = |x − e_m|`.
    fn abel_raw(&self, x: C, y: C, dist: &[f64]) -> Result<Row> {
        let g = self.g;
        let mut out = ZERO_ROW;
        if let Some(k) = self.e.iter().position(|&ek| ek == x) {
            out[..g].copy_from_slice(&self.u_branch[k]);
            return Ok(out);
        }
        // Candidates: the ray from ∞ and the segments from the ROUTE_CANDIDATES
        // nearest branch points (a far start is never better: its segment
        // passes the nearer ones). Any route is exact to the target; the
        // choice only sets the node count.
        let mut near = [(f64::INFINITY, 0usize); ROUTE_CANDIDATES];
        for (k, &d) in dist.iter().enumerate() {
            if d < near[ROUTE_CANDIDATES - 1].0 {
                let mut i = ROUTE_CANDIDATES - 1;
                while i > 0 && near[i - 1].0 > d {
                    near[i] = near[i - 1];
                    i -= 1;
                }
                near[i] = (d, k);
            }
        }
        let mut best = (Route::Infinity, self.infinity_quality(x, dist));
        for &(d, k) in &near {
            if d.is_finite() {
                let q = self.branch_quality(k, dist);
                if q > best.1 {
                    best = (Route::Branch(k), q);
                }
            }
        }
        match best.0 {
            Route::Branch(k) => {
                let v = self.path_from_branch(k, x, y, Some((dist, best.1)))?;
                for i in 0..g {
                    out[i] = self.u_branch[k][i] + v[i];
                }
            }
            Route::Infinity => {
                let (v, lam) = self.to_infinity(self.center, x, y, Some((dist, best.1)))?;
                let s = if self.e.len() % 2 == 1 || lam.re > 0.0 {
                    1.0
                } else {
                    -1.0
                };
                for i in 0..g {
                    out[i] = s * self.u_inf[i] - v[i];
                }
            }
        }
        Ok(out)
    }

    /// The integral `∫_{(x0,y0)}^{(x, y)} ω` (unnormalised) along a path
    /// through `∞` or the branch point `k` (`route = Some(k)`), for tests of
    /// path independence.
    pub fn abel_via(&self, x: C, y: C, route: Option<usize>) -> Result<Vec<C>> {
        self.check_point(x, y)?;
        let raw: Row = match route {
            Some(k) if k < self.e.len() => {
                let v = self.path_from_branch(k, x, y, None)?;
                std::array::from_fn(|i| {
                    if i < self.g {
                        self.u_branch[k][i] + v[i]
                    } else {
                        v[i]
                    }
                })
            }
            Some(k) => {
                return Err(Error::InvalidArgument {
                    what: "route",
                    reason: format!("branch point index {k} out of range"),
                })
            }
            None => {
                let (v, lam) = self.to_infinity(self.center, x, y, None)?;
                let s = if self.e.len() % 2 == 1 || lam.re > 0.0 {
                    1.0
                } else {
                    -1.0
                };
                std::array::from_fn(|i| {
                    if i < self.g {
                        s * self.u_inf[i] - v[i]
                    } else {
                        v[i]
                    }
                })
            }
        };
        Ok(self.normalise(&raw))
    }

    fn normalise(&self, raw: &[C]) -> Vec<C> {
        let mut out = ZERO_ROW;
        self.normalise_into(raw, &mut out[..self.g]);
        out[..self.g].to_vec()
    }

    #[inline]
    fn normalise_into(&self, raw: &[C], out: &mut [C]) {
        let g = self.g;
        for (i, o) in out.iter_mut().enumerate().take(g) {
            *o = (0..g).map(|j| self.a_inv[(i, j)] * raw[j]).sum();
        }
    }

    /// The Abel map `u(P) = A^{-1} ∫_{P0}^{P} ω` of `P = (x, y)` (`y` picks the
    /// sheet), `P0 = ∞` (odd `n`) or `e_1` (even `n`), modulo the lattice.
    ///
    /// Errors: `(x, y)` not on the curve to [`ON_CURVE_RTOL`], non-finite input.
    pub fn abel(&self, x: C, y: C) -> Result<Vec<C>> {
        let mut out = ZERO_ROW;
        self.abel_into(x, y, &mut out[..self.g])?;
        Ok(out[..self.g].to_vec())
    }

    /// The Abel map of the point `(x, y)` close to the branch point `e_k`,
    /// given its offset `dx = x − e_k` to full relative accuracy: the
    /// integral runs from `e_k` in the local parameter `√dx`, so the result
    /// keeps roundoff where [`Self::abel`] of the double `x` loses
    /// `u |x| / |x − e_k|` (u the unit roundoff). `y` picks the sheet.
    ///
    /// Errors: `k` out of range, non-finite input, `(e_k + dx, y)` not on the
    /// curve.
    pub fn abel_near_branch(&self, k: usize, dx: C, y: C) -> Result<Vec<C>> {
        if k >= self.e.len() {
            return Err(Error::InvalidArgument {
                what: "branch point index",
                reason: format!("{k} is out of range (0..{})", self.e.len()),
            });
        }
        let x = self.e[k] + dx;
        self.check_point(x, y)?;
        let v = self.path_from_branch_dx(k, dx, y, None)?;
        let raw: Row = std::array::from_fn(|i| {
            if i < self.g {
                self.u_branch[k][i] + v[i]
            } else {
                v[i]
            }
        });
        Ok(self.normalise(&raw))
    }

    /// [`Self::abel`] into `out` (length `g`), without allocating: the
    /// distances `|x − e_m|` serve the point check, the route choice and the
    /// node count.
    fn abel_into(&self, x: C, y: C, out: &mut [C]) -> Result<()> {
        let n = self.e.len();
        if !is_finite_c(x) || !is_finite_c(y) {
            return self.check_point(x, y);
        }
        let mut dist = [0.0; MAX_N];
        for (d, &em) in dist.iter_mut().zip(&self.e) {
            *d = abs_fast(x - em);
        }
        self.check_point_with(x, y, &dist[..n])?;
        let raw = self.abel_raw(x, y, &dist[..n])?;
        self.normalise_into(&raw, out);
        Ok(())
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
        let one = |(i, row): (usize, &mut [C])| -> Result<()> { self.abel_into(x[i], y[i], row) };
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
        // Linear equations for s = x1 + x2, p = x1 x2 from the quotients:
        // odd n:  p − e_j s + e_j² = q_j;
        // even n: p − e_j s + e_j² = q_j (p − e_0 s + e_0²).
        // The pair of equations with the largest determinant is used.
        let e0 = self.e[0];
        let rows: Vec<(C, C, C)> = d
            .calib
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
        let (p, s) = best_pair.ok_or(Error::NoConvergence {
            what: "Jacobi inversion start (no usable theta quotients)",
            tol: INVERT_MAX_RESIDUAL,
            reached: f64::INFINITY,
            iterations: 0,
        })?;
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
