//! Criterion benches of the Theorem (9)–(10): the set-up `Solution::new`
//! (reduction, curve, periods, Abel map, constants, U) and the evaluation of
//! `l(t)` at 4096 times near t = 1 and near t = 10^6, on one thread (the
//! 4096 times are below the parallel threshold of one work unit per thread).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::numeric::cancel::Cancel;
use manakov::solution::motion::classify;
use manakov::solution::normalize::TopFrame;
use manakov::solution::Solution;

const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
const B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];
const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];

fn bench_solution(c: &mut Criterion) {
    let mut g = c.benchmark_group("solution");
    g.bench_function("setup_generic", |b| {
        b.iter(|| Solution::new(black_box(&A), black_box(&B), black_box(&L0)).unwrap())
    });
    let sol = Solution::new(&A, &B, &L0).unwrap();
    let n = 4096;
    g.throughput(Throughput::Elements(n as u64));
    let cancel = Cancel::never();
    for t0 in [1.0, 1.0e6] {
        let t: Vec<f64> = (0..n).map(|k| t0 + 1e-3 * k as f64).collect();
        let mut out = vec![0.0; 6 * n];
        g.bench_with_input(BenchmarkId::new("l_4096_times_near", t0), &t, |b, t| {
            b.iter(|| sol.l_batch_serial(black_box(t), &mut out, &cancel).unwrap())
        });
    }
    g.finish();
}

/// What the dispatcher adds before a genus-2 set-up: the top's frame (once
/// per top) and the classification of the state (once per state).
fn bench_dispatch(c: &mut Criterion) {
    let mut g = c.benchmark_group("dispatch");
    g.bench_function("top_frame", |b| {
        b.iter(|| TopFrame::new(black_box(&A), black_box(&B)).unwrap())
    });
    let frame = TopFrame::new(&A, &B).unwrap();
    g.bench_function("classify", |b| {
        b.iter(|| classify(black_box(&frame), black_box(&L0)))
    });
    g.finish();
}

criterion_group!(benches, bench_solution, bench_dispatch);
criterion_main!(benches);
