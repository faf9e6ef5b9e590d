//! The methods, the options and their checks, the sampled trajectory, and the
//! step budget checked before any work.

use super::gauss_tables;
use super::taylor;
use crate::error::{check_finite, Error, Result};

/// An integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Method {
    /// 2-stage Gauss–Legendre collocation, order 4.
    Gauss4,
    /// 3-stage Gauss–Legendre collocation, order 6.
    Gauss6,
    /// 8-stage Gauss–Legendre collocation, order 16 (IRKGL16).
    Gauss16,
    /// Dormand–Prince 5(4), explicit, adaptive.
    Dopri5,
    /// Dormand–Prince 8(5,3) (DOP853), explicit, adaptive.
    Dop853,
    /// Taylor's method of order `⌈−ln rtol / 2 + 1⌉` with Jorba–Zou step
    /// control (so(4) only; see [`taylor`]).
    Taylor,
}

impl Method {
    /// All method names, as accepted by [`Method::from_name`].
    pub const NAMES: [&'static str; 6] =
        ["gauss4", "gauss6", "gauss16", "dopri5", "dop853", "taylor"];

    /// Parses `"gauss4"`, `"gauss6"`, `"gauss16"`, `"dopri5"`, `"dop853"` or `"taylor"`.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "gauss4" => Ok(Method::Gauss4),
            "gauss6" => Ok(Method::Gauss6),
            "gauss16" => Ok(Method::Gauss16),
            "dopri5" => Ok(Method::Dopri5),
            "dop853" => Ok(Method::Dop853),
            "taylor" => Ok(Method::Taylor),
            _ => Err(Error::InvalidArgument {
                what: "method",
                reason: format!("unknown method {name:?}; known: {}", Self::NAMES.join(", ")),
            }),
        }
    }

    /// The method's name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Gauss4 => "gauss4",
            Method::Gauss6 => "gauss6",
            Method::Gauss16 => "gauss16",
            Method::Dopri5 => "dopri5",
            Method::Dop853 => "dop853",
            Method::Taylor => "taylor",
        }
    }

    /// Number of stages of a Gauss method (`None` for explicit methods).
    pub fn stages(self) -> Option<usize> {
        match self {
            Method::Gauss4 => Some(2),
            Method::Gauss6 => Some(3),
            Method::Gauss16 => Some(8),
            Method::Dopri5 | Method::Dop853 | Method::Taylor => None,
        }
    }

    /// The stage predictor `E` (row-major `s × s`) of a Gauss method.
    pub fn gauss_predictor(self) -> Option<Vec<f64>> {
        use gauss_tables::*;
        match self {
            Method::Gauss4 => Some(E2.concat()),
            Method::Gauss6 => Some(E3.concat()),
            Method::Gauss16 => Some(E8.concat()),
            Method::Dopri5 | Method::Dop853 | Method::Taylor => None,
        }
    }

    /// The Gauss tableau `(c, b, μ)` (`μ` row-major `s × s`), `None` for explicit methods.
    pub fn gauss_tableau(self) -> Option<(&'static [f64], &'static [f64], Vec<f64>)> {
        use gauss_tables::*;
        match self {
            Method::Gauss4 => Some((&C2, &B2, MU2.concat())),
            Method::Gauss6 => Some((&C3, &B3, MU3.concat())),
            Method::Gauss16 => Some((&C8, &B8, MU8.concat())),
            Method::Dopri5 | Method::Dop853 | Method::Taylor => None,
        }
    }
}

/// Smallest `rtol` of the explicit methods, `100 ε` (scipy's floor): a relative error
/// target per step below ~100 ulps of the state is below the rounding of the step
/// itself, and `rtol = atol = 1e-300` made the error norm overflow.
pub const RTOL_MIN: f64 = 100.0 * f64::EPSILON;

/// Integration options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The method.
    pub method: Method,
    /// Gauss methods: the largest step. `dopri5`, `dop853`: the initial step (0 =
    /// automatic). `taylor`: the largest step (0 = none).
    pub dt: f64,
    /// Relative tolerance of `dopri5` and `dop853`, at least [`RTOL_MIN`]; of
    /// `taylor`, in [`taylor::TOL_MIN`, `taylor::TOL_MAX`] (ignored by the Gauss
    /// methods).
    pub rtol: f64,
    /// `dopri5` absolute tolerance.
    pub atol: f64,
    /// The largest number of steps one call may take, over all sample times
    /// (at most [`MAX_STEPS`]). Gauss methods check it before the first step,
    /// explicit methods while stepping; either way the call fails with
    /// `InvalidArgument` instead of running for hours.
    pub max_steps: u64,
}

impl Options {
    /// The options of the method named `method` ([`Method::from_name`]),
    /// checked ([`Options::validate`]).
    pub fn parse(method: &str, dt: f64, rtol: f64, atol: f64, max_steps: u64) -> Result<Options> {
        let o = Options {
            method: Method::from_name(method)?,
            dt,
            rtol,
            atol,
            max_steps,
        };
        o.validate()?;
        Ok(o)
    }

    /// Checks `dt`, `rtol`, `atol`, `max_steps`.
    pub fn validate(&self) -> Result<()> {
        if self.max_steps == 0 || self.max_steps as f64 > MAX_STEPS {
            return Err(Error::InvalidArgument {
                what: "max_steps",
                reason: format!("must be in [1, {MAX_STEPS:e}], got {}", self.max_steps),
            });
        }
        let gauss = self.method.stages().is_some();
        if !self.dt.is_finite() || self.dt < 0.0 || (gauss && self.dt == 0.0) {
            return Err(Error::InvalidArgument {
                what: "dt",
                reason: format!("must be finite and > 0, got {}", self.dt),
            });
        }
        for (what, v) in [("rtol", self.rtol), ("atol", self.atol)] {
            if !v.is_finite() || v < 0.0 {
                return Err(Error::InvalidArgument {
                    what,
                    reason: format!("must be finite and >= 0, got {v}"),
                });
            }
        }
        if self.method == Method::Taylor {
            if !(taylor::TOL_MIN..=taylor::TOL_MAX).contains(&self.rtol) {
                return Err(Error::InvalidArgument {
                    what: "rtol",
                    reason: format!(
                        "must be in [eps = {:e}, {:e}] for taylor (it sets the order, \
                         20 at eps), got {:e}",
                        taylor::TOL_MIN,
                        taylor::TOL_MAX,
                        self.rtol
                    ),
                });
            }
        } else if !gauss && self.rtol < RTOL_MIN {
            return Err(Error::InvalidArgument {
                what: "rtol",
                reason: format!(
                    "must be >= 100 eps = {RTOL_MIN:e} for the explicit methods (a smaller \
                     relative error per step is below rounding), got {:e}",
                    self.rtol
                ),
            });
        }
        Ok(())
    }
}

/// A sampled trajectory: `t[k]` and the state `y[k·dim .. (k+1)·dim]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Sample times.
    pub t: Vec<f64>,
    /// States at the sample times, row-major `(samples, dim)`.
    pub y: Vec<f64>,
    /// Number of accepted steps taken.
    pub steps: u64,
    /// Number of vector-field evaluations.
    pub evals: u64,
}

/// Hard cap on [`Options::max_steps`] (10^11 steps is ~a day of computing);
/// below 2^53, so step counts held in f64 are exact.
pub const MAX_STEPS: f64 = 1e11;

/// Number of equal Gauss substeps of at most `dt` covering `span`; a ratio within
/// 1e-9 of an integer is taken as that integer, so 1.0 / 0.1 gives 10 steps, not 11.
pub(super) fn substeps(span: f64, dt: f64) -> f64 {
    let r = span / dt;
    let k = r.round();
    if (r - k).abs() <= 1e-9 * k.max(1.0) {
        k.max(1.0)
    } else {
        r.ceil().max(1.0)
    }
}

/// Steps a Gauss method takes from `t0` through the sample `times` at steps of
/// at most `dt`: [`substeps`] for each interval of positive length (what
/// [`check_budget`] counts). Exact while below 2^53.
pub fn gauss_steps(t0: f64, times: &[f64], dt: f64) -> f64 {
    let (mut total, mut prev) = (0.0, t0);
    for &tk in times {
        if tk > prev {
            total += substeps(tk - prev, dt);
        }
        prev = tk;
    }
    total
}

/// Checks the sample times: finite, `t0 ≤ t[0] ≤ t[1] ≤ …`.
pub fn check_sample_times(t0: f64, times: &[f64]) -> Result<()> {
    check_finite("t_eval", times)?;
    if !t0.is_finite() {
        return Err(Error::NonFinite {
            what: "t0",
            index: 0,
        });
    }
    let mut prev = t0;
    for (i, &t) in times.iter().enumerate() {
        if t < prev {
            return Err(Error::InvalidArgument {
                what: "t_eval",
                reason: format!(
                    "sample times must be sorted and >= t0 = {t0}; entry {i} = {t} follows {prev}"
                ),
            });
        }
        prev = t;
    }
    Ok(())
}

/// Checks, before any work, that a run from `t0` through the sample `times` fits
/// in `max_steps`, and names the cause when it does not.
///
/// Every sample interval of positive length needs at least one step, whatever the
/// method: more such intervals than `max_steps` is refused as a matter of sample
/// spacing. A Gauss method's step count is known in advance (`⌈Δt/dt⌉` per
/// interval): over budget, the cause is `dt` when `(t_end − t0)/dt` alone exceeds
/// the budget, else the sample spacing (intervals shorter than `dt` still cost a
/// step each). The explicit methods' count depends on the error control; they are
/// checked while stepping — except for the lower bound that a largest step
/// gives: Taylor's method never steps further than `dt > 0`, so it needs at
/// least `(t_end − t0)/dt` steps (its dense output samples within a step, so
/// the spacing adds nothing), and is refused on that bound before any work.
pub fn check_budget(method: Method, t0: f64, times: &[f64], dt: f64, max_steps: u64) -> Result<()> {
    let gauss = method.stages().is_some();
    let (mut intervals, mut prev) = (0.0f64, t0);
    for &tk in times {
        if tk > prev {
            intervals += 1.0;
        }
        prev = tk;
    }
    let total = if gauss {
        gauss_steps(t0, times, dt)
    } else {
        0.0
    };
    let budget = max_steps as f64;
    if intervals > budget {
        return Err(Error::InvalidArgument {
            what: "max_steps",
            reason: format!(
                "the sample spacing: {intervals:e} sample intervals each need at least one \
                 step, more than max_steps = {max_steps}; sample less often (fewer t_eval \
                 points or a larger sample_every) or raise max_steps"
            ),
        });
    }
    if method == Method::Taylor && dt > 0.0 {
        let t_end = times.iter().copied().fold(t0, f64::max);
        let by_dt = (t_end - t0) / dt;
        if by_dt > budget {
            return Err(Error::InvalidArgument {
                what: "max_steps",
                reason: format!(
                    "dt: (t_end - t0) / dt = {:e} / {dt:e} = {by_dt:e} steps at least (the \
                     Taylor steps are at most dt), more than max_steps = {max_steps}; \
                     increase dt, shorten t_end or raise max_steps",
                    t_end - t0
                ),
            });
        }
    }
    if gauss && total > budget {
        let by_dt = (prev - t0) / dt;
        let reason = if by_dt > budget {
            format!(
                "dt: (t_end - t0) / dt = {:e} / {dt:e} = {by_dt:e} steps, more than \
                 max_steps = {max_steps}; increase dt, shorten t_end or raise max_steps",
                prev - t0
            )
        } else {
            format!(
                "the sample spacing: {intervals:e} sample intervals at steps of at most \
                 dt = {dt:e} need {total:e} steps (each interval at least one), more than \
                 max_steps = {max_steps}, although (t_end - t0) / dt is only {by_dt:e}; \
                 sample less often or raise max_steps"
            )
        };
        return Err(Error::InvalidArgument {
            what: "max_steps",
            reason,
        });
    }
    Ok(())
}
