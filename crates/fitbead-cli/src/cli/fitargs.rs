//! Flags and I/O shared by the fit commands (`klaw`, `jan`, `jaeger`).

use super::args::{DataArgs, LevelArgs, PlotArgs};
use super::values::{self, FitMethod, NamedPrior};
use super::{emit, read_input, CliError};
use fitbead::fit::posterior::{McmcSettings, Method};
use fitbead::inverse::mcmc::McmcOptions;
use fitbead::io::measurements::MeasurementFile;
use fitbead::io::AtomicFile;
use fitbead::pipeline::{FitCommand, FitRun, RunError};
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
    /// Hold a parameter at a value, NAME=VALUE, repeatable (lmfit's vary=False): NAME in every
    /// fit that has it (every series), NAME[SERIES] in that series' fit alone. A held
    /// parameter is not fitted: its row has the value, no stderr or interval (ci_method none)
    /// and the note "fixed"; dof, AIC and BIC count the free parameters only. A fit with every
    /// parameter held is scored at the values.
    #[arg(long = "fix", value_name = "NAME=VALUE", value_parser = values::named_value)]
    pub fix: Vec<(String, f64)>,
    /// Start a parameter at a value instead of the fit's own start, NAME=VALUE (or
    /// NAME[SERIES]=VALUE), repeatable; the value must lie in the parameter's box.
    #[arg(long = "init", value_name = "NAME=VALUE", value_parser = values::named_value)]
    pub init: Vec<(String, f64)>,
    /// Bound a parameter, NAME=LO,HI (or NAME[SERIES]=LO,HI), repeatable; -inf and inf leave a
    /// side open. The bounds are intersected with the parameter's box (where the model has a
    /// value at every point).
    #[arg(long = "bounds", value_name = "NAME=LO,HI", value_parser = values::named_bounds)]
    pub bounds: Vec<(String, (f64, f64))>,
    /// Least squares: scale the covariance by the reduced chi-square even with sigma_v given,
    /// as lmfit's scale_covar=True (sigma_v then weighs the points, its scale is estimated
    /// from the scatter); standard errors, covariance and profile intervals are then those of
    /// data without sigma_v (Student-t on dof, profile threshold scaled by the reduced
    /// chi-square, lmfit's F-test). Without sigma_v the covariance is scaled already.
    #[arg(long)]
    pub scale_covar: bool,
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
                    scale_covar: self.scale_covar,
                    fix: self.fix.clone(),
                    init: self.init.clone(),
                    bounds: self.bounds.clone(),
                },
            });
        }
        if self.scale_covar {
            return Err(super::flag_error(
                "--scale-covar",
                "",
                "applies to --method lsq only (a posterior run has no covariance to scale)",
            ));
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
            if name != McmcSettings::SCALE_NAME && !params.contains(&name.as_str()) {
                return Err(super::flag_error(
                    "--prior",
                    text,
                    format!(
                        "no parameter '{name}' in this fit; expected one of {}, {}",
                        params.join(", "),
                        McmcSettings::SCALE_NAME
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
                fix: self.fix.clone(),
                init: self.init.clone(),
                bounds: self.bounds.clone(),
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
    pub fn read(&self) -> Result<MeasurementFile, CliError> {
        let input = self.data.path();
        let (source, text) = read_input(input)?;
        Ok(MeasurementFile::read_checked(
            &source,
            &text,
            &self.data.defaults(),
            input.is_some(),
            self.data.strict_columns,
            &mut |w| eprintln!("fitbead: warning: {w}"),
        )?)
    }

    /// Runs the fit command `command` on the measurements of the flags with the method and
    /// level of the flags, then writes what it made ([`FitArgs::write`]). Its notes go to
    /// stderr as they come; a least-squares fit shows its model evaluations on a terminal once
    /// it has run for a couple of seconds (a posterior run shows the sampler's steps instead).
    pub fn fit(&self, command: FitCommand) -> Result<(), CliError> {
        // The handler goes in before the data are read: a signal while a large file is read
        // and checked raises the flag (polled from the first bracket on) instead of killing
        // the process with no exit code.
        super::stop_flag();
        let file = self.read()?;
        let choice = self.method(command.parameters())?;
        let progress = super::delayed_progress_bar("model evaluations");
        let name = command.name();
        let run = command
            .run(
                &file,
                choice.method,
                self.level.level(),
                progress,
                &mut |n| eprintln!("fitbead {name}: {n}"),
            )
            .map_err(CliError::from)?;
        self.write(&run)
    }

    /// Writes what a fit command made: the files given are staged and renamed together (a
    /// failure leaves all of them untouched); the fit reports go to stdout without
    /// `--output`, the statistics to stderr as a table without `--output-stats`.
    ///
    /// The draws of the posterior runs go to `--draws` and their corner plots to `--plot`,
    /// in the same atomic group. A run stopped by Ctrl-C writes everything and then returns
    /// [`CliError::InterruptedPartial`].
    pub fn write(&self, run: &FitRun) -> Result<(), CliError> {
        let interrupted = run.interrupted();
        for w in run.misfits() {
            eprintln!("fitbead: warning: {w}");
        }
        let stats = &run.stats();
        let failed = |e: RunError| CliError::Other(e.to_string());
        let p_csv = run.params_csv().map_err(failed)?;
        let s = run.stats_csv().map_err(failed)?;
        let d_csv = match &self.draws {
            Some(_) => run.draws_csv().map_err(failed)?,
            None => Vec::new(),
        };
        let figures = match &self.plot.plot {
            Some(path) => run.figures(path).map_err(failed)?,
            None => Vec::new(),
        };
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
            AtomicFile::write_files(&files)
                .map_err(|e| CliError::Other(format!("cannot write: {e}")))?;
        }
        // Without --output the fit reports on stdout carry the statistics.
        if self.output_stats.is_none() && self.out.output.is_some() {
            for r in stats {
                eprintln!("{}", r.summary_line());
            }
        }
        if self.out.to_stdout() {
            emit(None, &p_csv)?;
        } else if self.out.output.is_none() {
            emit(None, run.fit_reports().as_bytes())?;
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
        not_converged(run.not_converged())
    }
}

/// Exit 1 for fits that did not converge, once their outputs are written, with the message
/// that names each fit, its series and why ([`fitbead::pipeline::FitRun::not_converged`]).
pub fn not_converged(message: Option<String>) -> Result<(), CliError> {
    match message {
        Some(m) => Err(CliError::NotConverged(m)),
        None => Ok(()),
    }
}
