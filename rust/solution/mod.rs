//! The Theorem (9)–(10): the state `l(t)` as a quotient of genus-2 theta
//! functions whose argument moves on a straight line, `v(t) = v0 + U t`.
//!
//! The chain (docs/theorem.md, equation numbers Perelomov's, corrections in
//! docs/errata.md):
//!
//! * the reduction of `l0` ([`crate::kotter`]): the level-set constants
//!   (`d_j`, `α_j … δ_j` of the corrected (24), `K`, `ε` of the corrected
//!   (40)), the points `(z_i, y_i)`, `g` and the branch of the `P_j`, all fixed
//!   once per solution;
//! * the curve (8) as a [`HyperellipticCurve`] with branch points
//!   `(d_0, …, d_4)`: `τ`, the Abel map `u` (base point ∞) and the Riemann
//!   constant `K_R`; `v = u(P1) + u(P2) + K_R`;
//! * (34): `P_L = C_L θ[χ_L](v)/θ(v)`, `χ_j = η(d_j)`, `χ_jk = χ_j + χ_k`, with
//!   `C_L²` from a well-conditioned auxiliary divisor and the sign of `C_L`
//!   from the initial state;
//! * (37) and the corrected (42): `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`,
//!   `g = G/(1 − ε P_0)`, `G = √(h0/K)`, so `ξ_j = √c_j G C_kl θ_kl/D`,
//!   `η_j = √c_j G C_j4 θ_j4/D` with the common denominator
//!   `D(v) = θ(v) − ε C_0 θ_0(v)`;
//! * (23): `l` is linear in `ξ, η`, hence `l_q(v) = N_q(v)/D(v)` with
//!   `N_q` a fixed combination of six theta functions — (9)–(10) as they truly read;
//! * `U` in closed form ([`dubrovin`]): Dubrovin's equations at the half
//!   periods `d_0 + d_p`, where the state and its derivative along the flow are
//!   explicit, give `V = A U` from the level-set constants; its lattice
//!   coordinates in double-double (periods in DD on the unrounded curve) with
//!   the real structure imposed. Its sign, and a guard, from the quotients' own
//!   velocity at `v0`: `d l/dt = (∇N_q − l_q ∇D)·U / D = (1)`, a 6 × 2 complex
//!   linear system solved by least squares (theta gradients at `v0`).
//!
//! Evaluation at large `t`: `v = x + τ y` with real lattice coordinates
//! `x(t) = x0 + X t`, `y(t) = y0 + Y t`, reduced modulo 2 (an even lattice
//! vector multiplies every `θ[χ]` by one common factor, so the quotients are
//! exact); the products `X t`, `Y t` are split error-free (fma) and `X, Y`
//! carried in double-double, so the phase keeps its digits at `t = 10^6`.

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use rayon::prelude::*;

use crate::curve::{KotterCurve, CYCLIC};
use crate::error::{Error, Result, SingularKind};
use crate::kotter::{kotter_with, KotterConstants, KotterState};
use crate::numeric::cancel::Cancel;
use crate::numeric::complex::sqrt_principal;
use crate::riemann::HyperellipticCurve;
use crate::so4;
use crate::theta::{char_index, LatticeLanes, SelectedBlock, ThetaJet, ThetaPlan, BLOCK};

mod build;
mod check;
pub mod constant;
pub mod dubrovin;
pub mod euler;
pub mod jacobi;
mod lattice;
mod level_set;
pub mod motion;
pub mod normalize;
pub mod precise;
mod setup;
pub mod transverse;
pub mod velocity;
pub mod verify;

pub use check::{
    DRIFT_DEFECT_FLOOR, DRIFT_RTOL, HORIZON_RTOL, PHASE_ROUNDING_RTOL, SELF_CHECK_RTOL,
    VELOCITY_CHECK_RTOL,
};
use level_set::level_set_curve_soft;
pub use level_set::{a_periods_of, level_set_curve, LevelSetCurve};
pub use setup::{INCONSISTENT, QUOTIENT_RESIDUAL_RTOL};

use build::{Candidates, Divisor0, Phase};
use check::{sign_patterns, Built, SelfCheck};
use level_set::{abel_of_point, eps41, map_coinciding};
use setup::{
    aux_constants_squared, check_velocity_fit, quotient_weights, signed_constants, ThetaAtV0,
    VelocitySystem,
};

type C = Complex64;

/// Truncation tolerance of the theta sums (absolute, on normalised values):
/// below the rounding of the quotients.
pub const THETA_TOL: f64 = 1e-16;

/// The divisor of `l0` contains ∞ (the `P_L` have poles) when `θ(v0)` is
/// this small relative to the largest `|θ[χ](v0)|`.
pub const DIVISOR_AT_INFINITY_RTOL: f64 = 1e-10;

/// Times per work unit between two cancellation checks (~2 ms on one core).
const CHUNK: usize = 8192;

/// Smallest piece handed to one thread.
const PAR_PIECE: usize = 512;

/// Rows `l(t_k)` of `out` (row-major `(N, 6)`) by `eval` on blocks of times:
/// `chunk` times per thread between Ctrl-C checks, split over rayon's threads
/// in pieces of at least `min_piece` times (fewer stay on the calling thread,
/// where a fork would cost more than it saves). Shared by the genus-2
/// solution and the dispatcher, whose evaluations differ in cost.
pub(crate) fn rows_in_parallel(
    t: &[f64],
    out: &mut [f64],
    cancel: &Cancel,
    chunk: usize,
    min_piece: usize,
    eval: impl Fn(&[f64], &mut [f64]) -> Result<()> + Sync,
) -> Result<()> {
    let threads = rayon::current_num_threads();
    let unit = chunk * threads.max(1);
    for (tc, oc) in t.chunks(unit).zip(out.chunks_mut(6 * unit)) {
        cancel.check()?;
        if threads > 1 && tc.len() >= 2 * min_piece {
            let piece = tc.len().div_ceil(4 * threads).max(min_piece);
            tc.par_chunks(piece)
                .zip(oc.par_chunks_mut(6 * piece))
                .try_for_each(|(tp, op)| eval(tp, op))?;
        } else {
            eval(tc, oc)?;
        }
    }
    Ok(())
}

/// Labels of the Wurzelfunktionen that enter (37) and (42), in the order of
/// [`Solution::constants`]: `P_0`, `P_kl` for `j = 1, 2, 3` (`kl = 23, 31, 12`),
/// `P_j4` for `j = 1, 2, 3`.
pub const LABELS: [&str; 7] = ["P0", "P23", "P31", "P12", "P14", "P24", "P34"];

/// An explicit solution of the Manakov top on the level set of `l0`.
#[derive(Debug)]
pub struct Solution {
    a: [f64; 4],
    c4: [f64; 6],
    /// The rounding errors of `c4` (`c4 + c4_lo` the top's `c_ij` in
    /// double-double; zeros where `c4` was given): the top the certificate
    /// integrates in double-double ([`verify`]).
    c4_lo: [f64; 6],
    l0: [f64; 6],
    kotter: KotterConstants,
    state0: KotterState,
    curve: HyperellipticCurve,
    plan: ThetaPlan,
    tau: [C; 4],
    rc: [C; 2],
    u0: [C; 2],
    rate: [C; 2],
    /// `x0, y0` of `v0 = x0 + τ y0`.
    lat0: [f64; 4],
    /// `X, Y` of `U = X + τ Y`.
    lat_rate: [f64; 4],
    /// Their rounding errors: `lat_rate + lat_rate_lo` is `X, Y` in DD, so
    /// that the phase keeps its digits at large `t` ([`phase_mod2`]).
    lat_rate_lo: [f64; 4],
    /// The sign of the closed-form velocities ([`dubrovin`]) in this
    /// solution's convention.
    v_sign: f64,
    /// Whether `U` is the closed form (else the theta quotients' fit at
    /// `v0`, where the closed form refused and `v_sign` is not known).
    closed_u: bool,
    /// Theta indices (FLINT order): `θ`, then the seven labels.
    idx: [usize; 8],
    /// Characteristics `(a, b)` of the seven labels.
    chars: [([u8; 2], [u8; 2]); 7],
    cl: [C; 7],
    /// `l_q = Re(Σ_m num[q][m] θ_idx[m] / Σ_m den[m] θ_idx[m])`.
    num: [[C; 8]; 6],
    den: [C; 8],
    calibration: [f64; 7],
    /// The self-check's defect of the quotients' shape ([`check::Defect`]).
    self_check: f64,
    /// The self-check's defect of the quotients' motion along `U`.
    velocity_check: f64,
    /// The relative defect `δ` whose drift `δ |t| |l̇|` [`Solution::l_batch`]
    /// bounds: the self-check's larger part where `U` is the quotients' fit,
    /// its velocity part where it is the closed form ([`check::drift_defect`]).
    drift_defect: f64,
    /// Where the closed form failed a check (the self-check, the fit of (1)
    /// at `v0`, the reduction's consistency checks; the reasons) and was set
    /// up anyway ([`Solution::with_c4_lo_certifying`]): every `l(t)` is then
    /// certified by an integration of (1), at every call.
    certify_every: Option<String>,
    /// `|l0|` (`Σ l_ij²` is a Casimir of (1): `|l(t)| = |l0|`).
    size: f64,
    /// `4 max|c_ij| |l0|²`, a bound of `|l̇|` by (1) for the phase horizon
    /// (`‖[L, Ω]‖_F ≤ 2 ‖L‖_F ‖Ω‖_F`, `‖Ω‖_F ≤ max|c_ij| ‖L‖_F`, `‖L‖_F² = 2|l|²`).
    speed_bound: f64,
    /// The largest `|t|` for `t < 0` and for `t > 0` up to which an
    /// integration of (1) has certified `l(t)` where the drift check could
    /// not ([`verify`]).
    certified: std::sync::Mutex<[f64; 2]>,
    /// Calls whose values came from the integration standing in for the
    /// closed form ([`Solution::stand_ins`]), and the last one's reason.
    stand_ins: std::sync::atomic::AtomicU64,
    stand_in_reason: std::sync::Mutex<String>,
    /// The constants polished in DD ([`precise::Precise`]), on first use
    /// (boxed: the fast path moves the solution and never reads them).
    precise: std::sync::OnceLock<Result<Box<precise::Precise>>>,
}

fn singular(kind: SingularKind, reason: String) -> Error {
    Error::Singular {
        what: "state l0",
        kind,
        reason,
    }
}

/// `x + X t` reduced to `[−1, 1]` modulo 2 with `X t` split error-free,
/// `X = rate + rate_lo` in double-double (the second product needs no
/// precision: it is below an ulp of the first).
#[inline(always)]
fn phase_mod2(x0: f64, rate: f64, rate_lo: f64, t: f64) -> f64 {
    let p = rate * t;
    let e = rate.mul_add(t, -p) + rate_lo * t;
    // p − 2 round(p/2) is exact (|result| ≤ 1 and both are multiples of ulp(p)).
    let r = crate::theta::rem2(p);
    crate::theta::rem2(x0 + r + e)
}

/// The arguments of a batch of `l(t_k)`: `out` holds `(N, 6)` rows for the
/// `N` times, and every time is finite.
pub(crate) fn check_rows(t: &[f64], out: &[f64]) -> Result<()> {
    if out.len() != 6 * t.len() {
        return Err(Error::Shape {
            what: "out",
            expected: format!("({}, 6)", t.len()),
            got: format!("{} entries", out.len()),
        });
    }
    crate::error::check_finite("t", t)
}

impl Solution {
    /// Sets up the solution through `l0` for the top with parameters `a, b`.
    ///
    /// Errors ([`Error::Singular`] naming the reason): `l0 = 0`;
    /// `h1² = 4h0²`; coinciding branch points `d_j`; the divisor of `l0` at
    /// infinity (`θ(v0) = 0`); and those of the reduction; a solution that
    /// fails its self-check ([`Error::Unverified`]).
    pub fn new(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> Result<Self> {
        crate::error::check_finite("l0", l0)?;
        let c = so4::manakov_c(a, b)?;
        // State order (12, 13, 14, 23, 24, 34) from the row-major 4 × 4 matrix.
        let c4 = [c[1], c[2], c[3], c[6], c[7], c[11]];
        Self::with_c4_lo(a, &c4, &normalize::c_rounding(a, b, &c4), l0)
    }

    /// [`Solution::new`] for the top with parameters `a` and Manakov
    /// coefficients `c4` (state order) given directly, e.g. the normalized
    /// `c' = (c − μ)/λ` of [`normalize::TopFrame`], which no `b` represents
    /// exactly in doubles.
    pub fn with_c4(a: &[f64; 4], c4: &[f64; 6], l0: &[f64; 6]) -> Result<Self> {
        Self::with_c4_lo(a, c4, &[0.0; 6], l0)
    }

    /// [`Solution::with_c4`] for the coefficients `c4 + c4_lo` in double-double
    /// (`c4_lo` the rounding errors of `c4`, [`normalize::c_rounding`]): the
    /// closed form of `U`, hence the phase, is that of the unrounded top; the
    /// rest takes `c4`.
    pub fn with_c4_lo(
        a: &[f64; 4],
        c4: &[f64; 6],
        c4_lo: &[f64; 6],
        l0: &[f64; 6],
    ) -> Result<Self> {
        Self::set_up(a, c4, c4_lo, l0, false)
    }

    /// [`Solution::with_c4_lo`], except that a solution whose theta quotients
    /// fail the self-check (with a finite defect) or fit (1) at `v0` for no
    /// velocity, or whose reduction fails a consistency check, is returned
    /// rather than refused, marked ([`Solution::certify_every`]) so that its
    /// `l(t)` is returned only where an integration of (1) certifies it, at
    /// every call
    /// ([`verify`]): the self-check's points spread over the whole torus, and
    /// a solution that misses them may still be right where it is evaluated
    /// (docs/degenerate.md, "Solutions that fail the self-check").
    pub fn with_c4_lo_certifying(
        a: &[f64; 4],
        c4: &[f64; 6],
        c4_lo: &[f64; 6],
        l0: &[f64; 6],
    ) -> Result<Self> {
        Self::set_up(a, c4, c4_lo, l0, true)
    }

    fn set_up(
        a: &[f64; 4],
        c4: &[f64; 6],
        c4_lo: &[f64; 6],
        l0: &[f64; 6],
        certifying: bool,
    ) -> Result<Self> {
        crate::error::check_finite("l0", l0)?;
        crate::error::check_finite("c", c4)?;
        crate::error::check_finite("c_lo", c4_lo)?;
        let c4 = *c4;
        // In the certifying set-up the reduction's consistency checks do not
        // refuse: their failure marks the solution as certified at every call.
        let mut soft_failure: Option<String> = None;
        let d = Divisor0::new(a, l0, certifying.then_some(&mut soft_failure))?;
        let at_v0 = ThetaAtV0::new(&d.jet, &d.idx)?;
        let sc = d.state0.curve.c().map(sqrt_principal);
        let eps = eps41(&d.kotter);
        // The constants C_L (37) and the signs l0 decides.
        let est = at_v0.estimates(&d.state0, &sc);
        let est0 = at_v0.votes().then(|| est.map(|r| r * r));
        let c2 = aux_constants_squared(&d.curve, &d.state0.curve, &d.plan, &d.idx, &d.rc, est0)?;
        let (cl0, calibration) = signed_constants(&c2, &est);
        // Where the closed form refuses (none known), U is the theta
        // quotients' fit at v0.
        let closed = build::closed_velocity(&d, l0, &c4, c4_lo);
        let cands = Candidates {
            d: &d,
            at_v0,
            sc,
            eps,
            c4,
            closed: &closed,
            check: SelfCheck::new(a, l0, &c4),
            certifying,
        };
        let (
            defect,
            Built {
                cl,
                num,
                den,
                rate,
                closed: closed_used,
            },
            verdict,
        ) = cands.best(&cl0, &calibration)?;
        if let Err(e) = verdict {
            // a failed check with a finite defect is kept (certifying only)
            let keep = certifying && defect.shape.is_finite() && defect.velocity.is_finite();
            crate::error::soften(keep.then_some(&mut soft_failure), e)?;
        }
        let certify_every = soft_failure;
        // the phase of the closed form where the checked pattern took it, else
        // of the fit
        let closed = if closed_used {
            closed
        } else {
            Err(Error::InvalidArgument {
                what: dubrovin::CLOSED_FORM,
                reason: "the closed form misses the theta quotients' equations at v0".into(),
            })
        };
        let (x0, y0) = d.curve.lattice_coordinates(&d.v0);
        let phase = Phase::new(&d.curve, &closed, rate);
        let Divisor0 {
            kotter,
            curve,
            chars,
            state0,
            tau,
            plan,
            rc,
            idx,
            u0,
            ..
        } = d;
        Ok(Solution {
            a: *a,
            c4,
            c4_lo: *c4_lo,
            l0: *l0,
            kotter,
            state0,
            curve,
            plan,
            tau,
            rc,
            u0,
            rate: phase.rate,
            lat0: [x0[0], x0[1], y0[0], y0[1]],
            lat_rate: phase.lat_rate,
            lat_rate_lo: phase.lat_rate_lo,
            v_sign: phase.v_sign,
            closed_u: closed.is_ok(),
            idx,
            chars,
            cl,
            num,
            den,
            calibration,
            self_check: defect.shape,
            velocity_check: defect.velocity,
            drift_defect: check::drift_defect(&defect, closed_used),
            size: l0.iter().map(|x| x * x).sum::<f64>().sqrt(),
            speed_bound: 4.0
                * c4.iter().fold(0.0f64, |m, v| m.max(v.abs()))
                * l0.iter().map(|x| x * x).sum::<f64>(),
            certified: std::sync::Mutex::new([0.0; 2]),
            stand_ins: std::sync::atomic::AtomicU64::new(0),
            stand_in_reason: std::sync::Mutex::new(String::new()),
            precise: std::sync::OnceLock::new(),
            certify_every,
        })
    }

    /// The state the solution starts from.
    pub fn l0(&self) -> &[f64; 6] {
        &self.l0
    }

    /// The parameters `a`.
    pub fn a(&self) -> &[f64; 4] {
        &self.a
    }

    /// The Manakov `c_ij` (2), state order.
    pub fn c4(&self) -> &[f64; 6] {
        &self.c4
    }

    /// The rounding errors of [`Solution::c4`]: `c4 + c4_lo` are the top's
    /// `c_ij` to double-double accuracy (zero where the solution was built
    /// from `c4` alone).
    pub fn c4_lo(&self) -> &[f64; 6] {
        &self.c4_lo
    }

    /// The level-set constants of the reduction (fixed branches).
    pub fn kotter(&self) -> &KotterConstants {
        &self.kotter
    }

    /// The reduction of `l0`.
    pub fn state0(&self) -> &KotterState {
        &self.state0
    }

    /// The curve (8) with its homology basis, periods and Abel map.
    pub fn curve(&self) -> &HyperellipticCurve {
        &self.curve
    }

    /// The theta plan of `τ` (first derivatives, serial), shared with
    /// callers that evaluate the quotients themselves.
    pub fn plan(&self) -> &ThetaPlan {
        &self.plan
    }

    /// The velocities on this level set of the Manakov flows with
    /// coefficients `c4s` (state order), each with the relative residual of
    /// its least-squares fit: the equations that give [`Solution::rate`], with
    /// other right-hand sides (the curve, the divisor and the quotients depend
    /// on `a` and `l0` only). For the solution's own `c4` this is `U`.
    pub fn rates(&self, c4s: &[[f64; 6]]) -> Result<Vec<([C; 2], f64)>> {
        let sys = self.velocity_system()?;
        c4s.iter().map(|c4| sys.rate(c4, "U'")).collect()
    }

    /// The quotients' velocity equations at `v0` ([`Solution::rates`]).
    fn velocity_system(&self) -> Result<VelocitySystem> {
        let v0 = [self.u0[0] + self.rc[0], self.u0[1] + self.rc[1]];
        let jet = self.plan.jet(&v0, 1)?;
        VelocitySystem::at(&jet, &self.idx, &self.num, &self.den)
    }

    /// The velocity of the flow with coefficients `c4` fitted as in
    /// [`Solution::rates`], with the relative residual of the fit and that of
    /// `candidate` in the same equations (the quotients' velocity equations at
    /// `v0`): where the quotients hardly depend on one direction of `u` (next
    /// to a pinched curve) the fit is undetermined along it, and a candidate
    /// that satisfies the equations as well as the fit does is as good.
    pub fn rate_and_residual_of(
        &self,
        c4: &[f64; 6],
        candidate: &[C; 2],
    ) -> Result<(([C; 2], f64), f64)> {
        let sys = self.velocity_system()?;
        Ok((sys.rate(c4, "U'")?, sys.residual_at(candidate, c4)))
    }

    /// The velocities `U` of the Manakov flows (1) with coefficients `c`
    /// (state order) for each `c` in `cs` on this level set, in closed form
    /// ([`dubrovin`]) and in this solution's sign convention, with their
    /// lattice coordinates (the real structure imposed). For the solution's
    /// own `c4` this is `U`.
    /// `dd`: the closed form and the periods in double-double on the unrounded
    /// curve (`X, Y` to ~1e-19, as the solution's own phase), else in double
    /// with the curve's double periods (to ~1e-15, ~1e-11 on stiff tops, as the
    /// frequency map: a few times cheaper).
    ///
    /// Errors: [`Error::InvalidArgument`] naming [`dubrovin::CLOSED_FORM`]
    /// where the closed form refuses, or refused for this solution's own `U`
    /// (its sign convention is then unknown).
    pub fn closed_rates(&self, cs: &[[f64; 6]], dd: bool) -> Result<dubrovin::LatticeRates> {
        if !self.closed_u {
            return Err(Error::InvalidArgument {
                what: dubrovin::CLOSED_FORM,
                reason: "the solution's U is the theta quotients' fit: the closed form \
                         refused at its set-up"
                    .into(),
            });
        }
        let hp = dubrovin::half_period_velocities(&self.kotter, &self.l0, cs, dd)?;
        let v: Vec<_> = hp
            .v_dd
            .iter()
            .map(|z| z.map(|x| x.mul_f64(self.v_sign)))
            .collect();
        let e_lo = if dd {
            hp.branch_point_errors(&self.curve)
        } else {
            None
        };
        dubrovin::lattice_rates_dd(&self.curve, e_lo.as_ref().map(|e| &e[..]), &v)
    }

    /// `τ`, row-major.
    pub fn tau(&self) -> [C; 4] {
        self.tau
    }

    /// The vector of Riemann constants `K_R` (`v = u + K_R`).
    pub fn riemann_constant(&self) -> [C; 2] {
        self.rc
    }

    /// `u0 = u(P1) + u(P2)`, the Abel image of the divisor of `l0`.
    pub fn u0(&self) -> [C; 2] {
        self.u0
    }

    /// `U`: `u(t) = u0 + U t`.
    pub fn rate(&self) -> [C; 2] {
        self.rate
    }

    /// The velocities of the flows with coefficients `c4s` on this level set
    /// from the chain rule at auxiliary divisors ([`velocity::algebraic_rates`]),
    /// in the sign convention of this solution: the first flow's velocity is
    /// compared with the theta-side fit of the same flow at `v0`
    /// ([`Solution::rates`]).
    ///
    /// Errors: those of [`velocity::algebraic_rates`], and the two routes
    /// disagreeing on the first flow by more than [`QUOTIENT_RESIDUAL_RTOL`]
    /// relative ([`INCONSISTENT`]). Both use the principal `G` of (42), so no
    /// sign is flipped here: a flipped sign would be such a disagreement.
    pub fn algebraic_rates(&self, c4s: &[[f64; 6]]) -> Result<velocity::AlgebraicRates> {
        let alg = velocity::algebraic_rates(
            &self.kotter,
            &self.state0.curve,
            &a_periods_of(&self.curve),
            c4s,
        )?;
        let reference = self.rates(&c4s[..1])?[0].0;
        let u = alg.rates[0];
        let dev = (u[0] - reference[0])
            .norm()
            .max((u[1] - reference[1]).norm());
        let scale = reference[0].norm().max(reference[1].norm());
        if dev.is_nan() || dev > QUOTIENT_RESIDUAL_RTOL * scale {
            return Err(Error::Singular {
                what: INCONSISTENT,
                kind: SingularKind::InconsistentQuotients,
                reason: format!(
                    "the velocity by the chain rule at auxiliary divisors differs from the \
                     theta quotients' at v0 by {dev:e} (|U| = {scale:e})"
                ),
            });
        }
        Ok(alg)
    }

    /// Characteristics `(a, b)` of [`LABELS`].
    pub fn characteristics(&self) -> [([u8; 2], [u8; 2]); 7] {
        self.chars
    }

    /// `C_L` of (34) for [`LABELS`]: `P_L = C_L θ[χ_L](v)/θ(v)`.
    pub fn constants(&self) -> [C; 7] {
        self.cl
    }

    /// `|C_L − P_L(l0) θ(v0)/θ[χ_L](v0)| / |C_L|`: the agreement of the
    /// auxiliary-divisor constants with the initial state.
    pub fn calibration(&self) -> [f64; 7] {
        self.calibration
    }

    /// The largest relative defect of the quotients' shape the solution
    /// showed at its self-check points when it was built (`l(0) = l0`, the
    /// integrals (6)–(7), a real `l`); at most [`SELF_CHECK_RTOL`].
    pub fn self_check(&self) -> f64 {
        self.self_check
    }

    /// The largest defect of Frahm's equations (1) along `U` at the
    /// self-check points, relative to the largest speed there; at most
    /// [`VELOCITY_CHECK_RTOL`].
    pub fn velocity_check(&self) -> f64 {
        self.velocity_check
    }

    /// The relative defect `δ` of the drift bound of [`Solution::l_batch`]
    /// ([`check::drift_defect`]).
    pub fn drift_defect(&self) -> f64 {
        self.drift_defect
    }

    /// Coefficients of (9)–(10) as they read: `l_q = N_q/D`,
    /// `N_q = Σ_m num[q][m] θ[idx[m]]`, `D = Σ_m den[m] θ[idx[m]]`.
    pub fn quotient(&self) -> ([usize; 8], [[C; 8]; 6], [C; 8]) {
        (self.idx, self.num, self.den)
    }

    /// The Abel image `u(P1) + u(P2)` of a state on the same level set (the
    /// branches of `l0`'s reduction), modulo the lattice.
    pub fn abel(&self, l: &[f64; 6]) -> Result<[C; 2]> {
        let st = kotter_with(self.kotter.clone(), l)?;
        let p = &st.points;
        let ua = abel_of_point(&self.curve, p.z1, p.y1, &p.zd1)?;
        let ub = abel_of_point(&self.curve, p.z2, p.y2, &p.zd2)?;
        Ok([ua[0] + ub[0], ua[1] + ub[1]])
    }

    /// Lattice coordinates `(x, y)` of `v(t) = x + τ y`, reduced modulo 2.
    #[inline]
    pub fn lattice_reduced(&self, t: f64) -> ([f64; 2], [f64; 2]) {
        (
            [
                phase_mod2(self.lat0[0], self.lat_rate[0], self.lat_rate_lo[0], t),
                phase_mod2(self.lat0[1], self.lat_rate[1], self.lat_rate_lo[1], t),
            ],
            [
                phase_mod2(self.lat0[2], self.lat_rate[2], self.lat_rate_lo[2], t),
                phase_mod2(self.lat0[3], self.lat_rate[3], self.lat_rate_lo[3], t),
            ],
        )
    }

    /// `v(t) = v0 + U t` reduced modulo twice the lattice.
    #[inline]
    pub fn v_reduced(&self, t: f64) -> [C; 2] {
        let (x, y) = self.lattice_reduced(t);
        [
            C::new(x[0], 0.0) + self.tau[0] * y[0] + self.tau[1] * y[1],
            C::new(x[1], 0.0) + self.tau[2] * y[0] + self.tau[3] * y[1],
        ]
    }

    /// `l_q = Re(N_q/D)` for the points of one theta block (rows `m` of
    /// `blk` are `θ_idx[m]`), written to `out` (row-major, `blk.len` rows);
    /// only real parts are formed: `Re(N/D) = Re(N D̄)/|D|²`. The sums run
    /// over the block's points in its own structure-of-arrays layout, so they
    /// vectorise; each is the complex product and the sum over `m` in the
    /// order of the per-point form, so the bits are the same.
    fn combine(&self, blk: &SelectedBlock, out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2 (checked just above).
                return unsafe { self.combine_avx2(blk, out) };
            }
        }
        self.combine_body(blk, out)
    }

    /// [`Solution::combine`] compiled for AVX2: four points per instruction
    /// (no FMA: the products and sums round as in the baseline, same bits).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn combine_avx2(&self, blk: &SelectedBlock, out: &mut [f64]) {
        self.combine_body(blk, out)
    }

    #[inline(always)]
    fn combine_body(&self, blk: &SelectedBlock, out: &mut [f64]) {
        const P: usize = crate::theta::BLOCK;
        // A function, not a closure, so that it inlines into the AVX2 copy.
        #[inline(always)]
        fn weighted(blk: &SelectedBlock, w: &[C; 8]) -> ([f64; P], [f64; P]) {
            let (mut re, mut im) = ([0.0; P], [0.0; P]);
            for (m, w) in w.iter().enumerate() {
                // Each row of (23) has two nonzero weights of eight (`ξ_j`
                // and `η_j`); an exact zero adds nothing to a finite sum.
                if w.re == 0.0 && w.im == 0.0 {
                    continue;
                }
                let (tr, ti) = (&blk.re[m], &blk.im[m]);
                for p in 0..P {
                    re[p] += w.re * tr[p] - w.im * ti[p];
                    im[p] += w.re * ti[p] + w.im * tr[p];
                }
            }
            (re, im)
        }
        let (dre, dim) = weighted(blk, &self.den);
        let inv: [f64; P] = std::array::from_fn(|p| 1.0 / (dre[p] * dre[p] + dim[p] * dim[p]));
        for (q, w) in self.num.iter().enumerate() {
            let (nre, nim) = weighted(blk, w);
            for (p, o) in out.chunks_exact_mut(6).enumerate().take(blk.len) {
                o[q] = (nre[p] * dre[p] + nim[p] * dim[p]) * inv[p];
            }
        }
    }

    /// [`Solution::lattice_reduced`] for the times `t` of one block (at most
    /// [`BLOCK`]) into lanes `0..t.len()`; the other lanes get those of
    /// `t = 0`, so that every lane is computed and the loops vectorise.
    fn lattice_lanes(&self, t: &[f64], lanes: &mut LatticeLanes) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                return unsafe { self.lattice_lanes_avx2(t, lanes) };
            }
        }
        self.lattice_lanes_body(t, lanes)
    }

    /// [`Solution::lattice_lanes`] compiled for AVX2 with FMA: the
    /// error-free product of [`phase_mod2`] is one instruction instead of a
    /// library call, and it rounds exactly as that call does (same bits).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn lattice_lanes_avx2(&self, t: &[f64], lanes: &mut LatticeLanes) {
        self.lattice_lanes_body(t, lanes)
    }

    #[inline(always)]
    fn lattice_lanes_body(&self, t: &[f64], lanes: &mut LatticeLanes) {
        let mut tt = [0.0; BLOCK];
        tt[..t.len()].copy_from_slice(t);
        for k in 0..2 {
            for (p, &t) in tt.iter().enumerate() {
                lanes.x[k][p] = phase_mod2(self.lat0[k], self.lat_rate[k], self.lat_rate_lo[k], t);
                lanes.y[k][p] = phase_mod2(
                    self.lat0[2 + k],
                    self.lat_rate[2 + k],
                    self.lat_rate_lo[2 + k],
                    t,
                );
            }
        }
    }

    /// The rows `l(t_k)` without the drift check.
    fn eval_rows(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
        self.plan.eval_selected_g2_lattice_lanes(
            t.len(),
            |first, m, lanes| self.lattice_lanes(&t[first..first + m], lanes),
            &self.idx,
            |first, blk| self.combine(blk, &mut out[6 * first..6 * (first + blk.len)]),
        )
    }

    fn eval_serial(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
        self.eval_rows(t, out)?;
        self.check_drift(t, out)
    }

    /// Whether the drift check applies its bound [`DRIFT_RTOL`] (the defect
    /// above [`DRIFT_DEFECT_FLOOR`]).
    fn gated(&self) -> bool {
        self.certify_every.is_some() || self.drift_defect > DRIFT_DEFECT_FLOOR
    }

    /// Where the closed form failed a check and was set up to be certified at
    /// every call ([`Solution::with_c4_lo_certifying`]): the reasons.
    pub fn certify_every(&self) -> Option<&str> {
        self.certify_every.as_deref()
    }

    /// `l(t)` of a solution that failed its self-check: the closed form's
    /// values (in `out`) stand only where an integration of (1) from `l0`
    /// agrees with them at every requested time of a direction of time, to
    /// [`verify::VERIFY_RTOL`]; where it does not, the integration's own
    /// values stand in if a finer one confirms them ([`verify::Outcome::Integrated`]);
    /// else refused, with the self-check's reason and what the integration
    /// found. At `t = 0` the value is `l0` itself. Nothing is cached: the
    /// closed form may be right at some times and not at others.
    fn check_every_time(
        &self,
        why: &str,
        t: &[f64],
        out: &mut [f64],
        cancel: &Cancel,
    ) -> Result<()> {
        let mut stood: Option<(f64, f64, f64, u32)> = None;
        for (&tk, lk) in t.iter().zip(out.chunks_exact_mut(6)) {
            if tk == 0.0 {
                let d = verify::nan_max(lk.iter().zip(&self.l0).map(|(x, y)| (x - y).abs()))
                    / self.size;
                if d.is_nan() || d > verify::VERIFY_RTOL {
                    // no integration: l0 itself (split 0)
                    stood = Some((if d.is_nan() { f64::INFINITY } else { d }, 0.0, 0.0, 0));
                }
                // `l(0) = l0` is known exactly: it stands in for the closed
                // form, whose check failed.
                lk.copy_from_slice(&self.l0);
            }
        }
        for sign in [1.0, -1.0] {
            let times: Vec<f64> = t.iter().copied().filter(|&x| x * sign > 0.0).collect();
            if times.is_empty() {
                continue;
            }
            let outcome = verify::certify(
                &self.c4,
                &self.c4_lo,
                &self.l0,
                self.size,
                sign,
                &times,
                false,
                |ts, o| self.eval_rows(ts, o),
                cancel,
            )?;
            match outcome {
                verify::Outcome::Agree => {}
                verify::Outcome::Integrated(si) => si.apply(t, sign, out, &mut stood),
                other => return Err(verify::refusal_unchecked(why, &other)),
            }
        }
        if let Some(worst) = stood {
            self.note_stand_in(why, worst);
        }
        Ok(())
    }

    /// Counts a call whose values (some or all) come from the integration
    /// that stands in for the closed form, and keeps why: the largest
    /// disagreement `(off, t, spread, split)` of the call (`split = 0`: only
    /// `l(0) = l0` stood in).
    fn note_stand_in(&self, why: &str, (off, at, spread, split): (f64, f64, f64, u32)) {
        self.stand_ins
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let mut m = self
            .stand_in_reason
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        *m = if split == 0 {
            format!("{why}; the closed form misses l0 by {off:.1e} |l0| at t = 0, and l0 stands in")
        } else {
            format!(
                "{why}; the closed form differs from an integration of (1) (Gauss-Legendre \
                 order 16 in double-double) by {off:.1e} |l0| at t = {at:e}, and the \
                 integration's values stand in for it (confirmed by one with every step \
                 split in {split}, to {spread:.1e} |l0|)"
            )
        };
    }

    /// The count of [`Solution::stand_ins`] alone (cheap: one atomic load).
    pub fn stand_in_calls(&self) -> u64 {
        self.stand_ins.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// How many `l(t)` calls returned values of the integration that stands
    /// in for the closed form where the closed form disagreed with it
    /// ([`verify::Outcome::Integrated`]), and why the last one did.
    pub fn stand_ins(&self) -> (u64, String) {
        (
            self.stand_in_calls(),
            self.stand_in_reason
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .clone(),
        )
    }

    /// The drift check of a solution whose defect `δ` ([`Solution::drift_defect`])
    /// is above rounding ([`DRIFT_DEFECT_FLOOR`]): where the first-order drift
    /// `δ |t| |l̇(t)|` may exceed [`DRIFT_RTOL`] `|l0|` (and `|t|` is beyond
    /// what is already certified), an integration of (1), once per direction
    /// of time, certifies `l(t)` where the two agree to
    /// [`verify::VERIFY_RTOL`] ([`verify`]). Where they do not, and the same
    /// integration with every step halved confirms its own values, those stand in
    /// for the closed form's at every requested time of that direction
    /// ([`Solution::stand_ins`]); else `l(t)` is refused.
    fn check_drift_certified(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        if let Some(why) = &self.certify_every {
            return self.check_every_time(why, t, out, cancel);
        }
        let certified = *self.certified.lock().unwrap_or_else(|e| e.into_inner());
        let side = |t: f64| usize::from(t > 0.0);
        let delta = self.drift_defect;
        let mut failing: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
        let mut reason = None;
        for (&tk, lk) in t.iter().zip(out.chunks_exact(6)) {
            let l: &[f64; 6] = lk.try_into().expect("rows of 6");
            let f = so4::vector_field4(&self.c4, l);
            let speed = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let drift = delta * tk.abs() * speed / self.size;
            if drift > DRIFT_RTOL && tk.abs() > certified[side(tk)] {
                failing[side(tk)].push(tk);
                reason.get_or_insert_with(|| drift_reason(tk, self.drift_defect, drift));
            }
        }
        let Some(reason) = reason else {
            return Ok(());
        };
        let mut stood: Option<(f64, f64, f64, u32)> = None;
        for (s, failing) in failing.iter().enumerate() {
            if failing.is_empty() {
                continue;
            }
            let sign = if s == 1 { 1.0 } else { -1.0 };
            // Every requested time of this direction, not only the failing
            // ones: where the integration stands in, it does for all of them.
            let times: Vec<f64> = t.iter().copied().filter(|&x| x * sign > 0.0).collect();
            let outcome = verify::certify(
                &self.c4,
                &self.c4_lo,
                &self.l0,
                self.size,
                sign,
                &times,
                true,
                |ts, o| self.eval_rows(ts, o),
                cancel,
            )?;
            match outcome {
                verify::Outcome::Agree => {
                    let reach = times.iter().fold(0.0f64, |m, t| m.max(t.abs()));
                    let mut c = self.certified.lock().unwrap_or_else(|e| e.into_inner());
                    c[s] = c[s].max(reach);
                }
                verify::Outcome::Integrated(si) => si.apply(t, sign, out, &mut stood),
                other => {
                    return Err(verify::refusal(
                        format!("{reason}; evaluate nearer t = 0"),
                        &other,
                    ))
                }
            }
        }
        if let Some(worst) = stood {
            // `l(0) = l0` exactly, as the integration has it.
            for (&tk, lk) in t.iter().zip(out.chunks_exact_mut(6)) {
                if tk == 0.0 {
                    lk.copy_from_slice(&self.l0);
                }
            }
            self.note_stand_in(&reason, worst);
        }
        Ok(())
    }

    /// The phase horizon of a solution whose defect `δ` is at rounding level
    /// ([`DRIFT_DEFECT_FLOOR`]; above it [`Solution::check_drift_certified`]
    /// applies the drift check's bound [`DRIFT_RTOL`]): `l(t)` is refused where
    /// even a rounding-level `δ` (`max(δ, PHASE_ROUNDING_RTOL)`) drifts it by
    /// more than [`HORIZON_RTOL`] `|l0|` — the first-order drift `δ |t| |l̇(t)|`,
    /// `l̇` Frahm's (1) at the computed `l(t)` — where the phase `U t` is no
    /// longer determined by the double `U` (at `|U t| ~ 1e16` not even its
    /// integer part is), and the value would be arbitrary.
    fn check_drift(&self, t: &[f64], out: &[f64]) -> Result<()> {
        let delta = self.drift_defect.max(PHASE_ROUNDING_RTOL);
        // One comparison per block on the generic path, with the bound
        // `speed_bound` of |l̇| (|l| = |l0|: Σ l² is conserved).
        let t_max = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if delta * t_max * self.speed_bound / self.size <= HORIZON_RTOL {
            return Ok(());
        }
        for (&tk, lk) in t.iter().zip(out.chunks_exact(6)) {
            let l: &[f64; 6] = lk.try_into().expect("rows of 6");
            let f = so4::vector_field4(&self.c4, l);
            let speed = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let drift = delta * tk.abs() * speed / self.size;
            // NaN (a non-finite l) passes here: the quotient's own checks own it
            if drift > HORIZON_RTOL {
                return Err(check::beyond_horizon(tk, drift, "the velocity U"));
            }
        }
        Ok(())
    }

    /// `l(t_k)` into `out` (row-major `(N, 6)`); rayon for large batches,
    /// `cancel` checked between chunks.
    ///
    /// Errors: non-finite `t`, wrong `out` size, [`Error::Interrupted`].
    pub fn l_batch(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        check_rows(t, out)?;
        if self.gated() {
            rows_in_parallel(t, out, cancel, CHUNK, PAR_PIECE, |tp, op| {
                self.eval_rows(tp, op)
            })?;
            return self.check_drift_certified(t, out, cancel);
        }
        rows_in_parallel(t, out, cancel, CHUNK, PAR_PIECE, |tp, op| {
            self.eval_serial(tp, op)
        })
    }

    /// [`Solution::l_batch`] on the calling thread only (for benchmarks and
    /// callers that parallelise themselves).
    pub fn l_batch_serial(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        check_rows(t, out)?;
        let gated = self.gated();
        for (tc, oc) in t.chunks(CHUNK).zip(out.chunks_mut(6 * CHUNK)) {
            cancel.check()?;
            if gated {
                self.eval_rows(tc, oc)?;
            } else {
                self.eval_serial(tc, oc)?;
            }
        }
        if gated {
            return self.check_drift_certified(t, out, cancel);
        }
        Ok(())
    }

    /// `l(t)` at one time.
    pub fn l(&self, t: f64) -> Result<[f64; 6]> {
        let mut out = [0.0; 6];
        self.l_batch(&[t], &mut out, &Cancel::never())?;
        Ok(out)
    }
}

/// The drift check's reason for refusing `l(t)` at `t`.
fn drift_reason(t: f64, defect: f64, drift: f64) -> String {
    format!(
        "at t = {t:e} the relative defect {defect:e} left by the self-check may \
         move l(t) by {drift:e} |l0| > {DRIFT_RTOL:e} (the drift \
         delta |t| |dl/dt| of the phase)"
    )
}

#[cfg(test)]
pub(crate) mod tests;
