//! `report --method mcmc` on the default data: every posterior converges to the report's
//! thresholds in a few thousand steps (the posterior bands of v̄(δ) are tested in
//! `src/report/bands.rs`).

use crate::common::{bin, read_table, root, stderr, tmpdir};
use std::time::Instant;

/// Draws the report keeps per posterior for its figures, once summarised on all of them
/// (docs/GUIDE.md, "report").
const REPORT_DRAWS: usize = 10_000;

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
