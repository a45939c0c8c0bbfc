//! Files: CSV reading with errors that name file, line, column and value; atomic writing.

pub mod scenes;

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
        let dir: PathBuf = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut tmp = tempfile::Builder::new()
            .prefix(".fitbead-")
            .suffix(".tmp")
            .tempfile_in(&dir)
            .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        staged.push((tmp, *path));
    }
    for (tmp, path) in staged {
        tmp.persist(path).map_err(|e| {
            std::io::Error::new(e.error.kind(), format!("{}: {}", path.display(), e.error))
        })?;
    }
    Ok(())
}

/// `x` rounded to `digits` significant digits, written as the shortest decimal of that
/// value (for messages and terminal tables; `inf`/`NaN` spelled out).
pub fn fmt_sig(x: f64, digits: usize) -> String {
    if x.is_finite() {
        let s = format!("{:.*e}", digits.max(1) - 1, x);
        s.parse::<f64>().map(fmt_f64).unwrap_or(s)
    } else {
        x.to_string()
    }
}

/// Shortest decimal that reads back as the same double (ryu).
pub fn fmt_f64(x: f64) -> String {
    if x.is_finite() {
        let mut b = ryu::Buffer::new();
        let s = b.format_finite(x);
        s.strip_suffix(".0").unwrap_or(s).to_string()
    } else {
        String::new()
    }
}
