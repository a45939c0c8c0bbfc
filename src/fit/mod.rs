//! The bead problems posed to the solvers: K per measurement (eq 69), the K(α) laws across
//! series, Jan's λ/μ and Jaeger's a1–a3. Nothing here reads CSV or knows the CLI.

pub mod data;
pub mod jaeger;
pub mod jan;
pub mod k;
pub mod klaw;
pub mod posterior;
pub mod summary;
