//! The work-precision table of `fitbead bench` and the molecular-dynamics runs of `fitbead
//! forward --model md`.

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
        .map_err(RunError::Failed)
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

/// `fitbead forward --model md` on a scene table (CSV `xi,delta_deg[,rho][,f]` and per-row md
/// settings, as the command line reads it; `source` names it in errors): one md run of every
/// row under `md`, as the CSV the command line writes (the input's columns, then the md
/// columns). `rho` and `f` are those of rows without the columns. A raised `stop` ends the
/// run with [`RunError::Interrupted`].
pub fn forward_md(
    table: &[u8],
    source: &str,
    md: crate::models::md::Md,
    rho: f64,
    f: f64,
    stop: Option<&AtomicBool>,
) -> Result<Vec<u8>, RunError> {
    use crate::io::md::{md_csv, md_jobs, MdTable};
    use rayon::prelude::*;
    let t = crate::io::scenes::Table::parse(source, table)?;
    let base = MdTable {
        md,
        flags: crate::models::md::MdSettings::default(),
        rho,
        f,
    };
    let jobs = md_jobs(&t, &base)?;
    let never = AtomicBool::new(false);
    let stop = stop.unwrap_or(&never);
    let results: Vec<(crate::models::md::MdResult, Option<f64>)> = jobs
        .par_iter()
        .map(|(scene, md)| (md.simulate_until(scene, 1.0, None, Some(stop)), None))
        .collect();
    if stop.load(std::sync::atomic::Ordering::SeqCst) {
        return Err(RunError::Interrupted);
    }
    md_csv(&t, &jobs, &results).map_err(|e| RunError::Failed(e.to_string()))
}
