use super::clebsch::{ClebschConjugacy, ClebschSolution, CLEBSCH_RTOL};
use super::*;
use crate::integrate::{integrate, integrate_many, Method, Options};
use crate::numeric::cancel::Cancel;
use crate::numeric::test_rng::Rng;
use crate::so4::FrahmTop;

/// A random body with a dense, positive definite energy: `Q = G Gᵀ + I/2`.
fn random_body(rng: &mut Rng) -> KirchhoffBody {
    let g: [f64; 36] = rng.vec();
    let mut q = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            q[i][j] = (0..6).map(|k| g[6 * i + k] * g[6 * j + k]).sum::<f64>() * 0.5;
        }
        q[i][i] += 0.5;
    }
    let a: Vec<f64> = (0..9).map(|k| q[k / 3][k % 3]).collect();
    let b: Vec<f64> = (0..9).map(|k| q[k / 3][3 + k % 3]).collect();
    let c: Vec<f64> = (0..9).map(|k| q[3 + k / 3][3 + k % 3]).collect();
    KirchhoffBody::new(&a, &b, &c).unwrap()
}

fn cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

fn opts(method: Method, dt: f64) -> Options {
    Options {
        method,
        dt,
        rtol: 1e-13,
        atol: 1e-13,
        max_steps: 100_000_000,
    }
}

#[test]
fn field_is_kirchhoffs_equations() {
    let mut rng = Rng(7);
    for _ in 0..20 {
        let body = random_body(&mut rng);
        let y: [f64; 6] = rng.vec();
        let (m, p) = ([y[0], y[1], y[2]], [y[3], y[4], y[5]]);
        let (a, b, c) = (body.a(), body.b(), body.c());
        let w: [f64; 3] = std::array::from_fn(|i| {
            (0..3)
                .map(|k| a[3 * i + k] * m[k] + b[3 * i + k] * p[k])
                .sum()
        });
        let v: [f64; 3] = std::array::from_fn(|i| {
            (0..3)
                .map(|k| b[3 * k + i] * m[k] + c[3 * i + k] * p[k])
                .sum()
        });
        let (mw, pv, pw) = (cross(m, w), cross(p, v), cross(p, w));
        let f = body.vector_field(&y);
        for i in 0..3 {
            approx::assert_relative_eq!(f[i], mw[i] + pv[i], epsilon = 1e-14);
            approx::assert_relative_eq!(f[3 + i], pw[i], epsilon = 1e-14);
        }
        // H = ½ yᵀ Q y.
        let q = body.energy_matrix();
        let yv = nalgebra::Vector6::from_row_slice(&y);
        approx::assert_relative_eq!(
            body.hamiltonian(&y),
            0.5 * yv.dot(&(q * yv)),
            epsilon = 1e-14
        );
        // ∂H/∂y by central differences = (ω, v).
        let h = 1e-6;
        for k in 0..6 {
            let (mut yp, mut ym) = (y, y);
            yp[k] += h;
            ym[k] -= h;
            let g = (body.hamiltonian(&yp) - body.hamiltonian(&ym)) / (2.0 * h);
            let want = if k < 3 { w[k] } else { v[k - 3] };
            assert!((g - want).abs() < 1e-8, "dH/dy_{k}: {g} vs {want}");
        }
    }
}

#[test]
fn lanes_give_the_bits_of_single_states() {
    let mut rng = Rng(11);
    for diag in [false, true] {
        let body = if diag {
            KirchhoffBody::new(
                &[1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0],
                &[0.1, 0.0, 0.0, 0.0, 0.2, 0.0, 0.0, 0.0, -0.3],
                &[2.0, 0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, 0.7],
            )
            .unwrap()
        } else {
            random_body(&mut rng)
        };
        let ys: [[f64; 6]; 8] = std::array::from_fn(|_| rng.vec());
        let lanes: [[f64; 8]; 6] = std::array::from_fn(|k| std::array::from_fn(|i| ys[i][k]));
        let mut out = [[0.0; 8]; 6];
        body.vector_field_lanes(&lanes, &mut out);
        for i in 0..8 {
            let f = body.vector_field(&ys[i]);
            for k in 0..6 {
                assert_eq!(f[k].to_bits(), out[k][i].to_bits());
            }
        }
    }
}

#[test]
fn bad_bodies_are_refused() {
    let i3 = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let z = [0.0; 9];
    assert!(KirchhoffBody::new(&i3, &z, &i3).is_ok());
    // Not symmetric.
    let mut a = i3;
    a[1] = 0.1;
    assert!(matches!(
        KirchhoffBody::new(&a, &z, &i3),
        Err(Error::NotSymmetric { what: "A", .. })
    ));
    // Not positive definite: names the eigenvalues and the Casimir remedy.
    let mut c = i3;
    c[0] = -1.0;
    let e = KirchhoffBody::new(&i3, &z, &c).unwrap_err().to_string();
    assert!(
        e.contains("positive definite") && e.contains("kappa"),
        "{e}"
    );
    // Semidefinite (B couples M and p fully).
    assert!(KirchhoffBody::new(&i3, &i3, &i3).is_err());
    // Shapes and NaN.
    assert!(matches!(
        KirchhoffBody::new(&i3[..8], &z, &i3),
        Err(Error::Shape { what: "A", .. })
    ));
    let mut n = i3;
    n[4] = f64::NAN;
    assert!(matches!(
        KirchhoffBody::new(&i3, &z, &n),
        Err(Error::NonFinite { what: "C", .. })
    ));
}

#[test]
fn gauss16_keeps_the_casimirs_and_the_energy() {
    let mut rng = Rng(3);
    let body = random_body(&mut rng);
    let y0: [f64; 6] = rng.vec();
    let dt = 1.0 / (body.rate_scale() * 6f64.sqrt());
    let times: Vec<f64> = (1..=100).map(|k| k as f64).collect();
    let tr = integrate(&body, &y0, 0.0, &times, &opts(Method::Gauss16, dt)).unwrap();
    let (c0, h0) = (casimirs(&y0), body.hamiltonian(&y0));
    for row in tr.y.chunks_exact(6) {
        let y: [f64; 6] = row.try_into().unwrap();
        let (c, h) = (casimirs(&y), body.hamiltonian(&y));
        assert!((c[0] - c0[0]).abs() <= 1e-13 * c0[0]);
        assert!((c[1] - c0[1]).abs() <= 1e-13 * c0[0].max(1.0));
        assert!((h - h0).abs() <= 1e-13 * h0);
    }
    // And agrees with dop853 at tight tolerance while the (chaotic) motion has
    // not yet amplified rounding: on [0, 10] (the two differ by 1e-6 at t = 100).
    let short = &times[..10];
    let g = integrate(&body, &y0, 0.0, short, &opts(Method::Gauss16, dt)).unwrap();
    let d = integrate(&body, &y0, 0.0, short, &opts(Method::Dop853, 0.0)).unwrap();
    let err =
        g.y.iter()
            .zip(&d.y)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(err < 1e-11, "gauss16 vs dop853 on [0, 10]: {err:e}");
}

#[test]
fn batches_give_the_bits_of_single_runs() {
    let mut rng = Rng(5);
    let body = random_body(&mut rng);
    let y0s: Vec<f64> = (0..5 * 6).map(|_| rng.uniform()).collect();
    let times = [0.5, 1.0, 2.0];
    let o = opts(Method::Gauss16, 0.05);
    let (ys, _) = integrate_many(&body, &y0s, 0.0, &times, &o, true).unwrap();
    for (r, y0) in y0s.chunks_exact(6).enumerate() {
        let one = integrate(&body, y0, 0.0, &times, &o).unwrap();
        assert_eq!(&ys[r * 18..(r + 1) * 18], &one.y[..]);
    }
}

#[test]
fn the_body_in_space_keeps_its_impulse_and_moment() {
    let mut rng = Rng(9);
    let body = random_body(&mut rng);
    let y: [f64; 6] = rng.vec();
    let mut s0 = vec![0.0; SPACE_DIM];
    s0[..6].copy_from_slice(&y);
    for i in 0..3 {
        s0[6 + 4 * i] = 1.0;
    }
    let motion = SpaceMotion { body: &body };
    let times: Vec<f64> = (1..=50).map(|k| 0.5 * k as f64).collect();
    let tr = integrate(&motion, &s0, 0.0, &times, &opts(Method::Gauss16, 0.02)).unwrap();
    let space = |s: &[f64]| -> ([f64; 3], [f64; 3]) {
        let r = &s[6..15];
        let rv = |u: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|i| r[3 * i] * u[0] + r[3 * i + 1] * u[1] + r[3 * i + 2] * u[2])
        };
        let p = rv([s[3], s[4], s[5]]);
        let rm = rv([s[0], s[1], s[2]]);
        let xp = cross([s[15], s[16], s[17]], p);
        (p, [rm[0] + xp[0], rm[1] + xp[1], rm[2] + xp[2]])
    };
    let (p0, k0) = space(&s0);
    for row in tr.y.chunks_exact(SPACE_DIM) {
        let (p, k) = space(row);
        for i in 0..3 {
            assert!((p[i] - p0[i]).abs() < 1e-13, "P drifts: {p:?} vs {p0:?}");
            assert!((k[i] - k0[i]).abs() < 1e-11, "K drifts: {k:?} vs {k0:?}");
        }
        // R stays a rotation.
        let r = &row[6..15];
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| r[3 * i + k] * r[3 * j + k]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((d - want).abs() < 1e-13);
            }
        }
    }
}

/// A Clebsch body `C_i = κ + θ A_j A_k` with positive `A`.
fn clebsch_body(a: [f64; 3], theta: f64, kappa: f64) -> ([f64; 3], [f64; 3]) {
    let c = [
        kappa + theta * a[1] * a[2],
        kappa + theta * a[2] * a[0],
        kappa + theta * a[0] * a[1],
    ];
    (a, c)
}

fn diag9(d: [f64; 3]) -> [f64; 9] {
    [d[0], 0.0, 0.0, 0.0, d[1], 0.0, 0.0, 0.0, d[2]]
}

#[test]
fn clebsch_field_is_conjugate_to_a_manakov_top() {
    let mut rng = Rng(21);
    for trial in 0..30 {
        let a = [
            0.5 + rng.uniform().abs(),
            0.5 + rng.uniform().abs(),
            0.5 + rng.uniform().abs(),
        ];
        let (a, c) = clebsch_body(a, 2.0 * rng.uniform(), 3.0);
        let conj = ClebschConjugacy::new(&a, &c).unwrap();
        let al = conj.alpha();
        assert!(al[0] == 0.0 && al.windows(2).all(|w| w[0] < w[1]) && al[3] == 1.0);
        let body = KirchhoffBody::new(&diag9(a), &[0.0; 9], &diag9(c)).unwrap();
        let top = FrahmTop::manakov(conj.alpha(), conj.beta()).unwrap();
        for _ in 0..5 {
            let y: [f64; 6] = rng.vec();
            let l = conj.to_so4(&y);
            let mut lhs = [0.0; 6];
            top.vector_field(&l, &mut lhs);
            let rhs = conj.to_so4(&body.vector_field(&y));
            let scale = rhs.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for k in 0..6 {
                assert!(
                    (lhs[k] - rhs[k]).abs() <= 1e-13 * scale,
                    "trial {trial}: X(L y) = {lhs:?} vs L X(y) = {rhs:?}"
                );
            }
            let back = conj.to_body(&l);
            for k in 0..6 {
                assert!((back[k] - y[k]).abs() <= 4.0 * f64::EPSILON * y[k].abs());
            }
        }
    }
}

#[test]
fn clebsch_condition_and_degenerate_bodies_are_refused() {
    let (a, mut c) = clebsch_body([1.0, 2.0, 3.0], 0.5, 1.0);
    assert!(ClebschConjugacy::new(&a, &c).is_ok());
    c[0] *= 1.0 + 10.0 * CLEBSCH_RTOL;
    let e = ClebschConjugacy::new(&a, &c).unwrap_err().to_string();
    assert!(e.contains("Clebsch's condition"), "{e}");
    // C1 = C2 (and A1 = A2): Kirchhoff's axisymmetric case.
    let (a, c) = clebsch_body([1.0, 1.0, 3.0], 0.5, 1.0);
    let e = ClebschConjugacy::new(&a, &c).unwrap_err().to_string();
    assert!(e.contains("axisymmetric"), "{e}");
    // All C equal.
    assert!(ClebschConjugacy::new(&[1.0, 2.0, 3.0], &[2.0; 3]).is_err());
    assert!(ClebschConjugacy::new(&[0.0, 2.0, 3.0], &[1.0, 2.0, 3.0]).is_err());
}

#[test]
fn clebsch_closed_form_follows_the_integration() {
    let (a, c) = clebsch_body([0.7, 1.3, 2.2], 0.6, 1.5);
    let conj = ClebschConjugacy::new(&a, &c).unwrap();
    let body = KirchhoffBody::new(&diag9(a), &[0.0; 9], &diag9(c)).unwrap();
    // A generic state, and one with M·p = 0 exactly (the conjugate top's
    // h0 = 0: a regular level set, reduced through its limit).
    for y0 in [
        [0.4, -0.7, 0.9, 0.8, 0.3, -0.5],
        [1.0, 2.0, 0.0, 2.0, -1.0, 3.0],
    ] {
        let sol = ClebschSolution::new(conj.clone(), &y0).unwrap();
        let times: Vec<f64> = (0..=40).map(|k| 0.5 * k as f64).collect();
        let tr = integrate(&body, &y0, 0.0, &times, &opts(Method::Gauss16, 0.01)).unwrap();
        let mut out = vec![0.0; 6 * times.len()];
        sol.state_batch(&times, &mut out, &Cancel::never()).unwrap();
        let scale = y0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let err = out
            .iter()
            .zip(&tr.y)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(
            err < 1e-12 * scale,
            "closed form vs gauss16 on [0, 20] from {y0:?}: {err:e}"
        );
        let one = sol.state(20.0).unwrap();
        assert_eq!(&one[..], &out[out.len() - 6..]);
    }
}
