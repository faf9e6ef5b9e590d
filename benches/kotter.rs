//! Criterion benches of the reduction (19)–(26), (37)–(42): the level-set
//! constants `kotter_constants` (roots of F polished on their own branch and
//! refined in double-double, `σ_p`, `F'`, `Δ`, `d_j`, `α_j … δ_j`, `K`, `ε`) and
//! the per-state map `kotter_with`, per call, on a fixed seeded set of random
//! tops and states (`a`, `l` standard normal, `a` sorted).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::kotter::{kotter_constants, kotter_with};

/// A small deterministic generator (xorshift64* with a Box–Muller step), so the
/// inputs are reproducible without a dependency.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

fn bench_kotter(c: &mut Criterion) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let n = 200;
    let cases: Vec<([f64; 4], [f64; 6])> = (0..n)
        .map(|_| {
            let mut a: [f64; 4] = std::array::from_fn(|_| rng.normal());
            a.sort_by(|x, y| x.partial_cmp(y).unwrap());
            let l: [f64; 6] = std::array::from_fn(|_| rng.normal());
            (a, l)
        })
        .filter(|(a, l)| kotter_constants(a, l).is_ok_and(|k| kotter_with(k, l).is_ok()))
        .collect();
    let constants: Vec<_> = cases
        .iter()
        .map(|(a, l)| kotter_constants(a, l).unwrap())
        .collect();

    let mut group = c.benchmark_group("kotter");
    group.throughput(Throughput::Elements(cases.len() as u64));
    group.bench_function(BenchmarkId::new("kotter_constants", cases.len()), |b| {
        b.iter(|| {
            for (a, l) in &cases {
                black_box(kotter_constants(black_box(a), l).unwrap());
            }
        })
    });
    group.bench_function(BenchmarkId::new("kotter_with", cases.len()), |b| {
        b.iter(|| {
            for (k, (_, l)) in constants.iter().zip(&cases) {
                black_box(kotter_with(k.clone(), black_box(l)).unwrap());
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench_kotter);
criterion_main!(benches);
