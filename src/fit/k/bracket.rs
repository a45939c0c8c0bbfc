//! The bracket of K (module docs of [`super`]): derived ends, checked against the forward
//! model, moved to the model's true boundary where it fails inside.

use super::types::{KBracket, KFailure, LowerLimit, UpperLimit};
use crate::fit::data::Dataset;
use crate::models::regimes::theta_g;
use crate::models::slip::SlipPhase;
use crate::models::{stick, stickslip, ForwardModel, Model, NotSteady, Steady};
use crate::scene::Scene;
use crate::special::root::brent;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The models whose K can be inverted.
pub(crate) fn invertible(model: &Model) -> bool {
    matches!(
        model,
        Model::Stick
            | Model::StickApprox
            | Model::Slip
            | Model::SlipApprox
            | Model::StickSlip
            | Model::Contact(_)
    )
}

/// The steady state of `model` at this scene with K = `k`, counting the evaluation in
/// `evals`: for stick/slip without the forward model's map-slope and second-fixed-point
/// diagnostics (the inversion and the K-law fits need v̄ and the final velocity only).
pub(crate) fn eval(
    model: &Model,
    scene: &Scene,
    k: f64,
    evals: &mut usize,
) -> Result<Steady, NotSteady> {
    *evals += 1;
    super::count_contacts(1);
    match scene.with_k(k) {
        // The search needs v̄ and the final velocity only: stick/slip skips its map-slope
        // and second-fixed-point diagnostics (they cost more than the steady state).
        Ok(s) if k.is_finite() && matches!(model, Model::StickSlip) => stickslip::steady_lean(&s),
        Ok(s) if k.is_finite() => model.evaluate(&s),
        _ => Err(NotSteady::Invalid {
            reason: "K out of range",
        }),
    }
}

/// [`eval`] at two K, with the same results: stick evaluates them side by side
/// ([`stick::steady_pair`]).
fn eval_pair(
    model: &Model,
    scene: &Scene,
    [ka, kb]: [f64; 2],
    evals: &mut usize,
) -> [Result<Steady, NotSteady>; 2] {
    if matches!(model, Model::Stick) && ka.is_finite() && kb.is_finite() {
        if let (Ok(a), Ok(b)) = (scene.with_k(ka), scene.with_k(kb)) {
            *evals += 2;
            super::count_contacts(2);
            return stick::steady_pair(&a, &b);
        }
    }
    [eval(model, scene, ka, evals), eval(model, scene, kb, evals)]
}

/// The lowest K above `lo` (and not above `limit`) at which `model` is steady, among the K that
/// double precision resolves there: lo + 2ⁿ lo ε, n = 0, 1, …, each at least one ulp above lo.
pub(crate) fn lowest_steady(
    model: &Model,
    scene: &Scene,
    lo: f64,
    limit: f64,
    evals: &mut usize,
) -> Option<(f64, Steady)> {
    let step = (lo * f64::EPSILON).max(f64::MIN_POSITIVE);
    (0..64)
        .map(|n| lo + step * 2f64.powi(n))
        .take_while(|&k| k <= limit)
        .find_map(|k| eval(model, scene, k, evals).ok().map(|s| (k, s)))
}

/// Squared speed at Θf of one slip contact launched at Θ0 with squared speed `w0sq` (eq 38
/// from Θ0; no stop check: the caller's bracket logic handles stopping).
fn slip_contact_sq(scene: &Scene, w0sq: f64) -> f64 {
    slip_contact_sq_at(scene, w0sq, scene.theta_f)
}

/// Whether a rolling model's analytic bracket (closed form, eqs 30a and 32) is empty, so
/// that [`bracket`] fails before any forward evaluation; `false` for the other models.
pub(crate) fn empty_rolling_bracket(model: &Model, scene: &Scene) -> bool {
    matches!(model, Model::Stick | Model::StickApprox)
        && !candidate(model, scene).is_some_and(|(lo, hi, _)| lo < hi)
}

/// Analytic candidate bracket (lo, hi, lower kind); `None` when it is empty.
fn candidate(model: &Model, scene: &Scene) -> Option<(f64, f64, LowerLimit)> {
    let s0 = scene.sc_half_0.s;
    let sf = scene.sc_half_f.s;
    let cf = scene.sc_f.c;
    let drop = 2.0 * scene.b * scene.sin_delta_sin_alpha(); // B (cos Θ0 − cos Θf), eq 9
    match model {
        Model::Stick | Model::StickApprox => {
            // Lift-off at the steady state: L² = K²L² + drop = cos Θf (eqs 19, 30a).
            if !(cf > drop) {
                return None;
            }
            let hi = (1.0 - drop / cf).sqrt();
            let (lo, kind) = if matches!(model, Model::StickApprox) {
                // eq 28 needs A > B: both factors of the top speed² positive (|Θ0| either way).
                (
                    s0.abs() / sf,
                    if s0 < 0.0 {
                        LowerLimit::Crawl
                    } else {
                        LowerLimit::Model
                    },
                )
            } else if s0 < 0.0 {
                (-s0 / sf, LowerLimit::Crawl) // P = 0: eq 32 inverted
            } else {
                (0.0, LowerLimit::Zero)
            };
            Some((lo, hi, kind))
        }
        Model::Slip | Model::SlipApprox => {
            // Θ̇² = w0² E(θ) + g(θ), E = e^{2f(θ−Θ0)}: the bead passes iff w0² > −g/E at its
            // minimum, where d(g/E)/dθ ∝ sin θ − f cos θ vanishes: θ* = atan f.
            let ts = scene.f.atan().clamp(scene.theta_0, scene.theta_f);
            let e_s = (2.0 * scene.f * (ts - scene.theta_0)).exp();
            let wc2 = (-slip_contact_sq_at(scene, 0.0, ts) / e_s).max(0.0);
            let e_f = (4.0 * scene.f * scene.alpha).exp();
            let g_f = slip_contact_sq(scene, 0.0);
            // Lift-off: x² = K² x² E_f + g_f = cos Θf.
            if !(cf > g_f) {
                return None;
            }
            let hi = ((cf - g_f) / (cf * e_f)).sqrt();
            let (lo, kind) = if matches!(model, Model::SlipApprox) {
                // eqs 56–59 have their own stop and validity limits: start from K → 0 and let
                // the status bisection find them.
                (0.0, LowerLimit::Zero)
            } else if wc2 > 0.0 {
                ((wc2 / (wc2 * e_f + g_f)).sqrt(), LowerLimit::Crawl)
            } else {
                (0.0, LowerLimit::Zero)
            };
            Some((lo, hi, kind))
        }
        Model::StickSlip => {
            let unit = scene.with_k(1.0).ok()?;
            let phi = |w0: f64| stickslip::map(&unit, w0).map(|m| m.final_velocity);
            // Lower end: rolling over the top needs w0² > 2B sin²(Θ0/2) (when slip starts
            // after the top); the contact from there is K-independent.
            let (lo, kind) = if s0 < 0.0 {
                let wc = (2.0 * scene.b).sqrt() * s0.abs();
                let tg_ok = theta_g(&unit, wc * wc).is_some_and(|t| t > 0.0);
                // Φ at the crawl itself is a limit (the top speed 0 is not launched): take it by
                // linear extrapolation from just above, h and 2h, leaving an O(h²) error.
                let h = 1e-13;
                match (phi(wc * (1.0 + h)), phi(wc * (1.0 + 2.0 * h))) {
                    (Ok(x1), Ok(x2)) if tg_ok => (wc / (2.0 * x1 - x2), LowerLimit::Crawl),
                    _ => (0.0, LowerLimit::Model),
                }
            } else {
                (0.0, LowerLimit::Zero)
            };
            // Upper end: the launch speed whose final speed is the lift-off speed.
            let xd = cf.max(0.0).sqrt();
            let q = |w0: f64| match phi(w0) {
                Ok(x) => x - xd,
                Err(NotSteady::Stops { .. }) => -xd,
                Err(_) => xd,
            };
            let w_lo = f64::MIN_POSITIVE;
            let q_lo = q(w_lo);
            if !(q_lo < 0.0) {
                return None;
            }
            let mut w_hi = xd;
            let mut q_hi = q(w_hi);
            let mut n = 0;
            while q_hi < 0.0 && n < 60 {
                w_hi *= 2.0;
                q_hi = q(w_hi);
                n += 1;
            }
            let r = brent(q, w_lo, w_hi, q_lo, q_hi, 0.0, 200)?;
            Some((lo, r.x / xd, kind))
        }
        // The general contact model has no closed-form ends: from K → 0 (the bead stops when
        // Θ0 < 0) to K = 1, both ends found by bisection on the model's own status.
        Model::Contact(_) => Some((0.0, 1.0, LowerLimit::Zero)),
        _ => None,
    }
}

fn slip_contact_sq_at(scene: &Scene, w0sq: f64, theta: f64) -> f64 {
    SlipPhase::new(scene.theta_0, w0sq, scene.f).speed_sq(theta)
}

/// The steady K closest to `bad` between `good` (steady) and `bad` (not steady): the largest
/// steady K at an upper end, the smallest at a lower end; bisection on the model's status to
/// |ΔK| ≤ 1e-15 + 2 ulp. Stick/slip's bisection asks only whether the fixed point exists
/// ([`stickslip::steady_status`], without the slip phase's contact time) and is shortened
/// next to the saddle-node at an upper end, along a tested chain at a lower end
/// ([`stickslip_status_end`]); the point it ends on is
/// then evaluated in full, and where that fails, the bisection is redone on full evaluations,
/// as [`eval`] decides. The other models bisect on [`eval`] itself.
fn status_boundary(
    model: &Model,
    scene: &Scene,
    good: f64,
    bad: f64,
    evals: &mut usize,
) -> (f64, Steady) {
    if matches!(model, Model::StickSlip) {
        let k = stickslip_status_end(scene, good, bad, evals);
        if let Ok(s) = eval(model, scene, k, evals) {
            return (k, s);
        }
    }
    // Bisection on full evaluations: the steady state of the point it ends on is that of the
    // last steady point it tried, or, when none was, of `good` itself.
    let mut at_good = None;
    let k = bisect_status(good, bad, |k| {
        eval(model, scene, k, evals)
            .map(|s| at_good = Some(s))
            .is_ok()
    });
    let s = at_good.map_or_else(|| eval(model, scene, k, evals), Ok);
    (k, s.unwrap_or_else(|_| unreachable_steady()))
}

/// Steps of stick/slip's status bisection checked against the saddle-node before the rest is
/// skipped ([`stickslip_status_end`]).
const CHECKED_STEPS: usize = 8;

/// [`bisect_status`] on stick/slip's status, shortened where the end is the saddle-node of the
/// final-velocity map (the largest K with a fixed point, K_sn, found once in launch space by
/// [`stickslip::saddle_node`]). The bisection's own first [`CHECKED_STEPS`] steps run as they
/// would, each checked against K_sn (steady below, not above); where all agree, the end is
/// looked for next to K_sn ([`beside_saddle_node`]): two or three status tests instead of the
/// ~40 left of the bisection. Where a step disagrees (the status flips elsewhere, or is not
/// monotone) or no end is found next to K_sn, the bisection goes on from where it is, so its
/// result is then exactly the plain bisection's. On the random measured file of
/// `scripts/gen_measurements.py` the end lies within 1.3e-15 relative below K_sn wherever the
/// saddle-node is found. A lower end (`good` > `bad`) is first tried along the chain of
/// [`lower_end_chain`].
fn stickslip_status_end(scene: &Scene, good: f64, bad: f64, evals: &mut usize) -> f64 {
    let mut status = |k: f64| {
        *evals += 1;
        k.is_finite()
            && scene
                .with_k(k)
                .is_ok_and(|s| stickslip::steady_status(&s).is_ok())
    };
    if good > bad {
        if let Some(k) = lower_end_chain(good, bad, &mut status) {
            return k;
        }
    }
    let (mut good, mut bad) = (good, bad);
    let mut steps = 0;
    let k_sn = if good < bad {
        stickslip::saddle_node(scene)
            .map(|sn| sn.k)
            .filter(|&k| k > good && k < bad)
    } else {
        None
    };
    if let Some(k_sn) = k_sn {
        let mut agree = true;
        while steps < CHECKED_STEPS {
            let Some(mid) = bisect_mid(good, bad) else {
                return good;
            };
            steps += 1;
            let steady = status(mid);
            if steady {
                good = mid;
            } else {
                bad = mid;
            }
            if steady != (mid < k_sn) {
                agree = false;
                break;
            }
        }
        if agree {
            if let Some(k) = beside_saddle_node(k_sn, good, bad, &mut status) {
                return k;
            }
        }
    }
    bisect_steps(good, bad, BISECTION_STEPS - steps, &mut status)
}

/// Every [`LOWER_CHAIN_SAMPLE`]-th point of the lower-end chain is tested ([`lower_end_chain`]).
const LOWER_CHAIN_SAMPLE: usize = 8;

/// A lower end of stick/slip's status bisection (`good` > `bad`) where the bisection would
/// find every point steady: each point then halves the distance to `bad`, and the end is the
/// last of that chain (for Θ0 ≥ 0, where the steady state is the same down to K ~ 1e-100
/// and `bad` is K = 2⁻¹⁰²², this walks down ~50 steps to ~1e-15). The chain's last point and
/// every [`LOWER_CHAIN_SAMPLE`]-th one are tested; `None` (the caller bisects as before)
/// unless all are steady. The result is the plain bisection's wherever the untested points of
/// the chain are steady too (on the 100,000-row random measured file of
/// `scripts/gen_measurements.py`, every row's bracket is byte-identical).
fn lower_end_chain(good: f64, bad: f64, status: &mut impl FnMut(f64) -> bool) -> Option<f64> {
    let mut chain = Vec::new();
    let mut g = good;
    while chain.len() < BISECTION_STEPS {
        let Some(mid) = bisect_mid(g, bad) else {
            break;
        };
        chain.push(mid);
        g = mid;
    }
    let (&last, rest) = chain.split_last()?;
    if !status(last) {
        return None;
    }
    rest.iter()
        .skip(LOWER_CHAIN_SAMPLE - 1)
        .step_by(LOWER_CHAIN_SAMPLE)
        .all(|&k| status(k))
        .then_some(last)
}

/// The status end next to the saddle-node `k_sn`, inside (`good`, `bad`): not steady at
/// K_sn + t/2, steady at K_sn − (t/2)·4ʲ for the first j that is (t = 1e-15 + 2 ulp, steps
/// up to 1e-9 K_sn), then bisected between the two to [`bisect_status`]'s tolerance. `None`
/// where a test goes the other way or leaves the interval.
fn beside_saddle_node(
    k_sn: f64,
    good: f64,
    bad: f64,
    status: &mut impl FnMut(f64) -> bool,
) -> Option<f64> {
    let t = 1e-15 + 2.0 * f64::EPSILON * k_sn;
    let mut above = k_sn + 0.5 * t;
    if !(above < bad) || status(above) {
        return None;
    }
    let mut step = 0.5 * t;
    let below = loop {
        let k = k_sn - step;
        if !(k > good) || step > 1e-9 * k_sn {
            return None;
        }
        if status(k) {
            break k;
        }
        above = k;
        step *= 4.0;
    };
    Some(bisect_status(below, above, status))
}

/// Most steps of a status bisection (from an interval of width 1, the tolerance is reached
/// in about 50).
const BISECTION_STEPS: usize = 80;

/// The next point of a status bisection between `good` and `bad`, or `None` once they are
/// within 1e-15 + 2 ulp (or adjacent doubles).
fn bisect_mid(good: f64, bad: f64) -> Option<f64> {
    let mid = 0.5 * (good + bad);
    let done =
        (good - bad).abs() <= 1e-15 + 2.0 * f64::EPSILON * good.abs() || mid == good || mid == bad;
    (!done).then_some(mid)
}

/// Bisection between `good` (steady) and `bad` on `steady`, to |ΔK| ≤ 1e-15 + 2 ulp: the last
/// steady point.
fn bisect_status(good: f64, bad: f64, steady: impl FnMut(f64) -> bool) -> f64 {
    bisect_steps(good, bad, BISECTION_STEPS, steady)
}

/// [`bisect_status`] in at most `steps` steps.
fn bisect_steps(
    mut good: f64,
    mut bad: f64,
    steps: usize,
    mut steady: impl FnMut(f64) -> bool,
) -> f64 {
    for _ in 0..steps {
        let Some(mid) = bisect_mid(good, bad) else {
            break;
        };
        if steady(mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    good
}

// `good` was verified steady before the bisection started; re-evaluating it cannot fail, but a
// failure must not panic either: an empty steady state makes the caller's checks reject it.
fn unreachable_steady() -> Steady {
    Steady::basic(0.0, 0.0, 0.0, f64::INFINITY)
}

/// The bracket of K with a steady state for `model` at the scene's ξ, δ, ρ, f (the scene's own
/// K is ignored).
pub fn bracket(model: &Model, scene: &Scene) -> Result<KBracket, KFailure> {
    if !invertible(model) {
        return Err(KFailure::Invalid(format!(
            "K is not a parameter of the {} model",
            model.name()
        )));
    }
    let mut evals = 0;
    let none = || {
        KFailure::Invalid(
            "no K gives a steady state at this xi and slope (the bead stops or lifts off)".into(),
        )
    };
    let (lo, hi, mut lower) = candidate(model, scene).ok_or_else(|| {
        KFailure::Invalid(
            "no K gives a steady state: the bead lifts off at this xi and slope even as K -> 0"
                .into(),
        )
    })?;
    if !(lo < hi) {
        return Err(KFailure::Invalid(format!(
            "no K gives a steady state: the lowest K that carries the bead over the top \
             ({lo:.6}) already makes it lift off (K_d = {hi:.6})"
        )));
    }
    let tiny = (hi - lo) * 1e-9;
    let hi_in = hi * (1.0 - 4.0 * f64::EPSILON);
    let lo_test = if lo == 0.0 {
        f64::MIN_POSITIVE
    } else {
        lo + tiny
    };
    let [r_lo, r_hi] = eval_pair(model, scene, [lo_test, hi_in], &mut evals);
    let mut upper = UpperLimit::LiftOff;
    // A steady point inside the bracket, to bisect from where an end fails.
    let good = match (&r_lo, &r_hi) {
        (Ok(_), _) => Some(lo_test),
        (_, Ok(_)) => Some(hi_in),
        _ => (1..32)
            .map(|i| lo + (hi - lo) * i as f64 / 32.0)
            .find(|&k| eval(model, scene, k, &mut evals).is_ok()),
    }
    .ok_or_else(none)?;
    let (hi, top) = match r_hi {
        Ok(s) => {
            // Stick/slip: lift-off of the final-velocity map's fixed point can happen on its
            // unstable branch, while the stable one (the one a bead settles on) lives on up to
            // the saddle-node where the two merge. Probe above; if steady, walk up to the end.
            let mut d = 1e-9 * (hi - lo);
            let mut last_ok = (hi_in, s);
            let mut found_bad = None;
            if matches!(model, Model::StickSlip) {
                while hi_in + d < 1.0 {
                    match eval(model, scene, hi_in + d, &mut evals) {
                        Ok(t) => last_ok = (hi_in + d, t),
                        Err(_) => {
                            found_bad = Some(hi_in + d);
                            break;
                        }
                    }
                    d *= 4.0;
                }
                if last_ok.0 > hi_in && found_bad.is_none() {
                    found_bad = Some(1.0);
                }
            }
            match found_bad {
                Some(bad) if last_ok.0 > hi_in => {
                    upper = UpperLimit::Model;
                    status_boundary(model, scene, last_ok.0, bad, &mut evals)
                }
                _ => (hi_in, s),
            }
        }
        Err(_) => {
            upper = UpperLimit::Model;
            status_boundary(model, scene, good, hi, &mut evals)
        }
    };
    let (lo, v_lo) = match (&r_lo, lower) {
        (Ok(_), LowerLimit::Crawl) => (lo, 0.0),
        (Ok(s), LowerLimit::Zero) => (0.0, s.mean_velocity),
        (Ok(_), LowerLimit::Model) => {
            // An approximate model's own limit (the analytic candidate is its exact boundary):
            // the slowest motion is its value at the lowest steady K above lo that double
            // precision resolves (steps of 2ⁿ lo ε, at least one ulp each).
            let first = lowest_steady(model, scene, lo, lo + (hi - lo) * 1e-13, &mut evals);
            let s = first.map_or_else(
                || eval(model, scene, lo + (hi - lo) * 1e-13, &mut evals),
                |(_, s)| Ok(s),
            );
            (lo, s.map(|s| s.mean_velocity).unwrap_or(0.0))
        }
        (Err(_), _) => {
            lower = LowerLimit::Model;
            let (k, s) = status_boundary(model, scene, good, lo_test.min(good), &mut evals);
            // The model is steady from k up: the bracket starts just below.
            (k * (1.0 - 2.0 * f64::EPSILON), s.mean_velocity)
        }
    };
    if !(top.contact_time.is_finite() && top.contact_time > 0.0) {
        return Err(none());
    }
    Ok(KBracket {
        lo,
        hi,
        v_lo,
        v_hi: top.mean_velocity,
        tau_hi: top.contact_time,
        lower,
        upper,
        evals,
    })
}

/// The points of `ds` that no K makes steady under any of `models` (regime A or C for every
/// K), with why under the first model; none once `stop` is raised.
pub(crate) fn unsteady_points(
    models: &[Model],
    ds: &Dataset,
    stop: Option<&AtomicBool>,
) -> Vec<(usize, String)> {
    ds.points
        .par_iter()
        .enumerate()
        .filter_map(|(i, p)| {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return None;
            }
            let mut why = None;
            for m in models {
                match bracket(m, &p.scene) {
                    Ok(_) => return None,
                    Err(e) => {
                        why.get_or_insert_with(|| e.to_string());
                    }
                }
            }
            why.map(|w| (i, w))
        })
        .collect()
}
