//! The period matrix in double-double, for a curve whose branch points are
//! known beyond double precision.
//!
//! The periods of [`HyperellipticCurve::periods`] are good to a few units of
//! rounding (a double quadrature on the rounded branch points). A velocity
//! `V = A X + B Y` in lattice coordinates carries that error into the
//! frequencies `X, Y`, and a motion's phase error grows like `δX · t`; the
//! Theorem's `l(t)` needs `X, Y` to well below an ulp (docs/theorem.md,
//! "The phase in double-double"). Here each cycle edge's period is the same
//! Gauss–Chebyshev sum as in double — the same tree, the same branches of the
//! square roots, the same symplectic combination — with nodes, weights,
//! integrand and sum in DD, on the branch points `e_k + e_lo[k]`.

use num_complex::Complex64;
use std::sync::OnceLock;

use super::quad::{self, SegmentSqrt};
use super::HyperellipticCurve;
use crate::error::Result;
use crate::numeric::compensated::{ExactProd, Fused, Veltkamp};
use crate::numeric::dd::{Cdd, Dd};
use crate::numeric::first_order::{cmul_err, Cc};

type C = Complex64;

/// `ln(1/ε)` of the DD quadrature target, `ρ^{-2N} ≤ e^{-41}` ≈ 1.6e-18, the
/// double quadrature's: the lattice rates come out to ~1e-19 (measured against
/// 60-digit mpmath periods: ≤ 1.4e-19 on 34 states; e^{-47} gave ≤ 1e-21 at
/// ~15 % more nodes), a thousand times below their rounding to double, which
/// is what the phase of `l(t)` needs.
const TARGET_LN_DD: f64 = 41.0;

/// π in double-double.
const PI_DD: Dd = Dd {
    hi: std::f64::consts::PI,
    lo: 1.224_646_799_147_353_2e-16,
};

/// A Gauss–Chebyshev rule with nodes and weight in DD.
struct RuleDd {
    nodes: Vec<Dd>,
    weight: Dd,
}

/// `(cos α, sin α)` in DD by their Taylor series (`|α| ≤ π/12`: 20 terms
/// reach DD precision).
fn cos_sin_small(alpha: Dd) -> (Dd, Dd) {
    let a2 = alpha.mul(alpha);
    let (mut c, mut s) = (Dd::new(1.0), alpha);
    let (mut tc, mut ts) = (Dd::new(1.0), alpha);
    for k in 1..20 {
        let kk = k as f64;
        tc = tc.mul(a2).neg().div(Dd::new((2.0 * kk - 1.0) * (2.0 * kk)));
        ts = ts.mul(a2).neg().div(Dd::new((2.0 * kk) * (2.0 * kk + 1.0)));
        c = c.add(tc);
        s = s.add(ts);
    }
    (c, s)
}

/// Nodes `cos((2k+1)π/(2n))` by the rotation `e^{i(2k+1)α} = e^{i(2k−1)α} e^{2iα}`,
/// `α = π/(2n)` (the error grows linearly in `k`: ~n · 1e-32), weight `π/n`.
fn rule_dd(n: usize) -> RuleDd {
    let alpha = PI_DD.div(Dd::new(2.0 * n as f64));
    let (c1, s1) = cos_sin_small(alpha);
    // e^{2iα}
    let c2 = c1.mul(c1).sub(s1.mul(s1));
    let s2 = c1.mul(s1).mul_f64(2.0);
    let mut nodes = vec![Dd::ZERO; n];
    let (mut c, mut s) = (c1, s1);
    for k in 0..n.div_ceil(2) {
        nodes[k] = c;
        nodes[n - 1 - k] = c.neg();
        let cn = c.mul(c2).sub(s.mul(s2));
        s = s.mul(c2).add(c.mul(s2));
        c = cn;
    }
    if n % 2 == 1 {
        nodes[n / 2] = Dd::ZERO;
    }
    RuleDd {
        nodes,
        weight: PI_DD.div(Dd::new(n as f64)),
    }
}

/// The Chebyshev node counts, and their DD rules (built once each): steps of
/// at most ~1/6, since every node of a rounded-up count is paid per curve.
const LADDER: [usize; 25] = [
    6, 8, 10, 12, 14, 16, 18, 20, 24, 28, 32, 36, 40, 48, 56, 64, 72, 80, 96, 112, 128, 144, 160,
    176, 192,
];
static RULES: [OnceLock<RuleDd>; LADDER.len()] = [const { OnceLock::new() }; LADDER.len()];

fn cheb_rule_dd(n: usize) -> Option<&'static RuleDd> {
    let i = LADDER.iter().position(|&m| m >= n)?;
    Some(RULES[i].get_or_init(|| rule_dd(LADDER[i])))
}

/// `1/P` in DD, where `P² = Π_m w_m` and `p0` is `P` in double on the wanted
/// branch: one Newton step `P = p0 + (Π w_m − p0²)/(2 p0)` (with `p0²` exact)
/// doubles the digits of `p0` and keeps its branch; then `1/P = q0 (1 + e)`,
/// `q0 = 1/p0` in double and `e = 1 − P q0` from the exact products `p0 q0`
/// (a DD division costs twice that).
fn inv_root_product(ws: &[Cdd], p0: C) -> Cdd {
    let prod = ws[1..].iter().fold(ws[0], |acc, w| acc.mul(*w));
    let sq = Cdd {
        re: Dd::prod(p0.re, p0.re).sub(Dd::prod(p0.im, p0.im)),
        im: Dd::prod(p0.re, p0.im).mul_f64(2.0),
    };
    let corr = crate::numeric::complex::cdiv(prod.sub(sq).to_c(), 2.0 * p0);
    let q0 = crate::numeric::complex::cdiv(C::new(1.0, 0.0), p0);
    // P q0 = p0 q0 + corr q0, the first exactly
    let pq = Cdd {
        re: Dd::prod(p0.re, q0.re).sub(Dd::prod(p0.im, q0.im)),
        im: Dd::prod(p0.re, q0.im).add(Dd::prod(p0.im, q0.re)),
    };
    let e = Cdd::new(C::new(1.0, 0.0)).sub(pq).to_c() - corr * q0;
    let d = q0 * e;
    Cdd {
        re: Dd::sum(q0.re, d.re),
        im: Dd::sum(q0.im, d.im),
    }
}

/// Gauss–Legendre on `[0, 1]` in DD: the double nodes polished by one Newton
/// step on `P_n` in DD, weights `1/((1 − x²) P_n'(x)²)` (mapped).
struct GlDd {
    nodes: Vec<Dd>,
    weights: Vec<Dd>,
}

fn legendre_dd(n: usize, x: Dd) -> (Dd, Dd) {
    let (mut p0, mut p1) = (Dd::new(1.0), x);
    for j in 2..=n {
        let jf = j as f64;
        let p2 = x
            .mul(p1)
            .mul_f64(2.0 * jf - 1.0)
            .sub(p0.mul_f64(jf - 1.0))
            .div(Dd::new(jf));
        p0 = p1;
        p1 = p2;
    }
    // P_n' = n (x P_n − P_{n−1}) / (x² − 1)
    let dp = x
        .mul(p1)
        .sub(p0)
        .mul_f64(n as f64)
        .div(x.mul(x).sub(Dd::new(1.0)));
    (p1, dp)
}

fn gl_dd(n: usize) -> GlDd {
    let rule = quad::gl_rule(n);
    let (mut nodes, mut weights) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for &v in &rule.nodes {
        // the double node on [0, 1] back on [−1, 1], one Newton step in DD
        let x0 = Dd::new(2.0 * v - 1.0);
        let (p, dp) = legendre_dd(n, x0);
        let x = x0.sub(p.div(dp));
        let (_, dp) = legendre_dd(n, x);
        let w = Dd::new(1.0).div(Dd::new(1.0).sub(x.mul(x)).mul(dp).mul(dp));
        nodes.push(x.add(Dd::new(1.0)).mul_f64(0.5));
        weights.push(w);
    }
    GlDd { nodes, weights }
}

const GL_LADDER: [usize; 14] = [4, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40, 48, 64];
static GL_RULES: [OnceLock<GlDd>; GL_LADDER.len()] = [const { OnceLock::new() }; GL_LADDER.len()];

fn gl_rule_dd(n: usize) -> &'static GlDd {
    let i = GL_LADDER
        .iter()
        .position(|&m| m >= n)
        .unwrap_or(GL_LADDER.len() - 1);
    GL_RULES[i].get_or_init(|| gl_dd(GL_LADDER[i]))
}

/// One Chebyshev edge `x = mid + h t` with the other branch points (with
/// their rounding errors) and the rotations of their square roots.
struct ChebEdge {
    mid: Cc,
    h: Cc,
    others: Vec<(Cc, SegmentSqrt)>,
    /// `Π c^{-1/2}` of the rotations.
    unrot: C,
}

/// A DD value as a double and its rounding error.
fn first_order(z: Cdd) -> Cc {
    let hi = z.to_c();
    Cc::new(hi, z.sub(Cdd::new(hi)).to_c())
}

/// `acc[i] += x^i / Π_m φ_m(x)` over the nodes `t` (DD: `hi + lo`) of one
/// Chebyshev edge, each term to `O(u²)` relative with its first-order error
/// ([`Cc`]): `x` and the factors `w_m = x − e_m` carry the rounding errors of
/// the nodes, of `mid`, `h` and of the branch points; `1/P` with
/// `P² = Π w_m` is `q0 (1 − E/2)`, `q0 = 1/p0` for `p0` the double product of
/// the roots on the branches of the double route and `E = Q q0² − 1` (of
/// order `u`, so `E²` is below the target).
fn cheb_node_sums(edge: &ChebEdge, nodes: &[Dd], acc: &mut [Cc]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports FMA (checked just above).
            return unsafe { cheb_node_sums_fma(edge, nodes, acc) };
        }
    }
    cheb_node_sums_body::<Veltkamp>(edge, nodes, acc)
}

/// [`cheb_node_sums`] compiled with FMA: each exact product is one
/// instruction instead of Dekker's seventeen (the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn cheb_node_sums_fma(edge: &ChebEdge, nodes: &[Dd], acc: &mut [Cc]) {
    cheb_node_sums_body::<Fused>(edge, nodes, acc)
}

#[inline(always)]
fn cheb_node_sums_body<M: ExactProd>(edge: &ChebEdge, nodes: &[Dd], acc: &mut [Cc]) {
    let one = C::new(1.0, 0.0);
    let n = acc.len();
    for t in nodes {
        let x = edge.mid.add(edge.h.mul_real::<M>(t.hi, t.lo));
        let mut q = Cc::new(one, C::new(0.0, 0.0));
        let mut p0 = edge.unrot;
        for (k, (e, s)) in edge.others.iter().enumerate() {
            let w = x.sub(*e);
            p0 *= s.rotated(w.hi);
            q = if k == 0 { w } else { q.mul::<M>(w) };
        }
        let q0 = crate::numeric::complex::cdiv(one, p0);
        let (s_hi, s_err) = cmul_err::<M>(q0, q0);
        let m = q.mul::<M>(Cc::new(s_hi, s_err));
        // m.hi ≈ 1: its real part minus 1 is exact (Sterbenz)
        let e = C::new(m.hi.re - 1.0, m.hi.im) + m.lo;
        let mut f = Cc::new(q0, -0.5 * (q0 * e));
        for (i, a) in acc.iter_mut().enumerate() {
            *a = a.add(f);
            if i + 1 < n {
                f = f.mul::<M>(x);
            }
        }
    }
}

/// The period matrices in DD: `a[i][j] = ∮_{a_j} x^i dx/y`, `b` likewise.
#[derive(Debug, Clone)]
pub(crate) struct PeriodsDd {
    /// a-periods, `a[i][j]`.
    pub a: Vec<Vec<Cdd>>,
    /// b-periods, `b[i][j]`.
    pub b: Vec<Vec<Cdd>>,
}

impl HyperellipticCurve {
    /// The periods `A`, `B` of [`HyperellipticCurve::periods`] in DD, for the
    /// curve with branch points `e_k + e_lo[k]` (`e_k` those of this curve,
    /// `e_lo` their rounding errors): the same cycles, sums in DD (an edge
    /// with a branch point near an end as two composite Gauss–Legendre halves,
    /// as in double). `None` where a piece plan does not close (a branch point
    /// within rounding of a path).
    ///
    /// Errors: `e_lo` of the wrong length or not finite.
    pub(crate) fn periods_dd(&self, e_lo: &[C]) -> Result<Option<PeriodsDd>> {
        if e_lo.len() != self.e.len() {
            return Err(crate::error::Error::Shape {
                what: "e_lo",
                expected: format!("({},)", self.e.len()),
                got: format!("({},)", e_lo.len()),
            });
        }
        if let Some(index) = e_lo.iter().position(|v| !super::is_finite_c(*v)) {
            return Err(crate::error::Error::NonFinite {
                what: "e_lo",
                index,
            });
        }
        let g = self.g;
        // e_lo in the internal coordinate x / 2^k (exact)
        let down = 2f64.powi(-self.scale_exp);
        let lo: Vec<C> = e_lo.iter().map(|v| v * down).collect();
        let mut edge = Vec::with_capacity(self.cycle_edges.len());
        for &ce in &self.cycle_edges {
            let (p, q) = self.tree[ce];
            match self.edge_period_dd(p, q, &lo) {
                Some(per) => edge.push(per),
                None => return Ok(None),
            }
        }
        let m = 2 * g;
        let mut a = vec![vec![Cdd::ZERO; g]; g];
        let mut b = vec![vec![Cdd::ZERO; g]; g];
        for j in 0..m {
            for (k, per) in edge.iter().enumerate() {
                let coef = self.symplectic[j][k] as f64;
                if coef == 0.0 {
                    continue;
                }
                for i in 0..g {
                    // row i in the user's coordinate (a power of 2: exact)
                    let v = per[i].mul_f64(coef * self.period_row_scale(i));
                    if j < g {
                        a[i][j] = a[i][j].add(v);
                    } else {
                        b[i][j - g] = b[i][j - g].add(v);
                    }
                }
            }
        }
        Ok(Some(PeriodsDd { a, b }))
    }

    /// The loop period of the tree edge `p → q` in DD (see `edge_period`):
    /// `∮ ω_i = −2i ∫_{−1}^{1} x^i / Π_{k≠p,q} φ_k dt/√(1 − t²)`, by
    /// Chebyshev over the whole edge, else (a branch point near an end) as two
    /// halves from the ends. `e_lo` in the internal coordinate.
    fn edge_period_dd(&self, p: usize, q: usize, e_lo: &[C]) -> Option<Vec<Cdd>> {
        self.edge_period_cheb_dd(p, q, e_lo)
            .or_else(|| self.edge_period_halves_dd(p, q, e_lo))
    }

    /// [`Self::edge_period_dd`] by Chebyshev over the whole edge, `None` where
    /// a branch point near an end needs the halves.
    fn edge_period_cheb_dd(&self, p: usize, q: usize, e_lo: &[C]) -> Option<Vec<Cdd>> {
        let g = self.g;
        let ed = |k: usize| Cdd::from_parts(self.e[k], e_lo[k]);
        let half = Dd::new(0.5);
        let mid = ed(p).add(ed(q)).mul_dd(half);
        let h = ed(q).sub(ed(p)).mul_dd(half);
        // The branches of the double computation: the same rotations.
        let (mid_c, h_c) = (0.5 * (self.e[p] + self.e[q]), 0.5 * (self.e[q] - self.e[p]));
        let others: Vec<usize> = (0..self.e.len()).filter(|&k| k != p && k != q).collect();
        let segs: Vec<SegmentSqrt> = others
            .iter()
            .map(|&k| SegmentSqrt::new(mid_c - self.e[k] - h_c, 2.0 * h_c))
            .collect();
        let segs_unrot = segs.iter().fold(C::new(1.0, 0.0), |u, s| u * s.unrot());
        let lr = super::basis::edge_quality(&self.e, p, q);
        let nc = (TARGET_LN_DD / (2.0 * lr)).ceil();
        if !(nc.is_finite() && nc <= quad::CHEB_MAX as f64) {
            return None;
        }
        let rule = cheb_rule_dd(nc as usize)?;
        let edge = ChebEdge {
            mid: first_order(mid),
            h: first_order(h),
            others: others
                .iter()
                .zip(segs)
                .map(|(&k, s)| (first_order(ed(k)), s))
                .collect(),
            unrot: segs_unrot,
        };
        let mut acc = vec![Cc::ZERO; g];
        cheb_node_sums(&edge, &rule.nodes, &mut acc);
        // × weight × (−2i)
        Some(
            acc.into_iter()
                .map(|v| {
                    Cdd::from_parts(v.hi, v.lo)
                        .mul_dd(rule.weight)
                        .mul_i()
                        .mul_f64(-2.0)
                })
                .collect(),
        )
    }

    /// The loop period of the edge `p → q` as twice the difference of the
    /// integrals from either end to the middle, on the branch `Y` of the
    /// Chebyshev form there (the double route for an edge with a branch point
    /// near an end).
    fn edge_period_halves_dd(&self, p: usize, q: usize, e_lo: &[C]) -> Option<Vec<Cdd>> {
        let ed = |k: usize| Cdd::from_parts(self.e[k], e_lo[k]);
        let mid = ed(p).add(ed(q)).mul_dd(Dd::new(0.5));
        let (mid_c, h_c) = (0.5 * (self.e[p] + self.e[q]), 0.5 * (self.e[q] - self.e[p]));
        let (unrot, prod_mid) = (0..self.e.len())
            .filter(|&k| k != p && k != q)
            .map(|k| {
                let s = SegmentSqrt::new(mid_c - self.e[k] - h_c, 2.0 * h_c);
                (s.unrot(), s.rotated(mid_c - self.e[k]))
            })
            .fold((C::new(1.0, 0.0), C::new(1.0, 0.0)), |(u, r), (a, b)| {
                (u * a, r * b)
            });
        let y_mid = C::new(0.0, 1.0) * h_c * unrot * prod_mid;
        let from_p = self.half_edge_dd(p, mid, y_mid, e_lo)?;
        let from_q = self.half_edge_dd(q, mid, y_mid, e_lo)?;
        Some(
            from_p
                .iter()
                .zip(&from_q)
                .map(|(a, b)| a.sub(*b).mul_f64(2.0))
                .collect(),
        )
    }

    /// `∫ ω_i` from the branch point `e_k` to `(x, y)` in DD (the route of
    /// `path_from_branch_dx`): `x = e_k + dx σ²`, `ω_i = 2 √dx x^i dσ / Π_{m≠k}
    /// √(a_m + σ² dx)`, `a_m = e_k − e_m`, composite Gauss–Legendre in `σ` with
    /// pieces planned for the DD target; `y` fixes the sheet.
    fn half_edge_dd(&self, k: usize, x: Cdd, y: C, e_lo: &[C]) -> Option<Vec<Cdd>> {
        let g = self.g;
        let ed = |m: usize| Cdd::from_parts(self.e[m], e_lo[m]);
        let dx = x.sub(ed(k));
        let dxc = dx.to_c();
        let ms: Vec<usize> = (0..self.e.len()).filter(|&m| m != k).collect();
        let a: Vec<Cdd> = ms.iter().map(|&m| ed(k).sub(ed(m))).collect();
        let ac: Vec<C> = a.iter().map(|z| z.to_c()).collect();
        let bc = vec![dxc; ms.len()];
        let abs_a: Vec<f64> = ac.iter().map(|z| z.norm()).collect();
        let abs_e: Vec<f64> = ac.iter().map(|z| (z + dxc).norm()).collect();
        let prod = quad::SqrtProduct::new(&ac, &bc, &abs_a, &abs_e);
        let unrot = prod.unrot();
        let q0 = super::sqrt_principal(dxc);
        let y1 = q0 * unrot * prod.rotated(1.0);
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let sing: Vec<C> = ac
            .iter()
            .flat_map(|&am| {
                let s = super::sqrt_principal(-am / dxc);
                [s, -s]
            })
            .collect();
        let mut pieces = Vec::new();
        quad::plan_pieces(&sing, &mut pieces).ok()?;
        let mut acc = vec![Cdd::ZERO; g];
        let mut ws = Vec::with_capacity(ms.len());
        for pc in &pieces {
            let rule = gl_rule_dd(pc.n);
            let hh = Dd::sum(pc.b, -pc.a);
            for (&t, &w) in rule.nodes.iter().zip(&rule.weights) {
                let sig = Dd::new(pc.a).add(hh.mul(t));
                let s2 = sig.mul(sig);
                ws.clear();
                for am in &a {
                    ws.push(am.add(dx.mul_dd(s2)));
                }
                let p0 = prod.rotated(s2.to_f64()) * unrot;
                let mut f = inv_root_product(&ws, p0).mul_dd(w.mul(hh));
                let xs = ed(k).add(dx.mul_dd(s2));
                for v in acc.iter_mut() {
                    *v = v.add(f);
                    f = f.mul(xs);
                }
            }
        }
        // × 2 sign √dx (√dx in DD on the branch of q0)
        let q = inv_root_product(&[dx], q0).recip();
        Some(
            acc.into_iter()
                .map(|v| v.mul(q).mul_f64(2.0 * sign))
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The DD nodes are zeros of `T_n` to DD precision (`T_n` by its
    /// three-term recurrence in DD), the weight is `π/n`.
    #[test]
    fn dd_chebyshev_nodes_are_zeros_of_t_n() {
        for n in [6, 7, 32, 192] {
            let r = rule_dd(n);
            for (k, &t) in r.nodes.iter().enumerate() {
                let exact = ((2 * k + 1) as f64 * std::f64::consts::PI / (2 * n) as f64).cos();
                // (the double reference has the rounding of its argument, ~4e-16)
                assert!((t.to_f64() - exact).abs() <= 1e-15, "{n} {k}");
                let (mut tm, mut tc) = (Dd::new(1.0), t);
                for _ in 1..n {
                    let tn = t.mul(tc).mul_f64(2.0).sub(tm);
                    tm = tc;
                    tc = tn;
                }
                // |T_n'| ≤ n², and the recurrence adds ~n u² per step
                let bound = (n * n) as f64 * 1e-30;
                assert!(
                    tc.to_f64().abs() <= bound,
                    "{n} {k}: T_n = {:e}",
                    tc.to_f64()
                );
            }
            let w = std::f64::consts::PI / n as f64;
            assert!((r.weight.to_f64() - w).abs() <= 2.3e-16 * w);
            // the DD weight times n is π to DD precision
            let back = r.weight.mul_f64(n as f64).sub(PI_DD);
            assert!(back.to_f64().abs() <= 1e-30);
        }
    }

    /// The two DD routes of an edge period, Chebyshev over the whole edge and
    /// composite Gauss–Legendre halves from its ends, agree to the DD target
    /// on every edge of a well-separated curve (independent quadratures of
    /// the same integral); and a curve with a branch point near an end of an
    /// edge (`1.0001` beside `1`), whose periods need the halves, agrees with
    /// the double periods to their accuracy.
    #[test]
    fn the_two_dd_routes_of_an_edge_period_agree() {
        let e = [
            C::new(0.0, 0.0),
            C::new(0.7, 0.3),
            C::new(1.9, -0.2),
            C::new(3.1, 0.5),
            C::new(-1.4, 2.2),
        ];
        let lo = [C::new(0.0, 0.0); 5];
        let curve = HyperellipticCurve::new(&e).unwrap();
        for &(p, q) in curve.tree() {
            let cheb = curve.edge_period_dd(p, q, &lo).unwrap();
            let halves = curve.edge_period_halves_dd(p, q, &lo).unwrap();
            for (a, b) in cheb.iter().zip(&halves) {
                let d = a.sub(*b).to_c().norm();
                // both quadratures stop at e^{-41} ≈ 1.6e-18 (TARGET_LN_DD);
                // measured 2.1e-19
                assert!(d <= 2e-18 * a.to_c().norm(), "edge {p}-{q}: {d:e}");
            }
        }
        let e2 = [
            C::new(0.0, 0.0),
            C::new(1.0, 0.0),
            C::new(1.0001, 0.0),
            C::new(3.0, 0.0),
            C::new(5.0, 0.0),
        ];
        let curve = HyperellipticCurve::new(&e2).unwrap();
        let pd = curve.periods_dd(&lo).unwrap().unwrap();
        let (a, b) = curve.periods();
        let scale = a
            .iter()
            .chain(b.iter())
            .fold(0.0f64, |m, v| m.max(v.norm()));
        for i in 0..2 {
            for j in 0..2 {
                assert!((pd.a[i][j].to_c() - a[(i, j)]).norm() <= 1e-14 * scale);
                assert!((pd.b[i][j].to_c() - b[(i, j)]).norm() <= 1e-14 * scale);
            }
        }
    }

    /// On a curve beyond the internal scale (`|e_4|` = 9e22, the curve of a
    /// state 1e-7 from an so(3) block of 'physical'), the DD periods are in
    /// the user's coordinate like [`HyperellipticCurve::periods`]: the branch
    /// points' errors enter scaled, the rows come back scaled (they were mixed
    /// before, off by powers of 2^76).
    #[test]
    fn dd_periods_of_a_rescaled_curve_are_in_the_users_coordinate() {
        let e = [
            C::new(0.0, 0.0),
            C::new(0.0, 50461376.96848367),
            C::new(0.0, 15739201.518415319),
            C::new(0.0, -114122608.17868833),
            C::new(0.0, 9.063866112046367e+22),
        ];
        let curve = HyperellipticCurve::new(&e).unwrap();
        assert!(curve.scale_exp != 0);
        let pd = curve.periods_dd(&[C::new(0.0, 0.0); 5]).unwrap().unwrap();
        let (a, b) = curve.periods();
        for i in 0..2 {
            let row = (0..2)
                .map(|j| a[(i, j)].norm().max(b[(i, j)].norm()))
                .fold(0.0f64, f64::max);
            for j in 0..2 {
                assert!(
                    (pd.a[i][j].to_c() - a[(i, j)]).norm() <= 1e-13 * row,
                    "a {i}{j}"
                );
                assert!(
                    (pd.b[i][j].to_c() - b[(i, j)]).norm() <= 1e-13 * row,
                    "b {i}{j}"
                );
            }
        }
    }

    /// With `e_lo = 0` the DD periods round to the double ones (to their
    /// accuracy, ~1e-15 relative).
    #[test]
    fn dd_periods_agree_with_the_double_ones() {
        let e = [
            C::new(0.0, 0.0),
            C::new(0.7, 0.0),
            C::new(1.9, 0.0),
            C::new(3.1, 0.0),
            C::new(0.7 * 1.9 * 3.1, 0.0),
        ];
        let curve = HyperellipticCurve::new(&e).unwrap();
        let pd = curve.periods_dd(&[C::new(0.0, 0.0); 5]).unwrap().unwrap();
        let (a, b) = curve.periods();
        let scale = a
            .iter()
            .chain(b.iter())
            .fold(0.0f64, |m, v| m.max(v.norm()));
        for i in 0..2 {
            for j in 0..2 {
                assert!((pd.a[i][j].to_c() - a[(i, j)]).norm() <= 1e-14 * scale);
                assert!((pd.b[i][j].to_c() - b[(i, j)]).norm() <= 1e-14 * scale);
            }
        }
    }
}
