//! The argmin state of fitbead's Levenberg–Marquardt solver: [`LmState`] implements argmin's
//! [`State`] (current and best parameters and χ², iteration counts, termination status, what
//! argmin's `Executor` and observers read) and carries what the solver reports of its own
//! iteration — the Levenberg–Marquardt parameter λ, the trust radius Δ, the scaling D, the
//! parameters held on their bounds (the active set), the stage, and the evaluation counts.
//!
//! Everything sits behind one box, so that the state the executor moves through `init`,
//! `next_iter` and the termination checks at every iteration is a pointer.

use argmin::core::{Problem, State, TerminationReason, TerminationStatus};
use nalgebra::DVector;
use std::collections::HashMap;
use std::time::Duration;

/// Where the Levenberg–Marquardt solver is (see [`super::LevenbergMarquardt`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LmStage {
    /// Not started.
    #[default]
    Idle,
    /// Levenberg–Marquardt iterations (one Jacobian and the trial steps until one is accepted
    /// per argmin iteration).
    Lm,
    /// Gauss–Newton polish of a converged point (one step per argmin iteration).
    Polish,
    /// Finished.
    Done,
}

impl LmStage {
    /// The stage's name: `idle`, `lm`, `polish` or `done`.
    pub fn name(self) -> &'static str {
        match self {
            LmStage::Idle => "idle",
            LmStage::Lm => "lm",
            LmStage::Polish => "polish",
            LmStage::Done => "done",
        }
    }
}

/// The argmin state of [`super::LevenbergMarquardt`]: `param` is the current estimate and
/// `cost` its χ²; besides argmin's [`State`], the solver's own view of its iteration
/// ([`LmState::lambda`], [`LmState::radius`], [`LmState::scaling`], [`LmState::held`],
/// [`LmState::stage`], [`LmState::steps`] and the evaluation counts), which observers can read.
///
/// Configured like argmin's `IterState` (`Executor::configure`): [`LmState::param`] (a start
/// replacing the problem's), [`LmState::max_iters`], [`LmState::target_cost`],
/// [`LmState::counting`].
///
/// ```
/// use argmin::core::State;
/// use fitbead::inverse::{LmStage, LmState};
/// use nalgebra::DVector;
/// let s = LmState::new().param(DVector::from_vec(vec![1.0, 2.0])).max_iters(10);
/// assert_eq!(s.get_max_iters(), 10);
/// assert_eq!(s.get_param().unwrap()[1], 2.0);
/// assert_eq!(s.stage(), LmStage::Idle);
/// ```
#[derive(Debug, Clone, Default)]
pub struct LmState(Box<Inner>);

#[derive(Debug, Clone)]
struct Inner {
    param: Option<DVector<f64>>,
    best_param: Option<DVector<f64>>,
    cost: f64,
    best_cost: f64,
    target_cost: f64,
    iter: u64,
    last_best_iter: u64,
    max_iters: u64,
    counts: HashMap<String, u64>,
    counting: bool,
    time: Option<Duration>,
    status: TerminationStatus,
    lambda: f64,
    radius: f64,
    scaling: Vec<f64>,
    held: Vec<bool>,
    stage: LmStage,
    steps: usize,
    residual_evals: usize,
    jacobian_evals: usize,
    model_evals: usize,
}

impl Default for Inner {
    fn default() -> Self {
        Inner {
            param: None,
            best_param: None,
            cost: f64::INFINITY,
            best_cost: f64::INFINITY,
            target_cost: f64::NEG_INFINITY,
            iter: 0,
            last_best_iter: 0,
            max_iters: u64::MAX,
            counts: HashMap::new(),
            counting: false,
            time: Some(Duration::ZERO),
            status: TerminationStatus::NotTerminated,
            lambda: 0.0,
            radius: f64::INFINITY,
            scaling: Vec::new(),
            held: Vec::new(),
            stage: LmStage::Idle,
            steps: 0,
            residual_evals: 0,
            jacobian_evals: 0,
            model_evals: 0,
        }
    }
}

impl Inner {
    /// Makes the current point the best one.
    fn new_best(&mut self) {
        if let Some(p) = &self.param {
            match &mut self.best_param {
                Some(b) if b.len() == p.len() => b.copy_from(p),
                b => *b = Some(p.clone()),
            }
        }
        self.best_cost = self.cost;
        self.last_best_iter = self.iter;
    }

    /// Copies argmin's function counts of a problem.
    fn copy_counts(&mut self, counts: &HashMap<&'static str, u64>) {
        for (k, &v) in counts.iter() {
            match self.counts.get_mut(*k) {
                Some(c) => *c = v,
                None => {
                    self.counts.insert(k.to_string(), v);
                }
            }
        }
    }
}

/// Copies `src` into `dst`, reusing its allocation when the lengths agree.
fn copy_into<T: Copy>(dst: &mut Vec<T>, src: &[T]) {
    if dst.len() == src.len() {
        dst.copy_from_slice(src);
    } else {
        dst.clear();
        dst.extend_from_slice(src);
    }
}

impl LmState {
    /// The starting point (replacing the problem's; projected onto the box).
    #[must_use]
    pub fn param(mut self, param: DVector<f64>) -> Self {
        self.0.param = Some(param);
        self
    }

    /// At most `iters` argmin iterations (then [`super::Termination::MaxIterations`]).
    #[must_use]
    pub fn max_iters(mut self, iters: u64) -> Self {
        self.0.max_iters = iters;
        self
    }

    /// Stop once χ² is at most `cost` (argmin's target cost).
    #[must_use]
    pub fn target_cost(mut self, cost: f64) -> Self {
        self.0.target_cost = cost;
        self
    }

    /// Copy the problem's function counts (`operator_count`, `jacobian_count`) into the state
    /// at every iteration ([`State::get_func_counts`]); off by default.
    #[must_use]
    pub fn counting(mut self, on: bool) -> Self {
        self.0.counting = on;
        self
    }

    /// Whether the function counts are copied at every iteration ([`LmState::counting`]).
    pub fn is_counting(&self) -> bool {
        self.0.counting
    }

    /// The Levenberg–Marquardt parameter λ of the last iteration (0 in the polish).
    pub fn lambda(&self) -> f64 {
        self.0.lambda
    }

    /// The trust radius Δ (+∞ in the polish, whose Gauss–Newton steps are unconstrained).
    pub fn radius(&self) -> f64 {
        self.0.radius
    }

    /// The diagonal scaling D of the last iteration (the running maximum of the Jacobian's
    /// column norms; in the polish, the current column norms); empty before the first
    /// Jacobian.
    pub fn scaling(&self) -> &[f64] {
        &self.0.scaling
    }

    /// The active set of the last iteration: true for a parameter held on its bound (its
    /// gradient component points out of the box); empty before the first Jacobian.
    pub fn held(&self) -> &[bool] {
        &self.0.held
    }

    /// Where the solver is.
    pub fn stage(&self) -> LmStage {
        self.0.stage
    }

    /// Steps taken so far: accepted Levenberg–Marquardt steps and Gauss–Newton polish steps,
    /// over the restarts — what [`super::Fit::iterations`] reports at the end.
    pub fn steps(&self) -> usize {
        self.0.steps
    }

    /// Residual evaluations so far (finite-difference ones included).
    pub fn residual_evals(&self) -> usize {
        self.0.residual_evals
    }

    /// Jacobian evaluations so far (analytic or by differences).
    pub fn jacobian_evals(&self) -> usize {
        self.0.jacobian_evals
    }

    /// Model evaluations so far: every residual vector (finite-difference ones included) and
    /// every analytic Jacobian, one each — the count `ProgressObserver` reports.
    pub fn model_evals(&self) -> usize {
        self.0.model_evals
    }

    /// Sets the current point and χ² (the point's buffer is reused).
    #[inline]
    pub(crate) fn set_point(&mut self, x: &[f64], cost: f64) {
        let s = &mut *self.0;
        match &mut s.param {
            Some(p) if p.len() == x.len() => p.copy_from_slice(x),
            p => *p = Some(DVector::from_column_slice(x)),
        }
        s.cost = cost;
    }

    /// Sets what the solver reports of its iteration.
    #[inline]
    pub(crate) fn set_lm(&mut self, stage: LmStage, lambda: f64, radius: f64, steps: usize) {
        let s = &mut *self.0;
        s.stage = stage;
        s.lambda = lambda;
        s.radius = radius;
        s.steps = steps;
    }

    /// Sets the scaling D and the active set from the solver's `free` flags.
    #[inline]
    pub(crate) fn set_scaling(&mut self, diag: &[f64], free: &[bool]) {
        let s = &mut *self.0;
        copy_into(&mut s.scaling, diag);
        if s.held.len() != free.len() {
            s.held.resize(free.len(), false);
        }
        for (h, f) in s.held.iter_mut().zip(free) {
            *h = !f;
        }
    }

    /// Sets the evaluation counts.
    #[inline]
    pub(crate) fn set_evals(&mut self, residual: usize, jacobian: usize, model: usize) {
        let s = &mut *self.0;
        s.residual_evals = residual;
        s.jacobian_evals = jacobian;
        s.model_evals = model;
    }
}

impl State for LmState {
    type Param = DVector<f64>;
    type Float = f64;

    fn new() -> Self {
        LmState::default()
    }

    /// A lower χ² makes the current point the best one.
    #[inline]
    fn update(&mut self) {
        let s = &mut *self.0;
        if s.cost < s.best_cost
            || (s.cost.is_infinite()
                && s.best_cost.is_infinite()
                && s.cost.is_sign_positive() == s.best_cost.is_sign_positive())
        {
            s.new_best();
        }
    }

    fn get_param(&self) -> Option<&DVector<f64>> {
        self.0.param.as_ref()
    }

    fn get_best_param(&self) -> Option<&DVector<f64>> {
        self.0.best_param.as_ref()
    }

    fn get_max_iters(&self) -> u64 {
        self.0.max_iters
    }

    fn increment_iter(&mut self) {
        self.0.iter += 1;
    }

    fn get_iter(&self) -> u64 {
        self.0.iter
    }

    fn get_cost(&self) -> f64 {
        self.0.cost
    }

    fn get_best_cost(&self) -> f64 {
        self.0.best_cost
    }

    fn get_target_cost(&self) -> f64 {
        self.0.target_cost
    }

    /// Copies the problem's counts when counting is on ([`LmState::counting`]).
    #[inline]
    fn func_counts<O>(&mut self, problem: &Problem<O>) {
        if self.0.counting {
            self.0.copy_counts(&problem.counts);
        }
    }

    fn get_func_counts(&self) -> &HashMap<String, u64> {
        &self.0.counts
    }

    fn time(&mut self, time: Option<Duration>) -> &mut Self {
        self.0.time = time;
        self
    }

    fn get_time(&self) -> Option<Duration> {
        self.0.time
    }

    fn get_last_best_iter(&self) -> u64 {
        self.0.last_best_iter
    }

    fn is_best(&self) -> bool {
        self.0.last_best_iter == self.0.iter
    }

    fn terminate_with(mut self, reason: TerminationReason) -> Self {
        self.0.status = TerminationStatus::Terminated(reason);
        self
    }

    fn get_termination_status(&self) -> &TerminationStatus {
        &self.0.status
    }

    fn get_termination_reason(&self) -> Option<&TerminationReason> {
        match &self.0.status {
            TerminationStatus::Terminated(r) => Some(r),
            TerminationStatus::NotTerminated => None,
        }
    }
}
