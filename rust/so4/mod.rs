//! The Euler–Frahm top on so(4) and so(n): vector field (1), Poisson bracket (3),
//! Hamiltonian (4), integrals (6)–(7), Manakov's coefficients (2).
//!
//! **State.** An angular momentum `l ∈ so(n)` is stored as its strict upper
//! triangle in row-major order, `(l12, l13, …, l1n, l23, …, l(n-1)n)`, of
//! length `n(n-1)/2`; `l_ji = -l_ij`. For `n = 4` this is
//! `(l12, l13, l14, l23, l24, l34)` and the code has a fixed-size fast path on
//! `[f64; 6]`.
//!
//! **Sign.** Equation (1), `l̇ = [l, ω]` with `ω_ij = c_ij l_ij`, is the
//! Hamiltonian flow `l̇_q = {H, l_q} = Σ_p ∂H/∂l_p {l_p, l_q}` of (4) under the
//! bracket (3) exactly as printed, sign included (checked in the tests here and
//! in `tests/test_dynamics.py`).
//!
//! **Erratum (7).** As printed, `H3 = Σ_{j<k} a_j a_k l_jk²` is not conserved.
//! The conserved forms consistent with Schottky's generating function (15) use
//! the complementary pair `{l, m} = {1,2,3,4} \ {j, k}`:
//! `H2 = Σ_{j<k} (a_l + a_m) l_jk²`, `H3 = Σ_{j<k} a_l a_m l_jk²`
//! (see `docs/errata.md`). [`integrals4`] returns the corrected forms.

// Index loops mirror the subscripts of the formulas (i, j stages; k components).
#![allow(clippy::needless_range_loop)]

use crate::error::{check_finite, Error, Result};
use crate::numeric::compensated::dot2;

/// Length of the so(4) state vector.
pub const DIM4: usize = 6;

/// The index pairs `(i, j)`, `i < j`, of the so(4) state, 0-based, in state order.
pub const PAIRS4: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Dimension `n(n-1)/2` of so(n).
pub fn state_dim(n: usize) -> usize {
    n * n.saturating_sub(1) / 2
}

/// Position of `l_ij` (`i < j`, 0-based) in the row-major upper-triangle state of so(n).
#[inline]
pub fn pair_index(n: usize, i: usize, j: usize) -> usize {
    // Rows 0..i hold (n-1) + (n-2) + ... + (n-i) entries.
    i * (2 * n - i - 1) / 2 + (j - i - 1)
}

/// The `n` with `n(n-1)/2 = m`, if any (`n ≥ 2`; O(1) in `m`).
pub fn n_from_state_dim(m: usize) -> Option<usize> {
    // n = (1 + sqrt(1 + 8m))/2, rounded, then checked exactly (the square root
    // of a double is within one of the integer root for every usize m).
    let guess = ((1.0 + (1.0 + 8.0 * m as f64).sqrt()) / 2.0).round() as usize;
    (guess.saturating_sub(1)..=guess + 1).find(|&n| n >= 2 && n.checked_mul(n - 1) == Some(2 * m))
}

/// Largest `n` of a top on so(n). One evaluation of (1) costs ~`n³` ns and an
/// integrator checks for Ctrl-C every `numeric::cancel::CHECK_EVERY` steps of
/// up to ~120 evaluations (gauss16): at `n = 32` that is ~0.25 s, within the
/// 0.5 s promised; Manakov's integrals (`n⁵`) stay at ~30 ms a state.
pub const MAX_N: usize = 32;

/// Refuses `n` above [`MAX_N`] (checked before anything of size `n²` is built).
pub fn check_n(what: &'static str, n: usize) -> Result<()> {
    if n > MAX_N {
        return Err(Error::InvalidArgument {
            what,
            reason: format!(
                "a top on so(n) with n = {n}: n must be at most {MAX_N} (the cost of \
                 Frahm's equations grows like n^3)"
            ),
        });
    }
    Ok(())
}

/// Entry `L_ik` of the full skew matrix of the state `l` of so(n).
#[inline]
fn skew_entry(n: usize, l: &[f64], i: usize, k: usize) -> f64 {
    match i.cmp(&k) {
        std::cmp::Ordering::Less => l[pair_index(n, i, k)],
        std::cmp::Ordering::Greater => -l[pair_index(n, k, i)],
        std::cmp::Ordering::Equal => 0.0,
    }
}

/// The full `n × n` skew matrix (row-major) of a state `l` of so(n).
pub fn to_matrix(n: usize, l: &[f64]) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        for k in 0..n {
            m[i * n + k] = skew_entry(n, l, i, k);
        }
    }
    m
}

/// Manakov's coefficients (2), `c_ij = (b_i - b_j)/(a_i - a_j)`, as a symmetric
/// `n × n` row-major matrix with zero diagonal.
///
/// Accuracy: when `a_i` and `a_j` are within a factor 2 of each other (the
/// nearly degenerate case) the difference `a_i - a_j` of the two doubles is
/// exact (Sterbenz's lemma), and likewise for `b`; so `c_ij` is the correctly
/// rounded quotient of exact differences of the given doubles. No rewriting can
/// do better: what is lost in that case was lost when the decimal inputs were
/// rounded to doubles (the condition number of `a ↦ c_ij` is
/// `|a_i| / |a_i - a_j|`).
///
/// Errors: `Shape` unless `a`, `b` have the same length `n ≥ 3`; `NonFinite`;
/// `RepeatedA { i, j }` if `a_i == a_j`; `InvalidArgument` if a difference
/// `a_i - a_j` overflows; `NonFinite` if a quotient overflows.
pub fn manakov_c(a: &[f64], b: &[f64]) -> Result<Vec<f64>> {
    let n = a.len();
    if b.len() != n {
        return Err(Error::Shape {
            what: "b",
            expected: format!("({n},) like a"),
            got: format!("({},)", b.len()),
        });
    }
    if n < 3 {
        return Err(Error::Shape {
            what: "a",
            expected: "(n,) with n >= 3".into(),
            got: format!("({n},)"),
        });
    }
    check_n("a", n)?;
    check_finite("a", a)?;
    check_finite("b", b)?;
    let mut c = vec![0.0; n * n];
    for i in 0..n {
        for j in i + 1..n {
            let da = a[i] - a[j];
            if da == 0.0 {
                return Err(Error::RepeatedA { i, j, value: a[i] });
            }
            // An overflowed difference would make c_ij = 0 silently.
            if !da.is_finite() {
                return Err(Error::InvalidArgument {
                    what: "a",
                    reason: format!(
                        "a[{i}] - a[{j}] = {} - {} overflows; rescale a and b \
                         (c_ij is invariant under a, b -> s a, s b)",
                        a[i], a[j]
                    ),
                });
            }
            let v = (b[i] - b[j]) / da;
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    what: "c = (b_i - b_j)/(a_i - a_j) (overflow)",
                    index: i * n + j,
                });
            }
            c[i * n + j] = v;
            c[j * n + i] = v;
        }
    }
    Ok(c)
}

/// Relative asymmetry tolerated in a user's `c`: a few ulps, so that a matrix
/// computed as `(x_i ⊕ x_j)` in two orders passes, while any modelling mistake
/// (a genuinely non-symmetric inertia) is rejected.
pub const SYMMETRY_RTOL: f64 = 8.0 * f64::EPSILON;

/// The Euler–Frahm top (1) on so(n) with symmetric coefficients `c_ij = I_ij^{-1}`.
#[derive(Debug, Clone, PartialEq)]
pub struct FrahmTop {
    n: usize,
    /// `c_ij` for `i < j` in state order (the diagonal of `c` never enters (1) or (4)).
    cv: Vec<f64>,
    /// For `n = 4`: the six `c_ij` of the fast path, see [`vector_field4`].
    c4: Option<[f64; 6]>,
    /// The full symmetric `c` with zero diagonal, row-major (general path).
    cfull: Vec<f64>,
}

/// Bodies up to this dimension evaluate (1) on a stack copy of the skew matrix.
const SMALL_N: usize = 16;

impl FrahmTop {
    /// A top from a symmetric `n × n` row-major `c`; `n ≥ 3`.
    ///
    /// The upper triangle is used; the diagonal must be finite but is not used.
    /// Errors: `Shape`, `NonFinite`, `NotSymmetric` (if
    /// `|c_ij - c_ji| > SYMMETRY_RTOL · max(|c_ij|, |c_ji|)`).
    pub fn new(n: usize, c: &[f64]) -> Result<Self> {
        if n < 3 || c.len() != n * n {
            return Err(Error::Shape {
                what: "c",
                expected: "(n, n) with n >= 3".into(),
                got: format!("{} entries for n = {n}", c.len()),
            });
        }
        check_n("c", n)?;
        check_finite("c", c)?;
        let mut max_asym: f64 = 0.0;
        let mut bad = false;
        for i in 0..n {
            for j in i + 1..n {
                let (x, y) = (c[i * n + j], c[j * n + i]);
                let d = (x - y).abs();
                max_asym = max_asym.max(d);
                if d > SYMMETRY_RTOL * x.abs().max(y.abs()) {
                    bad = true;
                }
            }
        }
        if bad {
            return Err(Error::NotSymmetric {
                what: "c",
                max_asym,
            });
        }
        let mut cv = Vec::with_capacity(state_dim(n));
        for i in 0..n {
            for j in i + 1..n {
                cv.push(c[i * n + j]);
            }
        }
        let c4 = if n == 4 {
            let mut a = [0.0; 6];
            a.copy_from_slice(&cv);
            Some(a)
        } else {
            None
        };
        let mut cfull = vec![0.0; n * n];
        for i in 0..n {
            for j in i + 1..n {
                cfull[i * n + j] = c[i * n + j];
                cfull[j * n + i] = c[i * n + j];
            }
        }
        Ok(FrahmTop { n, cv, c4, cfull })
    }

    /// Manakov's top: `c` from (2), see [`manakov_c`].
    pub fn manakov(a: &[f64], b: &[f64]) -> Result<Self> {
        let c = manakov_c(a, b)?;
        Self::new(a.len(), &c)
    }

    /// The dimension `n` of the body.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Length `n(n-1)/2` of the state.
    pub fn dim(&self) -> usize {
        self.cv.len()
    }

    /// For `n = 4`, the six `c_ij` (`i < j`) in state order.
    #[inline(always)]
    pub fn c4(&self) -> Option<&[f64; 6]> {
        self.c4.as_ref()
    }

    /// `c_ij` for `i < j` in state order.
    pub fn c_upper(&self) -> &[f64] {
        &self.cv
    }

    /// The vector field (1), `l̇_ij = Σ_k (l_ik ω_kj - ω_ik l_kj)`, `ω_ij = c_ij l_ij`.
    ///
    /// `l` and `out` have length [`FrahmTop::dim`] (checked by the caller; a
    /// mismatch panics in debug builds only through slice indexing, so callers
    /// validate shapes first).
    #[inline(always)]
    pub fn vector_field(&self, l: &[f64], out: &mut [f64]) {
        if let (Some(c), Ok(l4), Ok(o4)) = (
            &self.c4,
            <&[f64; 6]>::try_from(l),
            <&mut [f64; 6]>::try_from(&mut *out),
        ) {
            *o4 = vector_field4(c, l4);
            return;
        }
        let n = self.n;
        if n <= SMALL_N {
            // Full skew matrix on the stack: no allocation, no index arithmetic
            // in the O(n³) loop.
            let mut lm = [0.0; SMALL_N * SMALL_N];
            let mut p = 0;
            for i in 0..n {
                for j in i + 1..n {
                    lm[i * n + j] = l[p];
                    lm[j * n + i] = -l[p];
                    p += 1;
                }
            }
            let c = &self.cfull;
            let mut p = 0;
            for i in 0..n {
                for j in i + 1..n {
                    // (1) with ω_kj = c_kj l_kj:  l̇_ij = Σ_k l_ik l_kj (c_kj - c_ik);
                    // the k = i, j terms vanish (l_ii = 0, c_jj - c_ij multiplies l_jj = 0).
                    let mut s = 0.0;
                    for k in 0..n {
                        s += lm[i * n + k] * lm[k * n + j] * (c[k * n + j] - c[i * n + k]);
                    }
                    out[p] = s;
                    p += 1;
                }
            }
            return;
        }
        // (1) with ω_kj = c_kj l_kj:  l̇_ij = Σ_k l_ik l_kj (c_kj - c_ik).
        let cc = |i: usize, k: usize| -> f64 {
            match i.cmp(&k) {
                std::cmp::Ordering::Less => self.cv[pair_index(n, i, k)],
                std::cmp::Ordering::Greater => self.cv[pair_index(n, k, i)],
                std::cmp::Ordering::Equal => 0.0,
            }
        };
        let mut p = 0;
        for i in 0..n {
            for j in i + 1..n {
                let mut s = 0.0;
                for k in 0..n {
                    if k == i || k == j {
                        continue;
                    }
                    s += skew_entry(n, l, i, k) * skew_entry(n, l, k, j) * (cc(k, j) - cc(i, k));
                }
                out[p] = s;
                p += 1;
            }
        }
    }

    /// The Hamiltonian (4), `H = ½ Σ_{j<k} c_jk l_jk²`.
    pub fn hamiltonian(&self, l: &[f64]) -> f64 {
        0.5 * self.cv.iter().zip(l).map(|(c, x)| c * x * x).sum::<f64>()
    }
}

/// The so(4) vector field (1) on the fixed-size state, `c` the six `c_ij`
/// (`i < j`) in state order: `l̇_ij = Σ_{k ∉ {i,j}} l_ik l_kj (c_kj - c_ik)`.
#[inline(always)]
pub fn vector_field4(c: &[f64; 6], l: &[f64; 6]) -> [f64; 6] {
    let [l12, l13, l14, l23, l24, l34] = *l;
    let [c12, c13, c14, c23, c24, c34] = *c;
    // Each component has two terms, k running over the complementary pair;
    // l_ki = -l_ik supplies the signs.
    [
        // (1,2): k = 3, 4
        l13 * (-l23) * (c23 - c13) + l14 * (-l24) * (c24 - c14),
        // (1,3): k = 2, 4
        l12 * l23 * (c23 - c12) + l14 * (-l34) * (c34 - c14),
        // (1,4): k = 2, 3
        l12 * l24 * (c24 - c12) + l13 * l34 * (c34 - c13),
        // (2,3): k = 1, 4
        (-l12) * l13 * (c13 - c12) + l24 * (-l34) * (c34 - c24),
        // (2,4): k = 1, 3
        (-l12) * l14 * (c14 - c12) + l23 * l34 * (c34 - c23),
        // (3,4): k = 1, 2
        (-l13) * l14 * (c14 - c13) + (-l23) * l24 * (c24 - c23),
    ]
}

/// [`vector_field4`] at `S` states at once, component-major (`l[k][i]` is
/// component `k` of state `i`), written lane-wise so that it vectorises.
#[inline(always)]
pub fn vector_field4_lanes<const S: usize>(
    c: &[f64; 6],
    l: &[[f64; S]; 6],
    out: &mut [[f64; S]; 6],
) {
    let [c12, c13, c14, c23, c24, c34] = *c;
    let (d1, d2) = (c23 - c13, c24 - c14);
    let (d3, d4) = (c23 - c12, c34 - c14);
    let (d5, d6) = (c24 - c12, c34 - c13);
    let (d7, d8) = (c13 - c12, c34 - c24);
    let (d9, d10) = (c14 - c12, c34 - c23);
    let (d11, d12) = (c14 - c13, c24 - c23);
    let [l12, l13, l14, l23, l24, l34] = l;
    for i in 0..S {
        // The same terms as vector_field4, with the c differences hoisted.
        out[0][i] = -(l13[i] * l23[i] * d1 + l14[i] * l24[i] * d2);
        out[1][i] = l12[i] * l23[i] * d3 - l14[i] * l34[i] * d4;
        out[2][i] = l12[i] * l24[i] * d5 + l13[i] * l34[i] * d6;
        out[3][i] = -(l12[i] * l13[i] * d7 + l24[i] * l34[i] * d8);
        out[4][i] = l23[i] * l34[i] * d10 - l12[i] * l14[i] * d9;
        out[5][i] = -(l13[i] * l14[i] * d11 + l23[i] * l24[i] * d12);
    }
}

/// The Poisson tensor of the so(n) bracket (3):
/// `P[(ij),(km)] = {l_ij, l_km} = l_im δ_jk - l_ik δ_jm + l_jk δ_im - l_jm δ_ik`,
/// for `i < j`, `k < m` in state order; `out` is `dim × dim` row-major.
pub fn poisson_tensor(n: usize, l: &[f64], out: &mut [f64]) {
    let d = |x: usize, y: usize| if x == y { 1.0 } else { 0.0 };
    let m = state_dim(n);
    let mut p = 0;
    for i in 0..n {
        for j in i + 1..n {
            let mut q = 0;
            for k in 0..n {
                for mm in k + 1..n {
                    out[p * m + q] = skew_entry(n, l, i, mm) * d(j, k)
                        - skew_entry(n, l, i, k) * d(j, mm)
                        + skew_entry(n, l, j, k) * d(i, mm)
                        - skew_entry(n, l, j, mm) * d(i, k);
                    q += 1;
                }
            }
            p += 1;
        }
    }
}

/// `[H1 + 2 H0, H1 − 2 H0]` as the sums of squares they are,
/// `H1 ± 2H0 = (l12 ± l34)² + (l14 ± l23)² + (l13 ∓ l24)²`, i.e. `2|m|²` and
/// `2|n|²` of the self-dual and anti-self-dual parts of `l`: each to full
/// relative accuracy (a difference of nearby components is exact), where
/// `H1² − 4H0²`, their product, formed from `H0` and `H1` cancels to rounding
/// near the self-dual states `m = ±n` (a one-factor rotation, `n = 0` or `m = 0`).
///
/// The terms are summed in the order of `|m ± n|²` with Kötter's `m = (l23,
/// −l13, l12)`, `n = (l14, l24, l34)` (13), so that the reduction's
/// denominator of (19), `|m − n|² |m + n|²`, is this product to the bit.
pub fn casimir_factors(l: &[f64; 6]) -> [f64; 2] {
    let [l12, l13, l14, l23, l24, l34] = *l;
    let sq = |x: f64, y: f64, z: f64| x * x + y * y + z * z;
    [
        sq(l23 + l14, l24 - l13, l12 + l34),
        sq(l23 - l14, l13 + l24, l12 - l34),
    ]
}

/// `|h1² − 4h0²| ≤ SINGULAR_SET_RTOL (h1² + 4h0²)` in terms of the factors
/// `h1 ± 2h0` of [`casimir_factors`] (`h1² + 4h0² = (hp² + hm²)/2`),
/// as a ratio so that no square overflows.
pub fn near_self_dual(hp: f64, hm: f64) -> bool {
    let (lo, hi) = (hp.min(hm), hp.max(hm));
    let r = lo / hi;
    r <= crate::numeric::tol::SINGULAR_SET_RTOL * 0.5 * (1.0 + r * r)
}

/// The so(4) integrals, corrected where (7) is misprinted (see the module docs):
/// `[H0, H1, H2, H3]` with
/// `H0 = l12 l34 + l23 l14 + l31 l24` (6),
/// `H1 = Σ l_jk²`, `H2 = Σ (a_l + a_m) l_jk²`, `H3 = Σ a_l a_m l_jk²` (7, corrected),
/// `{l, m}` the complement of `{j, k}` in `{1, 2, 3, 4}`.
pub fn integrals4(a: &[f64; 4], l: &[f64; 6]) -> [f64; 4] {
    let [l12, l13, l14, l23, l24, l34] = *l;
    // H0 is a sum of products that cancels on and near rank-2 states (h0 = 0,
    // Moser's case), where the reduction needs it to full relative accuracy:
    // summed compensated, it is the correctly rounded value up to a few ulps.
    let h0 = dot2(&[l12, l23, -l13], &[l34, l14, l24]);
    let mut h1 = 0.0;
    let mut h2 = 0.0;
    let mut h3 = 0.0;
    for (p, &(j, k)) in PAIRS4.iter().enumerate() {
        // The complementary pair of (j, k) is the pair at position 5 - p.
        let (u, v) = PAIRS4[5 - p];
        debug_assert!(u != j && u != k && v != j && v != k);
        let x2 = l[p] * l[p];
        h1 += x2;
        h2 += (a[u] + a[v]) * x2;
        h3 += a[u] * a[v] * x2;
    }
    [h0, h1, h2, h3]
}

/// Labels `(k, j)` of Manakov's integrals on so(n) returned by
/// [`manakov_integrals`]: the coefficient of `λ^j` in `tr (l + λ A)^k`,
/// for `k = 2..=n` and `0 ≤ j ≤ k - 2` with `k - j` even (the others vanish
/// identically or are constants `tr A^k`).
pub fn manakov_integral_labels(n: usize) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    for k in 2..=n {
        for j in 0..=k.saturating_sub(2) {
            if (k - j) % 2 == 0 {
                v.push((k, j));
            }
        }
    }
    v
}

/// Manakov's integrals [Ma 1977]: the coefficients of `λ^j` in the polynomial
/// `tr (l + λ A)^k`, `A = diag(a)`, labelled by [`manakov_integral_labels`].
///
/// They are conserved by (1) with `c` from (2) because `l̇ = [l, ω]` is
/// equivalent to the Lax equation `d/dt (l + λA) = [l + λA, ω + λB]`, `B = diag(b)`.
/// Allocates `O(n² · n)` scratch; meant for checks and diagnostics, not inner loops.
pub fn manakov_integrals(a: &[f64], l: &[f64]) -> Vec<f64> {
    let n = a.len();
    let lm = to_matrix(n, l);
    // pw[d] = coefficient of λ^d of (l + λA)^k, an n×n row-major matrix.
    let mut pw: Vec<Vec<f64>> = vec![lm.clone(), diag(a)];
    let labels = manakov_integral_labels(n);
    let mut out = Vec::with_capacity(labels.len());
    for k in 2..=n {
        // (l + λA)^k = (l + λA)^{k-1} (l + λA): coefficient d gets P[d] l + P[d-1] A.
        let mut next = vec![vec![0.0; n * n]; k + 1];
        for (d, pd) in pw.iter().enumerate() {
            matmul_acc(n, pd, &lm, &mut next[d]);
            // Right multiplication by diag(a) scales column c by a_c.
            for r in 0..n {
                for cidx in 0..n {
                    next[d + 1][r * n + cidx] += pd[r * n + cidx] * a[cidx];
                }
            }
        }
        pw = next;
        for &(kk, j) in labels.iter().filter(|(kk, _)| *kk == k) {
            let _ = kk;
            out.push((0..n).map(|r| pw[j][r * n + r]).sum());
        }
    }
    out
}

fn diag(a: &[f64]) -> Vec<f64> {
    let n = a.len();
    let mut m = vec![0.0; n * n];
    for (i, &x) in a.iter().enumerate() {
        m[i * n + i] = x;
    }
    m
}

fn matmul_acc(n: usize, x: &[f64], y: &[f64], out: &mut [f64]) {
    for i in 0..n {
        for k in 0..n {
            let xik = x[i * n + k];
            if xik == 0.0 {
                continue;
            }
            for j in 0..n {
                out[i * n + j] += xik * y[k * n + j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    const GENERIC_A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
    const GENERIC_B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];

    #[test]
    fn casimir_factors_are_h1_plus_minus_2h0_and_exact_on_the_self_dual_sets() {
        let l = [0.7, -0.5, 0.3, 0.3, 0.5, 0.7];
        let [p, m] = casimir_factors(&l);
        let h = integrals4(&GENERIC_A, &l);
        assert_relative_eq!(p, h[1] + 2.0 * h[0], max_relative = 1e-15);
        assert_eq!(m, 0.0);
        // 2^-30 off the set: H1 - 2 H0 = 0.83 · 2^-60 exactly, which H1 - 2 H0
        // formed from the integrals loses entirely.
        let e = 1.0 + 2f64.powi(-30);
        let l = [0.7, -0.5, 0.3 * e, 0.3, 0.5 * e, 0.7 * e];
        let [_, m] = casimir_factors(&l);
        let exact = (0.49 + 0.25 + 0.09) * 2f64.powi(-60);
        assert_relative_eq!(m, exact, max_relative = 1e-14);
    }

    /// Independent (1): build the matrices and form l ω - ω l.
    fn vf_matrix(n: usize, c: &[f64], l: &[f64]) -> Vec<f64> {
        let lm = to_matrix(n, l);
        let w: Vec<f64> = (0..n * n).map(|i| c[i] * lm[i]).collect();
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += lm[i * n + k] * w[k * n + j] - w[i * n + k] * lm[k * n + j];
                }
                out.push(s);
            }
        }
        out
    }

    #[test]
    fn pair_index_is_row_major_upper_triangle() {
        for n in 3..8 {
            let mut p = 0;
            for i in 0..n {
                for j in i + 1..n {
                    assert_eq!(pair_index(n, i, j), p);
                    p += 1;
                }
            }
            assert_eq!(n_from_state_dim(state_dim(n)), Some(n));
        }
        assert_eq!(n_from_state_dim(7), None);
    }

    #[test]
    fn rejects_repeated_a_naming_the_pair() {
        let e = manakov_c(&[1.0, 2.0, 1.0, 3.0], &[0.0, 1.0, 2.0, 3.0]).unwrap_err();
        assert_eq!(
            e,
            Error::RepeatedA {
                i: 0,
                j: 2,
                value: 1.0
            }
        );
    }

    #[test]
    fn rejects_asymmetric_c() {
        let mut c = vec![0.0; 16];
        c[1] = 1.0;
        c[4] = 1.5;
        assert!(matches!(
            FrahmTop::new(4, &c),
            Err(Error::NotSymmetric { .. })
        ));
    }

    #[test]
    fn near_degenerate_c_is_the_rounded_exact_quotient() {
        let a = [1.0, 1.000001, 2.0, 3.0];
        let b = [0.3, 0.300002, -0.4, 1.2];
        let c = manakov_c(&a, &b).unwrap();
        // Sterbenz: both differences are exact, so c12 is one rounding away from the truth.
        assert_eq!(c[1], (b[0] - b[1]) / (a[0] - a[1]));
        assert_relative_eq!(c[1], 2.0, max_relative = 1e-9);
    }

    proptest! {
        #[test]
        fn fast_so4_path_matches_matrix_form(
            l in prop::array::uniform6(-2.0f64..2.0),
            b in prop::array::uniform4(-2.0f64..2.0),
        ) {
            let top = FrahmTop::manakov(&GENERIC_A, &b).unwrap();
            let c = manakov_c(&GENERIC_A, &b).unwrap();
            let mut out = [0.0; 6];
            top.vector_field(&l, &mut out);
            let want = vf_matrix(4, &c, &l);
            for (x, y) in out.iter().zip(&want) {
                prop_assert!((x - y).abs() <= 1e-13 * (1.0 + y.abs()));
            }
        }

        #[test]
        fn lane_form_matches_single_states(
            l in prop::collection::vec(-2.0f64..2.0, 48),
            b in prop::array::uniform4(-2.0f64..2.0),
        ) {
            let top = FrahmTop::manakov(&GENERIC_A, &b).unwrap();
            let mut y = [[0.0; 8]; 6];
            for k in 0..6 {
                for i in 0..8 {
                    y[k][i] = l[8 * k + i];
                }
            }
            let mut out = [[0.0; 8]; 6];
            vector_field4_lanes(top.c4().unwrap(), &y, &mut out);
            for i in 0..8 {
                let li: [f64; 6] = std::array::from_fn(|k| y[k][i]);
                let want = vf_matrix(4, &manakov_c(&GENERIC_A, &b).unwrap(), &li);
                for k in 0..6 {
                    prop_assert!((out[k][i] - want[k]).abs() <= 1e-13 * (1.0 + want[k].abs()));
                }
            }
        }

        #[test]
        fn vector_field_is_hamiltonian_flow_of_h(
            l in prop::collection::vec(-2.0f64..2.0, 10),
            b in prop::collection::vec(-2.0f64..2.0, 5),
        ) {
            let n = 5;
            let a = [0.1, 0.7, 1.3, 2.9, 4.0];
            let top = FrahmTop::manakov(&a, &b).unwrap();
            let m = top.dim();
            let mut p = vec![0.0; m * m];
            poisson_tensor(n, &l, &mut p);
            // {H, l_q} = Σ_p ∂H/∂l_p P[p][q], ∂H/∂l_p = c_p l_p.
            let mut f = vec![0.0; m];
            top.vector_field(&l, &mut f);
            for q in 0..m {
                let s: f64 = (0..m).map(|pp| top.c_upper()[pp] * l[pp] * p[pp * m + q]).sum();
                prop_assert!((s - f[q]).abs() <= 1e-12 * (1.0 + f[q].abs()));
            }
        }

        #[test]
        fn corrected_integrals_have_zero_derivative_along_1(
            l in prop::array::uniform6(-2.0f64..2.0),
        ) {
            let top = FrahmTop::manakov(&GENERIC_A, &GENERIC_B).unwrap();
            let mut f = [0.0; 6];
            top.vector_field(&l, &mut f);
            // d/dt H_i = ∇H_i · f, gradient by central differences of a quadratic (exact up to rounding).
            let h = 1e-3;
            for idx in 0..4 {
                let mut d = 0.0;
                for p in 0..6 {
                    let mut lp = l; lp[p] += h;
                    let mut lm = l; lm[p] -= h;
                    d += (integrals4(&GENERIC_A, &lp)[idx] - integrals4(&GENERIC_A, &lm)[idx]) / (2.0 * h) * f[p];
                }
                prop_assert!(d.abs() < 1e-9, "dH{}/dt = {}", idx, d);
            }
        }
    }

    #[test]
    fn manakov_integral_k2_is_minus_twice_h1() {
        let l = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];
        let ints = manakov_integrals(&GENERIC_A, &l);
        assert_eq!(manakov_integral_labels(4)[0], (2, 0));
        let h1: f64 = l.iter().map(|x| x * x).sum();
        // tr l² = -2 Σ_{j<k} l_jk².
        assert_relative_eq!(ints[0], -2.0 * h1, max_relative = 1e-14);
    }
}
