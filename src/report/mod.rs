//! Reports: the comparisons of `fitbead report` ([`analysis`]), its SVG figures ([`figures`]), its text ([`text`])
//! and the work-precision engine of `fitbead bench` ([`workprecision`]).

pub mod analysis;
pub mod figures;
pub mod text;
pub mod workprecision;
