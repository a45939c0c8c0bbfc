//! What the timing examples share.

use std::time::Instant;

/// The best of three runs of `f`, in seconds.
pub fn best_of_three(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}
