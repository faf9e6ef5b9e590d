//! The map of a state to Kötter's coordinates and the points of the curve
//! (8) — the algebraic uniformization (37), (42) — and its inverse: the
//! level-set constants, `ξ, η` (22), the inverse map of the curve module
//! started in double-double, and the sign of `g` from the corrected (42).

use super::constants::{l_p_dd, near_singular, Coefficients23, KotterConstants};
use super::{integrals, kotter_constants, C, CYCLIC, ONE, ZERO};
use crate::curve::{CurvePoint, KotterCurve, WurzelPoints};
use crate::error::{check_finite, cnum, Error, Result};
use crate::numeric::complex::sqrt_principal;
use crate::numeric::dd::Cdd;

/// The start of the inverse map of (37) and `P_0` of (31b), from the closed
/// forms of the curve module (`g² = Σ_j c̃_j Y_j²/d_4` (30a),
/// `z1 + z2 = d_4 + Σ_j c̃_j X_j²/g²`, `z1 z2 = Σ_j c̃_j d_j X_j²/g²` (30b),
/// `g² P_0 = −Σ_j c̃_j X_j Y_j` (31b), `X_j = ξ_j/√c_j`, `Y_j = η_j/√c_j`), evaluated
/// in DD on the unrounded curve `d + d_lo` from the DD `ξ, η`. Near the singular
/// set these sums cancel by `|d_4|/|z|` (1e13 and more: `d_4 ~ 1e19` against
/// points `~1e7`), so in double precision they put a point thousands of units
/// off, across a pair of branch points a few units apart; in DD they leave
/// ~`u² |d_4|/|z|`. The offsets are taken from the rounded curve's branch
/// points. `None` when a value is not finite (then the double-precision
/// closed forms stand).
fn inverse_start(
    k: &KotterConstants,
    curve: &KotterCurve,
    xi: &[Cdd; 3],
    eta: &[Cdd; 3],
) -> Option<(crate::curve::InverseStart, C)> {
    let d: [Cdd; 3] = std::array::from_fn(|j| Cdd::from_parts(k.d[j], k.d_lo[j]));
    let d4 = d[0].mul(d[1]).mul(d[2]);
    let sc_round = curve.c().map(sqrt_principal);
    let mut ct = [Cdd::ZERO; 3];
    let mut x = [Cdd::ZERO; 3];
    let mut y = [Cdd::ZERO; 3];
    for (j, &(_, kk, ll)) in CYCLIC.iter().enumerate() {
        ct[j] = d[j].sub(d[kk]).mul(d[j].sub(d[ll])).recip();
        let mut sc = d[j].sub(d4).mul(ct[j]).sqrt();
        // the curve's branch of √c_j (principal of the rounded c_j)
        if (sc.to_c() * sc_round[j].conj()).re < 0.0 {
            sc = sc.neg();
        }
        x[j] = xi[j].div(sc);
        y[j] = eta[j].div(sc);
    }
    let sum = |f: &dyn Fn(usize) -> Cdd| (0..3).fold(Cdd::ZERO, |acc, j| acc.add(f(j)));
    let g2 = sum(&|j| ct[j].mul(y[j]).mul(y[j])).div(d4);
    let s1 = d4.add(sum(&|j| ct[j].mul(x[j]).mul(x[j])).div(g2));
    let s2 = sum(&|j| ct[j].mul(d[j]).mul(x[j]).mul(x[j])).div(g2);
    let p0 = sum(&|j| ct[j].mul(x[j]).mul(y[j])).div(g2).neg();
    // roots of z² − s1 z + s2, the larger first, without cancellation
    let sq = s1.mul(s1).sub(s2.mul_f64(4.0)).sqrt();
    let q = if (s1.to_c().conj() * sq.to_c()).re >= 0.0 {
        s1.add(sq)
    } else {
        s1.sub(sq)
    };
    let z1 = q.mul_f64(0.5);
    let z2 = s2.div(z1);
    let bp = curve.branch_points();
    let offsets = |z: Cdd| -> [C; 5] { bp.map(|b| z.sub(Cdd::new(b)).to_c()) };
    let start = crate::curve::InverseStart {
        z: [z1.to_c(), z2.to_c()],
        zd: [offsets(z1), offsets(z2)],
        g2: g2.to_c(),
    };
    let finite = |v: &C| v.re.is_finite() && v.im.is_finite();
    let ok = start.z.iter().all(finite)
        && start.zd.iter().flatten().all(finite)
        && finite(&start.g2)
        && start.g2 != ZERO
        && finite(&p0.to_c());
    ok.then_some((start, p0.to_c()))
}

/// Tolerance passed to the inverse map of the curve module
/// ([`KotterCurve::points_from_xi_eta`]): exact data reproduce `(ξ, η)` to
/// ~1e-14 relative on well-conditioned curves, to ~1e-7 when two branch
/// points nearly coincide (points trapped between them); data off the
/// quadrics miss by O(1), so 1e-6 separates the two.
pub const UNIFORM_RTOL: f64 = 1e-6;

/// Relative agreement required between `g` from (30a) (the curve's inverse
/// map) and the corrected (42). The sign choice needs only `|Δg| ≪ |g|`; the
/// accuracy of the closed forms for `K`, `ε` (sums with `c̃_j ~ 1/(d_j − d_k)`)
/// degrades with the conditioning of the `d_j` (clustered roots of F give
/// ~1e-8), so 1e-6 flags a wrong structure, not rounding.
pub const G42_RTOL: f64 = 1e-6;

/// A state in Kötter's coordinates: the constants of its level set, the
/// vectors `l^(p)`, `ξ, η`, the curve (8) and the point pair with `g` (37), (42).
#[derive(Debug, Clone, PartialEq)]
pub struct KotterState {
    /// Constants of the level set.
    pub constants: KotterConstants,
    /// `l^(p)` (20), `p = 1 … 4`.
    pub l_p: [[C; 3]; 4],
    /// `ξ` (22).
    pub xi: [C; 3],
    /// `η` (22).
    pub eta: [C; 3],
    /// The curve (8) with the `d_j` of (26).
    pub curve: KotterCurve,
    /// `P_0 = √(z1 z2)` in the curve's branch, from (31b): `P_0 = −Σ_j c̃_j P_j4 P_kl`.
    pub p0: C,
    /// The points, `g` and the branch of the `P_j` (see [`crate::curve`]),
    /// with `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4` (37); the sign of `g` is
    /// fixed by the corrected (42): `g (1 − ε P_0) = √(h0/K)` (principal root).
    pub points: WurzelPoints,
}

/// From a state `l` of the top with parameters `a` to Kötter's coordinates
/// and the points of the curve (the algebraic uniformization (37), (42)).
///
/// `g` (37) is fixed up to sign by (30a), `g² = Σ_j c̃_j (η_j/√c_j)² / d4`;
/// the corrected (40) reads `h0 = K g² (1 − ε P_0)²`, so the corrected (42)
/// is `g = √(h0/K) / (1 − ε P_0)`, which fixes the sign (and is checked).
///
/// Errors: those of [`kotter_constants`], of [`KotterCurve::new`] (coinciding
/// branch points `d_j`: the genus drops) and of the inverse map of the curve
/// module (`z1 = z2`, data off the quadrics); and `1 − ε P_0 = 0` (then (42)
/// puts `g` at infinity: `ξ, η` are not finite multiples of the `P_jk`).
pub fn kotter(a: &[f64; 4], l: &[f64; 6]) -> Result<KotterState> {
    let constants = kotter_constants(a, l)?;
    kotter_with(constants, l)
}

/// [`kotter`] for a state whose level-set constants are already known
/// (e.g. along a trajectory). The constants must belong to `l`'s level set.
pub fn kotter_with(constants: KotterConstants, l: &[f64; 6]) -> Result<KotterState> {
    kotter_with_soft(constants, l, None)
}

/// [`kotter_with`]; with `soft`, a disagreement of `g` with the corrected
/// (42) ([`G42_RTOL`]) is written there instead of refused (for a solution
/// that certifies every `l(t)` by an integration,
/// `crate::solution::Solution::with_c4_lo_certifying`).
pub(crate) fn kotter_with_soft(
    constants: KotterConstants,
    l: &[f64; 6],
    soft: Option<&mut Option<String>>,
) -> Result<KotterState> {
    check_finite("l", l)?;
    near_singular(l, kotter_with_impl(constants, l, soft))
}

fn kotter_with_impl(
    constants: KotterConstants,
    l: &[f64; 6],
    soft: Option<&mut Option<String>>,
) -> Result<KotterState> {
    let lp_dd = l_p_dd(&constants, l);
    let lp = lp_dd.map(|row| row.map(Cdd::to_c));
    let xi_dd: [Cdd; 3] = std::array::from_fn(|j| lp_dd[0][j].add(lp_dd[1][j].mul_i()));
    let eta_dd: [Cdd; 3] = std::array::from_fn(|j| lp_dd[0][j].sub(lp_dd[1][j].mul_i()));
    let (xi, eta) = (xi_dd.map(Cdd::to_c), eta_dd.map(Cdd::to_c));
    let [d1, d2, d3] = constants.d;
    let curve = KotterCurve::new(d1, d2, d3)?;
    let start = inverse_start(&constants, &curve, &xi_dd, &eta_dd);
    let p0 = match &start {
        Some((_, p0)) => *p0,
        None => {
            let ct = curve.c_tilde();
            let sc = curve.c().map(sqrt_principal);
            let d4 = curve.branch_points()[4];
            let x: [C; 3] = std::array::from_fn(|j| xi[j] / sc[j]);
            let y: [C; 3] = std::array::from_fn(|j| eta[j] / sc[j]);
            let g2: C = (0..3).map(|j| ct[j] * y[j] * y[j]).sum::<C>() / d4;
            let g2p0: C = -(0..3).map(|j| ct[j] * x[j] * y[j]).sum::<C>();
            g2p0 / g2
        }
    };
    let g42_at = |p0: C| -> Result<C> {
        let one_m = ONE - constants.eps * p0;
        let size = 1.0 + (constants.eps * p0).norm();
        if !(one_m.re.is_finite() && one_m.im.is_finite()) {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "1 - eps P_0 is not finite (eps = {}, P_0 = {}): g (42) is undefined",
                    cnum(constants.eps),
                    cnum(p0)
                ),
            });
        }
        if one_m.norm() <= 1e-12 * size {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "1 - eps P_0 = {} vanishes: g (42) is infinite at this state",
                    cnum(one_m)
                ),
            });
        }
        Ok(sqrt_principal(C::new(constants.h[0], 0.0) / constants.k) / one_m)
    };
    // h0 negligible (K = 0): (42) is 0/0 and the sign of g free; g from (30a).
    let h0_free = constants.k == ZERO;
    // The sign of g from (42) at the closed-form P_0 (31b); the consistency
    // check at P_0 of the polished points: near the singular set the closed
    // form cancels like the start of the inverse map (to ~1e-6 at
    // (h1² − 4h0²)/h1² = 4e-12), while P_0 = eps_0 √z1 √z2 of the points is
    // accurate.
    let g_sign = if h0_free { None } else { Some(g42_at(p0)?) };
    let lmap = [
        constants.alpha,
        constants.beta,
        constants.gamma,
        constants.delta,
    ];
    let points = curve.points_from_xi_eta_start(
        xi,
        eta,
        None,
        g_sign,
        UNIFORM_RTOL,
        Some(&lmap),
        start.as_ref().map(|(s, _)| s),
    )?;
    let p0 =
        f64::from(points.eps[0]) * sqrt_principal(points.zd1[0]) * sqrt_principal(points.zd2[0]);
    let g42 = if h0_free { points.g } else { g42_at(p0)? };
    let mis = (points.g - g42).norm();
    if mis.is_nan() || mis > G42_RTOL * g42.norm() {
        let e = Error::InvalidArgument {
            what: "state l",
            reason: format!(
                "the corrected (42) g = sqrt(h0/K)/(1 - eps P0) = {} disagrees with g = {} \
                 from (30a) (|difference| = {mis:.1e})",
                cnum(g42),
                cnum(points.g)
            ),
        };
        if mis.is_nan() {
            return Err(e);
        }
        crate::error::soften(soft, e)?;
    }
    Ok(KotterState {
        constants,
        l_p: lp,
        xi,
        eta,
        curve,
        p0,
        points,
    })
}

/// States whose integrals differ from the level set's by more than
/// `LEVEL_SET_RTOL` (relative to `h1` and its powers, see [`on_level_set`])
/// are not on it: a trajectory integrated at `rtol = 1e-10` drifts by
/// ~1e-10 over long runs, a state of another level set by O(1).
pub const LEVEL_SET_RTOL: f64 = 1e-6;

/// Checks that `l` lies on the level set of `constants` (to [`LEVEL_SET_RTOL`]):
/// `|h_i(l) − h_i| ≤ LEVEL_SET_RTOL · h1 · A^{max(i−1, 0)}`, `A = max(1, max|a_j|)`
/// (`h0`, `h1` are quadratic in `l`; `h2`, `h3` carry one and two powers of `a`).
pub fn on_level_set(constants: &KotterConstants, l: &[f64; 6]) -> Result<()> {
    check_finite("l", l)?;
    let h = integrals(&constants.a, l);
    let amax = constants.a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let h1 = constants.h[1].abs().max(h[1].abs());
    for (i, (&hi, &ci)) in h.iter().zip(constants.h.iter()).enumerate() {
        let scale = h1 * amax.powi((i as i32 - 1).max(0));
        let miss = (hi - ci).abs();
        if miss.is_nan() || miss > LEVEL_SET_RTOL * scale {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "it is not on this level set: h{i}(l) = {:e} differs from the level set's \
                     h{i} = {ci:e} by {miss:e} > {LEVEL_SET_RTOL:e} * {scale:e}",
                    hi
                ),
            });
        }
    }
    Ok(())
}

/// Exchanges the two points of `cur` when that brings them nearer to those
/// of `prev` (the pair is unordered; (27)–(28) and with them `ξ, η`, `g`,
/// `eps` are symmetric in the two points).
pub fn follow_order(prev: &WurzelPoints, cur: &mut WurzelPoints) {
    let same = (cur.z1 - prev.z1).norm() + (cur.z2 - prev.z2).norm();
    let swapped = (cur.z1 - prev.z2).norm() + (cur.z2 - prev.z1).norm();
    if swapped < same {
        std::mem::swap(&mut cur.z1, &mut cur.z2);
        std::mem::swap(&mut cur.y1, &mut cur.y2);
        std::mem::swap(&mut cur.zd1, &mut cur.zd2);
    }
}

/// One branch per level set: the states `l` (e.g. samples of a trajectory,
/// in time order) mapped with the constants of one level set, fixed once
/// (`kotter_constants(a, l0)`), by [`kotter_with`]. The roots' order, `σ_p`,
/// `√F'(s_p)`, `√c_j`, `K` and with them `ξ, η` (linear in `l`) and
/// `g = √(h0/K)/(1 − εP_0)` (42) are then the same functions of `l` at every
/// sample, so the divisor moves continuously along a trajectory and never
/// jumps to its hyperelliptic-involution image. Each row's point pair is
/// ordered to follow the previous successful row ([`follow_order`]).
///
/// Per row: the error of [`on_level_set`] or [`kotter_with`].
pub fn kotter_along(constants: &KotterConstants, rows: &[[f64; 6]]) -> Vec<Result<KotterState>> {
    let mut prev: Option<WurzelPoints> = None;
    rows.iter()
        .map(|l| kotter_along_step(constants, l, &mut prev))
        .collect()
}

/// One row of [`kotter_along`]: `l` mapped with `constants`, its points in
/// the order that follows `prev` (the last row mapped, updated on success).
pub fn kotter_along_step(
    constants: &KotterConstants,
    l: &[f64; 6],
    prev: &mut Option<WurzelPoints>,
) -> Result<KotterState> {
    on_level_set(constants, l)?;
    let mut st = kotter_with(constants.clone(), l)?;
    if let Some(p) = prev.as_ref() {
        follow_order(p, &mut st.points);
    }
    *prev = Some(st.points);
    Ok(st)
}

/// The inverse of [`kotter`]: the state `l` from the curve's points, `g`
/// and the branch of the `P_j` by (37) and (23):
/// `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`, `m_j = α_j ξ_j + β_j η_j`,
/// `n_j = γ_j ξ_j + δ_j η_j`, `l = (m3, −m2, n1, m1, n2, n3)`.
///
/// `z = [z1, z2]`, `y = [y1, y2]`; `zd = Some([zd1, zd2])` gives the offsets
/// `zd_i[j] = z_i − d_j` (as returned in [`KotterState::points`]), used for
/// the roots `√(z_i − d_j)` of (27)–(28) — with only `z` (`zd = None`) a
/// point within `δ` of a branch point loses `u |z| / δ` (see
/// [`crate::curve::CurvePoint`]).
///
/// Errors: those of [`KotterCurve::xi_eta_points`] (points off the curve,
/// offsets inconsistent with `z`, `z1 = z2`, a bad branch) and of
/// [`l_from_xi_eta`](super::l_from_xi_eta) (a complex state).
pub fn from_kotter(
    coef: &Coefficients23,
    d: [C; 3],
    z: [C; 2],
    y: [C; 2],
    zd: Option<[[C; 5]; 2]>,
    g: C,
    branch: [i8; 5],
) -> Result<[f64; 6]> {
    let curve = KotterCurve::new(d[0], d[1], d[2])?;
    let pt = |i: usize| match zd {
        Some(o) => CurvePoint {
            z: z[i],
            y: y[i],
            zd: o[i],
        },
        None => curve.point(z[i], y[i]),
    };
    let (xi, eta) = curve.xi_eta_points(&pt(0), &pt(1), g, Some(branch), None)?;
    coef.state(&xi, &eta)
}
