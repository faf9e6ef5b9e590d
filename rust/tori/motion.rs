//! Frequencies of every kind of state ([`crate::solution::motion`];
//! docs/degenerate.md §5): the frequency map and `sol.torus` classify the
//! state first, on the normalized top.
//!
//! | kind | status | `(ν1, ν2)` |
//! |---|---|---|
//! | genus-2 | as before ([`super::solve`]), on the normalized data; where it refuses, the routes next to degenerate sets ([`super::near_euler`]), then the closed orbits ([`super::closed_orbits`]) | the real torus's, times `T` |
//! | Euler (block or self-dual) | [`Status::Ok`] | `(ν_E, ν_⊥)` of [`crate::solution::transverse`] |
//! | separatrix | [`Status::Separatrix`] | NaN |
//! | equilibrium, spherical top | [`Status::Equilibrium`] | NaN |
//! | `l0 = 0` | [`Status::ZeroState`] | NaN |
//!
//! Frequencies are in cycles per unit of the user's time: the normalized
//! problem's times `T` (`t' = T t`, [`Motion::time_scale`]).

use num_complex::Complex64 as C;

use super::closed_orbits::closed_orbit_frequencies;
use super::near_euler::near_euler_frequencies;
use super::solve::{classify as classify_error, flow_data_with, level_set_entry_with};
use super::{real_torus_with_rates, MapEntry, RealTorus, Status};
use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;
use crate::solution::motion::{classify, refusal_of, Kind, Motion};
use crate::solution::normalize::TopFrame;
use crate::solution::transverse::euler_frequencies_with;

/// Status and `(ν1, ν2)` of the state `l0` of the top with frame `frame`
/// (see the module table). Nothing here panics or raises.
pub fn state_frequencies_in(frame: &TopFrame, l0: &[f64; 6]) -> MapEntry {
    state_frequencies_in_with(frame, l0, &Cancel::never())
}

/// [`state_frequencies_in`] with a cancellation token, checked inside the
/// (up to ~0.1 s) monodromy of an Euler state; when it fires the entry is a
/// failure and the caller's next check stops the map.
pub fn state_frequencies_in_with(frame: &TopFrame, l0: &[f64; 6], cancel: &Cancel) -> MapEntry {
    let entry = state_frequencies_plain(frame, l0, cancel);
    if !near_euler_may_answer(entry.status) {
        return entry;
    }
    // Next to an so(3) block the level set's route refuses on pinched curves,
    // next to the self-dual states where h1² = 4h0² to rounding; the
    // frequencies there are the interpolation between the Euler motion of the
    // nearest state of that subspace and states farther out
    // (docs/degenerate.md §11).
    match near_euler_frequencies(frame, l0, cancel) {
        Ok(nu) => MapEntry {
            status: Status::Ok,
            nu,
        },
        // Where those refuse too, the frequencies' definition: the closed
        // orbits of the two commuting flows (docs/degenerate.md §11).
        Err(Error::Interrupted) => entry,
        Err(_) => match closed_orbit_frequencies_of_state(frame, l0, cancel) {
            Ok(nu) => MapEntry {
                status: Status::Ok,
                nu,
            },
            Err(_) => entry,
        },
    }
}

/// [`closed_orbit_frequencies`] of the user's state `l0`, per unit of the
/// user's time.
pub fn closed_orbit_frequencies_of_state(
    frame: &TopFrame,
    l0: &[f64; 6],
    cancel: &Cancel,
) -> Result<[f64; 2]> {
    let (_, scale, ln) = classify(frame, l0);
    let t_scale = scale * frame.lambda;
    closed_orbit_frequencies(frame, &ln, cancel).map(|nu| nu.map(|v| v * t_scale))
}

/// Whether a genus-2 state refused with this status may be answered by
/// [`near_euler_frequencies`]: a refusal of the level set's route (singular
/// Casimirs included: a state next to, not on, the self-dual states), not a
/// class of the state (equilibria, separatrices, non-finite or zero states
/// keep their status).
fn near_euler_may_answer(status: Status) -> bool {
    !matches!(
        status,
        Status::Ok
            | Status::ZeroState
            | Status::NonFinite
            | Status::Equilibrium
            | Status::Separatrix
    )
}

/// [`state_frequencies_in_with`] without the interpolation next to Euler
/// subspaces: the classification's route alone (the interpolation's own nodes).
pub(crate) fn state_frequencies_plain(
    frame: &TopFrame,
    l0: &[f64; 6],
    cancel: &Cancel,
) -> MapEntry {
    if l0.iter().any(|v| !v.is_finite()) {
        return MapEntry::failed(Status::NonFinite);
    }
    let (kind, scale, ln) = classify(frame, l0);
    let t_scale = scale * frame.lambda;
    match kind {
        Kind::Rest => MapEntry::failed(Status::ZeroState),
        Kind::Spherical | Kind::Equilibrium => MapEntry::failed(Status::Equilibrium),
        Kind::Separatrix => MapEntry::failed(Status::Separatrix),
        // Not a class of `classify` (a motion's body decides it).
        Kind::Integrated => MapEntry::failed(Status::Singular),
        Kind::Euler => {
            match Motion::in_frame(frame.clone(), l0)
                .and_then(|m| euler_frequencies_with(&m, cancel))
            {
                Ok(nu) if nu.iter().all(|v| v.is_finite()) => MapEntry {
                    status: Status::Ok,
                    nu,
                },
                Ok(_) => MapEntry::failed(Status::Singular),
                Err(e) => MapEntry::failed(classify_error(&e)),
            }
        }
        Kind::Genus2 => {
            let entry = level_set_entry_with(
                &frame.a,
                &frame.c4,
                &frame.c4_lo,
                &frame.second_flow_b(),
                &ln,
                cancel,
            );
            if entry.status == Status::Ok && t_scale != 1.0 {
                MapEntry {
                    status: Status::Ok,
                    nu: entry.nu.map(|v| v * t_scale),
                }
            } else {
                entry
            }
        }
    }
}

/// The real torus of a genus-2 motion and the second velocity `U'`, both in
/// the normalized frame except the frequencies, which are per unit of the
/// user's time.
///
/// `cancel` reaches the integrations of the Abel-map check of the velocities.
///
/// Errors: a motion of another kind (the message names it; those have no
/// 2-torus), and those of [`flow_data_with`] and [`real_torus_with_rates`].
pub fn torus_of_motion(m: &Motion, cancel: &Cancel) -> Result<(RealTorus, [C; 2])> {
    if m.kind() == Kind::Integrated {
        return Err(Error::Unverified {
            what: "torus of this l0",
            reason: format!("{}; its frequencies are not known", m.stand_ins().1),
        });
    }
    let sol = m.genus2().ok_or_else(|| Error::InvalidArgument {
        what: "state l0",
        reason: format!(
            "the motion is of kind '{}': it has no genus-2 torus (its frequencies are those of \
             the closed form)",
            m.kind().name()
        ),
    })?;
    let torus = flow_data_with(sol, &m.frame().second_flow_b(), cancel).and_then(|d| {
        Ok((
            real_torus_with_rates(&d.tau, &d.u, &d.u2, &d.chars, d.w.as_ref())?,
            d.u2,
        ))
    });
    let (mut t, u2) = torus.map_err(torus_refusal)?;
    t.nu = t.nu.map(|v| v * m.time_scale());
    Ok((t, u2))
}

/// An error of the torus of a valid genus-2 motion: a refusal
/// ([`Error::Unverified`], Python's `ClosedFormError`) naming the step, not
/// invalid input, as the set-up's own refusals.
fn torus_refusal(e: Error) -> Error {
    refusal_of(
        "torus of this l0",
        "its solution l(t) stands; its frequencies are not known",
        e,
    )
}
