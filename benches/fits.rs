//! Speed of the bead fits: `klaw` (stick/slip model, 40 points), `jan` and `jaeger` (four
//! series), each with covariance and profile-likelihood intervals as the commands compute them.
//! The data are made as in `tests/it/fits.rs` (whose simulation helpers this bench shares).
//! `klaw` on the shipped data is timed as it is and with slope errors of 0.1° on every point
//! (orthogonal distance regression from the least-squares optimum).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::fit::builder::{JaegerFitter, JanFitter, KLawFitter};
use fitbead::fit::klaw::KLaw;
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
    // The shipped data as they are, and with every slope uncertain by 0.1° (orthogonal
    // distance regression instead of least squares).
    let shipped = fitbead::fit::data::Dataset::default_data();
    let mut sloped = shipped.clone();
    for p in &mut sloped.points {
        p.sigma_delta = 0.1f64.to_radians();
    }
    let mut g = c.benchmark_group("fits");
    g.sample_size(30);
    for (name, data) in [
        ("", &shipped),
        (" with slope errors 0.1 deg (ODR)", &sloped),
    ] {
        for profile in [false, true] {
            let what = if profile {
                "profile"
            } else {
                "covariance only"
            };
            g.bench_function(format!("klaw stick c, shipped data{name}, {what}"), |b| {
                let fitter = KLawFitter::new(Model::Stick, KLaw::C).least_squares(profile);
                b.iter(|| fitter.fit(black_box(data)).map(|f| f.stats.chi2))
            });
        }
    }
    g.bench_function("klaw stickslip c, 40 points, profile", |b| {
        let fitter = KLawFitter::new(Model::StickSlip, KLaw::C).least_squares(true);
        b.iter(|| fitter.fit(black_box(&stickslip)).map(|f| f.stats.chi2))
    });
    g.bench_function("klaw stickslip c, 40 points, covariance only", |b| {
        let fitter = KLawFitter::new(Model::StickSlip, KLaw::C).least_squares(false);
        b.iter(|| fitter.fit(black_box(&stickslip)).map(|f| f.stats.chi2))
    });
    g.bench_function("klaw stickslip free-per-series, 40 points, profile", |b| {
        let fitter = KLawFitter::new(Model::StickSlip, KLaw::FreePerSeries).least_squares(true);
        b.iter(|| fitter.fit(black_box(&stickslip)).map(|f| f.stats.chi2))
    });
    g.bench_function("jan 4 series + global, 36 points, profile", |b| {
        let fitter = JanFitter::new().least_squares(true);
        b.iter(|| {
            fitter
                .fit(black_box(&jan))
                .map(|s| s.get("jan-global", "all").map(|g| g.stats.chi2))
        })
    });
    g.bench_function("jaeger 4 series, 36 points, profile", |b| {
        let fitter = JaegerFitter::new()
            .branch(JaegerBranch::Upper)
            .least_squares(true);
        b.iter(|| fitter.fit(black_box(&jaeger)).map(|s| s.notes.len()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
