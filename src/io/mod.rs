//! Files: CSV reading with errors that name file, line, column and value; atomic writing
//! (`AtomicFile`, `AtomicFile::write_files`: whole files or none, modes kept, links followed;
//! directories of outputs written as one unit: `outdir`);
//! tables streamed through a per-row computation in bounded memory (`stream`), which the
//! door of `fitbead forward` and `fitbead k` ([`crate::pipeline::TableCommand`]) runs with
//! their row plans.

mod atomic;
pub(crate) mod cells;
mod csvsyntax;
pub(crate) mod fit_tables;
pub mod measurements;
pub(crate) mod outdir;
mod ranges;
pub mod records;
pub(crate) mod scenes;
pub(crate) mod stream;

pub(crate) use atomic::remove_stale_temporaries;
pub use atomic::AtomicFile;

pub(crate) use crate::numfmt::{clip, echo, fmt_f64, ECHO_CHARS};

use std::fmt;

/// Where the settings come from, as messages name it.
pub(crate) const SETTINGS_ORIGIN: &str = "<command line>";

/// An error about a setting (named `--NAME` of [`SETTINGS_ORIGIN`]).
pub(crate) fn setting_error(name: &str, value: &str, message: impl Into<String>) -> InputError {
    InputError {
        file: SETTINGS_ORIGIN.into(),
        line: None,
        column: Some(format!("--{name}")),
        value: Some(value.to_string()),
        message: message.into(),
    }
}

/// An input error located in a file.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// The file (or `<stdin>`, `<embedded default data>`, `<command line>`).
    pub file: String,
    /// 1-based line number, when known.
    pub line: Option<u64>,
    /// The column name, when known.
    pub column: Option<String>,
    /// The offending value, when there is one.
    pub value: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl InputError {
    /// The name settings go under as the file of an error: the command line's flags, or the
    /// keywords of a call.
    pub const SETTINGS: &'static str = SETTINGS_ORIGIN;

    /// Longest echo of a user's value in a message, in characters ([`InputError::clip`]).
    pub const ECHO_CHARS: usize = ECHO_CHARS;

    /// `s` cut to at most `max` characters for a message: a longer text keeps its first
    /// `max` − 1 characters followed by `…` and its full length in bytes, so that a huge cell
    /// or argument is never echoed whole.
    pub fn clip(s: &str, max: usize) -> std::borrow::Cow<'_, str> {
        clip(s, max)
    }

    /// An error about a whole file.
    pub fn file(file: &str, message: impl Into<String>) -> Self {
        InputError {
            file: file.to_string(),
            line: None,
            column: None,
            value: None,
            message: message.into(),
        }
    }

    /// An error about one cell.
    pub fn cell(
        file: &str,
        line: u64,
        column: &str,
        value: &str,
        message: impl Into<String>,
    ) -> Self {
        InputError {
            file: file.to_string(),
            line: Some(line),
            column: Some(column.to_string()),
            value: Some(value.to_string()),
            message: message.into(),
        }
    }
}

/// Longest message shown by [`InputError`]'s `Display`, in characters: a message that quotes
/// a huge cell is cut (the value itself is cut at [`ECHO_CHARS`]).
pub(crate) const MESSAGE_CHARS: usize = 1000;

impl fmt::Display for InputError {
    /// `file, line L, column 'C', value 'V': message` (for a flag of the command line,
    /// `<command line>, flag '--NAME', value 'V': message`, without an empty value), with the
    /// file name, the column name and
    /// the value each cut at `ECHO_CHARS` characters and the message at `MESSAGE_CHARS`
    /// (`clip`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", clip(&self.file, 4 * ECHO_CHARS))?;
        if let Some(l) = self.line {
            write!(f, ", line {l}")?;
        }
        // A setting is named as the flag it came from; an empty value says nothing.
        let setting = self.file == SETTINGS_ORIGIN
            && self.column.as_ref().is_some_and(|c| c.starts_with("--"));
        if let Some(c) = &self.column {
            let what = if setting { "flag" } else { "column" };
            write!(f, ", {what} '{}'", echo(c, ECHO_CHARS))?;
        }
        match &self.value {
            Some(v) if setting && v.is_empty() => {}
            Some(v) => write!(f, ", value '{}'", echo(v, ECHO_CHARS))?,
            None => {}
        }
        write!(f, ": {}", clip(&self.message, MESSAGE_CHARS))
    }
}

impl std::error::Error for InputError {}

/// The output names of input columns passed through beside `outputs`, in order: each name as
/// written, unless it is one of `outputs`; then `in_NAME`, prefixed with `in_` again while it
/// is still an output, an input or an output name given before (`v` beside an input `in_v`
/// becomes `in_in_v`). The names returned and `outputs` are all distinct.
pub(crate) fn pass_through_names<'a>(
    inputs: impl IntoIterator<Item = &'a str> + Clone,
    outputs: &[&str],
) -> Vec<String> {
    let given: std::collections::HashSet<&str> = inputs.clone().into_iter().collect();
    let mut chosen: std::collections::HashSet<String> = std::collections::HashSet::new();
    let mut names = Vec::new();
    for h in inputs {
        let mut name = h.to_string();
        if outputs.contains(&h) {
            name = format!("in_{h}");
            while outputs.contains(&name.as_str())
                || given.contains(name.as_str())
                || chosen.contains(&name)
            {
                name.insert_str(0, "in_");
            }
        }
        chosen.insert(name.clone());
        names.push(name);
    }
    names
}

/// Appends one CSV field to `out` as the `csv` crate's default writer does: quoted (with
/// quotes doubled) when it holds a comma, a quote, a carriage return or a newline.
pub(crate) fn push_csv_field(out: &mut Vec<u8>, field: &[u8]) {
    if needs_quotes(field) {
        out.push(b'"');
        let mut from = 0;
        for q in memchr::memchr_iter(b'"', field) {
            out.extend_from_slice(&field[from..=q]);
            out.push(b'"');
            from = q + 1;
        }
        out.extend_from_slice(&field[from..]);
        out.push(b'"');
    } else {
        out.extend_from_slice(field);
    }
}

/// Whether `field` holds a comma, a quote, a carriage return or a newline: byte by byte up to
/// 16 bytes, by `memchr` beyond. (A `k` row's message is ~160 bytes on half the rows of the
/// random file; this function and its caller ran 1,409 instructions a row byte by byte, 710
/// with `memchr`: callgrind, `k --model stick` on 100,000 rows.)
#[inline]
fn needs_quotes(field: &[u8]) -> bool {
    if field.len() > 16 {
        memchr::memchr3(b',', b'"', b'\n', field).is_some()
            || memchr::memchr(b'\r', field).is_some()
    } else {
        field
            .iter()
            .any(|&b| matches!(b, b',' | b'"' | b'\r' | b'\n'))
    }
}

#[cfg(test)]
mod quote_tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The test of long cells by `memchr` against the byte-by-byte one, on random cells of
    /// bytes near the four that need quotes, of UTF-8 and of letters, every length to 40.
    #[test]
    fn needs_quotes_is_the_byte_test() {
        let mut rng = ChaCha8Rng::seed_from_u64(38);
        let alphabet = b"\n\r\",+-.09AZaz \x7f\x80\xc3\xa9\xff";
        let mut quoted = 0;
        for _ in 0..200_000 {
            let len = rng.random_range(0..40);
            let sparse = rng.random_bool(0.5);
            let field: Vec<u8> = (0..len)
                .map(|_| {
                    if sparse && rng.random_bool(0.95) {
                        b'7'
                    } else {
                        alphabet[rng.random_range(0..alphabet.len())]
                    }
                })
                .collect();
            let want = field
                .iter()
                .any(|&b| matches!(b, b',' | b'"' | b'\r' | b'\n'));
            assert_eq!(needs_quotes(&field), want, "{field:?}");
            quoted += usize::from(want);
        }
        assert!(quoted > 50_000 && quoted < 150_000, "{quoted}");
    }

    /// A field as the `csv` crate's writer writes it (in a record with a second field, so
    /// that an empty one is not quoted as a lone empty record is), on random fields of every
    /// length to 200 with commas, quotes, line ends, spaces and letters.
    #[test]
    fn a_field_is_written_as_the_csv_crate_writes_it() {
        let mut rng = ChaCha8Rng::seed_from_u64(39);
        let alphabet = b"\n\r\",  abcdefghij-.0123456789";
        for case in 0..20_000 {
            let len = rng.random_range(0..200);
            let rare = case % 2 == 0;
            let field: String = (0..len)
                .map(|_| {
                    let c = alphabet[rng.random_range(0..alphabet.len())];
                    if rare && matches!(c, b'\n' | b'\r' | b'"' | b',') && rng.random_bool(0.9) {
                        'x'
                    } else {
                        char::from(c)
                    }
                })
                .collect();
            let mut out = Vec::new();
            push_csv_field(&mut out, field.as_bytes());
            out.extend_from_slice(b",x\n");
            let mut c = csv::Writer::from_writer(Vec::new());
            c.write_record([field.as_str(), "x"]).unwrap();
            assert_eq!(out, c.into_inner().unwrap(), "{field:?}");
        }
    }
}
