//! Criterion benches of the Riemann-surface layer on genus-2 curves with
//! complex branch points (seeded): the period matrix (`HyperellipticCurve::new`
//! for degree 5 and 6, and with the Riemann constant and inversion calibration),
//! the Abel map per point in a batch, and Jacobi inversion per call.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::riemann::HyperellipticCurve;
use num_complex::Complex64 as C;

/// A small deterministic generator (xorshift64*).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
    fn c(&mut self, lo: f64, hi: f64) -> C {
        C::new(self.uniform(lo, hi), self.uniform(lo, hi))
    }
}

fn bench_riemann(c: &mut Criterion) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let curves5: Vec<Vec<C>> = (0..20)
        .map(|_| (0..5).map(|_| rng.c(-2.0, 2.0)).collect())
        .collect();
    let curves6: Vec<Vec<C>> = (0..20)
        .map(|_| (0..6).map(|_| rng.c(-2.0, 2.0)).collect())
        .collect();
    let mut group = c.benchmark_group("riemann");
    group.throughput(Throughput::Elements(curves5.len() as u64));
    group.bench_function(BenchmarkId::new("period_matrix_deg5", 20), |b| {
        b.iter(|| {
            for e in &curves5 {
                black_box(HyperellipticCurve::new(black_box(e)).unwrap());
            }
        })
    });
    group.bench_function(BenchmarkId::new("period_matrix_deg6", 20), |b| {
        b.iter(|| {
            for e in &curves6 {
                black_box(HyperellipticCurve::new(black_box(e)).unwrap());
            }
        })
    });
    group.bench_function(BenchmarkId::new("with_riemann_constant_deg5", 20), |b| {
        b.iter(|| {
            for e in &curves5 {
                let h = HyperellipticCurve::new(black_box(e)).unwrap();
                black_box(h.riemann_constant().unwrap());
            }
        })
    });

    let h = HyperellipticCurve::new(&curves5[0]).unwrap();
    let n = 1000;
    let xs: Vec<C> = (0..n).map(|_| rng.c(-3.0, 3.0)).collect();
    let ys: Vec<C> = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| h.y(x, if i % 2 == 0 { 1 } else { -1 }))
        .collect();
    let mut out = vec![C::new(0.0, 0.0); 2 * n];
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("abel_batch", n), |b| {
        b.iter(|| h.abel_batch(black_box(&xs), &ys, &mut out).unwrap())
    });
    let us: Vec<Vec<C>> = (0..100)
        .map(|i| {
            let (a, b) = (
                h.abel(xs[2 * i], ys[2 * i]).unwrap(),
                h.abel(xs[2 * i + 1], ys[2 * i + 1]).unwrap(),
            );
            vec![a[0] + b[0], a[1] + b[1]]
        })
        .collect();
    group.throughput(Throughput::Elements(us.len() as u64));
    group.bench_function(BenchmarkId::new("invert", us.len()), |b| {
        b.iter(|| {
            for u in &us {
                black_box(h.invert(black_box(u)).unwrap());
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench_riemann);
criterion_main!(benches);
