//! Speed of the least-squares solver: all 54 NIST StRD nonlinear cases (27 problems × 2
//! starts), each fitted with covariance, as in `tests/it/nist.rs` (whose parser and models this
//! bench shares).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::inverse::fit;

#[allow(dead_code)]
#[path = "../tests/it/nist.rs"]
mod nist;

/// The log relative error the NIST module reports (shared with the tests).
#[allow(dead_code)]
#[path = "../tests/shared/cross_check.rs"]
mod cross_check;
use fitbead::inverse::{LeastSquares, LsqOptions, Residuals};

fn bench(c: &mut Criterion) {
    let probs = nist::problems();
    let data: Vec<_> = probs.iter().map(nist::data).collect();
    let opts = nist::options();
    let mut g = c.benchmark_group("nist");
    g.sample_size(30);
    g.bench_function("all 54 cases", |b| {
        b.iter(|| {
            let mut evals = 0;
            for (p, d) in probs.iter().zip(&data) {
                for start in &p.starts {
                    if let Ok(f) = fit(d, black_box(start), &opts) {
                        evals += f.residual_evals;
                    }
                }
            }
            black_box(evals)
        })
    });
    // The slowest single case, for scale.
    if let Some(i) = probs.iter().position(|p| p.name == "Bennett5") {
        g.bench_function("Bennett5 start 1", |b| {
            b.iter(|| fit(&data[i], black_box(&probs[i].starts[0]), &opts).map(|f| f.chi2))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
