//! lmfit's controls on the fit commands: `--fix`, `--init`, `--bounds` and `--scale-covar`
//! (and the builders' `fix`, `init`, `bounds`, `scale_covar`): a held parameter has no
//! standard error or interval and counts no degree of freedom, Jaeger with a2 held at 0 is
//! Jan's law (eq 74 is eq 80 with a2 = 0), a start or bounds move the start but not the
//! optimum, the covariance scaled by the reduced χ² is lmfit's, and every control that cannot
//! be used exits 2 naming its flag and value.

use crate::common::{bin, expect, records, root, s, stdout_ok};
use fitbead::prelude::*;
use std::collections::HashMap;

/// The parameter CSV of `fitbead ARGS… --output -` on the shipped data, as records.
fn params(args: &[&str]) -> Vec<HashMap<String, String>> {
    let data = root().join("data/default.csv");
    let out = bin()
        .args(args)
        .arg(s(&data))
        .args(["--output", "-", "--output-stats", "/dev/null"])
        .output()
        .unwrap();
    records(&stdout_ok(&out)).1
}

/// The statistics CSV of `fitbead ARGS…` on the shipped data, as records.
fn stats(args: &[&str]) -> Vec<HashMap<String, String>> {
    let data = root().join("data/default.csv");
    let out = bin()
        .args(args)
        .arg(s(&data))
        .args(["--output", "/dev/null", "--output-stats", "-"])
        .output()
        .unwrap();
    records(&stdout_ok(&out)).1
}

fn num(r: &HashMap<String, String>, c: &str) -> f64 {
    r[c].parse()
        .unwrap_or_else(|_| panic!("{c} = '{}' is not a number", r[c]))
}

/// The row of `parameter` of series `series`.
fn row<'a>(
    rows: &'a [HashMap<String, String>],
    series: &str,
    parameter: &str,
) -> &'a HashMap<String, String> {
    rows.iter()
        .find(|r| r["series"] == series && r["parameter"] == parameter)
        .unwrap_or_else(|| panic!("no {parameter} [{series}]"))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

#[test]
fn jaeger_with_a2_held_at_zero_is_jans_law() {
    let data = Dataset::default_data();
    let jan = JanFitter::new().least_squares(false).fit(&data).unwrap();
    let jaeger = JaegerFitter::new()
        .least_squares(false)
        .fix("a2", 0.0)
        .fit(&data)
        .unwrap();
    let mut worst = 0.0f64;
    for label in &data.labels {
        let j = jan.get("jan-series", label).unwrap();
        let g = jaeger.get("jaeger", label).unwrap();
        // The same curve through the same points: v̄ fitted at every point, and χ².
        assert_eq!(j.points.len(), g.points.len());
        for (a, b) in j.points.iter().zip(&g.points) {
            worst = worst.max(rel(b.v_fit, a.v_fit));
        }
        assert!(
            rel(g.chi2(), j.chi2()) < 1e-10,
            "{label}: {} {}",
            g.chi2(),
            j.chi2()
        );
        // μ is a1 (tan δ = a3 X + a1); a2 is held: no error, no interval, no dof.
        let (mu, a1) = (j.param("mu").unwrap(), g.param("a1").unwrap());
        assert!(
            rel(a1.value, mu.value) < 1e-9,
            "{label}: a1 {} mu {}",
            a1.value,
            mu.value
        );
        let a2 = g.param("a2").unwrap();
        assert!(a2.fixed && a2.value == 0.0 && a2.stderr.is_none());
        assert_eq!(a2.interval_method(), "none");
        assert_eq!((g.stats.n_params, g.stats.dof), (2, j.stats.dof));
        assert!(g.stats.note.contains("held fixed: a2"), "{}", g.stats.note);
        // AIC counts the free parameters: Jan's.
        assert!(rel(g.aic(), j.aic()) < 1e-10);
    }
    assert!(
        worst < 1e-10,
        "largest relative difference of v̄ fitted {worst:e}"
    );
    println!("jaeger a2 = 0 against jan: largest relative difference of v̄ fitted {worst:.2e}");
}

#[test]
fn the_command_line_holds_a_parameter() {
    let jan = params(&["jan"]);
    let jaeger = params(&["jaeger", "--fix", "a2=0"]);
    for series in ["0.8", "1", "1.6", "2"] {
        let mu = num(row(&jan, series, "mu"), "value");
        let a1 = num(row(&jaeger, series, "a1"), "value");
        assert!(rel(a1, mu) < 1e-9, "{series}: {a1} {mu}");
        let a2 = row(&jaeger, series, "a2");
        assert_eq!(a2["value"], "0");
        for c in ["stderr", "ci_low", "ci_high", "cov_low", "cov_high"] {
            assert_eq!(a2[c], "", "{c}");
        }
        assert_eq!(a2["ci_method"], "none");
        assert!(a2["note"].starts_with("fixed"), "{}", a2["note"]);
    }
    let st = stats(&["jaeger", "--fix", "a2=0"]);
    for r in &st {
        assert_eq!((num(r, "n_params"), num(r, "dof")), (2.0, 7.0), "{r:?}");
    }
    // One series only: NAME[SERIES].
    let one = params(&["jaeger", "--fix", "a2[1]=0"]);
    assert_eq!(row(&one, "1", "a2")["ci_method"], "none");
    assert_ne!(row(&one, "0.8", "a2")["ci_method"], "none");
}

#[test]
fn a_law_with_every_parameter_held_is_scored() {
    let st = stats(&["klaw", "--model", "stick", "--fix", "c=0.5"]);
    let c = &st[0];
    assert_eq!(c["termination"], "scored");
    assert_eq!((num(c, "n_params"), num(c, "dof")), (0.0, 36.0));
    let p = params(&["klaw", "--model", "stick", "--fix", "c=0.5"]);
    assert_eq!(row(&p, "all", "c")["value"], "0.5");
    assert_eq!(row(&p, "all", "c")["stderr"], "");
    // The same χ² as the library's law at c = 0.5, scored by hand.
    let data = Dataset::default_data();
    let fit = KLawFitter::new(Model::Stick, KLaw::C)
        .fix("c", 0.5)
        .fit(&data)
        .unwrap();
    let chi2: f64 = fit.residuals.iter().map(|r| r * r).sum();
    assert!(rel(num(c, "chi2"), chi2) < 1e-6);
    assert!(fit.converged() && fit.params[0].fixed);
}

#[test]
fn a_start_or_bounds_move_the_start_not_the_optimum() {
    let base = params(&["klaw", "--model", "stick", "--no-profile"]);
    let c0 = num(row(&base, "all", "c"), "value");
    let started = params(&[
        "klaw",
        "--model",
        "stick",
        "--no-profile",
        "--init",
        "c=0.9",
    ]);
    assert!(rel(num(row(&started, "all", "c"), "value"), c0) < 1e-8);
    // Bounds that hold the optimum change nothing; bounds beyond it put c on their end.
    let wide = params(&["klaw", "--model", "stick", "--bounds", "c=0.5,0.9"]);
    assert!(rel(num(row(&wide, "all", "c"), "value"), c0) < 1e-8);
    let hi = c0 - 0.01;
    let narrow = params(&[
        "klaw",
        "--model",
        "stick",
        "--bounds",
        &format!("c=0.5,{hi}"),
    ]);
    let c = row(&narrow, "all", "c");
    assert_eq!(num(c, "value"), hi);
    assert_eq!(c["at_bound"], "true");
    assert_eq!(c["profile_high_status"], "bound");
    // The library says where each fit started.
    let data = Dataset::default_data();
    let fit = KLawFitter::new(Model::Stick, KLaw::C)
        .least_squares(false)
        .init("c", 0.9)
        .fit(&data)
        .unwrap();
    assert_eq!(fit.params[0].start, Some(0.9));
}

#[test]
fn scale_covar_scales_the_errors_by_the_reduced_chi_square() {
    let data = Dataset::default_data();
    let plain = JanFitter::new().least_squares(false).fit(&data).unwrap();
    let scaled = JanFitter::new()
        .least_squares(false)
        .scale_covar(true)
        .fit(&data)
        .unwrap();
    assert_eq!(plain.fits.len(), 5);
    for (a, b) in plain.fits.iter().zip(&scaled.fits) {
        let k = a.reduced_chi2().sqrt();
        for (p, q) in a.params.iter().zip(&b.params) {
            // The global laws start from the series' values weighted by their errors: the
            // same optimum from another start.
            assert!(rel(q.value, p.value) < 1e-9, "{}", p.parameter);
            let (se, se_scaled) = (p.stderr.unwrap(), q.stderr.unwrap());
            assert!(
                rel(se_scaled, k * se) < 1e-8,
                "{}: {se_scaled} {se}",
                p.parameter
            );
            // The covariance interval on Student-t, as without sigma.
            let (lo, hi) = q.cov.unwrap();
            let t = (hi - lo) / (2.0 * se_scaled);
            assert!(t > 1.96 && t < 2.5, "{t}");
        }
        assert!(b.stats.scale_covar && !a.stats.scale_covar);
        assert!(rel(b.chi2(), a.chi2()) < 1e-12 && rel(b.aic(), a.aic()) < 1e-12);
    }
    // On the command line: the report's sigma line and the statistics' note say so.
    let d = root().join("data/default.csv");
    let out = bin()
        .args(["jan", "--scale-covar", "--no-profile", s(&d)])
        .output()
        .unwrap();
    let text = stdout_ok(&out);
    assert!(
        text.contains("covariance scaled by reduced chi-square"),
        "{text}"
    );
    let st = stats(&["jan", "--scale-covar", "--no-profile"]);
    assert!(st[0]["note"].contains("covariance scaled by reduced chi-square"));
}

#[test]
fn controls_that_cannot_be_used_exit_2_naming_flag_and_value() {
    let d = root().join("data/default.csv");
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["jaeger", "--fix", "a4=0"],
            &["'--fix'", "'a4=0'", "expected one of a1, a2, a3"],
        ),
        (&["jaeger", "--fix", "a2=x"], &["'--fix'", "'a2=x'"]),
        (
            &["jan", "--fix", "lamda=0.5"],
            &["'--fix'", "no parameter 'lamda'", "did you mean 'lambda'?"],
        ),
        (
            &["jaeger", "--fix", "a2=-1"],
            &["'--fix'", "outside the box"],
        ),
        (
            &["jaeger", "--fix", "a2[9]=0"],
            &["'--fix'", "no series '9'"],
        ),
        (
            &["jan", "--init", "mu=0.5"],
            &["'--init'", "'mu=0.5'", "outside the box"],
        ),
        (
            &["jan", "--bounds", "mu=-2,-1"],
            &["'--bounds'", "'mu=-2,-1'", "leaves nothing of the box"],
        ),
        (&["jan", "--bounds", "mu=1,0"], &["'--bounds'", "LO < HI"]),
        (&["jan", "--bounds", "mu=1"], &["'--bounds'", "NAME=LO,HI"]),
        (
            &["jan", "--fix", "mu=0.1", "--init", "mu=0.1"],
            &["'--fix'", "mu is held"],
        ),
        (
            &[
                "klaw", "--model", "stick", "--law", "impact", "--fix", "c=1",
            ],
            &["'--fix'", "this fit has none"],
        ),
        (
            &["klaw", "--model", "stick", "--fix", "K=1"],
            &["'--fix'", "no parameter 'K'", "expected one of c"],
        ),
        (
            &["jaeger", "--method", "mcmc", "--scale-covar"],
            &["'--scale-covar'", "--method lsq only"],
        ),
        (
            &[
                "klaw", "--model", "stick", "--method", "mcmc", "--fix", "c=0.6",
            ],
            &["'--fix'", "nothing to sample"],
        ),
        (
            &[
                "jaeger", "--method", "mcmc", "--fix", "a2=0", "--prior", "a2=flat",
            ],
            &["'--prior'", "a2 is held"],
        ),
    ];
    for (args, must) in cases {
        let out = bin().args(*args).arg(s(&d)).output().unwrap();
        expect(&out, 2, must, &args.join(" "));
    }
}

#[test]
fn held_parameters_reach_posterior_runs_and_slope_errors() {
    // A posterior run samples the free parameters; the held one is a constant column.
    let data = Dataset::default_data();
    let mut settings = McmcSettings::seeded(3);
    settings.options.min_ess = 200.0;
    let set = JaegerFitter::new()
        .mcmc(settings)
        .fix("a2", 0.0)
        .fit(&data)
        .unwrap();
    let f = set.get("jaeger", "0.8").unwrap();
    let a2 = f.draws_of("a2").unwrap();
    assert!(a2.iter().all(|v| *v == 0.0) && !a2.is_empty());
    assert!(f.param("a2").unwrap().posterior.is_none());
    assert!(f.param("a1").unwrap().posterior.is_some());
    // Slopes with errors: the orthogonal distance regression in the free parameters.
    let odr = root().join("tests/reference/odr/bead_stick.csv");
    let out = bin()
        .args(["jaeger", "--fix", "a2=0", s(&odr), "--output-stats", "-"])
        .args(["--output", "/dev/null"])
        .output()
        .unwrap();
    let st = records(&stdout_ok(&out)).1;
    assert!(st
        .iter()
        .all(|r| r["method"] == "odr" && r["n_params"] == "2"));
}
