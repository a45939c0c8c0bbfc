//! Slip over the whole contact (§4.3, eqs 37–53 corrected) and its elliptic approximation
//! (eqs 54–59), plus the forward-slip phase shared with the stick/slip model.

use super::{NotSteady, Outcome, Phases, Steady};
use crate::scene::Scene;
use crate::special::elliptic::cos_integral;
use crate::special::quad::{gk21_pairs, integrate, QuadOptions};
use crate::special::root::brent;
use crate::special::SinCos;

/// Coefficients of the slip first integral Θ̇² = a e^{2fΘ} + b sin Θ + c cos Θ (eq 39):
/// b = −6f/(1+4f²), c = (4f² − 2)/(1+4f²).
#[inline]
pub fn slip_coefficients(f: f64) -> (f64, f64) {
    let d = 1.0 + 4.0 * f * f;
    (-6.0 * f / d, (4.0 * f * f - 2.0) / d)
}

/// A forward-slip phase (friction T = f N opposing the motion, eq 37) that starts at angle
/// `theta_s` with squared speed `ws_sq`.
#[derive(Debug, Clone, Copy)]
pub struct SlipPhase {
    /// Angle where the slip starts.
    pub theta_s: f64,
    /// Squared speed there.
    pub ws_sq: f64,
    /// Friction coefficient.
    pub f: f64,
    b: f64,
    c: f64,
    sin_s: f64,
    cos_s: f64,
}

impl SlipPhase {
    /// A phase starting at `theta_s` with squared speed `ws_sq`.
    pub fn new(theta_s: f64, ws_sq: f64, f: f64) -> Self {
        let (b, c) = slip_coefficients(f);
        let (sin_s, cos_s) = theta_s.sin_cos();
        SlipPhase {
            theta_s,
            ws_sq,
            f,
            b,
            c,
            sin_s,
            cos_s,
        }
    }

    /// Θ̇²(θ) = a e^{2f(θ−Θs)} + b sin θ + c cos θ with a = Θ̇s² − b sin Θs − c cos Θs
    /// (eqs 38, 40), written as Θ̇s² E + b (sin θ − sin Θs E) + c (cos θ − cos Θs E),
    /// E = e^{2f(θ−Θs)}, with the differences taken in product form so that small f and
    /// θ near Θs keep their digits.
    #[inline]
    pub fn speed_sq(&self, theta: f64) -> f64 {
        self.speed_sq_offset(theta - self.theta_s)
    }

    /// [`Self::speed_sq`] at θ = Θs + d, for offsets d below the resolution of θ itself (a
    /// bead launched almost at rest has a boundary layer of width Θ̇s²/|dΘ̇²/dθ|).
    #[inline]
    pub fn speed_sq_offset(&self, d: f64) -> f64 {
        let em1 = (2.0 * self.f * d).exp_m1();
        let (sh, _) = (0.5 * d).sin_cos();
        let (sm, cm) = (self.theta_s + 0.5 * d).sin_cos();
        let dsin = 2.0 * cm * sh;
        let dcos = -2.0 * sm * sh;
        self.ws_sq * (1.0 + em1)
            + self.b * (dsin - self.sin_s * em1)
            + self.c * (dcos - self.cos_s * em1)
    }

    /// [`Self::speed_sq`] with sin θ and cos θ, which come almost free from the half-angle
    /// sines and cosines it already needs (addition formulas: a few ulp).
    #[inline]
    pub fn speed_sq_sin_cos(&self, theta: f64) -> (f64, f64, f64) {
        let d = theta - self.theta_s;
        let em1 = (2.0 * self.f * d).exp_m1();
        let (sh, ch) = (0.5 * d).sin_cos();
        let (sm, cm) = (self.theta_s + 0.5 * d).sin_cos();
        let dsin = 2.0 * cm * sh;
        let dcos = -2.0 * sm * sh;
        let u = self.ws_sq * (1.0 + em1)
            + self.b * (dsin - self.sin_s * em1)
            + self.c * (dcos - self.cos_s * em1);
        (u, sm * ch + cm * sh, cm * ch - sm * sh)
    }

    /// d(Θ̇²)/dθ = 2 Θ̈ = 2 (sin θ − f (cos θ − Θ̇²)) (eq 37).
    #[inline]
    pub fn speed_sq_slope(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        2.0 * (s - self.f * (c - self.speed_sq(theta)))
    }

    /// Time to slip from Θs to `theta_end`, or where the bead stops.
    pub fn time_to(&self, theta_end: f64, tol: f64) -> Result<f64, NotSteady> {
        slip_time(self, self.theta_s, theta_end, tol)
    }
}

/// ∫_{θa}^{θb} dθ / sqrt(Θ̇²(θ)) on one Gauss–Kronrod 10/21 panel, for a phase whose speed
/// grows from θa (slope `ga` ≥ 0 of Θ̇² there): `None` unless QUADPACK's error estimate is
/// within `tol` of the value (the caller then subdivides). The twenty off-centre abscissae come
/// in pairs θc ± t, and each pair shares one sin_cos and one exp_m1 through the addition
/// formulas, with Θ̇² in the cancellation-free form of [`SlipPhase::speed_sq_offset`]: about
/// 0.5 µs where the adaptive 15-point rule needed about 2 µs (three panels) on the stick/slip
/// scenes of `cargo bench --bench forward`, with the same value to 1e-15.
fn slip_time_panel(ph: &SlipPhase, a: f64, b: f64, ga: f64, tol: f64) -> Option<f64> {
    let m = ph.speed_sq(a);
    let h = 0.5 * (b - a);
    // A zero of Θ̇² within ~m/ga of θa (a bead crawling into the slip) makes the integrand
    // far from polynomial on the panel: leave it to the adaptive, substituted rules.
    if !(m > 0.0) || m < 0.4 * h * ga {
        return None;
    }
    let d0 = 0.5 * (a + b) - ph.theta_s;
    let (sd, cd) = (0.5 * d0).sin_cos();
    let (sm, cm) = (ph.theta_s + 0.5 * d0).sin_cos();
    let ed = (2.0 * ph.f * d0).exp_m1();
    // Θ̇² at θs + d from sin(d/2), sin/cos(θs + d/2) and e^{2fd} − 1.
    let speed_sq = |sh: f64, s_mid: f64, c_mid: f64, em1: f64| {
        ph.ws_sq * (1.0 + em1)
            + ph.b * (2.0 * c_mid * sh - ph.sin_s * em1)
            + ph.c * (-2.0 * s_mid * sh - ph.cos_s * em1)
    };
    let uc = speed_sq(sd, sm, cm, ed);
    if !(uc > 0.0) {
        return None;
    }
    let mut bad = false;
    let (value, err) = gk21_pairs(
        |x| {
            let t = h * x;
            let (st, ct) = (0.5 * t).sin_cos();
            let ep = (2.0 * ph.f * t).exp_m1();
            let em = -ep / (1.0 + ep);
            let (scd, ssc) = (sd * ct, cd * st);
            let (smc, cms) = (sm * ct, cm * st);
            let (cmc, sms) = (cm * ct, sm * st);
            let lo = speed_sq(scd - ssc, smc - cms, cmc + sms, ed + em + ed * em);
            let hi = speed_sq(scd + ssc, smc + cms, cmc - sms, ed + ep + ed * ep);
            if !(lo > 0.0 && hi > 0.0) {
                bad = true;
                return (0.0, 0.0);
            }
            (1.0 / lo.sqrt(), 1.0 / hi.sqrt())
        },
        1.0 / uc.sqrt(),
        h,
    );
    (!bad && value.is_finite() && err <= tol * value).then_some(value)
}

/// ∫_{θa}^{θb} dθ / sqrt(Θ̇²(θ)) along a slip phase. The interval is split at the minimum of
/// Θ̇² and each side is integrated after θ = θm ± h sinh t with h = sqrt(Θ̇²(θm)/q),
/// q = ½ d²Θ̇²/dθ² at θm, which turns the near-singular peak (a bead crawling over the top)
/// into an almost constant integrand.
pub fn slip_time(ph: &SlipPhase, a: f64, b: f64, tol: f64) -> Result<f64, NotSteady> {
    if b <= a {
        return Ok(0.0);
    }
    let ga = ph.speed_sq_slope(a);
    let gb = ph.speed_sq_slope(b);
    let tm = if ga >= 0.0 {
        a
    } else if gb <= 0.0 {
        b
    } else {
        match brent(|t| ph.speed_sq_slope(t), a, b, ga, gb, 1e-15, 200) {
            Some(r) => r.x,
            None => {
                return Err(NotSteady::Invalid {
                    reason: "slip speed minimum not found",
                })
            }
        }
    };
    if ga >= 0.0 {
        // The slowest point is the start: one 21-point panel usually settles it.
        if let Some(t) = slip_time_panel(ph, a, b, ga, tol) {
            return Ok(t);
        }
    }
    let m = ph.speed_sq(tm);
    if !(m > 0.0) {
        // Stops where Θ̇² first reaches 0 before the minimum.
        let ya = ph.speed_sq(a);
        let angle = brent(|t| ph.speed_sq(t), a, tm, ya, m, 1e-15, 200)
            .map(|r| r.x)
            .unwrap_or(a);
        return Err(NotSteady::Stops { angle });
    }
    let q = (tm.cos() + ph.f * tm.sin()).max(1e-3);
    let h = (m / q).sqrt();
    // At an interior minimum Θ̇² carries an absolute rounding error of a few ulp of its O(1)
    // terms, i.e. a relative error ~ε/m there: no quadrature can resolve the integral better
    // than that, and asking for more only exhausts the panels (a bead crawling over the top,
    // m → 0). The tolerance is floored at that inherent level. At an end (a bead launched
    // slowly, m = its launch speed²) Θ̇² keeps its relative precision: no floor.
    let interior = tm != a && tm != b;
    let opts = QuadOptions {
        rel_tol: if interior {
            tol.max(8.0 * f64::EPSILON / m.min(1.0))
        } else {
            tol
        },
        abs_tol: 0.0,
        max_panels: 128,
    };
    let mut total = 0.0;
    // Minimum at an end with a nonzero slope g there (the bead launched slowly just past the
    // top): Θ̇² ≈ m + |g| u grows linearly away from it, and the layer has width m/|g|, not
    // sqrt(m/q). Then w = sqrt(m + |g| u) is the variable that makes the integrand flat:
    // dθ/Θ̇ = (2w/|g|) dw / Θ̇ ≈ 2 dw/|g|.
    let g_end = if tm == a && ga > 0.0 {
        ga
    } else if tm == b && gb < 0.0 {
        gb
    } else {
        0.0
    };
    let linear_layer = g_end != 0.0 && g_end.abs() > (m * q).sqrt();
    if linear_layer {
        let gl = g_end.abs();
        let dir = g_end.signum();
        let w0 = m.sqrt();
        let w1 = (m + gl * (b - a)).sqrt();
        let d0 = tm - ph.theta_s;
        let span = b - a;
        let r = integrate(
            |w: f64| {
                let u = ((w - w0) * (w + w0) / gl).min(span);
                let g = ph.speed_sq_offset(d0 + dir * u);
                if g > 0.0 {
                    2.0 * w / (gl * g.sqrt())
                } else {
                    f64::INFINITY
                }
            },
            w0,
            w1,
            opts,
        );
        total = r.value;
    }
    for (lo, dir) in [(a, -1.0), (b, 1.0)] {
        let span = (lo - tm).abs();
        if span == 0.0 || linear_layer {
            continue;
        }
        let tmax = (span / h).asinh();
        let r = integrate(
            |t: f64| {
                let g = ph.speed_sq_offset((tm - ph.theta_s) + dir * h * t.sinh());
                if g > 0.0 {
                    h * t.cosh() / g.sqrt()
                } else {
                    f64::INFINITY
                }
            },
            0.0,
            tmax,
            opts,
        );
        total += r.value;
    }
    if total.is_finite() && total > 0.0 {
        Ok(total)
    } else {
        Err(NotSteady::Invalid {
            reason: "slip integrand not positive",
        })
    }
}

/// Steady final velocity squared of the slip model (eq 50 corrected):
/// L'² = (b sin Θf + c cos Θf − (b sin Θ0 + c cos Θ0) e^{4fα}) / (1 − K² e^{4fα}), with the
/// differences in product form (e^{4fα} − 1 by expm1). `Err(Runaway)` when K² e^{4fα} ≥ 1.
pub fn final_velocity_sq(scene: &Scene) -> Result<f64, NotSteady> {
    let (b, c) = slip_coefficients(scene.f);
    let em1 = (4.0 * scene.f * scene.alpha).exp_m1();
    let k2 = scene.k * scene.k;
    let den = scene.one_minus_k2() - k2 * em1;
    if !(den > 0.0) {
        return Err(NotSteady::Runaway);
    }
    let sa = scene.sin_alpha;
    let dsin = 2.0 * scene.sc_delta.c * sa - scene.sc_0.s * em1;
    let dcos = -2.0 * scene.sc_delta.s * sa - scene.sc_0.c * em1;
    Ok((b * dsin + c * dcos) / den)
}

fn slip_state(scene: &Scene) -> Result<f64, NotSteady> {
    let l2 = final_velocity_sq(scene)?;
    if !(l2 > 0.0) {
        return Err(NotSteady::Stops {
            angle: scene.theta_0,
        });
    }
    Ok(l2)
}

/// Lift-off check at Θf (eq 30a), made after the stop check: a bead that stops on the way
/// never reaches Θf (regime A takes precedence).
fn check_lift_off(scene: &Scene, l2: f64) -> Result<(), NotSteady> {
    if scene.sc_f.c - l2 < 0.0 {
        return Err(NotSteady::LiftOff {
            angle: scene.theta_f,
        });
    }
    Ok(())
}

/// Steady slip over the whole contact (§4.3): τ' = ∫ dθ / G(θ) (eq 51) by adaptive
/// Gauss–Kronrod to relative tolerance 1e-14.
pub fn steady(scene: &Scene) -> Outcome {
    steady_tol(scene, 1e-14)
}

/// [`steady`] with a chosen quadrature tolerance.
pub fn steady_tol(scene: &Scene, tol: f64) -> Outcome {
    let l2 = slip_state(scene)?;
    let w0sq = scene.k * scene.k * l2;
    let ph = SlipPhase::new(scene.theta_0, w0sq, scene.f);
    let tau = slip_time(&ph, scene.theta_0, scene.theta_f, tol)?;
    check_lift_off(scene, l2)?;
    let l = l2.sqrt();
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, l, scene.k * l, tau);
    s.map_slope = Some(scene.k * scene.k * (4.0 * scene.f * scene.alpha).exp());
    s.phases = Phases::Slip;
    Ok(s)
}

/// Steady slip with the paper's approximation e^{2fθ} ≈ 1 + 4f² + 2f sin θ − 4f² cos θ
/// (eqs 54–56 as used): Θ̇² ≈ a' + b' sin θ + c' cos θ = a' + p cos(θ − θ*), whose time is an
/// elliptic integral (eqs 57–59), evaluated by [`cos_integral`].
pub fn steady_approx(scene: &Scene) -> Outcome {
    let l2 = slip_state(scene)?;
    let (b, c) = slip_coefficients(scene.f);
    let f = scene.f;
    let w0sq = scene.k * scene.k * l2;
    let a_inf = w0sq - b * scene.sc_0.s - c * scene.sc_0.c; // eq 53
    let e = a_inf * (-2.0 * f * scene.theta_0).exp();
    let a1 = e * (1.0 + 4.0 * f * f); // eq 56a
    let b1 = b + 2.0 * f * e; // eq 56b
    let c1 = c - 4.0 * f * f * e; // eq 56c
    let p = b1.hypot(c1); // eq 58c
    let star = b1.atan2(c1);
    // a' + p cos(θ − θ*) = a' − p cos ψ with ψ = θ − θ* − π, brought into (−π, π].
    let wrap = |x: f64| {
        let t = std::f64::consts::TAU;
        let mut y = x % t;
        if y <= -std::f64::consts::PI {
            y += t;
        } else if y > std::f64::consts::PI {
            y -= t;
        }
        y
    };
    let psi0 = wrap(scene.theta_0 - star - std::f64::consts::PI);
    let psif = psi0 + 2.0 * scene.alpha;
    if psif >= std::f64::consts::PI {
        return Err(NotSteady::Invalid {
            reason: "approximate slip integrand: contact spans the speed maximum",
        });
    }
    let vsq = |th: f64| a1 + b1 * th.sin() + c1 * th.cos();
    let w0 = vsq(scene.theta_0);
    let wf = vsq(scene.theta_f);
    let wt = a1 - p;
    if !(w0 > 0.0 && wf > 0.0) || (psi0 < 0.0 && psif > 0.0 && !(wt > 0.0)) {
        // The approximate speed² vanishes on the way: under this model the bead stops where
        // a' − p cos ψ = 0 before the top (ψ < 0).
        let psi_stop = -(a1 / p).clamp(-1.0, 1.0).acos();
        return Err(NotSteady::Stops {
            angle: psi_stop + star + std::f64::consts::PI
                - std::f64::consts::TAU
                    * ((psi_stop + star + std::f64::consts::PI - scene.theta_0)
                        / std::f64::consts::TAU)
                        .floor(),
        });
    }
    check_lift_off(scene, l2)?;
    let den = (0.5 * (psif + psi0)).sin() * scene.sin_alpha;
    let tau = cos_integral(
        SinCos::of(0.5 * psi0),
        SinCos::of(0.5 * psif),
        w0,
        wf,
        wt,
        den,
    );
    if !(tau.is_finite() && tau > 0.0) {
        return Err(NotSteady::Invalid {
            reason: "approximate slip time not finite",
        });
    }
    let l = l2.sqrt();
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, l, scene.k * l, tau);
    s.phases = Phases::Slip;
    Ok(s)
}
