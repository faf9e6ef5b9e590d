//! The frequency map on the Theorem's level set ([`crate::solution`]).
//!
//! Two routes to the data of [`real_torus`] (`τ`, `U`, `U'`, the
//! characteristics):
//!
//! * [`level_set_flow_data`] (the frequency map): the reduction's constants,
//!   the curve (8) and its periods, and the velocities of both flows in closed
//!   form ([`crate::solution::dubrovin`]: Dubrovin's equations at the half
//!   periods; where they refuse, none known, the chain rule at auxiliary
//!   divisors of [`crate::solution::velocity`]). No theta function, no divisor
//!   of `l0`, no Abel map: the frequencies are a property of the level set.
//!   Where neither gives the velocities, the state takes the second route.
//! * [`flow_data`] on a [`Solution`] (`sol.torus`): where the first route
//!   gives the velocities, its numbers; else the solution's `U` and the
//!   closed form of `U'` in the solution's sign convention, each checked
//!   against the theta quotients' fit at `v0`, and for a solution that failed
//!   its self-check (kept for its certified `l(t)`) by the Abel images of
//!   integrated states alone.
//!
//! Both take the same closed form on the same curve, so they agree to the
//! last bits (`tests/data/closed_u_frequencies.py`), and neither refuses what
//! the other gives.

use num_complex::Complex64 as C;

use super::{frequencies_of_state, second_flow_b, Char, FlowData, MapEntry, RealTorus, Status};
use crate::error::{Error, Result, SingularKind};
use crate::numeric::cancel::Cancel;
use crate::riemann::HyperellipticCurve;
use crate::so4;
use crate::solution::dubrovin::{
    closed_form_fits, half_period_velocities, lattice_rates_dd, CLOSED_FORM,
};
use crate::solution::velocity::algebraic_rates;
use crate::solution::verify::{abel_rate, AbelRate};
use crate::solution::VELOCITY_CHECK_RTOL;
use crate::solution::{a_periods_of, level_set_curve, Solution};

/// Above this spread of the branch points ([`HyperellipticCurve::spread`])
/// the frequencies are computed from the velocities and periods in
/// double-double on the unrounded branch points, below it in double. The
/// double route is accurate to ~ε times the spread: against the DD route, at
/// most 4.2e-15 (relative, max norm) where the spread is at most 100 (Rust
/// `tori::tests::the_double_route_is_good_where_the_spread_is_moderate`), up
/// to 3.3e-14 at spreads up to 1e3 and 1e-11 at spreads up to 1e12 (tops with
/// two close `a_i`). The DD route costs about 1.5 times the double one per
/// state; the shared tops have spreads 21–65.
pub const DD_SPREAD: f64 = 100.0;

/// Above this spread of the branch points the frequency map does not take
/// the level set's closed form unchecked: it takes the Theorem's solution,
/// whose set-up checks the closed form against the theta quotients' own
/// velocity at `v0` and takes their fit where the two disagree
/// (docs/theorem.md). There the clustered branch points are below the
/// resolution of the largest one in double; on the harsh random draw
/// (tests/data/every_state_harsh.py, seed 5, 2000 states) the closed form's
/// frequencies were off by 1e-12 … 3.5e5 relative on 28 states, all with
/// spreads from 9.8e16 up (none below), while the Theorem's agreed with the
/// spectrum of an integrated trajectory.
pub const CLOSED_FORM_SPREAD: f64 = 1e14;

/// Whether the frequencies of a level set with this curve take the DD route
/// ([`DD_SPREAD`]): both the frequency map and `sol.torus` decide by it, on
/// the same curve, so they give the same frequencies.
pub fn needs_dd(curve: &HyperellipticCurve) -> bool {
    // a NaN spread (non-finite branch points) takes the DD route too
    let spread = curve.spread();
    spread.is_nan() || spread > DD_SPREAD
}

/// Largest velocity defect of a solution's self-check
/// ([`Solution::velocity_check`]) for which its frequencies are given: the
/// self-check's bound on the quotients' shape, the accuracy the frequencies
/// are vouched for to (a velocity defect `δ` can put `U`, hence `ν`, off by
/// `δ` relative).
pub const FREQUENCY_VELOCITY_RTOL: f64 = crate::solution::SELF_CHECK_RTOL;

/// Where a solution's `U` is the theta quotients' least-squares fit at `v0`
/// (its closed form refused), the fit is trusted for the frequencies only if
/// the largest eigenvalue of `Im τ` is at most this; beyond it the Abel-map
/// check decides. The quotients' terms along the eigendirection are
/// `~exp(−π λ)` of the others, so next to a pinched curve (`λ` large) they
/// hardly depend on one direction of `u`, and the fit can move along it by far
/// more than its residual says: on the harsh draw (`λ` ~ 10 … 17 where
/// measured) by up to 7e-10 of the largest lattice rate with velocity checks
/// of ~1e-14. Away from pinched curves (`λ` ~ 1, the Clebsch contraction's
/// tops, whose closed form refuses for their rounded `c_ij`) the fit is `U` to
/// rounding, and the check would only cost (their stiff flows exceed its
/// budget).
pub const FIT_PINCHED_IM_TAU: f64 = 3.0;

/// The bound to which the Abel-map check holds `U`: half the bound the
/// frequencies are vouched for to ([`FREQUENCY_VELOCITY_RTOL`]). The check's
/// statistic, the third smallest of the thirteen phases' defects (robust to a
/// few Abel images next to branch points), can fall below `U`'s error by the
/// scatter of the images: on the harsh draw one state passed at 9.0e-11 whose
/// `U` was off by 1.3e-10 against the slope of the Abel images of a
/// quadruple-precision trajectory over 20 periods.
pub const ABEL_RATE_RTOL: f64 = 0.5 * FREQUENCY_VELOCITY_RTOL;

/// The bound to which the Abel-map check holds the second flow's `U'`: it
/// only fixes the real plane, in which the lattice basis is found as integer
/// vectors (the projection integral to [`super::RATIONAL_TOL`], which a
/// wrong `U'` fails instead of giving another basis); the frequencies are the
/// coordinates of `U` alone in that basis. Next to pinched curves the
/// quotients' fit of `U'` is off along the direction they hardly see by more
/// than `U`'s (on the harsh draw 32 states had `U` within 1e-10 by the check,
/// and `U'` at 1e-10 … 5e-2; `U` of three of them against the Abel images of a
/// quadruple-precision trajectory: within 6e-12). Where `U'` cannot be
/// checked (its flow beyond the integrations' budget), that integrality
/// stands in (`abel_check`).
pub const ABEL_SECOND_FLOW_RTOL: f64 = 1e-8;

/// The largest eigenvalue of `Im τ` (`τ` row-major, symmetric).
fn largest_im_tau(t: &[C; 4]) -> f64 {
    let (p, q, r) = (t[0].im, 0.5 * (t[1].im + t[2].im), t[3].im);
    0.5 * (p + r) + (0.25 * (p - r) * (p - r) + q * q).sqrt()
}

/// The six `c_ij` (`i < j`, state order) of `ManakovTop(a, b)` (2).
pub fn c_pairs(a: &[f64; 4], b: &[f64; 4]) -> Result<[f64; 6]> {
    // manakov_c returns the full 4×4 matrix, row-major.
    let c = so4::manakov_c(a, b)?;
    Ok([c[1], c[2], c[3], c[6], c[7], c[11]])
}

/// `τ`, `U`, `U'` (the flow of `ManakovTop(a, b2)` by [`rate_for`]) and the
/// characteristics of a solution, in the layout of this module.
pub fn flow_data(sol: &Solution, b2: &[f64; 4]) -> Result<FlowData> {
    flow_data_with(sol, b2, &Cancel::never())
}

/// [`flow_data`] with a cancellation token, checked inside the integrations
/// of the Abel-map check of the velocities ([`abel_rate`]).
pub fn flow_data_with(sol: &Solution, b2: &[f64; 4], cancel: &Cancel) -> Result<FlowData> {
    // Where the frequency map takes the level set's closed form unchecked
    // (branch points spread over at most CLOSED_FORM_SPREAD, and the half
    // periods or the auxiliary divisors give the velocities), the solution
    // takes the same numbers: `sol.torus` and the map agree to the bit, and
    // neither refuses what the other gives.
    let c2 = c_pairs(sol.a(), b2)?;
    match level_set_flow_data_c4(sol.a(), sol.c4(), &c2, sol.l0()) {
        Err(Error::Singular {
            kind: SingularKind::NoVelocityConsensus,
            ..
        }) => solution_flow_data(sol, b2, c2, cancel),
        other => other,
    }
}

/// [`flow_data_with`] where the level set gives no velocities unchecked
/// (`c2`: the second flow's `c_ij`, state order): from the solution.
fn solution_flow_data(
    sol: &Solution,
    b2: &[f64; 4],
    c2: [f64; 6],
    cancel: &Cancel,
) -> Result<FlowData> {
    // The frequencies come from U: where its self-check left a velocity
    // defect above the shape's bound (next to pinched curves, where the theta
    // quotients' derivatives are sums of nearly cancelling terms), U and U'
    // are vouched for only if the Abel images of integrated states move along
    // them ([`abel_rate`], at the end).
    //
    // A solution that failed its self-check (kept for its certified l(t),
    // [`Solution::certify_every`]) has its constants C_L, G or divisor in
    // doubt, none of which the frequencies use: they are the coordinates of U
    // in the lattice of the curve's periods. Its U and U' stand only where
    // the Abel images of integrated states vouch for them, which is a check of
    // the curve as well (on a wrong curve the images of the motion do not lie
    // on a line), whether they are the closed forms or the quotients' fits.
    let soft = sol.certify_every();
    let by_abel = soft.is_some() || sol.velocity_check() > FREQUENCY_VELOCITY_RTOL;
    if soft.is_none() && sol.velocity_check() > VELOCITY_CHECK_RTOL {
        // (not reached from a solution that passed its self-check)
        return Err(Error::Unverified {
            what: "frequencies",
            reason: format!(
                "the theta quotients move along U against Frahm's equations (1) by {:e} of \
                 the largest speed (> {VELOCITY_CHECK_RTOL:e})",
                sol.velocity_check()
            ),
        });
    }
    let t = sol.tau();
    let chars: Vec<Char> = sol
        .characteristics()
        .iter()
        .map(|(a, b)| [a[0], a[1], b[0], b[1]])
        .collect();
    // the second flow's rounding errors, for the Abel-map check's integrations
    let c2_lo = crate::solution::normalize::c_rounding(sol.a(), b2, &c2);
    // The velocities themselves in closed form (the solution's sign
    // convention), in double or DD by the curve's spread ([`needs_dd`]), as
    // the frequency map takes them (the same numbers, so the two routes give
    // the same frequencies).
    // Where the closed form refuses (its half periods disagree beyond
    // rounding: the Clebsch contraction's top, one a_i ~ 1e8 and more, whose
    // rounded c_ij are of the form (2) only to ~1e-12 of the flow), the
    // solution's U is its fit, and so is U'.
    let closed = match sol.closed_rates(&[*sol.c4(), c2], needs_dd(sol.curve())) {
        Ok(lat) => Some(lat),
        Err(Error::InvalidArgument {
            what: CLOSED_FORM, ..
        }) => None,
        Err(e) => return Err(e),
    };
    // The top's own flow was checked by `Solution::new` (the same equations);
    // the second flow's fit must hold as well before it defines the real plane,
    // and it must agree with the closed form: within CLOSED_VS_FIT_RTOL, or
    // the closed form satisfies the quotients' equations as well as the fit
    // does (next to a pinched curve the fit is undetermined along one
    // direction; `dubrovin::closed_form_fits`, as `Solution::new` does for U).
    let candidate = closed
        .as_ref()
        .map_or([C::new(0.0, 0.0); 2], |lat| lat.u[1]);
    let ((u2_fit, res), res_closed) = sol.rate_and_residual_of(&c2, &candidate)?;
    let theta_refusal = |reason: String| Error::Singular {
        what: INCONSISTENT,
        kind: SingularKind::InconsistentQuotients,
        reason,
    };
    let refusal = if res.is_nan() || res > QUOTIENT_RESIDUAL_RTOL {
        Some(theta_refusal(format!(
            "the theta quotients (9)-(10) at v0 satisfy Frahm's equations (1) of the second \
             flow for no velocity (least-squares residual {res:e} > \
             {QUOTIENT_RESIDUAL_RTOL:e}): the solution's set-up is wrong at this state; its \
             frequencies would be too"
        )))
    } else if let Some(lat) = closed.as_ref() {
        let u2c = lat.u[1];
        let dev = (u2c[0] - u2_fit[0]).norm().max((u2c[1] - u2_fit[1]).norm())
            / u2_fit[0]
                .norm()
                .max(u2_fit[1].norm())
                .max(f64::MIN_POSITIVE);
        (!closed_form_fits(dev, res_closed, res)).then(|| {
            theta_refusal(format!(
                "the theta quotients (9)-(10) at v0 move along the second flow at a velocity \
                 {dev:e} (relative) away from the closed form, which leaves a residual \
                 {res_closed:e} in their equations against {res:e} for their own fit: the \
                 solution's set-up is wrong at this state; its frequencies would be too"
            ))
        })
    } else {
        None
    };
    // Where the solution's U is the quotients' fit (the closed form refused
    // or missed their equations), the fit is determined only where the
    // quotients depend on u: next to a pinched curve they hardly see one
    // direction, and the Abel images decide (FIT_PINCHED_IM_TAU).
    let by_abel = by_abel || (closed.is_none() && largest_im_tau(&t) > FIT_PINCHED_IM_TAU);
    let (mut u, mut u2, mut w) = match closed.as_ref() {
        Some(lat) => (lat.u[0], lat.u[1], Some(lat.w[0])),
        None => (sol.rate(), u2_fit, None),
    };
    if let Some(refusal) = refusal {
        // Where the quotients' second flow at v0 disagrees with the closed
        // form (or fits no velocity), the closed form stands only if the Abel
        // images of integrated states move along U and U' (next to pinched
        // curves the quotients' derivatives lose their digits; the shape of
        // the quotients, which fixes the lattice of periods of l, passed the
        // self-check). Where there is no closed form, the quotients' fits are
        // checked the same way, or replaced by the velocities the images move
        // at (on the harsh draw four such states have their frequencies so;
        // three compared against a quadruple-precision Abel fit: within
        // 6.3e-12).
        match abel_check(sol, (&c2, &c2_lo), &u, &u2, closed.is_some(), cancel) {
            Ok(checked) => (u, u2, w) = (checked.u, checked.u2, checked.w.or(w)),
            Err(Error::Unverified { .. }) => return Err(refusal),
            Err(e) => return Err(e),
        }
    } else if by_abel {
        let checked = abel_check(sol, (&c2, &c2_lo), &u, &u2, closed.is_some(), cancel)?;
        (u, u2, w) = (checked.u, checked.u2, checked.w.or(w));
    }
    Ok(FlowData {
        tau: [[t[0], t[1]], [t[2], t[3]]],
        u,
        u2,
        chars,
        w,
    })
}

/// The velocities checked by the Abel images of integrated states.
struct Checked {
    u: [C; 2],
    u2: [C; 2],
    /// Where `U` is the velocity fitted to the images: its lattice
    /// coordinates ([`FlowData::w`]).
    w: Option<[f64; 4]>,
}

/// `U` and `U'` (the flows with coefficients `sol.c4()` and `c2`) checked by
/// the Abel images of integrated states ([`abel_rate`]) to
/// [`ABEL_RATE_RTOL`] and [`ABEL_SECOND_FLOW_RTOL`] (an unchecked `U'`
/// left to the lattice basis), for a solution whose theta quotients'
/// velocity check did not hold them to it, whose `U` is their fit next to a
/// pinched curve, or that failed its self-check (`u_closed`: whether `U` is
/// the closed form, for the message). Where the images move along another
/// velocity, on a line to within the same bound, that velocity replaces the
/// given one.
fn abel_check(
    sol: &Solution,
    (c2, c2_lo): (&[f64; 6], &[f64; 6]),
    u: &[C; 2],
    u2: &[C; 2],
    u_closed: bool,
    cancel: &Cancel,
) -> Result<Checked> {
    // `U = X + τY` of lattice coordinates `(X1, X2, Y1, Y2)`
    let velocity = |w: &[f64; 4]| -> [C; 2] {
        let u = sol.curve().lattice_point(&w[..2], &w[2..]);
        [u[0], u[1]]
    };
    // the given velocity where the images hold it to `rtol`, else the one
    // fitted to them where that holds to `rtol`
    let decide = |r: AbelRate, given: &[C; 2], rtol: f64| match r.fit {
        _ if r.defect <= rtol => (r.defect, *given, None),
        Some((w, bound)) if bound <= rtol => (bound, velocity(&w), Some(w)),
        Some((_, bound)) => (r.defect.min(bound), *given, None),
        None => (r.defect, *given, None),
    };
    let r1 = abel_rate(sol, sol.c4(), sol.c4_lo(), u, ABEL_RATE_RTOL, cancel)?;
    let (d1, u, w) = decide(r1, u, ABEL_RATE_RTOL);
    let (d2, u2) = if d1 <= ABEL_RATE_RTOL {
        let r2 = abel_rate(sol, c2, c2_lo, u2, ABEL_SECOND_FLOW_RTOL, cancel)?;
        let (d2, u2, _) = decide(r2, u2, ABEL_SECOND_FLOW_RTOL);
        (d2, u2)
    } else {
        (f64::NAN, *u2)
    };
    // Where U' could not be checked (its flow beyond the integrations' budget,
    // or too few of its states that the Abel map takes), the lattice basis
    // decides: U' only fixes the real plane, and a plane off by more than
    // ~RATIONAL_TOL holds no rank-2 lattice of integer vectors (the torus is
    // then refused as "no real lattice"), while the basis found in a plane
    // within it is the same integer vectors; the frequencies are U's
    // coordinates in that basis.
    if d1 <= ABEL_RATE_RTOL && (d2 <= ABEL_SECOND_FLOW_RTOL || d2.is_nan()) {
        return Ok(Checked { u, u2, w });
    }
    // the failing flow's defect (NaN: the check could not be made)
    let (worst, which, bound) = if d1 <= ABEL_RATE_RTOL {
        (d2, "U'", ABEL_SECOND_FLOW_RTOL)
    } else {
        (d1, "U", ABEL_RATE_RTOL)
    };
    let abel = if worst.is_nan() {
        format!(
            "the Abel images of integrated states could not check {which} (an integration \
             beyond its budget, or a state the Abel map refuses)"
        )
    } else {
        format!(
            "the Abel images of integrated states move along {which}, or along a velocity \
             fitted to them, only to {worst:e} (relative, > {bound:e})"
        )
    };
    let thetas = if let Some(why) = sol.certify_every() {
        format!(
            "{why}; U is {}",
            if u_closed {
                "its closed form"
            } else {
                "the theta quotients' fit at v0"
            }
        )
    } else if sol.velocity_check() > FREQUENCY_VELOCITY_RTOL {
        format!(
            "the theta quotients move along U against Frahm's equations (1) by {:e} of the \
             largest speed (> {FREQUENCY_VELOCITY_RTOL:e})",
            sol.velocity_check()
        )
    } else {
        "U is the theta quotients' least-squares fit at v0 (the closed form of U refused), \
         which next to a pinched curve they leave undetermined along a direction they hardly \
         depend on"
            .to_string()
    };
    Err(Error::Unverified {
        what: "frequencies",
        reason: format!(
            "{thetas}, and {abel}: U's frequencies are not vouched for to \
             {FREQUENCY_VELOCITY_RTOL:e}"
        ),
    })
}

/// The status code of an error of [`Solution::new`].
pub fn classify(e: &Error) -> Status {
    match e {
        Error::Singular { kind, .. } => match kind {
            SingularKind::ZeroState => Status::ZeroState,
            SingularKind::SelfDual => Status::SingularCasimirs,
            // h0 = 0 is d_0 = 0 meeting another d_j; a double root of F (19)
            // drops the genus alike (a separatrix).
            SingularKind::VanishingH0
            | SingularKind::CoincidingBranchPoints
            | SingularKind::RepeatedRoot => Status::CoincidingBranchPoints,
            SingularKind::DivisorAtInfinity => Status::DivisorAtInfinity,
            SingularKind::DegenerateGradients => Status::DegenerateGradients,
            SingularKind::InconsistentQuotients => Status::InconsistentQuotients,
            SingularKind::NoVelocityConsensus => Status::Singular,
        },
        Error::NoRealTorus { failure } => Status::from(*failure),
        Error::RepeatedBranchPoints { .. } => Status::CoincidingBranchPoints,
        Error::NoConvergence { .. } => Status::NoConvergence,
        Error::NonFinite { .. } => Status::NonFinite,
        _ => Status::Singular,
    }
}

/// `τ`, `U`, `U'` and the characteristics from the level set of `l0` alone:
/// the reduction's constants, the curve and its periods, and the velocities
/// of the top `(a, b)` and of the second flow `(a, b2)` in closed form
/// ([`half_period_velocities`], the lattice coordinates in DD with the real
/// structure imposed), or where that refuses by the chain rule at auxiliary
/// divisors ([`algebraic_rates`]). `U` and `U'` share one sign convention; the
/// frequencies do not depend on it (the basis is oriented so that `ν ≥ 0`).
pub fn level_set_flow_data(
    a: &[f64; 4],
    b: &[f64; 4],
    b2: &[f64; 4],
    l0: &[f64; 6],
) -> Result<FlowData> {
    let c4 = c_pairs(a, b)?;
    let c2 = c_pairs(a, b2)?;
    level_set_flow_data_c4(a, &c4, &c2, l0)
}

/// [`level_set_flow_data`] with the `c_ij` of the top (`c4`) and of the
/// second flow (`c2`) given directly (state order), e.g. normalized ones.
pub fn level_set_flow_data_c4(
    a: &[f64; 4],
    c4: &[f64; 6],
    c2: &[f64; 6],
    l0: &[f64; 6],
) -> Result<FlowData> {
    level_set_flow_data_route(a, c4, c2, l0, None)
}

/// [`level_set_flow_data_c4`] with the route forced: `Some(true)` DD,
/// `Some(false)` double, `None` by [`needs_dd`] (the tests compare them).
pub(crate) fn level_set_flow_data_route(
    a: &[f64; 4],
    c4: &[f64; 6],
    c2: &[f64; 6],
    l0: &[f64; 6],
    route: Option<bool>,
) -> Result<FlowData> {
    let (c4, c2) = (*c4, *c2);
    let ls = level_set_curve(a, l0)?;
    let spread = ls.curve.spread();
    if spread.is_nan() || spread > CLOSED_FORM_SPREAD {
        return Err(Error::Singular {
            what: CLOSED_FORM,
            kind: SingularKind::NoVelocityConsensus,
            reason: format!(
                "the branch points of (8) spread over {:e} (> {CLOSED_FORM_SPREAD:e}): the level \
                 set's closed form is not checked there; the Theorem's solution checks it",
                spread
            ),
        });
    }
    // In double with the curve's double periods where the branch points are
    // spread over less than DD_SPREAD (frequencies to ~5e-15), else in DD on
    // the unrounded branch points ([`needs_dd`]); `flow_data` takes the same
    // numbers.
    let dd = route.unwrap_or_else(|| needs_dd(&ls.curve));
    let (rates, w) = match half_period_velocities(&ls.kotter, l0, &[c4, c2], dd) {
        Ok(hp) => {
            let e_lo = if dd {
                hp.branch_point_errors(&ls.curve)
            } else {
                None
            };
            let lat = lattice_rates_dd(&ls.curve, e_lo.as_ref().map(|e| &e[..]), &hp.v_dd)?;
            let w = lat.w[0];
            (lat.u, Some(w))
        }
        Err(Error::InvalidArgument {
            what: CLOSED_FORM, ..
        }) => (
            algebraic_rates(&ls.kotter, &ls.kcurve, &a_periods_of(&ls.curve), &[c4, c2])?.rates,
            None,
        ),
        Err(e) => return Err(e),
    };
    let t = ls.curve.tau_row_major();
    Ok(FlowData {
        tau: [[t[0], t[1]], [t[2], t[3]]],
        u: rates[0],
        u2: rates[1],
        chars: ls
            .chars
            .iter()
            .map(|(a, b)| [a[0], a[1], b[0], b[1]])
            .collect(),
        w,
    })
}

/// Status and `(ν1, ν2)` of the state `l0` of the top `(a, b)`, from the
/// level set ([`level_set_flow_data`]); where the auxiliary divisors do not
/// reach a consensus on the velocities (none is known), through the
/// Theorem's solution ([`state_frequencies_theta`]).
///
/// The state is first normalized and classified
/// ([`super::motion::state_frequencies_in`]): equilibria, separatrices and
/// `l0 = 0` get their status, Euler motions their closed-form frequencies,
/// and genus-2 states this level-set route on the normalized data.
pub fn state_frequencies(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> MapEntry {
    match crate::solution::normalize::TopFrame::new(a, b) {
        Ok(frame) => super::motion::state_frequencies_in(&frame, l0),
        Err(e) => super::MapEntry::failed(classify(&e)),
    }
}

/// The level-set route of [`state_frequencies`] on the data as given (no
/// normalization, no classification).
pub fn state_frequencies_level_set(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> MapEntry {
    match c_pairs(a, b) {
        Ok(c4) => level_set_entry(a, &c4, &second_flow_b(a, b), l0),
        Err(e) => MapEntry::failed(classify(&e)),
    }
}

/// Status and `(ν1, ν2)` of the state `l0` of the top with parameters `a`
/// and coefficients `c4` (state order), the second flow `b2`: from the level
/// set ([`level_set_flow_data_c4`]); where the auxiliary divisors do not reach
/// a consensus on the velocities, through the Theorem's solution
/// ([`flow_data`]).
pub fn level_set_entry(a: &[f64; 4], c4: &[f64; 6], b2: &[f64; 4], l0: &[f64; 6]) -> MapEntry {
    level_set_entry_with(a, c4, &[0.0; 6], b2, l0, &Cancel::never())
}

/// [`level_set_entry`] with a cancellation token ([`flow_data_with`]) and the
/// rounding errors `c4_lo` of `c4`, which the Theorem's solution takes where
/// the level set gives no velocities ([`Solution::with_c4_lo_certifying`], as
/// `sol.torus` does: the two give the same frequencies).
pub fn level_set_entry_with(
    a: &[f64; 4],
    c4: &[f64; 6],
    c4_lo: &[f64; 6],
    b2: &[f64; 4],
    l0: &[f64; 6],
    cancel: &Cancel,
) -> MapEntry {
    let c2 = match c_pairs(a, b2) {
        Ok(c2) => c2,
        Err(e) => return MapEntry::failed(classify(&e)),
    };
    frequencies_of_state(
        l0,
        |l| match level_set_flow_data_c4(a, c4, &c2, l) {
            Err(Error::Singular {
                kind: SingularKind::NoVelocityConsensus,
                ..
            }) => Solution::with_c4_lo_certifying(a, c4, c4_lo, l)
                .and_then(|s| solution_flow_data(&s, b2, c2, cancel)),
            other => other,
        },
        classify,
    )
}

/// The frequency map of the top `(a, b)` over `states`: [`state_frequencies`]
/// of each, in parallel ([`super::map_states`], `cancel` checked between
/// waves). The top's normalized frame is built once for all states.
///
/// Errors: an invalid top (non-finite `a`, `b`, repeated `a_i`: an argument
/// error, not a status); `Interrupted`.
pub fn frequency_map(
    a: &[f64; 4],
    b: &[f64; 4],
    states: &[[f64; 6]],
    cancel: &Cancel,
) -> Result<Vec<MapEntry>> {
    crate::error::check_finite("a", a)?;
    crate::error::check_finite("b", b)?;
    // The top itself must be valid (distinct a_i): an argument error, not a status.
    let frame = crate::solution::normalize::TopFrame::new(a, b)?;
    super::map_states(
        states,
        |l0| super::motion::state_frequencies_in_with(&frame, l0, cancel),
        cancel,
    )
}

/// [`state_frequencies`] through the Theorem's solution ([`flow_data`]):
/// the frequencies of `sol.torus` (the route of `torus_of_state`).
pub fn state_frequencies_theta(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> MapEntry {
    let b2 = second_flow_b(a, b);
    frequencies_of_state(
        l0,
        |l| Solution::new(a, b, l).and_then(|s| flow_data(&s, &b2)),
        classify,
    )
}

/// The velocity `U'` of the flow of the Manakov top with coefficients `c4'`
/// on the level set of `sol`, without a second solution
/// ([`Solution::rates`]: the equations that give `U`, with the right-hand side
/// of (1) for `c4'`).
pub fn rate_for(sol: &Solution, c4: &[f64; 6]) -> Result<[C; 2]> {
    Ok(sol.rates(&[*c4])?[0].0)
}

pub use crate::solution::{INCONSISTENT, QUOTIENT_RESIDUAL_RTOL};

/// The real torus of the state `l0` of the top `(a, b)` and the second
/// velocity `U'`, or the error that stopped it: invalid input, the solution's
/// refusal, or the torus's own ([`Error::Unverified`] naming the step: a
/// valid state whose torus could not be verified).
///
/// Through the dispatcher ([`crate::solution::motion::Motion`]): the torus of
/// a genus-2 state of the normalized top, frequencies in the user's time; a
/// state of another kind has no genus-2 torus and is refused, naming its kind.
pub fn torus_of_state(
    a: &[f64; 4],
    b: &[f64; 4],
    l0: &[f64; 6],
    cancel: &Cancel,
) -> Result<(RealTorus, [C; 2])> {
    let m = crate::solution::motion::Motion::new(a, b, l0)?;
    super::motion::torus_of_motion(&m, cancel)
}
