//! Wall time of the K inversion alone (eq 69: bracket, K, K_lo, K_hi, dv̄/dK; no CSV), per row
//! of a measured file, by class of row: what the estimate costs inside `fitbead k`, whose
//! whole-process time adds reading, checking and writing the rows.
//!
//! Usage: cargo run --release --features bench-internals --example k_row_cost -- FILE [MODEL]
//!   FILE: a measured table with columns series, xi, delta_deg, v, sigma_v and optionally rho
//!   and f (e.g. `python3 scripts/gen_measurements.py 100000 1`); rows that do not parse or
//!   make no scene are skipped. MODEL: stick (default) or stickslip.
//!
//! Each class (the `status` and `lower_limit` that `fitbead k` would print) is timed as a
//! whole, three times over, on one thread; the best of the three is printed, in µs per row, with
//! its share of the total.

use fitbead::fit::k::{estimate, KFailure, LowerLimit};
use fitbead::{CollisionLaw, Model, Scene};
use std::collections::BTreeMap;
use std::time::Instant;

fn class(model: &Model, sc: &Scene, v: f64, sigma: Option<f64>) -> String {
    let e = estimate(model, sc, v, sigma);
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
    let (xi, d, v, s) = (col("xi"), col("delta_deg"), col("v"), col("sigma_v"));
    let (rho, f) = (col("rho"), col("f"));
    let mut rows: BTreeMap<String, Vec<(Scene, f64, Option<f64>)>> = BTreeMap::new();
    for r in rdr.records() {
        let r = r?;
        let num = |c: Option<usize>| c.and_then(|c| r.get(c)).and_then(|x| x.parse::<f64>().ok());
        let (Some(xi), Some(d), Some(v)) = (num(xi), num(d), num(v)) else {
            continue;
        };
        let law = CollisionLaw::Adjusted;
        let Ok(sc) = Scene::new(xi, d, num(rho).unwrap_or(0.4), num(f).unwrap_or(0.1), law) else {
            continue;
        };
        let sigma = num(s);
        rows.entry(class(&model, &sc, v, sigma))
            .or_default()
            .push((sc, v, sigma));
    }
    let n: usize = rows.values().map(Vec::len).sum();
    let mut total = 0.0;
    let mut lines = Vec::new();
    for (name, rs) in &rows {
        let best = (0..3)
            .map(|_| {
                let t = Instant::now();
                for (sc, v, sigma) in rs {
                    std::hint::black_box(estimate(&model, sc, *v, *sigma));
                }
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min);
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
    Ok(())
}
