//! # fitbead
//!
//! Forward models and inverse problems for a bead rolling down a row of beads, after Ancey,
//! Evesque & Coussot, "Motion of a single bead on a bead row: theoretical investigations",
//! J. Phys. I France 6 (1996) 725–751. Equation numbers in the docs are the paper's; where the
//! printed text has typos, the corrected forms of the project's MODEL.md are used.
//!
//! Units are dimensionless: length R + r, time 1/ω0 with ω0² = g/(R+r); a velocity v converts
//! to SI as v · sqrt(g (R + r)).
//!
//! ## Layers
//!
//! ```text
//!   io ─────────── CSV schemas, measurements with units (Dataset::from_csv), atomic files
//!   report ─────── the paper's comparisons, figures, the work-precision engine
//!   fit ────────── the bead problems: K per point (eq 69), K(α) laws, Jan, Jaeger;
//!                  typed results (FitResult) with a printable fit report, builders
//!   inverse ────── solvers that know nothing of beads: Levenberg–Marquardt, profiles,
//!                  ensemble MCMC, priors and posteriors over any residual problem
//!   models ─────── one forward model per file (stick, slip, stick/slip, contact, Jan,
//!                  Jaeger, md, auto); regimes (δ_m, δ_d, the regime-B interval)
//!   scene ──────── ξ, δ, ρ, f and the collision law, validated
//!   special ────── math with no beads in it: elliptic integrals, quadrature, roots, dd
//! ```
//!
//! Each layer uses only the layers below it (`numfmt`, `progress` and `error` are leaves or
//! the crate's top). The command line is the binary's (`src/main.rs`, `src/cli/`), built with
//! the default feature `cli`; without it (`default-features = false`) the library has no
//! command-line dependencies.
//!
//! ## Quickstart
//!
//! The program `examples/quickstart.rs` (`cargo run --release --example quickstart`):
//!
#![doc = "```"]
#![doc = include_str!("../examples/quickstart.rs")]
#![doc = "```"]
// `!(x > 0.0)` is deliberate throughout: a NaN must land in the failure branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod fit;
pub mod inverse;
pub mod models;
pub mod numfmt;
pub mod progress;
pub mod report;
pub mod scene;
pub mod special;

pub mod io;
pub mod prelude;

pub use error::{Error, Result};
pub use fit::data::Dataset;
pub use fit::summary::FitResult;
pub use models::{ForwardModel, Model, ModelKind, NotSteady, Outcome, Regime, Steady};
pub use scene::{CollisionLaw, Scene};
