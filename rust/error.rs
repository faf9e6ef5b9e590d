//! The crate's one error type.
//!
//! Every variant carries the offending numbers so that the message a user
//! sees names what was wrong. The Python layer maps each variant onto an
//! exception in `rust/python/errors.rs` (invalid arguments become
//! `ValueError`, non-convergence becomes `manakov.ConvergenceError`).

use std::fmt;

use num_complex::Complex64;

/// Errors of the `manakov` core.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// An array or vector has the wrong length or shape.
    Shape {
        what: &'static str,
        expected: String,
        got: String,
    },
    /// A NaN or infinity where a finite number is required.
    NonFinite { what: &'static str, index: usize },
    /// Two of the `a_i` coincide, so `c_ij = (b_i - b_j)/(a_i - a_j)` (2) is undefined.
    RepeatedA { i: usize, j: usize, value: f64 },
    /// A matrix that must be symmetric is not.
    NotSymmetric { what: &'static str, max_asym: f64 },
    /// Im τ is not positive definite.
    ImagNotPositiveDefinite { min_eig: f64 },
    /// Two branch points `d_i`, `d_j` of the curve (8) coincide: the genus drops.
    /// The branch points are complex in general, hence `value: Complex64`.
    RepeatedBranchPoints {
        i: usize,
        j: usize,
        value: Complex64,
    },
    /// A state on which the Theorem's genus-2 solution (or the reduction
    /// under it) does not exist: a singular level set or a degenerate divisor.
    /// `kind` says which; the message (worded like [`Error::InvalidArgument`])
    /// names the numbers. Python sees a `ValueError`.
    Singular {
        what: &'static str,
        kind: SingularKind,
        reason: String,
    },
    /// Any other invalid argument, with the reason.
    InvalidArgument { what: &'static str, reason: String },
    /// A valid input whose closed-form result could not be built or did not
    /// pass its own check (`reason` names the step): never returned as a
    /// result. Python sees `manakov.ClosedFormError`.
    Unverified { what: &'static str, reason: String },
    /// An iteration did not reach its tolerance.
    NoConvergence {
        what: &'static str,
        tol: f64,
        reached: f64,
        iterations: usize,
    },
    /// No real torus carries the motion (the frequency maps, `crate::tori`):
    /// `failure` says why. Python sees a `ValueError`.
    NoRealTorus { failure: TorusFailure },
    /// The computation was cancelled (Ctrl-C in Python; see [`crate::numeric::cancel`]).
    Interrupted,
    /// Row `row` of a batch of `rows` failed with `source` (Python sees the
    /// exception of `source`, its message prefixed with the row).
    InRow {
        row: usize,
        rows: usize,
        source: Box<Error>,
    },
}

/// Why a state has no genus-2 theta-function solution ([`Error::Singular`]).
///
/// The frequency maps (`crate::tori`) turn the kind into a status code, so a
/// kind is part of the API; the message stays free text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum SingularKind {
    /// `l0 = 0`: the rest state, no curve (8).
    ZeroState,
    /// `h0 = 0`: the branch point `d_0 = 0` meets another `d_j`.
    VanishingH0,
    /// `h1² = 4h0²` (`m = ±n`): `F` of (19) is undefined.
    SelfDual,
    /// Two branch points `d_i`, `d_j` of (8) coincide (`d_j = 0` meets
    /// `d_0`, `d_j = ∞` the branch point at infinity), or a root of `F` (19)
    /// meets an `a_j`: the genus drops.
    CoincidingBranchPoints,
    /// `F(s)` of (19) has a repeated root (a separatrix): the genus drops.
    RepeatedRoot,
    /// The divisor of `l0` contains the point at infinity (`θ(v0) = 0`).
    DivisorAtInfinity,
    /// The theta-quotient gradients at `v0` do not determine `U`.
    DegenerateGradients,
    /// The solution's theta quotients reproduce `l0` but solve Frahm's
    /// equations (1) at `v0` for no velocity: its set-up is wrong at this state.
    InconsistentQuotients,
    /// The auxiliary divisors of the level-set route (`crate::solution::velocity`)
    /// do not agree on the velocities; the solution's own route may still succeed.
    NoVelocityConsensus,
}

/// Why no real torus carries a motion ([`Error::NoRealTorus`]); the frequency
/// maps turn it into a status code. The message (`Display`) is in
/// `crate::tori`, beside the tolerances it cites.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum TorusFailure {
    /// A non-finite entry in `τ`, `U` or `U'`.
    NonFinite,
    /// `Im τ` is not positive definite.
    ImagTauNotPositive,
    /// `U` and `U'` are (nearly) R-linearly dependent: `sin_angle` between them.
    DegeneratePlane { sin_angle: f64 },
    /// The integer kernel of the projection could not be recognised: no
    /// denominator `≤ tori::MAX_DENOMINATOR` makes it integral to
    /// `tori::RATIONAL_TOL` (`residual` at the best one). The orbit is then not
    /// on a compact real 2-torus (or `U'` is not a flow of the same family).
    NoRealLattice { residual: f64 },
}

/// `Result` with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Shape {
                what,
                expected,
                got,
            } => write!(f, "{what}: expected shape {expected}, got {got}"),
            Error::NonFinite { what, index } => {
                write!(f, "{what} must be finite; entry {index} is NaN or infinite")
            }
            Error::RepeatedA { i, j, value } => write!(
                f,
                "a[{i}] == a[{j}] == {value}: the a_i must be distinct, \
                 c_ij = (b_i - b_j)/(a_i - a_j) (2) is undefined"
            ),
            Error::NotSymmetric { what, max_asym } => {
                write!(f, "{what} must be symmetric; max |M - M^T| = {max_asym:e}")
            }
            Error::ImagNotPositiveDefinite { min_eig } => write!(
                f,
                "Im tau must be positive definite; its smallest eigenvalue is {min_eig:e}"
            ),
            Error::RepeatedBranchPoints { i, j, value } => write!(
                f,
                "branch points d{i} and d{j} coincide (= {value}): the curve is singular, its genus drops"
            ),
            // The same text as the `InvalidArgument` these once were.
            Error::Singular { what, reason, .. } | Error::InvalidArgument { what, reason } => {
                write!(f, "invalid {what}: {reason}")
            }
            Error::Unverified { what, reason } => write!(f, "no trustworthy {what}: {reason}"),
            Error::NoConvergence {
                what,
                tol,
                reached,
                iterations,
            } => write!(
                f,
                "{what} did not converge: tolerance {tol:e}, reached {reached:e} after {iterations} iterations"
            ),
            Error::NoRealTorus { failure } => write!(f, "invalid real torus: {failure}"),
            Error::Interrupted => write!(f, "interrupted"),
            Error::InRow { row, rows, source } => write!(f, "row {row} of {rows}: {source}"),
        }
    }
}

impl std::error::Error for Error {}

/// Checks that every entry of `x` is finite.
pub fn check_finite(what: &'static str, x: &[f64]) -> Result<()> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::NonFinite { what, index }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_finite_names_the_entry() {
        assert_eq!(check_finite("l", &[1.0, 2.0]), Ok(()));
        assert_eq!(
            check_finite("l", &[1.0, f64::NAN]),
            Err(Error::NonFinite {
                what: "l",
                index: 1
            })
        );
    }

    #[test]
    fn messages_carry_the_numbers() {
        let e = Error::RepeatedA {
            i: 0,
            j: 2,
            value: 1.5,
        };
        assert!(e.to_string().contains("a[0] == a[2] == 1.5"));
    }

    #[test]
    fn singular_reads_like_an_invalid_state() {
        let e = Error::Singular {
            what: "state l0",
            kind: SingularKind::SelfDual,
            reason: "h1^2 - 4 h0^2 = 0e0 vanishes".into(),
        };
        let old = Error::InvalidArgument {
            what: "state l0",
            reason: "h1^2 - 4 h0^2 = 0e0 vanishes".into(),
        };
        assert_eq!(e.to_string(), old.to_string());
    }
}
