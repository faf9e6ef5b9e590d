//! `U` from the equations of motion on the algebraic side: the chain rule at
//! auxiliary divisors.
//!
//! The reduction gives the state as a function on the symmetric square of
//! the curve (8): for a divisor `D = (z1, y1) + (z2, y2)`,
//!
//! ```text
//!   P_j, P_jk  (27)–(28),   g = G/(1 − ε P_0)  (42, corrected),   G = √(h0/K),
//!   ξ_j = √c_j g P_kl,  η_j = √c_j g P_j4  (37),
//!   m_j = α_j ξ_j + β_j η_j,  n_j = γ_j ξ_j + δ_j η_j  (23), (24) corrected,
//!   l(D) = (m3, −m2, n1, m1, n2, n3).
//! ```
//!
//! Along the flow the divisor moves so that its Abel image moves on a
//! straight line: `Σ_i (1, z_i) ż_i / y_i = V` (unnormalised differentials
//! `(1, x) dx/y`), a constant of the level set, and `U = A⁻¹ V` with `A` the
//! a-periods. The chain rule `l̇ = Σ_i ∂l/∂z_i ż_i` with `l̇` from (1) at
//! `l(D)` gives `ż_i` (six equations, two unknowns, least squares) and so `V`
//! — at *any* divisor of the level set, since `V` is constant there. At the
//! divisor of the initial state this is ill-conditioned when a point is near
//! a branch point (`ż_i` and `y_i` both vanish there) or the two points are
//! close; at divisors of our choosing, generic and away from the branch
//! points, it keeps the digits of the level-set constants. Several such
//! divisors are used and at least [`MIN_SUPPORT`] must agree (a consensus,
//! like the constants `C_L` of the solution).
//!
//! The state `l(D)` at an auxiliary divisor is complex (the divisor is not on
//! the real torus); (1) and the integrals are polynomial identities and hold
//! on the complexified level set. Any sheet of the two points, and any sign
//! pattern of the `P_j`, puts `l(D)` on the level set (they differ by the
//! involution and by half periods, which do not change `V`); the level-set
//! residual only catches gross inconsistencies of the constants. The sign of
//! `G` is a genuine choice (`G → −G` is `l → −l`, the hyperelliptic
//! involution, and flips `V`): here `G = +√(h0/K)` (principal), the
//! reduction's choice of (42); [`crate::solution::Solution::algebraic_rates`]
//! checks it against the theta-side fit.
//!
//! (The direction of `V` also has a closed form, `V ∥ (1, M(μ_b))` with `M`
//! the Möbius map of the `s`-line sending the roots of `F` (19) to `±1/ε`,
//! `∓d_4 ε`; docs/theorem.md and its test in `tests/test_solution.py`.)

use nalgebra::{Matrix2, Vector2};
use num_complex::Complex64;

use crate::curve::{KotterCurve, CYCLIC};
use crate::error::{Error, Result, SingularKind};
use crate::kotter::KotterConstants;
use crate::numeric::complex::sqrt_principal;
use crate::so4::PAIRS4;

type C = Complex64;

const ZERO: C = C::new(0.0, 0.0);
const ONE: C = C::new(1.0, 0.0);

/// `l(D)` must satisfy `|H(l(D)) − h| ≤ AUX_LEVEL_RTOL |l(D)|²` (times `max|a|`
/// for `H2`, `max|a|²` for `H3`). Consistent constants leave rounding
/// (~1e-16); this catches gross errors only (a wrong constant or branch puts
/// `l(D)` off by O(1)), not the rounding of the constants.
pub const AUX_LEVEL_RTOL: f64 = 1e-8;

/// Relative residual `|J ż − l̇| / |l̇|` of the chain rule at a divisor above
/// which it is not used: with consistent constants `l̇` lies in the span of
/// `∂l/∂z_1, ∂l/∂z_2` to rounding (~1e-15).
pub const CHAIN_RULE_RTOL: f64 = 1e-10;

/// The two columns `∂l/∂z_i` must be this far from parallel (sine of their
/// angle, squared, i.e. `det G / (G11 G22)` of the Gram matrix): otherwise
/// `ż` is ill-determined even when the residual is small.
const MIN_GRAM_SIN2: f64 = 1e-6;

/// Two divisors' velocities agree (a vote in the consensus) within this
/// relative distance, for every flow. Measured spreads: ~1e-14 on generic,
/// physical, wide; 1.2e-12 on near_degenerate (`d_1 − d_2 = 3.8e-5`, whose
/// constants carry ~1e-12); 3.5e-12 with the pair 1e-7 apart.
pub const AGREE_RTOL: f64 = 1e-10;

/// At least this many auxiliary divisors must agree.
pub const MIN_SUPPORT: usize = 3;

/// `what` of the error when fewer than [`MIN_SUPPORT`] divisors agree (the
/// frequency map then takes the solution's route, `crate::tori::solve`).
pub const NO_CONSENSUS: &str = "velocity at auxiliary divisors";

/// The factor `1 − ε P_0` of `g` (42) below this size puts the divisor near a
/// pole of the state; such a divisor is not used.
const POLE_MARGIN: f64 = 1e-2;

/// An auxiliary point must be at least this fraction of the divisors' scale
/// away from every branch point and from the other point.
const MIN_DISTANCE: f64 = 0.05;

/// Fixed generic positions of the two points of an auxiliary divisor, in
/// units of the curve's scale (off the real and imaginary axes, apart).
const OFFSETS: [(f64, f64, f64, f64); 6] = [
    (0.43, 0.57, -0.61, 0.32),
    (-0.52, -0.38, 0.29, -0.71),
    (0.66, -0.24, -0.17, 0.83),
    (-0.31, 0.74, 0.77, 0.41),
    (0.21, -0.62, -0.73, -0.26),
    (0.81, 0.36, 0.12, -0.58),
];

/// The velocities of several flows on one level set, from the chain rule at
/// auxiliary divisors.
#[derive(Debug, Clone, PartialEq)]
pub struct AlgebraicRates {
    /// `U` of each flow (normalised: `v = u + U t`), in the order of the
    /// coefficient sets passed, for `G = √(h0/K)` principal.
    pub rates: Vec<[C; 2]>,
    /// The unnormalised velocities `V = A U`.
    pub v: Vec<[C; 2]>,
    /// Number of divisors that agreed with the result (≥ [`MIN_SUPPORT`]).
    pub support: usize,
    /// Largest relative distance of an agreeing divisor's `U` from the mean
    /// (over all flows): the agreement, not an error bar (the constants'
    /// rounding is common to all divisors).
    pub spread: f64,
    /// Largest relative level-set residual `|H(l(D)) − h|` of the agreeing divisors.
    pub level_residual: f64,
    /// Largest relative chain-rule residual `|J ż − l̇| / |l̇|` of the agreeing divisors.
    pub chain_residual: f64,
}

/// One auxiliary divisor's result: `U` and `V` of each flow, and the
/// level-set residual of its state.
#[derive(Debug)]
struct Candidate {
    u: Vec<[C; 2]>,
    v: Vec<[C; 2]>,
    level: f64,
    chain: f64,
}

/// `(1)` for a complex state: `l̇ = [l, ω]`, `ω_ij = c_ij l_ij`, written as
/// the matrix commutator (not the expanded form of [`crate::so4::vector_field4`]).
pub fn vector_field_complex(c4: &[f64; 6], l: &[C; 6]) -> [C; 6] {
    let mut lm = [[ZERO; 4]; 4];
    let mut om = [[ZERO; 4]; 4];
    for (q, &(i, j)) in PAIRS4.iter().enumerate() {
        lm[i][j] = l[q];
        lm[j][i] = -l[q];
        om[i][j] = l[q] * c4[q];
        om[j][i] = -l[q] * c4[q];
    }
    std::array::from_fn(|q| {
        let (i, j) = PAIRS4[q];
        (0..4).fold(ZERO, |acc, k| {
            acc + lm[i][k] * om[k][j] - om[i][k] * lm[k][j]
        })
    })
}

/// `(H0, H1, H2, H3)` of (6)–(7) (corrected: complementary pairs) for a
/// complex state.
pub fn integrals_complex(a: &[f64; 4], l: &[C; 6]) -> [C; 4] {
    let [l12, l13, l14, l23, l24, l34] = *l;
    let h0 = l12 * l34 + l23 * l14 - l13 * l24;
    let (mut h1, mut h2, mut h3) = (ZERO, ZERO, ZERO);
    for (p, _) in PAIRS4.iter().enumerate() {
        let (u, v) = PAIRS4[5 - p];
        let x2 = l[p] * l[p];
        h1 += x2;
        h2 += x2 * (a[u] + a[v]);
        h3 += x2 * (a[u] * a[v]);
    }
    [h0, h1, h2, h3]
}

/// The state at a divisor and its derivatives along the curve.
struct StateJet {
    l: [C; 6],
    /// `dl[i][q] = ∂l_q/∂z_i` (`y_i` continued along its sheet).
    dl: [[C; 6]; 2],
}

/// What the auxiliary states need of the level set: the reduction's
/// constants, the branch points `d_m` of (8), `√c_j` and the constant
/// `G = g (1 − ε P_0) = √(h0/K)` of the corrected (42).
struct Level<'a> {
    k: &'a KotterConstants,
    d: [C; 5],
    sc: [C; 3],
    big_g: C,
}

impl<'a> Level<'a> {
    fn new(k: &'a KotterConstants, curve: &KotterCurve) -> Self {
        Level {
            k,
            d: curve.branch_points(),
            sc: curve.c().map(sqrt_principal),
            // G = √(h0/K) (42); at negligible h0 (K = 0, ε = 0) l is linear in G
            // and G is fixed per divisor by H1(l) = h1 instead ([`state_jet`]).
            big_g: if k.k == ZERO {
                ZERO
            } else {
                sqrt_principal(C::new(k.h[0], 0.0) / k.k)
            },
        }
    }
}

/// `l(D)` and `∂l/∂z_i` at the divisor with roots `r[i][m] = √(z_i − d_m)`
/// (signs carrying the sheet: `Π_m r[i][m] = y_i`) and branch `eps` of the
/// `P_j`. With `A = r2_j r2_k Π_{m≠j,k} r1_m`, `B = r1_j r1_k Π_{m≠j,k} r2_m`,
/// (28) reads `P_jk = (A − B)/(z1 − z2)`, and `∂r_im/∂z_i = r_im/(2(z_i − d_m))`.
fn state_jet(lv: &Level, z: [C; 2], r: &[[C; 5]; 2], eps: &[f64; 5]) -> Option<StateJet> {
    let Level { k, d, sc, big_g } = *lv;
    let dz = z[0] - z[1];
    // h[i][m] = 1/(2(z_i − d_m)): the logarithmic derivative of r[i][m].
    let h: [[C; 5]; 2] = std::array::from_fn(|i| std::array::from_fn(|m| 0.5 / (z[i] - d[m])));
    let p: [C; 5] = std::array::from_fn(|m| eps[m] * r[0][m] * r[1][m]);
    let dp: [[C; 5]; 2] = std::array::from_fn(|i| std::array::from_fn(|m| p[m] * h[i][m]));
    // P_jk and its derivatives for the six pairs that enter (37).
    let pjk = |j: usize, kk: usize| -> (C, [C; 2]) {
        let (mut a, mut b) = (r[1][j] * r[1][kk], r[0][j] * r[0][kk]);
        let (mut sa1, mut sb2) = (ZERO, ZERO);
        for m in (0..5).filter(|&m| m != j && m != kk) {
            a *= r[0][m];
            b *= r[1][m];
            sa1 += h[0][m];
            sb2 += h[1][m];
        }
        let s = eps[j] * eps[kk];
        let v = s * (a - b) / dz;
        let da1 = a * sa1;
        let db1 = b * (h[0][j] + h[0][kk]);
        let da2 = a * (h[1][j] + h[1][kk]);
        let db2 = b * sb2;
        let d1 = s * (da1 - db1) / dz - v / dz;
        let d2 = s * (da2 - db2) / dz + v / dz;
        (v, [d1, d2])
    };
    let den = ONE - k.eps * p[0];
    if den.norm_sqr() < POLE_MARGIN * POLE_MARGIN {
        return None;
    }
    // G = 0 marks negligible h0: l is then computed at G = 1 and scaled below.
    let h1_scale = big_g == ZERO;
    let g = if h1_scale { ONE } else { big_g } / den;
    // ∂g/∂z_i = g ε ∂P_0/∂z_i / (1 − ε P_0)
    let dg: [C; 2] = std::array::from_fn(|i| g * k.eps * dp[i][0] / den);
    let mut m = [ZERO; 3];
    let mut n = [ZERO; 3];
    let mut dm = [[ZERO; 3]; 2];
    let mut dn = [[ZERO; 3]; 2];
    for (jj, &(j, kk, ll)) in CYCLIC.iter().enumerate() {
        let (pkl, dpkl) = pjk(kk, ll);
        let (pj4, dpj4) = pjk(j, 4);
        let xi = sc[jj] * g * pkl;
        let eta = sc[jj] * g * pj4;
        m[jj] = k.alpha[jj] * xi + k.beta[jj] * eta;
        n[jj] = k.gamma[jj] * xi + k.delta[jj] * eta;
        for i in 0..2 {
            let dxi = sc[jj] * (dg[i] * pkl + g * dpkl[i]);
            let deta = sc[jj] * (dg[i] * pj4 + g * dpj4[i]);
            dm[i][jj] = k.alpha[jj] * dxi + k.beta[jj] * deta;
            dn[i][jj] = k.gamma[jj] * dxi + k.delta[jj] * deta;
        }
    }
    let lay = |m: &[C; 3], n: &[C; 3]| [m[2], -m[1], n[0], m[0], n[1], n[2]];
    let mut l = lay(&m, &n);
    let mut dl = [lay(&dm[0], &dn[0]), lay(&dm[1], &dn[1])];
    if h1_scale {
        // ε = 0: l and ∂l/∂z are linear in G; G² = h1 / Σ_q l_q² at G = 1, the
        // principal root as for √(h0/K) (the sign is the involution's).
        let s2: C = l.iter().map(|v| v * v).sum();
        let gg = sqrt_principal(C::new(k.h[1], 0.0) / s2);
        l = l.map(|v| v * gg);
        dl = dl.map(|row| row.map(|v| v * gg));
    }
    let finite = |v: &C| v.re.is_finite() && v.im.is_finite();
    (l.iter().all(finite) && dl.iter().flatten().all(finite)).then_some(StateJet { l, dl })
}

/// Relative distance of the integrals of `l` from `h`.
fn level_residual(a: &[f64; 4], h: &[f64; 4], l: &[C; 6]) -> f64 {
    let hl = integrals_complex(a, l);
    let size = l.iter().map(|v| v.norm_sqr()).sum::<f64>();
    let am = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1.0);
    let w = [1.0, 1.0, 2.0 * am, am * am];
    (0..4)
        .map(|q| (hl[q] - h[q]).norm_sqr().sqrt() / (size * w[q]))
        .fold(0.0f64, f64::max)
}

/// Least squares `J x = b` for a 6 × 2 complex `J`: normal equations with
/// one step of iterative refinement. Refused (`None`) when the columns are
/// nearly parallel ([`MIN_GRAM_SIN2`]: the normal equations square the
/// condition number, and `x` would be ill-determined anyway). Returns `x`
/// and the relative residual `|J x − b| / |b|`.
fn lstsq_6x2(j: &[[C; 6]; 2], b: &[C; 6]) -> Option<([C; 2], f64)> {
    let dot = |u: &[C; 6], v: &[C; 6]| (0..6).fold(ZERO, |s, q| s + u[q].conj() * v[q]);
    let (g11, g12, g22) = (dot(&j[0], &j[0]), dot(&j[0], &j[1]), dot(&j[1], &j[1]));
    let det = g11 * g22 - g12 * g12.conj();
    // (NaN refuses too)
    if det.re.is_nan() || det.re <= MIN_GRAM_SIN2 * g11.re * g22.re {
        return None;
    }
    let inv = Matrix2::new(g11, g12, g12.conj(), g22).try_inverse()?;
    let solve = |rhs: &[C; 6]| inv * Vector2::new(dot(&j[0], rhs), dot(&j[1], rhs));
    let residual =
        |x: &[C; 2]| -> [C; 6] { std::array::from_fn(|q| b[q] - j[0][q] * x[0] - j[1][q] * x[1]) };
    let x0 = solve(b);
    let x0 = [x0[0], x0[1]];
    let dx = solve(&residual(&x0));
    let x = [x0[0] + dx[0], x0[1] + dx[1]];
    let rn = residual(&x)
        .iter()
        .map(|v| v.norm_sqr())
        .sum::<f64>()
        .sqrt();
    let bn = b.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
    let rel = if bn > 0.0 { rn / bn } else { 0.0 };
    (x.iter().all(|v| v.re.is_finite() && v.im.is_finite()) && rel.is_finite()).then_some((x, rel))
}

/// Two candidates agree (a vote) when their velocities do, flow by flow,
/// within [`AGREE_RTOL`] of the larger.
fn agree(x: &Candidate, y: &Candidate) -> bool {
    x.u.iter().zip(&y.u).all(|(p, q)| {
        // squared moduli: no libm hypot in the per-state path
        let s2 = p[0]
            .norm_sqr()
            .max(p[1].norm_sqr())
            .max(q[0].norm_sqr().max(q[1].norm_sqr()));
        (p[0] - q[0]).norm_sqr().max((p[1] - q[1]).norm_sqr()) <= AGREE_RTOL * AGREE_RTOL * s2
    })
}

/// `(votes, index)` of the candidate with the most votes (itself included),
/// ties to the smaller of its residuals; `None` without candidates.
fn best_supported(cands: &[Candidate]) -> Option<(usize, usize)> {
    cands
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let votes = cands.iter().filter(|o| agree(c, o)).count();
            (votes, -c.chain.max(c.level), i)
        })
        .max_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)))
        .map(|(votes, _, i)| (votes, i))
}

/// The candidates that agree with the best-supported one, if there are at
/// least [`MIN_SUPPORT`]; otherwise the error naming [`NO_CONSENSUS`] and
/// whether no candidate or too few agreeing ones were found.
fn supporters(cands: &[Candidate]) -> Result<Vec<&Candidate>> {
    let (votes, i) = best_supported(cands).ok_or(Error::Singular {
        what: NO_CONSENSUS,
        kind: SingularKind::NoVelocityConsensus,
        reason: "no auxiliary divisor gives a consistent state on the level set: the \
                 reduction's constants are inconsistent"
            .into(),
    })?;
    if votes < MIN_SUPPORT {
        return Err(Error::Singular {
            what: NO_CONSENSUS,
            kind: SingularKind::NoVelocityConsensus,
            reason: format!(
                "only {votes} of {} auxiliary divisors agree on the velocity (at least \
                 {MIN_SUPPORT} must, to {AGREE_RTOL:e})",
                cands.len()
            ),
        });
    }
    Ok(cands.iter().filter(|o| agree(&cands[i], o)).collect())
}

/// The velocities `U` of the flows with coefficients `c4s` (the six `c_ij`,
/// `i < j`, of (1)) on the level set of the constants `k`, by the chain rule
/// at auxiliary divisors, for the sign `G = +√(h0/K)` (principal).
///
/// `curve` is the curve (8) of `k`; `a_periods` the a-period matrix
/// `A_ij = ∮_{a_j} x^{i} dx/y` (row-major, 2 × 2) of the homology basis in
/// which `U` is wanted.
///
/// A divisor is used when its points are away from the branch points and
/// from each other ([`MIN_DISTANCE`]), away from a pole of `l` (`1 − ε P_0`
/// not small), `l(D)` lies on the level set ([`AUX_LEVEL_RTOL`]) and the
/// chain rule is consistent ([`CHAIN_RULE_RTOL`]) and well conditioned. The
/// result is the mean over the divisors that agree, for every flow, within
/// [`AGREE_RTOL`] of the best-supported one.
///
/// Errors: `c4s` empty or not finite, a singular `a_periods`
/// ([`Error::InvalidArgument`]); fewer than [`MIN_SUPPORT`] divisors agree
/// ([`Error::Singular`] of kind [`SingularKind::NoVelocityConsensus`], `what` = [`NO_CONSENSUS`]).
pub fn algebraic_rates(
    k: &KotterConstants,
    curve: &KotterCurve,
    a_periods: &[C; 4],
    c4s: &[[f64; 6]],
) -> Result<AlgebraicRates> {
    if c4s.is_empty() {
        return Err(Error::InvalidArgument {
            what: "c4s",
            reason: "no flow given".into(),
        });
    }
    for c4 in c4s {
        crate::error::check_finite("c4", c4)?;
    }
    let lv = Level::new(k, curve);
    let d = lv.d;
    let amat = Matrix2::new(a_periods[0], a_periods[1], a_periods[2], a_periods[3]);
    let ainv = amat.try_inverse().ok_or(Error::InvalidArgument {
        what: "a-periods",
        reason: "the a-period matrix is singular".into(),
    })?;
    // Scales: the geometric mean of the non-zero |d_j| (in ratio far from
    // every branch point however widely they spread), then the outer radius.
    let (log_sum, count) = d
        .iter()
        .filter(|x| x.norm() > 0.0)
        .fold((0.0f64, 0u32), |(s, n), x| (s + x.norm().ln(), n + 1));
    let center: C = d.iter().sum::<C>() / 5.0;
    let radius = d.iter().fold(0.0f64, |m, x| m.max((x - center).norm()));
    let geo = if count > 0 {
        (log_sum / f64::from(count)).exp()
    } else {
        radius
    };
    let mut cands: Vec<Candidate> = Vec::new();
    // Divisors one at a time until MIN_SUPPORT agree (on a well-conditioned
    // curve the first ones do), the geometric-mean scale first.
    'scales: for (origin, scale) in [(ZERO, geo), (center, 1.3 * radius)] {
        for &(a1, b1, a2, b2) in &OFFSETS {
            if best_supported(&cands).is_some_and(|(votes, _)| votes >= MIN_SUPPORT) {
                break 'scales;
            }
            let z = [
                origin + C::new(a1, b1) * scale,
                origin + C::new(a2, b2) * scale,
            ];
            let min2 = (MIN_DISTANCE * scale).powi(2);
            let clear = (z[0] - z[1]).norm_sqr() >= min2
                && z.iter()
                    .all(|zi| d.iter().all(|dm| (zi - dm).norm_sqr() >= min2));
            if !clear {
                continue;
            }
            if let Some(c) = candidate(&lv, z, c4s, &ainv) {
                cands.push(c);
            }
        }
    }
    // The mean over the divisors that agree with the best-supported one.
    let sup = supporters(&cands)?;
    let nf = sup.len() as f64;
    let mean = |pick: &dyn Fn(&Candidate) -> [C; 2]| -> [C; 2] {
        let s = sup.iter().fold([ZERO; 2], |acc, c| {
            let x = pick(c);
            [acc[0] + x[0], acc[1] + x[1]]
        });
        [s[0] / nf, s[1] / nf]
    };
    let rates: Vec<[C; 2]> = (0..c4s.len()).map(|f| mean(&|c| c.u[f])).collect();
    let v: Vec<[C; 2]> = (0..c4s.len()).map(|f| mean(&|c| c.v[f])).collect();
    let mut spread = 0.0f64;
    for (f, r) in rates.iter().enumerate() {
        let scale_u = r[0].norm().max(r[1].norm());
        if scale_u > 0.0 {
            for c in &sup {
                let dev = (c.u[f][0] - r[0]).norm().max((c.u[f][1] - r[1]).norm());
                spread = spread.max(dev / scale_u);
            }
        }
    }
    Ok(AlgebraicRates {
        rates,
        v,
        support: sup.len(),
        spread,
        level_residual: sup.iter().map(|c| c.level).fold(0.0f64, f64::max),
        chain_residual: sup.iter().map(|c| c.chain).fold(0.0f64, f64::max),
    })
}

/// The velocities of the flows `c4s` from one auxiliary divisor at `z` (first
/// point on the canonical sheet, the second on either: both give the same
/// velocity; the other sheet only when the first puts the divisor at a pole),
/// or `None` when it does not qualify (see [`algebraic_rates`]).
fn candidate(lv: &Level, z: [C; 2], c4s: &[[f64; 6]], ainv: &Matrix2<C>) -> Option<Candidate> {
    let eps_default = [1.0; 5];
    let r0: [[C; 5]; 2] =
        std::array::from_fn(|i| std::array::from_fn(|m| sqrt_principal(z[i] - lv.d[m])));
    let (jet, r) = [1.0, -1.0].into_iter().find_map(|s2| {
        let mut r = r0;
        r[1][0] *= s2;
        state_jet(lv, z, &r, &eps_default).map(|j| (j, r))
    })?;
    let level = level_residual(&lv.k.a, &lv.k.h, &jet.l);
    if level.is_nan() || level > AUX_LEVEL_RTOL {
        return None;
    }
    let y: [C; 2] = std::array::from_fn(|i| r[i].iter().product::<C>());
    let mut u = Vec::with_capacity(c4s.len());
    let mut v = Vec::with_capacity(c4s.len());
    let mut chain = 0.0f64;
    for c4 in c4s {
        let ldot = vector_field_complex(c4, &jet.l);
        let (zdot, res) = lstsq_6x2(&jet.dl, &ldot)?;
        if res.is_nan() || res > CHAIN_RULE_RTOL {
            return None;
        }
        chain = chain.max(res);
        let w = [zdot[0] / y[0], zdot[1] / y[1]];
        let vf = [w[0] + w[1], z[0] * w[0] + z[1] * w[1]];
        let uf = ainv * Vector2::new(vf[0], vf[1]);
        if !uf.iter().all(|x| x.re.is_finite() && x.im.is_finite()) {
            return None;
        }
        v.push(vf);
        u.push([uf[0], uf[1]]);
    }
    Some(Candidate { u, v, level, chain })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kotter::kotter_constants;
    use crate::so4::{integrals4, vector_field4};

    use crate::solution::tests::TOPS;

    const GENERIC: ([f64; 4], [f64; 4], [f64; 6]) = TOPS[0];

    #[test]
    fn complex_field_and_integrals_match_the_real_ones() {
        let c4 = [0.7, -1.3, 2.1, 0.4, -0.2, 1.9];
        let (a, _, l) = GENERIC;
        let lc = l.map(|x| C::new(x, 0.0));
        let f = vector_field_complex(&c4, &lc);
        let fr = vector_field4(&c4, &l);
        let h = integrals_complex(&a, &lc);
        let hr = integrals4(&a, &l);
        for q in 0..6 {
            assert!((f[q] - fr[q]).norm() <= 1e-14, "{q}: {} {}", f[q], fr[q]);
        }
        for q in 0..4 {
            assert!((h[q] - hr[q]).norm() <= 1e-14 * hr[q].abs().max(1.0));
        }
    }

    /// `∂l/∂z_i` of [`state_jet`] against the Cauchy integral
    /// `f'(z) = (1/N r) Σ_k f(z + r ω^k) ω^{−k}` (32 nodes on a circle of
    /// radius 0.2 of the distance to the nearest singularity: the trapezoid
    /// rule on the circle converges like 0.2^32, rounding stays at 1e-15/0.2).
    #[test]
    fn state_derivatives_match_a_cauchy_integral() {
        let (a, _, l0) = GENERIC;
        let k = kotter_constants(&a, &l0).unwrap();
        let curve = KotterCurve::new(k.d[0], k.d[1], k.d[2]).unwrap();
        let lv = Level::new(&k, &curve);
        let d = lv.d;
        let z = [C::new(1.1, 0.9), C::new(-2.3, 1.7)];
        // roots continued from the centre of the circle (no cut crossed)
        let roots = |zz: [C; 2], r0: &[[C; 5]; 2]| -> [[C; 5]; 2] {
            std::array::from_fn(|i| {
                std::array::from_fn(|m| {
                    let v = sqrt_principal(zz[i] - d[m]);
                    if (v - r0[i][m]).norm() <= (v + r0[i][m]).norm() {
                        v
                    } else {
                        -v
                    }
                })
            })
        };
        let r0: [[C; 5]; 2] =
            std::array::from_fn(|i| std::array::from_fn(|m| sqrt_principal(z[i] - d[m])));
        let e = [1.0; 5];
        let jet = state_jet(&lv, z, &r0, &e).unwrap();
        let near = (0..2)
            .map(|i| {
                d.iter()
                    .fold((z[0] - z[1]).norm(), |m, x| m.min((z[i] - x).norm()))
            })
            .fold(f64::INFINITY, f64::min);
        let rad = 0.2 * near;
        let n = 32;
        for i in 0..2 {
            let mut acc = [ZERO; 6];
            for kk in 0..n {
                let w = C::from_polar(1.0, 2.0 * std::f64::consts::PI * kk as f64 / n as f64);
                let mut zz = z;
                zz[i] += w * rad;
                let r = roots(zz, &r0);
                let lj = state_jet(&lv, zz, &r, &e).unwrap();
                for (a, lq) in acc.iter_mut().zip(lj.l) {
                    *a += lq / w;
                }
            }
            let scale = jet.dl[i].iter().fold(0.0f64, |m, v| m.max(v.norm()));
            for (q, (a, exact)) in acc.iter().zip(jet.dl[i]).enumerate() {
                let fd = a / (n as f64 * rad);
                assert!(
                    (fd - exact).norm() <= 1e-12 * scale,
                    "z{i}, l{q}: {exact} vs {fd}"
                );
            }
        }
    }

    fn shared(n: usize) -> ([f64; 4], [f64; 4], [f64; 6]) {
        TOPS[n]
    }

    /// The chain rule at auxiliary divisors against the solution's theta-side
    /// fit at `v0` (an independent route through theta functions and the Abel
    /// map of `l0`): 1.5e-15 on generic, ~1e-14 on physical and wide, 3.6e-12
    /// on near_degenerate (its constants, `d_1 − d_2 = 3.8e-5`).
    #[test]
    fn chain_rule_velocity_matches_the_theta_fit_on_the_shared_tops() {
        let tol = [1e-13, 1e-13, 1e-13, 1e-10];
        for (n, tol) in tol.into_iter().enumerate() {
            let (a, b, l0) = shared(n);
            let sol = crate::solution::Solution::new(&a, &b, &l0).unwrap();
            let alg = sol.algebraic_rates(&[*sol.c4()]).unwrap();
            let (u, r) = (alg.rates[0], sol.rate());
            let scale = r[0].norm().max(r[1].norm());
            let dev = (u[0] - r[0]).norm().max((u[1] - r[1]).norm()) / scale;
            assert!(dev <= tol, "top {n}: {dev:e}");
            assert!(alg.support >= MIN_SUPPORT);
            assert!(
                alg.level_residual <= 1e-12,
                "top {n}: {:e}",
                alg.level_residual
            );
            assert!(
                alg.chain_residual <= 1e-12,
                "top {n}: {:e}",
                alg.chain_residual
            );
        }
    }

    /// The reduction's constants, the curve (8) and its a-periods for `a, l0`.
    fn level_set_data(a: &[f64; 4], l0: &[f64; 6]) -> (KotterConstants, KotterCurve, [C; 4]) {
        let k = kotter_constants(a, l0).unwrap();
        let curve = KotterCurve::new(k.d[0], k.d[1], k.d[2]).unwrap();
        let hc = crate::riemann::HyperellipticCurve::new(&curve.branch_points()).unwrap();
        let ap = super::super::a_periods_of(&hc);
        (k, curve, ap)
    }

    /// Constants that do not belong to one level set (`α_1` off by 1e-6)
    /// give no auxiliary state on it: the consensus refuses, naming itself,
    /// where the true constants give a velocity.
    #[test]
    fn inconsistent_constants_give_no_consensus() {
        let (a, b, l0) = GENERIC;
        let (k, curve, ap) = level_set_data(&a, &l0);
        let c = crate::so4::manakov_c(&a, &b).unwrap();
        let c4 = [c[1], c[2], c[3], c[6], c[7], c[11]];
        let good = algebraic_rates(&k, &curve, &ap, &[c4]).unwrap();
        assert!(good.support >= MIN_SUPPORT);
        let mut bad = k.clone();
        bad.alpha[0] *= 1.0 + 1e-6;
        match algebraic_rates(&bad, &curve, &ap, &[c4]) {
            Err(Error::Singular {
                what,
                kind: SingularKind::NoVelocityConsensus,
                reason,
            }) => {
                assert_eq!(what, NO_CONSENSUS, "{reason}");
                assert!(reason.contains("no auxiliary divisor"), "{reason}");
            }
            other => panic!("expected no consensus, got {other:?}"),
        }
    }

    /// The vote on its own, on made-up candidates: no candidate, and too few
    /// agreeing ones (two of four, where three must), are refused with their
    /// reasons; with three agreeing (within [`AGREE_RTOL`]) and one off, the
    /// supporters are the three, the off one and the near miss excluded.
    #[test]
    fn the_vote_needs_min_support_and_drops_the_dissenters() {
        let cand = |u0: f64| Candidate {
            u: vec![[C::new(u0, 0.0), C::new(2.0, -1.0)]],
            v: vec![[ZERO; 2]],
            level: 1e-15,
            chain: 1e-15,
        };
        let reason = |r: Result<Vec<&Candidate>>| match r {
            Err(Error::Singular {
                what,
                kind: SingularKind::NoVelocityConsensus,
                reason,
            }) => {
                assert_eq!(what, NO_CONSENSUS);
                reason
            }
            other => panic!("expected no consensus, got {other:?}"),
        };
        assert!(reason(supporters(&[])).contains("no auxiliary divisor"));
        let two = [cand(1.0), cand(1.0 + 1e-13), cand(1.5), cand(0.5)];
        assert!(reason(supporters(&two)).contains("only 2 of 4"));
        // `agree` measures against the larger modulus of the pair, |2 − i| = √5
        // here: a miss by 3 AGREE_RTOL of that is a clear miss.
        let near_miss = 1.0 + 3.0 * AGREE_RTOL * 5f64.sqrt();
        let three = [
            cand(1.0),
            cand(0.7),
            cand(1.0 - 1e-13),
            cand(near_miss),
            cand(1.0 + 1e-13),
        ];
        let sup = supporters(&three).unwrap();
        assert_eq!(sup.len(), 3);
        assert!(sup.iter().all(|c| (c.u[0][0].re - 1.0).abs() <= 1e-12));
    }

    /// Any sheet of the second point gives a state on the level set and the
    /// same velocity (they differ by the involution and half periods).
    #[test]
    fn both_sheets_of_the_second_point_give_the_same_velocity() {
        let (a, b, l0) = GENERIC;
        let k = kotter_constants(&a, &l0).unwrap();
        let curve = KotterCurve::new(k.d[0], k.d[1], k.d[2]).unwrap();
        let d = curve.branch_points();
        let hc = crate::riemann::HyperellipticCurve::new(&d).unwrap();
        let ap = super::super::a_periods_of(&hc);
        let ainv = Matrix2::new(ap[0], ap[1], ap[2], ap[3])
            .try_inverse()
            .unwrap();
        let c = crate::so4::manakov_c(&a, &b).unwrap();
        let c4 = [c[1], c[2], c[3], c[6], c[7], c[11]];
        let lv = Level::new(&k, &curve);
        let z = [C::new(1.1, 0.9), C::new(-2.3, 1.7)];
        let mut us = Vec::new();
        for s2 in [1.0, -1.0] {
            let mut r: [[C; 5]; 2] =
                std::array::from_fn(|i| std::array::from_fn(|m| sqrt_principal(z[i] - d[m])));
            r[1][0] *= s2;
            let jet = state_jet(&lv, z, &r, &[1.0; 5]).unwrap();
            assert!(level_residual(&k.a, &k.h, &jet.l) <= 1e-14);
            let (zd, res) = lstsq_6x2(&jet.dl, &vector_field_complex(&c4, &jet.l)).unwrap();
            assert!(res <= 1e-13);
            let y: [C; 2] = std::array::from_fn(|i| r[i].iter().product::<C>());
            let w = [zd[0] / y[0], zd[1] / y[1]];
            us.push(ainv * Vector2::new(w[0] + w[1], z[0] * w[0] + z[1] * w[1]));
        }
        let scale = us[0][0].norm().max(us[0][1].norm());
        assert!((us[0] - us[1]).norm() <= 1e-13 * scale);
    }

    #[test]
    fn bad_flows_are_refused_and_a_zero_flow_is_at_rest() {
        let (a, _, l0) = GENERIC;
        let (k, curve, ap) = level_set_data(&a, &l0);
        assert!(matches!(
            algebraic_rates(&k, &curve, &ap, &[]),
            Err(Error::InvalidArgument { what: "c4s", .. })
        ));
        let nan = [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(matches!(
            algebraic_rates(&k, &curve, &ap, &[nan]),
            Err(Error::NonFinite { .. })
        ));
        let r = algebraic_rates(&k, &curve, &ap, &[[0.0; 6]]).unwrap();
        assert!(r.rates[0].iter().all(|v| *v == ZERO) && r.spread == 0.0);
    }
}
