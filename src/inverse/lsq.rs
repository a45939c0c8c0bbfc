//! Weighted nonlinear least squares by the Levenberg–Marquardt method with Moré's scaling.
//!
//! The algorithm is that of J. J. Moré, "The Levenberg–Marquardt algorithm: implementation and
//! theory", in *Numerical Analysis*, Lecture Notes in Mathematics 630, Springer (1978) 105–116 —
//! the MINPACK-1 `lmder` — with these choices:
//!
//! * **Trust region on the scaled step.** Each iteration minimises ‖f + J s‖ subject to
//!   ‖D s‖ ≤ Δ. The diagonal scaling D is the running maximum of the Jacobian's column norms
//!   (Moré 1978 §6, MINPACK mode 1), so the method is invariant under rescaling of the
//!   parameters. The Levenberg–Marquardt parameter λ is found by the Hebden/Moré safeguarded
//!   Newton iteration on ‖D s(λ)‖ − Δ (see `lmpar.rs`), each trial λ solving the augmented
//!   least-squares problem [J; √λ D] by QR (faer's column-pivoted Householder QR of J once per
//!   iteration, then Givens rotations for the diagonal rows): the normal equations are never
//!   formed.
//! * **Radius update** by the ratio ρ of actual to predicted reduction of ‖f‖² (Moré 1978 §4):
//!   ρ ≤ ¼ shrinks Δ (by the quadratic-interpolation factor, clamped to [0.1, 0.5]); ρ ≥ ¾ or
//!   λ = 0 sets Δ = 2‖D s‖. A step is accepted when ρ ≥ 10⁻⁴.
//! * **Infeasible points.** A residual evaluation may answer [`Infeasible`] (the model left its
//!   valid range), and a non-finite residual counts the same. A trial point that is infeasible is
//!   a rejected step with the strongest shrink of Δ (to at most ‖D s‖, ×0.1): the solver backs
//!   off towards the current, feasible point and never propagates a NaN.
//! * **Box bounds** by projection with an active set: a parameter sitting on a bound whose
//!   gradient component points out of the box is held fixed for the iteration (its Jacobian
//!   column is removed from the subproblem); the trial point of the others is projected onto the
//!   box, and the predicted reduction is recomputed for the projected step, so the ratio test
//!   stays honest. Projection was chosen over reflection because it keeps a parameter exactly on
//!   its bound when the optimum is there (a reflective transform only approaches it). A start
//!   outside the box is projected onto it.
//! * **Restarts.** After convergence the iteration is restarted once (by default) from the point
//!   reached, with the scaling D recomputed from the Jacobian there and a fresh radius: Moré's
//!   running-maximum scaling remembers column norms from far-away starting points, which can
//!   make the last stretch of a difficult problem (NIST MGH10, Bennett5) crawl.
//!
//! Jacobians are analytic when [`Residuals::jacobian`] provides them, else central differences
//! with step h = ε^{1/3}·max(|p|, typical) — second-order one-sided differences next to a bound or
//! an infeasible point.
//!
//! The covariance comes from the SVD of the column-equilibrated Jacobian at the optimum,
//! (JᵀJ)⁻¹ = V Σ⁻² Vᵀ, never from an explicitly formed JᵀJ. It is validated against the NIST
//! Statistical Reference Datasets (StRD) for nonlinear regression — see `tests/nist.rs`.

use faer::{Mat, MatMut};
use thiserror::Error;

use super::lmpar::{norm2, Subproblem};

/// The model left its valid range at the parameters asked for (a physical quantity would be
/// negative, a regime boundary was crossed, …). The solver treats it as a rejected step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Error)]
#[error("parameters outside the model's feasible region")]
pub struct Infeasible;

/// A least-squares problem: m weighted residuals rᵢ(p) of n parameters, to minimise
/// χ²(p) = Σ rᵢ(p)².
///
/// Residuals are expected already weighted — divided by the standard deviation σᵢ of each
/// observation, rᵢ = (yᵢ − f(xᵢ; p)) / σᵢ (see [`WeightedData`] for a helper that does that).
pub trait Residuals {
    /// Number of parameters n.
    fn n_params(&self) -> usize;
    /// Number of residuals m (at least n).
    fn n_residuals(&self) -> usize;
    /// Writes the m residuals at `p` into `out`, or reports that `p` is infeasible.
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible>;
    /// Writes the m × n Jacobian ∂rᵢ/∂pⱼ at `p` into `out` and returns `Some(Ok(()))`; returns
    /// `None` (the default) when the problem has no analytic Jacobian, in which case the solver
    /// uses finite differences.
    fn jacobian(&self, p: &[f64], out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let _ = (p, out);
        None
    }
}

impl<R: Residuals + ?Sized> Residuals for &R {
    fn n_params(&self) -> usize {
        (**self).n_params()
    }
    fn n_residuals(&self) -> usize {
        (**self).n_residuals()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        (**self).residuals(p, out)
    }
    fn jacobian(&self, p: &[f64], out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        (**self).jacobian(p, out)
    }
}

/// A model function y = f(x; p) for [`WeightedData`].
pub trait Model<X: ?Sized> {
    /// Number of parameters.
    fn n_params(&self) -> usize;
    /// f(x; p), or [`Infeasible`].
    fn value(&self, x: &X, p: &[f64]) -> Result<f64, Infeasible>;
    /// ∂f/∂pⱼ at (x; p) into `grad`; `None` (the default) to let the solver difference.
    fn gradient(&self, x: &X, p: &[f64], grad: &mut [f64]) -> Option<Result<(), Infeasible>> {
        let _ = (x, p, grad);
        None
    }
}

/// Data (xᵢ, yᵢ, σᵢ) and a [`Model`], seen as the residuals rᵢ = (yᵢ − f(xᵢ; p)) / σᵢ.
#[derive(Debug, Clone)]
pub struct WeightedData<X, M> {
    model: M,
    x: Vec<X>,
    y: Vec<f64>,
    inv_sigma: Vec<f64>,
}

impl<X, M: Model<X>> WeightedData<X, M> {
    /// Data with standard deviations `sigma` (each finite and > 0), or unit weights if `None`.
    pub fn new(
        model: M,
        x: Vec<X>,
        y: Vec<f64>,
        sigma: Option<Vec<f64>>,
    ) -> Result<Self, LsqError> {
        if x.len() != y.len() {
            return Err(LsqError::Length {
                what: "y",
                got: y.len(),
                expected: x.len(),
            });
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(LsqError::NonFinite {
                what: "y",
                index: i,
            });
        }
        let inv_sigma = match sigma {
            None => vec![1.0; y.len()],
            Some(s) => {
                if s.len() != y.len() {
                    return Err(LsqError::Length {
                        what: "sigma",
                        got: s.len(),
                        expected: y.len(),
                    });
                }
                if let Some(i) = s.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                    return Err(LsqError::NonFinite {
                        what: "sigma (must be finite and > 0)",
                        index: i,
                    });
                }
                s.iter().map(|v| 1.0 / v).collect()
            }
        };
        Ok(WeightedData {
            model,
            x,
            y,
            inv_sigma,
        })
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }
}

impl<X, M: Model<X>> Residuals for WeightedData<X, M> {
    fn n_params(&self) -> usize {
        self.model.n_params()
    }
    fn n_residuals(&self) -> usize {
        self.y.len()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        for (i, o) in out.iter_mut().enumerate() {
            *o = (self.y[i] - self.model.value(&self.x[i], p)?) * self.inv_sigma[i];
        }
        Ok(())
    }
    fn jacobian(&self, p: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let n = self.model.n_params();
        let mut g = vec![0.0; n];
        for i in 0..self.y.len() {
            match self.model.gradient(&self.x[i], p, &mut g)? {
                Ok(()) => {}
                Err(e) => return Some(Err(e)),
            }
            for (j, gj) in g.iter().enumerate() {
                out[(i, j)] = -gj * self.inv_sigma[i];
            }
        }
        Some(Ok(()))
    }
}

/// Bad input to the solver (never a numerical failure: those are [`Termination`] reasons).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LsqError {
    /// A vector has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length expected.
        expected: usize,
    },
    /// A value that must be finite is not.
    #[error("{what}[{index}] is not finite")]
    NonFinite {
        /// Which vector.
        what: &'static str,
        /// The index of the bad entry.
        index: usize,
    },
    /// The problem has no parameters, or fewer residuals than parameters.
    #[error("the problem has {m} residuals for {n} parameters (need 1 ≤ n ≤ m)")]
    Shape {
        /// Residuals.
        m: usize,
        /// Parameters.
        n: usize,
    },
    /// A lower bound is above its upper bound, or a bound is NaN.
    #[error("bounds of parameter {0} are empty or NaN")]
    Bounds(usize),
    /// An option is out of its domain.
    #[error("option {name}: {reason}")]
    Option {
        /// The option.
        name: &'static str,
        /// Its domain.
        reason: &'static str,
    },
}

/// How the covariance is scaled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SigmaKind {
    /// The σᵢ dividing the residuals are absolute standard deviations: covariance (JᵀJ)⁻¹.
    #[default]
    Absolute,
    /// The σᵢ are known only up to a common factor (or are all 1): covariance s²·(JᵀJ)⁻¹ with
    /// s² = χ²/(m − n). This is the convention of the NIST StRD certified standard deviations.
    Relative,
}

/// Solver settings. `Default` gives tolerances of 10⁻¹², at most 1000 iterations and one
/// restart.
#[derive(Debug, Clone, PartialEq)]
pub struct LsqOptions {
    /// Relative-reduction tolerance: converged when both the actual and the predicted relative
    /// reductions of χ² are at most `ftol` (MINPACK's test). Taken as at least ε.
    pub ftol: f64,
    /// Step tolerance: converged when the trust radius Δ ≤ `xtol`·‖D p‖. Taken as at least ε.
    pub xtol: f64,
    /// Gradient tolerance: converged when the largest cosine between the residual vector and a
    /// Jacobian column is at most `gtol`. Taken as at least ε.
    pub gtol: f64,
    /// Maximum number of iterations (Jacobian evaluations) of one run.
    pub max_iterations: usize,
    /// Maximum number of residual evaluations in total (finite-difference ones included).
    pub max_residual_evals: usize,
    /// Initial trust radius, as a multiple of ‖D p₀‖ (MINPACK's `factor`, default 100).
    pub initial_radius_factor: f64,
    /// Lower bounds (length n; −∞ allowed), or none.
    pub lower: Option<Vec<f64>>,
    /// Upper bounds (length n; +∞ allowed), or none.
    pub upper: Option<Vec<f64>>,
    /// Typical magnitude of each parameter, used for finite-difference steps near zero;
    /// default |p₀| (1 where p₀ = 0).
    pub typical: Option<Vec<f64>>,
    /// How many times the iteration is restarted from a converged point with fresh scaling.
    pub restarts: usize,
    /// Scaling convention of the covariance.
    pub sigma: SigmaKind,
    /// Refine a converged point by a few Gauss–Newton steps (see [`fit`]).
    pub polish: bool,
}

impl Default for LsqOptions {
    fn default() -> Self {
        LsqOptions {
            ftol: 1e-12,
            xtol: 1e-12,
            gtol: 1e-12,
            max_iterations: 1000,
            max_residual_evals: 100_000,
            initial_radius_factor: 100.0,
            lower: None,
            upper: None,
            typical: None,
            restarts: 1,
            sigma: SigmaKind::Absolute,
            polish: true,
        }
    }
}

/// Why the solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// χ² reached exactly zero.
    ExactFit,
    /// Converged: the actual and predicted relative reductions of χ² are below `ftol`.
    RelativeReduction,
    /// Converged: the trust radius fell below `xtol` relative to the (scaled) parameters.
    StepSize,
    /// Converged: the residual vector is orthogonal to the Jacobian's columns within `gtol`.
    Gradient,
    /// Not converged: the iteration limit was reached.
    MaxIterations,
    /// Not converged: the residual-evaluation limit was reached.
    MaxEvaluations,
    /// Not converged: the starting point is infeasible (or gives non-finite residuals).
    InfeasibleStart,
    /// Not converged: the Jacobian could not be formed (non-finite, or every difference point
    /// infeasible).
    JacobianFailed,
    /// Not converged: the trust region collapsed on trial points that were infeasible — the
    /// iteration is stuck against the edge of the feasible region.
    Stalled,
}

impl Termination {
    /// True only for the genuine convergence criteria.
    pub fn converged(self) -> bool {
        matches!(
            self,
            Termination::ExactFit
                | Termination::RelativeReduction
                | Termination::StepSize
                | Termination::Gradient
        )
    }
}

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
    /// Residuals at the estimate.
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
    /// Accepted steps (all runs).
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
}

/// Validated problem data shared by the solver and the profile.
#[derive(Debug, Clone)]
pub(crate) struct Setup {
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub typical: Vec<f64>,
    pub start: Vec<f64>,
}

pub(crate) fn validate<R: Residuals + ?Sized>(
    problem: &R,
    start: &[f64],
    opts: &LsqOptions,
) -> Result<Setup, LsqError> {
    let n = problem.n_params();
    let m = problem.n_residuals();
    if n == 0 || m < n {
        return Err(LsqError::Shape { m, n });
    }
    if start.len() != n {
        return Err(LsqError::Length {
            what: "start",
            got: start.len(),
            expected: n,
        });
    }
    if let Some(i) = start.iter().position(|v| !v.is_finite()) {
        return Err(LsqError::NonFinite {
            what: "start",
            index: i,
        });
    }
    let positive = |v: f64| v.is_finite() && v > 0.0;
    for (name, v) in [
        ("ftol", opts.ftol),
        ("xtol", opts.xtol),
        ("gtol", opts.gtol),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(LsqError::Option {
                name,
                reason: "must be finite and ≥ 0",
            });
        }
    }
    if !positive(opts.initial_radius_factor) {
        return Err(LsqError::Option {
            name: "initial_radius_factor",
            reason: "must be finite and > 0",
        });
    }
    let bound =
        |b: &Option<Vec<f64>>, what: &'static str, fill: f64| -> Result<Vec<f64>, LsqError> {
            match b {
                None => Ok(vec![fill; n]),
                Some(v) if v.len() != n => Err(LsqError::Length {
                    what,
                    got: v.len(),
                    expected: n,
                }),
                Some(v) => Ok(v.clone()),
            }
        };
    let lower = bound(&opts.lower, "lower", f64::NEG_INFINITY)?;
    let upper = bound(&opts.upper, "upper", f64::INFINITY)?;
    for j in 0..n {
        if !(lower[j] <= upper[j]) || lower[j] == f64::INFINITY || upper[j] == f64::NEG_INFINITY {
            return Err(LsqError::Bounds(j));
        }
    }
    let start: Vec<f64> = (0..n).map(|j| start[j].clamp(lower[j], upper[j])).collect();
    let typical = match &opts.typical {
        Some(t) => {
            if t.len() != n {
                return Err(LsqError::Length {
                    what: "typical",
                    got: t.len(),
                    expected: n,
                });
            }
            if let Some(i) = t.iter().position(|v| !positive(*v)) {
                return Err(LsqError::NonFinite {
                    what: "typical (must be finite and > 0)",
                    index: i,
                });
            }
            t.clone()
        }
        None => start
            .iter()
            .map(|v| if *v != 0.0 { v.abs() } else { 1.0 })
            .collect(),
    };
    Ok(Setup {
        lower,
        upper,
        typical,
        start,
    })
}

/// Residual and Jacobian evaluation with counting, finiteness checks and finite differences.
pub(crate) struct Evaluator<'a, R: ?Sized> {
    problem: &'a R,
    pub m: usize,
    pub n: usize,
    pub nfev: usize,
    pub njev: usize,
    lower: &'a [f64],
    upper: &'a [f64],
    typical: &'a [f64],
    work: Vec<f64>,
    work2: Vec<f64>,
    xp: Vec<f64>,
}

impl<'a, R: Residuals + ?Sized> Evaluator<'a, R> {
    pub fn new(problem: &'a R, setup: &'a Setup) -> Self {
        let m = problem.n_residuals();
        let n = problem.n_params();
        Evaluator {
            problem,
            m,
            n,
            nfev: 0,
            njev: 0,
            lower: &setup.lower,
            upper: &setup.upper,
            typical: &setup.typical,
            work: vec![0.0; m],
            work2: vec![0.0; m],
            xp: vec![0.0; n],
        }
    }

    /// Residuals at `x`; false if infeasible or not finite.
    pub fn residuals(&mut self, x: &[f64], out: &mut [f64]) -> bool {
        self.nfev += 1;
        match self.problem.residuals(x, out) {
            Ok(()) => out.iter().all(|v| v.is_finite()),
            Err(Infeasible) => false,
        }
    }

    /// Jacobian at `x` (where the residuals are `f`); false if it cannot be formed.
    pub fn jacobian(&mut self, x: &[f64], f: &[f64], jac: &mut Mat<f64>) -> bool {
        self.njev += 1;
        match self.problem.jacobian(x, jac.as_mut()) {
            Some(Ok(())) => {
                for j in 0..self.n {
                    for i in 0..self.m {
                        if !jac[(i, j)].is_finite() {
                            return false;
                        }
                    }
                }
                true
            }
            Some(Err(Infeasible)) => false,
            None => self.differences(x, f, jac),
        }
    }

    /// Evaluates at x with component j replaced by v (within bounds); the residuals go to
    /// `work` (`second = false`) or `work2`.
    fn probe(&mut self, x: &[f64], j: usize, v: f64, second: bool) -> bool {
        if !(v >= self.lower[j] && v <= self.upper[j]) {
            return false;
        }
        self.xp.copy_from_slice(x);
        self.xp[j] = v;
        let xp = std::mem::take(&mut self.xp);
        let mut out = std::mem::take(if second {
            &mut self.work2
        } else {
            &mut self.work
        });
        let ok = self.residuals(&xp, &mut out);
        self.xp = xp;
        if second {
            self.work2 = out;
        } else {
            self.work = out;
        }
        ok
    }

    fn differences(&mut self, x: &[f64], f: &[f64], jac: &mut Mat<f64>) -> bool {
        let eta = f64::EPSILON.cbrt();
        for j in 0..self.n {
            let xj = x[j];
            let h0 = eta * xj.abs().max(self.typical[j]);
            // Steps exactly representable as differences of doubles.
            let up = xj + h0;
            let dn = xj - h0;
            let ok_up = self.probe(x, j, up, false);
            let ok_dn = self.probe(x, j, dn, true);
            if ok_up && ok_dn {
                let h = up - dn;
                for i in 0..self.m {
                    jac[(i, j)] = (self.work[i] - self.work2[i]) / h;
                }
                continue;
            }
            // One-sided, second order if the second point is available, else first order.
            let (sign, h) = if ok_up {
                (1.0, up - xj)
            } else if ok_dn {
                // Move the backward residuals into `work`.
                std::mem::swap(&mut self.work, &mut self.work2);
                (-1.0, xj - dn)
            } else {
                return false;
            };
            let far = xj + sign * 2.0 * h;
            if self.probe(x, j, far, true) {
                for i in 0..self.m {
                    jac[(i, j)] =
                        sign * (4.0 * self.work[i] - 3.0 * f[i] - self.work2[i]) / (2.0 * h);
                }
            } else {
                for i in 0..self.m {
                    jac[(i, j)] = sign * (self.work[i] - f[i]) / h;
                }
            }
        }
        true
    }
}

/// The outcome of the iteration proper (no covariance).
#[derive(Debug, Clone)]
pub(crate) struct Solution {
    pub x: Vec<f64>,
    pub f: Vec<f64>,
    pub fnorm: f64,
    pub termination: Termination,
    pub iterations: usize,
}

/// One Levenberg–Marquardt run from `x0` (MINPACK `lmder` with projection on the box).
fn lm_run<R: Residuals + ?Sized>(
    ev: &mut Evaluator<'_, R>,
    setup: &Setup,
    x0: Vec<f64>,
    opts: &LsqOptions,
) -> Solution {
    let (m, n) = (ev.m, ev.n);
    let eps = f64::EPSILON;
    let ftol = opts.ftol.max(eps);
    let xtol = opts.xtol.max(eps);
    let gtol = opts.gtol.max(eps);
    let (lo, hi) = (&setup.lower, &setup.upper);

    let mut x = x0;
    let mut f = vec![0.0; m];
    let mut iterations = 0;
    let done = |x: Vec<f64>, f: Vec<f64>, fnorm: f64, t: Termination, it: usize| Solution {
        x,
        f,
        fnorm,
        termination: t,
        iterations: it,
    };
    if !ev.residuals(&x, &mut f) {
        return done(x, f, f64::INFINITY, Termination::InfeasibleStart, 0);
    }
    let mut fnorm = norm2(&f);
    if fnorm == 0.0 {
        return done(x, f, fnorm, Termination::ExactFit, 0);
    }

    let mut jac = Mat::<f64>::zeros(m, n);
    let mut jw = Mat::<f64>::zeros(m, n);
    let mut diag = vec![0.0; n];
    let mut acnorm = vec![0.0; n];
    let mut qtf = vec![0.0; n];
    let mut grad = vec![0.0; n];
    let mut free = vec![true; n];
    let mut sp = Subproblem::new(n);
    let mut ipvt = vec![0usize; n];
    let mut trial = vec![0.0; n];
    let mut step = vec![0.0; n];
    let mut ft = vec![0.0; m];
    let mut u = vec![0.0; m];
    let mut par = 0.0;
    let mut delta = 0.0;
    let mut xnorm = 0.0;
    let mut first = true;
    let mut outer = 0usize;

    loop {
        if outer >= opts.max_iterations {
            return done(x, f, fnorm, Termination::MaxIterations, iterations);
        }
        outer += 1;
        if !ev.jacobian(&x, &f, &mut jac) {
            return done(x, f, fnorm, Termination::JacobianFailed, iterations);
        }
        // Column norms, gradient Jᵀf and the active set.
        for j in 0..n {
            let col: Vec<f64> = (0..m).map(|i| jac[(i, j)]).collect();
            acnorm[j] = norm2(&col);
            grad[j] = (0..m).map(|i| jac[(i, j)] * f[i]).sum();
            free[j] = !((x[j] <= lo[j] && grad[j] > 0.0) || (x[j] >= hi[j] && grad[j] < 0.0));
            for i in 0..m {
                jw[(i, j)] = if free[j] { jac[(i, j)] } else { 0.0 };
            }
        }
        if first {
            for j in 0..n {
                diag[j] = if acnorm[j] != 0.0 { acnorm[j] } else { 1.0 };
            }
            xnorm = scaled_norm(&diag, &x);
            delta = opts.initial_radius_factor * xnorm;
            if delta == 0.0 {
                delta = opts.initial_radius_factor;
            }
        }
        // QR with column pivoting of the (active-set) Jacobian; Qᵀf.
        let qr = jw.col_piv_qr();
        let r = qr.thin_R();
        let (fwd, _) = qr.P().arrays();
        ipvt.copy_from_slice(fwd);
        for j in 0..n {
            for i in 0..n {
                sp.r[i + j * n] = if i <= j { r[(i, j)] } else { 0.0 };
            }
        }
        let q = qr.compute_thin_Q();
        for (j, q_j) in qtf.iter_mut().enumerate() {
            *q_j = (0..m).map(|i| q[(i, j)] * f[i]).sum();
        }
        // Scaled gradient norm (largest cosine between f and a free column of J).
        let mut gnorm: f64 = 0.0;
        for j in 0..n {
            let l = ipvt[j];
            if acnorm[l] != 0.0 && free[l] {
                let sum: f64 = (0..=j).map(|i| sp.r[i + j * n] * (qtf[i] / fnorm)).sum();
                gnorm = gnorm.max((sum / acnorm[l]).abs());
            }
        }
        if gnorm <= gtol {
            return done(x, f, fnorm, Termination::Gradient, iterations);
        }
        for j in 0..n {
            diag[j] = diag[j].max(acnorm[j]);
        }

        // Inner loop: until a step is accepted.
        loop {
            par = sp.lm_step(&ipvt, &diag, &qtf, delta, par);
            let mut projected = false;
            for j in 0..n {
                let t = if free[j] { x[j] - sp.x[j] } else { x[j] };
                trial[j] = t.clamp(lo[j], hi[j]);
                if trial[j] != t {
                    projected = true;
                }
                step[j] = trial[j] - x[j];
            }
            let pnorm = scaled_norm(&diag, &step);
            if first {
                delta = delta.min(pnorm);
            }
            let feasible = ev.residuals(&trial, &mut ft);
            let fnorm1 = if feasible { norm2(&ft) } else { f64::INFINITY };
            let actred = if 0.1 * fnorm1 < fnorm {
                1.0 - (fnorm1 / fnorm) * (fnorm1 / fnorm)
            } else {
                -1.0
            };
            // Predicted reduction and scaled directional derivative.
            let (prered, dirder) = if !projected {
                // The exact LM step: pred = ‖J s‖² + 2λ‖D s‖² (Moré 1978, eq. 4.4 ff.).
                let mut rs = vec![0.0; n];
                for j in 0..n {
                    let l = ipvt[j];
                    let sl = step[l];
                    for (i, v) in rs.iter_mut().enumerate().take(j + 1) {
                        *v += sp.r[i + j * n] * sl;
                    }
                }
                let temp1 = norm2(&rs) / fnorm;
                let temp2 = par.sqrt() * pnorm / fnorm;
                (
                    temp1 * temp1 + temp2 * temp2 / 0.5,
                    -(temp1 * temp1 + temp2 * temp2),
                )
            } else {
                for (i, ui) in u.iter_mut().enumerate() {
                    *ui = (0..n).map(|j| jw[(i, j)] * step[j]).sum();
                }
                let uf: f64 = u.iter().zip(&f).map(|(a, b)| a * b).sum::<f64>() / (fnorm * fnorm);
                let uu = norm2(&u) / fnorm;
                (-2.0 * uf - uu * uu, uf)
            };
            let ratio = if prered != 0.0 { actred / prered } else { 0.0 };

            if ratio <= 0.25 {
                let mut temp = if actred >= 0.0 {
                    0.5
                } else {
                    0.5 * dirder / (dirder + 0.5 * actred)
                };
                if 0.1 * fnorm1 >= fnorm || !(temp >= 0.1) {
                    temp = 0.1;
                }
                delta = temp * delta.min(pnorm / 0.1);
                par /= temp;
            } else if par == 0.0 || ratio >= 0.75 {
                delta = pnorm / 0.5;
                par *= 0.5;
            }

            if ratio >= 1e-4 {
                x.copy_from_slice(&trial);
                std::mem::swap(&mut f, &mut ft);
                xnorm = scaled_norm(&diag, &x);
                fnorm = fnorm1;
                iterations += 1;
                first = false;
                if fnorm == 0.0 {
                    return done(x, f, fnorm, Termination::ExactFit, iterations);
                }
            }

            if actred.abs() <= ftol && prered <= ftol && 0.5 * ratio <= 1.0 {
                return done(x, f, fnorm, Termination::RelativeReduction, iterations);
            }
            if delta <= xtol * xnorm || delta < f64::MIN_POSITIVE {
                let t = if feasible {
                    Termination::StepSize
                } else {
                    Termination::Stalled
                };
                return done(x, f, fnorm, t, iterations);
            }
            if ev.nfev >= opts.max_residual_evals {
                return done(x, f, fnorm, Termination::MaxEvaluations, iterations);
            }
            if ratio >= 1e-4 {
                break;
            }
        }
    }
}

fn scaled_norm(d: &[f64], x: &[f64]) -> f64 {
    let v: Vec<f64> = d.iter().zip(x).map(|(a, b)| a * b).collect();
    norm2(&v)
}

/// Minimisation with restarts; returns the solution and the evaluator's counts.
pub(crate) fn solve<R: Residuals + ?Sized>(
    ev: &mut Evaluator<'_, R>,
    setup: &Setup,
    opts: &LsqOptions,
) -> Solution {
    let mut sol = lm_run(ev, setup, setup.start.clone(), opts);
    for _ in 0..opts.restarts {
        if !sol.termination.converged() || sol.termination == Termination::ExactFit {
            break;
        }
        let again = lm_run(ev, setup, sol.x.clone(), opts);
        let improved = again.fnorm < sol.fnorm;
        let iterations = sol.iterations + again.iterations;
        if again.termination.converged() || improved {
            let stop = !improved;
            sol = Solution {
                iterations,
                ..again
            };
            if stop {
                break;
            }
        } else {
            sol.iterations = iterations;
            break;
        }
    }
    if opts.polish && sol.termination.converged() && sol.termination != Termination::ExactFit {
        sol = polish(ev, setup, sol, opts);
    }
    sol
}

/// Gauss–Newton refinement of a converged point: at most 10 full Gauss–Newton steps
/// (λ = 0, rank-revealing QR), each kept only if it is feasible, does not raise ‖f‖ beyond
/// `POLISH_SLACK` relative, and (after the first) is at most half the previous one in the
/// scaled norm — the contraction expected of Gauss–Newton next to a minimum. Near the optimum
/// of an ill-conditioned problem the χ² differences that the trust-region ratio test relies on
/// drown in rounding, so the radius collapses while the Gauss–Newton step, computed from the
/// gradient Jᵀf, still knows where the minimum is.
fn polish<R: Residuals + ?Sized>(
    ev: &mut Evaluator<'_, R>,
    setup: &Setup,
    sol: Solution,
    opts: &LsqOptions,
) -> Solution {
    const POLISH_SLACK: f64 = 1e-10;
    const POLISH_STEPS: usize = 50;
    const POLISH_CONTRACTION: f64 = 0.9;
    let (m, n) = (ev.m, ev.n);
    let (lo, hi) = (&setup.lower, &setup.upper);
    let xtol = opts.xtol.max(f64::EPSILON);
    let mut sol = sol;
    let mut jac = Mat::<f64>::zeros(m, n);
    let mut sp = Subproblem::new(n);
    let mut ipvt = vec![0usize; n];
    let mut qtf = vec![0.0; n];
    let mut diag = vec![0.0; n];
    let mut trial = vec![0.0; n];
    let mut step = vec![0.0; n];
    let mut ft = vec![0.0; m];
    let mut previous = f64::INFINITY;
    for _ in 0..POLISH_STEPS {
        if ev.nfev >= opts.max_residual_evals || !ev.jacobian(&sol.x, &sol.f, &mut jac) {
            break;
        }
        let mut free = vec![true; n];
        for j in 0..n {
            let col: Vec<f64> = (0..m).map(|i| jac[(i, j)]).collect();
            diag[j] = norm2(&col);
            if diag[j] == 0.0 {
                diag[j] = 1.0;
            }
            let g: f64 = (0..m).map(|i| jac[(i, j)] * sol.f[i]).sum();
            free[j] = !((sol.x[j] <= lo[j] && g > 0.0) || (sol.x[j] >= hi[j] && g < 0.0));
            if !free[j] {
                for i in 0..m {
                    jac[(i, j)] = 0.0;
                }
            }
        }
        let qr = jac.col_piv_qr();
        let r = qr.thin_R();
        let (fwd, _) = qr.P().arrays();
        ipvt.copy_from_slice(fwd);
        // Rank-revealing truncation: drop trailing pivots below n·ε·|r₀₀|.
        let rmax = r[(0, 0)].abs();
        for j in 0..n {
            for i in 0..n {
                sp.r[i + j * n] = if i <= j { r[(i, j)] } else { 0.0 };
            }
            if r[(j, j)].abs() <= rmax * f64::EPSILON * n as f64 {
                sp.r[j + j * n] = 0.0;
            }
        }
        let q = qr.compute_thin_Q();
        for (j, q_j) in qtf.iter_mut().enumerate() {
            *q_j = (0..m).map(|i| q[(i, j)] * sol.f[i]).sum();
        }
        sp.lm_step(&ipvt, &diag, &qtf, f64::INFINITY, 0.0);
        for j in 0..n {
            let t = if free[j] {
                sol.x[j] - sp.x[j]
            } else {
                sol.x[j]
            };
            trial[j] = t.clamp(lo[j], hi[j]);
            step[j] = trial[j] - sol.x[j];
        }
        let snorm = scaled_norm(&diag, &step);
        if !(snorm > xtol * scaled_norm(&diag, &sol.x)) || !(snorm <= POLISH_CONTRACTION * previous)
        {
            break;
        }
        if !ev.residuals(&trial, &mut ft) {
            break;
        }
        let fnorm1 = norm2(&ft);
        if !(fnorm1 <= sol.fnorm * (1.0 + POLISH_SLACK)) {
            break;
        }
        sol.x.copy_from_slice(&trial);
        std::mem::swap(&mut sol.f, &mut ft);
        sol.fnorm = fnorm1;
        previous = snorm;
    }
    sol
}

/// Fits `problem` from `start`: Levenberg–Marquardt with Moré scaling (see the module docs),
/// then the covariance from the SVD of the Jacobian at the estimate.
///
/// Returns an error only for malformed input; numerical failure is reported in
/// [`Fit::termination`] (check [`Fit::converged`]).
///
/// ```
/// use fitbead::inverse::{fit, LsqOptions, Model, SigmaKind, WeightedData, Infeasible};
/// struct Line;
/// impl Model<f64> for Line {
///     fn n_params(&self) -> usize { 2 }
///     fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> { Ok(p[0] + p[1] * x) }
/// }
/// let data = WeightedData::new(Line, vec![0.0, 1.0, 2.0, 3.0], vec![1.1, 2.9, 5.2, 6.8], None).unwrap();
/// let opts = LsqOptions { sigma: SigmaKind::Relative, ..Default::default() };
/// let fit = fit(&data, &[0.0, 1.0], &opts).unwrap();
/// assert!(fit.converged());
/// assert!((fit.params[1] - 1.92).abs() < 1e-9);
/// ```
pub fn fit<R: Residuals + ?Sized>(
    problem: &R,
    start: &[f64],
    opts: &LsqOptions,
) -> Result<Fit, LsqError> {
    let setup = validate(problem, start, opts)?;
    let mut ev = Evaluator::new(problem, &setup);
    let sol = solve(&mut ev, &setup, opts);
    Ok(finish(&mut ev, &setup, sol, opts.sigma))
}

fn finish<R: Residuals + ?Sized>(
    ev: &mut Evaluator<'_, R>,
    setup: &Setup,
    sol: Solution,
    sigma: SigmaKind,
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
        let scale = match sigma {
            SigmaKind::Absolute => Some(1.0),
            SigmaKind::Relative if dof > 0 => Some(reduced_chi2),
            SigmaKind::Relative => None,
        };
        match scale {
            Some(s) if ev.jacobian(&sol.x, &sol.f, &mut jac) => covariance(&jac, s),
            _ => None,
        }
    } else {
        None
    };
    let (k, mf) = (n as f64, m as f64);
    let (aic, bic) = match sigma {
        SigmaKind::Absolute => (chi2 + 2.0 * k, chi2 + k * mf.ln()),
        SigmaKind::Relative => {
            let m2ll = mf * ((2.0 * std::f64::consts::PI * chi2 / mf).ln() + 1.0);
            (m2ll + 2.0 * (k + 1.0), m2ll + (k + 1.0) * mf.ln())
        }
    };
    let at_bound = (0..n)
        .map(|j| sol.x[j] <= setup.lower[j] || sol.x[j] >= setup.upper[j])
        .collect();
    Fit {
        params: sol.x,
        residuals: sol.f,
        chi2,
        dof,
        reduced_chi2,
        covariance,
        sigma,
        aic,
        bic,
        iterations: sol.iterations,
        residual_evals: ev.nfev,
        jacobian_evals: ev.njev,
        termination: sol.termination,
        at_bound,
    }
}

/// scale·(JᵀJ)⁻¹ from the SVD of J with unit-norm columns: J = J̃ C, J̃ = U Σ Vᵀ, so
/// (JᵀJ)⁻¹ = C⁻¹ V Σ⁻² Vᵀ C⁻¹. `None` if J is numerically rank deficient.
pub(crate) fn covariance(jac: &Mat<f64>, scale: f64) -> Option<Covariance> {
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
    if !(smin > smax * f64::EPSILON * (m.max(n) as f64)) {
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
