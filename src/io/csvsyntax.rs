//! CSV syntax shared by the one reader of a table ([`super::scenes::TableReader`]) and the
//! reader of byte ranges in parallel ([`super::ranges`]): the quoting state of a byte-by-byte
//! scan, and the messages for malformed CSV, so both readers say the same thing.

use super::InputError;

/// The state of a scan that follows CSV quoting byte by byte: at the start of a field, in an unquoted field, in a quoted
/// cell, or just after a quote in a quoted cell.
#[derive(Clone, Copy, PartialEq, Debug)]
pub(crate) enum Quoting {
    FieldStart,
    Unquoted,
    Quoted,
    QuoteInQuoted,
}

impl Quoting {
    /// The state after byte `b` of line `line` (counted with `b`); a quote that opens a cell
    /// sets `opened` to `line`.
    #[inline]
    pub(crate) fn step(self, b: u8, line: u64, opened: &mut u64) -> Quoting {
        match (self, b) {
            (Quoting::Quoted, b'"') => Quoting::QuoteInQuoted,
            (Quoting::Quoted, _) => Quoting::Quoted,
            (Quoting::QuoteInQuoted, b'"') => Quoting::Quoted,
            (Quoting::FieldStart, b'"') => {
                *opened = line;
                Quoting::Quoted
            }
            (_, b',' | b'\n' | b'\r') => Quoting::FieldStart,
            _ => Quoting::Unquoted,
        }
    }
}

/// A `csv` error other than a ragged row, as the table reader reports it.
pub(crate) fn csv_error(source: &str, e: &csv::Error) -> InputError {
    if let csv::ErrorKind::Io(io) = e.kind() {
        return InputError::file(source, format!("cannot read: {io}"));
    }
    InputError {
        file: source.to_string(),
        line: e.position().map(|p| p.line()),
        column: None,
        value: None,
        message: format!("malformed CSV: {e}"),
    }
}

/// A row of `len` fields under a header of `expected`, starting on `line`.
pub(crate) fn ragged_row(source: &str, line: Option<u64>, len: u64, expected: u64) -> InputError {
    let mut message = format!(
        "malformed CSV: line {} has {len} fields, the header {expected}",
        line.unwrap_or(0)
    );
    if len > expected {
        message.push_str(
            ": is ',' used as the decimal separator? fitbead reads '.' as the \
             decimal point and ',' between fields (quote a cell that holds a comma)",
        );
    }
    InputError {
        file: source.to_string(),
        line,
        column: None,
        value: None,
        message,
    }
}

/// A record at `pos` with invalid UTF-8 (the byte index counted from the trimmed cell).
pub(crate) fn utf8_error(source: &str, pos: &csv::Position, e: csv::FromUtf8Error) -> InputError {
    let (field, up_to) = (e.utf8_error().field(), e.utf8_error().valid_up_to());
    let b = e.into_byte_record();
    let cell = b.get(field).unwrap_or(b"");
    let lead = cell.iter().take_while(|c| c.is_ascii_whitespace()).count();
    InputError {
        file: source.to_string(),
        line: Some(pos.line()),
        column: None,
        value: None,
        message: format!(
            "malformed CSV: CSV parse error: record {} (line {}, field: {field}, \
             byte: {}): invalid utf-8: invalid UTF-8 in field {field} near byte \
             index {}",
            pos.record(),
            pos.line(),
            pos.byte(),
            up_to.saturating_sub(lead)
        ),
    }
}

/// A quoted cell opened on `line` that runs to the end of the input.
pub(crate) fn unterminated_quote(source: &str, line: u64) -> InputError {
    InputError {
        file: source.to_string(),
        line: Some(line),
        column: None,
        value: None,
        message: format!(
            "malformed CSV: unterminated quote: the quoted cell opened on line \
             {line} runs to the end of the input"
        ),
    }
}
