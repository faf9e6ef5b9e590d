//! Frequencies of states next to an Euler subspace (an so(3) block or the
//! self-dual states) where the genus-2 route refuses (docs/degenerate.md §11).
//!
//! A state `l = l_E + l_⊥`, with `l_E` the nearest state of an invariant
//! subspace where the motion is an Euler top ([`Embedding`]: a block, three
//! components sharing no fourth index; or `m = ±n`) and `l_⊥` the rest, at
//! relative distance `δ = |l_⊥|/|l|`. Its curve is pinched by `δ` (next to a
//! block), or its Casimirs nearly coincide (`h1² − 4h0² ~ δ²` next to the
//! self-dual states, where `F` (19) is not defined): the level set's route
//! refuses. The frequencies are smooth there, along the line
//! `l(σ) = l_E + σ l_⊥/δ`:
//!
//! * at `σ = 0` they are the Euler motion's `(ν_⊥, ν_E)`
//!   ([`crate::solution::transverse`]), where the orbit is transversally
//!   elliptic (`ν_⊥ > 0`; next to a hyperbolic block orbit no tori shrink onto
//!   it, and the frequencies are not analytic in `σ`: that case is
//!   [`super::near_hyperbolic`]'s);
//! * next to a block, the reflection of the axis outside it flips the sign of
//!   `l_⊥` and is a symmetry of (1) (conjugation by a diagonal `±1` matrix
//!   preserves `l̇ = [l, Ω]`, `Ω_ij = c_ij l_ij`): the frequencies are even in
//!   `σ`, analytic in `x = σ²`; next to the self-dual states no symmetry
//!   flips `l_⊥` (the Casimir `|m|² − |n|²` is linear in `σ`), and `x = σ`.
//!
//! So the frequencies are interpolated in `x`: through the Euler value at
//! `x = 0` and the genus-2 frequencies at three nodes `σ = 1e-3, 2e-3, 4e-3`
//! (next to a block; `1e-5 … 4e-5` next to the self-dual states), where the
//! level set's route answers, each node's reduced basis matched to
//! `(ν_⊥, ν_E)` by a unimodular integer matrix; a fourth node (`σ = 8e-3`,
//! `8e-5`) checks the cubic. The bound of the answer is that check scaled by the
//! remainder's factor `|w(x)/w(x_4)|` (`w(x) = x Π (x − x_k)`) plus the
//! nodes' own bound times their Lagrange weights at the state; it must stay
//! below [`NEAR_EULER_RTOL`]. Next to the subspace (`x ≪ x_k`) the answer is
//! the Euler value plus a correction of relative size `~x/x_1`.

use super::motion::state_frequencies_plain;
use super::near_hyperbolic::near_hyperbolic_frequencies;
use super::near_plane::near_plane_frequencies;
use super::{MapEntry, Status};
use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;
use crate::so4::PAIRS4;
use crate::solution::euler::Embedding;
use crate::solution::normalize::TopFrame;

/// Largest relative distance `|l_⊥|/|l|` from a block at which the
/// interpolation is tried.
pub const NEAR_BLOCK_MAX: f64 = 1e-2;

/// Relative distances `σ` of the node states from a block: the first three
/// carry the cubic, the last checks it. Scaled up by `8δ/σ_1` where that is
/// larger than 1, so that the first node is at least [`NODE_MARGIN`] times as
/// far out as the state: the answer is an interpolation next to the cubic's
/// `x = 0` end, never an extrapolation.
pub const BLOCK_NODES: [f64; 4] = [1e-3, 2e-3, 4e-3, 8e-3];

/// Largest relative distance from the self-dual states at which the
/// interpolation is tried.
pub const NEAR_SELF_DUAL_MAX: f64 = 1e-3;

/// Relative distances of the node states from the self-dual states, scaled
/// alike. Closer in than next to a block: the frequencies
/// move linearly in `σ` here, and the first node's shift from the Euler value
/// (`~σ_1` times their sensitivity) must stay below the basis match's
/// tolerance; the level set's route answers from `σ ~ 1e-6` out
/// (`h1² − 4h0² ~ σ²` above its rounding).
pub const SELF_DUAL_NODES: [f64; 4] = [1e-5, 2e-5, 4e-5, 8e-5];

/// The node sets tried, as factors of the standard nodes.
const NODE_SCALES: [f64; 3] = [1.0, 0.25, 4.0];

/// The first node is at least this many times as far out as the state: the
/// nodes' Lagrange weights at the state then sum to at most 0.42 (`x = σ`,
/// next to the self-dual states; 0.03 for `x = σ²`), which keeps the nodes'
/// own bound within [`NEAR_EULER_RTOL`].
pub(super) const NODE_MARGIN: f64 = 8.0;

/// Largest bound (relative, max norm) of interpolated frequencies that the
/// map gives: half the bound the genus-2 frequencies are vouched for to, as
/// for the Abel-map check of `U` ([`super::solve::ABEL_RATE_RTOL`]).
pub const NEAR_EULER_RTOL: f64 = 0.5 * NODE_RTOL;

/// The bound of a node's frequencies: those of the genus-2 route
/// ([`super::solve::FREQUENCY_VELOCITY_RTOL`]).
const NODE_RTOL: f64 = super::solve::FREQUENCY_VELOCITY_RTOL;

/// A node's reduced basis is matched to `(ν_⊥, ν_E)` carried to the node
/// (the polynomial through the block and the nodes before it) when its
/// frequencies are within this of an integer combination (relative, max
/// norm): the shift from the block at the first node (`~x_1 = 1e-6` times the
/// frequencies' sensitivity to `x`) is below it (on the harsh draw up to
/// 5.5e-5), the later nodes' misses of the prediction far below. Two
/// combinations with entries up to [`MAX_ENTRY`] come this close only where
/// `ν_⊥/ν_E` is this close to a fraction with a denominator up to
/// `2 MAX_ENTRY`; the match must be unique (no other within ten times its
/// residual), so such a state is refused, not matched wrongly.
const MATCH_RTOL: f64 = 1e-4;

/// Largest entry of the unimodular matrices tried: the reduced bases of tori
/// next to the orbit are integer combinations of `(ν_⊥, ν_E)` (docs/degenerate.md
/// §5), on the harsh draw up to `(−1, 10)` (a reduced basis in the metric of
/// `Im τ`, not in the frequencies).
const MAX_ENTRY: i32 = 32;

/// Above this misprediction of the fourth node (relative) the nodes do not lie
/// on one smooth curve through the Euler value (a basis matched wrongly, a
/// resonance, a hyperbolic neighbourhood): no answer, whatever the bound.
const CHECK_MAX: f64 = 1e-6;

/// The nearest state `l_E` of the Euler subspace `emb` (the orthogonal
/// projection: the block's components, or `m' = (m + σ n)/2` for `n = σ m`)
/// and the relative 2-norm distance `|l − l_E|/|l|`, scaled first so that no
/// square overflows or underflows.
fn euler_projection(l: &[f64; 6], emb: Embedding) -> (f64, [f64; 6]) {
    let le = match emb {
        Embedding::Block(blk) => {
            let out = (0..4).find(|i| !blk.contains(i)).unwrap_or(3);
            let mut le = *l;
            for (q, &(i, j)) in PAIRS4.iter().enumerate() {
                if i == out || j == out {
                    le[q] = 0.0;
                }
            }
            le
        }
        Embedding::SelfDual(sg) => {
            let (m, n) = crate::kotter::m_n(l);
            let s = f64::from(sg);
            emb.state(&std::array::from_fn(|j| 0.5 * (m[j] + s * n[j])))
        }
    };
    (relative_distance(l, &le), le)
}

/// `|l − le|/|l|` (2-norm), scaled first so that no square overflows or
/// underflows; NaN for a zero or non-finite `l`.
pub(super) fn relative_distance(l: &[f64; 6], le: &[f64; 6]) -> f64 {
    let s = l.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if s == 0.0 || !s.is_finite() {
        return f64::NAN;
    }
    let all: f64 = l.iter().map(|v| (v / s) * (v / s)).sum();
    let off: f64 = (0..6)
        .map(|q| ((l[q] - le[q]) / s) * ((l[q] - le[q]) / s))
        .sum();
    (off / all).sqrt()
}

/// The Euler subspaces: the four blocks, then the self-dual and
/// anti-self-dual states.
fn embeddings() -> [Embedding; 6] {
    let b = Embedding::BLOCKS;
    [
        Embedding::Block(b[0]),
        Embedding::Block(b[1]),
        Embedding::Block(b[2]),
        Embedding::Block(b[3]),
        Embedding::SelfDual(1),
        Embedding::SelfDual(-1),
    ]
}

/// The integer combination `(p, q)` with `f ≈ p ν_⊥ + q ν_E` (`|p|, |q| ≤`
/// [`MAX_ENTRY`]) and its residual relative to `scale`, if it is within
/// [`MATCH_RTOL`] and no other comes within ten times its residual.
fn match_row(f: f64, nu0: &[f64; 2], scale: f64) -> Option<[i32; 2]> {
    let candidates = (-MAX_ENTRY..=MAX_ENTRY).flat_map(|q| {
        // the nearest p and its neighbours: the runner-up may be either
        let p0 = ((f - f64::from(q) * nu0[1]) / nu0[0]).round();
        [p0 - 1.0, p0, p0 + 1.0]
            .into_iter()
            .filter(|p| p.abs() <= f64::from(MAX_ENTRY))
            // |p| ≤ MAX_ENTRY: the cast is exact
            .map(move |p| {
                (
                    [p as i32, q],
                    (f - p * nu0[0] - f64::from(q) * nu0[1]).abs() / scale,
                )
            })
    });
    let (m, rb, second) = unique_best(candidates)?;
    (rb <= MATCH_RTOL && second > 10.0 * rb).then_some(m)
}

/// The candidate with the smallest miss, that miss, and the runner-up's
/// (infinite if there is none); `None` for no candidates. Both the basis
/// match here and the long cycle's identification next to a hyperbolic orbit
/// ask for a best that no other comes near.
pub(super) fn unique_best<T>(candidates: impl Iterator<Item = (T, f64)>) -> Option<(T, f64, f64)> {
    let mut best: Option<(T, f64)> = None;
    let mut second = f64::INFINITY;
    for (c, miss) in candidates {
        match &best {
            Some((_, b)) if miss >= *b => second = second.min(miss),
            _ => {
                if let Some((_, b)) = &best {
                    second = second.min(*b);
                }
                best = Some((c, miss));
            }
        }
    }
    best.map(|(c, b)| (c, b, second))
}

/// The first answer of `attempts` (tried in order, lazily), the
/// cancellation at once, else the first refusal; `None` if nothing was
/// tried. The node sets of both interpolations are tried this way.
pub(super) fn first_answer(
    attempts: impl IntoIterator<Item = Result<[f64; 2]>>,
) -> Option<Result<[f64; 2]>> {
    let mut first_err = None;
    for attempt in attempts {
        match attempt {
            Ok(nu) => return Some(Ok(nu)),
            Err(Error::Interrupted) => return Some(Err(Error::Interrupted)),
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    first_err.map(Err)
}

/// The unimodular matrix `M` with `f ≈ M ν0`: each row by [`match_row`], and
/// `det M = ±1` (the node's reduced basis is a basis of the same lattice).
fn match_basis(f: &[f64; 2], nu0: &[f64; 2]) -> Option<[[i32; 2]; 2]> {
    let scale = f[0].abs().max(f[1].abs());
    let m = [match_row(f[0], nu0, scale)?, match_row(f[1], nu0, scale)?];
    ((m[0][0] * m[1][1] - m[0][1] * m[1][0]).abs() == 1).then_some(m)
}

/// `M⁻¹ f` for a unimodular `M`.
fn unmatch(m: &[[i32; 2]; 2], f: &[f64; 2]) -> [f64; 2] {
    let det = f64::from(m[0][0] * m[1][1] - m[0][1] * m[1][0]);
    let (a, b, c, d) = (
        f64::from(m[0][0]),
        f64::from(m[0][1]),
        f64::from(m[1][0]),
        f64::from(m[1][1]),
    );
    [(d * f[0] - b * f[1]) / det, (a * f[1] - c * f[0]) / det]
}

/// Lagrange weights of the abscissae `xs` at `x`.
fn lagrange(xs: &[f64], x: f64) -> Vec<f64> {
    (0..xs.len())
        .map(|k| {
            (0..xs.len())
                .filter(|&j| j != k)
                .map(|j| (x - xs[j]) / (xs[k] - xs[j]))
                .product()
        })
        .collect()
}

/// The polynomial through the values `vals` at the abscissae `xs`, at `x`.
fn predict(xs: &[f64], vals: &[[f64; 2]], x: f64) -> [f64; 2] {
    let w = lagrange(xs, x);
    std::array::from_fn(|i| w.iter().zip(vals).map(|(w, v)| w * v[i]).sum())
}

/// The refusal of the interpolation (the caller keeps the genus-2 route's
/// status; the message serves `Solution.frequencies`).
fn refusal(reason: String) -> Error {
    Error::Unverified {
        what: "frequencies next to an so(3) block or a self-dual state",
        reason,
    }
}

/// `(ν1, ν2)` (user's time) of the state `l0` of the top `frame` by the
/// interpolation of the module doc, in the reduced basis of the nearest node
/// (next to a transversally hyperbolic block orbit: the fits of
/// [`super::near_hyperbolic`]); where neither applies, the interpolation
/// next to the nearest coordinate-plane equilibrium
/// ([`super::near_plane`]); an error where none applies or the bound exceeds
/// [`NEAR_EULER_RTOL`] (the first refusal's, which names the nearest Euler
/// subspace, and the plane's reason after it).
pub fn near_euler_frequencies(
    frame: &TopFrame,
    l0: &[f64; 6],
    cancel: &Cancel,
) -> Result<[f64; 2]> {
    match near_subspace_frequencies(frame, l0, cancel) {
        Ok(nu) => Ok(nu),
        Err(Error::Interrupted) => Err(Error::Interrupted),
        Err(first) => near_plane_frequencies(frame, l0, cancel).map_err(|e| match (e, first) {
            (Error::Interrupted, _) => Error::Interrupted,
            (
                Error::Unverified { what, reason },
                Error::Unverified {
                    what: w0,
                    reason: r0,
                },
            ) => Error::Unverified {
                what: w0,
                reason: format!("{r0}; {what}: {reason}"),
            },
            (_, first) => first,
        }),
    }
}

/// [`near_euler_frequencies`] next to the Euler subspaces alone.
fn near_subspace_frequencies(frame: &TopFrame, l0: &[f64; 6], cancel: &Cancel) -> Result<[f64; 2]> {
    let (delta, emb, le) = embeddings()
        .iter()
        .map(|&e| {
            let (d, le) = euler_projection(l0, e);
            (d, e, le)
        })
        // the first of equal distances; a NaN distance (non-finite l0) last
        .min_by(|p, q| p.0.total_cmp(&q.0))
        .unwrap_or((f64::NAN, embeddings()[0], *l0));
    // Even in σ next to a block (the reflection), not next to the self-dual
    // states (module doc).
    let even = matches!(emb, Embedding::Block(_));
    let (max, base) = if even {
        (NEAR_BLOCK_MAX, BLOCK_NODES)
    } else {
        (NEAR_SELF_DUAL_MAX, SELF_DUAL_NODES)
    };
    if !(delta > 0.0 && delta <= max) {
        return Err(refusal(format!(
            "the state is at relative distance {delta:e} from the nearest {} state (the \
             interpolation needs 0 < distance <= {max:e})",
            emb.name()
        )));
    }
    let abscissa = |sigma: f64| if even { sigma * sigma } else { sigma };
    let euler = state_frequencies_plain(frame, &le, cancel);
    let nu0 = euler.nu;
    if even && euler.status == Status::Ok && nu0[0] == 0.0 && nu0[1] > 0.0 {
        // transversally hyperbolic (ν_⊥ = 0 is reported only for those)
        return near_hyperbolic_frequencies(frame, l0, &le, delta, nu0[1], cancel);
    }
    if euler.status != Status::Ok || !(nu0[0] > 0.0 && nu0[1] > 0.0) {
        return Err(refusal(format!(
            "the Euler motion of the nearest {} state is not transversally elliptic: \
             frequencies {nu0:?} (status '{}')",
            emb.name(),
            euler.status.name()
        )));
    }
    interpolate_over_node_sets(frame, l0, &le, delta, nu0, base, &abscissa, cancel)
}

/// [`interpolate`] through the node set `base` first; where a node is
/// refused or its basis does not match (the first node's shift from the
/// value at `x = 0` too large), nodes four times closer in, then four times
/// farther out ([`NODE_SCALES`]), each never closer in than [`NODE_MARGIN`]
/// times the state's distance: the first answer, else the first refusal.
#[allow(clippy::too_many_arguments)]
pub(super) fn interpolate_over_node_sets(
    frame: &TopFrame,
    l0: &[f64; 6],
    le: &[f64; 6],
    delta: f64,
    nu0: [f64; 2],
    base: [f64; 4],
    abscissa: &dyn Fn(f64) -> f64,
    cancel: &Cancel,
) -> Result<[f64; 2]> {
    let mut tried: Vec<f64> = Vec::new();
    let attempts = NODE_SCALES.into_iter().filter_map(|scale| {
        let factor = scale.max(NODE_MARGIN * delta / base[0]);
        if tried.contains(&factor) {
            return None;
        }
        tried.push(factor);
        let nodes = base.map(|s| s * factor);
        Some(interpolate(
            frame, l0, le, delta, nu0, nodes, abscissa, cancel,
        ))
    });
    first_answer(attempts).unwrap_or_else(|| Err(refusal("no set of nodes applies".into())))
}

/// The interpolation of the module doc through the Euler value `nu0` of the
/// nearest state `le` of the subspace and the nodes at relative distances
/// `nodes` along `le + σ (l0 − le)/δ`, at the state (`abscissa`: `σ ↦ x`).
#[allow(clippy::too_many_arguments)]
fn interpolate(
    frame: &TopFrame,
    l0: &[f64; 6],
    le: &[f64; 6],
    delta: f64,
    nu0: [f64; 2],
    nodes: [f64; 4],
    abscissa: &dyn Fn(f64) -> f64,
    cancel: &Cancel,
) -> Result<[f64; 2]> {
    let xs: [f64; 4] = nodes.map(abscissa);
    let mut g = [[0.0; 2]; 4];
    let mut first = [[0; 2]; 2];
    for (k, &sigma) in nodes.iter().enumerate() {
        cancel.check()?;
        let node: [f64; 6] = std::array::from_fn(|q| le[q] + (l0[q] - le[q]) * (sigma / delta));
        let MapEntry { status, nu } = state_frequencies_plain(frame, &node, cancel);
        if status != Status::Ok {
            return Err(refusal(format!(
                "the node at distance {sigma:e} from the subspace has status '{}'",
                status.name()
            )));
        }
        // Matched against the polynomial through the block and the nodes
        // before it, at this node: the shift from the block grows like x, the
        // prediction's miss far less.
        let pts: Vec<f64> = std::iter::once(0.0)
            .chain(xs[..k].iter().copied())
            .collect();
        let vals: Vec<[f64; 2]> = std::iter::once(nu0).chain(g[..k].iter().copied()).collect();
        let pred = predict(&pts, &vals, xs[k]);
        let m = match_basis(&nu, &pred).ok_or_else(|| {
            refusal(format!(
                "the node at distance {sigma:e} has frequencies {nu:?}, no unique integer \
                 combination of {pred:?} (the Euler value {nu0:?} carried to the node)"
            ))
        })?;
        if k == 0 {
            first = m;
        }
        g[k] = unmatch(&m, &nu);
    }
    // The cubic through (0, ν0) and the first three nodes, at the fourth node
    // and at x = δ².
    let pts = [0.0, xs[0], xs[1], xs[2]];
    let vals = [nu0, g[0], g[1], g[2]];
    let p4 = predict(&pts, &vals, xs[3]);
    let check = (0..2)
        .map(|i| (p4[i] - g[3][i]).abs() / g[3][i].abs())
        .fold(0.0f64, f64::max);
    let x = abscissa(delta);
    let w = |y: f64| y * (y - xs[0]) * (y - xs[1]) * (y - xs[2]);
    let weights = lagrange(&pts, x);
    let bound = check * (w(x) / w(xs[3])).abs()
        + NODE_RTOL * weights[1..].iter().map(|v| v.abs()).sum::<f64>();
    if !(check <= CHECK_MAX && bound <= NEAR_EULER_RTOL) {
        return Err(refusal(format!(
            "the nodes' frequencies miss the cubic through the Euler value by {check:e} at the \
             last node, which bounds the interpolation at this state by {bound:e} (> \
             {NEAR_EULER_RTOL:e}, or a miss above {CHECK_MAX:e})"
        )));
    }
    let p = predict(&pts, &vals, x);
    let nu = [
        f64::from(first[0][0]) * p[0] + f64::from(first[0][1]) * p[1],
        f64::from(first[1][0]) * p[0] + f64::from(first[1][1]) * p[1],
    ];
    if !nu.iter().all(|v| v.is_finite() && *v >= 0.0) {
        return Err(refusal(format!("interpolated frequencies {nu:?}")));
    }
    Ok(nu)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_basis_match_finds_the_unimodular_matrix_and_only_it() {
        let r2 = std::f64::consts::SQRT_2;
        let nu0 = [0.3, r2];
        let f = [r2 * (1.0 + 1e-9), 0.3 + r2];
        let m = match_basis(&f, &nu0).expect("a match");
        assert_eq!(m, [[0, 1], [1, 1]]);
        let g = unmatch(&m, &f);
        assert!((g[0] - 0.3).abs() < 1e-8 && (g[1] - r2).abs() < 1e-8);
        // between combinations: no match
        assert!(match_basis(&[0.3 + 0.5 * r2, 5.0], &nu0).is_none());
        // two combinations alike (ν_⊥/ν_E rational, 3/17): no match
        assert!(match_basis(&[1.7, 2.0], &[0.3, 1.7]).is_none());
        // a reduced basis far from (ν_⊥, ν_E) (harsh draw 8207: (−1, 10))
        let nu0 = [17882464.901168905, 46947661.87792917];
        let f = [451594124.4372472, 46947641.98835879];
        assert_eq!(match_basis(&f, &nu0), Some([[-1, 10], [0, 1]]));
        // not unimodular: no match
        assert!(match_basis(&[0.6, r2], &[0.3, r2]).is_none());
    }

    #[test]
    fn the_projections_onto_the_euler_subspaces_are_scaled() {
        // block (0, 1, 2): l12, l13, l23 inside; l14, l24, l34 outside
        let l = [1e200, 1e200, 3e193, 1e200, 4e193, 0.0];
        let (d, le) = euler_projection(&l, Embedding::Block([0, 1, 2]));
        assert_eq!(le, [1e200, 1e200, 0.0, 1e200, 0.0, 0.0]);
        assert!((d / (5e-7 / 3f64.sqrt()) - 1.0).abs() < 1e-12, "{d}");
        // m = (1, 2, 3), n = m + (0, 0, 2e-8): the self-dual state of m' = m + (0, 0, 1e-8)
        let l = crate::kotter::l_from_m_n(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0 + 2e-8]);
        let (d, le) = euler_projection(&l, Embedding::SelfDual(1));
        let (m, n) = crate::kotter::m_n(&le);
        assert_eq!(m, n);
        assert!((m[2] - (3.0 + 1e-8)).abs() < 1e-15);
        assert!(
            (d / (2f64.sqrt() * 1e-8 / 28f64.sqrt()) - 1.0).abs() < 1e-7,
            "{d}"
        );
    }

    #[test]
    fn the_weights_reproduce_a_cubic() {
        let xs = [0.0, 1.0, 4.0, 9.0];
        let f = |x: f64| 2.0 - x + 0.5 * x * x - 0.1 * x * x * x;
        let vals = xs.map(|x| [f(x), -f(x)]);
        let p = predict(&xs, &vals, 2.5);
        assert!((p[0] - f(2.5)).abs() < 1e-12 && (p[1] + f(2.5)).abs() < 1e-12);
    }
}
