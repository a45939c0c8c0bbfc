//! Fits at their edges: data that cannot determine the parameters (fewer distinct slopes than
//! parameters, or a χ² of 0 with no σ given) report no standard errors and no intervals (empty
//! cells, not zero-width ones) with a note saying why, and never an AIC or BIC of −inf.

use crate::common::{bin, read_table, records, stdout_ok, tmpdir, write};
use std::collections::HashMap;
use std::path::Path;

/// Four identical points, no σ: one distinct slope, χ² = 0 at any exact fit.
const IDENTICAL: &str = "series,xi,delta_deg,v\nA,1,3,0.5\nA,1,3,0.5\nA,1,3,0.5\nA,1,3,0.5\n";

/// Four points with scatter at two slopes, no σ: two distinct slopes.
const TWO_SLOPES: &str =
    "series,xi,delta_deg,v\nA,1,10,0.50\nA,1,10,0.52\nA,1,20,0.80\nA,1,20,0.83\n";

/// Rows of a CSV, each keyed by column name.
type Rows = Vec<HashMap<String, String>>;

/// Runs `cmd` on `data`: the fit report, the parameter rows and the statistics rows.
fn run(dir: &Path, cmd: &[&str], data: &str) -> (String, Rows, Rows) {
    let input = write(dir, "data.csv", data);
    let report = stdout_ok(&bin().args(cmd).arg(&input).output().unwrap());
    let stats = dir.join("stats.csv");
    let out = bin()
        .args(cmd)
        .arg(&input)
        .args(["--output", "-", "--output-stats"])
        .arg(&stats)
        .output()
        .unwrap();
    let (_, params) = records(&stdout_ok(&out));
    let (h, rows) = read_table(&stats);
    let stats = rows
        .into_iter()
        .map(|r| h.iter().cloned().zip(r).collect())
        .collect();
    (report, params, stats)
}

/// Every parameter row of `fit` has no standard error and no interval, and says why.
fn assert_no_interval(params: &[HashMap<String, String>], fit: &str) {
    let rows: Vec<_> = params.iter().filter(|r| r["fit"] == fit).collect();
    assert!(!rows.is_empty(), "no rows of {fit}: {params:?}");
    for r in rows {
        for c in ["stderr", "ci_low", "ci_high", "cov_low", "cov_high"] {
            assert_eq!(r[c], "", "{fit} {}: {c} = {}", r["parameter"], r[c]);
        }
        assert_eq!(r["ci_method"], "none", "{fit} {}", r["parameter"]);
        assert!(r["note"].contains("not determined by the data"), "{r:?}");
    }
}

#[test]
fn identical_points_give_jan_and_jaeger_no_interval_and_no_infinite_aic() {
    let dir = tmpdir();
    for (cmd, fit, why) in [
        (
            &["jan"][..],
            "jan-series",
            "1 distinct point(s) for 2 parameters",
        ),
        (
            &["jaeger"][..],
            "jaeger",
            "1 distinct point(s) for 3 parameters",
        ),
    ] {
        let (report, params, stats) = run(dir.path(), cmd, IDENTICAL);
        assert!(report.contains(why), "{fit}: {report}");
        assert!(!report.contains("95% interval ["), "{fit}: {report}");
        assert!(!report.contains("inf"), "{fit}: {report}");
        assert!(
            report.contains("AIC                = undefined"),
            "{report}"
        );
        assert_no_interval(&params, fit);
        let s = stats.iter().find(|r| r["fit"] == fit).unwrap();
        assert_eq!(s["series"], "A");
        assert_eq!((s["aic"].as_str(), s["bic"].as_str()), ("", ""), "{s:?}");
        assert!(s["note"].contains(why), "{s:?}");
        assert!(s["note"].contains("AIC and BIC undefined"), "{s:?}");
    }
}

#[test]
fn fewer_distinct_slopes_than_parameters_leave_jaeger_undetermined_despite_scatter() {
    let dir = tmpdir();
    let (report, params, stats) = run(dir.path(), &["jaeger"], TWO_SLOPES);
    assert!(
        report.contains("2 distinct point(s) for 3 parameters"),
        "{report}"
    );
    assert_no_interval(&params, "jaeger");
    let s = &stats[0];
    assert!(s["aic"].parse::<f64>().unwrap().is_finite(), "{s:?}");
}

#[test]
fn as_many_distinct_slopes_as_parameters_still_give_jan_intervals() {
    let dir = tmpdir();
    let (_, params, _) = run(dir.path(), &["jan"], TWO_SLOPES);
    for r in params.iter().filter(|r| r["fit"] == "jan-series") {
        let (lo, hi): (f64, f64) = (r["ci_low"].parse().unwrap(), r["ci_high"].parse().unwrap());
        let se: f64 = r["stderr"].parse().unwrap();
        assert!(lo < hi && se > 0.0, "{r:?}");
        assert!(!r["note"].contains("not determined"), "{r:?}");
    }
}

#[test]
fn identical_points_give_klaw_no_interval_though_chi2_is_rounding_not_zero() {
    let dir = tmpdir();
    for (law, fit) in [("c", "klaw-c"), ("free-per-series", "klaw-free-per-series")] {
        let cmd = ["klaw", "--model", "stick", "--law", law];
        let (report, params, stats) = run(dir.path(), &cmd, IDENTICAL);
        assert!(
            report.contains("the scatter is estimated as 0"),
            "{fit}: {report}"
        );
        assert!(!report.contains("95% interval ["), "{fit}: {report}");
        assert!(
            report.contains("AIC                = undefined"),
            "{report}"
        );
        assert_no_interval(&params, fit);
        let s = stats.iter().find(|r| r["fit"] == fit).unwrap();
        let chi2: f64 = s["chi2"].parse().unwrap();
        assert!(chi2 < 1e-25, "{s:?}");
        assert_eq!((s["aic"].as_str(), s["bic"].as_str()), ("", ""), "{s:?}");
        assert!(s["note"].contains("the scatter is estimated as 0"), "{s:?}");
        assert!(s["note"].contains("AIC and BIC undefined"), "{s:?}");
    }
}

#[test]
fn identical_points_with_sigma_keep_klaw_intervals() {
    let dir = tmpdir();
    let data = "series,xi,delta_deg,v,sigma_v\nA,1,3,0.5,0.01\nA,1,3,0.5,0.01\nA,1,3,0.5,0.01\n";
    let (_, params, _) = run(dir.path(), &["klaw", "--model", "stick"], data);
    let r = params.iter().find(|r| r["fit"] == "klaw-c").unwrap();
    let (lo, hi): (f64, f64) = (r["ci_low"].parse().unwrap(), r["ci_high"].parse().unwrap());
    assert!(lo < hi, "{r:?}");
    assert!(!r["note"].contains("not determined"), "{r:?}");
}

#[test]
fn identical_points_leave_the_posterior_of_the_scale_improper_and_unsampled() {
    let dir = tmpdir();
    let input = write(dir.path(), "data.csv", IDENTICAL);
    for cmd in [&["klaw", "--model", "stick"][..], &["jan"][..]] {
        let t0 = std::time::Instant::now();
        let out = bin()
            .args(cmd)
            .arg(&input)
            .args(["--method", "mcmc", "--seed", "1", "--output", "-"])
            .output()
            .unwrap();
        let took = t0.elapsed();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{cmd:?}: {err}");
        assert!(
            err.contains("posterior of the scatter's scale improper"),
            "{err}"
        );
        // Refused before sampling: no 100,000 steps towards a scale of 0.
        assert!(took.as_secs_f64() < 10.0, "{cmd:?} took {took:?}");
        let (_, params) = records(&String::from_utf8_lossy(&out.stdout));
        let fit = if cmd[0] == "klaw" {
            "klaw-c"
        } else {
            "jan-series"
        };
        let rows: Vec<_> = params.iter().filter(|r| r["fit"] == fit).collect();
        assert!(!rows.is_empty(), "{params:?}");
        for r in rows {
            for c in ["stderr", "ci_low", "ci_high", "mean", "sd"] {
                assert_eq!(r[c], "", "{fit} {}: {c}", r["parameter"]);
            }
            assert!(r["note"].contains("MCMC did not run"), "{r:?}");
        }
    }
}
