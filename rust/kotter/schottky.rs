//! Schottky's vector `l(s)` (12), `f(s) = Σ l_j(s)²` (14)–(15) and the Lax
//! pair `L(s)`, `M_b(s)` (16)–(18) at a point `s`, on the branch conventions
//! of the module docs (`√s_j4` principal, `√s_kl = √G/√s_j4`).

use super::{check_a, m_n, C, CYCLIC, ONE, ZERO};
use crate::error::{check_finite, Error, Result};
use crate::numeric::complex::sqrt_principal;

/// `s_jk = (s − a_j)(s − a_k)` (13), 0-based indices.
fn s_pair(s: C, a: &[f64; 4], j: usize, k: usize) -> C {
    (s - a[j]) * (s - a[k])
}

/// `G(s) = Π_{j=1}^{4} (s − a_j)` (15).
pub fn g_poly(a: &[f64; 4], s: C) -> C {
    a.iter().fold(ONE, |acc, &aj| acc * (s - aj))
}

/// Schottky's vector (12) and the vector `m(s)` of (17) on the branch
/// `√s_j4 √s_kl = sqrt_g` (`√s_j4` principal, see the module docs):
/// `l_j(s) = √s_j4 m_j + √s_kl n_j`, `m_j(s) = √s_kl m_j + √s_j4 n_j`.
///
/// Errors: non-finite input; `s = a_j` or `s = a_4` for some `j` (then
/// `√s_kl = √G/√s_j4` is 0/0).
pub fn schottky(a: &[f64; 4], l: &[f64; 6], s: C, sqrt_g: C) -> Result<([C; 3], [C; 3])> {
    check_finite("a", a)?;
    check_finite("l", l)?;
    check_finite("s, sqrt_g", &[s.re, s.im, sqrt_g.re, sqrt_g.im])?;
    let (m, n) = m_n(l);
    let mut lv = [ZERO; 3];
    let mut mv = [ZERO; 3];
    for (j, _) in CYCLIC.iter().enumerate() {
        let r = sqrt_principal(s_pair(s, a, j, 3));
        if r == ZERO {
            return Err(Error::InvalidArgument {
                what: "s",
                reason: format!(
                    "s = {s} is a root of s_j4 (j = {}): l(s) (12) is taken at s != a_i",
                    j + 1
                ),
            });
        }
        let q = sqrt_g / r;
        lv[j] = r * m[j] + q * n[j];
        mv[j] = q * m[j] + r * n[j];
    }
    if lv
        .iter()
        .chain(mv.iter())
        .any(|v| !(v.re.is_finite() && v.im.is_finite()))
    {
        return Err(Error::InvalidArgument {
            what: "l, s",
            reason: format!(
                "l(s) (12) or m(s) (17) overflows at s = {s}: the supported range is \
                 max|l_ij| * max|s - a_j| (and |sqrt G(s)|/|s - a_j|) below ~1e308"
            ),
        });
    }
    Ok((lv, mv))
}

/// The cubic interpolant of `b` over `a`: `(p0, p1, p2, p3)` with
/// `b_i = p0 + p1 a_i + p2 a_i² + p3 a_i³`, `i = 1 … 4` (always possible for
/// four distinct `a_i`; `p3` is the third divided difference of `b` over
/// `a`). By (2), `c_ij = p1 + p2 (a_i + a_j) + p3 (a_i² + a_i a_j + a_j²)`.
///
/// Errors: non-finite or repeated `a`, non-finite `b`.
pub fn cubic_interpolant(a: &[f64; 4], b: &[f64; 4]) -> Result<[f64; 4]> {
    check_a(a)?;
    check_finite("b", b)?;
    // Newton's divided differences: b(x) = b0 + f01 (x − a0) + f012 (x − a0)(x − a1)
    // + f0123 (x − a0)(x − a1)(x − a2).
    let f01 = (b[1] - b[0]) / (a[1] - a[0]);
    let f12 = (b[2] - b[1]) / (a[2] - a[1]);
    let f23 = (b[3] - b[2]) / (a[3] - a[2]);
    let f012 = (f12 - f01) / (a[2] - a[0]);
    let f123 = (f23 - f12) / (a[3] - a[1]);
    let f0123 = (f123 - f012) / (a[3] - a[0]);
    let p3 = f0123;
    let p2 = f012 - f0123 * (a[0] + a[1] + a[2]);
    let p1 = f01 - f012 * (a[0] + a[1]) + f0123 * (a[0] * a[1] + a[0] * a[2] + a[1] * a[2]);
    let p0 = b[0] - f01 * a[0] + f012 * a[0] * a[1] - f0123 * a[0] * a[1] * a[2];
    let p = [p0, p1, p2, p3];
    if p.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidArgument {
            what: "a, b",
            reason: format!(
                "the divided differences of b over a overflow (p = {p:?}): the a_i are too \
                 close together for double precision (differences of a must keep \
                 (b_i - b_j)/(a_i - a_j) and its higher quotients below ~1e308)"
            ),
        });
    }
    Ok(p)
}

/// `|sqrt_g² − G(s)| ≤ SQRT_G_RTOL · |G(s)|` is required of the branch passed
/// to [`lax_m`]: a rounded square root is good to a few ulps; the sign `τ`
/// (below) is meaningless for a number that is not a root of `G`.
pub const SQRT_G_RTOL: f64 = 1e-8;

/// The branch sign `τ = √s_14 √s_24 √s_34 √G / ((s − a_4) G(s)) = ±1`
/// (`√s_j4` principal, `√G = sqrt_g`); its square is 1 because
/// `s_14 s_24 s_34 = (s − a_4)² G(s)`.
///
/// Errors: `sqrt_g` not a square root of `G(s)` (to [`SQRT_G_RTOL`]),
/// `G(s) = 0`.
pub fn branch_sign(a: &[f64; 4], s: C, sqrt_g: C) -> Result<f64> {
    let g = g_poly(a, s);
    let miss = (sqrt_g * sqrt_g - g).norm();
    if g == ZERO || miss.is_nan() || miss > SQRT_G_RTOL * g.norm() {
        return Err(Error::InvalidArgument {
            what: "sqrt_g",
            reason: format!(
                "sqrt_g = {sqrt_g} is not a square root of G(s) = {g} at s = {s} (or G(s) = 0)"
            ),
        });
    }
    let r: C = (0..3).map(|j| sqrt_principal(s_pair(s, a, j, 3))).product();
    let tau = r * sqrt_g / ((s - a[3]) * g);
    Ok(if tau.re >= 0.0 { 1.0 } else { -1.0 })
}

/// The vector `m_b(s)` of the Lax matrix `M_b(s)` (18) for the top with
/// parameters `(a, b)`, so that `L̇(s) = [L(s), M_b(s)]` (16) along the flow
/// (1)–(2), on the branch `√s_j4 √s_kl = sqrt_g` (`√s_j4` principal):
///
/// `m_b(s) = −τ [p2 m(s) + p3 (e2 m(s) + m^[ω3](s)) / (e1 − s)]`
///
/// with `(p0, …, p3)` the cubic interpolant of `b` over `a`
/// ([`cubic_interpolant`]), `m(s)` the vector (17) (`m^[l]`), `m^[X](s)` the
/// same built from an antisymmetric `X` instead of `l`
/// (`m^[X]_j = √s_kl X_kl + √s_j4 X_j4`), `(ω3)_ij = (a_i² + a_i a_j + a_j²) l_ij`
/// (the angular velocity of the top with `b = a³`), `e1 = Σ a_i`,
/// `e2 = Σ_{i<j} a_i a_j`, and `τ = ±1` the branch sign ([`branch_sign`]).
/// The printed (17)–(18) is the case `b = a²` on the branch `τ = −1`
/// (erratum, `docs/errata.md`; derivation in `docs/kotter.md` §2).
///
/// Errors: those of [`schottky`] and [`branch_sign`]; `s = e1` when
/// `p3 ≠ 0` (a pole of `M_b`).
pub fn lax_m(a: &[f64; 4], b: &[f64; 4], l: &[f64; 6], s: C, sqrt_g: C) -> Result<[C; 3]> {
    let p = cubic_interpolant(a, b)?;
    let (_, m) = schottky(a, l, s, sqrt_g)?;
    let tau = branch_sign(a, s, sqrt_g)?;
    let mut mb: [C; 3] = m.map(|v| v * p[2]);
    if p[3] != 0.0 {
        let e1: f64 = a.iter().sum();
        let e2 = a[0] * (a[1] + a[2] + a[3]) + a[1] * (a[2] + a[3]) + a[2] * a[3];
        let den = e1 - s;
        if den == ZERO {
            return Err(Error::InvalidArgument {
                what: "s",
                reason: format!(
                    "s = {s} equals e1 = a1 + a2 + a3 + a4, a pole of M_b(s) (b is not \
                     quadratic in a: p3 = {})",
                    p[3]
                ),
            });
        }
        // ω3 in the state order (l12, l13, l14, l23, l24, l34)
        const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
        let w3: [f64; 6] = std::array::from_fn(|q| {
            let (i, j) = PAIRS[q];
            (a[i] * a[i] + a[i] * a[j] + a[j] * a[j]) * l[q]
        });
        let (_, m3) = schottky(a, &w3, s, sqrt_g)?;
        for j in 0..3 {
            mb[j] += p[3] * (e2 * m[j] + m3[j]) / den;
        }
    }
    if mb.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
        return Err(Error::InvalidArgument {
            what: "a, b, l, s",
            reason: format!(
                "M_b(s) (18) overflows at s = {s}: the products of the cubic interpolant of b \
                 with l(s) leave the double range (~1e308)"
            ),
        });
    }
    Ok(mb.map(|v| -tau * v))
}

/// The polynomial part `h1 s² − h2 s + h3` of (15).
pub fn p_poly(h: &[f64; 4], s: C) -> C {
    (s * h[1] - h[2]) * s + h[3]
}
