//! `fitbead k`: the collisional parameter K of every measured point (eq 69), its interval at
//! v ± σ, and why where there is none.

use super::{emit, read_input, CliError};
use fitbead::fit::k::auto::{self as kauto, KChoice};
use fitbead::fit::k::{estimate, KEstimate, KFailure, LowerLimit, UpperLimit};
use fitbead::io::measurements::{read_measurements, Measurement};
use fitbead::io::scenes::Table;
use fitbead::io::{fmt_f64, write_atomic};
use fitbead::models::auto::Auto;
use fitbead::models::{Model, ModelKind};
use fitbead::report::figures::{scatter_svg, PointSeries, Scatter};
use fitbead::scene::CollisionLaw;
use rayon::prelude::*;
use std::path::PathBuf;

/// Arguments of `fitbead k`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Contact model: stick, stick-approx, slip, slip-approx, stickslip, contact, or auto (per
    /// row the model chosen at the stick K; see --tol).
    #[arg(long)]
    pub model: String,
    /// Measurements CSV: series,xi,delta_deg,v[,sigma_v] (v dimensionless), or dimensional
    /// v_m_s,R_m[,g][,sigma_v_m_s] instead of v. Without it: the embedded default data set.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// The measurements CSV given as a plain argument (same as --input).
    #[arg(value_name = "DATA.csv", conflicts_with = "input")]
    pub data: Option<PathBuf>,
    /// Gyration parameter ρ (2/5 sphere, 1/2 cylinder), for rows without a rho column.
    #[arg(long, default_value_t = 0.4)]
    pub rho: f64,
    /// Coulomb friction coefficient f, for rows without an f column.
    #[arg(long, default_value_t = 0.1)]
    pub f: f64,
    /// Gravity g in m/s² for dimensional rows without a g column.
    #[arg(long, default_value_t = 9.81)]
    pub g: f64,
    /// Output CSV (written atomically); stdout when absent.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// SVG of K against the steady final velocity, one colour per series, with the cos 2α
    /// lines (as the paper's Fig. 5).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// With --model auto: the target relative tolerance T on v of the model chosen per row.
    #[arg(long, default_value_t = 1e-10)]
    pub tol: f64,
}

/// The contract columns, in order.
pub const COLUMNS: [&str; 18] = [
    "series",
    "xi",
    "delta_deg",
    "v",
    "sigma_v",
    "model",
    "K",
    "K_lo",
    "K_hi",
    "dv_dK",
    "final_velocity",
    "theta_G_deg",
    "K_cos2a",
    "K_adjusted",
    "K_impact",
    "regime",
    "status",
    "iterations",
];

/// Columns added after [`EXTRA_COLUMNS`] by --model auto: the model each row was inverted
/// with, and why.
pub const AUTO_COLUMNS: [&str; 2] = ["model_used", "reason"];

/// Columns added after the contract ones.
pub const EXTRA_COLUMNS: [&str; 5] = ["K_min", "K_max", "lower_limit", "upper_limit", "message"];

/// Parses the model flag of `k` (the five contact models).
pub fn parse_model(name: &str) -> Result<Model, CliError> {
    let err = || {
        super::flag_error(
            "--model",
            name,
            "expected one of stick, stick-approx, slip, slip-approx, stickslip, contact",
        )
    };
    let kind: ModelKind = name.parse().map_err(|_| err())?;
    if kind == ModelKind::Md {
        return Err(super::flag_error(
            "--model",
            name,
            "model md has no K inversion (its collisions come from the contact forces)",
        ));
    }
    if kind == ModelKind::Auto {
        return Err(super::flag_error(
            "--model",
            name,
            "model auto is chosen per row by k and klaw themselves (see --tol), not here",
        ));
    }
    kind.contact_model().ok_or_else(err)
}

/// The auto model of `--model auto --tol T` (k and klaw), or `None` for any other model.
pub fn parse_auto(name: &str, tol: f64) -> Result<Option<Auto>, CliError> {
    if name != "auto" {
        return Ok(None);
    }
    if !(tol > 0.0 && tol < 1.0) {
        return Err(super::flag_error(
            "--tol",
            &tol.to_string(),
            "expected a relative tolerance in (0, 1)",
        ));
    }
    Ok(Some(Auto { tol }))
}

/// Runs `fitbead k`.
pub fn run(a: Args) -> Result<(), CliError> {
    // Per row, the model chosen at the stick K
    let auto = parse_auto(&a.model, a.tol)?;
    let model = match auto {
        Some(_) => Model::Stick,
        None => parse_model(&a.model)?,
    };
    let input = a.input.as_deref().or(a.data.as_deref());
    let (source, text) = read_input(input)?;
    let t = Table::parse(&source, &text)?;
    let defaults = super::measurement_defaults(a.rho, a.f, a.g)?;
    let rows = read_measurements(&t, &defaults)?;
    super::warn_implausible(&t, &rows);
    let (results, autos): (Vec<KEstimate>, Vec<Option<KChoice>>) = rows
        .par_iter()
        .map(|r| match &auto {
            Some(au) => {
                let c = kauto::choose(au, &r.scene, r.v);
                (estimate(&c.model, &r.scene, r.v, r.sigma_v), Some(c))
            }
            None => (estimate(&model, &r.scene, r.v, r.sigma_v), None),
        })
        .unzip();
    let bytes = render(&t, &rows, &results, &autos, &a.model)
        .map_err(|e| CliError::Other(e.to_string()))?;
    if let Some(p) = &a.plot {
        let svg = plot(&rows, &results, &a.model).map_err(CliError::Other)?;
        write_atomic(p, svg.as_bytes())
            .map_err(|e| CliError::Other(format!("{}: cannot write: {e}", p.display())))?;
    }
    emit(a.output.as_deref(), &bytes)
}

fn lower_name(l: LowerLimit) -> &'static str {
    match l {
        LowerLimit::Crawl => "crawl-over-top",
        LowerLimit::Zero => "K=0",
        LowerLimit::Model => "model-limit",
    }
}

fn upper_name(u: UpperLimit) -> &'static str {
    match u {
        UpperLimit::LiftOff => "lift-off",
        UpperLimit::Model => "model-limit",
    }
}

fn render(
    t: &Table,
    rows: &[Measurement],
    res: &[KEstimate],
    autos: &[Option<KChoice>],
    model: &str,
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::with_capacity(rows.len() * 260));
    // Model_used, reason after the extra columns
    let auto = autos.iter().any(|a| a.is_some());
    let auto_cols: &[&str] = if auto { &AUTO_COLUMNS } else { &[] };
    let own: Vec<&str> = COLUMNS
        .iter()
        .chain(EXTRA_COLUMNS.iter())
        .chain(auto_cols.iter())
        .copied()
        .collect();
    let input_own = ["series", "xi", "delta_deg", "v", "sigma_v"];
    let pass: Vec<usize> = (0..t.headers.len())
        .filter(|&i| !input_own.contains(&t.headers[i].as_str()))
        .collect();
    let mut header: Vec<String> = own.iter().map(|s| s.to_string()).collect();
    for &i in &pass {
        let h = &t.headers[i];
        header.push(if own.contains(&h.as_str()) {
            format!("in_{h}")
        } else {
            h.clone()
        });
    }
    w.write_record(&header)?;
    let opt = |x: Option<f64>| x.map(fmt_f64).unwrap_or_default();
    for (i, ((row, e), au)) in rows.iter().zip(res).zip(autos).enumerate() {
        let s = &row.scene;
        let mut out: Vec<String> = Vec::with_capacity(header.len());
        out.push(row.series.clone());
        out.push(fmt_f64(s.xi()));
        out.push(t.cell(i, t.col("delta_deg").unwrap_or(0)).to_string());
        out.push(fmt_f64(row.v));
        out.push(opt(row.sigma_v));
        out.push(model.to_string());
        let (k, fv, iters) = match &e.root {
            Ok(r) => (
                Some(r.k),
                Some(r.steady.final_velocity),
                Some(r.evals as f64),
            ),
            Err(_) => (None, None, None),
        };
        out.push(opt(k));
        out.push(opt(e.k_lo));
        out.push(opt(e.k_hi));
        out.push(opt(e.dv_dk));
        out.push(opt(fv));
        out.push(opt(e.theta_g.map(f64::to_degrees)));
        out.push(fmt_f64(CollisionLaw::Cos2a.k(s.alpha_rad(), s.rho())));
        out.push(fmt_f64(CollisionLaw::Adjusted.k(s.alpha_rad(), s.rho())));
        out.push(fmt_f64(CollisionLaw::Impact.k(s.alpha_rad(), s.rho())));
        let (regime, status) = match &e.root {
            Ok(_) => ("B", "ok"),
            Err(KFailure::BelowRange) => ("A", "below-range"),
            Err(KFailure::AboveRange) => ("C", "above-range"),
            Err(KFailure::Invalid(_)) => ("", "invalid"),
        };
        out.push(regime.into());
        out.push(status.into());
        out.push(opt(iters));
        match &e.bracket {
            Some(b) => {
                out.push(fmt_f64(b.lo));
                out.push(fmt_f64(b.hi));
                out.push(lower_name(b.lower).into());
                out.push(upper_name(b.upper).into());
            }
            None => out.extend(std::iter::repeat_n(String::new(), 4)),
        }
        let mut msg: Vec<String> = Vec::new();
        if let Err(f) = &e.root {
            msg.push(f.to_string());
        }
        msg.extend(e.notes.iter().cloned());
        out.push(msg.join("; "));
        if auto {
            match au {
                Some(c) => {
                    out.push(c.choice.name().to_string());
                    out.push(c.reason.clone());
                }
                None => out.extend([String::new(), String::new()]),
            }
        }
        for &c in &pass {
            out.push(t.cell(i, c).to_string());
        }
        w.write_record(&out)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

fn plot(rows: &[Measurement], res: &[KEstimate], model: &str) -> Result<String, String> {
    let mut series: Vec<PointSeries> = Vec::new();
    for (row, e) in rows.iter().zip(res) {
        let Ok(r) = &e.root else { continue };
        let label = if row.series.is_empty() {
            format!("xi = {}", fmt_f64(row.scene.xi()))
        } else {
            format!("series {}", row.series)
        };
        let idx = match series.iter().position(|s| s.label == label) {
            Some(i) => i,
            None => {
                let c2 = CollisionLaw::Cos2a.k(row.scene.alpha_rad(), row.scene.rho());
                series.push(PointSeries {
                    label: label.clone(),
                    points: Vec::new(),
                    reference: Some((c2, format!("cos 2alpha = {c2:.4}"))),
                });
                series.len() - 1
            }
        };
        series[idx].points.push((
            r.steady.final_velocity,
            r.k,
            e.k_lo.unwrap_or(r.k),
            e.k_hi.unwrap_or(r.k),
        ));
    }
    scatter_svg(&Scatter {
        title: format!("K per measurement (eq 69), {model} model"),
        x_label: "steady final velocity (units sqrt(g(R+r)))".into(),
        y_label: "K".into(),
        series,
    })
}
