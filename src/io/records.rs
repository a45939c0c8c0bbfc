//! One typed record per output row: a parameter ([`ParamRecord`], params.csv and `--output`),
//! the statistics of a fit ([`StatsRecord`], stats.csv and `--output-stats`), a point against
//! its fit ([`ResidualRecord`], residuals.csv), a pair of parameters ([`CorrelationRecord`],
//! correlations.csv), a scene's steady state ([`ForwardRecord`], with [`ContactRecord`] and
//! [`AutoRecord`]: `fitbead forward`), a measurement's K ([`KRecord`]: `fitbead k`) and a
//! law's regime limits ([`RegimeRecord`]: `fitbead regimes`).
//!
//! Each record derives `serde::Serialize`; its columns are its fields, in order, with their
//! serde names (`columns`, or the keys [`Cell::each`] visits). Every writer reads the record ([`Cell::each`]): the CSV files,
//! the streaming commands and the Python binding's columns and dicts. A number is written as
//! the shortest decimal that reads back as the same double ([`crate::numfmt::fmt_f64`]), an
//! absent or non-finite number as an empty cell.

use crate::fit::k::auto::{estimate_with, KChoice};
use crate::fit::k::slope::estimate_with_slope;
use crate::fit::k::KEstimate;
use crate::fit::summary::{FitResult, ParamRow, PointFit, StatsRow};
use crate::inverse::{ProfileEnd, SigmaKind};
use crate::models::auto::Auto;
use crate::models::contact::{SpinRule, SteadyContact};
use crate::models::{Model, Outcome, Phases, Regime};
pub use crate::record::Cell;
pub(crate) use crate::record::{columns, to_csv};
use crate::scene::{CollisionLaw, Scene};
use serde::Serialize;
use std::borrow::Cow;

/// One parameter of one fit: its estimate, standard error, reported interval and how it was
/// found, the covariance and profile intervals, and, for a posterior run, the posterior summary.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ParamRecord {
    /// Name of the fit (e.g. `stickslip law c`).
    pub fit: String,
    /// Series label, or `all` for a fit across series.
    pub series: String,
    /// Parameter name.
    pub parameter: String,
    /// Estimate (the posterior median for a posterior run).
    pub value: f64,
    /// Standard error (the posterior sd for a posterior run).
    pub stderr: Option<f64>,
    /// Lower end of the reported interval.
    pub ci_low: Option<f64>,
    /// Upper end of the reported interval.
    pub ci_high: Option<f64>,
    /// How the reported interval was found: `profile`, `covariance`, `posterior` or `none`.
    pub ci_method: String,
    /// Unit of the parameter.
    pub unit: String,
    /// Confidence level of the intervals.
    pub level: f64,
    /// Lower end of the covariance (Wald) interval, not cut to the parameter's box.
    pub cov_low: Option<f64>,
    /// Upper end of the covariance interval.
    pub cov_high: Option<f64>,
    /// Lower end of the profile-likelihood interval, where determined.
    pub profile_low: Option<f64>,
    /// Upper end of the profile-likelihood interval, where determined.
    pub profile_high: Option<f64>,
    /// How the lower profile end ended: `found`, `bound`, `edge`, `not_found` or `none`.
    pub profile_low_status: String,
    /// How the upper profile end ended.
    pub profile_high_status: String,
    /// Whether the estimate sits on a bound of its box.
    pub at_bound: bool,
    /// The paper's value of the same parameter.
    pub paper_value: Option<f64>,
    /// Where `paper_value` comes from.
    pub paper_source: String,
    /// Anything the user should know about this parameter.
    pub note: String,
    /// Posterior mean.
    pub mean: Option<f64>,
    /// Posterior standard deviation.
    pub sd: Option<f64>,
    /// Posterior 2.5 % quantile.
    #[serde(rename = "q2.5")]
    pub q2_5: Option<f64>,
    /// Posterior median.
    pub q50: Option<f64>,
    /// Posterior 97.5 % quantile.
    #[serde(rename = "q97.5")]
    pub q97_5: Option<f64>,
    /// Bulk effective sample size.
    pub ess_bulk: Option<f64>,
    /// Tail effective sample size.
    pub ess_tail: Option<f64>,
    /// Rank-normalised split R̂.
    pub rhat: Option<f64>,
    /// Integrated autocorrelation time, in steps.
    pub tau: Option<f64>,
    /// The least-squares optimum (the start of the chains for a posterior run).
    pub lsq_value: Option<f64>,
    /// Power-scaling sensitivity of the posterior to the prior (posterior runs).
    pub prior_sensitivity: Option<f64>,
    /// Power-scaling sensitivity of the posterior to the likelihood (posterior runs).
    pub likelihood_sensitivity: Option<f64>,
    /// `prior-driven`, `prior-data conflict` or empty (posterior runs; threshold 0.05).
    pub prior_diagnosis: String,
}

fn end_value(e: ProfileEnd) -> Option<f64> {
    match e {
        ProfileEnd::Found(v) | ProfileEnd::Bound(v) | ProfileEnd::Edge(v) => Some(v),
        ProfileEnd::NotFound => None,
    }
}

fn end_status(e: ProfileEnd) -> &'static str {
    match e {
        ProfileEnd::Found(_) => "found",
        ProfileEnd::Bound(_) => "bound",
        ProfileEnd::Edge(_) => "edge",
        ProfileEnd::NotFound => "not_found",
    }
}

impl From<&ParamRow> for ParamRecord {
    fn from(r: &ParamRow) -> Self {
        let (ci, method) = r.interval();
        let post = r.posterior.as_ref();
        let (pl, ph) = match r.profile {
            Some((a, b)) => ((end_value(a), end_status(a)), (end_value(b), end_status(b))),
            None => ((None, "none"), (None, "none")),
        };
        ParamRecord {
            fit: r.fit.clone(),
            series: r.series.clone(),
            parameter: r.parameter.clone(),
            value: r.value,
            stderr: r.stderr,
            ci_low: ci.map(|c| c.0),
            ci_high: ci.map(|c| c.1),
            ci_method: method.into(),
            unit: r.unit.into(),
            level: r.level,
            cov_low: r.cov.map(|c| c.0),
            cov_high: r.cov.map(|c| c.1),
            profile_low: pl.0,
            profile_high: ph.0,
            profile_low_status: pl.1.into(),
            profile_high_status: ph.1.into(),
            at_bound: r.at_bound,
            paper_value: r.paper_value,
            paper_source: r.paper_source.into(),
            note: r.note.clone(),
            mean: post.map(|d| d.mean),
            sd: post.map(|d| d.sd),
            q2_5: post.map(|d| d.q025),
            q50: post.map(|d| d.median),
            q97_5: post.map(|d| d.q975),
            ess_bulk: post.map(|d| d.ess_bulk),
            ess_tail: post.map(|d| d.ess_tail),
            rhat: post.map(|d| d.rhat),
            tau: post.map(|d| d.tau),
            lsq_value: r.lsq_value,
            prior_sensitivity: r.sensitivity.map(|x| x.prior),
            likelihood_sensitivity: r.sensitivity.map(|x| x.likelihood),
            prior_diagnosis: r.sensitivity.map_or("", |x| x.diagnosis()).into(),
        }
    }
}

/// The statistics of one fit: goodness of fit, the solver's account and, for a posterior run,
/// the sampler's.
#[derive(Debug, Clone, Default, Serialize)]
pub struct StatsRecord {
    /// Name of the fit.
    pub fit: String,
    /// Series label, or `all`.
    pub series: String,
    /// Number of data points.
    pub n_points: u64,
    /// Number of fitted parameters.
    pub n_params: u64,
    /// χ² at the estimate.
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: u64,
    /// χ²/dof.
    pub reduced_chi2: f64,
    /// Akaike's information criterion (empty where undefined).
    pub aic: f64,
    /// Bayesian information criterion (empty where undefined).
    pub bic: f64,
    /// Why the solver stopped.
    pub termination: String,
    /// Whether the solver converged.
    pub converged: bool,
    /// Solver iterations.
    pub iterations: u64,
    /// Residual evaluations, profiles included.
    pub residual_evals: u64,
    /// `given` (σ absolute) or `estimated` (unit weights, covariance scaled by χ²/dof).
    pub sigma: String,
    /// Condition number of the column-equilibrated Jacobian, if known.
    pub condition: Option<f64>,
    /// Anything the user should know about this fit.
    pub note: String,
    /// `lsq` or `mcmc`.
    pub method: String,
    /// The sampler's status (posterior runs).
    pub mcmc_status: Option<String>,
    /// Walkers.
    pub walkers: Option<u64>,
    /// Steps per walker.
    pub steps: Option<u64>,
    /// Steps discarded as burn-in.
    pub burn_in: Option<u64>,
    /// Draws kept.
    pub draws: Option<u64>,
    /// Mean acceptance fraction.
    pub acceptance: Option<f64>,
    /// Smallest effective sample size over the parameters.
    pub ess_min: Option<f64>,
    /// Largest R̂ over the parameters.
    pub rhat_max: Option<f64>,
    /// Widely applicable information criterion.
    pub waic: Option<f64>,
    /// WAIC's effective number of parameters.
    pub p_waic: Option<f64>,
    /// WAIC's standard error.
    pub waic_se: Option<f64>,
}

impl From<&StatsRow> for StatsRecord {
    fn from(r: &StatsRow) -> Self {
        let m = r.mcmc.as_ref();
        let waic = m.and_then(|m| m.waic);
        StatsRecord {
            fit: r.fit.clone(),
            series: r.series.clone(),
            n_points: r.n_points as u64,
            n_params: r.n_params as u64,
            chi2: r.chi2,
            dof: r.dof as u64,
            reduced_chi2: r.reduced_chi2,
            aic: r.aic,
            bic: r.bic,
            termination: r.termination.clone(),
            converged: r.converged,
            iterations: r.iterations as u64,
            residual_evals: r.residual_evals as u64,
            sigma: match r.sigma {
                SigmaKind::Absolute => "given",
                SigmaKind::Relative => "estimated",
            }
            .into(),
            condition: r.condition,
            note: r.note.clone(),
            method: if m.is_some() {
                "mcmc"
            } else if r.slope_errors {
                "odr"
            } else {
                "lsq"
            }
            .into(),
            mcmc_status: m.map(|m| m.status.clone()),
            walkers: m.map(|m| m.walkers as u64),
            steps: m.map(|m| m.steps as u64),
            burn_in: m.map(|m| m.burn_in as u64),
            draws: m.map(|m| m.draws as u64),
            acceptance: m.map(|m| m.acceptance),
            ess_min: m.map(|m| m.ess_min),
            rhat_max: m.map(|m| m.rhat_max),
            waic: waic.map(|w| w.0),
            p_waic: waic.map(|w| w.1),
            waic_se: waic.map(|w| w.2),
        }
    }
}

/// One point of one fit against its fitted v̄. Cells are empty where there is no σ or no
/// steady state at the estimate.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ResidualRecord {
    /// Name of the fit.
    pub fit: String,
    /// Series label.
    pub series: String,
    /// Radius ratio ξ.
    pub xi: f64,
    /// Slope δ, degrees.
    pub delta_deg: f64,
    /// Measured mean velocity (dimensionless).
    pub v: f64,
    /// Its standard deviation, if given.
    pub sigma_v: Option<f64>,
    /// Fitted v̄ at the reported estimate.
    pub v_fit: f64,
    /// v − v̄_fit.
    pub residual: f64,
    /// (v − v̄_fit)/σ (without σ, divided by the scatter estimated from the fit).
    pub normalised_residual: f64,
}

/// A [`ResidualRecord`] with the adjusted slope of a fit that took the slopes as measured
/// with error: the columns `delta_fit_deg` (δ_fit, degrees) and `delta_residual`
/// ((δ_fit − δ)/σ_δ, empty where the slope is exact) after the others.
#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct SlopeResidualRecord {
    fit: String,
    series: String,
    xi: f64,
    delta_deg: f64,
    v: f64,
    sigma_v: Option<f64>,
    v_fit: f64,
    residual: f64,
    normalised_residual: f64,
    delta_fit_deg: Option<f64>,
    delta_residual: Option<f64>,
}

impl SlopeResidualRecord {
    /// Every point of every fit, in order.
    pub fn of(fits: &[&FitResult]) -> Vec<Self> {
        fits.iter()
            .flat_map(|f| {
                f.points.iter().map(|p| {
                    let b = ResidualRecord::new(&f.stats.fit, p);
                    SlopeResidualRecord {
                        fit: b.fit,
                        series: b.series,
                        xi: b.xi,
                        delta_deg: b.delta_deg,
                        v: b.v,
                        sigma_v: b.sigma_v,
                        v_fit: b.v_fit,
                        residual: b.residual,
                        normalised_residual: b.normalised_residual,
                        delta_fit_deg: p.delta_fit_deg,
                        delta_residual: p.delta_residual,
                    }
                })
            })
            .collect()
    }
}

impl ResidualRecord {
    /// The record of point `p` of the fit named `fit`.
    pub fn new(fit: &str, p: &PointFit) -> Self {
        ResidualRecord {
            fit: fit.into(),
            series: p.series.clone(),
            xi: p.xi,
            delta_deg: p.delta_deg,
            v: p.v,
            sigma_v: p.sigma_v,
            v_fit: p.v_fit,
            residual: p.residual,
            normalised_residual: p.normalised_residual,
        }
    }

    /// Every point of every fit, in order.
    pub fn of(fits: &[&FitResult]) -> Vec<Self> {
        fits.iter()
            .flat_map(|f| f.points.iter().map(|p| Self::new(&f.stats.fit, p)))
            .collect()
    }
}

/// One pair of parameters of one fit with its correlation.
#[derive(Debug, Clone, Default, Serialize)]
pub struct CorrelationRecord {
    /// Name of the fit.
    pub fit: String,
    /// Series label, or `all`.
    pub series: String,
    /// First parameter (`K[series]` for a fit with one parameter per series).
    pub parameter_1: String,
    /// Second parameter.
    pub parameter_2: String,
    /// Their correlation.
    pub correlation: f64,
}

impl CorrelationRecord {
    /// Every pair of parameters of every fit, each pair once in the order of the fit's
    /// parameters; a fit without a correlation matrix has none, and a parameter held fixed
    /// is in no pair.
    pub fn of(fits: &[&FitResult]) -> Vec<Self> {
        let mut out = Vec::new();
        for f in fits {
            let Some(c) = &f.correlation else { continue };
            let names = f.param_names();
            let n = names.len().min(c.len());
            for i in 0..n {
                for j in i + 1..n {
                    // A parameter held fixed has no correlation.
                    if f.params.get(i).is_some_and(|p| p.fixed)
                        || f.params.get(j).is_some_and(|p| p.fixed)
                    {
                        continue;
                    }
                    out.push(CorrelationRecord {
                        fit: f.stats.fit.clone(),
                        series: f.stats.series.clone(),
                        parameter_1: names[i].clone(),
                        parameter_2: names[j].clone(),
                        correlation: c[i][j],
                    });
                }
            }
        }
        out
    }
}

/// The columns every model adds to a `forward` row: the steady state (eq 68 for v̄), or why
/// there is none. Velocities are in units of √(g (R + r)), angles in degrees.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ForwardRecord {
    /// Mean velocity v̄; empty without a steady state.
    pub v: Option<f64>,
    /// Regime `A`, `B` or `C`; empty where the model does not say.
    pub regime: &'static str,
    /// `ok`, or why there is no steady state.
    pub status: &'static str,
    /// The collision parameter K used (the contact models; empty for Jan and Jaeger).
    #[serde(rename = "K_used")]
    pub k_used: Option<f64>,
    /// Final velocity of the steady contact (contact models).
    pub final_velocity: Option<f64>,
    /// Velocity just after the collision (contact models).
    pub initial_velocity: Option<f64>,
    /// Contact time, in units of √((R + r)/g).
    pub contact_time: Option<f64>,
    /// Θ_G (eq 36), where rolling gives way to slip.
    #[serde(rename = "theta_G_deg")]
    pub theta_g_deg: Option<f64>,
    /// Slope of the final-velocity map at the fixed point.
    pub map_slope: Option<f64>,
    /// Another fixed point of the final-velocity map, where the scene is bistable.
    pub other_fixed_point: Option<f64>,
    /// The phases of the steady contact (`roll`, `slip`, `roll>slip`, or a sequence).
    pub phases: Cow<'static, str>,
    /// Why there is no steady state, or a warning about the one found.
    pub message: Cow<'static, str>,
}

/// The columns the general contact model adds to a `forward` row: its phases, spins and
/// energy partition (fractions of the potential drop).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ContactRecord {
    /// The phase sequence of the steady contact.
    pub phase_sequence: String,
    /// The angles of its phase changes, degrees.
    pub phase_change_deg: String,
    /// Spin ω0/ε at the start of the contact.
    pub initial_spin: Option<f64>,
    /// Spin ωf/ε at its end.
    pub final_spin: Option<f64>,
    /// Contacts evaluated to find the fixed point.
    pub beads: Option<u64>,
    /// Translational energy lost at each collision.
    pub collision_translation_frac: Option<f64>,
    /// Spin energy lost at each collision.
    pub collision_spin_frac: Option<f64>,
    /// Work of friction over the contact.
    pub friction_work_frac: Option<f64>,
    /// The energy balance's closure (0 when the partition adds up).
    pub energy_closure: Option<f64>,
    /// The spin rule at each collision.
    pub spin_rule: String,
}

/// The columns `auto` adds to a `forward` or `k` row: the model it used, and why.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AutoRecord {
    /// The model used.
    pub model_used: &'static str,
    /// Why.
    pub reason: String,
}

/// The message of a steady state on two fixed points.
fn bistable(contact: bool) -> &'static str {
    if contact {
        "bistable: another fixed point of the final-velocity map"
    } else {
        "two positive roots (eq 84): bistable band"
    }
}

fn phases_text(p: Phases) -> Cow<'static, str> {
    match p {
        Phases::Roll => Cow::Borrowed("roll"),
        Phases::Slip => Cow::Borrowed("slip"),
        Phases::RollSlip => Cow::Borrowed("roll>slip"),
        Phases::None => Cow::Borrowed(""),
        p => Cow::Owned(p.to_string()),
    }
}

impl ForwardRecord {
    /// The records of `scene` under `model`: the columns every model adds, the contact
    /// model's (that model only) and auto's (auto only).
    pub fn evaluate(
        scene: &Scene,
        model: &Model,
    ) -> (ForwardRecord, Option<ContactRecord>, Option<AutoRecord>) {
        let ev = model.evaluate_detailed(scene);
        let contact = ev
            .contact
            .as_ref()
            .map(|(rule, steady)| ContactRecord::new(scene, *rule, steady.as_ref()));
        let auto = ev.auto.as_ref().map(|a| AutoRecord {
            model_used: a.choice.name(),
            reason: a.reason.to_string(),
        });
        let uses_k = !matches!(model, Model::Jan(_) | Model::Jaeger(_));
        (
            ForwardRecord::new(scene, uses_k, &ev.outcome),
            contact,
            auto,
        )
    }

    /// The record of `outcome` at `scene`, whose K is reported when `uses_k` (the models of
    /// the contact, not Jan's or Jaeger's laws).
    pub(crate) fn new(scene: &Scene, uses_k: bool, outcome: &Outcome) -> ForwardRecord {
        let k_used = uses_k.then(|| scene.k());
        let regime = Regime::of(outcome).map_or("", Regime::letter);
        match outcome {
            Ok(s) => ForwardRecord {
                v: Some(s.mean_velocity),
                regime,
                status: "ok",
                k_used,
                final_velocity: uses_k.then_some(s.final_velocity),
                initial_velocity: uses_k.then_some(s.initial_velocity),
                contact_time: Some(s.contact_time),
                theta_g_deg: s.theta_g.map(f64::to_degrees),
                map_slope: s.map_slope,
                other_fixed_point: s.other_fixed_point,
                phases: phases_text(s.phases),
                message: Cow::Borrowed(if s.other_fixed_point.is_some() {
                    bistable(uses_k)
                } else {
                    ""
                }),
            },
            Err(e) => ForwardRecord {
                regime,
                status: e.status(),
                k_used,
                message: Cow::Owned(e.to_string()),
                ..ForwardRecord::default()
            },
        }
    }
}

impl ContactRecord {
    /// The record of the general contact model's steady state at `scene` (empty but for the
    /// spin rule where there is none).
    pub(crate) fn new(scene: &Scene, rule: SpinRule, steady: Option<&SteadyContact>) -> Self {
        let Some(s) = steady else {
            return ContactRecord {
                spin_rule: rule.to_string(),
                ..ContactRecord::default()
            };
        };
        let e = s.energy(scene);
        let p = e.potential_drop;
        ContactRecord {
            phase_sequence: s.run.phases.to_string(),
            phase_change_deg: s.run.phases.changes_deg(),
            initial_spin: Some(s.launch.spin),
            final_spin: Some(s.final_spin),
            beads: Some(s.beads as u64),
            collision_translation_frac: Some(e.collision_translation / p),
            collision_spin_frac: Some(e.collision_spin / p),
            friction_work_frac: Some(e.friction_work / p),
            energy_closure: Some(e.closure()),
            spin_rule: rule.to_string(),
        }
    }
}

/// The K of one measurement (eq 69) as the columns `fitbead k` adds after the measurement's
/// own: K, its interval for v ± σ, the bracket it was sought in, and the three named laws' K
/// at the measurement's ξ for comparison.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct KRecord {
    /// K at the measured v̄; empty where there is none (see `status`).
    #[serde(rename = "K")]
    pub k: Option<f64>,
    /// K at v − σ.
    #[serde(rename = "K_lo")]
    pub k_lo: Option<f64>,
    /// K at v + σ.
    #[serde(rename = "K_hi")]
    pub k_hi: Option<f64>,
    /// dv̄/dK at K.
    #[serde(rename = "dv_dK")]
    pub dv_dk: Option<f64>,
    /// Final velocity of the steady contact at K.
    pub final_velocity: Option<f64>,
    /// Θ_G (eq 36) at K, degrees.
    #[serde(rename = "theta_G_deg")]
    pub theta_g_deg: Option<f64>,
    /// K = cos 2α at the measurement's ξ.
    #[serde(rename = "K_cos2a")]
    pub k_cos2a: f64,
    /// The adjusted law's K.
    #[serde(rename = "K_adjusted")]
    pub k_adjusted: f64,
    /// The impact law's K.
    #[serde(rename = "K_impact")]
    pub k_impact: f64,
    /// `B` with a K, `A` below the steady range, `C` above it, empty when invalid.
    pub regime: &'static str,
    /// `ok`, `below-range`, `above-range` or `invalid`.
    pub status: &'static str,
    /// Model evaluations of the root search.
    pub iterations: Option<u64>,
    /// Lower end of the bracket of K.
    #[serde(rename = "K_min")]
    pub k_min: Option<f64>,
    /// Upper end of the bracket.
    #[serde(rename = "K_max")]
    pub k_max: Option<f64>,
    /// What sets the bracket's lower end.
    pub lower_limit: &'static str,
    /// What sets its upper end.
    pub upper_limit: &'static str,
    /// Why there is no K, and notes on the interval's ends, separated by `; `.
    pub message: String,
}

impl KRecord {
    /// The K of measurement `v` (± `sigma_v`) at `scene` under `model`, or under the model
    /// `auto` chooses for it, with that choice (eq 69).
    pub fn estimate(
        model: &Model,
        auto: Option<&Auto>,
        scene: &Scene,
        v: f64,
        sigma_v: Option<f64>,
    ) -> (KRecord, Option<AutoRecord>) {
        let (e, choice) = estimate_with(model, auto, scene, v, sigma_v);
        (
            KRecord::new(&e, named_laws(scene)),
            choice.map(AutoRecord::of_choice),
        )
    }

    /// [`KRecord::estimate`] for a slope with standard uncertainty `sigma_delta` (radians, 0
    /// for an exact slope), with σ_K: K_lo and K_hi are the inverses at v ∓ σ_eff, σ_eff² =
    /// σ_v² + (∂v̄/∂δ · σ_δ)² (∂v̄/∂δ at the measurement's K), and σ_K = σ_eff/|dv̄/dK|. σ_K is
    /// `None` where there is no K or no σ; with `sigma_delta` = 0 the record is
    /// [`KRecord::estimate`]'s and σ_K = σ_v/|dv̄/dK|.
    pub fn estimate_with_slope(
        model: &Model,
        auto: Option<&Auto>,
        scene: &Scene,
        v: f64,
        sigma_v: Option<f64>,
        sigma_delta: f64,
    ) -> (KRecord, Option<AutoRecord>, Option<f64>) {
        let (e, choice, sigma_k) = estimate_with_slope(model, auto, scene, v, sigma_v, sigma_delta);
        (
            KRecord::new(&e, named_laws(scene)),
            choice.map(AutoRecord::of_choice),
            sigma_k,
        )
    }

    /// The record of estimate `e`, with the three named laws' K (cos 2α, adjusted, impact).
    pub(crate) fn new(e: &KEstimate, laws: [f64; 3]) -> KRecord {
        let root = e.root.as_ref().ok();
        let (regime, status) = e.regime_status();
        let failure = e.root.as_ref().err().map(ToString::to_string);
        let message = match (failure, e.notes.is_empty()) {
            (None, true) => String::new(),
            (f, _) => f
                .into_iter()
                .chain(e.notes.iter().cloned())
                .collect::<Vec<_>>()
                .join("; "),
        };
        let b = e.bracket.as_ref();
        KRecord {
            k: root.map(|r| r.k),
            k_lo: e.k_lo,
            k_hi: e.k_hi,
            dv_dk: e.dv_dk,
            final_velocity: root.map(|r| r.steady.final_velocity),
            theta_g_deg: e.theta_g.map(f64::to_degrees),
            k_cos2a: laws[0],
            k_adjusted: laws[1],
            k_impact: laws[2],
            regime,
            status,
            iterations: root.map(|r| r.evals as u64),
            k_min: b.map(|b| b.lo),
            k_max: b.map(|b| b.hi),
            lower_limit: b.map_or("", |b| b.lower.name()),
            upper_limit: b.map_or("", |b| b.upper.name()),
            message,
        }
    }
}

/// K of cos 2α, the adjusted law and the impact law at `scene`'s ξ and ρ.
fn named_laws(scene: &Scene) -> [f64; 3] {
    let (alpha, rho) = (scene.alpha_rad(), scene.rho());
    [
        CollisionLaw::Cos2a,
        CollisionLaw::Adjusted,
        CollisionLaw::Impact,
    ]
    .map(|l| l.k(alpha, rho))
}

/// The column `fitbead k` adds after K's when rows carry slope errors: σ_K, the standard
/// uncertainty of K from the velocity's and the slope's ([`KRecord::estimate_with_slope`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub(crate) struct SigmaKRecord {
    /// σ_K; empty where there is no K or no σ.
    #[serde(rename = "sigma_K")]
    pub sigma_k: Option<f64>,
}

impl AutoRecord {
    /// The record of auto's choice of a model to invert eq 69 with.
    pub(crate) fn of_choice(c: KChoice) -> Self {
        AutoRecord {
            model_used: c.choice.name(),
            reason: c.reason,
        }
    }
}

/// The regime limits of a collision law at one ξ (`fitbead regimes`): δ_m (eq 32), δ_d
/// (eq 31), the bulk friction of eq 79, and the law's critical ξ (eq 32 = eq 31), below which
/// no steady regime exists. Angles in degrees.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RegimeRecord {
    /// Radius ratio ξ = R/r.
    pub xi: f64,
    /// α (eq 2).
    pub alpha_deg: f64,
    /// The law's K at this α.
    #[serde(rename = "K")]
    pub k: f64,
    /// δ_m: below it the bead stops (eq 32).
    pub delta_m_deg: f64,
    /// δ_d: above it the bead lifts off (eq 31).
    pub delta_d_deg: f64,
    /// Bulk friction μ of eq 79.
    pub mu_eq79: f64,
    /// `yes` where δ_m < δ_d (a steady regime exists), else `no`.
    pub steady_range: &'static str,
    /// The law's critical ξ; empty where there is none.
    pub critical_xi: Option<f64>,
}

impl RegimeRecord {
    /// The records of the ξ of `xi` under `law` with gyration parameter `rho`.
    pub fn table(xi: &[f64], law: CollisionLaw, rho: f64) -> Vec<RegimeRecord> {
        use crate::models::regimes::{
            alpha_of_xi, bulk_friction_law, critical_xi, delta_d_law, delta_m_law,
        };
        let critical = critical_xi(law, rho);
        xi.iter()
            .map(|&xi| {
                let alpha = alpha_of_xi(xi);
                let (dm, dd) = (delta_m_law(alpha, law, rho), delta_d_law(alpha, law, rho));
                RegimeRecord {
                    xi,
                    alpha_deg: alpha.to_degrees(),
                    k: law.k(alpha, rho),
                    delta_m_deg: dm.to_degrees(),
                    delta_d_deg: dd.to_degrees(),
                    mu_eq79: bulk_friction_law(alpha, law, rho),
                    steady_range: if dm < dd { "yes" } else { "no" },
                    critical_xi: critical,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_are_the_fields_in_order_with_their_serde_names() {
        let p = columns::<ParamRecord>();
        assert_eq!(p.len(), 33);
        assert_eq!(&p[..4], ["fit", "series", "parameter", "value"]);
        assert_eq!(&p[22..25], ["q2.5", "q50", "q97.5"]);
        assert_eq!(
            &p[29..],
            [
                "lsq_value",
                "prior_sensitivity",
                "likelihood_sensitivity",
                "prior_diagnosis"
            ]
        );
        assert_eq!(columns::<StatsRecord>().len(), 28);
        assert_eq!(columns::<ResidualRecord>().len(), 9);
        assert_eq!(columns::<CorrelationRecord>().len(), 5);
    }
}
