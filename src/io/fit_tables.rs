//! The CSV tables of the fits: one row per parameter (`--output`, params.csv), one row
//! of statistics per fit (`--output-stats`, stats.csv), the posterior draws (`--draws`), and the
//! contact model's bead-by-bead transient (`simulate --v0`), and every point against its fit
//! (residuals.csv) and every pair of parameters with its correlation (correlations.csv).

use super::records::{
    to_csv, CorrelationRecord, ParamRecord, ResidualRecord, SlopeResidualRecord, StatsRecord,
};
use crate::fit::posterior::draws_column;
use crate::fit::summary::{FitResult, ParamRow, StatsRow};
use crate::models::contact::{Contact, ContactEnd, Launch};
use crate::numfmt::fmt_f64;
use crate::scene::Scene;

/// The parameter report as CSV, one [`ParamRecord`] per row: the contract columns `fit`,
/// `series`, `parameter`, `value`, `stderr`, `ci_low`, `ci_high`, `ci_method`, `unit`, then the
/// intervals' details and the posterior summary.
pub fn params_csv(rows: &[ParamRow]) -> csv::Result<Vec<u8>> {
    to_csv(rows.iter().map(ParamRecord::from))
}

/// The statistics report as CSV, one [`StatsRecord`] per fit.
pub fn stats_csv(rows: &[StatsRow]) -> csv::Result<Vec<u8>> {
    to_csv(rows.iter().map(StatsRecord::from))
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

/// Every point of every fit against its fitted v̄, one [`ResidualRecord`] per fit and point:
/// the measured v̄ and σ, the fitted v̄ at the reported estimate, the residual v − v̄_fit and
/// the normalised residual (v − v̄_fit)/σ (without σ, divided by the scatter estimated from the
/// fit). Cells are empty where there is no σ or no steady state.
///
/// When some fit took the slopes as measured with error, two more columns follow:
/// `delta_fit_deg`, the adjusted slope, and `delta_residual`, (δ_fit − δ)/σ_δ.
pub fn residuals_csv(fits: &[&FitResult]) -> csv::Result<Vec<u8>> {
    let slopes = fits
        .iter()
        .any(|f| f.points.iter().any(|p| p.delta_fit_deg.is_some()));
    if slopes {
        to_csv(SlopeResidualRecord::of(fits))
    } else {
        to_csv(ResidualRecord::of(fits))
    }
}

/// Every pair of parameters of every fit with its correlation, one [`CorrelationRecord`] per
/// pair, each pair once in the order of the fit's parameters: from the covariance at the
/// least-squares optimum, or from the draws of a posterior run. Parameters of a fit with one
/// per series are named `K[series]`. A fit whose correlation matrix does not exist (a
/// rank-deficient Jacobian, a single parameter) has no rows.
pub fn correlations_csv(fits: &[&FitResult]) -> csv::Result<Vec<u8>> {
    to_csv(CorrelationRecord::of(fits))
}

/// Columns of the `simulate --model contact --v0` transient.
pub(crate) const TRACE_COLUMNS: [&str; 15] = [
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
/// printed), as CSV (`TRACE_COLUMNS`), with each
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
