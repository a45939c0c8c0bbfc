//! Laws K(α) fitted to all series at once: K = cos 2α + c sin²α sin 2α (one parameter c; the
//! paper's fit with the rolling model is c = ½, §3.6.1, Figs. 3–4), one free K per series, and
//! the parameter-free impact law K = (cos 2α + ρ)/(1 + ρ) scored for comparison.
//!
//! Every law here makes the K of point i affine in one parameter, K_i = a_i + b_i p_{g(i)}
//! (law c: a = cos 2α, b = sin²α sin 2α > 0, one group; free: a = 0, b = 1, one group per
//! series). Hence:
//! - the feasible box of each parameter is exact: point i stays in regime B for K in its
//!   bracket (K_min, K_max] (`fit::k::bracket`), so p_j must lie in the intersection
//!   of ((K_min,i − a_i)/b_i, (K_max,i − a_i)/b_i] over the points of group j. An empty
//!   intersection means no value of the law keeps every point steady, and the fit says so
//!   instead of searching;
//! - the start is derived: the median over the group of the per-point inversions of eq 69
//!   (at most `START_POINTS` per group, evenly spread over its points), mapped to p, clamped
//!   into the box;
//! - the Jacobian costs two forward evaluations per point whatever the number of parameters:
//!   ∂r_i/∂p_j = −(dv̄/dK)_i b_i/σ_i for j = g(i), else 0, with dv̄/dK from
//!   `crate::fit::k::dv_dk` (the derivative of the K inversion: steps uniform in
//!   s = ln(K − K_min), accurate where the slope in K is nearly infinite, differenced over the
//!   K values actually evaluated), v̄ at the point itself being the one the residuals just
//!   computed there;
//! - with one parameter per series the parameters are independent (each moves its own
//!   series' residuals only): the profile of one is computed on its series' points alone,
//!   the other series staying at their optimum, instead of refitting them at every step.
//!
//! Memory grows with the points (a bracket, the law's coefficients and the last velocities
//! per point), not with the iterations. The forward model is the lean steady state of the K
//! inversion (stick/slip without its map-slope and second-fixed-point diagnostics). A point
//! that leaves regime B during the search makes the residuals [`Infeasible`] (a rejected
//! step), never NaN.

use super::controls::{ControlError, Controls, Parameters, Plan};
use super::data::Dataset;
use super::k::bracket::eval;
use super::k::{bracket, dv_dk, estimate, KBracket};
use super::posterior::{summarise_with, Method};
use super::slopes;
use super::summary::{observed_norm, summarise_with_profiles, FitResult, ParamSpec, Solved};
use crate::inverse::estimate::{covariance_scale, information_criteria as fit_criteria};
use crate::inverse::{
    fit, profile_interval, Covariance, Fit, Infeasible, LsqOptions, OdrModel, ProfileInterval,
    Residuals, SigmaKind, Termination,
};
use crate::models::regimes::{regime_b_interval, REGIME_B_SCAN_STEP};
use crate::models::Model;
use crate::progress::{Progress, ProgressEvent, Tally};
use faer::{Mat, MatMut};
use rayon::prelude::*;
use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

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
    /// A control of the parameters (`fix`, `init`, `bounds`) that cannot be used on these
    /// data: the command line's flag, the value as given and why.
    Setting {
        /// The flag (`--fix`, `--init`, `--bounds`).
        flag: String,
        /// The control as given (`NAME=VALUE`).
        value: String,
        /// Why it cannot be used.
        reason: String,
    },
}

impl From<ControlError> for KLawError {
    fn from(e: ControlError) -> Self {
        KLawError::Setting {
            flag: e.flag.to_string(),
            value: e.value,
            reason: e.reason,
        }
    }
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
            KLawError::Setting {
                flag,
                value,
                reason,
            } => write!(f, "{flag} {value}: {reason}"),
        }
    }
}

/// The residuals (v_i − v̄_th(K_i(p)))/σ_i of a law over a dataset.
#[derive(Debug)]
pub(crate) struct KLawProblem<'a> {
    model: Model,
    data: &'a Dataset,
    law: KLaw,
    a: Vec<f64>,
    b: Vec<f64>,
    group: Vec<usize>,
    /// The points of each group, in order.
    members: Vec<Vec<usize>>,
    n: usize,
    brackets: Vec<KBracket>,
    /// Raised by the caller to cut the per-point work short ([`KLawError::Interrupted`]).
    stop: Option<Arc<AtomicBool>>,
    /// The parameters of the last successful residuals and v̄ of every point there (what the
    /// Jacobian at the same parameters starts from).
    last: Mutex<Option<(Vec<f64>, Vec<f64>)>>,
    /// Forward evaluations so far, and where they are reported.
    evals: AtomicU64,
    progress: Option<Progress>,
}

/// A law's points with their slopes as ODR inputs ([`super::slopes`]): v̄ of point i at slope δ
/// and the K of the law there (K depends on ξ alone, not on δ).
struct Slopes<'p, 'a>(&'p KLawProblem<'a>);

impl OdrModel for Slopes<'_, '_> {
    fn n_params(&self) -> usize {
        self.0.n
    }
    fn n_points(&self) -> usize {
        self.0.data.points.len()
    }
    fn value(&self, i: usize, delta: f64, p: &[f64]) -> Result<f64, Infeasible> {
        let pr = self.0;
        let scene = pr.data.points[i]
            .scene
            .with_delta(delta)
            .map_err(|_| Infeasible)?;
        let mut n = 0;
        pr.tick(1);
        match eval(&pr.model, &scene, pr.k_of(i, p), &mut n) {
            Ok(s) if s.mean_velocity.is_finite() => Ok(s.mean_velocity),
            _ => Err(Infeasible),
        }
    }
}

/// The parameters of `law` as the reports name them, with the paper's value of c.
fn law_specs(problem: &KLawProblem<'_>, law: KLaw) -> Vec<ParamSpec> {
    (0..problem.n)
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
        .collect()
}

/// The series whose largest σ_δ is wider than their steady range of slopes at the law's
/// parameters `p` (regime B at their ξ, ρ, f and K), as a note ("" when none): there, one
/// standard uncertainty spans every slope at which the bead rolls steadily. `steady` holds
/// slopes (radians, one per point of the data, in order) known to be steady at `p` — the
/// adjusted slopes of an ODR fit at its estimate — or is empty. Regime B at one K being an
/// interval of slopes, a series whose steady slopes span more than its σ_δ plus three steps
/// of the scan of [`regime_b_interval`] (its refined ends can fall up to two steps inside the
/// interval's) has a range wider than σ_δ, and is not scanned.
fn wide_slope_errors(problem: &KLawProblem<'_>, p: &[f64], steady: &[f64]) -> String {
    let data = problem.data;
    let mut out = Vec::new();
    for (s, label) in data.labels.iter().enumerate() {
        let pts = data.series_index(s);
        let Some(&i) = pts.first() else { continue };
        let sd = pts
            .iter()
            .map(|&j| data.points[j].sigma_delta)
            .fold(0.0, f64::max);
        if sd == 0.0 {
            continue;
        }
        let known: Option<Vec<f64>> = pts.iter().map(|&j| steady.get(j).copied()).collect();
        if let Some(known) = known {
            let lo = known.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = known.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if hi - lo >= sd + 3.0 * REGIME_B_SCAN_STEP {
                continue;
            }
        }
        let sc = &data.points[i].scene;
        let law = crate::scene::CollisionLaw::Value(problem.k_of(i, p));
        let range = regime_b_interval(&problem.model, sc.xi, sc.rho, sc.f, law);
        if let Some((lo, hi)) = range.filter(|(lo, hi)| sd > hi - lo) {
            out.push(format!(
                "series '{}': sigma_delta {} deg is wider than its steady range of slopes ({} \
                 to {} deg)",
                crate::numfmt::clip(label, crate::numfmt::ECHO_CHARS),
                crate::numfmt::fmt_sig(sd.to_degrees(), 3),
                crate::numfmt::fmt_sig(lo.to_degrees(), 5),
                crate::numfmt::fmt_sig(hi.to_degrees(), 5)
            ));
        }
    }
    out.join("; ")
}

/// Points per rayon task: a stick/slip evaluation costs a few µs, so small batches already pay.
const MIN_CHUNK: usize = 4;

/// Points per group whose inversions give the start (evenly spread over the group).
pub(crate) const START_POINTS: usize = 255;

impl<'a> KLawProblem<'a> {
    /// The problem for `law` under `model` (a contact model whose K can be inverted).
    #[cfg(test)]
    pub fn new(model: Model, data: &'a Dataset, law: KLaw) -> Result<Self, KLawError> {
        Self::new_until(model, data, law, None)
    }

    /// As [`KLawProblem::new`], the per-point work (here, in [`KLawProblem::start`] and in the
    /// Jacobian) cut short with [`KLawError::Interrupted`] once `stop` is raised.
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
        Ok(Self::with_brackets(model, data, law, brackets).with_stop(stop))
    }

    /// The problem with the brackets of every point already known (one bracket of K per point,
    /// in the order of `data.points`).
    ///
    /// # Panics
    /// When there are not as many brackets as points.
    pub fn with_brackets(
        model: Model,
        data: &'a Dataset,
        law: KLaw,
        brackets: Vec<KBracket>,
    ) -> Self {
        assert_eq!(brackets.len(), data.points.len(), "one bracket per point");
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
        let mut members = vec![Vec::new(); n.max(1)];
        for (i, &g) in group.iter().enumerate() {
            members[g].push(i);
        }
        KLawProblem {
            model,
            data,
            law,
            a,
            b,
            group,
            members,
            n,
            brackets,
            stop: None,
            last: Mutex::new(None),
            evals: AtomicU64::new(0),
            progress: None,
        }
    }

    /// Cuts the per-point work short once `stop` is raised ([`KLawError::Interrupted`] from
    /// [`KLawProblem::start`], a rejected step from the Jacobian).
    pub fn with_stop(mut self, stop: Option<Arc<AtomicBool>>) -> Self {
        self.stop = stop;
        self
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
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
        self.members.get(j).into_iter().flatten().copied()
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

    /// The start: per group, the median of the per-point inversions of eq 69 (at most
    /// `START_POINTS` points, evenly spread over the group) mapped to the parameter, clamped
    /// into the open box (ends pulled in by 1e-6 of its width); the box's middle when no point
    /// of the group inverts.
    pub fn start(&self) -> Result<Vec<f64>, KLawError> {
        let (lo, hi) = self.feasible_box()?;
        if self.stopped() {
            return Err(KLawError::Interrupted);
        }
        let start: Vec<f64> = (0..self.n)
            .map(|j| {
                let pts = &self.members[j];
                let step = pts.len().div_ceil(START_POINTS).max(1);
                let mut v: Vec<f64> = pts
                    .par_iter()
                    .step_by(step)
                    .filter_map(|&i| {
                        if self.stopped() {
                            return None;
                        }
                        let p = &self.data.points[i];
                        let e = estimate(&self.model, &p.scene, p.v, None);
                        e.root.ok().map(|r| (r.k - self.a[i]) / self.b[i])
                    })
                    .collect();
                self.tick(v.len() as u64);
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
            .collect();
        if self.stopped() {
            return Err(KLawError::Interrupted);
        }
        Ok(start)
    }

    /// Counts `n` forward evaluations (more or less: inversions count one each) and reports
    /// the total.
    fn tick(&self, n: u64) {
        let total = self.evals.fetch_add(n, Ordering::Relaxed) + n;
        if let Some(p) = &self.progress {
            p.report(ProgressEvent::Position(total));
        }
    }

    /// v̄ of point `i` at K = `k` (the lean steady state of the K inversion).
    fn eval_v(&self, i: usize, k: f64) -> Result<f64, Infeasible> {
        let p = &self.data.points[i];
        let mut n = 0;
        match eval(&self.model, &p.scene, k, &mut n) {
            Ok(s) if s.mean_velocity.is_finite() => Ok(s.mean_velocity),
            _ => Err(Infeasible),
        }
    }

    /// ∂r_i/∂p at point `i`, at K = `k` where v̄ = `v0`.
    fn slope(&self, i: usize, k: f64, v0: f64) -> Result<f64, Infeasible> {
        let pt = &self.data.points[i];
        let d = dv_dk(&self.brackets[i], k, v0, |k| self.eval_v(i, k).ok()).ok_or(Infeasible)?;
        Ok(-d * self.b[i] / pt.sigma)
    }

    /// The points of parameter `j`'s group as a problem of its own in that parameter alone
    /// (module docs: the parameters are independent with one per series, so the others do
    /// not enter its residuals).
    fn group(&self, j: usize) -> GroupProblem<'_, 'a> {
        GroupProblem { parent: self, j }
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
        let m = self.data.points.len();
        let mut last = self.last.lock().map(|mut l| l.take()).unwrap_or(None);
        let mut v = match last.take() {
            Some((_, v)) if v.len() == m => v,
            _ => vec![0.0; m],
        };
        let r = out
            .par_iter_mut()
            .zip(v.par_iter_mut())
            .with_min_len(MIN_CHUNK)
            .enumerate()
            .try_for_each(|(i, (o, vi))| {
                // A stop makes the residuals unavailable at once (a rejected step, a rejected
                // proposal of the sampler, which then stops at its next check).
                if self.stopped() {
                    return Err(Infeasible);
                }
                let pt = &self.data.points[i];
                *vi = self.eval_v(i, self.k_of(i, p))?;
                *o = (pt.v - *vi) / pt.sigma;
                Ok(())
            });
        self.tick(m as u64);
        if r.is_ok() {
            if let Ok(mut l) = self.last.lock() {
                *l = Some((p.to_vec(), v));
            }
        }
        r
    }
    fn jacobian(&self, p: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let m = self.data.points.len();
        // v̄ at p from the residuals just computed there, when they were.
        let known = self
            .last
            .lock()
            .ok()
            .and_then(|mut l| l.take())
            .filter(|(q, v)| q.as_slice() == p && v.len() == m);
        let d: Result<Vec<f64>, Infeasible> = (0..m)
            .into_par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|i| {
                // A stop cuts the costliest step of an iteration short; the solver then
                // stops at its next check.
                if self.stopped() {
                    return Err(Infeasible);
                }
                let k = self.k_of(i, p);
                let v0 = match &known {
                    Some((_, v)) => v[i],
                    None => self.eval_v(i, k)?,
                };
                self.slope(i, k, v0)
            })
            .collect();
        self.tick(2 * m as u64 + if known.is_some() { 0 } else { m as u64 });
        if let (Some(k), Ok(mut l)) = (known, self.last.lock()) {
            *l = Some(k);
        }
        let d = match d {
            Ok(d) => d,
            Err(e) => return Some(Err(e)),
        };
        for j in 0..self.n {
            for i in 0..m {
                out[(i, j)] = 0.0;
            }
        }
        for (i, di) in d.into_iter().enumerate() {
            out[(i, self.group[i])] = di;
        }
        Some(Ok(()))
    }
}

/// The points of one group as a one-parameter problem (the group's own parameter, on which
/// alone their residuals depend).
struct GroupProblem<'p, 'a> {
    parent: &'p KLawProblem<'a>,
    j: usize,
}

impl GroupProblem<'_, '_> {
    /// K of point `i` (of this group) at the group's parameter `x`.
    fn k_at(&self, i: usize, x: f64) -> f64 {
        self.parent.a[i] + self.parent.b[i] * x
    }
}

impl Residuals for GroupProblem<'_, '_> {
    fn n_params(&self) -> usize {
        1
    }
    fn n_residuals(&self) -> usize {
        self.parent.members[self.j].len()
    }
    fn residuals(&self, x: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        let pts = &self.parent.members[self.j];
        let r = out
            .par_iter_mut()
            .zip(pts.par_iter())
            .with_min_len(MIN_CHUNK)
            .try_for_each(|(o, &i)| {
                let pt = &self.parent.data.points[i];
                *o = (pt.v - self.parent.eval_v(i, self.k_at(i, x[0]))?) / pt.sigma;
                Ok(())
            });
        self.parent.tick(pts.len() as u64);
        r
    }
    fn jacobian(&self, x: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let pts = &self.parent.members[self.j];
        let d: Result<Vec<f64>, Infeasible> = pts
            .par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|&i| {
                if self.parent.stopped() {
                    return Err(Infeasible);
                }
                let k = self.k_at(i, x[0]);
                self.parent.slope(i, k, self.parent.eval_v(i, k)?)
            })
            .collect();
        self.parent.tick(3 * pts.len() as u64);
        match d {
            Ok(d) => {
                for (r, di) in d.into_iter().enumerate() {
                    out[(r, 0)] = di;
                }
                Some(Ok(()))
            }
            Err(e) => Some(Err(e)),
        }
    }
}

/// The options of parameter `j` of `opts` alone, as a one-parameter problem's (its bounds
/// and typical size; the tolerances, stop flag and progress as `opts`), σ taken as `sigma`.
fn one_param_options(opts: &LsqOptions, j: usize, sigma: SigmaKind) -> LsqOptions {
    let one = |v: &Option<Vec<f64>>| v.as_ref().map(|v| vec![v[j]]);
    LsqOptions {
        ftol: opts.ftol,
        xtol: opts.xtol,
        gtol: opts.gtol,
        max_iterations: opts.max_iterations,
        max_residual_evals: opts.max_residual_evals,
        initial_radius_factor: opts.initial_radius_factor,
        lower: one(&opts.lower),
        upper: one(&opts.upper),
        typical: one(&opts.typical),
        restarts: opts.restarts,
        sigma,
        scale_covar: opts.scale_covar,
        polish: opts.polish,
        stop: opts.stop.clone(),
        progress: opts.progress.clone(),
    }
}

/// A 1 × 1 covariance of standard error `se` with the factor `scale`.
fn covariance_1(se: f64, scale: f64) -> Covariance {
    Covariance {
        matrix: Mat::from_fn(1, 1, |_, _| se * se),
        correlation: Mat::from_fn(1, 1, |_, _| 1.0),
        std_errors: vec![se],
        scale,
        condition: 1.0,
    }
}

/// Profile intervals of a law with one parameter per series, each on its series' points
/// alone (module docs): the same Δχ² threshold and covariance half-width as the full fit's,
/// the constrained χ² of the others being their optimum's. `None` when one cannot be formed.
fn separable_profiles(
    problem: &KLawProblem<'_>,
    fit: &Fit,
    level: f64,
    opts: &LsqOptions,
) -> Option<Vec<ProfileInterval>> {
    (0..problem.n)
        .into_par_iter()
        .map(|j| {
            let group = problem.group(j);
            let pts = &problem.members[j];
            let residuals: Vec<f64> = pts.iter().map(|&i| fit.residuals[i]).collect();
            let chi2 = residuals.iter().map(|r| r * r).sum();
            let sub = Fit {
                params: vec![fit.params[j]],
                residuals,
                chi2,
                dof: fit.dof,
                reduced_chi2: fit.reduced_chi2,
                covariance: fit
                    .covariance
                    .as_ref()
                    .map(|c| covariance_1(c.std_errors[j], c.scale)),
                sigma: fit.sigma,
                scale_covar: fit.scale_covar,
                aic: fit.aic,
                bic: fit.bic,
                iterations: fit.iterations,
                residual_evals: fit.residual_evals,
                jacobian_evals: fit.jacobian_evals,
                termination: fit.termination,
                at_bound: vec![fit.at_bound.get(j).copied().unwrap_or(false)],
            };
            let sub_opts = one_param_options(opts, j, opts.sigma);
            profile_interval(&group, &sub, 0, level, &sub_opts).ok()
        })
        .collect()
}

/// The least-squares fit of a law with one parameter per series, made series by series
/// (module docs: each parameter moves its own series' residuals only, so the joint optimum is
/// the optimum of every series on its own), in time linear in the number of series.
///
/// The result is the joint fit's: the parameters and residuals of every series in the order
/// of the parameters and points; χ², the degrees of freedom m − n, AIC and BIC over all m
/// points and n parameters; the covariance block-diagonal (JᵀJ is diagonal), each variance
/// 1/Σᵢ ∂rᵢ/∂p_j² of its series times the joint scale (1 with σ given, χ²/(m − n) with unit
/// weights), the correlations 0 and the condition number of the column-equilibrated
/// Jacobian 1 (orthogonal columns). It has a covariance only when every series has one. The
/// termination is the first series' (in parameter order) that did not converge, else that of
/// the series that took the most iterations; iterations and evaluations are the most any
/// series took (the series run side by side).
fn fit_per_series(
    problem: &KLawProblem<'_>,
    start: &[f64],
    opts: &LsqOptions,
) -> Result<Fit, KLawError> {
    let (n, m) = (problem.n, problem.data.points.len());
    let fits = (0..n)
        .into_par_iter()
        .map(|j| {
            // σ is taken as given in each series' fit: the scale of unit weights (or of
            // `scale_covar`) is the joint χ²/(m − n), applied below.
            let sub_opts = LsqOptions {
                scale_covar: false,
                ..one_param_options(opts, j, SigmaKind::Absolute)
            };
            fit(&problem.group(j), &start[j..=j], &sub_opts)
        })
        .collect::<Result<Vec<Fit>, _>>()
        .map_err(|e| KLawError::Solver(e.to_string()))?;
    let mut residuals = vec![f64::NAN; m];
    let mut feasible = true;
    for (j, f) in fits.iter().enumerate() {
        let pts = &problem.members[j];
        if f.residuals.len() == pts.len() {
            for (&i, &r) in pts.iter().zip(&f.residuals) {
                residuals[i] = r;
            }
        } else {
            feasible = false;
        }
    }
    let chi2 = if feasible && fits.iter().all(|f| f.chi2.is_finite()) {
        residuals.iter().map(|r| r * r).sum()
    } else {
        f64::INFINITY
    };
    if !feasible {
        residuals.clear();
    }
    let dof = m - n;
    let reduced_chi2 = if dof > 0 {
        chi2 / dof as f64
    } else {
        f64::INFINITY
    };
    let scale = covariance_scale(opts.sigma, opts.scale_covar, dof, reduced_chi2);
    let covariance = match scale {
        Some(s) if chi2.is_finite() => fits
            .iter()
            .map(|f| f.covariance.as_ref().map(|c| c.std_errors[0] * s.sqrt()))
            .collect::<Option<Vec<f64>>>()
            .map(|se| Covariance {
                matrix: Mat::from_fn(n, n, |i, j| if i == j { se[i] * se[i] } else { 0.0 }),
                correlation: Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 }),
                std_errors: se,
                scale: s,
                condition: 1.0,
            }),
        _ => None,
    };
    let (aic, bic) = fit_criteria(chi2, m, n, opts.sigma);
    let slowest = fits.iter().max_by_key(|f| f.iterations);
    let termination = fits
        .iter()
        .find(|f| !f.converged())
        .or(slowest)
        .map_or(Termination::InfeasibleStart, |f| f.termination);
    let most = |g: fn(&Fit) -> usize| fits.iter().map(g).max().unwrap_or(0);
    Ok(Fit {
        params: fits.iter().map(|f| f.params[0]).collect(),
        residuals,
        chi2,
        dof,
        reduced_chi2,
        covariance,
        sigma: opts.sigma,
        scale_covar: opts.scale_covar,
        aic,
        bic,
        iterations: most(|f| f.iterations),
        residual_evals: most(|f| f.residual_evals),
        jacobian_evals: most(|f| f.jacobian_evals),
        termination,
        at_bound: fits
            .iter()
            .map(|f| f.at_bound.first().copied().unwrap_or(false))
            .collect(),
    })
}

/// The fitted law with its reports.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct KLawFit {
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
pub(crate) fn fit_law(
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
pub(crate) fn fit_law_with(
    model: Model,
    data: &Dataset,
    law: KLaw,
    level: f64,
    method: &Method,
) -> Result<KLawFit, KLawError> {
    fit_law_in(model, data, law, level, method, KLawContext::default())
}

/// What a K-law fit may be given besides its model, data, law, level and method.
#[derive(Debug, Clone, Default)]
pub(crate) struct KLawContext {
    /// The brackets of K of every point (one per point, in the order of the points), when
    /// the caller already has them; computed otherwise.
    pub brackets: Option<Vec<KBracket>>,
    /// Where progress goes: a task labelled with the fit's name, of unknown total, whose
    /// positions count the model evaluations (residual vectors and Jacobians over the data) of
    /// the least-squares fit and its profiles, from a `ProgressObserver`
    /// on their iterations.
    pub progress: Option<Progress>,
}

/// Reports `Finish` to a progress sink when dropped.
struct Finish<'p>(Option<&'p Progress>);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        if let Some(p) = self.0 {
            p.report(ProgressEvent::Finish);
        }
    }
}

/// As [`fit_law_with`], given the brackets or a progress sink (see [`KLawContext`]).
pub(crate) fn fit_law_in(
    model: Model,
    data: &Dataset,
    law: KLaw,
    level: f64,
    method: &Method,
    context: KLawContext,
) -> Result<KLawFit, KLawError> {
    let fit_name = format!("klaw-{}", law.name());
    let progress = context.progress;
    let _finish = Finish(progress.as_ref());
    if let Some(p) = &progress {
        p.report(ProgressEvent::Start {
            label: &fit_name,
            total: 0,
            check_every: 0,
        });
    }
    let m = data.points.len();
    if law == KLaw::Impact {
        return Ok(score_impact(model, data, fit_name));
    }
    let problem = match context.brackets {
        Some(b) => {
            if b.len() != m {
                return Err(KLawError::Solver(format!(
                    "{} brackets for {m} points",
                    b.len()
                )));
            }
            KLawProblem::with_brackets(model, data, law, b).with_stop(method.stop().cloned())
        }
        None => KLawProblem::new_until(model, data, law, method.stop().cloned())?,
    };
    let (lower, upper) = problem.feasible_box()?;
    let specs = law_specs(&problem, law);
    let plan = law_plan(&problem, method, &lower, &upper)?;
    let opts = plan.options(LsqOptions {
        lower: Some(lower),
        upper: Some(upper),
        sigma: data.sigma,
        stop: method.stop().cloned(),
        progress: progress.clone().map(Tally::new),
        ..Default::default()
    });
    let index: Vec<usize> = (0..m).collect();
    if plan.all_held() {
        return score_held(&problem, &plan, &fit_name, &specs, level, method);
    }
    let pinned = plan.wrap(&problem);
    plan.check_start(&pinned)?;
    let separable = law == KLaw::FreePerSeries && plan.all_free();
    let f = match method {
        // Independent parameters: each series fitted on its own.
        Method::Lsq { .. } if separable => fit_per_series(&problem, &plan.start(), &opts)?,
        _ => fit(&pinned, &plan.start(), &opts).map_err(|e| KLawError::Solver(e.to_string()))?,
    };
    let free_specs = plan.free_of(&specs);
    let solved = Solved {
        name: &fit_name,
        series: "all",
        specs: &free_specs,
        problem: &pinned,
        fit: &f,
        level,
        options: &opts,
        distinct: None,
        observed_norm: Some(observed_norm(data.points.iter().map(|p| (&p.v, &p.sigma)))),
    };
    let odr = slopes::summarise(
        method,
        &solved,
        plan.wrap(Slopes(&problem)),
        data,
        &index,
        false,
    );
    let slope_errors = odr.is_some();
    let mut summary = match (odr, method) {
        (Some(s), _) => s,
        // Independent parameters: each profiled on its own series.
        (None, Method::Lsq { profile: true, .. }) if separable && problem.n > 1 => {
            summarise_with_profiles(solved, |s| {
                separable_profiles(&problem, s.fit, s.level, s.options)
            })
        }
        (None, _) => summarise_with(method, solved),
    };
    plan.restore(&mut summary, &specs, level);
    label_rows(&mut summary, &problem);
    let params: Vec<f64> = if slope_errors {
        summary
            .params
            .iter()
            .take(problem.n)
            .map(|r| r.value)
            .collect()
    } else {
        plan.expand(&f.params)
    };
    let k = (0..m).map(|i| problem.k_of(i, &params)).collect();
    if slope_errors {
        // The adjusted slopes are steady at the estimate of an ODR fit, not at a posterior's.
        let steady: Vec<f64> = match method {
            Method::Lsq { .. } => summary
                .points
                .iter()
                .map_while(|pt| pt.delta_fit_deg.map(f64::to_radians))
                .collect(),
            Method::Mcmc(_) => Vec::new(),
        };
        let note = wide_slope_errors(&problem, &params, &steady);
        summary.stats.note = super::summary::join(&summary.stats.note, &note);
    } else {
        summary.attach_points(data, &index);
    }
    Ok(KLawFit { law, summary, k })
}

/// The controls of `method` on the law of `problem`, whose box is `lower`, `upper`: each K
/// of a law with one per series is of its series.
fn law_plan(
    problem: &KLawProblem<'_>,
    method: &Method,
    lower: &[f64],
    upper: &[f64],
) -> Result<Plan, KLawError> {
    let start = problem.start()?;
    let names = vec![problem.param_name(); problem.n];
    let series: Vec<&str> = match problem.law {
        KLaw::FreePerSeries => problem.data.labels.iter().map(String::as_str).collect(),
        _ => vec!["all"; problem.n],
    };
    Ok(Plan::new(
        &Controls::of(method),
        Parameters {
            names: &names,
            series: &series,
            lower,
            upper,
            start: &start,
        },
    )?)
}

/// Names the series of each K of a law with one per series in the rows of `summary`, and
/// says where the box ends are in the note of a row on one.
fn label_rows(summary: &mut FitResult, problem: &KLawProblem<'_>) {
    if problem.law == KLaw::FreePerSeries {
        for (j, row) in summary.params.iter_mut().take(problem.n).enumerate() {
            row.series = problem.data.labels[j].clone();
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
}

/// The law of `problem` with every parameter held (`plan`): scored at the values held, or an
/// error for a posterior run (nothing to sample).
fn score_held(
    problem: &KLawProblem<'_>,
    plan: &Plan,
    fit_name: &str,
    specs: &[ParamSpec],
    level: f64,
    method: &Method,
) -> Result<KLawFit, KLawError> {
    if matches!(method, Method::Mcmc(_)) {
        return Err(plan.nothing_to_sample().into());
    }
    let data = problem.data;
    let m = data.points.len();
    let mut summary = plan.score(problem, (fit_name, "all"), specs, level, data.sigma);
    label_rows(&mut summary, problem);
    summary.attach_points(data, &(0..m).collect::<Vec<_>>());
    let params = plan.expand(&[]);
    let k = (0..m).map(|i| problem.k_of(i, &params)).collect();
    Ok(KLawFit {
        law: problem.law,
        summary,
        k,
    })
}

/// The impact law scored on `data` (nothing to fit): χ², AIC, BIC of its residuals, or how
/// many points it leaves without a steady state.
fn score_impact(model: Model, data: &Dataset, fit_name: String) -> KLawFit {
    let m = data.points.len();
    let k: Vec<f64> = data
        .points
        .iter()
        .map(|p| {
            let s = &p.scene;
            let c2a = (2.0 * s.alpha).cos();
            (c2a + s.rho) / (1.0 + s.rho)
        })
        .collect();
    let r: Vec<Option<f64>> = data
        .points
        .par_iter()
        .zip(&k)
        .with_min_len(MIN_CHUNK)
        .map(|(p, &k)| {
            let mut n = 0;
            match eval(&model, &p.scene, k, &mut n) {
                Ok(s) if s.mean_velocity.is_finite() => Some((p.v - s.mean_velocity) / p.sigma),
                _ => None,
            }
        })
        .collect();
    let out = r.iter().filter(|x| x.is_none()).count();
    let r: Vec<f64> = r.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect();
    let infeasible =
        (out > 0).then(|| format!("{out} of {m} points have no steady state under the impact law"));
    let mut summary = FitResult::scored(
        (fit_name, "all".into()),
        r,
        data.sigma,
        infeasible,
        Vec::new(),
    );
    summary.attach_points(data, &(0..m).collect::<Vec<_>>());
    KLawFit {
        law: KLaw::Impact,
        summary,
        k,
    }
}

#[cfg(test)]
mod quadrature_tests {
    use super::*;
    use crate::fit::slopes::{Integrated, SLOPE_NODES, SLOPE_NODES_PLAIN};
    use crate::inverse::Residuals;

    /// The log-likelihood integrated over the slopes of `tests/reference/odr/bead_stick.csv`
    /// (σ_δ = 0.1°, law c) on the nodes centred on each integrand agrees with 400 plain
    /// Gauss–Hermite nodes around the measured slopes (an independent rule, converged: it agrees
    /// with 20 centred nodes to 1e-10) to 1e-3 at 41 values of c across ±3.5 posterior
    /// standard deviations; 12 plain nodes miss it by more than 0.1, alternately above and
    /// below.
    #[test]
    fn centred_slope_quadrature_matches_a_high_order_rule() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/reference/odr/bead_stick.csv"
        );
        let d = Dataset::from_csv(path).unwrap();
        let pr = KLawProblem::new(Model::Stick, &d, KLaw::C).unwrap();
        let index: Vec<usize> = (0..d.points.len()).collect();
        let rules =
            |centred, plain| Integrated::with_rules(Slopes(&pr), &d, &index, centred, plain);
        let (reference, fine, used, plain) = (
            rules(0, 400),
            rules(20, SLOPE_NODES_PLAIN),
            rules(SLOPE_NODES, SLOPE_NODES_PLAIN),
            rules(0, SLOPE_NODES_PLAIN),
        );
        let ll = |x: &dyn Residuals, c: f64| {
            let mut r = vec![0.0; x.n_residuals()];
            x.residuals(&[c], &mut r).unwrap();
            -0.5 * r.iter().map(|v| v * v).sum::<f64>()
        };
        let (mut worst_fine, mut worst_used, mut worst_plain) = (0f64, 0f64, 0f64);
        for j in 0..=40 {
            let c = 0.49 + 0.0007 * j as f64;
            let want = ll(&reference, c);
            worst_fine = worst_fine.max((ll(&fine, c) - want).abs());
            worst_used = worst_used.max((ll(&used, c) - want).abs());
            worst_plain = worst_plain.max((ll(&plain, c) - want).abs());
        }
        assert!(worst_fine < 1e-10, "20 centred nodes: {worst_fine}");
        assert!(
            worst_used < 1e-3,
            "{SLOPE_NODES} centred nodes: {worst_used}"
        );
        assert!(worst_plain > 0.1, "12 plain nodes: {worst_plain}");
    }
}
