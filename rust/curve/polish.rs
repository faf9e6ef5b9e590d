//! The polish of the inverse map: Levenberg–Marquardt from a far start, then
//! Gauss–Newton to rounding, on the local uniformizing parameters of the two
//! points at their nearest branch points.

use super::wurzel::{factor_quotients, pair_quotient};
use super::*;

/// Floor of the relative weights of the Gauss–Newton polish of the points
/// (a fraction of the largest of the six targets): below it a component is
/// fitted absolutely.
const REL_FLOOR: f64 = 1e-8;

/// Relative residual (2-norm of the relative residuals of the six data) at
/// which the Levenberg–Marquardt phase of the inverse map's polish hands over
/// to Gauss–Newton, whose quadratic convergence then reaches rounding in one
/// or two steps.
const LM_HANDOVER: f64 = 1e-12;

/// Residual of the Gauss–Newton phase (relative, or in the metric of (23)) at
/// which it has reached the rounding floor of the data (~50 ulps): there a
/// step that does not halve the residual ends the polish. Measured on the
/// generic bench state: the closed-form start is at 1.2e-16, one step reaches
/// 8.7e-17 and a second 8.69e-17; the third finds no decrease.
const GN_FLOOR: f64 = 1e-14;

impl KotterCurve {
    /// Gauss–Newton polish of `(z1, z2, g)` for [`KotterCurve::points_from_xi_eta`].
    ///
    /// The closed form goes through `Σ c̃_j X_j²`, whose terms cancel heavily
    /// when the `P_kl` are nearly equal (points far out or close together) or
    /// when two branch points nearly coincide (`c̃_j ~ 1/(d_j − d_k)`); that
    /// costs up to ~1e3 over the conditioning of the map itself, and more for
    /// clustered branch points. Least-squares Newton steps on the six
    /// equations `X = g P_kl`, `Y = g P_j4` recover the intrinsic accuracy.
    ///
    /// Each point is parametrised by the local uniformizing parameter at its
    /// nearest branch point `d_b`: `w = r_b(z) = √(z − d_b)` (with its
    /// branch), `z = d_b + w²`. In `w` the map is holomorphic and regular
    /// through the branch point, whereas in `z` it has a square-root
    /// singularity there: a closed-form `z` whose error is comparable to its
    /// distance from `d_b` (a point 5e-11 from `d_1` when `d_1, d_2` are 3e-5
    /// apart) is outside the basin of Newton's method in `z`, not in `w`.
    /// The offsets are then `zd_j = w² + (d_b − d_j)`, accurate to a few ulps
    /// ([`CurvePoint`]). The other roots are continued holomorphically,
    /// `r_j(z + δ) = r_j(z) √(1 + δ/(z − d_j))`, so a step never crosses a
    /// cut of the principal roots; the final branch is expressed again as
    /// `eps` relative to the canonical roots.
    ///
    /// Two phases. First Levenberg–Marquardt, fitting each component relative
    /// to its size (in the 2-norm), from the closed-form start, which near the
    /// singular set h1² = 4h0² can be far off (the closed form cancels by
    /// ~|d_4|/|z| there, and a point may sit between two branch points that
    /// nearly coincide); skipped when the start is already within
    /// [`LM_HANDOVER`]. Then Gauss–Newton to rounding, in the metric of (23)
    /// when `lmap` is given (it moves the components `l` is least sensitive
    /// to; see `points_from_xi_eta_fit`), else relative again (max-norm). The
    /// metric of (23) is not used from a far start: its α_j … δ_j are large
    /// and nearly dependent near the singular set, and the Gauss–Newton step
    /// ran off along the wrong direction.
    pub(super) fn refine(
        &self,
        start: WurzelPoints,
        target: &[Complex64; 6],
        sc: &[Complex64; 3],
        lmap: Option<&[[Complex64; 3]; 4]>,
    ) -> WurzelPoints {
        let fit = Fit::new(self, &start, target, sc, lmap);
        let mut st = fit.start_state(self, &start);
        let mut improved = false;
        let last = if lmap.is_some() {
            (Phase::GnL, 6)
        } else {
            (Phase::Gn, 8)
        };
        for (phase, iterations) in [(Phase::Lm, 40), last] {
            st.obj = fit.cost(&st.f, phase);
            // a start already within reach of Gauss–Newton skips LM
            if phase == Phase::Lm && st.obj <= LM_HANDOVER * LM_HANDOVER {
                continue;
            }
            let mut mu = 1e-3;
            for _ in 0..iterations {
                let Some(next) = fit.iterate(&st, phase, &mut mu) else {
                    break;
                };
                let before = st.obj;
                st = next;
                improved = true;
                // LM hands over to Gauss–Newton once the relative residuals are
                // at 1e-12: a step or two from rounding.
                if phase == Phase::Lm && st.obj <= LM_HANDOVER * LM_HANDOVER {
                    break;
                }
                // Gauss–Newton at the rounding floor: a step that gains less
                // than a factor 2 there is noise, and the next would be too.
                if phase != Phase::Lm && st.obj <= GN_FLOOR && st.obj > 0.5 * before {
                    break;
                }
            }
        }
        if !improved {
            return start;
        }
        fit.points(self, &st)
    }
}

/// The phases of the polish ([`KotterCurve::refine`]): Levenberg–Marquardt,
/// Gauss–Newton relative, Gauss–Newton in the metric of (23).
#[derive(Clone, Copy, PartialEq)]
enum Phase {
    Lm,
    Gn,
    GnL,
}

/// What the polish keeps fixed: the data, the weights, and each point's
/// nearest branch point `d_b` with the differences `d_b − d_j`.
struct Fit<'a> {
    target: &'a [Complex64; 6],
    sc: &'a [Complex64; 3],
    lmap: Option<&'a [[Complex64; 3]; 4]>,
    /// Relative weights of the six components (floored at [`REL_FLOOR`]).
    wt: [f64; 6],
    /// The nearest branch points of the two points.
    b1: usize,
    b2: usize,
    /// `d_b − d_j`: exactly 0 at `j = b`, so `zd_b = w²` exactly.
    dd1: [Complex64; 5],
    dd2: [Complex64; 5],
    /// The scale on which the map varies in `w`: the square root of the
    /// distance from `d_b` to the next branch point.
    ws1: f64,
    ws2: f64,
    d12: Complex64,
}

/// The polish's iterate: `g`, the roots of the two points (the start's
/// branch folded into the first: `P_j = (eps_j r_j(z1)) r_j(z2)`), the six
/// values and the objective of the current phase.
#[derive(Clone, Copy)]
struct FitState {
    g: Complex64,
    r1: [Complex64; 5],
    r2: [Complex64; 5],
    f: [Complex64; 6],
    obj: f64,
}

const ZERO: Complex64 = Complex64::new(0.0, 0.0);

impl<'a> Fit<'a> {
    fn new(
        curve: &KotterCurve,
        start: &WurzelPoints,
        target: &'a [Complex64; 6],
        sc: &'a [Complex64; 3],
        lmap: Option<&'a [[Complex64; 3]; 4]>,
    ) -> Fit<'a> {
        let d = curve.d;
        let nearest = |zd: &[Complex64; 5]| -> usize {
            (0..5).fold(0, |b, j| if zd[j].norm() < zd[b].norm() { j } else { b })
        };
        let (b1, b2) = (nearest(&start.zd1), nearest(&start.zd2));
        let dd1: [Complex64; 5] = std::array::from_fn(|j| d[b1] - d[j]);
        let dd2: [Complex64; 5] = std::array::from_fn(|j| d[b2] - d[j]);
        let wscale = |dd: &[Complex64; 5]| -> f64 {
            dd.iter()
                .filter(|v| v.norm() > 0.0)
                .map(|v| v.norm())
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        };
        // Newton works on relative residuals: (23) maps ξ, η to l with
        // coefficients α_j … δ_j that grow where ξ_j is small (one |d_j| of
        // 1e5 … 1e6 makes a component 100× smaller than the largest), so an
        // absolute fit left that component 1e-12 off relatively and the round
        // trip l → l 3e-12 off. A floor keeps an exactly vanishing one finite.
        let tmax = target.iter().fold(0.0f64, |m, v| m.max(v.norm()));
        Fit {
            target,
            sc,
            lmap,
            wt: std::array::from_fn(|i| 1.0 / target[i].norm().max(REL_FLOOR * tmax)),
            b1,
            b2,
            dd1,
            dd2,
            ws1: wscale(&dd1),
            ws2: wscale(&dd2),
            d12: d[b1] - d[b2],
        }
    }

    /// The iterate at the start (its branch folded into the first point's roots).
    fn start_state(&self, curve: &KotterCurve, start: &WurzelPoints) -> FitState {
        let eps_f = start.eps.map(f64::from);
        let mut r1 = curve.roots_from_offsets(&start.zd1, start.y1);
        for j in 0..5 {
            r1[j] *= eps_f[j];
        }
        let r2 = curve.roots_from_offsets(&start.zd2, start.y2);
        let g = start.g;
        FitState {
            g,
            r1,
            r2,
            f: self.six(&r1, &r2, g),
            obj: f64::INFINITY,
        }
    }

    /// `z1 − z2 = (d_b1 − d_b2) + (w1² − w2²)`.
    fn dz_of(&self, w1: Complex64, w2: Complex64) -> Complex64 {
        self.d12 + (w1 * w1 - w2 * w2)
    }

    /// The six values `g P_kl`, `g P_j4` of the roots `r1`, `r2`.
    fn six(&self, r1: &[Complex64; 5], r2: &[Complex64; 5], g: Complex64) -> [Complex64; 6] {
        let dz = self.dz_of(r1[self.b1], r2[self.b2]);
        // only the six pairs of (37) (all among 1..4; the canonical branch)
        let fq = factor_quotients(r1, r2, dz);
        let pair = |j: usize, k: usize| pair_quotient(r1, r2, dz, &fq, j.min(k), j.max(k));
        let mut f = [ZERO; 6];
        for (i, &(j, k, l)) in CYCLIC.iter().enumerate() {
            f[i] = g * pair(k, l);
            f[i + 3] = g * pair(j, 4);
        }
        f
    }

    /// The rows the polish minimises: a residual (or Jacobian column) in the
    /// P-space of the six targets, mapped to l-space by `lmap` (through
    /// `ξ = √c P`) when `in_l`, else weighted relatively.
    fn rows(&self, v: &[Complex64; 6], in_l: bool) -> [Complex64; 6] {
        match self.lmap {
            Some([al, be, ga, de]) if in_l => std::array::from_fn(|q| {
                let j = q % 3;
                let (x, y) = (self.sc[j] * v[j], self.sc[j] * v[j + 3]);
                if q < 3 {
                    al[j] * x + be[j] * y
                } else {
                    ga[j] * x + de[j] * y
                }
            }),
            _ => std::array::from_fn(|i| v[i] * self.wt[i]),
        }
    }

    /// The max-norm of the rows of the residual.
    fn obj_of(&self, f: &[Complex64; 6], in_l: bool) -> f64 {
        let r: [Complex64; 6] = std::array::from_fn(|i| self.target[i] - f[i]);
        self.rows(&r, in_l)
            .iter()
            .map(|v| v.norm())
            .fold(0.0, nan_max)
    }

    /// The objective of `phase`: the sum of squares of the relative residuals
    /// (LM), else [`Fit::obj_of`].
    fn cost(&self, f: &[Complex64; 6], phase: Phase) -> f64 {
        if phase == Phase::Lm {
            let r: [Complex64; 6] = std::array::from_fn(|i| self.target[i] - f[i]);
            self.rows(&r, false).iter().map(|v| v.norm_sqr()).sum()
        } else {
            self.obj_of(f, phase == Phase::GnL)
        }
    }

    /// One step of `phase` from `st`; `None` ends the phase (a degenerate
    /// point, a non-finite system, or no step that decreases the objective).
    fn iterate(&self, st: &FitState, phase: Phase, mu: &mut f64) -> Option<FitState> {
        if st.g == ZERO || self.dz_of(st.r1[self.b1], st.r2[self.b2]) == ZERO {
            return None;
        }
        let (jac, rhs, colscale) = self.jacobian(st, phase == Phase::GnL)?;
        if phase == Phase::Lm {
            self.lm_step(st, &jac, &rhs, &colscale, mu)
        } else {
            self.gn_step(st, phase, &jac, &rhs, &colscale)
        }
    }

    /// The Jacobian of the rows in `(w1, w2, g)` by central differences, its
    /// columns scaled to unit norm (the scales returned), and the residual's
    /// rows; `None` for a non-finite system.
    #[allow(clippy::type_complexity)]
    fn jacobian(
        &self,
        st: &FitState,
        in_l: bool,
    ) -> Option<(
        nalgebra::SMatrix<Complex64, 6, 3>,
        nalgebra::SVector<Complex64, 6>,
        [f64; 3],
    )> {
        let (r1, r2, g, f) = (&st.r1, &st.r2, st.g, &st.f);
        let (h1, h2) = (1e-7 * self.ws1, 1e-7 * self.ws2);
        let mut jac = nalgebra::SMatrix::<Complex64, 6, 3>::zeros();
        let c = |x: f64| Complex64::new(x, 0.0);
        let fp1 = self.six(&moved(r1, self.b1, &self.dd1, c(h1)), r2, g);
        let fm1 = self.six(&moved(r1, self.b1, &self.dd1, c(-h1)), r2, g);
        let fp2 = self.six(r1, &moved(r2, self.b2, &self.dd2, c(h2)), g);
        let fm2 = self.six(r1, &moved(r2, self.b2, &self.dd2, c(-h2)), g);
        let mut rhs = nalgebra::SVector::<Complex64, 6>::zeros();
        let col0 = self.rows(
            &std::array::from_fn(|i| (fp1[i] - fm1[i]) / (2.0 * h1)),
            in_l,
        );
        let col1 = self.rows(
            &std::array::from_fn(|i| (fp2[i] - fm2[i]) / (2.0 * h2)),
            in_l,
        );
        let col2 = self.rows(&std::array::from_fn(|i| f[i] / g), in_l);
        let res = self.rows(&std::array::from_fn(|i| self.target[i] - f[i]), in_l);
        for i in 0..6 {
            jac[(i, 0)] = col0[i];
            jac[(i, 1)] = col1[i];
            jac[(i, 2)] = col2[i];
            rhs[i] = res[i];
        }
        // nalgebra's SVD never returns on a NaN entry and panics on an
        // infinite one (curves of scale 1e27 and beyond overflow here):
        // only finite systems are solved.
        let finite = |v: &Complex64| v.re.is_finite() && v.im.is_finite();
        if !(jac.iter().all(finite) && rhs.iter().all(finite)) {
            return None;
        }
        // Columns scaled to unit norm: the solve's cut-off 1e-14 is absolute
        // on the singular values, and the columns differ by the curve's
        // scale (|dP/dw| against |P/g|: 1e-20 against 1 at |d| ~ 1e4), so
        // unscaled a whole direction was dropped and the polish stalled.
        let mut colscale = [1.0f64; 3];
        for (cidx, cs) in colscale.iter_mut().enumerate() {
            let nrm = jac.column(cidx).norm();
            if nrm > 0.0 && nrm.is_finite() {
                *cs = nrm;
                for i in 0..6 {
                    jac[(i, cidx)] /= nrm;
                }
            }
        }
        Some((jac, rhs, colscale))
    }

    /// The iterate after the step `lam · step` (in the unit-norm columns).
    fn try_step(
        &self,
        st: &FitState,
        phase: Phase,
        step: &nalgebra::SVector<Complex64, 3>,
        colscale: &[f64; 3],
        lam: f64,
    ) -> FitState {
        let s: [Complex64; 3] = std::array::from_fn(|i| step[i] / colscale[i] * lam);
        let r1 = moved(&st.r1, self.b1, &self.dd1, s[0]);
        let r2 = moved(&st.r2, self.b2, &self.dd2, s[1]);
        let g = st.g + s[2];
        let f = self.six(&r1, &r2, g);
        FitState {
            g,
            r1,
            r2,
            f,
            obj: self.cost(&f, phase),
        }
    }

    /// A Levenberg–Marquardt step: `(JᴴJ + μ I) δ = Jᴴ r` on the unit-norm
    /// columns; `μ` grows until the step decreases the sum of squares, and
    /// shrinks after a success.
    fn lm_step(
        &self,
        st: &FitState,
        jac: &nalgebra::SMatrix<Complex64, 6, 3>,
        rhs: &nalgebra::SVector<Complex64, 6>,
        colscale: &[f64; 3],
        mu: &mut f64,
    ) -> Option<FitState> {
        let jh = jac.adjoint();
        let (a, b) = (jh * jac, jh * rhs);
        for _ in 0..12 {
            let m = a + nalgebra::Matrix3::<Complex64>::identity() * Complex64::new(*mu, 0.0);
            let Some(step) = m.lu().solve(&b) else {
                *mu *= 4.0;
                continue;
            };
            let next = self.try_step(st, Phase::Lm, &step, colscale, 1.0);
            if !next.obj.is_nan() && next.obj < st.obj {
                *mu = (*mu / 3.0).max(1e-15);
                return Some(next);
            }
            *mu *= 4.0;
        }
        None
    }

    /// A Gauss–Newton step (least squares by SVD): the full step, else up to
    /// three halvings of it; none decreasing the objective ends the phase
    /// (converged to rounding, or stuck).
    fn gn_step(
        &self,
        st: &FitState,
        phase: Phase,
        jac: &nalgebra::SMatrix<Complex64, 6, 3>,
        rhs: &nalgebra::SVector<Complex64, 6>,
        colscale: &[f64; 3],
    ) -> Option<FitState> {
        // nalgebra's SVD panics on NaN entries
        if !jac
            .iter()
            .chain(rhs.iter())
            .all(|v| v.re.is_finite() && v.im.is_finite())
        {
            return None;
        }
        let Ok(step) = jac.svd(true, true).solve(rhs, 1e-14) else {
            return None;
        };
        let mut lam = 1.0;
        for _ in 0..4 {
            let next = self.try_step(st, phase, &step, colscale, lam);
            if !next.obj.is_nan() && next.obj < st.obj {
                return Some(next);
            }
            lam *= 0.5;
        }
        None
    }

    /// The polished pair: points, offsets, and the continued roots expressed
    /// as `(y_i, eps)` relative to the canonical roots (`Π_j eps_j = +1`, so
    /// the product of the branch-folded roots is `y1`).
    fn points(&self, curve: &KotterCurve, st: &FitState) -> WurzelPoints {
        let d = curve.d;
        let (r1, r2) = (&st.r1, &st.r2);
        let resid = (0..6)
            .map(|i| ((self.target[i] - st.f[i]) * self.sc[i % 3]).norm())
            .fold(0.0, nan_max);
        let (w1, w2) = (r1[self.b1], r2[self.b2]);
        let zd1: [Complex64; 5] = std::array::from_fn(|j| w1 * w1 + self.dd1[j]);
        let zd2: [Complex64; 5] = std::array::from_fn(|j| w2 * w2 + self.dd2[j]);
        let (z1, z2) = (d[self.b1] + w1 * w1, d[self.b2] + w2 * w2);
        let y1: Complex64 = r1.iter().product();
        let y2: Complex64 = r2.iter().product();
        let c1 = curve.roots_from_offsets(&zd1, y1);
        let c2 = curve.roots_from_offsets(&zd2, y2);
        WurzelPoints {
            z1,
            y1,
            z2,
            y2,
            g: st.g,
            eps: branch_of(r1, r2, &c1, &c2),
            residual: resid,
            zd1,
            zd2,
        }
    }
}

/// Moves a point's parameter `w = r[b]` to `w + dw`: `r_b = w + dw`, the other
/// roots continued along `t = w² → (w + dw)²`.
fn moved(r: &[Complex64; 5], b: usize, dd: &[Complex64; 5], dw: Complex64) -> [Complex64; 5] {
    let w = r[b];
    let dt = (2.0 * w + dw) * dw;
    let t = w * w;
    std::array::from_fn(|j| {
        if j == b {
            w + dw
        } else {
            r[j] * sqrt_principal(1.0 + dt / (t + dd[j]))
        }
    })
}

/// The branch `eps` (`eps_4 = +1`, `Π eps_j = +1`) of the continued roots
/// `r1`, `r2` relative to the canonical roots `c1`, `c2`.
fn branch_of(
    r1: &[Complex64; 5],
    r2: &[Complex64; 5],
    c1: &[Complex64; 5],
    c2: &[Complex64; 5],
) -> [i8; 5] {
    // The sign of each continued root relative to the canonical one (a
    // root at a branch point is 0 on both: its sign is immaterial).
    let sign = |r: Complex64, c: Complex64| -> i8 {
        if c == ZERO || (r / c).re >= 0.0 {
            1
        } else {
            -1
        }
    };
    let mut eps: [i8; 5] = std::array::from_fn(|j| sign(r1[j], c1[j]) * sign(r2[j], c2[j]));
    if eps.iter().map(|&e| i32::from(e)).product::<i32>() < 0 {
        // Only possible with a root exactly 0: flip the sign of the P_j
        // nearest zero, the one the data determine least.
        let j = (0..5).fold(0, |m, j| {
            if (c1[j] * c2[j]).norm() < (c1[m] * c2[m]).norm() {
                j
            } else {
                m
            }
        });
        eps[j] = -eps[j];
    }
    if eps[4] < 0 {
        eps = eps.map(|e| -e);
        eps[0] = -eps[0];
    }
    eps
}

/// `max` that propagates NaN (`f64::max` drops it), so that a NaN anywhere in
/// a residual makes the residual NaN and the check fail.
pub(super) fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
