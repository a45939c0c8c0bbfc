//! Posterior bands of the mean velocity: for every fit of a posterior analysis
//! ([`Analysis`] under `--method mcmc`) and every series it covers, the 5 %, 50 % and 95 %
//! quantiles of the model's v̄(δ) over the posterior draws, on a grid of slopes spanning the
//! series' measured slopes, and the posterior median of v̄ at each measured point.
//!
//! The band is that of the model's v̄ (the posterior of the mean curve): measurement noise is
//! not added. It uses at most [`BAND_DRAWS`] draws, evenly spaced through the kept draws
//! (step by step, every walker); a draw under which the model has no steady state at a slope
//! is left out of the quantiles there.
//!
//! v̄ of a draw is the fit's own model at the series' ξ, ρ and f:
//! - the K(α) laws (`rolling-klaw-c`, `stickslip-klaw-c`, `…-klaw-free-per-series`): the
//!   contact model's v̄ with K = cos 2α + c sin²α sin 2α (law c) or the series' K;
//! - Jan (`jan-series`, `jan-global`): eq 74 with the series' λ and μ, or with
//!   λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α};
//! - Jaeger (`jaeger`): the root of eq 84 on the fitted branch, v̄ = √(2 cos δ X/ε) (eq 81).

use super::analysis::Analysis;
use crate::fit::data::{Dataset, Point};
use crate::fit::jaeger::JaegerModel;
use crate::fit::jan::{JanGlobal, JanSeries};
use crate::fit::summary::FitResult;
use crate::inverse::mcmc::diagnostics::quantile_sorted;
use crate::inverse::CurveModel as _;
use crate::models::{ForwardModel, Model};
use crate::scene::{CollisionLaw, Scene};
use rayon::prelude::*;
use statrs::distribution::{ContinuousCDF, Normal};
use std::sync::atomic::{AtomicBool, Ordering};

/// Draws used per fit at most.
pub const BAND_DRAWS: usize = 1000;

/// Slopes of the grid per series (equally spaced in degrees from the smallest measured slope
/// to the largest).
pub const BAND_GRID: usize = 41;

/// The band of one fit over one series.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// The fit, named as in params.csv (`rolling-klaw-c`, `jan-series`, `jaeger`, …).
    pub fit: String,
    /// The series label.
    pub series: String,
    /// The series' radius ratio ξ.
    pub xi: f64,
    /// The slopes of the grid, degrees.
    pub delta_deg: Vec<f64>,
    /// 5 % quantile of v̄ at each slope (NaN where no draw has a steady state).
    pub q05: Vec<f64>,
    /// Median of v̄ at each slope.
    pub q50: Vec<f64>,
    /// 95 % quantile of v̄ at each slope.
    pub q95: Vec<f64>,
    /// Draws used.
    pub draws: usize,
}

/// The posterior median of one fit's v̄ at one measured point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMedian {
    /// The fit, named as in params.csv.
    pub fit: String,
    /// The series label.
    pub series: String,
    /// Index of the point in the analysis' data set ([`Analysis::data`]).
    pub point: usize,
    /// Its slope, degrees.
    pub delta_deg: f64,
    /// Posterior median of v̄ there (NaN where no draw has a steady state).
    pub v_median: f64,
}

/// Every band and every point median of an analysis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PosteriorBands {
    /// Per fit and series, fits in the order of params.csv.
    pub bands: Vec<Band>,
    /// Per fit and measured point the fit used, in the same order.
    pub points: Vec<PointMedian>,
}

/// How a fit's parameters (a draw, or the least-squares optimum) give v̄ at a point's ξ, ρ, f
/// and a slope δ (radians); `column` is where the series' own parameters start.
#[derive(Debug, Clone, Copy)]
pub enum Curve {
    /// A contact model with K(α) = cos 2α + c sin²α sin 2α (parameter c).
    LawC(Model),
    /// A contact model with one K per series (parameter K of the series).
    FreeK(Model),
    /// A contact model with the impact law's K (no parameter).
    Impact(Model),
    /// Jan's eq 74 with the series' λ and μ.
    JanSeries,
    /// Jan's eq 74 with λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α}.
    JanGlobal,
    /// Jaeger's eq 84 on a branch, v̄ from eq 81.
    Jaeger(JaegerModel),
}

impl Curve {
    fn velocity(self, draw: &[f64], column: usize, p: &Point, delta: f64) -> Option<f64> {
        let s = &p.scene;
        let contact = |m: Model, law: CollisionLaw| {
            Scene::from_radians(s.xi(), delta, s.rho(), s.f(), law)
                .ok()
                .and_then(|sc| m.evaluate(&sc).ok())
                .map(|st| st.mean_velocity)
        };
        let v = match self {
            Curve::LawC(m) => contact(m, CollisionLaw::C(draw[0]))?,
            Curve::FreeK(m) => contact(m, CollisionLaw::Value(draw[column]))?,
            Curve::Impact(m) => contact(m, CollisionLaw::Impact)?,
            Curve::JanSeries => JanSeries
                .value(&(s.sin_alpha(), delta.sin(), delta.cos()), &draw[..2])
                .ok()?,
            Curve::JanGlobal => JanGlobal
                .value(&(s.sin_alpha(), delta.sin(), delta.cos()), &draw[..4])
                .ok()?,
            Curve::Jaeger(m) => m
                .value(&(delta.tan(), delta.cos(), s.eps()), &draw[..3])
                .ok()?,
        };
        v.is_finite().then_some(v)
    }
}

/// The posterior bands and point medians of every fit of `an` that kept draws (none under
/// least squares; see the module docs), or `None` once `stop` is raised (polled before every
/// draw's v̄).
pub fn posterior_bands_until(an: &Analysis, stop: &AtomicBool) -> Option<PosteriorBands> {
    let mut out = PosteriorBands::default();
    let all: Vec<usize> = (0..an.data.points.len()).collect();
    for c in &an.contact {
        let laws = [
            (&c.law_c, Curve::LawC(c.model)),
            (&c.free, Curve::FreeK(c.model)),
        ];
        for (fit, curve) in laws {
            if let Some(f) = fit {
                let name = format!("{}-{}", c.name, f.summary.stats.fit);
                add(
                    &mut out, &name, &f.summary, curve, &c.data, &c.used, None, stop,
                )?;
            }
        }
    }
    for (s, f) in an.jan.series.iter().enumerate() {
        if let Some(f) = f {
            add(
                &mut out,
                "jan-series",
                f,
                Curve::JanSeries,
                &an.data,
                &all,
                Some(s),
                stop,
            )?;
        }
    }
    if let Some(f) = &an.jan.global {
        add(
            &mut out,
            "jan-global",
            f,
            Curve::JanGlobal,
            &an.data,
            &all,
            None,
            stop,
        )?;
    }
    for (s, f) in an.jaeger.series.iter().enumerate() {
        if let Some(f) = f {
            let curve = Curve::Jaeger(JaegerModel(f.branch));
            add(
                &mut out,
                "jaeger",
                &f.summary,
                curve,
                &an.data,
                &all,
                Some(s),
                stop,
            )?;
        }
    }
    Some(out)
}

/// Adds the bands and point medians of one fit: `data` is the data set it was fitted on,
/// `index` maps its points to the analysis' data set, `only` restricts it to one series (a
/// per-series fit). `None` once `stop` is raised.
#[allow(clippy::too_many_arguments)]
fn add(
    out: &mut PosteriorBands,
    name: &str,
    fit: &FitResult,
    curve: Curve,
    data: &Dataset,
    index: &[usize],
    only: Option<usize>,
    stop: &AtomicBool,
) -> Option<()> {
    let Some(d) = &fit.draws else {
        return Some(());
    };
    let draws = subset(&d.chains);
    if draws.is_empty() {
        return Some(());
    }
    for (s, label) in data.labels.iter().enumerate() {
        if only.is_some_and(|o| o != s) {
            continue;
        }
        let pts: Vec<(usize, &Point)> = data
            .points
            .iter()
            .enumerate()
            .filter(|(_, p)| p.series == s)
            .collect();
        let Some(&(_, first)) = pts.first() else {
            continue;
        };
        // The free law's K of this series: the row of parameter K for its label.
        let column = match curve {
            Curve::FreeK(_) => match fit.params.iter().position(|r| r.series == *label) {
                Some(j) => j,
                None => continue,
            },
            _ => 0,
        };
        let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
            (a.0.min(p.1.scene.delta), a.1.max(p.1.scene.delta))
        });
        let grid: Vec<f64> = if hi > lo {
            (0..BAND_GRID)
                .map(|i| lo + (hi - lo) * i as f64 / (BAND_GRID - 1) as f64)
                .collect()
        } else {
            vec![lo]
        };
        // The grid slopes at the series' first point, then every point at its own slope.
        let at: Vec<(&Point, f64)> = grid
            .iter()
            .map(|&g| (first, g))
            .chain(pts.iter().map(|&(_, p)| (p, p.scene.delta)))
            .collect();
        let q: Vec<[f64; 3]> = at
            .par_iter()
            .map(|&(p, delta)| {
                let mut v = Vec::with_capacity(draws.len());
                for x in &draws {
                    if stop.load(Ordering::Relaxed) {
                        return None;
                    }
                    v.extend(curve.velocity(x, column, p, delta));
                }
                v.sort_by(f64::total_cmp);
                Some([0.05, 0.5, 0.95].map(|pr| quantile_sorted(&v, pr)))
            })
            .collect::<Option<_>>()?;
        let (qg, qp) = q.split_at(grid.len());
        out.bands.push(Band {
            fit: name.to_string(),
            series: label.clone(),
            xi: first.scene.xi(),
            delta_deg: grid.iter().map(|g| g.to_degrees()).collect(),
            q05: qg.iter().map(|r| r[0]).collect(),
            q50: qg.iter().map(|r| r[1]).collect(),
            q95: qg.iter().map(|r| r[2]).collect(),
            draws: draws.len(),
        });
        for (&(i, p), r) in pts.iter().zip(qp) {
            out.points.push(PointMedian {
                fit: name.to_string(),
                series: label.clone(),
                point: index[i],
                delta_deg: p.scene.delta_deg(),
                v_median: r[1],
            });
        }
    }
    Some(())
}

/// At most [`BAND_DRAWS`] draws, evenly spaced through the kept draws taken step by step
/// (every walker's first kept step, then every walker's second, …).
fn subset(chains: &[Vec<Vec<f64>>]) -> Vec<&[f64]> {
    let steps = chains.iter().map(Vec::len).min().unwrap_or(0);
    let pooled: Vec<&[f64]> = (0..steps)
        .flat_map(|k| chains.iter().map(move |c| c[k].as_slice()))
        .collect();
    let stride = pooled.len().div_ceil(BAND_DRAWS).max(1);
    pooled.into_iter().step_by(stride).collect()
}

/// The least-squares curve of one fit over one series with its confidence band.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LsqBand {
    /// The slopes of the grid, degrees.
    pub delta_deg: Vec<f64>,
    /// v̄ at the optimum (NaN where the model has no steady state).
    pub v: Vec<f64>,
    /// The band's ends (NaN where it cannot be computed; all NaN without a covariance).
    pub lo: Vec<f64>,
    /// See `lo`.
    pub hi: Vec<f64>,
}

/// The fitted v̄(δ) of `fit` (least squares: `value` of its rows) over series `s` of `data`,
/// on `grid` (radians), with the band v̄ ± z σ_v̄ at the fit's level: σ_v̄² = gᵀ C g, the delta
/// method, with C the covariance at the optimum (standard errors and correlation) and g the
/// gradient of v̄ in the parameters by central differences of a thousandth of each standard
/// error. `None` when the fit does not cover the series.
pub(crate) fn lsq_band(
    fit: &FitResult,
    curve: Curve,
    data: &Dataset,
    s: usize,
    grid: &[f64],
) -> Option<LsqBand> {
    let label = &data.labels[s];
    let first = data.series(s).next()?;
    let covers = fit.stats.series == *label || fit.stats.series == "all";
    if !covers {
        return None;
    }
    let theta: Vec<f64> = fit.params.iter().map(|r| r.value).collect();
    let column = match curve {
        Curve::FreeK(_) => fit.params.iter().position(|r| r.series == *label)?,
        _ => 0,
    };
    let used: Vec<usize> = match curve {
        Curve::LawC(_) => vec![0],
        Curve::FreeK(_) => vec![column],
        Curve::Impact(_) => vec![],
        Curve::JanSeries => vec![0, 1],
        Curve::JanGlobal => vec![0, 1, 2, 3],
        Curve::Jaeger(_) => vec![0, 1, 2],
    };
    if used.iter().any(|&j| j >= theta.len()) {
        return None;
    }
    // A parameter held fixed has no uncertainty to carry.
    let used: Vec<usize> = used.into_iter().filter(|&j| !fit.params[j].fixed).collect();
    let level = fit.params.first().map_or(0.95, |r| r.level);
    let z = Normal::standard().inverse_cdf(0.5 + level / 2.0);
    // The covariance of the parameters the curve uses.
    let cov: Option<Vec<Vec<f64>>> = fit.correlation.as_ref().and_then(|corr| {
        let se: Option<Vec<f64>> = used.iter().map(|&j| fit.params[j].stderr).collect();
        let se = se?;
        Some(
            used.iter()
                .enumerate()
                .map(|(a, &i)| {
                    used.iter()
                        .enumerate()
                        .map(|(b, &j)| corr[i][j] * se[a] * se[b])
                        .collect()
                })
                .collect(),
        )
    });
    let at = |th: &[f64], d: f64| curve.velocity(th, column, first, d).unwrap_or(f64::NAN);
    let rows: Vec<(f64, f64, f64)> = grid
        .par_iter()
        .map(|&d| {
            let v = at(&theta, d);
            let Some(c) = &cov else {
                return (v, f64::NAN, f64::NAN);
            };
            let g: Vec<f64> = used
                .iter()
                .enumerate()
                .map(|(a, &j)| {
                    let h = 1e-3 * c[a][a].sqrt().max(1e-12 * theta[j].abs().max(1.0));
                    let (mut up, mut down) = (theta.clone(), theta.clone());
                    up[j] += h;
                    down[j] -= h;
                    (at(&up, d) - at(&down, d)) / (2.0 * h)
                })
                .collect();
            let var: f64 = (0..g.len())
                .flat_map(|a| (0..g.len()).map(move |b| (a, b)))
                .map(|(a, b)| g[a] * c[a][b] * g[b])
                .sum();
            // A covariance with undefined entries (a rank-deficient Jacobian) gives no band.
            let sd = if var.is_finite() {
                var.max(0.0).sqrt()
            } else {
                f64::NAN
            };
            (v, v - z * sd, v + z * sd)
        })
        .collect();
    Some(LsqBand {
        delta_deg: grid.iter().map(|d| d.to_degrees()).collect(),
        v: rows.iter().map(|r| r.0).collect(),
        lo: rows.iter().map(|r| r.1).collect(),
        hi: rows.iter().map(|r| r.2).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::{BAND_DRAWS, BAND_GRID};
    use crate::fit::data::Dataset;
    use crate::inverse::posterior::{McmcSettings, Method};
    use crate::progress::{Progress, ProgressEvent};
    use crate::report::analysis::analyse;
    use std::sync::atomic::AtomicBool;
    use std::sync::{Arc, Mutex};

    #[test]
    fn posterior_bands_of_every_fit() {
        let data = Dataset::default_data();
        // The fits run concurrently; the progress sink must still see one task at a time.
        let events: Arc<Mutex<Vec<String>>> = Arc::default();
        let log = Arc::clone(&events);
        let mut settings = McmcSettings::seeded(1);
        settings.progress = Some(Progress::new(move |e| {
            let tag = match e {
                ProgressEvent::Start { label, .. } => format!("start {label}"),
                ProgressEvent::Position(_) => "position".into(),
                ProgressEvent::Finish => "finish".into(),
            };
            log.lock().unwrap().push(tag);
        }));
        let an = analyse(&data, 0.95, &Method::Mcmc(Box::new(settings)));
        let events = events.lock().unwrap().clone();
        let mut open = false;
        let mut tasks = 0;
        for e in &events {
            match e.as_str() {
                "finish" => {
                    assert!(open, "a finish without a start");
                    open = false;
                }
                "position" => assert!(open, "a position outside a task"),
                start => {
                    assert!(!open, "{start} while another task holds the sink");
                    open = true;
                    tasks += 1;
                }
            }
        }
        assert!(!open && tasks >= 1, "{tasks} tasks reported");
        let b = super::posterior_bands_until(&an, &AtomicBool::new(false)).unwrap();
        // Per series: 2 contact models × 2 laws, Jan per series and global, Jaeger.
        assert_eq!(b.bands.len(), 4 * 7);
        assert_eq!(b.points.len(), 36 * 7);
        for band in &b.bands {
            let what = format!("{} [{}]", band.fit, band.series);
            let s = data.labels.iter().position(|l| *l == band.series).unwrap();
            let slopes: Vec<f64> = data.series(s).map(|p| p.scene.delta_deg()).collect();
            let lo = slopes.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = slopes.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(band.delta_deg.len(), BAND_GRID, "{what}");
            assert!((band.delta_deg[0] - lo).abs() < 1e-9, "{what}");
            assert!((band.delta_deg[BAND_GRID - 1] - hi).abs() < 1e-9, "{what}");
            assert!(
                band.draws <= BAND_DRAWS && band.draws > BAND_DRAWS / 2,
                "{what}"
            );
            for i in 0..BAND_GRID {
                let (a, m, z) = (band.q05[i], band.q50[i], band.q95[i]);
                assert!(
                    a.is_finite() && a < m && m < z,
                    "{what} at {}: {a} {m} {z}",
                    band.delta_deg[i]
                );
            }
            // The band's ends are at the series' smallest and largest measured slopes, where the
            // point medians were computed on their own.
            for (end, slope) in [(0, lo), (BAND_GRID - 1, hi)] {
                let p = b
                    .points
                    .iter()
                    .find(|p| p.fit == band.fit && p.series == band.series && p.delta_deg == slope)
                    .unwrap();
                let d = (p.v_median - band.q50[end]).abs();
                assert!(
                    d <= 1e-12 * p.v_median,
                    "{what}: {} vs {}",
                    p.v_median,
                    band.q50[end]
                );
            }
        }
        // Under the K(α) laws v̄ at a point rises with the one parameter that sets its K (c, or
        // the series' K), so the median of v̄ over the draws is v̄ at the median parameter: the
        // fit's own v̄ at its posterior median (computed by the K-law problem's forward model,
        // on all the draws) must match within the Monte Carlo error of a median of the band's
        // draws, 1.2533 sd/√n (n draws, sd from the 90 % band: (q95 − q05)/3.29), doubled for the
        // fit's own median and taken four times.
        let mut worst: f64 = 0.0;
        for c in &an.contact {
            for f in [&c.law_c, &c.free].into_iter().flatten() {
                let name = format!("{}-{}", c.name, f.summary.stats.fit);
                for (k, pf) in f.summary.points.iter().enumerate() {
                    let i = c.used[k];
                    let p = b
                        .points
                        .iter()
                        .find(|p| p.fit == name && p.point == i)
                        .unwrap();
                    let band = b
                        .bands
                        .iter()
                        .find(|x| x.fit == name && x.series == pf.series)
                        .unwrap();
                    let sd = band
                        .q95
                        .iter()
                        .zip(&band.q05)
                        .map(|(z, a)| (z - a) / 3.29)
                        .fold(0.0, f64::max);
                    let tol = 4.0 * 2f64.sqrt() * 1.2533 * sd / (band.draws as f64).sqrt();
                    let z = (p.v_median - pf.v_fit).abs() / tol;
                    worst = worst.max(z);
                    assert!(
                        z <= 1.0,
                        "{name} point {i}: median {} vs v̄ at the median parameter {} (tolerance {tol:e})",
                        p.v_median,
                        pf.v_fit
                    );
                }
            }
        }
        println!("K-law point medians: largest |difference|/tolerance {worst:.3}");
    }
}
