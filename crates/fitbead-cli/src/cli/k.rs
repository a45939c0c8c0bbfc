//! `fitbead k`: the collisional parameter K of every measured point (eq 69), its interval at
//! v ± σ, and why where there is none.

use super::args::{DataArgs, OutputArgs, PlotArgs};
use super::forward::{open_input, stream_options, stream_to};
use super::values::{self, KModel};
use super::CliError;
use fitbead::io::AtomicFile;
use fitbead::pipeline::TableCommand;
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

/// Runs `fitbead k`: the rows stream through the library's door [`TableCommand::run`];
/// `--plot` keeps the inverted points for the figure.
pub fn run(a: Args) -> Result<(), CliError> {
    let input = a.data.path();
    let command = TableCommand::K {
        model: a.model.kind(),
        tol: a.tol,
        defaults: a.data.defaults(),
        check_columns: input.is_some(),
        strict_columns: a.data.strict_columns,
        plot: a.plot.plot.is_some(),
    };
    let (source, input, size) = open_input(input)?;
    // The plot's file is created first so that a target that cannot be written is reported
    // (after the input proved good) before the output is committed.
    let plot = a.plot.plot.as_deref().map(|p| (p, AtomicFile::create(p)));
    let opts = stream_options(&command, size);
    stream_to(
        &command,
        &source,
        input,
        a.out.output.as_deref(),
        &opts,
        |run| {
            for w in run.warnings() {
                eprintln!("fitbead: warning: {source}: {w}");
            }
            let Some((p, file)) = plot else {
                return Ok(());
            };
            let cannot =
                |e: std::io::Error| CliError::Other(format!("{}: cannot write: {e}", p.display()));
            let bytes = run.plot(p).map_err(|e| CliError::Other(e.to_string()))?;
            let mut f = file.map_err(cannot)?;
            f.write_all(&bytes).map_err(cannot)?;
            f.commit().map_err(cannot)
        },
    )
    .map(|_| ())
}
