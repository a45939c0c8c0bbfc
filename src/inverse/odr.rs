//! Weighted orthogonal distance regression (ODR) of explicit models y = f(x; β) whose input x
//! is measured with error as well as the response y: [`Odr`], an argmin `Solver` on an
//! [`OdrProblem`], returning the estimate with its covariance and the adjusted inputs.
//!
//! With σ_y,i and σ_x,i the standard deviations of point i, ODR minimises over the parameters β
//! and one correction δ_i of every input
//!
//! S(β, δ) = Σ_i [ ((y_i − f_i(x_i + δ_i; β)) / σ_y,i)² + (δ_i / σ_x,i)² ],
//!
//! the method of ODRPACK (P. T. Boggs, R. H. Byrd & R. B. Schnabel, "A stable and efficient
//! algorithm for nonlinear orthogonal distance regression", SIAM J. Sci. Stat. Comput. 8 (1987)
//! 1052–1078; P. T. Boggs, J. R. Donaldson, R. H. Byrd & R. B. Schnabel, "ODRPACK: software for
//! weighted orthogonal distance regression", ACM TOMS 15 (1989) 348–364):
//!
//! * **A Levenberg–Marquardt step on (β, δ) with the δ's eliminated in closed form.** The
//!   linearised residuals are r_i + a_i·s + d_i t_i (response) and ρ_i + e_i t_i (input), with
//!   a_i = ∂r_i/∂β, d_i = ∂r_i/∂δ_i, e_i = 1/σ_x,i. For a damping λ and scaling D, each
//!   correction step t_i depends on the parameter step s alone, and minimising it out leaves
//!   the weighted, damped linear least-squares problem
//!   min Σ ω_i (r_i − c_i + a_i·s)² + λ‖D_β s‖², with h_i = e_i² + λ D_δ,i²,
//!   ω_i = h_i/(d_i² + h_i) and c_i = d_i e_i ρ_i / h_i; then
//!   t_i = −(d_i (r_i + a_i·s) + e_i ρ_i)/(d_i² + h_i). A step costs O(n p²), never O((n + p)³).
//! * **Damping** by the gain ratio of actual to predicted reduction of S (Marquardt's update
//!   in the form of H. B. Nielsen, "Damping parameter in Marquardt's method", IMM DTU
//!   REP-1999-05): a step is accepted when the ratio exceeds 10⁻⁴; the scaling D is the running
//!   maximum of the column norms of the full Jacobian (Moré 1978 §6), so the method is blind to
//!   the units of β and x.
//! * **Two stages.** The parameters are first fitted with every input held at its measured
//!   value (weighted least squares, δ = 0); then each correction is moved to its best value at
//!   those parameters (a few safeguarded Newton steps per point, on a three-point stencil of
//!   f_i in x), and the full iteration runs from there. Starting the full iteration from
//!   δ = 0 at a distant start lets inputs far from the curve dominate the first steps, which
//!   can then walk into a local minimum (SciPy's Pearson example, either way round, from its
//!   start (1, 1)).
//! * **Inputs that leave the model's domain.** A trial point where some f_i(x_i + δ_i; β) is
//!   [`Infeasible`] (or not finite) is a rejected step, so that no accepted input ever leaves
//!   the model's domain — for the bead fits, no adjusted slope leaves the steady range.
//! * **Fixed inputs.** σ_x,i = 0 holds x_i exact (δ_i = 0; ODRPACK's `ifixx`).
//! * **Derivatives** analytic where [`OdrModel::derivatives`] gives them, else central
//!   differences with steps ε^{1/3}·max(|β_j|, typical) and ε^{1/3}·max(|x|, σ_x), one-sided
//!   (second order) where one side is infeasible or outside the box.
//! * **Covariance** as ODRPACK gives it: the β block of the inverse of the Gauss–Newton matrix
//!   of (β, δ), which, the δ's eliminated, is (Σ_i w_i g_i g_iᵀ)⁻¹ with g_i = ∂f_i/∂β and the
//!   effective weight w_i = 1/(σ_y,i² + (∂f_i/∂x)² σ_x,i²) at the adjusted inputs. It is
//!   unscaled when the σ's are absolute ([`SigmaKind::Absolute`]) and scaled by the residual
//!   variance S/(n − p) when the responses carry no σ ([`SigmaKind::Relative`]: σ_x is then a
//!   relative weight, as in ODRPACK).
//!
//! Validated on ODRPACK's own explicit examples as SciPy's `scipy.odr` runs them
//! (`tests/reference/odr/odrpack_examples.json`, checked in `inverse/suite/odr.rs`).

// Index loops mirror the subscripts of the formulas.
#![allow(clippy::needless_range_loop)]

use argmin::core::observers::ObserverMode;
use argmin::core::{Error, Executor, Problem, Solver, State, TerminationReason, KV};
use faer::Mat;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::Ordering;
use std::sync::Mutex;

use super::estimate::{covariance, covariance_scale, information_criteria, rank_tolerance, Fit};
use super::lsq::{
    validate, Infeasible, LsqError, LsqOptions, Residuals, Setup, SigmaKind, Termination,
};
use super::observer::ProgressObserver;
use super::state::{LmStage, LmState};

/// An explicit model for orthogonal distance regression: point i's response f_i(x; β) to an
/// input x (the point's other coordinates, exact, are the model's to keep).
pub trait OdrModel {
    /// Number of parameters p.
    fn n_params(&self) -> usize;
    /// Number of points n.
    fn n_points(&self) -> usize;
    /// f_i(x; β), or [`Infeasible`] where the model has no value (outside its domain).
    fn value(&self, i: usize, x: f64, p: &[f64]) -> Result<f64, Infeasible>;
    /// ∂f_i/∂β into `grad` and ∂f_i/∂x as the result; `None` (the default) to let the solver
    /// difference.
    fn derivatives(
        &self,
        i: usize,
        x: f64,
        p: &[f64],
        grad: &mut [f64],
    ) -> Option<Result<f64, Infeasible>> {
        let _ = (i, x, p, grad);
        None
    }
}

impl<M: OdrModel + ?Sized> OdrModel for &M {
    fn n_params(&self) -> usize {
        (**self).n_params()
    }
    fn n_points(&self) -> usize {
        (**self).n_points()
    }
    fn value(&self, i: usize, x: f64, p: &[f64]) -> Result<f64, Infeasible> {
        (**self).value(i, x, p)
    }
    fn derivatives(
        &self,
        i: usize,
        x: f64,
        p: &[f64],
        grad: &mut [f64],
    ) -> Option<Result<f64, Infeasible>> {
        (**self).derivatives(i, x, p, grad)
    }
}

/// Data (x_i, y_i, σ_x,i, σ_y,i) and an [`OdrModel`], with the parameters' box, typical
/// magnitudes and start: the problem of [`Odr`].
#[derive(Debug, Clone)]
pub struct OdrProblem<M> {
    model: M,
    x: Vec<f64>,
    y: Vec<f64>,
    inv_sy: Vec<f64>,
    /// 1/σ_x (0 where the input is exact).
    inv_sx: Vec<f64>,
    sx: Vec<f64>,
    setup: Setup,
    /// The start is the weighted least-squares optimum with the inputs held: the first stage
    /// is skipped.
    at_optimum: bool,
}

impl<M: OdrModel> OdrProblem<M> {
    /// The problem of fitting `model` to inputs `x` with standard deviations `sigma_x` (each
    /// finite and ≥ 0; 0 holds the input exact) and responses `y` with standard deviations
    /// `sigma_y` (each finite and > 0; `None` for unit weights), from `start`, with the box and
    /// typical magnitudes of `opts`.
    pub fn new(
        model: M,
        x: Vec<f64>,
        y: Vec<f64>,
        sigma_x: Vec<f64>,
        sigma_y: Option<Vec<f64>>,
        start: &[f64],
        opts: &LsqOptions,
    ) -> Result<Self, LsqError> {
        let n = model.n_points();
        for (what, v) in [("x", &x), ("y", &y), ("sigma_x", &sigma_x)] {
            if v.len() != n {
                return Err(LsqError::Length {
                    what,
                    got: v.len(),
                    expected: n,
                });
            }
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(LsqError::NonFinite {
                what: "x",
                index: i,
            });
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(LsqError::NonFinite {
                what: "y",
                index: i,
            });
        }
        if let Some(i) = sigma_x.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(LsqError::NonFinite {
                what: "sigma_x (must be finite and ≥ 0)",
                index: i,
            });
        }
        let inv_sy = match sigma_y {
            None => vec![1.0; n],
            Some(s) => {
                if s.len() != n {
                    return Err(LsqError::Length {
                        what: "sigma_y",
                        got: s.len(),
                        expected: n,
                    });
                }
                if let Some(i) = s.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                    return Err(LsqError::NonFinite {
                        what: "sigma_y (must be finite and > 0)",
                        index: i,
                    });
                }
                s.iter().map(|v| 1.0 / v).collect()
            }
        };
        let inv_sx = sigma_x
            .iter()
            .map(|&s| if s > 0.0 { 1.0 / s } else { 0.0 })
            .collect();
        let setup = validate(&Shape(model.n_params(), n), start, opts)?;
        Ok(OdrProblem {
            model,
            x,
            y,
            inv_sy,
            inv_sx,
            sx: sigma_x,
            setup,
            at_optimum: false,
        })
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The starting point, projected onto the box.
    pub fn start(&self) -> &[f64] {
        &self.setup.start
    }

    /// Declares the start the weighted least-squares optimum with every input held: the
    /// solver's first stage (module docs) is then skipped.
    pub(crate) fn started_at_optimum(mut self) -> Self {
        self.at_optimum = true;
        self
    }

    fn n(&self) -> usize {
        self.x.len()
    }

    fn p(&self) -> usize {
        self.setup.start.len()
    }

    fn free(&self, i: usize) -> bool {
        self.inv_sx[i] > 0.0
    }

    /// ∂f_i/∂x at input `xi` (where f_i = `f0`) and parameters β, by the differences of
    /// [`difference`] with step ε^{1/3}·max(|x|, σ_x,i); `None` where both sides are infeasible.
    fn x_slope(&self, i: usize, xi: f64, f0: f64, beta: &[f64]) -> Option<f64> {
        let h = STEP * xi.abs().max(self.sx[i]);
        let inf = f64::INFINITY;
        difference(f0, h, -inf, inf, |t| self.model.value(i, xi + t, beta).ok())
    }

    /// The best correction of input i at parameters β, from `at` = (r_i, ρ_i, δ_i), a feasible
    /// point: safeguarded Newton steps on φ(δ) = r_i(δ)² + ρ_i(δ)² (at most `SETTLE`), each
    /// halved until it lowers φ. The derivatives of f_i in x are those of the quadratic through
    /// three equally spaced values (the point and two at steps h = ε^{1/3}·max(|x|, σ_x,i),
    /// central where both sides are feasible), or the model's [`OdrModel::derivatives`] (then
    /// Gauss–Newton: f″ taken as 0); the curvature r′² + ρ′² + r·r″ of φ/2 falls back to the
    /// Gauss–Newton r′² + ρ′² where it is below half of it. A step that stays within the
    /// interpolated span ends the search there, with r_i from the quadratic (its error, of
    /// order f‴h³, is below rounding), so that a start near the optimum costs two model
    /// evaluations; any other step is evaluated, and the search ends once one gains less than
    /// 1e-15 of φ. Returns the point reached, counting its
    /// derivative evaluations into `evals`.
    fn correct(
        &self,
        i: usize,
        beta: &[f64],
        at: (f64, f64, f64),
        evals: &mut usize,
    ) -> (f64, f64, f64) {
        let (mut r, mut rho, mut delta) = at;
        if !self.free(i) {
            return at;
        }
        let (isy, isx) = (self.inv_sy[i], self.inv_sx[i]);
        let mut g = vec![0.0; beta.len()];
        for _ in 0..SETTLE {
            let xi = self.x[i] + delta;
            let f0 = self.y[i] - r / isy;
            *evals += 1;
            let local = match self.model.derivatives(i, xi, beta, &mut g) {
                Some(Ok(fx)) => Some(Local {
                    f1: fx,
                    f2: 0.0,
                    span: (0.0, 0.0),
                }),
                Some(Err(_)) => None,
                None => {
                    let h = STEP * xi.abs().max(self.sx[i]);
                    quadratic(f0, h, |t| {
                        self.model
                            .value(i, xi + t, beta)
                            .ok()
                            .filter(|v| v.is_finite())
                    })
                }
            };
            let Some(q) = local.filter(|q| q.f1.is_finite() && q.f2.is_finite()) else {
                break;
            };
            // r′ and r″ (r = (y − f)/σ_y), the gradient and curvature of φ/2.
            let (d, dd) = (-q.f1 * isy, -q.f2 * isy);
            let grad = d * r + isx * rho;
            let gauss = d * d + isx * isx;
            let newton = gauss + r * dd;
            let mut t = -grad / if newton >= 0.5 * gauss { newton } else { gauss };
            if !t.is_finite() {
                break;
            }
            if q.span.0 <= t && t <= q.span.1 {
                delta += t;
                r += t * (d + 0.5 * dd * t);
                rho = delta * isx;
                break;
            }
            let before = r * r + rho * rho;
            let mut gain = 0.0;
            for _ in 0..30 {
                let trial = delta + t;
                if let Ok(f) = self.model.value(i, self.x[i] + trial, beta) {
                    let (r1, rho1) = ((self.y[i] - f) * isy, trial * isx);
                    let after = r1 * r1 + rho1 * rho1;
                    if after < before {
                        (r, rho, delta, gain) = (r1, rho1, trial, before - after);
                        break;
                    }
                }
                t *= 0.5;
            }
            if !(gain > 1e-15 * before) {
                break;
            }
        }
        (r, rho, delta)
    }

    /// The objective minimised over the corrections at each β, as least-squares residuals
    /// (r_i, then ρ_i, at each input's best correction): what the profile intervals of an ODR
    /// fit profile. Each evaluation searches each correction from its optimum at the nearest
    /// parameters evaluated so far (continuation), starting with the fit's `delta` at `beta`.
    pub(crate) fn reduced(&self, beta: &[f64], delta: Vec<f64>) -> Reduced<'_, M> {
        Reduced {
            problem: self,
            fitted: delta.clone(),
            seen: Mutex::new(vec![(beta.to_vec(), delta)]),
        }
    }
}

/// [`OdrProblem::reduced`]: S(β, δ*(β)) as 2n residuals of β alone.
pub(crate) struct Reduced<'a, M> {
    problem: &'a OdrProblem<M>,
    /// The fit's corrections: where a search starts when the nearest optimum is infeasible.
    fitted: Vec<f64>,
    /// The parameters evaluated so far and the optimal corrections there.
    seen: Mutex<Vec<(Vec<f64>, Vec<f64>)>>,
}

impl<M: OdrModel> Reduced<'_, M> {
    /// The corrections at the evaluated parameters nearest to `p` (distances scaled by the
    /// typical magnitudes).
    fn nearest(&self, p: &[f64]) -> Vec<f64> {
        let typical = &self.problem.setup.typical;
        let distance = |q: &[f64]| -> f64 {
            p.iter()
                .zip(q)
                .zip(typical)
                .map(|((a, b), t)| ((a - b) / t.max(f64::MIN_POSITIVE)).powi(2))
                .sum()
        };
        let seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        seen.iter()
            .min_by(|a, b| distance(&a.0).total_cmp(&distance(&b.0)))
            .map_or_else(|| self.fitted.clone(), |s| s.1.clone())
    }
}

impl<M: OdrModel + Sync> Residuals for Reduced<'_, M> {
    fn n_params(&self) -> usize {
        self.problem.p()
    }
    fn n_residuals(&self) -> usize {
        2 * self.problem.n()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        let pr = self.problem;
        let n = pr.n();
        let near = self.nearest(p);
        let points: Vec<(f64, f64, f64)> = (0..n)
            .into_par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|i| {
                // From the nearest optimum, else the fit's correction, else the measured input.
                let start = [near[i], self.fitted[i], 0.0].into_iter().find_map(|d| {
                    let f = pr.model.value(i, pr.x[i] + d, p).ok()?;
                    f.is_finite()
                        .then(|| ((pr.y[i] - f) * pr.inv_sy[i], d * pr.inv_sx[i], d))
                });
                let mut evals = 0;
                Ok(pr.correct(i, p, start.ok_or(Infeasible)?, &mut evals))
            })
            .collect::<Result<_, Infeasible>>()?;
        let (r, rho) = out.split_at_mut(n);
        for (i, &(ri, rhoi, _)) in points.iter().enumerate() {
            r[i] = ri;
            rho[i] = rhoi;
        }
        let mut seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        seen.push((p.to_vec(), points.into_iter().map(|t| t.2).collect()));
        Ok(())
    }
}

/// The dimensions alone, for the checks of the start, box and typical magnitudes shared with
/// the least-squares solver.
struct Shape(usize, usize);

impl Residuals for Shape {
    fn n_params(&self) -> usize {
        self.0
    }
    fn n_residuals(&self) -> usize {
        self.1
    }
    fn residuals(&self, _: &[f64], _: &mut [f64]) -> Result<(), Infeasible> {
        Err(Infeasible)
    }
}

/// Where the iteration is: parameters, corrections, the weighted residuals and S.
#[derive(Debug, Clone, Default)]
struct Point {
    beta: Vec<f64>,
    delta: Vec<f64>,
    /// (y_i − f_i(x_i + δ_i; β))/σ_y,i.
    r: Vec<f64>,
    /// δ_i/σ_x,i (0 for exact inputs).
    rho: Vec<f64>,
    s: f64,
}

/// The linearisation at a point: a_i = ∂r_i/∂β (row-major, n × p) and d_i = ∂r_i/∂δ_i.
#[derive(Debug, Clone, Default)]
struct Linear {
    a: Vec<f64>,
    d: Vec<f64>,
}

/// Orthogonal distance regression as an argmin `Solver` on an [`OdrProblem`], with the
/// tolerances, iteration limit and stop flag of [`LsqOptions`] and [`LmState`] as its state
/// (λ is the damping; `radius` is unused), so that [`Odr::fit`] counts its evaluations for a
/// progress bar like the least-squares fits. See the module docs for the method.
///
/// ```
/// use fitbead::inverse::{Infeasible, LsqOptions, Odr, OdrModel, OdrProblem, SigmaKind};
/// // A straight line through points with errors in both coordinates.
/// struct Line;
/// impl OdrModel for Line {
///     fn n_params(&self) -> usize { 2 }
///     fn n_points(&self) -> usize { 4 }
///     fn value(&self, _: usize, x: f64, p: &[f64]) -> Result<f64, Infeasible> {
///         Ok(p[0] + p[1] * x)
///     }
/// }
/// let opts = LsqOptions { sigma: SigmaKind::Relative, ..Default::default() };
/// let x = vec![0.0, 1.0, 2.0, 3.0];
/// let y = vec![-0.1, 1.1, 1.9, 3.1];
/// let problem = OdrProblem::new(Line, x, y, vec![0.1; 4], Some(vec![0.1; 4]), &[0.4, 0.4], &opts)
///     .unwrap();
/// let (fit, x_fit) = Odr::fit(problem, &opts).unwrap();
/// assert!(fit.converged());
/// // ODRPACK (scipy.odr, SciPy's test_work_ind): β = (−0.0648034, 1.0432023).
/// assert!((fit.params[1] - 1.0432023).abs() < 1e-6);
/// assert_eq!(x_fit.len(), 4);
/// ```
#[derive(Debug, Clone)]
pub struct Odr {
    ftol: f64,
    xtol: f64,
    max_evals: usize,
    stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    cur: Point,
    lin: Linear,
    /// Scaling of β (p) and of δ (n).
    d_beta: Vec<f64>,
    d_delta: Vec<f64>,
    lambda: f64,
    nu: f64,
    steps: usize,
    nfev: usize,
    njev: usize,
    /// Inputs held at their measured values (the first stage: module docs).
    frozen: bool,
    /// Whether some derivative was differenced (the covariance's rank test is then looser).
    differenced: bool,
    termination: Option<Termination>,
}

/// An ODR fit with its adjusted inputs and their weighted corrections.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OdrFit {
    /// The estimate. `chi2` is the whole objective S (responses and inputs), `residuals` the
    /// weighted response residuals (y_i − f_i(x_i + δ_i; β))/σ_y,i, `dof` = n − p, and the
    /// covariance is ODRPACK's (module docs).
    pub fit: Fit,
    /// The adjusted inputs x_i + δ_i.
    pub x_fit: Vec<f64>,
    /// The weighted input corrections δ_i/σ_x,i (0 for exact inputs).
    pub x_residuals: Vec<f64>,
}

impl Odr {
    /// A solver with the tolerances (`ftol`, `xtol`), limits and stop flag of `opts` (its
    /// bounds and typical magnitudes belong to the problem: [`OdrProblem::new`]).
    pub fn new(opts: &LsqOptions) -> Self {
        Odr {
            ftol: opts.ftol.max(f64::EPSILON),
            xtol: opts.xtol.max(f64::EPSILON),
            max_evals: opts.max_residual_evals,
            stop: opts.stop.clone(),
            cur: Point::default(),
            lin: Linear::default(),
            d_beta: Vec::new(),
            d_delta: Vec::new(),
            lambda: LAMBDA0,
            nu: 2.0,
            steps: 0,
            nfev: 0,
            njev: 0,
            differenced: false,
            frozen: false,
            termination: None,
        }
    }

    /// Fits `problem` under argmin's `Executor` (at most `opts.max_iterations` iterations,
    /// evaluations counted into `opts.progress`), then the covariance at the estimate.
    /// Numerical failure is reported in the fit's `termination`.
    ///
    /// Returns the estimate ([`Fit`]: `chi2` is the whole objective S, `residuals` the weighted
    /// response residuals (y_i − f_i(x_i + δ_i; β))/σ_y,i, `dof` = n − p, the covariance
    /// ODRPACK's) and the adjusted inputs x_i + δ_i.
    pub fn fit<M: OdrModel + Sync>(
        problem: OdrProblem<M>,
        opts: &LsqOptions,
    ) -> Result<(Fit, Vec<f64>), LsqError> {
        Self::fit_keep(problem, opts).map(|(f, _)| (f.fit, f.x_fit))
    }

    /// As [`Odr::fit`], handing the problem back.
    pub(crate) fn fit_keep<M: OdrModel + Sync>(
        problem: OdrProblem<M>,
        opts: &LsqOptions,
    ) -> Result<(OdrFit, OdrProblem<M>), LsqError> {
        let solver = Odr::new(opts);
        let mut exec = Executor::new(problem, solver)
            .configure(|s| s.max_iters(opts.max_iterations as u64))
            .ctrlc(false)
            .timer(false);
        if let Some(tally) = &opts.progress {
            exec = exec.add_observer(ProgressObserver::new(tally.clone()), ObserverMode::Always);
        }
        let res = exec.run().map_err(|e| LsqError::Solver(e.to_string()))?;
        let reason = res.state.get_termination_reason().cloned();
        let problem = res
            .problem
            .problem
            .ok_or_else(|| LsqError::Solver("the executor lost the problem".into()))?;
        let mut solver = res.solver;
        let termination = solver.termination.unwrap_or(match reason {
            Some(TerminationReason::MaxItersReached) => Termination::MaxIterations,
            _ => Termination::Interrupted,
        });
        Ok((
            solver.finish(&problem, termination, (opts.sigma, opts.scale_covar)),
            problem,
        ))
    }

    /// Why the solver stopped, once it has.
    pub fn termination(&self) -> Option<Termination> {
        self.termination
    }

    /// Whether input i moves in the present stage.
    fn moves<M: OdrModel + Sync>(&self, pr: &OdrProblem<M>, i: usize) -> bool {
        !self.frozen && pr.free(i)
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// The point at (β, δ): the residuals, or `None` where some input leaves the model's
    /// domain (or a residual is not finite).
    fn evaluate<M: OdrModel + Sync>(
        &mut self,
        pr: &OdrProblem<M>,
        beta: Vec<f64>,
        delta: Vec<f64>,
    ) -> Option<Point> {
        self.nfev += 1;
        let n = pr.n();
        let f: Vec<f64> = (0..n)
            .into_par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|i| pr.model.value(i, pr.x[i] + delta[i], &beta).ok())
            .collect::<Option<_>>()?;
        let mut r = vec![0.0; n];
        let mut rho = vec![0.0; n];
        let mut s = 0.0;
        for i in 0..n {
            r[i] = (pr.y[i] - f[i]) * pr.inv_sy[i];
            rho[i] = delta[i] * pr.inv_sx[i];
            s += r[i] * r[i] + rho[i] * rho[i];
        }
        s.is_finite().then_some(Point {
            beta,
            delta,
            r,
            rho,
            s,
        })
    }

    /// The linearisation at the current point, or `None` where it cannot be formed.
    fn linearise<M: OdrModel + Sync>(&mut self, pr: &OdrProblem<M>) -> Option<Linear> {
        self.njev += 1;
        let (n, p) = (pr.n(), pr.p());
        let beta = &self.cur.beta;
        let moves: Vec<bool> = (0..n).map(|i| self.moves(pr, i)).collect();
        // Per point: ∂f_i/∂β, ∂f_i/∂x, and whether they were differenced.
        let rows: Vec<Option<(Vec<f64>, f64, bool)>> = (0..n)
            .into_par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|i| {
                let xi = pr.x[i] + self.cur.delta[i];
                let f0 = pr.y[i] - self.cur.r[i] / pr.inv_sy[i];
                let mut g = vec![0.0; p];
                match pr.model.derivatives(i, xi, beta, &mut g) {
                    Some(r) => r.ok().map(|fx| (g, fx, false)),
                    None => {
                        let mut at = beta.clone();
                        for j in 0..p {
                            let h = STEP * beta[j].abs().max(pr.setup.typical[j]);
                            let (lo, hi) = (pr.setup.lower[j], pr.setup.upper[j]);
                            g[j] = difference(f0, h, lo - beta[j], hi - beta[j], |t| {
                                at[j] = beta[j] + t;
                                pr.model.value(i, xi, &at).ok()
                            })?;
                            at[j] = beta[j];
                        }
                        let fx = if moves[i] {
                            pr.x_slope(i, xi, f0, beta)?
                        } else {
                            0.0
                        };
                        Some((g, fx, true))
                    }
                }
            })
            .collect();
        self.differenced |= rows.iter().any(|r| r.as_ref().is_some_and(|r| r.2));
        let mut a = vec![0.0; n * p];
        let mut d = vec![0.0; n];
        for (i, row) in rows.into_iter().enumerate() {
            let (g, fx, _) = row?;
            for j in 0..p {
                a[i * p + j] = -g[j] * pr.inv_sy[i];
            }
            d[i] = -fx * pr.inv_sy[i];
        }
        let finite = a.iter().chain(&d).all(|v| v.is_finite());
        finite.then_some(Linear { a, d })
    }

    /// The step (s, t) for damping λ, and the predicted S; `None` when the damped normal
    /// matrix is not positive definite.
    fn step<M: OdrModel + Sync>(
        &self,
        pr: &OdrProblem<M>,
        lambda: f64,
    ) -> Option<(Vec<f64>, Vec<f64>, f64)> {
        let (n, p) = (pr.n(), pr.p());
        let (a, d) = (&self.lin.a, &self.lin.d);
        let (r, rho) = (&self.cur.r, &self.cur.rho);
        let mut nmat = DMatrix::<f64>::zeros(p, p);
        let mut rhs = DVector::<f64>::zeros(p);
        let mut q = vec![0.0; n];
        for i in 0..n {
            let (w, c) = if self.moves(pr, i) {
                let e = pr.inv_sx[i];
                let h = e * e + lambda * self.d_delta[i] * self.d_delta[i];
                q[i] = d[i] * d[i] + h;
                (h / q[i], d[i] * e * rho[i] / h)
            } else {
                (1.0, 0.0)
            };
            let ai = &a[i * p..(i + 1) * p];
            for j in 0..p {
                rhs[j] -= w * ai[j] * (r[i] - c);
                for k in 0..=j {
                    nmat[(j, k)] += w * ai[j] * ai[k];
                }
            }
        }
        for j in 0..p {
            nmat[(j, j)] += lambda * self.d_beta[j] * self.d_beta[j];
            for k in 0..j {
                nmat[(k, j)] = nmat[(j, k)];
            }
        }
        let mut s = nmat.cholesky()?.solve(&rhs);
        // The box: the parameters' step is projected, the corrections then follow it.
        for j in 0..p {
            let b = (self.cur.beta[j] + s[j]).clamp(pr.setup.lower[j], pr.setup.upper[j]);
            s[j] = b - self.cur.beta[j];
        }
        let mut t = vec![0.0; n];
        let mut pred = 0.0;
        for i in 0..n {
            let ai = &a[i * p..(i + 1) * p];
            let lin = r[i] + (0..p).map(|j| ai[j] * s[j]).sum::<f64>();
            if self.moves(pr, i) {
                t[i] = -(d[i] * lin + pr.inv_sx[i] * rho[i]) / q[i];
            }
            let ry = lin + d[i] * t[i];
            let rx = rho[i] + pr.inv_sx[i] * t[i];
            pred += ry * ry + rx * rx;
        }
        Some((s.as_slice().to_vec(), t, pred))
    }

    /// Updates the scaling with the column norms of the current linearisation.
    fn rescale<M: OdrModel + Sync>(&mut self, pr: &OdrProblem<M>) {
        let (n, p) = (pr.n(), pr.p());
        for j in 0..p {
            let c = (0..n)
                .map(|i| self.lin.a[i * p + j].powi(2))
                .sum::<f64>()
                .sqrt();
            self.d_beta[j] = self.d_beta[j].max(c).max(f64::MIN_POSITIVE);
        }
        for i in 0..n {
            let c = (self.lin.d[i].powi(2) + pr.inv_sx[i].powi(2)).sqrt();
            self.d_delta[i] = self.d_delta[i].max(c).max(f64::MIN_POSITIVE);
        }
    }

    /// One iteration: the linearisation, then trial steps until one is accepted or the
    /// iteration ends.
    fn iterate<M: OdrModel + Sync>(&mut self, pr: &OdrProblem<M>) -> Option<Termination> {
        if self.cur.s == 0.0 {
            return Some(Termination::ExactFit);
        }
        self.lin = match self.linearise(pr) {
            Some(l) => l,
            None => return Some(Termination::JacobianFailed),
        };
        self.rescale(pr);
        let mut blocked = false;
        loop {
            if self.stopped() {
                return Some(Termination::Interrupted);
            }
            if self.nfev >= self.max_evals {
                return Some(Termination::MaxEvaluations);
            }
            if !(self.lambda < 1e300) {
                return Some(if blocked {
                    Termination::Stalled
                } else {
                    Termination::RelativeReduction
                });
            }
            let Some((s, t, pred)) = self.step(pr, self.lambda) else {
                self.lambda *= self.nu;
                self.nu *= 2.0;
                continue;
            };
            let beta: Vec<f64> = self.cur.beta.iter().zip(&s).map(|(b, s)| b + s).collect();
            let delta: Vec<f64> = self.cur.delta.iter().zip(&t).map(|(d, t)| d + t).collect();
            let predicted = (self.cur.s - pred) / self.cur.s;
            let size = self.scaled_step(&s, &t);
            let Some(trial) = self.evaluate(pr, beta, delta) else {
                blocked = true;
                self.lambda *= self.nu;
                self.nu *= 2.0;
                if size <= self.xtol * self.scaled_norm() {
                    return Some(Termination::Stalled);
                }
                continue;
            };
            let actual = (self.cur.s - trial.s) / self.cur.s;
            let ratio = if predicted > 0.0 {
                actual / predicted
            } else {
                0.0
            };
            let small = predicted <= self.ftol && actual.abs() <= self.ftol;
            let tiny = size <= self.xtol * self.scaled_norm();
            if ratio > 1e-4 {
                self.lambda *= (1.0 - (2.0 * ratio - 1.0).powi(3)).max(1.0 / 3.0);
                self.nu = 2.0;
                self.steps += 1;
                self.cur = trial;
                if small {
                    return Some(Termination::RelativeReduction);
                }
                if tiny {
                    return Some(Termination::StepSize);
                }
                return None;
            }
            if small || tiny {
                let converged = if small {
                    Termination::RelativeReduction
                } else {
                    Termination::StepSize
                };
                return Some(if blocked {
                    Termination::Stalled
                } else {
                    converged
                });
            }
            self.lambda *= self.nu;
            self.nu *= 2.0;
        }
    }

    /// Ends the first stage (module docs): the inputs move from now on, each correction
    /// starts from its best value at the present parameters ([`Odr::settle`]), and the damping
    /// starts afresh.
    fn release<M: OdrModel + Sync>(&mut self, pr: &OdrProblem<M>) {
        self.frozen = false;
        self.settle(pr);
        self.lambda = LAMBDA0;
        self.nu = 2.0;
    }

    /// Moves every correction to its best value at the start's parameters
    /// ([`OdrProblem::correct`]). The iteration then starts from the parameters' best
    /// corrections, not from δ = 0, whose objective may be dominated by inputs far from the
    /// curve (the first steps then see every input pulled and can walk into a local minimum:
    /// SciPy's Pearson data with x and y exchanged).
    fn settle<M: OdrModel + Sync>(&mut self, pr: &OdrProblem<M>) {
        let cur = &self.cur;
        let settled: Vec<((f64, f64, f64), usize)> = (0..pr.n())
            .into_par_iter()
            .with_min_len(MIN_CHUNK)
            .map(|i| {
                let mut evals = 0;
                let at = (cur.r[i], cur.rho[i], cur.delta[i]);
                (pr.correct(i, &cur.beta, at, &mut evals), evals)
            })
            .collect();
        for (i, ((r, rho, delta), evals)) in settled.into_iter().enumerate() {
            self.cur.r[i] = r;
            self.cur.rho[i] = rho;
            self.cur.delta[i] = delta;
            self.nfev += evals;
        }
        self.cur.s = self.cur.r.iter().chain(&self.cur.rho).map(|v| v * v).sum();
    }

    /// ‖(D_β s, D_δ t)‖.
    fn scaled_step(&self, s: &[f64], t: &[f64]) -> f64 {
        let a = s.iter().zip(&self.d_beta).map(|(s, d)| (s * d).powi(2));
        let b = t.iter().zip(&self.d_delta).map(|(t, d)| (t * d).powi(2));
        a.chain(b).sum::<f64>().sqrt()
    }

    /// ‖(D_β β, D_δ δ)‖ at the current point, at least ε (a start at zero still moves).
    fn scaled_norm(&self) -> f64 {
        self.scaled_step(&self.cur.beta, &self.cur.delta)
            .max(f64::EPSILON)
    }

    /// The state after an iteration.
    fn report(&self, mut state: LmState) -> Result<(LmState, Option<KV>), Error> {
        let stage = if self.termination.is_some() {
            LmStage::Done
        } else {
            LmStage::Lm
        };
        state.set_lm(stage, self.lambda, f64::NAN, self.steps);
        state.set_point(&self.cur.beta, self.cur.s);
        state.set_evals(self.nfev, self.njev, self.nfev);
        if let Some(t) = self.termination {
            state = state.terminate_with(if t.converged() {
                TerminationReason::SolverConverged
            } else {
                TerminationReason::SolverExit(format!("{t:?}"))
            });
        }
        Ok((state, None))
    }

    /// The [`OdrFit`] at the current point: statistics and ODRPACK's covariance.
    fn finish<M: OdrModel + Sync>(
        &mut self,
        pr: &OdrProblem<M>,
        termination: Termination,
        (sigma, scale_covar): (SigmaKind, bool),
    ) -> OdrFit {
        let (n, p) = (pr.n(), pr.p());
        let dof = n - p;
        let started = self.cur.beta.len() == p;
        let chi2 = if started { self.cur.s } else { f64::INFINITY };
        let reduced_chi2 = if dof > 0 {
            chi2 / dof as f64
        } else {
            f64::INFINITY
        };
        let scale = covariance_scale(sigma, scale_covar, dof, reduced_chi2);
        let covariance = match (started && chi2.is_finite(), scale) {
            (true, Some(scale)) => self.linearise(pr).and_then(|lin| {
                let mut jac = Mat::<f64>::zeros(n, p);
                for i in 0..n {
                    let w = if pr.free(i) {
                        let e2 = pr.inv_sx[i] * pr.inv_sx[i];
                        (e2 / (lin.d[i] * lin.d[i] + e2)).sqrt()
                    } else {
                        1.0
                    };
                    for j in 0..p {
                        jac[(i, j)] = w * lin.a[i * p + j];
                    }
                }
                covariance(&jac, scale, rank_tolerance(self.differenced, n, p))
            }),
            _ => None,
        };
        let (aic, bic) = information_criteria(chi2, n, p, sigma);
        let at_bound = (0..p)
            .map(|j| {
                started
                    && (self.cur.beta[j] <= pr.setup.lower[j]
                        || self.cur.beta[j] >= pr.setup.upper[j])
            })
            .collect();
        let x_fit = if started {
            (0..n).map(|i| pr.x[i] + self.cur.delta[i]).collect()
        } else {
            pr.x.clone()
        };
        OdrFit {
            fit: Fit {
                params: if started {
                    self.cur.beta.clone()
                } else {
                    pr.setup.start.clone()
                },
                residuals: self.cur.r.clone(),
                chi2,
                dof,
                reduced_chi2,
                covariance,
                sigma,
                scale_covar,
                aic,
                bic,
                iterations: self.steps,
                residual_evals: self.nfev,
                jacobian_evals: self.njev,
                termination,
                at_bound,
            },
            x_fit,
            x_residuals: if started {
                self.cur.rho.clone()
            } else {
                vec![0.0; n]
            },
        }
    }
}

/// The damping a stage starts from (relative to the squared scaling).
const LAMBDA0: f64 = 1e-3;

/// How a stage ends that also ends the fit, whatever the stage.
const FINAL: [Termination; 3] = [
    Termination::Interrupted,
    Termination::MaxEvaluations,
    Termination::JacobianFailed,
];

/// Most Newton steps per correction (`OdrProblem::correct`).
const SETTLE: usize = 20;

/// Fewest points per parallel task of the per-point work (each a few model evaluations).
const MIN_CHUNK: usize = 4;

/// Step factor of the central differences, ε^{1/3}.
const STEP: f64 = 6.055454452393343e-6;

/// The derivative at 0 of g, with g(0) = `f0`, by central differences of step `h`, or
/// second-order one-sided ones where a side is outside [`lo`, `hi`] or infeasible (`None`).
fn difference(
    f0: f64,
    h: f64,
    lo: f64,
    hi: f64,
    mut g: impl FnMut(f64) -> Option<f64>,
) -> Option<f64> {
    let up = if h <= hi { g(h) } else { None };
    let down = if -h >= lo { g(-h) } else { None };
    match (up, down) {
        (Some(u), Some(d)) => Some((u - d) / (2.0 * h)),
        (Some(u), None) => {
            let u2 = if 2.0 * h <= hi { g(2.0 * h) } else { None };
            Some(match u2 {
                Some(u2) => (-3.0 * f0 + 4.0 * u - u2) / (2.0 * h),
                None => (u - f0) / h,
            })
        }
        (None, Some(d)) => {
            let d2 = if -2.0 * h >= lo { g(-2.0 * h) } else { None };
            Some(match d2 {
                Some(d2) => (3.0 * f0 - 4.0 * d + d2) / (2.0 * h),
                None => (f0 - d) / h,
            })
        }
        (None, None) => None,
    }
}

/// The derivatives at 0 of the quadratic through three equally spaced values of g, and the
/// span of steps they cover: f′ = `f1`, f″ = `f2`, steps in [`span.0`, `span.1`].
#[derive(Debug, Clone, Copy)]
struct Local {
    f1: f64,
    f2: f64,
    span: (f64, f64),
}

/// [`Local`] of g, with g(0) = `f0`, from g(±h) (central), else g(h), g(2h) or g(−h), g(−2h)
/// where one side is infeasible (`None`), else the first-order difference of the feasible side
/// with f″ taken as 0 and an empty span; `None` where g(h) and g(−h) are both infeasible.
fn quadratic(f0: f64, h: f64, mut g: impl FnMut(f64) -> Option<f64>) -> Option<Local> {
    let h2 = h * h;
    match (g(h), g(-h)) {
        (Some(u), Some(d)) => Some(Local {
            f1: (u - d) / (2.0 * h),
            f2: (u - 2.0 * f0 + d) / h2,
            span: (-h, h),
        }),
        (Some(u), None) => Some(match g(2.0 * h) {
            Some(u2) => Local {
                f1: (-3.0 * f0 + 4.0 * u - u2) / (2.0 * h),
                f2: (f0 - 2.0 * u + u2) / h2,
                span: (0.0, 2.0 * h),
            },
            None => Local {
                f1: (u - f0) / h,
                f2: 0.0,
                span: (0.0, 0.0),
            },
        }),
        (None, Some(d)) => Some(match g(-2.0 * h) {
            Some(d2) => Local {
                f1: (3.0 * f0 - 4.0 * d + d2) / (2.0 * h),
                f2: (f0 - 2.0 * d + d2) / h2,
                span: (-2.0 * h, 0.0),
            },
            None => Local {
                f1: (f0 - d) / h,
                f2: 0.0,
                span: (0.0, 0.0),
            },
        }),
        (None, None) => None,
    }
}

impl<M: OdrModel + Sync> Solver<OdrProblem<M>, LmState> for Odr {
    fn name(&self) -> &str {
        "orthogonal distance regression (Boggs, Byrd & Schnabel 1987)"
    }

    fn init(
        &mut self,
        problem: &mut Problem<OdrProblem<M>>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let pr = problem
            .problem
            .as_ref()
            .ok_or_else(|| Error::msg("no ODR problem"))?;
        let (n, p) = (pr.n(), pr.p());
        let start = pr.setup.start_from(state.get_param())?;
        self.d_beta = vec![0.0; p];
        self.d_delta = vec![0.0; n];
        match self.evaluate(pr, start, vec![0.0; n]) {
            Some(pt) => {
                self.cur = pt;
                self.frozen = (0..n).any(|i| pr.free(i));
                if self.frozen && pr.at_optimum {
                    self.release(pr);
                }
            }
            None => self.termination = Some(Termination::InfeasibleStart),
        }
        self.report(state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<OdrProblem<M>>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let pr = problem
            .problem
            .as_ref()
            .ok_or_else(|| Error::msg("no ODR problem"))?;
        if self.termination.is_none() {
            match self.iterate(pr) {
                // The parameters' first fit, inputs held, has ended: now the inputs move.
                Some(t) if self.frozen && !FINAL.contains(&t) => self.release(pr),
                t => self.termination = t,
            }
        }
        self.report(state)
    }
}
