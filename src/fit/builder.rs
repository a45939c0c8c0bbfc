//! Builders for the fits across series: choose the model, the law, the method (least squares
//! or a posterior run) and the confidence level, then [`fit`](KLawFitter::fit) a
//! [`Dataset`]. Each returns [`FitResult`]s that print as a fit report.
//!
//! ```
//! use fitbead::prelude::*;
//! let data = Dataset::default_data();
//! let fit = KLawFitter::new(Model::Stick, KLaw::C).fit(&data).unwrap();
//! let c = fit.param("c").unwrap();
//! assert!(c.stderr.unwrap() > 0.0 && fit.converged());
//! ```

use super::data::Dataset;
use super::error::FitError;
use super::jaeger::fit_jaeger_with;
use super::jan::fit_jan_with;
use super::klaw::{fit_law_with, KLaw};
use super::summary::FitResult;
use super::summary::FitSet;
use crate::inverse::posterior::{McmcSettings, Method};
use crate::inverse::DEFAULT_LEVEL;
use crate::models::{JaegerBranch, Model};

/// The method, level and parameter controls every builder shares.
#[derive(Debug, Clone)]
struct Common {
    level: f64,
    method: Method,
    fix: Vec<(String, f64)>,
    init: Vec<(String, f64)>,
    bounds: Vec<(String, (f64, f64))>,
    scale_covar: bool,
}

impl Default for Common {
    fn default() -> Self {
        Common {
            level: DEFAULT_LEVEL,
            method: Method::lsq(true),
            fix: Vec::new(),
            init: Vec::new(),
            bounds: Vec::new(),
            scale_covar: false,
        }
    }
}

impl Common {
    /// The method with the controls set on the builder.
    fn method(&self) -> Method {
        let mut m = self.method.clone();
        match &mut m {
            Method::Lsq {
                fix,
                init,
                bounds,
                scale_covar,
                ..
            } => {
                fix.clone_from(&self.fix);
                init.clone_from(&self.init);
                bounds.clone_from(&self.bounds);
                *scale_covar = self.scale_covar;
            }
            Method::Mcmc(s) => {
                s.fix.clone_from(&self.fix);
                s.init.clone_from(&self.init);
                s.bounds.clone_from(&self.bounds);
            }
        }
        m
    }

    /// Refuses a level outside (0, 1), a method that cannot fit `data`, a control of a
    /// parameter not among `params` (or of a series not in `data`), and the covariance
    /// scaled under a posterior run.
    fn check(&self, data: &Dataset, params: &[&str]) -> Result<Method, FitError> {
        if !(self.level > 0.0 && self.level < 1.0) {
            return Err(FitError::Level(self.level));
        }
        if self.scale_covar && matches!(self.method, Method::Mcmc(_)) {
            return Err(FitError::Method(
                "scale_covar applies to least squares only".into(),
            ));
        }
        let method = self.method();
        super::controls::Controls::of(&method).check(params, &data.labels)?;
        match super::slopes::unsupported(&method, data) {
            Some(why) => Err(FitError::Method(why)),
            None => Ok(method),
        }
    }
}

macro_rules! common_setters {
    () => {
        /// Confidence level of the intervals, in (0, 1) (default 0.95).
        pub fn level(mut self, level: f64) -> Self {
            self.common.level = level;
            self
        }

        /// Least squares with covariance intervals, and profile-likelihood intervals when
        /// `profile` (the default).
        pub fn least_squares(mut self, profile: bool) -> Self {
            self.common.method = Method::lsq(profile);
            self
        }

        /// A posterior run (started from the least-squares optimum) instead of least squares.
        pub fn mcmc(mut self, settings: McmcSettings) -> Self {
            self.common.method = Method::Mcmc(Box::new(settings));
            self
        }

        /// Holds parameter `name` at `value` (lmfit's `vary=False`): `NAME` in every fit that
        /// has it, `NAME[SERIES]` in that series' fit alone. It is not fitted: no standard
        /// error or interval, no degree of freedom.
        pub fn fix(mut self, name: &str, value: f64) -> Self {
            self.common.fix.push((name.to_string(), value));
            self
        }

        /// Starts parameter `name` (`NAME` or `NAME[SERIES]`) at `value` instead of the fit's
        /// own start; the value must lie in the parameter's box.
        pub fn init(mut self, name: &str, value: f64) -> Self {
            self.common.init.push((name.to_string(), value));
            self
        }

        /// Bounds parameter `name` (`NAME` or `NAME[SERIES]`) to [`lower`, `upper`],
        /// intersected with its box.
        pub fn bounds(mut self, name: &str, lower: f64, upper: f64) -> Self {
            self.common.bounds.push((name.to_string(), (lower, upper)));
            self
        }

        /// Scales the covariance by the reduced χ² even with σ given (lmfit's
        /// `scale_covar=True`; least squares only).
        pub fn scale_covar(mut self, scale: bool) -> Self {
            self.common.scale_covar = scale;
            self
        }
    };
}

/// A law K(α) fitted to every series at once under a contact model (eq 69 on the velocities).
#[derive(Debug, Clone)]
pub struct KLawFitter {
    model: Model,
    law: KLaw,
    common: Common,
}

impl KLawFitter {
    /// The law `law` under `model` (stick, stick-approx, slip, slip-approx, stickslip or
    /// contact), by least squares with profile intervals at 95 %.
    pub fn new(model: Model, law: KLaw) -> Self {
        KLawFitter {
            model,
            law,
            common: Common::default(),
        }
    }

    common_setters!();

    /// Fits the law to `data` (the impact law, with nothing to fit, is scored).
    pub fn fit(&self, data: &Dataset) -> Result<FitResult, FitError> {
        let params: &[&str] = match self.law {
            KLaw::C => &["c"],
            KLaw::FreePerSeries => &["K"],
            KLaw::Impact => &[],
        };
        let method = self.common.check(data, params)?;
        let f = fit_law_with(self.model, data, self.law, self.common.level, &method)?;
        Ok(f.summary)
    }
}

/// Jan's energy balance (eq 74): λ and μ per series, and the global laws of eqs 75–76.
#[derive(Debug, Clone, Default)]
pub struct JanFitter {
    common: Common,
}

impl JanFitter {
    /// By least squares with profile intervals at 95 %.
    pub fn new() -> Self {
        Self::default()
    }

    common_setters!();

    /// Fits every series with at least 3 points, then the global laws.
    pub fn fit(&self, data: &Dataset) -> Result<FitSet, FitError> {
        let params = ["lambda", "mu", "lambda0", "lambda1", "mu0", "mu1"];
        let method = self.common.check(data, &params)?;
        let j = fit_jan_with(data, self.common.level, &method);
        if let Some(e) = j.fault {
            return Err(e.into());
        }
        Ok(FitSet {
            fits: j.series.into_iter().flatten().chain(j.global).collect(),
            notes: j.notes,
        })
    }
}

/// Jaeger's heuristic law (eqs 80–84): a1, a2, a3 per series on one root of eq 84.
#[derive(Debug, Clone)]
pub struct JaegerFitter {
    branch: JaegerBranch,
    common: Common,
}

impl JaegerFitter {
    /// On the upper root of eq 84, by least squares with profile intervals at 95 %.
    pub fn new() -> Self {
        JaegerFitter {
            branch: JaegerBranch::Upper,
            common: Common::default(),
        }
    }

    /// The root of eq 84 the velocities are taken on.
    pub fn branch(mut self, branch: JaegerBranch) -> Self {
        self.branch = branch;
        self
    }

    common_setters!();

    /// Fits every series with at least 4 points.
    pub fn fit(&self, data: &Dataset) -> Result<FitSet, FitError> {
        let method = self.common.check(data, &["a1", "a2", "a3"])?;
        let j = fit_jaeger_with(data, self.branch, self.common.level, &method);
        if let Some(e) = j.fault {
            return Err(e.into());
        }
        Ok(FitSet {
            fits: j.series.into_iter().flatten().map(|f| f.summary).collect(),
            notes: j.notes,
        })
    }
}

impl Default for JaegerFitter {
    fn default() -> Self {
        Self::new()
    }
}
