//! # manakov
//!
//! The free rigid body in four dimensions — Frahm's equations in Manakov's
//! integrable case — and its explicit solution in genus-2 Riemann theta
//! functions, after A. M. Perelomov, *Motion of four-dimensional rigid body
//! around a fixed point: an elementary approach* (equation numbers are the
//! paper's).
//!
//! The data follow the paper's chain: state `l` → Schottky's `l(s)`, `f(s)` →
//! Kötter's `ξ, η, d_j` → a pair of points on the curve (8) → their Abel map
//! `u` → theta functions → `l(t)` → real tori. The modules, each depending
//! only on those listed before it (no cycle):
//!
//! * [`error`]: the one error type; [`numeric`]: the shared numerics
//!   (compensated arithmetic, double-double, principal roots, the
//!   cancellation token, shared thresholds).
//! * [`so4`]: the top, Frahm's equations (1)–(7); [`integrate`]: their
//!   trajectories.
//! * [`theta`]: Riemann theta functions (34)–(36) for any genus ≤ 6.
//! * [`curve`]: the curve (8) from its branch points `d_j`, the
//!   Wurzelfunktionen (27)–(28) and the inverse of (37), `(ξ, η)` → points.
//! * [`kotter`]: Schottky's `l(s)`, `f(s)` (12)–(18) and Kötter's reduction
//!   (19)–(26), (38)–(42): `l` → `ξ, η, d_j` → the points on [`curve`]'s curve.
//! * [`riemann`]: any hyperelliptic curve: homology basis, periods, `τ`, the
//!   Abel map, the Riemann constant, Jacobi inversion (on [`theta`]).
//! * [`solution`]: the Theorem (9)–(10), `l0` → `(τ, u0, U, constants)` →
//!   `l(t)`, from [`kotter`], [`riemann`] and [`theta`].
//! * [`tori`]: real Liouville tori, frequencies and frequency maps, on
//!   [`solution`].
//! * [`fluid`]: a rigid body in an ideal fluid, Kirchhoff's equations on
//!   e(3) (a field for [`integrate`]), and the Clebsch case through a linear
//!   conjugacy to a Manakov top solved by [`solution`].
//!
//! The crate is pure Rust; the Python bindings live behind the `python`
//! feature in a private module.

pub mod curve;
pub mod error;
pub mod fluid;
pub mod integrate;
pub mod kotter;
pub mod numeric;
pub mod riemann;
pub mod so4;
pub mod solution;
pub mod theta;
pub mod tori;

pub use error::{Error, Result, SingularKind, TorusFailure};

#[cfg(feature = "python")]
mod python;
