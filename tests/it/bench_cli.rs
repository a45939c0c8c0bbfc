//! `fitbead bench` and `--model auto`: columns, the references' cross-checks, and
//! auto meeting its tolerance on every scene.

use std::collections::HashMap;

use crate::common::{bin, records, stdout_ok, tmpdir, write};

fn num(r: &HashMap<String, String>, c: &str) -> f64 {
    r[c].parse::<f64>()
        .unwrap_or_else(|_| panic!("{c} = {:?}", r[c]))
}

#[test]
fn bench_small_run_has_the_contract_columns_checked_references_and_auto_within_tolerance() {
    let dir = tmpdir();
    let csv_path = dir.path().join("wp.csv");
    let svg_path = dir.path().join("wp.svg");
    let out = bin()
        .args(["bench", "--scenes", "40", "--seed", "7", "--output"])
        .arg(&csv_path)
        .arg("--plot")
        .arg(&svg_path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("FAILED"), "{err}");
    let text = std::fs::read_to_string(&csv_path).unwrap();
    let (h, rows) = records(&text);
    assert_eq!(
        h,
        [
            "model",
            "method",
            "tolerance",
            "scenes",
            "err_median",
            "err_p99",
            "err_max",
            "ns_median",
            "ns_p99"
        ]
    );
    // Every model and method variant is there.
    let has = |m: &str, meth: &str, tol: &str| {
        rows.iter()
            .any(|r| r["model"] == m && r["method"] == meth && r["tolerance"] == tol)
    };
    assert!(has("stick", "elliptic", ""));
    assert!(has("stick-approx", "asinh-eq29", ""));
    assert!(has("slip-approx", "elliptic-eq57", ""));
    for t in ["0.0001", "1e-6", "1e-8", "1e-10", "1e-12", "1e-14"] {
        for m in ["stick", "slip", "stickslip", "contact"] {
            assert!(has(m, "quadrature", t), "{m} at {t}\n{text}");
        }
    }
    assert!(rows.iter().any(|r| r["model"] == "k-stickslip"));
    // The references are cross-checked by independent methods, and agree.
    let bounds = [
        ("stick", 1e-13),
        ("slip", 1e-11),
        ("stickslip", 1e-11),
        ("contact", 1e-12),
    ];
    for (m, b) in bounds {
        let x: Vec<_> = rows
            .iter()
            .filter(|r| r["model"] == m && r["method"].starts_with("crosscheck"))
            .collect();
        assert_eq!(x.len(), 1, "{m}");
        assert!(
            num(x[0], "scenes") >= 5.0,
            "{m}: too few scenes cross-checked"
        );
        assert!(num(x[0], "err_max") <= b, "{m}: {:?}", x[0]);
    }
    // Auto meets its tolerance on every scene.
    let autos: Vec<_> = rows.iter().filter(|r| r["model"] == "auto").collect();
    assert_eq!(autos.len(), 5);
    for r in autos {
        let t = num(r, "tolerance");
        assert!(num(r, "err_max") <= t, "{r:?}");
        assert!(num(r, "scenes") >= 30.0, "{r:?}");
        assert!(num(r, "ns_median") > 0.0);
    }
    // Stick by quadrature at 1e-10 or tighter meets 1e-10 against the elliptic closed form.
    for r in rows
        .iter()
        .filter(|r| r["model"] == "stick" && r["method"] == "quadrature")
    {
        if num(r, "tolerance") <= 1e-10 {
            assert!(num(r, "err_max") <= 1e-10, "{r:?}");
        }
    }
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("auto"));
}

#[test]
fn bench_rejects_zero_scenes() {
    let out = bin().args(["bench", "--scenes", "0"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--scenes"));
}

fn forward(model: &str, tol: &str, input: &str) -> Vec<HashMap<String, String>> {
    let dir = tmpdir();
    let p = write(&dir, "s.csv", input);
    let out = bin()
        .args(["forward", "--model", model, "--tol", tol, "--input"])
        .arg(&p)
        .output()
        .unwrap();
    records(&stdout_ok(&out)).1
}

#[test]
fn forward_auto_says_which_model_and_why_and_matches_the_general_model() {
    // f = 0.5: no slip at all (rolling exact); f = 0.1 at the paper's Fig. 7 scenes: slip.
    let input = "xi,delta_deg,f\n2,5.73,0.5\n2,5.73,0.1\n1,11.53,0.1\n0.8,14,0.02\n";
    let auto = forward("auto", "1e-10", input);
    let contact = forward("contact", "1e-14", input);
    let stick = forward("stick", "1e-14", input);
    assert_eq!(auto[0]["model_used"], "stick");
    assert!(auto[0]["reason"].starts_with("no slip"), "{:?}", auto[0]);
    assert_eq!(auto[0]["v"], stick[0]["v"]);
    for (a, c) in auto.iter().zip(&contact) {
        assert!(
            ["stick", "stickslip", "contact"].contains(&a["model_used"].as_str()),
            "{a:?}"
        );
        assert!(!a["reason"].is_empty());
        assert_eq!(a["status"], c["status"], "{a:?}");
        if c["v"].is_empty() {
            assert!(a["v"].is_empty());
            continue;
        }
        let (va, vc) = (num(a, "v"), num(c, "v"));
        assert!(((va - vc) / vc).abs() <= 1e-10, "{a:?} vs {vc}");
    }
    assert_eq!(auto[1]["model_used"], "stickslip");
    assert_eq!(auto[2]["model_used"], "contact");
    assert!(auto[2]["reason"].starts_with("slip before the top"));
}

#[test]
fn forward_auto_rejects_a_bad_tolerance() {
    let out = bin()
        .args([
            "forward",
            "--model",
            "auto",
            "--xi",
            "1",
            "--delta-deg",
            "12",
            "--tol",
            "0",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--tol"));
}

fn k_rows(args: &[&str]) -> Vec<HashMap<String, String>> {
    let out = bin().arg("k").args(args).output().unwrap();
    records(&stdout_ok(&out)).1
}

#[test]
fn k_auto_inverts_each_row_with_the_model_it_names() {
    // The embedded default data set: every row says its model, and its K is that model's K.
    let auto = k_rows(&["--model", "auto", "--tol", "1e-10"]);
    let ss = k_rows(&["--model", "stickslip"]);
    let contact = k_rows(&["--model", "contact"]);
    let stick = k_rows(&["--model", "stick"]);
    assert!(!auto.is_empty());
    let mut used = std::collections::HashSet::new();
    for (i, a) in auto.iter().enumerate() {
        assert_eq!(a["model"], "auto");
        assert!(a["reason"].starts_with("at the stick K"), "{a:?}");
        used.insert(a["model_used"].clone());
        let other = match a["model_used"].as_str() {
            "stick" => &stick[i],
            "stickslip" => &ss[i],
            "contact" => &contact[i],
            m => panic!("model_used {m}"),
        };
        assert_eq!(a["status"], other["status"], "{a:?}");
        if a["K"].is_empty() {
            continue;
        }
        let (ka, ko) = (num(a, "K"), num(other, "K"));
        // contact inside auto runs at T/10 = 1e-11 (the plain run at 1e-14).
        assert!(((ka - ko) / ko).abs() <= 1e-9, "{a:?} vs {ko}");
        // The choice was made at the stick K of the same row.
        if !stick[i]["K"].is_empty() {
            let ks = num(&stick[i], "K");
            assert!(a["reason"].contains(&format!("{ks:.6}")), "{a:?} {ks}");
        }
    }
    assert!(
        used.contains("contact") && used.contains("stickslip"),
        "{used:?}"
    );
}

#[test]
fn klaw_auto_fits_with_the_most_general_model_any_point_needs_and_says_so() {
    let out = bin()
        .args(["klaw", "--model", "auto", "--tol", "1e-10", "--output", "-"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let (_, rows) = records(&String::from_utf8(out.stdout).unwrap());
    let c = rows.iter().find(|r| r["fit"] == "klaw-c").unwrap();
    // The fit summary (stderr) carries the note.
    assert!(
        err.contains("klaw-c [all]") && err.contains("model_used contact for all points"),
        "{err}"
    );
    // The same fit as --model contact at the auto's inner tolerance: c agrees closely.
    let out = bin()
        .args(["klaw", "--model", "contact", "--output", "-"])
        .output()
        .unwrap();
    let (_, plain) = records(&String::from_utf8(out.stdout).unwrap());
    let p = plain.iter().find(|r| r["fit"] == "klaw-c").unwrap();
    let (ca, cp) = (num(c, "value"), num(p, "value"));
    assert!(((ca - cp) / cp).abs() < 1e-8, "{ca} {cp}");
    let bad = bin()
        .args(["k", "--model", "auto", "--tol", "2"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
