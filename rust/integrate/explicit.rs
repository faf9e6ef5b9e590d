//! What the explicit adaptive methods (dopri5, dop853, and their batch
//! kernels) share: the error norm's scaled components, the starting step
//! (HNW I, II.4), the attempt loop's checks (cancellation, step-size
//! underflow) and the step budget.

use super::{Cancel, VectorField};
use crate::error::{Error, Result};
use crate::numeric::cancel::CHECK_EVERY;
use crate::numeric::tol::min_step;

/// `x / sc` in the error norms, with `0 / 0 = 0`: with `atol = 0` a component that is
/// exactly zero has scale 0, and it contributes nothing to the norm.
#[inline(always)]
pub(super) fn scaled(x: f64, sc: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x / sc
    }
}

/// Starting step (HNW I, II.4, first part) from `d0 = ‖y‖` and `d1 = ‖f(y)‖` in the
/// error norm with scale `atol + rtol |y_i|`: `0.01 d0/d1`, or `1e-6` when either is
/// tiny — and also when `d1` overflowed (a component with zero scale and nonzero
/// derivative, or a tiny `atol`), where the formula would give 0; the step controller
/// adapts from there.
pub(super) fn starting_step(y: &[f64], f0: &[f64], atol: f64, rtol: f64) -> f64 {
    let m = y.len().max(1) as f64;
    let (mut d0, mut d1) = (0.0f64, 0.0f64);
    for (&yi, &fi) in y.iter().zip(f0) {
        let sc = atol + rtol * yi.abs();
        d0 += scaled(yi, sc).powi(2);
        d1 += scaled(fi, sc).powi(2);
    }
    let (d0, d1) = ((d0 / m).sqrt(), (d1 / m).sqrt());
    let h = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    if h.is_finite() && h > 0.0 {
        h
    } else {
        1e-6
    }
}

/// The error of an explicit method that needs more than its step budget.
pub(super) fn too_many_steps(budget: u64) -> Error {
    Error::InvalidArgument {
        what: "rtol/atol",
        reason: format!(
            "more steps needed than the remaining budget of {budget} (max_steps); \
             loosen rtol/atol, shorten t_end or raise max_steps"
        ),
    }
}

/// The next step attempt of an explicit method from `t` toward `t_target`,
/// given the controller's step `h_ctl`: `(h, last)`, the step cut to land on
/// `t_target` when it would pass it. Checks `cancel` every [`CHECK_EVERY`]
/// attempts (counted in `attempts`) and refuses a step below
/// [`min_step`] that is not the last one (`what` names the method's
/// underflow; `rtol` and `steps` go into the error).
#[inline(always)]
pub(super) fn next_attempt(
    what: &'static str,
    h_ctl: f64,
    t: f64,
    t_target: f64,
    (rtol, steps): (f64, u64),
    attempts: &mut u32,
    cancel: &Cancel,
) -> Result<(f64, bool)> {
    let remaining = t_target - t;
    let last = h_ctl >= remaining;
    let h = if last { remaining } else { h_ctl };
    *attempts = attempts.wrapping_add(1);
    if *attempts % CHECK_EVERY == 0 {
        cancel.check()?;
    }
    if h <= min_step(t) && !last {
        return Err(Error::NoConvergence {
            what,
            tol: rtol,
            reached: h,
            iterations: steps as usize,
        });
    }
    Ok((h, last))
}

/// Refuses a non-finite error norm `err` (the state overflowed or became
/// NaN): `what` names the method.
#[inline(always)]
pub(super) fn check_error_norm(what: &'static str, err: f64, rtol: f64, steps: u64) -> Result<()> {
    if !err.is_finite() {
        return Err(Error::NoConvergence {
            what,
            tol: rtol,
            reached: err,
            iterations: steps as usize,
        });
    }
    Ok(())
}

/// What an explicit stepper carries between calls: the step size its
/// controller proposes, the slot `k1 = f(y)` (valid between calls, FSAL), the
/// evaluation count and the tolerances.
pub(super) struct Control {
    pub(super) m: usize,
    pub(super) h: f64,
    pub(super) k1_valid: bool,
    pub(super) evals: u64,
    pub(super) rtol: f64,
    pub(super) atol: f64,
}

impl Control {
    pub(super) fn new(m: usize, h0: f64, rtol: f64, atol: f64) -> Self {
        Control {
            m,
            h: h0,
            k1_valid: false,
            evals: 0,
            rtol,
            atol,
        }
    }
}

/// An explicit adaptive stepper (dopri5, dop853) with its scratch space: the
/// method-specific parts of [`Explicit::advance`].
pub(super) trait Explicit {
    /// The errors' names of a step-size underflow and of a non-finite state.
    const UNDERFLOW: &'static str;
    const NON_FINITE: &'static str;

    fn ctl(&self) -> &Control;
    fn ctl_mut(&mut self) -> &mut Control;
    /// The stage slot `k1` (length `m`), which holds `f(y)`.
    fn k1(&mut self) -> &mut [f64];

    /// Computes the stages of a step of size `h` from `y` and the candidate
    /// new state; returns the error norm of the step.
    fn attempt<F: VectorField>(&mut self, f: &F, y: &[f64], h: f64) -> f64;

    /// Takes the candidate as the new state `y` (and `k1 = f(y)` with it).
    fn accept<F: VectorField>(&mut self, f: &F, y: &mut [f64]);

    /// The controller's next step after an attempt of size `h` with error
    /// `err` (`accepted` when `err ≤ 1`; `last` when `h` was cut to the target).
    fn next_h(&self, h: f64, err: f64, last: bool, accepted: bool) -> f64;

    /// The vector-field evaluations so far.
    fn evals(&self) -> u64 {
        self.ctl().evals
    }

    /// Advances `y` from `t` to exactly `t_target` with adaptive steps;
    /// returns the number of accepted steps, failing once more than `budget`
    /// are needed.
    fn advance<F: VectorField>(
        &mut self,
        f: &F,
        y: &mut [f64],
        t: &mut f64,
        t_target: f64,
        budget: u64,
        cancel: &Cancel,
    ) -> Result<u64> {
        let mut steps = 0u64;
        let mut attempts = 0u32;
        if !self.ctl().k1_valid {
            f.eval(y, self.k1());
            let c = self.ctl_mut();
            c.evals += 1;
            c.k1_valid = true;
        }
        if self.ctl().h == 0.0 {
            let (atol, rtol) = (self.ctl().atol, self.ctl().rtol);
            let h = starting_step(y, self.k1(), atol, rtol);
            self.ctl_mut().h = h;
        }
        while *t < t_target {
            let rtol = self.ctl().rtol;
            let (h, last) = next_attempt(
                Self::UNDERFLOW,
                self.ctl().h,
                *t,
                t_target,
                (rtol, steps),
                &mut attempts,
                cancel,
            )?;
            let err = self.attempt(f, y, h);
            check_error_norm(Self::NON_FINITE, err, rtol, steps)?;
            let accepted = err <= 1.0;
            if accepted {
                self.accept(f, y);
                *t = if last { t_target } else { *t + h };
                steps += 1;
            }
            self.ctl_mut().h = self.next_h(h, err, last, accepted);
            if steps > budget {
                return Err(too_many_steps(budget));
            }
        }
        Ok(steps)
    }
}
