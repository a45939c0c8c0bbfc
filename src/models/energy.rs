//! Energy per row bead in the steady state (§4.6, eqs 70–72; docs/PHYSICS.md#energy-per-bead), in
//! units of m g (R + r): the potential drop 2 sin α sin δ equals the collision loss (translation
//! and spin) plus the friction work.

use super::slip::SlipPhase;
use super::stick;
use super::stickslip::{map, Branch};
use super::{NotSteady, Steady};
use crate::scene::Scene;
use crate::special::quad::{integrate, QuadOptions};

/// Energy partition of one steady contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyPartition {
    /// Potential drop per bead, 2 sin α sin δ.
    pub potential_drop: f64,
    /// Translational kinetic energy lost at the collision, ½ (1 − K²) Θ̇f².
    pub collision_translation: f64,
    /// Spin kinetic energy lost at the collision (rolling restarts: spin → K Θ̇f).
    pub collision_spin: f64,
    /// Work of the sliding friction during the contact.
    pub friction_work: f64,
}

impl EnergyPartition {
    /// Relative closure (potential drop − losses)/potential drop; zero up to round-off.
    pub fn closure(&self) -> f64 {
        (self.potential_drop
            - self.collision_translation
            - self.collision_spin
            - self.friction_work)
            / self.potential_drop
    }

    /// Ratio of the collision loss to the potential drop (eq 70; 1 for rolling, eq 71).
    pub fn collision_fraction(&self) -> f64 {
        (self.collision_translation + self.collision_spin) / self.potential_drop
    }
}

/// Partition for pure rolling: no friction work, collision loss ½ (1+ρ)(1 − K²) L² (eq 70).
pub(crate) fn rolling(scene: &Scene, s: &Steady) -> EnergyPartition {
    let l2 = s.final_velocity * s.final_velocity;
    let omk2 = scene.one_minus_k2();
    EnergyPartition {
        potential_drop: 2.0 * scene.sin_delta_sin_alpha(),
        collision_translation: 0.5 * omk2 * l2,
        collision_spin: 0.5 * scene.rho * omk2 * l2,
        friction_work: 0.0,
    }
}

/// Partition for the stick/slip steady state `s`. The spin Ψ = ω/ε at Θf comes from
/// ρ Ψ̇ = f N = sin Θ − Θ̈ (eqs 37, 43), i.e. ρ (Ψf − Ψ_G) = ∫ sin θ dθ/Θ̇ − (Θ̇f − Θ̇_G);
/// the friction work W = ∫ f N (Θ̇ − Ψ) dt is integrated on its own (nested quadrature), so the
/// closure of the balance is a genuine check of the fixed point, the phases and both integrals.
pub(crate) fn stickslip(scene: &Scene, s: &Steady) -> Result<EnergyPartition, NotSteady> {
    let x = s.final_velocity;
    let step = map(scene, x)?;
    let w0sq = scene.k * scene.k * x * x;
    let drop = 2.0 * scene.sin_delta_sin_alpha();
    let omk2 = scene.one_minus_k2();
    let rolling_spin =
        |spin_f: f64| 0.5 * scene.rho * (spin_f * spin_f - scene.k * scene.k * x * x);
    let (ts, ws_sq) = match step.branch {
        Branch::NoSlip => {
            return Ok(EnergyPartition {
                potential_drop: drop,
                collision_translation: 0.5 * omk2 * x * x,
                collision_spin: rolling_spin(x),
                friction_work: 0.0,
            })
        }
        Branch::SlipFromStart => (scene.theta_0, w0sq),
        Branch::RollSlip => {
            let tg = step.theta_g;
            (
                tg,
                stick::rolling_speed_sq(scene.b, scene.theta_0, w0sq, tg),
            )
        }
    };
    if scene.rho == 0.0 {
        return Err(NotSteady::Invalid {
            reason: "slip with rho = 0 has no spin dynamics",
        });
    }
    let ph = SlipPhase::new(ts, ws_sq, scene.f);
    let opts = QuadOptions {
        rel_tol: 1e-15,
        abs_tol: 1e-17,
        max_panels: 200,
    };
    let wg = ws_sq.sqrt();
    // Spin at θ (Ψ = Θ̇ at the slip onset: rolling before it; after a collision restart when
    // slipping from the start).
    let spin = |th: f64| {
        let s_int = integrate(|u: f64| u.sin() / ph.speed_sq(u).sqrt(), ts, th, opts).value;
        wg + (s_int - (ph.speed_sq(th).sqrt() - wg)) / scene.rho
    };
    let spin_f = spin(scene.theta_f);
    // W = ∫ f N (Θ̇ − Ψ) dθ / Θ̇, N = cos θ − Θ̇².
    let work = integrate(
        |th: f64| {
            let v2 = ph.speed_sq(th);
            let v = v2.sqrt();
            scene.f * (th.cos() - v2) * (v - spin(th)) / v
        },
        ts,
        scene.theta_f,
        QuadOptions {
            rel_tol: 1e-14,
            abs_tol: 1e-18,
            max_panels: 64,
        },
    )
    .value;
    Ok(EnergyPartition {
        potential_drop: drop,
        collision_translation: 0.5 * omk2 * x * x,
        collision_spin: rolling_spin(spin_f),
        friction_work: work,
    })
}
