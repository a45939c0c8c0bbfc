//! Progress of long computations, reported to whoever wants it: the library calls a
//! [`Progress`] sink, a user interface (the command line's progress bar) renders it. Nothing
//! in the library draws or prints.

use std::fmt;
use std::sync::Arc;

/// What a long computation reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProgressEvent<'a> {
    /// A task starts: its label and how many units of work it may take at most.
    Start {
        /// What runs, e.g. `klaw-c [all]`.
        label: &'a str,
        /// Units of work at most (steps, rows, scenes).
        total: u64,
        /// How often (in units) convergence is checked, when that applies; 0 otherwise.
        check_every: u64,
    },
    /// Units of work done so far.
    Position(u64),
    /// The task ended (converged, stopped or failed).
    Finish,
}

/// A sink for [`ProgressEvent`]s, cheap to clone and shareable across threads.
#[derive(Clone)]
pub struct Progress(Arc<dyn Fn(ProgressEvent<'_>) + Send + Sync>);

impl Progress {
    /// A sink calling `f` with every event.
    pub fn new(f: impl Fn(ProgressEvent<'_>) + Send + Sync + 'static) -> Self {
        Progress(Arc::new(f))
    }

    /// Reports one event.
    pub fn report(&self, e: ProgressEvent<'_>) {
        (self.0)(e)
    }
}

impl fmt::Debug for Progress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Progress(..)")
    }
}
