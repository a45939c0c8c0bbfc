//! Convergence diagnostics and summaries for any set of Markov chains.
//!
//! Layout: the draws of one scalar quantity are given as `&[Vec<f64>]`, one vector per chain
//! (for an ensemble sampler, one chain per walker), all of the same length. The draws of a
//! vector parameter are given as `&[Vec<Vec<f64>>]`, indexed `[chain][step][parameter]`;
//! `parameter_chains` extracts one parameter from that layout.
//!
//! * [`integrated_time`] — the integrated autocorrelation time with Sokal's automatic window,
//!   as in emcee's `integrated_time` (D. Foreman-Mackey, D. W. Hogg, D. Lang & J. Goodman,
//!   "emcee: the MCMC hammer", PASP 125, 2013; A. Sokal, "Monte Carlo methods in statistical
//!   mechanics: foundations and new algorithms", 1997);
//! * [`rhat`], [`ess_bulk`], [`ess_tail`], [`ess_mean`] — rank-normalised split-R̂ and the
//!   effective sample sizes of A. Vehtari, A. Gelman, D. Simpson, B. Carpenter & P.-C. Bürkner,
//!   "Rank-normalization, folding, and localization: an improved R̂ for assessing convergence
//!   of MCMC", Bayesian Analysis 16, 2021, with Geyer's initial monotone sequence (C. J. Geyer,
//!   "Practical Markov chain Monte Carlo", Statistical Science 7, 1992), as in Stan and the R
//!   package `posterior`; `convergence` computes the three together, sharing their sorts;
//! * `summarise` — all of the above plus mean, standard deviation and quantiles of the pooled
//!   draws, per parameter.

use rayon::prelude::*;
use realfft::num_complex::Complex;
use realfft::RealFftPlanner;
use statrs::distribution::{ContinuousCDF, Normal};

/// Sokal's window constant used by emcee: the window is the smallest M with M ≥ c·τ(M).
pub(crate) const SOKAL_C: f64 = 5.0;

/// Extracts parameter `k` from chains laid out `[chain][step][parameter]`.
pub(crate) fn parameter_chains(chains: &[Vec<Vec<f64>>], k: usize) -> Vec<Vec<f64>> {
    chains
        .iter()
        .map(|c| c.iter().map(|x| x[k]).collect())
        .collect()
}

thread_local! {
    /// FFT plans of `realfft`, kept per thread: the convergence checks transform chains of the
    /// same few lengths again and again.
    static PLANNER: std::cell::RefCell<RealFftPlanner<f64>> =
        std::cell::RefCell::new(RealFftPlanner::new());
}

/// Biased autocovariance γ̂(t) = (1/n) Σ_{i<n−t} (xᵢ − x̄)(x_{i+t} − x̄), t = 0..n, by a real FFT
/// (`realfft`) with zero padding to avoid circular wrap-around: O(n log n), where the direct sum
/// is O(n²) (`cargo bench --features bench-internals --bench mcmc -- autocovariance` times the three ways it has been done:
/// at n = 10⁴, 0.42 ms here, 3.17 ms by a hand-written radix-2 complex FFT, 61 ms by the direct
/// sum; criterion medians, 2-core AMD EPYC, 2026-11-23).
pub fn autocovariance(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let m = (2 * n).next_power_of_two();
    let (r2c, c2r) = PLANNER.with(|p| {
        let mut p = p.borrow_mut();
        (p.plan_fft_forward(m), p.plan_fft_inverse(m))
    });
    let mut input = vec![0.0; m];
    for (r, &v) in input.iter_mut().zip(x) {
        *r = v - mean;
    }
    let mut spectrum = r2c.make_output_vec();
    let mut out = c2r.make_output_vec();
    // The buffers come from the plans, so neither transform can fail; if one did, NaN makes
    // every diagnostic built on it say "not converged".
    if r2c.process(&mut input, &mut spectrum).is_err() {
        return vec![f64::NAN; n];
    }
    for z in spectrum.iter_mut() {
        *z = Complex::new(z.norm_sqr(), 0.0);
    }
    if c2r.process(&mut spectrum, &mut out).is_err() {
        return vec![f64::NAN; n];
    }
    out.truncate(n);
    let scale = 1.0 / (m as f64 * n as f64);
    out.iter_mut().for_each(|v| *v *= scale);
    out
}

/// Normalised autocorrelation function ρ̂(t) = γ̂(t)/γ̂(0) (all zeros for a constant series).
pub(crate) fn autocorrelation(x: &[f64]) -> Vec<f64> {
    let mut acov = autocovariance(x);
    let v0 = acov.first().copied().unwrap_or(0.0);
    if v0 > 0.0 {
        acov.iter_mut().for_each(|v| *v /= v0);
    } else {
        acov.iter_mut().for_each(|v| *v = 0.0);
    }
    acov
}

/// Integrated autocorrelation time τ of one scalar quantity, in steps, as emcee's
/// `integrated_time` (Foreman-Mackey et al. 2013): the autocorrelation functions of the chains
/// are averaged, τ(M) = 1 + 2 Σ_{t=1}^{M} ρ̂(t), and the window M is the smallest with
/// M ≥ c·τ(M) (Sokal 1997; `c` = `SOKAL_C` by default), or the last lag if none is.
///
/// The estimate is reliable only for chains longer than about 50 τ (emcee's rule of thumb).
/// Returns NaN for empty chains, and 1 for constant ones.
pub fn integrated_time(chains: &[Vec<f64>], c: f64) -> f64 {
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    if n == 0 {
        return f64::NAN;
    }
    let mut f = vec![0.0; n];
    for chain in chains {
        for (a, b) in f.iter_mut().zip(autocorrelation(&chain[..n])) {
            *a += b;
        }
    }
    let w = chains.len() as f64;
    f.iter_mut().for_each(|v| *v /= w);
    if f[0] == 0.0 {
        return 1.0;
    }
    // τ(M) = 2 Σ_{t=0}^{M} ρ(t) − 1 (emcee's cumulative form).
    let mut sum = 0.0;
    let mut tau = 1.0;
    for (m, &rho) in f.iter().enumerate() {
        sum += rho;
        tau = 2.0 * sum - 1.0;
        if (m as f64) >= c * tau {
            return tau;
        }
    }
    tau
}

/// Integrated autocorrelation times of every parameter of chains laid out
/// `[chain][step][parameter]` (see [`integrated_time`]).
pub(crate) fn integrated_times(chains: &[Vec<Vec<f64>>], c: f64) -> Vec<f64> {
    let dim = chains
        .first()
        .and_then(|c| c.first())
        .map_or(0, |x| x.len());
    (0..dim)
        .into_par_iter()
        .map(|k| integrated_time(&parameter_chains(chains, k), c))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Vehtari et al. (2021).
// ---------------------------------------------------------------------------------------------

/// Splits each chain in two halves (dropping the middle draw of odd-length chains), giving
/// 2·M chains of length ⌊N/2⌋.
pub(crate) fn split_chains(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    let half = n / 2;
    let mut out = Vec::with_capacity(2 * chains.len());
    for c in chains {
        out.push(c[..half].to_vec());
        out.push(c[n - half..n].to_vec());
    }
    out
}

/// Rank-normalises draws pooled over all chains: each draw is replaced by
/// Φ⁻¹((r − 3/8)/(S + 1/4)), r its rank among the S pooled draws (ties get their average
/// rank), Φ the standard normal CDF (Vehtari et al. 2021, eq. 14).
pub(crate) fn rank_normalise(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    // Values with their pooled index, sorted by value (ties in any order: they share their
    // average rank).
    let mut order: Vec<(f64, usize)> = chains.iter().flatten().copied().zip(0..).collect();
    let s = order.len();
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let mut ranks = vec![0.0; s];
    let mut i = 0;
    while i < s {
        let mut j = i;
        while j + 1 < s && order[j + 1].0 == order[i].0 {
            j += 1;
        }
        // 1-based ranks i+1..=j+1 share their average.
        let r = 0.5 * ((i + 1) + (j + 1)) as f64;
        for &(_, o) in &order[i..=j] {
            ranks[o] = r;
        }
        i = j + 1;
    }
    let normal = Normal::standard();
    let denom = s as f64 + 0.25;
    // Each chain's draws start at its offset in the pooled order.
    let starts: Vec<usize> = chains
        .iter()
        .scan(0, |next, c| {
            let at = *next;
            *next += c.len();
            Some(at)
        })
        .collect();
    chains
        .par_iter()
        .zip(starts)
        .map(|(c, at)| {
            ranks[at..at + c.len()]
                .iter()
                .map(|r| normal.inverse_cdf((r - 0.375) / denom))
                .collect()
        })
        .collect()
}

/// Basic R̂ of chains taken as they are (no splitting, no ranks): √(V̂⁺/W) with
/// V̂⁺ = (N−1)/N · W + B/N (Gelman et al., Bayesian Data Analysis, 3rd ed., 2013, §11.4).
fn rhat_basic(chains: &[Vec<f64>]) -> f64 {
    let m = chains.len();
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    if m < 2 || n < 2 {
        return f64::NAN;
    }
    let nf = n as f64;
    let means: Vec<f64> = chains
        .iter()
        .map(|c| c[..n].iter().sum::<f64>() / nf)
        .collect();
    let vars: Vec<f64> = chains
        .iter()
        .zip(&means)
        .map(|(c, mu)| c[..n].iter().map(|v| (v - mu).powi(2)).sum::<f64>() / (nf - 1.0))
        .collect();
    let grand = means.iter().sum::<f64>() / m as f64;
    let b = nf * means.iter().map(|mu| (mu - grand).powi(2)).sum::<f64>() / (m as f64 - 1.0);
    let w = vars.iter().sum::<f64>() / m as f64;
    if w <= 0.0 {
        return if b <= 0.0 { 1.0 } else { f64::INFINITY };
    }
    (((nf - 1.0) / nf * w + b / nf) / w).sqrt()
}

/// Rank-normalised split-R̂ (Vehtari et al. 2021, §4.2): the maximum of the bulk R̂ (split
/// chains, rank-normalised) and the tail R̂ (the same on the folded draws |θ − median θ|).
/// Values above ~1.01 flag chains that have not mixed. NaN for fewer than 4 draws per chain.
#[cfg(test)]
pub fn rhat(chains: &[Vec<f64>]) -> f64 {
    let split = split_chains(chains);
    if split.first().map_or(0, Vec::len) < 2 {
        return f64::NAN;
    }
    let mut sorted: Vec<f64> = chains.iter().flatten().copied().collect();
    sorted.sort_by(f64::total_cmp);
    rhat_ranked(
        &split,
        &rank_normalise(&split),
        quantile_sorted(&sorted, 0.5),
    )
}

/// [`rhat`] from the split chains, their rank normalisation and the median of the pooled
/// draws.
#[cfg(test)]
fn rhat_ranked(split: &[Vec<f64>], ranked: &[Vec<f64>], med: f64) -> f64 {
    rhat_basic(ranked).max(rhat_tail(split, med))
}

/// The tail R̂: [`rhat_basic`] of the rank-normalised folded draws |θ − `med`|.
fn rhat_tail(split: &[Vec<f64>], med: f64) -> f64 {
    let folded: Vec<Vec<f64>> = split
        .iter()
        .map(|c| c.iter().map(|v| (v - med).abs()).collect())
        .collect();
    rhat_basic(&rank_normalise(&folded))
}

/// [`rhat`], [`ess_bulk`] and [`ess_tail`] of one scalar quantity, computed together: the
/// three share one sort of the pooled draws and one rank normalisation of the split chains,
/// and return exactly what the three functions return on their own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Rank-normalised split-R̂.
    pub rhat: f64,
    /// Bulk effective sample size.
    pub ess_bulk: f64,
    /// Tail effective sample size.
    pub ess_tail: f64,
}

/// [`Convergence`] of chains (one vector of draws per chain).
pub(crate) fn convergence(chains: &[Vec<f64>]) -> Convergence {
    let mut sorted: Vec<f64> = chains.iter().flatten().copied().collect();
    sorted.sort_by(f64::total_cmp);
    convergence_sorted(chains, &sorted)
}

/// [`convergence`] given the pooled draws already sorted.
///
/// Its three independent parts (the rank-normalised draws with the bulk R̂ and ESS, the tail
/// R̂, the tail ESS) run side by side: a check during a one-parameter run has no other work
/// for the threads.
fn convergence_sorted(chains: &[Vec<f64>], sorted: &[f64]) -> Convergence {
    let split = split_chains(chains);
    let enough = split.first().map_or(0, Vec::len) >= 2;
    let ((bulk, ess_bulk), (tail, ess_tail)) = rayon::join(
        || {
            let ranked = rank_normalise(&split);
            (rhat_basic(&ranked), ess_basic(&ranked))
        },
        || {
            rayon::join(
                || {
                    if enough {
                        rhat_tail(&split, quantile_sorted(sorted, 0.5))
                    } else {
                        f64::NAN
                    }
                },
                || ess_tail_sorted(&split, sorted),
            )
        },
    );
    Convergence {
        rhat: if enough { bulk.max(tail) } else { f64::NAN },
        ess_bulk,
        ess_tail,
    }
}

/// Effective sample size of chains taken as they are (no splitting, no ranks), from the
/// combined autocorrelation ρ̂ₜ = 1 − (W − mean γ̂ₜ)/V̂⁺ truncated and made monotone by
/// Geyer's initial monotone sequence (Vehtari et al. 2021, §3.2; Stan's `ess`, including the
/// `posterior` package's use of the last positive even lag and the 1/log₁₀(MN) floor on τ̂).
/// NaN when the draws are constant or too few (N < 4).
pub(crate) fn ess_basic(chains: &[Vec<f64>]) -> f64 {
    let m = chains.len();
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    if m == 0 || n < 4 {
        return f64::NAN;
    }
    let nf = n as f64;
    let acovs: Vec<Vec<f64>> = chains.iter().map(|c| autocovariance(&c[..n])).collect();
    let means: Vec<f64> = chains
        .iter()
        .map(|c| c[..n].iter().sum::<f64>() / nf)
        .collect();
    let mean_acov = |t: usize| acovs.iter().map(|a| a[t]).sum::<f64>() / m as f64;
    let mean_var = mean_acov(0) * nf / (nf - 1.0);
    let mut var_plus = mean_var * (nf - 1.0) / nf;
    if m > 1 {
        let grand = means.iter().sum::<f64>() / m as f64;
        var_plus += means.iter().map(|mu| (mu - grand).powi(2)).sum::<f64>() / (m as f64 - 1.0);
    }
    if !(var_plus > 0.0) {
        return f64::NAN;
    }
    let rho = |t: usize| 1.0 - (mean_var - mean_acov(t)) / var_plus;
    let mut r = vec![0.0; n];
    r[0] = 1.0;
    let mut even = 1.0;
    let mut odd = rho(1);
    r[1] = odd;
    let mut t = 0;
    while t + 5 < n && even + odd > 0.0 {
        t += 2;
        even = rho(t);
        odd = rho(t + 1);
        if even + odd >= 0.0 {
            r[t] = even;
            r[t + 1] = odd;
        }
    }
    let max_t = t;
    if even > 0.0 {
        r[max_t] = even;
    }
    // Geyer's initial monotone sequence on the sums of pairs.
    let mut t = 2;
    while t + 2 <= max_t {
        if r[t] + r[t + 1] > r[t - 2] + r[t - 1] {
            let v = 0.5 * (r[t - 2] + r[t - 1]);
            r[t] = v;
            r[t + 1] = v;
        }
        t += 2;
    }
    let total = (m * n) as f64;
    let mut tau = -1.0 + 2.0 * r[..max_t.max(1)].iter().sum::<f64>() + r[max_t.min(n - 1)];
    tau = tau.max(1.0 / total.log10());
    total / tau
}

/// Bulk effective sample size: `ess_basic` of the rank-normalised split chains
/// (Vehtari et al. 2021, §4.3). Measures the efficiency of estimates of the centre of the
/// distribution (mean, median).
#[cfg(test)]
pub fn ess_bulk(chains: &[Vec<f64>]) -> f64 {
    ess_basic(&rank_normalise(&split_chains(chains)))
}

/// Tail effective sample size: the smaller of the split-chain ESS of the indicators
/// I(θ ≤ q₀.₀₅) and I(θ ≤ q₀.₉₅) (Vehtari et al. 2021, §4.3), measuring the efficiency of the
/// 5 % and 95 % quantile estimates.
#[cfg(test)]
pub fn ess_tail(chains: &[Vec<f64>]) -> f64 {
    let mut sorted: Vec<f64> = chains.iter().flatten().copied().collect();
    sorted.sort_by(f64::total_cmp);
    ess_tail_sorted(&split_chains(chains), &sorted)
}

/// [`ess_tail`] from the split chains and the pooled draws (of the chains before splitting)
/// sorted.
fn ess_tail_sorted(split: &[Vec<f64>], sorted: &[f64]) -> f64 {
    [0.05, 0.95]
        .iter()
        .map(|&p| {
            let q = quantile_sorted(sorted, p);
            let ind: Vec<Vec<f64>> = split
                .iter()
                .map(|c| c.iter().map(|&v| f64::from(u8::from(v <= q))).collect())
                .collect();
            ess_basic(&ind)
        })
        .fold(f64::INFINITY, |a, b| {
            if b.is_nan() || a.is_nan() {
                f64::NAN
            } else {
                a.min(b)
            }
        })
}

/// Effective sample size for the mean: `ess_basic` of the split chains on the original scale
/// (no rank normalisation), as `posterior::ess_mean`. Use it for Monte-Carlo standard errors
/// of means: MCSE = sd/√ESS.
#[cfg(test)]
pub fn ess_mean(chains: &[Vec<f64>]) -> f64 {
    ess_basic(&split_chains(chains))
}

// ---------------------------------------------------------------------------------------------
// Summaries.
// ---------------------------------------------------------------------------------------------

/// Quantile of sorted data with linear interpolation between order statistics (Hyndman & Fan
/// 1996, type 7, the default of R and NumPy). NaN for empty data.
pub(crate) fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    let h = (n - 1) as f64 * p.clamp(0.0, 1.0);
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(n - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// Diagnostics and summary of one parameter over all chains (pooled draws for the moments and
/// quantiles).
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterDiagnostics {
    /// Mean of the pooled draws.
    pub mean: f64,
    /// Standard deviation of the pooled draws (denominator S − 1).
    pub sd: f64,
    /// 2.5 % quantile.
    pub q025: f64,
    /// Median.
    pub median: f64,
    /// 97.5 % quantile.
    pub q975: f64,
    /// Central interval at the level asked of `summarise`: (quantile (1−level)/2,
    /// quantile (1+level)/2).
    pub interval: (f64, f64),
    /// Integrated autocorrelation time (in steps of the chains given), see `integrated_time`.
    pub tau: f64,
    /// Rank-normalised split-R̂, see `rhat`.
    pub rhat: f64,
    /// Bulk effective sample size, see `ess_bulk`.
    pub ess_bulk: f64,
    /// Tail effective sample size, see `ess_tail`.
    pub ess_tail: f64,
}

/// Diagnostics of one scalar quantity given as one vector of draws per chain; `level` is the
/// probability of the central interval (e.g. 0.95).
pub(crate) fn summarise_scalar(chains: &[Vec<f64>], level: f64) -> ParameterDiagnostics {
    let mut sorted: Vec<f64> = chains.iter().flatten().copied().collect();
    let s = sorted.len() as f64;
    let mean = sorted.iter().sum::<f64>() / s;
    let sd = (sorted.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (s - 1.0)).sqrt();
    sorted.sort_by(f64::total_cmp);
    let (c, tau) = rayon::join(
        || convergence_sorted(chains, &sorted),
        || integrated_time(chains, SOKAL_C),
    );
    let alpha = 0.5 * (1.0 - level);
    ParameterDiagnostics {
        mean,
        sd,
        q025: quantile_sorted(&sorted, 0.025),
        median: quantile_sorted(&sorted, 0.5),
        q975: quantile_sorted(&sorted, 0.975),
        interval: (
            quantile_sorted(&sorted, alpha),
            quantile_sorted(&sorted, 1.0 - alpha),
        ),
        tau,
        rhat: c.rhat,
        ess_bulk: c.ess_bulk,
        ess_tail: c.ess_tail,
    }
}

/// Diagnostics of every parameter of chains laid out `[chain][step][parameter]`; `level` is
/// the probability of the central interval (e.g. 0.95).
pub(crate) fn summarise(chains: &[Vec<Vec<f64>>], level: f64) -> Vec<ParameterDiagnostics> {
    let dim = chains
        .first()
        .and_then(|c| c.first())
        .map_or(0, |x| x.len());
    (0..dim)
        .into_par_iter()
        .map(|k| summarise_scalar(&parameter_chains(chains, k), level))
        .collect()
}
