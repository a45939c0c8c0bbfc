//! Least-squares problems and the solver's settings: [`Residuals`] (weighted residuals of n
//! parameters, analytic Jacobian optional), [`CurveModel`] with [`WeightedData`] (y = f(x; p) with data
//! (x, y, σ)), [`Infeasible`] points, [`LsqOptions`], the reasons a fit stops
//! ([`Termination`]) and malformed input ([`LsqError`]).
//!
//! The solver is [`super::LevenbergMarquardt`] (module `lm`), the problem as argmin sees it
//! [`super::LeastSquares`] (module `problem`), and the estimate [`super::fit`] (module
//! `estimate`).

use crate::progress::Tally;
use faer::MatMut;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use thiserror::Error;

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
pub trait CurveModel<X: ?Sized> {
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

/// Data (xᵢ, yᵢ, σᵢ) and a [`CurveModel`], seen as the residuals rᵢ = (yᵢ − f(xᵢ; p)) / σᵢ.
#[derive(Debug, Clone)]
pub struct WeightedData<X, M> {
    model: M,
    x: Vec<X>,
    y: Vec<f64>,
    inv_sigma: Vec<f64>,
}

impl<X, M: CurveModel<X>> WeightedData<X, M> {
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

impl<X, M: CurveModel<X>> Residuals for WeightedData<X, M> {
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
    /// argmin's executor failed (it does not for fitbead's solver and problems, whose
    /// numerical failures are [`Termination`] reasons).
    #[error("the solver failed: {0}")]
    Solver(String),
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
    /// With [`SigmaKind::Absolute`], scale the covariance by the reduced χ² all the same, as
    /// lmfit's `scale_covar=True` does: the σᵢ then give the relative weights only, and the
    /// intervals are those of [`SigmaKind::Relative`] (Student-t on m − n degrees of freedom,
    /// profile threshold s²·t²). Without effect under [`SigmaKind::Relative`], which scales
    /// already. Default false.
    pub scale_covar: bool,
    /// Refine a converged point by Gauss–Newton steps (see the module docs).
    pub polish: bool,
    /// Checked before every iteration and every trial step: once raised, the solver stops
    /// with [`Termination::Interrupted`] (e.g. from a signal handler). Profiles pass it on to
    /// their constrained fits.
    pub stop: Option<Arc<AtomicBool>>,
    /// Counts the model evaluations of the iterations — every residual vector and every
    /// analytic Jacobian, one each (a finite-difference Jacobian by its residual evaluations) —
    /// as the position of the caller's task, through a `ProgressObserver` that
    /// [`super::fit`] attaches to its executor (positions move once per iteration; the
    /// covariance's Jacobian at the end is not counted). Profiles pass it on to their
    /// constrained fits. The solver itself ignores it: a run built by hand under argmin's
    /// `Executor` counts by adding the observer.
    pub progress: Option<Tally>,
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
            scale_covar: false,
            polish: true,
            stop: None,
            progress: None,
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

/// Validated problem data shared by the solver and the profile.
#[derive(Debug, Clone)]
pub(crate) struct Setup {
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub typical: Vec<f64>,
    pub start: Vec<f64>,
}

impl Setup {
    /// The start a solver's `init` takes: `given` (the state's parameters, configured on
    /// argmin's `Executor`) projected onto the box, else the problem's start; an error when
    /// `given` has the wrong length or a non-finite entry.
    pub fn start_from(
        &self,
        given: Option<&nalgebra::DVector<f64>>,
    ) -> Result<Vec<f64>, argmin::core::Error> {
        let n = self.start.len();
        match given {
            None => Ok(self.start.clone()),
            Some(p) if p.len() == n && p.iter().all(|v| v.is_finite()) => Ok((0..n)
                .map(|j| p[j].clamp(self.lower[j], self.upper[j]))
                .collect()),
            Some(p) => Err(argmin::core::Error::msg(format!(
                "the initial parameter vector has length {} (expected {n}) or a \
                 non-finite entry",
                p.len()
            ))),
        }
    }
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
