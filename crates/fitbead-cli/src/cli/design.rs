//! `fitbead design`: the slopes to measure (and how many points at each), per series, for a
//! fit's parameters (D or c criterion) or to tell two models apart (T), with the predicted
//! standard errors at the design and at evenly spaced slopes.

use super::args::{ContactArgs, OutputArgs, PlotArgs};
use super::values::{self, NamedPrior, Numbers, SlopeRange};
use super::{emit, CliError};
use fitbead::design::{design, Criterion, DesignError, DesignFit, DesignResult, DesignSettings};
use fitbead::io::AtomicFile;
use fitbead::models::{JaegerBranch, ModelKind};
use fitbead::scene::CollisionLaw;
use std::io::Write;
use std::path::Path;

/// Arguments of `fitbead design`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The fit the data are for: klaw (a K(α) law), jan (λ, μ) or jaeger (a1, a2, a3).
    #[arg(long, default_value = "klaw", value_parser = values::choice::<DesignFit>())]
    pub fit: DesignFit,
    /// The model the data follow: for --fit klaw a contact model (stick, stick-approx, slip,
    /// slip-approx, stickslip, contact, auto) [default: stickslip]; jan and jaeger have their
    /// own.
    #[arg(long, value_parser = values::choice::<ModelKind>())]
    pub model: Option<ModelKind>,
    /// For --fit klaw, the fitted law with the guess of its parameter: c=VALUE (law c) or a
    /// number K (one K per series, each guessed at K).
    #[arg(long, default_value = "c=0.5", value_parser = values::law)]
    pub law: CollisionLaw,
    /// Radius ratios ξ of the series, comma-separated.
    #[arg(long, default_value = "0.8,1,1.6,2", value_parser = values::number_list)]
    pub series: Numbers,
    /// Points per series.
    #[arg(long, default_value_t = 9)]
    pub points: usize,
    /// Points over all series, shared out by the design (a series may get none); the evenly
    /// spaced comparison spreads them as evenly as they go. Replaces --points.
    #[arg(long, conflicts_with = "points")]
    pub total: Option<usize>,
    /// Noise of v̄: relative (σ = noise · v̄, as `simulate --noise`), or abs=SIGMA for an
    /// absolute σ (dimensionless).
    #[arg(long, default_value = "0.02", value_parser = values::design_noise)]
    pub noise: (f64, bool),
    /// Slopes LO,HI in degrees, cut to regime B of the guess [default: regime B of the guess];
    /// the design keeps --margin of the range's width (and 2 --sigma-delta) from either end.
    #[arg(long, value_parser = values::slope_range)]
    pub delta_range: Option<SlopeRange>,
    /// Standard uncertainty of a set slope, degrees: each point's variance becomes
    /// σ_v² + (∂v̄/∂δ)² σ_δ² (the effective variance the fits with slope errors minimise), so
    /// a slope where v̄ changes steeply tells less, and the range keeps 2 σ_δ from its ends so
    /// that a slope set 2 σ_δ off is still steady at the guess. 0: exact slopes.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = values::slope_sigma)]
    pub sigma_delta: f64,
    /// The fraction F of the range's width kept from each of its ends (0 <= F < 0.5; the
    /// default keeps the 5 %–95 % over which `simulate` spreads its points).
    #[arg(long, value_name = "F", default_value_t = DesignSettings::default().margin, value_parser = values::margin)]
    pub margin: f64,
    /// Criterion: d (D-optimal: all parameters), c (the smallest variance of --target) or t
    /// (model discrimination against --vs).
    #[arg(long, default_value = "d", value_parser = values::choice::<Criterion>())]
    pub criterion: Criterion,
    /// The parameter of --criterion c (c, mu, a1, …; needed when the fit has several). For
    /// --fit klaw also the bulk friction μ (eq 79, dimensionless) at the fitted K: mu (one
    /// series) or "mu of series 'xi=X'", its standard error by the delta method.
    #[arg(long)]
    pub target: Option<String>,
    /// The rival model of --criterion t: for --fit klaw a contact model whose law's parameter
    /// is fitted; for --fit jaeger, jan (λ, μ, or the laws of eqs 75–76 across series). --fit
    /// jan has no rival: Jan's model is Jaeger's with a2 = 0.
    #[arg(long, value_parser = values::choice::<ModelKind>())]
    pub vs: Option<ModelKind>,
    /// A prior of a parameter, NAME=DIST, repeatable, for a Bayesian design (the criterion
    /// averaged over --draws draws; parameters without a prior stay at the guess). DIST is
    /// uniform(a,b), normal(mean,sd), lognormal(mu,sigma) or halfnormal(scale), in the
    /// parameter's own units; quote it for the shell ('c=normal(0.5,0.1)'). Draws that leave
    /// a series no steady slope in its range are redrawn.
    #[arg(long = "prior", value_name = "NAME=DIST", value_parser = values::design_prior)]
    pub priors: Vec<NamedPrior>,
    /// Prior draws the Bayesian criterion is averaged over (with --prior).
    #[arg(long, default_value_t = DesignSettings::default().draws)]
    pub draws: usize,
    /// Seed of the prior draws (a locally optimal design draws nothing).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Branch of eq 84 for --fit jaeger: upper or lower.
    #[arg(long, default_value = "upper", value_parser = values::choice::<JaegerBranch>())]
    pub branch: JaegerBranch,
    /// ρ and f of the scenes.
    #[command(flatten)]
    pub contact: ContactArgs,
    /// Where the design goes (CSV: series,xi,delta_deg,replicates); the summary goes to
    /// stdout, or to stderr when the design does.
    #[command(flatten)]
    pub out: OutputArgs,
    /// With --plot: the sensitivity of each candidate slope per series (the standardised
    /// variance for d, the target's variance share for c, the squared distance of the two
    /// models for t), with the chosen slopes marked.
    #[command(flatten)]
    pub plot: PlotArgs,
}

/// Runs `fitbead design`.
pub fn run(a: Args) -> Result<(), CliError> {
    let s = settings(&a)?;
    // The figure's file is created first so that a target that cannot be written is reported
    // before the work.
    let plot = match a.plot.plot.as_deref() {
        Some(p) if p != Path::new("-") => Some((
            p,
            Some(
                AtomicFile::create(p)
                    .map_err(|e| CliError::Other(format!("{}: cannot write: {e}", p.display())))?,
            ),
        )),
        Some(p) => Some((p, None)),
        None => None,
    };
    let r = design_until_stopped(&s)?.map_err(design_error)?;
    let bytes = r.csv().map_err(|e| CliError::Other(e.to_string()))?;
    let summary = r.summary(&s);
    if let Some((p, file)) = plot {
        let svg = r.figure_svg(&s);
        match file {
            Some(mut f) => {
                f.write_all(svg.as_bytes())
                    .map_err(|e| CliError::Other(format!("{}: cannot write: {e}", p.display())))?;
                f.commit()
                    .map_err(|e| CliError::Other(format!("{}: cannot write: {e}", p.display())))?;
            }
            None => super::print_stdout(svg.as_bytes())?,
        }
    }
    let to_stdout = a.out.output.as_deref().is_none_or(|p| p == Path::new("-"));
    emit(a.out.output.as_deref(), &bytes)?;
    if to_stdout || a.plot.plot.as_deref() == Some(Path::new("-")) {
        eprint!("{summary}");
        Ok(())
    } else {
        super::print_stdout(summary.as_bytes())
    }
}

/// The design of `s`, computed on a thread of its own while this one watches the stop flag
/// (SIGINT, SIGTERM, SIGHUP): a signal ends the run at once (exit 130), the figure's
/// temporary file removed as the run unwinds, and the computation is dropped with the
/// process.
fn design_until_stopped(s: &DesignSettings) -> Result<Result<DesignResult, DesignError>, CliError> {
    use std::sync::atomic::Ordering;
    use std::sync::mpsc::RecvTimeoutError;
    let stop = super::stop_flag();
    let (tx, rx) = std::sync::mpsc::channel();
    let owned = s.clone();
    std::thread::spawn(move || {
        let _ = tx.send(design(&owned));
    });
    loop {
        match rx.recv_timeout(std::time::Duration::from_millis(50)) {
            Ok(r) => return Ok(r),
            Err(RecvTimeoutError::Timeout) if stop.load(Ordering::SeqCst) => {
                return Err(CliError::Interrupted)
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                return Err(CliError::Other(
                    "design: the computation ended without a result".into(),
                ))
            }
        }
    }
}

/// A library refusal as the flag to change (exit 2).
fn design_error(e: DesignError) -> CliError {
    super::flag_error(&format!("--{}", e.setting), &e.value, e.message)
}

/// The library's settings from the flags.
fn settings(a: &Args) -> Result<DesignSettings, CliError> {
    if a.target.is_some() && a.criterion != Criterion::C {
        return Err(super::flag_error(
            "--target",
            a.target.as_deref().unwrap_or(""),
            "a target parameter goes with --criterion c",
        ));
    }
    let (noise, noise_absolute) = a.noise;
    Ok(DesignSettings {
        fit: a.fit,
        model: a.model,
        law: a.law,
        series: a.series.0.clone(),
        rho: a.contact.rho(),
        f: a.contact.f(),
        points: a.points,
        noise,
        noise_absolute,
        delta_range: a.delta_range.as_ref().map(|r| (r.lo, r.hi)),
        criterion: a.criterion,
        target: a.target.clone(),
        vs: a.vs,
        branch: a.branch,
        priors: a
            .priors
            .iter()
            .map(|p| (p.name.clone(), p.prior.clone()))
            .collect(),
        draws: a.draws,
        seed: a.seed,
        total: a.total,
        sigma_delta: a.sigma_delta,
        margin: a.margin,
        ..DesignSettings::default()
    })
}
