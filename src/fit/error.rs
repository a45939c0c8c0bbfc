//! Why a fit across series cannot be made or queried.

use super::klaw::KLawError;
use super::summary::NoSuchParameter;
use thiserror::Error;

/// Why a fit cannot be made, or a result has no such parameter.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FitError {
    /// The K(α) law cannot be fitted to the data.
    #[error(transparent)]
    KLaw(#[from] KLawError),
    /// A confidence level outside (0, 1).
    #[error("confidence level {0} is not in (0, 1)")]
    Level(f64),
    /// The method cannot fit these data (a posterior run on slopes that carry errors).
    #[error("{0}")]
    Method(String),
    /// A parameter name that the fit does not have.
    #[error(transparent)]
    NoSuchParameter(#[from] NoSuchParameter),
    /// A control of the parameters (held, started or bounded) that cannot be used on these
    /// data: the command line's flag (`--fix`, `--init`, `--bounds`), the control as given
    /// (`NAME=VALUE`) and why.
    #[error("{flag} {value}: {reason}")]
    Setting {
        /// The flag.
        flag: String,
        /// The control as given.
        value: String,
        /// Why it cannot be used.
        reason: String,
    },
}

impl From<super::controls::ControlError> for FitError {
    fn from(e: super::controls::ControlError) -> Self {
        FitError::Setting {
            flag: e.flag.to_string(),
            value: e.value,
            reason: e.reason,
        }
    }
}
