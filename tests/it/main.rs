//! The integration tests, in one binary. Each module covers one area; run one with
//! `cargo test --release --test it <module>::` and add `-- --nocapture` to see the figures
//! the tests print (measured errors, coverage tables).

mod common;
/// The LRE and argmin's solvers, shared with the library's in-crate cross-checks.
#[path = "../shared/cross_check.rs"]
mod cross_check;
use fitbead::inverse::{LeastSquares, LsqOptions, Residuals};

mod bench_cli;
mod cli;
mod cli_mcmc;
mod contact;
mod controls;
mod cross_solvers;
mod design;
mod edges_cli;
mod edges_files;
mod edges_fits;
mod faults;
mod figures;
mod fits;
mod layers;
mod md;
mod nist;
mod pipeline;
mod prior_sensitivity;
mod recipes;
mod report;
mod report_mcmc;
mod stress;
mod threads;
