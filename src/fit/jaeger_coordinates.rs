//! The coordinates in which Jaeger's a1, a2, a3 are sampled: the series' velocity at its mean
//! slope, the slope of the law there, and a shape, all three derived from eqs 83–84.
//!
//! # Why
//!
//! With X = u² (eq 81), eq 83 reads tan δ = g(X) = a3 X + a1/(1 + a2 X). A series measured
//! over a few degrees pins the level and the slope of g where it was measured, and its
//! curvature only roughly. In (a1, a2, a3) the set of laws that fit is a curved ridge: once
//! a2 X ≫ 1 the resistance term is a1/(a2 X), so a1 and a2 slide along it together (at ξ = 0.8
//! on the default data, a2 from 0.2 to 170 and a1 with it). Ensemble moves, which are affine,
//! follow a straight ridge but not a curved one.
//!
//! # The coordinates
//!
//! Let δ̄ be the mean slope of the series' points, t₀ = tan δ̄, and X₀ the root of eq 84 at t₀
//! on the fitted branch: u₀ = √X₀ is the series' steady velocity at its mean slope in
//! Jaeger's units (eq 81). Then
//!
//! - s = g′(X₀) = a3 − a1 a2/(1 + a2 X₀)², the slope d tan δ/d(u²) of the law at t₀;
//! - w = a2 X₀, the shape: how far into the hyperbolic regime of the resistance term the mean
//!   slope lies (w ≪ 1: a1/(1 + a2 X) ≈ a1 (1 − a2 X), nearly a straight law; w ≫ 1:
//!   ≈ a1/(a2 X)). The curvature g″(X₀) = 2 a1 a2²/(1 + w)³ rises with w from 0 to a bound,
//!   so the data constrain w only from its effect on curvature, and nothing else moves with it.
//!
//! The sampling coordinates are y = (ln u₀, ln s, ln w) on the upper branch, where s > 0 (the
//! upper root is where g increases), and (ln u₀, s, ln w) on the lower branch, where s < 0
//! when eq 84 has two positive roots and s > 0 when it has one.
//!
//! # Back to a1, a2, a3
//!
//! With P = 1 + w and Q = 1 + 2w, the two conditions g(X₀) = t₀ (eq 83 at the mean slope) and
//! g′(X₀) = s are linear in a1 and a3 at fixed a2 = w/X₀:
//!
//! ```text
//!   a3 X₀ + a1/P        = t₀
//!   a3 − a1 w/(X₀ P²)   = s
//! ```
//!
//! so that, with D = t₀ − s X₀,
//!
//! ```text
//!   a1 = D P²/Q,   a2 = w/X₀,   a3 = s + D a2/Q.                       (J1)
//! ```
//!
//! a1 ≥ 0 is D ≥ 0, i.e. s X₀ ≤ t₀; a3 > 0 is one more condition on the lower branch only. g is
//! convex in X (g″ > 0), so on the upper branch (s > 0) X₀ is the larger root of eq 84 at t₀,
//! and y ↦ a is one to one. On the lower branch the map is kept one to one by requiring that
//! the lower root of eq 84 at t₀ be X₀ (a point y that lands on the other root is outside the
//! domain).
//!
//! # Jacobian
//!
//! At fixed a2, ∂(a1, a3)/∂(X₀, s) has determinant −s P²/Q (expand (J1): the terms in D
//! cancel), so |det ∂(a1, a2, a3)/∂(X₀, s, a2)| = |s| P²/Q. From y, X₀ = e^{2y₁},
//! s = e^{y₂} (upper) or y₂ (lower), and a2 = e^{y₃}/X₀: a triangular map with determinant
//! 2X₀ · s · a2 (upper) or 2X₀ · a2 (lower). Since X₀ a2 = w,
//!
//! ```text
//!   ln |det ∂a/∂y| = ln 2 + ln w + 2 ln P − ln Q + 2 ln s      (upper)
//!                  = ln 2 + ln w + 2 ln P − ln Q + ln |s|      (lower)   (J2)
//! ```
//!
//! The posterior in y is p(a(y)) |det ∂a/∂y|: the priors stated on a1, a2, a3 keep their
//! meaning, and the draws are reported in a1, a2, a3. `src/fit/suite/jaeger_posterior.rs` checks
//! (J1) against its inverse, (J2) against finite differences, and the posterior quantiles
//! against those sampled in (ln a1, ln a2, ln a3).

use crate::inverse::posterior::Reparameterisation;
use crate::models::jaeger::Jaeger;
use crate::models::JaegerBranch;

/// What Jaeger's formula needs of a point: (tan δ, cos δ, ε).
pub type JaegerX = (f64, f64, f64);

/// The shape w = a2 X₀ a sampling run starts from at least: a least-squares optimum on the
/// bound a2 = 0 has ln w = −∞, and the posterior density in ln w falls as w towards it (the
/// factor w of (J2)). At w = e⁻³ ≈ 0.05 the resistance term a1/(1 + a2 X) is within 1 % of
/// the straight a1 (1 − a2 X) wherever X < 2X₀; on the shipped data ln w = −3 lies between the
/// 2.5 % quantile and the median of ln w in the three posteriors whose optimum has a2 = 0.
pub(crate) const START_MIN_LN_SHAPE: f64 = -3.0;

/// Relative agreement required between X₀ and the lower root of eq 84 at t₀ on the lower
/// branch (the two differ by rounding only when y is in the domain).
const ROOT_CHECK: f64 = 1e-9;

/// The sampling coordinates of Jaeger's law for one series (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JaegerCoordinates {
    /// t₀ = tan δ̄, δ̄ the mean slope of the series' points.
    pub tan_mean_slope: f64,
    /// The branch fitted.
    pub branch: JaegerBranch,
}

impl JaegerCoordinates {
    /// The coordinates of a series whose points are `x` ((tan δ, cos δ, ε) per point), on
    /// `branch`: t₀ is the tangent of the mean of the points' slopes. `None` without points.
    pub fn for_series(x: &[JaegerX], branch: JaegerBranch) -> Option<Self> {
        if x.is_empty() {
            return None;
        }
        let mean = x.iter().map(|q| q.0.atan()).sum::<f64>() / x.len() as f64;
        Some(JaegerCoordinates {
            tan_mean_slope: mean.tan(),
            branch,
        })
    }

    /// (a1, a2, a3) from the coordinates y (J1), with ln |det ∂a/∂y| (J2); `None` outside the
    /// domain (a1 < 0, a3 ≤ 0, not finite, or on the lower branch X₀ not the lower root).
    pub fn to_params(self, y: &[f64]) -> Option<([f64; 3], f64)> {
        let t0 = self.tan_mean_slope;
        let x0 = (2.0 * y[0]).exp();
        let (s, ln_ds) = match self.branch {
            JaegerBranch::Upper => (y[1].exp(), y[1]),
            JaegerBranch::Lower => (y[1], 0.0),
        };
        let w = y[2].exp();
        let (p, q) = (1.0 + w, 1.0 + 2.0 * w);
        let d = t0 - s * x0;
        let a2 = w / x0;
        let a = [d * p * p / q, a2, s + d * a2 / q];
        if !(a.iter().all(|v| v.is_finite()) && a[0] >= 0.0 && a[1] >= 0.0 && a[2] > 0.0) {
            return None;
        }
        if self.branch == JaegerBranch::Lower {
            let m = Jaeger {
                a1: a[0],
                a2: a[1],
                a3: a[2],
                branch: self.branch,
            };
            let root = m.roots(t0).lower?;
            if !((root - x0).abs() <= ROOT_CHECK * x0) {
                return None;
            }
        }
        let log_j = std::f64::consts::LN_2 + y[2] + 2.0 * p.ln() - q.ln() + s.abs().ln() + ln_ds;
        log_j.is_finite().then_some((a, log_j))
    }

    /// The coordinates of (a1, a2, a3): `None` where eq 84 has no root at t₀ on the branch,
    /// where a2 = 0 (ln w = −∞), or on the upper branch where s ≤ 0 (a double root).
    pub fn to_coordinates(self, a: &[f64]) -> Option<[f64; 3]> {
        let y = self.coordinates_of(a)?;
        y.iter().all(|v| v.is_finite()).then_some(y)
    }

    /// (ln u₀, ln s or s, ln w) of a, ln w = −∞ when a2 = 0.
    fn coordinates_of(&self, a: &[f64]) -> Option<[f64; 3]> {
        let x0 = self.root(a)?;
        let w = a[1] * x0;
        let s = a[2] - a[0] * a[1] / ((1.0 + w) * (1.0 + w));
        let y1 = match self.branch {
            JaegerBranch::Upper if s > 0.0 => s.ln(),
            JaegerBranch::Upper => return None,
            JaegerBranch::Lower => s,
        };
        Some([0.5 * x0.ln(), y1, w.ln()])
    }

    /// X₀: the root of eq 84 at t₀ on the branch.
    fn root(&self, a: &[f64]) -> Option<f64> {
        if !(a[0] >= 0.0 && a[1] >= 0.0 && a[2] > 0.0) {
            return None;
        }
        let m = Jaeger {
            a1: a[0],
            a2: a[1],
            a3: a[2],
            branch: self.branch,
        };
        let r = m.roots(self.tan_mean_slope);
        match self.branch {
            JaegerBranch::Upper => r.upper,
            JaegerBranch::Lower => r.lower,
        }
        .filter(|x| x.is_finite() && *x > 0.0)
    }
}

impl Reparameterisation for JaegerCoordinates {
    fn params(&self, y: &[f64], x: &mut [f64]) -> Option<f64> {
        let (a, log_j) = self.to_params(y)?;
        x.copy_from_slice(&a);
        Some(log_j)
    }

    fn coordinates(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.to_coordinates(x).map(|y| y.to_vec())
    }

    /// The coordinates of (a1, a2, a3) with ln w raised to at least `START_MIN_LN_SHAPE`:
    /// the same level u₀ and slope s at the mean slope, a little curvature where the optimum
    /// had none.
    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        let mut y = self.coordinates_of(x)?;
        y[2] = y[2].max(START_MIN_LN_SHAPE);
        self.to_params(&y)?;
        Some(y.to_vec())
    }
}
