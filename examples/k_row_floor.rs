//! The floor of a `fitbead k` row on one thread: the work no way of streaming the rows can
//! avoid, each part timed alone over the rows of a measured file:
//!
//! - parsing the row's six numeric cells (ξ, δ, v, σ_v, ρ, f) from their text;
//! - building its scene (`Scene::new`);
//! - the K inversion (eq 69: K, K_lo, K_hi, dv̄/dK; `fit::k::estimate`);
//! - writing the fourteen numbers of its output row (ξ, v, σ_v, K, K_lo, K_hi, dv̄/dK, Θ̇f,
//!   Θ_G, the three laws' K, K_min, K_max; those a row has) as the shortest decimals that read
//!   back as them, the way `fitbead k` writes them.
//!
//! Their sum is what a row would cost if splitting the CSV, checking cells, the text cells,
//! the series and plausibility checks and the pipeline cost nothing; the whole process
//! (`scripts/bench_k_peer.sh`) adds those.
//!
//! Usage: cargo run --release --features bench-internals --example k_row_floor -- FILE [MODEL]
//!   FILE: a measured table with columns series, xi, delta_deg, v, sigma_v, rho and f (e.g.
//!   `python3 scripts/gen_measurements.py 100000 1`; an empty ρ or f is its default, 0.4 or
//!   0.1); rows that do not parse or make no scene are skipped. MODEL: stick (default) or stickslip.
//!
//! Each part runs three times over all the rows; the best is printed, in µs per row.

use fitbead::bench_internals::push_number_cells;
use fitbead::fit::k::estimate;
use fitbead::{CollisionLaw, Model, Scene};
use std::hint::black_box;
use std::time::Instant;

/// The best of three runs of `f`, in µs per row of `n`.
fn best_us(n: usize, mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
        * 1e6
        / n as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: k_row_floor FILE [stick|stickslip]")?;
    let model = match std::env::args().nth(2).as_deref() {
        None | Some("stick") => Model::Stick,
        Some("stickslip") => Model::StickSlip,
        Some(m) => return Err(format!("model '{m}': stick or stickslip").into()),
    };
    let mut rdr = csv::Reader::from_path(&path)?;
    let h = rdr.headers()?.clone();
    let names = ["xi", "delta_deg", "v", "sigma_v", "rho", "f"];
    let cols = names
        .iter()
        .map(|n| {
            h.iter()
                .position(|x| x == *n)
                .ok_or(format!("no column {n}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The six numeric cells of each row, as text.
    let mut cells: Vec<[String; 6]> = Vec::new();
    for r in rdr.records() {
        let r = r?;
        let c: [String; 6] = std::array::from_fn(|i| r.get(cols[i]).unwrap_or("").to_string());
        // ρ and f may be empty (their defaults, 0.4 and 0.1).
        let ok = c
            .iter()
            .enumerate()
            .all(|(i, x)| (i >= 4 && x.is_empty()) || x.parse::<f64>().is_ok_and(f64::is_finite));
        if ok {
            cells.push(c);
        }
    }
    let defaults = [f64::NAN, f64::NAN, f64::NAN, f64::NAN, 0.4, 0.1];
    let parse = |c: &[String; 6]| -> [f64; 6] {
        std::array::from_fn(|i| match c[i].as_str() {
            "" => defaults[i],
            x => x.parse::<f64>().unwrap_or(f64::NAN),
        })
    };
    let law = CollisionLaw::Adjusted;
    let rows: Vec<(Scene, f64, f64)> = cells
        .iter()
        .filter_map(|c| {
            let [xi, d, v, s, rho, f] = parse(c);
            Scene::new(xi, d, rho, f, law).ok().map(|sc| (sc, v, s))
        })
        .collect();
    let n = rows.len();
    // The numbers of each output row.
    let numbers: Vec<Vec<f64>> = rows
        .iter()
        .map(|(sc, v, s)| {
            let e = estimate(&model, sc, *v, Some(*s));
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
                Some(*v),
                Some(*s),
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
        })
        .collect();
    let cells_n = cells.len();
    let t_parse = best_us(cells_n, || {
        for c in &cells {
            black_box(parse(black_box(c)));
        }
    });
    let t_scene = best_us(n, || {
        for (sc, _, _) in &rows {
            black_box(Scene::new(sc.xi(), sc.delta_deg(), sc.rho(), sc.f(), law).ok());
        }
    });
    let t_estimate = best_us(n, || {
        for (sc, v, s) in &rows {
            black_box(estimate(&model, sc, *v, Some(*s)));
        }
    });
    let mut out = Vec::with_capacity(1 << 20);
    let t_write = best_us(n, || {
        for xs in &numbers {
            if out.len() > (1 << 20) - 512 {
                out.clear();
            }
            push_number_cells(&mut out, black_box(xs));
        }
    });
    let per_row = numbers.iter().map(Vec::len).sum::<usize>() as f64 / n as f64;
    println!("{n} rows of {path}, model {model:?}, one thread, best of 3, µs per row");
    println!("  parse six numeric cells          {t_parse:8.3}");
    println!("  Scene::new                       {t_scene:8.3}");
    println!("  K inversion (K, K_lo, K_hi, dv/dK) {t_estimate:6.3}");
    println!("  write {per_row:.1} numbers              {t_write:8.3}");
    println!(
        "  sum                              {:8.3}",
        t_parse + t_scene + t_estimate + t_write
    );
    Ok(())
}
