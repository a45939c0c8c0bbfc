//! K inversion (eq 69) benchmarks: one measurement row — bracket, K, K_lo, K_hi (v ± σ, exact
//! inverses), dv/dK — single-threaded, on the shipped default data (36 rows, 4 series); K
//! alone; and K alone by the general search in K (src/fit/k/search.rs) for comparison with the
//! launch-speed path that `estimate` takes for stick and stick/slip (src/fit/k/launch.rs).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::bench_internals::{bracket, solve};
use fitbead::fit::k::estimate;
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
    let ours = fitbead::bench_internals::brent(f, a, b, f(a), f(b), 1e-15, 200)
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
            fitbead::bench_internals::brent(f, a, b, f(a), f(b), 1e-15, 200).map(|r| r.x)
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

/// The contact times of two rolling launches from the top of each shipped scene (speeds² y and
/// 2y at the top, y from 1e-6 to 1, as the launch-speed path evaluates them): two
/// `cos_integral` calls, each the next one's input (as in a root search), against
/// `cos_integral_pair` (the four R_F side by side, as for the top and first root pass, the
/// dτ/du side passes and the K_lo, K_hi searches); and a row's scene built alone against one
/// that takes what depends on ξ alone from the row before.
fn lanes(c: &mut Criterion) {
    use fitbead::bench_internals::{cos_integral, cos_integral_pair, SinCos};
    let rows = rows();
    let args: Vec<(SinCos, SinCos, f64, f64, f64)> = rows
        .iter()
        .enumerate()
        .map(|(i, (s, _, _))| {
            let (t0, tf) = (s.theta_0_rad(), s.theta_f_rad());
            let drop = 2.0 * s.b() * s.sin_delta_sin_alpha();
            let wc2 = 2.0 * s.b() * (0.5 * t0).sin().powi(2);
            let y = 10f64.powf(-6.0 * (i % 7) as f64 / 6.0);
            (SinCos::of(0.5 * t0), SinCos::of(0.5 * tf), wc2, drop, y)
        })
        .filter(|a| a.0.s < 0.0)
        .collect();
    let den = |h0: SinCos, h1: SinCos| (h1.s - h0.s) * (h1.s + h0.s);
    let mut g = c.benchmark_group("launch-passes");
    g.throughput(criterion::Throughput::Elements(2 * args.len() as u64));
    g.bench_function("two cos_integral, chained", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(h0, h1, wc2, drop, y) in &args {
                let y = black_box(y) + 0.0 * acc;
                let t1 = cos_integral(h0, h1, y + wc2, y + wc2 + drop, y, den(h0, h1));
                let y2 = 2.0 * y + 0.0 * t1;
                let t2 = cos_integral(h0, h1, y2 + wc2, y2 + wc2 + drop, y2, den(h0, h1));
                acc += t1 + t2;
            }
            acc
        })
    });
    g.bench_function("cos_integral_pair", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(h0, h1, wc2, drop, y) in &args {
                let y = black_box(y) + 0.0 * acc;
                let y2 = 2.0 * y;
                let [t1, t2] = cos_integral_pair(
                    h0,
                    h1,
                    [y + wc2, y + wc2 + drop, y],
                    [y2 + wc2, y2 + wc2 + drop, y2],
                    den(h0, h1),
                );
                acc += t1 + t2;
            }
            acc
        })
    });
    g.finish();
    let mut g = c.benchmark_group("row-scene");
    g.throughput(criterion::Throughput::Elements(rows.len() as u64));
    let cells: Vec<(f64, f64)> = rows
        .iter()
        .map(|(s, _, _)| (s.xi(), s.delta_deg()))
        .collect();
    let law = CollisionLaw::Value(0.5);
    g.bench_function("Scene::new", |b| {
        b.iter(|| {
            cells
                .iter()
                .map(|&(xi, d)| Scene::new(black_box(xi), d, 0.4, 0.1, law).unwrap().b())
                .sum::<f64>()
        })
    });
    g.bench_function("Scene::new_like (the row before)", |b| {
        b.iter(|| {
            let mut like: Option<Scene> = None;
            cells
                .iter()
                .map(|&(xi, d)| {
                    let s =
                        Scene::new_like(like.as_ref(), black_box(xi), d, 0.4, 0.1, law).unwrap();
                    like = Some(s);
                    s.b()
                })
                .sum::<f64>()
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench, roots, lanes
}
criterion_main!(benches);
