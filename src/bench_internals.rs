//! Internals that the benchmarks time against their alternatives (`benches/`) and that the
//! example `wp_plot` calls, compiled with the non-default feature `bench-internals` only. Not
//! part of the library's API: these names may change with any release.

pub use crate::fit::k::bracket::bracket;
pub use crate::fit::k::search::solve;
pub use crate::inverse::mcmc::diagnostics::autocovariance;
pub use crate::models::sample::{draw_scenes, Draw};
pub use crate::models::slip::steady_tol as slip_steady_tol;
pub use crate::models::stickquad::steady_quad as stick_steady_quad;
pub use crate::models::stickslip::steady_tol as stickslip_steady_tol;
pub use crate::special::elliptic::{cos_integral, cos_integral_pair, rf};
pub use crate::special::root::{brent, Root};
pub use crate::special::SinCos;

/// A work-precision table written by `fitbead bench --output`, re-plotted as the bench
/// command's SVG figure under `title`.
pub fn replot(csv_bytes: &[u8], title: &str) -> Result<String, String> {
    crate::report::workprecision::plot(&crate::report::workprecision::read_rows(csv_bytes)?, title)
}
