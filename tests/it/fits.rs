//! The bead fits (`klaw`, `jan`, `jaeger`) on data simulated with known parameters.
//!
//! * Exactness: on noise-free data the fits return the parameters that made the data. The
//!   reference is the generating value itself, an input of the simulation, not an output of
//!   the code under test.
//! * Recovery and coverage: on 200 replicates with 2 % Gaussian noise (fixed seeds) the 95 %
//!   intervals must cover the truth in a fraction of replicates compatible with 95 %: inside
//!   [0.90, 0.99] (±3.2 binomial standard deviations of 200 draws). The figures are printed
//!   (`cargo test --release --test it fits:: -- --nocapture`).

use fitbead::fit::builder::{JaegerFitter, JanFitter, KLawFitter};
use fitbead::fit::data::Dataset;
use fitbead::fit::klaw::KLaw;
use fitbead::fit::summary::FitSet;
use fitbead::fit::summary::{FitResult, ParamRow};
use fitbead::models::jaeger::Jaeger;
use fitbead::models::jan::Jan;
use fitbead::models::regimes::regime_b_interval;
use fitbead::models::JaegerBranch;
use fitbead::{CollisionLaw, ForwardModel, Model, Scene};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

pub const XIS: [f64; 4] = [0.8, 1.0, 1.6, 2.0];

/// Points spread over 5 %–95 % of [lo, hi] per series, v = v_true (1 + noise z), σ = noise·v_true
/// (σ = 0.01 v_true when noise = 0, so that the fits have weights).
pub fn simulate(
    model_of: impl Fn(f64, f64) -> Model,
    range_of: impl Fn(&Model, f64) -> (f64, f64),
    law: CollisionLaw,
    points: usize,
    noise: f64,
    seed: u64,
) -> Dataset {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut rows = Vec::new();
    for &xi in &XIS {
        let alpha = Scene::new(xi, 1.0, 0.4, 0.1, law).unwrap().alpha_rad();
        let model = model_of(xi, alpha);
        let (lo, hi) = range_of(&model, xi);
        for j in 0..points {
            let d = lo + (hi - lo) * (0.05 + 0.9 * j as f64 / (points - 1) as f64);
            let scene = Scene::from_radians(xi, d, 0.4, 0.1, law).unwrap();
            let v_true = model.evaluate(&scene).unwrap().mean_velocity;
            let z: f64 = StandardNormal.sample(&mut rng);
            let v = v_true * (1.0 + noise * z);
            rows.push((
                format!("{xi}"),
                scene,
                v,
                Some(if noise > 0.0 { noise } else { 0.01 } * v_true),
            ));
        }
    }
    Dataset::new(rows).unwrap()
}

pub fn regime_b(law: CollisionLaw) -> impl Fn(&Model, f64) -> (f64, f64) {
    move |m, xi| regime_b_interval(m, xi, 0.4, 0.1, law).unwrap()
}

/// Onset to onset + 12° (the open-ended models of §5).
pub fn open_range(law: CollisionLaw) -> impl Fn(&Model, f64) -> (f64, f64) {
    move |m, xi| {
        let (lo, _) = regime_b_interval(m, xi, 0.4, 0.1, law).unwrap();
        (lo, lo + 12f64.to_radians())
    }
}

pub fn jan_model(p: [f64; 4]) -> impl Fn(f64, f64) -> Model {
    move |_, alpha| {
        let s = alpha.sin();
        Model::Jan(Jan::new(p[0] * (p[1] * s).exp(), p[2] * (p[3] * s).exp()).unwrap())
    }
}

/// The paper's Fig. 9 values (ξ, a1, a2, a3) of Jaeger's law, Jaeger units.
const PAPER_FIG9: [(f64, f64, f64, f64); 4] = [
    (0.8, 0.19, 3.83, 1.28),
    (1.0, 0.131, 18.57, 1.41),
    (1.6, 0.06, 20.71, 0.8987),
    (2.0, 0.042, 27.67, 0.78),
];

/// Fig. 9's (a1, a2, a3) at ξ, one of its four series.
pub fn paper_values(xi: f64) -> [f64; 3] {
    let r = PAPER_FIG9.iter().find(|r| r.0 == xi).unwrap();
    [r.1, r.2, r.3]
}

pub fn jaeger_model(xi: f64, _alpha: f64) -> Model {
    let p = paper_values(xi);
    Model::Jaeger(Jaeger::new(p[0], p[1], p[2], JaegerBranch::Upper).unwrap())
}

/// The K(α) law `law` under `model`, least squares at 95 %, profile intervals when `profile`.
pub fn fit_law(model: Model, data: &Dataset, law: KLaw, profile: bool) -> FitResult {
    KLawFitter::new(model, law)
        .least_squares(profile)
        .fit(data)
        .unwrap()
}

/// Jan's per-series and global fits, least squares at 95 %.
pub fn fit_jan(data: &Dataset, profile: bool) -> FitSet {
    JanFitter::new().least_squares(profile).fit(data).unwrap()
}

/// Jaeger's per-series fits on the upper root, least squares at 95 %.
pub fn fit_jaeger(data: &Dataset, profile: bool) -> FitSet {
    JaegerFitter::new()
        .branch(JaegerBranch::Upper)
        .least_squares(profile)
        .fit(data)
        .unwrap()
}

fn covers(r: &ParamRow, truth: f64) -> Option<bool> {
    let (ci, _) = r.interval();
    ci.map(|(a, b)| a <= truth && truth <= b)
}

pub const PAPER_JAN: [f64; 4] = [0.063, 4.96, 0.0025, 7.46];

#[test]
fn klaw_c_recovers_the_adjusted_law_from_exact_data() {
    // Stick/slip data made with K = cos 2α + ½ sin²α sin 2α: the fitted c is ½.
    let law = CollisionLaw::Adjusted;
    let ds = simulate(|_, _| Model::StickSlip, regime_b(law), law, 9, 0.0, 1);
    let f = fit_law(Model::StickSlip, &ds, KLaw::C, false);
    assert!(f.stats.converged, "{:?}", f.stats);
    let c = f.params[0].value;
    assert!((c - 0.5).abs() < 1e-9, "c = {c}");
    assert!(f.stats.chi2 < 1e-12, "{}", f.stats.chi2);
}

#[test]
fn klaw_free_recovers_each_series_k_from_exact_data() {
    let law = CollisionLaw::Adjusted;
    let ds = simulate(|_, _| Model::Stick, regime_b(law), law, 7, 0.0, 1);
    let f = fit_law(Model::Stick, &ds, KLaw::FreePerSeries, true);
    assert!(f.stats.converged);
    for (row, &xi) in f.params.iter().zip(&XIS) {
        let s = Scene::new(xi, 1.0, 0.4, 0.1, law).unwrap();
        assert!(
            (row.value - s.k()).abs() < 1e-10,
            "ξ {xi}: {} vs {}",
            row.value,
            s.k()
        );
        assert_eq!(row.series, format!("{xi}"));
    }
}

#[test]
fn klaw_impact_is_scored_with_zero_chi2_on_its_own_data() {
    // Data made with the impact law itself: its χ² is 0 and every point is feasible.
    let law = CollisionLaw::Impact;
    let ds = simulate(|_, _| Model::Stick, regime_b(law), law, 5, 0.0, 1);
    let f = fit_law(Model::Stick, &ds, KLaw::Impact, false);
    assert!(f.params.is_empty());
    assert!(f.stats.chi2 < 1e-20, "{}", f.stats.chi2);
    assert_eq!(f.stats.n_params, 0);
}

#[test]
fn jan_recovers_the_paper_laws_from_exact_data() {
    let law = CollisionLaw::Adjusted;
    let ds = simulate(jan_model(PAPER_JAN), open_range(law), law, 9, 0.0, 1);
    let fits = fit_jan(&ds, false);
    let g = fits.get("jan-global", "all").expect("global fit");
    assert!(g.stats.converged);
    for (row, t) in g.params.iter().zip(PAPER_JAN) {
        assert!(
            (row.value - t).abs() < 1e-8 * t,
            "{}: {} vs {t}",
            row.parameter,
            row.value
        );
        assert_eq!(row.paper_value, Some(t));
    }
    for &xi in &XIS {
        let s = fits.get("jan-series", &format!("{xi}")).unwrap();
        let alpha = Scene::new(xi, 1.0, 0.4, 0.1, law).unwrap().alpha_rad();
        let p = Jan::paper_fit(alpha);
        assert!((s.params[0].value - p.lambda).abs() < 1e-9 * p.lambda);
        assert!((s.params[1].value - p.mu).abs() < 1e-9);
    }
}

#[test]
fn jaeger_recovers_fig_9_values_from_exact_data() {
    let law = CollisionLaw::Adjusted;
    let ds = simulate(jaeger_model, open_range(law), law, 9, 0.0, 1);
    let fits = fit_jaeger(&ds, false);
    for &xi in &XIS {
        let f = fits.get("jaeger", &format!("{xi}")).unwrap();
        let t = paper_values(xi);
        assert!(f.stats.converged, "ξ {xi}: {:?}", f.stats);
        for (row, t) in f.params.iter().zip(t) {
            assert!(
                (row.value - t).abs() < 1e-6 * t,
                "ξ {xi} {}: {} vs {t}",
                row.parameter,
                row.value
            );
        }
    }
}

/// Coverage tally of one parameter: (covered by the reported interval, by the Wald interval,
/// replicates with an interval, replicates).
#[derive(Default, Clone, Copy)]
struct Tally {
    reported: usize,
    wald: usize,
    with_interval: usize,
    total: usize,
    profile_method: usize,
}

impl Tally {
    fn add(&mut self, r: &ParamRow, truth: f64) {
        self.total += 1;
        if let Some(c) = covers(r, truth) {
            self.with_interval += 1;
            self.reported += c as usize;
        }
        if r.interval().1 == "profile" {
            self.profile_method += 1;
        }
        if let Some((a, b)) = r.cov {
            self.wald += (a <= truth && truth <= b) as usize;
        }
    }
    fn rate(&self) -> f64 {
        self.reported as f64 / self.total as f64
    }
    fn print(&self, name: &str) {
        println!(
            "{name:<28} reported {:>5.1} %  wald {:>5.1} %  (profile method {}/{}, no interval {})",
            100.0 * self.rate(),
            100.0 * self.wald as f64 / self.total as f64,
            self.profile_method,
            self.total,
            self.total - self.with_interval
        );
    }
}

const REPLICATES: u64 = 200;
/// ±3.2 binomial standard deviations of 200 draws at p = 0.95.
const COVERAGE_BAND: (f64, f64) = (0.90, 0.99);

fn in_band(t: &Tally) -> bool {
    (COVERAGE_BAND.0..=COVERAGE_BAND.1).contains(&t.rate())
}

#[test]
fn klaw_and_jan_intervals_cover_the_truth_95_percent_of_200_replicates() {
    let law = CollisionLaw::Adjusted;
    let mut c = Tally::default();
    let mut free = [Tally::default(); 4];
    let mut jan = [Tally::default(); 4];
    for seed in 0..REPLICATES {
        let ds = simulate(
            |_, _| Model::StickSlip,
            regime_b(law),
            law,
            9,
            0.02,
            1000 + seed,
        );
        let f = fit_law(Model::StickSlip, &ds, KLaw::C, true);
        c.add(&f.params[0], 0.5);
        let ds = simulate(
            |_, _| Model::Stick,
            regime_b(law),
            law,
            9,
            0.02,
            2000 + seed,
        );
        let f = fit_law(Model::Stick, &ds, KLaw::FreePerSeries, true);
        for (j, &xi) in XIS.iter().enumerate() {
            free[j].add(
                &f.params[j],
                Scene::new(xi, 1.0, 0.4, 0.1, law).unwrap().k(),
            );
        }
        let ds = simulate(
            jan_model(PAPER_JAN),
            open_range(law),
            law,
            9,
            0.02,
            3000 + seed,
        );
        let fits = fit_jan(&ds, true);
        let g = fits.get("jan-global", "all").unwrap();
        for j in 0..4 {
            jan[j].add(&g.params[j], PAPER_JAN[j]);
        }
    }
    c.print("klaw stickslip c");
    for (j, t) in free.iter().enumerate() {
        t.print(&format!("klaw stick K (xi = {})", XIS[j]));
    }
    for (j, t) in jan.iter().enumerate() {
        t.print(&format!("jan global p{j}"));
    }
    for t in std::iter::once(&c).chain(&free).chain(&jan) {
        assert!(
            in_band(t),
            "coverage {} outside {COVERAGE_BAND:?}",
            t.rate()
        );
    }
}

#[test]
fn jaeger_coverage_over_200_replicates() {
    let law = CollisionLaw::Adjusted;
    let mut t = [[Tally::default(); 3]; 4];
    for seed in 0..REPLICATES {
        let ds = simulate(jaeger_model, open_range(law), law, 9, 0.02, 4000 + seed);
        let fits = fit_jaeger(&ds, true);
        for (s, &xi) in XIS.iter().enumerate() {
            let truth = paper_values(xi);
            if let Some(f) = fits.get("jaeger", &format!("{xi}")) {
                for k in 0..3 {
                    t[s][k].add(&f.params[k], truth[k]);
                }
            } else {
                for tk in t[s].iter_mut() {
                    tk.total += 1;
                }
            }
        }
    }
    let mut outside = Vec::new();
    for (s, row) in t.iter().enumerate() {
        for (k, tk) in row.iter().enumerate() {
            tk.print(&format!("jaeger xi = {} a{}", XIS[s], k + 1));
            if !in_band(tk) {
                outside.push((XIS[s], k + 1, tk.rate()));
            }
        }
    }
    // Every parameter in the band: at ξ = 2 a1 (0.042, far below the slopes sampled) once
    // covered 85.5 %, when an edge end on one side of its profile dropped the other end too;
    // with each end decided on its own it covers 92.5 % (docs/ACCURACY.md).
    assert!(
        outside.is_empty(),
        "coverage outside {COVERAGE_BAND:?}: {outside:?}"
    );
}
