//! Reports: the comparisons of `fitbead report` ([`analysis`]) and the SVG figures
//! ([`figures`]).

pub mod analysis;
pub mod figures;
