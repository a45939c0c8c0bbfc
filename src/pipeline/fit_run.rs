//! What the fit commands (`klaw`, `jan`, `jaeger`) hand back, [`FitRun`]: the fits, and the
//! files the command line writes from them (the parameter, statistics and draws CSVs, the
//! figure, the fit reports).

use super::RunError;
use crate::fit::data::Dataset;
use crate::fit::summary::{FitResult, ParamRow, StatsRow};
use crate::io::fit_tables::{draws_csv, params_csv, stats_csv};
use crate::report::bands::Curve;
use crate::report::figures::{CornerBlock, FigureFormat};
use crate::report::file_stems;
use crate::report::plots::lsq_fit_figure;
use std::path::{Path, PathBuf};

/// What a fit command made: its fits, in the order the command line writes them, and what
/// its figure draws.
#[derive(Debug, Clone)]
pub struct FitRun {
    /// The fits (klaw: the law's, then the impact law's unless the law is impact; jan: per
    /// series, then the global laws; jaeger: per series). A fit that could not be made is
    /// absent, and said in a note.
    pub fits: Vec<FitResult>,
    /// The title of the least-squares figure.
    pub(crate) title: String,
    /// The data fitted (klaw: without the points left out).
    pub(crate) data: Dataset,
    /// The curve of each fit, in the order of the fits.
    pub(crate) curves: Vec<Curve>,
}

impl FitRun {
    /// Whether a posterior run was cut short by the stop flag (its draws so far are kept and
    /// its rows marked).
    pub fn interrupted(&self) -> bool {
        self.fits
            .iter()
            .any(|f| f.draws.as_ref().is_some_and(|d| d.interrupted))
    }

    /// The fits sampled by a posterior run.
    fn posteriors(&self) -> Vec<&FitResult> {
        self.fits.iter().filter(|f| f.draws.is_some()).collect()
    }

    /// The statistics of every fit as written, a misfit improbable for the σ given (or an
    /// absurd reduced χ²) said in its note ([`StatsRow::with_misfit_note`]).
    pub fn stats(&self) -> Vec<StatsRow> {
        self.fits
            .iter()
            .map(|f| f.stats.with_misfit_note())
            .collect()
    }

    /// The misfit warning of each fit that has one, as `FIT [SERIES]: warning`
    /// ([`StatsRow::misfit_warning`]).
    pub fn misfits(&self) -> Vec<String> {
        self.fits
            .iter()
            .filter_map(|f| {
                let s = &f.stats;
                s.misfit_warning()
                    .map(|w| format!("{} [{}]: {w}", s.fit, s.series))
            })
            .collect()
    }

    /// The parameter CSV (`fit,series,parameter,value,stderr,ci_low,ci_high,ci_method,unit,…`).
    pub fn params_csv(&self) -> Result<Vec<u8>, RunError> {
        let rows: Vec<ParamRow> = self
            .fits
            .iter()
            .flat_map(|f| f.params.iter().cloned())
            .collect();
        params_csv(&rows).map_err(|e| RunError::Failed(e.to_string()))
    }

    /// The statistics CSV, one row per fit ([`FitRun::stats`]).
    pub fn stats_csv(&self) -> Result<Vec<u8>, RunError> {
        stats_csv(&self.stats()).map_err(|e| RunError::Failed(e.to_string()))
    }

    /// The kept draws of every posterior run (`fit,series,walker,step`, one column per
    /// parameter, `log_posterior`).
    pub fn draws_csv(&self) -> Result<Vec<u8>, RunError> {
        draws_csv(&self.posteriors()).map_err(|e| RunError::Failed(e.to_string()))
    }

    /// The fit report of every fit, one after another, with the statistics as written
    /// ([`FitRun::stats`]).
    pub fn fit_reports(&self) -> String {
        let stats = self.stats();
        let mut out = String::new();
        for (i, f) in self.fits.iter().enumerate() {
            if i > 0 {
                out.push('\n');
            }
            match stats.get(i) {
                Some(s) if *s != f.stats => {
                    let mut g = FitResult {
                        draws: None,
                        ..f.clone()
                    };
                    g.stats = s.clone();
                    out.push_str(&g.to_string());
                }
                _ => out.push_str(&f.to_string()),
            }
        }
        out
    }

    /// The figure files for `path`: under least squares one figure, v̄ against δ per series
    /// with each fitted curve and its band; after posterior runs one corner plot per fit and
    /// series, named PATH's stem followed by `_FIT_SERIES` (all stacked in one SVG document
    /// when `path` is `-`). A name ending `.png` or `.pdf` gets a PNG or a PDF, any other SVG.
    pub fn figures(&self, path: &Path) -> Result<Vec<(PathBuf, Vec<u8>)>, RunError> {
        let posteriors = self.posteriors();
        let mut figures = Vec::new();
        if posteriors.is_empty() {
            let with: Vec<(&FitResult, Curve)> = self
                .fits
                .iter()
                .zip(&self.curves)
                .map(|(f, c)| (f, *c))
                .collect();
            let svg = lsq_fit_figure(&self.title, &self.data, &with)
                .map_err(|e| RunError::Failed(format!("--plot: {e}")))?;
            figures.push((path.to_path_buf(), figure_bytes(path, svg)?));
        } else if path.as_os_str() == "-" {
            let svg = CornerBlock::svg(&CornerBlock::from_posteriors(&posteriors))
                .map_err(|e| RunError::Failed(format!("corner plot: {e}")))?;
            figures.push((path.to_path_buf(), svg.into_bytes()));
        } else {
            let labels: Vec<String> = posteriors.iter().map(|p| p.stats.series.clone()).collect();
            let stems = file_stems(&labels);
            let stem = path.file_stem().map_or_else(
                || "corner".to_string(),
                |s| s.to_string_lossy().into_owned(),
            );
            let ext = path
                .extension()
                .map_or_else(|| "svg".to_string(), |e| e.to_string_lossy().into_owned());
            for (p, series) in posteriors.iter().zip(&stems) {
                let svg = CornerBlock::svg(&CornerBlock::from_posteriors(&[*p]))
                    .map_err(|e| RunError::Failed(format!("corner plot: {e}")))?;
                let name = path.with_file_name(format!("{stem}_{}_{series}.{ext}", p.stats.fit));
                let bytes = figure_bytes(&name, svg)?;
                figures.push((name, bytes));
            }
        }
        Ok(figures)
    }

    /// Why the command fails once its outputs are written (exit 1 on the command line), naming
    /// each fit and its series: a least-squares fit that stopped short of its tolerance, a
    /// posterior run that could not start (its rows hold the least-squares values, marked) or
    /// one that stopped at its step limit before its R̂ and ESS targets. A law with no free
    /// parameter is scored, not fitted: a point it cannot make steady is said in its note.
    pub fn not_converged(&self) -> Option<String> {
        not_converged(&self.stats())
    }
}

/// The message of [`FitRun::not_converged`] for the statistics `stats` as written.
pub(crate) fn not_converged(stats: &[StatsRow]) -> Option<String> {
    let failed: Vec<String> = stats
        .iter()
        .filter_map(|s| {
            let why = match s.mcmc.as_ref().and_then(|m| m.failure.as_ref()) {
                Some(f) => {
                    format!("{f} (its rows hold the least-squares values, marked in their notes)")
                }
                // A law with nothing to fit (impact, cos 2α) is scored, not solved.
                None if !s.converged && s.n_params > 0 => s.note.clone(),
                None => return None,
            };
            Some(format!("{} [{}]: {why}", s.fit, s.series))
        })
        .collect();
    (!failed.is_empty()).then(|| failed.join("; "))
}

/// A command of fits per series (`jan`, `jaeger`) that made none fails, naming why each was
/// not made (or [`RunError::Interrupted`] when the stop flag cut them short); otherwise each
/// note of a fit not made goes to `note`.
pub(crate) fn some_fit_made(
    command: &str,
    fits: &[FitResult],
    notes: &[String],
    method: &crate::inverse::posterior::Method,
    note: &mut dyn FnMut(&str),
) -> Result<(), RunError> {
    if fits.iter().all(|f| f.params.is_empty()) {
        if method.stopped() {
            return Err(RunError::Interrupted);
        }
        return Err(RunError::Failed(format!(
            "{command}: no fit could be made: {}",
            notes.join("; ")
        )));
    }
    for n in notes {
        note(n);
    }
    Ok(())
}

/// The figure `svg` as the bytes of the file `path`: rendered to PNG or converted to PDF when
/// its name ends `.png` or `.pdf`.
pub(crate) fn figure_bytes(path: &Path, svg: String) -> Result<Vec<u8>, RunError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("png") => FigureFormat::Png,
        Some("pdf") => FigureFormat::Pdf,
        _ => return Ok(svg.into_bytes()),
    };
    let out = format
        .apply(vec![("plot.svg".to_string(), svg.into_bytes())])
        .map_err(|e| RunError::Failed(format!("--plot: {e}")))?;
    Ok(out.into_iter().next().map(|f| f.1).unwrap_or_default())
}
