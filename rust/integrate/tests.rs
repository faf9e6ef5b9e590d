use super::dopri5::{DP_A, DP_B, DP_BHAT, DP_C};
use super::driver::alloc_output;
use super::*;
use crate::error::Error;
use crate::so4::{integrals4, FrahmTop};
use approx::assert_relative_eq;

const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
const B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];
const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];

/// Harmonic oscillator ẋ = v, v̇ = -x: exact solution known.
struct Osc;
impl VectorField for Osc {
    fn dim(&self) -> usize {
        2
    }
    fn eval(&self, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
}

fn opts(method: Method, dt: f64) -> Options {
    Options {
        method,
        dt,
        rtol: 1e-10,
        atol: 1e-10,
        max_steps: MAX_STEPS as u64,
    }
}

/// rtol below 100 ε is refused for the explicit methods (rtol = atol = 1e-300 once
/// overflowed the error norm and failed as "state became non-finite"); the Gauss
/// methods ignore rtol. At the floor with atol = 0 and a zero component (0/0 in the
/// norms before) dopri5 and dop853 run and stay on the circle.
#[test]
fn rtol_floor_and_zero_scale_components() {
    for m in [Method::Dopri5, Method::Dop853] {
        for (rtol, atol) in [(1e-300, 1e-300), (0.0, 1e-12), (RTOL_MIN * 0.999, 1.0)] {
            let o = Options {
                rtol,
                atol,
                ..opts(m, 0.0)
            };
            match integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o) {
                Err(Error::InvalidArgument { what: "rtol", .. }) => {}
                other => panic!("{m:?} {rtol}: {other:?}"),
            }
        }
        for atol in [0.0, 1e-300] {
            let o = Options {
                rtol: RTOL_MIN,
                atol,
                ..opts(m, 0.0)
            };
            let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o).unwrap();
            let r2 = tr.y[0] * tr.y[0] + tr.y[1] * tr.y[1];
            // the explicit methods' per-step error at rtol = 100 ε over t = 1
            assert!((r2 - 1.0).abs() < 1e-12, "{m:?} atol {atol}: r² = {r2}");
        }
    }
    let o = Options {
        rtol: 0.0,
        atol: 0.0,
        ..opts(Method::Gauss6, 0.1)
    };
    assert!(integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o).is_ok());
}

#[test]
fn tableaux_satisfy_collocation_conditions() {
    for m in [Method::Gauss4, Method::Gauss6, Method::Gauss16] {
        let (c, b, mu) = m.gauss_tableau().unwrap();
        let s = b.len();
        for i in 0..s {
            for j in 0..s {
                // Symplecticity held exactly in floating point.
                assert_eq!(mu[i * s + j] + mu[j * s + i], 1.0);
            }
        }
        for k in 1..=2 * s {
            let q: f64 = (0..s).map(|i| b[i] * c[i].powi(k as i32 - 1)).sum();
            assert_relative_eq!(q, 1.0 / k as f64, max_relative = 1e-14);
        }
    }
}

#[test]
fn gauss_orders_on_the_oscillator() {
    // Error ratio for halving dt ≈ 2^p.
    for (m, p, dt) in [
        (Method::Gauss4, 4.0, 0.2),
        (Method::Gauss6, 6.0, 0.4),
        (Method::Dopri5, 5.0, 0.0),
    ] {
        let err = |dt: f64| {
            let mut o = opts(m, dt);
            if m == Method::Dopri5 {
                o.rtol = dt;
                o.atol = dt;
            }
            let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &[2.0], &o).unwrap();
            ((tr.y[0] - 2f64.cos()).powi(2) + (tr.y[1] + 2f64.sin()).powi(2)).sqrt()
        };
        if m == Method::Dopri5 {
            // Tolerance proportionality: error shrinks with tol.
            assert!(err(1e-10) < 1e-8 && err(1e-6) < 1e-4);
            continue;
        }
        let ratio = err(dt) / err(dt / 2.0);
        assert!(
            (ratio.log2() - p).abs() < 0.3,
            "{m:?}: observed order {}",
            ratio.log2()
        );
    }
}

#[test]
fn dopri5_tableau_satisfies_order_conditions() {
    for i in 0..7 {
        let s: f64 = DP_A[i].iter().sum();
        assert!((s - DP_C[i]).abs() < 1e-14, "row {i}");
    }
    for k in 0..5 {
        let s: f64 = (0..7).map(|i| DP_B[i] * DP_C[i].powi(k)).sum();
        assert_relative_eq!(s, 1.0 / (k as f64 + 1.0), max_relative = 1e-14);
    }
    for k in 0..4 {
        let s: f64 = (0..7).map(|i| DP_BHAT[i] * DP_C[i].powi(k)).sum();
        assert_relative_eq!(s, 1.0 / (k as f64 + 1.0), max_relative = 1e-14);
    }
}

#[test]
fn dop853_is_eighth_order_on_the_oscillator() {
    // Fixed steps through the sampling: with huge tolerances no step is
    // rejected, and steps of 0.1 land on the samples.
    let err = |h: f64| {
        let times: Vec<f64> = (1..=(2.0 / h).round() as usize)
            .map(|k| k as f64 * h)
            .collect();
        let o = Options {
            method: Method::Dop853,
            dt: h,
            rtol: 1e3,
            atol: 1e3,
            max_steps: MAX_STEPS as u64,
        };
        let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &times, &o).unwrap();
        let n = tr.y.len();
        (tr.y[n - 2] - 2f64.cos()).abs()
    };
    let ratio = err(0.2) / err(0.1);
    assert!((ratio.log2() - 8.0).abs() < 0.5, "order {}", ratio.log2());
}

#[test]
fn gauss16_is_exact_to_roundoff_on_the_oscillator() {
    let tr = integrate(&Osc, &[1.0, 0.0], 0.0, &[10.0], &opts(Method::Gauss16, 0.5)).unwrap();
    assert!((tr.y[0] - 10f64.cos()).abs() < 1e-13);
    assert_eq!(tr.steps, 20);
}

#[test]
fn gauss_keeps_the_integrals_on_generic() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let times: Vec<f64> = (1..=100).map(|k| k as f64).collect();
    for m in [Method::Gauss4, Method::Gauss6, Method::Gauss16] {
        let tr = integrate(&top, &L0, 0.0, &times, &opts(m, 0.05)).unwrap();
        let h0 = integrals4(&A, &L0);
        let last: [f64; 6] = tr.y[tr.y.len() - 6..].try_into().unwrap();
        let h = integrals4(&A, &last);
        for i in 0..4 {
            // Roundoff only: ~2000 steps, sqrt growth → a few 1e-15.
            assert_relative_eq!(h[i], h0[i], max_relative = 1e-13);
        }
    }
}

#[test]
fn bad_options_are_errors() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    for dt in [0.0, -1.0, f64::NAN] {
        assert!(integrate(&top, &L0, 0.0, &[1.0], &opts(Method::Gauss6, dt)).is_err());
    }
    assert!(integrate(&top, &L0, 0.0, &[2.0, 1.0], &opts(Method::Gauss6, 0.1)).is_err());
    assert!(integrate(&top, &L0, 0.0, &[1e300], &opts(Method::Gauss6, 1e-300)).is_err());
    assert!(matches!(
        integrate(&top, &L0, 0.0, &[10.0], &opts(Method::Gauss6, 10.0)),
        Err(Error::NoConvergence { .. })
    ));
}

#[test]
fn batch_matches_single_runs() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let mut y0s = L0.to_vec();
    y0s.extend(L0.iter().map(|x| 0.5 * x));
    let times = [0.0, 1.0, 2.0];
    let o = opts(Method::Gauss6, 0.1);
    for parallel in [false, true] {
        let (ys, _) = integrate_many(&top, &y0s, 0.0, &times, &o, parallel).unwrap();
        for (b, y0) in y0s.chunks(6).enumerate() {
            let tr = integrate(&top, y0, 0.0, &times, &o).unwrap();
            assert_eq!(&ys[b * 18..(b + 1) * 18], &tr.y[..]);
        }
    }
}

/// Pseudo-random states (seeded LCG), entries in [-1, 1).
fn states(seed: u64, rows: usize) -> Vec<f64> {
    let mut s = seed;
    (0..rows * 6)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

/// The lane kernels (gauss16, dop853) give exactly the single-trajectory
/// results, for batch sizes that are not multiples of the lane width, with
/// repeated and zero-length sample intervals.
#[test]
fn lane_kernels_match_single_runs_bit_for_bit() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let times = [0.0, 0.7, 0.7, 2.0, 3.5];
    for rows in [1usize, 3, 7, 37] {
        let y0s = states(rows as u64, rows);
        for (m, dt) in [
            (Method::Gauss16, 0.3),
            (Method::Dop853, 0.0),
            (Method::Taylor, 0.0),
            (Method::Taylor, 0.3),
        ] {
            let o = opts(m, dt);
            for parallel in [false, true] {
                let (ys, steps) = integrate_many(&top, &y0s, 0.0, &times, &o, parallel).unwrap();
                let mut want_steps = 0;
                for (b, y0) in y0s.chunks(6).enumerate() {
                    let tr = integrate(&top, y0, 0.0, &times, &o).unwrap();
                    let got = &ys[b * 30..(b + 1) * 30];
                    let same = got
                        .iter()
                        .zip(&tr.y)
                        .all(|(x, y)| x.to_bits() == y.to_bits());
                    assert!(same, "{m:?} rows {rows} state {b}: {got:?} vs {:?}", tr.y);
                    want_steps += tr.steps;
                }
                assert_eq!(steps, want_steps, "{m:?} rows {rows}");
            }
        }
    }
}

/// A cancelled token stops every path with `Interrupted`.
#[test]
fn cancelled_runs_stop() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let c = Cancel::never();
    c.cancel();
    let y0s = states(5, 9);
    for (m, dt) in [
        (Method::Gauss16, 0.3),
        (Method::Dop853, 0.0),
        (Method::Gauss6, 0.01),
        (Method::Dopri5, 0.0),
        (Method::Taylor, 0.0),
    ] {
        let o = opts(m, dt);
        let r = integrate_with(&top, &L0, 0.0, &[1e3], &o, &c);
        assert_eq!(r.unwrap_err(), Error::Interrupted, "{m:?}");
        for parallel in [false, true] {
            let r = integrate_many_with(&top, &y0s, 0.0, &[1e3], &o, parallel, &c);
            assert_eq!(r.unwrap_err(), Error::Interrupted, "{m:?}");
        }
    }
}

/// Taylor's method: its tolerance range is checked, it refuses any field but
/// so(4)'s, and it stays on the flow: against gauss16 at a small step (a
/// different method, converged to roundoff) on 'generic''s l0 to t = 10.
#[test]
fn taylor_checks_and_agrees_with_gauss16() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    for rtol in [0.0, f64::EPSILON / 2.0, 2e-3, f64::NAN] {
        let o = Options {
            rtol,
            ..opts(Method::Taylor, 0.0)
        };
        match integrate(&top, &L0, 0.0, &[1.0], &o) {
            Err(Error::InvalidArgument { what: "rtol", .. }) => {}
            other => panic!("rtol {rtol}: {other:?}"),
        }
    }
    let o = Options {
        rtol: f64::EPSILON,
        ..opts(Method::Taylor, 0.0)
    };
    for r in [
        integrate(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o).map(|_| ()),
        integrate_many(&Osc, &[1.0, 0.0], 0.0, &[1.0], &o, false).map(|_| ()),
    ] {
        assert!(matches!(
            r,
            Err(Error::InvalidArgument { what: "method", .. })
        ));
    }
    let times = [0.0, 2.5, 10.0];
    let tr = integrate(&top, &L0, 0.0, &times, &o).unwrap();
    let g = integrate(&top, &L0, 0.0, &times, &opts(Method::Gauss16, 0.02)).unwrap();
    for (a, b) in tr.y.iter().zip(&g.y) {
        // both at roundoff: ~100-500 steps, O(1) state
        assert!((a - b).abs() < 1e-13, "{a} vs {b}");
    }
    assert_eq!(&tr.y[..6], &L0[..], "the sample at t0 is the initial state");
    assert_eq!(tr.evals, tr.steps * taylor::order(f64::EPSILON) as u64);
}

/// Over-budget runs are refused before any work, naming the cause.
#[test]
fn budget_is_checked_first_and_names_the_cause() {
    let spacing: Vec<f64> = (1..=100).map(f64::from).collect();
    let e = check_budget(Method::Dop853, 0.0, &spacing, 0.0, 50).unwrap_err();
    assert!(e.to_string().contains("sample spacing"), "{e}");
    let e = check_budget(Method::Gauss16, 0.0, &[1e6], 0.1, 1000).unwrap_err();
    assert!(e.to_string().contains("dt:"), "{e}");
    // 100 intervals of 1 at dt = 0.6: 200 steps, although 100 / 0.6 < 170.
    let e = check_budget(Method::Gauss16, 0.0, &spacing, 0.6, 170).unwrap_err();
    assert!(e.to_string().contains("sample spacing"), "{e}");
    assert!(check_budget(Method::Gauss16, 0.0, &spacing, 0.6, 200).is_ok());
}

/// Taylor's largest step bounds its step count from below: a run that cannot
/// fit `max_steps` at steps of at most `dt` is refused before any work.
#[test]
fn taylor_with_a_tiny_largest_step_is_refused_first() {
    let times = [10.0];
    let e = check_budget(Method::Taylor, 0.0, &times, 5e-324, 100_000_000).unwrap_err();
    assert!(e.to_string().contains("dt: (t_end - t0) / dt"), "{e}");
    // dt = 0 (no largest step) leaves the count to the error control.
    assert!(check_budget(Method::Taylor, 0.0, &times, 0.0, 10).is_ok());
    assert!(check_budget(Method::Taylor, 0.0, &times, 0.5, 20).is_ok());
    assert!(check_budget(Method::Taylor, 0.0, &times, 0.5, 19).is_err());
    // Dense samples cost a Taylor run no steps beyond the intervals' own.
    let dense: Vec<f64> = (1..=100).map(|k| 0.1 * k as f64).collect();
    assert!(check_budget(Method::Taylor, 0.0, &dense, 0.5, 100).is_ok());
}

/// An output that cannot be allocated is an error, not an abort.
#[test]
fn huge_output_is_an_error() {
    assert!(matches!(
        alloc_output(usize::MAX, 2),
        Err(Error::TooLarge { .. })
    ));
    assert!(alloc_output(usize::MAX / 4, 1).is_err());
    let just_over = crate::numeric::alloc::MAX_BYTES / 48 + 1;
    assert!(alloc_output(just_over, 6).is_err());
    assert_eq!(alloc_output(1, 3).unwrap(), vec![0.0; 3]);
}

#[test]
fn subnormal_steps_restart_the_stages() {
    // A subnormal h once made 0/0 (h b_j) in the predictor and an infinite
    // ratio h / last_h on the next normal step.
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let times = [1e-320, 2e-320, 1.0];
    for m in [Method::Gauss4, Method::Gauss16] {
        let tr = integrate(&top, &L0, 0.0, &times, &opts(m, 0.05)).unwrap();
        assert_eq!(&tr.y[..6], &L0[..], "a subnormal step cannot move l");
        let direct = integrate(&top, &L0, 0.0, &[1.0], &opts(m, 0.05)).unwrap();
        for k in 0..6 {
            // Same step on [0, 1]; only the restart of the stage guess differs.
            assert!((tr.y[12 + k] - direct.y[k]).abs() < 1e-14);
        }
    }
    let osc = integrate(
        &Osc,
        &[1.0, 0.0],
        0.0,
        &[5e-324, 1.0],
        &opts(Method::Gauss6, 0.1),
    );
    assert!(osc.unwrap().y.iter().all(|v| v.is_finite()));
}

#[test]
fn step_budget_counts_every_sample_of_a_call() {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let times: Vec<f64> = (1..=100).map(f64::from).collect();
    for m in [Method::Dopri5, Method::Dop853, Method::Gauss6] {
        let mut o = opts(m, if m == Method::Gauss6 { 0.1 } else { 0.0 });
        let full = integrate(&top, &L0, 0.0, &times, &o).unwrap();
        // Each sample interval needs fewer steps than the budget, the call more.
        o.max_steps = full.steps / 2;
        let err = integrate(&top, &L0, 0.0, &times, &o).unwrap_err();
        assert!(err.to_string().contains("max_steps"), "{err}");
        o.max_steps = full.steps;
        assert_eq!(integrate(&top, &L0, 0.0, &times, &o).unwrap().y, full.y);
    }
    let mut o = opts(Method::Gauss6, 0.1);
    o.max_steps = 0;
    assert!(o.validate().is_err());
}
