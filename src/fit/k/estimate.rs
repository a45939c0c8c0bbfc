//! The entry point of the K inversion: the launch-speed path where it applies, the search in K
//! elsewhere.

use super::launch;
use super::search::estimate_in_k_or;
use super::types::KEstimate;
use crate::models::Model;
use crate::scene::Scene;

/// K, its interval at v ± σ, dv̄/dK and diagnostics for one measurement (eq 69).
pub fn estimate(model: &Model, scene: &Scene, v: f64, sigma_v: Option<f64>) -> KEstimate {
    // Stick and stick/slip with Θ0 < 0: solve in the launch speed (no fixed point inside).
    if let Some(e) = launch::estimate(model, scene, v, sigma_v) {
        return e;
    }
    // Stick with Θ0 > 0: the same in w0², on the general search's bracket.
    estimate_in_k_or(model, scene, v, sigma_v, |scene, br| {
        launch::estimate_past_top(model, scene, br, v, sigma_v)
    })
}
