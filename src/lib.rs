//! # fitbead
//!
//! Forward models and inverse problems for a bead rolling down a row of beads, after Ancey,
//! Evesque & Coussot, "Motion of a single bead on a bead row: theoretical investigations",
//! J. Phys. I France 6 (1996) 725–751: from a scene (radius ratio ξ, slope δ, gyration ρ,
//! friction f, collision law K) the steady mean velocity and regime under each of the paper's
//! models; from measured mean velocities the collisional parameter K per point (eq 69), laws
//! K(α), Jan's λ and μ and Jaeger's a1–a3, by least squares or MCMC.
//!
//! Equation numbers in the docs are the paper's. Where the printed paper has misprints,
//! fitbead uses corrected forms; the repository's `docs/PHYSICS.md` lists each one with the
//! check that confirmed it. `docs/GUIDE.md` describes the command line, `docs/ACCURACY.md` the
//! measured errors and `docs/PERFORMANCE.md` the measured speed.
//!
//! Units are dimensionless: length R + r, time 1/ω0 with ω0² = g/(R+r); a velocity v converts
//! to SI as v · sqrt(g (R + r)). Slopes given to [`Scene::new`] are in degrees.
//!
//! ## Layers
//!
//! ```text
//!   pipeline ───── whole runs as library calls: synthetic data (simulate), the fit
//!                  commands (FitCommand: klaw, jan, jaeger), the report directory (report)
//!   error ──────── the one error type (Error) wrapping every layer's below
//!   io ─────────── CSV schemas, measurements with units (Dataset::from_csv), atomic files;
//!                  one typed record per output row (io::records: ForwardRecord, KRecord, …)
//!   report ─────── the paper's comparisons, figures, the work-precision engine
//!   design ─────── optimal experimental design: the slopes to measure for a parameter
//!                  (D, c criteria) or to tell two models apart (T)
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
//! Each layer uses only the layers below it (`numfmt`, `progress`, `record` and `last` are leaves;
//! `prelude` and the crate root's re-exports are the crate's top). Every command of the
//! command line is a call of [`pipeline`] (or of [`design`] for `design`). The command line
//! itself is the workspace package `fitbead-cli` (`crates/fitbead-cli`, binary `fitbead`),
//! which parses flags, calls those doors and writes what they return; the library depends on
//! none of its crates (argument parsing, progress bars, signals, recipes, its allocator).
//!
//! ## Which crate does what
//!
//! | crate | what it does here |
//! |---|---|
//! | argmin | the optimisation framework: the least-squares solver is an argmin `Solver` ([`inverse::LevenbergMarquardt`]) run by argmin's `Executor`, and every least-squares problem is an argmin problem ([`inverse::LeastSquares`]), so argmin's other solvers, observers and termination rules apply; the fits' progress comes from an argmin observer (`inverse::ProgressObserver`), and argmin problems fit with fitbead's solver ([`inverse::ArgminResiduals`]) |
//! | nalgebra (with argmin-math's nalgebra backend) | the vectors and matrices of that argmin interface; fixed-size 2-D geometry: the molecular-dynamics bead's position, velocity and forces (`Vector2`) and the 2×2 Newton polish of the contact model's fixed point (`Matrix2`) |
//! | faer | dense linear algebra inside the solver: the column-pivoted QR of each Levenberg–Marquardt iteration and the SVD behind every covariance |
//! | statrs | Student-t and normal quantiles of the confidence intervals and the MCMC diagnostics; the priors' densities |
//! | rand, rand_chacha, rand_distr | random streams reproducible from a seed whatever the thread count: the MCMC sampler, simulated data |
//! | rayon | parallel per-row and per-point work (`forward`, `k`, the K-law fits) |
//! | csv, serde, ryu | the CSV formats; shortest round-trip printing of floats |
//! | resvg (feature `png`, default), svg2pdf (feature `pdf`, default) | PNG rendering of the figures, with the embedded font |
//! | thiserror, tempfile | error types; atomic output files |
//!
//! What is hand-written instead, and the measurement that keeps it so, is said where it lives:
//! the SVG figures (`report::figures::svg`: a plotting crate's backend rounds coordinates to
//! whole pixels and cannot measure text), Carlson's R_F (`special::elliptic::rf`), the Brent root finder (`special::root`), the
//! double-double arithmetic (`special::dd`) and the Levenberg–Marquardt iteration itself
//! (argmin has none; the NIST cross-checks in `docs/ACCURACY.md`).
//!
//! ## Quickstart
//!
//! [`prelude`] imports what a typical program needs. The program `examples/quickstart.rs`
//! (`cargo run --release --example quickstart`) evaluates one scene, inverts one measurement
//! and fits a K(α) law to a data set by least squares and by MCMC:
//!
#![doc = "```"]
#![doc = include_str!("../examples/quickstart.rs")]
#![doc = "```"]
// `!(x > 0.0)` is deliberate throughout: a NaN must land in the failure branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod design;
pub mod error;
pub mod fit;
pub mod inverse;
pub(crate) mod last;
pub mod models;
pub mod numfmt;
pub mod pipeline;
pub mod progress;
pub(crate) mod record;
pub mod report;
pub mod scene;
pub(crate) mod special;

pub mod io;
pub mod prelude;

#[cfg(feature = "bench-internals")]
pub mod bench_internals;

pub use error::{Error, Result};
pub use fit::data::Dataset;
pub use fit::summary::FitResult;
pub use models::{ForwardModel, Model, ModelKind, NotSteady, Outcome, Regime, Steady};
pub use scene::{CollisionLaw, Scene};
