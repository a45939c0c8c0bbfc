//! Jan's energy balance fitted on the measured velocities (eq 74), not on the linearised plot
//! v̄²/cos δ against tan δ (Fig. 8): per series λ and μ, and across series the laws
//! λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α} (the form of eqs 75–76).
//!
//! v̄ = sqrt((2 sin α/λ)(sin δ − μ cos δ)) has the analytic gradient
//! ∂v̄/∂λ = −v̄/(2λ), ∂v̄/∂μ = −sin α cos δ/(λ v̄). A point with tan δ ≤ μ has no motion in this
//! model (regime A), so μ is boxed to [0, min tan δ) and a trial μ beyond a point's slope is
//! [`Infeasible`].
//!
//! The per-series start is the weighted straight line of the linearised plot
//! (v̄²/cos δ = (2 sin α/λ)(tan δ − μ)); the global start is the straight lines of ln λ and
//! ln μ against sin α through the per-series fits (the paper's values where those fail).

use super::controls::{ControlError, Controls, Parameters, Plan};
use super::data::Dataset;
use super::posterior::{per_series, summarise_with, Method};
use super::slopes::{self, SlopeCurve};
use super::summary::{distinct_points, observed_norm, FitResult, ParamSpec, Solved};
use crate::inverse::{fit, CurveModel, Infeasible, LsqOptions, WeightedData};

/// The paper's global values (λ0, λ1, μ0, μ1), eqs 75–76.
pub(crate) const PAPER_GLOBAL: [f64; 4] = [0.063, 4.96, 0.0025, 7.46];

/// What Jan's formula needs of a point: (sin α, sin δ, cos δ).
pub(crate) type JanX = (f64, f64, f64);

/// v̄ and (∂v̄/∂λ, ∂v̄/∂μ) at (λ, μ), or infeasible where sin δ − μ cos δ ≤ 0 or λ ≤ 0.
pub(crate) fn velocity(x: &JanX, lambda: f64, mu: f64) -> Result<(f64, f64, f64), Infeasible> {
    let (sa, sd, cd) = *x;
    let drive = sd - mu * cd;
    if !(drive > 0.0 && lambda > 0.0) {
        return Err(Infeasible);
    }
    let v = (2.0 * sa / lambda * drive).sqrt();
    Ok((v, -v / (2.0 * lambda), -sa * cd / (lambda * v)))
}

/// Jan's abscissa of a point at slope δ (radians).
fn at_slope(x: &JanX, delta: f64) -> JanX {
    let (sd, cd) = delta.sin_cos();
    (x.0, sd, cd)
}

/// Per-series model: p = (λ, μ).
#[derive(Debug, Clone, Copy)]
pub(crate) struct JanSeries;

impl CurveModel<JanX> for JanSeries {
    fn n_params(&self) -> usize {
        2
    }
    fn value(&self, x: &JanX, p: &[f64]) -> Result<f64, Infeasible> {
        velocity(x, p[0], p[1]).map(|r| r.0)
    }
    fn gradient(&self, x: &JanX, p: &[f64], g: &mut [f64]) -> Option<Result<(), Infeasible>> {
        Some(velocity(x, p[0], p[1]).map(|(_, dl, dm)| {
            g[0] = dl;
            g[1] = dm;
        }))
    }
}

/// Global model: p = (λ0, λ1, μ0, μ1).
#[derive(Debug, Clone, Copy)]
pub(crate) struct JanGlobal;

impl CurveModel<JanX> for JanGlobal {
    fn n_params(&self) -> usize {
        4
    }
    fn value(&self, x: &JanX, p: &[f64]) -> Result<f64, Infeasible> {
        let (l, m) = (p[0] * (p[1] * x.0).exp(), p[2] * (p[3] * x.0).exp());
        velocity(x, l, m).map(|r| r.0)
    }
    fn gradient(&self, x: &JanX, p: &[f64], g: &mut [f64]) -> Option<Result<(), Infeasible>> {
        let (el, em) = ((p[1] * x.0).exp(), (p[3] * x.0).exp());
        let (l, m) = (p[0] * el, p[2] * em);
        Some(velocity(x, l, m).map(|(_, dl, dm)| {
            g[0] = dl * el;
            g[1] = dl * l * x.0;
            g[2] = dm * em;
            g[3] = dm * m * x.0;
        }))
    }
}

/// The fits of `fitbead jan`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JanFits {
    /// Per series (λ, μ), in the dataset's series order; `None` where the series has fewer
    /// than 3 points (no degree of freedom left for the scatter).
    pub series: Vec<Option<FitResult>>,
    /// The global laws; `None` with fewer than two distinct α.
    pub global: Option<FitResult>,
    /// Why a fit was not made.
    pub notes: Vec<String>,
    /// A control of the method (`fix`, `init`, `bounds`) that cannot be used on these data.
    pub fault: Option<ControlError>,
}

fn xs(data: &Dataset, s: Option<usize>) -> (Vec<JanX>, Vec<f64>, Vec<f64>) {
    let mut x = Vec::new();
    let mut y = Vec::new();
    let mut sg = Vec::new();
    for p in data
        .points
        .iter()
        .filter(|p| s.is_none_or(|s| p.series == s))
    {
        let sc = &p.scene;
        let (sd, cd) = sc.delta.sin_cos();
        x.push((sc.sin_alpha, sd, cd));
        y.push(p.v);
        sg.push(p.sigma);
    }
    (x, y, sg)
}

/// Weighted straight line y = a + b x (weights 1/σ²); `None` if degenerate.
fn line(x: &[f64], y: &[f64], sigma: &[f64]) -> Option<(f64, f64)> {
    let (mut sw, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for ((&xi, &yi), &si) in x.iter().zip(y).zip(sigma) {
        let w = 1.0 / (si * si);
        sw += w;
        sx += w * xi;
        sy += w * yi;
        sxx += w * xi * xi;
        sxy += w * xi * yi;
    }
    let d = sw * sxx - sx * sx;
    if !(d.abs() > 0.0) {
        return None;
    }
    let b = (sw * sxy - sx * sy) / d;
    let a = (sy - b * sx) / sw;
    (a.is_finite() && b.is_finite()).then_some((a, b))
}

/// Fits Jan's model per series and globally, with intervals at `level`, the parameters
/// estimated by `method` (least squares, or a posterior run per fit started from its
/// least-squares optimum; see [`super::posterior`]). The global
/// fit starts from the per-series least-squares optima either way.
pub(crate) fn fit_jan_with(data: &Dataset, level: f64, method: &Method) -> JanFits {
    let fits = per_series(data, method, |s, label, method| {
        let mut notes = Vec::new();
        let mut pts: (LogPoints, LogPoints) = (Vec::new(), Vec::new());
        let fit = fit_jan_series(data, s, label, level, method, &mut notes, &mut pts);
        (fit, notes, pts)
    });
    let mut notes = Vec::new();
    let mut per = Vec::new();
    let mut fault = None;
    // (sin α, ln λ, weight σ of ln λ) and the same of μ, one per converged series fit.
    let mut pts: (LogPoints, LogPoints) = (Vec::new(), Vec::new());
    for (fit, n, p) in fits {
        match fit {
            Ok(f) => per.push(f),
            Err(e) => {
                per.push(None);
                fault = fault.or(Some(e));
            }
        }
        notes.extend(n);
        pts.0.extend(p.0);
        pts.1.extend(p.1);
    }
    if fault.is_some() {
        return JanFits {
            series: per,
            global: None,
            notes,
            fault,
        };
    }
    let mut alphas: Vec<f64> = data.points.iter().map(|p| p.scene.sin_alpha).collect();
    alphas.sort_by(|a, b| a.total_cmp(b));
    alphas.dedup();
    let global = if alphas.len() < 2 {
        notes.push("global laws need series at two or more contact angles".into());
        Ok(None)
    } else {
        fit_jan_global(data, level, method, &pts.0, &pts.1, &mut notes)
    };
    let (global, fault) = match global {
        Ok(g) => (g, None),
        Err(e) => (None, Some(e)),
    };
    JanFits {
        series: per,
        global,
        notes,
        fault,
    }
}

/// (sin α, ln x, σ of ln x) of a parameter x of each converged series fit.
type LogPoints = Vec<(f64, f64, f64)>;

/// The linearised start (λ, μ) of a series' points `x`, `y`, `sg` whose least tan δ is
/// `tmin`: the weighted line v̄²/cos δ = A (tan δ − μ), σ of v̄²/cos δ = 2 v̄ σ / cos δ.
fn series_start(x: &[JanX], y: &[f64], sg: &[f64], tmin: f64) -> (f64, f64) {
    let sa = x[0].0;
    let lx: Vec<f64> = x.iter().map(|p| p.1 / p.2).collect();
    let ly: Vec<f64> = x.iter().zip(y).map(|(p, v)| v * v / p.2).collect();
    let ls: Vec<f64> = x
        .iter()
        .zip(y)
        .zip(sg)
        .map(|((p, v), s)| 2.0 * v * s / p.2)
        .collect();
    match line(&lx, &ly, &ls) {
        Some((a, b)) if b > 0.0 => (2.0 * sa / b, (-a / b).clamp(0.0, 0.999 * tmin)),
        _ => (crate::models::jan::Jan::paper_fit(sa.asin()).lambda, 0.0),
    }
}

/// Jan's λ and μ of series `s` (eq 74), or `None` with a note saying why not; a converged fit
/// adds its (sin α, ln λ, σ of ln λ) and (sin α, ln μ, σ of ln μ) to `pts`.
fn fit_jan_series(
    data: &Dataset,
    s: usize,
    label: &str,
    level: f64,
    method: &Method,
    notes: &mut Vec<String>,
    pts: &mut (LogPoints, LogPoints),
) -> Result<Option<FitResult>, ControlError> {
    let (x, y, sg) = xs(data, Some(s));
    if x.len() < 3 {
        notes.push(format!(
            "series '{label}': {} points, need at least 3 for λ and μ",
            x.len()
        ));
        return Ok(None);
    }
    let sa = x[0].0;
    let tmin = x.iter().map(|p| p.1 / p.2).fold(f64::INFINITY, f64::min);
    let (lam0, mu0) = series_start(&x, &y, &sg, tmin);
    let distinct = distinct_points(x.iter().map(|p| [p.1, p.2]));
    let norm = observed_norm(y.iter().zip(&sg));
    let base = x.clone();
    let problem = match WeightedData::new(JanSeries, x, y, Some(sg)) {
        Ok(p) => p,
        Err(e) => {
            notes.push(format!("series '{label}': {e}"));
            return Ok(None);
        }
    };
    let (lower, upper) = ([0.0, 0.0], [f64::INFINITY, tmin]);
    let plan = Plan::new(
        &Controls::of(method),
        Parameters {
            names: &["lambda", "mu"],
            series: &[label, label],
            lower: &lower,
            upper: &upper,
            start: &[lam0, mu0],
        },
    )?;
    let opts = plan.options(LsqOptions {
        lower: Some(lower.to_vec()),
        upper: Some(upper.to_vec()),
        sigma: data.sigma,
        stop: method.stop().cloned(),
        progress: method.progress().cloned(),
        ..Default::default()
    });
    let pinned = plan.wrap(&problem);
    let paper = crate::models::jan::Jan::paper_fit(sa.asin());
    let specs = [
        ParamSpec {
            name: "lambda",
            unit: "1",
            paper_value: Some(paper.lambda),
            paper_source: "paper eq 75 at this alpha",
            default_prior: None,
        },
        ParamSpec {
            name: "mu",
            unit: "1",
            paper_value: Some(paper.mu),
            paper_source: "paper eq 76 at this alpha",
            default_prior: None,
        },
    ];
    let index = data.series_index(s);
    if plan.all_held() {
        if matches!(method, Method::Mcmc(_)) {
            return Err(plan.nothing_to_sample());
        }
        let mut sum = plan.score(&problem, ("jan-series", label), &specs, level, data.sigma);
        sum.attach_points(data, &index);
        return Ok(Some(sum));
    }
    plan.check_start(&pinned)?;
    let f = match fit(&pinned, &plan.start(), &opts) {
        Ok(f) => f,
        Err(e) => {
            notes.push(format!("series '{label}': {e}"));
            return Ok(None);
        }
    };
    let free_specs = plan.free_of(&specs);
    let solved = Solved {
        name: "jan-series",
        series: label,
        specs: &free_specs,
        problem: &pinned,
        fit: &f,
        level,
        options: &opts,
        distinct: Some(distinct),
        observed_norm: Some(norm),
    };
    let curve = plan.wrap(SlopeCurve {
        model: &JanSeries,
        base: &base,
        at: at_slope,
    });
    let mut sum =
        slopes::summarise(method, &solved, curve, data, &index, true).unwrap_or_else(|| {
            let mut sum = summarise_with(method, solved);
            sum.attach_points(data, &index);
            sum
        });
    plan.restore(&mut sum, &specs, level);
    if f.converged() {
        log_points(&plan, &f, sa, pts);
    }
    Ok(Some(sum))
}

/// Adds the (sin α, ln x, σ of ln x) of λ and μ of a converged series fit `f` (made by
/// `plan`) to `pts`; a held parameter has no standard error, and its point weighs as a unit
/// one.
fn log_points(plan: &Plan, f: &crate::inverse::Fit, sa: f64, pts: &mut (LogPoints, LogPoints)) {
    let p = plan.expand(&f.params);
    let se: Vec<f64> = match f.std_errors() {
        Some(se) => plan
            .expand(se)
            .iter()
            .zip(plan.pins())
            .map(|(e, pin)| if pin.is_some() { f64::NAN } else { *e })
            .collect(),
        None => vec![1.0; 2],
    };
    if p[0] > 0.0 {
        pts.0.push((sa, p[0].ln(), se[0] / p[0]));
    }
    if p[1] > 0.0 {
        pts.1.push((sa, p[1].ln(), se[1] / p[1]));
    }
}

/// The parameters of the global laws (eqs 75–76) with the paper's values.
fn global_specs() -> [ParamSpec; 4] {
    let spec = |name, k: usize, paper_source| ParamSpec {
        name,
        unit: "1",
        paper_value: Some(PAPER_GLOBAL[k]),
        paper_source,
        default_prior: None,
    };
    [
        spec("lambda0", 0, "paper eq 75"),
        spec("lambda1", 1, "paper eq 75"),
        spec("mu0", 2, "paper eq 76"),
        spec("mu1", 3, "paper eq 76"),
    ]
}

/// The straight line y = ln a + b x through the points (x, y, σ) `pts` as (a, b), or
/// `paper` with fewer than two points or a degenerate line.
fn log_line(pts: &[(f64, f64, f64)], paper: (f64, f64)) -> (f64, f64) {
    let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let s: Vec<f64> = pts
        .iter()
        .map(|p| {
            if p.2 > 0.0 && p.2.is_finite() {
                p.2
            } else {
                1.0
            }
        })
        .collect();
    match (pts.len() >= 2).then(|| line(&x, &y, &s)).flatten() {
        Some((a, b)) => (a.exp(), b),
        None => paper,
    }
}

/// The global laws of eqs 75–76 fitted to every point, started from the lines through the
/// series' ln λ and ln μ (`lam_pts`, `mu_pts`), or `None` with a note saying why not; an
/// error for a control of `method` that cannot be used on them.
fn fit_jan_global(
    data: &Dataset,
    level: f64,
    method: &Method,
    lam_pts: &[(f64, f64, f64)],
    mu_pts: &[(f64, f64, f64)],
    notes: &mut Vec<String>,
) -> Result<Option<FitResult>, ControlError> {
    let (l0, l1) = log_line(lam_pts, (PAPER_GLOBAL[0], PAPER_GLOBAL[1]));
    let (m0, m1) = log_line(mu_pts, (PAPER_GLOBAL[2], PAPER_GLOBAL[3]));
    let (x, y, sg) = xs(data, None);
    let norm = observed_norm(y.iter().zip(&sg));
    let Ok(problem) = WeightedData::new(JanGlobal, x.clone(), y, Some(sg)) else {
        notes.push("global laws: the data cannot form a weighted problem".into());
        return Ok(None);
    };
    let lower = [0.0, f64::NEG_INFINITY, 0.0, f64::NEG_INFINITY];
    let mut plan = Plan::new(
        &Controls::of(method),
        Parameters {
            names: &["lambda0", "lambda1", "mu0", "mu1"],
            series: &["all"; 4],
            lower: &lower,
            upper: &[f64::INFINITY; 4],
            start: &[l0, l1, m0, m1],
        },
    )?;
    let opts = plan.options(LsqOptions {
        lower: Some(lower.to_vec()),
        sigma: data.sigma,
        stop: method.stop().cloned(),
        progress: method.progress().cloned(),
        ..Default::default()
    });
    let feasible = |p: &[f64]| x.iter().all(|q| JanGlobal.value(q, p).is_ok());
    // The start must keep μ(α) below every slope; shrink μ0 until it does (unless μ0 is
    // held or its start given).
    let mut tries = 0;
    while !feasible(&plan.expand(&plan.start())) && tries < 60 && !plan.start_given(2) {
        plan.scale_start(2, 0.5);
        tries += 1;
    }
    let specs = global_specs();
    let index: Vec<usize> = (0..data.points.len()).collect();
    if plan.all_held() {
        if matches!(method, Method::Mcmc(_)) {
            return Err(plan.nothing_to_sample());
        }
        let mut sum = plan.score(&problem, ("jan-global", "all"), &specs, level, data.sigma);
        sum.attach_points(data, &index);
        return Ok(Some(sum));
    }
    let pinned = plan.wrap(&problem);
    plan.check_start(&pinned)?;
    let f = match fit(&pinned, &plan.start(), &opts) {
        Ok(f) => f,
        Err(e) => {
            notes.push(format!("global laws: {e}"));
            return Ok(None);
        }
    };
    let free_specs = plan.free_of(&specs);
    let solved = Solved {
        name: "jan-global",
        series: "all",
        specs: &free_specs,
        problem: &pinned,
        fit: &f,
        level,
        options: &opts,
        distinct: Some(distinct_points(x.iter().map(|p| [p.0, p.1, p.2]))),
        observed_norm: Some(norm),
    };
    let curve = plan.wrap(SlopeCurve {
        model: &JanGlobal,
        base: &x,
        at: at_slope,
    });
    let mut sum =
        slopes::summarise(method, &solved, curve, data, &index, true).unwrap_or_else(|| {
            let mut sum = summarise_with(method, solved);
            sum.attach_points(data, &index);
            sum
        });
    plan.restore(&mut sum, &specs, level);
    Ok(Some(sum))
}
