use super::*;
use crate::solution::tests::TOPS;

/// Two solutions of the same motion, one through normalized data: their
/// states agree to the genus-2 route's accuracy (~1e-13 relative on [0, 10]).
const SAME_MOTION: f64 = 1e-11;

fn max_rel(x: &[f64], y: &[f64], scale: f64) -> f64 {
    x.iter()
        .zip(y)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()))
        / scale
}

fn norm(l: &[f64; 6]) -> f64 {
    l.iter().map(|v| v * v).sum::<f64>().sqrt()
}

#[test]
fn kinds_of_the_shared_states() {
    for (a, b, l0) in TOPS {
        let m = Motion::new(&a, &b, &l0).unwrap();
        assert_eq!(m.kind(), Kind::Genus2);
        assert_eq!(Motion::new(&a, &b, &[0.0; 6]).unwrap().kind(), Kind::Rest);
        for q in 0..6 {
            let mut l = [0.0; 6];
            l[q] = -0.8;
            assert_eq!(Motion::new(&a, &b, &l).unwrap().kind(), Kind::Equilibrium);
        }
        let planes = [
            [0.4, 0.0, 0.0, 0.0, 0.0, 1.3],
            [0.0, 0.4, 0.0, 0.0, 1.3, 0.0],
        ];
        for l in planes {
            assert_eq!(Motion::new(&a, &b, &l).unwrap().kind(), Kind::Equilibrium);
        }
        let block = [0.4, -0.9, 0.0, 0.3, 0.0, 0.0];
        assert_eq!(Motion::new(&a, &b, &block).unwrap().kind(), Kind::Euler);
        let sd = [0.4, -0.9, 0.3, 0.3, 0.9, 0.4];
        assert_eq!(Motion::new(&a, &b, &sd).unwrap().kind(), Kind::Euler);
        let asd = [0.4, -0.9, -0.3, 0.3, -0.9, -0.4];
        assert_eq!(Motion::new(&a, &b, &asd).unwrap().kind(), Kind::Euler);
        // b = α a + β: spherical.
        let bs = a.map(|x| 0.7 * x + 0.2);
        assert_eq!(Motion::new(&a, &bs, &l0).unwrap().kind(), Kind::Spherical);
    }
}

#[test]
fn the_generic_path_is_unchanged_for_moderate_data() {
    let (a, b, l0) = TOPS[0];
    let m = Motion::new(&a, &b, &l0).unwrap();
    let s = Solution::new(&a, &b, &l0).unwrap();
    let t: Vec<f64> = (0..50).map(|k| 0.7 * k as f64).collect();
    let mut o1 = vec![0.0; 300];
    let mut o2 = vec![0.0; 300];
    m.l_batch(&t, &mut o1, &Cancel::never()).unwrap();
    s.l_batch(&t, &mut o2, &Cancel::never()).unwrap();
    assert_eq!(o1, o2);
}

#[test]
fn scaled_states_follow_l_of_s_l0_equals_s_l_of_s_t() {
    let t: Vec<f64> = (0..21).map(|k| 0.5 * k as f64).collect();
    for (a, b, l0) in TOPS {
        for l in [
            l0,
            [0.4, -0.9, 0.0, 0.3, 0.0, 0.0],
            [0.4, -0.9, 0.3, 0.3, 0.9, 0.4],
        ] {
            let base = Motion::new(&a, &b, &l).unwrap();
            for s in [1e-150, 1e150, 3.0e-7, 2f64.powi(40)] {
                let ls = l.map(|v| v * s);
                let m = Motion::new(&a, &b, &ls).unwrap();
                assert_eq!(m.kind(), base.kind());
                let ts: Vec<f64> = t.iter().map(|x| x / s).collect();
                let mut o1 = vec![0.0; 6 * t.len()];
                let mut o2 = vec![0.0; 6 * t.len()];
                m.l_batch(&ts, &mut o1, &Cancel::never()).unwrap();
                base.l_batch(&t, &mut o2, &Cancel::never()).unwrap();
                let o2s: Vec<f64> = o2.iter().map(|v| v * s).collect();
                let err = max_rel(&o1, &o2s, norm(&l) * s);
                assert!(
                    err < SAME_MOTION,
                    "a = {a:?}, l = {l:?}, s = {s:e}: {err:e}"
                );
            }
        }
    }
}

#[test]
fn shifted_a_gives_the_same_motion() {
    let t: Vec<f64> = (0..21).map(|k| 0.5 * k as f64).collect();
    for (a, b, l0) in TOPS {
        let base = Motion::new(&a, &b, &l0).unwrap();
        let mut o2 = vec![0.0; 6 * t.len()];
        base.l_batch(&t, &mut o2, &Cancel::never()).unwrap();
        for shift in [1e6, -1e6, 1e9] {
            let a6 = a.map(|v| v + shift);
            // b shifted with the same a keeps c: b' = b + (a' − a) · 0 and
            // the c_ij of the doubles (b_i − b_j)/(a6_i − a6_j).
            let m = Motion::new(&a6, &b, &l0).unwrap();
            assert_eq!(m.kind(), Kind::Genus2);
            let mut o1 = vec![0.0; 6 * t.len()];
            m.l_batch(&t, &mut o1, &Cancel::never()).unwrap();
            // The reference is the flow of the shifted doubles' c, which
            // differs from the unshifted c by the rounding of a + shift.
            let mut c = [[0.0; 16]; 1];
            let cc = crate::so4::manakov_c(&a6, &b).unwrap();
            c[0].copy_from_slice(&cc);
            let top = crate::so4::FrahmTop::new(4, &c[0]).unwrap();
            let opts = crate::integrate::Options {
                method: crate::integrate::Method::Gauss16,
                dt: 1e-2,
                rtol: 0.0,
                atol: 0.0,
                max_steps: 10_000_000,
            };
            let traj = crate::integrate::integrate(&top, &l0, 0.0, &t, &opts).unwrap();
            let err = max_rel(&o1, &traj.y, norm(&l0));
            assert!(err < SAME_MOTION, "shift {shift:e}, a = {a:?}: {err:e}");
        }
    }
}

/// A genus-2 state whose closed form cannot be built (the reduction refuses
/// it) is of kind [`Kind::Integrated`]: `l(t)` is the confirmed integration
/// in double-double, at every call. Draw 921 of the harsh draw of
/// tests/data/every_state_harsh.py (components from 7.9e-5 to 2.0e5;
/// F(s) (19) has a repeated root to double precision), against the
/// quadruple-precision reference of tests/data/longdouble_ref.py
/// (`reference_quad`) at the end of its window.
#[test]
fn a_state_without_a_closed_form_is_integrated() {
    let a = [
        -0.40479253116618286,
        42.304798225664136,
        42.31061822972205,
        42.82083809160014,
    ];
    let b = [
        0.6428522984348821,
        -113.6114258865171,
        -245.78800591972782,
        -947.5605312431403,
    ];
    let l0 = [
        6606.538820057217,
        -109.13243355654599,
        -198984.87716968727,
        -11.791448622088316,
        -117.11871122851196,
        7.907522737757678e-05,
    ];
    let t = 2.2118745405398934e-07;
    let quad = [
        18747.52085127394,
        989.9264563901506,
        198198.03043773773,
        2.776829483693518,
        -1935.1081788673716,
        -7.064288108108099,
    ];
    assert!(Solution::new(&a, &b, &l0).is_err());
    let m = Motion::new(&a, &b, &l0).unwrap();
    assert_eq!(m.kind(), Kind::Integrated);
    assert!(m.genus2().is_none() && m.closed_form_frequency().is_none());
    assert!(
        m.stand_ins().1.contains("repeated root"),
        "{}",
        m.stand_ins().1
    );
    let times = [-t, 0.0, t / 2.0, t];
    let mut out = vec![0.0; 6 * times.len()];
    m.l_batch(&times, &mut out, &Cancel::never()).unwrap();
    assert_eq!(&out[6..12], &l0[..]);
    assert!(max_rel(&out[18..], &quad, norm(&l0)) <= 1e-14);
    // backwards: the same motion reversed returns to l0 (the time-reversed
    // flow of (1) from l(-t) is the forward one)
    let back = Motion::new(&a, &b, &out[..6].try_into().unwrap()).unwrap();
    let mut again = [0.0; 6];
    back.l_batch(&[t], &mut again, &Cancel::never()).unwrap();
    assert!(max_rel(&again, &l0, norm(&l0)) <= 1e-12);
    assert_eq!(m.stand_ins().0, 1);
    // calls that integrate nothing are not counted
    m.l_batch(&[0.0], &mut [0.0; 6], &Cancel::never()).unwrap();
    m.l_batch(&[], &mut [], &Cancel::never()).unwrap();
    assert_eq!(m.stand_ins().0, 1);
    // the kind has no torus: a refusal naming the step, not invalid input
    match crate::tori::motion::torus_of_motion(&m, &Cancel::never()) {
        Err(Error::Unverified { reason, .. }) => {
            assert!(reason.contains("repeated root"), "{reason}")
        }
        other => panic!("not refused: {:?}", other.map(|_| ())),
    }
}
