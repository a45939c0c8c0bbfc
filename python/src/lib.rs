//! The compiled core of the `fitbead` Python package: numpy arrays in and out of fitbead's
//! forward models, the K inversion of eq 69, the regime limits and the fits.
//!
//! The Python package (`python/fitbead/`) wraps these functions in a documented API; the
//! functions here take flat, contiguous float64 arrays of equal length (the Python layer
//! broadcasts) and return dictionaries of arrays. Text columns come back as codes into a list
//! of categories (`(codes, names)`), which the Python layer turns into string arrays. Every
//! number is computed by the Rust library exactly as the command line computes it.

use fitbead::fit::data::Dataset as RsDataset;
use fitbead::fit::klaw::KLaw;
use fitbead::fit::summary::FitResult as RsFitResult;
use fitbead::inverse::posterior::{McmcSettings, Method};
use fitbead::io::measurements::{MeasurementDefaults, MeasurementFile};
use fitbead::io::records::{
    AutoRecord, Cell, ContactRecord, CorrelationRecord, ForwardRecord, KRecord, ParamRecord,
    RegimeRecord, ResidualRecord, StatsRecord,
};
use fitbead::models::auto::Auto;
use fitbead::models::contact::{Contact, SpinRule};
use fitbead::models::jaeger::Jaeger;
use fitbead::models::jan::Jan;
use fitbead::models::regimes::{alpha_of_xi, critical_xi};
use fitbead::models::{JaegerBranch, Model, ModelKind};
use fitbead::pipeline::FitCommand;
use fitbead::scene::{CollisionLaw, Scene};
use numpy::{PyArray1, PyArray3, PyReadonlyArray1};
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU32, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

pyo3::create_exception!(
    _fitbead,
    FitbeadError,
    PyValueError,
    "Bad input or a computation that cannot be done: the command line's message (file, line, \
     column, value where it has them)."
);

fn value_error(msg: impl Into<String>) -> PyErr {
    FitbeadError::new_err(python_words(&msg.into()))
}

/// The keyword argument of the Python functions that the command line's flag `--NAME` sets.
fn keyword(flag: &str) -> String {
    match flag {
        "prior" => "priors".into(),
        "input" => "data".into(),
        _ => flag.replace('-', "_"),
    }
}

/// The library's message in the words of the Python functions: a setting is named by its
/// keyword argument (`level = '2': …` for `<command line>, flag '--level', value '2': …`),
/// and a flag quoted in the text as the keyword with its value where one follows
/// (`vs=MODEL`, `fit='jaeger'`, `skip_unsteady=True`). The rest is the library's text.
fn python_words(msg: &str) -> String {
    const HEAD: &str = "<command line>, flag '--";
    let mut out = String::with_capacity(msg.len());
    let mut body = msg;
    if let Some(rest) = msg.strip_prefix(HEAD) {
        if let Some(end) = rest.find('\'') {
            let kw = keyword(&rest[..end]);
            let after = &rest[end + 1..];
            let (value, tail) = match after.strip_prefix(", value '") {
                Some(v) => match v.find("': ") {
                    Some(q) => (Some(&v[..q]), &v[q + 1..]),
                    None => (None, after),
                },
                None => (None, after),
            };
            out.push_str(&kw);
            if let Some(v) = value {
                out.push_str(" = '");
                out.push_str(v);
                out.push('\'');
            }
            body = tail;
        }
    }
    let mut prev = ' ';
    let mut i = 0;
    while i < body.len() {
        let rest = &body[i..];
        let starts_flag = rest.starts_with("--")
            && matches!(prev, ' ' | '(' | '`' | '"' | '\'')
            && rest[2..].starts_with(|c: char| c.is_ascii_lowercase());
        if !starts_flag {
            let c = rest.chars().next().unwrap_or(' ');
            out.push(c);
            prev = c;
            i += c.len_utf8();
            continue;
        }
        let name_len = rest[2..]
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(rest.len() - 2);
        let name = rest[2..2 + name_len].trim_end_matches('-');
        let kw = keyword(name);
        i += 2 + name.len();
        out.push_str(&kw);
        prev = 'x';
        // The flag's argument, where one follows: a placeholder (MODEL), a word of a
        // setting that takes text, or nothing for a switch.
        let arg_rest = &body[i..];
        let token = arg_rest
            .strip_prefix(' ')
            .map(|t| t.split([' ', ')', ';', ':']).next().unwrap_or(""))
            .unwrap_or("");
        let placeholder = token.chars().any(|c| c.is_ascii_uppercase())
            && !token.chars().any(|c| c.is_ascii_lowercase());
        let text_setting = matches!(
            kw.as_str(),
            "fit" | "vs" | "model" | "method" | "units" | "law" | "branch" | "spin" | "criterion"
        ) && !token.is_empty()
            && token
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || "-.=".contains(c));
        if placeholder {
            out.push('=');
            out.push_str(token);
            i += 1 + token.len();
        } else if text_setting {
            out.push_str("='");
            out.push_str(token);
            out.push('\'');
            i += 1 + token.len();
        } else if matches!(
            kw.as_str(),
            "skip_unsteady" | "strict_columns" | "scale_covar" | "fit_scatter" | "keep_going"
        ) {
            out.push_str("=True");
        }
    }
    out
}

/// The process that loaded the module (0 until it is loaded).
static LOAD_PID: AtomicU32 = AtomicU32::new(0);

/// The thread pool of a process forked from the one that loaded the module, with that
/// process's id (null until such a process needs one).
static FORK_POOL: AtomicPtr<(u32, rayon::ThreadPool)> = AtomicPtr::new(std::ptr::null_mut());

/// Runs `work` on rayon's threads: the global pool in the process that loaded the module; in
/// a process forked from it, a pool of its own, built on first use (a fork copies the global
/// pool's state but none of its threads, so work sent there would wait forever). The pool
/// has the global pool's size (`RAYON_NUM_THREADS`, else one thread per core), one thread if
/// that many cannot be started; an error says why none could be.
fn on_pool<R: Send>(work: impl FnOnce() -> R + Send) -> Result<R, String> {
    let pid = std::process::id();
    let home = LOAD_PID.load(Ordering::Acquire);
    if home == 0 || home == pid {
        return Ok(work());
    }
    let mut cur = FORK_POOL.load(Ordering::Acquire);
    // SAFETY: a non-null FORK_POOL points to a box this function leaked and never frees (a
    // process forked from this one inherits the pointer, with its memory, and replaces it
    // without dropping a pool whose threads it does not have).
    if cur.is_null() || unsafe { (*cur).0 } != pid {
        let built = rayon::ThreadPoolBuilder::new()
            .build()
            .or_else(|_| rayon::ThreadPoolBuilder::new().num_threads(1).build())
            .map_err(|e| format!("no threads for the work in this forked process: {e}"))?;
        let fresh = Box::into_raw(Box::new((pid, built)));
        match FORK_POOL.compare_exchange(cur, fresh, Ordering::AcqRel, Ordering::Acquire) {
            Ok(_) => cur = fresh,
            Err(other) => {
                // Another thread of this process stored its pool first: use that one.
                // SAFETY: `fresh` came from Box::into_raw above and was never shared.
                drop(unsafe { Box::from_raw(fresh) });
                cur = other;
            }
        }
    }
    // SAFETY: as above: a box leaked and never freed.
    let pool = unsafe { &(*cur).1 };
    Ok(pool.install(work))
}

/// A contiguous view of a 1-D float64 array.
fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| value_error(format!("{name}: expected a contiguous float64 array")))
}

/// The arrays as slices, every one as long as the first (xi): an array that is not contiguous
/// float64 or has another length is an error naming it, checked in the order given.
fn slices_of<'a, const N: usize>(
    arrays: [(&'a PyReadonlyArray1<'_, f64>, &str); N],
) -> PyResult<[&'a [f64]; N]> {
    let mut out: [&[f64]; N] = [&[]; N];
    for (i, (a, name)) in arrays.into_iter().enumerate() {
        let s = slice(a, name)?;
        if i > 0 {
            check_len(name, s.len(), out[0].len())?;
        }
        out[i] = s;
    }
    Ok(out)
}

fn opt_slice<'a>(
    a: &'a Option<PyReadonlyArray1<'_, f64>>,
    name: &str,
    n: usize,
) -> PyResult<Option<&'a [f64]>> {
    match a {
        None => Ok(None),
        Some(a) => {
            let s = slice(a, name)?;
            check_len(name, s.len(), n)?;
            Ok(Some(s))
        }
    }
}

fn check_len(name: &str, len: usize, n: usize) -> PyResult<()> {
    if len == n {
        Ok(())
    } else {
        Err(value_error(format!(
            "{name}: length {len}, expected {n} (the length of xi)"
        )))
    }
}

/// Python's repr of a float (shortest round trip), for error messages.
fn show(x: f64) -> String {
    if x.is_nan() {
        "NaN".to_string()
    } else {
        fitbead::numfmt::fmt_f64(x)
    }
}

/// A text column: one code per row into a list of distinct values.
///
/// A sparse column (messages: mostly empty, the rest mostly distinct) keeps instead the rows
/// with a value and their values.
#[derive(Default)]
struct TextColumn {
    codes: Vec<u32>,
    names: Vec<String>,
    index: HashMap<String, u32>,
    last: Option<u32>,
    /// Codes of `'static` texts by address and length (at most [`STATIC_CODES`]): a static
    /// text's bytes never change, so an equal address and length is an equal text.
    statics: Vec<(usize, usize, u32)>,
    sparse: bool,
    rows: usize,
    at: Vec<u64>,
}

/// Static texts a [`TextColumn`] recognises by address (the values of a status, a regime or a
/// phase column are a handful of constants).
const STATIC_CODES: usize = 16;

impl TextColumn {
    fn named(name: &str) -> Self {
        TextColumn {
            sparse: matches!(name, "message" | "reason"),
            ..TextColumn::default()
        }
    }

    fn code(&mut self, s: &str) -> u32 {
        if let Some(c) = self.last {
            if self.names[c as usize] == s {
                return c;
            }
        }
        // Most columns hold a handful of values: a scan beats hashing them.
        // (the first 16 are scanned, the rest looked up).
        let head = self.names.len().min(16);
        let found = match self.names[..head].iter().position(|n| n == s) {
            Some(c) => Some(c as u32),
            None if self.names.len() > head => self.index.get(s).copied(),
            None => None,
        };
        let c = match found {
            Some(c) => c,
            None => {
                let c = self.names.len() as u32;
                self.names.push(s.to_string());
                self.index.insert(s.to_string(), c);
                c
            }
        };
        self.last = Some(c);
        c
    }

    fn push(&mut self, s: &str) {
        if self.sparse {
            if !s.is_empty() {
                self.at.push(self.rows as u64);
                self.names.push(s.to_string());
            }
        } else {
            let c = self.code(s);
            self.codes.push(c);
        }
        self.rows += 1;
    }

    /// [`TextColumn::push`] of a static text, coded by its address where it was seen before.
    #[inline]
    fn push_static(&mut self, s: &'static str) {
        if self.sparse {
            return self.push(s);
        }
        let key = (s.as_ptr() as usize, s.len());
        let c = match self.statics.iter().find(|e| (e.0, e.1) == key) {
            Some(e) => e.2,
            None => {
                let c = self.code(s);
                if self.statics.len() < STATIC_CODES {
                    self.statics.push((key.0, key.1, c));
                }
                c
            }
        };
        self.codes.push(c);
        self.rows += 1;
    }

    /// Appends `other`'s rows, recoding its values into this column's list.
    fn append(&mut self, other: TextColumn) {
        let offset = self.rows as u64;
        self.rows += other.rows;
        if self.sparse {
            self.at.extend(other.at.iter().map(|&r| r + offset));
            self.names.extend(other.names);
            return;
        }
        let map: Vec<u32> = other.names.iter().map(|s| self.code(s)).collect();
        self.codes
            .extend(other.codes.iter().map(|&c| map[c as usize]));
    }
}

/// Where a record's cell goes: a numeric column or a text column, by index.
#[derive(Clone, Copy)]
enum Slot {
    Num(usize),
    Text(usize),
}

/// The fields of record type `R` as (column, whether it is a number), in order. A record's
/// text fields are never optional, so a field that is not text in the default record (a
/// number, a count, or an empty `Option`) is a number.
fn fields<R: serde::Serialize + Default>() -> Vec<(&'static str, bool)> {
    let mut out = Vec::new();
    Cell::each(&R::default(), |k, c| {
        out.push((k, !matches!(c, Cell::Text(_))))
    });
    out
}

/// Columns being filled from records: numbers and texts, by name.
struct Columns {
    num_names: Vec<&'static str>,
    nums: Vec<Vec<f64>>,
    text_names: Vec<&'static str>,
    texts: Vec<TextColumn>,
    /// Per field of a row's records, in order: its column.
    slots: Vec<Slot>,
}

impl Columns {
    /// The columns of rows made of records with these fields ([`fields`]), in order.
    fn of(fields: impl IntoIterator<Item = (&'static str, bool)>) -> Self {
        let mut c = Columns {
            num_names: Vec::new(),
            nums: Vec::new(),
            text_names: Vec::new(),
            texts: Vec::new(),
            slots: Vec::new(),
        };
        for (name, number) in fields {
            if number {
                c.slots.push(Slot::Num(c.num_names.len()));
                c.num_names.push(name);
                c.nums.push(Vec::new());
            } else {
                c.slots.push(Slot::Text(c.text_names.len()));
                c.text_names.push(name);
                c.texts.push(TextColumn::named(name));
            }
        }
        c
    }

    fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in self.num_names.into_iter().zip(self.nums) {
            d.set_item(name, PyArray1::from_vec(py, v))?;
        }
        for (name, t) in self.text_names.into_iter().zip(self.texts) {
            if t.sparse {
                let at = PyArray1::from_vec(py, t.at);
                d.set_item(name, (at, PyList::new(py, t.names)?, t.rows))?;
            } else {
                let codes = PyArray1::from_vec(py, t.codes);
                d.set_item(name, (codes, PyList::new(py, t.names)?))?;
            }
        }
        Ok(d)
    }
}

/// One row being written into a task's columns, record by record, field by field.
struct RowSink<'a, 's> {
    /// The row's index in the task.
    j: usize,
    /// The next field's index in the row.
    slot: usize,
    slots: &'a [Slot],
    nums: &'a mut [&'s mut [f64]],
    texts: &'a mut [TextColumn],
}

impl RowSink<'_, '_> {
    /// Writes `record`'s fields as the row's next cells: a number (a count as a float, an
    /// empty cell as NaN) or a text.
    fn record<R: serde::Serialize>(&mut self, record: &R) {
        Cell::each(record, |_, c| {
            match self.slots[self.slot] {
                Slot::Num(i) => {
                    self.nums[i][self.j] = match c {
                        Cell::Number(x) => x,
                        Cell::Count(n) => n as f64,
                        Cell::Flag(b) => f64::from(u8::from(b)),
                        Cell::Text(_) | Cell::Empty => f64::NAN,
                    }
                }
                Slot::Text(i) => self.texts[i].push(match &c {
                    Cell::Text(s) => s,
                    _ => "",
                }),
            }
            self.slot += 1;
        });
    }
}

/// Receives a record's fields in column order, by name: a number (`None` for an empty cell)
/// or a text.
trait FieldVisit {
    fn num(&mut self, name: &'static str, x: Option<f64>);
    fn text(&mut self, name: &'static str, s: &str);
    /// A text known to be static (a constant of the crate).
    fn text_static(&mut self, name: &'static str, s: &'static str) {
        self.text(name, s);
    }
    /// A text that is static where borrowed (the `Cow` itself, not its `&str`, since its
    /// variant says which).
    #[allow(clippy::ptr_arg)]
    fn text_cow(&mut self, name: &'static str, s: &std::borrow::Cow<'static, str>) {
        match s {
            std::borrow::Cow::Borrowed(b) => self.text_static(name, b),
            std::borrow::Cow::Owned(o) => self.text(name, o),
        }
    }
}

/// [`ForwardRecord`]'s fields, each by its column name, in the order of its `Serialize`: the
/// row writer of the forward models, without serde's per-cell dispatch (which cost about 1,000
/// instructions a row, as much as the stick model itself). [`forward_fields_checked`] holds
/// the names and kinds against the record's serde fields before any row is written.
fn visit_forward(r: &ForwardRecord, v: &mut impl FieldVisit) {
    v.num("v", r.v);
    v.text_static("regime", r.regime);
    v.text_static("status", r.status);
    v.num("K_used", r.k_used);
    v.num("final_velocity", r.final_velocity);
    v.num("initial_velocity", r.initial_velocity);
    v.num("contact_time", r.contact_time);
    v.num("theta_G_deg", r.theta_g_deg);
    v.num("map_slope", r.map_slope);
    v.num("other_fixed_point", r.other_fixed_point);
    v.text_cow("phases", &r.phases);
    v.text_cow("message", &r.message);
}

/// Whether [`visit_forward`] names [`ForwardRecord`]'s serde fields, in order, each with its
/// kind (number or text); an error naming the first difference otherwise.
fn forward_fields_checked() -> Result<(), String> {
    struct Names(Vec<(&'static str, bool)>);
    impl FieldVisit for Names {
        fn num(&mut self, name: &'static str, _: Option<f64>) {
            self.0.push((name, true));
        }
        fn text(&mut self, name: &'static str, _: &str) {
            self.0.push((name, false));
        }
    }
    let mut typed = Names(Vec::new());
    visit_forward(&ForwardRecord::default(), &mut typed);
    let serde = fields::<ForwardRecord>();
    if typed.0 == serde {
        Ok(())
    } else {
        Err(format!(
            "internal error: the forward row writer's fields {:?} are not the record's {:?}",
            typed.0, serde
        ))
    }
}

impl FieldVisit for RowSink<'_, '_> {
    #[inline]
    fn num(&mut self, _: &'static str, x: Option<f64>) {
        if let Slot::Num(i) = self.slots[self.slot] {
            self.nums[i][self.j] = x.unwrap_or(f64::NAN);
        }
        self.slot += 1;
    }

    #[inline]
    fn text(&mut self, _: &'static str, s: &str) {
        if let Slot::Text(i) = self.slots[self.slot] {
            self.texts[i].push(s);
        }
        self.slot += 1;
    }

    #[inline]
    fn text_static(&mut self, _: &'static str, s: &'static str) {
        if let Slot::Text(i) = self.slots[self.slot] {
            self.texts[i].push_static(s);
        }
        self.slot += 1;
    }
}

/// Rows per parallel task of [`fill`].
const TASK_ROWS: usize = 2048;

/// Evaluates rows `0..n` in parallel tasks of [`TASK_ROWS`], each row writing its records
/// into a [`RowSink`] (every field of `cols`, in order), and fills `cols` in row order:
/// numbers written in place, texts coded per task and merged, on rayon's threads
/// ([`on_pool`]). The error of the lowest failing row is returned.
fn fill<F>(n: usize, cols: &mut Columns, row: F) -> Result<(), String>
where
    F: Fn(usize, &mut RowSink<'_, '_>) -> Result<(), String> + Sync,
{
    for c in cols.nums.iter_mut() {
        c.clear();
        c.resize(n, f64::NAN);
    }
    let tasks = n.div_ceil(TASK_ROWS);
    // Per task: its slice of every numeric column.
    let mut slices: Vec<Vec<&mut [f64]>> = (0..tasks).map(|_| Vec::new()).collect();
    for c in cols.nums.iter_mut() {
        for (t, ch) in c.chunks_mut(TASK_ROWS).enumerate() {
            slices[t].push(ch);
        }
    }
    let (slots, text_names) = (&cols.slots, &cols.text_names);
    let done: Vec<Result<Vec<TextColumn>, String>> = on_pool(|| {
        slices
            .into_par_iter()
            .enumerate()
            .map(|(t, mut out)| {
                let start = t * TASK_ROWS;
                let mut texts: Vec<TextColumn> = text_names
                    .iter()
                    .map(|name| TextColumn::named(name))
                    .collect();
                let len = (n - start).min(TASK_ROWS);
                for j in 0..len {
                    let mut sink = RowSink {
                        j,
                        slot: 0,
                        slots,
                        nums: &mut out,
                        texts: &mut texts,
                    };
                    row(start + j, &mut sink)?;
                    debug_assert_eq!(sink.slot, slots.len(), "a row writes every field");
                }
                Ok(texts)
            })
            .collect()
    })?;
    for r in done {
        for (c, part) in cols.texts.iter_mut().zip(r?) {
            c.append(part);
        }
    }
    Ok(())
}

/// [`fill`] without the GIL, stopped by a signal: the rows check a stop flag that a signal
/// handler's exception raises (Ctrl-C's KeyboardInterrupt, or the handler's own), so a batch
/// of any size ends within a row's time of it on every thread, and that exception is raised.
fn fill_interruptible<F>(py: Python<'_>, n: usize, cols: &mut Columns, row: F) -> PyResult<()>
where
    F: Fn(usize, &mut RowSink<'_, '_>) -> Result<(), String> + Sync + Send,
{
    let stop = AtomicBool::new(false);
    let r = interruptible(py, &stop, || {
        fill(n, cols, |i, sink| {
            if stop.load(Ordering::Relaxed) {
                return Err("interrupted".into());
            }
            row(i, sink)
        })
    })?;
    r.map_err(value_error)
}

fn opt(x: Option<f64>) -> f64 {
    x.unwrap_or(f64::NAN)
}

/// A report record as a dict keyed by its CSV columns: text, float, int, bool, or None for an
/// empty cell.
fn record_dict<'py, R: serde::Serialize>(py: Python<'py>, r: &R) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let mut result = Ok(());
    Cell::each(r, |k, c| {
        if result.is_err() {
            return;
        }
        result = match c {
            Cell::Text(s) => d.set_item(k, s.as_ref()),
            Cell::Number(x) if x.is_finite() => d.set_item(k, x),
            Cell::Count(n) => d.set_item(k, n),
            Cell::Flag(b) => d.set_item(k, b),
            Cell::Number(_) | Cell::Empty => d.set_item(k, py.None()),
        };
    });
    result.map(|()| d)
}

/// The collision law of row `i`: a number from `k`, else the named law.
fn law_of(k: Option<&[f64]>, law: CollisionLaw, i: usize) -> Result<CollisionLaw, String> {
    match k {
        Some(k) => {
            let x = k[i];
            if !x.is_finite() {
                return Err(format!(
                    "K[{i}] = {}: value must be a finite number",
                    show(x)
                ));
            }
            Ok(CollisionLaw::Value(x))
        }
        None => Ok(law),
    }
}

fn scene_of(
    i: usize,
    xi: &[f64],
    d: &[f64],
    rho: &[f64],
    f: &[f64],
    law: CollisionLaw,
) -> Result<Scene, String> {
    Scene::new(xi[i], d[i], rho[i], f[i], law).map_err(|e| {
        format!(
            "row {i} (xi = {}, delta_deg = {}, rho = {}, f = {}): {e}",
            show(xi[i]),
            show(d[i]),
            show(rho[i]),
            show(f[i])
        )
    })
}

fn parse_law(law: &str) -> PyResult<CollisionLaw> {
    law.parse()
        .map_err(|e: fitbead::scene::ParameterError| value_error(format!("K = '{law}': {e}")))
}

/// The per-row parameters of the phenomenological models and the contact model.
struct ModelArgs<'a> {
    kind: ModelKind,
    lambda: Option<&'a [f64]>,
    mu: Option<&'a [f64]>,
    a: [Option<&'a [f64]>; 3],
    branch: JaegerBranch,
    spin: SpinRule,
    tol: f64,
}

impl ModelArgs<'_> {
    /// The model of row `i` (the command line's `forward` builds it the same way from cells).
    fn model(&self, i: usize, scene: &Scene) -> Result<Model, String> {
        let at = |a: Option<&[f64]>| a.map(|a| a[i]).filter(|x| !x.is_nan());
        Ok(match (self.kind, self.kind.contact_model()) {
            (ModelKind::Auto, _) => Model::Auto(Auto { tol: self.tol }),
            (ModelKind::Contact, _) => Model::Contact(Contact {
                spin: self.spin,
                tol: self.tol,
            }),
            (_, Some(m)) => m,
            (ModelKind::Jan, None) => {
                let paper = Jan::paper_fit(scene.alpha_rad());
                let lambda = at(self.lambda).unwrap_or(paper.lambda);
                let mu = at(self.mu).unwrap_or(paper.mu);
                Model::Jan(Jan::new(lambda, mu).map_err(|e| format!("row {i}: {e}"))?)
            }
            _ => {
                let mut v = [0.0; 3];
                for (j, vj) in v.iter_mut().enumerate() {
                    *vj = at(self.a[j]).ok_or_else(|| {
                        format!("row {i}: jaeger needs a1, a2, a3 (a{} is missing)", j + 1)
                    })?;
                }
                Model::Jaeger(
                    Jaeger::new(v[0], v[1], v[2], self.branch)
                        .map_err(|e| format!("row {i}: {e}"))?,
                )
            }
        })
    }
}

/// Forward model over flat arrays (see the Python `fitbead.forward`).
#[pyfunction]
#[pyo3(signature = (model, xi, delta_deg, rho, f, k=None, law="adjusted", lam=None, mu=None, a1=None, a2=None, a3=None, branch="upper", spin="roll", tol=1e-14))]
#[allow(clippy::too_many_arguments)]
fn forward<'py>(
    py: Python<'py>,
    model: &str,
    xi: PyReadonlyArray1<'py, f64>,
    delta_deg: PyReadonlyArray1<'py, f64>,
    rho: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    k: Option<PyReadonlyArray1<'py, f64>>,
    law: &str,
    lam: Option<PyReadonlyArray1<'py, f64>>,
    mu: Option<PyReadonlyArray1<'py, f64>>,
    a1: Option<PyReadonlyArray1<'py, f64>>,
    a2: Option<PyReadonlyArray1<'py, f64>>,
    a3: Option<PyReadonlyArray1<'py, f64>>,
    branch: &str,
    spin: &str,
    tol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = model
        .parse::<ModelKind>()
        .map_err(|e| value_error(e.to_string()))?;
    if kind == ModelKind::Md {
        return Err(value_error(
            "model md runs through forward_md (it integrates each scene's bead row)",
        ));
    }
    let [xi_s, d_s, rho_s, f_s] = slices_of([
        (&xi, "xi"),
        (&delta_deg, "delta_deg"),
        (&rho, "rho"),
        (&f, "f"),
    ])?;
    let n = xi_s.len();
    let k_s = opt_slice(&k, "K", n)?;
    let base_law = parse_law(law)?;
    let spin: SpinRule = spin.parse().map_err(|e: fitbead::scene::ParameterError| {
        value_error(format!("spin = '{spin}': {e}"))
    })?;
    if !(tol > 0.0 && tol < 1.0) {
        return Err(value_error(format!(
            "tol = {}: expected a relative tolerance in (0, 1)",
            show(tol)
        )));
    }
    let branch: JaegerBranch = branch
        .parse()
        .map_err(|e: String| value_error(format!("branch = '{branch}': {e}")))?;
    let args = ModelArgs {
        kind,
        lambda: opt_slice(&lam, "lam", n)?,
        mu: opt_slice(&mu, "mu", n)?,
        a: [
            opt_slice(&a1, "a1", n)?,
            opt_slice(&a2, "a2", n)?,
            opt_slice(&a3, "a3", n)?,
        ],
        branch,
        spin,
        tol,
    };
    let contact = kind == ModelKind::Contact;
    let auto = kind == ModelKind::Auto;
    // The records' columns: every model's, then the contact model's or auto's.
    let mut f = fields::<ForwardRecord>();
    if contact {
        f.extend(fields::<ContactRecord>());
    }
    if auto {
        f.extend(fields::<AutoRecord>());
    }
    let mut cols = Columns::of(f);
    forward_fields_checked().map_err(PyRuntimeError::new_err)?;
    fill_interruptible(py, n, &mut cols, |i, sink| {
        let law = law_of(k_s, base_law, i)?;
        let scene = scene_of(i, xi_s, d_s, rho_s, f_s, law)?;
        let m = args.model(i, &scene)?;
        let (common, c, a) = ForwardRecord::evaluate(&scene, &m);
        visit_forward(&common, sink);
        if contact {
            sink.record(&c.unwrap_or_default());
        }
        if auto {
            sink.record(&a.unwrap_or_default());
        }
        Ok(())
    })?;
    cols.into_dict(py)
}

/// The model of `k`'s `--model` (the five contact models, contact, or auto).
fn k_model(name: &str, tol: f64) -> PyResult<(Model, Option<Auto>)> {
    if name.trim().eq_ignore_ascii_case("auto") {
        if !(tol > 0.0 && tol < 1.0) {
            return Err(value_error(format!(
                "tol = {}: expected a relative tolerance in (0, 1)",
                show(tol)
            )));
        }
        return Ok((Model::Stick, Some(Auto { tol })));
    }
    let err = || {
        value_error(format!(
            "model = '{name}': expected one of stick, stick-approx, slip, slip-approx, stickslip, contact, auto"
        ))
    };
    let kind: ModelKind = name.parse().map_err(|_| err())?;
    match kind {
        ModelKind::Md | ModelKind::Auto => Err(err()),
        k => k.contact_model().map(|m| (m, None)).ok_or_else(err),
    }
}

/// The K inversion of eq 69 over flat arrays (see the Python `fitbead.invert_k`).
#[pyfunction]
#[pyo3(signature = (model, xi, delta_deg, v, sigma_v, rho, f, tol=1e-10))]
#[allow(clippy::too_many_arguments)]
fn invert_k<'py>(
    py: Python<'py>,
    model: &str,
    xi: PyReadonlyArray1<'py, f64>,
    delta_deg: PyReadonlyArray1<'py, f64>,
    v: PyReadonlyArray1<'py, f64>,
    sigma_v: PyReadonlyArray1<'py, f64>,
    rho: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    tol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (model, auto) = k_model(model, tol)?;
    let [xi_s, d_s, v_s, s_s, rho_s, f_s] = slices_of([
        (&xi, "xi"),
        (&delta_deg, "delta_deg"),
        (&v, "v"),
        (&sigma_v, "sigma_v"),
        (&rho, "rho"),
        (&f, "f"),
    ])?;
    let n = xi_s.len();
    let mut cols = k_columns(auto.is_some(), false);
    fill_interruptible(py, n, &mut cols, |i, sink| {
        let scene = scene_of(i, xi_s, d_s, rho_s, f_s, CollisionLaw::Value(0.5))?;
        let measured = measured(i, v_s, s_s)?;
        k_record(sink, &model, auto.as_ref(), &scene, measured, None);
        Ok(())
    })?;
    cols.into_dict(py)
}

/// Row `i`'s measured v (finite, > 0) and σ (finite, > 0; NaN for none).
fn measured(i: usize, v: &[f64], sigma_v: &[f64]) -> Result<(f64, Option<f64>), String> {
    let vi = v[i];
    if !(vi > 0.0 && vi.is_finite()) {
        return Err(format!(
            "v[{i}] = {}: must be a finite number > 0",
            show(vi)
        ));
    }
    let si = sigma_v[i];
    let sigma = if si.is_nan() {
        None
    } else if si > 0.0 && si.is_finite() {
        Some(si)
    } else {
        return Err(format!(
            "sigma_v[{i}] = {}: must be a finite number > 0 (NaN for none)",
            show(si)
        ));
    };
    Ok((vi, sigma))
}

/// The column of σ_K that the K records of points with slope errors add.
#[derive(Default, serde::Serialize)]
struct SigmaK {
    #[serde(rename = "sigma_K")]
    sigma_k: Option<f64>,
}

/// The columns of the K records, with σ_K's when `slopes` and auto's when `auto`.
fn k_columns(auto: bool, slopes: bool) -> Columns {
    let mut f = fields::<KRecord>();
    if slopes {
        f.extend(fields::<SigmaK>());
    }
    if auto {
        f.extend(fields::<AutoRecord>());
    }
    Columns::of(f)
}

/// One measurement's K records (eq 69) written into `sink`; with `slope` = Some(σ_δ, radians)
/// also σ_K, the slope's uncertainty carried into K's (`KRecord::estimate_with_slope`).
fn k_record(
    sink: &mut RowSink<'_, '_>,
    model: &Model,
    auto: Option<&Auto>,
    scene: &Scene,
    (v, sigma_v): (f64, Option<f64>),
    slope: Option<f64>,
) {
    let (rec, choice) = match slope {
        Some(sd) => {
            let (rec, choice, sigma_k) =
                KRecord::estimate_with_slope(model, auto, scene, v, sigma_v, sd);
            sink.record(&rec);
            sink.record(&SigmaK { sigma_k });
            (None, choice)
        }
        None => {
            let (rec, choice) = KRecord::estimate(model, auto, scene, v, sigma_v);
            (Some(rec), choice)
        }
    };
    if let Some(rec) = rec {
        sink.record(&rec);
    }
    if auto.is_some() {
        sink.record(&choice.unwrap_or_default());
    }
}

/// δ_m (eq 32), δ_d (eq 31), the bulk friction of eq 79 per ξ (the columns of `fitbead
/// regimes`), and the critical ξ of the law.
#[pyfunction]
#[pyo3(signature = (xi, law="adjusted", rho=0.4))]
fn regimes<'py>(
    py: Python<'py>,
    xi: PyReadonlyArray1<'py, f64>,
    law: &str,
    rho: f64,
) -> PyResult<(Bound<'py, PyDict>, Option<f64>)> {
    let l = parse_law(law)?;
    if !(rho.is_finite() && rho >= 0.0) {
        return Err(value_error(format!("rho = {}: must be >= 0", show(rho))));
    }
    let xs = slice(&xi, "xi")?;
    for (i, &x) in xs.iter().enumerate() {
        if !(x.is_finite() && x > 0.0) {
            return Err(value_error(format!(
                "xi[{i}] = {}: radius ratio must be > 0",
                show(x)
            )));
        }
        let k = l.k(alpha_of_xi(x), rho);
        if !(k.is_finite() && k > 0.0) {
            return Err(value_error(format!(
                "K = '{law}': K = {} at xi = {}: must be > 0",
                show(k),
                show(x)
            )));
        }
    }
    let table = RegimeRecord::table(xs, l, rho);
    let mut cols = Columns::of(fields::<RegimeRecord>());
    fill(table.len(), &mut cols, |i, sink| {
        sink.record(&table[i]);
        Ok(())
    })
    .map_err(value_error)?;
    Ok((cols.into_dict(py)?, critical_xi(l, rho)))
}

/// Measured mean velocities grouped in series (the library's `Dataset`).
#[pyclass(module = "fitbead._fitbead", name = "_Dataset", frozen)]
struct PyDataset {
    inner: RsDataset,
    /// The command line's plausibility warnings on the data (unit mistakes), each prefixed
    /// with the data's source as the command line prints it.
    warnings: Vec<String>,
    /// The measurement file the data were read from (its columns, line numbers and source,
    /// which the report uses).
    file: MeasurementFile,
    /// What the data set was made from, to make it again (`state`).
    origin: Origin,
}

/// What a [`PyDataset`] was made from: replayed through the same constructor, it gives the
/// same data set (pickling, saved results).
#[derive(Clone)]
enum Origin {
    /// Measurement CSV text named `source`, read with these defaults.
    Text {
        source: String,
        text: Arc<str>,
        defaults: MeasurementDefaults,
    },
    /// The arrays given to `from_arrays`: the series labels and the columns of
    /// [`ARRAY_COLUMNS`], in its order; `text` is the measurement file written from them.
    Arrays {
        series: Vec<String>,
        columns: Vec<Vec<f64>>,
        text: Arc<str>,
    },
}

/// The numeric arguments of `from_arrays`, in order.
const ARRAY_COLUMNS: [&str; 7] = [
    "xi",
    "delta_deg",
    "v",
    "sigma_v",
    "rho",
    "f",
    "sigma_delta_deg",
];

/// The name data given as arrays go by in warnings and reports (a line N is element N - 2).
const ARRAYS_NAME: &str = "<arrays>";

impl PyDataset {
    /// The data set of measurement CSV `text`, read as `m` with `defaults`.
    fn of_file(m: MeasurementFile, text: Arc<str>, defaults: MeasurementDefaults) -> Self {
        let warnings = m
            .plausibility()
            .iter()
            .map(|w| format!("{}: {w}", m.source()))
            .collect();
        let origin = Origin::Text {
            source: m.source().to_string(),
            text,
            defaults,
        };
        PyDataset {
            inner: m.dataset().clone(),
            warnings,
            file: m,
            origin,
        }
    }

    /// Parses CSV `bytes` named `source` with `defaults` (checked first).
    fn parsed(source: &str, bytes: &[u8], defaults: MeasurementDefaults) -> PyResult<Self> {
        let d = defaults.checked().map_err(|e| value_error(e.to_string()))?;
        let m =
            MeasurementFile::parse(source, bytes, &d).map_err(|e| value_error(e.to_string()))?;
        // A table that parsed is UTF-8 (its cells are text).
        let text = String::from_utf8_lossy(bytes);
        Ok(PyDataset::of_file(m, Arc::from(text.as_ref()), d))
    }
}

/// The defaults of the columns a file leaves out, with ρ, f and g given.
fn defaults_of(rho: f64, f: f64, g: f64) -> MeasurementDefaults {
    MeasurementDefaults {
        rho,
        f,
        g,
        ..MeasurementDefaults::default()
    }
}

#[pymethods]
impl PyDataset {
    /// Reads a measurement CSV exactly as the command line does (same columns, units and
    /// error messages).
    #[staticmethod]
    #[pyo3(signature = (path, rho=0.4, f=0.1, g=9.81))]
    fn from_csv(path: &str, rho: f64, f: f64, g: f64) -> PyResult<Self> {
        let d = defaults_of(rho, f, g)
            .checked()
            .map_err(|e| value_error(e.to_string()))?;
        let path = std::path::Path::new(path);
        match std::fs::read(path) {
            Ok(bytes) => PyDataset::parsed(&path.display().to_string(), &bytes, d),
            // The reader's own message for a file it cannot read.
            Err(_) => Err(value_error(match MeasurementFile::read(path, &d) {
                Err(e) => e.to_string(),
                Ok(_) => format!("{}: cannot read", path.display()),
            })),
        }
    }

    /// Parses CSV text (named `source` in errors), as `from_csv` reads a file.
    #[staticmethod]
    #[pyo3(signature = (text, source, rho=0.4, f=0.1, g=9.81))]
    fn from_text(text: &str, source: &str, rho: f64, f: f64, g: f64) -> PyResult<Self> {
        PyDataset::parsed(source, text.as_bytes(), defaults_of(rho, f, g))
    }

    /// The same measurements read again with these defaults for the columns their rows leave
    /// out (`None` keeps the reader's default: ρ 0.4, f 0.1, g 9.81 m/s², σ_δ 0 degrees).
    #[pyo3(signature = (rho=None, f=None, g=None, sigma_delta=None))]
    fn with_defaults(
        &self,
        rho: Option<f64>,
        f: Option<f64>,
        g: Option<f64>,
        sigma_delta: Option<f64>,
    ) -> PyResult<Self> {
        let base = MeasurementDefaults::default();
        let d = MeasurementDefaults {
            rho: rho.unwrap_or(base.rho),
            f: f.unwrap_or(base.f),
            g: g.unwrap_or(base.g),
            sigma_delta_deg: sigma_delta.unwrap_or(base.sigma_delta_deg),
        }
        .checked()
        .map_err(|e| value_error(e.to_string()))?;
        let m = self
            .file
            .with_defaults(&d)
            .map_err(|e| value_error(e.to_string()))?;
        let (Origin::Text { text, .. } | Origin::Arrays { text, .. }) = &self.origin;
        Ok(PyDataset::of_file(m, text.clone(), d))
    }

    /// The columns fitbead does not read that look misspelt or misnamed (close to a known
    /// name, or named like an uncertainty), as the command line warns about them.
    #[getter]
    fn column_warnings(&self) -> PyResult<Vec<String>> {
        self.file
            .unknown_columns(false)
            .map_err(|e| value_error(e.to_string()))
    }

    /// Refuses a column fitbead does not read, as `--strict-columns` does (the error names the
    /// column and the known name it is close to).
    fn check_strict_columns(&self) -> PyResult<()> {
        self.file
            .unknown_columns(true)
            .map(|_| ())
            .map_err(|e| value_error(e.to_string()))
    }

    /// The shipped synthetic data set (data/default.csv).
    #[staticmethod]
    fn default_data() -> PyResult<Self> {
        let m = MeasurementFile::parse(
            MeasurementFile::DEFAULT_DATA_NAME,
            MeasurementFile::DEFAULT_DATA.as_bytes(),
            &MeasurementDefaults::default(),
        )
        .map_err(|e| value_error(e.to_string()))?;
        Ok(PyDataset {
            inner: RsDataset::default_data(),
            warnings: Vec::new(),
            file: m,
            origin: Origin::Text {
                source: MeasurementFile::DEFAULT_DATA_NAME.to_string(),
                text: Arc::from(MeasurementFile::DEFAULT_DATA),
                defaults: MeasurementDefaults::default(),
            },
        })
    }

    /// From flat arrays; `sigma_v` NaN everywhere for no σ (then relative weights).
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        series: Vec<String>,
        xi: PyReadonlyArray1<'_, f64>,
        delta_deg: PyReadonlyArray1<'_, f64>,
        v: PyReadonlyArray1<'_, f64>,
        sigma_v: PyReadonlyArray1<'_, f64>,
        rho: PyReadonlyArray1<'_, f64>,
        f: PyReadonlyArray1<'_, f64>,
        sigma_delta_deg: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Self> {
        let n = slice(&xi, "xi")?.len();
        check_len("series", series.len(), n)?;
        let [xs, d, vs, ss, rs, fs, sd] = slices_of([
            (&xi, "xi"),
            (&delta_deg, "delta_deg"),
            (&v, "v"),
            (&sigma_v, "sigma_v"),
            (&rho, "rho"),
            (&f, "f"),
            (&sigma_delta_deg, "sigma_delta_deg"),
        ])?;
        if let Some(i) = sd.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
            return Err(value_error(format!(
                "sigma_delta_deg[{i}] = {}: the slope's standard uncertainty must be finite and \
                 >= 0 (degrees; 0: the slope is exact)",
                sd[i]
            )));
        }
        let slopes = sd.iter().any(|x| *x > 0.0);
        let mut rows = Vec::with_capacity(n);
        // The same points as a measurement file, for the command line's checks of the data
        // (plausibility) and for the report: every number written in its shortest round-trip
        // form, so that the file reads back the same doubles.
        let sigma = ss.iter().any(|x| !x.is_nan());
        let mut text = String::from("series,xi,delta_deg,v,rho,f");
        if sigma {
            text.push_str(",sigma_v");
        }
        if slopes {
            text.push_str(",sigma_delta_deg");
        }
        text.push('\n');
        for (i, label) in series.iter().enumerate() {
            let scene =
                scene_of(i, xs, d, rs, fs, CollisionLaw::Value(0.5)).map_err(value_error)?;
            let (v, s) = measured(i, vs, ss).map_err(value_error)?;
            rows.push((label.clone(), scene, v, s));
        }
        let mut inner = RsDataset::new(rows).map_err(|e| value_error(e.to_string()))?;
        for (p, s) in inner.points.iter_mut().zip(sd) {
            p.sigma_delta = s.to_radians();
        }
        for (i, label) in series.iter().enumerate() {
            let quoted = format!("\"{}\"", label.replace('"', "\"\""));
            text.push_str(&quoted);
            for x in [xs[i], d[i], vs[i], rs[i], fs[i]] {
                text.push(',');
                text.push_str(&fitbead::numfmt::fmt_f64(x));
            }
            if sigma {
                text.push(',');
                if !ss[i].is_nan() {
                    text.push_str(&fitbead::numfmt::fmt_f64(ss[i]));
                }
            }
            if slopes {
                text.push(',');
                text.push_str(&fitbead::numfmt::fmt_f64(sd[i]));
            }
            text.push('\n');
        }
        let m = MeasurementFile::parse(
            ARRAYS_NAME,
            text.as_bytes(),
            &MeasurementDefaults::default(),
        )
        .map_err(|e| value_error(e.to_string()))?;
        let warnings = m
            .plausibility()
            .iter()
            .map(|w| format!("{ARRAYS_NAME}: {w}"))
            .collect();
        let origin = Origin::Arrays {
            series,
            columns: [xs, d, vs, ss, rs, fs, sd].map(<[f64]>::to_vec).to_vec(),
            text: Arc::from(text),
        };
        Ok(PyDataset {
            inner,
            warnings,
            file: m,
            origin,
        })
    }

    /// The K inversion of every point (as `invert_k` over arrays, from the points' own
    /// scenes: no round trip of δ through degrees).
    #[pyo3(signature = (model, tol=1e-10))]
    fn invert_k<'py>(
        &self,
        py: Python<'py>,
        model: &str,
        tol: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (model, auto) = k_model(model, tol)?;
        let p = &self.inner.points;
        let slopes = p.iter().any(|q| q.sigma_delta > 0.0);
        let mut cols = k_columns(auto.is_some(), slopes);
        let abs = self.has_sigma();
        fill_interruptible(py, p.len(), &mut cols, |i, sink| {
            let q = &p[i];
            let sigma = abs.then_some(q.sigma);
            let slope = slopes.then_some(q.sigma_delta);
            k_record(sink, &model, auto.as_ref(), &q.scene, (q.v, sigma), slope);
            Ok(())
        })?;
        cols.into_dict(py)
    }

    /// The columns of the file that the data set converts away, as text cells per point (one
    /// list per column present): `v_m_s`, `sigma_v_m_s`, `R_m`, `g`.
    fn file_columns(&self) -> Vec<(String, Vec<String>)> {
        ["v_m_s", "sigma_v_m_s", "R_m", "g"]
            .iter()
            .filter_map(|c| self.file.column(c).map(|v| (c.to_string(), v)))
            .collect()
    }

    /// What the data set was made from, as plain values, to make it again: for measurement
    /// CSV text, `{"origin": "text", "source", "text", "rho", "f", "g", "sigma_delta"}` (give
    /// `from_text` the text, source, ρ, f, g, then `with_defaults` σ_δ); for arrays,
    /// `{"origin": "arrays", "series", "xi", "delta_deg", "v", "sigma_v", "rho", "f",
    /// "sigma_delta_deg"}` (give them to `from_arrays`).
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        match &self.origin {
            Origin::Text {
                source,
                text,
                defaults,
            } => {
                d.set_item("origin", "text")?;
                d.set_item("source", source)?;
                d.set_item("text", text.as_ref())?;
                d.set_item("rho", defaults.rho)?;
                d.set_item("f", defaults.f)?;
                d.set_item("g", defaults.g)?;
                d.set_item("sigma_delta", defaults.sigma_delta_deg)?;
            }
            Origin::Arrays {
                series, columns, ..
            } => {
                d.set_item("origin", "arrays")?;
                d.set_item("series", series)?;
                for (name, c) in ARRAY_COLUMNS.iter().zip(columns) {
                    d.set_item(name, PyArray1::from_slice(py, c))?;
                }
            }
        }
        Ok(d)
    }

    /// Number of points.
    fn __len__(&self) -> usize {
        self.inner.points.len()
    }

    /// The command line's plausibility warnings on the data read (unit mistakes: slopes in
    /// radians, velocities in m/s or mm/s, radii in millimetres).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The series labels, in order of first appearance.
    #[getter]
    fn labels(&self) -> Vec<String> {
        self.inner.labels.clone()
    }

    /// Whether the points carry absolute σ (else relative weights).
    #[getter]
    fn has_sigma(&self) -> bool {
        self.inner.sigma == fitbead::inverse::SigmaKind::Absolute
    }

    /// The points as columns: series index, ξ, δ (degrees), v, σ (NaN without), ρ, f.
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.inner.points;
        let abs = self.has_sigma();
        let d = PyDict::new(py);
        let col = |g: &dyn Fn(&fitbead::fit::data::Point) -> f64| -> Vec<f64> {
            p.iter().map(g).collect()
        };
        d.set_item(
            "series_index",
            PyArray1::from_vec(py, p.iter().map(|q| q.series as i64).collect()),
        )?;
        d.set_item("xi", PyArray1::from_vec(py, col(&|q| q.scene.xi())))?;
        d.set_item(
            "delta_deg",
            PyArray1::from_vec(py, col(&|q| q.scene.delta_deg())),
        )?;
        d.set_item("v", PyArray1::from_vec(py, col(&|q| q.v)))?;
        d.set_item(
            "sigma_v",
            PyArray1::from_vec(py, col(&|q| if abs { q.sigma } else { f64::NAN })),
        )?;
        d.set_item("rho", PyArray1::from_vec(py, col(&|q| q.scene.rho())))?;
        d.set_item("f", PyArray1::from_vec(py, col(&|q| q.scene.f())))?;
        Ok(d)
    }
}

/// One fit's result: the library's `FitResult`.
#[pyclass(module = "fitbead._fitbead", name = "_FitResult", frozen)]
struct PyFitResult {
    inner: RsFitResult,
}

#[pymethods]
impl PyFitResult {
    /// The fit report (as the command line prints it).
    fn report(&self) -> String {
        self.inner.to_string()
    }

    /// The fit's name (e.g. `stickslip law c`) and series (empty for a global fit).
    fn name(&self) -> (String, String) {
        (
            self.inner.stats.fit.clone(),
            self.inner.stats.series.clone(),
        )
    }

    /// One dict per parameter, keyed by the columns of the parameter report (params.csv):
    /// the same record the command line writes; an empty cell is None.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let l = PyList::empty(py);
        for p in &self.inner.params {
            l.append(record_dict(py, &ParamRecord::from(p))?)?;
        }
        Ok(l)
    }

    /// Each parameter's box (lower, upper), in the order of `params`.
    fn param_bounds(&self) -> Vec<(f64, f64)> {
        self.inner.params.iter().map(|p| p.bounds).collect()
    }

    /// The value each parameter's least-squares fit started from (None where the fit does not
    /// say), in the order of `params`.
    fn param_starts(&self) -> Vec<Option<f64>> {
        self.inner.params.iter().map(|p| p.start).collect()
    }

    /// Whether each parameter was held at its value (`fix`), in the order of `params`.
    fn param_fixed(&self) -> Vec<bool> {
        self.inner.params.iter().map(|p| p.fixed).collect()
    }

    /// Fit statistics, keyed by the columns of the statistics report (stats.csv): the same
    /// record the command line writes; an empty cell is None.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        record_dict(py, &StatsRecord::from(&self.inner.stats.with_misfit_note()))
    }

    /// One dict per fitted point, keyed by the columns of residuals.csv (the command line's
    /// record).
    fn residual_records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let l = PyList::empty(py);
        for (r, p) in ResidualRecord::of(&[&self.inner])
            .iter()
            .zip(&self.inner.points)
        {
            let d = record_dict(py, r)?;
            // A fit that took the slopes as measured with error: the adjusted slope too.
            if p.delta_fit_deg.is_some() {
                d.set_item("delta_fit_deg", p.delta_fit_deg)?;
                d.set_item("delta_residual", p.delta_residual)?;
            }
            l.append(d)?;
        }
        Ok(l)
    }

    /// One dict per pair of parameters, keyed by the columns of correlations.csv (the command
    /// line's record).
    fn correlation_records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let l = PyList::empty(py);
        for r in CorrelationRecord::of(&[&self.inner]) {
            l.append(record_dict(py, &r)?)?;
        }
        Ok(l)
    }

    /// The warning the command line prints when the misfit is implausible for the σ given
    /// (reduced χ² far above 1: a unit mistake), or None.
    fn absurd_misfit(&self) -> Option<String> {
        self.inner.stats.absurd_misfit()
    }

    /// The warning the command line prints when the misfit is absurd (a unit mistake) or
    /// improbable for the σ given (χ² tail probability below 0.001), or None.
    fn misfit_warning(&self) -> Option<String> {
        self.inner.stats.misfit_warning()
    }

    /// The χ² tail probability P(χ²_dof ≥ χ²) with σ given, or None (unit weights, no degree
    /// of freedom).
    fn chi2_p_value(&self) -> Option<f64> {
        self.inner.stats.chi2_p_value()
    }

    /// The correlation matrix of the parameters (rows in the order of `params`), or None.
    fn correlation(&self) -> Option<Vec<Vec<f64>>> {
        self.inner.correlation.clone()
    }

    /// The fitted points as columns.
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.inner.points;
        let d = PyDict::new(py);
        let col = |g: &dyn Fn(&fitbead::fit::summary::PointFit) -> f64| -> Vec<f64> {
            p.iter().map(g).collect()
        };
        d.set_item(
            "series",
            PyList::new(py, p.iter().map(|q| q.series.as_str()))?,
        )?;
        d.set_item("xi", PyArray1::from_vec(py, col(&|q| q.xi)))?;
        d.set_item("delta_deg", PyArray1::from_vec(py, col(&|q| q.delta_deg)))?;
        d.set_item("v", PyArray1::from_vec(py, col(&|q| q.v)))?;
        d.set_item("sigma_v", PyArray1::from_vec(py, col(&|q| opt(q.sigma_v))))?;
        d.set_item("v_fit", PyArray1::from_vec(py, col(&|q| q.v_fit)))?;
        d.set_item("residual", PyArray1::from_vec(py, col(&|q| q.residual)))?;
        d.set_item(
            "normalised_residual",
            PyArray1::from_vec(py, col(&|q| q.normalised_residual)),
        )?;
        // A fit that took the slopes as measured with error: the adjusted slopes too.
        if p.iter().any(|q| q.delta_fit_deg.is_some()) {
            let fitted = col(&|q| opt(q.delta_fit_deg));
            d.set_item("delta_fit_deg", PyArray1::from_vec(py, fitted))?;
            let moved = col(&|q| opt(q.delta_residual));
            d.set_item("delta_residual", PyArray1::from_vec(py, moved))?;
        }
        Ok(d)
    }

    /// The posterior draws `[walker, kept step, parameter]`, their log posterior
    /// `[walker, kept step]`, the burn-in, the thinning and whether the run was interrupted;
    /// None for a least-squares fit.
    #[allow(clippy::type_complexity)]
    fn draws<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<
        Option<(
            Bound<'py, PyArray3<f64>>,
            Bound<'py, numpy::PyArray2<f64>>,
            usize,
            usize,
            bool,
        )>,
    > {
        let Some(d) = &self.inner.draws else {
            return Ok(None);
        };
        let chains = PyArray3::from_vec3(py, &d.chains)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        let lp = numpy::PyArray2::from_vec2(py, &d.log_posterior)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(Some((chains, lp, d.burn_in, d.thin, d.interrupted)))
    }
}

/// The estimation settings shared by the fit functions, as their keywords give them.
struct MethodArgs {
    method: Method,
    level: f64,
    stop: Arc<AtomicBool>,
}

/// The keywords of the posterior runs that are not the sampler's options, and the controls
/// of the parameters (`fix`, `init`, `bounds`, `scale_covar`).
struct Sampling {
    thin: Option<usize>,
    priors: Vec<(String, String)>,
    fit_scatter: bool,
    fix: Vec<(String, f64)>,
    init: Vec<(String, f64)>,
    bounds: Vec<(String, (f64, f64))>,
    scale_covar: bool,
}

#[allow(clippy::too_many_arguments)]
fn method_args(
    method: &str,
    level: f64,
    profile: bool,
    seed: u64,
    walkers: Option<usize>,
    max_steps: Option<usize>,
    min_ess: Option<f64>,
    sampling: Sampling,
) -> PyResult<MethodArgs> {
    let stop = Arc::new(AtomicBool::new(false));
    let method = match method.to_ascii_lowercase().as_str() {
        "lsq" => {
            let sampler_only = [
                ("thin", sampling.thin.is_some()),
                ("priors", !sampling.priors.is_empty()),
                ("fit_scatter", sampling.fit_scatter),
            ];
            if let Some((name, _)) = sampler_only.iter().find(|k| k.1) {
                return Err(value_error(format!(
                    "{name}: applies to method = 'mcmc' only"
                )));
            }
            Method::Lsq {
                profile,
                stop: Some(stop.clone()),
                progress: None,
                scale_covar: sampling.scale_covar,
                fix: sampling.fix,
                init: sampling.init,
                bounds: sampling.bounds,
            }
        }
        "mcmc" => {
            if sampling.scale_covar {
                return Err(value_error(
                    "scale_covar: applies to method = 'lsq' only (a posterior run has no \
                     covariance to scale)",
                ));
            }
            let mut s = McmcSettings::seeded(seed);
            if let Some(w) = walkers {
                s.options.walkers = Some(w);
            }
            if let Some(m) = max_steps {
                s.options.max_steps = m;
            }
            if let Some(e) = min_ess {
                s.options.min_ess = e;
            }
            if let Some(t) = sampling.thin {
                s.options.thin = t;
            }
            s.options.check().map_err(|e| value_error(e.to_string()))?;
            s.options.stop = Some(stop.clone());
            for (name, dist) in sampling.priors {
                let prior = dist
                    .parse::<fitbead::prelude::Prior>()
                    .map_err(|e| value_error(format!("prior = '{name}={dist}': {e}")))?;
                s.priors.push((name, prior));
            }
            s.fit_scatter = sampling.fit_scatter;
            s.fix = sampling.fix;
            s.init = sampling.init;
            s.bounds = sampling.bounds;
            Method::Mcmc(Box::new(s))
        }
        _ => {
            return Err(value_error(format!(
                "method = '{method}': expected lsq or mcmc"
            )))
        }
    };
    Ok(MethodArgs {
        method,
        level,
        stop,
    })
}

/// Runs `work` without the GIL on a scoped thread (on rayon's threads through [`on_pool`]),
/// checking for Ctrl-C every 100 ms; on an interrupt the stop flag is raised, the run finishes
/// cleanly and `KeyboardInterrupt` is raised.
fn interruptible<T: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    match interruptible_keep(py, stop, work)? {
        (_, Some(e)) => Err(e),
        (r, None) => Ok(r),
    }
}

/// [`interruptible`], keeping what the work made after an interrupt: that, and the
/// exception a signal handler raised (KeyboardInterrupt for Ctrl-C, or the handler's own)
/// when one did.
fn interruptible_keep<T: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<(T, Option<PyErr>)> {
    let slot: (Mutex<Option<Result<T, String>>>, Condvar) = (Mutex::new(None), Condvar::new());
    std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let r = on_pool(work);
            *slot.0.lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
            slot.1.notify_all();
        });
        let mut interrupted: Option<PyErr> = None;
        loop {
            let got = py.detach(|| {
                let g = slot.0.lock().unwrap_or_else(|e| e.into_inner());
                let (mut g, _) = slot
                    .1
                    .wait_timeout_while(g, Duration::from_millis(100), |v| v.is_none())
                    .unwrap_or_else(|e| e.into_inner());
                g.take()
            });
            if let Some(r) = got {
                return match (r, interrupted) {
                    (Ok(r), e) => Ok((r, e)),
                    (Err(_), Some(e)) => Err(e),
                    (Err(msg), None) => Err(PyRuntimeError::new_err(msg)),
                };
            }
            if worker.is_finished() && slot.0.lock().map(|g| g.is_none()).unwrap_or(true) {
                let _ = worker.join();
                return Err(PyRuntimeError::new_err(
                    "the fit failed unexpectedly (panic)",
                ));
            }
            if interrupted.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::SeqCst);
                    interrupted = Some(e);
                }
            }
        }
    })
}

/// What a fit function returns to the Python layer: the fits, the run's notes, the draws
/// CSV when it was asked for, and the exception of a signal (Ctrl-C's KeyboardInterrupt, or
/// a handler's own) that cut a posterior run short, its draws so far kept in the fits.
type Fitted = (
    Vec<PyFitResult>,
    Vec<String>,
    Option<Vec<u8>>,
    Option<PyErr>,
);

/// Runs the fit command `command` of the library on `data` without the GIL, interruptibly:
/// the fits, their draws as the command line's `--draws` CSV when `draws`, and the run's
/// notes. With `warn`, each note is also a `FitbeadWarning` (`fitbead COMMAND: note`, as the
/// command line prints it), raised as it would be printed: before an error as well.
///
/// A signal during the run stops it; what it kept (a posterior run's draws so far, its rows
/// marked interrupted) comes back with the signal's exception, which is raised where nothing
/// was kept.
fn run_fit(
    py: Python<'_>,
    data: &PyDataset,
    command: FitCommand,
    a: MethodArgs,
    draws: bool,
    warn: bool,
) -> PyResult<Fitted> {
    let file = &data.file;
    let MethodArgs {
        method,
        level,
        stop,
    } = a;
    let ((r, notes), signal) = interruptible_keep(py, &stop, || {
        let mut notes = Vec::new();
        let r = command
            .run(file, method, level, None, &mut |n| {
                notes.push(n.to_string())
            })
            .and_then(|run| {
                let d = if draws { Some(run.draws_csv()?) } else { None };
                Ok((run.fits, d))
            });
        (r, notes)
    })?;
    if warn && !notes.is_empty() {
        let category = py.import("fitbead._api")?.getattr("FitbeadWarning")?;
        for n in &notes {
            let text = std::ffi::CString::new(format!("fitbead {}: {n}", command.name()))
                .map_err(|e| value_error(e.to_string()))?;
            PyErr::warn(py, &category, &text, 2)?;
        }
    }
    match (r, signal) {
        (Ok((fits, d)), signal) => {
            let fits = fits
                .into_iter()
                .map(|inner| PyFitResult { inner })
                .collect();
            Ok((fits, notes, d, signal))
        }
        (Err(_), Some(e)) => Err(e),
        (Err(e), None) => Err(pipeline_error(e)),
    }
}

/// A K(α) law fitted across series (see the Python `fitbead.fit_klaw`): the law's fit and the
/// impact law's (unless the law is impact), the notes, and the draws CSV when `draws`.
#[pyfunction]
#[pyo3(signature = (data, model="stickslip", law="c", method="lsq", level=0.95, profile=true, seed=1, walkers=None, max_steps=None, min_ess=None, tol=1e-10, thin=None, priors=vec![], fit_scatter=false, skip_unsteady=false, draws=false, fix=vec![], init=vec![], bounds=vec![], scale_covar=false))]
#[allow(clippy::too_many_arguments)]
fn fit_klaw(
    py: Python<'_>,
    data: &PyDataset,
    model: &str,
    law: &str,
    method: &str,
    level: f64,
    profile: bool,
    seed: u64,
    walkers: Option<usize>,
    max_steps: Option<usize>,
    min_ess: Option<f64>,
    tol: f64,
    thin: Option<usize>,
    priors: Vec<(String, String)>,
    fit_scatter: bool,
    skip_unsteady: bool,
    draws: bool,
    fix: Vec<(String, f64)>,
    init: Vec<(String, f64)>,
    bounds: Vec<(String, (f64, f64))>,
    scale_covar: bool,
) -> PyResult<Fitted> {
    let (_, auto) = k_model(model, tol)?;
    let kind = if auto.is_some() {
        ModelKind::Auto
    } else {
        model
            .parse::<ModelKind>()
            .map_err(|e| value_error(format!("model = '{model}': {e}")))?
    };
    let l: KLaw = law
        .parse()
        .map_err(|e: String| value_error(format!("law = '{law}': {e}")))?;
    let command = FitCommand::Klaw {
        model: kind,
        law: l,
        tol,
        skip_unsteady,
    };
    let sampling = Sampling {
        thin,
        priors,
        fit_scatter,
        fix,
        init,
        bounds,
        scale_covar,
    };
    let a = method_args(
        method, level, profile, seed, walkers, max_steps, min_ess, sampling,
    )?;
    run_fit(py, data, command, a, draws, true)
}

/// Jan's λ and μ per series and the global laws (see the Python `fitbead.fit_jan`).
#[pyfunction]
#[pyo3(signature = (data, method="lsq", level=0.95, profile=true, seed=1, walkers=None, max_steps=None, min_ess=None, thin=None, priors=vec![], fit_scatter=false, draws=false, fix=vec![], init=vec![], bounds=vec![], scale_covar=false))]
#[allow(clippy::too_many_arguments)]
fn fit_jan(
    py: Python<'_>,
    data: &PyDataset,
    method: &str,
    level: f64,
    profile: bool,
    seed: u64,
    walkers: Option<usize>,
    max_steps: Option<usize>,
    min_ess: Option<f64>,
    thin: Option<usize>,
    priors: Vec<(String, String)>,
    fit_scatter: bool,
    draws: bool,
    fix: Vec<(String, f64)>,
    init: Vec<(String, f64)>,
    bounds: Vec<(String, (f64, f64))>,
    scale_covar: bool,
) -> PyResult<Fitted> {
    let command = FitCommand::Jan;
    let sampling = Sampling {
        thin,
        priors,
        fit_scatter,
        fix,
        init,
        bounds,
        scale_covar,
    };
    let a = method_args(
        method, level, profile, seed, walkers, max_steps, min_ess, sampling,
    )?;
    run_fit(py, data, command, a, draws, false)
}

/// Jaeger's a1–a3 per series (see the Python `fitbead.fit_jaeger`).
#[pyfunction]
#[pyo3(signature = (data, branch="upper", method="lsq", level=0.95, profile=true, seed=1, walkers=None, max_steps=None, min_ess=None, thin=None, priors=vec![], fit_scatter=false, draws=false, fix=vec![], init=vec![], bounds=vec![], scale_covar=false))]
#[allow(clippy::too_many_arguments)]
fn fit_jaeger(
    py: Python<'_>,
    data: &PyDataset,
    branch: &str,
    method: &str,
    level: f64,
    profile: bool,
    seed: u64,
    walkers: Option<usize>,
    max_steps: Option<usize>,
    min_ess: Option<f64>,
    thin: Option<usize>,
    priors: Vec<(String, String)>,
    fit_scatter: bool,
    draws: bool,
    fix: Vec<(String, f64)>,
    init: Vec<(String, f64)>,
    bounds: Vec<(String, (f64, f64))>,
    scale_covar: bool,
) -> PyResult<Fitted> {
    let b: JaegerBranch = branch
        .parse()
        .map_err(|e: String| value_error(format!("branch = '{branch}': {e}")))?;
    let command = FitCommand::Jaeger { branch: b };
    let sampling = Sampling {
        thin,
        priors,
        fit_scatter,
        fix,
        init,
        bounds,
        scale_covar,
    };
    let a = method_args(
        method, level, profile, seed, walkers, max_steps, min_ess, sampling,
    )?;
    run_fit(py, data, command, a, draws, false)
}

/// The quantile at probability `p` of Student's t on `dof` degrees of freedom (the scale of
/// `FitResult.eval_uncertainty`, as lmfit's).
#[pyfunction]
fn t_quantile(p: f64, dof: f64) -> PyResult<f64> {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    if !(p > 0.0 && p < 1.0) {
        return Err(value_error(format!(
            "p = {p}: expected a probability in (0, 1)"
        )));
    }
    let t = StudentsT::new(0.0, 1.0, dof).map_err(|e| value_error(format!("dof = {dof}: {e}")))?;
    Ok(t.inverse_cdf(p))
}

/// The columns of records `R`: the keys [`Cell::each`] visits, in order.
fn columns<R: serde::Serialize + Default>() -> Vec<&'static str> {
    let mut v = Vec::new();
    Cell::each(&R::default(), |k, _| v.push(k));
    v
}

/// The column names of the command line's CSV report `kind`: `params`, `stats`,
/// `residuals` or `correlations` (the records both write).
#[pyfunction]
fn record_columns(kind: &str) -> PyResult<Vec<String>> {
    match kind {
        "params" => Ok(columns::<ParamRecord>()),
        "stats" => Ok(columns::<StatsRecord>()),
        "residuals" => Ok(columns::<ResidualRecord>()),
        "correlations" => Ok(columns::<CorrelationRecord>()),
        "regimes" => Ok(columns::<RegimeRecord>()),
        _ => Err(value_error(format!(
            "kind = {kind:?}: expected params, stats, residuals, correlations or regimes"
        ))),
    }
    .map(|c| c.into_iter().map(String::from).collect())
}

/// The column names of the command line's `forward` output under `model` (after the input's
/// own columns), or of its `k` output (the input columns with an output of their own first;
/// auto's two when `model` is auto; `sigma_K` before them when `slopes`, as for rows with slope
/// errors): `command` is `forward` or `k`.
#[pyfunction]
#[pyo3(signature = (command, model, slopes=false))]
fn output_columns(command: &str, model: &str, slopes: bool) -> PyResult<Vec<String>> {
    let kind = model
        .parse::<ModelKind>()
        .map_err(|e| value_error(e.to_string()))?;
    use fitbead::pipeline::{ForwardSettings, TableCommand};
    let table = match command {
        "forward" => TableCommand::Forward {
            settings: ForwardSettings {
                kind,
                ..ForwardSettings::default()
            },
            strict_columns: false,
        },
        "k" => TableCommand::K {
            model: kind,
            tol: 1e-10,
            // Any σ_δ above 0 gives the rows the column σ_K.
            defaults: MeasurementDefaults {
                sigma_delta_deg: if slopes { 1.0 } else { 0.0 },
                ..MeasurementDefaults::default()
            },
            check_columns: false,
            strict_columns: false,
            plot: false,
        },
        _ => {
            return Err(value_error(format!(
                "command = {command:?}: expected forward or k"
            )))
        }
    };
    let Some(names) = table.columns() else {
        return Err(value_error(format!(
            "model = {model:?}: the columns of md follow its settings"
        )));
    };
    Ok(names.into_iter().map(String::from).collect())
}

/// An experimental design (`fitbead design`): the settings as the command line's flags, the
/// result as a dict of plain values (rows as columns).
#[pyfunction]
#[pyo3(signature = (fit, model=None, law="c=0.5", series=vec![0.8, 1.0, 1.6, 2.0], points=9, noise=0.02, noise_absolute=false, delta_range=None, criterion="d", target=None, vs=None, branch="upper", rho=0.4, f=0.1, priors=vec![], draws=64, seed=1, total=None, sigma_delta=0.0, margin=0.05))]
#[allow(clippy::too_many_arguments)]
fn design<'py>(
    py: Python<'py>,
    fit: &str,
    model: Option<&str>,
    law: &str,
    series: Vec<f64>,
    points: usize,
    noise: f64,
    noise_absolute: bool,
    delta_range: Option<(f64, f64)>,
    criterion: &str,
    target: Option<String>,
    vs: Option<&str>,
    branch: &str,
    rho: f64,
    f: f64,
    priors: Vec<(String, String)>,
    draws: usize,
    seed: u64,
    total: Option<usize>,
    sigma_delta: f64,
    margin: f64,
) -> PyResult<Bound<'py, PyDict>> {
    use fitbead::design::{Criterion, DesignFit, DesignSettings};
    let priors = priors
        .into_iter()
        .map(|(name, dist)| {
            dist.parse::<fitbead::prelude::Prior>()
                .map(|p| (name.clone(), p))
                .map_err(|e| value_error(format!("prior = '{name}={dist}': {e}")))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let kind = |name: &str, v: &str| {
        v.parse::<ModelKind>()
            .map_err(|e| value_error(format!("{name} = '{v}': {e}")))
    };
    let settings = DesignSettings {
        fit: fit
            .parse::<DesignFit>()
            .map_err(|e| value_error(format!("fit = '{fit}': {e}")))?,
        model: model.map(|m| kind("model", m)).transpose()?,
        law: parse_law(law)?,
        series,
        rho,
        f,
        points,
        noise,
        noise_absolute,
        delta_range,
        criterion: criterion
            .parse::<Criterion>()
            .map_err(|e| value_error(format!("criterion = '{criterion}': {e}")))?,
        target,
        vs: vs.map(|m| kind("vs", m)).transpose()?,
        branch: branch
            .parse()
            .map_err(|e: String| value_error(format!("branch = '{branch}': {e}")))?,
        priors,
        draws,
        seed,
        total,
        sigma_delta,
        margin,
        ..DesignSettings::default()
    };
    let r = py
        .detach(|| on_pool(|| fitbead::design::design(&settings)))
        .map_err(PyRuntimeError::new_err)?
        .map_err(|e| {
            // The setting named as the keyword argument that gives it.
            let name = keyword(e.setting);
            value_error(format!("{name} = '{}': {}", e.value, e.message))
        })?;
    let d = PyDict::new(py);
    let rows = |rows: &[fitbead::design::DesignRow]| -> PyResult<Bound<'py, PyDict>> {
        let t = PyDict::new(py);
        t.set_item(
            "series",
            rows.iter().map(|r| r.series.clone()).collect::<Vec<_>>(),
        )?;
        t.set_item("xi", rows.iter().map(|r| r.xi).collect::<Vec<_>>())?;
        t.set_item(
            "delta_deg",
            rows.iter().map(|r| r.delta_deg).collect::<Vec<_>>(),
        )?;
        t.set_item(
            "replicates",
            rows.iter().map(|r| r.replicates).collect::<Vec<_>>(),
        )?;
        Ok(t)
    };
    d.set_item("design", rows(&r.rows)?)?;
    d.set_item("even", rows(&r.even)?)?;
    let errors = PyList::empty(py);
    for e in &r.errors {
        let x = PyDict::new(py);
        x.set_item("parameter", &e.name)?;
        x.set_item("guess", e.guess)?;
        x.set_item("stderr_design", opt(e.design))?;
        x.set_item("stderr_even", opt(e.even))?;
        errors.append(x)?;
    }
    d.set_item("errors", errors)?;
    d.set_item("target", r.target.clone())?;
    d.set_item("efficiency", r.efficiency)?;
    d.set_item("gap", r.gap)?;
    d.set_item("discrimination", r.discrimination)?;
    d.set_item("points_needed", r.points_needed)?;
    d.set_item("ranges", r.ranges.clone())?;
    d.set_item("bayes", r.bayes)?;
    let steady = PyList::empty(py);
    for ranges in &r.steady {
        let x = PyDict::new(py);
        for (name, lo, hi) in ranges {
            x.set_item(name, (*lo, *hi))?;
        }
        steady.append(x)?;
    }
    d.set_item("steady", steady)?;
    Ok(d)
}

/// A run of the library's pipeline without the GIL, interruptibly; its errors as the
/// command line words them.
fn pipeline_error(e: fitbead::pipeline::RunError) -> PyErr {
    match e {
        fitbead::pipeline::RunError::Interrupted => {
            PyKeyboardInterrupt::new_err("interrupted (the run stopped cleanly)")
        }
        e => value_error(e.to_string()),
    }
}

/// Synthetic measurements (`fitbead simulate`): the settings as its flags, the result as the
/// CSV text it writes (see the Python `fitbead.simulate`).
#[pyfunction]
#[pyo3(signature = (model="stickslip", law="adjusted", series=vec![0.8, 1.0, 1.6, 2.0], points=9, noise=0.02, seed=1, rho=0.4, f=0.1, jan=None, jaeger=None, branch="upper", delta_range=None, design=None, v0=None, delta_deg=None, beads=None, spin="roll", md_preset="ristow", sigma_delta=0.0))]
#[allow(clippy::too_many_arguments)]
fn simulate(
    py: Python<'_>,
    model: &str,
    law: &str,
    series: Vec<f64>,
    points: usize,
    noise: f64,
    seed: u64,
    rho: f64,
    f: f64,
    jan: Option<[f64; 4]>,
    jaeger: Option<[f64; 3]>,
    branch: &str,
    delta_range: Option<(f64, f64)>,
    design: Option<std::path::PathBuf>,
    v0: Option<f64>,
    delta_deg: Option<f64>,
    beads: Option<usize>,
    spin: &str,
    md_preset: &str,
    sigma_delta: f64,
) -> PyResult<String> {
    use fitbead::models::md::{Md, MdParams, MdRunConfig};
    use fitbead::pipeline::SimulateSettings;
    let kind = model
        .parse::<ModelKind>()
        .map_err(|_| value_error(format!("model = '{model}': unknown model")))?;
    let spin: SpinRule = spin.parse().map_err(|e: fitbead::scene::ParameterError| {
        value_error(format!("spin = '{spin}': {e}"))
    })?;
    let params = match md_preset.to_ascii_lowercase().as_str() {
        "ristow" => MdParams::ristow(),
        "steel" => MdParams::steel(),
        _ => {
            return Err(value_error(format!(
                "md_preset = '{md_preset}': expected ristow or steel"
            )))
        }
    };
    let stop = Arc::new(AtomicBool::new(false));
    let settings = SimulateSettings {
        model: kind,
        law: parse_law(law)?,
        series,
        points,
        noise,
        seed,
        rho,
        f,
        jan,
        jaeger,
        branch: branch
            .parse()
            .map_err(|e: String| value_error(format!("branch = '{branch}': {e}")))?,
        delta_range,
        design,
        v0,
        delta_deg,
        beads,
        spin,
        md: Md {
            params,
            config: MdRunConfig::default(),
        },
        sigma_delta,
        stop: Some(stop.clone()),
        ..SimulateSettings::default()
    };
    let r = interruptible(py, &stop, || settings.run())?;
    let bytes = r.map_err(pipeline_error)?;
    String::from_utf8(bytes).map_err(|e| value_error(e.to_string()))
}

/// The report (`fitbead report`) of `data`: every file (name, bytes) in the order written,
/// the warnings of the run (implausible misfits, posterior runs that did not converge) and
/// whether a posterior run was cut short; the directory written
/// when `out_dir` is given (see the Python `fitbead.report`).
#[pyfunction]
#[pyo3(signature = (data, out_dir=None, method="lsq", format="svg", units="dimensionless", figure_width=None, level=0.95, seed=None, min_ess=None, max_steps=None, keep_going=false, g=9.81))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn report(
    py: Python<'_>,
    data: &PyDataset,
    out_dir: Option<std::path::PathBuf>,
    method: &str,
    format: &str,
    units: &str,
    figure_width: Option<String>,
    level: f64,
    seed: Option<u64>,
    min_ess: Option<f64>,
    max_steps: Option<usize>,
    keep_going: bool,
    g: f64,
) -> PyResult<(
    Vec<(String, Vec<u8>)>,
    Vec<String>,
    Vec<String>,
    Vec<String>,
    bool,
    String,
    Option<PyErr>,
)> {
    use fitbead::inverse::posterior::Method;
    use fitbead::pipeline::ReportSettings;
    let stop = Arc::new(AtomicBool::new(false));
    let m = match method.to_ascii_lowercase().as_str() {
        "lsq" => {
            if seed.is_some() || min_ess.is_some() || max_steps.is_some() {
                return Err(value_error(
                    "seed, min_ess and max_steps apply to method = 'mcmc' only",
                ));
            }
            Method::Lsq {
                profile: true,
                stop: Some(stop.clone()),
                progress: None,
                scale_covar: false,
                fix: Vec::new(),
                init: Vec::new(),
                bounds: Vec::new(),
            }
        }
        "mcmc" => {
            let mut s = McmcSettings::seeded(seed.unwrap_or(1));
            if let Some(e) = min_ess {
                s.options.min_ess = e;
            }
            if let Some(m) = max_steps {
                s.options.max_steps = m;
            }
            s.options.check().map_err(|e| value_error(e.to_string()))?;
            s.options.stop = Some(stop.clone());
            Method::Mcmc(Box::new(s))
        }
        _ => {
            return Err(value_error(format!(
                "method = '{method}': expected lsq or mcmc"
            )))
        }
    };
    let si_units = match units.to_ascii_lowercase().as_str() {
        "dimensionless" => false,
        "si" => true,
        _ => {
            return Err(value_error(format!(
                "units = '{units}': expected dimensionless or si"
            )))
        }
    };
    let defaults = MeasurementDefaults {
        g,
        ..MeasurementDefaults::default()
    }
    .checked()
    .map_err(|e| value_error(e.to_string()))?;
    let settings = ReportSettings {
        level,
        method: m,
        format: format.to_string(),
        si_units,
        figure_width,
        keep_going,
        defaults,
        stop: Some(stop.clone()),
        ..ReportSettings::default()
    };
    let file = &data.file;
    let dir = out_dir.as_deref();
    // A signal that cut a posterior run short comes back with the report of the draws so
    // far (written to `dir` as the command line writes it); where nothing was kept, it is
    // raised.
    let (out, signal) = match interruptible_keep(py, &stop, || settings.run(file, dir))? {
        (Ok(out), signal) => (out, signal),
        (Err(_), Some(e)) => return Err(e),
        (Err(e), None) => return Err(pipeline_error(e)),
    };
    // The warnings by kind: implausible misfits (unit mistakes), posterior runs that did not
    // converge.
    let absurd: Vec<String> = out
        .stats
        .iter()
        .filter_map(|s| {
            s.absurd_misfit()
                .map(|w| format!("{} [{}]: {w}", s.fit, s.series))
        })
        .collect();
    let misfits = out.misfits;
    let unconverged: Vec<String> = out
        .warnings
        .iter()
        .filter(|w| !absurd.contains(w) && !misfits.contains(w))
        .cloned()
        .collect();
    Ok((
        out.files,
        absurd,
        misfits,
        unconverged,
        out.interrupted,
        out.summary,
        signal,
    ))
}

/// `fitbead forward --model md` on the CSV text of a scene table, under the md preset: the CSV
/// text it writes.
#[pyfunction]
#[pyo3(signature = (table, rho=0.4, f=0.1, md_preset="ristow"))]
fn forward_md(py: Python<'_>, table: &str, rho: f64, f: f64, md_preset: &str) -> PyResult<String> {
    use fitbead::models::md::{Md, MdParams, MdRunConfig};
    let params = match md_preset.to_ascii_lowercase().as_str() {
        "ristow" => MdParams::ristow(),
        "steel" => MdParams::steel(),
        _ => {
            return Err(value_error(format!(
                "md_preset = '{md_preset}': expected ristow or steel"
            )))
        }
    };
    let md = Md {
        params,
        config: MdRunConfig::default(),
    };
    let stop = Arc::new(AtomicBool::new(false));
    let command = fitbead::pipeline::TableCommand::ForwardMd {
        md,
        flags: Default::default(),
        rho,
        f,
        check_step: false,
        strict_columns: false,
    };
    let options = fitbead::pipeline::StreamOptions {
        stop: Some(stop.clone()),
        ..command.options()
    };
    let r = interruptible(py, &stop, || {
        let mut out = Vec::new();
        command
            .run(
                "<arrays>",
                table.as_bytes(),
                &mut out,
                &options,
                &mut |_| {},
            )
            .map(|_| out)
    })?;
    let bytes = r.map_err(pipeline_error)?;
    String::from_utf8(bytes).map_err(|e| value_error(e.to_string()))
}

/// The work-precision table of `fitbead bench` as the CSV text of its `--output`.
#[pyfunction]
#[pyo3(signature = (scenes=2000, seed=1))]
fn work_precision(py: Python<'_>, scenes: usize, seed: u64) -> PyResult<String> {
    let stop = Arc::new(AtomicBool::new(false));
    let r = interruptible(py, &stop, || {
        fitbead::pipeline::Bench::run(scenes, seed, Some(&stop))
    })?;
    let bytes = r.and_then(|b| b.csv()).map_err(pipeline_error)?;
    String::from_utf8(bytes).map_err(|e| value_error(e.to_string()))
}

#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// Threads rayon uses (set `RAYON_NUM_THREADS` before the first call to change it): those of
/// the pool the work of this process runs on ([`on_pool`]).
#[pyfunction]
fn threads() -> PyResult<usize> {
    on_pool(rayon::current_num_threads).map_err(PyRuntimeError::new_err)
}

#[pymodule]
fn _fitbead(m: &Bound<'_, PyModule>) -> PyResult<()> {
    LOAD_PID.store(std::process::id(), Ordering::Release);
    m.add_function(wrap_pyfunction!(forward, m)?)?;
    m.add_function(wrap_pyfunction!(invert_k, m)?)?;
    m.add_function(wrap_pyfunction!(regimes, m)?)?;
    m.add_function(wrap_pyfunction!(fit_klaw, m)?)?;
    m.add_function(wrap_pyfunction!(fit_jan, m)?)?;
    m.add_function(wrap_pyfunction!(fit_jaeger, m)?)?;
    m.add_function(wrap_pyfunction!(t_quantile, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(record_columns, m)?)?;
    m.add_function(wrap_pyfunction!(output_columns, m)?)?;
    m.add_function(wrap_pyfunction!(design, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    m.add_function(wrap_pyfunction!(work_precision, m)?)?;
    m.add_function(wrap_pyfunction!(forward_md, m)?)?;
    m.add("FitbeadError", m.py().get_type::<FitbeadError>())?;
    m.add_function(wrap_pyfunction!(threads, m)?)?;
    m.add_class::<PyDataset>()?;
    m.add_class::<PyFitResult>()?;
    Ok(())
}
