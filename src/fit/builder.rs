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

/// The method and level every builder shares.
#[derive(Debug, Clone)]
struct Common {
    level: f64,
    method: Method,
}

impl Default for Common {
    fn default() -> Self {
        Common {
            level: DEFAULT_LEVEL,
            method: Method::lsq(true),
        }
    }
}

impl Common {
    /// Refuses a level outside (0, 1) and a method that cannot fit `data`.
    fn check(&self, data: &Dataset) -> Result<(), FitError> {
        if !(self.level > 0.0 && self.level < 1.0) {
            return Err(FitError::Level(self.level));
        }
        match super::slopes::unsupported(&self.method, data) {
            Some(why) => Err(FitError::Method(why)),
            None => Ok(()),
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
        self.common.check(data)?;
        let f = fit_law_with(
            self.model,
            data,
            self.law,
            self.common.level,
            &self.common.method,
        )?;
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
        self.common.check(data)?;
        let j = fit_jan_with(data, self.common.level, &self.common.method);
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
        self.common.check(data)?;
        let j = fit_jaeger_with(data, self.branch, self.common.level, &self.common.method);
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
