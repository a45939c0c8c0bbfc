//! Pure rolling ("stick" model, §3): exact closed form and the asinh approximation (eq 29).

use super::{NotSteady, Outcome, Phases, Steady};
use crate::scene::Scene;
use crate::special::dd::Dd;
use crate::special::elliptic::{cos_integral, cos_integral_pair};

/// Steady final velocity squared L² = 4 sin δ sin α / ((1+ρ)(1−K²)) (eq 19).
#[inline]
pub(crate) fn final_velocity_sq(scene: &Scene) -> f64 {
    scene.b * 2.0 * scene.sin_delta_sin_alpha() / scene.one_minus_k2()
}

/// P = sin(Θ0/2) + K sin(Θf/2) = cos(δ/2) cos(α/2) [(1+K) tan(δ/2) − (1−K) tan(α/2)]:
/// the factor of the squared top velocity that vanishes at δ = δ_m (eq 32). The bracket is
/// recomputed in double-double when it cancels, so P keeps its relative accuracy for δ as close
/// to δ_m as the double inputs allow; 1 − K comes from [`Scene::one_minus_k`] (exact for a
/// number K, from sin²α for a named law).
pub(crate) fn lower_limit_factor(scene: &Scene) -> f64 {
    let k = scene.k;
    let omk = scene.one_minus_k();
    let (sd, cd) = (scene.sc_half_delta.s, scene.sc_half_delta.c);
    let ta = scene.tan_half_alpha.to_f64();
    let td = sd / cd;
    let up = (1.0 + k) * td;
    let mut bracket = up - omk * ta;
    if bracket.abs() < 1e-3 * up.abs() {
        bracket = lower_limit_bracket_dd(scene, omk);
    }
    cd * scene.sc_half_alpha.c * bracket
}

/// The bracket (1+K) tan(δ/2) − (1−K) tan(α/2) of [`lower_limit_factor`] in double-double,
/// with 1 − K exact for a number K and `omk` (relative error ~u) for a named law.
#[cold]
#[inline(never)]
fn lower_limit_bracket_dd(scene: &Scene, omk: f64) -> f64 {
    let tan_half_delta = match scene.tan_half_delta.0 {
        Some(t) => t,
        None => Dd::tan_half(scene.delta),
    };
    let one = Dd::from(1.0);
    let kd = Dd::from(scene.k);
    let omk = if scene.law.is_value() {
        one - kd
    } else {
        Dd::from(omk)
    };
    ((one + kd) * tan_half_delta - omk * scene.tan_half_alpha).to_f64()
}

/// Squared velocity at the top Θ = 0 in the steady rolling state:
/// Θ̇_top² = A − B = 2B (K sin(Θf/2) + sin(Θ0/2)) (K sin(Θf/2) − sin(Θ0/2)) / (1 − K²)
/// (eq 9 at Θ = 0 with eqs 19–20, factored so that no digits cancel).
pub(crate) fn top_velocity_sq(scene: &Scene) -> f64 {
    let p = lower_limit_factor(scene);
    let q = scene.k * scene.sc_half_f.s - scene.sc_half_0.s;
    2.0 * scene.b * p * q / scene.one_minus_k2()
}

/// Angle where a bead rolling up from Θ0 with squared speed `w0sq` stops (Θ̇ = 0), from
/// sin²(Θ/2) = sin²(Θ0/2) − Θ̇0²/(2B) (eq 9).
pub(crate) fn stop_angle(scene: &Scene, w0sq: f64) -> f64 {
    let s0 = scene.sc_half_0.s;
    let r = (s0 * s0 - w0sq / (2.0 * scene.b)).max(0.0).sqrt();
    -2.0 * r.min(1.0).asin()
}

struct RollingState {
    l2: f64,
    w0sq: f64,
    wtsq: f64,
}

fn rolling_state(scene: &Scene) -> Result<RollingState, NotSteady> {
    if scene.k >= 1.0 {
        return Err(NotSteady::Runaway);
    }
    let l2 = final_velocity_sq(scene);
    let w0sq = scene.k * scene.k * l2;
    let wtsq = top_velocity_sq(scene);
    if scene.theta_0 < 0.0 && wtsq <= 0.0 || l2 == 0.0 {
        return Err(NotSteady::Stops {
            angle: stop_angle(scene, w0sq),
        });
    }
    if scene.sc_f.c - l2 < 0.0 {
        return Err(NotSteady::LiftOff {
            angle: scene.theta_f,
        });
    }
    Ok(RollingState { l2, w0sq, wtsq })
}

/// The steady rolling velocities (L = Θ̇f, K L = Θ̇0; eq 19) when the rolling steady state
/// exists (the same checks as [`steady`], without its contact time).
pub(crate) fn rolling_velocities(scene: &Scene) -> Result<(f64, f64), NotSteady> {
    let st = rolling_state(scene)?;
    Ok((st.l2.sqrt(), st.w0sq.sqrt()))
}

/// Steady pure rolling, exact: τ = ∫_{Θ0}^{Θf} dθ / sqrt(A − B cos θ) (eq 11) in Carlson's form
/// (see [`cos_integral`]; equal to eqs 21–27 as corrected in
/// docs/PHYSICS.md#corrections-to-the-printed-paper), v̄ = 2 sin α / τ (eq 27).
pub fn steady(scene: &Scene) -> Outcome {
    let st = rolling_state(scene)?;
    let tau = cos_integral(
        scene.sc_half_0,
        scene.sc_half_f,
        st.w0sq,
        st.l2,
        st.wtsq,
        scene.sin_delta_sin_alpha(),
    );
    rolled(scene, &st, tau)
}

/// [`steady`] at two scenes that differ only in K (copies of one scene by
/// [`Scene::with_k`]), each to the last bit: the R_F of their contact times run side by side
/// ([`cos_integral_pair`]).
pub(crate) fn steady_pair(a: &Scene, b: &Scene) -> [Outcome; 2] {
    match (rolling_state(a), rolling_state(b)) {
        (Ok(sa), Ok(sb)) => {
            let tau = cos_integral_pair(
                a.sc_half_0,
                a.sc_half_f,
                [sa.w0sq, sa.l2, sa.wtsq],
                [sb.w0sq, sb.l2, sb.wtsq],
                a.sin_delta_sin_alpha(),
            );
            [rolled(a, &sa, tau[0]), rolled(b, &sb, tau[1])]
        }
        _ => [steady(a), steady(b)],
    }
}

/// The steady state of the rolling state `st` with contact time `tau`.
fn rolled(scene: &Scene, st: &RollingState, tau: f64) -> Outcome {
    if !(tau.is_finite() && tau > 0.0) {
        return Err(NotSteady::Invalid {
            reason: "rolling time not finite",
        });
    }
    let l = st.l2.sqrt();
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, l, scene.k * l, tau);
    s.top_velocity_sq = Some(st.wtsq);
    s.map_slope = Some(scene.k * scene.k);
    s.phases = Phases::Roll;
    Ok(s)
}

/// Steady pure rolling with the paper's approximation F(Ω, k) ≈ asinh(tan Ω) (eqs 28–29):
/// τ̃ = γ [asinh(tan Ω_f) − sgn(Θ0) asinh(tan Ω(|Θ0|))], γ = 2/sqrt(A+B),
/// tan Ω(Θ) = sqrt(A+B) |sin(Θ/2)| / (Θ̇_top cos(Θ/2)) (eq 14 corrected). Needs A > B.
pub fn steady_approx(scene: &Scene) -> Outcome {
    let st = rolling_state(scene)?;
    if st.wtsq <= 0.0 {
        return Err(NotSteady::Invalid {
            reason: "asinh approximation needs A > B (eq 28)",
        });
    }
    let apb = st.wtsq + 2.0 * scene.b;
    let root = apb.sqrt();
    let wt = st.wtsq.sqrt();
    let t = |h: crate::scene::SinCos| (root * h.s.abs() / (wt * h.c)).asinh();
    let sgn0 = if scene.sc_half_0.s < 0.0 { 1.0 } else { -1.0 };
    let tau = 2.0 / root * (t(scene.sc_half_f) + sgn0 * t(scene.sc_half_0));
    if !(tau.is_finite() && tau > 0.0) {
        return Err(NotSteady::Invalid {
            reason: "approximate rolling time not positive",
        });
    }
    let l = st.l2.sqrt();
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, l, scene.k * l, tau);
    s.top_velocity_sq = Some(st.wtsq);
    s.phases = Phases::Roll;
    Ok(s)
}

/// Squared speed at θ of a bead rolling from Θa with squared speed `wa_sq`:
/// Θ̇² = Θ̇a² + B (cos Θa − cos θ) (eq 9), with the difference in product form
/// 2B sin((θ+Θa)/2) sin((θ−Θa)/2) so that θ near Θa keeps its digits.
#[inline]
pub(crate) fn rolling_speed_sq(b: f64, theta_a: f64, wa_sq: f64, theta: f64) -> f64 {
    wa_sq + 2.0 * b * (0.5 * (theta + theta_a)).sin() * (0.5 * (theta - theta_a)).sin()
}

/// Time to roll from Θa to Θb (Θa ≤ Θb, both on the row bead) starting with squared speed
/// `wa_sq` at Θa; `None` if the bead stops before Θb. Used by the stick/slip model.
pub(crate) fn rolling_time(b: f64, theta_a: f64, theta_b: f64, wa_sq: f64) -> Option<f64> {
    let sa = (0.5 * theta_a).sin();
    rolling_time_top(b, theta_a, theta_b, wa_sq, wa_sq - 2.0 * b * sa * sa)
}

/// [`rolling_time`] with the squared speed at the top, `wt_sq` = Θ̇a² − 2B sin²(Θa/2), given by
/// the caller (who may know it without the cancellation of that difference).
pub(crate) fn rolling_time_top(
    b: f64,
    theta_a: f64,
    theta_b: f64,
    wa_sq: f64,
    wt_sq: f64,
) -> Option<f64> {
    use crate::special::SinCos;
    let ha = SinCos::of(0.5 * theta_a);
    let hb = SinCos::of(0.5 * theta_b);
    // Θ̇² = Θ̇a² + B (cos Θa − cos θ) = Θ̇a² + 2B (sin²(θ/2) − sin²(Θa/2)).
    let den = (0.5 * (theta_b + theta_a)).sin() * (0.5 * (theta_b - theta_a)).sin();
    let wb_sq = wa_sq + 2.0 * b * den;
    if wb_sq < 0.0 || (theta_a < 0.0 && theta_b > 0.0 && wt_sq <= 0.0) {
        return None;
    }
    Some(cos_integral(ha, hb, wa_sq, wb_sq, wt_sq, den))
}
