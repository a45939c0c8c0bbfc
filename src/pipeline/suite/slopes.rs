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

/// Coverage by simulation: `simulate --model stick --law c=0.5 --noise 0.01 --sigma-delta 0.1
/// --seed S --design D` for S = 1 … 400, with D the true slopes of
/// `tests/reference/odr/bead_stick.csv` (ξ = 0.8, 1, 1.6; 8 slopes each across 10–90 % of the
/// steady range), each set fitted for c with its slope errors (ODR) and with the slopes taken
/// as exact (weighted least squares). The 95 % intervals of ODR cover the true c = 0.5 in at
/// least 93 % of the sets, as often as ODRPACK's do on 400 sets of the same design
/// (`tests/reference/odr/bead_stick_coverage.json`: 97.0 %; the estimator is conservative
/// there, its √cov 6 % above the spread of ĉ); those of least squares, which ignore the
/// slopes' errors, far less often (ODRPACK's file: 52.3 %). Measured here: 97.75 % (covariance
/// and profile intervals alike) and 50.75 %.
#[test]
fn odr_intervals_cover_at_their_level() {
    let dir = tempfile::tempdir().unwrap();
    let design = design_file(dir.path());
    let (mut hit, mut hit_profile, mut hit_wls, mut fitted) = (0, 0, 0, 0);
    let mut fails = Vec::new();
    for seed in 1..=400u64 {
        let mut d = simulated(&design, seed);
        // (covariance interval covers, profile interval covers) of the law-c fit.
        let covers = |d: &Dataset, profile: bool| -> Option<(bool, bool)> {
            let f = fit_law(Model::Stick, d, KLaw::C, 0.95, profile).ok()?;
            let row = &f.summary.params[0];
            let se = row.stderr?;
            let by_profile = matches!(row.profile,
                Some((ProfileEnd::Found(lo), ProfileEnd::Found(hi))) if lo <= 0.5 && 0.5 <= hi);
            Some(((row.value - 0.5).abs() <= 1.959964 * se, by_profile))
        };
        match covers(&d, true) {
            Some((c, p)) => {
                fitted += 1;
                hit += usize::from(c);
                hit_profile += usize::from(p);
                for p in &mut d.points {
                    p.sigma_delta = 0.0;
                }
                hit_wls += usize::from(covers(&d, false).is_some_and(|c| c.0));
            }
            None => fails.push(seed),
        }
    }
    let rate = |k: usize| k as f64 / fitted as f64;
    let (odr, profile, wls) = (rate(hit), rate(hit_profile), rate(hit_wls));
    eprintln!(
        "coverage over {fitted} sets: ODR {odr:.4} (profile {profile:.4}), slopes exact \
         {wls:.4}; not fitted: {fails:?}"
    );
    assert!(
        fails.len() <= 8,
        "{} sets not fitted: {fails:?}",
        fails.len()
    );
    // The intervals are not too narrow: the lower end.
    assert!(odr >= 0.93, "ODR coverage {odr}");
    // The same as ODRPACK's on the same design and noise (other draws): within three standard
    // errors of the difference of two binomial proportions over 400 sets each.
    let c: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/reference/odr/bead_stick_coverage.json"
        ))
        .unwrap(),
    )
    .unwrap();
    for (ours, key) in [(odr, "odr"), (wls, "wls")] {
        let theirs = c[key]["coverage_95_unscaled"].as_f64().unwrap();
        let p = 0.5 * (ours + theirs);
        let se = (2.0 * p * (1.0 - p) / 400.0).sqrt();
        assert!(
            (ours - theirs).abs() <= 3.0 * se,
            "{key}: {ours} against ODRPACK's {theirs}"
        );
    }
    assert!(wls < 0.85, "least squares with exact slopes covers {wls}");
}

/// The posterior of c on `bead_stick.csv` with its slope errors (the likelihood integrated
/// over each true slope) against the ODR fit of the same data: the same centre and spread to
/// within the sampler's error (posterior sd within 10 % of ODR's √cov, which is ODRPACK's to
/// 1e-4), and about twice the spread of the posterior that takes the slopes as exact (the ODR
/// and least-squares errors of this set differ ×1.95).
#[test]
fn posterior_with_slope_errors_spreads_as_odr() {
    use crate::fit::klaw::fit_law_with;
    use crate::inverse::posterior::{McmcSettings, Method};
    let run = |d: &Dataset| {
        let method = Method::Mcmc(Box::new(McmcSettings::seeded(5)));
        let f = fit_law_with(Model::Stick, d, KLaw::C, 0.95, &method).unwrap();
        let row = f.summary.params[0].clone();
        let post = row.posterior.expect("posterior summary");
        assert!(f.summary.stats.mcmc.is_some());
        (post.mean, post.sd)
    };
    let odr = fit_law(Model::Stick, &data(0.1), KLaw::C, 0.95, false).unwrap();
    let (c, se) = (
        odr.summary.params[0].value,
        odr.summary.params[0].stderr.unwrap(),
    );
    let (mean, sd) = run(&data(0.1));
    assert!(
        (sd / se - 1.0).abs() < 0.10,
        "posterior sd {sd} against ODR's {se}"
    );
    assert!(
        (mean - c).abs() < 0.3 * se,
        "posterior mean {mean} against ODR's {c}"
    );
    let (_, sd_exact) = run(&data(0.0));
    let ratio = sd / sd_exact;
    assert!(
        (1.6..2.4).contains(&ratio),
        "sd with slope errors / without: {ratio}"
    );
}

/// Coverage of the posterior's 95 % intervals with slope errors, on 100 of the simulated sets
/// of [`odr_intervals_cover_at_their_level`] (seeds 1–100): 90–99 %. Ignored by default (a
/// few minutes on two cores): `cargo test --release --lib pipeline::suite::slopes::posterior_
/// -- --ignored --nocapture`.
#[test]
#[ignore]
fn posterior_intervals_cover_at_their_level() {
    use crate::fit::klaw::fit_law_with;
    use crate::inverse::posterior::{McmcSettings, Method};
    let dir = tempfile::tempdir().unwrap();
    let design = design_file(dir.path());
    let (mut hit, mut fitted) = (0, 0);
    for seed in 1..=100u64 {
        let d = simulated(&design, seed);
        let method = Method::Mcmc(Box::new(McmcSettings::seeded(seed)));
        let Ok(f) = fit_law_with(Model::Stick, &d, KLaw::C, 0.95, &method) else {
            continue;
        };
        let Some(post) = f.summary.params[0].posterior.clone() else {
            continue;
        };
        fitted += 1;
        hit += usize::from(post.q025 <= 0.5 && 0.5 <= post.q975);
    }
    let rate = hit as f64 / fitted as f64;
    eprintln!("posterior coverage over {fitted} sets: {rate:.3}");
    assert!(fitted >= 98, "{fitted} of 100 sets sampled");
    assert!((0.90..=0.99).contains(&rate), "posterior coverage {rate}");
}

/// A `simulate --design` file in `dir` with the true slopes of `bead_stick.csv` (ξ = 0.8, 1,
/// 1.6; 8 slopes each across 10–90 % of the steady range at c = 0.5), one replicate each.
fn design_file(dir: &std::path::Path) -> std::path::PathBuf {
    let design = dir.join("design.csv");
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/odr/bead_stick.csv"
    );
    let mut reader = csv::Reader::from_path(path).unwrap();
    let h = reader.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (cs, cx, cd) = (col("series"), col("xi"), col("delta_true_deg"));
    let mut text = String::from("series,xi,delta_deg,replicates\n");
    for r in reader.records() {
        let r = r.unwrap();
        text.push_str(&format!("{},{},{},1\n", &r[cs], &r[cx], &r[cd]));
    }
    std::fs::write(&design, text).unwrap();
    design
}

/// A slope recorded 0.6° off (6 σ_δ) is adjusted back and named in the fit's note; a σ_δ wider
/// than a series' steady range of slopes is named too.
#[test]
fn moved_slopes_and_wide_errors_are_named() {
    let mut d = data(0.1);
    d.points[3].scene = d.points[3]
        .scene
        .with_delta_deg(d.points[3].scene.delta_deg() + 0.6)
        .unwrap();
    let fit = fit_law(Model::Stick, &d, KLaw::C, 0.95, false).unwrap();
    let s = &fit.summary;
    let r = s.points[3].delta_residual.unwrap();
    assert!(r < -2.0, "the shifted slope's residual {r}");
    assert!(
        s.stats
            .note
            .contains("1 point(s) whose adjusted slope moved by more than 2 sigma_delta"),
        "{}",
        s.stats.note
    );
    let mut d = data(0.1);
    for p in d.points.iter_mut().filter(|p| p.series == 0) {
        p.sigma_delta = 7f64.to_radians();
    }
    let fit = fit_law(Model::Stick, &d, KLaw::C, 0.95, false).unwrap();
    let note = &fit.summary.stats.note;
    assert!(
        note.contains("sigma_delta 7 deg is wider than its steady range"),
        "{note}"
    );
}

/// `simulate --model stick --law c=0.5 --design DESIGN --noise 0.01 --sigma-delta 0.1 --seed
/// SEED`, read back as the fits read a file.
fn simulated(design: &std::path::Path, seed: u64) -> Dataset {
    use crate::io::measurements::MeasurementFile;
    use crate::models::ModelKind;
    use crate::pipeline::SimulateSettings;
    use crate::scene::CollisionLaw;
    let sim = SimulateSettings {
        model: ModelKind::Stick,
        law: CollisionLaw::C(0.5),
        design: Some(design.to_path_buf()),
        noise: 0.01,
        sigma_delta: 0.1,
        seed,
        ..Default::default()
    };
    let bytes = sim.run().unwrap();
    let file = MeasurementFile::parse("sim", &bytes, &MeasurementDefaults::default()).unwrap();
    file.into_dataset()
}
