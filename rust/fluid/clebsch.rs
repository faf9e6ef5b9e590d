//! The Clebsch case: Kirchhoff's equations with `A = diag(A_i)`, `B = 0`,
//! `C = diag(C_i)` and Clebsch's condition
//! `(C2 − C3)/A1 + (C3 − C1)/A2 + (C1 − C2)/A3 = 0`, solved exactly through
//! the Manakov top's theta functions (docs/clebsch.md).
//!
//! **The conjugacy.** Write `a_j − a_k = (C_k − C_j)/A_i` (`(i, j, k)` cyclic;
//! consistent exactly by Clebsch's condition) and `b_i = −C_i`, so that
//! `A_i = (b_j − b_k)/(a_j − a_k)`: the body is the contraction `a4 → ∞`,
//! `b4 = 0` of the Manakov top `(a, b)`. The Möbius map `s = σ + λ/t` of the
//! spectral parameter of (12) sends `a4 = ∞` to `t = 0` and `a_i` to
//! `α_i = λ/(a_i − σ)`. With
//!
//! ```text
//! α = (α1, α2, α3, 0),   β_i = (√(α1 α2 α3)/λ) b_i α_i,  β4 = 0,
//! m_j = M_j/√α_j,   n_j = √λ p_j/√(α_k α_l)     (m = (l23, l31, l12), n = (l14, l24, l34))
//! ```
//!
//! Schottky's vector (12) of the Manakov top `(α, β)` at `l(M, p)` is
//! `(t/√λ)` times the contracted vector of the body at `s = σ + λ/t`, and —
//! the identity everything rests on — Frahm's field (1) of `(α, β)` at
//! `l(M, p)` is the image of Kirchhoff's field at `(M, p)`:
//! `X_{α,β}(L y) = L X_Kirchhoff(y)` for every `y`, a polynomial identity
//! (verified symbolically by `tests/data/clebsch_conjugacy_sympy.py` and in
//! exact rational arithmetic by `tests/test_fluid_clebsch.py`). The time is the
//! same. So `y(t) = L⁻¹ l(t)` with `l(t)` the Theorem's solution (9)–(10) of
//! the top `(α, β)`: theta quotients with arguments linear in `t`.
//!
//! **Choices.** `σ < min a_i` and `λ = min a_i − σ` make every `α_i` lie in
//! `(0, 1]`, the largest 1; `σ` maximises the smallest gap between the four
//! points `α1, α2, α3, 0` (the cross-ratio of `(a1, a2, a3, ∞)` is fixed, so
//! this only spreads them as evenly as the body allows). The top's indices are
//! relabelled so that `α` is ascending (`t = 0` first): relabelling the indices
//! of so(4) commutes with (1).

use crate::error::{check_finite, Error, Result};
use crate::numeric::cancel::Cancel;
use crate::solution::Solution;

/// Clebsch's condition must hold to this fraction of `Σ |C_j − C_k|/A_i`:
/// coefficients computed in floating point (e.g. `C_i = κ + θ A_j A_k`)
/// violate it by a few ulps; anything larger is another body, which the
/// conjugacy would silently replace by its nearest Clebsch body.
pub const CLEBSCH_RTOL: f64 = 1e-12;

/// The linear conjugacy of a Clebsch body to a Manakov top (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ClebschConjugacy {
    /// The body's `a_i` (`a_j − a_k = (C_k − C_j)/A_i`, mean 0).
    a: [f64; 3],
    /// The body's `b_i = −C_i` (centred: mean 0).
    b: [f64; 3],
    /// Clebsch's condition, relative: `|Σ (C_j − C_k)/A_i| / Σ |C_j − C_k|/A_i`.
    violation: f64,
    /// `σ` and `λ` of the Möbius map `s = σ + λ/t`.
    sigma: f64,
    lambda: f64,
    /// `α`, `β` of the Manakov top, in its (ascending) index order.
    alpha: [f64; 4],
    beta: [f64; 4],
    /// `orig[q]`: the original index (0, 1, 2 the body's axes, 3 = ∞) of the
    /// top's index `q`.
    orig: [usize; 4],
    /// `m_j = M_j sm[j]`, `n_j = p_j sn[j]`; `M_j = m_j / sm[j]` etc. use the
    /// reciprocals below, each computed once.
    sm: [f64; 3],
    sn: [f64; 3],
    sm_inv: [f64; 3],
    sn_inv: [f64; 3],
}

/// The smallest gap of the normalised points `1 = x/d0 > x/d1 > x/d2 > 0`,
/// `d = (x, x + g1, x + g1 + g2)`, as a function of `x = min a − σ`.
fn spread(x: f64, g1: f64, g2: f64) -> f64 {
    let (d1, d2) = (x + g1, x + g1 + g2);
    (g1 / d1).min(x * g2 / (d1 * d2)).min(x / d2)
}

/// `x > 0` maximising [`spread`] (quasi-concave: the minimum of a decreasing, an
/// increasing and a unimodal function), by golden-section search on `ln x`.
fn best_offset(g1: f64, g2: f64) -> f64 {
    let s = g1 + g2;
    let (mut lo, mut hi) = ((1e-8 * s).ln(), (1e8 * s).ln());
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let f = |u: f64| spread(u.exp(), g1, g2);
    let (mut u1, mut u2) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut f1, mut f2) = (f(u1), f(u2));
    for _ in 0..200 {
        if f1 < f2 {
            lo = u1;
            u1 = u2;
            f1 = f2;
            u2 = lo + r * (hi - lo);
            f2 = f(u2);
        } else {
            hi = u2;
            u2 = u1;
            f2 = f1;
            u1 = hi - r * (hi - lo);
            f1 = f(u1);
        }
    }
    (0.5 * (lo + hi)).exp()
}

/// The cyclic orders `(i, j, k)` of the body's three axes.
const CYC: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];

/// The differences `d_i = a_j − a_k = (C_k − C_j)/A_i` and Clebsch's condition
/// relative to its terms (`|Σ d_i| / Σ |d_i|`): the body's data checked before
/// any of the conjugacy is built on them ([`ClebschConjugacy::new`]'s errors).
fn clebsch_differences(a_diag: &[f64; 3], c_diag: &[f64; 3]) -> Result<([f64; 3], f64)> {
    check_finite("A", a_diag)?;
    check_finite("C", c_diag)?;
    if let Some(i) = a_diag.iter().position(|&x| x == 0.0) {
        return Err(Error::InvalidArgument {
            what: "A",
            reason: format!("A_{} = 0: Clebsch's condition divides by A_i", i + 1),
        });
    }
    // d_i = a_j − a_k = (C_k − C_j)/A_i.
    let d: [f64; 3] = CYC.map(|(i, j, k)| (c_diag[k] - c_diag[j]) / a_diag[i]);
    let scale: f64 = d.iter().map(|x| x.abs()).sum();
    if !scale.is_finite() {
        return Err(Error::InvalidArgument {
            what: "A, C",
            reason: "(C_k - C_j)/A_i overflows; rescale A and C".into(),
        });
    }
    if scale == 0.0 {
        return Err(Error::InvalidArgument {
            what: "C",
            reason: "C1 = C2 = C3: the body rotates freely (Euler's top with the \
                     impulse carried along); its motion is elliptic, not genus 2"
                .into(),
        });
    }
    let r = d[0] + d[1] + d[2];
    let violation = r.abs() / scale;
    if violation > CLEBSCH_RTOL {
        return Err(Error::InvalidArgument {
            what: "A, C",
            reason: format!(
                "Clebsch's condition (C2 - C3)/A1 + (C3 - C1)/A2 + (C1 - C2)/A3 = 0 \
                 fails: it is {r:e}, {violation:e} of the sum of its terms' moduli \
                 (at most {CLEBSCH_RTOL:e} is accepted)"
            ),
        });
    }
    Ok((d, violation))
}

/// The body's `a_i` (not yet centred) and the cyclic triple `(k, p, q)` whose
/// pair `(p, q)` keeps its difference `d_k` exactly.
struct BodyAxes {
    a: [f64; 3],
    k: usize,
    p: usize,
    q: usize,
}

/// The body's `a_i` from the differences `d_i` (which sum to the rounding
/// `r` of Clebsch's condition, not to 0), refusing an axisymmetric body.
fn body_axes(d: &[f64; 3]) -> Result<BodyAxes> {
    // The pair (p, q) with the smallest |a_p − a_q| = |d_k| keeps its
    // difference exactly: A_k = (b_p − b_q)/(a_p − a_q) is a quotient of two
    // small differences there, and the rounding of the violation r into
    // a_p − a_q would move A_k by r/d_k (1e-10 on a body with
    // C1 − C2 = 1.6e-6). The third axis takes r, split between its two
    // (large) differences.
    let k = (0..3)
        .min_by(|&x, &y| d[x].abs().total_cmp(&d[y].abs()))
        .unwrap_or(0);
    let (_, p, q) = CYC[k];
    let mut a = [0.0; 3];
    a[q] = -d[k];
    a[k] = 0.5 * ((a[q] - d[p]) + d[q]);
    for (_, j, l) in CYC {
        if a[j] == a[l] {
            return Err(Error::InvalidArgument {
                what: "C",
                reason: format!(
                    "C{} = C{} (so A{} = A{} by Clebsch's condition): the body is \
                     axisymmetric (Kirchhoff's case); its motion is elliptic, the \
                     genus-2 curve degenerates",
                    j + 1,
                    l + 1,
                    j + 1,
                    l + 1
                ),
            });
        }
    }
    Ok(BodyAxes { a, k, p, q })
}

/// The Möbius map `s = σ + λ/t` of the spectral parameter (module docs,
/// "Choices") and the images `α_i = λ/(a_i − σ)` of the body's `a_i`.
struct MobiusMap {
    /// The axes by ascending `a`: `sorted[0]` has the smallest.
    sorted: [usize; 3],
    /// `σ`, in the coordinates of the uncentred `a`.
    sigma: f64,
    lambda: f64,
    /// `α_i` of the body's axis `i`.
    al: [f64; 3],
}

/// [`MobiusMap`] of the body's `a_i`: `σ` spreads `α1, α2, α3, 0` as evenly as
/// the body allows ([`best_offset`]), `λ = min a_i − σ`.
fn mobius_map(a: &[f64; 3]) -> MobiusMap {
    // Sort the axes by a: sorted[0] has the smallest a.
    let mut sorted = [0usize, 1, 2];
    sorted.sort_by(|&x, &y| a[x].total_cmp(&a[y]));
    let (g1, g2) = (a[sorted[1]] - a[sorted[0]], a[sorted[2]] - a[sorted[1]]);
    let x = best_offset(g1, g2);
    let sigma = a[sorted[0]] - x;
    let lambda = x;
    // α_i = λ/(a_i − σ); the smallest a gets α = 1 exactly.
    let al: [f64; 3] = std::array::from_fn(|i| {
        if i == sorted[0] {
            1.0
        } else {
            lambda / (x + (a[i] - a[sorted[0]]))
        }
    });
    MobiusMap {
        sorted,
        sigma,
        lambda,
        al,
    }
}

/// `β_i` of the axes and `β_∞` of the conjugate top, in the gauge
/// `β_p = β_q = 0` of the exactly kept pair `(p, q)` ([`body_axes`]).
fn beta_in_gauge(
    a_diag: &[f64; 3],
    al: &[f64; 3],
    k: usize,
    p: usize,
    q: usize,
) -> ([f64; 3], f64) {
    // β_i = (ρ/λ) b_i α_i, ρ = √(α1 α2 α3), up to β → β + p0 + p1 α (no change
    // of the flow). In the gauge β_p = β_q = 0 the top's c_pq = 0 and
    // c_p∞ = ρ A_k/α_p exactly, instead of a difference of two nearly equal
    // c's (docs/clebsch.md, "Conditioning"); the remaining two relations
    // (α_j/ρ)(c_j∞ − c_{j,l}) = A_m give β_∞ = −ρ A_k and β_k, taken as the
    // mean of its two expressions (equal by Clebsch's condition).
    let rho = (al[0] * al[1] * al[2]).sqrt();
    let mut be = [0.0; 3];
    be[k] = 0.5
        * rho
        * ((a_diag[p] - a_diag[k]) * (al[q] - al[k]) / al[q]
            + (a_diag[q] - a_diag[k]) * (al[p] - al[k]) / al[p]);
    let be_inf = -rho * a_diag[k];
    (be, be_inf)
}

impl ClebschConjugacy {
    /// The conjugacy of the Clebsch body `A = diag(A_i)`, `C = diag(C_i)`.
    ///
    /// Errors (`InvalidArgument`): non-finite or zero `A_i`; Clebsch's
    /// condition violated by more than [`CLEBSCH_RTOL`]; `C_j = C_k` for some
    /// pair (then `a_j = a_k` and, by the condition, `A_j = A_k` or all `C`
    /// equal: an axisymmetric body or a free rotation, whose motion is
    /// elliptic — the genus-2 curve degenerates).
    pub fn new(a_diag: &[f64; 3], c_diag: &[f64; 3]) -> Result<Self> {
        let (d, violation) = clebsch_differences(a_diag, c_diag)?;
        let BodyAxes { a, k, p, q } = body_axes(&d)?;
        let mean_a = (a[0] + a[1] + a[2]) / 3.0;
        let a_centred = a.map(|x| x - mean_a);
        let mean_c = (c_diag[0] + c_diag[1] + c_diag[2]) / 3.0;
        let b = c_diag.map(|c| mean_c - c);
        let MobiusMap {
            sorted,
            sigma,
            lambda,
            al,
        } = mobius_map(&a);
        let (be, be_inf) = beta_in_gauge(a_diag, &al, k, p, q);
        // Ascending α: ∞ (α = 0) first, then the axes by decreasing a.
        let orig = [3, sorted[2], sorted[1], sorted[0]];
        let alpha = orig.map(|o| if o == 3 { 0.0 } else { al[o] });
        let beta = orig.map(|o| if o == 3 { be_inf } else { be[o] });
        let sl = lambda.sqrt();
        let sm: [f64; 3] = std::array::from_fn(|j| 1.0 / al[j].sqrt());
        let sn: [f64; 3] = CYC.map(|(_, k, l)| sl / (al[k] * al[l]).sqrt());
        let sm_inv: [f64; 3] = std::array::from_fn(|j| al[j].sqrt());
        let sn_inv: [f64; 3] = CYC.map(|(_, k, l)| (al[k] * al[l]).sqrt() / sl);
        Ok(ClebschConjugacy {
            a: a_centred,
            b,
            violation,
            sigma: sigma - mean_a,
            lambda,
            alpha,
            beta,
            orig,
            sm,
            sn,
            sm_inv,
            sn_inv,
        })
    }

    /// The body's `a_i` (`a_j − a_k = (C_k − C_j)/A_i`, `Σ a_i = 0`).
    pub fn body_a(&self) -> &[f64; 3] {
        &self.a
    }
    /// The body's `b_i = −C_i + mean(C)`.
    pub fn body_b(&self) -> &[f64; 3] {
        &self.b
    }
    /// Clebsch's condition of the given `A`, `C`, relative to its terms.
    pub fn violation(&self) -> f64 {
        self.violation
    }
    /// `(σ, λ)` of the Möbius map `s = σ + λ/t`, `σ` in the coordinates of
    /// [`ClebschConjugacy::body_a`]: `α_i = λ/(a_i − σ)`.
    pub fn mobius(&self) -> (f64, f64) {
        (self.sigma, self.lambda)
    }
    /// `a` of the conjugate Manakov top (2), ascending, `α = 0` (the image of
    /// `a4 = ∞`) first.
    pub fn alpha(&self) -> &[f64; 4] {
        &self.alpha
    }
    /// `b` of the conjugate Manakov top (2).
    pub fn beta(&self) -> &[f64; 4] {
        &self.beta
    }
    /// The original index of each of the top's indices (0–2 the body's axes, 3 = ∞).
    pub fn order(&self) -> &[usize; 4] {
        &self.orig
    }

    /// The skew 4 × 4 matrix in the original indexing (3 = ∞) of `y = (M, p)`:
    /// `X_kl = m_j`, `X_j4 = n_j`.
    fn original_matrix(&self, y: &[f64; 6]) -> [[f64; 4]; 4] {
        let mut x = [[0.0; 4]; 4];
        for (j, k, l) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
            let m = y[j] * self.sm[j];
            let n = y[3 + j] * self.sn[j];
            x[k][l] = m;
            x[l][k] = -m;
            x[j][3] = n;
            x[3][j] = -n;
        }
        x
    }

    /// The state `l = L y` of the conjugate Manakov top,
    /// `(l12, l13, l14, l23, l24, l34)` in its index order.
    pub fn to_so4(&self, y: &[f64; 6]) -> [f64; 6] {
        let x = self.original_matrix(y);
        let o = &self.orig;
        crate::so4::PAIRS4.map(|(q, r)| x[o[q]][o[r]])
    }

    /// `y = L⁻¹ l`: the body's `(M, p)` of a state of the conjugate top.
    pub fn to_body(&self, l: &[f64; 6]) -> [f64; 6] {
        let mut x = [[0.0; 4]; 4];
        for (p, &(q, r)) in crate::so4::PAIRS4.iter().enumerate() {
            let (i, j) = (self.orig[q], self.orig[r]);
            x[i][j] = l[p];
            x[j][i] = -l[p];
        }
        let mut y = [0.0; 6];
        for (j, k, l) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
            y[j] = x[k][l] * self.sm_inv[j];
            y[3 + j] = x[j][3] * self.sn_inv[j];
        }
        y
    }
}

/// The closed-form solution of a Clebsch body through `y0 = (M0, p0)`:
/// `y(t) = L⁻¹ l(t)`, `l(t)` the Theorem (9)–(10) for the conjugate top.
#[derive(Debug)]
pub struct ClebschSolution {
    conj: ClebschConjugacy,
    sol: Solution,
}

impl ClebschSolution {
    /// Sets up the solution (the conjugate top's [`Solution::new`] at `L y0`).
    ///
    /// Errors: those of [`Solution::new`]: `Singular` (a singular level set,
    /// named; `M0·p0 = 0`, the top's `h0 = 0`, is not one by itself) and
    /// `Unverified` (the top's solution failed its own check).
    pub fn new(conj: ClebschConjugacy, y0: &[f64; 6]) -> Result<Self> {
        check_finite("M0, p0", y0)?;
        let l0 = conj.to_so4(y0);
        let sol = Solution::new(&conj.alpha, &conj.beta, &l0)?;
        Ok(ClebschSolution { conj, sol })
    }

    /// The conjugacy.
    pub fn conjugacy(&self) -> &ClebschConjugacy {
        &self.conj
    }

    /// The conjugate top's solution.
    pub fn solution(&self) -> &Solution {
        &self.sol
    }

    /// `(M, p)` at time `t`.
    pub fn state(&self, t: f64) -> Result<[f64; 6]> {
        Ok(self.conj.to_body(&self.sol.l(t)?))
    }

    /// `(M, p)` at the times `t` into `out` (`6 t.len()` entries, row-major).
    pub fn state_batch(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        self.sol.l_batch(t, out, cancel)?;
        for row in out.chunks_exact_mut(6) {
            let l: [f64; 6] = std::array::from_fn(|k| row[k]);
            row.copy_from_slice(&self.conj.to_body(&l));
        }
        Ok(())
    }
}
