//! The estimate of a least-squares fit: [`fit`] runs [`super::LevenbergMarquardt`] under
//! argmin's `Executor` and adds the covariance, from the SVD of the column-equilibrated Jacobian
//! at the optimum, (JᵀJ)⁻¹ = V Σ⁻² Vᵀ, never from an explicitly formed JᵀJ. Both are validated
//! against the NIST Statistical Reference Datasets (StRD) for nonlinear regression — see
//! `tests/it/nist.rs`.

// Index loops mirror the subscripts of the matrix formulas.
#![allow(clippy::needless_range_loop)]

use faer::Mat;

use argmin::core::OptimizationResult;

use super::lm::{into_parts, solve, DynLeastSquares, LevenbergMarquardt, Solution, Spare};
use super::lmpar::norm2;
use super::lsq::{LsqError, LsqOptions, Residuals, SigmaKind, Termination};
use super::problem::{Evaluator, LeastSquares, View};
use super::state::LmState;

/// Covariance of the estimates, from the SVD of the Jacobian at the optimum.
#[derive(Debug, Clone, PartialEq)]
pub struct Covariance {
    /// The n × n covariance matrix: `scale`·(JᵀJ)⁻¹.
    pub matrix: Mat<f64>,
    /// The correlation matrix Cᵢⱼ / √(Cᵢᵢ Cⱼⱼ).
    pub correlation: Mat<f64>,
    /// Standard errors √Cᵢᵢ.
    pub std_errors: Vec<f64>,
    /// The factor applied to (JᵀJ)⁻¹: 1 for [`SigmaKind::Absolute`], s² = χ²/dof for
    /// [`SigmaKind::Relative`].
    pub scale: f64,
    /// Condition number of the column-equilibrated Jacobian.
    pub condition: f64,
}

/// The result of [`fit`].
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// Estimated parameters.
    pub params: Vec<f64>,
    /// Residuals at the estimate (empty if the start was infeasible).
    pub residuals: Vec<f64>,
    /// χ² = Σ rᵢ² at the estimate (+∞ if the start was infeasible).
    pub chi2: f64,
    /// Degrees of freedom m − n.
    pub dof: usize,
    /// χ²/dof (+∞ when dof = 0).
    pub reduced_chi2: f64,
    /// Covariance, correlation and standard errors; `None` when the Jacobian at the estimate is
    /// rank deficient (or could not be formed), or with [`SigmaKind::Relative`] and dof = 0.
    pub covariance: Option<Covariance>,
    /// Scaling convention used for the covariance.
    pub sigma: SigmaKind,
    /// Whether the covariance of absolute σ was scaled by the reduced χ² all the same
    /// ([`LsqOptions::scale_covar`]); its intervals are then those of relative σ.
    pub scale_covar: bool,
    /// Akaike information criterion from the Gaussian likelihood, with k = n parameters and m
    /// residuals:
    /// * [`SigmaKind::Absolute`]: AIC = χ² + 2k (the constant Σ ln 2πσᵢ², the same for every
    ///   model of the same data, is left out);
    /// * [`SigmaKind::Relative`]: the common variance is a parameter too, estimated by χ²/m, so
    ///   −2 ln L = m (ln(2π χ²/m) + 1) and AIC = −2 ln L + 2(k + 1) (as R's `AIC` of `nls`,
    ///   weights' Σ ln wᵢ left out).
    pub aic: f64,
    /// Bayesian information criterion, as `aic` with the penalty 2k (2(k + 1)) replaced by
    /// k ln m ((k + 1) ln m).
    pub bic: f64,
    /// Accepted steps: Levenberg–Marquardt steps of every run, plus Gauss–Newton polish
    /// steps.
    pub iterations: usize,
    /// Residual evaluations, finite-difference ones included.
    pub residual_evals: usize,
    /// Jacobian evaluations (analytic or by differences).
    pub jacobian_evals: usize,
    /// Why the solver stopped.
    pub termination: Termination,
    /// Which parameters finish on a bound. The covariance ignores the bounds.
    pub at_bound: Vec<bool>,
}

impl Fit {
    /// True when the solver met a genuine convergence criterion.
    pub fn converged(&self) -> bool {
        self.termination.converged()
    }

    /// Standard errors, if the covariance exists.
    pub fn std_errors(&self) -> Option<&[f64]> {
        self.covariance.as_ref().map(|c| c.std_errors.as_slice())
    }

    /// The [`Fit`] (estimate, statistics and covariance) of a run of
    /// [`super::LevenbergMarquardt`] under argmin's `Executor` built by hand, e.g. with observers or
    /// a timeout. A run that argmin stopped (iteration limit, timeout, target cost, interrupt)
    /// reports the point reached, with [`Termination::MaxIterations`] for the iteration limit,
    /// [`Termination::RelativeReduction`] for a target cost and [`Termination::Interrupted`] for the
    /// others.
    pub fn from_run<R: Residuals>(
        result: OptimizationResult<LeastSquares<R>, LevenbergMarquardt, LmState>,
        sigma: SigmaKind,
    ) -> Result<Fit, LsqError> {
        let (sol, solver, ls) = into_parts(result).map_err(|e| LsqError::Solver(e.to_string()))?;
        Ok(finish(
            &mut solver.into_evaluator(),
            ls.view(),
            sol,
            (sigma, false),
        ))
    }
}

/// Fits `problem` from `start`: bounded Levenberg–Marquardt with Moré scaling
/// ([`super::LevenbergMarquardt`], run under argmin's `Executor`),
/// then the covariance from the SVD of the Jacobian at the estimate.
///
/// Returns an error only for malformed input; numerical failure is reported in
/// [`Fit::termination`] (check [`Fit::converged`]).
///
/// ```
/// use fitbead::inverse::{fit, LsqOptions, CurveModel, SigmaKind, WeightedData, Infeasible};
/// struct Line;
/// impl CurveModel<f64> for Line {
///     fn n_params(&self) -> usize { 2 }
///     fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> { Ok(p[0] + p[1] * x) }
/// }
/// let data = WeightedData::new(Line, vec![0.0, 1.0, 2.0, 3.0], vec![1.1, 2.9, 5.2, 6.8], None).unwrap();
/// let opts = LsqOptions { sigma: SigmaKind::Relative, ..Default::default() };
/// let fit = fit(&data, &[0.0, 1.0], &opts).unwrap();
/// assert!(fit.converged());
/// assert!((fit.params[1] - 1.94).abs() < 1e-9);
/// ```
pub fn fit<R: Residuals + ?Sized>(
    problem: &R,
    start: &[f64],
    opts: &LsqOptions,
) -> Result<Fit, LsqError> {
    let ls = DynLeastSquares::new(&problem, start, opts)?;
    let (sol, mut ev, ls) =
        solve(ls, opts, &mut Spare::new()).map_err(|e| LsqError::Solver(e.to_string()))?;
    Ok(finish(
        &mut ev,
        ls.view(),
        sol,
        (opts.sigma, opts.scale_covar),
    ))
}

/// The [`Fit`] of a solution: statistics, and the covariance from the Jacobian at the estimate
/// under the σ convention and covariance scaling `(sigma, scale_covar)`.
fn finish(
    ev: &mut Evaluator,
    ls: View<'_>,
    sol: Solution,
    (sigma, scale_covar): (SigmaKind, bool),
) -> Fit {
    let (m, n) = (ev.m, ev.n);
    let dof = m - n;
    let chi2 = if sol.fnorm.is_finite() {
        sol.fnorm * sol.fnorm
    } else {
        f64::INFINITY
    };
    let reduced_chi2 = if dof > 0 {
        chi2 / dof as f64
    } else {
        f64::INFINITY
    };
    let covariance = if chi2.is_finite() {
        let mut jac = Mat::<f64>::zeros(m, n);
        match covariance_scale(sigma, scale_covar, dof, reduced_chi2) {
            Some(s) if ev.jacobian(ls, &sol.x, &sol.f, &mut jac) => {
                covariance(&jac, s, rank_tolerance(ev.differenced, m, n))
            }
            _ => None,
        }
    } else {
        None
    };
    let (aic, bic) = information_criteria(chi2, m, n, sigma);
    let at_bound = (0..n)
        .map(|j| sol.x[j] <= ls.setup.lower[j] || sol.x[j] >= ls.setup.upper[j])
        .collect();
    Fit {
        params: sol.x,
        residuals: sol.f,
        chi2,
        dof,
        reduced_chi2,
        covariance,
        sigma,
        scale_covar,
        aic,
        bic,
        iterations: sol.iterations,
        residual_evals: ev.nfev,
        jacobian_evals: ev.njev,
        termination: sol.termination,
        at_bound,
    }
}

/// The factor of (JᵀJ)⁻¹ in the covariance: 1 for absolute σ, the reduced χ² for relative σ
/// or when `scale_covar` asks for it (`None` there without a degree of freedom).
pub(crate) fn covariance_scale(
    sigma: SigmaKind,
    scale_covar: bool,
    dof: usize,
    reduced_chi2: f64,
) -> Option<f64> {
    match sigma {
        SigmaKind::Absolute if !scale_covar => Some(1.0),
        _ if dof > 0 => Some(reduced_chi2),
        _ => None,
    }
}

/// The relative singular-value threshold below which an m × n Jacobian counts as rank
/// deficient, to its precision: ε·max(m, n) for an analytic one, 10 ε^(2/3) (the
/// central-difference error) for differences.
pub(crate) fn rank_tolerance(differenced: bool, m: usize, n: usize) -> f64 {
    if differenced {
        10.0 * f64::EPSILON.powf(2.0 / 3.0)
    } else {
        f64::EPSILON * m.max(n) as f64
    }
}

/// AIC and BIC of a fit of `n` parameters to `m` residuals with χ² = `chi2` (the conventions
/// of [`Fit::aic`] and [`Fit::bic`]).
pub(crate) fn information_criteria(chi2: f64, m: usize, n: usize, sigma: SigmaKind) -> (f64, f64) {
    let (k, mf) = (n as f64, m as f64);
    match sigma {
        SigmaKind::Absolute => (chi2 + 2.0 * k, chi2 + k * mf.ln()),
        SigmaKind::Relative => {
            let m2ll = mf * ((2.0 * std::f64::consts::PI * chi2 / mf).ln() + 1.0);
            (m2ll + 2.0 * (k + 1.0), m2ll + (k + 1.0) * mf.ln())
        }
    }
}

/// scale·(JᵀJ)⁻¹ from the SVD of J with unit-norm columns: J = J̃ C, J̃ = U Σ Vᵀ, so
/// (JᵀJ)⁻¹ = C⁻¹ V Σ⁻² Vᵀ C⁻¹. `None` if J is numerically rank deficient: σ_min ≤ rtol·σ_max.
pub(crate) fn covariance(jac: &Mat<f64>, scale: f64, rtol: f64) -> Option<Covariance> {
    let (m, n) = (jac.nrows(), jac.ncols());
    let mut c = vec![0.0; n];
    let mut a = Mat::<f64>::zeros(m, n);
    for j in 0..n {
        let col: Vec<f64> = (0..m).map(|i| jac[(i, j)]).collect();
        c[j] = norm2(&col);
        if !(c[j] > 0.0 && c[j].is_finite()) {
            return None;
        }
        for i in 0..m {
            a[(i, j)] = jac[(i, j)] / c[j];
        }
    }
    let svd = a.thin_svd().ok()?;
    let s = svd.S().column_vector();
    let v = svd.V();
    let smax = s[0];
    let smin = s[n - 1];
    if !(smin > smax * rtol) {
        return None;
    }
    let mut matrix = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        for j in 0..=i {
            let mut sum = 0.0;
            for k in 0..n {
                sum += v[(i, k)] * v[(j, k)] / (s[k] * s[k]);
            }
            let val = scale * sum / (c[i] * c[j]);
            matrix[(i, j)] = val;
            matrix[(j, i)] = val;
        }
    }
    let std_errors: Vec<f64> = (0..n).map(|i| matrix[(i, i)].max(0.0).sqrt()).collect();
    let mut correlation = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            let d = std_errors[i] * std_errors[j];
            correlation[(i, j)] = if i == j {
                1.0
            } else if d > 0.0 {
                matrix[(i, j)] / d
            } else {
                0.0
            };
        }
    }
    Some(Covariance {
        matrix,
        correlation,
        std_errors,
        scale,
        condition: smax / smin,
    })
}
