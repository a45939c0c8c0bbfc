//! Pure rolling by quadrature: the contact time of eq 11,
//! τ = ∫_{Θ0}^{Θf} dθ / sqrt(A − B cos θ), integrated numerically at a chosen relative
//! tolerance instead of through the elliptic closed form (eqs 12–15 corrected).
//!
//! The steady state itself (eqs 17–20) is the stick model's; only τ differs. Near the lower
//! regime limit A − B → 0 and the integrand peaks sharply at the top Θ = 0, where
//! Θ̇² = Θ̇t² + 2B sin²(θ/2) with Θ̇t² = A − B the squared top velocity. When the contact
//! crosses the top, each side of it is integrated in θ = h sinh t with h = Θ̇t·sqrt(2/B), which
//! turns the peak 1/sqrt(Θ̇t² + Bθ²/2) into a smooth integrand (the same device as the slip
//! model's time integral).

use super::stick;
use super::{NotSteady, Outcome, Phases, Steady};
use crate::scene::Scene;
use crate::special::quad::{integrate, QuadOptions};

/// Contact time of eq 11 from Θ0 to Θf at launch velocity² `w0sq` and top velocity² `wtsq`
/// (= w0sq − 2B sin²(Θ0/2)), by adaptive Gauss–Kronrod quadrature at relative tolerance
/// `tol` (at most 256 panels per side). `None` when the integrand is not positive.
pub(crate) fn rolling_time_quad(scene: &Scene, w0sq: f64, wtsq: f64, tol: f64) -> Option<f64> {
    let b = scene.b;
    let (t0, tf) = (scene.theta_0, scene.theta_f);
    let opts = QuadOptions {
        rel_tol: tol,
        abs_tol: 0.0,
        max_panels: 256,
    };
    let tau = if t0 < 0.0 && tf > 0.0 {
        if !(wtsq > 0.0) {
            return None;
        }
        // Θ̇² = Θ̇t² + 2B sin²(θ/2) (eq 9 written about the top); θ = h sinh t.
        let h = (2.0 * wtsq / b).sqrt();
        let side = |end: f64| {
            let tmax = (end / h).asinh();
            integrate(
                |t: f64| {
                    let th = h * t.sinh();
                    let s = (0.5 * th).sin();
                    h * t.cosh() / (wtsq + 2.0 * b * s * s).sqrt()
                },
                0.0,
                tmax,
                opts,
            )
            .value
        };
        side(-t0) + side(tf)
    } else {
        integrate(
            |th: f64| {
                let g = stick::rolling_speed_sq(b, t0, w0sq, th);
                if g > 0.0 {
                    1.0 / g.sqrt()
                } else {
                    f64::INFINITY
                }
            },
            t0,
            tf,
            opts,
        )
        .value
    };
    (tau.is_finite() && tau > 0.0).then_some(tau)
}

/// The stick model's steady state (eqs 17–20) with the contact time of eq 11 by quadrature at
/// relative tolerance `tol`.
pub fn steady_quad(scene: &Scene, tol: f64) -> Outcome {
    if scene.k >= 1.0 {
        return Err(NotSteady::Runaway);
    }
    let l2 = stick::final_velocity_sq(scene); // eq 19
    let w0sq = scene.k * scene.k * l2; // eq 20
    let wtsq = stick::top_velocity_sq(scene);
    if scene.theta_0 < 0.0 && wtsq <= 0.0 || l2 == 0.0 {
        return Err(NotSteady::Stops {
            angle: stick::stop_angle(scene, w0sq),
        });
    }
    if scene.sc_f.c - l2 < 0.0 {
        return Err(NotSteady::LiftOff {
            angle: scene.theta_f,
        });
    }
    let Some(tau) = rolling_time_quad(scene, w0sq, wtsq, tol) else {
        return Err(NotSteady::Invalid {
            reason: "rolling time by quadrature not finite",
        });
    };
    let l = l2.sqrt();
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, l, scene.k * l, tau);
    s.top_velocity_sq = Some(wtsq);
    s.map_slope = Some(scene.k * scene.k);
    s.phases = Phases::Roll;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::CollisionLaw;

    #[test]
    fn quadrature_matches_the_elliptic_closed_form() {
        // The checked scene of docs/PHYSICS.md#reference-figures: ξ = 1, δ = 12°, ρ = 0.4, fitted
        // K.
        let s = Scene::new(1.0, 12.0, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
        let exact = stick::steady(&s).unwrap().mean_velocity;
        let q = steady_quad(&s, 1e-15).unwrap().mean_velocity;
        assert!((q - exact).abs() < 1e-14 * exact, "{q} {exact}");
        assert!((exact - 0.39120827).abs() < 1e-8);
        // Past the top (Θ0 > 0) the plain integrand is used.
        let s = Scene::new(1.0, 40.0, 0.4, 0.1, CollisionLaw::Value(0.3)).unwrap();
        if let Ok(e) = stick::steady(&s) {
            let q = steady_quad(&s, 1e-15).unwrap().mean_velocity;
            assert!((q - e.mean_velocity).abs() < 1e-14 * q);
        }
    }
}
