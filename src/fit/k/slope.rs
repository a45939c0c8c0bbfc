//! K of a measurement whose slope carries a standard uncertainty σ_δ.
//!
//! The slope's error is carried to first order as an equivalent error of the velocity:
//! σ_eff² = σ_v² + (∂v̄/∂δ · σ_δ)², with ∂v̄/∂δ taken at the measurement's K (eq 69) and the
//! model's steady state, by a central difference in δ. K_lo and K_hi are then the exact
//! inverses at v ∓ σ_eff (the same inversion as for σ_v alone, so the interval keeps the
//! curvature of v̄ in K), and σ_K = σ_eff / |dv̄/dK|.
//!
//! That is the effective variance of orthogonal distance regression for one point (Boggs,
//! Byrd & Schnabel 1987), which the fits use with σ_δ; the test beside the inversion's
//! (`k_with_slope_errors_spreads_as_draws`) holds σ_K and the interval against the spread of K
//! over draws of (v̄, δ), each inverted exactly.

use super::auto::{estimate_with, KChoice};
use super::types::KEstimate;
use crate::models::auto::Auto;
use crate::models::{ForwardModel, Model};
use crate::scene::Scene;

/// Step of the central difference of v̄ in δ, radians (5.7e-4°). The steady state is computed
/// to about 1e-13 relative, so the difference carries about 1e-8 of relative rounding error;
/// the truncation error is of order h² v̄'''/6, far smaller away from the regime ends.
const H_DELTA: f64 = 1e-5;

/// K of one measurement, its interval and σ_K, with the slope's standard uncertainty
/// `sigma_delta` (radians, 0 for an exact slope) carried as in the module docs. The third
/// value is σ_K: `None` where there is no K, no dv̄/dK, no σ at all, or where v̄ has no
/// steady state on either side of the slope.
pub(crate) fn estimate_with_slope(
    model: &Model,
    auto: Option<&Auto>,
    scene: &Scene,
    v: f64,
    sigma_v: Option<f64>,
    sigma_delta: f64,
) -> (KEstimate, Option<KChoice>, Option<f64>) {
    let (e, choice) = estimate_with(model, auto, scene, v, sigma_v);
    let Ok(root) = e.root.as_ref() else {
        return (e, choice, None);
    };
    let Some(dv_dk) = e.dv_dk.filter(|d| *d != 0.0 && d.is_finite()) else {
        return (e, choice, None);
    };
    if sigma_delta == 0.0 {
        let sigma_k = sigma_v.map(|s| s / dv_dk.abs());
        return (e, choice, sigma_k);
    }
    let used = choice.as_ref().map_or(model, |c| &c.model);
    let Some(slope) = dv_ddelta(used, scene, root.k) else {
        return (e, choice, None);
    };
    let sigma_eff = sigma_v.unwrap_or(0.0).hypot(slope * sigma_delta);
    if !(sigma_eff > 0.0 && sigma_eff.is_finite()) {
        return (e, choice, sigma_v.map(|s| s / dv_dk.abs()));
    }
    let wide = super::estimate(used, scene, v, Some(sigma_eff));
    let e = KEstimate {
        k_lo: wide.k_lo,
        k_hi: wide.k_hi,
        notes: wide.notes,
        ..e
    };
    (e, choice, Some(sigma_eff / dv_dk.abs()))
}

/// ∂v̄/∂δ (per radian) of `model` at `scene`'s slope with K held at `k`: the central
/// difference over ±[`H_DELTA`], or the one-sided one where only one side is steady.
pub(crate) fn dv_ddelta(model: &Model, scene: &Scene, k: f64) -> Option<f64> {
    let at = scene.with_k(k).ok()?;
    let d = at.delta_rad();
    let v = |delta: f64| {
        at.with_delta(delta)
            .ok()
            .and_then(|s| model.evaluate(&s).ok())
            .map(|s| s.mean_velocity)
            .filter(|v| v.is_finite())
    };
    match (v(d - H_DELTA), v(d + H_DELTA)) {
        (Some(a), Some(b)) => Some((b - a) / (2.0 * H_DELTA)),
        (None, Some(b)) => v(d).map(|m| (b - m) / H_DELTA),
        (Some(a), None) => v(d).map(|m| (m - a) / H_DELTA),
        (None, None) => None,
    }
}
