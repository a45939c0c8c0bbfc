//! Reports: the comparisons of `fitbead report` ([`analysis`]) and their posterior bands
//! ([`bands`]), its SVG figures ([`figures`]), its text ([`text`])
//! and the work-precision engine of `fitbead bench` ([`workprecision`]).

pub mod analysis;
pub mod bands;
pub mod figures;
pub mod text;
pub mod workprecision;

/// Every file `fitbead report` may write in its directory.
pub const REPORT_FILES: [&str; 14] = [
    "bulk_friction.csv",
    "energy.csv",
    "regime_map.csv",
    "points.csv",
    "models.csv",
    "models_by_series.csv",
    "params.csv",
    "stats.csv",
    "velocity.svg",
    "jan_linear.svg",
    "k_final_velocity.svg",
    "regime_map.svg",
    "corner.svg",
    "report.md",
];
