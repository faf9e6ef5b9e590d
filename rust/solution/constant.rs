//! Constant solutions: the equilibria of Frahm's equations (1) for Manakov's
//! `c` (docs/degenerate.md §2).
//!
//! `l̇ = [l, ω]`, `ω_ij = c_ij l_ij`, reads componentwise
//!
//! ```text
//! l̇_ik = Σ_{j ∉ {i,k}} l_ij l_jk (c_jk − c_ij),
//! ```
//!
//! and for Manakov's `c` (2) the differences are second divided differences of
//! `b`: `c_jk − c_ij = (a_k − a_i) b[i,j,k]`. With `x = (l12, l34)`,
//! `y = (l13, l24)`, `z = (l14, l23)` and `B_m = b[i,j,k]` (`m` the index not in
//! `{i,j,k}`), `l̇ = 0` is the six bilinear equations
//!
//! ```text
//! B4 y1 z2 + B3 y2 z1 = 0,   B2 y1 z1 + B1 y2 z2 = 0,
//! B4 x1 z2 − B2 x2 z1 = 0,   B3 x1 z1 − B1 x2 z2 = 0,
//! B3 x1 y2 + B2 x2 y1 = 0,   B4 x1 y1 + B1 x2 y2 = 0,
//! ```
//!
//! whose real solutions (all `B_m ≠ 0`) are the three coordinate planes
//! `{x}`, `{y}`, `{z}` (Cartan subalgebras: single components, `l12 E12 + l34 E34`
//! and the like) and, when `B1 B2 B3 B4 > 0`, the two 3-dimensional subspaces
//! `V± = {z = ζ(1, r), x = ξ(B2, B4 r), y = η(B3, −B4 r)}`,
//! `r = ±√(B2 B3/(B1 B4))`; for `b` quadratic in `a` (all `B_m` equal)
//! `V±` are the self-dual subspaces `n = ±m`; a vanishing `B_m` makes the
//! so(3) block opposite `m` spherical (all of it at rest).
//!
//! The test here is that equation itself, to rounding: every component of
//! `l̇` must vanish to [`EQUILIBRIUM_RTOL`] of the sum of the moduli of its
//! terms. On the coordinate planes every term is an exact zero; on `V±`
//! (irrational in general) the terms cancel to the rounding of the state.

/// A state is an equilibrium when every `|l̇_ik|` is at most this fraction of
/// `Σ_j |l_ij l_jk (c_jk − c_ij)|`. Why `8 ε = 16 u`: a state on an
/// equilibrium subspace, rounded to doubles, has each product `l_ij l_jk`
/// within `2u` of its exact value, so its exact `l̇` is below `2u` of the
/// terms; the evaluation (one rounding for the difference of `c`, two for the
/// products, one for the sum) adds at most `4u`; the margin (×8/3) covers
/// states computed from the subspace's parametrisation by a few more
/// operations. A state off the set by more than ~1e-15 relative is not
/// caught: it moves, and is solved as such.
pub const EQUILIBRIUM_RTOL: f64 = 8.0 * f64::EPSILON;

/// Whether `l` is an equilibrium of (1) with coefficients `c4` (state order)
/// in the sense of [`EQUILIBRIUM_RTOL`] (exact zeros of `l̇` included).
pub fn is_equilibrium(c4: &[f64; 6], l: &[f64; 6]) -> bool {
    let (ldot, terms) = field_and_terms(c4, l);
    ldot.iter()
        .zip(&terms)
        .all(|(d, t)| d.abs() <= EQUILIBRIUM_RTOL * t)
}

/// `l̇` of (1) as `Σ_j l_ij l_jk (c_jk − c_ij)`, and `Σ_j |l_ij l_jk (c_jk − c_ij)|`
/// per component (state order).
pub fn field_and_terms(c4: &[f64; 6], l: &[f64; 6]) -> ([f64; 6], [f64; 6]) {
    const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    let mut lm = [[0.0f64; 4]; 4];
    let mut cm = [[0.0f64; 4]; 4];
    for (q, &(i, j)) in PAIRS.iter().enumerate() {
        lm[i][j] = l[q];
        lm[j][i] = -l[q];
        cm[i][j] = c4[q];
        cm[j][i] = c4[q];
    }
    let mut ldot = [0.0; 6];
    let mut terms = [0.0; 6];
    for (q, &(i, k)) in PAIRS.iter().enumerate() {
        for j in 0..4 {
            if j == i || j == k {
                continue;
            }
            let t = lm[i][j] * lm[j][k] * (cm[j][k] - cm[i][j]);
            ldot[q] += t;
            terms[q] += t.abs();
        }
    }
    (ldot, terms)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::so4;

    fn c4_of(a: &[f64; 4], b: &[f64; 4]) -> [f64; 6] {
        let c = so4::manakov_c(a, b).unwrap();
        [c[1], c[2], c[3], c[6], c[7], c[11]]
    }

    #[test]
    fn the_field_is_1() {
        for (a, b, l0) in crate::solution::tests::TOPS {
            let c4 = c4_of(&a, &b);
            let (f, _) = field_and_terms(&c4, &l0);
            let g = so4::vector_field4(&c4, &l0);
            for q in 0..6 {
                assert!((f[q] - g[q]).abs() < 1e-15, "{a:?}");
            }
            assert!(!is_equilibrium(&c4, &l0));
        }
    }

    #[test]
    fn coordinate_planes_and_the_subspaces_v_are_equilibria() {
        for (a, b, _) in crate::solution::tests::TOPS {
            let c4 = c4_of(&a, &b);
            // Coordinate planes: (l12, l34), (l13, l24), (l14, l23).
            for (p, q) in [(0, 5), (1, 4), (2, 3)] {
                let mut l = [0.0; 6];
                l[p] = 0.7;
                l[q] = -1.3;
                assert!(is_equilibrium(&c4, &l));
                assert_eq!(so4::vector_field4(&c4, &l), [0.0; 6]);
            }
            // V±: B_m = b[i,j,k] (m the index left out), from the c_ij the
            // test (1) sees: (c_jk − c_ij)/(a_k − a_i) over the widest pair.
            let cij = |i: usize, j: usize| {
                let pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
                let q = pairs
                    .iter()
                    .position(|&p| p == (i.min(j), i.max(j)))
                    .unwrap();
                c4[q]
            };
            let dd = |t: [usize; 3]| {
                // The two ends are the pair of the triple farthest apart in a.
                let mut best = (0.0, 0.0);
                for (i, k) in [(t[0], t[1]), (t[0], t[2]), (t[1], t[2])] {
                    let j = t.iter().copied().find(|&x| x != i && x != k).unwrap();
                    let w = (a[k] - a[i]).abs();
                    if w > best.0 {
                        best = (w, (cij(j, k) - cij(i, j)) / (a[k] - a[i]));
                    }
                }
                best.1
            };
            let bb = [dd([1, 2, 3]), dd([0, 2, 3]), dd([0, 1, 3]), dd([0, 1, 2])];
            let prod = bb.iter().product::<f64>();
            for sg in [1.0, -1.0] {
                let r = sg * (bb[1] * bb[2] / (bb[0] * bb[3])).abs().sqrt();
                let (xi, eta, zeta) = (0.3, -0.7, 1.1);
                // l = (x1, y1, z1, z2, y2, x2).
                let l = [
                    xi * bb[1],
                    eta * bb[2],
                    zeta,
                    zeta * r,
                    -eta * bb[3] * r,
                    xi * bb[3] * r,
                ];
                // Real only for B1 B2 B3 B4 > 0 ('wide' has none). On
                // near_degenerate the c_ij with a_1 ≈ a_2 carry 1e-10 of
                // rounding in their differences, so the doubles' equilibria
                // are only the slices below, not all of V± (tested there).
                if a[1] - a[0] > 1e-3 {
                    assert_eq!(is_equilibrium(&c4, &l), prod > 0.0, "{a:?}, r = {r}");
                }
                // A relative change of 1e-12 in one component leaves V.
                let mut l2 = l;
                l2[2] *= 1.0 + 1e-12;
                assert!(!is_equilibrium(&c4, &l2));
            }
            // The slice x = 0 of V±, from the two equations l̇_12 = l̇_34 = 0
            // with the c_ij themselves: (z2/z1)² = (c24 − c14)(c14 − c13) /
            // ((c23 − c13)(c24 − c23)), y ∝ (z1 (c24 − c14), −z2 (c23 − c13)).
            let q = (c4[4] - c4[2]) * (c4[2] - c4[1]) / ((c4[3] - c4[1]) * (c4[4] - c4[3]));
            if q > 0.0 {
                for sg in [1.0, -1.0] {
                    let (z1, z2) = (0.9, sg * 0.9 * q.sqrt());
                    let (y1, y2) = (0.6 * z1 * (c4[4] - c4[2]), -0.6 * z2 * (c4[3] - c4[1]));
                    let l = [0.0, y1, z1, z2, y2, 0.0];
                    assert!(is_equilibrium(&c4, &l), "{a:?}: slice");
                }
            }
        }
    }
}
