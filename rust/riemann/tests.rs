use super::*;

fn c(re: f64, im: f64) -> C {
    C::new(re, im)
}

/// xorshift64*: deterministic test inputs without a rand dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn c(&mut self, r: f64) -> C {
        c(r * (2.0 * self.next() - 1.0), r * (2.0 * self.next() - 1.0))
    }
}

fn max_asym(t: &DMatrix<C>) -> f64 {
    let mut m: f64 = 0.0;
    for i in 0..t.nrows() {
        for j in 0..t.ncols() {
            m = m.max((t[(i, j)] - t[(j, i)]).norm());
        }
    }
    m / t.norm()
}

#[test]
fn random_curves_all_genera() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for n in 3..=10 {
        for _ in 0..20 {
            let e: Vec<C> = (0..n).map(|_| rng.c(2.0)).collect();
            let h = HyperellipticCurve::new(&e).unwrap();
            let (a, b) = h.periods();
            let raw = a.clone().try_inverse().unwrap() * b;
            assert!(max_asym(&raw) < 1e-13, "n={n} asym {}", max_asym(&raw));
            let k = h.riemann_constant();
            assert!(k.is_ok(), "n={n}: {k:?}");
        }
    }
}

#[test]
fn abel_path_independence_and_theta_divisor() {
    let mut rng = Rng(77);
    for n in [5usize, 6] {
        for _ in 0..20 {
            let e: Vec<C> = (0..n).map(|_| rng.c(2.0)).collect();
            let h = HyperellipticCurve::new(&e).unwrap();
            let plan = h.theta_plan().unwrap();
            let kv = h.riemann_constant().unwrap().to_vec();
            for _ in 0..10 {
                let x = rng.c(3.0);
                let y = h.y(x, if rng.next() < 0.5 { 1 } else { -1 });
                let u0 = h.abel(x, y).unwrap();
                for route in [None, Some(0), Some(n - 1)] {
                    let u1 = h.abel_via(x, y, route).unwrap();
                    let d: Vec<C> = (0..2).map(|i| u1[i] - u0[i]).collect();
                    let r = h.reduce(&d);
                    assert!(
                        r[0].norm().max(r[1].norm()) < 1e-12,
                        "route {route:?}: {r:?}"
                    );
                }
                let z: Vec<C> = (0..2).map(|i| u0[i] + kv[i]).collect();
                let (vals, _) = plan.theta_all(&z).unwrap();
                let big = vals.iter().map(|v| v.norm()).fold(0.0, f64::max);
                assert!(
                    vals[0].norm() < 1e-13 * big,
                    "theta {}",
                    vals[0].norm() / big
                );
            }
        }
    }
}

#[test]
fn inversion_round_trip() {
    let mut rng = Rng(99);
    for _ in 0..20 {
        let e: Vec<C> = (0..5).map(|_| rng.c(2.0)).collect();
        let h = HyperellipticCurve::new(&e).unwrap();
        for _ in 0..5 {
            let (x1, x2) = (rng.c(2.5), rng.c(2.5));
            let (y1, y2) = (h.y(x1, 1), h.y(x2, -1));
            let u1 = h.abel(x1, y1).unwrap();
            let u2 = h.abel(x2, y2).unwrap();
            let u: Vec<C> = (0..2).map(|i| u1[i] + u2[i]).collect();
            let [(a1, b1), (a2, b2)] = h.invert(&u).unwrap();
            let ok = |p: C, q: C, r: C, s: C| {
                (p - x1).norm() + (q - y1).norm() + (r - x2).norm() + (s - y2).norm()
            };
            let err = ok(a1, b1, a2, b2).min(ok(a2, b2, a1, b1));
            assert!(err < 1e-9 * (1.0 + y1.norm() + y2.norm()), "err {err}");
        }
    }
}
