//! Wall time of the K inversion alone (eq 69: bracket, K, K_lo, K_hi, dv̄/dK; no CSV), per row
//! of a measured file, by class of row: what the estimate costs inside `fitbead k`, whose
//! whole-process time adds reading, checking and writing the rows. Then the row's floor: the
//! work no way of streaming the rows can avoid, each part timed alone over all the rows —
//! parsing the six numeric cells (ξ, δ, v, σ_v, ρ, f) from their text, building the scene
//! (`Scene::new`), the inversion, and writing the numbers of the output row (ξ, v, σ_v, K,
//! K_lo, K_hi, dv̄/dK, Θ̇f, Θ_G, the three laws' K, K_min, K_max: those the row has) as the
//! shortest decimals that read back as them, as `fitbead k` writes them. Their sum is what a
//! row would cost if splitting the CSV, checking cells, the text cells, the series and
//! plausibility checks and the pipeline cost nothing.
//!
//! Usage: cargo run --release --features bench-internals --example k_row_cost -- FILE [MODEL]
//!   FILE: a measured table with columns series, xi, delta_deg, v, sigma_v and optionally rho
//!   and f (e.g. `python3 scripts/gen_measurements.py 100000 1`; an empty or absent ρ or f is
//!   its default, 0.4 or 0.1); rows that do not parse or make no scene are skipped. MODEL:
//!   stick (default) or stickslip.
//!
//! The contact times each row's estimate computed are counted too
//! (`bench_internals::contacts_counted`), and their spread printed per class.
//!
//! Each class (the `status` and `lower_limit` that `fitbead k` would print) and each part of
//! the floor is timed as a whole, three times over, on one thread; the best of the three is
//! printed, in µs per row, with its share of the total.

use fitbead::bench_internals::{contacts_counted, push_number_cells};
use fitbead::fit::k::{estimate, KEstimate, KFailure, LowerLimit};
use fitbead::{CollisionLaw, Model, Scene};
use std::collections::BTreeMap;
use std::hint::black_box;

mod common;

fn class(e: &KEstimate) -> String {
    let lower = e.bracket.as_ref().map_or("none", |b| match b.lower {
        LowerLimit::Crawl => "crawl-over-top",
        LowerLimit::Zero => "K=0",
        LowerLimit::Model => "model-limit",
    });
    let status = match &e.root {
        Ok(_) => "ok",
        Err(KFailure::BelowRange) => "below-range",
        Err(KFailure::AboveRange) => "above-range",
        Err(KFailure::Invalid(_)) => "invalid",
    };
    format!("{status:11} {lower}")
}

/// The numbers of the row `fitbead k` writes for estimate `e` of the measurement (`sc`, v, σ).
fn row_numbers(sc: &Scene, v: f64, sigma: Option<f64>, e: &KEstimate) -> Vec<f64> {
    let root = e.root.as_ref().ok();
    let laws = [
        CollisionLaw::Cos2a,
        CollisionLaw::Adjusted,
        CollisionLaw::Impact,
    ]
    .map(|l| l.k(sc.alpha_rad(), sc.rho()));
    let b = e.bracket.as_ref();
    [
        Some(sc.xi()),
        Some(v),
        sigma,
        root.map(|r| r.k),
        e.k_lo,
        e.k_hi,
        e.dv_dk,
        root.map(|r| r.steady.final_velocity),
        e.theta_g.map(f64::to_degrees),
        Some(laws[0]),
        Some(laws[1]),
        Some(laws[2]),
        b.map(|b| b.lo),
        b.map(|b| b.hi),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// One measured row: its six numeric cells as text (ρ and f possibly empty), its scene, v
/// and σ.
struct Measured {
    /// The row's place in the file.
    line: usize,
    cells: [String; 6],
    /// The numbers of its output row ([`row_numbers`]).
    numbers: Vec<f64>,
    scene: Scene,
    v: f64,
    sigma: Option<f64>,
    /// Contact times its estimate computed ([`contacts_counted`]).
    contacts: u64,
    /// Of those, the root search's for K itself (`KRoot::evals`; 0 without a root).
    root_evals: u64,
}

/// Mean, median, 90th percentile and largest of `xs`.
fn spread(mut xs: Vec<u64>) -> (f64, u64, u64, u64) {
    xs.sort_unstable();
    let n = xs.len().max(1);
    let mean = xs.iter().sum::<u64>() as f64 / n as f64;
    let at = |q: f64| {
        xs.get(((q * (n - 1) as f64).round()) as usize)
            .copied()
            .unwrap_or(0)
    };
    (mean, at(0.5), at(0.9), xs.last().copied().unwrap_or(0))
}

/// The six cells parsed (an empty ρ or f its default, any other empty cell NaN).
fn parse(c: &[String; 6]) -> [f64; 6] {
    let defaults = [f64::NAN, f64::NAN, f64::NAN, f64::NAN, 0.4, 0.1];
    std::array::from_fn(|i| match c[i].as_str() {
        "" => defaults[i],
        x => x.parse::<f64>().unwrap_or(f64::NAN),
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: k_row_cost FILE [stick|stickslip]")?;
    let model = match std::env::args().nth(2).as_deref() {
        None | Some("stick") => Model::Stick,
        Some("stickslip") => Model::StickSlip,
        Some(m) => return Err(format!("model '{m}': stick or stickslip").into()),
    };
    let mut rdr = csv::Reader::from_path(&path)?;
    let h = rdr.headers()?.clone();
    let col = |n: &str| h.iter().position(|x| x == n);
    let cols = ["xi", "delta_deg", "v", "sigma_v", "rho", "f"].map(col);
    let law = CollisionLaw::Adjusted;
    let mut rows: BTreeMap<String, Vec<Measured>> = BTreeMap::new();
    for (line, r) in rdr.records().enumerate() {
        let r = r?;
        let cells: [String; 6] =
            std::array::from_fn(|i| cols[i].and_then(|c| r.get(c)).unwrap_or("").to_string());
        let [xi, d, v, s, rho, f] = parse(&cells);
        let Ok(scene) = Scene::new(xi, d, rho, f, law) else {
            continue;
        };
        if !v.is_finite() {
            continue;
        }
        let sigma = s.is_finite().then_some(s);
        let before = contacts_counted();
        let e = estimate(&model, &scene, v, sigma);
        let contacts = contacts_counted() - before;
        rows.entry(class(&e)).or_default().push(Measured {
            line,
            cells,
            numbers: row_numbers(&scene, v, sigma, &e),
            scene,
            v,
            sigma,
            contacts,
            root_evals: e.root.as_ref().map_or(0, |r| r.evals as u64),
        });
    }
    let n: usize = rows.values().map(Vec::len).sum();
    let mut total = 0.0;
    let mut lines = Vec::new();
    for (name, rs) in &rows {
        let best = common::best_of_three(|| {
            for m in rs {
                black_box(estimate(&model, &m.scene, m.v, m.sigma));
            }
        });
        total += best;
        lines.push((name, rs.len(), best));
    }
    println!("{n} rows of {path}, model {model:?}, one thread");
    for (name, k, t) in lines {
        println!(
            "{name:28} {k:7} rows {:8.3} µs/row   {:5.1} % of the total",
            1e6 * t / k as f64,
            100.0 * t / total
        );
    }
    println!("all {:>40} {:8.3} µs/row", n, 1e6 * total / n as f64);
    println!(
        "contact times computed per row (K, K_lo, K_hi, dv̄/dK; then K's search alone): \
         mean, median, 90 %, max"
    );
    for (name, rs) in &rows {
        let (mean, p50, p90, max) = spread(rs.iter().map(|m| m.contacts).collect());
        let r = spread(rs.iter().map(|m| m.root_evals).collect());
        println!(
            "{name:28} {mean:6.2} {p50:4} {p90:4} {max:5}   {:6.2} {:4} {:4} {:5}",
            r.0, r.1, r.2, r.3
        );
    }
    let all = spread(rows.values().flatten().map(|m| m.contacts).collect());
    println!("all {:>30.2} {:4} {:4} {:5}", all.0, all.1, all.2, all.3);

    // The floor.
    let mut in_order: Vec<&Measured> = rows.values().flatten().collect();
    in_order.sort_by_key(|m| m.line);
    // The cells, the scenes' parameters and the output numbers in arrays of their own, in file order, as a
    // stream holds them (not scattered among the classes' rows).
    let cells: Vec<[String; 6]> = in_order.iter().map(|m| m.cells.clone()).collect();
    let numbers: Vec<Vec<f64>> = in_order.iter().map(|m| m.numbers.clone()).collect();
    let params: Vec<[f64; 4]> = in_order
        .iter()
        .map(|m| {
            let s = &m.scene;
            [s.xi(), s.delta_deg(), s.rho(), s.f()]
        })
        .collect();
    let us = |t: f64| 1e6 * t / n as f64;
    let t_parse = us(common::best_of_three(|| {
        for c in &cells {
            black_box(parse(black_box(c)));
        }
    }));
    let t_scene = us(common::best_of_three(|| {
        for &[xi, d, rho, f] in &params {
            black_box(Scene::new(xi, d, rho, f, law).ok());
        }
    }));
    let mut out = Vec::with_capacity(1 << 20);
    let t_write = us(common::best_of_three(|| {
        for xs in &numbers {
            if out.len() > (1 << 20) - 1024 {
                out.clear();
            }
            push_number_cells(&mut out, black_box(xs));
        }
    }));
    let t_estimate = us(common::best_of_three(|| {
        for m in &in_order {
            black_box(estimate(&model, &m.scene, m.v, m.sigma));
        }
    }));
    let per_row = numbers.iter().map(Vec::len).sum::<usize>() as f64 / n as f64;
    println!("the row's floor, µs/row:");
    println!("  parse six numeric cells       {t_parse:8.3}");
    println!("  Scene::new                    {t_scene:8.3}");
    println!("  K inversion, rows in file order {t_estimate:6.3}");
    println!("  write {per_row:4.1} numbers            {t_write:8.3}");
    println!(
        "  sum                           {:8.3}",
        t_parse + t_scene + t_estimate + t_write
    );
    Ok(())
}
