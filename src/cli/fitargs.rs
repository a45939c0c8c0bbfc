//! Flags and I/O shared by the fit commands (`klaw`, `jan`, `jaeger`).

use super::k::{read_rows, Row};
use super::{emit, read_input, CliError};
use crate::fit::data::{DataError, Dataset};
use crate::fit::summary::{params_csv, stats_csv, ParamRow, StatsRow};
use crate::io::scenes::Table;
use crate::io::{fmt_f64, write_atomic_all};
use std::path::PathBuf;

/// Flags common to every fit command.
#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// Measurements CSV: series,xi,delta_deg,v[,sigma_v] (v dimensionless), or dimensional
    /// v_m_s,R_m[,g][,sigma_v_m_s]. Without it: the embedded default data set. Either every row
    /// has sigma_v (absolute errors) or none has (unit weights; the common scale is estimated
    /// from the scatter, χ²/dof).
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// The measurements CSV given as a plain argument (same as --input).
    #[arg(value_name = "DATA.csv", conflicts_with = "input")]
    pub data: Option<PathBuf>,
    /// Gyration parameter ρ, for rows without a rho column.
    #[arg(long, default_value_t = 0.4)]
    pub rho: f64,
    /// Coulomb friction coefficient f, for rows without an f column.
    #[arg(long, default_value_t = 0.1)]
    pub f: f64,
    /// Gravity g in m/s² for dimensional rows without a g column.
    #[arg(long, default_value_t = 9.81)]
    pub g: f64,
    /// Confidence level of the intervals, in (0, 1).
    #[arg(long, default_value_t = 0.95)]
    pub level: f64,
    /// Covariance intervals only (skip the profile-likelihood ones, which cost more fits).
    #[arg(long)]
    pub no_profile: bool,
    /// Parameter report CSV (written atomically): fit,series,parameter,value,stderr,ci_low,
    /// ci_high,ci_method,unit, then extra columns. Stdout when absent.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Fit statistics CSV (written atomically): χ², dof, AIC, BIC, termination per fit.
    /// Printed to stderr as a table when absent.
    #[arg(long)]
    pub output_stats: Option<PathBuf>,
}

impl FitArgs {
    /// Validates the flags and reads the measurements.
    pub fn read(&self) -> Result<(Table, Vec<Row>, Dataset), CliError> {
        if !(self.level > 0.0 && self.level < 1.0) {
            return Err(super::flag_error(
                "--level",
                &self.level.to_string(),
                "must be in (0, 1), e.g. 0.95",
            ));
        }
        let input = self.input.as_deref().or(self.data.as_deref());
        let (source, text) = read_input(input)?;
        let t = Table::parse(&source, &text)?;
        let rows = read_rows(&t, self.rho, self.f, self.g)?;
        let ds = Dataset::new(
            rows.iter()
                .map(|r| (r.series.clone(), r.scene, r.v, r.sigma_v)),
        )
        .map_err(|e| match e {
            DataError::Empty => {
                CliError::Input(crate::io::InputError::file(&t.source, "no data rows"))
            }
            DataError::MixedSigma(i) => {
                let c = t
                    .col("sigma_v")
                    .or_else(|| t.col("sigma_v_m_s"))
                    .unwrap_or(0);
                CliError::Input(t.err(
                    i,
                    c,
                    "sigma missing on this row while other rows have it: give sigma on every \
                     row or on none",
                ))
            }
        })?;
        Ok((t, rows, ds))
    }

    /// Writes the reports: the files given are staged and renamed together (a failure leaves
    /// all of them untouched); the report goes to stdout without `--output`, the statistics to
    /// stderr as a table without `--output-stats`.
    pub fn write(&self, params: &[ParamRow], stats: &[StatsRow]) -> Result<(), CliError> {
        let p_csv = params_csv(params).map_err(|e| CliError::Other(e.to_string()))?;
        let s = stats_csv(stats).map_err(|e| CliError::Other(e.to_string()))?;
        let files: Vec<(&std::path::Path, &[u8])> = self
            .output
            .iter()
            .map(|p| (p.as_path(), p_csv.as_slice()))
            .chain(
                self.output_stats
                    .iter()
                    .map(|q| (q.as_path(), s.as_slice())),
            )
            .collect();
        if !files.is_empty() {
            write_atomic_all(&files).map_err(|e| CliError::Other(format!("cannot write: {e}")))?;
        }
        if self.output_stats.is_none() {
            for r in stats {
                eprintln!(
                    "{} [{}]: chi2 {} dof {} reduced {} AIC {} BIC {} ({}){}",
                    r.fit,
                    r.series,
                    fmt_sig(r.chi2),
                    r.dof,
                    fmt_sig(r.reduced_chi2),
                    fmt_sig(r.aic),
                    fmt_sig(r.bic),
                    r.termination,
                    if r.note.is_empty() {
                        String::new()
                    } else {
                        format!(" — {}", r.note)
                    }
                );
            }
        }
        if self.output.is_none() {
            emit(None, &p_csv)?;
        }
        Ok(())
    }
}

/// Six significant digits for the terminal (the CSV files keep every digit).
fn fmt_sig(x: f64) -> String {
    if x.is_finite() {
        let s = format!("{x:.6e}");
        s.parse::<f64>().map(fmt_f64).unwrap_or(s)
    } else {
        x.to_string()
    }
}
