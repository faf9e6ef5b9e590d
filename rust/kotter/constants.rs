//! The constants of Kötter's reduction for one level set (20)–(26), (38)–(41):
//! from the roots `s_p` of `F` (19), `l^(p) = l(s_p)/√F'(s_p)`, the
//! determinants `Δ_j^(p)` (25), `d_j` (26), the coefficients `α_j … δ_j` of
//! (23)–(24) and the structure of `H0` on Kötter's quadrics (38)–(40), all
//! carried in double-double and rounded once (docs/kotter.md §3).

use super::pairs::{self, PAIR_ROUTE_RTOL};
use super::polish::{polish_root, split_pair, Level, PolishedRoot};
use super::roots::{
    check_converged, documented_order, quartic_f_den, quartic_roots_unordered, repeated_pair,
    repeated_root_error,
};
use super::{check_a, integrals, l_from_m_n, m_n, C, CYCLIC, ONE, ZERO};
use crate::error::{check_finite, cnum, Error, Result, SingularKind};
use crate::numeric::complex::{sqrt_principal, Modulus};
use crate::numeric::dd::{Cdd, Dd};

/// Residual (relative to the size of the terms) above which the existence
/// conditions of (38)–(39) (`Σ c_j q_j = 0`, `Σ c_j (p_j + r_j) = 0`) and the
/// perfect square of the corrected (40) are reported as failing: they hold to
/// rounding (a few 1e-13 on the reference tops, up to ~1e-7 when two `d_j`
/// nearly coincide, which amplifies rounding in `α_j … δ_j` by
/// `1/|d_j − d_k|`); 1e-6 still rejects an inconsistent structure, whose
/// residual is O(1).
pub const STRUCTURE_RTOL: f64 = 1e-6;

/// `Δ_j^(3)` (25) below this fraction of the size of its products
/// `(|u_j^(1)| + |v_j^(1)|)(|u_j^(2)| + |v_j^(2)|)` is refused as 0 (`d_j` at
/// infinity, (26)). It is small, not zero, near the degenerate level sets
/// (so(3) blocks, single components: `|Δ_j^(3)|` ~ the distance to them, or a
/// power of it), where `d_j` is large; the determinant is summed in DD from DD
/// coefficients, so down to this fraction `d_j`, `α_j … δ_j` still carry
/// double precision (DD's ~1e-32 relative to the products).
pub const DELTA3_MIN_RTOL: f64 = 1e-16;

/// The constants of Kötter's reduction for one level set `(a, h)`.
///
/// Everything here depends only on `a` and the integrals `h`, hence is
/// constant along a trajectory; `ξ, η` ([`xi_eta`]) carry the time dependence.
#[derive(Debug, Clone, PartialEq)]
pub struct KotterConstants {
    /// The top's `a` (2): the constants belong to the level set of `(a, h)`.
    pub a: [f64; 4],
    /// `(h0, h1, h2, h3)` ([`integrals`]).
    pub h: [f64; 4],
    /// Roots `s_1 … s_4` of `F` (19), in the documented order.
    pub s: [C; 4],
    /// `σ_p`, the branch of `√G(s_p)` on which `f(s_p) = 0`.
    pub sigma: [C; 4],
    /// `√F'(s_p)`, principal.
    pub sqrt_fprime: [C; 4],
    /// `u[p][j] = √s_j4(s_p) / √F'(s_p)` (coefficient of `m_j` in `l_j^(p)` (20)).
    pub u: [[C; 3]; 4],
    /// `v[p][j] = √s_kl(s_p) / √F'(s_p)` (coefficient of `n_j`).
    pub v: [[C; 3]; 4],
    /// The rounding errors of `u`: `u + u_lo` is `u` to double-double
    /// accuracy. [`l_p`] and [`xi_eta`] sum `(u + u_lo) m + (v + v_lo) n` in DD:
    /// near the singular set `h1² = 4h0²` the two terms cancel by about the
    /// inverse relative distance to it (docs/kotter.md §3).
    pub u_lo: [[C; 3]; 4],
    /// The rounding errors of `v` (see [`KotterConstants::u_lo`]).
    pub v_lo: [[C; 3]; 4],
    /// `delta_det[p][j] = Δ_j^(p)` (25) (corrected: a 2×2 determinant), `p = 1, 2, 3`.
    pub delta_det: [[C; 3]; 3],
    /// `√d_j = (Δ_j^(1) − i Δ_j^(2)) / Δ_j^(3)` (26).
    pub sqrt_d: [C; 3],
    /// `d_j` (26), the constants of Kötter's quadrics (11) and of the curve (8).
    pub d: [C; 3],
    /// The rounding errors of `d`: `d + d_lo` is `d_j` to double-double
    /// accuracy. [`kotter_with`](super::kotter_with) starts the inverse map of (37) from the closed
    /// form (30) on this unrounded curve: near the singular set the closed form
    /// cancels by `|d_4|/|z|` (docs/kotter.md, "Near the singular set").
    pub d_lo: [C; 3],
    /// `α_j, β_j, γ_j, δ_j` of (23) in corrected form (24):
    /// `m_j = α_j ξ_j + β_j η_j`, `n_j = γ_j ξ_j + δ_j η_j`.
    pub alpha: [C; 3],
    /// See [`KotterConstants::alpha`].
    pub beta: [C; 3],
    /// See [`KotterConstants::alpha`].
    pub gamma: [C; 3],
    /// See [`KotterConstants::alpha`].
    pub delta: [C; 3],
    /// `A_j = α + β d_j + γ/d_j` of (38)–(39): on Kötter's quadrics
    /// `H0 = Σ_j A_j (ξ_j² − η_j²) + B_j ξ_j η_j` (the unique representative of
    /// that form).
    pub a_coef: [C; 3],
    /// `B_j = δ (d_j + 1/d_j)` of (38)–(39).
    pub b_coef: [C; 3],
    /// `(α, β, γ, δ)` of (39) (the paper's unnamed constants; not the `α_j` of (24)),
    /// in closed form with `K`, `ε` of the corrected (40), `κ = Π_{m=1}^{3} (d_m − d_4)`,
    /// `e1 = d_1 + d_2 + d_3`: `β = −K/κ`, `γ = ε² d_4² K/κ`, `δ = 2 ε d_4 K/κ`,
    /// `α = (K/(2κ)) (κ ε² + (e1 − d_4)(1 − ε² d_4²))`.
    pub abgd39: [C; 4],
    /// `ε` of (40)–(41), corrected: `H0 = K g² (1 − ε P_0)²` with [`KotterConstants::k`];
    /// `ε = Σ_j c̃_j (α_j δ_j + β_j γ_j) / (2 Σ_j c̃_j d_j β_j δ_j)`.
    pub eps: C,
    /// `K` of the corrected (40) (printed as `1/(4 ε d_4)`):
    /// `K = κ Σ_j c̃_j d_j β_j δ_j`, `κ = Π_{m=1}^{3} (d_m − d_4)`, `c̃_j` of (33).
    pub k: C,
}

/// Kötter's constants for the level set of the state `l` of the top with
/// parameters `a` (only `a` and the integrals of `l` enter).
///
/// Errors: non-finite or repeated `a`; non-finite `l`; `h0 = 0` or
/// `h1² = 4h0²` (F (19) not defined or with double roots); repeated roots of
/// `F`; a root `s_p` at some `a_j` (then `√s_kl` is 0/0); `Δ_j^(3) = 0`
/// (the pair `s1, s2` does not determine `m_j, n_j`); `d_j` zero or infinite.
pub fn kotter_constants(a: &[f64; 4], l: &[f64; 6]) -> Result<KotterConstants> {
    kotter_constants_soft(a, l, None)
}

/// [`kotter_constants`]; with `soft`, a failure of the structure check of
/// `H0` is written there instead of refused ([`constants_impl`]).
pub(crate) fn kotter_constants_soft(
    a: &[f64; 4],
    l: &[f64; 6],
    soft: Option<&mut Option<String>>,
) -> Result<KotterConstants> {
    check_a(a)?;
    check_finite("l", l)?;
    let h = integrals(a, l);
    let (m, n) = m_n(l);
    // P(a_i) = h1 a_i^2 - h2 a_i + h3 from the state itself: the sum of the
    // non-vanishing terms s_j4 m_j^2 + s_kl n_j^2 at s = a_i, without the
    // cancellation of the form in h (it is small exactly when a root of F is
    // near a_i, which is when it is needed to full relative accuracy).
    let p_at_a: [f64; 4] = std::array::from_fn(|i| {
        let x = a[i];
        CYCLIC
            .iter()
            .enumerate()
            .map(|(j, &(_, k, ll))| {
                (x - a[j]) * (x - a[3]) * m[j] * m[j] + (x - a[k]) * (x - a[ll]) * n[j] * n[j]
            })
            .sum()
    });
    near_singular(l, constants_impl(a, &h, &p_at_a, Some((m, n)), soft))
}

/// Below this `|h0|/h1` the constants `ε` and `K` of the corrected (40) are set
/// to 0, their value at `h0 = 0`. With (20) normalised by `√(F'(s_p)/|h0|)`, `ε`
/// and `K` vanish like `h0` and their closed forms (sums in DD, relative accuracy
/// ~1e-32) cancel down to them, leaving an absolute error of ~1e-32/|h0| in `ε`;
/// at `|h0| = 1e-16 h1` that error and `ε` itself are both ~1e-16 of the scale,
/// so below it 0 is the more accurate value. Then `h0 = K g² (1 − ε P_0)²` no
/// longer fixes `g` (its sign is free: the hyperelliptic involution), and the
/// scale of `g` comes from (30a) alone (docs/degenerate.md, "h0 = 0").
pub const H0_NEGLIGIBLE_RTOL: f64 = 1e-16;

/// States closer than `NEAR_SINGULAR_RTOL` to the singular set `h1² = 4h0²`,
/// in the relative distance `δ = (h1² − 4h0²)/h1²` (`= |m − n|²|m + n|²/h1²`),
/// may raise. Down to it the reduction round-trips at roundoff: all 3000 states
/// of `tests/data/kotter_singular_sweep.py` at `δ` from 1e-10 to 1e-4 (shared,
/// random and pinched tops), worst 2.4e-15, and 600 more at 2.5e-11; the
/// mismatch of (42) is ≤ 3.4e-11 there (1e-6 is refused). Below it the
/// double-double level-set constants run out of digits (`d_j` to 2e-17 at
/// `δ = 4e-12`, the mismatch of (42) reaches 6e-9) and the inverse map of the
/// curve starts to fail (2 of 600 states at `δ = 4e-12`; docs/kotter.md, "Near
/// the singular set"). Below [`REDUCTION_FLOOR_RTOL`] every state raises.
pub const NEAR_SINGULAR_RTOL: f64 = 1e-10;

/// `δ = (h1² − 4h0²)/h1²` from the state (`h1² − 4h0² = |m − n|²|m + n|²`,
/// full relative accuracy).
fn singular_distance(l: &[f64; 6]) -> f64 {
    let (m, n) = m_n(l);
    let h1: f64 = l.iter().map(|x| x * x).sum();
    den_from_state(&m, &n) / (h1 * h1)
}

/// A failure of a state closer than [`NEAR_SINGULAR_RTOL`] to the singular set
/// is reported as such (kind [`SingularKind::SelfDual`]), with the step that failed.
pub(super) fn near_singular<T>(l: &[f64; 6], r: Result<T>) -> Result<T> {
    r.map_err(|e| {
        let dist = singular_distance(l);
        if matches!(e, Error::Singular { .. }) || dist.is_nan() || dist >= NEAR_SINGULAR_RTOL {
            return e;
        }
        Error::Singular {
            what: "state l",
            kind: SingularKind::SelfDual,
            reason: format!(
                "it lies at relative distance (h1^2 - 4 h0^2)/h1^2 = {dist:e} from the singular \
                 set h1^2 = 4 h0^2 (m = +-n), closer than {NEAR_SINGULAR_RTOL:e}, where the \
                 reduction is no longer guaranteed: {e}"
            ),
        }
    })
}

/// [`kotter_constants`] from the integrals `h = (h0, h1, h2, h3)` directly.
///
/// A root `s_p` close to some `a_i` is then known only to an absolute
/// accuracy of a few ulps of the coefficients, so `s_p − a_i` (and with it
/// `√s_j4`, `l^(p)`) loses relative accuracy; [`kotter_constants`] avoids this.
pub fn constants_from_h(a: &[f64; 4], h: &[f64; 4]) -> Result<KotterConstants> {
    check_finite("h", h)?;
    let p_at_a: [f64; 4] = std::array::from_fn(|i| (h[1] * a[i] - h[2]) * a[i] + h[3]);
    constants_impl(a, h, &p_at_a, None, None)
}

/// `h1² − 4h0² = |m − n|² |m + n|²` from the state: the difference of squares
/// in `h` loses all its digits near the singular set `m = ±n`, this product
/// does not.
fn den_from_state(m: &[f64; 3], n: &[f64; 3]) -> f64 {
    let [dp, dm] = crate::so4::casimir_factors(&super::l_from_m_n(m, n));
    dm * dp
}

/// Relative distance above which two DD-polished roots of `F` are distinct
/// ([`resolved_in_dd`]): a thousand times the double rounding of `s`, far above
/// the DD accuracy of the roots.
const DD_DISTINCT_RTOL: f64 = 1e-13;

/// [`kotter_constants`] and [`constants_from_h`]: the roots of `F` (19)
/// polished on their branches, then everything else from `(s_p, σ_p, F'(s_p))`.
///
/// `soft`: where given, a failure of the structure check of `H0`
/// ([`STRUCTURE_RTOL`]) is written there instead of refused (for a solution
/// that certifies every `l(t)` by an integration,
/// `crate::solution::Solution::with_c4_lo_certifying`).
fn constants_impl(
    a: &[f64; 4],
    h: &[f64; 4],
    p_at_a: &[f64; 4],
    mn: Option<([f64; 3], [f64; 3])>,
    soft: Option<&mut Option<String>>,
) -> Result<KotterConstants> {
    check_a(a)?;
    let den = match mn {
        Some((m, n)) => den_from_state(&m, &n),
        None => h[1] * h[1] - 4.0 * h[0] * h[0],
    };
    let f = quartic_f_den(a, h, den)?;
    let lv = Level { a, h, mn, den };
    let (roots, pair) = roots_of_f(&lv, p_at_a, &f)?;
    // Everything below is a function of (s_p, σ_p, F'(s_p)) and is carried in
    // DD, rounded to double once at the end: the third quadric (11) of the
    // rounded constants holds only as well as they are consistent with each
    // other, and near the singular set Δ_j^(3) and the forms u m + v n cancel
    // by about the inverse relative distance to it (docs/kotter.md §3).
    let (u, v) = coefficients_20(a, &roots, pair.as_ref())?;
    let dd = delta_determinants(&u, &v);
    let bc = BranchConstants::from_determinants(&u, &v, &dd)?;
    // ε ~ h0 and K ~ |h0| (in the normalisation of (20) by √(F'/|h0|)): below
    // H0_NEGLIGIBLE_RTOL their DD sums are rounding noise and their true values
    // below it, so they are 0 (K = 0 marks the case downstream).
    let kk = if h[0].abs() <= H0_NEGLIGIBLE_RTOL * h[1] {
        (ZERO, ZERO, ZERO)
    } else {
        k_keps_dd(&bc.abgd_dd, &bc.d_dd)
    };
    let [alpha, beta, gamma, delta] = bc.abgd_dd.map(|row| row.map(Cdd::to_c));
    let ((a_coef, b_coef, abgd39, eps, k), refusal) =
        h0_structure(&alpha, &beta, &gamma, &delta, &bc.d, kk)?;
    if let Some(e) = refusal {
        crate::error::soften(soft, e)?;
    }
    let round2 = |x: &[[Cdd; 3]; 4]| x.map(|row| row.map(Cdd::to_c));
    let lo2 = |x: &[[Cdd; 3]; 4]| x.map(|row| row.map(|z| z.sub(Cdd::new(z.to_c())).to_c()));
    Ok(KotterConstants {
        a: *a,
        h: *h,
        s: std::array::from_fn(|p| roots[p].s),
        sigma: std::array::from_fn(|p| roots[p].sigma.to_c()),
        sqrt_fprime: std::array::from_fn(|p| roots[p].sqrt_fprime.to_c()),
        u: round2(&u),
        v: round2(&v),
        u_lo: lo2(&u),
        v_lo: lo2(&v),
        delta_det: dd.map(|row| row.map(Cdd::to_c)),
        sqrt_d: bc.sqrt_d,
        d: bc.d,
        d_lo: bc.d_lo,
        alpha,
        beta,
        gamma,
        delta,
        a_coef,
        b_coef,
        abgd39,
        eps,
        k,
    })
}

/// The four roots of `F` (19), polished, in the documented order: near
/// `h0 = 0` as pairs on the two branches of `√G` ([`pairs`], with the pair
/// structure returned), elsewhere (or where the pair route does not apply)
/// from the quartic; where the quartic leaves two roots within rounding of
/// each other, as a cluster at a branch point `a_i`
/// ([`pairs::branch_point_cluster`]) or as the pairs at the roots of `P`
/// whatever `h0`, else refused as a repeated root.
fn roots_of_f(
    lv: &Level,
    p_at_a: &[f64; 4],
    f: &[f64; 5],
) -> Result<(Vec<PolishedRoot>, Option<PairStructure>)> {
    match roots_by_route(lv, p_at_a, f) {
        Ok((roots, pair)) => {
            if resolved_in_dd(&roots) {
                return Ok((roots, pair));
            }
            match hidden_conjugate_pair(lv, p_at_a, &roots)
                .or_else(|| hidden_real_pair(lv, p_at_a, &roots))
                .or_else(|| root_census(lv, p_at_a, f, &roots))
            {
                Some(fixed) => Ok((fixed, None)),
                None => Ok((roots, pair)),
            }
        }
        Err(
            e @ Error::Singular {
                kind: SingularKind::RepeatedRoot,
                ..
            },
        ) => match root_census(lv, p_at_a, f, &[]) {
            Some(found) => Ok((found, None)),
            None => Err(e),
        },
        Err(e) => Err(e),
    }
}

/// The four roots of `F` found afresh where the routes left two of them on one
/// root, unconverged, or refused a repeated root that is none: every seed (the
/// quartic's iterate, the roots given, and for each seed near the real axis
/// the non-real seeds `Re z ± i δ` and the real ones `Re z ± |Im z|`, `δ` the
/// distance to the nearest other seed) is polished on each branch of `√G`
/// (a root of `F = f f̃/(h1² − 4h0²)` is a root of `f` on one of them; where
/// the polish does not converge, the two roots of that branch closer than the
/// seed are split about their centre, [`split_pair`]), the
/// polishes that converged in DD are merged within [`DD_DISTINCT_RTOL`], and
/// the conjugate of each non-real root added. Exactly four distinct roots,
/// each converged, are the result, in the documented order; anything else
/// (a true double root, a root no seed reaches) is `None`.
fn root_census(
    lv: &Level,
    p_at_a: &[f64; 4],
    f: &[f64; 5],
    given: &[PolishedRoot],
) -> Option<Vec<PolishedRoot>> {
    let (z, _, _) = quartic_roots_unordered(f).ok()?;
    let mut seeds: Vec<C> = z.to_vec();
    seeds.extend(given.iter().map(|r| r.s));
    let base = seeds.clone();
    let scale = base.iter().fold(0.0f64, |m, x| m.max(x.modulus()));
    for (k, x) in base.iter().enumerate() {
        let near = base
            .iter()
            .enumerate()
            .filter(|&(q, y)| q != k && (y - x).modulus() > 0.0)
            .map(|(_, y)| (y - x).modulus())
            .fold(f64::INFINITY, f64::min);
        if x.im.abs() <= HIDDEN_PAIR_RTOL * scale {
            if near.is_finite() && near <= HIDDEN_PAIR_RTOL * scale {
                seeds.push(C::new(x.re, near));
            }
            // a stagnated iterate can sit on the axis far from a pair with a
            // small imaginary part: non-real seeds at a few scales
            for rel in [1e-3, 1e-5, 1e-7] {
                seeds.push(C::new(x.re, rel * x.modulus()));
            }
            if x.im != 0.0 {
                seeds.push(C::new(x.re + x.im.abs(), 0.0));
                seeds.push(C::new(x.re - x.im.abs(), 0.0));
            }
        }
    }
    let mut found: Vec<PolishedRoot> = Vec::new();
    let add = |r: PolishedRoot, found: &mut Vec<PolishedRoot>| {
        if r.dd_converged
            && r.s.re.is_finite()
            && r.s.im.is_finite()
            && found
                .iter()
                .all(|q| (q.s - r.s).modulus() > DD_DISTINCT_RTOL * scale)
        {
            found.push(r);
        }
    };
    // an imaginary part below DD resolution (left by a start off the axis)
    // is a real root
    let take = |mut r: PolishedRoot, found: &mut Vec<PolishedRoot>| {
        if r.s.im != 0.0 && r.s.im.abs() <= 1e-30 * r.s.modulus() {
            r.s.im = 0.0;
            for xm in &mut r.x {
                xm.im = Dd::ZERO;
            }
        }
        if r.s.im != 0.0 {
            let rc = r.conj();
            add(r, found);
            add(rc, found);
        } else {
            add(r, found);
        }
    };
    for &s0 in &seeds {
        let g0 = sqrt_principal(lv.a.iter().map(|&am| s0 - am).product());
        for branch in [g0, -g0] {
            if g0 == ZERO {
                continue;
            }
            let r = polish_root(lv, p_at_a, s0, Some(branch));
            if !r.dd_converged {
                // two roots of this branch closer than the seed: split the
                // pair about its centre (from where the polish stopped, which
                // is nearer it than the seed)
                let from = if r.s.re.is_finite() && r.s.im.is_finite() {
                    r.s
                } else {
                    s0
                };
                if let Some(pair) = split_pair(lv, from, branch) {
                    for q in pair {
                        take(q, &mut found);
                    }
                }
            }
            take(r, &mut found);
        }
        if found.len() > 4 {
            return None;
        }
    }
    if found.len() != 4 {
        return None;
    }
    let out = documented_roots(found)?;
    resolved_in_dd(&out).then_some(out)
}

/// Four distinct roots in the documented order: the non-real root of largest
/// imaginary part, its conjugate, the remaining root of larger imaginary part
/// (then real part), the last; all real: descending. A non-real root is
/// followed by its exact conjugate. `None` if a non-real root has no conjugate
/// among them.
fn documented_roots(mut r: Vec<PolishedRoot>) -> Option<Vec<PolishedRoot>> {
    use std::cmp::Ordering;
    let key = |x: &PolishedRoot, y: &PolishedRoot| {
        x.s.im
            .partial_cmp(&y.s.im)
            .unwrap_or(Ordering::Equal)
            .then(x.s.re.partial_cmp(&y.s.re).unwrap_or(Ordering::Equal))
    };
    let mut out = Vec::with_capacity(4);
    while !r.is_empty() {
        if r.iter().any(|x| x.s.im != 0.0) {
            let i = (0..r.len()).max_by(|&i, &j| key(&r[i], &r[j]))?;
            let top = r.remove(i);
            let j = (0..r.len()).find(|&j| r[j].s == top.s.conj())?;
            let partner = r.remove(j);
            out.push(top);
            out.push(partner);
        } else {
            r.sort_by(|x, y| y.s.re.partial_cmp(&x.s.re).unwrap_or(Ordering::Equal));
            out.append(&mut r);
        }
    }
    Some(out)
}

/// Two real roots of `F`, close to each other, whose polish in DD did not
/// converge, are taken for a conjugate pair `s, s̄` with an imaginary part below
/// what the quartic resolves (the iterate locates a near-double root only to
/// `√u` relative, and its imaginary part, 1e-11 … 1e-7 of the root on the
/// harsh draw, was snapped to the real axis): Newton's method in real
/// arithmetic from a real start cannot leave the axis, and each of the two
/// ended near `Re s`, neither a root. The pair is polished again from
/// `mid + i half` (`mid`, `half` the midpoint and half the distance of the two
/// reals) on its own branch; if that converges in DD to a non-real root, the
/// two are replaced by it and its conjugate, in the documented order. `None`
/// when there is no such pair or the polish does not resolve it
/// ([`resolved_in_dd`]); the roots then stand as they were.
fn hidden_conjugate_pair(
    lv: &Level,
    p_at_a: &[f64; 4],
    roots: &[PolishedRoot],
) -> Option<Vec<PolishedRoot>> {
    let scale = root_scale(roots);
    let mut best: Option<(usize, usize, f64)> = None;
    for p in 0..roots.len() {
        for q in (p + 1)..roots.len() {
            let (rp, rq) = (&roots[p], &roots[q]);
            if rp.s.im != 0.0 || rq.s.im != 0.0 || (rp.dd_converged && rq.dd_converged) {
                continue;
            }
            let dist = (rp.s - rq.s).modulus();
            if dist <= HIDDEN_PAIR_RTOL * scale && best.is_none_or(|(_, _, b)| dist < b) {
                best = Some((p, q, dist));
            }
        }
    }
    let (p, q, _) = best?;
    conjugate_pair_from(lv, p_at_a, roots, p, q, roots[p].s, roots[q].s)
}

/// [`hidden_conjugate_pair`] for the roots `p`, `q` of `roots`, seeded from
/// `zp`, `zq` (their polished values, or the quartic's iterate where the two
/// polishes ended on one root).
fn conjugate_pair_from(
    lv: &Level,
    p_at_a: &[f64; 4],
    roots: &[PolishedRoot],
    p: usize,
    q: usize,
    zp: C,
    zq: C,
) -> Option<Vec<PolishedRoot>> {
    let scale = root_scale(roots);
    let mid = (zp + zq) * 0.5;
    let half = (0.5 * (zp - zq).modulus()).max(f64::EPSILON * mid.modulus());
    let r = polish_root(lv, p_at_a, C::new(mid.re, half), None);
    if !r.dd_converged || r.s.im.abs() <= DD_DISTINCT_RTOL * scale {
        return None;
    }
    let r = if r.s.im > 0.0 { r } else { r.conj() };
    let others: Vec<PolishedRoot> = (0..roots.len())
        .filter(|&k| k != p && k != q)
        .map(|k| roots[k].clone())
        .collect();
    let rc = r.conj();
    let out: Vec<PolishedRoot> = if others.iter().all(|o| o.s.im == 0.0) {
        // s1 = r, s2 = its conjugate, then the real roots descending
        let (a, b) = (&others[0], &others[1]);
        let (hi, lo) = if a.s.re >= b.s.re { (a, b) } else { (b, a) };
        vec![r, rc, hi.clone(), lo.clone()]
    } else {
        // the other pair is conjugate: s1 the member of larger imaginary part
        let o = if others[0].s.im > 0.0 {
            &others[0]
        } else {
            &others[1]
        };
        let (oc, o) = (o.conj(), o.clone());
        if o.s.im > r.s.im {
            vec![o, oc, r, rc]
        } else {
            vec![r, rc, o, oc]
        }
    };
    resolved_in_dd(&out).then_some(out)
}

/// The converse of [`hidden_conjugate_pair`]: a conjugate pair `s, s̄` of the
/// iterate whose polish did not converge, with `|Im s|` below
/// [`HIDDEN_PAIR_RTOL`] of the largest root, is taken for two real roots the
/// quartic did not resolve (they may lie on different branches of `√G`, where
/// Newton's method on one branch from a non-real start has no root to reach).
/// Each is polished from `Re s ± |Im s|`; if both converge in DD to distinct
/// real roots, they replace the pair, in the documented order.
fn hidden_real_pair(
    lv: &Level,
    p_at_a: &[f64; 4],
    roots: &[PolishedRoot],
) -> Option<Vec<PolishedRoot>> {
    let scale = root_scale(roots);
    let p = (0..roots.len().saturating_sub(1)).find(|&p| {
        let (rp, rq) = (&roots[p], &roots[p + 1]);
        rp.s.im != 0.0
            && rq.s == rp.s.conj()
            && !(rp.dd_converged && rq.dd_converged)
            && rp.s.im.abs() <= HIDDEN_PAIR_RTOL * scale
    })?;
    let (re, im) = (roots[p].s.re, roots[p].s.im.abs());
    // the second on the other branch of √G if the first seed's branch gave
    // both polishes the same root (F = f f̃/(h1² − 4h0²))
    let r1 = polish_root(lv, p_at_a, C::new(re + im, 0.0), None);
    let mut r2 = polish_root(lv, p_at_a, C::new(re - im, 0.0), None);
    if (r2.s - r1.s).modulus() <= DD_DISTINCT_RTOL * scale {
        r2 = polish_root(lv, p_at_a, C::new(re - im, 0.0), Some(-r1.sigma.to_c()));
    }
    if r1.s.im != 0.0 || r2.s.im != 0.0 {
        return None;
    }
    let others: Vec<PolishedRoot> = (0..roots.len())
        .filter(|&k| k != p && k != p + 1)
        .map(|k| roots[k].clone())
        .collect();
    let mut reals = vec![r1, r2];
    let out: Vec<PolishedRoot> = if others.iter().all(|o| o.s.im == 0.0) {
        reals.extend(others);
        reals.sort_by(|x, y| {
            y.s.re
                .partial_cmp(&x.s.re)
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        reals
    } else {
        reals.sort_by(|x, y| {
            y.s.re
                .partial_cmp(&x.s.re)
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let mut v = others;
        v.extend(reals);
        v
    };
    resolved_in_dd(&out).then_some(out)
}

/// Two real roots of `F` this close (relative to the largest root) whose polish
/// did not converge are tried as a conjugate pair ([`hidden_conjugate_pair`]).
const HIDDEN_PAIR_RTOL: f64 = 1e-4;

/// The roots of `F` by the routes below ([`roots_of_f`]).
fn roots_by_route(
    lv: &Level,
    p_at_a: &[f64; 4],
    f: &[f64; 5],
) -> Result<(Vec<PolishedRoot>, Option<PairStructure>)> {
    let h = lv.h;
    if h[0].abs() <= PAIR_ROUTE_RTOL * h[1] {
        if let Some((r, partner, side)) = pairs::pair_roots(lv, p_at_a) {
            return Ok((r.into(), Some(PairStructure { partner, side })));
        }
    }
    if h[0] == 0.0 {
        return Err(Error::Singular {
            what: "state l",
            kind: SingularKind::RepeatedRoot,
            reason: "h0 = 0 and the double roots of F(s) (19), the roots of h1 s^2 - h2 s + h3, \
                     coincide or lie at an a_j: the reduction degenerates there (an equilibrium, \
                     an so(3) block or a separatrix)"
                .into(),
        });
    }
    let (z, converged, last) = quartic_roots_unordered(f)?;
    let z = documented_order(z);
    let roots = polished_roots(lv, p_at_a, &z);
    let s: Vec<C> = roots.iter().map(|r| r.s).collect();
    // two roots within rounding of each other in the iterate, or polished onto
    // each other
    let repeated = match repeated_pair(&z) {
        Some(pair) => Some((pair, &z[..])),
        None => repeated_pair(&s).map(|pair| (pair, &s[..])),
    };
    let Some(((i, j), at)) = repeated else {
        // Aberth stagnates where two roots of F lie close on different
        // branches of √G (it sees F, not f): the polish on each root's own
        // branch takes them from the stagnated iterate, and the roots stand
        // when it moved none of them by more than the stagnation allowed
        if let Err(e) = check_converged(converged, last) {
            let moved = z
                .iter()
                .zip(&s)
                .all(|(z, s)| (z - s).modulus() <= 1e3 * last * z.modulus().max(1.0));
            if !moved {
                return Err(e);
            }
        }
        return Ok((roots, None));
    };
    // A cluster at a branch point of √G is found in the local parameter there;
    // a pair at a root of P = h1 s^2 - h2 s + h3 whose split 2 h0 √G/P' is
    // small though h0 is not, by the pair route (pairs.rs checks the split and
    // the polish); else the roots as polished if DD resolves them; else a
    // repeated root.
    // or, two real roots of the iterate being a conjugate pair whose imaginary
    // part the quartic did not resolve, that pair ([`conjugate_pair_from`])
    // (each tried only where the routes before it failed)
    let polished = roots.clone();
    let resolved = || {
        if resolved_in_dd(&polished) {
            return Some(polished.clone());
        }
        // The two polishes may have found the same root of f: the other root
        // of F next to it is then the root of f on the other branch of √G
        // (F = f f̃/(h1² − 4h0²), f̃ being f with −√G).
        let mut alt = polished.clone();
        alt[j] = polish_root(lv, p_at_a, z[j], Some(-polished[i].sigma.to_c()));
        resolved_in_dd(&alt).then_some(alt)
    };
    let hidden = || {
        (z[i].im == 0.0 && z[j].im == 0.0)
            .then(|| conjugate_pair_from(lv, p_at_a, &polished, i, j, z[i], z[j]))
            .flatten()
    };
    pairs::branch_point_cluster(lv, p_at_a, roots, (i, j))
        .or_else(|| pairs::pair_roots(lv, p_at_a))
        .map(|(r, partner, side)| (r.into(), Some(PairStructure { partner, side })))
        .or_else(|| resolved().map(|r| (r, None)))
        .or_else(|| hidden().map(|r| (r, None)))
        .ok_or_else(|| repeated_root_error(at, i, j))
}

/// The largest `|s_p|`: the scale the distances between roots are taken
/// relative to.
fn root_scale(roots: &[PolishedRoot]) -> f64 {
    roots.iter().fold(0.0f64, |m, r| m.max(r.s.modulus()))
}

/// Two roots of `F` closer than [`REPEATED_ROOT_RTOL`] that neither the cluster
/// nor the pair route takes are still distinct roots when each was polished on
/// its own branch of `√G` to double-double accuracy ([`PolishedRoot::dd_converged`])
/// and they stay apart by more than [`DD_DISTINCT_RTOL`]: on different branches
/// `f'(s_p)` is not small, so each root is located to DD however close the other
/// lies (`F'(s_p)`, proportional to their distance, is then accurate in DD too).
/// Two polishes that ended on the same root, or one that did not converge,
/// leave the pair refused as repeated.
fn resolved_in_dd(roots: &[PolishedRoot]) -> bool {
    if !roots.iter().all(|r| r.dd_converged) {
        return false;
    }
    let scale = root_scale(roots);
    (0..roots.len()).all(|p| {
        ((p + 1)..roots.len())
            .all(|q| (roots[p].s - roots[q].s).modulus() > DD_DISTINCT_RTOL * scale)
    })
}

/// What the pair route knows of its roots ([`pairs::pair_roots`]): which is
/// the exact conjugate partner of the root before it, and the side of the
/// real axis (`±1`, 0 for real pairs) each member of a conjugate pair comes
/// from as `h0 → 0`.
struct PairStructure {
    partner: [bool; 4],
    side: [f64; 4],
}

/// The four roots of `F` polished on their own branches ([`polish_root`]);
/// the partner of a conjugate pair as the exact conjugate.
fn polished_roots(lv: &Level, p_at_a: &[f64; 4], s0: &[C; 4]) -> Vec<PolishedRoot> {
    let mut roots: Vec<PolishedRoot> = Vec::with_capacity(4);
    for p in 0..4 {
        if p % 2 == 1 && s0[p] == s0[p - 1].conj() && s0[p].im != 0.0 {
            let partner = roots[p - 1].conj();
            roots.push(partner);
        } else {
            roots.push(polish_root(lv, p_at_a, s0[p], None));
        }
    }
    roots
}

/// The coefficients of `l^(p)` (20), `u[p][j] = √s_j4(s_p)/√F'(s_p)` and
/// `v[p][j] = √s_kl(s_p)/√F'(s_p) = σ_p/(√s_j4 √F'(s_p))`, in DD.
///
/// Errors: `F'(s_p)` zero or not finite; a root `s_p` indistinguishable from
/// some `a_j` (then `√s_kl = √G/√s_j4` is 0/0).
#[allow(clippy::type_complexity)]
fn coefficients_20(
    a: &[f64; 4],
    roots: &[PolishedRoot],
    pair: Option<&PairStructure>,
) -> Result<([[Cdd; 3]; 4], [[Cdd; 3]; 4])> {
    let s: [C; 4] = std::array::from_fn(|p| roots[p].s);
    let scale_a = a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut u = [[Cdd::ZERO; 3]; 4];
    let mut v = [[Cdd::ZERO; 3]; 4];
    // √(x_j x_4) of the previous root (for its conjugate partner)
    let mut root_jd = [Cdd::ZERO; 3];
    for p in 0..4 {
        let sqrt_fp = roots[p].sqrt_fprime.to_c();
        if !(sqrt_fp.modulus().is_finite() && sqrt_fp.modulus() > 0.0) {
            let reason = format!(
                "F'(s_{}) = {} (19) at the root s_{} = {} is zero or not finite",
                p + 1,
                cnum(roots[p].fprime),
                p + 1,
                cnum(s[p])
            );
            // F'(s_p) = 0 is a repeated root of F, as in `check_repeated`; an
            // overflow is not a property of the state.
            return Err(if sqrt_fp.modulus() == 0.0 {
                Error::Singular {
                    what: "state l",
                    kind: SingularKind::RepeatedRoot,
                    reason,
                }
            } else {
                Error::InvalidArgument {
                    what: "state l",
                    reason,
                }
            });
        }
        for (j, &aj) in a.iter().enumerate() {
            // the offsets are accurate to a few ulps relative (polish.rs, and
            // exact from w² at a branch point, pairs.rs) however small: only a
            // root at a_j itself is 0/0
            if roots[p].x[j].to_c().modulus() <= f64::MIN_POSITIVE * scale_a {
                return Err(Error::Singular {
                    what: "state l",
                    kind: SingularKind::CoincidingBranchPoints,
                    reason: format!(
                        "the root s_{} = {} of F (19) coincides with a_{} = {aj}: sqrt(s_kl) = \
                         sqrt(G)/sqrt(s_j4) is 0/0 there",
                        p + 1,
                        cnum(s[p]),
                        j + 1
                    ),
                });
            }
        }
        // The partner of a conjugate pair has the conjugate u, v, unless a
        // principal root (of x_j x_4 or of F') lies on its cut, where both
        // members take +i√|·|.
        let conj_pair = match pair {
            Some(ps) => ps.partner[p],
            None => p % 2 == 1 && s[p].im != 0.0 && s[p] == s[p - 1].conj(),
        };
        let partner = conj_pair && roots[p].sqrt_fprime == roots[p - 1].sqrt_fprime.conj();
        let x = &roots[p].x;
        let inv_sfp = roots[p].sqrt_fprime.recip();
        let sg_sfp = roots[p].sigma.mul(inv_sfp);
        for j in 0..3 {
            if partner && root_jd[j].re.hi > 0.0 {
                u[p][j] = u[p - 1][j].conj();
                v[p][j] = v[p - 1][j].conj();
                continue;
            }
            let mut r = x[j].mul(x[3]).sqrt();
            // A conjugate pair merged onto the real axis (h0 ≈ 0, pairs.rs) with
            // s_j4 < 0 there: √s_j4 on its cut. The branch is the limit from the
            // member's own side of the axis, Im s → ±0, where Im s_j4 has the sign
            // of ±Re(x_j + x_4): as for the pair at small h0 ≠ 0.
            let side = pair.map_or(0.0, |ps| ps.side[p]);
            let prod = x[j].mul(x[3]).to_c();
            if side != 0.0 && prod.re < 0.0 && prod.im.abs() <= 1e-28 * prod.re.abs() {
                let up = side * (x[j].add(x[3]).to_c().re).signum();
                if (r.to_c().im > 0.0) != (up > 0.0) {
                    r = r.neg();
                }
            }
            root_jd[j] = r;
            u[p][j] = r.mul(inv_sfp);
            v[p][j] = sg_sfp.div(r);
        }
    }
    Ok((u, v))
}

/// `Δ_j^(p)` (25), corrected: `dd[p][j] = u[q][j] v[r][j] − u[r][j] v[q][j]`
/// for `(p, q, r)` cyclic in `(1, 2, 3)`.
fn delta_determinants(u: &[[Cdd; 3]; 4], v: &[[Cdd; 3]; 4]) -> [[Cdd; 3]; 3] {
    let mut dd = [[Cdd::ZERO; 3]; 3];
    for (p, q, r) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
        for j in 0..3 {
            dd[p][j] = u[q][j].mul(v[r][j]).sub(u[r][j].mul(v[q][j]));
        }
    }
    dd
}

/// `√d_j`, `d_j` (26) and `α_j … δ_j` (24), in DD and rounded.
struct BranchConstants {
    sqrt_d: [C; 3],
    d: [C; 3],
    d_lo: [C; 3],
    d_dd: [Cdd; 3],
    /// `α_j, β_j, γ_j, δ_j` (rows), in DD.
    abgd_dd: [[Cdd; 3]; 4],
}

impl BranchConstants {
    /// From the coefficients of (20) and the determinants (25).
    ///
    /// Errors: `Δ_j^(3) = 0` (the pair `s1, s2` does not determine
    /// `m_j, n_j`); `d_j` zero or infinite.
    fn from_determinants(
        u: &[[Cdd; 3]; 4],
        v: &[[Cdd; 3]; 4],
        dd: &[[Cdd; 3]; 3],
    ) -> Result<BranchConstants> {
        let mut bc = BranchConstants {
            sqrt_d: [ZERO; 3],
            d: [ZERO; 3],
            d_lo: [ZERO; 3],
            d_dd: [Cdd::ZERO; 3],
            abgd_dd: [[Cdd::ZERO; 3]; 4],
        };
        for j in 0..3 {
            let d3 = dd[2][j];
            let size = (u[0][j].to_c().modulus() + v[0][j].to_c().modulus())
                * (u[1][j].to_c().modulus() + v[1][j].to_c().modulus());
            if d3.to_c().modulus() <= DELTA3_MIN_RTOL * size {
                // √d_j = (Δ1 − iΔ2)/Δ3: d_j at infinity, where the curve (8)
                // has its own branch point.
                return Err(Error::Singular {
                    what: "state l",
                    kind: SingularKind::CoincidingBranchPoints,
                    reason: format!(
                        "Delta_{}^(3) (25) vanishes: l_j^(1), l_j^(2) do not determine m_j, n_j",
                        j + 1
                    ),
                });
            }
            // (26) both halves: √d_j = (Δ1 − iΔ2)/Δ3 = −Δ3/(Δ1 + iΔ2), since
            // (Δ1 − iΔ2)(Δ1 + iΔ2) = −Δ3². A small (or large) d_j is a cancellation
            // in one of Δ1 ∓ iΔ2; the other, larger one keeps full accuracy.
            let i_d2 = dd[1][j].mul_i();
            let (minus, plus) = (dd[0][j].sub(i_d2), dd[0][j].add(i_d2));
            let sd = if minus.to_c().modulus() >= plus.to_c().modulus() {
                minus.div(d3)
            } else {
                d3.div(plus).neg()
            };
            bc.sqrt_d[j] = sd.to_c();
            let dj = sd.mul(sd);
            bc.d[j] = dj.to_c();
            bc.d_lo[j] = dj.sub(Cdd::new(bc.d[j])).to_c();
            let (u1, v1, u2, v2) = (u[0][j], v[0][j], u[1][j], v[1][j]);
            let two_d3 = d3.mul_f64(2.0);
            bc.abgd_dd[0][j] = v2.add(v1.mul_i()).div(two_d3);
            bc.abgd_dd[1][j] = v2.sub(v1.mul_i()).div(two_d3);
            bc.abgd_dd[2][j] = u2.add(u1.mul_i()).div(two_d3).neg();
            bc.abgd_dd[3][j] = u2.sub(u1.mul_i()).div(two_d3).neg();
            bc.d_dd[j] = dj;
            if bc.d[j].modulus() == 0.0 || !bc.d[j].modulus().is_finite() {
                // d_j = 0 meets the branch point d_0 = 0 of (8), d_j = ∞ the one
                // at infinity: the genus drops, as for coinciding roots.
                return Err(Error::Singular {
                    what: "state l",
                    kind: SingularKind::CoincidingBranchPoints,
                    reason: format!("d_{} = {} (26) is zero or infinite", j + 1, cnum(bc.d[j])),
                });
            }
        }
        Ok(bc)
    }
}

type H0Structure = ([C; 3], [C; 3], [C; 4], C, C);

/// `K`, `Kε` and `K/κ` of the corrected (40) (the closed forms of
/// [`h0_structure`]) evaluated in DD from the DD `α_j … δ_j` (`abgd`) and `d_j`,
/// rounded once.
///
/// `2Kε`: `(d_j − d4) q_j` is of degree 1 in `d_j`, so two nodes suffice and
/// the symmetric three-node form `κ Σ c̃_j q_j` equals the slope
/// `(q_j − q_k)/(w_j − w_k)`, `w_j = 1/(d_j − d4)`, through any pair. The pair
/// with the most separated `w` avoids the cancellation of the three-node form
/// when two `d_j` nearly coincide (`c̃_j ~ 1/(d_1 − d_2)`: 1e12 on
/// near-degenerate states). Near the singular set `d_4` dominates the `d_j` by 1e15 and
/// more, so `w_j = 1/(d_j − d_4)` agree to ~`|d_j|/|d_4|` and the slope
/// `2Kε = (q_j − q_k)/(w_j − w_k)` divides a difference of nearly equal `q_j`
/// by one of nearly equal `w_j`: in double both are rounding noise (ε came out
/// NaN at `d_4 ~ 1e26`); `w_j − w_k = (d_k − d_j)/((d_j − d_4)(d_k − d_4))` and DD
/// `q_j` keep them.
fn k_keps_dd(abgd: &[[Cdd; 3]; 4], d: &[Cdd; 3]) -> (C, C, C) {
    let [al, be, ga, de] = abgd;
    let d4 = d[0].mul(d[1]).mul(d[2]);
    let dm4: [Cdd; 3] = std::array::from_fn(|j| d[j].sub(d4));
    let kappa = dm4[0].mul(dm4[1]).mul(dm4[2]);
    let mut k_over_kappa = Cdd::ZERO;
    for (j, &(_, kk, ll)) in CYCLIC.iter().enumerate() {
        let ct = d[j].sub(d[kk]).mul(d[j].sub(d[ll])).recip();
        k_over_kappa = k_over_kappa.add(ct.mul(d[j]).mul(be[j].mul(de[j])));
    }
    let dw = |j: usize, k: usize| d[k].sub(d[j]).div(dm4[j].mul(dm4[k]));
    let (pj, pk) = [(0, 1), (0, 2), (1, 2)]
        .into_iter()
        .max_by(|&(a, b), &(c, e)| {
            dw(a, b)
                .to_c()
                .modulus()
                .partial_cmp(&dw(c, e).to_c().modulus())
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .unwrap_or((0, 1));
    let q = |j: usize| al[j].mul(de[j]).add(be[j].mul(ga[j]));
    let k_eps = q(pj).sub(q(pk)).div(dw(pj, pk)).mul_f64(0.5);
    (
        kappa.mul(k_over_kappa).to_c(),
        k_eps.to_c(),
        k_over_kappa.to_c(),
    )
}

/// (38)–(40): `H0 = Σ_j m_j n_j` as a quadratic form in `ξ, η`, reduced modulo
/// Kötter's quadrics (11), all in closed form.
///
/// `H0 = Σ_j p_j ξ_j² + q_j ξ_j η_j + r_j η_j²` with `p_j = α_j γ_j`,
/// `q_j = α_j δ_j + β_j γ_j`, `r_j = β_j δ_j` (from (23)). Adding
/// `λ Q1 + μ Q2 + ν Q3` of (11) gives the form (38) when
/// `p_j + λ + ν d_j = −(r_j + λ + ν/d_j) =: A_j` and `B_j = q_j + μ`; (39) asks
/// `A_j = α + β d_j + γ/d_j`, `B_j = δ (d_j + 1/d_j)`. Times `d_j`, these are
/// values at `x = d_j` of quadratics in `x`, so a representative exists iff the
/// Lagrange interpolants through `d_1, d_2, d_3` have equal `x²` and `x⁰`
/// coefficients: `Σ_j c_j q_j = 0` and `Σ_j c_j (p_j + r_j) = 0` (`c_j` of (33));
/// both hold identically (they are checked here to [`STRUCTURE_RTOL`]).
///
/// The corrected (40): on the quadrics, by (30a), (30b), (31b),
/// `H0 ≡ K/d4 Σ η_j²/(d_j − d4) + 2Kε Σ ξ_jη_j/(d_j − d4) + Kε² Σ d_j ξ_j²/(d_j − d4)`
/// `= K g² (1 − ε P_0)²` with, in closed form (`κ = Π_m (d_m − d4)`,
/// `c̃_j` of (33)),
/// `K = κ Σ_j c̃_j d_j β_j δ_j`, `2Kε = κ Σ_j c̃_j (α_j δ_j + β_j γ_j)`,
/// `Kε² = (κ/d4) Σ_j c̃_j α_j γ_j`; the perfect square `(Kε)² = K · Kε²` is checked.
/// Reducing this representative to the form (38) (the residue sums
/// `Σ_j c̃_j d_j^n/(d_j − d4) = d4^n/κ`, `n ≤ 2`) gives (39) explicitly:
/// `β = −K/κ`, `γ = ε² d4² K/κ`, `δ = 2 ε d4 K/κ`,
/// `α = (K/(2κ)) (κ ε² + (e1 − d4)(1 − ε² d4²))`, `e1 = d1 + d2 + d3`
/// (docs/kotter.md §7).
fn h0_structure(
    alpha: &[C; 3],
    beta: &[C; 3],
    gamma: &[C; 3],
    delta: &[C; 3],
    d: &[C; 3],
    (k, k_eps, k_over_kappa): (C, C, C),
) -> Result<(H0Structure, Option<Error>)> {
    let d4 = d[0] * d[1] * d[2];
    let ac: [C; 3] = std::array::from_fn(|j| alpha[j] * gamma[j]);
    let bc: [C; 3] = std::array::from_fn(|j| alpha[j] * delta[j] + beta[j] * gamma[j]);
    let cc: [C; 3] = std::array::from_fn(|j| beta[j] * delta[j]);
    let ct: [C; 3] = std::array::from_fn(|j| {
        let (k2, l2) = ((j + 1) % 3, (j + 2) % 3);
        ONE / ((d[j] - d[k2]) * (d[j] - d[l2]))
    });
    let c33: [C; 3] = std::array::from_fn(|j| (d[j] - d4) * ct[j]);
    let (r1, r2) = existence_residuals(&c33, &ac, &bc, &cc, alpha, beta, gamma, delta);
    // (40) corrected, in closed form. On the quadrics H0 ≡ K g² − 2Kε g²P_0 +
    // Kε² g²P_0², with g² = Σ η_j²/((d_j − d4) d4) (30a), g²P_0 = −Σ ξ_jη_j/(d_j − d4)
    // (31b), g²P_0² = Σ d_j ξ_j²/(d_j − d4) (30b), up to λQ1 + μQ2 + νQ3 of (11).
    // Matching the coefficients of η_j², ξ_jη_j, ξ_j² and multiplying by (d_j − d4)
    // (and d_j) gives polynomials of degree ≤ 2 in d_j whose value at x = d4 —
    // the Lagrange interpolant through d1, d2, d3, L_j(d4) = c̃_j (d4 − d_k)(d4 − d_l)
    // — isolates the K terms, since the multiplier terms vanish at x = d4:
    // K = κ Σ c̃_j d_j r_j, 2Kε = κ Σ c̃_j q_j, Kε² d4 = κ Σ c̃_j p_j, with
    // κ = Π (d_m − d4) (docs/kotter.md §7). K, Kε and K/κ come from
    // [`k_keps_dd`] (K/κ directly: κ vanishes when some d_j = d4).
    let kappa = (d[0] - d4) * (d[1] - d4) * (d[2] - d4);
    // K = 0: h0 negligible (constants_impl), where ε = 0 too and the perfect
    // square below holds trivially.
    let eps = if k == ZERO { ZERO } else { k_eps / k };
    // The perfect square of (40), (Kε)² = K · Kε², with Kε² d4 = κ Σ c̃_j p_j;
    // relative to the size of the terms (the sum cancels when two d_j are close).
    let terms_e2: f64 = (0..3).map(|j| (ct[j] * ac[j]).modulus()).sum();
    let k_eps2: C = kappa / d4 * (0..3).map(|j| ct[j] * ac[j]).sum::<C>();
    let r3 = if k == ZERO {
        0.0
    } else {
        (k_eps * k_eps - k * k_eps2).modulus()
            / ((k_eps * k_eps).modulus() + (k * kappa / d4).modulus() * terms_e2)
    };
    let worst = r1.max(r2).max(r3);
    if worst.is_nan() {
        return Err(structure_refusal(worst));
    }
    let refusal = (worst > STRUCTURE_RTOL).then(|| structure_refusal(worst));
    // (39) in closed form: the (40) representative p_j = Kε² d_j w_j,
    // q_j = 2Kε w_j, r_j = K w_j/d4 reduced to the form (38) (the representative
    // of that form is unique, so these are the paper's α, β, γ, δ).
    let e1 = d[0] + d[1] + d[2];
    let eps2 = eps * eps;
    let beta39 = -k_over_kappa;
    let gamma39 = eps2 * d4 * d4 * k_over_kappa;
    let delta39 = 2.0 * d4 * k_eps / kappa;
    let alpha39 = 0.5 * k_over_kappa * (kappa * eps2 + (e1 - d4) * (ONE - eps2 * d4 * d4));
    let (a_coef, b_coef) = coefficients_38(&ac, &bc, &cc, d);
    let abgd39 = [alpha39, beta39, gamma39, delta39];
    Ok(((a_coef, b_coef, abgd39, eps, k), refusal))
}

/// The refusal of level-set constants whose `H0` does not reduce to the form
/// (38)/(40) ([`STRUCTURE_RTOL`]).
fn structure_refusal(worst: f64) -> Error {
    Error::InvalidArgument {
        what: "Koetter constants",
        reason: format!(
            "H0 does not reduce to the form (38)/(40) on Koetter's quadrics: relative \
             residual {worst:e} > {STRUCTURE_RTOL:e}"
        ),
    }
}

/// The residuals of the existence conditions of (38)–(39): they exist iff
/// `Σ c_j q_j = 0` and `Σ c_j (p_j + r_j) = 0` (the x² and x⁰ coefficients of
/// the interpolants agree); relative to the size of the products that enter
/// (`q_j` and `p_j + r_j` themselves can cancel, and the sums cancel by
/// `1/|d_j − d_k|` when two `d_j` nearly coincide).
#[allow(clippy::too_many_arguments)]
fn existence_residuals(
    c33: &[C; 3],
    ac: &[C; 3],
    bc: &[C; 3],
    cc: &[C; 3],
    alpha: &[C; 3],
    beta: &[C; 3],
    gamma: &[C; 3],
    delta: &[C; 3],
) -> (f64, f64) {
    let rel_sum = |t: [C; 3], size: [f64; 3]| {
        let size: f64 = size.iter().sum();
        (t[0] + t[1] + t[2]).modulus() / size.max(f64::MIN_POSITIVE)
    };
    // The size of a term is that of the full products (|α_j| + |β_j|)(|γ_j| + |δ_j|)
    // of (23)'s coefficients, the scale of their rounding: near h0 = 0 some of
    // α_j … δ_j vanish like h0 (docs/degenerate.md), and the products p_j + r_j,
    // q_j with them, so relative to those products alone the sums would be noise.
    let full: [f64; 3] = std::array::from_fn(|j| {
        (alpha[j].modulus() + beta[j].modulus()) * (gamma[j].modulus() + delta[j].modulus())
    });
    let r1 = rel_sum(
        std::array::from_fn(|j| c33[j] * (ac[j] + cc[j])),
        std::array::from_fn(|j| c33[j].modulus() * full[j]),
    );
    let r2 = rel_sum(
        std::array::from_fn(|j| c33[j] * bc[j]),
        std::array::from_fn(|j| c33[j].modulus() * full[j]),
    );
    (r1, r2)
}

/// `A_j`, `B_j` of (38)–(39) from the same reduction applied to
/// `p = ac`, `q = bc`, `r = cc` per `j`: `ν = −(s_j − s_k)/(t_j − t_k)`,
/// `s = p + r`, `t_j = d_j + 1/d_j`, then `A_j = (p_j − r_j)/2 + (ν/2)(d_j − 1/d_j)`;
/// `B_j = q_j + μ` with `μ = δ t_j − q_j`, `δ = (q_j − q_k)/(t_j − t_k)`. Two
/// nodes (the most separated `t`) suffice and keep `A_j`, `B_j` accurate when
/// two `d_j` nearly coincide, where `α, β, γ` (three-node quantities, through
/// `K`) are only known to ~`u/|d_j − d_k|²`.
fn coefficients_38(ac: &[C; 3], bc: &[C; 3], cc: &[C; 3], d: &[C; 3]) -> ([C; 3], [C; 3]) {
    let t: [C; 3] = std::array::from_fn(|j| d[j] + ONE / d[j]);
    let (tj, tk) = [(0, 1), (0, 2), (1, 2)]
        .into_iter()
        .fold((0, 1), |best, (j, kk)| {
            if (t[j] - t[kk]).modulus() > (t[best.0] - t[best.1]).modulus() {
                (j, kk)
            } else {
                best
            }
        });
    let nu = -((ac[tj] + cc[tj]) - (ac[tk] + cc[tk])) / (t[tj] - t[tk]);
    let delta_two = (bc[tj] - bc[tk]) / (t[tj] - t[tk]);
    let mu = delta_two * t[tj] - bc[tj];
    let a_coef: [C; 3] =
        std::array::from_fn(|j| 0.5 * (ac[j] - cc[j]) + 0.5 * nu * (d[j] - ONE / d[j]));
    let b_coef: [C; 3] = std::array::from_fn(|j| bc[j] + mu);
    (a_coef, b_coef)
}

/// `l^(p) = l(s_p)/√F'(s_p)` (20) for `p = 1 … 4`, on the documented branches.
///
/// Summed in DD from `u + u_lo`, `v + v_lo` ([`KotterConstants::u_lo`]) and
/// rounded once: near the singular set the two terms cancel.
pub fn l_p(k: &KotterConstants, l: &[f64; 6]) -> [[C; 3]; 4] {
    l_p_dd(k, l).map(|row| row.map(Cdd::to_c))
}

pub(super) fn l_p_dd(k: &KotterConstants, l: &[f64; 6]) -> [[Cdd; 3]; 4] {
    let (m, n) = m_n(l);
    std::array::from_fn(|p| {
        std::array::from_fn(|j| {
            let u = Cdd::from_parts(k.u[p][j], k.u_lo[p][j]);
            let v = Cdd::from_parts(k.v[p][j], k.v_lo[p][j]);
            u.mul_f64(m[j]).add(v.mul_f64(n[j]))
        })
    })
}

/// Kötter's vectors (22): `ξ = l^(1) + i l^(2)`, `η = l^(1) − i l^(2)` (from
/// the DD sums of [`l_p`], rounded once).
pub fn xi_eta(k: &KotterConstants, l: &[f64; 6]) -> ([C; 3], [C; 3]) {
    let lp = l_p_dd(k, l);
    let xi = std::array::from_fn(|j| lp[0][j].add(lp[1][j].mul_i()).to_c());
    let eta = std::array::from_fn(|j| lp[0][j].sub(lp[1][j].mul_i()).to_c());
    (xi, eta)
}

/// Relative size of the imaginary part above which [`l_from_xi_eta`] refuses
/// to return a real state: a round trip leaves ~1e-15 on well-conditioned
/// curves and up to ~1e-8 near coinciding branch points; data that do not
/// come from a real state leave an O(1) imaginary part.
pub const REAL_RTOL: f64 = 1e-6;

/// The state from `ξ, η` by (23): `m_j = α_j ξ_j + β_j η_j`,
/// `n_j = γ_j ξ_j + δ_j η_j`, `l = (m3, −m2, n1, m1, n2, n3)`.
///
/// Errors: non-finite input; an imaginary part larger than [`REAL_RTOL`]
/// times the size of `l` (the data do not describe a real state).
pub fn l_from_xi_eta(k: &KotterConstants, xi: &[C; 3], eta: &[C; 3]) -> Result<[f64; 6]> {
    real_state(&k.coefficients23(), xi, eta)
}

fn real_state(k: &Coefficients23, xi: &[C; 3], eta: &[C; 3]) -> Result<[f64; 6]> {
    let mut m = [0.0; 3];
    let mut n = [0.0; 3];
    let mut im: f64 = 0.0;
    let mut size: f64 = 0.0;
    for j in 0..3 {
        let mj = k.alpha[j] * xi[j] + k.beta[j] * eta[j];
        let nj = k.gamma[j] * xi[j] + k.delta[j] * eta[j];
        if !(mj.re.is_finite() && mj.im.is_finite() && nj.re.is_finite() && nj.im.is_finite()) {
            return Err(Error::NonFinite {
                what: "m_j, n_j from (xi, eta)",
                index: j,
            });
        }
        im = im.max(mj.im.abs()).max(nj.im.abs());
        size = size.max(mj.modulus()).max(nj.modulus());
        m[j] = mj.re;
        n[j] = nj.re;
    }
    if im > REAL_RTOL * size {
        return Err(Error::InvalidArgument {
            what: "xi, eta",
            reason: format!(
                "they give a complex state: max |Im m_j, Im n_j| = {im:e} > {REAL_RTOL:e} * {size:e}"
            ),
        });
    }
    Ok(l_from_m_n(&m, &n))
}

/// The coefficients `α_j, β_j, γ_j, δ_j` of (23), the linear map `(ξ, η) → (m, n)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients23 {
    /// `α_j`.
    pub alpha: [C; 3],
    /// `β_j`.
    pub beta: [C; 3],
    /// `γ_j`.
    pub gamma: [C; 3],
    /// `δ_j`.
    pub delta: [C; 3],
}

impl Coefficients23 {
    /// The state of (23); see [`l_from_xi_eta`].
    pub fn state(&self, xi: &[C; 3], eta: &[C; 3]) -> Result<[f64; 6]> {
        for (what, v) in [
            ("alpha", &self.alpha),
            ("beta", &self.beta),
            ("gamma", &self.gamma),
            ("delta", &self.delta),
        ] {
            if let Some(index) = v
                .iter()
                .position(|z| !(z.re.is_finite() && z.im.is_finite()))
            {
                return Err(Error::NonFinite { what, index });
            }
        }
        real_state(self, xi, eta)
    }
}

impl KotterConstants {
    /// The coefficients of (23).
    pub fn coefficients23(&self) -> Coefficients23 {
        Coefficients23 {
            alpha: self.alpha,
            beta: self.beta,
            gamma: self.gamma,
            delta: self.delta,
        }
    }
}
