//! `fitbead bench`: the work-precision report of `crate::report::workprecision`, as CSV and
//! SVG.

use super::args::{OutputArgs, PlotArgs};
use super::{emit, CliError};
use crate::io::write_atomic_all;
use crate::report::workprecision::{draw_scenes, plot, render, run_bench_until, XCHECK_BOUNDS};

/// Arguments of `fitbead bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of scenes drawn across regime B (about 30 % of them a hard subset: near δ_m,
    /// near Θ0 = 0, near the upper K limit).
    #[arg(long, default_value_t = 2000, value_parser = super::values::scenes)]
    pub scenes: usize,
    /// Seed of the scene draw.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// With --plot: the work-precision diagram, log time per evaluation against log maximum
    /// error.
    #[command(flatten)]
    pub plot: PlotArgs,
}

/// Runs `fitbead bench`.
pub fn run(a: Args) -> Result<(), CliError> {
    let scenes = draw_scenes(a.scenes, a.seed);
    if scenes.len() < a.scenes {
        return Err(CliError::Other(format!(
            "could draw only {} of {} scenes",
            scenes.len(),
            a.scenes
        )));
    }
    let stop = super::stop_flag();
    let res = run_bench_until(&scenes, &stop).map_err(|_| CliError::Interrupted)?;
    for r in res
        .rows
        .iter()
        .filter(|r| r.method.starts_with("crosscheck"))
    {
        let bound = XCHECK_BOUNDS
            .iter()
            .find(|b| b.0 == r.model)
            .map(|b| b.1)
            .unwrap_or(0.0);
        if r.scenes == 0 {
            eprintln!(
                "reference {:<10} {:<42} scenes     0: no scenes: none of the {} drawn falls in \
                 this check's domain (draw more with --scenes)",
                r.model,
                r.method,
                scenes.len()
            );
            continue;
        }
        eprintln!(
            "reference {:<10} {:<42} scenes {:>5}  max {:.2e}  median {:.2e}  bound {:.0e}: {}",
            r.model,
            r.method,
            r.scenes,
            r.err_max,
            r.err_median,
            bound,
            if r.err_max <= bound { "ok" } else { "FAILED" }
        );
    }
    for (t, best) in &res.cheapest {
        let auto = res
            .rows
            .iter()
            .find(|r| r.model == "auto" && r.tol == Some(*t))
            .and_then(|r| r.ns_median)
            .unwrap_or(f64::NAN);
        match best {
            Some((name, ns)) => eprintln!(
                "auto at T = {t:e}: median {auto:.0} ns; cheapest single method meeting T on all scenes (vs physics reference): {name}, {ns:.0} ns"
            ),
            None => eprintln!(
                "auto at T = {t:e}: median {auto:.0} ns; no single method meets T on all scenes"
            ),
        }
    }
    eprintln!(
        "auto at T = 1e-10 used stick on {}, stickslip on {}, contact on {} scenes",
        res.auto_mix.0, res.auto_mix.1, res.auto_mix.2
    );
    let bytes = render(&res.rows).map_err(|e| CliError::Other(e.to_string()))?;
    let svg = match &a.plot.plot {
        Some(_) => a.plot.bytes(
            plot(
                &res.rows,
                &format!("Work-precision, {} scenes (seed {})", scenes.len(), a.seed),
            )
            .map_err(CliError::Other)?,
        )?,
        None => Vec::new(),
    };
    // The plot and the CSV file are written as one group: both or neither.
    let files: Vec<(&std::path::Path, &[u8])> = a
        .plot
        .plot
        .iter()
        .map(|p| (p.as_path(), svg.as_slice()))
        .chain(a.out.output.iter().map(|p| (p.as_path(), bytes.as_slice())))
        .collect();
    if !files.is_empty() {
        write_atomic_all(&files).map_err(|e| CliError::Other(format!("cannot write: {e}")))?;
    }
    if a.out.output.is_none() {
        emit(None, &bytes)?;
    }
    Ok(())
}
