//! How many contact times the K inversion computes per row (`fit::k::contacts_counted`): the
//! bracket's top, K's own search, dv̄/dK and the searches for K_lo and K_hi. Stick rows in three
//! sets: random measurements (scenes as `scripts/gen_measurements.py` draws them, v at a K
//! drawn across the bracket, σ 0.5–10 % of v), and measurements within 1e-15 … 1e-2 (relative,
//! log-uniform) of either end of the bracket, as the edge tests draw them: near the crawl (K
//! above K_min) and near lift-off (K below K_d). Printed per set and path (over the top, δ < α;
//! past it, δ > α): mean, median, 90th percentile and largest, of the whole row and of K's
//! search alone; the means are held below bounds a tenth above those measured, so that a
//! change that costs contacts shows here. `cargo test --release --lib k_contacts --
//! --nocapture`.

use super::k_edges::random_scene;
use crate::fit::k::{bracket, contacts_counted, estimate};
use crate::models::{ForwardModel, Model};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Where in the bracket a set's K is drawn.
#[derive(Clone, Copy, Debug)]
enum Set {
    Random,
    NearCrawl,
    NearLiftOff,
}

/// Counts per ok row of `set`, split by path (over the top, past it): (whole row, K's search).
fn counts(set: Set, rows: usize, seed: u64) -> [Vec<(u64, u64)>; 2] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = [Vec::new(), Vec::new()];
    let m = Model::Stick;
    while out[0].len() + out[1].len() < rows {
        let scene = random_scene(&mut rng);
        let Ok(br) = bracket(&m, &scene) else {
            continue;
        };
        let eps = (rng.random_range(1e-15f64.ln()..1e-2f64.ln())).exp();
        let k = match set {
            Set::Random => br.lo + rng.random_range(0.0..1.0) * (br.hi - br.lo),
            Set::NearCrawl if br.lo > 0.0 => br.lo * (1.0 + eps),
            Set::NearCrawl => eps * br.hi,
            Set::NearLiftOff => br.hi * (1.0 - eps),
        };
        let Some(Ok(st)) = scene.with_k(k).ok().map(|s| m.evaluate(&s)) else {
            continue;
        };
        let v = st.mean_velocity;
        let sigma = rng.random_range(0.005..0.1) * v;
        let before = contacts_counted();
        let e = estimate(&m, &scene, v, Some(sigma));
        let row = contacts_counted() - before;
        if let Ok(r) = &e.root {
            out[usize::from(scene.theta_0 >= 0.0)].push((row, r.evals as u64));
        }
    }
    out
}

/// Mean, median, 90th percentile and largest.
fn spread(mut xs: Vec<u64>) -> (f64, u64, u64, u64) {
    xs.sort_unstable();
    let n = xs.len();
    let at = |q: f64| xs[(q * (n - 1) as f64).round() as usize];
    let mean = xs.iter().sum::<u64>() as f64 / n as f64;
    (mean, at(0.5), at(0.9), xs[n - 1])
}

#[test]
fn contacts_per_ok_stick_row() {
    // Bounds on the means (whole row, K's search), per set and path: measured × 1.1.
    let bounds = [
        (Set::Random, [(10.4, 3.4), (16.8, 5.2)]),
        (Set::NearCrawl, [(15.3, 4.1), (38.3, 13.5)]),
        (Set::NearLiftOff, [(7.3, 3.6), (14.1, 3.7)]),
    ];
    for (i, (set, bound)) in bounds.into_iter().enumerate() {
        let by_path = counts(set, 4000, 70 + i as u64);
        for (path, (rows, (b_row, b_root))) in ["over the top", "past the top"]
            .iter()
            .zip(by_path.into_iter().zip(bound))
        {
            if rows.is_empty() {
                println!("{set:?}, {path}: no ok rows");
                continue;
            }
            let n = rows.len();
            let row = spread(rows.iter().map(|r| r.0).collect());
            let root = spread(rows.iter().map(|r| r.1).collect());
            println!(
                "{set:?}, {path}: {n} ok rows; per row mean {:.2}, median {}, 90 % {}, max {}; \
                 K's search mean {:.2}, median {}, 90 % {}, max {}",
                row.0, row.1, row.2, row.3, root.0, root.1, root.2, root.3
            );
            assert!(
                row.0 <= b_row,
                "{set:?}, {path}: {:.2} contacts per row",
                row.0
            );
            assert!(
                root.0 <= b_root,
                "{set:?}, {path}: {:.2} in K's search",
                root.0
            );
        }
    }
}
