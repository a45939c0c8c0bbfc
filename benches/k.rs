//! K inversion (eq 69) benchmarks: one measurement row — bracket, K, K_lo, K_hi (v ± σ, exact
//! inverses), dv/dK — single-threaded, on the shipped default data (36 rows, 4 series); K
//! alone; and K alone by the general search in K (src/fit/k/search.rs) for comparison with the
//! launch-speed path that `estimate` takes for stick and stick/slip (src/fit/k/launch.rs).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::fit::k::{bracket, estimate, solve};
use fitbead::{CollisionLaw, Model, Scene};

fn rows() -> Vec<(Scene, f64, f64)> {
    let text = include_str!("../data/default.csv");
    let mut rdr = csv::Reader::from_reader(text.as_bytes());
    rdr.records()
        .map(|r| {
            let r = r.unwrap();
            let x = |i: usize| r[i].parse::<f64>().unwrap();
            (
                Scene::new(x(1), x(2), 0.4, 0.1, CollisionLaw::Value(0.5)).unwrap(),
                x(3),
                x(4),
            )
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let rows = rows();
    let n = rows.len() as u64;
    let mut g = c.benchmark_group("k-per-row");
    g.throughput(criterion::Throughput::Elements(n));
    for (name, m) in [
        ("stick", Model::Stick),
        ("stick-approx", Model::StickApprox),
        ("slip", Model::Slip),
        ("stickslip", Model::StickSlip),
    ] {
        g.bench_function(format!("{name} full row (K, K_lo, K_hi, dv/dK)"), |b| {
            b.iter(|| {
                rows.iter()
                    .map(|(s, v, sg)| {
                        let e = estimate(&m, black_box(s), *v, Some(*sg));
                        e.root.map(|r| r.k).unwrap_or(0.0)
                    })
                    .sum::<f64>()
            })
        });
        g.bench_function(format!("{name} K only"), |b| {
            b.iter(|| {
                rows.iter()
                    .map(|(s, v, _)| {
                        let e = estimate(&m, black_box(s), *v, None);
                        e.root.map(|r| r.k).unwrap_or(0.0)
                    })
                    .sum::<f64>()
            })
        });
        // The general search in K alone (bracket, then Brent in ln(K − K_min)): what every
        // model used before the launch-speed path, and what slip still uses.
        g.bench_function(format!("{name} K only, search in K"), |b| {
            b.iter(|| {
                rows.iter()
                    .map(|(s, v, _)| {
                        let Ok(br) = bracket(&m, black_box(s)) else {
                            return 0.0;
                        };
                        solve(&m, s, &br, *v).map(|r| r.k).unwrap_or(0.0)
                    })
                    .sum::<f64>()
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
