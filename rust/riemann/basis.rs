//! The homology basis: a spanning tree of straight segments between branch
//! points, the intersection numbers of its lifted loops, and the symplectic
//! reduction to a canonical basis (Molin & Neurohr, Math. Comp. 88 (2019),
//! §3–4, specialised to `m = 2`; the intersection rule below is derived in
//! docs/riemann.md).

use crate::numeric::complex::Modulus;
use num_complex::Complex64;
use std::cmp::Ordering;

use super::quad::focal_half_sum;
use crate::error::{Error, Result};

type C = Complex64;

/// Edges whose segment passes within this ellipse parameter (`ln ρ`) of
/// another branch point are not used: the branch point is on the segment up
/// to rounding (`ln ρ ≈ √(2δ)` for a point at relative distance `δ` from the
/// segment's interior). A point near an *end* of the segment (a cluster of
/// branch points, or one far from the rest) is not on it: its quality is
/// computed from its offset to that end to full relative accuracy
/// ([`edge_quality`]), and the composite quadrature from that end resolves it
/// (docs/riemann.md, "Clusters"). So only an exact zero is refused here.
const MIN_EDGE_LOG_RHO: f64 = 0.0;

/// Below this `ρ`-excess `s − 1` (`s` the focal half sum) the quality is
/// recomputed from the offset of the point to the nearer end of the segment:
/// the plain `(|z − 1| + |z + 1|)/2 − 1` keeps only `u/(s − 1)` of its digits,
/// and at `s − 1 ≲ u` (a point `1e-16` of the segment's length from its end)
/// it is 0. Above, the plain form is used as it always was (same bits).
const ACCURATE_EXCESS_BELOW: f64 = 1e-3;

/// The `ρ`-excess `x` of [`log_rho_near_end`] is rounding noise below this many
/// ulps of `|w|/|v|` (a point on the segment's line inside it, where the two
/// terms of `x` cancel): the point is then on the segment.
const ON_SEGMENT_ULPS: f64 = 16.0;

/// Quality `ln ρ` of the segment `[p, q]`: the smallest ellipse parameter of
/// the other branch points in the coordinate `t`, `x = (p+q)/2 + t (q−p)/2`.
pub fn edge_quality(e: &[C], p: usize, q: usize) -> f64 {
    let mid = 0.5 * (e[p] + e[q]);
    let half = 0.5 * (e[q] - e[p]);
    e.iter()
        .enumerate()
        .filter(|&(m, _)| m != p && m != q)
        .map(|(_, &em)| {
            let fhs = focal_half_sum((em - mid) / half);
            if fhs - 1.0 < ACCURATE_EXCESS_BELOW {
                log_rho_near_end(e[p], e[q], em)
            } else {
                fhs.acosh()
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// `ln ρ` of the point `em` for the segment `[ep, eq]` from the offsets to
/// the nearer end. With `s = (|em − ep| + |em − eq|)/|ep − eq|` the focal
/// half sum, `x = s − 1` is, for `em` nearer `ep` (`w = em − ep`,
/// `v = ep − eq`), `(|w| + (|w + v| − |v|))/|v|` with
/// `|w + v| − |v| = (|w|² + 2 Re(w v̄))/(|w + v| + |v|)` — no difference of
/// nearly equal numbers — and `ln ρ = acosh(1 + x) = log1p(x + √(x(x + 2)))`.
fn log_rho_near_end(ep: C, eq: C, em: C) -> f64 {
    let (near, far) = if (em - ep).modulus() <= (em - eq).modulus() {
        (ep, eq)
    } else {
        (eq, ep)
    };
    let w = em - near;
    let v = near - far;
    let (aw, av, awv) = (w.modulus(), v.modulus(), (w + v).modulus());
    let x = (aw + (aw * aw + 2.0 * (w * v.conj()).re) / (awv + av)) / av;
    // Its rounding error is a few u |w|/|v|: below that the point lies on the
    // segment to rounding (x = 0, as the plain form has it), whatever its offset.
    if x.partial_cmp(&(ON_SEGMENT_ULPS * f64::EPSILON * aw / av)) != Some(Ordering::Greater) {
        return 0.0;
    }
    (x + (x * (x + 2.0)).sqrt()).ln_1p()
}
fn orient(a: C, b: C, c: C) -> f64 {
    ((b - a).conj() * (c - a)).im
}

/// Whether the segments `[a, b]` and `[c, d]` (no shared endpoint) cross
/// properly. Touching or overlapping needs an endpoint on the other segment,
/// which the edge quality already excludes (a branch point on a segment).
fn crosses(a: C, b: C, c: C, d: C) -> bool {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    o1 * o2 < 0.0 && o3 * o4 < 0.0
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// A spanning tree of non-crossing segments maximising the smallest edge
/// quality (Kruskal on the qualities in decreasing order, skipping edges that
/// would close a cycle or cross a chosen edge). A maximal set of
/// non-crossing segments is a triangulation, hence connected, so the greedy
/// choice always spans (docs/riemann.md).
pub fn spanning_tree(e: &[C]) -> Result<Vec<(usize, usize)>> {
    let n = e.len();
    let mut cand: Vec<(f64, usize, usize)> = Vec::with_capacity(n * (n - 1) / 2);
    for p in 0..n {
        for q in (p + 1)..n {
            let w = edge_quality(e, p, q);
            if w > MIN_EDGE_LOG_RHO {
                cand.push((w, p, q));
            }
        }
    }
    cand.sort_by(|x, y| y.0.total_cmp(&x.0));
    let mut parent: Vec<usize> = (0..n).collect();
    let mut tree: Vec<(usize, usize)> = Vec::with_capacity(n - 1);
    for &(_, p, q) in &cand {
        let (rp, rq) = (find(&mut parent, p), find(&mut parent, q));
        if rp == rq {
            continue;
        }
        let cross = tree
            .iter()
            .any(|&(s, t)| s != p && s != q && t != p && t != q && crosses(e[p], e[q], e[s], e[t]));
        if cross {
            continue;
        }
        parent[rp] = rq;
        tree.push((p, q));
        if tree.len() == n - 1 {
            return Ok(tree);
        }
    }
    Err(Error::InvalidArgument {
        what: "branch_points",
        reason: "no spanning tree of segments clear of the other branch points \
                 (branch points collinear and overlapping to rounding)"
            .into(),
    })
}

/// Reduces the integer skew form `c` (`m × m`, unimodular, `m = 2g`) to the
/// canonical one: returns `M` (rows `a_1..a_g, b_1..b_g` as integer
/// combinations of the original cycles) with `M c Mᵀ = J = [[0, I], [−I, 0]]`.
///
/// Symplectic Gram–Schmidt over `Z`: take the first remaining vector `v`,
/// run Euclid's algorithm on the remaining vectors' pairings with `v` until
/// one pairs to `±1` (the form is unimodular, so the gcd is 1), make the pair
/// `(v, w)` with `⟨v, w⟩ = 1` and project the rest off the pair.
pub fn symplectic_reduction(c: &[Vec<i64>]) -> Result<Vec<Vec<i64>>> {
    let m = c.len();
    let g = m / 2;
    let form = |x: &[i64], y: &[i64]| -> i64 {
        let mut s = 0;
        for i in 0..m {
            if x[i] == 0 {
                continue;
            }
            for j in 0..m {
                s += x[i] * c[i][j] * y[j];
            }
        }
        s
    };
    let bad = || Error::InvalidArgument {
        what: "branch_points",
        reason: "the intersection matrix of the loops is not unimodular \
                 (inconsistent geometry; please report)"
            .into(),
    };
    let mut rest: Vec<Vec<i64>> = (0..m)
        .map(|i| (0..m).map(|j| i64::from(i == j)).collect())
        .collect();
    let mut a_rows = Vec::with_capacity(g);
    let mut b_rows = Vec::with_capacity(g);
    while !rest.is_empty() {
        let v = rest.remove(0);
        // Euclid on the pairings ⟨v, u⟩ of the remaining vectors.
        loop {
            let pr: Vec<i64> = rest.iter().map(|u| form(&v, u)).collect();
            let nz: Vec<usize> = (0..rest.len()).filter(|&i| pr[i] != 0).collect();
            if nz.is_empty() {
                return Err(bad());
            }
            let k = *nz.iter().min_by_key(|&&i| pr[i].abs()).ok_or_else(bad)?;
            if nz.len() == 1 {
                if pr[k].abs() != 1 {
                    return Err(bad());
                }
                break;
            }
            for &i in &nz {
                if i != k {
                    let q = pr[i] / pr[k];
                    let uk = rest[k].clone();
                    for (x, y) in rest[i].iter_mut().zip(&uk) {
                        *x -= q * y;
                    }
                }
            }
        }
        let pr: Vec<i64> = rest.iter().map(|u| form(&v, u)).collect();
        let k = pr.iter().position(|&p| p != 0).ok_or_else(bad)?;
        let mut w = rest.remove(k);
        if pr[k] < 0 {
            w.iter_mut().for_each(|x| *x = -*x);
        }
        // Project: u' = u − ⟨u, w⟩ v + ⟨u, v⟩ w.
        for u in rest.iter_mut() {
            let (uw, uv) = (form(u, &w), form(u, &v));
            for i in 0..m {
                u[i] = u[i] - uw * v[i] + uv * w[i];
            }
        }
        a_rows.push(v);
        b_rows.push(w);
    }
    a_rows.extend(b_rows);
    Ok(a_rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reduction_of_a_chain_form_is_canonical() {
        // Chain of 4 loops, each meeting the next once: the genus-2 pattern.
        let mut c = vec![vec![0i64; 4]; 4];
        for i in 0..3 {
            c[i][i + 1] = 1;
            c[i + 1][i] = -1;
        }
        let m = symplectic_reduction(&c).unwrap();
        for i in 0..4 {
            for j in 0..4 {
                let mut s = 0;
                for k in 0..4 {
                    for l in 0..4 {
                        s += m[i][k] * c[k][l] * m[j][l];
                    }
                }
                let want = if j == i + 2 {
                    1
                } else if i == j + 2 {
                    -1
                } else {
                    0
                };
                assert_eq!(s, want, "({i},{j})");
            }
        }
    }

    #[test]
    fn tree_of_collinear_points_is_the_chain() {
        let e: Vec<C> = [0.0, 1.0, 2.5, 4.0, 7.0]
            .iter()
            .map(|&x| C::new(x, 0.0))
            .collect();
        let mut t = spanning_tree(&e).unwrap();
        t.sort();
        assert_eq!(t, vec![(0, 1), (1, 2), (2, 3), (3, 4)]);
    }
}
