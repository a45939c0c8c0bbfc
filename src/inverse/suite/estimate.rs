//! Tests of the least-squares estimate together with its profile intervals: the fit of
//! [`crate::inverse::estimate`] and the intervals of [`crate::inverse::profile`] on problems with known answers.

use crate::inverse::estimate::*;
use crate::inverse::lm::LevenbergMarquardt;
use crate::inverse::lsq::{CurveModel, Infeasible, WeightedData};
use crate::inverse::lsq::{LsqError, LsqOptions, Residuals, SigmaKind, Termination};
use crate::inverse::problem::LeastSquares;
use crate::inverse::profile::{ConfidenceIntervals, ProfileEnd};
use crate::inverse::state::LmState;
use std::cell::Cell;

/// y = a + b·x.
struct Line;
impl CurveModel<f64> for Line {
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
impl CurveModel<f64> for Decay {
    fn n_params(&self) -> usize {
        2
    }
    fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
        Ok(p[0] * (p[1] * x).exp())
    }
}

/// y = exp(b·x): one parameter.
struct Exp1;
impl CurveModel<f64> for Exp1 {
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
            let ci = ConfidenceIntervals::compute(&data, &f, level, &opts).unwrap();
            let wald = ci.covariance.as_ref().unwrap();
            for (k, wk) in wald.iter().enumerate().take(2) {
                let lo = ci.profile[k].lower.value().unwrap();
                let hi = ci.profile[k].upper.value().unwrap();
                let w = wk.upper - wk.lower;
                assert!(
                    (lo - wk.lower).abs() <= 1e-8 * w,
                    "{sigma:?} {level} {k}: {lo} vs {}",
                    wk.lower
                );
                assert!(
                    (hi - wk.upper).abs() <= 1e-8 * w,
                    "{sigma:?} {level} {k}: {hi} vs {}",
                    wk.upper
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
    let ci = ConfidenceIntervals::compute(&data, &f, 0.95, &opts).unwrap();
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

/// `LsqOptions::progress` counts the residual evaluations of the fit's iterations (a model
/// without a gradient: its Jacobians are differences) and of its profiles' constrained
/// fits, each report the running total. The fit's count is checked against the solver's
/// own count of the same run built by hand without an observer.
#[test]
fn progress_counts_the_fit_and_its_profiles() {
    use crate::progress::{Progress, ProgressEvent, Tally};
    use argmin::core::Executor;
    use std::sync::{Arc, Mutex};
    let (x, y) = exp_data();
    let data = WeightedData::new(Decay, x, y, Some(vec![0.3; 10])).unwrap();
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = {
        let seen = seen.clone();
        Progress::new(move |e| {
            if let ProgressEvent::Position(p) = e {
                seen.lock().unwrap().push(p);
            }
        })
    };
    let tally = Tally::new(sink);
    let opts = LsqOptions {
        progress: Some(tally.clone()),
        ..Default::default()
    };
    let f = fit(&data, &[1.0, 0.1], &opts).unwrap();
    assert!(f.converged());
    let ls = LeastSquares::new(&data, &[1.0, 0.1], &LsqOptions::default()).unwrap();
    let plain = Executor::new(ls, LevenbergMarquardt::new(&LsqOptions::default()))
        .run()
        .unwrap();
    let iterated = plain.solver().residual_evals();
    assert_eq!(tally.done() as usize, iterated);
    // The covariance's Jacobian, by differences, comes after the iterations.
    assert!(iterated < f.residual_evals);
    {
        let seen = seen.lock().unwrap();
        assert!(seen.windows(2).all(|w| w[0] < w[1]), "{seen:?}");
        assert_eq!(seen.last().copied(), Some(tally.done()));
    }
    let ci = ConfidenceIntervals::compute(&data, &f, 0.95, &opts).unwrap();
    let profiled: usize = ci.profile.iter().map(|p| p.residual_evals).sum();
    assert!(profiled > 0);
    assert_eq!(tally.done() as usize, iterated + profiled);
    // Every report is a running total (the profiles may run in parallel).
    let mut seen = seen.lock().unwrap().clone();
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.last().copied(), Some(tally.done()));
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
    let ci = ConfidenceIntervals::compute(&data, &f, 0.95, &opts).unwrap();
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
impl CurveModel<f64> for Root {
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
    impl CurveModel<f64> for LineNoGrad {
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
    impl CurveModel<f64> for Twice {
        fn n_params(&self) -> usize {
            2
        }
        fn value(&self, _x: &f64, p: &[f64]) -> Result<f64, Infeasible> {
            Ok(p[0] + p[1])
        }
        fn gradient(&self, _x: &f64, _p: &[f64], g: &mut [f64]) -> Option<Result<(), Infeasible>> {
            g.fill(1.0);
            Some(Ok(()))
        }
    }
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let d = WeightedData::new(Twice, x, y, None).unwrap();
    let f = fit(&d, &[1.0, 1.0], &LsqOptions::default()).unwrap();
    assert!(f.converged(), "{:?}", f.termination);
    assert!(f.covariance.is_none());
    assert!(close(f.params[0] + f.params[1], mean, 1e-12));
}

/// A run built by hand under argmin's `Executor` gives `fit`'s result; argmin's iteration
/// limit stops it where it is, as not converged; an observer sees every iteration.
#[test]
fn executor_runs_agree_with_fit() {
    use argmin::core::observers::{Observe, ObserverMode};
    use argmin::core::{Executor, State, KV};
    use std::sync::{Arc, Mutex};

    let (x, y) = exp_data();
    let data = WeightedData::new(Decay, x, y, None).unwrap();
    let opts = LsqOptions {
        restarts: 2,
        ..LsqOptions::default()
    };
    let direct = fit(&data, &[1.0, 0.0], &opts).unwrap();
    let ls = LeastSquares::new(&data, &[1.0, 0.0], &opts).unwrap();
    let run = Executor::new(ls, LevenbergMarquardt::new(&opts))
        .run()
        .unwrap();
    assert_eq!(Fit::from_run(run, opts.sigma).unwrap(), direct);

    #[derive(Clone)]
    struct Seen(Arc<Mutex<Vec<f64>>>);
    impl Observe<LmState> for Seen {
        fn observe_iter(&mut self, state: &LmState, kv: &KV) -> Result<(), argmin::core::Error> {
            let chi2 = kv.get("chi2").and_then(|v| v.get_float()).unwrap();
            assert_eq!(chi2, state.get_cost());
            self.0.lock().unwrap().push(chi2);
            Ok(())
        }
    }
    let seen = Seen(Arc::new(Mutex::new(Vec::new())));
    let ls = LeastSquares::new(&data, &[1.0, 0.0], &opts).unwrap();
    let run = Executor::new(ls, LevenbergMarquardt::new(&opts).with_log(true))
        .add_observer(seen.clone(), ObserverMode::Always)
        .configure(|s| s.max_iters(2))
        .run()
        .unwrap();
    let cut = Fit::from_run(run, opts.sigma).unwrap();
    assert_eq!(cut.termination, Termination::MaxIterations);
    assert!(!cut.converged());
    assert!(cut.chi2 > direct.chi2);
    let chi2s = seen.0.lock().unwrap().clone();
    assert_eq!(chi2s.len(), 2);
    assert!(chi2s[1] <= chi2s[0]);
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
    let ci = ConfidenceIntervals::compute(&data, &f, 0.95, &opts).unwrap();
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
    let ci = ConfidenceIntervals::compute(&data, &free, 0.95, &LsqOptions::default()).unwrap();
    let hi = ci.profile[0].upper.value().unwrap();
    let cap = free.params[0] + 0.5 * (hi - free.params[0]);
    let capped = Capped(data, cap);
    let f = fit(&capped, &[0.1], &LsqOptions::default()).unwrap();
    assert!(f.converged());
    let ci = ConfidenceIntervals::compute(&capped, &f, 0.95, &LsqOptions::default()).unwrap();
    match ci.profile[0].upper {
        ProfileEnd::Edge(v) => assert!(v <= cap && v > cap - 0.01 * (hi - f.params[0])),
        other => panic!("{other:?}"),
    }
}
