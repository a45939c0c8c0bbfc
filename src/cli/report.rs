//! `fitbead report`: every model fitted to one data set, and the paper's comparisons — bulk
//! friction μ of Jan's model against eq 79, energy budgets, the regime map, the model ranking —
//! as a directory of CSV tables, SVG figures and a `report.md` that links them.

use super::args::{ContactArgs, DataArgs, LevelArgs, PlotArgs};
use super::fitargs::{not_converged, FitArgs, FitOutputArgs};
use super::CliError;
use crate::pipeline::{report, ReportSettings};
use crate::report::figures::{FigureFormat, FigureWidth};
use std::path::{Path, PathBuf};

/// Arguments of `fitbead report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The measurements (as for `klaw`) and the defaults of the columns they may leave out.
    #[command(flatten)]
    pub data: DataArgs,
    /// Directory for the tables, figures and report.md, created if missing [default: report].
    /// Written as one unit: locked while written (concurrent runs wait, never mix), every
    /// file or none, the run recorded in .fitbead.manifest; files of the previous run that
    /// this one does not write are removed, other files (yours) are never touched
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// lsq or mcmc (posteriors for every fit; adds one corner_<fit>_<series>.svg per
    /// posterior) [default: lsq]
    #[arg(long)]
    pub method: Option<String>,
    /// Figure files: svg, png (rendered from the SVG), pdf (vector, the font embedded, text
    /// selectable), both (svg and png) or all (svg, png and pdf) [default: svg]
    #[arg(long)]
    pub format: Option<String>,
    /// Velocities on the figures: dimensionless (units of sqrt(g (R + r))) or si (m/s, for
    /// data given in m/s with R_m; every velocity axis: velocity.svg, jan_linear.svg in
    /// m²/s², k_final_velocity.svg) [default: dimensionless]
    #[arg(long)]
    pub units: Option<String>,
    /// Print width of the figures: single (one journal column, 86 mm), double (two columns,
    /// 178 mm) or a width in mm (40-500); each figure is laid out for it (fewer columns,
    /// narrower panels, titles broken into lines) so that no text prints below 7 pt, sized in
    /// mm in SVG and PDF, PNG at 300 dpi [default: each figure's natural size]
    #[arg(long)]
    pub figure_width: Option<String>,
    /// The level of every interval.
    #[command(flatten)]
    pub level: LevelArgs,
    /// MCMC seed [default: 1]
    #[arg(long)]
    pub seed: Option<u64>,
    /// MCMC: minimum bulk and tail ESS per parameter [default: 1000]
    #[arg(long)]
    pub min_ess: Option<f64>,
    /// MCMC: maximum steps per fit [default: 100000]
    #[arg(long)]
    pub max_steps: Option<usize>,
    /// A TOML recipe with any of the keys input, out_dir, method, format, units, figure_width,
    /// rho, f, g,
    /// level, seed, min_ess, max_steps (paths relative to the recipe's directory, never
    /// empty); flags given on the command line win. seed, min_ess and max_steps apply to mcmc
    /// and are ignored under lsq. A bad value is reported with the recipe file, line and key
    #[arg(long)]
    pub recipe: Option<PathBuf>,
    /// Write what can be written when the data fail a fit command's input check (points that
    /// the rolling or the stick/slip model cannot make steady, a K(α) law that cannot be
    /// fitted): the fits leave those points out and report.md opens with the warnings.
    /// Without it such data exit 2 (as `klaw` does) and nothing is written
    #[arg(long)]
    pub keep_going: bool,
}

/// The keys of a recipe file.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Recipe {
    /// Measurements CSV.
    pub input: Option<PathBuf>,
    /// Output directory.
    pub out_dir: Option<PathBuf>,
    /// lsq or mcmc.
    pub method: Option<String>,
    /// svg, png, pdf, both or all.
    pub format: Option<String>,
    /// dimensionless or si.
    pub units: Option<String>,
    /// single, double or a width in mm.
    pub figure_width: Option<String>,
    /// ρ.
    pub rho: Option<f64>,
    /// f.
    pub f: Option<f64>,
    /// g.
    pub g: Option<f64>,
    /// Interval level.
    pub level: Option<f64>,
    /// MCMC seed.
    pub seed: Option<u64>,
    /// MCMC minimum ESS.
    pub min_ess: Option<f64>,
    /// MCMC maximum steps.
    pub max_steps: Option<usize>,
    /// The input path as written in the recipe (shown in report.md, so that the report does
    /// not depend on where the recipe was run from).
    #[serde(skip)]
    pub shown_input: Option<String>,
}

/// The recipe's keys that a flag of the same meaning overrides, with that flag.
const RECIPE_FLAGS: [(&str, &str); 13] = [
    ("input", "--input"),
    ("out_dir", "--out-dir"),
    ("method", "--method"),
    ("format", "--format"),
    ("units", "--units"),
    ("figure_width", "--figure-width"),
    ("rho", "--rho"),
    ("f", "--f"),
    ("g", "--g"),
    ("level", "--level"),
    ("seed", "--seed"),
    ("min_ess", "--min-ess"),
    ("max_steps", "--max-steps"),
];

/// A recipe as read: its keys, its file's name and text (to blame a bad value on its line).
struct RecipeFile {
    recipe: Recipe,
    name: String,
    text: String,
}

impl RecipeFile {
    /// The 1-based line of `key = …` in the recipe, when it is written that way.
    fn line_of(&self, key: &str) -> Option<u64> {
        self.text
            .lines()
            .position(|l| {
                l.trim_start()
                    .strip_prefix(key)
                    .is_some_and(|rest| rest.trim_start().starts_with('='))
            })
            .map(|i| i as u64 + 1)
    }

    /// An error about the recipe's `key`, located on its line.
    fn error(&self, key: &str, value: &str, message: impl Into<String>) -> CliError {
        CliError::Input(crate::io::InputError {
            file: self.name.clone(),
            line: self.line_of(key),
            column: Some(key.to_string()),
            value: Some(value.to_string()),
            message: message.into(),
        })
    }
}

fn read_recipe(path: &Path) -> Result<RecipeFile, CliError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| {
        CliError::Input(crate::io::InputError::file(
            &name,
            format!("cannot read: {e}"),
        ))
    })?;
    let mut r: Recipe = toml::from_str(&text).map_err(|e| {
        CliError::Input(crate::io::InputError::file(
            &name,
            format!("not a valid recipe: {e}"),
        ))
    })?;
    let file = RecipeFile {
        recipe: Recipe::default(),
        name,
        text,
    };
    // An empty path would be the recipe's own directory; the flags refuse it too.
    for (key, p) in [("input", &r.input), ("out_dir", &r.out_dir)] {
        if p.as_ref().is_some_and(|p| p.as_os_str().is_empty()) {
            return Err(file.error(
                key,
                "",
                "an empty path: name a file or directory (\".\" for the recipe's own directory)",
            ));
        }
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    r.shown_input = r.input.as_ref().map(|p| p.display().to_string());
    r.input = r.input.map(|p| dir.join(p));
    r.out_dir = r.out_dir.map(|p| dir.join(p));
    Ok(RecipeFile { recipe: r, ..file })
}

/// Whether the recipe's `key` is the value used: set in the recipe and not given as a flag.
fn from_recipe(a: &Args, r: &Recipe, key: &str) -> bool {
    match key {
        "input" => a.data.path().is_none() && r.input.is_some(),
        "out_dir" => a.out_dir.is_none() && r.out_dir.is_some(),
        "method" => a.method.is_none() && r.method.is_some(),
        "format" => a.format.is_none() && r.format.is_some(),
        "units" => a.units.is_none() && r.units.is_some(),
        "figure_width" => a.figure_width.is_none() && r.figure_width.is_some(),
        "rho" => a.data.contact.rho.is_none() && r.rho.is_some(),
        "f" => a.data.contact.f.is_none() && r.f.is_some(),
        "g" => a.data.g.is_none() && r.g.is_some(),
        "level" => a.level.level.is_none() && r.level.is_some(),
        "seed" => a.seed.is_none() && r.seed.is_some(),
        "min_ess" => a.min_ess.is_none() && r.min_ess.is_some(),
        "max_steps" => a.max_steps.is_none() && r.max_steps.is_some(),
        _ => false,
    }
}

/// `e` blamed on the recipe when it is about a setting whose value came from the recipe: the
/// recipe file, the key's line, the key.
fn blame_recipe(e: CliError, file: &RecipeFile, keys: &[&str]) -> CliError {
    let CliError::Input(ie) = e else { return e };
    if ie.file != crate::io::SETTINGS_ORIGIN {
        return CliError::Input(ie);
    }
    let flag = ie.column.clone().unwrap_or_default();
    let key = RECIPE_FLAGS
        .iter()
        .find(|(_, f)| *f == flag)
        .map(|(k, _)| *k);
    match key.filter(|k| keys.contains(k)) {
        Some(k) => CliError::Input(crate::io::InputError {
            file: file.name.clone(),
            line: file.line_of(k),
            column: Some(k.to_string()),
            ..ie
        }),
        None => CliError::Input(ie),
    }
}

/// The unit of the velocities on the report's figures (`--units`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Units {
    /// Units of sqrt(g (R + r)).
    Dimensionless,
    /// m/s.
    Si,
}

/// Runs `fitbead report`. An error about a setting taken from the recipe names the recipe
/// file, the key's line and the key.
pub fn run(a: Args) -> Result<(), CliError> {
    let Some(path) = a.recipe.clone() else {
        return run_with(a, Recipe::default());
    };
    let mut file = read_recipe(&path)?;
    let mut r = std::mem::take(&mut file.recipe);
    // The MCMC keys of a recipe apply to a posterior run only; under least squares (the
    // recipe's method or --method lsq, which wins) they are ignored, not an error.
    let method = a.method.clone().or(r.method.clone()).unwrap_or_default();
    if !method.eq_ignore_ascii_case("mcmc") {
        r.seed = None;
        r.min_ess = None;
        r.max_steps = None;
    }
    let keys: Vec<&str> = RECIPE_FLAGS
        .iter()
        .map(|(k, _)| *k)
        .filter(|k| from_recipe(&a, &r, k))
        .collect();
    run_with(a, r).map_err(|e| blame_recipe(e, &file, &keys))
}

fn run_with(a: Args, r: Recipe) -> Result<(), CliError> {
    let from_flags = a.data.path().map(Path::to_path_buf);
    let shown = match (&from_flags, &r.shown_input) {
        (None, Some(s)) => Some(s.clone()),
        _ => None,
    };
    let input = from_flags.or(r.input);
    let units = match a.units.clone().or(r.units.clone()).as_deref() {
        None => Units::Dimensionless,
        Some(u) if u.eq_ignore_ascii_case("dimensionless") => Units::Dimensionless,
        Some(u) if u.eq_ignore_ascii_case("si") => Units::Si,
        Some(u) => {
            return Err(super::flag_error(
                "--units",
                u,
                "expected dimensionless or si",
            ))
        }
    };
    let format_text = a.format.clone().or(r.format);
    let format: FigureFormat = match &format_text {
        Some(f) => f
            .parse()
            .map_err(|e: String| super::flag_error("--format", f, e))?,
        None => FigureFormat::Svg,
    };
    // Checked here, before the data are read; the library reads the text again.
    let figure_width_text = a.figure_width.clone().or(r.figure_width);
    if let Some(w) = &figure_width_text {
        w.parse::<FigureWidth>()
            .map_err(|e: String| super::flag_error("--figure-width", w, e))?;
    }
    let out_dir = a
        .out_dir
        .clone()
        .or(r.out_dir)
        .unwrap_or_else(|| PathBuf::from("report"));
    let io = FitArgs {
        data: DataArgs {
            input: input.clone(),
            data: None,
            contact: ContactArgs {
                rho: a.data.contact.rho.or(r.rho),
                f: a.data.contact.f.or(r.f),
            },
            g: a.data.g.or(r.g),
            strict_columns: a.data.strict_columns,
        },
        level: LevelArgs {
            level: a.level.level.or(r.level),
        },
        no_profile: false,
        out: FitOutputArgs::default(),
        output_stats: None,
        method: a
            .method
            .clone()
            .or(r.method)
            .unwrap_or_else(|| "lsq".into()),
        seed: a.seed.or(r.seed),
        walkers: None,
        min_ess: a.min_ess.or(r.min_ess),
        max_steps: a.max_steps.or(r.max_steps),
        thin: None,
        priors: Vec::new(),
        fit_scatter: false,
        draws: None,
        plot: PlotArgs::default(),
    };
    // No file of the report may be the input (or the recipe).
    let targets: Vec<PathBuf> = crate::report::REPORT_FILES
        .iter()
        .flat_map(|f| {
            if f.ends_with(".svg") {
                format.names(f)
            } else {
                vec![f.to_string()]
            }
        })
        .map(|f| out_dir.join(f))
        .collect();
    let outputs: Vec<(&str, Option<&Path>)> = targets
        .iter()
        .map(|p| ("--out-dir", Some(p.as_path())))
        .collect();
    crate::io::distinct_paths(
        &[
            ("--input", input.as_deref()),
            ("--recipe", a.recipe.as_deref()),
        ],
        &outputs,
    )?;
    let (table, rows, dataset) = io.read()?;
    let choice = io.method(&[])?;
    let data = crate::io::measurements::MeasurementFile {
        table,
        rows,
        dataset,
    };
    let settings = ReportSettings {
        level: io.level.level(),
        method: choice.method,
        format: format_text.unwrap_or_else(|| "svg".into()),
        si_units: units == Units::Si,
        figure_width: figure_width_text,
        keep_going: a.keep_going,
        defaults: io.data.defaults()?,
        source: shown,
        stop: Some(super::stop_flag()),
        method_name: Some(io.method.clone()),
    };
    let out = report(&data, &settings, Some(&out_dir))?;
    for s in &out.stats {
        if let Some(w) = s.absurd_misfit() {
            eprintln!("fitbead: warning: {} [{}]: {w}", s.fit, s.series);
        }
    }
    // Outside an interrupted run the exit-1 message names the fits that did not converge.
    if out.interrupted {
        for s in out
            .stats
            .iter()
            .filter(|s| s.mcmc.is_some() && !s.converged)
        {
            eprintln!("fitbead: warning: {} [{}]: {}", s.fit, s.series, s.note);
        }
    }
    {
        // The summary only repeats the files: a closed or broken stdout does not fail the
        // report (print! would panic on a broken pipe).
        use std::io::Write;
        let _ = std::io::stdout().write_all(out.summary.as_bytes());
    }
    if out.interrupted {
        return Err(CliError::InterruptedPartial);
    }
    not_converged(&out.stats)
}
