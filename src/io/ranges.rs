//! The rows of a CSV table parsed in parallel: one thread reads the raw bytes and cuts them
//! at record boundaries into ranges; each range is parsed by its own `csv` reader on a rayon
//! task; the rows come back in input order, with the line numbers, byte offsets, checks and
//! messages of [`TableReader`](super::scenes::TableReader) reading the same input alone.
//!
//! A boundary is the position right after the byte that ends a record (`\n`, or the `\r` of
//! `\r\n` or of a lone `\r`), where the `csv` reader begins the next record: a range that
//! starts there is read by a fresh reader exactly as the one reader of the whole input reads
//! it, and its positions are the whole input's less the range's start. The scan that finds
//! boundaries follows the quoting as the `csv` reader does (a quote opens a cell only at the
//! start of a field; `""` inside one is a quote), so a newline inside a quoted cell never
//! cuts a record; it runs byte by byte only over a block of input that holds a quote, and
//! otherwise looks only at line ends. A range's reader gets its first byte alone, so that it keeps the bytes
//! of a UTF-8 byte order mark at the range's start, as the one reader does after the header.
//!
//! Errors keep their order: a range stops at its first malformed row (a row whose field count
//! differs from the header's, or with invalid UTF-8), and that row is reported only after
//! every row before it has been handed out; a quoted cell still open at the end of the input
//! is reported after the last row.

use super::csvsyntax::{csv_error, ragged_row, unterminated_quote, utf8_error, Quoting};
use super::InputError;
use rayon::prelude::*;
use std::collections::VecDeque;
use std::io::Read;

/// The fewest bytes read ahead at once.
const MIN_BLOCK: usize = 64 * 1024;
/// The bounds of one range's size in bytes.
const MIN_RANGE: usize = 16 * 1024;
const MAX_RANGE: usize = 1024 * 1024;
/// Ranges per thread in one block (so that the tasks even out).
const RANGES_PER_THREAD: usize = 4;
/// Bytes per row assumed before any row has been parsed.
const FIRST_ROW_BYTES: u64 = 128;

/// A table's input after its header: what [`Ranges`] starts from.
pub(crate) struct Rest<R> {
    /// Where the input came from (for messages).
    pub source: String,
    /// Fields in the header.
    pub width: usize,
    /// Bytes already read after the header.
    pub bytes: Vec<u8>,
    /// The rest of the input.
    pub input: R,
    /// Offset of `bytes[0]` in the input.
    pub byte: u64,
    /// Line of `bytes[0]` (1 plus the newlines before it).
    pub line: u64,
    /// Records before `bytes[0]` (the header's).
    pub records: u64,
    /// The quoting of the input up to `bytes[0]`, as the reader's watch saw it.
    pub quoting: Quoting,
    /// The line on which the watch's last quoted cell opened.
    pub opened: u64,
}

/// Reads the rows of a table in parallel (see the module docs), [`read_chunk`] at a time.
///
/// [`read_chunk`]: Ranges::read_chunk
pub struct Ranges<R> {
    source: String,
    width: usize,
    input: R,
    /// Raw bytes from a boundary on, not yet parsed.
    buf: Vec<u8>,
    /// Offset, line and quoting (as the reader's watch sees it) of `buf[0]`.
    byte: u64,
    line: u64,
    quoting: Quoting,
    opened: u64,
    /// The input has no more bytes (or failed: `read_error`).
    eof: bool,
    read_error: Option<std::io::Error>,
    /// Nothing more to parse.
    exhausted: bool,
    /// Rows parsed and not yet handed out.
    ahead: VecDeque<csv::StringRecord>,
    /// The malformed row (or input) after the rows of `ahead`.
    failed: Option<InputError>,
    /// Records parsed, the header's and blank ones included.
    records: u64,
    rows_seen: u64,
    /// Records to reuse.
    spare: Vec<csv::StringRecord>,
    /// Bytes and rows parsed so far, for the size of the next block.
    parsed_bytes: u64,
    parsed_rows: u64,
}

/// One range to parse: its bytes in the block, and its offset and line in the input.
#[derive(Clone, Copy)]
struct Span {
    start: usize,
    end: usize,
    byte: u64,
    line: u64,
}

/// The ranges of a block: where the last ends, and the line and the watch's quoting there.
struct Cut {
    spans: Vec<Span>,
    end: usize,
    line: u64,
    quoting: Quoting,
    opened: u64,
}

/// What a range's task hands back.
struct Parsed {
    rows: Vec<csv::StringRecord>,
    spare: Vec<csv::StringRecord>,
    /// Records read (blank ones included).
    records: u64,
    failure: Option<Failure>,
}

/// A malformed row of a range, its record number counted from the range's start.
enum Failure {
    Ragged {
        line: u64,
        len: u64,
    },
    Utf8 {
        pos: csv::Position,
        err: csv::FromUtf8Error,
    },
    Other(InputError),
}

/// Where the `csv` reader's state machine stands, as far as boundaries go.
#[derive(Clone, Copy, PartialEq)]
enum Csv {
    /// Before a record (blank lines are skipped here).
    RecordStart,
    FieldStart,
    Unquoted,
    Quoted,
    QuoteInQuoted,
}

impl Csv {
    /// The state after byte `b`, and whether `b` ended a record.
    #[inline]
    fn step(self, b: u8) -> (Csv, bool) {
        match (self, b) {
            (Csv::Quoted, b'"') => (Csv::QuoteInQuoted, false),
            (Csv::Quoted, _) => (Csv::Quoted, false),
            (Csv::RecordStart, b'\r' | b'\n') => (Csv::RecordStart, false),
            (_, b'\r' | b'\n') => (Csv::RecordStart, true),
            (Csv::QuoteInQuoted, b'"') => (Csv::Quoted, false),
            (Csv::RecordStart | Csv::FieldStart, b'"') => (Csv::Quoted, false),
            (_, b',') => (Csv::FieldStart, false),
            _ => (Csv::Unquoted, false),
        }
    }
}

fn is_end(b: u8) -> bool {
    b == b'\n' || b == b'\r'
}

/// In a block that starts before a record and holds no quote: whether the line end at `i`
/// ends a record (the byte before it is on the same, non-blank line).
fn ends_record(buf: &[u8], i: usize) -> bool {
    i >= 1 && is_end(buf[i]) && !is_end(buf[i - 1])
}

/// Newlines in `bytes`.
fn newlines(bytes: &[u8]) -> u64 {
    bytes.iter().filter(|&&b| b == b'\n').count() as u64
}

impl<R: Read> Ranges<R> {
    pub(crate) fn new(rest: Rest<R>) -> Self {
        Ranges {
            source: rest.source,
            width: rest.width,
            input: rest.input,
            buf: rest.bytes,
            byte: rest.byte,
            line: rest.line,
            quoting: rest.quoting,
            opened: rest.opened,
            eof: false,
            read_error: None,
            exhausted: false,
            ahead: VecDeque::new(),
            failed: None,
            records: rest.records,
            rows_seen: 0,
            spare: Vec::new(),
            parsed_bytes: 0,
            parsed_rows: 0,
        }
    }

    /// Bytes of the input consumed by the rows handed out so far (the header included).
    pub fn bytes_read(&self) -> u64 {
        self.ahead
            .front()
            .and_then(|r| r.position())
            .map_or(self.byte, |p| p.byte())
    }

    /// The error for an input with a header and no data rows.
    pub fn no_rows(&self) -> InputError {
        InputError::file(&self.source, "no data rows after the header")
    }

    /// Reads up to `max` rows into `recs[..n]` (reusing the records already there) and
    /// returns `n`, as [`TableReader::read_chunk`](super::scenes::TableReader::read_chunk)
    /// does: fewer than `max` only at the end of the input; a malformed row is an error once
    /// the rows before it have been handed out.
    pub fn read_chunk(
        &mut self,
        recs: &mut Vec<csv::StringRecord>,
        max: usize,
    ) -> Result<usize, InputError> {
        let mut n = 0;
        loop {
            while n < max {
                let Some(r) = self.ahead.pop_front() else {
                    break;
                };
                match recs.get_mut(n) {
                    Some(old) => self.spare.push(std::mem::replace(old, r)),
                    None => recs.push(r),
                }
                n += 1;
            }
            if n == max {
                return Ok(n);
            }
            if let Some(e) = self.failed.take() {
                self.exhausted = true;
                return Err(e);
            }
            if self.exhausted {
                return Ok(n);
            }
            self.parse_more(max - n);
        }
    }

    /// Reads the rest of the input only to find what the whole table's reading would have
    /// reported before any check of the values: a malformed row, or no data rows at all.
    pub fn drain(&mut self) -> Option<InputError> {
        loop {
            if let Some(e) = self.failed.take() {
                self.exhausted = true;
                return Some(e);
            }
            if self.exhausted {
                break;
            }
            let keep = self.spare.len().max(self.ahead.len());
            self.spare.extend(self.ahead.drain(..));
            self.spare.truncate(keep);
            self.parse_more(1 << 20);
        }
        (self.rows_seen == 0).then(|| self.no_rows())
    }

    /// Reads and parses about enough input for `rows` more rows, appending them to `ahead`;
    /// sets `failed` at a malformed row and `exhausted` at the end of the input.
    fn parse_more(&mut self, rows: usize) {
        let per_row = match self.parsed_rows {
            0 => FIRST_ROW_BYTES,
            n => (self.parsed_bytes / n).max(1),
        };
        let rows = rows as u64;
        let want = rows
            .saturating_mul(per_row)
            .saturating_add(rows * per_row / 8);
        let mut want = usize::try_from(want).unwrap_or(usize::MAX).max(MIN_BLOCK);
        let Cut {
            spans,
            end,
            line,
            quoting,
            opened,
        } = loop {
            self.fill(want);
            if let Some(cut) = self.cut() {
                break cut;
            }
            if self.eof {
                // A read error: the bytes after the last whole record stay unparsed.
                break Cut {
                    spans: Vec::new(),
                    end: 0,
                    line: self.line,
                    quoting: self.quoting,
                    opened: self.opened,
                };
            }
            want = want.max(self.buf.len()).saturating_mul(2);
        };
        let tasks: Vec<(Span, Vec<csv::StringRecord>)> = spans
            .iter()
            .map(|s| {
                let rows = (s.end - s.start) / per_row as usize + 1;
                let from = self.spare.len().saturating_sub(rows);
                (*s, self.spare.split_off(from))
            })
            .collect();
        let (buf, width, source) = (&self.buf, self.width, self.source.as_str());
        let parsed: Vec<Parsed> = tasks
            .into_par_iter()
            .map(|(s, spare)| parse(source, &buf[s.start..s.end], s, width, spare))
            .collect();
        let mut failed = false;
        for p in parsed {
            self.spare.extend(p.spare);
            if failed {
                self.spare.extend(p.rows);
                continue;
            }
            self.rows_seen += p.rows.len() as u64;
            self.parsed_rows += p.rows.len() as u64;
            self.ahead.extend(p.rows);
            if let Some(f) = p.failure {
                self.failed = Some(match f {
                    Failure::Ragged { line, len } => {
                        ragged_row(&self.source, Some(line), len, width as u64)
                    }
                    Failure::Utf8 { mut pos, err } => {
                        pos.set_record(self.records + pos.record());
                        utf8_error(&self.source, &pos, err)
                    }
                    Failure::Other(e) => e,
                });
                failed = true;
            }
            self.records += p.records;
        }
        self.parsed_bytes += end as u64;
        self.byte += end as u64;
        self.line = line;
        self.quoting = quoting;
        self.opened = opened;
        self.buf.drain(..end);
        if failed {
            self.exhausted = true;
        } else if self.eof && (self.buf.is_empty() || self.read_error.is_some()) {
            self.exhausted = true;
            if let Some(e) = self.read_error.take() {
                self.failed = Some(InputError::file(&self.source, format!("cannot read: {e}")));
            } else if self.quoting == Quoting::Quoted {
                self.failed = Some(unterminated_quote(&self.source, self.opened));
            }
        }
    }

    /// Reads until `buf` holds `want` bytes or the input ends.
    fn fill(&mut self, want: usize) {
        while !self.eof && self.buf.len() < want {
            let add = (want - self.buf.len()).max(MIN_BLOCK);
            let before = self.buf.len();
            let r = (&mut self.input)
                .take(add as u64)
                .read_to_end(&mut self.buf);
            match r {
                Ok(_) if self.buf.len() < before + add => self.eof = true,
                Ok(_) => {}
                Err(e) => {
                    self.eof = true;
                    self.read_error = Some(e);
                }
            }
        }
    }

    /// The ranges of `buf` to parse now, up to the last boundary where a range may start
    /// (all of it at the end of the input), with the watch's quoting there; `None` when
    /// `buf` holds no such boundary yet.
    fn cut(&self) -> Option<Cut> {
        let buf = &self.buf;
        // A read error ends the input after the last whole record.
        let eof = self.eof && self.read_error.is_none();
        let threads = rayon::current_num_threads().max(1);
        let size = |end: usize| (end / (threads * RANGES_PER_THREAD)).clamp(MIN_RANGE, MAX_RANGE);
        let mut cuts = vec![0];
        let (end, quoting, opened);
        if buf.contains(&b'"') {
            // Byte by byte, following the quoting of the `csv` reader and of the watch.
            let mut csv = Csv::RecordStart;
            let (mut q, mut line, mut op) = (self.quoting, self.line, self.opened);
            let mut last = None;
            let step = size(buf.len());
            for (i, &b) in buf.iter().enumerate() {
                if b == b'\n' {
                    line += 1;
                }
                q = q.step(b, line, &mut op);
                let (next, ended) = csv.step(b);
                csv = next;
                if ended {
                    last = Some((i + 1, q, op));
                    if i + 1 - cuts[cuts.len() - 1] >= step {
                        cuts.push(i + 1);
                    }
                }
            }
            if eof {
                (end, quoting, opened) = (buf.len(), q, op);
            } else {
                (end, quoting, opened) = last?;
            }
        } else {
            // No quote: a record ends at every line end that follows a byte of its line.
            let last = if eof {
                Some(buf.len())
            } else {
                let mut hi = buf.len();
                loop {
                    let Some(i) = buf[..hi].iter().rposition(|&b| is_end(b)) else {
                        break None;
                    };
                    if ends_record(buf, i) {
                        break Some(i + 1);
                    }
                    hi = i;
                }
            };
            end = last?;
            // The watch sees no quote either: a quoted cell open before stays open.
            quoting = match (self.quoting, end.checked_sub(1).map(|i| buf[i])) {
                (Quoting::Quoted, _) => Quoting::Quoted,
                (q, None) => q,
                (_, Some(b',' | b'\n' | b'\r')) => Quoting::FieldStart,
                (_, Some(_)) => Quoting::Unquoted,
            };
            opened = self.opened;
            let step = size(end);
            let mut at = step;
            while at < end {
                let next = buf[at..end]
                    .iter()
                    .enumerate()
                    .filter(|&(_, &b)| is_end(b))
                    .map(|(k, _)| at + k)
                    .find(|&i| ends_record(buf, i));
                match next {
                    Some(i) if i + 1 < end => {
                        cuts.push(i + 1);
                        at = i + 1 + step;
                    }
                    _ => break,
                }
            }
        }
        if end == 0 {
            return eof.then_some(Cut {
                spans: Vec::new(),
                end,
                line: self.line,
                quoting,
                opened,
            });
        }
        cuts.retain(|&c| c < end);
        cuts.push(end);
        let counts: Vec<u64> = cuts
            .par_windows(2)
            .map(|w| newlines(&buf[w[0]..w[1]]))
            .collect();
        let mut line = self.line;
        let spans = cuts
            .windows(2)
            .zip(counts)
            .map(|(w, n)| {
                let s = Span {
                    start: w[0],
                    end: w[1],
                    byte: self.byte + w[0] as u64,
                    line,
                };
                line += n;
                s
            })
            .collect();
        Some(Cut {
            spans,
            end,
            line,
            quoting,
            opened,
        })
    }
}

/// A range's bytes read with the first byte alone: the `csv` reader drops a byte order mark
/// only when its first read holds one whole, which a range's first read then never does.
struct FirstByteAlone<'a>(&'a [u8], bool);

impl Read for FirstByteAlone<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = if std::mem::take(&mut self.1) {
            buf.len().min(1)
        } else {
            buf.len()
        };
        self.0.read(&mut buf[..n])
    }
}

/// Parses one range (`bytes`, at `at`'s offset and line of the input `source`) under a
/// header of `width` fields, reusing the records of `spare`.
fn parse(
    source: &str,
    bytes: &[u8],
    at: Span,
    width: usize,
    mut spare: Vec<csv::StringRecord>,
) -> Parsed {
    let (byte, line) = (at.byte, at.line);
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .buffer_capacity(1 << 16)
        .from_reader(FirstByteAlone(bytes, true));
    let mut rows = Vec::with_capacity(spare.len());
    let mut rec = spare.pop().unwrap_or_default();
    let mut failure = None;
    loop {
        let mut b = rec.into_byte_record();
        match rdr.read_byte_record(&mut b) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                failure = Some(Failure::Other(csv_error(source, &e)));
                break;
            }
        }
        let local = b.position().cloned().unwrap_or_else(csv::Position::new);
        let mut pos = csv::Position::new();
        pos.set_byte(byte + local.byte())
            .set_line(line + local.line() - 1)
            .set_record(local.record());
        if b.len() != width {
            failure = Some(Failure::Ragged {
                line: pos.line(),
                len: b.len() as u64,
            });
            break;
        }
        match csv::StringRecord::from_byte_record(b) {
            Ok(mut r) => {
                if r.len() == 1 && r.get(0).map(str::trim) == Some("") {
                    rec = r; // blank line
                    continue;
                }
                r.set_position(Some(pos));
                rows.push(r);
                rec = spare.pop().unwrap_or_default();
            }
            Err(err) => {
                failure = Some(Failure::Utf8 { pos, err });
                break;
            }
        }
    }
    Parsed {
        rows,
        spare,
        records: rdr.position().record(),
        failure,
    }
}
