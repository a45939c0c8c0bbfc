//! Speed of the bead fits: `klaw` (stick/slip model, 40 points), `jan` and `jaeger` (four
//! series), each with covariance and profile-likelihood intervals as the commands compute them.
//! The data are made as in `tests/it/fits.rs` (whose simulation helpers this bench shares).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::fit::jaeger::fit_jaeger;
use fitbead::fit::jan::fit_jan;
use fitbead::fit::klaw::{fit_law, KLaw};
use fitbead::models::JaegerBranch;
use fitbead::{CollisionLaw, Model};

#[allow(dead_code, unused_imports)]
#[path = "../tests/it/fits.rs"]
mod fits;

fn bench(c: &mut Criterion) {
    let law = CollisionLaw::Adjusted;
    let stickslip = fits::simulate(
        |_, _| Model::StickSlip,
        fits::regime_b(law),
        law,
        10,
        0.02,
        7,
    );
    let jan = fits::simulate(
        fits::jan_model(fits::PAPER_JAN),
        fits::open_range(law),
        law,
        9,
        0.02,
        7,
    );
    let jaeger = fits::simulate(fits::jaeger_model, fits::open_range(law), law, 9, 0.02, 7);
    let mut g = c.benchmark_group("fits");
    g.sample_size(30);
    g.bench_function("klaw stickslip c, 40 points, profile", |b| {
        b.iter(|| {
            fit_law(Model::StickSlip, black_box(&stickslip), KLaw::C, 0.95, true).map(|f| f.k)
        })
    });
    g.bench_function("klaw stickslip c, 40 points, covariance only", |b| {
        b.iter(|| {
            fit_law(
                Model::StickSlip,
                black_box(&stickslip),
                KLaw::C,
                0.95,
                false,
            )
            .map(|f| f.k)
        })
    });
    g.bench_function("klaw stickslip free-per-series, 40 points, profile", |b| {
        b.iter(|| {
            fit_law(
                Model::StickSlip,
                black_box(&stickslip),
                KLaw::FreePerSeries,
                0.95,
                true,
            )
            .map(|f| f.k)
        })
    });
    g.bench_function("jan 4 series + global, 36 points, profile", |b| {
        b.iter(|| {
            fit_jan(black_box(&jan), 0.95, true)
                .global
                .map(|s| s.stats.chi2)
        })
    });
    g.bench_function("jaeger 4 series, 36 points, profile", |b| {
        b.iter(|| {
            fit_jaeger(black_box(&jaeger), JaegerBranch::Upper, 0.95, true)
                .notes
                .len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
