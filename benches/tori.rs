//! Criterion benches of the tori module on one core: the real torus from
//! (τ, U, U') alone, and the whole per-state chain of a frequency map
//! (`tori::solve::state_frequencies`: the Theorem's set-up, the second flow,
//! the lattice and ν) on a fixed set of states of the shared 'generic' top.
//! Run with RAYON_NUM_THREADS=1 for the one-core figure.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::tori::{self, solve::state_frequencies};
use num_complex::Complex64 as C;

/// The seven characteristics of the `simple` curve (docs/theta_quotients.md).
const SIMPLE: [[u8; 4]; 7] = [
    [1, 0, 0, 0],
    [0, 0, 0, 1],
    [1, 1, 0, 1],
    [1, 1, 0, 0],
    [1, 0, 0, 1],
    [0, 1, 0, 1],
    [0, 1, 0, 0],
];

fn bench_tori(c: &mut Criterion) {
    let mut group = c.benchmark_group("tori");
    // A plane through two lattice points of a generic τ.
    let tau = [
        [C::new(0.1, 1.2), C::new(-0.3, 0.4)],
        [C::new(-0.3, 0.4), C::new(0.2, 0.9)],
    ];
    let lp = |x: [i64; 4]| tori::lattice_point(&tau, &x);
    let (l1, l2) = (lp([2, 0, 1, -1]), lp([0, 2, 0, 2]));
    let u = [l1[0] * 0.31 + l2[0] * 0.17, l1[1] * 0.31 + l2[1] * 0.17];
    let u2 = [l1[0] * -0.4 + l2[0] * 1.1, l1[1] * -0.4 + l2[1] * 1.1];
    group.throughput(Throughput::Elements(1));
    group.bench_function("real_torus", |b| {
        b.iter(|| tori::real_torus(black_box(&tau), &u, &u2, &SIMPLE).unwrap())
    });

    let a = [0.3, 1.1, 2.0, 3.7];
    let bb = [0.5, -0.2, 1.4, 0.9];
    let l0 = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];
    // 64 states near l0 (a deterministic spread), as in a frequency map.
    let states: Vec<[f64; 6]> = (0..64)
        .map(|k| {
            let s = 0.05 * ((k as f64) * 0.7).sin();
            std::array::from_fn(|i| l0[i] * (1.0 + s * ((i + k) as f64).cos()))
        })
        .collect();
    group.throughput(Throughput::Elements(states.len() as u64));
    group.bench_function(BenchmarkId::new("state_frequencies", states.len()), |b| {
        b.iter(|| {
            for s in &states {
                black_box(state_frequencies(&a, &bb, black_box(s)));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench_tori);
criterion_main!(benches);
