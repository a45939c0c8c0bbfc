//! Edges of the command line: stopping long fits at once, md settings that would run for
//! ever, values echoed as the user wrote them, outputs that may coincide, and files as people
//! write them (misspelt, differently cased or differently separated columns).

use crate::common::{bin, expect, interrupt, s, stderr, tmpdir, write};
use std::path::Path;
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};

/// Runs fitbead with `args`, killed after `limit`; the output and whether it ended in time.
fn fb_within(args: &[&str], limit: Duration) -> (Output, Duration) {
    let t0 = Instant::now();
    let mut child = bin()
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    (child.wait_with_output().unwrap(), t0.elapsed())
}

/// Runs fitbead with `args` (at most 60 s).
fn fb(args: &[&str]) -> Output {
    let (out, took) = fb_within(args, Duration::from_secs(60));
    assert!(
        took < Duration::from_secs(60),
        "{args:?} did not end in 60 s"
    );
    out
}

/// The default data set copied `copies` times, each copy's series renamed apart (4 series
/// of 9 points per copy), each row written `rows` times.
fn many_series(dir: &Path, copies: usize, rows: usize) -> std::path::PathBuf {
    let text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let mut lines = text.lines();
    let mut out = String::from(lines.next().unwrap());
    out.push('\n');
    let body: Vec<&str> = lines.filter(|l| !l.is_empty()).collect();
    for c in 0..copies {
        for l in &body {
            let (series, rest) = l.split_once(',').unwrap();
            for _ in 0..rows {
                out.push_str(&format!("{series}_{c},{rest}\n"));
            }
        }
    }
    write(dir, "many.csv", &out)
}

#[test]
fn free_per_series_fit_time_grows_linearly_with_the_series() {
    // 2,000 series took about two minutes when the series were fitted jointly (cubic in
    // their number); fitted one by one they take about a second.
    let dir = tmpdir();
    let input = many_series(dir.path(), 500, 1);
    let out_csv = dir.path().join("o.csv");
    let args = [
        "klaw",
        "--model",
        "stick",
        "--law",
        "free-per-series",
        "--input",
        s(&input),
        "--output",
        s(&out_csv),
        "--output-stats",
        "/dev/null",
    ];
    let (out, took) = fb_within(&args, Duration::from_secs(30));
    expect(&out, 0, &[], "2000 series");
    assert!(took < Duration::from_secs(30), "took {took:?}");
    let text = std::fs::read_to_string(&out_csv).unwrap();
    assert_eq!(text.lines().count(), 1 + 2000, "one row per series");
}

#[cfg(unix)]
#[test]
fn free_per_series_fit_stops_within_a_second_of_sigint_or_sigterm() {
    let dir = tmpdir();
    let input = many_series(dir.path(), 750, 4);
    for sig in ["-INT", "-TERM"] {
        let args = [
            "klaw",
            "--model",
            "stickslip",
            "--law",
            "free-per-series",
            "--input",
            s(&input),
            "--output",
            "o.csv",
            "--output-stats",
            "s.csv",
        ];
        let (st, took) = interrupt(dir.path(), &args, sig, Duration::from_millis(1500));
        assert_eq!(st.code(), Some(130), "{sig}");
        assert!(
            took < Duration::from_millis(1500),
            "{sig}: stopped after {took:?}"
        );
        assert!(!dir.path().join("o.csv").exists(), "{sig}: nothing written");
    }
}

/// A posterior report on 20 series of 50 points stops within a second of SIGINT while it
/// samples, writing the draws so far (the posterior bands, millions of model evaluations
/// over the draws, are left out of an interrupted report).
#[cfg(unix)]
#[test]
fn posterior_report_on_twenty_series_stops_within_a_second_of_sigint() {
    let dir = tmpdir();
    let data = dir.path().join("big.csv");
    let series = "0.8,0.85,0.9,0.95,1,1.05,1.1,1.15,1.2,1.25,1.3,1.35,1.4,1.45,1.5,1.6,1.7,1.8,\
                  1.9,2";
    let out = fb(&[
        "simulate",
        "--series",
        series,
        "--points",
        "50",
        "--output",
        s(&data),
    ]);
    expect(&out, 0, &[], "simulate");
    // The least-squares report times the fits that come before the sampling: the signal
    // comes 3 s after that, well inside the sampling (minutes), however loaded the machine.
    let (out, lsq) = fb_within(
        &["report", s(&data), "--out-dir", s(&dir.path().join("lsq"))],
        Duration::from_secs(120),
    );
    expect(&out, 0, &[], "least-squares report");
    let args = [
        "report",
        "big.csv",
        "--method",
        "mcmc",
        "--seed",
        "1",
        "--out-dir",
        "out",
    ];
    let (st, took) = interrupt(dir.path(), &args, "-INT", lsq + Duration::from_secs(3));
    eprintln!("stopped {took:?} after SIGINT (least-squares report: {lsq:?})");
    assert_eq!(st.code(), Some(130));
    assert!(took < Duration::from_secs(1), "stopped after {took:?}");
    // The signal came while sampling: the report holds the draws so far, marked.
    let stats = std::fs::read_to_string(dir.path().join("out/stats.csv")).unwrap();
    let (h, rows) = crate::common::table(&stats);
    let c = crate::common::col(&h, "mcmc_status");
    assert!(
        rows.iter().any(|r| r[c] == "interrupted"),
        "no interrupted run: {stats}"
    );
}

#[test]
fn md_settings_beyond_the_step_cap_are_refused_at_once() {
    let dir = tmpdir();
    let scenes = write(dir.path(), "md.csv", "xi,delta_deg,young_pa\n1,12,1e300\n");
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["--xi", "1", "--delta-deg", "12", "--young-pa", "1e300"],
            vec!["--young-pa", "'1e300'", "1e12 time steps"],
        ),
        (
            vec!["--xi", "1", "--delta-deg", "12", "--density", "1e-300"],
            vec!["--density", "'1e-300'", "1e12 time steps"],
        ),
        (
            vec!["--input", s(&scenes)],
            vec!["line 2", "young_pa", "1e12 time steps"],
        ),
    ];
    for (extra, must) in cases {
        let mut args = vec!["forward", "--model", "md"];
        args.extend(&extra);
        let (out, took) = fb_within(&args, Duration::from_secs(20));
        expect(&out, 2, &must, &format!("{extra:?}"));
        assert!(took < Duration::from_secs(20), "{extra:?}: {took:?}");
    }
    let (out, _) = fb_within(
        &[
            "simulate",
            "--model",
            "md",
            "--series",
            "1",
            "--points",
            "2",
            "--young-pa",
            "1e300",
        ],
        Duration::from_secs(20),
    );
    expect(&out, 2, &["--young-pa", "1e12 time steps"], "simulate");
}

#[test]
fn non_finite_and_huge_flag_values_are_echoed_as_written() {
    for (v, echo) in [("NaN", "'NaN'"), ("inf", "'inf'"), ("-inf", "'-inf'")] {
        let out = fb(&["forward", "--model", "stick", "--xi", "1", "--delta-deg", v]);
        expect(&out, 2, &["--delta-deg", echo, "not a finite number"], v);
    }
    let out = fb(&[
        "forward",
        "--model",
        "stick",
        "--xi",
        "1",
        "--delta-deg",
        "1e308",
    ]);
    expect(&out, 2, &["delta_deg = 1e308"], "1e308");
    assert!(!stderr(&out).contains("0000000000"), "{}", stderr(&out));
}

#[test]
fn a_law_without_k_at_small_xi_blames_xi() {
    let out = fb(&[
        "forward",
        "--model",
        "stick",
        "--xi",
        "1e-8",
        "--delta-deg",
        "12",
    ]);
    expect(
        &out,
        2,
        &["'xi'", "'1e-8'", "no K > 0 at this xi"],
        "xi 1e-8",
    );
    assert!(!stderr(&out).contains("--K"), "{}", stderr(&out));
}

#[cfg(unix)]
#[test]
fn dev_null_may_take_several_outputs() {
    let out = fb(&[
        "klaw",
        "--model",
        "stick",
        "--output",
        "/dev/null",
        "--output-stats",
        "/dev/null",
    ]);
    expect(&out, 0, &[], "two outputs on /dev/null");
}

const DATA: &str = "series,xi,delta_deg,v,sigma_v\n\
                    a,0.8,10.9354,0.2766,0.0057\n\
                    a,0.8,11.2709,0.2977,0.0060\n\
                    a,0.8,11.6064,0.3143,0.0062\n";

#[test]
fn a_misspelt_column_is_warned_about_and_refused_when_strict() {
    let dir = tmpdir();
    let p = write(&dir, "d.csv", &DATA.replacen("sigma_v", "sigma_vs", 1));
    for cmd in ["klaw", "k"] {
        let out = fb(&[cmd, "--model", "stick", s(&p)]);
        expect(
            &out,
            0,
            &["d.csv", "'sigma_vs'", "did you mean 'sigma_v'?"],
            cmd,
        );
        let out = fb(&[cmd, "--model", "stick", "--strict-columns", s(&p)]);
        expect(
            &out,
            2,
            &["d.csv", "line 1", "'sigma_vs'", "did you mean 'sigma_v'?"],
            cmd,
        );
    }
    // A column far from every known name passes through in silence, unless strict.
    let p = write(&dir, "id.csv", "xi,delta_deg,id\n1,12,a\n");
    let out = fb(&["forward", "--model", "stick", "--input", s(&p)]);
    expect(&out, 0, &[], "id");
    assert_eq!(stderr(&out), "");
    let out = fb(&[
        "forward",
        "--model",
        "stick",
        "--strict-columns",
        "--input",
        s(&p),
    ]);
    expect(&out, 2, &["id.csv", "line 1", "'id'"], "strict id");
    let p = write(&dir, "rh0.csv", "xi,delta_deg,rh0\n1,12,0.5\n");
    let out = fb(&["forward", "--model", "stick", "--input", s(&p)]);
    expect(&out, 0, &["'rh0'", "did you mean 'rho'?"], "rh0");
}

/// A column named like an uncertainty, in a file without the uncertainty column it most
/// likely means, is warned about with that name (`sigma_v` beside `v`, `sigma_v_m_s` beside
/// `v_m_s`); the columns `simulate` writes beside the measurement pass `--strict-columns`.
#[test]
fn an_uncertainty_under_another_name_is_named_and_simulated_columns_pass() {
    let dir = tmpdir();
    for (name, text, means) in [
        ("err.csv", DATA.replacen("sigma_v", "err_v", 1), "sigma_v"),
        ("sd.csv", DATA.replacen("sigma_v", "SD", 1), "sigma_v"),
        (
            "si.csv",
            "xi,delta_deg,v_m_s,R_m,stdev\n0.8,12,0.05,0.0025,0.001\n".to_string(),
            "sigma_v_m_s",
        ),
    ] {
        let p = write(&dir, name, &text);
        let out = fb(&["k", "--model", "stick", s(&p)]);
        let did = format!("did you mean '{means}'?");
        expect(&out, 0, &[name, &did], name);
    }
    // With sigma_v present, an `err` column is one fitbead does not read, and says nothing.
    let p = write(
        &dir,
        "both.csv",
        "xi,delta_deg,v,sigma_v,err_note\n0.8,10.9354,0.2766,0.0057,x\n",
    );
    let out = fb(&["k", "--model", "stick", "--output", "/dev/null", s(&p)]);
    assert!(!stderr(&out).contains("err_note"), "{}", stderr(&out));
    let sim = fb(&[
        "simulate",
        "--model",
        "stick",
        "--series",
        "1",
        "--points",
        "4",
        "--sigma-delta",
        "0.1",
    ]);
    expect(&sim, 0, &[], "simulate");
    let p = write(&dir, "sim.csv", &String::from_utf8(sim.stdout).unwrap());
    let out = fb(&[
        "k",
        "--model",
        "stick",
        "--strict-columns",
        "--output",
        "/dev/null",
        s(&p),
    ]);
    expect(&out, 0, &[], "simulated columns under --strict-columns");
}

#[test]
fn header_names_match_in_any_case_and_outputs_keep_canonical_names() {
    let dir = tmpdir();
    let p = write(&dir, "d.csv", &DATA.replacen("xi", "Xi", 1));
    let out = fb(&["k", "--model", "stick", "--strict-columns", s(&p)]);
    expect(&out, 0, &[], "Xi");
    let text = String::from_utf8(out.stdout).unwrap();
    let header = text.lines().next().unwrap();
    assert!(header.starts_with("series,xi,delta_deg,"), "{header}");
    assert!(!header.contains("Xi"), "{header}");
}

#[test]
fn a_missing_column_suggests_the_nearest_present_name() {
    let dir = tmpdir();
    let p = write(&dir, "d.csv", &DATA.replacen("delta_deg", "dleta_deg", 1));
    let out = fb(&["klaw", "--model", "stick", s(&p)]);
    expect(
        &out,
        2,
        &[
            "'delta_deg'",
            "missing required column",
            "did you mean 'dleta_deg'?",
        ],
        "dleta_deg",
    );
}

#[test]
fn semicolon_tab_and_decimal_comma_files_are_named_as_such() {
    let dir = tmpdir();
    let p = write(&dir, "semi.csv", &DATA.replace(',', ";"));
    let out = fb(&["klaw", "--model", "stick", s(&p)]);
    expect(&out, 2, &["semi.csv", "line 1", "semicolon-separated"], ";");
    let p = write(&dir, "tab.csv", &DATA.replace(',', "\t"));
    let out = fb(&["k", "--model", "stick", s(&p)]);
    expect(&out, 2, &["tab.csv", "line 1", "tab-separated"], "tab");
    let p = write(&dir, "comma.csv", "xi,delta_deg,v\n0,8,10,9,0,27\n");
    let out = fb(&["k", "--model", "stick", s(&p)]);
    expect(
        &out,
        2,
        &[
            "comma.csv",
            "line 2 has 6 fields, the header 3",
            "decimal separator",
        ],
        "decimal comma",
    );
}

#[test]
fn an_unterminated_quote_is_refused_naming_its_line() {
    let dir = tmpdir();
    let p = write(&dir, "q.csv", "xi,delta_deg\n1,12\n1,\"12\n");
    let out = fb(&["forward", "--model", "stick", "--input", s(&p)]);
    expect(&out, 2, &["q.csv", "line 3", "unterminated quote"], "quote");
    // A quoted cell that is closed reads as before.
    let p = write(&dir, "ok.csv", "xi,delta_deg,note\n1,12,\"a, b\"\n");
    let out = fb(&["forward", "--model", "stick", "--input", s(&p)]);
    expect(&out, 0, &[], "closed quote");
}

#[test]
fn noise_free_simulations_read_back_and_repeated_series_are_refused() {
    let dir = tmpdir();
    let out = fb(&["simulate", "--noise", "0", "--points", "3", "--series", "1"]);
    expect(&out, 0, &[], "noise 0");
    let p = write(&dir, "n0.csv", &String::from_utf8(out.stdout).unwrap());
    for cmd in ["k", "klaw"] {
        expect(&fb(&[cmd, "--model", "stick", s(&p)]), 0, &[], cmd);
    }
    let out = fb(&["simulate", "--series", "1,2,1.0"]);
    expect(
        &out,
        2,
        &["--series", "'1.0'", "given twice"],
        "duplicate series",
    );
}

#[test]
fn pass_through_columns_named_like_outputs_get_unique_names() {
    let dir = tmpdir();
    let p = write(
        &dir,
        "o.csv",
        "xi,delta_deg,v,in_v,model_used\n1,12,1,2,x\n",
    );
    let out = fb(&["forward", "--model", "auto", "--input", s(&p)]);
    expect(&out, 0, &[], "forward");
    let text = String::from_utf8(out.stdout).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let mut unique = header.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), header.len(), "{header:?}");
    let again = write(&dir, "again.csv", &text);
    expect(
        &fb(&["forward", "--model", "stick", "--input", s(&again)]),
        0,
        &[],
        "output read back",
    );
    let p = write(&dir, "k.csv", "xi,delta_deg,v,K,in_K\n1,12,0.3,1,2\n");
    let out = fb(&["k", "--model", "stick", s(&p)]);
    let text = String::from_utf8(out.stdout.clone()).unwrap();
    expect(&out, 0, &[], "k");
    assert!(
        text.lines().next().unwrap().ends_with(",in_in_K,in_K"),
        "{text}"
    );
}

#[test]
fn a_law_giving_k_of_one_or_more_is_refused_naming_law_xi_and_k() {
    // Law c = 10 at ξ = 1 gives K = 2.665; c = 1e308 gives K ≈ 2e307.
    for law in ["c=10", "c=1e308"] {
        let out = fb(&["regimes", "--law", law, "--xi", "1"]);
        expect(&out, 2, &["--law", law, "xi = 1", "(0, 1)"], "regimes");
        let out = fb(&[
            "forward",
            "--model",
            "stick",
            "--K",
            law,
            "--xi",
            "1",
            "--delta-deg",
            "12",
        ]);
        expect(&out, 2, &["K", law, "xi = 1", "K >= 1"], "forward");
    }
    // Where a law gives K < 1 (c = 1 at ξ = 1.6: K = 0.81), the run goes on.
    let out = fb(&["regimes", "--law", "c=1", "--xi", "1.6"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}
