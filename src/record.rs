//! Records: the rows of fitbead's output tables as structs deriving `serde::Serialize`,
//! whose columns are their fields, in order, with their serde names ([`columns`]). Every
//! writer reads a record through [`each_cell`]: the CSV files ([`to_csv`] and the streaming
//! commands' writer), the reports, and the Python binding's columns and dicts. A number is
//! written as the shortest decimal that reads back as the same double
//! ([`crate::numfmt::fmt_f64`]), an absent or non-finite number as an empty cell.

use crate::numfmt::fmt_f64;
use serde::ser::{self, Impossible, SerializeStruct, Serializer};
use serde::Serialize;
use std::borrow::Cow;
use std::fmt;

/// One cell of a record: what a writer needs to know of a field's value.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell<'a> {
    /// Text.
    Text(Cow<'a, str>),
    /// A number (a writer of text writes a non-finite one as an empty cell).
    Number(f64),
    /// A count.
    Count(u64),
    /// A flag.
    Flag(bool),
    /// No value.
    Empty,
}

impl Cell<'_> {
    /// The cell as the CSV files write it.
    pub fn to_csv(&self) -> String {
        match self {
            Cell::Text(s) => s.to_string(),
            Cell::Number(x) => fmt_f64(*x),
            Cell::Count(n) => n.to_string(),
            Cell::Flag(b) => b.to_string(),
            Cell::Empty => String::new(),
        }
    }

    /// The cell owning its text.
    fn into_owned(self) -> Cell<'static> {
        match self {
            Cell::Text(s) => Cell::Text(Cow::Owned(s.into_owned())),
            Cell::Number(x) => Cell::Number(x),
            Cell::Count(n) => Cell::Count(n),
            Cell::Flag(b) => Cell::Flag(b),
            Cell::Empty => Cell::Empty,
        }
    }
}

/// Calls `visit` with each (column, cell) of `record`, in column order. Text is lent, not
/// copied: only a field written through its `Display` (serde's `collect_str`) allocates.
///
/// A record is a struct of flat fields: numbers (`f64`, integers, `Option` of them), text
/// (`&str`, `String`, `Cow<str>`, unit enum variants), `bool`, and `Option` of any of these
/// (`None` is an empty cell).
///
/// # Panics
/// If `R` is not such a struct, which the records of this crate all are.
#[inline]
pub(crate) fn each_cell<R: Serialize + ?Sized>(
    record: &R,
    visit: impl FnMut(&'static str, Cell<'_>),
) {
    walk(record, ByCell(visit));
}

impl Cell<'_> {
    /// Hands every field of `record` to `visit`, in order, with its serde name and its value
    /// as a [`Cell`]. A record is a struct of flat fields: numbers (`f64`, integers, `Option`
    /// of them), text (`&str`, `String`, `Cow<str>`, unit enum variants), `bool`, and `Option`
    /// of any of these (`None` is an empty cell).
    ///
    /// # Panics
    /// If `R` is not such a struct, which the records of this crate all are.
    #[inline]
    pub fn each<R: Serialize + ?Sized>(record: &R, visit: impl FnMut(&'static str, Cell<'_>)) {
        each_cell(record, visit);
    }
}

/// What a walk of a record ([`walk`]) hands over, field by field, in column order: one call
/// per field, by the kind of its value, with the field's name and index. [`each_cell`] makes each a [`Cell`]; the streaming
/// writer (`io::cells`) writes each straight into its buffer.
pub(crate) trait Visit {
    /// Whether the visitor reads the fields' names (when not, the walk does not keep them:
    /// one store less per field on the streaming path).
    const KEYS: bool = true;
    /// A number (non-finite as it is).
    fn number(&mut self, key: &'static str, field: usize, x: f64);
    /// A count.
    fn count(&mut self, key: &'static str, field: usize, n: u64);
    /// Text.
    fn text(&mut self, key: &'static str, field: usize, s: &str);
    /// A flag.
    fn flag(&mut self, key: &'static str, field: usize, b: bool);
    /// No value.
    fn empty(&mut self, key: &'static str, field: usize);
}

/// Walks `record`'s fields with serde, handing each to `visit` (the walker of [`each_cell`]).
///
/// # Panics
/// As [`each_cell`].
#[inline]
pub(crate) fn walk<R: Serialize + ?Sized, V: Visit>(record: &R, visit: V) {
    if let Err(e) = record.serialize(RecordSerializer {
        visit,
        key: "",
        field: 0,
    }) {
        panic!("not a record of flat fields: {e}");
    }
}

/// A [`Visit`] that hands every field to a closure as a [`Cell`].
struct ByCell<F>(F);

impl<F: FnMut(&'static str, Cell<'_>)> Visit for ByCell<F> {
    #[inline]
    fn number(&mut self, key: &'static str, _: usize, x: f64) {
        (self.0)(key, Cell::Number(x))
    }
    #[inline]
    fn count(&mut self, key: &'static str, _: usize, n: u64) {
        (self.0)(key, Cell::Count(n))
    }
    #[inline]
    fn text(&mut self, key: &'static str, _: usize, s: &str) {
        (self.0)(key, Cell::Text(Cow::Borrowed(s)))
    }
    #[inline]
    fn flag(&mut self, key: &'static str, _: usize, b: bool) {
        (self.0)(key, Cell::Flag(b))
    }
    #[inline]
    fn empty(&mut self, key: &'static str, _: usize) {
        (self.0)(key, Cell::Empty)
    }
}

/// The record's (column, cell) pairs, in column order; a non-finite number is an empty cell.
///
/// # Panics
/// As [`each_cell`].
pub(crate) fn cells<R: Serialize>(record: &R) -> Vec<(&'static str, Cell<'static>)> {
    let mut out = Vec::new();
    each_cell(record, |k, c| {
        let c = match c {
            Cell::Number(x) if !x.is_finite() => Cell::Empty,
            c => c.into_owned(),
        };
        out.push((k, c));
    });
    out
}

/// The columns of record type `R`, generated from its fields (their serde names, in order).
pub(crate) fn columns<R: Serialize + Default>() -> Vec<&'static str> {
    let mut out = Vec::new();
    each_cell(&R::default(), |k, _| out.push(k));
    out
}

/// The records as CSV: the header from [`columns`], one row per record.
pub(crate) fn to_csv<R: Serialize + Default>(
    records: impl IntoIterator<Item = R>,
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(columns::<R>())?;
    for r in records {
        w.write_record(cells(&r).into_iter().map(|(_, c)| c.to_csv()))?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// Why a value is not a record of flat fields.
#[derive(Debug)]
struct NotFlat(String);

impl fmt::Display for NotFlat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotFlat {}

impl ser::Error for NotFlat {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        NotFlat(msg.to_string())
    }
}

fn not_flat<T>(what: &str) -> Result<T, NotFlat> {
    Err(NotFlat(format!(
        "{what} where a record or a flat field was expected"
    )))
}

/// Serialises a record (a struct) by visiting its fields.
struct RecordSerializer<V> {
    /// The visitor, held in place: a field reaches it with no pointer between.
    visit: V,
    /// The name of the field being serialised.
    key: &'static str,
    /// Its index.
    field: usize,
}

/// Serialises one field's value by handing it to the visitor.
struct FieldSerializer<'f, V>(&'f mut RecordSerializer<V>);

/// The serializer methods of a kind of value a record does not hold: each an error.
macro_rules! refuse {
    ($($method:ident($($arg:ty),*) -> $ok:ty;)*) => {
        $(fn $method(self, $(_: $arg),*) -> Result<$ok, NotFlat> {
            not_flat(stringify!($method))
        })*
    };
}

impl<V: Visit> Serializer for RecordSerializer<V> {
    type Ok = ();
    type Error = NotFlat;
    type SerializeSeq = Impossible<(), NotFlat>;
    type SerializeTuple = Impossible<(), NotFlat>;
    type SerializeTupleStruct = Impossible<(), NotFlat>;
    type SerializeTupleVariant = Impossible<(), NotFlat>;
    type SerializeMap = Impossible<(), NotFlat>;
    type SerializeStruct = Self;
    type SerializeStructVariant = Impossible<(), NotFlat>;

    #[inline]
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self, NotFlat> {
        Ok(self)
    }

    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), NotFlat> {
        value.serialize(self)
    }

    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<(), NotFlat> {
        not_flat("an option")
    }

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<(), NotFlat> {
        not_flat("an enum")
    }

    refuse! {
        serialize_bool(bool) -> ();
        serialize_i8(i8) -> ();
        serialize_i16(i16) -> ();
        serialize_i32(i32) -> ();
        serialize_i64(i64) -> ();
        serialize_u8(u8) -> ();
        serialize_u16(u16) -> ();
        serialize_u32(u32) -> ();
        serialize_u64(u64) -> ();
        serialize_f32(f32) -> ();
        serialize_f64(f64) -> ();
        serialize_char(char) -> ();
        serialize_str(&str) -> ();
        serialize_bytes(&[u8]) -> ();
        serialize_none() -> ();
        serialize_unit() -> ();
        serialize_unit_struct(&'static str) -> ();
        serialize_unit_variant(&'static str, u32, &'static str) -> ();
        serialize_seq(Option<usize>) -> Self::SerializeSeq;
        serialize_tuple(usize) -> Self::SerializeTuple;
        serialize_tuple_struct(&'static str, usize) -> Self::SerializeTupleStruct;
        serialize_tuple_variant(&'static str, u32, &'static str, usize) -> Self::SerializeTupleVariant;
        serialize_map(Option<usize>) -> Self::SerializeMap;
        serialize_struct_variant(&'static str, u32, &'static str, usize) -> Self::SerializeStructVariant;
    }
}

impl<V: Visit> SerializeStruct for RecordSerializer<V> {
    type Ok = ();
    type Error = NotFlat;

    #[inline(always)]
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), NotFlat> {
        if V::KEYS {
            self.key = key;
        }
        value.serialize(FieldSerializer(self))?;
        self.field += 1;
        Ok(())
    }

    fn end(self) -> Result<(), NotFlat> {
        Ok(())
    }
}

impl<V: Visit> Serializer for FieldSerializer<'_, V> {
    type Ok = ();
    type Error = NotFlat;
    type SerializeSeq = Impossible<(), NotFlat>;
    type SerializeTuple = Impossible<(), NotFlat>;
    type SerializeTupleStruct = Impossible<(), NotFlat>;
    type SerializeTupleVariant = Impossible<(), NotFlat>;
    type SerializeMap = Impossible<(), NotFlat>;
    type SerializeStruct = Impossible<(), NotFlat>;
    type SerializeStructVariant = Impossible<(), NotFlat>;

    #[inline]
    fn serialize_bool(self, v: bool) -> Result<(), NotFlat> {
        self.0.visit.flag(self.0.key, self.0.field, v);
        Ok(())
    }
    fn serialize_i8(self, v: i8) -> Result<(), NotFlat> {
        self.serialize_i64(v.into())
    }
    fn serialize_i16(self, v: i16) -> Result<(), NotFlat> {
        self.serialize_i64(v.into())
    }
    fn serialize_i32(self, v: i32) -> Result<(), NotFlat> {
        self.serialize_i64(v.into())
    }
    #[inline]
    fn serialize_i64(self, v: i64) -> Result<(), NotFlat> {
        match u64::try_from(v) {
            Ok(n) => self.serialize_u64(n),
            Err(_) => self.serialize_f64(v as f64),
        }
    }
    fn serialize_u8(self, v: u8) -> Result<(), NotFlat> {
        self.serialize_u64(v.into())
    }
    fn serialize_u16(self, v: u16) -> Result<(), NotFlat> {
        self.serialize_u64(v.into())
    }
    fn serialize_u32(self, v: u32) -> Result<(), NotFlat> {
        self.serialize_u64(v.into())
    }
    #[inline(always)]
    fn serialize_u64(self, v: u64) -> Result<(), NotFlat> {
        self.0.visit.count(self.0.key, self.0.field, v);
        Ok(())
    }
    fn serialize_f32(self, v: f32) -> Result<(), NotFlat> {
        self.serialize_f64(v.into())
    }
    #[inline(always)]
    fn serialize_f64(self, v: f64) -> Result<(), NotFlat> {
        self.0.visit.number(self.0.key, self.0.field, v);
        Ok(())
    }
    fn serialize_char(self, v: char) -> Result<(), NotFlat> {
        self.serialize_str(v.encode_utf8(&mut [0; 4]))
    }
    #[inline(always)]
    fn serialize_str(self, v: &str) -> Result<(), NotFlat> {
        self.0.visit.text(self.0.key, self.0.field, v);
        Ok(())
    }
    #[inline(always)]
    fn serialize_none(self) -> Result<(), NotFlat> {
        self.0.visit.empty(self.0.key, self.0.field);
        Ok(())
    }
    #[inline(always)]
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), NotFlat> {
        value.serialize(self)
    }
    #[inline]
    fn serialize_unit(self) -> Result<(), NotFlat> {
        self.0.visit.empty(self.0.key, self.0.field);
        Ok(())
    }
    #[inline]
    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<(), NotFlat> {
        self.serialize_str(variant)
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), NotFlat> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<(), NotFlat> {
        not_flat("an enum with data")
    }

    refuse! {
        serialize_bytes(&[u8]) -> ();
        serialize_unit_struct(&'static str) -> ();
        serialize_seq(Option<usize>) -> Self::SerializeSeq;
        serialize_tuple(usize) -> Self::SerializeTuple;
        serialize_tuple_struct(&'static str, usize) -> Self::SerializeTupleStruct;
        serialize_tuple_variant(&'static str, u32, &'static str, usize) -> Self::SerializeTupleVariant;
        serialize_map(Option<usize>) -> Self::SerializeMap;
        serialize_struct(&'static str, usize) -> Self::SerializeStruct;
        serialize_struct_variant(&'static str, u32, &'static str, usize) -> Self::SerializeStructVariant;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Default)]
    struct Sample<'a> {
        whole: f64,
        tenth: f64,
        negative_zero: f64,
        count: u64,
        large: f64,
        nan: f64,
        none: Option<f64>,
        flag: bool,
        #[serde(rename = "text, quoted")]
        text: &'a str,
        negative: i32,
    }

    #[test]
    fn cells_follow_the_csv_rules() {
        let s = Sample {
            whole: 2.0,
            tenth: 0.1,
            negative_zero: -0.0,
            count: 7,
            large: 1e300,
            nan: f64::NAN,
            none: None,
            flag: true,
            text: "a",
            negative: -3,
        };
        let csv: Vec<(&str, String)> = cells(&s)
            .into_iter()
            .map(|(k, c)| (k, c.to_csv()))
            .collect();
        let expected = [
            ("whole", "2"),
            ("tenth", "0.1"),
            ("negative_zero", "-0"),
            ("count", "7"),
            ("large", "1e300"),
            ("nan", ""),
            ("none", ""),
            ("flag", "true"),
            ("text, quoted", "a"),
            ("negative", "-3"),
        ];
        assert_eq!(csv.len(), expected.len());
        for ((k, v), (ek, ev)) in csv.iter().zip(expected) {
            assert_eq!((*k, v.as_str()), (ek, ev));
        }
        assert_eq!(cells(&s)[5].1, Cell::Empty);
        assert_eq!(cells(&s)[3].1, Cell::Count(7));
        assert_eq!(cells(&s)[9].1, Cell::Number(-3.0));
        let mut seen = Vec::new();
        each_cell(&s, |_, c| {
            seen.push(matches!(c, Cell::Number(x) if x.is_nan()))
        });
        assert_eq!(
            seen.iter().filter(|&&b| b).count(),
            1,
            "each_cell lends NaN as it is"
        );
    }

    #[test]
    #[should_panic(expected = "not a record of flat fields")]
    fn a_nested_value_is_refused() {
        #[derive(Serialize)]
        struct Nested {
            inner: Vec<f64>,
        }
        each_cell(&Nested { inner: vec![1.0] }, |_, _| {});
    }
}
