//! Each root `s_p` of `F` (19) polished on its own branch of `√G`: Newton's
//! method on `f(s) = P(s) + 2 h0 √G(s)` (15) in the offset from the nearest
//! `a_i`, then one step in double-double for `s_p`, `σ_p` and `F'(s_p)`
//! consistent to better than double precision (docs/kotter.md §3).

use super::schottky::p_poly;
use super::{C, CYCLIC, ONE, ZERO};
use crate::numeric::complex::sqrt_principal;
use crate::numeric::complex::Modulus;
use crate::numeric::dd::{Cdd, Dd};

/// What the polish of the roots of `F` needs of the level set: `a`, `h`,
/// `h1² − 4h0²` and, when the reduction starts from a state, `(m, n)`
/// themselves (then `P(s)` and `f(s)` are summed from the state, without the
/// cancellation of the forms in `h`).
pub(super) struct Level<'a> {
    pub(super) a: &'a [f64; 4],
    pub(super) h: &'a [f64; 4],
    pub(super) mn: Option<([f64; 3], [f64; 3])>,
    pub(super) den: f64,
}

impl Level<'_> {
    /// `sgn(h0)`, `+1` at `h0 = 0`: (20) is normalised by `√(F'(s_p)/|h0|)`
    /// ([`super::KotterConstants::sqrt_fprime`]), and
    /// `F'(s_p)/|h0| = −4 sgn(h0) σ_p f'(s_p)/(h1² − 4h0²)` by (19').
    pub(super) fn h0_sign(&self) -> f64 {
        if self.h[0] < 0.0 {
            -1.0
        } else {
            1.0
        }
    }

    /// `P(s) = h1 s² − h2 s + h3` and `P'(s)` from the offsets `x_m = s − a_m`.
    /// From the state, `P(s) = Σ_j (x_j x_4 m_j² + x_k x_l n_j²)`: the
    /// offsets carry `s − a_m` to full relative accuracy, so `P` near a root of
    /// `G` (where it is small) keeps its relative accuracy.
    pub(super) fn p_dp(&self, s: C, x: &[C; 4]) -> (C, C) {
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
                    size += (r.modulus() * m[j].abs() + q.modulus() * n[j].abs()).powi(2);
                }
                (f, size)
            }
            None => {
                let (p, _) = self.p_dp(s, x);
                let [h0, h1, h2, h3] = *self.h;
                let size = (h1 * s * s).modulus()
                    + (h2 * s).modulus()
                    + h3.abs()
                    + (2.0 * h0 * sigma).modulus();
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
                    let dlj = if wa.modulus() <= wb.modulus() {
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
pub(super) fn offsets_at(a: &[f64; 4], i: usize, t: C) -> [C; 4] {
    std::array::from_fn(|m| if m == i { t } else { (a[i] - a[m]) + t })
}

/// The continuation of the branch `√G(s)`: the root of `Π x_m` nearest `prev`.
fn sqrt_g_near(x: &[C; 4], prev: C) -> C {
    let r = sqrt_principal(x.iter().product());
    if (r - prev).modulus() <= (r + prev).modulus() {
        r
    } else {
        -r
    }
}

/// A root of `F` (19) polished on its own branch, with what (20) needs there.
#[derive(Clone)]
pub(super) struct PolishedRoot {
    pub(super) s: C,
    /// `s − a_m` in DD (exact sums from the root's offset to its nearest `a_i`).
    pub(super) x: [Cdd; 4],
    /// `σ = √G(s)` on the branch where `f(s) = 0`.
    pub(super) sigma: Cdd,
    /// `F'(s)/|h0| = f'(s) f̃(s) / (|h0| (h1² − 4h0²))` with `f̃(s) = −4 h0 σ`
    /// (docs/kotter.md §3; the scale `|h0|` keeps it finite at `h0 = 0`).
    pub(super) fprime: C,
    /// `√(F'(s)/|h0|)`, principal.
    pub(super) sqrt_fprime: Cdd,
    /// Newton's method in DD ([`refine_dd`]) ended on a step below DD
    /// resolution: `s` is a root of `f` to DD accuracy, not only to double.
    pub(super) dd_converged: bool,
}

impl PolishedRoot {
    /// The root of the conjugate pair's partner: every quantity conjugated,
    /// `√F'` kept principal (`conj(√F')` is the principal root of `conj(F')`
    /// except on the cut `F' < 0`, where both are `+i√|F'|`).
    pub(super) fn conj(&self) -> PolishedRoot {
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
            dd_converged: self.dd_converged,
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
///
/// With `branch` given (the pair route near `h0 = 0`, [`super::pairs`]) the
/// branch is the one of `±√G(s0)` nearest it and the squared form is skipped:
/// there the two roots of a pair are on different branches a distance `~h0`
/// apart, and `|f|` at the start does not tell them apart (at `h0 = 0` not at all).
pub(super) fn polish_root(lv: &Level, p_at_a: &[f64; 4], s0: C, branch: Option<C>) -> PolishedRoot {
    let best = nearest_a(lv.a, s0);
    polish_root_at(lv, p_at_a, best, s0 - lv.a[best], branch)
}

/// The index of the `a_i` nearest `s` (the first of equals).
fn nearest_a(a: &[f64; 4], s: C) -> usize {
    (1..4).fold(0, |best, i| {
        if (s - a[i]).modulus() < (s - a[best]).modulus() {
            i
        } else {
            best
        }
    })
}

/// [`polish_root`] from the offset `t0 = s0 − a_best` itself (a root within
/// rounding of `a_best` — the pairs at a branch point of `√G`, [`super::pairs`] —
/// keeps its offset, which `s0` alone would lose).
pub(super) fn polish_root_at(
    lv: &Level,
    p_at_a: &[f64; 4],
    best: usize,
    t0: C,
    branch: Option<C>,
) -> PolishedRoot {
    let a = lv.a;
    let ai = a[best];
    let gap = (0..4)
        .filter(|&m| m != best)
        .map(|m| (a[m] - ai).abs())
        .fold(f64::INFINITY, f64::min);
    let mut t = t0;
    if branch.is_none() && t.modulus() < 0.1 * gap {
        t = refine_on_squared_form(lv, p_at_a, best, t);
    }
    let (x0, sigma) = starting_branch(lv, best, t, branch);
    let (t, x, sigma) = newton_on_branch(lv, best, t, x0, sigma);
    let s = ai + t;
    let df = lv.df(s, &x, sigma);
    let fprime = df * (-4.0 * lv.h0_sign() * sigma) / lv.den;
    let plain = PolishedRoot {
        s,
        x: x.map(Cdd::new),
        sigma: Cdd::new(sigma),
        fprime,
        sqrt_fprime: Cdd::new(sqrt_principal(fprime)),
        dd_converged: false,
    };
    refine_dd(lv, best, t, sigma, df).unwrap_or(plain)
}

/// The offset `t` near `a_best` refined by four Newton steps on the numerator
/// of (19) at `s = a_best + t`, `(P(a_i) + P'(a_i) t + h1 t²)² − 4h0² t
/// Π_{m≠i}(a_i − a_m + t)`, smooth where `√G ~ √t` is not ([`polish_root`]).
fn refine_on_squared_form(lv: &Level, p_at_a: &[f64; 4], best: usize, t0: C) -> C {
    let a = lv.a;
    let [h0, h1, h2, _] = *lv.h;
    let ai = a[best];
    let mut t = t0;
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
        if der == ZERO || !(val / der).modulus().is_finite() {
            break;
        }
        let step = val / der;
        t -= step;
        if step.modulus() <= f64::EPSILON * t.modulus() {
            break;
        }
    }
    t
}

/// The offsets `s − a_m` at `s = a_best + t` and the branch `σ` of `√G` there:
/// of `±√G(s)`, the one nearest `branch` if given, else the one on which `|f|`
/// is the smaller.
fn starting_branch(lv: &Level, best: usize, t: C, branch: Option<C>) -> ([C; 4], C) {
    let a = lv.a;
    let ai = a[best];
    // the branch: of ±√G(s0), the one given, else the one on which f is the smaller
    let x0 = offsets_at(a, best, t);
    let g0 = sqrt_principal(x0.iter().product());
    let sigma = match branch {
        Some(b) => {
            if (g0 * b.conj()).re >= 0.0 {
                g0
            } else {
                -g0
            }
        }
        None => {
            let (fp, _) = lv.f(ai + t, &x0, g0);
            let (fm, _) = lv.f(ai + t, &x0, -g0);
            if fp.modulus() <= fm.modulus() {
                g0
            } else {
                -g0
            }
        }
    };
    (x0, sigma)
}

/// Up to eight Newton steps on `f` (15) from `(t, x0, σ)`, following the
/// branch of `√G` ([`sqrt_g_near`]): the state `(t, x, σ)` of the smallest
/// relative residual `|f|/size` met.
fn newton_on_branch(lv: &Level, best: usize, t: C, x0: [C; 4], mut sigma: C) -> (C, [C; 4], C) {
    let a = lv.a;
    let ai = a[best];
    let mut cur = (t, x0, sigma);
    let (f_cur, size) = lv.f(ai + t, &x0, sigma);
    let mut res_best = f_cur.modulus() / size.max(f64::MIN_POSITIVE);
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
        let res = fn_.modulus() / size.max(f64::MIN_POSITIVE);
        if res < res_best {
            res_best = res;
            best_state = cur;
        }
        if step.modulus() <= 2.0 * f64::EPSILON * (ai + tn).modulus().max(tn.modulus())
            || res == 0.0
        {
            break;
        }
    }
    best_state
}

/// At most this many Newton steps in DD in [`refine_dd`].
const DD_NEWTON_STEPS: usize = 6;
/// The last Newton step in DD (with the DD `f'`) below this fraction of the
/// offset: the root is converged in DD ([`PolishedRoot::dd_converged`]).
const DD_CONVERGED_RTOL: f64 = 1e-20;
/// A step below this fraction of the offset leaves nothing to gain in DD.
const DD_STEP_RTOL: f64 = 1e-31;
/// The first step (with the double `f'`) stands when its estimated error, the
/// step times the relative error of that `f'`, is below this fraction of the
/// offset: twelve digits beyond double, far more than the cancellations of
/// (22) take near an equilibrium (a phase error of the normalisations `√F'`
/// turns into ~1e9 times that relative error in the smallest `ξ_j`, measured
/// at 1e-20 → 8e-10). Generic roots leave 1e-32 … 1e-30 and take one step.
const DD_FIRST_STEP_RTOL: f64 = 1e-28;
/// A step not below this fraction of the one before has stalled at the
/// rounding of `f` in DD (1e-29 … 1e-27 of the offset where the terms of `f`
/// cancel, measured), and ends the iteration. Not smaller: near a double root
/// of `f` Newton's method converges only linearly, by a factor of about 2 per
/// step (stopping at a ratio of 1e-3 left 20 more states of the harsh draw
/// unresolved).
const DD_STALL_RATIO: f64 = 0.9;

/// The root, `σ`, the offsets `s − a_m` and `√F'(s)` to double-double
/// accuracy: Newton's method on `f` evaluated in DD from the double root
/// (`t = s − a_i`), the first step with the double `f'`, the next with `f'` in
/// DD until a step is below [`DD_CONVERGED_RTOL`], then `σ`, `f'` and
/// `F' = −4h0 σ f'/(h1² − 4h0²)` in DD at the new root.
///
/// Why: `l^(p)`, `Δ`, `d_j` and `α_j … δ_j` are all built from `(s_p, σ_p, F'(s_p))`,
/// and the third quadric (11) of the rounded constants holds only as well as
/// these are consistent with each other, amplified by about `√|d_j|` for a
/// large branch point: `F'` in double (a few ulps off) left a round trip of
/// 3.5e-12 at `|d_1| = 1.2e7`, DD constants 5e-16 (docs/kotter.md §3). `None`
/// when a DD value is not finite (then the double values stand).
///
/// Why more than one step: where `f'` cancels (a root of `F` a few 1e-9 from
/// its neighbour on the other branch of `√G`, both near an `a_i`), the double
/// `f'` is good to ~1e-4 only, and one step left the offsets 1e-20 off; the
/// normalisations `√F'(s_p)` of a conjugate pair were then off by a phase of
/// 2e-15, which (22) turns into an error of `φ η_j` in `ξ_j`: 8e-10 relative in
/// the small components, and no pair of points on the curve reproduced them
/// (states near `l_ij E_ij + l_kl E_kl`, docs/degenerate.md §11).
fn refine_dd(lv: &Level, i: usize, t: C, sigma: C, df: C) -> Option<PolishedRoot> {
    let (h0, den) = h0_den_dd(lv);
    refine_dd_with(lv, h0, den, i, Cdd::new(t), sigma, df)
}

/// `h0` and `h1² − 4h0²` in DD: from the state's `m, n` where given
/// (`h1² − 4h0² = |m − n|² |m + n|²`, no cancellation), else from `h`.
#[inline(always)]
fn h0_den_dd(lv: &Level) -> (Dd, Dd) {
    match lv.mn {
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
    }
}

/// [`refine_dd`] from a start `t` given in DD (inlined: the generic path
/// takes it once per root, as it took the body of `refine_dd` before).
#[inline(always)]
fn refine_dd_with(
    lv: &Level,
    h0: Dd,
    den: Dd,
    i: usize,
    t: Cdd,
    sigma: C,
    df: C,
) -> Option<PolishedRoot> {
    // Newton's method in DD: the first step with the double f', then with the
    // DD f'.
    let mut t_dd = t;
    let mut dfc = df;
    let (mut x, mut sg) = offsets_dd(lv.a, i, t_dd, sigma);
    let mut dfd = df_dd(lv, h0, &x, sg);
    let mut converged = false;
    let mut prev_rel = f64::INFINITY;
    for k in 0..DD_NEWTON_STEPS {
        let f = f_dd(lv, h0, &x, sg);
        let step = f.to_c() / dfc;
        if !(step.re.is_finite() && step.im.is_finite()) {
            if k == 0 {
                return None;
            }
            break;
        }
        t_dd = t_dd.sub(Cdd::new(step));
        (x, sg) = offsets_dd(lv.a, i, t_dd, sigma);
        dfd = df_dd(lv, h0, &x, sg);
        dfc = dfd.to_c();
        let rel = step.modulus() / t_dd.to_c().modulus();
        if k == 0 {
            // The first step took the double f': its error leaves the new
            // offset off by about |step| times the relative error of that f',
            // which the DD f' at the new root shows. Where f' kept its digits
            // (every generic root) that is below DD resolution and the one
            // step stands, as it always did.
            let df_err = (dfc - df).modulus() / dfc.modulus();
            if rel * df_err <= DD_FIRST_STEP_RTOL || rel <= DD_STEP_RTOL {
                converged = true;
                break;
            }
        } else {
            converged = rel <= DD_CONVERGED_RTOL;
            // at DD resolution, or stalled at the rounding of f in DD
            if rel <= DD_STEP_RTOL || rel > DD_STALL_RATIO * prev_rel {
                break;
            }
        }
        prev_rel = rel;
    }
    let fp = dfd.mul(sg).mul_f64(-4.0 * lv.h0_sign()).div_dd(den);
    let sq = fp.sqrt();
    let s = t_dd.add_f64(lv.a[i]);
    let out = PolishedRoot {
        s: s.to_c(),
        x,
        sigma: sg,
        fprime: fp.to_c(),
        sqrt_fprime: sq,
        dd_converged: converged,
    };
    let finite = |z: Cdd| {
        let (hi, lo) = (z.to_c(), C::new(z.re.lo, z.im.lo));
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

/// Newton steps on `f'` for the centre of a close pair ([`split_pair`]).
const PAIR_CENTRE_STEPS: usize = 12;

/// Step of the central difference of `f'` (relative to the offset `t`) that
/// gives `f''` for [`split_pair`]: `f'` in DD keeps ~1e-30 of its terms, so
/// 1e-9 leaves `f''` good to ~1e-21, and the pairs it is for are 1e-10 … 1e-6
/// of the offset apart, so the difference stays inside the pair's disc.
const PAIR_FD_RTOL: f64 = 1e-9;

/// Two roots of `f` on the branch `√G ≈ branch` that lie closer together than
/// the quartic resolves, from a seed `s0` next to them: the centre `c` of the
/// pair (`f'(c) = 0`, Newton's method on `f'` in DD, `f''` by a central
/// difference of the DD `f'`), the roots `c ± √(−2 f(c)/f''(c))` of the local
/// quadratic, each then polished by Newton's method in DD. From a seed farther
/// than the pair's separation Newton's method on `f` itself creeps like on a
/// double root (its steps halve), and six DD steps do not converge. `None`
/// unless both roots converge in DD.
pub(super) fn split_pair(lv: &Level, s0: C, branch: C) -> Option<[PolishedRoot; 2]> {
    let a = lv.a;
    let i = nearest_a(a, s0);
    let (h0, den) = h0_den_dd(lv);
    let df_at = |t: Cdd| {
        let (x, sg) = offsets_dd(a, i, t, branch);
        df_dd(lv, h0, &x, sg)
    };
    let finite = |v: C| v.re.is_finite() && v.im.is_finite();
    let mut t = Cdd::new(s0 - a[i]);
    let mut d2 = C::new(f64::NAN, 0.0);
    for _ in 0..PAIR_CENTRE_STEPS {
        let h = PAIR_FD_RTOL * t.to_c().modulus();
        if !(h > 0.0 && h.is_finite()) {
            return None;
        }
        let dh = Cdd::new(C::new(h, 0.0));
        d2 = df_at(t.add(dh)).sub(df_at(t.sub(dh))).to_c() / (2.0 * h);
        let step = df_at(t).to_c() / d2;
        if !finite(step) {
            return None;
        }
        t = t.sub(Cdd::new(step));
        if step.modulus() <= DD_STEP_RTOL * t.to_c().modulus() {
            break;
        }
    }
    let (x, sg) = offsets_dd(a, i, t, branch);
    let u = f_dd(lv, h0, &x, sg).mul_f64(-2.0).div(Cdd::new(d2)).sqrt();
    let root = |t: Cdd| -> Option<PolishedRoot> {
        let r = refine_dd_with(lv, h0, den, i, t, branch, df_at(t).to_c())?;
        r.dd_converged.then_some(r)
    };
    Some([root(t.add(u))?, root(t.sub(u))?])
}
