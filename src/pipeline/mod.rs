//! Whole runs of the command line as library calls, one door per command: `forward` and `k`
//! ([`TableCommand::run`]), the fit commands `klaw`, `jan` and `jaeger`
//! ([`FitCommand::run`]), `regimes` ([`RegimeRecord::csv`](crate::io::records::RegimeRecord::csv)),
//! `report` ([`ReportSettings::run`]), `simulate` ([`SimulateSettings::run`]) and `bench`
//! ([`Bench::run`]); `design` is [`crate::design::design`]. The command line parses its flags
//! into these settings, calls these doors and prints or writes what they return; the Python
//! package calls the same doors.
//!
//! A setting that cannot be used is an [`InputError`] named as the command line's flag
//! (`--points`, `--series`, …) in the column of the error, so that both front ends report it
//! alike.

mod bench;
mod fit_command;
mod fit_run;
mod forward;
mod jaeger;
mod jan;
mod k;
mod klaw;
mod regimes;
mod report;
mod simulate;
#[cfg(test)]
mod suite;
mod table;

pub use crate::io::stream::StreamOptions;
pub use bench::Bench;
pub use fit_command::FitCommand;
pub use fit_run::FitRun;
pub(crate) use fit_run::{figure_bytes, not_converged};
pub use forward::plan::ForwardSettings;
pub(crate) use report::law_error;
pub use report::{ReportOutput, ReportSettings};
pub use simulate::SimulateSettings;
pub use table::{TableCommand, TableRun};

use crate::io::InputError;
use std::fmt;

/// Why a run of this module failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum RunError {
    /// A bad setting (its flag in `column`) or a bad cell of an input file, located.
    Input(InputError),
    /// Any other failure (a model without a steady state where one is needed, a figure that
    /// cannot be drawn, a directory that cannot be written), with its message.
    Failed(String),
    /// Stopped by the settings' stop flag before anything was written.
    Interrupted,
    /// A library call that failed (a figure that could not be drawn or rendered, …), with the
    /// library's own error.
    Library(crate::error::Error),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Input(e) => write!(f, "{e}"),
            RunError::Failed(s) => f.write_str(s),
            RunError::Interrupted => f.write_str("interrupted: nothing written"),
            RunError::Library(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RunError {}

impl From<InputError> for RunError {
    fn from(e: InputError) -> Self {
        RunError::Input(e)
    }
}

impl From<crate::error::Error> for RunError {
    fn from(e: crate::error::Error) -> Self {
        RunError::Library(e)
    }
}

impl From<crate::report::figures::FigureError> for RunError {
    fn from(e: crate::report::figures::FigureError) -> Self {
        RunError::Library(e.into())
    }
}

/// An error about the setting `flag` (the command line's flag, e.g. `--points`) of value
/// `value`.
pub(crate) fn setting_error(flag: &str, value: &str, message: impl Into<String>) -> RunError {
    RunError::Input(InputError {
        file: crate::io::SETTINGS_ORIGIN.into(),
        line: None,
        column: Some(flag.to_string()),
        value: Some(value.to_string()),
        message: message.into(),
    })
}

/// The error of a control of a fit's parameters (`--fix`, `--init`, `--bounds`) that cannot
/// be used, on its flag.
pub(crate) fn control_error(e: crate::fit::controls::ControlError) -> RunError {
    setting_error(e.flag, &e.value, e.reason)
}
