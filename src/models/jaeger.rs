//! Jaeger's heuristic law (§5.2, eqs 80–90): tan δ = a3 u² + a1/(1 + a2 u²) with Jaeger's
//! velocity u = v_SI / sqrt(2 g r cos δ) (eq 81); in the paper's units u² = v̄² ε / (2 cos δ).

use super::{JaegerBranch, NotSteady, Outcome, Steady};
use crate::scene::Scene;
use crate::scene::{ParameterError as Error, ParameterResult as Result};

/// Jaeger's model with its three coefficients (Jaeger units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jaeger {
    /// a1: static part (≈ tan of the angle of maximum stability).
    pub a1: f64,
    /// a2: geometric coefficient.
    pub a2: f64,
    /// a3: collisional coefficient.
    pub a3: f64,
    /// Which root to return when there are two.
    pub branch: JaegerBranch,
}

/// The positive roots X = u² of eq 84 at one slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JaegerRoots {
    /// Number of positive roots (0, 1 or 2; Table I).
    pub count: u8,
    /// The smaller positive root, if any.
    pub lower: Option<f64>,
    /// The larger positive root, if any (equal to `lower` when there is one).
    pub upper: Option<f64>,
}

impl Jaeger {
    /// A validated model (a1 ≥ 0, a2 ≥ 0, a3 > 0, finite).
    pub fn new(a1: f64, a2: f64, a3: f64, branch: JaegerBranch) -> Result<Self> {
        for (field, v, ok) in [
            ("a1", a1, a1 >= 0.0),
            ("a2", a2, a2 >= 0.0),
            ("a3", a3, a3 > 0.0),
        ] {
            if !(v.is_finite() && ok) {
                return Err(Error::InvalidParameter {
                    field,
                    value: v.to_string(),
                    reason: "a1, a2 must be >= 0 and a3 > 0",
                });
            }
        }
        Ok(Jaeger { a1, a2, a3, branch })
    }

    /// Positive roots of a2 a3 X² + (a3 − a2 tan δ) X + (a1 − tan δ) = 0 (eq 84), computed
    /// without cancellation (the root of larger magnitude first, the other from the product).
    pub fn roots(&self, tan_delta: f64) -> JaegerRoots {
        let (a1, a2, a3) = (self.a1, self.a2, self.a3);
        let qa = a2 * a3;
        let qb = a3 - a2 * tan_delta;
        let qc = a1 - tan_delta;
        let mut r: Vec<f64> = Vec::with_capacity(2);
        if qa == 0.0 {
            // a2 = 0: tan δ = a3 X + a1.
            r.push(-qc / qb);
        } else {
            // Δ = (a3 + a2 tan δ)² − 4 a1 a2 a3 (eq 85).
            let disc = (a3 + a2 * tan_delta).powi(2) - 4.0 * a1 * a2 * a3;
            if disc >= 0.0 {
                let q = -0.5 * (qb + qb.signum() * disc.sqrt());
                if q != 0.0 {
                    r.push(q / qa);
                    r.push(qc / q);
                } else {
                    r.push(0.0);
                }
            }
        }
        let mut pos: Vec<f64> = r
            .into_iter()
            .filter(|x| x.is_finite() && *x > 0.0)
            .collect();
        pos.sort_by(|a, b| a.total_cmp(b));
        pos.dedup();
        JaegerRoots {
            count: pos.len() as u8,
            lower: pos.first().copied(),
            upper: pos.last().copied(),
        }
    }

    /// True when tan δ lies in the bistable band of eq 90:
    /// a1 > tan δ > (a3/a2)(2 sqrt(a1 a2/a3) − 1).
    pub fn bistable(&self, tan_delta: f64) -> bool {
        self.a2 > 0.0
            && tan_delta < self.a1
            && tan_delta > self.a3 / self.a2 * (2.0 * (self.a1 * self.a2 / self.a3).sqrt() - 1.0)
    }

    /// Mean velocity v̄ = sqrt(2 cos δ X / ε) from the chosen positive root X of eq 84
    /// (eqs 81, 83; eqs 87–89 as printed mix up a1, a2 and ε: docs/PHYSICS.md#jaeger).
    pub fn evaluate(&self, scene: &Scene) -> Outcome {
        let t = scene.sc_delta.s / scene.sc_delta.c;
        let roots = self.roots(t);
        let x = match self.branch {
            JaegerBranch::Upper => roots.upper,
            JaegerBranch::Lower => roots.lower,
        };
        let Some(x) = x else {
            return Err(NotSteady::Stops { angle: 0.0 });
        };
        let v = (2.0 * scene.sc_delta.c * x / scene.eps).sqrt();
        let mut s = Steady::basic(v, v, v, 2.0 * scene.sin_alpha / v);
        // Reuse the slot for "another steady state exists": the other root's velocity.
        if roots.count == 2 {
            let other = match self.branch {
                JaegerBranch::Upper => roots.lower,
                JaegerBranch::Lower => roots.upper,
            };
            s.other_fixed_point = other.map(|x| (2.0 * scene.sc_delta.c * x / scene.eps).sqrt());
        }
        Ok(s)
    }
}
