//! Progress of a least-squares fit as an argmin observer: [`ProgressObserver`] reads the model
//! evaluations of [`super::LevenbergMarquardt`] from its state ([`LmState::model_evals`]) at
//! initialisation and after every iteration, and adds the new ones to a [`Tally`] — the
//! count a user interface draws (the command line's progress bars of `klaw`, `jan` and
//! `jaeger`). [`super::fit`] and the profiles' constrained fits attach one to their executor
//! when [`super::LsqOptions::progress`] is set.

use argmin::core::observers::Observe;
use argmin::core::{Error, KV};

use super::state::LmState;
use crate::progress::Tally;

/// An argmin observer of [`super::LevenbergMarquardt`] that adds the model evaluations of
/// each iteration (residual vectors, finite-difference ones included, and analytic Jacobians:
/// [`LmState::model_evals`]) to a [`Tally`].
#[derive(Debug, Clone)]
pub struct ProgressObserver {
    tally: Tally,
    reported: usize,
}

impl ProgressObserver {
    /// An observer adding to `tally` (shared with its clones and with the caller).
    pub fn new(tally: Tally) -> Self {
        ProgressObserver { tally, reported: 0 }
    }

    /// Adds the evaluations since the last report.
    fn advance(&mut self, state: &LmState) {
        let done = state.model_evals();
        if done > self.reported {
            self.tally.add((done - self.reported) as u64);
            self.reported = done;
        }
    }
}

impl Observe<LmState> for ProgressObserver {
    fn observe_init(&mut self, _name: &str, state: &LmState, _kv: &KV) -> Result<(), Error> {
        self.advance(state);
        Ok(())
    }

    fn observe_iter(&mut self, state: &LmState, _kv: &KV) -> Result<(), Error> {
        self.advance(state);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inverse::{
        fit, CurveModel, Fit, Infeasible, LeastSquares, LevenbergMarquardt, LmStage, LsqOptions,
        WeightedData,
    };
    use crate::progress::{Progress, ProgressEvent};
    use argmin::core::observers::ObserverMode;
    use argmin::core::{Executor, State};
    use std::sync::{Arc, Mutex};

    /// y = a e^(−b x), with or without its analytic gradient.
    struct Decay {
        analytic: bool,
    }
    impl CurveModel<f64> for Decay {
        fn n_params(&self) -> usize {
            2
        }
        fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
            Ok(p[0] * (-p[1] * x).exp())
        }
        fn gradient(&self, x: &f64, p: &[f64], g: &mut [f64]) -> Option<Result<(), Infeasible>> {
            if !self.analytic {
                return None;
            }
            let e = (-p[1] * x).exp();
            g[0] = e;
            g[1] = -p[0] * x * e;
            Some(Ok(()))
        }
    }

    /// One iteration as an observer saw it: (iteration, steps, stage, model evaluations).
    type Row = (u64, usize, LmStage, usize);

    /// What an observer saw at each iteration.
    #[derive(Clone, Default)]
    struct Seen(Arc<Mutex<Vec<Row>>>);
    impl Observe<LmState> for Seen {
        fn observe_iter(&mut self, state: &LmState, _kv: &KV) -> Result<(), Error> {
            self.0.lock().unwrap().push((
                state.get_iter(),
                state.steps(),
                state.stage(),
                state.model_evals(),
            ));
            Ok(())
        }
    }

    /// The observer is called at every iteration of a fit: once per Jacobian (one per
    /// Levenberg–Marquardt iteration or polish step; `fit` evaluates one more for the
    /// covariance), the steps it reads add up to the fit's iterations, and the tally it feeds
    /// ends at the solver's own count of model evaluations.
    /// Under argmin's `Executor`, the tally ends at the solver's count of residual
    /// evaluations.
    #[test]
    fn the_tally_counts_every_residual_evaluation_under_an_executor() {
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|x| 3.0 * (-0.5 * x).exp() + 0.01 * x.sin())
            .collect();
        let opts = LsqOptions::default();
        let data = WeightedData::new(Decay { analytic: false }, x, y, None).unwrap();
        let ls = LeastSquares::new(data, &[1.0, 1.0], &opts).unwrap();
        let tally = Tally::new(Progress::new(|_| {}));
        let result = Executor::new(ls, LevenbergMarquardt::new(&opts))
            .add_observer(ProgressObserver::new(tally.clone()), ObserverMode::Always)
            .run()
            .unwrap();
        assert_eq!(tally.done() as usize, result.solver().residual_evals());
    }

    #[test]
    fn the_observer_sees_every_iteration_of_a_fit() {
        let x: Vec<f64> = (0..12).map(f64::from).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|x| 3.0 * (-0.4 * x).exp() + 0.02 * (3.0 * x).sin())
            .collect();
        for analytic in [false, true] {
            let data = WeightedData::new(Decay { analytic }, x.clone(), y.clone(), None).unwrap();
            let opts = LsqOptions::default();
            let direct = fit(&data, &[1.0, 1.0], &opts).unwrap();
            assert!(direct.converged());

            let positions = Arc::new(Mutex::new(Vec::new()));
            let sink = {
                let positions = positions.clone();
                Progress::new(move |e| {
                    if let ProgressEvent::Position(p) = e {
                        positions.lock().unwrap().push(p);
                    }
                })
            };
            let tally = Tally::new(sink);
            let seen = Seen::default();
            let ls = LeastSquares::new(&data, &[1.0, 1.0], &opts).unwrap();
            let result = Executor::new(ls, LevenbergMarquardt::new(&opts))
                .add_observer(ProgressObserver::new(tally.clone()), ObserverMode::Always)
                .add_observer(seen.clone(), ObserverMode::Always)
                .run()
                .unwrap();
            let (nfev, njev) = (
                result.solver().residual_evals(),
                result.solver().jacobian_evals(),
            );
            let observed = Fit::from_run(result, opts.sigma).unwrap();
            assert_eq!(observed, direct);

            let seen = seen.0.lock().unwrap().clone();
            let iters: Vec<u64> = seen.iter().map(|s| s.0).collect();
            assert_eq!(iters, (0..seen.len() as u64).collect::<Vec<_>>());
            assert_eq!(
                seen.len(),
                direct.jacobian_evals - 1,
                "analytic: {analytic}"
            );
            assert_eq!(seen.len(), njev);
            let steps: Vec<usize> = seen.iter().map(|s| s.1).collect();
            assert!(steps.windows(2).all(|w| w[1] == w[0] || w[1] == w[0] + 1));
            assert_eq!(steps.last().copied(), Some(direct.iterations));
            assert!(seen.iter().any(|s| s.2 == LmStage::Lm));
            assert!(seen.iter().any(|s| s.2 == LmStage::Polish));
            assert_eq!(seen.last().map(|s| s.2), Some(LmStage::Done));

            let model = nfev + if analytic { njev } else { 0 };
            assert_eq!(seen.last().map(|s| s.3), Some(model));
            assert_eq!(tally.done() as usize, model);
            let positions = positions.lock().unwrap().clone();
            assert!(positions.windows(2).all(|w| w[0] < w[1]));
            // At most one report at the start and one per iteration.
            assert!(positions.len() <= seen.len() + 1);
            assert_eq!(positions.last().copied(), Some(tally.done()));
        }
    }
}
