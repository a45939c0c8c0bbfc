//! Regime limits and derived quantities of the rolling model: δ_m (eq 32), δ_d (eq 31), the
//! smallest ξ with a steady regime, Θ_G (eq 36), H (eq 35) and the bulk friction μ (eq 79).

use super::{ForwardModel, Model};
use crate::scene::{CollisionLaw, Scene};
use crate::special::root::brent;

/// Lower limit of the steady regime, δ_m = 2 atan(tan(α/2) (1−K)/(1+K)) (eq 32), radians
/// (the tests' form at a given K; [`delta_m_law`] is the library's).
#[cfg(test)]
pub(crate) fn delta_m(alpha: f64, k: f64) -> f64 {
    delta_m_of(alpha, k, 1.0 - k)
}

/// Upper limit (lift-off at Θf), δ_d = atan((1+ρ)(1−K²) / (tan α (4 + (1+ρ)(1−K²)))) (eq 31),
/// radians.
pub(crate) fn delta_d(alpha: f64, k: f64, rho: f64) -> f64 {
    delta_d_of(alpha, k, 1.0 - k, rho)
}

/// Bulk friction of the rolling model, μ = lim_{v→0} tan δ
/// = (1 − K²) sin α / ((1 + K²) cos α + 2K) (eqs 78–79). Equals tan δ_m exactly.
pub(crate) fn bulk_friction(alpha: f64, k: f64) -> f64 {
    bulk_friction_of(alpha, k, 1.0 - k)
}

/// δ_m (eq 32) for a collision law at α and ρ, with 1 − K from
/// [`CollisionLaw::one_minus_k`]: for a named law it keeps its relative accuracy as ξ → ∞,
/// where 1 − K ≈ 2 sin²α and the 1 − K of a double K would cost about u/(2 sin²α).
pub fn delta_m_law(alpha: f64, law: CollisionLaw, rho: f64) -> f64 {
    delta_m_of(alpha, law.k(alpha, rho), law.one_minus_k(alpha, rho))
}

/// δ_d (eq 31) for a collision law at α and ρ (1 − K as in [`delta_m_law`]).
pub fn delta_d_law(alpha: f64, law: CollisionLaw, rho: f64) -> f64 {
    delta_d_of(alpha, law.k(alpha, rho), law.one_minus_k(alpha, rho), rho)
}

/// The bulk friction (eq 79) for a collision law at α and ρ (1 − K as in [`delta_m_law`]).
pub fn bulk_friction_law(alpha: f64, law: CollisionLaw, rho: f64) -> f64 {
    bulk_friction_of(alpha, law.k(alpha, rho), law.one_minus_k(alpha, rho))
}

/// Eq 32 with K and 1 − K given separately.
fn delta_m_of(alpha: f64, k: f64, omk: f64) -> f64 {
    2.0 * ((0.5 * alpha).tan() * omk / (1.0 + k)).atan()
}

/// Eq 31 with K and 1 − K given separately.
fn delta_d_of(alpha: f64, k: f64, omk: f64, rho: f64) -> f64 {
    let c = (1.0 + rho) * omk * (1.0 + k);
    (c / (alpha.tan() * (4.0 + c))).atan()
}

/// Eq 79 with K and 1 − K given separately.
fn bulk_friction_of(alpha: f64, k: f64, omk: f64) -> f64 {
    omk * (1.0 + k) * alpha.sin() / ((1.0 + k * k) * alpha.cos() + 2.0 * k)
}

/// The K whose stop limit δ_m is `delta` at contact angle `alpha` (eq 32 solved for K):
/// K = (1 − t)/(1 + t) with t = tan(δ/2)/tan(α/2). Negative when δ > α (no K > 0 stops the
/// bead there). Radians.
pub(crate) fn k_at_delta_m(alpha: f64, delta: f64) -> f64 {
    let t = (0.5 * delta).tan() / (0.5 * alpha).tan();
    (1.0 - t) / (1.0 + t)
}

/// The K whose lift-off limit δ_d is `delta` (eq 31 solved for K):
/// K² = 1 − 4u/((1 − u)(1 + ρ)) with u = tan δ tan α; `None` when no K > 0 has δ_d = δ
/// (the bead lifts off at this slope whatever K). Radians.
pub(crate) fn k_at_delta_d(alpha: f64, delta: f64, rho: f64) -> Option<f64> {
    let u = delta.tan() * alpha.tan();
    if u >= 1.0 {
        return None;
    }
    let c = 4.0 * u / (1.0 - u);
    let k2 = 1.0 - c / (1.0 + rho);
    (k2 > 0.0).then(|| k2.sqrt())
}

/// α = asin(1/(1+ξ)) (eq 2).
pub fn alpha_of_xi(xi: f64) -> f64 {
    (1.0 / (1.0 + xi)).asin()
}

/// δ_m and δ_d (radians) at radius ratio ξ for a collision law ([`delta_m_law`],
/// [`delta_d_law`]).
pub(crate) fn limits(xi: f64, law: CollisionLaw, rho: f64) -> (f64, f64) {
    let a = alpha_of_xi(xi);
    (delta_m_law(a, law, rho), delta_d_law(a, law, rho))
}

/// Smallest ξ with a steady regime (δ_m < δ_d) for a law, where δ_m(ξ) = δ_d(ξ); `None` if the
/// limits do not cross for ξ in [1e-4, 1e4]. The paper quotes ≈ 0.62 for its fitted law.
pub fn critical_xi(law: CollisionLaw, rho: f64) -> Option<f64> {
    let h = |lx: f64| {
        let (m, d) = limits(lx.exp(), law, rho);
        d - m
    };
    // Scan in log ξ for the first sign change from below (no steady regime) to above.
    let n = 400;
    let (lo, hi) = ((1e-4f64).ln(), (1e4f64).ln());
    let mut x0 = lo;
    let mut f0 = h(x0);
    for i in 1..=n {
        let x1 = lo + (hi - lo) * i as f64 / n as f64;
        let f1 = h(x1);
        if f0 < 0.0 && f1 >= 0.0 {
            let r = brent(h, x0, x1, f0, f1, 1e-15, 200)?;
            return Some(r.x.exp());
        }
        x0 = x1;
        f0 = f1;
    }
    None
}

/// ϑ = 2 cos Θ0 + (1+ρ) Θ̇0² (eq 36).
#[inline]
pub(crate) fn vartheta(scene: &Scene, w0sq: f64) -> f64 {
    2.0 * scene.sc_0.c + (1.0 + scene.rho) * w0sq
}

/// Θ_G: the angle where rolling from Θ0 with squared speed `w0sq` first needs more friction
/// than f (eq 36), radians, in the rationalised form that keeps its digits as f → 0:
/// tan(Θ_G/2) = f (3+ρ−ϑ) / (ρ + sqrt(ρ² + f² ((3+ρ)² − ϑ²))) (docs/PHYSICS.md#friction-demand).
/// `None` when no real Θ_G exists ((3+ρ)² < ϑ²: the normal force is negative everywhere), or
/// when ρ = f = 0 (no friction is ever needed).
pub(crate) fn theta_g(scene: &Scene, w0sq: f64) -> Option<f64> {
    theta_g_of(scene.rho, scene.f, vartheta(scene, w0sq))
}

/// Θ_G of a rolling phase with energy invariant ϑ = 2 cos Θa + (1+ρ) Θ̇a² (eq 36, rationalised
/// as in [`theta_g`]): the angle > 0 where H = T/N reaches f; `None` when N < 0 on the whole
/// bead.
pub(crate) fn theta_g_of(rho: f64, f: f64, th: f64) -> Option<f64> {
    let p = 3.0 + rho;
    let disc = rho * rho + f * f * (p - th) * (p + th);
    if disc < 0.0 || p - th < 0.0 {
        return None;
    }
    // Beyond f = 1e150 f² overflows: divided through by f > 0, the tangent is
    // (p − ϑ)/(ρ/f + √((p − ϑ)(p + ϑ) + (ρ/f)²)).
    if f > 1e150 {
        let r = rho / f;
        let den = r + ((p - th) * (p + th) + r * r).sqrt();
        return (den != 0.0).then(|| 2.0 * ((p - th) / den).atan());
    }
    let den = rho + disc.sqrt();
    if den == 0.0 {
        return None;
    }
    Some(2.0 * (f * (p - th) / den).atan())
}

/// The longest run of `true` in `flags` as [start, end) indices; `None` when there is none.
pub(crate) fn longest_run(flags: &[bool]) -> Option<(usize, usize)> {
    let (mut best, mut cur): ((usize, usize), Option<usize>) = ((0, 0), None);
    for i in 0..=flags.len() {
        let f = i < flags.len() && flags[i];
        match (f, cur) {
            (true, None) => cur = Some(i),
            (false, Some(s)) => {
                if i - s > best.1 - best.0 {
                    best = (s, i);
                }
                cur = None;
            }
            _ => {}
        }
    }
    (best.1 > best.0).then_some(best)
}

/// Spacing (radians) of the scan of [`regime_b_interval`]: 89° over 2000.
pub(crate) const REGIME_B_SCAN_STEP: f64 = 89.0 * std::f64::consts::PI / 180.0 / 2000.0;

/// The slopes (radians) where `model` has a steady state at this ξ: the longest run of a
/// 2000-point scan of (0°, 89°), its ends refined by bisection to 1e-12 rad.
pub fn regime_b_interval(
    model: &Model,
    xi: f64,
    rho: f64,
    f: f64,
    law: CollisionLaw,
) -> Option<(f64, f64)> {
    let ok = |d: f64| {
        Scene::from_radians(xi, d, rho, f, law)
            .map(|s| model.evaluate(&s).is_ok())
            .unwrap_or(false)
    };
    let n = 2000;
    let top = 89f64.to_radians();
    let grid: Vec<f64> = (1..n).map(|i| top * i as f64 / n as f64).collect();
    let flags: Vec<bool> = grid.iter().map(|&d| ok(d)).collect();
    let best = longest_run(&flags)?;
    let bisect = |mut good: f64, mut bad: f64| {
        for _ in 0..60 {
            let m = 0.5 * (good + bad);
            if ok(m) {
                good = m
            } else {
                bad = m
            }
            if (good - bad).abs() < 1e-12 {
                break;
            }
        }
        good
    };
    let lo = if best.0 == 0 {
        grid[0]
    } else {
        bisect(grid[best.0], grid[best.0 - 1])
    };
    let hi = if best.1 >= grid.len() {
        grid[grid.len() - 1]
    } else {
        bisect(grid[best.1 - 1], grid[best.1])
    };
    Some((lo, hi))
}
