//! Progress of long computations, reported to whoever wants it: the library calls a
//! [`Progress`] sink, a user interface (the command line's progress bar) renders it. Nothing
//! in the library draws or prints.
//!
//! Stopping works the other way: a caller passes a stop flag (`AtomicBool`, usually in an
//! `Arc`) to the long computations (least-squares iterations and profiles through
//! `LsqOptions::stop`, the sampler through `McmcOptions::stop`, the work-precision bench, md
//! runs), which poll it and end early; a computation with nothing useful to return then says
//! so in its error (`RunError::Interrupted`, `Termination::Interrupted`, …). The library never installs a signal handler: the command line raises the
//! flag on SIGINT, SIGTERM and SIGHUP.

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
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

/// A count of work units shared by the parts of one task (clones share the count), each
/// addition reported to a [`Progress`] sink as the task's [`ProgressEvent::Position`]. The
/// caller reports the task's `Start` and `Finish`; the computations it hands a tally to (e.g.
/// the least-squares runs of a fit, through `LsqOptions::progress`) only add to it.
#[derive(Clone, Debug)]
pub struct Tally {
    sink: Progress,
    done: Arc<AtomicU64>,
}

impl Tally {
    /// A count from 0, reported to `sink`.
    pub fn new(sink: Progress) -> Self {
        Tally {
            sink,
            done: Arc::new(AtomicU64::new(0)),
        }
    }

    /// Adds `n` units and reports the total.
    pub fn add(&self, n: u64) {
        let total = self.done.fetch_add(n, Ordering::Relaxed) + n;
        self.sink.report(ProgressEvent::Position(total));
    }

    /// The units counted so far.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }
}

/// A computation stopped early because its caller raised the stop flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Interrupted;

impl fmt::Display for Interrupted {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Interrupted {}
