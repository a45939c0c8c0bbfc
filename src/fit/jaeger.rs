//! Jaeger's law fitted per series on the measured velocities: a1, a2, a3 in Jaeger's velocity
//! units (eq 81), the branch of eq 84 used, and the points of the series that fall in the
//! bistable band of eq 90 at the fitted values.
//!
//! v̄ = sqrt(2 cos δ X/ε) with X the chosen positive root of
//! F(X) = a2 a3 X² + (a3 − a2 tan δ) X + a1 − tan δ = 0 (eq 84). The gradient is analytic by
//! implicit differentiation: ∂X/∂a_k = −(∂F/∂a_k)/(∂F/∂X) with ∂F/∂a1 = 1,
//! ∂F/∂a2 = a3 X² − X tan δ, ∂F/∂a3 = a2 X² + X, ∂F/∂X = 2 a2 a3 X + a3 − a2 tan δ, and
//! ∂v̄/∂X = v̄/(2X). Where eq 84 has no positive root (the slope is below the band) the point
//! is [`Infeasible`]; where it has one, both branches return it.
//!
//! The start is derived: with u² = X_i computed from each measured v̄_i, eq 83 reads
//! tan δ_i = a3 X_i + a1/(1 + a2 X_i), linear in (a1, a3) for fixed a2. A log grid of a2 over
//! 10⁻²…10⁴ (and a2 = 0) gives one linear fit each; the candidate of least χ² in v̄ starts
//! Levenberg–Marquardt. Against argmin's particle swarm over the same span (40 particles, 200
//! iterations, then the same Levenberg–Marquardt), on 200 noisy replicates of the four Fig. 9
//! series the grid reaches the best optimum either finds in 96.2 % of the 800 fits, the swarm
//! in 94.9 %, at 100 times the cost (`tests/it/cross_solvers.rs`).
//!
//! A posterior run samples a1, a2, a3 in the coordinates of `super::jaeger_coordinates`
//! (the velocity at the series' mean slope, the slope of the law there and a shape), where the
//! ridge of a1 and a2 is straight; priors, draws and reported values are those of a1, a2, a3.

use super::controls::{ControlError, Controls, Parameters, Plan};
use super::data::Dataset;
use super::jaeger_coordinates::JaegerCoordinates;
pub(crate) use super::jaeger_coordinates::JaegerX;
use super::posterior::{per_series, summarise_reparameterised, summarise_with, Method, Prior};
use super::slopes::{self, SlopeCurve};
use super::summary::{distinct_points, observed_norm, FitResult, ParamSpec, Solved};
use crate::inverse::{fit, CurveModel, Infeasible, LsqOptions, WeightedData};
use crate::models::jaeger::Jaeger;
use crate::models::JaegerBranch;

/// The paper's Fig. 9 values (ξ, a1, a2, a3), Jaeger units.
pub(crate) const PAPER_FIG9: [(f64, f64, f64, f64); 4] = [
    (0.8, 0.19, 3.83, 1.28),
    (1.0, 0.131, 18.57, 1.41),
    (1.6, 0.06, 20.71, 0.8987),
    (2.0, 0.042, 27.67, 0.78),
];

/// The paper's Fig. 9 values (a1, a2, a3) at ξ, if ξ is one of its four series.
pub(crate) fn paper_values(xi: f64) -> Option<[f64; 3]> {
    PAPER_FIG9
        .iter()
        .find(|r| (r.0 - xi).abs() < 1e-9)
        .map(|r| [r.1, r.2, r.3])
}

/// Jaeger's model on one branch, p = (a1, a2, a3).
#[derive(Debug, Clone, Copy)]
pub(crate) struct JaegerModel(pub JaegerBranch);

impl JaegerModel {
    fn root(&self, x: &JaegerX, p: &[f64]) -> Result<f64, Infeasible> {
        if !(p[0] >= 0.0 && p[1] >= 0.0 && p[2] > 0.0) {
            return Err(Infeasible);
        }
        let m = Jaeger {
            a1: p[0],
            a2: p[1],
            a3: p[2],
            branch: self.0,
        };
        let r = m.roots(x.0);
        match self.0 {
            JaegerBranch::Upper => r.upper,
            JaegerBranch::Lower => r.lower,
        }
        .filter(|x| x.is_finite() && *x > 0.0)
        .ok_or(Infeasible)
    }
}

impl CurveModel<JaegerX> for JaegerModel {
    fn n_params(&self) -> usize {
        3
    }
    fn value(&self, x: &JaegerX, p: &[f64]) -> Result<f64, Infeasible> {
        let r = self.root(x, p)?;
        Ok((2.0 * x.1 * r / x.2).sqrt())
    }
    fn gradient(&self, x: &JaegerX, p: &[f64], g: &mut [f64]) -> Option<Result<(), Infeasible>> {
        let r = match self.root(x, p) {
            Ok(r) => r,
            Err(e) => return Some(Err(e)),
        };
        let (a2, a3, t) = (p[1], p[2], x.0);
        let fx = 2.0 * a2 * a3 * r + a3 - a2 * t;
        let v = (2.0 * x.1 * r / x.2).sqrt();
        let dv_dx = v / (2.0 * r);
        let parts = [1.0, a3 * r * r - r * t, a2 * r * r + r];
        for k in 0..3 {
            g[k] = -parts[k] / fx * dv_dx;
        }
        Some(if g.iter().all(|d| d.is_finite()) {
            Ok(())
        } else {
            Err(Infeasible)
        })
    }
}

/// One series' fit.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JaegerFit {
    /// Reports (parameter rows carry the paper's Fig. 9 values where ξ matches).
    pub summary: FitResult,
    /// Branch used.
    pub branch: JaegerBranch,
    /// Points of the series inside the bistable band (eq 90) at the fitted values.
    pub bistable_points: usize,
    /// Whether a1 a2 > a3 (eq 82: the resistance has a minimum).
    pub has_minimum: bool,
}

/// Jaeger's fits of every series.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JaegerFits {
    /// Per series, in the dataset's order (`None` with fewer than 4 points).
    pub series: Vec<Option<JaegerFit>>,
    /// Why a fit was not made.
    pub notes: Vec<String>,
    /// A control of the method (`fix`, `init`, `bounds`) that cannot be used on these data.
    pub fault: Option<ControlError>,
}

fn chi2(model: &JaegerModel, x: &[JaegerX], y: &[f64], s: &[f64], p: &[f64]) -> f64 {
    let mut c = 0.0;
    for i in 0..x.len() {
        match model.value(&x[i], p) {
            Ok(v) => c += ((y[i] - v) / s[i]).powi(2),
            Err(_) => return f64::INFINITY,
        }
    }
    c
}

/// The derived start (module docs).
#[cfg(test)]
pub(crate) fn start(model: &JaegerModel, x: &[JaegerX], y: &[f64], s: &[f64]) -> Option<[f64; 3]> {
    start_held(model, x, y, s, [None; 3])
}

/// The derived start with the parameters of `held` at their values: the grid of a2 is the
/// value held, and a held a1 or a3 leaves the other fitted alone.
pub(crate) fn start_held(
    model: &JaegerModel,
    x: &[JaegerX],
    y: &[f64],
    s: &[f64],
    held: [Option<f64>; 3],
) -> Option<[f64; 3]> {
    let xx: Vec<f64> = x
        .iter()
        .zip(y)
        .map(|(q, v)| v * v * q.2 / (2.0 * q.1))
        .collect();
    let mut best: Option<([f64; 3], f64)> = None;
    let grid: Vec<f64> = match held[1] {
        Some(a2) => vec![a2],
        None => std::iter::once(0.0)
            .chain((0..=60).map(|i| 10f64.powf(-2.0 + 6.0 * i as f64 / 60.0)))
            .collect(),
    };
    for a2 in grid {
        // tan δ = a1 · 1/(1 + a2 X) + a3 · X: normal equations of the 2 × 2 problem.
        let (mut s11, mut s12, mut s22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (q, &xi) in x.iter().zip(&xx) {
            let (c1, c2) = (1.0 / (1.0 + a2 * xi), xi);
            s11 += c1 * c1;
            s12 += c1 * c2;
            s22 += c2 * c2;
            b1 += c1 * q.0;
            b2 += c2 * q.0;
        }
        let (a1, a3) = match (held[0], held[2]) {
            (None, None) => {
                let d = s11 * s22 - s12 * s12;
                if !(d.abs() > 0.0) {
                    continue;
                }
                ((s22 * b1 - s12 * b2) / d, (s11 * b2 - s12 * b1) / d)
            }
            // One of the pair held: the other by its own normal equation.
            (Some(a1), None) => (a1, (b2 - s12 * a1) / s22),
            (None, Some(a3)) => ((b1 - s12 * a3) / s11, a3),
            (Some(a1), Some(a3)) => (a1, a3),
        };
        let a1 = if held[0].is_some() { a1 } else { a1.max(0.0) };
        if !(a3 > 0.0) {
            continue;
        }
        let p = [a1, a2, a3];
        let c = chi2(model, x, y, s, &p);
        if c.is_finite() && best.is_none_or(|b| c < b.1) {
            best = Some((p, c));
        }
    }
    best.map(|b| b.0)
}

/// Fits Jaeger's law to every series on `branch`, with intervals at `level`, the parameters
/// estimated by `method` (least squares, or a posterior run per series started from its
/// least-squares optimum; see [`super::posterior`]). The branch notes are those of the least-squares optimum.
pub(crate) fn fit_jaeger_with(
    data: &Dataset,
    branch: JaegerBranch,
    level: f64,
    method: &Method,
) -> JaegerFits {
    let model = JaegerModel(branch);
    let fits = per_series(data, method, |s, label, method| {
        fit_jaeger_series(data, s, label, model, level, method)
    });
    let mut notes = Vec::new();
    let mut fault = None;
    let mut series = Vec::with_capacity(fits.len());
    for r in fits {
        match r {
            Ok(f) => series.push(Some(f)),
            Err(Unfitted::Note(note)) => {
                notes.push(note);
                series.push(None);
            }
            Err(Unfitted::Control(e)) => {
                fault = fault.or(Some(e));
                series.push(None);
            }
        }
    }
    JaegerFits {
        series,
        notes,
        fault,
    }
}

/// Why a series was not fitted: its note (`series 'LABEL': …`), or a control of the method
/// that cannot be used on it.
enum Unfitted {
    Note(String),
    Control(ControlError),
}

impl From<ControlError> for Unfitted {
    fn from(e: ControlError) -> Self {
        Unfitted::Control(e)
    }
}

/// The parameters a1, a2, a3 with the paper's Fig. 9 values where ξ is one of its series.
fn specs(xi: f64) -> [ParamSpec; 3] {
    let paper = paper_values(xi);
    let src = if paper.is_some() { "paper Fig. 9" } else { "" };
    let mut specs = [("a1", 10.0), ("a2", 100.0), ("a3", 10.0)].map(|(name, scale)| ParamSpec {
        name,
        unit: "1 (Jaeger units, eq 81)",
        paper_value: None,
        paper_source: src,
        default_prior: Some(Prior::half_normal(scale)),
    });
    if let Some(pv) = paper {
        for k in 0..3 {
            specs[k].paper_value = Some(pv[k]);
        }
    }
    specs
}

/// Jaeger's abscissae (tan δ, cos δ, ε), the velocities and their σ of the points `pts`.
fn series_data(pts: &[&super::data::Point]) -> (Vec<JaegerX>, Vec<f64>, Vec<f64>) {
    let x = pts
        .iter()
        .map(|p| {
            let (sd, cd) = p.scene.delta.sin_cos();
            (sd / cd, cd, p.scene.eps)
        })
        .collect();
    let y = pts.iter().map(|p| p.v).collect();
    let sg = pts.iter().map(|p| p.sigma).collect();
    (x, y, sg)
}

/// Jaeger's law fitted to series `s` (labelled `label`) of `data` on `model`'s branch, or the
/// note saying why not.
fn fit_jaeger_series(
    data: &Dataset,
    s: usize,
    label: &str,
    model: JaegerModel,
    level: f64,
    method: &Method,
) -> Result<JaegerFit, Unfitted> {
    let branch = model.0;
    let pts: Vec<_> = data.series(s).collect();
    if pts.len() < 4 {
        return Err(Unfitted::Note(format!(
            "series '{label}': {} points, need at least 4 for a1, a2, a3",
            pts.len()
        )));
    }
    let (x, y, sg) = series_data(&pts);
    let norm = observed_norm(y.iter().zip(&sg));
    let controls = Controls::of(method);
    let names = ["a1", "a2", "a3"];
    let lower = [0.0; 3];
    let upper = [f64::INFINITY; 3];
    // The start is derived with the values held in place.
    let plan = Plan::new(
        &controls,
        Parameters {
            names: &names,
            series: &[label; 3],
            lower: &lower,
            upper: &upper,
            start: &[0.0; 3],
        },
    )?;
    let held = [plan.pins()[0], plan.pins()[1], plan.pins()[2]];
    let Some(p0) = start_held(&model, &x, &y, &sg, held) else {
        return Err(Unfitted::Note(format!(
            "series '{label}': no start with every point on the {} branch",
            branch_name(branch)
        )));
    };
    let plan = plan.with_start(&p0);
    let problem = match WeightedData::new(model, x.clone(), y, Some(sg)) {
        Ok(p) => p,
        Err(e) => {
            return Err(Unfitted::Note(format!("series '{label}': {e}")));
        }
    };
    let opts = plan.options(LsqOptions {
        lower: Some(lower.to_vec()),
        sigma: data.sigma,
        stop: method.stop().cloned(),
        progress: method.progress().cloned(),
        ..Default::default()
    });
    let specs = specs(pts[0].scene.xi);
    let index = data.series_index(s);
    if plan.all_held() {
        if matches!(method, Method::Mcmc(_)) {
            return Err(plan.nothing_to_sample().into());
        }
        let mut summary = plan.score(&problem, ("jaeger", label), &specs, level, data.sigma);
        summary.attach_points(data, &index);
        return Ok(JaegerFit::described(summary, &x, &plan.expand(&[]), branch));
    }
    let pinned = plan.wrap(&problem);
    plan.check_start(&pinned)?;
    let f = match fit(&pinned, &plan.start(), &opts) {
        Ok(f) => f,
        Err(e) => {
            return Err(Unfitted::Note(format!("series '{label}': {e}")));
        }
    };
    let free_specs = plan.free_of(&specs);
    let solved = Solved {
        name: "jaeger",
        series: label,
        specs: &free_specs,
        problem: &pinned,
        fit: &f,
        level,
        options: &opts,
        distinct: Some(distinct_points(x.iter().map(|q| [q.0, q.1, q.2]))),
        observed_norm: Some(norm),
    };
    let jm = JaegerModel(branch);
    let curve = plan.wrap(SlopeCurve {
        model: &jm,
        base: &x,
        at: at_slope,
    });
    let odr = slopes::summarise(method, &solved, curve, data, &index, true);
    let mut summary = odr.unwrap_or_else(|| {
        // The sampling coordinates are those of all three parameters.
        let coordinates = plan
            .all_free()
            .then(|| JaegerCoordinates::for_series(&x, branch))
            .flatten();
        let mut summary = match coordinates {
            Some(c) => summarise_reparameterised(method, solved, &c),
            None => summarise_with(method, solved),
        };
        summary.attach_points(data, &index);
        summary
    });
    plan.restore(&mut summary, &specs, level);
    let optimum = plan.expand(&f.params);
    Ok(JaegerFit::described(summary, &x, &optimum, branch))
}

impl JaegerFit {
    /// The fit of `summary` on `branch`, its notes saying what [`describe`] finds at its
    /// values (`optimum` where a row is missing) on the points `x`.
    fn described(
        mut summary: FitResult,
        x: &[JaegerX],
        optimum: &[f64],
        branch: JaegerBranch,
    ) -> Self {
        let (bistable_points, has_minimum) = describe(&mut summary, x, optimum, branch);
        JaegerFit {
            summary,
            branch,
            bistable_points,
            has_minimum,
        }
    }
}

/// Notes the branch, the points in the bistable band of eq 90 and a resistance without a
/// minimum (eq 82) on every row of `summary` and on its statistics; returns the number of
/// bistable points and whether the resistance has a minimum. The notes describe the values
/// reported: the optimum `optimum`, or the posterior medians.
fn describe(
    summary: &mut FitResult,
    x: &[JaegerX],
    optimum: &[f64],
    branch: JaegerBranch,
) -> (usize, bool) {
    let value = |k: usize| summary.params.get(k).map_or(optimum[k], |r| r.value);
    let m = Jaeger {
        a1: value(0),
        a2: value(1),
        a3: value(2),
        branch,
    };
    let bistable_points = x.iter().filter(|q| m.bistable(q.0)).count();
    let has_minimum = m.a1 * m.a2 > m.a3;
    let mut extra = format!("branch {}", branch_name(branch));
    if bistable_points > 0 {
        extra.push_str(&format!(
            "; {bistable_points} point(s) in the bistable band of eq 90"
        ));
    }
    if !has_minimum {
        extra.push_str("; a1 a2 <= a3: no minimum of the resistance (eq 82)");
    }
    for row in summary.params.iter_mut() {
        row.note = if row.note.is_empty() {
            extra.clone()
        } else {
            format!("{} {extra}", row.note)
        };
    }
    summary.stats.note = if summary.stats.note.is_empty() {
        extra
    } else {
        format!("{}; {extra}", summary.stats.note)
    };
    (bistable_points, has_minimum)
}

/// Jaeger's abscissa (tan δ, cos δ, ε) of a point at slope δ (radians).
fn at_slope(x: &JaegerX, delta: f64) -> JaegerX {
    let (sd, cd) = delta.sin_cos();
    (sd / cd, cd, x.2)
}

/// `upper` or `lower`.
pub(crate) fn branch_name(b: JaegerBranch) -> &'static str {
    match b {
        JaegerBranch::Upper => "upper",
        JaegerBranch::Lower => "lower",
    }
}
