//! `fitbead bench`: the work-precision table and the summary of its checks.

use super::{setting_error, RunError};
use crate::report::workprecision::{draw_scenes, plot, run_bench_until, BenchResult, WpRow};
use std::sync::atomic::AtomicBool;

/// What `fitbead bench` made: the table's rows and the summary of its checks.
pub(crate) struct Bench {
    /// The measurements.
    pub result: BenchResult,
    /// The number of scenes drawn.
    pub drawn: usize,
    /// The seed of the draw.
    pub seed: u64,
}

impl Bench {
    /// The summary printed on stderr ([`BenchResult::summary`]).
    pub fn summary(&self) -> String {
        self.result.summary(self.drawn)
    }

    /// The work-precision diagram (SVG).
    pub fn figure(&self) -> Result<String, RunError> {
        plot(
            &self.result.rows,
            &format!("Work-precision, {} scenes (seed {})", self.drawn, self.seed),
        )
        .map_err(RunError::from)
    }
}

/// `fitbead bench`: the work-precision measurements over `scenes` scenes drawn across regime B
/// from `seed`; a raised `stop` ends the run with [`RunError::Interrupted`].
pub(crate) fn bench(
    scenes: usize,
    seed: u64,
    stop: Option<&AtomicBool>,
) -> Result<Bench, RunError> {
    if scenes == 0 || scenes > 1_000_000 {
        return Err(setting_error(
            "--scenes",
            &scenes.to_string(),
            "expected a number of scenes in 1..=1000000",
        ));
    }
    let drawn = draw_scenes(scenes, seed);
    if drawn.len() < scenes {
        return Err(RunError::Failed(format!(
            "could draw only {} of {} scenes",
            drawn.len(),
            scenes
        )));
    }
    let never = AtomicBool::new(false);
    let result =
        run_bench_until(&drawn, stop.unwrap_or(&never)).map_err(|_| RunError::Interrupted)?;
    Ok(Bench {
        result,
        drawn: drawn.len(),
        seed,
    })
}

/// The work-precision table of `fitbead bench` (its `--output` rows, [`WpRow`]): the error
/// against a cross-checked reference and the time per evaluation of every model and method
/// variant, and of the auto model, over `scenes` scenes drawn across regime B from `seed`.
/// The times are measured on this machine; the errors depend on the scenes only. A raised
/// `stop` ends the run with [`RunError::Interrupted`].
pub fn work_precision(
    scenes: usize,
    seed: u64,
    stop: Option<&AtomicBool>,
) -> Result<Vec<WpRow>, RunError> {
    bench(scenes, seed, stop).map(|b| b.result.rows)
}
