//! Streaming a CSV table through a per-row computation in bounded memory: rows are read
//! [`CHUNK_ROWS`] at a time; each chunk is checked, computed and formatted in parallel (rayon
//! tasks of [`TASK_ROWS`] rows writing straight into byte buffers) while the previous chunk's
//! bytes are written and the next chunk is read. Reading is parallel too: one thread reads
//! the raw bytes and cuts them into ranges at record boundaries (a scan that follows the CSV
//! quoting, so a quoted cell may hold newlines), and rayon tasks parse the ranges, each with
//! its own `csv` reader, alongside the tasks of the chunk being computed; the rows keep the
//! line numbers, checks and messages of one reader reading the whole input. Memory stays at
//! about two chunks of input records and raw bytes and one of output bytes, whatever the
//! number of rows; the output is in input order.
//!
//! What a row means is a [`RowPlan`]'s business: `fitbead forward`'s scenes
//! ([`super::forward::ForwardPlan`]) and `fitbead k`'s measurements
//! ([`super::kstream::KPlan`]) are two. The engine gives every plan the same error rules as
//! reading the whole table first: a malformed row anywhere in the input (or an input with no
//! rows) is reported before any bad value, then the first bad row in input order; a failed
//! write is reported only once the whole input proved good, writing stopping at the failure.
//! Nothing is written before the first chunk has been checked (the header goes out with its
//! rows), so an input whose first [`CHUNK_ROWS`] rows hold the bad one leaves even a stream
//! such as standard output empty; a bad row further on follows the rows before it there (a
//! file given as `--output` is written atomically and stays untouched).
//! It reports its progress in input bytes to a [`Progress`] sink and stops between tasks when
//! the caller's stop flag is raised.

use super::ranges::Ranges;
use super::scenes::{line_of, Row, TableReader};
use super::InputError;
use crate::progress::{Progress, ProgressEvent};
use rayon::prelude::*;
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Rows read, checked, computed and formatted per step.
pub const CHUNK_ROWS: usize = 32 * 1024;
/// Rows per parallel task within a chunk.
pub const TASK_ROWS: usize = 512;

/// What a stream does with each row: check its cells ([`prepare`](RowPlan::prepare)),
/// compute and format it ([`write`](RowPlan::write)) — both in parallel, one pass per task —
/// then, in input order, keep or check what the row's [`Note`](RowPlan::Note) says against
/// the rows before it ([`record`](RowPlan::record): rules that span the file, such as a
/// series that may not mix ξ values, and what is kept across it).
pub trait RowPlan: Sync {
    /// A row whose cells passed their checks, ready to compute.
    type Ready: Send;
    /// What the plan keeps across the rows, in input order (a ledger per series, points for
    /// a plot); `()` when nothing.
    type Ledger: Send;
    /// What [`write`](RowPlan::write) hands to [`record`](RowPlan::record); `()` when nothing.
    type Note: Send;
    /// Scratch space of one task, handed to each [`write`](RowPlan::write) of its rows (a
    /// cache of what consecutive rows share); `()` when none.
    type Scratch: Default + Send;

    /// Appends the output's header record.
    fn header(&self, out: &mut Vec<u8>);

    /// Checks the cells of one row, or reports its first bad value; `scratch` is the task's,
    /// as [`write`](RowPlan::write) gets it.
    fn prepare(
        &self,
        row: &Row<'_>,
        scratch: &mut Self::Scratch,
    ) -> Result<Self::Ready, InputError>;

    /// Computes one row and appends its output record to `out`.
    fn write(
        &self,
        row: &Row<'_>,
        ready: Self::Ready,
        scratch: &mut Self::Scratch,
        out: &mut Vec<u8>,
    ) -> Self::Note;

    /// Checks a written row against what `ledger` kept of the rows before it, and keeps what
    /// its note says; called in input order, for every row before the first one that failed
    /// [`prepare`](RowPlan::prepare). An error here is the row's error (the row's output is
    /// then not written).
    fn record(
        &self,
        ledger: &mut Self::Ledger,
        row: &Row<'_>,
        note: Self::Note,
    ) -> Result<(), InputError> {
        let _ = (ledger, row, note);
        Ok(())
    }
}

/// How to run a stream.
#[derive(Debug, Clone)]
pub struct StreamOptions {
    /// Rows per chunk (at least 1).
    pub chunk_rows: usize,
    /// Rows per parallel task (at least 1).
    pub task_rows: usize,
    /// Raised by the caller (e.g. on Ctrl-C): the stream stops before its next task and
    /// returns [`StreamError::Stopped`].
    pub stop: Option<Arc<AtomicBool>>,
    /// Where progress goes: a `Start` whose total is `input_bytes` (0 when unknown), the
    /// input bytes consumed after each chunk, and `Finish`.
    pub progress: Option<Progress>,
    /// The label of the progress events.
    pub label: String,
    /// Size of the input in bytes, when known (for progress only).
    pub input_bytes: Option<u64>,
}

impl Default for StreamOptions {
    /// [`CHUNK_ROWS`], [`TASK_ROWS`], no stop flag, no progress.
    fn default() -> Self {
        StreamOptions {
            chunk_rows: CHUNK_ROWS,
            task_rows: TASK_ROWS,
            stop: None,
            progress: None,
            label: String::new(),
            input_bytes: None,
        }
    }
}

/// Why a stream ended early.
#[derive(Debug)]
pub enum StreamError {
    /// Bad input (located): nothing more was written after it was found.
    Input(InputError),
    /// Writing the output failed (reported once the whole input proved good).
    Write(std::io::Error),
    /// The stop flag was raised.
    Stopped,
}

impl From<InputError> for StreamError {
    fn from(e: InputError) -> Self {
        StreamError::Input(e)
    }
}

/// What a finished stream returns: the plan's ledger and the number of rows.
#[derive(Debug)]
pub struct Streamed<L> {
    /// What the plan kept across the rows.
    pub ledger: L,
    /// Data rows read.
    pub rows: u64,
}

/// The source and column names every [`Row`] of the stream refers to.
struct Context {
    source: String,
    headers: Vec<String>,
}

impl Context {
    fn row<'a>(&'a self, rec: &'a csv::StringRecord) -> Row<'a> {
        Row {
            source: &self.source,
            headers: &self.headers,
            rec,
            line: line_of(rec),
        }
    }
}

/// Reports `Finish` when dropped, whichever way the stream ends.
struct Finish<'a>(Option<&'a Progress>);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        if let Some(p) = self.0 {
            p.report(ProgressEvent::Finish);
        }
    }
}

/// Streams the rows of `reader` through the plan that `make` builds from its header, writing
/// the plan's header and then every row's record to `out` in input order; `ledger` starts
/// what the plan keeps across rows. See the module docs for the order in which errors are
/// reported.
pub fn stream<R, P, F>(
    reader: TableReader<R>,
    make: F,
    ledger: P::Ledger,
    out: &mut (dyn Write + Send),
    opts: &StreamOptions,
) -> Result<Streamed<P::Ledger>, StreamError>
where
    R: Read + Send,
    P: RowPlan,
    F: FnOnce(&TableReader<R>) -> Result<P, InputError>,
{
    let mut ledger = ledger;
    let plan = match make(&reader) {
        Ok(p) => p,
        Err(e) => return Err(first_error(&mut Source::new(reader), e, opts)),
    };
    let chunk_rows = opts.chunk_rows.max(1);
    let ctx = Context {
        source: reader.source().to_string(),
        headers: reader.headers().to_vec(),
    };
    let mut reader = Source::new(reader);
    let _finish = Finish(opts.progress.as_ref());
    if let Some(p) = &opts.progress {
        p.report(ProgressEvent::Start {
            label: &opts.label,
            total: opts.input_bytes.unwrap_or(0),
            check_every: 0,
        });
    }
    let mut cur = Vec::new();
    let mut next = Vec::new();
    let mut n_cur = reader.read_chunk(&mut cur, chunk_rows)?;
    if n_cur == 0 {
        return Err(reader.no_rows().into());
    }
    // The header goes out with the first chunk's rows, once they have all been checked: an
    // input whose first chunk holds a bad row writes nothing, even to a stream.
    let mut header = Vec::new();
    plan.header(&mut header);
    let mut header = Some(header);
    let mut pending: Vec<Vec<u8>> = Vec::new();
    // Output buffers come back here once written, and serve the chunk after next; the notes'
    // vectors come back once recorded, and serve the next chunk.
    let mut spare: Vec<Vec<u8>> = Vec::new();
    let mut note_bufs: Vec<Vec<P::Note>> = Vec::new();
    let mut failed = None;
    let mut rows = 0u64;
    // Output bytes per row to reserve (grown to what the rows so far needed).
    let mut row_bytes = 192;
    loop {
        if stopped(opts) {
            return Err(StreamError::Stopped);
        }
        let bufs = std::mem::take(&mut spare);
        let (read, done) = rayon::join(
            || {
                write_parts(out, &pending, &mut failed);
                reader.read_chunk(&mut next, chunk_rows)
            },
            || {
                chunk(
                    &plan,
                    &ctx,
                    &cur[..n_cur],
                    (bufs, &mut note_bufs),
                    row_bytes,
                    &mut ledger,
                    opts,
                )
            },
        );
        let n_next = read?;
        let mut parts = match done {
            Ok(parts) => parts,
            Err(StreamError::Input(e)) => return Err(first_error(&mut reader, e, opts)),
            Err(e) => return Err(e),
        };
        let bytes: usize = parts.iter().map(Vec::len).sum();
        row_bytes = row_bytes.max(bytes.div_ceil(n_cur) + 16);
        if let Some(h) = header.take() {
            parts.insert(0, h);
        }
        spare = std::mem::replace(&mut pending, parts);
        rows += n_cur as u64;
        if let Some(p) = &opts.progress {
            p.report(ProgressEvent::Position(reader.bytes_read()));
        }
        if n_next == 0 {
            break;
        }
        std::mem::swap(&mut cur, &mut next);
        n_cur = n_next;
    }
    write_parts(out, &pending, &mut failed);
    match failed {
        Some(e) => Err(StreamError::Write(e)),
        None => Ok(Streamed { ledger, rows }),
    }
}

fn stopped(opts: &StreamOptions) -> bool {
    opts.stop
        .as_ref()
        .is_some_and(|s| s.load(Ordering::Relaxed))
}

/// The error to report when a check failed with `e`: a malformed row anywhere in the input,
/// or an input without rows, is reported first (as when the whole table was read before any
/// check); a stop raised meanwhile ends the stream instead.
fn first_error<R: Read>(
    reader: &mut Source<R>,
    e: InputError,
    opts: &StreamOptions,
) -> StreamError {
    if stopped(opts) {
        return StreamError::Stopped;
    }
    StreamError::Input(reader.drain().unwrap_or(e))
}

/// Where the rows come from: ranges parsed in parallel, or (for a reader that has read rows
/// already) the reader itself.
enum Source<R: Read> {
    Ranges(Ranges<R>),
    Serial(TableReader<R>),
}

impl<R: Read> Source<R> {
    fn new(reader: TableReader<R>) -> Self {
        if reader.hands_over() {
            Source::Ranges(reader.into_ranges())
        } else {
            Source::Serial(reader)
        }
    }

    fn read_chunk(
        &mut self,
        recs: &mut Vec<csv::StringRecord>,
        max: usize,
    ) -> Result<usize, InputError> {
        match self {
            Source::Ranges(r) => r.read_chunk(recs, max),
            Source::Serial(r) => r.read_chunk(recs, max),
        }
    }

    fn drain(&mut self) -> Option<InputError> {
        match self {
            Source::Ranges(r) => r.drain(),
            Source::Serial(r) => r.drain(),
        }
    }

    fn no_rows(&self) -> InputError {
        match self {
            Source::Ranges(r) => r.no_rows(),
            Source::Serial(r) => r.no_rows(),
        }
    }

    fn bytes_read(&self) -> u64 {
        match self {
            Source::Ranges(r) => r.bytes_read(),
            Source::Serial(r) => r.bytes_read(),
        }
    }
}

fn write_parts(out: &mut dyn Write, parts: &[Vec<u8>], failed: &mut Option<std::io::Error>) {
    for p in parts {
        if failed.is_some() {
            return;
        }
        if let Err(e) = out.write_all(p) {
            *failed = Some(e);
        }
    }
}

/// One task's output: its bytes, its rows' notes, and the error of the row it stopped at.
type Part<N> = (Vec<u8>, Vec<N>, Option<StreamError>);

/// One chunk of rows: their output bytes in order (one buffer per task, taken from `bufs`
/// where there is one, with room for `row_bytes` per row), the notes recorded (their
/// vectors taken from and returned to `note_bufs`), or the first bad row's error.
fn chunk<P: RowPlan>(
    plan: &P,
    ctx: &Context,
    recs: &[csv::StringRecord],
    (mut bufs, note_bufs): (Vec<Vec<u8>>, &mut Vec<Vec<P::Note>>),
    row_bytes: usize,
    ledger: &mut P::Ledger,
    opts: &StreamOptions,
) -> Result<Vec<Vec<u8>>, StreamError> {
    let task = opts.task_rows.max(1);
    let tasks = recs.len().div_ceil(task);
    bufs.resize_with(tasks, Vec::new);
    note_bufs.resize_with(tasks.max(note_bufs.len()), Vec::new);
    let note_vecs: Vec<Vec<P::Note>> = note_bufs.drain(..tasks).collect();
    let parts: Vec<Part<P::Note>> = recs
        .par_chunks(task)
        .zip(bufs.into_par_iter().zip(note_vecs))
        .map(|(rs, (mut buf, mut notes))| {
            buf.clear();
            buf.reserve(rs.len() * row_bytes);
            notes.clear();
            notes.reserve(rs.len());
            if stopped(opts) {
                return (buf, notes, Some(StreamError::Stopped));
            }
            let mut scratch = P::Scratch::default();
            for rec in rs {
                let row = ctx.row(rec);
                match plan.prepare(&row, &mut scratch) {
                    Ok(r) => notes.push(plan.write(&row, r, &mut scratch, &mut buf)),
                    Err(e) => return (buf, notes, Some(StreamError::Input(e))),
                }
            }
            (buf, notes, None)
        })
        .collect();
    let mut out = Vec::with_capacity(parts.len());
    for ((buf, mut notes, err), rs) in parts.into_iter().zip(recs.chunks(task)) {
        for (n, rec) in notes.drain(..).zip(rs) {
            plan.record(ledger, &ctx.row(rec), n)?;
        }
        note_bufs.push(notes);
        if let Some(e) = err {
            return Err(e);
        }
        out.push(buf);
    }
    Ok(out)
}
