//! # manakov
//!
//! The free rigid body in four dimensions — Frahm's equations in Manakov's
//! integrable case — and its explicit solution in genus-2 Riemann theta
//! functions, after A. M. Perelomov, *Motion of four-dimensional rigid body
//! around a fixed point: an elementary approach* (equation numbers are the
//! paper's).
//!
//! The modules follow the paper's chain of data, each depending only on those
//! before it:
//!
//! state `l` ([`so4`], [`integrate`]) → Schottky's `l(s)`, `f(s)` and Kötter's
//! `ξ, η, d_j` ([`kotter`]) → points on the curve (8) and the Abel map
//! ([`curve`]) → theta functions ([`theta`]) → real tori and frequency maps
//! ([`tori`]).
//!
//! The crate is pure Rust; the Python bindings live behind the `python`
//! feature in a private module.

pub mod curve;
pub mod error;
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
