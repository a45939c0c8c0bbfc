//! Work-precision hot paths: one evaluation of each variant the `bench` command
//! times, on a fixed set of scenes drawn by `fitbead bench`'s own generator.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::bench_internals::{
    draw_scenes, slip_steady_tol, stick_steady_quad, stickslip_steady_tol,
};
use fitbead::models::auto::Auto;
use fitbead::models::contact::{Contact, SpinRule};
use fitbead::models::Outcome;
use fitbead::{ForwardModel, Model, Scene};

fn sum(s: &[Scene], f: impl Fn(&Scene) -> Outcome) -> f64 {
    s.iter()
        .map(|x| f(black_box(x)).map(|r| r.mean_velocity).unwrap_or(0.0))
        .sum()
}

fn bench(c: &mut Criterion) {
    let s: Vec<Scene> = draw_scenes(40, 1).into_iter().map(|(s, _)| s).collect();
    let mut g = c.benchmark_group("wp-per-scene");
    g.throughput(criterion::Throughput::Elements(s.len() as u64));
    g.bench_function("stick-elliptic", |b| {
        b.iter(|| sum(&s, |x| Model::Stick.evaluate(x)))
    });
    for tol in [1e-6, 1e-10, 1e-14] {
        g.bench_function(format!("stick-quadrature-{tol:e}"), |b| {
            b.iter(|| sum(&s, |x| stick_steady_quad(x, tol)))
        });
        g.bench_function(format!("slip-{tol:e}"), |b| {
            b.iter(|| sum(&s, |x| slip_steady_tol(x, tol)))
        });
        g.bench_function(format!("stickslip-{tol:e}"), |b| {
            b.iter(|| sum(&s, |x| stickslip_steady_tol(x, tol)))
        });
        let cm = Contact {
            spin: SpinRule::Roll,
            tol,
        };
        g.bench_function(format!("contact-{tol:e}"), |b| {
            b.iter(|| sum(&s, |x| cm.evaluate(x)))
        });
    }
    for tol in [1e-6, 1e-10] {
        let a = Auto { tol };
        g.bench_function(format!("auto-{tol:e}"), |b| {
            b.iter(|| sum(&s, |x| a.evaluate(x)))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
