//! `report --method mcmc` on the default data: every posterior converges to the report's
//! thresholds in a few thousand steps, and the posterior bands of v̄(δ) (`report::bands`).

use crate::common::{bin, read_table, root, stderr, tmpdir};
use fitbead::fit::posterior::{McmcSettings, Method};
use fitbead::progress::{Progress, ProgressEvent};
use fitbead::report::analysis::{analyse, REPORT_DRAWS};
use fitbead::report::bands::{posterior_bands, BAND_DRAWS, BAND_GRID};
use fitbead::Dataset;
use std::sync::{Arc, Mutex};
use std::time::Instant;

#[test]
fn report_mcmc_on_the_default_data_converges() {
    let dir = tmpdir();
    let t = Instant::now();
    let out = bin()
        .current_dir(root())
        .args(["report", "--method", "mcmc", "--out-dir"])
        .arg(dir.path())
        .output()
        .unwrap();
    let secs = t.elapsed().as_secs_f64();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (h, rows) = read_table(&dir.path().join("stats.csv"));
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let num = |r: &Vec<String>, name: &str| r[col(name)].parse::<f64>().unwrap();
    // Four K-law fits, Jan per series and global, Jaeger per series.
    assert_eq!(rows.len(), 13);
    let mut steps_total = 0.0;
    for r in &rows {
        let fit = format!("{} [{}]", r[col("fit")], r[col("series")]);
        assert_eq!(
            r[col("mcmc_status")],
            "converged",
            "{fit}: {}",
            r[col("note")]
        );
        // The report's defaults: R̂ ≤ 1.01, bulk and tail ESS ≥ 1000.
        assert!(num(r, "rhat_max") <= 1.01, "{fit}");
        assert!(num(r, "ess_min") >= 1000.0, "{fit}");
        // The run is deterministic for the seed; its length stands for the time it takes.
        // Today the longest fit takes 4 500 steps (Jaeger at ξ = 1.6); sampled in
        // (ln a1, ln a2, ln a3), Jaeger at ξ = 0.8 ran the full 100 000 without converging.
        let steps = num(r, "steps");
        assert!(steps <= 10_000.0, "{fit}: {steps} steps");
        steps_total += steps;
        // The report keeps at most REPORT_DRAWS draws per fit, after summarising all.
        assert!(
            num(r, "draws") > REPORT_DRAWS as f64,
            "{fit}: summarised on all draws"
        );
    }
    println!("report --method mcmc: {secs:.1} s wall, {steps_total} sampler steps in all");
}

#[test]
fn posterior_bands_of_every_fit() {
    let data = Dataset::default_data();
    // The fits run concurrently; the progress sink must still see one task at a time.
    let events: Arc<Mutex<Vec<String>>> = Arc::default();
    let log = Arc::clone(&events);
    let mut settings = McmcSettings::seeded(1);
    settings.progress = Some(Progress::new(move |e| {
        let tag = match e {
            ProgressEvent::Start { label, .. } => format!("start {label}"),
            ProgressEvent::Position(_) => "position".into(),
            ProgressEvent::Finish => "finish".into(),
        };
        log.lock().unwrap().push(tag);
    }));
    let an = analyse(&data, 0.95, &Method::Mcmc(Box::new(settings)));
    let events = events.lock().unwrap().clone();
    let mut open = false;
    let mut tasks = 0;
    for e in &events {
        match e.as_str() {
            "finish" => {
                assert!(open, "a finish without a start");
                open = false;
            }
            "position" => assert!(open, "a position outside a task"),
            start => {
                assert!(!open, "{start} while another task holds the sink");
                open = true;
                tasks += 1;
            }
        }
    }
    assert!(!open && tasks >= 1, "{tasks} tasks reported");
    let b = posterior_bands(&an);
    // Per series: 2 contact models × 2 laws, Jan per series and global, Jaeger.
    assert_eq!(b.bands.len(), 4 * 7);
    assert_eq!(b.points.len(), 36 * 7);
    for band in &b.bands {
        let what = format!("{} [{}]", band.fit, band.series);
        let s = data.labels.iter().position(|l| *l == band.series).unwrap();
        let slopes: Vec<f64> = data.series(s).map(|p| p.scene.delta_deg()).collect();
        let lo = slopes.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = slopes.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(band.delta_deg.len(), BAND_GRID, "{what}");
        assert!((band.delta_deg[0] - lo).abs() < 1e-9, "{what}");
        assert!((band.delta_deg[BAND_GRID - 1] - hi).abs() < 1e-9, "{what}");
        assert!(
            band.draws <= BAND_DRAWS && band.draws > BAND_DRAWS / 2,
            "{what}"
        );
        for i in 0..BAND_GRID {
            let (a, m, z) = (band.q05[i], band.q50[i], band.q95[i]);
            assert!(
                a.is_finite() && a < m && m < z,
                "{what} at {}: {a} {m} {z}",
                band.delta_deg[i]
            );
        }
        // The band's ends are at the series' smallest and largest measured slopes, where the
        // point medians were computed on their own.
        for (end, slope) in [(0, lo), (BAND_GRID - 1, hi)] {
            let p = b
                .points
                .iter()
                .find(|p| p.fit == band.fit && p.series == band.series && p.delta_deg == slope)
                .unwrap();
            let d = (p.v_median - band.q50[end]).abs();
            assert!(
                d <= 1e-12 * p.v_median,
                "{what}: {} vs {}",
                p.v_median,
                band.q50[end]
            );
        }
    }
    // Under the K(α) laws v̄ at a point rises with the one parameter that sets its K (c, or
    // the series' K), so the median of v̄ over the draws is v̄ at the median parameter: the
    // fit's own v̄ at its posterior median (computed by the K-law problem's forward model,
    // on all the draws) must match within the Monte Carlo error of a median of the band's
    // draws, 1.2533 sd/√n (n draws, sd from the 90 % band: (q95 − q05)/3.29), doubled for the
    // fit's own median and taken four times.
    let mut worst: f64 = 0.0;
    for c in &an.contact {
        for f in [&c.law_c, &c.free].into_iter().flatten() {
            let name = format!("{}-{}", c.name, f.summary.stats.fit);
            for (k, pf) in f.summary.points.iter().enumerate() {
                let i = c.used[k];
                let p = b
                    .points
                    .iter()
                    .find(|p| p.fit == name && p.point == i)
                    .unwrap();
                let band = b
                    .bands
                    .iter()
                    .find(|x| x.fit == name && x.series == pf.series)
                    .unwrap();
                let sd = band
                    .q95
                    .iter()
                    .zip(&band.q05)
                    .map(|(z, a)| (z - a) / 3.29)
                    .fold(0.0, f64::max);
                let tol = 4.0 * 2f64.sqrt() * 1.2533 * sd / (band.draws as f64).sqrt();
                let z = (p.v_median - pf.v_fit).abs() / tol;
                worst = worst.max(z);
                assert!(
                    z <= 1.0,
                    "{name} point {i}: median {} vs v̄ at the median parameter {} (tolerance {tol:e})",
                    p.v_median,
                    pf.v_fit
                );
            }
        }
    }
    println!("K-law point medians: largest |difference|/tolerance {worst:.3}");
}
