//! Power-scaling sensitivity of a posterior to its prior and to its likelihood (N. Kallioinen,
//! T. Paananen, P.-C. Bürkner & A. Vehtari, "Detecting and diagnosing prior and likelihood
//! sensitivity with power-scaling", Stat. Comput. 34, 57, 2024; the method of the `priorsense`
//! package).
//!
//! Raising one component of the posterior, p(θ | y) ∝ p(θ) p(y | θ), to a power α near 1
//! reweights the draws by w_i ∝ exp((α − 1) ℓ_i), with ℓ_i the log of that component at draw
//! i: no new sampling. For each parameter the distance between the draws' empirical CDF and
//! the reweighted one is the cumulative Jensen–Shannon distance (H.-V. Nguyen & J. Vreeken,
//! ECML PKDD 2015), normalised by its upper bound; the sensitivity is its derivative in
//! log₂ α, estimated from α = 0.99 and 1.01 as (D(0.99) + D(1.01)) / (2 log₂ 1.01). A value of
//! at least [`SENSITIVITY_THRESHOLD`] flags a parameter: sensitive to the prior but not to the
//! likelihood means the prior decides the posterior (the data say little); sensitive to both,
//! a conflict between prior and data.
//!
//! The weights are plain normalised importance weights: at α = 1 ± 0.01 their log spread is a
//! hundredth of that of ℓ over the draws (a few nats for these posteriors), so the Pareto
//! smoothing `priorsense` applies changes nothing material here.

/// The power-scaling perturbations, below and above 1.
const ALPHAS: [f64; 2] = [0.99, 1.01];

/// Sensitivity at or above which a parameter is flagged (`priorsense`'s default).
pub(crate) const SENSITIVITY_THRESHOLD: f64 = 0.05;

/// The sensitivity of each parameter to power-scaling the component whose log value at each
/// draw is `log_component`; `draws[i][j]` is parameter j at draw i. `None` for fewer than
/// two draws or a non-finite log value.
pub(crate) fn sensitivity(draws: &[&[f64]], log_component: &[f64]) -> Option<Vec<f64>> {
    let m = draws.len();
    if m < 2 || log_component.len() != m || log_component.iter().any(|l| !l.is_finite()) {
        return None;
    }
    let k = draws[0].len();
    let mean = log_component.iter().sum::<f64>() / m as f64;
    let weights: Vec<Vec<f64>> = ALPHAS
        .iter()
        .map(|&a| {
            let lw: Vec<f64> = log_component
                .iter()
                .map(|l| (a - 1.0) * (l - mean))
                .collect();
            let mx = lw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let w: Vec<f64> = lw.iter().map(|x| (x - mx).exp()).collect();
            let s: f64 = w.iter().sum();
            w.into_iter().map(|x| x / s).collect()
        })
        .collect();
    let scale = 2.0 * ALPHAS[1].log2();
    Some(
        (0..k)
            .map(|j| {
                let x: Vec<f64> = draws.iter().map(|d| d[j]).collect();
                weights.iter().map(|w| cjs_distance(&x, w)).sum::<f64>() / scale
            })
            .collect(),
    )
}

/// The normalised cumulative Jensen–Shannon distance between the equally weighted empirical
/// CDF of `x` and the one weighted by `w` (summing to 1), the larger of the distances of x
/// and of −x (so that the measure does not depend on the parameter's orientation).
pub(crate) fn cjs_distance(x: &[f64], w: &[f64]) -> f64 {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let xs: Vec<f64> = idx.iter().map(|&i| x[i]).collect();
    let ws: Vec<f64> = idx.iter().map(|&i| w[i]).collect();
    let forward = cjs_sorted(&xs, &ws);
    let xr: Vec<f64> = xs.iter().rev().map(|v| -v).collect();
    let wr: Vec<f64> = ws.iter().rev().copied().collect();
    forward.max(cjs_sorted(&xr, &wr))
}

/// The distance for sorted `x`: the two CDFs are step functions on the same points, so the
/// integrals are sums over the gaps between neighbouring draws.
fn cjs_sorted(x: &[f64], w: &[f64]) -> f64 {
    let n = x.len();
    let u = 1.0 / n as f64;
    let (mut p, mut q) = (0.0f64, 0.0f64);
    let (mut pq, mut qp, mut p_int, mut q_int) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..n - 1 {
        p += u;
        q += w[i];
        let dx = x[i + 1] - x[i];
        if dx <= 0.0 {
            continue;
        }
        let mid = 0.5 * (p + q);
        if p > 0.0 {
            pq += dx * p * (p.log2() - mid.log2());
        }
        if q > 0.0 {
            qp += dx * q * (q.log2() - mid.log2());
        }
        p_int += dx * p;
        q_int += dx * q;
    }
    let half_ln2 = 0.5 / std::f64::consts::LN_2;
    let cjs_pq = pq + half_ln2 * (q_int - p_int);
    let cjs_qp = qp + half_ln2 * (p_int - q_int);
    let bound = p_int + q_int;
    if !(bound > 0.0) {
        return 0.0;
    }
    ((cjs_pq + cjs_qp) / bound).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;

    /// A conjugate check with a closed form: prior N(0, τ²), likelihood of one observation
    /// y = 0 with noise σ², posterior N(0, s²) with 1/s² = 1/τ² + 1/σ². Power-scaling the
    /// prior by α gives 1/s_α² = α/τ² + 1/σ²: the reweighted draws must have that variance
    /// (checked on the weights directly), and the prior sensitivity grows as the prior's share
    /// of the precision grows.
    #[test]
    fn power_scaled_weights_move_a_normal_posterior_as_the_closed_form_says() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let (tau2, sigma2) = (1.0f64, 4.0f64);
        let s2 = 1.0 / (1.0 / tau2 + 1.0 / sigma2);
        let m = 200_000;
        let x: Vec<f64> = (0..m)
            .map(|_| s2.sqrt() * rng.sample::<f64, _>(StandardNormal))
            .collect();
        let lp: Vec<f64> = x.iter().map(|v| -0.5 * v * v / tau2).collect();
        let alpha: f64 = 1.5;
        let lw: Vec<f64> = lp.iter().map(|l| (alpha - 1.0) * l).collect();
        let mx = lw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let w: Vec<f64> = lw.iter().map(|l| (l - mx).exp()).collect();
        let sw: f64 = w.iter().sum();
        let var: f64 = x.iter().zip(&w).map(|(v, wi)| v * v * wi).sum::<f64>() / sw;
        let want = 1.0 / (alpha / tau2 + 1.0 / sigma2);
        assert!((var / want - 1.0).abs() < 0.01, "{var} vs {want}");
        // Prior share of the precision 0.8 (τ² = 1, σ² = 4) against 0.2 (τ² = 4, σ² = 1).
        let draws: Vec<&[f64]> = x.chunks(1).collect();
        let strong = sensitivity(&draws, &lp).unwrap()[0];
        let lp_weak: Vec<f64> = x.iter().map(|v| -0.5 * v * v / 16.0).collect();
        let weak = sensitivity(&draws, &lp_weak).unwrap()[0];
        assert!(
            strong > SENSITIVITY_THRESHOLD && weak < strong / 4.0,
            "{strong} {weak}"
        );
    }

    #[test]
    fn equal_weights_give_zero_distance_and_a_flat_component_zero_sensitivity() {
        let x: Vec<f64> = (0..100).map(|i| (i as f64).sin()).collect();
        let w = vec![0.01; 100];
        assert!(cjs_distance(&x, &w) < 1e-7);
        let draws: Vec<&[f64]> = x.chunks(1).collect();
        let flat = vec![-3.0; 100];
        assert!(sensitivity(&draws, &flat).unwrap()[0] < 1e-7);
        assert!(sensitivity(&draws[..1], &flat[..1]).is_none());
    }
}
