//! Command-line contracts: column names, exit codes, located errors, atomic output.

use crate::common::{bin, col, read_table, table, tmpdir, write};

#[test]
fn forward_single_scene_reports_v_regime_status() {
    let out = bin()
        .args([
            "forward",
            "--model",
            "stick",
            "--xi",
            "1",
            "--delta-deg",
            "12",
            "--K",
            "adjusted",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    let mut lines = s.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for c in [
        "xi",
        "delta_deg",
        "v",
        "regime",
        "status",
        "final_velocity",
        "theta_G_deg",
    ] {
        assert!(header.contains(&c), "missing column {c}: {header:?}");
    }
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    let v: f64 = row[header.iter().position(|h| *h == "v").unwrap()]
        .parse()
        .unwrap();
    // docs/PHYSICS.md#reference-figures: v̄ = 0.39120827… at ξ = 1, δ = 12°, ρ = 0.4, fitted K.
    assert!((v - 0.39120827).abs() < 1e-8, "{v}");
    assert_eq!(
        row[header.iter().position(|h| *h == "regime").unwrap()],
        "B"
    );
}

#[test]
fn forward_file_passes_extra_columns_and_keeps_order() {
    let d = tmpdir();
    let inp = write(
        &d,
        "s.csv",
        "id,xi,delta_deg,K,rho,f\na,1,12,adjusted,0.4,0.1\nb,1,3,0.6,0.4,0.1\nc,1,60,0.6,0.4,0.1\n",
    );
    let outp = d.path().join("o.csv");
    let st = bin()
        .args(["forward", "--model", "stickslip", "--input"])
        .arg(&inp)
        .arg("--output")
        .arg(&outp)
        .status()
        .unwrap();
    assert!(st.success());
    let s = std::fs::read_to_string(&outp).unwrap();
    let rows: Vec<Vec<String>> = s
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let h = &rows[0];
    let reg = h.iter().position(|x| x == "regime").unwrap();
    assert_eq!(rows[1][0], "a");
    assert_eq!(rows[2][0], "b");
    assert_eq!(rows[3][0], "c");
    assert_eq!(rows[1][reg], "B");
    assert_eq!(rows[2][reg], "A", "3 degrees is below delta_m");
    assert_eq!(rows[3][reg], "C", "60 degrees lifts off");
}

fn expect_error(args: &[&str], input: &str, must_contain: &[&str]) {
    let d = tmpdir();
    let inp = write(&d, "bad.csv", input);
    let outp = write(&d, "out.csv", "precious");
    let out = bin()
        .args(args)
        .arg("--input")
        .arg(&inp)
        .arg("--output")
        .arg(&outp)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "exit code for {input:?}");
    let err = String::from_utf8(out.stderr).unwrap();
    for m in must_contain {
        assert!(err.contains(m), "stderr {err:?} lacks {m:?}");
    }
    assert!(err.contains("bad.csv"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&outp).unwrap(),
        "precious",
        "output touched"
    );
    let leftovers: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 2, "temporary files left behind");
}

#[test]
fn bad_inputs_exit_2_with_file_line_column_value() {
    let f = ["forward", "--model", "stick"];
    expect_error(&f, "xi,K\n1,0.6\n", &["line 1", "delta_deg", "missing"]);
    expect_error(
        &f,
        "xi,delta_deg\n1,abc\n",
        &["line 2", "delta_deg", "'abc'"],
    );
    expect_error(
        &f,
        "xi,delta_deg\n1,10\n1,NaN\n",
        &["line 3", "delta_deg", "NaN"],
    );
    expect_error(&f, "xi,delta_deg\n1,inf\n", &["line 2", "inf"]);
    expect_error(&f, "xi,delta_deg\n-1,10\n", &["line 2", "'xi'", "-1"]);
    expect_error(&f, "xi,delta_deg\n1,95\n", &["line 2", "delta_deg", "95"]);
    expect_error(&f, "", &["empty"]);
    expect_error(&f, "xi,delta_deg\n", &["no data rows"]);
    expect_error(
        &f,
        "xi,delta_deg,K\n1,10,smooth\n",
        &["line 2", "'K'", "smooth", "unknown collision law"],
    );
    expect_error(&f, "xi,delta_deg,K\n1,10,-0.5\n", &["line 2", "'K'"]);
    expect_error(
        &f,
        "xi,delta_deg,rho\n1,10,-2\n",
        &["line 2", "'rho'", "-2"],
    );
}

/// A bad `--spin` (and a bad `spin` cell) says what is wrong with the spin rule, and only that;
/// `--K` keeps its own message. Exact stderr, exit 2.
#[test]
fn unknown_spin_rule_is_reported_as_a_spin_rule() {
    let run = |args: &[&str]| {
        let out = bin().args(args).output().unwrap();
        (out.status.code(), String::from_utf8(out.stderr).unwrap())
    };
    let scene = ["--xi", "1", "--delta-deg", "12"];
    let (code, err) = run(&[
        &["forward", "--model", "contact", "--spin", "reset"][..],
        &scene,
    ]
    .concat());
    assert_eq!(code, Some(2));
    assert_eq!(
        err,
        "fitbead: error: <command line>, flag '--spin', value 'reset': unknown spin rule \
         'reset' (expected roll, keep, impact or factor=L)\n"
    );
    let (code, err) = run(&[&["forward", "--model", "stick", "--K", "bogus"][..], &scene].concat());
    assert_eq!(code, Some(2));
    assert_eq!(
        err,
        "fitbead: error: <command line>, flag '--K', value 'bogus': unknown collision law \
         'bogus' (expected a number, cos2a, adjusted, impact or c=VALUE)\n"
    );
    expect_error(
        &["forward", "--model", "contact"],
        "xi,delta_deg,spin\n1,10,factor=x\n",
        &[
            "line 2",
            "'spin'",
            ": unknown spin rule 'factor=x' (expected roll, keep, impact or factor=L)",
        ],
    );
}

/// The streaming `forward` (chunks of 32,768 rows): a bad row far past the first chunk is
/// still reported with its line, and nothing is left at --output.
#[test]
fn bad_row_past_the_first_chunks_exits_2_and_leaves_no_output() {
    let f = ["forward", "--model", "stick"];
    let mut text = String::from("id,xi,delta_deg\n");
    for i in 0..100_000 {
        if i == 70_000 {
            text.push_str("bad,1,abc\n");
        } else {
            text.push_str(&format!("{i},1,{}\n", 5 + i % 20));
        }
    }
    expect_error(&f, &text, &["line 70002", "delta_deg", "'abc'"]);
    // A malformed row later still wins, as when the whole table was read first.
    text.push_str("1,2\n");
    expect_error(&f, &text, &["line 100002", "malformed CSV"]);
}

/// Many chunks: the file written atomically and the stream on stdout are the same bytes, one
/// row per scene in input order.
#[test]
fn forward_file_and_stdout_agree_on_many_chunks() {
    let d = tmpdir();
    let mut text = String::from("id,xi,delta_deg,K\n");
    for i in 0..80_000 {
        let k = ["adjusted", "0.6", "", "cos2a"][i % 4];
        text.push_str(&format!(
            "s{i},{},{},{k}\n",
            0.7 + (i % 97) as f64 * 0.1,
            (i % 31) as f64
        ));
    }
    let inp = write(&d, "many.csv", &text);
    let outp = d.path().join("many.out.csv");
    let run = |to_file: bool| {
        let mut c = bin();
        c.args(["forward", "--model", "stick", "--input"]).arg(&inp);
        if to_file {
            c.arg("--output").arg(&outp);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        o.stdout
    };
    assert!(run(true).is_empty());
    let stdout = run(false);
    let file = std::fs::read(&outp).unwrap();
    assert!(stdout == file, "stdout and --output differ");
    let s = String::from_utf8(file).unwrap();
    assert_eq!(s.lines().count(), 80_001);
    for (i, l) in s.lines().skip(1).enumerate() {
        assert!(l.starts_with(&format!("s{i},")), "row {i}: {l}");
    }
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        2,
        "temporary files left"
    );
}

/// An output that cannot be created (missing directory) is exit 2, refused before any work:
/// before the input is read, good or bad.
#[test]
fn unwritable_output_is_refused_before_the_input_is_read() {
    let d = tmpdir();
    let good = write(&d, "good.csv", "xi,delta_deg\n1,12\n");
    let bad = write(&d, "bad.csv", "xi,delta_deg\n1,12\n1,abc\n");
    let outp = d.path().join("missing").join("o.csv");
    for (inp, want) in [(&good, "cannot be created"), (&bad, "cannot be created")] {
        let o = bin()
            .args(["forward", "--model", "stick", "--input"])
            .arg(inp)
            .arg("--output")
            .arg(&outp)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2));
        let err = String::from_utf8(o.stderr).unwrap();
        assert!(err.contains(want), "{err}");
    }
    assert!(!outp.exists());
}

#[test]
fn regimes_reports_the_critical_xi() {
    let out = bin()
        .args(["regimes", "--law", "adjusted", "--xi", "1"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    assert!(
        s.starts_with("xi,alpha_deg,K,delta_m_deg,delta_d_deg"),
        "{s}"
    );
    let row: Vec<f64> = s
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .filter_map(|x| x.parse().ok())
        .collect();
    assert!((row[3] - 7.469).abs() < 5e-4, "delta_m {row:?}");
    assert!(
        (row[row.len() - 1] - 0.6215).abs() < 1e-4,
        "critical xi {row:?}"
    );
}

#[test]
fn simulate_is_reproducible_from_its_seed_and_stays_in_regime_b() {
    let run = |seed: &str| {
        let o = bin()
            .args([
                "simulate", "--model", "stick", "--law", "adjusted", "--series", "0.8,2",
                "--points", "5", "--noise", "0.02", "--seed", seed,
            ])
            .output()
            .unwrap();
        assert!(o.status.success());
        String::from_utf8(o.stdout).unwrap()
    };
    let a = run("7");
    assert_eq!(a, run("7"));
    assert_ne!(a, run("8"));
    assert!(a.starts_with("series,xi,delta_deg,v,sigma_v"));
    assert_eq!(a.lines().count(), 11);
    // Every simulated slope is steady under the model that made it.
    let d = tmpdir();
    let p = write(&d, "sim.csv", &a);
    let o = bin()
        .args(["forward", "--model", "stick", "--input"])
        .arg(&p)
        .output()
        .unwrap();
    let s = String::from_utf8(o.stdout).unwrap();
    assert_eq!(
        s.lines().skip(1).filter(|l| l.contains(",B,ok,")).count(),
        10,
        "{s}"
    );
}

#[test]
fn forward_without_input_runs_on_the_embedded_default_data() {
    let o = bin()
        .args(["forward", "--model", "stickslip"])
        .output()
        .unwrap();
    assert!(o.status.success());
    let s = String::from_utf8(o.stdout).unwrap();
    assert!(
        s.lines().next().unwrap().contains("in_v"),
        "measured v passes through as in_v"
    );
    assert_eq!(s.lines().count(), 37);
}

/// The CSV on stdout of a run, whatever its exit status.
fn k_table(out: &std::process::Output) -> (Vec<String>, Vec<Vec<String>>) {
    table(&String::from_utf8(out.stdout.clone()).unwrap())
}

#[test]
fn k_on_default_data_has_the_contract_columns_and_exact_round_trip() {
    let out = bin().args(["k", "--model", "stick"]).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (h, rows) = k_table(&out);
    let contract = "series,xi,delta_deg,v,sigma_v,model,K,K_lo,K_hi,dv_dK,final_velocity,\
                    theta_G_deg,K_cos2a,K_adjusted,K_impact,regime,status,iterations";
    assert_eq!(h[..18].join(","), contract);
    assert_eq!(rows.len(), 36);
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    for r in &rows {
        assert_eq!(r[col("status")], "ok", "{r:?}");
        // Forward with the K found gives back v (the library's round trip, through the CLI).
        let fwd = bin()
            .args([
                "forward",
                "--model",
                "stick",
                "--xi",
                &r[col("xi")],
                "--delta-deg",
                &r[col("delta_deg")],
                "--K",
                &r[col("K")],
            ])
            .output()
            .unwrap();
        let (fh, frows) = k_table(&fwd);
        let v: f64 = frows[0][fh.iter().position(|x| x == "v").unwrap()]
            .parse()
            .unwrap();
        let v0: f64 = r[col("v")].parse().unwrap();
        assert!((v - v0).abs() <= 1e-14 * v0, "{v} vs {v0}");
        let k: f64 = r[col("K")].parse().unwrap();
        let lo: f64 = r[col("K_lo")].parse().unwrap();
        let hi: f64 = r[col("K_hi")].parse().unwrap();
        assert!(lo < k && k < hi);
    }
}

#[test]
fn k_dimensional_input_matches_dimensionless() {
    let dir = tmpdir();
    // ξ = 1, R = 3 mm, g = 9.81: v_m_s = v · sqrt(g R (1 + ξ)).
    let v = 0.39120827263;
    let scale = (9.81f64 * 0.003 * 2.0).sqrt();
    let a = write(
        &dir,
        "a.csv",
        &format!("series,xi,delta_deg,v\ns,1,12,{v}\n"),
    );
    let b = write(
        &dir,
        "b.csv",
        &format!(
            "series,xi,delta_deg,v_m_s,R_m\ns,1,12,{},0.003\n",
            v * scale
        ),
    );
    let ka = bin()
        .args(["k", "--model", "stick"])
        .arg(&a)
        .output()
        .unwrap();
    let kb = bin()
        .args(["k", "--model", "stick", "--input"])
        .arg(&b)
        .output()
        .unwrap();
    let (ha, ra) = k_table(&ka);
    let (hb, rb) = k_table(&kb);
    let k = |h: &[String], r: &[Vec<String>]| -> f64 {
        r[0][h.iter().position(|x| x == "K").unwrap()]
            .parse()
            .unwrap()
    };
    // docs/PHYSICS.md#reference-figures: v̄ = 0.39120827… at the paper's fitted law, K = cos 60° +
    // ½ sin²30° sin 60°.
    let k_paper = 0.5 + 0.0625 * 3f64.sqrt();
    assert!((k(&ha, &ra) - k_paper).abs() < 1e-8, "{}", k(&ha, &ra));
    assert!((k(&ha, &ra) - k(&hb, &rb)).abs() < 1e-13);
    assert!(hb.contains(&"v_m_s".to_string()) && hb.contains(&"R_m".to_string()));
}

#[test]
fn k_reports_out_of_range_points_with_a_status() {
    let dir = tmpdir();
    // ξ = 4, δ = 15° (Θ0 = 3.46° > 0): v far above the lift-off speed, and below the K → 0
    // limit (the bead launched at rest past the top is already faster).
    let p = write(
        &dir,
        "m.csv",
        "series,xi,delta_deg,v,sigma_v\na,4,15,5,0.1\na,4,15,0.01,0.001\nb,1,12,0.39,0.01\n",
    );
    let out = bin()
        .args(["k", "--model", "stickslip", "--input"])
        .arg(&p)
        .output()
        .unwrap();
    assert!(out.status.success());
    let (h, rows) = k_table(&out);
    let st = h.iter().position(|x| x == "status").unwrap();
    let k = h.iter().position(|x| x == "K").unwrap();
    assert_eq!(rows[0][st], "above-range");
    assert_eq!(rows[1][st], "below-range");
    assert_eq!(rows[2][st], "ok");
    assert!(rows[0][k].is_empty() && rows[1][k].is_empty());
    assert_eq!(rows[0][h.iter().position(|x| x == "regime").unwrap()], "C");
    let msg = h.iter().position(|x| x == "message").unwrap();
    assert!(
        rows[0][msg].contains("K_hi is the bracket's upper end: v + sigma_v"),
        "{}",
        rows[0][msg]
    );
    assert!(
        rows[0][msg].contains("K_lo is the bracket's upper end: v - sigma_v"),
        "{}",
        rows[0][msg]
    );
    assert!(
        rows[1][msg].contains("K_lo is the bracket's lower end: v - sigma_v"),
        "{}",
        rows[1][msg]
    );
    assert_eq!(rows[1][h.iter().position(|x| x == "regime").unwrap()], "A");
}

#[test]
fn k_bad_input_exits_2_with_location_and_leaves_output_untouched() {
    let dir = tmpdir();
    let out_path = write(&dir, "out.csv", "precious\n");
    let cases = [
        (
            "series,xi,delta_deg,v,sigma_v\na,1,12,0.3,0\n",
            "line 2",
            "sigma_v",
        ),
        (
            "series,xi,delta_deg,v,sigma_v\na,1,12,-0.3,0.01\n",
            "line 2",
            "'v'",
        ),
        (
            "series,xi,delta_deg,v\na,1,12,0.3\na,2,12,0.3\n",
            "line 3",
            "mixes xi",
        ),
        ("series,xi,delta_deg\na,1,12\n", "line 1", "'v'"),
        (
            "series,xi,delta_deg,v\na,1,12,abc\n",
            "value 'abc'",
            "not a number",
        ),
        ("series,xi,delta_deg,v_m_s\na,1,12,0.3\n", "R_m", "missing"),
        (
            "series,xi,delta_deg,v,sigma_v_m_s\na,1,12,0.3,0.01\n",
            "line 1",
            "sigma_v_m_s",
        ),
    ];
    for (text, want1, want2) in cases {
        let p = write(&dir, "bad.csv", text);
        let out = bin()
            .args(["k", "--model", "stick", "--input"])
            .arg(&p)
            .arg("--output")
            .arg(&out_path)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{text}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("bad.csv"), "{err}");
        assert!(err.contains(want1) && err.contains(want2), "{text}: {err}");
        assert_eq!(std::fs::read_to_string(&out_path).unwrap(), "precious\n");
    }
}

#[test]
fn k_plot_writes_an_svg() {
    let dir = tmpdir();
    let svg = dir.path().join("k.svg");
    let out = bin()
        .args(["k", "--model", "stick", "--plot"])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(out.status.success());
    let s = std::fs::read_to_string(&svg).unwrap();
    assert!(
        s.starts_with("<svg") && s.contains("K = cos 2α"),
        "{}",
        &s[..200]
    );
    // One marker per point (circles and polygons: each series has its shape).
    assert!(s.matches("<circle").count() + s.matches("<polygon").count() >= 36);
}

const FIT_COLUMNS: [&str; 9] = [
    "fit",
    "series",
    "parameter",
    "value",
    "stderr",
    "ci_low",
    "ci_high",
    "ci_method",
    "unit",
];

#[test]
fn fit_commands_write_the_contract_reports() {
    let dir = tmpdir();
    for (cmd, extra, fits, rows) in [
        (
            "klaw",
            vec!["--model", "stickslip"],
            vec!["klaw-c", "klaw-impact"],
            1,
        ),
        (
            "klaw",
            vec!["--model", "stick", "--law", "free-per-series"],
            vec!["klaw-free-per-series", "klaw-impact"],
            4,
        ),
        ("jan", vec![], vec!["jan-series", "jan-global"], 12),
        ("jaeger", vec![], vec!["jaeger"], 12),
    ] {
        let rep = dir.path().join(format!("{cmd}.csv"));
        let st = dir.path().join(format!("{cmd}-stats.csv"));
        let out = bin()
            .arg(cmd)
            .args(&extra)
            .arg("--output")
            .arg(&rep)
            .arg("--output-stats")
            .arg(&st)
            .arg("--level")
            .arg("0.9")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{cmd}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (h, recs) = read_table(&rep);
        assert_eq!(&h[..9], &FIT_COLUMNS[..], "{cmd}");
        assert_eq!(recs.len(), rows, "{cmd} {extra:?}");
        let level = col(&h, "level");
        for rec in &recs {
            assert!(rec[3].parse::<f64>().unwrap().is_finite());
            assert_eq!(&rec[level], "0.9");
            if let (Ok(lo), Ok(hi)) = (rec[5].parse::<f64>(), rec[6].parse::<f64>()) {
                let v: f64 = rec[3].parse().unwrap();
                assert!(lo <= v && v <= hi, "{cmd}: {rec:?}");
            }
        }
        let (h, stat_rows) = read_table(&st);
        for c in ["chi2", "dof", "aic", "bic", "termination"] {
            assert!(h.iter().any(|x| x == c), "{cmd}: stats lacks {c}");
        }
        let names: Vec<String> = stat_rows.into_iter().map(|r| r[0].clone()).collect();
        for f in &fits {
            assert!(names.iter().any(|n| n == f), "{cmd}: {names:?} lacks {f}");
        }
    }
}

#[test]
fn fit_commands_reject_bad_input_with_exit_2() {
    let mixed = "series,xi,delta_deg,v,sigma_v\na,1,10,0.3,0.01\na,1,11,0.35,\na,1,12,0.4,0.01\n";
    expect_error(&["jan"], mixed, &["line 3", "sigma_v", "every row"]);
    let dir = tmpdir();
    let outp = write(&dir, "out.csv", "precious");
    for (args, flag) in [
        (vec!["klaw", "--model", "stick", "--law", "cubic"], "--law"),
        (vec!["klaw", "--model", "jan"], "--model"),
        (vec!["jaeger", "--branch", "middle"], "--branch"),
        (vec!["jan", "--level", "95"], "--level"),
    ] {
        let out = bin()
            .args(&args)
            .arg("--output")
            .arg(&outp)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flag), "{args:?}: {err}");
        assert_eq!(std::fs::read_to_string(&outp).unwrap(), "precious");
    }
}

#[test]
fn fit_reports_are_not_written_when_one_target_fails() {
    let dir = tmpdir();
    let stats = write(&dir, "stats.csv", "precious");
    let out = bin()
        .args([
            "jan",
            "--output",
            "/nonexistent-dir/x.csv",
            "--output-stats",
        ])
        .arg(&stats)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nonexistent-dir"));
    assert_eq!(std::fs::read_to_string(&stats).unwrap(), "precious");
}

#[test]
fn klaw_names_or_skips_points_that_no_k_makes_steady() {
    // The default data (stick/slip) holds points that the slip model cannot make steady.
    let out = bin().args(["klaw", "--model", "slip"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("line 20") && err.contains("--skip-unsteady"),
        "{err}"
    );
    let out = bin()
        .args([
            "klaw",
            "--model",
            "slip",
            "--law",
            "free-per-series",
            "--skip-unsteady",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("left out") && err.contains("line 20"), "{err}");
}

#[test]
fn simulate_jan_and_jaeger_with_their_flags() {
    for args in [
        vec!["--model", "jan", "--jan", "0.063,4.96,0.0025,7.46"],
        vec![
            "--model",
            "jaeger",
            "--jaeger",
            "0.131,18.57,1.41",
            "--series",
            "1",
        ],
        vec!["--model", "jaeger", "--branch", "lower", "--series", "1"],
        vec!["--model", "stick", "--series", "1", "--delta-range", "0,30"],
        vec!["--model", "jaeger", "--delta-range", "0,30"],
    ] {
        let out = bin().arg("simulate").args(&args).output().unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let n = table(&String::from_utf8(out.stdout).unwrap()).1.len();
        assert!(n >= 9, "{args:?}: {n} rows");
    }
    for (args, flag) in [
        (vec!["--model", "jan", "--jan", "1,2,3"], "--jan"),
        (vec!["--model", "jaeger", "--series", "3"], "--series"),
        (
            vec!["--model", "stick", "--delta-range", "20,10"],
            "--delta-range",
        ),
    ] {
        let out = bin().arg("simulate").args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(flag),
            "{args:?}"
        );
    }
}

/// `jan` and `jaeger` show a progress bar of their model evaluations on a terminal only. With
/// the bar's delay at 0 (`FITBEAD_PROGRESS_DELAY_MS`, so that even a short run would draw it),
/// a piped stderr gets no bar; the same run under a pseudo-terminal (util-linux `script`, where
/// it is installed) draws it, which shows that the first check could have failed.
#[test]
fn jan_and_jaeger_draw_their_progress_bar_on_a_terminal_only() {
    let d = tmpdir();
    for cmd in ["jan", "jaeger"] {
        let (o, s) = (d.path().join("o.csv"), d.path().join("s.csv"));
        let out = bin()
            .arg(cmd)
            .arg("--output")
            .arg(&o)
            .arg("--output-stats")
            .arg(&s)
            .env("FITBEAD_PROGRESS_DELAY_MS", "0")
            .output()
            .unwrap();
        let err = crate::common::stderr(&out);
        assert!(out.status.success(), "{cmd}: {err}");
        assert!(
            !err.contains("model evaluations") && !err.contains('\r'),
            "{cmd}: a bar on a piped stderr: {err:?}"
        );
        let exe = crate::common::bin_path().display().to_string();
        let shell = format!(
            "'{exe}' {cmd} --output '{}' --output-stats '{}'",
            o.display(),
            s.display()
        );
        let Ok(pty) = std::process::Command::new("script")
            .args(["-qec", &shell, "/dev/null"])
            .env("FITBEAD_PROGRESS_DELAY_MS", "0")
            .stdin(std::process::Stdio::null())
            .output()
        else {
            eprintln!("no `script` here: the terminal side of {cmd}'s bar is not checked");
            continue;
        };
        let shown = String::from_utf8_lossy(&pty.stdout);
        assert!(pty.status.success(), "{cmd} under script: {shown}");
        assert!(
            shown.contains(&format!("{cmd} ")) && shown.contains("model evaluations"),
            "{cmd}: no bar on a terminal: {shown:?}"
        );
    }
}

/// `klaw`'s least-squares fit shows the same bar (its model evaluations, counted by the
/// library's progress observer on the fit's iterations) on a terminal only, as
/// `jan_and_jaeger_draw_their_progress_bar_on_a_terminal_only` checks for those.
#[test]
fn klaw_draws_its_progress_bar_on_a_terminal_only() {
    let d = tmpdir();
    let o = d.path().join("o.csv");
    let out = bin()
        .args(["klaw", "--model", "stick", "--no-profile", "--output"])
        .arg(&o)
        .env("FITBEAD_PROGRESS_DELAY_MS", "0")
        .output()
        .unwrap();
    let err = crate::common::stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        !err.contains("model evaluations") && !err.contains('\r'),
        "a bar on a piped stderr: {err:?}"
    );
    let exe = crate::common::bin_path().display().to_string();
    let shell = format!(
        "'{exe}' klaw --model stick --no-profile --output '{}'",
        o.display()
    );
    let Ok(pty) = std::process::Command::new("script")
        .args(["-qec", &shell, "/dev/null"])
        .env("FITBEAD_PROGRESS_DELAY_MS", "0")
        .stdin(std::process::Stdio::null())
        .output()
    else {
        eprintln!("no `script` here: the terminal side of klaw's bar is not checked");
        return;
    };
    let shown = String::from_utf8_lossy(&pty.stdout);
    assert!(pty.status.success(), "klaw under script: {shown}");
    assert!(
        shown.contains("klaw-c") && shown.contains("model evaluations"),
        "no bar on a terminal: {shown:?}"
    );
}

/// Runs fitbead with `args`: the exit code, stdout and stderr.
fn run_cli(args: &[&str]) -> (Option<i32>, String, String) {
    let out = bin().args(args).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A choice is a whole name in any case, spaces around it ignored: the same output as the
/// name as listed.
#[test]
fn choices_are_whole_names_in_any_case() {
    let scene = ["--xi", "1", "--delta-deg", "12"];
    let (code, want, _) = run_cli(&[&["forward", "--model", "stickslip"][..], &scene].concat());
    assert_eq!(code, Some(0));
    let (code, got, err) = run_cli(&[&["forward", "--model", " StickSlip "][..], &scene].concat());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(got, want);
    // The k table names the model as listed, whatever its spelling on the command line.
    let (code, got, err) = run_cli(&["k", "--model", "STICK"]);
    assert_eq!(code, Some(0), "{err}");
    let (h, rows) = table(&got);
    let m = h.iter().position(|c| c == "model").unwrap();
    assert!(rows.iter().all(|r| r[m] == "stick"), "{:?}", rows[0]);
}

/// A refused value is one line in the flag form, exit 2, before any work: a choice with the
/// list of its names, a number out of its range or not a number, an item of a list by itself.
/// A bad value of a flag the run would not use is refused as well.
#[test]
fn refused_values_name_the_flag_and_the_value() {
    let cases: [(&[&str], &str); 7] = [
        (
            &["simulate", "--model", "foo"],
            "fitbead: error: <command line>, flag '--model', value 'foo': unknown model; \
             expected one of stick, stick-approx, slip, slip-approx, stickslip, jan, jaeger, \
             contact, md, auto\n",
        ),
        (
            &["k", "--model", "jan"],
            "fitbead: error: <command line>, flag '--model', value 'jan': expected one of \
             stick, stick-approx, slip, slip-approx, stickslip, contact, auto\n",
        ),
        (
            &["klaw", "--model", "stick", "--level", "abc"],
            "fitbead: error: <command line>, flag '--level', value 'abc': must be in (0, 1), \
             e.g. 0.95\n",
        ),
        (
            &["regimes", "--rho", "-1"],
            "fitbead: error: <command line>, flag '--rho', value '-1': must be a finite number \
             >= 0\n",
        ),
        (
            &["simulate", "--jan", "1, x,3,4"],
            "fitbead: error: <command line>, flag '--jan', value 'x': not a finite number\n",
        ),
        (
            &["simulate", "--model", "stick", "--branch", "sideways"],
            "fitbead: error: <command line>, flag '--branch', value 'sideways': expected upper \
             or lower\n",
        ),
        (
            &["report", "--format", "gif"],
            "fitbead: error: <command line>, flag '--format', value 'gif': must be svg, png, \
             pdf, both (svg and png) or all\n",
        ),
    ];
    for (args, want) in cases {
        let (code, out, err) = run_cli(args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert_eq!(err, want, "{args:?}");
        assert!(out.is_empty(), "{args:?}: {out}");
    }
    // The help lists every choice's names.
    let (code, out, _) = run_cli(&["simulate", "--help"]);
    assert_eq!(code, Some(0));
    assert!(
        out.contains("[possible values: stick, stick-approx, slip, slip-approx, stickslip"),
        "{out}"
    );
}
