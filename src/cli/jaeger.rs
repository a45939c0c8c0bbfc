//! `fitbead jaeger`: Jaeger's a1, a2, a3 per series (Jaeger units, eq 81), the branch used and
//! the points in the bistable band (eq 90), beside the paper's Fig. 9 values.

use super::fitargs::{FitArgs, LsqPlot};
use super::CliError;
use crate::fit::jaeger::fit_jaeger_with;
use crate::fit::jaeger::JaegerModel;
use crate::fit::summary::FitResult;
use crate::io::measurements::locate_note;
use crate::models::JaegerBranch;
use crate::report::bands::Curve;

/// Arguments of `fitbead jaeger`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Root of eq 84 to fit where there are two: upper or lower.
    #[arg(long, default_value = "upper", value_parser = super::values::choice::<JaegerBranch>())]
    pub branch: JaegerBranch,
    /// Input, output and interval flags.
    #[command(flatten)]
    pub io: FitArgs,
}

/// Runs `fitbead jaeger`.
pub fn run(a: Args) -> Result<(), CliError> {
    let branch = a.branch;
    let (t, _rows, ds) = a.io.read()?;
    let choice = a.io.method(&["a1", "a2", "a3"])?;
    let (method, task) = super::counted_fit("jaeger", choice.method);
    let fits = fit_jaeger_with(&ds, branch, a.io.level.level(), &method);
    drop(task);
    let notes: Vec<String> = fits.notes.iter().map(|n| locate_note(&t, &ds, n)).collect();
    let all: Vec<&FitResult> = fits.series.iter().flatten().map(|f| &f.summary).collect();
    if all.iter().all(|f| f.params.is_empty()) {
        if super::stop_requested() {
            return Err(CliError::Interrupted);
        }
        return Err(CliError::Other(format!(
            "jaeger: no fit could be made: {}",
            notes.join("; ")
        )));
    }
    for n in &notes {
        eprintln!("fitbead jaeger: {n}");
    }
    let curves: Vec<Curve> = fits
        .series
        .iter()
        .flatten()
        .map(|f| Curve::Jaeger(JaegerModel(f.branch)))
        .collect();
    let plot = LsqPlot {
        title: "Jaeger's law (eqs 80–84) fitted on v\u{304}",
        data: &ds,
        curves: &curves,
    };
    a.io.write(&all, &plot)
}
