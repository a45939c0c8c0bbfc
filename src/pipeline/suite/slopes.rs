//! Slopes measured with error, against an independent implementation: the law-c fit of
//! `tests/reference/odr/bead_stick.csv` (three series, 8 slopes each, 1 % velocity noise,
//! σ_δ = 0.1°) by orthogonal distance regression, compared with ODRPACK's (`scipy.odr`,
//! `scripts/odr_reference.py`, `tests/reference/odr/bead_stick.json`), and the same data with
//! the slopes taken as exact, compared with that file's weighted least squares.

use crate::fit::data::Dataset;
use crate::fit::klaw::{fit_law, KLaw};
use crate::inverse::ProfileEnd;
use crate::io::measurements::MeasurementDefaults;
use crate::models::Model;

fn reference() -> serde_json::Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/odr/bead_stick.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The data with every point's σ_δ set to `sigma_deg` (the file's column holds 0.1).
fn data(sigma_deg: f64) -> Dataset {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/odr/bead_stick.csv"
    );
    let mut d = Dataset::from_csv_with(path, &MeasurementDefaults::default()).unwrap();
    for p in &mut d.points {
        p.sigma_delta = sigma_deg.to_radians();
    }
    d
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn bead_odr_matches_odrpack() {
    let r = reference();
    let odr = &r["fits"]["odr"];
    let fit = fit_law(Model::Stick, &data(0.1), KLaw::C, 0.95, true).unwrap();
    let s = &fit.summary;
    assert!(s.stats.slope_errors && s.stats.converged, "{:?}", s.stats);
    let c = s.params[0].value;
    let want = num(&odr["beta"][0]);
    assert!((c - want).abs() < 1e-6 * want, "c {c} vs ODRPACK {want}");
    // Absolute σ: the standard error is ODRPACK's unscaled √cov_β.
    let se = s.params[0].stderr.unwrap();
    let want_se = num(&odr["cov_beta"][0][0]).sqrt();
    assert!(
        (se - want_se).abs() < 1e-4 * want_se,
        "se {se} vs {want_se}"
    );
    let chi2 = s.stats.chi2;
    let want_s = num(&odr["sum_square"]);
    assert!(
        (chi2 - want_s).abs() < 1e-6 * want_s,
        "S {chi2} vs {want_s}"
    );
    // Adjusted slopes: ODRPACK's δ (degrees) added to the measured slopes.
    for (k, p) in s.points.iter().enumerate() {
        let d = num(&odr["delta"][k]);
        let got = p.delta_fit_deg.unwrap() - p.delta_deg;
        assert!((got - d).abs() < 1e-4 * 0.1, "point {k}: δ {got} vs {d}");
        assert!((p.delta_residual.unwrap() - d / 0.1).abs() < 1e-3);
    }
    // The profile interval of c brackets the estimate and is about ±1.96 se wide.
    let (ProfileEnd::Found(lo), ProfileEnd::Found(hi)) = s.params[0].profile.expect("profile")
    else {
        panic!("profile ends not found: {:?}", s.params[0].profile)
    };
    assert!(lo < c && c < hi);
    let ratio = (hi - lo) / (2.0 * 1.959964 * se);
    assert!(
        (ratio - 1.0).abs() < 0.1,
        "profile width / covariance width {ratio}"
    );
}

#[test]
fn exact_slopes_keep_least_squares() {
    let r = reference();
    let wls = &r["fits"]["wls"];
    let fit = fit_law(Model::Stick, &data(0.0), KLaw::C, 0.95, false).unwrap();
    let s = &fit.summary;
    assert!(!s.stats.slope_errors);
    assert!(s.points.iter().all(|p| p.delta_fit_deg.is_none()));
    let want = num(&wls["beta"][0]);
    assert!((s.params[0].value - want).abs() < 1e-6 * want);
}
