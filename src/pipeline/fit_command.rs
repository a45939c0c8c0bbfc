//! The fit commands (`klaw`, `jan`, `jaeger`) as one library call, [`FitCommand::run`], which
//! returns a [`FitRun`](super::FitRun).

use super::fit_run::FitRun;
use super::{control_error, jaeger, jan, klaw, setting_error, RunError};
use crate::fit::controls::Controls;
use crate::fit::klaw::KLaw;
use crate::fit::slopes;
use crate::fit::summary::{FitResult, McmcFailure};
use crate::inverse::posterior::{Method, SCALE_NAME};
use crate::io::fmt_f64;
use crate::io::measurements::MeasurementFile;
use crate::models::{JaegerBranch, ModelKind};
use crate::progress::{Progress, ProgressEvent, Tally};

/// A fit command of the command line with the settings of its own; the method, the level and
/// the data are given to [`FitCommand::run`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FitCommand {
    /// `fitbead klaw`: a law K(α) fitted to all series at once under a contact model, the
    /// impact law scored beside it.
    Klaw {
        /// The contact model (stick, stick-approx, slip, slip-approx, stickslip, contact), or
        /// auto: the most general model any point needs at its stick K.
        model: ModelKind,
        /// The law fitted.
        law: KLaw,
        /// With auto: the target relative tolerance on v.
        tol: f64,
        /// Leave out the points no K makes steady (each named in a note) instead of failing.
        skip_unsteady: bool,
    },
    /// `fitbead jan`: Jan's λ and μ per series (eq 74) and the global laws (eqs 75–76).
    Jan,
    /// `fitbead jaeger`: Jaeger's a1, a2, a3 per series (eqs 80–84).
    Jaeger {
        /// The root of eq 84 fitted where there are two.
        branch: JaegerBranch,
    },
}

impl FitCommand {
    /// The command's name (`klaw`, `jan`, `jaeger`).
    pub fn name(&self) -> &'static str {
        match self {
            FitCommand::Klaw { .. } => "klaw",
            FitCommand::Jan => "jan",
            FitCommand::Jaeger { .. } => "jaeger",
        }
    }

    /// The names of the parameters a posterior run samples, which priors may name (besides
    /// the error scale `sigma_scale`).
    pub fn parameters(&self) -> &'static [&'static str] {
        match self {
            FitCommand::Klaw { law, .. } => match law {
                KLaw::C => &["c"],
                KLaw::FreePerSeries => &["K"],
                KLaw::Impact => &[],
            },
            FitCommand::Jan => &["lambda", "mu", "lambda0", "lambda1", "mu0", "mu1"],
            FitCommand::Jaeger { .. } => &["a1", "a2", "a3"],
        }
    }

    /// Fits the data of `file` by `method` at confidence `level`.
    ///
    /// `progress`, when given, counts the model evaluations of a least-squares fit (a task of
    /// unknown total labelled with the fit's name; a posterior run reports its sampler's steps
    /// through its own settings instead). `note` is told, as soon as they are known, what the
    /// command line prints after `fitbead NAME: `: the model auto chose, each point left out,
    /// each fit that could not be made.
    ///
    /// Errors: data no fit can be made on (a point no K makes steady, an empty box of the
    /// law's parameter, no series with enough points), a prior whose support misses its
    /// parameter's box ([`RunError::Input`] on `--prior`), and [`RunError::Interrupted`] when
    /// the method's stop flag was raised before anything could be kept (a posterior run cut
    /// short is kept, its rows marked).
    pub fn run(
        &self,
        file: &MeasurementFile,
        method: Method,
        level: f64,
        progress: Option<Progress>,
        note: &mut dyn FnMut(&str),
    ) -> Result<FitRun, RunError> {
        self.check(&method, level, &file.dataset.labels)?;
        if let Some(why) = slopes::unsupported(&method, file.dataset()) {
            return Err(setting_error("--method", "mcmc", why));
        }
        let progress = progress.filter(|_| matches!(method, Method::Lsq { .. }));
        let run = match *self {
            FitCommand::Klaw {
                model,
                law,
                tol,
                skip_unsteady,
            } => {
                let s = klaw::KlawSettings {
                    model,
                    law,
                    tol,
                    skip_unsteady,
                };
                klaw::run(&s, file, &method, level, progress, note)?
            }
            FitCommand::Jan => {
                let (counted, _task) = counted(self.name(), &method, progress);
                jan::run(file, &counted, level, note)?
            }
            FitCommand::Jaeger { branch } => {
                let (counted, _task) = counted(self.name(), &method, progress);
                jaeger::run(file, branch, &counted, level, note)?
            }
        };
        // Least squares stopped by the flag: nothing is kept.
        if method.stopped() && !run.interrupted() {
            return Err(RunError::Interrupted);
        }
        prior_faults(&run.fits)?;
        Ok(run)
    }
}

impl FitCommand {
    /// Refuses a level outside (0, 1), a control (`fix`, `init`, `bounds`) of a parameter
    /// the fit does not have or of a series not among `labels`, and a prior on a parameter
    /// the fit does not have or holds.
    fn check(&self, method: &Method, level: f64, labels: &[String]) -> Result<(), RunError> {
        if !(level > 0.0 && level < 1.0) {
            return Err(setting_error(
                "--level",
                &fmt_f64(level),
                format!("confidence level {} is not in (0, 1)", fmt_f64(level)),
            ));
        }
        let params = self.parameters();
        let controls = Controls::of(method);
        controls.check(params, labels).map_err(|mut e| {
            // A name the fit does not have: the one it most likely misspells.
            let key = e.value.rsplit_once('=').map_or(e.value.as_str(), |k| k.0);
            let name = key.split('[').next().unwrap_or(key);
            if e.reason.starts_with("no parameter") {
                if let Some(n) = crate::io::scenes::nearest(name, params.iter().copied()) {
                    e.reason.push_str(&format!("; did you mean '{n}'?"));
                }
            }
            control_error(e)
        })?;
        let Method::Mcmc(m) = method else {
            return Ok(());
        };
        for (name, prior) in &m.priors {
            if controls.fix.iter().any(|(k, _)| k == name) {
                return Err(setting_error(
                    "--prior",
                    &format!("{name}={prior}"),
                    format!("{name} is held (--fix): it is not sampled and takes no prior"),
                ));
            }
            if name != SCALE_NAME && !params.contains(&name.as_str()) {
                return Err(setting_error(
                    "--prior",
                    &format!("{name}={prior}"),
                    format!(
                        "no parameter '{name}' in this fit; expected one of {}, {SCALE_NAME}",
                        params.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// `method` with its least-squares runs counted on `progress` as a task labelled `label`,
/// started here, and the task's end (reported when dropped).
fn counted(label: &str, method: &Method, progress: Option<Progress>) -> (Method, Finished) {
    if let Some(p) = &progress {
        p.report(ProgressEvent::Start {
            label,
            total: 0,
            check_every: 0,
        });
    }
    let m = method
        .clone()
        .with_progress(progress.clone().map(Tally::new));
    (m, Finished(progress))
}

/// Reports a progress task finished when dropped.
struct Finished(Option<Progress>);

impl Drop for Finished {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            p.report(ProgressEvent::Finish);
        }
    }
}

/// A prior that leaves nothing to sample (its support misses the parameter's feasible box) is
/// a bad setting: an error on `--prior` naming the prior, its support and the box.
fn prior_faults(fits: &[FitResult]) -> Result<(), RunError> {
    for s in fits.iter().map(|f| &f.stats) {
        if let Some(
            f @ McmcFailure::PriorOutsideBox {
                parameter, prior, ..
            },
        ) = s.mcmc.as_ref().and_then(|m| m.failure.as_ref())
        {
            return Err(setting_error(
                "--prior",
                &format!("{parameter}={prior}"),
                format!("{} [{}]: {f}", s.fit, s.series),
            ));
        }
    }
    Ok(())
}
