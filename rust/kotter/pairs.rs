//! The roots of `F` (19) near and at `h0 = 0`: pairs on the two branches of `√G`.
//!
//! At `h0 = 0`, `F(s) = P(s)²/h1²` with `P(s) = h1 s² − h2 s + h3`: each root
//! `r` of `P` is a double root of `F`. For small `h0` it splits into the two
//! zeros of `f = P + 2 h0 σ` (15) near `r`, one on each branch `σ = ±√G`:
//!
//! ```text
//! s = r + h0 ρ + O(h0²),   ρ = −2 σ(r)/P'(r),   σ(r) = ±√G(r)
//! ```
//!
//! (`P(r + h0 ρ) = h0 ρ P'(r) + O(h0²)`). The quartic's root finder knows two
//! roots `δ` apart only to `u/δ`, and below `δ ~ √u` it can no longer tell
//! them apart at all; `f` on its own branch has `f' ≈ P'(r)`, not small. So
//! for small `h0` each root is seeded from `r` and its branch and polished on
//! `f` on that branch ([`super::polish_root`] with the branch given). The
//! four are then ordered by the documented rule (module docs of
//! [`super`]) applied to `r + h0 ρ` — at `h0 = 0` to the limit `h0 → 0⁺`, a
//! choice (the other limit is the reduction with `s1 ↔ s2`, also valid).
//!
//! Everything after the roots is a function of `(s_p, σ_p, F'(s_p)/|h0|)`,
//! finite at `h0 = 0` (docs/degenerate.md, "h0 = 0").

use num_complex::Complex64;

use super::polish::{polish_root, Level, PolishedRoot};
use crate::numeric::complex::sqrt_principal;

type C = Complex64;

/// Below this `|h0|/h1` the roots of `F` are found as pairs from the roots of
/// `P` (the pair's split `4|h0 √G(r)/P'(r)|` is then about this fraction of the
/// roots' scale or less, where the quartic's roots lose `u/split` of their
/// digits and, below `√u`, merge); above it, by the quartic. In between the
/// two routes agree to roundoff (`tests::pair_and_quartic_routes_agree`).
pub const PAIR_ROUTE_RTOL: f64 = 1e-3;

/// The pair route applies while the split `|2 h0 √G(r)/P'(r)|` is at most
/// this fraction of the distance from `r` to the nearest `a_i` (the
/// expansion in `h0` converges within that distance).
const PAIR_GAP_FRACTION: f64 = 0.1;

/// The two roots of `P(s) = h1 s² − h2 s + h3`, real for a real state (else
/// `None`), each polished by two Newton steps on `P` summed from the state
/// (no cancellation near a root of `G`).
fn p_roots(lv: &Level) -> Option<[f64; 2]> {
    let [_, h1, h2, h3] = *lv.h;
    if h1 <= 0.0 {
        return None;
    }
    let disc = h2 * h2 - 4.0 * h1 * h3;
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    // the stable pair: q = (h2 + sign(h2) √disc)/2, roots q/h1 and h3/q
    let q = 0.5 * (h2 + h2.signum() * disc.sqrt());
    let mut r = if q == 0.0 {
        [0.0, 0.0]
    } else {
        [q / h1, h3 / q]
    };
    for x in r.iter_mut() {
        for _ in 0..2 {
            let xs: [C; 4] = std::array::from_fn(|m| C::new(*x - lv.a[m], 0.0));
            let (p, dp) = lv.p_dp(C::new(*x, 0.0), &xs);
            if dp.re != 0.0 && (p.re / dp.re).is_finite() {
                *x -= p.re / dp.re;
            }
        }
    }
    r.sort_by(|p, q| q.total_cmp(p));
    Some(r)
}

/// The ordered roots, the conjugate-partner flags and the sides ([`pair_roots`]).
pub(super) type PairRoute = ([PolishedRoot; 4], [bool; 4], [f64; 4]);

/// One root of a pair before ordering: the polished root, the root `r` of `P`
/// it comes from and its first-order direction `ρ = −2σ/P'(r)`.
struct PairRoot {
    root: PolishedRoot,
    r: f64,
    rho: C,
    /// `±1` for the upper/lower member of a conjugate pair, else 0: the side of
    /// the real axis it approaches as `h0 → 0` (branches on cuts follow it).
    side: f64,
}

/// The four roots of `F` as pairs (see the module docs), ordered, with a flag
/// per root that is true when it is the exact conjugate partner of the root
/// before it, and the side of the real axis (`±1`, 0 for real pairs) each
/// member of a conjugate pair comes from as `h0 → 0`. `None` when the pair route does not apply (complex or repeated
/// roots of `P`, or a polished root that left its pair): the caller then takes
/// the quartic route.
pub(super) fn pair_roots(lv: &Level, p_at_a: &[f64; 4]) -> Option<PairRoute> {
    let h0 = lv.h[0];
    let r = p_roots(lv)?;
    let scale =
        lv.a.iter()
            .chain(r.iter())
            .fold(1.0f64, |m, v| m.max(v.abs()));
    if (r[0] - r[1]).abs() <= 1e-8 * scale {
        return None;
    }
    let mut out: Vec<PairRoot> = Vec::with_capacity(4);
    for &rk in &r {
        let xs: [C; 4] = std::array::from_fn(|m| C::new(rk - lv.a[m], 0.0));
        let (_, dp) = lv.p_dp(C::new(rk, 0.0), &xs);
        let g = xs.iter().product::<C>();
        let sg = sqrt_principal(g);
        if dp.re == 0.0 || sg.norm() == 0.0 {
            return None;
        }
        // G(r) < 0: √G imaginary, the pair is a conjugate pair (partner by
        // conjugation); G(r) > 0: two real roots, each polished.
        let conj_pair = g.re < 0.0;
        // The expansion needs the split small against the distance from r to
        // the nearest a_i, where √G has its branch point: near r = a_i the two
        // members meet on the real axis (a root of F at a_i, a separatrix of
        // the real motion), which is not a pair of this kind.
        let gap =
            lv.a.iter()
                .fold(f64::INFINITY, |m, &ai| m.min((rk - ai).abs()));
        if (2.0 * h0 * sg / dp.re).norm() > PAIR_GAP_FRACTION * gap {
            return None;
        }
        for (k, b) in [1.0, -1.0].into_iter().enumerate() {
            let sigma = sg * b;
            let rho = -2.0 * sigma / dp.re;
            if conj_pair && k == 1 {
                let first: &PairRoot = out.last()?;
                let side = -first.side;
                out.push(PairRoot {
                    root: first.root.conj(),
                    r: rk,
                    rho: first.rho.conj(),
                    side,
                });
                continue;
            }
            let seed = C::new(rk, 0.0) + rho * h0;
            let root = polish_root(lv, p_at_a, seed, Some(sigma));
            // the polish must stay with its pair: within a few splits of r
            let split = (rho * h0).norm();
            let tol = 8.0 * split + 1e-10 * scale;
            let off = (root.s - C::new(rk, 0.0)).norm();
            if off.is_nan() || off > tol {
                return None;
            }
            // the side of the axis this member lies on for h0 → 0⁺ (κ > 0 in
            // order_pairs): that of Im(κ ρ)
            let kappa = if h0 == 0.0 { 1.0 } else { h0 };
            let side = if conj_pair {
                (rho * kappa).im.signum()
            } else {
                0.0
            };
            out.push(PairRoot {
                root,
                r: rk,
                rho,
                side,
            });
        }
    }
    order_pairs(out, h0)
}

/// The documented order (module docs of [`super`]) of the four roots
/// `w_p = r_p + κ ρ_p`, `κ = h0` (`κ → 0⁺` at `h0 = 0`), compared
/// lexicographically in `(r, κ ρ)` so that an exact double root at `h0 = 0`
/// is ordered by its limit.
fn order_pairs(roots: Vec<PairRoot>, h0: f64) -> Option<PairRoute> {
    let kappa = if h0 == 0.0 { 1.0 } else { h0 };
    let im = |p: &PairRoot| (p.rho * kappa).im;
    let re_cmp = |p: &PairRoot, q: &PairRoot| {
        p.r.total_cmp(&q.r)
            .then((p.rho * kappa).re.total_cmp(&(q.rho * kappa).re))
    };
    let by_im_re = |p: &PairRoot, q: &PairRoot| im(p).total_cmp(&im(q)).then(re_cmp(p, q));
    let mut rest: Vec<PairRoot> = roots;
    let mut order: Vec<PairRoot> = Vec::with_capacity(4);
    let mut partner = [false; 4];
    if rest.iter().any(|p| im(p) != 0.0) {
        // s1: the non-real root of largest imaginary part; s2 its conjugate
        // (the other member of its pair); s3 the remaining one of larger
        // imaginary part (then real part); s4 the last.
        let i1 = (0..rest.len())
            .filter(|&i| im(&rest[i]) != 0.0)
            .max_by(|&i, &j| by_im_re(&rest[i], &rest[j]))?;
        let s1 = rest.remove(i1);
        let i2 = (0..rest.len()).find(|&i| rest[i].r == s1.r)?;
        let s2 = rest.remove(i2);
        order.push(s1);
        order.push(s2);
        partner[1] = true;
        rest.sort_by(|p, q| by_im_re(q, p));
        let conj34 = rest[0].r == rest[1].r && im(&rest[0]) != 0.0;
        order.extend(rest);
        partner[3] = conj34;
    } else {
        rest.sort_by(|p, q| re_cmp(q, p));
        order.extend(rest);
    }
    let side: [f64; 4] = std::array::from_fn(|p| order[p].side);
    let mut it = order.into_iter().map(|p| p.root);
    let roots = [it.next()?, it.next()?, it.next()?, it.next()?];
    Some((roots, partner, side))
}
