//! `fitbead design`: the slopes to measure (and how many points at each), per series, for a
//! fit's parameters (D or c criterion) or to tell two models apart (T), with the predicted
//! standard errors at the design and at evenly spaced slopes.

use super::args::{ContactArgs, OutputArgs, PlotArgs};
use super::values::{self, NamedPrior, Numbers, SlopeRange};
use super::{emit, CliError};
use crate::design::{design, Criterion, DesignError, DesignFit, DesignResult, DesignSettings};
use crate::io::{fmt_f64, fmt_sig, AtomicFile};
use crate::models::{JaegerBranch, ModelKind};
use crate::report::figures::plot::{Axis, Figure, LegendEntry, Panel, PALETTE};
use crate::report::figures::svg::{Mark, Stroke};
use crate::scene::CollisionLaw;
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
    /// the design keeps 5 % of the range's width from either end.
    #[arg(long, value_parser = values::slope_range)]
    pub delta_range: Option<SlopeRange>,
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
    let bytes = csv_bytes(&r)?;
    let summary = summary(&s, &r);
    if let Some((p, file)) = plot {
        let svg = figure(&s, &r).to_svg();
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
        ..DesignSettings::default()
    })
}

/// The design as CSV: series,xi,delta_deg,replicates.
fn csv_bytes(r: &DesignResult) -> Result<Vec<u8>, CliError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::Other(e.to_string());
    w.write_record(["series", "xi", "delta_deg", "replicates"])
        .map_err(io)?;
    for row in &r.rows {
        w.write_record([
            row.series.clone(),
            fmt_f64(row.xi),
            fmt_f64(row.delta_deg),
            row.replicates.to_string(),
        ])
        .map_err(io)?;
    }
    w.into_inner().map_err(|e| CliError::Other(e.to_string()))
}

/// The summary: the design, the predicted standard errors and the efficiency.
fn summary(s: &DesignSettings, r: &DesignResult) -> String {
    use std::fmt::Write as _;
    let mut o = String::new();
    let crit = match s.criterion {
        Criterion::D => "D-optimal".to_string(),
        Criterion::C => format!("c-optimal for {}", r.target.as_deref().unwrap_or("")),
        Criterion::T => "T-optimal (model discrimination)".to_string(),
    };
    let budget = match s.total {
        None => format!("{} points per series", s.points),
        Some(n) => format!("{n} points in all (shared out by the design)"),
    };
    let _ = writeln!(
        o,
        "design: {crit}, {budget}, noise {}{}",
        fmt_sig(s.noise, 3),
        if s.noise_absolute {
            " (absolute)"
        } else {
            " (relative)"
        }
    );
    if let Some((n, redrawn)) = r.bayes {
        let priors: Vec<String> = s.priors.iter().map(|(n, p)| format!("{n}={p}")).collect();
        let _ = writeln!(
            o,
            "Bayesian design: the criterion averaged over {n} prior draws (seed {}; {}); {redrawn} \
             draws redrawn (a series without a steady slope in its range); standard errors are \
             root mean variances over the draws",
            s.seed,
            priors.join(", ")
        );
    }
    for (k, xi) in s.series.iter().enumerate() {
        let (lo, hi) = r.ranges[k];
        let slopes: Vec<String> = r
            .rows
            .iter()
            .filter(|row| row.xi == *xi)
            .map(|row| format!("{} deg x{}", fmt_f64(row.delta_deg), row.replicates))
            .collect();
        let slopes = if slopes.is_empty() {
            vec!["no points".to_string()]
        } else {
            slopes
        };
        let _ = writeln!(
            o,
            "  xi {}: range {}-{} deg: {}",
            fmt_f64(*xi),
            fmt_sig(lo, 5),
            fmt_sig(hi, 5),
            slopes.join(", ")
        );
    }
    let _ = writeln!(
        o,
        "predicted standard errors (design / evenly spaced slopes):"
    );
    let se = |x: Option<f64>| x.map_or("not determined".to_string(), |v| fmt_sig(v, 3));
    for e in &r.errors {
        let _ = writeln!(
            o,
            "  {} = {}: {} / {}",
            e.name,
            fmt_sig(e.guess, 6),
            se(e.design),
            se(e.even)
        );
    }
    let eff = fmt_sig(r.efficiency, 3);
    match s.criterion {
        Criterion::D => {
            let _ = writeln!(o, "D-efficiency of evenly spaced slopes: {eff}");
        }
        Criterion::C => {
            let _ = writeln!(
                o,
                "efficiency of evenly spaced slopes (variance ratio): {eff}; SE ratio even/design: {}",
                fmt_sig(r.efficiency.recip().sqrt(), 3)
            );
        }
        Criterion::T => {
            if let (Some((td, te)), Some((nd, ne))) = (r.discrimination, r.points_needed) {
                let _ = writeln!(
                    o,
                    "discrimination T = min chi2 of the rival fitted to the model: design {} / \
                     evenly spaced {} (efficiency {eff})",
                    fmt_sig(td, 4),
                    fmt_sig(te, 4)
                );
                let n = |x: f64| {
                    if x.is_finite() {
                        format!("{x}")
                    } else {
                        "never".to_string()
                    }
                };
                let _ = writeln!(
                    o,
                    "points in all for power 0.8 at significance 0.05: design {} / evenly \
                     spaced {}",
                    n(nd),
                    n(ne)
                );
            }
        }
    }
    let _ = writeln!(o, "equivalence gap: {}", fmt_sig(r.gap, 2));
    o
}

/// The figure: per series, the sensitivity of every candidate slope with the chosen ones
/// marked (marker height: the sensitivity there; the label the replicates).
fn figure(s: &DesignSettings, r: &DesignResult) -> Figure {
    let mut panels = Vec::new();
    for (k, xi) in s.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let mut p = Panel::new(
            &format!("ξ = {}", fmt_f64(*xi)),
            Axis::new("slope δ (deg)"),
            Axis::new(&r.sensitivity_label),
        );
        let curve = &r.sensitivity[k];
        p.curve(curve.clone(), Stroke::solid(colour, 2.0));
        let chosen: Vec<(f64, f64, f64, f64)> = r
            .rows
            .iter()
            .filter(|row| row.xi == *xi)
            .map(|row| {
                let y = curve
                    .iter()
                    .min_by(|a, b| {
                        (a.0 - row.delta_deg)
                            .abs()
                            .total_cmp(&(b.0 - row.delta_deg).abs())
                    })
                    .map_or(f64::NAN, |c| c.1);
                (row.delta_deg, y, y, y)
            })
            .collect();
        for row in r.rows.iter().filter(|row| row.xi == *xi) {
            p.items.push(crate::report::figures::plot::Item::VLine {
                x: row.delta_deg,
                stroke: Stroke::solid("#808080", 1.0).dashed("4 3"),
            });
        }
        p.items.push(crate::report::figures::plot::Item::HLine {
            y: 1.0,
            stroke: Stroke::solid("#404040", 1.0).dashed("2 3"),
        });
        p.points(chosen, colour, Mark::Circle);
        let even: Vec<(f64, f64, f64, f64)> = r
            .even
            .iter()
            .filter(|row| row.xi == *xi)
            .map(|row| {
                let y = curve
                    .iter()
                    .min_by(|a, b| {
                        (a.0 - row.delta_deg)
                            .abs()
                            .total_cmp(&(b.0 - row.delta_deg).abs())
                    })
                    .map_or(f64::NAN, |c| c.1);
                (row.delta_deg, y, y, y)
            })
            .collect();
        p.points(even, "#808080", Mark::Cross);
        panels.push(p);
    }
    let cols = if panels.len() > 2 { 2 } else { panels.len() };
    let mut f = Figure::new(
        "Where to measure: sensitivity per slope",
        cols,
        (380.0, 240.0),
        panels,
    );
    f.legend = vec![
        LegendEntry::mark("design slopes", Mark::Circle, "#404040"),
        LegendEntry::mark("evenly spaced slopes", Mark::Cross, "#808080"),
    ];
    f.legend.push(LegendEntry::line(
        "equivalence bound (1 on the design)",
        &Stroke::solid("#404040", 1.0).dashed("2 3"),
    ));
    f.notes = s
        .series
        .iter()
        .map(|xi| {
            let at: Vec<String> = r
                .rows
                .iter()
                .filter(|row| row.xi == *xi)
                .map(|row| format!("{}° ×{}", fmt_f64(row.delta_deg), row.replicates))
                .collect();
            format!("design at ξ = {}: {}", fmt_f64(*xi), at.join(", "))
        })
        .collect();
    f
}
