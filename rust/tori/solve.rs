//! The frequency map on the Theorem's solution ([`crate::solution`]).

use nalgebra::{DMatrix, DVector};
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
    // The top's own flow as a check: the quotients must solve (1) at v0 for
    // some velocity. A set-up that reproduces l0 but not l̇0 (the Theorem's
    // silent outliers) fails here, before it yields wrong frequencies.
    let fits = velocities(sol, &[*sol.c4(), c2])?;
    let worst = fits[0].1.max(fits[1].1);
    if worst.is_nan() || worst > QUOTIENT_RESIDUAL_RTOL {
        return Err(Error::InvalidArgument {
            what: INCONSISTENT,
            reason: format!(
                "the theta quotients (9)-(10) at v0 satisfy Frahm's equations (1) for no \
                 velocity (least-squares residual {worst:e} > {QUOTIENT_RESIDUAL_RTOL:e}): \
                 the solution's set-up is wrong at this state; its frequencies would be too"
            ),
        });
    }
    Ok(FlowData {
        tau: [[t[0], t[1]], [t[2], t[3]]],
        u: sol.rate(),
        u2: fits[1].0,
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
/// on the level set of `sol`, without a second solution: `l_q = Re(N_q/D)`
/// (9)–(10) and `d l_q/dt = (∇N_q − l_q ∇D)·U' / D` at `v0` with `l̇` from
/// Frahm's equations (1) for `c4'`, a 6 × 2 complex least-squares problem —
/// the same equations the solution solves for its own `U`, with another
/// right-hand side (the curve, the divisor and the quotients depend on `a`
/// and `l0` only).
pub fn rate_for(sol: &Solution, c4: &[f64; 6]) -> Result<[C; 2]> {
    Ok(velocities(sol, &[*c4])?[0].0)
}

pub use crate::solution::{INCONSISTENT, QUOTIENT_RESIDUAL_RTOL};

/// The velocities of the flows with coefficients `c4s` on the level set of
/// `sol` (see [`rate_for`]), one SVD for all, each with the relative
/// residual of its least-squares fit.
pub fn velocities(sol: &Solution, c4s: &[[f64; 6]]) -> Result<Vec<([C; 2], f64)>> {
    let (idx, num, den) = sol.quotient();
    let plan = sol.plan();
    let (u0, rc) = (sol.u0(), sol.riemann_constant());
    let v0 = [u0[0] + rc[0], u0[1] + rc[1]];
    let jet = plan.jet(&v0, 1)?;
    let theta = |m: usize| jet.values[idx[m]];
    let grad = |m: usize, k: usize| jet.gradient[idx[m] * 2 + k];
    let dval: C = (0..8).map(|m| den[m] * theta(m)).sum();
    let dgrad: [C; 2] = std::array::from_fn(|k| (0..8).map(|m| den[m] * grad(m, k)).sum());
    let mut amat = DMatrix::<C>::zeros(6, 2);
    let mut weight = [0.0; 6];
    for q in 0..6 {
        let nval: C = (0..8).map(|m| num[q][m] * theta(m)).sum();
        let lq = nval / dval;
        let row: [C; 2] = std::array::from_fn(|k| {
            (0..8).map(|m| num[q][m] * grad(m, k)).sum::<C>() - lq * dgrad[k]
        });
        // Rows scaled by the gradient only (not by the right-hand side), so
        // that the weights, and hence the fit, are the same for every flow.
        let w = row[0].norm().max(row[1].norm());
        if w > 0.0 {
            weight[q] = 1.0 / w;
            amat[(q, 0)] = row[0] / w;
            amat[(q, 1)] = row[1] / w;
        }
    }
    let svd = amat.clone().svd(true, true);
    let mut out = Vec::with_capacity(c4s.len());
    for c4 in c4s {
        let ldot = so4::vector_field4(c4, sol.l0());
        let rhs = DVector::<C>::from_fn(6, |q, _| C::new(ldot[q], 0.0) * dval * weight[q]);
        let x = svd.solve(&rhs, 0.0).map_err(|e| Error::InvalidArgument {
            what: "U'",
            reason: e.to_string(),
        })?;
        let u = [x[0], x[1]];
        if !u.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
            return Err(Error::NonFinite {
                what: "U'",
                index: 0,
            });
        }
        let res = (&amat * &x - &rhs).norm() / rhs.norm();
        out.push((u, res));
    }
    Ok(out)
}

/// The real torus of the state `l0` of the top `(a, b)` and the second
/// velocity `U'`, or the error that stopped it (the solution's, or the
/// lattice's as [`Error::InvalidArgument`]).
pub fn torus_of_state(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> Result<(RealTorus, [C; 2])> {
    let sol = Solution::new(a, b, l0)?;
    let d = flow_data(&sol, &second_flow_b(a, b))?;
    let t = real_torus(&d.tau, &d.u, &d.u2, &d.chars)?;
    Ok((t, d.u2))
}
