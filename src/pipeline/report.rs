//! The report of every model fitted to one data set and the paper's comparisons — bulk
//! friction μ of Jan's model against eq 79, energy budgets, the regime map, the model ranking
//! — as CSV tables, figures and a `report.md` that links them, written as one directory.

use super::{setting_error as flag_error, RunError};
use crate::fit::data::{Dataset, SiSeries};
use crate::fit::k::unsteady_points;
use crate::fit::klaw::KLawError;
use crate::fit::posterior::Method;
use crate::fit::summary::StatsRow;
use crate::io::measurements::{
    is_shipped_data, locate_point, si_conversion, MeasurementDefaults, MeasurementFile,
};
use crate::io::scenes::Table;
use crate::numfmt::fmt_f64;
use crate::report::analysis::{analyse, Analysis};
use crate::report::bands::PosteriorBands;
use crate::report::figures::{FigureError, FigureFormat, FigureWidth};
use crate::report::text::{markdown, one_line, terminal_summary, ReportContext};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The contact models the report fits (a point must be steady under one of them).
const CONTACT_MODELS: [crate::models::Model; 2] =
    [crate::models::Model::Stick, crate::models::Model::StickSlip];

/// [`CONTACT_MODELS`] in prose.
const CONTACT_NAMES: [&str; 2] = ["rolling", "stick/slip"];

/// How [`ReportSettings::run`] fits and draws: the settings of `fitbead report` (the defaults are its
/// flags' defaults).
#[derive(Debug, Clone)]
pub struct ReportSettings {
    /// The level of every interval (`--level`).
    pub level: f64,
    /// Least squares or MCMC (`--method` and the MCMC flags), with its stop flag.
    pub method: Method,
    /// The figure files (`--format`): svg, png (rendered from the SVG, where the library is
    /// built with PNG output), pdf, both (svg and png) or all.
    pub format: String,
    /// Velocities on the figures in m/s (`--units si`; needs data given as `v_m_s` with
    /// `R_m`) instead of dimensionless.
    pub si_units: bool,
    /// Print width of the figures (`--figure-width`): single (86 mm), double (178 mm) or a
    /// width in mm (40-500); `None`: each figure's natural size.
    pub figure_width: Option<String>,
    /// Write what can be written when the data fail a fit command's input check
    /// (`--keep-going`); otherwise such data are an error and nothing is written.
    pub keep_going: bool,
    /// ρ, f and g of the rows that leave them out (`--rho`, `--f`, `--g`: g converts
    /// `v_m_s` for the figures in m/s).
    pub defaults: MeasurementDefaults,
    /// How report.md names the data; `None`: the name the data were read under.
    pub source: Option<String>,
    /// Raised to stop the run: [`ReportSettings::run`] then returns [`RunError::Interrupted`] (or, once a
    /// posterior run has been cut short, writes what it has, marked interrupted).
    pub stop: Option<Arc<AtomicBool>>,
    /// The method as report.md names it (the command line gives its flag's text); `None`:
    /// `lsq` or `mcmc`.
    pub method_name: Option<String>,
}

impl Default for ReportSettings {
    /// Level 0.95, least squares with profiles, SVG figures in dimensionless units at their
    /// natural size, the default ρ, f and g.
    fn default() -> Self {
        ReportSettings {
            level: 0.95,
            method: Method::lsq(true),
            format: "svg".into(),
            si_units: false,
            figure_width: None,
            keep_going: false,
            defaults: MeasurementDefaults::default(),
            source: None,
            stop: None,
            method_name: None,
        }
    }
}

/// What [`ReportSettings::run`] made.
#[derive(Debug, Clone)]
pub struct ReportOutput {
    /// Every file of the directory, by name, in the order written: the CSV tables, the
    /// figures (in the settings' format), the corner plots and report.md.
    pub files: Vec<(String, Vec<u8>)>,
    /// The summary the command line prints: the fitted parameters and the files.
    pub summary: String,
    /// Every fit's statistics (the rows of stats.csv).
    pub stats: Vec<StatsRow>,
    /// The warnings of the run: fits whose misfit is implausible or improbable for the σ
    /// given, posterior runs that did not converge.
    pub warnings: Vec<String>,
    /// Of those, the fits whose χ² tail probability is below 0.001 and whose misfit is not
    /// implausible ([`StatsRow::misfit_warning`]), as `FIT [SERIES]: message`.
    pub misfits: Vec<String>,
    /// Whether a posterior run was cut short by the stop flag (its files are marked so).
    pub interrupted: bool,
}

impl ReportSettings {
    /// The names `format` takes: the file formats of the figures.
    pub const FORMATS: [&'static str; 5] = ["svg", "png", "pdf", "both", "all"];

    /// Runs `fitbead report` on `data`: every model fitted, the comparisons drawn, and, when
    /// `out_dir` is given, the directory written as one unit (locked while written, every file or
    /// none, the run recorded in `.fitbead.manifest`; missing parents created and removed again
    /// on failure). The files are returned either way.
    ///
    /// In stages: the flags checked, the input checked (points no contact model makes steady),
    /// the models fitted and their laws checked, then the tables, the figures and report.md
    /// drawn, and the directory written.
    pub fn run(
        &self,
        data: &MeasurementFile,
        out_dir: Option<&Path>,
    ) -> Result<ReportOutput, RunError> {
        report(data, self, out_dir)
    }

    /// Checks a figure format's name (one of [`ReportSettings::FORMATS`], any case, spaces
    /// around it ignored); the error says which names there are.
    pub fn check_format(name: &str) -> Result<(), FigureError> {
        name.parse::<FigureFormat>().map(|_| ())
    }

    /// Checks a figure width: `single` (86 mm), `double` (178 mm) or a width in mm from 40
    /// to 500 (`120` or `120mm`).
    pub fn check_figure_width(width: &str) -> Result<(), FigureError> {
        width.parse::<FigureWidth>().map(|_| ())
    }

    /// Whether `dir` can take a report's files before any work is done: an existing
    /// directory, or a path whose nearest existing ancestor is a directory (the missing ones
    /// are made when the files are written). The error says what stands in the way (without
    /// naming `dir`).
    pub fn check_out_dir(dir: &Path) -> std::io::Result<()> {
        crate::io::outdir::check_dir(dir)
    }

    fn stopped(&self) -> bool {
        self.stop.as_ref().is_some_and(|s| s.load(Ordering::SeqCst))
    }
}

impl ReportOutput {
    /// The files of a report directory, in the order they are written (the figures as SVG;
    /// the format of the settings gives each figure's other files).
    pub const FILES: [&'static str; 19] = crate::report::REPORT_FILES;

    /// [`ReportOutput::FILES`] with each figure's names in the figure format `format` (one
    /// of [`ReportSettings::FORMATS`]): `NAME.svg`, `NAME.png` or both, and so on.
    pub fn file_names(format: &str) -> Result<Vec<String>, FigureError> {
        let format: FigureFormat = format.parse()?;
        Ok(Self::FILES
            .iter()
            .flat_map(|f| {
                if f.ends_with(".svg") {
                    format.names(f)
                } else {
                    vec![f.to_string()]
                }
            })
            .collect())
    }

    /// `FIT [SERIES]: why` for each fit that did not converge, joined by `; `; `None` when
    /// every fit converged (as [`FitRun::not_converged`](super::FitRun::not_converged)).
    pub fn not_converged(&self) -> Option<String> {
        super::not_converged(&self.stats)
    }
}

impl MeasurementFile {
    /// The cells of column `name` as the file holds them (trimmed), one per point in file
    /// order; `None` when the file has no such column. The columns a data set does not keep
    /// (`R_m`, `g`, `v_m_s`, `sigma_v_m_s`) are read this way.
    pub fn column(&self, name: &str) -> Option<Vec<String>> {
        let c = self.table.col(name)?;
        Some(
            (0..self.table.rows.len())
                .map(|i| self.table.cell(i, c).trim().to_string())
                .collect(),
        )
    }
}

/// Why a law cannot be fitted, in words, with the points an empty box names located by
/// `locate` (given an index into the fitted data set).
pub(crate) fn law_error(e: &KLawError, locate: &dyn Fn(usize) -> String) -> String {
    match e {
        KLawError::EmptyBox {
            param,
            lower,
            upper,
        } if lower.0.is_finite() && upper.0.is_finite() => format!(
            "no value of {param} keeps every point in regime B: {} needs {param} > {} \
             (below, the bead stops), while {} needs {param} <= {} (above, it lifts off or runs \
             away)",
            locate(lower.1),
            fmt_f64(lower.0),
            locate(upper.1),
            fmt_f64(upper.0)
        ),
        e => e.to_string(),
    }
}

/// [`ReportSettings::run`].
fn report(
    data: &MeasurementFile,
    s: &ReportSettings,
    out_dir: Option<&Path>,
) -> Result<ReportOutput, RunError> {
    let (t, rows, ds) = (&data.table, &data.rows, &data.dataset);
    let (format, figure_width) = figure_settings(s)?;
    // The output directory is checked before the fits, not found wanting after them.
    if let Some(d) = out_dir {
        crate::io::outdir::check_dir(d)
            .map_err(|e| RunError::Failed(format!("{}: {e}", d.display())))?;
    }
    let never = Arc::new(AtomicBool::new(false));
    let stop = s.stop.clone().unwrap_or(never);
    let mut input_warnings = unsteady_checks(s, t, ds, &stop)?;
    let implausible = crate::io::measurements::plausibility(t, rows);
    let mut an = analyse(ds, s.level, &s.method);
    an.print_width_mm = figure_width.map(FigureWidth::mm);
    let law_failures = law_failures(&an, t, ds);
    if !s.stopped() {
        refuse_unless_keep_going(s.keep_going, &law_failures)?;
    }
    input_warnings.extend(law_failures);
    let interrupted = an
        .posteriors()
        .iter()
        .any(|p| p.draws.as_ref().is_some_and(|d| d.interrupted));
    if s.stopped() && !interrupted {
        return Err(RunError::Interrupted);
    }
    let mut files = analysis_tables(&an)?;
    // Under a posterior run: the bands of v̄(δ) and the posterior median at every point.
    // A run whose sampling was interrupted has none (the bands of every fit's draws cost
    // model evaluations by the million); a stop while they are drawn writes nothing.
    let bands = if an.mcmc && !interrupted {
        match crate::report::bands::posterior_bands_until(&an, &stop) {
            Some(b) => Some(b),
            None => return Err(RunError::Interrupted),
        }
    } else {
        None
    };
    let fits = an.fit_results_at(bands.as_ref());
    let params = an.params();
    let stats: Vec<StatsRow> = fits.iter().map(|f| f.stats.clone()).collect();
    let mut warnings = Vec::new();
    let stats = flag_absurd_misfits(stats, &mut warnings);
    files.extend(fit_tables(&params, &stats, &fits)?);
    // Velocities in m/s on the figures: each series' unit sqrt(g R (1 + ξ)).
    let si = si_conversion(t, &s.defaults);
    let units_m_s = if s.si_units {
        Some(si_units(si.as_deref(), ds)?)
    } else {
        None
    };
    let figures = Figures {
        an: &an,
        bands: bands.as_ref(),
        units_m_s: units_m_s.as_deref(),
        fits: &fits,
    };
    let corner_files = figures.draw(&mut files)?;
    let StatsWarnings {
        not_converged,
        absurd,
        misfits,
    } = stats_warnings(&stats);
    let context = ReportContext {
        source: s.source.clone().unwrap_or_else(|| t.source.clone()),
        shipped_synthetic: is_shipped_data(ds),
        si,
        figure_format: format,
        corner_files,
        input_warnings,
        plausibility: implausible
            .iter()
            .map(|w| w.to_string())
            .chain(absurd)
            .collect(),
        misfits: misfits.clone(),
    };
    let md = report_markdown(&an, &context, s, &not_converged);
    warnings.extend(not_converged);
    files.push(("report.md".into(), md.into_bytes()));
    let files = format.apply(files)?;
    // A stop that came while the tables and figures were drawn: nothing is written.
    if s.stopped() && !interrupted {
        return Err(RunError::Interrupted);
    }
    let shown_dir = out_dir.map(|d| d.display().to_string()).unwrap_or_default();
    if let Some(out_dir) = out_dir {
        write_report_dir(out_dir, &files)?;
    }
    Ok(ReportOutput {
        files,
        summary: terminal_summary(&an, &shown_dir),
        stats,
        warnings,
        misfits,
        interrupted,
    })
}

/// The fits' tables of the report: params.csv, stats.csv (`stats` as written, with their
/// misfit notes), residuals.csv and correlations.csv.
fn fit_tables(
    params: &[crate::fit::summary::ParamRow],
    stats: &[StatsRow],
    fits: &[crate::fit::summary::FitResult],
) -> Result<Vec<(String, Vec<u8>)>, RunError> {
    use crate::io::fit_tables::{correlations_csv, params_csv, residuals_csv, stats_csv};
    let fit_refs: Vec<&crate::fit::summary::FitResult> = fits.iter().collect();
    Ok(vec![
        ("params.csv".into(), params_csv(params).map_err(csv_error)?),
        ("stats.csv".into(), stats_csv(stats).map_err(csv_error)?),
        (
            "residuals.csv".into(),
            residuals_csv(&fit_refs).map_err(csv_error)?,
        ),
        (
            "correlations.csv".into(),
            correlations_csv(&fit_refs).map_err(csv_error)?,
        ),
    ])
}

/// What the statistics of the report's fits warn of, each as `FIT [SERIES]: message`.
struct StatsWarnings {
    /// Posterior runs that did not converge (their notes).
    not_converged: Vec<String>,
    /// Misfits so large that the units are in doubt.
    absurd: Vec<String>,
    /// Misfits improbable for the σ given (the others).
    misfits: Vec<String>,
}

fn stats_warnings(stats: &[StatsRow]) -> StatsWarnings {
    let named = |s: &StatsRow, w: String| format!("{} [{}]: {w}", s.fit, s.series);
    StatsWarnings {
        not_converged: stats
            .iter()
            .filter(|s| s.mcmc.is_some() && !s.converged)
            .map(|s| named(s, s.note.clone()))
            .collect(),
        absurd: stats
            .iter()
            .filter_map(|s| s.absurd_misfit().map(|w| named(s, w.to_string())))
            .collect(),
        misfits: stats
            .iter()
            .filter(|s| s.absurd_misfit().is_none())
            .filter_map(|s| s.misfit_warning().map(|w| named(s, w.to_string())))
            .collect(),
    }
}

/// The figure settings of `s`, checked with its level: the format and the print width.
fn figure_settings(s: &ReportSettings) -> Result<(FigureFormat, Option<FigureWidth>), RunError> {
    if !(s.level > 0.0 && s.level < 1.0) {
        return Err(flag_error(
            "--level",
            &s.level.to_string(),
            "must be in (0, 1), e.g. 0.95",
        ));
    }
    let format: FigureFormat = s
        .format
        .parse()
        .map_err(|e: FigureError| flag_error("--format", &s.format, e.to_string()))?;
    let figure_width: Option<FigureWidth> = match &s.figure_width {
        Some(w) => Some(
            w.parse()
                .map_err(|e: FigureError| flag_error("--figure-width", w, e.to_string()))?,
        ),
        None => None,
    };
    Ok((format, figure_width))
}

/// The input checks of the fit commands, per contact model: the points it cannot make steady
/// at any K (`klaw`'s input check), as warnings; a point steady under no contact model is an
/// error, as in klaw, and so is any warning, unless `--keep-going` (the fits then leave such
/// points out).
fn unsteady_checks(
    s: &ReportSettings,
    t: &Table,
    ds: &Dataset,
    stop: &Arc<AtomicBool>,
) -> Result<Vec<String>, RunError> {
    let unsteady: Vec<Vec<(usize, String)>> = CONTACT_MODELS
        .iter()
        .map(|m| unsteady_points(std::slice::from_ref(m), ds, Some(stop)))
        .collect();
    if s.stopped() {
        return Err(RunError::Interrupted);
    }
    if !s.keep_going {
        refuse_unsteady_under_all(&unsteady, t, ds)?;
    }
    let mut input_warnings = Vec::new();
    for (u, name) in unsteady.iter().zip(CONTACT_NAMES) {
        if let Some((i, why)) = u.first() {
            input_warnings.push(format!(
                "{}: {why} (and {} more such point(s)); no K of the {name} model makes this \
                 point steady (the {name} fits leave such points out)",
                locate_point(t, ds, *i),
                u.len() - 1
            ));
        }
    }
    refuse_unless_keep_going(s.keep_going, &input_warnings)?;
    Ok(input_warnings)
}

/// An error naming the first point steady under none of the contact models (`unsteady`:
/// per model, the points it cannot make steady, with why).
fn refuse_unsteady_under_all(
    unsteady: &[Vec<(usize, String)>],
    t: &Table,
    ds: &Dataset,
) -> Result<(), RunError> {
    let under_none: Vec<&(usize, String)> = unsteady[0]
        .iter()
        .filter(|(i, _)| unsteady[1..].iter().all(|u| u.iter().any(|(j, _)| j == i)))
        .collect();
    if let Some((i, why)) = under_none.first() {
        return Err(RunError::Failed(format!(
            "{}: {why} (and {} more such point(s)); no K of the rolling or stick/slip model \
             makes this point steady: leave it out of the data (--keep-going leaves it out of \
             their fits)",
            locate_point(t, ds, *i),
            under_none.len() - 1
        )));
    }
    Ok(())
}

/// The K(α) laws `klaw` would have refused to fit (on the points each model keeps), in
/// words.
fn law_failures(an: &Analysis, t: &Table, ds: &Dataset) -> Vec<String> {
    let mut law_failures = Vec::new();
    for (c, name) in an.contact.iter().zip(CONTACT_NAMES) {
        for (law, e) in &c.law_failures {
            let located = law_error(e, &|i| locate_point(t, ds, c.used[i]));
            law_failures.push(format!("{name} law {}: {located}", law.name()));
        }
    }
    law_failures
}

/// A CSV writer's error as the run's.
fn csv_error(e: csv::Error) -> RunError {
    RunError::Failed(e.to_string())
}

/// The tables of the analysis: bulk friction, energy, the regime map, the points and the
/// model rankings.
fn analysis_tables(an: &Analysis) -> Result<Vec<(String, Vec<u8>)>, RunError> {
    Ok(vec![
        ("bulk_friction.csv".into(), an.mu_csv().map_err(csv_error)?),
        ("energy.csv".into(), an.energy_csv().map_err(csv_error)?),
        (
            "regime_map.csv".into(),
            an.regime_map_csv().map_err(csv_error)?,
        ),
        ("points.csv".into(), an.points_csv().map_err(csv_error)?),
        ("models.csv".into(), an.models_csv().map_err(csv_error)?),
        (
            "models_by_series.csv".into(),
            an.models_by_series_csv().map_err(csv_error)?,
        ),
    ])
}

/// Every fit whose misfit is absurd for the σ given or improbable (χ² tail probability below
/// 0.001), flagged in its note and in `warnings`.
fn flag_absurd_misfits(stats: Vec<StatsRow>, warnings: &mut Vec<String>) -> Vec<StatsRow> {
    stats
        .into_iter()
        .map(|s| {
            if let Some(w) = s.misfit_warning() {
                warnings.push(format!("{} [{}]: {w}", s.fit, s.series));
            }
            s.with_misfit_note()
        })
        .collect()
}

/// Each series' velocity unit in m/s, for `--units si`: an error where the velocities were
/// given dimensionless or a series mixes units.
fn si_units(si: Option<&[SiSeries]>, ds: &Dataset) -> Result<Vec<f64>, RunError> {
    let si = si.ok_or_else(|| {
        flag_error(
            "--units",
            "si",
            "the velocities were given dimensionless (column v): figures in m/s need \
             v_m_s with R_m",
        )
    })?;
    let mut u = Vec::new();
    for label in &ds.labels {
        let series = si.iter().find(|s| &s.series == label);
        match series.and_then(|s| s.unit()) {
            Some(x) => u.push(x),
            None => {
                return Err(flag_error(
                    "--units",
                    "si",
                    format!(
                        "series {label} has rows of different R_m or g, so no one unit \
                         converts its velocities to m/s"
                    ),
                ))
            }
        }
    }
    Ok(u)
}

/// What the report's figures are drawn from.
struct Figures<'a> {
    /// The analysis.
    an: &'a Analysis,
    /// The posterior bands, under a posterior run.
    bands: Option<&'a PosteriorBands>,
    /// Each series' velocity unit in m/s, for figures in m/s.
    units_m_s: Option<&'a [f64]>,
    /// Every fit, at the posterior medians under a posterior run.
    fits: &'a [crate::fit::summary::FitResult],
}

impl Figures<'_> {
    /// Draws the figures and the corner plots onto `files`; the corner plots' names.
    fn draw(&self, files: &mut Vec<(String, Vec<u8>)>) -> Result<Vec<String>, RunError> {
        let (an, bands, units_m_s) = (self.an, self.bands, self.units_m_s);
        let fig = |name: &str, r: Result<String, FigureError>| {
            r.map(|s| (name.to_string(), s.into_bytes()))
                .map_err(|e| RunError::Failed(format!("figure {name}: {e}")))
        };
        files.push(fig(
            "velocity.svg",
            an.velocity_figure_with(bands, units_m_s),
        )?);
        files.push(fig("jan_linear.svg", an.jan_figure(units_m_s))?);
        files.push(fig("k_final_velocity.svg", an.k_figure(units_m_s))?);
        files.push(fig("regime_map.svg", an.regime_figure())?);
        files.push(fig("jaeger.svg", an.jaeger_figure())?);
        files.push(fig("k_alpha.svg", an.k_alpha_figure())?);
        files.push(fig("energy.svg", an.energy_figure())?);
        files.push(fig("residuals.svg", an.residuals_figure_with(self.fits))?);
        let mut corner_files = Vec::new();
        for (name, svg) in an.corner_figures() {
            corner_files.push(name.clone());
            files.push((name, svg.into_bytes()));
        }
        Ok(corner_files)
    }
}

/// report.md: the analysis in words, then the posterior runs that did not converge.
fn report_markdown(
    an: &Analysis,
    context: &ReportContext,
    s: &ReportSettings,
    not_converged: &[String],
) -> String {
    let method = s.method_name.clone().unwrap_or_else(|| {
        match s.method {
            Method::Mcmc(_) => "mcmc",
            _ => "lsq",
        }
        .to_string()
    });
    let mut md = markdown(an, context, &method);
    if !not_converged.is_empty() {
        md.push_str(
            "
## Posterior runs that did not converge

",
        );
        for w in not_converged {
            md.push_str(&format!("- {}\n", one_line(w)));
        }
    }
    md
}

/// Writes the report's `files` into `out_dir` as one unit, creating it and its missing
/// parents; all or nothing: the directories made for it go again when the writing fails.
fn write_report_dir(out_dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), RunError> {
    let created = create_dirs(out_dir)
        .map_err(|e| RunError::Failed(format!("{}: cannot create: {e}", out_dir.display())))?;
    if let Err(e) = crate::io::outdir::write_dir(out_dir, files) {
        // All or nothing: directories made for this report go as well.
        for d in created.iter().rev() {
            let _ = std::fs::remove_dir(d);
        }
        return Err(RunError::Failed(format!("cannot write: {e}")));
    }
    Ok(())
}

/// An error on `problems` (the input checks a fit command would have failed), unless
/// `keep_going`.
fn refuse_unless_keep_going(keep_going: bool, problems: &[String]) -> Result<(), RunError> {
    if keep_going || problems.is_empty() {
        return Ok(());
    }
    Err(RunError::Failed(format!(
        "{}{}; nothing written (--keep-going writes the report without what these leave out, \
         report.md opening with the warnings)",
        problems[0],
        match problems.len() {
            1 => String::new(),
            n => format!("; and {} more problem(s)", n - 1),
        }
    )))
}

/// Creates `dir` and its missing parents; returns the directories it made, outermost first.
fn create_dirs(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut missing = Vec::new();
    let mut p = Some(dir);
    while let Some(d) = p {
        if d.as_os_str().is_empty() || d.exists() {
            break;
        }
        missing.push(d.to_path_buf());
        p = d.parent();
    }
    missing.reverse();
    std::fs::create_dir_all(dir)?;
    Ok(missing)
}
