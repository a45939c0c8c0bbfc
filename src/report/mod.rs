//! Reports: figures (SVG) and, in later issues, uncertainty tables and model comparison.

pub mod figures;
