//! Tests of the ensemble sampler and its diagnostics (src/inverse/mcmc.rs).
//!
//! Every tolerance is a Monte-Carlo error: an estimate of E[f] from the draws is checked
//! against the exact value within 4 standard errors, sd(f)/√ESS with ESS = `ess_mean` of the
//! series f itself (Vehtari et al. 2021), so a correct sampler fails a given check with
//! probability ≈ 6e-5.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::inverse::mcmc::diagnostics::{
    autocovariance, ess_bulk, ess_mean, ess_tail, integrated_time, parameter_chains, rhat, SOKAL_C,
};
use crate::inverse::mcmc::{
    EnsembleSampler, LogDensity, McmcError, McmcOptions, McmcResult, StopReason,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Gaussian N(μ, L Lᵀ) with L lower triangular: log p = −½ |L⁻¹(x − μ)|².
struct Gaussian {
    mu: Vec<f64>,
    l: Vec<Vec<f64>>,
}

impl Gaussian {
    fn covariance(&self) -> Vec<Vec<f64>> {
        self.l
            .iter()
            .map(|li| {
                self.l
                    .iter()
                    .map(|lj| li.iter().zip(lj).map(|(a, b)| a * b).sum())
                    .collect()
            })
            .collect()
    }
}

impl LogDensity for Gaussian {
    fn dim(&self) -> usize {
        self.mu.len()
    }
    fn log_density(&self, x: &[f64]) -> f64 {
        // Forward substitution L u = x − μ.
        let n = self.mu.len();
        let mut u = vec![0.0; n];
        for i in 0..n {
            let s: f64 = (0..i).map(|k| self.l[i][k] * u[k]).sum();
            u[i] = (x[i] - self.mu[i] - s) / self.l[i][i];
        }
        -0.5 * u.iter().map(|v| v * v).sum::<f64>()
    }
}

/// Checks that the mean of f over the draws is within 4 Monte-Carlo standard errors of
/// `expected`; returns (estimate, standard error) for printing.
fn check_mean(name: &str, r: &McmcResult, f: impl Fn(&[f64]) -> f64, expected: f64) -> (f64, f64) {
    let series: Vec<Vec<f64>> = r
        .chains
        .iter()
        .map(|c| c.iter().map(|x| f(x)).collect())
        .collect();
    let all: Vec<f64> = series.iter().flatten().copied().collect();
    let s = all.len() as f64;
    let mean = all.iter().sum::<f64>() / s;
    let sd = (all.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (s - 1.0)).sqrt();
    let ess = ess_mean(&series);
    let se = sd / ess.sqrt();
    println!(
        "{name}: {mean:.5} (exact {expected:.5}), MC se {se:.5}, ESS {ess:.0}, |err|/se = {:.2}",
        (mean - expected).abs() / se
    );
    assert!(
        (mean - expected).abs() <= 4.0 * se,
        "{name}: {mean} vs {expected}, se {se}"
    );
    (mean, se)
}

fn report(r: &McmcResult) {
    println!(
        "steps {}, burn-in {}, kept/walker {}, τ_max {:.1}, acceptance {:.3}, converged {}, {:?}",
        r.steps,
        r.burn_in,
        r.chains[0].len(),
        r.tau_max,
        r.acceptance_overall,
        r.converged,
        r.reason
    );
    for (k, d) in r.diagnostics.iter().enumerate() {
        println!(
            "  p{k}: mean {:.4} sd {:.4} [{:.4}, {:.4}] R̂ {:.4} ESS bulk {:.0} tail {:.0} τ {:.1}",
            d.mean, d.sd, d.q025, d.q975, d.rhat, d.ess_bulk, d.ess_tail, d.tau
        );
    }
}

/// Correlated 2-D Gaussian, ρ = 0.9, σ = (1, 10), μ = (1, −2). Exact moments: the parameters
/// of the density. Covariance entries are means of (xᵢ − μᵢ)(xⱼ − μⱼ) with μ known.
#[test]
fn correlated_gaussian_2d() {
    let (s1, s2, rho) = (1.0, 10.0, 0.9_f64);
    let g = Gaussian {
        mu: vec![1.0, -2.0],
        l: vec![vec![s1, 0.0], vec![rho * s2, s2 * (1.0 - rho * rho).sqrt()]],
    };
    let sampler = EnsembleSampler::new(
        &g,
        McmcOptions {
            seed: 1,
            ..McmcOptions::default()
        },
    )
    .unwrap();
    let r = sampler.run(&[0.0, 0.0]).unwrap();
    report(&r);
    assert!(r.converged && r.reason == StopReason::Converged);
    assert_eq!(r.failing_parameter, None);
    for d in &r.diagnostics {
        assert!(d.rhat <= 1.01 && d.ess_bulk >= 1000.0 && d.ess_tail >= 1000.0);
    }
    let c = g.covariance();
    for i in 0..2 {
        check_mean(&format!("mean x{i}"), &r, |x| x[i], g.mu[i]);
    }
    for i in 0..2 {
        for j in i..2 {
            let mu = g.mu.clone();
            check_mean(
                &format!("cov[{i}][{j}]"),
                &r,
                move |x| (x[i] - mu[i]) * (x[j] - mu[j]),
                c[i][j],
            );
        }
    }
}

/// 5-D Gaussian with the dense covariance Σ = L Lᵀ, L below (exact moments μ, Σ).
#[test]
fn dense_gaussian_5d() {
    let l = vec![
        vec![2.0, 0.0, 0.0, 0.0, 0.0],
        vec![0.5, 1.0, 0.0, 0.0, 0.0],
        vec![-1.0, 0.3, 0.5, 0.0, 0.0],
        vec![0.2, -0.4, 0.6, 3.0, 0.0],
        vec![1.0, 1.0, 1.0, 1.0, 0.1],
    ];
    let g = Gaussian {
        mu: vec![0.0, 1.0, -1.0, 10.0, 5.0],
        l,
    };
    let sampler = EnsembleSampler::new(
        &g,
        McmcOptions {
            seed: 5,
            thin: 5,
            check_every: 1000,
            ..McmcOptions::default()
        },
    )
    .unwrap();
    let r = sampler
        .run(&g.mu.iter().map(|m| m + 1.0).collect::<Vec<_>>())
        .unwrap();
    report(&r);
    assert!(r.converged);
    let c = g.covariance();
    for i in 0..5 {
        check_mean(&format!("mean x{i}"), &r, |x| x[i], g.mu[i]);
        let mu = g.mu[i];
        check_mean(
            &format!("var x{i}"),
            &r,
            move |x| (x[i] - mu).powi(2),
            c[i][i],
        );
    }
}

/// Banana (Rosenbrock-type) density log p = −(x − 1)²/2 − (y − x²)²/(2·0.25), a milder
/// curvature than emcee's Rosenbrock example (whose τ of ~4000 steps would need minutes).
/// Derivation of the exact moments: for fixed x, y ~ N(x², 0.25), whose normaliser does not
/// depend on x, so the marginal of x is ∝ exp(−(x − 1)²/2), i.e. x ~ N(1, 1): E[x] = 1, and
/// E[y] = E[E[y | x]] = E[x²] = Var x + (E x)² = 1 + 1 = 2.
#[test]
fn banana() {
    struct Banana;
    impl LogDensity for Banana {
        fn dim(&self) -> usize {
            2
        }
        fn log_density(&self, p: &[f64]) -> f64 {
            let (x, y) = (p[0], p[1]);
            -0.5 * (x - 1.0).powi(2) - 2.0 * (y - x * x).powi(2)
        }
    }
    let sampler = EnsembleSampler::new(
        &Banana,
        McmcOptions {
            seed: 3,
            max_steps: 100_000,
            thin: 5,
            check_every: 2000,
            ..McmcOptions::default()
        },
    )
    .unwrap();
    let r = sampler.run(&[1.0, 1.0]).unwrap();
    report(&r);
    assert!(r.converged);
    check_mean("E[x]", &r, |p| p[0], 1.0);
    check_mean("E[y]", &r, |p| p[1], 2.0);
}

/// Walkers started alternately in the two modes (±10, 0) of a bimodal mixture, a few hundred
/// steps: the stretch move cannot carry a walker between modes (its proposals from a
/// complementary walker in the other mode land between the modes or beyond), so the split
/// chains have different means and R̂ on x₀ is far above 1.01.
#[test]
fn bimodal_not_converged() {
    struct Bimodal;
    impl LogDensity for Bimodal {
        fn dim(&self) -> usize {
            2
        }
        fn log_density(&self, p: &[f64]) -> f64 {
            let a = -0.5 * ((p[0] - 10.0).powi(2) + p[1] * p[1]);
            let b = -0.5 * ((p[0] + 10.0).powi(2) + p[1] * p[1]);
            a.max(b) + (-(a - b).abs()).exp().ln_1p()
        }
    }
    let options = McmcOptions {
        seed: 7,
        max_steps: 400,
        check_every: 100,
        ..McmcOptions::default()
    };
    let sampler = EnsembleSampler::new(&Bimodal, options).unwrap();
    let nw = sampler.walkers();
    let ensemble: Vec<Vec<f64>> = (0..nw)
        .map(|w| {
            let s = if w % 2 == 0 { 10.0 } else { -10.0 };
            vec![s + 0.01 * w as f64, 0.01 * (w as f64 - 16.0)]
        })
        .collect();
    let r = sampler.run_from(ensemble, |_, _| {}).unwrap();
    report(&r);
    assert!(!r.converged);
    assert_eq!(r.reason, StopReason::MaxSteps);
    assert_eq!(r.steps, 400);
    assert!(r.diagnostics[0].rhat > 1.01, "R̂ {}", r.diagnostics[0].rhat);
    assert_eq!(r.failing_parameter, Some(0));
}

/// Same seed ⇒ bit-identical chains with 1 and with 2 rayon threads.
#[test]
fn deterministic_across_thread_counts() {
    let g = Gaussian {
        mu: vec![0.0, 0.0, 0.0],
        l: vec![
            vec![1.0, 0.0, 0.0],
            vec![0.5, 1.0, 0.0],
            vec![0.1, 0.2, 0.3],
        ],
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let options = McmcOptions {
                seed: 42,
                max_steps: 600,
                check_every: 200,
                init_scale: Some(vec![1.0, 1.0, 1.0]),
                ..McmcOptions::default()
            };
            EnsembleSampler::new(&g, options)
                .unwrap()
                .run(&[0.5, 0.5, 0.5])
                .unwrap()
        })
    };
    let (a, b) = (run(1), run(2));
    let bits = |r: &McmcResult| -> Vec<u64> {
        r.chains
            .iter()
            .flatten()
            .flatten()
            .chain(r.log_densities.iter().flatten())
            .map(|v| v.to_bits())
            .collect()
    };
    assert!(!a.chains[0].is_empty());
    assert_eq!(a.steps, b.steps);
    assert_eq!(a.burn_in, b.burn_in);
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.acceptance, b.acceptance);
    println!("{} draws identical with 1 and 2 threads", bits(&a).len());
    // A different seed gives different chains.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let c = pool.install(|| {
        let options = McmcOptions {
            seed: 43,
            max_steps: 600,
            check_every: 200,
            init_scale: Some(vec![1.0, 1.0, 1.0]),
            ..McmcOptions::default()
        };
        EnsembleSampler::new(&g, options)
            .unwrap()
            .run(&[0.5, 0.5, 0.5])
            .unwrap()
    });
    assert_ne!(bits(&a)[..100], bits(&c)[..100]);
}

/// On i.i.d. N(0, 1) draws (8 chains × 2000): R̂ ≤ 1.01 and the ESS are the number of draws
/// within 20 % (for independent draws ESS = S by definition, Vehtari et al. 2021); on 4 AR(1)
/// chains x_{t+1} = φ x_t + √(1−φ²) ε of 100 000 steps with φ = 0.9, the integrated
/// autocorrelation time is (1 + φ)/(1 − φ) = 19 (Sokal 1997, ρ(t) = φ^t) within 15 %.
#[test]
fn diagnostics_iid_and_ar1() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let iid: Vec<Vec<f64>> = (0..8)
        .map(|_| (0..2000).map(|_| StandardNormal.sample(&mut rng)).collect())
        .collect();
    let s = 16000.0;
    let (rh, eb, et, em) = (rhat(&iid), ess_bulk(&iid), ess_tail(&iid), ess_mean(&iid));
    let tau = integrated_time(&iid, SOKAL_C);
    println!("iid: R̂ {rh:.5}, ESS bulk {eb:.0} tail {et:.0} mean {em:.0} (S = {s}), τ {tau:.3}");
    assert!((0.99..=1.01).contains(&rh));
    for e in [eb, et, em] {
        assert!((e - s).abs() <= 0.2 * s, "ESS {e}");
    }

    let phi = 0.9_f64;
    let innov = (1.0 - phi * phi).sqrt();
    let ar: Vec<Vec<f64>> = (0..4)
        .map(|_| {
            let mut x: f64 = StandardNormal.sample(&mut rng);
            (0..100_000)
                .map(|_| {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    x = phi * x + innov * e;
                    x
                })
                .collect()
        })
        .collect();
    let tau = integrated_time(&ar, SOKAL_C);
    let exact = (1.0 + phi) / (1.0 - phi);
    let em = ess_mean(&ar);
    println!(
        "AR(1) φ = 0.9: τ {tau:.3} (exact {exact}), ESS mean {em:.0} (S/τ = {:.0}), R̂ {:.5}",
        400_000.0 / exact,
        rhat(&ar)
    );
    assert!((tau - exact).abs() <= 0.15 * exact);
    assert!((em - 400_000.0 / exact).abs() <= 0.2 * 400_000.0 / exact);
}

/// Support x > 0 only: x ~ Exp(1) (log p = −x on x > 0, −∞ elsewhere), y ~ N(0, 1).
/// No draw may land in x ≤ 0; E[x] = 1 (exponential mean). The start ball (scale 1 around
/// x = 0.5) puts some initial walkers at x ≤ 0, which must be redrawn.
#[test]
fn infeasible_region() {
    struct HalfLine;
    impl LogDensity for HalfLine {
        fn dim(&self) -> usize {
            2
        }
        fn log_density(&self, p: &[f64]) -> f64 {
            if p[0] <= 0.0 {
                f64::NEG_INFINITY
            } else {
                -p[0] - 0.5 * p[1] * p[1]
            }
        }
    }
    let sampler = EnsembleSampler::new(
        &HalfLine,
        McmcOptions {
            seed: 9,
            init_scale: Some(vec![1.0, 1.0]),
            ..McmcOptions::default()
        },
    )
    .unwrap();
    let init = sampler.initial_ensemble(&[0.5, 0.0]).unwrap();
    assert!(init.iter().all(|x| x[0] > 0.0));
    let r = sampler.run(&[0.5, 0.0]).unwrap();
    report(&r);
    assert!(r.converged);
    let min_x = r
        .chains
        .iter()
        .flatten()
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min);
    println!("smallest x drawn: {min_x:e}");
    assert!(min_x > 0.0);
    assert!(r.log_densities.iter().flatten().all(|v| v.is_finite()));
    check_mean("E[x]", &r, |p| p[0], 1.0);
    check_mean("E[y]", &r, |p| p[1], 0.0);
}

/// A NaN log density is treated as −∞ and counted; the stop flag interrupts a run; invalid
/// options are rejected.
#[test]
fn nan_stop_and_validation() {
    struct NanLeft;
    impl LogDensity for NanLeft {
        fn dim(&self) -> usize {
            1
        }
        fn log_density(&self, p: &[f64]) -> f64 {
            if p[0] < 0.0 {
                f64::NAN
            } else {
                -0.5 * (p[0] - 1.0).powi(2)
            }
        }
    }
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let sampler = EnsembleSampler::new(
        &NanLeft,
        McmcOptions {
            seed: 1,
            max_steps: 10_000,
            init_scale: Some(vec![0.5]),
            stop: Some(stop),
            ..McmcOptions::default()
        },
    )
    .unwrap();
    let mut calls = 0;
    let r = sampler
        .run_with_progress(&[1.0], |step, max| {
            calls += 1;
            assert_eq!(max, 10_000);
            if step == 300 {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        })
        .unwrap();
    println!(
        "interrupted after {} steps, {} NaN evaluations",
        r.steps, r.nan_evaluations
    );
    assert_eq!(r.reason, StopReason::Interrupted);
    assert_eq!(r.steps, 300);
    assert_eq!(calls, 300);
    assert!(r.nan_evaluations > 0);
    assert!(r.chains.iter().flatten().all(|p| p[0] >= 0.0));

    let g = Gaussian {
        mu: vec![0.0; 3],
        l: vec![
            vec![1.0, 0.0, 0.0],
            vec![0.0, 1.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ],
    };
    let with = |walkers| McmcOptions {
        walkers: Some(walkers),
        ..McmcOptions::default()
    };
    assert_eq!(
        EnsembleSampler::new(&g, with(7)).err(),
        Some(McmcError::OddWalkers(7))
    );
    assert_eq!(
        EnsembleSampler::new(&g, with(2)).err(),
        Some(McmcError::TooFewWalkers { walkers: 2, dim: 3 })
    );
    let s = EnsembleSampler::new(&g, McmcOptions::default()).unwrap();
    assert_eq!(s.walkers(), 32);
    assert!(matches!(s.run(&[0.0, 0.0]), Err(McmcError::Length { .. })));
    // A start point outside the support: every draw of the ball is infeasible.
    let s = EnsembleSampler::new(
        &NanLeft,
        McmcOptions {
            max_init_tries: 5,
            ..McmcOptions::default()
        },
    )
    .unwrap();
    assert!(matches!(
        s.run(&[-1.0]),
        Err(McmcError::InitFailed { tries: 5, .. })
    ));
    // parameter_chains extracts one parameter.
    let chains = vec![vec![vec![1.0, 2.0], vec![3.0, 4.0]]];
    assert_eq!(parameter_chains(&chains, 1), vec![vec![2.0, 4.0]]);
}

/// The FFT autocovariance against the direct O(n²) sum (1/n) Σ (xᵢ − x̄)(x_{i+t} − x̄), on
/// random series of lengths 1 to 5,000, including lengths just past a power of two: agreement
/// within 1e-13 of γ(0) at every lag (measured: at most 1.6e-15).
#[test]
fn autocovariance_matches_the_direct_sum() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst: f64 = 0.0;
    for n in [1, 2, 3, 7, 64, 65, 100, 1023, 1025, 5000] {
        let x: Vec<f64> = (0..n)
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                3.0 + z
            })
            .collect();
        let mean = x.iter().sum::<f64>() / n as f64;
        let fft = autocovariance(&x);
        assert_eq!(fft.len(), n);
        let scale = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        for t in 0..n {
            let direct: f64 = (0..n - t)
                .map(|i| (x[i] - mean) * (x[i + t] - mean))
                .sum::<f64>()
                / n as f64;
            let err = if scale > 0.0 {
                (fft[t] - direct).abs() / scale
            } else {
                fft[t].abs()
            };
            worst = worst.max(err);
            assert!(err <= 1e-13, "n = {n}, lag {t}: {} vs {direct}", fft[t]);
        }
    }
    println!("worst difference from the direct sum: {worst:.2e} of γ(0)");
    assert!(autocovariance(&[]).is_empty());
    assert!(autocovariance(&[2.0; 10]).iter().all(|v| *v == 0.0));
}
