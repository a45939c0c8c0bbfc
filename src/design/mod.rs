//! Optimal experimental design: which slopes to measure, per series, to pin down the
//! parameters of a fit (D and c criteria), or to tell two models apart (T criterion).
//!
//! [`design`] takes [`DesignSettings`] (the fit, the model, the guess of the parameters, the
//! series, the points per series, the noise and the criterion) and returns a
//! [`DesignResult`]: the design as [`DesignRow`]s (series, slope, replicates), the predicted
//! standard error of every parameter at the design and at evenly spaced slopes, and the
//! efficiency of the evenly spaced slopes relative to the design.
//!
//! The method, in order:
//! - **Range.** Per series, regime B of the guess (the slopes where the model at the guess
//!   has a steady state, [`crate::models::regimes::regime_b_interval`]; Jan and Jaeger, whose
//!   range has no upper end, are cut to the onset + 12°), cut to the caller's range if one is
//!   given, then kept a margin away from both ends: the fraction `margin` of its width (5 % by
//!   default, as `fitbead simulate` spreads its points over 5 %–95 % of the range; at least
//!   0.01°, or 5 % if less, so that the difference steps at the ends stay steady) or, with
//!   slope errors, 2σ_δ plus the 1e-4° a slope is rounded to, whichever is wider, so that a
//!   chosen slope off by 2σ_δ is still steady at the guess. No design point lies outside it.
//! - **Candidates.** An even grid of slopes over the range (200 per series), each rounded to
//!   1e-4° as a measured slope is written. At each, v̄ at the guess, its σ (relative noise
//!   σ = noise · v̄, as `simulate --noise`, or absolute) and the gradient ∂v̄/∂p by central
//!   differences (step 1e-4 · max(|p|, 1e-3)), the Jacobian of the weighted least-squares
//!   problem the fits solve.
//! - **Slope errors** (`sigma_delta` σ_δ > 0): a slope set with error σ_δ moves v̄ by about
//!   (∂v̄/∂δ) σ_δ, so each candidate's variance is the effective variance
//!   σ² = σ_v² + (∂v̄/∂δ)² σ_δ² (Orear 1982), ∂v̄/∂δ by a central difference in
//!   δ (radians, step 1e-4 · δ) at the guess, or at each prior draw for a Bayesian design. The
//!   weighted least squares with this variance is what the ODR fits of such data
//!   ([`crate::inverse::odr`]) solve to first order, and it enters every criterion and every
//!   predicted standard error. Near the ends of regime B v̄ changes steeply with δ (near δ_m,
//!   eq 32, the bead crawls over the top) and the slope term dominates σ²: where ∂v̄/∂p grows
//!   less steeply the design moves inward. Near δ_m of a K-law fit both grow in the ratio
//!   ∂δ_m/∂p, so the information of a point tends to (∂δ_m/∂p)²/σ_δ² instead of falling,
//!   and a c-optimal design may stay at the lower end of its range, 2σ_δ or the margin
//!   inside it. A prior draw at which a difference in δ leaves the steady state gives the
//!   candidate no information, as a draw at which it is not steady.
//! - **Fisher information** of n_j points at each candidate: M = Σ n_j g_j g_jᵀ with
//!   g = (∂v̄/∂p)/σ; the predicted covariance of the least-squares estimate is M⁻¹.
//! - **Criteria.** D: maximise log det M; c: minimise (M⁻¹)_kk of the target parameter k; T:
//!   maximise min_θ Σ n_j (v̄_A(δ_j) − v̄_B(δ_j; θ))²/σ_j², model A at the guess and its rival B
//!   fitted to A's curve (Atkinson & Fedorov 1975).
//! - **Approximate design** over the grid, points per series fixed: the multiplicative
//!   algorithm for D and c (Titterington 1976; Silvey, Titterington & Torsney 1978), the
//!   Atkinson–Fedorov iteration for T. The equivalence theorem (Kiefer & Wolfowitz 1960,
//!   stratum by stratum) gives the stopping rule and the reported gap.
//! - **Exact design**: neighbouring grid points that carry weight merge into one slope, and
//!   the weights round to whole points by efficient rounding (Pukelsheim & Rieder 1992).
//!
//! The summary gives, per chosen slope, the range of each parameter (the others at the guess)
//! over which the slope stays in regime B: how far the guess may be off before the bead stops
//! or jumps there.
//!
//! For T, the points needed are those, in the design's proportions, at which the
//! noncentrality λ = N · T/N_design of the one-degree-of-freedom χ² test of B reaches
//! (z_{1−α/2} + z_{power})² (significance α = 0.05, power 0.8: λ ≈ 7.85).
//!
//! Extensions:
//! - **Total budget** (`total`): one stratum over every candidate of every series, its
//!   weights adding up to the total; the design decides the points per series.
//! - **Bayesian designs** (`priors`): D and c averaged over `draws` seeded draws from the
//!   priors (E[log det M], E[cᵀ M⁻¹ c]; Chaloner & Verdinelli 1995), each draw with its own
//!   gradients (zero at a slope not steady at that draw); a draw leaving a series no steady
//!   candidate is redrawn. The rounded design is then improved by point exchange (Fedorov
//!   1972) on the averaged criterion. Standard errors are the root of the mean variance
//!   over the draws.
//! - **μ of eq 79** as a c target of the K-law fits: c = ∇μ_s, the delta method.
//! - **Jaeger against Jan** (T): Jan's fitted to Jaeger's curve. The reverse is refused: Jan's
//!   eq 74 is Jaeger's eq 80 with a2 = 0, so T = 0 at every design.

mod optimal;
mod problem;
mod text;

use crate::inverse::posterior::Prior;
use crate::models::{JaegerBranch, ModelKind};
use crate::numfmt::{fmt_f64, fmt_sig};
use crate::scene::CollisionLaw;
use optimal::{information, variance_of, variances, Approx, Cand, Crit, Draw};
use problem::Problem;
use std::fmt;

/// The fit a design is made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignFit {
    /// A K(α) law under a contact model: c of K = cos 2α + c sin²α sin 2α (`law` c=VALUE), or
    /// one K per series (`law` a number).
    KLaw,
    /// Jan's eq 74: λ and μ at one ξ, or the laws λ0, λ1, μ0, μ1 (eqs 75–76) across series;
    /// the guess is the paper's eqs 75–76.
    Jan,
    /// Jaeger's a1, a2, a3 per series (eqs 80–84); the guess is the paper's Fig. 9 values.
    Jaeger,
}

impl std::str::FromStr for DesignFit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "klaw" => Ok(DesignFit::KLaw),
            "jan" => Ok(DesignFit::Jan),
            "jaeger" => Ok(DesignFit::Jaeger),
            _ => Err(format!(
                "unknown fit '{}': expected klaw, jan or jaeger",
                crate::numfmt::clip(s, crate::numfmt::ECHO_CHARS)
            )),
        }
    }
}

/// The optimality criterion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Criterion {
    /// D-optimal: the largest det M (smallest joint confidence region).
    D,
    /// c-optimal: the smallest variance of one target parameter.
    C,
    /// T-optimal: the largest distance between the model and its rival fitted to it.
    T,
}

impl std::str::FromStr for Criterion {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "d" => Ok(Criterion::D),
            "c" => Ok(Criterion::C),
            "t" => Ok(Criterion::T),
            _ => Err(format!(
                "unknown criterion '{}': expected d, c or t",
                crate::numfmt::clip(s, crate::numfmt::ECHO_CHARS)
            )),
        }
    }
}

/// What [`design`] needs.
#[derive(Debug, Clone)]
pub struct DesignSettings {
    /// The fit.
    pub fit: DesignFit,
    /// The model the data follow: a contact model for [`DesignFit::KLaw`] (stickslip when
    /// `None`); `None`, jan or jaeger for the other fits.
    pub model: Option<ModelKind>,
    /// For [`DesignFit::KLaw`], the fitted law with its guess: `CollisionLaw::C(c)` or a
    /// number K (one K per series).
    pub law: CollisionLaw,
    /// Radius ratios ξ of the series.
    pub series: Vec<f64>,
    /// Gyration parameter ρ.
    pub rho: f64,
    /// Friction coefficient f.
    pub f: f64,
    /// Points per series.
    pub points: usize,
    /// Noise: relative (σ = noise · v̄) unless `noise_absolute`.
    pub noise: f64,
    /// Whether `noise` is an absolute σ of v̄ (dimensionless).
    pub noise_absolute: bool,
    /// Slopes LO, HI in degrees, cut to regime B of the guess.
    pub delta_range: Option<(f64, f64)>,
    /// The criterion.
    pub criterion: Criterion,
    /// The target parameter of [`Criterion::C`] (needed when the fit has several).
    pub target: Option<String>,
    /// The rival model of [`Criterion::T`] (a contact model, its law's parameter fitted).
    pub vs: Option<ModelKind>,
    /// The root of eq 84 for [`DesignFit::Jaeger`].
    pub branch: JaegerBranch,
    /// Candidate slopes per series.
    pub grid: usize,
    /// Priors of parameters, by name, for a Bayesian design (the criterion averaged over
    /// draws from them; the parameters without one stay at the guess). Empty: a locally
    /// optimal design at the guess.
    pub priors: Vec<(String, Prior)>,
    /// Prior draws a Bayesian design averages over.
    pub draws: usize,
    /// Seed of the prior draws.
    pub seed: u64,
    /// Points over all series, shared out by the design (`points` is then unused); `None`:
    /// `points` per series.
    pub total: Option<usize>,
    /// Standard uncertainty σ_δ of a set slope, degrees (≥ 0 and < 90): each point's variance
    /// becomes σ_v² + (∂v̄/∂δ)² σ_δ², and the range keeps at least 2σ_δ from its ends. 0:
    /// slopes exact.
    pub sigma_delta: f64,
    /// The fraction of the range's width kept from each of its ends (0 ≤ margin < 0.5;
    /// default 0.05, the 5 %–95 % over which `simulate` spreads its points).
    pub margin: f64,
}

impl Default for DesignSettings {
    /// K-law c = 0.5 under stick/slip, the paper's four ξ, 9 points per series, 2 % noise,
    /// exact slopes, ranges kept 5 % of their width from their ends, D, locally optimal (64
    /// draws, seed 1, should priors be added).
    fn default() -> Self {
        DesignSettings {
            fit: DesignFit::KLaw,
            model: None,
            law: CollisionLaw::C(0.5),
            series: vec![0.8, 1.0, 1.6, 2.0],
            rho: 0.4,
            f: 0.1,
            points: 9,
            noise: 0.02,
            noise_absolute: false,
            delta_range: None,
            criterion: Criterion::D,
            target: None,
            vs: None,
            branch: JaegerBranch::Upper,
            grid: 200,
            priors: Vec::new(),
            draws: DEFAULT_DRAWS,
            seed: 1,
            total: None,
            sigma_delta: 0.0,
            margin: DEFAULT_MARGIN,
        }
    }
}

/// One slope of a design.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignRow {
    /// Series label (its ξ, as `simulate` labels series).
    pub series: String,
    /// Radius ratio ξ.
    pub xi: f64,
    /// Slope, degrees (rounded to 1e-4°).
    pub delta_deg: f64,
    /// Points to measure at this slope.
    pub replicates: usize,
}

/// The predicted standard error of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictedError {
    /// Parameter name, as the fit names it.
    pub name: String,
    /// Its guess.
    pub guess: f64,
    /// Standard error at the design (`None`: the design does not determine it).
    pub design: Option<f64>,
    /// Standard error at evenly spaced slopes, same points and range.
    pub even: Option<f64>,
}

/// A design and what it is predicted to achieve.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignResult {
    /// The design, series by series, slopes increasing.
    pub rows: Vec<DesignRow>,
    /// Evenly spaced slopes over the same ranges, the same points per series.
    pub even: Vec<DesignRow>,
    /// The slope range of each series, degrees.
    pub ranges: Vec<(f64, f64)>,
    /// Predicted standard errors of every parameter.
    pub errors: Vec<PredictedError>,
    /// The criterion's target parameter (c), if any.
    pub target: Option<String>,
    /// Efficiency of the evenly spaced slopes relative to the design: D,
    /// (det M_even/det M)^{1/p}; c, Var/Var_even; T, T_even/T.
    pub efficiency: f64,
    /// Equivalence gap of the approximate design (max ψ/λ − 1; 0 at the optimum).
    pub gap: f64,
    /// T: the criterion min_θ Σ (v̄_A − v̄_B(θ))²/σ² at the design and at evenly spaced
    /// slopes (the noncentrality of the test of B).
    pub discrimination: Option<(f64, f64)>,
    /// T: the points needed, in all, for the test of B to reach power 0.8 at significance
    /// 0.05, at the design's proportions and at evenly spaced slopes (+∞ where the two models
    /// agree at every slope of the design).
    pub points_needed: Option<(f64, f64)>,
    /// What each candidate slope contributes, per series: (slope in degrees, sensitivity
    /// ψ/λ of the approximate design; 1 on its support at the optimum).
    pub sensitivity: Vec<Vec<(f64, f64)>>,
    /// What the sensitivity is (for the figure's axis).
    pub sensitivity_label: String,
    /// A Bayesian design: the prior draws the criterion was averaged over, and the draws
    /// redrawn because some series had no steady slope in its range there (or, for a μ
    /// target, K left (0, 1)); `None` for a locally optimal design.
    pub bayes: Option<(usize, usize)>,
    /// Per row of `rows`, the range of each parameter that moves its series over which its
    /// slope stays steady (in regime B), the others at the guess: (name, low, high), an end
    /// `None` where the steady state holds to the end of the parameter's domain.
    #[allow(clippy::type_complexity)]
    pub steady: Vec<Vec<(String, Option<f64>, Option<f64>)>>,
}

/// A setting [`design`] cannot work with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DesignError {
    /// The setting (as the command line names it, without dashes: `series`, `law`, …).
    pub setting: &'static str,
    /// The offending value.
    pub value: String,
    /// What is wrong.
    pub message: String,
}

impl DesignError {
    pub(crate) fn new(setting: &'static str, value: &str, message: impl Into<String>) -> Self {
        DesignError {
            setting,
            value: value.to_string(),
            message: message.into(),
        }
    }
}

impl fmt::Display for DesignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = '{}': {}", self.setting, self.value, self.message)
    }
}

impl std::error::Error for DesignError {}

/// The fraction of a range's width kept from each end unless told otherwise.
const DEFAULT_MARGIN: f64 = 0.05;
/// The least a range keeps from its ends, degrees (unless 5 % of its width is less).
const MIN_KEPT_DEG: f64 = 0.01;
/// The step slopes are rounded to, degrees.
const SLOPE_STEP_DEG: f64 = 1e-4;

/// Most points per series.
const MAX_POINTS: usize = 100_000;
/// Prior draws of a Bayesian design unless told otherwise.
const DEFAULT_DRAWS: usize = 64;
/// Most prior draws.
const MAX_DRAWS: usize = 10_000;
/// Draws tried per draw kept before a prior is refused as leaving no steady slope.
const TRIES_PER_DRAW: usize = 20;
/// Steps of the Atkinson–Fedorov iteration.
const T_STEPS: usize = 150;

/// The target of the c criterion: a parameter, or μ of eq 79 of a series (K-law fits).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    Param(usize),
    Mu(usize),
}

/// The optimal design for `s` (see the module docs for the method), in stages: the problem
/// and its candidate slopes, the draws the criterion is averaged over, the approximate
/// design and its rounding to points, then the comparison with evenly spaced slopes.
pub fn design(s: &DesignSettings) -> Result<DesignResult, DesignError> {
    check(s)?;
    let model = design_model(s)?;
    let prob = problem::problem(s.fit, model, s.law, &s.series, s.rho, s.f, s.branch)?;
    let p = prob.names.len();
    let priors = prior_indices(s, &prob)?;
    let rival_prob = match s.criterion {
        Criterion::T => Some(rival(s, &prob)?),
        _ => None,
    };
    let ranges = ranges(s, &prob, rival_prob.as_ref())?;
    let (cands, strata) = candidate_grid(s, &prob, &ranges)?;
    let n_series = s.series.len();
    // Points per series of the evenly spaced design (the budget shared out as evenly as it
    // goes under a total).
    let even_counts: Vec<usize> = match s.total {
        None => vec![s.points; n_series],
        Some(n) => (0..n_series)
            .map(|k| n / n_series + usize::from(k < n % n_series))
            .collect(),
    };
    let total_points: usize = even_counts.iter().sum();
    let target = match s.criterion {
        Criterion::C => Some(target_index(s, &prob)?),
        _ => None,
    };
    let even_cands = even_design(s, &prob, &ranges, &even_counts)?;
    let ones = vec![1.0; even_cands.len()];
    // The draws the criterion is averaged over: the guess alone, or draws from the priors.
    let target_c = |theta: &[f64]| -> Option<Vec<f64>> {
        match target {
            Some(Target::Mu(k)) => prob.mu_gradient(k, theta),
            Some(Target::Param(k)) => {
                let mut c = vec![0.0; p];
                c[k] = 1.0;
                Some(c)
            }
            None => Some(vec![0.0; p]),
        }
    };
    let (draws, even_draws, bayes) = if priors.is_empty() {
        let (d, e) = guess_draws(s, target_c(&prob.guess), &cands, &even_cands)?;
        (d, e, None)
    } else {
        let (d, e, redrawn) =
            prior_draws(s, &prob, &priors, &cands, &strata, &even_cands, &target_c)?;
        let n = d.len();
        (d, e, Some((n, redrawn)))
    };
    let series_of: Vec<usize> = cands.iter().map(|c| c.series).collect();
    let Approximate {
        approx,
        sens_label,
        rival,
        strata,
        alg,
    } = approximate(s, &prob, &draws, &cands, strata, target)?;
    let counts: Vec<usize> = alg.1.iter().map(|&n| n as usize).collect();
    let exact = optimal::round(&alg.0, &counts, &approx, &series_of);
    // A Bayesian design's exact slopes are improved on the averaged criterion itself.
    let exact = match (bayes, s.criterion) {
        (Some(_), Criterion::D) => optimal::exchange(&draws, &alg.0, &exact, p, Crit::D),
        (Some(_), Criterion::C) => optimal::exchange(&draws, &alg.0, &exact, p, Crit::C),
        _ => exact,
    };
    let (w, rows) = exact_rows(s, &cands, &exact);
    let steady = exact
        .iter()
        .flatten()
        .map(|&(j, _)| steady_ranges(&prob, &cands[j]))
        .collect();
    let even: Vec<DesignRow> = even_cands
        .iter()
        .map(|c| row(s.series[c.series], c.delta, 1))
        .collect();
    let (cmp, errors) = Comparison::new(&prob, target, (&draws, &w), (&even_draws, &ones));
    let mut discrimination = None;
    let mut points_needed = None;
    let efficiency = match s.criterion {
        Criterion::T => {
            let rival = rival.expect("t has a rival");
            let (t, needed) =
                discriminate(s, &prob, &rival, &cands, &exact, &even_cands, total_points);
            discrimination = Some(t);
            points_needed = Some(needed);
            t.1 / t.0
        }
        Criterion::D => cmp.d_efficiency(bayes.is_some(), p),
        Criterion::C => cmp.c_efficiency(target.expect("c has a target")),
    };
    let sensitivity = strata
        .iter()
        .map(|st| {
            st.iter()
                .map(|&j| (cands[j].delta.to_degrees(), approx.sens[j]))
                .collect()
        })
        .collect();
    let mut result = DesignResult {
        rows,
        even,
        ranges: ranges
            .iter()
            .map(|r| (r.0.to_degrees(), r.1.to_degrees()))
            .collect(),
        errors,
        target: target.map(|k| target_label(&prob, k)),
        efficiency,
        gap: approx.gap,
        discrimination,
        points_needed,
        sensitivity,
        sensitivity_label: sens_label,
        bayes,
        steady,
    };
    scale_to_noise(s, &mut result);
    Ok(result)
}

/// The forward model a design's fit is made with: the contact model `s.model` names for
/// the K-law fits (stick-slip by default); Jan's and Jaeger's fits have their own.
fn design_model(s: &DesignSettings) -> Result<crate::models::Model, DesignError> {
    Ok(match (s.fit, s.model) {
        (DesignFit::KLaw, m) => {
            let kind = m.unwrap_or(ModelKind::StickSlip);
            kind.contact_model().ok_or_else(|| {
                DesignError::new(
                    "model",
                    &kind_name(kind),
                    "the K-law fits need a contact model (stick, stick-approx, slip, \
                     slip-approx, stickslip, contact or auto)",
                )
            })?
        }
        (DesignFit::Jan, None | Some(ModelKind::Jan))
        | (DesignFit::Jaeger, None | Some(ModelKind::Jaeger)) => crate::models::Model::StickSlip,
        (fit, Some(kind)) => {
            return Err(DesignError::new(
                "model",
                &kind_name(kind),
                format!(
                    "the {} fit has its own model: leave --model out",
                    match fit {
                        DesignFit::Jan => "jan",
                        _ => "jaeger",
                    }
                ),
            ))
        }
    })
}

/// The candidate slopes at the guess: `s.grid` slopes evenly over each series' range, those
/// with a steady state kept, and the strata (the candidates of each series, as indices).
fn candidate_grid(
    s: &DesignSettings,
    prob: &Problem,
    ranges: &[(f64, f64)],
) -> Result<(Vec<Cand>, Vec<Vec<usize>>), DesignError> {
    let mut cands = Vec::new();
    let mut strata: Vec<Vec<usize>> = Vec::new();
    for (k, &(lo, hi)) in ranges.iter().enumerate() {
        let mut st = Vec::new();
        for i in 0..s.grid {
            let d = round_deg(lo + (hi - lo) * i as f64 / (s.grid - 1) as f64);
            if let Some(c) = candidate(s, prob, k, d) {
                st.push(cands.len());
                cands.push(c);
            }
        }
        if st.is_empty() {
            return Err(no_range(
                s.series[k],
                "no slope of its range has a steady state",
            ));
        }
        strata.push(st);
    }
    Ok((cands, strata))
}

/// The evenly spaced comparison design: `counts[k]` slopes evenly over series k's range
/// (its middle for one), each of which must have a steady state.
fn even_design(
    s: &DesignSettings,
    prob: &Problem,
    ranges: &[(f64, f64)],
    counts: &[usize],
) -> Result<Vec<Cand>, DesignError> {
    let mut even_cands = Vec::new();
    for (k, &(lo, hi)) in ranges.iter().enumerate() {
        let m = counts[k];
        for j in 0..m {
            let frac = if m == 1 {
                0.5
            } else {
                j as f64 / (m - 1) as f64
            };
            let d = round_deg(lo + (hi - lo) * frac);
            let c = candidate(s, prob, k, d).ok_or_else(|| {
                no_range(s.series[k], "an evenly spaced slope has no steady state")
            })?;
            even_cands.push(c);
        }
    }
    Ok(even_cands)
}

/// The name of a criterion's target: the parameter's, or μ's of its series.
fn target_label(prob: &Problem, k: Target) -> String {
    match k {
        Target::Param(k) => prob.names[k].clone(),
        Target::Mu(k) => prob.mu_names()[k].clone(),
    }
}

/// An approximate design with what goes with it.
struct Approximate {
    /// The design.
    approx: Approx,
    /// What its sensitivity is.
    sens_label: String,
    /// The rival model of a T design.
    rival: Option<Problem>,
    /// The candidates of every series taking part.
    strata: Vec<Vec<usize>>,
    /// The strata and budgets of the algorithm (see [`algorithm_strata`]).
    alg: (Vec<Vec<usize>>, Vec<f64>),
}

/// The approximate design of `s.criterion` on the candidates `cands` in `strata`.
fn approximate(
    s: &DesignSettings,
    prob: &Problem,
    draws: &[Draw],
    cands: &[Cand],
    strata: Vec<Vec<usize>>,
    target: Option<Target>,
) -> Result<Approximate, DesignError> {
    let p = prob.names.len();
    Ok(match s.criterion {
        Criterion::D => {
            let alg = algorithm_strata(s, &strata);
            Approximate {
                approx: optimal::multiplicative(draws, &alg.0, &alg.1, p, Crit::D),
                sens_label: "standardised variance d/λ (D)".to_string(),
                rival: None,
                strata,
                alg,
            }
        }
        Criterion::C => {
            let k = target.expect("c has a target");
            let alg = algorithm_strata(s, &strata);
            Approximate {
                approx: optimal::multiplicative(draws, &alg.0, &alg.1, p, Crit::C),
                sens_label: format!("information on {} ψ/λ (c)", target_label(prob, k)),
                rival: None,
                strata,
                alg,
            }
        }
        Criterion::T => {
            let (a, rival, st, alg) = t_design(s, prob, cands, &strata)?;
            Approximate {
                approx: a,
                sens_label: "squared distance to the rival ψ/λ (T)".to_string(),
                rival: Some(rival),
                strata: st,
                alg,
            }
        }
    })
}

/// The rows of an exact design (candidate, replicates per stratum) and its weights on the
/// candidates.
fn exact_rows(
    s: &DesignSettings,
    cands: &[Cand],
    exact: &[Vec<(usize, usize)>],
) -> (Vec<f64>, Vec<DesignRow>) {
    let mut w = vec![0.0; cands.len()];
    let mut rows = Vec::new();
    for st in exact {
        for &(j, n) in st {
            w[j] = n as f64;
            let c = &cands[j];
            rows.push(row(s.series[c.series], c.delta, n));
        }
    }
    (w, rows)
}

/// The range of each parameter that moves the series of candidate `c` over which its slope
/// stays steady, the others at the guess ([`Problem::steady_range`]).
fn steady_ranges(prob: &Problem, c: &Cand) -> Vec<(String, Option<f64>, Option<f64>)> {
    (0..prob.names.len())
        .filter(|&j| prob.touches(c.series, j))
        .filter_map(|j| {
            let (lo, hi) = prob.steady_range(c.series, c.delta, j)?;
            Some((prob.names[j].clone(), lo, hi))
        })
        .collect()
}

/// A variance averaged over the draws (the expected posterior variance of a Bayesian
/// design): `f` of every draw's information matrix; undetermined where any draw leaves it
/// undetermined.
fn mean_var(
    ms: &[nalgebra::DMatrix<f64>],
    f: &dyn Fn(usize, &nalgebra::DMatrix<f64>) -> Option<f64>,
) -> Option<f64> {
    let mut sum = 0.0;
    for (i, m) in ms.iter().enumerate() {
        sum += f(i, m)?;
    }
    Some(sum / ms.len() as f64)
}

/// The design and the evenly spaced slopes compared: their information matrices at every
/// draw and the variances they predict.
struct Comparison {
    /// The design's information matrix at every draw.
    m_design: Vec<nalgebra::DMatrix<f64>>,
    /// The evenly spaced slopes' information matrix at every draw.
    m_even: Vec<nalgebra::DMatrix<f64>>,
    /// Every parameter's variance at the design, averaged over the draws.
    v_design: Vec<Option<f64>>,
    /// Every parameter's variance at the evenly spaced slopes, averaged over the draws.
    v_even: Vec<Option<f64>>,
    /// A μ target's variance at the design and at the evenly spaced slopes.
    mu_var: Option<(Option<f64>, Option<f64>)>,
}

impl Comparison {
    /// The comparison of the design (its draws and weights on the candidates) with the
    /// evenly spaced slopes (theirs), and the predicted standard errors of every parameter
    /// and of a μ target.
    fn new(
        prob: &Problem,
        target: Option<Target>,
        (draws, w): (&[Draw], &[f64]),
        (even_draws, ones): (&[Draw], &[f64]),
    ) -> (Self, Vec<PredictedError>) {
        let p = prob.names.len();
        let m_design: Vec<_> = draws.iter().map(|d| information(&d.cands, w, p)).collect();
        let m_even: Vec<_> = even_draws
            .iter()
            .map(|d| information(&d.cands, ones, p))
            .collect();
        let vd: Vec<Vec<Option<f64>>> = m_design.iter().map(variances).collect();
        let ve: Vec<Vec<Option<f64>>> = m_even.iter().map(variances).collect();
        let v_design: Vec<Option<f64>> = (0..p)
            .map(|k| mean_var(&m_design, &|i, _| vd[i][k]))
            .collect();
        let v_even: Vec<Option<f64>> = (0..p)
            .map(|k| mean_var(&m_even, &|i, _| ve[i][k]))
            .collect();
        let mut errors: Vec<PredictedError> = (0..p)
            .map(|k| PredictedError {
                name: prob.names[k].clone(),
                guess: prob.guess[k],
                design: v_design[k].map(f64::sqrt),
                even: v_even[k].map(f64::sqrt),
            })
            .collect();
        let mut mu_var = None;
        if let Some(Target::Mu(k)) = target {
            let vd = mean_var(&m_design, &|i, m| variance_of(m, &draws[i].c));
            let ve = mean_var(&m_even, &|i, m| variance_of(m, &even_draws[i].c));
            mu_var = Some((vd, ve));
            errors.push(PredictedError {
                name: target_label(prob, Target::Mu(k)),
                guess: prob.mu(k, &prob.guess).unwrap_or(f64::NAN),
                design: vd.map(f64::sqrt),
                even: ve.map(f64::sqrt),
            });
        }
        let cmp = Comparison {
            m_design,
            m_even,
            v_design,
            v_even,
            mu_var,
        };
        (cmp, errors)
    }

    /// The D efficiency of the evenly spaced slopes relative to the design,
    /// (det M_even/det M)^{1/p}; of a Bayesian design, exp(E[log det M_even] −
    /// E[log det M])^{1/p}.
    fn d_efficiency(&self, bayes: bool, p: usize) -> f64 {
        let (m_design, m_even) = (&self.m_design, &self.m_even);
        if !bayes {
            let (a, b) = (m_even[0].determinant(), m_design[0].determinant());
            if b > 0.0 {
                (a.max(0.0) / b).powf(1.0 / p as f64)
            } else {
                f64::NAN
            }
        } else {
            let mut sum = 0.0;
            for (a, b) in m_even.iter().zip(m_design) {
                let (a, b) = (a.determinant(), b.determinant());
                sum += if b > 0.0 && a > 0.0 {
                    (a / b).ln()
                } else if b > 0.0 {
                    f64::NEG_INFINITY
                } else {
                    f64::NAN
                };
            }
            (sum / (m_design.len() * p) as f64).exp()
        }
    }

    /// The c efficiency of the evenly spaced slopes relative to the design: the target's
    /// Var/Var_even.
    fn c_efficiency(&self, target: Target) -> f64 {
        let (vd, ve) = match target {
            Target::Param(k) => (self.v_design[k], self.v_even[k]),
            Target::Mu(_) => self.mu_var.expect("a μ target has its variances"),
        };
        match (vd, ve) {
            (Some(a), Some(b)) => a / b,
            (Some(_), None) => 0.0,
            _ => f64::NAN,
        }
    }
}

/// The strata and budgets of the approximate design: one stratum per series with `points`
/// each, or, under a total, one stratum of every candidate with the total.
fn algorithm_strata(s: &DesignSettings, strata: &[Vec<usize>]) -> (Vec<Vec<usize>>, Vec<f64>) {
    match s.total {
        None => (strata.to_vec(), vec![s.points as f64; strata.len()]),
        Some(n) => (vec![strata.concat()], vec![n as f64]),
    }
}

/// The index of each prior's parameter, checked: a known name, given once, a proper prior.
fn prior_indices(s: &DesignSettings, prob: &Problem) -> Result<Vec<(usize, Prior)>, DesignError> {
    let mut out: Vec<(usize, Prior)> = Vec::new();
    for (name, prior) in &s.priors {
        let text = format!("{name}={prior}");
        let k = prob.names.iter().position(|n| n == name).ok_or_else(|| {
            DesignError::new(
                "prior",
                &text,
                format!(
                    "no parameter '{name}' in this fit; expected one of {}",
                    prob.names.join(", ")
                ),
            )
        })?;
        if out.iter().any(|(j, _)| *j == k) {
            return Err(DesignError::new(
                "prior",
                &text,
                "a second prior of the same parameter",
            ));
        }
        if prior.draw(0.0, 0.5).is_none() {
            return Err(DesignError::new(
                "prior",
                &text,
                "a Bayesian design draws from the prior: flat and jeffreys are improper; \
                 give uniform(a,b), normal(mean,sd), lognormal(mu,sigma) or halfnormal(scale)",
            ));
        }
        out.push((k, prior.clone()));
    }
    Ok(out)
}

/// The draws of a Bayesian design: `s.draws` parameter vectors from the priors (the other
/// parameters at the guess), each with the candidates' and the evenly spaced slopes' scaled
/// gradients there (zero at a slope where that draw has no steady state) and the target's
/// gradient. A draw that leaves a series no steady candidate in its range (or, for a μ
/// target, puts K outside (0, 1)) is redrawn: the prior is cut to the parameters where every
/// series has a steady slope in its range, as the fits cut theirs to the feasible region.
/// Returns the draws, the evenly spaced slopes' draws and the number redrawn.
#[allow(clippy::too_many_arguments)]
fn prior_draws(
    s: &DesignSettings,
    prob: &Problem,
    priors: &[(usize, Prior)],
    cands: &[Cand],
    strata: &[Vec<usize>],
    even_cands: &[Cand],
    target_c: &(dyn Fn(&[f64]) -> Option<Vec<f64>> + Sync),
) -> Result<(Vec<Draw>, Vec<Draw>, usize), DesignError> {
    use rand::{Rng, SeedableRng};
    use rand_distr::{Distribution, StandardNormal};
    use rayon::prelude::*;
    // A candidate at a draw, and whether that draw is steady there.
    let at = |theta: &[f64], c: &Cand| -> (Cand, bool) {
        let g = prob.velocity(c.series, c.delta, theta).and_then(|v| {
            let sg = effective_sigma(s, prob, c.series, c.delta, theta, v)?;
            prob.gradient_at(c.series, c.delta, theta)
                .map(|g| (g.iter().map(|x| x / sg).collect::<Vec<f64>>(), sg))
        });
        let steady = g.is_some();
        let (g, sg) = g.unwrap_or_else(|| (vec![0.0; theta.len()], f64::INFINITY));
        let c = Cand {
            series: c.series,
            delta: c.delta,
            g,
            sigma: sg,
        };
        (c, steady)
    };
    let build = |theta: &Vec<f64>| -> Option<(Draw, Draw)> {
        let c = target_c(theta)?;
        let (d, steady): (Vec<Cand>, Vec<bool>) = cands.iter().map(|x| at(theta, x)).unzip();
        if !strata.iter().all(|st| st.iter().any(|&j| steady[j])) {
            return None;
        }
        let e: Vec<Cand> = even_cands.iter().map(|x| at(theta, x).0).collect();
        Some((
            Draw {
                cands: d,
                c: c.clone(),
            },
            Draw { cands: e, c },
        ))
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s.seed);
    let (mut kept, mut even, mut redrawn, mut tried) = (Vec::new(), Vec::new(), 0, 0);
    while kept.len() < s.draws {
        let need = s.draws - kept.len();
        if tried + need > TRIES_PER_DRAW * s.draws {
            let text: Vec<String> = s.priors.iter().map(|(n, p)| format!("{n}={p}")).collect();
            return Err(DesignError::new(
                "prior",
                &text.join(" "),
                format!(
                    "{redrawn} of {tried} draws leave a series no steady slope in its range \
                     (or K outside (0, 1)): narrow the prior or the series"
                ),
            ));
        }
        let batch: Vec<Vec<f64>> = (0..need)
            .map(|_| {
                let mut theta = prob.guess.clone();
                for (k, prior) in priors {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    let u: f64 = rng.random();
                    theta[*k] = prior.draw(z, u).expect("a proper prior");
                }
                theta
            })
            .collect();
        tried += need;
        let built: Vec<Option<(Draw, Draw)>> = batch.par_iter().map(build).collect();
        for b in built {
            match b {
                Some((d, e)) => {
                    kept.push(d);
                    even.push(e);
                }
                None => redrawn += 1,
            }
        }
    }
    Ok((kept, even, redrawn))
}

/// The settings' own checks.
fn check(s: &DesignSettings) -> Result<(), DesignError> {
    if s.series.is_empty() {
        return Err(DesignError::new("series", "", "no series given"));
    }
    for (j, &x) in s.series.iter().enumerate() {
        if !(x.is_finite() && x > 0.0) {
            return Err(DesignError::new(
                "series",
                &fmt_f64(x),
                "a radius ratio must be finite and > 0",
            ));
        }
        if s.series[..j].contains(&x) {
            return Err(DesignError::new(
                "series",
                &fmt_f64(x),
                "xi is given twice: each series needs its own xi",
            ));
        }
    }
    if let Some(n) = s.total {
        if n < s.series.len() || n > MAX_POINTS {
            return Err(DesignError::new(
                "total",
                &n.to_string(),
                format!(
                    "expected {} (one point per series) to {MAX_POINTS} points in all",
                    s.series.len()
                ),
            ));
        }
    }
    if !s.priors.is_empty() && (s.draws == 0 || s.draws > MAX_DRAWS) {
        return Err(DesignError::new(
            "draws",
            &s.draws.to_string(),
            format!("expected 1 to {MAX_DRAWS} prior draws"),
        ));
    }
    if !s.priors.is_empty() && s.criterion == Criterion::T {
        let text: Vec<String> = s.priors.iter().map(|(n, p)| format!("{n}={p}")).collect();
        return Err(DesignError::new(
            "prior",
            &text.join(" "),
            "a Bayesian design is made for the d and c criteria; the t criterion is locally \
             optimal at the guess",
        ));
    }
    if s.points == 0 || s.points > MAX_POINTS {
        return Err(DesignError::new(
            "points",
            &s.points.to_string(),
            format!("expected 1 to {MAX_POINTS} points per series"),
        ));
    }
    let noise_ok = if s.noise_absolute {
        s.noise.is_finite() && s.noise > 0.0
    } else {
        s.noise.is_finite() && s.noise > 0.0 && s.noise < 0.5
    };
    if !noise_ok {
        return Err(DesignError::new(
            "noise",
            &fmt_f64(s.noise),
            if s.noise_absolute {
                "an absolute noise must be finite and > 0"
            } else {
                "a relative noise must be in (0, 0.5)"
            },
        ));
    }
    if !(s.rho.is_finite() && s.rho >= 0.0) {
        return Err(DesignError::new("rho", &fmt_f64(s.rho), "must be >= 0"));
    }
    if !(s.f.is_finite() && s.f >= 0.0) {
        return Err(DesignError::new("f", &fmt_f64(s.f), "must be >= 0"));
    }
    check_slopes(s)?;
    match (s.criterion, s.vs) {
        (Criterion::T, None) => Err(DesignError::new(
            "vs",
            "",
            "the T criterion needs the rival model (--vs MODEL)",
        )),
        (c, Some(v)) if c != Criterion::T => Err(DesignError::new(
            "vs",
            &kind_name(v),
            "a rival model goes with --criterion t",
        )),
        _ => Ok(()),
    }
}

/// The settings of the slopes: the caller's range, the slope error, the margin and the grid.
fn check_slopes(s: &DesignSettings) -> Result<(), DesignError> {
    if let Some((lo, hi)) = s.delta_range {
        if !(lo.is_finite() && hi.is_finite() && lo < hi && lo > 0.0 && hi < 90.0) {
            return Err(DesignError::new(
                "delta-range",
                &format!("{},{}", fmt_f64(lo), fmt_f64(hi)),
                "expected LO,HI in degrees with 0 < LO < HI < 90",
            ));
        }
    }
    if !(s.sigma_delta.is_finite() && (0.0..90.0).contains(&s.sigma_delta)) {
        return Err(DesignError::new(
            "sigma-delta",
            &fmt_f64(s.sigma_delta),
            "must be a finite number of degrees >= 0 and < 90",
        ));
    }
    if !(s.margin.is_finite() && (0.0..0.5).contains(&s.margin)) {
        return Err(DesignError::new(
            "margin",
            &fmt_f64(s.margin),
            "expected a fraction of the range's width with 0 <= F < 0.5",
        ));
    }
    if s.grid < 10 || s.grid > 100_000 {
        return Err(DesignError::new(
            "grid",
            &s.grid.to_string(),
            "expected 10 to 100000 candidate slopes",
        ));
    }
    Ok(())
}

fn no_range(xi: f64, why: &str) -> DesignError {
    DesignError::new(
        "series",
        &fmt_f64(xi),
        format!("no regime-B slope range for this series at the guess: {why}"),
    )
}

/// The slope range of each series (radians): regime B of the guess, cut to the caller's
/// range, kept [`kept_from_ends`] from each end.
fn ranges(
    s: &DesignSettings,
    prob: &Problem,
    rival: Option<&Problem>,
) -> Result<Vec<(f64, f64)>, DesignError> {
    (0..s.series.len())
        .map(|k| {
            let xi = s.series[k];
            let (lo, hi) = prob.regime_b(k).ok_or_else(|| {
                no_range(
                    xi,
                    "the model at the guess has no steady state at any slope",
                )
            })?;
            let (lo, hi) = match s.delta_range {
                Some((l, h)) => (l.to_radians().max(lo), h.to_radians().min(hi)),
                None => (lo, hi),
            };
            if !(lo < hi) {
                return Err(no_range(
                    xi,
                    "the slope range given lies outside regime B of the guess",
                ));
            }
            // The T criterion compares the two models where both are steady at the guess.
            let (lo, hi) = match rival {
                Some(r) => {
                    let (l, h) = r.regime_b(k).ok_or_else(|| {
                        no_range(xi, "the rival model at the guess has no steady state")
                    })?;
                    (lo.max(l), hi.min(h))
                }
                None => (lo, hi),
            };
            if !(lo < hi) {
                return Err(no_range(
                    xi,
                    "the model and its rival at the guess have no steady slope in common",
                ));
            }
            let m = kept_from_ends(s, hi - lo);
            if !(lo + m < hi - m) {
                return Err(DesignError::new(
                    "sigma-delta",
                    &fmt_f64(s.sigma_delta),
                    format!(
                        "series xi={}: its steady range {}-{} deg is too narrow to keep a slope \
                         2 sigma_delta from both ends",
                        fmt_f64(xi),
                        fmt_sig(lo.to_degrees(), 5),
                        fmt_sig(hi.to_degrees(), 5)
                    ),
                ));
            }
            Ok((lo + m, hi - m))
        })
        .collect()
}

/// What a range of width `w` (radians) keeps from each of its ends (radians): the fraction
/// `margin` of its width, but at least 0.01° (or the default 5 % of the width, if less), so
/// that the slopes at the ends, and the difference steps about them, stay steady; with slope
/// errors at least 2σ_δ and the rounding step of a slope (1e-4°), so that a design slope set
/// 2σ_δ off is still inside.
fn kept_from_ends(s: &DesignSettings, w: f64) -> f64 {
    let m = (s.margin * w).max(MIN_KEPT_DEG.to_radians().min(DEFAULT_MARGIN * w));
    if s.sigma_delta > 0.0 {
        m.max((2.0 * s.sigma_delta + SLOPE_STEP_DEG).to_radians())
    } else {
        m
    }
}

/// A slope rounded to 1e-4°, in radians.
fn round_deg(d: f64) -> f64 {
    ((d.to_degrees() * 1e4).round() / 1e4).to_radians()
}

fn row(xi: f64, delta: f64, n: usize) -> DesignRow {
    DesignRow {
        series: fmt_f64(xi),
        xi,
        delta_deg: (delta.to_degrees() * 1e4).round() / 1e4,
        replicates: n,
    }
}

/// σ of v̄ at a point in units of the noise: 1 (absolute noise) or v̄ (relative). The design
/// does not depend on the noise's size, which only scales what it predicts; working in its
/// units keeps the information matrices in range for any noise (an absolute σ of 1e-160
/// would square to 0 in them), and [`scale_to_noise`] brings the predictions back to σ.
fn sigma(s: &DesignSettings, v: f64) -> f64 {
    if s.noise_absolute {
        1.0
    } else {
        v
    }
}

/// The unit of the σ the design works in: the noise, or with slope errors the noise and σ_δ
/// (radians) in quadrature, so that neither term of the effective variance
/// ([`effective_sigma`]) leaves the range of the information matrices.
fn unit(s: &DesignSettings) -> f64 {
    if s.sigma_delta > 0.0 {
        s.noise.hypot(s.sigma_delta.to_radians())
    } else {
        s.noise
    }
}

/// The σ of v̄ of series `k` at slope `d` (radians) under parameters `theta`, where v̄ is
/// `v`, in units of [`unit`]: [`sigma`] without slope errors; with them the root of the
/// effective variance σ_v² + (∂v̄/∂δ)² σ_δ² (δ and σ_δ in radians). `None` where the
/// difference in δ leaves the steady state.
fn effective_sigma(
    s: &DesignSettings,
    prob: &Problem,
    k: usize,
    d: f64,
    theta: &[f64],
    v: f64,
) -> Option<f64> {
    if s.sigma_delta > 0.0 {
        let u = unit(s);
        let slope = prob.slope_derivative(k, d, theta)?;
        let sv = sigma(s, v) * (s.noise / u);
        Some(sv.hypot(slope * s.sigma_delta.to_radians() / u))
    } else {
        Some(sigma(s, v))
    }
}

/// The predictions of a design made in units of [`unit`] (the noise without slope errors)
/// for the noise of `s`: standard errors times the unit, the discrimination over its square
/// (the points needed are scaled where they are counted).
fn scale_to_noise(s: &DesignSettings, r: &mut DesignResult) {
    let n = unit(s);
    for e in &mut r.errors {
        e.design = e.design.map(|x| x * n);
        e.even = e.even.map(|x| x * n);
    }
    r.discrimination = r.discrimination.map(|(a, b)| (a / n / n, b / n / n));
}

/// The candidate of series `k` at slope `d` (radians), if the model at and around the guess
/// is steady there.
fn candidate(s: &DesignSettings, prob: &Problem, k: usize, d: f64) -> Option<Cand> {
    let v = prob.velocity(k, d, &prob.guess)?;
    let sg = effective_sigma(s, prob, k, d, &prob.guess, v)?;
    let g = prob.gradient(k, d)?;
    Some(Cand {
        series: k,
        delta: d,
        g: g.iter().map(|x| x / sg).collect(),
        sigma: sg,
    })
}

/// The c criterion's target: a parameter, or (K-law fits) μ of eq 79 of a series.
fn target_index(s: &DesignSettings, prob: &Problem) -> Result<Target, DesignError> {
    let mus = prob.mu_names();
    let expected = || {
        let mut all = prob.names.clone();
        all.extend(mus.iter().cloned());
        all.join(", ")
    };
    match &s.target {
        None if prob.names.len() == 1 => Ok(Target::Param(0)),
        None => Err(DesignError::new(
            "target",
            "",
            format!(
                "the c criterion needs the target parameter: one of {}",
                expected()
            ),
        )),
        Some(t) => {
            if let Some(k) = prob.names.iter().position(|n| n == t) {
                return Ok(Target::Param(k));
            }
            if let Some(k) = mus.iter().position(|n| n == t) {
                return Ok(Target::Mu(k));
            }
            Err(DesignError::new(
                "target",
                t,
                format!("no such parameter: expected one of {}", expected()),
            ))
        }
    }
}

/// The rival's problem for the T criterion: for a K-law fit, another contact model with the
/// same law's parameter free; for Jan's fit, Jaeger's (a1, a2, a3 per series); for Jaeger's,
/// Jan's (λ, μ at one series, the laws of eqs 75–76 across several).
fn rival(s: &DesignSettings, prob: &Problem) -> Result<Problem, DesignError> {
    let kind = s.vs.expect("checked");
    let (fit, m) = match s.fit {
        DesignFit::KLaw => {
            let m = kind.contact_model().ok_or_else(|| {
                DesignError::new(
                    "vs",
                    &kind_name(kind),
                    "the rival of a K-law fit is a contact model",
                )
            })?;
            if Some(kind) == s.model || (s.model.is_none() && kind == ModelKind::StickSlip) {
                return Err(DesignError::new(
                    "vs",
                    &kind_name(kind),
                    "the rival must differ from --model",
                ));
            }
            (DesignFit::KLaw, m)
        }
        // Jan's eq 74 is Jaeger's eq 80 with a2 = 0 (tan δ = μ + λ u²/(ε sin α)): Jaeger
        // fits Jan's curve exactly at any slopes, so no design tells them apart when Jan's
        // model is true.
        DesignFit::Jan if kind == ModelKind::Jaeger => {
            return Err(DesignError::new(
                "vs",
                "jaeger",
                "Jan's model (eq 74) is Jaeger's (eq 80) with a2 = 0, tan delta = mu + \
                 lambda u^2/(eps sin alpha): Jaeger's curve fits Jan's exactly at any slopes, \
                 so no design tells them apart when Jan's model holds (the T criterion is 0). \
                 To find the slopes that show a2 > 0, design for --fit jaeger --vs jan",
            ));
        }
        DesignFit::Jaeger if kind == ModelKind::Jan => {
            (DesignFit::Jan, crate::models::Model::StickSlip)
        }
        DesignFit::Jan | DesignFit::Jaeger => {
            let (own, other) = if s.fit == DesignFit::Jan {
                ("jan", "jaeger")
            } else {
                ("jaeger", "jan")
            };
            return Err(DesignError::new(
                "vs",
                &kind_name(kind),
                format!("the rival of the {own} fit is {other} (--vs {other})"),
            ));
        }
    };
    problem::problem(fit, m, s.law, &prob.series, prob.rho, prob.f, s.branch)
}

/// The rival's least-squares fit to the true curve at points `pts` with weights `w` (the
/// rival's guess as the start): its parameters and χ² = min_θ Σ w (v̄_A − v̄_B(θ))²/σ².
fn fit_rival(
    truth: &Problem,
    rival: &Problem,
    pts: &[&Cand],
    w: &[f64],
    start: &[f64],
) -> Option<(Vec<f64>, f64)> {
    use crate::inverse::{fit, CurveModel, Infeasible, LsqOptions, WeightedData};
    struct Curve<'a>(&'a Problem);
    impl CurveModel<(usize, f64)> for Curve<'_> {
        fn n_params(&self) -> usize {
            self.0.names.len()
        }
        fn value(&self, x: &(usize, f64), p: &[f64]) -> Result<f64, Infeasible> {
            self.0.velocity(x.0, x.1, p).ok_or(Infeasible)
        }
    }
    let mut x = Vec::new();
    let mut y = Vec::new();
    let mut sg = Vec::new();
    for (c, &wj) in pts.iter().zip(w) {
        let v = truth.velocity(c.series, c.delta, &truth.guess)?;
        x.push((c.series, c.delta));
        y.push(v);
        sg.push(c.sigma / wj.sqrt());
    }
    let data = WeightedData::new(Curve(rival), x, y, Some(sg)).ok()?;
    let opts = LsqOptions {
        ftol: 1e-10,
        xtol: 1e-10,
        gtol: 1e-10,
        polish: false,
        ..LsqOptions::default()
    };
    let f = fit(&data, start, &opts).ok()?;
    f.chi2.is_finite().then_some((f.params, f.chi2))
}

/// The one "draw" of a locally optimal design, at the guess: the candidates and the evenly
/// spaced slopes with the target's gradient `c` there (`None`: K at the guess has no μ).
fn guess_draws(
    s: &DesignSettings,
    c: Option<Vec<f64>>,
    cands: &[Cand],
    even: &[Cand],
) -> Result<(Vec<Draw>, Vec<Draw>), DesignError> {
    let c = c.ok_or_else(|| {
        DesignError::new(
            "law",
            &s.law.to_string(),
            "K at the guess is outside (0, 1): eq 79 has no μ there",
        )
    })?;
    Ok((
        vec![Draw {
            cands: cands.to_vec(),
            c: c.clone(),
        }],
        vec![Draw {
            cands: even.to_vec(),
            c,
        }],
    ))
}

/// How well the exact design (`exact`, replicates of candidates `cands`) and the evenly
/// spaced one (`even`, one point each) tell the model of `truth` from `rival`: T of each
/// (the rival's least χ², in units of the noise), and the points in all each needs for power
/// 0.8 at significance 0.05.
fn discriminate(
    s: &DesignSettings,
    truth: &Problem,
    rival: &Problem,
    cands: &[Cand],
    exact: &[Vec<(usize, usize)>],
    even: &[Cand],
    total_points: usize,
) -> ((f64, f64), (f64, f64)) {
    let pts: Vec<Cand> = exact
        .iter()
        .flatten()
        .map(|&(j, _)| cands[j].clone())
        .collect();
    let wts: Vec<f64> = exact.iter().flatten().map(|&(_, n)| n as f64).collect();
    let ones = vec![1.0; even.len()];
    let t_design = t_value(truth, rival, &pts, &wts).unwrap_or(f64::NAN);
    let t_even = t_value(truth, rival, even, &ones).unwrap_or(f64::NAN);
    let total = total_points as f64;
    // t is in units of [`unit`]: the points needed scale as its square.
    let u = unit(s);
    let need = |t: f64| {
        let per_point = t / total;
        if per_point > 0.0 {
            (noncentrality(0.05, 0.8) / per_point * u * u).ceil()
        } else {
            f64::INFINITY
        }
    };
    ((t_design, t_even), (need(t_design), need(t_even)))
}

/// T at an exact design: the rival's least χ² against the true curve.
fn t_value(truth: &Problem, rival: &Problem, pts: &[Cand], w: &[f64]) -> Option<f64> {
    let refs: Vec<&Cand> = pts.iter().collect();
    fit_rival(truth, rival, &refs, w, &rival.guess).map(|r| r.1)
}

/// The T-optimal approximate design (Atkinson–Fedorov), started from equal weights on every
/// fifth candidate.
/// Only the candidates where the rival at its guess is steady take part (the rival is
/// fitted there); these strata are returned with the design.
#[allow(clippy::type_complexity)]
fn t_design(
    s: &DesignSettings,
    prob: &Problem,
    cands: &[Cand],
    strata: &[Vec<usize>],
) -> Result<
    (
        Approx,
        Problem,
        Vec<Vec<usize>>,
        (Vec<Vec<usize>>, Vec<f64>),
    ),
    DesignError,
> {
    let rival = rival(s, prob)?;
    let strata: Vec<Vec<usize>> = strata
        .iter()
        .map(|st| {
            st.iter()
                .copied()
                .filter(|&j| {
                    let c = &cands[j];
                    rival.velocity(c.series, c.delta, &rival.guess).is_some()
                })
                .collect()
        })
        .collect();
    if let Some(k) = strata.iter().position(Vec::is_empty) {
        return Err(no_range(
            s.series[k],
            "the rival model at the guess has no steady state in its range",
        ));
    }
    let alg = algorithm_strata(s, &strata);
    let (alg_strata, budgets) = (&alg.0[..], &alg.1[..]);
    let truth: Vec<Option<f64>> = cands
        .iter()
        .map(|c| prob.velocity(c.series, c.delta, &prob.guess))
        .collect();
    let mut start = vec![0.0; cands.len()];
    for (st, &n) in alg_strata.iter().zip(budgets) {
        let picks: Vec<usize> = st.iter().copied().step_by(5).collect();
        for &j in &picks {
            start[j] = n / picks.len() as f64;
        }
    }
    let mut theta = rival.guess.clone();
    let fit = |w: &[f64]| -> Option<Vec<f64>> {
        let idx: Vec<usize> = (0..cands.len()).filter(|&j| w[j] > 0.0).collect();
        let pts: Vec<&Cand> = idx.iter().map(|&j| &cands[j]).collect();
        let wts: Vec<f64> = idx.iter().map(|&j| w[j]).collect();
        let (t, _) = fit_rival(prob, &rival, &pts, &wts, &theta)?;
        theta = t;
        Some(
            cands
                .iter()
                .zip(&truth)
                .map(|(c, va)| {
                    match (va, rival.velocity(c.series, c.delta, &theta)) {
                        (Some(a), Some(b)) => {
                            let r = (a - b) / c.sigma;
                            r * r
                        }
                        // Where the rival has no steady state, nothing is learnt from its curve.
                        _ => 0.0,
                    }
                })
                .collect(),
        )
    };
    let a = optimal::t_optimal(alg_strata, budgets, start, T_STEPS, fit).ok_or_else(|| {
        DesignError::new(
            "vs",
            &s.vs.map(kind_name).unwrap_or_default(),
            "the rival model could not be fitted to the true curve",
        )
    })?;
    Ok((a, rival, strata, alg))
}

/// The noncentrality at which a one-degree-of-freedom χ² test at significance `alpha` has
/// power `power`: (z_{1−α/2} + z_{power})², neglecting the far tail.
fn noncentrality(alpha: f64, power: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    let n = Normal::standard();
    let z = n.inverse_cdf(1.0 - alpha / 2.0) + n.inverse_cdf(power);
    z * z
}

/// A model kind as the command line writes it.
fn kind_name(k: ModelKind) -> String {
    format!("{k:?}").to_ascii_lowercase()
}
