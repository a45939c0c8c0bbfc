//! Forward-model benchmarks: one evaluation of each model on scenes across regime B.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::models::{slip, stick, stickslip};
use fitbead::special::elliptic::rf;
use fitbead::{CollisionLaw, Scene};

fn scenes() -> Vec<Scene> {
    let mut v = Vec::new();
    for &(xi, lo, hi) in &[
        (0.8, 11.0, 16.0),
        (1.0, 8.0, 16.0),
        (1.6, 4.0, 15.0),
        (2.0, 3.0, 14.0),
    ] {
        for i in 0..8 {
            let d = lo + (hi - lo) * i as f64 / 7.0;
            v.push(Scene::new(xi, d, 0.4, 0.1, CollisionLaw::Adjusted).unwrap());
        }
    }
    v
}

fn bench(c: &mut Criterion) {
    let s = scenes();
    let n = s.len() as u64;
    let mut g = c.benchmark_group("per-scene");
    g.throughput(criterion::Throughput::Elements(n));
    g.bench_function("stick", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    stick::steady(black_box(x))
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    // The stick model with its scene built from (ξ, δ°, ρ, f, K) as the forward command and the
    // Python binding build it per row (K a number): the exact per-scene work without any I/O.
    let inputs: Vec<(f64, f64, f64)> = s.iter().map(|x| (x.xi(), x.delta_deg(), x.k())).collect();
    g.bench_function("stick with its scene", |b| {
        b.iter(|| {
            inputs
                .iter()
                .map(|&(xi, d, k)| {
                    let x = Scene::new(
                        black_box(xi),
                        black_box(d),
                        0.4,
                        0.1,
                        CollisionLaw::Value(k),
                    )
                    .unwrap();
                    stick::steady(&x).map(|r| r.mean_velocity).unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.bench_function("stick-approx", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    stick::steady_approx(black_box(x))
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.bench_function("slip", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    slip::steady(black_box(x))
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.bench_function("slip-approx", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    slip::steady_approx(black_box(x))
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.bench_function("stickslip", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    stickslip::steady(black_box(x))
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    // The general contact model on the scenes where it has a steady state (the rest lift off
    // under it): the full steady-state solve (fixed point of the contact map).
    let contact = fitbead::models::contact::Contact::default();
    let steady: Vec<Scene> = s
        .iter()
        .copied()
        .filter(|x| contact.steady_state(x).is_ok())
        .collect();
    let per = steady.len() as u64;
    g.throughput(criterion::Throughput::Elements(per));
    g.bench_function("contact", |b| {
        b.iter(|| {
            steady
                .iter()
                .map(|x| {
                    contact
                        .steady_state(black_box(x))
                        .map(|r| r.run.time)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.throughput(criterion::Throughput::Elements(n));
    g.bench_function("scene-construction", |b| {
        b.iter(|| {
            (0..32)
                .map(|i| {
                    Scene::new(
                        black_box(1.0),
                        8.0 + 0.25 * i as f64,
                        0.4,
                        0.1,
                        CollisionLaw::Adjusted,
                    )
                    .unwrap()
                    .k()
                })
                .sum::<f64>()
        })
    });
    g.finish();
    c.bench_function("carlson-rf", |b| {
        b.iter(|| rf(black_box(0.3), black_box(1.2), black_box(0.7)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
