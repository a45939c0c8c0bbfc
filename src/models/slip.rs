//! Slip over the whole contact (§4.3, eqs 37–53 corrected) and its elliptic approximation
//! (eqs 54–59), plus the forward-slip phase shared with the stick/slip model.

use super::{NotSteady, Outcome, Phases, Steady};
use crate::scene::Scene;
use crate::special::dd::Dd;
use crate::special::elliptic::cos_integral;
use crate::special::quad::{gk21_pairs, integrate, QuadOptions};
use crate::special::root::brent;
use crate::special::SinCos;

/// Coefficients of the slip first integral Θ̇² = a e^{2fΘ} + b sin Θ + c cos Θ (eq 39):
/// b = −6f/(1+4f²), c = (4f² − 2)/(1+4f²); beyond f = 1e150, where f² would overflow, in
/// the form divided through by f², b = −6g/(g² + 4), c = (4 − 2g²)/(g² + 4) with g = 1/f.
#[inline]
pub(crate) fn slip_coefficients(f: f64) -> (f64, f64) {
    if f.abs() > 1e150 {
        let g = 1.0 / f;
        let d = g * g + 4.0;
        return (-6.0 * g / d, (4.0 - 2.0 * g * g) / d);
    }
    let d = 1.0 + 4.0 * f * f;
    (-6.0 * f / d, (4.0 * f * f - 2.0) / d)
}

/// A forward-slip phase (friction T = f N opposing the motion, eq 37) that starts at angle
/// `theta_s` with squared speed `ws_sq`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SlipPhase {
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
        if theta.to_bits() == self.theta_s.to_bits() {
            // At Θs itself (where every slip phase is first asked for its slope): sin Θs and
            // cos Θs as `new` computed them, and Θ̇² = Θ̇s² exactly, since every offset term of
            // `speed_sq_offset(0)` vanishes. The same bits as below, without its three
            // sin_cos and one exp_m1.
            return 2.0 * (self.sin_s - self.f * (self.cos_s - self.ws_sq));
        }
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
/// formulas, with Θ̇² in the cancellation-free form of [`SlipPhase::speed_sq_offset`]: one
/// panel where the adaptive 15-point rule takes three on the stick/slip scenes of
/// `cargo bench --features bench-internals --bench forward` (timings in docs/PERFORMANCE.md), with the same value to
/// 1e-15.
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
pub(crate) fn slip_time(ph: &SlipPhase, a: f64, b: f64, tol: f64) -> Result<f64, NotSteady> {
    slip_time_in(ph, a, b, tol, None)
}

/// Where Θ̇² is least on [a, b] (an end, or the zero of its slope), with the slopes at a and b.
fn minimum_angle(ph: &SlipPhase, a: f64, b: f64) -> Result<(f64, f64, f64), NotSteady> {
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
    Ok((tm, ga, gb))
}

/// The least squared speed of the slip model's steady contact (§4.3) and where it lies:
/// (θm, Θ̇²(θm)), in double-double (`SlipDd`) when θm is interior. It vanishes at the slip
/// model's stop limit, like the squared top speed of rolling at δ_m.
#[cfg(test)]
pub fn speed_minimum(scene: &Scene) -> Result<(f64, f64), NotSteady> {
    let l2 = final_velocity_sq(scene)?;
    let ph = SlipPhase::new(scene.theta_0, scene.k * scene.k * l2, scene.f);
    let (tm, _, _) = minimum_angle(&ph, scene.theta_0, scene.theta_f)?;
    if tm == scene.theta_0 || tm == scene.theta_f {
        return Ok((tm, ph.speed_sq(tm)));
    }
    Ok((tm, SlipDd::new(scene)?.speed_sq_slope(tm).0.to_f64()))
}

/// Interior minima of Θ̇² below this value are recomputed in double-double when the phase is
/// the slip model's whole contact: the double minimum carries an absolute error of a few ulp
/// of its O(1) terms, i.e. a relative error ~1e-16/m, and v̄ inherits about 0.02 of it
/// (6.9e-12 at m = 5.4e-7 on the stop-limit rows of tests/reference/forward_refs.csv), so
/// above 1e-4 the double form costs at most ~4e-14 (5.4e-14 measured at m ≈ 1.1e-4). The
/// double-double path costs a few times the double one (docs/PERFORMANCE.md), hence the
/// threshold.
const DD_MINIMUM_BELOW: f64 = 1e-4;

/// A double minimum below this is a stop whatever its rounding (its absolute error is a few
/// ulp of O(1) terms): no double-double needed to say so.
const DD_MINIMUM_ABOVE: f64 = -1e-12;

/// [`slip_time`]; with `scene` given, the phase is the slip model's whole contact of that
/// scene (from Θ0 with Θ̇0² = K² L'²), and an interior speed minimum below
/// [`DD_MINIMUM_BELOW`] is taken from [`SlipDd`] with the integrand expanded about it
/// ([`slip_time_about_minimum`]).
fn slip_time_in(
    ph: &SlipPhase,
    a: f64,
    b: f64,
    tol: f64,
    scene: Option<&Scene>,
) -> Result<f64, NotSteady> {
    if b <= a {
        return Ok(0.0);
    }
    let (tm, ga, gb) = minimum_angle(ph, a, b)?;
    if ga >= 0.0 {
        // The slowest point is the start: one 21-point panel usually settles it.
        if let Some(t) = slip_time_panel(ph, a, b, ga, tol) {
            return Ok(t);
        }
    }
    let m = ph.speed_sq(tm);
    if let Some(scene) = scene {
        if tm != a && tm != b && m < DD_MINIMUM_BELOW && m > DD_MINIMUM_ABOVE {
            let exact = SlipDd::new(scene)?;
            return slip_time_about_minimum(ph, &exact, a, b, tm, tol);
        }
    }
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

/// The slip model's steady contact in double-double (about 30 digits), from the exact double
/// inputs ξ, δ, K, f: α = asin(1/(1+ξ)) by [`Dd::asin`], Θ0 and Θf = δ ∓ α, L'² (eq 50
/// corrected) and the coefficient a of eq 38 at Θ0. Three places need it: L'² where
/// 1 − K² e^{4fα} is small (its double form loses digits in proportion, 4.6e-11 at 1e-6),
/// the speed minimum of a bead crawling over the top, a difference of O(1) terms, and the
/// same minimum under the slip approximation ([`SlipDd::approx_speeds_sq`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SlipDd {
    f: f64,
    th0: Dd,
    sc0: (Dd, Dd),
    scf: (Dd, Dd),
    a: Dd,
    b: Dd,
    c: Dd,
    /// L'² = Θ̇f² (eq 50 corrected).
    pub l2: Dd,
}

impl SlipDd {
    /// The steady slip state of `scene`; `Err(Runaway)` when K² e^{4fα} ≥ 1.
    #[cold]
    #[inline(never)]
    pub fn new(scene: &Scene) -> Result<Self, NotSteady> {
        let f = scene.f;
        // sin α = 1/(1+ξ) (eq 2), cos α = sqrt(ξ (2+ξ))/(1+ξ): both without cancellation, and
        // Θ0, Θf = δ ∓ α through the addition formulas (two series evaluations, not four).
        let one_xi = Dd::sum(1.0, scene.xi);
        let sa = Dd::from(1.0) / one_xi;
        let ca = (Dd::from(scene.xi) * Dd::sum(2.0, scene.xi)).sqrt() / one_xi;
        let alpha = Dd::asin(sa);
        let (sd, cd) = Dd::sin_cos_dd(Dd::from(scene.delta));
        let th0 = Dd::from(scene.delta) - alpha;
        let (s0, c0) = (sd * ca - cd * sa, cd * ca + sd * sa);
        let (sf, cf) = (sd * ca + cd * sa, cd * ca - sd * sa);
        // b = −6f/(1+4f²), c = (4f² − 2)/(1+4f²) (eq 39).
        let f2x4 = Dd::prod(f, f).scale(4.0);
        let d = Dd::from(1.0) + f2x4;
        let b = -(Dd::prod(f, 6.0) / d);
        let c = (f2x4 - Dd::from(2.0)) / d;
        let em1 = Dd::exp_m1(alpha.mul_f64(f).scale(4.0));
        let k2 = Dd::prod(scene.k, scene.k);
        let den = Dd::from(1.0) - k2 - k2 * em1;
        if !(den.hi > 0.0) {
            return Err(NotSteady::Runaway);
        }
        let u0 = b * s0 + c * c0;
        let l2 = (b * (sf - s0) + c * (cf - c0) - u0 * em1) / den;
        Ok(SlipDd {
            f,
            th0,
            sc0: (s0, c0),
            scf: (sf, cf),
            a: k2 * l2 - u0,
            b,
            c,
            l2,
        })
    }

    /// Θ̇²(θ) = a e^{2f(θ−Θ0)} + b sin θ + c cos θ (eq 38) and its slope
    /// 2f a e^{2f(θ−Θ0)} + b cos θ − c sin θ at a double θ.
    pub fn speed_sq_slope(&self, theta: f64) -> (Dd, Dd) {
        let x = (Dd::from(theta) - self.th0).mul_f64(self.f).scale(2.0);
        let ae = self.a * (Dd::exp_m1(x) + Dd::from(1.0));
        let (s, c) = Dd::sin_cos_dd(Dd::from(theta));
        (
            ae + self.b * s + self.c * c,
            ae.mul_f64(self.f).scale(2.0) + self.b * c - self.c * s,
        )
    }

    /// The squared speed of the slip approximation, a′ + b′ sin θ + c′ cos θ (eqs 56a–c), in
    /// double-double: its least value a′ − p (eq 58c), formed as (a′² − b′² − c′²)/(a′ + p)
    /// so that nothing cancels but the double-double numerator, and its values at Θ0 and Θf.
    /// The coefficients come from e = a e^{−2fΘ0} (eq 53 with a at Θ0): a′ = e (1 + 4f²),
    /// b′ = b + 2f e, c′ = c − 4f² e.
    pub fn approx_speeds_sq(&self) -> ApproxSpeedsSq {
        let f = self.f;
        let e = self.a * (Dd::exp_m1(-self.th0.mul_f64(f).scale(2.0)) + Dd::from(1.0));
        let f2x4 = Dd::prod(f, f).scale(4.0);
        let a1 = e * (Dd::from(1.0) + f2x4);
        let b1 = self.b + e.mul_f64(f).scale(2.0);
        let c1 = self.c - e * f2x4;
        let bc2 = b1 * b1 + c1 * c1;
        let least = (a1 * a1 - bc2) / (a1 + bc2.sqrt());
        let at = |(s, c): (Dd, Dd)| (a1 + b1 * s + c1 * c).to_f64();
        ApproxSpeedsSq {
            least: least.to_f64(),
            at_0: at(self.sc0),
            at_f: at(self.scf),
        }
    }
}

/// Squared speeds of the slip approximation from [`SlipDd::approx_speeds_sq`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ApproxSpeedsSq {
    /// a′ − p: the least value over all θ (eq 58c).
    pub least: f64,
    /// At Θ0.
    pub at_0: f64,
    /// At Θf.
    pub at_f: f64,
}

/// 1/n! for n = 0..=19 (each one division from the previous: the first terms, which dominate,
/// are correctly rounded).
fn inv_factorials() -> [f64; 20] {
    let mut t = [1.0; 20];
    for n in 1..20 {
        t[n] = t[n - 1] / n as f64;
    }
    t
}

/// e^x − 1 − x to a few ulp relative for every x (Taylor series to x¹⁹ for |x| < 1, whose
/// truncation is below 2e-17 relative; the direct form beyond, where it cannot cancel).
fn exp_m1_minus_x(x: f64, inv: &[f64; 20]) -> f64 {
    if x.abs() >= 1.0 {
        return x.exp_m1() - x;
    }
    let mut p = 0.0;
    for n in (2..20).rev() {
        p = p * x + inv[n];
    }
    p * x * x
}

/// sin x − x to a few ulp relative for |x| < 1 (odd Taylor terms to x¹⁹, truncation below
/// 1e-16 relative), and the direct form beyond (absolute error ~1e-16, where the excess it
/// feeds is O(1)).
fn sin_minus_x(x: f64, inv: &[f64; 20]) -> f64 {
    if x.abs() >= 1.0 {
        return x.sin() - x;
    }
    let x2 = x * x;
    let mut p = 0.0;
    for n in (3..20).rev().step_by(2) {
        p = p * x2 + if n % 4 == 3 { -inv[n] } else { inv[n] };
    }
    p * x2 * x
}

/// The slip time of the slip model's whole contact about an interior speed minimum at `tm`
/// (see [`slip_time`]), with the minimum m = Θ̇²(θm) and the slope s1 there (≈ 0, θm being
/// rounded) in double-double from `exact`, and the integrand as m + [Θ̇²(θm + d) − m] where the
/// bracket is written in terms that are each O(d²) (eq 38 expanded about θm), plus s1 d:
///
/// `A (e^{2fd} − 1 − 2fd) + b [sin θm (cos d − 1) + cos θm (sin d − d)]`
/// `+ c [cos θm (cos d − 1) − sin θm (sin d − d)] + s1 d`, with A = m − b sin θm − c cos θm.
///
/// Its relative error is a few ulp at every d, so the integrand keeps double precision even
/// where Θ̇² is 1e-10 of its terms (a bead crawling over the top within 1e-9 of the stop
/// limit), and no tolerance floor is needed.
// Kept out of line, like `SlipDd::new`: inlined into `slip_time_in`, these rare paths slow the
// common double path (measured in docs/PERFORMANCE.md).
#[cold]
#[inline(never)]
fn slip_time_about_minimum(
    ph: &SlipPhase,
    exact: &SlipDd,
    a: f64,
    b: f64,
    tm: f64,
    tol: f64,
) -> Result<f64, NotSteady> {
    let (m_dd, s1_dd) = exact.speed_sq_slope(tm);
    let m = m_dd.to_f64();
    if !(m > 0.0) {
        let ya = ph.speed_sq(a);
        let angle = brent(|t| ph.speed_sq(t), a, tm, ya, ph.speed_sq(tm), 1e-15, 200)
            .map(|r| r.x)
            .unwrap_or(tm);
        return Err(NotSteady::Stops { angle });
    }
    let s1 = s1_dd.to_f64();
    let (sm, cm) = tm.sin_cos();
    let big_a = m - ph.b * sm - ph.c * cm;
    let f2 = 2.0 * ph.f;
    let inv = inv_factorials();
    let excess = |d: f64| {
        let cm1 = -2.0 * (0.5 * d).sin().powi(2);
        let smx = sin_minus_x(d, &inv);
        big_a * exp_m1_minus_x(f2 * d, &inv)
            + ph.b * (sm * cm1 + cm * smx)
            + ph.c * (cm * cm1 - sm * smx)
            + s1 * d
    };
    let q = (tm.cos() + ph.f * tm.sin()).max(1e-3);
    let h = (m / q).sqrt();
    let opts = QuadOptions {
        rel_tol: tol,
        abs_tol: 0.0,
        max_panels: 128,
    };
    let mut total = 0.0;
    for (end, dir) in [(a, -1.0), (b, 1.0)] {
        let span = (end - tm).abs();
        let tmax = (span / h).asinh();
        let r = integrate(
            |t: f64| {
                let g = m + excess(dir * h * t.sinh());
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

/// Below this value of 1 − K² e^{4fα}, [`final_velocity_sq`] takes L'² from [`SlipDd`]. The
/// double form's error in v̄ is up to about 3e-16/den (measured on
/// tests/reference/slip_limits_refs.csv: 4.6e-11 at den = 2e-6, 1.6e-13 at 1.1e-3, 1.4e-13 at
/// 2e-3), so above 1e-2 it stays near 3e-14 (measured: at most 1.2e-14 at den = 2e-2).
const DD_DENOMINATOR_BELOW: f64 = 1e-2;

/// A double denominator below this is a runaway (K² e^{4fα} > 1) whatever its rounding.
const DD_DENOMINATOR_ABOVE: f64 = -1e-13;

/// Steady final velocity squared of the slip model (eq 50 corrected):
/// L'² = (b sin Θf + c cos Θf − (b sin Θ0 + c cos Θ0) e^{4fα}) / (1 − K² e^{4fα}), with the
/// differences in product form (e^{4fα} − 1 by expm1), and from [`SlipDd`] where the
/// denominator is below `DD_DENOMINATOR_BELOW` (1e-2). `Err(Runaway)` when K² e^{4fα} ≥ 1.
pub(crate) fn final_velocity_sq(scene: &Scene) -> Result<f64, NotSteady> {
    let (b, c) = slip_coefficients(scene.f);
    let em1 = (4.0 * scene.f * scene.alpha).exp_m1();
    let k2 = scene.k * scene.k;
    let den = scene.one_minus_k2() - k2 * em1;
    if den < DD_DENOMINATOR_ABOVE {
        return Err(NotSteady::Runaway);
    }
    if den < DD_DENOMINATOR_BELOW {
        // 1 − K² e^{4fα} cancels: its double form has an absolute error of a few ulp of
        // K² e^{4fα} (and of α), a relative error ~1e-16/den.
        return SlipDd::new(scene).map(|s| s.l2.to_f64());
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
    let tau = slip_time_in(&ph, scene.theta_0, scene.theta_f, tol, Some(scene))?;
    check_lift_off(scene, l2)?;
    let l = l2.sqrt();
    let mut s = Steady::basic(2.0 * scene.sin_alpha / tau, l, scene.k * l, tau);
    s.map_slope = Some(scene.k * scene.k * (4.0 * scene.f * scene.alpha).exp());
    s.phases = Phases::Slip;
    Ok(s)
}

/// Below this fraction of a′, the least squared speed of the slip approximation on the contact
/// (a′ − p inside it, or the value at an end) is taken from [`SlipDd::approx_speeds_sq`]. In
/// double it is a difference of O(a′) terms that each carry a rounding error of order u a′, so
/// its relative error is about u a′/least, while v̄ depends on it only through the
/// problem's conditioning (at ξ = 4, δ = 22.551947104571017°, f = 0.2 the double path was
/// 118 cond·u off at 1e-3 above the stop limit in K, 242 cond·u at 1e-9). Measured on
/// tests/reference/slip_approx_limit_refs.csv in double: 9.9 cond·u at least/a′ = 6.8e-3, at
/// most 1.2 cond·u from 1.4e-2 up, hence the threshold.
const APPROX_DD_BELOW: f64 = 1e-2;

/// A double least squared speed below this fraction of a′ is a stop whatever its rounding.
const APPROX_DD_ABOVE: f64 = -1e-12;

/// [`SlipDd::approx_speeds_sq`] of the slip model's steady contact of `scene`, kept out of
/// line: the common double path of [`steady_approx`] does not need it.
#[cold]
#[inline(never)]
fn approx_speeds_sq_dd(scene: &Scene) -> Result<ApproxSpeedsSq, NotSteady> {
    Ok(SlipDd::new(scene)?.approx_speeds_sq())
}

/// Steady slip with the paper's approximation e^{2fθ} ≈ 1 + 4f² + 2f sin θ − 4f² cos θ
/// (eqs 54–56 as used): Θ̇² ≈ a' + b' sin θ + c' cos θ = a' + p cos(θ − θ*), whose time is an
/// elliptic integral (eqs 57–59), evaluated by [`cos_integral`]. Near the approximation's own
/// stop limit, where its least squared speed is below 1e-2 a′, that least value and the
/// squared speeds at Θ0 and Θf come from double-double (`SlipDd::approx_speeds_sq`).
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
    let mut w0 = vsq(scene.theta_0);
    let mut wf = vsq(scene.theta_f);
    let mut wt = a1 - p;
    let interior = psi0 < 0.0 && psif > 0.0;
    let least = if interior { wt } else { w0.min(wf) };
    if least < APPROX_DD_BELOW * a1 && least > APPROX_DD_ABOVE * a1 {
        let dd = approx_speeds_sq_dd(scene)?;
        (wt, w0, wf) = (dd.least, dd.at_0, dd.at_f);
    }
    if !(w0 > 0.0 && wf > 0.0) || (interior && !(wt > 0.0)) {
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
