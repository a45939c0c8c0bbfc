//! What the paths of the K inversion share: the bracket of K and what sets its ends, a root,
//! a full estimate, and why a measurement has no K.

use crate::models::Steady;
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

impl LowerLimit {
    /// The name in the `k` command's `lower_limit` column.
    pub fn name(self) -> &'static str {
        match self {
            LowerLimit::Crawl => "crawl-over-top",
            LowerLimit::Zero => "K=0",
            LowerLimit::Model => "model-limit",
        }
    }
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

impl UpperLimit {
    /// The name in the `k` command's `upper_limit` column.
    pub fn name(self) -> &'static str {
        match self {
            UpperLimit::LiftOff => "lift-off",
            UpperLimit::Model => "model-limit",
        }
    }
}

/// The range of K over which a model has a steady state at one (ξ, δ, ρ, f).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KBracket {
    /// Lowest K (exclusive).
    pub lo: f64,
    /// Highest K (inclusive: the forward model is steady there; for a stick/slip range ending
    /// at the map's saddle-node, the last K below it where the forward model finds the stable
    /// fixed point — tested to within 1e-9 of the range in src/fit/suite/k_inversion.rs).
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

impl KEstimate {
    /// The `k` command's regime and status words: `B`/`ok` with a K, `A`/`below-range`,
    /// `C`/`above-range`, and no regime for `invalid`.
    pub fn regime_status(&self) -> (&'static str, &'static str) {
        match &self.root {
            Ok(_) => ("B", "ok"),
            Err(KFailure::BelowRange) => ("A", "below-range"),
            Err(KFailure::AboveRange) => ("C", "above-range"),
            Err(KFailure::Invalid(_)) => ("", "invalid"),
        }
    }

    /// K at the measured v̄, or why there is none.
    pub fn k(&self) -> Result<f64, KFailure> {
        self.root.as_ref().map(|r| r.k).map_err(Clone::clone)
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
    /// dv̄/dK at the root: analytic where the stick model's search runs in the launch speed over
    /// the top, δ < α (relative error a few ε), else a second-order difference on steps
    /// uniform in ln(K − K_min) (relative error up to about 1e-9; docs/GUIDE.md, `dv_dK`).
    pub dv_dk: Option<f64>,
    /// Θ_G at the root (radians): where rolling gives way to slip (eq 36); for the rolling
    /// models, where the steady rolling motion would need more friction than f.
    pub theta_g: Option<f64>,
    /// Notes on the interval ends.
    pub notes: Vec<String>,
}

/// Why an end of the interval at v ± σ is an end of the bracket ([`end_note`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AtEnd {
    /// v ∓ σ ≤ 0: the lower end.
    NotPositive,
    /// v ∓ σ is below the steady range: the lower end.
    Below,
    /// v ∓ σ is above the steady range: the upper end.
    Above,
}

/// The note of an interval end `end` (`K_lo` or `K_hi`, at `side`, `v - sigma_v` or
/// `v + sigma_v`) that is an end of the bracket, for the reason `why`.
pub(crate) fn end_note(end: &str, side: &str, why: AtEnd) -> String {
    let (which, reason) = match why {
        AtEnd::NotPositive => ("lower", " <= 0"),
        AtEnd::Below => ("lower", " is below the steady range"),
        AtEnd::Above => ("upper", " is above the steady range"),
    };
    [end, " is the bracket's ", which, " end: ", side, reason].concat()
}
