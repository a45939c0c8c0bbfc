//! `fitbead jaeger`: Jaeger's a1, a2, a3 per series (eqs 80–84), with the branch of eq 84.

use super::fit_run::{some_fit_made, FitRun};
use super::RunError;
use crate::fit::jaeger::{fit_jaeger_with, JaegerModel};
use crate::inverse::posterior::Method;
use crate::io::measurements::{locate_note, MeasurementFile};
use crate::models::JaegerBranch;
use crate::report::bands::Curve;

/// Fits Jaeger's law to the data of `file`, on `branch` where eq 84 has two roots
/// ([`super::FitCommand::Jaeger`]).
pub(crate) fn run(
    file: &MeasurementFile,
    branch: JaegerBranch,
    method: &Method,
    level: f64,
    note: &mut dyn FnMut(&str),
) -> Result<FitRun, RunError> {
    let (t, ds) = (&file.table, &file.dataset);
    let fits = fit_jaeger_with(ds, branch, level, method);
    if let Some(e) = fits.fault {
        return Err(super::control_error(e));
    }
    let notes: Vec<String> = fits.notes.iter().map(|n| locate_note(t, ds, n)).collect();
    let curves: Vec<Curve> = fits
        .series
        .iter()
        .flatten()
        .map(|f| Curve::Jaeger(JaegerModel(f.branch)))
        .collect();
    let fits: Vec<_> = fits
        .series
        .into_iter()
        .flatten()
        .map(|f| f.summary)
        .collect();
    some_fit_made("jaeger", &fits, &notes, method, note)?;
    Ok(FitRun {
        fits,
        title: "Jaeger's law (eqs 80–84) fitted on v\u{304}".to_string(),
        data: ds.clone(),
        curves,
    })
}
