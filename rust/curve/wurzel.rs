//! The Wurzelfunktionen (27)–(28) of a pair of points, on a given branch,
//! and `ξ, η` from them by (37): `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`.

use super::*;

impl KotterCurve {
    /// [`KotterCurve::wurzel`] for points given with their offsets
    /// ([`CurvePoint`]): the roots `√(z_i − d_j)` are taken from the offsets,
    /// so points close to branch points keep full accuracy.
    ///
    /// Errors: as [`KotterCurve::wurzel`], and offsets inconsistent with `z`.
    pub fn wurzel_points(
        &self,
        p1: &CurvePoint,
        p2: &CurvePoint,
        eps: Option<[i8; 5]>,
    ) -> Result<Wurzel> {
        self.check_curve_point("point (z1, y1, zd1)", p1)?;
        self.check_curve_point("point (z2, y2, zd2)", p2)?;
        self.wurzel_unchecked(p1, p2, eps)
    }

    fn wurzel_unchecked(
        &self,
        p1: &CurvePoint,
        p2: &CurvePoint,
        eps: Option<[i8; 5]>,
    ) -> Result<Wurzel> {
        let (z1, z2) = (p1.z, p2.z);
        let eps = match eps {
            None => [1.0; 5],
            Some(e) => check_eps(e)?,
        };
        let r1 = self.roots_from_offsets(&p1.zd, p1.y);
        let r2 = self.roots_from_offsets(&p2.zd, p2.y);
        // z1 == z2: the telescoped (28) is the tangent limit when the two points
        // are the same point of the curve (same roots, none zero); with
        // y1 = -y2 it is a pole, at a branch point 0/0.
        if z1 == z2 && (r1 != r2 || r1.iter().any(|&v| v == Complex64::new(0.0, 0.0))) {
            return Err(Error::InvalidArgument {
                what: "points (z1, z2)",
                reason: format!(
                    "z1 == z2 == {z1} on different sheets or at a branch point: P_jk (28) \
                     divides by z1 - z2 (a pole, or 0/0 at a branch point); the same point \
                     twice (y1 == y2) is its tangent limit"
                ),
            });
        }
        Ok(wurzel_from_roots(&r1, &r2, z1 - z2, &eps))
    }

    /// [`KotterCurve::xi_eta`] for points given with their offsets
    /// ([`CurvePoint`], [`KotterCurve::wurzel_points`]).
    pub fn xi_eta_points(
        &self,
        p1: &CurvePoint,
        p2: &CurvePoint,
        g: Complex64,
        eps: Option<[i8; 5]>,
        sqrt_c: Option<[Complex64; 3]>,
    ) -> Result<([Complex64; 3], [Complex64; 3])> {
        check_finite_c("g", &[g])?;
        let sc = self.sqrt_c_checked(sqrt_c)?;
        let w = self.wurzel_points(p1, p2, eps)?;
        Ok(xi_eta_of(&w, &sc, g))
    }

    /// The Wurzelfunktionen (27)–(28) of the points `(z1, y1)`, `(z2, y2)` in
    /// the branch `eps` (`None` = all `+1`; see the module docs):
    /// `P_j = eps_j √((z1 − d_j)(z2 − d_j))` with `Π P_j = y1 y2`, and
    /// `P_jk = P_j P_k/(z1 − z2) · (√R(z1)/((z1 − d_j)(z1 − d_k)) − √R(z2)/((z2 − d_j)(z2 − d_k)))`
    /// with `√R(z_i) = y_i`, evaluated in the division-free product form.
    ///
    /// Errors: non-finite input, a point off the curve, `z1 == z2` ((28)
    /// divides by `z1 − z2`), `eps` not in `{±1}⁵` with product `+1`.
    pub fn wurzel(
        &self,
        z1: Complex64,
        y1: Complex64,
        z2: Complex64,
        y2: Complex64,
        eps: Option<[i8; 5]>,
    ) -> Result<Wurzel> {
        self.check_point("point (z1, y1)", z1, y1)?;
        self.check_point("point (z2, y2)", z2, y2)?;
        self.wurzel_unchecked(&self.point(z1, y1), &self.point(z2, y2), eps)
    }

    /// Kötter's vectors (37): `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`,
    /// `(j, k, l)` cyclic, from the points, `g` and the branch `eps`.
    /// `sqrt_c = None` takes `√c_j = sqrt_principal(c_j)`.
    #[allow(clippy::too_many_arguments)]
    pub fn xi_eta(
        &self,
        z1: Complex64,
        y1: Complex64,
        z2: Complex64,
        y2: Complex64,
        g: Complex64,
        eps: Option<[i8; 5]>,
        sqrt_c: Option<[Complex64; 3]>,
    ) -> Result<([Complex64; 3], [Complex64; 3])> {
        check_finite_c("g", &[g])?;
        let sc = self.sqrt_c_checked(sqrt_c)?;
        let w = self.wurzel(z1, y1, z2, y2, eps)?;
        Ok(xi_eta_of(&w, &sc, g))
    }

    pub(super) fn sqrt_c_checked(&self, sqrt_c: Option<[Complex64; 3]>) -> Result<[Complex64; 3]> {
        let c = self.c();
        match sqrt_c {
            None => Ok(c.map(sqrt_principal)),
            Some(sc) => {
                check_finite_c("sqrt_c", &sc)?;
                for i in 0..3 {
                    let err = (sc[i] * sc[i] - c[i]).norm();
                    if err.is_nan() || err > ON_CURVE_RTOL * c[i].norm() {
                        return Err(Error::InvalidArgument {
                            what: "sqrt_c",
                            reason: format!(
                                "sqrt_c[{i}]^2 = {} differs from c_{} = {} (33)",
                                sc[i] * sc[i],
                                i + 1,
                                c[i]
                            ),
                        });
                    }
                }
                Ok(sc)
            }
        }
    }
}

/// (37) from the Wurzelfunktionen: `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`.
fn xi_eta_of(w: &Wurzel, sc: &[Complex64; 3], g: Complex64) -> ([Complex64; 3], [Complex64; 3]) {
    let mut xi = [Complex64::new(0.0, 0.0); 3];
    let mut eta = xi;
    for (i, &(j, k, l)) in CYCLIC.iter().enumerate() {
        xi[i] = sc[i] * g * w.pjk[k][l];
        eta[i] = sc[i] * g * w.pjk[j][4];
    }
    (xi, eta)
}

/// Checks a branch vector: entries `±1`, product `+1`.
fn check_eps(e: [i8; 5]) -> Result<[f64; 5]> {
    if e.iter().any(|&v| v != 1 && v != -1) {
        return Err(Error::InvalidArgument {
            what: "eps",
            reason: format!("entries must be +1 or -1, got {e:?}"),
        });
    }
    if e.iter().map(|&v| v as i32).product::<i32>() != 1 {
        return Err(Error::InvalidArgument {
            what: "eps",
            reason: format!(
                "the product of the signs must be +1 (so that P_0 ... P_4 = y1 y2), got {e:?}"
            ),
        });
    }
    Ok(e.map(f64::from))
}

/// `(A − B)/(z1 − z2)` for one factor of (28), `A − B = ±(r1 − r2)` with
/// `r_i² = z_i − d_j`: telescoped, `(r1 − r2)/(z1 − z2) = 1/(r1 + r2)`, when
/// the two roots lie on the same side (`|r1 + r2| ≥ |r1 − r2|`: no
/// cancellation, and finite at `z1 = z2`); the plain quotient otherwise
/// (then `r1 − r2` does not cancel).
fn factor_quotient(r1: Complex64, r2: Complex64, dz: Complex64) -> Complex64 {
    let sum = r1 + r2;
    // |r1 + r2| ≥ |r1 − r2| ⇔ Re(r1 conj r2) ≥ 0 (no modulus: libm's hypot was
    // the largest cost of the inverse map)
    if (r1 * r2.conj()).re >= 0.0 && sum != Complex64::new(0.0, 0.0) {
        cdiv(Complex64::new(1.0, 0.0), sum)
    } else {
        cdiv(r1 - r2, dz)
    }
}

/// (27)–(28) from the canonical roots of the two points, in the branch `eps`.
///
/// `P_jk = eps_j eps_k (a − b)/(z1 − z2)` with `a = Π_i A_i`, `b = Π_i B_i`,
/// `A = (r_j(z2), r_k(z2), r_m(z1) …)`, `B = (r_j(z1), r_k(z1), r_m(z2) …)`
/// (`m ∉ {j, k}`), is evaluated as the telescoped sum
/// `Σ_i A_1 … A_{i−1} · (A_i − B_i)/(z1 − z2) · B_{i+1} … B_5`, each quotient
/// by [`factor_quotient`]: for two points on one sheet with `z1 ≈ z2` the
/// difference `a − b` loses `u/|z1 − z2|`, the telescoped form does not, and
/// at `z1 = z2` (same `y`) it is the tangent limit (`dz` is not used then).
pub(super) fn wurzel_from_roots(
    r1: &[Complex64; 5],
    r2: &[Complex64; 5],
    dz: Complex64,
    eps: &[f64; 5],
) -> Wurzel {
    let zero = Complex64::new(0.0, 0.0);
    let p: [Complex64; 5] = std::array::from_fn(|j| eps[j] * r1[j] * r2[j]);
    let fq = factor_quotients(r1, r2, dz);
    let mut pjk = [[zero; 5]; 5];
    for j in 0..5 {
        for k in (j + 1)..5 {
            let v = eps[j] * eps[k] * pair_quotient(r1, r2, dz, &fq, j, k);
            pjk[j][k] = v;
            pjk[k][j] = v;
        }
    }
    Wurzel { p, pjk }
}

/// The quotients [`factor_quotient`] of the five factors (each pair's
/// telescoped sum uses all five).
#[inline]
pub(super) fn factor_quotients(
    r1: &[Complex64; 5],
    r2: &[Complex64; 5],
    dz: Complex64,
) -> [Complex64; 5] {
    std::array::from_fn(|m| factor_quotient(r1[m], r2[m], dz))
}

/// `(a − b)/(z1 − z2)` of (28) for the pair `j < k`, in the canonical branch
/// (see [`wurzel_from_roots`]; `fq` from [`factor_quotients`]).
pub(super) fn pair_quotient(
    r1: &[Complex64; 5],
    r2: &[Complex64; 5],
    dz: Complex64,
    fq: &[Complex64; 5],
    j: usize,
    k: usize,
) -> Complex64 {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    // factors in the order j, k, then the complement
    let mut idx = [j, k, 0, 0, 0];
    for (n, m) in (2..).zip((0..5).filter(|&m| m != j && m != k)) {
        idx[n] = m;
    }
    let fa: [Complex64; 5] = std::array::from_fn(|i| if i < 2 { r2[idx[i]] } else { r1[idx[i]] });
    let fb: [Complex64; 5] = std::array::from_fn(|i| if i < 2 { r1[idx[i]] } else { r2[idx[i]] });
    // (A_i − B_i)/(z1 − z2): for i < 2, A − B = r2 − r1 = −(r1 − r2)
    let q: [Complex64; 5] = std::array::from_fn(|i| {
        let v = fq[idx[i]];
        if i < 2 {
            -v
        } else {
            v
        }
    });
    let mut suffix = [one; 6];
    for i in (0..5).rev() {
        suffix[i] = suffix[i + 1] * fb[i];
    }
    let mut prefix = one;
    let mut sum = zero;
    let mut size_t = 0.0;
    for i in 0..5 {
        let term = prefix * q[i] * suffix[i + 1];
        sum += term;
        size_t += term.re.abs() + term.im.abs();
        prefix *= fa[i];
    }
    // The plain difference (a − b)/(z1 − z2) rounds to u (|a| + |b|)/|z1 − z2|,
    // the telescoped sum to u Σ|terms|: take the one with the smaller bound
    // (far-apart points: the plain form, whose terms do not cancel).
    let (a, b) = (prefix, suffix[0]);
    // both bounds from above without a modulus (1-norm over ∞-norm, each
    // within √2 of the modulus): hypot was the largest cost here
    let l1 = |z: Complex64| z.re.abs() + z.im.abs();
    let size_p = (l1(a) + l1(b)) / dz.re.abs().max(dz.im.abs());
    if dz != zero && size_p.is_finite() && size_p < size_t {
        cdiv(a - b, dz)
    } else {
        sum
    }
}
