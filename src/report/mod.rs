//! Reports: the comparisons of `fitbead report` ([`analysis`]) and their posterior bands
//! ([`bands`]), the list of its fits ([`fits`]), its figures ([`plots`], drawn with the engine
//! in [`figures`]), its text ([`text`]) and the work-precision engine of `fitbead bench`
//! ([`workprecision`]).

pub mod analysis;
pub mod bands;
pub mod figures;
pub mod fits;
pub mod plots;
pub mod text;
pub mod workprecision;

/// Every file of fixed name `fitbead report` may write in its directory (with `--format png`
/// or `both`, each figure `NAME.svg` also, or instead, as `NAME.png`; with `--method mcmc`, one
/// corner plot per posterior, `corner_<fit>_<series>.svg` with the fit named as in
/// `params.csv`).
pub const REPORT_FILES: [&str; 19] = [
    "bulk_friction.csv",
    "energy.csv",
    "regime_map.csv",
    "points.csv",
    "models.csv",
    "models_by_series.csv",
    "params.csv",
    "stats.csv",
    "residuals.csv",
    "correlations.csv",
    "velocity.svg",
    "jan_linear.svg",
    "k_final_velocity.svg",
    "regime_map.svg",
    "jaeger.svg",
    "k_alpha.svg",
    "energy.svg",
    "residuals.svg",
    "report.md",
];
