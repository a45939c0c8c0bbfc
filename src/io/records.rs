//! One typed record per row of the fit reports: a parameter ([`ParamRecord`], params.csv and
//! `--output`), the statistics of a fit ([`StatsRecord`], stats.csv and `--output-stats`), a
//! point against its fit ([`ResidualRecord`], residuals.csv) and a pair of parameters
//! ([`CorrelationRecord`], correlations.csv).
//!
//! Each record derives `serde::Serialize`; its columns are its fields, in order, with their
//! serde names ([`columns`]). Every writer reads the record: the CSV files (`to_csv`) and the
//! Python binding's dicts (through [`cells`]). A number is written as the shortest decimal
//! that reads back as the same double ([`crate::numfmt::fmt_f64`]), an absent or non-finite
//! number as an empty cell.

use crate::fit::summary::{FitResult, ParamRow, PointFit, StatsRow};
use crate::inverse::{ProfileEnd, SigmaKind};
use crate::numfmt::fmt_f64;
use serde::Serialize;
use serde_json::Value;

/// One cell of a record: what a writer needs to know of a field's value.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// Text.
    Text(String),
    /// A finite number.
    Number(f64),
    /// A count.
    Count(u64),
    /// A flag.
    Flag(bool),
    /// No value (an absent or non-finite number).
    Empty,
}

impl Cell {
    /// The cell as the CSV files write it.
    pub fn to_csv(&self) -> String {
        match self {
            Cell::Text(s) => s.clone(),
            Cell::Number(x) => fmt_f64(*x),
            Cell::Count(n) => n.to_string(),
            Cell::Flag(b) => b.to_string(),
            Cell::Empty => String::new(),
        }
    }
}

fn cell(v: Value) -> Cell {
    match v {
        Value::Null => Cell::Empty,
        Value::Bool(b) => Cell::Flag(b),
        Value::String(s) => Cell::Text(s),
        Value::Number(n) => match n.as_u64() {
            Some(k) if !n.is_f64() => Cell::Count(k),
            _ => n
                .as_f64()
                .filter(|x| x.is_finite())
                .map_or(Cell::Empty, Cell::Number),
        },
        // Records are flat: a nested value is written as JSON text.
        other => Cell::Text(other.to_string()),
    }
}

/// The record's (column, cell) pairs, in column order.
///
/// # Panics
/// If `R` does not serialise as a flat struct, which the records of this module all do.
pub fn cells<R: Serialize>(record: &R) -> Vec<(String, Cell)> {
    match serde_json::to_value(record).expect("a record serialises") {
        Value::Object(m) => m.into_iter().map(|(k, v)| (k, cell(v))).collect(),
        other => panic!("a record serialises as a struct, not {other}"),
    }
}

/// The columns of record type `R`, generated from its fields.
pub fn columns<R: Serialize + Default>() -> Vec<String> {
    cells(&R::default()).into_iter().map(|(k, _)| k).collect()
}

/// The records as CSV: the header from [`columns`], one row per record.
pub(crate) fn to_csv<R: Serialize + Default>(
    records: impl IntoIterator<Item = R>,
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(columns::<R>())?;
    for r in records {
        w.write_record(cells(&r).into_iter().map(|(_, c)| c.to_csv()))?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

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
            method: if m.is_some() { "mcmc" } else { "lsq" }.into(),
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
    /// parameters; a fit without a correlation matrix has none.
    pub fn of(fits: &[&FitResult]) -> Vec<Self> {
        let mut out = Vec::new();
        for f in fits {
            let Some(c) = &f.correlation else { continue };
            let names = f.param_names();
            let n = names.len().min(c.len());
            for i in 0..n {
                for j in i + 1..n {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_follow_the_csv_rules() {
        assert_eq!(cell(serde_json::json!(2.0)).to_csv(), "2");
        assert_eq!(cell(serde_json::json!(0.1)).to_csv(), "0.1");
        assert_eq!(cell(serde_json::json!(-0.0)).to_csv(), "-0");
        assert_eq!(cell(serde_json::json!(7u64)).to_csv(), "7");
        assert_eq!(cell(serde_json::json!(1e300)).to_csv(), "1e300");
        assert_eq!(cell(serde_json::to_value(f64::NAN).unwrap()), Cell::Empty);
        assert_eq!(
            cell(serde_json::to_value(None::<f64>).unwrap()),
            Cell::Empty
        );
        assert_eq!(cell(serde_json::json!(true)).to_csv(), "true");
    }

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
