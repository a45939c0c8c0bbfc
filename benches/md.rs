//! Molecular-dynamics benchmark: one run of 400 row beads of travel (Ristow's row) at
//! Ristow's parameters, single-threaded, in regime B.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::models::md::Md;
use fitbead::{CollisionLaw, Scene};

fn bench(c: &mut Criterion) {
    let md = Md::ristow();
    let mut g = c.benchmark_group("md-400-beads");
    g.sample_size(20);
    for (xi, d) in [(1.0, 11.0), (1.0, 12.0), (0.8, 17.0)] {
        let sc = Scene::new(xi, d, 0.4, 0.1, CollisionLaw::Value(0.5)).unwrap();
        g.bench_function(format!("xi={xi} delta={d}"), |b| {
            b.iter(|| {
                md.simulate(black_box(&sc), 1.0, None)
                    .mean_velocity
                    .unwrap_or(0.0)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
