//! Schottky's `l(s)`, `f(s)` (12)–(18) and Kötter's reduction (19)–(26),
//! (38)–(42): from a state `l` of the top to the vectors `ξ, η`, the constants
//! `d_j` of Kötter's quadrics (11) and of the curve (8), and back.
//!
//! # Notation and conventions (all of them; see `docs/kotter.md`)
//!
//! * State `l = (l12, l13, l14, l23, l24, l34)`; `m_j = l_kl`, `n_j = l_j4` (13)
//!   with `(j, k, l)` cyclic in `(1, 2, 3)`: `m = (l23, l31, l12)`,
//!   `n = (l14, l24, l34)`.
//! * Integrals: `h0 = l12 l34 + l23 l14 + l31 l24` (6), `h1 = Σ l_jk²`, and
//!   **`h2 = Σ_{j<k} (a_l + a_m) l_jk²`, `h3 = Σ_{j<k} a_l a_m l_jk²`** with
//!   `{l, m}` the complement of `{j, k}` — the forms for which the closed form
//!   (15) holds (erratum to (7)/(15), `docs/errata.md`).
//! * `√s_j4` is the principal root of `s_j4 = (s − a_j)(s − a_4)`, and
//!   `√s_kl := √G / √s_j4` for a chosen branch `√G` of `G(s) = Π (s − a_j)`,
//!   so that `√s_j4 √s_kl = √G` for every `j` (the cross term of (15)).
//! * At a root `s_p` of `F` (19), the branch of `√G` is `σ_p`, the one on
//!   which `f(s_p) = 0` (`σ_p = −(h1 s_p² − h2 s_p + h3)/(2 h0)`; computed as
//!   `√G(s_p)` on that branch).
//! * The level-set constants (`s_p`, `σ_p`, `F'(s_p)`, `u`, `v`, `Δ`, `d_j`,
//!   `α_j … δ_j`) are computed in double-double (`rust/numeric/dd.rs`) and rounded once; the
//!   low parts of `u`, `v` are kept for `l^(p)`, `ξ`, `η` (docs/kotter.md §3).
//! * `√F'(s_p)` principal. Order of the roots: `s1` the non-real root of
//!   largest imaginary part, `s2` the root nearest `conj(s1)`, `s3` the
//!   remaining root of larger imaginary part (then larger real part), `s4`
//!   the last; when all four are real, descending order. With this order
//!   `l^(2) = conj(l^(1))` for real `l` whenever `s2 = conj(s1)`.
//! * `Δ_j^(p)` (25) is the 2×2 determinant
//!   `(√s_j4^(q) √s_kl^(r) − √s_j4^(r) √s_kl^(q)) / (√F'(s_q) √F'(s_r))`
//!   (erratum: printed with one root over the whole difference).

//!
//! # Files
//!
//! `schottky.rs`: `l(s)`, `f(s)` and the Lax pair at a point `s`;
//! `batch.rs`: many states at once, with the policy for failing rows;
//! `roots.rs`: the quartic `F` (19) and its roots; `polish.rs`: each root on
//! its own branch, in double-double; `constants.rs`: the level-set constants
//! (20)–(26), (38)–(41); `map.rs`: a state to `ξ, η` and the points of the
//! curve (37), (42), and back.

mod batch;
mod constants;
mod map;
mod pairs;
mod polish;
mod roots;
mod schottky;

pub use batch::{kotter_batch, KotterBatch, ROW_BYTES};
pub(crate) use constants::kotter_constants_soft;
pub use constants::{
    constants_from_h, kotter_constants, l_from_xi_eta, l_p, xi_eta, Coefficients23,
    KotterConstants, H0_NEGLIGIBLE_RTOL, NEAR_SINGULAR_RTOL, REAL_RTOL, STRUCTURE_RTOL,
};
pub(crate) use map::kotter_with_soft;
pub use map::{
    follow_order, from_kotter, kotter, kotter_along, kotter_along_step, kotter_with, on_level_set,
    KotterState, G42_RTOL, LEVEL_SET_RTOL, UNIFORM_RTOL,
};
pub use pairs::PAIR_ROUTE_RTOL;
pub use roots::{quartic_f, quartic_roots, REPEATED_ROOT_RTOL, ROOT_STAGNATION};
pub use schottky::{branch_sign, cubic_interpolant, g_poly, lax_m, p_poly, schottky, SQRT_G_RTOL};

use num_complex::Complex64;

use crate::error::{check_finite, Error, Result};

type C = Complex64;

const ZERO: C = C::new(0.0, 0.0);
const ONE: C = C::new(1.0, 0.0);

/// `(j, k, l)` cyclic permutations of `(1, 2, 3)`, 0-based, in the order `j = 1, 2, 3`.
pub const CYCLIC: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];

fn check_a(a: &[f64; 4]) -> Result<()> {
    check_finite("a", a)?;
    for i in 0..4 {
        for j in (i + 1)..4 {
            if a[i] == a[j] {
                return Err(Error::RepeatedA { i, j, value: a[i] });
            }
        }
    }
    Ok(())
}

/// `(m, n)` of (13): `m_j = l_kl`, `n_j = l_j4`, from `l = (l12, l13, l14, l23, l24, l34)`.
pub fn m_n(l: &[f64; 6]) -> ([f64; 3], [f64; 3]) {
    ([l[3], -l[1], l[0]], [l[2], l[4], l[5]])
}

/// Inverse of [`m_n`]: `l = (m3, −m2, n1, m1, n2, n3)`.
pub fn l_from_m_n(m: &[f64; 3], n: &[f64; 3]) -> [f64; 6] {
    [m[2], -m[1], n[0], m[0], n[1], n[2]]
}

/// The integrals `(h0, h1, h2, h3)`: `H0` (6), `H1` (7), and `H2`, `H3` in the
/// form consistent with (15) (complementary index pairs) — the dynamics module's
/// [`crate::so4::integrals4`], under the name the reduction uses.
pub use crate::so4::integrals4 as integrals;

#[cfg(test)]
mod tests;
