//! Shared numerics, below every layer of the chain: each item is defined once
//! here and used by the layers above (statrs' `prec.rs` is the model).
//!
//! * [`compensated`]: error-free transformations — Knuth's `two_sum`,
//!   Dekker's `fast_two_sum`, Veltkamp's `split` and Dekker's `two_prod`.
//! * [`dd`]: double-double real and complex numbers built on them (the
//!   reduction's level-set constants, `crate::kotter`; the separatrix test and
//!   `1 − m` of the Euler tops, `crate::solution::euler`).
//! * `dd_fn`: `exp` and the circular functions in double-double (the theta
//!   series of the precise evaluation, `crate::theta::dd`).
//! * [`first_order`]: complex values with their first-order rounding error
//!   (compensated arithmetic; the double-double periods' node sums).
//! * [`complex`]: the principal square root with the crate's one branch cut
//!   and Smith's complex division.
//! * [`cancel`]: cooperative cancellation ([`cancel::Cancel`]), the poll of a
//!   parallel computation from the calling thread ([`cancel::poll_during`])
//!   and the step count between two checks ([`cancel::CHECK_EVERY`]).
//! * [`alloc`]: the one path for allocations sized by user input (a size
//!   budget, then fallible allocation: an error naming the size, never an abort).
//! * `test_rng`: the tests' deterministic random inputs.
//! * [`tol`]: thresholds shared by several layers (the smallest step of the
//!   explicit integrators, the two tests for the singular level sets).

pub mod alloc;
pub mod cancel;
pub mod compensated;
pub mod complex;
pub mod dd;
pub(crate) mod dd_fn;
pub(crate) mod first_order;
#[cfg(test)]
pub(crate) mod test_rng;
pub mod tol;
