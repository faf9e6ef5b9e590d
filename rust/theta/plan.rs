//! Building a [`ThetaPlan`]: validation of `τ`, the exact reduction of
//! `Re τ` modulo 2, the `LDLᵀ` factorisation of `Im τ`, the radius of the
//! summation ellipsoid from the proven tail bound ([`super::tail_bound`]) and
//! the cost model that refuses sums too large to run.

use super::linalg::{invert_spd, ldl_reversed, min_eigenvalue, shortest_vector_reduced};
use super::{pi, tail_bound, PlanInfo, ThetaPlan, Workspace, MAX_GENUS, MAX_SECONDS_PER_POINT};
use super::{MAX_TERMS, SYMMETRY_RTOL};
use crate::error::{check_finite, Error, Result};
use num_complex::Complex64;

/// Cost model of one point, in nanoseconds: `terms · TERM + rows · ROW`, times
/// `1 + order` on the generic path. Fitted on this crate's own timings
/// (genus 2–6, random and anisotropic `Im τ`, 1e4–2e8 terms, release build,
/// one core): the genus-2 walk costs 3–6 ns a term whatever the order; the
/// generic path 8–60 ns a term (up to 240 ns when rows are short) and
/// 250–1300 ns per inner row (two exponentials and the class bookkeeping).
/// The generic constants are upper quartiles, so the estimate errs high (by up
/// to ~2×) rather than low.
const COST_G2_TERM_NS: f64 = 5.0;
const COST_G2_ROW_NS: f64 = 40.0;
const COST_TERM_NS: f64 = 15.0;
const COST_ROW_NS: f64 = 500.0;

/// Above this diagonal entry of `Im τ` the genus-2 walk would multiply by
/// `exp(π Im τ_kk / 2) > e^{78}`; the generic path (upward sweeps only) is used.
const FAST_PATH_MAX_IMAG_DIAG: f64 = 50.0;

impl ThetaPlan {
    /// Validates `tau` (row-major `g×g`, `1 ≤ g ≤` [`MAX_GENUS`]) and prepares the sums
    /// for truncation error `tol` (absolute, on the normalised values and their
    /// z-derivatives up to `order ≤ 2`).
    ///
    /// Errors: non-finite entries, wrong size, asymmetry above [`SYMMETRY_RTOL`]
    /// ([`Error::NotSymmetric`]), `Im τ` not positive definite
    /// ([`Error::ImagNotPositiveDefinite`] with its smallest eigenvalue), `tol`
    /// outside (0, 1), `order > 2`, or more than [`MAX_TERMS`] terms.
    pub fn new(tau: &[Complex64], g: usize, tol: f64, order: usize) -> Result<Self> {
        check_arguments(tau, g, tol, order)?;
        check_symmetric(tau, g)?;
        let sym = symmetrised(tau, g);
        let y: Vec<f64> = sym.iter().map(|c| c.im).collect();
        let (ldl_d, ldl_l) = factor_imag(&y, g)?;
        let yinv = invert_spd(&ldl_d, &ldl_l, g);
        let (s, taur) = reduce_real_part(&sym, g);
        let x: Vec<f64> = taur.iter().map(|c| c.re).collect();
        let re_tau: Vec<f64> = sym.iter().map(|c| c.re).collect();
        // On an LLL-reduced basis: the enumeration on Im tau as given visits
        // ~Y_ii^{g/2}/sqrt(det Y) points, 1e12-1e18 for an ill-conditioned Im tau
        // (minutes, before the cost check below could refuse it).
        let rho = pi().sqrt() * shortest_vector_reduced(&y, &ldl_d, &ldl_l, g).sqrt();
        // |m_k - c_k| ≤ sqrt((Y^{-1})_kk / π) |x| (Cauchy–Schwarz in the Y metric).
        let sk = (0..g)
            .map(|k| (yinv[k * g + k] / pi()).sqrt())
            .fold(0.0, f64::max);
        let (radius, rho_used, rq, rq_values) = summation_radius(g, rho, sk, order, tol);
        let qmat: Vec<Complex64> = taur
            .iter()
            .map(|t| (Complex64::i() * pi() * 0.5 * t).exp())
            .collect();
        let qinv: Vec<Complex64> = taur
            .iter()
            .map(|t| (-Complex64::i() * pi() * 0.5 * t).exp())
            .collect();
        let fast_g2 = g == 2 && y[0].max(y[3]) <= FAST_PATH_MAX_IMAG_DIAG;
        let plan = ThetaPlan {
            g,
            order,
            tau: taur,
            re_tau,
            x,
            y,
            yinv,
            ldl_d,
            ldl_l,
            rq,
            rq_values,
            radius,
            rho,
            rho_used,
            class_of: class_table(g),
            unit_pow: unit_powers(&s, g),
            qmat,
            qinv,
            fast_g2,
            batch2: std::sync::OnceLock::new(),
            parallel: true,
        };
        plan.check_cost()?;
        Ok(plan)
    }

    /// Refuses a plan whose sums exceed [`MAX_TERMS`] or
    /// [`MAX_SECONDS_PER_POINT`] by the cost model.
    fn check_cost(&self) -> Result<()> {
        let info = self.info();
        let expected = info.expected_terms;
        let cost = info.seconds_per_point;
        if expected > MAX_TERMS || cost.is_nan() || cost > MAX_SECONDS_PER_POINT {
            return Err(Error::InvalidArgument {
                what: "tau",
                reason: format!(
                    "Im tau is too ill-conditioned for genus {}: about {expected:.2e} terms \
                     and {:.2e} rows needed per point, estimated {:.2} s each (budget \
                     {MAX_TERMS:.0e} terms, {MAX_SECONDS_PER_POINT} s; det Im tau = {:.3e}); \
                     reduce tau first",
                    self.g,
                    info.expected_rows,
                    info.seconds_per_point,
                    self.ldl_d.iter().product::<f64>()
                ),
            });
        }
        Ok(())
    }

    /// Whether batches of at least 4096 points are split over rayon's thread pool
    /// (default `true`; the pool size follows `RAYON_NUM_THREADS`). Results do not
    /// depend on it: every point is computed by the same code either way.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// Genus.
    pub fn genus(&self) -> usize {
        self.g
    }

    /// Derivative order the plan was built for.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Whether the plan was built for `tau` (row-major, `g × g`): its
    /// symmetrised real and imaginary parts are the plan's, to the bit.
    pub fn is_for(&self, tau: &[Complex64]) -> bool {
        tau.len() == self.g * self.g && {
            let sym = symmetrised(tau, self.g);
            sym.iter()
                .zip(self.re_tau.iter().zip(&self.y))
                .all(|(z, (re, im))| z.re == *re && z.im == *im)
        }
    }

    /// Radius, shortest vector, proven truncation bound and expected term count.
    pub fn info(&self) -> PlanInfo {
        let g = self.g;
        let det: f64 = self.ldl_d.iter().product();
        // vol{u : Q(u) < rq} = V_g rq^{g/2} / sqrt(det Y); 2^g half-lattice points per unit volume.
        let vg = pi().powf(g as f64 / 2.0) / gamma_half_int(g + 2);
        let sk = (0..g)
            .map(|k| (self.yinv[k * g + k] / pi()).sqrt())
            .fold(0.0, f64::max);
        let expected_terms = vg * self.rq.powf(g as f64 / 2.0) / det.sqrt() * f64::from(1u32 << g);
        // The outer coordinates j_1..j_{g-1} range over the projection of the
        // ellipsoid, whose form is Σ_{i<g-1} d_i (…)² (the factorisation eliminates
        // the last coordinate first).
        let expected_rows = if g == 1 {
            1.0
        } else {
            let outer_det: f64 = self.ldl_d[..g - 1].iter().product();
            let v = pi().powf((g - 1) as f64 / 2.0) / gamma_half_int(g + 1);
            (v * self.rq.powf((g - 1) as f64 / 2.0) / outer_det.sqrt() * f64::from(1u32 << (g - 1)))
                .max(1.0)
        };
        let ns = if self.fast_g2 {
            expected_terms * COST_G2_TERM_NS + expected_rows * COST_G2_ROW_NS
        } else {
            (expected_terms * COST_TERM_NS + expected_rows * COST_ROW_NS) * (1 + self.order) as f64
        };
        PlanInfo {
            radius: self.radius,
            rho: self.rho,
            error_bound: output_error_bound(g, self.rho_used, self.radius, sk, self.order),
            expected_terms,
            expected_rows,
            seconds_per_point: ns * 1e-9,
        }
    }

    /// New scratch space for [`ThetaPlan::eval_into`].
    pub fn workspace(&self) -> Workspace {
        let n = 1usize << (2 * self.g);
        Workspace {
            s0: vec![Complex64::new(0.0, 0.0); n],
            s1: vec![Complex64::new(0.0, 0.0); n * self.g],
            s2: vec![Complex64::new(0.0, 0.0); n * self.g * self.g],
            buf: vec![Complex64::new(0.0, 0.0); 1 << self.g],
            vrow: vec![Complex64::new(0.0, 0.0); 1 << self.g],
            grow: vec![Complex64::new(0.0, 0.0); self.g << self.g],
            rows: 0,
        }
    }
}

/// The genus, the size and finiteness of `tau`, `tol` and `order`.
fn check_arguments(tau: &[Complex64], g: usize, tol: f64, order: usize) -> Result<()> {
    if g == 0 || g > MAX_GENUS {
        return Err(Error::InvalidArgument {
            what: "genus",
            reason: format!("g must be in 1..={MAX_GENUS}, got {g}"),
        });
    }
    if tau.len() != g * g {
        return Err(Error::Shape {
            what: "tau",
            expected: format!("({g}, {g})"),
            got: format!("{} entries", tau.len()),
        });
    }
    let flat: Vec<f64> = tau.iter().flat_map(|c| [c.re, c.im]).collect();
    check_finite("tau", &flat).map_err(|e| match e {
        Error::NonFinite { what, index } => Error::NonFinite {
            what,
            index: index / 2,
        },
        other => other,
    })?;
    if !(tol > 0.0 && tol < 1.0) {
        return Err(Error::InvalidArgument {
            what: "tol",
            reason: format!("must be in (0, 1), got {tol}"),
        });
    }
    if order > 2 {
        return Err(Error::InvalidArgument {
            what: "order",
            reason: format!("derivative order must be 0, 1 or 2, got {order}"),
        });
    }
    Ok(())
}

/// Refuses an asymmetry of `tau` above [`SYMMETRY_RTOL`] of its largest entry.
fn check_symmetric(tau: &[Complex64], g: usize) -> Result<()> {
    let scale = tau.iter().map(|c| c.norm()).fold(0.0, f64::max);
    let mut max_asym: f64 = 0.0;
    for i in 0..g {
        for k in 0..i {
            max_asym = max_asym.max((tau[i * g + k] - tau[k * g + i]).norm());
        }
    }
    if max_asym > SYMMETRY_RTOL * scale {
        return Err(Error::NotSymmetric {
            what: "tau",
            max_asym,
        });
    }
    Ok(())
}

/// `(τ + τᵀ)/2`, row-major. Halving first gives the same (exact) result as
/// halving the sum, but cannot overflow for entries near the double range.
fn symmetrised(tau: &[Complex64], g: usize) -> Vec<Complex64> {
    (0..g * g)
        .map(|ik| {
            let (i, k) = (ik / g, ik % g);
            tau[i * g + k] * 0.5 + tau[k * g + i] * 0.5
        })
        .collect()
}

/// The factorisation of `Im τ` ([`ldl_reversed`]); its failure names the cause.
#[allow(clippy::type_complexity)]
fn factor_imag(y: &[f64], g: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    ldl_reversed(y, g).ok_or_else(|| {
        let min_eig = min_eigenvalue(y, g);
        if min_eig > 0.0 {
            // Positive definite, yet the factorisation overflowed (entries beyond
            // ~1e154 square to infinity) or rounded a pivot to <= 0: saying "not
            // positive definite" would be false.
            let ymax = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            Error::InvalidArgument {
                what: "tau",
                reason: format!(
                    "Im tau is positive definite (smallest eigenvalue {min_eig:e}) but its \
                     LDL^T factorisation fails in double precision (largest entry \
                     {ymax:e})"
                ),
            }
        } else {
            Error::ImagNotPositiveDefinite { min_eig }
        }
    })
}

/// `Re τ = Re τ' + 2S` exactly (`x − 2 round(x/2)` is exact in binary floating
/// point): `S mod 4` and `τ'`, row-major.
fn reduce_real_part(sym: &[Complex64], g: usize) -> (Vec<i64>, Vec<Complex64>) {
    let mut s = vec![0i64; g * g];
    let mut taur = vec![Complex64::new(0.0, 0.0); g * g];
    for (ik, &t) in sym.iter().enumerate() {
        let sik = (0.5 * t.re).round();
        // Only S mod 4 enters (through unit_pow); rem_euclid is exact on the
        // integer-valued double, where a cast would saturate beyond 2^63 (and the
        // sums below overflow) for huge Re tau.
        s[ik] = sik.rem_euclid(4.0) as i64;
        taur[ik] = Complex64::new(t.re - 2.0 * sik, t.im);
    }
    (s, taur)
}

/// Bit `k` of the characteristic half `a` (coordinate `k` at bit `g − 1 − k`).
fn abit(a: usize, k: usize, g: usize) -> usize {
    (a >> (g - 1 - k)) & 1
}

/// `unit_pow[(a << g) | b] = a·b + aᵀSa mod 4`: the power of `i` multiplying
/// the transform of characteristic `[a; b]`.
fn unit_powers(s: &[i64], g: usize) -> Vec<u8> {
    let nh = 1usize << g;
    let mut unit_pow = vec![0u8; 1usize << (2 * g)];
    for a in 0..nh {
        let mut asa = 0i64;
        for i in 0..g {
            for k in 0..g {
                asa += (abit(a, i, g) * abit(a, k, g)) as i64 * s[i * g + k];
            }
        }
        for b in 0..nh {
            let ab = (a & b).count_ones() as i64;
            unit_pow[(a << g) | b] = (ab + asa).rem_euclid(4) as u8;
        }
    }
    unit_pow
}

/// `class_of[a * 2^g + h]`: the index of the class `j ≡ a + 2h (mod 4)`.
fn class_table(g: usize) -> Vec<usize> {
    let nh = 1usize << g;
    let mut class_of = vec![0usize; nh * nh];
    for a in 0..nh {
        for h in 0..nh {
            class_of[a * nh + h] = (0..g).fold(0, |r, k| 4 * r + abit(a, k, g) + 2 * abit(h, k, g));
        }
    }
    class_of
}

/// The radius `R` of the summation ball for `tol`, the packing constant it
/// used, and `R²/π` for the plan's order and for values only.
///
/// Any `ρ' ≤ ρ` is a valid packing constant; a smaller one trades the factor
/// `(2/ρ')^g` for a later start of the integral. Keeps the best radius.
fn summation_radius(g: usize, rho: f64, sk: f64, order: usize, tol: f64) -> (f64, f64, f64, f64) {
    let (radius, rho_used) = best_radius(rho, tol, |rp, r| output_error_bound(g, rp, r, sk, order));
    let rq = radius * radius / pi();
    let rq_values = if order == 0 {
        rq
    } else {
        let (r0, _) = best_radius(rho, tol, |rp, r| output_error_bound(g, rp, r, sk, 0));
        // never above the plan's own radius (the bisection is to ~1e-5)
        (r0 * r0 / pi()).min(rq)
    };
    (radius, rho_used, rq, rq_values)
}

/// The smallest of the radii [`radius_for`] gives with the packing constants
/// `ρ' = ρ · {0.3, 0.5, 0.75, 1}`, and its `ρ'` (the largest on a tie). A
/// constant whose bound still exceeds `tol` at the best radius so far has its
/// radius above it (the bound decreases in `R`, and the bisection ends where
/// the bound is within `tol`), so it is not searched: the same result, at a
/// fraction of the bound evaluations.
fn best_radius(rho: f64, tol: f64, bound: impl Fn(f64, f64) -> f64) -> (f64, f64) {
    let mut radius = f64::INFINITY;
    let mut rho_used = rho;
    // the smallest constant first: it usually gives the smallest radius
    for frac in [0.3, 0.5, 0.75, 1.0] {
        let rp = rho * frac;
        if radius < RADIUS_CAP && bound(rp, radius) > tol {
            continue;
        }
        let r = radius_for(|r| bound(rp, r), 0.5 * rp, tol);
        // on a tie the larger constant, as when searched from the largest
        if r < radius || (r == radius && rp > rho_used) {
            radius = r;
            rho_used = rp;
        }
    }
    (radius, rho_used)
}

/// Truncation bound for values (`p = 0`), gradients and Hessians: with
/// `|m_k| ≤ |c_k| + s|x|`, `|c_k| ≤ 1/2` after reduction.
fn output_error_bound(g: usize, rho: f64, r: f64, s: f64, order: usize) -> f64 {
    let b0 = tail_bound(g, rho, r, 0);
    let mut e = b0;
    if order >= 1 {
        let b1 = tail_bound(g, rho, r, 1);
        e = e.max(2.0 * pi() * (0.5 * b0 + s * b1));
        if order >= 2 {
            let b2 = tail_bound(g, rho, r, 2);
            e = e.max(4.0 * pi() * pi() * (0.25 * b0 + s * b1 + s * s * b2));
        }
    }
    e
}

/// The largest radius [`radius_for`] grows to; [`best_radius`] prunes only
/// below it, where a radius is one whose bound is within `tol`.
const RADIUS_CAP: f64 = 1e3;

/// Smallest `R ≥ r0` (to ~1e-5 relative, from above) with `bound(R) ≤ tol`; `bound` is
/// decreasing in `R` and `+∞` below `r0`.
fn radius_for(bound: impl Fn(f64) -> f64, r0: f64, tol: f64) -> f64 {
    let mut lo = r0;
    let mut hi = r0.max(1.0);
    while bound(hi) > tol && hi < RADIUS_CAP {
        lo = hi;
        hi *= 1.25;
    }
    for _ in 0..16 {
        let mid = 0.5 * (lo + hi);
        if bound(mid) > tol {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// `Γ(n/2)` for small integers `n ≥ 1`.
fn gamma_half_int(n: usize) -> f64 {
    if n == 1 {
        pi().sqrt()
    } else if n == 2 {
        1.0
    } else {
        (n as f64 / 2.0 - 1.0) * gamma_half_int(n - 2)
    }
}
