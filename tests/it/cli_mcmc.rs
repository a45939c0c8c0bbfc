//! `--method mcmc` on the fit commands: report and draws columns, reproducibility from the
//! seed, flag errors (exit 2), and a clean stop on Ctrl-C (exit 130, draws written).

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{bin, col, table, tmpdir, write};

struct Run {
    out: Output,
    report: String,
    stats: String,
    draws: String,
}

fn run(dir: &Path, tag: &str, args: &[&str]) -> Run {
    let p = |s: &str| -> PathBuf { dir.join(format!("{tag}_{s}")) };
    let out = bin()
        .args(args)
        .arg("--output")
        .arg(p("r.csv"))
        .arg("--output-stats")
        .arg(p("s.csv"))
        .arg("--draws")
        .arg(p("d.csv"))
        .output()
        .unwrap();
    let read = |s: &str| std::fs::read_to_string(p(s)).unwrap_or_default();
    Run {
        report: read("r.csv"),
        stats: read("s.csv"),
        draws: read("d.csv"),
        out,
    }
}

#[test]
fn klaw_mcmc_report_draws_and_seed() {
    let dir = tmpdir();
    let args = [
        "klaw",
        "--model",
        "stick",
        "--method",
        "mcmc",
        "--seed",
        "7",
        "--min-ess",
        "400",
    ];
    let a = run(dir.path(), "a", &args);
    assert!(
        a.out.status.success(),
        "{}",
        String::from_utf8_lossy(&a.out.stderr)
    );
    let (h, rows) = table(&a.report);
    for c in [
        "fit",
        "series",
        "parameter",
        "value",
        "stderr",
        "ci_low",
        "ci_high",
        "ci_method",
        "unit",
        "mean",
        "sd",
        "q2.5",
        "q50",
        "q97.5",
        "ess_bulk",
        "ess_tail",
        "rhat",
        "tau",
    ] {
        col(&h, c);
    }
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    let f = |c: &str| r[col(&h, c)].parse::<f64>().unwrap();
    assert_eq!(r[col(&h, "ci_method")], "posterior");
    assert_eq!(r[col(&h, "parameter")], "c");
    assert!(f("ci_low") < f("value") && f("value") < f("ci_high"));
    // Default level 0.95: the interval is the 2.5 % and 97.5 % quantiles.
    assert_eq!(f("ci_low"), f("q2.5"));
    assert_eq!(f("ci_high"), f("q97.5"));
    assert_eq!(f("value"), f("q50"));
    assert!(f("ess_bulk") >= 400.0 && f("ess_tail") >= 400.0);
    assert!(f("rhat") <= 1.01);
    // The least-squares optimum lies well inside the posterior.
    let lsq = f("lsq_value");
    assert!((lsq - f("mean")).abs() < f("sd"), "{lsq} vs {}", f("mean"));
    let (sh, srows) = table(&a.stats);
    let s = srows.iter().find(|s| s[0] == "klaw-c").unwrap();
    assert_eq!(s[col(&sh, "method")], "mcmc");
    assert_eq!(s[col(&sh, "mcmc_status")], "converged");
    let kept: usize = s[col(&sh, "draws")].parse().unwrap();
    // The draws file: one row per kept draw, columns fit,series,walker,step,c,log_posterior.
    let (dh, drows) = table(&a.draws);
    assert_eq!(
        dh,
        ["fit", "series", "walker", "step", "c", "log_posterior"].map(String::from)
    );
    assert_eq!(drows.len(), kept);
    // Same seed, same bytes; another seed, other draws.
    let b = run(dir.path(), "b", &args);
    assert_eq!(a.report, b.report);
    assert_eq!(a.draws, b.draws);
    let mut other = args.to_vec();
    other[6] = "8";
    let c = run(dir.path(), "c", &other);
    assert!(c.out.status.success());
    assert_ne!(a.draws, c.draws);
}

#[test]
fn scale_is_sampled_without_sigma_and_with_fit_scatter() {
    let dir = tmpdir();
    // The default data without its sigma_v column: the scatter is a parameter.
    let text: String = std::fs::read_to_string(crate::common::root().join("data/default.csv"))
        .unwrap()
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            format!("{},{},{},{}\n", f[0], f[1], f[2], f[3])
        })
        .collect();
    let data = write(&dir, "nosigma.csv", &text);
    let common = ["--method", "mcmc", "--min-ess", "300"];
    let mut args = vec![
        "klaw",
        "--model",
        "stick",
        "--input",
        data.to_str().unwrap(),
    ];
    args.extend(common);
    let a = run(dir.path(), "ns", &args);
    assert!(
        a.out.status.success(),
        "{}",
        String::from_utf8_lossy(&a.out.stderr)
    );
    let (h, rows) = table(&a.report);
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r[col(&h, "parameter")].as_str())
        .collect();
    assert_eq!(names, ["c", "sigma_scale"]);
    // The scatter of the default data is about 2 % of v ≈ 0.3–1: s of order 0.01.
    let s: f64 = rows[1][col(&h, "value")].parse().unwrap();
    assert!(s > 0.002 && s < 0.05, "sigma_scale {s}");
    let (dh, _) = table(&a.draws);
    assert!(dh.contains(&"sigma_scale".to_string()));
    // With sigma given, --fit-scatter adds the scale (near 1: the default data were made by
    // the stickslip model with noise of the sigma given).
    let mut args = vec!["klaw", "--model", "stickslip", "--fit-scatter"];
    args.extend(common);
    let b = run(dir.path(), "fs", &args);
    assert!(
        b.out.status.success(),
        "{}",
        String::from_utf8_lossy(&b.out.stderr)
    );
    let (h, rows) = table(&b.report);
    assert_eq!(rows[1][col(&h, "parameter")], "sigma_scale");
    let lo: f64 = rows[1][col(&h, "ci_low")].parse().unwrap();
    let hi: f64 = rows[1][col(&h, "ci_high")].parse().unwrap();
    assert!(lo < 1.0 && 1.0 < hi, "sigma_scale interval [{lo}, {hi}]");
}

#[test]
fn jaeger_mcmc_reports_priors_and_names_what_did_not_converge() {
    let dir = tmpdir();
    let args = [
        "jaeger",
        "--method",
        "mcmc",
        "--prior",
        "a2=halfnormal(50)",
        "--max-steps",
        "1500",
        "--min-ess",
        "300",
    ];
    let a = run(dir.path(), "j", &args);
    let (h, rows) = table(&a.report);
    assert_eq!(rows.len(), 12, "a1, a2, a3 for four series");
    for r in &rows {
        assert_eq!(r[col(&h, "ci_method")], "posterior");
        let p = &r[col(&h, "parameter")];
        let prior = if p == "a2" {
            "prior halfnormal(50)"
        } else {
            "prior halfnormal(10)"
        };
        assert!(
            r[col(&h, "note")].contains(prior),
            "{p}: {}",
            r[col(&h, "note")]
        );
    }
    let (sh, srows) = table(&a.stats);
    let err = String::from_utf8_lossy(&a.out.stderr);
    // Exit 0 when every series converged, 1 (outputs written) when one stopped at --max-steps.
    let stopped = srows
        .iter()
        .any(|s| s[col(&sh, "mcmc_status")] == "max_steps");
    assert_eq!(a.out.status.code(), Some(i32::from(stopped)), "{err}");
    for s in &srows {
        let status = &s[col(&sh, "mcmc_status")];
        assert!(status == "converged" || status == "max_steps", "{status}");
        if status == "max_steps" {
            // The warning names the failing parameter, in the note and on stderr.
            assert!(s[col(&sh, "note")].contains("not converged after 1500 steps: parameter"));
            assert!(err.contains(&format!("jaeger [{}]: ", s[1])), "{err}");
        }
    }
}

fn expect_flag_error(args: &[&str], must: &[&str]) {
    let out = bin().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let e = String::from_utf8_lossy(&out.stderr);
    for m in must {
        assert!(e.contains(m), "{args:?}: '{m}' not in: {e}");
    }
}

#[test]
fn mcmc_flag_errors_exit_2() {
    expect_flag_error(
        &["klaw", "--model", "stick", "--draws", "x.csv"],
        &["--draws", "--method mcmc"],
    );
    expect_flag_error(
        &["klaw", "--model", "stick", "--method", "bayes"],
        &["--method", "bayes"],
    );
    expect_flag_error(
        &[
            "klaw", "--model", "stick", "--method", "mcmc", "--prior", "K=flat",
        ],
        &["--prior", "no parameter 'K'", "c, sigma_scale"],
    );
    expect_flag_error(
        &[
            "klaw",
            "--model",
            "stick",
            "--method",
            "mcmc",
            "--prior",
            "c=normal(0.5,-1)",
        ],
        &["--prior", "normal(0.5,-1)"],
    );
    expect_flag_error(
        &["jan", "--method", "mcmc", "--prior", "mu=gamma(1,1)"],
        &["unknown prior"],
    );
    expect_flag_error(
        &["jan", "--method", "mcmc", "--walkers", "7"],
        &["--walkers", "even"],
    );
    expect_flag_error(
        &[
            "klaw", "--model", "stick", "--law", "impact", "--method", "mcmc",
        ],
        &["no parameter to sample"],
    );
}

#[cfg(unix)]
#[test]
fn ctrl_c_stops_cleanly_and_writes_the_draws() {
    let dir = tmpdir();
    let p = |s: &str| dir.path().join(s);
    let mut child = bin()
        .args([
            "klaw",
            "--model",
            "stick",
            "--method",
            "mcmc",
            "--min-ess",
            "1e12",
            "--max-steps",
            "100000000",
        ])
        .arg("--output")
        .arg(p("r.csv"))
        .arg("--output-stats")
        .arg(p("s.csv"))
        .arg("--draws")
        .arg(p("d.csv"))
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let (sh, srows) = table(&std::fs::read_to_string(p("s.csv")).unwrap());
    let s = &srows[0];
    assert_eq!(s[col(&sh, "mcmc_status")], "interrupted");
    assert!(s[col(&sh, "note")].contains("interrupted"));
    let kept: usize = s[col(&sh, "draws")].parse().unwrap();
    let (_, drows) = table(&std::fs::read_to_string(p("d.csv")).unwrap());
    assert!(kept > 0);
    assert_eq!(drows.len(), kept);
}
