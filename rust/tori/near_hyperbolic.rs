//! Frequencies of states next to a transversally hyperbolic so(3)-block
//! orbit, where the genus-2 route refuses (docs/degenerate.md §11,
//! "Frequencies next to a hyperbolic block orbit").
//!
//! Along the line `l(σ) = l_E + σ l_⊥/δ` off a block state `l_E` whose Euler
//! orbit (period `1/ν_E`) has the transverse multipliers `e^{±λ/ν_E}`, the
//! tori pass the orbit at a distance `~σ` once per cycle of a long period;
//! no cycle shrinks onto it. The curve is pinched, and by the
//! Picard–Lefschetz formula the period of the cycle through the pinch is
//! `log σ²` times that of the vanishing cycle plus a function analytic in
//! `x = σ²` (even in `σ` by the block's reflection symmetry). In the lattice
//! basis `(s, g)` with `s` the cycle along the orbit and `g` the long one,
//! the velocity is `w = ν1 s + ν2 g`, and both
//!
//! * `1/ν2 = (2/λ) ln(1/σ) + A(x) + B(x) ln(1/σ)` (the time of one long
//!   cycle: `(1/λ) ln(1/σ²)` spent next to the orbit, `A(0)` elsewhere;
//!   `B(0) = 0`), and
//! * `(ν1 − ε ν_E)/ν2 = C(x) + D(x) ln(1/σ)` with `D(0) = 0` and `ε = ±1`
//!   (the cycle `s` tends to the orbit itself),
//!
//! are linear in `ln(1/σ)` with coefficients analytic in `x`. The slope
//! `2/λ` is the orbit's own ([`hyperbolic_exponent_with`]); the rest is
//! fitted to the genus-2 frequencies of seven node states `σ = 1e-3 … 8e-3`
//! out (the basis `(1, x, x², x ln(1/σ), x² ln(1/σ))`), and the fits are
//! evaluated at the state's `σ = δ`. On the harsh draw the fits evaluated at
//! `σ = 3e-5` and `1e-4`, where the genus-2 torus answers on its own, meet it
//! to 2.7e-13 (median) and 4.1e-11 (max) (docs/degenerate.md §11).
//!
//! The answer is given only where a second node set (`0.7` times the first,
//! distinct states) gives the same frequencies, and the fits' residuals and
//! the exponent's error leave a bound of at most [`NEAR_EULER_RTOL`].

use super::motion::state_frequencies_plain;
use super::near_euler::{first_answer, unique_best, NEAR_EULER_RTOL, NODE_MARGIN};
use super::Status;
use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;
use crate::solution::motion::Motion;
use crate::solution::normalize::TopFrame;
use crate::solution::transverse::hyperbolic_exponent_with;

/// Relative distances of the node states from the block (the first at least
/// [`NODE_MARGIN`] times the state's distance: states beyond 1.25e-4 are not
/// answered; closer-in sets are tried where these fail). Seven
/// nodes for five coefficients: the fits' residuals show whether the
/// frequencies follow the form of the module doc.
pub const HYPERBOLIC_NODES: [f64; 7] = [1e-3, 1.5e-3, 2e-3, 3e-3, 4e-3, 6e-3, 8e-3];

/// The second node set, as a factor of the first: none of its states is one
/// of the first set's.
const SECOND_SET: f64 = 0.7;

/// The frequency `ν2` of the long cycle is the integer combination of a
/// node's frequencies whose `1/ν2` moves between the first two nodes with
/// the slope `2/λ` in `ln(1/σ)` to this (relative): the analytic terms shift
/// the slope there by `~x` (measured up to 1e-4).
const SLOPE_ID_RTOL: f64 = 1e-2;

/// Largest entry of the integer combinations tried for `ν2`.
const MAX_COMB: i32 = 4;

/// Largest fitted coefficient of `ln(1/σ)` in `(ν1 − ε ν_E)/ν2`, relative to
/// the other sign's (`2 ν_E · 2/λ`), for the sign `ε` to be taken: the fit
/// with that extra column is ill-conditioned (`ln(1/σ)` varies by a factor
/// 1.4 over the nodes), and only has to tell 0 from ±1 (measured: 8e-3).
/// The fits themselves are checked by their residuals and the second set.
const SIGN_RTOL: f64 = 0.1;

/// The line `le + σ (l0 − le)/δ` through the state and what every fit on it
/// shares: the block state's Euler frequency `ν_E` and the orbit's slope
/// `2/λ`.
struct Line<'a> {
    frame: &'a TopFrame,
    l0: &'a [f64; 6],
    le: &'a [f64; 6],
    delta: f64,
    nu_e: f64,
    slope: f64,
    cancel: &'a Cancel,
}

/// The refusal of the fit (the caller keeps the genus-2 route's status).
fn refusal(reason: String) -> Error {
    Error::Unverified {
        what: "frequencies next to a transversally hyperbolic so(3)-block orbit",
        reason,
    }
}

/// `(ν1, ν2)` (user's time) of the state `l0`, at relative distance `delta`
/// from the block state `le` whose Euler frequency is `nu_e` and whose orbit
/// is transversally hyperbolic, by the fits of the module doc; an error where
/// they do not apply or their bound exceeds [`NEAR_EULER_RTOL`].
pub(super) fn near_hyperbolic_frequencies(
    frame: &TopFrame,
    l0: &[f64; 6],
    le: &[f64; 6],
    delta: f64,
    nu_e: f64,
    cancel: &Cancel,
) -> Result<[f64; 2]> {
    let (lambda, lambda_rel) = Motion::in_frame(frame.clone(), le)
        .and_then(|m| hyperbolic_exponent_with(&m, cancel))
        .map_err(|e| match e {
            Error::Interrupted => Error::Interrupted,
            e => refusal(format!("the block orbit's transverse exponent: {e}")),
        })?;
    // finite and positive (hyperbolic_exponent_with)
    fit_with_slope(frame, l0, le, delta, nu_e, 2.0 / lambda, lambda_rel, cancel)
}

/// The fits of the module doc with a given slope `slope` of `1/ν2` in
/// `ln(1/σ)` (relative error `slope_rel`): `2/λ` next to a block orbit,
/// `4/λ` next to a coordinate-plane equilibrium that is a saddle in one
/// direction and elliptic (frequency `nu_e`) in the other
/// ([`super::near_plane`]), for the state `l0` at relative distance `delta`
/// from `le`.
#[allow(clippy::too_many_arguments)]
pub(super) fn fit_with_slope(
    frame: &TopFrame,
    l0: &[f64; 6],
    le: &[f64; 6],
    delta: f64,
    nu_e: f64,
    slope: f64,
    slope_rel: f64,
    cancel: &Cancel,
) -> Result<[f64; 2]> {
    // The standard nodes first; where they do not answer, nodes four, sixteen
    // and sixty-four times closer in (the analytic terms 16, 256, 4096 times
    // smaller, where the level set's route still answers),
    // never closer than NODE_MARGIN times the state's distance.
    // Never farther out than the standard nodes either: with nodes scaled out
    // (a state beyond HYPERBOLIC_NODES[0]/NODE_MARGIN = 1.25e-4) the two sets
    // agreed while the answer at 3e-4 missed the genus-2 torus there by up to
    // 1.1e-10 on the harsh draw (tests/data/hyperbolic_block_check.txt).
    let line = Line {
        frame,
        l0,
        le,
        delta,
        nu_e,
        slope,
        cancel,
    };
    let attempts = NODE_SCALES
        .into_iter()
        .filter(|scale| NODE_MARGIN * delta <= scale * HYPERBOLIC_NODES[0])
        .map(|scale| two_sets(&line, slope_rel, scale));
    first_answer(attempts).unwrap_or_else(|| {
        Err(refusal(format!(
            "the state is at relative distance {delta:e}; the fits need at most {:e} \
             ({NODE_MARGIN} times closer in than the first node)",
            HYPERBOLIC_NODES[0] / NODE_MARGIN
        )))
    })
}

/// The node sets tried, as factors of [`HYPERBOLIC_NODES`].
pub(super) const NODE_SCALES: [f64; 4] = [1.0, 0.25, 0.0625, 0.015625];

/// The answer of the node sets `first` and [`SECOND_SET`] times `first`
/// (factors of [`HYPERBOLIC_NODES`]), if their bound allows.
fn two_sets(line: &Line, lambda_rel: f64, first: f64) -> Result<[f64; 2]> {
    let mut answers = Vec::with_capacity(2);
    for factor in [first, SECOND_SET * first] {
        let nodes = HYPERBOLIC_NODES.map(|s| s * factor);
        answers.push(fit_at(line, nodes)?);
    }
    let (nu, resid, reach) = answers[0];
    let (other, resid2, _) = answers[1];
    let spread = (0..2)
        .map(|i| (nu[i] - other[i]).abs() / nu[i].abs())
        .fold(0.0f64, f64::max);
    // Both sets share the slope: its error is not in their spread.
    let slope_share = lambda_rel * reach;
    let bound = spread + resid.max(resid2) + slope_share;
    if bound.is_nan() || bound > NEAR_EULER_RTOL {
        return Err(refusal(format!(
            "the two node sets' frequencies differ by {spread:e}, the fits' residuals are \
             {resid:e} and {resid2:e}, and the exponent's error ({lambda_rel:e}) moves them by \
             {slope_share:e}: a bound of {bound:e} (> {NEAR_EULER_RTOL:e})"
        )));
    }
    Ok(nu)
}

/// The fits of the module doc through the nodes at relative distances
/// `nodes` along the line, at `σ = δ`: `(ν1, ν2)`, the largest residual
/// (relative), and the factor by which a relative error of the slope `2/λ`
/// reaches them (relative).
fn fit_at(line: &Line, nodes: [f64; 7]) -> Result<([f64; 2], f64, f64)> {
    let Line {
        frame,
        l0,
        le,
        delta,
        nu_e,
        slope,
        cancel,
    } = *line;
    let f = node_frequencies(frame, l0, le, delta, &nodes, "the block", cancel)?;
    let ln: [f64; 7] = nodes.map(|s| (1.0 / s).ln());
    let [r, s] = long_cycle(&f, &ln, slope)?;
    let [p, q] = complement(r, s);
    let comb = |m: [i32; 2], v: &[f64; 2]| f64::from(m[0]) * v[0] + f64::from(m[1]) * v[1];
    let nu2: [f64; 7] = std::array::from_fn(|k| comb([r, s], &f[k]));
    let sgn = if comb([p, q], &f[0]) < 0.0 { -1.0 } else { 1.0 };
    let nu1: [f64; 7] = std::array::from_fn(|k| sgn * comb([p, q], &f[k]));
    if !nu2.iter().all(|v| *v > 0.0 && v.is_finite()) {
        return Err(refusal(format!("the long cycle's frequencies {nu2:?}")));
    }
    let xs: [f64; 7] = nodes.map(|s| s * s);
    let xmax = xs[6];
    // 1/ν2 less the orbit's slope
    let inv: [f64; 7] = std::array::from_fn(|k| 1.0 / nu2[k] - slope * ln[k]);
    let a = least_squares(&xs, &ln, xmax, &inv, false)?;
    // the sign ε: the other one leaves a slope 2 ν_E (2/λ) in ln(1/σ)
    let mut chosen = None;
    let mut logs = [0.0; 2];
    for (i, eps) in [1.0, -1.0].into_iter().enumerate() {
        // ν1 is the same integer combination at every node: where a node's
        // reduced basis differs, the fits' residuals refuse
        let g: [f64; 7] = std::array::from_fn(|k| (nu1[k] - eps * nu_e) / nu2[k]);
        let with_log = least_squares(&xs, &ln, xmax, &g, true)?;
        logs[i] = with_log[5];
        if with_log[5].abs() <= SIGN_RTOL * 2.0 * nu_e * slope {
            if chosen.is_some() {
                return Err(refusal(format!(
                    "(ν1 ∓ ν_E)/ν2 has no slope in ln(1/σ) for both signs of ν_E = {nu_e:e}"
                )));
            }
            chosen = Some((eps, g));
        }
    }
    let (eps, g) = chosen.ok_or_else(|| {
        refusal(format!(
            "(ν1 ∓ ν_E)/ν2 has a slope in ln(1/σ) for either sign of ν_E = {nu_e:e} ({logs:?}; \
             the other sign's is ±{:e})",
            2.0 * nu_e * slope
        ))
    })?;
    let c = least_squares(&xs, &ln, xmax, &g, false)?;
    let model = |coef: &[f64], x: f64, l: f64| {
        let y = x / xmax;
        coef[0] + coef[1] * y + coef[2] * y * y + coef[3] * y * l + coef[4] * y * y * l
    };
    let resid = (0..7)
        .map(|k| {
            let e1 = (model(&a, xs[k], ln[k]) - inv[k]).abs() * nu2[k];
            let e2 = (model(&c, xs[k], ln[k]) - g[k]).abs() * nu2[k] / nu1[k].abs();
            e1.max(e2)
        })
        .fold(0.0f64, f64::max);
    let (x, l) = (delta * delta, (1.0 / delta).ln());
    let n2 = 1.0 / (model(&a, x, l) + slope * l);
    let n1 = eps * nu_e + model(&c, x, l) * n2;
    let nu = [n1.abs(), n2];
    if !(nu.iter().all(|v| v.is_finite() && *v > 0.0) && resid.is_finite()) {
        return Err(refusal(format!("fitted frequencies {nu:?}")));
    }
    // An error `d` of the slope shifts the fitted 1/ν2 at the state by
    // `d (ln(1/δ) − Σ w_k ln(1/σ_k))` (`w_k` the fit's weights at the state):
    // ν2 by that times ν2, relative; ν1 = ε ν_E + g ν2 by that times
    // |g ν2/ν1|.
    let lfit = least_squares(&xs, &ln, xmax, &ln, false)?;
    let share = slope * (l - model(&lfit, x, l)).abs() * n2;
    let carry = (n1 - eps * nu_e).abs() / n1.abs();
    Ok((nu, resid, share * carry.max(1.0)))
}

/// The genus-2 frequencies of the node states `le + σ (l0 − le)/δ` at the
/// relative distances `nodes` from `le` (named `from` in the refusal of a
/// node the level set's route refuses).
pub(super) fn node_frequencies(
    frame: &TopFrame,
    l0: &[f64; 6],
    le: &[f64; 6],
    delta: f64,
    nodes: &[f64; 7],
    from: &str,
    cancel: &Cancel,
) -> Result<[[f64; 2]; 7]> {
    let mut f = [[0.0; 2]; 7];
    for (k, &sigma) in nodes.iter().enumerate() {
        cancel.check()?;
        let node: [f64; 6] = std::array::from_fn(|q| le[q] + (l0[q] - le[q]) * (sigma / delta));
        let e = state_frequencies_plain(frame, &node, cancel);
        if e.status != Status::Ok {
            return Err(refusal(format!(
                "the node at distance {sigma:e} from {from} has status '{}'",
                e.status.name()
            )));
        }
        f[k] = e.nu;
    }
    Ok(f)
}

/// The integer combination `(r, s)` (`|r|, |s| ≤` [`MAX_COMB`], coprime) of
/// the nodes' frequencies that is the long cycle's `ν2`: positive at the
/// first two nodes, with `1/ν2` moving between them at the slope `slope` in
/// `ln(1/σ)` to [`SLOPE_ID_RTOL`], and no other within ten times as close.
fn long_cycle(f: &[[f64; 2]; 7], ln: &[f64; 7], slope: f64) -> Result<[i32; 2]> {
    let range = || -MAX_COMB..=MAX_COMB;
    let candidates = range()
        .flat_map(|r| range().map(move |s| [r, s]))
        .filter(|&[r, s]| gcd(r, s) == 1)
        .filter_map(|[r, s]| {
            let v = |k: usize| f64::from(r) * f[k][0] + f64::from(s) * f[k][1];
            let (v0, v1) = (v(0), v(1));
            (v0 > 0.0 && v1 > 0.0).then(|| {
                let miss = ((1.0 / v1 - 1.0 / v0) / (ln[1] - ln[0]) / slope - 1.0).abs();
                ([r, s], miss)
            })
        });
    match unique_best(candidates) {
        Some((m, b, second)) if b <= SLOPE_ID_RTOL && second > 10.0 * b => Ok(m),
        Some((_, b, second)) => Err(refusal(format!(
            "no unique integer combination of the nodes' frequencies moves with the orbit's \
             slope 2/λ = {slope:e} (closest: {b:e} relative, next: {second:e})"
        ))),
        None => Err(refusal(
            "no positive combination of the nodes' frequencies".into(),
        )),
    }
}

fn gcd(a: i32, b: i32) -> i32 {
    let (mut a, mut b) = (a.abs(), b.abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// Integers `(p, q)` with `p s − q r = 1` (`r, s` coprime): the frequency
/// `ν1 = p f1 + q f2` that completes `ν2 = r f1 + s f2` to a basis.
fn complement(r: i32, s: i32) -> [i32; 2] {
    for p in -MAX_COMB..=MAX_COMB {
        for q in -MAX_COMB..=MAX_COMB {
            if p * s - q * r == 1 {
                return [p, q];
            }
        }
    }
    // (unreachable for coprime r, s with |r|, |s| ≤ MAX_COMB)
    [0, 0]
}

/// The least-squares coefficients of the values `v` at the nodes
/// (`x = σ²`, `ln(1/σ)`) in the basis `(1, y, y², y ln, y² ln)` with
/// `y = x/xmax`, and `ln(1/σ)` itself when `with_log`.
fn least_squares(
    xs: &[f64; 7],
    ln: &[f64; 7],
    xmax: f64,
    v: &[f64; 7],
    with_log: bool,
) -> Result<Vec<f64>> {
    let cols = if with_log { 6 } else { 5 };
    let m = nalgebra::DMatrix::from_fn(7, cols, |k, j| {
        let y = xs[k] / xmax;
        match j {
            0 => 1.0,
            1 => y,
            2 => y * y,
            3 => y * ln[k],
            4 => y * y * ln[k],
            _ => ln[k],
        }
    });
    let b = nalgebra::DVector::from_column_slice(v);
    m.svd(true, true)
        .solve(&b, 0.0)
        .map(|c| c.iter().copied().collect())
        .map_err(|e| refusal(format!("the least-squares fit: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_complement_completes_a_basis() {
        for (r, s) in [(0, 1), (1, 1), (1, -1), (4, -3), (-1, 4), (3, 2)] {
            let [p, q] = complement(r, s);
            assert_eq!(p * s - q * r, 1, "{r} {s}");
        }
    }

    #[test]
    fn the_long_cycle_is_found_by_its_slope() {
        // 1/ν2 = 0.1 ln(1/σ) + 0.3, ν1 = 79 + ν2/2, reported as (ν1 + ν2, ν2)
        let nodes = HYPERBOLIC_NODES;
        let ln = nodes.map(|s: f64| (1.0 / s).ln());
        let f: [[f64; 2]; 7] = std::array::from_fn(|k| {
            let n2 = 1.0 / (0.1 * ln[k] + 0.3);
            [79.0 + 1.5 * n2, n2]
        });
        assert_eq!(long_cycle(&f, &ln, 0.1).unwrap(), [0, 1]);
        // another slope: no combination
        assert!(long_cycle(&f, &ln, 0.13).is_err());
    }

    #[test]
    fn the_fit_reproduces_its_basis() {
        let nodes = HYPERBOLIC_NODES;
        let xs = nodes.map(|s| s * s);
        let ln = nodes.map(|s: f64| (1.0 / s).ln());
        let v: [f64; 7] = std::array::from_fn(|k| {
            let y = xs[k] / xs[6];
            0.3 - 2.0 * y + 0.5 * y * y + 0.01 * y * ln[k]
        });
        let c = least_squares(&xs, &ln, xs[6], &v, false).unwrap();
        assert!((c[0] - 0.3).abs() < 1e-12, "{c:?}");
        let c = least_squares(&xs, &ln, xs[6], &v, true).unwrap();
        assert!(c[5].abs() < 1e-10, "{c:?}");
    }
}
