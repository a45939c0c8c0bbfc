//! `fitbead report`: every model fitted to one data set, and the paper's comparisons — bulk
//! friction μ of Jan's model against eq 79, energy budgets, the regime map, the model ranking —
//! as a directory of CSV tables, SVG figures and a `report.md` that links them.

use super::args::{DataArgs, LevelArgs, PlotArgs};
use super::fitargs::{not_converged, FitArgs, FitOutputArgs};
use super::values::{self, FigureFormat, FitMethod, Units};
use super::CliError;
use fitbead::io::InputError;
use fitbead::pipeline::{ReportOutput, ReportSettings};
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
    #[arg(long, value_parser = values::choice::<FitMethod>())]
    pub method: Option<FitMethod>,
    /// Figure files: svg, png (rendered from the SVG), pdf (vector, the font embedded, text
    /// selectable), both (svg and png) or all (svg, png and pdf) [default: svg]
    #[arg(long, value_parser = values::choice::<FigureFormat>())]
    pub format: Option<FigureFormat>,
    /// Velocities on the figures: dimensionless (units of sqrt(g (R + r))) or si (m/s, for
    /// data given in m/s with R_m; every velocity axis: velocity.svg, jan_linear.svg in
    /// m²/s², k_final_velocity.svg) [default: dimensionless]
    #[arg(long, value_parser = values::choice::<Units>())]
    pub units: Option<Units>,
    /// Print width of the figures: single (one journal column, 86 mm), double (two columns,
    /// 178 mm) or a width in mm (40-500); each figure is laid out for it (fewer columns,
    /// narrower panels, titles broken into lines) so that no text prints below 7 pt, sized in
    /// mm in SVG and PDF, PNG at 300 dpi [default: each figure's natural size]
    #[arg(long, value_parser = values::figure_width)]
    pub figure_width: Option<String>,
    /// The level of every interval.
    #[command(flatten)]
    pub level: LevelArgs,
    /// MCMC seed [default: 1]
    #[arg(long)]
    pub seed: Option<u64>,
    /// MCMC: minimum bulk and tail ESS per parameter [default: 1000]
    #[arg(long, value_parser = values::non_negative)]
    pub min_ess: Option<f64>,
    /// MCMC: maximum steps per fit [default: 100000]
    #[arg(long, value_parser = values::at_least_one)]
    pub max_steps: Option<usize>,
    /// A TOML recipe with any of the keys input, out_dir, method, format, units, figure_width,
    /// rho, f, g, sigma_delta (degrees),
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
    /// The recipe whose keys gave the defaults of the flags above (set by `super::parse`).
    #[arg(skip)]
    pub recipe_used: Option<Recipe>,
}

/// The keys of a recipe file: each is the flag of the same name (`out_dir` for `--out-dir`)
/// and takes the same values, with the TOML types here.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Keys {
    /// Measurements CSV.
    input: Option<PathBuf>,
    /// Output directory.
    out_dir: Option<PathBuf>,
    /// lsq or mcmc.
    method: Option<String>,
    /// svg, png, pdf, both or all.
    format: Option<String>,
    /// dimensionless or si.
    units: Option<String>,
    /// single, double or a width in mm (a string or a number).
    figure_width: Option<Width>,
    /// ρ.
    rho: Option<f64>,
    /// f.
    f: Option<f64>,
    /// g.
    g: Option<f64>,
    /// Standard uncertainty of the slope, degrees.
    sigma_delta: Option<f64>,
    /// Interval level.
    level: Option<f64>,
    /// MCMC seed.
    seed: Option<u64>,
    /// MCMC minimum ESS.
    min_ess: Option<f64>,
    /// MCMC maximum steps.
    max_steps: Option<usize>,
}

/// A recipe's figure width: `"single"`, `"double"`, or millimetres as a number or a string.
#[derive(Debug, Clone, serde::Deserialize, serde::Serialize)]
#[serde(untagged)]
enum Width {
    /// A width in millimetres written as a number (`figure_width = 120`).
    Mm(f64),
    /// A name or a width written as a string.
    Text(String),
}

/// The keys that apply to a posterior run only: ignored under least squares.
const MCMC_KEYS: [&str; 3] = ["seed", "min_ess", "max_steps"];

/// A recipe as applied to a command line: each key not given as a flag is that flag's default
/// value, so that clap's own parsing gives a flag over the recipe over the built-in default,
/// and checks the recipe's values as it checks the flags'.
#[derive(Debug, Clone)]
pub(crate) struct Recipe {
    /// The recipe file's name.
    name: String,
    /// Its text (to blame a bad value on its line).
    text: String,
    /// The keys applied, with their values as command-line text (paths relative to the
    /// recipe's directory already joined to it).
    keys: Vec<(String, String)>,
    /// The input path as written in the recipe, when the input is the recipe's (shown in
    /// report.md, so that the report does not depend on where the recipe was run from).
    shown_input: Option<String>,
}

impl Recipe {
    /// The recipe of `--recipe`, read, with the keys that the flags of `m` (the report's
    /// matches) do not give; `None` without `--recipe`.
    pub fn for_flags(m: &clap::ArgMatches) -> Result<Option<Recipe>, CliError> {
        use clap::parser::ValueSource;
        let Some(path) = m.get_one::<PathBuf>("recipe") else {
            return Ok(None);
        };
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::file(&name, format!("cannot read: {e}")))?;
        let mut keys: Keys = toml::from_str(&text)
            .map_err(|e| InputError::file(&name, format!("not a valid recipe: {e}")))?;
        let mut r = Recipe {
            name,
            text,
            keys: Vec::new(),
            shown_input: None,
        };
        // An empty path would be the recipe's own directory; the flags refuse it too.
        for (key, p) in [("input", &keys.input), ("out_dir", &keys.out_dir)] {
            if p.as_ref().is_some_and(|p| p.as_os_str().is_empty()) {
                return Err(r.error(
                    key,
                    "",
                    "an empty path: name a file or directory (\".\" for the recipe's own directory)",
                ));
            }
        }
        let dir = path.parent().unwrap_or(Path::new(""));
        let given = |id: &str| m.value_source(id) == Some(ValueSource::CommandLine);
        // The measurements given as a plain argument are the input as well.
        if given("input") || given("data") {
            keys.input = None;
        }
        r.shown_input = keys.input.as_ref().map(|p| p.display().to_string());
        keys.input = keys.input.map(|p| dir.join(p));
        keys.out_dir = keys.out_dir.map(|p| dir.join(p));
        // The MCMC keys apply to a posterior run only; under least squares (the recipe's
        // method or --method lsq, which wins) they are ignored, not an error.
        let method = match m.get_one::<FitMethod>("method").filter(|_| given("method")) {
            Some(m) => Some(*m),
            None => keys
                .method
                .as_deref()
                .and_then(|t| <FitMethod as clap::ValueEnum>::from_str(t.trim(), true).ok()),
        };
        let mcmc = method == Some(FitMethod::Mcmc);
        // Unsigned counts are written as they are (a TOML value holds at most i64::MAX, and
        // a seed may be any u64); the rest through TOML's own values.
        let counts = [
            ("seed", keys.seed.take().map(|n| n.to_string())),
            ("max_steps", keys.max_steps.take().map(|n| n.to_string())),
        ];
        let toml::Value::Table(map) =
            toml::Value::try_from(&keys).map_err(|e| CliError::Other(e.to_string()))?
        else {
            return Ok(Some(r));
        };
        let counts = counts
            .into_iter()
            .filter_map(|(k, v)| v.map(|v| (k.to_string(), toml::Value::String(v))));
        for (key, value) in map.into_iter().chain(counts) {
            let text = match value {
                toml::Value::String(s) => s,
                toml::Value::Float(x) => fitbead::numfmt::echo_f64(x),
                toml::Value::Integer(n) => n.to_string(),
                _ => continue,
            };
            if given(&key) || (!mcmc && MCMC_KEYS.contains(&key.as_str())) {
                continue;
            }
            r.keys.push((key, text));
        }
        Ok(Some(r))
    }

    /// The report's command with the recipe's keys as the defaults of their flags.
    pub fn defaults(&self, cmd: clap::Command) -> clap::Command {
        self.keys.iter().fold(cmd, |cmd, (key, value)| {
            // The command is built once per run: its defaults live as long as the process.
            let value: &'static str = value.clone().leak();
            cmd.mut_arg(key.as_str(), |a| a.default_value(value))
        })
    }

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
        CliError::Input(InputError {
            file: self.name.clone(),
            line: self.line_of(key),
            column: Some(key.to_string()),
            value: Some(value.to_string()),
            message: message.into(),
        })
    }

    /// `e` blamed on the recipe when it is about a flag whose value the recipe gave: the
    /// recipe file, the key's line, the key.
    pub fn blame(&self, e: CliError) -> CliError {
        let CliError::Input(ie) = e else { return e };
        let key = ie
            .column
            .as_deref()
            .filter(|_| ie.file == InputError::SETTINGS)
            .and_then(|c| c.strip_prefix("--"))
            .map(|f| f.replace('-', "_"))
            .filter(|k| self.keys.iter().any(|(key, _)| key == k));
        match key {
            Some(k) => CliError::Input(InputError {
                file: self.name.clone(),
                line: self.line_of(&k),
                column: Some(k),
                ..ie
            }),
            None => CliError::Input(ie),
        }
    }
}

/// Runs `fitbead report`. An error about a setting taken from the recipe names the recipe
/// file, the key's line and the key.
pub fn run(mut a: Args) -> Result<(), CliError> {
    match a.recipe_used.take() {
        Some(r) => run_with(a, r.shown_input.clone()).map_err(|e| r.blame(e)),
        None => run_with(a, None),
    }
}

/// Runs the report of the flags `a` (the recipe's keys applied); `shown` is the input path as
/// the recipe writes it.
fn run_with(a: Args, shown: Option<String>) -> Result<(), CliError> {
    let input = a.data.path().map(Path::to_path_buf);
    let format = a.format.unwrap_or_default();
    let out_dir = a.out_dir.clone().unwrap_or_else(|| PathBuf::from("report"));
    let io = FitArgs {
        data: a.data.clone(),
        level: a.level.clone(),
        no_profile: false,
        fix: Vec::new(),
        init: Vec::new(),
        bounds: Vec::new(),
        scale_covar: false,
        out: FitOutputArgs::default(),
        output_stats: None,
        method: a.method.unwrap_or_default(),
        seed: a.seed,
        walkers: None,
        min_ess: a.min_ess,
        max_steps: a.max_steps,
        thin: None,
        priors: Vec::new(),
        fit_scatter: false,
        draws: None,
        plot: PlotArgs::default(),
    };
    // No file of the report may be the input (or the recipe).
    let targets: Vec<PathBuf> = ReportOutput::file_names(format.0)
        .map_err(|e| CliError::Other(e.to_string()))?
        .iter()
        .map(|f| out_dir.join(f))
        .collect();
    ReportSettings::check_out_dir(&out_dir).map_err(|e| {
        super::flag_error("--out-dir", &out_dir.display().to_string(), e.to_string())
    })?;
    // A directory still to be made holds no input.
    let outputs: Vec<(&str, Option<&Path>)> = targets
        .iter()
        .filter(|_| out_dir.is_dir())
        .map(|p| ("--out-dir", Some(p.as_path())))
        .collect();
    fitbead::io::AtomicFile::distinct_paths(
        &[
            ("--input", input.as_deref()),
            ("--recipe", a.recipe.as_deref()),
        ],
        &outputs,
    )?;
    let data = io.read()?;
    let choice = io.method(&[])?;
    let settings = ReportSettings {
        level: io.level.level(),
        method: choice.method,
        format: format.0.to_string(),
        si_units: a.units == Some(Units::Si),
        figure_width: a.figure_width.clone(),
        keep_going: a.keep_going,
        defaults: io.data.defaults().checked()?,
        source: shown,
        stop: Some(super::stop_flag()),
        method_name: Some(values::name_of(&io.method)),
    };
    let out = settings.run(&data, Some(&out_dir))?;
    for s in &out.stats {
        if let Some(w) = s.misfit_warning() {
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
    not_converged(out.not_converged())
}
