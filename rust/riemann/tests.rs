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
            let k = h.try_riemann_constant();
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
            let kv = h.try_riemann_constant().unwrap().to_vec();
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

#[test]
#[ignore]
fn debug_node_counts() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let e: Vec<C> = (0..5).map(|_| rng.c(2.0)).collect();
    let h = HyperellipticCurve::new(&e).unwrap();
    let mut tot = 0;
    for _ in 0..100 {
        let x = rng.c(3.0);
        let mut best = (Route::Infinity, h.route_quality(Route::Infinity, x));
        for k in 0..5 {
            let q = h.route_quality(Route::Branch(k), x);
            if q > best.1 {
                best = (Route::Branch(k), q);
            }
        }
        let mut sing = vec![];
        match best.0 {
            Route::Branch(k) => {
                for m in 0..5 {
                    if m != k {
                        let s = sqrt_principal((e[m] - e[k]) / (x - e[k]));
                        sing.push(s);
                        sing.push(-s);
                    }
                }
            }
            Route::Infinity => {
                for m in 0..5 {
                    let s = sqrt_principal((x - h.center) / (e[m] - h.center));
                    sing.push(s);
                    sing.push(-s);
                }
            }
        }
        let mut p = vec![];
        quad::plan_pieces(&sing, &mut p).unwrap();
        let nn: usize = p.iter().map(|q| quad::gl_rule(q.n).nodes.len()).sum();
        println!(
            "{:?} q={:.3} pieces={} nodes={}",
            best.0,
            best.1,
            p.len(),
            nn
        );
        tot += nn;
    }
    println!("avg {}", tot as f64 / 100.0);
}

#[test]
#[ignore]
fn debug_timing() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let e: Vec<C> = (0..5).map(|_| rng.c(2.0)).collect();
    let h = HyperellipticCurve::new(&e).unwrap();
    let xs: Vec<C> = (0..1000).map(|_| rng.c(3.0)).collect();
    let ys: Vec<C> = xs.iter().map(|&x| h.y(x, 1)).collect();
    let t = std::time::Instant::now();
    let mut s = 0.0;
    for &x in &xs {
        for k in 0..5 {
            s += h.route_quality(Route::Branch(k), x);
        }
    }
    println!("quality {:?} {s}", t.elapsed() / 1000);
    let t = std::time::Instant::now();
    for (&x, &y) in xs.iter().zip(&ys) {
        s += h.path_from_branch(0, x, y).unwrap()[0].re;
    }
    println!("path {:?} {s}", t.elapsed() / 1000);
    let t = std::time::Instant::now();
    for (&x, &y) in xs.iter().zip(&ys) {
        s += h.abel(x, y).unwrap()[0].re;
    }
    println!("abel {:?} {s}", t.elapsed() / 1000);
}

#[test]
#[ignore]
fn debug_timing2() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let e: Vec<C> = (0..5).map(|_| rng.c(2.0)).collect();
    let xs: Vec<C> = (0..1000).map(|_| rng.c(3.0)).collect();
    let t = std::time::Instant::now();
    let mut p = vec![];
    let mut s = 0.0;
    for &x in &xs {
        let sing: Vec<C> = e[1..]
            .iter()
            .map(|&em| sqrt_principal((em - e[0]) / (x - e[0])))
            .collect();
        quad::plan_pieces(&sing, &mut p).unwrap();
        s += p.len() as f64;
    }
    println!("plan {:?} {s}", t.elapsed() / 1000);
    let segs: Vec<SegmentSqrt> = e
        .iter()
        .map(|&em| SegmentSqrt::new(em, C::new(1.0, 0.5)))
        .collect();
    let t = std::time::Instant::now();
    let mut acc = C::new(0.0, 0.0);
    for i in 0..17000 {
        let v = i as f64 / 17000.0;
        let prod: C = segs
            .iter()
            .map(|sg| sg.rotated(e[1] + C::new(1.0, 0.5) * v))
            .product();
        acc += C::new(1.0, 0.0) / prod;
    }
    println!("17 nodes {:?} {acc}", t.elapsed() / 1000);
}
