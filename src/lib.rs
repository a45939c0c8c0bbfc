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
//! ```
//! use fitbead::{CollisionLaw, ForwardModel, Model, Scene};
//! // ξ = 1, δ = 12°, ρ = 0.4, f = 0.1, the paper's fitted collision law (§3.6.1).
//! let scene = Scene::new(1.0, 12.0, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
//! let v = Model::Stick.evaluate(&scene).unwrap().mean_velocity;
//! assert!((v - 0.39120827).abs() < 1e-8); // MODEL.md §2
//! ```

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

pub use error::{Error, Result};
pub use models::{ForwardModel, Model, ModelKind, NotSteady, Outcome, Regime, Steady};
pub use scene::{CollisionLaw, Scene};

pub mod io;
