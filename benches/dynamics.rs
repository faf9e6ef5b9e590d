//! Cost of one right-hand side evaluation (1) and of one integration step.
//!
//! `cargo bench --bench dynamics`. The step benches run 1000 steps of the
//! shared 'generic' top at the method's default step (see `docs/dynamics.md`)
//! and report time per element = per step.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::integrate::{integrate, integrate_many, Method, Options, MAX_STEPS};
use manakov::so4::{vector_field4_lanes, FrahmTop};

const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
const B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];
const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];
const STEPS: u64 = 1000;

/// A fixed pseudo-random state (seeded LCG; no RNG crate needed).
fn seeded_state(seed: u64, m: usize) -> Vec<f64> {
    let mut s = seed;
    (0..m)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

fn rhs(c: &mut Criterion) {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let mut g = c.benchmark_group("rhs");
    g.throughput(Throughput::Elements(1));
    g.bench_function("so4_fast_path", |bch| {
        let mut out = [0.0; 6];
        bch.iter(|| {
            top.vector_field(black_box(&L0), &mut out);
            black_box(out)
        })
    });
    g.throughput(Throughput::Elements(8));
    g.bench_function("so4_8_lanes", |bch| {
        let c4 = *top.c4().unwrap();
        let mut y = [[0.0; 8]; 6];
        for (k, row) in y.iter_mut().enumerate() {
            for (i, x) in row.iter_mut().enumerate() {
                *x = L0[k] * (1.0 + 0.01 * i as f64);
            }
        }
        let mut out = [[0.0; 8]; 6];
        bch.iter(|| {
            vector_field4_lanes(&c4, black_box(&y), &mut out);
            black_box(out[0][0])
        })
    });
    g.throughput(Throughput::Elements(1));
    for n in [5usize, 8] {
        let a: Vec<f64> = (0..n).map(|i| 0.3 + i as f64).collect();
        let b = seeded_state(7, n);
        let t = FrahmTop::manakov(&a, &b).unwrap();
        let l = seeded_state(n as u64, t.dim());
        let mut out = vec![0.0; t.dim()];
        g.bench_with_input(BenchmarkId::new("son_general", n), &n, |bch, _| {
            bch.iter(|| {
                t.vector_field(black_box(&l), &mut out);
                black_box(out[0])
            })
        });
    }
    g.finish();
}

fn steps(c: &mut Criterion) {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let mut g = c.benchmark_group("step");
    g.throughput(Throughput::Elements(STEPS));
    g.sample_size(20);
    // Default steps on 'generic' (DT_SCALE / Ω of python/manakov/top.py, Ω = 4.375).
    for (method, dt) in [
        (Method::Gauss4, 0.01 / 4.375),
        (Method::Gauss6, 0.044 / 4.375),
        (Method::Gauss16, 1.0 / 3.0),
    ] {
        let opts = Options {
            method,
            dt,
            rtol: 0.0,
            atol: 0.0,
            max_steps: MAX_STEPS as u64,
        };
        let t_end = [STEPS as f64 * dt];
        g.bench_function(BenchmarkId::new("gauss", method.name()), |bch| {
            bch.iter(|| integrate(&top, black_box(&L0), 0.0, &t_end, &opts).unwrap())
        });
    }
    // Explicit methods at rtol = atol = 1e-12: time per accepted step.
    for method in [Method::Dopri5, Method::Dop853] {
        let opts = Options {
            method,
            dt: 0.0,
            rtol: 1e-12,
            atol: 1e-12,
            max_steps: MAX_STEPS as u64,
        };
        let probe = integrate(&top, &L0, 0.0, &[10.0], &opts).unwrap();
        let t_end = 10.0 * STEPS as f64 / probe.steps as f64;
        g.bench_function(
            BenchmarkId::new("explicit_tol1e-12", method.name()),
            |bch| bch.iter(|| integrate(&top, black_box(&L0), 0.0, &[t_end], &opts).unwrap()),
        );
    }
    g.finish();
}

/// The trajectory-lane batch kernels (integrate_many, one thread): 64 states
/// of the norm of 'generic''s l0 to t = 10; time per element = per trajectory-step
/// (Taylor's method at rtol = eps: order 20, ~2.3x gauss16's steps at dt = 1/3).
fn batch(c: &mut Criterion) {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let n0: f64 = L0.iter().map(|x| x * x).sum::<f64>().sqrt();
    let rows = 64;
    let mut y0s = seeded_state(11, rows * 6);
    for y in y0s.chunks_mut(6) {
        let n: f64 = y.iter().map(|x| x * x).sum::<f64>().sqrt();
        y.iter_mut().for_each(|x| *x *= n0 / n);
    }
    let mut g = c.benchmark_group("batch");
    g.sample_size(10);
    for (method, dt, rtol) in [
        (Method::Gauss16, 1.0 / 3.0, 0.0),
        (Method::Dop853, 0.0, 1e-12),
        (Method::Taylor, 0.0, f64::EPSILON),
    ] {
        let opts = Options {
            method,
            dt,
            rtol,
            atol: rtol,
            max_steps: MAX_STEPS as u64,
        };
        let (_, steps) = integrate_many(&top, &y0s, 0.0, &[10.0], &opts, false).unwrap();
        g.throughput(Throughput::Elements(steps));
        g.bench_function(BenchmarkId::new("lanes_1thread", method.name()), |bch| {
            bch.iter(|| integrate_many(&top, black_box(&y0s), 0.0, &[10.0], &opts, false).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, rhs, steps, batch);
criterion_main!(benches);
