//! Bayesian posteriors of least-squares problems: any [`Residuals`] problem turned into a log
//! density (Gaussian errors, optional error scale, priors by parameter), sampled by the
//! ensemble sampler of [`super::mcmc`] — what lmfit's `emcee` method does for its models.
//!
//! Likelihood: independent Gaussian errors on the weighted residuals r_i:
//! - σ given: ln L = −χ²/2;
//! - with a scale s (parameter `sigma_scale`) multiplying every σ: ln L = −m ln s − χ²/(2s²).
//!
//! Priors are per parameter ([`Prior`]); the support is the parameter box intersected with the
//! set where the residuals are feasible: the log density is −∞ wherever they are
//! [`Infeasible`](super::Infeasible), never NaN. Parameters whose box is [0, ∞) (and the
//! scale) are sampled in ln x.

use super::mcmc::{LogDensity, McmcOptions};
use super::Residuals;
use crate::numfmt::fmt_f64;
use crate::progress::{Progress, ProgressEvent, Tally};
use statrs::distribution::{Continuous, LogNormal, Normal, Uniform};
use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Name of the error-scale parameter.
pub(crate) const SCALE_NAME: &str = "sigma_scale";

/// A prior density of one parameter, parsed from `flat`, `jeffreys`, `uniform(a,b)`,
/// `normal(mean,sd)`, `lognormal(mu,sigma)` (of ln x) or `halfnormal(scale)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    text: String,
    kind: PriorKind,
}

#[derive(Debug, Clone, PartialEq)]
enum PriorKind {
    Flat,
    Jeffreys,
    Uniform(Uniform),
    Normal(Normal),
    LogNormal(LogNormal),
    HalfNormal(Normal),
}

impl Prior {
    /// The flat (improper uniform) prior: only the support restricts the parameter.
    pub fn flat() -> Self {
        Prior {
            text: "flat".into(),
            kind: PriorKind::Flat,
        }
    }

    /// The half-normal prior of scale `scale` > 0 on [0, ∞).
    ///
    /// # Panics
    /// If `scale` is not finite and positive (a programming error: user input goes through
    /// [`FromStr`]).
    pub fn half_normal(scale: f64) -> Self {
        let d = Normal::new(0.0, scale).expect("half-normal scale must be finite and > 0");
        Prior {
            text: format!("halfnormal({})", fmt_f64(scale)),
            kind: PriorKind::HalfNormal(d),
        }
    }

    /// Jeffreys' prior of a scale, ∝ 1/s on s > 0.
    pub fn jeffreys() -> Self {
        Prior {
            text: "jeffreys".into(),
            kind: PriorKind::Jeffreys,
        }
    }

    /// ln p(x) up to a constant; −∞ outside the prior's support.
    pub fn ln_pdf(&self, x: f64) -> f64 {
        match &self.kind {
            PriorKind::Flat => 0.0,
            PriorKind::Jeffreys => {
                if x > 0.0 {
                    -x.ln()
                } else {
                    f64::NEG_INFINITY
                }
            }
            PriorKind::Uniform(d) => d.ln_pdf(x),
            PriorKind::Normal(d) => d.ln_pdf(x),
            PriorKind::LogNormal(d) => {
                if x > 0.0 {
                    d.ln_pdf(x)
                } else {
                    f64::NEG_INFINITY
                }
            }
            PriorKind::HalfNormal(d) => {
                if x >= 0.0 {
                    d.ln_pdf(x) + std::f64::consts::LN_2
                } else {
                    f64::NEG_INFINITY
                }
            }
        }
    }
}

impl Prior {
    /// The interval outside which the prior density is zero.
    pub fn support(&self) -> (f64, f64) {
        match &self.kind {
            PriorKind::Uniform(d) => (d.min(), d.max()),
            PriorKind::Jeffreys | PriorKind::LogNormal(_) | PriorKind::HalfNormal(_) => {
                (0.0, f64::INFINITY)
            }
            PriorKind::Flat | PriorKind::Normal(_) => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
}

impl Prior {
    /// One draw from the prior given a standard normal `z` and a uniform `u` on [0, 1), or
    /// `None` for the improper priors (flat, jeffreys), which cannot be drawn from.
    pub(crate) fn draw(&self, z: f64, u: f64) -> Option<f64> {
        use statrs::statistics::Distribution as _;
        match &self.kind {
            PriorKind::Flat | PriorKind::Jeffreys => None,
            PriorKind::Uniform(d) => Some(d.min() + u * (d.max() - d.min())),
            PriorKind::Normal(d) => Some(d.mean()? + d.std_dev()? * z),
            PriorKind::LogNormal(d) => Some((d.location() + d.scale() * z).exp()),
            PriorKind::HalfNormal(d) => Some((d.std_dev()? * z).abs()),
        }
    }
}

impl fmt::Display for Prior {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl FromStr for Prior {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let t: String = s.chars().filter(|c| !c.is_whitespace()).collect();
        let lower = t.to_ascii_lowercase();
        let expected = "expected flat, jeffreys, uniform(a,b), normal(mean,sd), \
                        lognormal(mu,sigma) or halfnormal(scale)";
        let (name, args) = match lower.split_once('(') {
            None => (lower.as_str(), Vec::new()),
            Some((n, rest)) => {
                let inner = rest
                    .strip_suffix(')')
                    .ok_or_else(|| format!("'{s}': missing ')'; {expected}"))?;
                let args = inner
                    .split(',')
                    .map(|a| {
                        a.parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| format!("'{s}': '{a}' is not a finite number"))
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                (n, args)
            }
        };
        let want = |k: usize| {
            if args.len() == k {
                Ok(())
            } else {
                Err(format!(
                    "'{s}': {name} takes {k} number(s), {} given",
                    args.len()
                ))
            }
        };
        let kind = match name {
            "flat" => {
                want(0)?;
                PriorKind::Flat
            }
            "jeffreys" => {
                want(0)?;
                PriorKind::Jeffreys
            }
            "uniform" => {
                want(2)?;
                if !(args[0] < args[1]) {
                    return Err(format!("'{s}': uniform(a,b) needs a < b"));
                }
                PriorKind::Uniform(
                    Uniform::new(args[0], args[1]).map_err(|e| format!("'{s}': {e}"))?,
                )
            }
            "normal" => {
                want(2)?;
                PriorKind::Normal(Normal::new(args[0], args[1]).map_err(|e| format!("'{s}': {e}"))?)
            }
            "lognormal" => {
                want(2)?;
                PriorKind::LogNormal(
                    LogNormal::new(args[0], args[1]).map_err(|e| format!("'{s}': {e}"))?,
                )
            }
            "halfnormal" => {
                want(1)?;
                PriorKind::HalfNormal(Normal::new(0.0, args[0]).map_err(|e| format!("'{s}': {e}"))?)
            }
            _ => return Err(format!("'{s}': unknown prior; {expected}")),
        };
        Ok(Prior { text: t, kind })
    }
}

/// How a fit's parameters are estimated.
#[derive(Debug, Clone)]
pub enum Method {
    /// Least squares with covariance intervals, and profile-likelihood ones when `profile`.
    Lsq {
        /// Compute the profile-likelihood intervals.
        profile: bool,
        /// Raised to stop every solver run of the fit ([`LsqOptions::stop`](super::LsqOptions)).
        stop: Option<Arc<AtomicBool>>,
        /// Counts the residual and Jacobian evaluations of every solver run of the fit, profiles
        /// included ([`LsqOptions::progress`](super::LsqOptions)).
        progress: Option<Tally>,
        /// Scale the covariance by the reduced χ² even with σ given, as lmfit's
        /// `scale_covar=True` ([`LsqOptions::scale_covar`](super::LsqOptions)).
        scale_covar: bool,
        /// Parameters held at a value, by name: `NAME` holds it in every fit that has it
        /// (every series), `NAME[SERIES]` in the fit of that series only. A held parameter is
        /// not fitted: no standard error or interval, no degree of freedom.
        fix: Vec<(String, f64)>,
        /// Starting values by name (`NAME` or `NAME[SERIES]`), replacing the fit's own start;
        /// each must lie in the parameter's box.
        init: Vec<(String, f64)>,
        /// Bounds (lower, upper) by name (`NAME` or `NAME[SERIES]`), intersected with the
        /// parameter's box.
        bounds: Vec<(String, (f64, f64))>,
    },
    /// Posterior sampling, started from the least-squares optimum (its stop flag,
    /// [`McmcOptions::stop`], stops the least-squares start as well).
    Mcmc(Box<McmcSettings>),
}

impl Method {
    /// Least squares, with profile-likelihood intervals when `profile`, never stopped.
    pub fn lsq(profile: bool) -> Self {
        Method::Lsq {
            profile,
            stop: None,
            progress: None,
            scale_covar: false,
            fix: Vec::new(),
            init: Vec::new(),
            bounds: Vec::new(),
        }
    }

    /// The same method, its least-squares runs counted by `progress` (a posterior run reports
    /// its sampler's steps through [`McmcSettings::progress`] instead, and is returned as it
    /// is).
    pub fn with_progress(self, progress: Option<Tally>) -> Self {
        match self {
            Method::Lsq {
                profile,
                stop,
                scale_covar,
                fix,
                init,
                bounds,
                ..
            } => Method::Lsq {
                profile,
                stop,
                progress,
                scale_covar,
                fix,
                init,
                bounds,
            },
            m => m,
        }
    }

    /// Where the fit's least-squares runs count their evaluations, if anywhere
    /// ([`LsqOptions::progress`](super::LsqOptions)).
    pub fn progress(&self) -> Option<&Tally> {
        match self {
            Method::Lsq { progress, .. } => progress.as_ref(),
            Method::Mcmc(_) => None,
        }
    }

    /// The flag that stops the fit's solvers and sampler, if any.
    pub fn stop(&self) -> Option<&Arc<AtomicBool>> {
        match self {
            Method::Lsq { stop, .. } => stop.as_ref(),
            Method::Mcmc(s) => s.options.stop.as_ref(),
        }
    }

    /// True once the stop flag was raised.
    pub fn stopped(&self) -> bool {
        self.stop().is_some_and(|s| s.load(Ordering::SeqCst))
    }
}

/// Settings of a posterior run.
#[derive(Debug, Clone, Default)]
pub struct McmcSettings {
    /// Sampler options (its `level` is replaced by the fit's level).
    pub options: McmcOptions,
    /// Priors by parameter name; parameters not named get the defaults (module docs).
    pub priors: Vec<(String, Prior)>,
    /// Sample the error scale `sigma_scale` even when σ is given.
    pub fit_scatter: bool,
    /// Where to report the sampler's progress (steps run), if anywhere.
    pub progress: Option<Progress>,
    /// Parameters held at a value, as [`Method::Lsq`]'s `fix`: not sampled.
    pub fix: Vec<(String, f64)>,
    /// Starting values of the least-squares optimum the sampler starts from, as
    /// [`Method::Lsq`]'s `init`.
    pub init: Vec<(String, f64)>,
    /// Bounds by name, as [`Method::Lsq`]'s `bounds`: they cut the support of the priors.
    pub bounds: Vec<(String, (f64, f64))>,
}

impl McmcSettings {
    /// The name of the error-scale parameter (sampled when σ is not given or
    /// [`McmcSettings::fit_scatter`] asks for it); a prior may be given to it by this name.
    pub const SCALE_NAME: &'static str = SCALE_NAME;

    /// The default settings (flat priors on the parameter boxes, R̂ ≤ 1.01 and ESS ≥ 1000 or
    /// 100 000 steps) with the sampler seeded by `seed`: the same seed gives the same draws
    /// whatever the number of threads.
    pub fn seeded(seed: u64) -> Self {
        let mut s = Self::default();
        s.options.seed = seed;
        s
    }

    /// The prior given for parameter `name` (the last one given wins), if any.
    pub fn prior(&self, name: &str) -> Option<&Prior> {
        self.priors.iter().rev().find(|p| p.0 == name).map(|p| &p.1)
    }
}

/// The kept draws of one posterior run.
#[derive(Debug, Clone, PartialEq)]
pub struct Draws {
    /// `[walker][kept step][parameter]`, parameters in the order of the summary's rows.
    pub chains: Vec<Vec<Vec<f64>>>,
    /// Log posterior (up to a constant) of every kept draw, `[walker][kept step]`.
    pub log_posterior: Vec<Vec<f64>>,
    /// Steps discarded as burn-in.
    pub burn_in: usize,
    /// Thinning: one step kept in `thin`.
    pub thin: usize,
    /// Whether the run was interrupted (stop flag raised).
    pub interrupted: bool,
}

impl Draws {
    /// The step number (counted from 1, burn-in included) of kept draw `k`.
    pub fn step(&self, k: usize) -> usize {
        self.burn_in + (k + 1) * self.thin
    }

    /// Number of draws kept (all walkers).
    pub fn len(&self) -> usize {
        self.chains.iter().map(Vec::len).sum()
    }

    /// Whether no draw is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Thins the kept draws further to at most `max_draws` in all (at least one step per
    /// walker): every walker keeps its k-th, 2k-th, … kept step, k the smallest stride that
    /// fits, and `thin` is multiplied by k, so that [`Self::step`] still numbers them. A
    /// summary computed before thinning is unchanged; the draws left are for what needs only
    /// a sample of the posterior (plots, predictive bands).
    pub fn thin_to(&mut self, max_draws: usize) {
        let walkers = self.chains.len().max(1);
        let per_walker = (max_draws / walkers).max(1);
        let kept = self.chains.iter().map(Vec::len).max().unwrap_or(0);
        if kept <= per_walker {
            return;
        }
        let k = kept.div_ceil(per_walker);
        for c in self.chains.iter_mut() {
            *c = std::mem::take(c)
                .into_iter()
                .skip(k - 1)
                .step_by(k)
                .collect();
        }
        for l in self.log_posterior.iter_mut() {
            *l = std::mem::take(l)
                .into_iter()
                .skip(k - 1)
                .step_by(k)
                .collect();
        }
        self.thin *= k;
    }
}

/// A change of the coordinates in which a problem's parameters are sampled: a smooth bijection
/// y ↦ x = T(y) from an open set of ℝⁿ onto the parameters, chosen so that the posterior is
/// closer to Gaussian in y than in x (a ridge of x straightened). The posterior density in y
/// is p(T(y)) |det ∂T/∂y|, so that priors stated on x keep their meaning ([`Posterior`]).
pub trait Reparameterisation: Sync {
    /// The parameters x = T(y), written to `x`, and ln |det ∂T/∂y| at y; `None` where y is
    /// outside the domain of T (the posterior density is zero there).
    fn params(&self, y: &[f64], x: &mut [f64]) -> Option<f64>;

    /// The coordinates y = T⁻¹(x), `None` where x is outside the image of T.
    fn coordinates(&self, x: &[f64]) -> Option<Vec<f64>>;

    /// The coordinates to start sampling from, given a start x in parameters (a least-squares
    /// optimum, which may sit on a boundary where the coordinates are infinite): by default
    /// [`Self::coordinates`].
    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.coordinates(x)
    }
}

/// The log posterior of a least-squares problem (module docs), over sampling coordinates y.
/// By default a parameter whose box is [0, ∞), and the scale, is sampled as y = ln x (the log
/// density then gains the Jacobian term ln x = y), every other parameter as itself: long right
/// tails of positive parameters (the scale) become short in ln x, where the ensemble moves mix
/// far better. With a [`Reparameterisation`] ([`Posterior::with_reparameterisation`]) the
/// problem's parameters are sampled in its coordinates instead (the scale stays in ln s), and
/// the log density gains its ln |det ∂x/∂y|.
///
/// Whatever the coordinates, the sampler records the parameters x (and the scale s): the
/// draws, and the R̂ and ESS that decide convergence, are those of the reported parameters
/// ([`LogDensity::observe`]).
pub struct Posterior<'a, R: ?Sized> {
    problem: &'a R,
    lower: Vec<f64>,
    upper: Vec<f64>,
    priors: Vec<Prior>,
    scale: Option<Prior>,
    log: Vec<bool>,
    transform: Option<&'a dyn Reparameterisation>,
}

impl<'a, R: Residuals + Sync + ?Sized> Posterior<'a, R> {
    /// The posterior of `problem` with parameters in the box [`lower`, `upper`], `priors` per
    /// parameter, and, with `scale`, the error scale appended as a last parameter with that
    /// prior.
    pub fn new(
        problem: &'a R,
        lower: Vec<f64>,
        upper: Vec<f64>,
        priors: Vec<Prior>,
        scale: Option<Prior>,
    ) -> Self {
        let log = lower
            .iter()
            .zip(&upper)
            .map(|(&l, &u)| l == 0.0 && u == f64::INFINITY)
            .chain(scale.iter().map(|_| true))
            .collect();
        Posterior {
            problem,
            lower,
            upper,
            priors,
            scale,
            log,
            transform: None,
        }
    }

    /// The same posterior with the problem's parameters sampled in the coordinates of
    /// `transform` (the scale, if any, stays in ln s).
    pub fn with_reparameterisation(mut self, transform: &'a dyn Reparameterisation) -> Self {
        let n = self.problem.n_params();
        self.log[..n].iter_mut().for_each(|l| *l = false);
        self.transform = Some(transform);
        self
    }

    /// The reparameterisation in use, if any.
    pub fn reparameterisation(&self) -> Option<&'a dyn Reparameterisation> {
        self.transform
    }

    /// Whether coordinate `j` is sampled as ln x (never for the parameters of a
    /// reparameterised posterior).
    pub fn is_log(&self, j: usize) -> bool {
        self.log[j]
    }

    /// Parameters x from sampling coordinates y, with ln |det ∂x/∂y|; `None` outside the
    /// domain of the reparameterisation.
    fn params_and_jacobian(&self, y: &[f64]) -> Option<(Vec<f64>, f64)> {
        let n = self.problem.n_params();
        let mut x: Vec<f64> = y
            .iter()
            .zip(&self.log)
            .map(|(&v, &l)| if l { v.exp() } else { v })
            .collect();
        // Jacobian of x = e^y: ln |dx/dy| = y.
        let mut log_j: f64 = y
            .iter()
            .zip(&self.log)
            .filter(|(_, &l)| l)
            .map(|(&v, _)| v)
            .sum();
        if let Some(t) = self.transform {
            log_j += t.params(&y[..n], &mut x[..n])?;
        }
        Some((x, log_j))
    }

    /// Parameters x from sampling coordinates y (NaN where y is outside the domain of the
    /// reparameterisation).
    pub fn to_params(&self, y: &[f64]) -> Vec<f64> {
        self.params_and_jacobian(y)
            .map(|(x, _)| x)
            .unwrap_or_else(|| vec![f64::NAN; y.len()])
    }

    /// Sampling coordinates y from parameters x (x > 0 where sampled as ln x); `None` where
    /// x is outside the image of the reparameterisation.
    pub fn to_coordinates(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.coordinates_with(x, |t, p| t.coordinates(p))
    }

    /// Sampling coordinates to start from, given a start x (see
    /// [`Reparameterisation::start`]); without a reparameterisation, [`Self::to_coordinates`].
    pub fn start_coordinates(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.coordinates_with(x, |t, p| t.start(p))
    }

    fn coordinates_with(
        &self,
        x: &[f64],
        f: impl Fn(&dyn Reparameterisation, &[f64]) -> Option<Vec<f64>>,
    ) -> Option<Vec<f64>> {
        let n = self.problem.n_params();
        let mut y: Vec<f64> = x
            .iter()
            .zip(&self.log)
            .map(|(&v, &l)| if l { v.ln() } else { v })
            .collect();
        if let Some(t) = self.transform {
            let c = f(t, &x[..n])?;
            y[..n].copy_from_slice(&c);
        }
        Some(y)
    }
}

impl<R: Residuals + Sync + ?Sized> LogDensity for Posterior<'_, R> {
    fn dim(&self) -> usize {
        self.problem.n_params() + usize::from(self.scale.is_some())
    }

    fn log_density(&self, y: &[f64]) -> f64 {
        let n = self.problem.n_params();
        let Some((x, mut lp)) = self.params_and_jacobian(y) else {
            return f64::NEG_INFINITY;
        };
        let p = &x[..n];
        for (((&x, &lo), &hi), prior) in
            p.iter().zip(&self.lower).zip(&self.upper).zip(&self.priors)
        {
            if !(x >= lo && x <= hi) {
                return f64::NEG_INFINITY;
            }
            lp += prior.ln_pdf(x);
        }
        let s = match &self.scale {
            Some(prior) => {
                let s = x[n];
                if !(s > 0.0 && s.is_finite()) {
                    return f64::NEG_INFINITY;
                }
                lp += prior.ln_pdf(s);
                Some(s)
            }
            None => None,
        };
        if lp == f64::NEG_INFINITY || lp.is_nan() {
            return f64::NEG_INFINITY;
        }
        let m = self.problem.n_residuals();
        let mut r = vec![0.0; m];
        if self.problem.residuals(p, &mut r).is_err() {
            return f64::NEG_INFINITY;
        }
        let chi2: f64 = r.iter().map(|v| v * v).sum();
        if !chi2.is_finite() {
            return f64::NEG_INFINITY;
        }
        match s {
            None => lp - 0.5 * chi2,
            Some(s) => lp - m as f64 * s.ln() - 0.5 * chi2 / (s * s),
        }
    }

    /// The parameters (and the scale) at y: what the draws record.
    fn observe(&self, y: &[f64]) -> Vec<f64> {
        self.to_params(y)
    }
}

/// A progress sink shared by fits that run concurrently: each fit gets its own sink
/// ([`Self::method`]), and only the fit holding the shared one reaches it. A fit that starts
/// while the sink is free takes it; once its holder finishes, the next fit still running to
/// report takes it over, its start repeated first.
pub(crate) struct SharedProgress<'a> {
    method: &'a Method,
    holder: Arc<Mutex<Option<usize>>>,
    next: AtomicUsize,
}

impl<'a> SharedProgress<'a> {
    pub(crate) fn of(method: &'a Method) -> Self {
        SharedProgress {
            method,
            holder: Arc::new(Mutex::new(None)),
            next: AtomicUsize::new(0),
        }
    }

    /// The method for one more fit: `method` itself, with its own sink under MCMC.
    pub(crate) fn method(&self) -> Method {
        let Method::Mcmc(settings) = self.method else {
            return self.method.clone();
        };
        let Some(outer) = settings.progress.clone() else {
            return self.method.clone();
        };
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let holder = Arc::clone(&self.holder);
        // This fit's start (label, total, check interval) while it runs, to repeat on a
        // take-over.
        let started: Mutex<Option<(String, u64, u64)>> = Mutex::new(None);
        let mut s = settings.clone();
        s.progress = Some(Progress::new(move |e| {
            let Ok(mut h) = holder.lock() else { return };
            let Ok(mut mine) = started.lock() else { return };
            match e {
                ProgressEvent::Start {
                    label,
                    total,
                    check_every,
                } => {
                    *mine = Some((label.to_string(), total, check_every));
                    if h.is_none() {
                        *h = Some(id);
                        outer.report(e);
                    }
                }
                ProgressEvent::Position(_) => {
                    if h.is_none() {
                        if let Some((label, total, check_every)) = mine.as_ref() {
                            *h = Some(id);
                            outer.report(ProgressEvent::Start {
                                label,
                                total: *total,
                                check_every: *check_every,
                            });
                        }
                    }
                    if *h == Some(id) {
                        outer.report(e);
                    }
                }
                ProgressEvent::Finish => {
                    *mine = None;
                    if *h == Some(id) {
                        *h = None;
                        outer.report(e);
                    }
                }
            }
        }));
        Method::Mcmc(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two fits share one sink: the first to start holds it; the second, started meanwhile,
    /// takes it over at its next position once the first has finished, its start repeated.
    #[test]
    fn a_shared_sink_passes_to_the_next_running_fit() {
        let seen = Arc::new(Mutex::new(Vec::<String>::new()));
        let log = Arc::clone(&seen);
        let mut settings = McmcSettings::seeded(1);
        settings.progress = Some(Progress::new(move |e| {
            let line = match e {
                ProgressEvent::Start { label, total, .. } => format!("start {label} {total}"),
                ProgressEvent::Position(p) => format!("at {p}"),
                ProgressEvent::Finish => "finish".to_string(),
            };
            log.lock().unwrap().push(line);
        }));
        let method = Method::Mcmc(Box::new(settings));
        let shared = SharedProgress::of(&method);
        let sink = |m: &Method| match m {
            Method::Mcmc(s) => s.progress.clone().unwrap(),
            Method::Lsq { .. } => unreachable!(),
        };
        let (a, b) = (sink(&shared.method()), sink(&shared.method()));
        let start = |p: &Progress, label: &str| {
            p.report(ProgressEvent::Start {
                label,
                total: 100,
                check_every: 10,
            })
        };
        start(&a, "a");
        start(&b, "b");
        a.report(ProgressEvent::Position(5));
        b.report(ProgressEvent::Position(7));
        a.report(ProgressEvent::Finish);
        b.report(ProgressEvent::Position(9));
        b.report(ProgressEvent::Finish);
        a.report(ProgressEvent::Position(11));
        assert_eq!(
            *seen.lock().unwrap(),
            [
                "start a 100",
                "at 5",
                "finish",
                "start b 100",
                "at 9",
                "finish"
            ]
        );
    }
}
