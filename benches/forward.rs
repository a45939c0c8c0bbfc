//! Forward-model benchmarks: one evaluation of each model on scenes across regime B.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::bench_internals::{python_bench_scenes, rf, rf_dy_lanes, rf_lanes};
use fitbead::{CollisionLaw, ForwardModel, Model, Scene};

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
    // The stick model with its scene built per row from (ξ, δ°, K, ρ, f) as `forward` and the
    // Python binding build it: the exact per-scene work without reading or writing anything.
    let random = python_bench_scenes(100_000);
    let mut g = c.benchmark_group("random scenes");
    g.throughput(criterion::Throughput::Elements(random.len() as u64));
    g.sample_size(20);
    g.bench_function("stick with its scene", |b| {
        b.iter(|| {
            random
                .iter()
                .map(|&(xi, d, k, rho)| {
                    let x = Scene::new(black_box(xi), d, rho, 0.1, CollisionLaw::Value(k)).unwrap();
                    Model::Stick
                        .evaluate(&x)
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.finish();
    let mut g = c.benchmark_group("per-scene");
    g.throughput(criterion::Throughput::Elements(n));
    g.bench_function("stick", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    Model::Stick
                        .evaluate(black_box(x))
                        .map(|r| r.mean_velocity)
                        .unwrap_or(0.0)
                })
                .sum::<f64>()
        })
    });
    g.bench_function("stick-approx", |b| {
        b.iter(|| {
            s.iter()
                .map(|x| {
                    Model::StickApprox
                        .evaluate(black_box(x))
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
                    Model::Slip
                        .evaluate(black_box(x))
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
                    Model::SlipApprox
                        .evaluate(black_box(x))
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
                    Model::StickSlip
                        .evaluate(black_box(x))
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
    // Four independent R_F (arguments of the size the stick model's across-the-top halves
    // take), one after the other and side by side: what `rf_lanes` overlaps.
    let four = [
        [0.3, 1.2, 0.7],
        [0.05, 0.9, 1.4],
        [0.6, 0.4, 2.1],
        [0.2, 1.7, 0.35],
    ];
    let mut g = c.benchmark_group("carlson-rf x4");
    g.bench_function("one at a time", |b| {
        b.iter(|| black_box(four).map(|[x, y, z]| rf(x, y, z)))
    });
    g.bench_function("rf_lanes", |b| b.iter(|| rf_lanes(black_box(four))));
    g.finish();
    // The same side by side with ∂R_F/∂y (R_D's sum in the same duplication loop), as the K
    // inversion's passes over the top take them: four lanes (a pair of passes) and two (one
    // pass), with the triples the rolling contact forms across the top (c² y, y + c, y).
    let across = [
        [0.3 * 1e-4, 1e-4 + 0.2, 1e-4],
        [0.7 * 1e-4, 1e-4 + 0.05, 1e-4],
        [0.3 * 0.02, 0.02 + 0.2, 0.02],
        [0.7 * 0.02, 0.02 + 0.05, 0.02],
    ];
    let two = [across[0], across[1]];
    let mut g = c.benchmark_group("carlson-rf with dR_F/dy");
    g.bench_function("rf_lanes x4", |b| b.iter(|| rf_lanes(black_box(across))));
    g.bench_function("rf_dy_lanes x4", |b| {
        b.iter(|| rf_dy_lanes(black_box(across)))
    });
    g.bench_function("rf_lanes x2", |b| b.iter(|| rf_lanes(black_box(two))));
    g.bench_function("rf_dy_lanes x2", |b| b.iter(|| rf_dy_lanes(black_box(two))));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
