//! Eq 69 solved in K by Brent's method in s = ln(K − K_min) (module docs of [`super`]), K_lo
//! and K_hi at v ∓ σ, and dv̄/dK over the evaluated K values. Where v̄(K) is continuous, the
//! searches for K_lo and K_hi start next to the K that the quadratic through the root and
//! dv̄/dK's stencil predicts ([`Seed`]): about 6 evaluations each instead of 8 or 9.

use super::bracket::{bracket, empty_rolling_bracket, eval, lowest_steady};
use super::types::{end_note, AtEnd, KBracket, KEstimate, KFailure, KRoot};
use crate::models::regimes::theta_g;
use crate::models::{Model, NotSteady, Steady};
use crate::scene::Scene;
use crate::special::root::brent_until;

/// Solves v̄_th(K) = v (eq 69) on a bracket from [`bracket`]. Brent's method runs to full
/// precision in s = ln(K − K_min), so |ΔK| ≈ 2ε |s| (K − K_min): about 1e-14 at most across
/// the bracket (measured round trips: ≤ 3.4e-15, src/fit/suite/k_inversion.rs). Where the bead crawls
/// so slowly that no K distinguishable from K_min gives v, the first steady K above K_min is
/// returned (within 1e-12 of the root).
pub fn solve(model: &Model, scene: &Scene, br: &KBracket, v: f64) -> Result<KRoot, KFailure> {
    solve_with(model, scene, br, v, None)
}

/// Where [`solve_with`] looks first for a root close to one already found: the predicted
/// s = ln(K − K_min) and the distance from it at which to look for the sign change
/// ([`Seed::near`]).
#[derive(Debug, Clone, Copy)]
struct Seed {
    s: f64,
    step: f64,
}

impl Seed {
    /// The seed for v̄ = `v` from a root at s0 = ln(k0 − K_min) where v̄ = v0, and v̄ at two more
    /// points `pts` = (K, v̄) (dv̄/dK's stencil): Newton's step Δ1 = (v − v0)/v̄′ in s, corrected
    /// by the quadratic through the three points to Δ2 = Δ1 − v̄″Δ1²/(2v̄′). The first search
    /// step is a quarter of that correction (the error of Δ2 is of the order Δ1³): Brent's
    /// method then starts from a bracket about as wide as the error of the prediction.
    fn near(br: &KBracket, (k0, v0): (f64, f64), pts: [(f64, f64); 2], v: f64) -> Option<Self> {
        let s_of = |k: f64| (k - br.lo).ln();
        let s0 = s_of(k0);
        let (a1, a2) = (s_of(pts[0].0) - s0, s_of(pts[1].0) - s0);
        let (f0, f1, f2) = (v0, pts[0].1, pts[1].1);
        let d1 = quadratic_slope((f0, f1, f2), a1, a2);
        // The second derivative of the same quadratic.
        let d2 = 2.0 * (f0 / (a1 * a2) + f1 / (a1 * (a1 - a2)) + f2 / (a2 * (a2 - a1)));
        let step1 = (v - v0) / d1;
        let step2 = step1 - 0.5 * d2 * step1 * step1 / d1;
        let seed = Seed {
            s: s0 + step2,
            step: 0.25 * (step2 - step1).abs() + 1e-12 * (1.0 + s0.abs()),
        };
        (seed.s.is_finite() && seed.step.is_finite()).then_some(seed)
    }
}

/// [`solve`], first looking for the root's bracket around `seed` when there is one: its
/// sign change within a few widening steps of the seed, then Brent's method from there; the
/// search from the top of the bracket when none is found.
fn solve_with(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    v: f64,
    seed: Option<Seed>,
) -> Result<KRoot, KFailure> {
    if !(v > 0.0 && v.is_finite()) {
        return Err(KFailure::Invalid(format!(
            "v must be > 0 and finite, got {v}"
        )));
    }
    let mut evals = 0;
    // Within ROUNDING (relative) of the slowest or fastest steady motion, v is that motion to
    // the rounding of v̄ itself: K is the bracket's bottom (its lowest steady K) or top.
    if v < br.v_lo {
        if v >= br.v_lo * (1.0 - ROUNDING) {
            if let Some((k, steady)) = lowest_steady(model, scene, br.lo, br.hi, &mut evals) {
                return Ok(KRoot { k, steady, evals });
            }
        }
        return Err(KFailure::BelowRange);
    }
    if v > br.v_hi * (1.0 + ROUNDING) {
        return Err(KFailure::AboveRange);
    }
    let tau_star = 2.0 * scene.sin_alpha / v;
    let width = br.hi - br.lo;
    let k_of = |s: f64| br.lo + s.exp();
    let s_hi = width.ln();
    let g_hi = tau_star - br.tau_hi;
    if g_hi <= 0.0 {
        // v = v_hi to rounding (of v̄, and of τ* = 2 sin α / v).
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
    let ulp_floor = (br.lo * f64::EPSILON).max(f64::MIN_POSITIVE);
    let near = seed.and_then(|sd| {
        seeded_bracket(sd, (ulp_floor.ln(), s_hi, g_hi), |s: f64| {
            g(s, &mut evals, &mut last)
        })
    });
    // Lower end of the s-bracket: step down until the time exceeds τ*.
    let start = match near {
        Some(b) => b,
        None => (s_hi - 2.0, g(s_hi - 2.0, &mut evals, &mut last), s_hi, g_hi),
    };
    let Some((s_lo, g_lo, mut s_up, mut g_up)) =
        step_down(start, ulp_floor, |s| g(s, &mut evals, &mut last))
    else {
        // v is slower than the motion at every K that double precision distinguishes from
        // K_min.
        let s_floor = ulp_floor.ln();
        return match last {
            Some((s, st)) if s == s_floor => {
                below_resolution(model, scene, br, tau_star, k_of(s), st, evals)
            }
            _ => Err(KFailure::BelowRange),
        };
    };
    if g_lo == 0.0 {
        s_up = s_lo;
        g_up = 0.0;
    }
    let mut inner = 0;
    // g depends on s only through the double K = k_of(s): once the bracket's ends give
    // adjacent doubles of K, the root's K is decided (`brent_until`).
    let adjacent_k = |a: f64, b: f64| {
        let (ka, kb) = (k_of(a).min(br.hi), k_of(b).min(br.hi));
        ka.max(kb) <= ka.min(kb).next_up()
    };
    let r = brent_until(
        |s| g(s, &mut inner, &mut last),
        s_lo,
        s_up,
        g_lo,
        g_up,
        0.0,
        200,
        adjacent_k,
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
        resolved(model, scene, br, tau_star, k, &steady, &mut evals)?;
    }
    Ok(KRoot { k, steady, evals })
}

/// The bracket `(s_lo, g_lo, s_up, g_up)` of `start` with its lower end stepped down in s (by
/// 4, 8, 16, …) until `g` there is no longer positive, the upper end following; the lowest
/// step is ln `ulp_floor` (the lowest K above K_min that double precision resolves: K_min +
/// K_min ε is at least one ulp above it). `None` when `g` is still positive there.
fn step_down(
    start: (f64, f64, f64, f64),
    ulp_floor: f64,
    mut g: impl FnMut(f64) -> f64,
) -> Option<(f64, f64, f64, f64)> {
    let (mut s_lo, mut g_lo, mut s_up, mut g_up) = start;
    let mut step = 4.0;
    while g_lo > 0.0 {
        s_up = s_lo;
        g_up = g_lo;
        s_lo -= step;
        step *= 2.0;
        if s_lo.exp() < ulp_floor {
            s_lo = ulp_floor.ln();
            g_lo = g(s_lo);
            if g_lo > 0.0 {
                return None;
            }
            break;
        }
        g_lo = g(s_lo);
    }
    Some((s_lo, g_lo, s_up, g_up))
}

/// The sign change of `g` (increasing in s) near `seed`: g at the seed, then at steps of
/// `seed.step` growing eightfold away from it towards the root (at most six), inside
/// (`s_min`, `s_hi`] where g(`s_hi`) = `g_hi` > 0. Gives (s_lo, g_lo, s_up, g_up) with g_lo ≤ 0
/// ≤ g_up, or `None` (the caller then searches from the top).
fn seeded_bracket(
    seed: Seed,
    (s_min, s_hi, g_hi): (f64, f64, f64),
    mut g: impl FnMut(f64) -> f64,
) -> Option<(f64, f64, f64, f64)> {
    let mut s1 = seed.s.min(s_hi);
    if !(s1 > s_min) {
        return None;
    }
    let mut g1 = g(s1);
    let mut step = seed.step;
    for _ in 0..6 {
        if g1 == 0.0 {
            return Some((s1, g1, s1, g1));
        }
        // g rises with s: the root is below a point where g > 0.
        let s2 = if g1 > 0.0 { s1 - step } else { s1 + step };
        if s2 >= s_hi {
            return Some((s1, g1, s_hi, g_hi));
        }
        if !(s2 > s_min) {
            return None;
        }
        let g2 = g(s2);
        if (g1 > 0.0) != (g2 > 0.0) || g2 == 0.0 {
            return Some(if s1 < s2 {
                (s1, g1, s2, g2)
            } else {
                (s2, g2, s1, g1)
            });
        }
        (s1, g1) = (s2, g2);
        step *= 8.0;
    }
    None
}

/// Relative tolerance on v at the ends of the steady range: the rounding of v̄ by the
/// forward models there (measured up to 49 ε for stick-approx near its limit A = B,
/// src/fit/suite/k_edges.rs).
const ROUNDING: f64 = 128.0 * f64::EPSILON;

/// v is slower than the motion at `k`, the lowest steady K that double precision resolves
/// above K_min. Either by rounding only, and then `k` is the root; or near a crawl end, where
/// the contact time grows as a − b ln(K − K_min) (module docs of [`super`]): a and b from the
/// model at 2⁶ and 2¹² steps of K_min ε above K_min give the distance d* at which τ = τ*.
/// Where d* is at least half a step, the root is resolved to within a few ulp by `k` itself;
/// below that it rounds to K_min, where the bead stops: v is below the range (regime A).
fn below_resolution(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    tau_star: f64,
    k: f64,
    steady: Steady,
    evals: usize,
) -> Result<KRoot, KFailure> {
    let mut evals = evals;
    if tau_star - steady.contact_time <= ROUNDING * tau_star {
        // v is the motion at `k` to rounding (v̄ flat near K_min, as where K² w_f² is below
        // the rounding of the squared speed it adds to).
        return Ok(KRoot { k, steady, evals });
    }
    let step = (br.lo * f64::EPSILON).max(f64::MIN_POSITIVE);
    let (d1, d2) = (64.0 * step, 4096.0 * step);
    let t1 = eval(model, scene, br.lo + d1, &mut evals).map(|s| s.contact_time);
    let t2 = eval(model, scene, br.lo + d2, &mut evals).map(|s| s.contact_time);
    if let (Ok(t1), Ok(t2)) = (t1, t2) {
        let b = (t1 - t2) / (d2 / d1).ln();
        let d_star = d1 * (-(tau_star - t1) / b).exp();
        if b > 0.0 && d_star >= 0.5 * step {
            return Ok(KRoot { k, steady, evals });
        }
    }
    Err(KFailure::BelowRange)
}

/// Whether v̄(K) is continuous in K inside its bracket. The rolling models are: the contact
/// time is an integral of (w0² + g(θ))^{-1/2} with w0 = K Θ̇f (eqs 11–27, eq 29 for the
/// approximation), continuous in K while the speed stays positive, which is what the bracket
/// holds. So are the slip models: the same with the factor e^{2fθ} (§4.3), or the elliptic
/// integral of a′ + p cos(θ − θ*) with coefficients continuous in K (eqs 53–59). Stick/slip and
/// the general contact model can jump where the fixed point of the collision map changes branch
/// or a phase appears.
fn continuous_in_k(model: &Model) -> bool {
    matches!(
        model,
        Model::Stick | Model::StickApprox | Model::Slip | Model::SlipApprox
    )
}

/// Accepts a root `k` of τ(K) = τ* whose residual is above 1e-9 τ*: either K is resolved to
/// its last bits where τ is steep (near the crawl end one ulp of K moves τ by a visible
/// step), or v̄(K) jumps over v, or v is slower than the slowest motion at any K that double
/// precision distinguishes from K_min.
///
/// Within a few u = 2ε K of K_min, K is the lowest steady K resolved above K_min: v slower than the motion there is decided by
/// [`below_resolution`]. A model
/// continuous in K ([`continuous_in_k`]) otherwise has its root where Brent's method put it
/// (its bracket held a sign change). Elsewhere τ* must lie between τ at K ∓ w for w = u, 4u or
/// 16u (the wider pairs where rounding makes τ uneven at the scale of an ulp), and the step
/// between them must be one a continuous function makes ([`steady_step`]).
fn resolved(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    tau_star: f64,
    k: f64,
    steady: &Steady,
    evals: &mut usize,
) -> Result<(), KFailure> {
    let u = 2.0 * f64::EPSILON * k;
    let jump = || KFailure::Invalid(format!("v(K) jumps at K = {k}: no K gives this velocity"));
    let mut tau_at = |k: f64| eval(model, scene, k, evals).map(|s| s.contact_time);
    let below = tau_at(k - u);
    let above = tau_at((k + u).min(br.hi));
    if k - u <= br.lo + 4.0 * u {
        // The bottom of the steady range, within rounding of K_min, where every model rolls
        // over the top and so is continuous in K.
        return if steady.contact_time < tau_star {
            below_resolution(model, scene, br, tau_star, k, *steady, 0).map(|_| ())
        } else {
            Ok(())
        };
    }
    if continuous_in_k(model) {
        return Ok(());
    }
    let mut pair = (below, above);
    for w in [u, 4.0 * u, 16.0 * u] {
        let (km, kp) = (k - w, (k + w).min(br.hi));
        if w > u {
            pair = (tau_at(km), tau_at(kp));
        }
        if let (Ok(a), Ok(b)) = pair {
            if (a - tau_star) * (b - tau_star) <= 0.0 {
                let continuous = (a - b).abs() <= 1e-3 * tau_star
                    || steady_step(model, scene, br, (km, a), (kp, b), evals);
                return if continuous { Ok(()) } else { Err(jump()) };
            }
        }
    }
    Err(jump())
}

/// Whether the step of τ from K = `m.0` to `p.0` (values `m.1`, `p.1`) is what a continuous
/// τ(K) makes there, by two tests; a jump of size J fails both.
///
/// 1. Slope in s = ln(K − K_min), where τ is close to linear near the crawl end (module docs
///    of [`super`]): over a stencil 16 times wider than the step in s (never under 0.05; at
///    least 8 times where the top of the bracket clips it), the slope predicts the step; a
///    jump gives the stencil a slope of at most J over its width, so its step is more than
///    four times the prediction.
/// 2. Growth with the width: the step across 8 times the distance is at least 3 times the
///    step (a continuous function's grows about 8-fold unless it bends sharply; a jump's stays
///    J). This one serves near the top end, where s is not the natural variable.
fn steady_step(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    m: (f64, f64),
    p: (f64, f64),
    evals: &mut usize,
) -> bool {
    let step = (p.1 - m.1).abs();
    let tau_at = |k: f64, evals: &mut usize| {
        (k > br.lo && k <= br.hi)
            .then(|| eval(model, scene, k, evals).ok())
            .flatten()
            .map(|st| st.contact_time)
    };
    // 1. The slope in s.
    let s_of = |x: f64| (x - br.lo).ln();
    let step_s = s_of(p.0) - s_of(m.0);
    if step_s > 0.0 {
        let half = (8.0 * step_s).max(0.025);
        let s0 = 0.5 * (s_of(p.0) + s_of(m.0));
        let s_top = s_of(br.hi);
        let stencils = [
            (s0 - half, s0 + half),
            (s0 - 2.0 * half, s0),
            (s0, s0 + 2.0 * half),
        ];
        for (sa, sb) in stencils {
            // Clipped to the top of the bracket, if still eight steps wide.
            let sb = sb.min(s_top);
            if sb - sa < 8.0 * step_s {
                continue;
            }
            let ka = br.lo + sa.exp();
            let kb = br.lo + sb.exp();
            if let (Some(ta), Some(tb)) = (tau_at(ka, evals), tau_at(kb, evals)) {
                let predicted = (tb - ta).abs() / (sb - sa) * step_s;
                if step <= 4.0 * predicted {
                    return true;
                }
                break;
            }
        }
    }
    // 2. Growth with the width.
    let w = p.0 - m.0;
    let mid = 0.5 * (p.0 + m.0);
    let wide = [
        (mid - 4.0 * w, mid + 4.0 * w),
        (mid - 8.0 * w, mid),
        (mid, mid + 8.0 * w),
    ];
    for (ka, kb) in wide {
        if let (Some(ta), Some(tb)) = (tau_at(ka, evals), tau_at(kb, evals)) {
            return (tb - ta).abs() >= 3.0 * step;
        }
    }
    false
}

fn clamp_end(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    (v, seed): (f64, Option<Seed>),
    end: &'static str,
    notes: &mut Vec<String>,
) -> Option<f64> {
    let side = if end == "K_lo" {
        "v - sigma_v"
    } else {
        "v + sigma_v"
    };
    match solve_with(model, scene, br, v, seed) {
        Ok(r) => Some(r.k),
        Err(KFailure::BelowRange) => {
            notes.push(end_note(end, side, AtEnd::Below));
            Some(br.lo)
        }
        Err(KFailure::AboveRange) => {
            notes.push(end_note(end, side, AtEnd::Above));
            Some(br.hi)
        }
        Err(KFailure::Invalid(_)) if v <= 0.0 => {
            notes.push(end_note(end, side, AtEnd::NotPositive));
            Some(br.lo)
        }
        Err(KFailure::Invalid(why)) => {
            notes.push(format!("no {end}: {why}"));
            None
        }
    }
}

/// [`estimate`](fn@super::estimate) by the general search in K: [`bracket`], then [`solve`] at v and v ± σ.
#[cfg(test)]
pub(crate) fn estimate_in_k(
    model: &Model,
    scene: &Scene,
    v: f64,
    sigma_v: Option<f64>,
) -> KEstimate {
    estimate_in_k_or(model, scene, v, sigma_v, |_, _| None)
}

/// [`estimate_in_k`], unless `on_bracket`, given the bracket and the scene the search would
/// use, returns the estimate itself.
pub(crate) fn estimate_in_k_or(
    model: &Model,
    scene: &Scene,
    v: f64,
    sigma_v: Option<f64>,
    on_bracket: impl FnOnce(&Scene, &KBracket) -> Option<KEstimate>,
) -> KEstimate {
    // The rolling models need tan(δ/2) in double-double near δ_m, at every K the search
    // tries there: computed once for the row where the bead crawls over the top at K_min
    // (Θ0 < 0), the end of the range where the factor of the top speed vanishes; not where
    // the analytic bracket is already empty, which no evaluation follows.
    let kept;
    let rolling = matches!(model, Model::Stick | Model::StickApprox | Model::StickSlip);
    let scene = if rolling && scene.theta_0 < 0.0 && !empty_rolling_bracket(model, scene) {
        kept = scene.with_tan_half_delta();
        &kept
    } else {
        scene
    };
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
    if let Some(e) = on_bracket(scene, &br) {
        return e;
    }
    let root = solve(model, scene, &br, v);
    let mut notes = Vec::new();
    if root == Err(KFailure::BelowRange) && v >= br.v_lo {
        notes.push(format!(
            "v = {} is slower than the motion at any K that double precision distinguishes \
             from K_min = {} (v̄ → 0 only as K → K_min, where the bead stops)",
            crate::numfmt::fmt_sig(v, 4),
            br.lo
        ));
    }
    // dv̄/dK's stencil also seeds the searches for K_lo and K_hi where v̄(K) is smooth.
    let mut stencil = Vec::with_capacity(2);
    let dv_dk = root.as_ref().ok().and_then(|r| {
        let mut n = 0;
        dv_dk(&br, r.k, r.steady.mean_velocity, |k| {
            let v = eval(model, scene, k, &mut n).ok().map(|s| s.mean_velocity);
            stencil.extend(v.map(|v| (k, v)));
            v
        })
    });
    let seed = |v_end: f64| match (&root, &stencil[..]) {
        (Ok(r), &[p1, p2]) if continuous_in_k(model) => {
            Seed::near(&br, (r.k, r.steady.mean_velocity), [p1, p2], v_end)
        }
        _ => None,
    };
    let (k_lo, k_hi) = match sigma_v {
        Some(s) => (
            clamp_end(model, scene, &br, (v - s, seed(v - s)), "K_lo", &mut notes),
            clamp_end(model, scene, &br, (v + s, seed(v + s)), "K_hi", &mut notes),
        ),
        None => (None, None),
    };
    let (dv_dk, tg) = match &root {
        Ok(r) => (
            dv_dk,
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

/// f′(x0) of the quadratic through (x0, f0), (x0 + a1, f1) and (x0 + a2, f2): the three-point
/// Lagrange derivative on any spacing.
fn quadratic_slope((f0, f1, f2): (f64, f64, f64), a1: f64, a2: f64) -> f64 {
    -f0 * (a1 + a2) / (a1 * a2) + f1 * a2 / (a1 * (a2 - a1)) - f2 * a1 / (a2 * (a2 - a1))
}

/// dv̄/dK at K = `k0` inside the bracket `br`, where v̄ = `v0`, from `v_at` (v̄ at a K, or
/// `None` where there is no steady state) at K_min + d e^{±h}, d = K − K_min, h = 1e-5
/// (steps uniform in s = ln(K − K_min), which keeps their size right where the slope in K is
/// nearly infinite), differenced over the K values actually evaluated (a three-point Lagrange
/// derivative at `k0`, second-order accurate on any spacing). Near the bracket's top, where
/// K_min + d e^h is out of range, the step is shrunk to fit and, failing that, the points are
/// taken at s − h and s − 2h (one-sided, still second order); a first-order one-sided
/// difference would be off by 5e-4 below lift-off (src/fit/suite/k_inversion.rs, mpmath
/// references). Used by the K inversion (`dv_dK` of `fitbead k`) and by the K-law fits'
/// Jacobian ([`crate::fit::klaw`]).
pub(crate) fn dv_dk(
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
    let (a1, a2) = (k1 - k0, k2 - k0);
    let dv = quadratic_slope((v0, v1, v2), a1, a2);
    dv.is_finite().then_some(dv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::k::types::LowerLimit;
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
