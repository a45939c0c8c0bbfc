//! The collisional parameter K of one measurement (eq 69): find K with v̄_th(K; α, δ, ρ, f) =
//! v̄_exp for the rolling, slip and stick/slip models.
//!
//! The search runs on a bracket of K that is derived, not guessed ([`bracket`]). Every contact
//! model maps the speed Θ̇0 just after a collision to the speed Θ̇f at the next one by a
//! function Φ that does not involve K; K enters only through Θ̇0 = K Θ̇f. Hence:
//! - the lowest K is K_min = w_c / Φ(w_c), where w_c is the smallest launch speed that still
//!   carries the bead to Θf (over the top for rolling: w_c² = 2B sin²(Θ0/2), which gives
//!   K_min = −sin(Θ0/2)/sin(Θf/2), the inverse of eq 32; for slip the minimum of Θ̇² e^{−2fθ}
//!   sits at tan θ = f); there the bead crawls over the top and v̄ → 0;
//! - the highest K is where the steady final speed reaches lift-off, Φ(w_d) = sqrt(cos Θf)
//!   (eq 30a), K_d = w_d / sqrt(cos Θf) — below the runaway limits K < 1 (rolling) and
//!   K² e^{4fα} < 1 (slip) of the issue, which lift-off always reaches first when δ > 0.
//!
//! Each end is then checked against the forward model itself; where the model fails inside the
//! analytic bracket (the approximate models' own validity limits, the stick/slip map's
//! saddle-node beyond K e^{2fα} ≈ 1), the end is moved to the model's true boundary by bisection
//! on its status.
//!
//! The root is found by Brent's method in s = ln(K − K_min) on g(s) = τ* − τ(K), τ the contact
//! time (v̄ = 2 sin α / τ, eq 10). Near K_min the time grows like −ln(K − K_min) (the bead
//! crawls over the top, v̄ has an infinite slope in K), so in s the function is close to a
//! straight line and the solver converges superlinearly at either end instead of stalling.

use crate::models::regimes::theta_g;
use crate::models::slip::SlipPhase;
use crate::models::{stickslip, ForwardModel, Model, NotSteady, Steady};
use crate::scene::Scene;
use crate::special::root::brent;
use std::fmt;

/// What sets the lower end of the K bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LowerLimit {
    /// The bead just crawls over the top (Θ̇ → 0 there): v̄ → 0 at K_min.
    Crawl,
    /// K_min = 0: the contact starts past the top; v̄(K → 0) is the slowest steady motion.
    Zero,
    /// The model's own validity limit, found by bisection on its status.
    Model,
}

/// What sets the upper end of the K bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpperLimit {
    /// The steady final speed reaches lift-off at Θf (eq 30a, δ = δ_d(K)).
    LiftOff,
    /// The model stops having a steady state before lift-off (found by bisection on its
    /// status): runaway of the stick/slip map, or an approximate model's validity limit.
    Model,
}

/// The range of K over which a model has a steady state at one (ξ, δ, ρ, f).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KBracket {
    /// Lowest K (exclusive).
    pub lo: f64,
    /// Highest K (inclusive: the forward model is steady there; for a stick/slip range ending
    /// at the map's saddle-node, the last K below it where the forward model finds the stable
    /// fixed point — tested to within 1e-9 of the range in tests/k_inversion.rs).
    pub hi: f64,
    /// v̄ at the lower end (0 when the bead crawls over the top).
    pub v_lo: f64,
    /// v̄ at the upper end: the fastest steady motion.
    pub v_hi: f64,
    /// Contact time at the upper end.
    pub tau_hi: f64,
    /// What sets the lower end.
    pub lower: LowerLimit,
    /// What sets the upper end.
    pub upper: UpperLimit,
    /// Forward evaluations spent on the bracket.
    pub evals: usize,
}

/// Why a measurement has no K.
#[derive(Debug, Clone, PartialEq)]
pub enum KFailure {
    /// v is below the slowest steady motion (regime A).
    BelowRange,
    /// v is above the fastest steady motion (lift-off or runaway: regime C).
    AboveRange,
    /// No K gives a steady state at this ξ and δ, or the model failed.
    Invalid(String),
}

impl KFailure {
    /// The status word of the `k` command.
    pub fn status(&self) -> &'static str {
        match self {
            KFailure::BelowRange => "below-range",
            KFailure::AboveRange => "above-range",
            KFailure::Invalid(_) => "invalid",
        }
    }
}

impl std::error::Error for KFailure {}

impl fmt::Display for KFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KFailure::BelowRange => f.write_str("v is below the slowest steady motion (regime A)"),
            KFailure::AboveRange => {
                f.write_str("v is above the fastest steady motion (lift-off or runaway)")
            }
            KFailure::Invalid(s) => f.write_str(s),
        }
    }
}

/// The models whose K can be inverted.
pub fn invertible(model: &Model) -> bool {
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

fn eval(model: &Model, scene: &Scene, k: f64, evals: &mut usize) -> Result<Steady, NotSteady> {
    *evals += 1;
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

/// Squared speed at Θf of one slip contact launched at Θ0 with squared speed `w0sq` (eq 38
/// from Θ0; no stop check: the caller's bracket logic handles stopping).
fn slip_contact_sq(scene: &Scene, w0sq: f64) -> f64 {
    slip_contact_sq_at(scene, w0sq, scene.theta_f)
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
/// |ΔK| ≤ 1e-15 + 2 ulp.
fn status_boundary(
    model: &Model,
    scene: &Scene,
    mut good: f64,
    mut bad: f64,
    evals: &mut usize,
) -> (f64, Steady) {
    let mut best = None;
    for _ in 0..80 {
        let mid = 0.5 * (good + bad);
        if (good - bad).abs() <= 1e-15 + 2.0 * f64::EPSILON * good.abs()
            || mid == good
            || mid == bad
        {
            break;
        }
        match eval(model, scene, mid, evals) {
            Ok(s) => {
                good = mid;
                best = Some(s);
            }
            Err(_) => bad = mid,
        }
    }
    let s = match best {
        Some(s) => s,
        None => match eval(model, scene, good, evals) {
            Ok(s) => s,
            Err(_) => unreachable_steady(),
        },
    };
    (good, s)
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
    let r_lo = eval(model, scene, lo_test, &mut evals);
    let r_hi = eval(model, scene, hi_in, &mut evals);
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
            // the slowest motion is its limit at lo.
            let s = eval(model, scene, lo + (hi - lo) * 1e-13, &mut evals);
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

/// K for one measured mean velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KRoot {
    /// The collisional parameter.
    pub k: f64,
    /// The steady state at that K (for stick/slip without the forward model's map-slope and
    /// second-fixed-point diagnostics, which the search does not compute).
    pub steady: Steady,
    /// Forward evaluations used by the root search.
    pub evals: usize,
}

/// Solves v̄_th(K) = v (eq 69) on a bracket from [`bracket`]. Brent's method runs to full
/// precision in s = ln(K − K_min), so |ΔK| ≈ 2ε |s| (K − K_min): about 1e-14 at most across
/// the bracket (measured round trips: ≤ 3.4e-15, tests/k_inversion.rs). Where the bead crawls
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

/// Everything the `k` command reports for one measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct KEstimate {
    /// The bracket (when one exists).
    pub bracket: Option<KBracket>,
    /// K at v, or why there is none.
    pub root: Result<KRoot, KFailure>,
    /// K at v − σ (exact inverse); the bracket's lower end when v − σ is below its range.
    pub k_lo: Option<f64>,
    /// K at v + σ (exact inverse); the bracket's upper end when v + σ is above its range.
    pub k_hi: Option<f64>,
    /// dv̄/dK at the root (a second-order difference on steps uniform in ln(K − K_min)).
    pub dv_dk: Option<f64>,
    /// Θ_G at the root (radians): where rolling gives way to slip (eq 36); for the rolling
    /// models, where the steady rolling motion would need more friction than f.
    pub theta_g: Option<f64>,
    /// Notes on the interval ends.
    pub notes: Vec<String>,
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

/// K, its interval at v ± σ, dv̄/dK and diagnostics for one measurement (eq 69).
pub fn estimate(model: &Model, scene: &Scene, v: f64, sigma_v: Option<f64>) -> KEstimate {
    // Stick and stick/slip with Θ0 < 0: solve in the launch speed (no fixed point inside).
    if let Some(e) = super::klaunch::estimate(model, scene, v, sigma_v) {
        return e;
    }
    estimate_in_k(model, scene, v, sigma_v)
}

/// [`estimate`] by the general search in K: [`bracket`], then [`solve`] at v and v ± σ.
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

/// dv̄/dK at the root from v̄ at K_min + d e^{±h}, d = K − K_min, h = 1e-5 (steps uniform in
/// s = ln(K − K_min), which keeps their size right where the slope in K is nearly infinite),
/// differenced over the K values actually evaluated (a three-point Lagrange derivative at the
/// root, second-order accurate on any spacing). Near the bracket's top, where K_min + d e^h
/// is out of range, the step is shrunk to fit and, failing that, the points are taken at
/// s − h and s − 2h (one-sided, still second order). With a first-order one-sided difference
/// here the error below lift-off was 5e-4 (tests/k_inversion.rs, mpmath references).
fn slope(model: &Model, scene: &Scene, br: &KBracket, r: &KRoot) -> Option<f64> {
    let mut n = 0;
    let d = r.k - br.lo;
    if !(d > 0.0) {
        return None;
    }
    let k0 = r.k;
    let v0 = r.steady.mean_velocity;
    let mut v_at = |k: f64| eval(model, scene, k, &mut n).ok().map(|s| s.mean_velocity);
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
