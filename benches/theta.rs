//! Criterion benches for `manakov::theta` on the shared benchmark τ of
//! problems.json ("benchmark" → "theta"): the 16 genus-2 values at one point,
//! one characteristic, gradient + Hessian, and batch throughput on one core
//! (`with_parallel(false)`) and on all cores (rayon, the default).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::theta::{ThetaPlan, DEFAULT_TOL};
use num_complex::Complex64 as C;

fn bench_tau() -> Vec<C> {
    vec![
        C::new(0.3, 1.1),
        C::new(0.1, 0.4),
        C::new(0.1, 0.4),
        C::new(-0.2, 1.3),
    ]
}

/// Seeded points as in problems.json: Re z uniform in [0,1), Im z in [-0.5, 0.5].
fn points(n: usize) -> Vec<C> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..2 * n).map(|_| C::new(next(), next() - 0.5)).collect()
}

fn theta(c: &mut Criterion) {
    let tau = bench_tau();
    let plan0 = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0).unwrap();
    let plan2 = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 2).unwrap();
    let z = points(1);
    let mut ws = plan0.workspace();
    let mut vals = vec![C::new(0.0, 0.0); 16];
    let mut grad = vec![C::new(0.0, 0.0); 32];
    let mut hess = vec![C::new(0.0, 0.0); 64];

    let mut group = c.benchmark_group("theta_g2_one_point");
    group.throughput(Throughput::Elements(1));
    group.bench_function("all16", |bch| {
        bch.iter(|| {
            plan0
                .eval_into(black_box(&z), &mut ws, &mut vals, &mut [], &mut [])
                .unwrap()
        })
    });
    group.bench_function("one_char", |bch| {
        bch.iter(|| {
            plan0
                .eval_into(black_box(&z), &mut ws, &mut vals, &mut [], &mut [])
                .unwrap();
            vals[5]
        })
    });
    group.bench_function("all16_gradient", |bch| {
        bch.iter(|| {
            plan2
                .eval_into(black_box(&z), &mut ws, &mut vals, &mut grad, &mut [])
                .unwrap()
        })
    });
    group.bench_function("all16_gradient_hessian", |bch| {
        bch.iter(|| {
            plan2
                .eval_into(black_box(&z), &mut ws, &mut vals, &mut grad, &mut hess)
                .unwrap()
        })
    });
    group.bench_function("plan_new", |bch| {
        bch.iter(|| ThetaPlan::new(black_box(&tau), 2, DEFAULT_TOL, 0).unwrap())
    });
    group.finish();

    let plan1 = ThetaPlan::new(&tau, 2, DEFAULT_TOL, 0)
        .unwrap()
        .with_parallel(false);
    let mut group = c.benchmark_group("theta_g2_batch");
    for &(n, parallel) in &[(100usize, false), (10_000, false), (100_000, true)] {
        let plan = if parallel { &plan0 } else { &plan1 };
        let name = if parallel {
            "all16_all_cores"
        } else {
            "all16_one_core"
        };
        let zs = points(n);
        let mut v = vec![C::new(0.0, 0.0); 16 * n];
        let mut l = vec![0.0; n];
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::new(name, n), &n, |bch, _| {
            bch.iter(|| {
                plan.eval_batch(black_box(&zs), &mut v, &mut [], &mut [], &mut l)
                    .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = theta
}
criterion_main!(benches);
