//! A CSV table's rows cut into byte ranges that can be parsed in parallel: one thread reads
//! the raw bytes and cuts them at record boundaries into ranges ([`Ranges::next_block`]);
//! each range is parsed by a `csv` reader in the state of a new one ([`parse`]: the thread's
//! reader, kept between ranges and reset to the range's start), with the line numbers, byte
//! offsets, checks and messages of [`TableReader`](super::scenes::TableReader) reading the
//! same input alone.
//!
//! A boundary is the position right after the byte that ends a record (`\n`, or the `\r` of `\r\n`
//! or of a lone `\r`), where the `csv` reader begins the next record: a range that starts there is
//! read by a new (or reset) reader exactly as the one reader of the whole input reads it, and its
//! positions are the whole input's less the range's start. The scan that finds boundaries follows
//! the quoting as the `csv` reader does (a quote opens a cell only at the start of a field; `""`
//! inside one is a quote), so a newline inside a quoted cell never cuts a record; it runs byte by
//! byte only over a block of input that holds a quote, and otherwise looks only at line ends. A
//! range's reader gets its first byte alone, so that it keeps the bytes of a UTF-8 byte order mark
//! at the range's start, as the one reader does after the header.
//!
//! Errors keep their order once the ranges' results are taken in input order: a range stops
//! at its first malformed row (a row whose field count differs from the header's, or with
//! invalid UTF-8, [`Failure`]); a read error, or a quoted cell still open at the end of the
//! input, comes after the last range ([`Next::End`]).

use super::csvsyntax::{csv_error, ragged_row, unterminated_quote, utf8_error, Quoting};
use super::InputError;
use rayon::prelude::*;
use std::cell::RefCell;
use std::io::{Read, Seek, SeekFrom};
use std::sync::Arc;

/// The fewest bytes read ahead at once.
const MIN_BLOCK: usize = 64 * 1024;
/// The bounds of one range's size in bytes.
pub(crate) const MIN_RANGE: usize = 4 * 1024;
pub(crate) const MAX_RANGE: usize = 1024 * 1024;
/// Bytes per row assumed before any row has been cut.
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

/// The input of a table cut into ranges at record boundaries (see the module docs), one
/// block of ranges at a time ([`next_block`](Ranges::next_block)); each range is then parsed
/// on its own ([`parse`]).
pub(crate) struct Ranges<R> {
    source: String,
    width: usize,
    input: R,
    /// Raw bytes from a boundary on, not yet cut.
    buf: Vec<u8>,
    /// Offset, line and quoting (as the reader's watch sees it) of `buf[0]`.
    byte: u64,
    line: u64,
    quoting: Quoting,
    opened: u64,
    /// Records before `buf[0]`'s first range, as the header left them.
    records: u64,
    /// The input has no more bytes (or failed: `read_error`).
    eof: bool,
    read_error: Option<std::io::Error>,
    /// Nothing more to cut; `failed` is what the input ends with.
    exhausted: bool,
    failed: Option<InputError>,
    /// Bytes and line ends cut so far, for the size of the next ranges.
    cut_bytes: u64,
    cut_lines: u64,
}

/// One range to parse: its bytes in the block, and its offset and line in the input.
#[derive(Clone, Copy)]
pub(crate) struct Span {
    pub start: usize,
    pub end: usize,
    pub byte: u64,
    pub line: u64,
}

/// What [`Ranges::next_block`] gives.
pub(crate) enum Next {
    /// Bytes of the input and the ranges that cover them.
    Block(Vec<u8>, Vec<Span>),
    /// The end of the input, with the error it ends with (a read error, or a quoted cell still
    /// open), which comes after every row.
    End(Option<InputError>),
}

/// The ranges of a block: where the last ends, and the line and the watch's quoting there.
struct Cut {
    spans: Vec<Span>,
    end: usize,
    line: u64,
    quoting: Quoting,
    opened: u64,
}

/// What a range's parse gives.
pub(crate) struct Parsed {
    /// The rows, up to the first malformed one.
    pub rows: Vec<csv::StringRecord>,
    /// Records read (blank ones included).
    pub records: u64,
    /// The malformed row after `rows`, if any.
    pub failure: Option<Failure>,
}

/// A malformed row of a range, its record number counted from the range's start.
pub(crate) enum Failure {
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

impl Failure {
    /// The error to report for this failure of a table read from `source` under a header of
    /// `width` fields, `records` being the records before the range (the header's included).
    pub(crate) fn into_error(self, source: &str, width: usize, records: u64) -> InputError {
        match self {
            Failure::Ragged { line, len } => ragged_row(source, Some(line), len, width as u64),
            Failure::Utf8 { mut pos, err } => {
                pos.set_record(records + pos.record());
                utf8_error(source, &pos, err)
            }
            Failure::Other(e) => e,
        }
    }
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

/// In a stretch of input with no quote, outside a quoted cell: whether the line end at `i`,
/// not the stretch's first byte, ends a record (the byte before it is on the same, non-blank
/// line).
fn ends_record(buf: &[u8], i: usize) -> bool {
    i >= 1 && is_end(buf[i]) && !is_end(buf[i - 1])
}

/// Newlines in `bytes`.
fn newlines(bytes: &[u8]) -> u64 {
    memchr::memchr_iter(b'\n', bytes).count() as u64
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
            records: rest.records,
            eof: false,
            read_error: None,
            exhausted: false,
            failed: None,
            cut_bytes: 0,
            cut_lines: 0,
        }
    }

    /// Records before the first range (the header's).
    pub(crate) fn records_before(&self) -> u64 {
        self.records
    }

    /// The mean bytes per line of the input cut so far (a guess before any).
    pub(crate) fn bytes_per_row(&self) -> u64 {
        match self.cut_lines {
            0 => FIRST_ROW_BYTES,
            n => (self.cut_bytes / n).max(1),
        }
    }

    /// The error for an input with a header and no data rows.
    pub(crate) fn no_rows(&self) -> InputError {
        InputError::file(&self.source, "no data rows after the header")
    }

    /// Reads about `block` more bytes (more when no record ends within them) and cuts them
    /// into ranges of about `range` bytes, the block's bytes held in `bytes` (whose
    /// allocation is reused); or the end of the input.
    pub(crate) fn next_block(&mut self, block: usize, range: usize, bytes: Vec<u8>) -> Next {
        if self.exhausted {
            return Next::End(self.failed.take());
        }
        let mut want = block.max(MIN_BLOCK);
        let Cut {
            spans,
            end,
            line,
            quoting,
            opened,
        } = loop {
            self.fill(want);
            if let Some(cut) = self.cut(range) {
                break cut;
            }
            if self.eof {
                // A read error: the bytes after the last whole record stay uncut.
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
        let mut rest = bytes;
        rest.clear();
        rest.extend_from_slice(&self.buf[end..]);
        let mut block = std::mem::replace(&mut self.buf, rest);
        block.truncate(end);
        self.cut_bytes += end as u64;
        self.cut_lines += line - self.line;
        self.byte += end as u64;
        self.line = line;
        self.quoting = quoting;
        self.opened = opened;
        if self.eof && (self.buf.is_empty() || self.read_error.is_some()) {
            self.exhausted = true;
            if let Some(e) = self.read_error.take() {
                self.failed = Some(InputError::file(&self.source, format!("cannot read: {e}")));
            } else if self.quoting == Quoting::Quoted {
                self.failed = Some(unterminated_quote(&self.source, self.opened));
            }
        }
        if spans.is_empty() {
            return Next::End(self.failed.take());
        }
        Next::Block(block, spans)
    }

    /// Reads the rest of the input only to find what the whole table's reading would have
    /// reported before any check of the values: a malformed row, or no data rows at all.
    pub(crate) fn drain(&mut self) -> Option<InputError> {
        let threads = rayon::current_num_threads().max(1);
        let mut rows = 0u64;
        let mut records = self.records;
        let mut bytes = Vec::new();
        loop {
            let range = (self.bytes_per_row() as usize * 512).clamp(MIN_RANGE, MAX_RANGE);
            let (block, spans) = match self.next_block(range * threads * 4, range, bytes) {
                Next::Block(b, s) => (b, s),
                Next::End(Some(e)) => return Some(e),
                Next::End(None) => break,
            };
            let (source, width) = (self.source.as_str(), self.width);
            let block = Arc::new(block);
            let parsed: Vec<Parsed> = spans
                .par_iter()
                .map(|s| parse(source, &block, *s, width, Vec::new()))
                .collect();
            for p in parsed {
                rows += p.rows.len() as u64;
                if let Some(f) = p.failure {
                    return Some(f.into_error(source, width, records));
                }
                records += p.records;
            }
            bytes = Arc::into_inner(block).unwrap_or_default();
        }
        (rows == 0).then(|| self.no_rows())
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

    /// The ranges of `buf` to parse now, about `step` bytes each, up to the last boundary
    /// where a range may start (all of it at the end of the input), with the watch's quoting
    /// there; `None` when `buf` holds no such boundary yet.
    fn cut(&self, step: usize) -> Option<Cut> {
        let buf = &self.buf;
        // A read error ends the input after the last whole record.
        let eof = self.eof && self.read_error.is_none();
        let mut cuts = vec![0];
        let (end, quoting, opened);
        if memchr::memchr(b'"', buf).is_some() {
            // Following the quoting of the `csv` reader and of the watch.
            let sc = scan_quoted(buf, step, self.quoting, self.line, self.opened);
            cuts = sc.cuts;
            if eof {
                (end, quoting, opened) = (buf.len(), sc.quoting, sc.opened);
            } else {
                (end, quoting, opened) = sc.last?;
            }
        } else {
            // No quote: the block is one quote-free stretch from a record's start.
            let last = plain_stretch(buf, 0, buf.len(), Csv::RecordStart, step, &mut cuts);
            end = if eof { buf.len() } else { last? };
            // The watch sees no quote either: a quoted cell open before stays open.
            quoting = match (self.quoting, end.checked_sub(1).map(|i| buf[i])) {
                (Quoting::Quoted, _) => Quoting::Quoted,
                (q, None) => q,
                (_, Some(b',' | b'\n' | b'\r')) => Quoting::FieldStart,
                (_, Some(_)) => Quoting::Unquoted,
            };
            opened = self.opened;
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
        let mut line = self.line;
        let spans = cuts
            .windows(2)
            .map(|w| {
                let s = Span {
                    start: w[0],
                    end: w[1],
                    byte: self.byte + w[0] as u64,
                    line,
                };
                line += newlines(&buf[w[0]..w[1]]);
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

/// What [`scan_quoted`] finds in a block.
#[derive(Debug, PartialEq)]
struct Scan {
    /// 0 and the record ends at which ranges of at least `step` bytes end.
    cuts: Vec<usize>,
    /// The last record end, with the watch's state and opening line there.
    last: Option<(usize, Quoting, u64)>,
    /// The watch's state and opening line after the block.
    quoting: Quoting,
    opened: u64,
}

/// The record ends of a block that holds a quote, by the `csv` reader's state machine
/// ([`Csv`]) and the watch's ([`Quoting`]), the block starting before a record with the
/// watch at `quoting` (its quoted cell opened on line `opened`) on line `line`.
///
/// Only quotes and line ends can change where the machines go next: outside a quoted cell a
/// run of other bytes (commas included) leaves both machines in the state its last byte
/// gives, whatever the state before (a comma: field start; any other byte: unquoted cell),
/// and inside one only a quote ends it. So the scan jumps from one quote or line end to the
/// next (`memchr`) and steps the machines byte by byte only there, with the results of a
/// step through every byte (`scan_bytes` in the tests, against which it is checked).
fn scan_quoted(buf: &[u8], step: usize, quoting: Quoting, line: u64, opened: u64) -> Scan {
    let (mut csv, mut q, mut line, mut op) = (Csv::RecordStart, quoting, line, opened);
    let mut cuts = vec![0];
    let mut last = None;
    let n = buf.len();
    let mut i = 0;
    while i < n {
        let plain = matches!(csv, Csv::RecordStart | Csv::FieldStart | Csv::Unquoted)
            && matches!(q, Quoting::FieldStart | Quoting::Unquoted);
        if plain {
            // Up to the next quote, line ends are the only bytes that end records: the
            // stretch is taken whole (`plain_stretch`).
            let j = memchr::memchr(b'"', &buf[i..]).map_or(n, |k| i + k);
            if j > i {
                if let Some(end) = plain_stretch(buf, i, j, csv, step, &mut cuts) {
                    last = Some((end, Quoting::FieldStart, op));
                }
                line += newlines(&buf[i..j]);
                // The last byte sets both machines' states, whatever came before it.
                let b = buf[j - 1];
                csv = if is_end(b) {
                    Csv::RecordStart
                } else {
                    csv.step(b).0
                };
                q = q.step(b, line, &mut op);
            }
            i = j;
        } else if csv == Csv::Quoted && q == Quoting::Quoted {
            let j = memchr::memchr(b'"', &buf[i..]).map_or(n, |k| i + k);
            line += memchr::memchr_iter(b'\n', &buf[i..j]).count() as u64;
            i = j;
        }
        if i == n {
            break;
        }
        let b = buf[i];
        if b == b'\n' {
            line += 1;
        }
        q = q.step(b, line, &mut op);
        let (next, ended) = csv.step(b);
        csv = next;
        i += 1;
        if ended {
            last = Some((i, q, op));
            if i - cuts[cuts.len() - 1] >= step {
                cuts.push(i);
            }
        }
    }
    Scan {
        cuts,
        last,
        quoting: q,
        opened: op,
    }
}

/// The record ends of `buf[i..j]`, a stretch with no quote in which the `csv` reader is
/// outside a quoted cell, starting in state `csv`: a line end ends a record unless the reader
/// is before a record there, i.e. unless it is the stretch's first byte with `csv` at a
/// record's start, or follows another line end ([`ends_record`]). Pushes onto `cuts` each
/// record end at least `step` bytes after the last cut, as the byte-by-byte scan does,
/// looking only near those positions; returns the position after the stretch's last record
/// end.
fn plain_stretch(
    buf: &[u8],
    i: usize,
    j: usize,
    csv: Csv,
    step: usize,
    cuts: &mut Vec<usize>,
) -> Option<usize> {
    let ends = |p: usize| {
        if p == i {
            csv != Csv::RecordStart
        } else {
            ends_record(buf, p)
        }
    };
    // The first record end at or after `from`, before j.
    let next_end = |mut from: usize| {
        while let Some(k) = buf
            .get(from..j)
            .and_then(|b| memchr::memchr2(b'\n', b'\r', b))
        {
            let p = from + k;
            if ends(p) {
                return Some(p);
            }
            from = p + 1;
        }
        None
    };
    // A record end at p gives a cut at p + 1 >= the last cut + step.
    while let Some(p) = next_end((cuts[cuts.len() - 1] + step).saturating_sub(1).max(i)) {
        cuts.push(p + 1);
    }
    let mut hi = j;
    loop {
        match memchr::memrchr2(b'\n', b'\r', &buf[i..hi]) {
            Some(k) if ends(i + k) => return Some(i + k + 1),
            Some(k) => hi = i + k,
            None => return None,
        }
    }
}

/// A range of a block of input as a reader: its first byte alone, so that the `csv` reader,
/// which drops a UTF-8 byte order mark only when its first read holds one whole, keeps one at
/// a range's start (as the one reader of the whole input does after the header).
#[derive(Default)]
struct RangeBytes {
    block: Option<Arc<Vec<u8>>>,
    at: usize,
    end: usize,
    first: bool,
}

impl Read for RangeBytes {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let Some(block) = &self.block else {
            return Ok(0);
        };
        let left = self.end - self.at;
        let n = if std::mem::take(&mut self.first) {
            buf.len().min(left).min(1)
        } else {
            buf.len().min(left)
        };
        buf[..n].copy_from_slice(&block[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}

/// A new range is put in place before [`csv::Reader::seek_raw`] asks to go to its start, so
/// the seek itself moves nothing.
impl Seek for RangeBytes {
    fn seek(&mut self, _: SeekFrom) -> std::io::Result<u64> {
        Ok(0)
    }
}

thread_local! {
    /// This thread's `csv` reader of ranges, kept from one range to the next: building one
    /// costs about 270,000 instructions (its state machine) and zeroes its buffer, as much as
    /// parsing 250 rows (`valgrind --tool=callgrind`, `fitbead forward`, 512-row ranges).
    static RANGE_READER: RefCell<Option<csv::Reader<RangeBytes>>> = const { RefCell::new(None) };
}

/// A reader at the start of a range of `block`, in the state of a new one: line 1, byte 0,
/// record 0, no header, its byte order mark rule as on a new input.
fn range_reader<'r>(
    kept: &'r mut Option<csv::Reader<RangeBytes>>,
    block: &Arc<Vec<u8>>,
    start: usize,
    end: usize,
) -> &'r mut csv::Reader<RangeBytes> {
    let rdr = kept.get_or_insert_with(|| {
        let mut r = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .buffer_capacity(1 << 16)
            .from_reader(RangeBytes::default());
        // With headers set, `seek_raw` reads none.
        r.set_byte_headers(csv::ByteRecord::new());
        r
    });
    *rdr.get_mut() = RangeBytes {
        block: Some(Arc::clone(block)),
        at: start,
        end,
        first: true,
    };
    // Cannot fail: the headers are set and the seek is `RangeBytes`'s.
    let _ = rdr.seek_raw(SeekFrom::Start(0), csv::Position::new());
    rdr
}

/// Parses one range (`span` of `block`, at its offset and line of the input `source`) under a
/// header of `width` fields, reusing the records of `spare` (whatever their contents).
///
/// Whole lines with no quote and no carriage return are split at newlines and commas
/// directly ([`parse_plain`]); from the record that holds one, this thread's `csv` reader
/// reads on ([`parse_by_reader`]) until it stops at a boundary before plain lines again.
pub(crate) fn parse(
    source: &str,
    block: &Arc<Vec<u8>>,
    at: Span,
    width: usize,
    spare: Vec<csv::StringRecord>,
) -> Parsed {
    let bytes = &block[at.start..at.end];
    let mut part = Part {
        width,
        rows: Vec::with_capacity(spare.len()),
        spare,
        records: 0,
        failure: None,
    };
    let (mut from, mut line) = (0, at.line);
    while from < bytes.len() && part.failure.is_none() {
        let cut = plain_until(bytes, from);
        if cut > from {
            line = parse_plain(&bytes[from..cut], at.byte + from as u64, line, &mut part);
            from = cut;
        } else {
            (from, line) = parse_by_reader(source, block, at, from, line, &mut part);
        }
    }
    Parsed {
        rows: part.rows,
        records: part.records,
        failure: part.failure,
    }
}

/// The end of the lines from `from` (a boundary) up to the first line that holds a quote or
/// a carriage return (the end of `bytes` when none does), itself a boundary: after a newline
/// that ends a record, before any empty lines that follow it (the reader gives the record
/// after them the position where they begin). `from` when there is no such record.
fn plain_until(bytes: &[u8], from: usize) -> usize {
    let Some(special) = memchr::memchr2(b'"', b'\r', &bytes[from..]).map(|n| from + n) else {
        return bytes.len();
    };
    let mut cut = memchr::memrchr(b'\n', &bytes[from..special]).map_or(from, |n| from + n + 1);
    // `bytes[cut - 1]` is a newline while `cut > from`.
    while cut > from && !(cut >= from + 2 && bytes[cut - 2] != b'\n') {
        cut -= 1;
    }
    cut
}

/// The rows of a range as its parts are parsed, and the spare records to read them into.
struct Part {
    width: usize,
    rows: Vec<csv::StringRecord>,
    spare: Vec<csv::StringRecord>,
    /// Records read so far (blank ones included).
    records: u64,
    failure: Option<Failure>,
}

impl Part {
    /// A record read at `pos`: added to the rows unless it is blank (one cell of white space,
    /// which is skipped); the record to read the next one into (a spare one or the blank
    /// one), or the failure a ragged or non-UTF-8 record is.
    fn keep(
        &mut self,
        b: csv::ByteRecord,
        pos: csv::Position,
    ) -> Result<csv::StringRecord, Failure> {
        if b.len() != self.width {
            return Err(Failure::Ragged {
                line: pos.line(),
                len: b.len() as u64,
            });
        }
        match csv::StringRecord::from_byte_record(b) {
            Ok(r) if r.len() == 1 && r.get(0).map(str::trim) == Some("") => Ok(r),
            Ok(mut r) => {
                r.set_position(Some(pos));
                self.rows.push(r);
                Ok(self.spare.pop().unwrap_or_default())
            }
            Err(err) => Err(Failure::Utf8 { pos, err }),
        }
    }
}

/// Parses lines with no quote and no carriage return, which start at offset `byte` of the
/// input on line `line`, without the `csv` reader: a record is a line and its fields are the
/// line split at commas. Empty lines are skipped, as the reader skips them; a record's
/// position is the reader's, where the previous record ended (before the empty lines it
/// skips); the last line needs no newline. The line after them.
fn parse_plain(bytes: &[u8], byte: u64, mut line: u64, part: &mut Part) -> u64 {
    let mut rec = part.spare.pop().unwrap_or_default();
    let mut i = 0;
    loop {
        let mut pos = csv::Position::new();
        pos.set_byte(byte + i as u64)
            .set_line(line)
            .set_record(part.records);
        while bytes.get(i) == Some(&b'\n') {
            i += 1;
            line += 1;
        }
        if i == bytes.len() {
            break;
        }
        let end = memchr::memchr(b'\n', &bytes[i..]).map_or(bytes.len(), |n| i + n);
        let mut b = rec.into_byte_record();
        b.clear();
        let text = &bytes[i..end];
        let mut from = 0;
        for comma in memchr::memchr_iter(b',', text) {
            b.push_field(&text[from..comma]);
            from = comma + 1;
        }
        b.push_field(&text[from..]);
        if end < bytes.len() {
            line += 1;
            i = end + 1;
        } else {
            i = end;
        }
        part.records += 1;
        match part.keep(b, pos) {
            Ok(next) => rec = next,
            Err(f) => {
                part.failure = Some(f);
                return line;
            }
        }
    }
    part.spare.push(rec);
    line
}

/// Parses range `at` of `block` from `from` (a boundary, on line `line` of the input) by
/// this thread's `csv` reader, up to the first boundary it stops at that plain lines follow
/// ([`plain_until`]), or to the range's end: where it stopped, and the line there.
fn parse_by_reader(
    source: &str,
    block: &Arc<Vec<u8>>,
    at: Span,
    from: usize,
    line: u64,
    part: &mut Part,
) -> (usize, u64) {
    RANGE_READER.with(|kept| {
        let mut kept = kept.borrow_mut();
        let rdr = range_reader(&mut kept, block, at.start + from, at.end);
        let bytes = &block[at.start..at.end];
        let stop = read_records(rdr, source, bytes, at.byte + from as u64, from, line, part);
        // Let go of the block, which goes back to the stream's pool once every range is read.
        rdr.get_mut().block = None;
        stop
    })
}

/// [`parse_by_reader`] with the reader placed at `from` of `bytes`, offset `byte` of the
/// input.
fn read_records(
    rdr: &mut csv::Reader<RangeBytes>,
    source: &str,
    bytes: &[u8],
    byte: u64,
    from: usize,
    line: u64,
    part: &mut Part,
) -> (usize, u64) {
    let records = part.records;
    let mut rec = part.spare.pop().unwrap_or_default();
    loop {
        let mut b = rec.into_byte_record();
        match rdr.read_byte_record(&mut b) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                part.failure = Some(Failure::Other(csv_error(source, &e)));
                return (bytes.len(), line);
            }
        }
        let local = b.position().cloned().unwrap_or_else(csv::Position::new);
        let mut pos = csv::Position::new();
        pos.set_byte(byte + local.byte())
            .set_line(line + local.line() - 1)
            .set_record(records + local.record());
        let now = rdr.position();
        part.records = records + now.record();
        match part.keep(b, pos) {
            Ok(next) => rec = next,
            Err(f) => {
                part.failure = Some(f);
                return (bytes.len(), line);
            }
        }
        let stop = from + now.byte() as usize;
        if stop < bytes.len() && ends_record(bytes, stop - 1) && plain_until(bytes, stop) > stop {
            part.spare.push(rec);
            return (stop, line + now.line() - 1);
        }
    }
    part.records = records + rdr.position().record();
    (bytes.len(), line + rdr.position().line() - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The scan of [`scan_quoted`] one byte at a time: both machines stepped through every
    /// byte.
    fn scan_bytes(buf: &[u8], step: usize, quoting: Quoting, line: u64, opened: u64) -> Scan {
        let mut csv = Csv::RecordStart;
        let (mut q, mut line, mut op) = (quoting, line, opened);
        let mut cuts = vec![0];
        let mut last = None;
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
        Scan {
            cuts,
            last,
            quoting: q,
            opened: op,
        }
    }

    /// [`scan_quoted`] of `buf` against [`scan_bytes`], from a start state and lines drawn
    /// from `rng` (the start state cycling with `case`); the byte scan's result.
    fn scan_as_bytes(rng: &mut ChaCha8Rng, buf: &[u8], step: usize, case: usize) -> Scan {
        let starts = [
            Quoting::FieldStart,
            Quoting::Unquoted,
            Quoting::Quoted,
            Quoting::QuoteInQuoted,
        ];
        let q = starts[case % starts.len()];
        let (line, opened) = (rng.random_range(1..5), rng.random_range(0..5));
        let want = scan_bytes(buf, step, q, line, opened);
        let got = scan_quoted(buf, step, q, line, opened);
        assert_eq!(
            got,
            want,
            "{:?}, step {step}, from {q:?}",
            String::from_utf8_lossy(buf)
        );
        want
    }

    /// Long quote-free stretches of many lines (a quote every ~150 bytes), the shape of a
    /// table with an occasional quoted cell: [`plain_stretch`] takes them whole.
    #[test]
    fn the_scan_of_long_plain_stretches_is_the_byte_scan() {
        let mut rng = ChaCha8Rng::seed_from_u64(36);
        let mut cuts = 0;
        for case in 0..5_000 {
            let len = rng.random_range(0..600);
            let buf: Vec<u8> = (0..len)
                .map(|_| match rng.random_range(0..300) {
                    0 | 1 => b'"',
                    2..=19 => b'\n',
                    20..=23 => b'\r',
                    24..=79 => b',',
                    _ => b'7',
                })
                .collect();
            let step = rng.random_range(1..80);
            cuts += scan_as_bytes(&mut rng, &buf, step, case).cuts.len();
        }
        // Most cases cut their stretches several times.
        assert!(cuts > 20_000, "{cuts}");
    }

    #[test]
    fn the_jumping_scan_finds_what_the_byte_scan_finds() {
        let mut rng = ChaCha8Rng::seed_from_u64(35);
        // Bytes that steer the machines, and two that do not.
        let alphabet = b"\",\n\rab";
        let mut quoted_ends = 0;
        for case in 0..20_000 {
            let len = rng.random_range(0..64);
            // Runs of one byte, so that long plain and quoted stretches occur.
            let mut buf = Vec::with_capacity(len);
            while buf.len() < len {
                let b = alphabet[rng.random_range(0..alphabet.len())];
                let run = if rng.random_bool(0.3) {
                    rng.random_range(1..12)
                } else {
                    1
                };
                buf.extend(std::iter::repeat_n(b, run));
            }
            let step = rng.random_range(1..16);
            let want = scan_as_bytes(&mut rng, &buf, step, case);
            quoted_ends += usize::from(want.quoting == Quoting::Quoted);
        }
        // The cases reach every kind of ending, a quoted cell still open among them.
        assert!(quoted_ends > 1000, "{quoted_ends}");
    }

    /// A parse's result as text: each row's cells and position, the records read, and the
    /// failure.
    fn parsed_text(p: &Parsed) -> String {
        let rows: Vec<String> = p
            .rows
            .iter()
            .map(|r| {
                let pos = r.position().expect("a row has its position");
                format!("{:?}@{},{},{}", r, pos.byte(), pos.line(), pos.record())
            })
            .collect();
        let failure = match &p.failure {
            None => String::new(),
            Some(Failure::Ragged { line, len }) => format!("ragged {line} {len}"),
            Some(Failure::Utf8 { pos, err }) => {
                format!("utf8 {},{},{} {err}", pos.byte(), pos.line(), pos.record())
            }
            Some(Failure::Other(e)) => format!("other {e}"),
        };
        format!("{rows:?} records {} {failure}", p.records)
    }

    /// The range parsed by the `csv` reader alone, record after record.
    fn reader_alone(block: &Arc<Vec<u8>>, at: Span, width: usize) -> Parsed {
        let mut part = Part {
            width,
            rows: Vec::new(),
            spare: Vec::new(),
            records: 0,
            failure: None,
        };
        let mut kept = None;
        let rdr = range_reader(&mut kept, block, at.start, at.end);
        let mut b = csv::ByteRecord::new();
        loop {
            match rdr.read_byte_record(&mut b) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => {
                    part.failure = Some(Failure::Other(csv_error("in.csv", &e)));
                    break;
                }
            }
            let local = b.position().cloned().expect("a record has its position");
            let mut pos = csv::Position::new();
            pos.set_byte(at.byte + local.byte())
                .set_line(at.line + local.line() - 1)
                .set_record(local.record());
            match part.keep(std::mem::take(&mut b), pos) {
                Ok(next) => b = next.into_byte_record(),
                Err(f) => {
                    part.failure = Some(f);
                    break;
                }
            }
        }
        Parsed {
            rows: part.rows,
            records: rdr.position().record(),
            failure: part.failure,
        }
    }

    /// A range parsed in plain stretches and by the reader ([`parse`]) gives what the `csv`
    /// reader alone gives: the same cells, positions (after empty lines too), record counts,
    /// and the same first ragged or non-UTF-8 row. The ranges are drawn from commas,
    /// newlines, spaces, a byte order mark, a lone UTF-8 lead byte, letters and numbers, and
    /// in a third of the cases quotes, quoted cells holding a comma or a newline, carriage
    /// returns and `\r\n`.
    #[test]
    fn ranges_parse_as_the_reader_alone_parses_them() {
        let mut rng = ChaCha8Rng::seed_from_u64(37);
        let pieces: [&[u8]; 12] = [
            b",",
            b"\n",
            b"\n\n",
            b" ",
            b"\xEF\xBB\xBF",
            b"\xC3",
            b"ab",
            b"7.5",
            b"\"",
            b"\"a,\nb\"",
            b"\r",
            b"\r\n",
        ];
        let (mut ragged, mut utf8, mut rows, mut mixed_rows) = (0, 0, 0, 0);
        for case in 0..30_000 {
            let special = case % 3 == 0;
            let len = rng.random_range(0..60);
            let mut block = Vec::new();
            let start = rng.random_range(0..3);
            block.resize(start, b'x');
            for _ in 0..len {
                let piece = match rng.random_range(0..if special { 108 } else { 100 }) {
                    0 => pieces[5],
                    1 => pieces[4],
                    2..=8 => pieces[0],
                    9..=32 => pieces[1],
                    33..=36 => pieces[2],
                    37..=40 => pieces[3],
                    41..=70 => pieces[6],
                    71..=99 => pieces[7],
                    100..=101 => pieces[8],
                    102..=103 => pieces[9],
                    104..=105 => pieces[10],
                    _ => pieces[11],
                };
                block.extend_from_slice(piece);
            }
            let at = Span {
                start,
                end: block.len(),
                byte: rng.random_range(0..1000),
                line: rng.random_range(1..50),
            };
            let width = rng.random_range(1..4);
            let block = Arc::new(block);
            let got = parse("in.csv", &block, at, width, Vec::new());
            let want = reader_alone(&block, at, width);
            assert_eq!(
                parsed_text(&got),
                parsed_text(&want),
                "case {case}: {:?}, width {width}",
                String::from_utf8_lossy(&block[at.start..])
            );
            rows += got.rows.len();
            if special && memchr::memchr2(b'"', b'\r', &block[at.start..]).is_some() {
                mixed_rows += got.rows.len();
            }
            match got.failure {
                Some(Failure::Ragged { .. }) => ragged += 1,
                Some(Failure::Utf8 { .. }) => utf8 += 1,
                _ => {}
            }
        }
        // The cases reach rows, rows of ranges with quotes or carriage returns, ragged rows
        // and invalid UTF-8.
        assert!(
            rows > 15_000 && mixed_rows > 3_000 && ragged > 1_000 && utf8 > 500,
            "{rows} {mixed_rows} {ragged} {utf8}"
        );
    }
}
