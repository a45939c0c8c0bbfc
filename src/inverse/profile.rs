//! Confidence intervals: from the covariance (Wald) and by profile likelihood.
//!
//! For parameter k the profile is χ²ₖ(v) = min over the other parameters of χ²(p | pₖ = v),
//! each point computed by the same Levenberg–Marquardt solver, warm-started from the nearest
//! point already profiled on the estimate's side of the end (continuation from the optimum).
//! The interval ends are the two roots of Δχ²(v) = χ²ₖ(v) − χ²_min = threshold, each bracketed
//! by stepping outward from the estimate (doubling steps, starting from the covariance
//! half-width; bisecting back towards the last good point where a constrained fit fails) and
//! then refined by Brent's method. The ends can also be a bound of the box
//! ([`ProfileEnd::Bound`]) or the edge of the region where the constrained fits succeed
//! ([`ProfileEnd::Edge`]).
//!
//! The profile is only as global as the constrained fits: each is a local minimisation, so on a
//! problem with several basins a constrained fit can stop in a higher local minimum and make the
//! interval too short on that side.
//!
//! The threshold is the one that makes the profile interval of a linear model coincide with
//! the covariance interval:
//! * σ absolute ([`SigmaKind::Absolute`]): threshold = χ²₁ quantile at the level = z², with
//!   z the standard normal (1 + level)/2 quantile; the covariance interval is p̂ ± z·se;
//! * σ relative ([`SigmaKind::Relative`]): threshold = s²·F₁,dof quantile = s²·t², with t the
//!   Student-t (1 + level)/2 quantile on dof = m − n degrees of freedom and s² = χ²_min/dof;
//!   the covariance interval is p̂ ± t·se. The same with σ absolute and the covariance scaled
//!   by the reduced χ² all the same ([`LsqOptions::scale_covar`]): for one parameter this
//!   threshold is lmfit's F-test, Δχ² = χ²_min·F₁,dof/dof.

use faer::{Mat, MatMut};
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
use std::cell::RefCell;

use super::estimate::Fit;
use super::lm::{solve, DynLeastSquares, Spare};
use super::lsq::{validate, Infeasible, LsqError, LsqOptions, Residuals, SigmaKind};
use crate::special::root::brent;

/// The customary confidence level, 0.95.
pub(crate) const DEFAULT_LEVEL: f64 = 0.95;

/// A closed interval [lower, upper].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
}

/// One end of a profile-likelihood interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProfileEnd {
    /// Δχ² reaches the threshold at this value.
    Found(f64),
    /// Δχ² stays below the threshold all the way to this bound of the box: the interval reaches
    /// (at least) the bound.
    Bound(f64),
    /// Δχ² is still below the threshold at this value, but the constrained fits fail
    /// (infeasible or not converging) beyond it — located by bisection to 10⁻⁶ of the initial
    /// step: the interval reaches at least here.
    Edge(f64),
    /// Not determined: Δχ² did not reach the threshold within the step doublings, or a
    /// constrained fit failed during the final root search.
    NotFound,
}

impl ProfileEnd {
    /// The value where the threshold is crossed, if it was found.
    pub fn value(self) -> Option<f64> {
        match self {
            ProfileEnd::Found(v) => Some(v),
            _ => None,
        }
    }
}

/// Profile-likelihood interval of one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileInterval {
    /// Lower end.
    pub lower: ProfileEnd,
    /// Upper end.
    pub upper: ProfileEnd,
    /// Number of constrained fits done.
    pub fits: usize,
    /// Residual evaluations used by those fits.
    pub residual_evals: usize,
}

/// Both kinds of interval for every parameter, at one level.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfidenceIntervals {
    /// Confidence level, e.g. 0.95.
    pub level: f64,
    /// The quantile used: z (σ absolute) or Student-t on dof (σ relative), at (1 + level)/2.
    pub quantile: f64,
    /// The Δχ² threshold of the profile intervals.
    pub threshold: f64,
    /// p̂ ± quantile·se, if the covariance exists.
    pub covariance: Option<Vec<Interval>>,
    /// Profile-likelihood intervals.
    pub profile: Vec<ProfileInterval>,
}

/// The problem with parameter `k` held at `value`.
struct Fixed<'a, R: ?Sized> {
    inner: &'a R,
    k: usize,
    value: f64,
    /// The point whose other parameters stand in for those `p` does not give.
    full: Vec<f64>,
    /// Work space: the full point, and the full Jacobian.
    point: RefCell<Vec<f64>>,
    jac: RefCell<Mat<f64>>,
}

impl<'a, R: Residuals + ?Sized> Fixed<'a, R> {
    /// `inner` with parameter `k` held (at `full[k]` until [`Fixed::value`] is set).
    fn new(inner: &'a R, k: usize, full: Vec<f64>) -> Self {
        Fixed {
            inner,
            k,
            value: full[k],
            point: RefCell::new(full.clone()),
            jac: RefCell::new(Mat::zeros(inner.n_residuals(), inner.n_params())),
            full,
        }
    }

    /// The full point of `p` (the other parameters) into `point`.
    fn expand(&self, p: &[f64], point: &mut [f64]) {
        point.copy_from_slice(&self.full);
        let mut it = p.iter();
        for (j, v) in point.iter_mut().enumerate() {
            if j == self.k {
                *v = self.value;
            } else if let Some(x) = it.next() {
                *v = *x;
            }
        }
    }
}

impl<R: Residuals + ?Sized> Residuals for Fixed<'_, R> {
    fn n_params(&self) -> usize {
        self.inner.n_params() - 1
    }
    fn n_residuals(&self) -> usize {
        self.inner.n_residuals()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        let mut point = self.point.borrow_mut();
        self.expand(p, &mut point);
        self.inner.residuals(&point, out)
    }
    fn jacobian(&self, p: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let n = self.inner.n_params();
        let m = self.inner.n_residuals();
        let mut point = self.point.borrow_mut();
        self.expand(p, &mut point);
        let mut jac = self.jac.borrow_mut();
        // As new: the problem may leave entries unwritten.
        jac.fill(0.0);
        match self.inner.jacobian(&point, jac.as_mut())? {
            Ok(()) => {}
            Err(e) => return Some(Err(e)),
        }
        let mut c = 0;
        for j in 0..n {
            if j == self.k {
                continue;
            }
            for i in 0..m {
                out[(i, c)] = jac[(i, j)];
            }
            c += 1;
        }
        Some(Ok(()))
    }
}

fn subset(v: &Option<Vec<f64>>, k: usize) -> Option<Vec<f64>> {
    v.as_ref().map(|v| {
        v.iter()
            .enumerate()
            .filter(|(j, _)| *j != k)
            .map(|(_, x)| *x)
            .collect()
    })
}

/// Quantile and Δχ² threshold for `fit` at `level`.
fn thresholds(fit: &Fit, level: f64) -> Result<(f64, f64), LsqError> {
    if !(level > 0.0 && level < 1.0) {
        return Err(LsqError::Option {
            name: "level",
            reason: "must be in (0, 1)",
        });
    }
    let q = 0.5 * (1.0 + level);
    match fit.sigma {
        SigmaKind::Absolute if !fit.scale_covar => {
            let z = Normal::new(0.0, 1.0)
                .map_err(|_| LsqError::Option {
                    name: "level",
                    reason: "normal quantile unavailable",
                })?
                .inverse_cdf(q);
            Ok((z, z * z))
        }
        _ => {
            if fit.dof == 0 {
                return Err(LsqError::Option {
                    name: "sigma",
                    reason: "relative σ needs at least one degree of freedom",
                });
            }
            let t = StudentsT::new(0.0, 1.0, fit.dof as f64)
                .map_err(|_| LsqError::Option {
                    name: "level",
                    reason: "Student-t quantile unavailable",
                })?
                .inverse_cdf(q);
            Ok((t, fit.reduced_chi2 * t * t))
        }
    }
}

/// Covariance (Wald) intervals p̂ ± q·se at `level`: q is the standard normal quantile when σ
/// are absolute, Student-t on `fit.dof` when relative. `None` without a covariance.
pub(crate) fn covariance_intervals(
    fit: &Fit,
    level: f64,
) -> Result<Option<Vec<Interval>>, LsqError> {
    let (q, _) = thresholds(fit, level)?;
    Ok(fit.covariance.as_ref().map(|c| {
        fit.params
            .iter()
            .zip(&c.std_errors)
            .map(|(p, se)| Interval {
                lower: p - q * se,
                upper: p + q * se,
            })
            .collect()
    }))
}

/// Profile-likelihood interval of parameter `index` at `level` (see the module docs). `fit`
/// must be a converged fit of `problem` made with `opts` (the same bounds and tolerances are
/// used for the constrained fits).
pub(crate) fn profile_interval<R: Residuals + ?Sized>(
    problem: &R,
    fit: &Fit,
    index: usize,
    level: f64,
    opts: &LsqOptions,
) -> Result<ProfileInterval, LsqError> {
    let n = problem.n_params();
    if fit.params.len() != n {
        return Err(LsqError::Length {
            what: "fit.params",
            got: fit.params.len(),
            expected: n,
        });
    }
    if index >= n {
        return Err(LsqError::Length {
            what: "index (as a length: index + 1)",
            got: index + 1,
            expected: n,
        });
    }
    if !fit.converged() || !fit.chi2.is_finite() {
        return Err(LsqError::Option {
            name: "fit",
            reason: "the profile needs a converged fit",
        });
    }
    let setup = validate(problem, &fit.params, opts)?;
    let (q, threshold) = thresholds(fit, level)?;
    let p_hat = fit.params[index];
    let width = match fit.std_errors() {
        Some(se) if se[index] > 0.0 && se[index].is_finite() => q * se[index],
        _ => 0.1 * p_hat.abs().max(setup.typical[index]),
    };
    let mut prof = Profiler {
        problem,
        opts,
        sub: LsqOptions {
            lower: subset(&opts.lower, index),
            upper: subset(&opts.upper, index),
            typical: subset(&opts.typical, index),
            ..opts.clone()
        },
        spare: Spare::new(),
        chi2_min: fit.chi2,
        threshold,
        others: fit
            .params
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != index)
            .map(|(_, x)| *x)
            .collect(),
        fits: 0,
        evals: 0,
        fixed: Fixed::new(problem, index, fit.params.clone()),
    };
    let lower = prof.end(p_hat, -width, setup.lower[index]);
    let upper = prof.end(p_hat, width, setup.upper[index]);
    Ok(ProfileInterval {
        lower,
        upper,
        fits: prof.fits,
        residual_evals: prof.evals,
    })
}

struct Profiler<'a, R: ?Sized> {
    problem: &'a R,
    /// The problem with the profiled parameter held.
    fixed: Fixed<'a, R>,
    opts: &'a LsqOptions,
    /// The options of the constrained fits: those of the fit without the profiled parameter.
    sub: LsqOptions,
    /// Work space of the constrained fits, all of the same shape.
    spare: Spare,
    chi2_min: f64,
    threshold: f64,
    /// Optimum of the other parameters at p̂.
    others: Vec<f64>,
    fits: usize,
    evals: usize,
}

impl<R: Residuals + ?Sized> Profiler<'_, R> {
    /// Δχ²(v) − threshold and the other parameters there, warm-started at `warm`; `None` if the
    /// constrained fit failed.
    fn eval(&mut self, v: f64, warm: &[f64]) -> Option<(f64, Vec<f64>)> {
        // Once the caller's stop flag is up, every point counts as failed, at no cost.
        if self
            .opts
            .stop
            .as_ref()
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
        {
            return None;
        }
        self.fixed.value = v;
        self.fits += 1;
        if warm.is_empty() {
            // One parameter: nothing to re-minimise.
            let mut r = vec![0.0; self.problem.n_residuals()];
            self.evals += 1;
            if let Some(t) = &self.opts.progress {
                t.add(1);
            }
            self.problem.residuals(&[v], &mut r).ok()?;
            let chi2: f64 = r.iter().map(|x| x * x).sum();
            return chi2
                .is_finite()
                .then(|| (chi2 - self.chi2_min - self.threshold, Vec::new()));
        }
        let ls = DynLeastSquares::new(&self.fixed, warm, &self.sub).ok()?;
        let (sol, ev, _) = solve(ls, &self.sub, &mut self.spare).ok()?;
        self.evals += ev.nfev;
        if !sol.termination.converged() {
            return None;
        }
        let chi2 = sol.fnorm * sol.fnorm;
        Some((chi2 - self.chi2_min - self.threshold, sol.x))
    }

    /// One end: step from `p_hat` by `step` (signed), doubling, until Δχ² passes the threshold
    /// or `bound` is reached; then Brent.
    fn end(&mut self, p_hat: f64, step: f64, bound: f64) -> ProfileEnd {
        // (v, g, others) of the last point with g < 0.
        let mut inside = (p_hat, -self.threshold, self.others.clone());
        let mut w = step;
        let mut outside = None;
        // The nearest point where the constrained fit failed (infeasible or not converging):
        // once there is one, the search bisects between it and the last good point.
        let mut failed_at: Option<f64> = None;
        for _ in 0..200 {
            let mut v = match failed_at {
                Some(vf) => {
                    if (vf - inside.0).abs() <= 1e-6 * step.abs() {
                        return ProfileEnd::Edge(inside.0);
                    }
                    0.5 * (inside.0 + vf)
                }
                None => p_hat + w,
            };
            let at_bound = if step > 0.0 { v >= bound } else { v <= bound };
            if at_bound {
                v = bound;
            }
            if !v.is_finite() {
                return ProfileEnd::NotFound;
            }
            let Some((g, x)) = self.eval(v, &inside.2) else {
                failed_at = Some(v);
                continue;
            };
            if g >= 0.0 {
                outside = Some((v, g));
                break;
            }
            inside = (v, g, x);
            if at_bound {
                return ProfileEnd::Bound(bound);
            }
            w *= 2.0;
        }
        let Some((vb, gb)) = outside else {
            return ProfileEnd::NotFound;
        };
        let (va, ga, warm) = inside;
        let mut failed = false;
        // Constrained optima on the near side of the end (Δχ² below the threshold): each
        // Brent evaluation is warm-started from the one nearest to it. Far-side optima are
        // never used: beyond the end the other parameters may have wandered into another basin,
        // and starting from there could stop the fit in a higher local minimum.
        let mut near: Vec<(f64, Vec<f64>)> = vec![(va, warm)];
        let xtol = 1e-11 * (vb - va).abs();
        let root = brent(
            |v| {
                if failed {
                    return 0.0;
                }
                let warm = near
                    .iter()
                    .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
                    .map(|w| w.1.clone())
                    .unwrap_or_default();
                match self.eval(v, &warm) {
                    Some((g, x)) => {
                        if g < 0.0 {
                            near.push((v, x));
                        }
                        g
                    }
                    None => {
                        failed = true;
                        0.0
                    }
                }
            },
            va,
            vb,
            ga,
            gb,
            xtol,
            200,
        );
        match root {
            Some(r) if !failed => ProfileEnd::Found(r.x),
            _ => ProfileEnd::NotFound,
        }
    }
}

impl ConfidenceIntervals {
    /// Covariance and profile-likelihood intervals of every parameter at `level`
    /// (0.95 is the usual choice).
    ///
    /// ```
    /// use fitbead::inverse::{fit, ConfidenceIntervals, Infeasible, LsqOptions, CurveModel, WeightedData};
    /// struct Decay;
    /// impl CurveModel<f64> for Decay {
    ///     fn n_params(&self) -> usize { 2 }
    ///     fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> { Ok(p[0] * (-p[1] * x).exp()) }
    /// }
    /// let x: Vec<f64> = (0..8).map(f64::from).collect();
    /// let y = vec![10.2, 6.0, 3.8, 2.1, 1.4, 0.8, 0.5, 0.3];
    /// let data = WeightedData::new(Decay, x, y, Some(vec![0.2; 8])).unwrap();
    /// let opts = LsqOptions::default();
    /// let f = fit(&data, &[5.0, 0.1], &opts).unwrap();
    /// let ci = ConfidenceIntervals::compute(&data, &f, 0.95, &opts).unwrap();
    /// let wald = ci.covariance.unwrap();
    /// let prof = &ci.profile[1];
    /// assert!(prof.lower.value().unwrap() < f.params[1] && wald[1].lower < f.params[1]);
    /// ```
    pub fn compute<R: Residuals + ?Sized>(
        problem: &R,
        fit: &Fit,
        level: f64,
        opts: &LsqOptions,
    ) -> Result<ConfidenceIntervals, LsqError> {
        let (quantile, threshold) = thresholds(fit, level)?;
        let covariance = covariance_intervals(fit, level)?;
        let profile = (0..problem.n_params())
            .map(|k| profile_interval(problem, fit, k, level, opts))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ConfidenceIntervals {
            level,
            quantile,
            threshold,
            covariance,
            profile,
        })
    }
}
