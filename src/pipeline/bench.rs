//! The work-precision table of `fitbead bench`.

use super::{setting_error, RunError};
use crate::report::workprecision::{draw_scenes, run_bench_until, WpRow};
use std::sync::atomic::AtomicBool;

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
    run_bench_until(&drawn, stop.unwrap_or(&never))
        .map(|r| r.rows)
        .map_err(|_| RunError::Interrupted)
}
