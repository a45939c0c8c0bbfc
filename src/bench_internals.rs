//! Internals that the benchmarks time against their alternatives (`benches/`) and that the
//! example `wp_plot` calls, compiled with the non-default feature `bench-internals` only. Not
//! part of the library's API: these names may change with any release.

pub use crate::fit::k::bracket::bracket;
pub use crate::fit::k::contacts_counted;
pub use crate::fit::k::search::solve;
pub use crate::inverse::mcmc::diagnostics::autocovariance;

/// R̂, bulk and tail ESS of one parameter's chains, as one convergence check computes them.
pub fn convergence(chains: &[Vec<f64>]) -> (f64, f64, f64) {
    let c = crate::inverse::mcmc::diagnostics::convergence(chains);
    (c.rhat, c.ess_bulk, c.ess_tail)
}
pub use crate::models::sample::{draw_scenes, Draw};
pub use crate::models::slip::steady_tol as slip_steady_tol;
pub use crate::models::stickquad::steady_quad as stick_steady_quad;
pub use crate::models::stickslip::steady_tol as stickslip_steady_tol;
pub use crate::special::elliptic::{cos_integral, cos_integral_pair, rf, rf_dy_lanes, rf_lanes};
pub use crate::special::root::{brent, Root};
pub use crate::special::SinCos;

/// Numbers as the streaming commands write a row's number cells: each of `xs` as the shortest
/// decimal that reads back as it ([`crate::numfmt::fmt_f64`]), comma-separated, then the
/// record's newline, appended to `out`.
pub fn push_number_cells(out: &mut Vec<u8>, xs: &[f64]) {
    let mut c = crate::io::cells::Cells::new(out);
    for &x in xs {
        c.num(x);
    }
    c.end();
}

/// A work-precision table written by `fitbead bench --output`, re-plotted as the bench
/// command's SVG figure under `title`.
pub fn replot(csv_bytes: &[u8], title: &str) -> Result<String, Box<dyn std::error::Error>> {
    let rows = crate::report::workprecision::read_rows(csv_bytes)?;
    Ok(crate::report::workprecision::plot(&rows, title)?)
}

/// `n` random scenes as python/bench/bench_forward.py draws them (ξ in [0.8, 3], the adjusted
/// law's K as a number, ρ = 0.4 on half of them and in [0.2, 0.7] on the others, f = 0.1; δ 90 %
/// in (δ_m, δ_d), 5 % below δ_m, 5 % above δ_d, with δ_m of eq 32 and δ_d of eq 31): (ξ, δ in
/// degrees, K, ρ).
pub fn python_bench_scenes(n: usize) -> Vec<(f64, f64, f64, f64)> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20251125);
    (0..n)
        .map(|_| {
            let xi: f64 = rng.random_range(0.8..3.0);
            let rho = if rng.random::<f64>() < 0.5 {
                0.4
            } else {
                rng.random_range(0.2..0.7f64)
            };
            let a = (1.0 / (1.0 + xi)).asin();
            let k = (2.0 * a).cos() + 0.5 * a.sin().powi(2) * (2.0 * a).sin();
            let dm = 2.0 * ((a / 2.0).tan() * (1.0 - k) / (1.0 + k)).atan();
            let c = (1.0 + rho) * (1.0 - k * k);
            let dd = (c / (a.tan() * (4.0 + c))).atan();
            let (u, class) = (rng.random::<f64>(), rng.random::<f64>());
            let d = if class < 0.9 {
                dm + u * (dd - dm)
            } else if class < 0.95 {
                dm * (0.5 + 0.5 * u)
            } else {
                dd + u * ((1.5 * dd).min(89f64.to_radians()) - dd)
            };
            (xi, d.to_degrees(), k, rho)
        })
        .collect()
}
