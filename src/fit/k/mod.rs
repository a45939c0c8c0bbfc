//! The collisional parameter K of one measurement (eq 69): find K with v̄_th(K; α, δ, ρ, f) =
//! v̄_exp for the rolling, slip and stick/slip models.
//!
//! The search runs on a bracket of K that is derived, not guessed (`bracket`). Every contact
//! model maps the speed Θ̇0 just after a collision to the speed Θ̇f at the next one by a
//! function Φ that does not involve K; K enters only through Θ̇0 = K Θ̇f. Hence:
//! - the lowest K is K_min = w_c / Φ(w_c), where w_c is the smallest launch speed that still
//!   carries the bead to Θf (over the top for rolling: w_c² = 2B sin²(Θ0/2), which gives
//!   K_min = −sin(Θ0/2)/sin(Θf/2), the inverse of eq 32; for slip the minimum of Θ̇² e^{−2fθ}
//!   sits at tan θ = f); there the bead crawls over the top and v̄ → 0;
//! - the highest K is where the steady final speed reaches lift-off, Φ(w_d) = sqrt(cos Θf)
//!   (eq 30a), K_d = w_d / sqrt(cos Θf) — below the runaway limits K < 1 (rolling) and
//!   K² e^{4fα} < 1 (slip), which lift-off always reaches first when δ > 0.
//!
//! Each end is then checked against the forward model itself; where the model fails inside the
//! analytic bracket (the approximate models' own validity limits, the stick/slip map's
//! saddle-node beyond K e^{2fα} ≈ 1), the end is moved to the model's true boundary by bisection
//! on its status.
//!
//! The root is found by Brent's method in s = ln(K − K_min) on g(s) = τ* − τ(K), τ the contact
//! time (v̄ = 2 sin α / τ, eq 10). Near K_min the time grows like −ln(K − K_min) (the bead
//! crawls over the top, v̄ has an infinite slope in K), so in s the function is close to a
//! straight line and the solver converges superlinearly at either end instead of stalling.
//!
//! Layout: [`types`] holds what every path shares; `bracket` derives the bracket of K;
//! `search` solves eq 69 in K; [`launch`] solves it in the launch speed where that applies;
//! [`estimate`](mod@estimate) picks the path; [`auto`] picks the model per point; `slope` carries a slope's
//! uncertainty into K's.

pub mod auto;
pub(crate) mod bracket;
pub mod estimate;
pub mod launch;
pub(crate) mod search;
pub(crate) mod slope;
pub mod types;

pub(crate) use bracket::bracket;
pub(crate) use bracket::unsteady_points;
pub use estimate::estimate;
pub(crate) use search::dv_dk;
pub(crate) use search::solve;
pub use types::{KBracket, KEstimate, KFailure, KRoot, LowerLimit, UpperLimit};

#[cfg(any(test, feature = "bench-internals"))]
thread_local! {
    /// Contact times computed by the K inversion on this thread ([`count_contacts`]).
    static CONTACTS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Adds `n` to this thread's count of contact times computed by the K inversion (one per
/// forward evaluation that integrates a contact: [`launch`]'s passes, the general search's
/// evaluations), read by [`contacts_counted`]. Compiled only for the tests and the
/// `bench-internals` feature; elsewhere it is nothing.
#[inline(always)]
pub(crate) fn count_contacts(n: u64) {
    #[cfg(any(test, feature = "bench-internals"))]
    CONTACTS.with(|c| c.set(c.get() + n));
    #[cfg(not(any(test, feature = "bench-internals")))]
    let _ = n;
}

/// The contact times computed by the K inversion on this thread so far ([`count_contacts`]).
#[cfg(any(test, feature = "bench-internals"))]
pub fn contacts_counted() -> u64 {
    CONTACTS.with(std::cell::Cell::get)
}
