//! Honesty under stress: intervals that widen with the noise, misfits named by their χ² tail
//! probability, simulated data a fit can take at any noise allowed, floating-point edges,
//! runs that stop on a signal, and outputs that never replace what they should not.

use crate::common::{bin, records, s, stderr, tmpdir, write};
use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs fitbead with `args` in `dir`.
fn fb(dir: &Path, args: &[&str]) -> Output {
    bin().args(args).current_dir(dir).output().unwrap()
}

/// Runs fitbead with `args` in `dir`, which must succeed; its stdout.
fn fb_ok(dir: &Path, args: &[&str]) -> String {
    let out = fb(dir, args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    String::from_utf8(out.stdout).unwrap()
}

/// The row of `fit` (and `series`) in a CSV text with `fit` and `series` columns.
fn row<'a>(
    rows: &'a [HashMap<String, String>],
    fit: &str,
    series: &str,
) -> &'a HashMap<String, String> {
    rows.iter()
        .find(|r| r["fit"] == fit && r["series"] == series)
        .unwrap_or_else(|| panic!("no row {fit} [{series}]"))
}

fn num(r: &HashMap<String, String>, c: &str) -> f64 {
    r[c].parse()
        .unwrap_or_else(|_| panic!("{c} = {:?} is not a number", r[c]))
}

/// The reported 95 % interval of the law's c grows with the noise on average (five seeds at
/// each noise), and it holds every profile end the profile found. The interval once dropped
/// both profile ends when one of them stopped at the edge of the feasible region and fell back
/// to a covariance interval cut to the box, which shrank as the noise grew.
#[test]
fn interval_widens_with_noise_and_holds_the_profile_ends() {
    let d = tmpdir();
    let noises = [0.05, 0.1, 0.2, 0.3, 0.45];
    let mut mean_width = Vec::new();
    for n in noises {
        let mut widths = Vec::new();
        for seed in [7, 11, 12, 13, 14] {
            let name = format!("s{n}-{seed}.csv");
            let (ns, ss) = (n.to_string(), seed.to_string());
            fb_ok(
                d.path(),
                &["simulate", "--noise", &ns, "--seed", &ss, "--output", &name],
            );
            let out = fb_ok(
                d.path(),
                &["klaw", "--model", "stickslip", &name, "--output", "-"],
            );
            let (_, rows) = records(&out);
            let r = row(&rows, "klaw-c", "all");
            let (lo, hi) = (num(r, "ci_low"), num(r, "ci_high"));
            for (end, status) in [
                ("profile_low", "profile_low_status"),
                ("profile_high", "profile_high_status"),
            ] {
                if r[status] == "found" {
                    let v = num(r, end);
                    assert!(
                        lo <= v && v <= hi,
                        "noise {n} seed {seed}: the found {end} {v} lies outside the reported \
                         interval [{lo}, {hi}] ({})",
                        r["ci_method"]
                    );
                }
            }
            widths.push(hi - lo);
        }
        mean_width.push(widths.iter().sum::<f64>() / widths.len() as f64);
    }
    println!("noise {noises:?}: mean 95 % width of c {mean_width:?}");
    for (i, w) in mean_width.windows(2).enumerate() {
        assert!(
            w[1] > w[0],
            "the mean width falls from noise {} to {}: {mean_width:?}",
            noises[i],
            noises[i + 1]
        );
    }
}

/// The issue's own case: noise 0.45, seed 11. The upper profile end was found at 0.53126 and
/// the lower one reached the edge of the feasible region, which here is the box's bound of c;
/// the interval keeps the found end and reaches the bound (it once fell back to the covariance
/// interval on both sides, 0.47401–0.48728).
#[test]
fn an_edge_end_keeps_the_found_end() {
    let d = tmpdir();
    fb_ok(
        d.path(),
        &[
            "simulate", "--noise", "0.45", "--seed", "11", "--output", "s.csv",
        ],
    );
    let out = fb_ok(
        d.path(),
        &["klaw", "--model", "stickslip", "s.csv", "--output", "-"],
    );
    let (_, rows) = records(&out);
    let r = row(&rows, "klaw-c", "all");
    assert_eq!(r["profile_high_status"], "found", "{r:?}");
    assert_eq!(r["profile_low_status"], "edge", "{r:?}");
    assert_eq!(r["ci_high"], r["profile_high"]);
    assert!((num(r, "ci_high") - 0.53126).abs() < 1e-4, "{r:?}");
    // The lower end: the farther of the edge and the covariance end, cut to the box.
    assert!(num(r, "ci_low") <= num(r, "profile_low"), "{r:?}");
    assert!(num(r, "ci_low") >= num(r, "cov_low"), "{r:?}");
    assert!(
        r["note"].contains("edge of the model's feasible region"),
        "{}",
        r["note"]
    );
    // The MCMC run on the same file gives 0.4748–0.5355 (the issue's figures): the interval
    // now spans it but for its last 0.004.
    assert!(
        num(r, "ci_low") < 0.4748 && num(r, "ci_high") > 0.53,
        "{r:?}"
    );
}

/// ln Γ(x) by Lanczos' approximation (g = 7, n = 9), for the test's own χ² tail probability.
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// P(χ²_k ≥ x) = Q(k/2, x/2), the regularised upper incomplete gamma function: by its series
/// below a + 1 and by its continued fraction (modified Lentz) above. Independent of the
/// library's (statrs) implementation.
fn chi2_tail(k: f64, x: f64) -> f64 {
    let (a, x) = (0.5 * k, 0.5 * x);
    if x <= 0.0 {
        return 1.0;
    }
    let ln_pre = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * ln_pre.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut dd = 1.0 / b;
        let mut h = dd;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            dd = an * dd + b;
            if dd.abs() < tiny {
                dd = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            dd = 1.0 / dd;
            let del = dd * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        ln_pre.exp() * h
    }
}

#[test]
fn the_tests_chi2_tail_matches_known_values() {
    // Known values (tables of the χ² distribution): the 0.001 critical values for 1, 10 and
    // 35 degrees of freedom are 10.828, 29.588 and 66.619; P(χ²_2 ≥ x) = exp(−x/2).
    for (k, x) in [(1.0, 10.828), (10.0, 29.588), (35.0, 66.619)] {
        let p = chi2_tail(k, x);
        assert!((p - 1e-3).abs() < 2e-6, "k {k}: {p}");
    }
    for x in [0.5, 3.0, 40.0] {
        let p = chi2_tail(2.0, x);
        assert!((p / (-x / 2.0f64).exp() - 1.0).abs() < 1e-12, "{x}: {p}");
    }
}

/// One fit of a simulated data set: the command's stats rows and whether stderr warned of a
/// misfit for each.
struct FitRun {
    label: String,
    /// (fit, series, χ², dof, warned)
    rows: Vec<(String, String, f64, usize, bool)>,
}

fn run_pair(dir: &Path, sim: &[&str], fit: &[&str], label: &str) -> Option<FitRun> {
    let data = format!("{}.csv", label.replace(['/', ' ', '>'], "_"));
    let mut a = vec!["simulate"];
    a.extend_from_slice(sim);
    a.extend_from_slice(&["--output", &data]);
    let out = fb(dir, &a);
    assert!(out.status.success(), "{label}: {}", stderr(&out));
    let mut a = fit.to_vec();
    a.extend_from_slice(&[&data, "--output", "/dev/null", "--output-stats", "-"]);
    let out = fb(dir, &a);
    if !out.status.success() {
        // No parameter keeps every point steady: an error, no interval at all.
        assert_eq!(out.status.code(), Some(2), "{label}: {}", stderr(&out));
        return None;
    }
    let err = stderr(&out);
    let (_, rows) = records(&String::from_utf8(out.stdout).unwrap());
    let rows = rows
        .iter()
        .filter(|r| !r["chi2"].is_empty() && r["n_params"] != "0")
        .map(|r| {
            let prefix = format!("warning: {} [{}]: misfit", r["fit"], r["series"]);
            (
                r["fit"].clone(),
                r["series"].clone(),
                num(r, "chi2"),
                r["dof"].parse().unwrap(),
                err.contains(&prefix),
            )
        })
        .collect();
    Some(FitRun {
        label: label.into(),
        rows,
    })
}

/// Data simulated with one model or law and fitted with another: every fit whose χ² tail
/// probability is below 0.001 (computed here independently of the library) warns, naming
/// it as a misfit, and no fit of the model and law that made the data does. Before, only a
/// reduced χ² above 1000 warned: slip data fitted by the rolling model (reduced χ² 160) passed
/// in silence.
#[test]
fn misfits_warn_by_their_chi2_tail_probability() {
    let d = tmpdir();
    let mut mismatched = Vec::new();
    let mut matched = Vec::new();
    let klaw = |m: &'static str| vec!["klaw", "--model", m, "--law", "c", "--skip-unsteady"];
    // Model against model, and the impact law against law c.
    for seed in ["2", "3", "5"] {
        for (sm, fm) in [
            ("slip", "stick"),
            ("stickslip", "stick"),
            ("contact", "stick"),
            ("contact", "stickslip"),
        ] {
            let label = format!("{sm}>{fm} seed {seed}");
            let sim = ["--model", sm, "--law", "c=0.5", "--seed", seed];
            mismatched.extend(run_pair(d.path(), &sim, &klaw(fm), &label));
        }
        for m in ["stick", "slip", "stickslip"] {
            let label = format!("{m} impact>c seed {seed}");
            let sim = ["--model", m, "--law", "impact", "--seed", seed];
            mismatched.extend(run_pair(d.path(), &sim, &klaw(m), &label));
        }
        for (sm, cmd) in [("jaeger", "jan"), ("stick", "jan"), ("stickslip", "jaeger")] {
            let label = format!("{sm}>{cmd} seed {seed}");
            let sim = ["--model", sm, "--seed", seed];
            mismatched.extend(run_pair(d.path(), &sim, &[cmd], &label));
        }
        // The model and law that made the data.
        for m in ["stick", "slip", "stickslip", "contact"] {
            let label = format!("{m}>{m} seed {seed}");
            let sim = ["--model", m, "--law", "c=0.45", "--seed", seed];
            matched.extend(run_pair(d.path(), &sim, &klaw(m), &label));
            let label = format!("{m} free seed {seed}");
            let sim = ["--model", m, "--seed", seed];
            let fit = ["klaw", "--model", m, "--law", "free-per-series"];
            matched.extend(run_pair(d.path(), &sim, &fit, &label));
        }
        for m in ["jan", "jaeger"] {
            let label = format!("{m}>{m} seed {seed}");
            let sim = ["--model", m, "--seed", seed];
            matched.extend(run_pair(d.path(), &sim, &[m], &label));
        }
    }
    // md data fitted by stick/slip (one seed: the simulation takes seconds).
    let sim = ["--model", "md", "--seed", "2"];
    mismatched.extend(run_pair(d.path(), &sim, &klaw("stickslip"), "md>stickslip"));
    assert!(
        mismatched.len() >= 30,
        "{} mismatched pairs fitted",
        mismatched.len()
    );
    assert!(
        matched.len() >= 30,
        "{} matched pairs fitted",
        matched.len()
    );
    let mut flagged = 0;
    for run in &mismatched {
        for (fit, series, chi2, dof, warned) in &run.rows {
            let p = chi2_tail(*dof as f64, *chi2);
            println!(
                "{} {fit} [{series}]: chi2 {chi2:.4} dof {dof} p {p:.3e} warned {warned}",
                run.label
            );
            assert_eq!(
                *warned,
                p < 1e-3,
                "{} {fit} [{series}]: chi2 {chi2} on {dof}, p = {p:e}",
                run.label
            );
            flagged += usize::from(*warned);
        }
    }
    for run in &matched {
        for (fit, series, chi2, dof, warned) in &run.rows {
            assert!(
                !warned,
                "matched pair {} {fit} [{series}] warns: chi2 {chi2} on {dof}",
                run.label
            );
        }
    }
    // The issue's cases are among the flagged: slip data under rolling, impact-law data under
    // law c, md data under stick/slip.
    for label in ["slip>stick seed 2", "stick impact>c seed 2", "md>stickslip"] {
        let run = mismatched.iter().find(|r| r.label == label).unwrap();
        assert!(run.rows.iter().all(|r| r.4), "{label} does not warn");
    }
    println!(
        "{flagged} fit rows flagged over {} mismatched pairs; {} matched pairs, none flagged",
        mismatched.len(),
        matched.len()
    );
}

/// The report names misfits in report.md's warnings section.
#[test]
fn report_names_a_misfit() {
    let d = tmpdir();
    fb_ok(
        d.path(),
        &[
            "simulate",
            "--model",
            "stickslip",
            "--law",
            "impact",
            "--seed",
            "2",
            "--output",
            "imp.csv",
        ],
    );
    let out = fb(
        d.path(),
        &[
            "report",
            "--input",
            "imp.csv",
            "--out-dir",
            "r",
            "--format",
            "svg",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let md = std::fs::read_to_string(d.path().join("r/report.md")).unwrap();
    assert!(md.contains("chi2 tail probability below 0.001"), "{md}");
    assert!(
        md.contains("- stickslip-klaw-c [all]: misfit: chi2 ="),
        "{md}"
    );
}

/// Simulated velocities are positive at any noise allowed (the noise is truncated to v > 0),
/// so every fit takes them. At noise 0.45, 9 of the seeds 1–26 once wrote negative velocities.
#[test]
fn simulated_velocities_are_positive_at_high_noise() {
    let d = tmpdir();
    let mut fitted = 0;
    for seed in 1..=26 {
        let seed = seed.to_string();
        let text = fb_ok(
            d.path(),
            &[
                "simulate", "--noise", "0.45", "--seed", &seed, "--output", "-",
            ],
        );
        let (_, rows) = records(&text);
        assert!(rows.iter().all(|r| num(r, "v") > 0.0), "seed {seed}");
        let p = write(d.path(), "n.csv", &text);
        let out = fb(
            d.path(),
            &[
                "klaw",
                "--model",
                "stickslip",
                s(&p),
                "--output",
                "/dev/null",
            ],
        );
        // Exit 2 is a refusal of the data; seed 9 ends at exit 1, its optimum pinned against
        // the edge of the feasible region (a fit that does not converge, named as such).
        assert_ne!(out.status.code(), Some(2), "seed {seed}: {}", stderr(&out));
        fitted += usize::from(out.status.success());
    }
    assert!(fitted >= 25, "{fitted} of 26 fitted");
}

/// A posterior run cut off at `--max-steps` says so on every parameter row, as an interrupted
/// run does; its sd and interval come from chains that have not mixed.
#[test]
fn a_run_stopped_at_the_step_cap_flags_every_row() {
    let d = tmpdir();
    let data = crate::common::root().join("data/default.csv");
    let out = fb(
        d.path(),
        &[
            "klaw",
            "--model",
            "stick",
            "--law",
            "free-per-series",
            s(&data),
            "--method",
            "mcmc",
            "--max-steps",
            "1",
            "--output",
            "-",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let (_, rows) = records(&String::from_utf8(out.stdout.clone()).unwrap());
    let posterior: Vec<_> = rows
        .iter()
        .filter(|r| r["ci_method"] == "posterior")
        .collect();
    assert_eq!(posterior.len(), 4);
    for r in posterior {
        assert!(
            r["note"].starts_with("stopped at the step cap, not converged"),
            "{}",
            r["note"]
        );
    }
    // The non-convergence message names a parameter as the draws file does (K[0.8]).
    let e = stderr(&out);
    assert!(!e.contains("of this fit"), "{e}");
    assert!(
        e.contains("parameter 'K[") || e.contains("too few draws"),
        "{e}"
    );
}

/// The last row of `forward`'s CSV output, keyed by column.
fn forward_row(dir: &Path, args: &[&str]) -> HashMap<String, String> {
    let mut a = vec!["forward"];
    a.extend_from_slice(args);
    let (_, rows) = records(&fb_ok(dir, &a));
    rows.into_iter().last().unwrap()
}

/// Floating-point edges: f² overflowing, ξ at the ends of the doubles. A steady result with
/// no finite positive velocity is `invalid`, never `ok`.
#[test]
fn floating_point_edges_of_the_forward_models() {
    let d = tmpdir();
    let p = d.path();
    let base = ["--model", "stickslip", "--xi", "0.8", "--delta-deg", "12"];
    let at = |f: &str| {
        let mut a = base.to_vec();
        a.extend_from_slice(&["--f", f]);
        forward_row(p, &a)
    };
    let reference = at("1e150");
    assert_eq!(reference["status"], "ok");
    for f in ["1e154", "1e200", "1.7e308"] {
        let r = at(f);
        assert_eq!(r["status"], "ok", "f {f}: {r:?}");
        assert_eq!(r["v"], reference["v"], "f {f}: rolling, as at 1e150");
    }
    for (model, xi, extra) in [
        ("slip", "1e300", vec!["--K", "0.5"]),
        ("slip", "1e20", vec!["--K", "0.5"]),
        (
            "jaeger",
            "5e-324",
            vec!["--K", "0.5", "--a1", "0.1", "--a2", "1", "--a3", "1"],
        ),
    ] {
        let mut a = vec!["--model", model, "--xi", xi, "--delta-deg", "12"];
        a.extend(extra);
        let r = forward_row(p, &a);
        assert_eq!(r["status"], "invalid", "{model} at xi {xi}: {r:?}");
        assert!(r["v"].is_empty());
    }
}

/// A design for an absolute σ does not depend on σ: the same slopes at 1e-160, 0.01 and 1e160,
/// the same efficiency, and standard errors in proportion to σ.
#[test]
fn an_absolute_noise_design_does_not_depend_on_sigma() {
    let d = tmpdir();
    let run = |noise: &str| {
        let out = fb(
            d.path(),
            &[
                "design",
                "--fit",
                "klaw",
                "--model",
                "stickslip",
                "--noise",
                noise,
                "--output",
                "-",
            ],
        );
        assert!(out.status.success(), "{noise}: {}", stderr(&out));
        (String::from_utf8(out.stdout.clone()).unwrap(), stderr(&out))
    };
    let (mid, mid_summary) = run("abs=0.01");
    for noise in ["abs=1e-160", "abs=1e160"] {
        let (rows, summary) = run(noise);
        assert_eq!(rows, mid, "{noise}: the design moved");
        let eff = |s: &str| {
            s.lines()
                .find(|l| l.contains("efficiency"))
                .unwrap_or_else(|| panic!("{s}"))
                .to_string()
        };
        assert_eq!(eff(&summary), eff(&mid_summary), "{noise}");
        assert!(!summary.contains("NaN"), "{summary}");
    }
    let se = |s: &str| -> f64 {
        let l = s.lines().find(|l| l.contains("c = 0.5:")).unwrap();
        l.split(':')
            .nth(1)
            .unwrap()
            .split('/')
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    let (_, small) = run("abs=1e-160");
    let ratio = se(&small) / se(&mid_summary);
    assert!((ratio / 1e-158 - 1.0).abs() < 1e-2, "{ratio:e}");
}

/// The shipped data with the cell of `column` (0-based) on file line 3 set to `value`,
/// written to `name` in `dir`.
fn default_with(dir: &Path, name: &str, column: usize, value: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[2].split(',').map(String::from).collect();
    cells[column] = value.into();
    lines[2] = cells.join(",");
    write(dir, name, &(lines.join("\n") + "\n"))
}

/// σ finer than the rounding of the velocity is refused, naming the cell (so is a velocity of
/// 1e200 beside σ = 0.006, which once fitted to χ² = ∞ with no word); a velocity of 1e10 is
/// named an implausible misfit.
#[test]
fn sigma_below_rounding_is_refused_and_an_absurd_velocity_warned() {
    let d = tmpdir();
    let klaw = |p: &Path| {
        fb(
            d.path(),
            &[
                "klaw",
                "--model",
                "stickslip",
                s(p),
                "--output",
                "/dev/null",
            ],
        )
    };
    let out = klaw(&default_with(d.path(), "tiny.csv", 4, "1e-300"));
    crate::common::expect(
        &out,
        2,
        &["line 3", "column 'sigma_v'", "value '1e-300'"],
        "tiny sigma",
    );
    let out = klaw(&default_with(d.path(), "huge.csv", 3, "1e200"));
    crate::common::expect(
        &out,
        2,
        &["line 3", "column 'sigma_v'", "(1e200)"],
        "v 1e200",
    );
    // One point at 1e10 is an outlier, named as one, not a unit mistake.
    let out = klaw(&default_with(d.path(), "big.csv", 3, "1e10"));
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("warning: klaw-c [all]: 1 outlier(s)")
            && err.contains("series '0.8', delta 11.2709 deg, v 10000000000"),
        "{err}"
    );
    assert!(!err.contains("are the velocities dimensionless"), "{err}");
}

/// One velocity at 3× its value is named as an outlier by every fit it enters (series,
/// slope, value and normalised residual), without a unit warning; every velocity at 100× is a
/// unit mistake, warned as one, with no outlier named.
#[test]
fn one_outlier_is_named_and_a_unit_mistake_stays_one() {
    let d = tmpdir();
    let text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let scaled = |line: usize, by: f64| -> String {
        let mut out = String::new();
        for (i, l) in text.lines().enumerate() {
            let mut c: Vec<String> = l.split(',').map(String::from).collect();
            if i > 0 && (line == 0 || i == line) {
                c[3] = (c[3].parse::<f64>().unwrap() * by).to_string();
            }
            out.push_str(&c.join(","));
            out.push('\n');
        }
        out
    };
    // Line 6 of the file: series 0.8, δ = 12.613°.
    let one = write(d.path(), "one.csv", &scaled(6, 3.0));
    let all = write(d.path(), "all.csv", &scaled(0, 100.0));
    for cmd in [&["klaw", "--model", "stick"][..], &["jan"]] {
        let run = |p: &Path| {
            let mut args = cmd.to_vec();
            args.extend(["--no-profile", s(p), "--output", "/dev/null"]);
            fb(d.path(), &args)
        };
        let cmd = cmd[0];
        let out = run(&one);
        let err = stderr(&out);
        assert!(out.status.success(), "{err}");
        let named = err
            .lines()
            .filter(|l| l.contains("1 outlier(s)") && l.contains("delta 12.613 deg"))
            .count();
        assert!(named >= 2, "{cmd}: {err}");
        assert!(
            !err.contains("are the velocities dimensionless"),
            "{cmd}: {err}"
        );
        let out = run(&all);
        let err = stderr(&out);
        assert!(
            err.contains("are the velocities dimensionless"),
            "{cmd}: {err}"
        );
        assert!(!err.contains("outlier"), "{cmd}: {err}");
    }
}

/// Runs `args` in `dir` for at most `limit`; the output and how long it took.
fn within(dir: &Path, args: &[&str], limit: Duration) -> (Output, Duration) {
    let t0 = Instant::now();
    let mut child = bin()
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    while child.try_wait().unwrap().is_none() && t0.elapsed() < limit {
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = child.kill();
    (child.wait_with_output().unwrap(), t0.elapsed())
}

/// md settings that would carry the bead past a row bead per step, or sink it into the row,
/// are refused at once (they once ran for ever, deaf to signals), blaming the setting given.
#[test]
fn md_extreme_settings_are_refused_at_once() {
    let d = tmpdir();
    let p = d.path();
    let lv = write(p, "lv.csv", "xi,delta_deg,launch_velocity\n1,12,1e12\n");
    let md = ["forward", "--model", "md", "--xi", "1", "--delta-deg", "12"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--md-g", "1e20"], "flag '--md-g'"),
        (
            vec!["--launch-velocity", "1e12"],
            "flag '--launch-velocity'",
        ),
        (vec!["--young-pa", "1e-300"], "flag '--young-pa'"),
        (vec!["--row-radius-m", "1e300"], "flag '--row-radius-m'"),
    ];
    for (extra, blamed) in cases {
        let mut a = md.to_vec();
        a.extend(extra.iter().copied());
        let (out, took) = within(p, &a, Duration::from_secs(10));
        assert!(took < Duration::from_secs(2), "{extra:?} took {took:?}");
        crate::common::expect(&out, 2, &[blamed], &format!("{extra:?}"));
    }
    let (out, took) = within(
        p,
        &["forward", "--model", "md", "--input", s(&lv)],
        Duration::from_secs(10),
    );
    assert!(took < Duration::from_secs(2), "column: {took:?}");
    crate::common::expect(&out, 2, &["column 'launch_velocity'"], "column");
    let (out, took) = within(
        p,
        &["simulate", "--model", "md", "--launch-velocity", "1e13"],
        Duration::from_secs(10),
    );
    assert!(took < Duration::from_secs(2), "simulate: {took:?}");
    crate::common::expect(&out, 2, &["launch_velocity"], "simulate");
}

/// `--input -` with standard input redirected from the output file is refused, the file kept.
#[test]
fn standard_input_from_the_output_file_is_refused() {
    let d = tmpdir();
    let text = std::fs::read(crate::common::root().join("data/default.csv")).unwrap();
    let p = d.path().join("d.csv");
    std::fs::write(&p, &text).unwrap();
    for cmd in [
        vec![
            "k",
            "--model",
            "stickslip",
            "--input",
            "-",
            "--output",
            "d.csv",
        ],
        vec![
            "klaw",
            "--model",
            "stickslip",
            "--input",
            "-",
            "--output",
            "d.csv",
        ],
    ] {
        let out = bin()
            .args(&cmd)
            .current_dir(d.path())
            .stdin(std::fs::File::open(&p).unwrap())
            .output()
            .unwrap();
        crate::common::expect(
            &out,
            2,
            &["is the same file as --input"],
            &format!("{cmd:?}"),
        );
        assert_eq!(
            std::fs::read(&p).unwrap(),
            text,
            "{cmd:?} replaced the input"
        );
    }
}

/// A measurements file of `n` plain rows (one series at ξ = 1).
fn many_rows(n: usize) -> String {
    let mut t = String::from("series,xi,delta_deg,v,sigma_v\n");
    for i in 0..n {
        let d = 10.0 + (i % 1000) as f64 * 1e-3;
        let v = 0.4 + (i % 997) as f64 * 1e-5;
        t.push_str(&format!("1,1,{d},{v},0.01\n"));
    }
    t
}

/// A broken standard output (`| head -1`) with a figure still to write: an error naming the
/// figure, not a quiet exit 0 without it.
#[test]
fn a_broken_stdout_names_the_files_left_unwritten() {
    let d = tmpdir();
    let p = write(d.path(), "big.csv", &many_rows(300_000));
    let mut child = bin()
        .args([
            "k",
            "--model",
            "stickslip",
            "--input",
            s(&p),
            "--output",
            "-",
            "--plot",
            "k.svg",
        ])
        .current_dir(d.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    {
        use std::io::Read;
        let mut first = [0u8; 64];
        child.stdout.take().unwrap().read_exact(&mut first).unwrap();
        // The pipe's reader is gone here.
    }
    let out = child.wait_with_output().unwrap();
    crate::common::expect(&out, 2, &["broken pipe", "k.svg not written"], "k | head");
    assert!(!d.path().join("k.svg").exists());
    assert!(crate::common::leftovers(d.path()).is_empty());
}

/// `design` on SIGTERM exits 130 at once and leaves no temporary file of its figure.
#[test]
fn design_stops_on_sigterm_without_leftovers() {
    let d = tmpdir();
    let args = [
        "design",
        "--fit",
        "klaw",
        "--model",
        "stickslip",
        "--prior",
        "c=normal(0.5,0.1)",
        "--draws",
        "10000",
        "--plot",
        "p.svg",
        "--output",
        "o.csv",
    ];
    let (status, took) =
        crate::common::interrupt(d.path(), &args, "-TERM", Duration::from_millis(400));
    assert!(took < Duration::from_secs(1), "{took:?}");
    assert_eq!(status.code(), Some(130));
    assert!(crate::common::leftovers(d.path()).is_empty());
    assert!(!d.path().join("p.svg").exists() && !d.path().join("o.csv").exists());
}

/// `k --model contact` stops within a second of SIGINT (the flag was once looked at only
/// between tasks of 512 rows, seconds apart under the contact model).
#[test]
fn contact_k_stops_within_a_second_of_sigint() {
    let d = tmpdir();
    let p = write(d.path(), "kc.csv", &many_rows(100_000));
    let args = [
        "k",
        "--model",
        "contact",
        "--input",
        s(&p),
        "--output",
        "out.csv",
    ];
    let (status, took) =
        crate::common::interrupt(d.path(), &args, "-INT", Duration::from_millis(1500));
    assert!(
        took < Duration::from_secs(1),
        "stopped {took:?} after SIGINT"
    );
    assert_eq!(status.code(), Some(130));
    assert!(!d.path().join("out.csv").exists());
}

/// Outputs that cannot be written are refused before any work, not after it.
#[test]
fn unwritable_output_places_are_refused_before_the_work() {
    let d = tmpdir();
    let p = d.path();
    write(p, "afile", "mine\n");
    let data = crate::common::root().join("data/default.csv");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["report", "--method", "mcmc", "--out-dir", "afile"],
            "is not a directory",
        ),
        (
            vec!["report", "--out-dir", "afile/sub"],
            "cannot be created",
        ),
        (
            vec![
                "klaw",
                "--model",
                "stickslip",
                s(&data),
                "--output",
                "nodir/x.csv",
            ],
            "cannot be created in nodir",
        ),
        (
            vec!["bench", "--output", "nodir/x.csv"],
            "cannot be created in nodir",
        ),
    ];
    for (args, msg) in cases {
        let (out, took) = within(p, &args, Duration::from_secs(30));
        assert!(took < Duration::from_secs(1), "{args:?} took {took:?}");
        crate::common::expect(&out, 2, &[msg], &format!("{args:?}"));
    }
    assert_eq!(std::fs::read_to_string(p.join("afile")).unwrap(), "mine\n");
    // A new directory, and its missing parents, are still made.
    let out = fb(p, &["report", "--out-dir", "new/sub"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(p.join("new/sub/report.md").exists());
}

/// A huge series label is cut in the figures and in report.md (the CSV tables keep it).
#[test]
fn a_huge_label_does_not_flood_the_figures() {
    let d = tmpdir();
    let label = "L".repeat(200_000);
    let text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let mut out = String::new();
    for (i, l) in text.lines().enumerate() {
        if i > 0 && l.starts_with("0.8,") {
            out.push_str(&format!("{label}{}\n", &l[3..]));
        } else {
            out.push_str(l);
            out.push('\n');
        }
    }
    let p = write(d.path(), "big.csv", &out);
    let r = fb(d.path(), &["report", "--input", s(&p), "--out-dir", "r"]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(r.stdout.len() < 100_000, "stdout {} bytes", r.stdout.len());
    for e in std::fs::read_dir(d.path().join("r")).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        let len = e.metadata().unwrap().len();
        if name.ends_with(".svg") || name == "report.md" {
            assert!(len < 400_000, "{name}: {len} bytes");
        }
    }
    // The data keep the label whole.
    let pts = std::fs::read_to_string(d.path().join("r/points.csv")).unwrap();
    assert!(pts.contains(&label));
}

/// `report --keep-going` with a point no contact model can make steady writes the report
/// without it, as GUIDE says, instead of exiting 2.
#[test]
fn keep_going_leaves_out_a_point_no_model_makes_steady() {
    let d = tmpdir();
    let mut text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    text.push_str("0.8,0.8,60,0.3,0.01,0.3\n");
    let p = write(d.path(), "kg.csv", &text);
    let out = fb(d.path(), &["report", "--input", s(&p), "--out-dir", "r"]);
    crate::common::expect(
        &out,
        2,
        &["line 38", "--keep-going"],
        "without --keep-going",
    );
    let out = fb(
        d.path(),
        &["report", "--input", s(&p), "--keep-going", "--out-dir", "r"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let md = std::fs::read_to_string(d.path().join("r/report.md")).unwrap();
    assert!(
        md.contains("line 38 (series '0.8', xi 0.8, delta_deg 60)"),
        "{md}"
    );
}

/// Every flag GUIDE's table for `simulate` documents is one the parser accepts.
#[test]
fn guide_documents_only_flags_simulate_takes() {
    let guide = std::fs::read_to_string(crate::common::root().join("docs/GUIDE.md")).unwrap();
    let section = guide.split("\n## simulate\n").nth(1).unwrap();
    let section = section.split("\n## ").next().unwrap();
    let help =
        String::from_utf8(bin().args(["simulate", "--help"]).output().unwrap().stdout).unwrap();
    let mut seen = 0;
    for line in section.lines().filter(|l| l.starts_with("| `--")) {
        for flag in line.split('`').filter(|t| t.starts_with("--")) {
            let name = flag.split([' ', '=']).next().unwrap();
            assert!(
                help.contains(&format!("{name} ")),
                "GUIDE documents {name}: not a flag"
            );
            seen += 1;
        }
    }
    assert!(seen > 10, "{seen} flags read from GUIDE");
}

/// Flags documented to take negative numbers reach their own checks with the project's
/// message (clap once took `-5` for an unknown flag).
#[test]
fn negative_list_values_reach_their_checks() {
    let d = tmpdir();
    for args in [
        vec!["simulate", "--delta-range", "-5,10"],
        vec!["simulate", "--series", "-1,2"],
        vec!["simulate", "--model", "jan", "--jan", "-1,4.96,0.0025,7.46"],
    ] {
        let out = fb(d.path(), &args);
        let e = stderr(&out);
        assert!(!e.contains("unexpected argument"), "{args:?}: {e}");
        match out.status.code() {
            // Taken: the range is cut to the steady one.
            Some(0) => {}
            Some(2) => assert!(
                e.starts_with("fitbead: error: <command line>, flag '"),
                "{args:?}: {e}"
            ),
            c => panic!("{args:?}: exit {c:?}: {e}"),
        }
    }
    // A value that is a number list starting with a negative one is accepted where valid.
    let out = fb(
        d.path(),
        &[
            "simulate",
            "--model",
            "jan",
            "--jan",
            "0.063,-4.96,0.0025,7.46",
            "--output",
            "/dev/null",
        ],
    );
    assert!(
        !stderr(&out).contains("unexpected argument"),
        "{}",
        stderr(&out)
    );
}

/// Recipes take a seed up to u64::MAX (as the flag does) and a figure width as a number.
#[test]
fn recipes_take_large_seeds_and_numeric_widths() {
    let d = tmpdir();
    let data = crate::common::root().join("data/default.csv");
    let recipe = format!(
        "input = \"{}\"\nmethod = \"lsq\"\nseed = 18446744073709551615\nfigure_width = 120\n",
        s(&data)
    );
    let r = write(d.path(), "r.toml", &recipe);
    let out = fb(d.path(), &["report", "--recipe", s(&r), "--out-dir", "out"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let svg = std::fs::read_to_string(d.path().join("out/velocity.svg")).unwrap();
    assert!(
        svg.contains("width=\"120mm\""),
        "{}",
        &svg[..300.min(svg.len())]
    );
    let r = write(d.path(), "bad.toml", "figure_width = 1000\n");
    let out = fb(
        d.path(),
        &["report", "--recipe", s(&r), "--out-dir", "out2"],
    );
    crate::common::expect(&out, 2, &["bad.toml, line 1", "figure_width"], "width 1000");
}

/// A PNG-only report links PNG figures only.
#[test]
fn a_png_report_links_no_svg() {
    let d = tmpdir();
    let out = fb(d.path(), &["report", "--format", "png", "--out-dir", "r"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let md = std::fs::read_to_string(d.path().join("r/report.md")).unwrap();
    assert!(!md.contains(".svg"), "report.md links an SVG");
    for f in ["regime_map.png", "jaeger.png"] {
        assert!(md.contains(&format!("]({f})")), "{f}");
        assert!(d.path().join("r").join(f).exists());
    }
}

/// `bench --scenes 1` says which checks drew no scene instead of failing them.
#[test]
fn bench_with_too_few_scenes_says_so() {
    let d = tmpdir();
    let out = fb(
        d.path(),
        &["bench", "--scenes", "1", "--output", "/dev/null"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(!e.contains("FAILED"), "{e}");
    assert!(!e.contains("NaN"), "{e}");
    assert!(e.contains("no scenes: none of the 1 drawn"), "{e}");
}

/// A design file whose series mixes ξ values is refused by `simulate --design`.
#[test]
fn a_design_mixing_xi_in_a_series_is_refused() {
    let d = tmpdir();
    let p = write(
        d.path(),
        "des.csv",
        "series,xi,delta_deg,replicates\n1,1,10,2\n1,1.5,12,2\n",
    );
    let out = fb(
        d.path(),
        &["simulate", "--design", s(&p), "--output", "o.csv"],
    );
    crate::common::expect(
        &out,
        2,
        &["line 3", "column 'xi'", "mixes xi values"],
        "design",
    );
    assert!(!d.path().join("o.csv").exists());
}

/// Small messages: a NUL byte shown as `\0`, law `C=0.5` in any case.
#[test]
fn values_echoed_visibly_and_laws_in_any_case() {
    let d = tmpdir();
    let p = write(
        d.path(),
        "nul.csv",
        "series,xi,delta_deg,v,sigma_v\n1,1,10,0.38\0x,0.01\n",
    );
    let out = fb(d.path(), &["klaw", "--model", "stick", s(&p)]);
    crate::common::expect(&out, 2, &["value '0.38\\0x'"], "nul");
    assert!(!stderr(&out).contains('\0'));
    let a = fb_ok(d.path(), &["simulate", "--law", "C=0.5", "--output", "-"]);
    let b = fb_ok(d.path(), &["simulate", "--law", "c=0.5", "--output", "-"]);
    assert_eq!(a, b);
}

/// An existing file the user may not write is not replaced, even in a directory anyone may
/// write. As root the command runs as `nobody` (root may write any file).
#[test]
fn a_file_the_user_may_not_write_is_not_replaced() {
    let d = tmpdir();
    let p = d.path();
    let data = crate::common::root().join("data/default.csv");
    std::fs::copy(&data, p.join("in.csv")).unwrap();
    std::fs::write(p.join("ro.csv"), "precious\n").unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(p.join("ro.csv"), std::fs::Permissions::from_mode(0o444)).unwrap();
    std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o1777)).unwrap();
    std::fs::set_permissions(p.join("in.csv"), std::fs::Permissions::from_mode(0o644)).unwrap();
    let root = Command::new("id").arg("-u").output().unwrap().stdout == b"0\n";
    let args = [
        "klaw",
        "--model",
        "stickslip",
        "in.csv",
        "--output",
        "ro.csv",
    ];
    let out = if root {
        // A copy of the binary in the shared directory: the checkout's own may sit under a
        // directory that `nobody` cannot enter.
        let exe = crate::common::bin_path();
        let copy = p.join("fitbead-copy");
        std::fs::copy(&exe, &copy).unwrap();
        std::fs::set_permissions(&copy, std::fs::Permissions::from_mode(0o755)).unwrap();
        let mut c = Command::new("setpriv");
        c.args(["--reuid=nobody", "--regid=nogroup", "--clear-groups"])
            .arg(&copy);
        c.args(args).current_dir(p).output().unwrap()
    } else {
        fb(p, &args)
    };
    crate::common::expect(&out, 2, &["may not write it"], "read-only target");
    assert_eq!(
        std::fs::read_to_string(p.join("ro.csv")).unwrap(),
        "precious\n"
    );
    assert!(crate::common::leftovers(p).is_empty());
}
