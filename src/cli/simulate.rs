//! `fitbead simulate`: synthetic measurements spread inside regime B of each series, with
//! multiplicative Gaussian noise, reproducible from the seed (ChaCha8 stream).

use super::args::{ContactArgs, OutputArgs};
use super::{emit, parse_list, CliError};
use crate::io::fmt_f64;
use crate::models::contact::{Contact, SpinRule};
use crate::models::jaeger::Jaeger;
use crate::models::jan::Jan;
use crate::models::md::{
    regime_b_interval_until as md_regime_b_interval, MD_NARROW, MD_REFINE, MD_SCAN_POINTS,
};
use crate::models::regimes::regime_b_interval;
use crate::models::{ForwardModel, Model, ModelKind};
use crate::scene::{CollisionLaw, Scene};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::sync::atomic::{AtomicBool, Ordering};

/// Arguments of `fitbead simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Forward model that makes the data: stick, stick-approx, slip, slip-approx, stickslip,
    /// contact (with --v0: the bead-by-bead transient instead), jan (see --jan), jaeger (see
    /// --jaeger), md (molecular dynamics, see the md flags).
    #[arg(long, default_value = "stickslip")]
    pub model: String,
    /// Collision law: a number, cos2a, adjusted, impact or c=VALUE.
    #[arg(long, default_value = "adjusted")]
    pub law: String,
    /// Radius ratios ξ of the series, comma-separated.
    #[arg(long, default_value = "0.8,1,1.6,2")]
    pub series: String,
    /// Points per series.
    #[arg(long, default_value_t = 9)]
    pub points: usize,
    /// Relative noise: v = v_true (1 + noise · N(0,1)), sigma_v = noise · v_true.
    #[arg(long, default_value_t = 0.02)]
    pub noise: f64,
    /// Seed of the random stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// ρ and f of rows without those columns.
    #[command(flatten)]
    pub contact: ContactArgs,
    /// Jan's global laws λ0,λ1,μ0,μ1 (λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α}) for
    /// --model jan [default: 0.063,4.96,0.0025,7.46, the paper's eqs 75–76]
    #[arg(long)]
    pub jan: Option<String>,
    /// Jaeger's a1,a2,a3 (Jaeger units, eq 81) for --model jaeger, used for every series
    /// [default: the paper's Fig. 9 values of the series' ξ, for ξ = 0.8, 1, 1.6 or 2]
    #[arg(long)]
    pub jaeger: Option<String>,
    /// Branch of eq 84 for --model jaeger: upper or lower.
    #[arg(long, default_value = "upper")]
    pub branch: String,
    /// Slopes LO,HI in degrees: the range is cut to the model's steady range and the points
    /// spread over 5 %–95 % of it [default: the steady range; for jan and jaeger, whose steady
    /// range has no upper end, the onset to the onset + 12°]
    #[arg(long)]
    pub delta_range: Option<String>,
    /// A design (CSV: series,xi,delta_deg,replicates, as `fitbead design` writes it): the
    /// data are made at exactly its slopes, `replicates` points at each, instead of spread
    /// over the steady range.
    #[arg(long, conflicts_with_all = ["series", "points", "delta_range", "v0"])]
    pub design: Option<std::path::PathBuf>,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// --model contact only: launch speed Θ̇0 on the first bead (dimensionless, rolling
    /// launch). With it, simulate writes the bead-by-bead transient of one scene per ξ of
    /// --series at --delta-deg instead of synthetic measurements.
    #[arg(long)]
    pub v0: Option<f64>,
    /// Slope of the --v0 transient, degrees.
    #[arg(long = "delta-deg")]
    pub delta_deg: Option<f64>,
    /// Spin rule of the collision for --model contact: roll, keep, factor=L or impact.
    #[arg(long, default_value = "roll")]
    pub spin: String,
    /// Molecular-dynamics settings (`--model md`).
    #[command(flatten)]
    pub md: super::forward::MdArgs,
}

/// Most points per series (`--points`).
pub const MAX_POINTS: usize = 1_000_000;
/// Most rows in all (series × points).
pub const MAX_ROWS: usize = 10_000_000;
/// Most series (`--series`).
pub const MAX_SERIES: usize = 10_000;

/// `simulate --model contact --v0 V --beads N`: the bead-by-bead transient from a launch.
fn trace(
    a: &Args,
    law: CollisionLaw,
    series: &[f64],
    v0: f64,
    model: Contact,
) -> Result<(), CliError> {
    use crate::io::reports::transient_csv;
    if !(v0.is_finite() && v0 >= 0.0) {
        return Err(super::flag_error(
            "--v0",
            &v0.to_string(),
            "expected a finite launch speed >= 0",
        ));
    }
    // --beads (shared with md: row beads travelled) defaults to 50 for the transient.
    let beads = a.md.beads.unwrap_or(50);
    if beads == 0 || beads > 10_000_000 {
        return Err(super::flag_error(
            "--beads",
            &beads.to_string(),
            "expected 1 to 10000000 beads",
        ));
    }
    let Some(d) = a.delta_deg else {
        return Err(super::flag_error(
            "--delta-deg",
            "",
            "--v0 needs the slope of the scene (--delta-deg)",
        ));
    };
    let scenes = series
        .iter()
        .map(|&xi| {
            Scene::new(xi, d, a.contact.rho(), a.contact.f(), law).map_err(|e| {
                super::flag_error("--series/--delta-deg", &xi.to_string(), e.to_string())
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let bytes = transient_csv(&model, &scenes, d, v0, beads)?;
    emit(a.out.output.as_deref(), &bytes)
}

/// `--spin`: the contact model's spin rule. A rule other than the default `roll` is refused
/// for the other models, which have no spin rule.
fn spin_rule(a: &Args, kind: ModelKind) -> Result<SpinRule, CliError> {
    let spin: SpinRule = a.spin.parse().map_err(|e: crate::scene::ParameterError| {
        super::flag_error("--spin", &a.spin, e.to_string())
    })?;
    if kind != ModelKind::Contact && spin != SpinRule::Roll {
        return Err(super::flag_error(
            "--spin",
            &a.spin,
            "a spin rule applies to --model contact only",
        ));
    }
    Ok(spin)
}

/// `--delta-range LO,HI` (degrees, LO < HI), when given.
fn delta_range(flag: Option<&str>) -> Result<Option<(f64, f64)>, CliError> {
    let Some(s) = flag else {
        return Ok(None);
    };
    let r = parse_list("--delta-range", s)?;
    if r.len() != 2 || !(r[0] < r[1]) {
        return Err(super::flag_error(
            "--delta-range",
            s,
            "expected LO,HI in degrees with LO < HI",
        ));
    }
    Ok(Some((r[0], r[1])))
}

/// Runs `fitbead simulate`.
pub fn run(a: Args) -> Result<(), CliError> {
    let kind: ModelKind = a
        .model
        .parse()
        .map_err(|_| super::flag_error("--model", &a.model, "unknown model"))?;
    let law: CollisionLaw = a.law.parse().map_err(|e: crate::scene::ParameterError| {
        super::flag_error("--law", &a.law, e.to_string())
    })?;
    // The contact model under the --spin rule (other models have none).
    let contact = Contact {
        spin: spin_rule(&a, kind)?,
        ..Contact::default()
    };
    let series = parse_list("--series", &a.series)?;
    // Rows of a series are labelled by its ξ: two equal values would make one series.
    for (j, x) in series.iter().enumerate() {
        if let Some(i) = series[..j].iter().position(|y| y == x) {
            let text: Vec<&str> = a.series.split(',').map(str::trim).collect();
            return Err(super::flag_error(
                "--series",
                text[j],
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
        return Err(super::flag_error(
            "--series",
            &format!("{} values", series.len()),
            format!("expected at most {MAX_SERIES} series"),
        ));
    }
    let stop = super::stop_flag();
    if let Some(v0) = a.v0 {
        if kind != ModelKind::Contact {
            return Err(super::flag_error(
                "--v0",
                &v0.to_string(),
                "the bead-by-bead transient needs --model contact",
            ));
        }
        return trace(&a, law, &series, v0, contact);
    }
    if a.points == 0 || a.points > MAX_POINTS {
        return Err(super::flag_error(
            "--points",
            &a.points.to_string(),
            format!("expected 1 to {MAX_POINTS} points per series"),
        ));
    }
    if series.len().saturating_mul(a.points) > MAX_ROWS {
        return Err(super::flag_error(
            "--points",
            &a.points.to_string(),
            format!(
                "{} series of {} points make more than {MAX_ROWS} rows",
                series.len(),
                a.points
            ),
        ));
    }
    if !(a.noise.is_finite() && (0.0..0.5).contains(&a.noise)) {
        return Err(super::flag_error(
            "--noise",
            &a.noise.to_string(),
            "must be in [0, 0.5)",
        ));
    }
    if kind == ModelKind::Md {
        if let Some(p) = &a.design {
            return Err(super::flag_error(
                "--design",
                &p.display().to_string(),
                "a design is simulated with the steady-state models, not --model md",
            ));
        }
        return run_md(&a, &series, &stop);
    }
    let jan = a
        .jan
        .as_deref()
        .map(|s| parse_list("--jan", s))
        .transpose()?;
    if jan.as_ref().is_some_and(|p| p.len() != 4) {
        return Err(super::flag_error(
            "--jan",
            a.jan.as_deref().unwrap_or(""),
            "expected four numbers lambda0,lambda1,mu0,mu1",
        ));
    }
    let jaeger = a
        .jaeger
        .as_deref()
        .map(|s| parse_list("--jaeger", s))
        .transpose()?;
    if jaeger.as_ref().is_some_and(|p| p.len() != 3) {
        return Err(super::flag_error(
            "--jaeger",
            a.jaeger.as_deref().unwrap_or(""),
            "expected three numbers a1,a2,a3",
        ));
    }
    let branch = super::jaeger_branch(&a.branch)?;
    let range = delta_range(a.delta_range.as_deref())?;
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::Other(e.to_string());
    w.write_record(["series", "xi", "delta_deg", "v", "sigma_v", "v_true"])
        .map_err(io)?;
    let model_for = |xi: f64| -> Result<Model, CliError> {
        let alpha = Scene::from_radians(xi, 0.1, a.contact.rho(), a.contact.f(), law)
            .map_err(|e| super::flag_error("--series", &xi.to_string(), e.to_string()))?
            .alpha_rad();
        Ok(match (kind, kind.contact_model()) {
            (ModelKind::Contact, _) => Model::Contact(contact),
            (_, Some(m)) => m,
            (ModelKind::Jan, None) => match &jan {
                None => Model::Jan(Jan::paper_fit(alpha)),
                Some(p) => {
                    let s = alpha.sin();
                    Model::Jan(
                        Jan::new(p[0] * (p[1] * s).exp(), p[2] * (p[3] * s).exp())
                            .map_err(|e| super::flag_error("--jan", "", e.to_string()))?,
                    )
                }
            },
            _ => {
                let p = match &jaeger {
                    Some(p) => [p[0], p[1], p[2]],
                    None => crate::fit::jaeger::paper_values(xi).ok_or_else(|| {
                        super::flag_error(
                            "--series",
                            &xi.to_string(),
                            "the paper gives Jaeger's a1, a2, a3 for xi = 0.8, 1, 1.6, 2 only: \
                             give --jaeger A1,A2,A3",
                        )
                    })?,
                };
                Model::Jaeger(
                    Jaeger::new(p[0], p[1], p[2], branch)
                        .map_err(|e| super::flag_error("--jaeger", "", e.to_string()))?,
                )
            }
        })
    };
    if let Some(path) = a.design.as_deref() {
        return simulate_design(&a, path, law, &model_for, &mut rng);
    }
    for &xi in &series {
        let model = model_for(xi)?;
        let Some((lo, hi)) = regime_b_interval(&model, xi, a.contact.rho(), a.contact.f(), law)
        else {
            return Err(super::flag_error(
                "--series",
                &xi.to_string(),
                "no steady regime for this xi under this model and law",
            ));
        };
        let open_ended = matches!(kind, ModelKind::Jan | ModelKind::Jaeger);
        let (lo, hi, f0, f1) = match range {
            Some((l, h)) => {
                let (l, h) = (l.to_radians().max(lo), h.to_radians().min(hi));
                if !(l < h) {
                    return Err(super::flag_error(
                        "--delta-range",
                        a.delta_range.as_deref().unwrap_or(""),
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
        };
        for j in 0..a.points {
            if stop.load(Ordering::Relaxed) {
                return Err(CliError::Interrupted);
            }
            let frac = if a.points == 1 {
                0.5
            } else {
                f0 + (f1 - f0) * j as f64 / (a.points - 1) as f64
            };
            let d = lo + (hi - lo) * frac;
            // Round the slope to 1e-4 degree, as a measured slope would be written.
            let d_deg = (d.to_degrees() * 1e4).round() / 1e4;
            let scene = Scene::new(xi, d_deg, a.contact.rho(), a.contact.f(), law)
                .map_err(|e| CliError::Other(e.to_string()))?;
            let v_true = match model.evaluate(&scene) {
                Ok(s) => s.mean_velocity,
                Err(e) => return Err(CliError::Other(format!("xi {xi}, delta {d_deg} deg: {e}"))),
            };
            let z: f64 = StandardNormal.sample(&mut rng);
            let v = v_true * (1.0 + a.noise * z);
            w.write_record([
                fmt_f64(xi),
                fmt_f64(xi),
                fmt_f64(d_deg),
                fmt_f64(v),
                sigma_cell(a.noise * v_true),
                fmt_f64(v_true),
            ])
            .map_err(io)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.out.output.as_deref(), &bytes)
}

/// One row of a design file: its line, series label, ξ, slope (degrees) and replicates.
struct DesignLine {
    line: u64,
    series: String,
    xi: f64,
    delta_deg: f64,
    replicates: usize,
}

/// Reads a design file (series,xi,delta_deg,replicates; other columns ignored), every cell
/// checked: a bad one is an error naming file, line, column and value.
fn read_design(path: &std::path::Path) -> Result<Vec<DesignLine>, CliError> {
    use crate::io::InputError;
    let file = path.display().to_string();
    let err = |line: Option<u64>, column: Option<&str>, value: Option<&str>, message: String| {
        CliError::Input(InputError {
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
    let col = |name: &str| -> Result<usize, CliError> {
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

/// `simulate --design FILE`: synthetic points at exactly the design's slopes, `replicates`
/// at each, noise drawn from the seed's stream in the file's order.
fn simulate_design(
    a: &Args,
    path: &std::path::Path,
    law: CollisionLaw,
    model_for: &dyn Fn(f64) -> Result<Model, CliError>,
    rng: &mut ChaCha8Rng,
) -> Result<(), CliError> {
    let rows = read_design(path)?;
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::Other(e.to_string());
    w.write_record(["series", "xi", "delta_deg", "v", "sigma_v", "v_true"])
        .map_err(io)?;
    let stop = super::stop_flag();
    for row in &rows {
        if stop.load(Ordering::Relaxed) {
            return Err(CliError::Interrupted);
        }
        let at = |message: String| {
            CliError::Input(crate::io::InputError {
                file: path.display().to_string(),
                line: Some(row.line),
                column: Some("delta_deg".into()),
                value: Some(fmt_f64(row.delta_deg)),
                message,
            })
        };
        let model = model_for(row.xi)?;
        let scene = Scene::new(row.xi, row.delta_deg, a.contact.rho(), a.contact.f(), law)
            .map_err(|e| at(e.to_string()))?;
        let v_true = model
            .evaluate(&scene)
            .map_err(|e| at(format!("no steady state at xi {}: {e}", fmt_f64(row.xi))))?
            .mean_velocity;
        for _ in 0..row.replicates {
            let z: f64 = StandardNormal.sample(rng);
            let v = v_true * (1.0 + a.noise * z);
            w.write_record([
                row.series.clone(),
                fmt_f64(row.xi),
                fmt_f64(row.delta_deg),
                fmt_f64(v),
                sigma_cell(a.noise * v_true),
                fmt_f64(v_true),
            ])
            .map_err(io)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.out.output.as_deref(), &bytes)
}

/// The `sigma_v` cell of a synthetic point: empty when σ is 0 (`--noise 0`), so that the file
/// reads as noise-free data (unit weights) rather than as a refused σ = 0.
fn sigma_cell(sigma: f64) -> String {
    if sigma > 0.0 {
        fmt_f64(sigma)
    } else {
        String::new()
    }
}

fn run_md(a: &Args, series: &[f64], stop: &AtomicBool) -> Result<(), CliError> {
    use crate::models::md::{Md, MdResult};
    use crate::models::Regime;
    use rayon::prelude::*;
    let md: Md = a.md.model()?;
    if !(a.contact.rho() > 0.0) {
        return Err(super::flag_error(
            "--rho",
            &fmt_f64(a.contact.rho()),
            "md needs rho > 0 (the bead's moment of inertia)",
        ));
    }
    let range = delta_range(a.delta_range.as_deref())?;
    let per_series = (MD_SCAN_POINTS + 2 * MD_REFINE + a.points) as u64;
    let bar = super::forward::md_progress_bar(per_series * series.len() as u64, "md simulate");
    let tick = || {
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::Other(e.to_string());
    w.write_record([
        "series",
        "xi",
        "delta_deg",
        "v",
        "sigma_v",
        "v_true",
        "v_md_stderr",
        "v_m_s",
    ])
    .map_err(io)?;
    for &xi in series {
        let sc = Scene::new(xi, 1.0, a.contact.rho(), 0.1, CollisionLaw::Value(0.5))
            .map_err(|e| super::flag_error("--series", &xi.to_string(), e.to_string()))?;
        md.check_scene(&sc).map_err(|e| md_error(a, xi, e))?;
        let interval = md_regime_b_interval(&md, xi, a.contact.rho(), &tick, Some(stop))
            .map_err(|e| super::flag_error("--series", &xi.to_string(), e.to_string()))?;
        if stop.load(Ordering::Relaxed) {
            return Err(CliError::Interrupted);
        }
        let Some((lo, hi)) = interval else {
            return Err(super::flag_error(
                "--series",
                &xi.to_string(),
                "md finds no steady regime (B) for this xi between 0.5 and 45 degrees",
            ));
        };
        let (lo, hi) = match range {
            Some((l, h)) => {
                let (l, h) = (l.max(lo), h.min(hi));
                if !(l < h) {
                    return Err(super::flag_error(
                        "--delta-range",
                        a.delta_range.as_deref().unwrap_or(""),
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
        };
        // Near the ends of regime B the md bead's bounces are chaotic and B can have holes: a
        // point that is not in B narrows the range from its side and the points are redrawn.
        let (mut lo, mut hi) = (lo, hi);
        let mut runs: Vec<(f64, f64, f64, MdResult)> = Vec::new();
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
            let done: Vec<(f64, f64, f64, MdResult)> = slopes
                .par_iter()
                .map(|&d| {
                    let sc = Scene::new(xi, d, a.contact.rho(), 0.1, CollisionLaw::Value(0.5))
                        .map_err(|e| CliError::Other(e.to_string()))?;
                    let r = md.simulate_until(&sc, 1.0, None, Some(stop));
                    tick();
                    Ok((d, lo, hi, r))
                })
                .collect::<Result<_, CliError>>()?;
            if stop.load(Ordering::Relaxed) {
                return Err(CliError::Interrupted);
            }
            let bad: Vec<f64> = done
                .iter()
                .filter(|x| x.3.regime != Some(Regime::B))
                .map(|x| x.0)
                .collect();
            if bad.is_empty() {
                runs = done;
                break;
            }
            if attempt == MD_NARROW {
                return Err(CliError::Other(format!(
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
            eprintln!(
                "fitbead: note: md, xi {xi}: slopes {bad:?} deg are not in regime B; steady range \
                 narrowed from [{}, {}] to [{}, {}] deg",
                fmt_f64(old_lo),
                fmt_f64(old_hi),
                fmt_f64(lo),
                fmt_f64(hi)
            );
        }
        for (d, _, _, r) in runs {
            let (Some(v_true), Some(se)) = (r.mean_velocity, r.stderr) else {
                return Err(CliError::Other(format!(
                    "md: xi {xi}, delta {d} deg: no mean velocity measured"
                )));
            };
            let z: f64 = StandardNormal.sample(&mut rng);
            let v = v_true * (1.0 + a.noise * z);
            let sigma = (a.noise * v_true).hypot(se);
            w.write_record([
                fmt_f64(xi),
                fmt_f64(xi),
                fmt_f64(d),
                fmt_f64(v),
                sigma_cell(sigma),
                fmt_f64(v_true),
                fmt_f64(se),
                r.mean_velocity_si.map(fmt_f64).unwrap_or_default(),
            ])
            .map_err(io)?;
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let bytes = w.into_inner().map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.out.output.as_deref(), &bytes)
}

/// A scene outside the md model's domain, as the flag to change.
fn md_error(a: &Args, xi: f64, e: crate::scene::ParameterError) -> CliError {
    use crate::scene::ParameterError;
    let (flag, value) = match &e {
        ParameterError::InvalidParameter { field: "rho", .. } => {
            ("--rho", fmt_f64(a.contact.rho()))
        }
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
    super::flag_error(&flag, &value, e.to_string())
}
