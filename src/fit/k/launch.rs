//! K inversion (eq 69) through the launch speed: the fast path of [`super::estimate()`](super::estimate::estimate) for
//! the stick and stick/slip models.
//!
//! A contact launched at Θ0 with speed Θ̇0 = w0 ends at Θf with a speed Φ(w0) after a time
//! τ(w0), and neither involves K: K enters only through the collision, Θ̇0 = K Θ̇f. A steady
//! state is a launch that reproduces itself, so each launch speed *is* a steady state, of
//! K = w0 / Φ(w0). Eq 69 is then one equation in one unknown with no fixed point inside:
//! τ(w0) = τ* = 2 sin α / v (eq 10), one contact per evaluation instead of one fixed point
//! of the final-velocity map (stick/slip) or one closed form in K (stick).
//!
//! The unknown is u = ln y, y = w0² − 2B sin²(Θ0/2) the squared speed the rolling law gives at
//! the top (Θ0 < 0). As the bead crawls over the top (y → 0, K → K_min) the contact time grows
//! like −u/sqrt(2B): in u the equation is nearly linear at the slow end, smooth at the fast end
//! (lift-off, y_d), and y keeps its digits where K itself no longer resolves the motion. The
//! root is found from the asinh approximation of eq 29 (its error in τ is 0.1–3 %), kept
//! inside the bracket: where the bead rolls over the top, the search's single passes give
//! dτ/du in closed form (Carlson's R_D beside R_F, `Launch::over_top_times`) and it takes
//! Newton's steps; its first pass (taken beside the top's) and the paired passes of the K_lo
//! and K_hi searches go without the derivative, which costs more beside four R_F than it saves
//! there, and take the secant method's. K_lo and K_hi start from a second-order Taylor step off
//! the root; τ' there is the analytic one (and gives dv̄/dK) with τ'' from the last two Newton
//! iterates, or both come from a central difference where the passes carry no derivative.
//!
//! The path applies when Θ0 < 0 (δ < α) and, for stick/slip, when the slip starts after the top
//! at the crawl and K(w0) rises from the crawl: either all the way to lift-off (one fixed point
//! per K) or to a maximum, the saddle-node of the final-velocity map, beyond which the launches
//! belong to the unstable branch. In that second case the range ends at the saddle-node
//! (`UpperLimit::Model`), each root is checked against the forward model (it must settle on the
//! stable fixed point found here), and measurements within 1e-6 of the fastest stable motion
//! are left to the general search, where the forward model's own fixed-point search gives out.
//! Rolling rows above the steady range are reported here too: no root, K_lo and K_hi by the
//! rule of every row.
//!
//! For stick with Θ0 > 0 (δ > α) the contact starts past the top: every w0 ≥ 0 reaches Θf, K
//! runs from 0 (w0 = 0, a finite contact time τ0) to lift-off, and τ is smooth in u = ln w0²,
//! tending to τ0 as u → −∞ (`estimate_past_top`). The same secant runs there, from the time
//! on a slope of constant pitch matched to τ0 and to lift-off, on the general search's bracket
//! (whose statuses and ends it keeps); measurements within 1e-6 of either end of the range
//! are left to that search.
//! Elsewhere [`super::estimate()`](super::estimate::estimate) uses its general bracketing search in K.

use super::types::{end_note, AtEnd, KBracket, KEstimate, KFailure, KRoot, LowerLimit, UpperLimit};
use crate::models::regimes::theta_g;
use crate::models::stickslip::{self, Branch};
use crate::models::{Model, NotSteady, Phases, Steady};
use crate::scene::Scene;
use crate::special::elliptic::{cos_integral, cos_integral_pair, rf_dy_lanes};
use crate::special::root::{brent, golden_max};

/// Which contact mechanics the launch follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mechanics {
    Roll,
    RollSlip,
}

/// One contact from a launch: time, launch and final speeds.
#[derive(Debug, Clone, Copy)]
struct Pass {
    tau: f64,
    /// dτ/du (u = ln y) where the pass computes it (rolling over the top,
    /// [`Launch::over_top`]); NaN elsewhere.
    dtau: f64,
    w0: f64,
    wf: f64,
    /// Θ_G (stick/slip).
    theta_g: Option<f64>,
    /// Phases (stick/slip).
    branch: Option<Branch>,
}

impl Pass {
    fn k(&self) -> f64 {
        self.w0 / self.wf
    }
}

struct Launch<'a> {
    scene: &'a Scene,
    mech: Mechanics,
    /// Squared crawl launch speed 2B sin²(Θ0/2).
    wc2: f64,
    /// Potential drop of a rolling contact, 2B sin δ sin α (eq 9).
    drop: f64,
    /// Largest y with a steady state (lift-off at Θf).
    y_d: f64,
    /// K at the crawl.
    k_min: f64,
    /// K(w0) rises to a maximum below lift-off (a saddle-node of the final-velocity map):
    /// `y_d` is that maximum, the end of the stable branch.
    saddle: bool,
    /// Rolling with Θ0 > 0 ([`Launch::past_top`]): y is w0² itself, K_min = 0, and the range
    /// is the general search's bracket, whose ends this path leaves to that search.
    past_top: bool,
}

/// The contact time in the asinh approximation (eq 29) as a function of y:
/// τ̃(y) = 2/r [asinh(r a_f / q) + asinh(r a_0 / q)], r = sqrt(y + 2B), q = sqrt(y),
/// a = |tan(Θ/2)|; returns τ̃ and dτ̃/du (u = ln y).
fn approx_tau(b: f64, a0: f64, af: f64, y: f64) -> (f64, f64) {
    let r = (y + 2.0 * b).sqrt();
    let q = y.sqrt();
    let mut sum = 0.0;
    let mut dsum = 0.0;
    for a in [a0, af] {
        let x = r * a / q;
        sum += x.asinh();
        // dX/dy = −a B / (r q³)
        dsum += -a * b / (r * q * q * q) / (1.0 + x * x).sqrt();
    }
    let tau = 2.0 / r * sum;
    let dtau_dy = -sum / (r * r * r) + 2.0 / r * dsum;
    (tau, y * dtau_dy)
}

impl<'a> Launch<'a> {
    fn new(model: &Model, scene: &'a Scene) -> Option<Self> {
        let mech = match model {
            Model::Stick => Mechanics::Roll,
            Model::StickSlip => Mechanics::RollSlip,
            _ => return None,
        };
        let s0 = scene.sc_half_0.s;
        if !(s0 < 0.0) {
            return None;
        }
        let b = scene.b;
        let wc2 = 2.0 * b * s0 * s0;
        let drop = 2.0 * b * scene.sin_delta_sin_alpha();
        let cf = scene.sc_f.c;
        let mut l = Launch {
            scene,
            mech,
            wc2,
            drop,
            y_d: 0.0,
            k_min: -s0 / scene.sc_half_f.s,
            saddle: false,
            past_top: false,
        };
        match mech {
            Mechanics::Roll => {
                // Lift-off at Θf: w0² + drop = cos Θf.
                l.y_d = cf - drop - wc2;
            }
            Mechanics::RollSlip => {
                // Slip must start after the top at the crawl (else the crawl speed is another).
                if !theta_g(scene, wc2).is_some_and(|t| t > 0.0) {
                    return None;
                }
                let crawl = l.launch(f64::MIN_POSITIVE)?;
                l.k_min = crawl.w0 / crawl.wf;
                // Lift-off: the launch whose final speed is sqrt(cos Θf).
                let xd = cf.max(0.0).sqrt();
                // A launch that stops is slower than lift-off, one that lifts off faster.
                let q = |y: f64| match stickslip::launch(scene, y + wc2, y) {
                    Ok(st) => st.final_velocity - xd,
                    Err(NotSteady::Stops { .. }) => -xd,
                    Err(_) => xd,
                };
                let mut y_hi = (cf - wc2).max(1e-3);
                let mut q_hi = q(y_hi);
                let mut n = 0;
                while !(q_hi > 0.0) && n < 60 {
                    y_hi *= 2.0;
                    q_hi = q(y_hi);
                    n += 1;
                }
                let y_lo = f64::MIN_POSITIVE;
                let r = brent(q, y_lo, y_hi, crawl.wf - xd, q_hi, 0.0, 200)?;
                // The largest launch at or below lift-off: within a few ulp of Brent's answer
                // when Φ crosses sqrt(cos Θf) continuously; otherwise the range ends at a
                // jump of the map (the launch stops or lifts off elsewhere): leave that to
                // the general search.
                let mut y = r.x;
                let mut steps = 0;
                while !l.launch(y).is_some_and(|p| p.wf <= xd) {
                    y *= 1.0 - 4.0 * f64::EPSILON;
                    steps += 1;
                    if steps > 64 {
                        return None;
                    }
                }
                l.y_d = y;
                // One fixed point per K: K(w0) = w0/Φ(w0) increasing from the crawl to
                // lift-off (dK/dw0 > 0 is H'(x) = K Φ'(K x) < 1 at every fixed point: no
                // saddle-node, no second branch). Where the map's asymptotic slope K e^{2fα}
                // stays below 0.95 that is the forward model's own premise; above, K(w0) is
                // checked on 41 launches — 32 log-spaced from 1e-8 y_d to y_d, 8 at
                // y_d (1 − 2^-j) and one at y_d (1 − 1e-7) — since a saddle-node below
                // lift-off shows as K falling towards y_d. Then the bracket, the statuses and
                // each root are those of the forward model, whose search starts from the
                // rolling state.
                let k_d = l.k_of_launch(y)?;
                if k_d * (2.0 * scene.f * scene.alpha).exp() >= 0.95 {
                    let mut ys: Vec<f64> = (0..32)
                        .map(|i| y * 10f64.powf(-8.0 * (31 - i) as f64 / 31.0))
                        .collect();
                    ys.extend((1..=8).map(|j| y * (1.0 - 0.5f64.powi(j))));
                    ys.push(y * (1.0 - 1e-7));
                    ys.push(y);
                    ys.sort_by(f64::total_cmp);
                    let mut k_prev = l.k_min;
                    for (i, &yi) in ys.iter().enumerate() {
                        let k = l.k_of_launch(yi)?;
                        if !(k > k_prev) {
                            // K falls: the stable branch ends at the maximum of K between
                            // ys[i-2] and ys[i], found by golden section in u to 1e-9 of
                            // that span.
                            if i < 2 {
                                return None;
                            }
                            let f = |u: f64| l.k_of_launch(u.exp()).unwrap_or(f64::NEG_INFINITY);
                            let (a, b) = (ys[i - 2].ln(), ys[i].ln());
                            let a = golden_max(f, a, b, 1e-9 * (b - a), 100);
                            l.y_d = a.exp();
                            l.saddle = true;
                            break;
                        }
                        k_prev = k;
                    }
                }
            }
        }
        (l.y_d > 0.0 && l.k_min < l.k_of_launch(l.y_d)?).then_some(l)
    }

    /// Rolling launches when the contact starts past the top (Θ0 > 0): every w0 ≥ 0 carries the
    /// bead to Θf, so the unknown is y = w0² (no crawl: `wc2` = 0) from K_min = 0 (w0 = 0,
    /// where the contact time is finite) to lift-off, y_d = cos Θf − 2B sin δ sin α (eq 30a).
    fn past_top(scene: &'a Scene) -> Option<Self> {
        if !(scene.sc_half_0.s > 0.0) {
            return None;
        }
        let drop = 2.0 * scene.b * scene.sin_delta_sin_alpha();
        let y_d = scene.sc_f.c - drop;
        (y_d > 0.0).then_some(Launch {
            scene,
            mech: Mechanics::Roll,
            wc2: 0.0,
            drop,
            y_d,
            k_min: 0.0,
            saddle: false,
            past_top: true,
        })
    }

    /// Launch and final speeds without the contact time.
    fn launch(&self, y: f64) -> Option<Pass> {
        let w0sq = y + self.wc2;
        match self.mech {
            Mechanics::Roll => Some(Pass {
                tau: f64::NAN,
                dtau: f64::NAN,
                w0: w0sq.sqrt(),
                wf: (w0sq + self.drop).sqrt(),
                theta_g: None,
                branch: None,
            }),
            Mechanics::RollSlip => {
                let st = stickslip::launch(self.scene, w0sq, y).ok()?;
                Some(Pass {
                    tau: f64::NAN,
                    dtau: f64::NAN,
                    w0: w0sq.sqrt(),
                    wf: st.final_velocity,
                    theta_g: Some(st.theta_g),
                    branch: Some(st.branch),
                })
            }
        }
    }

    /// K of a search's root: its pass's, or a launch's at its u where the root was not
    /// evaluated.
    fn k_of_found(&self, r: &Found) -> Option<f64> {
        match r.pass {
            Some(p) => Some(p.k()),
            None => self.k_of_launch(r.u.exp()),
        }
    }

    fn k_of_launch(&self, y: f64) -> Option<f64> {
        self.launch(y).map(|p| p.k())
    }

    /// dK/du at y (u = ln y). K changes by a relative O(y) over a step in u, so near the crawl a
    /// difference of K in u would cancel: rolling has the closed form, K² = w0²/(w0² + drop)
    /// gives dK/dy = drop / (2 K wf⁴); stick/slip differences Φ in w0², which is smooth
    /// through the crawl (only the contact time has a logarithm there), with step 1e-5 w0².
    /// Also returns the slope of the final-velocity map at this fixed point, H'(x) = K Φ'(w0).
    fn dk_du(&self, y: f64, p: &Pass) -> Option<(f64, f64)> {
        let k = p.k();
        match self.mech {
            Mechanics::Roll => {
                let wf2 = p.wf * p.wf;
                // Φ² = w0² + drop: H' = K w0/Φ = K².
                Some((y * self.drop / (2.0 * k * wf2 * wf2), k * k))
            }
            Mechanics::RollSlip => {
                let w0sq = y + self.wc2;
                let h = 1e-5 * w0sq;
                // The final speed depends on w0² alone; the top speed only gates the crawl.
                let phi = |dw: f64| {
                    stickslip::launch(self.scene, w0sq + dw, (y + dw).max(f64::MIN_POSITIVE))
                        .ok()
                        .map(|st| st.final_velocity)
                };
                // Central where the launch below exists, else one-sided (second order).
                let (lo, mid) = match phi(-h) {
                    Some(pm) => (-h, pm),
                    None => (0.0, p.wf),
                };
                let (hi, top) = (lo + 2.0 * h, phi(lo + 2.0 * h)?);
                let kq = |dw: f64, f: f64| (w0sq + dw).sqrt() / f;
                let (dk_dy, dphi_dy) = if lo < 0.0 {
                    (
                        (kq(hi, top) - kq(lo, mid)) / (2.0 * h),
                        (top - mid) / (2.0 * h),
                    )
                } else {
                    let (q1, f1) = (h, phi(h)?);
                    (
                        (-3.0 * kq(0.0, p.wf) + 4.0 * kq(q1, f1) - kq(hi, top)) / (2.0 * h),
                        (-3.0 * p.wf + 4.0 * f1 - top) / (2.0 * h),
                    )
                };
                // dΦ/dw0 = 2 w0 dΦ/d(w0²).
                let dphi = 2.0 * p.w0 * dphi_dy;
                Some((y * dk_dy, k * dphi))
            }
        }
    }

    /// One whole contact: speeds and time.
    fn pass(&self, y: f64, evals: &mut usize) -> Option<Pass> {
        *evals += 1;
        super::count_contacts(1);
        let sc = self.scene;
        let w0sq = y + self.wc2;
        match self.mech {
            Mechanics::Roll if self.over_top() => {
                Self::roll_pass(self.over_top_times(y), w0sq, w0sq + self.drop)
            }
            Mechanics::Roll => {
                let wf2 = w0sq + self.drop;
                let tau = cos_integral(
                    sc.sc_half_0,
                    sc.sc_half_f,
                    w0sq,
                    wf2,
                    y,
                    sc.sin_delta_sin_alpha(),
                );
                Self::roll_pass((tau, f64::NAN), w0sq, wf2)
            }
            Mechanics::RollSlip => {
                let st = stickslip::launch(sc, w0sq, y).ok()?;
                let tau = stickslip::launch_time(sc, w0sq, y, &st, 1e-14).ok()?;
                Some(Pass {
                    tau,
                    dtau: f64::NAN,
                    w0: w0sq.sqrt(),
                    wf: st.final_velocity,
                    theta_g: Some(st.theta_g),
                    branch: Some(st.branch),
                })
            }
        }
    }

    /// The start of the root search: the asinh approximation (eq 29) solved for τ̃ = τ* by
    /// Newton's method in u from its crawl asymptote, and its slope there.
    fn guess(&self, tau_star: f64) -> (f64, f64) {
        let sc = self.scene;
        let b = sc.b;
        let a0 = (sc.sc_half_0.s / sc.sc_half_0.c).abs();
        let af = (sc.sc_half_f.s / sc.sc_half_f.c).abs();
        let u_d = self.y_d.ln();
        // y → 0: τ̃ ≈ 2/sqrt(2B) [ln(8B a0 af) − ln y].
        let mut u = ((8.0 * b * a0 * af).ln() - tau_star * (0.5 * b).sqrt()).min(u_d);
        let mut slope = -(2.0 / b).sqrt();
        for _ in 0..3 {
            let (t, d) = approx_tau(b, a0, af, u.exp());
            if !(t.is_finite() && d < 0.0) {
                break;
            }
            slope = d;
            let step = (t - tau_star) / d;
            u = (u - step).min(u_d);
            // The approximation itself is off by ~1 %: no point in more digits.
            if step.abs() < 1e-2 * u.abs().max(1.0) {
                break;
            }
        }
        (u, slope)
    }

    /// Two whole contacts, [`Launch::pass`] at `ya` and at `yb` to the last bit (uncounted):
    /// for rolling, the four R_F of their contact times run side by side
    /// ([`cos_integral_pair`]).
    fn pass_pair(&self, ya: f64, yb: f64) -> [Option<Pass>; 2] {
        let mut n = 0;
        match self.mech {
            Mechanics::RollSlip => [self.pass(ya, &mut n), self.pass(yb, &mut n)],
            Mechanics::Roll => {
                super::count_contacts(2);
                let sc = self.scene;
                let w0sq = [ya + self.wc2, yb + self.wc2];
                let wf2 = w0sq.map(|w| w + self.drop);
                // No derivative here: R_D's sum beside four R_F costs twice the four alone
                // (211 against 105 ns), beside two 1.8 times (123 against 69 ns; criterion
                // medians, `cargo bench --features bench-internals --bench forward --
                // "carlson-rf with"`). Newton's steps on single passes, and no stencil for
                // dv̄/dK, still pay for it: the whole row takes 0.94 of the secant's time.
                let times = cos_integral_pair(
                    sc.sc_half_0,
                    sc.sc_half_f,
                    [w0sq[0], wf2[0], ya],
                    [w0sq[1], wf2[1], yb],
                    sc.sin_delta_sin_alpha(),
                )
                .map(|t| (t, f64::NAN));
                [0, 1].map(|i| Self::roll_pass(times[i], w0sq[i], wf2[i]))
            }
        }
    }

    /// Whether the passes roll over the top (Θ0 < 0 < Θf, the crawl path of rolling), where
    /// [`Launch::over_top_times`] gives a single pass's time with dτ/du (pairs of passes,
    /// [`Launch::pass_pair`], come without it).
    fn over_top(&self) -> bool {
        self.mech == Mechanics::Roll && !self.past_top
    }

    /// The contact time τ and its derivative dτ/du (u = ln y) of a rolling launch over the top
    /// at the squared top speed `y`.
    ///
    /// Over the top τ = 2 Σ |sin(Θ/2)| R_F(cos²(Θ/2) y, y + c, y), summed over the halves on
    /// either side of the top (Θ0's and Θf's; [`cos_integral`]), where c is the half's squared
    /// speed less the top's: 2B sin²(Θ0/2) on Θ0's side, that plus the drop 2B sin δ sin α on
    /// Θf's. R_F is homogeneous of degree −½ (x ∂_x + y ∂_y + z ∂_z = −R_F/2, DLMF 19.18.1), so
    /// y d/dy R_F(a y, y + c, y) = −R_F/2 − c ∂_y R_F: one derivative per half, ∂_y R_F =
    /// −R_D/6 ([`rf_dy_lanes`]), where three would serve otherwise. The difference cancels
    /// only by the factor ln(1/y) of the crawl's logarithm: dτ/du keeps its relative accuracy
    /// to a few ε ln(1/y).
    fn over_top_times(&self, y: f64) -> (f64, f64) {
        let sc = self.scene;
        let (h0, h1) = (sc.sc_half_0, sc.sc_half_f);
        let (c0, c1) = (self.wc2, self.wc2 + self.drop);
        let half = |h: crate::scene::SinCos, c: f64| [h.c * h.c * y, y + c, y];
        let [(f1, d1), (f0, d0)] = rf_dy_lanes([half(h1, c1), half(h0, c0)]);
        let (s1, s0) = (h1.s.abs(), h0.s.abs());
        (
            2.0 * (s1 * f1 + s0 * f0),
            2.0 * (s1 * (-0.5 * f1 - c1 * d1) + s0 * (-0.5 * f0 - c0 * d0)),
        )
    }

    /// A rolling contact of time `tau` (with dτ/du, NaN where not computed) from squared speed
    /// `w0sq` to `wf2`, if the time is one.
    fn roll_pass((tau, dtau): (f64, f64), w0sq: f64, wf2: f64) -> Option<Pass> {
        (tau.is_finite() && tau > 0.0).then(|| Pass {
            tau,
            dtau,
            w0: w0sq.sqrt(),
            wf: wf2.sqrt(),
            theta_g: None,
            branch: None,
        })
    }

    /// Solves τ(e^u) = τ* by [`Secant`] from `u0`; `first`, when given, is the pass at the
    /// secant's first point, evaluated by the caller.
    fn solve(
        &self,
        mut secant: Secant,
        first: Option<Option<Pass>>,
        evals: &mut usize,
    ) -> Option<Found> {
        let mut p = match first {
            Some(p) => p,
            None => self.pass(secant.x.exp(), evals),
        };
        loop {
            match secant.feed(p) {
                Step::Eval(x) => p = self.pass(x.exp(), evals),
                Step::Done(r) => return r,
            }
        }
    }

    /// Two independent [`Launch::solve`]s run side by side, each pair of their passes by
    /// [`Launch::pass_pair`]: the same results, to the last bit.
    fn solve_two(&self, (a, b): (Secant, Secant), evals: &mut usize) -> [Option<Found>; 2] {
        let mut secants = [a, b];
        let [pa, pb] = self.pass_pair(secants[0].x.exp(), secants[1].x.exp());
        *evals += 2;
        let mut steps = [secants[0].feed(pa), secants[1].feed(pb)];
        loop {
            match steps {
                [Step::Eval(xa), Step::Eval(xb)] => {
                    let [pa, pb] = self.pass_pair(xa.exp(), xb.exp());
                    *evals += 2;
                    steps = [secants[0].feed(pa), secants[1].feed(pb)];
                }
                [Step::Done(ra), Step::Done(rb)] => return [ra, rb],
                [Step::Done(ra), Step::Eval(xb)] => {
                    let p = self.pass(xb.exp(), evals);
                    let [_, b] = secants;
                    return [ra, self.solve(b, Some(p), evals)];
                }
                [Step::Eval(xa), Step::Done(rb)] => {
                    let p = self.pass(xa.exp(), evals);
                    let [a, _] = secants;
                    return [self.solve(a, Some(p), evals), rb];
                }
            }
        }
    }
}

/// What a [`Secant`] asks for next.
#[derive(Debug, Clone, Copy)]
enum Step {
    /// The pass at this u.
    Eval(f64),
    /// The end of the search; `None` when it failed.
    Done(Option<Found>),
}

/// The root of a [`Secant`] search.
#[derive(Debug, Clone, Copy)]
struct Found {
    /// The root in u.
    u: f64,
    /// The pass at `u`, when the last iterate was evaluated there.
    pass: Option<Pass>,
    /// dτ/du at `u`: the pass's, or, at an unevaluated Newton iterate, the last pass's carried
    /// to `u` by τ''; NaN where the passes give no derivative.
    dtau: f64,
    /// τ'' = d²τ/du² near `u`, from the last two passes' derivatives (or the search's given
    /// curvature); NaN where unknown.
    d2: f64,
}

/// The root search of τ(e^u) = τ* by the secant method, kept inside (−∞, u_d] with bisection
/// once both sides are known, as a state machine that asks for one pass at a time (so that two
/// searches can share the work of their passes, [`Launch::solve_two`]).
///
/// With C = τ''/(2τ') — given as `curv` (K_lo, K_hi: from the root's differences) or
/// estimated from the divided differences of the last three iterates — a secant iterate whose
/// predicted error |C| |Δ_n| |Δ_{n−1}| (the secant method's error recursion) is below one ulp
/// of u is returned without its own evaluation.
///
/// Where the passes carry dτ/du ([`Launch::over_top_times`]) the step is Newton's instead,
/// with C from the last two derivatives (or `curv`), and a Newton iterate whose predicted
/// error |C| Δ² is below a twentieth of an ulp of u is returned without its own evaluation.
#[derive(Debug, Clone, Copy)]
struct Secant {
    tau_star: f64,
    slope0: f64,
    curv: Option<f64>,
    /// Where |τ − τ*| falls to the rounding of τ: return the secant step from the last two
    /// iterates (unevaluated), not the iterate itself. Where τ is flat in u (launches from
    /// rest at small K) that step is closer to the root than the iterate's rounding band.
    refine: bool,
    /// Bracket: g = τ − τ* > 0 below the root (slower), < 0 above.
    lo: f64,
    hi: f64,
    /// The point whose pass comes next.
    x: f64,
    prev: Option<(f64, f64)>,
    before: Option<(f64, f64)>,
    /// The last iterate with a derivative: (u, dτ/du).
    dprev: Option<(f64, f64)>,
    /// Iterations done.
    it: usize,
}

impl Secant {
    /// The search from `u0` (first step with `slope0` ≈ dτ/du) below the end of the range
    /// (u_d, τ_d); `None` when τ_d ≥ τ* (no root below).
    fn new(
        tau_star: f64,
        u0: f64,
        slope0: f64,
        (u_d, tau_d): (f64, f64),
        curv: Option<f64>,
    ) -> Option<Self> {
        let g_hi = tau_d - tau_star;
        if g_hi >= 0.0 {
            return None;
        }
        let x = Self::first_point(u0, u_d);
        Some(Secant {
            tau_star,
            slope0,
            curv,
            refine: false,
            lo: f64::NEG_INFINITY,
            hi: u_d,
            x,
            prev: None,
            before: None,
            dprev: None,
            it: 0,
        })
    }

    /// The first point of a search from `u0` below `u_d` (as [`Secant::new`] sets it).
    fn first_point(u0: f64, u_d: f64) -> f64 {
        let x = u0.min(u_d);
        if x == u_d {
            x - 1e-3
        } else {
            x
        }
    }

    /// Takes the pass at the point asked for (`None`: the pass failed, and so does the
    /// search) and says what comes next.
    fn feed(&mut self, p: Option<Pass>) -> Step {
        const MAX_ITERATIONS: usize = 80;
        let Some(p) = p else {
            return Step::Done(None);
        };
        let (x, tau_star) = (self.x, self.tau_star);
        let gx = p.tau - tau_star;
        // Newton's step where the pass has the derivative, τ'' from the last one.
        let d = p.dtau;
        let newton = d.is_finite() && d < 0.0;
        let d2 = match self.dprev {
            Some((xp, dp)) if newton && xp != x => (d - dp) / (x - xp),
            _ => self.curv.map_or(f64::NAN, |c| 2.0 * c * d),
        };
        let found = |u: f64, pass: Option<Pass>, dtau: f64| Found { u, pass, dtau, d2 };
        // |τ − τ*| at the rounding level of τ itself: no iterate can do better.
        if gx.abs() <= 4.0 * f64::EPSILON * tau_star {
            if let Some((xp, gp)) = self.prev.filter(|&(_, gp)| self.refine && gp != gx) {
                let next = x - gx * (x - xp) / (gx - gp);
                if next > self.lo && next < self.hi && next != x {
                    return Step::Done(Some(found(next, None, f64::NAN)));
                }
            }
            return Step::Done(Some(found(x, Some(p), d)));
        }
        if gx > 0.0 {
            self.lo = x;
        } else {
            self.hi = x;
        }
        let (lo, hi) = (self.lo, self.hi);
        let tol = 4.0 * f64::EPSILON * x.abs().max(1.0);
        let mut next = match self.prev {
            _ if newton => x - gx / d,
            Some((xp, gp)) if gp != gx && self.it < 30 => x - gx * (x - xp) / (gx - gp),
            None => x - gx / self.slope0,
            _ => f64::NAN,
        };
        if !(next > lo && next < hi) {
            next = if lo.is_finite() {
                0.5 * (lo + hi)
            } else {
                // The slow side is not bracketed yet: step down in u.
                x - 2.0 * (1.0 + (x - self.prev.map_or(x, |q| q.0)).abs())
            };
        } else if newton {
            let c = 0.5 * d2 / d;
            let dx = next - x;
            if c.is_finite() && (c * dx * dx).abs() <= 0.05 * tol {
                return Step::Done(Some(found(next, None, d + d2 * dx)));
            }
        } else if let Some((xp, gp)) = self.prev {
            let c = self.curv.or_else(|| {
                let (xb, gb) = self.before?;
                let d1 = (gx - gp) / (x - xp);
                let d2 = (d1 - (gp - gb) / (xp - xb)) / (x - xb);
                Some(d2 / d1)
            });
            if let Some(c) = c.filter(|c| c.is_finite()) {
                if (c * (next - x) * (x - xp)).abs() <= 0.5 * tol {
                    return Step::Done(Some(found(next, None, f64::NAN)));
                }
            }
        }
        // The last step is the error of x: x is the root to within `tol`.
        if (next - x).abs() <= tol || hi - lo <= tol {
            return Step::Done(Some(found(x, Some(p), d)));
        }
        self.before = self.prev;
        self.prev = Some((x, gx));
        if newton {
            self.dprev = Some((x, d));
        }
        self.x = next;
        self.it += 1;
        if self.it == MAX_ITERATIONS {
            return Step::Done(None);
        }
        Step::Eval(next)
    }
}

/// The steady state of a launch, as the forward model reports it.
fn steady_of(scene: &Scene, p: &Pass, top_sq: f64, map_slope: f64) -> Steady {
    let mut s = Steady::basic(2.0 * scene.sin_alpha / p.tau, p.wf, p.w0, p.tau);
    s.top_velocity_sq = Some(top_sq);
    s.map_slope = Some(map_slope);
    s.theta_g = p.theta_g;
    s.phases = match p.branch {
        None | Some(Branch::NoSlip) => Phases::Roll,
        Some(Branch::RollSlip) => Phases::RollSlip,
        Some(Branch::SlipFromStart) => Phases::Slip,
    };
    s
}

/// How an end of the interval at v ± σ is found.
enum End {
    /// A bracket end (v ∓ σ outside the steady range).
    At(f64),
    /// A root search.
    Search(Secant),
}

/// [`super::estimate()`](super::estimate::estimate) by the launch speed, when this path applies (`None`: use the
/// general search). Same outputs and statuses as the general path.
pub(crate) fn estimate(
    model: &Model,
    scene: &Scene,
    v: f64,
    sigma_v: Option<f64>,
) -> Option<KEstimate> {
    if !(v > 0.0 && v.is_finite()) {
        return None;
    }
    let l = Launch::new(model, scene)?;
    let u_d = l.y_d.ln();
    let sin_alpha = scene.sin_alpha;
    let tau_star = 2.0 * sin_alpha / v;
    let (br, first) = bracket(&l, tau_star, u_d)?;
    let end = (u_d, br.tau_hi);
    // Near a saddle-node the range's end is where the forward model's status search puts it:
    // measurements within 1e-6 of the fastest stable motion, or whose v + σ passes it, are
    // left to the general search, whose bracket (and so whose statuses there) is that one.
    if l.saddle && v + sigma_v.unwrap_or(0.0) > br.v_hi * (1.0 - 1e-6) {
        return None;
    }
    if v > br.v_hi {
        return above_range(&l, &br, v, sigma_v);
    }
    // The root.
    let mut n_root = 0;
    let (u0, s0, first) = match first {
        Some((u0, s0, p)) => (u0, s0, Some(p)),
        None => {
            let (u0, s0) = l.guess(tau_star);
            (u0, s0, None)
        }
    };
    let secant = Secant::new(tau_star, u0, s0, end, None)?;
    n_root += usize::from(first.is_some());
    let root = l.solve(secant, first, &mut n_root)?;
    // Keep the crawl end to the general search: there K rounds to K_min.
    if root.u.exp() < 1e-12 * l.wc2 {
        return None;
    }
    l.conclude(&br, tau_star, (v, sigma_v), root, n_root)
}

/// [`super::estimate()`](super::estimate::estimate) of a stick row whose contact starts past
/// the top (Θ0 > 0, K_min = 0), on the general search's bracket `br`, whose statuses and ends
/// it keeps: the secant method in u = ln w0² ([`Launch::past_top`]) from the time on a slope
/// of constant pitch, then K_lo and K_hi as on the crawl path. `None` (use the general search)
/// for other rows, and where v or v ± σ lies within [`END_BAND`] of either end of the steady
/// range.
pub(crate) fn estimate_past_top(
    model: &Model,
    scene: &Scene,
    br: &KBracket,
    v: f64,
    sigma_v: Option<f64>,
) -> Option<KEstimate> {
    if !matches!(model, Model::Stick)
        || br.lower != LowerLimit::Zero
        || br.upper != UpperLimit::LiftOff
        || !(v > br.v_lo && v < br.v_hi)
        || near_an_end(v, br)
    {
        return None;
    }
    let l = Launch::past_top(scene)?;
    let u_d = l.y_d.ln();
    let tau_star = 2.0 * scene.sin_alpha / v;
    // The start: the time of a bead on a slope of constant pitch, τ/τ0 = sqrt(z² + 1) − z
    // with z ∝ w0 (finite from rest, L/w0 when fast), matched to the time from rest (τ0, at
    // v_lo) and at lift-off (τ_hi): z(ρ) = (1 − ρ²)/(2ρ) at ρ = τ/τ0.
    let tau_0 = 2.0 * scene.sin_alpha / br.v_lo;
    let z_of = |rho: f64| (1.0 - rho * rho) / (2.0 * rho);
    let z = z_of(tau_star / tau_0);
    let u0 = u_d + 2.0 * (z / z_of(br.tau_hi / tau_0)).ln();
    // dτ/du = τ0 (z/sqrt(z² + 1) − 1) z/2 (u = ln w0², z ∝ e^{u/2}).
    let slope0 = tau_0 * (z / z.hypot(1.0) - 1.0) * 0.5 * z;
    let mut secant = Secant::new(tau_star, u0, slope0, (u_d, br.tau_hi), None)?;
    secant.refine = true;
    let mut n_root = 0;
    let root = l.solve(secant, None, &mut n_root)?;
    l.conclude(br, tau_star, (v, sigma_v), root, n_root)
}

/// A rolling row above the steady range (v faster than lift-off): no root; K_lo and K_hi at
/// v ∓ σ by the rule of every other row, the bracket's top where v ∓ σ is above the range
/// (noted) and otherwise the secant method from the asinh start. `None` (the general search
/// reports the row) for stick/slip, within [`END_BAND`] of the top, and at the crawl end.
fn above_range(l: &Launch<'_>, br: &KBracket, v: f64, sigma_v: Option<f64>) -> Option<KEstimate> {
    if l.mech != Mechanics::Roll || near_an_end(v, br) {
        return None;
    }
    let mut notes = Vec::new();
    let mut end_at = |vs: f64, name: &str| -> Option<f64> {
        if let Some(k) = bracket_end(vs, br, true, name, &mut notes)? {
            return Some(k);
        }
        let t = 2.0 * l.scene.sin_alpha / vs;
        let (u0, s0) = l.guess(t);
        let secant = Secant::new(t, u0, s0, (l.y_d.ln(), br.tau_hi), None)?;
        let found = l.solve(secant, None, &mut 0)?;
        if found.u.exp() < 1e-12 * l.wc2 {
            return None;
        }
        l.k_of_found(&found)
    };
    let (k_lo, k_hi) = match sigma_v {
        Some(sg) => (Some(end_at(v - sg, "K_lo")?), Some(end_at(v + sg, "K_hi")?)),
        None => (None, None),
    };
    Some(KEstimate {
        bracket: Some(*br),
        root: Err(KFailure::AboveRange),
        k_lo,
        k_hi,
        dv_dk: None,
        theta_g: None,
        notes,
    })
}

/// Relative distance from the ends of the steady range (v̄ at K_min = 0 and at the top) within
/// which [`estimate_past_top`] and [`above_range`] leave a row to the general search, which
/// resolves K there to the rounding of v̄ (its `ROUNDING` band and the lowest resolved K).
const END_BAND: f64 = 1e-6;

/// Where the interval end `name` (`K_lo` or `K_hi`) at v ∓ σ = `vs` is an end of the bracket
/// `br`, with no search: `Some(Some(K))`, noted in `notes`, where `vs` ≤ 0 or lies outside the
/// steady range; `Some(None)` where a search must find it; `None` (the general search's) where
/// `guard` is set and `vs` lies within [`END_BAND`] of either end of the range.
fn bracket_end(
    vs: f64,
    br: &KBracket,
    guard: bool,
    name: &str,
    notes: &mut Vec<String>,
) -> Option<Option<f64>> {
    let side = if name == "K_lo" {
        "v - sigma_v"
    } else {
        "v + sigma_v"
    };
    if vs <= 0.0 {
        notes.push(end_note(name, side, AtEnd::NotPositive));
        return Some(Some(br.lo));
    }
    if guard && near_an_end(vs, br) {
        return None;
    }
    if vs < br.v_lo {
        notes.push(end_note(name, side, AtEnd::Below));
        return Some(Some(br.lo));
    }
    if vs > br.v_hi {
        notes.push(end_note(name, side, AtEnd::Above));
        return Some(Some(br.hi));
    }
    Some(None)
}

/// Whether `v` lies within [`END_BAND`] of either end of the bracket's steady range.
fn near_an_end(v: f64, br: &KBracket) -> bool {
    (v - br.v_lo).abs() <= END_BAND * br.v_lo || (v - br.v_hi).abs() <= END_BAND * br.v_hi
}

impl Launch<'_> {
    /// The estimate from the root (u, its pass if evaluated) of τ = τ* = `tau_star` on the
    /// bracket `br`, found in `n_root` passes: dv̄/dK, K_lo and K_hi at v ∓ σ, the steady state.
    fn conclude(
        &self,
        br: &KBracket,
        tau_star: f64,
        (v, sigma_v): (f64, Option<f64>),
        root: Found,
        mut n_root: usize,
    ) -> Option<KEstimate> {
        let (u, p) = (root.u, root.pass);
        let (l, scene) = (self, self.scene);
        let sin_alpha = scene.sin_alpha;
        let u_d = l.y_d.ln();
        let end = (u_d, br.tau_hi);
        let mut notes = Vec::new();
        let y = u.exp();
        // An unevaluated root is the secant step from evaluated neighbours with a predicted error
        // below one ulp of u: its contact time is τ* and its speeds need no quadrature.
        let p = match p {
            Some(p) => p,
            None => Pass {
                tau: tau_star,
                ..l.launch(y)?
            },
        };
        let k = p.k();
        // τ' at the root is the search's where its passes carry it (rolling over the top), and so
        // is τ'' where K_lo and K_hi need it; elsewhere both come from central differences.
        // The differences' step in u: 1e-5, wider from rest past the top, where τ is flat in u
        // as K → 0 (τ' ≈ (τ − τ0)/2, τ0 the time from rest): there the step balances the
        // rounding of the central difference, ε τ/(h |τ'|), against its truncation,
        // h² |τ'''/τ'|/6 with τ'''/τ' ≈ 1/4, at h³ = 12 ε τ/|τ'|.
        let h = if l.past_top {
            let tau_0 = 2.0 * sin_alpha / br.v_lo;
            let r = 0.5 * (tau_0 - p.tau) / p.tau;
            (12.0 * f64::EPSILON / r).cbrt().max(1e-5)
        } else {
            1e-5
        };
        let (d1, d2) = if root.dtau.is_finite() && (sigma_v.is_none() || root.d2.is_finite()) {
            (root.dtau, root.d2)
        } else {
            tau_derivatives(l, (u, h), u_d, &p)?
        };
        let (dk, map_slope) = l.dk_du(y, &p)?;
        // v̄ = 2 sin α / τ: dv̄/du = −v̄ τ'/τ.
        let dv_dk = -(2.0 * sin_alpha / p.tau) * d1 / p.tau / dk;
        // K at v ± σ: a second-order Taylor step in τ off the root, then the secant method (the
        // two searches side by side).
        let ends = SigmaEnds {
            l,
            br,
            sin_alpha,
            end,
            u,
            tau: p.tau,
            d1,
            d2,
        };
        let (k_lo, k_hi) = match sigma_v {
            Some(sg) => ends.interval(v, sg, &mut notes)?,
            None => (f64::NAN, f64::NAN),
        };
        if l.saddle {
            // Two fixed points per K here: the forward model must settle on this one, the stable
            // one below the saddle-node.
            let st = stickslip::steady_lean(&scene.with_k(k).ok()?).ok()?;
            n_root += 1;
            if (st.contact_time - p.tau).abs() > 1e-9 * p.tau {
                return None;
            }
        }
        // The squared speed at the top, w0² − 2B sin²(Θ0/2): y itself on the crawl path.
        let top_sq = if l.past_top {
            y - 2.0 * scene.b * scene.sc_half_0.s * scene.sc_half_0.s
        } else {
            y
        };
        let steady = steady_of(scene, &p, top_sq, map_slope);
        let theta_g = match l.mech {
            // Θ_G does not involve K: the scene's own serves (K checked as `Scene::with_k` would).
            Mechanics::Roll => (k.is_finite() && k > 0.0)
                .then_some(())
                .and_then(|()| theta_g(scene, p.w0 * p.w0)),
            Mechanics::RollSlip => steady.theta_g,
        };
        Some(KEstimate {
            bracket: Some(*br),
            root: Ok(KRoot {
                k,
                steady,
                evals: n_root,
            }),
            k_lo: sigma_v.map(|_| k_lo),
            k_hi: sigma_v.map(|_| k_hi),
            dv_dk: Some(dv_dk),
            theta_g,
            notes,
        })
    }
}

/// The bracket of a launch-speed estimate: K from K_min to the top of the steady range,
/// and, rolling, the root search's first pass (from the asinh start at τ* = `tau_star`,
/// taken beside the top's) with its start.
#[allow(clippy::type_complexity)]
fn bracket(
    l: &Launch<'_>,
    tau_star: f64,
    u_d: f64,
) -> Option<(KBracket, Option<(f64, f64, Option<Pass>)>)> {
    let mut evals = 0;
    // Rolling: the pass at the top of the range and the root search's first one (from the
    // asinh start, which needs no pass) side by side; stick/slip takes them one by one, the
    // second only when the root is searched.
    let (top, first) = match l.mech {
        Mechanics::Roll => {
            let (u0, s0) = l.guess(tau_star);
            let [top, first] = l.pass_pair(l.y_d, Secant::first_point(u0, u_d).exp());
            evals += 1;
            (top?, Some((u0, s0, first)))
        }
        Mechanics::RollSlip => (l.pass(l.y_d, &mut evals)?, None),
    };
    let br = KBracket {
        lo: l.k_min,
        hi: top.k(),
        v_lo: 0.0,
        v_hi: 2.0 * l.scene.sin_alpha / top.tau,
        tau_hi: top.tau,
        lower: LowerLimit::Crawl,
        upper: if l.saddle {
            UpperLimit::Model
        } else {
            UpperLimit::LiftOff
        },
        evals,
    };
    Some((br, first))
}

/// dτ/du and d²τ/du² at the root `p` (u = ln y) by central differences with step `h` in u
/// (one-sided at lift-off, u_d).
fn tau_derivatives(l: &Launch<'_>, (u, h): (f64, f64), u_d: f64, p: &Pass) -> Option<(f64, f64)> {
    let [pm, pp] = if u + h <= u_d {
        l.pass_pair((u - h).exp(), (u + h).exp())
    } else {
        l.pass_pair((u - 2.0 * h).exp(), (u - h).exp())
    };
    let (pm, pp) = (pm?, pp?);
    Some(if u + h <= u_d {
        (
            (pp.tau - pm.tau) / (2.0 * h),
            (pp.tau - 2.0 * p.tau + pm.tau) / (h * h),
        )
    } else {
        (
            (3.0 * p.tau - 4.0 * pp.tau + pm.tau) / (2.0 * h),
            (p.tau - 2.0 * pp.tau + pm.tau) / (h * h),
        )
    })
}

/// K at v ± σ, from the root: a second-order Taylor step in τ off it, then the secant
/// method.
struct SigmaEnds<'a> {
    /// The launch.
    l: &'a Launch<'a>,
    /// The bracket.
    br: &'a KBracket,
    /// sin α.
    sin_alpha: f64,
    /// The end of the root search's range, (u_d, τ there).
    end: (f64, f64),
    /// u = ln y at the root.
    u: f64,
    /// Contact time at the root.
    tau: f64,
    /// dτ/du at the root.
    d1: f64,
    /// d²τ/du² at the root.
    d2: f64,
}

impl SigmaEnds<'_> {
    /// How the end named `name` (`K_lo` or `K_hi`) at velocity `vs` is found: a bracket end
    /// where `vs` is outside the steady range (noted in `notes`), else a search.
    fn plan_end(&self, vs: f64, name: &'static str, notes: &mut Vec<String>) -> Option<End> {
        let (br, sin_alpha, end, u) = (self.br, self.sin_alpha, self.end, self.u);
        let (d1, d2) = (self.d1, self.d2);
        if let Some(k) = bracket_end(vs, br, self.l.past_top, name, notes)? {
            return Some(End::At(k));
        }
        let t = 2.0 * sin_alpha / vs;
        let dt = t - self.tau;
        let du = dt / d1;
        let du = du - 0.5 * d2 * du * du / d1;
        Secant::new(t, u + du, d1 + d2 * du, end, Some(0.5 * d2 / d1)).map(|mut sc| {
            sc.refine = self.l.past_top;
            End::Search(sc)
        })
    }

    /// K of a search's result.
    fn k_at(&self, r: Option<Found>) -> Option<f64> {
        self.l.k_of_found(&r?)
    }

    /// K_lo and K_hi at v ∓ `sg` (the two searches side by side).
    fn interval(&self, v: f64, sg: f64, notes: &mut Vec<String>) -> Option<(f64, f64)> {
        let l = self.l;
        let n_side = &mut 0;
        let lo = self.plan_end(v - sg, "K_lo", notes)?;
        let hi = self.plan_end(v + sg, "K_hi", notes)?;
        Some(match (lo, hi) {
            (End::Search(a), End::Search(b)) => {
                let [ra, rb] = l.solve_two((a, b), n_side);
                (self.k_at(ra)?, self.k_at(rb)?)
            }
            (End::Search(a), End::At(kh)) => (self.k_at(l.solve(a, None, n_side))?, kh),
            (End::At(kl), End::Search(b)) => (kl, self.k_at(l.solve(b, None, n_side))?),
            (End::At(kl), End::At(kh)) => (kl, kh),
        })
    }
}
