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
//!   given, then kept a margin (5 % of its width) away from both ends, as `fitbead simulate`
//!   spreads its points over 5 %–95 % of the range. No design point lies outside it.
//! - **Candidates.** An even grid of slopes over the range (200 per series), each rounded to
//!   1e-4° as a measured slope is written. At each, v̄ at the guess, its σ (relative noise
//!   σ = noise · v̄, as `simulate --noise`, or absolute) and the gradient ∂v̄/∂p by central
//!   differences (step 1e-4 · max(|p|, 1e-3)), the Jacobian of the weighted least-squares
//!   problem the fits solve.
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
//! For T, the points needed are those, in the design's proportions, at which the
//! noncentrality λ = N · T/N_design of the one-degree-of-freedom χ² test of B reaches
//! (z_{1−α/2} + z_{power})² (significance α = 0.05, power 0.8: λ ≈ 7.85).

mod optimal;
mod problem;

use crate::models::{JaegerBranch, ModelKind};
use crate::numfmt::fmt_f64;
use crate::scene::CollisionLaw;
use optimal::{information, variances, Approx, Cand, Crit};
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
}

impl Default for DesignSettings {
    /// K-law c = 0.5 under stick/slip, the paper's four ξ, 9 points per series, 2 % noise, D.
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

/// Most points per series.
const MAX_POINTS: usize = 100_000;
/// Steps of the Atkinson–Fedorov iteration.
const T_STEPS: usize = 150;

/// The optimal design for `s` (see the module docs for the method).
pub fn design(s: &DesignSettings) -> Result<DesignResult, DesignError> {
    check(s)?;
    let model = match (s.fit, s.model) {
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
    };
    let prob = problem::problem(s.fit, model, s.law, &s.series, s.rho, s.f, s.branch)?;
    let p = prob.names.len();
    let rival_prob = match s.criterion {
        Criterion::T => Some(rival(s, &prob)?),
        _ => None,
    };
    let ranges = ranges(s, &prob, rival_prob.as_ref())?;
    // Candidates, stratum by stratum.
    let mut cands = Vec::new();
    let mut strata: Vec<Vec<usize>> = Vec::new();
    for (k, &(lo, hi)) in ranges.iter().enumerate() {
        let mut st = Vec::new();
        for i in 0..s.grid {
            let d = round_deg(lo + (hi - lo) * i as f64 / (s.grid - 1) as f64);
            if let Some(c) = candidate(s, &prob, k, d) {
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
    let budgets: Vec<f64> = vec![s.points as f64; s.series.len()];
    let counts = vec![s.points; s.series.len()];
    let target = match s.criterion {
        Criterion::C => Some(target_index(s, &prob)?),
        _ => None,
    };
    // The evenly spaced comparison design.
    let mut even_cands = Vec::new();
    for (k, &(lo, hi)) in ranges.iter().enumerate() {
        for j in 0..s.points {
            let frac = if s.points == 1 {
                0.5
            } else {
                j as f64 / (s.points - 1) as f64
            };
            let d = round_deg(lo + (hi - lo) * frac);
            let c = candidate(s, &prob, k, d).ok_or_else(|| {
                no_range(s.series[k], "an evenly spaced slope has no steady state")
            })?;
            even_cands.push(c);
        }
    }
    let ones = vec![1.0; even_cands.len()];
    let (approx, label, rival) = match s.criterion {
        Criterion::D => (
            optimal::multiplicative(&cands, &strata, &budgets, p, Crit::D),
            "standardised variance d/λ (D)".to_string(),
            None,
        ),
        Criterion::C => {
            let k = target.expect("c has a target");
            (
                optimal::multiplicative(&cands, &strata, &budgets, p, Crit::C(k)),
                format!("information on {} ψ/λ (c)", prob.names[k]),
                None,
            )
        }
        Criterion::T => {
            let (a, rival, st) = t_design(s, &prob, &cands, &strata, &budgets)?;
            strata = st;
            (
                a,
                "squared distance to the rival ψ/λ (T)".to_string(),
                Some(rival),
            )
        }
    };
    let exact = optimal::round(&strata, &counts, &approx);
    let mut w = vec![0.0; cands.len()];
    let mut rows = Vec::new();
    for st in &exact {
        for &(j, n) in st {
            w[j] = n as f64;
            let c = &cands[j];
            rows.push(row(s.series[c.series], c.delta, n));
        }
    }
    let even: Vec<DesignRow> = even_cands
        .iter()
        .map(|c| row(s.series[c.series], c.delta, 1))
        .collect();
    let m_design = information(&cands, &w, p);
    let m_even = information(&even_cands, &ones, p);
    let (v_design, v_even) = (variances(&m_design), variances(&m_even));
    let errors = (0..p)
        .map(|k| PredictedError {
            name: prob.names[k].clone(),
            guess: prob.guess[k],
            design: v_design[k].map(f64::sqrt),
            even: v_even[k].map(f64::sqrt),
        })
        .collect();
    let mut discrimination = None;
    let mut points_needed = None;
    let efficiency = match s.criterion {
        Criterion::D => {
            let (a, b) = (m_even.determinant(), m_design.determinant());
            if b > 0.0 {
                (a.max(0.0) / b).powf(1.0 / p as f64)
            } else {
                f64::NAN
            }
        }
        Criterion::C => {
            let k = target.expect("c has a target");
            match (v_design[k], v_even[k]) {
                (Some(a), Some(b)) => a / b,
                (Some(_), None) => 0.0,
                _ => f64::NAN,
            }
        }
        Criterion::T => {
            let rival = rival.expect("t has a rival");
            let pts: Vec<Cand> = exact
                .iter()
                .flatten()
                .map(|&(j, _)| cands[j].clone())
                .collect();
            let wts: Vec<f64> = exact.iter().flatten().map(|&(_, n)| n as f64).collect();
            let t_design = t_value(s, &prob, &rival, &pts, &wts).unwrap_or(f64::NAN);
            let t_even = t_value(s, &prob, &rival, &even_cands, &ones).unwrap_or(f64::NAN);
            discrimination = Some((t_design, t_even));
            let total = (s.points * s.series.len()) as f64;
            let need = |t: f64| {
                let per_point = t / total;
                if per_point > 0.0 {
                    (noncentrality(0.05, 0.8) / per_point).ceil()
                } else {
                    f64::INFINITY
                }
            };
            points_needed = Some((need(t_design), need(t_even)));
            t_even / t_design
        }
    };
    let sensitivity = strata
        .iter()
        .map(|st| {
            st.iter()
                .map(|&j| (cands[j].delta.to_degrees(), approx.sens[j]))
                .collect()
        })
        .collect();
    Ok(DesignResult {
        rows,
        even,
        ranges: ranges
            .iter()
            .map(|r| (r.0.to_degrees(), r.1.to_degrees()))
            .collect(),
        errors,
        target: target.map(|k| prob.names[k].clone()),
        efficiency,
        gap: approx.gap,
        discrimination,
        points_needed,
        sensitivity,
        sensitivity_label: label,
    })
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
    if let Some((lo, hi)) = s.delta_range {
        if !(lo.is_finite() && hi.is_finite() && lo < hi && lo > 0.0 && hi < 90.0) {
            return Err(DesignError::new(
                "delta-range",
                &format!("{},{}", fmt_f64(lo), fmt_f64(hi)),
                "expected LO,HI in degrees with 0 < LO < HI < 90",
            ));
        }
    }
    if s.grid < 10 || s.grid > 100_000 {
        return Err(DesignError::new(
            "grid",
            &s.grid.to_string(),
            "expected 10 to 100000 candidate slopes",
        ));
    }
    match (s.criterion, s.vs) {
        (Criterion::T, None) => Err(DesignError::new(
            "vs",
            "",
            "the T criterion needs the rival model (--vs MODEL)",
        )),
        (Criterion::T, Some(_)) if s.fit != DesignFit::KLaw => Err(DesignError::new(
            "criterion",
            "t",
            "model discrimination is made for the K-law fits (--fit klaw)",
        )),
        (c, Some(v)) if c != Criterion::T => Err(DesignError::new(
            "vs",
            &kind_name(v),
            "a rival model goes with --criterion t",
        )),
        _ => Ok(()),
    }
}

fn no_range(xi: f64, why: &str) -> DesignError {
    DesignError::new(
        "series",
        &fmt_f64(xi),
        format!("no regime-B slope range for this series at the guess: {why}"),
    )
}

/// The slope range of each series (radians): regime B of the guess, cut to the caller's
/// range, kept 5 % of its width from each end.
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
            let m = 0.05 * (hi - lo);
            Ok((lo + m, hi - m))
        })
        .collect()
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

/// σ of v̄ at a point.
fn sigma(s: &DesignSettings, v: f64) -> f64 {
    if s.noise_absolute {
        s.noise
    } else {
        s.noise * v
    }
}

/// The candidate of series `k` at slope `d` (radians), if the model at and around the guess
/// is steady there.
fn candidate(s: &DesignSettings, prob: &Problem, k: usize, d: f64) -> Option<Cand> {
    let v = prob.velocity(k, d, &prob.guess)?;
    let sg = sigma(s, v);
    let g = prob.gradient(k, d)?;
    Some(Cand {
        series: k,
        delta: d,
        g: g.iter().map(|x| x / sg).collect(),
    })
}

/// The index of the c criterion's target.
fn target_index(s: &DesignSettings, prob: &Problem) -> Result<usize, DesignError> {
    match &s.target {
        None if prob.names.len() == 1 => Ok(0),
        None => Err(DesignError::new(
            "target",
            "",
            format!(
                "the c criterion needs the target parameter: one of {}",
                prob.names.join(", ")
            ),
        )),
        Some(t) => prob.names.iter().position(|n| n == t).ok_or_else(|| {
            DesignError::new(
                "target",
                t,
                format!(
                    "no such parameter: expected one of {}",
                    prob.names.join(", ")
                ),
            )
        }),
    }
}

/// The rival's problem for the T criterion: its own model, the same law's parameter free.
fn rival(s: &DesignSettings, prob: &Problem) -> Result<Problem, DesignError> {
    let kind = s.vs.expect("checked");
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
    problem::problem(s.fit, m, s.law, &prob.series, prob.rho, prob.f, s.branch)
}

/// The rival's least-squares fit to the true curve at points `pts` with weights `w` (the
/// rival's guess as the start): its parameters and χ² = min_θ Σ w (v̄_A − v̄_B(θ))²/σ².
fn fit_rival(
    s: &DesignSettings,
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
        sg.push(sigma(s, v) / wj.sqrt());
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

/// T at an exact design: the rival's least χ² against the true curve.
fn t_value(
    s: &DesignSettings,
    truth: &Problem,
    rival: &Problem,
    pts: &[Cand],
    w: &[f64],
) -> Option<f64> {
    let refs: Vec<&Cand> = pts.iter().collect();
    fit_rival(s, truth, rival, &refs, w, &rival.guess).map(|r| r.1)
}

/// The T-optimal approximate design (Atkinson–Fedorov), started from equal weights on every
/// fifth candidate.
/// Only the candidates where the rival at its guess is steady take part (the rival is
/// fitted there); these strata are returned with the design.
fn t_design(
    s: &DesignSettings,
    prob: &Problem,
    cands: &[Cand],
    strata: &[Vec<usize>],
    budgets: &[f64],
) -> Result<(Approx, Problem, Vec<Vec<usize>>), DesignError> {
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
    let strata = &strata[..];
    let truth: Vec<Option<f64>> = cands
        .iter()
        .map(|c| prob.velocity(c.series, c.delta, &prob.guess))
        .collect();
    let mut start = vec![0.0; cands.len()];
    for (st, &n) in strata.iter().zip(budgets) {
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
        let (t, _) = fit_rival(s, prob, &rival, &pts, &wts, &theta)?;
        theta = t;
        Some(
            cands
                .iter()
                .zip(&truth)
                .map(|(c, va)| {
                    match (va, rival.velocity(c.series, c.delta, &theta)) {
                        (Some(a), Some(b)) => {
                            let r = (a - b) / sigma(s, *a);
                            r * r
                        }
                        // Where the rival has no steady state, nothing is learnt from its curve.
                        _ => 0.0,
                    }
                })
                .collect(),
        )
    };
    let a = optimal::t_optimal(strata, budgets, start, T_STEPS, fit).ok_or_else(|| {
        DesignError::new(
            "vs",
            &s.vs.map(kind_name).unwrap_or_default(),
            "the rival model could not be fitted to the true curve",
        )
    })?;
    Ok((a, rival, strata.to_vec()))
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
