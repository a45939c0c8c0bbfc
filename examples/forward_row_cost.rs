//! Wall time per scene of the stick forward model's pieces, on one thread, without the CSV or
//! the Python binding: building the scene (`Scene::new`), the model (`Model::evaluate`), and
//! the forward record that `fitbead forward` writes and `fitbead.forward` returns
//! (`ForwardRecord::evaluate`: the model plus its columns and message). What the binding and
//! the command line add is the difference from their own timings.
//!
//! Usage: `cargo run --release --features bench-internals --example forward_row_cost -- [N]`
//!
//! N scenes (default 1,000,000) drawn as `python/bench/bench_forward.py` draws them (its
//! recipe, another generator: `bench_internals::python_bench_scenes`, as the criterion
//! benchmark `random scenes` draws them). Each piece is timed three times over the N scenes;
//! the best is printed.

use fitbead::bench_internals::python_bench_scenes;
use fitbead::io::records::ForwardRecord;
use fitbead::{CollisionLaw, ForwardModel, Model, Scene};
use std::hint::black_box;

mod common;

/// The best of three runs of `f` over every row, in ns per row.
fn best_ns(n: usize, f: impl FnMut()) -> f64 {
    common::best_of_three(f) * 1e9 / n as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = match std::env::args().nth(1) {
        Some(a) => a.parse().map_err(|e| format!("N = '{a}': {e}"))?,
        None => 1_000_000,
    };
    let rows = python_bench_scenes(n);
    let scene = |&(xi, d, k, rho): &(f64, f64, f64, f64)| {
        Scene::new(xi, d, rho, 0.1, CollisionLaw::Value(k)).expect("a valid scene")
    };
    let built: Vec<Scene> = rows.iter().map(scene).collect();
    let m = Model::Stick;
    let t_scene = best_ns(n, || {
        for r in &rows {
            black_box(scene(r));
        }
    });
    let t_model = best_ns(n, || {
        for s in &built {
            let _ = black_box(m.evaluate(s));
        }
    });
    let t_record = best_ns(n, || {
        for s in &built {
            black_box(ForwardRecord::evaluate(s, &m));
        }
    });
    let t_all = best_ns(n, || {
        for r in &rows {
            black_box(ForwardRecord::evaluate(&scene(r), &m));
        }
    });
    let steady = built.iter().filter(|s| m.evaluate(s).is_ok()).count();
    println!("{n} scenes ({steady} steady), model stick, one thread, best of 3, ns per scene:");
    println!("  Scene::new                        {t_scene:7.1}");
    println!("  Model::evaluate                   {t_model:7.1}");
    println!("  ForwardRecord::evaluate           {t_record:7.1}");
    println!("  Scene::new + ForwardRecord        {t_all:7.1}");
    Ok(())
}
