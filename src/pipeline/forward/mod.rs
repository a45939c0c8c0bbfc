//! `fitbead forward --model md`: one molecular-dynamics run per row of a scene table.

pub(crate) mod md;
pub(crate) mod plan;

use super::RunError;
use crate::io::scenes::Table;
use crate::models::md::MdResult;
use crate::progress::{Progress, ProgressEvent, Tally};
use md::{md_csv, md_jobs, MdTable};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The md runs of every row of `t` under `base` (its model, the settings of the command line,
/// ρ and f of rows without those columns), as the CSV `fitbead forward` writes: the input's
/// columns, then the md columns. With `check_step` every row is run again at half the time
/// step and the relative change of v̄ goes in `md_step_check`. `progress` gets a task
/// labelled `md` whose total counts the beads passed over all runs. A raised `stop` ends the
/// runs with [`RunError::Interrupted`].
pub(crate) fn md_runs(
    t: &Table,
    base: &MdTable,
    check_step: bool,
    progress: Option<Progress>,
    stop: &AtomicBool,
) -> Result<Vec<u8>, RunError> {
    let jobs = md_jobs(t, base)?;
    let reps: u64 = if check_step { 3 } else { 1 };
    let total: u64 = jobs.iter().map(|(_, m)| m.config.beads as u64 * reps).sum();
    if let Some(p) = &progress {
        p.report(ProgressEvent::Start {
            label: "md",
            total,
            check_every: 0,
        });
    }
    let tally = progress.clone().map(Tally::new);
    let tick = |n: u64| {
        if let Some(t) = &tally {
            t.add(n);
        }
    };
    let results: Vec<(MdResult, Option<f64>)> = jobs
        .par_iter()
        .map(|(scene, md)| {
            let r = md.simulate_until(scene, 1.0, Some(&tick), Some(stop));
            let rel = if check_step {
                let h = md.simulate_until(scene, 0.5, Some(&tick), Some(stop));
                match (r.mean_velocity, h.mean_velocity) {
                    (Some(x), Some(y)) => Some(((y - x) / x).abs()),
                    _ => None,
                }
            } else {
                None
            };
            (r, rel)
        })
        .collect();
    if let Some(p) = &progress {
        p.report(ProgressEvent::Finish);
    }
    if stop.load(Ordering::SeqCst) {
        return Err(RunError::Interrupted);
    }
    md_csv(t, &jobs, &results).map_err(|e| RunError::Failed(e.to_string()))
}
