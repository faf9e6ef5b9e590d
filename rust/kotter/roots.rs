//! The quartic `F(s)` (19) whose roots `s_1 … s_4` carry the level set, and
//! its roots by the Aberth–Ehrlich iteration (O. Aberth, *Iteration methods
//! for finding all zeros of a polynomial simultaneously*, Math. Comp. 27
//! (1973) 339–344) with Newton polishing, in the documented order.

use super::{C, ONE, ZERO};
use crate::error::{check_finite, cnum_within, num, Error, Result, SingularKind};
use crate::numeric::complex::Modulus;
use crate::numeric::tol::REDUCTION_FLOOR_RTOL;

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
pub(super) fn quartic_f_den(a: &[f64; 4], h: &[f64; 4], den: f64) -> Result<[f64; 5]> {
    let [h0, h1, h2, h3] = *h;
    if h1 == 0.0 {
        // h1 = |l|^2: only the rest state, which has no curve (and no distance
        // to the self-dual set to report).
        return Err(Error::Singular {
            what: "state l",
            kind: SingularKind::ZeroState,
            reason: "l = 0 (h1 = 0): the rest state; the motion is l(t) = 0, there is no \
                     curve (8)"
                .into(),
        });
    }
    if den.abs() <= REDUCTION_FLOOR_RTOL * h1 * h1 {
        return Err(Error::Singular {
            what: "state l",
            kind: SingularKind::SelfDual,
            reason: format!(
                "h1^2 - 4 h0^2 = {} vanishes (h1 = {}, h0 = {}; the state is self-dual or \
                 anti-self-dual, m = +-n, or at a relative distance (h1^2 - 4 h0^2)/h1^2 = {} \
                 <= {REDUCTION_FLOOR_RTOL:e} from it): F(s) (19) is not defined",
                num(den),
                num(h1),
                num(h0),
                num(den / (h1 * h1))
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
    let (z, converged, last) = quartic_roots_unordered(f)?;
    // A cluster is reported as a repeated root even when the iteration has not
    // met its tolerance: Aberth converges only linearly to a multiple root.
    check_repeated(&z)?;
    check_converged(converged, last)?;
    Ok(documented_order(z))
}

/// The no-convergence error of [`quartic_roots_unordered`]'s iteration.
pub(super) fn check_converged(converged: bool, last: f64) -> Result<()> {
    if !converged && last > ROOT_STAGNATION {
        return Err(Error::NoConvergence {
            what: "roots of F(s) (19)",
            tol: ROOT_STAGNATION,
            reached: last,
            iterations: 500,
        });
    }
    Ok(())
}

/// The Aberth–Ehrlich iteration and two Newton steps of [`quartic_roots`],
/// unordered and unchecked, with whether it converged and its last relative
/// step.
pub(super) fn quartic_roots_unordered(f: &[f64; 5]) -> Result<([C; 4], bool, f64)> {
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
    Ok((z, converged, last))
}

/// Two roots closer than [`REPEATED_ROOT_RTOL`] times the larger of the two
/// are a repeated root. Relative to the pair, not to the largest root: near
/// the singular set `h1² = 4h0²` one or two roots of `F` grow like the
/// inverse distance to it while the others stay of the size of the `a_i`.
pub(super) fn check_repeated(z: &[C]) -> Result<()> {
    match repeated_pair(z) {
        None => Ok(()),
        Some((i, j)) => Err(repeated_root_error(z, i, j)),
    }
}

/// The error of a repeated root `z_i ≈ z_j` of `F`.
pub(super) fn repeated_root_error(z: &[C], i: usize, j: usize) -> Error {
    Error::Singular {
        what: "state l",
        kind: SingularKind::RepeatedRoot,
        reason: format!(
            "F(s) (19) has a repeated root s = {} (|s_{} - s_{}| = {:.1e}): l^(p) \
                         (20) divides by sqrt(F'(s_p)) = 0",
            // The pair's mean, to the digits its separation leaves.
            cnum_within((z[i] + z[j]) * 0.5, (z[i] - z[j]).modulus()),
            i + 1,
            j + 1,
            (z[i] - z[j]).modulus()
        ),
    }
}

/// The first two roots closer than [`REPEATED_ROOT_RTOL`] times the larger of
/// the two ([`check_repeated`]).
pub(super) fn repeated_pair(z: &[C]) -> Option<(usize, usize)> {
    for i in 0..z.len() {
        for j in (i + 1)..z.len() {
            let pair = z[i].modulus().max(z[j].modulus());
            if (z[i] - z[j]).modulus() <= REPEATED_ROOT_RTOL * pair {
                return Some((i, j));
            }
        }
    }
    None
}

/// The roots of [`quartic_roots_unordered`] in the documented order, as
/// [`quartic_roots`] returns them.
pub(super) fn documented_order(z: [C; 4]) -> [C; 4] {
    let scale = z.iter().fold(1.0f64, |m, v| m.max(v.modulus()));
    order_roots(z, scale)
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
                    .modulus()
                    .partial_cmp(&(r[j] - s1.conj()).modulus())
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
