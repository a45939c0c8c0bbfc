//! Log-density evaluations per effective sample of the ensemble sampler on Gaussian targets,
//! for several fractions of differential-evolution moves (the rest stretch moves): the
//! measurement behind the default `McmcOptions::de_fraction`.
//!
//! Run: `cargo run --release --example mcmc_moves` (a few minutes: 20 runs of 20 000 steps).

use fitbead::inverse::mcmc::{EnsembleSampler, LogDensity, McmcOptions};

/// A Gaussian whose coordinates form an AR(1) chain with correlation `rho` (unit marginals).
struct Gauss {
    dim: usize,
    rho: f64,
}

impl LogDensity for Gauss {
    fn dim(&self) -> usize {
        self.dim
    }
    fn log_density(&self, x: &[f64]) -> f64 {
        let r = self.rho;
        let mut s = x[0] * x[0];
        for k in 1..x.len() {
            s += (x[k] - r * x[k - 1]).powi(2) / (1.0 - r * r);
        }
        -0.5 * s
    }
}

fn main() {
    println!("dim,rho,de_fraction,tau_max,ess_min,evals_per_ess,acceptance");
    for (dim, rho) in [(1usize, 0.0), (2, 0.0), (2, 0.99), (5, 0.0), (5, 0.9)] {
        for de in [0.0, 0.5, 0.8, 1.0] {
            let target = Gauss { dim, rho };
            let options = McmcOptions {
                seed: 3,
                walkers: Some(32),
                max_steps: 20_000,
                min_ess: f64::INFINITY,
                de_fraction: de,
                ..Default::default()
            };
            let sampler = EnsembleSampler::new(&target, options).expect("valid options");
            let r = sampler.run(&vec![0.0; dim]).expect("feasible start");
            let ess = r
                .diagnostics
                .iter()
                .map(|d| d.ess_bulk.min(d.ess_tail))
                .fold(f64::INFINITY, f64::min);
            let tau = r.diagnostics.iter().map(|d| d.tau).fold(0.0, f64::max);
            println!(
                "{dim},{rho},{de},{tau:.1},{ess:.0},{:.1},{:.2}",
                (r.steps * 32) as f64 / ess,
                r.acceptance_overall
            );
        }
    }
}
