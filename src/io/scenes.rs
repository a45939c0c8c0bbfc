//! Reading tables of scenes or measurements: typed, validated rows that keep their extra
//! columns and their line numbers.

use super::InputError;
use std::collections::HashMap;

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

impl Table {
    /// Parses CSV text. Fails on an empty input, a ragged row or a header without rows.
    pub fn parse(source: &str, text: &[u8]) -> Result<Table, InputError> {
        if text.iter().all(|b| b.is_ascii_whitespace()) {
            return Err(InputError::file(
                source,
                "file is empty: expected a header line",
            ));
        }
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .from_reader(text);
        let headers: Vec<String> = rdr
            .headers()
            .map_err(|e| InputError::file(source, format!("cannot read header: {e}")))?
            .iter()
            .map(|s| s.to_string())
            .collect();
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
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        let mut rec = csv::StringRecord::new();
        loop {
            match rdr.read_record(&mut rec) {
                Ok(true) => {
                    let line = rec.position().map(|p| p.line()).unwrap_or(0);
                    if rec.len() == 1 && rec.get(0) == Some("") {
                        continue; // blank line
                    }
                    rows.push(rec.clone());
                    lines.push(line);
                }
                Ok(false) => break,
                Err(e) => {
                    let line = e.position().map(|p| p.line());
                    return Err(InputError {
                        file: source.to_string(),
                        line,
                        column: None,
                        value: None,
                        message: format!("malformed CSV: {e}"),
                    });
                }
            }
        }
        if rows.is_empty() {
            return Err(InputError::file(source, "no data rows after the header"));
        }
        Ok(Table {
            source: source.to_string(),
            headers,
            rows,
            lines,
            index,
        })
    }

    /// Index of a column, if present.
    pub fn col(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    /// Index of a required column.
    pub fn require(&self, name: &str) -> Result<usize, InputError> {
        self.col(name).ok_or_else(|| InputError {
            file: self.source.clone(),
            line: Some(1),
            column: Some(name.to_string()),
            value: None,
            message: format!(
                "missing required column (header has: {})",
                self.headers.join(",")
            ),
        })
    }

    /// Raw text of a cell.
    pub fn cell(&self, row: usize, col: usize) -> &str {
        self.rows[row].get(col).unwrap_or("")
    }

    /// A finite number from a cell, or an error naming file, line, column and value.
    pub fn number(&self, row: usize, col: usize) -> Result<f64, InputError> {
        let s = self.cell(row, col);
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.err(row, col, "value must be a finite number")),
            Err(_) => Err(self.err(row, col, "not a number")),
        }
    }

    /// An optional number: empty cell or absent column gives `None`.
    pub fn opt_number(&self, row: usize, col: Option<usize>) -> Result<Option<f64>, InputError> {
        match col {
            Some(c) if !self.cell(row, c).is_empty() => self.number(row, c).map(Some),
            _ => Ok(None),
        }
    }

    /// An error at one cell.
    pub fn err(&self, row: usize, col: usize, message: impl Into<String>) -> InputError {
        InputError::cell(
            &self.source,
            self.lines[row],
            &self.headers[col],
            self.cell(row, col),
            message,
        )
    }
}
