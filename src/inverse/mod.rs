//! Inverse problems: a generic weighted nonlinear least-squares solver that knows nothing of
//! beads.
//!
//! * [`fit`] — Levenberg–Marquardt with Moré's scaling (J. J. Moré, "The Levenberg–Marquardt
//!   algorithm: implementation and theory", Lecture Notes in Mathematics 630, 1978) on any
//!   [`Residuals`], with box bounds, infeasible regions, analytic or finite-difference
//!   Jacobians, and the covariance from the SVD of the Jacobian at the optimum;
//! * [`LevenbergMarquardt`] and [`LeastSquares`] — that solver as an argmin `Solver`, and the
//!   problem as argmin's `Operator` + `Jacobian` (residuals) and `CostFunction` + `Gradient`
//!   (χ²) on nalgebra vectors: [`fit`] runs under argmin's `Executor`, argmin's other solvers
//!   run on fitbead's problems, and observers, timeouts and iteration limits apply to both;
//!   the solver's state is [`LmState`] (argmin's `State` with λ, the trust radius, the scaling,
//!   the active set and the stage for observers), and `ProgressObserver` is the observer that
//!   counts a fit's model evaluations for a progress bar;
//! * [`ArgminResiduals`] — any argmin problem with residuals and their Jacobian
//!   (`Operator` + `Jacobian` on nalgebra vectors) fitted by fitbead's solver;
//! * [`ConfidenceIntervals::compute`] — covariance (Student-t / normal) and profile-likelihood
//!   intervals;
//! * [`WeightedData`] — a [`CurveModel`] y = f(x; p) with data (x, y, σ) seen as residuals;
//! * [`EnsembleSampler`] — Bayesian sampling of any [`LogDensity`] with the affine-invariant
//!   stretch move (J. Goodman & J. Weare, "Ensemble samplers with affine invariance", Comm.
//!   App. Math. Comp. Sci. 5, 2010; emcee's split-half parallel form, Foreman-Mackey et al.
//!   2013), reproducible for a seed whatever the thread count, run until the rank-normalised
//!   split-R̂ and bulk/tail effective sample sizes of Vehtari et al. (2021) meet their
//!   thresholds; the diagnostics (`mcmc::diagnostics`) work on any chains.
//!
//! The solver is validated on the 27 nonlinear problems of the NIST Statistical Reference
//! Datasets (StRD), from both starting points (`tests/it/nist.rs`).

pub mod estimate;
pub mod lm;
mod lmpar;
pub mod lsq;
pub mod mcmc;
pub(crate) mod observer;
pub mod odr;
pub mod posterior;
pub mod problem;
pub mod profile;
mod qr;
pub mod state;
#[cfg(test)]
mod suite;

pub use estimate::{fit, Covariance, Fit};
pub use lm::LevenbergMarquardt;
pub use lsq::{
    CurveModel, Infeasible, LsqError, LsqOptions, Residuals, SigmaKind, Termination, WeightedData,
};
pub use mcmc::{
    EnsembleSampler, LogDensity, McmcError, McmcOptions, McmcResult, ParameterDiagnostics,
    StopReason,
};
pub(crate) use odr::OdrFit;
pub use odr::{Odr, OdrModel, OdrProblem};
pub use problem::{ArgminResiduals, LeastSquares};
pub(crate) use profile::{covariance_intervals, profile_interval, DEFAULT_LEVEL};
pub use profile::{ConfidenceIntervals, Interval, ProfileEnd, ProfileInterval};
pub use state::{LmStage, LmState};
