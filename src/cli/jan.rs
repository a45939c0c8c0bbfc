//! `fitbead jan`: Jan's λ and μ per series (eq 74, fitted on v̄) and the global laws
//! λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α} (form of eqs 75–76), beside the paper's values.

use super::fitargs::{FitArgs, LsqPlot};
use super::CliError;
use crate::fit::jan::fit_jan_with;
use crate::fit::summary::FitResult;
use crate::io::measurements::locate_note;
use crate::report::bands::Curve;

/// Arguments of `fitbead jan`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input, output and interval flags.
    #[command(flatten)]
    pub io: FitArgs,
}

/// Runs `fitbead jan`.
pub fn run(a: Args) -> Result<(), CliError> {
    let (t, _rows, ds) = a.io.read()?;
    let choice =
        a.io.method(&["lambda", "mu", "lambda0", "lambda1", "mu0", "mu1"])?;
    let (method, task) = super::counted_fit("jan", choice.method);
    let fits = fit_jan_with(&ds, a.io.level.level(), &method);
    drop(task);
    let notes: Vec<String> = fits.notes.iter().map(|n| locate_note(&t, &ds, n)).collect();
    let all: Vec<&FitResult> = fits
        .series
        .iter()
        .flatten()
        .chain(fits.global.iter())
        .collect();
    if all.iter().all(|f| f.params.is_empty()) {
        if super::stop_requested() {
            return Err(CliError::Interrupted);
        }
        return Err(CliError::Other(format!(
            "jan: no fit could be made: {}",
            notes.join("; ")
        )));
    }
    for n in &notes {
        eprintln!("fitbead jan: {n}");
    }
    let curves: Vec<Curve> = fits
        .series
        .iter()
        .flatten()
        .map(|_| Curve::JanSeries)
        .chain(fits.global.iter().map(|_| Curve::JanGlobal))
        .collect();
    let plot = LsqPlot {
        title: "Jan's law (eq 74) fitted on v\u{304}",
        data: &ds,
        curves: &curves,
    };
    a.io.write(&all, &plot)
}
