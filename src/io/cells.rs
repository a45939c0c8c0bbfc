//! Writing CSV records straight into a byte buffer, cell by cell, with the bytes of the `csv`
//! crate's default writer (comma separators, quotes only where needed, `\n` after a record)
//! and without allocating: numbers by [`push_f64`], text quoted by `push_csv_field`.

use super::push_csv_field;
use crate::numfmt::push_f64;
use std::io::Write;

/// The cells of one CSV record, appended to a byte buffer (the test below shows the calls).
pub struct Cells<'b> {
    out: &'b mut Vec<u8>,
    first: bool,
}

impl<'b> Cells<'b> {
    /// A record starting at the end of `out`.
    pub fn new(out: &'b mut Vec<u8>) -> Self {
        Cells { out, first: true }
    }

    fn sep(&mut self) {
        if !self.first {
            self.out.push(b',');
        }
        self.first = false;
    }

    /// An empty cell.
    pub fn empty(&mut self) {
        self.sep();
    }

    /// One or more cells already written as CSV (separated by commas, quoted where needed),
    /// appended as they are.
    pub fn raw(&mut self, cells: &[u8]) {
        self.sep();
        self.out.extend_from_slice(cells);
    }

    /// A whole number (as [`Cells::num`] writes it).
    pub fn count(&mut self, n: u64) {
        self.sep();
        let mut digits = [0u8; 20];
        let mut i = digits.len();
        let mut n = n;
        loop {
            i -= 1;
            digits[i] = b'0' + (n % 10) as u8;
            n /= 10;
            if n == 0 {
                break;
            }
        }
        self.out.extend_from_slice(&digits[i..]);
    }

    /// A text cell, quoted when it holds a comma, a quote, a carriage return or a newline.
    pub fn text(&mut self, s: &str) {
        self.sep();
        push_csv_field(self.out, s.as_bytes());
    }

    /// A number as [`crate::numfmt::fmt_f64`] writes it (never needs quotes; empty for
    /// inf and NaN).
    pub fn num(&mut self, x: f64) {
        self.sep();
        push_f64(self.out, x);
    }

    /// A number, or an empty cell.
    pub fn opt(&mut self, x: Option<f64>) {
        self.sep();
        if let Some(x) = x {
            push_f64(self.out, x);
        }
    }

    /// A cell with the `Display` text of `x`, quoted where needed.
    pub fn show(&mut self, x: impl std::fmt::Display) {
        self.sep();
        let start = self.out.len();
        // Writing into a Vec cannot fail.
        let _ = write!(self.out, "{x}");
        self.quote_from(start);
    }

    /// A cell holding `parts` joined by `sep`, quoted where needed.
    pub fn joined<I>(&mut self, parts: I, sep: &str)
    where
        I: IntoIterator,
        I::Item: std::fmt::Display,
    {
        self.sep();
        let start = self.out.len();
        for (i, p) in parts.into_iter().enumerate() {
            if i > 0 {
                self.out.extend_from_slice(sep.as_bytes());
            }
            let _ = write!(self.out, "{p}");
        }
        self.quote_from(start);
    }

    /// Quotes the cell that starts at `start` when it needs it.
    fn quote_from(&mut self, start: usize) {
        if self.out[start..]
            .iter()
            .any(|&b| matches!(b, b',' | b'"' | b'\r' | b'\n'))
        {
            let s = self.out.split_off(start);
            push_csv_field(self.out, &s);
        }
    }

    /// The `Display` text of `x`, or an empty cell.
    pub fn opt_show(&mut self, x: Option<impl std::fmt::Display>) {
        match x {
            Some(x) => self.show(x),
            None => self.empty(),
        }
    }

    /// Ends the record.
    pub fn end(self) {
        self.out.push(b'\n');
    }
}

#[cfg(test)]
mod tests {
    use super::Cells;

    #[test]
    fn a_record_of_text_number_empty_and_shown_cells() {
        let mut out = Vec::new();
        let mut w = Cells::new(&mut out);
        w.text("a,b");
        w.num(0.5);
        w.empty();
        w.show(3);
        w.end();
        assert_eq!(out, b"\"a,b\",0.5,,3\n");
    }
}
