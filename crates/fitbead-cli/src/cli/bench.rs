//! `fitbead bench`: the work-precision report of the library's door [`Bench::run`], as CSV
//! and SVG.

use super::args::{OutputArgs, PlotArgs};
use super::{emit, CliError};
use fitbead::io::AtomicFile;
use fitbead::pipeline::Bench;

/// Arguments of `fitbead bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of scenes drawn across regime B (about 30 % of them a hard subset: near δ_m,
    /// near Θ0 = 0, near the upper K limit).
    #[arg(long, default_value_t = 2000, value_parser = super::values::scenes)]
    pub scenes: usize,
    /// Seed of the scene draw.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// With --plot: the work-precision diagram, log time per evaluation against log maximum
    /// error.
    #[command(flatten)]
    pub plot: PlotArgs,
}

/// Runs `fitbead bench`.
pub fn run(a: Args) -> Result<(), CliError> {
    let stop = super::stop_flag();
    let b = Bench::run(a.scenes, a.seed, Some(&stop))?;
    eprint!("{}", b.summary());
    let bytes = b.csv()?;
    let svg = match &a.plot.plot {
        Some(p) => b.figure(p).map_err(|e| CliError::Other(e.to_string()))?,
        None => Vec::new(),
    };
    // The plot and the CSV file are written as one group: both or neither.
    let files: Vec<(&std::path::Path, &[u8])> = a
        .plot
        .plot
        .iter()
        .map(|p| (p.as_path(), svg.as_slice()))
        .chain(a.out.output.iter().map(|p| (p.as_path(), bytes.as_slice())))
        .collect();
    if !files.is_empty() {
        AtomicFile::write_files(&files)
            .map_err(|e| CliError::Other(format!("cannot write: {e}")))?;
    }
    if a.out.output.is_none() {
        emit(None, &bytes)?;
    }
    Ok(())
}
