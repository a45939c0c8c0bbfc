//! The one error type of the public API. Each module keeps its own precise error (a scene
//! parameter out of its domain, a bad cell in a file, a point that no K makes steady, …);
//! [`Error`](enum@Error) wraps any of them, so `?` works across modules and into
//! `Box<dyn std::error::Error>`.

use crate::design::DesignError;
use crate::fit::data::DataError;
use crate::fit::error::FitError;
use crate::fit::k::KFailure;
use crate::fit::klaw::KLawError;
use crate::inverse::{LsqError, McmcError};
use crate::io::InputError;
use crate::models::NotSteady;
use crate::report::figures::FigureError;
use crate::scene::ParameterError;
use thiserror::Error;

/// Every way a library call can fail.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A scene or model parameter outside its domain, or an unknown law or model name.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// A bad file, row or cell (file, line, column and value are in the error).
    #[error(transparent)]
    Input(#[from] InputError),
    /// Measurements that cannot form a data set.
    #[error(transparent)]
    Data(#[from] DataError),
    /// A forward model found no steady state (regime A or C, or the model's own validity).
    #[error(transparent)]
    NotSteady(#[from] NotSteady),
    /// A measured point with no collisional parameter K (eq 69).
    #[error(transparent)]
    K(#[from] KFailure),
    /// A K(α) law that cannot be fitted to the data.
    #[error(transparent)]
    KLaw(#[from] KLawError),
    /// The least-squares solver refused its problem.
    #[error(transparent)]
    Lsq(#[from] LsqError),
    /// The posterior sampler refused its problem.
    #[error(transparent)]
    Mcmc(#[from] McmcError),
    /// A fit that cannot be made, or a parameter the fit does not have.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// Design settings that cannot make a design.
    #[error(transparent)]
    Design(#[from] DesignError),
    /// A figure that cannot be drawn, rendered or converted.
    #[error(transparent)]
    Figure(#[from] FigureError),
    /// Reading or writing a file failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

impl From<crate::fit::summary::NoSuchParameter> for Error {
    fn from(e: crate::fit::summary::NoSuchParameter) -> Self {
        Error::Fit(e.into())
    }
}

/// Result alias for library calls.
pub type Result<T> = std::result::Result<T, Error>;
