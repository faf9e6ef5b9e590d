use super::*;
use crate::error::Error;
use proptest::prelude::*;

type C = Complex64;

/// Error allowed against the brute-force sum, relative to the largest of the
/// 4^g values: the claim of the module is 1e-13; the brute force itself (one
/// exponential per term, ~400 terms) is accurate to a few 1e-16.
const AGREE: f64 = 1e-13;

/// Independent reference: one exponential per term over a box far larger than
/// the ellipsoid, no reduction of z, no recurrences; returns θ (not normalised)
/// and, with `weight`, Σ w(m) E(m) for a polynomial weight in m = n + a/2.
fn brute(z: &[C], tau: &[C], g: usize, idx: usize, nmax: i64, weight: &dyn Fn(&[f64]) -> C) -> C {
    let (a, b) = char_from_index(g, idx);
    let mut n = vec![-nmax; g];
    let mut total = C::new(0.0, 0.0);
    loop {
        let m: Vec<f64> = (0..g).map(|k| n[k] as f64 + 0.5 * a[k] as f64).collect();
        let mut ex = C::new(0.0, 0.0);
        for i in 0..g {
            for k in 0..g {
                ex += C::i() * std::f64::consts::PI * m[i] * tau[i * g + k] * m[k];
            }
            ex += 2.0 * C::i() * std::f64::consts::PI * m[i] * (z[i] + 0.5 * b[i] as f64);
        }
        total += weight(&m) * ex.exp();
        let mut k = 0;
        loop {
            if k == g {
                return total;
            }
            n[k] += 1;
            if n[k] <= nmax {
                break;
            }
            n[k] = -nmax;
            k += 1;
        }
    }
}

fn one(_: &[f64]) -> C {
    C::new(1.0, 0.0)
}

fn tau2(t11: C, t12: C, t22: C) -> Vec<C> {
    vec![t11, t12, t12, t22]
}

fn bench_tau() -> Vec<C> {
    tau2(C::new(0.3, 1.1), C::new(0.1, 0.4), C::new(-0.2, 1.3))
}

fn max_abs(v: &[C]) -> f64 {
    v.iter().map(|c| c.norm()).fold(0.0, f64::max)
}

fn check_against_brute(tau: &[C], z: &[C], g: usize, nmax: i64) {
    let plan = ThetaPlan::new(tau, g, DEFAULT_TOL, 0).unwrap();
    let (om, l) = plan.theta_all(z).unwrap();
    let vals: Vec<C> = om.iter().map(|w| w * l.exp()).collect();
    let refs: Vec<C> = (0..1 << (2 * g))
        .map(|i| brute(z, tau, g, i, nmax, &one))
        .collect();
    let scale = max_abs(&refs);
    for (i, (v, r)) in vals.iter().zip(&refs).enumerate() {
        assert!(
            (v - r).norm() <= AGREE * scale,
            "g={g} idx={i} got {v} want {r} (scale {scale})"
        );
    }
}

#[test]
fn genus_two_matches_brute_force() {
    let z = [C::new(0.2, 0.1), C::new(0.7, -0.3)];
    check_against_brute(&bench_tau(), &z, 2, 12);
    // large Im z: reduction by q = round((Im τ)^{-1} Im z) is exercised
    let z = [C::new(-1.3, 1.7), C::new(2.6, -2.2)];
    check_against_brute(&bench_tau(), &z, 2, 14);
    // Re τ outside [-1, 1]: exact reduction τ = τ' + 2S with the phase i^{aᵀSa}
    let tau = tau2(C::new(3.3, 0.9), C::new(-2.6, 0.3), C::new(5.1, 1.4));
    check_against_brute(&tau, &[C::new(0.4, 0.2), C::new(-0.1, 0.05)], 2, 14);
}

#[test]
fn generic_path_matches_fast_path() {
    let tau = bench_tau();
    let fast = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 2).unwrap();
    let mut slow = fast.clone();
    slow.fast_g2 = false;
    for z in [
        [C::new(0.2, 0.1), C::new(0.7, -0.3)],
        [C::new(-0.45, 0.4), C::new(0.1, 0.35)],
        [C::new(3.0, -2.0), C::new(-1.0, 4.0)],
    ] {
        let a = fast.jet(&z, 2).unwrap();
        let b = slow.jet(&z, 2).unwrap();
        approx::assert_relative_eq!(a.log_scale, b.log_scale, max_relative = 1e-14);
        for (x, y) in [
            (&a.values, &b.values),
            (&a.gradient, &b.gradient),
            (&a.hessian, &b.hessian),
        ] {
            let s = max_abs(y);
            for (u, v) in x.iter().zip(y.iter()) {
                assert!((u - v).norm() <= AGREE * s, "{u} vs {v}");
            }
        }
    }
}

#[test]
fn genus_one_three_four_match_brute_force() {
    check_against_brute(&[C::new(0.3, 0.8)], &[C::new(0.23, -0.31)], 1, 30);
    let t3 = vec![
        C::new(0.2, 1.2),
        C::new(0.1, 0.3),
        C::new(-0.3, -0.2),
        C::new(0.1, 0.3),
        C::new(-0.4, 1.1),
        C::new(0.25, 0.1),
        C::new(-0.3, -0.2),
        C::new(0.25, 0.1),
        C::new(0.45, 1.4),
    ];
    check_against_brute(
        &t3,
        &[C::new(0.1, 0.2), C::new(-0.3, 0.1), C::new(0.6, -0.4)],
        3,
        6,
    );
    let mut t4 = vec![C::new(0.0, 0.0); 16];
    for i in 0..4 {
        for k in 0..4 {
            t4[i * 4 + k] = if i == k {
                C::new(0.1 * i as f64, 1.3 + 0.1 * k as f64)
            } else {
                C::new(0.05 * (i + k) as f64, 0.15)
            };
        }
    }
    check_against_brute(
        &t4,
        &[
            C::new(0.1, 0.05),
            C::new(0.2, -0.1),
            C::new(-0.3, 0.1),
            C::new(0.4, 0.0),
        ],
        4,
        4,
    );
}

#[test]
fn derivatives_match_weighted_brute_force() {
    let tau = bench_tau();
    let z = [C::new(0.31, -0.12), C::new(-0.4, 0.27)];
    let jet = theta_jet(&z, &tau, DEFAULT_TOL).unwrap();
    let f = jet.log_scale.exp();
    let two_pi_i = 2.0 * C::i() * std::f64::consts::PI;
    for idx in 0..16 {
        for k in 0..2 {
            let r = brute(&z, &tau, 2, idx, 12, &|m| two_pi_i * m[k]);
            let scale = (0..2)
                .map(|kk| brute(&z, &tau, 2, 0, 12, &|m| two_pi_i * m[kk]).norm())
                .fold(1.0, f64::max);
            assert!((jet.gradient[idx * 2 + k] * f - r).norm() <= AGREE * 10.0 * scale);
            for l in 0..2 {
                let r = brute(&z, &tau, 2, idx, 12, &|m| two_pi_i * two_pi_i * m[k] * m[l]);
                assert!(
                    (jet.hessian[(idx * 2 + k) * 2 + l] * f - r).norm() <= AGREE * 100.0 * scale
                );
            }
        }
    }
}

#[test]
fn bad_tau_is_rejected() {
    let mut tau = bench_tau();
    tau[1] += C::new(1e-3, 0.0);
    assert!(matches!(
        ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0),
        Err(Error::NotSymmetric { .. })
    ));
    let tau = tau2(C::new(0.0, 1.0), C::new(0.0, 2.0), C::new(0.0, 1.0));
    match ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0) {
        Err(Error::ImagNotPositiveDefinite { min_eig }) => assert!((min_eig + 1.0).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    let tau = tau2(C::new(f64::NAN, 1.0), C::new(0.0, 0.2), C::new(0.0, 1.0));
    assert!(matches!(
        ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0),
        Err(Error::NonFinite { index: 0, .. })
    ));
    assert!(ThetaPlan::new(&bench_tau(), 3, DEFAULT_TOL, 0).is_err());
    assert!(ThetaPlan::new(&bench_tau(), 2, 0.0, 0).is_err());
    assert!(ThetaPlan::new(&bench_tau(), 2, 1e-15, 3).is_err());
    let plan = ThetaPlan::new(&bench_tau(), 2, DEFAULT_TOL, 0).unwrap();
    assert!(plan
        .theta_all(&[C::new(f64::INFINITY, 0.0), C::new(0.0, 0.0)])
        .is_err());
    assert!(plan.theta_all(&[C::new(0.0, 0.0)]).is_err());
    assert!(plan
        .theta_all(&[C::new(0.0, 1e300), C::new(0.0, 0.0)])
        .is_err());
    assert!(plan.jet(&[C::new(0.0, 0.0), C::new(0.0, 0.0)], 1).is_err());
    // Im τ tiny: far too many terms, refused instead of hanging
    let tau = tau2(C::new(0.0, 1e-9), C::new(0.0, 0.0), C::new(0.0, 1e-9));
    assert!(matches!(
        ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0),
        Err(Error::InvalidArgument { .. })
    ));
}

/// Entries of Re τ beyond the i64 range once saturated in the reduction
/// Re τ = Re τ' + 2S (and overflowed the sum aᵀSa): θ(z, τ + 8K) = θ(z, τ) for
/// integer K, and every shift below is a multiple of 8 as a double.
#[test]
fn huge_real_tau_reduces_exactly() {
    let base: Vec<C> = bench_tau().iter().map(|t| C::new(0.0, t.im)).collect();
    let z = [C::new(0.2, 0.1), C::new(0.7, -0.3)];
    let want = full(&ThetaPlan::new(&base, 2, DEFAULT_TOL, 0).unwrap(), &z);
    for shift in [8.0, 2f64.powi(60), 1e20, 1e300, -1e300, 1.7e308] {
        assert_eq!(shift % 8.0, 0.0);
        let tau: Vec<C> = base.iter().map(|t| C::new(shift, t.im)).collect();
        let got = full(&ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap(), &z);
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).norm() <= AGREE * max_abs(&want),
                "{shift}: {g} vs {w}"
            );
        }
    }
}

/// Overflow at the edge of the double range is an error, never NaN values: L
/// overflowing, and a positive definite Im τ whose factorisation overflows (reported
/// as such, not as "not positive definite").
#[test]
fn double_range_edges_are_errors_not_nan() {
    let tau = tau2(C::new(0.3, 1e308), C::new(0.1, 0.4), C::new(-0.2, 1.3));
    let plan = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap();
    let z = [C::new(0.0, -1e308), C::new(0.5, 0.1)];
    assert!(matches!(
        plan.theta_all(&z),
        Err(Error::InvalidArgument { what: "z", .. })
    ));
    let plan2 = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 2).unwrap();
    assert!(matches!(
        plan2.jet(&z, 2),
        Err(Error::InvalidArgument { what: "z", .. })
    ));
    let tau: Vec<C> = bench_tau().iter().map(|t| t * 1e300).collect();
    match ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0) {
        Err(Error::InvalidArgument {
            what: "tau",
            reason,
        }) => {
            assert!(
                reason.contains("positive definite (smallest eigenvalue"),
                "{reason}"
            )
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn plan_bound_is_below_tol_and_rho_is_shortest() {
    let plan = ThetaPlan::new(&bench_tau(), 2, 1e-15, 2).unwrap();
    let info = plan.info();
    assert!(info.error_bound <= 1e-15);
    // shortest vector of Y = [[1.1,.4],[.4,1.3]] over Z^2 \ 0: min(1.1, 1.3, 1.1+1.3-0.8 = 1.6) = 1.1
    approx::assert_relative_eq!(
        info.rho,
        (std::f64::consts::PI * 1.1).sqrt(),
        max_relative = 1e-14
    );
}

fn arb_point() -> impl Strategy<Value = (Vec<C>, [C; 2])> {
    (
        -1.0..1.0f64,
        -1.0..1.0f64,
        -1.0..1.0f64,
        0.6..2.0f64,
        -0.4..0.4f64,
        0.6..2.0f64,
        prop::array::uniform4(-2.0..2.0f64),
    )
        .prop_map(|(x11, x12, x22, y11, r, y22, zz)| {
            let y12 = r * (y11 * y22).sqrt();
            (
                tau2(C::new(x11, y11), C::new(x12, y12), C::new(x22, y22)),
                [C::new(zz[0], zz[1]), C::new(zz[2], zz[3])],
            )
        })
}

fn full(plan: &ThetaPlan, z: &[C]) -> Vec<C> {
    let (om, l) = plan.theta_all(z).unwrap();
    om.iter().map(|w| w * l.exp()).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// θ[a;b](z + m + τn) = exp(-iπ nᵀτn - 2πi nᵀz) exp(iπ(aᵀm - bᵀn)) θ[a;b](z).
    #[test]
    fn quasi_periodicity((tau, z) in arb_point(), m in prop::array::uniform2(-2i64..=2), n in prop::array::uniform2(-2i64..=2)) {
        let plan = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap();
        let zs: Vec<C> = (0..2).map(|i| z[i] + m[i] as f64 + tau[i * 2] * n[0] as f64 + tau[i * 2 + 1] * n[1] as f64).collect();
        let lhs = full(&plan, &zs);
        let rhs = full(&plan, &z);
        let mut ntn = C::new(0.0, 0.0);
        let mut nz = C::new(0.0, 0.0);
        for i in 0..2 {
            for k in 0..2 { ntn += n[i] as f64 * tau[i * 2 + k] * n[k] as f64; }
            nz += n[i] as f64 * z[i];
        }
        let mult = (-C::i() * std::f64::consts::PI * (ntn + 2.0 * nz)).exp();
        let scale = max_abs(&lhs);
        for idx in 0..16 {
            let (a, b) = char_from_index(2, idx);
            let s: i64 = (0..2).map(|k| a[k] as i64 * m[k] - b[k] as i64 * n[k]).sum();
            let sign = if s.rem_euclid(2) == 0 { 1.0 } else { -1.0 };
            prop_assert!((lhs[idx] - mult * sign * rhs[idx]).norm() <= 1e-12 * scale);
        }
    }

    /// θ[a;b](-z) = (-1)^{a·b} θ[a;b](z); the six odd ones vanish at 0.
    #[test]
    fn parity_and_odd_zeros((tau, z) in arb_point()) {
        let plan = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap();
        let p = full(&plan, &z);
        let mz: Vec<C> = z.iter().map(|c| -c).collect();
        let mneg = full(&plan, &mz);
        let zero = full(&plan, &[C::new(0.0, 0.0); 2]);
        let (s, s0) = (max_abs(&p), max_abs(&zero));
        for idx in 0..16 {
            prop_assert!((mneg[idx] - parity(2, idx) as f64 * p[idx]).norm() <= AGREE * s);
            if parity(2, idx) == -1 {
                prop_assert!(zero[idx].norm() <= AGREE * s0);
            }
        }
    }

    /// Heat equation ∂²θ/∂z_j∂z_k = 2πi (1 + δ_jk) ∂θ/∂τ_jk, with ∂θ/∂τ_jk from
    /// the brute-force sum of iπ (2 - δ_jk) m_j m_k E(m) (τ_jk = τ_kj both vary).
    #[test]
    fn heat_equation((tau, z) in arb_point()) {
        let z = [C::new(z[0].re * 0.25, z[0].im * 0.25), C::new(z[1].re * 0.25, z[1].im * 0.25)];
        let jet = theta_jet(&z, &tau, DEFAULT_TOL).unwrap();
        let f = jet.log_scale.exp();
        for idx in [0usize, 5, 9, 15] {
            for (j, k) in [(0usize, 0usize), (0, 1), (1, 1)] {
                let dtau = brute(&z, &tau, 2, idx, 14, &|m| {
                    let w = if j == k { 1.0 } else { 2.0 };
                    C::i() * std::f64::consts::PI * w * m[j] * m[k]
                });
                let delta = if j == k { 2.0 } else { 1.0 };
                let rhs = 2.0 * C::i() * std::f64::consts::PI * delta * dtau;
                let lhs = jet.hessian[(idx * 2 + j) * 2 + k] * f;
                let scale = 4.0 * std::f64::consts::PI.powi(2) * jet.values.iter().map(|c| c.norm() * f).fold(0.0, f64::max);
                prop_assert!((lhs - rhs).norm() <= 1e-12 * scale, "{} vs {}", lhs, rhs);
            }
        }
    }
}

/// The vectorised genus-2 batch kernel (values only) against the per-point
/// walk, over points that need reduction and a batch that is not a multiple
/// of the chunk size.
#[test]
fn batch_kernel_matches_single_point_path() {
    for tau in [
        bench_tau(),
        tau2(C::new(3.3, 0.9), C::new(-2.6, 0.3), C::new(5.1, 1.4)),
        tau2(C::new(0.1, 0.35), C::new(0.05, 0.1), C::new(-0.3, 0.5)),
    ] {
        let plan = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap();
        let npts = 77;
        let mut z = Vec::new();
        for i in 0..npts {
            let t = i as f64;
            z.push(C::new((0.37 * t).sin() * 3.0, (0.71 * t).cos() * 2.5));
            z.push(C::new((0.53 * t).cos() * 2.0, (0.29 * t).sin() * 1.5));
        }
        let mut vals = vec![C::new(0.0, 0.0); 16 * npts];
        let mut logs = vec![0.0; npts];
        plan.eval_batch(&z, &mut vals, &mut [], &mut [], &mut logs)
            .unwrap();
        for i in 0..npts {
            let (om, l) = plan.theta_all(&z[2 * i..2 * i + 2]).unwrap();
            assert_eq!(l, logs[i]);
            let s = max_abs(&om);
            for k in 0..16 {
                assert!((om[k] - vals[16 * i + k]).norm() <= AGREE * s);
            }
        }
    }
}

/// Batches above the parallel threshold are split over threads; every point is
/// computed by the same code, so the result must be bitwise the one-core result,
/// with and without derivatives and scaling (genus 2 and the generic path, g = 3).
#[test]
fn parallel_batches_equal_serial() {
    let npts = 5000;
    for (tau, g) in [
        (bench_tau(), 2),
        (
            vec![
                C::new(0.2, 1.2),
                C::new(0.1, 0.3),
                C::new(0.0, 0.1),
                C::new(0.1, 0.3),
                C::new(-0.3, 1.0),
                C::new(0.2, 0.2),
                C::new(0.0, 0.1),
                C::new(0.2, 0.2),
                C::new(0.4, 1.4),
            ],
            3,
        ),
    ] {
        let n = 1usize << (2 * g);
        let z: Vec<C> = (0..npts * g)
            .map(|i| C::new((0.37 * i as f64).sin() * 2.0, (0.71 * i as f64).cos() * 1.5))
            .collect();
        let order = if g == 2 { 1 } else { 0 };
        let par = ThetaPlan::new(&tau, g, DEFAULT_TOL, order).unwrap();
        let ser = par.clone().with_parallel(false);
        let run = |plan: &ThetaPlan, grad: bool| {
            let mut v = vec![C::new(0.0, 0.0); n * npts];
            let mut gr = vec![C::new(0.0, 0.0); if grad { n * g * npts } else { 0 }];
            let mut l = vec![0.0; npts];
            plan.eval_batch(&z, &mut v, &mut gr, &mut [], &mut l)
                .unwrap();
            let mut vs = vec![C::new(0.0, 0.0); n * npts];
            let mut ls = vec![0.0; npts];
            let ok = plan.eval_batch_scaled(&z, &mut vs, &mut ls).unwrap();
            (v, gr, l, vs, ls, ok)
        };
        assert_eq!(run(&par, false), run(&ser, false));
        if order == 1 {
            assert_eq!(run(&par, true), run(&ser, true));
        }
    }
}

#[test]
fn foreign_workspace_and_extreme_imaginary_parts() {
    let p1 = ThetaPlan::new(&[C::new(0.1, 0.9)], 1, DEFAULT_TOL, 0).unwrap();
    let p2 = ThetaPlan::new(&bench_tau(), 2, DEFAULT_TOL, 0).unwrap();
    let mut ws = p1.workspace();
    let mut v = vec![C::new(0.0, 0.0); 16];
    let z = [C::new(0.2, 0.1), C::new(0.7, -0.3)];
    p2.eval_into(&z, &mut ws, &mut v, &mut [], &mut []).unwrap();
    assert_eq!(v, p2.theta_all(&z).unwrap().0);
    // Im τ = 1000: θ[0;0] = 1 + O(e^{-1000π}); Im τ = 0.01 I: ~1.4e4 terms, generic path
    for (tau, nmax) in [
        (
            tau2(C::new(0.3, 1000.0), C::new(0.1, 1.0), C::new(-0.2, 900.0)),
            2,
        ),
        (
            tau2(C::new(0.3, 0.01), C::new(0.0, 0.002), C::new(-0.2, 0.012)),
            80,
        ),
    ] {
        let z = [C::new(0.13, 0.002), C::new(-0.3, 0.001)];
        let plan = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap();
        let (om, l) = plan.theta_all(&z).unwrap();
        let want = brute(&z, &tau, 2, 0, nmax, &one);
        let got = om[0] * l.exp();
        assert!(
            (got - want).norm() <= AGREE * want.norm() * 10.0,
            "{got} vs {want}"
        );
    }
}

#[test]
fn a_cancelled_batch_stops_with_interrupted_serial_and_parallel() {
    let plan = ThetaPlan::new(&bench_tau(), 2, 1e-15, 0).unwrap();
    let npts = 20_000;
    let z: Vec<C> = (0..2 * npts)
        .map(|i| C::new(0.001 * i as f64, 0.1))
        .collect();
    for parallel in [false, true] {
        let plan = plan.clone().with_parallel(parallel);
        let cancel = crate::numeric::cancel::Cancel::never();
        cancel.cancel();
        let mut v = vec![C::new(0.0, 0.0); 16 * npts];
        let mut l = vec![0.0; npts];
        assert_eq!(
            plan.eval_batch_cancel(&z, &mut v, &mut [], &mut [], &mut l, &cancel),
            Err(Error::Interrupted)
        );
        assert_eq!(
            plan.eval_batch_scaled_cancel(&z, &mut v, &mut l, &cancel),
            Err(Error::Interrupted)
        );
        // an uncancelled token changes nothing
        let mut v2 = vec![C::new(0.0, 0.0); 16 * npts];
        let mut l2 = vec![0.0; npts];
        plan.eval_batch(&z, &mut v, &mut [], &mut [], &mut l)
            .unwrap();
        plan.eval_batch_cancel(
            &z,
            &mut v2,
            &mut [],
            &mut [],
            &mut l2,
            &crate::numeric::cancel::Cancel::never(),
        )
        .unwrap();
        assert_eq!(v, v2);
    }
}

#[test]
fn large_genus_sums_over_the_cost_budget_are_refused() {
    let g = 6;
    let tau: Vec<C> = (0..g * g)
        .map(|ik| C::new(0.3, if ik / g == ik % g { 0.2 } else { 0.0 }))
        .collect();
    match ThetaPlan::new(&tau, g, 1e-15, 0) {
        Err(Error::InvalidArgument { reason, .. }) => {
            assert!(reason.contains("estimated"), "{reason}")
        }
        other => panic!("{other:?}"),
    }
    let ok: Vec<C> = (0..g * g)
        .map(|ik| C::new(0.3, if ik / g == ik % g { 1.0 } else { 0.0 }))
        .collect();
    let info = ThetaPlan::new(&ok, g, 1e-15, 0).unwrap().info();
    assert!(info.seconds_per_point > 0.0 && info.seconds_per_point <= MAX_SECONDS_PER_POINT);
}

/// The branch-free reduction of a block whose lattice coordinates lie in
/// [−1, 1] writes the same bits, lane by lane, as the per-point reduction of
/// the same coordinates: on the ends ±1, the rounding ties ±1/2 (where
/// `floor(v + 1/2)` and round-half-even differ), ±0 and a sweep in between,
/// with `Re τ` beyond [−1, 1] so that `Re z_r` also crosses the ties.
#[test]
fn bounded_block_reduction_writes_the_bits_of_the_per_point_reduction() {
    let tau = tau2(C::new(2.3, 1.1), C::new(-3.1, 0.4), C::new(-0.2, 1.3));
    let plan = ThetaPlan::new(&tau, 2, 1e-16, 0).unwrap();
    let edges = [-1.0, -0.5, -0.0, 0.0, 0.5, 1.0, 0.25, -0.75];
    let mut values: Vec<f64> = edges.to_vec();
    values.extend((0..200).map(|k| ((k as f64) * 0.618_033_988_749_895).fract() * 2.0 - 1.0));
    let mut blocks = 0;
    for start in (0..values.len()).step_by(3) {
        let mut lanes = LatticeLanes::default();
        for p in 0..BLOCK {
            let v = |o: usize| values[(start + 7 * p + o) % values.len()];
            lanes.x[0][p] = v(0);
            lanes.x[1][p] = v(1);
            lanes.y[0][p] = v(2);
            lanes.y[1][p] = v(3);
        }
        // The portable body itself, and the block entry point (the AVX2 copy
        // where the CPU has it): both must write the per-point bits.
        let mut portable = batch::ChunkIn::default();
        plan.reduce2_bounded(&lanes, &mut portable);
        let mut fast = batch::ChunkIn::default();
        plan.reduce2_lattice_lanes(&lanes, BLOCK, &mut fast)
            .unwrap();
        let mut slow = batch::ChunkIn::default();
        for p in 0..BLOCK {
            let x = [lanes.x[0][p], lanes.x[1][p]];
            let y = [lanes.y[0][p], lanes.y[1][p]];
            plan.reduce2_lattice_into(x, y, &mut slow, p).unwrap();
        }
        let bits = |c: &batch::ChunkIn| -> Vec<u64> {
            let rows = c
                .zre
                .iter()
                .chain(&c.zim)
                .chain(&c.wr)
                .chain([&c.phase, &c.logs]);
            rows.chain(&c.sa)
                .chain(&c.sb)
                .flatten()
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(
            bits(&portable),
            bits(&slow),
            "block starting at value {start}"
        );
        assert_eq!(bits(&fast), bits(&slow), "block starting at value {start}");
        blocks += 1;
    }
    assert!(blocks > 60);
}

/// A `Re τ` so large that `Re z` of a bounded block leaves the range where
/// theta is determined: the block goes point by point and gives the
/// per-point error, as the same point does through the per-point reduction
/// (the block path must not return a value where that path refuses).
#[test]
fn huge_re_tau_blocks_give_the_per_point_error() {
    let tau = tau2(C::new(1e16, 1.1), C::new(0.1, 0.4), C::new(-0.2, 1.3));
    let plan = ThetaPlan::new(&tau, 2, 1e-16, 0).unwrap();
    let (x, y) = ([0.1, 0.0], [0.5, 0.1]);
    let mut inp = batch::ChunkIn::default();
    let single = plan.reduce2_lattice_into(x, y, &mut inp, 0).unwrap_err();
    assert!(
        matches!(single, Error::InvalidArgument { what: "z", .. }),
        "{single:?}"
    );
    let err = plan
        .eval_selected_g2_lattice_lanes(
            3,
            |_, m, lanes| {
                for p in 0..m {
                    for i in 0..2 {
                        lanes.x[i][p] = x[i];
                        lanes.y[i][p] = y[i];
                    }
                }
            },
            &[0],
            |_, _| {},
        )
        .unwrap_err();
    assert_eq!(format!("{err}"), format!("{single}"));
}

/// Without the batch kernel (`Im τ_11 = 60`: its tables would overflow), the
/// block form of the lattice input takes the per-point sum, point by point
/// from the right lanes: the thetas of `z = x + τ y` against the brute-force
/// sum, for a full block and a short tail.
#[test]
fn lattice_lanes_without_the_batch_kernel_give_the_thetas_of_the_point() {
    let tau = tau2(C::new(0.3, 60.0), C::new(0.1, 0.4), C::new(-0.2, 1.3));
    let plan = ThetaPlan::new(&tau, 2, 1e-16, 0).unwrap();
    assert!(batch::Batch2::build(&plan).is_none());
    let n = BLOCK + 3;
    let coords = |p: usize| {
        let t = p as f64;
        (
            [(0.37 * t).sin(), (0.53 * t).cos()],
            [(0.71 * t).cos() * 0.9, (0.29 * t).sin() * 0.6],
        )
    };
    let chars = [0, 5, 9, 15];
    let mut got = vec![[C::new(0.0, 0.0); 4]; n];
    plan.eval_selected_g2_lattice_lanes(
        n,
        |first, m, lanes| {
            for p in 0..m {
                let (x, y) = coords(first + p);
                for i in 0..2 {
                    lanes.x[i][p] = x[i];
                    lanes.y[i][p] = y[i];
                }
            }
        },
        &chars,
        |first, blk| {
            for p in 0..blk.len {
                for k in 0..chars.len() {
                    got[first + p][k] = C::new(blk.re[k][p], blk.im[k][p]) * blk.log_scale[p].exp();
                }
            }
        },
    )
    .unwrap();
    for (p, row) in got.iter().enumerate() {
        let (x, y) = coords(p);
        let z: Vec<C> = (0..2)
            .map(|i| C::new(x[i], 0.0) + tau[2 * i] * y[0] + tau[2 * i + 1] * y[1])
            .collect();
        let refs: Vec<C> = (0..16).map(|c| brute(&z, &tau, 2, c, 14, &one)).collect();
        let scale = max_abs(&refs);
        for (k, &c) in chars.iter().enumerate() {
            assert!(
                (row[k] - refs[c]).norm() <= AGREE * scale,
                "point {p} char {c}: {} vs {}",
                row[k],
                refs[c]
            );
        }
    }
}

/// A block with a coordinate that is not finite goes point by point: an
/// error naming the lattice coordinates, not a NaN (coordinates beyond
/// [−1, 1] are `lattice_coordinates_give_the_thetas_of_the_point`).
#[test]
fn unbounded_or_non_finite_lanes_take_the_checked_path() {
    let tau = tau2(C::new(0.3, 1.1), C::new(0.1, 0.4), C::new(-0.2, 1.3));
    let plan = ThetaPlan::new(&tau, 2, 1e-16, 0).unwrap();
    for bad in [f64::NAN, f64::INFINITY] {
        let err = plan
            .eval_selected_g2_lattice_lanes(
                BLOCK,
                |_, m, lanes| {
                    for p in 0..m {
                        lanes.x[0][p] = 0.1;
                        lanes.y[1][p] = if p == 5 { bad } else { 0.2 };
                    }
                },
                &[0, 1],
                |_, _| {},
            )
            .unwrap_err();
        assert!(
            matches!(
                err,
                Error::NonFinite {
                    what: "lattice coordinates",
                    ..
                }
            ),
            "{err:?}"
        );
    }
}

/// Points given by lattice coordinates (`z = x + τ y`) give the thetas of `z`:
/// against the brute-force sum, through the batch kernel (a full block) and the
/// per-point path (a short tail), with `Re τ` beyond [−1, 1] (`S ≠ 0`) and
/// `|y|` up to 3.7 (reduction shifts `q` with `|q| > 1`).
#[test]
fn lattice_coordinates_give_the_thetas_of_the_point() {
    let tau = tau2(C::new(2.3, 1.1), C::new(-3.1, 0.4), C::new(-0.2, 1.3));
    let plan = ThetaPlan::new(&tau, 2, 1e-16, 0).unwrap();
    let n = BLOCK + 5;
    let lat: Vec<([f64; 2], [f64; 2])> = (0..n)
        .map(|p| {
            let t = p as f64;
            (
                [(0.37 * t).sin() * 5.0, (0.53 * t).cos() * 1.5],
                [(0.71 * t).cos() * 3.7, (0.29 * t).sin() * 1.2],
            )
        })
        .collect();
    let chars: Vec<usize> = (0..16).collect();
    let mut got = vec![[C::new(0.0, 0.0); 16]; n];
    plan.eval_selected_g2_lattice(
        n,
        |i| lat[i],
        &chars,
        |first, blk| {
            for p in 0..blk.len {
                for (k, _) in chars.iter().enumerate() {
                    got[first + p][k] = C::new(blk.re[k][p], blk.im[k][p]) * blk.log_scale[p].exp();
                }
            }
        },
    )
    .unwrap();
    for (p, (x, y)) in lat.iter().enumerate() {
        let z: Vec<C> = (0..2)
            .map(|i| C::new(x[i], 0.0) + tau[2 * i] * y[0] + tau[2 * i + 1] * y[1])
            .collect();
        let refs: Vec<C> = (0..16).map(|c| brute(&z, &tau, 2, c, 14, &one)).collect();
        let scale = max_abs(&refs);
        for c in 0..16 {
            assert!(
                (got[p][c] - refs[c]).norm() <= AGREE * scale,
                "point {p} char {c}: {} vs {}",
                got[p][c],
                refs[c]
            );
        }
    }
}

/// The batch entry of the binding: the widths of the derivative outputs per
/// order, a batch too large to address refused before any allocation, and
/// `eval_batch_jet` the same values as the per-point path (scaled: times exp(L)).
#[test]
fn batch_jet_widths_and_values() {
    let tau = [
        Complex64::new(0.3, 1.1),
        Complex64::new(0.1, 0.4),
        Complex64::new(0.1, 0.4),
        Complex64::new(-0.2, 1.3),
    ];
    for (order, widths) in [(0, (0, 0)), (1, (2, 0)), (2, (2, 2))] {
        let plan = ThetaPlan::new(&tau, 2, 1e-15, order).unwrap();
        assert_eq!(plan.batch_widths(10).unwrap(), widths);
        assert!(matches!(
            plan.batch_widths(usize::MAX / 8),
            Err(Error::InvalidArgument { what: "z", .. })
        ));
    }
    let plan = ThetaPlan::new(&tau, 2, 1e-15, 0).unwrap();
    let z = [Complex64::new(0.2, 0.7), Complex64::new(-0.4, 1.9)];
    let (one, l) = plan.theta_all(&z).unwrap();
    let mut values = vec![Complex64::new(0.0, 0.0); 16];
    let mut logs = [0.0];
    let never = crate::numeric::cancel::Cancel::never();
    let ok = plan
        .eval_batch_jet(&z, &mut values, &mut [], &mut [], &mut logs, false, &never)
        .unwrap();
    assert!(ok);
    assert_eq!((values.clone(), logs[0]), (one.clone(), l));
    plan.eval_batch_jet(&z, &mut values, &mut [], &mut [], &mut logs, true, &never)
        .unwrap();
    for (v, w) in values.iter().zip(&one) {
        assert!((v - w * l.exp()).norm() <= 1e-15 * (w * l.exp()).norm());
    }
}
