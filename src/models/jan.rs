//! Jan's energy balance (§5.1, eqs 73–76): m g 2R sin δ = m λ v̄² + μ m g 2R cos δ.

use super::{NotSteady, Outcome, Steady};
use crate::scene::Scene;
use crate::scene::{ParameterError as Error, ParameterResult as Result};

/// Jan's model with collisional coefficient λ and bulk friction μ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jan {
    /// Collisional dissipation coefficient λ (eq 73).
    pub lambda: f64,
    /// Bulk resistance coefficient μ (eq 73).
    pub mu: f64,
}

impl Jan {
    /// A validated model (λ > 0, μ ≥ 0, both finite).
    pub fn new(lambda: f64, mu: f64) -> Result<Self> {
        if !(lambda.is_finite() && lambda > 0.0) {
            return Err(Error::InvalidParameter {
                field: "lambda",
                value: lambda.to_string(),
                reason: "must be > 0",
            });
        }
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(Error::InvalidParameter {
                field: "mu",
                value: mu.to_string(),
                reason: "must be >= 0",
            });
        }
        Ok(Jan { lambda, mu })
    }

    /// The paper's fits to Ristow's data at contact angle α: λ = 0.063 e^{4.96 sin α}
    /// (eq 75), μ = 0.0025 e^{7.46 sin α} (eq 76).
    pub fn paper_fit(alpha: f64) -> Self {
        let s = alpha.sin();
        Jan {
            lambda: 0.063 * (4.96 * s).exp(),
            mu: 0.0025 * (7.46 * s).exp(),
        }
    }

    /// v̄ = sqrt((2 sin α/λ)(sin δ − μ cos δ)) (eq 74); regime A where tan δ ≤ μ.
    pub fn evaluate(&self, scene: &Scene) -> Outcome {
        let drive = scene.sc_delta.s - self.mu * scene.sc_delta.c;
        if !(drive > 0.0) {
            return Err(NotSteady::Stops { angle: 0.0 });
        }
        let v = (2.0 * scene.sin_alpha / self.lambda * drive).sqrt();
        Ok(Steady::basic(v, v, v, 2.0 * scene.sin_alpha / v))
    }
}
