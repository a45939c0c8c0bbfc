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
use crate::progress::{Progress, Tally};
use statrs::distribution::{Continuous, LogNormal, Normal, Uniform};
use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Name of the error-scale parameter.
pub const SCALE_NAME: &str = "sigma_scale";

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
        }
    }

    /// The same method, its least-squares runs counted by `progress` (a posterior run reports
    /// its sampler's steps through [`McmcSettings::progress`] instead, and is returned as it
    /// is).
    pub fn with_progress(self, progress: Option<Tally>) -> Self {
        match self {
            Method::Lsq { profile, stop, .. } => Method::Lsq {
                profile,
                stop,
                progress,
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
}

impl McmcSettings {
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
}

/// The log posterior of a least-squares problem (module docs), over sampling coordinates y:
/// a parameter whose box is [0, ∞), and the scale, is sampled as y = ln x (the log density
/// then gains the Jacobian term ln x = y), every other parameter as itself. Long right tails
/// of positive parameters (Jaeger's a2, the scale) become short in ln x, where the ensemble
/// moves mix far better.
pub struct Posterior<'a, R: ?Sized> {
    problem: &'a R,
    lower: Vec<f64>,
    upper: Vec<f64>,
    priors: Vec<Prior>,
    scale: Option<Prior>,
    log: Vec<bool>,
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
        }
    }

    /// Whether coordinate `j` is sampled as ln x.
    pub fn is_log(&self, j: usize) -> bool {
        self.log[j]
    }

    /// Parameters x from sampling coordinates y.
    pub fn to_params(&self, y: &[f64]) -> Vec<f64> {
        y.iter()
            .zip(&self.log)
            .map(|(&v, &l)| if l { v.exp() } else { v })
            .collect()
    }

    /// Sampling coordinates y from parameters x (x > 0 where sampled as ln x).
    pub fn to_coordinates(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(&self.log)
            .map(|(&v, &l)| if l { v.ln() } else { v })
            .collect()
    }
}

impl<R: Residuals + Sync + ?Sized> LogDensity for Posterior<'_, R> {
    fn dim(&self) -> usize {
        self.problem.n_params() + usize::from(self.scale.is_some())
    }

    fn log_density(&self, y: &[f64]) -> f64 {
        let n = self.problem.n_params();
        // Jacobian of x = e^y: ln |dx/dy| = y.
        let mut lp: f64 = y
            .iter()
            .zip(&self.log)
            .filter(|(_, &l)| l)
            .map(|(&v, _)| v)
            .sum();
        let x = self.to_params(y);
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
}
