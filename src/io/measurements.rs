//! Measured mean velocities as a [`Dataset`]: the measurement CSV's columns, its units and
//! their conversion, validated row by row with errors that name file, line, column and value.
//!
//! Columns: `xi`, `delta_deg` (degrees), and either `v` (dimensionless, units sqrt(g (R + r)))
//! with an optional `sigma_v`, or `v_m_s` with `R_m` (the row beads' radius, metres), an
//! optional `g` (m/s²) and an optional `sigma_v_m_s`, converted with
//! v = v_m_s / sqrt(g R (1 + ξ)). Optional `series` (rows without one are grouped by ξ),
//! `rho` and `f` (per-row values of the defaults), `sigma_delta_deg` (the standard uncertainty
//! of the slope in degrees, ≥ 0; a missing column or an empty cell takes the default, 0: the
//! slope is exact). A series may not mix ξ values.
//!
//! Units are never guessed: `sigma_v_m_s` beside `v`, `sigma_v` beside `v_m_s`, and `v` beside
//! `v_m_s` with `R_m` are errors. A file can still read fine in the wrong unit (slopes in
//! radians, m/s in the column `v`, `R_m` in millimetres): `plausibility` looks for that with
//! the physics of the rolling model and returns warnings.

use super::scenes::{Header, Row, Table};
use super::InputError;
pub(crate) use crate::fit::data::SiSeries;
use crate::fit::data::{DataError, Dataset};
use crate::last::Last;
use crate::numfmt::fmt_f64;
use crate::scene::{CollisionLaw, Scene};
use std::path::Path;

/// The shipped default data set (synthetic; provenance in data/README.md).
pub(crate) const DEFAULT_DATA: &str = include_str!("../../data/default.csv");
/// The name the default data set goes by in messages.
pub(crate) const DEFAULT_DATA_NAME: &str = "<embedded default data: data/default.csv>";

/// Every column a measurement file may have (module docs), with the columns `fitbead simulate`
/// writes beside them and no reader uses: `delta_true_deg` and `v_true` (the true slope and
/// velocity beside noisy ones) and `v_md_stderr` (the molecular dynamics' standard error); any
/// other passes through `fitbead k` and is otherwise unused ([`super::scenes::check_columns`]).
pub(crate) const MEASUREMENT_COLUMNS: [&str; 15] = [
    "xi",
    "delta_deg",
    "series",
    "v",
    "v_m_s",
    "sigma_v",
    "sigma_v_m_s",
    "R_m",
    "g",
    "rho",
    "f",
    "sigma_delta_deg",
    "delta_true_deg",
    "v_true",
    "v_md_stderr",
];

/// Values for the columns a measurement file may leave out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementDefaults {
    /// Gyration parameter ρ (2/5 sphere, 1/2 cylinder) of rows without a `rho` column.
    pub rho: f64,
    /// Coulomb friction coefficient f of rows without an `f` column.
    pub f: f64,
    /// Gravity g (m/s²) of dimensional rows without a `g` column.
    pub g: f64,
    /// Standard uncertainty of the slope, degrees, of rows without a `sigma_delta_deg` value
    /// (0: the slopes are exact).
    pub sigma_delta_deg: f64,
}

impl Default for MeasurementDefaults {
    /// ρ = 0.4 (a sphere), f = 0.1, g = 9.81 m/s², exact slopes (σ_δ = 0).
    fn default() -> Self {
        MeasurementDefaults {
            rho: 0.4,
            f: 0.1,
            g: 9.81,
            sigma_delta_deg: 0.0,
        }
    }
}

impl MeasurementDefaults {
    /// These defaults as a command line's settings: ρ ≥ 0, f ≥ 0, σ_δ ≥ 0 and g > 0, all
    /// finite, or an error naming `--rho`, `--f`, `--sigma-delta` or `--g` with its value.
    pub fn checked(self) -> Result<Self, InputError> {
        use super::setting_error;
        let non_negative = [
            ("rho", self.rho),
            ("f", self.f),
            ("sigma-delta", self.sigma_delta_deg),
        ];
        for (name, x) in non_negative {
            if !(x >= 0.0 && x.is_finite()) {
                return Err(setting_error(
                    name,
                    &x.to_string(),
                    "must be a finite number >= 0",
                ));
            }
        }
        if !(self.g > 0.0 && self.g.is_finite()) {
            return Err(setting_error("g", &self.g.to_string(), "g must be > 0"));
        }
        Ok(self)
    }

    /// Checks ρ ≥ 0, f ≥ 0, σ_δ ≥ 0 and g > 0, all finite.
    pub fn validate(&self, source: &str) -> Result<(), InputError> {
        let bad = |name: &str, x: f64, message: &str| InputError {
            file: source.to_string(),
            line: None,
            column: Some(name.to_string()),
            value: Some(x.to_string()),
            message: format!("default {message}"),
        };
        let non_negative = [
            ("rho", self.rho),
            ("f", self.f),
            ("sigma_delta_deg", self.sigma_delta_deg),
        ];
        for (name, x) in non_negative {
            if !(x >= 0.0 && x.is_finite()) {
                return Err(bad(name, x, "must be a finite number >= 0"));
            }
        }
        if !(self.g > 0.0 && self.g.is_finite()) {
            return Err(bad("g", self.g, "g must be > 0"));
        }
        Ok(())
    }
}

/// One measurement, validated.
#[derive(Debug, Clone)]
pub(crate) struct Measurement {
    /// Series label (empty when the file has none).
    pub series: String,
    /// The scene (its K is a placeholder).
    pub scene: Scene,
    /// Dimensionless mean velocity.
    pub v: f64,
    /// Its standard deviation, when given.
    pub sigma_v: Option<f64>,
    /// Standard uncertainty of the slope, radians (0: exact).
    pub sigma_delta: f64,
}

/// Where the measurement columns are in a table (module docs), with the defaults of the
/// columns a table may leave out: reads one row at a time ([`MeasurementColumns::read`]),
/// so that a table streamed in chunks is checked exactly as one read whole.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MeasurementColumns {
    xi: usize,
    delta_deg: usize,
    series: Option<usize>,
    v: Option<usize>,
    v_m_s: Option<usize>,
    sigma_v: Option<usize>,
    sigma_v_m_s: Option<usize>,
    r_m: Option<usize>,
    g: Option<usize>,
    rho: Option<usize>,
    f: Option<usize>,
    sigma_delta_deg: Option<usize>,
    defaults: MeasurementDefaults,
}

/// One measurement row, validated; its series label is the row's `series` cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Measured {
    /// The scene (its K is a placeholder).
    pub scene: Scene,
    /// Dimensionless mean velocity.
    pub v: f64,
    /// Its standard deviation, when given.
    pub sigma_v: Option<f64>,
    /// Standard uncertainty of the slope, radians (0: exact).
    pub sigma_delta: f64,
}

/// What the checks across rows keep: per series, the first ξ and its line (a series may not
/// mix ξ values). Its size grows with the number of series, not of rows.
#[derive(Debug, Clone, Default)]
pub(crate) struct SeriesLedger {
    /// The first ξ of each series and its line. Hashed with FxHash, not SipHash: it is looked
    /// up once per row on the ordered side of the stream, one thread at a time.
    first_xi: rustc_hash::FxHashMap<String, (f64, u64)>,
    /// The last series checked, with its first ξ and line.
    last: Option<(String, f64, u64)>,
}

impl MeasurementColumns {
    /// The columns of a table's header: `xi`, `delta_deg`, and `v` or `v_m_s` with `R_m` are
    /// required, `sigma_v_m_s` goes with `v_m_s`; then `defaults` are checked.
    pub fn new(t: &impl Header, defaults: &MeasurementDefaults) -> Result<Self, InputError> {
        let xi = t.require("xi")?;
        let delta_deg = t.require("delta_deg")?;
        let c = MeasurementColumns {
            xi,
            delta_deg,
            series: t.col("series"),
            v: t.col("v"),
            v_m_s: t.col("v_m_s"),
            sigma_v: t.col("sigma_v"),
            sigma_v_m_s: t.col("sigma_v_m_s"),
            r_m: t.col("R_m"),
            g: t.col("g"),
            rho: t.col("rho"),
            f: t.col("f"),
            sigma_delta_deg: t.col("sigma_delta_deg"),
            defaults: *defaults,
        };
        if c.v.is_none() && c.v_m_s.is_none() {
            return Err(t.require("v").unwrap_err());
        }
        let header_error = |c: usize, message: &str| InputError {
            file: t.source().to_string(),
            line: Some(1),
            column: Some(t.headers()[c].clone()),
            value: None,
            message: message.into(),
        };
        if let (Some(_), Some(cm), Some(_)) = (c.v, c.v_m_s, c.r_m) {
            return Err(header_error(
                cm,
                "both v (dimensionless) and v_m_s with R_m (m/s) are given: keep one velocity \
                 column, or rename the other",
            ));
        }
        if let (None, Some(_), Some(cs)) = (c.v, c.v_m_s, c.sigma_v) {
            return Err(header_error(
                cs,
                "sigma_v is dimensionless but the velocities are v_m_s (m/s): with SI velocities \
                 the error column must be sigma_v_m_s (m/s)",
            ));
        }
        if let (Some(_), Some(cs)) = (c.v, c.sigma_v_m_s) {
            return Err(InputError {
                file: t.source().to_string(),
                line: Some(1),
                column: Some(t.headers()[cs].clone()),
                value: None,
                message: "sigma_v_m_s is in m/s but v is dimensionless: give v_m_s and R_m \
                          with sigma_v_m_s, or sigma_v with v"
                    .into(),
            });
        }
        if c.v.is_none() && c.r_m.is_none() {
            return Err(t.require("R_m").unwrap_err());
        }
        defaults.validate(t.source())?;
        Ok(c)
    }

    /// The column of ξ.
    pub fn xi(&self) -> usize {
        self.xi
    }

    /// The column of δ (degrees).
    pub fn delta_deg(&self) -> usize {
        self.delta_deg
    }

    /// Whether rows may carry a slope uncertainty: the table has a `sigma_delta_deg` column,
    /// or the defaults give rows without one a σ_δ > 0.
    pub fn has_slope_errors(&self) -> bool {
        self.sigma_delta_deg.is_some() || self.defaults.sigma_delta_deg > 0.0
    }

    /// The series label of a row: its `series` cell, empty when the table has none.
    pub fn series<'a>(&self, r: &Row<'a>) -> &'a str {
        self.series.map_or("", |c| r.cell(c))
    }

    /// Reads and validates one row (dimensional input converted with
    /// v = v_m_s / sqrt(g R (1 + ξ))), or reports its first bad value.
    pub fn read(&self, r: &Row<'_>) -> Result<Measured, InputError> {
        self.read_like(r, None)
    }

    /// [`MeasurementColumns::read`], its scene built by [`Scene::new_like`] from `like` (the
    /// scene of a row read before, usually the one before it).
    pub fn read_like(&self, r: &Row<'_>, like: Option<&Scene>) -> Result<Measured, InputError> {
        let MeasurementDefaults {
            rho,
            f,
            g,
            sigma_delta_deg,
        } = self.defaults;
        let xi = r.number(self.xi)?;
        let d = r.number(self.delta_deg)?;
        let rho = r.opt_number(self.rho)?.unwrap_or(rho);
        let f = r.opt_number(self.f)?.unwrap_or(f);
        let scene =
            Scene::new_like(like, xi, d, rho, f, CollisionLaw::Value(0.5)).map_err(|e| {
                let col = match &e {
                    crate::scene::ParameterError::InvalidParameter { field, .. } => match *field {
                        "xi" => Some(self.xi),
                        "delta" | "delta_deg" => Some(self.delta_deg),
                        "rho" => self.rho,
                        "f" => self.f,
                        _ => None,
                    },
                    _ => None,
                };
                match col {
                    Some(c) => r.err(c, e.to_string()),
                    None => InputError {
                        file: r.source.to_string(),
                        line: Some(r.line),
                        column: None,
                        value: None,
                        message: e.to_string(),
                    },
                }
            })?;
        let given = |c: Option<usize>| c.filter(|&c| !r.cell(c).is_empty());
        let (v, sigma_v) = match self.v {
            Some(c) => {
                let v = positive(r, c, "v")?;
                let s = match given(self.sigma_v) {
                    Some(cs) => Some(resolvable(
                        r,
                        cs,
                        "sigma_v",
                        positive(r, cs, "sigma_v")?,
                        v,
                    )?),
                    None => None,
                };
                (v, s)
            }
            None => {
                let (c, cr) = (self.v_m_s.unwrap_or(0), self.r_m.unwrap_or(0));
                let vms = positive(r, c, "v_m_s")?;
                let radius = positive(r, cr, "R_m")?;
                let gg = match given(self.g) {
                    Some(cg) => positive(r, cg, "g")?,
                    None => g,
                };
                let scale = (gg * radius * (1.0 + xi)).sqrt();
                let s = match given(self.sigma_v_m_s) {
                    Some(cs) => {
                        let sms = positive(r, cs, "sigma_v_m_s")?;
                        Some(resolvable(r, cs, "sigma_v_m_s", sms, vms)? / scale)
                    }
                    None => None,
                };
                (vms / scale, s)
            }
        };
        let sigma_delta_deg = match given(self.sigma_delta_deg) {
            Some(c) => non_negative(r, c, "sigma_delta_deg")?,
            None => sigma_delta_deg,
        };
        Ok(Measured {
            scene,
            v,
            sigma_v,
            sigma_delta: sigma_delta_deg.to_radians(),
        })
    }

    /// For a row of dimensional velocities (`v_m_s` with `R_m`, no `v`): the row beads' radius
    /// R in metres, g in m/s² and the velocity unit sqrt(g R (1 + ξ)) in m/s that
    /// [`MeasurementColumns::read`] divides by; `None` for a dimensionless row or a cell that
    /// does not read (which `read` reports).
    pub fn velocity_unit(&self, r: &Row<'_>) -> Option<(f64, f64, f64)> {
        if self.v.is_some() {
            return None;
        }
        let xi = r.number(self.xi).ok()?;
        let radius = positive(r, self.r_m?, "R_m").ok()?;
        let g = match self.g.filter(|&c| !r.cell(c).is_empty()) {
            Some(c) => positive(r, c, "g").ok()?,
            None => self.defaults.g,
        };
        Some((radius, g, (g * radius * (1.0 + xi)).sqrt()))
    }

    /// Checks a read row (whose ξ is `xi`) against the rows before it, as `ledger` kept them:
    /// a series may not mix ξ values (the error names the line of the series' first ξ).
    pub fn check_series(
        &self,
        ledger: &mut SeriesLedger,
        r: &Row<'_>,
        xi: f64,
    ) -> Result<(), InputError> {
        let series = self.series(r);
        if self.series.is_none() || series.is_empty() {
            return Ok(());
        }
        // Rows of a series usually follow each other: the last series answers most rows.
        let (x0, line) = match &ledger.last {
            Some((s, x0, line)) if s == series => (*x0, *line),
            _ => {
                let first = match ledger.first_xi.get(series) {
                    Some(&first) => first,
                    None => {
                        ledger.first_xi.insert(series.to_string(), (xi, r.line));
                        (xi, r.line)
                    }
                };
                let last = ledger.last.get_or_insert_with(Default::default);
                last.0.clear();
                last.0.push_str(series);
                (last.1, last.2) = first;
                first
            }
        };
        if x0 != xi {
            return Err(r.err(
                self.xi,
                format!(
                    "series '{series}' mixes xi values: {} on line {line}, {} here",
                    fmt_f64(x0),
                    fmt_f64(xi)
                ),
            ));
        }
        Ok(())
    }
}

/// The smallest σ of a velocity, relative to the velocity, that a fit can resolve: below it σ
/// is finer than the rounding of v and of any model value in double precision (2⁻⁵² ≈
/// 2.2e-16), and χ² would measure rounding alone, or overflow.
pub(crate) const MIN_RELATIVE_SIGMA: f64 = 1e-15;

/// `sigma` (cell `c`, named `what`) if it is at least [`MIN_RELATIVE_SIGMA`] of the velocity
/// `v` it belongs to.
fn resolvable(r: &Row<'_>, c: usize, what: &str, sigma: f64, v: f64) -> Result<f64, InputError> {
    if sigma >= MIN_RELATIVE_SIGMA * v {
        Ok(sigma)
    } else {
        Err(r.err(
            c,
            format!(
                "{what} is below 1e-15 of the velocity it belongs to ({}): finer than the \
                 rounding of any computed velocity, so no fit can resolve it; give the \
                 measurement's real uncertainty",
                fmt_f64(v)
            ),
        ))
    }
}

fn positive(r: &Row<'_>, c: usize, what: &str) -> Result<f64, InputError> {
    let x = r.number(c)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(r.err(c, format!("{what} must be > 0")))
    }
}

fn non_negative(r: &Row<'_>, c: usize, what: &str) -> Result<f64, InputError> {
    let x = r.number(c)?;
    if x >= 0.0 {
        Ok(x)
    } else {
        Err(r.err(c, format!("{what} must be >= 0")))
    }
}

/// Reads and validates the measurements (dimensional input converted with
/// v = v_m_s / sqrt(g R (1 + ξ))).
pub(crate) fn read_measurements(
    t: &Table,
    defaults: &MeasurementDefaults,
) -> Result<Vec<Measurement>, InputError> {
    let cols = MeasurementColumns::new(t, defaults)?;
    let mut ledger = SeriesLedger::default();
    let mut rows = Vec::with_capacity(t.rows.len());
    for r in 0..t.rows.len() {
        let row = t.row(r);
        let m = cols.read(&row)?;
        cols.check_series(&mut ledger, &row, m.scene.xi())?;
        rows.push(Measurement {
            series: cols.series(&row).to_string(),
            scene: m.scene,
            v: m.v,
            sigma_v: m.sigma_v,
            sigma_delta: m.sigma_delta,
        });
    }
    Ok(rows)
}

/// Whether `ds` holds the measurements of the shipped synthetic data set ([`DEFAULT_DATA`]):
/// the same series, ξ, δ, v and σ, exact slopes, whatever ρ and f it was read with.
pub(crate) fn is_shipped_data(ds: &Dataset) -> bool {
    let d = Dataset::default_data();
    ds.labels == d.labels
        && ds.sigma == d.sigma
        && ds.points.len() == d.points.len()
        && ds.points.iter().zip(&d.points).all(|(a, b)| {
            a.series == b.series
                && a.scene.xi == b.scene.xi
                && a.scene.delta_deg() == b.scene.delta_deg()
                && a.v == b.v
                && a.sigma == b.sigma
                && a.sigma_delta == b.sigma_delta
        })
}

/// Per series, in order of first appearance, how the velocities of a table in m/s were made
/// dimensionless (v = v_m_s / sqrt(g R (1 + ξ))); `None` when the velocities were given
/// dimensionless (column `v`). The rows must have been read by [`read_measurements`] with the
/// same `defaults`.
pub(crate) fn si_conversion(t: &Table, defaults: &MeasurementDefaults) -> Option<Vec<SiSeries>> {
    let cols = MeasurementColumns::new(t, defaults).ok()?;
    let mut out: Vec<SiSeries> = Vec::new();
    for i in 0..t.rows.len() {
        let row = t.row(i);
        let (r, g, u) = cols.velocity_unit(&row)?;
        let label = cols.series(&row);
        let label = if label.is_empty() {
            format!("xi={}", fmt_f64(row.number(cols.xi).ok()?))
        } else {
            label.to_string()
        };
        let widen = |a: (f64, f64), x: f64| (a.0.min(x), a.1.max(x));
        match out.iter_mut().find(|s| s.series == label) {
            Some(s) => {
                s.r_m = widen(s.r_m, r);
                s.g = widen(s.g, g);
                s.unit_m_s = widen(s.unit_m_s, u);
            }
            None => out.push(SiSeries {
                series: label,
                xi: row.number(cols.xi).ok()?,
                r_m: (r, r),
                g: (g, g),
                unit_m_s: (u, u),
            }),
        }
    }
    Some(out)
}

/// Groups validated measurements into a [`Dataset`]; `t` is the table they were read from
/// (for the location of an error).
pub(crate) fn dataset_of(t: &Table, rows: &[Measurement]) -> Result<Dataset, InputError> {
    let mut ds = Dataset::new(
        rows.iter()
            .map(|r| (r.series.clone(), r.scene, r.v, r.sigma_v)),
    )
    .map_err(|e| match e {
        DataError::Empty => InputError::file(&t.source, "no data rows"),
        DataError::MixedSigma(i) => {
            let c = t
                .col("sigma_v")
                .or_else(|| t.col("sigma_v_m_s"))
                .unwrap_or(0);
            t.err(
                i,
                c,
                "sigma missing on this row while other rows have it: give sigma on every row \
                 or on none",
            )
        }
    })?;
    // One point per row, in the rows' order.
    for (p, r) in ds.points.iter_mut().zip(rows) {
        p.sigma_delta = r.sigma_delta;
    }
    Ok(ds)
}

/// A measurement file read whole: the table, its validated rows and their data set.
#[derive(Debug, Clone)]
pub struct MeasurementFile {
    /// The parsed table (cells as text, with line numbers).
    pub(crate) table: Table,
    /// One validated measurement per data row.
    pub(crate) rows: Vec<Measurement>,
    /// The rows grouped in series.
    pub(crate) dataset: Dataset,
}

impl MeasurementFile {
    /// The shipped default data set, as CSV (synthetic, 36 points in 4 series).
    pub const DEFAULT_DATA: &'static str = DEFAULT_DATA;

    /// The name of [`MeasurementFile::DEFAULT_DATA`] in messages.
    pub const DEFAULT_DATA_NAME: &'static str = DEFAULT_DATA_NAME;

    /// Reads `bytes`, named `source` in errors, as the command line reads a measurements file
    /// given to it: with `check_columns`, a column fitbead does not read is an error when
    /// `strict`, else a column close to a known name is a warning; the defaults are checked
    /// (ρ ≥ 0, f ≥ 0, σ_δ ≥ 0, g > 0) once the table proved well formed; the data's plausibility
    /// warnings (unit mistakes, [`MeasurementFile::plausibility`]) follow, each preceded by
    /// `source` and `: `. Every warning goes to `warn` as it is found.
    pub fn read_checked(
        source: &str,
        bytes: &[u8],
        defaults: &MeasurementDefaults,
        check_columns: bool,
        strict: bool,
        warn: &mut dyn FnMut(&str),
    ) -> Result<Self, InputError> {
        let table = Table::parse(source, bytes)?;
        if check_columns {
            for w in crate::io::scenes::check_columns(&table, &MEASUREMENT_COLUMNS, strict)? {
                warn(&w.to_string());
            }
        }
        let defaults = defaults.checked()?;
        let rows = read_measurements(&table, &defaults)?;
        let dataset = dataset_of(&table, &rows)?;
        for x in plausibility(&table, &rows) {
            warn(&format!("{source}: {x}"));
        }
        Ok(MeasurementFile {
            table,
            rows,
            dataset,
        })
    }

    /// The columns of the file that fitbead does not read, checked as the command line checks
    /// a measurements file ([`crate::io::scenes::check_columns`]): with `strict`, the first of
    /// them is an error; otherwise those that look like a misspelt or misnamed column (close
    /// to a known name, or named like an uncertainty) are returned, for the caller to warn
    /// about.
    pub fn unknown_columns(
        &self,
        strict: bool,
    ) -> Result<Vec<crate::io::scenes::UnknownColumn>, InputError> {
        crate::io::scenes::check_columns(&self.table, &MEASUREMENT_COLUMNS, strict)
    }

    /// Parses and validates `bytes`, named `source` in errors.
    pub fn parse(
        source: &str,
        bytes: &[u8],
        defaults: &MeasurementDefaults,
    ) -> Result<Self, InputError> {
        let table = Table::parse(source, bytes)?;
        let rows = read_measurements(&table, defaults)?;
        let dataset = dataset_of(&table, &rows)?;
        Ok(MeasurementFile {
            table,
            rows,
            dataset,
        })
    }

    /// The same file read again with `defaults` for the columns its rows leave out (ρ, f,
    /// g, σ_δ).
    pub fn with_defaults(&self, defaults: &MeasurementDefaults) -> Result<Self, InputError> {
        let rows = read_measurements(&self.table, defaults)?;
        let dataset = dataset_of(&self.table, &rows)?;
        Ok(MeasurementFile {
            table: self.table.clone(),
            rows,
            dataset,
        })
    }

    /// Reads the file at `path`.
    pub fn read(path: &Path, defaults: &MeasurementDefaults) -> Result<Self, InputError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path)
            .map_err(|e| InputError::file(&name, format!("cannot read: {e}")))?;
        Self::parse(&name, &bytes, defaults)
    }

    /// The name the file was read under (its path, or the `source` given to
    /// [`MeasurementFile::parse`]), as errors and warnings name it.
    pub fn source(&self) -> &str {
        &self.table.source
    }

    /// The data set: the rows grouped in series.
    pub fn dataset(&self) -> &Dataset {
        &self.dataset
    }

    /// The data set, taking it out of the file.
    pub fn into_dataset(self) -> Dataset {
        self.dataset
    }

    /// The warnings of the command line about data that read fine but look like a unit
    /// mistake (slopes in radians, velocities in m/s in the dimensionless column, row-bead
    /// radii in millimetres), in its order; none when the data look plausible.
    pub fn plausibility(&self) -> Vec<Implausible> {
        plausibility(&self.table, &self.rows)
    }
}

impl Dataset {
    /// Reads a measurement CSV (module docs for its columns and units) with the default ρ,
    /// f and g of [`MeasurementDefaults::default`].
    pub fn from_csv(path: impl AsRef<Path>) -> Result<Dataset, InputError> {
        Self::from_csv_with(path, &MeasurementDefaults::default())
    }

    /// As [`Dataset::from_csv`], with other defaults for the columns a file leaves out.
    pub fn from_csv_with(
        path: impl AsRef<Path>,
        defaults: &MeasurementDefaults,
    ) -> Result<Dataset, InputError> {
        Ok(MeasurementFile::read(path.as_ref(), defaults)?.dataset)
    }

    /// The shipped default data set (`DEFAULT_DATA`: synthetic, 36 points in 4 series).
    pub fn default_data() -> Dataset {
        MeasurementFile::parse(
            DEFAULT_DATA_NAME,
            DEFAULT_DATA.as_bytes(),
            &MeasurementDefaults::default(),
        )
        .map(|m| m.dataset)
        .unwrap_or_else(|e| unreachable!("the embedded data set is valid: {e}"))
    }
}

/// Where point `i` of `ds` (read from `t`, in the same order) is: file, line, series, ξ and
/// δ as written in the file.
pub(crate) fn locate_point(t: &Table, ds: &Dataset, i: usize) -> String {
    let p = &ds.points[i];
    let d = t
        .col("delta_deg")
        .map(|c| t.cell(i, c).to_string())
        .unwrap_or_else(|| fmt_f64(p.scene.delta_deg()));
    format!(
        "{}, line {} (series '{}', xi {}, delta_deg {})",
        t.source,
        t.lines[i],
        crate::numfmt::clip(&ds.labels[p.series], crate::numfmt::ECHO_CHARS),
        fmt_f64(p.scene.xi()),
        d,
    )
}

/// The lines of `t` that hold the points of series `s` of `ds`, as `2, 3, 5`.
pub(crate) fn series_lines(t: &Table, ds: &Dataset, s: usize) -> String {
    ds.series_index(s)
        .iter()
        .map(|&i| t.lines[i].to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// A note of the fits that starts `series 'LABEL': ` located in the file: `FILE, lines …
/// (series 'LABEL'): …`; other notes unchanged.
pub(crate) fn locate_note(t: &Table, ds: &Dataset, note: &str) -> String {
    for (s, label) in ds.labels.iter().enumerate() {
        if let Some(rest) = note.strip_prefix(&format!("series '{label}': ")) {
            return format!(
                "{}, lines {} (series '{}'): {rest}",
                t.source,
                series_lines(t, ds, s),
                crate::numfmt::clip(label, crate::numfmt::ECHO_CHARS)
            );
        }
    }
    note.to_string()
}

/// A warning about measurements that read fine but look like a unit mistake
/// (`plausibility`).
#[derive(Debug, Clone, PartialEq)]
pub struct Implausible {
    /// The column in doubt.
    pub column: String,
    /// What looks wrong and its likely cause.
    pub message: String,
}

impl std::fmt::Display for Implausible {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "column '{}': {}", self.column, self.message)
    }
}

/// Slopes are doubted when every one is below this fraction of the stop slope δ_m (eq 32) of
/// its ξ under the paper's fitted law: no K near the paper's moves a bead there, while the
/// same numbers read as radians usually fall in the steady range.
pub(crate) const SLOPE_FRACTION: f64 = 0.5;

/// Velocities are doubted when their median ratio to the rolling model at the paper's fitted
/// law (over the points inside its steady range) is below 1/`VELOCITY_FACTOR` or above
/// `VELOCITY_FACTOR`. The paper's models agree with measurements within about 40 % (§5.3), and
/// the factor sqrt(g (R + r)) between m/s and the dimensionless unit is below 0.5 for every
/// bead row with R + r < 2.5 cm.
pub(crate) const VELOCITY_FACTOR: f64 = 2.0;

/// Row-bead radii above this (metres) are doubted: beads over 20 cm across; the experiments
/// the paper discusses use millimetre beads (Ristow's R = 2.5 mm).
pub(crate) const MAX_ROW_RADIUS_M: f64 = 0.1;

/// Velocity ratios kept by a [`Plausibility`] at most (the first ones in file order): the
/// median of 10,000 ratios is as telling as that of millions (its standard error is about
/// 1.25/sqrt(10,000) = 1.3 % of the spread), and memory and time stay bounded on streamed
/// files (each ratio costs one rolling-model evaluation).
pub(crate) const MAX_RATIOS: usize = 10_000;

/// Looks for unit mistakes in measurements read from `t`: slopes in radians, velocities in
/// m/s in the dimensionless column, row-bead radii in millimetres. The thresholds come from
/// the rolling model with the paper's fitted law K = cos 2α + ½ sin²α sin 2α
/// (`SLOPE_FRACTION`, `VELOCITY_FACTOR`, `MAX_ROW_RADIUS_M`). Nothing is refused: the
/// caller shows the warnings. A table streamed row by row gets the same checks from a
/// [`Plausibility`].
pub(crate) fn plausibility(t: &Table, rows: &[Measurement]) -> Vec<Implausible> {
    let mut p = Plausibility::new(t);
    for (i, m) in rows.iter().enumerate() {
        let measured = Measured {
            scene: m.scene,
            v: m.v,
            sigma_v: m.sigma_v,
            sigma_delta: m.sigma_delta,
        };
        p.add(&t.row(i), &measured);
    }
    p.warnings()
}

/// What the checks of [`Plausibility`] need of one validated row: its scene's ξ, δ (radians)
/// and ρ, its dimensionless v, the stop and lift-off slopes of its ξ and ρ, and the rolling
/// model's v̄ on its slope when that was computed with the row ([`PlausiblePoint::new`]), as
/// a streamed row's is, in parallel with the other rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PlausiblePoint {
    /// Radius ratio ξ.
    pub xi: f64,
    /// Slope δ (radians).
    pub delta: f64,
    /// Gyration parameter ρ.
    pub rho: f64,
    /// Friction coefficient f.
    pub f: f64,
    /// Dimensionless mean velocity.
    pub v: f64,
    /// δ_m and δ_d (degrees) at the paper's law (eqs 31–32).
    pub limits: (f64, f64),
    /// The rolling model's v̄ at the paper's law on this slope, when computed with the row:
    /// `Some(None)` where it has no steady state or the slope is outside (δ_m, δ_d).
    pub paper_v: Option<Option<f64>>,
}

/// δ_m and δ_d (degrees) at the paper's law for the last (ξ, ρ) seen, which the next row of
/// the same pair reuses (rows of a series usually follow each other).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct StopSlopes(Last<(u64, u64), (f64, f64)>);

impl StopSlopes {
    fn of(&mut self, xi: f64, alpha: f64, rho: f64) -> (f64, f64) {
        use crate::models::regimes::{delta_d_law, delta_m_law};
        *self.0.get((xi.to_bits(), rho.to_bits()), |v| {
            let law = CollisionLaw::Adjusted;
            *v = (
                delta_m_law(alpha, law, rho).to_degrees(),
                delta_d_law(alpha, law, rho).to_degrees(),
            );
        })
    }
}

impl PlausiblePoint {
    /// The point of `m`, its slopes' limits through `slopes`; with `paper_v`, also the
    /// rolling model's v̄ where the slope is between them (what the velocity check needs).
    pub fn new(m: &Measured, slopes: &mut StopSlopes, paper_v: bool) -> Self {
        let s = &m.scene;
        let limits = slopes.of(s.xi(), s.alpha_rad(), s.rho());
        let mut p = PlausiblePoint {
            xi: s.xi(),
            delta: s.delta_rad(),
            rho: s.rho(),
            f: s.f(),
            v: m.v,
            limits,
            paper_v: None,
        };
        if paper_v {
            p.paper_v = Some(p.rolling_v());
        }
        p
    }

    /// The rolling model's v̄ at the paper's law, where the slope is inside (δ_m, δ_d).
    fn rolling_v(&self) -> Option<f64> {
        use crate::models::ForwardModel;
        let d = self.delta.to_degrees();
        let (dm, dd) = self.limits;
        if !(d > dm && d < dd) {
            return None;
        }
        Scene::new(self.xi, d, self.rho, self.f, CollisionLaw::Adjusted)
            .ok()
            .and_then(|sc| crate::models::Model::Stick.evaluate(&sc).ok())
            .map(|o| o.mean_velocity)
    }
}

/// The checks of [`plausibility`], fed one validated row at a time in file order; its memory
/// is bounded (at most `MAX_RATIOS` velocity ratios). [`Plausibility::warnings`] says what it found.
#[derive(Debug, Clone)]
pub(crate) struct Plausibility {
    /// The velocities are `v_m_s` (no column `v`).
    dimensional: bool,
    /// `v` and `v_m_s` without `R_m`: `v` is used.
    both_without_radius: bool,
    r_m: Option<usize>,
    rows: usize,
    all_low: bool,
    all_below_half_pi: bool,
    /// The row with the largest slope: δ (degrees), its line, δ_m there (degrees), ξ.
    largest: Option<(f64, u64, f64, f64)>,
    ratios: Vec<f64>,
    /// The largest `R_m` and its line.
    largest_radius: Option<(f64, u64)>,
    /// δ_m and δ_d of the last (ξ, ρ) seen by [`Plausibility::add`].
    limits: StopSlopes,
}

impl Plausibility {
    /// The checks for a table with `t`'s header.
    pub fn new(t: &impl Header) -> Self {
        Plausibility {
            dimensional: t.col("v").is_none(),
            both_without_radius: t.col("v").is_some()
                && t.col("v_m_s").is_some()
                && t.col("R_m").is_none(),
            r_m: t.col("R_m"),
            rows: 0,
            all_low: true,
            all_below_half_pi: true,
            largest: None,
            ratios: Vec::new(),
            largest_radius: None,
            limits: StopSlopes::default(),
        }
    }

    /// Takes one validated row (`m` read from `r`).
    pub fn add(&mut self, r: &Row<'_>, m: &Measured) {
        let p = PlausiblePoint::new(m, &mut self.limits, false);
        self.add_point(r, &p);
    }

    /// Takes one validated row (read from `r`) by what the checks need of it.
    pub fn add_point(&mut self, r: &Row<'_>, p: &PlausiblePoint) {
        let (dm, dd) = p.limits;
        self.rows += 1;
        let d = p.delta.to_degrees();
        self.all_low &= d < SLOPE_FRACTION * dm;
        self.all_below_half_pi &= d < std::f64::consts::FRAC_PI_2;
        if self.largest.is_none_or(|l| d >= l.0) {
            self.largest = Some((d, r.line, dm, p.xi));
        }
        if self.ratios.len() < MAX_RATIOS && d > dm && d < dd {
            let v = p.paper_v.unwrap_or_else(|| p.rolling_v());
            if let Some(v) = v.filter(|&v| v > 0.0) {
                self.ratios.push(p.v / v);
            }
        }
        if let Some(x) = self.r_m.and_then(|c| r.cell(c).parse::<f64>().ok()) {
            if x > MAX_ROW_RADIUS_M && self.largest_radius.is_none_or(|l| x > l.0) {
                self.largest_radius = Some((x, r.line));
            }
        }
    }

    /// Whether the velocity check has all the rows it takes (`MAX_RATIOS`): a later row's
    /// [`PlausiblePoint::paper_v`] is not needed.
    pub fn has_all_ratios(&self) -> bool {
        self.ratios.len() >= MAX_RATIOS
    }

    /// The warnings so far, in the order slopes, velocities, radii, columns.
    pub fn warnings(&self) -> Vec<Implausible> {
        let mut out = Vec::new();
        if self.rows == 0 {
            return out;
        }
        // Slopes: every one far below the stop slope of its ξ.
        if self.all_low {
            if let Some((d, line, dm, xi)) = self.largest {
                let mut message = format!(
                    "every delta_deg is below {} of the stop slope delta_m of its xi at the \
                     paper's K (the largest, {} on line {}, against delta_m = {} deg at xi = \
                     {}): no steady motion there",
                    fmt_f64(SLOPE_FRACTION),
                    crate::numfmt::fmt_sig(d, 4),
                    line,
                    crate::numfmt::fmt_sig(dm, 4),
                    fmt_f64(xi),
                );
                if self.all_below_half_pi {
                    message.push_str(&format!(
                        "; are these radians? ({} rad = {} deg)",
                        crate::numfmt::fmt_sig(d, 4),
                        crate::numfmt::fmt_sig(d.to_degrees(), 4)
                    ));
                }
                out.push(Implausible {
                    column: "delta_deg".into(),
                    message,
                });
            }
            // The velocities cannot be judged against a model in which nothing moves.
            return out;
        }
        // Velocities: against the rolling model at the paper's K, in its steady range.
        if !self.ratios.is_empty() {
            let mut ratios = self.ratios.clone();
            ratios.sort_by(|a, b| a.total_cmp(b));
            let med = ratios[ratios.len() / 2];
            let what = format!(
                "the velocities are on median {} times the rolling model's at the paper's K \
                 (over the {} point(s) in its steady range)",
                crate::numfmt::fmt_sig(med, 3),
                ratios.len()
            );
            let cause = match (self.dimensional, med < 1.0) {
                (false, true) => {
                    "are these m/s? The column v is dimensionless (units sqrt(g (R + r))): \
                     give v_m_s and R_m instead"
                }
                (false, false) => "are these cm/s, or in another unit than sqrt(g (R + r))?",
                (true, true) => "is R_m in millimetres? It must be in metres",
                (true, false) => "is R_m too small (in km?) or v_m_s in cm/s or mm/s?",
            };
            if !(1.0 / VELOCITY_FACTOR..=VELOCITY_FACTOR).contains(&med) {
                out.push(Implausible {
                    column: if self.dimensional { "v_m_s" } else { "v" }.into(),
                    message: format!("{what}; {cause}"),
                });
            }
        }
        // Row-bead radii.
        if let Some((x, line)) = self.largest_radius {
            out.push(Implausible {
                column: "R_m".into(),
                message: format!(
                    "R_m = {} m on line {line}: row beads over {} m across; are these \
                     millimetres? R_m is in metres ({} mm = {} m)",
                    fmt_f64(x),
                    fmt_f64(2.0 * MAX_ROW_RADIUS_M),
                    fmt_f64(x),
                    fmt_f64(x / 1000.0),
                ),
            });
        }
        // Both velocity columns without R_m: the dimensionless one is used.
        if self.both_without_radius {
            out.push(Implausible {
                column: "v_m_s".into(),
                message: "ignored: the dimensionless column v is used (v_m_s would need R_m)"
                    .into(),
            });
        }
        out
    }
}

#[cfg(test)]
mod slope_error_tests {
    use super::*;

    fn parse(text: &str, defaults: &MeasurementDefaults) -> Result<MeasurementFile, InputError> {
        MeasurementFile::parse("m.csv", text.as_bytes(), defaults)
    }

    /// A bad `sigma_delta_deg` cell is refused with the file, line, column and value.
    #[test]
    fn bad_slope_uncertainties_are_located() {
        for (cell, message) in [
            ("-0.5", "sigma_delta_deg must be >= 0"),
            ("NaN", "finite"),
            ("inf", "finite"),
            ("abc", "not a number"),
        ] {
            let text = format!(
                "series,xi,delta_deg,v,sigma_delta_deg\na,1,12,0.3,0.1\na,1,14,0.4,{cell}\n"
            );
            let e = parse(&text, &MeasurementDefaults::default()).unwrap_err();
            assert_eq!(e.file, "m.csv", "{cell}: {e}");
            assert_eq!(e.line, Some(3), "{cell}: {e}");
            assert_eq!(e.column.as_deref(), Some("sigma_delta_deg"), "{cell}: {e}");
            assert_eq!(e.value.as_deref(), Some(cell), "{cell}: {e}");
            assert!(e.message.contains(message), "{cell}: {e}");
        }
    }

    /// The points carry σ_δ in radians; an empty cell or a missing column takes the default.
    #[test]
    fn slope_uncertainties_reach_the_points_in_radians() {
        let text = "series,xi,delta_deg,v,sigma_delta_deg\na,1,12,0.3,0.5\na,1,14,0.4,\n\
                    a,1,16,0.5,0\n";
        let ds = parse(text, &MeasurementDefaults::default())
            .unwrap()
            .dataset;
        let got: Vec<f64> = ds.points.iter().map(|p| p.sigma_delta).collect();
        assert_eq!(got, [0.5f64.to_radians(), 0.0, 0.0]);
        assert!(ds.has_slope_errors());
        let d = MeasurementDefaults {
            sigma_delta_deg: 0.25,
            ..MeasurementDefaults::default()
        };
        let ds = parse(text, &d).unwrap().dataset;
        let got: Vec<f64> = ds.points.iter().map(|p| p.sigma_delta).collect();
        assert_eq!(got, [0.5f64.to_radians(), 0.25f64.to_radians(), 0.0]);
        let plain = "series,xi,delta_deg,v\na,1,12,0.3\n";
        let ds = parse(plain, &MeasurementDefaults::default())
            .unwrap()
            .dataset;
        assert!(!ds.has_slope_errors());
        let ds = parse(plain, &d).unwrap().dataset;
        assert_eq!(ds.points[0].sigma_delta, 0.25f64.to_radians());
        // Subsets keep each point's σ_δ.
        assert_eq!(ds.only(0).points[0].sigma_delta, 0.25f64.to_radians());
    }

    /// A default σ_δ must be finite and ≥ 0, named as its flag on the command line.
    #[test]
    fn bad_default_slope_uncertainties_are_refused() {
        for x in [-1.0, f64::NAN, f64::INFINITY] {
            let d = MeasurementDefaults {
                sigma_delta_deg: x,
                ..MeasurementDefaults::default()
            };
            let e = d.checked().unwrap_err();
            assert_eq!(e.column.as_deref(), Some("--sigma-delta"), "{x}: {e}");
            let e = parse("xi,delta_deg,v\n1,12,0.3\n", &d).unwrap_err();
            assert_eq!(e.column.as_deref(), Some("sigma_delta_deg"), "{x}: {e}");
        }
    }

    /// `sigma_delta_deg` and `delta_true_deg` are columns fitbead knows: no near-miss warning,
    /// no refusal under strict columns.
    #[test]
    fn slope_columns_are_known() {
        let text = "series,xi,delta_deg,v,sigma_delta_deg,delta_true_deg\na,1,12,0.3,0.1,12.05\n";
        let mut warnings = Vec::new();
        let m = MeasurementFile::read_checked(
            "m.csv",
            text.as_bytes(),
            &MeasurementDefaults::default(),
            true,
            true,
            &mut |w| warnings.push(w.to_string()),
        )
        .unwrap();
        assert!(
            warnings
                .iter()
                .all(|w| !w.contains("not one fitbead reads")),
            "{warnings:?}"
        );
        assert_eq!(m.dataset.points[0].sigma_delta, 0.1f64.to_radians());
    }
}
