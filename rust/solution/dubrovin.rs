//! `U` in closed form: the velocity of the Abel image at the half periods
//! `d_0 + d_p` (docs/theorem.md, "U in closed form").
//!
//! Along a flow the divisor `z_1 + z_2` of the state moves so that its Abel
//! image moves on a straight line (Dubrovin's equations):
//!
//! ```text
//!   ż_1/y_1 + ż_2/y_2 = V_0,   z_1 ż_1/y_1 + z_2 ż_2/y_2 = V_1,   U = A⁻¹ V,
//! ```
//!
//! with `V` a constant of the level set (`A` the a-periods of `(1, x) dx/y`).
//! `V` is read off at the complex points of the level set whose divisor is the
//! half period `D_p = d_0 + d_p` (`p = 1 … 4`; `d_0 = 0`). There the
//! Wurzelfunktionen (27)–(28) are explicit: with `r_m(0) = √(−d_m)`,
//! `r_m(d_p) = √(d_p − d_m)`, `P_0 = 0` (so `g = G`, the constant of the
//! corrected (42)), `P_op = r_o(0) r_p(0) Π_{m∉{o,p}} r_m(d_p) / d_p` for the
//! labels that contain `p`, and `P_jk = 0` for those that do not
//! (`y_1 = y_2 = 0`); `G` is the scale that puts the state on the level set
//! (`Σ l_ij² = h1`).
//! In the local parameters `w_1 = r_0(z_1)`, `w_2 = r_p(z_2)` a vanishing
//! `P_jk` is linear, and Dubrovin's equations at `D_p` give
//!
//! ```text
//!   Ṗ_jk = −½ r_j(0) r_k(0) r_j(d_p) r_k(d_p) (d_q V_0 − V_1),
//! ```
//!
//! `q` the fifth index (`{0, p, j, k, q} = {0 … 4}`). The left side is the
//! component `√c g Ṗ_jk` of `ξ̇` or `η̇` (37) at the state `l(D_p)` of (23),
//! i.e. Frahm's equations (1) there mapped by (20), (22):
//! `ξ̇_j = (u_j^(1) + i u_j^(2)) ṁ_j + (v_j^(1) + i v_j^(2)) ṅ_j`, and `η̇_j` with
//! `−i`. Three labels vanish at every `D_p` (`q` takes three of the values
//! `d_1 … d_4`), so each `D_p` gives three linear equations
//! `d_q V_0 − V_1 = ρ_q` for the two unknowns `(V_0, V_1)`: two solve, the
//! third checks. Nothing here integrates, fits or evaluates a theta function.
//!
//! The four `D_p` are equivalent in exact arithmetic; numerically the state
//! `l(D_p)` can be far larger than `l0` (`|l(D_4)| ~ 300 |l0|` when two `d_j`
//! are `4e-5` apart), and `V` loses the square of that ratio. So the two `D_p`
//! with the smallest states are evaluated — in double-double from the
//! reduction's double-double constants (`d_j`, `u`, `v` of (20); `α_j … δ_j`
//! recomputed from them), with `h1` and `c_ij = (b_i − b_j)/(a_i − a_j)` exact
//! to DD — and must agree: the first is the result, the second a check (a
//! wrong constant of the level set breaks the identity between them).
//!
//! The sign of `V` depends on the branches of the square roots at `D_p` (a
//! different branch is the involution or a half-period shift); the caller fixes
//! it (the solution from its theta quotients at `v0`). All flows passed share
//! one sign.

use crate::numeric::complex::Modulus;
use num_complex::Complex64;

use crate::error::{Error, Result};
use crate::kotter::KotterConstants;
use crate::numeric::dd::{Cdd, Dd};
use crate::riemann::HyperellipticCurve;
use crate::so4::PAIRS4;

type C = Complex64;

/// The check of the closed form: the velocity at a second half period,
/// evaluated in double, agrees with the result to ~1e-16 times the square of
/// its state ratio `|l(D_p)|/|l0|` (measured ≤ 1e-15 where the ratio is 1);
/// the distance divided by that square must be below this. An inconsistent
/// constant of the level set gives O(1) (a perturbation of 1e-9 in one
/// coefficient of (20), ~1e-9).
pub const HALF_PERIOD_AGREE_RTOL: f64 = 1e-12;

/// `what` of the errors of this module.
pub const CLOSED_FORM: &str = "closed-form velocity at the half periods";

/// The labels of (37) in the order `ξ_1, ξ_2, ξ_3, η_1, η_2, η_3`, as pairs of
/// branch-point indices (`P_23, P_31, P_12, P_14, P_24, P_34`).
const LABELS: [(usize, usize); 6] = [(2, 3), (3, 1), (1, 2), (1, 4), (2, 4), (3, 4)];

/// The velocities of several flows on one level set, in closed form.
#[derive(Debug, Clone, PartialEq)]
pub struct HalfPeriodVelocities {
    /// `V = A U` of each flow (unnormalised differentials `(1, x) dx/y`), in the
    /// order of the `c` passed, rounded from DD.
    pub v: Vec<[C; 2]>,
    /// The half period `D_p = d_0 + d_p` they were taken at (`p` in `1 … 4`).
    pub p: usize,
    /// The half period of the check.
    pub check_p: usize,
    /// Largest relative distance, over the flows, between the result and the
    /// check at the second half period (up to their sign; the check in double).
    pub agreement: f64,
    /// `|l(D_p)| / |l0|` at the half period used.
    pub state_ratio: f64,
    /// `V` in DD.
    pub(crate) v_dd: Vec<[Cdd; 2]>,
    /// The branch points `(0, d_1, d_2, d_3, d_1 d_2 d_3)` in DD.
    pub(crate) branch_points_dd: [Cdd; 5],
}

impl HalfPeriodVelocities {
    /// The rounding errors of the branch points of `curve` (the curve (8) of
    /// the same level set, branch points `(d_0, …, d_4)`) against the DD ones.
    /// `None` if `curve` has other branch points (to 1e-12 relative).
    pub fn branch_point_errors(&self, curve: &HyperellipticCurve) -> Option<[C; 5]> {
        let e = curve.branch_points();
        if e.len() != 5 {
            return None;
        }
        let lo: [C; 5] =
            std::array::from_fn(|k| self.branch_points_dd[k].sub(Cdd::new(e[k])).to_c());
        let scale = e.iter().fold(0.0f64, |m, z| m.max(z.modulus()));
        lo.iter()
            .all(|z| z.modulus() <= 1e-12 * scale)
            .then_some(lo)
    }
}

/// The arithmetic the closed form runs in: double-double for the result,
/// double for choosing the half period and for the check.
trait Num: Copy {
    fn zero() -> Self;
    fn to_c(self) -> C;
    fn add(self, b: Self) -> Self;
    fn sub(self, b: Self) -> Self;
    fn mul(self, b: Self) -> Self;
    fn div(self, b: Self) -> Self;
    fn neg(self) -> Self;
    fn mul_f64(self, x: f64) -> Self;
    /// The principal root.
    fn sqrt(self) -> Self;
}

impl Num for Cdd {
    fn zero() -> Self {
        Cdd::ZERO
    }
    fn to_c(self) -> C {
        Cdd::to_c(self)
    }
    fn add(self, b: Self) -> Self {
        Cdd::add(self, b)
    }
    fn sub(self, b: Self) -> Self {
        Cdd::sub(self, b)
    }
    fn mul(self, b: Self) -> Self {
        Cdd::mul(self, b)
    }
    fn div(self, b: Self) -> Self {
        Cdd::div(self, b)
    }
    fn neg(self) -> Self {
        Cdd::neg(self)
    }
    fn mul_f64(self, x: f64) -> Self {
        Cdd::mul_f64(self, x)
    }
    fn sqrt(self) -> Self {
        Cdd::sqrt(self)
    }
}

impl Num for C {
    fn zero() -> Self {
        C::new(0.0, 0.0)
    }
    fn to_c(self) -> C {
        self
    }
    fn add(self, b: Self) -> Self {
        self + b
    }
    fn sub(self, b: Self) -> Self {
        self - b
    }
    fn mul(self, b: Self) -> Self {
        self * b
    }
    fn div(self, b: Self) -> Self {
        crate::numeric::complex::cdiv(self, b)
    }
    fn neg(self) -> Self {
        -self
    }
    fn mul_f64(self, x: f64) -> Self {
        self * x
    }
    fn sqrt(self) -> Self {
        crate::numeric::complex::sqrt_principal(self)
    }
}

/// The level set: branch points `(0, d_1, d_2, d_3, d_4)`, `√c_j`, `h1` of
/// `l0`, `α_j … δ_j` of (24) and the coefficients of (20).
struct Level<T> {
    d: [T; 5],
    /// `diff[p][m] = d_p − d_m`, formed in DD (the double level set rounds the
    /// differences, not the `d`: two `d_j` 4e-5 apart keep their gap's digits).
    diff: [[T; 5]; 5],
    sc: [T; 3],
    h1: T,
    /// `(α_j, β_j, γ_j, δ_j)`.
    abgd: [[T; 4]; 3],
    /// `u_j^(1) + i u_j^(2)`, `v_j^(1) + i v_j^(2)` (ξ̇ from ṁ, ṅ) and the same with `−i` (η̇).
    to_xi: [[T; 2]; 3],
    to_eta: [[T; 2]; 3],
}

impl Level<Cdd> {
    /// In DD from the reduction's DD constants.
    fn new(k: &KotterConstants, l0: &[f64; 6]) -> Result<Level<Cdd>> {
        let d1 = Cdd::from_parts(k.d[0], k.d_lo[0]);
        let d2 = Cdd::from_parts(k.d[1], k.d_lo[1]);
        let d3 = Cdd::from_parts(k.d[2], k.d_lo[2]);
        let d4 = d1.mul(d2).mul(d3);
        let d = [Cdd::ZERO, d1, d2, d3, d4];
        let half = Dd::new(0.5);
        let mut abgd = [[Cdd::ZERO; 4]; 3];
        let mut to_xi = [[Cdd::ZERO; 2]; 3];
        let mut to_eta = [[Cdd::ZERO; 2]; 3];
        for j in 0..3 {
            let u1 = Cdd::from_parts(k.u[0][j], k.u_lo[0][j]);
            let u2 = Cdd::from_parts(k.u[1][j], k.u_lo[1][j]);
            let v1 = Cdd::from_parts(k.v[0][j], k.v_lo[0][j]);
            let v2 = Cdd::from_parts(k.v[1][j], k.v_lo[1][j]);
            // (25) corrected: Δ_j^(3) = u^(1) v^(2) − u^(2) v^(1); (24) corrected.
            let inv = Cdd::real(half).div(u1.mul(v2).sub(u2.mul(v1)));
            abgd[j] = [
                v2.add(v1.mul_i()).mul(inv),
                v2.sub(v1.mul_i()).mul(inv),
                u2.add(u1.mul_i()).mul(inv).neg(),
                u2.sub(u1.mul_i()).mul(inv).neg(),
            ];
            // (20), (22): ξ = l^(1) + i l^(2), η = l^(1) − i l^(2), l^(p) = u^(p) m + v^(p) n.
            to_xi[j] = [u1.add(u2.mul_i()), v1.add(v2.mul_i())];
            to_eta[j] = [u1.sub(u2.mul_i()), v1.sub(v2.mul_i())];
        }
        // √c_j of (33).
        let mut sc = [Cdd::ZERO; 3];
        for (j, s) in sc.iter_mut().enumerate() {
            let (kk, ll) = ((j + 1) % 3 + 1, (j + 2) % 3 + 1);
            let ct = Cdd::new(C::new(1.0, 0.0)).div(d[j + 1].sub(d[kk]).mul(d[j + 1].sub(d[ll])));
            *s = d[j + 1].sub(d4).mul(ct).sqrt();
        }
        let h1 = l0.iter().fold(Dd::ZERO, |acc, &x| acc.add(Dd::prod(x, x)));
        let diff = std::array::from_fn(|p| std::array::from_fn(|m| d[p].sub(d[m])));
        let lv = Level {
            d,
            diff,
            sc,
            h1: Cdd::real(h1),
            abgd,
            to_xi,
            to_eta,
        };
        let finite = |z: &Cdd| z.to_c().re.is_finite() && z.to_c().im.is_finite();
        if !(lv.sc.iter().all(finite) && h1.to_f64() > 0.0) {
            return Err(Error::InvalidArgument {
                what: CLOSED_FORM,
                reason: "sqrt(c_j) (33) not finite, or h1 = 0".into(),
            });
        }
        Ok(lv)
    }

    /// The same level set in double.
    fn rounded(&self) -> Level<C> {
        let r = |z: &Cdd| z.to_c();
        Level {
            d: self.d.each_ref().map(r),
            diff: self.diff.each_ref().map(|x| x.each_ref().map(r)),
            sc: self.sc.each_ref().map(r),
            h1: self.h1.to_c(),
            abgd: self.abgd.each_ref().map(|x| x.each_ref().map(r)),
            to_xi: self.to_xi.each_ref().map(|x| x.each_ref().map(r)),
            to_eta: self.to_eta.each_ref().map(|x| x.each_ref().map(r)),
        }
    }
}

/// The six `c_ij` of (2) (state order) in DD: `c4 + lo`, `lo` their rounding
/// errors from the exact quotients of the double `a, b`
/// (`normalize::c_rounding`; zero where not known). Rounded alone, six
/// numbers are of the form (2) only to rounding, so the half periods agree to
/// about that (far inside [`HALF_PERIOD_AGREE_RTOL`]), not to DD. A least-squares
/// `b` does not help: on a top with one small spacing it moves that `c_ij` by
/// the others' rounding over the spacing (1e-10 at `a_2 − a_1 = 1e-6`).
fn c_dd(c4: &[f64; 6], lo: &[f64; 6]) -> [Cdd; 6] {
    std::array::from_fn(|q| Cdd::real(Dd::sum(c4[q], lo[q])))
}

/// Frahm's field (1) `l̇_ij = Σ_k l_ik l_kj (c_kj − c_ik)` for a complex state.
fn field<T: Num>(c: &[T; 6], l: &[T; 6]) -> [T; 6] {
    let idx = |i: usize, j: usize| PAIRS4.iter().position(|&p| p == (i.min(j), i.max(j)));
    let lij = |i: usize, j: usize| -> T {
        match idx(i, j) {
            Some(q) if i < j => l[q],
            Some(q) => l[q].neg(),
            None => T::zero(),
        }
    };
    let cij = |i: usize, j: usize| -> T { idx(i, j).map_or(T::zero(), |q| c[q]) };
    std::array::from_fn(|q| {
        let (i, j) = PAIRS4[q];
        (0..4)
            .filter(|&k| k != i && k != j)
            .fold(T::zero(), |acc, k| {
                acc.add(lij(i, k).mul(lij(k, j)).mul(cij(k, j).sub(cij(i, k))))
            })
    })
}

/// The state at the half period `D_p` and the three equations it gives.
struct HalfPeriod<T> {
    p: usize,
    l: [T; 6],
    /// `(component of (ξ, η), q, √c G Q)` for the three vanishing labels.
    eqs: [(usize, usize, T); 3],
}

/// `(ξ, η)` of (37) at `D_p` (zero on the labels without `p`) and the equations.
///
/// `g = G` there (`P_0 = r_0(0) r_0(d_p) = 0` in (42)), and `G` is the scale that
/// puts `l(D_p)` on the level set of `l0`: `l` is linear in `G`, and
/// `H1 = Σ l_ij² = h1` gives `G² = h1 / H1(l|_{G=1})`. (Not `G² = h0/K` of the
/// corrected (42): both vanish as `h0 → 0`, and at `h0 = 0` the reduction's
/// constants are in another normalisation of (20); `H1` is neither, and
/// at the real half periods used `H1(l|_{G=1}) = |l|_{G=1}|²`.) The sign of `G`
/// is that of its principal root: a convention, fixed by the caller.
fn half_period<T: Num>(lv: &Level<T>, p: usize) -> HalfPeriod<T> {
    let d = &lv.d;
    let r0: [T; 5] = std::array::from_fn(|m| lv.diff[0][m].sqrt());
    let rp: [T; 5] = std::array::from_fn(|m| lv.diff[p][m].sqrt());
    let mut comp = [T::zero(); 6];
    let mut eqs = [(0usize, 0usize, T::zero()); 3];
    let mut ne = 0;
    for (i, &(j, k)) in LABELS.iter().enumerate() {
        let sc = lv.sc[i % 3];
        if j == p || k == p {
            let o = if j == p { k } else { j };
            let prod = (0..5)
                .filter(|&m| m != o && m != p)
                .fold(r0[o].mul(r0[p]), |acc, m| acc.mul(rp[m]));
            comp[i] = sc.mul(prod.div(d[p]));
        } else if ne < 3 {
            let q = (0..5)
                .find(|&m| m != 0 && m != p && m != j && m != k)
                .unwrap_or(0);
            let qf = r0[j].mul(r0[k]).mul(rp[j]).mul(rp[k]);
            eqs[ne] = (i, q, sc.mul(qf));
            ne += 1;
        }
    }
    // (23): m_j = α_j ξ_j + β_j η_j, n_j = γ_j ξ_j + δ_j η_j; l = (m3, −m2, n1, m1, n2, n3).
    let m: [T; 3] = std::array::from_fn(|j| {
        lv.abgd[j][0]
            .mul(comp[j])
            .add(lv.abgd[j][1].mul(comp[3 + j]))
    });
    let n: [T; 3] = std::array::from_fn(|j| {
        lv.abgd[j][2]
            .mul(comp[j])
            .add(lv.abgd[j][3].mul(comp[3 + j]))
    });
    let unit = [m[2], m[1].neg(), n[0], m[0], n[1], n[2]];
    let h1_unit = unit.iter().fold(T::zero(), |acc, x| acc.add(x.mul(*x)));
    let g = lv.h1.div(h1_unit).sqrt();
    HalfPeriod {
        p,
        l: unit.map(|x| x.mul(g)),
        eqs: eqs.map(|(i, q, f)| (i, q, f.mul(g))),
    }
}

fn size2<T: Num>(l: &[T; 6]) -> f64 {
    l.iter().map(|z| z.to_c().norm_sqr()).sum()
}

/// `V` of the flow `c` at the half period `hp`, and the relative residual of
/// the third equation.
fn velocity_at<T: Num>(lv: &Level<T>, hp: &HalfPeriod<T>, c: &[T; 6]) -> ([T; 2], f64) {
    let ld = field(c, &hp.l);
    let (md, nd) = ([ld[3], ld[1].neg(), ld[0]], [ld[2], ld[4], ld[5]]);
    let rows: [(usize, T); 3] = std::array::from_fn(|e| {
        let (i, q, fac) = hp.eqs[e];
        let j = i % 3;
        let w = if i < 3 { &lv.to_xi[j] } else { &lv.to_eta[j] };
        let cdot = w[0].mul(md[j]).add(w[1].mul(nd[j]));
        // d_q V0 − V1 = −2 Ċ/(√c G Q)
        (q, cdot.mul_f64(-2.0).div(fac))
    });
    // The pair of equations with the widest-apart d_q solves, the third checks.
    let gap = |a: usize, b: usize| lv.diff[rows[a].0][rows[b].0].to_c().modulus();
    let (a, b, t) = [(0, 1, 2), (0, 2, 1), (1, 2, 0)]
        .into_iter()
        .max_by(|x, y| gap(x.0, x.1).total_cmp(&gap(y.0, y.1)))
        .unwrap_or((0, 1, 2));
    let (qa, qb, qt) = (rows[a].0, rows[b].0, rows[t].0);
    let v0 = rows[a].1.sub(rows[b].1).div(lv.diff[qa][qb]);
    let v1 = lv.d[qa].mul(v0).sub(rows[a].1);
    // the third: d_qt V0 − V1 − ρ_t = (d_qt − d_qa) V0 + ρ_a − ρ_t
    let lhs = lv.diff[qt][qa].mul(v0).add(rows[a].1);
    let scale = lv.d[qt]
        .mul(v0)
        .to_c()
        .modulus()
        .max(v1.to_c().modulus())
        .max(rows[t].1.to_c().modulus());
    let res = lhs.sub(rows[t].1).to_c().modulus() / scale.max(f64::MIN_POSITIVE);
    ([v0, v1], res)
}

/// The velocities `V = A U` of the Manakov flows (1) with coefficients `c`
/// (state order) for each `c` in `cs` on the level set of `k` (`a = k.a`),
/// `l0` a state of that level set (it supplies `h1` exactly), in closed form (module docs). One sign
/// convention for all flows; the caller fixes it.
///
/// The half period with the smallest state gives the result — in DD with
/// `dd`, else in double (~1e-16 relative on most level sets, enough for
/// frequencies and a few times cheaper) — and the next one the check, in
/// double (to [`HALF_PERIOD_AGREE_RTOL`] times the square of its state ratio).
/// Where the two miss (double loses digits when the `d_j` spread over many
/// orders of magnitude), both are taken again in DD.
///
/// Errors ([`Error::InvalidArgument`] naming [`CLOSED_FORM`]): no flow, a
/// non-finite `c`, `√c_j` not finite, fewer than two half periods with a
/// finite state, or the two half periods disagreeing (constants that do not
/// belong to one level set).
pub fn half_period_velocities(
    k: &KotterConstants,
    l0: &[f64; 6],
    cs: &[[f64; 6]],
    dd: bool,
) -> Result<HalfPeriodVelocities> {
    half_period_velocities_lo(k, l0, cs, &[], dd)
}

/// [`half_period_velocities`] for coefficients `cs[k] + cs_lo[k]` in
/// double-double (`cs_lo` their rounding errors; empty for none): the DD
/// result is that of the unrounded `c`, the double paths take `cs`.
///
/// Errors: those of [`half_period_velocities`]; `cs_lo` neither empty nor of
/// the length of `cs`.
pub fn half_period_velocities_lo(
    k: &KotterConstants,
    l0: &[f64; 6],
    cs: &[[f64; 6]],
    cs_lo: &[[f64; 6]],
    dd: bool,
) -> Result<HalfPeriodVelocities> {
    if !cs_lo.is_empty() && cs_lo.len() != cs.len() {
        return Err(Error::Shape {
            what: "c_lo",
            expected: format!("({},) like c", cs.len()),
            got: format!("({},)", cs_lo.len()),
        });
    }
    if cs.is_empty() {
        return Err(Error::InvalidArgument {
            what: CLOSED_FORM,
            reason: "no flow given".into(),
        });
    }
    for c in cs {
        crate::error::check_finite("c", c)?;
    }
    let lv = Level::new(k, l0)?;
    let lr = lv.rounded();
    let hps = two_smallest_half_periods(&lr)?;
    let l0size2: f64 = l0.iter().map(|x| x * x).sum();
    let mut at = HalfPeriodPair {
        check_ratio2: (hps[1].0 / l0size2).max(1.0),
        lv: &lv,
        lr: &lr,
        hps: &hps,
        best_dd: None,
        check_dd: None,
        dd,
    };
    let mut v = Vec::with_capacity(cs.len());
    let mut v_dd = Vec::with_capacity(cs.len());
    let mut agreement = 0.0f64;
    for (q, c4) in cs.iter().enumerate() {
        let c = c_dd(c4, cs_lo.get(q).unwrap_or(&[0.0; 6]));
        // The result in the precision asked, the check in double; where they
        // miss (double loses digits on widely spread d_j, ~1e-11 at |d_4| ~
        // 1e9), both again in DD.
        let (mut va, mut worst, mut dist) = at.attempt(&c, false);
        if worst.is_nan() || worst > HALF_PERIOD_AGREE_RTOL {
            (va, worst, dist) = at.attempt(&c, true);
        }
        if worst.is_nan() || worst > HALF_PERIOD_AGREE_RTOL {
            return Err(Error::InvalidArgument {
                what: CLOSED_FORM,
                reason: format!(
                    "the half periods d_0 + d_{} and d_0 + d_{} give velocities that differ \
                     (or miss their third equation) by {worst:e} in double-double: the \
                     constants of the level set are inconsistent",
                    hps[0].1.p, hps[1].1.p
                ),
            });
        }
        agreement = agreement.max(dist);
        v.push(va.map(|z| z.to_c()));
        v_dd.push(va);
    }
    Ok(HalfPeriodVelocities {
        v,
        p: hps[0].1.p,
        check_p: hps[1].1.p,
        agreement,
        state_ratio: (hps[0].0 / l0size2).sqrt(),
        v_dd,
        branch_points_dd: lv.d,
    })
}

/// The states at the four half periods in double, the two smallest first
/// (`|l|²` and the half period); at least two finite ones.
fn two_smallest_half_periods(lr: &Level<C>) -> Result<Vec<(f64, HalfPeriod<C>)>> {
    let mut hps: Vec<(f64, HalfPeriod<C>)> = (1..5)
        .map(|p| {
            let hp = half_period(lr, p);
            (size2(&hp.l), hp)
        })
        .filter(|(s, _)| s.is_finite())
        .collect();
    hps.sort_by(|x, y| x.0.total_cmp(&y.0));
    if hps.len() < 2 {
        return Err(Error::InvalidArgument {
            what: CLOSED_FORM,
            reason: "fewer than two half periods give a finite state".into(),
        });
    }
    Ok(hps)
}

/// The half period with the smallest state (the result) and the next one (the
/// check), in double and, built when first needed, in DD.
struct HalfPeriodPair<'a> {
    lv: &'a Level<Cdd>,
    lr: &'a Level<C>,
    hps: &'a [(f64, HalfPeriod<C>)],
    best_dd: Option<HalfPeriod<Cdd>>,
    check_dd: Option<HalfPeriod<Cdd>>,
    /// The check's `|l|²` over `|l0|²` (at least 1): its errors scale with it.
    check_ratio2: f64,
    dd: bool,
}

impl HalfPeriodPair<'_> {
    /// The velocity of the flow `c` at the result's half period (in DD with
    /// `dd` or `full`, else in double), the worst of its residual and its
    /// distance from the check (in DD with `full`, else in double), and that
    /// distance.
    fn attempt(&mut self, c: &[Cdd; 6], full: bool) -> ([Cdd; 2], f64, f64) {
        let cc = c.map(|x| x.to_c());
        let (va, ra) = if self.dd || full {
            let (lv, p) = (self.lv, self.hps[0].1.p);
            let hp = self.best_dd.get_or_insert_with(|| half_period(lv, p));
            velocity_at(self.lv, hp, c)
        } else {
            let (v, r) = velocity_at(self.lr, &self.hps[0].1, &cc);
            (v.map(Cdd::new), r)
        };
        let (vb, rb, ratio2) = if full {
            let (lv, p) = (self.lv, self.hps[1].1.p);
            let hp = self.check_dd.get_or_insert_with(|| half_period(lv, p));
            let (v, r) = velocity_at(self.lv, hp, c);
            (v.map(|z| z.to_c()), r, 1.0)
        } else {
            let (v, r) = velocity_at(self.lr, &self.hps[1].1, &cc);
            (v, r, self.check_ratio2)
        };
        let a = va.map(|z| z.to_c());
        let scale = a[0].modulus().max(a[1].modulus());
        let dev = |s: f64| {
            (a[0] - s * vb[0])
                .modulus()
                .max((a[1] - s * vb[1]).modulus())
        };
        let dist = dev(1.0).min(dev(-1.0)) / scale.max(f64::MIN_POSITIVE);
        let finite = a.iter().all(|z| z.re.is_finite() && z.im.is_finite());
        // a zero flow (b constant) has V = 0: nothing to compare
        let worst = if !finite {
            f64::INFINITY
        } else if scale == 0.0 {
            0.0
        } else {
            // the check's errors scale with the square of its state ratio
            (dist.max(rb) / ratio2).max(ra)
        };
        (va, worst, dist)
    }
}

pub(crate) use super::lattice::lattice_rates_dd;
pub use super::lattice::LatticeRates;

/// The closed form and the theta quotients' fit at `v0` agree on `V` to this,
/// relative (measured ≤ 3.4e-15 on the shared tops and ≤ 2e-13 on random
/// states: the fit's own error); a wrong sign or constant gives O(1).
pub const CLOSED_VS_FIT_RTOL: f64 = 1e-9;

/// Where the fit is not determined to [`CLOSED_VS_FIT_RTOL`], the closed
/// form is accepted when it satisfies the quotients' velocity equations at
/// `v0` as well as the fit does: its residual in them at most this factor
/// times the fit's, plus [`CLOSED_RESIDUAL_FLOOR`]. Near a pinched curve the
/// quotients hardly depend on one direction of `u` (`Im τ_22` ~ 12: its theta
/// terms are ~1e-16 of the others), so the least-squares fit is determined
/// along it only to its condition times the roundoff. Measured on 'physical',
/// 1e-7 from an so(3) block: the fit 9.5e-10 from the closed form (3.3e-9
/// with periods 2e-15 more accurate), residuals 2.3e-15 (closed form) and
/// 1.9e-15 (fit); on the shared tops the closed form's residual is at most
/// 1.4 times the fit's. A wrong sign or constant leaves an O(1) residual.
pub const CLOSED_RESIDUAL_FACTOR: f64 = 4.0;

/// The absolute part of the residual test of [`CLOSED_RESIDUAL_FACTOR`]: 64
/// units of roundoff.
pub const CLOSED_RESIDUAL_FLOOR: f64 = 64.0 * f64::EPSILON;

/// The closed form is also accepted when its residual in the quotients'
/// velocity equations at `v0` is at most this, relative: the bound to which
/// the quotients' velocity check vouches for frequencies at all. Next to a
/// pinched curve the quotients' derivatives carry errors of ~1e-14 that the
/// least-squares fit absorbs by moving along the direction they hardly depend
/// on: on 24 states of the harsh draw the fit left 1e-15 … 3e-14 and the
/// closed form 3e-14 … 3e-11, yet the fit was 1e-9 … 1e-7 away from the closed
/// form in `V`, and the Abel images of a quadruple-precision trajectory moved
/// along the closed form (to 3e-15 … 1e-11 of the largest lattice rate, seven
/// measured) while the fit was off by up to 7e-10 of it (tests/data/frequency_abel_check.txt). A wrong
/// sign or constant leaves a residual of 1e-5 … 1e7 there.
pub const CLOSED_RESIDUAL_RTOL: f64 = 1e-10;

/// Whether the closed form agrees with the theta quotients' own velocity at
/// `v0`: the relative distance `dev` of their fit (on `V = A U`) and the
/// closed form's residual `res_closed` in the quotients' velocity equations
/// both within [`CLOSED_VS_FIT_RTOL`], or that residual within
/// [`CLOSED_RESIDUAL_FACTOR`] of the fit's `res_fit` or within
/// [`CLOSED_RESIDUAL_RTOL`]. Where it does not, the
/// callers take the fit (the set-up, whose self-check then decides) or refuse
/// (the torus's second flow).
pub(crate) fn closed_form_fits(dev: f64, res_closed: f64, res_fit: f64) -> bool {
    // NaN fails every comparison below.
    // `dev` is measured on `V = A U` relative to its largest component; where
    // `A` is ill-conditioned (a pinched curve) a small `dev` still allows a
    // large error of `U` in the direction `A` nearly annihilates, which the
    // residual in the quotients' own equations shows: both must be small.
    let near = dev <= CLOSED_VS_FIT_RTOL && res_closed <= CLOSED_VS_FIT_RTOL;
    near || res_closed
        <= (CLOSED_RESIDUAL_FACTOR * res_fit + CLOSED_RESIDUAL_FLOOR).max(CLOSED_RESIDUAL_RTOL)
}

/// The sign of the closed-form velocities in the convention of a reference
/// velocity `u_ref` of the first flow (normalised, e.g. the theta quotients' fit
/// at `v0`), and the relative distance between the two.
pub fn sign_against(
    curve: &crate::riemann::HyperellipticCurve,
    v: &[C; 2],
    u_ref: &[C; 2],
) -> (f64, f64) {
    let ap = crate::solution::a_periods_of(curve);
    let vr = [
        ap[0] * u_ref[0] + ap[1] * u_ref[1],
        ap[2] * u_ref[0] + ap[3] * u_ref[1],
    ];
    let s = if (v[0].conj() * vr[0] + v[1].conj() * vr[1]).re >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let scale = vr[0].modulus().max(vr[1].modulus());
    let dev = (s * v[0] - vr[0])
        .modulus()
        .max((s * v[1] - vr[1]).modulus())
        / scale.max(f64::MIN_POSITIVE);
    (s, dev)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solution::tests::TOPS;
    use crate::solution::velocity::algebraic_rates;
    use crate::solution::{a_periods_of, level_set_curve, Solution};
    use crate::tori::solve::c_pairs;

    /// The fit check refuses O(1) deviations and residuals, NaN, and a closed
    /// form that moves the quotients worse than the fit; it accepts a fit that
    /// strays along a direction the quotients do not determine (the measured
    /// pinched case) when the closed form's residual is the fit's.
    #[test]
    fn the_fit_check_reads_the_residual_where_the_fit_is_undetermined() {
        assert!(closed_form_fits(1e-15, 1e-15, 1e-15));
        assert!(closed_form_fits(3.3e-9, 2.3e-15, 1.9e-15));
        assert!(!closed_form_fits(3.3e-9, 1e-9, 1.9e-15));
        // far from the fit in V, but as consistent with the quotients as they
        // vouch for (the fit moved along the direction they hardly see: draw
        // 1186 of the harsh draw)
        assert!(closed_form_fits(2.2e-9, 2.3e-13, 8.4e-15));
        assert!(!closed_form_fits(0.5, 0.3, 1e-15));
        assert!(!closed_form_fits(f64::NAN, f64::NAN, 1e-15));
        assert!(!closed_form_fits(2e-9, f64::NAN, 1e-15));
        // close in V = A U, far in the quotients' equations (A ill-conditioned,
        // a state of the harsh draw next to a pinched curve): the fit's turn
        assert!(!closed_form_fits(2.0e-14, 0.29, 1.2e-12));
    }

    /// Relative distance of `x` from `±y` (the sign of `y` left open).
    fn dist_up_to_sign(x: &[C; 2], y: &[C; 2]) -> f64 {
        let d = |s: f64| (x[0] - s * y[0]).modulus().max((x[1] - s * y[1]).modulus());
        d(1.0).min(d(-1.0)) / y[0].modulus().max(y[1].modulus())
    }

    /// The theta quotients' own velocity at `v0` (least squares on theta
    /// gradients: an independent route through the Abel map of `l0`) against
    /// the closed form. Measured: 1.8e-15, 6.6e-16, 3.4e-15, 9.3e-16 on the
    /// four tops — the fit's own error (the closed form agrees with the
    /// 60-digit mpmath reference of tests/data/closed_u_reference.py to
    /// ~1e-31). The check at the second half period (double) agrees to ~1e-16.
    #[test]
    fn closed_form_matches_the_theta_fit_on_the_shared_tops() {
        for (n, (a, b, l0)) in TOPS.iter().enumerate() {
            let sol = Solution::new(a, b, l0).unwrap();
            let hp = half_period_velocities(sol.kotter(), l0, &[*sol.c4()], true).unwrap();
            let (fit, _) = sol.rates(&[*sol.c4()]).unwrap()[0];
            let (_, dev) = sign_against(sol.curve(), &hp.v[0], &fit);
            assert!(dev <= 1e-13, "top {n}: {dev:e}");
            assert!(hp.agreement <= 1e-14, "top {n}: {:e}", hp.agreement);
            assert!(hp.state_ratio <= 1.0 + 1e-12, "top {n}: {}", hp.state_ratio);
        }
    }

    /// The chain rule at auxiliary divisors (velocity.rs: no half period, no
    /// theta function) gives the same `V` up to its sign convention:
    /// measured ~1e-14 (near_degenerate ~1e-12, its chain-rule spread).
    #[test]
    fn closed_form_matches_the_chain_rule_at_auxiliary_divisors() {
        let tol = [1e-13, 1e-13, 1e-13, 1e-10];
        for (n, (a, b, l0)) in TOPS.iter().enumerate() {
            let ls = level_set_curve(a, l0).unwrap();
            let c = c_pairs(a, b).unwrap();
            let alg =
                algebraic_rates(&ls.kotter, &ls.kcurve, &a_periods_of(&ls.curve), &[c]).unwrap();
            let hp = half_period_velocities(&ls.kotter, l0, &[c], true).unwrap();
            let dev = dist_up_to_sign(&hp.v[0], &alg.v[0]);
            assert!(dev <= tol[n], "top {n}: {dev:e}");
        }
    }

    /// All four half periods `d_0 + d_p` give one velocity (up to the sign of
    /// their branches): an identity of the level set, to DD precision where
    /// the states `l(D_p)` are of the size of `l0` (the generic top).
    #[test]
    fn every_half_period_gives_the_same_velocity() {
        let (a, b, l0) = TOPS[0];
        let k = crate::kotter::kotter_constants(&a, &l0).unwrap();
        let lv = Level::new(&k, &l0).unwrap();
        // c exactly of the form (2), to DD: the identity holds to DD
        let c: [Cdd; 6] = std::array::from_fn(|q| {
            let (i, j) = crate::so4::PAIRS4[q];
            Cdd::real(Dd::sum(b[i], -b[j]).div(Dd::sum(a[i], -a[j])))
        });
        let vs: Vec<[Cdd; 2]> = (1..5)
            .map(|p| {
                let (v, res) = velocity_at(&lv, &half_period(&lv, p), &c);
                assert!(res <= 1e-28, "p = {p}: third equation {res:e}");
                v
            })
            .collect();
        let scale = vs[0][0].to_c().modulus().max(vs[0][1].to_c().modulus());
        for (p, v) in vs.iter().enumerate().skip(1) {
            // the difference in DD, up to the sign of the branches
            let dev = [1.0, -1.0]
                .map(|sg| {
                    (0..2)
                        .map(|i| v[i].sub(vs[0][i].mul_f64(sg)).to_c().modulus())
                        .fold(0.0f64, f64::max)
                })
                .into_iter()
                .fold(f64::INFINITY, f64::min)
                / scale;
            assert!(dev <= 1e-28, "p = {}: {dev:e}", p + 1);
        }
    }

    /// α_j … δ_j recomputed in DD from the DD coefficients of (20) round to
    /// the reduction's (its DD values rounded once).
    #[test]
    fn dd_level_set_constants_round_to_the_reductions() {
        for (a, _, l0) in TOPS {
            let k = crate::kotter::kotter_constants(&a, &l0).unwrap();
            let lv = Level::new(&k, &l0).unwrap();
            for j in 0..3 {
                for (m, x) in [k.alpha[j], k.beta[j], k.gamma[j], k.delta[j]]
                    .iter()
                    .enumerate()
                {
                    let y = lv.abgd[j][m].to_c();
                    assert!((x - y).modulus() <= 2e-16 * x.modulus(), "{j} {m}: {x} {y}");
                }
            }
        }
    }

    /// Constants that do not belong to one level set (`u_1^(1)` off by 1e-9)
    /// break the identity between the half periods, and the closed form
    /// refuses, naming itself.
    #[test]
    fn inconsistent_constants_are_refused() {
        let (a, b, l0) = TOPS[0];
        let mut k = crate::kotter::kotter_constants(&a, &l0).unwrap();
        let c = c_pairs(&a, &b).unwrap();
        assert!(half_period_velocities(&k, &l0, &[c], true).is_ok());
        k.u[0][0] *= 1.0 + 1e-9;
        match half_period_velocities(&k, &l0, &[c], true) {
            Err(Error::InvalidArgument { what, reason }) => {
                assert_eq!(what, CLOSED_FORM);
                assert!(reason.contains("inconsistent"), "{reason}");
            }
            other => panic!("expected a refusal, got {other:?}"),
        }
        assert!(matches!(
            half_period_velocities(&k, &l0, &[], true),
            Err(Error::InvalidArgument {
                what: CLOSED_FORM,
                ..
            })
        ));
    }

    /// `c_ij` is linear in `b`, so `V(b) = p2 V(a²) + p3 V(a³)` for the cubic
    /// interpolant `b = p0 + p1 a + p2 a² + p3 a³`: one sign convention for all
    /// flows of one call (a flipped sign would miss by O(1)).
    #[test]
    fn velocities_are_linear_in_b_with_one_sign() {
        let (a, b, l0) = TOPS[0];
        let k = crate::kotter::kotter_constants(&a, &l0).unwrap();
        let cs = [b, a.map(|x| x * x), a.map(|x| x * x * x)].map(|b| c_pairs(&a, &b).unwrap());
        let hp = half_period_velocities(&k, &l0, &cs, true).unwrap();
        let v = nalgebra::Matrix4::from_fn(|i, j| a[i].powi(j as i32));
        let p = v
            .lu()
            .solve(&nalgebra::Vector4::from_column_slice(&b))
            .unwrap();
        for i in 0..2 {
            let lin = p[2] * hp.v[1][i] + p[3] * hp.v[2][i];
            assert!((lin - hp.v[0][i]).modulus() <= 1e-13 * hp.v[0][i].modulus());
        }
    }

    /// The real structure: on 'generic' (real `d_j`, `V` real) two lattice
    /// rates vanish by symmetry and come out exactly zero, and `T w = w` to
    /// rounding; on 'wide' (imaginary `d_j`) `Y = 0` exactly. Without the
    /// projection they were ~1e-16 (the motion drifting off the real torus).
    #[test]
    fn the_real_structure_is_exact() {
        for (n, zeros) in [(0usize, [0usize, 3]), (2, [2, 3])] {
            let (a, b, l0) = TOPS[n];
            let sol = Solution::new(&a, &b, &l0).unwrap();
            let lat = sol.closed_rates(&[*sol.c4()], true).unwrap();
            let t = lat.involution.expect("a real level set has its involution");
            let w = lat.w[0];
            for z in zeros {
                assert_eq!(w[z], 0.0, "top {n}: w = {w:?}");
                assert_eq!(lat.w_lo[0][z], 0.0);
            }
            for r in 0..4 {
                let tw: f64 = (0..4).map(|k| t[r][k] as f64 * w[k]).sum();
                assert!((tw - w[r]).abs() <= 1e-15 * w.iter().fold(0.0f64, |m, x| m.max(x.abs())));
            }
            assert!(lat.periods_dd);
        }
    }

    /// Rank-2 states (`h0 = 0`, where the reduction takes its limit and (20)
    /// another normalisation) and their neighbourhood, `h0/h1` from 1e-1 to
    /// 1e-16 and 0: the closed form (with `G` from `h1`, not from `h0/K`)
    /// agrees with the theta fit (measured ≤ 5.7e-15) and its half periods
    /// with each other (~1e-31).
    #[test]
    fn closed_form_holds_near_and_at_h0_zero() {
        let (a, b, l0) = TOPS[0];
        for e in [1e-1, 1e-4, 1e-8, 1e-12, 1e-16, 0.0] {
            let mut l = l0;
            // h0 is linear in l34: l12 l34 + (l23 l14 − l13 l24)
            let rest = l[3] * l[2] - l[1] * l[4];
            let h1: f64 = l.iter().map(|x| x * x).sum();
            l[5] = (e * h1 - rest) / l[0];
            let sol = Solution::new(&a, &b, &l).unwrap();
            let hp = half_period_velocities(sol.kotter(), &l, &[*sol.c4()], true).unwrap();
            let (fit, _) = sol.rates(&[*sol.c4()]).unwrap()[0];
            let (_, dev) = sign_against(sol.curve(), &hp.v[0], &fit);
            assert!(dev <= 1e-13, "h0/h1 = {e:e}: {dev:e}");
            assert!(hp.agreement <= 1e-14, "h0/h1 = {e:e}: {:e}", hp.agreement);
        }
    }

    /// Branch points spread over many orders of magnitude (`d ≈ 2.6e4i,
    /// 3.5e3i, −11i`, `|d_4| ~ 1e9`): the closed form in double misses its
    /// check by ~1e-11 there and is taken again in DD; the result is the DD
    /// one (to its rounding) and agrees with the theta fit.
    #[test]
    fn double_evaluation_falls_back_to_dd_where_it_loses_digits() {
        let a = [
            0.9010814166306469,
            1.002408171560955,
            2.7193603249730787,
            4.127958089201849,
        ];
        let b = [
            2.899819754665347,
            -2.403522620439499,
            8.08464973253058,
            -1.7688076509028858,
        ];
        let l0 = [
            1.262430932291859,
            0.5335933913743319,
            0.4254334480991254,
            0.3085696178245133,
            -0.5479900458514644,
            3.195363984068542,
        ];
        let sol = Solution::new(&a, &b, &l0).unwrap();
        let fast = half_period_velocities(sol.kotter(), &l0, &[*sol.c4()], false).unwrap();
        let full = half_period_velocities(sol.kotter(), &l0, &[*sol.c4()], true).unwrap();
        assert!(dist_up_to_sign(&fast.v[0], &full.v[0]) <= 1e-15);
        assert!(fast.agreement <= 1e-14, "{:e}", fast.agreement);
        let (fit, _) = sol.rates(&[*sol.c4()]).unwrap()[0];
        let (_, dev) = sign_against(sol.curve(), &full.v[0], &fit);
        assert!(dev <= 1e-12, "{dev:e}");
    }
}
