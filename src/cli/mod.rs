//! The command line: one module per subcommand. Errors are rendered here, once.

pub mod bench;
pub mod fitargs;
pub mod forward;
pub mod jaeger;
pub mod jan;
pub mod k;
pub mod klaw;
pub mod regimes;
pub mod report;
pub mod simulate;

use clap::{Parser, Subcommand};
use fitbead::io::{write_atomic, InputError};
use fitbead::progress::{Progress, ProgressEvent};
use std::path::Path;
use std::sync::Mutex;

use fitbead::io::measurements::{MeasurementDefaults, DEFAULT_DATA, DEFAULT_DATA_NAME};

/// fitbead: a bead rolling down a row of beads (Ancey, Evesque & Coussot 1996) — forward
/// models, regime limits and synthetic data. Velocities are dimensionless (units
/// sqrt(g (R + r))), slopes in degrees.
#[derive(Debug, Parser)]
#[command(name = "fitbead", version, about, long_about = None)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Mean velocity, regime and diagnostics of scenes under one forward model.
    Forward(forward::Args),
    /// The collisional parameter K of every measured point (eq 69), with its interval.
    K(k::Args),
    /// A law K(α) fitted to all series at once (law c or one K per series), with the impact
    /// law scored beside it.
    Klaw(klaw::Args),
    /// Jan's λ and μ per series (eq 74) and the global laws of eqs 75–76, fitted on v̄.
    Jan(jan::Args),
    /// Jaeger's a1, a2, a3 per series (eqs 80–84), with the branch and the bistable band.
    Jaeger(jaeger::Args),
    /// Regime limits δ_m (eq 32) and δ_d (eq 31) per ξ, and the critical ξ, for a law.
    Regimes(regimes::Args),
    /// Every model fitted to one data set and the paper's comparisons (bulk friction vs eq 79,
    /// energy budgets, regime map, model ranking) as CSV tables, SVG figures and report.md.
    Report(report::Args),
    /// Synthetic measurements inside regime B, reproducible from a seed.
    Simulate(simulate::Args),
    /// Work-precision report: error against time of every model and method variant, and of
    /// `--model auto`, against cross-checked references (CSV and SVG).
    Bench(bench::Args),
}

/// Why a command failed: bad input (exit 2), an I/O failure (exit 2 as well: nothing was
/// written), or an interruption by Ctrl-C after the outputs were written (exit 130).
#[derive(Debug)]
pub enum CliError {
    /// Bad input, located.
    Input(InputError),
    /// Any other failure, with a message.
    Other(String),
    /// Stopped by Ctrl-C after writing what there was (exit 130).
    Interrupted,
    /// Reading or writing failed (a closed pipe on stdout is not an error: exit 0).
    Io(std::io::Error),
    /// Stopped by Ctrl-C or SIGTERM before the end, saying what was (not) written (exit 130).
    Stopped(String),
}

impl From<std::io::Error> for CliError {
    fn from(e: std::io::Error) -> Self {
        CliError::Io(e)
    }
}

impl From<csv::Error> for CliError {
    fn from(e: csv::Error) -> Self {
        if e.is_io_error() {
            match e.into_kind() {
                csv::ErrorKind::Io(io) => CliError::Io(io),
                k => CliError::Other(format!("{k:?}")),
            }
        } else {
            CliError::Other(e.to_string())
        }
    }
}

impl From<fitbead::Error> for CliError {
    fn from(e: fitbead::Error) -> Self {
        match e {
            fitbead::Error::Input(i) => CliError::Input(i),
            fitbead::Error::Io(io) => CliError::Io(io),
            e => CliError::Other(e.to_string()),
        }
    }
}

impl std::error::Error for CliError {}

impl From<InputError> for CliError {
    fn from(e: InputError) -> Self {
        CliError::Input(e)
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CliError::Input(e) => write!(f, "{e}"),
            CliError::Other(s) => f.write_str(s),
            CliError::Interrupted => f.write_str(
                "interrupted (Ctrl-C): the outputs hold the draws so far, marked interrupted",
            ),
            CliError::Io(e) => write!(f, "{e}"),
            CliError::Stopped(s) => f.write_str(s),
        }
    }
}

/// Runs the parsed command line; returns the process exit code.
pub fn run(cli: Cli) -> i32 {
    let r = match cli.command {
        Command::Forward(a) => forward::run(a),
        Command::K(a) => k::run(a),
        Command::Klaw(a) => klaw::run(a),
        Command::Jan(a) => jan::run(a),
        Command::Jaeger(a) => jaeger::run(a),
        Command::Regimes(a) => regimes::run(a),
        Command::Report(a) => report::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Bench(a) => bench::run(a),
    };
    match r {
        Ok(()) => 0,
        Err(CliError::Io(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e @ (CliError::Interrupted | CliError::Stopped(_))) => {
            eprintln!("fitbead: {e}");
            130
        }
        Err(e) => {
            eprintln!("fitbead: error: {e}");
            2
        }
    }
}

/// Reads an input file (or the embedded default data when `path` is `None`).
pub fn read_input(path: Option<&Path>) -> Result<(String, Vec<u8>), CliError> {
    match path {
        None => Ok((
            DEFAULT_DATA_NAME.to_string(),
            DEFAULT_DATA.as_bytes().to_vec(),
        )),
        Some(p) => {
            let name = p.display().to_string();
            std::fs::read(p)
                .map(|b| (name.clone(), b))
                .map_err(|e| CliError::Input(InputError::file(&name, format!("cannot read: {e}"))))
        }
    }
}

/// Writes output bytes to a file atomically, or to stdout.
pub fn emit(output: Option<&Path>, bytes: &[u8]) -> Result<(), CliError> {
    match output {
        Some(p) => write_atomic(p, bytes)
            .map_err(|e| CliError::Other(format!("{}: cannot write: {e}", p.display()))),
        None => print_stdout(bytes),
    }
}

/// Writes `bytes` to stdout. A reader that closed the pipe early (`fitbead … | head -1`) is
/// [`CliError::Io`] with kind `BrokenPipe`, which [`run`] turns into a quiet exit 0.
pub fn print_stdout(bytes: &[u8]) -> Result<(), CliError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(CliError::Io(e)),
        Err(e) => Err(CliError::Other(format!("<stdout>: {e}"))),
    }
}

/// Checks the `--rho`, `--f` and `--g` flags and makes them the measurement defaults.
pub fn measurement_defaults(rho: f64, f: f64, g: f64) -> Result<MeasurementDefaults, CliError> {
    for (flag, x) in [("--rho", rho), ("--f", f)] {
        if !(x >= 0.0 && x.is_finite()) {
            return Err(flag_error(
                flag,
                &x.to_string(),
                "must be a finite number >= 0",
            ));
        }
    }
    if !(g > 0.0 && g.is_finite()) {
        return Err(flag_error("--g", &g.to_string(), "g must be > 0"));
    }
    Ok(MeasurementDefaults { rho, f, g })
}

/// A progress bar on stderr for posterior runs: one bar per run, drawn from the library's
/// progress events.
pub fn sampler_progress_bar() -> Progress {
    let bar: Mutex<Option<indicatif::ProgressBar>> = Mutex::new(None);
    Progress::new(move |e| {
        let Ok(mut slot) = bar.lock() else { return };
        match e {
            ProgressEvent::Start {
                label,
                total,
                check_every,
            } => {
                let b = indicatif::ProgressBar::new(total);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{msg} {bar:30} {pos}/{len} steps ({elapsed}, checks every {prefix})",
                    )
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
                );
                b.set_prefix(check_every.to_string());
                b.set_message(label.to_string());
                *slot = Some(b);
            }
            ProgressEvent::Position(p) => {
                if let Some(b) = slot.as_ref() {
                    b.set_position(p);
                }
            }
            ProgressEvent::Finish => {
                if let Some(b) = slot.take() {
                    b.finish_and_clear();
                }
            }
        }
    })
}

/// A progress bar on a terminal's stderr for long runs (none when stderr is not a terminal):
/// drawn from the library's progress events only once a task has run for two seconds, so
/// that short runs show nothing. Totals count `unit`s; a task of unknown total (0) shows a
/// spinner with the count.
pub fn delayed_progress_bar(unit: &'static str) -> Option<Progress> {
    use std::io::IsTerminal;
    use std::time::{Duration, Instant};
    if !std::io::stderr().is_terminal() {
        return None;
    }
    struct State {
        label: String,
        total: u64,
        started: Instant,
        bar: Option<indicatif::ProgressBar>,
    }
    let state: Mutex<Option<State>> = Mutex::new(None);
    Some(Progress::new(move |e| {
        let Ok(mut slot) = state.lock() else { return };
        match e {
            ProgressEvent::Start { label, total, .. } => {
                if let Some(b) = slot.take().and_then(|s| s.bar) {
                    b.finish_and_clear();
                }
                *slot = Some(State {
                    label: label.to_string(),
                    total,
                    started: Instant::now(),
                    bar: None,
                });
            }
            ProgressEvent::Position(p) => {
                let Some(s) = slot.as_mut() else { return };
                if s.bar.is_none() && s.started.elapsed() >= Duration::from_secs(2) {
                    let (b, template) = if s.total > 0 {
                        (
                            indicatif::ProgressBar::new(s.total),
                            format!("{{msg}} {{bar:30}} {{percent}}% of {{len}} {unit} ({{elapsed}}, eta {{eta}})"),
                        )
                    } else {
                        (
                            indicatif::ProgressBar::new_spinner(),
                            format!("{{msg}} {{spinner}} {{pos}} {unit} ({{elapsed}})"),
                        )
                    };
                    b.set_style(
                        indicatif::ProgressStyle::with_template(&template)
                            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
                    );
                    b.set_message(s.label.clone());
                    b.enable_steady_tick(Duration::from_millis(200));
                    s.bar = Some(b);
                }
                if let Some(b) = &s.bar {
                    b.set_position(p);
                }
            }
            ProgressEvent::Finish => {
                if let Some(b) = slot.take().and_then(|s| s.bar) {
                    b.finish_and_clear();
                }
            }
        }
    }))
}

/// Parses a comma-separated list of numbers given on the command line.
pub fn parse_list(flag: &str, s: &str) -> Result<Vec<f64>, CliError> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    CliError::Input(InputError {
                        file: "<command line>".into(),
                        line: None,
                        column: Some(flag.to_string()),
                        value: Some(t.to_string()),
                        message: "not a finite number".into(),
                    })
                })
        })
        .collect()
}

/// The Jaeger root of `--branch` (`upper`, the default, or `lower`; eqs 80–89).
pub fn jaeger_branch(value: &str) -> Result<fitbead::models::JaegerBranch, CliError> {
    use fitbead::models::JaegerBranch;
    match value {
        "upper" => Ok(JaegerBranch::Upper),
        "lower" => Ok(JaegerBranch::Lower),
        b => Err(flag_error("--branch", b, "expected upper or lower")),
    }
}

/// An error about a command-line flag value.
pub fn flag_error(flag: &str, value: &str, message: impl Into<String>) -> CliError {
    CliError::Input(InputError {
        file: "<command line>".into(),
        line: None,
        column: Some(flag.to_string()),
        value: Some(value.to_string()),
        message: message.into(),
    })
}
