//! The homology basis and the periods: the loops around the edges of a
//! spanning tree of the branch points, their periods by Gauss–Chebyshev
//! quadrature, the intersection numbers from the local picture at the shared
//! branch points, a symplectic reduction to a canonical basis, and
//! `τ = A^{-1} B` (Molin & Neurohr 2019; docs/riemann.md).

use super::*;
use crate::numeric::complex::Modulus;

/// Two branch points closer than this relative to their modulus are one
/// (the curve is singular to double precision).
const REPEATED_RTOL: f64 = 8.0 * f64::EPSILON;

/// A branch point nearer than this fraction of a tree segment's length to one
/// of its ends is "near the end": the segment's factors then take exact
/// offsets at the ends ([`HyperellipticCurve::edge_period`]).
const NEAR_END_FRACTION: f64 = 1e-8;

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
        // The internal coordinate x / 2^k (module docs, "Scale").
        let big = branch_points
            .iter()
            .map(|v| v.modulus())
            .fold(0.0, f64::max);
        let scale_exp = if big > MAX_ABS_BRANCH_POINT {
            let k = 2 * (big.log2() / 2.0).floor() as i32;
            if k * n as i32 / 2 > MAX_Y_SCALE_EXP {
                let kmax = branch_points
                    .iter()
                    .position(|v| v.modulus() == big)
                    .unwrap_or(0);
                return Err(Error::InvalidArgument {
                    what: "branch_points",
                    reason: format!(
                        "|e[{kmax}]| = {big:e} is too large: y ~ x^(n/2) at that scale leaves \
                         the double range"
                    ),
                });
            }
            k
        } else {
            0
        };
        for i in 0..n {
            for j in (i + 1)..n {
                let scale = branch_points[i].modulus().max(branch_points[j].modulus());
                if (branch_points[i] - branch_points[j]).modulus() <= REPEATED_RTOL * scale {
                    return Err(Error::RepeatedBranchPoints {
                        i,
                        j,
                        value: branch_points[i],
                    });
                }
            }
        }
        let e_user = branch_points.to_vec();
        let e: Vec<C> = if scale_exp == 0 {
            e_user.clone()
        } else {
            let down = 2f64.powi(-scale_exp);
            e_user.iter().map(|&v| v * down).collect()
        };
        let g = (n - 1) / 2;
        let center = e.iter().sum::<C>() / n as f64;
        let radius = e.iter().map(|v| (v - center).modulus()).fold(0.0, f64::max);

        let tree = basis::spanning_tree(&e)?;
        let e_abs = e.iter().map(|&v| v.modulus()).collect();
        let e_dist = (0..n * n)
            .map(|i| (e[i / n] - e[i % n]).modulus())
            .collect();
        let c_dist = e.iter().map(|&v| (v - center).modulus()).collect();
        let mut this = HyperellipticCurve {
            e,
            e_user,
            scale_exp,
            a_user: DMatrix::zeros(g, g),
            b_user: DMatrix::zeros(g, g),
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
        let g = self.g;
        // Periods and end directions of every tree edge.
        let mut dirs: Vec<(C, C)> = Vec::with_capacity(self.tree.len());
        let mut periods = Vec::with_capacity(self.tree.len());
        for &(p, q) in &self.tree {
            let (per, dp, dq) = self.edge_period(p, q)?;
            periods.push(per);
            dirs.push((dp, dq));
        }
        let cycle_edges = self.cycle_edges_of()?;
        let c = self.intersection_numbers(&cycle_edges, &dirs);
        let msym = basis::symplectic_reduction(&c)?;
        let (a, b) = canonical_periods(&periods, &cycle_edges, &msym, g);
        // The periods of x^k dx / y scale like |e|^{k+1-n/2}: branch points of
        // magnitude ~1e-150 or ~1e150 put them beyond the double range. Name
        // that cause (the scale) rather than the NaN it leaves in Im tau.
        if !a
            .iter()
            .chain(b.iter())
            .all(|v| v.re.is_finite() && v.im.is_finite())
            || a.iter().all(|v| v.modulus() == 0.0)
        {
            let scale = self.e_abs.iter().fold(0.0f64, |m, &v| m.max(v));
            return Err(Error::InvalidArgument {
                what: "branch_points",
                reason: format!(
                    "the periods of the curve are not finite in double precision at this \
                     scale (largest |e_k| = {}): rescale x (e_k -> e_k / s) first",
                    crate::error::num(scale)
                ),
            });
        }
        let a_inv = a
            .clone()
            .try_inverse()
            .ok_or_else(|| Error::InvalidArgument {
                what: "branch_points",
                reason: "the a-period matrix is singular (inaccurate periods)".into(),
            })?;
        let (tau, im_tau_inv) = tau_of(&a_inv, &b, g)?;
        self.im_tau_inv = im_tau_inv;
        self.tau_flat = (0..g * g).map(|k| tau[(k / g, k % g)]).collect();
        self.cycle_edges = cycle_edges;
        self.intersection = c;
        self.symplectic = msym;
        let rs: Vec<f64> = (0..g).map(|i| self.period_row_scale(i)).collect();
        let row = |m: &DMatrix<C>| DMatrix::from_fn(g, g, |i, j| m[(i, j)] * rs[i]);
        self.a_user = row(&a);
        self.b_user = row(&b);
        self.a = a;
        self.b = b;
        self.a_inv = a_inv;
        self.tau = tau;
        self.edge_periods = periods;
        self.base_points()?;
        Ok(())
    }

    /// The tree edges whose loops form a basis of the homology. Odd `n`: the
    /// `2g` edges of the tree on the finite branch points. Even `n`: the
    /// `2g + 1` edges satisfy one relation; a leaf edge is dropped (then the
    /// tree spans `2g + 1` of the `2g + 2` branch points, a basis).
    fn cycle_edges_of(&self) -> Result<Vec<usize>> {
        let n = self.e.len();
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
        Ok(cycle_edges)
    }

    /// The intersection numbers of the loops of `cycle_edges`: `±1` for two
    /// edges sharing a branch point, by the orientation of their end
    /// directions `dirs` there; 0 otherwise.
    fn intersection_numbers(&self, cycle_edges: &[usize], dirs: &[(C, C)]) -> Vec<Vec<i64>> {
        let m = 2 * self.g;
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
        c
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
        // A branch point within a tiny fraction of the segment's length of one
        // of its ends (a cluster, or a point far from the rest seen from it):
        // `mid − e_k ± h` rounds that offset away (to 0 at 1e-16 of the
        // length), which put the end directions below at 0 and the
        // intersection numbers wrong. Then the factors take the exact offsets
        // `e_p − e_k`, `e_q − e_k` at the ends (elsewhere, as before, the same bits).
        let near_end = others.iter().any(|&k| {
            (self.e[p] - self.e[k])
                .modulus()
                .min((self.e[q] - self.e[k]).modulus())
                < NEAR_END_FRACTION * (2.0 * h).modulus()
        });
        let start = |k: usize| {
            if near_end {
                self.e[p] - self.e[k]
            } else {
                mid - self.e[k] - h
            }
        };
        let segs: Vec<SegmentSqrt> = others
            .iter()
            .map(|&k| SegmentSqrt::new(start(k), 2.0 * h))
            .collect();
        let unrot: C = segs.iter().map(|s| s.unrot()).product();
        let prod_at = |t: f64| -> C {
            others
                .iter()
                .zip(&segs)
                .map(|(&k, s)| s.rotated(mid - self.e[k] + h * t))
                .product::<C>()
        };
        let prod_at_end = |end: usize, t: f64| -> C {
            if near_end {
                others
                    .iter()
                    .zip(&segs)
                    .map(|(&k, s)| s.rotated(self.e[end] - self.e[k]))
                    .product::<C>()
            } else {
                prod_at(t)
            }
        };
        let i_unit = C::new(0.0, 1.0);
        let dp = i_unit * h * unrot * prod_at_end(p, -1.0);
        let dq = -i_unit * h * unrot * prod_at_end(q, 1.0);
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
}

/// The `a`- and `b`-period matrices `A`, `B` (`g × g`) of the canonical basis
/// `msym` (rows: integer combinations of the loops of `cycle_edges`).
fn canonical_periods(
    periods: &[Vec<C>],
    cycle_edges: &[usize],
    msym: &[Vec<i64>],
    g: usize,
) -> (DMatrix<C>, DMatrix<C>) {
    let mut a = DMatrix::<C>::zeros(g, g);
    let mut b = DMatrix::<C>::zeros(g, g);
    for j in 0..2 * g {
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
    (a, b)
}

/// `τ = A^{-1} B`, symmetrised, and `(Im τ)^{-1}`.
///
/// Errors: `Im τ` not positive definite (a guard; never seen).
fn tau_of(a_inv: &DMatrix<C>, b: &DMatrix<C>, g: usize) -> Result<(DMatrix<C>, DMatrix<f64>)> {
    let mut tau = a_inv * b;
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
    Ok((tau, chol.inverse()))
}
