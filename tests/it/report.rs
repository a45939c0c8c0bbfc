//! `fitbead report`'s fit reports and tables, and the fit commands' report on stdout:
//! residuals.csv and correlations.csv (their contract columns and what their rows must
//! satisfy), report.md stating every fitted value, and `klaw`/`jan`/`jaeger` printing a fit
//! report without `--output`.

use crate::common::{bin, col, read_table, records, stdout_ok, tmpdir, write};
use std::path::Path;

fn report_into(dir: &Path, extra: &[&str]) {
    let mut args = vec!["report", "--out-dir", dir.to_str().unwrap()];
    args.extend_from_slice(extra);
    stdout_ok(&bin().args(&args).output().unwrap());
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

/// residuals.csv has the contract columns, one row per fit and point, and each row's residual
/// is v − v_fit and its normalised residual (v − v_fit)/σ. The fitted v̄ of the stick/slip
/// law-c fit is checked against `fitbead forward` run at the fitted c on the same points.
#[test]
fn residuals_csv_holds_every_point_of_every_fit() {
    let dir = tmpdir();
    report_into(dir.path(), &[]);
    let (h, rows) = read_table(&dir.path().join("residuals.csv"));
    assert_eq!(
        h,
        [
            "fit",
            "series",
            "xi",
            "delta_deg",
            "v",
            "sigma_v",
            "v_fit",
            "residual",
            "normalised_residual"
        ]
    );
    // Every fit of params.csv appears with all 36 points of the shipped data (every fit of
    // the report uses every point of that set).
    let (ph, prow) = read_table(&dir.path().join("params.csv"));
    let mut fits: Vec<String> = prow.iter().map(|r| r[col(&ph, "fit")].clone()).collect();
    fits.dedup();
    // (Per-series fits, jan-series and jaeger, name 4 fits of 9 points each.)
    for f in &fits {
        let n = rows.iter().filter(|r| &r[0] == f).count();
        assert_eq!(n, 36, "{f}: {n} rows");
    }
    for r in &rows {
        let (v, s, vf, res, nr) = (num(&r[4]), num(&r[5]), num(&r[6]), num(&r[7]), num(&r[8]));
        assert!((res - (v - vf)).abs() <= 1e-15, "{r:?}");
        assert!((nr - res / s).abs() <= 1e-12 * nr.abs().max(1.0), "{r:?}");
    }
    // The stick/slip law-c fit's v̄ at each point, recomputed by the forward command at c.
    let c = prow
        .iter()
        .find(|r| r[0] == "stickslip-klaw-c" && r[2] == "c")
        .map(|r| r[col(&ph, "value")].clone())
        .expect("stickslip law c in params.csv");
    let pts: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "stickslip-klaw-c").collect();
    let mut scenes = String::from("xi,delta_deg\n");
    for r in &pts {
        scenes.push_str(&format!("{},{}\n", r[2], r[3]));
    }
    let input = write(dir.path(), "scenes.csv", &scenes);
    let out = bin()
        .args(["forward", "--model", "stickslip", "--input"])
        .arg(&input)
        .arg(format!("--K=c={c}"))
        .output()
        .unwrap();
    let (_, fr) = records(&stdout_ok(&out));
    assert_eq!(fr.len(), pts.len());
    for (r, f) in pts.iter().zip(&fr) {
        let v = num(&f["v"]);
        assert!(
            (v - num(&r[6])).abs() <= 1e-15 * v,
            "forward {v} against v_fit {}",
            r[6]
        );
    }
}

/// correlations.csv has the contract columns; every correlation lies in [−1, 1]; each fit with
/// a matrix lists each pair once; one K per series fitted together has independent
/// parameters (each residual depends on its own series' K only), so their correlations are 0.
#[test]
fn correlations_csv_lists_every_pair_once() {
    let dir = tmpdir();
    report_into(dir.path(), &[]);
    let (h, rows) = read_table(&dir.path().join("correlations.csv"));
    assert_eq!(
        h,
        ["fit", "series", "parameter_1", "parameter_2", "correlation"]
    );
    for r in &rows {
        let c = num(&r[4]);
        assert!((-1.0..=1.0).contains(&c), "{r:?}");
    }
    for model in ["rolling", "stickslip"] {
        let fit = format!("{model}-klaw-free-per-series");
        let sel: Vec<_> = rows.iter().filter(|r| r[0] == fit).collect();
        assert_eq!(sel.len(), 6, "{fit}: 4 parameters make 6 pairs");
        assert!(sel.iter().all(|r| num(&r[4]) == 0.0), "{sel:?}");
    }
    // Jan's per-series fits: λ and μ, one pair per series, and strongly anti-correlated (a
    // larger drag λ is traded against a smaller friction μ along the measured v̄).
    let jan: Vec<_> = rows.iter().filter(|r| r[0] == "jan-series").collect();
    assert_eq!(jan.len(), 4);
    assert!(jan.iter().all(|r| r[2] == "lambda" && r[3] == "mu"));
    assert!(jan.iter().all(|r| num(&r[4]) < -0.5), "{jan:?}");
}

/// report.md opens (after the data line) with a table of every fitted parameter, one row per
/// row of params.csv with its value; it has a Jaeger section that explains a2 on its bound,
/// the banner of the shipped synthetic data, and each fit's report.
#[test]
fn report_md_states_every_fitted_value() {
    let dir = tmpdir();
    report_into(dir.path(), &[]);
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(md.contains("**These data are synthetic.**"));
    let table_at = md.find("## Fitted parameters").expect("parameter table");
    assert!(table_at < md.find("## Bulk friction").unwrap());
    let (ph, prow) = read_table(&dir.path().join("params.csv"));
    for r in &prow {
        let (fit, param, value) = (
            &r[col(&ph, "fit")],
            &r[col(&ph, "parameter")],
            num(&r[col(&ph, "value")]),
        );
        let series = &r[col(&ph, "series")];
        // A per-series fit's row names its series; a fit across series names the parameter
        // by series (`K[1.6]`) in the row of `all`.
        let line = md
            .lines()
            .find(|l| {
                l.starts_with(&format!("| {fit} | {series} | {param} |"))
                    || l.starts_with(&format!("| {fit} | all | {param}[{series}] |"))
            })
            .unwrap_or_else(|| panic!("no row for {fit} {series} {param}"));
        // The value cell, rounded as printed, is within half a unit of its last digit.
        let cell = line.split('|').nth(4).unwrap().trim();
        let shown = cell.split(" ± ").next().unwrap();
        let places = shown.split('.').nth(1).map_or(0, str::len) as i32;
        let tol = 0.5 * 10f64.powi(-places) + 1e-12;
        let rel = shown.contains('e');
        assert!(
            rel || (num(shown) - value).abs() <= tol * 1.0000001,
            "{fit} {param}: shown {shown}, value {value}"
        );
    }
    assert!(md.contains("## Jaeger's law"));
    assert!(md.contains("a2 sits on its bound 0"));
    assert!(md.contains("## Fit reports"));
    assert_eq!(
        md.matches("[[Fit ").count(),
        {
            let mut f: Vec<(String, String)> =
                prow.iter().map(|r| (r[0].clone(), r[1].clone())).collect();
            // A fit across series has one row per series parameter but one report.
            for x in f.iter_mut() {
                if x.0.contains("klaw") {
                    x.1 = "all".into();
                }
            }
            f.dedup();
            f.len()
        },
        "one fit report per fit"
    );
}

/// With velocities in m/s, report.md says how they were made dimensionless, per series; a
/// file other than the shipped data gets no synthetic-data banner.
#[test]
fn report_md_states_the_si_conversion() {
    let dir = tmpdir();
    let input = write(
        dir.path(),
        "si.csv",
        "series,xi,delta_deg,v_m_s,sigma_v_m_s,R_m\n\
         A,1,8,0.068,0.0024,0.003\nA,1,10,0.092,0.0024,0.003\nA,1,12,0.109,0.0024,0.003\n\
         A,1,14,0.124,0.0024,0.003\nB,2,4,0.098,0.0045,0.003\nB,2,6,0.137,0.0045,0.003\n\
         B,2,8,0.163,0.0045,0.003\nB,2,10,0.187,0.0045,0.003\n",
    );
    let out_dir = dir.path().join("r");
    report_into(&out_dir, &["--input", input.to_str().unwrap()]);
    let md = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(!md.contains("These data are synthetic"));
    assert!(md.contains("made dimensionless by v = v_m_s / sqrt(g R (1 + ξ))"));
    // sqrt(9.81 · 0.003 · 2) = 0.242611 m/s and sqrt(9.81 · 0.003 · 3) = 0.297136 m/s.
    assert!(md.contains("| A | 1 | 0.003 | 9.81 | 0.242611 |"), "{md}");
    assert!(md.contains("| B | 2 | 0.003 | 9.81 | 0.297136 |"), "{md}");
    // Without --units the velocity figure is dimensionless; with --units si, in m/s.
    let fig = std::fs::read_to_string(out_dir.join("velocity.svg")).unwrap();
    assert!(fig.contains("√(g(R + r))") && !fig.contains("(m/s)"));
    let si_dir = dir.path().join("si");
    report_into(
        &si_dir,
        &["--input", input.to_str().unwrap(), "--units", "si"],
    );
    let fig = std::fs::read_to_string(si_dir.join("velocity.svg")).unwrap();
    assert!(fig.contains("(m/s)"), "velocity.svg is not in m/s");
    // Every velocity axis: Jan's v̄²/cos δ in m²/s² (the exponents are superscript runs),
    // the final velocity of the K figure in m/s.
    let jan = std::fs::read_to_string(si_dir.join("jan_linear.svg")).unwrap();
    assert!(
        jan.contains("(m</tspan>") && jan.contains(">/s</tspan>"),
        "jan_linear.svg is not in m²/s²"
    );
    assert!(!jan.contains("g(R + r)"));
    let k = std::fs::read_to_string(si_dir.join("k_final_velocity.svg")).unwrap();
    assert!(k.contains("(m/s)"), "k_final_velocity.svg is not in m/s");
    assert!(!k.contains("√(g(R + r))"));
    // The dimensionless data are refused with --units si.
    let out = bin()
        .args(["report", "--units", "si", "--out-dir"])
        .arg(dir.path().join("no"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--units"));
    assert!(!dir.path().join("no").exists());
}

/// Without --output, klaw, jan and jaeger print a fit report per fit on stdout (and no
/// statistics table on stderr, which the reports carry); `--output -` prints the parameter CSV.
#[test]
fn fit_commands_print_a_fit_report_without_output() {
    for (cmd, extra, name) in [
        ("klaw", vec!["--model", "stick"], "c "),
        ("jan", vec![], "lambda "),
        ("jaeger", vec![], "a2 "),
    ] {
        let out = bin().arg(cmd).args(&extra).output().unwrap();
        let text = stdout_ok(&out);
        assert!(text.starts_with("[[Fit "), "{cmd}: {text}");
        assert!(text.contains("[[Variables]]"), "{cmd}");
        assert!(text.contains(&format!("    {name}")), "{cmd}: {text}");
        assert!(text.contains("reduced chi-square"), "{cmd}");
        assert!(
            !String::from_utf8_lossy(&out.stderr).contains(" dof "),
            "{cmd}: statistics table on stderr"
        );
        let csv = stdout_ok(
            &bin()
                .arg(cmd)
                .args(&extra)
                .args(["--output", "-"])
                .output()
                .unwrap(),
        );
        assert!(
            csv.starts_with("fit,series,parameter,value,stderr,ci_low,ci_high,ci_method,unit"),
            "{cmd}: {csv}"
        );
        assert!(!Path::new("-").exists(), "a file named '-' was written");
    }
}

#[test]
fn output_dash_is_standard_output_for_every_table_command() {
    // Run in a fresh directory: a file named '-' there would be the bug.
    let tmp = tmpdir();
    let dir = tmp.path();
    for args in [
        vec![
            "forward",
            "--model",
            "stick",
            "--xi",
            "1",
            "--delta-deg",
            "12",
        ],
        vec!["k", "--model", "stick"],
        vec!["regimes"],
    ] {
        let out = bin()
            .current_dir(dir)
            .args(&args)
            .args(["--output", "-"])
            .output()
            .unwrap();
        let text = stdout_ok(&out);
        let plain = stdout_ok(&bin().current_dir(dir).args(&args).output().unwrap());
        assert_eq!(text, plain, "{args:?}: --output - differs from no --output");
        assert!(text.lines().count() > 1, "{args:?}: {text}");
        assert!(
            !dir.join("-").exists(),
            "{args:?}: a file named '-' was written"
        );
    }
}

/// `--format all` writes every figure as SVG, PNG and PDF; each PDF is a PDF document with the
/// embedded font subset into it and a ToUnicode map (its text is selectable), and report.md
/// links all three. The figures' titles carry no reference to the paper's figures: report.md's
/// captions do.
#[test]
fn report_writes_pdf_figures_with_the_font_embedded() {
    let dir = tmpdir();
    let out_dir = dir.path().join("r");
    report_into(&out_dir, &["--format", "all"]);
    let md = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    let mut svgs = 0;
    for e in std::fs::read_dir(&out_dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "svg") {
            svgs += 1;
            let svg = std::fs::read_to_string(&p).unwrap();
            assert!(!svg.contains("(the paper's Fig"), "{}", p.display());
            assert!(p.with_extension("png").exists(), "{}", p.display());
            let pdf = std::fs::read(p.with_extension("pdf")).unwrap();
            assert!(pdf.starts_with(b"%PDF-"), "{}", p.display());
            let text = String::from_utf8_lossy(&pdf);
            for key in ["DejaVuSans", "/FontFile2", "/ToUnicode"] {
                assert!(text.contains(key), "{}: no {key}", p.display());
            }
            let name = p
                .file_name()
                .unwrap()
                .to_string_lossy()
                .replace(".svg", ".pdf");
            assert!(
                md.contains(&format!("[{name}]({name})")),
                "{name} not linked"
            );
        }
    }
    assert_eq!(svgs, 8);
    assert!(md.contains("(the paper's Fig. 4)"));
}

/// With slope errors report.md says how the fits used them and lists, per fit, exactly the
/// points whose adjusted slope moved by more than 2σ_δ (residuals.csv's `delta_residual`), and
/// Jan's μ intervals (bulk_friction.csv) are wider than those of the same points with the
/// slopes taken as exact; without slope errors there is no such section.
#[test]
fn report_md_names_the_moved_slopes_and_mu_carries_them() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/odr/bead_stick.csv");
    let text = std::fs::read_to_string(&data).unwrap();
    let exact: String = text
        .lines()
        .map(|l| l.split(',').take(5).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    let (with, without) = (tmpdir(), tmpdir());
    let plain = write(without.path(), "exact.csv", &exact);
    report_into(with.path(), &["--keep-going", data.to_str().unwrap()]);
    report_into(without.path(), &["--keep-going", plain.to_str().unwrap()]);
    let md = std::fs::read_to_string(with.path().join("report.md")).unwrap();
    let at = md
        .find("## Slopes measured with error")
        .expect("slope section");
    let section = &md[at..md[at..].find("## Bulk friction").unwrap() + at];
    assert!(section.contains("24 of 24 points carry a slope uncertainty σ_δ (0.1°)"));
    let listed: Vec<(String, String, f64)> = section
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| fit |"))
        .map(|l| {
            let c: Vec<&str> = l.split('|').map(str::trim).collect();
            (c[1].to_string(), c[2].to_string(), num(c[3]))
        })
        .collect();
    let (h, rows) = read_table(&with.path().join("residuals.csv"));
    let moved: Vec<(String, String, f64)> = rows
        .iter()
        .filter(|r| num(&r[col(&h, "delta_residual")]).abs() > 2.0)
        .map(|r| {
            let d = num(&r[col(&h, "delta_deg")]);
            (r[col(&h, "fit")].clone(), r[col(&h, "series")].clone(), d)
        })
        .collect();
    assert_eq!(listed.len(), moved.len(), "{section}");
    for ((f, s, d), (g, t, e)) in listed.iter().zip(&moved) {
        assert!(
            f == g && s == t && (d - e).abs() < 1e-4,
            "{f} {s} {d} against {g} {t} {e}"
        );
    }
    if moved.is_empty() {
        assert!(section.contains("none."));
    }
    let md0 = std::fs::read_to_string(without.path().join("report.md")).unwrap();
    assert!(!md0.contains("## Slopes measured with error"));
    let width = |dir: &Path| -> Vec<f64> {
        let (h, rows) = read_table(&dir.join("bulk_friction.csv"));
        rows.iter()
            .map(|r| num(&r[col(&h, "mu_jan_hi")]) - num(&r[col(&h, "mu_jan_lo")]))
            .collect()
    };
    let (w1, w0) = (width(with.path()), width(without.path()));
    assert!(!w1.is_empty() && w1.len() == w0.len());
    for (a, b) in w1.iter().zip(&w0) {
        assert!(
            a > &(1.2 * b),
            "μ interval {a} with slope errors, {b} without"
        );
    }
}
