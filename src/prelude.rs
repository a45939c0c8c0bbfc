//! The names a typical program needs, in one import: `use fitbead::prelude::*;`.

pub use crate::design::{design, Criterion, DesignFit, DesignResult, DesignRow, DesignSettings};
pub use crate::error::Error;
pub use crate::fit::builder::{JaegerFitter, JanFitter, KLawFitter};
pub use crate::fit::data::Dataset;
pub use crate::fit::error::FitError;
pub use crate::fit::k::{estimate as estimate_k, KEstimate, KFailure};
pub use crate::fit::klaw::KLaw;
pub use crate::fit::summary::FitSet;
pub use crate::fit::summary::{FitResult, ParamRow, PointFit};
pub use crate::inverse::posterior::{McmcSettings, Prior};
pub use crate::io::measurements::MeasurementDefaults;
pub use crate::models::{ForwardModel, JaegerBranch, Model, NotSteady, Outcome, Regime, Steady};
pub use crate::scene::{CollisionLaw, Scene, SceneBuilder};
