//! The door of `fitbead forward` and `fitbead k`: a table in, one output row per input row
//! out. Every model but md streams the rows through the engine of `io::stream` in bounded
//! memory, with the row plans of `forward` (`forward/plan.rs`) and `k` (`k.rs`); md, whose
//! runs are long and few, reads the whole table (`forward/md.rs`).

use super::forward::md::MdTable;
use super::forward::md_runs;
use super::forward::plan::{scene_columns, ForwardPlan, ForwardSettings};
use super::k::{self as kstream, KLedger, KPlan, KSettings};
use super::{figure_bytes, RunError};
use crate::io::measurements::{Implausible, MeasurementDefaults, MEASUREMENT_COLUMNS};
use crate::io::scenes::{check_columns, Header, Table, TableReader};
use crate::io::stream::{stream, StreamError, StreamOptions};
use crate::io::InputError;
use crate::models::auto::Auto;
use crate::models::md::{Md, MdSettings};
use crate::models::{Model, ModelKind};
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// A command that reads a table and writes one output row per input row, with its settings.
#[derive(Debug, Clone)]
#[non_exhaustive]
// One command is built per run: the md variant's size costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum TableCommand {
    /// `fitbead forward` under every model but md: per scene (`xi`, `delta_deg` and the
    /// optional columns of the settings), v̄ and its diagnostics.
    Forward {
        /// The model and the values of rows without the optional columns.
        settings: ForwardSettings,
        /// Refuse a column fitbead does not read (else a column close to a known name is a
        /// warning).
        strict_columns: bool,
    },
    /// `fitbead forward --model md`: one molecular-dynamics run per scene.
    ForwardMd {
        /// The model: a preset with the settings of the command line applied
        /// ([`MdSettings::apply_flags`]).
        md: Md,
        /// The md settings given as flags (a row's cell takes precedence only where no flag
        /// was given).
        flags: MdSettings,
        /// ρ of rows without a `rho` column.
        rho: f64,
        /// f of rows without an `f` column.
        f: f64,
        /// Run every row again at half the time step and report the relative change of v̄
        /// (`md_step_check`).
        check_step: bool,
        /// As for [`TableCommand::Forward`].
        strict_columns: bool,
    },
    /// `fitbead k`: per measurement, the collisional parameter K (eq 69) and its interval at
    /// v ± σ, and why where there is none.
    K {
        /// stick, stick-approx, slip, slip-approx, stickslip, contact, or auto (per row, the
        /// model chosen at the row's stick K).
        model: ModelKind,
        /// With auto: the target relative tolerance on v̄ of the model chosen per row.
        tol: f64,
        /// ρ, f and g of rows without those columns (checked once the header proved good).
        defaults: MeasurementDefaults,
        /// Check the columns (`false` for the shipped data set).
        check_columns: bool,
        /// As for [`TableCommand::Forward`].
        strict_columns: bool,
        /// Keep every inverted point for [`TableRun::plot`] (memory then grows with the
        /// rows).
        plot: bool,
    },
}

/// What a [`TableCommand`] kept once every row was written: `k`'s unit-mistake warnings and
/// the points of its figure.
#[derive(Debug)]
pub struct TableRun {
    ledger: Option<KLedger>,
    model: ModelKind,
}

impl TableRun {
    /// The warnings about data that read fine but look like a unit mistake (`k` only).
    pub fn warnings(&self) -> Vec<Implausible> {
        self.ledger
            .as_ref()
            .map(KLedger::warnings)
            .unwrap_or_default()
    }

    /// `k`'s figure, K against the steady final velocity, one colour per series, with the
    /// K = cos 2α lines (as the paper's Fig. 5), as the bytes of the file `path`: PNG or PDF
    /// when its name ends `.png` or `.pdf`, SVG otherwise. An error for a run that kept no
    /// points (another command, or `plot` not asked for).
    pub fn plot(&self, path: &Path) -> Result<Vec<u8>, RunError> {
        let Some(ledger) = &self.ledger else {
            return Err(RunError::Failed("this run kept no points to plot".into()));
        };
        let svg = ledger.plot_svg(self.model.prose_name())?;
        figure_bytes(path, svg)
    }
}

impl TableCommand {
    /// The columns the command writes, in order, generated from its records: `forward`'s
    /// after the input's own (every model's, then the contact model's or auto's); `k`'s, the
    /// input's columns that have an output of their own, then K's (then `sigma_K` when the
    /// defaults give a slope uncertainty — a table with a `sigma_delta_deg` column gets it
    /// too —, then auto's two under auto), the input's other columns following them. `None`
    /// for md, whose columns follow its settings.
    pub fn columns(&self) -> Option<Vec<&'static str>> {
        match self {
            TableCommand::Forward { settings, .. } => {
                Some(super::forward::plan::output_columns(settings.kind))
            }
            TableCommand::ForwardMd { .. } => None,
            TableCommand::K {
                model, defaults, ..
            } => Some(kstream::output_columns(
                *model == ModelKind::Auto,
                defaults.sigma_delta_deg > 0.0,
            )),
        }
    }

    /// The stream options of the command ([`StreamOptions::default`] with the command's
    /// label and chunk size), for the caller to add its stop flag, progress and input size.
    pub fn options(&self) -> StreamOptions {
        match self {
            TableCommand::K { .. } => StreamOptions {
                chunk_rows: kstream::CHUNK_ROWS,
                label: "k".into(),
                ..StreamOptions::default()
            },
            _ => StreamOptions {
                label: "forward".into(),
                ..StreamOptions::default()
            },
        }
    }

    /// Runs the command on `input`, named `source` in errors, writing the output table to
    /// `out`. The header and the columns are checked first (each warning goes to `warn`),
    /// then the settings, then the rows; the errors of the streamed commands and what is
    /// written before them are those of `io::stream` (docs/ARCHITECTURE.md): a bad row is
    /// [`RunError::Input`], a failed write of `out` [`RunError::Library`] with the I/O error,
    /// and a raised stop flag [`RunError::Interrupted`].
    pub fn run<R: Read + Send>(
        &self,
        source: &str,
        input: R,
        out: &mut (dyn Write + Send),
        options: &StreamOptions,
        warn: &mut dyn FnMut(&str),
    ) -> Result<TableRun, RunError> {
        let mut checked = |t: &dyn Header, known: &[&str], strict: bool| {
            for w in check_columns(t, known, strict)? {
                warn(&w.to_string());
            }
            Ok::<(), InputError>(())
        };
        let streamed = |e: StreamError| match e {
            StreamError::Input(e) => RunError::Input(e),
            StreamError::Write(e) => RunError::Library(e.into()),
            StreamError::Stopped => RunError::Interrupted,
        };
        match self {
            TableCommand::Forward {
                settings,
                strict_columns,
            } => {
                let reader = TableReader::new(source, input)?;
                checked(&reader, &scene_columns(), *strict_columns)?;
                let make = |r: &TableReader<R>| ForwardPlan::checked(r, *settings);
                stream(reader, make, (), out, options).map_err(streamed)?;
                Ok(TableRun {
                    ledger: None,
                    model: settings.kind,
                })
            }
            TableCommand::ForwardMd {
                md,
                flags,
                rho,
                f,
                check_step,
                strict_columns,
            } => {
                let mut bytes = Vec::new();
                let mut input = input;
                input
                    .read_to_end(&mut bytes)
                    .map_err(|e| InputError::file(source, format!("cannot read: {e}")))?;
                let t = Table::parse(source, &bytes)?;
                checked(&t, &scene_columns(), *strict_columns)?;
                let base = MdTable {
                    md: *md,
                    flags: *flags,
                    rho: *rho,
                    f: *f,
                };
                let never = AtomicBool::new(false);
                let stop = options.stop.as_deref().unwrap_or(&never);
                let csv = md_runs(&t, &base, *check_step, options.progress.clone(), stop)?;
                out.write_all(&csv)
                    .map_err(|e| RunError::Library(e.into()))?;
                Ok(TableRun {
                    ledger: None,
                    model: ModelKind::Md,
                })
            }
            TableCommand::K {
                model,
                tol,
                defaults,
                check_columns,
                strict_columns,
                plot,
            } => {
                let reader = TableReader::new(source, input)?;
                if *check_columns {
                    checked(&reader, &MEASUREMENT_COLUMNS, *strict_columns)?;
                }
                let ledger = KLedger::checking(&reader);
                let (fixed, auto) = if *model == ModelKind::Auto {
                    (Model::Stick, Some(Auto { tol: *tol }))
                } else {
                    (model.contact_model().unwrap_or(Model::Stick), None)
                };
                let settings = KSettings {
                    model: fixed,
                    auto,
                    model_name: model.name().to_string(),
                    plot: *plot,
                };
                let make = |r: &TableReader<R>| {
                    let d = defaults.checked()?;
                    KPlan::new(r, &d, settings)
                };
                let done = stream(reader, make, ledger, out, options).map_err(streamed)?;
                Ok(TableRun {
                    ledger: Some(done.ledger),
                    model: *model,
                })
            }
        }
    }
}

impl MdSettings {
    /// `base` with the values given here, validated ([`Md::validate`]), as the command line
    /// applies its flags: a refusal of one of these settings names its flag (`--young-pa`)
    /// and the value given.
    pub fn apply_flags(&self, base: Md) -> Result<Md, RunError> {
        self.apply(base).map_err(|(s, e)| match s {
            Some(s) => super::setting_error(
                &format!("--{}", s.flag()),
                &self.get(s).map(crate::numfmt::fmt_f64).unwrap_or_default(),
                e.to_string(),
            ),
            None => RunError::Failed(e.to_string()),
        })
    }
}
