//! An affine-invariant ensemble MCMC sampler that knows nothing of beads.
//!
//! [`EnsembleSampler`] draws from any [`LogDensity`] with the stretch move of J. Goodman &
//! J. Weare, "Ensemble samplers with affine invariance", Comm. App. Math. Comp. Sci. 5, 2010,
//! in the parallel split-half form of emcee (D. Foreman-Mackey, D. W. Hogg, D. Lang &
//! J. Goodman, "emcee: the MCMC hammer", PASP 125, 2013): the walkers are split into two
//! halves, and each half moves in parallel (rayon) using the other half as its complementary
//! ensemble.
//!
//! Each walker's update is, with probability [`McmcOptions::de_fraction`], a
//! differential-evolution move (C. J. F. ter Braak, "A Markov chain Monte Carlo version of the
//! genetic algorithm Differential Evolution", Stat. Comput. 16, 2006; emcee's `DEMove`), and
//! otherwise a stretch move. Both are affine invariant and leave the target invariant given
//! the complementary half, so their mixture does too.
//!
//! Reproducibility: every random number of walker `w` at step `s` comes from a ChaCha8 stream
//! seeded by the run's seed, with stream number `w` and word position fixed by `s`; no
//! generator is shared between parallel tasks, so a run is bit-identical for a given seed
//! whatever the number of rayon threads.
//!
//! [`EnsembleSampler::run`] steps until every parameter's rank-normalised split-R̂ and bulk and
//! tail effective sample sizes (A. Vehtari, A. Gelman, D. Simpson, B. Carpenter &
//! P.-C. Bürkner, Bayesian Analysis 16, 2021), computed after discarding a burn-in of a few
//! integrated autocorrelation times, meet the thresholds of [`McmcOptions`], or until
//! `max_steps`, or until a caller raises the stop flag. The chains, and the diagnostics on
//! them, are of what the density records of each point ([`LogDensity::observe`]: the point
//! itself unless the density is over transformed coordinates). The diagnostics are in
//! `diagnostics` and work on any chains.

pub(crate) mod diagnostics;
pub(crate) mod sensitivity;

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;
use thiserror::Error;

pub use diagnostics::ParameterDiagnostics;
pub(crate) use diagnostics::{integrated_times, summarise};

/// An unnormalised log probability density on ℝⁿ.
///
/// `log_density` returns −∞ outside the support. A NaN return is treated as −∞ (the point is
/// rejected) and counted in [`McmcResult::nan_evaluations`]. It is called from several threads
/// at once, hence `Sync`.
pub trait LogDensity: Sync {
    /// Dimension n of the parameter space.
    fn dim(&self) -> usize;
    /// log p(x) up to an additive constant, or −∞ where p(x) = 0.
    fn log_density(&self, x: &[f64]) -> f64;
    /// What the sampler records of a point x, as many numbers as `dim`: x itself by default.
    /// A density over transformed coordinates returns the quantities of interest (the
    /// parameters the coordinates stand for), so that the chains, and the R̂, ESS and τ that
    /// decide convergence and burn-in, are theirs.
    fn observe(&self, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }
}

/// Options of an [`EnsembleSampler`]. [`Default`] gives the documented defaults.
#[derive(Debug, Clone)]
pub struct McmcOptions {
    /// Number of walkers; `None` for max(2·dim + 2, 32). Must be even, greater than dim and at
    /// least 4 (the ensemble must span the space; Goodman & Weare 2010 advise ≥ 2·dim).
    pub walkers: Option<usize>,
    /// Seed of every random stream.
    pub seed: u64,
    /// Keep one step in `thin` (default 1).
    pub thin: usize,
    /// Maximum number of steps (each step moves every walker once; default 100 000).
    pub max_steps: usize,
    /// Minimum bulk and tail effective sample size of every parameter (default 1000).
    pub min_ess: f64,
    /// Maximum rank-normalised split-R̂ of every parameter (default 1.01).
    pub rhat_max: f64,
    /// Steps between convergence checks (default 500); once the run is ten times longer, a
    /// check comes every tenth of the run so far, so that the checks (each over the whole
    /// stored run) cost a fixed multiple of the run, not its square.
    pub check_every: usize,
    /// Burn-in discarded, as a multiple of the largest integrated autocorrelation time
    /// estimated on the run so far (default 5).
    pub burn_in_tau: f64,
    /// The autocorrelation time is trusted only when the kept chain is at least this many
    /// times longer (default 50, emcee's rule of thumb); convergence also requires this.
    pub tau_reliability: f64,
    /// Stretch-move scale a > 1: z has density ∝ 1/√z on [1/a, a] (default 2, as emcee).
    pub stretch: f64,
    /// Probability that a walker's update is a differential-evolution move instead of a
    /// stretch move (default 0.8, emcee's recommended mix; 0 for stretch moves only). On
    /// Gaussian targets of dimension 1, 2 and 5 (`cargo run --release --example mcmc_moves`)
    /// it cut the log-density evaluations per effective sample from 29, 34 and 68 (stretch
    /// only) to 5.5, 9.2 and 21.
    pub de_fraction: f64,
    /// Standard deviation per parameter of the initial Gaussian ball around the start point;
    /// `None` for 1e-4·max(|xᵢ|, 1).
    pub init_scale: Option<Vec<f64>>,
    /// Redraws allowed per walker whose initial point has log density −∞ (default 1000).
    pub max_init_tries: usize,
    /// Probability of the central interval in the diagnostics (default 0.95).
    pub level: f64,
    /// Checked before every step; when set, the run stops cleanly (e.g. from a Ctrl-C handler).
    pub stop: Option<Arc<AtomicBool>>,
}

impl Default for McmcOptions {
    fn default() -> Self {
        McmcOptions {
            walkers: None,
            seed: 0,
            thin: 1,
            max_steps: 100_000,
            min_ess: 1000.0,
            rhat_max: 1.01,
            check_every: 500,
            burn_in_tau: 5.0,
            tau_reliability: 50.0,
            stretch: 2.0,
            de_fraction: 0.8,
            init_scale: None,
            max_init_tries: 1000,
            level: 0.95,
            stop: None,
        }
    }
}

/// Most walkers a run may have: each step keeps one draw per walker in memory.
pub(crate) const MAX_WALKERS: usize = 10_000;

/// A user-given sampler setting out of its range: the option (`walkers`, `min_ess`,
/// `max_steps` or `thin`), the value given, and what it must be.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{option} = {value}: {expected}")]
pub struct OptionError {
    /// The option's name.
    pub option: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What the option must be.
    pub expected: String,
}

impl McmcOptions {
    /// Most walkers a run may have: each step keeps one draw per walker in memory.
    pub const MAX_WALKERS: usize = MAX_WALKERS;

    /// Checks the settings a user chooses (walkers, min_ess, max_steps, thin) against their
    /// ranges: walkers even, at least 4 and at most `MAX_WALKERS`; min_ess finite and ≥ 0;
    /// max_steps and thin ≥ 1. The command line and the Python binding refuse the same values.
    pub fn check(&self) -> Result<(), OptionError> {
        let bad = |option, value: String, expected: String| {
            Err(OptionError {
                option,
                value,
                expected,
            })
        };
        if let Some(w) = self.walkers {
            if w < 4 || w % 2 == 1 || w > MAX_WALKERS {
                return bad(
                    "walkers",
                    w.to_string(),
                    format!(
                        "must be even, at least 4 (and more than the parameters) and at most \
                         {MAX_WALKERS}"
                    ),
                );
            }
        }
        if !(self.min_ess >= 0.0 && self.min_ess.is_finite()) {
            return bad(
                "min_ess",
                self.min_ess.to_string(),
                "must be a finite number >= 0".into(),
            );
        }
        if self.max_steps == 0 {
            return bad("max_steps", "0".into(), "must be >= 1".into());
        }
        if self.thin == 0 {
            return bad("thin", "0".into(), "must be >= 1".into());
        }
        Ok(())
    }
}

/// Errors of the ensemble sampler (all detected before sampling starts).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum McmcError {
    /// The density has dimension 0.
    #[error("the density has dimension 0")]
    ZeroDimension,
    /// The number of walkers is odd (split-half updates need two equal halves).
    #[error("{0} walkers: the number of walkers must be even")]
    OddWalkers(usize),
    /// Too few walkers for the dimension.
    #[error(
        "{walkers} walkers for dimension {dim}: need more walkers than dimensions, and at least 4"
    )]
    TooFewWalkers {
        /// Walkers asked for.
        walkers: usize,
        /// Dimension of the density.
        dim: usize,
    },
    /// An option is out of range.
    #[error("option {name} = {value}: {reason}")]
    BadOption {
        /// Option name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
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
    /// A start point, initial walker or scale is not finite.
    #[error("{what} is not finite")]
    NotFinite {
        /// Which value.
        what: &'static str,
    },
    /// A walker could not be placed where the log density is finite.
    #[error("walker {walker}: no finite log density after {tries} draws around the start point")]
    InitFailed {
        /// The walker.
        walker: usize,
        /// Draws tried.
        tries: usize,
    },
    /// An initial walker given to [`EnsembleSampler::run_from`] has log density −∞ or NaN.
    #[error("initial walker {walker} has log density −∞ or NaN")]
    InfeasibleWalker {
        /// The walker.
        walker: usize,
    },
}

/// Why a run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// Every parameter met the R̂ and ESS thresholds.
    Converged,
    /// `max_steps` reached first.
    MaxSteps,
    /// The stop flag was raised.
    Interrupted,
}

/// The outcome of [`EnsembleSampler::run`].
#[derive(Debug, Clone)]
pub struct McmcResult {
    /// Kept draws after burn-in and thinning, as recorded by [`LogDensity::observe`], indexed
    /// `[walker][kept step][parameter]`.
    pub chains: Vec<Vec<Vec<f64>>>,
    /// Log densities of the kept draws, `[walker][kept step]`.
    pub log_densities: Vec<Vec<f64>>,
    /// Fraction of accepted proposals per walker over the whole run (burn-in included).
    pub acceptance: Vec<f64>,
    /// Fraction of accepted proposals over all walkers.
    pub acceptance_overall: f64,
    /// Steps discarded as burn-in (a multiple of `thin`).
    pub burn_in: usize,
    /// Steps run.
    pub steps: usize,
    /// Whether every parameter met the R̂ and ESS thresholds (with a trusted τ).
    pub converged: bool,
    /// Why the run stopped.
    pub reason: StopReason,
    /// When not converged, the index of the parameter furthest from the thresholds (largest
    /// max(R̂/R̂ₘₐₓ, ESSₘᵢₙ/min(bulk ESS, tail ESS))), or with the longest τ if only the
    /// τ-reliability rule failed; `None` when converged or when nothing was kept.
    pub failing_parameter: Option<usize>,
    /// Diagnostics per parameter on the kept draws; τ in units of kept (thinned) steps.
    pub diagnostics: Vec<ParameterDiagnostics>,
    /// Largest integrated autocorrelation time over the whole stored run, in steps (not
    /// thinned), used for the burn-in.
    pub tau_max: f64,
    /// Number of log-density evaluations that returned NaN (treated as −∞).
    pub nan_evaluations: usize,
}

/// The Goodman & Weare (2010) affine-invariant ensemble sampler with stretch moves.
pub struct EnsembleSampler<'a, D: LogDensity + ?Sized> {
    target: &'a D,
    options: McmcOptions,
    walkers: usize,
}

/// Words of the ChaCha stream reserved for one walker at one step (a step uses 3 or 4 u64 =
/// 6–8 words, rarely more when an index draw is rejected; overlap would be harmless anyway,
/// only deterministic).
const WORDS_PER_STEP: u128 = 64;
/// Stream offset of the initial-ball draws, kept apart from the sampling streams.
const INIT_STREAM: u64 = 1 << 63;

impl<'a, D: LogDensity + ?Sized> EnsembleSampler<'a, D> {
    /// A sampler of `target` with `options`, validated.
    pub fn new(target: &'a D, options: McmcOptions) -> Result<Self, McmcError> {
        let dim = target.dim();
        if dim == 0 {
            return Err(McmcError::ZeroDimension);
        }
        let walkers = options.walkers.unwrap_or((2 * dim + 2).max(32));
        if !walkers.is_multiple_of(2) {
            return Err(McmcError::OddWalkers(walkers));
        }
        if walkers <= dim || walkers < 4 {
            return Err(McmcError::TooFewWalkers { walkers, dim });
        }
        let bad = |name, value: f64, reason| {
            Err(McmcError::BadOption {
                name,
                value,
                reason,
            })
        };
        if options.thin == 0 {
            return bad("thin", 0.0, "must be ≥ 1");
        }
        if options.check_every == 0 {
            return bad("check_every", 0.0, "must be ≥ 1");
        }
        if !(options.min_ess >= 0.0) {
            return bad("min_ess", options.min_ess, "must be ≥ 0");
        }
        if !(options.rhat_max >= 1.0) {
            return bad("rhat_max", options.rhat_max, "must be ≥ 1");
        }
        if !(options.burn_in_tau >= 0.0 && options.burn_in_tau.is_finite()) {
            return bad("burn_in_tau", options.burn_in_tau, "must be finite and ≥ 0");
        }
        if !(options.tau_reliability >= 0.0 && options.tau_reliability.is_finite()) {
            return bad(
                "tau_reliability",
                options.tau_reliability,
                "must be finite and ≥ 0",
            );
        }
        if !(options.stretch > 1.0 && options.stretch.is_finite()) {
            return bad("stretch", options.stretch, "must be finite and > 1");
        }
        if !(options.de_fraction >= 0.0 && options.de_fraction <= 1.0) {
            return bad("de_fraction", options.de_fraction, "must be in [0, 1]");
        }
        if options.de_fraction > 0.0 && walkers / 2 < 2 {
            return bad(
                "de_fraction",
                options.de_fraction,
                "the differential-evolution move needs at least 4 walkers",
            );
        }
        if !(options.level > 0.0 && options.level < 1.0) {
            return bad("level", options.level, "must be in (0, 1)");
        }
        if let Some(scale) = &options.init_scale {
            if scale.len() != dim {
                return Err(McmcError::Length {
                    what: "init_scale",
                    got: scale.len(),
                    expected: dim,
                });
            }
            if scale.iter().any(|s| !(s.is_finite() && *s >= 0.0)) {
                return Err(McmcError::NotFinite {
                    what: "init_scale (must be finite and ≥ 0)",
                });
            }
        }
        Ok(EnsembleSampler {
            target,
            options,
            walkers,
        })
    }

    /// Number of walkers.
    pub fn walkers(&self) -> usize {
        self.walkers
    }

    /// The options in use.
    pub fn options(&self) -> &McmcOptions {
        &self.options
    }

    fn eval(&self, x: &[f64], nans: &AtomicUsize) -> f64 {
        let v = self.target.log_density(x);
        if v.is_nan() {
            nans.fetch_add(1, Ordering::Relaxed);
            f64::NEG_INFINITY
        } else {
            v
        }
    }

    /// The initial ensemble: walkers drawn from a Gaussian ball around `start` (standard
    /// deviations `init_scale`, or 1e-4·max(|xᵢ|, 1)); a walker with log density −∞ is redrawn
    /// up to `max_init_tries` times. Deterministic for a given seed.
    pub fn initial_ensemble(&self, start: &[f64]) -> Result<Vec<Vec<f64>>, McmcError> {
        let dim = self.target.dim();
        if start.len() != dim {
            return Err(McmcError::Length {
                what: "start",
                got: start.len(),
                expected: dim,
            });
        }
        if start.iter().any(|v| !v.is_finite()) {
            return Err(McmcError::NotFinite { what: "start" });
        }
        let scale: Vec<f64> = match &self.options.init_scale {
            Some(s) => s.clone(),
            None => start.iter().map(|x| 1e-4 * x.abs().max(1.0)).collect(),
        };
        let nans = AtomicUsize::new(0);
        let tries = self.options.max_init_tries.max(1);
        (0..self.walkers)
            .into_par_iter()
            .map(|w| {
                let mut rng = ChaCha8Rng::seed_from_u64(self.options.seed);
                rng.set_stream(INIT_STREAM | w as u64);
                for _ in 0..tries {
                    let x: Vec<f64> = start
                        .iter()
                        .zip(&scale)
                        .map(|(x, s)| x + s * rng.sample::<f64, _>(StandardNormal))
                        .collect();
                    if self.eval(&x, &nans) > f64::NEG_INFINITY {
                        return Ok(x);
                    }
                }
                Err(McmcError::InitFailed { walker: w, tries })
            })
            .collect()
    }

    /// Runs from a Gaussian ball around `start` (see [`Self::initial_ensemble`]).
    pub fn run(&self, start: &[f64]) -> Result<McmcResult, McmcError> {
        self.run_with_progress(start, |_, _| {})
    }

    /// As [`Self::run`], calling `progress(step, max_steps)` after every step.
    pub fn run_with_progress(
        &self,
        start: &[f64],
        progress: impl FnMut(usize, usize),
    ) -> Result<McmcResult, McmcError> {
        let ensemble = self.initial_ensemble(start)?;
        self.run_from(ensemble, progress)
    }

    /// Runs from a given initial ensemble (one point per walker, each with a finite log
    /// density), calling `progress(step, max_steps)` after every step.
    pub fn run_from(
        &self,
        ensemble: Vec<Vec<f64>>,
        mut progress: impl FnMut(usize, usize),
    ) -> Result<McmcResult, McmcError> {
        let dim = self.target.dim();
        let nw = self.walkers;
        self.check_ensemble(&ensemble)?;
        let nans = AtomicUsize::new(0);
        let mut pos = ensemble;
        let mut lp: Vec<f64> = pos.par_iter().map(|x| self.eval(x, &nans)).collect();
        if let Some(w) = lp.iter().position(|v| *v == f64::NEG_INFINITY) {
            return Err(McmcError::InfeasibleWalker { walker: w });
        }
        let o = &self.options;
        let half = nw / 2;
        let gamma0 = 2.38 / (2.0 * dim as f64).sqrt();
        let mut accepted = vec![0usize; nw];
        let mut chains: Vec<Vec<Vec<f64>>> = vec![Vec::new(); nw];
        let mut lps: Vec<Vec<f64>> = vec![Vec::new(); nw];
        let mut steps = 0;
        let mut reason = StopReason::MaxSteps;
        let mut last: Option<Assessment> = None;
        let mut next_check = o.check_every;
        let stopped = || o.stop.as_ref().is_some_and(|s| s.load(Ordering::Relaxed));
        'steps: while steps < o.max_steps {
            if stopped() {
                reason = StopReason::Interrupted;
                break;
            }
            let step = steps as u128;
            let accepted_before = accepted.clone();
            for h in 0..2 {
                let (moving, other) = halves(h, half, nw);
                let complement = &pos[other.clone()];
                let updates: Vec<Option<(Vec<f64>, f64)>> = moving
                    .clone()
                    .into_par_iter()
                    .map(|w| {
                        let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
                        rng.set_stream(w as u64);
                        rng.set_word_pos(step * WORDS_PER_STEP);
                        let (y, log_jacobian) = self.propose(&mut rng, &pos[w], complement, gamma0);
                        let lpy = self.eval(&y, &nans);
                        if lpy == f64::NEG_INFINITY {
                            return None;
                        }
                        let log_ratio = log_jacobian + lpy - lp[w];
                        let r: f64 = rng.random();
                        (r.ln() < log_ratio).then_some((y, lpy))
                    })
                    .collect();
                // A stop during the half-step may have cut evaluations short (a target may
                // refuse to evaluate once it sees the flag): the step is left out of the
                // chains, which hold whole steps only.
                if stopped() {
                    accepted = accepted_before;
                    reason = StopReason::Interrupted;
                    break 'steps;
                }
                for (w, up) in moving.zip(updates) {
                    if let Some((y, lpy)) = up {
                        pos[w] = y;
                        lp[w] = lpy;
                        accepted[w] += 1;
                    }
                }
            }
            steps += 1;
            if steps.is_multiple_of(o.thin) {
                for w in 0..nw {
                    chains[w].push(self.target.observe(&pos[w]));
                    lps[w].push(lp[w]);
                }
            }
            progress(steps, o.max_steps);
            if steps >= next_check {
                next_check = steps + o.check_every.max(steps / 10);
                let assessment = self.assess(&chains, false);
                let done = assessment.converged;
                last = Some(assessment);
                if done {
                    reason = StopReason::Converged;
                    break;
                }
            }
        }
        // Reassess unless the last check saw exactly the stored draws.
        let stored = chains.first().map_or(0, Vec::len);
        let assessment = match last {
            Some(a) if a.stored == stored && a.complete => a,
            _ => self.assess(&chains, true),
        };
        let burn = assessment.burn;
        let kept_chains = after_burn_in(chains, burn);
        let kept_lps = after_burn_in(lps, burn);
        let diagnostics = if stored > burn {
            summarise(&kept_chains, o.level)
        } else {
            Vec::new()
        };
        let acceptance = acceptance_rates(&accepted, steps);
        let acceptance_overall = acceptance.iter().sum::<f64>() / nw as f64;
        Ok(McmcResult {
            chains: kept_chains,
            log_densities: kept_lps,
            acceptance,
            acceptance_overall,
            burn_in: burn * o.thin,
            steps,
            converged: assessment.converged,
            reason,
            failing_parameter: assessment.failing,
            diagnostics,
            tau_max: assessment.tau_max * o.thin as f64,
            nan_evaluations: nans.load(Ordering::Relaxed),
        })
    }

    /// Checks an initial ensemble: one point per walker, each of the target's dimension and
    /// finite.
    fn check_ensemble(&self, ensemble: &[Vec<f64>]) -> Result<(), McmcError> {
        let dim = self.target.dim();
        let nw = self.walkers;
        if ensemble.len() != nw {
            return Err(McmcError::Length {
                what: "initial ensemble",
                got: ensemble.len(),
                expected: nw,
            });
        }
        for x in ensemble {
            if x.len() != dim {
                return Err(McmcError::Length {
                    what: "initial walker",
                    got: x.len(),
                    expected: dim,
                });
            }
            if x.iter().any(|v| !v.is_finite()) {
                return Err(McmcError::NotFinite {
                    what: "initial walker",
                });
            }
        }
        Ok(())
    }

    /// The proposal for walker position `x` from the walkers of the other half,
    /// `complement`, with the draws of `rng`: a differential-evolution move with probability
    /// `de_fraction` (scale `gamma0`), else a stretch move; the proposed point and the log
    /// of the move's Jacobian.
    #[inline]
    fn propose(
        &self,
        rng: &mut ChaCha8Rng,
        x: &[f64],
        complement: &[Vec<f64>],
        gamma0: f64,
    ) -> (Vec<f64>, f64) {
        let o = &self.options;
        // Every walker has the target's dimension (see `check_ensemble`).
        let dim = x.len();
        let a = o.stretch;
        let de = o.de_fraction > 0.0 && rng.random::<f64>() < o.de_fraction;
        if de {
            // Differential evolution (ter Braak 2006; emcee's DEMove):
            // y = x + γ (c_a − c_b), a ≠ b drawn from the complement,
            // γ = γ0 (1 + u/10), u uniform on [−1, 1], γ0 = 2.38/√(2 dim).
            // Symmetric (swap a and b), so no Jacobian term.
            let nc = complement.len();
            let ia = rng.random_range(0..nc);
            let ib = (ia + 1 + rng.random_range(0..nc - 1)) % nc;
            let g = gamma0 * (1.0 + 0.1 * (2.0 * rng.random::<f64>() - 1.0));
            let (ca, cb) = (&complement[ia], &complement[ib]);
            let y: Vec<f64> = x
                .iter()
                .zip(ca.iter().zip(cb))
                .map(|(xi, (p, q))| xi + g * (p - q))
                .collect();
            (y, 0.0)
        } else {
            let c = &complement[rng.random_range(0..complement.len())];
            let u: f64 = rng.random();
            // z ~ g(z) ∝ 1/√z on [1/a, a] by inversion (Goodman & Weare 2010, eq. 9).
            let z = ((a - 1.0) * u + 1.0).powi(2) / a;
            let y: Vec<f64> = x.iter().zip(c).map(|(xi, ci)| ci + z * (xi - ci)).collect();
            (y, (dim as f64 - 1.0) * z.ln())
        }
    }

    /// Burn-in and convergence of the stored (thinned) chains; when `complete`, the failing
    /// parameter is the one furthest from the thresholds even when τ is not yet reliable.
    fn assess(&self, chains: &[Vec<Vec<f64>>], complete: bool) -> Assessment {
        let o = &self.options;
        let n = chains.first().map_or(0, Vec::len);
        let mut out = Assessment {
            stored: n,
            burn: n / 2,
            tau_max: f64::NAN,
            converged: false,
            failing: None,
            complete: true,
        };
        if n < 8 {
            out.failing = Some(0).filter(|_| n > 0);
            return out;
        }
        let taus = integrated_times(chains, diagnostics::SOKAL_C);
        let (k_tau, tau_max) =
            taus.iter()
                .copied()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |(kb, tb), (k, t)| {
                    let t = if t.is_nan() { f64::INFINITY } else { t };
                    if t > tb {
                        (k, t)
                    } else {
                        (kb, tb)
                    }
                });
        out.tau_max = tau_max;
        let burn = (o.burn_in_tau * tau_max).ceil();
        let post = n as f64 - burn;
        if !(burn.is_finite() && post >= 8.0) {
            // τ unusable: report the slowest parameter, keep the second half of the run.
            out.failing = Some(k_tau);
            return out;
        }
        let reliable = post >= o.tau_reliability * tau_max;
        out.burn = burn as usize;
        // Without a reliable τ the run cannot have converged: a check during the run stops
        // here, the final assessment goes on to name the parameter furthest from the
        // thresholds.
        if !reliable && !complete {
            out.failing = Some(k_tau);
            out.complete = false;
            return out;
        }
        let dim = self.target.dim();
        let scores: Vec<f64> = (0..dim)
            .into_par_iter()
            .map(|k| {
                let p: Vec<Vec<f64>> = chains
                    .iter()
                    .map(|c| c[out.burn..].iter().map(|x| x[k]).collect())
                    .collect();
                let c = diagnostics::convergence(&p);
                let ess = c.ess_bulk.min(c.ess_tail);
                let score = (c.rhat / o.rhat_max).max(o.min_ess / ess);
                if score.is_nan() {
                    f64::INFINITY
                } else {
                    score
                }
            })
            .collect();
        let (k_worst, worst) =
            scores
                .iter()
                .copied()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |(kb, sb), (k, s)| {
                    if s > sb {
                        (k, s)
                    } else {
                        (kb, sb)
                    }
                });
        if worst > 1.0 {
            out.failing = Some(k_worst);
        } else if !reliable {
            out.failing = Some(k_tau);
        } else {
            out.converged = true;
        }
        out
    }
}

/// Burn-in and convergence of the chains stored so far (all counts in stored samples).
struct Assessment {
    stored: usize,
    burn: usize,
    tau_max: f64,
    converged: bool,
    failing: Option<usize>,
    /// Whether `failing` is final (false for a check that stopped at an unreliable τ).
    complete: bool,
}
/// The walkers that move in half-step `h` (0: the first half, 1: the second) and those they
/// move against, of `nw` walkers split at `half`.
fn halves(h: usize, half: usize, nw: usize) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
    if h == 0 {
        (0..half, half..nw)
    } else {
        (half..nw, 0..half)
    }
}

/// Each walker's stored draws after the first `burn`.
fn after_burn_in<T>(chains: Vec<Vec<T>>, burn: usize) -> Vec<Vec<T>> {
    chains
        .into_iter()
        .map(|mut c| c.split_off(burn.min(c.len())))
        .collect()
}

/// Each walker's acceptance rate over `steps` steps (0 before any step).
fn acceptance_rates(accepted: &[usize], steps: usize) -> Vec<f64> {
    accepted
        .iter()
        .map(|&n| {
            if steps > 0 {
                n as f64 / steps as f64
            } else {
                0.0
            }
        })
        .collect()
}
