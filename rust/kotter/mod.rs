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

use num_complex::Complex64;

use crate::curve::{CurvePoint, KotterCurve, WurzelPoints};
use crate::error::{check_finite, Error, Result, SingularKind};
use crate::numeric::complex::sqrt_principal;
use crate::numeric::dd::{Cdd, Dd};
use crate::numeric::tol::REDUCTION_FLOOR_RTOL;

type C = Complex64;

const ZERO: C = C::new(0.0, 0.0);
const ONE: C = C::new(1.0, 0.0);

/// `(j, k, l)` cyclic permutations of `(1, 2, 3)`, 0-based, in the order `j = 1, 2, 3`.
pub const CYCLIC: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];

/// Roots of `F` closer than `REPEATED_ROOT_RTOL` times their scale are
/// treated as repeated: then `F'(s_p) → 0` and `l^(p)` (20) is undefined. A
/// double root is located only to `√ε ≈ 1.5e-8` relative, so two roots
/// within 1e-7 are indistinguishable from a double root.
pub const REPEATED_ROOT_RTOL: f64 = 1e-7;

/// Roots within a relative distance `δ` of each other are determined only to
/// about `u/δ` (u the unit roundoff), and the Aberth iteration then jitters
/// at that level instead of reaching 1e-15. Steps still larger than 1e-8
/// after 500 sweeps mean no convergence (roots closer than ~1e-8 are
/// reported as repeated anyway).
pub const ROOT_STAGNATION: f64 = 1e-8;

/// Residual (relative to the size of the terms) above which the existence
/// conditions of (38)–(39) (`Σ c_j q_j = 0`, `Σ c_j (p_j + r_j) = 0`) and the
/// perfect square of the corrected (40) are reported as failing: they hold to
/// rounding (a few 1e-13 on the reference tops, up to ~1e-7 when two `d_j`
/// nearly coincide, which amplifies rounding in `α_j … δ_j` by
/// `1/|d_j − d_k|`); 1e-6 still rejects an inconsistent structure, whose
/// residual is O(1).
pub const STRUCTURE_RTOL: f64 = 1e-6;

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

/// Coefficients of `F(s)` (19), monic, highest power first:
/// `F = [(h1 s² − h2 s + h3)² − 4 h0² G(s)] / (h1² − 4 h0²)`.
///
/// Errors: `h1² = 4 h0²` (to [`REDUCTION_FLOOR_RTOL`]), i.e. `m = ±n`: (19) is not
/// defined (and `f(s)` has fewer than four zeros).
pub fn quartic_f(a: &[f64; 4], h: &[f64; 4]) -> Result<[f64; 5]> {
    quartic_f_den(a, h, h[1] * h[1] - 4.0 * h[0] * h[0])
}

/// [`quartic_f`] with `h1² − 4h0²` given (from the state, `|m − n|² |m + n|²`
/// keeps its relative accuracy where the difference of squares loses it).
fn quartic_f_den(a: &[f64; 4], h: &[f64; 4], den: f64) -> Result<[f64; 5]> {
    let [h0, h1, h2, h3] = *h;
    if den.abs() <= REDUCTION_FLOOR_RTOL * h1 * h1 || h1 == 0.0 {
        return Err(Error::Singular {
            what: "state l",
            kind: SingularKind::SelfDual,
            reason: format!(
                "h1^2 - 4 h0^2 = {den:e} vanishes (h1 = {h1}, h0 = {h0}; the state is \
                 self-dual or anti-self-dual, m = +-n, or at a relative distance \
                 (h1^2 - 4 h0^2)/h1^2 = {:e} <= {REDUCTION_FLOOR_RTOL:e} from it): F(s) (19) is not \
                 defined",
                den / (h1 * h1)
            ),
        });
    }
    // G(s) = s^4 - e1 s^3 + e2 s^2 - e3 s + e4
    let mut g = [1.0, 0.0, 0.0, 0.0, 0.0];
    for &aj in a {
        for i in (1..5).rev() {
            g[i] -= aj * g[i - 1];
        }
    }
    let p2 = [
        h1 * h1,
        -2.0 * h1 * h2,
        h2 * h2 + 2.0 * h1 * h3,
        -2.0 * h2 * h3,
        h3 * h3,
    ];
    let mut f = [0.0; 5];
    for i in 0..5 {
        f[i] = (p2[i] - 4.0 * h0 * h0 * g[i]) / den;
    }
    Ok(f)
}

fn horner(c: &[f64; 5], s: C) -> (C, C) {
    let mut p = C::new(c[0], 0.0);
    let mut dp = ZERO;
    for &ci in &c[1..] {
        dp = dp * s + p;
        p = p * s + ci;
    }
    (p, dp)
}

/// The four roots of the monic quartic `F` (19), by the Aberth–Ehrlich
/// iteration followed by Newton polishing, in the documented order (module
/// docs).
///
/// Errors: two roots closer than [`REPEATED_ROOT_RTOL`] (repeated roots of
/// F, where (20) divides by `F'(s_p) = 0`); no convergence.
pub fn quartic_roots(f: &[f64; 5]) -> Result<[C; 4]> {
    check_finite("F coefficients", f)?;
    // Cauchy bound for the initial circle.
    let rad = 1.0 + f[1..].iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let mut z: [C; 4] = std::array::from_fn(|k| {
        C::from_polar(rad * 0.5, 0.4 + std::f64::consts::FRAC_PI_2 * k as f64)
    });
    let mut converged = false;
    let mut last = f64::INFINITY;
    for _ in 0..500 {
        let prev = last;
        let mut maxstep = 0.0f64;
        for k in 0..4 {
            let (p, dp) = horner(f, z[k]);
            if p == ZERO {
                continue;
            }
            let ratio = p / dp;
            let mut sum = ZERO;
            for j in 0..4 {
                if j != k {
                    sum += ONE / (z[k] - z[j]);
                }
            }
            let w = ratio / (ONE - ratio * sum);
            z[k] -= w;
            // the ∞-norm over the 1-norm (a relative step within a factor √2 of
            // the modulus ratio, without libm's hypot, which cost more than the
            // iteration's arithmetic)
            let step = w.re.abs().max(w.im.abs()) / (1.0 + z[k].re.abs() + z[k].im.abs());
            maxstep = maxstep.max(step);
        }
        last = maxstep;
        if maxstep < 1e-15 {
            converged = true;
            break;
        }
        // Below ROOT_STAGNATION the iteration is in its (cubic) basin; a step
        // that no longer halves is rounding noise at the roots' conditioning
        // (u/δ for roots δ apart), and more sweeps only jitter (they used to
        // run to the cap of 500 on clustered roots, 40 % of a frequency map's
        // time). The roots are polished on their own branch afterwards.
        if maxstep < ROOT_STAGNATION && maxstep > 0.5 * prev {
            converged = true;
            break;
        }
    }
    for zk in z.iter_mut() {
        for _ in 0..2 {
            let (p, dp) = horner(f, *zk);
            if dp != ZERO {
                *zk -= p / dp;
            }
        }
    }
    let scale = z.iter().fold(1.0f64, |m, v| m.max(v.norm()));
    // A cluster is reported as a repeated root even when the iteration has not
    // met its tolerance: Aberth converges only linearly to a multiple root.
    check_repeated(&z)?;
    if !converged && last > ROOT_STAGNATION {
        return Err(Error::NoConvergence {
            what: "roots of F(s) (19)",
            tol: ROOT_STAGNATION,
            reached: last,
            iterations: 500,
        });
    }
    Ok(order_roots(z, scale))
}

/// Two roots closer than [`REPEATED_ROOT_RTOL`] times the larger of the two
/// are a repeated root. Relative to the pair, not to the largest root: near
/// the singular set `h1² = 4h0²` one or two roots of `F` grow like the
/// inverse distance to it while the others stay of the size of the `a_i`.
fn check_repeated(z: &[C]) -> Result<()> {
    for i in 0..z.len() {
        for j in (i + 1)..z.len() {
            let pair = z[i].norm().max(z[j].norm());
            if (z[i] - z[j]).norm() <= REPEATED_ROOT_RTOL * pair {
                return Err(Error::Singular {
                    what: "state l",
                    kind: SingularKind::RepeatedRoot,
                    reason: format!(
                        "F(s) (19) has a repeated root s = {} (|s_{} - s_{}| = {:e}): l^(p) (20) \
                         divides by sqrt(F'(s_p)) = 0",
                        z[i],
                        i + 1,
                        j + 1,
                        (z[i] - z[j]).norm()
                    ),
                });
            }
        }
    }
    Ok(())
}

fn order_roots(z: [C; 4], scale: f64) -> [C; 4] {
    // F has real coefficients: a root whose imaginary part is at rounding
    // level is real (made exactly real, so that the order below does not
    // depend on the sign of rounding noise), and the partner of a non-real
    // root is its exact conjugate. Genuinely complex roots this close to the
    // axis would form a pair closer than REPEATED_ROOT_RTOL (already rejected).
    let snap = |x: C| {
        if x.im.abs() <= 1e-12 * scale {
            C::new(x.re, 0.0)
        } else {
            x
        }
    };
    let mut r: Vec<C> = z.iter().map(|&x| snap(x)).collect();
    let by_im_re = |x: &C, y: &C| {
        x.im.partial_cmp(&y.im)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(x.re.partial_cmp(&y.re).unwrap_or(std::cmp::Ordering::Equal))
    };
    if r.iter().any(|x| x.im != 0.0) {
        let i1 = (0..4)
            .filter(|&i| r[i].im != 0.0)
            .max_by(|&i, &j| by_im_re(&r[i], &r[j]))
            .unwrap_or(0);
        let s1 = r.remove(i1);
        let i2 = (0..3)
            .min_by(|&i, &j| {
                (r[i] - s1.conj())
                    .norm()
                    .partial_cmp(&(r[j] - s1.conj()).norm())
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
            .unwrap_or(0);
        r.remove(i2);
        let (s3, mut s4) = if by_im_re(&r[0], &r[1]) == std::cmp::Ordering::Less {
            (r[1], r[0])
        } else {
            (r[0], r[1])
        };
        if s3.im != 0.0 {
            // the second conjugate pair: s4 = conj(s3) exactly
            s4 = s3.conj();
        }
        [s1, s1.conj(), s3, s4]
    } else {
        r.sort_by(|x, y| y.re.partial_cmp(&x.re).unwrap_or(std::cmp::Ordering::Equal));
        [r[0], r[1], r[2], r[3]]
    }
}

/// The constants of Kötter's reduction for one level set `(a, h)`.
///
/// Everything here depends only on `a` and the integrals `h`, hence is
/// constant along a trajectory; `ξ, η` ([`xi_eta`]) carry the time dependence.
#[derive(Debug, Clone, PartialEq)]
pub struct KotterConstants {
    /// The top's `a` (2): the constants belong to the level set of `(a, h)`.
    pub a: [f64; 4],
    /// `(h0, h1, h2, h3)` ([`integrals`]).
    pub h: [f64; 4],
    /// Roots `s_1 … s_4` of `F` (19), in the documented order.
    pub s: [C; 4],
    /// `σ_p`, the branch of `√G(s_p)` on which `f(s_p) = 0`.
    pub sigma: [C; 4],
    /// `√F'(s_p)`, principal.
    pub sqrt_fprime: [C; 4],
    /// `u[p][j] = √s_j4(s_p) / √F'(s_p)` (coefficient of `m_j` in `l_j^(p)` (20)).
    pub u: [[C; 3]; 4],
    /// `v[p][j] = √s_kl(s_p) / √F'(s_p)` (coefficient of `n_j`).
    pub v: [[C; 3]; 4],
    /// The rounding errors of `u`: `u + u_lo` is `u` to double-double
    /// accuracy. [`l_p`] and [`xi_eta`] sum `(u + u_lo) m + (v + v_lo) n` in DD:
    /// near the singular set `h1² = 4h0²` the two terms cancel by about the
    /// inverse relative distance to it (docs/kotter.md §3).
    pub u_lo: [[C; 3]; 4],
    /// The rounding errors of `v` (see [`KotterConstants::u_lo`]).
    pub v_lo: [[C; 3]; 4],
    /// `delta_det[p][j] = Δ_j^(p)` (25) (corrected: a 2×2 determinant), `p = 1, 2, 3`.
    pub delta_det: [[C; 3]; 3],
    /// `√d_j = (Δ_j^(1) − i Δ_j^(2)) / Δ_j^(3)` (26).
    pub sqrt_d: [C; 3],
    /// `d_j` (26), the constants of Kötter's quadrics (11) and of the curve (8).
    pub d: [C; 3],
    /// The rounding errors of `d`: `d + d_lo` is `d_j` to double-double
    /// accuracy. [`kotter_with`] starts the inverse map of (37) from the closed
    /// form (30) on this unrounded curve: near the singular set the closed form
    /// cancels by `|d_4|/|z|` (docs/kotter.md, "Near the singular set").
    pub d_lo: [C; 3],
    /// `α_j, β_j, γ_j, δ_j` of (23) in corrected form (24):
    /// `m_j = α_j ξ_j + β_j η_j`, `n_j = γ_j ξ_j + δ_j η_j`.
    pub alpha: [C; 3],
    /// See [`KotterConstants::alpha`].
    pub beta: [C; 3],
    /// See [`KotterConstants::alpha`].
    pub gamma: [C; 3],
    /// See [`KotterConstants::alpha`].
    pub delta: [C; 3],
    /// `A_j = α + β d_j + γ/d_j` of (38)–(39): on Kötter's quadrics
    /// `H0 = Σ_j A_j (ξ_j² − η_j²) + B_j ξ_j η_j` (the unique representative of
    /// that form).
    pub a_coef: [C; 3],
    /// `B_j = δ (d_j + 1/d_j)` of (38)–(39).
    pub b_coef: [C; 3],
    /// `(α, β, γ, δ)` of (39) (the paper's unnamed constants; not the `α_j` of (24)),
    /// in closed form with `K`, `ε` of the corrected (40), `κ = Π_{m=1}^{3} (d_m − d_4)`,
    /// `e1 = d_1 + d_2 + d_3`: `β = −K/κ`, `γ = ε² d_4² K/κ`, `δ = 2 ε d_4 K/κ`,
    /// `α = (K/(2κ)) (κ ε² + (e1 − d_4)(1 − ε² d_4²))`.
    pub abgd39: [C; 4],
    /// `ε` of (40)–(41), corrected: `H0 = K g² (1 − ε P_0)²` with [`KotterConstants::k`];
    /// `ε = Σ_j c̃_j (α_j δ_j + β_j γ_j) / (2 Σ_j c̃_j d_j β_j δ_j)`.
    pub eps: C,
    /// `K` of the corrected (40) (printed as `1/(4 ε d_4)`):
    /// `K = κ Σ_j c̃_j d_j β_j δ_j`, `κ = Π_{m=1}^{3} (d_m − d_4)`, `c̃_j` of (33).
    pub k: C,
}

/// Kötter's constants for the level set of the state `l` of the top with
/// parameters `a` (only `a` and the integrals of `l` enter).
///
/// Errors: non-finite or repeated `a`; non-finite `l`; `h0 = 0` or
/// `h1² = 4h0²` (F (19) not defined or with double roots); repeated roots of
/// `F`; a root `s_p` at some `a_j` (then `√s_kl` is 0/0); `Δ_j^(3) = 0`
/// (the pair `s1, s2` does not determine `m_j, n_j`); `d_j` zero or infinite.
pub fn kotter_constants(a: &[f64; 4], l: &[f64; 6]) -> Result<KotterConstants> {
    check_a(a)?;
    check_finite("l", l)?;
    let h = integrals(a, l);
    let (m, n) = m_n(l);
    // P(a_i) = h1 a_i^2 - h2 a_i + h3 from the state itself: the sum of the
    // non-vanishing terms s_j4 m_j^2 + s_kl n_j^2 at s = a_i, without the
    // cancellation of the form in h (it is small exactly when a root of F is
    // near a_i, which is when it is needed to full relative accuracy).
    let p_at_a: [f64; 4] = std::array::from_fn(|i| {
        let x = a[i];
        CYCLIC
            .iter()
            .enumerate()
            .map(|(j, &(_, k, ll))| {
                (x - a[j]) * (x - a[3]) * m[j] * m[j] + (x - a[k]) * (x - a[ll]) * n[j] * n[j]
            })
            .sum()
    });
    near_singular(l, constants_impl(a, &h, &p_at_a, Some((m, n))))
}

/// States closer than `NEAR_SINGULAR_RTOL` to the singular set `h1² = 4h0²`,
/// in the relative distance `δ = (h1² − 4h0²)/h1²` (`= |m − n|²|m + n|²/h1²`),
/// may raise. Down to it the reduction round-trips at roundoff: all 3000 states
/// of `tests/data/kotter_singular_sweep.py` at `δ` from 1e-10 to 1e-4 (shared,
/// random and pinched tops), worst 2.4e-15, and 600 more at 2.5e-11; the
/// mismatch of (42) is ≤ 3.4e-11 there (1e-6 is refused). Below it the
/// double-double level-set constants run out of digits (`d_j` to 2e-17 at
/// `δ = 4e-12`, the mismatch of (42) reaches 6e-9) and the inverse map of the
/// curve starts to fail (2 of 600 states at `δ = 4e-12`; docs/kotter.md, "Near
/// the singular set"). Below [`REDUCTION_FLOOR_RTOL`] every state raises.
pub const NEAR_SINGULAR_RTOL: f64 = 1e-10;

/// `δ = (h1² − 4h0²)/h1²` from the state (`h1² − 4h0² = |m − n|²|m + n|²`,
/// full relative accuracy).
fn singular_distance(l: &[f64; 6]) -> f64 {
    let (m, n) = m_n(l);
    let h1: f64 = l.iter().map(|x| x * x).sum();
    den_from_state(&m, &n) / (h1 * h1)
}

/// A failure of a state closer than [`NEAR_SINGULAR_RTOL`] to the singular set
/// is reported as such (kind [`SingularKind::SelfDual`]), with the step that failed.
fn near_singular<T>(l: &[f64; 6], r: Result<T>) -> Result<T> {
    r.map_err(|e| {
        let dist = singular_distance(l);
        if matches!(e, Error::Singular { .. }) || dist.is_nan() || dist >= NEAR_SINGULAR_RTOL {
            return e;
        }
        Error::Singular {
            what: "state l",
            kind: SingularKind::SelfDual,
            reason: format!(
                "it lies at relative distance (h1^2 - 4 h0^2)/h1^2 = {dist:e} from the singular \
                 set h1^2 = 4 h0^2 (m = +-n), closer than {NEAR_SINGULAR_RTOL:e}, where the \
                 reduction is no longer guaranteed: {e}"
            ),
        }
    })
}

/// [`kotter_constants`] from the integrals `h = (h0, h1, h2, h3)` directly.
///
/// A root `s_p` close to some `a_i` is then known only to an absolute
/// accuracy of a few ulps of the coefficients, so `s_p − a_i` (and with it
/// `√s_j4`, `l^(p)`) loses relative accuracy; [`kotter_constants`] avoids this.
pub fn constants_from_h(a: &[f64; 4], h: &[f64; 4]) -> Result<KotterConstants> {
    check_finite("h", h)?;
    let p_at_a: [f64; 4] = std::array::from_fn(|i| (h[1] * a[i] - h[2]) * a[i] + h[3]);
    constants_impl(a, h, &p_at_a, None)
}

/// What the polish of the roots of `F` needs of the level set: `a`, `h`,
/// `h1² − 4h0²` and, when the reduction starts from a state, `(m, n)`
/// themselves (then `P(s)` and `f(s)` are summed from the state, without the
/// cancellation of the forms in `h`).
struct Level<'a> {
    a: &'a [f64; 4],
    h: &'a [f64; 4],
    mn: Option<([f64; 3], [f64; 3])>,
    den: f64,
}

impl Level<'_> {
    /// `P(s) = h1 s² − h2 s + h3` and `P'(s)` from the offsets `x_m = s − a_m`.
    /// From the state, `P(s) = Σ_j (x_j x_4 m_j² + x_k x_l n_j²)`: the
    /// offsets carry `s − a_m` to full relative accuracy, so `P` near a root of
    /// `G` (where it is small) keeps its relative accuracy.
    fn p_dp(&self, s: C, x: &[C; 4]) -> (C, C) {
        match self.mn {
            Some((m, n)) => {
                let mut p = ZERO;
                let mut dp = ZERO;
                for (j, &(_, k, l)) in CYCLIC.iter().enumerate() {
                    let (m2, n2) = (m[j] * m[j], n[j] * n[j]);
                    p += x[j] * x[3] * m2 + x[k] * x[l] * n2;
                    dp += (x[j] + x[3]) * m2 + (x[k] + x[l]) * n2;
                }
                (p, dp)
            }
            None => (p_poly(self.h, s), 2.0 * self.h[1] * s - self.h[2]),
        }
    }

    /// `f(s) = Σ_j l_j(s)²` (14) on the branch `√G = sigma` and its size (the
    /// sum of the magnitudes of its terms, for the convergence test). From the
    /// state, `l_j(s) = √s_j4 (m_j + τ n_j) + n_j (s_kl − s_j4)/(√s_kl + τ √s_j4)`
    /// with `τ = ±1` making the denominator the larger of `√s_kl ± √s_j4`:
    /// near the singular set `m ≈ ∓n` and at large `|s|` the two terms of
    /// `√s_j4 m_j + √s_kl n_j` cancel, this form does not.
    fn f(&self, s: C, x: &[C; 4], sigma: C) -> (C, f64) {
        match self.mn {
            Some((m, n)) => {
                let mut f = ZERO;
                let mut size = 0.0;
                for (j, &(_, k, l)) in CYCLIC.iter().enumerate() {
                    let r = sqrt_principal(x[j] * x[3]);
                    let q = sigma / r;
                    let tau = if (q * r.conj()).re >= 0.0 { 1.0 } else { -1.0 };
                    let lj = r * (m[j] + tau * n[j])
                        + n[j] * (x[k] * x[l] - x[j] * x[3]) / (q + tau * r);
                    f += lj * lj;
                    size += (r.norm() * m[j].abs() + q.norm() * n[j].abs()).powi(2);
                }
                (f, size)
            }
            None => {
                let (p, _) = self.p_dp(s, x);
                let [h0, h1, h2, h3] = *self.h;
                let size =
                    (h1 * s * s).norm() + (h2 * s).norm() + h3.abs() + (2.0 * h0 * sigma).norm();
                (p + 2.0 * h0 * sigma, size)
            }
        }
    }

    /// `f'(s)` on the branch `√G = sigma`. From the state, `f' = 2 Σ_j l_j l_j'`
    /// with `l_j` as in [`Level::f`] and, with `w_a = 1/x_j + 1/x_4`,
    /// `w_b = 1/x_k + 1/x_l`, `w_b − w_a = (a_k − a_j)/(x_j x_k) + (a_l − a_4)/(x_l x_4)`,
    /// `l_j' = ½ [w_a l_j + √s_kl n_j (w_b − w_a)]` or `½ [w_b l_j − √s_j4 m_j (w_b − w_a)]`
    /// (the derivative `½ (w_a √s_j4 m_j + w_b √s_kl n_j)` regrouped so that the
    /// two terms that cancel near `m = ∓n` at large `|s|` enter only through
    /// `l_j`; of the two, the one whose `w` has no pole at a nearby `a_i`). The
    /// closed form `P'(s) + h0 σ Σ_m 1/x_m` cancels there by about the relative
    /// distance `(h1² − 4h0²)/h1²` to the singular set (docs/kotter.md §3).
    fn df(&self, s: C, x: &[C; 4], sigma: C) -> C {
        match self.mn {
            Some((m, n)) => {
                let a = self.a;
                let mut df = ZERO;
                for (j, &(_, k, l)) in CYCLIC.iter().enumerate() {
                    let r = sqrt_principal(x[j] * x[3]);
                    let q = sigma / r;
                    let tau = if (q * r.conj()).re >= 0.0 { 1.0 } else { -1.0 };
                    let lj = r * (m[j] + tau * n[j])
                        + n[j] * (x[k] * x[l] - x[j] * x[3]) / (q + tau * r);
                    // w_a = 1/x_j + 1/x_4, w_b = 1/x_k + 1/x_l; w_b − w_a from the
                    // differences of the a's (no cancellation)
                    let wa = ONE / x[j] + ONE / x[3];
                    let wb = ONE / x[k] + ONE / x[l];
                    let wba = (a[k] - a[j]) / (x[j] * x[k]) + (a[l] - a[3]) / (x[l] * x[3]);
                    let dlj = if wa.norm() <= wb.norm() {
                        0.5 * (wa * lj + q * n[j] * wba)
                    } else {
                        0.5 * (wb * lj - r * m[j] * wba)
                    };
                    df += 2.0 * lj * dlj;
                }
                df
            }
            None => {
                let (_, dp) = self.p_dp(s, x);
                dp + self.h[0] * sigma * x.iter().map(|&xm| ONE / xm).sum::<C>()
            }
        }
    }
}

/// The offsets `x_m = s − a_m` with `s = a_i + t` (`i` the nearest `a`):
/// `x_i = t`, `x_m = (a_i − a_m) + t`, to full relative accuracy when `t` is.
fn offsets_at(a: &[f64; 4], i: usize, t: C) -> [C; 4] {
    std::array::from_fn(|m| if m == i { t } else { (a[i] - a[m]) + t })
}

/// The continuation of the branch `√G(s)`: the root of `Π x_m` nearest `prev`.
fn sqrt_g_near(x: &[C; 4], prev: C) -> C {
    let r = sqrt_principal(x.iter().product());
    if (r - prev).norm() <= (r + prev).norm() {
        r
    } else {
        -r
    }
}

/// A root of `F` (19) polished on its own branch, with what (20) needs there.
struct PolishedRoot {
    s: C,
    /// `s − a_m` in DD (exact sums from the root's offset to its nearest `a_i`).
    x: [Cdd; 4],
    /// `σ = √G(s)` on the branch where `f(s) = 0`.
    sigma: Cdd,
    /// `F'(s) = f'(s) f̃(s) / (h1² − 4h0²)` with `f̃(s) = −4 h0 σ` (docs/kotter.md §3).
    fprime: C,
    /// `√F'(s)`, principal.
    sqrt_fprime: Cdd,
}

impl PolishedRoot {
    /// The root of the conjugate pair's partner: every quantity conjugated,
    /// `√F'` kept principal (`conj(√F')` is the principal root of `conj(F')`
    /// except on the cut `F' < 0`, where both are `+i√|F'|`).
    fn conj(&self) -> PolishedRoot {
        let c = self.sqrt_fprime.conj();
        let sqrt_fprime = if c.re.hi == 0.0 && c.im.hi < 0.0 {
            c.neg()
        } else {
            c
        };
        PolishedRoot {
            s: self.s.conj(),
            x: self.x.map(Cdd::conj),
            sigma: self.sigma.conj(),
            fprime: self.fprime.conj(),
            sqrt_fprime,
        }
    }
}

/// Newton's method on `f(s) = P(s) + 2 h0 √G(s)` (15) itself, on the branch
/// `√G = σ` that vanishes at the root (chosen from the starting value: the
/// sign with the smaller `|f|`), in the offset `t = s − a_i` from the
/// nearest `a_i`. `F = f f̃/(h1² − 4h0²)` merges the two branches: when two
/// roots of `F` lie on different branches `δ` apart, `F'(s_p) ~ δ` and the
/// quartic's root is good to `u/δ` only, while `f'(s_p)` is not small.
///
/// Near `a_i`, where `√G ~ √t` is not smooth, the start is first refined on
/// `(P(a_i) + P'(a_i) t + h1 t²)² − 4h0² t Π_{m≠i}(a_i − a_m + t)` (the
/// numerator of (19) at `s = a_i + t`, all terms of the size of `t`).
fn polish_root(lv: &Level, p_at_a: &[f64; 4], s0: C) -> PolishedRoot {
    let a = lv.a;
    let [h0, h1, h2, _] = *lv.h;
    let mut best = 0;
    for i in 1..4 {
        if (s0 - a[i]).norm() < (s0 - a[best]).norm() {
            best = i;
        }
    }
    let ai = a[best];
    let gap = (0..4)
        .filter(|&m| m != best)
        .map(|m| (a[m] - ai).abs())
        .fold(f64::INFINITY, f64::min);
    let mut t = s0 - ai;
    if t.norm() < 0.1 * gap {
        let pa = p_at_a[best];
        let dpa = 2.0 * h1 * ai - h2;
        for _ in 0..4 {
            let pt = pa + (h1 * t + dpa) * t;
            let dpt = dpa + 2.0 * h1 * t;
            let mut prod = ONE;
            let mut dprod = ZERO;
            for m in (0..4).filter(|&m| m != best) {
                let f = ai - a[m] + t;
                dprod = dprod * f + prod;
                prod *= f;
            }
            let val = pt * pt - 4.0 * h0 * h0 * t * prod;
            let der = 2.0 * pt * dpt - 4.0 * h0 * h0 * (prod + t * dprod);
            if der == ZERO || !(val / der).norm().is_finite() {
                break;
            }
            let step = val / der;
            t -= step;
            if step.norm() <= f64::EPSILON * t.norm() {
                break;
            }
        }
    }
    // the branch: of ±√G(s0), the one on which f is the smaller
    let x0 = offsets_at(a, best, t);
    let g0 = sqrt_principal(x0.iter().product());
    let (fp, _) = lv.f(ai + t, &x0, g0);
    let (fm, _) = lv.f(ai + t, &x0, -g0);
    let mut sigma = if fp.norm() <= fm.norm() { g0 } else { -g0 };
    let mut cur = (t, x0, sigma);
    let (f_cur, size) = lv.f(ai + t, &x0, sigma);
    let mut res_best = f_cur.norm() / size.max(f64::MIN_POSITIVE);
    let mut best_state = cur;
    for _ in 0..8 {
        let (t, x, sg) = cur;
        let s = ai + t;
        let (f, _) = lv.f(s, &x, sg);
        let df = lv.df(s, &x, sg);
        let step = f / df;
        if !(step.re.is_finite() && step.im.is_finite()) {
            break;
        }
        let tn = t - step;
        let xn = offsets_at(a, best, tn);
        sigma = sqrt_g_near(&xn, sg);
        cur = (tn, xn, sigma);
        let (fn_, size) = lv.f(ai + tn, &xn, sigma);
        let res = fn_.norm() / size.max(f64::MIN_POSITIVE);
        if res < res_best {
            res_best = res;
            best_state = cur;
        }
        if step.norm() <= 2.0 * f64::EPSILON * (ai + tn).norm().max(tn.norm()) || res == 0.0 {
            break;
        }
    }
    let (t, x, sigma) = best_state;
    let s = ai + t;
    let df = lv.df(s, &x, sigma);
    let fprime = df * (-4.0 * h0 * sigma) / lv.den;
    let plain = PolishedRoot {
        s,
        x: x.map(Cdd::new),
        sigma: Cdd::new(sigma),
        fprime,
        sqrt_fprime: Cdd::new(sqrt_principal(fprime)),
    };
    refine_dd(lv, best, t, sigma, df).unwrap_or(plain)
}

/// The root, `σ`, the offsets `s − a_m` and `√F'(s)` to double-double
/// accuracy: one Newton step on `f` evaluated in DD from the double root
/// (`t = s − a_i`), then `σ`, `f'` and `F' = −4h0 σ f'/(h1² − 4h0²)` in DD at
/// the new root.
///
/// Why: `l^(p)`, `Δ`, `d_j` and `α_j … δ_j` are all built from `(s_p, σ_p, F'(s_p))`,
/// and the third quadric (11) of the rounded constants holds only as well as
/// these are consistent with each other, amplified by about `√|d_j|` for a
/// large branch point: `F'` in double (a few ulps off) left a round trip of
/// 3.5e-12 at `|d_1| = 1.2e7`, DD constants 5e-16 (docs/kotter.md §3). `None`
/// when a DD value is not finite (then the double values stand).
fn refine_dd(lv: &Level, i: usize, t: C, sigma: C, df: C) -> Option<PolishedRoot> {
    let (h0, den) = match lv.mn {
        Some((m, n)) => {
            let mut h0 = Dd::ZERO;
            let (mut dm, mut dp) = (Dd::ZERO, Dd::ZERO);
            for j in 0..3 {
                h0 = h0.add(Dd::prod(m[j], n[j]));
                let (mi, pl) = (Dd::sum(m[j], -n[j]), Dd::sum(m[j], n[j]));
                dm = dm.add(mi.mul(mi));
                dp = dp.add(pl.mul(pl));
            }
            (h0, dm.mul(dp))
        }
        None => {
            let [h0, h1, _, _] = *lv.h;
            (
                Dd::new(h0),
                Dd::prod(h1, h1).sub(Dd::prod(h0, h0).mul_f64(4.0)),
            )
        }
    };
    let (x, sg) = offsets_dd(lv.a, i, Cdd::new(t), sigma);
    let f = f_dd(lv, h0, &x, sg);
    let step = f.to_c() / df;
    if !(step.re.is_finite() && step.im.is_finite()) {
        return None;
    }
    let t_dd = Cdd::new(t).sub(Cdd::new(step));
    let (x, sg) = offsets_dd(lv.a, i, t_dd, sigma);
    let dfd = df_dd(lv, h0, &x, sg);
    let fp = dfd.mul(sg).mul_dd(h0).mul_f64(-4.0).div_dd(den);
    let sq = fp.sqrt();
    let s = t_dd.add_f64(lv.a[i]);
    let out = PolishedRoot {
        s: s.to_c(),
        x,
        sigma: sg,
        fprime: fp.to_c(),
        sqrt_fprime: sq,
    };
    let finite = |z: Cdd| {
        let (hi, lo) = (z.to_c(), Complex64::new(z.re.lo, z.im.lo));
        hi.re.is_finite() && hi.im.is_finite() && lo.re.is_finite() && lo.im.is_finite()
    };
    let ok = finite(s)
        && out.x.iter().all(|&v| finite(v))
        && finite(sg)
        && finite(sq)
        && sq.to_c() != ZERO;
    ok.then_some(out)
}

/// The offsets `x_m = s − a_m` at `s = a_i + t` (exact sums) and `√G(s)` on
/// the branch nearest `sigma`, in DD.
fn offsets_dd(a: &[f64; 4], i: usize, t: Cdd, sigma: C) -> ([Cdd; 4], Cdd) {
    let x: [Cdd; 4] = std::array::from_fn(|m| {
        if m == i {
            t
        } else {
            t.add(Cdd::real(Dd::sum(a[i], -a[m])))
        }
    });
    let sg = x[0].mul(x[1]).mul(x[2]).mul(x[3]).sqrt();
    if (sg.to_c() * sigma.conj()).re < 0.0 {
        (x, sg.neg())
    } else {
        (x, sg)
    }
}

/// `P(s) = h1 s² − h2 s + h3` in DD from the offsets: from the state,
/// `P = Σ_j (x_j x_4 m_j² + x_k x_l n_j²)` (no cancellation near a root of
/// `G`), else from `h`.
fn p_dd(lv: &Level, x: &[Cdd; 4]) -> Cdd {
    match lv.mn {
        Some((m, n)) => CYCLIC
            .iter()
            .enumerate()
            .fold(Cdd::ZERO, |p, (j, &(_, k, l))| {
                p.add(x[j].mul(x[3]).mul_dd(Dd::prod(m[j], m[j])))
                    .add(x[k].mul(x[l]).mul_dd(Dd::prod(n[j], n[j])))
            }),
        None => {
            let [_, h1, h2, h3] = *lv.h;
            let s = x[0].add_f64(lv.a[0]);
            s.mul_f64(h1).add_f64(-h2).mul(s).add_f64(h3)
        }
    }
}

/// `P'(s)` in DD (the derivative of the forms of [`p_dd`]).
fn dp_dd(lv: &Level, x: &[Cdd; 4]) -> Cdd {
    match lv.mn {
        Some((m, n)) => CYCLIC
            .iter()
            .enumerate()
            .fold(Cdd::ZERO, |p, (j, &(_, k, l))| {
                p.add(x[j].add(x[3]).mul_dd(Dd::prod(m[j], m[j])))
                    .add(x[k].add(x[l]).mul_dd(Dd::prod(n[j], n[j])))
            }),
        None => {
            let [_, h1, h2, _] = *lv.h;
            x[0].add_f64(lv.a[0]).mul_f64(2.0 * h1).add_f64(-h2)
        }
    }
}

/// `f = P + 2h0 σ` (15) in DD.
///
/// The closed forms here and in [`df_dd`] cancel near the singular set by
/// about the relative distance `(h1² − 4h0²)/h1²` to it ([`Level::f`]), which
/// DD absorbs: its `u²` leaves `u² h1²/(h1² − 4h0²)`, far below double
/// precision for every state not refused by [`REDUCTION_FLOOR_RTOL`].
fn f_dd(lv: &Level, h0: Dd, x: &[Cdd; 4], sg: Cdd) -> Cdd {
    p_dd(lv, x).add(sg.mul_dd(h0).mul_f64(2.0))
}

/// `f' = P' + h0 G'/σ` in DD (`G'/√G = σ Σ_m 1/x_m`), with
/// `G' = (x_1 + x_2) x_3 x_4 + x_1 x_2 (x_3 + x_4)`.
fn df_dd(lv: &Level, h0: Dd, x: &[Cdd; 4], sg: Cdd) -> Cdd {
    let (a, b) = (x[0].mul(x[1]), x[2].mul(x[3]));
    let dg = x[0].add(x[1]).mul(b).add(a.mul(x[2].add(x[3])));
    dp_dd(lv, x).add(dg.mul_dd(h0).div(sg))
}

/// `h1² − 4h0² = |m − n|² |m + n|²` from the state: the difference of squares
/// in `h` loses all its digits near the singular set `m = ±n`, this product
/// does not.
fn den_from_state(m: &[f64; 3], n: &[f64; 3]) -> f64 {
    let (mut dm, mut dp) = (0.0, 0.0);
    for j in 0..3 {
        dm += (m[j] - n[j]) * (m[j] - n[j]);
        dp += (m[j] + n[j]) * (m[j] + n[j]);
    }
    dm * dp
}

fn constants_impl(
    a: &[f64; 4],
    h: &[f64; 4],
    p_at_a: &[f64; 4],
    mn: Option<([f64; 3], [f64; 3])>,
) -> Result<KotterConstants> {
    check_a(a)?;
    let den = match mn {
        Some((m, n)) => den_from_state(&m, &n),
        None => h[1] * h[1] - 4.0 * h[0] * h[0],
    };
    let f = quartic_f_den(a, h, den)?;
    if h[0] == 0.0 || h[0].abs() <= REDUCTION_FLOOR_RTOL * h[1] {
        return Err(Error::Singular {
            what: "state l",
            kind: SingularKind::VanishingH0,
            reason: format!(
                "h0 = {} vanishes: F(s) (19) = (h1 s^2 - h2 s + h3)^2 / h1^2 has double roots and \
                 the branch sigma = -(h1 s^2 - h2 s + h3)/(2 h0) is undefined",
                h[0]
            ),
        });
    }
    let s0 = quartic_roots(&f)?;
    let lv = Level { a, h, mn, den };
    let mut roots: Vec<PolishedRoot> = Vec::with_capacity(4);
    for p in 0..4 {
        // the partner of a conjugate pair is polished as the exact conjugate
        if p % 2 == 1 && s0[p] == s0[p - 1].conj() && s0[p].im != 0.0 {
            let partner = roots[p - 1].conj();
            roots.push(partner);
        } else {
            roots.push(polish_root(&lv, p_at_a, s0[p]));
        }
    }
    check_repeated(&roots.iter().map(|r| r.s).collect::<Vec<_>>())?;
    let s: [C; 4] = std::array::from_fn(|p| roots[p].s);
    let scale_a = a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    // Everything below is a function of (s_p, σ_p, F'(s_p)) and is carried in
    // DD, rounded to double once at the end: the third quadric (11) of the
    // rounded constants holds only as well as they are consistent with each
    // other, and near the singular set Δ_j^(3) and the forms u m + v n cancel
    // by about the inverse relative distance to it (docs/kotter.md §3).
    let mut u = [[Cdd::ZERO; 3]; 4];
    let mut v = [[Cdd::ZERO; 3]; 4];
    // √(x_j x_4) of the previous root (for its conjugate partner)
    let mut root_jd = [Cdd::ZERO; 3];
    for p in 0..4 {
        let sqrt_fp = roots[p].sqrt_fprime.to_c();
        if !(sqrt_fp.norm().is_finite() && sqrt_fp.norm() > 0.0) {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "F'(s_{}) = {} (19) at the root s_{} = {} is zero or not finite",
                    p + 1,
                    roots[p].fprime,
                    p + 1,
                    s[p]
                ),
            });
        }
        for (j, &aj) in a.iter().enumerate() {
            // the offsets are accurate to a few ulps relative (root_offsets):
            // only a root indistinguishable from a_j in double precision is 0/0
            if roots[p].x[j].to_c().norm() <= 4.0 * f64::EPSILON * scale_a {
                return Err(Error::Singular {
                    what: "state l",
                    kind: SingularKind::CoincidingBranchPoints,
                    reason: format!(
                        "the root s_{} = {} of F (19) coincides with a_{} = {aj}: sqrt(s_kl) = \
                         sqrt(G)/sqrt(s_j4) is 0/0 there",
                        p + 1,
                        s[p],
                        j + 1
                    ),
                });
            }
        }
        // The partner of a conjugate pair has the conjugate u, v, unless a
        // principal root (of x_j x_4 or of F') lies on its cut, where both
        // members take +i√|·|.
        let partner = p % 2 == 1
            && s[p].im != 0.0
            && s[p] == s[p - 1].conj()
            && roots[p].sqrt_fprime == roots[p - 1].sqrt_fprime.conj();
        let x = &roots[p].x;
        let inv_sfp = roots[p].sqrt_fprime.recip();
        let sg_sfp = roots[p].sigma.mul(inv_sfp);
        for j in 0..3 {
            if partner && root_jd[j].re.hi > 0.0 {
                u[p][j] = u[p - 1][j].conj();
                v[p][j] = v[p - 1][j].conj();
                continue;
            }
            let r = x[j].mul(x[3]).sqrt();
            root_jd[j] = r;
            u[p][j] = r.mul(inv_sfp);
            v[p][j] = sg_sfp.div(r);
        }
    }
    let mut dd = [[Cdd::ZERO; 3]; 3];
    for (p, q, r) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
        for j in 0..3 {
            dd[p][j] = u[q][j].mul(v[r][j]).sub(u[r][j].mul(v[q][j]));
        }
    }
    let mut sqrt_d = [ZERO; 3];
    let mut d = [ZERO; 3];
    let mut d_lo = [ZERO; 3];
    let mut d_dd = [Cdd::ZERO; 3];
    let mut abgd_dd = [[Cdd::ZERO; 3]; 4];
    let mut alpha = [ZERO; 3];
    let mut beta = [ZERO; 3];
    let mut gamma = [ZERO; 3];
    let mut delta = [ZERO; 3];
    for j in 0..3 {
        let d3 = dd[2][j];
        let size = (u[0][j].to_c().norm() + v[0][j].to_c().norm())
            * (u[1][j].to_c().norm() + v[1][j].to_c().norm());
        if d3.to_c().norm() <= 1e-12 * size {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "Delta_{}^(3) (25) vanishes: l_j^(1), l_j^(2) do not determine m_j, n_j",
                    j + 1
                ),
            });
        }
        // (26) both halves: √d_j = (Δ1 − iΔ2)/Δ3 = −Δ3/(Δ1 + iΔ2), since
        // (Δ1 − iΔ2)(Δ1 + iΔ2) = −Δ3². A small (or large) d_j is a cancellation
        // in one of Δ1 ∓ iΔ2; the other, larger one keeps full accuracy.
        let i_d2 = dd[1][j].mul_i();
        let (minus, plus) = (dd[0][j].sub(i_d2), dd[0][j].add(i_d2));
        let sd = if minus.to_c().norm() >= plus.to_c().norm() {
            minus.div(d3)
        } else {
            d3.div(plus).neg()
        };
        sqrt_d[j] = sd.to_c();
        let dj = sd.mul(sd);
        d[j] = dj.to_c();
        d_lo[j] = dj.sub(Cdd::new(d[j])).to_c();
        let (u1, v1, u2, v2) = (u[0][j], v[0][j], u[1][j], v[1][j]);
        let two_d3 = d3.mul_f64(2.0);
        abgd_dd[0][j] = v2.add(v1.mul_i()).div(two_d3);
        abgd_dd[1][j] = v2.sub(v1.mul_i()).div(two_d3);
        abgd_dd[2][j] = u2.add(u1.mul_i()).div(two_d3).neg();
        abgd_dd[3][j] = u2.sub(u1.mul_i()).div(two_d3).neg();
        d_dd[j] = dj;
        alpha[j] = abgd_dd[0][j].to_c();
        beta[j] = abgd_dd[1][j].to_c();
        gamma[j] = abgd_dd[2][j].to_c();
        delta[j] = abgd_dd[3][j].to_c();
        if d[j].norm() == 0.0 || !d[j].norm().is_finite() {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!("d_{} = {} (26) is zero or infinite", j + 1, d[j]),
            });
        }
    }
    let round2 = |x: &[[Cdd; 3]; 4]| x.map(|row| row.map(Cdd::to_c));
    let lo2 = |x: &[[Cdd; 3]; 4]| x.map(|row| row.map(|z| z.sub(Cdd::new(z.to_c())).to_c()));
    let (u_lo, v_lo) = (lo2(&u), lo2(&v));
    let (u, v) = (round2(&u), round2(&v));
    let dd = dd.map(|row| row.map(Cdd::to_c));
    let sigma: [C; 4] = std::array::from_fn(|p| roots[p].sigma.to_c());
    let sqrt_fp: [C; 4] = std::array::from_fn(|p| roots[p].sqrt_fprime.to_c());
    let kk = k_keps_dd(&abgd_dd, &d_dd);
    let (a_coef, b_coef, abgd39, eps, k) =
        h0_structure(&alpha, &beta, &gamma, &delta, &d, Some(kk))?;
    Ok(KotterConstants {
        a: *a,
        h: *h,
        s,
        sigma,
        sqrt_fprime: sqrt_fp,
        u,
        v,
        u_lo,
        v_lo,
        delta_det: dd,
        sqrt_d,
        d,
        d_lo,
        alpha,
        beta,
        gamma,
        delta,
        a_coef,
        b_coef,
        abgd39,
        eps,
        k,
    })
}

type H0Structure = ([C; 3], [C; 3], [C; 4], C, C);

/// `K`, `2Kε` and `K/κ` of the corrected (40) (the closed forms of
/// [`h0_structure`]) evaluated in DD from the DD `α_j … δ_j` (`abgd`) and `d_j`,
/// rounded once. Near the singular set `d_4` dominates the `d_j` by 1e15 and
/// more, so `w_j = 1/(d_j − d_4)` agree to ~`|d_j|/|d_4|` and the slope
/// `2Kε = (q_j − q_k)/(w_j − w_k)` divides a difference of nearly equal `q_j`
/// by one of nearly equal `w_j`: in double both are rounding noise (ε came out
/// NaN at `d_4 ~ 1e26`); `w_j − w_k = (d_k − d_j)/((d_j − d_4)(d_k − d_4))` and DD
/// `q_j` keep them.
fn k_keps_dd(abgd: &[[Cdd; 3]; 4], d: &[Cdd; 3]) -> (C, C, C) {
    let [al, be, ga, de] = abgd;
    let d4 = d[0].mul(d[1]).mul(d[2]);
    let dm4: [Cdd; 3] = std::array::from_fn(|j| d[j].sub(d4));
    let kappa = dm4[0].mul(dm4[1]).mul(dm4[2]);
    let mut k_over_kappa = Cdd::ZERO;
    for (j, &(_, kk, ll)) in CYCLIC.iter().enumerate() {
        let ct = d[j].sub(d[kk]).mul(d[j].sub(d[ll])).recip();
        k_over_kappa = k_over_kappa.add(ct.mul(d[j]).mul(be[j].mul(de[j])));
    }
    let dw = |j: usize, k: usize| d[k].sub(d[j]).div(dm4[j].mul(dm4[k]));
    let (pj, pk) = [(0, 1), (0, 2), (1, 2)]
        .into_iter()
        .max_by(|&(a, b), &(c, e)| {
            dw(a, b)
                .to_c()
                .norm()
                .partial_cmp(&dw(c, e).to_c().norm())
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .unwrap_or((0, 1));
    let q = |j: usize| al[j].mul(de[j]).add(be[j].mul(ga[j]));
    let k_eps = q(pj).sub(q(pk)).div(dw(pj, pk)).mul_f64(0.5);
    (
        kappa.mul(k_over_kappa).to_c(),
        k_eps.to_c(),
        k_over_kappa.to_c(),
    )
}

/// (38)–(40): `H0 = Σ_j m_j n_j` as a quadratic form in `ξ, η`, reduced modulo
/// Kötter's quadrics (11), all in closed form.
///
/// `H0 = Σ_j p_j ξ_j² + q_j ξ_j η_j + r_j η_j²` with `p_j = α_j γ_j`,
/// `q_j = α_j δ_j + β_j γ_j`, `r_j = β_j δ_j` (from (23)). Adding
/// `λ Q1 + μ Q2 + ν Q3` of (11) gives the form (38) when
/// `p_j + λ + ν d_j = −(r_j + λ + ν/d_j) =: A_j` and `B_j = q_j + μ`; (39) asks
/// `A_j = α + β d_j + γ/d_j`, `B_j = δ (d_j + 1/d_j)`. Times `d_j`, these are
/// values at `x = d_j` of quadratics in `x`, so a representative exists iff the
/// Lagrange interpolants through `d_1, d_2, d_3` have equal `x²` and `x⁰`
/// coefficients: `Σ_j c_j q_j = 0` and `Σ_j c_j (p_j + r_j) = 0` (`c_j` of (33));
/// both hold identically (they are checked here to [`STRUCTURE_RTOL`]).
///
/// The corrected (40): on the quadrics, by (30a), (30b), (31b),
/// `H0 ≡ K/d4 Σ η_j²/(d_j − d4) + 2Kε Σ ξ_jη_j/(d_j − d4) + Kε² Σ d_j ξ_j²/(d_j − d4)`
/// `= K g² (1 − ε P_0)²` with, in closed form (`κ = Π_m (d_m − d4)`,
/// `c̃_j` of (33)),
/// `K = κ Σ_j c̃_j d_j β_j δ_j`, `2Kε = κ Σ_j c̃_j (α_j δ_j + β_j γ_j)`,
/// `Kε² = (κ/d4) Σ_j c̃_j α_j γ_j`; the perfect square `(Kε)² = K · Kε²` is checked.
/// Reducing this representative to the form (38) (the residue sums
/// `Σ_j c̃_j d_j^n/(d_j − d4) = d4^n/κ`, `n ≤ 2`) gives (39) explicitly:
/// `β = −K/κ`, `γ = ε² d4² K/κ`, `δ = 2 ε d4 K/κ`,
/// `α = (K/(2κ)) (κ ε² + (e1 − d4)(1 − ε² d4²))`, `e1 = d1 + d2 + d3`
/// (docs/kotter.md §7).
fn h0_structure(
    alpha: &[C; 3],
    beta: &[C; 3],
    gamma: &[C; 3],
    delta: &[C; 3],
    d: &[C; 3],
    k_dd: Option<(C, C, C)>,
) -> Result<H0Structure> {
    let d4 = d[0] * d[1] * d[2];
    let ac: [C; 3] = std::array::from_fn(|j| alpha[j] * gamma[j]);
    let bc: [C; 3] = std::array::from_fn(|j| alpha[j] * delta[j] + beta[j] * gamma[j]);
    let cc: [C; 3] = std::array::from_fn(|j| beta[j] * delta[j]);
    let ct: [C; 3] = std::array::from_fn(|j| {
        let (k2, l2) = ((j + 1) % 3, (j + 2) % 3);
        ONE / ((d[j] - d[k2]) * (d[j] - d[l2]))
    });
    let c33: [C; 3] = std::array::from_fn(|j| (d[j] - d4) * ct[j]);

    // (38)–(39) exist iff Σ c_j q_j = 0 and Σ c_j (p_j + r_j) = 0 (the x² and x⁰
    // coefficients of the interpolants agree); relative to the size of the products
    // that enter (q_j and p_j + r_j themselves can cancel, and the sums cancel by
    // 1/|d_j − d_k| when two d_j nearly coincide).
    let rel_sum = |t: [C; 3], size: [f64; 3]| {
        let size: f64 = size.iter().sum();
        (t[0] + t[1] + t[2]).norm() / size.max(f64::MIN_POSITIVE)
    };
    let r1 = rel_sum(
        std::array::from_fn(|j| c33[j] * (ac[j] + cc[j])),
        std::array::from_fn(|j| c33[j].norm() * (ac[j].norm() + cc[j].norm())),
    );
    let r2 = rel_sum(
        std::array::from_fn(|j| c33[j] * bc[j]),
        std::array::from_fn(|j| {
            c33[j].norm() * ((alpha[j] * delta[j]).norm() + (beta[j] * gamma[j]).norm())
        }),
    );

    // (40) corrected, in closed form. On the quadrics H0 ≡ K g² − 2Kε g²P_0 +
    // Kε² g²P_0², with g² = Σ η_j²/((d_j − d4) d4) (30a), g²P_0 = −Σ ξ_jη_j/(d_j − d4)
    // (31b), g²P_0² = Σ d_j ξ_j²/(d_j − d4) (30b), up to λQ1 + μQ2 + νQ3 of (11).
    // Matching the coefficients of η_j², ξ_jη_j, ξ_j² and multiplying by (d_j − d4)
    // (and d_j) gives polynomials of degree ≤ 2 in d_j whose value at x = d4 —
    // the Lagrange interpolant through d1, d2, d3, L_j(d4) = c̃_j (d4 − d_k)(d4 − d_l)
    // — isolates the K terms, since the multiplier terms vanish at x = d4:
    // K = κ Σ c̃_j d_j r_j, 2Kε = κ Σ c̃_j q_j, Kε² d4 = κ Σ c̃_j p_j, with
    // κ = Π (d_m − d4) (docs/kotter.md §7).
    let kappa = (d[0] - d4) * (d[1] - d4) * (d[2] - d4);
    // K/κ directly (no division by κ, which vanishes when some d_j = d4).
    let k_over_kappa: C = match k_dd {
        Some((_, _, kok)) => kok,
        None => (0..3).map(|j| ct[j] * d[j] * cc[j]).sum::<C>(),
    };
    let k = match k_dd {
        Some((k, _, _)) => k,
        None => kappa * k_over_kappa,
    };
    // 2Kε: (d_j − d4) q_j is of degree 1 in d_j, so two nodes suffice and the
    // symmetric three-node form κ Σ c̃_j q_j equals the slope
    // (q_j − q_k)/(w_j − w_k), w_j = 1/(d_j − d4), through any pair. The pair with
    // the most separated w avoids the cancellation of the three-node form when
    // two d_j nearly coincide (c̃_j ~ 1/(d_1 − d_2): 1e12 on near_degenerate states).
    let w: [C; 3] = std::array::from_fn(|j| ONE / (d[j] - d4));
    let (pj, pk) = [(0, 1), (0, 2), (1, 2)]
        .into_iter()
        .fold((0, 1), |best, (j, kk)| {
            if (w[j] - w[kk]).norm() > (w[best.0] - w[best.1]).norm() {
                (j, kk)
            } else {
                best
            }
        });
    let k_eps: C = match k_dd {
        Some((_, ke, _)) => ke,
        None => 0.5 * (bc[pj] - bc[pk]) / (w[pj] - w[pk]),
    };
    let eps = k_eps / k;
    // The perfect square of (40), (Kε)² = K · Kε², with Kε² d4 = κ Σ c̃_j p_j;
    // relative to the size of the terms (the sum cancels when two d_j are close).
    let terms_e2: f64 = (0..3).map(|j| (ct[j] * ac[j]).norm()).sum();
    let k_eps2: C = kappa / d4 * (0..3).map(|j| ct[j] * ac[j]).sum::<C>();
    let r3 = (k_eps * k_eps - k * k_eps2).norm()
        / ((k_eps * k_eps).norm() + (k * kappa / d4).norm() * terms_e2);
    let worst = r1.max(r2).max(r3);
    if worst.is_nan() || worst > STRUCTURE_RTOL {
        return Err(Error::InvalidArgument {
            what: "Koetter constants",
            reason: format!(
                "H0 does not reduce to the form (38)/(40) on Koetter's quadrics: relative \
                 residual {worst:e} > {STRUCTURE_RTOL:e}"
            ),
        });
    }

    // (39) in closed form: the (40) representative p_j = Kε² d_j w_j,
    // q_j = 2Kε w_j, r_j = K w_j/d4 reduced to the form (38) (the representative
    // of that form is unique, so these are the paper's α, β, γ, δ).
    let e1 = d[0] + d[1] + d[2];
    let eps2 = eps * eps;
    let beta39 = -k_over_kappa;
    let gamma39 = eps2 * d4 * d4 * k_over_kappa;
    let delta39 = 2.0 * d4 * k_eps / kappa;
    let alpha39 = 0.5 * k_over_kappa * (kappa * eps2 + (e1 - d4) * (ONE - eps2 * d4 * d4));
    // A_j, B_j themselves from the same reduction applied to p, q, r per j:
    // ν = −(s_j − s_k)/(t_j − t_k), s = p + r, t_j = d_j + 1/d_j, then
    // A_j = (p_j − r_j)/2 + (ν/2)(d_j − 1/d_j); B_j = q_j + μ with
    // μ = δ t_j − q_j, δ = (q_j − q_k)/(t_j − t_k). Two nodes (the most separated
    // t) suffice and keep A_j, B_j accurate when two d_j nearly coincide, where
    // α, β, γ (three-node quantities, through K) are only known to ~u/|d_j − d_k|².
    let t: [C; 3] = std::array::from_fn(|j| d[j] + ONE / d[j]);
    let (tj, tk) = [(0, 1), (0, 2), (1, 2)]
        .into_iter()
        .fold((0, 1), |best, (j, kk)| {
            if (t[j] - t[kk]).norm() > (t[best.0] - t[best.1]).norm() {
                (j, kk)
            } else {
                best
            }
        });
    let nu = -((ac[tj] + cc[tj]) - (ac[tk] + cc[tk])) / (t[tj] - t[tk]);
    let delta_two = (bc[tj] - bc[tk]) / (t[tj] - t[tk]);
    let mu = delta_two * t[tj] - bc[tj];
    let a_coef: [C; 3] =
        std::array::from_fn(|j| 0.5 * (ac[j] - cc[j]) + 0.5 * nu * (d[j] - ONE / d[j]));
    let b_coef: [C; 3] = std::array::from_fn(|j| bc[j] + mu);
    let abgd39 = [alpha39, beta39, gamma39, delta39];
    Ok((a_coef, b_coef, abgd39, eps, k))
}

/// `l^(p) = l(s_p)/√F'(s_p)` (20) for `p = 1 … 4`, on the documented branches.
///
/// Summed in DD from `u + u_lo`, `v + v_lo` ([`KotterConstants::u_lo`]) and
/// rounded once: near the singular set the two terms cancel.
pub fn l_p(k: &KotterConstants, l: &[f64; 6]) -> [[C; 3]; 4] {
    l_p_dd(k, l).map(|row| row.map(Cdd::to_c))
}

fn l_p_dd(k: &KotterConstants, l: &[f64; 6]) -> [[Cdd; 3]; 4] {
    let (m, n) = m_n(l);
    std::array::from_fn(|p| {
        std::array::from_fn(|j| {
            let u = Cdd::from_parts(k.u[p][j], k.u_lo[p][j]);
            let v = Cdd::from_parts(k.v[p][j], k.v_lo[p][j]);
            u.mul_f64(m[j]).add(v.mul_f64(n[j]))
        })
    })
}

/// Kötter's vectors (22): `ξ = l^(1) + i l^(2)`, `η = l^(1) − i l^(2)` (from
/// the DD sums of [`l_p`], rounded once).
pub fn xi_eta(k: &KotterConstants, l: &[f64; 6]) -> ([C; 3], [C; 3]) {
    let lp = l_p_dd(k, l);
    let xi = std::array::from_fn(|j| lp[0][j].add(lp[1][j].mul_i()).to_c());
    let eta = std::array::from_fn(|j| lp[0][j].sub(lp[1][j].mul_i()).to_c());
    (xi, eta)
}

/// Relative size of the imaginary part above which [`l_from_xi_eta`] refuses
/// to return a real state: a round trip leaves ~1e-15 on well-conditioned
/// curves and up to ~1e-8 near coinciding branch points; data that do not
/// come from a real state leave an O(1) imaginary part.
pub const REAL_RTOL: f64 = 1e-6;

/// The state from `ξ, η` by (23): `m_j = α_j ξ_j + β_j η_j`,
/// `n_j = γ_j ξ_j + δ_j η_j`, `l = (m3, −m2, n1, m1, n2, n3)`.
///
/// Errors: non-finite input; an imaginary part larger than [`REAL_RTOL`]
/// times the size of `l` (the data do not describe a real state).
pub fn l_from_xi_eta(k: &KotterConstants, xi: &[C; 3], eta: &[C; 3]) -> Result<[f64; 6]> {
    real_state(&k.coefficients23(), xi, eta)
}

fn real_state(k: &Coefficients23, xi: &[C; 3], eta: &[C; 3]) -> Result<[f64; 6]> {
    let mut m = [0.0; 3];
    let mut n = [0.0; 3];
    let mut im: f64 = 0.0;
    let mut size: f64 = 0.0;
    for j in 0..3 {
        let mj = k.alpha[j] * xi[j] + k.beta[j] * eta[j];
        let nj = k.gamma[j] * xi[j] + k.delta[j] * eta[j];
        if !(mj.re.is_finite() && mj.im.is_finite() && nj.re.is_finite() && nj.im.is_finite()) {
            return Err(Error::NonFinite {
                what: "m_j, n_j from (xi, eta)",
                index: j,
            });
        }
        im = im.max(mj.im.abs()).max(nj.im.abs());
        size = size.max(mj.norm()).max(nj.norm());
        m[j] = mj.re;
        n[j] = nj.re;
    }
    if im > REAL_RTOL * size {
        return Err(Error::InvalidArgument {
            what: "xi, eta",
            reason: format!(
                "they give a complex state: max |Im m_j, Im n_j| = {im:e} > {REAL_RTOL:e} * {size:e}"
            ),
        });
    }
    Ok(l_from_m_n(&m, &n))
}

/// The start of the inverse map of (37) and `P_0` of (31b), from the closed
/// forms of the curve module (`g² = Σ_j c̃_j Y_j²/d_4` (30a),
/// `z1 + z2 = d_4 + Σ_j c̃_j X_j²/g²`, `z1 z2 = Σ_j c̃_j d_j X_j²/g²` (30b),
/// `g² P_0 = −Σ_j c̃_j X_j Y_j` (31b), `X_j = ξ_j/√c_j`, `Y_j = η_j/√c_j`), evaluated
/// in DD on the unrounded curve `d + d_lo` from the DD `ξ, η`. Near the singular
/// set these sums cancel by `|d_4|/|z|` (1e13 and more: `d_4 ~ 1e19` against
/// points `~1e7`), so in double precision they put a point thousands of units
/// off, across a pair of branch points a few units apart; in DD they leave
/// ~`u² |d_4|/|z|`. The offsets are taken from the rounded curve's branch
/// points. `None` when a value is not finite (then the double-precision
/// closed forms stand).
fn inverse_start(
    k: &KotterConstants,
    curve: &KotterCurve,
    xi: &[Cdd; 3],
    eta: &[Cdd; 3],
) -> Option<(crate::curve::InverseStart, C)> {
    let d: [Cdd; 3] = std::array::from_fn(|j| Cdd::from_parts(k.d[j], k.d_lo[j]));
    let d4 = d[0].mul(d[1]).mul(d[2]);
    let sc_round = curve.c().map(sqrt_principal);
    let mut ct = [Cdd::ZERO; 3];
    let mut x = [Cdd::ZERO; 3];
    let mut y = [Cdd::ZERO; 3];
    for (j, &(_, kk, ll)) in CYCLIC.iter().enumerate() {
        ct[j] = d[j].sub(d[kk]).mul(d[j].sub(d[ll])).recip();
        let mut sc = d[j].sub(d4).mul(ct[j]).sqrt();
        // the curve's branch of √c_j (principal of the rounded c_j)
        if (sc.to_c() * sc_round[j].conj()).re < 0.0 {
            sc = sc.neg();
        }
        x[j] = xi[j].div(sc);
        y[j] = eta[j].div(sc);
    }
    let sum = |f: &dyn Fn(usize) -> Cdd| (0..3).fold(Cdd::ZERO, |acc, j| acc.add(f(j)));
    let g2 = sum(&|j| ct[j].mul(y[j]).mul(y[j])).div(d4);
    let s1 = d4.add(sum(&|j| ct[j].mul(x[j]).mul(x[j])).div(g2));
    let s2 = sum(&|j| ct[j].mul(d[j]).mul(x[j]).mul(x[j])).div(g2);
    let p0 = sum(&|j| ct[j].mul(x[j]).mul(y[j])).div(g2).neg();
    // roots of z² − s1 z + s2, the larger first, without cancellation
    let sq = s1.mul(s1).sub(s2.mul_f64(4.0)).sqrt();
    let q = if (s1.to_c().conj() * sq.to_c()).re >= 0.0 {
        s1.add(sq)
    } else {
        s1.sub(sq)
    };
    let z1 = q.mul_f64(0.5);
    let z2 = s2.div(z1);
    let bp = curve.branch_points();
    let offsets = |z: Cdd| -> [C; 5] { bp.map(|b| z.sub(Cdd::new(b)).to_c()) };
    let start = crate::curve::InverseStart {
        z: [z1.to_c(), z2.to_c()],
        zd: [offsets(z1), offsets(z2)],
        g2: g2.to_c(),
    };
    let finite = |v: &C| v.re.is_finite() && v.im.is_finite();
    let ok = start.z.iter().all(finite)
        && start.zd.iter().flatten().all(finite)
        && finite(&start.g2)
        && start.g2 != ZERO
        && finite(&p0.to_c());
    ok.then_some((start, p0.to_c()))
}

/// Tolerance passed to the inverse map of the curve module
/// ([`KotterCurve::points_from_xi_eta`]): exact data reproduce `(ξ, η)` to
/// ~1e-14 relative on well-conditioned curves, to ~1e-7 when two branch
/// points nearly coincide (points trapped between them); data off the
/// quadrics miss by O(1), so 1e-6 separates the two.
pub const UNIFORM_RTOL: f64 = 1e-6;

/// Relative agreement required between `g` from (30a) (the curve's inverse
/// map) and the corrected (42). The sign choice needs only `|Δg| ≪ |g|`; the
/// accuracy of the closed forms for `K`, `ε` (sums with `c̃_j ~ 1/(d_j − d_k)`)
/// degrades with the conditioning of the `d_j` (clustered roots of F give
/// ~1e-8), so 1e-6 flags a wrong structure, not rounding.
pub const G42_RTOL: f64 = 1e-6;

/// A state in Kötter's coordinates: the constants of its level set, the
/// vectors `l^(p)`, `ξ, η`, the curve (8) and the point pair with `g` (37), (42).
#[derive(Debug, Clone, PartialEq)]
pub struct KotterState {
    /// Constants of the level set.
    pub constants: KotterConstants,
    /// `l^(p)` (20), `p = 1 … 4`.
    pub l_p: [[C; 3]; 4],
    /// `ξ` (22).
    pub xi: [C; 3],
    /// `η` (22).
    pub eta: [C; 3],
    /// The curve (8) with the `d_j` of (26).
    pub curve: KotterCurve,
    /// `P_0 = √(z1 z2)` in the curve's branch, from (31b): `P_0 = −Σ_j c̃_j P_j4 P_kl`.
    pub p0: C,
    /// The points, `g` and the branch of the `P_j` (see [`crate::curve`]),
    /// with `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4` (37); the sign of `g` is
    /// fixed by the corrected (42): `g (1 − ε P_0) = √(h0/K)` (principal root).
    pub points: WurzelPoints,
}

/// From a state `l` of the top with parameters `a` to Kötter's coordinates
/// and the points of the curve (the algebraic uniformization (37), (42)).
///
/// `g` (37) is fixed up to sign by (30a), `g² = Σ_j c̃_j (η_j/√c_j)² / d4`;
/// the corrected (40) reads `h0 = K g² (1 − ε P_0)²`, so the corrected (42)
/// is `g = √(h0/K) / (1 − ε P_0)`, which fixes the sign (and is checked).
///
/// Errors: those of [`kotter_constants`], of [`KotterCurve::new`] (coinciding
/// branch points `d_j`: the genus drops) and of the inverse map of the curve
/// module (`z1 = z2`, data off the quadrics); and `1 − ε P_0 = 0` (then (42)
/// puts `g` at infinity: `ξ, η` are not finite multiples of the `P_jk`).
pub fn kotter(a: &[f64; 4], l: &[f64; 6]) -> Result<KotterState> {
    let constants = kotter_constants(a, l)?;
    kotter_with(constants, l)
}

/// [`kotter`] for a state whose level-set constants are already known
/// (e.g. along a trajectory). The constants must belong to `l`'s level set.
pub fn kotter_with(constants: KotterConstants, l: &[f64; 6]) -> Result<KotterState> {
    check_finite("l", l)?;
    near_singular(l, kotter_with_impl(constants, l))
}

fn kotter_with_impl(constants: KotterConstants, l: &[f64; 6]) -> Result<KotterState> {
    let lp_dd = l_p_dd(&constants, l);
    let lp = lp_dd.map(|row| row.map(Cdd::to_c));
    let xi_dd: [Cdd; 3] = std::array::from_fn(|j| lp_dd[0][j].add(lp_dd[1][j].mul_i()));
    let eta_dd: [Cdd; 3] = std::array::from_fn(|j| lp_dd[0][j].sub(lp_dd[1][j].mul_i()));
    let (xi, eta) = (xi_dd.map(Cdd::to_c), eta_dd.map(Cdd::to_c));
    let [d1, d2, d3] = constants.d;
    let curve = KotterCurve::new(d1, d2, d3)?;
    let start = inverse_start(&constants, &curve, &xi_dd, &eta_dd);
    let p0 = match &start {
        Some((_, p0)) => *p0,
        None => {
            let ct = curve.c_tilde();
            let sc = curve.c().map(sqrt_principal);
            let d4 = curve.branch_points()[4];
            let x: [C; 3] = std::array::from_fn(|j| xi[j] / sc[j]);
            let y: [C; 3] = std::array::from_fn(|j| eta[j] / sc[j]);
            let g2: C = (0..3).map(|j| ct[j] * y[j] * y[j]).sum::<C>() / d4;
            let g2p0: C = -(0..3).map(|j| ct[j] * x[j] * y[j]).sum::<C>();
            g2p0 / g2
        }
    };
    let g42_at = |p0: C| -> Result<C> {
        let one_m = ONE - constants.eps * p0;
        let size = 1.0 + (constants.eps * p0).norm();
        if !(one_m.re.is_finite() && one_m.im.is_finite()) {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "1 - eps P_0 is not finite (eps = {}, P_0 = {p0}): g (42) is undefined",
                    constants.eps
                ),
            });
        }
        if one_m.norm() <= 1e-12 * size {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!("1 - eps P_0 = {one_m} vanishes: g (42) is infinite at this state"),
            });
        }
        Ok(sqrt_principal(C::new(constants.h[0], 0.0) / constants.k) / one_m)
    };
    // The sign of g from (42) at the closed-form P_0 (31b); the consistency
    // check at P_0 of the polished points: near the singular set the closed
    // form cancels like the start of the inverse map (to ~1e-6 at
    // (h1² − 4h0²)/h1² = 4e-12), while P_0 = eps_0 √z1 √z2 of the points is
    // accurate.
    let g_sign = g42_at(p0)?;
    let lmap = [
        constants.alpha,
        constants.beta,
        constants.gamma,
        constants.delta,
    ];
    let points = curve.points_from_xi_eta_start(
        xi,
        eta,
        None,
        Some(g_sign),
        UNIFORM_RTOL,
        Some(&lmap),
        start.as_ref().map(|(s, _)| s),
    )?;
    let p0 =
        f64::from(points.eps[0]) * sqrt_principal(points.zd1[0]) * sqrt_principal(points.zd2[0]);
    let g42 = g42_at(p0)?;
    let mis = (points.g - g42).norm();
    if mis.is_nan() || mis > G42_RTOL * g42.norm() {
        return Err(Error::InvalidArgument {
            what: "state l",
            reason: format!(
                "the corrected (42) g = sqrt(h0/K)/(1 - eps P0) = {g42} disagrees with g = {} \
                 from (30a) (|difference| = {mis:e})",
                points.g
            ),
        });
    }
    Ok(KotterState {
        constants,
        l_p: lp,
        xi,
        eta,
        curve,
        p0,
        points,
    })
}

/// States whose integrals differ from the level set's by more than
/// `LEVEL_SET_RTOL` (relative to `h1` and its powers, see [`on_level_set`])
/// are not on it: a trajectory integrated at `rtol = 1e-10` drifts by
/// ~1e-10 over long runs, a state of another level set by O(1).
pub const LEVEL_SET_RTOL: f64 = 1e-6;

/// Checks that `l` lies on the level set of `constants` (to [`LEVEL_SET_RTOL`]):
/// `|h_i(l) − h_i| ≤ LEVEL_SET_RTOL · h1 · A^{max(i−1, 0)}`, `A = max(1, max|a_j|)`
/// (`h0`, `h1` are quadratic in `l`; `h2`, `h3` carry one and two powers of `a`).
pub fn on_level_set(constants: &KotterConstants, l: &[f64; 6]) -> Result<()> {
    check_finite("l", l)?;
    let h = integrals(&constants.a, l);
    let amax = constants.a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let h1 = constants.h[1].abs().max(h[1].abs());
    for (i, (&hi, &ci)) in h.iter().zip(constants.h.iter()).enumerate() {
        let scale = h1 * amax.powi((i as i32 - 1).max(0));
        let miss = (hi - ci).abs();
        if miss.is_nan() || miss > LEVEL_SET_RTOL * scale {
            return Err(Error::InvalidArgument {
                what: "state l",
                reason: format!(
                    "it is not on this level set: h{i}(l) = {:e} differs from the level set's \
                     h{i} = {ci:e} by {miss:e} > {LEVEL_SET_RTOL:e} * {scale:e}",
                    hi
                ),
            });
        }
    }
    Ok(())
}

/// Exchanges the two points of `cur` when that brings them nearer to those
/// of `prev` (the pair is unordered; (27)–(28) and with them `ξ, η`, `g`,
/// `eps` are symmetric in the two points).
pub fn follow_order(prev: &WurzelPoints, cur: &mut WurzelPoints) {
    let same = (cur.z1 - prev.z1).norm() + (cur.z2 - prev.z2).norm();
    let swapped = (cur.z1 - prev.z2).norm() + (cur.z2 - prev.z1).norm();
    if swapped < same {
        std::mem::swap(&mut cur.z1, &mut cur.z2);
        std::mem::swap(&mut cur.y1, &mut cur.y2);
        std::mem::swap(&mut cur.zd1, &mut cur.zd2);
    }
}

/// One branch per level set: the states `l` (e.g. samples of a trajectory,
/// in time order) mapped with the constants of one level set, fixed once
/// (`kotter_constants(a, l0)`), by [`kotter_with`]. The roots' order, `σ_p`,
/// `√F'(s_p)`, `√c_j`, `K` and with them `ξ, η` (linear in `l`) and
/// `g = √(h0/K)/(1 − εP_0)` (42) are then the same functions of `l` at every
/// sample, so the divisor moves continuously along a trajectory and never
/// jumps to its hyperelliptic-involution image. Each row's point pair is
/// ordered to follow the previous successful row ([`follow_order`]).
///
/// Per row: the error of [`on_level_set`] or [`kotter_with`].
pub fn kotter_along(constants: &KotterConstants, rows: &[[f64; 6]]) -> Vec<Result<KotterState>> {
    let mut prev: Option<WurzelPoints> = None;
    rows.iter()
        .map(|l| {
            on_level_set(constants, l)?;
            let mut st = kotter_with(constants.clone(), l)?;
            if let Some(p) = &prev {
                follow_order(p, &mut st.points);
            }
            prev = Some(st.points);
            Ok(st)
        })
        .collect()
}

/// The inverse of [`kotter`]: the state `l` from the curve's points, `g`
/// and the branch of the `P_j` by (37) and (23):
/// `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`, `m_j = α_j ξ_j + β_j η_j`,
/// `n_j = γ_j ξ_j + δ_j η_j`, `l = (m3, −m2, n1, m1, n2, n3)`.
///
/// `z = [z1, z2]`, `y = [y1, y2]`; `zd = Some([zd1, zd2])` gives the offsets
/// `zd_i[j] = z_i − d_j` (as returned in [`KotterState::points`]), used for
/// the roots `√(z_i − d_j)` of (27)–(28) — with only `z` (`zd = None`) a
/// point within `δ` of a branch point loses `u |z| / δ` (see
/// [`crate::curve::CurvePoint`]).
///
/// Errors: those of [`KotterCurve::xi_eta_points`] (points off the curve,
/// offsets inconsistent with `z`, `z1 = z2`, a bad branch) and of
/// [`l_from_xi_eta`] (a complex state).
pub fn from_kotter(
    coef: &Coefficients23,
    d: [C; 3],
    z: [C; 2],
    y: [C; 2],
    zd: Option<[[C; 5]; 2]>,
    g: C,
    branch: [i8; 5],
) -> Result<[f64; 6]> {
    let curve = KotterCurve::new(d[0], d[1], d[2])?;
    let pt = |i: usize| match zd {
        Some(o) => CurvePoint {
            z: z[i],
            y: y[i],
            zd: o[i],
        },
        None => curve.point(z[i], y[i]),
    };
    let (xi, eta) = curve.xi_eta_points(&pt(0), &pt(1), g, Some(branch), None)?;
    coef.state(&xi, &eta)
}

/// The coefficients `α_j, β_j, γ_j, δ_j` of (23), the linear map `(ξ, η) → (m, n)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients23 {
    /// `α_j`.
    pub alpha: [C; 3],
    /// `β_j`.
    pub beta: [C; 3],
    /// `γ_j`.
    pub gamma: [C; 3],
    /// `δ_j`.
    pub delta: [C; 3],
}

impl Coefficients23 {
    /// The state of (23); see [`l_from_xi_eta`].
    pub fn state(&self, xi: &[C; 3], eta: &[C; 3]) -> Result<[f64; 6]> {
        for (what, v) in [
            ("alpha", &self.alpha),
            ("beta", &self.beta),
            ("gamma", &self.gamma),
            ("delta", &self.delta),
        ] {
            if let Some(index) = v
                .iter()
                .position(|z| !(z.re.is_finite() && z.im.is_finite()))
            {
                return Err(Error::NonFinite { what, index });
            }
        }
        real_state(self, xi, eta)
    }
}

impl KotterConstants {
    /// The coefficients of (23).
    pub fn coefficients23(&self) -> Coefficients23 {
        Coefficients23 {
            alpha: self.alpha,
            beta: self.beta,
            gamma: self.gamma,
            delta: self.delta,
        }
    }
}

#[cfg(test)]
mod tests;
