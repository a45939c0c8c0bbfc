//! Reading tables of scenes or measurements: typed, validated rows that keep their extra
//! columns and their line numbers — whole ([`Table`]) or a chunk at a time
//! ([`TableReader`]), with the same checks and messages either way.

use super::csvsyntax::{csv_error, ragged_row, unterminated_quote, utf8_error, Quoting};
use super::InputError;
use std::collections::HashMap;
use std::io::{Chain, Cursor, Read};

/// A CSV table read into memory: header, rows, line numbers.
#[derive(Debug, Clone)]
pub struct Table {
    /// Where it came from (for messages).
    pub source: String,
    /// Column names.
    pub headers: Vec<String>,
    /// Cells, row by row.
    pub rows: Vec<csv::StringRecord>,
    /// 1-based line number of each row.
    pub lines: Vec<u64>,
    index: HashMap<String, usize>,
}

/// Streams the rows of a CSV table: the header is read and checked on creation, the rows a
/// chunk at a time. Empty input, an empty or duplicate column name, a malformed or ragged
/// row and an input without rows are reported as [`Table::parse`] reports them (it is built
/// on this reader); blank lines are skipped.
pub struct TableReader<R: Read> {
    source: String,
    headers: Vec<String>,
    index: HashMap<String, usize>,
    rdr: csv::Reader<QuoteWatch<Chain<Cursor<Vec<u8>>, R>>>,
    rows_seen: u64,
    done: bool,
    /// A record swapped with the caller's while one is read (so that reading allocates
    /// nothing once the records have grown to the rows' size).
    spare: Option<csv::StringRecord>,
    /// Bytes of the longest row so far, to size new records.
    row_bytes: usize,
}

/// Where the CSV quoting of the bytes read through it stands: whether a quoted cell is open,
/// and on which line it opened. A quote opens a cell only at the start of a field, as the
/// `csv` reader reads it (elsewhere it is a literal character). Until `keep` is dropped it
/// also keeps every byte it passes on, so that the rows after the header can be handed to
/// [`super::ranges::Ranges`] without reading the input twice.
struct QuoteWatch<R> {
    inner: R,
    state: Quoting,
    line: u64,
    opened: u64,
    keep: Option<Vec<u8>>,
}

impl<R> QuoteWatch<R> {
    fn new(inner: R) -> Self {
        QuoteWatch {
            inner,
            state: Quoting::FieldStart,
            line: 1,
            opened: 0,
            keep: Some(Vec::new()),
        }
    }

    /// The line of a quoted cell still open (the input ended inside it), if any.
    fn open_quote(&self) -> Option<u64> {
        (self.state == Quoting::Quoted).then_some(self.opened)
    }
}

impl<R: Read> Read for QuoteWatch<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' {
                self.line += 1;
            }
            self.state = self.state.step(b, self.line, &mut self.opened);
        }
        if let Some(k) = &mut self.keep {
            k.extend_from_slice(&buf[..n]);
        }
        Ok(n)
    }
}

/// 1-based line number where a record read by [`TableReader`] starts (0 when unknown).
pub fn line_of(rec: &csv::StringRecord) -> u64 {
    rec.position().map(|p| p.line()).unwrap_or(0)
}

impl<R: Read> TableReader<R> {
    /// Reads and checks the header of `input`; `source` names it in messages. Fails on an
    /// input that is empty or only whitespace, an unreadable header, an empty or duplicate
    /// column name, or a read error ("cannot read").
    pub fn new(source: &str, mut input: R) -> Result<Self, InputError> {
        // The leading whitespace (if any) up to the first other byte decides "file is empty".
        let mut prefix = Vec::new();
        let mut buf = [0u8; 8192];
        loop {
            let n = match input.read(&mut buf) {
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(InputError::file(source, format!("cannot read: {e}"))),
            };
            if n == 0 {
                return Err(InputError::file(
                    source,
                    "file is empty: expected a header line",
                ));
            }
            prefix.extend_from_slice(&buf[..n]);
            if buf[..n].iter().any(|b| !b.is_ascii_whitespace()) {
                break;
            }
        }
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::Headers)
            .buffer_capacity(1 << 16)
            .from_reader(QuoteWatch::new(Cursor::new(prefix).chain(input)));
        let headers: Vec<String> = rdr
            .headers()
            .map_err(|e| InputError::file(source, format!("cannot read header: {e}")))?
            .iter()
            .map(|s| s.to_string())
            .collect();
        if let [h] = headers.as_slice() {
            for (sep, name) in [(';', "semicolon"), ('\t', "tab")] {
                if h.contains(sep) {
                    return Err(InputError {
                        file: source.to_string(),
                        line: Some(1),
                        column: None,
                        value: Some(h.clone()),
                        message: format!(
                            "the header looks {name}-separated; fitbead reads comma-separated \
                             files (with '.' as the decimal point)"
                        ),
                    });
                }
            }
        }
        let mut index = HashMap::new();
        for (i, h) in headers.iter().enumerate() {
            if h.is_empty() {
                return Err(InputError {
                    file: source.to_string(),
                    line: Some(1),
                    column: Some(format!("#{}", i + 1)),
                    value: Some(String::new()),
                    message: "empty column name".into(),
                });
            }
            if index.insert(h.clone(), i).is_some() {
                return Err(InputError::cell(source, 1, h, h, "duplicate column name"));
            }
        }
        Ok(TableReader {
            source: source.to_string(),
            headers,
            index,
            rdr,
            rows_seen: 0,
            done: false,
            spare: None,
            row_bytes: 64,
        })
    }

    /// Where the input came from (for messages).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Column names.
    pub fn headers(&self) -> &[String] {
        &self.headers
    }

    /// Index of a column, if present (`find_column`).
    pub fn col(&self, name: &str) -> Option<usize> {
        find_column(&self.index, &self.headers, name)
    }

    /// Index of a required column.
    pub fn require(&self, name: &str) -> Result<usize, InputError> {
        require(&self.source, &self.headers, &self.index, name)
    }

    /// Bytes of the input consumed so far (the header included).
    pub fn bytes_read(&self) -> u64 {
        self.rdr.position().byte()
    }

    /// Reads up to `max` rows into `recs[..n]` (reusing the records already there, growing
    /// `recs` as needed) and returns `n`; fewer than `max` only at the end of the input.
    /// Cells are as in the file, not trimmed: read them through [`Row`], which trims them
    /// (as [`Table`] does). Line numbers: [`line_of`]. A malformed row is an error naming
    /// its line.
    pub fn read_chunk(
        &mut self,
        recs: &mut Vec<csv::StringRecord>,
        max: usize,
    ) -> Result<usize, InputError> {
        self.rdr.get_mut().keep = None;
        let mut n = 0;
        while n < max && !self.done {
            if n == recs.len() {
                recs.push(csv::StringRecord::with_capacity(
                    2 * self.row_bytes,
                    self.headers.len(),
                ));
            }
            if self.read_one(&mut recs[n])? {
                n += 1;
            }
        }
        Ok(n)
    }

    /// Reads the rest of the input only to find what [`Table::parse`] would have reported
    /// before any check of the values: a malformed row, or no data rows at all.
    pub fn drain(&mut self) -> Option<InputError> {
        self.rdr.get_mut().keep = None;
        let mut rec = csv::StringRecord::new();
        while !self.done {
            if let Err(e) = self.read_one(&mut rec) {
                return Some(e);
            }
        }
        (self.rows_seen == 0).then(|| self.no_rows())
    }

    /// Reads one record into `rec`, reusing its buffers; true for a row, false for a blank
    /// line or the end of the input. The cells are not trimmed, but a record with invalid
    /// UTF-8 is reported as when they were (the byte index counted from the trimmed cell).
    fn read_one(&mut self, rec: &mut csv::StringRecord) -> Result<bool, InputError> {
        let pos = self.rdr.position().clone();
        let spare = self.spare.take().unwrap_or_default();
        let mut b = std::mem::replace(rec, spare).into_byte_record();
        let read = self.rdr.read_byte_record(&mut b);
        let utf8 = csv::StringRecord::from_byte_record(b);
        let more = match read {
            Ok(more) => more,
            Err(e) => {
                self.done = true;
                return Err(self.csv_error(e));
            }
        };
        let read = match utf8 {
            Ok(r) => r,
            Err(e) => {
                self.done = true;
                return Err(utf8_error(&self.source, &pos, e));
            }
        };
        self.spare = Some(std::mem::replace(rec, read));
        self.row_bytes = self.row_bytes.max(rec.as_byte_record().as_slice().len());
        if !more {
            self.done = true;
            if let Some(line) = self.rdr.get_ref().open_quote() {
                return Err(unterminated_quote(&self.source, line));
            }
            return Ok(false);
        }
        if rec.len() == 1 && rec.get(0).map(str::trim) == Some("") {
            return Ok(false); // blank line
        }
        self.rows_seen += 1;
        Ok(true)
    }

    /// The error for an input with a header and no data rows.
    pub fn no_rows(&self) -> InputError {
        InputError::file(&self.source, "no data rows after the header")
    }

    fn csv_error(&self, e: csv::Error) -> InputError {
        if let csv::ErrorKind::Io(io) = e.kind() {
            return InputError::file(&self.source, format!("cannot read: {io}"));
        }
        if let csv::ErrorKind::UnequalLengths {
            pos,
            expected_len,
            len,
        } = e.kind()
        {
            let line = pos.as_ref().map(|p| p.line());
            return ragged_row(&self.source, line, *len, *expected_len);
        }
        csv_error(&self.source, &e)
    }

    /// Whether [`into_ranges`](Self::into_ranges) can take over: no row has been read yet,
    /// and the bytes after the header are still at hand.
    pub(crate) fn hands_over(&self) -> bool {
        self.rows_seen == 0 && !self.done && self.rdr.get_ref().keep.is_some()
    }

    /// The reader's rows from here on as [`super::ranges::Ranges`], which parses them in
    /// parallel; only when [`hands_over`](Self::hands_over) (otherwise it has no rows).
    pub(crate) fn into_ranges(self) -> super::ranges::Ranges<R> {
        let pos = self.rdr.position().clone();
        let TableReader {
            source,
            headers,
            rdr,
            ..
        } = self;
        let watch = rdr.into_inner();
        let kept = watch.keep.unwrap_or_default();
        let (prefix, input) = watch.inner.into_inner();
        let start = usize::try_from(pos.byte()).map_or(kept.len(), |h| h.min(kept.len()));
        let mut bytes = kept[start..].to_vec();
        let at = usize::try_from(prefix.position()).unwrap_or(usize::MAX);
        bytes.extend_from_slice(prefix.get_ref().get(at..).unwrap_or(&[]));
        // Where the quoting stands at the end of the header, as the watch saw it.
        let (mut state, mut line, mut opened) = (Quoting::FieldStart, 1, 0);
        for &b in &kept[..start] {
            if b == b'\n' {
                line += 1;
            }
            state = state.step(b, line, &mut opened);
        }
        super::ranges::Ranges::new(super::ranges::Rest {
            source,
            width: headers.len(),
            bytes,
            input,
            byte: pos.byte(),
            line: pos.line(),
            records: pos.record(),
            quoting: state,
            opened,
        })
    }
}

/// What a table's header says: its source, its column names and where each column is; both
/// [`Table`] and [`TableReader`] have one.
pub trait Header {
    /// Where the table came from (for messages).
    fn source(&self) -> &str;
    /// Column names.
    fn headers(&self) -> &[String];
    /// Index of a column, if present.
    fn col(&self, name: &str) -> Option<usize>;
    /// Index of a required column, or the error naming it and the columns there are.
    fn require(&self, name: &str) -> Result<usize, InputError> {
        self.col(name)
            .ok_or_else(|| missing_column(self.source(), self.headers(), name))
    }
}

impl<R: Read> Header for TableReader<R> {
    fn source(&self) -> &str {
        &self.source
    }
    fn headers(&self) -> &[String] {
        &self.headers
    }
    fn col(&self, name: &str) -> Option<usize> {
        find_column(&self.index, &self.headers, name)
    }
}

impl Header for Table {
    fn source(&self) -> &str {
        &self.source
    }
    fn headers(&self) -> &[String] {
        &self.headers
    }
    fn col(&self, name: &str) -> Option<usize> {
        find_column(&self.index, &self.headers, name)
    }
}

fn missing_column(source: &str, headers: &[String], name: &str) -> InputError {
    let mut message = format!(
        "missing required column (header has: {})",
        headers.join(",")
    );
    if let Some(h) = nearest(name, headers.iter().map(String::as_str)) {
        message.push_str(&format!("; did you mean '{h}'?"));
    }
    InputError {
        file: source.to_string(),
        line: Some(1),
        column: Some(name.to_string()),
        value: None,
        message,
    }
}

fn require(
    source: &str,
    headers: &[String],
    index: &HashMap<String, usize>,
    name: &str,
) -> Result<usize, InputError> {
    find_column(index, headers, name).ok_or_else(|| missing_column(source, headers, name))
}

/// Where column `name` is: the column of that exact name, else the one column whose name
/// differs from it only in case (`Xi` for `xi`); `None` when there is none, or several that
/// differ only in case. Every lookup of a column by name goes through here.
pub(crate) fn find_column(
    index: &HashMap<String, usize>,
    headers: &[String],
    name: &str,
) -> Option<usize> {
    if let Some(&i) = index.get(name) {
        return Some(i);
    }
    let mut found = headers
        .iter()
        .enumerate()
        .filter(|(_, h)| h.eq_ignore_ascii_case(name))
        .map(|(i, _)| i);
    let first = found.next()?;
    found.next().is_none().then_some(first)
}

/// Levenshtein distance between `a` and `b`, ignoring ASCII case.
pub(crate) fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().map(|c| c.to_ascii_lowercase()).collect();
    let b: Vec<char> = b.chars().map(|c| c.to_ascii_lowercase()).collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.iter().enumerate() {
        cur[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// Whether `name` looks like a misspelling of `known`: at most 2 edits apart (ignoring case),
/// and at most a third of `known`'s length, so that names of one or two letters (`v`, `K`,
/// `id`) are never taken for one another.
pub(crate) fn is_close(name: &str, known: &str) -> bool {
    let d = edit_distance(name, known);
    d > 0 && d <= 2 && d <= known.chars().count() / 3
}

/// The name among `candidates` that `name` most likely misspells (`is_close`), if any.
pub fn nearest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .filter(|c| is_close(name, c))
        .min_by_key(|c| edit_distance(name, c))
}

/// A column of a table that no reader of it uses, with the known name it most likely
/// misspells.
#[derive(Debug, Clone, PartialEq)]
pub struct UnknownColumn {
    /// Where the table came from.
    pub source: String,
    /// The column's name as written.
    pub column: String,
    /// The known column it is close to (`is_close`), if any.
    pub nearest: Option<String>,
}

impl std::fmt::Display for UnknownColumn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: column '{}' is not one fitbead reads",
            self.source, self.column
        )?;
        if let Some(n) = &self.nearest {
            write!(f, "; did you mean '{n}'?")?;
        }
        Ok(())
    }
}

/// Where a column named like an uncertainty (`sigma…`, `err…`, `sd…`, `std…`, `unc…`, any
/// case) is not one fitbead reads, the known uncertainty column that it most likely means:
/// the first `sigma_X` of `known` whose `X` the table has (`sigma_v` beside `v`, `sigma_v_m_s`
/// beside `v_m_s`: the velocity's, which `known` lists first), when the table lacks it. A σ
/// under another name would otherwise leave the points unweighted without a word.
fn uncertainty_column<'a>(
    t: &(impl Header + ?Sized),
    name: &str,
    known: &[&'a str],
) -> Option<&'a str> {
    let lower = name.trim().to_ascii_lowercase();
    let looks = ["sigma", "err", "sd", "std", "unc"]
        .iter()
        .any(|p| lower.starts_with(p));
    if !looks {
        return None;
    }
    known
        .iter()
        .copied()
        .find(|k| {
            k.strip_prefix("sigma_")
                .is_some_and(|of| t.col(of).is_some())
        })
        .filter(|k| t.col(k).is_none())
}

/// The columns of `t` that none of `known` resolves to (`find_column`). With `strict`, the
/// first of them is an error (line 1, naming the column and the nearest known name);
/// otherwise those close to a known name, or named like an uncertainty while the table lacks
/// a known uncertainty column, are returned, for the caller to warn about (other columns pass
/// through on purpose, e.g. an `id`).
pub fn check_columns(
    t: &(impl Header + ?Sized),
    known: &[&str],
    strict: bool,
) -> Result<Vec<UnknownColumn>, InputError> {
    let used: Vec<usize> = known.iter().filter_map(|k| t.col(k)).collect();
    let mut out = Vec::new();
    for (i, h) in t.headers().iter().enumerate() {
        if used.contains(&i) {
            continue;
        }
        let near = nearest(h, known.iter().copied())
            .or_else(|| uncertainty_column(t, h, known))
            .map(str::to_string);
        if strict {
            let mut message =
                String::from("not a column fitbead reads (refused by --strict-columns)");
            if let Some(n) = &near {
                message.push_str(&format!("; did you mean '{n}'?"));
            }
            return Err(InputError {
                file: t.source().to_string(),
                line: Some(1),
                column: Some(h.clone()),
                value: None,
                message,
            });
        }
        if near.is_some() {
            out.push(UnknownColumn {
                source: t.source().to_string(),
                column: h.clone(),
                nearest: near,
            });
        }
    }
    Ok(out)
}

/// One row of a table with what its messages need: the source, the column names and the
/// line number.
#[derive(Debug, Clone, Copy)]
pub struct Row<'a> {
    /// Where it came from (for messages).
    pub source: &'a str,
    /// Column names.
    pub headers: &'a [String],
    /// The cells.
    pub rec: &'a csv::StringRecord,
    /// 1-based line number.
    pub line: u64,
}

impl<'a> Row<'a> {
    /// Text of a cell, without leading and trailing whitespace.
    pub fn cell(&self, col: usize) -> &'a str {
        let s = self.rec.get(col).unwrap_or("");
        // Bytes in '!'..='~' are never whitespace: most cells need no trimming.
        let plain = |b: Option<&u8>| b.is_some_and(|&b| b > b' ' && b < 0x7f);
        if plain(s.as_bytes().first()) && plain(s.as_bytes().last()) {
            s
        } else {
            s.trim()
        }
    }

    /// A finite number from a cell, or an error naming file, line, column and value.
    pub fn number(&self, col: usize) -> Result<f64, InputError> {
        match self.cell(col).parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.err(col, "value must be a finite number")),
            Err(_) => Err(self.err(col, "not a number")),
        }
    }

    /// An optional number: empty cell or absent column gives `None`.
    pub fn opt_number(&self, col: Option<usize>) -> Result<Option<f64>, InputError> {
        match col {
            Some(c) if !self.cell(c).is_empty() => self.number(c).map(Some),
            _ => Ok(None),
        }
    }

    /// An error at one cell.
    pub fn err(&self, col: usize, message: impl Into<String>) -> InputError {
        InputError::cell(
            self.source,
            self.line,
            &self.headers[col],
            self.cell(col),
            message,
        )
    }
}

impl Table {
    /// Parses CSV text. Fails on an empty input, a ragged row or a header without rows.
    pub fn parse(source: &str, text: &[u8]) -> Result<Table, InputError> {
        let mut r = TableReader::new(source, text)?;
        let mut rows = Vec::new();
        let n = r.read_chunk(&mut rows, usize::MAX)?;
        rows.truncate(n);
        for row in &mut rows {
            row.trim();
        }
        if rows.is_empty() {
            return Err(r.no_rows());
        }
        let lines = rows.iter().map(line_of).collect();
        Ok(Table {
            source: r.source,
            headers: r.headers,
            rows,
            lines,
            index: r.index,
        })
    }

    /// Index of a column, if present (`find_column`).
    pub fn col(&self, name: &str) -> Option<usize> {
        find_column(&self.index, &self.headers, name)
    }

    /// Index of a required column.
    pub fn require(&self, name: &str) -> Result<usize, InputError> {
        require(&self.source, &self.headers, &self.index, name)
    }

    /// Row `row` with its line number, for typed cells and located errors.
    pub fn row(&self, row: usize) -> Row<'_> {
        Row {
            source: &self.source,
            headers: &self.headers,
            rec: &self.rows[row],
            line: self.lines[row],
        }
    }

    /// Raw text of a cell.
    pub fn cell(&self, row: usize, col: usize) -> &str {
        self.rows[row].get(col).unwrap_or("")
    }

    /// A finite number from a cell, or an error naming file, line, column and value.
    pub fn number(&self, row: usize, col: usize) -> Result<f64, InputError> {
        self.row(row).number(col)
    }

    /// An optional number: empty cell or absent column gives `None`.
    pub fn opt_number(&self, row: usize, col: Option<usize>) -> Result<Option<f64>, InputError> {
        self.row(row).opt_number(col)
    }

    /// An error at one cell.
    pub fn err(&self, row: usize, col: usize, message: impl Into<String>) -> InputError {
        self.row(row).err(col, message)
    }
}
