//! The self-check of a genus-2 solution, and the choice of the signs of the
//! constants `C_L` that the initial state leaves undecided.
//!
//! A constant or branch of the set-up that is wrong reproduces `l0` at `t = 0`
//! and may reproduce `l̇(0)` too (a wrong sign of a `C_L` whose `P_L(l0)`
//! vanishes: the divisor of `l0` on a branch point, e.g. states with zero
//! components), while `l(t)` is O(1) wrong later. So every solution is checked
//! at points spread over its torus before it is returned (docs/degenerate.md).

use num_complex::Complex64;

use super::phase_mod2;
use crate::error::Result;
use crate::riemann::HyperellipticCurve;
use crate::so4;
use crate::theta::{ThetaJet, ThetaPlan};

type C = Complex64;

/// The estimate of a `C_L` at `v0` decides its sign when it agrees with one
/// of `±√(C_L²)` to this relative accuracy (decided estimates agree to
/// ~1e-14; an undecided one, `P_L(l0) θ(v0)/θ[χ_L](v0)` with both factors at
/// rounding level, is off by O(1)). A sign left undecided is taken from the
/// self-check ([`SelfCheck`]).
pub(super) const SIGN_DECIDED_RTOL: f64 = 1e-3;

/// Largest relative defect of the quotients' shape at the self-check points
/// ([`Defect::shape`]) that is accepted. Correct set-ups leave 1e-15 … 6e-12
/// (the four shared tops; 1000 random states with normal entries: median
/// 1.3e-14, max 6e-12, measured when the velocity part was held to the same
/// bound); a wrong sign of one constant leaves 1e-3 … 1. Near degenerate sets
/// (a harsh random draw, docs/degenerate.md) solutions whose error over their
/// window exceeds 1e-10 showed defects from 1e-13 to 1e-8, those within it up
/// to 5e-10; what no check at a few points can see, a drift of the phase, the
/// drift check bounds ([`drift_defect`], [`DRIFT_RTOL`]).
pub const SELF_CHECK_RTOL: f64 = 1e-10;

/// Largest defect of Frahm's equations (1) along `U` at the self-check
/// points, relative to the largest speed met there, that is accepted. Far
/// looser than [`SELF_CHECK_RTOL`]: near an equilibrium or an so(3) block the
/// motion is slow, and the velocity (1) of a state accurate to rounding is
/// itself only accurate to ~ε (max c − min c)|l|², 1e-9 relative to a speed of
/// 1e-7 of that scale, 1e-7 relative to one of 1e-9 (a harsh draw of 2000
/// states: defects up to 1e-7 on solutions accurate to 1e-15 over their
/// window). A wrong constant or sign leaves an O(1) defect; the drift a
/// moderate one could cause is what [`drift_defect`] and [`DRIFT_RTOL`]
/// bound. On the harsh draw of 10⁴ states (`tests/data/every_state_harsh.py`)
/// this bound instead of [`SELF_CHECK_RTOL`] took the self-check's refusals
/// from 420 to 149, none returned wrong.
pub const VELOCITY_CHECK_RTOL: f64 = 1e-6;

/// The relative defect `δ` whose drift `δ |t| |l̇(t)|` the solution bounds
/// ([`DRIFT_RTOL`]). Where `U` is the quotients' fit at `v0` it is the
/// self-check's larger part: a wrong `U` moves the phase, and quotients off
/// the level set of `l0` move on a neighbouring torus at its frequencies.
/// Where `U` is the closed form (the level set of `l0` in double-double, and
/// the quotients' equations at `v0` hold for it) it is the velocity part
/// alone: the phase then runs at the frequencies of `l0`'s own torus, so a
/// defect of the quotients' shape stays where it is, while a velocity defect
/// (the quotients' lattice, from the double periods, against the closed
/// form's) still drifts. On the harsh draw of 10⁴ states
/// (`tests/data/every_state_harsh.py`) dropping the shape part for the
/// closed form solved 32 more states, none wrong; dropping the velocity part
/// too would have returned 4 wrong ones (closed form, velocity defects 2e-10
/// … 1.5e-9, errors growing to 2.5e-10 … 8.9e-9 over their window).
pub(super) fn drift_defect(d: &Defect, closed: bool) -> f64 {
    if closed {
        d.velocity
    } else {
        d.worst()
    }
}

/// Largest first-order drift `δ |t| |l̇(t)| / |l0|` of `l(t)` that
/// [`super::Solution::l_batch`] returns without the certificate of an
/// integration of (1) ([`super::verify`]), `δ` the relative defect the
/// self-check leaves ([`drift_defect`]; before the self-check had two parts,
/// its single defect, to which the measurements below refer). A relative
/// error `δ` of `U` evaluates `l` at the phase of time `(1 + δ) t`; a defect `δ` of `l(0)` or of the
/// integrals puts `l(t)` on a neighbouring torus, whose frequencies differ by
/// `O(δ)`: either way an error `~δ t |l̇(t)|` that grows with `t` and peaks
/// where the motion is fast, which no check at a few points of the torus
/// sees. Near the pinched sets (two harsh random draws and the sweeps of
/// docs/degenerate.md) the error of the solutions wrong by more than 1e-10
/// against the long-double reference was 0.2 … 4.4 times this estimate (once
/// 43, at a fast passage where the estimate was 60 times this bound); half the
/// self-check's bound refuses every one of them above [`DRIFT_DEFECT_FLOOR`]
/// (a quarter would refuse half again as many correct ones).
pub const DRIFT_RTOL: f64 = SELF_CHECK_RTOL / 2.0;

/// Drift defects ([`drift_defect`]) up to this are taken as rounding, not as
/// a measure of the drift, and [`DRIFT_RTOL`] is not applied. A calibrated
/// gate, not a derived one: generic states leave 1e-15 … 6e-12 ('wide' has 3e-13 and
/// meets 1e-9 at `t = 1e4`, where `δ t |l̇|` would claim 4e-9); the solutions
/// of two harsh draws and the sweeps wrong by more than 1e-10 over their window
/// had defects from 1e-12 to 7e-11 — but one (seed 2) with 4e-13, which drifts
/// to 1.09e-10 unseen (its estimate: 1.08e-10). Above the gate correct
/// solutions are refused too where their estimate exceeds the bound (a random
/// Clebsch state with defect 2.1e-12, good to 1e-10 at `t = 48`, estimate
/// 1.03e-10): the price of refusing the wrong ones.
pub const DRIFT_DEFECT_FLOOR: f64 = 1e-12;

/// The relative rounding of the velocity `U` and of the phase `U t` (a few
/// ulp: U is accurate to ~1e-16 relative against long-double fits,
/// docs/theorem.md), the smallest drift rate the phase horizon assumes.
pub const PHASE_ROUNDING_RTOL: f64 = 4.0 * f64::EPSILON;

/// Beyond the time where `max(δ, PHASE_ROUNDING_RTOL) |t| |l̇|` exceeds this
/// fraction of `|l0|`, `l(t)` is refused whatever the self-check left: the
/// phase is not determined there (any integrator of (1) in double precision
/// has lost as much by then). Far beyond every use the tests make
/// (`t = 1e4 … 1e6` on O(1) tops leaves ≤ 1e-9), well before `|U t| ~ 1e16`
/// where the phase has no digit left.
pub const HORIZON_RTOL: f64 = 1e-6;

/// The refusal of `l(t)` at a time `t` beyond the phase horizon, where the
/// rounding of the phase rate (`rate`: "the velocity U", "the frequency")
/// alone may move it by `drift |l0|` > [`HORIZON_RTOL`].
pub(super) fn beyond_horizon(t: f64, drift: f64, rate: &str) -> crate::error::Error {
    crate::error::Error::Unverified {
        what: "l(t)",
        reason: format!(
            "t = {t:e} is beyond the phase horizon: the rounding of {rate} alone may move \
             l(t) by {drift:e} |l0| > {HORIZON_RTOL:e}; integrate from a state nearer \
             that time instead"
        ),
    }
}

/// Fractions of the shortest lattice period of the phase at which the
/// self-check evaluates the solution (besides `t = 0`): points spread over
/// the torus, none a simple fraction of a period.
const CHECK_PHASES: [f64; 3] = [0.29, 0.71, 1.37];

/// The self-check looks at most this many shortest periods of the phase away
/// from `t = 0`: far enough to see the torus when its two periods differ by
/// orders of magnitude, not so far that the rounding of `U` (~1e-14 relative,
/// growing linearly in `t`) is what it measures.
const SLOW_CHECK_CAP: f64 = 50.0;

/// `m.max(x)` with a NaN `x` taken as an infinite defect (`f64::max` would
/// drop it).
fn max_defect(m: f64, x: f64) -> f64 {
    if x.is_nan() {
        f64::INFINITY
    } else {
        m.max(x)
    }
}

/// The self-check's relative defects ([`SelfCheck::defect`]), in two parts.
#[derive(Debug, Clone, Copy)]
pub(super) struct Defect {
    /// Where the quotients are: `l(0) = l0`, a real `l`, the integrals.
    pub(super) shape: f64,
    /// How they move: Frahm's (1) along `U`, relative to the largest speed.
    pub(super) velocity: f64,
}

impl Defect {
    /// The larger part (the `δ` of the drift estimate).
    pub(super) fn worst(&self) -> f64 {
        self.shape.max(self.velocity)
    }

    /// The larger part relative to its bound: the sign pattern of the
    /// constants with the smallest is the one checked ([`SELF_CHECK_RTOL`] and
    /// [`VELOCITY_CHECK_RTOL`] differ 1e4-fold, so the raw parts do not compare).
    pub(super) fn rank(&self) -> f64 {
        (self.shape / SELF_CHECK_RTOL).max(self.velocity / VELOCITY_CHECK_RTOL)
    }
}

/// What one sign pattern of the constants `C_L` makes of the solution: the
/// quotients (9)–(10) and `U`.
pub(super) struct Built {
    pub(super) cl: [C; 7],
    pub(super) num: [[C; 8]; 6],
    pub(super) den: [C; 8],
    pub(super) rate: [C; 2],
    /// Whether `rate` is the closed form's (else the quotients' fit: the
    /// closed form refused, or disagreed with the quotients' equations).
    pub(super) closed: bool,
}

/// The sign patterns to try: the signs decided at `v0` with every
/// combination of flips of the undecided ones (`calibration` above
/// [`SIGN_DECIDED_RTOL`]); in practice 1, 2 or 4 patterns.
pub(super) fn sign_patterns(cl: &[C; 7], calibration: &[f64; 7]) -> Vec<[C; 7]> {
    let undecided: Vec<usize> = (0..7)
        .filter(|&m| calibration[m].is_nan() || calibration[m] > SIGN_DECIDED_RTOL)
        .collect();
    (0..(1u32 << undecided.len()))
        .map(|mask| {
            let mut c = *cl;
            for (bit, &m) in undecided.iter().enumerate() {
                if (mask >> bit) & 1 == 1 {
                    c[m] = -c[m];
                }
            }
            c
        })
        .collect()
}

/// The self-check of a solution before it is returned: at `t = 0` and at a
/// few points of the torus ([`CHECK_PHASES`]) the quotients (9)–(10) must
/// give a real state on the level set of `l0` (the integrals (6)–(7)) whose
/// velocity along `U` is Frahm's (1), and `l(0) = l0`. A constant or branch
/// of the set-up that is wrong shows at once; the velocity fit at `v0` alone
/// does not see every such error (a wrong sign of a `C_L` whose `P_L(l0)`
/// vanishes reproduces `l0` and `l̇(0)`).
pub(super) struct SelfCheck {
    a: [f64; 4],
    l0: [f64; 6],
    c4: [f64; 6],
    h: [f64; 4],
    /// `|l0|`, the scale of `l`.
    size: f64,
    /// The scale of `l̇`: `(max c − min c) |l0|²` bounds `|l̇|` up to a factor
    /// (adding a constant to every `c_ij` does not change (1)).
    rate_scale: f64,
    /// Scales of `h0 … h3`.
    h_scale: [f64; 4],
}

impl SelfCheck {
    pub(super) fn new(a: &[f64; 4], l0: &[f64; 6], c4: &[f64; 6]) -> Self {
        let size = l0.iter().map(|x| x * x).sum::<f64>().sqrt();
        let (cmin, cmax) = c4
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        let amax = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let s2 = size * size;
        SelfCheck {
            a: *a,
            l0: *l0,
            c4: *c4,
            h: so4::integrals4(a, l0),
            size,
            rate_scale: (cmax - cmin) * s2,
            h_scale: [s2, s2, 2.0 * amax * s2, amax * amax * s2],
        }
    }

    /// The largest relative defects over the check points (0 is perfect; NaN
    /// counts as infinite), in two parts ([`Defect`]): the shape,
    /// `|l(0) − l0|/|l0|`, `|Im l|/|l0|`, `|Im dl/dt|` relative to
    /// [`SelfCheck::rate_scale`] and the integrals (6)–(7) of `Re l` against
    /// those of `l0`; the velocity, `|dl/dt − (1)|` relative to the largest
    /// speed met, with `dl/dt = (∇N − l ∇D)·U / D` from the theta jet (`jet0`
    /// that at `v0`, of order 1).
    pub(super) fn defect(
        &self,
        plan: &ThetaPlan,
        curve: &HyperellipticCurve,
        idx: &[usize; 8],
        b: &Built,
        v0: &[C; 2],
        jet0: &ThetaJet,
    ) -> Result<Defect> {
        // Lattice coordinates of v0 and U: the check points are taken modulo
        // twice the lattice (as l(t) is), at times that are fractions of the
        // shortest and of the longest lattice period of the motion, so that they
        // spread over the torus also when its two periods differ by orders of
        // magnitude (near degenerate sets).
        let (x0, y0) = curve.lattice_coordinates(v0);
        let (xr, yr) = curve.lattice_coordinates(&b.rate);
        let rates: Vec<f64> = xr.iter().chain(yr.iter()).map(|v| v.abs()).collect();
        let fastest = rates.iter().fold(0.0f64, |m, &v| m.max(v));
        let slowest = rates
            .iter()
            .filter(|&&v| v > 1e-12 * fastest)
            .fold(f64::INFINITY, |m, &v| m.min(v));
        let p_fast = if fastest > 0.0 { 2.0 / fastest } else { 1.0 };
        let p_slow = if slowest.is_finite() {
            2.0 / slowest
        } else {
            p_fast
        };
        let mut times: Vec<f64> = vec![0.0];
        times.extend(CHECK_PHASES.iter().map(|c| c * p_fast));
        // The slow period up to SLOW_CHECK_CAP fast periods: the check is of the
        // quotient's shape, not of the drift of the phase over long times.
        let p_slow = p_slow.min(SLOW_CHECK_CAP * p_fast);
        if p_slow > 2.0 * p_fast {
            times.extend(CHECK_PHASES.iter().map(|c| c * p_slow));
        }
        let tau = curve.tau_row_major();
        let at = |t: f64| -> [C; 2] {
            let ph = |a: f64, r: f64| phase_mod2(a, r, 0.0, t);
            let x = [ph(x0[0], xr[0]), ph(x0[1], xr[1])];
            let y = [ph(y0[0], yr[0]), ph(y0[1], yr[1])];
            [
                C::new(x[0], 0.0) + tau[0] * y[0] + tau[1] * y[1],
                C::new(x[1], 0.0) + tau[2] * y[0] + tau[3] * y[1],
            ]
        };
        // The velocity defect is relative to the largest speed |(1)| met at the
        // check points, not to the scale (max c − min c)|l|²: near an equilibrium
        // the motion is slow, and a defect small against that scale would be a
        // large relative error of the velocity, hence of the phase.
        let (mut ode_res, mut speed) = (0.0f64, 0.0f64);
        let mut worst = 0.0f64;
        let mut note = |x: f64| worst = max_defect(worst, x);
        for (k, &t) in times.iter().enumerate() {
            // the set-up's own jet at v0 for t = 0
            let owned;
            let jet = if k == 0 {
                jet0
            } else {
                owned = plan.jet(&at(t), 1)?;
                &owned
            };
            let theta = |m: usize| jet.values[idx[m]];
            let grad = |m: usize, k: usize| jet.gradient[idx[m] * 2 + k];
            let d: C = (0..8).map(|m| b.den[m] * theta(m)).sum();
            let dg: [C; 2] = std::array::from_fn(|k| (0..8).map(|m| b.den[m] * grad(m, k)).sum());
            let mut l = [0.0; 6];
            let mut ldot = [0.0; 6];
            for q in 0..6 {
                let n: C = (0..8).map(|m| b.num[q][m] * theta(m)).sum();
                let ng: [C; 2] =
                    std::array::from_fn(|k| (0..8).map(|m| b.num[q][m] * grad(m, k)).sum());
                let lq = n / d;
                let dq = ((ng[0] - lq * dg[0]) * b.rate[0] + (ng[1] - lq * dg[1]) * b.rate[1]) / d;
                l[q] = lq.re;
                ldot[q] = dq.re;
                note(lq.im.abs() / self.size);
                note(dq.im.abs() / self.rate_scale);
            }
            let f = so4::vector_field4(&self.c4, &l);
            for q in 0..6 {
                ode_res = max_defect(ode_res, (ldot[q] - f[q]).abs());
                speed = speed.max(f[q].abs());
                if k == 0 {
                    note((l[q] - self.l0[q]).abs() / self.size);
                }
            }
            let h = so4::integrals4(&self.a, &l);
            for ((hi, h0i), sc) in h.iter().zip(&self.h).zip(&self.h_scale) {
                note((hi - h0i).abs() / sc);
            }
        }
        let velocity = ode_res / speed.max(1e-30 * self.rate_scale);
        Ok(Defect {
            shape: worst,
            velocity: max_defect(0.0, velocity),
        })
    }
}
