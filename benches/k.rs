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

/// Kepler's equation E − e sin E = M (e = 0.5, M = 1) on [0, π]: a function as cheap as the
/// inner loops' (a few flops), so the root finder's own cost shows.
struct Kepler;

impl argmin::core::CostFunction for Kepler {
    type Param = f64;
    type Output = f64;
    fn cost(&self, e: &f64) -> Result<f64, argmin::core::Error> {
        Ok(e - 0.5 * e.sin() - 1.0)
    }
}

/// fitbead's Brent (`special::root::brent`, allocation-free, called inside every stick/slip
/// evaluation) against argmin's `BrentRoot` under its `Executor`, both to 1e-15 on the same
/// root.
fn roots(c: &mut Criterion) {
    use argmin::core::{CostFunction, Executor, State};
    use argmin::solver::brent::BrentRoot;
    let f = |e: f64| Kepler.cost(&e).unwrap();
    let (a, b) = (0.0, std::f64::consts::PI);
    let ours = fitbead::special::root::brent(f, a, b, f(a), f(b), 1e-15, 200)
        .unwrap()
        .x;
    let theirs = *Executor::new(Kepler, BrentRoot::new(a, b, 1e-15))
        .configure(|s| s.param(1.0).max_iters(200))
        .ctrlc(false)
        .run()
        .unwrap()
        .state()
        .get_best_param()
        .unwrap();
    assert!((ours - theirs).abs() <= 4e-15, "{ours} vs {theirs}");
    let mut g = c.benchmark_group("root");
    g.bench_function("brent (fitbead)", |bn| {
        bn.iter(|| {
            let (a, b) = (black_box(a), black_box(b));
            fitbead::special::root::brent(f, a, b, f(a), f(b), 1e-15, 200).map(|r| r.x)
        })
    });
    g.bench_function("BrentRoot (argmin)", |bn| {
        bn.iter(|| {
            let solver = BrentRoot::new(black_box(a), black_box(b), 1e-15);
            let res = Executor::new(Kepler, solver)
                .configure(|s| s.param(1.0).max_iters(200))
                .ctrlc(false)
                .run()
                .unwrap();
            *res.state().get_best_param().unwrap()
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench, roots
}
criterion_main!(benches);
