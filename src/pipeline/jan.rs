//! `fitbead jan`: Jan's λ and μ per series (eq 74, fitted on v̄) and the global laws
//! λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α} (form of eqs 75–76).

use super::fit_run::{some_fit_made, FitRun};
use super::RunError;
use crate::fit::jan::fit_jan_with;
use crate::inverse::posterior::Method;
use crate::io::measurements::{locate_note, MeasurementFile};
use crate::report::bands::Curve;

/// Fits Jan's laws to the data of `file` ([`super::FitCommand::Jan`]).
pub(crate) fn run(
    file: &MeasurementFile,
    method: &Method,
    level: f64,
    note: &mut dyn FnMut(&str),
) -> Result<FitRun, RunError> {
    let (t, ds) = (&file.table, &file.dataset);
    let fits = fit_jan_with(ds, level, method);
    if let Some(e) = fits.fault {
        return Err(super::control_error(e));
    }
    let notes: Vec<String> = fits.notes.iter().map(|n| locate_note(t, ds, n)).collect();
    let curves: Vec<Curve> = fits
        .series
        .iter()
        .flatten()
        .map(|_| Curve::JanSeries)
        .chain(fits.global.iter().map(|_| Curve::JanGlobal))
        .collect();
    let fits: Vec<_> = fits
        .series
        .into_iter()
        .flatten()
        .chain(fits.global)
        .collect();
    some_fit_made("jan", &fits, &notes, method, note)?;
    Ok(FitRun {
        fits,
        title: "Jan's law (eq 74) fitted on v\u{304}".to_string(),
        data: ds.clone(),
        curves,
    })
}
