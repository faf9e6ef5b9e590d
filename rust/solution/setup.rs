//! The constants of the Theorem's quotients at the divisor of `l0`: the
//! constants `C_L` of (34) by a consensus of auxiliary divisors, `g (1 − εP_0)`
//! from the theta side, the weights of `l_q = N_q/D` ((37), (42), (23)) and
//! the velocity `U` from Frahm's equations (1) at `v0` by least squares.

use super::*;
use crate::numeric::complex::Modulus;
use std::cmp::Ordering;

/// The estimate of the `C_L²` at `v0` takes part in the consensus of
/// [`aux_constants_squared`] when every needed `|θ[χ](v0)|` is at least this
/// fraction of the largest (below, the quotient `P_L θ/θ_L` loses digits).
const AUX_V0_MIN: f64 = 1e-3;

/// Relative least-squares residual of the velocity equations
/// `(∇N_q − l_q ∇D)·U = l̇_q D` above which the theta quotients at `v0` solve
/// Frahm's equations (1) for no velocity: the set-up is wrong, and the
/// solution is refused rather than returned. Consistent set-ups leave ~1e-13
/// (≤ 1e-10 on near_degenerate); the set-ups that took the wrong combination
/// of (41) left 1e-2 … 1.
pub const QUOTIENT_RESIDUAL_RTOL: f64 = 1e-6;

/// `what` of the error for quotients that solve (1) for no velocity.
pub const INCONSISTENT: &str = "theta quotients at v0";

/// The velocity equations at `v0`: `l_q = N_q(v)/D(v)` gives
/// `(∇N_q − l_q ∇D)·U = l̇_q D`, six complex equations for `U ∈ C²`, with the
/// gradients from the theta jet at `v0`. The rows are the components of `l`
/// themselves, unscaled (they share the scale `|l|`), and `l̇` is (1) at the
/// quotient's own value `l_q(v0)` (it differs from `l0` by the rounding of the
/// constants, ~1e-13): `U` is then the rate of the theta quotient's own flow.
/// On tops with a nearly symmetric pair `a_i ≈ a_j` (`|U|` ~ 100) this keeps
/// `U` to ~1e-14, where rows in `ξ, η` scaled to unit size lost up to 1e-12 of
/// `U` (1e-9 of `l` at `t = 20`).
/// Relative residual of the normal equations `Aᴴ(r − A U)` (in units of
/// `|A| (|A| |U| + |r|)`) above which the SVD's least-squares solution of the
/// velocity system is replaced by Householder QR's ([`VelocitySystem::rate`]):
/// accurate solutions leave a few `u` (rounding of the residual itself).
const NORMAL_RESIDUAL_RTOL: f64 = 64.0 * f64::EPSILON;

/// `|Aᴴ(r − A x)| / (|A| (|A| |x| + |r|))`, Frobenius and 2-norms, the
/// residual `r − A x` in double-double (it is the small difference of two
/// large terms that decides; in double its rounding alone would be of the
/// size of the threshold).
fn normal_residual(a: &DMatrix<C>, x: &DVector<C>, r: &DVector<C>) -> f64 {
    use crate::numeric::dd::Cdd;
    let (m, n) = a.shape();
    let res = DVector::<C>::from_fn(m, |i, _| {
        (0..n)
            .fold(Cdd::new(r[i]), |acc, j| {
                acc.sub(Cdd::new(a[(i, j)]).mul_c(x[j]))
            })
            .to_c()
    });
    let g = a.adjoint() * res;
    let an = a.norm();
    g.norm() / (an * (an * x.norm() + r.norm())).max(f64::MIN_POSITIVE)
}

/// The least-squares solution of `A x = r` by Householder QR of `A` with its
/// columns multiplied by `colscale` (undone on `x`); `None` if `R` is singular.
fn qr_least_squares(a: &DMatrix<C>, r: &DVector<C>, colscale: &[f64; 2]) -> Option<DVector<C>> {
    let mut scaled = a.clone();
    for (k, &s) in colscale.iter().enumerate() {
        if s != 1.0 {
            scaled.column_mut(k).scale_mut(s);
        }
    }
    let qr = scaled.qr();
    let qtb = qr.q().adjoint() * r;
    let mut x = qr.r().solve_upper_triangular(&qtb)?;
    for (xk, &s) in x.iter_mut().zip(colscale) {
        *xk *= s;
    }
    x.iter()
        .all(|v| v.re.is_finite() && v.im.is_finite())
        .then_some(x)
}

/// The two columns of the velocity system are equilibrated before its SVD
/// when their norms differ by more than this ratio ([`VelocitySystem::at`]):
/// generic states stay far below it (same bits as the unscaled solve), the
/// pinched level sets exceed it (1e5 at distance 1e-5 from an so(3) block).
const COLUMN_BALANCE_RATIO: f64 = 1e3;

pub(super) struct VelocitySystem {
    pub(super) amat: DMatrix<C>,
    /// The SVD of `amat` with its columns multiplied by `colscale`.
    pub(super) svd: nalgebra::SVD<C, nalgebra::Dyn, nalgebra::Dyn>,
    pub(super) colscale: [f64; 2],
    pub(super) lq: [f64; 6],
    pub(super) dval: C,
}

impl VelocitySystem {
    /// Errors: [`SingularKind::DegenerateGradients`] when the two singular
    /// values differ by more than 1e12 (`U` is not determined).
    pub(super) fn at(
        jet: &ThetaJet,
        idx: &[usize; 8],
        num: &[[C; 8]; 6],
        den: &[C; 8],
    ) -> Result<Self> {
        let theta = |m: usize| jet.values[idx[m]];
        let grad = |m: usize, k: usize| jet.gradient[idx[m] * 2 + k];
        let dval: C = (0..8).map(|m| den[m] * theta(m)).sum();
        let dgrad: [C; 2] = std::array::from_fn(|k| (0..8).map(|m| den[m] * grad(m, k)).sum());
        let lq: [C; 6] =
            std::array::from_fn(|q| (0..8).map(|m| num[q][m] * theta(m)).sum::<C>() / dval);
        let mut amat = DMatrix::<C>::zeros(6, 2);
        for (q, w) in num.iter().enumerate() {
            for k in 0..2 {
                let ng: C = (0..8).map(|m| w[m] * grad(m, k)).sum();
                amat[(q, k)] = ng - lq[q] * dgrad[k];
            }
        }
        // nalgebra's SVD panics on NaN entries: a non-finite system is refused first.
        if !amat.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
            return Err(Error::Singular {
                what: "state l0",
                kind: SingularKind::DegenerateGradients,
                reason: "the theta-quotient gradients at v0 are not finite: U is not determined"
                    .into(),
            });
        }
        // Columns of very different size (near a pinched level set the phase
        // along the pinched cycle moves only the components of size δ: the two
        // columns differ by 1e5 at δ = 1e-5) are equilibrated before the SVD:
        // nalgebra's SVD of the unscaled system lost the small column's
        // component of U to ~u·(column ratio)² (U_1 off by 6e-6 relative at
        // δ = 1e-5, 5e-9 of l at t = 100). Balanced systems (every generic state)
        // are solved unscaled, as before, with the same bits.
        let cn = [amat.column(0).norm(), amat.column(1).norm()];
        let colscale = if cn[0].max(cn[1]) > COLUMN_BALANCE_RATIO * cn[0].min(cn[1])
            && cn[0] > 0.0
            && cn[1] > 0.0
        {
            [1.0 / cn[0], 1.0 / cn[1]]
        } else {
            [1.0, 1.0]
        };
        let mut scaled = amat.clone();
        for (k, &s) in colscale.iter().enumerate() {
            if s != 1.0 {
                scaled.column_mut(k).scale_mut(s);
            }
        }
        let svd = scaled.svd(true, true);
        let sv = &svd.singular_values;
        if sv[1].is_nan() || sv[1] <= 1e-12 * sv[0] {
            return Err(Error::Singular {
                what: "state l0",
                kind: SingularKind::DegenerateGradients,
                reason: format!(
                    "the theta-quotient gradients at v0 are degenerate (singular values {:e}, {:e}): \
                     U is not determined",
                    sv[0], sv[1]
                ),
            });
        }
        Ok(VelocitySystem {
            amat,
            svd,
            colscale,
            lq: lq.map(|z| z.re),
            dval,
        })
    }

    /// The relative residual `|A u − r| / |r|` of a velocity `u` of the flow
    /// with coefficients `c4`.
    pub(super) fn residual_at(&self, u: &[C; 2], c4: &[f64; 6]) -> f64 {
        let ldot = so4::vector_field4(c4, &self.lq);
        let rhs = DVector::<C>::from_fn(6, |q, _| ldot[q] * self.dval);
        let x = DVector::<C>::from_column_slice(u);
        (&self.amat * &x - &rhs).norm() / rhs.norm().max(f64::MIN_POSITIVE)
    }

    /// The velocity of the flow with coefficients `c4` and the relative
    /// residual `|A U − r| / |r|` of its fit.
    pub(super) fn rate(&self, c4: &[f64; 6], what: &'static str) -> Result<([C; 2], f64)> {
        let ldot = so4::vector_field4(c4, &self.lq);
        let rhs = DVector::<C>::from_fn(6, |q, _| ldot[q] * self.dval);
        let mut x = self
            .svd
            .solve(&rhs, 0.0)
            .map_err(|e| Error::InvalidArgument {
                what,
                reason: e.to_string(),
            })?;
        for k in 0..2 {
            if self.colscale[k] != 1.0 {
                x[k] *= self.colscale[k];
            }
        }
        // The SVD's solution is checked against the normal equations
        // Aᴴ(r − A U) = 0 (what every least-squares solution satisfies): nalgebra's
        // SVD of these 6 × 2 systems leaves 1e-11 of |U| in the smaller
        // component on some states near the degenerate sets (a phase drift of
        // 1e-10 in l over [0, 100], which the self-check at a few points cannot
        // see), where Householder QR keeps roundoff. Where the SVD's solution
        // passes (every generic state) it is kept, with its bits.
        let ne = normal_residual(&self.amat, &x, &rhs);
        if !matches!(
            ne.partial_cmp(&NORMAL_RESIDUAL_RTOL),
            Some(Ordering::Less | Ordering::Equal)
        ) {
            if let Some(xq) = qr_least_squares(&self.amat, &rhs, &self.colscale) {
                x = xq;
            }
        }
        let u = [x[0], x[1]];
        if !u.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
            return Err(Error::NonFinite { what, index: 0 });
        }
        let res = (&self.amat * &x - &rhs).norm() / rhs.norm().max(f64::MIN_POSITIVE);
        Ok((u, res))
    }
}

/// Refuses a set-up whose quotients fit (1) for no velocity (least-squares
/// residual above [`QUOTIENT_RESIDUAL_RTOL`]): a guard against a wrong
/// constant or branch, which reproduces `l0` at `t = 0` and is O(1) wrong later.
pub(super) fn check_velocity_fit(res: f64) -> Result<()> {
    if res.is_nan() || res > QUOTIENT_RESIDUAL_RTOL {
        return Err(Error::Singular {
            what: INCONSISTENT,
            kind: SingularKind::InconsistentQuotients,
            reason: format!(
                "the theta quotients (9)-(10) at v0 satisfy Frahm's equations (1) for no \
                 velocity (least-squares residual {res:e} > {QUOTIENT_RESIDUAL_RTOL:e}): the \
                 set-up lost too many digits at this state (or took a wrong constant or \
                 branch), and its l(t) would be wrong"
            ),
        });
    }
    Ok(())
}

/// Relative agreement of two estimates of the `C_L²` that counts as a vote
/// in [`aux_constants_squared`]: estimates from well-conditioned divisors
/// agree to ~1e-14, a poorly conditioned one misses by 1e-10 … 1e-5.
const AUX_AGREE_RTOL: f64 = 1e-12;

/// The thetas of the labels at `v0` (the divisor of `l0`), for the set-up of
/// [`Solution::new`]: `θ(v0)`, the largest `|θ[χ](v0)|` and the jet.
pub(super) struct ThetaAtV0<'a> {
    jet: &'a ThetaJet,
    idx: &'a [usize; 8],
    th0: C,
    big: f64,
}

impl<'a> ThetaAtV0<'a> {
    /// Errors: `θ(v0) = 0` (relative to [`DIVISOR_AT_INFINITY_RTOL`]): the
    /// divisor of `l0` contains the point at infinity.
    pub(super) fn new(jet: &'a ThetaJet, idx: &'a [usize; 8]) -> Result<Self> {
        let big = jet.values.iter().fold(0.0f64, |m, v| m.max(v.norm()));
        let th0 = jet.values[idx[0]];
        if th0.norm() <= DIVISOR_AT_INFINITY_RTOL * big {
            return Err(singular(
                SingularKind::DivisorAtInfinity,
                format!(
                    "the divisor of l0 contains the point at infinity of the curve (8) \
                 (|theta(v0)| = {:e} of max |theta[chi](v0)|): the P_L (34) have poles there; \
                 the solution exists (take l0 at another time of the same trajectory)",
                    th0.norm() / big
                ),
            ));
        }
        Ok(ThetaAtV0 { jet, idx, th0, big })
    }

    /// `θ_L(v0)`, the theta of label `m`.
    pub(super) fn label(&self, m: usize) -> C {
        self.jet.values[self.idx[m + 1]]
    }

    /// The estimates `C_L = P_L θ(v0)/θ_L(v0)` at `l0`, with the `P_L` in the
    /// branch of the reduction: (37) inverted with the reduction's `g` ((30a),
    /// sign fixed by the corrected (42)), `P_0` from (31b).
    pub(super) fn estimates(&self, state0: &KotterState, sc: &[C; 3]) -> [C; 7] {
        let g = state0.points.g;
        let mut p_at0 = [C::new(0.0, 0.0); 7];
        p_at0[0] = state0.p0;
        for j in 0..3 {
            p_at0[1 + j] = state0.xi[j] / (sc[j] * g);
            p_at0[4 + j] = state0.eta[j] / (sc[j] * g);
        }
        std::array::from_fn(|m| p_at0[m] * self.th0 / self.label(m))
    }

    /// Whether the estimate at `v0` votes in [`aux_constants_squared`]: no
    /// `θ[χ_L](v0)` too small to divide by ([`AUX_V0_MIN`]).
    pub(super) fn votes(&self) -> bool {
        let qv0 = self
            .idx
            .iter()
            .map(|&i| self.jet.values[i].norm() / self.big)
            .fold(f64::INFINITY, f64::min);
        qv0 > AUX_V0_MIN
    }

    /// `G = g (1 − ε P_0)` at `v0` from the theta side: the `P_L(v0)` of the
    /// calibrated (34), `g` by least squares from the six equations (37)
    /// `(ξ_j, η_j) = √c_j g P_L(v0)`. The reduction's own `g`, `P_0` ((30a),
    /// (31b)) are sums that cancel when the `|d_j|` spread over many orders of
    /// magnitude (`P_0` loses up to 1e-6 there); the fit keeps `l(v0) = l0`.
    pub(super) fn big_g(&self, state0: &KotterState, sc: &[C; 3], cl: &[C; 7], eps: C) -> C {
        let p_th: [C; 7] = std::array::from_fn(|m| cl[m] * self.label(m) / self.th0);
        let (mut num_g, mut den_g) = (C::new(0.0, 0.0), 0.0);
        for j in 0..3 {
            for (w, r) in [
                (sc[j] * p_th[1 + j], state0.xi[j]),
                (sc[j] * p_th[4 + j], state0.eta[j]),
            ] {
                num_g += w.conj() * r;
                den_g += w.norm_sqr();
            }
        }
        let g_fit = if den_g > 0.0 {
            num_g / den_g
        } else {
            state0.points.g
        };
        g_fit * (C::new(1.0, 0.0) - eps * p_th[0])
    }
}

/// `C_L` from `C_L²` (by consensus) with the sign of the estimate at `l0`,
/// and the relative distance of the estimate from it (the calibration).
pub(super) fn signed_constants(c2: &[C; 7], est: &[C; 7]) -> ([C; 7], [f64; 7]) {
    let mut cl = [C::new(0.0, 0.0); 7];
    let mut calibration = [0.0; 7];
    for m in 0..7 {
        let root = sqrt_principal(c2[m]);
        let (plus, minus) = ((est[m] - root).norm(), (est[m] + root).norm());
        cl[m] = if plus <= minus { root } else { -root };
        calibration[m] = plus.min(minus) / root.norm();
    }
    (cl, calibration)
}

/// The theta-quotient form of (37), (42), (23): `l_q = N_q / D` with
/// `N_q = Σ_m num[q][m] θ_idx[m]`, `D = Σ_m den[m] θ_idx[m]`.
pub(super) fn quotient_weights(
    kotter: &KotterConstants,
    sc: &[C; 3],
    eps: C,
    big_g: C,
    cl: &[C; 7],
) -> ([[C; 8]; 6], [C; 8]) {
    let mut den = [C::new(0.0, 0.0); 8];
    den[0] = C::new(1.0, 0.0);
    den[1] = -eps * cl[0];
    let mut xi_w = [[C::new(0.0, 0.0); 8]; 3];
    let mut eta_w = [[C::new(0.0, 0.0); 8]; 3];
    for j in 0..3 {
        xi_w[j][2 + j] = sc[j] * big_g * cl[1 + j];
        eta_w[j][5 + j] = sc[j] * big_g * cl[4 + j];
    }
    let mut mw = [[C::new(0.0, 0.0); 8]; 3];
    let mut nw = [[C::new(0.0, 0.0); 8]; 3];
    for j in 0..3 {
        for s in 0..8 {
            mw[j][s] = kotter.alpha[j] * xi_w[j][s] + kotter.beta[j] * eta_w[j][s];
            nw[j][s] = kotter.gamma[j] * xi_w[j][s] + kotter.delta[j] * eta_w[j][s];
        }
    }
    let neg = |w: [C; 8]| w.map(|v| -v);
    // l = (m3, −m2, n1, m1, n2, n3)
    ([mw[2], neg(mw[1]), nw[0], mw[0], nw[1], nw[2]], den)
}

/// `C_L² = P_L² θ(v)²/θ_L(v)²` by consensus over a few fixed divisors and the
/// estimate `est0` at `v0` (`None` where a `θ_L(v0)` is too small to divide by).
///
/// A single divisor is not enough: where the branch points span many orders
/// of magnitude (`|d_4| / |d_3|` up to 1e10 when two `a_j` nearly coincide), a
/// divisor at the scale of the largest one loses up to 1e-9 of `C_L²` (a
/// common factor in all seven), while divisors at the geometric mean of the
/// scales keep roundoff. So four divisors are placed at the geometric-mean
/// scale, four more at the outer scale only if fewer than three estimates
/// agree, each gives an estimate, and the estimate that agrees
/// ([`AUX_AGREE_RTOL`]) with the most others wins; ties go to the divisor whose smallest needed `|θ[χ](v)|` is
/// largest relative to the largest.
pub(super) fn aux_constants_squared(
    curve: &HyperellipticCurve,
    kc: &KotterCurve,
    plan: &ThetaPlan,
    idx: &[usize; 8],
    rc: &[C; 2],
    est0: Option<[C; 7]>,
) -> Result<[C; 7]> {
    let (center, radius, geo, median) = aux_scales(kc);
    // Fixed generic offsets (off the real axis, both sheets).
    const W: [(f64, f64, f64, f64); 4] = [
        (0.37, 0.61, -0.53, -0.29),
        (-0.71, 0.43, 0.58, 0.47),
        (0.12, -0.77, -0.41, 0.66),
        (0.83, 0.21, -0.19, -0.88),
    ];
    let mut cands: Vec<(f64, [C; 7])> = Vec::with_capacity(9);
    if let Some(e) = est0 {
        cands.push((0.0, e));
    }
    // moduli without libm's hypot (within 1.5 ulp; the vote is a threshold
    // test, and these comparisons were the most frequent moduli of the set-up)
    let agree = |x: &[C; 7], y: &[C; 7]| {
        x.iter()
            .zip(y)
            .all(|(p, q)| (p - q).modulus() <= AUX_AGREE_RTOL * (*p).modulus().max((*q).modulus()))
    };
    // (votes, q, index) of the best-supported candidate.
    let best = |cands: &[(f64, [C; 7])]| {
        cands
            .iter()
            .enumerate()
            .map(|(i, (q, x))| (cands.iter().filter(|(_, y)| agree(x, y)).count(), *q, i))
            .max_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)))
    };
    // The geometric-mean scale first; the median scale, then the outer scale,
    // only when fewer than three estimates agree (a clustered curve: the scales
    // coincide). Near a pinched level set one branch point lies far out (|d_4|
    // 1e15 times the others and more): the geometric mean then sits in the thin
    // neck of the pinched cycle, where the thetas at the divisor are sums of two
    // comparable terms and the estimates scatter by 1e-11 … 1e-9, and the
    // outer scale at the far pair itself; at the median of the |d_j| the points
    // lie among the bulk of the branch points, where the estimates keep roundoff.
    let scales = [
        (C::new(0.0, 0.0), geo),
        (C::new(0.0, 0.0), median),
        (center, 1.3 * radius),
    ];
    for (origin, scale) in scales {
        if best(&cands).is_some_and(|(votes, _, _)| votes >= 3) {
            break;
        }
        for (k, &(a1, b1, a2, b2)) in W.iter().enumerate() {
            let x1 = origin + C::new(a1, b1) * scale;
            let x2 = origin + C::new(a2, b2) * scale;
            let y1 = curve.y(x1, 1);
            let y2 = curve.y(x2, if k % 2 == 0 { -1 } else { 1 });
            let aux = AuxDivisor {
                curve,
                kc,
                plan,
                idx,
                rc,
            };
            if let Some(cand) = aux.estimate((x1, y1), (x2, y2))? {
                cands.push(cand);
            }
        }
    }
    best(&cands)
        .map(|(_, _, i)| cands[i].1)
        .ok_or(Error::InvalidArgument {
            what: "curve",
            reason: "no auxiliary divisor gives finite Wurzelfunktionen".into(),
        })
}

/// The centre and radius of the branch points of `kc`, the geometric mean of
/// the non-zero `|d_j|` (a point at that modulus is, in ratio, far from every
/// branch point, whatever their spread) and the median of `|d_1| … |d_4|`.
fn aux_scales(kc: &KotterCurve) -> (C, f64, f64, f64) {
    let bp = kc.branch_points();
    let center: C = bp.iter().sum::<C>() / 5.0;
    let radius = bp
        .iter()
        .fold(0.0f64, |m, d| m.max((d - center).norm()))
        .max(f64::MIN_POSITIVE);
    let (log_sum, count) = bp
        .iter()
        .filter(|d| d.norm() > 0.0)
        .fold((0.0f64, 0u32), |(s, n), d| (s + d.norm().ln(), n + 1));
    let geo = if count > 0 {
        (log_sum / f64::from(count)).exp()
    } else {
        radius
    };
    // the median of |d_1| … |d_4| (the mean of the middle two)
    let mut mods: Vec<f64> = bp[1..].iter().map(|d| d.norm()).collect();
    mods.sort_by(f64::total_cmp);
    let median = if mods.len() == 4 {
        0.5 * (mods[1] + mods[2])
    } else {
        geo
    };
    (center, radius, geo, median)
}

/// The estimate of the `C_L²` at one auxiliary divisor.
struct AuxDivisor<'a> {
    curve: &'a HyperellipticCurve,
    kc: &'a KotterCurve,
    plan: &'a ThetaPlan,
    idx: &'a [usize; 8],
    rc: &'a [C; 2],
}

impl AuxDivisor<'_> {
    /// `(q, C_L² = P_L² θ(v)²/θ_L(v)²)` at the divisor `{P1, P2}`,
    /// `v = u(P1) + u(P2) + K`, `q` the smallest `|θ[χ](v)|` of the labels
    /// relative to the largest; `None` where a theta vanishes, the
    /// Wurzelfunktionen fail or an estimate is not finite.
    fn estimate(&self, (x1, y1): (C, C), (x2, y2): (C, C)) -> Result<Option<(f64, [C; 7])>> {
        let (idx, rc) = (self.idx, self.rc);
        let ua = self.curve.abel(x1, y1)?;
        let ub = self.curve.abel(x2, y2)?;
        let v = [ua[0] + ub[0] + rc[0], ua[1] + ub[1] + rc[1]];
        let (vals, _) = self.plan.theta_all(&v)?;
        // (moduli without hypot: q only ranks the divisors)
        let big = vals.iter().fold(0.0f64, |m, z| m.max((*z).modulus()));
        let q = idx
            .iter()
            .map(|&i| vals[i].modulus() / big)
            .fold(f64::INFINITY, f64::min);
        if q.is_nan() || q <= 0.0 {
            return Ok(None);
        }
        let Ok(w) = self.kc.wurzel(x1, y1, x2, y2, None) else {
            return Ok(None);
        };
        let p: [C; 7] = [
            w.p[0],
            w.pjk[2][3],
            w.pjk[3][1],
            w.pjk[1][2],
            w.pjk[1][4],
            w.pjk[2][4],
            w.pjk[3][4],
        ];
        let th = vals[idx[0]];
        let c2: [C; 7] = std::array::from_fn(|m| {
            let r = p[m] * th / vals[idx[m + 1]];
            r * r
        });
        Ok(c2
            .iter()
            .all(|z| z.re.is_finite() && z.im.is_finite())
            .then_some((q, c2)))
    }
}
