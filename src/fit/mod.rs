//! The bead problems posed to the solvers: K per measurement (eq 69), and (in later issues)
//! the K(α) laws, Jan's λ/μ and Jaeger's a1–a3. Nothing here reads CSV or knows the CLI.

pub mod k;
