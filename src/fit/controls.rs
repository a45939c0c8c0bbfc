//! lmfit's controls of a fit's parameters, by name: parameters held at a value (`fix`),
//! starting values (`init`), bounds (`bounds`), and the covariance scaled by the reduced χ²
//! (`scale_covar`, [`LsqOptions::scale_covar`]).
//!
//! A fit with parameters held is made in its free parameters alone: [`Pinned`] wraps the
//! fit's residuals (or its ODR model) and puts the held values into the full parameter vector,
//! so that least squares, the profiles, orthogonal distance regression and posterior runs all
//! see a problem of fewer parameters. The summary gets the held parameters back as rows of
//! their own ([`Plan::restore`]): the value held, no standard error or interval
//! (`ci_method = none`), the note `fixed`, NaN in the correlation matrix and a constant column
//! in the draws; χ², the degrees of freedom (m − free), AIC and BIC count the free parameters
//! only. A fit whose parameters are all held is scored at them ([`Plan::score`]).
//!
//! A start given replaces the fit's own and must lie in the parameter's box; bounds are
//! intersected with the box (the fit's own start is then moved into the intersection). The
//! box of each parameter is the fit's: for the K(α) laws where every point stays in regime B,
//! for Jan's μ below every slope's tan δ, for Jaeger's a1, a2, a3 non-negative.
//!
//! Names: `NAME` applies to that parameter in every fit that has it (every series of a fit per
//! series, every K of `free-per-series`), `NAME[SERIES]` in the fit (or to the K) of that
//! series alone; a parameter named both ways takes the series' control, and a name given twice
//! the last.

use super::summary::{FitResult, ParamRow, ParamSpec};
use crate::inverse::posterior::Method;
use crate::inverse::{Infeasible, LsqOptions, OdrModel, Residuals, SigmaKind};
use crate::numfmt::{clip, echo_f64, fmt_f64, ECHO_CHARS};
use faer::{Mat, MatMut};
use std::fmt;

/// The controls of a method ([`Method::Lsq`]'s `fix`, `init`, `bounds` and `scale_covar`, or
/// those of a posterior run's settings).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Controls<'a> {
    pub fix: &'a [(String, f64)],
    pub init: &'a [(String, f64)],
    pub bounds: &'a [(String, (f64, f64))],
    pub scale_covar: bool,
}

/// A control that cannot be used: the command line's flag, the value as given, and why.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ControlError {
    pub flag: &'static str,
    pub value: String,
    pub reason: String,
}

impl fmt::Display for ControlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}: {}", self.flag, self.value, self.reason)
    }
}

/// An end of a box as a message shows it (`inf`, `-inf` where it is open).
fn end_text(x: f64) -> String {
    if x.is_infinite() {
        (if x > 0.0 { "inf" } else { "-inf" }).to_string()
    } else {
        fmt_f64(x)
    }
}

/// `NAME=VALUE` as the command line takes it.
fn pair_text(key: &str, v: f64) -> String {
    format!("{}={}", clip(key, ECHO_CHARS), echo_f64(v))
}

/// `NAME=LO,HI` as the command line takes it.
fn bounds_text(key: &str, (lo, hi): (f64, f64)) -> String {
    format!(
        "{}={},{}",
        clip(key, ECHO_CHARS),
        echo_f64(lo),
        echo_f64(hi)
    )
}

/// A control's key split into the parameter's name and the series it is limited to.
fn split_key(key: &str) -> (&str, Option<&str>) {
    match (key.find('['), key.strip_suffix(']')) {
        (Some(i), Some(k)) if i > 0 => (&key[..i], Some(&k[i + 1..])),
        _ => (key, None),
    }
}

impl<'a> Controls<'a> {
    /// The controls `method` carries.
    pub fn of(method: &'a Method) -> Self {
        match method {
            Method::Lsq {
                fix,
                init,
                bounds,
                scale_covar,
                ..
            } => Controls {
                fix,
                init,
                bounds,
                scale_covar: *scale_covar,
            },
            Method::Mcmc(s) => Controls {
                fix: &s.fix,
                init: &s.init,
                bounds: &s.bounds,
                scale_covar: false,
            },
        }
    }

    /// Every key with its flag and the control as given.
    fn keys(&self) -> Vec<(&'static str, &'a str, String)> {
        let fix = self.fix.iter().map(|(k, v)| ("--fix", k, pair_text(k, *v)));
        let init = self
            .init
            .iter()
            .map(|(k, v)| ("--init", k, pair_text(k, *v)));
        let bounds = self
            .bounds
            .iter()
            .map(|(k, b)| ("--bounds", k, bounds_text(k, *b)));
        fix.chain(init)
            .chain(bounds)
            .map(|(f, k, t)| (f, k.as_str(), t))
            .collect()
    }

    /// Refuses a control of a parameter the fit does not have (its names `params`) or of a
    /// series not among `labels`, bounds that are not an interval, and a value that is not a
    /// number.
    pub fn check(&self, params: &[&str], labels: &[String]) -> Result<(), ControlError> {
        for (flag, key, text) in self.keys() {
            let fail = |reason: String| ControlError {
                flag,
                value: text.clone(),
                reason,
            };
            let (name, series) = split_key(key);
            if !params.contains(&name) {
                let why = if params.is_empty() {
                    format!(
                        "no parameter '{}': this fit has none",
                        clip(name, ECHO_CHARS)
                    )
                } else {
                    format!(
                        "no parameter '{}' in this fit; expected one of {}",
                        clip(name, ECHO_CHARS),
                        params.join(", ")
                    )
                };
                return Err(fail(why));
            }
            if let Some(s) = series.filter(|s| !labels.iter().any(|l| l == s)) {
                return Err(fail(format!(
                    "no series '{}' in the data (series: {})",
                    clip(s, ECHO_CHARS),
                    labels.join(", ")
                )));
            }
        }
        let numbers = self
            .fix
            .iter()
            .map(|(k, v)| ("--fix", pair_text(k, *v), v.is_finite()))
            .chain(
                self.init
                    .iter()
                    .map(|(k, v)| ("--init", pair_text(k, *v), v.is_finite())),
            );
        for (flag, value, ok) in numbers {
            if !ok {
                return Err(ControlError {
                    flag,
                    value,
                    reason: "the value must be a finite number".into(),
                });
            }
        }
        for (k, b) in self.bounds {
            if b.0.is_nan() || b.1.is_nan() || b.0 >= b.1 {
                return Err(ControlError {
                    flag: "--bounds",
                    value: bounds_text(k, *b),
                    reason: "expected LO,HI with LO < HI (-inf and inf allowed)".into(),
                });
            }
        }
        Ok(())
    }

    /// The control in `list` of parameter `name` of series `series`: `NAME[SERIES]` over
    /// `NAME`, the last of each.
    fn find<'l, T: Copy>(
        list: &'l [(String, T)],
        name: &str,
        series: &str,
    ) -> Option<(&'l str, T)> {
        let mine = |k: &str, specific: bool| {
            let (n, s) = split_key(k);
            n == name
                && (if specific {
                    s == Some(series)
                } else {
                    s.is_none()
                })
        };
        list.iter()
            .rev()
            .find(|(k, _)| mine(k, true))
            .or_else(|| list.iter().rev().find(|(k, _)| mine(k, false)))
            .map(|(k, v)| (k.as_str(), *v))
    }
}

/// The controls of one fit resolved against its parameters: which are held, the box and start
/// of the free ones, and whether the covariance is scaled.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    /// The value held, per parameter of the fit.
    pins: Vec<Option<f64>>,
    /// The free parameters' indices, in order.
    free: Vec<usize>,
    /// The box of every parameter, the controls' bounds intersected with the fit's.
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Whether any bound was given for this fit.
    bounded: bool,
    /// The start of every parameter (a held one's is its value).
    start: Vec<f64>,
    /// The parameters whose start was given.
    initialised: Vec<usize>,
    /// The series of each parameter.
    series: Vec<String>,
    /// The controls that apply to this fit, as given (for the message of a start at which
    /// the model has no value).
    given: Vec<(&'static str, String)>,
    scale_covar: bool,
}

/// What [`Plan::new`] needs of a fit: its parameters' names and series, box and start.
pub(crate) struct Parameters<'a> {
    pub names: &'a [&'a str],
    /// The series of each parameter (the fit's, or each K's for one K per series).
    pub series: &'a [&'a str],
    pub lower: &'a [f64],
    pub upper: &'a [f64],
    pub start: &'a [f64],
}

impl Plan {
    /// The plan of `controls` for a fit of parameters `p`: each held value and start checked
    /// against the parameter's box, bounds intersected with it.
    pub fn new(controls: &Controls<'_>, p: Parameters<'_>) -> Result<Plan, ControlError> {
        let n = p.names.len();
        let mut plan = Plan {
            pins: vec![None; n],
            free: Vec::with_capacity(n),
            lower: p.lower.to_vec(),
            upper: p.upper.to_vec(),
            bounded: false,
            start: p.start.to_vec(),
            initialised: Vec::new(),
            series: p.series.iter().map(|s| s.to_string()).collect(),
            given: Vec::new(),
            scale_covar: controls.scale_covar,
        };
        for j in 0..n {
            let (name, series) = (p.names[j], p.series[j]);
            let fix = Controls::find(controls.fix, name, series);
            let init = Controls::find(controls.init, name, series);
            let bounds = Controls::find(controls.bounds, name, series);
            let (lo, hi) = (p.lower[j], p.upper[j]);
            let box_text = format!("[{}, {}]", end_text(lo), end_text(hi));
            let place = if series == "all" {
                String::new()
            } else {
                format!(" of series '{}'", clip(series, ECHO_CHARS))
            };
            if let Some((k, v)) = fix {
                let fail = |reason: String| ControlError {
                    flag: "--fix",
                    value: pair_text(k, v),
                    reason,
                };
                if let Some((k2, v2)) = init {
                    return Err(fail(format!(
                        "{name} is held, and --init {} gives it a start",
                        pair_text(k2, v2)
                    )));
                }
                if let Some((k2, b)) = bounds {
                    return Err(fail(format!(
                        "{name} is held, and --bounds {} gives it bounds",
                        bounds_text(k2, b)
                    )));
                }
                if !(v >= lo && v <= hi) {
                    return Err(fail(format!(
                        "outside the box {box_text} of {name}{place} (where the model has a \
                         value at every point)"
                    )));
                }
                plan.pins[j] = Some(v);
                plan.start[j] = v;
                plan.given.push(("--fix", pair_text(k, v)));
                continue;
            }
            plan.free.push(j);
            if let Some((k, b)) = bounds {
                let (l, h) = (lo.max(b.0), hi.min(b.1));
                if !(l < h) {
                    return Err(ControlError {
                        flag: "--bounds",
                        value: bounds_text(k, b),
                        reason: format!(
                            "leaves nothing of the box {box_text} of {name}{place}; give \
                             bounds that overlap it (or --fix to hold {name})"
                        ),
                    });
                }
                plan.lower[j] = l;
                plan.upper[j] = h;
                plan.bounded = true;
                plan.given.push(("--bounds", bounds_text(k, b)));
            }
            let (l, h) = (plan.lower[j], plan.upper[j]);
            match init {
                Some((k, v)) if !(v >= l && v <= h) => {
                    return Err(ControlError {
                        flag: "--init",
                        value: pair_text(k, v),
                        reason: format!(
                            "outside the box [{}, {}] of {name}{place}",
                            end_text(l),
                            end_text(h)
                        ),
                    });
                }
                Some((k, v)) => {
                    plan.start[j] = v;
                    plan.initialised.push(j);
                    plan.given.push(("--init", pair_text(k, v)));
                }
                None => plan.start[j] = plan.start[j].max(l).min(h),
            }
        }
        Ok(plan)
    }

    /// The plan with `start` as the fit's own start of the parameters neither held nor
    /// given a start, moved into their box.
    pub fn with_start(mut self, start: &[f64]) -> Plan {
        for &j in &self.free {
            if !self.initialised.contains(&j) {
                self.start[j] = start[j].max(self.lower[j]).min(self.upper[j]);
            }
        }
        self
    }

    /// Whether no parameter is held.
    pub fn all_free(&self) -> bool {
        self.free.len() == self.pins.len()
    }

    /// Whether every parameter is held.
    pub fn all_held(&self) -> bool {
        self.free.is_empty()
    }

    /// The refusal of a posterior run whose parameters are all held.
    pub fn nothing_to_sample(&self) -> ControlError {
        let held: Vec<&str> = self
            .given
            .iter()
            .filter(|g| g.0 == "--fix")
            .map(|g| g.1.as_str())
            .collect();
        ControlError {
            flag: "--fix",
            value: held.join(" "),
            reason: "every parameter of the fit is held: nothing to sample (use --method lsq to \
                     score the values held)"
                .into(),
        }
    }

    /// The value held of every parameter (`None` where it is free).
    pub fn pins(&self) -> &[Option<f64>] {
        &self.pins
    }

    /// The full parameter vector of the free parameters `free`.
    pub fn expand(&self, free: &[f64]) -> Vec<f64> {
        expand(&self.pins, &self.free, free)
    }

    /// Whether parameter `j`'s start was given (held, or by `init`).
    pub fn start_given(&self, j: usize) -> bool {
        self.pins[j].is_some() || self.initialised.contains(&j)
    }

    /// Multiplies the start of parameter `j` by `factor`.
    pub fn scale_start(&mut self, j: usize, factor: f64) {
        self.start[j] *= factor;
    }

    /// The start of the free parameters.
    pub fn start(&self) -> Vec<f64> {
        self.free.iter().map(|&j| self.start[j]).collect()
    }

    /// The free entries of `full` (one per parameter).
    pub fn free_of<T: Clone>(&self, full: &[T]) -> Vec<T> {
        self.free.iter().map(|&j| full[j].clone()).collect()
    }

    /// `opts` for the free parameters: their box (with the bounds given), their typical
    /// magnitudes, and the covariance scaled as asked. Without held parameters or bounds the
    /// box is `opts`' own.
    pub fn options(&self, opts: LsqOptions) -> LsqOptions {
        let scale_covar = self.scale_covar || opts.scale_covar;
        if self.all_free() && !self.bounded {
            return LsqOptions {
                scale_covar,
                ..opts
            };
        }
        LsqOptions {
            lower: Some(self.free_of(&self.lower)),
            upper: Some(self.free_of(&self.upper)),
            typical: opts.typical.as_ref().map(|t| self.free_of(t)),
            scale_covar,
            ..opts
        }
    }

    /// `inner` (residuals or an ODR model of every parameter) in the free parameters alone.
    pub fn wrap<R>(&self, inner: R) -> Pinned<R> {
        Pinned {
            inner,
            pins: self.pins.clone(),
            free: self.free.clone(),
        }
    }

    /// Refuses the controls of this fit when the model has no value at its start (some point
    /// without a steady state at the values held or the start given). Nothing is refused for
    /// a fit without controls: its own start is its solver's business.
    pub fn check_start<R: Residuals>(&self, problem: &Pinned<R>) -> Result<(), ControlError> {
        let Some((flag, _)) = self.given.first() else {
            return Ok(());
        };
        let mut out = vec![0.0; problem.n_residuals()];
        let ok =
            problem.residuals(&self.start(), &mut out).is_ok() && out.iter().all(|r| r.is_finite());
        if ok {
            return Ok(());
        }
        let flag = self
            .given
            .iter()
            .find(|g| g.0 == "--init")
            .map_or(*flag, |g| g.0);
        Err(ControlError {
            flag,
            value: self
                .given
                .iter()
                .filter(|g| g.0 == flag)
                .map(|g| g.1.as_str())
                .collect::<Vec<_>>()
                .join(" "),
            reason: "some point has no value under the model at this start (no steady state, \
                     or a slope below the law's threshold); give other values"
                .into(),
        })
    }

    /// Puts the held parameters back into `summary` (a summary of the free parameters), each
    /// a row of its own at its place (from `specs`, at `level`), with NaN in the correlation
    /// matrix and a constant column in the draws; the statistics' note says which are held
    /// and, with σ given, that the covariance was scaled.
    pub fn restore(&self, summary: &mut FitResult, specs: &[ParamSpec], level: f64) {
        if summary.stats.scale_covar {
            summary.stats.note = super::summary::join(
                &summary.stats.note,
                "covariance scaled by reduced chi-square (scale_covar)",
            );
        }
        for (row, &j) in summary.params.iter_mut().zip(&self.free) {
            row.start = Some(self.start[j]);
        }
        if self.all_free() {
            return;
        }
        let old = summary.params.len();
        // New place of each old row: the free ones in order, then any rows after them.
        let held = self.pins.len() - self.free.len();
        let mut place: Vec<usize> = self.free.clone();
        place.extend((self.free.len()..old).map(|k| k + held));
        let total = old + held;
        let mut rows: Vec<Option<ParamRow>> = vec![None; total];
        for (k, row) in summary.params.drain(..).enumerate() {
            rows[place[k]] = Some(row);
        }
        let (fit, series) = (&summary.stats.fit, &summary.stats.series);
        for (j, pin) in self.pins.iter().enumerate() {
            if let Some(v) = pin {
                rows[j] = Some(held_row(&specs[j], *v, fit, series, level));
            }
        }
        summary.params = rows.into_iter().flatten().collect();
        if let Some(c) = summary.correlation.take() {
            let mut m = vec![vec![f64::NAN; total]; total];
            for (a, row) in c.iter().enumerate() {
                for (b, r) in row.iter().enumerate() {
                    m[place[a]][place[b]] = *r;
                }
            }
            summary.correlation = Some(m);
        }
        if let Some(d) = summary.draws.as_mut() {
            for draw in d.chains.iter_mut().flatten() {
                let mut full = vec![0.0; total];
                for (k, x) in draw.iter().enumerate() {
                    full[place[k]] = *x;
                }
                for (j, pin) in self.pins.iter().enumerate() {
                    if let Some(v) = pin {
                        full[j] = *v;
                    }
                }
                *draw = full;
            }
        }
        let names: Vec<String> = (0..self.pins.len())
            .filter(|&j| self.pins[j].is_some())
            .map(|j| {
                if self.series[j] == summary.stats.series {
                    specs[j].name.to_string()
                } else {
                    format!("{}[{}]", specs[j].name, clip(&self.series[j], ECHO_CHARS))
                }
            })
            .collect();
        let note = format!("held fixed: {}", names.join(", "));
        summary.stats.note = super::summary::join(&summary.stats.note, &note);
    }

    /// The fit `name` of `series` with every parameter held: the residuals of `problem` at the
    /// values held, scored as a law with nothing to fit (its χ², AIC and BIC; `infeasible`
    /// where some point has no value there), with a row per parameter.
    pub fn score<R: Residuals + ?Sized>(
        &self,
        problem: &R,
        (name, series): (&str, &str),
        specs: &[ParamSpec],
        level: f64,
        sigma: SigmaKind,
    ) -> FitResult {
        let full = self.expand(&[]);
        let mut r = vec![0.0; problem.n_residuals()];
        let feasible = problem.residuals(&full, &mut r).is_ok() && r.iter().all(|x| x.is_finite());
        let infeasible = (!feasible).then(|| {
            r.fill(f64::NAN);
            "some point has no value under the model at the values held".to_string()
        });
        let params = specs
            .iter()
            .zip(&full)
            .map(|(s, v)| held_row(s, *v, name, series, level))
            .collect();
        let names: Vec<&str> = specs.iter().map(|s| s.name).collect();
        let held = format!("every parameter held fixed ({}): scored", names.join(", "));
        let mut fit = FitResult::scored(
            (name.to_string(), series.to_string()),
            r,
            sigma,
            infeasible,
            params,
        );
        fit.stats.note = super::summary::join(&fit.stats.note, &held);
        fit
    }
}

/// The row of a parameter held at `value`.
fn held_row(spec: &ParamSpec, value: f64, fit: &str, series: &str, level: f64) -> ParamRow {
    ParamRow {
        fit: fit.to_string(),
        series: series.to_string(),
        parameter: spec.name.to_string(),
        value,
        stderr: None,
        level,
        cov: None,
        profile: None,
        unit: spec.unit,
        at_bound: false,
        paper_value: spec.paper_value,
        paper_source: spec.paper_source,
        note: "fixed: held at this value, not fitted.".into(),
        bounds: (value, value),
        lsq_value: Some(value),
        posterior: None,
        sensitivity: None,
        fixed: true,
        start: Some(value),
    }
}

/// The full vector of free values `free` (at the indices `at`) with the values `pins` held.
fn expand(pins: &[Option<f64>], at: &[usize], free: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = pins.iter().map(|p| p.unwrap_or(f64::NAN)).collect();
    for (&j, v) in at.iter().zip(free) {
        out[j] = *v;
    }
    out
}

/// Residuals or an ODR model of every parameter seen in the free parameters alone, the held
/// ones put in their place ([`Plan::wrap`]).
#[derive(Debug, Clone)]
pub(crate) struct Pinned<R> {
    inner: R,
    pins: Vec<Option<f64>>,
    free: Vec<usize>,
}

impl<R> Pinned<R> {
    /// Whether nothing is held (the problem is the inner one).
    fn identity(&self) -> bool {
        self.free.len() == self.pins.len()
    }
}

impl<R: Residuals> Residuals for Pinned<R> {
    fn n_params(&self) -> usize {
        self.free.len()
    }
    fn n_residuals(&self) -> usize {
        self.inner.n_residuals()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        if self.identity() {
            return self.inner.residuals(p, out);
        }
        self.inner
            .residuals(&expand(&self.pins, &self.free, p), out)
    }
    fn jacobian(&self, p: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        if self.identity() {
            return self.inner.jacobian(p, out);
        }
        let m = self.inner.n_residuals();
        let mut full = Mat::<f64>::zeros(m, self.pins.len());
        if let Err(e) = self
            .inner
            .jacobian(&expand(&self.pins, &self.free, p), full.as_mut())?
        {
            return Some(Err(e));
        }
        for (c, &j) in self.free.iter().enumerate() {
            for i in 0..m {
                out[(i, c)] = full[(i, j)];
            }
        }
        Some(Ok(()))
    }
}

impl<M: OdrModel> OdrModel for Pinned<M> {
    fn n_params(&self) -> usize {
        self.free.len()
    }
    fn n_points(&self) -> usize {
        self.inner.n_points()
    }
    fn value(&self, i: usize, x: f64, p: &[f64]) -> Result<f64, Infeasible> {
        if self.identity() {
            return self.inner.value(i, x, p);
        }
        self.inner.value(i, x, &expand(&self.pins, &self.free, p))
    }
    fn derivatives(
        &self,
        i: usize,
        x: f64,
        p: &[f64],
        grad: &mut [f64],
    ) -> Option<Result<f64, Infeasible>> {
        if self.identity() {
            return self.inner.derivatives(i, x, p, grad);
        }
        let mut full = vec![0.0; self.pins.len()];
        let r = self
            .inner
            .derivatives(i, x, &expand(&self.pins, &self.free, p), &mut full)?;
        for (c, &j) in self.free.iter().enumerate() {
            grad[c] = full[j];
        }
        Some(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_split_into_name_and_series() {
        assert_eq!(split_key("a2"), ("a2", None));
        assert_eq!(split_key("a2[0.8]"), ("a2", Some("0.8")));
        assert_eq!(split_key("K[s[1]]"), ("K", Some("s[1]")));
        assert_eq!(split_key("[x]"), ("[x]", None));
    }

    #[test]
    fn the_series_control_wins_and_the_last_of_each() {
        let fix = vec![
            ("mu".to_string(), 0.1),
            ("mu[b]".to_string(), 0.2),
            ("mu".to_string(), 0.3),
        ];
        assert_eq!(Controls::find(&fix, "mu", "a"), Some(("mu", 0.3)));
        assert_eq!(Controls::find(&fix, "mu", "b"), Some(("mu[b]", 0.2)));
        assert_eq!(Controls::find(&fix, "lambda", "b"), None);
    }

    #[test]
    fn plans_hold_bound_and_start() {
        let fix = vec![("a2".to_string(), 0.0)];
        let bounds = vec![("a3".to_string(), (0.5, 2.0))];
        let c = Controls {
            fix: &fix,
            bounds: &bounds,
            ..Controls::default()
        };
        let p = Parameters {
            names: &["a1", "a2", "a3"],
            series: &["s", "s", "s"],
            lower: &[0.0; 3],
            upper: &[f64::INFINITY; 3],
            start: &[0.1, 5.0, 3.0],
        };
        let plan = Plan::new(&c, p).unwrap();
        assert_eq!(plan.start(), vec![0.1, 2.0]);
        assert_eq!(plan.expand(&[0.2, 1.0]), vec![0.2, 0.0, 1.0]);
        let o = plan.options(LsqOptions::default());
        assert_eq!(o.lower, Some(vec![0.0, 0.5]));
        assert_eq!(o.upper, Some(vec![f64::INFINITY, 2.0]));
        // A held value outside the box, bounds missing it, a start outside them.
        let bad = |fix: &[(String, f64)], init: &[(String, f64)], b: &[(String, (f64, f64))]| {
            let c = Controls {
                fix,
                init,
                bounds: b,
                scale_covar: false,
            };
            let p = Parameters {
                names: &["a1", "a2", "a3"],
                series: &["s", "s", "s"],
                lower: &[0.0; 3],
                upper: &[f64::INFINITY; 3],
                start: &[0.1, 5.0, 3.0],
            };
            Plan::new(&c, p).unwrap_err()
        };
        let e = bad(&[("a2".into(), -1.0)], &[], &[]);
        assert_eq!((e.flag, e.value.as_str()), ("--fix", "a2=-1"));
        let e = bad(&[], &[], &[("a1".into(), (-3.0, -1.0))]);
        assert_eq!(e.flag, "--bounds");
        let e = bad(&[], &[("a3".into(), 3.0)], &[("a3".into(), (0.5, 2.0))]);
        assert_eq!((e.flag, e.value.as_str()), ("--init", "a3=3"));
        let e = bad(&[("a2".into(), 1.0)], &[("a2".into(), 3.0)], &[]);
        assert_eq!(e.flag, "--fix");
    }

    #[test]
    fn unknown_names_are_refused_with_the_fit_s_names() {
        let fix = vec![("a4".to_string(), 0.0)];
        let c = Controls {
            fix: &fix,
            ..Controls::default()
        };
        let e = c.check(&["a1", "a2", "a3"], &[]).unwrap_err();
        assert!(e.reason.contains("expected one of a1, a2, a3"), "{e}");
        let fix = vec![("a2[x]".to_string(), 0.0)];
        let c = Controls {
            fix: &fix,
            ..Controls::default()
        };
        let e = c.check(&["a1", "a2", "a3"], &["0.8".into()]).unwrap_err();
        assert!(e.reason.contains("no series 'x'"), "{e}");
    }
}
