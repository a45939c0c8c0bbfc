//! Writing CSV records straight into a byte buffer, cell by cell or a whole record (a struct
//! of [`crate::record`], walked by [`crate::record::walk`], the walker of `each_cell`) at once, with the bytes of
//! the `csv` crate's default writer (comma separators, quotes only where needed, `\n` after a
//! record) and without allocating: numbers by [`push_f64`], text quoted by `push_csv_field`.

use super::push_csv_field;
use crate::last::Last;
use crate::numfmt::push_f64;
use crate::record::{columns, walk, Visit};
use serde::Serialize;

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

    #[inline]
    fn sep(&mut self) {
        if !self.first {
            self.out.push(b',');
        }
        self.first = false;
    }

    /// An empty cell.
    #[inline]
    pub fn empty(&mut self) {
        self.sep();
    }

    /// A whole number (as [`Cells::num`] writes it).
    #[inline]
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
    #[inline]
    pub fn text(&mut self, s: &str) {
        self.sep();
        push_csv_field(self.out, s.as_bytes());
    }

    /// A number as [`crate::numfmt::fmt_f64`] writes it (never needs quotes; empty for
    /// inf and NaN).
    #[inline]
    pub fn num(&mut self, x: f64) {
        self.sep();
        push_f64(self.out, x);
    }

    /// The cells of `record`, one per field in column order (the fields
    /// [`crate::record::Cell::each`] visits): numbers as [`Cells::num`], counts as
    /// [`Cells::count`], text quoted where needed, `None` empty.
    ///
    /// # Panics
    /// If `R` is not a record of flat fields (see [`crate::record::Cell::each`]).
    #[inline]
    pub fn record<R: Serialize>(&mut self, record: &R) {
        self.write_record(record, None);
    }

    /// [`Cells::record`], reusing the text of the numbers `repeat` caches while they repeat
    /// from the last record it saw.
    #[inline]
    pub fn record_repeating<R: Serialize>(&mut self, record: &R, repeat: &mut Repeat) {
        self.write_record(record, Some(repeat));
    }

    #[inline]
    fn write_record<R: Serialize>(&mut self, record: &R, repeat: Option<&mut Repeat>) {
        walk(
            record,
            CellWriter {
                cells: self,
                repeat,
            },
        );
    }

    /// Ends the record.
    pub fn end(self) {
        self.out.push(b'\n');
    }
}

/// Writes each field of a record walked by [`crate::record::walk`] straight into [`Cells`],
/// one cell per field, with no intermediate value.
struct CellWriter<'w, 'b> {
    cells: &'w mut Cells<'b>,
    repeat: Option<&'w mut Repeat>,
}

impl Visit for CellWriter<'_, '_> {
    const KEYS: bool = false;

    #[inline]
    fn number(&mut self, _: &'static str, field: usize, x: f64) {
        if let Some(r) = &mut self.repeat {
            if r.mask >> field & 1 == 1 {
                self.cells.sep();
                let text = r.last[field].get(x.to_bits(), |text| {
                    text.clear();
                    push_f64(text, x);
                });
                self.cells.out.extend_from_slice(text);
                return;
            }
        }
        self.cells.num(x);
    }
    #[inline]
    fn count(&mut self, _: &'static str, _: usize, n: u64) {
        self.cells.count(n);
    }
    #[inline]
    fn text(&mut self, _: &'static str, _: usize, s: &str) {
        self.cells.text(s);
    }
    #[inline]
    fn flag(&mut self, _: &'static str, _: usize, b: bool) {
        self.cells.text(if b { "true" } else { "false" });
    }
    #[inline]
    fn empty(&mut self, _: &'static str, _: usize) {
        self.cells.empty();
    }
}

/// The text of chosen numeric fields of a record type as last written, for
/// [`Cells::record_repeating`]: fields whose values consecutive rows share (ξ and the
/// quantities of ξ alone, along a series) are formatted once per run of equal values.
#[derive(Debug, Clone)]
pub(crate) struct Repeat {
    /// Bit i set: field i's text is kept (a record has at most 64 fields).
    mask: u64,
    /// Per field: the text of its last value, keyed by the value's bits.
    last: Vec<Last<u64, Vec<u8>>>,
}

impl Repeat {
    /// A cache for the fields `names` of record type `R`.
    ///
    /// # Panics
    /// If a name is not a column of `R`, or `R` has more than 64 fields (programming errors the
    /// tests catch).
    pub fn new<R: Serialize + Default>(names: &[&str]) -> Self {
        let columns = columns::<R>();
        assert!(columns.len() <= 64, "a record of more than 64 fields");
        let mut mask = 0;
        for n in names {
            let i = columns.iter().position(|c| c == n);
            let i = i.unwrap_or_else(|| panic!("{n} is not a column of the record"));
            mask |= 1 << i;
        }
        Repeat {
            mask,
            last: vec![Last::default(); columns.len()],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Cells, Repeat};

    #[test]
    fn a_record_of_text_number_empty_and_count_cells() {
        let mut out = Vec::new();
        let mut w = Cells::new(&mut out);
        w.text("a,b");
        w.num(0.5);
        w.empty();
        w.count(3);
        w.num(f64::NAN);
        w.end();
        assert_eq!(out, b"\"a,b\",0.5,,3,\n");
    }

    #[test]
    fn repeated_numbers_are_written_as_their_first_text() {
        #[derive(serde::Serialize, Default)]
        struct R {
            a: f64,
            b: f64,
            c: Option<f64>,
        }
        let mut repeat = Repeat::new::<R>(&["a", "c"]);
        let (mut plain, mut reused) = (Vec::new(), Vec::new());
        for r in [
            R {
                a: 0.1,
                b: 1.0,
                c: Some(2.5),
            },
            R {
                a: 0.1,
                b: 2.0,
                c: Some(2.5),
            },
            R {
                a: -0.0,
                b: 3.0,
                c: None,
            },
            R {
                a: 0.0,
                b: 3.0,
                c: Some(f64::NAN),
            },
            R {
                a: 0.0,
                b: 4.0,
                c: Some(2.5),
            },
        ] {
            let mut w = Cells::new(&mut plain);
            w.record(&r);
            w.end();
            let mut w = Cells::new(&mut reused);
            w.record_repeating(&r, &mut repeat);
            w.end();
        }
        assert_eq!(reused, plain);
        assert_eq!(plain, b"0.1,1,2.5\n0.1,2,2.5\n-0,3,\n0,3,\n0,4,2.5\n");
    }

    #[test]
    #[should_panic(expected = "d is not a column")]
    fn a_repeat_cache_names_columns_of_its_record() {
        #[derive(serde::Serialize, Default)]
        struct R {
            a: f64,
        }
        Repeat::new::<R>(&["d"]);
    }

    #[test]
    fn a_record_is_written_field_by_field_as_the_csv_crate_writes_it() {
        #[derive(serde::Serialize)]
        struct R<'a> {
            text: &'a str,
            quoted: String,
            number: f64,
            none: Option<f64>,
            count: Option<u64>,
            flag: bool,
            inf: f64,
        }
        let r = R {
            text: "roll>slip",
            quoted: "a \"b\", c".into(),
            number: 1e-7,
            none: None,
            count: Some(12),
            flag: false,
            inf: f64::INFINITY,
        };
        let mut out = Vec::new();
        let mut w = Cells::new(&mut out);
        w.record(&r);
        w.end();
        // The csv crate's writer on the same cells (the reference for quoting).
        let mut c = csv::Writer::from_writer(Vec::new());
        c.write_record(["roll>slip", "a \"b\", c", "1e-7", "", "12", "false", ""])
            .unwrap();
        assert_eq!(out, c.into_inner().unwrap());
    }

    /// The streaming writer ([`Cells::record`]) writes a record's cells as
    /// [`Cell::each`](crate::record::Cell::each) sees them, with the bytes the `csv` crate writes for those cells: checked
    /// on the records of scenes across every model (steady, stopped, lifted off, bistable, the
    /// contact model's phases and auto's reasons) and of K estimates.
    #[test]
    fn the_streaming_writer_writes_the_records_cells() {
        use crate::io::records::{ForwardRecord, KRecord, RegimeRecord};
        use crate::models::auto::Auto;
        use crate::models::contact::SpinRule;
        use crate::models::{ForwardModel, Model, ModelKind};
        use crate::record::cells;
        use crate::scene::{CollisionLaw, Scene};
        use serde::Serialize;
        fn check<R: Serialize>(r: &R) {
            let mut out = Vec::new();
            let mut w = Cells::new(&mut out);
            w.record(r);
            w.end();
            let mut c = csv::Writer::from_writer(Vec::new());
            c.write_record(cells(r).into_iter().map(|(_, c)| c.to_csv()))
                .unwrap();
            let expected = c.into_inner().unwrap();
            assert_eq!(
                String::from_utf8_lossy(&out),
                String::from_utf8_lossy(&expected)
            );
        }
        let mut written = 0;
        for kind in [
            ModelKind::Stick,
            ModelKind::StickSlip,
            ModelKind::Contact,
            ModelKind::Jan,
            ModelKind::Auto,
        ] {
            for (xi, delta) in [
                (1.0, 3.0),
                (1.0, 20.0),
                (2.0, 26.0),
                (0.6, 40.0),
                (1.6, 14.0),
            ] {
                let scene = Scene::new(xi, delta, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
                let model = match kind {
                    ModelKind::Jan => {
                        Model::Jan(crate::models::jan::Jan::paper_fit(scene.alpha_rad()))
                    }
                    ModelKind::Contact => Model::Contact(crate::models::contact::Contact {
                        spin: SpinRule::Roll,
                        tol: 1e-10,
                    }),
                    ModelKind::Auto => Model::Auto(Auto { tol: 1e-10 }),
                    k => k.contact_model().unwrap(),
                };
                let (f, c, a) = ForwardRecord::evaluate(&scene, &model);
                check(&f);
                written += 1;
                if let Some(c) = c {
                    check(&c);
                }
                if let Some(a) = a {
                    check(&a);
                }
                if let Ok(v) = model.evaluate(&scene).map(|s| s.mean_velocity) {
                    for dv in [0.5, 1.0, 2.0] {
                        let (k, a) =
                            KRecord::estimate(&Model::Stick, None, &scene, v * dv, Some(0.01));
                        check(&k);
                        check(&a.unwrap_or_default());
                    }
                }
            }
        }
        assert_eq!(written, 25);
        check(&RegimeRecord::table(&[0.5, 1.0], CollisionLaw::Cos2a, 0.4)[0]);
    }
}
