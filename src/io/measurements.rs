//! Measured mean velocities as a [`Dataset`]: the measurement CSV's columns, its units and
//! their conversion, validated row by row with errors that name file, line, column and value.
//!
//! Columns: `xi`, `delta_deg` (degrees), and either `v` (dimensionless, units sqrt(g (R + r)))
//! with an optional `sigma_v`, or `v_m_s` with `R_m` (the row beads' radius, metres), an
//! optional `g` (m/s²) and an optional `sigma_v_m_s`, converted with
//! v = v_m_s / sqrt(g R (1 + ξ)). Optional `series` (rows without one are grouped by ξ),
//! `rho` and `f` (per-row values of the defaults). A series may not mix ξ values.

use super::scenes::Table;
use super::InputError;
use crate::fit::data::{DataError, Dataset};
use crate::numfmt::fmt_f64;
use crate::scene::{CollisionLaw, Scene};
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

fn positive(t: &Table, r: usize, c: usize, what: &str) -> Result<f64, InputError> {
    let x = t.number(r, c)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(t.err(r, c, format!("{what} must be > 0")))
    }
}

/// Reads and validates the measurements (dimensional input converted with
/// v = v_m_s / sqrt(g R (1 + ξ))).
pub fn read_measurements(
    t: &Table,
    defaults: &MeasurementDefaults,
) -> Result<Vec<Measurement>, InputError> {
    let MeasurementDefaults { rho, f, g } = *defaults;
    let c_xi = t.require("xi")?;
    let c_d = t.require("delta_deg")?;
    let c_series = t.col("series");
    let c_v = t.col("v");
    let c_vms = t.col("v_m_s");
    let c_sigma = t.col("sigma_v");
    let c_sigma_ms = t.col("sigma_v_m_s");
    let c_r = t.col("R_m");
    let c_g = t.col("g");
    let c_rho = t.col("rho");
    let c_f = t.col("f");
    if c_v.is_none() && c_vms.is_none() {
        return Err(t.require("v").unwrap_err());
    }
    if let (Some(_), Some(cs)) = (c_v, c_sigma_ms) {
        return Err(InputError {
            file: t.source.clone(),
            line: Some(1),
            column: Some(t.headers[cs].clone()),
            value: None,
            message: "sigma_v_m_s is in m/s but v is dimensionless: give v_m_s and R_m with \
                      sigma_v_m_s, or sigma_v with v"
                .into(),
        });
    }
    if c_v.is_none() && c_r.is_none() {
        return Err(t.require("R_m").unwrap_err());
    }
    defaults.validate(&t.source)?;
    let mut first_xi: std::collections::HashMap<String, (f64, u64)> = Default::default();
    let mut rows = Vec::with_capacity(t.rows.len());
    for r in 0..t.rows.len() {
        let xi = t.number(r, c_xi)?;
        let d = t.number(r, c_d)?;
        let rho = t.opt_number(r, c_rho)?.unwrap_or(rho);
        let f = t.opt_number(r, c_f)?.unwrap_or(f);
        let scene = Scene::new(xi, d, rho, f, CollisionLaw::Value(0.5)).map_err(|e| {
            let col = match &e {
                crate::scene::ParameterError::InvalidParameter { field, .. } => match *field {
                    "xi" => Some(c_xi),
                    "delta" | "delta_deg" => Some(c_d),
                    "rho" => c_rho,
                    "f" => c_f,
                    _ => None,
                },
                _ => None,
            };
            match col {
                Some(c) => t.err(r, c, e.to_string()),
                None => InputError {
                    file: t.source.clone(),
                    line: Some(t.lines[r]),
                    column: None,
                    value: None,
                    message: e.to_string(),
                },
            }
        })?;
        let (v, sigma_v) = match c_v {
            Some(c) => {
                let v = positive(t, r, c, "v")?;
                let s = match c_sigma {
                    Some(cs) if !t.cell(r, cs).is_empty() => Some(positive(t, r, cs, "sigma_v")?),
                    _ => None,
                };
                (v, s)
            }
            None => {
                let (c, cr) = (c_vms.unwrap_or(0), c_r.unwrap_or(0));
                let vms = positive(t, r, c, "v_m_s")?;
                let radius = positive(t, r, cr, "R_m")?;
                let gg = match c_g {
                    Some(cg) if !t.cell(r, cg).is_empty() => positive(t, r, cg, "g")?,
                    _ => g,
                };
                let scale = (gg * radius * (1.0 + xi)).sqrt();
                let s = match (c_sigma_ms, c_sigma) {
                    (Some(cs), _) if !t.cell(r, cs).is_empty() => {
                        Some(positive(t, r, cs, "sigma_v_m_s")? / scale)
                    }
                    (_, Some(cs)) if !t.cell(r, cs).is_empty() => {
                        Some(positive(t, r, cs, "sigma_v")?)
                    }
                    _ => None,
                };
                (vms / scale, s)
            }
        };
        let series = c_series
            .map(|c| t.cell(r, c).to_string())
            .unwrap_or_default();
        if let (Some(c), false) = (c_series, series.is_empty()) {
            match first_xi.get(&series) {
                Some(&(x0, line)) if x0 != xi => {
                    return Err(t.err(
                        r,
                        c_xi,
                        format!(
                            "series '{series}' mixes xi values: {} on line {line}, {} here",
                            fmt_f64(x0),
                            fmt_f64(xi)
                        ),
                    ));
                }
                Some(_) => {}
                None => {
                    first_xi.insert(series.clone(), (xi, t.lines[r]));
                }
            }
            let _ = c;
        }
        rows.push(Measurement {
            series,
            scene,
            v,
            sigma_v,
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
