//! Weighted nonlinear least squares by the Levenberg–Marquardt method with Moré's scaling, as an
//! argmin solver ([`LevenbergMarquardt`]: `impl Solver<LeastSquares<R>, LmState>`).
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
//! * **Infeasible points.** A residual evaluation may answer [`Infeasible`](super::Infeasible) (the model left its
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
//! Each argmin iteration is one outer iteration (one Jacobian, then trial steps until one is
//! accepted) or one polish step; the solver's reasons for stopping are [`Termination`]s, and the
//! estimate with its covariance is [`super::fit`]'s [`super::Fit`].
//!
//! The iteration is compiled once, whatever the problem: it sees the residuals through a trait
//! object (`&dyn Residuals`, with the box), and the [`Solver`] implementation, generic over the
//! problem, only unwraps argmin's problem and calls it. [`super::fit`] and the profiles run
//! argmin's `Executor` on that trait object too (`DynLeastSquares`), so one copy of the
//! executor loop and of the iteration serves every fit. The work space (the Jacobian, its
//! pivoted QR factors, the subproblem, the trial point) is allocated when a fit starts and
//! passed on to its restarts and its polish; the profiles' constrained fits, all of one shape,
//! share it (`Spare`).

// Index loops mirror the subscripts of the published algorithm (MINPACK-1).
#![allow(clippy::needless_range_loop)]

use argmin::core::observers::ObserverMode;
use argmin::core::{Error, Problem, Solver, State, TerminationReason, KV};
use faer::{Mat, MatRef};
use std::collections::HashMap;
use std::sync::atomic::Ordering;

use super::lmpar::{norm2, Subproblem};
use super::lsq::{LsqOptions, Residuals, Termination};
use super::observer::ProgressObserver;
use super::problem::{Evaluator, LeastSquares, View};
use super::qr::PivotedQr;
use super::state::{LmStage, LmState};

/// The outcome of the iteration proper (no covariance).
#[derive(Debug, Clone)]
pub(crate) struct Solution {
    pub x: Vec<f64>,
    pub f: Vec<f64>,
    pub fnorm: f64,
    pub termination: Termination,
    pub iterations: usize,
}

/// The work space of a fit (m residuals, n parameters): the Jacobian, its factorisation, the
/// subproblem and the trial point. A run hands it to the restart or the polish after it
/// ([`Work::reuse`]).
#[derive(Debug, Clone)]
struct Work {
    jac: Mat<f64>,
    jw: Mat<f64>,
    qr: PivotedQr,
    diag: Vec<f64>,
    acnorm: Vec<f64>,
    qtf: Vec<f64>,
    grad: Vec<f64>,
    free: Vec<bool>,
    sp: Subproblem,
    ipvt: Vec<usize>,
    trial: Vec<f64>,
    step: Vec<f64>,
    ft: Vec<f64>,
    u: Vec<f64>,
    /// Work space: a scaled vector and R·s (n).
    scaled: Vec<f64>,
    rs: Vec<f64>,
}

impl Work {
    fn new(m: usize, n: usize) -> Self {
        Work {
            jac: Mat::<f64>::zeros(m, n),
            jw: Mat::<f64>::zeros(m, n),
            qr: PivotedQr::new(m, n),
            diag: vec![0.0; n],
            acnorm: vec![0.0; n],
            qtf: vec![0.0; n],
            grad: vec![0.0; n],
            free: vec![true; n],
            sp: Subproblem::new(n),
            ipvt: vec![0usize; n],
            trial: vec![0.0; n],
            step: vec![0.0; n],
            ft: vec![0.0; m],
            u: vec![0.0; m],
            scaled: vec![0.0; n],
            rs: vec![0.0; n],
        }
    }

    /// `work` made ready for the next stage, or new work space when there is none of this
    /// shape. Every buffer is written before it is read, except those the problem writes (the
    /// Jacobian and the trial residuals), which are zeroed as when new.
    fn reuse(work: Option<Work>, m: usize, n: usize) -> Work {
        match work {
            Some(mut w) if w.jac.nrows() == m && w.jac.ncols() == n => {
                w.jac.fill(0.0);
                w.ft.fill(0.0);
                w
            }
            _ => Work::new(m, n),
        }
    }
}

/// Work space passed from one fit to the next ([`solve`]): a caller that runs many fits of the
/// same shape (the profiles' constrained fits) allocates it once.
#[derive(Debug, Default)]
pub(crate) struct Spare(Option<Work>);

impl Spare {
    /// No work space yet.
    pub fn new() -> Self {
        Spare(None)
    }
}

/// One Levenberg–Marquardt run (MINPACK `lmder` with projection on the box): the point reached,
/// the trust region, the scaling and the work space, advanced one outer iteration (one
/// Jacobian) at a time by [`LmRun::iterate`].
#[derive(Debug, Clone)]
struct LmRun {
    x: Vec<f64>,
    f: Vec<f64>,
    fnorm: f64,
    iterations: usize,
    w: Work,
    /// The Levenberg–Marquardt parameter λ.
    par: f64,
    /// The trust radius Δ.
    delta: f64,
    xnorm: f64,
    first: bool,
    outer: usize,
    /// Set by an infeasible trial point, cleared by an accepted step the trust region did not
    /// constrain (λ = 0): while set, a small radius or predicted reduction may be the edge of
    /// the feasible region speaking, not a minimum.
    edge: bool,
}

impl LmRun {
    /// Starts a run at `x0` (in the work space of `work`, taken when the run starts), or
    /// returns the solution when the start already ends it (an infeasible start, or χ² = 0).
    fn start(
        ev: &mut Evaluator,
        ls: View<'_>,
        x0: Vec<f64>,
        work: &mut Option<Work>,
    ) -> Result<LmRun, Solution> {
        let (m, n) = (ev.m, ev.n);
        let mut f = vec![0.0; m];
        if !ev.residuals(ls, &x0, &mut f) {
            // Whatever the problem wrote there is not a residual vector.
            return Err(Solution {
                x: x0,
                f: Vec::new(),
                fnorm: f64::INFINITY,
                termination: Termination::InfeasibleStart,
                iterations: 0,
            });
        }
        let fnorm = norm2(&f);
        if fnorm == 0.0 {
            return Err(Solution {
                x: x0,
                f,
                fnorm,
                termination: Termination::ExactFit,
                iterations: 0,
            });
        }
        Ok(LmRun {
            x: x0,
            f,
            fnorm,
            iterations: 0,
            w: Work::reuse(work.take(), m, n),
            par: 0.0,
            delta: 0.0,
            xnorm: 0.0,
            first: true,
            outer: 0,
            edge: false,
        })
    }

    /// The run's result, ended by `termination`, and its work space.
    fn end(self, termination: Termination) -> (Solution, Work) {
        let sol = Solution {
            x: self.x,
            f: self.f,
            fnorm: self.fnorm,
            termination,
            iterations: self.iterations,
        };
        (sol, self.w)
    }

    /// One outer iteration: a Jacobian, then trial steps until one is accepted. Returns the
    /// reason when the run ends.
    fn iterate(
        &mut self,
        ev: &mut Evaluator,
        ls: View<'_>,
        opts: &LsqOptions,
    ) -> Option<Termination> {
        let n = ev.n;
        let eps = f64::EPSILON;
        let ftol = opts.ftol.max(eps);
        let xtol = opts.xtol.max(eps);
        let gtol = opts.gtol.max(eps);
        let (lo, hi) = (&ls.setup.lower, &ls.setup.upper);
        let stopped = || {
            opts.stop
                .as_ref()
                .is_some_and(|s| s.load(Ordering::Relaxed))
        };
        let LmRun {
            x,
            f,
            fnorm,
            iterations,
            w,
            par,
            delta,
            xnorm,
            first,
            outer,
            edge,
        } = self;
        let Work {
            jac,
            jw,
            qr,
            diag,
            acnorm,
            qtf,
            grad,
            free,
            sp,
            ipvt,
            trial,
            step,
            ft,
            u,
            scaled,
            rs,
        } = w;

        if *outer >= opts.max_iterations {
            return Some(Termination::MaxIterations);
        }
        if stopped() {
            return Some(Termination::Interrupted);
        }
        *outer += 1;
        if !ev.jacobian(ls, x, f, jac) {
            return Some(Termination::JacobianFailed);
        }
        // Column norms, gradient Jᵀf and the active set.
        for j in 0..n {
            let c = jac.col_as_slice(j);
            acnorm[j] = norm2(c);
            grad[j] = c.iter().zip(f.iter()).map(|(a, b)| a * b).sum();
            free[j] = !((x[j] <= lo[j] && grad[j] > 0.0) || (x[j] >= hi[j] && grad[j] < 0.0));
            let w = jw.col_as_slice_mut(j);
            if free[j] {
                w.copy_from_slice(c);
            } else {
                w.fill(0.0);
            }
        }
        if *first {
            for j in 0..n {
                diag[j] = if acnorm[j] != 0.0 { acnorm[j] } else { 1.0 };
            }
            *xnorm = scaled_norm(diag, x, scaled);
            *delta = opts.initial_radius_factor * *xnorm;
            if *delta == 0.0 {
                *delta = opts.initial_radius_factor;
            }
        }
        // QR with column pivoting of the (active-set) Jacobian; Qᵀf.
        qr.factor(jw, |r, perm| load_r(sp, ipvt, r, perm, acnorm));
        for (j, q_j) in qtf.iter_mut().enumerate() {
            *q_j = qr.q_col(j).iter().zip(f.iter()).map(|(a, b)| a * b).sum();
        }
        // Scaled gradient norm (largest cosine between f and a free column of J).
        let mut gnorm: f64 = 0.0;
        for j in 0..n {
            let l = ipvt[j];
            if acnorm[l] != 0.0 && free[l] {
                let sum: f64 = (0..=j).map(|i| sp.r[i + j * n] * (qtf[i] / *fnorm)).sum();
                gnorm = gnorm.max((sum / acnorm[l]).abs());
            }
        }
        if gnorm <= gtol {
            return Some(Termination::Gradient);
        }
        for j in 0..n {
            diag[j] = diag[j].max(acnorm[j]);
        }

        // Inner loop: until a step is accepted.
        loop {
            if stopped() {
                return Some(Termination::Interrupted);
            }
            *par = sp.lm_step(ipvt, diag, qtf, *delta, *par);
            let mut projected = false;
            for j in 0..n {
                let t = if free[j] { x[j] - sp.x[j] } else { x[j] };
                trial[j] = t.clamp(lo[j], hi[j]);
                if trial[j] != t {
                    projected = true;
                }
                step[j] = trial[j] - x[j];
            }
            let pnorm = scaled_norm(diag, step, scaled);
            if *first {
                *delta = delta.min(pnorm);
            }
            let feasible = ev.residuals(ls, trial, ft);
            if !feasible {
                *edge = true;
            }
            let fnorm1 = if feasible { norm2(ft) } else { f64::INFINITY };
            let actred = if 0.1 * fnorm1 < *fnorm {
                1.0 - (fnorm1 / *fnorm) * (fnorm1 / *fnorm)
            } else {
                -1.0
            };
            // Predicted reduction and scaled directional derivative.
            let (prered, dirder) = if !projected {
                // The exact LM step: pred = ‖J s‖² + 2λ‖D s‖² (Moré 1978, eq. 4.4 ff.).
                rs.fill(0.0);
                for j in 0..n {
                    let l = ipvt[j];
                    let sl = step[l];
                    for (i, v) in rs.iter_mut().enumerate().take(j + 1) {
                        *v += sp.r[i + j * n] * sl;
                    }
                }
                let temp1 = norm2(rs) / *fnorm;
                let temp2 = par.sqrt() * pnorm / *fnorm;
                (
                    temp1 * temp1 + temp2 * temp2 / 0.5,
                    -(temp1 * temp1 + temp2 * temp2),
                )
            } else {
                let jw = jw.as_ref();
                for (i, ui) in u.iter_mut().enumerate() {
                    *ui = (0..n).map(|j| jw[(i, j)] * step[j]).sum();
                }
                let uf: f64 =
                    u.iter().zip(f.iter()).map(|(a, b)| a * b).sum::<f64>() / (*fnorm * *fnorm);
                let uu = norm2(u) / *fnorm;
                (-2.0 * uf - uu * uu, uf)
            };
            let ratio = if prered != 0.0 { actred / prered } else { 0.0 };

            if ratio <= 0.25 {
                let mut temp = if actred >= 0.0 {
                    0.5
                } else {
                    0.5 * dirder / (dirder + 0.5 * actred)
                };
                if 0.1 * fnorm1 >= *fnorm || !(temp >= 0.1) {
                    temp = 0.1;
                }
                *delta = temp * delta.min(pnorm / 0.1);
                *par /= temp;
            } else if *par == 0.0 || ratio >= 0.75 {
                *delta = pnorm / 0.5;
                *par *= 0.5;
            }

            if ratio >= 1e-4 {
                if *par == 0.0 {
                    *edge = false;
                }
                x.copy_from_slice(trial);
                std::mem::swap(f, ft);
                *xnorm = scaled_norm(diag, x, scaled);
                *fnorm = fnorm1;
                *iterations += 1;
                *first = false;
                if *fnorm == 0.0 {
                    return Some(Termination::ExactFit);
                }
            }

            let ftest = actred.abs() <= ftol && prered <= ftol && 0.5 * ratio <= 1.0;
            let xtest = *delta <= xtol * *xnorm || *delta < f64::MIN_POSITIVE;
            if ftest || xtest {
                return Some(if *edge {
                    Termination::Stalled
                } else if ftest {
                    Termination::RelativeReduction
                } else {
                    Termination::StepSize
                });
            }
            if ev.nfev >= opts.max_residual_evals {
                return Some(Termination::MaxEvaluations);
            }
            if ratio >= 1e-4 {
                return None;
            }
        }
    }
}

/// At most this many Gauss–Newton polish steps.
const POLISH_STEPS: usize = 50;
/// A polish step may raise ‖f‖ by at most this much, relative.
const POLISH_SLACK: f64 = 1e-10;
/// After the first, a polish step must be at most this fraction of the previous one (scaled).
const POLISH_CONTRACTION: f64 = 0.9;

/// Gauss–Newton refinement of a converged point: at most [`POLISH_STEPS`] full Gauss–Newton
/// steps (λ = 0, rank-revealing QR), each kept only if it is feasible, does not raise ‖f‖ beyond
/// [`POLISH_SLACK`] relative, and (after the first) is at most [`POLISH_CONTRACTION`] of the
/// previous one in the scaled norm — the contraction expected of Gauss–Newton next to a
/// minimum. Near the optimum of an ill-conditioned problem the χ² differences that the
/// trust-region ratio test relies on drown in rounding, so the radius collapses while the
/// Gauss–Newton step, computed from the gradient Jᵀf, still knows where the minimum is.
#[derive(Debug, Clone)]
struct Polisher {
    /// The work space (of the run before, when there was one): the Jacobian is masked in
    /// place, `diag` holds its column norms.
    w: Work,
    previous: f64,
    steps: usize,
}

impl Polisher {
    fn new(w: Work) -> Self {
        Polisher {
            w,
            previous: f64::INFINITY,
            steps: 0,
        }
    }

    /// Tries one polish step from `sol`; true when it was taken (and `sol` moved), false when
    /// the polish is over.
    fn step(
        &mut self,
        ev: &mut Evaluator,
        ls: View<'_>,
        opts: &LsqOptions,
        sol: &mut Solution,
    ) -> bool {
        if self.steps >= POLISH_STEPS {
            return false;
        }
        self.steps += 1;
        let n = ev.n;
        let (lo, hi) = (&ls.setup.lower, &ls.setup.upper);
        let xtol = opts.xtol.max(f64::EPSILON);
        let Polisher {
            w,
            previous,
            steps: _,
        } = self;
        let Work {
            jac,
            qr,
            sp,
            ipvt,
            qtf,
            diag,
            free,
            trial,
            step,
            ft,
            scaled,
            ..
        } = w;
        if ev.nfev >= opts.max_residual_evals || !ev.jacobian(ls, &sol.x, &sol.f, jac) {
            return false;
        }
        for j in 0..n {
            let c = jac.col_as_slice_mut(j);
            diag[j] = norm2(c);
            if diag[j] == 0.0 {
                diag[j] = 1.0;
            }
            let g: f64 = c.iter().zip(sol.f.iter()).map(|(a, b)| a * b).sum();
            free[j] = !((sol.x[j] <= lo[j] && g > 0.0) || (sol.x[j] >= hi[j] && g < 0.0));
            if !free[j] {
                c.fill(0.0);
            }
        }
        qr.factor(jac, |r, perm| load_r(sp, ipvt, r, perm, diag));
        for (j, q_j) in qtf.iter_mut().enumerate() {
            *q_j = qr
                .q_col(j)
                .iter()
                .zip(sol.f.iter())
                .map(|(a, b)| a * b)
                .sum();
        }
        sp.lm_step(ipvt, diag, qtf, f64::INFINITY, 0.0);
        for j in 0..n {
            let t = if free[j] {
                sol.x[j] - sp.x[j]
            } else {
                sol.x[j]
            };
            trial[j] = t.clamp(lo[j], hi[j]);
            step[j] = trial[j] - sol.x[j];
        }
        let snorm = scaled_norm(diag, step, scaled);
        if !(snorm > xtol * scaled_norm(diag, &sol.x, scaled))
            || !(snorm <= POLISH_CONTRACTION * *previous)
        {
            return false;
        }
        if !ev.residuals(ls, trial, ft) {
            return false;
        }
        let fnorm1 = norm2(ft);
        if !(fnorm1 <= sol.fnorm * (1.0 + POLISH_SLACK)) {
            return false;
        }
        sol.x.copy_from_slice(trial);
        std::mem::swap(&mut sol.f, ft);
        sol.fnorm = fnorm1;
        sol.iterations += 1;
        *previous = snorm;
        true
    }
}

/// Where the solver is.
#[derive(Debug, Clone, Default)]
enum Stage {
    /// Not initialised.
    #[default]
    Idle,
    /// A Levenberg–Marquardt run; `restarts` runs have been started after the first, and
    /// `previous` is the solution of the run before this one.
    Run {
        run: Box<LmRun>,
        restarts: usize,
        previous: Option<Solution>,
    },
    /// Gauss–Newton polish of a converged solution.
    Polish {
        polisher: Box<Polisher>,
        sol: Solution,
    },
    /// Finished.
    Done(Solution),
}

/// fitbead's bounded Levenberg–Marquardt method (see the module docs) as an argmin
/// [`Solver`] on a [`LeastSquares`] problem.
///
/// Each argmin iteration is one outer Levenberg–Marquardt iteration (one Jacobian and the
/// trial steps until one is accepted) or one Gauss–Newton polish step. Infeasible trial points
/// are rejected steps, never errors. The state's `param` is the current estimate and `cost` its
/// χ²; a `param` set on the initial state (`Executor::configure`) replaces the problem's start
/// (projected onto the box). The solver's own reason for stopping is
/// [`LevenbergMarquardt::termination`]; argmin's own stops (`max_iters`, a timeout, a target
/// cost) end the run where it is; [`super::Fit::from_run`] turns the executor's result
/// into a [`super::Fit`] (argmin's reasons mapped onto [`Termination`]).
///
/// ```
/// use argmin::core::{Executor, State};
/// use fitbead::inverse::{Infeasible, LeastSquares, LevenbergMarquardt, LsqOptions, CurveModel,
///     WeightedData};
/// struct Decay;
/// impl CurveModel<f64> for Decay {
///     fn n_params(&self) -> usize { 2 }
///     fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
///         Ok(p[0] * (-p[1] * x).exp())
///     }
/// }
/// let x: Vec<f64> = (0..10).map(f64::from).collect();
/// let y: Vec<f64> = x.iter().map(|x| 3.0 * (-0.5 * x).exp()).collect();
/// let opts = LsqOptions::default();
/// let problem = LeastSquares::new(WeightedData::new(Decay, x, y, None).unwrap(), &[1.0, 1.0], &opts)
///     .unwrap();
/// let result = Executor::new(problem, LevenbergMarquardt::new(&opts)).run().unwrap();
/// let p = result.state().get_param().unwrap();
/// assert!((p[0] - 3.0).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12);
/// assert!(result.solver().termination().unwrap().converged());
/// // The estimate with its statistics and covariance, as `fit` gives it.
/// let fit = fitbead::inverse::Fit::from_run(result, opts.sigma).unwrap();
/// assert!(fit.converged() && fit.std_errors().is_some());
/// ```
#[derive(Debug, Clone)]
pub struct LevenbergMarquardt {
    opts: LsqOptions,
    ev: Evaluator,
    stage: Stage,
    log: bool,
    /// Whether argmin's function counts are kept (off only for [`solve`], which discards
    /// them).
    counts: bool,
    /// Work space for the next run, and the last run's once the solver has finished.
    spare: Option<Work>,
}

impl LevenbergMarquardt {
    /// A solver with the tolerances, limits, restarts, polish and stop flag of `opts` (its
    /// bounds and typical magnitudes belong to the problem: [`LeastSquares::new`]).
    pub fn new(opts: &LsqOptions) -> Self {
        LevenbergMarquardt {
            opts: LsqOptions {
                ftol: opts.ftol,
                xtol: opts.xtol,
                gtol: opts.gtol,
                max_iterations: opts.max_iterations,
                max_residual_evals: opts.max_residual_evals,
                initial_radius_factor: opts.initial_radius_factor,
                lower: None,
                upper: None,
                typical: None,
                restarts: opts.restarts,
                sigma: opts.sigma,
                scale_covar: opts.scale_covar,
                polish: opts.polish,
                stop: opts.stop.clone(),
                // Counted by an observer ([`super::ProgressObserver`]), not by the solver.
                progress: None,
            },
            ev: Evaluator::new(0, 0),
            stage: Stage::Idle,
            log: false,
            counts: true,
            spare: None,
        }
    }

    /// Also hand argmin's observers, at every iteration, the key–value pairs `chi2`, `lambda`
    /// (the Levenberg–Marquardt parameter), `radius` (the trust radius Δ) and `stage` (`lm` or
    /// `polish`). Off by default: building them costs an allocation per iteration.
    pub fn with_log(mut self, log: bool) -> Self {
        self.log = log;
        self
    }

    /// Why the solver stopped, once it has (`None` while it runs, or when argmin stopped it).
    pub fn termination(&self) -> Option<Termination> {
        match &self.stage {
            Stage::Done(sol) => Some(sol.termination),
            _ => None,
        }
    }

    /// Residual evaluations so far (finite-difference ones included).
    pub fn residual_evals(&self) -> usize {
        self.ev.nfev
    }

    /// Jacobian evaluations so far.
    pub fn jacobian_evals(&self) -> usize {
        self.ev.njev
    }

    /// The evaluator: its counts and work space.
    pub(crate) fn into_evaluator(self) -> Evaluator {
        self.ev
    }

    /// The solution reached: the finished one, or, when argmin stopped the run
    /// (`reason`, from the final state), the current point with `reason` mapped onto
    /// [`Termination`] (an interrupt or a timeout is [`Termination::Interrupted`], the
    /// iteration limit [`Termination::MaxIterations`], a target cost
    /// [`Termination::RelativeReduction`]).
    pub(crate) fn solution(&mut self, reason: Option<&TerminationReason>) -> Option<Solution> {
        let mapped = match reason {
            Some(TerminationReason::MaxItersReached) => Termination::MaxIterations,
            Some(TerminationReason::TargetCostReached) => Termination::RelativeReduction,
            _ => Termination::Interrupted,
        };
        match std::mem::take(&mut self.stage) {
            Stage::Idle => None,
            Stage::Done(sol) | Stage::Polish { sol, .. } => Some(sol),
            Stage::Run { run, previous, .. } => {
                let (current, _) = run.end(mapped);
                Some(match previous {
                    Some(p) if p.fnorm <= current.fnorm => Solution {
                        iterations: p.iterations + current.iterations,
                        termination: mapped,
                        ..p
                    },
                    Some(p) => Solution {
                        iterations: p.iterations + current.iterations,
                        ..current
                    },
                    None => current,
                })
            }
        }
    }

    /// After a run ended with `sol`: restarts (from `sol`, if it converged and restarts are
    /// left), keeps the better of a restart and the run before it, then polishes a converged
    /// solution. `work` is the work space of the run, if it started.
    fn settle(
        &mut self,
        ls: View<'_>,
        mut sol: Solution,
        mut restarts: usize,
        mut previous: Option<Solution>,
        mut work: Option<Work>,
    ) -> Stage {
        loop {
            let current = match previous.take() {
                None => sol,
                Some(mut prev) => {
                    let improved = sol.fnorm < prev.fnorm;
                    let iterations = prev.iterations + sol.iterations;
                    if sol.termination.converged() || improved {
                        let s = Solution { iterations, ..sol };
                        if !improved {
                            return self.finalise(s, work);
                        }
                        s
                    } else {
                        prev.iterations = iterations;
                        return self.finalise(prev, work);
                    }
                }
            };
            if restarts < self.opts.restarts
                && current.termination.converged()
                && current.termination != Termination::ExactFit
            {
                restarts += 1;
                match LmRun::start(&mut self.ev, ls, current.x.clone(), &mut work) {
                    Ok(run) => {
                        return Stage::Run {
                            run: Box::new(run),
                            restarts,
                            previous: Some(current),
                        }
                    }
                    Err(s) => {
                        sol = s;
                        previous = Some(current);
                        continue;
                    }
                }
            }
            return self.finalise(current, work);
        }
    }

    /// Polish a converged solution (if asked; in `work`, if there is one), else finish.
    fn finalise(&mut self, sol: Solution, work: Option<Work>) -> Stage {
        if self.opts.polish
            && sol.termination.converged()
            && sol.termination != Termination::ExactFit
        {
            Stage::Polish {
                polisher: Box::new(Polisher::new(Work::reuse(work, self.ev.m, self.ev.n))),
                sol,
            }
        } else {
            if work.is_some() {
                self.spare = work;
            }
            Stage::Done(sol)
        }
    }

    /// The state after an iteration: the current point and χ², what the solver reports of its
    /// iteration, and the termination once done.
    fn report(&self, mut state: LmState) -> Result<(LmState, Option<KV>), Error> {
        let (x, fnorm) = match &self.stage {
            Stage::Run { run, previous, .. } => {
                let steps = run.iterations + previous.as_ref().map_or(0, |p| p.iterations);
                state.set_lm(LmStage::Lm, run.par, run.delta, steps);
                if run.outer > 0 {
                    state.set_scaling(&run.w.diag, &run.w.free);
                }
                (&run.x, run.fnorm)
            }
            Stage::Polish { polisher, sol } => {
                state.set_lm(LmStage::Polish, 0.0, f64::INFINITY, sol.iterations);
                if polisher.steps > 0 {
                    state.set_scaling(&polisher.w.diag, &polisher.w.free);
                }
                (&sol.x, sol.fnorm)
            }
            Stage::Done(sol) => {
                state.set_lm(LmStage::Done, 0.0, f64::INFINITY, sol.iterations);
                (&sol.x, sol.fnorm)
            }
            Stage::Idle => return Err(Error::msg("the Levenberg–Marquardt solver has no state")),
        };
        let chi2 = fnorm * fnorm;
        state.set_point(x, chi2);
        state.set_evals(self.ev.nfev, self.ev.njev, self.ev.nfev + self.ev.analytic);
        if let Stage::Done(sol) = &self.stage {
            let reason = if sol.termination.converged() {
                TerminationReason::SolverConverged
            } else {
                TerminationReason::SolverExit(format!("{:?}", sol.termination))
            };
            state = state.terminate_with(reason);
        }
        let kv = self.log.then(|| {
            argmin::kv!(
                "chi2" => chi2;
                "lambda" => state.lambda();
                "radius" => state.radius();
                "stage" => if state.stage() == LmStage::Lm { "lm" } else { "polish" };
            )
        });
        Ok((state, kv))
    }
}

/// The least-squares problem inside argmin's wrapper, as the iteration sees it, and argmin's
/// function counts.
fn parts<R: Residuals>(
    problem: &mut Problem<LeastSquares<R>>,
) -> Result<(View<'_>, &mut Counts), Error> {
    match &problem.problem {
        Some(ls) => Ok((ls.view(), &mut problem.counts)),
        None => Err(Error::msg("no least-squares problem")),
    }
}

/// argmin's function counts of a problem.
type Counts = HashMap<&'static str, u64>;

/// The solver proper, compiled once for every problem type: the [`Solver`] implementation only
/// unwraps argmin's problem and calls these.
impl LevenbergMarquardt {
    /// Moves the evaluator's counts into argmin's function counts (every iteration when the
    /// state counts, `LmState::counting`, else once the solver has finished).
    fn count(&self, state: &LmState, counts: &mut Counts) {
        if self.counts && (state.is_counting() || matches!(self.stage, Stage::Done(_))) {
            counts.insert("operator_count", self.ev.nfev as u64);
            counts.insert("jacobian_count", self.ev.njev as u64);
        }
    }

    /// [`Solver::init`]: the start (the state's `param` projected onto the box, else the
    /// problem's), the first run's residuals, and the state reporting them.
    #[inline(never)]
    fn init_view(
        &mut self,
        ls: View<'_>,
        counts: &mut Counts,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let (m, n) = (ls.problem.n_residuals(), ls.problem.n_params());
        let start = ls.setup.start_from(state.get_param())?;
        self.ev = Evaluator::new(m, n);
        let mut spare = self.spare.take();
        self.stage = match LmRun::start(&mut self.ev, ls, start, &mut spare) {
            Ok(run) => Stage::Run {
                run: Box::new(run),
                restarts: 0,
                previous: None,
            },
            Err(sol) => self.settle(ls, sol, 0, None, spare),
        };
        self.count(&state, counts);
        self.report(state)
    }

    /// [`Solver::next_iter`]: one outer Levenberg–Marquardt iteration or one polish step, the
    /// next stage when this one ends, and the state reporting it.
    #[inline(never)]
    fn next_iter_view(
        &mut self,
        ls: View<'_>,
        counts: &mut Counts,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        // The stage is replaced only when it ends.
        let ended = match &mut self.stage {
            Stage::Run { run, .. } => run.iterate(&mut self.ev, ls, &self.opts),
            Stage::Polish { polisher, sol } => {
                if polisher.step(&mut self.ev, ls, &self.opts, sol) {
                    None
                } else {
                    // Any value: the polish ends with the termination of its solution.
                    Some(Termination::Interrupted)
                }
            }
            Stage::Done(_) => None,
            Stage::Idle => return Err(Error::msg("the solver was not initialised")),
        };
        if let Some(t) = ended {
            self.stage = match std::mem::take(&mut self.stage) {
                Stage::Run {
                    run,
                    restarts,
                    previous,
                } => {
                    let (sol, work) = run.end(t);
                    self.settle(ls, sol, restarts, previous, Some(work))
                }
                Stage::Polish { sol, polisher } => {
                    self.spare = Some(polisher.w);
                    Stage::Done(sol)
                }
                other => other,
            };
        }
        self.count(&state, counts);
        self.report(state)
    }
}

impl<R: Residuals> Solver<LeastSquares<R>, LmState> for LevenbergMarquardt {
    fn name(&self) -> &str {
        "Levenberg-Marquardt (Moré 1978, bounded)"
    }

    fn init(
        &mut self,
        problem: &mut Problem<LeastSquares<R>>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let (ls, counts) = parts(problem)?;
        self.init_view(ls, counts, state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<LeastSquares<R>>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let (ls, counts) = parts(problem)?;
        self.next_iter_view(ls, counts, state)
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
    r: MatRef<'_, f64>,
    perm: &[usize],
    colnorm: &[f64],
) {
    let n = ipvt.len();
    ipvt.copy_from_slice(perm);
    for j in 0..n {
        for i in 0..n {
            sp.r[i + j * n] = if i <= j { r[(i, j)] } else { 0.0 };
        }
        if r[(j, j)].abs() <= n as f64 * f64::EPSILON * colnorm[ipvt[j]] {
            sp.r[j + j * n] = 0.0;
        }
    }
}

/// ‖D x‖, with `work` (length n) for D x.
fn scaled_norm(d: &[f64], x: &[f64], work: &mut [f64]) -> f64 {
    for ((w, a), b) in work.iter_mut().zip(d).zip(x) {
        *w = a * b;
    }
    norm2(work)
}

/// A problem of any type behind a trait object: the one problem type of the fits that
/// [`solve`] runs, so that argmin's `Executor` and the solver are compiled once for all of them.
pub(crate) type DynLeastSquares<'a> = LeastSquares<&'a dyn Residuals>;

/// Runs [`LevenbergMarquardt`] on `ls` under argmin's `Executor` (argmin's Ctrl-C handling off:
/// the stop flag of `opts` is the caller's; its timer off: nothing reads the iteration times,
/// and the profiles' many small fits would pay two clock reads per iteration; argmin's
/// function counts off: the evaluator counts, and the problem's counts are dropped), with a
/// [`ProgressObserver`] over `opts.progress` when there is one; returns the solution, the
/// evaluator (its counts and work space, for the covariance) and the problem.
pub(crate) fn solve<'a>(
    ls: DynLeastSquares<'a>,
    opts: &LsqOptions,
    spare: &mut Spare,
) -> Result<(Solution, Evaluator, DynLeastSquares<'a>), Error> {
    let solver = LevenbergMarquardt {
        counts: false,
        spare: spare.0.take(),
        ..LevenbergMarquardt::new(opts)
    };
    let mut executor = argmin::core::Executor::new(ls, solver)
        .ctrlc(false)
        .timer(false);
    if let Some(tally) = &opts.progress {
        executor =
            executor.add_observer(ProgressObserver::new(tally.clone()), ObserverMode::Always);
    }
    let (sol, solver, ls) = into_parts(executor.run()?)?;
    spare.0 = solver.spare;
    Ok((sol, solver.ev, ls))
}

/// The solution, the solver and the problem of an executor's result.
pub(crate) fn into_parts<R: Residuals>(
    result: argmin::core::OptimizationResult<LeastSquares<R>, LevenbergMarquardt, LmState>,
) -> Result<(Solution, LevenbergMarquardt, LeastSquares<R>), Error> {
    let mut result = result;
    let reason = result.state.get_termination_reason();
    let sol = result
        .solver
        .solution(reason)
        .ok_or_else(|| Error::msg("the Levenberg–Marquardt solver did not start"))?;
    let ls = result
        .problem
        .problem
        .ok_or_else(|| Error::msg("the executor lost the problem"))?;
    Ok((sol, result.solver, ls))
}
