//! Stick/slip model (§4.4, eqs 64–68): after each collision the bead rolls from Θ0 until the
//! friction demand reaches f at Θ_G (eq 36), then slips forward to Θf (eqs 66–67). The steady
//! state is a fixed point of the final-velocity map, found by following the map from the
//! rolling steady state (docs/PHYSICS.md#stickslip): the map is not smooth and need not have a
//! unique fixed point, so every root is checked for continuity and stability, and a second
//! fixed point is looked for where the map's asymptotic slope K e^{2fα} is near or above 1.

use super::regimes::theta_g;
use super::slip::{slip_time, SlipPhase};
use super::stick;
use super::{NotSteady, Outcome, Phases, Steady};
use crate::scene::{CollisionLaw, Scene};
use crate::special::root::{brent, golden_max};
use std::cell::Cell;

/// Which phases one contact goes through under the stick/slip model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Branch {
    /// Θ_G ≥ Θf: rolls over the whole contact.
    NoSlip,
    /// Θ0 < Θ_G < Θf: rolls, then slips.
    RollSlip,
    /// Θ_G ≤ Θ0: slips from the start.
    SlipFromStart,
}

/// One application of the final-velocity map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MapStep {
    /// Final velocity on this bead.
    pub final_velocity: f64,
    /// Phases of this contact.
    pub branch: Branch,
    /// Θ_G of this contact (radians).
    pub theta_g: f64,
}

/// The final-velocity map H: final velocity `x` on the previous bead → final velocity on this
/// one (collision Θ̇0 = K x, rolling restarts, eqs 64–67).
pub(crate) fn map(scene: &Scene, x: f64) -> Result<MapStep, NotSteady> {
    let w0sq = scene.k * scene.k * x * x;
    let s0 = scene.sc_half_0.s;
    launch(scene, w0sq, w0sq - 2.0 * scene.b * s0 * s0)
}

/// One contact launched at Θ0 with squared speed `w0sq` (the map without the collision: it
/// does not involve K). `top_sq` = w0sq − 2B sin²(Θ0/2) is the squared speed the rolling law
/// gives at the top Θ = 0, passed by the caller so that a launch just above the crawl speed
/// keeps its digits (it decides whether the bead passes the top when Θ0 < 0).
pub(crate) fn launch(scene: &Scene, w0sq: f64, top_sq: f64) -> Result<MapStep, NotSteady> {
    let b = scene.b;
    let Some(tg) = theta_g(scene, w0sq) else {
        return Err(NotSteady::LiftOff {
            angle: scene.theta_0,
        });
    };
    if scene.theta_0 < 0.0 && tg > 0.0 && top_sq <= 0.0 {
        return Err(NotSteady::Stops {
            angle: stick::stop_angle(scene, w0sq),
        });
    }
    let (xf_sq, branch, phase) = if tg >= scene.theta_f {
        (
            w0sq + 2.0 * b * scene.sin_delta_sin_alpha(),
            Branch::NoSlip,
            None,
        )
    } else if tg <= scene.theta_0 {
        let ph = SlipPhase::new(scene.theta_0, w0sq, scene.f);
        (ph.speed_sq(scene.theta_f), Branch::SlipFromStart, Some(ph))
    } else {
        let wg_sq = stick::rolling_speed_sq(b, scene.theta_0, w0sq, tg);
        let ph = SlipPhase::new(tg, wg_sq, scene.f);
        (ph.speed_sq(scene.theta_f), Branch::RollSlip, Some(ph))
    };
    if let Some(ph) = phase {
        // With strong friction the slip may decelerate the bead to a stop before Θf.
        if ph.speed_sq_slope(ph.theta_s) < 0.0 {
            check_slip_positive(&ph, scene.theta_f)?;
        }
    }
    if !(xf_sq > 0.0) {
        return Err(NotSteady::Stops {
            angle: scene.theta_f,
        });
    }
    if scene.sc_f.c - xf_sq < 0.0 {
        return Err(NotSteady::LiftOff {
            angle: scene.theta_f,
        });
    }
    Ok(MapStep {
        final_velocity: xf_sq.sqrt(),
        branch,
        theta_g: tg,
    })
}

/// Contact time of a launch (eqs 64–65): rolling to Θ_G by Carlson's form, slip to Θf by
/// quadrature to `tol`; `w0sq`, `top_sq` and `step` as given to and returned by [`launch`].
pub(crate) fn launch_time(
    scene: &Scene,
    w0sq: f64,
    top_sq: f64,
    step: &MapStep,
    tol: f64,
) -> Result<f64, NotSteady> {
    let b = scene.b;
    let tau = match step.branch {
        Branch::NoSlip => stick::rolling_time_top(b, scene.theta_0, scene.theta_f, w0sq, top_sq),
        Branch::SlipFromStart => SlipPhase::new(scene.theta_0, w0sq, scene.f)
            .time_to(scene.theta_f, tol)
            .ok(),
        Branch::RollSlip => {
            let tg = step.theta_g;
            let t1 = stick::rolling_time_top(b, scene.theta_0, tg, w0sq, top_sq);
            let wg_sq = stick::rolling_speed_sq(b, scene.theta_0, w0sq, tg);
            let ph = SlipPhase::new(tg, wg_sq, scene.f);
            let t2 = slip_time(&ph, tg, scene.theta_f, tol).ok();
            t1.zip(t2).map(|(a, b)| a + b)
        }
    };
    tau.filter(|t| t.is_finite() && *t > 0.0)
        .ok_or(NotSteady::Invalid {
            reason: "stick/slip contact time not finite",
        })
}

fn check_slip_positive(ph: &SlipPhase, end: f64) -> Result<(), NotSteady> {
    let a = ph.theta_s;
    let ga = ph.speed_sq_slope(a);
    let gb = ph.speed_sq_slope(end);
    let tm = if gb <= 0.0 {
        end
    } else {
        brent(|t| ph.speed_sq_slope(t), a, end, ga, gb, 1e-15, 200)
            .map(|r| r.x)
            .unwrap_or(end)
    };
    let m = ph.speed_sq(tm);
    if m > 0.0 {
        Ok(())
    } else {
        let angle = brent(|t| ph.speed_sq(t), a, tm, ph.ws_sq, m, 1e-15, 200)
            .map(|r| r.x)
            .unwrap_or(a);
        Err(NotSteady::Stops { angle })
    }
}

/// g(x) = H(x) − x with the map's failures mapped to the side they belong to: a bead that
/// stops is "slower than any fixed point", one that lifts off "faster".
fn excess(scene: &Scene, x: f64) -> f64 {
    excess_of(&map(scene, x), x)
}

/// [`excess`] from the map's step at x, for callers that need the step too.
fn excess_of(step: &Result<MapStep, NotSteady>, x: f64) -> f64 {
    match step {
        Ok(m) => m.final_velocity - x,
        Err(NotSteady::Stops { .. }) => -x.max(1e-300),
        Err(_) => f64::INFINITY,
    }
}

/// A continuous root of g in [a, b] (g(a), g(b) of opposite signs), or the jump it straddles.
fn refine(scene: &Scene, a: f64, b: f64, ga: f64, gb: f64) -> Result<f64, NotSteady> {
    let (lo, hi, glo, ghi) = if a < b {
        (a, b, ga, gb)
    } else {
        (b, a, gb, ga)
    };
    let glo = glo.clamp(-1e300, 1e300);
    let ghi = ghi.clamp(-1e300, 1e300);
    let r = brent(
        |x| excess(scene, x).clamp(-1e300, 1e300),
        lo,
        hi,
        glo,
        ghi,
        0.0,
        200,
    )
    .ok_or(NotSteady::Invalid {
        reason: "fixed-point bracket lost",
    })?;
    // A true fixed point has g → 0; a jump of the map leaves |g| finite at the "root".
    if r.fx.abs() <= 1e-9 * r.x.max(1e-3) {
        Ok(r.x)
    } else {
        Err(NotSteady::MapJump { at: r.x })
    }
}

/// Fixed point of the final-velocity map reached from `x0` (the way a bead launched there
/// evolves), with the bracket search accelerated by Aitken extrapolation.
pub(crate) fn fixed_point_from(scene: &Scene, x0: f64) -> Result<f64, NotSteady> {
    // Where the map's asymptotic slope K e^{2fα} is well below 1 the fixed point is unique (the
    // same premise as [`steady_tol`]'s search for a second one), so any convergent iteration
    // finds the one the bead settles on: try the secant method first.
    let unique = scene.k * (2.0 * scene.f * scene.alpha).exp() < 0.95;
    if unique {
        if let Some(x) = secant_fixed_point(scene, x0) {
            return Ok(x);
        }
    }
    match follow(scene, x0) {
        // Following the map ended in a definite lift-off or stop of an iterate (not in an
        // iteration cap): with a single fixed point there is none to find beyond it.
        Err(e @ (NotSteady::LiftOff { .. } | NotSteady::Stops { .. })) if unique => Err(e),
        Err(e @ (NotSteady::Runaway | NotSteady::LiftOff { .. } | NotSteady::Stops { .. })) => {
            match stable_branch_fixed_point(scene, x0) {
                Some(x) => Ok(x),
                None => scan(scene, x0).unwrap_or(Err(e)),
            }
        }
        r => r,
    }
}

/// The stable fixed point below a saddle-node of the map, found in launch space (the view of
/// src/fit/k/launch.rs): a launch at Θ0 with squared top speed y is the fixed point of
/// K(y) = Θ̇0/Φ(Θ̇0), and K(y) rises from the crawl to a maximum K_sn at the saddle-node; the
/// stable fixed point for K ≤ K_sn solves K(y) = K below that maximum, where K(y) is monotone
/// (Brent). Near the saddle-node the map's slope is so close to 1 that following it does not
/// settle and the grid of [`scan`] misses the pair of fixed points (3e-5 apart within ~1e-9 of
/// it; where the saddle-node lies just below lift-off, up to 5.1e-7 below it on the random
/// measured file of `scripts/gen_measurements.py`); this finds them. `None` unless
/// [`saddle_node`] finds the maximum, K ≤ K_sn, and the launch speed x0 the bead starts from is
/// below the saddle-node's (so that the bead, following the map, settles on this fixed point).
fn stable_branch_fixed_point(scene: &Scene, x0: f64) -> Option<f64> {
    let sn = saddle_node(scene)?;
    if !(scene.k <= sn.k && scene.k > sn.k_low && x0 <= sn.x) {
        return None;
    }
    let g = |y: f64| sn.k_at(scene, y).map_or(f64::NAN, |p| p.0 - scene.k);
    let root = brent(
        g,
        sn.y_low,
        sn.y,
        sn.k_low - scene.k,
        sn.k - scene.k,
        0.0,
        200,
    )?;
    let (_, x) = sn.k_at(scene, root.x)?;
    // A true fixed point of the map at this K.
    let back = map(scene, x).ok()?.final_velocity;
    ((back - x).abs() <= 1e-10 * x).then_some(x)
}

/// The saddle-node of the final-velocity map in launch space (see
/// [`stable_branch_fixed_point`]): the maximum K_sn of K(y) = Θ̇0/Φ(Θ̇0) over the launches y,
/// which does not depend on the scene's own K.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SaddleNode {
    /// K_sn, the largest K with a fixed point of the map on this branch.
    pub(crate) k: f64,
    /// The launch speed Θ̇0 there.
    pub(crate) x: f64,
    /// y at the saddle-node (the squared top speed for Θ0 < 0, else Θ̇0²).
    y: f64,
    /// The lowest y of the grid, and K(y) there.
    y_low: f64,
    k_low: f64,
    /// 2B sin²(Θ0/2) for Θ0 < 0 (Θ̇0² = y + wc2), else 0.
    wc2: f64,
}

impl SaddleNode {
    /// K(y) and Φ at the launch y.
    fn k_at(&self, scene: &Scene, y: f64) -> Option<(f64, f64)> {
        k_of_launch(scene, self.wc2, y)
    }
}

/// K(y) = Θ̇0/Φ(Θ̇0) and Φ for the launch y, with Θ̇0² = y + `wc2` (see [`SaddleNode`]).
fn k_of_launch(scene: &Scene, wc2: f64, y: f64) -> Option<(f64, f64)> {
    launch(scene, y + wc2, y)
        .ok()
        .map(|m| ((y + wc2).sqrt() / m.final_velocity, m.final_velocity))
}

/// [`SaddleNode`] of the scene's map: `None` unless (for Θ0 < 0) the slip starts after the top
/// at the crawl, and the maximum of K(y) is bracketed on a 56-point grid (40 log-spaced, 16
/// crowding towards lift-off) and refined by golden section. Where the first launch of the
/// grid that fails comes before K(y) is seen to fall, the launches that pass end (the bead
/// lifts off at Θf, say) between two grid points, and the maximum can lie just below that end:
/// the end is found by bisection on whether the launch passes (to 1e-13 relative), and 16 more
/// points crowd towards it from the last grid point that passed; the scan for the fall goes on
/// over them.
///
/// It does not depend on the scene's K, which is all that changes between the evaluations of
/// one K inversion (every status test near the top of stick/slip's bracket asks for it, at
/// ~1e5 instructions each): the last scene's result is kept per thread and returned for a
/// scene equal to it apart from K.
pub(crate) fn saddle_node(scene: &Scene) -> Option<SaddleNode> {
    thread_local! {
        static LAST: Cell<Option<(Scene, Option<SaddleNode>)>> = const { Cell::new(None) };
    }
    let mut key = *scene;
    key.k = 1.0;
    key.law = CollisionLaw::Value(1.0);
    if let Some((last, sn)) = LAST.get() {
        if last == key {
            return sn;
        }
    }
    let sn = saddle_node_of(scene);
    LAST.set(Some((key, sn)));
    sn
}

fn saddle_node_of(scene: &Scene) -> Option<SaddleNode> {
    // With Θ0 < 0, y is the squared top speed (y = Θ̇0² − 2B sin²(Θ0/2)); else y = Θ̇0².
    let s0 = scene.sc_half_0.s;
    let wc2 = if s0 < 0.0 {
        2.0 * scene.b * s0 * s0
    } else {
        0.0
    };
    if s0 < 0.0 && !theta_g(scene, wc2).is_some_and(|t| t > 0.0) {
        return None;
    }
    let k_at = |y: f64| k_of_launch(scene, wc2, y);
    // Launches up to lift-off at Θf: Θ̇0² ≤ cos Θf.
    let y_top = scene.sc_f.c - wc2;
    if !(y_top > 0.0) {
        return None;
    }
    let mut grid: Vec<f64> = (0..40)
        .map(|i| y_top * 10f64.powf(-8.0 * (39 - i) as f64 / 39.0))
        .collect();
    grid.extend((1..=16).map(|j| y_top * (1.0 - 0.6 * 0.75f64.powi(j))));
    grid.sort_by(f64::total_cmp);
    let mut prev = f64::NEG_INFINITY;
    let mut peak = None;
    let mut refined = false;
    let mut i = 0;
    while i < grid.len() {
        let Some((k, _)) = k_at(grid[i]) else {
            if refined || i < 2 {
                break;
            }
            // The last launch that passes, between the last grid point that did and this one;
            // the grid goes on from the former towards it.
            refined = true;
            let y0 = grid[i - 1];
            let mut ok = y0;
            let mut bad = grid[i];
            // At most 64 halvings (1e-13 of the gap is ~43): the bound also ends it where the
            // two are adjacent doubles wider apart than 1e-13 (subnormal y).
            for _ in 0..64 {
                let mid = 0.5 * (ok + bad);
                if !(bad - ok > 1e-13 * bad) || mid == ok || mid == bad {
                    break;
                }
                if k_at(mid).is_some() {
                    ok = mid;
                } else {
                    bad = mid;
                }
            }
            grid.truncate(i);
            grid.extend((1..=16).map(|j| ok - (ok - y0) * 0.75f64.powi(j)));
            grid.push(ok);
            continue;
        };
        if k <= prev {
            peak = Some(i);
            break;
        }
        prev = k;
        i += 1;
    }
    let i = peak?;
    if i < 2 {
        return None;
    }
    let f = |u: f64| k_at(u.exp()).map_or(f64::NEG_INFINITY, |p| p.0);
    let (a, b) = (grid[i - 2].ln(), grid[i].ln());
    let a = golden_max(f, a, b, 1e-12 * (b - a), 100);
    let y = a.exp();
    let (k, x) = k_at(y)?;
    let (k_low, _) = k_at(grid[0])?;
    Some(SaddleNode {
        k,
        x,
        y,
        y_low: grid[0],
        k_low,
        wc2,
    })
}

/// The secant method on g(x) = H(x) − x from x0 and x0 + g(x0) (one step of the map): about
/// six map evaluations to full precision where following the map with Aitken steps and a
/// Brent refinement needed about sixteen. `None` (the caller falls back to [`follow`]) as
/// soon as the map fails, an iterate leaves (0, lift-off), or the iteration does not settle
/// within 40 steps; an accepted root has |g| at the rounding level of the map, so it is a true
/// fixed point, not a jump.
fn secant_fixed_point(scene: &Scene, x0: f64) -> Option<f64> {
    let x_hi = scene.sc_f.c.max(0.0).sqrt();
    let g = |x: f64| map(scene, x).ok().map(|m| m.final_velocity - x);
    let (mut xa, mut ga) = (x0, g(x0)?);
    if ga == 0.0 {
        return Some(x0);
    }
    let mut xb = x0 + ga;
    if !(xb > 0.0 && xb < x_hi) {
        return None;
    }
    let mut gb = g(xb)?;
    for _ in 0..40 {
        if gb.abs() <= 16.0 * f64::EPSILON * xb {
            return Some(xb);
        }
        let den = gb - ga;
        if den == 0.0 {
            return None;
        }
        let xn = xb - gb * (xb - xa) / den;
        if !(xn > 0.0 && xn < x_hi) {
            return None;
        }
        if (xn - xb).abs() <= 2.0 * f64::EPSILON * xb {
            // The step is below the rounding of x: accept if g is at its noise level.
            return (gb.abs() <= 1e-12 * xb).then_some(xn);
        }
        xa = xb;
        ga = gb;
        xb = xn;
        gb = g(xb)?;
    }
    None
}

/// Fallback of [`fixed_point_from`] for maps whose slope is so close to 1 at the fixed point
/// (near a saddle-node of the map) that following it does not converge: the first sign
/// change of H(x) − x on a 64-point grid from `x0` towards lift-off (or towards 0 when the map
/// goes down), refined by Brent with the continuity check.
fn scan(scene: &Scene, x0: f64) -> Option<Result<f64, NotSteady>> {
    let x_hi = scene.sc_f.c.max(0.0).sqrt();
    let g0 = excess(scene, x0);
    let up = g0 > 0.0;
    let end = if up { x_hi } else { 0.0 };
    let n = 64;
    let (mut a, mut ga) = (x0, g0);
    for i in 1..=n {
        let b = x0 + (end - x0) * i as f64 / n as f64;
        let b = if i == n && up {
            b * (1.0 - 1e-12)
        } else {
            b.max(1e-300)
        };
        let gb = excess(scene, b);
        if (gb > 0.0) != up || gb == 0.0 {
            return Some(refine(scene, a, b, ga, gb));
        }
        a = b;
        ga = gb;
    }
    None
}

fn follow(scene: &Scene, x0: f64) -> Result<f64, NotSteady> {
    let x_hi = scene.sc_f.c.max(0.0).sqrt();
    let mut x = x0;
    let mut gx = excess(scene, x);
    if gx == 0.0 {
        return Ok(x);
    }
    let up = gx > 0.0;
    for _ in 0..60 {
        // Two plain steps of the map, then an Aitken estimate of the limit.
        if gx.abs() <= 16.0 * f64::EPSILON * x {
            // H(x) = x to within the rounding of the map itself: no sign change can be
            // resolved closer (slopes near 1 leave a one-sided rounding bias).
            return Ok(x);
        }
        let x1 = x + gx;
        let step_1 = map(scene, x1);
        let g1 = excess_of(&step_1, x1);
        if (g1 > 0.0) != up || g1 == 0.0 {
            return refine(scene, x, x1, gx, g1);
        }
        if !g1.is_finite() || x1 > x_hi {
            return Err(step_1.err().unwrap_or(NotSteady::Runaway));
        }
        if x1 <= 0.0 {
            return Err(map(scene, x1.max(1e-300))
                .err()
                .unwrap_or(NotSteady::Stops {
                    angle: scene.theta_0,
                }));
        }
        let x2 = x1 + g1;
        let d2 = g1 - gx; // (x2 − x1) − (x1 − x)
        let mut xe = if d2 != 0.0 && (up && d2 < 0.0 || !up && d2 > 0.0) {
            x - gx * gx / d2
        } else {
            x2 + 2.0 * g1
        };
        if !(xe.is_finite()) || xe <= 0.0 {
            xe = x2;
        }
        let step_e = map(scene, xe);
        if let Err(fail) = step_e {
            // The extrapolation overshot into launch speeds from which the bead stops (going
            // down) or lifts off (going up). The fixed point, if any, lies between x2 and the
            // boundary of that region: find the boundary and look at the map just inside it.
            let step_2 = map(scene, x2);
            let g2 = excess_of(&step_2, x2);
            if (g2 > 0.0) != up || g2 == 0.0 {
                return refine(scene, x1, x2, g1, g2);
            }
            step_2?;
            let (xb, bad) = failure_boundary(scene, x2, xe);
            let gb = excess(scene, xb);
            if (gb > 0.0) != up || gb == 0.0 {
                return refine(scene, x2, xb, g2, gb);
            }
            return Err(map(scene, bad).err().unwrap_or(fail));
        }
        let ge = excess_of(&step_e, xe);
        if (ge > 0.0) != up || ge == 0.0 {
            // Bracket between the last same-side point and the estimate.
            let g2 = excess(scene, x2);
            if (g2 > 0.0) != up || g2 == 0.0 {
                return refine(scene, x1, x2, g1, g2);
            }
            return refine(scene, x2, xe, g2, ge);
        }
        x = xe;
        gx = ge;
        if !gx.is_finite() || x > x_hi {
            return Err(step_e.err().unwrap_or(NotSteady::Runaway));
        }
    }
    Err(NotSteady::Runaway)
}

/// The last final velocity from `ok` towards `bad` whose next contact succeeds, and the first
/// that fails, by bisection to 1e-15 relative (the map succeeds at `ok`, fails at `bad`).
fn failure_boundary(scene: &Scene, mut ok: f64, mut bad: f64) -> (f64, f64) {
    for _ in 0..80 {
        let mid = 0.5 * (bad + ok);
        if (ok - bad).abs() <= 1e-15 * ok.abs() || mid == ok || mid == bad {
            break;
        }
        if map(scene, mid).is_err() {
            bad = mid;
        } else {
            ok = mid;
        }
    }
    (ok, bad)
}

fn slope_at(scene: &Scene, x: f64) -> Option<f64> {
    let h = 1e-6 * x;
    let a = map(scene, x - h).ok()?.final_velocity;
    let b = map(scene, x + h).ok()?.final_velocity;
    Some((b - a) / (2.0 * h))
}

/// Looks for another (continuous) fixed point above `x` up to lift-off.
fn other_fixed_point(scene: &Scene, x: f64) -> Option<f64> {
    let x_hi = scene.sc_f.c.max(0.0).sqrt();
    if x_hi <= x {
        return None;
    }
    let n = 64;
    let mut a = x * (1.0 + 1e-6);
    let mut ga = excess(scene, a);
    for i in 1..=n {
        let b = a + (x_hi - x) / n as f64 * if i == 1 { 1.0 - 1e-6 } else { 1.0 };
        let gb = excess(scene, b);
        if ga.is_finite() && gb.is_finite() && (ga > 0.0) != (gb > 0.0) {
            if let Ok(r) = refine(scene, a, b, ga, gb) {
                return Some(r);
            }
        }
        a = b;
        ga = gb;
    }
    None
}

/// ρ = 0: rolling needs no friction (H = 0, eq 35), so the bead never slips and the model is
/// the stick model, its regimes and the angles it reports included. (Eq 36 then gives the
/// angle where the normal force of the rolling motion vanishes, not a friction limit; it is
/// reported as Θ_G, as on the no-slip branch.)
fn rolling_without_friction(scene: &Scene) -> Outcome {
    let mut out = stick::steady(scene)?;
    out.theta_g = theta_g(scene, out.initial_velocity * out.initial_velocity);
    Ok(out)
}

/// Steady stick/slip state: mean velocity v̄'' = 2 sin α / τ'' (eq 68), τ'' = rolling time to
/// Θ_G (eq 64, Carlson form) + slip time to Θf (eq 65, quadrature to 1e-14).
pub fn steady(scene: &Scene) -> Outcome {
    steady_tol(scene, 1e-14)
}

/// [`steady`] with a chosen quadrature tolerance for the slip phase.
pub fn steady_tol(scene: &Scene, tol: f64) -> Outcome {
    steady_with(scene, tol, true)
}

/// [`steady`] without the diagnostics that cost more map evaluations than the steady state
/// itself: the map's slope at the fixed point and the search for a second fixed point (64
/// maps where K e^{2fα} ≥ 0.95). For root finders that need only v̄ and the final velocity.
pub(crate) fn steady_lean(scene: &Scene) -> Outcome {
    steady_with(scene, 1e-14, false)
}

/// Where [`settle`] ends: the rolling steady state (no slip at it, or ρ = 0), complete with
/// its contact time, or the fixed point of the final-velocity map with the map's step there.
enum Settled {
    Rolling(Steady),
    Fixed { xs: f64, step: MapStep },
}

/// The steady state's final velocity without the slip phase's contact time: the rolling
/// steady state when it needs no slip, else the fixed point of the map followed from it.
fn settle(scene: &Scene) -> Result<Settled, NotSteady> {
    if scene.rho == 0.0 {
        return rolling_without_friction(scene).map(Settled::Rolling);
    }
    let x_hi = scene.sc_f.c.max(0.0).sqrt();
    // Start from the rolling steady state when it exists (its contact time, an elliptic
    // integral, only when it is the answer).
    let x0 = match stick::rolling_velocities(scene) {
        Ok((l, w0)) => {
            let tg = theta_g(scene, w0 * w0);
            if let Some(tg) = tg {
                if tg >= scene.theta_f {
                    // No slip at the rolling steady state: it is the stick/slip fixed point,
                    // and the two models agree exactly.
                    let mut out = stick::steady(scene)?;
                    out.theta_g = Some(tg);
                    return Ok(Settled::Rolling(out));
                }
            }
            l
        }
        // No rolling steady state: follow the map down from just below lift-off, so that a
        // fast-launched bead's steady state is found where a slow one would stop.
        Err(_) => x_hi * (1.0 - 1e-9),
    };
    let xs = fixed_point_from(scene, x0.min(x_hi))?;
    let step = map(scene, xs)?;
    Ok(Settled::Fixed { xs, step })
}

/// Whether [`steady_lean`] finds a steady state here, up to its contact time: `Ok` where the
/// fixed point exists, even if the slip phase's quadrature were then to fail (the caller
/// checks the point it keeps with [`steady_lean`]). A fixed point costs a fraction of the
/// slip time's quadrature: this is the test the bracket's status bisection repeats.
pub(crate) fn steady_status(scene: &Scene) -> Result<(), NotSteady> {
    settle(scene).map(|_| ())
}

fn steady_with(scene: &Scene, tol: f64, diagnostics: bool) -> Outcome {
    let (xs, step) = match settle(scene)? {
        Settled::Rolling(s) => return Ok(s),
        Settled::Fixed { xs, step } => (xs, step),
    };
    let slope = if diagnostics {
        slope_at(scene, xs)
    } else {
        None
    };
    let asym = scene.k * (2.0 * scene.f * scene.alpha).exp();
    let other = if diagnostics && asym >= 0.95 {
        other_fixed_point(scene, xs)
    } else {
        None
    };
    let w0sq = scene.k * scene.k * xs * xs;
    let s0 = scene.sc_half_0.s;
    let tau = launch_time(scene, w0sq, w0sq - 2.0 * scene.b * s0 * s0, &step, tol)?;
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, xs, scene.k * xs, tau);
    s.theta_g = Some(step.theta_g);
    s.map_slope = slope;
    s.other_fixed_point = other;
    s.phases = match step.branch {
        Branch::NoSlip => Phases::Roll,
        Branch::RollSlip => Phases::RollSlip,
        Branch::SlipFromStart => Phases::Slip,
    };
    if scene.theta_0 < 0.0 {
        s.top_velocity_sq = Some(w0sq - 2.0 * scene.b * scene.sc_half_0.s * scene.sc_half_0.s);
    }
    Ok(s)
}
