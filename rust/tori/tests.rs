use super::*;
use crate::theta::theta_all;

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// The seven characteristics of P_0, P_23, P_31, P_12, P_14, P_24, P_34 on the
/// `simple` curve of docs/theta_quotients.md (bits a1 a2 b1 b2).
const SIMPLE: [Char; 7] = [
    [1, 0, 0, 0],
    [0, 0, 0, 1],
    [1, 1, 0, 1],
    [1, 1, 0, 0],
    [1, 0, 0, 1],
    [0, 1, 0, 1],
    [0, 1, 0, 0],
];

/// A small deterministic generator (no dependency on rand).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
    }
    fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + ((self.next() * (hi - lo + 1) as f64) as i64).min(hi - lo)
    }
}

fn random_tau(r: &mut Lcg) -> Tau {
    let (x, y, z) = (r.next() - 0.5, r.next() - 0.5, r.next() - 0.5);
    // Im τ = B Bᵀ + 0.3 I, positive definite.
    let b = [
        [r.next() + 0.2, r.next() - 0.5],
        [r.next() - 0.5, r.next() + 0.2],
    ];
    let im =
        |i: usize, j: usize| b[i][0] * b[j][0] + b[i][1] * b[j][1] + if i == j { 0.3 } else { 0.0 };
    [
        [c(x, im(0, 0)), c(y, im(0, 1))],
        [c(y, im(1, 0)), c(z, im(1, 1))],
    ]
}

fn im_inv(tau: &Tau) -> [[f64; 2]; 2] {
    let (p, q, r) = (tau[0][0].im, tau[0][1].im, tau[1][1].im);
    let d = p * r - q * q;
    [[r / d, -q / d], [-q / d, p / d]]
}

/// Re(z^H (Im τ)^{-1} w), written out independently of `Metric`.
fn herm(tau: &Tau, z: &C2, w: &C2) -> f64 {
    let h = im_inv(tau);
    let mut s = Complex64::new(0.0, 0.0);
    for i in 0..2 {
        for j in 0..2 {
            s += z[i].conj() * h[i][j] * w[j];
        }
    }
    s.re
}

fn lin(a: f64, x: &C2, b: f64, y: &C2) -> C2 {
    [x[0] * a + y[0] * b, x[1] * a + y[1] * b]
}

/// All lattice points of Λ' in the box |x_i| ≤ B whose image lies in the
/// real span of (p, q), by brute force (distance from the plane by least squares).
fn brute_force(tau: &Tau, p: &C2, q: &C2, chars: &[Char], bound: i64) -> Vec<Coords> {
    let mut hits = Vec::new();
    let (pp, pq, qq) = (herm(tau, p, p), herm(tau, p, q), herm(tau, q, q));
    let det = pp * qq - pq * pq;
    for m1 in -bound..=bound {
        for m2 in -bound..=bound {
            for n1 in -bound..=bound {
                for n2 in -bound..=bound {
                    let x = [m1, m2, n1, n2];
                    if x == [0; 4] || !is_period(chars, &x) {
                        continue;
                    }
                    let z = lattice_point(tau, &x);
                    let (zp, zq) = (herm(tau, p, &z), herm(tau, q, &z));
                    let a = (qq * zp - pq * zq) / det;
                    let b = (pp * zq - pq * zp) / det;
                    let f = lin(a, p, b, q);
                    let d = [z[0] - f[0], z[1] - f[1]];
                    if herm(tau, &d, &d).sqrt() <= 1e-9 * herm(tau, &z, &z).sqrt() {
                        hits.push(x);
                    }
                }
            }
        }
    }
    hits
}

/// Integer coefficients (k1, k2) with x = k1 c1 + k2 c2, if there are any.
fn int_combination(c1: &Coords, c2: &Coords, x: &Coords) -> Option<(i64, i64)> {
    // Solve on the best-conditioned pair of coordinates, then check all four.
    for i in 0..4 {
        for j in i + 1..4 {
            let d = c1[i] * c2[j] - c1[j] * c2[i];
            if d == 0 {
                continue;
            }
            let n1 = x[i] * c2[j] - x[j] * c2[i];
            let n2 = c1[i] * x[j] - c1[j] * x[i];
            if n1 % d != 0 || n2 % d != 0 {
                return None;
            }
            let (k1, k2) = (n1 / d, n2 / d);
            return (0..4)
                .all(|k| k1 * c1[k] + k2 * c2[k] == x[k])
                .then_some((k1, k2));
        }
    }
    None
}

fn check_torus(tau: &Tau, u: &C2, u2: &C2, chars: &[Char], t: &RealTorus, bound: i64) {
    let [l1, l2] = &t.lambda;
    // The basis is in Λ', reduced, oriented, and reproduces U.
    for x in &t.coords {
        assert!(is_period(chars, x));
    }
    let (n1, n2, d12) = (herm(tau, l1, l1), herm(tau, l2, l2), herm(tau, l1, l2));
    assert!(n1 <= n2 * (1.0 + 1e-12), "|λ1|² = {n1} > |λ2|² = {n2}");
    assert!(d12.abs() <= 0.5 * n1 * (1.0 + 1e-12));
    assert!(t.nu[0] >= 0.0 && t.nu[1] >= 0.0);
    let f = lin(t.nu[0], l1, t.nu[1], l2);
    let d = [u[0] - f[0], u[1] - f[1]];
    // U is rebuilt from two O(1) vectors: roundoff only.
    assert!(herm(tau, &d, &d).sqrt() <= 1e-12 * herm(tau, u, u).sqrt());
    // Every lattice point of Λ' in the plane (box search) is an integer
    // combination of the basis, and the basis vectors themselves are found.
    let hits = brute_force(tau, u, u2, chars, bound);
    assert!(!hits.is_empty());
    for x in &hits {
        assert!(
            int_combination(&t.coords[0], &t.coords[1], x).is_some(),
            "{x:?} not in the span of {:?}",
            t.coords
        );
    }
    for x in &t.coords {
        if x.iter().all(|v| v.abs() <= bound) {
            assert!(hits.contains(x));
        }
    }
}

#[test]
fn residues_of_the_simple_table_form_a_subgroup_of_order_two() {
    // The seven characteristics span a 3-dimensional subspace of F_2^4
    // (docs/theta_quotients.md), so Λ'/2Λ has 2^(4-3) = 2 elements.
    let r = period_residues(&SIMPLE);
    assert_eq!(r.len(), 2);
    assert!(r.contains(&[0, 0, 0, 0]));
}

#[test]
fn quotient_signs_match_theta_functions() {
    // θ[χ](v+λ)/θ(v+λ) = sign · θ[χ](v)/θ(v), with theta values from the
    // theta module (independent of the sign rule).
    let mut r = Lcg(7);
    let tau = random_tau(&mut r);
    let flat = [tau[0][0], tau[0][1], tau[1][0], tau[1][1]];
    let v = [c(0.13, 0.07), c(-0.21, 0.11)];
    let (t0, _) = theta_all(&v, &flat, 1e-15).unwrap();
    for _ in 0..20 {
        let x = [r.int(-2, 2), r.int(-2, 2), r.int(-2, 2), r.int(-2, 2)];
        let l = lattice_point(&tau, &x);
        let (t1, _) = theta_all(&[v[0] + l[0], v[1] + l[1]], &flat, 1e-15).unwrap();
        for idx in 0..16 {
            let chi: Char = [
                (idx >> 3) as u8 & 1,
                (idx >> 2) as u8 & 1,
                (idx >> 1) as u8 & 1,
                idx as u8 & 1,
            ];
            let ratio = (t1[idx] / t1[0]) / (t0[idx] / t0[0]);
            let s = quotient_sign(&chi, &x) as f64;
            // Quotients of O(1) theta values at O(1) arguments: roundoff.
            assert!(
                (ratio - s).norm() < 1e-9,
                "x {x:?} chi {chi:?} ratio {ratio}"
            );
        }
    }
}

#[test]
fn real_plane_of_a_diagonal_tau() {
    // τ = i diag(1.3, 0.8), U and U' real: the plane is Re C² = R², which
    // meets Λ in Z² (n = 0); Λ' ∩ R² is {m : (m, 0) ∈ Λ'}.
    let tau = [[c(0.0, 1.3), c(0.0, 0.0)], [c(0.0, 0.0), c(0.0, 0.8)]];
    let u = [c(0.37, 0.0), c(0.52, 0.0)];
    let u2 = [c(-0.2, 0.0), c(0.9, 0.0)];
    let t = real_torus(&tau, &u, &u2, &SIMPLE).unwrap();
    check_torus(&tau, &u, &u2, &SIMPLE, &t, 4);
    for x in &t.coords {
        assert_eq!((x[2], x[3]), (0, 0));
    }
}

#[test]
fn random_lattices_match_a_brute_force_search() {
    let mut r = Lcg(2026);
    let mut n_ok = 0;
    for case in 0..40 {
        let tau = random_tau(&mut r);
        // A plane through two random points of Λ' (doubled if needed).
        let pick = |r: &mut Lcg| {
            let x = [r.int(-2, 2), r.int(-2, 2), r.int(-2, 2), r.int(-2, 2)];
            if is_period(&SIMPLE, &x) {
                x
            } else {
                x.map(|v| 2 * v)
            }
        };
        let (x1, x2) = (pick(&mut r), pick(&mut r));
        let (l1, l2) = (lattice_point(&tau, &x1), lattice_point(&tau, &x2));
        if herm(&tau, &l1, &l1) * herm(&tau, &l2, &l2) - herm(&tau, &l1, &l2).powi(2) < 1e-3 {
            continue;
        }
        let u = lin(r.next() + 0.1, &l1, r.next() - 0.5, &l2);
        let u2 = lin(r.next() - 0.5, &l1, r.next() + 0.1, &l2);
        let t = real_torus(&tau, &u, &u2, &SIMPLE).unwrap_or_else(|e| panic!("case {case}: {e:?}"));
        check_torus(&tau, &u, &u2, &SIMPLE, &t, 5);
        for x in [&x1, &x2] {
            assert!(int_combination(&t.coords[0], &t.coords[1], x).is_some());
        }
        n_ok += 1;
    }
    assert!(n_ok >= 30);
}

#[test]
fn basis_convention_is_independent_of_the_spanning_flows() {
    // The same plane from another pair of flows gives the same reduced basis
    // and frequencies of the same U.
    let mut r = Lcg(11);
    let tau = random_tau(&mut r);
    let (x1, x2) = ([2, 0, 1, -1], [0, 2, 0, 2]);
    let (l1, l2) = (lattice_point(&tau, &x1), lattice_point(&tau, &x2));
    let u = lin(0.31, &l1, 0.17, &l2);
    let a = real_torus(&tau, &u, &lin(-0.4, &l1, 1.1, &l2), &SIMPLE).unwrap();
    let b = real_torus(&tau, &u, &lin(2.0, &l1, 0.3, &l2), &SIMPLE).unwrap();
    assert_eq!(a.coords, b.coords);
    for k in 0..2 {
        assert!((a.nu[k] - b.nu[k]).abs() <= 1e-13 * a.nu[0].max(a.nu[1]));
    }
}

#[test]
fn failures_are_named() {
    let tau = [[c(0.0, 1.3), c(0.0, 0.0)], [c(0.0, 0.0), c(0.0, 0.8)]];
    let u = [c(0.37, 0.0), c(0.52, 0.0)];
    let par = [c(0.74, 0.0), c(1.04, 0.0)];
    assert!(matches!(
        real_torus(&tau, &u, &par, &SIMPLE),
        Err(TorusFailure::DegeneratePlane { .. })
    ));
    // A generic complex plane meets the lattice in no rank-2 lattice.
    let w = [c(0.3, 0.1 * std::f64::consts::SQRT_2), c(0.5, -0.7)];
    let w2 = [c(-0.2, std::f64::consts::E / 7.0), c(0.9, 0.11)];
    assert!(matches!(
        real_torus(&tau, &w, &w2, &SIMPLE),
        Err(TorusFailure::NoRealLattice { .. })
    ));
    let nan = [c(f64::NAN, 0.0), c(0.0, 0.0)];
    assert_eq!(
        real_torus(&tau, &nan, &u, &SIMPLE),
        Err(TorusFailure::NonFinite)
    );
    let bad = [[c(0.0, -1.0), c(0.0, 0.0)], [c(0.0, 0.0), c(0.0, 0.8)]];
    assert_eq!(
        real_torus(&bad, &u, &w, &SIMPLE),
        Err(TorusFailure::ImagTauNotPositive)
    );
    let e: Error = TorusFailure::DegeneratePlane { sin_angle: 0.0 }.into();
    // The failure stays data; the message reads as before ("invalid real torus: …").
    assert_eq!(
        e,
        Error::NoRealTorus {
            failure: TorusFailure::DegeneratePlane { sin_angle: 0.0 }
        }
    );
    assert_eq!(
        e.to_string(),
        "invalid real torus: the two flows do not span a real plane (sin of their angle 0e0)"
    );
    assert_eq!(solve::classify(&e), Status::DegeneratePlane);
}

/// The status codes and their names come from one table: every code is its
/// index, and `name` agrees with `STATUS_NAMES`.
#[test]
fn status_codes_and_names_agree() {
    assert_eq!(Status::ALL.len(), STATUS_NAMES.len());
    for (code, s) in Status::ALL.iter().enumerate() {
        assert_eq!(*s as usize, code);
        assert_eq!(s.name(), STATUS_NAMES[code]);
    }
    assert_eq!(
        Status::InconsistentQuotients.name(),
        "inconsistent quotients"
    );
}

#[test]
fn map_states_keeps_order_and_stops_when_cancelled() {
    let states: Vec<u64> = (0..1000).collect();
    let out = map_states(&states, |&s| s * s, &Cancel::never()).unwrap();
    assert_eq!(out, states.iter().map(|s| s * s).collect::<Vec<_>>());
    let c = Cancel::never();
    c.cancel();
    assert_eq!(map_states(&states, |&s| s, &c), Err(Error::Interrupted));
    assert!(map_states::<u64, u64, _>(&[], |&s| s, &Cancel::never())
        .unwrap()
        .is_empty());
}

#[test]
fn second_flow_is_the_other_power() {
    let a = [0.3, 1.1, 2.0, 3.7];
    let sq = a.map(|x| x * x);
    let cu = a.map(|x| x * x * x);
    // b = a²: the top's flow is the a² flow, so the second is a³; and back.
    assert_eq!(second_flow_b(&a, &sq), cu);
    assert_eq!(second_flow_b(&a, &cu), sq);
    let mixed: [f64; 4] = std::array::from_fn(|i| 0.5 + sq[i] - 0.1 * cu[i]);
    assert_eq!(second_flow_b(&a, &mixed), cu);
}

#[test]
fn state_statuses_and_nan_policy() {
    // A stand-in for the Theorem: the plane of `real_plane_of_a_diagonal_tau`,
    // or an error chosen by the state.
    let tau = [[c(0.0, 1.3), c(0.0, 0.0)], [c(0.0, 0.0), c(0.0, 0.8)]];
    let solve = |l0: &[f64; 6]| -> Result<FlowData> {
        if l0[0] > 10.0 {
            return Err(Error::RepeatedBranchPoints {
                i: 1,
                j: 2,
                value: c(1.0, 0.0),
            });
        }
        Ok(FlowData {
            tau,
            u: [c(0.37, 0.0), c(0.52, 0.0)],
            u2: [c(-0.2, 0.0), c(0.9, 0.0)],
            chars: SIMPLE.to_vec(),
            w: None,
        })
    };
    let classify = |e: &Error| match e {
        Error::RepeatedBranchPoints { .. } => Status::CoincidingBranchPoints,
        _ => Status::Singular,
    };
    let run = |l0: [f64; 6]| frequencies_of_state(&l0, solve, classify);
    let ok = run([0.8, -0.3, 0.5, 1.1, -0.7, 0.2]);
    assert_eq!(ok.status, Status::Ok);
    assert!((ok.nu[0] - 0.185).abs() < 1e-15 && (ok.nu[1] - 0.26).abs() < 1e-15);
    assert_eq!(run([0.0; 6]).status, Status::ZeroState);
    assert_eq!(
        run([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]).status,
        Status::NonFinite
    );
    // m = n (m = (l23, l31, l12), n = (l14, l24, l34)): h1 = 2 h0.
    assert_eq!(
        run([0.3, -0.2, 0.5, 0.5, 0.2, 0.3]).status,
        Status::SingularCasimirs
    );
    assert_eq!(
        run([11.0, 0.0, 0.0, 0.0, 1.0, 0.0]).status,
        Status::CoincidingBranchPoints
    );
    for l0 in [[0.0; 6], [11.0, 0.0, 0.0, 0.0, 1.0, 0.0]] {
        assert!(run(l0).nu.iter().all(|v| v.is_nan()));
    }
}

mod on_the_solution {
    use super::super::solve::{
        c_pairs, classify, flow_data, rate_for, state_frequencies, state_frequencies_theta,
        torus_of_state, QUOTIENT_RESIDUAL_RTOL,
    };
    use super::super::*;
    use crate::error::SingularKind;
    use crate::solution::Solution;

    use crate::solution::tests::TOPS;

    const GENERIC: ([f64; 4], [f64; 4], [f64; 6]) = TOPS[0];

    #[test]
    fn rate_for_the_tops_own_field_is_the_solutions_rate() {
        let (a, b, l0) = GENERIC;
        let s = Solution::new(&a, &b, &l0).unwrap();
        let u = rate_for(&s, s.c4()).unwrap();
        let r = s.rate();
        for k in 0..2 {
            // The same equations (Solution::rates), rebuilt from the stored
            // constants and a fresh theta jet at v0: equal to rounding.
            assert!((u[k] - r[k]).norm() <= 1e-14 * r[0].norm().max(r[1].norm()));
        }
    }

    #[test]
    fn velocities_are_linear_in_b() {
        // c_ij is linear in b, so U(b) = p2 U(a²) + p3 U(a³) for the cubic
        // interpolant b = p0 + p1 a + p2 a² + p3 a³ (docs/tori.md §2).
        let (a, b, l0) = GENERIC;
        let s = Solution::new(&a, &b, &l0).unwrap();
        let c_of = |bb: [f64; 4]| c_pairs(&a, &bb).unwrap();
        let u2 = rate_for(&s, &c_of(a.map(|x| x * x))).unwrap();
        let u3 = rate_for(&s, &c_of(a.map(|x| x * x * x))).unwrap();
        let v = nalgebra::Matrix4::from_fn(|i, j| a[i].powi(j as i32));
        let p = v
            .lu()
            .solve(&nalgebra::Vector4::from_column_slice(&b))
            .unwrap();
        let r = s.rate();
        for k in 0..2 {
            let lin = u2[k] * p[2] + u3[k] * p[3];
            assert!(
                (lin - r[k]).norm() <= 1e-12 * r[0].norm().max(r[1].norm()),
                "{lin} vs {}",
                r[k]
            );
        }
    }

    #[test]
    fn second_velocity_agrees_with_a_second_solution() {
        // U' by rate_for (the l rows of (9)–(10) at v0) against the set-up of
        // ManakovTop(a, a²) itself (its own U): the same curve and divisor
        // (the reduction depends on a and l0 only), so the same vector.
        for (a, b, l0) in [TOPS[0], TOPS[1]] {
            let s = Solution::new(&a, &b, &l0).unwrap();
            let b2 = a.map(|x| x * x);
            let u2 = rate_for(&s, &c_pairs(&a, &b2).unwrap()).unwrap();
            let r = Solution::new(&a, &b2, &l0).unwrap().rate();
            let scale = r[0].norm().max(r[1].norm());
            for k in 0..2 {
                // Two least-squares fits of the same consistent system with
                // different row sets/weights: agreement to the solution's ~1e-12.
                assert!(
                    (u2[k] - r[k]).norm() <= 1e-10 * scale,
                    "{} vs {}",
                    u2[k],
                    r[k]
                );
            }
        }
    }

    #[test]
    fn frequencies_of_the_generic_top_are_positive_and_rebuild_u() {
        let (a, b, l0) = GENERIC;
        let (t, _) = torus_of_state(&a, &b, &l0, &Cancel::never()).unwrap();
        let s = Solution::new(&a, &b, &l0).unwrap();
        let d = flow_data(&s, &second_flow_b(&a, &b)).unwrap();
        assert!(t.nu[0] > 0.0 && t.nu[1] > 0.0);
        for k in 0..2 {
            let f = t.lambda[0][k] * t.nu[0] + t.lambda[1][k] * t.nu[1];
            assert!((f - d.u[k]).norm() <= 1e-12);
        }
        for x in &t.coords {
            assert!(is_period(&d.chars, x));
        }
        // The map's level-set route against the solution's theta route:
        // the same frequencies up to the accuracy of the constants.
        let e = state_frequencies(&a, &b, &l0);
        assert_eq!(e.status, Status::Ok);
        for k in 0..2 {
            assert!(
                (e.nu[k] - t.nu[k]).abs() <= ROUTES_RTOL * t.nu[k],
                "{:?} vs {:?}",
                e.nu,
                t.nu
            );
        }
    }

    /// The two routes to the frequencies (level set vs theta fit) agree to
    /// the accuracy of the reduction's constants: 3e-15 measured on 'generic'.
    const ROUTES_RTOL: f64 = 1e-12;

    #[test]
    fn the_two_routes_agree_on_the_shared_tops() {
        // near_degenerate: its constants carry ~1e-12 (d_1 − d_2 = 3.8e-5).
        for (n, (a, b, l0)) in SHARED.into_iter().enumerate() {
            let tol = if n == 3 { 1e-10 } else { ROUTES_RTOL };
            let e = state_frequencies(&a, &b, &l0);
            let t = state_frequencies_theta(&a, &b, &l0);
            assert_eq!((e.status, t.status), (Status::Ok, Status::Ok));
            for k in 0..2 {
                assert!(
                    (e.nu[k] - t.nu[k]).abs() <= tol * t.nu[k],
                    "{n}: {e:?} {t:?}"
                );
            }
        }
    }

    #[test]
    fn singular_states_get_their_codes() {
        let (a, b, _) = GENERIC;
        // h0 = 0 exactly (dyadic components), in no so(3) block and not an
        // equilibrium: a genus-2 state (the reduction's limit h0 → 0), with the
        // level-set route's frequencies, bit for bit.
        let l = [0.5, 0.25, 0.125, 0.5, 0.75, 0.25];
        let e = state_frequencies(&a, &b, &l);
        assert_eq!(e.status, Status::Ok, "{e:?}");
        assert!(e.nu.iter().all(|v| v.is_finite()), "{e:?}");
        let o = super::super::solve::state_frequencies_level_set(&a, &b, &l);
        assert_eq!(e.nu.map(f64::to_bits), o.nu.map(f64::to_bits));
        // An so(3) block ({1, 2, 4}) and a self-dual state: Euler tops, with
        // (ν_⊥, ν_E) (crate::solution::transverse).
        for l in [
            [1.0, 0.0, 0.0, 0.0, 0.5, 0.0],
            [0.3, -0.2, 0.5, 0.5, 0.2, 0.3],
        ] {
            let e = state_frequencies(&a, &b, &l);
            assert_eq!(e.status, Status::Ok, "{l:?}");
            assert!(
                e.nu[0] >= 0.0 && e.nu[0] <= 0.5 * e.nu[1] && e.nu[1] > 0.0,
                "{e:?}"
            );
        }
        // l12, l34 only: a stationary rotation.
        let e = state_frequencies(&a, &b, &[1.0, 0.0, 0.0, 0.0, 0.0, 0.5]);
        assert_eq!(e.status, Status::Equilibrium);
        assert!(e.nu.iter().all(|v| v.is_nan()));
        // b = a: every state at rest.
        let e = state_frequencies(&a, &a, &[0.3, -0.2, 0.5, 0.5, 0.2, 0.7]);
        assert_eq!(e.status, Status::Equilibrium);
    }

    fn kind_of(e: Error) -> (&'static str, SingularKind) {
        match e {
            Error::Singular { what, kind, .. } => (what, kind),
            other => panic!("not a Singular error: {other}"),
        }
    }

    #[test]
    fn refusals_of_the_solution_carry_their_kind() {
        let (a, b, _) = GENERIC;
        let new = |l0: [f64; 6]| kind_of(Solution::new(&a, &b, &l0).map(|_| ()).unwrap_err());
        assert_eq!(new([0.0; 6]), ("state l0", SingularKind::ZeroState));
        // an so(3)-block state: h0 = 0 with the roots of h1 s² − h2 s + h3 at a_j
        assert_eq!(
            new([1.0, 0.0, 0.0, 0.0, 0.5, 0.0]),
            ("state l", SingularKind::RepeatedRoot)
        );
        // m = n: the solution's own check, before the reduction's.
        assert_eq!(
            new([0.3, -0.2, 0.5, 0.5, 0.2, 0.3]),
            ("state l0", SingularKind::SelfDual)
        );
        // 1e-12 from an equilibrium: the roots of F near a_3, a_4 are found
        // (in the local parameter w = sqrt(s - a_i), kotter/pairs.rs), but
        // Delta_1^(3) (25) vanishes to working precision there.
        assert_eq!(
            new([1.0, 0.0, 0.0, 0.0, 0.0, 1e-12]),
            ("state l", SingularKind::CoincidingBranchPoints)
        );
        assert_eq!(
            new([1.0, 0.0, 0.0, 0.0, 0.0, 0.5]),
            ("state l", SingularKind::RepeatedRoot)
        );
    }

    #[test]
    fn every_kind_has_its_status() {
        // Written out, so that a new kind or a changed code shows here.
        let table = [
            (SingularKind::ZeroState, Status::ZeroState),
            (SingularKind::VanishingH0, Status::CoincidingBranchPoints),
            (SingularKind::SelfDual, Status::SingularCasimirs),
            (
                SingularKind::CoincidingBranchPoints,
                Status::CoincidingBranchPoints,
            ),
            (SingularKind::RepeatedRoot, Status::CoincidingBranchPoints),
            (SingularKind::DivisorAtInfinity, Status::DivisorAtInfinity),
            (
                SingularKind::DegenerateGradients,
                Status::DegenerateGradients,
            ),
        ];
        for (kind, status) in table {
            let e = Error::Singular {
                what: "state l0",
                kind,
                reason: String::new(),
            };
            assert_eq!(classify(&e), status, "{kind:?}");
        }
        let other = Error::InvalidArgument {
            what: "state l",
            reason: "h0 = 0 coincide infinity".into(),
        };
        let inconsistent = Error::Singular {
            what: super::super::solve::INCONSISTENT,
            kind: SingularKind::InconsistentQuotients,
            reason: String::new(),
        };
        assert_eq!(classify(&inconsistent), Status::InconsistentQuotients);
        // The message no longer decides the code.
        assert_eq!(classify(&other), Status::Singular);
        assert_eq!(
            classify(&Error::NoConvergence {
                what: "x",
                tol: 0.0,
                reached: 1.0,
                iterations: 1
            }),
            Status::NoConvergence
        );
    }

    /// The four shared tops (/work/shared/reference/problems.json).
    use crate::solution::tests::TOPS as SHARED;

    #[test]
    fn consistent_set_ups_fit_both_flows() {
        for (a, b, l0) in SHARED {
            let s = Solution::new(&a, &b, &l0).unwrap();
            let c2 = c_pairs(&a, &second_flow_b(&a, &b)).unwrap();
            let fits = s.rates(&[*s.c4(), c2]).unwrap();
            for (_, res) in &fits {
                assert!(*res <= 1e-3 * QUOTIENT_RESIDUAL_RTOL, "a = {a:?}: {res:e}");
            }
        }
    }

    #[test]
    fn the_former_inconsistent_set_up_is_consistent() {
        // State 14 of tests/data/tori_naff_random100.py (seed 1313): `solve`
        // took the wrong combination of (41) there (ε → −1/(d_4 ε), docs/errata.md)
        // and returned l(0) = l0 with l'(0) off by 300 % (residual of the
        // velocity fit ~0.2). With the combination fixed by (40) it fits.
        let a = [
            0.6262672408286707,
            1.1558542100739666,
            3.9251780045549682,
            4.5883259242255034,
        ];
        let b = [
            -0.05178024146863031,
            -0.42179480568224204,
            -0.1045833884785173,
            -0.5348591116146967,
        ];
        let l0 = [
            -0.7041138736314696,
            0.538991160465901,
            -0.27246109242831956,
            0.26712289621603547,
            1.7213065155493528,
            -0.22470690403864946,
        ];
        let s = Solution::new(&a, &b, &l0).unwrap();
        let fits = s.rates(&[*s.c4()]).unwrap();
        assert!(
            fits[0].1 <= 1e-3 * QUOTIENT_RESIDUAL_RTOL,
            "{:e}",
            fits[0].1
        );
        let e = state_frequencies(&a, &b, &l0);
        assert_eq!(e.status, Status::Ok);
        assert!(e.nu.iter().all(|v| v.is_finite()));
    }
}

/// The dispatcher keeps the frequency map's bits on genus-2 states of
/// moderate data (the identity frame): the level-set route as before.
#[test]
fn moderate_genus2_states_keep_the_map_bits() {
    use crate::tori::solve::{state_frequencies, state_frequencies_level_set};
    let shared = crate::solution::tests::TOPS;
    for (a, b, l0) in shared {
        for k in 0..8 {
            let l: [f64; 6] =
                std::array::from_fn(|q| l0[q] * (1.0 + 0.05 * ((k * 7 + q) % 5) as f64));
            let e = state_frequencies(&a, &b, &l);
            let o = state_frequencies_level_set(&a, &b, &l);
            assert_eq!(e.status, o.status);
            assert_eq!(
                e.nu.map(f64::to_bits),
                o.nu.map(f64::to_bits),
                "{a:?} {l:?}"
            );
        }
    }
}

/// ν of the level-set route with the route forced (`None`: by the spread).
fn nu_by_route(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6], route: Option<bool>) -> [f64; 2] {
    use crate::solution::motion::classify;
    use crate::solution::normalize::TopFrame;
    use crate::tori::solve::{c_pairs, level_set_flow_data_route};
    let frame = TopFrame::new(a, b).unwrap();
    let (_, _, ln) = classify(&frame, l0);
    let c2 = c_pairs(&frame.a, &frame.second_flow_b()).unwrap();
    let d = level_set_flow_data_route(&frame.a, &frame.c4, &c2, &ln, route).unwrap();
    real_torus_with_rates(&d.tau, &d.u, &d.u2, &d.chars, d.w.as_ref())
        .unwrap()
        .nu
}

/// Where the branch points of (8) spread over many orders of magnitude (here
/// 1.3e10: a state of a top with two close `a_i`, from a draw like the harsh
/// one of tests/data/every_state_harsh.py) the periods in double are good to ε
/// of the largest only, and the frequencies from them are off by 6.6e-12. The
/// map takes the DD route there ([`solve::DD_SPREAD`]); on moderate tops it
/// keeps the double route, within 5e-15 of the DD one.
#[test]
fn spread_branch_points_take_the_dd_route() {
    let a = [
        0.8472218437873744,
        3.536529566159616,
        3.544338765167191,
        3.678495720337954,
    ];
    let b = [
        0.7492541778815034,
        -8.055547654286608,
        -8.054132390752505,
        -8.018062349315318,
    ];
    let l0 = [
        2.4127139795326155e-5,
        1.4735266795282608e-6,
        -6691.400104168625,
        10.500476636712293,
        -13447.962188614489,
        749486.3911317746,
    ];
    let rel = |x: [f64; 2], y: [f64; 2]| {
        (x[0] - y[0]).abs().max((x[1] - y[1]).abs()) / y[0].abs().max(y[1].abs())
    };
    let (auto, dd, double) = (
        nu_by_route(&a, &b, &l0, None),
        nu_by_route(&a, &b, &l0, Some(true)),
        nu_by_route(&a, &b, &l0, Some(false)),
    );
    assert_eq!(auto.map(f64::to_bits), dd.map(f64::to_bits));
    assert!(rel(double, dd) > 1e-12, "{double:?} {dd:?}");
    // the test tops: the double route where their spread allows it, within
    // 5e-15 of the DD one either way
    let mut double_routes = 0;
    for (a, b, l0) in crate::solution::tests::TOPS {
        let (auto, dd) = (
            nu_by_route(&a, &b, &l0, None),
            nu_by_route(&a, &b, &l0, Some(true)),
        );
        let double = nu_by_route(&a, &b, &l0, Some(false));
        if auto.map(f64::to_bits) == double.map(f64::to_bits) {
            double_routes += 1;
        } else {
            assert_eq!(auto.map(f64::to_bits), dd.map(f64::to_bits));
        }
        assert!(rel(auto, dd) <= 5e-15, "{a:?}: {auto:?} {dd:?}");
        assert!(rel(double, dd) <= 5e-15, "{a:?}: {double:?} {dd:?}");
    }
    assert!(double_routes >= 2);
}

/// Where the spread of the branch points is at most [`solve::DD_SPREAD`],
/// the double route (the one the map takes there) is within 1e-14 of the DD
/// one, relative: 300 random tops (`a` in [−2, 2], `b` in [−2, 2], `l0` in
/// [−1, 1]⁶, a fixed xorshift sequence).
#[test]
fn the_double_route_is_good_where_the_spread_is_moderate() {
    use crate::solution::motion::{classify, Kind};
    use crate::solution::normalize::TopFrame;
    use crate::tori::solve::{c_pairs, level_set_flow_data_route, needs_dd};
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = |lo: f64, hi: f64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    let (mut checked, mut worst) = (0, 0.0f64);
    for _ in 0..300 {
        let mut a: [f64; 4] = std::array::from_fn(|_| uniform(-2.0, 2.0));
        a.sort_by(f64::total_cmp);
        let b: [f64; 4] = std::array::from_fn(|_| uniform(-2.0, 2.0));
        let l0: [f64; 6] = std::array::from_fn(|_| uniform(-1.0, 1.0));
        let Ok(frame) = TopFrame::new(&a, &b) else {
            continue;
        };
        let (kind, _, ln) = classify(&frame, &l0);
        if kind != Kind::Genus2 {
            continue;
        }
        let c2 = c_pairs(&frame.a, &frame.second_flow_b()).unwrap();
        let nu = |dd: bool| -> Option<[f64; 2]> {
            let d = level_set_flow_data_route(&frame.a, &frame.c4, &c2, &ln, Some(dd)).ok()?;
            real_torus_with_rates(&d.tau, &d.u, &d.u2, &d.chars, d.w.as_ref())
                .ok()
                .map(|t| t.nu)
        };
        let Ok(ls) = crate::solution::level_set_curve(&frame.a, &ln) else {
            continue;
        };
        if needs_dd(&ls.curve) {
            continue;
        }
        if let (Some(x), Some(y)) = (nu(false), nu(true)) {
            let rel = (x[0] - y[0]).abs().max((x[1] - y[1]).abs()) / y[0].abs().max(y[1].abs());
            worst = worst.max(rel);
            checked += 1;
        }
    }
    assert!(checked >= 60, "{checked}");
    assert!(worst <= 1e-14, "{worst:e} over {checked}");
    eprintln!("double vs DD where the spread is moderate: {worst:e} over {checked} states");
}

/// Draw 48 of the harsh random draw (tests/data/every_state_harsh.py, seed
/// 20261125): the branch points of (8) spread over 1e30, and the theta
/// quotients' velocity check leaves 1.8e-9 (above the 1e-10 the frequencies
/// are vouched for to), so the map refused the state. The Abel images of
/// integrated states vouch for `U` instead; it agrees with the slope of the
/// Abel images of a trajectory integrated in 80-bit long double over 20
/// periods (tests/data/frequency_abel_check.py; `X` below, `Y = 0`) to 1.1e-12.
/// A velocity off by 1e-8 fails the same check.
#[test]
fn the_abel_map_of_integrated_states_vouches_for_u_where_the_thetas_cannot() {
    use crate::solution::verify::abel_rate_defect;
    use crate::tori::solve::{c_pairs, state_frequencies, FREQUENCY_VELOCITY_RTOL};
    let a = [
        -0.9256184990074312,
        279.5208482998301,
        279.7404819891023,
        633.6897780257893,
    ];
    let b = [
        0.7214233479274308,
        0.803524043302418,
        0.13253913180949373,
        0.15850845930244173,
    ];
    let l0 = [
        -24227.877002259997,
        -4.465596212550228e-05,
        -4.466639654445864e-05,
        -9.437204342422283e-05,
        0.0030091702881019362,
        9.001940697342075e-05,
    ];
    // the long-double Abel fit's lattice rates
    let x_ref: [f64; 2] = [-659.1365549602779, 12.179008547527214];
    let e = state_frequencies(&a, &b, &l0);
    assert_eq!(e.status, Status::Ok);
    assert!(e.nu.iter().all(|v| v.is_finite() && *v > 0.0), "{:?}", e.nu);
    let sol = crate::solution::Solution::new(&a, &b, &l0).unwrap();
    assert!(sol.velocity_check() > FREQUENCY_VELOCITY_RTOL);
    let c4 = c_pairs(&a, &b).unwrap();
    let u = sol.rate();
    let (x, y) = sol.curve().lattice_coordinates(&u);
    for k in 0..2 {
        assert!((x[k] - x_ref[k]).abs() <= 1e-10 * x_ref[0].abs(), "{x:?}");
        assert!(y[k].abs() <= 1e-10 * x_ref[0].abs(), "{y:?}");
    }
    let cancel = Cancel::never();
    let d = abel_rate_defect(&sol, &c4, sol.c4_lo(), &u, &cancel).unwrap();
    assert!(d <= FREQUENCY_VELOCITY_RTOL, "{d:e}");
    let off = [u[0] * (1.0 + 1e-8), u[1]];
    let d = abel_rate_defect(&sol, &c4, sol.c4_lo(), &off, &cancel).unwrap();
    assert!(d > 1e-9, "{d:e}");
    // the frequencies of `sol.torus` are the map's
    let t = crate::tori::solve::torus_of_state(&a, &b, &l0, &Cancel::never())
        .unwrap()
        .0;
    assert_eq!(t.nu.map(f64::to_bits), e.nu.map(f64::to_bits));
}

/// A state of the harsh draw (seed 5) next to a pinched curve (branch points
/// spread over 1e18), whose `U` is the theta quotients' fit (the closed form
/// misses their equations by 0.29): its frequencies need the Abel-map check.
/// Integrated in double, its small components (down to 1e-9 of `|l0|`) carry
/// the rounding, and the Abel images move along `U` only to 3.2e-10; in
/// double-double to ~3e-13, as against a quadruple-precision trajectory
/// (3.4e-13, tests/data/frequency_abel_check.py). Its spectrum puts the
/// frequencies at 3100-3105 and 62635-62640 (tests/test_every_state.py).
#[test]
fn double_double_decides_where_the_double_runs_of_the_abel_check_are_off() {
    use crate::solution::verify::abel_rate_defect;
    use crate::tori::solve::{state_frequencies, FREQUENCY_VELOCITY_RTOL};
    let a = [
        -0.10907535773028432,
        256.5114084997023,
        527.71611990517,
        527.732721070654,
    ];
    let b = [
        0.0583713087223785,
        -47.56369265254456,
        -47.60399835624438,
        -37.35655009504283,
    ];
    let l0 = [
        33.516747842930975,
        -36.70711236162657,
        804481.9029273331,
        2472.88455969831,
        -1862.481230191442,
        -0.0010016427544778436,
    ];
    let e = state_frequencies(&a, &b, &l0);
    assert_eq!(e.status, Status::Ok);
    let mut nu = e.nu;
    nu.sort_by(f64::total_cmp);
    assert!(
        (nu[0] - 3102.5).abs() <= 5.0 && (nu[1] - 62637.5).abs() <= 5.0,
        "{nu:?}"
    );
    let m = crate::solution::motion::Motion::new(&a, &b, &l0).unwrap();
    let sol = m.genus2().expect("a genus-2 motion");
    let d = abel_rate_defect(sol, sol.c4(), sol.c4_lo(), &sol.rate(), &Cancel::never()).unwrap();
    assert!(d <= FREQUENCY_VELOCITY_RTOL, "{d:e}");
}

/// Draw 927 of the harsh draw (tests/data/every_state_harsh.py, seed 20261125;
/// branch points spread over 1e26): its theta quotients fail the self-check
/// (defect 2.0e-10), so its solution is kept for its certified `l(t)`, and the
/// earlier code refused its torus. The frequencies use none of the quotients'
/// constants: the Abel images of integrated states vouch for the closed form's
/// `U` and `U'`, and `U` agrees with the slope of the Abel images of a
/// long-double trajectory over 20 periods to 5.6e-16 of the largest lattice
/// rate (tests/data/frequency_abel_check.py).
#[test]
fn a_solution_that_fails_its_self_check_has_the_frequencies_the_abel_images_vouch_for() {
    use crate::solution::motion::Motion;
    use crate::tori::solve::{state_frequencies, torus_of_state};
    let a = [
        -0.7602688355914728,
        -0.7581946759199528,
        58.01446061429555,
        58.02456787736087,
    ];
    let b = [
        -0.28375241315964983,
        -0.30510857946001957,
        -0.29813703787396717,
        -0.3002112913105826,
    ];
    let l0 = [
        -5.567493763149003e-06,
        -1.079508644208164,
        675.3544042539954,
        -152399.66258918872,
        1.2270140457595652e-06,
        0.35257708939333,
    ];
    // the long-double Abel fit's lattice rates (normalized frame)
    let x_ref: [f64; 2] = [-0.02263767538871286, 0.000996531291781728];
    let m = Motion::new(&a, &b, &l0).unwrap();
    let sol = m.genus2().expect("a genus-2 motion");
    assert!(sol.certify_every().is_some());
    let (t, _) = torus_of_state(&a, &b, &l0, &Cancel::never()).unwrap();
    let e = state_frequencies(&a, &b, &l0);
    assert_eq!(e.status, Status::Ok);
    assert_eq!(t.nu.map(f64::to_bits), e.nu.map(f64::to_bits));
    // U T = ν1 λ1 + ν2 λ2
    let u: [num_complex::Complex64; 2] = std::array::from_fn(|k| {
        (t.lambda[0][k] * t.nu[0] + t.lambda[1][k] * t.nu[1]) / m.time_scale()
    });
    let (x, y) = sol.curve().lattice_coordinates(&u);
    for k in 0..2 {
        assert!((x[k] - x_ref[k]).abs() <= 1e-12 * x_ref[0].abs(), "{x:?}");
        assert!(y[k].abs() <= 1e-12 * x_ref[0].abs(), "{y:?}");
    }
}

/// Draw 419 of the same harsh draw (branch points spread over 1e13; its
/// solution fails the self-check): the motion moves with the rounding of the
/// normalized `c_ij` by far more than ε. Integrated with `c4` as rounded, the
/// Abel images move along the closed form's `U` only to 6.1e-8 of the phase
/// (which would refuse what the frequency map gives); with `c4 + c4_lo` in
/// double-double to ~6e-17, as a quadruple-precision trajectory of the exact
/// top agrees with `U` to 6.5e-16 (tests/test_every_state.py).
#[test]
fn the_abel_map_check_integrates_the_unrounded_top() {
    use crate::solution::motion::Motion;
    use crate::solution::verify::abel_rate_defect;
    use crate::tori::solve::{state_frequencies, torus_of_state, FREQUENCY_VELOCITY_RTOL};
    let a = [
        -0.372957902310908,
        518.970922110997,
        528.5057515053029,
        528.5541475693918,
    ];
    let b = [
        0.02426807846241763,
        0.02323496172665361,
        -170.7933971919448,
        -170.7944265648801,
    ];
    let l0 = [
        0.01637482784361056,
        42703.46123765193,
        0.00012411891433441858,
        0.00034999164319303113,
        4.946118404808643e-05,
        -2920.9334950443185,
    ];
    let m = Motion::new(&a, &b, &l0).unwrap();
    let sol = m.genus2().expect("a genus-2 motion");
    assert!(sol.certify_every().is_some());
    let cancel = Cancel::never();
    let exact = abel_rate_defect(sol, sol.c4(), sol.c4_lo(), &sol.rate(), &cancel).unwrap();
    assert!(exact <= 1e-12, "{exact:e}");
    let rounded = abel_rate_defect(sol, sol.c4(), &[0.0; 6], &sol.rate(), &cancel).unwrap();
    assert!(rounded > FREQUENCY_VELOCITY_RTOL, "{rounded:e}");
    let (t, _) = torus_of_state(&a, &b, &l0, &cancel).unwrap();
    let e = state_frequencies(&a, &b, &l0);
    assert_eq!(e.status, Status::Ok);
    assert_eq!(t.nu.map(f64::to_bits), e.nu.map(f64::to_bits));
}

/// Draw 989 of the same harsh draw (branch points spread over 6e31; `U` the
/// theta quotients' fit next to a pinched curve): the Abel images of
/// integrated states vouch for `U`, but the second flow's integration exceeds
/// the check's budget, so `U'` cannot be checked. The lattice basis decides:
/// it must be integral to `RATIONAL_TOL` in the plane `U'` fixes, which a
/// plane off by more does not allow. `U` agrees with a quadruple-precision
/// Abel fit to 1.8e-12 (tests/test_every_state.py).
#[test]
fn the_lattice_basis_decides_where_the_second_flow_cannot_be_checked() {
    use crate::solution::motion::Motion;
    use crate::solution::normalize::c_rounding;
    use crate::solution::verify::abel_rate_defect;
    use crate::tori::solve::{c_pairs, state_frequencies, torus_of_state, FREQUENCY_VELOCITY_RTOL};
    let a = [
        -0.13897539582017626,
        83.64154129404191,
        83.64492743384096,
        83.64709272192884,
    ];
    let b = [
        -0.10081634421509844,
        -2.377322434312812,
        -136.56366274243945,
        -135.3452112223749,
    ];
    let l0 = [
        -1.080358529308542e-06,
        2.636230535279978e-05,
        0.0006467681230083904,
        26581.587676304684,
        0.6550686225480357,
        -0.0013776500821983681,
    ];
    let cancel = Cancel::never();
    let (t, u2) = torus_of_state(&a, &b, &l0, &cancel).unwrap();
    let e = state_frequencies(&a, &b, &l0);
    assert_eq!(e.status, Status::Ok);
    assert_eq!(t.nu.map(f64::to_bits), e.nu.map(f64::to_bits));
    let m = Motion::new(&a, &b, &l0).unwrap();
    let sol = m.genus2().expect("a genus-2 motion");
    let d1 = abel_rate_defect(sol, sol.c4(), sol.c4_lo(), &sol.rate(), &cancel).unwrap();
    assert!(d1 <= FREQUENCY_VELOCITY_RTOL, "{d1:e}");
    let b2 = m.frame().second_flow_b();
    let c2 = c_pairs(sol.a(), &b2).unwrap();
    let d2 = abel_rate_defect(sol, &c2, &c_rounding(sol.a(), &b2, &c2), &u2, &cancel).unwrap();
    assert!(d2.is_nan(), "{d2:e}");
}

/// Draw 1724 of the same harsh draw (branch points spread over 1e14 and
/// more; velocity defect 3.1e-9): the Abel images of integrated states do not
/// move along the solution's `U` to the check's bound, but they lie on a line
/// whose slope is the velocity, within it; the frequencies are its
/// coordinates (against a quadruple-precision Abel fit: 6.5e-14,
/// tests/test_every_state.py).
#[test]
fn the_frequencies_rest_on_the_velocity_the_abel_images_move_at() {
    use crate::solution::motion::Motion;
    use crate::solution::verify::abel_rate;
    use crate::tori::solve::{state_frequencies, torus_of_state, ABEL_RATE_RTOL};
    let a = [
        -0.5418066723731292,
        5.489311414050225,
        7.892608735593191,
        8.482776549852908,
    ];
    let b = [
        -0.5061151963599513,
        -0.16699530284397474,
        -0.17447762438702374,
        -0.40448708043917325,
    ];
    let l0 = [
        6.665991411962938e-05,
        -0.00017742300824603844,
        -38703.052749430375,
        0.0005861107858978626,
        13989.820985456234,
        -5.125851437021158e-06,
    ];
    let cancel = Cancel::never();
    let m = Motion::new(&a, &b, &l0).unwrap();
    let sol = m.genus2().expect("a genus-2 motion");
    let r = abel_rate(
        sol,
        sol.c4(),
        sol.c4_lo(),
        &sol.rate(),
        ABEL_RATE_RTOL,
        &cancel,
    )
    .unwrap();
    assert!(
        r.defect > ABEL_RATE_RTOL,
        "the given U holds: {:e}",
        r.defect
    );
    let (w, bound) = r.fit.expect("a velocity fitted to the images");
    assert!(bound <= ABEL_RATE_RTOL, "{bound:e}");
    // the fitted velocity is another than the solution's, by more than the bound
    let (x, y) = sol.curve().lattice_coordinates(&sol.rate());
    let given = [x[0], x[1], y[0], y[1]];
    let rate = given.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let moved = (0..4).fold(0.0f64, |m, q| m.max((w[q] - given[q]).abs())) / rate;
    assert!(moved > ABEL_RATE_RTOL, "{moved:e}");
    let (t, _) = torus_of_state(&a, &b, &l0, &cancel).unwrap();
    let e = state_frequencies(&a, &b, &l0);
    assert_eq!(e.status, Status::Ok);
    assert_eq!(t.nu.map(f64::to_bits), e.nu.map(f64::to_bits));
}

/// Harsh draw 8316 (`tests/data/every_state_harsh.py`): 2.2e-4 (relative)
/// from the so(3) block (1, 3, 4) of a stiff top (`l34` large, `l12` next), where the level set's route
/// refuses; the interpolation next to the block answers, and the slope of the
/// Abel images of a quadruple-precision trajectory over 100 periods
/// (heyoka, `real128`) gives (7915.547952020019, 5432.563682473131), which the
/// answer meets to 3.5e-13. The block's Euler value alone is 7.2e-10 off.
#[test]
fn next_to_a_block_the_frequencies_interpolate_from_the_euler_orbit() {
    use crate::solution::normalize::TopFrame;
    use crate::tori::motion::{state_frequencies_in, state_frequencies_plain};
    use crate::tori::near_euler::NEAR_EULER_RTOL;
    let a = [
        -0.6110918554618494,
        28.096121468103778,
        28.295441156394567,
        28.306037409524382,
    ];
    let b = [
        -0.4655328431848831,
        43.06934905449684,
        43.23986953528779,
        43.23237578830688,
    ];
    let l0 = [
        5.032681551105081,
        -4.711240043085908e-06,
        -0.00014190944736832905,
        -0.000211271346175163,
        -5.320603182556908e-06,
        22415.64352492835,
    ];
    let frame = TopFrame::new(&a, &b).unwrap();
    let cancel = Cancel::never();
    assert_ne!(
        state_frequencies_plain(&frame, &l0, &cancel).status,
        Status::Ok,
        "the level set's route answers: the interpolation is not tested"
    );
    let e = state_frequencies_in(&frame, &l0);
    assert_eq!(e.status, Status::Ok);
    let reference = [7915.547952020019, 5432.563682473131];
    let err = (0..2)
        .map(|i| (e.nu[i] - reference[i]).abs() / reference[i])
        .fold(0.0f64, f64::max);
    assert!(err <= 2.0 * NEAR_EULER_RTOL, "{:?}: {err:e}", e.nu);
    // the block's own Euler frequencies miss by far more (the correction is real)
    let mut lb = l0;
    for q in [0, 3, 4] {
        lb[q] = 0.0;
    }
    let euler = state_frequencies_plain(&frame, &lb, &cancel);
    assert_eq!(euler.status, Status::Ok);
    let miss = (euler.nu[1] - reference[1]).abs() / reference[1];
    assert!(miss > 1e-10, "{miss:e}");
}

/// Harsh draw 744 (tests/data/every_state_harsh.py, seed 20261125): 3.6e-8
/// (relative) from the block 124, whose Euler orbit is transversally
/// hyperbolic (multiplier `e^0.255` per period). The level set's route
/// refuses it; the fit of docs/degenerate.md §11 (next to a hyperbolic block
/// orbit) answers. An integration
/// cannot check it (a trajectory in double moves between tori whose `ν2`
/// differ by `~ε/δ²`), so the fit is checked where the genus-2 torus answers
/// on its own, on the same line at `σ = 3e-5` (ten times closer in than the
/// first node; measured 2.1e-14), and the state's own `ν2` against that
/// torus's through the orbit's exponent (measured 5.7e-10, the analytic terms
/// at `x = 9e-10`).
#[test]
fn next_to_a_hyperbolic_block_the_frequencies_follow_the_orbits_exponent() {
    use crate::solution::motion::Motion;
    use crate::solution::normalize::TopFrame;
    use crate::solution::transverse::hyperbolic_exponent_with;
    use crate::tori::motion::{state_frequencies_in, state_frequencies_plain};
    use crate::tori::near_euler::{near_euler_frequencies, NEAR_EULER_RTOL};
    let a = [
        0.7198613953580191,
        0.7217156264155928,
        821.6686749293884,
        1762.6977729539296,
    ];
    let b = [
        0.7685421107289672,
        0.7667558647660103,
        0.7269525795908851,
        0.7258336883756266,
    ];
    let l0 = [
        246.71750689326697,
        5.902675374587227e-05,
        -829909.3496802971,
        0.02963596787819141,
        305.71044464976757,
        0.0035517203059793386,
    ];
    let frame = TopFrame::new(&a, &b).unwrap();
    let cancel = Cancel::never();
    assert_ne!(
        state_frequencies_plain(&frame, &l0, &cancel).status,
        Status::Ok,
        "the level set's route answers: the fit is not tested"
    );
    let deep = state_frequencies_in(&frame, &l0);
    assert_eq!(deep.status, Status::Ok);
    // the block 124: l13, l23, l34 are the components off it
    let mut le = l0;
    for q in [1, 3, 5] {
        le[q] = 0.0;
    }
    let norm = |v: &[f64; 6]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let off: [f64; 6] = std::array::from_fn(|q| l0[q] - le[q]);
    let delta = norm(&off) / norm(&l0);
    let sigma = 3e-5;
    let lh: [f64; 6] = std::array::from_fn(|q| le[q] + off[q] * (sigma / delta));
    let torus = state_frequencies_plain(&frame, &lh, &cancel);
    assert_eq!(torus.status, Status::Ok, "the genus-2 torus at 3e-5");
    let fit = near_euler_frequencies(&frame, &lh, &cancel).unwrap();
    // the same module: a unimodular integer matrix takes one pair to the other
    let miss = module_miss(&fit, &torus.nu);
    assert!(
        miss <= NEAR_EULER_RTOL,
        "fit {fit:?}, torus {:?}: {miss:e}",
        torus.nu
    );
    // The state's ν2 (the second entry in both) against the torus's through
    // the orbit's own exponent: 1/ν2 moves by (2/λ) ln(σ/δ), up to the
    // analytic terms of size ~σ² (relative 1e-8 at most here).
    let m = Motion::in_frame(frame.clone(), &le).unwrap();
    let (lambda, lambda_rel) = hyperbolic_exponent_with(&m, &cancel).unwrap();
    // the 6 × 6 variational equations of (1) by scipy's DOP853
    // (tests/data/hyperbolic_block_check.py, exponent_reference)
    let reference = 20.16346107037;
    let e = (lambda - reference).abs() / reference;
    assert!(
        e <= lambda_rel + 1e-12,
        "λ = {lambda}: {e:e} (bound {lambda_rel:e})"
    );
    let predicted = 1.0 / (1.0 / torus.nu[1] + 2.0 / lambda * (sigma / delta).ln());
    let err = (deep.nu[1] - predicted).abs() / predicted;
    assert!(
        err <= 1e-8,
        "{:?} against ν2 = {predicted}: {err:e}",
        deep.nu
    );
}

/// The smallest miss of `g` by `M f` over the unimodular integer matrices `M`
/// whose first column has entries up to 64 (the second is then the nearest
/// integer), relative per component (`|(M f)_i| − g_i` over `g_i`), max over
/// the two: whether two frequency pairs span the same module. Wide enough for
/// bases of very different frequencies, where `M` has entries like 19.
pub(super) fn module_miss(f: &[f64; 2], g: &[f64; 2]) -> f64 {
    // for each g_i, the integer pairs (p, q) with |p f1 + q f2| nearest to it
    let rows = |gi: f64| -> Vec<(i64, i64, f64)> {
        (-64i64..=64)
            .flat_map(|p| {
                [1.0, -1.0].map(move |sign: f64| {
                    let q = ((sign * gi - p as f64 * f[0]) / f[1]).round();
                    let h = p as f64 * f[0] + q * f[1];
                    (p, q as i64, (h.abs() - gi).abs() / gi)
                })
            })
            .collect()
    };
    let (r1, r2) = (rows(g[0]), rows(g[1]));
    let mut miss = f64::INFINITY;
    for &(p, q, e1) in &r1 {
        for &(r, s, e2) in &r2 {
            if (p * s - q * r).abs() == 1 {
                miss = miss.min(e1.max(e2));
            }
        }
    }
    miss
}
