//! Scenes drawn at random across regime B for rolling, hard cases included (near the stop
//! limit δ_m, near Θ0 = 0, near the lift-off limit δ_d), reproducible from a seed: the
//! work-precision bench's scenes and the models' own tests.

use crate::models::regimes::{alpha_of_xi, delta_d, k_at_delta_d, k_at_delta_m};
use crate::models::stick;
use crate::scene::{CollisionLaw, Scene};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// How a scene was drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Draw {
    /// K uniform inside its feasible range.
    Ordinary,
    /// K within 1e-9…1e-3 (relative to the range) of the stop limit δ = δ_m (eq 32).
    NearDeltaM,
    /// δ within a relative 1e-8…1e-2 of α: Θ0 ≈ 0.
    NearTheta0,
    /// K within 1e-9…1e-3 of the lift-off limit δ = δ_d (eq 31).
    NearKLimit,
}

/// Draws `n` scenes of regime B for rolling (ξ ∈ [0.65, 10] log-uniform, ρ ∈ {0.4, 0.5},
/// f ∈ [0.01, 0.5] log-uniform, K inside (K at δ_m, K at δ_d)), reproducible from `seed`.
pub fn draw_scenes(n: usize, seed: u64) -> Vec<(Scene, Draw)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n);
    let logu = |rng: &mut ChaCha8Rng, a: f64, b: f64| (rng.random_range(a.ln()..b.ln())).exp();
    for i in 0..n {
        let draw = match i % 10 {
            7 => Draw::NearDeltaM,
            8 => Draw::NearTheta0,
            9 => Draw::NearKLimit,
            _ => Draw::Ordinary,
        };
        for _ in 0..100_000 {
            let xi = logu(&mut rng, 0.65, 10.0);
            let rho = if rng.random_bool(0.5) { 0.4 } else { 0.5 };
            let f = logu(&mut rng, 0.01, 0.5);
            let alpha = alpha_of_xi(xi);
            let delta = match draw {
                Draw::NearTheta0 => {
                    let s = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                    alpha * (1.0 + s * logu(&mut rng, 1e-8, 1e-2))
                }
                _ => rng.random_range(0.1f64..45.0).to_radians(),
            };
            let k_m = k_at_delta_m(alpha, delta).max(0.0);
            let Some(k_d) = k_at_delta_d(alpha, delta, rho) else {
                continue;
            };
            if k_d <= k_m || (draw == Draw::NearDeltaM && k_m <= 0.0) {
                continue;
            }
            let frac = match draw {
                Draw::NearDeltaM => logu(&mut rng, 1e-9, 1e-3),
                Draw::NearKLimit => 1.0 - logu(&mut rng, 1e-9, 1e-3),
                _ => rng.random_range(0.01..0.99),
            };
            let k = k_m + frac * (k_d - k_m);
            let Ok(scene) = Scene::from_radians(xi, delta, rho, f, CollisionLaw::Value(k)) else {
                continue;
            };
            debug_assert!(delta < delta_d(alpha, k, rho) * (1.0 + 1e-9));
            if stick::steady(&scene).is_ok() {
                out.push((scene, draw));
                break;
            }
        }
    }
    out
}
