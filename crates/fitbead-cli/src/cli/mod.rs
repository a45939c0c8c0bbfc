//! The command line: one module per subcommand. Errors are rendered here, once.

mod args;
mod bench;
mod design;
mod fitargs;
mod forward;
mod jaeger;
mod jan;
mod k;
mod klaw;
mod regimes;
mod report;
mod simulate;
mod values;

use clap::{Parser, Subcommand};
use fitbead::io::{AtomicFile, InputError};
use fitbead::progress::{Progress, ProgressEvent};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use fitbead::io::measurements::MeasurementFile;

/// fitbead: a bead rolling down a row of beads (Ancey, Evesque & Coussot 1996) — forward
/// models, regime limits and synthetic data. Velocities are dimensionless (units
/// sqrt(g (R + r))), slopes in degrees.
#[derive(Debug, Parser)]
#[command(name = "fitbead", version, about, long_about = None)]
pub(crate) struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub(crate) command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
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
    /// The slopes to measure, per series, for a fit's parameters (D, c criteria) or to tell
    /// two models apart (T), with the predicted standard errors. With --plot: the sensitivity
    /// of every candidate slope per series, the chosen slopes marked.
    Design(design::Args),
    /// Work-precision report: error against time of every model and method variant, and of
    /// `--model auto`, against cross-checked references (CSV and SVG).
    Bench(bench::Args),
}

/// Why a command failed: bad input (exit 2), an I/O failure (exit 2 as well: nothing was
/// written), a fit that produced no converged estimate (exit 1, after writing its outputs), or
/// an interruption by SIGINT or SIGTERM (exit 130).
#[derive(Debug)]
pub(crate) enum CliError {
    /// Bad input, located.
    Input(InputError),
    /// Any other failure, with a message.
    Other(String),
    /// The outputs were written but a fit did not converge: the message says which (exit 1).
    NotConverged(String),
    /// Stopped by SIGINT or SIGTERM before writing anything: existing outputs are untouched
    /// (exit 130).
    Interrupted,
    /// Reading or writing failed (a closed pipe on stdout is not an error: exit 0).
    Io(std::io::Error),
    /// Stopped by Ctrl-C or SIGTERM before the end, saying what was (not) written (exit 130).
    Stopped(String),
    /// Stopped by SIGINT or SIGTERM after writing what there was, every output marked
    /// `interrupted` (exit 130).
    InterruptedPartial,
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

impl From<fitbead::pipeline::RunError> for CliError {
    fn from(e: fitbead::pipeline::RunError) -> Self {
        use fitbead::pipeline::RunError;
        match e {
            RunError::Input(i) => CliError::Input(i),
            RunError::Failed(s) => CliError::Other(s),
            RunError::Interrupted => CliError::Interrupted,
            RunError::Library(e) => CliError::from(e),
            e => CliError::Other(e.to_string()),
        }
    }
}

impl From<InputError> for CliError {
    fn from(e: InputError) -> Self {
        CliError::Input(e)
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CliError::Input(e) => write!(f, "{e}"),
            CliError::Other(s) | CliError::NotConverged(s) => f.write_str(s),
            CliError::Interrupted => f.write_str(
                "interrupted (SIGINT or SIGTERM): nothing written, existing outputs untouched",
            ),
            CliError::InterruptedPartial => f.write_str(
                "interrupted (SIGINT or SIGTERM): the outputs hold the draws so far, every row \
                 marked interrupted",
            ),
            CliError::Io(e) => write!(f, "{e}"),
            CliError::Stopped(s) => f.write_str(s),
        }
    }
}

/// Longest error message printed, in characters; a run of more than [`InputError::ECHO_CHARS`]
/// characters without a space (a value quoted whole) is cut as well.
const MESSAGE_CHARS: usize = 2000;

/// `message` with every word longer than [`InputError::ECHO_CHARS`] characters cut ([`InputError::clip`]) and the
/// whole cut at [`MESSAGE_CHARS`].
fn clip_message(message: &str) -> String {
    let words: Vec<std::borrow::Cow<'_, str>> = message
        .split(' ')
        .map(|w| InputError::clip(w, 2 * InputError::ECHO_CHARS))
        .collect();
    InputError::clip(&words.join(" "), MESSAGE_CHARS).into_owned()
}

/// The command line's parser: [`Cli`]'s, with negative numbers allowed as the values of every
/// flag (`--xi -1` is the value −1 given to `--xi`, refused by its check, not an unknown flag
/// `-1`), and any value starting with `-` taken by a flag that reads a number or a list of
/// them (`--delta-deg -inf` is the value −∞, refused by the flag's check, not a flag `-i`;
/// `--delta-range -5,10` and `--series -1,2` reach their flags' checks).
fn command() -> clap::Command {
    use clap::CommandFactory;
    let mut cmd = Cli::command();
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    let number = std::any::TypeId::of::<f64>();
    for n in names {
        cmd = cmd.mut_subcommand(n, |s| {
            s.allow_negative_numbers(true).mut_args(|a| {
                let takes_value = a.get_action().takes_values();
                let parser = a.get_value_parser().type_id();
                let text = [
                    std::any::TypeId::of::<String>(),
                    std::any::TypeId::of::<PathBuf>(),
                    std::any::TypeId::of::<std::ffi::OsString>(),
                ];
                if parser == number
                    || (takes_value && !text.iter().any(|t| parser == *t) && !a.is_positional())
                {
                    a.allow_hyphen_values(true)
                } else {
                    a
                }
            })
        });
    }
    cmd
}

/// Parses the command line. A value refused by its flag's parser is an error in the project's
/// form ([`value_error`]); clap's other errors (an unknown flag, a missing value) and `--help`
/// print and exit as clap does. A report's recipe gives the defaults of the flags named by its
/// keys ([`report::Recipe`]).
pub(crate) fn parse() -> Result<Cli, CliError> {
    use clap::FromArgMatches;
    let cmd = command();
    let m = cmd.clone().try_get_matches().map_err(value_error)?;
    let recipe = match m.subcommand() {
        Some(("report", sub)) => report::Recipe::for_flags(sub)?,
        _ => None,
    };
    let Some(recipe) = recipe else {
        return Cli::from_arg_matches(&m).map_err(value_error);
    };
    let cmd = cmd.mut_subcommand("report", |s| recipe.defaults(s));
    let m = cmd
        .try_get_matches()
        .map_err(|e| recipe.blame(value_error(e)))?;
    let mut cli = Cli::from_arg_matches(&m).map_err(value_error)?;
    if let Command::Report(a) = &mut cli.command {
        a.recipe_used = Some(recipe);
    }
    Ok(cli)
}

/// A value refused by its flag's parser as the project's error (`<command line>, flag
/// '--NAME', value 'V': message`, exit 2); any other error of clap is printed by clap, which
/// exits.
fn value_error(e: clap::Error) -> CliError {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let text = |k: ContextKind| match e.get(k) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        _ => None,
    };
    // `--NAME <VALUE>`: the flag is the first word.
    let flag = text(ContextKind::InvalidArg)
        .and_then(|a| a.split(' ').next().map(str::to_string))
        .filter(|f| f.starts_with("--"));
    let value = text(ContextKind::InvalidValue).filter(|v| !v.is_empty());
    let (Some(flag), Some(value)) = (flag, value) else {
        e.exit()
    };
    let (value, message) = match e.kind() {
        ErrorKind::ValueValidation => {
            let source = std::error::Error::source(&e);
            match source.and_then(|s| s.downcast_ref::<values::Refusal>()) {
                Some(r) => (r.part.clone().unwrap_or(value), r.message.clone()),
                None => (value, source.map(|s| s.to_string()).unwrap_or_default()),
            }
        }
        ErrorKind::InvalidValue => {
            let expected = match e.get(ContextKind::ValidValue) {
                Some(ContextValue::Strings(v)) => v.join(", "),
                _ => String::new(),
            };
            (value, format!("expected one of {expected}"))
        }
        _ => e.exit(),
    };
    flag_error(&flag, &value, message)
}

/// Runs the parsed command line; returns the process exit code.
pub(crate) fn run(cli: Cli) -> i32 {
    if let Err(e) = check_stdout(&cli.command).and_then(|()| check_paths(&cli.command)) {
        eprintln!("fitbead: error: {}", clip_message(&e.to_string()));
        return 2;
    }
    let files: Vec<(PathBuf, FileState)> = file_outputs(&cli.command)
        .into_iter()
        // A character device (/dev/null, a terminal) is never "unwritten".
        .filter(|p| !fitbead::io::AtomicFile::is_char_device(p))
        .map(|p| {
            let st = file_state(&p);
            (p, st)
        })
        .collect();
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
        Command::Design(a) => design::run(a),
    };
    // A signal that arrived after the last check still means the run was cut short.
    let r = match r {
        Ok(()) if stop_requested() => Err(CliError::Interrupted),
        r => r,
    };
    match r {
        Ok(()) => 0,
        // A reader that stops early (`| head`) ends the run quietly, unless files it was to
        // write are left unwritten: then it is an error that names them.
        Err(CliError::Io(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            let unwritten: Vec<String> = files
                .iter()
                .filter(|(p, before)| file_state(p) == *before)
                .map(|(p, _)| p.display().to_string())
                .collect();
            if unwritten.is_empty() {
                0
            } else {
                eprintln!(
                    "fitbead: error: standard output was closed before the run ended (broken \
                     pipe): {} not written",
                    unwritten.join(", ")
                );
                2
            }
        }
        Err(e @ (CliError::Interrupted | CliError::InterruptedPartial | CliError::Stopped(_))) => {
            eprintln!("fitbead: {e}");
            130
        }
        Err(CliError::NotConverged(m)) => {
            eprintln!("fitbead: not converged: {}", clip_message(&m));
            1
        }
        Err(e) => {
            eprintln!("fitbead: error: {}", clip_message(&e.to_string()));
            2
        }
    }
}

/// True when standard output was closed when fitbead started. Rust's runtime reopens a closed
/// descriptor 1 on `/dev/null`, read-write, before `main`, so that the output would vanish
/// without an error; that descriptor is recognised here (on Linux, from /proc: `/dev/null`
/// opened read-write, which a shell's `>/dev/null` never does). Elsewhere only a descriptor
/// that is not open at all counts.
pub(crate) fn stdout_closed() -> bool {
    static CLOSED: OnceLock<bool> = OnceLock::new();
    *CLOSED.get_or_init(|| {
        #[cfg(target_os = "linux")]
        {
            let null =
                std::fs::read_link("/proc/self/fd/1").is_ok_and(|p| p == Path::new("/dev/null"));
            if null {
                let flags = std::fs::read_to_string("/proc/self/fdinfo/1")
                    .ok()
                    .and_then(|info| {
                        info.lines()
                            .find_map(|l| l.strip_prefix("flags:"))
                            .and_then(|f| u32::from_str_radix(f.trim(), 8).ok())
                    });
                // O_ACCMODE = 3, O_RDWR = 2.
                if flags.is_some_and(|f| f & 3 == 2) {
                    return true;
                }
            }
        }
        #[cfg(unix)]
        {
            use std::os::fd::BorrowedFd;
            // SAFETY: descriptor 1 is only duplicated (F_DUPFD_CLOEXEC), never closed or
            // read; a descriptor that is not open makes the duplication fail with EBADF,
            // which is what is tested.
            let fd = unsafe { BorrowedFd::borrow_raw(1) };
            if fd.try_clone_to_owned().is_err() {
                return true;
            }
        }
        false
    })
}

/// Refuses a command whose result would go to a closed standard output.
fn check_stdout(c: &Command) -> Result<(), CliError> {
    let to_stdout = match c {
        Command::Forward(a) => a.out.output.is_none(),
        Command::K(a) => a.out.output.is_none(),
        Command::Klaw(a) => a.io.out.output.is_none(),
        Command::Jan(a) => a.io.out.output.is_none(),
        Command::Jaeger(a) => a.io.out.output.is_none(),
        Command::Regimes(a) => a.out.output.is_none(),
        // The tables go to --out-dir; stdout only shows a summary of them.
        Command::Report(_) => false,
        Command::Simulate(a) => a.out.output.is_none(),
        Command::Bench(a) => a.out.output.is_none(),
        Command::Design(a) => a.out.output.is_none(),
    };
    if stdout_closed() && to_stdout {
        return Err(CliError::Other(
            "standard output is closed: the result has nowhere to go (give --output FILE, or \
             redirect stdout)"
                .into(),
        ));
    }
    Ok(())
}

/// Paths named by the flag that gives them (absent when the flag is not given).
pub(crate) type NamedPaths<'a> = Vec<(&'static str, Option<&'a Path>)>;

/// The inputs and outputs of a command, named by the flags that give them (absent ones
/// `None`; the first output is the result's, `--output`, where the command has one).
fn paths(c: &Command) -> (NamedPaths<'_>, NamedPaths<'_>) {
    fn opt(p: &Option<PathBuf>) -> Option<&Path> {
        p.as_deref()
    }
    match c {
        Command::Forward(a) => (
            vec![("--input", opt(&a.input))],
            vec![("--output", opt(&a.out.output))],
        ),
        Command::K(a) => (
            vec![("--input", a.data.path())],
            vec![
                ("--output", opt(&a.out.output)),
                ("--plot", opt(&a.plot.plot)),
            ],
        ),
        Command::Klaw(a) => a.io.paths(),
        Command::Jan(a) => a.io.paths(),
        Command::Jaeger(a) => a.io.paths(),
        Command::Regimes(a) => (vec![], vec![("--output", opt(&a.out.output))]),
        Command::Report(a) => (
            vec![("--input", a.data.path()), ("--recipe", opt(&a.recipe))],
            vec![],
        ),
        Command::Simulate(a) => (
            vec![("--design", opt(&a.design))],
            vec![("--output", opt(&a.out.output))],
        ),
        Command::Bench(a) => (
            vec![],
            vec![
                ("--output", opt(&a.out.output)),
                ("--plot", opt(&a.plot.plot)),
            ],
        ),
        Command::Design(a) => (
            vec![],
            vec![
                ("--output", opt(&a.out.output)),
                ("--plot", opt(&a.plot.plot)),
            ],
        ),
    }
}

/// What a file's metadata says of its content: none (no file), or its inode, size and
/// modification time (a file replaced by a rename gets a new inode).
type FileState = Option<(u64, u64, Option<std::time::SystemTime>)>;

fn file_state(p: &Path) -> FileState {
    #[cfg(unix)]
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(p).ok()?;
    #[cfg(unix)]
    let ino = m.ino();
    #[cfg(not(unix))]
    let ino = 0;
    Some((ino, m.len(), m.modified().ok()))
}

/// The output files of a command that are not standard output (`--out-dir` aside): what a
/// broken standard output leaves unwritten.
fn file_outputs(c: &Command) -> Vec<PathBuf> {
    paths(c)
        .1
        .into_iter()
        .filter_map(|(_, p)| p)
        .filter(|p| fitbead::io::AtomicFile::stream_of(p) != Some(1))
        .map(Path::to_path_buf)
        .collect()
}

/// Refuses, before any work, an output that is also an input or another output of the same
/// run (after following symbolic links), an output that is a directory, and two outputs to
/// standard output (`-`, `/dev/stdout`; without `--output` the result takes it).
fn check_paths(c: &Command) -> Result<(), CliError> {
    let (inputs, outputs) = paths(c);
    AtomicFile::distinct_paths(&inputs, &outputs)?;
    // Without --output the result goes to standard output, which no other output may take.
    let result_on_stdout =
        matches!(outputs.first(), Some(("--output", None))) && !matches!(c, Command::Report(_));
    if result_on_stdout {
        for (flag, p) in outputs.iter().skip(1) {
            if let Some(p) = p.filter(|p| fitbead::io::AtomicFile::stream_of(p) == Some(1)) {
                return Err(flag_error(
                    flag,
                    &p.display().to_string(),
                    "goes to standard output, which takes the result when --output is not \
                     given: give --output FILE, or a file here",
                ));
            }
        }
    }
    Ok(())
}

/// The stop flag raised by SIGINT (Ctrl-C), SIGTERM or SIGHUP: the handler is installed on the
/// first call and every later call returns the same flag. Long computations poll it (the
/// library takes it as an option) and stop within about a second.
pub(crate) fn stop_flag() -> Arc<AtomicBool> {
    STOP.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        // Installing fails only if another handler is installed already (e.g. by a caller
        // that runs commands in-process); the flag then stays down and the run is not
        // interruptible this way, which is no worse than without it.
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
        stop
    })
    .clone()
}

/// True once SIGINT, SIGTERM or SIGHUP arrived (false when [`stop_flag`] was never called).
pub(crate) fn stop_requested() -> bool {
    STOP.get().is_some_and(|f| f.load(Ordering::SeqCst))
}

/// The flag of [`stop_flag`], once installed.
static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Reads an input file (or the embedded default data when `path` is `None`; standard input
/// when it is `-`).
pub(crate) fn read_input(path: Option<&Path>) -> Result<(String, Vec<u8>), CliError> {
    match path {
        None => Ok((
            MeasurementFile::DEFAULT_DATA_NAME.to_string(),
            MeasurementFile::DEFAULT_DATA.as_bytes().to_vec(),
        )),
        Some(p) if p == Path::new("-") => {
            use std::io::Read;
            let mut b = Vec::new();
            std::io::stdin()
                .lock()
                .read_to_end(&mut b)
                .map(|_| ("<stdin>".to_string(), b))
                .map_err(|e| {
                    CliError::Input(InputError::file("<stdin>", format!("cannot read: {e}")))
                })
        }
        Some(p) => {
            let name = p.display().to_string();
            std::fs::read(p)
                .map(|b| (name.clone(), b))
                .map_err(|e| CliError::Input(InputError::file(&name, format!("cannot read: {e}"))))
        }
    }
}

/// Writes output bytes to a file atomically, or to stdout.
pub(crate) fn emit(output: Option<&Path>, bytes: &[u8]) -> Result<(), CliError> {
    // `--output -` is standard output, as for the fit commands.
    match output.filter(|p| *p != Path::new("-")) {
        Some(p) => AtomicFile::write_file(p, bytes)
            .map_err(|e| CliError::Other(format!("{}: cannot write: {e}", p.display()))),
        None => print_stdout(bytes),
    }
}

/// Writes `bytes` to stdout. A reader that closed the pipe early (`fitbead … | head -1`) is
/// [`CliError::Io`] with kind `BrokenPipe`, which [`run`] turns into a quiet exit 0.
pub(crate) fn print_stdout(bytes: &[u8]) -> Result<(), CliError> {
    use std::io::Write;
    if stdout_closed() {
        return Err(CliError::Other(
            "<stdout>: standard output is closed: the result has nowhere to go".into(),
        ));
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(CliError::Io(e)),
        Err(e) => Err(CliError::Other(format!("<stdout>: {e}"))),
    }
}

/// A progress bar on stderr for posterior runs: one bar per run, drawn from the library's
/// progress events.
pub(crate) fn sampler_progress_bar() -> Progress {
    bar_sink(|label, total, check_every| {
        let b = indicatif::ProgressBar::new(total);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg} {bar:30} {pos}/{len} steps ({elapsed}, checks every {prefix})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b.set_prefix(check_every.to_string());
        b.set_message(label.to_string());
        Some(b)
    })
}

/// A progress sink that draws one bar per task: `start(label, total, check_every)` makes the
/// task's bar (or none), which follows the task's positions and is cleared when it finishes.
pub(crate) fn bar_sink(
    start: impl Fn(&str, u64, u64) -> Option<indicatif::ProgressBar> + Send + Sync + 'static,
) -> Progress {
    let bar: Mutex<Option<indicatif::ProgressBar>> = Mutex::new(None);
    Progress::new(move |e| {
        let Ok(mut slot) = bar.lock() else { return };
        match e {
            ProgressEvent::Start {
                label,
                total,
                check_every,
            } => *slot = start(label, total, check_every),
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
pub(crate) fn delayed_progress_bar(unit: &'static str) -> Option<Progress> {
    use std::io::IsTerminal;
    use std::time::{Duration, Instant};
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let delay = progress_delay();
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
                if s.bar.is_none() && s.started.elapsed() >= delay {
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

/// How long a task runs before [`delayed_progress_bar`] draws it: two seconds, or the
/// milliseconds of the environment variable `FITBEAD_PROGRESS_DELAY_MS`.
fn progress_delay() -> std::time::Duration {
    std::env::var("FITBEAD_PROGRESS_DELAY_MS")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .map_or(
            std::time::Duration::from_secs(2),
            std::time::Duration::from_millis,
        )
}

/// An error about a command-line flag value.
pub(crate) fn flag_error(flag: &str, value: &str, message: impl Into<String>) -> CliError {
    CliError::Input(InputError {
        file: InputError::SETTINGS.into(),
        line: None,
        column: Some(flag.to_string()),
        value: Some(value.to_string()),
        message: message.into(),
    })
}

/// The `fitbead` command: parses the process's arguments, runs the subcommand, and returns the
/// exit code (0 done, 1 a fit that did not converge, 2 bad input or a failed read or write,
/// 130 interrupted by a signal; `docs/GUIDE.md`, "Exit codes"). The binary is this call.
pub fn main() -> i32 {
    match parse() {
        Ok(cli) => run(cli),
        Err(e) => {
            eprintln!("fitbead: error: {}", clip_message(&e.to_string()));
            2
        }
    }
}
