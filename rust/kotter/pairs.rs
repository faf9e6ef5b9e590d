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
//!
//! **A root of `P` at a branch point `a_i` of `√G`** (so(3)-block states and
//! single components, where `P(a_i) = 0`, and their neighbourhoods): the
//! expansion above needs the split small against `|r − a_i|` and fails. In the
//! local parameter `w = √(s − a_i)` of the curve `σ² = G(s)` at `a_i`,
//! `σ = w √Π_i(s)`, `Π_i(s) = Π_{m≠i}(s − a_m)`, and
//!
//! ```text
//! φ(w) = f(a_i + w²) = P(a_i + w²) + 2 h0 w √Π_i(a_i + w²)
//!      = P(a_i) + 2 h0 √Π_i(a_i) w + P'(a_i) w² + O(h0 w³, w⁴)
//! ```
//!
//! is analytic in `w` (`φ(−w)` is `f` on the other branch). Its two small
//! zeros are the pair of roots of `F` near `a_i` (`w = O(h0)` when
//! `P(a_i) = O(h0²)`), each on the branch `σ = w √Π_i`; they are seeded from the
//! quadratic `P'(a_i) w² + 2 h0 √Π_i(a_i) w + P(a_i) = 0` and polished by Newton's
//! method on `φ` in `w`, where nothing is singular; the root is then carried by
//! its offset `t = w² = s − a_i`, exact however small (the double `s` rounds it
//! away below `u |a_i|`; the quartic cannot separate the two roots, `|t|` apart,
//! from each other or from `a_i`). For a real state the quadratic has real
//! `B² − 4AC` (`B² = 4h0² Π_i(a_i)`): the two `t` are a conjugate pair when
//! `(B² − 4AC) Π_i(a_i) < 0`, else both real. At
//! `h0 = 0` the zeros are `±w_0`, one root `a_i + w_0²` on both branches, as for
//! the pairs above; its first-order split `ρ = dt/dh0 = −2σ/P'(a_i)` orders the
//! two members (the limit `h0 → 0⁺`).

use num_complex::Complex64;
use std::cmp::Ordering;

use super::polish::{offsets_at, polish_root, polish_root_at, Level, PolishedRoot};
use super::roots::repeated_pair;
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

/// A root `r` of `P` whose pair fails [`PAIR_GAP_FRACTION`] is taken at the
/// branch point `a_i` nearest it when `|r − a_i|` is below this fraction of
/// the distance from `a_i` to the other `a_m` (the expansion of `φ(w)` in the
/// module docs converges within that distance).
const BRANCH_POINT_FRACTION: f64 = 0.1;

/// Newton steps on `φ(w)` (quadratic convergence from the quadratic's seed,
/// whose relative error is `O(|w|²/gap)`).
const W_NEWTON_STEPS: usize = 12;

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
    /// The offset from `r` that orders the members: `h0 ρ` (first order) for a
    /// pair of the expansion, the exact `t = s − a_i` at a branch point.
    off: C,
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
        // G(r) < 0: √G imaginary, the pair is a conjugate pair (partner by
        // conjugation); G(r) > 0: two real roots, each polished.
        let conj_pair = g.re < 0.0;
        // The expansion needs the split small against the distance from r to
        // the nearest a_i, where √G has its branch point: near r = a_i the two
        // members meet near a_i and are found in the local parameter there
        // (module docs; r may even round to a_i).
        let gap =
            lv.a.iter()
                .fold(f64::INFINITY, |m, &ai| m.min((rk - ai).abs()));
        if dp.re == 0.0
            || sg.norm() == 0.0
            || (2.0 * h0 * sg / dp.re).norm() > PAIR_GAP_FRACTION * gap
        {
            let (ib, agap) = nearest_a(lv.a, rk);
            if gap > BRANCH_POINT_FRACTION * agap {
                return None;
            }
            out.extend(branch_point_pair(lv, p_at_a, ib)?);
            continue;
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
                    off: first.off.conj(),
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
                off: rho * h0,
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
    // Im s: that of the offset (exact at a branch point, first order in a pair of
    // the expansion), ties (h0 = 0) broken by the first-order split; Re s by the
    // root of P, then the offset, then the split. The members of a pair share r.
    order_members(
        roots
            .into_iter()
            .map(|p| {
                let split = p.rho * kappa;
                Member {
                    pair: Some(p.r.to_bits()),
                    im: [p.off.im, split.im],
                    re: [p.r, p.off.re, split.re],
                    side: p.side,
                    root: p.root,
                }
            })
            .collect(),
    )
}

/// A root of `F` with what orders it ([`order_members`]).
struct Member {
    root: PolishedRoot,
    /// The pair it belongs to (`None`: a root the quartic found alone): the
    /// two members of a non-real pair are each other's conjugates.
    pair: Option<u64>,
    /// Lexicographic keys of `Im s` and `Re s`: where the double `s` cannot
    /// tell the members of a pair apart, their exact offsets (and, at
    /// `h0 = 0`, their first-order split) can.
    im: [f64; 2],
    re: [f64; 3],
    side: f64,
}

impl Member {
    fn is_real(&self) -> bool {
        self.im == [0.0, 0.0]
    }

    /// The conjugate partner: the other member of its pair, or the quartic's
    /// root at the exact conjugate.
    fn is_partner_of(&self, other: &Member) -> bool {
        match other.pair {
            Some(g) => self.pair == Some(g),
            None => self.pair.is_none() && self.root.s == other.root.s.conj(),
        }
    }
}

fn lex(x: &[f64], y: &[f64]) -> Ordering {
    x.iter()
        .zip(y)
        .map(|(a, b)| a.total_cmp(b))
        .find(|o| o.is_ne())
        .unwrap_or(Ordering::Equal)
}

/// The four roots in the documented order (module docs of [`super`]) by their
/// keys, with the conjugate-partner flags and the sides: `s1` the non-real
/// root of largest imaginary part (then real part), `s2` its conjugate, `s3`
/// the remaining one of larger imaginary part (then real part), `s4` the last;
/// four real roots by decreasing real part.
fn order_members(mut rest: Vec<Member>) -> Option<PairRoute> {
    let by_im_re = |p: &Member, q: &Member| lex(&p.im, &q.im).then(lex(&p.re, &q.re));
    let mut order: Vec<Member> = Vec::with_capacity(4);
    let mut partner = [false; 4];
    if rest.iter().any(|p| !p.is_real()) {
        let i1 = (0..rest.len())
            .filter(|&i| !rest[i].is_real())
            .max_by(|&i, &j| by_im_re(&rest[i], &rest[j]))?;
        let s1 = rest.remove(i1);
        let i2 = (0..rest.len()).find(|&i| rest[i].is_partner_of(&s1))?;
        let s2 = rest.remove(i2);
        order.push(s1);
        order.push(s2);
        partner[1] = true;
        rest.sort_by(|p, q| by_im_re(q, p));
        let conj34 = !rest[0].is_real() && rest[1].is_partner_of(&rest[0]);
        order.extend(rest);
        partner[3] = conj34;
    } else {
        rest.sort_by(|p, q| lex(&q.re, &p.re));
        order.extend(rest);
    }
    let side: [f64; 4] = std::array::from_fn(|p| order[p].side);
    let mut it = order.into_iter().map(|p| p.root);
    let roots = [it.next()?, it.next()?, it.next()?, it.next()?];
    Some((roots, partner, side))
}

/// The `a_i` nearest `r` and its distance to the other `a_m`.
fn nearest_a(a: &[f64; 4], r: f64) -> (usize, f64) {
    let ib = (0..4)
        .min_by(|&i, &j| (r - a[i]).abs().total_cmp(&(r - a[j]).abs()))
        .unwrap_or(0);
    let agap = (0..4)
        .filter(|&m| m != ib)
        .fold(f64::INFINITY, |g, m| g.min((a[m] - a[ib]).abs()));
    (ib, agap)
}

/// The two roots of `F` near the branch point `a_i` of `√G` (module docs): the
/// zeros of `φ(w) = P(a_i + w²) + 2 h0 w √Π_i(a_i + w²)` near 0, seeded from the
/// quadratic `P'(a_i) w² + 2 h0 √Π_i(a_i) w + P(a_i) = 0` and polished in `w`;
/// each root is then carried by its offset `t = w²` from `a_i` and polished on
/// `f` on its branch `σ = w √Π_i` in DD ([`polish_root_at`]). `None` when the
/// pair does not lie near `a_i` (then the quartic takes over) or is exactly
/// `a_i` (`P(a_i) = h0 = 0`: the state lies on the degenerate set).
fn branch_point_pair(lv: &Level, p_at_a: &[f64; 4], i: usize) -> Option<[PairRoot; 2]> {
    let a = lv.a;
    let h0 = lv.h[0];
    let ai = a[i];
    let x0 = offsets_at(a, i, C::new(0.0, 0.0));
    let pi0: C = (0..4).filter(|&m| m != i).map(|m| x0[m]).product();
    let sqrt_pi0 = sqrt_principal(pi0);
    let (_, dp0) = lv.p_dp(C::new(ai, 0.0), &x0);
    let (qa, qb, qc) = (dp0, 2.0 * h0 * sqrt_pi0, C::new(p_at_a[i], 0.0));
    if qa == C::new(0.0, 0.0) {
        return None;
    }
    // stable roots of qa w² + qb w + qc = 0; B² − 4AC is real for a real state
    let disc = qb * qb - 4.0 * qa * qc;
    let sd = sqrt_principal(disc);
    let q = if (qb + sd).norm() >= (qb - sd).norm() {
        -0.5 * (qb + sd)
    } else {
        -0.5 * (qb - sd)
    };
    if q == C::new(0.0, 0.0) {
        return None;
    }
    let agap = nearest_a(a, ai).1;
    let seeds = [q / qa, qc / q];
    // t = w²: with w = (−B ± √disc)/(2A), t1 and t2 are conjugate (and not
    // real) when disc Π_i(a_i) < 0 (Π_i > 0: complex w, conjugate; Π_i < 0: B is
    // imaginary, w = i v with v complex conjugate); else both are real.
    let conj_pair = disc.re * pi0.re < 0.0;
    let kappa = if h0 == 0.0 { 1.0 } else { h0 };
    let mut out: Vec<PairRoot> = Vec::with_capacity(2);
    for (k, &w0) in seeds.iter().enumerate() {
        if conj_pair && k == 1 {
            let first: &PairRoot = out.last()?;
            let side = -first.side;
            out.push(PairRoot {
                root: first.root.conj(),
                r: ai,
                off: first.off.conj(),
                rho: first.rho.conj(),
                side,
            });
            continue;
        }
        let (w, sp) = polish_w(lv, i, w0, sqrt_pi0)?;
        let t = w * w;
        if t.norm().partial_cmp(&(BRANCH_POINT_FRACTION * agap)) != Some(Ordering::Less) {
            return None;
        }
        let sigma = w * sp;
        let root = polish_root_at(lv, p_at_a, i, t, Some(sigma));
        // The DD polish must keep the root at its offset: within a quarter of
        // the members' separation (it does not run to the other one) and 1e-3
        // of the offset (nor off the pair). The double Newton in `w` leaves
        // `t` good to about 1e-6 relative where the members nearly coincide in
        // `t` (`w_1 ≈ −w_2`); the DD polish takes it from there.
        let off = root.x[i].to_c();
        let sep = (seeds[0] * seeds[0] - seeds[1] * seeds[1]).norm();
        let moved_tol = (1e-6 * t.norm()).max((0.25 * sep).min(1e-3 * t.norm()));
        if !matches!(
            (off - t).norm().partial_cmp(&moved_tol),
            Some(Ordering::Less | Ordering::Equal)
        ) {
            return None;
        }
        let rho = -2.0 * sigma / dp0;
        let side = if conj_pair {
            let sgn = if off.im != 0.0 {
                off.im
            } else {
                (rho * kappa).im
            };
            sgn.signum()
        } else {
            0.0
        };
        out.push(PairRoot {
            root,
            r: ai,
            off,
            rho,
            side,
        });
    }
    let mut it = out.into_iter();
    Some([it.next()?, it.next()?])
}

/// Newton's method on `φ(w) = P(a_i + w²) + 2 h0 w √Π_i(a_i + w²)` from `w0`,
/// `φ'(w) = 2w P'(s) + 2 h0 √Π_i(s) (1 + w² Σ_{m≠i} 1/(s − a_m))`, with `P`, `P'`
/// summed from the state at the offsets `s − a_m` (exact from `w²`) and
/// `√Π_i` continued from `√Π_i(a_i)`. Returns `w` and `√Π_i(a_i + w²)`, or
/// `None` if the iteration does not settle near its seed.
fn polish_w(lv: &Level, i: usize, w0: C, sqrt_pi0: C) -> Option<(C, C)> {
    let a = lv.a;
    let h0 = lv.h[0];
    let mut w = w0;
    let mut sp = sqrt_pi0;
    for _ in 0..W_NEWTON_STEPS {
        let t = w * w;
        let x = offsets_at(a, i, t);
        let pi: C = (0..4).filter(|&m| m != i).map(|m| x[m]).product();
        let r = sqrt_principal(pi);
        sp = if (r - sp).norm() <= (r + sp).norm() {
            r
        } else {
            -r
        };
        let (p, dp) = lv.p_dp(C::new(a[i], 0.0) + t, &x);
        let phi = p + 2.0 * h0 * w * sp;
        let suminv: C = (0..4).filter(|&m| m != i).map(|m| 1.0 / x[m]).sum();
        let dphi = 2.0 * w * dp + 2.0 * h0 * sp * (1.0 + t * suminv);
        let step = phi / dphi;
        if !(step.re.is_finite() && step.im.is_finite()) {
            break;
        }
        w -= step;
        if step.norm() <= 2.0 * f64::EPSILON * w.norm() {
            break;
        }
    }
    let t = w * w;
    let x = offsets_at(a, i, t);
    let pi: C = (0..4).filter(|&m| m != i).map(|m| x[m]).product();
    let r = sqrt_principal(pi);
    sp = if (r - sp).norm() <= (r + sp).norm() {
        r
    } else {
        -r
    };
    // it must stay with its seed (not run to the other zero or off the pair)
    ((w - w0).norm() <= 0.5 * w0.norm() && w.re.is_finite() && w.im.is_finite()).then_some((w, sp))
}

/// The four roots of `F` when the quartic put two of them within rounding of
/// each other at a branch point `a_i` of `√G` away from `h0 = 0` (two `a_i`
/// close together, with `P(a_i)` small: a state near an so(3) block or a
/// single component of a top with nearly equal `a_i`): the pair is taken in
/// the local parameter `w = √(s − a_i)` ([`branch_point_pair`], whose
/// expansion of `φ(w)` needs `w` small against the gap to the other `a_m`,
/// not `h0` small), the other two roots as the quartic polished them. The
/// members are told apart by their exact offsets `t = s − a_i`, which the
/// double `s` rounds away. Ordered by the documented rule (module docs of
/// [`super`]), the tie within the pair broken by the offsets. `None` when no
/// such pair explains the cluster (the caller then reports a repeated root).
pub(super) fn branch_point_cluster(
    lv: &Level,
    p_at_a: &[f64; 4],
    quartic: Vec<PolishedRoot>,
    repeated: (usize, usize),
) -> Option<PairRoute> {
    let mut rest: Vec<Member> = quartic
        .into_iter()
        .map(|root| Member {
            pair: None,
            im: [root.s.im, 0.0],
            re: [root.s.re, 0.0, 0.0],
            side: 0.0,
            root,
        })
        .collect();
    let mut all: Vec<Member> = Vec::with_capacity(4);
    // up to two clusters (an equilibrium l_ij E_ij + l_kl E_kl has one at each of
    // two a_i)
    let mut next = Some(repeated);
    for group in 0..2 {
        let Some((i, j)) = next else { break };
        let (si, sj) = (rest[i].root.s, rest[j].root.s);
        let mean = (si + sj) * 0.5;
        // a cluster off the real axis is not at a branch point
        if mean.im.abs() > 2.0 * (si - sj).norm().max(f64::EPSILON * mean.norm()) {
            return None;
        }
        let (k, agap) = nearest_a(lv.a, mean.re);
        let ak = C::new(lv.a[k], 0.0);
        if (mean - ak).norm() > BRANCH_POINT_FRACTION * agap {
            return None;
        }
        let [m1, m2] = branch_point_pair(lv, p_at_a, k)?;
        // the members must be distinct (a true double root stays refused), and
        // the other roots off the pair's neighbourhood
        if m1.off == m2.off {
            return None;
        }
        rest = rest
            .into_iter()
            .enumerate()
            .filter(|(p, _)| *p != i && *p != j)
            .map(|(_, r)| r)
            .collect();
        if rest
            .iter()
            .any(|r| (r.root.s - ak).norm() <= BRANCH_POINT_FRACTION * agap)
        {
            return None;
        }
        for m in [m1, m2] {
            all.push(Member {
                pair: Some(group),
                im: [m.off.im, 0.0],
                re: [lv.a[k] + m.off.re, m.off.re, 0.0],
                side: m.side,
                root: m.root,
            });
        }
        next = repeated_pair(&rest.iter().map(|r| r.root.s).collect::<Vec<_>>());
    }
    if next.is_some() {
        return None;
    }
    all.extend(rest);
    order_members(all)
}
