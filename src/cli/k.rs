//! `fitbead k`: the collisional parameter K of every measured point (eq 69), its interval at
//! v ± σ, and why where there is none.

use super::args::{DataArgs, OutputArgs, PlotArgs};
use super::forward::{open_input, stream_options, stream_to, Input};
use super::values::{self, KModel};
use super::CliError;
use crate::io::kstream::{self, KLedger, KPlan, KSettings};
use crate::io::scenes::TableReader;
use crate::io::stream::StreamOptions;
use crate::io::{AtomicFile, InputError};
use crate::models::auto::Auto;
use crate::models::Model;
use std::io::Write;

/// Arguments of `fitbead k`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Contact model: stick, stick-approx, slip, slip-approx, stickslip, contact, or auto (per
    /// row the model chosen at the stick K; see --tol).
    #[arg(long, value_parser = values::choice::<KModel>())]
    pub model: KModel,
    /// The measurements and the defaults of the columns they may leave out.
    #[command(flatten)]
    pub data: DataArgs,
    /// Where the table goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// With --plot: K against the steady final velocity, one colour per series, with the cos 2α
    /// lines (as the paper's Fig. 5).
    #[command(flatten)]
    pub plot: PlotArgs,
    /// With --model auto: the target relative tolerance T on v of the model chosen per row.
    #[arg(long, default_value = "1e-10", value_parser = values::tolerance)]
    pub tol: f64,
}

/// The model's name in prose for titles ("stick/slip" for `stickslip`).
pub fn prose_model_name(model: KModel) -> String {
    model.kind().prose_name().to_string()
}

/// The model of `--model` and, for `auto`, the auto model of `--tol` (k and klaw): the model
/// is then stick until the data are read.
pub fn model_of(model: KModel, tol: f64) -> (Model, Option<Auto>) {
    if model == KModel::Auto {
        return (Model::Stick, Some(Auto { tol }));
    }
    // Every other name is one of the five contact models.
    (model.kind().contact_model().unwrap_or(Model::Stick), None)
}

/// Runs `fitbead k`: the rows stream through the library's engine with the K plan of
/// `crate::io::kstream`; `--plot` keeps the inverted points for the figure.
pub fn run(a: Args) -> Result<(), CliError> {
    // Per row, the model chosen at the stick K
    let (model, auto) = model_of(a.model, a.tol);
    let input = a.data.path();
    let (source, input, size) = open_input(input)?;
    let reader = TableReader::new(&source, input)?;
    a.data.check_columns(&reader)?;
    let ledger = KLedger::checking(&reader);
    // Checked here, reported after the table's own errors (as when it was read whole).
    let defaults = a.data.defaults();
    let settings = KSettings {
        model,
        auto,
        model_name: a.model.name(),
        plot: a.plot.plot.is_some(),
    };
    let make = |r: &TableReader<Input>| -> Result<KPlan, InputError> {
        let d = match defaults {
            Ok(d) => d,
            Err(CliError::Input(e)) => return Err(e),
            Err(e) => return Err(InputError::file(crate::io::SETTINGS_ORIGIN, e.to_string())),
        };
        KPlan::new(r, &d, settings)
    };
    // The plot's file is created first so that a target that cannot be written is reported
    // (after the input proved good) before the output is committed.
    let plot = a.plot.plot.as_deref().map(|p| (p, AtomicFile::create(p)));
    let opts = StreamOptions {
        chunk_rows: kstream::CHUNK_ROWS,
        ..stream_options("k", size)
    };
    stream_to(
        reader,
        make,
        ledger,
        a.out.output.as_deref(),
        &opts,
        |ledger| {
            for w in ledger.warnings() {
                eprintln!("fitbead: warning: {source}: {w}");
            }
            let Some((p, file)) = plot else {
                return Ok(());
            };
            let cannot =
                |e: std::io::Error| CliError::Other(format!("{}: cannot write: {e}", p.display()));
            let svg = ledger
                .plot_svg(&prose_model_name(a.model))
                .map_err(|e| CliError::Other(e.to_string()))?;
            let bytes = a.plot.bytes(svg)?;
            let mut f = file.map_err(cannot)?;
            f.write_all(&bytes).map_err(cannot)?;
            f.commit().map_err(cannot)
        },
    )
    .map(|_| ())
}
