//! Laws K(α) fitted to all series at once: K = cos 2α + c sin²α sin 2α (one parameter c; the
//! paper's fit with the rolling model is c = ½, §3.6.1, Figs. 3–4), one free K per series, and
//! the parameter-free impact law K = (cos 2α + ρ)/(1 + ρ) scored for comparison.
//!
//! Every law here makes the K of point i affine in one parameter, K_i = a_i + b_i p_{g(i)}
//! (law c: a = cos 2α, b = sin²α sin 2α > 0, one group; free: a = 0, b = 1, one group per
//! series). Hence:
//! - the feasible box of each parameter is exact: point i stays in regime B for K in its
//!   bracket (K_min, K_max] ([`crate::fit::k::bracket()`]), so p_j must lie in the intersection
//!   of ((K_min,i − a_i)/b_i, (K_max,i − a_i)/b_i] over the points of group j. An empty
//!   intersection means no value of the law keeps every point steady, and the fit says so
//!   instead of searching;
//! - the start is derived: the median over the group of the per-point inversions of eq 69,
//!   mapped to p, clamped into the box;
//! - the Jacobian costs two forward evaluations per point whatever the number of parameters:
//!   ∂r_i/∂p_j = −(dv̄/dK)_i b_i/σ_i for j = g(i), else 0, with dv̄/dK by a central difference in
//!   s = ln(K − K_min) (as in [`crate::fit::k::estimate()`]; accurate where the slope in K is
//!   nearly infinite).
//!
//! A point that leaves regime B during the search makes the residuals [`Infeasible`] (a
//! rejected step), never NaN.

use super::data::Dataset;
use super::k::{bracket, estimate, KBracket};
use super::posterior::{summarise_with, Method};
use super::summary::{information_criteria, FitResult, ParamSpec, Solved, StatsRow};
use crate::inverse::{fit, Infeasible, LsqOptions, Residuals};
use crate::models::{ForwardModel, Model};
use faer::MatMut;
use rayon::prelude::*;
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Which law of K(α).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KLaw {
    /// K = cos 2α + c sin²α sin 2α, c fitted.
    C,
    /// K = (cos 2α + ρ)/(1 + ρ), nothing fitted (scored only).
    Impact,
    /// One K per series.
    FreePerSeries,
}

impl KLaw {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            KLaw::C => "c",
            KLaw::Impact => "impact",
            KLaw::FreePerSeries => "free-per-series",
        }
    }
}

impl std::str::FromStr for KLaw {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        // Whole names only (any case): an abbreviation is refused with the choices.
        match s.trim().to_ascii_lowercase().as_str() {
            "c" => Ok(KLaw::C),
            "impact" => Ok(KLaw::Impact),
            "free-per-series" => Ok(KLaw::FreePerSeries),
            _ => Err(format!(
                "unknown law '{}': expected c, impact or free-per-series",
                crate::numfmt::clip(s, crate::numfmt::ECHO_CHARS)
            )),
        }
    }
}

/// Why a law cannot be fitted to the data.
#[derive(Debug, Clone, PartialEq)]
pub enum KLawError {
    /// Point `index` has no K with a steady state at its ξ and δ under the model.
    NoBracket {
        /// Index of the point in the dataset.
        index: usize,
        /// Why.
        reason: String,
    },
    /// No value of parameter `param` keeps every point of its group in regime B: the
    /// intersection of the points' feasible intervals is empty.
    EmptyBox {
        /// Parameter name.
        param: String,
        /// Largest lower end (and the point that sets it).
        lower: (f64, usize),
        /// Smallest upper end (and the point that sets it).
        upper: (f64, usize),
    },
    /// The least-squares solver refused the problem (malformed input to it).
    Solver(String),
    /// No point to fit (every point left out), or none in the group of parameter `param`.
    NoPoints {
        /// Parameter name (`c`, or `K of series '…'`).
        param: String,
    },
    /// The caller's stop flag was raised before the fit could be made.
    Interrupted,
}

impl std::error::Error for KLawError {}

impl fmt::Display for KLawError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KLawError::NoBracket { index, reason } => {
                write!(
                    f,
                    "point {}: no steady state for any K: {reason}",
                    index + 1
                )
            }
            KLawError::EmptyBox {
                param,
                lower,
                upper,
            } if !(lower.0.is_finite() && upper.0.is_finite()) => write!(
                f,
                "the points cannot constrain {param}: the law's dependence on it vanishes at \
                 their contact angles (points {} and {})",
                lower.1 + 1,
                upper.1 + 1
            ),
            KLawError::EmptyBox {
                param,
                lower,
                upper,
            } => write!(
                f,
                "no value of {param} keeps every point in regime B: point {} needs {param} > {} \
                 (below, the bead stops) but point {} needs {param} <= {} (above, it lifts off \
                 or runs away)",
                lower.1 + 1,
                crate::numfmt::fmt_f64(lower.0),
                upper.1 + 1,
                crate::numfmt::fmt_f64(upper.0)
            ),
            KLawError::Solver(s) => write!(f, "least-squares solver: {s}"),
            KLawError::NoPoints { param } => write!(f, "no point left to fit {param}"),
            KLawError::Interrupted => f.write_str("interrupted"),
        }
    }
}

/// The residuals (v_i − v̄_th(K_i(p)))/σ_i of a law over a dataset.
#[derive(Debug, Clone)]
pub struct KLawProblem<'a> {
    model: Model,
    data: &'a Dataset,
    law: KLaw,
    a: Vec<f64>,
    b: Vec<f64>,
    group: Vec<usize>,
    n: usize,
    brackets: Vec<KBracket>,
    /// Raised by the caller to cut the per-point work short ([`KLawError::Interrupted`]).
    stop: Option<Arc<AtomicBool>>,
}

/// Points per rayon task: a stick/slip evaluation costs a few µs, so small batches already pay.
const MIN_CHUNK: usize = 4;

impl<'a> KLawProblem<'a> {
    /// The problem for `law` under `model` (a contact model whose K can be inverted).
    pub fn new(model: Model, data: &'a Dataset, law: KLaw) -> Result<Self, KLawError> {
        Self::new_until(model, data, law, None)
    }

    /// As [`KLawProblem::new`], the per-point work (here and in [`KLawProblem::start`]) cut
    /// short with [`KLawError::Interrupted`] once `stop` is raised.
    pub fn new_until(
        model: Model,
        data: &'a Dataset,
        law: KLaw,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<Self, KLawError> {
        let stopped = || stop.as_ref().is_some_and(|s| s.load(Ordering::Relaxed));
        let brackets = data
            .points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                if stopped() {
                    return Err(KLawError::Interrupted);
                }
                bracket(&model, &p.scene).map_err(|e| KLawError::NoBracket {
                    index: i,
                    reason: e.to_string(),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let (mut a, mut b, mut group) = (Vec::new(), Vec::new(), Vec::new());
        for p in &data.points {
            let s = &p.scene;
            let (s2a, c2a) = (2.0 * s.alpha).sin_cos();
            match law {
                KLaw::C => {
                    a.push(c2a);
                    b.push(s.sin_alpha * s.sin_alpha * s2a);
                    group.push(0);
                }
                KLaw::Impact => {
                    a.push((c2a + s.rho) / (1.0 + s.rho));
                    b.push(0.0);
                    group.push(0);
                }
                KLaw::FreePerSeries => {
                    a.push(0.0);
                    b.push(1.0);
                    group.push(p.series);
                }
            }
        }
        let n = match law {
            KLaw::C => 1,
            KLaw::Impact => 0,
            KLaw::FreePerSeries => data.labels.len(),
        };
        Ok(KLawProblem {
            model,
            data,
            law,
            a,
            b,
            group,
            n,
            brackets,
            stop,
        })
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// The law.
    pub fn law(&self) -> KLaw {
        self.law
    }

    /// Name of the parameters: `c`, or `K` (one per series).
    pub fn param_name(&self) -> &'static str {
        match self.law {
            KLaw::C => "c",
            KLaw::Impact => "",
            KLaw::FreePerSeries => "K",
        }
    }

    /// Indices of the points of parameter `j`'s group.
    pub fn group_points(&self, j: usize) -> impl Iterator<Item = usize> + '_ {
        (0..self.group.len()).filter(move |&i| self.group[i] == j)
    }

    /// K of point `i` at parameters `p`.
    pub fn k_of(&self, i: usize, p: &[f64]) -> f64 {
        if self.n == 0 {
            self.a[i]
        } else {
            self.a[i] + self.b[i] * p[self.group[i]]
        }
    }

    /// Whether point `i` is in regime B at parameters `p` (its K inside its bracket).
    pub fn point_is_steady(&self, i: usize, p: &[f64]) -> bool {
        let br = &self.brackets[i];
        let k = self.k_of(i, p);
        k > br.lo && k <= br.hi
    }

    /// The exact feasible box of every parameter (see the module docs).
    pub fn feasible_box(&self) -> Result<(Vec<f64>, Vec<f64>), KLawError> {
        let mut lo = vec![(f64::NEG_INFINITY, 0usize); self.n];
        let mut hi = vec![(f64::INFINITY, 0usize); self.n];
        for (i, br) in self.brackets.iter().enumerate() {
            if self.n == 0 {
                break;
            }
            let g = self.group[i];
            let l = (br.lo - self.a[i]) / self.b[i];
            let h = (br.hi - self.a[i]) / self.b[i];
            if l > lo[g].0 {
                lo[g] = (l, i);
            }
            if h < hi[g].0 {
                hi[g] = (h, i);
            }
        }
        for j in 0..self.n {
            let param = || match self.law {
                KLaw::FreePerSeries => format!("K of series '{}'", self.data.labels[j]),
                _ => "c".into(),
            };
            if self.group_points(j).next().is_none() {
                return Err(KLawError::NoPoints { param: param() });
            }
            if !(lo[j].0 < hi[j].0) {
                let param = param();
                return Err(KLawError::EmptyBox {
                    param,
                    lower: lo[j],
                    upper: hi[j],
                });
            }
        }
        Ok((
            lo.iter().map(|x| x.0).collect(),
            hi.iter().map(|x| x.0).collect(),
        ))
    }

    /// The start: per group, the median of the per-point inversions of eq 69 mapped to the
    /// parameter, clamped into the open box (ends pulled in by 1e-6 of its width); the box's
    /// middle when no point of the group inverts.
    pub fn start(&self) -> Result<Vec<f64>, KLawError> {
        let (lo, hi) = self.feasible_box()?;
        let per_point: Vec<Option<f64>> = self
            .data
            .points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                if self.stopped() {
                    return None;
                }
                let e = estimate(&self.model, &p.scene, p.v, None);
                e.root.ok().map(|r| (r.k - self.a[i]) / self.b[i])
            })
            .collect();
        if self.stopped() {
            return Err(KLawError::Interrupted);
        }
        Ok((0..self.n)
            .map(|j| {
                let mut v: Vec<f64> = self.group_points(j).filter_map(|i| per_point[i]).collect();
                v.sort_by(|x, y| x.total_cmp(y));
                let w = hi[j] - lo[j];
                let (l, h) = (lo[j] + 1e-6 * w, hi[j] - 1e-6 * w);
                let mid = if v.is_empty() {
                    0.5 * (lo[j] + hi[j])
                } else {
                    v[v.len() / 2]
                };
                // The box is finite and non-empty (feasible_box); max/min, unlike clamp, also
                // keep a NaN end from panicking.
                mid.max(l).min(h)
            })
            .collect())
    }

    fn eval_v(&self, i: usize, k: f64) -> Result<f64, Infeasible> {
        let p = &self.data.points[i];
        let scene = p.scene.with_k(k).map_err(|_| Infeasible)?;
        match self.model.evaluate(&scene) {
            Ok(s) if s.mean_velocity.is_finite() => Ok(s.mean_velocity),
            _ => Err(Infeasible),
        }
    }

    /// dv̄/dK at point `i` and K = `k`: central difference in s = ln(K − K_min), step 1e-5,
    /// one-sided (second order) where a side leaves the bracket.
    fn dv_dk(&self, i: usize, k: f64) -> Result<f64, Infeasible> {
        let br = &self.brackets[i];
        let d = k - br.lo;
        if !(d > 0.0) {
            return Err(Infeasible);
        }
        let h: f64 = 1e-5;
        let at = |t: f64| self.eval_v(i, br.lo + d * t.exp());
        let ds = match (at(h), at(-h)) {
            (Ok(p), Ok(m)) => (p - m) / (2.0 * h),
            (Err(_), Ok(m)) => {
                let (v0, m2) = (self.eval_v(i, k)?, at(-2.0 * h)?);
                (3.0 * v0 - 4.0 * m + m2) / (2.0 * h)
            }
            (Ok(p), Err(_)) => {
                let (v0, p2) = (self.eval_v(i, k)?, at(2.0 * h)?);
                (-3.0 * v0 + 4.0 * p - p2) / (2.0 * h)
            }
            _ => return Err(Infeasible),
        };
        Ok(ds / d)
    }
}

impl Residuals for KLawProblem<'_> {
    fn n_params(&self) -> usize {
        self.n
    }
    fn n_residuals(&self) -> usize {
        self.data.points.len()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        out.par_iter_mut()
            .with_min_len(MIN_CHUNK)
            .enumerate()
            .try_for_each(|(i, o)| {
                let pt = &self.data.points[i];
                let v = self.eval_v(i, self.k_of(i, p))?;
                *o = (pt.v - v) / pt.sigma;
                Ok(())
            })
    }
    fn jacobian(&self, p: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let m = self.data.points.len();
        let d: Result<Vec<f64>, Infeasible> = (0..m)
            .into_par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|i| {
                // A stop cuts the costliest step of an iteration short; the solver then
                // stops at its next check.
                if self.stopped() {
                    return Err(Infeasible);
                }
                let pt = &self.data.points[i];
                Ok(-self.dv_dk(i, self.k_of(i, p))? * self.b[i] / pt.sigma)
            })
            .collect();
        let d = match d {
            Ok(d) => d,
            Err(e) => return Some(Err(e)),
        };
        for i in 0..m {
            for j in 0..self.n {
                out[(i, j)] = if self.group[i] == j { d[i] } else { 0.0 };
            }
        }
        Some(Ok(()))
    }
}

/// The fitted law with its reports.
#[derive(Debug, Clone, PartialEq)]
pub struct KLawFit {
    /// The law.
    pub law: KLaw,
    /// Parameter rows and statistics (for the impact law: no parameter rows, the statistics
    /// of the score).
    pub summary: FitResult,
    /// K of every point at the estimate (NaN where the point is outside its bracket).
    pub k: Vec<f64>,
}

/// Fits (or, for the impact law, scores) `law` under `model` on `data`, with covariance and
/// (when `profile`) profile-likelihood intervals at `level`.
pub fn fit_law(
    model: Model,
    data: &Dataset,
    law: KLaw,
    level: f64,
    profile: bool,
) -> Result<KLawFit, KLawError> {
    fit_law_with(model, data, law, level, &Method::lsq(profile))
}

/// As [`fit_law`], with the parameters estimated by `method` (least squares, or a posterior
/// run started from the least-squares optimum; see [`super::posterior`]). The impact law has
/// nothing to sample and is scored either way.
pub fn fit_law_with(
    model: Model,
    data: &Dataset,
    law: KLaw,
    level: f64,
    method: &Method,
) -> Result<KLawFit, KLawError> {
    let problem = KLawProblem::new_until(model, data, law, method.stop().cloned())?;
    let fit_name = format!("klaw-{}", law.name());
    let m = data.points.len();
    if law == KLaw::Impact {
        let mut r = vec![0.0; m];
        let (chi2, note, termination) = match problem.residuals(&[], &mut r) {
            Ok(()) => (
                r.iter().map(|x| x * x).sum::<f64>(),
                String::new(),
                "scored",
            ),
            Err(_) => {
                let out = (0..m).filter(|&i| !problem.point_is_steady(i, &[])).count();
                (
                    f64::INFINITY,
                    format!("{out} of {m} points have no steady state under the impact law"),
                    "infeasible",
                )
            }
        };
        let (aic, bic) = if chi2.is_finite() {
            information_criteria(&r, data.sigma)
        } else {
            (f64::INFINITY, f64::INFINITY)
        };
        let reduced = if m > 0 { chi2 / m as f64 } else { f64::NAN };
        let k = (0..m).map(|i| problem.k_of(i, &[])).collect();
        let mut summary = FitResult {
            params: Vec::new(),
            stats: StatsRow {
                fit: fit_name,
                series: "all".into(),
                n_points: m,
                n_params: 0,
                chi2,
                dof: m,
                reduced_chi2: reduced,
                aic,
                bic,
                termination: termination.into(),
                converged: chi2.is_finite(),
                iterations: 0,
                residual_evals: 1,
                sigma: data.sigma,
                condition: None,
                note,
                mcmc: None,
            },
            draws: None,
            correlation: None,
            residuals: r,
            points: Vec::new(),
        };
        summary.attach_points(data, &(0..m).collect::<Vec<_>>());
        return Ok(KLawFit { law, summary, k });
    }
    let (lower, upper) = problem.feasible_box()?;
    let start = problem.start()?;
    let opts = LsqOptions {
        lower: Some(lower),
        upper: Some(upper),
        sigma: data.sigma,
        stop: method.stop().cloned(),
        ..Default::default()
    };
    let f = fit(&problem, &start, &opts).map_err(|e| KLawError::Solver(e.to_string()))?;
    let specs: Vec<ParamSpec> = (0..problem.n)
        .map(|_| ParamSpec {
            name: problem.param_name(),
            unit: "1",
            paper_value: (law == KLaw::C).then_some(0.5),
            paper_source: if law == KLaw::C {
                "paper §3.6.1, Figs. 3-4 (rolling model, rho = 1/2)"
            } else {
                ""
            },
            default_prior: None,
        })
        .collect();
    let mut summary = summarise_with(
        method,
        Solved {
            name: &fit_name,
            series: "all",
            specs: &specs,
            problem: &problem,
            fit: &f,
            level,
            options: &opts,
        },
    );
    if law == KLaw::FreePerSeries {
        for (j, row) in summary.params.iter_mut().take(problem.n).enumerate() {
            row.series = data.labels[j].clone();
        }
    }
    for row in summary.params.iter_mut() {
        if row.at_bound {
            row.note = format!(
                "{} (the box ends are where a point leaves regime B)",
                row.note
            );
        }
    }
    let k = (0..m).map(|i| problem.k_of(i, &f.params)).collect();
    summary.attach_points(data, &(0..m).collect::<Vec<_>>());
    Ok(KLawFit { law, summary, k })
}
