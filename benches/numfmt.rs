//! The shortest decimals the CSVs are written with: zmij against ryu on the same 10,000
//! doubles of the magnitudes a `k` or `forward` output holds (uniform on [0, 1) and spread
//! over 1e-20 … 1e20). Both write the same digits (src/numfmt.rs's tests); this measures
//! why the writer is zmij.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn bench(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let xs: Vec<f64> = (0..10_000)
        .map(|i| {
            let u = rng.random::<f64>();
            if i % 2 == 0 {
                u
            } else {
                u * 10f64.powi(rng.random_range(-20..20))
            }
        })
        .collect();
    let mut g = c.benchmark_group("shortest-decimal-10000");
    g.bench_function("ryu", |b| {
        let mut buf = ryu::Buffer::new();
        b.iter(|| {
            xs.iter()
                .map(|&x| buf.format_finite(black_box(x)).len())
                .sum::<usize>()
        })
    });
    g.bench_function("zmij", |b| {
        let mut buf = zmij::Buffer::new();
        b.iter(|| {
            xs.iter()
                .map(|&x| buf.format_finite(black_box(x)).len())
                .sum::<usize>()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
