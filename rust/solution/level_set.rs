//! The level set of `l0` as the reduction and the Riemann-surface layer see
//! it: the refusals of the singular level sets, Kötter's constants, the curve
//! (8) in both forms, the characteristics of the labels, and the Abel map of
//! the reduction's points.

use super::*;

/// `ε` by the corrected (41), in root differences of `F`: with
/// `Y = √((s2−s3)(s1−s4))`, `W = √((s1−s3)(s2−s4))`, `Z = √((s1−s2)(s3−s4))`
/// the two combinations `(Y ∓ W)/(√d_4 Z)` are `ε` and `−1/(d_4 ε)`
/// (`Y² − W² = −Z²`), and principal roots do not tell which is which; the
/// one (and the sign) nearest the reduction's `ε` (corrected (40)) is taken.
/// (41) serves because it keeps its digits where (40)'s sums cancel.
pub(super) fn eps41(k: &KotterConstants) -> C {
    // ε = 0 marks a negligible h0 (kotter::H0_NEGLIGIBLE_RTOL), where (41)
    // divides 0 by 0 (the roots of F are pairwise equal).
    if k.eps == C::new(0.0, 0.0) {
        return k.eps;
    }
    let s = k.s;
    let sq = sqrt_principal;
    let sd4 = k.sqrt_d[0] * k.sqrt_d[1] * k.sqrt_d[2];
    let y = sq((s[1] - s[2]) * (s[0] - s[3]));
    let w = sq((s[0] - s[2]) * (s[1] - s[3]));
    let z = sq((s[0] - s[1]) * (s[2] - s[3]));
    let den = sd4 * z;
    // (Y − W)(Y + W) = −Z²: the smaller of Y ∓ W is −Z²/(the larger), without
    // the cancellation of the difference (near h0 = 0 the roots pair up, Z ~ h0
    // and Y ≈ ±W to O(h0²)).
    let (ym, yp) = (y - w, y + w);
    let (ym, yp) = if ym.norm() <= yp.norm() {
        (-z * z / yp, yp)
    } else {
        (ym, -z * z / ym)
    };
    [ym / den, yp / den]
        .into_iter()
        .flat_map(|e| [e, -e])
        .filter(|e| e.re.is_finite() && e.im.is_finite())
        .min_by(|p, q| (p - k.eps).norm().total_cmp(&(q - k.eps).norm()))
        .unwrap_or(k.eps)
}

/// The Abel map takes the route from the nearest branch point `d_b` with the
/// reduction's offset `z − d_b` when that offset is below this fraction of
/// `|z|`: the double `z` fixes `z − d_b` only to `u |z|` absolute (u the unit
/// roundoff), so below it the local parameter `√(z − d_b)` would lose
/// `u |z| / |z − d_b|` of its digits; the offset keeps them.
const NEAR_BRANCH_FRACTION: f64 = 0.1;

/// The Abel map of a point of the divisor: from its offsets `zd[j] = z − d_j`
/// (full relative accuracy, [`crate::curve::WurzelPoints`]) when it is near a
/// branch point ([`HyperellipticCurve::abel_near_branch`]), else of `z`. The
/// two routes give the Abel map modulo the lattice, so a state moving across
/// the threshold may see its image jump by a lattice vector (the solution's
/// `u0` is computed once; `sol.abel` is documented modulo the lattice).
pub(super) fn abel_of_point(curve: &HyperellipticCurve, z: C, y: C, zd: &[C; 5]) -> Result<Vec<C>> {
    let b = (0..5)
        .min_by(|&i, &j| zd[i].norm().total_cmp(&zd[j].norm()))
        .unwrap_or(0);
    if zd[b].norm() < NEAR_BRANCH_FRACTION * z.norm() {
        curve.abel_near_branch(b, zd[b], y)
    } else {
        curve.abel(z, y)
    }
}

/// The a-period matrix `A_ij = ∮_{a_j} x^i dx/y` of the curve, row-major.
pub fn a_periods_of(curve: &HyperellipticCurve) -> [C; 4] {
    let (a, _) = curve.periods();
    [a[(0, 0)], a[(0, 1)], a[(1, 0)], a[(1, 1)]]
}

/// The level set of a state as the reduction and the Riemann-surface layer
/// see it: Kötter's constants, the curve (8) in both forms, and the
/// characteristics `χ_L` of [`LABELS`] in the curve's homology basis.
#[derive(Debug, Clone)]
pub struct LevelSetCurve {
    /// Kötter's constants of the level set ([`kotter_constants`]).
    pub kotter: KotterConstants,
    /// The curve (8) with the Wurzelfunktionen.
    pub kcurve: KotterCurve,
    /// The same curve with periods, Abel map and theta characteristics
    /// (branch points passed as `(d_0, …, d_4)`).
    pub curve: HyperellipticCurve,
    /// `χ_0 = η(d_0)`, `χ_kl = η(d_k) + η(d_l)`, `χ_j4 = η(d_j) + η(d_4)` for
    /// the labels `P0, P23, P31, P12, P14, P24, P34`.
    pub chars: [([u8; 2], [u8; 2]); 7],
}

/// The checks of `l0` that precede the reduction, and the reduction's
/// level-set objects: refuses `l0 = 0`, `h1² = 4h0²` (relative to
/// [`crate::numeric::tol::SINGULAR_SET_RTOL`], [`so4::near_self_dual`]) and coinciding branch points with a
/// [`Error::Singular`] that names the reason. `h0 = 0` (rank-2 states) is a
/// regular level set: the reduction takes its limit there (docs/degenerate.md).
pub fn level_set_curve(a: &[f64; 4], l0: &[f64; 6]) -> Result<LevelSetCurve> {
    level_set_curve_soft(a, l0, None)
}

/// [`level_set_curve`]; with `soft`, a failure of the structure check of
/// `H0` is written there instead of refused
/// ([`crate::kotter::kotter_constants_soft`]).
pub(crate) fn level_set_curve_soft(
    a: &[f64; 4],
    l0: &[f64; 6],
    soft: Option<&mut Option<String>>,
) -> Result<LevelSetCurve> {
    crate::error::check_finite("l0", l0)?;
    let size = l0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if size == 0.0 {
        return Err(singular(
            SingularKind::ZeroState,
            "l0 = 0: the rest state; the solution is l(t) = 0, there is no curve (8)".into(),
        ));
    }
    let [hp, hm] = so4::casimir_factors(l0);
    // h1² − 4h0² = (h1 + 2h0)(h1 − 2h0) from the exact sums of squares: the
    // value named in the message is right even where h1² − 4h0² cancels.
    let disc = hp * hm;
    if so4::near_self_dual(hp, hm) {
        return Err(singular(
            SingularKind::SelfDual,
            format!(
                "h1^2 - 4 h0^2 = {disc:e} vanishes (m = ±n, a self-dual state): F (19) is not \
                 defined; the motion reduces to an so(3) top (elliptic functions), the \
                 genus-2 solution exists only as a limit"
            ),
        ));
    }
    let kotter = crate::kotter::kotter_constants_soft(a, l0, soft).map_err(map_coinciding)?;
    let [d1, d2, d3] = kotter.d;
    let kcurve = KotterCurve::new(d1, d2, d3).map_err(map_coinciding)?;
    let curve = HyperellipticCurve::new(&kcurve.branch_points()).map_err(map_coinciding)?;
    // χ_j = η(d_j) (index j of the branch points passed), χ_jk = χ_j + χ_k mod 2.
    let mut eta = [([0u8; 2], [0u8; 2]); 5];
    for (j, e) in eta.iter_mut().enumerate() {
        let (ca, cb) = curve.branch_char(j)?;
        *e = ([ca[0], ca[1]], [cb[0], cb[1]]);
    }
    let sum = |p: usize, q: usize| {
        (
            [
                (eta[p].0[0] + eta[q].0[0]) % 2,
                (eta[p].0[1] + eta[q].0[1]) % 2,
            ],
            [
                (eta[p].1[0] + eta[q].1[0]) % 2,
                (eta[p].1[1] + eta[q].1[1]) % 2,
            ],
        )
    };
    let mut chars = [([0u8; 2], [0u8; 2]); 7];
    chars[0] = eta[0];
    for (j, &(_, k, l)) in CYCLIC.iter().enumerate() {
        chars[1 + j] = sum(k, l);
        chars[4 + j] = sum(j + 1, 4);
    }
    Ok(LevelSetCurve {
        kotter,
        kcurve,
        curve,
        chars,
    })
}

pub(super) fn map_coinciding(e: Error) -> Error {
    match e {
        Error::RepeatedBranchPoints { i, j, value } => coinciding(i, j, value),
        other => other,
    }
}

fn coinciding(i: usize, j: usize, value: C) -> Error {
    let reason = format!(
        "branch points d{i} and d{j} of the curve (8) coincide (= {}){}: the genus drops, \
         the motion is degenerate (the solution exists as a limit in lower-genus functions)",
        crate::error::cnum(value),
        if i == 0 || j == 0 {
            ", i.e. h0 = 0 or a vanishing d_j"
        } else {
            ""
        }
    );
    Error::Singular {
        what: "state l0",
        kind: SingularKind::CoincidingBranchPoints,
        reason,
    }
}
