//! Bayesian posteriors of the bead fits: the least-squares problems of [`super::klaw`],
//! [`super::jan`] and [`super::jaeger`] turned into log densities and sampled by the ensemble
//! sampler of [`crate::inverse::mcmc`], started from the least-squares optimum.
//!
//! Likelihood: independent Gaussian errors, with the weighted residuals of the least-squares
//! problem r_i = (v_i − v̄_th,i)/σ_i (same problem, same residuals):
//! - σ given on every row: ln L = −χ²/2;
//! - with a scale s (parameter `sigma_scale`) multiplying every σ: ln L = −m ln s − χ²/(2s²).
//!   It is always sampled when no σ is given (unit weights: s is then the scatter itself, in
//!   the units of v̄), and on request ([`McmcSettings::fit_scatter`]) when the given σ may be
//!   underestimated.
//!
//! Priors, per parameter by name ([`Prior`]): by default flat on the parameter's box (for the
//! K(α) laws that box is exact: it is where every point stays in regime B), and Jeffreys'
//! 1/s for `sigma_scale`. Jaeger's a1, a2, a3 are the exception: as a2 → ∞ the resistance
//! term a1/(1 + a2 X) vanishes and the likelihood tends to a constant, so a flat prior would
//! leave the posterior improper; their defaults are half-normal with scales 10, 100 and 10,
//! over 50 times the paper's Fig. 9 values (a1 ≤ 0.19, a2 ≤ 27.7, a3 ≤ 1.41), weak wherever
//! the data say anything. The support is the box intersected with the set where every point
//! has a steady state under the model: the log density is −∞ wherever the residuals are
//! [`Infeasible`](crate::inverse::Infeasible), never NaN.
//!
//! Coordinates: a parameter whose box is [0, ∞), and the scale, is sampled as ln x; Jaeger's
//! a1, a2, a3 in the coordinates of `super::jaeger_coordinates` (the velocity at the
//! series' mean slope, the slope of the law there and a shape), through
//! `summarise_reparameterised`. Either way the log density carries the Jacobian, so the
//! priors are those of the parameters, and the sampler records the parameters: the draws and
//! the R̂, ESS and τ that decide convergence are theirs.
//!
//! The report keeps the least-squares row format: `value` is the posterior median, `stderr`
//! the posterior standard deviation, and `ci_low`/`ci_high` the central posterior interval at
//! the level asked (`ci_method = posterior`); the covariance interval of the least-squares
//! optimum stays in `cov_low`/`cov_high` and the optimum in `lsq_value`.

use super::data::Dataset;
use super::summary::{
    chi2_vanishes, join, summarise, FitResult, McmcFailure, McmcStats, ParamRow, ParamSpec,
    PowerScaling, Solved,
};
use crate::inverse::mcmc::sensitivity::sensitivity;
use crate::inverse::mcmc::{EnsembleSampler, McmcError, McmcOptions, McmcResult, StopReason};
use crate::inverse::posterior::Posterior;
pub use crate::inverse::posterior::Reparameterisation;
pub use crate::inverse::posterior::{Draws, McmcSettings, Method, Prior};
pub(crate) use crate::inverse::posterior::{SharedProgress, SCALE_NAME};
use crate::inverse::{Fit, Residuals, SigmaKind};
use crate::numfmt::{fmt_f64, fmt_sig};
use crate::progress::ProgressEvent;
use rayon::prelude::*;

/// `fit` applied to every series of `data` (its index and label, and the method to fit it
/// by), the series side by side, the results in the series' order. The series are
/// independent fits whose sampler streams depend on the seed alone, so the results are those
/// of one series after the other; under MCMC the series share `method`'s progress sink
/// ([`SharedProgress`]).
pub(crate) fn per_series<T: Send>(
    data: &Dataset,
    method: &Method,
    fit: impl Fn(usize, &str, &Method) -> T + Sync,
) -> Vec<T> {
    let shared = SharedProgress::of(method);
    data.labels
        .par_iter()
        .enumerate()
        .map(|(s, label)| fit(s, label, &shared.method()))
        .collect()
}

/// The column naming a parameter in the draws file: its name, with the series appended where
/// a fit across series has one parameter per series (`K[series]`).
pub(crate) fn draws_column(fit: &FitResult, row: &ParamRow) -> String {
    if row.series == fit.stats.series {
        row.parameter.clone()
    } else {
        format!("{}[{}]", row.parameter, row.series)
    }
}

/// Summarises a finished least-squares fit by `method`: [`summarise`] for least squares, or
/// a posterior run started from the optimum (module docs) for MCMC.
pub(crate) fn summarise_with<R: Residuals + Sync + ?Sized>(
    method: &Method,
    solved: Solved<'_, R>,
) -> FitResult {
    match method {
        Method::Lsq { profile, .. } => summarise(solved, *profile),
        Method::Mcmc(s) => sample(s, solved, None),
    }
}

/// As [`summarise_with`], with a posterior run sampling the parameters in the coordinates of
/// `transform` (the priors, draws and reported values stay those of the parameters; see
/// [`Reparameterisation`]). Least squares ignores `transform`.
pub(crate) fn summarise_reparameterised<R: Residuals + Sync + ?Sized>(
    method: &Method,
    solved: Solved<'_, R>,
    transform: &dyn Reparameterisation,
) -> FitResult {
    match method {
        Method::Lsq { profile, .. } => summarise(solved, *profile),
        Method::Mcmc(s) => sample(s, solved, Some(transform)),
    }
}

/// The standard deviation of the initial ball in every coordinate of a reparameterised
/// posterior: the coordinates of a [`Reparameterisation`] are meant to be of order one
/// (logarithms, dimensionless shapes), and the ensemble widens from a small ball by itself.
const REPARAMETERISED_BALL: f64 = 1e-3;

/// The error scale the least-squares optimum implies, sqrt(χ²/dof) (1 where that is not a
/// positive number).
fn scatter_scale(chi2: f64, dof: usize) -> f64 {
    let s = (chi2 / dof.max(1) as f64).sqrt();
    if s > 0.0 && s.is_finite() {
        s
    } else {
        1.0
    }
}

/// The unit of the error scale `sigma_scale`: of v itself without σ, else a factor on σ_v.
fn scale_unit(sigma: SigmaKind) -> &'static str {
    if sigma == SigmaKind::Relative {
        "v (scatter of v; no sigma given)"
    } else {
        "1 (multiplies sigma_v)"
    }
}

/// A posterior run started from the least-squares optimum of `solved` (module docs), in
/// stages: the priors and their checks, the starting ball, the sampler's run, then the rows
/// and the fit's statistics from the draws.
fn sample<R: Residuals + Sync + ?Sized>(
    settings: &McmcSettings,
    solved: Solved<'_, R>,
    transform: Option<&dyn Reparameterisation>,
) -> FitResult {
    let Solved {
        name: fit_name,
        series,
        specs,
        problem,
        fit: f,
        level,
        options: _,
        distinct: _,
        observed_norm,
    } = solved;
    let mut out = summarise(solved, false);
    let n = specs.len();
    // The box of every parameter, as the least-squares summary read it from `opts`.
    let (lower, upper): (Vec<f64>, Vec<f64>) = out.params.iter().map(|r| r.bounds).unzip();
    let priors = parameter_priors(settings, specs);
    let with_scale = f.sigma == SigmaKind::Relative || settings.fit_scatter;
    // With χ² = 0 (or rounding) the likelihood grows without bound as the scale goes to 0:
    // the posterior of the scale is improper and there is nothing to sample.
    if with_scale && f.converged() && chi2_vanishes(f.chi2, observed_norm) {
        let failure = McmcFailure::NotStarted(format!(
            "chi2 = {} at the optimum leaves the posterior of the scatter's scale improper (it \
             piles up at 0); give sigma (and leave the scatter unfitted) to sample the parameters",
            fmt_sig(f.chi2, 3)
        ));
        return failed(out, failure);
    }
    let scale_prior = with_scale.then(|| {
        settings
            .prior(SCALE_NAME)
            .cloned()
            .unwrap_or_else(Prior::jeffreys)
    });
    let mut target = Posterior::new(
        problem,
        lower.clone(),
        upper.clone(),
        priors.clone(),
        scale_prior.clone(),
    );
    if let Some(t) = transform {
        target = target.with_reparameterisation(t);
    }
    // Start: the optimum; the scale at the scatter it implies.
    let s0 = scatter_scale(f.chi2, f.dof);
    if let Err(failure) = check_prior_supports(specs, &priors, scale_prior.as_ref(), &lower, &upper)
    {
        return failed(out, failure);
    }
    let start = StartingBall {
        fit: f,
        priors: &priors,
        lower: &lower,
        upper: &upper,
        scale: with_scale.then_some(s0),
        reparameterised: transform.is_some(),
    };
    let (start, ball) = start.points(&target);
    let Some(start) = target.start_coordinates(&start) else {
        return failed(
            out,
            McmcFailure::NotStarted(
                "the least-squares optimum has no sampling coordinates".to_string(),
            ),
        );
    };
    let mut options = settings.options.clone();
    options.level = level;
    options.init_scale = Some(ball);
    let thin = options.thin.max(1);
    let run = run_sampler(&target, options, settings, fit_name, series, &start);
    let (res, walkers) = match run {
        Ok(r) => r,
        Err(e) => return failed(out, McmcFailure::NotStarted(e.to_string())),
    };
    // The chains, and the diagnostics on them, are already in parameters
    // (`Posterior` records them so).
    // Rows: the parameters, then the scale.
    if with_scale {
        out.params
            .push(scale_row(fit_name, series, s0, level, scale_unit(f.sigma)));
    }
    let all_priors: Vec<&Prior> = priors.iter().chain(scale_prior.iter()).collect();
    // What the least-squares run noted is about the optimum the chains start from.
    if !out.stats.note.is_empty() {
        out.stats.note = format!("least-squares start: {}", out.stats.note);
    }
    let ll = pointwise_log_likelihood(problem, n, &res.chains);
    let scaling = power_scaling(&ll, &all_priors);
    posterior_rows(&mut out.params, &res, scaling.as_deref(), &all_priors);
    // Residuals at the posterior medians, and the correlations of the draws.
    if res.diagnostics.len() >= n {
        let median: Vec<f64> = res.diagnostics[..n].iter().map(|d| d.median).collect();
        let mut r = vec![0.0; problem.n_residuals()];
        if problem.residuals(&median, &mut r).is_ok() {
            out.residuals = r;
        }
        out.correlation = draws_correlation(&res.chains);
    }
    let note = run_note(&mut out.params, &res, settings, thin);
    out.stats.note = join(&out.stats.note, &note);
    let waic = waic(&ll);
    record_run(&mut out, res, walkers, thin, waic);
    out
}

/// The prior of every parameter: the one `settings` name for it, else the parameter's
/// default, else flat on its box.
fn parameter_priors(settings: &McmcSettings, specs: &[ParamSpec]) -> Vec<Prior> {
    specs
        .iter()
        .map(|s| {
            settings
                .prior(s.name)
                .cloned()
                .or_else(|| s.default_prior.clone())
                .unwrap_or_else(Prior::flat)
        })
        .collect()
}

/// A prior whose support misses the feasible box (`lower`, `upper` for the parameters,
/// (0, ∞) for the scale) leaves nothing to sample: the first such prior, as a failure.
fn check_prior_supports(
    specs: &[ParamSpec],
    priors: &[Prior],
    scale_prior: Option<&Prior>,
    lower: &[f64],
    upper: &[f64],
) -> Result<(), McmcFailure> {
    for (j, p) in priors.iter().enumerate() {
        let (a, b) = p.support();
        if !(a.max(lower[j]) < b.min(upper[j])) {
            return Err(McmcFailure::PriorOutsideBox {
                parameter: specs[j].name.to_string(),
                prior: p.to_string(),
                support: (a, b),
                feasible: (lower[j], upper[j]),
            });
        }
    }
    if let Some(p) = scale_prior {
        let (a, b) = p.support();
        if !(a.max(0.0) < b) {
            return Err(McmcFailure::PriorOutsideBox {
                parameter: SCALE_NAME.to_string(),
                prior: p.to_string(),
                support: (a, b),
                feasible: (0.0, f64::INFINITY),
            });
        }
    }
    Ok(())
}

/// What the starting point of the walkers and the width of their initial ball are made of:
/// the least-squares optimum and its standard errors, cut to the priors' supports and the
/// box.
struct StartingBall<'a> {
    /// The least-squares optimum.
    fit: &'a Fit,
    /// The priors of the parameters.
    priors: &'a [Prior],
    /// The lower ends of the parameters' boxes.
    lower: &'a [f64],
    /// The upper ends of the parameters' boxes.
    upper: &'a [f64],
    /// The scale's starting value, when the scale is sampled.
    scale: Option<f64>,
    /// Whether the posterior samples the parameters in a [`Reparameterisation`]'s coordinates.
    reparameterised: bool,
}

impl StartingBall<'_> {
    /// The starting point in parameters (the scale last, when sampled) and the standard
    /// deviation of the initial ball in every sampling coordinate.
    fn points<R: Residuals + Sync + ?Sized>(
        &self,
        target: &Posterior<'_, R>,
    ) -> (Vec<f64>, Vec<f64>) {
        let f = self.fit;
        let n = self.priors.len();
        // The optimum may lie outside a prior's support (a prior narrower than the data):
        // start then just inside the support, cut to the box.
        let mut start: Vec<f64> = f
            .params
            .iter()
            .zip(self.priors)
            .zip(self.lower.iter().zip(self.upper))
            .map(|((&x, p), (&l, &u))| {
                let (a, b) = p.support();
                let (a, b) = (a.max(l), b.min(u));
                if x >= a && x <= b {
                    x
                } else if a.is_finite() && b.is_finite() {
                    let w = b - a;
                    x.clamp(a + 1e-3 * w, b - 1e-3 * w)
                } else if x < a {
                    a + 1e-3 * a.abs().max(1.0)
                } else {
                    b - 1e-3 * b.abs().max(1.0)
                }
            })
            .collect();
        let mut se: Vec<Option<f64>> = (0..n)
            .map(|j| {
                f.std_errors()
                    .map(|s| s[j])
                    .filter(|s| *s > 0.0 && s.is_finite())
            })
            .collect();
        if let Some(s0) = self.scale {
            start.push(s0);
            se.push(None);
        }
        // Coordinates sampled as ln x need x > 0: an optimum on the bound 0 starts just above
        // it.
        for (j, x) in start.iter_mut().enumerate() {
            if target.is_log(j) && !(*x > 0.0) {
                *x = se[j].map_or(1e-6, |s| 1e-2 * s);
            }
        }
        let ball: Vec<f64> = (0..start.len())
            .map(|j| match (target.is_log(j), se[j]) {
                _ if j < n && self.reparameterised => REPARAMETERISED_BALL,
                (true, Some(s)) => (1e-2 * s / start[j]).clamp(1e-4, 1e-1),
                (true, None) => 1e-2,
                (false, Some(s)) => 1e-2 * s,
                (false, None) => 1e-4 * start[j].abs().max(1.0),
            })
            .collect();
        (start, ball)
    }
}

/// Runs the ensemble sampler on `target` from `start` (sampling coordinates), reporting its
/// progress to `settings.progress` under the label `fit [series]`; the result and the number
/// of walkers.
fn run_sampler<R: Residuals + Sync + ?Sized>(
    target: &Posterior<'_, R>,
    options: McmcOptions,
    settings: &McmcSettings,
    fit_name: &str,
    series: &str,
    start: &[f64],
) -> Result<(McmcResult, usize), McmcError> {
    EnsembleSampler::new(target, options).and_then(|sampler| {
        let bar = settings.progress.as_ref();
        if let Some(p) = bar {
            p.report(ProgressEvent::Start {
                label: &format!("{fit_name} [{series}]"),
                total: sampler.options().max_steps as u64,
                check_every: sampler.options().check_every as u64,
            });
        }
        let r = sampler.run_with_progress(start, |step, _| {
            if let Some(p) = bar {
                if step % 16 == 0 {
                    p.report(ProgressEvent::Position(step as u64));
                }
            }
        });
        if let Some(p) = bar {
            p.report(ProgressEvent::Finish);
        }
        r.map(|r| (r, sampler.walkers()))
    })
}

/// The row of the scatter's scale, at its starting value `s0` (the posterior fills it in
/// with the parameters' rows).
fn scale_row(fit_name: &str, series: &str, s0: f64, level: f64, unit: &'static str) -> ParamRow {
    ParamRow {
        fit: fit_name.to_string(),
        series: series.to_string(),
        parameter: SCALE_NAME.to_string(),
        value: s0,
        stderr: None,
        level,
        cov: None,
        profile: None,
        unit,
        at_bound: false,
        paper_value: None,
        paper_source: "",
        note: String::new(),
        bounds: (0.0, f64::INFINITY),
        lsq_value: Some(s0),
        posterior: None,
        sensitivity: None,
        fixed: false,
        start: None,
    }
}

/// Turns the least-squares rows into posterior rows: the optimum moves to `lsq_value`, the
/// value, standard deviation and interval are the posterior's, and the notes name the prior
/// and any sensitivity to it (the least-squares notes describe the optimum and are not
/// repeated here).
fn posterior_rows(
    rows: &mut [ParamRow],
    res: &McmcResult,
    scaling: Option<&[PowerScaling]>,
    all_priors: &[&Prior],
) {
    for (j, row) in rows.iter_mut().enumerate() {
        row.lsq_value = Some(row.value);
        row.profile = None;
        row.at_bound = false;
        let prior_note = format!("prior {}", all_priors[j]);
        match res.diagnostics.get(j) {
            Some(d) => {
                row.value = d.median;
                row.stderr = Some(d.sd);
                row.posterior = Some(d.clone());
                row.at_bound = d.median <= row.bounds.0 || d.median >= row.bounds.1;
                row.note = prior_note;
                if let Some(ps) = scaling.and_then(|v| v.get(j)).copied() {
                    row.sensitivity = Some(ps);
                    let what = match ps.diagnosis() {
                        "prior-driven" => Some(format!(
                            "prior-driven: the data say little about {}, so its posterior and \
                             interval reflect the prior",
                            row.parameter
                        )),
                        "prior-data conflict" => Some(format!(
                            "prior-data conflict: the prior and the data pull {} apart",
                            row.parameter
                        )),
                        _ => None,
                    };
                    if let Some(what) = what {
                        row.note = join(
                            &row.note,
                            &format!(
                                "{what} (power-scaling sensitivity to the prior {}, to the \
                                 likelihood {}; flagged from 0.05)",
                                fmt_sig(ps.prior, 2),
                                fmt_sig(ps.likelihood, 2)
                            ),
                        );
                    }
                }
            }
            None => {
                row.note = format!("{prior_note}; no draw kept: least-squares values");
            }
        }
    }
}

/// The fit's note on the run: interrupted (every row then says so too), not converged (and
/// which parameter is furthest from the thresholds), and NaN evaluations.
fn run_note(
    rows: &mut [ParamRow],
    res: &McmcResult,
    settings: &McmcSettings,
    thin: usize,
) -> String {
    // Names for the messages, as the draws file's columns name them: a name shared by several
    // parameters (one K per series) gets its series (`K[1]`).
    let names: Vec<String> = rows
        .iter()
        .map(|r| {
            if rows.iter().filter(|q| q.parameter == r.parameter).count() > 1 {
                format!("{}[{}]", r.parameter, r.series)
            } else {
                r.parameter.clone()
            }
        })
        .collect();
    let mut note = String::new();
    if res.reason == StopReason::Interrupted {
        note = format!(
            "interrupted after {} steps: the draws so far, not converged",
            res.steps
        );
        // Every row of an interrupted run says so.
        for row in rows.iter_mut() {
            row.note = join(INTERRUPTED_NOTE, &row.note);
        }
    } else if !res.converged {
        // Every row of a run cut off at the step cap says so: its sd and interval come from
        // chains that have not mixed.
        if res.reason == StopReason::MaxSteps {
            let plural = if res.steps == 1 { "" } else { "s" };
            let row_note = format!("{MAX_STEPS_NOTE} ({} step{plural})", res.steps);
            for row in rows.iter_mut() {
                row.note = join(&row_note, &row.note);
            }
        }
        note = match res.failing_parameter {
            Some(k) => match res.diagnostics.get(k) {
                Some(d) => format!(
                    "not converged after {} steps: parameter '{}' has R-hat {}, bulk ESS {}, \
                     tail ESS {}, tau {} steps (needs R-hat <= {}, ESS >= {}, run >= {} tau)",
                    res.steps,
                    names[k],
                    fmt_sig(d.rhat, 4),
                    fmt_sig(d.ess_bulk, 4),
                    fmt_sig(d.ess_tail, 4),
                    fmt_sig(d.tau * thin as f64, 4),
                    fmt_f64(settings.options.rhat_max),
                    fmt_f64(settings.options.min_ess),
                    fmt_f64(settings.options.tau_reliability),
                ),
                None => format!(
                    "not converged after {} steps: parameter '{}' (too few draws to assess)",
                    res.steps, names[k]
                ),
            },
            None => format!("not converged after {} steps", res.steps),
        };
    }
    if res.nan_evaluations > 0 {
        note = join(
            &note,
            &format!(
                "{} log-density evaluation(s) returned NaN (rejected)",
                res.nan_evaluations
            ),
        );
    }
    note
}

/// Records the run in the fit's statistics (convergence, steps, evaluations, the MCMC
/// statistics with `waic`) and keeps its draws.
fn record_run(
    out: &mut FitResult,
    res: McmcResult,
    walkers: usize,
    thin: usize,
    waic: Option<(f64, f64, f64)>,
) {
    let kept = res.chains.iter().map(Vec::len).sum::<usize>();
    // A diagnostic that could not be estimated (too few draws: NaN) makes the extreme NaN
    // too, as the note on the run says, rather than being passed over.
    let rhat_max = extreme(res.diagnostics.iter().map(|d| d.rhat), f64::max);
    let ess_min = extreme(
        res.diagnostics
            .iter()
            .flat_map(|d| [d.ess_bulk, d.ess_tail]),
        f64::min,
    );
    let status = match res.reason {
        StopReason::Converged => "converged",
        StopReason::MaxSteps => "max_steps",
        StopReason::Interrupted => "interrupted",
    };
    out.stats.converged = res.converged;
    out.stats.iterations = res.steps;
    out.stats.residual_evals += walkers * res.steps;
    out.stats.mcmc = Some(McmcStats {
        status: status.into(),
        walkers,
        steps: res.steps,
        burn_in: res.burn_in,
        draws: kept,
        acceptance: res.acceptance_overall,
        ess_min,
        rhat_max,
        waic,
        failure: None,
    });
    out.draws = Some(Draws {
        chains: res.chains,
        log_posterior: res.log_densities,
        burn_in: res.burn_in,
        thin,
        interrupted: res.reason == StopReason::Interrupted,
    });
}

/// The note every parameter row of a posterior run stopped at the step cap (`--max-steps`)
/// before converging starts with (the step count follows).
pub(crate) const MAX_STEPS_NOTE: &str =
    "stopped at the step cap, not converged: posterior from the draws so far, its sd and \
     interval unreliable";

/// The largest or smallest (`pick`) of `xs`: NaN when any is NaN or there are none.
fn extreme(xs: impl Iterator<Item = f64>, pick: fn(f64, f64) -> f64) -> f64 {
    let mut out = f64::NAN;
    for (i, x) in xs.enumerate() {
        if x.is_nan() {
            return f64::NAN;
        }
        out = if i == 0 { x } else { pick(out, x) };
    }
    out
}

/// The note every parameter row of an interrupted posterior run starts with.
pub(crate) const INTERRUPTED_NOTE: &str =
    "interrupted: posterior from the draws so far, not converged";

/// The least-squares summary `out` marked as a posterior run that could not sample: status
/// `failed`, the failure in the note and in [`McmcStats::failure`]; the rows keep the
/// least-squares values and intervals.
fn failed(mut out: FitResult, failure: McmcFailure) -> FitResult {
    out.stats.note = join(&out.stats.note, &failure.to_string());
    out.stats.converged = false;
    for row in out.params.iter_mut() {
        let what = if row.cov.is_some() || row.profile.is_some() {
            "MCMC did not run: least-squares value and interval"
        } else {
            "MCMC did not run: least-squares value"
        };
        row.note = join(what, &row.note);
    }
    out.stats.mcmc = Some(McmcStats {
        status: "failed".into(),
        failure: Some(failure),
        ..Default::default()
    });
    out
}

/// Draws used for WAIC at most (evenly spaced through the pooled kept draws).
const WAIC_DRAWS: usize = 1000;

/// WAIC (S. Watanabe, JMLR 11, 2010; in the deviance scale of A. Gelman, J. Hwang &
/// A. Vehtari, Stat. Comput. 24, 2014): −2 Σᵢ (lppdᵢ − p_waic,ᵢ), with lppdᵢ the log of the
/// posterior mean of p(yᵢ | θ) and p_waic,ᵢ the posterior variance of ln p(yᵢ | θ), over at
/// most [`WAIC_DRAWS`] draws. Pointwise ln p(yᵢ | θ) = −rᵢ²/2 (σ given) or −ln s − rᵢ²/(2s²)
/// (with the scale), dropping the constant −ln σᵢ − ½ ln 2π, which is the same for every model
/// of the same data, so WAIC differences between models are exact. Returns (WAIC, p_waic,
/// standard error of WAIC), or `None` without draws.
fn waic(ll: &[(&[f64], Vec<f64>)]) -> Option<(f64, f64, f64)> {
    let ns = ll.len();
    if ns < 2 {
        return None;
    }
    let m = ll[0].1.len();
    let mut elpd_i = Vec::with_capacity(m);
    let mut p_total = 0.0;
    for i in 0..m {
        let col: Vec<f64> = ll.iter().map(|d| d.1[i]).collect();
        let mx = col.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let lppd = mx + (col.iter().map(|v| (v - mx).exp()).sum::<f64>() / ns as f64).ln();
        let mean = col.iter().sum::<f64>() / ns as f64;
        let var = col.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (ns as f64 - 1.0);
        p_total += var;
        elpd_i.push(lppd - var);
    }
    let w: Vec<f64> = elpd_i.iter().map(|e| -2.0 * e).collect();
    let total: f64 = w.iter().sum();
    let mean = total / m as f64;
    let se = (m as f64 * w.iter().map(|v| (v - mean).powi(2)).sum::<f64>()
        / (m as f64 - 1.0).max(1.0))
    .sqrt();
    Some((total, p_total, se))
}

/// Up to [`WAIC_DRAWS`] draws evenly spaced through the pooled kept draws, each with its
/// pointwise log likelihood ln p(yᵢ | θ) (the constant −ln σᵢ − ½ ln 2π dropped, as in
/// [`waic`]); draws whose residuals cannot be evaluated are left out. Empty with fewer than
/// two draws.
fn pointwise_log_likelihood<'a, R: Residuals + Sync + ?Sized>(
    problem: &R,
    n: usize,
    chains: &'a [Vec<Vec<f64>>],
) -> Vec<(&'a [f64], Vec<f64>)> {
    let pooled: Vec<&Vec<f64>> = chains.iter().flatten().collect();
    if pooled.len() < 2 {
        return Vec::new();
    }
    let stride = pooled.len().div_ceil(WAIC_DRAWS).max(1);
    let m = problem.n_residuals();
    pooled
        .par_iter()
        .step_by(stride)
        .filter_map(|x| {
            let mut r = vec![0.0; m];
            problem.residuals(&x[..n], &mut r).ok()?;
            let s = x.get(n).copied();
            Some((
                x.as_slice(),
                r.iter()
                    .map(|ri| match s {
                        None => -0.5 * ri * ri,
                        Some(s) => -s.ln() - 0.5 * ri * ri / (s * s),
                    })
                    .collect(),
            ))
        })
        .collect()
}

/// The power-scaling sensitivity of every sampled parameter (the scale included) to the
/// prior and to the likelihood ([`crate::inverse::mcmc::sensitivity`]), from the draws of
/// [`pointwise_log_likelihood`]; the log prior of a draw is the sum of its parameters'
/// log prior densities.
fn power_scaling(ll: &[(&[f64], Vec<f64>)], priors: &[&Prior]) -> Option<Vec<PowerScaling>> {
    let draws: Vec<&[f64]> = ll.iter().map(|d| d.0).collect();
    let log_prior: Vec<f64> = draws
        .iter()
        .map(|x| x.iter().zip(priors).map(|(v, p)| p.ln_pdf(*v)).sum())
        .collect();
    let log_lik: Vec<f64> = ll.iter().map(|d| d.1.iter().sum()).collect();
    let prior = sensitivity(&draws, &log_prior)?;
    let likelihood = sensitivity(&draws, &log_lik)?;
    Some(
        prior
            .into_iter()
            .zip(likelihood)
            .map(|(prior, likelihood)| PowerScaling { prior, likelihood })
            .collect(),
    )
}

/// Pearson correlation matrix of the draws, all walkers pooled; `None` without draws.
fn draws_correlation(chains: &[Vec<Vec<f64>>]) -> Option<Vec<Vec<f64>>> {
    let n = chains.first()?.first()?.len();
    let draws: Vec<&Vec<f64>> = chains.iter().flatten().collect();
    let m = draws.len() as f64;
    let mean: Vec<f64> = (0..n)
        .map(|j| draws.iter().map(|x| x[j]).sum::<f64>() / m)
        .collect();
    let mut cov = vec![vec![0.0; n]; n];
    for x in &draws {
        for i in 0..n {
            for j in 0..n {
                cov[i][j] += (x[i] - mean[i]) * (x[j] - mean[j]);
            }
        }
    }
    Some(
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| cov[i][j] / (cov[i][i] * cov[j][j]).sqrt())
                    .collect()
            })
            .collect(),
    )
}
