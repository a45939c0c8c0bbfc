//! Flags and I/O shared by the fit commands (`klaw`, `jan`, `jaeger`).

use super::args::{DataArgs, LevelArgs, PlotArgs};
use super::values::{self, FitMethod, NamedPrior};
use super::{emit, read_input, CliError};
use crate::fit::data::Dataset;
use crate::fit::posterior::{McmcSettings, Method, SCALE_NAME};
use crate::fit::summary::{FitResult, McmcFailure, ParamRow, StatsRow};
use crate::inverse::mcmc::McmcOptions;
use crate::io::measurements::{dataset_of, read_measurements, Measurement};
use crate::io::reports::{draws_csv, params_csv, stats_csv};
use crate::io::scenes::Table;
use crate::io::{fmt_sig, write_atomic_all};
use crate::report::bands::Curve;
use crate::report::figures::{corner_svg, CornerBlock};
use crate::report::file_stems;
use crate::report::plots::lsq_fit_figure;
use std::io::IsTerminal;
use std::path::PathBuf;

/// `--output` of the fit commands: the parameter CSV, or the fit report on stdout.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct FitOutputArgs {
    /// The parameter report CSV (fit,series,parameter,value,stderr,ci_low,ci_high,ci_method,
    /// unit, then extra columns), written atomically; `-` writes it to stdout. Without it, a
    /// one-screen fit report per fit goes to stdout (values ± standard errors, intervals,
    /// correlations, χ², AIC, BIC, convergence, warnings). Every output flag takes `-` for
    /// stdout, and a standard stream or descriptor (/dev/stdout, /proc/self/fd/N) is written
    /// through in place; only one output may go to stdout (without --output the fit report
    /// takes it)
    #[arg(long)]
    pub output: Option<PathBuf>,
}

impl FitOutputArgs {
    /// Whether the parameter CSV goes to stdout (`--output -`).
    pub fn to_stdout(&self) -> bool {
        self.output.as_deref() == Some(std::path::Path::new("-"))
    }
}

/// Flags common to every fit command.
#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// The measurements and the defaults of the columns they may leave out (jan and jaeger do
    /// not use ρ and f). Either every row has sigma_v (absolute errors) or none has (unit
    /// weights; the common scale is estimated from the scatter, χ²/dof).
    #[command(flatten)]
    pub data: DataArgs,
    /// The level of the intervals.
    #[command(flatten)]
    pub level: LevelArgs,
    /// Covariance intervals only (skip the profile-likelihood ones, which cost more fits).
    #[arg(long)]
    pub no_profile: bool,
    /// The parameter report CSV.
    #[command(flatten)]
    pub out: FitOutputArgs,
    /// Fit statistics CSV (written atomically): χ², dof, AIC, BIC, termination per fit; `-`
    /// writes it to stdout (then --output must name a file). Printed to stderr as a table
    /// when absent.
    #[arg(long)]
    pub output_stats: Option<PathBuf>,
    /// Estimation method: lsq (least squares) or mcmc (posterior sampling by an affine-invariant
    /// ensemble sampler started from the least-squares optimum; value = posterior median,
    /// ci_low/ci_high = central posterior interval at --level, ci_method = posterior).
    #[arg(long, default_value = "lsq", value_parser = values::choice::<FitMethod>())]
    pub method: FitMethod,
    /// MCMC: seed of every random stream; a run is bit-identical for a seed, whatever the number
    /// of threads [default: 1]
    #[arg(long)]
    pub seed: Option<u64>,
    /// MCMC: number of walkers, even [default: max(2·dim + 2, 32)]
    #[arg(long, value_parser = values::walkers)]
    pub walkers: Option<usize>,
    /// MCMC: run until every parameter's bulk and tail ESS reach this and its rank-normalised
    /// split-R̂ is ≤ 1.01 [default: 1000]
    #[arg(long, value_parser = values::non_negative)]
    pub min_ess: Option<f64>,
    /// MCMC: stop after this many steps even if not converged, with a warning naming the
    /// failing parameter [default: 100000]
    #[arg(long, value_parser = values::at_least_one)]
    pub max_steps: Option<usize>,
    /// MCMC: keep one step in THIN [default: 1]
    #[arg(long, value_parser = values::at_least_one)]
    pub thin: Option<usize>,
    /// MCMC: prior of a parameter, NAME=DIST, repeatable; DIST is flat, jeffreys,
    /// uniform(a,b), normal(mean,sd), lognormal(mu,sigma) or halfnormal(scale); quote it for
    /// the shell ('c=normal(0.5,0.5)'). Defaults: flat on the parameter's feasible box (every
    /// point in regime B), except Jaeger's a1, a2, a3: halfnormal(10), halfnormal(100),
    /// halfnormal(10); jeffreys for sigma_scale. The support is always cut to the feasible
    /// region.
    #[arg(long = "prior", value_name = "NAME=DIST", value_parser = values::fit_prior)]
    pub priors: Vec<NamedPrior>,
    /// MCMC: also sample an error scale sigma_scale multiplying every sigma_v (for data whose
    /// sigma is underestimated). Always sampled when no sigma_v is given.
    #[arg(long)]
    pub fit_scatter: bool,
    /// MCMC: write the kept draws (after burn-in and thinning) to this CSV: fit,series,walker,
    /// step, one column per parameter, log_posterior; `-` writes it to stdout.
    #[arg(long)]
    pub draws: Option<PathBuf>,
    /// With --plot: under lsq, v̄ against δ per series, the data with their σ bars, each
    /// fitted curve and its confidence band at --level (delta method); under mcmc, a corner
    /// plot of every posterior (marginal histograms and pairwise scatter).
    #[command(flatten)]
    pub plot: PlotArgs,
}

/// What the least-squares figure of `--plot` draws: its title, the data fitted and the curve
/// of each fit passed to [`FitArgs::write`] (in the same order).
pub struct LsqPlot<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// The data the fits were made on.
    pub data: &'a crate::fit::data::Dataset,
    /// One curve per fit.
    pub curves: &'a [Curve],
}

/// The estimation method asked for on the command line (a posterior run carries the stop
/// flag raised by Ctrl-C in its sampler options).
pub struct MethodChoice {
    /// The method.
    pub method: Method,
}

impl FitArgs {
    /// The method from `--method` and the MCMC flags; `params` are the names `--prior` may
    /// use (the fit's parameters and sigma_scale). MCMC flags without `--method mcmc` are an
    /// error. Installs the signal handler whose stop flag ([`super::stop_flag`]) stops the
    /// solvers and the sampler cleanly.
    pub fn method(&self, params: &[&str]) -> Result<MethodChoice, CliError> {
        let mcmc_flags = [
            ("--seed", self.seed.is_some()),
            ("--walkers", self.walkers.is_some()),
            ("--min-ess", self.min_ess.is_some()),
            ("--max-steps", self.max_steps.is_some()),
            ("--thin", self.thin.is_some()),
            ("--prior", !self.priors.is_empty()),
            ("--fit-scatter", self.fit_scatter),
            ("--draws", self.draws.is_some()),
        ];
        if self.method == FitMethod::Lsq {
            if let Some((flag, _)) = mcmc_flags.iter().find(|f| f.1) {
                return Err(super::flag_error(flag, "", "applies to --method mcmc only"));
            }
            return Ok(MethodChoice {
                method: Method::Lsq {
                    profile: !self.no_profile,
                    stop: Some(super::stop_flag()),
                    progress: None,
                },
            });
        }
        let mut options = McmcOptions::default();
        if let Some(s) = self.seed {
            options.seed = s;
        } else {
            options.seed = 1;
        }
        options.walkers = self.walkers;
        if let Some(e) = self.min_ess {
            options.min_ess = e;
        }
        if let Some(m) = self.max_steps {
            options.max_steps = m;
        }
        if let Some(t) = self.thin {
            options.thin = t;
        }
        options.check().map_err(|e| {
            super::flag_error(
                &format!("--{}", e.option.replace('_', "-")),
                &e.value,
                e.expected,
            )
        })?;
        let mut priors = Vec::new();
        for NamedPrior { name, prior, text } in &self.priors {
            if name != SCALE_NAME && !params.contains(&name.as_str()) {
                return Err(super::flag_error(
                    "--prior",
                    text,
                    format!(
                        "no parameter '{name}' in this fit; expected one of {}, {SCALE_NAME}",
                        params.join(", ")
                    ),
                ));
            }
            priors.push((name.clone(), prior.clone()));
        }
        options.stop = Some(super::stop_flag());
        Ok(MethodChoice {
            method: Method::Mcmc(Box::new(McmcSettings {
                options,
                priors,
                fit_scatter: self.fit_scatter,
                progress: std::io::stderr()
                    .is_terminal()
                    .then(super::sampler_progress_bar),
            })),
        })
    }

    /// The input and the outputs named on the command line, by flag (for the check that no
    /// output is an input or another output).
    pub fn paths(&self) -> (super::NamedPaths<'_>, super::NamedPaths<'_>) {
        (
            vec![("--input", self.data.path())],
            vec![
                ("--output", self.out.output.as_deref()),
                ("--output-stats", self.output_stats.as_deref()),
                ("--draws", self.draws.as_deref()),
                ("--plot", self.plot.plot.as_deref()),
            ],
        )
    }

    /// Reads the measurements.
    pub fn read(&self) -> Result<(Table, Vec<Measurement>, Dataset), CliError> {
        let input = self.data.path();
        let (source, text) = read_input(input)?;
        let t = Table::parse(&source, &text)?;
        self.data.check_columns(&t)?;
        let defaults = self.data.defaults()?;
        let rows = read_measurements(&t, &defaults)?;
        let ds = dataset_of(&t, &rows)?;
        super::warn_implausible(&t, &rows);
        Ok((t, rows, ds))
    }

    /// Writes the reports: the files given are staged and renamed together (a failure leaves
    /// all of them untouched); the report goes to stdout without `--output`, the statistics to
    /// stderr as a table without `--output-stats`.
    ///
    /// `posteriors` are the fits sampled by MCMC: their draws go to `--draws` and their corner
    /// plots to `--plot`, in the same atomic group. A run stopped by Ctrl-C writes everything
    /// and then returns [`CliError::Interrupted`].
    pub fn write(&self, fits: &[&FitResult], plot: &LsqPlot<'_>) -> Result<(), CliError> {
        let posteriors: Vec<&FitResult> =
            fits.iter().copied().filter(|f| f.draws.is_some()).collect();
        let posteriors = posteriors.as_slice();
        let params: Vec<ParamRow> = fits.iter().flat_map(|f| f.params.iter().cloned()).collect();
        let stats: Vec<StatsRow> = fits.iter().map(|f| f.stats.clone()).collect();
        let interrupted = posteriors
            .iter()
            .any(|p| p.draws.as_ref().is_some_and(|d| d.interrupted));
        // Least squares stopped by a signal: nothing is written.
        if super::stop_requested() && !interrupted {
            return Err(CliError::Interrupted);
        }
        posterior_faults(&stats)?;
        let stats = &flag_absurd(&stats);
        let p_csv = params_csv(&params).map_err(|e| CliError::Other(e.to_string()))?;
        let s = stats_csv(stats).map_err(|e| CliError::Other(e.to_string()))?;
        let d_csv = match &self.draws {
            Some(_) => draws_csv(posteriors).map_err(|e| CliError::Other(e.to_string()))?,
            None => Vec::new(),
        };
        // The figure files: under least squares one figure; under MCMC one corner plot per
        // fit and series, PATH's stem followed by _FIT_SERIES (all stacked in one document
        // when the figure goes to stdout).
        let mut figures: Vec<(PathBuf, Vec<u8>)> = Vec::new();
        if let Some(path) = &self.plot.plot {
            if posteriors.is_empty() {
                let with: Vec<(&FitResult, Curve)> = fits
                    .iter()
                    .zip(plot.curves)
                    .map(|(f, c)| (*f, *c))
                    .collect();
                let svg = lsq_fit_figure(plot.title, plot.data, &with)
                    .map_err(|e| CliError::Other(format!("--plot: {e}")))?;
                figures.push((path.clone(), self.plot.bytes(svg)?));
            } else if path.as_os_str() == "-" {
                let svg = corner_svg(&CornerBlock::from_posteriors(posteriors))
                    .map_err(|e| CliError::Other(format!("corner plot: {e}")))?;
                figures.push((path.clone(), svg.into_bytes()));
            } else {
                let labels: Vec<String> =
                    posteriors.iter().map(|p| p.stats.series.clone()).collect();
                let stems = file_stems(&labels);
                let stem = path.file_stem().map_or_else(
                    || "corner".to_string(),
                    |s| s.to_string_lossy().into_owned(),
                );
                let ext = path
                    .extension()
                    .map_or_else(|| "svg".to_string(), |e| e.to_string_lossy().into_owned());
                for (p, series) in posteriors.iter().zip(&stems) {
                    let svg = corner_svg(&CornerBlock::from_posteriors(&[*p]))
                        .map_err(|e| CliError::Other(format!("corner plot: {e}")))?;
                    let name = format!("{stem}_{}_{series}.{ext}", p.stats.fit);
                    figures.push((path.with_file_name(name), self.plot.bytes(svg)?));
                }
            }
        }
        let files: Vec<(&std::path::Path, &[u8])> = self
            .out
            .output
            .iter()
            .filter(|_| !self.out.to_stdout())
            .map(|p| (p.as_path(), p_csv.as_slice()))
            .chain(
                self.output_stats
                    .iter()
                    .map(|q| (q.as_path(), s.as_slice())),
            )
            .chain(self.draws.iter().map(|q| (q.as_path(), d_csv.as_slice())))
            .chain(figures.iter().map(|(q, b)| (q.as_path(), b.as_slice())))
            .collect();
        if !files.is_empty() {
            write_atomic_all(&files).map_err(|e| CliError::Other(format!("cannot write: {e}")))?;
        }
        // Without --output the fit reports on stdout carry the statistics.
        if self.output_stats.is_none() && self.out.output.is_some() {
            for r in stats {
                eprintln!(
                    "{} [{}]: chi2 {} dof {} reduced {} AIC {} BIC {} ({}){}",
                    r.fit,
                    r.series,
                    fmt_sig(r.chi2, 7),
                    r.dof,
                    fmt_sig(r.reduced_chi2, 7),
                    fmt_sig(r.aic, 7),
                    fmt_sig(r.bic, 7),
                    r.termination,
                    if r.note.is_empty() {
                        String::new()
                    } else {
                        format!(" — {}", r.note)
                    }
                );
            }
        }
        if self.out.to_stdout() {
            emit(None, &p_csv)?;
        } else if self.out.output.is_none() {
            emit(None, fit_reports(fits, stats).as_bytes())?;
        }
        if interrupted {
            // The posterior runs cut short go to stderr even when the statistics go to a file.
            if self.output_stats.is_some() {
                for r in stats.iter().filter(|r| r.mcmc.is_some() && !r.converged) {
                    eprintln!("fitbead: warning: {} [{}]: {}", r.fit, r.series, r.note);
                }
            }
            return Err(CliError::InterruptedPartial);
        }
        // Every fit that did not converge is named once, with why, by the exit-1 message.
        not_converged(stats)
    }
}

/// The fit report of every fit, one after another (`stats` are the fits' statistics as
/// written, with any warning added to their notes).
fn fit_reports(fits: &[&FitResult], stats: &[StatsRow]) -> String {
    let mut out = String::new();
    for (i, f) in fits.iter().enumerate() {
        if i > 0 {
            out.push('\n');
        }
        match stats.get(i) {
            Some(s) if *s != f.stats => {
                let mut g = FitResult {
                    draws: None,
                    ..(*f).clone()
                };
                g.stats = s.clone();
                out.push_str(&g.to_string());
            }
            _ => out.push_str(&f.to_string()),
        }
    }
    out
}

/// A prior that leaves nothing to sample (its support misses the parameter's feasible box) is
/// a bad flag: exit 2 naming the prior, its support and the box, before anything is written.
pub fn posterior_faults(stats: &[StatsRow]) -> Result<(), CliError> {
    for s in stats {
        if let Some(
            f @ McmcFailure::PriorOutsideBox {
                parameter, prior, ..
            },
        ) = s.mcmc.as_ref().and_then(|m| m.failure.as_ref())
        {
            return Err(super::flag_error(
                "--prior",
                &format!("{parameter}={prior}"),
                format!("{} [{}]: {f}", s.fit, s.series),
            ));
        }
    }
    Ok(())
}

/// Exit 1 for fits that did not converge, once their outputs are written: a least-squares
/// fit that stopped short of its tolerance, a posterior run that could not start (its rows
/// hold the least-squares values, marked) or one that stopped at `--max-steps` before its
/// R̂ and ESS targets. A law with no free parameter is scored, not fitted: a point it cannot
/// make steady is said in its note, not in the exit code. The message names each fit, its
/// series and why.
pub fn not_converged(stats: &[StatsRow]) -> Result<(), CliError> {
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
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CliError::NotConverged(failed.join("; ")))
    }
}

/// `stats` with every fit whose misfit is absurd or improbable for the σ given flagged in its
/// note and on stderr ([`StatsRow::misfit_warning`]).
pub fn flag_absurd(stats: &[StatsRow]) -> Vec<StatsRow> {
    stats
        .iter()
        .map(|s| {
            if let Some(w) = s.misfit_warning() {
                eprintln!("fitbead: warning: {} [{}]: {w}", s.fit, s.series);
            }
            s.with_misfit_note()
        })
        .collect()
}
