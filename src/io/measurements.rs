//! Measured mean velocities as a [`Dataset`]: the measurement CSV's columns, its units and
//! their conversion, validated row by row with errors that name file, line, column and value.
//!
//! Columns: `xi`, `delta_deg` (degrees), and either `v` (dimensionless, units sqrt(g (R + r)))
//! with an optional `sigma_v`, or `v_m_s` with `R_m` (the row beads' radius, metres), an
//! optional `g` (m/s²) and an optional `sigma_v_m_s`, converted with
//! v = v_m_s / sqrt(g R (1 + ξ)). Optional `series` (rows without one are grouped by ξ),
//! `rho` and `f` (per-row values of the defaults). A series may not mix ξ values.

use super::scenes::{Header, Row, Table};
use super::InputError;
use crate::fit::data::{DataError, Dataset};
use crate::numfmt::fmt_f64;
use crate::scene::{CollisionLaw, Scene};
use std::collections::HashMap;
use std::path::Path;

/// The shipped default data set (synthetic; provenance in data/README.md).
pub const DEFAULT_DATA: &str = include_str!("../../data/default.csv");
/// The name the default data set goes by in messages.
pub const DEFAULT_DATA_NAME: &str = "<embedded default data: data/default.csv>";

/// Values for the columns a measurement file may leave out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementDefaults {
    /// Gyration parameter ρ (2/5 sphere, 1/2 cylinder) of rows without a `rho` column.
    pub rho: f64,
    /// Coulomb friction coefficient f of rows without an `f` column.
    pub f: f64,
    /// Gravity g (m/s²) of dimensional rows without a `g` column.
    pub g: f64,
}

impl Default for MeasurementDefaults {
    /// ρ = 0.4 (a sphere), f = 0.1, g = 9.81 m/s².
    fn default() -> Self {
        MeasurementDefaults {
            rho: 0.4,
            f: 0.1,
            g: 9.81,
        }
    }
}

impl MeasurementDefaults {
    /// Checks ρ ≥ 0, f ≥ 0 and g > 0, all finite.
    pub fn validate(&self, source: &str) -> Result<(), InputError> {
        let bad = |name: &str, x: f64, message: &str| InputError {
            file: source.to_string(),
            line: None,
            column: Some(name.to_string()),
            value: Some(x.to_string()),
            message: format!("default {message}"),
        };
        for (name, x) in [("rho", self.rho), ("f", self.f)] {
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
pub struct Measurement {
    /// Series label (empty when the file has none).
    pub series: String,
    /// The scene (its K is a placeholder).
    pub scene: Scene,
    /// Dimensionless mean velocity.
    pub v: f64,
    /// Its standard deviation, when given.
    pub sigma_v: Option<f64>,
}

/// Where the measurement columns are in a table (module docs), with the defaults of the
/// columns a table may leave out: reads one row at a time ([`MeasurementColumns::read`]),
/// so that a table streamed in chunks is checked exactly as one read whole.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementColumns {
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
    defaults: MeasurementDefaults,
}

/// One measurement row, validated; its series label is the row's `series` cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// The scene (its K is a placeholder).
    pub scene: Scene,
    /// Dimensionless mean velocity.
    pub v: f64,
    /// Its standard deviation, when given.
    pub sigma_v: Option<f64>,
}

/// What the checks across rows keep: per series, the first ξ and its line (a series may not
/// mix ξ values). Its size grows with the number of series, not of rows.
#[derive(Debug, Clone, Default)]
pub struct SeriesLedger {
    first_xi: HashMap<String, (f64, u64)>,
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
            defaults: *defaults,
        };
        if c.v.is_none() && c.v_m_s.is_none() {
            return Err(t.require("v").unwrap_err());
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

    /// The series label of a row: its `series` cell, empty when the table has none.
    pub fn series<'a>(&self, r: &Row<'a>) -> &'a str {
        self.series.map_or("", |c| r.cell(c))
    }

    /// Reads and validates one row (dimensional input converted with
    /// v = v_m_s / sqrt(g R (1 + ξ))), or reports its first bad value.
    pub fn read(&self, r: &Row<'_>) -> Result<Measured, InputError> {
        let MeasurementDefaults { rho, f, g } = self.defaults;
        let xi = r.number(self.xi)?;
        let d = r.number(self.delta_deg)?;
        let rho = r.opt_number(self.rho)?.unwrap_or(rho);
        let f = r.opt_number(self.f)?.unwrap_or(f);
        let scene = Scene::new(xi, d, rho, f, CollisionLaw::Value(0.5)).map_err(|e| {
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
                    Some(cs) => Some(positive(r, cs, "sigma_v")?),
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
                let s = match (given(self.sigma_v_m_s), given(self.sigma_v)) {
                    (Some(cs), _) => Some(positive(r, cs, "sigma_v_m_s")? / scale),
                    (_, Some(cs)) => Some(positive(r, cs, "sigma_v")?),
                    _ => None,
                };
                (vms / scale, s)
            }
        };
        Ok(Measured { scene, v, sigma_v })
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

fn positive(r: &Row<'_>, c: usize, what: &str) -> Result<f64, InputError> {
    let x = r.number(c)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(r.err(c, format!("{what} must be > 0")))
    }
}

/// Reads and validates the measurements (dimensional input converted with
/// v = v_m_s / sqrt(g R (1 + ξ))).
pub fn read_measurements(
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
        });
    }
    Ok(rows)
}

/// Groups validated measurements into a [`Dataset`]; `t` is the table they were read from
/// (for the location of an error).
pub fn dataset_of(t: &Table, rows: &[Measurement]) -> Result<Dataset, InputError> {
    Dataset::new(
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
    })
}

/// A measurement file read whole: the table, its validated rows and their data set.
#[derive(Debug, Clone)]
pub struct MeasurementFile {
    /// The parsed table (cells as text, with line numbers).
    pub table: Table,
    /// One validated measurement per data row.
    pub rows: Vec<Measurement>,
    /// The rows grouped in series.
    pub dataset: Dataset,
}

impl MeasurementFile {
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

    /// Reads the file at `path`.
    pub fn read(path: &Path, defaults: &MeasurementDefaults) -> Result<Self, InputError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path)
            .map_err(|e| InputError::file(&name, format!("cannot read: {e}")))?;
        Self::parse(&name, &bytes, defaults)
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

    /// The shipped default data set ([`DEFAULT_DATA`]: synthetic, 36 points in 4 series).
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
