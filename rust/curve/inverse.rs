//! The inverse map of (37): from Kötter's `(ξ, η)` back to the pair of
//! points, `g` and the branch. The closed forms (30a), (30b) give a start;
//! the branch of the sheets and of the `P_j` is searched among the 32
//! candidates; the polish ([`super::polish`]) takes the pair to rounding.

use super::polish::nan_max;
use super::wurzel::wurzel_from_roots;
use super::*;

/// Default relative tolerance of the consistency check in
/// [`KotterCurve::points_from_xi_eta`]: the reconstructed points must
/// reproduce the given `(ξ, η)` to `rtol · max|(ξ, η)|`. Exact data (from
/// [`KotterCurve::xi_eta`]) come back to ~1e-14; 1e-8 leaves room for `(ξ, η)`
/// computed elsewhere while rejecting data off Kötter's quadrics (11).
pub const INVERSE_RTOL: f64 = 1e-8;

/// `|z1 − z2|` (relative to `max(|z1|, |z2|)`, not to 1: the curve has no
/// preferred scale) below which the inverse reports
/// the double root `z1 == z2` instead of a pair: a discriminant `(z1 − z2)²`
/// that is zero in exact arithmetic comes out ~1e-16 after rounding, i.e.
/// `|z1 − z2|` ~1e-8, and the error of the recovered pair grows like
/// `u/|z1 − z2|²`, reaching O(1e-4) relative at 1e-6: below that the two
/// points are not resolved.
const NEAR_DOUBLE_ROOT: f64 = 1e-6;

/// A start for the inverse map of (37) ([`KotterCurve::points_from_xi_eta_fit`]):
/// the abscissas, their offsets `z_i − d_j` from this curve's branch points and
/// `g²`, in the units of the data (not scaled).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InverseStart {
    pub z: [Complex64; 2],
    pub zd: [[Complex64; 5]; 2],
    pub g2: Complex64,
}

impl KotterCurve {
    /// The inverse of (37): from `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`
    /// (`j = 1, 2, 3`, `(j, k, l)` cyclic) recover `g`, the points
    /// `(z1, y1)`, `(z2, y2)` and the branch `eps` of the `P_j`.
    ///
    /// With `X_j = ξ_j/√c_j = g P_kl`, `Y_j = η_j/√c_j = g P_j4`:
    ///
    /// * `g² = Σ_j c̃_j Y_j² / d_4` by (30a) `Σ c̃_j P_j4² = d_4`;
    /// * `z1 + z2 = d_4 + Σ_j c̃_j X_j² / g²` and `z1 z2 = Σ_j c̃_j d_j X_j² / g²`
    ///   (the second is (30b) with `P_0² = z1 z2`), so `z1`, `z2` are the roots
    ///   of `U(x) = x² − (z1 + z2) x + z1 z2`;
    /// * `y_i = ±y(z_i)`, and the signs together with `eps` are the choice
    ///   (among the 32 candidates, `eps_4 = +1`) that reproduces `(X, Y)`.
    ///
    /// `g` is determined only up to sign: `(g, y1, y2)` and `(−g, −y1, −y2)`
    /// give the same `(ξ, η)` (the hyperelliptic involution flips every
    /// `P_jk`). The sign of `g` is the one nearer `g_ref` if given, otherwise
    /// that of `sqrt_principal(g²)`; the `y_i` follow.
    ///
    /// Errors: non-finite input; `g² = 0`; `z1 = z2` (a double root of `U`,
    /// where (28) is undefined); data that the reconstruction does not
    /// reproduce to `rtol · max|(ξ, η)|` (not on Kötter's quadrics (11), or a
    /// `sqrt_c` branch inconsistent with the data).
    pub fn points_from_xi_eta(
        &self,
        xi: [Complex64; 3],
        eta: [Complex64; 3],
        sqrt_c: Option<[Complex64; 3]>,
        g_ref: Option<Complex64>,
        rtol: f64,
    ) -> Result<WurzelPoints> {
        self.points_from_xi_eta_fit(xi, eta, sqrt_c, g_ref, rtol, None)
    }

    /// [`KotterCurve::points_from_xi_eta`] with the polish fitting
    /// `(ξ, η)` in the norm of a downstream linear map: `lmap = [α, β, γ, δ]`
    /// weighs the residuals `r_ξj, r_ηj` as `α_j r_ξj + β_j r_ηj` and
    /// `γ_j r_ξj + δ_j r_ηj` ((23): the error the points cause in `m_j, n_j`).
    /// Without it each component is fitted relative to its own size.
    ///
    /// Data computed in floating point lie off the quadrics (11) by a few
    /// ulps of their largest terms; the polish has to move some component by
    /// that much, and `lmap` makes it move the ones `l` is least sensitive to.
    pub fn points_from_xi_eta_fit(
        &self,
        xi: [Complex64; 3],
        eta: [Complex64; 3],
        sqrt_c: Option<[Complex64; 3]>,
        g_ref: Option<Complex64>,
        rtol: f64,
        lmap: Option<&[[Complex64; 3]; 4]>,
    ) -> Result<WurzelPoints> {
        self.points_from_xi_eta_start(xi, eta, sqrt_c, g_ref, rtol, lmap, None)
    }

    /// [`KotterCurve::points_from_xi_eta_fit`] from a given start instead of
    /// the closed form (30) (the polish, the branch search and the checks are
    /// the same). The reduction passes the closed form evaluated in
    /// double-double on its unrounded curve: near the singular set
    /// `h1² = 4h0²` the double-precision closed form cancels by `|d_4|/|z|`
    /// (1e13 and more) and puts a point thousands of units off, across a pair of
    /// branch points a few units apart (docs/kotter.md, "Near the singular set").
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn points_from_xi_eta_start(
        &self,
        xi: [Complex64; 3],
        eta: [Complex64; 3],
        sqrt_c: Option<[Complex64; 3]>,
        g_ref: Option<Complex64>,
        rtol: f64,
        lmap: Option<&[[Complex64; 3]; 4]>,
        start: Option<&InverseStart>,
    ) -> Result<WurzelPoints> {
        check_finite_c("xi", &xi)?;
        check_finite_c("eta", &eta)?;
        if let Some(gr) = g_ref {
            check_finite_c("g_ref", &[gr])?;
        }
        if !rtol.is_finite() || rtol <= 0.0 {
            return Err(Error::InvalidArgument {
                what: "rtol",
                reason: format!("must be finite and positive, got {rtol}"),
            });
        }
        let sc = self.sqrt_c_checked(sqrt_c)?;
        // (37) is homogeneous in g: solve for the data scaled to max|·| = 1
        // (so that g² neither overflows nor underflows) and scale g back.
        let scale = xi
            .iter()
            .chain(eta.iter())
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        let x: [Complex64; 3] = std::array::from_fn(|i| xi[i] / scale / sc[i]);
        let yv: [Complex64; 3] = std::array::from_fn(|i| eta[i] / scale / sc[i]);
        let (g2, (z1, z2), (zd1, zd2)) = self.closed_form_start(&x, &yv, scale, start)?;
        let mut g = sqrt_principal(g2);
        if let Some(gr) = g_ref {
            if (gr.conj() * g).re < 0.0 {
                g = -g;
            }
        }
        let target: [Complex64; 6] = [x[0], x[1], x[2], yv[0], yv[1], yv[2]];
        let start = ((z1, zd1), (z2, zd2));
        let mut best: Option<WurzelPoints> = None;
        self.for_each_branch(&target, &sc, g, start, |c| {
            // the first candidate is the canonical sheets with eps = +1
            let cur = best.get_or_insert(WurzelPoints {
                residual: f64::INFINITY,
                ..c
            });
            if c.residual < cur.residual {
                *cur = c;
            }
        });
        let best = best.expect("32 candidates");
        let mut b = self.refine(best, &target, &sc, lmap);
        if b.residual.is_nan() || b.residual > rtol {
            // Where the start is off by more than the smallest components
            // (a point near one of two close branch points of a curve that
            // spans 1e15 and more), several branches reproduce the large
            // components equally well and the nearest need not be the one
            // the polish can reach: the others are polished in turn, nearest
            // first.
            let mut order: Vec<WurzelPoints> = Vec::with_capacity(32);
            self.for_each_branch(&target, &sc, g, start, |c| order.push(c));
            order.sort_by(|p, q| p.residual.total_cmp(&q.residual));
            for c in order.into_iter().filter(|c| *c != best) {
                let next = self.refine(c, &target, &sc, lmap);
                if next.residual < b.residual || b.residual.is_nan() {
                    b = next;
                }
                if b.residual <= rtol {
                    break;
                }
            }
        }
        b.g *= scale;
        b.residual *= scale;
        // A polish from a far start may end on the involution image of the
        // start's sheet, (−g, −y1, −y2), which has the same (ξ, η): the
        // documented sign of g (nearer g_ref) is restored.
        if let Some(gr) = g_ref {
            if (gr.conj() * b.g).re < 0.0 {
                b.g = -b.g;
                b.y1 = -b.y1;
                b.y2 = -b.y2;
            }
        }
        accept_points(b, rtol, scale)
    }

    /// `g²` (30a) and the points from the closed forms (30b) — or from
    /// `start` — for the scaled data `X_j = ξ_j/√c_j`, `Y_j = η_j/√c_j`.
    ///
    /// Errors: `g² = 0` or not finite (no point pair has these data).
    #[allow(clippy::type_complexity)]
    fn closed_form_start(
        &self,
        x: &[Complex64; 3],
        yv: &[Complex64; 3],
        scale: f64,
        start: Option<&InverseStart>,
    ) -> Result<(
        Complex64,
        (Complex64, Complex64),
        ([Complex64; 5], [Complex64; 5]),
    )> {
        let ct = self.c_tilde();
        let d = &self.d;
        let g2 = match start {
            Some(s) => s.g2 / (scale * scale),
            None => (0..3).map(|i| ct[i] * yv[i] * yv[i]).sum::<Complex64>() / d[4],
        };
        if scale == 0.0
            || g2 == Complex64::new(0.0, 0.0)
            || !(g2.re.is_finite() && g2.im.is_finite())
        {
            return Err(Error::InvalidArgument {
                what: "xi, eta",
                reason: "g^2 = sum_j c~_j (eta_j/sqrt c_j)^2 / d_4 vanishes (30a): \
                         no point pair has these Wurzelfunktionen"
                    .into(),
            });
        }
        let sum1 = (0..3).map(|i| ct[i] * x[i] * x[i]).sum::<Complex64>() / g2 + d[4];
        let sum2 = CYCLIC
            .iter()
            .enumerate()
            .map(|(i, &(j, _, _))| ct[i] * d[j] * x[i] * x[i])
            .sum::<Complex64>()
            / g2;
        let (z, zd) = match start {
            Some(s) => ((s.z[0], s.z[1]), (s.zd[0], s.zd[1])),
            None => {
                let (z1, z2) = quadratic_roots(sum1, sum2)?;
                ((z1, z2), (self.offsets(z1), self.offsets(z2)))
            }
        };
        Ok((g2, z, zd))
    }

    /// Each of the 32 sheets and branches (`y_i = ±` the canonical sheet, the 8
    /// admissible `eps` with `eps_4 = +1`) at the start, with the distance of
    /// its `g P_kl`, `g P_j4` from the scaled data `target`, handed to `each`
    /// in a fixed order (the canonical sheets with `eps = +1` first).
    fn for_each_branch(
        &self,
        target: &[Complex64; 6],
        sc: &[Complex64; 3],
        g: Complex64,
        ((z1, zd1), (z2, zd2)): ((Complex64, [Complex64; 5]), (Complex64, [Complex64; 5])),
        mut each: impl FnMut(WurzelPoints),
    ) {
        let canonical_y = |zd: &[Complex64; 5]| {
            zd.iter()
                .fold(Complex64::new(1.0, 0.0), |acc, &v| acc * sqrt_principal(v))
        };
        let yc1 = canonical_y(&zd1);
        let yc2 = canonical_y(&zd2);
        for s1 in [1.0, -1.0] {
            for s2 in [1.0, -1.0] {
                let (y1, y2) = (yc1 * s1, yc2 * s2);
                let r1 = self.roots_from_offsets(&zd1, y1);
                let r2 = self.roots_from_offsets(&zd2, y2);
                let w = wurzel_from_roots(&r1, &r2, z1 - z2, &[1.0; 5]);
                for bits in 0..8u8 {
                    let e = |b: u8| if bits & (1 << b) == 0 { 1.0 } else { -1.0 };
                    let eps = [e(0) * e(1) * e(2), e(0), e(1), e(2), 1.0];
                    let mut resid = 0.0f64;
                    for (i, &(j, k, l)) in CYCLIC.iter().enumerate() {
                        let pkl = g * eps[k] * eps[l] * w.pjk[k][l];
                        let pj4 = g * eps[j] * w.pjk[j][4];
                        resid = nan_max(resid, ((target[i] - pkl) * sc[i]).norm());
                        resid = nan_max(resid, ((target[i + 3] - pj4) * sc[i]).norm());
                    }
                    each(WurzelPoints {
                        z1,
                        y1,
                        z2,
                        y2,
                        g,
                        eps: eps.map(|v| v as i8),
                        residual: resid,
                        zd1,
                        zd2,
                    });
                }
            }
        }
    }
}

/// The polished pair if it reproduces the data to `rtol · scale` and its
/// points are resolved.
fn accept_points(b: WurzelPoints, rtol: f64, scale: f64) -> Result<WurzelPoints> {
    if (b.z1 - b.z2).norm() <= NEAR_DOUBLE_ROOT * b.z1.norm().max(b.z2.norm()) {
        // A discriminant that vanishes in exact arithmetic is ~1e-16 after
        // rounding, so z1 - z2 ~ 1e-8: the data sit at z1 == z2, and no
        // pair closer than NEAR_DOUBLE_ROOT can be resolved from them.
        Err(Error::InvalidArgument {
            what: "xi, eta",
            reason: format!(
                "they give (nearly) z1 == z2 (|z1 - z2| = {:e} at z = {}): P_jk (28) is \
                 singular there and the two points cannot be resolved",
                (b.z1 - b.z2).norm(),
                b.z1,
            ),
        })
    } else if b.residual <= rtol * scale {
        Ok(b)
    } else {
        Err(Error::InvalidArgument {
            what: "xi, eta",
            reason: format!(
                "no pair of points reproduces them: best residual {:e} > rtol {rtol:e} * \
                 max|(xi, eta)| {scale:e}; (xi, eta) are not on Koetter's quadrics (11) \
                 of this curve, or sqrt_c has another branch",
                b.residual
            ),
        })
    }
}

/// The roots of `x² − s x + p`, the one of larger modulus first, computed
/// without cancellation (`z1 = (s ± √(s² − 4p))/2` with the sign that adds
/// moduli, `z2 = p/z1`).
fn quadratic_roots(s: Complex64, p: Complex64) -> Result<(Complex64, Complex64)> {
    let sq = sqrt_principal(s * s - 4.0 * p);
    let q = if (s.conj() * sq).re >= 0.0 {
        s + sq
    } else {
        s - sq
    };
    let z1 = q / 2.0;
    // A double root: the two points have the same z (|q| ≥ |sq| makes q = 0 imply sq = 0).
    if sq.norm() <= 4.0 * f64::EPSILON * z1.norm() || z1 == Complex64::new(0.0, 0.0) {
        return Err(Error::InvalidArgument {
            what: "xi, eta",
            reason: format!(
                "they give z1 == z2 == {z1} (a double root of x^2 - (z1+z2) x + z1 z2): \
                 P_jk (28) is undefined there"
            ),
        });
    }
    Ok((z1, p / z1))
}
