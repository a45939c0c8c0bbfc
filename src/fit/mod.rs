//! The bead problems posed to the solvers: K per measurement (eq 69, [`k`]), the K(α) laws
//! across series ([`klaw`]), Jan's λ/μ ([`jan`]) and Jaeger's a1–a3 ([`jaeger`]); their
//! results ([`summary`], which prints as a fit report) and builders ([`builder`]). Nothing here
//! reads files, prints or knows the command line.

pub mod builder;
pub(crate) mod controls;
pub mod data;
mod display;
pub mod error;
pub mod jaeger;
pub(crate) mod jaeger_coordinates;
pub mod jan;
pub mod k;
pub mod klaw;
pub mod posterior;
pub(crate) mod slopes;
#[cfg(test)]
mod suite;
pub mod summary;
