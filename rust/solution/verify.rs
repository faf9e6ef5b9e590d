//! The certificate of `l(t)` by an independent integration where the drift
//! check cannot vouch for the phase.
//!
//! The drift check bounds the error the self-check's relative defect `δ` may
//! cause, `δ |t| |l̇(t)|` ([`super::check::DRIFT_RTOL`]). The bound is a
//! worst case: on a harsh random draw of 10⁴ states it refused 352 solutions,
//! of which 338 were within the accuracy bound over their whole window
//! against a long-double reference (docs/degenerate.md). No check at a few
//! points of the torus can tell those from the few that did drift: a drift of
//! the phase is a global property of the motion. An integration of Frahm's
//! equations (1) over the same times is: where the closed form and Gauss–Legendre
//! order 16 at its default step agree to [`VERIFY_RTOL`] `|l0|` at every sample,
//! both are accurate to about that (they share no step of their computation),
//! and the closed form's values are returned.
//!
//! Where they disagree, the integration in double may be the one that is off:
//! on states whose components span many orders of magnitude its rounding
//! (`~1e-16 |l0|` a step) is a large relative change of the small components,
//! and the motion carries it to the whole state (docs/degenerate.md). The same
//! method in double-double ([`gauss16_dd_so4`], rounding `~1e-32 |l0|`, the
//! top's `c_ij` in double-double) then decides, within
//! [`VERIFY_DD_MAX_STEPS`]. Where it too disagrees, the closed form is the one
//! that is off if the same integration with every step halved agrees with it
//! to [`STAND_IN_SPREAD`] (the steps halved again until two successive runs
//! do, within [`STAND_IN_MAX_STEPS`]): then the finest run's values stand in
//! for the closed form's ([`Outcome::Integrated`]). Otherwise, or where the
//! integrations would exceed their budgets, `l(t)` is refused.
//!
//! The velocity `U` itself, where the theta quotients' velocity check cannot
//! vouch for it to the frequencies' accuracy, is checked the same way, by
//! the Abel images of integrated states ([`abel_rate`]), or fitted to them
//! where they move along another.

use crate::error::{Error, Result};
use crate::integrate::gauss_dd::{gauss16_dd_so4, gauss16_dd_steps};
use crate::integrate::{integrate_with, Method, Options};
use crate::numeric::alloc::try_vec;
use crate::numeric::cancel::Cancel;
use crate::numeric::dd::Dd;
use crate::so4::{FrahmTop, PAIRS4};

/// Largest disagreement `max_k |l(t_k) − l_int(t_k)| / |l0|` between the closed
/// form and the integration that certifies `l(t)`: the bound the drift check
/// holds the solution to ([`super::check::DRIFT_RTOL`]).
pub const VERIFY_RTOL: f64 = super::check::DRIFT_RTOL;

/// Most steps the certifying integration may take per direction of time
/// (Gauss–Legendre order 16 on so(4): ~1 µs a step, so ~2 s); beyond it
/// `l(t)` is refused with the drift check's reason.
pub const VERIFY_MAX_STEPS: f64 = 2e6;

/// Most steps the double-double integration may take per direction of time
/// where the one in double disagrees (~40 µs a step, so ~2 s).
pub const VERIFY_DD_MAX_STEPS: f64 = 5e4;

/// Largest spread `max |l_h − l_{h/2}| / |l0|` of two successive
/// double-double integrations for the finer one to stand in for the closed
/// form: a tenth of [`VERIFY_RTOL`]. Where truncation dominates, the finer
/// run is `2^16` times better than the spread; where the rounding of
/// double-double, amplified by the motion, does (components spanning twelve
/// orders of magnitude), halving the step does not shrink the spread, which
/// then estimates the error only to a factor of a few (draw 3797 of
/// tests/data/every_state_harsh.py over its 51 times, with an earlier rule
/// of the stage iteration: spread 1.9e-11, error 8.1e-11 against quadruple
/// precision).
pub const STAND_IN_SPREAD: f64 = VERIFY_RTOL / 10.0;

/// Most steps, all runs together, of the double-double integrations that
/// confirm the one standing in for a closed form that is off (the default
/// step, then every step halved until two successive runs agree): `~40 µs`
/// a step, so
/// `~8 s`.
pub const STAND_IN_MAX_STEPS: f64 = 4.0 * VERIFY_DD_MAX_STEPS;

/// Samples of the certifying integration on `(0, T]` besides the requested
/// times: the error of a phase drift grows with `|t|`, and a grid sees it
/// between requested times too.
const VERIFY_GRID: usize = 64;

/// Most requested times compared one by one with the certifying integration;
/// beyond it the grid of [`VERIFY_GRID`] points and the largest time do.
const VERIFY_MAX_TIMES: usize = 1 << 16;

/// The default step of Gauss–Legendre order 16 for this top and state,
/// `1/((max c − min c) |l0|)` (as `FrahmTop.default_dt`, `DT_SCALE = 1`).
fn default_dt(c4: &[f64; 6], size: f64) -> f64 {
    let (lo, hi) = c4
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
    1.0 / ((hi - lo) * size)
}

/// The top with coefficients `sign · c4` (the time-reversed flow for
/// `sign = −1`: (1) is linear in `c`).
fn top(c4: &[f64; 6], sign: f64) -> Result<FrahmTop> {
    let mut c = [0.0; 16];
    for (q, &(i, j)) in PAIRS4.iter().enumerate() {
        c[4 * i + j] = sign * c4[q];
        c[4 * j + i] = sign * c4[q];
    }
    FrahmTop::new(4, &c)
}

/// What a certifying integration found on `[0, T]` (one direction of time).
pub(super) enum Outcome {
    /// Closed form and integration agree to [`VERIFY_RTOL`] `|l0|`.
    Agree,
    /// The integration would take this many steps (over [`VERIFY_MAX_STEPS`]).
    OverBudget(f64),
    /// The integration in double disagrees by this much at this time, and
    /// the one in double-double would take this many steps (over
    /// [`VERIFY_DD_MAX_STEPS`]).
    DisagreeDdOverBudget(f64, f64, f64),
    /// An integration's stage iteration did not converge at the default
    /// step (its message).
    NotConverged(String),
    /// The closed form is off, and two successive integrations in
    /// double-double (the default step, its steps split until they agree)
    /// agree to [`STAND_IN_SPREAD`] at every sample: the finer one's values
    /// stand in for the closed form's.
    Integrated(StandIn),
    /// The closed form is off by this much at this time, and no two
    /// successive double-double integrations within [`STAND_IN_MAX_STEPS`]
    /// agree (why, in words).
    Unconfirmed(f64, f64, String),
}

/// A confirmed integration in double-double that stands in for a closed
/// form that is off ([`Outcome::Integrated`]).
pub(super) struct StandIn {
    /// The absolute values of the sampled times, sorted (every requested
    /// time is one of them).
    pub times: Vec<f64>,
    /// `l` at `sign · times[k]`, 6 per time (the finest integration).
    pub y: Vec<f64>,
    /// How far the closed form is off (relative to `|l0|`), and at which
    /// (signed) time.
    pub off: f64,
    pub off_at: f64,
    /// The spread of the last two integrations (relative to `|l0|`), and
    /// in how many steps the finer one split each step.
    pub spread: f64,
    pub split: u32,
}

impl StandIn {
    /// Writes the values into the rows of `out` whose time `t_k` has the
    /// sign `sign`.
    pub(super) fn rows(&self, t: &[f64], sign: f64, out: &mut [f64]) {
        for (&tk, row) in t.iter().zip(out.chunks_exact_mut(6)) {
            if tk * sign > 0.0 {
                let k = self
                    .times
                    .binary_search_by(|x| x.total_cmp(&tk.abs()))
                    .expect("every requested time is sampled");
                row.copy_from_slice(&self.y[6 * k..6 * k + 6]);
            }
        }
    }

    /// [`StandIn::rows`], keeping in `worst` the largest disagreement of the
    /// call's directions of time as `(off, signed time, spread)`.
    pub(super) fn apply(
        &self,
        t: &[f64],
        sign: f64,
        out: &mut [f64],
        worst: &mut Option<(f64, f64, f64, u32)>,
    ) {
        self.rows(t, sign, out);
        if worst.is_none_or(|w| self.off > w.0) {
            *worst = Some((self.off, self.off_at, self.spread, self.split));
        }
    }
}

/// Integrates (1) from `l0` over `|times|` (all of one sign, `T` the largest
/// modulus) and, with `grid`, the grid of [`VERIFY_GRID`] points on `(0, T]`
/// (without it, every requested time however many), and compares with
/// `closed` at the same times.
#[allow(clippy::too_many_arguments)]
pub(super) fn certify(
    c4: &[f64; 6],
    c4_lo: &[f64; 6],
    l0: &[f64; 6],
    size: f64,
    sign: f64,
    times: &[f64],
    grid: bool,
    closed: impl Fn(&[f64], &mut [f64]) -> Result<()>,
    cancel: &Cancel,
) -> Result<Outcome> {
    let t_end = times.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    if t_end == 0.0 {
        return Ok(Outcome::Agree);
    }
    let dt = default_dt(c4, size);
    let steps = t_end / dt;
    if steps.is_nan() || steps > VERIFY_MAX_STEPS {
        return Ok(Outcome::OverBudget(steps));
    }
    // The requested times themselves where they are not too many; beyond that
    // the grid (and the largest) stand for them.
    let mut s: Vec<f64> = if !grid || times.len() <= VERIFY_MAX_TIMES {
        times.iter().map(|t| t.abs()).collect()
    } else {
        vec![t_end]
    };
    if grid {
        s.extend((1..=VERIFY_GRID).map(|k| t_end * k as f64 / VERIFY_GRID as f64));
    }
    s.sort_by(f64::total_cmp);
    s.dedup();
    let opts = Options {
        method: Method::Gauss16,
        dt,
        rtol: 0.0,
        atol: 0.0,
        max_steps: (steps.ceil() as u64).saturating_add(s.len() as u64 + 16),
    };
    let tr = match converged(integrate_with(&top(c4, sign)?, l0, 0.0, &s, &opts, cancel))? {
        Ok(tr) => tr,
        Err(o) => return Ok(o),
    };
    let signed: Vec<f64> = s.iter().map(|t| sign * t).collect();
    let mut out = try_vec("samples", 6 * signed.len(), 0.0)?;
    closed(&signed, &mut out)?;
    let worst = disagreement(&out, &tr.y, &signed, size);
    if worst.0 <= VERIFY_RTOL {
        return Ok(Outcome::Agree);
    }
    // The double integration may be the one that is off: double-double decides.
    let dd_steps = gauss16_dd_steps(&s, dt, 1);
    if dd_steps > VERIFY_DD_MAX_STEPS {
        return Ok(Outcome::DisagreeDdOverBudget(worst.0, worst.1, dd_steps));
    }
    let c = c_dd(c4, c4_lo, sign);
    let y = match converged(gauss16_dd_so4(&c, l0, &s, dt, 1, cancel))? {
        Ok(y) => y,
        Err(o) => return Ok(o),
    };
    let worst = disagreement(&out, &y, &signed, size);
    if worst.0 <= VERIFY_RTOL {
        return Ok(Outcome::Agree);
    }
    stand_in(&c, l0, size, sign, times, grid, (s, y), dt, worst, cancel)
}

/// Where the closed form and the double-double integration disagree: the
/// closed form is the one that is off when the same integration with every
/// step halved agrees with it to [`STAND_IN_SPREAD`] (order 16: the half
/// steps' truncation error is `2^-16` of the default step's, so their
/// difference measures the default step's error, and bounds the half steps';
/// where it does not, the steps are halved again, within
/// [`STAND_IN_MAX_STEPS`] and while the spread shrinks at least fourfold). Then
/// the finest run's values stand in for the closed form's
/// ([`Outcome::Integrated`]), at every requested time.
#[allow(clippy::too_many_arguments)]
fn stand_in(
    c: &[Dd; 6],
    l0: &[f64; 6],
    size: f64,
    sign: f64,
    times: &[f64],
    grid: bool,
    (s, y): (Vec<f64>, Vec<f64>),
    dt: f64,
    (off, off_at): (f64, f64),
    cancel: &Cancel,
) -> Result<Outcome> {
    // Where the requested times were too many to compare one by one, they
    // were not integrated to: the stand-in needs every one of them.
    let (s, y) = if grid && times.len() > VERIFY_MAX_TIMES {
        let mut all: Vec<f64> = times.iter().map(|t| t.abs()).collect();
        all.extend_from_slice(&s);
        all.sort_by(f64::total_cmp);
        all.dedup();
        (all, Vec::new())
    } else {
        (s, y)
    };
    let run = |split: u32| converged(gauss16_dd_so4(c, l0, &s, dt, split, cancel));
    // Steps at the default step; splitting every step in `k` takes `k` times as many.
    let base = gauss16_dd_steps(&s, dt, 1);
    let mut spent = base;
    if 3.0 * base > STAND_IN_MAX_STEPS {
        return Ok(Outcome::Unconfirmed(
            off,
            off_at,
            format!(
                "an integration in double-double at the default step and one with every \
                 step halved would take {:.1e} steps (more than {STAND_IN_MAX_STEPS:e})",
                3.0 * base
            ),
        ));
    }
    let mut coarse = if y.is_empty() {
        match run(1)? {
            Ok(v) => v,
            Err(o) => return Ok(o),
        }
    } else {
        y
    };
    let signed: Vec<f64> = s.iter().map(|t| sign * t).collect();
    // Halve every step until two successive integrations agree (each halving
    // divides the truncation error by 2^16 once in the asymptotic regime).
    // Every step, not the bound `dt`: between close requested times the steps
    // are shorter than `dt`, and a smaller bound would leave them as they are.
    let mut split = 1u32;
    let mut spread = f64::INFINITY;
    let mut before = f64::INFINITY;
    while spread > STAND_IN_SPREAD {
        // Truncation shrinks the spread `2^16`-fold a halving; where it does
        // not shrink even 4-fold, rounding dominates, and finer steps would
        // only spend the budget (states next to an unstable rotation, whose
        // small components the motion amplifies exponentially).
        if spread > before / 4.0 {
            let why = format!(
                "the integrations with every step split in {}, {} and {} differ by \
                 {before:.1e} and {spread:.1e} |l0| (more than {STAND_IN_SPREAD:.0e}): the \
                 spread does not shrink with the step (rounding, amplified by the motion)",
                split / 4,
                split / 2,
                split
            );
            return Ok(Outcome::Unconfirmed(off, off_at, why));
        }
        let next = base * f64::from(2 * split);
        if spent + next > STAND_IN_MAX_STEPS {
            let why = format!(
                "the integrations with every step split in {} and in {} differ by \
                 {spread:.1e} |l0| (more than {STAND_IN_SPREAD:.0e}), and a finer one would \
                 exceed {STAND_IN_MAX_STEPS:e} steps",
                split / 2,
                split
            );
            return Ok(Outcome::Unconfirmed(off, off_at, why));
        }
        split *= 2;
        spent += next;
        let fine = match run(split)? {
            Ok(v) => v,
            Err(o) => return Ok(o),
        };
        before = spread;
        spread = disagreement(&coarse, &fine, &signed, size).0;
        coarse = fine;
    }
    if coarse.iter().any(|v| !v.is_finite()) {
        return Ok(Outcome::Unconfirmed(
            off,
            off_at,
            "the integrations are not finite".into(),
        ));
    }
    Ok(Outcome::Integrated(StandIn {
        times: s,
        y: coarse,
        off,
        off_at,
        spread,
        split,
    }))
}

/// `r`, with an iteration that did not converge at the step taken as the
/// outcome [`Outcome::NotConverged`] (a refusal naming it, not an error).
fn converged<T>(r: Result<T>) -> Result<std::result::Result<T, Outcome>> {
    match r {
        Err(e @ Error::NoConvergence { .. }) => Ok(Err(Outcome::NotConverged(e.to_string()))),
        other => other.map(Ok),
    }
}

/// The largest of `v`, NaN if any is (`f64::max` would skip a NaN).
pub(super) fn nan_max(v: impl Iterator<Item = f64>) -> f64 {
    let mut m = 0.0f64;
    for e in v {
        if e.is_nan() {
            return f64::NAN;
        }
        m = m.max(e);
    }
    m
}

/// The largest `max_q |a_q − b_q| / size` over the rows (a NaN counts as
/// infinite) and the time of its row.
fn disagreement(a: &[f64], b: &[f64], times: &[f64], size: f64) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for (k, (x, y)) in a.chunks_exact(6).zip(b.chunks_exact(6)).enumerate() {
        let d = nan_max(x.iter().zip(y).map(|(p, q)| (p - q).abs())) / size;
        if d.is_nan() || d > worst.0 {
            worst = (if d.is_nan() { f64::INFINITY } else { d }, times[k]);
        }
    }
    worst
}

/// What a certifying integration found, as the end of a refusal's message
/// (empty where it agrees).
pub(super) fn found(outcome: &Outcome) -> String {
    match outcome {
        Outcome::Agree | Outcome::Integrated(_) => String::new(),
        Outcome::Unconfirmed(d, t, why) => format!(
            "; an integration of (1) (Gauss-Legendre order 16 in double-double) differs \
             from it by {d:.1e} |l0| at t = {t:e}, and {why}"
        ),
        Outcome::NotConverged(why) => format!(
            "; an integration of (1) to certify it did not converge at its default step ({why})"
        ),
        Outcome::DisagreeDdOverBudget(d, t, steps) => format!(
            "; an integration of (1) (Gauss-Legendre order 16) differs from it by \
             {d:.1e} |l0| at t = {t:e}, and one in double-double to decide would take \
             {steps:.1e} steps (more than {VERIFY_DD_MAX_STEPS:e})"
        ),
        Outcome::OverBudget(steps) => format!(
            "; an integration of (1) to certify it would take {steps:.1e} steps \
             (more than {VERIFY_MAX_STEPS:e})"
        ),
    }
}

/// The refusal of `l(t)` where the certificate failed: the drift check's
/// reason and what the integration found.
pub(super) fn refusal(reason: String, outcome: &Outcome) -> Error {
    Error::Unverified {
        what: "l(t)",
        reason: format!("{reason}{}", found(outcome)),
    }
}

/// The refusal of `l(t)` of a solution that failed its self-check
/// ([`super::Solution::with_c4_lo_certifying`]) where the integration did not
/// certify it: the self-check's reason and what the integration found.
pub(super) fn refusal_unchecked(why: &str, outcome: &Outcome) -> Error {
    let found = found(outcome);
    Error::Unverified {
        what: "l(t)",
        reason: format!(
            "{why}; l(t) is returned only where an integration of (1) certifies it{found}"
        ),
    }
}

/// `l(±t_k)` of (1) from `l0` at the sorted times `times ≥ 0` (`sign` the
/// direction), by Gauss–Legendre order 16 in double-double at the default
/// step, its steps split until two successive runs agree to
/// [`STAND_IN_SPREAD`] `|l0|` at every time (within [`STAND_IN_MAX_STEPS`]):
/// the finest run ([`StandIn`]; with no closed form to be off, `off` is
/// NaN). Where they do not agree, or an iteration does not converge,
/// `Ok(Err(why))`. The motion of a state without a closed form
/// ([`super::motion::Kind::Integrated`]).
pub(super) fn integrate_confirmed(
    c4: &[f64; 6],
    c4_lo: &[f64; 6],
    l0: &[f64; 6],
    size: f64,
    sign: f64,
    times: Vec<f64>,
    cancel: &Cancel,
) -> Result<std::result::Result<StandIn, String>> {
    let c = c_dd(c4, c4_lo, sign);
    let dt = default_dt(c4, size);
    let outcome = stand_in(
        &c,
        l0,
        size,
        sign,
        &[],
        false,
        (times, Vec::new()),
        dt,
        (f64::NAN, 0.0),
        cancel,
    )?;
    Ok(match outcome {
        Outcome::Integrated(si) => Ok(si),
        Outcome::Unconfirmed(_, _, why) | Outcome::NotConverged(why) => Err(why),
        Outcome::Agree | Outcome::OverBudget(_) | Outcome::DisagreeDdOverBudget(..) => {
            Err("the integration found nothing to confirm".into())
        }
    })
}

/// The coefficients `sign (c4 + c4_lo)` in double-double (`c4_lo` the
/// rounding errors of `c4`; `sign` ±1 for the direction of time).
pub(super) fn c_dd(c4: &[f64; 6], c4_lo: &[f64; 6], sign: f64) -> [Dd; 6] {
    std::array::from_fn(|q| Dd::sum(sign * c4[q], sign * c4_lo[q]))
}

/// Phases, in lattice periods of the fastest coordinate, at which
/// [`abel_rate`] compares: from one period to four, so that a wrong
/// velocity shows as a defect growing with time, at every one of them; in
/// quarter periods, for more chances of [`ABEL_AGREEING`] images away from
/// branch points (Abel evaluations are cheap next to the integration: on the
/// harsh draw, of 128 solutions whose fit of `U` next to a pinched curve the
/// check refused at half periods with `U'` held to 1e-10, 11 pass at half
/// periods with `U'` held to 1e-8, 25 at quarter periods; every one whose `U`
/// is off against a quadruple-precision trajectory is still refused).
const ABEL_PHASES: [f64; 13] = [
    1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 2.75, 3.0, 3.25, 3.5, 3.75, 4.0,
];

/// Phases of [`ABEL_PHASES`] that must agree in each run: the Abel image of a
/// single integrated state can be off (a point of its divisor next to a
/// branch point, where the reduction loses digits, or refused), which a wrong
/// velocity is not: it is off by the same relative amount at every phase.
const ABEL_AGREEING: usize = 3;

/// Most steps (both runs together) of the integrations of [`abel_rate`]:
/// Gauss–Legendre order 16 in double, `~0.5 µs` a step, so `~1 s` per flow.
/// Slow lattice rates on stiff tops need this many: on the harsh draw 22
/// states whose check was beyond 1e5 steps needed up to 1.4e6, and all but
/// one of them have their frequencies with it.
pub const ABEL_CHECK_MAX_STEPS: f64 = 2e6;

/// Where the double runs of [`abel_rate`] leave a defect above this
/// (the bound the check holds `U` to, `tori::solve::ABEL_RATE_RTOL`), the
/// same integrations are repeated in
/// double-double: on states whose components span many orders of magnitude
/// the rounding of Gauss–Legendre in double (`~1e-16 |l0|` a step) is a large
/// relative change of the small components, which moves the Abel images (a
/// state of the harsh draw next to a pinched curve: 3.2e-10 from the double
/// runs, 3e-13 from double-double, 3.4e-13 against a quadruple-precision
/// trajectory).
pub const ABEL_DD_FROM: f64 = 5e-11;

/// Most steps (both runs together) of the double-double integrations of
/// [`abel_rate`], `~20 µs` a step: `~20 s` per flow at most, taken only by
/// states whose check in double failed (the cancellation token is checked at
/// every step).
pub const ABEL_CHECK_MAX_DD_STEPS: f64 = 1e6;

/// Fewest of the [`ABEL_PHASES`] whose Abel images must lie on one line in
/// each double-double run for a velocity fitted to them to stand
/// ([`AbelRate::fit`]): a majority. With the line's eight parameters (an
/// offset and a slope in four lattice coordinates) fitted, seven images give
/// 28 numbers for it to explain, where a velocity given beforehand needs
/// [`ABEL_AGREEING`].
const ABEL_FIT_AGREEING: usize = 7;

/// Least span, in periods of the fastest lattice coordinate, of the phases
/// of the images a fitted velocity rests on: its error is the images' scatter
/// divided by about the span.
const ABEL_FIT_SPAN: f64 = 2.0;

/// Tolerance, in periods, within which images count as on the line through
/// a pair of them (the first, robust, step of the fit; the least-squares line
/// through those images is then held to the caller's bound).
const ABEL_FIT_CONSENSUS: f64 = 1e-8;

/// Where a velocity fitted to the images is bounded only to between the
/// caller's bound and this (relative), it is fitted again over phases
/// [`ABEL_LONG_SPAN`] times as long ([`long_fit`]).
const ABEL_LONG_FROM: f64 = 1e-7;

/// The factor by which [`long_fit`] stretches [`ABEL_PHASES`].
const ABEL_LONG_SPAN: f64 = 32.0;

/// Largest relative correction a fitted velocity may make to the given one:
/// the images are unwrapped modulo the lattice against the given velocity,
/// which needs its drift over the last of [`ABEL_PHASES`] well below half a
/// period. (The given velocity's defect can be far larger: an image of `l0`
/// off by a constant shifts every image alike, which the line's offset takes
/// up; on the harsh draw one solution had a defect of 2e-2 while its images
/// lay on a line to 5e-16.)
const ABEL_FIT_MAX_SLOPE: f64 = 1e-2;

/// What the Abel images of integrated states say about a velocity `u`
/// ([`abel_rate`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AbelRate {
    /// The relative defect of `u` ([`abel_rate`]); NaN where the comparison
    /// cannot be made.
    pub defect: f64,
    /// Where the defect is above the caller's bound and the double-double
    /// runs were made: the velocity the images move at, as lattice
    /// coordinates `(X1, X2, Y1, Y2)` (`U = X + τY`), and the bound on its
    /// relative error (the images' least-squares residual times the fit's
    /// sensitivity to it, or the two runs' disagreement, the larger).
    pub fit: Option<([f64; 4], f64)>,
}

/// Images of one run: the phase of each image the Abel map took, and its
/// offset from `u0 + u t_k` in lattice coordinates, reduced to the nearest
/// lattice vector.
type Images = Vec<(f64, [f64; 4])>;

/// [`abel_rate`]'s defect of `u` alone (no bound given, so no fit).
pub fn abel_rate_defect(
    sol: &super::Solution,
    c4: &[f64; 6],
    c4_lo: &[f64; 6],
    u: &[num_complex::Complex64; 2],
    cancel: &Cancel,
) -> Result<f64> {
    Ok(abel_rate(sol, c4, c4_lo, u, f64::INFINITY, cancel)?.defect)
}

/// The velocity `u` of the flow (1) with coefficients `c4` (state order;
/// `c4 + c4_lo` in double-double, `c4_lo` their rounding errors or zero) on
/// the level set of `sol`, checked without theta functions: `l0` is
/// integrated (Gauss–Legendre order 16, at the default step and at half of
/// it; again in double-double where the two leave more than [`ABEL_DD_FROM`])
/// to the times `t_k` at which `u t_k` has advanced [`ABEL_PHASES`]
/// periods in its fastest lattice coordinate, and the Abel image of each
/// state, `u(P1(t_k)) + u(P2(t_k))` ([`super::Solution::abel`]: the reduction of the
/// integrated state and Abel integrals on the curve), is compared with
/// `u0 + u t_k` modulo the lattice, in lattice coordinates and divided by the
/// phase advanced. The defect is, over both runs, the largest of each run's
/// [`ABEL_AGREEING`]-th smallest such defect: `u` is off by at most that
/// (relative), or [`ABEL_AGREEING`] Abel images would have to be off by the
/// same amount as `u`. NaN where the comparison cannot be made (an
/// integration over budget or not converged, fewer than [`ABEL_AGREEING`]
/// states the Abel map takes).
///
/// Where that defect is above `rtol` (the caller's bound) and the runs were
/// made in double-double, the velocity the images move at is fitted to them
/// ([`AbelRate::fit`]): the images are a line in time, `α + U t`, whatever
/// `u` is, and its slope needs neither the theta quotients nor `u0`. Next to
/// pinched curves the closed form's and the quotients' `U` can be off by
/// 1e-10 … 1e-6 while the images still lie on a line to 1e-13.
///
/// The theta quotients' own velocity check ([`super::Solution::velocity_check`]) is
/// ill-conditioned where the curve is nearly pinched (its thetas are sums of
/// nearly cancelling terms); this comparison uses only the reduction and the
/// curve's periods, which the closed form of `u` shares, but not its
/// derivation (Dubrovin's equations at half periods): a wrong `u` shows as a
/// defect proportional to `t`. The caller has bounded `u`'s error by far less
/// than a period per period (the velocity check within
/// [`super::check::VELOCITY_CHECK_RTOL`]), so the nearest lattice vector is
/// the right one.
pub fn abel_rate(
    sol: &super::Solution,
    c4: &[f64; 6],
    c4_lo: &[f64; 6],
    u: &[num_complex::Complex64; 2],
    rtol: f64,
    cancel: &Cancel,
) -> Result<AbelRate> {
    let unchecked = AbelRate {
        defect: f64::NAN,
        fit: None,
    };
    let (curve, l0) = (sol.curve(), &sol.l0);
    let (x, y) = curve.lattice_coordinates(u);
    let rate = nan_max(x.iter().chain(&y).map(|v| v.abs()));
    if !(rate > 0.0 && rate.is_finite()) {
        return Ok(unchecked);
    }
    let times = ABEL_PHASES.map(|f| f / rate);
    let t_end = times[ABEL_PHASES.len() - 1];
    let dt = default_dt(c4, sol.size);
    let steps = 3.0 * t_end / dt;
    if steps.is_nan() || steps > ABEL_CHECK_MAX_STEPS {
        return Ok(unchecked);
    }
    // the Abel image of l0 by the same route as the integrated states'
    let Ok(u0) = sol.abel(l0) else {
        return Ok(unchecked);
    };
    let images_of = |y: &[f64]| images(sol, &u0, u, &times, &ABEL_PHASES, y);
    // each run's ABEL_AGREEING-th smallest defect (None: too few Abel images)
    let defect_of = |images: &Images| -> Option<f64> {
        let mut defects: Vec<f64> = images
            .iter()
            .map(|(p, r)| nan_max(r.iter().map(|v| v.abs())) / p)
            .collect();
        if defects.len() < ABEL_AGREEING {
            return None;
        }
        defects.sort_by(f64::total_cmp);
        Some(defects[ABEL_AGREEING - 1])
    };
    let top = top(c4, 1.0)?;
    let mut worst = 0.0f64;
    for h in [dt, dt / 2.0] {
        let opts = Options {
            method: Method::Gauss16,
            dt: h,
            rtol: 0.0,
            atol: 0.0,
            max_steps: ((t_end / h).ceil() as u64).saturating_add(16 + times.len() as u64),
        };
        let tr = match integrate_with(&top, l0, 0.0, &times, &opts, cancel) {
            Ok(tr) => tr,
            Err(Error::NoConvergence { .. }) => return Ok(unchecked),
            Err(e) => return Err(e),
        };
        let Some(d) = defect_of(&images_of(&tr.y)) else {
            return Ok(unchecked);
        };
        worst = worst.max(d);
    }
    if worst <= ABEL_DD_FROM {
        return Ok(AbelRate {
            defect: worst,
            fit: None,
        });
    }
    if 3.0 * gauss16_dd_steps(&times, dt, 1) > ABEL_CHECK_MAX_DD_STEPS {
        // the double runs' defect may be theirs, not u's
        return Ok(unchecked);
    }
    // The double integrations may be the ones that are off: double-double
    // decides (the same steps, and every step halved), with the coefficients
    // unrounded (`c4 + c4_lo`): next to pinched curves the Abel images move
    // with the rounding of `c4` by far more than ε (on a state of the harsh
    // draw by 6e-8 of the phase, which `c4 + c4_lo` brings to 6e-17, as a
    // quadruple-precision trajectory of the exact top confirms).
    let c = c_dd(c4, c4_lo, 1.0);
    let mut worst_dd = 0.0f64;
    let mut runs: Vec<Images> = Vec::with_capacity(2);
    for split in [1, 2] {
        let y = match gauss16_dd_so4(&c, l0, &times, dt, split, cancel) {
            Ok(y) => y,
            Err(Error::NoConvergence { .. }) => return Ok(unchecked),
            Err(e) => return Err(e),
        };
        let images = images_of(&y);
        match defect_of(&images) {
            Some(d) => worst_dd = worst_dd.max(d),
            // too few images for the defect leaves too few for a fit as well
            None => return Ok(unchecked),
        }
        runs.push(images);
    }
    // (worst_dd is finite: every run gave its defect)
    if worst_dd <= rtol {
        return Ok(AbelRate {
            defect: worst_dd,
            fit: None,
        });
    }
    let w0 = [x[0], x[1], y[0], y[1]];
    let fit_to = |bound: f64| corrected(&w0, rate, fitted_rate(&runs, bound));
    let mut fit = fit_to(rtol);
    // Images that scatter about a line bound its slope only to their scatter
    // over the phases' span: a span ABEL_LONG_SPAN times longer, unwrapped
    // against the short fit, bounds it that many times more tightly.
    if fit.is_none() {
        if let Some((w, _)) = fit_to(ABEL_LONG_FROM) {
            fit = long_fit(sol, (&c, dt), &u0, &w, rtol, cancel)?;
        }
    }
    Ok(AbelRate {
        defect: worst_dd,
        fit,
    })
}

/// The images of the states `y` (rows of 6, at `times`, the phases
/// `phases`) that the Abel map takes: their offsets from `u0 + u t` in
/// lattice coordinates, reduced to the nearest lattice vector.
fn images(
    sol: &super::Solution,
    u0: &[num_complex::Complex64],
    u: &[num_complex::Complex64; 2],
    times: &[f64],
    phases: &[f64],
    y: &[f64],
) -> Images {
    let curve = sol.curve();
    let mut images = Vec::with_capacity(times.len());
    for (k, l) in y.chunks_exact(6).enumerate() {
        let l: [f64; 6] = l.try_into().expect("rows of 6");
        let Ok(w) = sol.abel(&l) else {
            continue;
        };
        let d = [
            w[0] - u0[0] - u[0] * times[k],
            w[1] - u0[1] - u[1] * times[k],
        ];
        let (dx, dy) = curve.lattice_coordinates(&d);
        let r = [dx[0], dx[1], dy[0], dy[1]].map(|v| v - v.round());
        if r.iter().all(|v| v.is_finite()) {
            images.push((phases[k], r));
        }
    }
    images
}

/// The velocity fitted to the images of double-double runs over
/// [`ABEL_LONG_SPAN`] times the phases of [`ABEL_PHASES`], against the
/// velocity `w` (lattice coordinates) fitted over the short ones; None where
/// the runs exceed [`ABEL_CHECK_MAX_DD_STEPS`] or give no line within
/// `rtol` (`c`: the coefficients in double-double, `dt` the step; `u0` the
/// image of `l0`).
fn long_fit(
    sol: &super::Solution,
    (c, dt): (&[Dd; 6], f64),
    u0: &[num_complex::Complex64],
    w: &[f64; 4],
    rtol: f64,
    cancel: &Cancel,
) -> Result<Option<([f64; 4], f64)>> {
    let u = sol.curve().lattice_point(&w[..2], &w[2..]);
    let u = [u[0], u[1]];
    let rate = nan_max(w.iter().map(|v| v.abs()));
    let phases = ABEL_PHASES.map(|f| f * ABEL_LONG_SPAN);
    let times = phases.map(|f| f / rate);
    let steps = 3.0 * gauss16_dd_steps(&times, dt, 1);
    if steps.is_nan() || steps > ABEL_CHECK_MAX_DD_STEPS {
        return Ok(None);
    }
    let mut runs: Vec<Images> = Vec::with_capacity(2);
    for split in [1, 2] {
        let y = match gauss16_dd_so4(c, &sol.l0, &times, dt, split, cancel) {
            Ok(y) => y,
            Err(Error::NoConvergence { .. }) => return Ok(None),
            Err(e) => return Err(e),
        };
        runs.push(images(sol, u0, &u, &times, &phases, &y));
    }
    // the slope per long phase, in the short fit's lattice units per period
    Ok(corrected(w, rate, fitted_rate(&runs, rtol)))
}

/// The velocity (lattice coordinates) `w0` corrected by a fitted slope (per
/// period of phase at the lattice rate `rate`) and its bound, where the
/// correction is at most [`ABEL_FIT_MAX_SLOPE`].
fn corrected(w0: &[f64; 4], rate: f64, fit: Option<([f64; 4], f64)>) -> Option<([f64; 4], f64)> {
    fit.filter(|(slope, _)| nan_max(slope.iter().map(|v| v.abs())) <= ABEL_FIT_MAX_SLOPE)
        .map(|(slope, bound)| (std::array::from_fn(|q| w0[q] + slope[q] * rate), bound))
}

/// The slope (lattice coordinates per period of phase, so the relative
/// correction to the velocity) of the line the images of every run lie on,
/// and the bound on its error: per run, the pair of images whose line the
/// most images lie on within [`ABEL_FIT_CONSENSUS`], the least-squares line
/// through those, trimmed of its worst image while its bound is above `rtol`
/// (at least [`ABEL_FIT_AGREEING`] images over [`ABEL_FIT_SPAN`] periods);
/// the bound is the largest residual times the least-squares slope's
/// sensitivity to it, or the runs' largest disagreement, the larger, and the
/// slope their mean. None where a run leaves too few images on a line.
fn fitted_rate(runs: &[Images], rtol: f64) -> Option<([f64; 4], f64)> {
    let mut slopes: Vec<[f64; 4]> = Vec::with_capacity(runs.len());
    let mut bound = 0.0f64;
    for images in runs {
        let (slope, b) = fitted_line(images, rtol)?;
        slopes.push(slope);
        bound = bound.max(b);
    }
    let n = slopes.len() as f64;
    let mean: [f64; 4] = std::array::from_fn(|q| slopes.iter().map(|s| s[q]).sum::<f64>() / n);
    for s in &slopes {
        for t in &slopes {
            bound = bound.max(nan_max((0..4).map(|q| (s[q] - t[q]).abs())));
        }
    }
    (bound.is_finite()).then_some((mean, bound))
}

/// One run's line ([`fitted_rate`]): its slope and error bound.
fn fitted_line(images: &Images, rtol: f64) -> Option<([f64; 4], f64)> {
    let off = |(p, r): &(f64, [f64; 4]), a: &[f64; 4], s: &[f64; 4]| {
        nan_max((0..4).map(|q| (r[q] - a[q] - s[q] * p).abs()))
    };
    // the robust start: the pair whose line the most images lie on
    let mut best: Vec<usize> = Vec::new();
    for i in 0..images.len() {
        for j in i + 1..images.len() {
            let ((pi, ri), (pj, rj)) = (images[i], images[j]);
            if pj - pi < 0.5 {
                continue;
            }
            let s: [f64; 4] = std::array::from_fn(|q| (rj[q] - ri[q]) / (pj - pi));
            let a: [f64; 4] = std::array::from_fn(|q| ri[q] - s[q] * pi);
            let on: Vec<usize> = (0..images.len())
                .filter(|&k| off(&images[k], &a, &s) <= ABEL_FIT_CONSENSUS)
                .collect();
            if on.len() > best.len() {
                best = on;
            }
        }
    }
    loop {
        if best.len() < ABEL_FIT_AGREEING {
            return None;
        }
        let p: Vec<f64> = best.iter().map(|&k| images[k].0).collect();
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if hi - lo < ABEL_FIT_SPAN {
            return None;
        }
        let n = p.len() as f64;
        let mean = p.iter().sum::<f64>() / n;
        let spread = p.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>();
        // the least-squares slope moves by at most this times the largest
        // change of an image
        let sensitivity = p.iter().map(|v| (v - mean).abs()).sum::<f64>() / spread;
        let s: [f64; 4] = std::array::from_fn(|q| {
            best.iter()
                .map(|&k| (images[k].0 - mean) * images[k].1[q])
                .sum::<f64>()
                / spread
        });
        let a: [f64; 4] = std::array::from_fn(|q| {
            best.iter().map(|&k| images[k].1[q]).sum::<f64>() / n - s[q] * mean
        });
        let (worst, at) = best
            .iter()
            .enumerate()
            .map(|(i, &k)| (off(&images[k], &a, &s), i))
            .max_by(|x, y| x.0.total_cmp(&y.0))?;
        let b = worst * sensitivity;
        if b <= rtol {
            return Some((s, b));
        }
        best.remove(at);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Images at every phase of [`ABEL_PHASES`] on the line `a + s p`, with a
    /// scatter of up to `noise` (a fixed pseudo-random pattern) and the
    /// images at `outliers` moved off it by `1e-3 (k² + 1)` (on no common
    /// line).
    fn images(a: [f64; 4], s: [f64; 4], noise: f64, outliers: &[usize]) -> Images {
        ABEL_PHASES
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                let bump = if outliers.contains(&k) {
                    1e-3 * (k * k + 1) as f64
                } else {
                    0.0
                };
                let r = std::array::from_fn(|q| {
                    // a fixed pseudo-random pattern in [-1, 1]
                    let scatter = (12.9898 * k as f64 + 78.233 * q as f64).sin();
                    a[q] + s[q] * p + scatter * noise + bump
                });
                (p, r)
            })
            .collect()
    }

    #[test]
    fn the_fitted_line_is_the_slope_of_the_images_despite_outliers() {
        let (a, s) = ([1e-9, -2e-9, 0.0, 3e-9], [3e-7, -1e-8, 2e-9, 0.0]);
        // four of thirteen images off by 1e-3 and more, the rest scattered by 1e-14
        let run = images(a, s, 1e-14, &[0, 3, 7, 12]);
        let (slope, bound) = fitted_line(&run, 5e-11).expect("nine images on a line");
        let err = nan_max((0..4).map(|q| (slope[q] - s[q]).abs()));
        assert!(bound <= 5e-11, "bound {bound:e}");
        assert!(err <= bound, "slope off by {err:e}, bound {bound:e}");
        // two runs: the mean slope, bounded by their disagreement as well
        let other = images(a, s.map(|v| v + 1e-12), 0.0, &[]);
        let (mean, bound) = fitted_rate(&[run, other], 5e-11).expect("both runs fit");
        assert!(bound >= 1e-12, "the runs' disagreement counts: {bound:e}");
        assert!(nan_max((0..4).map(|q| (mean[q] - s[q]).abs())) <= bound);
    }

    #[test]
    fn images_off_a_line_give_no_fitted_velocity() {
        let (a, s) = ([0.0; 4], [1e-8; 4]);
        // seven of thirteen off: only six on the line
        let run = images(a, s, 0.0, &[0, 2, 4, 6, 8, 10, 12]);
        assert!(fitted_line(&run, 5e-11).is_none());
        // images scattered by 1e-9 do not bound a slope to 5e-11
        assert!(fitted_line(&images(a, s, 1e-9, &[]), 5e-11).is_none());
        // six phases on a line, spanning under two periods
        let short: Images = images(a, s, 0.0, &[])
            .into_iter()
            .filter(|(p, _)| *p <= 2.5)
            .collect();
        assert!(fitted_line(&short, 5e-11).is_none());
    }
}
