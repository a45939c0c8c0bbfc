//! What every bead fit reports: one row per parameter (value, standard error, confidence
//! interval and how it was obtained) and one row of fit statistics, and their CSV forms.
//!
//! The interval in `ci_low`/`ci_high` is the profile-likelihood one where the profile closed
//! both of its ends (`ci_method = profile`): an end is where Δχ² reaches its threshold
//! (`found`) or the bound of the parameter's box (`bound`: no value beyond is admissible). An
//! end marked `edge` is where the constrained fits stop converging inside the feasible region
//! (their optimum lies against the region's edge, or the warm start left it) with Δχ² still
//! below its threshold: the interval reaches at least that far, and the reported end is the
//! farther of the edge and the covariance (Wald) interval's end on that side. An end the
//! search could not close (`not_found`) is the covariance interval's. Wherever an end is the
//! covariance interval's, `ci_method = covariance`; an end the profile found is kept either
//! way, so the interval holds every profile end found. The profile's state is in the extra
//! columns and the note; with neither interval the cells are empty and `ci_method = none`.

use crate::inverse::mcmc::ParameterDiagnostics;
pub use crate::inverse::posterior::Draws;
use crate::inverse::{
    ConfidenceIntervals, Covariance, Fit, LsqOptions, ProfileEnd, ProfileInterval, Residuals,
    SigmaKind, Termination,
};
use crate::numfmt::{fmt_f64, fmt_sig};

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamRow {
    /// Name of the fit (e.g. `klaw-c`, `jan-series`, `jan-global`, `jaeger`).
    pub fit: String,
    /// Series label, or `all` for a fit across series.
    pub series: String,
    /// Parameter name.
    pub parameter: String,
    /// Estimate.
    pub value: f64,
    /// Standard error from the covariance, if it exists.
    pub stderr: Option<f64>,
    /// Confidence level of the intervals.
    pub level: f64,
    /// Covariance (Wald) interval.
    pub cov: Option<(f64, f64)>,
    /// Profile-likelihood ends.
    pub profile: Option<(ProfileEnd, ProfileEnd)>,
    /// Unit of the parameter.
    pub unit: &'static str,
    /// True when the estimate sits on a bound of its box.
    pub at_bound: bool,
    /// The paper's value of the same parameter, for comparison.
    pub paper_value: Option<f64>,
    /// Where `paper_value` comes from.
    pub paper_source: &'static str,
    /// Anything the user should know about this parameter.
    pub note: String,
    /// The parameter's box (lower, upper); a covariance interval is cut to it.
    pub bounds: (f64, f64),
    /// The least-squares optimum (equal to `value` for a least-squares fit).
    pub lsq_value: Option<f64>,
    /// Posterior summary (MCMC only): `value` is then its median, `stderr` its sd.
    pub posterior: Option<ParameterDiagnostics>,
    /// How much the posterior of this parameter moves when the prior or the likelihood is
    /// power-scaled (MCMC only).
    pub sensitivity: Option<PowerScaling>,
    /// True when the parameter was held at `value`, not fitted (lmfit's `vary=False`): no
    /// standard error or interval, and it counts no degree of freedom.
    pub fixed: bool,
    /// The value the least-squares fit started from (lmfit's `init_value`; the value held for
    /// a parameter held), when the fit says.
    pub start: Option<f64>,
}

/// Power-scaling sensitivity of one parameter's posterior (`priorsense`'s diagnostic: the
/// derivative, in log₂ of the power, of the cumulative Jensen–Shannon distance between the
/// posterior and the posterior with that component raised to the power).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerScaling {
    /// Sensitivity to power-scaling the prior.
    pub prior: f64,
    /// Sensitivity to power-scaling the likelihood.
    pub likelihood: f64,
}

impl PowerScaling {
    /// `prior-driven` (sensitive to the prior, not to the likelihood: the data say little and
    /// the interval reflects the prior), `prior-data conflict` (sensitive to both), or empty.
    pub fn diagnosis(&self) -> &'static str {
        let t = crate::inverse::mcmc::sensitivity::SENSITIVITY_THRESHOLD;
        if self.prior >= t && self.likelihood >= t {
            "prior-data conflict"
        } else if self.prior >= t {
            "prior-driven"
        } else {
            ""
        }
    }
}

impl ParamRow {
    /// The reported interval and its method (module docs): per end, the profile's (found, or
    /// the box's bound); at an `edge`, the farther of the edge and the covariance end; where
    /// the profile could not close the end, the covariance end. `profile` when neither end is
    /// the covariance interval's, else `covariance`; `none` without either.
    pub fn interval(&self) -> (Option<(f64, f64)>, &'static str) {
        if let Some(d) = &self.posterior {
            return (Some(d.interval), "posterior");
        }
        let cov = self
            .cov
            .map(|(a, b)| (a.max(self.bounds.0), b.min(self.bounds.1)));
        let Some((lo, hi)) = self.profile else {
            return match cov {
                Some(c) => (Some(c), "covariance"),
                None => (None, "none"),
            };
        };
        // One end: its value, and whether it is the profile's.
        let end = |e: ProfileEnd, c: Option<f64>, lower: bool| -> (Option<f64>, bool) {
            match (e, c) {
                (ProfileEnd::Found(v) | ProfileEnd::Bound(v), _) => (Some(v), true),
                (ProfileEnd::Edge(v), Some(c)) if (lower && c < v) || (!lower && c > v) => {
                    (Some(c), false)
                }
                (ProfileEnd::Edge(v), _) => (Some(v), true),
                (ProfileEnd::NotFound, c) => (c, false),
            }
        };
        let (a, pa) = end(lo, cov.map(|c| c.0), true);
        let (b, pb) = end(hi, cov.map(|c| c.1), false);
        match (a, b) {
            (Some(a), Some(b)) if pa && pb => (Some((a, b)), "profile"),
            (Some(a), Some(b)) => (Some((a, b)), "covariance"),
            _ => (None, "none"),
        }
    }
}

/// Statistics of one fit.
#[derive(Debug, Clone, PartialEq)]
pub struct StatsRow {
    /// Name of the fit.
    pub fit: String,
    /// Series label, or `all`.
    pub series: String,
    /// Number of data points.
    pub n_points: usize,
    /// Number of fitted parameters.
    pub n_params: usize,
    /// χ² at the estimate.
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// χ²/dof.
    pub reduced_chi2: f64,
    /// AIC (see [`Fit::aic`]); NaN where undefined (χ² = 0 with no σ given, the note says so).
    pub aic: f64,
    /// BIC (see [`Fit::bic`]); NaN where AIC is.
    pub bic: f64,
    /// Termination reason (`scored` for a parameter-free law).
    pub termination: String,
    /// Whether the solver converged.
    pub converged: bool,
    /// Solver iterations.
    pub iterations: usize,
    /// Residual evaluations, profiles included.
    pub residual_evals: usize,
    /// `given` (σ absolute) or `estimated` (unit weights, covariance scaled by χ²/dof).
    pub sigma: SigmaKind,
    /// Condition number of the column-equilibrated Jacobian, if known.
    pub condition: Option<f64>,
    /// Anything the user should know about this fit.
    pub note: String,
    /// The sampler's account, for a posterior run.
    pub mcmc: Option<McmcStats>,
    /// True when the slopes were taken as measured with error: a least-squares fit is then
    /// an orthogonal distance regression (`method` = `odr`), and χ² its objective.
    pub slope_errors: bool,
    /// True when the covariance of σ given was scaled by the reduced χ² all the same
    /// (lmfit's `scale_covar=True`): standard errors and intervals are then those of relative
    /// σ.
    pub scale_covar: bool,
    /// The points whose normalised residual exceeds 4 in magnitude, when they are few enough
    /// to be outliers rather than a misfit of the whole curve (at most a fifth of the points,
    /// σ given; see [`FitResult::attach_points`]), each described by its series, slope,
    /// velocity and normalised residual.
    pub outliers: Vec<String>,
    /// χ² of the other points (the outliers' share left out), when there are outliers.
    pub others_chi2: f64,
}

/// A point whose normalised residual exceeds this in magnitude is named as an outlier: with
/// σ right and the model holding, one point in about 16,000 lies that far out (two-sided
/// normal tail at 4σ: 6.3e-5).
pub(crate) const OUTLIER_RESIDUAL: f64 = 4.0;

/// Outliers are named only while they are at most this fraction of the points (at least
/// one): beyond it the whole curve misses, or the units are wrong, and the misfit and unit
/// warnings say so instead.
const OUTLIER_SHARE: f64 = 0.2;

/// The median of `r` and its robust standard deviation, 1.4826 × the median absolute
/// deviation (the normal's σ for normal residuals), at least 1 (the σ the residuals are
/// normalised by); (0, 1) for no residuals.
fn robust_scale(r: &[f64]) -> (f64, f64) {
    fn median(mut x: Vec<f64>) -> f64 {
        if x.is_empty() {
            return 0.0;
        }
        x.sort_by(f64::total_cmp);
        let n = x.len();
        if n % 2 == 1 {
            x[n / 2]
        } else {
            0.5 * (x[n / 2 - 1] + x[n / 2])
        }
    }
    let m = median(r.to_vec());
    let mad = median(r.iter().map(|x| (x - m).abs()).collect());
    (m, (1.4826 * mad).max(1.0))
}

/// A fit with σ given whose reduced χ² exceeds this is flagged ([`StatsRow::absurd_misfit`]):
/// over 30 σ per point on average. The paper's models leave misfits of up to about 40 % of v̄
/// (§5.3), some 20 σ at the usual 2 % errors (reduced χ² near 400); far beyond that the
/// velocities or their σ are more likely in the wrong unit than the model wrong.
pub(crate) const ABSURD_REDUCED_CHI2: f64 = 1000.0;

/// A fit with σ given whose χ² tail probability, P(χ²_dof ≥ χ²), is below this is flagged as
/// a misfit ([`StatsRow::misfit_warning`]): with the model and σ right, one fit in a thousand.
pub(crate) const MISFIT_P_VALUE: f64 = 1e-3;

impl StatsRow {
    /// The row as one line, as the command line prints it on stderr when the statistics go
    /// nowhere else: `FIT [SERIES]: chi2 … dof … reduced … AIC … BIC … (termination)`, the
    /// numbers to 7 significant digits, and ` — note` when there is a note.
    pub fn summary_line(&self) -> String {
        format!(
            "{} [{}]: chi2 {} dof {} reduced {} AIC {} BIC {} ({}){}",
            self.fit,
            self.series,
            fmt_sig(self.chi2, 7),
            self.dof,
            fmt_sig(self.reduced_chi2, 7),
            fmt_sig(self.aic, 7),
            fmt_sig(self.bic, 7),
            self.termination,
            if self.note.is_empty() {
                String::new()
            } else {
                format!(" — {}", self.note)
            }
        )
    }

    /// The χ² tail probability P(χ²_dof ≥ χ²): the chance of a misfit at least this large if
    /// the model holds and σ is right. `None` without σ given (unit weights), with no degree of
    /// freedom, or where χ² is not a number; 0 where χ² is infinite.
    pub fn chi2_p_value(&self) -> Option<f64> {
        use statrs::distribution::{ChiSquared, ContinuousCDF};
        if self.sigma != SigmaKind::Absolute || self.dof == 0 || self.chi2.is_nan() {
            return None;
        }
        if self.chi2 == f64::INFINITY {
            return Some(0.0);
        }
        ChiSquared::new(self.dof as f64)
            .ok()
            .map(|d| d.sf(self.chi2.max(0.0)))
    }

    /// Why this fit's misfit should make the user doubt its intervals, if it should: the
    /// implausible misfit of [`StatsRow::absurd_misfit`] (a unit mistake), else a χ² tail
    /// probability below 0.001 with σ given (the model does not describe the data
    /// within their σ, and every interval assumes it does). A law whose χ² is infinite
    /// because some points have no steady state under it (termination `infeasible`) is not
    /// flagged again: its note says so.
    pub fn misfit_warning(&self) -> Option<String> {
        if let Some(w) = self.absurd_misfit() {
            return Some(w);
        }
        if self.termination == "infeasible" {
            return None;
        }
        if let Some(w) = self.outlier_warning() {
            return Some(w);
        }
        let p = self.chi2_p_value()?;
        (p < MISFIT_P_VALUE).then(|| {
            let p_text = if p == 0.0 {
                "p < 1e-300".to_string()
            } else {
                format!("p = {}", fmt_sig(p, 2))
            };
            format!(
                "misfit: chi2 = {} on {} degrees of freedom (reduced chi2 {}), chi2 tail \
                 probability {p_text}, below {}: the model does not describe these data within \
                 their sigma_v, and the intervals, which assume it does, are too narrow (check \
                 the model, the law and sigma_v)",
                fmt_sig(self.chi2, 5),
                self.dof,
                fmt_sig(self.reduced_chi2, 4),
                fmt_f64(MISFIT_P_VALUE)
            )
        })
    }

    /// The outliers' warning, if the fit has outliers ([`StatsRow::outliers`]): the points
    /// named, and the misfit of the others (their χ² and its tail probability).
    pub fn outlier_warning(&self) -> Option<String> {
        if self.outliers.is_empty() {
            return None;
        }
        let n = self.outliers.len();
        let rest = self.others_chi2;
        let dof = self.dof.saturating_sub(n);
        let others = if dof == 0 {
            String::new()
        } else {
            use statrs::distribution::{ChiSquared, ContinuousCDF};
            let p = ChiSquared::new(dof as f64).map_or(f64::NAN, |d| d.sf(rest));
            format!(
                "; the other points' chi2 at this fit, which {} pulls, = {} on {dof} degrees of \
                 freedom (tail probability {}{})",
                if n == 1 { "it" } else { "they" },
                fmt_sig(rest, 5),
                if p > 0.0 {
                    fmt_sig(p, 2)
                } else {
                    "< 1e-300".into()
                },
                if p < MISFIT_P_VALUE {
                    ": they misfit too, and the intervals, which assume the model holds, are \
                     too narrow"
                } else {
                    ""
                }
            )
        };
        Some(format!(
            "{n} outlier(s), |normalised residual| > {}: {}{others}; check {} (a misread \
             velocity or slope, a run that did not reach its steady state) before trusting \
             the intervals",
            fmt_f64(OUTLIER_RESIDUAL),
            self.outliers.join("; "),
            if n == 1 { "that point" } else { "those points" }
        ))
    }

    /// This row with [`StatsRow::misfit_warning`] appended to its note, as every report of
    /// it (the command line's stats.csv, the report, Python) shows it.
    pub fn with_misfit_note(&self) -> StatsRow {
        let mut s = self.clone();
        if let Some(w) = s.misfit_warning() {
            s.note = join(&s.note, &w);
        }
        s
    }

    /// Why this fit's misfit is implausible for the σ given, if it is: reduced χ² above
    /// `ABSURD_REDUCED_CHI2` with σ given (with unit weights χ² is in the units of v̄ and
    /// says nothing of units); `None` for a law scored without fitting.
    pub fn absurd_misfit(&self) -> Option<String> {
        // With outliers named, what the others leave is what could be a unit mistake.
        let n = self.outliers.len();
        let reduced = if n == 0 {
            self.reduced_chi2
        } else {
            self.others_chi2 / self.dof.saturating_sub(n).max(1) as f64
        };
        (self.sigma == SigmaKind::Absolute
            && self.n_params > 0
            && reduced.is_finite()
            && reduced > ABSURD_REDUCED_CHI2)
            .then(|| {
                format!(
                    "reduced chi2 = {} with sigma given (over {}): are the velocities \
                     dimensionless, and sigma_v in the same unit as v?",
                    fmt_sig(self.reduced_chi2, 5),
                    fmt_f64(ABSURD_REDUCED_CHI2)
                )
            })
    }
}

/// What a posterior run did (the `method = mcmc` columns of the statistics report).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct McmcStats {
    /// `converged`, `max_steps`, `interrupted` or `failed` (the sampler could not start).
    pub status: String,
    /// Walkers of the ensemble.
    pub walkers: usize,
    /// Steps run (each moves every walker once).
    pub steps: usize,
    /// Steps discarded as burn-in.
    pub burn_in: usize,
    /// Draws kept (all walkers, after burn-in and thinning).
    pub draws: usize,
    /// Fraction of proposals accepted.
    pub acceptance: f64,
    /// Smallest bulk or tail ESS over the parameters; NaN where one could not be estimated
    /// (too few draws).
    pub ess_min: f64,
    /// Largest rank-normalised split-R̂ over the parameters; NaN where one could not be
    /// estimated.
    pub rhat_max: f64,
    /// WAIC, its effective number of parameters p_waic and the standard error of WAIC (see
    /// [`super::posterior`]); `None` without draws.
    pub waic: Option<(f64, f64, f64)>,
    /// Why the run did not sample at all (status `failed`), when it did not.
    pub failure: Option<McmcFailure>,
}

/// Why a posterior run could not sample.
#[derive(Debug, Clone, PartialEq)]
pub enum McmcFailure {
    /// A prior whose support does not meet the parameter's feasible box: the posterior is
    /// zero everywhere. A fault of the prior given, not of the data.
    PriorOutsideBox {
        /// The parameter.
        parameter: String,
        /// The prior, as given (e.g. `uniform(10,20)`).
        prior: String,
        /// The prior's support.
        support: (f64, f64),
        /// The parameter's feasible box (where every point has a steady state, cut to the
        /// parameter's domain).
        feasible: (f64, f64),
    },
    /// The sampler refused to start (no walker with a finite posterior density, a bad
    /// option, …), with why.
    NotStarted(String),
}

impl std::fmt::Display for McmcFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            McmcFailure::PriorOutsideBox {
                parameter,
                prior,
                support,
                feasible,
            } => write!(
                f,
                "the prior {parameter}={prior} has support [{}, {}], which does not meet the \
                 feasible box [{}, {}] of {parameter} (where every point has a steady state): \
                 the posterior is zero everywhere; give a prior that overlaps the box",
                fmt_sig(support.0, 6),
                fmt_sig(support.1, 6),
                fmt_sig(feasible.0, 6),
                fmt_sig(feasible.1, 6),
            ),
            McmcFailure::NotStarted(why) => write!(f, "MCMC could not start: {why}"),
        }
    }
}

/// One fit: its parameters with their uncertainties, its statistics, the correlations, every
/// point against the fitted curve and, for a posterior run, the draws. `Display` prints a
/// one-screen fit report, in the spirit of lmfit's `fit_report`: the statistics, each
/// parameter ± standard error with its interval, the correlations above 0.1 and warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct FitResult {
    /// One row per parameter.
    pub params: Vec<ParamRow>,
    /// The statistics.
    pub stats: StatsRow,
    /// The kept draws of a posterior run (rows of `params` give the parameter order).
    pub draws: Option<Draws>,
    /// Correlation matrix of the parameters, in the order of `params` (least squares: from
    /// the covariance at the optimum; posterior: of the draws); `None` when it does not exist.
    pub correlation: Option<Vec<Vec<f64>>>,
    /// Weighted residuals (v_i − v̄_i)/σ_i at the reported estimate, in the problem's point
    /// order (unit σ when the data carry none).
    pub residuals: Vec<f64>,
    /// Every point of the fit against the fitted v̄ (empty for a fit not made on a
    /// [`Dataset`](super::data::Dataset)).
    pub points: Vec<PointFit>,
}

/// One measured point against its fit.
#[derive(Debug, Clone, PartialEq)]
pub struct PointFit {
    /// Series label.
    pub series: String,
    /// Radius ratio ξ.
    pub xi: f64,
    /// Slope δ in degrees.
    pub delta_deg: f64,
    /// Measured dimensionless mean velocity v̄.
    pub v: f64,
    /// Its standard deviation, when the data carry one.
    pub sigma_v: Option<f64>,
    /// The fitted v̄ at this point (NaN where the point has no steady state at the estimate).
    pub v_fit: f64,
    /// v − v_fit.
    pub residual: f64,
    /// (v − v_fit)/σ; without σ, divided by the scatter estimated from the fit,
    /// sqrt(χ²/dof).
    pub normalised_residual: f64,
    /// The adjusted slope, degrees, when the fit treated the slopes as measured with error
    /// (orthogonal distance regression); `None` otherwise.
    pub delta_fit_deg: Option<f64>,
    /// (δ_fit − δ)/σ_δ, when the slope carries an uncertainty σ_δ > 0 in such a fit.
    pub delta_residual: Option<f64>,
}

/// A parameter name that a fit does not have.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("no parameter '{name}' in this fit (it has: {have})")]
pub struct NoSuchParameter {
    /// The name asked for.
    pub name: String,
    /// The names the fit has, comma-separated.
    pub have: String,
}

impl FitResult {
    /// The parameter called `name`; a fit with one parameter per series (`K` of
    /// `free-per-series`) names them `K[series]`, and `K` alone is the first.
    pub fn param(&self, name: &str) -> Result<&ParamRow, NoSuchParameter> {
        self.params
            .iter()
            .find(|r| r.parameter == name || self.qualified_name(r) == name)
            .ok_or_else(|| NoSuchParameter {
                name: name.to_string(),
                have: self.param_names().join(", "),
            })
    }

    /// The parameters' names, qualified by series where a fit has one per series.
    pub fn param_names(&self) -> Vec<String> {
        self.params.iter().map(|r| self.qualified_name(r)).collect()
    }

    fn qualified_name(&self, r: &ParamRow) -> String {
        if r.series == self.stats.series {
            r.parameter.clone()
        } else {
            format!("{}[{}]", r.parameter, r.series)
        }
    }

    /// The correlation of parameters `a` and `b`, when the matrix exists.
    pub fn correlation_of(&self, a: &str, b: &str) -> Option<f64> {
        let names = self.param_names();
        let i = names.iter().position(|n| n == a)?;
        let j = names.iter().position(|n| n == b)?;
        self.correlation.as_ref().map(|c| c[i][j])
    }

    /// χ² at the estimate.
    pub fn chi2(&self) -> f64 {
        self.stats.chi2
    }

    /// χ²/dof.
    pub fn reduced_chi2(&self) -> f64 {
        self.stats.reduced_chi2
    }

    /// Akaike's information criterion.
    pub fn aic(&self) -> f64 {
        self.stats.aic
    }

    /// The Bayesian information criterion.
    pub fn bic(&self) -> f64 {
        self.stats.bic
    }

    /// Whether the solver converged (and, for a posterior run, the sampler met its R̂ and
    /// ESS thresholds).
    pub fn converged(&self) -> bool {
        self.stats.converged
    }

    /// Every kept posterior draw of parameter `name`, all walkers pooled (`None` for a
    /// least-squares fit or an unknown name).
    pub fn draws_of(&self, name: &str) -> Option<Vec<f64>> {
        let d = self.draws.as_ref()?;
        let j = self.param_names().iter().position(|n| n == name)?;
        Some(
            d.chains
                .iter()
                .flat_map(|c| c.iter().map(move |x| x[j]))
                .collect(),
        )
    }

    /// Fills [`FitResult::points`] from the data the fit was made on: `data.points[i]` for
    /// each `i` of `index`, in the problem's order (the order of [`FitResult::residuals`]).
    pub fn attach_points(&mut self, data: &super::data::Dataset, index: &[usize]) {
        let scatter = if data.sigma == SigmaKind::Relative {
            let s = self.stats.reduced_chi2.sqrt();
            if s > 0.0 && s.is_finite() {
                s
            } else {
                f64::NAN
            }
        } else {
            1.0
        };
        self.points = index
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let p = &data.points[i];
                let r = self.residuals.get(k).copied().unwrap_or(f64::NAN);
                let residual = r * p.sigma;
                PointFit {
                    series: data.labels[p.series].clone(),
                    xi: p.scene.xi,
                    delta_deg: p.scene.delta_deg(),
                    v: p.v,
                    sigma_v: (data.sigma == SigmaKind::Absolute).then_some(p.sigma),
                    v_fit: p.v - residual,
                    residual,
                    normalised_residual: r / scatter,
                    delta_fit_deg: None,
                    delta_residual: None,
                }
            })
            .collect();
        self.name_outliers();
    }

    /// Fills [`StatsRow::outliers`] from the points: with σ given, those whose normalised
    /// residual exceeds `OUTLIER_RESIDUAL` (4) in magnitude and lies as many robust standard
    /// deviations from the median residual (1.4826 × the median absolute deviation, at least
    /// 1), while they are at most a fifth of the points (at least one). The second test keeps
    /// the points that one far outlier drags off the curve from being named with it.
    fn name_outliers(&mut self) {
        self.stats.outliers.clear();
        self.stats.others_chi2 = 0.0;
        if self.stats.sigma != SigmaKind::Absolute || !self.stats.chi2.is_finite() {
            return;
        }
        let r: Vec<f64> = self
            .points
            .iter()
            .map(|p| p.normalised_residual)
            .filter(|r| r.is_finite())
            .collect();
        let (centre, spread) = robust_scale(&r);
        let far: Vec<&PointFit> = self
            .points
            .iter()
            .filter(|p| {
                let r = p.normalised_residual;
                r.abs() > OUTLIER_RESIDUAL && (r - centre).abs() > OUTLIER_RESIDUAL * spread
            })
            .collect();
        let most = ((OUTLIER_SHARE * self.points.len() as f64).floor() as usize).max(1);
        if far.is_empty() || far.len() > most {
            return;
        }
        self.stats.others_chi2 = self
            .points
            .iter()
            .filter(|p| !far.iter().any(|q| std::ptr::eq(*q, *p)))
            .map(|p| p.normalised_residual * p.normalised_residual)
            .sum();
        for p in far {
            self.stats.outliers.push(format!(
                "series '{}', delta {} deg, v {} (normalised residual {})",
                crate::numfmt::clip(&p.series, crate::numfmt::ECHO_CHARS),
                fmt_sig(p.delta_deg, 6),
                fmt_sig(p.v, 6),
                fmt_sig(p.normalised_residual, 3)
            ));
        }
    }
}

impl ParamRow {
    /// Lower end of the reported interval (`None` when there is none).
    pub fn interval_low(&self) -> Option<f64> {
        self.interval().0.map(|i| i.0)
    }

    /// Upper end of the reported interval.
    pub fn interval_high(&self) -> Option<f64> {
        self.interval().0.map(|i| i.1)
    }

    /// How the reported interval was obtained: `profile`, `covariance`, `posterior` or `none`.
    pub fn interval_method(&self) -> &'static str {
        self.interval().1
    }
}

/// A parameter's name, unit, the paper's value (with its source) if there is one, and its
/// default prior for a posterior run.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ParamSpec {
    /// Name.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// The paper's value.
    pub paper_value: Option<f64>,
    /// Where the paper's value comes from.
    pub paper_source: &'static str,
    /// Default prior of a posterior run; `None` for flat on the parameter's box (see
    /// [`super::posterior`]).
    pub default_prior: Option<crate::inverse::posterior::Prior>,
}

fn termination_name(t: Termination) -> &'static str {
    match t {
        Termination::ExactFit => "exact_fit",
        Termination::RelativeReduction => "relative_reduction",
        Termination::StepSize => "step_size",
        Termination::Gradient => "gradient",
        Termination::MaxIterations => "max_iterations",
        Termination::MaxEvaluations => "max_evaluations",
        Termination::InfeasibleStart => "infeasible_start",
        Termination::JacobianFailed => "jacobian_failed",
        Termination::Stalled => "stalled_at_feasibility_edge",
        Termination::Interrupted => "interrupted",
    }
}

/// A finished least-squares fit with what its summary needs: the fit's name and series, the
/// parameters' specifications, the problem, the solver's result and options, and the
/// confidence level of the intervals.
pub(crate) struct Solved<'a, R: ?Sized> {
    /// Name of the fit (e.g. `klaw-c`).
    pub name: &'a str,
    /// Series label, or `all`.
    pub series: &'a str,
    /// One specification per parameter.
    pub specs: &'a [ParamSpec],
    /// The problem that was solved.
    pub problem: &'a R,
    /// The solver's result.
    pub fit: &'a Fit,
    /// Confidence level of the intervals, in (0, 1).
    pub level: f64,
    /// The solver's options (bounds, σ convention).
    pub options: &'a LsqOptions,
    /// How many distinct points the fit sees (points at the same abscissae count once; see
    /// `distinct_points`), when the fit counts them: with fewer than the parameters the
    /// data cannot determine them all.
    pub distinct: Option<usize>,
    /// The size ‖y/σ‖ of the weighted observations, when the fit gives it: with no σ given, a
    /// χ² within the rounding of the data (`ROUNDING` · ‖y/σ‖, squared) estimates the
    /// scatter as 0 as χ² = 0 does.
    pub observed_norm: Option<f64>,
}

/// The relative size of residuals that are rounding, not scatter: 256 ε (5.7e-14) of the
/// observations' size. A model evaluated in double precision matches data it can reproduce
/// to a few ulp; no measured scatter is that small.
pub(crate) const ROUNDING: f64 = 256.0 * f64::EPSILON;

/// ‖y/σ‖ of observations `y` with σ `s` (see [`Solved::observed_norm`]).
pub(crate) fn observed_norm<'a>(y: impl IntoIterator<Item = (&'a f64, &'a f64)>) -> f64 {
    y.into_iter()
        .map(|(y, s)| (y / s) * (y / s))
        .sum::<f64>()
        .sqrt()
}

/// Whether `chi2` is 0 or within the rounding of observations of size `norm` (see
/// [`Solved::observed_norm`]): a scale of the scatter fitted to it is 0.
pub(crate) fn chi2_vanishes(chi2: f64, norm: Option<f64>) -> bool {
    chi2 == 0.0 || norm.is_some_and(|n| chi2 <= (ROUNDING * n) * (ROUNDING * n))
}

/// Whether a fit with no σ given estimates the scatter as 0 ([`chi2_vanishes`]).
fn scatter_vanishes(f: &Fit, norm: Option<f64>) -> bool {
    f.sigma == SigmaKind::Relative && chi2_vanishes(f.chi2, norm)
}

/// The number of distinct abscissae among `keys` (compared bit for bit).
pub(crate) fn distinct_points<const N: usize>(keys: impl IntoIterator<Item = [f64; N]>) -> usize {
    let set: std::collections::HashSet<[u64; N]> =
        keys.into_iter().map(|k| k.map(f64::to_bits)).collect();
    set.len()
}

/// Why the data of a converged least-squares fit do not determine its parameters, if they do
/// not: fewer distinct points than parameters; a Jacobian rank deficient at the estimate with
/// no parameter on a bound of its box (a direction along which χ² does not change); or, with
/// no σ given, χ² = 0 or within the rounding of observations of size `norm` (a scatter
/// estimated as 0 leaves intervals of zero width). Such a fit reports no standard errors,
/// correlations or intervals.
fn undetermined(
    f: &Fit,
    n_params: usize,
    distinct: Option<usize>,
    norm: Option<f64>,
) -> Option<String> {
    if !f.converged() {
        return None;
    }
    if let Some(d) = distinct.filter(|&d| d < n_params) {
        return Some(format!(
            "{d} distinct point(s) for {n_params} parameters: the data do not determine the \
             parameters; no standard errors or intervals"
        ));
    }
    let no_dof = (f.sigma == SigmaKind::Relative || f.scale_covar) && f.dof == 0;
    if f.covariance.is_none() && !no_dof && !f.at_bound.iter().any(|b| *b) {
        return Some(
            "Jacobian rank deficient at the estimate: the data do not determine the \
             parameters; no standard errors or intervals"
                .into(),
        );
    }
    if f.sigma == SigmaKind::Relative && f.chi2 == 0.0 {
        return Some(
            "chi2 = 0 with no sigma given: the scatter is estimated as 0; no standard errors \
             or intervals"
                .into(),
        );
    }
    if scatter_vanishes(f, norm) {
        return Some(format!(
            "chi2 = {} is rounding (the residuals are within {} of the data) with no sigma \
             given: the scatter is estimated as 0; no standard errors or intervals",
            fmt_sig(f.chi2, 3),
            fmt_sig(ROUNDING, 2)
        ));
    }
    None
}

impl<R: ?Sized> Clone for Solved<'_, R> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<R: ?Sized> Copy for Solved<'_, R> {}

/// Builds the summary of a finished fit: covariance intervals, and profile intervals when
/// `profile` is set and the fit converged.
pub(crate) fn summarise<R: Residuals + ?Sized>(s: Solved<'_, R>, profile: bool) -> FitResult {
    summarise_with_profiles(s, |s| {
        if profile {
            ConfidenceIntervals::compute(s.problem, s.fit, s.level, s.options)
                .ok()
                .map(|c| c.profile)
        } else {
            None
        }
    })
}

/// As [`summarise`], with the profile intervals (one per parameter) from `profiles`, called
/// only when the fit converged (a problem whose parameters are independent of one another
/// can profile each on its own residuals).
pub(crate) fn summarise_with_profiles<R: Residuals + ?Sized>(
    s: Solved<'_, R>,
    profiles: impl FnOnce(&Solved<'_, R>) -> Option<Vec<ProfileInterval>>,
) -> FitResult {
    let Solved {
        name: fit_name,
        series,
        specs,
        problem: _,
        fit: f,
        level,
        options: opts,
        distinct,
        observed_norm,
    } = s;
    let mut note = String::new();
    let unknown = undetermined(f, specs.len(), distinct, observed_norm);
    let ci = if unknown.is_some() {
        None
    } else if f.converged() && f.chi2.is_finite() {
        profiles(&s).filter(|p| p.len() == specs.len())
    } else {
        note = format!(
            "not converged ({}): values are where the solver stopped, no intervals",
            termination_name(f.termination)
        );
        None
    };
    let wald = if f.converged() && unknown.is_none() {
        crate::inverse::covariance_intervals(f, level)
            .ok()
            .flatten()
    } else {
        None
    };
    if let Some(why) = &unknown {
        note = why.clone();
    } else if f.converged() && f.covariance.is_none() {
        note = no_covariance(f).into();
    }
    let (aic, bic) = aic_bic(f, observed_norm, &mut note);
    let mut evals = f.residual_evals;
    let params = specs
        .iter()
        .enumerate()
        .map(|(j, s)| {
            let prof = ci.as_ref().map(|c| (c[j].lower, c[j].upper));
            if let Some(c) = &ci {
                evals += c[j].residual_evals;
            }
            let bounds = (
                opts.lower.as_ref().map_or(f64::NEG_INFINITY, |l| l[j]),
                opts.upper.as_ref().map_or(f64::INFINITY, |u| u[j]),
            );
            let cov = wald.as_ref().map(|w| (w[j].lower, w[j].upper));
            let pnote = param_note(f, j, bounds, cov, prof, unknown.is_some(), (level, s.name));
            ParamRow {
                fit: fit_name.to_string(),
                series: series.to_string(),
                parameter: s.name.to_string(),
                value: f.params[j],
                stderr: if f.converged() && unknown.is_none() {
                    f.std_errors().map(|se| se[j])
                } else {
                    None
                },
                level,
                cov,
                profile: prof,
                unit: s.unit,
                at_bound: f.at_bound.get(j).copied().unwrap_or(false),
                paper_value: s.paper_value,
                paper_source: s.paper_source,
                note: pnote,
                bounds,
                lsq_value: Some(f.params[j]),
                posterior: None,
                sensitivity: None,
                fixed: false,
                start: None,
            }
        })
        .collect();
    FitResult {
        params,
        stats: StatsRow {
            fit: fit_name.to_string(),
            series: series.to_string(),
            n_points: f.residuals.len().max(f.dof + specs.len()),
            n_params: specs.len(),
            chi2: f.chi2,
            dof: f.dof,
            reduced_chi2: f.reduced_chi2,
            aic,
            bic,
            termination: termination_name(f.termination).to_string(),
            converged: f.converged(),
            iterations: f.iterations,
            residual_evals: evals,
            sigma: f.sigma,
            condition: f.covariance.as_ref().map(|c| c.condition),
            note,
            mcmc: None,
            slope_errors: false,
            scale_covar: f.scale_covar && f.sigma == SigmaKind::Absolute,
            outliers: Vec::new(),
            others_chi2: 0.0,
        },
        draws: None,
        correlation: f
            .covariance
            .as_ref()
            .filter(|_| unknown.is_none())
            .map(correlation_rows),
        residuals: f.residuals.clone(),
        points: Vec::new(),
    }
}

/// Why the converged fit `f` has no covariance: no degree of freedom for the scale it
/// estimates, or a Jacobian rank deficient at the estimate.
fn no_covariance(f: &Fit) -> &'static str {
    match f.sigma {
        _ if f.dof > 0 => "Jacobian rank deficient at the estimate: no covariance",
        SigmaKind::Relative => {
            "no degree of freedom left to estimate the scatter (no sigma given): no covariance"
        }
        SigmaKind::Absolute if f.scale_covar => {
            "no degree of freedom left to scale the covariance (scale_covar): no covariance"
        }
        SigmaKind::Absolute => "Jacobian rank deficient at the estimate: no covariance",
    }
}

/// The note of parameter `j` of the fit `f` (box `bounds`, covariance interval `cov`,
/// profile ends `prof`; `undetermined` when the data do not determine it): an interval cut to
/// the box, a parameter on a bound, no standard error, and what the profile's ends say.
fn param_note(
    f: &Fit,
    j: usize,
    bounds: (f64, f64),
    cov: Option<(f64, f64)>,
    prof: Option<(ProfileEnd, ProfileEnd)>,
    undetermined: bool,
    (level, name): (f64, &str),
) -> String {
    let mut pnote = String::new();
    let profile_closed =
        prof.is_some_and(|(lo, hi)| closed_end(lo).is_some() && closed_end(hi).is_some());
    if let Some((a, b)) = cov {
        if !profile_closed && (a < bounds.0 || b > bounds.1) {
            pnote.push_str("covariance interval cut to the parameter's box. ");
        }
    }
    if f.at_bound.get(j).copied().unwrap_or(false) {
        pnote.push_str("on a bound of its box; the covariance ignores the bound. ");
    }
    if undetermined {
        pnote.push_str("not determined by the data: no standard error or interval. ");
    }
    if let Some(ends) = prof {
        push_profile_notes(&mut pnote, ends, level, name);
    }
    pnote.trim_end().to_string()
}

/// AIC and BIC of the fit `f`, undefined (NaN, with why appended to `note`) where the
/// likelihood is unbounded: with no σ given, −2 ln L = m ln(2π χ²/m) + m is unbounded below
/// at χ² = 0, and within the rounding of the data (‖y/σ‖ = `observed_norm`) χ² is 0 in all
/// but its noise, and so are AIC and BIC.
fn aic_bic(f: &Fit, observed_norm: Option<f64>, note: &mut String) -> (f64, f64) {
    if f.aic == f64::NEG_INFINITY
        || f.bic == f64::NEG_INFINITY
        || scatter_vanishes(f, observed_norm)
    {
        let why = if f.chi2 == 0.0 {
            "chi2 = 0: AIC and BIC undefined (the likelihood with the scatter estimated is \
             unbounded)"
        } else {
            "chi2 is rounding: AIC and BIC undefined (the likelihood with the scatter estimated \
             is unbounded)"
        };
        *note = if note.is_empty() {
            why.into()
        } else {
            format!("{note}; {why}")
        };
        (f64::NAN, f64::NAN)
    } else {
        (f.aic, f.bic)
    }
}

/// Appends to `pnote` what the profile interval's ends (lower, upper) of the parameter
/// `name` at `level` say when they are not found points.
fn push_profile_notes(
    pnote: &mut String,
    (lo, hi): (ProfileEnd, ProfileEnd),
    level: f64,
    name: &str,
) {
    for (end, which) in [(lo, "lower"), (hi, "upper")] {
        match end {
            ProfileEnd::Found(_) => {}
            ProfileEnd::Bound(b) => pnote.push_str(&format!(
                "profile {which} end reaches the bound {}. ",
                fmt_f64(b)
            )),
            ProfileEnd::Edge(e) => pnote.push_str(&format!(
                "profile {which} end reaches the edge of the model's feasible region at {} \
                 (the constrained fits beyond it do not converge; the interval reaches at \
                 least there). ",
                fmt_f64(e)
            )),
            ProfileEnd::NotFound => pnote.push_str(&format!(
                "profile {which} end not found: the likelihood does not fall by the \
                 {} % threshold on that side within the search, so the data do not \
                 bound {} there. ",
                fmt_sig(100.0 * level, 6),
                name
            )),
        }
    }
}

/// The correlation matrix of a covariance, as rows.
fn correlation_rows(c: &Covariance) -> Vec<Vec<f64>> {
    (0..c.correlation.nrows())
        .map(|i| {
            (0..c.correlation.ncols())
                .map(|j| c.correlation[(i, j)])
                .collect()
        })
        .collect()
}

impl FitResult {
    /// A law scored with nothing fitted: residuals `r` (NaN where a point has no value), its
    /// χ², AIC and BIC, termination `scored`; or, with `infeasible` the reason some point has
    /// no value, χ² = AIC = BIC = ∞, termination `infeasible` and the reason as the note.
    /// Every residual is a degree of freedom. `params`: the rows of the values scored at.
    pub(crate) fn scored(
        (fit, series): (String, String),
        r: Vec<f64>,
        sigma: SigmaKind,
        infeasible: Option<String>,
        params: Vec<ParamRow>,
    ) -> FitResult {
        let m = r.len();
        let (chi2, termination, note) = match infeasible {
            None => (
                r.iter().map(|x| x * x).sum::<f64>(),
                "scored",
                String::new(),
            ),
            Some(why) => (f64::INFINITY, "infeasible", why),
        };
        let (aic, bic) = if chi2.is_finite() {
            information_criteria(&r, sigma)
        } else {
            (f64::INFINITY, f64::INFINITY)
        };
        FitResult {
            params,
            stats: StatsRow {
                fit,
                series,
                n_points: m,
                n_params: 0,
                chi2,
                dof: m,
                reduced_chi2: if m > 0 { chi2 / m as f64 } else { f64::NAN },
                aic,
                bic,
                termination: termination.into(),
                converged: chi2.is_finite(),
                iterations: 0,
                residual_evals: 1,
                sigma,
                condition: None,
                note,
                mcmc: None,
                slope_errors: false,
                scale_covar: false,
                outliers: Vec::new(),
                others_chi2: 0.0,
            },
            draws: None,
            correlation: None,
            residuals: r,
            points: Vec::new(),
        }
    }
}

/// AIC and BIC of a parameter-free model with residuals `r` (conventions of [`Fit::aic`]).
pub(crate) fn information_criteria(r: &[f64], sigma: SigmaKind) -> (f64, f64) {
    let m = r.len() as f64;
    let chi2: f64 = r.iter().map(|x| x * x).sum();
    match sigma {
        SigmaKind::Absolute => (chi2, chi2),
        SigmaKind::Relative => {
            let m2ll = m * ((2.0 * std::f64::consts::PI * chi2 / m).ln() + 1.0);
            (m2ll + 2.0, m2ll + m.ln())
        }
    }
}

/// An end that closes the profile interval: Δχ² reached its threshold, or the box ends there.
fn closed_end(e: ProfileEnd) -> Option<f64> {
    match e {
        ProfileEnd::Found(v) | ProfileEnd::Bound(v) => Some(v),
        _ => None,
    }
}

/// Two notes as one, `a; b` (either alone where the other is empty).
pub(crate) fn join(a: &str, b: &str) -> String {
    match (a.is_empty(), b.is_empty()) {
        (true, _) => b.to_string(),
        (_, true) => a.to_string(),
        _ => format!("{a}; {b}"),
    }
}

/// Several fits made together (Jan's per-series and global laws, Jaeger's per-series fits), with
/// the reasons any fit was not made.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSet {
    /// The fits, in the order they were made.
    pub fits: Vec<FitResult>,
    /// Why a fit was not made (too few points in a series, no start, …).
    pub notes: Vec<String>,
}

impl FitSet {
    /// The fit named `name` (e.g. `jan-series`) of series `series` (`all` for a fit across
    /// series).
    pub fn get(&self, name: &str, series: &str) -> Option<&FitResult> {
        self.fits
            .iter()
            .find(|f| f.stats.fit == name && f.stats.series == series)
    }

    /// Whether every fit converged.
    pub fn converged(&self) -> bool {
        self.fits.iter().all(|f| f.converged())
    }
}
