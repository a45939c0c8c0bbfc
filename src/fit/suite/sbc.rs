//! Simulation-based calibration (S. Talts, M. Betancourt, D. Simpson, A. Vehtari &
//! A. Gelman, "Validating Bayesian inference algorithms with simulation-based calibration",
//! arXiv:1804.06788, 2018) of the posterior of the K(α) law c with the stick model.
//!
//! For each of 200 replicates (fixed seeds): c is drawn from its prior, uniform on an interval
//! where every point of the design stays in regime B; data are simulated from the stick
//! model with K = cos 2α + c sin²α sin 2α and Gaussian noise of known σ; the posterior is
//! sampled by `fit_law_with(.., Method::Mcmc ..)` with that same prior. If the sampler is
//! right, the rank of the true c among L independent posterior draws is uniform on {0..L}:
//! tested by χ² on 8 bins at the 1 % level. The 90 % central posterior intervals must cover
//! the truth in 85–95 % of the replicates.
//!
//! The draws used for the ranks are 3 per walker, a third of the kept chain apart (the chain
//! is at least 50 autocorrelation times long by the stopping rule, so they are nearly
//! independent): L = 95 of them (3 × 32 − 1, so that the L + 1 = 96 rank values fill 8 bins
//! evenly). Figures: `cargo test --release --lib fit::suite::sbc:: -- --nocapture`.

use crate::fit::data::Dataset;
use crate::fit::klaw::{fit_law_with, KLaw, KLawProblem};
use crate::fit::posterior::{McmcSettings, Method, Prior};
use crate::inverse::mcmc::McmcOptions;
use crate::models::{ForwardModel, Model};
use crate::scene::{CollisionLaw, Scene};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const REPLICATES: usize = 200;
const WALKERS: usize = 32;
const L: usize = 95;
const BINS: usize = 8;
/// χ² quantile 0.99 with 7 degrees of freedom (tables; scipy.stats.chi2.ppf(0.99, 7)).
const CHI2_7_99: f64 = 18.475;
const SIGMA: f64 = 0.01;

/// The design: 3 series, 4 slopes each, spread over the middle of regime B at c = 0.5.
fn design() -> Vec<(String, Scene)> {
    let law = CollisionLaw::C(0.5);
    let mut out = Vec::new();
    for xi in [0.8, 1.2, 1.6] {
        let (lo, hi) =
            crate::models::regimes::regime_b_interval(&Model::Stick, xi, 0.4, 0.1, law).unwrap();
        for j in 0..4 {
            let d = lo + (hi - lo) * (0.3 + 0.4 * j as f64 / 3.0);
            out.push((
                format!("{xi}"),
                Scene::from_radians(xi, d, 0.4, 0.1, law).unwrap(),
            ));
        }
    }
    out
}

fn dataset(design: &[(String, Scene)], c: f64, rng: &mut ChaCha8Rng) -> Dataset {
    Dataset::new(design.iter().map(|(label, s)| {
        let (s2a, c2a) = (2.0 * s.alpha_rad()).sin_cos();
        let k = c2a + c * s.sin_alpha() * s.sin_alpha() * s2a;
        let v = Model::Stick
            .evaluate(&s.with_k(k).unwrap())
            .unwrap()
            .mean_velocity;
        let z: f64 = StandardNormal.sample(rng);
        (label.clone(), *s, v + SIGMA * z, Some(SIGMA))
    }))
    .unwrap()
}

#[test]
fn sbc_klaw_c_stick() {
    let design = design();
    // The prior: uniform on [0.3, 0.7] cut to where every point of the design is steady.
    let probe = dataset(&design, 0.5, &mut ChaCha8Rng::seed_from_u64(0));
    let (blo, bhi) = KLawProblem::new(Model::Stick, &probe, KLaw::C)
        .unwrap()
        .feasible_box()
        .unwrap();
    let (a, b) = (0.3f64.max(blo[0]), 0.7f64.min(bhi[0]));
    assert!(b - a > 0.2, "prior interval [{a}, {b}] too narrow");
    let prior: Prior = format!("uniform({a},{b})").parse().unwrap();
    let mut counts = [0usize; BINS];
    let mut covered = 0;
    let mut converged = 0;
    for i in 0..REPLICATES {
        let mut rng = ChaCha8Rng::seed_from_u64(1000 + i as u64);
        let c_true = rng.random_range(a..b);
        let ds = dataset(&design, c_true, &mut rng);
        let method = Method::Mcmc(Box::new(McmcSettings {
            options: McmcOptions {
                seed: i as u64,
                walkers: Some(WALKERS),
                min_ess: 400.0,
                ..Default::default()
            },
            priors: vec![("c".into(), prior.clone())],
            fit_scatter: false,
            progress: None,
            ..Default::default()
        }));
        let fit = fit_law_with(Model::Stick, &ds, KLaw::C, 0.9, &method).unwrap();
        let s = &fit.summary;
        converged += usize::from(s.stats.converged);
        let (ci, how) = s.params[0].interval();
        assert_eq!(how, "posterior");
        let (lo, hi) = ci.unwrap();
        covered += usize::from(lo <= c_true && c_true <= hi);
        let d = s.draws.as_ref().unwrap();
        let t = d.chains[0].len();
        assert!(t >= 6, "replicate {i}: {t} kept steps");
        let mut picks: Vec<f64> = d
            .chains
            .iter()
            .flat_map(|ch| [ch[t / 6][0], ch[t / 2][0], ch[5 * t / 6][0]])
            .collect();
        picks.truncate(L);
        let rank = picks.iter().filter(|&&x| x < c_true).count();
        counts[rank * BINS / (L + 1)] += 1;
    }
    let expected = REPLICATES as f64 / BINS as f64;
    let chi2: f64 = counts
        .iter()
        .map(|&n| (n as f64 - expected).powi(2) / expected)
        .sum();
    let coverage = covered as f64 / REPLICATES as f64;
    println!(
        "SBC c (stick, {REPLICATES} replicates): rank bins {counts:?}, chi2 {chi2:.2} \
         (1 % critical {CHI2_7_99}), 90 % coverage {coverage:.3}, converged {converged}"
    );
    assert_eq!(
        converged, REPLICATES,
        "every run must meet its stopping rule"
    );
    assert!(
        chi2 < CHI2_7_99,
        "ranks not uniform: {counts:?}, chi2 {chi2}"
    );
    assert!(
        (0.85..=0.95).contains(&coverage),
        "90 % intervals cover {coverage}"
    );
}
