//! Streaming a CSV table through a per-row computation in bounded memory, on every thread,
//! with no pause between reading, computing and writing.
//!
//! The engine is a pipeline of rayon tasks. One reading task at a time takes the next block
//! of raw input and cuts it into ranges at record boundaries (a scan that follows the CSV
//! quoting, so a quoted cell may hold newlines); each range becomes a task that parses it
//! with a `csv` reader reset to its start, then checks, computes and formats its rows into
//! its own byte buffer; whichever task finishes the range that is next in input order takes
//! the finished ranges in order, keeps what the plan keeps across rows
//! ([`RowPlan::record`]) and writes their bytes. Ranges of many blocks are in flight at once:
//! while the last ranges of a block are computed, the next block's are, and the bytes before
//! them are written, so no thread waits for the slowest range of a step. A range holds about
//! [`TASK_ROWS`] rows (from the mean bytes per line so far), a block half as many ranges as
//! may be in flight: the reading task reads no further block once four ranges per thread (8
//! to 128) are read and not yet written, and is started again when half of them have been
//! written, so at most one and a half times that many are in flight, whatever the number of
//! rows (and at most two chunks of output are held for the rule below). The
//! rows keep the line numbers, checks and messages of one reader reading the whole input, and
//! the output is in input order, byte for byte the same at any number of threads.
//!
//! What a row means is a [`RowPlan`]'s business: `fitbead forward`'s scenes
//! (`pipeline::forward::plan::ForwardPlan`) and `fitbead k`'s measurements
//! (`pipeline::k::KPlan`) are two. The engine gives every plan the same error rules as
//! reading the whole table first: a malformed row anywhere in the input (or an input with no
//! rows) is reported before any bad value, then the first bad row in input order; a failed
//! write is reported only once the whole input proved good, writing stopping at the failure.
//! What is written before an error depends on the chunk size
//! ([`StreamOptions::chunk_rows`], [`CHUNK_ROWS`]) alone, not on the threads: the rows are
//! written a chunk at a time, a chunk once its rows and those of the chunk after it have been
//! read and its own rows checked (the header goes out with the first chunk). A bad value in
//! chunk `j` leaves chunks `0..j` written, a malformed row in chunk `j` chunks `0..j-1`, so
//! an input whose first [`CHUNK_ROWS`] rows hold the bad one leaves even a stream such as
//! standard output empty; a file given as `--output` is written atomically and stays
//! untouched. Where a failed stream's output is discarded anyway
//! ([`StreamOptions::atomic_output`], as for such a file), the rule has nothing to decide: rows
//! are written as soon as they are in input order.
//! It reports its progress in input bytes to a [`Progress`] sink and stops between tasks when
//! the caller's stop flag is raised.

use super::ranges::{parse, Failure, Next, Ranges, Span, MAX_RANGE, MIN_RANGE};
use super::scenes::{line_of, Row, TableReader};
use super::InputError;
use crate::progress::{Progress, ProgressEvent};
use std::collections::VecDeque;
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// Rows per chunk: the unit of what is written before an error (see the module docs).
pub const CHUNK_ROWS: usize = 32 * 1024;
/// Rows per parallel task: the input is cut into ranges of about this many rows.
pub const TASK_ROWS: usize = 512;
/// Ranges read and not yet written, per thread, and the bounds of their number.
const RANGES_PER_THREAD: usize = 4;
const MIN_IN_FLIGHT: usize = 8;
const MAX_IN_FLIGHT: usize = 128;
/// Input bytes between two progress reports.
const PROGRESS_BYTES: u64 = 1 << 20;

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
    /// Rows per chunk (at least 1): the unit of what is written before an error (module
    /// docs).
    pub chunk_rows: usize,
    /// Rows per parallel task (at least 1): the input is cut into ranges of about this many
    /// rows (from the mean bytes per line, between 4 KiB and 1 MiB), each parsed, checked,
    /// computed and formatted by one task, which looks at the stop flag before each row.
    pub task_rows: usize,
    /// Raised by the caller (e.g. on Ctrl-C): the stream stops before its next task and
    /// returns `StreamError::Stopped` (the door [`TableCommand::run`](crate::pipeline::TableCommand::run):
    /// [`RunError::Interrupted`](crate::pipeline::RunError::Interrupted)).
    pub stop: Option<Arc<AtomicBool>>,
    /// Where progress goes: a `Start` whose total is `input_bytes` (0 when unknown), the
    /// input bytes whose rows have been taken in order (about every MiB), and `Finish`.
    pub progress: Option<Progress>,
    /// The label of the progress events.
    pub label: String,
    /// Size of the input in bytes, when known (for progress only).
    pub input_bytes: Option<u64>,
    /// The output is seen only if the stream succeeds (the caller discards it otherwise, as
    /// a temporary file renamed over its target on success is): rows are then written as
    /// soon as they are in input order, none held back by the chunk rule, which only decides
    /// what a failed stream leaves written.
    pub atomic_output: bool,
}

impl Default for StreamOptions {
    /// 32,768 rows per chunk, 512 rows per task, no stop flag, no progress, an output seen as written.
    fn default() -> Self {
        StreamOptions {
            chunk_rows: CHUNK_ROWS,
            task_rows: TASK_ROWS,
            stop: None,
            progress: None,
            label: String::new(),
            input_bytes: None,
            atomic_output: false,
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

/// What a finished stream returns: the plan's ledger.
#[derive(Debug)]
pub struct Streamed<L> {
    /// What the plan kept across the rows.
    pub ledger: L,
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
/// reported and what is written before them.
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
    let plan = match make(&reader) {
        Ok(p) => p,
        Err(e) => return Err(first_error(Source::new(reader), e, opts)),
    };
    let ctx = Context {
        source: reader.source().to_string(),
        headers: reader.headers().to_vec(),
    };
    let source = Source::new(reader);
    let _finish = Finish(opts.progress.as_ref());
    if let Some(p) = &opts.progress {
        p.report(ProgressEvent::Start {
            label: &opts.label,
            total: opts.input_bytes.unwrap_or(0),
            check_every: 0,
        });
    }
    let mut header = Vec::new();
    plan.header(&mut header);
    let threads = rayon::current_num_threads().max(1);
    let records = match &source {
        Source::Ranges(r) => r.records_before(),
        Source::Serial(_) => 0,
    };
    let pipe = Pipe {
        plan: &plan,
        ctx: &ctx,
        opts,
        width: ctx.headers.len(),
        chunk: opts.chunk_rows.max(1) as u64,
        task: opts.task_rows.max(1),
        limit: (threads * RANGES_PER_THREAD).clamp(MIN_IN_FLIGHT, MAX_IN_FLIGHT),
        reader: Mutex::new(Reader {
            source,
            seq: 0,
            serial_rows: 0,
        }),
        queue: Mutex::new(Queue {
            items: VecDeque::new(),
            next: 0,
            writing: false,
            reading: true,
            in_flight: 0,
            read_all: false,
            ended: false,
        }),
        writer: Mutex::new(Writer {
            out,
            ledger,
            header: Some(header),
            parsed: 0,
            records,
            held: VecDeque::new(),
            written: 0,
            failed: None,
            bad: None,
            outcome: None,
            reported: 0,
        }),
        pools: Mutex::new(Pools::default()),
        halt: AtomicBool::new(false),
        drain: AtomicBool::new(false),
    };
    rayon::scope_fifo(|s| pipe.read(s));
    let w = pipe.writer.into_inner().unwrap_or_else(|e| e.into_inner());
    match w.outcome {
        Some(Ok(())) => match w.failed {
            Some(e) => Err(StreamError::Write(e)),
            None => Ok(Streamed { ledger: w.ledger }),
        },
        Some(Err(e)) => Err(e),
        None => Err(StreamError::Stopped),
    }
}

fn stopped(opts: &StreamOptions) -> bool {
    opts.stop
        .as_ref()
        .is_some_and(|s| s.load(Ordering::Relaxed))
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// The error to report when the plan could not be made (error `e`): a malformed row anywhere
/// in the input, or an input without rows, is reported first (as when the whole table was
/// read before any check); a stop raised meanwhile ends the stream instead.
fn first_error<R: Read>(mut reader: Source<R>, e: InputError, opts: &StreamOptions) -> StreamError {
    if stopped(opts) {
        return StreamError::Stopped;
    }
    let found = match &mut reader {
        Source::Ranges(r) => r.drain(),
        Source::Serial(r) => r.drain(),
    };
    StreamError::Input(found.unwrap_or(e))
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
}

/// The reading side of a stream: its source and the sequence number of its next item.
struct Reader<R: Read> {
    source: Source<R>,
    seq: u64,
    /// Rows read from a serial source (whose batches end at chunk boundaries).
    serial_rows: u64,
}

/// What a task gets to do: a range of a block to parse, or rows a serial source read (with
/// the input's offset after them).
enum Work {
    Range(Arc<Vec<u8>>, Span),
    Rows(Vec<csv::StringRecord>, u64),
}

/// What the writer takes, in input order.
enum Item<N> {
    /// The rows of one task.
    Rows(Box<Done<N>>),
    /// The end of the input, with the error it ends with.
    End(Option<InputError>),
    /// The stop flag was raised before the next block was read.
    Stopped,
}

/// The rows of one task: parsed up to `failure` (a malformed row), computed up to `error`.
struct Done<N> {
    recs: Vec<csv::StringRecord>,
    /// Records the range's reader read (blank lines included).
    records: u64,
    failure: Option<Failure>,
    /// The rows' output, each row's end in it, and their notes (rows `..notes.len()`).
    out: Vec<u8>,
    ends: Vec<usize>,
    notes: Vec<N>,
    /// The bad value of the row after the last note, or `Stopped`.
    error: Option<StreamError>,
    /// Input offset after the task's rows (for progress).
    end_byte: u64,
}

/// Buffers handed back by the writer for later tasks.
struct Pools<N> {
    recs: Vec<Vec<csv::StringRecord>>,
    bufs: Vec<Vec<u8>>,
    ends: Vec<Vec<usize>>,
    notes: Vec<Vec<N>>,
    blocks: Vec<Vec<u8>>,
}

impl<N> Default for Pools<N> {
    fn default() -> Self {
        Pools {
            recs: Vec::new(),
            bufs: Vec::new(),
            ends: Vec::new(),
            notes: Vec::new(),
            blocks: Vec::new(),
        }
    }
}

/// The items finished and not yet written, and who is reading and writing.
struct Queue<N> {
    /// Items from sequence number `next` on, as they arrive.
    items: VecDeque<Option<Item<N>>>,
    next: u64,
    /// A task is taking the items in order.
    writing: bool,
    /// A reading task is running or about to.
    reading: bool,
    /// Tasks read and not yet taken by the writer.
    in_flight: usize,
    /// The reader has handed out its last item.
    read_all: bool,
    /// The writer has reached the stream's end: later items are dropped.
    ended: bool,
}

/// The output side: the plan's ledger, the rows checked and not yet written, and the outcome.
struct Writer<'a, L> {
    out: &'a mut (dyn Write + Send),
    ledger: L,
    /// The plan's header, until the first rows go out.
    header: Option<Vec<u8>>,
    /// Rows parsed, in input order, up to the first malformed one.
    parsed: u64,
    /// Records before the next task's range (the header's and blank lines included).
    records: u64,
    /// The output of rows checked and not yet written, in order, from row `written` on.
    held: VecDeque<Held>,
    written: u64,
    /// The first failed write (nothing is written after it).
    failed: Option<std::io::Error>,
    /// The first bad value (its row, 0-based, and error): after it, the ranges are only
    /// parsed, to find a malformed row that is reported instead.
    bad: Option<(u64, InputError)>,
    outcome: Option<Result<(), StreamError>>,
    /// Input offset last reported as progress.
    reported: u64,
}

/// A task's output, held until its rows may be written.
struct Held {
    bytes: Vec<u8>,
    ends: Vec<usize>,
    /// The first row's number.
    first: u64,
}

struct Pipe<'a, R: Read, P: RowPlan> {
    plan: &'a P,
    ctx: &'a Context,
    opts: &'a StreamOptions,
    width: usize,
    chunk: u64,
    task: usize,
    /// Tasks read and not yet written, at most (about).
    limit: usize,
    reader: Mutex<Reader<R>>,
    queue: Mutex<Queue<P::Note>>,
    writer: Mutex<Writer<'a, P::Ledger>>,
    pools: Mutex<Pools<P::Note>>,
    /// The stream has ended: tasks still queued do nothing.
    halt: AtomicBool,
    /// A bad value was found: later tasks only parse.
    drain: AtomicBool,
}

impl<R: Read + Send, P: RowPlan> Pipe<'_, R, P> {
    /// The reading task: reads blocks and starts their tasks until the tasks in flight reach
    /// the limit, the input ends or the stream stops.
    fn read<'s>(&'s self, s: &rayon::ScopeFifo<'s>) {
        let mut guard = lock(&self.reader);
        let r = &mut *guard;
        loop {
            let mut works = Vec::new();
            let end = if self.halt.load(Ordering::Relaxed) {
                None
            } else if stopped(self.opts) {
                Some(Item::Stopped)
            } else {
                let serial_rows = r.serial_rows;
                match &mut r.source {
                    Source::Ranges(g) => {
                        let range = usize::try_from(g.bytes_per_row())
                            .unwrap_or(MAX_RANGE)
                            .saturating_mul(self.task)
                            .clamp(MIN_RANGE, MAX_RANGE);
                        let block = range.saturating_mul(self.limit / 2);
                        let bytes = lock(&self.pools).blocks.pop().unwrap_or_default();
                        match g.next_block(block, range, bytes) {
                            Next::Block(b, spans) => {
                                let b = Arc::new(b);
                                works
                                    .extend(spans.into_iter().map(|sp| Work::Range(b.clone(), sp)));
                                None
                            }
                            Next::End(e) => Some(Item::End(e)),
                        }
                    }
                    Source::Serial(t) => {
                        // Batches end at chunk boundaries, so that a malformed row's chunk is
                        // the chunk of the rows before its batch.
                        let left = self.chunk - serial_rows % self.chunk;
                        let batch = left.min(self.task as u64) as usize;
                        let mut recs = lock(&self.pools).recs.pop().unwrap_or_default();
                        match t.read_chunk(&mut recs, batch) {
                            Ok(0) => Some(Item::End(None)),
                            Ok(n) => {
                                recs.truncate(n);
                                r.serial_rows += n as u64;
                                works.push(Work::Rows(recs, t.bytes_read()));
                                None
                            }
                            Err(e) => Some(Item::End(Some(e))),
                        }
                    }
                }
            };
            let first = r.seq;
            r.seq += works.len() as u64;
            let go_on = {
                let mut q = lock(&self.queue);
                q.in_flight += works.len();
                if end.is_some() {
                    q.read_all = true;
                }
                let go_on = end.is_none()
                    && !works.is_empty()
                    && q.in_flight < self.limit
                    && !self.halt.load(Ordering::Relaxed);
                if !go_on {
                    q.reading = false;
                }
                go_on
            };
            for (seq, w) in (first..).zip(works) {
                s.spawn_fifo(move |s| {
                    let item = self.work(w);
                    self.deliver(seq, item, s);
                });
            }
            if let Some(item) = end {
                let seq = r.seq;
                r.seq += 1;
                self.deliver(seq, item, s);
            }
            if !go_on {
                return;
            }
        }
    }

    /// One task: parses its range (when it is one) and checks, computes and formats its rows
    /// (unless a bad value was found before, or the stream ended).
    fn work(&self, w: Work) -> Item<P::Note> {
        let (recs, records, failure, end_byte) = match w {
            Work::Range(block, span) => {
                let spare = lock(&self.pools).recs.pop().unwrap_or_default();
                let p = if self.halt.load(Ordering::Relaxed) {
                    super::ranges::Parsed {
                        rows: spare,
                        records: 0,
                        failure: None,
                    }
                } else {
                    parse(&self.ctx.source, &block, span, self.width, spare)
                };
                let end_byte = span.byte + (span.end - span.start) as u64;
                if let Some(b) = Arc::into_inner(block) {
                    lock(&self.pools).blocks.push(b);
                }
                (p.rows, p.records, p.failure, end_byte)
            }
            Work::Rows(recs, end_byte) => (recs, 0, None, end_byte),
        };
        let (out, ends, notes) = {
            let mut pools = lock(&self.pools);
            (
                pools.bufs.pop().unwrap_or_default(),
                pools.ends.pop().unwrap_or_default(),
                pools.notes.pop().unwrap_or_default(),
            )
        };
        let mut d = Done {
            recs,
            records,
            failure,
            out,
            ends,
            notes,
            error: None,
            end_byte,
        };
        if !self.drain.load(Ordering::Relaxed) && !self.halt.load(Ordering::Relaxed) {
            self.compute(&mut d);
        }
        Item::Rows(Box::new(d))
    }

    fn compute(&self, d: &mut Done<P::Note>) {
        let mut scratch = P::Scratch::default();
        // The stop flag is looked at before every row (one relaxed load): a row of the
        // contact or md model can take milliseconds, and a task's rows seconds.
        for rec in d.recs.iter() {
            if stopped(self.opts) {
                d.error = Some(StreamError::Stopped);
                return;
            }
            let row = self.ctx.row(rec);
            match self.plan.prepare(&row, &mut scratch) {
                Ok(r) => {
                    d.notes
                        .push(self.plan.write(&row, r, &mut scratch, &mut d.out));
                    d.ends.push(d.out.len());
                }
                Err(e) => {
                    d.error = Some(StreamError::Input(e));
                    return;
                }
            }
        }
    }

    /// Hands item `seq` to the writer: the task that delivers the item the writer waits for
    /// writes it and every item after it that has arrived (another task delivering
    /// meanwhile only leaves its item), then starts the reading task again when half the
    /// tasks in flight have been written.
    fn deliver<'s>(&'s self, seq: u64, item: Item<P::Note>, s: &rayon::ScopeFifo<'s>) {
        let mut q = lock(&self.queue);
        if q.ended {
            drop(q);
            self.recycle(item);
            return;
        }
        let at = usize::try_from(seq - q.next).unwrap_or(usize::MAX);
        if q.items.len() <= at {
            q.items.resize_with(at + 1, || None);
        }
        q.items[at] = Some(item);
        if q.writing {
            return;
        }
        q.writing = true;
        while let Some(Some(_)) = q.items.front() {
            let Some(Some(item)) = q.items.pop_front() else {
                break;
            };
            q.next += 1;
            let rows = matches!(item, Item::Rows(_));
            drop(q);
            let go_on = self.write(item);
            q = lock(&self.queue);
            if rows {
                q.in_flight -= 1;
            }
            if !go_on {
                q.ended = true;
                q.writing = false;
                self.halt.store(true, Ordering::Relaxed);
                let rest: Vec<Item<P::Note>> = q.items.drain(..).flatten().collect();
                drop(q);
                for i in rest {
                    self.recycle(i);
                }
                return;
            }
            if !q.reading && !q.read_all && q.in_flight <= self.limit / 2 {
                q.reading = true;
                s.spawn_fifo(move |s| self.read(s));
            }
        }
        q.writing = false;
    }

    /// Takes the next item in input order; false once the stream has ended.
    fn write(&self, item: Item<P::Note>) -> bool {
        let mut w = lock(&self.writer);
        let w = &mut *w;
        let mut d = match item {
            Item::Stopped => {
                w.outcome = Some(Err(StreamError::Stopped));
                return false;
            }
            Item::End(Some(e)) => {
                self.malformed(w, e);
                return false;
            }
            Item::End(None) => {
                let outcome = if let Some((v, e)) = w.bad.take() {
                    self.release(w, v / self.chunk * self.chunk);
                    Err(StreamError::Input(e))
                } else if w.parsed == 0 {
                    Err(StreamError::Input(InputError::file(
                        &self.ctx.source,
                        "no data rows after the header",
                    )))
                } else {
                    self.release(w, w.parsed);
                    Ok(())
                };
                w.outcome = Some(outcome);
                return false;
            }
            Item::Rows(d) => d,
        };
        if w.bad.is_none() {
            let mut ok = 0;
            let mut err = None;
            for (note, rec) in d.notes.drain(..).zip(&d.recs) {
                if let Err(e) = self.plan.record(&mut w.ledger, &self.ctx.row(rec), note) {
                    err = Some(StreamError::Input(e));
                    break;
                }
                ok += 1;
            }
            let err = err.or(d.error.take());
            if ok > 0 {
                d.ends.truncate(ok);
                w.held.push_back(Held {
                    bytes: std::mem::take(&mut d.out),
                    ends: std::mem::take(&mut d.ends),
                    first: w.parsed,
                });
            }
            match err {
                Some(StreamError::Input(e)) => {
                    w.bad = Some((w.parsed + ok as u64, e));
                    self.drain.store(true, Ordering::Relaxed);
                }
                Some(e) => {
                    w.outcome = Some(Err(e));
                    self.recycle(Item::Rows(d));
                    return false;
                }
                None => {}
            }
        }
        w.parsed += d.recs.len() as u64;
        if let Some(f) = d.failure.take() {
            let e = f.into_error(&self.ctx.source, self.width, w.records);
            self.malformed(w, e);
            self.recycle(Item::Rows(d));
            return false;
        }
        w.records += d.records;
        if w.bad.is_none() {
            // A chunk goes out once the chunk after it has been read whole (an output seen
            // only on success takes every row as it comes).
            let upto = if self.opts.atomic_output {
                w.parsed
            } else {
                (w.parsed / self.chunk).saturating_sub(1) * self.chunk
            };
            self.release(w, upto);
        }
        if let Some(p) = &self.opts.progress {
            if d.end_byte >= w.reported + PROGRESS_BYTES {
                w.reported = d.end_byte;
                p.report(ProgressEvent::Position(d.end_byte));
            }
        }
        self.recycle(Item::Rows(d));
        true
    }

    /// Ends the stream at a malformed row (or input) after the rows parsed: the chunks
    /// before the one before its chunk go out (before the bad value's chunk, if earlier).
    fn malformed(&self, w: &mut Writer<'_, P::Ledger>, e: InputError) {
        let mut upto = (w.parsed / self.chunk).saturating_sub(1) * self.chunk;
        if let Some((v, _)) = w.bad.take() {
            upto = upto.min(v / self.chunk * self.chunk);
        }
        self.release(w, upto);
        w.outcome = Some(Err(StreamError::Input(e)));
    }

    /// Writes the rows held before row `upto` (the header first), stopping at a failed write.
    fn release(&self, w: &mut Writer<'_, P::Ledger>, upto: u64) {
        if upto <= w.written {
            return;
        }
        if let Some(h) = w.header.take() {
            put(w.out, &h, &mut w.failed);
        }
        while w.written < upto {
            let Some(h) = w.held.front() else {
                break;
            };
            let n = h.ends.len() as u64;
            let last = upto.min(h.first + n);
            let from = match w.written - h.first {
                0 => 0,
                k => h.ends[k as usize - 1],
            };
            let to = h.ends[(last - h.first) as usize - 1];
            put(w.out, &h.bytes[from..to], &mut w.failed);
            w.written = last;
            if last == h.first + n {
                if let Some(mut h) = w.held.pop_front() {
                    h.bytes.clear();
                    h.ends.clear();
                    let mut pools = lock(&self.pools);
                    pools.bufs.push(h.bytes);
                    pools.ends.push(h.ends);
                }
            }
        }
    }

    /// Hands an item's buffers back for later tasks.
    fn recycle(&self, item: Item<P::Note>) {
        if let Item::Rows(d) = item {
            let mut pools = lock(&self.pools);
            let Done {
                recs,
                mut out,
                mut ends,
                mut notes,
                ..
            } = *d;
            out.clear();
            ends.clear();
            notes.clear();
            pools.recs.push(recs);
            // The output of rows held by the writer went there (and comes back once written).
            if out.capacity() > 0 {
                pools.bufs.push(out);
            }
            if ends.capacity() > 0 {
                pools.ends.push(ends);
            }
            pools.notes.push(notes);
        }
    }
}

fn put(out: &mut dyn Write, bytes: &[u8], failed: &mut Option<std::io::Error>) {
    if failed.is_none() {
        if let Err(e) = out.write_all(bytes) {
            *failed = Some(e);
        }
    }
}
