//! The one entry point: a state of a Manakov top, normalized
//! ([`super::normalize`]), classified, and solved by the representation that
//! holds on its set (docs/degenerate.md §4):
//!
//! | kind | set (exact) | solution |
//! |---|---|---|
//! | [`Kind::Rest`] | `l0 = 0` | `l(t) = 0` |
//! | [`Kind::Spherical`] | all `c_ij` equal (to their rounding) | `l(t) = l0` |
//! | [`Kind::Equilibrium`] | `l̇ = 0` by (1) ([`super::constant`]) | `l(t) = l0` |
//! | [`Kind::Euler`] | an so(3) block or `n = ±m`, exactly | Jacobi elliptic functions ([`super::euler`]) |
//! | [`Kind::Separatrix`] | the same, with `Δ = 0` | `tanh`, `sech` |
//! | [`Kind::Genus2`] | every other state | the Theorem (9)–(10) ([`Solution`]) |
//! | [`Kind::Integrated`] | a genus-2 state whose closed form cannot be built | an integration of (1) in double-double, confirmed by one with every step halved |
//!
//! The sets are tested exactly (components compared as doubles; the
//! equilibrium and spherical tests at the rounding of their defining
//! equations): a state *near* a set is a genus-2 state.
//!
//! Frames: the classification and the solution work on the normalized data
//! `a' = (a − κ)/σ`, `c' = (c − μ)/λ`, `l0' = l0/s`; then
//! `l(t) = s l'(T t)` with `T = s λ` (powers of two: exact). A [`Solution`]
//! inside keeps its attributes (`τ`, `U`, `u0`, …) in the normalized frame.

use std::sync::Arc;

use super::constant::is_equilibrium;
use super::euler::{Embedding, EulerRegime, EulerTop};
use super::normalize::{state_scale, TopFrame};
use super::{rows_in_parallel, Solution, HORIZON_RTOL, PHASE_ROUNDING_RTOL};
use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;

/// What kind of motion a state has (see the module table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// The genus-2 theta-function solution of the Theorem (9)–(10).
    Genus2,
    /// `l0 = 0`.
    Rest,
    /// All `c_ij` equal (`b = α a + β`): every state is at rest.
    Spherical,
    /// A stationary rotation: `l̇ = 0` by (1).
    Equilibrium,
    /// An Euler top in an so(3) block or a (anti-)self-dual state.
    Euler,
    /// The same on the separatrix of the Euler top (`m = 1`).
    Separatrix,
    /// A genus-2 state whose closed form could not be built (a step of the
    /// reduction refused it): `l(t)` by an integration of (1) in
    /// double-double, confirmed by one with every step halved ([`verify`]), at every call.
    /// Never a class of [`classify`]: the motion's body decides it.
    ///
    /// [`verify`]: super::verify
    Integrated,
}

impl Kind {
    /// All kinds, in the order of their codes.
    pub const ALL: [Kind; 7] = [
        Kind::Genus2,
        Kind::Rest,
        Kind::Spherical,
        Kind::Equilibrium,
        Kind::Euler,
        Kind::Separatrix,
        Kind::Integrated,
    ];

    /// The name the Python API uses.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Genus2 => "genus2",
            Kind::Rest => "rest",
            Kind::Spherical => "spherical",
            Kind::Equilibrium => "equilibrium",
            Kind::Euler => "euler",
            Kind::Separatrix => "separatrix",
            Kind::Integrated => "integrated",
        }
    }

    /// Whether `l(t) = l0` for all `t`.
    pub fn is_constant(self) -> bool {
        matches!(self, Kind::Rest | Kind::Spherical | Kind::Equilibrium)
    }
}

#[derive(Debug)]
enum Body {
    Constant,
    Euler {
        emb: Embedding,
        top: Box<EulerTop>,
    },
    Genus2(Arc<Solution>),
    /// The step that refused the closed form, and the count of `l(t)` calls
    /// that integrated.
    Integrated {
        step: String,
        calls: std::sync::atomic::AtomicU64,
    },
}

/// A solved state of a Manakov top, of any [`Kind`].
#[derive(Debug)]
pub struct Motion {
    kind: Kind,
    frame: TopFrame,
    /// `s`: `l0' = l0/s`.
    scale: f64,
    /// `T = s λ`: `t' = T t`.
    time_scale: f64,
    l0: [f64; 6],
    body: Body,
}

/// A closed form that could not be built for a state already checked to be
/// valid (finite, on a valid top, with a representable time scale): a refusal
/// of this state ([`Error::Unverified`], Python's `ClosedFormError`), not
/// invalid input — whatever the step that failed reported (a singular
/// coordinate of the reduction, an iteration that did not converge). The step
/// and its numbers stay in the message; cancellation and size errors pass.
fn refusal(e: Error) -> Error {
    refusal_of("closed form for this l0", "integrate it instead", e)
}

/// [`Error::Unverified`] for `what` of a valid state, the failed step and
/// its numbers in the message, then `advice`; cancellation and size errors
/// pass (the closed form's refusals here, the torus's in `tori::motion`).
pub(crate) fn refusal_of(what: &'static str, advice: &str, e: Error) -> Error {
    match failed_step(e) {
        Ok(step) => Error::Unverified {
            what,
            reason: format!("{step}; the state is valid: {advice}"),
        },
        Err(e) => e,
    }
}

/// The step that failed, in words (`what: reason`), of an error of a valid
/// state's closed form; a refusal (`Unverified`, which words its own step)
/// and cancellation and size errors are returned as they are.
fn failed_step(e: Error) -> std::result::Result<String, Error> {
    match e {
        Error::Unverified { .. }
        | Error::Interrupted
        | Error::TooLarge { .. }
        | Error::OutOfMemory { .. } => Err(e),
        Error::Singular { what, reason, .. } | Error::InvalidArgument { what, reason } => {
            Ok(format!("{what}: {reason}"))
        }
        other => Ok(other.to_string()),
    }
}

/// The end of the reason of a [`Kind::Integrated`] motion.
const INTEGRATED: &str = "its l(t) is an integration of (1) in double-double, confirmed by \
                          one with every step halved, at every call";

/// Times per cancellation check in the closed forms (~1 ms).
const CHUNK: usize = 16384;

/// Smallest piece handed to one thread by the closed forms.
const PAR_PIECE: usize = 4096;

impl Motion {
    /// Normalizes, classifies and solves the state `l0` of the top `(a, b)`.
    ///
    /// Errors: invalid `a`, `b` or `l0` (non-finite, repeated `a_i`), the
    /// only ones on the input. A valid genus-2 state whose closed form cannot
    /// be built is of kind [`Kind::Integrated`], the step that refused it in
    /// [`Motion::stand_ins`]; one whose closed form fails a check is kept for
    /// certified `l(t)` ([`Solution::with_c4_lo_certifying`]). An Euler state
    /// whose closed form cannot be built gets [`Error::Unverified`] naming the
    /// step.
    pub fn new(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> Result<Self> {
        crate::error::check_finite("l0", l0)?;
        let frame = TopFrame::new(a, b)?;
        Self::in_frame(frame, l0)
    }

    /// [`Motion::new`] for a top whose frame is already built (frequency maps
    /// build it once per top).
    pub fn in_frame(frame: TopFrame, l0: &[f64; 6]) -> Result<Self> {
        crate::error::check_finite("l0", l0)?;
        let (kind, scale, ln) = classify(&frame, l0);
        let time_scale = scale * frame.lambda;
        if !time_scale.is_finite() || time_scale == 0.0 {
            return Err(Error::InvalidArgument {
                what: "l0",
                reason: format!(
                    "the time scale |l0| x spread(c) = {scale:e} x {:e} is not representable",
                    frame.lambda
                ),
            });
        }
        let body = match kind {
            Kind::Rest | Kind::Spherical | Kind::Equilibrium => Body::Constant,
            Kind::Euler | Kind::Separatrix => {
                let emb = Embedding::of_state(&ln)
                    .ok_or(Error::InvalidArgument {
                        what: "l0",
                        reason: "classified as an Euler top but in no invariant subspace".into(),
                    })
                    .map_err(refusal)?;
                let top = EulerTop::new(emb.w_of(&frame.c4), emb.m_of(&ln)).map_err(refusal)?;
                Body::Euler {
                    emb,
                    top: Box::new(top),
                }
            }
            Kind::Genus2 | Kind::Integrated => {
                match Solution::with_c4_lo_certifying(&frame.a, &frame.c4, &frame.c4_lo, &ln) {
                    Ok(s) => Body::Genus2(Arc::new(s)),
                    // The closed form cannot be built: the motion is the
                    // integration's (cancellation and size errors pass).
                    Err(e) => {
                        let step = match failed_step(e) {
                            Ok(step) => step,
                            // a refusal of the solution itself
                            Err(Error::Unverified { what, reason }) => format!("{what}: {reason}"),
                            // cancellation and size errors pass
                            Err(other) => return Err(other),
                        };
                        Body::Integrated {
                            step,
                            calls: std::sync::atomic::AtomicU64::new(0),
                        }
                    }
                }
            }
        };
        let kind = match body {
            Body::Integrated { .. } => Kind::Integrated,
            _ => kind,
        };
        Ok(Motion {
            kind,
            frame,
            scale,
            time_scale,
            l0: *l0,
            body,
        })
    }

    /// The kind of motion.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// The user's `l0`.
    pub fn l0(&self) -> &[f64; 6] {
        &self.l0
    }

    /// The normalized top.
    pub fn frame(&self) -> &TopFrame {
        &self.frame
    }

    /// `s` of `l0' = l0/s` (a power of two).
    pub fn state_scale(&self) -> f64 {
        self.scale
    }

    /// `T` of `t' = T t` (a power of two).
    pub fn time_scale(&self) -> f64 {
        self.time_scale
    }

    /// The genus-2 solution in the normalized frame (kind [`Kind::Genus2`]).
    pub fn genus2(&self) -> Option<&Solution> {
        match &self.body {
            Body::Genus2(s) => Some(s),
            _ => None,
        }
    }

    /// The genus-2 solution, shared (for bindings that hand it out).
    pub fn genus2_shared(&self) -> Option<Arc<Solution>> {
        match &self.body {
            Body::Genus2(s) => Some(Arc::clone(s)),
            _ => None,
        }
    }

    /// The Euler top in the normalized frame and its embedding (kinds
    /// [`Kind::Euler`], [`Kind::Separatrix`]).
    pub fn euler(&self) -> Option<(&Embedding, &EulerTop)> {
        match &self.body {
            Body::Euler { emb, top } => Some((emb, top)),
            _ => None,
        }
    }

    /// The frequency of the closed forms in the user's time: the Euler
    /// frequency `ν_E = ω/(4K)` (0 on the separatrix), 0 for the constant
    /// kinds; `None` for the genus-2 kind (its two frequencies are the real
    /// torus's, in [`crate::tori`]).
    pub fn closed_form_frequency(&self) -> Option<f64> {
        match &self.body {
            Body::Constant => Some(0.0),
            Body::Euler { top, .. } => Some(top.frequency() * self.time_scale),
            Body::Genus2(_) | Body::Integrated { .. } => None,
        }
    }

    /// The count of [`Motion::stand_ins`] alone (cheap: no message is
    /// formatted).
    pub fn stand_in_calls(&self) -> u64 {
        match &self.body {
            Body::Integrated { calls, .. } => calls.load(std::sync::atomic::Ordering::Relaxed),
            Body::Genus2(sol) => sol.stand_in_calls(),
            _ => 0,
        }
    }

    /// `(calls, why)`: how many `l(t)` calls returned values of an
    /// integration of (1) (all of them for [`Kind::Integrated`]; those where
    /// it stood in for the closed form for [`Kind::Genus2`],
    /// [`Solution::stand_ins`]) and why the last one did; `(0, "")` for the
    /// other kinds.
    pub fn stand_ins(&self) -> (u64, String) {
        match &self.body {
            Body::Integrated { step, .. } => (
                self.stand_in_calls(),
                format!("{step}; the state is valid: {INTEGRATED}"),
            ),
            Body::Genus2(sol) => sol.stand_ins(),
            _ => (0, String::new()),
        }
    }

    /// `l(t_k)` of a [`Kind::Integrated`] motion: per direction of time, one
    /// confirmed integration in double-double over the requested times (in
    /// the normalized frame).
    fn integrated_rows(
        &self,
        step: &str,
        t: &[f64],
        out: &mut [f64],
        cancel: &Cancel,
    ) -> Result<()> {
        let ln = self.l0.map(|v| v / self.scale);
        let size = ln.iter().map(|x| x * x).sum::<f64>().sqrt();
        let ts: Vec<f64> = t.iter().map(|&x| self.time_scale * x).collect();
        crate::error::check_finite("t x time scale", &ts)?;
        for (o, &tk) in out.chunks_exact_mut(6).zip(&ts) {
            if tk == 0.0 {
                o.copy_from_slice(&self.l0);
            }
        }
        for sign in [1.0, -1.0] {
            let mut s: Vec<f64> = ts
                .iter()
                .filter(|&&x| x * sign > 0.0)
                .map(|x| x.abs())
                .collect();
            if s.is_empty() {
                continue;
            }
            s.sort_by(f64::total_cmp);
            s.dedup();
            super::verify::integrate_confirmed(
                &self.frame.c4,
                &self.frame.c4_lo,
                &ln,
                size,
                sign,
                s,
                cancel,
            )?
            .map_err(|e| Error::Unverified {
                what: "l(t)",
                reason: format!(
                    "{step}; the state is valid, but no integration of (1) in double-double \
                     confirms itself: {e}"
                ),
            })?
            .rows(&ts, sign, out);
        }
        if self.scale != 1.0 {
            // the integrated rows into the user's frame (those at t = 0 are l0)
            for (o, &tk) in out.chunks_exact_mut(6).zip(&ts) {
                if tk != 0.0 {
                    o.iter_mut().for_each(|v| *v *= self.scale);
                }
            }
        }
        // A call that integrated (not one at t = 0 alone, or of no times).
        if let (Body::Integrated { calls, .. }, true) = (&self.body, ts.iter().any(|&x| x != 0.0)) {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        Ok(())
    }

    /// The rows `l(t_k)` of one block of times: the closed forms of the
    /// constant and Euler kinds directly, the genus-2 kind through its
    /// solution's batch (which splits over threads itself).
    fn rows(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        match &self.body {
            Body::Constant => {
                for o in out.chunks_exact_mut(6) {
                    o.copy_from_slice(&self.l0);
                }
                Ok(())
            }
            Body::Euler { emb, top } => {
                // The phase horizon of the genus-2 kind ([`HORIZON_RTOL`]),
                // with the Euler top's own rate: a rounding of its frequency
                // by PHASE_ROUNDING_RTOL moves M(t) by ~that times 2π ν |t|
                // of its size. (ν = 0: at rest or on the separatrix, where
                // M(t) tends to its limit and every t is determined.)
                let nu = top.frequency() * self.time_scale;
                let t_max = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let drift = PHASE_ROUNDING_RTOL * std::f64::consts::TAU * nu * t_max;
                if drift > HORIZON_RTOL {
                    return Err(super::check::beyond_horizon(t_max, drift, "the frequency"));
                }
                for (o, &tk) in out.chunks_exact_mut(6).zip(t) {
                    let l = emb.state(&top.m(self.time_scale * tk));
                    for q in 0..6 {
                        o[q] = self.scale * l[q];
                    }
                }
                Ok(())
            }
            Body::Integrated { step, .. } => self.integrated_rows(step, t, out, cancel),
            Body::Genus2(sol) => {
                if self.time_scale == 1.0 && self.scale == 1.0 {
                    // The generic path, unchanged.
                    return sol.l_batch(t, out, cancel);
                }
                // In the normalized frame: the solution's own batch (parallel,
                // with a certifying integration, where the drift check needs
                // one, run once over all the times and interruptible).
                self.in_normalized_frame(t, out, |ts, o| sol.l_batch(ts, o, cancel))
            }
        }
    }

    /// `eval` at the times `T t` of the normalized frame, its rows taken back
    /// to the user's frame (`s l`; both scales powers of two: exact).
    fn in_normalized_frame(
        &self,
        t: &[f64],
        out: &mut [f64],
        eval: impl FnOnce(&[f64], &mut [f64]) -> Result<()>,
    ) -> Result<()> {
        let ts: Vec<f64> = t.iter().map(|&x| self.time_scale * x).collect();
        crate::error::check_finite("t x time scale", &ts)?;
        eval(&ts, out).map_err(|e| match e {
            // a refusal names the solution's times; say whose they are
            Error::Unverified { what, reason } if self.time_scale != 1.0 => Error::Unverified {
                what,
                reason: format!(
                    "{reason} (times in the normalized frame, T t with T = time_scale = {:e})",
                    self.time_scale
                ),
            },
            other => other,
        })?;
        if self.scale != 1.0 {
            out.iter_mut().for_each(|v| *v *= self.scale);
        }
        Ok(())
    }

    /// `l(t_k)` of the Theorem with its constants polished and evaluated in
    /// double-double ([`super::precise`]), in the user's frame: a genus-2
    /// motion's; a constant one's is `l0` itself.
    ///
    /// Errors: those of [`Solution::precise`]; [`Error::Unverified`] for the
    /// kinds with no precise evaluation (Euler and integrated motions).
    pub fn l_precise_batch(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        super::check_rows(t, out)?;
        match &self.body {
            Body::Constant => {
                for o in out.chunks_exact_mut(6) {
                    o.copy_from_slice(&self.l0);
                }
                Ok(())
            }
            Body::Genus2(sol) => {
                self.in_normalized_frame(t, out, |ts, o| sol.l_precise_batch(ts, o, cancel))
            }
            _ => Err(Error::Unverified {
                what: "precise l(t)",
                reason: format!(
                    "a motion of kind '{}' has no precise evaluation (the genus-2 and \
                     constant kinds have)",
                    self.kind().name()
                ),
            }),
        }
    }

    /// `l(t_k)` into `out` (row-major `(N, 6)`), in the user's frame; rayon
    /// for large batches, `cancel` checked between chunks.
    ///
    /// Errors: non-finite `t` (or `T t`), wrong `out` size, [`Error::Interrupted`].
    pub fn l_batch(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        super::check_rows(t, out)?;
        if let Body::Genus2(_) | Body::Integrated { .. } = &self.body {
            // Their own batches: the genus-2 one splits over threads itself,
            // the integration runs once from 0 over all the times.
            return self.rows(t, out, cancel);
        }
        rows_in_parallel(t, out, cancel, CHUNK, PAR_PIECE, |tp, op| {
            self.rows(tp, op, cancel)
        })
    }

    /// `l(t)` at one time.
    pub fn l(&self, t: f64) -> Result<[f64; 6]> {
        let mut out = [0.0; 6];
        self.l_batch(&[t], &mut out, &Cancel::never())?;
        Ok(out)
    }
}

/// The kind of the state `l0` on the normalized top `frame`, with the scale
/// `s` and the normalized state `l0/s`. Cheap (tens of nanoseconds): exact
/// comparisons and one evaluation of (1).
pub fn classify(frame: &TopFrame, l0: &[f64; 6]) -> (Kind, f64, [f64; 6]) {
    if l0.iter().all(|v| *v == 0.0) {
        return (Kind::Rest, 1.0, *l0);
    }
    let s = state_scale(l0);
    let ln = if s == 1.0 { *l0 } else { l0.map(|v| v / s) };
    if frame.spherical {
        return (Kind::Spherical, s, ln);
    }
    if is_equilibrium(&frame.c4, &ln) {
        return (Kind::Equilibrium, s, ln);
    }
    let kind = match Embedding::of_state(&ln) {
        None => Kind::Genus2,
        Some(emb) => {
            if euler_regime(frame, emb, &ln) == Some(EulerRegime::Separatrix) {
                Kind::Separatrix
            } else {
                Kind::Euler
            }
        }
    };
    (kind, s, ln)
}

fn euler_regime(frame: &TopFrame, emb: Embedding, l: &[f64; 6]) -> Option<EulerRegime> {
    EulerTop::new(emb.w_of(&frame.c4), emb.m_of(l))
        .ok()
        .map(|t| t.regime())
}

#[cfg(test)]
mod tests;
