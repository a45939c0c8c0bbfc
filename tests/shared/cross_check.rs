//! The cross-checks' shared part, compiled into the library's in-crate suite
//! (`src/fit/suite/cross_solvers.rs`, the bead fits) and into the integration tests
//! (`tests/it`, the NIST cases): the log relative error (LRE) by which every estimate is
//! judged, and argmin's Gauss–Newton and Nelder–Mead run on a fitbead problem through
//! `LeastSquares`. The module that includes this file brings `LeastSquares`, `LsqOptions` and
//! `Residuals` into scope (from `crate::inverse` or `fitbead::inverse`).

use super::{LeastSquares, LsqOptions, Residuals};
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::gaussnewton::GaussNewtonLS;
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::neldermead::NelderMead;
use nalgebra::DVector;

/// Log relative error of `est` against `reference`, capped at 11 (NIST's certified digits); 0
/// for anything non-finite.
pub fn lre(est: f64, reference: f64) -> f64 {
    let r = if reference != 0.0 {
        (est - reference).abs() / reference.abs()
    } else {
        est.abs()
    };
    if r == 0.0 {
        11.0
    } else if r.is_finite() {
        (-r.log10()).clamp(0.0, 11.0)
    } else {
        0.0
    }
}

/// Smallest LRE of `est` against `reference`.
pub fn min_lre(est: &[f64], reference: &[f64]) -> f64 {
    est.iter()
        .zip(reference)
        .map(|(e, c)| lre(*e, *c))
        .fold(11.0, f64::min)
}

/// argmin's Gauss–Newton with a Moré–Thuente line search from `start`: the estimate, or why
/// it failed.
pub fn gauss_newton<R: Residuals>(problem: R, start: &[f64]) -> Result<Vec<f64>, String> {
    let ls =
        LeastSquares::new(problem, start, &LsqOptions::default()).map_err(|e| e.to_string())?;
    let solver = GaussNewtonLS::new(MoreThuenteLineSearch::new())
        .with_tolerance(1e-12)
        .map_err(|e| e.to_string())?;
    let res = Executor::new(ls, solver)
        .configure(|s| s.param(DVector::from_column_slice(start)).max_iters(1000))
        .ctrlc(false)
        .run()
        .map_err(|e| first_line(&e.to_string()))?;
    let p = res.state().get_best_param().ok_or("no estimate")?;
    if p.iter().all(|v| v.is_finite()) {
        Ok(p.as_slice().to_vec())
    } else {
        Err("non-finite estimate".into())
    }
}

/// argmin's Nelder–Mead from `start` (initial simplex: each coordinate moved by 5 %, or by
/// 0.00025 where it is 0, as scipy does), restarted from its best vertex until a restart no
/// longer lowers χ² by 1e-15 relative (at most 10 runs of 10,000 iterations, each ended when the
/// standard deviation of χ² over the simplex is below 1e-15 of χ²).
pub fn nelder_mead<R: Residuals>(problem: R, start: &[f64]) -> Result<Vec<f64>, String> {
    let mut ls =
        LeastSquares::new(problem, start, &LsqOptions::default()).map_err(|e| e.to_string())?;
    let mut x = DVector::from_column_slice(start);
    let mut best = ls.cost(&x).map_err(|e| e.to_string())?;
    if !best.is_finite() {
        return Err("infeasible start".into());
    }
    for _ in 0..10 {
        let mut simplex = vec![x.clone()];
        for j in 0..x.len() {
            let mut v = x.clone();
            v[j] = if v[j] != 0.0 { 1.05 * v[j] } else { 0.00025 };
            simplex.push(v);
        }
        let solver = NelderMead::new(simplex)
            .with_sd_tolerance(1e-15 * best)
            .map_err(|e| e.to_string())?;
        let res = Executor::new(ls, solver)
            .configure(|s| s.max_iters(10_000))
            .ctrlc(false)
            .run()
            .map_err(|e| first_line(&e.to_string()))?;
        let cost = res.state().get_best_cost();
        let p = res.state().get_best_param().ok_or("no estimate")?.clone();
        ls = res.problem.problem.ok_or("problem lost")?;
        let improved = cost < best * (1.0 - 1e-15);
        if cost <= best {
            best = cost;
            x = p;
        }
        if !improved {
            break;
        }
    }
    Ok(x.as_slice().to_vec())
}

/// The first line of an error message, cut at 60 characters (for the tables).
pub fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").chars().take(60).collect()
}
