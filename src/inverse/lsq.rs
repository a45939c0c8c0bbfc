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
//! * **Convergence** as in MINPACK: relative reduction (actual and predicted reductions of
//!   ‖f‖² both ≤ `ftol`), step size (Δ ≤ `xtol`·‖D p‖) or gradient (largest cosine between f and
//!   a column of J ≤ `gtol`); tolerances below ε count as ε (MINPACK's "tolerance too small"
//!   exits are these tests at ε). While the radius is held small by infeasible trial points a
//!   met test is reported as [`Termination::Stalled`] instead: the iteration is pressed against
//!   the edge of the feasible region, not at a minimum.
//! * **Gauss–Newton polish** (on by default). χ² is flat to rounding well before the parameters
//!   of an ill-conditioned problem are: once the relative reduction per step is below ε the
//!   ratio test cannot tell good steps from bad and the radius collapses, leaving the estimate
//!   ~√ε·cond away from the minimiser. A converged point is therefore refined by full
//!   Gauss–Newton steps (rank-revealing QR) as long as they contract and do not raise ‖f‖: the
//!   step is computed from Jᵀf, which still resolves the minimiser. On the NIST problems this
//!   lifts the worst parameter LRE from 6.6 to 7.8.
//! * **Restarts** (optional, off by default): after convergence, run again from the point
//!   reached with the scaling and radius recomputed there.
//!
//! Jacobians are analytic when [`Residuals::jacobian`] provides them, else central differences
//! with step h = ε^{1/3}·max(|p|, typical) — second-order one-sided differences next to a bound or
//! an infeasible point.
//!
//! The covariance comes from the SVD of the column-equilibrated Jacobian at the optimum,
//! (JᵀJ)⁻¹ = V Σ⁻² Vᵀ, never from an explicitly formed JᵀJ. It is validated against the NIST
//! Statistical Reference Datasets (StRD) for nonlinear regression — see `tests/it/nist.rs`.

// Index loops mirror the subscripts of the published algorithm (MINPACK-1).
#![allow(clippy::needless_range_loop)]

use faer::{Mat, MatMut};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
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

/// Solver settings. `Default` gives tolerances of 10⁻¹², at most 1000 iterations, no restart,
/// the Gauss–Newton polish, absolute σ and no bounds.
#[derive(Debug, Clone)]
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
    /// How many times the iteration is restarted from a converged point with fresh scaling and
    /// radius (default 0: on the NIST problems restarts change no result).
    pub restarts: usize,
    /// Scaling convention of the covariance.
    pub sigma: SigmaKind,
    /// Refine a converged point by Gauss–Newton steps (see the module docs).
    pub polish: bool,
    /// Checked before every iteration and every trial step: once raised, the solver stops
    /// with [`Termination::Interrupted`] (e.g. from a signal handler). Profiles pass it on to
    /// their constrained fits.
    pub stop: Option<Arc<AtomicBool>>,
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
            restarts: 0,
            sigma: SigmaKind::Absolute,
            polish: true,
            stop: None,
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
    /// Not converged: the step-size or reduction test was met while the trust region was held
    /// small by infeasible trial points — the iteration is stuck against the edge of the
    /// feasible region, where the optimum of the model lies beyond.
    Stalled,
    /// Not converged: the caller raised [`LsqOptions::stop`].
    Interrupted,
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
    /// Whether the last Jacobian came by finite differences.
    pub differenced: bool,
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
            differenced: false,
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
        self.differenced = false;
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
            None => {
                self.differenced = true;
                self.differences(x, f, jac)
                    && (0..self.n).all(|j| (0..self.m).all(|i| jac[(i, j)].is_finite()))
            }
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
            let (room_up, room_dn) = (self.upper[j] - xj, xj - self.lower[j]);
            if !(room_up > 0.0 || room_dn > 0.0) {
                // A parameter held fixed by its bounds: it cannot move.
                for i in 0..self.m {
                    jac[(i, j)] = 0.0;
                }
                continue;
            }
            let mut h0 = eta * xj.abs().max(self.typical[j]);
            if room_up < h0 && room_dn < h0 {
                // A box narrower than the step: difference across the wider side.
                h0 = room_up.max(room_dn);
            }
            // The divisors below are the differences of the points actually used.
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
        // Whatever the problem wrote there is not a residual vector.
        return done(
            x,
            Vec::new(),
            f64::INFINITY,
            Termination::InfeasibleStart,
            0,
        );
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
    // Set by an infeasible trial point, cleared by an accepted step the trust region did not
    // constrain (λ = 0): while set, a small radius or predicted reduction may be the edge of
    // the feasible region speaking, not a minimum.
    let mut edge = false;

    let stopped = || {
        opts.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    };
    loop {
        if outer >= opts.max_iterations {
            return done(x, f, fnorm, Termination::MaxIterations, iterations);
        }
        if stopped() {
            return done(x, f, fnorm, Termination::Interrupted, iterations);
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
        load_r(&mut sp, &mut ipvt, &qr, &acnorm);
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
            if stopped() {
                return done(x, f, fnorm, Termination::Interrupted, iterations);
            }
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
            if !feasible {
                edge = true;
            }
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
                if par == 0.0 {
                    edge = false;
                }
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

            let ftest = actred.abs() <= ftol && prered <= ftol && 0.5 * ratio <= 1.0;
            let xtest = delta <= xtol * xnorm || delta < f64::MIN_POSITIVE;
            if ftest || xtest {
                let t = if edge {
                    Termination::Stalled
                } else if ftest {
                    Termination::RelativeReduction
                } else {
                    Termination::StepSize
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

/// Copies R and the pivot of a column-pivoted QR into the subproblem. A diagonal entry below
/// n·ε times the norm of its (unpivoted) Jacobian column is set to zero: that column is a
/// combination of the earlier ones to working precision, and the subproblem then treats R as
/// singular (a basic least-squares step) instead of taking a step of size 1/ε along the null
/// direction. The test is relative to the column norm so that it is blind to the parameters'
/// scales.
fn load_r(
    sp: &mut Subproblem,
    ipvt: &mut [usize],
    qr: &faer::linalg::solvers::ColPivQr<f64>,
    colnorm: &[f64],
) {
    let n = ipvt.len();
    let r = qr.thin_R();
    let (fwd, _) = qr.P().arrays();
    ipvt.copy_from_slice(fwd);
    for j in 0..n {
        for i in 0..n {
            sp.r[i + j * n] = if i <= j { r[(i, j)] } else { 0.0 };
        }
        if r[(j, j)].abs() <= n as f64 * f64::EPSILON * colnorm[ipvt[j]] {
            sp.r[j + j * n] = 0.0;
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
        load_r(&mut sp, &mut ipvt, &qr, &diag);
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
        sol.iterations += 1;
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
/// assert!((fit.params[1] - 1.94).abs() < 1e-9);
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
            Some(s) if ev.jacobian(&sol.x, &sol.f, &mut jac) => {
                // Rank is judged to the precision of the Jacobian: ε for an analytic one,
                // ε^(2/3) (the central-difference error) for differences.
                let rtol = if ev.differenced {
                    10.0 * f64::EPSILON.powf(2.0 / 3.0)
                } else {
                    f64::EPSILON * m.max(n) as f64
                };
                covariance(&jac, s, rtol)
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inverse::profile::{confidence_intervals, ProfileEnd};
    use std::cell::Cell;

    /// y = a + b·x.
    struct Line;
    impl Model<f64> for Line {
        fn n_params(&self) -> usize {
            2
        }
        fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
            Ok(p[0] + p[1] * x)
        }
        fn gradient(&self, x: &f64, _p: &[f64], g: &mut [f64]) -> Option<Result<(), Infeasible>> {
            g[0] = 1.0;
            g[1] = *x;
            Some(Ok(()))
        }
    }

    /// y = a·exp(b·x), gradient by the solver's differences.
    struct Decay;
    impl Model<f64> for Decay {
        fn n_params(&self) -> usize {
            2
        }
        fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
            Ok(p[0] * (p[1] * x).exp())
        }
    }

    /// y = exp(b·x): one parameter.
    struct Exp1;
    impl Model<f64> for Exp1 {
        fn n_params(&self) -> usize {
            1
        }
        fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
            Ok((p[0] * x).exp())
        }
    }

    fn line_data() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let x = vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let y = vec![1.3, 2.9, 5.4, 6.8, 9.3, 10.7, 13.4];
        let s = vec![0.2, 0.3, 0.2, 0.5, 0.4, 0.3, 0.6];
        (x, y, s)
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    /// The weighted straight line against the textbook closed form (e.g. Press et al.,
    /// Numerical Recipes §15.2): Δ = S·Sxx − Sx², a = (Sxx·Sy − Sx·Sxy)/Δ,
    /// b = (S·Sxy − Sx·Sy)/Δ, var a = Sxx/Δ, var b = S/Δ, cov ab = −Sx/Δ.
    #[test]
    fn straight_line_matches_closed_form() {
        let (x, y, s) = line_data();
        let (mut s0, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..x.len() {
            let w = 1.0 / (s[i] * s[i]);
            s0 += w;
            sx += w * x[i];
            sy += w * y[i];
            sxx += w * x[i] * x[i];
            sxy += w * x[i] * y[i];
        }
        let d = s0 * sxx - sx * sx;
        let (a, b) = ((sxx * sy - sx * sxy) / d, (s0 * sxy - sx * sy) / d);
        let (vaa, vbb, vab) = (sxx / d, s0 / d, -sx / d);
        let chi2: f64 = (0..x.len())
            .map(|i| ((y[i] - a - b * x[i]) / s[i]).powi(2))
            .sum();
        let data = WeightedData::new(Line, x, y, Some(s)).unwrap();
        for sigma in [SigmaKind::Absolute, SigmaKind::Relative] {
            let opts = LsqOptions {
                sigma,
                ..Default::default()
            };
            let f = fit(&data, &[0.0, 0.0], &opts).unwrap();
            assert!(f.converged(), "{:?}", f.termination);
            assert!(close(f.params[0], a, 1e-12) && close(f.params[1], b, 1e-12));
            assert!(close(f.chi2, chi2, 1e-12));
            assert_eq!(f.dof, 5);
            let k = match sigma {
                SigmaKind::Absolute => 1.0,
                SigmaKind::Relative => chi2 / 5.0,
            };
            let c = f.covariance.as_ref().unwrap();
            assert!(close(c.matrix[(0, 0)], k * vaa, 1e-12));
            assert!(close(c.matrix[(1, 1)], k * vbb, 1e-12));
            assert!(close(c.matrix[(0, 1)], k * vab, 1e-12));
            assert!(close(c.matrix[(1, 0)], k * vab, 1e-12));
            assert!(close(c.std_errors[1], (k * vbb).sqrt(), 1e-12));
            assert!(close(
                c.correlation[(0, 1)],
                vab / (vaa * vbb).sqrt(),
                1e-12
            ));
            assert_eq!(c.correlation[(0, 0)], 1.0);
            // AIC/BIC as documented.
            let m: f64 = 7.0;
            match sigma {
                SigmaKind::Absolute => {
                    assert!(close(f.aic, chi2 + 4.0, 1e-12));
                    assert!(close(f.bic, chi2 + 2.0 * m.ln(), 1e-12));
                }
                SigmaKind::Relative => {
                    let m2ll = m * ((2.0 * std::f64::consts::PI * chi2 / m).ln() + 1.0);
                    assert!(close(f.aic, m2ll + 6.0, 1e-12));
                    assert!(close(f.bic, m2ll + 3.0 * m.ln(), 1e-12));
                }
            }
        }
    }

    /// For a linear model Δχ² is exactly quadratic, so the profile interval equals the
    /// covariance interval (z with absolute σ, Student-t with relative σ).
    #[test]
    fn linear_profile_equals_covariance_interval() {
        let (x, y, s) = line_data();
        let data = WeightedData::new(Line, x, y, Some(s)).unwrap();
        for sigma in [SigmaKind::Absolute, SigmaKind::Relative] {
            let opts = LsqOptions {
                sigma,
                ..Default::default()
            };
            let f = fit(&data, &[0.0, 0.0], &opts).unwrap();
            for level in [0.683, 0.95, 0.99] {
                let ci = confidence_intervals(&data, &f, level, &opts).unwrap();
                let wald = ci.covariance.as_ref().unwrap();
                for k in 0..2 {
                    let lo = ci.profile[k].lower.value().unwrap();
                    let hi = ci.profile[k].upper.value().unwrap();
                    let w = wald[k].upper - wald[k].lower;
                    assert!(
                        (lo - wald[k].lower).abs() <= 1e-8 * w,
                        "{sigma:?} {level} {k}: {lo} vs {}",
                        wald[k].lower
                    );
                    assert!(
                        (hi - wald[k].upper).abs() <= 1e-8 * w,
                        "{sigma:?} {level} {k}: {hi} vs {}",
                        wald[k].upper
                    );
                }
            }
        }
    }

    fn exp_data() -> (Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = (0..10).map(|i| 0.3 * i as f64).collect();
        let noise = [0.05, -0.08, 0.1, -0.02, 0.07, -0.1, 0.04, 0.09, -0.06, 0.03];
        let y = x
            .iter()
            .zip(noise)
            .map(|(x, e)| (0.8 * x).exp() + e)
            .collect();
        (x, y)
    }

    /// y = exp(b·x): χ²(b) is far from quadratic, the profile interval is asymmetric, and its
    /// ends are where Δχ² equals the threshold.
    #[test]
    fn exponential_profile_is_asymmetric() {
        let (x, y) = exp_data();
        let sigma = vec![1.5; x.len()];
        let data = WeightedData::new(Exp1, x, y, Some(sigma)).unwrap();
        let opts = LsqOptions::default();
        let f = fit(&data, &[0.1], &opts).unwrap();
        assert!(f.converged());
        let ci = confidence_intervals(&data, &f, 0.95, &opts).unwrap();
        let b = f.params[0];
        let lo = ci.profile[0].lower.value().unwrap();
        let hi = ci.profile[0].upper.value().unwrap();
        assert!(lo < b && b < hi);
        let (below, above) = (b - lo, hi - b);
        assert!(below > 1.2 * above, "below {below}, above {above}");
        // Δχ² at both ends equals the χ²₁ quantile 1.959964² = 3.841459.
        let chi2 = |v: f64| {
            let mut r = vec![0.0; 10];
            data.residuals(&[v], &mut r).unwrap();
            r.iter().map(|v| v * v).sum::<f64>()
        };
        assert!((ci.threshold - 3.841458820694124).abs() < 1e-9);
        for end in [lo, hi] {
            assert!((chi2(end) - f.chi2 - ci.threshold).abs() < 1e-7);
        }
        // The Wald interval is symmetric and differs from the profile one.
        let wald = &ci.covariance.unwrap()[0];
        assert!(((wald.upper - b) - (b - wald.lower)).abs() < 1e-12);
        assert!((wald.lower - lo).abs() > 1e-3 * (hi - lo));
    }

    /// Two parameters: each profile point is a re-minimisation over the other.
    #[test]
    fn profile_with_reminimisation() {
        let (x, y) = exp_data();
        let sigma = vec![0.3; x.len()];
        let data = WeightedData::new(Decay, x, y, Some(sigma)).unwrap();
        let opts = LsqOptions::default();
        let f = fit(&data, &[1.0, 0.1], &opts).unwrap();
        assert!(f.converged());
        let ci = confidence_intervals(&data, &f, 0.95, &opts).unwrap();
        for k in 0..2 {
            let p = ci.profile[k];
            let (lo, hi) = (p.lower.value().unwrap(), p.upper.value().unwrap());
            assert!(lo < f.params[k] && f.params[k] < hi);
            // Check one end: fix parameter k there and re-fit the other from afar.
            let other = 1 - k;
            let mut lower = vec![f64::NEG_INFINITY; 2];
            let mut upper = vec![f64::INFINITY; 2];
            lower[k] = hi;
            upper[k] = hi;
            let mut start = f.params.clone();
            start[k] = hi;
            start[other] *= 0.7;
            let o = LsqOptions {
                lower: Some(lower),
                upper: Some(upper),
                ..opts.clone()
            };
            let g = fit(&data, &start, &o).unwrap();
            assert!(g.converged());
            assert!(
                (g.chi2 - f.chi2 - ci.threshold).abs() < 1e-7,
                "{k}: {}",
                g.chi2 - f.chi2
            );
        }
    }

    #[test]
    fn bounds_are_respected() {
        let (x, y) = exp_data();
        let data = WeightedData::new(Decay, x, y, None).unwrap();
        // Unconstrained b ≈ 0.8; cap it at 0.7 and hold a ≥ 1.05.
        let opts = LsqOptions {
            lower: Some(vec![1.05, f64::NEG_INFINITY]),
            upper: Some(vec![f64::INFINITY, 0.7]),
            ..Default::default()
        };
        let evals = Cell::new(0usize);
        struct Watch<'a, R> {
            inner: R,
            lo: [f64; 2],
            hi: [f64; 2],
            evals: &'a Cell<usize>,
        }
        impl<R: Residuals> Residuals for Watch<'_, R> {
            fn n_params(&self) -> usize {
                2
            }
            fn n_residuals(&self) -> usize {
                self.inner.n_residuals()
            }
            fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
                assert!(
                    p[0] >= self.lo[0] && p[1] <= self.hi[1],
                    "outside the box: {p:?}"
                );
                self.evals.set(self.evals.get() + 1);
                self.inner.residuals(p, out)
            }
        }
        let w = Watch {
            inner: &data,
            lo: [1.05, f64::NEG_INFINITY],
            hi: [f64::INFINITY, 0.7],
            evals: &evals,
        };
        // Start outside the box: projected.
        let f = fit(&w, &[0.5, 2.0], &opts).unwrap();
        assert!(f.converged(), "{:?}", f.termination);
        assert_eq!(f.params[1], 0.7);
        assert!(f.params[0] >= 1.05);
        assert!(f.at_bound[1]);
        assert_eq!(evals.get(), f.residual_evals);
        // The bound on b is active: the unconstrained optimum has a larger χ².
        let free = fit(&data, &[0.5, 2.0], &LsqOptions::default()).unwrap();
        assert!(free.params[1] > 0.7 && free.chi2 < f.chi2);
        assert!(!free.at_bound.iter().any(|b| *b));
        // With the bound inactive the answer is the unconstrained one.
        let loose = LsqOptions {
            upper: Some(vec![10.0, 10.0]),
            ..Default::default()
        };
        let g = fit(&data, &[0.5, 2.0], &loose).unwrap();
        assert!(close(g.params[1], free.params[1], 1e-9));
    }

    /// y = √(c − x)·d, infeasible for c ≤ max x; the optimum is feasible but the first
    /// trust-region steps from far away cross into the infeasible region.
    struct Root;
    impl Model<f64> for Root {
        fn n_params(&self) -> usize {
            2
        }
        fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
            if p[0] - x <= 0.0 {
                return Err(Infeasible);
            }
            Ok((p[0] - x).sqrt() * p[1])
        }
    }

    #[test]
    fn infeasible_region_is_a_rejected_step() {
        let x: Vec<f64> = (0..8).map(|i| i as f64).collect();
        let y: Vec<f64> = x.iter().map(|x| (7.5f64 - x).sqrt() * 2.0).collect();
        let data = WeightedData::new(Root, x, y, None).unwrap();
        let infeasible = Cell::new(0usize);
        struct Count<'a, R> {
            inner: R,
            bad: &'a Cell<usize>,
        }
        impl<R: Residuals> Residuals for Count<'_, R> {
            fn n_params(&self) -> usize {
                self.inner.n_params()
            }
            fn n_residuals(&self) -> usize {
                self.inner.n_residuals()
            }
            fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
                let r = self.inner.residuals(p, out);
                if r.is_err() {
                    self.bad.set(self.bad.get() + 1);
                }
                r
            }
        }
        let c = Count {
            inner: &data,
            bad: &infeasible,
        };
        let f = fit(&c, &[40.0, 0.1], &LsqOptions::default()).unwrap();
        assert!(f.converged(), "{:?}", f.termination);
        assert!(infeasible.get() > 0, "the test should cross the edge");
        assert!(close(f.params[0], 7.5, 1e-9) && close(f.params[1], 2.0, 1e-9));
        assert!(f.params.iter().chain(&f.residuals).all(|v| v.is_finite()));

        // Infeasible start: reported, not converged, nothing NaN.
        let g = fit(&data, &[3.0, 1.0], &LsqOptions::default()).unwrap();
        assert_eq!(g.termination, Termination::InfeasibleStart);
        assert!(!g.converged() && g.chi2 == f64::INFINITY && g.covariance.is_none());
        assert!(g.params.iter().all(|v| v.is_finite()) && g.residuals.is_empty());
    }

    /// r = p + 1 wants p = −1, but p < 0 is infeasible: the solver must not claim convergence
    /// at the edge, nor ever hand back a NaN.
    #[test]
    fn optimum_beyond_the_feasible_edge_is_not_convergence() {
        struct Edge;
        impl Residuals for Edge {
            fn n_params(&self) -> usize {
                1
            }
            fn n_residuals(&self) -> usize {
                1
            }
            fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
                if p[0] < 0.0 {
                    return Err(Infeasible);
                }
                out[0] = p[0] + 1.0;
                Ok(())
            }
        }
        let f = fit(&Edge, &[5.0], &LsqOptions::default()).unwrap();
        assert!(!f.converged(), "{:?}", f.termination);
        assert!(f.params[0] >= 0.0 && f.params[0] < 1e-3);
        // NaN residuals count as infeasible too.
        struct NanBelow;
        impl Residuals for NanBelow {
            fn n_params(&self) -> usize {
                1
            }
            fn n_residuals(&self) -> usize {
                1
            }
            fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
                out[0] = p[0].sqrt() + 1.0;
                Ok(())
            }
        }
        let f = fit(&NanBelow, &[5.0], &LsqOptions::default()).unwrap();
        assert!(!f.converged(), "{:?}", f.termination);
        assert!(f.params[0].is_finite() && f.chi2.is_finite());
    }

    #[test]
    fn differences_agree_with_analytic_jacobian() {
        struct LineNoGrad;
        impl Model<f64> for LineNoGrad {
            fn n_params(&self) -> usize {
                2
            }
            fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
                Ok(p[0] + p[1] * x)
            }
        }
        let (x, y, s) = line_data();
        let a = WeightedData::new(Line, x.clone(), y.clone(), Some(s.clone())).unwrap();
        let b = WeightedData::new(LineNoGrad, x, y, Some(s)).unwrap();
        let fa = fit(&a, &[0.0, 0.0], &LsqOptions::default()).unwrap();
        let fb = fit(&b, &[0.0, 0.0], &LsqOptions::default()).unwrap();
        for k in 0..2 {
            assert!(close(fb.params[k], fa.params[k], 1e-10));
            assert!(close(
                fb.std_errors().unwrap()[k],
                fa.std_errors().unwrap()[k],
                1e-8
            ));
        }
    }

    #[test]
    fn limits_and_rank_deficiency_are_reported() {
        let (x, y) = exp_data();
        let data = WeightedData::new(Decay, x.clone(), y.clone(), None).unwrap();
        let opts = LsqOptions {
            max_iterations: 1,
            restarts: 0,
            ..Default::default()
        };
        let f = fit(&data, &[0.01, 3.0], &opts).unwrap();
        assert_eq!(f.termination, Termination::MaxIterations);
        assert!(!f.converged());
        // y = a + b (two names for one constant): J has rank 1, no covariance.
        struct Twice;
        impl Model<f64> for Twice {
            fn n_params(&self) -> usize {
                2
            }
            fn value(&self, _x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
                Ok(p[0] + p[1])
            }
            fn gradient(
                &self,
                _x: &f64,
                _p: &[f64],
                g: &mut [f64],
            ) -> Option<Result<(), Infeasible>> {
                g.fill(1.0);
                Some(Ok(()))
            }
        }
        let d = WeightedData::new(Twice, x, y, None).unwrap();
        let f = fit(&d, &[1.0, 1.0], &LsqOptions::default()).unwrap();
        assert!(f.converged(), "{:?}", f.termination);
        assert!(f.covariance.is_none());
        let mean = d.y.iter().sum::<f64>() / d.y.len() as f64;
        assert!(close(f.params[0] + f.params[1], mean, 1e-12));
    }

    #[test]
    fn bad_input_is_an_error() {
        let (x, y) = exp_data();
        let data = WeightedData::new(Decay, x.clone(), y.clone(), None).unwrap();
        let o = LsqOptions::default();
        assert!(matches!(
            fit(&data, &[1.0], &o),
            Err(LsqError::Length { .. })
        ));
        assert!(matches!(
            fit(&data, &[1.0, f64::NAN], &o),
            Err(LsqError::NonFinite { .. })
        ));
        let b = LsqOptions {
            lower: Some(vec![0.0, 2.0]),
            upper: Some(vec![1.0, 1.0]),
            ..Default::default()
        };
        assert_eq!(fit(&data, &[0.5, 1.5], &b), Err(LsqError::Bounds(1)));
        let t = LsqOptions {
            ftol: -1.0,
            ..Default::default()
        };
        assert!(matches!(
            fit(&data, &[1.0, 1.0], &t),
            Err(LsqError::Option { .. })
        ));
        assert!(WeightedData::new(Decay, x.clone(), y[..3].to_vec(), None).is_err());
        assert!(WeightedData::new(Decay, x, y, Some(vec![0.0; 10])).is_err());
        let few = WeightedData::new(Decay, vec![1.0], vec![1.0], None).unwrap();
        assert_eq!(
            fit(&few, &[1.0, 1.0], &o),
            Err(LsqError::Shape { m: 1, n: 2 })
        );
    }

    #[test]
    fn one_sided_profile_end_at_a_bound() {
        let (x, y) = exp_data();
        let sigma = vec![0.3; x.len()];
        let data = WeightedData::new(Exp1, x, y, Some(sigma)).unwrap();
        let opts = LsqOptions {
            upper: Some(vec![0.8]),
            ..Default::default()
        };
        let f = fit(&data, &[0.1], &opts).unwrap();
        assert!(f.converged());
        let ci = confidence_intervals(&data, &f, 0.95, &opts).unwrap();
        assert_eq!(ci.profile[0].upper, ProfileEnd::Bound(0.8));
        assert!(ci.profile[0].lower.value().is_some());

        // An infeasible region inside the interval: the end is the edge reached.
        struct Capped(WeightedData<f64, Exp1>, f64);
        impl Residuals for Capped {
            fn n_params(&self) -> usize {
                1
            }
            fn n_residuals(&self) -> usize {
                self.0.n_residuals()
            }
            fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
                if p[0] > self.1 {
                    return Err(Infeasible);
                }
                self.0.residuals(p, out)
            }
        }
        let free = fit(&data, &[0.1], &LsqOptions::default()).unwrap();
        let ci = confidence_intervals(&data, &free, 0.95, &LsqOptions::default()).unwrap();
        let hi = ci.profile[0].upper.value().unwrap();
        let cap = free.params[0] + 0.5 * (hi - free.params[0]);
        let capped = Capped(data, cap);
        let f = fit(&capped, &[0.1], &LsqOptions::default()).unwrap();
        assert!(f.converged());
        let ci = confidence_intervals(&capped, &f, 0.95, &LsqOptions::default()).unwrap();
        match ci.profile[0].upper {
            ProfileEnd::Edge(v) => assert!(v <= cap && v > cap - 0.01 * (hi - f.params[0])),
            other => panic!("{other:?}"),
        }
    }
}
