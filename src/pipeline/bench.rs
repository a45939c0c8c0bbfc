//! `fitbead bench`: the work-precision table and the summary of its checks.

use super::{figure_bytes, setting_error, RunError};
use crate::report::workprecision::{
    draw_scenes, plot, render, run_bench_until, BenchResult, WpRow,
};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// `fitbead bench`: the work-precision measurements of every model and method variant, and
/// of the auto model, over scenes drawn across regime B, with the summary of their checks.
/// The times are measured on this machine; the errors depend on the scenes only.
pub struct Bench {
    /// The measurements.
    pub(crate) result: BenchResult,
    /// The number of scenes drawn.
    drawn: usize,
    /// The seed of the draw.
    seed: u64,
}

impl Bench {
    /// Measures over `scenes` scenes (1 to 1,000,000) drawn across regime B from `seed`; a
    /// raised `stop` ends the run with [`RunError::Interrupted`].
    pub fn run(scenes: usize, seed: u64, stop: Option<&AtomicBool>) -> Result<Bench, RunError> {
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

    /// The table's rows (the `--output` rows): the error against a cross-checked reference
    /// and the time per evaluation of each variant.
    pub fn rows(&self) -> &[WpRow] {
        &self.result.rows
    }

    /// The table as CSV (the `--output` file).
    pub fn csv(&self) -> Result<Vec<u8>, RunError> {
        render(&self.result.rows).map_err(|e| RunError::Failed(e.to_string()))
    }

    /// The summary of the checks, as the command line prints it on stderr.
    pub fn summary(&self) -> String {
        self.result.summary(self.drawn)
    }

    /// The work-precision diagram (log time per evaluation against log maximum error) as the
    /// bytes of the file `path`: PNG or PDF when its name ends `.png` or `.pdf`, SVG otherwise.
    pub fn figure(&self, path: &Path) -> Result<Vec<u8>, RunError> {
        let svg = plot(
            &self.result.rows,
            &format!("Work-precision, {} scenes (seed {})", self.drawn, self.seed),
        )?;
        figure_bytes(path, svg)
    }
}
