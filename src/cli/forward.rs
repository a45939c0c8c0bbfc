//! `fitbead forward`: mean velocity, regime and diagnostics of each scene under one model.
//! The rows stream through the library's engine (`fitbead::io::stream`) with the scene plan
//! of `fitbead::io::forward`; md, whose runs are long and few, reads the whole table.

use super::args::{ContactArgs, OutputArgs};
use super::{emit, read_input, CliError};
use fitbead::io::forward::{scene_error, ForwardPlan, ForwardSettings, SceneColumns};
use fitbead::io::scenes::{Table, TableReader};
use fitbead::io::stream::{stream, RowPlan, StreamError, StreamOptions, Streamed};
use fitbead::io::{fmt_f64, AtomicFile, InputError};
use fitbead::models::md::{
    Md, MdParams, MdResult, MdRunConfig, MdSetting, MdSettings, ReducedMass,
};
use fitbead::models::Regime;
use fitbead::models::{regime_of, JaegerBranch, Model, ModelKind};
use fitbead::scene::ParameterError as Error;
use fitbead::scene::{CollisionLaw, Scene};
use rayon::prelude::*;
use std::io::{Cursor, Read, Write};
use std::path::{Path, PathBuf};

/// Arguments of `fitbead forward`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Forward model: stick, stick-approx, slip, slip-approx, stickslip, contact, jan, jaeger,
    /// md, or auto (per scene the cheapest model meeting --tol whose assumptions hold).
    #[arg(long)]
    pub model: String,
    /// Scenes CSV with columns xi,delta_deg[,K,rho,f] (K a number or a law name); extra columns
    /// pass through. Without --input and --xi: the embedded default data set.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// Radius ratio ξ = r/R of a single scene.
    #[arg(long)]
    pub xi: Option<f64>,
    /// Slope δ of a single scene, degrees.
    #[arg(long = "delta-deg")]
    pub delta_deg: Option<f64>,
    /// Collisional parameter for rows without a K column: a number, cos2a, adjusted, impact or
    /// c=VALUE.
    #[arg(long = "K", default_value = "adjusted")]
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
    #[arg(long, default_value = "upper")]
    pub branch: String,
    /// Spin rule of the collision for --model contact: roll (rolling restarts, the paper's
    /// choice), keep (spin unchanged), factor=L (ω0 = L ωf, eq 63) or impact (no-slip impact
    /// conserving angular momentum about the new contact point; K is then not used). A `spin`
    /// column overrides it per row.
    #[arg(long, default_value = "roll")]
    pub spin: String,
    /// Relative tolerance of the contact model's quadratures (time and spin during slip); with
    /// --model auto, the target relative tolerance T on v.
    #[arg(long, default_value = "1e-14")]
    pub tol: f64,
    /// Molecular-dynamics settings (`--model md`).
    #[command(flatten)]
    pub md: MdArgs,
}

/// Runs `fitbead forward`.
pub fn run(a: Args) -> Result<(), CliError> {
    let kind: ModelKind = a.model.parse().map_err(|_| {
        super::flag_error(
            "--model",
            &a.model,
            format!("unknown model; expected one of {}", Model::NAMES.join(", ")),
        )
    })?;
    let branch = super::jaeger_branch(&a.branch)?;
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
    if kind == ModelKind::Md {
        let (source, text) = match single {
            Some(text) => ("<command line>".to_string(), text),
            None => read_input(a.input.as_deref())?,
        };
        let t = Table::parse(&source, &text)?;
        return run_md(&a, &t);
    }
    let (source, input, size) = match single {
        Some(text) => {
            let n = text.len() as u64;
            (
                "<command line>".to_string(),
                Input::Text(Cursor::new(text)),
                n,
            )
        }
        None => open_input(a.input.as_deref())?,
    };
    let reader = TableReader::new(&source, input)?;
    let opts = stream_options("forward", size);
    let make = |r: &TableReader<Input>| plan(&a, kind, branch, r);
    stream_to(reader, make, (), a.out.output.as_deref(), &opts, |_| Ok(())).map(|_| ())
}

/// The scene plan of `a` for a table with `r`'s header: the columns first, then the flags
/// (`--spin`, `--tol`, `--K`), so that their errors come in that order.
fn plan<R: Read>(
    a: &Args,
    kind: ModelKind,
    branch: JaegerBranch,
    r: &TableReader<R>,
) -> Result<ForwardPlan, InputError> {
    let cols = SceneColumns::new(r)?;
    let spin = a
        .spin
        .parse()
        .map_err(|e: Error| flag_input_error("--spin", &a.spin, e.to_string()))?;
    if !(a.tol > 0.0 && a.tol < 1.0) {
        return Err(flag_input_error(
            "--tol",
            &a.tol.to_string(),
            "expected a relative tolerance in (0, 1)",
        ));
    }
    let law =
        a.k.parse()
            .map_err(|e: Error| flag_input_error("--K", &a.k, e.to_string()))?;
    let settings = ForwardSettings {
        kind,
        law,
        rho: a.contact.rho(),
        f: a.contact.f(),
        lambda: a.lambda,
        mu: a.mu,
        a: [a.a1, a.a2, a.a3],
        branch,
        spin,
        tol: a.tol,
    };
    Ok(ForwardPlan::new(r, cols, settings))
}

/// A flag error as the input error it is reported as.
pub(super) fn flag_input_error(flag: &str, value: &str, message: impl Into<String>) -> InputError {
    InputError {
        file: "<command line>".into(),
        line: None,
        column: Some(flag.to_string()),
        value: Some(value.to_string()),
        message: message.into(),
    }
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
            super::DEFAULT_DATA_NAME.to_string(),
            Input::Static(super::DEFAULT_DATA.as_bytes()),
            super::DEFAULT_DATA.len() as u64,
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

/// Stream options with a stop flag raised by Ctrl-C or SIGTERM (the stream then ends between
/// tasks, `--output` untouched, exit 130) and a progress bar on a terminal's stderr for runs
/// longer than a couple of seconds.
pub(super) fn stream_options(label: &str, input_bytes: u64) -> StreamOptions {
    StreamOptions {
        stop: Some(super::stop_flag()),
        progress: super::delayed_progress_bar("bytes"),
        label: label.to_string(),
        input_bytes: Some(input_bytes),
        ..StreamOptions::default()
    }
}

/// Streams `reader` through the plan `make` builds into `output` (written atomically: a
/// temporary file renamed over the target only when the whole input proved good and `finish`
/// succeeded; a target that cannot be created is reported only after the input proved good)
/// or stdout. `finish` runs on the plan's ledger before the output is committed.
pub(super) fn stream_to<R, P, F>(
    reader: TableReader<R>,
    make: F,
    ledger: P::Ledger,
    output: Option<&Path>,
    opts: &StreamOptions,
    finish: impl FnOnce(&P::Ledger) -> Result<(), CliError>,
) -> Result<Streamed<P::Ledger>, CliError>
where
    R: Read + Send,
    P: RowPlan,
    F: FnOnce(&TableReader<R>) -> Result<P, InputError>,
{
    match output {
        Some(p) => {
            let cannot =
                |e: std::io::Error| CliError::Other(format!("{}: cannot write: {e}", p.display()));
            let mut file = AtomicFile::create(p);
            let r = match &mut file {
                Ok(f) => stream(reader, make, ledger, f, opts),
                Err(_) => stream(reader, make, ledger, &mut std::io::sink(), opts),
            };
            match r {
                Ok(done) => {
                    finish(&done.ledger)?;
                    file.and_then(AtomicFile::commit).map_err(cannot)?;
                    Ok(done)
                }
                Err(e) => Err(stream_error(e, &p.display().to_string(), true)),
            }
        }
        None => {
            let mut out = std::io::stdout();
            let r = stream(reader, make, ledger, &mut out, opts)
                .and_then(|d| out.flush().map(|()| d).map_err(StreamError::Write));
            match r {
                Ok(done) => {
                    finish(&done.ledger)?;
                    Ok(done)
                }
                Err(e) => Err(stream_error(e, "<stdout>", false)),
            }
        }
    }
}

fn stream_error(e: StreamError, target: &str, file: bool) -> CliError {
    match e {
        StreamError::Input(e) => CliError::Input(e),
        StreamError::Write(e) if file => CliError::Other(format!("{target}: cannot write: {e}")),
        StreamError::Write(e) if e.kind() == std::io::ErrorKind::BrokenPipe => CliError::Io(e),
        StreamError::Write(e) => CliError::Other(format!("{target}: {e}")),
        StreamError::Stopped => CliError::Stopped(if file {
            format!("interrupted: {target} was not written")
        } else {
            "interrupted: the output on stdout is incomplete".into()
        }),
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
    #[arg(long = "md-preset", default_value = "ristow")]
    pub md_preset: String,
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
    #[arg(long = "reduced-mass")]
    pub reduced_mass: Option<String>,
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

/// md output columns added to each row.
pub const MD_OUTPUT_COLUMNS: [&str; 29] = [
    "v",
    "regime",
    "status",
    "v_stderr",
    "v_m_s",
    "drift",
    "beads_passed",
    "stop_bead",
    "stop_theta_deg",
    "lift_offs_per_bead",
    "lift_off_theta_deg",
    "skipped_fraction",
    "flight_height_max",
    "flight_length_mean",
    "flight_length_max",
    "airborne_fraction",
    "contacts_per_bead",
    "bounces_per_contact",
    "diss_normal",
    "diss_tangential",
    "energy_error",
    "final_velocity",
    "initial_velocity",
    "K_eff",
    "dt",
    "contact_time",
    "steps",
    "step_check_rel",
    "message",
];

impl MdArgs {
    /// The model from the preset and the flags (no table).
    pub fn model(&self) -> Result<Md, CliError> {
        let given = self.settings();
        build_md(self, &given, &|s: MdSetting, msg: String| {
            super::flag_error(
                &md_flag(s),
                &given.get(s).map(fmt_f64).unwrap_or_default(),
                msg,
            )
        })
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

/// The flag of an md setting: `--` and its column with `-` for `_`, except `--coulomb`
/// (`mu_c`) and `--md-g` (`g`).
fn md_flag(s: MdSetting) -> String {
    match s {
        MdSetting::Coulomb => "--coulomb".into(),
        MdSetting::Gravity => "--md-g".into(),
        s => format!("--{}", s.column().replace('_', "-")),
    }
}

/// Builds the md model from the preset, `--reduced-mass` and the settings given (flags or
/// cells); `err(setting, message)` locates a bad value.
fn build_md(
    a: &MdArgs,
    given: &MdSettings,
    err: &dyn Fn(MdSetting, String) -> CliError,
) -> Result<Md, CliError> {
    let mut params = match a.md_preset.to_ascii_lowercase().as_str() {
        "ristow" => MdParams::ristow(),
        "steel" => MdParams::steel(),
        _ => {
            return Err(super::flag_error(
                "--md-preset",
                &a.md_preset,
                "expected ristow or steel",
            ))
        }
    };
    match a
        .reduced_mass
        .as_deref()
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        None | Some("pair") => {}
        Some("mobile") => params.reduced_mass = ReducedMass::Mobile,
        Some(_) => {
            return Err(super::flag_error(
                "--reduced-mass",
                a.reduced_mass.as_deref().unwrap_or_default(),
                "expected pair or mobile",
            ))
        }
    }
    let base = Md {
        params,
        config: MdRunConfig::default(),
    };
    given.apply(base).map_err(|(s, e)| match s {
        Some(s) => err(s, e.to_string()),
        None => CliError::Other(e.to_string()),
    })
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

fn run_md(a: &Args, t: &Table) -> Result<(), CliError> {
    let c_xi = t.require("xi")?;
    let c_d = t.require("delta_deg")?;
    let c_rho = t.col("rho");
    let cols: Vec<(MdSetting, usize)> = MdSetting::ALL
        .into_iter()
        .filter_map(|s| t.col(s.column()).map(|c| (s, c)))
        .collect();
    let flags = a.md.settings();
    let mut jobs: Vec<(Scene, Md)> = Vec::with_capacity(t.rows.len());
    for r in 0..t.rows.len() {
        let xi = t.number(r, c_xi)?;
        let d = t.number(r, c_d)?;
        let rho = t.opt_number(r, c_rho)?.unwrap_or(a.contact.rho());
        // K and f do not enter the md model: a placeholder K keeps Scene's validation quiet.
        let scene =
            Scene::new(xi, d, rho, a.contact.f(), CollisionLaw::Value(0.5)).map_err(|e| {
                scene_error(
                    &t.row(r),
                    e,
                    &[("xi", Some(c_xi)), ("delta_deg", Some(c_d)), ("rho", c_rho)],
                )
            })?;
        if !(rho > 0.0) {
            let msg = "md needs rho > 0 (the bead's moment of inertia)";
            return Err(match c_rho {
                Some(c) => t.err(r, c, msg).into(),
                None => super::flag_error("--rho", &fmt_f64(rho), msg),
            });
        }
        let mut given = flags;
        for &(s, c) in &cols {
            if let Some(x) = t.opt_number(r, Some(c))? {
                given.set(s, x);
            }
        }
        let err = |s: MdSetting, msg: String| -> CliError {
            match cols.iter().find(|(x, _)| *x == s) {
                Some(&(_, c)) if !t.cell(r, c).is_empty() => t.err(r, c, msg).into(),
                _ => super::flag_error(
                    &md_flag(s),
                    &given.get(s).map(fmt_f64).unwrap_or_default(),
                    msg,
                ),
            }
        };
        let md = build_md(&a.md, &given, &err)?;
        md.check_scene(&scene).map_err(|e| match &e {
            Error::InvalidParameter { field: "rho", .. } => match c_rho {
                Some(c) if !t.cell(r, c).is_empty() => t.err(r, c, e.to_string()).into(),
                _ => super::flag_error("--rho", &fmt_f64(rho), e.to_string()),
            },
            Error::InvalidParameter { field, .. } => match MdSetting::from_column(field) {
                Some(s) => err(s, e.to_string()),
                None => CliError::Other(e.to_string()),
            },
            _ => CliError::Other(e.to_string()),
        })?;
        fitbead::io::forward::check_scene_cells(&t.row(r), &|n| t.col(n))?;
        jobs.push((scene, md));
    }
    let stop = super::stop_flag();
    let reps: u64 = if a.md.check_step { 3 } else { 1 };
    let total: u64 = jobs.iter().map(|(_, m)| m.config.beads as u64 * reps).sum();
    let bar = if total >= 2000 {
        md_progress_bar(total, "md")
    } else {
        None
    };
    let tick = |n: u64| {
        if let Some(b) = &bar {
            b.inc(n);
        }
    };
    let results: Vec<(MdResult, Option<f64>)> = jobs
        .par_iter()
        .map(|(scene, md)| {
            let r = md.simulate_until(scene, 1.0, Some(&tick), Some(&stop));
            let rel = if a.md.check_step {
                let h = md.simulate_until(scene, 0.5, Some(&tick), Some(&stop));
                match (r.mean_velocity, h.mean_velocity) {
                    (Some(x), Some(y)) => Some(((y - x) / x).abs()),
                    _ => None,
                }
            } else {
                None
            };
            (r, rel)
        })
        .collect();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if stop.load(std::sync::atomic::Ordering::SeqCst) {
        return Err(CliError::Interrupted);
    }
    let bytes = render_md(t, &jobs, &results).map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.out.output.as_deref(), &bytes)
}

fn render_md(
    t: &Table,
    jobs: &[(Scene, Md)],
    results: &[(MdResult, Option<f64>)],
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::with_capacity(t.rows.len() * 400));
    let mut header: Vec<String> = t
        .headers
        .iter()
        .map(|h| {
            if MD_OUTPUT_COLUMNS.contains(&h.as_str()) {
                format!("in_{h}")
            } else {
                h.clone()
            }
        })
        .collect();
    header.extend(MD_OUTPUT_COLUMNS.iter().map(|s| s.to_string()));
    w.write_record(&header)?;
    let opt = |x: Option<f64>| x.map(fmt_f64).unwrap_or_default();
    for ((rec, (scene, _)), (r, rel)) in t.rows.iter().zip(jobs).zip(results) {
        let mut out: Vec<String> = rec.iter().map(|s| s.to_string()).collect();
        let o = Md::outcome(scene, r);
        let moving = matches!(r.regime, Some(Regime::B) | Some(Regime::C));
        let deg = |x: Option<f64>| opt(x.map(f64::to_degrees));
        out.push(if moving {
            opt(r.mean_velocity)
        } else {
            String::new()
        });
        out.push(regime_of(&o).map(|g| g.to_string()).unwrap_or_default());
        out.push(match &o {
            Ok(_) => "ok".into(),
            Err(e) => e.status().into(),
        });
        out.push(if moving { opt(r.stderr) } else { String::new() });
        out.push(if moving {
            opt(r.mean_velocity_si)
        } else {
            String::new()
        });
        out.push(opt(r.drift));
        out.push(r.beads_passed.to_string());
        out.push(r.stop.map(|s| s.bead.to_string()).unwrap_or_default());
        out.push(deg(r.stop.map(|s| s.angle)));
        let measured = r.mean_velocity.is_some();
        let m = |x: f64| if measured { fmt_f64(x) } else { String::new() };
        out.push(m(r.lift_offs_per_bead));
        out.push(deg(r.lift_off_angle));
        out.push(m(r.skipped_fraction));
        out.push(m(r.flight_height_max));
        out.push(opt(r.flight_length_mean));
        out.push(m(r.flight_length_max));
        out.push(m(r.airborne_fraction));
        out.push(m(r.contacts_per_bead));
        out.push(m(r.bounces_per_contact));
        out.push(m(r.dissipation_normal));
        out.push(m(r.dissipation_tangential));
        out.push(fmt_f64(r.energy_error));
        out.push(opt(r.final_velocity));
        out.push(opt(r.initial_velocity));
        out.push(opt(r.k_eff));
        out.push(fmt_f64(r.dt));
        out.push(fmt_f64(r.contact_time));
        out.push(r.steps.to_string());
        out.push(opt(*rel));
        out.push(match &o {
            Ok(_) => String::new(),
            Err(e) => match r.stop {
                Some(s) => format!("{e} (trapped after {} row beads)", s.bead),
                None => e.to_string(),
            },
        });
        w.write_record(&out)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

#[cfg(test)]
mod tests {
    //! The streaming path against golden outputs (tests/golden/forward/, written by a separate
    //! implementation of `forward` that read the whole table, evaluated it, then wrote it): the
    //! same bytes on the shipped data and on a table with every kind of cell, for every model
    //! but md, at chunk sizes from 1 row to [`CHUNK_ROWS`]; the same message for every kind of
    //! bad input.

    use super::*;
    use clap::Parser;
    use fitbead::io::stream::{CHUNK_ROWS, TASK_ROWS};

    #[derive(Parser)]
    struct Cmd {
        #[command(flatten)]
        a: Args,
    }

    fn args(flags: &[&str]) -> Args {
        Cmd::parse_from(std::iter::once("forward").chain(flags.iter().copied())).a
    }

    fn kind_branch(a: &Args) -> (ModelKind, JaegerBranch) {
        let kind = a.model.parse().unwrap();
        let branch = match a.branch.as_str() {
            "lower" => JaegerBranch::Lower,
            _ => JaegerBranch::Upper,
        };
        (kind, branch)
    }

    fn new(a: &Args, text: &[u8], chunk: usize, task: usize) -> Result<Vec<u8>, String> {
        let (kind, branch) = kind_branch(a);
        let reader = TableReader::new("in.csv", text).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        let opts = StreamOptions {
            chunk_rows: chunk,
            task_rows: task,
            ..StreamOptions::default()
        };
        match stream(reader, |r| plan(a, kind, branch, r), (), &mut out, &opts) {
            Ok(_) => Ok(out),
            Err(StreamError::Input(e)) => Err(e.to_string()),
            Err(e) => panic!("writing to a Vec failed: {e:?}"),
        }
    }

    const SIZES: [(usize, usize); 4] = [(1, 1), (7, 3), (64, 5), (CHUNK_ROWS, TASK_ROWS)];

    /// The streaming output of `text` under `flags` equals `want` at every chunk size.
    fn same(flags: &[&str], text: &[u8], want: &[u8]) {
        let a = args(flags);
        for (chunk, task) in SIZES {
            let got = new(&a, text, chunk, task)
                .unwrap_or_else(|e| panic!("{flags:?}, chunks of {chunk}: {e}"));
            assert!(
                want == got,
                "{flags:?}, chunks of {chunk}: output differs\nwant:\n{}\ngot:\n{}",
                String::from_utf8_lossy(want),
                String::from_utf8_lossy(&got)
            );
        }
    }

    /// A golden file under tests/golden/forward/.
    macro_rules! golden {
        ($($part:literal),+) => {
            include_bytes!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/tests/golden/forward/",
                $($part),+
            ))
        };
    }

    /// Each model's flags and its golden outputs on data/default.csv,
    /// data/virtual/md_ristow.csv and tests/golden/forward/generated/input.csv.
    macro_rules! models {
        ($(($name:literal, $flags:expr)),* $(,)?) => {
            [$(Golden {
                flags: $flags,
                default: golden!("default/", $name, ".csv"),
                md_ristow: golden!("md_ristow/", $name, ".csv"),
                generated: golden!("generated/", $name, ".csv"),
            }),*]
        };
    }

    struct Golden {
        flags: &'static [&'static str],
        default: &'static [u8],
        md_ristow: &'static [u8],
        generated: &'static [u8],
    }

    const MODELS: [Golden; 11] = models![
        ("stick", &["--model", "stick"]),
        (
            "stick_cos2a_rho0.5",
            &["--model", "stick", "--K", "cos2a", "--rho", "0.5"]
        ),
        ("stick-approx", &["--model", "stick-approx"]),
        ("slip", &["--model", "slip"]),
        ("slip-approx", &["--model", "slip-approx"]),
        ("stickslip_f0.3", &["--model", "stickslip", "--f", "0.3"]),
        ("contact_keep", &["--model", "contact", "--spin", "keep"]),
        ("jan", &["--model", "jan"]),
        (
            "jaeger_upper",
            &["--model", "jaeger", "--a1", "0.05", "--a2", "0.4", "--a3", "1.5"]
        ),
        (
            "jaeger_lower",
            &["--model", "jaeger", "--a1", "0.1", "--a2", "2", "--a3", "0.3", "--branch", "lower"]
        ),
        ("auto_tol1e-8", &["--model", "auto", "--tol", "1e-8"]),
    ];

    /// A table with every kind of cell the readers and writers meet: quoted cells (commas,
    /// quotes, a newline), non-ASCII text, columns whose names clash with the output (`v`,
    /// `regime`, `phase_sequence`), laws by name, empty cells falling back on the flags,
    /// padded cells (ASCII and Unicode spaces), blank lines, and scenes in regimes A, B and C
    /// with every outcome and phase sequence each model gives on them.
    const GENERATED: &[u8] = golden!("generated/input.csv");
    /// Rows of [`GENERATED`].
    const GENERATED_ROWS: usize = 44;

    #[test]
    fn same_bytes_as_the_golden_outputs_on_the_shipped_data() {
        for m in &MODELS {
            same(m.flags, include_bytes!("../../data/default.csv"), m.default);
            same(
                m.flags,
                include_bytes!("../../data/virtual/md_ristow.csv"),
                m.md_ristow,
            );
        }
    }

    #[test]
    fn same_bytes_as_the_golden_outputs_on_the_generated_table() {
        for m in &MODELS {
            same(m.flags, GENERATED, m.generated);
        }
        // A single scene on the command line goes through the same path.
        same(
            &["--model", "stick"],
            b"xi,delta_deg\n1,12\n",
            golden!("single_scene.csv"),
        );
    }

    /// Several full-size chunks and a partial one: the generated table's body repeated, whose
    /// output is the golden header and the golden body repeated (every row's output depends on
    /// that row alone).
    #[test]
    fn same_bytes_over_several_full_chunks() {
        let split = |b: &'static [u8]| {
            let i = b.iter().position(|&c| c == b'\n').unwrap() + 1;
            (&b[..i], &b[i..])
        };
        let reps = 3 * CHUNK_ROWS / GENERATED_ROWS + 1;
        let (head, body) = split(GENERATED);
        let text = [head, &body.repeat(reps)].concat();
        let (head, body) = split(MODELS[0].generated);
        let want = [head, &body.repeat(reps)].concat();
        let rows = csv::Reader::from_reader(MODELS[0].generated)
            .records()
            .count();
        assert_eq!(rows, GENERATED_ROWS);
        same(MODELS[0].flags, &text, &want);
    }

    fn error_cases() -> Vec<(&'static [&'static str], Vec<u8>)> {
        let good = "1,12\n".repeat(40);
        let late_s = |bad: &str| format!("xi,delta_deg\n{good}{bad}{good}");
        let late = |bad: &str| late_s(bad).into_bytes();
        let stick: &[&str] = &["--model", "stick"];
        vec![
            (stick, Vec::new()),
            (stick, " \n\t\n".into()),
            (stick, "xi,delta_deg\n".into()),
            (stick, "xi,delta_deg\n\n\n".into()),
            (stick, "xi,,delta_deg\n1,2,3\n".into()),
            (stick, "xi,xi,delta_deg\n1,2,3\n".into()),
            (stick, "xi,K\n1,0.6\n".into()),
            (stick, "xi,delta_deg\n1,abc\n".into()),
            (stick, "xi,delta_deg\n1,10\n1,NaN\n".into()),
            (stick, "xi,delta_deg\n1,inf\n".into()),
            (stick, "xi,delta_deg\n-1,10\n".into()),
            (stick, "xi,delta_deg\n1,95\n".into()),
            (stick, "xi,delta_deg\n ,10\n".into()),
            (stick, "xi,delta_deg,K\n1,10,smooth\n".into()),
            (stick, "xi,delta_deg,K\n1,10,-0.5\n".into()),
            (stick, "xi,delta_deg,K\n1,10,inf\n".into()),
            (stick, "xi,delta_deg,K\n1,10,c=abc\n".into()),
            (stick, "xi,delta_deg,rho\n1,10,-2\n".into()),
            (stick, "xi,delta_deg,f\n1,10,x\n".into()),
            // Bad rows after the first chunks; the first one is reported.
            (stick, late("1,abc\n")),
            (stick, late("1,10\n0,10\n1,abc\n")),
            // A malformed row anywhere wins over a bad value before it.
            (stick, late("1,10,3\n")),
            (stick, format!("{}1,abc\n{good}1,10,3\n", late_s("")).into()),
            (stick, format!("xi,delta_deg\n1,abc\n{good}\"1,10\n").into()),
            // Invalid UTF-8, the byte index counted in the trimmed cell.
            (stick, b"xi,delta_deg\n1,10\n1,\xff\n".to_vec()),
            (stick, b"xi,delta_deg\n1,10\n1, \t \xc3\xa9\xff \n".to_vec()),
            (stick, b"xi,delta_deg\n\n\n1,10\n\n1,\xc3\n".to_vec()),
            (stick, late("1,\u{e9}\n")),
            (stick, [late(""), b"  \xfe,1\n".to_vec()].concat()),
            (stick, [late("1,abc\n"), b"  \xfe,1\n".to_vec()].concat()),
            // Flag errors come after the table's own errors.
            (&["--model", "stick", "--tol", "2"], "xi,delta_deg\n".into()),
            (&["--model", "stick", "--tol", "2"], late("1,10,3\n")),
            (&["--model", "stick", "--tol", "2"], late("")),
            (&["--model", "stick", "--K", "bogus"], late("")),
            (&["--model", "stick", "--spin", "bogus"], late("")),
            (&["--model", "stick", "--rho=-1"], late("")),
            (&["--model", "jaeger"], late("")),
            (
                &["--model", "jaeger", "--a1", "1", "--a2", "1"],
                "xi,delta_deg,a3\n1,10,1\n1,10,\n".into(),
            ),
            (
                &["--model", "jaeger", "--a1", "1", "--a2", "1", "--a3=-1"],
                late(""),
            ),
            (
                &["--model", "jan"],
                "xi,delta_deg,lambda\n1,10,0.8\n1,10,-1\n".into(),
            ),
            (&["--model", "jan", "--mu=-1"], late("")),
            (
                &["--model", "contact"],
                "xi,delta_deg,spin\n1,10,roll\n1,10,twirl\n".into(),
            ),
            (&["--model", "auto"], late("1,-3\n")),
        ]
    }

    /// tests/golden/forward/errors.txt: one line per case of [`error_cases`], the message as a
    /// Rust string literal (`{:?}`).
    #[test]
    fn same_error_as_the_golden_messages() {
        let want: Vec<&str> = std::str::from_utf8(golden!("errors.txt"))
            .unwrap()
            .lines()
            .collect();
        let cases = error_cases();
        assert_eq!(want.len(), cases.len());
        for ((flags, bytes), want) in cases.into_iter().zip(want) {
            let a = args(flags);
            let text = String::from_utf8_lossy(&bytes);
            for (chunk, task) in SIZES {
                match new(&a, &bytes, chunk, task) {
                    Ok(_) => panic!("{flags:?} {text:?}, chunks of {chunk}: should fail"),
                    Err(e) => assert_eq!(
                        format!("{e:?}"),
                        want,
                        "{flags:?} {text:?}, chunks of {chunk}"
                    ),
                }
            }
        }
    }
}
