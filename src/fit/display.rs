//! The one-screen fit report that `Display` prints for a [`FitResult`] and a [`FitSet`], in the
//! spirit of lmfit's `fit_report`: the fit statistics and convergence, each parameter's value
//! ± standard error (and percent) with its interval and how it was obtained, the correlations
//! above 0.1 in magnitude, and warnings (a parameter on a bound of its box, a posterior run
//! that did not converge).

use super::summary::{FitResult, FitSet, ParamRow};
use crate::inverse::SigmaKind;
use crate::numfmt::{clip, fmt_sig};
use std::fmt;

/// Correlations at or below this magnitude are left out of the report.
const CORRELATION_SHOWN: f64 = 0.1;

fn num(x: f64) -> String {
    fmt_sig(x, 6)
}

/// An information criterion, `undefined` where it is NaN (see [`StatsRow::aic`]).
fn criterion(x: f64) -> String {
    if x.is_nan() {
        "undefined".into()
    } else {
        num(x)
    }
}

fn method_name(r: &FitResult) -> &'static str {
    if r.stats.mcmc.is_some() {
        "posterior sampling (affine-invariant ensemble)"
    } else if r.stats.n_params == 0 {
        "scored (nothing to fit)"
    } else if r.stats.slope_errors {
        "orthogonal distance regression (slope errors)"
    } else {
        "least squares (Levenberg-Marquardt)"
    }
}

/// Longest series label the report shows, in characters (the tables keep it whole).
const LABEL_CHARS: usize = 120;

fn param_line(f: &mut fmt::Formatter<'_>, r: &FitResult, p: &ParamRow) -> fmt::Result {
    let name = if p.series == r.stats.series {
        p.parameter.clone()
    } else {
        format!("{}[{}]", p.parameter, clip(&p.series, LABEL_CHARS))
    };
    write!(f, "    {name:<12} = {:>12}", num(p.value))?;
    if p.fixed {
        write!(f, " (fixed)")?;
        if let Some(pv) = p.paper_value {
            write!(f, "  paper: {}", num(pv))?;
        }
        return writeln!(f);
    }
    match p.stderr {
        Some(se) if se.is_finite() => {
            write!(f, " +/- {:<10}", num(se))?;
            if p.value != 0.0 {
                write!(f, " ({:.2}%)", 100.0 * (se / p.value).abs())?;
            }
        }
        _ => write!(f, " +/- (none)")?,
    }
    match p.interval().0 {
        Some((lo, hi)) => write!(
            f,
            "  {}% interval [{}, {}] ({})",
            num(100.0 * p.level),
            num(lo),
            num(hi),
            p.interval_method()
        )?,
        None => write!(f, "  no interval")?,
    }
    if !p.unit.is_empty() && p.unit != "1" {
        write!(f, "  [{}]", p.unit)?;
    }
    if let Some(pv) = p.paper_value {
        write!(f, "  paper: {}", num(pv))?;
    }
    writeln!(f)
}

impl fmt::Display for FitResult {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.stats;
        writeln!(f, "[[Fit {} [{}]]]", s.fit, clip(&s.series, LABEL_CHARS))?;
        writeln!(f, "    method             = {}", method_name(self))?;
        writeln!(f, "    data points        = {}", s.n_points)?;
        writeln!(f, "    variables          = {}", s.n_params)?;
        writeln!(f, "    chi-square         = {}", num(s.chi2))?;
        writeln!(f, "    reduced chi-square = {}", num(s.reduced_chi2))?;
        writeln!(f, "    AIC                = {}", criterion(s.aic))?;
        writeln!(f, "    BIC                = {}", criterion(s.bic))?;
        writeln!(
            f,
            "    sigma              = {}",
            match s.sigma {
                SigmaKind::Absolute if s.scale_covar => {
                    "given (relative weights): covariance scaled by reduced chi-square"
                }
                SigmaKind::Absolute => "given (absolute errors)",
                SigmaKind::Relative => "not given: unit weights, scale from the scatter",
            }
        )?;
        match &s.mcmc {
            Some(m) => writeln!(
                f,
                "    converged          = {} ({}; {} walkers, {} steps, {} draws, R-hat max {}, ESS min {})",
                if s.converged { "yes" } else { "no" },
                m.status,
                m.walkers,
                m.steps,
                m.draws,
                num(m.rhat_max),
                num(m.ess_min)
            )?,
            None if s.n_params == 0 => writeln!(
                f,
                "    converged          = n/a (nothing fitted: the law is scored as it stands; {})",
                s.termination
            )?,
            None => writeln!(
                f,
                "    converged          = {} ({}, {} iterations, {} residual evaluations)",
                if s.converged { "yes" } else { "no" },
                s.termination,
                s.iterations,
                s.residual_evals
            )?,
        }
        if !self.params.is_empty() {
            writeln!(f, "[[Variables]]")?;
            for p in &self.params {
                param_line(f, self, p)?;
            }
        }
        if let Some(c) = &self.correlation {
            let names = self.param_names();
            let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
            let n = c.len().min(names.len());
            for (i, row) in c.iter().enumerate().take(n) {
                for (j, &r) in row.iter().enumerate().take(n).skip(i + 1) {
                    if r.abs() > CORRELATION_SHOWN {
                        pairs.push((r, i, j));
                    }
                }
            }
            if !pairs.is_empty() {
                pairs.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
                writeln!(
                    f,
                    "[[Correlations]] (unreported correlations are < {CORRELATION_SHOWN})"
                )?;
                for (r, i, j) in pairs {
                    writeln!(f, "    C({}, {}) = {:+.4}", names[i], names[j], r)?;
                }
            }
        }
        let mut warnings: Vec<String> = Vec::new();
        for p in &self.params {
            if p.at_bound {
                warnings.push(format!(
                    "{} sits on a bound of its box [{}, {}]: its standard error and \
                     covariance interval ignore the bound, and the data may prefer a value \
                     outside the admissible range",
                    p.parameter,
                    num(p.bounds.0),
                    num(p.bounds.1)
                ));
            }
        }
        for p in &self.params {
            if let Some(x) = p.sensitivity.filter(|x| !x.diagnosis().is_empty()) {
                warnings.push(format!(
                    "{}: {} (power-scaling sensitivity to the prior {}, to the likelihood {}; \
                     flagged from 0.05): its posterior and interval depend on the prior",
                    p.parameter,
                    x.diagnosis(),
                    num(x.prior),
                    num(x.likelihood)
                ));
            }
        }
        if !s.converged && (s.n_params > 0 || s.mcmc.is_some()) {
            warnings.push("the fit did not converge: the values are not an optimum".into());
        }
        if !s.note.is_empty() {
            warnings.push(s.note.clone());
        }
        if !warnings.is_empty() {
            writeln!(f, "[[Warnings]]")?;
            for w in warnings {
                writeln!(f, "    {w}")?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for FitSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, r) in self.fits.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{r}")?;
        }
        for n in &self.notes {
            writeln!(f, "note: {n}")?;
        }
        Ok(())
    }
}
