//! `--model auto` for the inverse problems: which model to invert eq 69 with, per
//! measured point.
//!
//! The choice needs a K, which is what is being sought: the point's K is first found under
//! the stick model (eq 69, exact rolling), and [`Auto::choose`] decides at that K whether
//! rolling holds over the steady contact (Θ_G ≥ Θf, eq 36), the paper's roll-then-slip
//! sequence holds (Θ0 ≥ −Θ_G) or only the general contact model describes the contact. The
//! point is then inverted with the chosen model. Where no K makes the point steady under
//! stick, the general model is used.

use super::estimate::estimate;
use crate::models::auto::{Auto, Choice};
use crate::models::contact::{Contact, SpinRule};
use crate::models::Model;
use crate::scene::Scene;

/// The model auto uses to invert one point, and why.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct KChoice {
    /// The model to invert eq 69 with.
    pub model: Model,
    /// Which model that is.
    pub choice: Choice,
    /// Why (says that the choice was made at the stick K).
    pub reason: String,
}

/// The K estimate of one measurement (eq 69) under `model`, or under the model `auto`
/// chooses for it (`choose`) when `auto` is given, with that choice.
pub(crate) fn estimate_with(
    model: &Model,
    auto: Option<&Auto>,
    scene: &Scene,
    v: f64,
    sigma_v: Option<f64>,
) -> (super::KEstimate, Option<KChoice>) {
    match auto {
        Some(au) => {
            let c = choose(au, scene, v);
            (estimate(&c.model, scene, v, sigma_v), Some(c))
        }
        None => (estimate(model, scene, v, sigma_v), None),
    }
}

/// Chooses the model for inverting one point (ξ, δ, ρ, f of `scene`, measured `v`).
pub(crate) fn choose(auto: &Auto, scene: &Scene, v: f64) -> KChoice {
    let model_of = |c: Choice| match c {
        Choice::Stick => Model::Stick,
        Choice::StickSlip => Model::StickSlip,
        Choice::Contact => Model::Contact(Contact {
            spin: SpinRule::Roll,
            tol: auto.inner_tol(),
        }),
    };
    let stick = estimate(&Model::Stick, scene, v, None);
    let at = match &stick.root {
        Ok(r) => scene.with_k(r.k).ok().map(|s| (r.k, s)),
        Err(_) => None,
    };
    match at {
        Some((k, s)) => {
            let c = auto.choose(&s);
            KChoice {
                model: model_of(c.choice),
                choice: c.choice,
                reason: format!("at the stick K = {k:.6}: {}", c.reason),
            }
        }
        None => KChoice {
            model: model_of(Choice::Contact),
            choice: Choice::Contact,
            reason: match stick.root {
                Err(e) => format!("no K under stick ({}): general contact model", e.status()),
                Ok(_) => "stick K out of range: general contact model".into(),
            },
        },
    }
}

/// The most general model any of the points needs (contact over stickslip over stick), with
/// the count of points per model: auto for fits that need one model for all points.
pub(crate) fn most_general(choices: &[KChoice]) -> (Choice, [usize; 3]) {
    let mut n = [0usize; 3];
    for c in choices {
        n[match c.choice {
            Choice::Stick => 0,
            Choice::StickSlip => 1,
            Choice::Contact => 2,
        }] += 1;
    }
    let c = if n[2] > 0 {
        Choice::Contact
    } else if n[1] > 0 {
        Choice::StickSlip
    } else {
        Choice::Stick
    };
    (c, n)
}
