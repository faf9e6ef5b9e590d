//! The frequency map on the Theorem's solution ([`crate::solution`]).

use num_complex::Complex64 as C;

use super::{
    frequencies_of_state, real_torus, second_flow_b, Char, FlowData, MapEntry, RealTorus, Status,
};
use crate::error::{Error, Result, SingularKind};
use crate::so4;
use crate::solution::Solution;

/// The six `c_ij` (`i < j`, state order) of `ManakovTop(a, b)` (2).
pub fn c_pairs(a: &[f64; 4], b: &[f64; 4]) -> Result<[f64; 6]> {
    // manakov_c returns the full 4×4 matrix, row-major.
    let c = so4::manakov_c(a, b)?;
    Ok([c[1], c[2], c[3], c[6], c[7], c[11]])
}

/// `τ`, `U`, `U'` (the flow of `ManakovTop(a, b2)` by [`rate_for`]) and the
/// characteristics of a solution, in the layout of this module.
pub fn flow_data(sol: &Solution, b2: &[f64; 4]) -> Result<FlowData> {
    let t = sol.tau();
    let chars: Vec<Char> = sol
        .characteristics()
        .iter()
        .map(|(a, b)| [a[0], a[1], b[0], b[1]])
        .collect();
    let c2 = c_pairs(sol.a(), b2)?;
    // The top's own flow was checked by `Solution::new` (the same equations);
    // the second flow's fit must hold as well before it defines the real plane.
    let (u2, res) = sol.rates(&[c2])?[0];
    if res.is_nan() || res > QUOTIENT_RESIDUAL_RTOL {
        return Err(Error::InvalidArgument {
            what: INCONSISTENT,
            reason: format!(
                "the theta quotients (9)-(10) at v0 satisfy Frahm's equations (1) of the \
                 second flow for no velocity (least-squares residual {res:e} > \
                 {QUOTIENT_RESIDUAL_RTOL:e}): the solution's set-up is wrong at this state; \
                 its frequencies would be too"
            ),
        });
    }
    Ok(FlowData {
        tau: [[t[0], t[1]], [t[2], t[3]]],
        u: sol.rate(),
        u2,
        chars,
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
        },
        Error::RepeatedBranchPoints { .. } => Status::CoincidingBranchPoints,
        Error::NoConvergence { .. } => Status::NoConvergence,
        Error::NonFinite { .. } => Status::NonFinite,
        Error::InvalidArgument {
            what: INCONSISTENT, ..
        } => Status::InconsistentQuotients,
        _ => Status::Singular,
    }
}

/// Status and `(ν1, ν2)` of the state `l0` of the top `(a, b)`.
pub fn state_frequencies(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> MapEntry {
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
/// velocity `U'`, or the error that stopped it (the solution's, or the
/// lattice's as [`Error::InvalidArgument`]).
pub fn torus_of_state(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> Result<(RealTorus, [C; 2])> {
    let sol = Solution::new(a, b, l0)?;
    let d = flow_data(&sol, &second_flow_b(a, b))?;
    let t = real_torus(&d.tau, &d.u, &d.u2, &d.chars)?;
    Ok((t, d.u2))
}
