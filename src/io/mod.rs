//! Files: CSV reading with errors that name file, line, column and value; atomic writing;
//! tables streamed through a per-row computation in bounded memory ([`stream`]), with the
//! row plans of `fitbead forward` ([`forward`]) and `fitbead k` ([`kstream`]).

pub mod cells;
pub mod forward;
pub mod kstream;
pub mod measurements;
pub mod reports;
pub mod scenes;
pub mod stream;

pub use crate::numfmt::{fmt_f64, fmt_sig, push_f64};

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

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

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ", line {l}")?;
        }
        if let Some(c) = &self.column {
            write!(f, ", column '{c}'")?;
        }
        if let Some(v) = &self.value {
            write!(f, ", value '{v}'")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for InputError {}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed and
/// synced, then renamed over the target. On any error the target is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_all(&[(path, bytes)])
}

/// Writes several files atomically as a group: every temporary file is written and synced
/// first, and only then are they renamed into place — a failure while writing (missing
/// directory, full disk) leaves every target untouched.
pub fn write_atomic_all(files: &[(&Path, &[u8])]) -> std::io::Result<()> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        let mut tmp = AtomicFile::create(path)?;
        tmp.write_all(bytes)?;
        tmp.sync()?;
        staged.push(tmp);
    }
    for tmp in staged {
        tmp.persist()?;
    }
    Ok(())
}

/// A file written under a temporary name in the target's directory and renamed over the
/// target only by [`AtomicFile::commit`]; dropped uncommitted, the temporary file is removed
/// and the target is untouched.
pub struct AtomicFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl AtomicFile {
    /// Creates the temporary file next to `path`.
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        let dir: PathBuf = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let tmp = tempfile::Builder::new()
            .prefix(".fitbead-")
            .suffix(".tmp")
            .tempfile_in(&dir)
            .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        Ok(AtomicFile {
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Flushes the data to disk and renames the file over its target.
    pub fn commit(self) -> std::io::Result<()> {
        self.sync()?;
        self.persist()
    }

    fn sync(&self) -> std::io::Result<()> {
        self.tmp.as_file().sync_all()
    }

    fn persist(self) -> std::io::Result<()> {
        let path = self.path;
        self.tmp.persist(&path).map(|_| ()).map_err(|e| {
            std::io::Error::new(e.error.kind(), format!("{}: {}", path.display(), e.error))
        })
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.tmp.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.tmp.write_all(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.tmp.flush()
    }
}

/// Appends one CSV field to `out` as the `csv` crate's default writer does: quoted (with
/// quotes doubled) when it holds a comma, a quote, a carriage return or a newline.
pub fn push_csv_field(out: &mut Vec<u8>, field: &[u8]) {
    if field
        .iter()
        .any(|&b| matches!(b, b',' | b'"' | b'\r' | b'\n'))
    {
        out.push(b'"');
        for &b in field {
            if b == b'"' {
                out.push(b'"');
            }
            out.push(b);
        }
        out.push(b'"');
    } else {
        out.extend_from_slice(field);
    }
}
