//! Typed errors of the library. They are rendered once, at the command line, with file, line,
//! column and value where the error came from a file.

use thiserror::Error;

/// Every way a library call can refuse its input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// A scene or model parameter is outside its domain (or not finite).
    #[error("invalid {field} = {value}: {reason}")]
    InvalidParameter {
        /// Name of the field, as the user wrote it (`xi`, `delta_deg`, `K`, …).
        field: &'static str,
        /// The offending value, as text.
        value: String,
        /// What the domain is.
        reason: &'static str,
    },
    /// A collision law name that fitbead does not know.
    #[error("unknown collision law '{0}' (expected a number, cos2a, adjusted, impact or c=VALUE)")]
    UnknownLaw(String),
    /// A model name that fitbead does not know.
    #[error("unknown model '{0}'")]
    UnknownModel(String),
}

/// Result alias for library calls.
pub type Result<T> = std::result::Result<T, Error>;
