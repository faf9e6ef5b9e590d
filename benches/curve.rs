//! Criterion benches of the curve module: the Wurzelfunktionen (27)–(28) of a
//! point pair, the map (37) and its inverse, per call, on a fixed seeded set of
//! random pairs.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use manakov::curve::{KotterCurve, INVERSE_RTOL};
use num_complex::Complex64 as C;

/// A small deterministic generator (xorshift64*), so the inputs are reproducible
/// without a dependency.
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

fn bench_curve(c: &mut Criterion) {
    let k = KotterCurve::new(C::new(1.0, 0.5), C::new(2.0, -0.3), C::new(-1.5, 0.2)).unwrap();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let n = 1000;
    let pairs: Vec<(C, C, C, C)> = (0..n)
        .map(|_| {
            let (z1, z2) = (rng.c(-3.0, 3.0), rng.c(-3.0, 3.0));
            (z1, k.y(z1), z2, -k.y(z2))
        })
        .collect();
    let g = C::new(1.2, 0.1);
    let data: Vec<_> = pairs
        .iter()
        .map(|&(z1, y1, z2, y2)| k.xi_eta(z1, y1, z2, y2, g, None, None).unwrap())
        .collect();

    let mut group = c.benchmark_group("curve");
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("wurzel", n), |b| {
        b.iter(|| {
            for &(z1, y1, z2, y2) in &pairs {
                black_box(k.wurzel(black_box(z1), y1, z2, y2, None).unwrap());
            }
        })
    });
    group.bench_function(BenchmarkId::new("xi_eta", n), |b| {
        b.iter(|| {
            for &(z1, y1, z2, y2) in &pairs {
                black_box(k.xi_eta(black_box(z1), y1, z2, y2, g, None, None).unwrap());
            }
        })
    });
    group.bench_function(BenchmarkId::new("points_from_xi_eta", n), |b| {
        b.iter(|| {
            for &(xi, eta) in &data {
                black_box(
                    k.points_from_xi_eta(black_box(xi), eta, None, Some(g), INVERSE_RTOL)
                        .unwrap(),
                );
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench_curve);
criterion_main!(benches);
