//! Effective samples per second of the K(α) posterior (law c, stick/slip model, 40 points made
//! as in `tests/it/fits.rs`), on one core: a rayon pool of one thread runs the whole command's
//! work — the least-squares start, the sampler to its stopping rule (bulk and tail ESS ≥ 1000,
//! R̂ ≤ 1.01, run ≥ 50 τ) and the diagnostics.
//!
//! Before timing, one run prints its smallest ESS, steps, walkers and log-density evaluations
//! (deterministic for the seed), from which ESS/s = ESS / median time and evaluations per
//! effective sample follow: `cargo bench --bench mcmc`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::fit::klaw::{fit_law_with, KLaw};
use fitbead::fit::posterior::{McmcSettings, Method};
use fitbead::inverse::mcmc::McmcOptions;
use fitbead::{CollisionLaw, Model};

#[allow(dead_code, unused_imports)]
#[path = "../tests/it/fits.rs"]
mod fits;

fn bench(c: &mut Criterion) {
    let law = CollisionLaw::Adjusted;
    let data = fits::simulate(
        |_, _| Model::StickSlip,
        fits::regime_b(law),
        law,
        10,
        0.02,
        7,
    );
    let method = Method::Mcmc(Box::new(McmcSettings {
        options: McmcOptions {
            seed: 1,
            ..Default::default()
        },
        ..Default::default()
    }));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let run = || {
        pool.install(|| fit_law_with(Model::StickSlip, black_box(&data), KLaw::C, 0.95, &method))
            .unwrap()
    };
    let once = run();
    let s = &once.summary.stats;
    let m = s.mcmc.as_ref().unwrap();
    let evals = m.walkers * m.steps;
    eprintln!(
        "klaw stickslip c, 40 points, one core: status {}, min ESS {:.0}, {} steps x {} walkers \
         = {} log-density evaluations ({:.2} per effective sample), acceptance {:.2}",
        m.status,
        m.ess_min,
        m.steps,
        m.walkers,
        evals,
        evals as f64 / m.ess_min,
        m.acceptance
    );
    let mut g = c.benchmark_group("mcmc");
    g.sample_size(10);
    g.bench_function(
        "klaw stickslip c, 40 points, one core, to convergence",
        |b| b.iter(run),
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
