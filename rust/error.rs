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
    /// The computation was cancelled (Ctrl-C in Python; see `numeric::cancel`).
    Interrupted,
    /// `count` items of `what` would take `bytes` bytes, more than the `limit`
    /// one call may allocate (`numeric::alloc::MAX_BYTES`); checked before any
    /// work. Python sees a `MemoryError` (as numpy's for an array it cannot
    /// allocate).
    TooLarge {
        what: &'static str,
        count: usize,
        bytes: f64,
        limit: f64,
    },
    /// `bytes` bytes for `what`, within the budget, could not be allocated.
    /// Python sees a `MemoryError`.
    OutOfMemory { what: &'static str, bytes: f64 },
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

/// Bytes in a GiB (sizes in messages).
const GIB: f64 = (1u64 << 30) as f64;

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
                "branch points d{i} and d{j} coincide (= {}): the curve is singular, its genus drops",
                cnum(*value)
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
            Error::TooLarge {
                what,
                count,
                bytes,
                limit,
            } => write!(
                f,
                "cannot allocate {bytes:.0} bytes ({:.4} GiB) for {what} of {count} items: \
                 more than the {:.0} GiB one call may allocate; split the work into smaller calls",
                bytes / GIB,
                limit / GIB
            ),
            Error::OutOfMemory { what, bytes } => write!(
                f,
                "cannot allocate {bytes:.0} bytes ({:.3} GiB) for {what}: out of memory",
                bytes / GIB
            ),
            Error::InRow { row, rows, source } => write!(f, "row {row} of {rows}: {source}"),
        }
    }
}

impl std::error::Error for Error {}

/// Significant digits of a computed number in a message ([`num`], [`cnum`]):
/// enough to recognise a value, no more than a computed double carries after a
/// few operations.
pub const MESSAGE_DIGITS: usize = 10;

/// `x` for a message: [`MESSAGE_DIGITS`] significant digits, trailing zeros
/// dropped, scientific notation outside `1e-4 <= |x| < 1e10` (like C's `%.10g`),
/// so that `1e-12` never prints as `0.000000000001`.
pub fn num(x: f64) -> String {
    num_digits(x, MESSAGE_DIGITS)
}

/// `x` to `digits` significant digits, as [`num`].
fn num_digits(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = digits.max(1);
    let sci = format!("{:.*e}", digits - 1, x);
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if (-4..digits as i32).contains(&exp) {
        let decimals = (digits as i32 - 1 - exp).max(0) as usize;
        trim_zeros(&format!("{x:.decimals$}")).to_string()
    } else {
        format!("{}e{exp}", trim_zeros(mantissa))
    }
}

/// A complex number for a message: each part as [`num`], and a part smaller
/// than the last digit shown of the other (`10^-MESSAGE_DIGITS |z|`) left out
/// as rounding noise, so a real root carrying `-6e-40i` prints as real.
/// Written like Python's complex numbers (`1.5-2j`).
pub fn cnum(z: Complex64) -> String {
    cnum_digits(z, MESSAGE_DIGITS, 0.0)
}

/// `z` known only to about `noise` (absolute; a double root from its computed
/// separation): the digits stop near `noise` (at most [`MESSAGE_DIGITS`]) and a
/// part below it is left out.
pub fn cnum_within(z: Complex64, noise: f64) -> String {
    let size = z.norm();
    let digits = if noise > 0.0 && size > noise {
        ((size / noise).log10().floor() as usize + 1).min(MESSAGE_DIGITS)
    } else if noise > 0.0 {
        1
    } else {
        MESSAGE_DIGITS
    };
    cnum_digits(z, digits, noise)
}

fn cnum_digits(z: Complex64, digits: usize, noise: f64) -> String {
    let cut = (z.norm() * 10f64.powi(-(MESSAGE_DIGITS as i32))).max(noise);
    let re = if z.re.abs() > cut { z.re } else { 0.0 };
    let im = if z.im.abs() > cut { z.im } else { 0.0 };
    match (re == 0.0, im == 0.0) {
        (_, true) => num_digits(re, digits),
        (true, false) => format!("{}j", num_digits(im, digits)),
        (false, false) => {
            let sign = if im < 0.0 { '-' } else { '+' };
            format!(
                "{}{sign}{}j",
                num_digits(re, digits),
                num_digits(im.abs(), digits)
            )
        }
    }
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// A check's refusal `e` that the caller may keep instead ("soft"): with a
/// `slot` its reason is added there (reasons joined by "; ", each naming its
/// step as the set-up's refusals do, without "invalid" or "no trustworthy":
/// the state is valid) and `Ok(())` returned; without one, `Err(e)`. Used where
/// a solution that certifies every `l(t)` by an integration keeps a closed
/// form that failed a check (`crate::solution::Solution::with_c4_lo_certifying`).
pub(crate) fn soften(slot: Option<&mut Option<String>>, e: Error) -> Result<()> {
    let Some(slot) = slot else {
        return Err(e);
    };
    let reason = match e {
        Error::InvalidArgument { what, reason } => format!("{what}: {reason}"),
        Error::Unverified { reason, .. } | Error::Singular { reason, .. } => reason,
        other => other.to_string(),
    };
    *slot = Some(match slot.take() {
        Some(prev) => format!("{prev}; {reason}"),
        None => reason,
    });
    Ok(())
}

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
    fn numbers_in_messages_keep_the_digits_that_matter() {
        assert_eq!(num(1.4070413458937996), "1.407041346");
        assert_eq!(num(1e-12), "1e-12");
        assert_eq!(num(-2.5e20), "-2.5e20");
        assert_eq!(num(0.5), "0.5");
        assert_eq!(num(123456.0), "123456");
        assert_eq!(num(0.00012), "0.00012");
        assert_eq!(num(f64::NAN), "NaN");
        let noisy = Complex64::new(1.4070413458937996, -6.256420825295136e-40);
        assert_eq!(cnum(noisy), "1.407041346");
        assert_eq!(cnum(Complex64::new(-1e-30, 2.0)), "2j");
        assert_eq!(cnum(Complex64::new(0.3, -1.25)), "0.3-1.25j");
        assert_eq!(cnum(Complex64::new(0.0, 0.0)), "0");
        // A double root split by 4.3e-7 into a conjugate pair: its mean, to 8 digits.
        let pair = Complex64::new(5.288422876312, 0.0);
        assert_eq!(cnum_within(pair, 4.3e-7), "5.2884229");
        assert_eq!(cnum_within(Complex64::new(1.0, 2e-7), 4.3e-7), "1");
    }

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
