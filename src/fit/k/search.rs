//! Eq 69 solved in K by Brent's method in s = ln(K − K_min) (module docs of [`super`]), K_lo
//! and K_hi at v ∓ σ, and dv̄/dK over the evaluated K values.

use super::bracket::{bracket, eval};
use super::types::{KBracket, KEstimate, KFailure, KRoot, LowerLimit};
use crate::models::regimes::theta_g;
use crate::models::{Model, NotSteady, Steady};
use crate::scene::Scene;
use crate::special::root::brent;

/// Solves v̄_th(K) = v (eq 69) on a bracket from [`bracket`]. Brent's method runs to full
/// precision in s = ln(K − K_min), so |ΔK| ≈ 2ε |s| (K − K_min): about 1e-14 at most across
/// the bracket (measured round trips: ≤ 3.4e-15, tests/it/k_inversion.rs). Where the bead crawls
/// so slowly that no K distinguishable from K_min gives v, the first steady K above K_min is
/// returned (within 1e-12 of the root).
pub fn solve(model: &Model, scene: &Scene, br: &KBracket, v: f64) -> Result<KRoot, KFailure> {
    if !(v > 0.0 && v.is_finite()) {
        return Err(KFailure::Invalid(format!(
            "v must be > 0 and finite, got {v}"
        )));
    }
    if v < br.v_lo {
        return Err(KFailure::BelowRange);
    }
    if v > br.v_hi {
        return Err(KFailure::AboveRange);
    }
    let mut evals = 0;
    let tau_star = 2.0 * scene.sin_alpha / v;
    let width = br.hi - br.lo;
    let k_of = |s: f64| br.lo + s.exp();
    let s_hi = width.ln();
    let g_hi = tau_star - br.tau_hi;
    if g_hi <= 0.0 {
        // v = v_hi to the last ulp (τ* and τ_hi may differ by rounding of 2 sin α / v).
        let steady =
            eval(model, scene, br.hi, &mut evals).map_err(|e| KFailure::Invalid(e.to_string()))?;
        return Ok(KRoot {
            k: br.hi,
            steady,
            evals,
        });
    }
    let mut last: Option<(f64, Steady)> = None;
    let g = |s: f64, evals: &mut usize, last: &mut Option<(f64, Steady)>| -> f64 {
        let k = k_of(s).min(br.hi);
        match eval(model, scene, k, evals) {
            Ok(st) => {
                *last = Some((s, st));
                tau_star - st.contact_time
            }
            // Outside the steady range: slow side below, fast side above.
            Err(NotSteady::LiftOff { .. } | NotSteady::Runaway) => f64::MAX,
            Err(_) => {
                if k < br.lo + 0.5 * width {
                    f64::MIN
                } else {
                    f64::MAX
                }
            }
        }
    };
    // Lower end of the s-bracket: step down until the time exceeds τ*.
    let ulp_floor = (br.lo * f64::EPSILON).max(f64::MIN_POSITIVE);
    let mut s_lo = s_hi - 2.0;
    let mut g_lo = g(s_lo, &mut evals, &mut last);
    let (mut s_up, mut g_up) = (s_hi, g_hi);
    let mut step = 4.0;
    while g_lo > 0.0 {
        s_up = s_lo;
        g_up = g_lo;
        s_lo -= step;
        step *= 2.0;
        if s_lo.exp() < ulp_floor {
            // The root lies within rounding of K_min (v far below the crawl speed scale):
            // return the first K above K_min, a few ulp up, where the model is steady.
            let mut d = 2.0 * ulp_floor;
            for _ in 0..64 {
                if let Ok(steady) = eval(model, scene, br.lo + d, &mut evals) {
                    return Ok(KRoot {
                        k: br.lo + d,
                        steady,
                        evals,
                    });
                }
                d *= 2.0;
            }
            return Err(KFailure::Invalid(
                "no steady state found within rounding of K_min".into(),
            ));
        }
        g_lo = g(s_lo, &mut evals, &mut last);
    }
    if g_lo == 0.0 {
        s_up = s_lo;
        g_up = 0.0;
    }
    let mut inner = 0;
    let r = brent(
        |s| g(s, &mut inner, &mut last),
        s_lo,
        s_up,
        g_lo,
        g_up,
        0.0,
        200,
    )
    .ok_or_else(|| KFailure::Invalid("K bracket lost".into()))?;
    evals += inner;
    // The solution must be a true root of a continuous v̄(K), not a jump.
    let steady = match last {
        Some((s, st)) if s == r.x => st,
        _ => eval(model, scene, k_of(r.x).min(br.hi), &mut evals)
            .map_err(|e| KFailure::Invalid(e.to_string()))?,
    };
    let k = k_of(r.x).min(br.hi);
    if (tau_star - steady.contact_time).abs() > 1e-9 * tau_star {
        // Either K is resolved to its last bits where τ is steep (the crawl end: one ulp of K
        // moves ln(K − K_min) by a visible step), or v̄(K) jumps over v. The neighbours two
        // ulp away tell: a resolved root has τ* between them and a small step across.
        let u = 2.0 * f64::EPSILON * k;
        let tm = eval(model, scene, k - u, &mut evals).map(|s| s.contact_time);
        let tp = eval(model, scene, (k + u).min(br.hi), &mut evals).map(|s| s.contact_time);
        let resolved = match (tm, tp) {
            (Ok(a), Ok(b)) => {
                (a - tau_star) * (b - tau_star) <= 0.0 && (a - b).abs() <= 1e-3 * tau_star
            }
            // At the crawl end the steady state ends within rounding of K_min: v is slower
            // than any K distinguishable from K_min, which is then the answer to 1e-12.
            (Err(NotSteady::Stops { .. }), Ok(_)) => {
                br.lower == LowerLimit::Crawl
                    && k - br.lo <= 1e-12
                    && steady.contact_time < tau_star
            }
            _ => false,
        };
        if !resolved {
            return Err(KFailure::Invalid(format!(
                "v(K) jumps at K = {k}: no K gives this velocity"
            )));
        }
    }
    Ok(KRoot { k, steady, evals })
}

fn clamp_end(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    v: f64,
    end: &'static str,
    notes: &mut Vec<String>,
) -> Option<f64> {
    let side = if end == "K_lo" {
        "v - sigma_v"
    } else {
        "v + sigma_v"
    };
    match solve(model, scene, br, v) {
        Ok(r) => Some(r.k),
        Err(KFailure::BelowRange) => {
            notes.push(format!(
                "{end} is the bracket's lower end: {side} is below the steady range"
            ));
            Some(br.lo)
        }
        Err(KFailure::AboveRange) => {
            notes.push(format!(
                "{end} is the bracket's upper end: {side} is above the steady range"
            ));
            Some(br.hi)
        }
        Err(KFailure::Invalid(_)) if v <= 0.0 => {
            notes.push(format!("{end} is the bracket's lower end: {side} <= 0"));
            Some(br.lo)
        }
        Err(KFailure::Invalid(why)) => {
            notes.push(format!("no {end}: {why}"));
            None
        }
    }
}

/// [`estimate`](fn@super::estimate) by the general search in K: [`bracket`], then [`solve`] at v and v ± σ.
pub fn estimate_in_k(model: &Model, scene: &Scene, v: f64, sigma_v: Option<f64>) -> KEstimate {
    let br = match bracket(model, scene) {
        Ok(b) => b,
        Err(e) => {
            return KEstimate {
                bracket: None,
                root: Err(e),
                k_lo: None,
                k_hi: None,
                dv_dk: None,
                theta_g: None,
                notes: Vec::new(),
            }
        }
    };
    let root = solve(model, scene, &br, v);
    let mut notes = Vec::new();
    let (k_lo, k_hi) = match sigma_v {
        Some(s) => (
            clamp_end(model, scene, &br, v - s, "K_lo", &mut notes),
            clamp_end(model, scene, &br, v + s, "K_hi", &mut notes),
        ),
        None => (None, None),
    };
    let (dv_dk, tg) = match &root {
        Ok(r) => (
            slope(model, scene, &br, r),
            match model {
                Model::StickSlip => r.steady.theta_g,
                Model::Stick | Model::StickApprox => {
                    let w0 = r.steady.initial_velocity;
                    scene.with_k(r.k).ok().and_then(|s| theta_g(&s, w0 * w0))
                }
                _ => None,
            },
        ),
        Err(_) => (None, None),
    };
    KEstimate {
        bracket: Some(br),
        root,
        k_lo,
        k_hi,
        dv_dk,
        theta_g: tg,
        notes,
    }
}

/// dv̄/dK at the root of an estimate, by [`dv_dk`] with the model's own steady states.
fn slope(model: &Model, scene: &Scene, br: &KBracket, r: &KRoot) -> Option<f64> {
    let mut n = 0;
    dv_dk(br, r.k, r.steady.mean_velocity, |k| {
        eval(model, scene, k, &mut n).ok().map(|s| s.mean_velocity)
    })
}

/// dv̄/dK at K = `k0` inside the bracket `br`, where v̄ = `v0`, from `v_at` (v̄ at a K, or
/// `None` where there is no steady state) at K_min + d e^{±h}, d = K − K_min, h = 1e-5
/// (steps uniform in s = ln(K − K_min), which keeps their size right where the slope in K is
/// nearly infinite), differenced over the K values actually evaluated (a three-point Lagrange
/// derivative at `k0`, second-order accurate on any spacing). Near the bracket's top, where
/// K_min + d e^h is out of range, the step is shrunk to fit and, failing that, the points are
/// taken at s − h and s − 2h (one-sided, still second order); a first-order one-sided
/// difference would be off by 5e-4 below lift-off (tests/it/k_inversion.rs, mpmath
/// references). Used by the K inversion (`dv_dK` of `fitbead k`) and by the K-law fits'
/// Jacobian ([`crate::fit::klaw`]).
pub fn dv_dk(
    br: &KBracket,
    k0: f64,
    v0: f64,
    mut v_at: impl FnMut(f64) -> Option<f64>,
) -> Option<f64> {
    let d = k0 - br.lo;
    if !(d > 0.0) {
        return None;
    }
    let h_max = if br.hi > k0 {
        ((br.hi - br.lo) / d).ln()
    } else {
        0.0
    };
    let h = 1e-5f64.min(0.5 * h_max);
    let (k1, k2) = if h >= 1e-7 {
        (br.lo + d * (-h).exp(), br.lo + d * h.exp())
    } else {
        let h = 1e-5f64;
        (br.lo + d * (-h).exp(), br.lo + d * (-2.0 * h).exp())
    };
    if !(k1 != k0 && k2 != k0 && k1 != k2) {
        return None;
    }
    let (v1, v2) = (v_at(k1)?, v_at(k2)?);
    // f'(x0) of the quadratic through (x0, f0), (x1, f1), (x2, f2).
    let (a1, a2) = (k1 - k0, k2 - k0);
    let dv = -v0 * (a1 + a2) / (a1 * a2) + v1 * a2 / (a1 * (a2 - a1)) - v2 * a1 / (a2 * (a2 - a1));
    dv.is_finite().then_some(dv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::k::types::UpperLimit;
    use crate::models::ForwardModel;
    use crate::scene::CollisionLaw;

    fn scene(xi: f64, delta_deg: f64) -> Scene {
        Scene::new(xi, delta_deg, 0.4, 0.1, CollisionLaw::Adjusted).unwrap()
    }

    #[test]
    fn stick_bracket_is_eq_32_and_eq_31_inverted() {
        let s = scene(1.0, 12.0);
        let br = bracket(&Model::Stick, &s).unwrap();
        // δ_m(K_min) = δ and δ_d(K_max) = δ (eqs 31–32).
        let dm = crate::models::regimes::delta_m(s.alpha, br.lo);
        let dd = crate::models::regimes::delta_d(s.alpha, br.hi, s.rho);
        assert!((dm - s.delta).abs() < 1e-14, "{dm} {}", s.delta);
        assert!((dd - s.delta).abs() < 1e-12, "{dd} {}", s.delta);
        assert_eq!(br.lower, LowerLimit::Crawl);
        assert_eq!(br.upper, UpperLimit::LiftOff);
    }

    #[test]
    fn round_trip_at_the_paper_scene() {
        let s = scene(1.0, 12.0);
        for m in [Model::Stick, Model::StickSlip, Model::Slip] {
            let v = m.evaluate(&s).map(|x| x.mean_velocity);
            let Ok(v) = v else { continue };
            let br = bracket(&m, &s).unwrap();
            let r = solve(&m, &s, &br, v).unwrap();
            assert!((r.k - s.k).abs() < 1e-12, "{m:?}: {} vs {}", r.k, s.k);
        }
    }
}
