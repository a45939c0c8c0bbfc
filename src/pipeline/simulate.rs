//! Synthetic measurements spread inside regime B of each series, with multiplicative Gaussian
//! noise, reproducible from the seed (ChaCha8 stream); or the bead-by-bead transient of the
//! contact model from a launch speed.

use super::{setting_error as flag_error, RunError};
use crate::io::fmt_f64;
use crate::models::contact::{Contact, SpinRule};
use crate::models::jaeger::Jaeger;
use crate::models::jan::Jan;
use crate::models::md::{
    regime_b_interval_until as md_regime_b_interval, Md, MdParams, MdResult, MdRunConfig,
    MD_NARROW, MD_REFINE, MD_SCAN_POINTS,
};
use crate::models::regimes::regime_b_interval;
use crate::models::{ForwardModel, JaegerBranch, Model, ModelKind, Regime};
use crate::progress::{Progress, ProgressEvent};
use crate::scene::{CollisionLaw, Scene};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Most points per series (`points`).
pub(crate) const MAX_POINTS: usize = 1_000_000;
/// Most rows in all (series × points).
pub(crate) const MAX_ROWS: usize = 10_000_000;
/// Most series (`series`).
pub(crate) const MAX_SERIES: usize = 10_000;

/// What [`SimulateSettings::run`] makes: the settings of `fitbead simulate`, one field per flag (the
/// defaults are the flags' defaults).
#[derive(Clone)]
pub struct SimulateSettings {
    /// Forward model that makes the data (`--model`): a contact model, contact (with `v0`:
    /// the transient instead), jan, jaeger or md.
    pub model: ModelKind,
    /// Collision law (`--law`).
    pub law: CollisionLaw,
    /// Radius ratios ξ of the series (`--series`), each once.
    pub series: Vec<f64>,
    /// Points per series (`--points`).
    pub points: usize,
    /// Relative noise (`--noise`): v = v_true (1 + noise · z), σ = noise · v_true, with z
    /// standard normal truncated to v > 0 (drawn again until the velocity is positive).
    pub noise: f64,
    /// Standard uncertainty of the recorded slope, degrees (`--sigma-delta`): each point's
    /// `delta_deg` is δ_true + σ_δ · z (z standard normal from the seed's stream, drawn after
    /// the velocity's, truncated to a slope in (0, 90) degrees), its velocity made at
    /// δ_true; the columns `sigma_delta_deg` and `delta_true_deg` follow the others. 0: the
    /// slopes are exact and no draw is made.
    pub sigma_delta: f64,
    /// Seed of the random stream (`--seed`).
    pub seed: u64,
    /// Gyration parameter ρ (`--rho`).
    pub rho: f64,
    /// Friction coefficient f (`--f`).
    pub f: f64,
    /// Jan's global laws λ0, λ1, μ0, μ1 (`--jan`; λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α});
    /// `None`: the paper's eqs 75–76.
    pub jan: Option<[f64; 4]>,
    /// Jaeger's a1, a2, a3 for every series (`--jaeger`, eq 81); `None`: the paper's Fig. 9
    /// values of each series' ξ.
    pub jaeger: Option<[f64; 3]>,
    /// Branch of eq 84 for jaeger (`--branch`).
    pub branch: JaegerBranch,
    /// Slopes LO, HI in degrees (`--delta-range`), cut to the steady range.
    pub delta_range: Option<(f64, f64)>,
    /// A design file (`--design`: series,xi,delta_deg,replicates): the data are made at its
    /// slopes instead.
    pub design: Option<PathBuf>,
    /// Launch speed of the contact model's transient (`--v0`).
    pub v0: Option<f64>,
    /// Slope of the transient, degrees (`--delta-deg`).
    pub delta_deg: Option<f64>,
    /// Row beads of the transient (`--beads`); `None`: 50.
    pub beads: Option<usize>,
    /// Spin rule of the contact model (`--spin`).
    pub spin: SpinRule,
    /// The molecular-dynamics model of `model` md (the md flags).
    pub md: Md,
    /// Raised to stop the run: [`SimulateSettings::run`] then returns [`RunError::Interrupted`].
    pub stop: Option<Arc<AtomicBool>>,
    /// Progress of the md runs (label `md simulate`).
    pub progress: Option<Progress>,
    /// Called with each note of the run as it is made (md: a steady range narrowed).
    #[allow(clippy::type_complexity)]
    pub notes: Option<Arc<dyn Fn(&str) + Send + Sync>>,
}

impl std::fmt::Debug for SimulateSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SimulateSettings")
            .field("model", &self.model)
            .field("law", &self.law)
            .field("series", &self.series)
            .field("points", &self.points)
            .field("noise", &self.noise)
            .field("sigma_delta", &self.sigma_delta)
            .field("seed", &self.seed)
            .field("rho", &self.rho)
            .field("f", &self.f)
            .field("jan", &self.jan)
            .field("jaeger", &self.jaeger)
            .field("branch", &self.branch)
            .field("delta_range", &self.delta_range)
            .field("design", &self.design)
            .field("v0", &self.v0)
            .field("delta_deg", &self.delta_deg)
            .field("beads", &self.beads)
            .field("spin", &self.spin)
            .field("md", &self.md)
            .finish_non_exhaustive()
    }
}

impl Default for SimulateSettings {
    /// The command line's defaults: stickslip under the adjusted law, ξ = 0.8, 1, 1.6, 2,
    /// 9 points per series, 2 % noise, seed 1, ρ = 0.4, f = 0.1, md with the ristow preset.
    fn default() -> Self {
        SimulateSettings {
            model: ModelKind::StickSlip,
            law: CollisionLaw::Adjusted,
            series: vec![0.8, 1.0, 1.6, 2.0],
            points: 9,
            noise: 0.02,
            sigma_delta: 0.0,
            seed: 1,
            rho: 0.4,
            f: 0.1,
            jan: None,
            jaeger: None,
            branch: JaegerBranch::Upper,
            delta_range: None,
            design: None,
            v0: None,
            delta_deg: None,
            beads: None,
            spin: SpinRule::Roll,
            md: Md {
                params: MdParams::ristow(),
                config: MdRunConfig::default(),
            },
            stop: None,
            progress: None,
            notes: None,
        }
    }
}

impl SimulateSettings {
    /// The most points per series a steady-state run draws.
    pub const MAX_POINTS: usize = MAX_POINTS;

    /// Runs `fitbead simulate`: the CSV it writes (`series,xi,delta_deg,v,sigma_v,v_true`, md
    /// adding `v_md_stderr,v_m_s`, σ_δ > 0 then `sigma_delta_deg,delta_true_deg`; with `v0`
    /// the transient's columns).
    pub fn run(&self) -> Result<Vec<u8>, RunError> {
        simulate(self)
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }
}

/// [`SimulateSettings::run`].
fn simulate(a: &SimulateSettings) -> Result<Vec<u8>, RunError> {
    check_series(a)?;
    if !(a.sigma_delta.is_finite() && (0.0..90.0).contains(&a.sigma_delta)) {
        return Err(flag_error(
            "--sigma-delta",
            &a.sigma_delta.to_string(),
            "must be a finite number of degrees >= 0 and < 90",
        ));
    }
    // The contact model under the spin rule (other models have none).
    let contact = Contact {
        spin: a.spin,
        ..Contact::default()
    };
    if let Some(v0) = a.v0 {
        if a.model != ModelKind::Contact {
            return Err(flag_error(
                "--v0",
                &v0.to_string(),
                "the bead-by-bead transient needs --model contact",
            ));
        }
        if a.sigma_delta > 0.0 {
            return Err(flag_error(
                "--sigma-delta",
                &fmt_f64(a.sigma_delta),
                "the bead-by-bead transient (--v0) has no measured slopes",
            ));
        }
        return trace(a, a.law, &a.series, v0, contact);
    }
    check_steady(a)?;
    if a.model == ModelKind::Md {
        if let Some(p) = &a.design {
            return Err(flag_error(
                "--design",
                &p.display().to_string(),
                "a design is simulated with the steady-state models, not --model md",
            ));
        }
        return run_md(a, &a.series);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
    let model_for = |xi: f64| model_for(a, contact, xi);
    if let Some(path) = a.design.as_deref() {
        return simulate_design(a, path, a.law, &model_for, &mut rng);
    }
    steady_points(a, &model_for, &mut rng)
}

/// The checks of every run: a spin rule only for the contact model, each series' ξ once, at
/// most [`MAX_SERIES`] series.
fn check_series(a: &SimulateSettings) -> Result<(), RunError> {
    if a.model != ModelKind::Contact && a.spin != SpinRule::Roll {
        return Err(flag_error(
            "--spin",
            &a.spin.to_string(),
            "a spin rule applies to --model contact only",
        ));
    }
    let series = &a.series;
    // Rows of a series are labelled by its ξ: two equal values would make one series.
    for (j, x) in series.iter().enumerate() {
        if let Some(i) = series[..j].iter().position(|y| y == x) {
            return Err(flag_error(
                "--series",
                &fmt_f64(*x),
                format!(
                    "xi {} is given twice (values {} and {}): each series needs its own xi",
                    fmt_f64(*x),
                    i + 1,
                    j + 1
                ),
            ));
        }
    }
    if series.len() > MAX_SERIES {
        return Err(flag_error(
            "--series",
            &format!("{} values", series.len()),
            format!("expected at most {MAX_SERIES} series"),
        ));
    }
    Ok(())
}

/// The checks of a steady-state run: 1 to [`MAX_POINTS`] points per series and at most
/// [`MAX_ROWS`] rows, noise in [0, 0.5), a slope range with LO < HI.
fn check_steady(a: &SimulateSettings) -> Result<(), RunError> {
    if a.points == 0 || a.points > MAX_POINTS {
        return Err(flag_error(
            "--points",
            &a.points.to_string(),
            format!("expected 1 to {MAX_POINTS} points per series"),
        ));
    }
    if a.series.len().saturating_mul(a.points) > MAX_ROWS {
        return Err(flag_error(
            "--points",
            &a.points.to_string(),
            format!(
                "{} series of {} points make more than {MAX_ROWS} rows",
                a.series.len(),
                a.points
            ),
        ));
    }
    if !(a.noise.is_finite() && (0.0..0.5).contains(&a.noise)) {
        return Err(flag_error(
            "--noise",
            &a.noise.to_string(),
            "must be in [0, 0.5)",
        ));
    }
    if let Some((lo, hi)) = a.delta_range {
        if !(lo < hi) {
            return Err(flag_error(
                "--delta-range",
                &format!("{},{}", fmt_f64(lo), fmt_f64(hi)),
                "expected LO,HI in degrees with LO < HI",
            ));
        }
    }
    Ok(())
}

/// The model that makes the data of the series ξ: a contact model (`contact` for the
/// contact model, with its spin rule), Jan's with the global laws or Jaeger's with the
/// settings' parameters or the paper's.
fn model_for(a: &SimulateSettings, contact: Contact, xi: f64) -> Result<Model, RunError> {
    let alpha = Scene::from_radians(xi, 0.1, a.rho, a.f, a.law)
        .map_err(|e| flag_error("--series", &xi.to_string(), e.to_string()))?
        .alpha_rad();
    Ok(match (a.model, a.model.contact_model()) {
        (ModelKind::Contact, _) => Model::Contact(contact),
        (_, Some(m)) => m,
        (ModelKind::Jan, None) => match &a.jan {
            None => Model::Jan(Jan::paper_fit(alpha)),
            Some(p) => {
                let s = alpha.sin();
                Model::Jan(
                    Jan::new(p[0] * (p[1] * s).exp(), p[2] * (p[3] * s).exp())
                        .map_err(|e| flag_error("--jan", "", e.to_string()))?,
                )
            }
        },
        _ => {
            let p = match &a.jaeger {
                Some(p) => [p[0], p[1], p[2]],
                None => crate::fit::jaeger::paper_values(xi).ok_or_else(|| {
                    flag_error(
                        "--series",
                        &xi.to_string(),
                        "the paper gives Jaeger's a1, a2, a3 for xi = 0.8, 1, 1.6, 2 only: \
                         give --jaeger A1,A2,A3",
                    )
                })?,
            };
            Model::Jaeger(
                Jaeger::new(p[0], p[1], p[2], a.branch)
                    .map_err(|e| flag_error("--jaeger", "", e.to_string()))?,
            )
        }
    })
}

/// The slopes of the series ξ under `model`, in radians: the steady range (for jan and
/// jaeger, whose steady range has no upper end, the onset to the onset + 12°), cut to the
/// settings' slope range, with the fractions of it that the points spread over.
fn slope_span(
    a: &SimulateSettings,
    model: &Model,
    xi: f64,
) -> Result<(f64, f64, f64, f64), RunError> {
    let Some((lo, hi)) = regime_b_interval(model, xi, a.rho, a.f, a.law) else {
        return Err(flag_error(
            "--series",
            &xi.to_string(),
            "no steady regime for this xi under this model and law",
        ));
    };
    let open_ended = matches!(a.model, ModelKind::Jan | ModelKind::Jaeger);
    Ok(match a.delta_range {
        Some((l, h)) => {
            let (l, h) = (l.to_radians().max(lo), h.to_radians().min(hi));
            if !(l < h) {
                return Err(flag_error(
                    "--delta-range",
                    &range_text(a.delta_range),
                    format!(
                        "no steady state in this range at xi = {xi} (steady from {} to {} deg)",
                        fmt_f64(lo.to_degrees()),
                        fmt_f64(hi.to_degrees())
                    ),
                ));
            }
            (l, h, 0.05, 0.95)
        }
        None if open_ended => (lo, (lo + 12f64.to_radians()).min(hi), 0.05, 0.95),
        None => (lo, hi, 0.05, 0.95),
    })
}

/// Synthetic points spread over the steady range of each series, noise drawn from `rng` in
/// the order of the rows.
fn steady_points(
    a: &SimulateSettings,
    model_for: &dyn Fn(f64) -> Result<Model, RunError>,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<u8>, RunError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| RunError::Failed(e.to_string());
    w.write_record(slope_header(
        a,
        &["series", "xi", "delta_deg", "v", "sigma_v", "v_true"],
    ))
    .map_err(io)?;
    for &xi in &a.series {
        let model = model_for(xi)?;
        let (lo, hi, f0, f1) = slope_span(a, &model, xi)?;
        for j in 0..a.points {
            if a.stopped() {
                return Err(RunError::Interrupted);
            }
            let frac = if a.points == 1 {
                0.5
            } else {
                f0 + (f1 - f0) * j as f64 / (a.points - 1) as f64
            };
            let d = lo + (hi - lo) * frac;
            // Round the slope to 1e-4 degree, as a measured slope would be written.
            let d_deg = (d.to_degrees() * 1e4).round() / 1e4;
            let scene = Scene::new(xi, d_deg, a.rho, a.f, a.law)
                .map_err(|e| RunError::Failed(e.to_string()))?;
            let v_true = match model.evaluate(&scene) {
                Ok(s) => s.mean_velocity,
                Err(e) => return Err(RunError::Failed(format!("xi {xi}, delta {d_deg} deg: {e}"))),
            };
            let v = noisy(v_true, a.noise, rng);
            let slope = recorded_slope(a, d_deg, rng);
            let cells = [
                fmt_f64(xi),
                fmt_f64(xi),
                slope.delta_cell(),
                fmt_f64(v),
                sigma_cell(a.noise * v_true),
                fmt_f64(v_true),
            ];
            w.write_record(slope.cells(cells)).map_err(io)?;
        }
    }
    w.into_inner().map_err(|e| RunError::Failed(e.to_string()))
}

/// The slope range as `LO,HI` (the command line shows its flag's own text instead).
fn range_text(range: Option<(f64, f64)>) -> String {
    range
        .map(|(l, h)| format!("{},{}", fmt_f64(l), fmt_f64(h)))
        .unwrap_or_default()
}

/// The bead-by-bead transient from a launch `v0`, one scene per ξ at `delta_deg`.
fn trace(
    a: &SimulateSettings,
    law: CollisionLaw,
    series: &[f64],
    v0: f64,
    model: Contact,
) -> Result<Vec<u8>, RunError> {
    use crate::io::fit_tables::transient_csv;
    if !(v0.is_finite() && v0 >= 0.0) {
        return Err(flag_error(
            "--v0",
            &v0.to_string(),
            "expected a finite launch speed >= 0",
        ));
    }
    // The row beads travelled default to 50 for the transient.
    let beads = a.beads.unwrap_or(50);
    if beads == 0 || beads > 10_000_000 {
        return Err(flag_error(
            "--beads",
            &beads.to_string(),
            "expected 1 to 10000000 beads",
        ));
    }
    let Some(d) = a.delta_deg else {
        return Err(flag_error(
            "--delta-deg",
            "",
            "--v0 needs the slope of the scene (--delta-deg)",
        ));
    };
    let scenes = series
        .iter()
        .map(|&xi| {
            Scene::new(xi, d, a.rho, a.f, law)
                .map_err(|e| flag_error("--series/--delta-deg", &xi.to_string(), e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    transient_csv(&model, &scenes, d, v0, beads).map_err(|e| RunError::Failed(e.to_string()))
}

/// One row of a design file: its line, series label, ξ, slope (degrees) and replicates.
struct DesignLine {
    line: u64,
    series: String,
    xi: f64,
    delta_deg: f64,
    replicates: usize,
}

/// A series is one bead size (the fits refuse a series that mixes ξ values): the message when
/// `series` already has lines of `out` at another ξ than `xi`.
fn mixed_series(out: &[DesignLine], series: &str, xi: f64) -> Option<String> {
    let first = out.iter().find(|d| d.series == series && d.xi != xi)?;
    Some(format!(
        "series '{}' mixes xi values: {} on line {}, {} here (a series is one bead size)",
        crate::numfmt::clip(series, crate::numfmt::ECHO_CHARS),
        fmt_f64(first.xi),
        first.line,
        fmt_f64(xi)
    ))
}

/// Reads a design file (series,xi,delta_deg,replicates; other columns ignored), every cell
/// checked: a bad one is an error naming file, line, column and value.
fn read_design(path: &std::path::Path) -> Result<Vec<DesignLine>, RunError> {
    use crate::io::InputError;
    let file = path.display().to_string();
    let err = |line: Option<u64>, column: Option<&str>, value: Option<&str>, message: String| {
        RunError::Input(InputError {
            file: file.clone(),
            line,
            column: column.map(str::to_string),
            value: value.map(|v| crate::io::clip(v, crate::io::ECHO_CHARS).into_owned()),
            message,
        })
    };
    let mut r = csv::ReaderBuilder::new()
        .flexible(false)
        .from_path(path)
        .map_err(|e| err(None, None, None, format!("cannot read: {e}")))?;
    let header = r
        .headers()
        .map_err(|e| err(Some(1), None, None, e.to_string()))?
        .clone();
    let col = |name: &str| -> Result<usize, RunError> {
        header.iter().position(|h| h.trim() == name).ok_or_else(|| {
            err(
                Some(1),
                Some(name),
                None,
                "missing column: a design has the columns series,xi,delta_deg,replicates".into(),
            )
        })
    };
    let (cs, cx, cd, cr) = (
        col("series")?,
        col("xi")?,
        col("delta_deg")?,
        col("replicates")?,
    );
    let mut out = Vec::new();
    let mut total: usize = 0;
    for rec in r.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map(|p| p.line());
            err(line, None, None, e.to_string())
        })?;
        let line = rec.position().map_or(0, |p| p.line());
        let cell = |c: usize| rec.get(c).unwrap_or("").trim();
        let num = |c: usize, name: &str, ok: &dyn Fn(f64) -> bool, what: &str| {
            cell(c)
                .parse::<f64>()
                .ok()
                .filter(|v| ok(*v))
                .ok_or_else(|| err(Some(line), Some(name), Some(cell(c)), what.to_string()))
        };
        let xi = num(
            cx,
            "xi",
            &|v| v.is_finite() && v > 0.0,
            "expected a radius ratio > 0",
        )?;
        let delta_deg = num(
            cd,
            "delta_deg",
            &|v| v.is_finite() && v > 0.0 && v < 90.0,
            "expected a slope in degrees in (0, 90)",
        )?;
        let replicates = cell(cr)
            .parse::<usize>()
            .ok()
            .filter(|n| (1..=MAX_POINTS).contains(n))
            .ok_or_else(|| {
                err(
                    Some(line),
                    Some("replicates"),
                    Some(cell(cr)),
                    format!("expected a whole number of points from 1 to {MAX_POINTS}"),
                )
            })?;
        total = total.saturating_add(replicates);
        if total > MAX_ROWS {
            return Err(err(
                Some(line),
                Some("replicates"),
                Some(cell(cr)),
                format!("the design asks for more than {MAX_ROWS} points in all"),
            ));
        }
        let series = if cell(cs).is_empty() {
            fmt_f64(xi)
        } else {
            cell(cs).to_string()
        };
        if let Some(message) = mixed_series(&out, &series, xi) {
            return Err(err(Some(line), Some("xi"), Some(cell(cx)), message));
        }
        out.push(DesignLine {
            line,
            series,
            xi,
            delta_deg,
            replicates,
        });
    }
    if out.is_empty() {
        return Err(err(None, None, None, "the design has no rows".into()));
    }
    Ok(out)
}

/// Synthetic points at exactly the design's slopes, `replicates` at each, noise drawn from
/// the seed's stream in the file's order.
fn simulate_design(
    a: &SimulateSettings,
    path: &std::path::Path,
    law: CollisionLaw,
    model_for: &dyn Fn(f64) -> Result<Model, RunError>,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<u8>, RunError> {
    let rows = read_design(path)?;
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| RunError::Failed(e.to_string());
    w.write_record(slope_header(
        a,
        &["series", "xi", "delta_deg", "v", "sigma_v", "v_true"],
    ))
    .map_err(io)?;
    for row in &rows {
        if a.stopped() {
            return Err(RunError::Interrupted);
        }
        let at = |message: String| {
            RunError::Input(crate::io::InputError {
                file: path.display().to_string(),
                line: Some(row.line),
                column: Some("delta_deg".into()),
                value: Some(fmt_f64(row.delta_deg)),
                message,
            })
        };
        let model = model_for(row.xi)?;
        let scene =
            Scene::new(row.xi, row.delta_deg, a.rho, a.f, law).map_err(|e| at(e.to_string()))?;
        let v_true = model
            .evaluate(&scene)
            .map_err(|e| at(format!("no steady state at xi {}: {e}", fmt_f64(row.xi))))?
            .mean_velocity;
        for _ in 0..row.replicates {
            let v = noisy(v_true, a.noise, rng);
            let slope = recorded_slope(a, row.delta_deg, rng);
            let cells = [
                row.series.clone(),
                fmt_f64(row.xi),
                slope.delta_cell(),
                fmt_f64(v),
                sigma_cell(a.noise * v_true),
                fmt_f64(v_true),
            ];
            w.write_record(slope.cells(cells)).map_err(io)?;
        }
    }
    w.into_inner().map_err(|e| RunError::Failed(e.to_string()))
}

/// A measured velocity around `v_true` > 0: v_true (1 + noise · z), z a standard normal
/// draw truncated to 1 + noise · z > 0 (drawn again until it is), so that every simulated
/// velocity is positive, as a measured mean velocity is. Below noise 0.2 the truncation
/// (z < −5) is never met in practice; near the largest noise allowed, 0.5, it removes the
/// 2.3 % tail below z = −2, which lowers the spread of v by about 6 % and raises its mean by
/// about 0.06 σ. A `v_true` that is not positive is returned as it is.
fn noisy(v_true: f64, noise: f64, rng: &mut ChaCha8Rng) -> f64 {
    if !(v_true > 0.0) {
        return v_true;
    }
    loop {
        let z: f64 = StandardNormal.sample(rng);
        let v = v_true * (1.0 + noise * z);
        if v > 0.0 {
            return v;
        }
    }
}

/// The slope of a synthetic point as recorded: the true slope (degrees) and, with σ_δ > 0,
/// the recorded one drawn around it ([`recorded_slope`]).
struct RecordedSlope {
    /// The slope the velocity was made at, degrees.
    true_deg: f64,
    /// The recorded slope and σ_δ, degrees; `None` when the slopes are exact.
    noisy: Option<(f64, f64)>,
}

impl RecordedSlope {
    /// The `delta_deg` cell: the recorded slope.
    fn delta_cell(&self) -> String {
        fmt_f64(self.noisy.map_or(self.true_deg, |(d, _)| d))
    }

    /// A row's `cells` with `sigma_delta_deg` and `delta_true_deg` after them when the slope
    /// is noisy.
    fn cells<const N: usize>(&self, cells: [String; N]) -> Vec<String> {
        let mut out = cells.to_vec();
        if let Some((_, sigma)) = self.noisy {
            out.push(fmt_f64(sigma));
            out.push(fmt_f64(self.true_deg));
        }
        out
    }
}

/// The header `columns`, with `sigma_delta_deg` and `delta_true_deg` after them when the
/// settings draw noisy slopes (σ_δ > 0).
fn slope_header(a: &SimulateSettings, columns: &[&'static str]) -> Vec<&'static str> {
    let mut out = columns.to_vec();
    if a.sigma_delta > 0.0 {
        out.extend(["sigma_delta_deg", "delta_true_deg"]);
    }
    out
}

/// The recorded slope of a point made at `true_deg` degrees: with σ_δ > 0, δ_true + σ_δ · z,
/// z a standard normal draw from `rng` truncated to a slope in (0, 90) degrees (drawn again
/// until it is, as [`noisy`] truncates a velocity); with σ_δ = 0 the true slope, no draw
/// made (the stream, and so the output, is that of exact slopes).
fn recorded_slope(a: &SimulateSettings, true_deg: f64, rng: &mut ChaCha8Rng) -> RecordedSlope {
    let sigma = a.sigma_delta;
    let noisy = (sigma > 0.0).then(|| loop {
        let z: f64 = StandardNormal.sample(rng);
        let d = true_deg + sigma * z;
        if d > 0.0 && d < 90.0 {
            break (d, sigma);
        }
    });
    RecordedSlope { true_deg, noisy }
}

/// The `sigma_v` cell of a synthetic point: empty when σ is 0 (noise 0), so that the file
/// reads as noise-free data (unit weights) rather than as a refused σ = 0.
fn sigma_cell(sigma: f64) -> String {
    if sigma > 0.0 {
        fmt_f64(sigma)
    } else {
        String::new()
    }
}

/// Synthetic measurements of the molecular-dynamics model: regime B found per series by md
/// runs, then one md run per point.
fn run_md(a: &SimulateSettings, series: &[f64]) -> Result<Vec<u8>, RunError> {
    let md: Md = a.md;
    if !(a.rho > 0.0) {
        return Err(flag_error(
            "--rho",
            &fmt_f64(a.rho),
            "md needs rho > 0 (the bead's moment of inertia)",
        ));
    }
    let never = AtomicBool::new(false);
    let stop: &AtomicBool = a.stop.as_deref().unwrap_or(&never);
    let per_series = (MD_SCAN_POINTS + 2 * MD_REFINE + a.points) as u64;
    let tally = a.progress.as_ref().map(|p| {
        p.report(ProgressEvent::Start {
            label: "md simulate",
            total: per_series * series.len() as u64,
            check_every: 1,
        });
        crate::progress::Tally::new(p.clone())
    });
    let tick = || {
        if let Some(t) = &tally {
            t.add(1);
        }
    };
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| RunError::Failed(e.to_string());
    w.write_record(slope_header(
        a,
        &[
            "series",
            "xi",
            "delta_deg",
            "v",
            "sigma_v",
            "v_true",
            "v_md_stderr",
            "v_m_s",
        ],
    ))
    .map_err(io)?;
    for &xi in series {
        let (lo, hi) = md_steady_range(a, &md, xi, &tick, stop)?;
        for (d, r) in md_points(a, &md, xi, (lo, hi), &tick, stop)? {
            let (Some(v_true), Some(se)) = (r.mean_velocity, r.stderr) else {
                return Err(RunError::Failed(format!(
                    "md: xi {xi}, delta {d} deg: no mean velocity measured"
                )));
            };
            let v = noisy(v_true, a.noise, &mut rng);
            let sigma = (a.noise * v_true).hypot(se);
            let slope = recorded_slope(a, d, &mut rng);
            let cells = [
                fmt_f64(xi),
                fmt_f64(xi),
                slope.delta_cell(),
                fmt_f64(v),
                sigma_cell(sigma),
                fmt_f64(v_true),
                fmt_f64(se),
                r.mean_velocity_si.map(fmt_f64).unwrap_or_default(),
            ];
            w.write_record(slope.cells(cells)).map_err(io)?;
        }
    }
    if let Some(p) = &a.progress {
        p.report(ProgressEvent::Finish);
    }
    w.into_inner().map_err(|e| RunError::Failed(e.to_string()))
}

/// The steady range (regime B) of the series ξ found by md runs, in degrees, cut to the
/// settings' slope range.
fn md_steady_range(
    a: &SimulateSettings,
    md: &Md,
    xi: f64,
    tick: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<(f64, f64), RunError> {
    let sc = Scene::new(xi, 1.0, a.rho, 0.1, CollisionLaw::Value(0.5))
        .map_err(|e| flag_error("--series", &xi.to_string(), e.to_string()))?;
    md.check_scene(&sc).map_err(|e| md_error(a, xi, e))?;
    let interval = md_regime_b_interval(md, xi, a.rho, tick, Some(stop))
        .map_err(|e| flag_error("--series", &xi.to_string(), e.to_string()))?;
    if stop.load(Ordering::Relaxed) {
        return Err(RunError::Interrupted);
    }
    let Some((lo, hi)) = interval else {
        return Err(flag_error(
            "--series",
            &xi.to_string(),
            "md finds no steady regime (B) for this xi between 0.5 and 45 degrees",
        ));
    };
    let range = a.delta_range;
    Ok(match range {
        Some((l, h)) => {
            let (l, h) = (l.max(lo), h.min(hi));
            if !(l < h) {
                return Err(flag_error(
                    "--delta-range",
                    &range_text(range),
                    format!(
                        "no steady state in this range at xi = {xi} (md steady from {} to {} deg)",
                        fmt_f64(lo),
                        fmt_f64(hi)
                    ),
                ));
            }
            (l, h)
        }
        None => (lo, hi),
    })
}

/// The md runs of the points of the series ξ over `range` (degrees), each slope with its
/// result. Near the ends of regime B the md bead's bounces are chaotic and B can have holes:
/// a point that is not in B narrows the range from its side and the points are redrawn, at
/// most [`MD_NARROW`] times.
fn md_points(
    a: &SimulateSettings,
    md: &Md,
    xi: f64,
    range: (f64, f64),
    tick: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Vec<(f64, MdResult)>, RunError> {
    let note = |s: &str| {
        if let Some(n) = &a.notes {
            n(s);
        }
    };
    let (mut lo, mut hi) = range;
    for attempt in 0..=MD_NARROW {
        let slopes: Vec<f64> = (0..a.points)
            .map(|j| {
                let frac = if a.points == 1 {
                    0.5
                } else {
                    0.05 + 0.9 * j as f64 / (a.points - 1) as f64
                };
                // Rounded to 1e-4 degree, as a measured slope would be written.
                ((lo + (hi - lo) * frac) * 1e4).round() / 1e4
            })
            .collect();
        let done: Vec<(f64, MdResult)> = slopes
            .par_iter()
            .map(|&d| {
                let sc = Scene::new(xi, d, a.rho, 0.1, CollisionLaw::Value(0.5))
                    .map_err(|e| RunError::Failed(e.to_string()))?;
                let r = md.simulate_until(&sc, 1.0, None, Some(stop));
                tick();
                Ok((d, r))
            })
            .collect::<Result<_, RunError>>()?;
        if stop.load(Ordering::Relaxed) {
            return Err(RunError::Interrupted);
        }
        let bad: Vec<f64> = done
            .iter()
            .filter(|x| x.1.regime != Some(Regime::B))
            .map(|x| x.0)
            .collect();
        if bad.is_empty() {
            return Ok(done);
        }
        if attempt == MD_NARROW {
            return Err(RunError::Failed(format!(
                "md: xi {xi}: slopes {bad:?} deg are not in regime B after narrowing the \
                 steady range {MD_NARROW} times (now {} to {} deg); give --delta-range",
                fmt_f64(lo),
                fmt_f64(hi)
            )));
        }
        let mid = 0.5 * (lo + hi);
        let (old_lo, old_hi) = (lo, hi);
        for &d in &bad {
            if d >= mid {
                hi = hi.min(d - 0.01 * (old_hi - old_lo));
            } else {
                lo = lo.max(d + 0.01 * (old_hi - old_lo));
            }
        }
        note(&format!(
            "md, xi {xi}: slopes {bad:?} deg are not in regime B; steady range narrowed \
             from [{}, {}] to [{}, {}] deg",
            fmt_f64(old_lo),
            fmt_f64(old_hi),
            fmt_f64(lo),
            fmt_f64(hi)
        ));
    }
    Ok(Vec::new())
}

/// A scene outside the md model's domain, as the setting to change.
fn md_error(a: &SimulateSettings, xi: f64, e: crate::scene::ParameterError) -> RunError {
    use crate::scene::ParameterError;
    let (flag, value) = match &e {
        ParameterError::InvalidParameter { field: "rho", .. } => ("--rho", fmt_f64(a.rho)),
        ParameterError::InvalidParameter { field, value, .. } => (*field, value.clone()),
        _ => ("--series", fmt_f64(xi)),
    };
    let flag = match flag {
        "--rho" | "--series" => flag.to_string(),
        f => match crate::models::md::MdSetting::from_column(f) {
            Some(s) => format!("--{}", s.flag()),
            None => format!("--{}", f.replace('_', "-")),
        },
    };
    flag_error(&flag, &value, e.to_string())
}

#[cfg(test)]
mod slope_noise_tests {
    use super::*;

    fn run(s: &SimulateSettings) -> String {
        String::from_utf8(s.run().unwrap()).unwrap()
    }

    /// σ_δ = 0 writes what the settings without it write; σ_δ > 0 adds the two columns, the
    /// true slopes those of the exact run, the recorded ones spread around them by σ_δ.
    #[test]
    fn noisy_slopes_spread_by_sigma_delta() {
        let base = SimulateSettings {
            model: ModelKind::Stick,
            series: vec![1.0, 2.0],
            points: 250,
            ..SimulateSettings::default()
        };
        let exact = run(&base);
        let zero = run(&SimulateSettings {
            sigma_delta: 0.0,
            ..base.clone()
        });
        assert_eq!(zero, exact);
        let sigma = 0.3;
        let noisy = run(&SimulateSettings {
            sigma_delta: sigma,
            ..base.clone()
        });
        let mut lines = noisy.lines();
        assert_eq!(
            lines.next(),
            Some("series,xi,delta_deg,v,sigma_v,v_true,sigma_delta_deg,delta_true_deg")
        );
        let mut diffs = Vec::new();
        for (row, plain) in lines.zip(exact.lines().skip(1)) {
            let c: Vec<&str> = row.split(',').collect();
            let p: Vec<&str> = plain.split(',').collect();
            assert_eq!(c[6], "0.3", "{row}");
            // The velocity is made at the true slope, the exact run's.
            assert_eq!((c[0], c[1], c[5], c[7]), (p[0], p[1], p[5], p[2]), "{row}");
            let d: f64 = c[2].parse().unwrap();
            let t: f64 = c[7].parse().unwrap();
            diffs.push(t - d);
        }
        assert_eq!(diffs.len(), 500);
        let n = diffs.len() as f64;
        let mean = diffs.iter().sum::<f64>() / n;
        let sd = (diffs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        // The sample sd of 500 normal draws is within 15 % of σ far beyond 3 standard errors
        // (its relative standard error is 1/sqrt(2 (n − 1)) ≈ 3.2 %); the mean within 4 of its.
        assert!((sd / sigma - 1.0).abs() < 0.15, "sd {sd}");
        assert!(mean.abs() < 4.0 * sigma / n.sqrt(), "mean {mean}");
    }

    /// A design's points get the same columns; a bad σ_δ is named by its flag.
    #[test]
    fn noisy_slopes_of_a_design_and_bad_values() {
        let dir = std::env::temp_dir().join(format!("fitbead-sd-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let design = dir.join("design.csv");
        std::fs::write(&design, "series,xi,delta_deg,replicates\nA,1,10,3\n").unwrap();
        let s = SimulateSettings {
            model: ModelKind::Stick,
            design: Some(design),
            sigma_delta: 0.2,
            ..SimulateSettings::default()
        };
        let out = run(&s);
        std::fs::remove_dir_all(&dir).unwrap();
        let mut lines = out.lines();
        assert!(lines
            .next()
            .unwrap()
            .ends_with(",sigma_delta_deg,delta_true_deg"));
        for row in lines {
            assert!(row.ends_with(",0.2,10"), "{row}");
        }
        for x in [-0.1, f64::NAN, f64::INFINITY, 90.0] {
            let e = SimulateSettings {
                sigma_delta: x,
                ..SimulateSettings::default()
            }
            .run()
            .unwrap_err();
            let RunError::Input(ie) = &e else {
                panic!("{x}: {e}")
            };
            assert_eq!(ie.column.as_deref(), Some("--sigma-delta"), "{x}: {e}");
        }
    }
}
