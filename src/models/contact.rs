//! The general contact model (docs/PHYSICS.md#general-contact-model, beyond the paper): on each row
//! bead the mobile bead rolls or slips in either direction as Coulomb friction allows, may stop
//! before the top or lift off, and the collision law acts on the translational velocity (K, eq 1)
//! and on the spin (a named rule). The paper's stick/slip model (§4.4) is the special case "roll,
//! then one forward slip after Θ_G"; when Θ0 < −Θ_G the true contact starts with a backward slip
//! (slip > roll > slip), which this model resolves.
//!
//! State on a bead: Θ, Θ̇ and the spin ω (units ω0); the contact-point slip velocity is
//! s = Θ̇ − ω/ε. Normal force N = cos Θ − Θ̇²; tangential Θ̈ = sin Θ − T; spin ω̇ = (ε/ρ) T.
//! Rolling (s = 0): T = ρ sin Θ/(1+ρ), allowed while |T| ≤ f N. Slipping: T = f N sgn(s).
//!
//! Every phase is advanced with its closed-form first integral in Θ:
//! - rolling: Θ̇² = Θ̇a² + B (cos Θa − cos Θ) (eq 9), time by Carlson's R_F (eq 11), the end
//!   Θ_G from eq 36 with ϑ = 2 cos Θa + (1+ρ) Θ̇a² (the rolling energy invariant);
//! - slipping with sgn(s) = σ: Θ̇² = a e^{2σfΘ} + b_σ sin Θ + c cos Θ (eq 38 with f → σf),
//!   time by the adaptive quadrature of the slip model.
//!
//! Only the spin during slip has no closed form:
//! ω(Θ) = ωa + (ε σ f/ρ) G(Θ), G(Θ) = ∫_{Θa}^{Θ} N/Θ̇ dθ (eqs 43, 61 with dt = dθ/Θ̇), a
//! smooth integrand integrated by adaptive Gauss–Kronrod (15 points, relative 1e-14). The
//! events — stop (Θ̇² = 0), lift-off (N = 0), slip → stick (s = 0) and the collision at Θf — are
//! located by Brent's method on their event functions to 1e-15 in Θ, never by stepping.
//!
//! The friction work of a slip phase, W = ∫ f N |s| dt, follows from the same integrals by an
//! exact identity (G' = N/Θ̇): W = σ f [∫ N dθ − (ωa/ε) G_end] − f² G_end² / (2ρ), with
//! ∫ N dθ in closed form; the energy balance per contact is then a genuine check of the phases,
//! the first integrals and the spin.

use super::slip::{slip_time, SlipPhase};
use super::stick;
use super::{NotSteady, Outcome, Phases, Steady};
use crate::scene::Scene;
use crate::scene::{ParameterError as Error, ParameterResult as Result};
use crate::special::cheb::ChebIntegral;
use crate::special::quad::{integrate_smooth, integrate_smooth_n};
use crate::special::root::brent;
use nalgebra::{Matrix2, Vector2};
use std::fmt;
use std::str::FromStr;

/// What the collision does to the spin (the translational part is Θ̇0 = K Θ̇f, eq 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpinRule {
    /// Rolling restarts after the impact: ω0 = ε Θ̇0 (the paper's choice, eq 16).
    Roll,
    /// The spin passes through the impact unchanged: ω0 = ωf.
    Keep,
    /// ω0 = L ωf (the paper's eq 63 parameter L).
    Factor(f64),
    /// No-slip impact conserving the angular momentum about the new contact point:
    /// Θ̇0 = (Θ̇f cos 2α + ρ ωf/ε)/(1+ρ) and rolling; the scene's K is not used (for a bead
    /// rolling in, this is K = (cos 2α + ρ)/(1+ρ), the impact law).
    Impact,
}

impl FromStr for SpinRule {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        let lower = t.to_ascii_lowercase();
        match lower.as_str() {
            "roll" => Ok(SpinRule::Roll),
            "keep" => Ok(SpinRule::Keep),
            "impact" => Ok(SpinRule::Impact),
            _ => match lower
                .strip_prefix("factor=")
                .map(|v| v.trim().parse::<f64>())
            {
                Some(Ok(l)) if l.is_finite() => Ok(SpinRule::Factor(l)),
                _ => Err(Error::UnknownSpinRule(t.to_string())),
            },
        }
    }
}

impl fmt::Display for SpinRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpinRule::Roll => f.write_str("roll"),
            SpinRule::Keep => f.write_str("keep"),
            SpinRule::Factor(l) => write!(f, "factor={l}"),
            SpinRule::Impact => f.write_str("impact"),
        }
    }
}

/// One kind of phase of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PhaseKind {
    /// Rolling without slip (s = 0).
    #[default]
    Roll,
    /// Slipping with s > 0 (the bead outruns its spin; friction brakes it, eq 37).
    Slip,
    /// Slipping with s < 0 (the spin outruns the bead; friction drives it forward).
    BackSlip,
}

impl PhaseKind {
    fn word(self) -> &'static str {
        match self {
            PhaseKind::Roll => "roll",
            PhaseKind::Slip => "slip",
            PhaseKind::BackSlip => "backslip",
        }
    }
}

/// Most phases one contact may go through before the model gives up (chattering).
pub(crate) const MAX_PHASES: usize = 8;

/// The phase sequence of one contact and the angles where the phases change.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhaseSeq {
    kinds: [PhaseKind; MAX_PHASES],
    /// Angle (radians) where phase i+1 starts, for i < len − 1.
    changes: [f64; MAX_PHASES],
    len: usize,
}

impl PhaseSeq {
    /// The phases in order.
    pub fn kinds(&self) -> &[PhaseKind] {
        &self.kinds[..self.len]
    }
    /// Angles Θ (radians) where the phase changes, in order.
    pub fn changes(&self) -> &[f64] {
        &self.changes[..self.len.saturating_sub(1)]
    }
    fn push(&mut self, k: PhaseKind, start: f64) -> bool {
        if self.len == MAX_PHASES {
            return false;
        }
        if self.len > 0 {
            self.changes[self.len - 1] = start;
        }
        self.kinds[self.len] = k;
        self.len += 1;
        true
    }
    fn pop(&mut self) {
        if self.len > 0 {
            self.len -= 1;
        }
    }
    /// The phase-change angles in degrees joined by ';'.
    pub fn changes_deg(&self) -> String {
        self.changes()
            .iter()
            .map(|a| crate::numfmt::fmt_f64(a.to_degrees()))
            .collect::<Vec<_>>()
            .join(";")
    }
}

impl fmt::Display for PhaseSeq {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, k) in self.kinds().iter().enumerate() {
            if i > 0 {
                f.write_str(">")?;
            }
            f.write_str(k.word())?;
        }
        Ok(())
    }
}

/// The state just after a collision: Θ̇0 and the spin in velocity units, w = ω/ε (so the
/// slip velocity is Θ̇0 − w0; rolling means w0 = Θ̇0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Launch {
    /// Θ̇ just after the collision.
    pub theta_dot: f64,
    /// ω/ε just after the collision.
    pub spin: f64,
}

/// How one contact ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactEnd {
    /// Reached Θf: Θ̇ and ω/ε just before the next collision.
    Collision {
        /// Θ̇f.
        theta_dot: f64,
        /// ωf/ε.
        spin: f64,
    },
    /// Not completed: the bead stops or lifts off (or the phases chatter).
    Failed(NotSteady),
}

/// One contact from Θ0 to Θf (or to where it ends).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRun {
    /// Phases and their change angles.
    pub phases: PhaseSeq,
    /// How it ended.
    pub end: ContactEnd,
    /// Contact time (to the end, when completed).
    pub time: f64,
    /// Friction work ∫ f N |s| dt over the contact (units m g (R + r)).
    pub friction_work: f64,
}

/// The general contact model with a spin rule and a quadrature tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Spin rule at the collision.
    pub spin: SpinRule,
    /// Relative tolerance of the quadratures (time, spin); default 1e-14.
    pub tol: f64,
}

impl Default for Contact {
    fn default() -> Self {
        Contact {
            spin: SpinRule::Roll,
            tol: 1e-14,
        }
    }
}

/// The mode a bead takes at angle θ with squared speed u and slip velocity s.
fn mode_at(scene: &Scene, theta: f64, u: f64, s: f64) -> std::result::Result<PhaseKind, NotSteady> {
    let n = theta.cos() - u;
    if n < 0.0 {
        return Err(NotSteady::LiftOff { angle: theta });
    }
    if scene.f == 0.0 {
        // Frictionless: T = 0 whatever the slip, and its direction is immaterial.
        return Ok(if s == 0.0 && theta.sin() == 0.0 {
            PhaseKind::Roll
        } else {
            PhaseKind::Slip
        });
    }
    if s > 0.0 {
        return Ok(PhaseKind::Slip);
    }
    if s < 0.0 {
        return Ok(PhaseKind::BackSlip);
    }
    let t_roll = scene.rho * theta.sin() / (1.0 + scene.rho);
    let fn_ = scene.f * n;
    Ok(if t_roll > fn_ {
        PhaseKind::Slip
    } else if t_roll < -fn_ {
        PhaseKind::BackSlip
    } else {
        PhaseKind::Roll
    })
}

impl Contact {
    /// The collision: final state (Θ̇f, ωf/ε) on one bead → launch on the next.
    pub fn collide(&self, scene: &Scene, theta_dot_f: f64, spin_f: f64) -> Launch {
        match self.spin {
            SpinRule::Roll => {
                let y = scene.k * theta_dot_f;
                Launch {
                    theta_dot: y,
                    spin: y,
                }
            }
            SpinRule::Keep => Launch {
                theta_dot: scene.k * theta_dot_f,
                spin: spin_f,
            },
            SpinRule::Factor(l) => Launch {
                theta_dot: scene.k * theta_dot_f,
                spin: l * spin_f,
            },
            SpinRule::Impact => {
                let c2 = 1.0 - 2.0 * scene.sin_alpha * scene.sin_alpha;
                let y = (c2 * theta_dot_f + scene.rho * spin_f) / (1.0 + scene.rho);
                Launch {
                    theta_dot: y,
                    spin: y,
                }
            }
        }
    }

    /// One contact from Θ0 launched with `launch`: the phases, the end and the time.
    pub fn run(&self, scene: &Scene, launch: Launch) -> ContactRun {
        let mut out = ContactRun {
            phases: PhaseSeq::default(),
            end: ContactEnd::Failed(NotSteady::Invalid {
                reason: "contact not started",
            }),
            time: 0.0,
            friction_work: 0.0,
        };
        if !(launch.theta_dot >= 0.0 && launch.theta_dot.is_finite() && launch.spin.is_finite()) {
            out.end = ContactEnd::Failed(NotSteady::Invalid {
                reason: "launch velocity not finite and >= 0",
            });
            return out;
        }
        let mut theta = scene.theta_0;
        let mut u = launch.theta_dot * launch.theta_dot;
        let mut w = launch.spin;
        // Slip velocity known exactly zero when the launch rolls.
        let mut s = if launch.spin == launch.theta_dot {
            0.0
        } else {
            launch.theta_dot - launch.spin
        };
        // After a rolling phase ends at Θ_G (H = +f) the bead slips forward.
        let mut forced: Option<PhaseKind> = None;
        for _ in 0..4 * MAX_PHASES {
            let kind = match forced.take() {
                Some(k) => k,
                None => match mode_at(scene, theta, u, s) {
                    Ok(k) => k,
                    Err(e) => {
                        out.end = ContactEnd::Failed(e);
                        return out;
                    }
                },
            };
            if !out.phases.push(kind, theta) {
                out.end = ContactEnd::Failed(NotSteady::Invalid {
                    reason: "more than 8 phases on one bead (chattering)",
                });
                return out;
            }
            let step = match kind {
                PhaseKind::Roll => self.roll_phase(scene, theta, u),
                PhaseKind::Slip => self.slip_phase(scene, theta, u, w, 1.0),
                PhaseKind::BackSlip => self.slip_phase(scene, theta, u, w, -1.0),
            };
            match step {
                Err(e) => {
                    out.end = ContactEnd::Failed(e);
                    return out;
                }
                Ok(p) => {
                    if p.end == theta && !p.at_collision {
                        // A phase of zero length (rounding at its own boundary) is not one.
                        out.phases.pop();
                    }
                    if kind == PhaseKind::Roll && !p.at_collision {
                        forced = Some(PhaseKind::Slip);
                    }
                    out.time += p.time;
                    out.friction_work += p.work;
                    theta = p.end;
                    u = p.u;
                    w = p.w;
                    s = 0.0;
                    if p.at_collision {
                        out.end = ContactEnd::Collision {
                            theta_dot: u.sqrt(),
                            spin: w,
                        };
                        return out;
                    }
                }
            }
        }
        out.end = ContactEnd::Failed(NotSteady::Invalid {
            reason: "phases of zero length repeat (chattering at a phase boundary)",
        });
        out
    }

    /// Rolling from (Θa, Θ̇a²) to Θ_G or Θf.
    fn roll_phase(
        &self,
        scene: &Scene,
        ta: f64,
        ua: f64,
    ) -> std::result::Result<PhaseEnd, NotSteady> {
        let b = scene.b;
        let rho = scene.rho;
        let vartheta = 2.0 * ta.cos() + (1.0 + rho) * ua;
        let Some(tg) = super::regimes::theta_g_of(rho, scene.f, vartheta) else {
            return Err(NotSteady::LiftOff { angle: ta });
        };
        let end = tg.max(ta).min(scene.theta_f);
        if ta < 0.0 && end > 0.0 {
            let h = (0.5 * ta).sin();
            if ua - 2.0 * b * h * h <= 0.0 {
                let r = (h * h - ua / (2.0 * b)).max(0.0).sqrt();
                return Err(NotSteady::Stops {
                    angle: -2.0 * r.min(1.0).asin(),
                });
            }
        }
        let u_end = stick::rolling_speed_sq(b, ta, ua, end);
        if u_end < 0.0 {
            let r = ((0.5 * ta).sin().powi(2) - ua / (2.0 * b)).max(0.0).sqrt();
            return Err(NotSteady::Stops {
                angle: -2.0 * r.min(1.0).asin(),
            });
        }
        if end.cos() - u_end < 0.0 {
            // N = ((3+ρ) cos Θ − ϑ)/(1+ρ) vanishes at cos Θ = ϑ/(3+ρ).
            let c = (vartheta / (3.0 + rho)).clamp(-1.0, 1.0);
            return Err(NotSteady::LiftOff { angle: c.acos() });
        }
        let time = if end > ta {
            stick::rolling_time(b, ta, end, ua).ok_or(NotSteady::Stops { angle: ta })?
        } else {
            0.0
        };
        Ok(PhaseEnd {
            end,
            u: u_end,
            w: u_end.sqrt(),
            time,
            work: 0.0,
            at_collision: end >= scene.theta_f,
        })
    }

    /// Slipping with sgn(s) = σ from (Θa, Θ̇a², ωa/ε) to the first event.
    fn slip_phase(
        &self,
        scene: &Scene,
        ta: f64,
        ua: f64,
        wa: f64,
        sigma: f64,
    ) -> std::result::Result<PhaseEnd, NotSteady> {
        let f = scene.f;
        let rho = scene.rho;
        let tf = scene.theta_f;
        let ph = SlipPhase::new(ta, ua, sigma * f);
        let u = |t: f64| ph.speed_sq(t);
        let (end, fail, tm, um) = slip_limits(&ph, ta, ua, tf)?;
        // 3. Slip → stick (s = 0). ds/dθ has the sign of q(θ) = ρ sin θ/(1+ρ) − σ f N: s moves
        // towards 0 only where σ q < 0.
        let eps_f = sigma * f / rho;
        let stick = SlipStick {
            ph: &ph,
            ta,
            wa,
            sigma,
            f,
            rho,
            eps_f,
            tol: self.tol,
        };
        let stick_at = if end > ta && f > 0.0 {
            stick.first_stick(end)
        } else {
            None
        };
        let (end, g_stick, at_collision) = match stick_at {
            Some((t, g)) if t < end => (t, Some(g), false),
            _ => {
                if let Some(e) = fail {
                    return Err(e);
                }
                (end, None, true)
            }
        };
        let u_end = if at_collision || end > ta {
            u(end).max(0.0)
        } else {
            ua
        };
        // Time: where Θ̇² stays well away from 0 the integrand 1/Θ̇ is as smooth as the spin's
        // and one K15 panel usually resolves it (with the spin integral, when it is still
        // needed, on the same abscissae); near a crawl (Θ̇² → 0 inside the phase) the slip
        // model's substitution takes over.
        let u_lo = if tm > ta && tm < end {
            um
        } else {
            ua.min(u_end)
        };
        let smooth = u_lo >= 1e-2 * ua.max(u_end) && u_lo > 0.0;
        let inv_speed = |t: f64| 1.0 / u(t).max(f64::MIN_POSITIVE).sqrt();
        let (g_end, time) = match (g_stick, smooth) {
            (None, true) => {
                let [g, t] = integrate_smooth_n(
                    |t| {
                        let (uu, _, c) = ph.speed_sq_sin_cos(t);
                        let uu = uu.max(f64::MIN_POSITIVE);
                        let r = 1.0 / uu.sqrt();
                        [(c - uu) * r, r]
                    },
                    ta,
                    end,
                    self.tol,
                );
                (g, t)
            }
            (Some(g), true) => (g, integrate_smooth(inv_speed, ta, end, self.tol)),
            (g, false) => (
                g.unwrap_or_else(|| stick.g_int(ta, end)),
                slip_time(&ph, ta, end, self.tol)?,
            ),
        };
        let w_end = wa + eps_f * g_end;
        // ∫ N dθ in closed form: ∫ cos − ∫ Θ̇², Θ̇² = Θ̇a² E + b (sin θ − sin Θa E) + c (cos θ −
        // cos Θa E), E = e^{2σf(θ−Θa)}.
        let d = end - ta;
        let k2 = 2.0 * sigma * f;
        let ie = if k2 == 0.0 { d } else { (k2 * d).exp_m1() / k2 };
        let (b_c, c_c) = super::slip::slip_coefficients(sigma * f);
        let (sa, ca) = ta.sin_cos();
        let (se, ce) = end.sin_cos();
        let int_u = ua * ie + b_c * ((ca - ce) - sa * ie) + c_c * ((se - sa) - ca * ie);
        let int_n = (se - sa) - int_u;
        let work = sigma * f * (int_n - wa * g_end) - f * f * g_end * g_end / (2.0 * rho);
        Ok(PhaseEnd {
            end,
            u: u_end,
            w: w_end,
            time,
            work,
            at_collision,
        })
    }

    /// Runs `beads` contacts from a launch on the first bead; the trace of each.
    pub fn transient(
        &self,
        scene: &Scene,
        launch: Launch,
        beads: usize,
    ) -> Vec<(Launch, ContactRun)> {
        let mut out = Vec::with_capacity(beads);
        let mut l = launch;
        for _ in 0..beads {
            let r = self.run(scene, l);
            out.push((l, r));
            match r.end {
                ContactEnd::Collision { theta_dot, spin } => {
                    l = self.collide(scene, theta_dot, spin)
                }
                ContactEnd::Failed(_) => break,
            }
        }
        out
    }

    /// The steady contact: fixed point of the contact-to-contact map, reached by following the
    /// map from the rolling steady state (or, when there is none, from a bead launched just
    /// below lift-off), then solved directly.
    pub fn steady_state(&self, scene: &Scene) -> std::result::Result<SteadyContact, NotSteady> {
        match self.spin {
            SpinRule::Roll | SpinRule::Impact => self.steady_1d(scene),
            SpinRule::Keep | SpinRule::Factor(_) => self.steady_2d(scene),
        }
    }

    fn start(&self, scene: &Scene) -> f64 {
        let sc = if matches!(self.spin, SpinRule::Impact) {
            scene
                .with_k(
                    (scene.cos_alpha.powi(2) - scene.sin_alpha.powi(2) + scene.rho)
                        / (1.0 + scene.rho),
                )
                .ok()
        } else {
            Some(*scene)
        };
        if matches!(self.spin, SpinRule::Roll) {
            // The paper's stick/slip state is exact where its sequence is the true one and
            // close elsewhere: the best launch to follow the map from.
            if let Ok(st) = super::stickslip::steady(scene) {
                if st.initial_velocity > 0.0 {
                    return st.initial_velocity;
                }
            }
        }
        match sc.map(|s| (s, stick::steady(&s))) {
            Some((s, Ok(st))) if st.initial_velocity > 0.0 => {
                if matches!(self.spin, SpinRule::Impact) {
                    st.initial_velocity.min(s.sc_f.c.max(0.0).sqrt())
                } else {
                    st.initial_velocity
                }
            }
            _ => scene.k.min(1.0) * scene.sc_f.c.max(0.0).sqrt() * (1.0 - 1e-9),
        }
    }

    /// Launch speed y (rolling launch) → launch speed on the next bead.
    fn next_1d(&self, scene: &Scene, y: f64) -> std::result::Result<f64, NotSteady> {
        let r = self.run(
            scene,
            Launch {
                theta_dot: y,
                spin: y,
            },
        );
        match r.end {
            ContactEnd::Collision { theta_dot, spin } => {
                Ok(self.collide(scene, theta_dot, spin).theta_dot)
            }
            ContactEnd::Failed(e) => Err(e),
        }
    }

    fn excess(&self, scene: &Scene, y: f64) -> f64 {
        match self.next_1d(scene, y) {
            Ok(z) => z - y,
            Err(NotSteady::Stops { .. }) => -y.max(1e-300),
            Err(_) => f64::INFINITY,
        }
    }

    /// g(y) = P(y) − y with the contact run that gave it (failures mapped as in `excess`).
    fn excess_run(&self, scene: &Scene, y: f64) -> (f64, ContactRun) {
        let r = self.run(
            scene,
            Launch {
                theta_dot: y,
                spin: y,
            },
        );
        let g = match r.end {
            ContactEnd::Collision { theta_dot, spin } => {
                self.collide(scene, theta_dot, spin).theta_dot - y
            }
            ContactEnd::Failed(NotSteady::Stops { .. }) => -y.max(1e-300),
            ContactEnd::Failed(_) => f64::INFINITY,
        };
        (g, r)
    }

    /// Secant iteration on g(y) = P(y) − y from the start y0 and a second point y0 +
    /// g0/(1 − K²) (the rolling map's slope K² as the first estimate of P'): the map is smooth
    /// near an ordinary fixed point, so this converges superlinearly — 3 to 4 contacts from the
    /// stick/slip state. Stops once a secant step is below 1e-10 relative (the next iterate is
    /// then within ~1e-14 of the root, the steps shrinking superlinearly) and returns that
    /// iterate's run with the slope g' of the last secant. `None` when it does not settle (a
    /// jump of the map, a failed contact, no progress): the bracketing search takes over.
    fn secant_1d(&self, scene: &Scene, y0: f64, g0: f64) -> Option<(f64, usize, f64, ContactRun)> {
        let (mut ya, mut ga) = (y0, g0);
        let slope = (scene.k * scene.k).min(0.9);
        let mut yb = y0 + g0 / (1.0 - slope);
        if !(yb > 0.0 && yb.is_finite()) {
            return None;
        }
        let (mut gb, mut rb) = self.excess_run(scene, yb);
        let mut evals = 1;
        for _ in 0..12 {
            if !gb.is_finite() || gb <= -yb {
                return None;
            }
            let d = gb - ga;
            if d == 0.0 {
                return (gb.abs() <= 4.0 * f64::EPSILON * yb).then_some((yb, evals, -0.5, rb));
            }
            let dg = d / (yb - ya);
            if gb.abs() <= 4.0 * f64::EPSILON * yb {
                return Some((yb, evals, dg, rb));
            }
            let yc = yb - gb / dg;
            if !(yc > 0.0 && yc.is_finite()) {
                return None;
            }
            let (gc, rc) = self.excess_run(scene, yc);
            evals += 1;
            if (yc - yb).abs() <= 1e-10 * yb && gc.abs() <= (yc - yb).abs() {
                return Some((yc, evals, dg, rc));
            }
            if !(gc.abs() < gb.abs()) {
                // No progress: at the map's own rounding level when tiny, otherwise not smooth.
                return (gb.abs() <= 1e-13 * yb).then_some((yb, evals, dg, rb));
            }
            (ya, ga, yb, gb, rb) = (yb, gb, yc, gc, rc);
        }
        None
    }

    fn steady_1d(&self, scene: &Scene) -> std::result::Result<SteadyContact, NotSteady> {
        let y_hi = scene.sc_f.c.max(0.0).sqrt() * 2.0 + 1.0;
        let mut y = self.start(scene).max(1e-12);
        let mut g = self.excess(scene, y);
        let mut beads = 1;
        if g != 0.0 && g.is_finite() {
            if let Some((ys, n, dg, run)) = self.secant_1d(scene, y, g) {
                // H(y) = y to rounding: a fixed point. It is the one a bead settles on when
                // stable, |H'| < 1, i.e. −2 < g' < 0 (g' from the last secant); otherwise
                // follow the map as a bead would.
                if dg < 0.0 && dg > -2.0 {
                    return self.finish_run(
                        scene,
                        Launch {
                            theta_dot: ys,
                            spin: ys,
                        },
                        beads + n,
                        run,
                    );
                }
                beads += n;
            }
        }
        if g != 0.0 {
            let up = g > 0.0;
            let mut bracket = None;
            for _ in 0..200 {
                // A plain step of the map and a secant estimate from the last two points.
                let y1 = y + g;
                if !(y1 > 0.0) {
                    return Err(self.next_1d(scene, y1.max(1e-300)).err().unwrap_or(
                        NotSteady::Stops {
                            angle: scene.theta_0,
                        },
                    ));
                }
                if y1 > y_hi || !g.is_finite() {
                    return Err(self.next_1d(scene, y).err().unwrap_or(NotSteady::Runaway));
                }
                let g1 = self.excess(scene, y1);
                beads += 1;
                if (g1 > 0.0) != up || g1 == 0.0 {
                    bracket = Some((y, y1, g, g1));
                    break;
                }
                if !g1.is_finite() {
                    return Err(self.next_1d(scene, y1).err().unwrap_or(NotSteady::Runaway));
                }
                let d = g1 - g;
                let ye = if d != 0.0 && (d < 0.0) == up {
                    y1 - g1 * (y1 - y) / d
                } else {
                    y1 + 2.0 * g1
                };
                if ye.is_finite() && ye > 0.0 && ye < y_hi && (ye > y1) == up {
                    let ge = self.excess(scene, ye);
                    beads += 1;
                    if (ge > 0.0) != up || ge == 0.0 {
                        bracket = Some((y1, ye, g1, ge));
                        break;
                    }
                    if ge.is_finite() {
                        y = ye;
                        g = ge;
                        continue;
                    }
                }
                y = y1;
                g = g1;
                if g.abs() <= 16.0 * f64::EPSILON * y {
                    break;
                }
            }
            match bracket {
                Some((a, b, ga, gb)) => {
                    let (lo, hi, glo, ghi) = if a < b {
                        (a, b, ga, gb)
                    } else {
                        (b, a, gb, ga)
                    };
                    let r = brent(
                        |x| self.excess(scene, x).clamp(-1e300, 1e300),
                        lo,
                        hi,
                        glo.clamp(-1e300, 1e300),
                        ghi.clamp(-1e300, 1e300),
                        0.0,
                        200,
                    )
                    .ok_or(NotSteady::Invalid {
                        reason: "fixed-point bracket lost",
                    })?;
                    beads += r.evals;
                    if r.fx.abs() > 1e-9 * r.x.max(1e-3) {
                        return Err(NotSteady::MapJump { at: r.x });
                    }
                    y = r.x;
                }
                None if g.abs() <= 16.0 * f64::EPSILON * y => {}
                None => return Err(NotSteady::Runaway),
            }
        }
        self.finish(
            scene,
            Launch {
                theta_dot: y,
                spin: y,
            },
            beads,
        )
    }

    fn next_2d(&self, scene: &Scene, l: Launch) -> std::result::Result<Launch, NotSteady> {
        match self.run(scene, l).end {
            ContactEnd::Collision { theta_dot, spin } => Ok(self.collide(scene, theta_dot, spin)),
            ContactEnd::Failed(e) => Err(e),
        }
    }

    fn steady_2d(&self, scene: &Scene) -> std::result::Result<SteadyContact, NotSteady> {
        let y0 = self.start(scene);
        let mut l = Launch {
            theta_dot: y0,
            spin: y0,
        };
        let mut beads = 0;
        // Follow the map until it settles (its contraction is about K² per bead), then
        // polish with Newton steps on the 2×2 finite-difference Jacobian.
        let mut converged = false;
        for _ in 0..5000 {
            let n = self.next_2d(scene, l)?;
            beads += 1;
            let dy = (n.theta_dot - l.theta_dot).abs() + (n.spin - l.spin).abs();
            l = n;
            if dy <= 1e-8 * (l.theta_dot.abs() + l.spin.abs()) {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(NotSteady::Runaway);
        }
        for _ in 0..8 {
            let f0 = self.next_2d(scene, l)?;
            // G(l) = F(l) − l, the residual of the fixed point.
            let r = Vector2::new(f0.theta_dot - l.theta_dot, f0.spin - l.spin);
            if r.abs().sum() <= 4.0 * f64::EPSILON * (l.theta_dot + l.spin.abs()) {
                break;
            }
            let h = 1e-7 * l.theta_dot.max(1e-3);
            let fy = self.next_2d(
                scene,
                Launch {
                    theta_dot: l.theta_dot + h,
                    spin: l.spin,
                },
            )?;
            let fw = self.next_2d(
                scene,
                Launch {
                    theta_dot: l.theta_dot,
                    spin: l.spin + h,
                },
            )?;
            beads += 3;
            // The Jacobian of G by forward differences, and the Newton step −J⁻¹ G through
            // the adjugate.
            let jac = Matrix2::new(
                (fy.theta_dot - f0.theta_dot) / h - 1.0,
                (fw.theta_dot - f0.theta_dot) / h,
                (fy.spin - f0.spin) / h,
                (fw.spin - f0.spin) / h - 1.0,
            );
            let det = jac.determinant();
            if det == 0.0 || !det.is_finite() {
                break;
            }
            let adjugate = Matrix2::new(jac.m22, -jac.m12, -jac.m21, jac.m11);
            let step = adjugate * (-r) / det;
            let cand = Launch {
                theta_dot: l.theta_dot + step.x,
                spin: l.spin + step.y,
            };
            let Ok(fc) = self.next_2d(scene, cand) else {
                break;
            };
            let rc = Vector2::new(fc.theta_dot - cand.theta_dot, fc.spin - cand.spin);
            if rc.abs().sum() < r.abs().sum() {
                l = cand;
            } else {
                break;
            }
        }
        self.finish(scene, l, beads)
    }

    fn finish(
        &self,
        scene: &Scene,
        l: Launch,
        beads: usize,
    ) -> std::result::Result<SteadyContact, NotSteady> {
        self.finish_run(scene, l, beads, self.run(scene, l))
    }

    /// The steady contact from the run at its launch `l`.
    fn finish_run(
        &self,
        scene: &Scene,
        l: Launch,
        beads: usize,
        r: ContactRun,
    ) -> std::result::Result<SteadyContact, NotSteady> {
        let ContactEnd::Collision { theta_dot, spin } = r.end else {
            let ContactEnd::Failed(e) = r.end else {
                unreachable!()
            };
            return Err(e);
        };
        if !(r.time.is_finite() && r.time > 0.0) {
            return Err(NotSteady::Invalid {
                reason: "contact time not finite",
            });
        }
        let next = self.collide(scene, theta_dot, spin);
        let translation = 0.5 * (theta_dot * theta_dot - next.theta_dot * next.theta_dot);
        // Spin energy ½ ρ m r² ω² = ½ ρ (ω/ε)² in units m g (R + r).
        let spin_loss = 0.5 * scene.rho * (spin * spin - next.spin * next.spin);
        Ok(SteadyContact {
            launch: l,
            final_theta_dot: theta_dot,
            final_spin: spin,
            run: r,
            beads,
            collision_translation: translation,
            collision_spin: spin_loss,
        })
    }
}

/// Where a slip phase from `ta` (Θ̇² = `ua` there) ends at the latest, before any stick:
/// the end of the bead `tf`, or the angle where the bead stops (Θ̇² = 0) or lifts off (N = 0),
/// with that failure; a lift-off at `ta` itself is the error. Also the angle `tm` of Θ̇²'s
/// lowest point between `ta` and `tf` and Θ̇² there, `um`.
fn slip_limits(
    ph: &SlipPhase,
    ta: f64,
    ua: f64,
    tf: f64,
) -> std::result::Result<(f64, Option<NotSteady>, f64, f64), NotSteady> {
    let u = |t: f64| ph.speed_sq(t);
    let nrm = |t: f64| t.cos() - ph.speed_sq(t);
    // 1. Stop: Θ̇² has at most one interior minimum on the bead (at a critical point
    // d²Θ̇²/dθ² = 2 (cos θ + σ f sin θ) > 0), where its slope changes sign.
    let mut end = tf;
    let mut fail: Option<NotSteady> = None;
    let ga = ph.speed_sq_slope(ta);
    let gb = ph.speed_sq_slope(tf);
    let tm = if ga >= 0.0 {
        ta
    } else if gb <= 0.0 {
        tf
    } else {
        brent(|t| ph.speed_sq_slope(t), ta, tf, ga, gb, 1e-15, 200)
            .map(|r| r.x)
            .unwrap_or(tf)
    };
    let um = u(tm);
    if !(um > 0.0) {
        let angle = if ua <= 0.0 {
            ta
        } else {
            brent(u, ta, tm, ua, um, 1e-15, 200)
                .map(|r| r.x)
                .unwrap_or(ta)
        };
        end = angle;
        fail = Some(NotSteady::Stops { angle });
    }
    // 2. Lift-off: N' = −3 sin θ + 2σf N, so at a critical point N'' = −3 cos θ < 0: N has
    // no interior minimum and is negative somewhere iff it is at an end.
    let na = nrm(ta);
    if na < 0.0 {
        return Err(NotSteady::LiftOff { angle: ta });
    }
    let ne = nrm(end);
    if ne < 0.0 {
        let angle = brent(nrm, ta, end, na, ne, 1e-15, 200)
            .map(|r| r.x)
            .unwrap_or(end);
        end = angle;
        fail = Some(NotSteady::LiftOff { angle });
    }
    Ok((end, fail, tm, um))
}

/// The slip → stick search of one slip phase with sgn(s) = σ from (Θa, Θ̇a², ωa/ε): the
/// functions of θ it reads, with the phase's constants.
struct SlipStick<'a> {
    /// The phase's Θ̇²(θ).
    ph: &'a SlipPhase,
    /// Start angle Θa.
    ta: f64,
    /// Spin at the start, ωa/ε.
    wa: f64,
    /// sgn(s).
    sigma: f64,
    /// Friction coefficient.
    f: f64,
    /// ρ.
    rho: f64,
    /// σ f/ρ.
    eps_f: f64,
    /// Quadrature tolerance.
    tol: f64,
}

impl SlipStick<'_> {
    /// (cos θ − Θ̇²)/Θ̇, the integrand of the spin integral G.
    #[inline]
    fn integrand(&self, t: f64) -> f64 {
        let (uu, _, c) = self.ph.speed_sq_sin_cos(t);
        let uu = uu.max(f64::MIN_POSITIVE);
        (c - uu) / uu.sqrt()
    }

    /// G from `a` to `b`.
    #[inline]
    fn g_int(&self, a: f64, b: f64) -> f64 {
        if b == a {
            return 0.0;
        }
        integrate_smooth(|t| self.integrand(t), a, b, self.tol)
    }

    /// σ q(θ): the sign of dσs/dθ = ((1+ρ)/ρ) σ q / Θ̇.
    #[inline]
    fn sq(&self, t: f64) -> f64 {
        let (sigma, f, rho) = (self.sigma, self.f, self.rho);
        let (uu, sn, c) = self.ph.speed_sq_sin_cos(t);
        sigma * (rho * sn / (1.0 + rho) - sigma * f * (c - uu))
    }

    /// s relative to its sign: σ s(θ) = σ (Θ̇ − wa) − (f/ρ) G(θ), with G(θ) = `g`.
    #[inline]
    fn sig_s(&self, t: f64, g: f64) -> f64 {
        let sigma = self.sigma;
        sigma * (self.ph.speed_sq(t).max(0.0).sqrt() - self.wa) - self.eps_f * sigma * g
    }

    /// dσs/dθ.
    #[inline]
    fn dsig_s(&self, t: f64) -> f64 {
        let rho = self.rho;
        (1.0 + rho) / rho * self.sq(t) / self.ph.speed_sq(t).max(f64::MIN_POSITIVE).sqrt()
    }

    /// The first stick (s = 0) between Θa and `end`: its angle and G there.
    fn first_stick(&self, end: f64) -> Option<(f64, f64)> {
        // σs decreases exactly where σq < 0. Scan σq on 16 panels for the stretches
        // [d0, d1] where it is negative (ends refined by Brent); on each, σs is monotone,
        // so it has a zero there iff σs(d1) ≤ 0, found by safeguarded Newton with the
        // closed-form derivative and the spin integral carried incrementally.
        let n = 16;
        let ta = self.ta;
        let grid = |i: usize| ta + (end - ta) * i as f64 / n as f64;
        let mut i = 0;
        let mut qa = self.sq(ta);
        let mut t_known = ta;
        let mut g_known = 0.0;
        while i < n {
            // Next stretch start.
            let d0 = if qa < 0.0 {
                grid(i)
            } else {
                let mut found = None;
                while i < n {
                    let (a, b) = (grid(i), grid(i + 1));
                    let qb = self.sq(b);
                    i += 1;
                    if qb < 0.0 {
                        found = Some(
                            brent(|t| self.sq(t), a, b, qa, qb, 1e-15, 200)
                                .map(|r| r.x)
                                .unwrap_or(a),
                        );
                        qa = qb;
                        break;
                    }
                    qa = qb;
                }
                match found {
                    Some(d) => d,
                    None => break,
                }
            };
            // Stretch end: the first grid point where σq ≥ 0 again. It need not be
            // refined: past the true end σs rises, so the first zero of σs after d0 is
            // the same on [d0, d1].
            let mut d1 = end;
            while i < n {
                let b = grid(i + 1);
                let qb = self.sq(b);
                i += 1;
                qa = qb;
                if qb >= 0.0 {
                    d1 = b;
                    break;
                }
            }
            let g0 = g_known + self.g_int(t_known, d0);
            let s0 = self.sig_s(d0, g0);
            if d0 == ta && s0 <= 0.0 {
                // The slip starts at s = 0 exactly where σq = 0 (at Θ_G, or where a slip
                // reverses): the rounding of σq there says nothing, the mode decision
                // already chose σ. Look from the next stretch on.
                t_known = d0;
                g_known = g0;
                continue;
            }
            if s0 <= 0.0 {
                return Some((d0, g0));
            }
            // σs decreases on [d0, d1]: walk it in 8 panels (the spin integral carried
            // from panel to panel) to the first panel where σs reaches 0.
            let panels = 8;
            let (mut pa, mut ga_, mut sa_) = (d0, g0, s0);
            let mut found = None;
            for k in 1..=panels {
                let pb = d0 + (d1 - d0) * k as f64 / panels as f64;
                let gb_ = ga_ + self.g_int(pa, pb);
                let sb_ = self.sig_s(pb, gb_);
                if sb_ <= 0.0 {
                    found = Some((pa, ga_, sa_, pb, gb_, sb_));
                    break;
                }
                (pa, ga_, sa_) = (pb, gb_, sb_);
            }
            let Some((d0, g0, s0, d1, g1, s1)) = found else {
                t_known = d1;
                g_known = ga_;
                continue;
            };
            return Some(self.stick_in_panel((d0, g0, s0), (d1, g1, s1)));
        }
        None
    }

    /// The zero of σs on a panel [d0, d1] where it falls from s0 > 0 to s1 ≤ 0 (with G = g0
    /// and g1 at the ends): its angle and G there.
    fn stick_in_panel(
        &self,
        (d0, g0, s0): (f64, f64, f64),
        (d1, g1, s1): (f64, f64, f64),
    ) -> (f64, f64) {
        // G on that panel from one Chebyshev interpolant (every Newton iterate reads
        // it), or by adaptive quadrature where the interpolant does not resolve it.
        let cheb = ChebIntegral::new(|t| self.integrand(t), d0, d1, self.tol);
        let g_from = |lo: f64, glo: f64, x: f64| match &cheb {
            Some(c) => g0 + c.eval(x),
            None => glo + self.g_int(lo, x),
        };
        // Safeguarded Newton on [lo, hi] with σs(lo) > 0 ≥ σs(hi).
        let (mut lo, mut glo) = (d0, g0);
        let mut hi = d1;
        let mut x = lo + (hi - lo) * s0 / (s0 - s1);
        let mut last = (d1, g1);
        for _ in 0..100 {
            if !(x > lo && x < hi) {
                x = 0.5 * (lo + hi);
            }
            let gx = g_from(lo, glo, x);
            let sx = self.sig_s(x, gx);
            last = (x, gx);
            if sx == 0.0 {
                break;
            }
            if sx > 0.0 {
                (lo, glo) = (x, gx);
            } else {
                hi = x;
            }
            let dx = self.dsig_s(x);
            let nx = x - sx / dx;
            let step = (nx - x).abs();
            // Newton within the bracket; otherwise bisect.
            x = if dx < 0.0 && nx > lo && nx < hi {
                nx
            } else {
                0.5 * (lo + hi)
            };
            if step <= 1e-10 * (1.0 + x.abs()) || hi - lo <= 1e-15 * (1.0 + x.abs()) {
                // Quadratic convergence: a Newton step below 1e-10 leaves the new
                // iterate within ~1e-20 of the zero, far below the rounding of σs
                // itself; take it as the event.
                if dx < 0.0 && nx > lo && nx < hi {
                    last = (nx, g_from(lo, glo, nx));
                }
                break;
            }
        }
        last
    }
}

/// End of one phase.
struct PhaseEnd {
    end: f64,
    u: f64,
    w: f64,
    time: f64,
    work: f64,
    at_collision: bool,
}

/// A steady contact of the general model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyContact {
    /// The launch on each bead (Θ̇0, ω0/ε).
    pub launch: Launch,
    /// Θ̇f.
    pub final_theta_dot: f64,
    /// ωf/ε.
    pub final_spin: f64,
    /// The contact itself.
    pub run: ContactRun,
    /// Contacts evaluated to find the fixed point.
    pub beads: usize,
    /// Translational kinetic energy lost at each collision.
    pub collision_translation: f64,
    /// Spin kinetic energy lost at each collision.
    pub collision_spin: f64,
}

impl SteadyContact {
    /// The energy partition (units m g (R + r)).
    pub fn energy(&self, scene: &Scene) -> super::energy::EnergyPartition {
        super::energy::EnergyPartition {
            potential_drop: 2.0 * scene.sin_delta_sin_alpha(),
            collision_translation: self.collision_translation,
            collision_spin: self.collision_spin,
            friction_work: self.run.friction_work,
        }
    }
}

impl Contact {
    /// The steady state as a forward-model outcome (v̄ = 2 sin α / τ, eq 10).
    pub fn evaluate(&self, scene: &Scene) -> Outcome {
        Self::outcome(scene, &self.steady_state(scene))
    }

    /// The forward-model outcome of a steady contact already computed.
    pub fn outcome(scene: &Scene, r: &std::result::Result<SteadyContact, NotSteady>) -> Outcome {
        let sc = (*r)?;
        let mut s = Steady::basic(
            2.0 * scene.sin_alpha / sc.run.time,
            sc.final_theta_dot,
            sc.launch.theta_dot,
            sc.run.time,
        );
        s.phases = Phases::Sequence(sc.run.phases);
        Ok(s)
    }
}
