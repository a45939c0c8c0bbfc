//! `fitbead simulate`: synthetic measurements spread inside regime B of each series, with
//! multiplicative Gaussian noise, reproducible from the seed (ChaCha8 stream).

use super::{emit, parse_list, CliError};
use crate::io::fmt_f64;
use crate::models::jan::Jan;
use crate::models::{ForwardModel, Model, ModelKind};
use crate::scene::{CollisionLaw, Scene};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::path::PathBuf;

/// Arguments of `fitbead simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Forward model that makes the data: stick, stick-approx, slip, slip-approx, stickslip, jan
    /// (jan with the paper's fits, eqs 75–76).
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
    /// Gyration parameter ρ.
    #[arg(long, default_value_t = 0.4)]
    pub rho: f64,
    /// Coulomb friction coefficient f.
    #[arg(long, default_value_t = 0.1)]
    pub f: f64,
    /// Output CSV (written atomically); stdout when absent.
    #[arg(long)]
    pub output: Option<PathBuf>,
}

/// The slopes (radians) where `model` has a steady state at this ξ: the longest run of a
/// 2000-point scan of (0°, 89°), its ends refined by bisection to 1e-12 rad.
pub fn regime_b_interval(
    model: &Model,
    xi: f64,
    rho: f64,
    f: f64,
    law: CollisionLaw,
) -> Option<(f64, f64)> {
    let ok = |d: f64| {
        Scene::from_radians(xi, d, rho, f, law)
            .map(|s| model.evaluate(&s).is_ok())
            .unwrap_or(false)
    };
    let n = 2000;
    let top = 89f64.to_radians();
    let grid: Vec<f64> = (1..n).map(|i| top * i as f64 / n as f64).collect();
    let flags: Vec<bool> = grid.iter().map(|&d| ok(d)).collect();
    let (mut best, mut cur): ((usize, usize), Option<usize>) = ((0, 0), None);
    for i in 0..=flags.len() {
        let f = i < flags.len() && flags[i];
        match (f, cur) {
            (true, None) => cur = Some(i),
            (false, Some(s)) => {
                if i - s > best.1 - best.0 {
                    best = (s, i);
                }
                cur = None;
            }
            _ => {}
        }
    }
    if best.1 == best.0 {
        return None;
    }
    let bisect = |mut good: f64, mut bad: f64| {
        for _ in 0..60 {
            let m = 0.5 * (good + bad);
            if ok(m) {
                good = m
            } else {
                bad = m
            }
            if (good - bad).abs() < 1e-12 {
                break;
            }
        }
        good
    };
    let lo = if best.0 == 0 {
        grid[0]
    } else {
        bisect(grid[best.0], grid[best.0 - 1])
    };
    let hi = if best.1 >= grid.len() {
        grid[grid.len() - 1]
    } else {
        bisect(grid[best.1 - 1], grid[best.1])
    };
    Some((lo, hi))
}

/// Runs `fitbead simulate`.
pub fn run(a: Args) -> Result<(), CliError> {
    let kind: ModelKind = a
        .model
        .parse()
        .map_err(|_| super::flag_error("--model", &a.model, "unknown model"))?;
    let law: CollisionLaw = a
        .law
        .parse()
        .map_err(|e: crate::Error| super::flag_error("--law", &a.law, e.to_string()))?;
    let series = parse_list("--series", &a.series)?;
    if a.points == 0 {
        return Err(super::flag_error(
            "--points",
            "0",
            "need at least one point per series",
        ));
    }
    if !(a.noise.is_finite() && (0.0..0.5).contains(&a.noise)) {
        return Err(super::flag_error(
            "--noise",
            &a.noise.to_string(),
            "must be in [0, 0.5)",
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::Other(e.to_string());
    w.write_record(["series", "xi", "delta_deg", "v", "sigma_v", "v_true"])
        .map_err(io)?;
    for &xi in &series {
        let alpha = Scene::from_radians(xi, 0.1, a.rho, a.f, law)
            .map_err(|e| super::flag_error("--series", &xi.to_string(), e.to_string()))?
            .alpha;
        let model = match (kind, kind.contact_model()) {
            (_, Some(m)) => m,
            (ModelKind::Jan, None) => Model::Jan(Jan::paper_fit(alpha)),
            _ => {
                return Err(super::flag_error(
                    "--model",
                    "jaeger",
                    "simulate does not support jaeger",
                ))
            }
        };
        let Some((lo, hi)) = regime_b_interval(&model, xi, a.rho, a.f, law) else {
            return Err(super::flag_error(
                "--series",
                &xi.to_string(),
                "no steady regime for this xi under this model and law",
            ));
        };
        for j in 0..a.points {
            let frac = if a.points == 1 {
                0.5
            } else {
                0.05 + 0.9 * j as f64 / (a.points - 1) as f64
            };
            let d = lo + (hi - lo) * frac;
            // Round the slope to 1e-4 degree, as a measured slope would be written.
            let d_deg = (d.to_degrees() * 1e4).round() / 1e4;
            let scene = Scene::new(xi, d_deg, a.rho, a.f, law)
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
                fmt_f64(a.noise * v_true),
                fmt_f64(v_true),
            ])
            .map_err(io)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.output.as_deref(), &bytes)
}
