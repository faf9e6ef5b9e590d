//! Quadrature on straight paths of a hyperelliptic curve.
//!
//! Every integral of the layer is `∫_0^1 f(v) dv` (or a Gauss–Chebyshev
//! integral on `[-1, 1]`) of a function analytic on `[0, 1]` whose only
//! singularities are known points `z_j` of the complex `v`-plane (the branch
//! points, mapped into the path's parameter). The endpoint square roots are
//! removed beforehand by the substitutions of `mod.rs`. The node count comes
//! from the Bernstein ellipse through the nearest singularity: Gauss–Legendre
//! with `N` nodes errs by `O(ρ^{-2N})` for a function analytic inside the
//! ellipse with foci at the ends and parameter `ρ` (Trefethen, *Approximation
//! Theory and Approximation Practice*, Thm 19.3); the same holds for
//! Gauss–Chebyshev with the weight `1/√(1 − t²)`. A piece whose ellipse is
//! too thin (a singularity close to the path) is bisected, so the cost grows
//! only logarithmically with the closeness.

use num_complex::Complex64;
use std::sync::OnceLock;

use crate::error::{Error, Result};
use crate::numeric::complex::{sqrt_principal, Modulus};

type C = Complex64;

/// `ln(1/ε)` of the quadrature target: `ρ^{-2N} ≤ e^{-TARGET_LN}` ≈ 1e-18,
/// two digits below double rounding, which absorbs the `M/(ρ − 1)` prefactor
/// of the error bound for all but the thinnest ellipses (those are bisected).
pub const TARGET_LN: f64 = 41.0;

/// Gauss–Legendre rules available, by node count.
const GL_LADDER: [usize; 14] = [4, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40, 48, 64];

/// Largest Gauss–Legendre rule used on one piece; a thinner ellipse is bisected.
pub const GL_MAX: usize = 64;

/// Gauss–Chebyshev rules available (node counts); beyond the last one an edge
/// period is computed as two composite Gauss–Legendre halves instead.
const CHEB_LADDER: [usize; 16] = [
    6, 8, 10, 12, 16, 20, 24, 32, 40, 48, 64, 80, 96, 128, 160, 192,
];

/// Largest Gauss–Chebyshev rule.
pub const CHEB_MAX: usize = 192;

/// Most pieces one composite integral may use: a singularity at relative
/// distance `δ` from the path needs about `log2(1/δ)` bisections, so 400
/// pieces cover `δ` far below double precision; beyond, the path is refused.
const MAX_PIECES: usize = 400;

/// A piece is not split below this width relative to its position,
/// `half ≤ PIECE_MIN_RATIO · mid`: its nodes would no longer be distinct in
/// double precision (a singularity on the path to rounding). Pieces at the
/// start of the path (`[0, h]`) can be graded down to any width: a
/// singularity at a tiny `|v|` off the path (a cluster of branch points at
/// the start, seen from the far end of a long segment) is resolved.
const PIECE_MIN_RATIO: f64 = 1e-13;

/// A quadrature rule on `[0, 1]` (Gauss–Legendre) or `[-1, 1]` (Chebyshev).
#[derive(Debug)]
pub struct Rule {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

fn gauss_legendre(n: usize) -> Rule {
    // Newton on the three-term recurrence for P_n; Tricomi's initial guesses.
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let nf = n as f64;
    for k in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (k as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for j in 2..=n {
                let jf = j as f64;
                let p2 = ((2.0 * jf - 1.0) * x * p1 - (jf - 1.0) * p0) / jf;
                p0 = p1;
                p1 = p2;
            }
            dp = nf * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        // Map [-1, 1] → [0, 1].
        nodes[k] = (1.0 - x) / 2.0;
        nodes[n - 1 - k] = (1.0 + x) / 2.0;
        weights[k] = w / 2.0;
        weights[n - 1 - k] = w / 2.0;
    }
    Rule { nodes, weights }
}

fn gauss_chebyshev(n: usize) -> Rule {
    let w = std::f64::consts::PI / n as f64;
    let nodes = (0..n)
        .map(|k| ((2 * k + 1) as f64 * std::f64::consts::PI / (2 * n) as f64).cos())
        .collect();
    Rule {
        nodes,
        weights: vec![w; n],
    }
}

static GL_RULES: [OnceLock<Rule>; GL_LADDER.len()] = [const { OnceLock::new() }; GL_LADDER.len()];
static CHEB_RULES: [OnceLock<Rule>; CHEB_LADDER.len()] =
    [const { OnceLock::new() }; CHEB_LADDER.len()];

/// The smallest Gauss–Legendre rule (on `[0, 1]`) with at least `n` nodes.
pub fn gl_rule(n: usize) -> &'static Rule {
    let i = GL_LADDER
        .iter()
        .position(|&m| m >= n)
        .unwrap_or(GL_LADDER.len() - 1);
    GL_RULES[i].get_or_init(|| gauss_legendre(GL_LADDER[i]))
}

/// The smallest Gauss–Chebyshev rule with at least `n` nodes (`n ≤ CHEB_MAX`).
pub fn cheb_rule(n: usize) -> &'static Rule {
    let i = CHEB_LADDER
        .iter()
        .position(|&m| m >= n)
        .unwrap_or(CHEB_LADDER.len() - 1);
    CHEB_RULES[i].get_or_init(|| gauss_chebyshev(CHEB_LADDER[i]))
}

/// `ln ρ` of the Bernstein ellipse with foci `±1` through `z`: `acosh` of the
/// half sum of the focal distances (0 on the segment itself).
#[inline]
pub fn log_rho(z: C) -> f64 {
    focal_half_sum(z).acosh()
}

/// `(|z − 1| + |z + 1|)/2 ≥ 1`, monotone in `ρ` (cheap comparisons; no hypot).
#[inline]
pub fn focal_half_sum(z: C) -> f64 {
    let s = 0.5 * ((z - 1.0).norm_sqr().sqrt() + (z + 1.0).norm_sqr().sqrt());
    s.max(1.0)
}

/// Node count for an ellipse parameter `ln ρ` (infinite for `ln ρ = 0`).
#[inline]
pub fn nodes_for(log_rho: f64) -> f64 {
    (TARGET_LN / (2.0 * log_rho)).ceil()
}

/// The focal half sum [`focal_half_sum`] of `√w` from moduli alone:
/// `(|√w − 1| + |√w + 1|)² = 2|w| + 2 + 2|w − 1|`, so with `abs_w = |w|` and
/// `abs_w1 = |w − 1|` it is `√((|w| + 1 + |w − 1|)/2)` — no complex root, and
/// for `w = (e_m − e_k)/(x − e_k)` both moduli are distances between the
/// points `e_k, e_m, x` divided by `|x − e_k|`.
#[inline(always)]
pub fn focal_half_sum_sqrt(abs_w: f64, abs_w1: f64) -> f64 {
    (0.5 * (abs_w + 1.0 + abs_w1)).sqrt().max(1.0)
}

/// Square root of `w` with `Re w > 0` (the rotated values of [`SegmentSqrt`]):
/// `√w = (t, Im w / 2t)`, `t = √((|w| + Re w)/2)`, accurate to a few ulps
/// because no cancellation occurs on the right half plane.
#[inline(always)]
pub fn sqrt_right(w: C) -> C {
    let t = (0.5 * (w.norm_sqr().sqrt() + w.re)).sqrt();
    if t == 0.0 {
        return C::new(0.0, 0.0);
    }
    C::new(t, w.im / (2.0 * t))
}

/// A continuous branch of `√(a + v b)` for `v ∈ [0, 1]`, for a segment
/// `a + [0, 1] b` that does not pass through 0.
///
/// With `p` the point of the segment nearest to 0 and `c = p̄/|p|`, the
/// segment lies in the half plane `Re(c w) ≥ |p| > 0` (nearest-point property
/// of a convex set), so `√(c w)` (principal) is continuous along it and
/// `√(c w)·c^{-1/2}` squares to `w`.
#[derive(Debug, Clone, Copy)]
pub struct SegmentSqrt {
    rot: C,
    unrot: C,
}

impl SegmentSqrt {
    /// No rotation (a placeholder for fixed-size buffers).
    pub const UNIT: SegmentSqrt = SegmentSqrt {
        rot: C::new(1.0, 0.0),
        unrot: C::new(1.0, 0.0),
    };

    pub fn new(a: C, b: C) -> Self {
        Self::with_distance(a, b).0
    }

    /// [`Self::new`] and the distance of the segment from 0.
    pub fn with_distance(a: C, b: C) -> (Self, f64) {
        let bb = b.norm_sqr();
        let v = if bb > 0.0 {
            (-(b.conj() * a).re / bb).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let p = a + b * v;
        let r = p.modulus();
        let rot = if r > 0.0 {
            p.conj() / r
        } else {
            C::new(1.0, 0.0)
        };
        // c^{-1/2} = conj(√c) for |c| = 1; √c with Re c arbitrary: principal.
        let unrot = sqrt_principal(rot).conj();
        (SegmentSqrt { rot, unrot }, r)
    }

    /// `√w` on the branch of the segment (`w` a point of it).
    #[inline(always)]
    pub fn eval(&self, w: C) -> C {
        sqrt_right(self.rot * w) * self.unrot
    }

    /// `Π c^{-1/2}` is folded into one constant by callers that multiply many.
    #[inline(always)]
    pub fn rotated(&self, w: C) -> C {
        sqrt_right(self.rot * w)
    }

    /// The constant `c^{-1/2}`.
    pub fn unrot(&self) -> C {
        self.unrot
    }
}

/// Most factors of a [`SqrtProduct`] (the number of finite branch points).
pub const MAX_FACTORS: usize = 2 * crate::theta::MAX_GENUS + 2;

/// `sin` of the margin kept between the argument of a grouped product and
/// the branch cut of the principal root (0.05 rad: far above rounding).
const SIN_CUT_MARGIN: f64 = 0.05;

/// Bound on the modulus of a group's product (and of its inverse), so that
/// `|P|²` stays inside the double range and [`inv_sqrt_principal`] takes the
/// fast modulus.
const GROUP_MOD_MAX: f64 = 1e140;

/// A continuous branch of `Π_m √(a_m + v b_m)` for `v ∈ [0, 1]` (segments not
/// through 0) with few complex square roots per evaluation.
///
/// Factor `m` is rotated by the unit `c_m` that centres its segment on the
/// positive real axis: the ends `a_m`, `a_m + b_m` subtend an angle
/// `2δ_m < π` at 0, so `arg(c_m w) ∈ [−δ_m, δ_m]` along the segment.
/// Consecutive factors are grouped while `Σ δ_m < π − margin`; then the
/// argument of a group's rotated product stays off the cut, its principal
/// root is continuous in `v`, and one square root serves the whole group
/// (the per-factor roots of [`SegmentSqrt`] cost one each). A segment
/// passing too close to 0 for an accurate bisector takes the nearest-point
/// rotation of [`SegmentSqrt`] and counts as `δ = π/2`. The constant
/// `unrot = conj √(Π c_m)` undoes the rotations: `(unrot · rotated(v))² =
/// Π (a_m + v b_m)`.
#[derive(Debug, Clone, Copy)]
pub struct SqrtProduct {
    ra: [C; MAX_FACTORS],
    rb: [C; MAX_FACTORS],
    /// Exclusive end of each group.
    ends: [usize; MAX_FACTORS],
    groups: usize,
    unrot: C,
}

impl SqrtProduct {
    /// The product over `a[m] + v b[m]`, given the end moduli
    /// `abs_a[m] = |a_m|`, `abs_e[m] = |a_m + b_m|` (callers have them as
    /// distances between branch points and `x`). At most [`MAX_FACTORS`].
    pub fn new(a: &[C], b: &[C], abs_a: &[f64], abs_e: &[f64]) -> Self {
        let nf = a.len();
        let zero = C::new(0.0, 0.0);
        let mut sp = SqrtProduct {
            ra: [zero; MAX_FACTORS],
            rb: [zero; MAX_FACTORS],
            ends: [0; MAX_FACTORS],
            groups: 0,
            unrot: C::new(1.0, 0.0),
        };
        let mut all = C::new(1.0, 0.0);
        // e^{iΣδ} and the modulus bounds of the open group.
        let mut dir = C::new(1.0, 0.0);
        let (mut hi, mut lo) = (1.0f64, 1.0f64);
        for m in 0..nf {
            let (am, bm) = (a[m], b[m]);
            let (r0, r1) = (abs_a[m], abs_e[m]);
            let u0 = am / r0;
            let u1 = (am + bm) / r1;
            let bis = u0 + u1;
            let lb = bis.modulus();
            let (c, d, min_mod) = if r0 > 0.0 && r1 > 0.0 && lb > 1e-6 {
                let c = bis.conj() / lb;
                // e^{±iδ}: the rotated end; δ ∈ [0, π/2) from its imaginary part's sign
                let d = u1 * c;
                let d = if d.im < 0.0 { d.conj() } else { d };
                // Re(c w) is linear along the segment: its minimum is at an end
                (c, d, r0.min(r1) * d.re)
            } else {
                let (seg, near) = SegmentSqrt::with_distance(am, bm);
                (seg.rot, C::new(0.0, 1.0), near)
            };
            let max_mod = r0.max(r1);
            let nd = dir * d;
            let fits = m > 0
                && nd.im >= 0.0
                && (nd.re >= 0.0 || nd.im > SIN_CUT_MARGIN)
                && hi * max_mod <= GROUP_MOD_MAX
                && lo * min_mod >= 1.0 / GROUP_MOD_MAX;
            if fits {
                dir = nd;
                hi *= max_mod;
                lo *= min_mod;
            } else {
                if m > 0 {
                    sp.ends[sp.groups] = m;
                    sp.groups += 1;
                }
                dir = d;
                hi = max_mod;
                lo = min_mod;
            }
            sp.ra[m] = c * am;
            sp.rb[m] = c * bm;
            all *= c;
        }
        if nf > 0 {
            sp.ends[sp.groups] = nf;
            sp.groups += 1;
        }
        sp.unrot = sqrt_principal(all).conj();
        sp
    }

    /// `Π_groups √(Π_{m ∈ group} c_m (a_m + v b_m))` (principal roots).
    #[inline]
    pub fn rotated(&self, v: f64) -> C {
        let mut acc = C::new(1.0, 0.0);
        let mut start = 0;
        for &end in &self.ends[..self.groups] {
            let mut p = self.ra[start] + self.rb[start] * v;
            for m in start + 1..end {
                p *= self.ra[m] + self.rb[m] * v;
            }
            acc *= sqrt_principal(p);
            start = end;
        }
        acc
    }

    /// `1 / rotated(v)`, one real division per group.
    #[inline(always)]
    pub fn inv_rotated(&self, v: f64) -> C {
        let mut acc = C::new(1.0, 0.0);
        let mut start = 0;
        for &end in &self.ends[..self.groups] {
            let mut p = self.ra[start] + self.rb[start] * v;
            for m in start + 1..end {
                p *= self.ra[m] + self.rb[m] * v;
            }
            acc *= inv_sqrt_principal(p);
            start = end;
        }
        acc
    }

    /// `conj √(Π c_m)`.
    pub fn unrot(&self) -> C {
        self.unrot
    }

    /// Number of complex square roots per evaluation (for tests).
    pub fn groups(&self) -> usize {
        self.groups
    }
}

/// `1/√p` on the principal branch: `conj(√p)/|p|` with `√p` by Kahan's
/// formulation, `t² = (|p| + |Re p|)/2` formed without rounding `t`:
/// one square root for `|p|`, one for `t`, one division.
#[inline(always)]
pub fn inv_sqrt_principal(p: C) -> C {
    let (re, im) = (p.re, p.im + 0.0); // one cut side, as sqrt_principal
    let r = p.modulus();
    if re >= 0.0 {
        let t2 = 0.5 * (r + re);
        let inv = 1.0 / (t2.sqrt() * r);
        C::new(t2 * inv, -0.5 * im * inv)
    } else {
        let t2 = 0.5 * (r - re);
        let inv = 1.0 / (t2.sqrt() * r);
        C::new(0.5 * im.abs() * inv, -t2.copysign(im) * inv)
    }
}

/// One piece `[a, b] ⊂ [0, 1]` of a composite rule, with its node count.
#[derive(Debug, Clone, Copy)]
pub struct Piece {
    pub a: f64,
    pub b: f64,
    pub n: usize,
}

/// Splits `[0, 1]` into pieces on each of which Gauss–Legendre with at most
/// [`GL_MAX`] nodes reaches [`TARGET_LN`], given the singular points `sing`
/// of the integrand in the `v`-plane.
pub fn plan_pieces(sing: &[C], out: &mut Vec<Piece>) -> Result<()> {
    out.clear();
    let mut stack: Vec<(f64, f64)> = vec![(0.0, 1.0)];
    while let Some((a, b)) = stack.pop() {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        let lr = sing
            .iter()
            .map(|&z| log_rho((z - mid) / half))
            .fold(f64::INFINITY, f64::min);
        let n = nodes_for(lr);
        if n <= GL_MAX as f64 {
            out.push(Piece {
                a,
                b,
                n: (n as usize).max(4),
            });
        } else if out.len() + stack.len() >= MAX_PIECES || half <= PIECE_MIN_RATIO * mid {
            return Err(Error::InvalidArgument {
                what: "path",
                reason: "an integration path passes within rounding distance of a branch point"
                    .into(),
            });
        } else {
            stack.push((mid, b));
            stack.push((a, mid));
        }
    }
    Ok(())
}

/// `∫_0^1 f(v²) dv = ½ ∫_{−1}^{1} f(v²) dv` by one Gauss–Legendre rule on
/// `[−1, 1]` with `n` (even) nodes, evaluating only the positive half: the
/// integrand of an endpoint-substituted path is even in `v`, and its
/// singularities `±z_j` come in pairs, so the ellipse is that of `[−1, 1]`.
#[inline]
pub fn integrate_even(n: usize, acc: &mut [C], mut f: impl FnMut(f64, f64, &mut [C])) {
    let rule = gl_rule(n);
    for (&x, &w) in rule.nodes.iter().zip(&rule.weights) {
        if x > 0.5 {
            f(2.0 * x - 1.0, 2.0 * w, acc);
        }
    }
}

/// `∫_0^1 f(v) dv` on `pieces`, `f` adding `w·f(v)` into its accumulator.
#[inline]
pub fn integrate(pieces: &[Piece], acc: &mut [C], mut f: impl FnMut(f64, f64, &mut [C])) {
    for p in pieces {
        let rule = gl_rule(p.n);
        let h = p.b - p.a;
        for (&x, &w) in rule.nodes.iter().zip(&rule.weights) {
            f(p.a + h * x, w * h, acc);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for &n in &GL_LADDER {
            let r = gl_rule(n);
            for k in 0..(2 * n) {
                let s: f64 = r
                    .nodes
                    .iter()
                    .zip(&r.weights)
                    .map(|(x, w)| w * x.powi(k as i32))
                    .sum();
                assert!((s - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "n={n} k={k}");
            }
        }
    }

    #[test]
    fn segment_sqrt_is_continuous_and_squares_back() {
        let (a, b) = (C::new(-3.0, 0.5), C::new(6.0, -1.2));
        let s = SegmentSqrt::new(a, b);
        let mut prev = s.eval(a);
        for k in 1..=1000 {
            let w = a + b * (k as f64 / 1000.0);
            let r = s.eval(w);
            assert!((r * r - w).norm() < 1e-14 * w.norm().max(1.0));
            assert!((r - prev).norm() < 0.1);
            prev = r;
        }
    }

    /// The grouped roots square back to the product, are continuous along
    /// `v ∈ [0, 1]` (no jump across the cut of a group's principal root),
    /// and `inv_rotated` is their inverse; segments passing close to 0 on
    /// both sides and far ones (one group) are covered.
    #[test]
    fn sqrt_product_is_a_continuous_root_of_the_product() {
        let cases: [&[(C, C)]; 3] = [
            &[
                (C::new(-3.0, 0.5), C::new(6.0, -1.2)),
                (C::new(1.0, 2.0), C::new(-2.0, -4.1)),
                (C::new(-1.0, -0.01), C::new(2.0, 0.0)),
                (C::new(0.2, 0.3), C::new(0.1, -0.9)),
            ],
            &[
                (C::new(5.0, 1.0), C::new(0.5, 0.2)),
                (C::new(4.0, -2.0), C::new(0.3, 0.1)),
                (C::new(-6.0, 0.5), C::new(-0.2, 0.4)),
            ],
            &[
                (C::new(-1.0, 1e-9), C::new(2.0, 0.0)),
                (C::new(-1.0, -1e-9), C::new(2.0, 0.0)),
                (C::new(1e-3, 1.0), C::new(0.0, -2.0)),
            ],
        ];
        // Three segments each sweeping arg from −1.4 to 1.4: the product's
        // argument sweeps ±4.2 and crosses the cut unless it is split.
        let (lo, hi) = (C::from_polar(1.0, -1.4), C::from_polar(1.0, 1.4));
        let sweep = [(lo, hi - lo); 3];
        let cases: Vec<&[(C, C)]> = cases.iter().copied().chain([&sweep[..]]).collect();
        for (ci, f) in cases.iter().enumerate() {
            let a: Vec<C> = f.iter().map(|p| p.0).collect();
            let b: Vec<C> = f.iter().map(|p| p.1).collect();
            let abs_a: Vec<f64> = a.iter().map(|z| z.norm()).collect();
            let abs_e: Vec<f64> = f.iter().map(|p| (p.0 + p.1).norm()).collect();
            let sp = SqrtProduct::new(&a, &b, &abs_a, &abs_e);
            let root = |v: f64| sp.unrot() * sp.rotated(v);
            let mut prev = root(0.0);
            for k in 0..=4000 {
                let v = k as f64 / 4000.0;
                let want: C = f.iter().map(|p| p.0 + p.1 * v).product();
                let r = root(v);
                assert!(
                    (r * r - want).norm() <= 1e-14 * want.norm().max(1.0),
                    "case {ci} v {v}"
                );
                let inv = sp.inv_rotated(v) * sp.rotated(v);
                assert!((inv - 1.0).norm() < 1e-14, "case {ci} v {v}");
                // a sign flip would jump by 2|r|; steps of 1/4000 move it far less
                assert!(
                    (r - prev).norm() < 0.05 * r.norm().max(prev.norm()) + 1e-3,
                    "case {ci} v {v}"
                );
                prev = r;
            }
        }
        // Far segments: one square root for all factors.
        let a = [
            C::new(9.0, 1.0),
            C::new(-2.0, 8.0),
            C::new(7.0, -7.0),
            C::new(-9.0, -3.0),
        ];
        let b = [C::new(0.3, 0.1); 4];
        let abs_a: Vec<f64> = a.iter().map(|z| z.norm()).collect();
        let abs_e: Vec<f64> = a.iter().zip(&b).map(|(x, y)| (x + y).norm()).collect();
        assert_eq!(SqrtProduct::new(&a, &b, &abs_a, &abs_e).groups(), 1);
    }

    #[test]
    fn log_rho_of_known_points() {
        // On the real axis beyond the end: ρ = x + √(x² − 1).
        let x: f64 = 2.0;
        assert!((log_rho(C::new(x, 0.0)) - (x + (x * x - 1.0).sqrt()).ln()).abs() < 1e-15);
        assert_eq!(log_rho(C::new(0.3, 0.0)), 0.0);
    }
}
