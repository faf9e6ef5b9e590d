use super::*;
use crate::integrate::{integrate, Method, Options};
use crate::numeric::cancel::Cancel;
use crate::so4::{self, FrahmTop};
use crate::solution::tests::TOPS;

/// gauss16 with dt = 1e-2 errs by ~1e-15 per unit time on these O(1)
/// problems; the closed form must agree to well below the 1e-10 over
/// [0, 20].
const AGREE: f64 = 1e-12;

fn gauss16(c4: &[f64; 6], l0: &[f64; 6], times: &[f64]) -> Vec<f64> {
    let mut c = [0.0; 16];
    for (q, &(i, j)) in so4::PAIRS4.iter().enumerate() {
        c[4 * i + j] = c4[q];
        c[4 * j + i] = c4[q];
    }
    let top = FrahmTop::new(4, &c).unwrap();
    let opts = Options {
        method: Method::Gauss16,
        dt: 1e-2,
        rtol: 0.0,
        atol: 0.0,
        max_steps: 100_000_000,
    };
    let _ = Cancel::never();
    integrate(&top, l0, 0.0, times, &opts).unwrap().y
}

fn c4_of(a: &[f64; 4], b: &[f64; 4]) -> [f64; 6] {
    let c = so4::manakov_c(a, b).unwrap();
    [c[1], c[2], c[3], c[6], c[7], c[11]]
}

fn max_dev(emb: Embedding, top: &EulerTop, reference: &[f64], times: &[f64]) -> f64 {
    let mut dev = 0.0f64;
    for (k, &t) in times.iter().enumerate() {
        let l = emb.state(&top.m(t));
        for q in 0..6 {
            dev = dev.max((l[q] - reference[6 * k + q]).abs());
        }
    }
    dev
}

#[test]
fn blocks_and_self_dual_states_follow_the_integrator_on_the_shared_tops() {
    let times: Vec<f64> = (1..=40).map(|k| 0.5 * k as f64).collect();
    let mut seed = 12345u64;
    let mut rnd = || {
        // xorshift: a fixed, dependency-free stream of O(1) components.
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut worst = 0.0f64;
    for (a, b, _) in TOPS {
        let c4 = c4_of(&a, &b);
        let mut embs: Vec<Embedding> = Embedding::BLOCKS
            .iter()
            .map(|&k| Embedding::Block(k))
            .collect();
        embs.push(Embedding::SelfDual(1));
        embs.push(Embedding::SelfDual(-1));
        for emb in embs {
            for _ in 0..3 {
                let m0 = [rnd(), rnd(), rnd()];
                let l0 = emb.state(&m0);
                assert_eq!(Embedding::of_state(&l0), Some(emb));
                assert_eq!(emb.m_of(&l0), m0);
                let top = EulerTop::new(emb.w_of(&c4), m0).unwrap();
                assert_eq!(top.regime(), EulerRegime::Elliptic);
                let start = emb.state(&top.m(0.0));
                assert!(
                    (0..6).all(|q| (start[q] - l0[q]).abs() <= 4.0 * f64::EPSILON),
                    "{emb:?}: l(0)"
                );
                let reference = gauss16(&c4, &l0, &times);
                let dev = max_dev(emb, &top, &reference, &times);
                worst = worst.max(dev);
                assert!(dev < AGREE, "a = {a:?}, {emb:?}, m0 = {m0:?}: {dev:e}");
            }
        }
    }
    eprintln!("worst deviation from gauss16 on [0, 20]: {worst:e}");
}

#[test]
fn the_integrals_are_constant_along_the_closed_form() {
    let w = [Dd::new(-0.3), Dd::new(1.2), Dd::new(2.9)];
    let m0 = [0.4, -1.1, 0.7];
    let top = EulerTop::new(w, m0).unwrap();
    let e0: f64 = (0..3).map(|i| w[i].hi * m0[i] * m0[i]).sum();
    let g0: f64 = m0.iter().map(|v| v * v).sum();
    for k in 0..200 {
        let m = top.m(0.37 * k as f64);
        let e: f64 = (0..3).map(|i| w[i].hi * m[i] * m[i]).sum();
        let g: f64 = m.iter().map(|v| v * v).sum();
        assert!(
            (e - e0).abs() < 1e-14 && (g - g0).abs() < 1e-14,
            "t = {}",
            0.37 * k as f64
        );
    }
}

#[test]
fn the_period_is_4k_over_omega() {
    let w = [Dd::new(1.0), Dd::new(2.5), Dd::new(4.0)];
    for m0 in [[0.3, 1.0, 0.2], [1.0, 0.1, 0.4], [0.7, 0.7, 0.1]] {
        let top = EulerTop::new(w, m0).unwrap();
        let nu = top.frequency();
        let back = top.m(1.0 / nu);
        let half = top.m(0.5 / nu);
        for i in 0..3 {
            assert!((back[i] - m0[i]).abs() < 1e-13, "{m0:?}");
        }
        // Not a shorter period: half way round, M differs.
        assert!((0..3).any(|i| (half[i] - m0[i]).abs() > 1e-3), "{m0:?}");
    }
}

#[test]
fn axisymmetric_and_spherical_tops() {
    // W_1 = W_2: M_3 constant, (M_1, M_2) rotating at Ω = (W_3 − W_1) M_3.
    let w = [Dd::new(1.0), Dd::new(1.0), Dd::new(3.0)];
    let m0 = [0.6, -0.2, 0.5];
    let top = EulerTop::new(w, m0).unwrap();
    assert_eq!(top.regime(), EulerRegime::Axisymmetric);
    let om = (3.0 - 1.0) * 0.5;
    for k in 0..50 {
        let t = 0.9 * k as f64;
        let m = top.m(t);
        // Ṁ_1 = (W_3 − W_2) M_2 M_3 = Ω M_2: M_1 = M1 cos Ωt + M2 sin Ωt.
        let (s, c) = (om * t).sin_cos();
        assert!((m[0] - (0.6 * c - 0.2 * s)).abs() < 1e-14);
        assert!((m[1] - (-0.2 * c - 0.6 * s)).abs() < 1e-14);
        assert_eq!(m[2], 0.5);
    }
    assert!((top.frequency() - om / (2.0 * std::f64::consts::PI)).abs() < 1e-16);
    let top = EulerTop::new([Dd::new(2.0); 3], m0).unwrap();
    assert_eq!(top.regime(), EulerRegime::Rest);
    assert_eq!(top.m(17.0), m0);
}

#[test]
fn states_on_an_axis_are_at_rest() {
    let w = [Dd::new(1.0), Dd::new(2.0), Dd::new(4.0)];
    for m0 in [
        [0.0, 0.0, 0.0],
        [1.5, 0.0, 0.0],
        [0.0, -2.0, 0.0],
        [0.0, 0.0, 3.0],
    ] {
        let top = EulerTop::new(w, m0).unwrap();
        assert_eq!(top.regime(), EulerRegime::Rest);
        assert_eq!(top.m(10.0), m0);
    }
}

#[test]
fn an_exact_separatrix_state_moves_on_the_separatrix() {
    // W = (1, 2, 3): middle axis 2; Δ = (1 − 2) M_1² + (3 − 2) M_3² = 0 for
    // |M_1| = |M_3| (exact in doubles).
    let w = [Dd::new(1.0), Dd::new(2.0), Dd::new(3.0)];
    // The four heteroclinic orbits through the signs of (M_1, M_3), and both
    // directions of travel (M_2 of either sign).
    let c4 = [-3.0, -2.0, 0.0, -1.0, 0.0, 0.0];
    let emb = Embedding::Block([0, 1, 2]);
    let times: Vec<f64> = (1..=20).map(|k| 0.25 * k as f64).collect();
    for m0 in [
        [0.5, 0.25, 0.5],
        [0.5, -0.25, 0.5],
        [-0.5, 0.25, 0.5],
        [0.5, 0.75, -0.5],
        [-0.5, -0.1, -0.5],
    ] {
        let top = EulerTop::new(w, m0).unwrap();
        assert_eq!(top.regime(), EulerRegime::Separatrix);
        let start = top.m(0.0);
        assert!(
            (0..3).all(|i| (start[i] - m0[i]).abs() < 1e-15),
            "{m0:?}: {start:?}"
        );
        let reference = gauss16(&c4, &emb.state(&m0), &times);
        let dev = max_dev(emb, &top, &reference, &times);
        assert!(dev < AGREE, "{m0:?}: {dev:e}");
    }
    let m0 = [0.5, 0.25, -0.5];
    let top = EulerTop::new(w, m0).unwrap();
    assert_eq!(top.regime(), EulerRegime::Separatrix);
    assert_eq!(top.frequency(), 0.0);
    // Against the integrator (the block {1,2,3} of c = (1, 2, ·, 3, ·, ·) with
    // W = −(c23, c13, c12)).
    assert_eq!(emb.w_of(&c4).map(|x| x.hi), [1.0, 2.0, 3.0]);
    let times: Vec<f64> = (1..=20).map(|k| 0.5 * k as f64).collect();
    let reference = gauss16(&c4, &emb.state(&m0), &times);
    let dev = max_dev(emb, &top, &reference, &times);
    assert!(dev < AGREE, "{dev:e}");
    // It tends to the unstable axis: M → (0, ±|M|, 0).
    let far = top.m(60.0);
    assert!(far[0].abs() < 1e-12 && far[2].abs() < 1e-12);
    assert!((far[1].abs() - (0.5f64 * 0.5 * 2.0 + 0.0625).sqrt()).abs() < 1e-14);
}

#[test]
fn near_the_separatrix_the_elliptic_form_stays_accurate() {
    // Δ = 2^-40 and 2^-80 relative: m1 = 1 − m tiny, K ≈ ln(4/k') large.
    let w = [Dd::new(1.0), Dd::new(2.0), Dd::new(3.0)];
    let times: Vec<f64> = (1..=30).map(|k| 0.5 * k as f64).collect();
    let c4 = [-3.0, -2.0, 0.0, -1.0, 0.0, 0.0];
    let emb = Embedding::Block([0, 1, 2]);
    for e in [-20, -40] {
        let m0 = [0.5, 0.25, -0.5 * (1.0 + (e as f64).exp2())];
        let top = EulerTop::new(w, m0).unwrap();
        assert_eq!(top.regime(), EulerRegime::Elliptic);
        assert!(top.parameters()[1] < 1e-5);
        let reference = gauss16(&c4, &emb.state(&m0), &times);
        let dev = max_dev(emb, &top, &reference, &times);
        assert!(dev < 1e-11, "e = {e}: {dev:e}");
    }
}

#[test]
fn large_times_keep_the_phase() {
    // M(t + n T) = M(t) for the period T = 1/ν; at n ~ 1e6 the error is
    // that of ν times t (relative 1e-16 · 1e6).
    let w = [Dd::new(-0.5), Dd::new(0.25), Dd::new(1.5)];
    let m0 = [0.3, 0.9, -0.4];
    let top = EulerTop::new(w, m0).unwrap();
    let t = 1.0e6 / top.frequency();
    let m = top.m(t);
    for i in 0..3 {
        assert!((m[i] - m0[i]).abs() < 1e-8, "{m:?}");
    }
}

#[test]
fn extreme_component_ratios_are_solved() {
    // Components 1e-170 … 1e-300 beside O(1) ones: their squares underflow;
    // Δ, the amplitudes and k' are formed without squaring them.
    let w = [Dd::new(-1.777), Dd::new(-0.529), Dd::new(0.875)];
    let cases = [
        [0.0, -1e-300, 1.0],
        [0.0, -1e-170, 1.0],
        [1e-170, 1.0, 0.0],
        [1e-200, 0.0, 1.0],
        [0.3, 1.0, 1e-160],
    ];
    for m0 in cases {
        let top = EulerTop::new(w, m0).unwrap();
        for t in [0.0, 1.0, 37.0, 1e4] {
            let m = top.m(t);
            assert!(m.iter().all(|v| v.is_finite()), "{m0:?} at {t}: {m:?}");
            let g: f64 = m.iter().map(|v| v * v).sum();
            let g0: f64 = m0.iter().map(|v| v * v).sum();
            assert!((g - g0).abs() <= 1e-15 * g0, "{m0:?} at {t}");
        }
        // Near the middle axis (W_2) the motion is elliptic with k' ~ the
        // small components (not a separatrix).
        if m0[1] == 1.0 {
            assert_eq!(top.regime(), EulerRegime::Elliptic, "{m0:?}");
            assert!(top.frequency() > 0.0);
        }
    }
}
