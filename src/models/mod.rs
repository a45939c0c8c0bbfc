//! Forward models: one trait, one file per model of the paper, plus regime limits and energy.
//!
//! Every evaluation returns either a steady state (regime B) or the reason there is none:
//! the bead stops (regime A, with where), lifts off or runs away (regime C), or a
//! model-specific failure. No evaluation returns NaN or panics on a valid [`Scene`].

pub mod auto;
pub mod contact;
pub mod energy;
pub mod jaeger;
pub mod jan;
pub mod md;
pub mod regimes;
pub(crate) mod sample;
pub(crate) mod slip;
pub(crate) mod stick;
pub(crate) mod stickquad;
pub(crate) mod stickslip;
#[cfg(test)]
mod suite;

use crate::scene::Scene;
use crate::scene::{ParameterError as Error, ParameterResult as Result};
use std::fmt;
use std::str::FromStr;

/// The paper's three regimes (§3.5): A the bead stops, B steady, C lift-off / jumps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Regime {
    /// δ < δ_m: the bead stops.
    A,
    /// δ_m < δ < δ_d: a steady mean velocity exists.
    B,
    /// δ > δ_d: the bead lifts off (or accelerates without bound).
    C,
}

impl Regime {
    /// The regime of an outcome: B when steady, else the one its failure implies (none for
    /// a failure that says nothing about the regime).
    pub fn of(o: &Outcome) -> Option<Regime> {
        match o {
            Ok(_) => Some(Regime::B),
            Err(e) => e.regime(),
        }
    }

    /// The regime's letter.
    pub fn letter(self) -> &'static str {
        match self {
            Regime::A => "A",
            Regime::B => "B",
            Regime::C => "C",
        }
    }
}

impl fmt::Display for Regime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.letter())
    }
}

/// A steady state (regime B) and its diagnostics. Velocities are dimensionless (units sqrt(g
/// (R+r))), angles in radians, times in units 1/ω0 (docs/PHYSICS.md#geometry-and-units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steady {
    /// Mean velocity v̄ = 2 sin α / τ (eq 10).
    pub mean_velocity: f64,
    /// Steady velocity Θ̇f just before each collision.
    pub final_velocity: f64,
    /// Steady velocity Θ̇0 just after each collision.
    pub initial_velocity: f64,
    /// Contact time τ on one row bead.
    pub contact_time: f64,
    /// Squared velocity at the top Θ = 0 (when the contact crosses it; otherwise the value
    /// the rolling law extrapolates to).
    pub top_velocity_sq: Option<f64>,
    /// Angle Θ_G where rolling gives way to slip (eq 36), stick/slip model.
    pub theta_g: Option<f64>,
    /// Slope of the final-velocity map at the fixed point (stable when |slope| < 1).
    pub map_slope: Option<f64>,
    /// Another fixed point of the final-velocity map found above the returned one (unstable
    /// when the returned one is stable): the scene is bistable.
    pub other_fixed_point: Option<f64>,
    /// Which phases the steady contact goes through.
    pub phases: Phases,
}

/// The phase sequence of a steady contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phases {
    /// Pure rolling over the whole contact.
    Roll,
    /// Slip over the whole contact.
    Slip,
    /// Rolling, then forward slip after Θ_G.
    RollSlip,
    /// No contact mechanics: a phenomenological law (Jan, Jaeger).
    None,
    /// Any sequence of rolling and slipping (the general contact model), with the angles of
    /// the phase changes.
    Sequence(contact::PhaseSeq),
}

impl fmt::Display for Phases {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Phases::Roll => "roll",
            Phases::Slip => "slip",
            Phases::RollSlip => "roll>slip",
            Phases::None => "",
            Phases::Sequence(p) => return write!(f, "{p}"),
        })
    }
}

impl Steady {
    pub(crate) fn basic(
        mean_velocity: f64,
        final_velocity: f64,
        initial_velocity: f64,
        tau: f64,
    ) -> Self {
        Steady {
            mean_velocity,
            final_velocity,
            initial_velocity,
            contact_time: tau,
            top_velocity_sq: None,
            theta_g: None,
            map_slope: None,
            other_fixed_point: None,
            phases: Phases::None,
        }
    }
}

/// Why a scene has no steady state under a model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NotSteady {
    /// Regime A: the bead stops at this angle Θ (radians) on a row bead.
    Stops {
        /// Angle where the velocity vanishes.
        angle: f64,
    },
    /// Regime C: the normal force vanishes at this angle Θ (radians).
    LiftOff {
        /// Angle where N = 0 (eq 30a).
        angle: f64,
    },
    /// Regime C: the final-velocity map has no fixed point; the velocity grows without bound
    /// (K ≥ 1 for rolling, K² e^{4fα} ≥ 1 for slip, …).
    Runaway,
    /// The model's own integrand or approximation is not valid here.
    Invalid {
        /// Why.
        reason: &'static str,
    },
    /// The final-velocity map is discontinuous where it changes sign: no true fixed point.
    MapJump {
        /// Velocity at the jump.
        at: f64,
    },
}

impl NotSteady {
    /// The regime this failure belongs to, when it is one of the paper's.
    pub fn regime(&self) -> Option<Regime> {
        match self {
            NotSteady::Stops { .. } => Some(Regime::A),
            NotSteady::LiftOff { .. } | NotSteady::Runaway => Some(Regime::C),
            _ => None,
        }
    }

    /// A short machine-readable status word.
    pub fn status(&self) -> &'static str {
        match self {
            NotSteady::Stops { .. } => "stops",
            NotSteady::LiftOff { .. } => "lift-off",
            NotSteady::Runaway => "no-steady-state",
            NotSteady::Invalid { .. } => "invalid",
            NotSteady::MapJump { .. } => "no-fixed-point",
        }
    }
}

impl std::error::Error for NotSteady {}

impl fmt::Display for NotSteady {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NotSteady::Stops { angle } => {
                write!(f, "bead stops at Theta = {:.6} deg", angle.to_degrees())
            }
            NotSteady::LiftOff { angle } => {
                write!(
                    f,
                    "normal force vanishes at Theta = {:.6} deg",
                    angle.to_degrees()
                )
            }
            NotSteady::Runaway => write!(f, "no fixed point: the velocity grows without bound"),
            NotSteady::Invalid { reason } => f.write_str(reason),
            NotSteady::MapJump { at } => write!(
                f,
                "final-velocity map jumps across the diagonal at {at:.6}: no fixed point"
            ),
        }
    }
}

/// Result of one forward evaluation.
pub type Outcome = std::result::Result<Steady, NotSteady>;

/// A forward model: scene → steady mean velocity or the reason there is none.
pub trait ForwardModel: Sync {
    /// The model's name as used on the command line.
    fn name(&self) -> &'static str;
    /// Evaluates the steady state of one scene.
    fn evaluate(&self, scene: &Scene) -> Outcome;
}

/// Which branch of Jaeger's quadratic (eq 84) to return when it has two positive roots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JaegerBranch {
    /// The larger root (default).
    Upper,
    /// The smaller root.
    Lower,
}

impl std::str::FromStr for JaegerBranch {
    type Err = String;
    /// `upper` or `lower`, in any case.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "upper" => Ok(JaegerBranch::Upper),
            "lower" => Ok(JaegerBranch::Lower),
            _ => Err("expected upper or lower".into()),
        }
    }
}

/// Every forward model by name, with its own parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    /// Pure rolling, exact (eqs 11–27 corrected).
    Stick,
    /// Pure rolling with F(Ω,k) ≈ asinh(tan Ω) (eq 29).
    StickApprox,
    /// Slip over the whole contact, exact quadrature (§4.3).
    Slip,
    /// Slip with the second-order exponential (eqs 54–59).
    SlipApprox,
    /// Roll then slip after Θ_G (§4.4).
    StickSlip,
    /// Jan's energy balance (eq 74).
    Jan(jan::Jan),
    /// Jaeger's heuristic law (eqs 80–89).
    Jaeger(jaeger::Jaeger),
    /// The general contact model: any sequence of rolling and slipping
    /// (docs/PHYSICS.md#general-contact-model).
    Contact(contact::Contact),
    /// Ristow's soft-contact molecular dynamics (§5.3, eqs 91–92).
    Md(md::Md),
    /// Per scene the cheapest model whose assumptions hold and whose error is within a target
    /// tolerance (stick, stickslip or contact; [`auto::Auto`]).
    Auto(auto::Auto),
}

impl Model {
    /// Names accepted on the command line.
    pub const NAMES: [&'static str; 10] = [
        "stick",
        "stick-approx",
        "slip",
        "slip-approx",
        "stickslip",
        "jan",
        "jaeger",
        "contact",
        "md",
        "auto",
    ];
}

/// A forward evaluation with what the general contact model and `auto` tell beyond the
/// outcome (the `forward` command's extra columns).
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The steady state, or why there is none.
    pub outcome: Outcome,
    /// The general contact model: its spin rule and its steady state (`None` where there is
    /// none).
    pub contact: Option<(contact::SpinRule, Option<contact::SteadyContact>)>,
    /// `auto`: the model it chose and why.
    pub auto: Option<auto::AutoOutcome>,
}

impl Model {
    /// [`ForwardModel::evaluate`] with the contact model's steady state and `auto`'s choice
    /// kept (the same outcome).
    pub fn evaluate_detailed(&self, scene: &Scene) -> Evaluation {
        match self {
            Model::Contact(c) => {
                let r = c.steady_state(scene);
                Evaluation {
                    outcome: contact::Contact::outcome(scene, &r),
                    contact: Some((c.spin, r.ok())),
                    auto: None,
                }
            }
            Model::Auto(au) => {
                let r = au.choose(scene);
                Evaluation {
                    outcome: r.outcome,
                    contact: None,
                    auto: Some(r),
                }
            }
            m => Evaluation {
                outcome: m.evaluate(scene),
                contact: None,
                auto: None,
            },
        }
    }
}

impl ForwardModel for Model {
    fn name(&self) -> &'static str {
        match self {
            Model::Stick => "stick",
            Model::StickApprox => "stick-approx",
            Model::Slip => "slip",
            Model::SlipApprox => "slip-approx",
            Model::StickSlip => "stickslip",
            Model::Jan(_) => "jan",
            Model::Jaeger(_) => "jaeger",
            Model::Contact(_) => "contact",
            Model::Md(_) => "md",
            Model::Auto(_) => "auto",
        }
    }

    fn evaluate(&self, scene: &Scene) -> Outcome {
        let out = match self {
            Model::Stick => stick::steady(scene),
            Model::StickApprox => stick::steady_approx(scene),
            Model::Slip => slip::steady(scene),
            Model::SlipApprox => slip::steady_approx(scene),
            Model::StickSlip => stickslip::steady(scene),
            Model::Jan(m) => m.evaluate(scene),
            Model::Jaeger(m) => m.evaluate(scene),
            Model::Contact(m) => m.evaluate(scene),
            Model::Md(m) => m.evaluate(scene),
            Model::Auto(m) => m.evaluate(scene),
        };
        // A steady state whose mean velocity is not a positive number is arithmetic that
        // left the range of doubles (ξ near 0 or 1e300, f past 1e150), not a physical result.
        match out {
            Ok(s) if !(s.mean_velocity > 0.0 && s.mean_velocity.is_finite()) => {
                Err(NotSteady::Invalid {
                    reason: "the mean velocity is not a positive finite number at these \
                             settings: they lie outside the range where the model's \
                             arithmetic holds in double precision",
                })
            }
            out => out,
        }
    }
}

/// The kind of model named on the command line (parameters of jan/jaeger supplied apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// See [`Model::Stick`].
    Stick,
    /// See [`Model::StickApprox`].
    StickApprox,
    /// See [`Model::Slip`].
    Slip,
    /// See [`Model::SlipApprox`].
    SlipApprox,
    /// See [`Model::StickSlip`].
    StickSlip,
    /// See [`Model::Jan`].
    Jan,
    /// See [`Model::Jaeger`].
    Jaeger,
    /// See [`Model::Contact`] (spin rule `roll` unless set apart).
    Contact,
    /// See [`Model::Md`].
    Md,
    /// See [`Model::Auto`] (target tolerance 1e-10 unless set apart).
    Auto,
}

impl ModelKind {
    /// The model for the five contact models and auto, which need no parameters beyond the
    /// scene; `None` for jan, jaeger and md.
    pub fn contact_model(self) -> Option<Model> {
        Some(match self {
            ModelKind::Stick => Model::Stick,
            ModelKind::StickApprox => Model::StickApprox,
            ModelKind::Slip => Model::Slip,
            ModelKind::SlipApprox => Model::SlipApprox,
            ModelKind::StickSlip => Model::StickSlip,
            ModelKind::Contact => Model::Contact(contact::Contact::default()),
            ModelKind::Jan | ModelKind::Jaeger => return None,
            ModelKind::Md => return None,
            ModelKind::Auto => Model::Auto(auto::Auto::default()),
        })
    }

    /// The model's name on the command line, one of [`Model::NAMES`] (`stickslip`,
    /// `stick-approx`).
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::StickSlip => "stickslip",
            ModelKind::Jan => "jan",
            ModelKind::Jaeger => "jaeger",
            k => k.prose_name(),
        }
    }

    /// The model's name in prose (titles and sentences): "stick/slip" for `stickslip`, the
    /// command-line name otherwise.
    pub fn prose_name(self) -> &'static str {
        match self {
            ModelKind::Stick => "stick",
            ModelKind::StickApprox => "stick-approx",
            ModelKind::Slip => "slip",
            ModelKind::SlipApprox => "slip-approx",
            ModelKind::StickSlip => "stick/slip",
            ModelKind::Jan => "Jan",
            ModelKind::Jaeger => "Jaeger",
            ModelKind::Contact => "contact",
            ModelKind::Md => "md",
            ModelKind::Auto => "auto",
        }
    }
}

impl FromStr for ModelKind {
    type Err = Error;
    /// A model by its whole name, in any case.
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "stick" => ModelKind::Stick,
            "stick-approx" => ModelKind::StickApprox,
            "slip" => ModelKind::Slip,
            "slip-approx" => ModelKind::SlipApprox,
            "stickslip" => ModelKind::StickSlip,
            "jan" => ModelKind::Jan,
            "jaeger" => ModelKind::Jaeger,
            "contact" => ModelKind::Contact,
            "md" => ModelKind::Md,
            "auto" => ModelKind::Auto,
            _ => return Err(Error::UnknownModel(s.to_string())),
        })
    }
}
