//! The library's own batch call of the stick forward model, timed: every scene of a file of
//! arrays built (`Scene::new`) and evaluated into its forward record
//! (`ForwardRecord::evaluate`, the columns `fitbead forward` writes and `fitbead.forward`
//! returns) on rayon's threads, in tasks of 2,048 rows as the binding's, each record's numbers
//! and texts written into new columns (one entry per row, in input order). It is the baseline
//! that `python/bench/bench_binding.py` holds the Python binding against, on the same arrays
//! and threads.
//!
//! Usage: `cargo run --release --example forward_batch -- ARRAYS [RUNS]`
//!
//! ARRAYS holds five columns of N float64 numbers each, little-endian, one column after the
//! other: ξ, δ in degrees, K, ρ and f (what `bench_binding.py` writes). The batch runs once
//! as a warm-up, then RUNS times (default 5); the best and the median wall time are printed,
//! with the threads (`RAYON_NUM_THREADS`, else one per core) and the steady scenes.

use fitbead::io::records::ForwardRecord;
use fitbead::{CollisionLaw, Model, Scene};
use rayon::prelude::*;
use std::borrow::Cow;
use std::time::Instant;

/// The five columns of the arrays file.
struct Arrays {
    xi: Vec<f64>,
    delta_deg: Vec<f64>,
    k: Vec<f64>,
    rho: Vec<f64>,
    f: Vec<f64>,
}

fn read_arrays(path: &str) -> Result<Arrays, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    if bytes.is_empty() || bytes.len() % 40 != 0 {
        return Err(format!(
            "{path}: {} bytes: expected five columns of float64, a multiple of 40 bytes",
            bytes.len()
        ));
    }
    let n = bytes.len() / 40;
    let column = |c: usize| -> Vec<f64> {
        bytes[c * 8 * n..(c + 1) * 8 * n]
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("eight bytes")))
            .collect()
    };
    Ok(Arrays {
        xi: column(0),
        delta_deg: column(1),
        k: column(2),
        rho: column(3),
        f: column(4),
    })
}

/// Rows per parallel task, as the binding's.
const TASK_ROWS: usize = 2048;

/// The columns of the forward records: the eight numbers (NaN for an empty cell) and the
/// four texts, in the records' order.
struct Columns {
    nums: [Vec<f64>; 8],
    regime: Vec<&'static str>,
    status: Vec<&'static str>,
    phases: Vec<Cow<'static, str>>,
    message: Vec<Cow<'static, str>>,
}

/// One task's rows of every column.
struct Part<'a> {
    nums: Vec<&'a mut [f64]>,
    regime: &'a mut [&'static str],
    status: &'a mut [&'static str],
    phases: &'a mut [Cow<'static, str>],
    message: &'a mut [Cow<'static, str>],
}

/// Every scene's forward record under `model`, on rayon's threads in tasks of
/// [`TASK_ROWS`] rows, as columns (allocated here, as a batch call returns new ones).
fn batch(a: &Arrays, model: &Model) -> Result<Columns, String> {
    let n = a.xi.len();
    let mut cols = Columns {
        nums: std::array::from_fn(|_| vec![f64::NAN; n]),
        regime: vec![""; n],
        status: vec![""; n],
        phases: vec![Cow::Borrowed(""); n],
        message: vec![Cow::Borrowed(""); n],
    };
    let tasks = n.div_ceil(TASK_ROWS);
    let mut parts: Vec<Part<'_>> = Vec::with_capacity(tasks);
    let mut nums: Vec<_> = cols
        .nums
        .iter_mut()
        .map(|c| c.chunks_mut(TASK_ROWS))
        .collect();
    let mut regime = cols.regime.chunks_mut(TASK_ROWS);
    let mut status = cols.status.chunks_mut(TASK_ROWS);
    let mut phases = cols.phases.chunks_mut(TASK_ROWS);
    let mut message = cols.message.chunks_mut(TASK_ROWS);
    for _ in 0..tasks {
        parts.push(Part {
            nums: nums
                .iter_mut()
                .map(|c| c.next().expect("a chunk"))
                .collect(),
            regime: regime.next().expect("a chunk"),
            status: status.next().expect("a chunk"),
            phases: phases.next().expect("a chunk"),
            message: message.next().expect("a chunk"),
        });
    }
    parts
        .into_par_iter()
        .enumerate()
        .try_for_each(|(t, mut p)| {
            for j in 0..p.regime.len() {
                let i = t * TASK_ROWS + j;
                let law = CollisionLaw::Value(a.k[i]);
                let scene = Scene::new(a.xi[i], a.delta_deg[i], a.rho[i], a.f[i], law)
                    .map_err(|e| format!("row {i}: {e}"))?;
                let r = ForwardRecord::evaluate(&scene, model).0;
                let x = [
                    r.v,
                    r.k_used,
                    r.final_velocity,
                    r.initial_velocity,
                    r.contact_time,
                    r.theta_g_deg,
                    r.map_slope,
                    r.other_fixed_point,
                ];
                for (c, x) in p.nums.iter_mut().zip(x) {
                    c[j] = x.unwrap_or(f64::NAN);
                }
                p.regime[j] = r.regime;
                p.status[j] = r.status;
                p.phases[j] = r.phases;
                p.message[j] = r.message;
            }
            Ok::<(), String>(())
        })?;
    Ok(cols)
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: forward_batch ARRAYS [RUNS]: a file of five float64 columns")?;
    let runs: usize = match args.next() {
        Some(a) => a
            .parse()
            .ok()
            .filter(|&r| r > 0)
            .ok_or(format!("RUNS = '{a}': expected a whole number > 0"))?,
        None => 5,
    };
    let arrays = read_arrays(&path)?;
    let n = arrays.xi.len();
    let model = Model::Stick;
    let cols = batch(&arrays, &model)?;
    let steady = cols.nums[0].iter().filter(|v| !v.is_nan()).count();
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            let done = batch(&arrays, &model);
            let s = t.elapsed().as_secs_f64();
            done.map(|c| {
                drop(c);
                s
            })
        })
        .collect::<Result<_, _>>()?;
    times.sort_by(f64::total_cmp);
    println!(
        "scenes {n} steady {steady} threads {} runs {runs} best_s {:.6} median_s {:.6}",
        rayon::current_num_threads(),
        times[0],
        (times[(runs - 1) / 2] + times[runs / 2]) / 2.0
    );
    Ok(())
}
