//! Flags shared by several commands, declared once here and flattened into each command's
//! arguments: the measurements file with the defaults of the columns it may leave out (ρ, f,
//! g, σ_δ), the output file, the figure and the interval level.

use super::values;
use fitbead::io::measurements::MeasurementDefaults;
use std::path::{Path, PathBuf};

/// `--rho` and `--f`: the defaults of rows without a `rho` or `f` column.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ContactArgs {
    /// Gyration parameter ρ (2/5 sphere, 1/2 cylinder) of rows without a rho column
    /// [default: 0.4]
    #[arg(long, value_parser = values::non_negative)]
    pub rho: Option<f64>,
    /// Coulomb friction coefficient f of rows without an f column [default: 0.1]
    #[arg(long, value_parser = values::non_negative)]
    pub f: Option<f64>,
}

impl ContactArgs {
    /// ρ given, or 0.4.
    pub fn rho(&self) -> f64 {
        self.rho.unwrap_or(MeasurementDefaults::default().rho)
    }

    /// f given, or 0.1.
    pub fn f(&self) -> f64 {
        self.f.unwrap_or(MeasurementDefaults::default().f)
    }
}

/// The measurements file (`--input` or a plain argument) and the defaults of the columns it
/// may leave out (`--rho`, `--f`, `--g`, `--sigma-delta`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct DataArgs {
    /// Measurements CSV: series,xi,delta_deg,v[,sigma_v] (v dimensionless, units
    /// sqrt(g (R + r))), or dimensional v_m_s,R_m[,g][,sigma_v_m_s] instead of v; `-` reads
    /// standard input. Without it: the embedded default data set.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// The measurements CSV given as a plain argument (same as --input).
    #[arg(value_name = "DATA.csv", conflicts_with = "input")]
    pub data: Option<PathBuf>,
    /// ρ and f of rows without those columns.
    #[command(flatten)]
    pub contact: ContactArgs,
    /// Gravity g in m/s² of dimensional rows without a g column [default: 9.81]
    #[arg(long, value_parser = values::gravity)]
    pub g: Option<f64>,
    /// Standard uncertainty of the slope, degrees, for rows without a sigma_delta_deg value
    /// (0: slopes exact)
    #[arg(long, value_name = "DEG", value_parser = values::non_negative)]
    pub sigma_delta: Option<f64>,
    /// Refuse a column the measurements file has and fitbead does not read (without it, a
    /// column close to a known name gets a warning, others pass through)
    #[arg(long = "strict-columns")]
    pub strict_columns: bool,
}

impl DataArgs {
    /// The measurements file named, if any.
    pub fn path(&self) -> Option<&Path> {
        self.input.as_deref().or(self.data.as_deref())
    }

    /// g given, or 9.81 m/s².
    pub fn g(&self) -> f64 {
        self.g.unwrap_or(MeasurementDefaults::default().g)
    }

    /// The defaults given (unchecked: [`MeasurementDefaults::checked`]).
    pub fn defaults(&self) -> MeasurementDefaults {
        MeasurementDefaults {
            rho: self.contact.rho(),
            f: self.contact.f(),
            g: self.g(),
            sigma_delta_deg: self
                .sigma_delta
                .unwrap_or(MeasurementDefaults::default().sigma_delta_deg),
        }
    }
}

/// `--output`: the result's file.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct OutputArgs {
    /// Output CSV, written atomically (a temporary file renamed over the target only when the
    /// whole run succeeded); stdout when absent or `-`. A standard stream or open descriptor
    /// (/dev/stdout, /dev/stderr, /proc/self/fd/N) is written through in place, appending when
    /// it was opened to append (`>>`).
    #[arg(long)]
    pub output: Option<PathBuf>,
}

/// `--plot`: the command's figure.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PlotArgs {
    /// Figure of the result (the command's description says what it shows), written
    /// atomically: PNG for a name ending .png, PDF for .pdf, SVG otherwise; `-` writes the SVG
    /// to stdout (only one output may go there: without --output the result takes it).
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// `--level`: the level of every interval.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct LevelArgs {
    /// Confidence level of the intervals, in (0, 1) [default: 0.95]
    #[arg(long, value_parser = values::level)]
    pub level: Option<f64>,
}

impl LevelArgs {
    /// The level given, or 0.95.
    pub fn level(&self) -> f64 {
        self.level.unwrap_or(0.95)
    }
}
