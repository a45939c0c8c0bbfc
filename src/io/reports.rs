//! The CSV schemas of the fit reports: one row per parameter (`--output`, params.csv), one row
//! of statistics per fit (`--output-stats`, stats.csv), the posterior draws (`--draws`), and the
//! contact model's bead-by-bead transient (`simulate --v0`), and every point against its fit
//! (residuals.csv) and every pair of parameters with its correlation (correlations.csv).

use crate::fit::posterior::draws_column;
use crate::fit::summary::{FitResult, ParamRow, StatsRow};
use crate::inverse::{ProfileEnd, SigmaKind};
use crate::models::contact::{Contact, ContactEnd, Launch};
use crate::numfmt::fmt_f64;
use crate::scene::Scene;

/// The contract columns of the parameter report, in order.
pub const PARAM_COLUMNS: [&str; 9] = [
    "fit",
    "series",
    "parameter",
    "value",
    "stderr",
    "ci_low",
    "ci_high",
    "ci_method",
    "unit",
];

/// Columns of the parameter report after the contract ones (`cov_low`/`cov_high` are the
/// uncut covariance interval).
pub const PARAM_EXTRA_COLUMNS: [&str; 11] = [
    "level",
    "cov_low",
    "cov_high",
    "profile_low",
    "profile_high",
    "profile_low_status",
    "profile_high_status",
    "at_bound",
    "paper_value",
    "paper_source",
    "note",
];

/// Posterior columns of the parameter report, after [`PARAM_EXTRA_COLUMNS`]: filled by MCMC
/// (`ci_method = posterior`), empty for least squares but `lsq_value` (the least-squares
/// optimum, the start of the chains).
pub const PARAM_POSTERIOR_COLUMNS: [&str; 10] = [
    "mean",
    "sd",
    "q2.5",
    "q50",
    "q97.5",
    "ess_bulk",
    "ess_tail",
    "rhat",
    "tau",
    "lsq_value",
];

/// Columns of the statistics report.
pub const STATS_COLUMNS: [&str; 28] = [
    "fit",
    "series",
    "n_points",
    "n_params",
    "chi2",
    "dof",
    "reduced_chi2",
    "aic",
    "bic",
    "termination",
    "converged",
    "iterations",
    "residual_evals",
    "sigma",
    "condition",
    "note",
    "method",
    "mcmc_status",
    "walkers",
    "steps",
    "burn_in",
    "draws",
    "acceptance",
    "ess_min",
    "rhat_max",
    "waic",
    "p_waic",
    "waic_se",
];

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

fn opt(x: Option<f64>) -> String {
    x.map(fmt_f64).unwrap_or_default()
}

/// The parameter report as CSV: the contract columns, then [`PARAM_EXTRA_COLUMNS`].
pub fn params_csv(rows: &[ParamRow]) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(
        PARAM_COLUMNS
            .iter()
            .chain(PARAM_EXTRA_COLUMNS.iter())
            .chain(PARAM_POSTERIOR_COLUMNS.iter()),
    )?;
    for r in rows {
        let (ci, method) = r.interval();
        let (pl, ph) = match r.profile {
            Some((a, b)) => (
                (opt(end_value(a)), end_status(a)),
                (opt(end_value(b)), end_status(b)),
            ),
            None => ((String::new(), "none"), (String::new(), "none")),
        };
        w.write_record([
            r.fit.clone(),
            r.series.clone(),
            r.parameter.clone(),
            fmt_f64(r.value),
            opt(r.stderr),
            opt(ci.map(|c| c.0)),
            opt(ci.map(|c| c.1)),
            method.to_string(),
            r.unit.to_string(),
            fmt_f64(r.level),
            opt(r.cov.map(|c| c.0)),
            opt(r.cov.map(|c| c.1)),
            pl.0,
            ph.0,
            pl.1.to_string(),
            ph.1.to_string(),
            r.at_bound.to_string(),
            opt(r.paper_value),
            r.paper_source.to_string(),
            r.note.clone(),
            opt(r.posterior.as_ref().map(|d| d.mean)),
            opt(r.posterior.as_ref().map(|d| d.sd)),
            opt(r.posterior.as_ref().map(|d| d.q025)),
            opt(r.posterior.as_ref().map(|d| d.median)),
            opt(r.posterior.as_ref().map(|d| d.q975)),
            opt(r.posterior.as_ref().map(|d| d.ess_bulk)),
            opt(r.posterior.as_ref().map(|d| d.ess_tail)),
            opt(r.posterior.as_ref().map(|d| d.rhat)),
            opt(r.posterior.as_ref().map(|d| d.tau)),
            opt(r.lsq_value),
        ])?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// The statistics report as CSV ([`STATS_COLUMNS`]).
pub fn stats_csv(rows: &[StatsRow]) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(STATS_COLUMNS)?;
    for r in rows {
        w.write_record([
            r.fit.clone(),
            r.series.clone(),
            r.n_points.to_string(),
            r.n_params.to_string(),
            fmt_f64(r.chi2),
            r.dof.to_string(),
            fmt_f64(r.reduced_chi2),
            fmt_f64(r.aic),
            fmt_f64(r.bic),
            r.termination.clone(),
            r.converged.to_string(),
            r.iterations.to_string(),
            r.residual_evals.to_string(),
            match r.sigma {
                SigmaKind::Absolute => "given",
                SigmaKind::Relative => "estimated",
            }
            .to_string(),
            opt(r.condition),
            r.note.clone(),
            if r.mcmc.is_some() { "mcmc" } else { "lsq" }.to_string(),
            r.mcmc
                .as_ref()
                .map(|m| m.status.clone())
                .unwrap_or_default(),
            r.mcmc
                .as_ref()
                .map(|m| m.walkers.to_string())
                .unwrap_or_default(),
            r.mcmc
                .as_ref()
                .map(|m| m.steps.to_string())
                .unwrap_or_default(),
            r.mcmc
                .as_ref()
                .map(|m| m.burn_in.to_string())
                .unwrap_or_default(),
            r.mcmc
                .as_ref()
                .map(|m| m.draws.to_string())
                .unwrap_or_default(),
            opt(r.mcmc.as_ref().map(|m| m.acceptance)),
            opt(r.mcmc.as_ref().map(|m| m.ess_min).filter(|v| v.is_finite())),
            opt(r
                .mcmc
                .as_ref()
                .map(|m| m.rhat_max)
                .filter(|v| v.is_finite())),
            opt(r.mcmc.as_ref().and_then(|m| m.waic).map(|w| w.0)),
            opt(r.mcmc.as_ref().and_then(|m| m.waic).map(|w| w.1)),
            opt(r.mcmc.as_ref().and_then(|m| m.waic).map(|w| w.2)),
        ])?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// The draws of every posterior as one CSV: fit, series, walker, step, the union of the
/// parameter columns (empty where a fit has no such parameter), log_posterior; when a run was
/// interrupted, a last column `status` on every row (`interrupted`, or `complete` for a fit
/// that finished before the signal).
pub fn draws_csv(posteriors: &[&FitResult]) -> csv::Result<Vec<u8>> {
    let mut columns: Vec<String> = Vec::new();
    for p in posteriors {
        for r in &p.params {
            let c = draws_column(p, r);
            if !columns.contains(&c) {
                columns.push(c);
            }
        }
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = ["fit", "series", "walker", "step"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    header.extend(columns.iter().cloned());
    header.push("log_posterior".into());
    // An interrupted run marks every row of its draws.
    let interrupted = posteriors
        .iter()
        .any(|p| p.draws.as_ref().is_some_and(|d| d.interrupted));
    if interrupted {
        header.push("status".into());
    }
    w.write_record(&header)?;
    for p in posteriors {
        let Some(d) = &p.draws else { continue };
        let idx: Vec<usize> = p
            .params
            .iter()
            .map(|r| {
                let c = draws_column(p, r);
                columns.iter().position(|x| *x == c).unwrap_or(0)
            })
            .collect();
        for (wk, chain) in d.chains.iter().enumerate() {
            for (k, x) in chain.iter().enumerate() {
                let mut rec = vec![String::new(); header.len()];
                rec[0] = p.stats.fit.clone();
                rec[1] = p.stats.series.clone();
                rec[2] = wk.to_string();
                rec[3] = d.step(k).to_string();
                for (j, v) in x.iter().enumerate() {
                    rec[4 + idx[j]] = fmt_f64(*v);
                }
                let lp = header.len() - 1 - usize::from(interrupted);
                rec[lp] = fmt_f64(d.log_posterior[wk][k]);
                if interrupted {
                    rec[lp + 1] = if d.interrupted {
                        "interrupted".into()
                    } else {
                        "complete".into()
                    };
                }
                w.write_record(&rec)?;
            }
        }
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// Columns of the per-point residuals report (`residuals.csv`).
pub const RESIDUAL_COLUMNS: [&str; 9] = [
    "fit",
    "series",
    "xi",
    "delta_deg",
    "v",
    "sigma_v",
    "v_fit",
    "residual",
    "normalised_residual",
];

/// A finite number, or an empty cell (no σ given; no steady state at the estimate).
fn finite(x: f64) -> String {
    if x.is_finite() {
        fmt_f64(x)
    } else {
        String::new()
    }
}

/// Every point of every fit against its fitted v̄, one row per fit and point
/// ([`RESIDUAL_COLUMNS`]): the measured v̄ and σ, the fitted v̄ at the reported estimate, the
/// residual v − v̄_fit and the normalised residual (v − v̄_fit)/σ (without σ, divided by the
/// scatter estimated from the fit). Cells are empty where there is no σ or no steady state.
pub fn residuals_csv(fits: &[&FitResult]) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(RESIDUAL_COLUMNS)?;
    for f in fits {
        for p in &f.points {
            w.write_record([
                f.stats.fit.clone(),
                p.series.clone(),
                fmt_f64(p.xi),
                fmt_f64(p.delta_deg),
                fmt_f64(p.v),
                p.sigma_v.map(finite).unwrap_or_default(),
                finite(p.v_fit),
                finite(p.residual),
                finite(p.normalised_residual),
            ])?;
        }
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// Columns of the correlations report (`correlations.csv`).
pub const CORRELATION_COLUMNS: [&str; 5] =
    ["fit", "series", "parameter_1", "parameter_2", "correlation"];

/// Every pair of parameters of every fit with its correlation ([`CORRELATION_COLUMNS`]), each
/// pair once in the order of the fit's parameters: from the covariance at the least-squares
/// optimum, or from the draws of a posterior run. Parameters of a fit with one per series are
/// named `K[series]`. A fit whose correlation matrix does not exist (a rank-deficient
/// Jacobian, a single parameter) has no rows.
pub fn correlations_csv(fits: &[&FitResult]) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(CORRELATION_COLUMNS)?;
    for f in fits {
        let Some(c) = &f.correlation else { continue };
        let names = f.param_names();
        let n = names.len().min(c.len());
        for i in 0..n {
            for j in i + 1..n {
                w.write_record([
                    f.stats.fit.as_str(),
                    f.stats.series.as_str(),
                    names[i].as_str(),
                    names[j].as_str(),
                    &finite(c[i][j]),
                ])?;
            }
        }
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// Columns of the `simulate --model contact --v0` transient.
pub const TRACE_COLUMNS: [&str; 15] = [
    "xi",
    "delta_deg",
    "bead",
    "initial_velocity",
    "initial_spin",
    "final_velocity",
    "final_spin",
    "contact_time",
    "mean_velocity",
    "phase_sequence",
    "phase_change_deg",
    "friction_work",
    "status",
    "steady_mean_velocity",
    "message",
];

/// The bead-by-bead transient of the general contact model from the launch speed `v0` (and
/// spin `v0`), over `beads` row beads for each scene (all at the slope `delta_deg`, degrees, as
/// printed), as CSV ([`TRACE_COLUMNS`]), with each
/// scene's steady mean velocity beside it.
pub fn transient_csv(
    model: &Contact,
    scenes: &[Scene],
    delta_deg: f64,
    v0: f64,
    beads: usize,
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(TRACE_COLUMNS)?;
    for scene in scenes {
        let (xi, d) = (scene.xi(), delta_deg);
        let steady = model
            .evaluate(scene)
            .map(|s| fmt_f64(s.mean_velocity))
            .unwrap_or_default();
        let runs = model.transient(
            scene,
            Launch {
                theta_dot: v0,
                spin: v0,
            },
            beads,
        );
        for (i, (l, r)) in runs.iter().enumerate() {
            let (fv, fs, status, msg, v) = match r.end {
                ContactEnd::Collision { theta_dot, spin } => (
                    fmt_f64(theta_dot),
                    fmt_f64(spin),
                    "ok".to_string(),
                    String::new(),
                    fmt_f64(2.0 * scene.sin_alpha() / r.time),
                ),
                ContactEnd::Failed(e) => (
                    String::new(),
                    String::new(),
                    e.status().to_string(),
                    format!("{e} on bead {}", i + 1),
                    String::new(),
                ),
            };
            w.write_record([
                fmt_f64(xi),
                fmt_f64(d),
                (i + 1).to_string(),
                fmt_f64(l.theta_dot),
                fmt_f64(l.spin),
                fv,
                fs,
                if status == "ok" {
                    fmt_f64(r.time)
                } else {
                    String::new()
                },
                v,
                r.phases.to_string(),
                r.phases.changes_deg(),
                fmt_f64(r.friction_work),
                status,
                steady.clone(),
                msg,
            ])?;
        }
    }
    w.into_inner().map_err(|e| e.into_error().into())
}
