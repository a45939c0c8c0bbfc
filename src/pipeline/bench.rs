//! The work-precision table of `fitbead bench` and the molecular-dynamics runs of `fitbead
//! forward --model md`.

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
