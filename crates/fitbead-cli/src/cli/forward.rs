//! `fitbead forward`: mean velocity, regime and diagnostics of each scene under one model,
//! by the library's door [`TableCommand::run`] (the rows stream in bounded memory; md, whose
//! runs are long and few, reads the whole table).

use super::args::{ContactArgs, OutputArgs};
use super::values::{self, MdPreset};
use super::{emit, CliError};
use fitbead::io::measurements::MeasurementFile;
use fitbead::io::{AtomicFile, InputError};
use fitbead::models::md::{Md, MdParams, MdRunConfig, MdSettings, ReducedMass};
use fitbead::models::{JaegerBranch, ModelKind};
use fitbead::numfmt::fmt_f64;
use fitbead::pipeline::{ForwardSettings, RunError, StreamOptions, TableCommand, TableRun};
use fitbead::progress::Progress;
use std::io::{Cursor, Read, Write};
use std::path::{Path, PathBuf};

/// Arguments of `fitbead forward`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Forward model: stick, stick-approx, slip, slip-approx, stickslip, contact, jan, jaeger,
    /// md, or auto (per scene the cheapest model meeting --tol whose assumptions hold).
    #[arg(long, value_parser = values::choice::<ModelKind>())]
    pub model: ModelKind,
    /// Scenes CSV with columns xi,delta_deg[,K,rho,f] (K a number or a law name); extra columns
    /// pass through. Without --input and --xi: the embedded default data set.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Radius ratio ξ = r/R of a single scene.
    #[arg(long, value_parser = values::finite)]
    pub xi: Option<f64>,
    /// Slope δ of a single scene, degrees.
    #[arg(long = "delta-deg", value_parser = values::finite)]
    pub delta_deg: Option<f64>,
    /// Collisional parameter for rows without a K column: a number, cos2a, adjusted, impact or
    /// c=VALUE.
    #[arg(long = "K", default_value = "adjusted", value_parser = values::law_text)]
    pub k: String,
    /// ρ and f of rows without those columns.
    #[command(flatten)]
    pub contact: ContactArgs,
    /// Jan's λ (eq 74) [default: the paper's fit, eq 75, at each row's α]
    #[arg(long)]
    pub lambda: Option<f64>,
    /// Jan's μ (eq 74) [default: the paper's fit, eq 76, at each row's α]
    #[arg(long)]
    pub mu: Option<f64>,
    /// Jaeger's a1 (eq 83); required by --model jaeger.
    #[arg(long)]
    pub a1: Option<f64>,
    /// Jaeger's a2 (eq 83); required by --model jaeger.
    #[arg(long)]
    pub a2: Option<f64>,
    /// Jaeger's a3 (eq 83); required by --model jaeger.
    #[arg(long)]
    pub a3: Option<f64>,
    /// Jaeger root when there are two: upper or lower.
    #[arg(long, default_value = "upper", value_parser = values::choice::<JaegerBranch>())]
    pub branch: JaegerBranch,
    /// Spin rule of the collision for --model contact: roll (rolling restarts, the paper's
    /// choice), keep (spin unchanged), factor=L (ω0 = L ωf, eq 63) or impact (no-slip impact
    /// conserving angular momentum about the new contact point; K is then not used). A `spin`
    /// column overrides it per row.
    #[arg(long, default_value = "roll", value_parser = values::spin_text)]
    pub spin: String,
    /// Relative tolerance of the contact model's quadratures (time and spin during slip); with
    /// --model auto, the target relative tolerance T on v.
    #[arg(long, default_value = "1e-14", value_parser = values::tolerance)]
    pub tol: f64,
    /// Molecular-dynamics settings (`--model md`).
    #[command(flatten)]
    pub md: MdArgs,
    /// Refuse a column the scenes file has and fitbead does not read (without it, a column
    /// close to a known name gets a warning, others pass through)
    #[arg(long = "strict-columns")]
    pub strict_columns: bool,
}

/// Runs `fitbead forward`.
pub fn run(a: Args) -> Result<(), CliError> {
    let single = if let (Some(xi), Some(d)) = (a.xi, a.delta_deg) {
        Some(format!("xi,delta_deg\n{},{}\n", fmt_f64(xi), fmt_f64(d)).into_bytes())
    } else if a.xi.is_some() || a.delta_deg.is_some() {
        return Err(super::flag_error(
            "--xi/--delta-deg",
            "",
            "a single scene needs both --xi and --delta-deg",
        ));
    } else {
        None
    };
    let md = a.model == ModelKind::Md;
    let command = if md {
        TableCommand::ForwardMd {
            md: a.md.preset()?,
            flags: a.md.settings(),
            rho: a.contact.rho(),
            f: a.contact.f(),
            check_step: a.md.check_step,
            strict_columns: a.strict_columns,
        }
    } else {
        TableCommand::Forward {
            settings: settings(&a)?,
            strict_columns: a.strict_columns,
        }
    };
    let (source, input, size) = match single {
        Some(text) => {
            let n = text.len() as u64;
            (
                InputError::SETTINGS.to_string(),
                Input::Text(Cursor::new(text)),
                n,
            )
        }
        None => open_input(a.input.as_deref())?,
    };
    if md {
        let opts = StreamOptions {
            stop: Some(super::stop_flag()),
            progress: Some(md_progress(2000)),
            ..command.options()
        };
        let mut bytes = Vec::new();
        command.run(&source, input, &mut bytes, &opts, &mut warn)?;
        return emit(a.out.output.as_deref(), &bytes);
    }
    let opts = stream_options(&command, size);
    stream_to(
        &command,
        &source,
        input,
        a.out.output.as_deref(),
        &opts,
        |_| Ok(()),
    )
    .map(|_| ())
}

/// Prints a warning of a command on stderr.
pub(super) fn warn(w: &str) {
    eprintln!("fitbead: warning: {w}");
}

/// The forward settings of the flags (every model but md).
fn settings(a: &Args) -> Result<ForwardSettings, CliError> {
    let law = a.k.parse().map_err(|e: fitbead::scene::ParameterError| {
        super::flag_error("--K", &a.k, e.to_string())
    })?;
    let spin = a
        .spin
        .parse()
        .map_err(|e: fitbead::scene::ParameterError| {
            super::flag_error("--spin", &a.spin, e.to_string())
        })?;
    Ok(ForwardSettings {
        kind: a.model,
        law,
        rho: a.contact.rho(),
        f: a.contact.f(),
        lambda: a.lambda,
        mu: a.mu,
        a: [a.a1, a.a2, a.a3],
        branch: a.branch,
        spin,
        tol: a.tol,
    })
}

/// A streamed input: a file, the embedded default data, or text from the command line.
pub(super) enum Input {
    /// A file.
    File(std::fs::File),
    /// Text held in memory.
    Text(Cursor<Vec<u8>>),
    /// The embedded default data.
    Static(&'static [u8]),
    /// Standard input (`-`).
    Stdin(std::io::Stdin),
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Input::File(f) => f.read(buf),
            Input::Text(c) => c.read(buf),
            Input::Static(s) => s.read(buf),
            Input::Stdin(s) => s.read(buf),
        }
    }
}

/// Opens `path` for streaming (the embedded default data when `None`, standard input when it
/// is `-`): its name in messages, the reader and its size in bytes (0 when unknown).
pub(super) fn open_input(path: Option<&Path>) -> Result<(String, Input, u64), CliError> {
    match path {
        Some(p) if p == Path::new("-") => {
            Ok(("<stdin>".to_string(), Input::Stdin(std::io::stdin()), 0))
        }
        None => Ok((
            MeasurementFile::DEFAULT_DATA_NAME.to_string(),
            Input::Static(MeasurementFile::DEFAULT_DATA.as_bytes()),
            MeasurementFile::DEFAULT_DATA.len() as u64,
        )),
        Some(p) => {
            let name = p.display().to_string();
            let f = std::fs::File::open(p)
                .map_err(|e| InputError::file(&name, format!("cannot read: {e}")))?;
            let size = f.metadata().map(|m| m.len()).unwrap_or(0);
            Ok((name, Input::File(f), size))
        }
    }
}

/// The options of `command` with a stop flag raised by Ctrl-C or SIGTERM (the stream then
/// ends between tasks, `--output` untouched, exit 130) and a progress bar on a terminal's
/// stderr for runs longer than a couple of seconds.
pub(super) fn stream_options(command: &TableCommand, input_bytes: u64) -> StreamOptions {
    StreamOptions {
        stop: Some(super::stop_flag()),
        progress: super::delayed_progress_bar("bytes"),
        input_bytes: Some(input_bytes),
        ..command.options()
    }
}

/// Streams `input` through `command` into `output` (written atomically: a temporary file
/// renamed over the target only when the whole input proved good and `finish` succeeded; a
/// target that cannot be created is reported only after the input proved good) or stdout.
/// `finish` runs on what the run kept before the output is committed.
pub(super) fn stream_to(
    command: &TableCommand,
    source: &str,
    input: Input,
    output: Option<&Path>,
    opts: &StreamOptions,
    finish: impl FnOnce(&TableRun) -> Result<(), CliError>,
) -> Result<TableRun, CliError> {
    // `--output -` is standard output, as for the fit commands.
    match output.filter(|p| *p != Path::new("-")) {
        Some(p) => {
            let cannot =
                |e: std::io::Error| CliError::Other(format!("{}: cannot write: {e}", p.display()));
            let mut file = AtomicFile::create(p);
            // Unless the target is written in place (a device or FIFO), nothing written is
            // seen before the commit.
            let opts = StreamOptions {
                atomic_output: file.as_ref().map_or(true, |f| !f.is_direct()),
                ..opts.clone()
            };
            let r = match &mut file {
                Ok(f) => command.run(source, input, f, &opts, &mut warn),
                Err(_) => command.run(source, input, &mut std::io::sink(), &opts, &mut warn),
            };
            match r {
                Ok(done) => {
                    finish(&done)?;
                    file.and_then(AtomicFile::commit).map_err(cannot)?;
                    Ok(done)
                }
                Err(e) => Err(stream_error(e, &p.display().to_string(), true)),
            }
        }
        None => {
            let mut out = std::io::stdout();
            let r = command
                .run(source, input, &mut out, opts, &mut warn)
                .and_then(|d| {
                    out.flush()
                        .map(|()| d)
                        .map_err(|e| RunError::Library(e.into()))
                });
            match r {
                Ok(done) => {
                    finish(&done)?;
                    Ok(done)
                }
                Err(e) => Err(stream_error(e, "<stdout>", false)),
            }
        }
    }
}

/// The error of a streamed run whose output is `target` (a file when `file`).
fn stream_error(e: RunError, target: &str, file: bool) -> CliError {
    match e {
        RunError::Library(fitbead::Error::Io(e)) if file => {
            CliError::Other(format!("{target}: cannot write: {e}"))
        }
        RunError::Library(fitbead::Error::Io(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            CliError::Io(e)
        }
        RunError::Library(fitbead::Error::Io(e)) => CliError::Other(format!("{target}: {e}")),
        RunError::Interrupted => CliError::Stopped(if file {
            format!("interrupted: {target} was not written")
        } else {
            "interrupted: the output on stdout is incomplete".into()
        }),
        e => CliError::from(e),
    }
}

/// Settings of the molecular-dynamics model (`--model md`), shared by `forward` and
/// `simulate`. Every one has a default (Ristow's set, [`MdParams::ristow`]; the run of
/// [`MdRunConfig::default`]); in `forward` each may also be a column of the scenes CSV, named
/// as the flag with `_` for `-` (`young_pa`, `gamma_n`, …; `mu_c` for `--coulomb`), which
/// wins over the flag for its row.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct MdArgs {
    /// md parameter set: ristow (E = 1e7 Pa, gamma_n = 1000/s, gamma_s = 100/s, beta = 1.5,
    /// R = 2.5 mm, steel density) or steel (E = 2.1e11 Pa, the rest as ristow).
    #[arg(long = "md-preset", default_value = "ristow", value_parser = values::choice::<MdPreset>())]
    pub md_preset: MdPreset,
    /// md: radius R of the row beads, m [default: 2.5e-3]
    #[arg(long = "row-radius-m")]
    pub row_radius_m: Option<f64>,
    /// md: Young's modulus E, Pa (Ristow's k_n read as E in Hertz's law) [default: 1e7]
    #[arg(long = "young-pa")]
    pub young_pa: Option<f64>,
    /// md: Poisson ratio [default: 0.3]
    #[arg(long)]
    pub poisson: Option<f64>,
    /// md: bead density, kg/m^3 [default: 7850]
    #[arg(long)]
    pub density: Option<f64>,
    /// md: exponent beta of the normal force k_n d^beta [default: 1.5]
    #[arg(long)]
    pub beta: Option<f64>,
    /// md: normal damping gamma_n, 1/s [default: 1000]
    #[arg(long = "gamma-n")]
    pub gamma_n: Option<f64>,
    /// md: tangential damping gamma_s, 1/s [default: 100]
    #[arg(long = "gamma-s")]
    pub gamma_s: Option<f64>,
    /// md: Coulomb cap mu_c on the tangential force (column mu_c) [default: none, as Ristow]
    #[arg(long)]
    pub coulomb: Option<f64>,
    /// md: gravity, m/s^2 [default: 9.81]
    #[arg(long = "md-g")]
    pub md_g: Option<f64>,
    /// md: reduced mass of eq 92: pair (m M/(m+M)) or mobile (m) [default: pair]
    #[arg(long = "reduced-mass", value_parser = values::choice::<ReducedMass>())]
    pub reduced_mass: Option<ReducedMass>,
    /// Row beads travelled: by md, and by the contact transient of simulate --v0 [default: 400
    /// for md, 50 for the transient]
    #[arg(long)]
    pub beads: Option<usize>,
    /// md: row beads discarded as transient [default: 100]
    #[arg(long)]
    pub transient: Option<usize>,
    /// md: blocks for the standard error of v [default: 10]
    #[arg(long)]
    pub blocks: Option<usize>,
    /// md: launch speed on the top of the first row bead, units sqrt(g(R+r)) [default: 0.1]
    #[arg(long = "launch-velocity")]
    pub launch_velocity: Option<f64>,
    /// md: time step as a fraction of the contact time [default: 0.01]
    #[arg(long = "step-fraction")]
    pub step_fraction: Option<f64>,
    /// md: run again at half the step and report the relative change of v (step_check_rel).
    #[arg(long = "check-step")]
    pub check_step: bool,
}

impl MdArgs {
    /// The model from the preset, `--reduced-mass` and the flags (no table).
    pub fn model(&self) -> Result<Md, CliError> {
        Ok(self.settings().apply_flags(self.preset()?)?)
    }

    /// The model of the preset and `--reduced-mass`, before the other flags.
    fn preset(&self) -> Result<Md, CliError> {
        let mut params = match self.md_preset {
            MdPreset::Ristow => MdParams::ristow(),
            MdPreset::Steel => MdParams::steel(),
        };
        if let Some(m) = self.reduced_mass {
            params.reduced_mass = m;
        }
        let base = Md {
            params,
            config: MdRunConfig::default(),
        };
        Ok(MdSettings::default().apply_flags(base)?)
    }

    /// The md settings the flags give.
    fn settings(&self) -> MdSettings {
        let count = |n: Option<usize>| n.map(|b| b as f64);
        MdSettings {
            row_radius_m: self.row_radius_m,
            young_pa: self.young_pa,
            poisson: self.poisson,
            density: self.density,
            beta: self.beta,
            gamma_n: self.gamma_n,
            gamma_s: self.gamma_s,
            mu_c: self.coulomb,
            g: self.md_g,
            beads: count(self.beads),
            transient: count(self.transient),
            blocks: count(self.blocks),
            launch_velocity: self.launch_velocity,
            step_fraction: self.step_fraction,
        }
    }
}

/// A progress bar over `total` units on a terminal's stderr only.
pub fn md_progress_bar(total: u64, what: &str) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let b = indicatif::ProgressBar::new(total);
    b.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} {bar:30} {pos}/{len} ({elapsed}, eta {eta})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    b.set_message(what.to_string());
    Some(b)
}

/// The md runs' progress on a terminal's stderr (nothing elsewhere), drawn for tasks of at
/// least `min_total` units.
pub fn md_progress(min_total: u64) -> Progress {
    super::bar_sink(move |label, total, _| {
        if total >= min_total {
            md_progress_bar(total, label)
        } else {
            None
        }
    })
}
