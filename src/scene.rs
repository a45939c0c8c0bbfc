//! A scene: the mobile bead on the row (ξ, δ, ρ, f) and the collision law K; derived geometry.

use crate::numfmt::{clip, ECHO_CHARS};
use crate::special::dd::Dd;
pub(crate) use crate::special::SinCos;
use std::f64::consts::FRAC_PI_2;
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// Why a scene or a model's parameters are refused: a value outside its domain, or a name
/// fitbead does not know.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParameterError {
    /// A scene or model parameter is outside its domain (or not finite).
    #[error("invalid {field} = {value}: {reason}")]
    InvalidParameter {
        /// Name of the field, as the user wrote it (`xi`, `delta_deg`, `K`, …).
        field: &'static str,
        /// The offending value, as text.
        value: String,
        /// What the domain is.
        reason: &'static str,
    },
    /// A collision law name that fitbead does not know (the text is cut for the message: the
    /// value at `ECHO_CHARS` characters, a short description around it allowed).
    #[error(
        "unknown collision law '{}' (expected a number, cos2a, adjusted, impact or c=VALUE)",
        clip(.0, ECHO_CHARS + 64)
    )]
    UnknownLaw(String),
    /// A spin rule of the contact model that fitbead does not know (the text is cut for the
    /// message at `ECHO_CHARS` characters).
    #[error(
        "unknown spin rule '{}' (expected roll, keep, impact or factor=L)",
        clip(.0, ECHO_CHARS)
    )]
    UnknownSpinRule(String),
    /// A model name that fitbead does not know.
    #[error("unknown model '{}'", clip(.0, ECHO_CHARS))]
    UnknownModel(String),
}

/// Result of the constructors and parsers that validate parameters.
pub(crate) type ParameterResult<T> = std::result::Result<T, ParameterError>;

type Result<T> = ParameterResult<T>;

/// The collisional parameter K (eq 1): a number, or a law K(α).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CollisionLaw {
    /// A fixed value of K.
    Value(f64),
    /// The smooth collision K = cos 2α (§3.4.2).
    Cos2a,
    /// The paper's fitted law K = cos 2α + ½ sin²α sin 2α (§3.6.1).
    Adjusted,
    /// No-slip impact conserving angular momentum about the new contact point:
    /// K = (cos 2α + ρ)/(1 + ρ) (docs/PHYSICS.md#collision-laws).
    Impact,
    /// K = cos 2α + c sin²α sin 2α with a free coefficient c (the form of §3.6.1).
    C(f64),
}

impl CollisionLaw {
    /// Evaluates K at the contact angle α (radians) and gyration parameter ρ.
    ///
    /// Each law evaluates only the functions of α it needs (a number needs none).
    pub fn k(&self, alpha: f64, rho: f64) -> f64 {
        let c2 = || (2.0 * alpha).cos();
        let s_s2 = || {
            let s = alpha.sin();
            (s, (2.0 * alpha).sin())
        };
        match *self {
            CollisionLaw::Value(k) => k,
            CollisionLaw::Cos2a => c2(),
            CollisionLaw::Adjusted => {
                let (s, s2) = s_s2();
                c2() + 0.5 * s * s * s2
            }
            CollisionLaw::Impact => (c2() + rho) / (1.0 + rho),
            CollisionLaw::C(c) => {
                let (s, s2) = s_s2();
                c2() + c * s * s * s2
            }
        }
    }

    /// 1 − K at the contact angle α (radians) and gyration parameter ρ, without the
    /// cancellation of 1 − K for K near 1 (large ξ): for the named laws it is formed from
    /// sin²α, since 1 − cos 2α = 2 sin²α. See [`Self::one_minus_k_sc`].
    pub fn one_minus_k(&self, alpha: f64, rho: f64) -> f64 {
        let (s, c) = alpha.sin_cos();
        self.one_minus_k_sc(s, c, rho)
    }

    /// 1 − K from sin α and cos α: 2 sin²α (cos2a), 2 sin²α (1 − c sin α cos α) (law c;
    /// `adjusted` is c = ½), 2 sin²α/(1 + ρ) (impact), 1 − K (a number). Each named form keeps
    /// the relative accuracy of sin α as α → 0, where 1 − K ≈ 2 sin²α and the difference
    /// 1 − K of a double K ≈ 1 would lose about u/(2 sin²α) (1e-11 at ξ = 1000).
    #[inline]
    pub fn one_minus_k_sc(&self, sin_alpha: f64, cos_alpha: f64, rho: f64) -> f64 {
        let s2x2 = 2.0 * sin_alpha * sin_alpha;
        match *self {
            CollisionLaw::Value(k) => 1.0 - k,
            CollisionLaw::Cos2a => s2x2,
            CollisionLaw::Adjusted => s2x2 * (1.0 - 0.5 * sin_alpha * cos_alpha),
            CollisionLaw::Impact => s2x2 / (1.0 + rho),
            CollisionLaw::C(c) => s2x2 * (1.0 - c * sin_alpha * cos_alpha),
        }
    }

    /// True when the law is a plain number.
    pub fn is_value(&self) -> bool {
        matches!(self, CollisionLaw::Value(_))
    }
}

impl FromStr for CollisionLaw {
    type Err = ParameterError;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        match t.to_ascii_lowercase().as_str() {
            "cos2a" => return Ok(CollisionLaw::Cos2a),
            "adjusted" => return Ok(CollisionLaw::Adjusted),
            "impact" => return Ok(CollisionLaw::Impact),
            _ => {}
        }
        let rest = t
            .get(..2)
            .filter(|p| p.eq_ignore_ascii_case("c="))
            .map(|_| &t[2..]);
        if let Some(rest) = rest {
            return match rest.trim().parse::<f64>() {
                Ok(c) if c.is_finite() => Ok(CollisionLaw::C(c)),
                _ => Err(ParameterError::UnknownLaw(t.to_string())),
            };
        }
        match t.parse::<f64>() {
            Ok(k) => Ok(CollisionLaw::Value(k)),
            Err(_) => Err(ParameterError::UnknownLaw(t.to_string())),
        }
    }
}

impl fmt::Display for CollisionLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CollisionLaw::Value(k) => write!(f, "{k}"),
            CollisionLaw::Cos2a => write!(f, "cos2a"),
            CollisionLaw::Adjusted => write!(f, "adjusted"),
            CollisionLaw::Impact => write!(f, "impact"),
            CollisionLaw::C(c) => write!(f, "c={c}"),
        }
    }
}

/// A validated scene with its derived geometry. Angles are in radians internally; every
/// velocity is dimensionless (units sqrt(g (R + r)), docs/PHYSICS.md#geometry-and-units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scene {
    /// Radius ratio ξ = r/R of the mobile bead to the row beads.
    pub(crate) xi: f64,
    /// Slope δ of the row (radians).
    pub(crate) delta: f64,
    /// Gyration parameter ρ (moment of inertia m ρ r²): 2/5 sphere, 1/2 cylinder.
    pub(crate) rho: f64,
    /// Coulomb friction coefficient f at the contact.
    pub(crate) f: f64,
    /// The collision law as given.
    pub(crate) law: CollisionLaw,
    /// The collisional parameter K evaluated from the law (eq 1).
    pub(crate) k: f64,
    /// α = asin(1/(1+ξ)) (eq 2).
    pub(crate) alpha: f64,
    /// sin α.
    pub(crate) sin_alpha: f64,
    /// cos α.
    pub(crate) cos_alpha: f64,
    /// ε = (1+ξ)/ξ (eq 4).
    pub(crate) eps: f64,
    /// Θ0 = δ − α: angle just after the collision.
    pub(crate) theta_0: f64,
    /// Θf = δ + α: angle at the next collision.
    pub(crate) theta_f: f64,
    /// sin, cos of δ.
    pub(crate) sc_delta: SinCos,
    /// sin, cos of δ/2.
    pub(crate) sc_half_delta: SinCos,
    /// sin, cos of α/2.
    pub(crate) sc_half_alpha: SinCos,
    /// sin, cos of Θ0/2.
    pub(crate) sc_half_0: SinCos,
    /// sin, cos of Θf/2.
    pub(crate) sc_half_f: SinCos,
    /// sin, cos of Θ0.
    pub(crate) sc_0: SinCos,
    /// sin, cos of Θf.
    pub(crate) sc_f: SinCos,
    /// tan(α/2) = 1/(1 + ξ + sqrt(ξ(2+ξ))) in double-double precision (for the δ_m cancellation).
    pub(crate) tan_half_alpha: Dd,
    /// B = 2/(1+ρ) (eq 9).
    pub(crate) b: f64,
    /// tan(δ/2) in double-double precision, where a caller that evaluates the scene at many K
    /// has computed it ([`Scene::with_tan_half_delta`]); the δ_m cancellation of the rolling
    /// models computes it otherwise.
    pub(crate) tan_half_delta: Derived<Dd>,
}

/// A value derived from the other fields of the struct that holds it, kept once computed.
/// It takes no part in comparisons: two structs equal in every other field are equal, kept
/// value or not.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Derived<T>(pub(crate) Option<T>);

impl<T> PartialEq for Derived<T> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

fn check(field: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<()> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(ParameterError::InvalidParameter {
            field,
            value: crate::numfmt::echo_f64(value),
            reason,
        })
    }
}

/// What a scene derives from ξ alone with transcendental functions.
struct OfXi {
    alpha: f64,
    cos_alpha: f64,
    sc_half_alpha: SinCos,
    tan_half_alpha: Dd,
}

impl OfXi {
    fn new(xi: f64) -> Self {
        let alpha = (1.0 / (1.0 + xi)).asin();
        // tan(α/2) = sin α / (1 + cos α) = 1 / (1 + ξ + sqrt(ξ (2 + ξ))).
        let one_xi = Dd::from(1.0) + Dd::from(xi);
        let root = (Dd::from(xi) * (Dd::from(2.0) + Dd::from(xi))).sqrt();
        OfXi {
            alpha,
            cos_alpha: alpha.cos(),
            sc_half_alpha: SinCos::of(0.5 * alpha),
            tan_half_alpha: Dd::from(1.0) / (one_xi + root),
        }
    }
}

/// A [`Scene`] built from named values whose names carry their units: ξ and the slope are
/// required; ρ defaults to 2/5 (a sphere), f to 0.1 and the collision law to the paper's
/// fitted one, K = cos 2α + ½ sin²α sin 2α (§3.6.1).
///
/// ```
/// use fitbead::{CollisionLaw, Scene};
/// let s = Scene::builder().xi(1.0).delta_deg(12.0).rho(0.4).friction(0.1)
///     .law(CollisionLaw::Adjusted).build()?;
/// assert_eq!(s, Scene::new(1.0, 12.0, 0.4, 0.1, CollisionLaw::Adjusted)?);
/// # Ok::<(), fitbead::scene::ParameterError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneBuilder {
    xi: Option<f64>,
    slope: Option<Slope>,
    rho: f64,
    f: f64,
    law: CollisionLaw,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Slope {
    Degrees(f64),
    Radians(f64),
}

impl SceneBuilder {
    /// Radius ratio ξ = r/R of the mobile bead to the row beads.
    pub fn xi(mut self, xi: f64) -> Self {
        self.xi = Some(xi);
        self
    }

    /// Slope δ of the row, in degrees.
    pub fn delta_deg(mut self, delta: f64) -> Self {
        self.slope = Some(Slope::Degrees(delta));
        self
    }

    /// Slope δ of the row, in radians.
    pub fn delta_rad(mut self, delta: f64) -> Self {
        self.slope = Some(Slope::Radians(delta));
        self
    }

    /// Gyration parameter ρ (2/5 for a sphere, 1/2 for a cylinder).
    pub fn rho(mut self, rho: f64) -> Self {
        self.rho = rho;
        self
    }

    /// Coulomb friction coefficient f between the beads.
    pub fn friction(mut self, f: f64) -> Self {
        self.f = f;
        self
    }

    /// The collision law: a number K or a law K(α).
    pub fn law(mut self, law: CollisionLaw) -> Self {
        self.law = law;
        self
    }

    /// The scene, validated as [`Scene::new`] validates it; ξ or the slope not given is an
    /// error naming it.
    pub fn build(self) -> Result<Scene> {
        let missing = |field| ParameterError::InvalidParameter {
            field,
            value: String::new(),
            reason: "not given",
        };
        let xi = self.xi.ok_or_else(|| missing("xi"))?;
        match self.slope.ok_or_else(|| missing("delta_deg"))? {
            Slope::Degrees(d) => Scene::new(xi, d, self.rho, self.f, self.law),
            Slope::Radians(d) => Scene::from_radians(xi, d, self.rho, self.f, self.law),
        }
    }
}

impl Scene {
    /// A [`SceneBuilder`]: named, unit-suffixed setters.
    pub fn builder() -> SceneBuilder {
        SceneBuilder {
            xi: None,
            slope: None,
            rho: 0.4,
            f: 0.1,
            law: CollisionLaw::Adjusted,
        }
    }

    /// The same scene at another slope δ, in degrees.
    pub fn with_delta_deg(&self, delta_deg: f64) -> Result<Self> {
        self.with_delta(delta_deg.to_radians())
    }
}

impl Scene {
    /// Builds a scene from δ in degrees (the unit of the command line and of the CSV files).
    pub fn new(xi: f64, delta_deg: f64, rho: f64, f: f64, law: CollisionLaw) -> Result<Self> {
        Self::new_like(None, xi, delta_deg, rho, f, law)
    }

    /// [`Scene::new`], taking what depends on ξ alone (α, its sine, cosine and half-angle,
    /// tan(α/2)) from `like` when `like` has the same ξ: the same scene to the last bit,
    /// without the inverse sine, the sines and cosines and the double-double square root of
    /// α. For rows of one series read one after the other.
    pub fn new_like(
        like: Option<&Scene>,
        xi: f64,
        delta_deg: f64,
        rho: f64,
        f: f64,
        law: CollisionLaw,
    ) -> Result<Self> {
        check(
            "delta_deg",
            delta_deg,
            (0.0..90.0).contains(&delta_deg),
            "slope must be in [0, 90) degrees",
        )?;
        let like = like.filter(|s| s.xi.to_bits() == xi.to_bits());
        Self::build(xi, delta_deg.to_radians(), rho, f, law, like)
    }

    /// Builds a scene from δ in radians. K must be in (0, 1): a number K ≥ 1 is refused (a
    /// collision cannot return more tangential velocity than it receives); a law's K is < 1
    /// at every ξ for the named laws.
    pub fn from_radians(xi: f64, delta: f64, rho: f64, f: f64, law: CollisionLaw) -> Result<Self> {
        Self::build(xi, delta, rho, f, law, None)
    }

    /// [`Scene::from_radians`], with the quantities of ξ alone taken from `same_xi` (a scene
    /// of the same ξ) when given.
    fn build(
        xi: f64,
        delta: f64,
        rho: f64,
        f: f64,
        law: CollisionLaw,
        same_xi: Option<&Scene>,
    ) -> Result<Self> {
        check("xi", xi, xi > 0.0, "radius ratio must be > 0")?;
        check(
            "delta",
            delta,
            (0.0..FRAC_PI_2).contains(&delta),
            "slope must be in [0, 90) degrees",
        )?;
        check("rho", rho, rho >= 0.0, "gyration parameter must be >= 0")?;
        check("f", f, f >= 0.0, "friction coefficient must be >= 0")?;
        if let CollisionLaw::C(c) = law {
            check("K", c, true, "law coefficient must be finite")?;
        }
        let of_xi = match same_xi {
            Some(s) => OfXi {
                alpha: s.alpha,
                cos_alpha: s.cos_alpha,
                sc_half_alpha: s.sc_half_alpha,
                tan_half_alpha: s.tan_half_alpha,
            },
            None => OfXi::new(xi),
        };
        let alpha = of_xi.alpha;
        let k = law_k(law, alpha, rho, xi)?;
        let theta_0 = delta - alpha;
        let theta_f = delta + alpha;
        let sc_half_delta = SinCos::of(0.5 * delta);
        let sc_half_alpha = of_xi.sc_half_alpha;
        // Half angles of Θ0 and Θf by the addition formulas: no rounding of δ − α enters.
        let (sd, cd, sa, ca) = (
            sc_half_delta.s,
            sc_half_delta.c,
            sc_half_alpha.s,
            sc_half_alpha.c,
        );
        let sc_half_0 = SinCos {
            s: sd.mul_add(ca, -cd * sa),
            c: cd.mul_add(ca, sd * sa),
        };
        let sc_half_f = SinCos {
            s: sd.mul_add(ca, cd * sa),
            c: cd.mul_add(ca, -sd * sa),
        };
        let sc_0 = SinCos {
            s: 2.0 * sc_half_0.s * sc_half_0.c,
            c: 1.0 - 2.0 * sc_half_0.s * sc_half_0.s,
        };
        let sc_f = SinCos {
            s: 2.0 * sc_half_f.s * sc_half_f.c,
            c: 1.0 - 2.0 * sc_half_f.s * sc_half_f.s,
        };
        Ok(Scene {
            xi,
            delta,
            rho,
            f,
            law,
            k,
            alpha,
            sin_alpha: 1.0 / (1.0 + xi),
            cos_alpha: of_xi.cos_alpha,
            eps: (1.0 + xi) / xi,
            theta_0,
            theta_f,
            sc_delta: SinCos::of(delta),
            sc_half_delta,
            sc_half_alpha,
            sc_half_0,
            sc_half_f,
            sc_0,
            sc_f,
            tan_half_alpha: of_xi.tan_half_alpha,
            b: 2.0 / (1.0 + rho),
            tan_half_delta: Derived(None),
        })
    }

    /// The same scene with tan(δ/2) in double-double precision kept, for callers that
    /// evaluate it at many K (the K searches): the rolling models need it near δ_m, where the
    /// factor of the top speed cancels ([`crate::models::stick`]). The same bits as computed
    /// there.
    pub(crate) fn with_tan_half_delta(&self) -> Self {
        let mut s = *self;
        s.tan_half_delta = Derived(Some(Dd::tan_half(self.delta)));
        s
    }

    /// The same scene with another collisional parameter K (a number).
    pub fn with_k(&self, k: f64) -> Result<Self> {
        check("K", k, k > 0.0, "collisional parameter must be > 0")?;
        let mut s = *self;
        s.k = k;
        s.law = CollisionLaw::Value(k);
        Ok(s)
    }

    /// The same scene at another slope δ (radians).
    pub fn with_delta(&self, delta: f64) -> Result<Self> {
        Self::build(self.xi, delta, self.rho, self.f, self.law, Some(self))
    }

    /// Radius ratio ξ = r/R of the mobile bead to the row beads.
    #[inline]
    pub fn xi(&self) -> f64 {
        self.xi
    }

    /// Slope δ of the row in degrees.
    pub fn delta_deg(&self) -> f64 {
        self.delta.to_degrees()
    }

    /// Slope δ of the row in radians.
    #[inline]
    pub fn delta_rad(&self) -> f64 {
        self.delta
    }

    /// Gyration parameter ρ (moment of inertia m ρ r²): 2/5 sphere, 1/2 cylinder.
    #[inline]
    pub fn rho(&self) -> f64 {
        self.rho
    }

    /// Coulomb friction coefficient f at the contact.
    #[inline]
    pub fn f(&self) -> f64 {
        self.f
    }

    /// The collision law as given.
    #[inline]
    pub fn law(&self) -> CollisionLaw {
        self.law
    }

    /// The collisional parameter K evaluated from the law (eq 1), dimensionless.
    #[inline]
    pub fn k(&self) -> f64 {
        self.k
    }

    /// Contact angle α = asin(1/(1+ξ)) (eq 2) in radians.
    #[inline]
    pub fn alpha_rad(&self) -> f64 {
        self.alpha
    }

    /// Contact angle α in degrees.
    pub fn alpha_deg(&self) -> f64 {
        self.alpha.to_degrees()
    }

    /// sin α = 1/(1+ξ).
    #[inline]
    pub fn sin_alpha(&self) -> f64 {
        self.sin_alpha
    }

    /// cos α.
    #[inline]
    pub fn cos_alpha(&self) -> f64 {
        self.cos_alpha
    }

    /// ε = (1+ξ)/ξ (eq 4).
    #[inline]
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// Θ0 = δ − α, the angle just after a collision, in radians.
    #[inline]
    pub fn theta_0_rad(&self) -> f64 {
        self.theta_0
    }

    /// Θf = δ + α, the angle at the next collision, in radians.
    #[inline]
    pub fn theta_f_rad(&self) -> f64 {
        self.theta_f
    }

    /// B = 2/(1+ρ) (eq 9).
    #[inline]
    pub fn b(&self) -> f64 {
        self.b
    }

    /// 1 − K² computed as (1 − K)(1 + K), with 1 − K from [`Self::one_minus_k`]: without
    /// cancellation near K = 1, for a number K and for a named law at large ξ.
    #[inline]
    pub fn one_minus_k2(&self) -> f64 {
        self.one_minus_k() * (1.0 + self.k)
    }

    /// 1 − K: for a named law from sin²α ([`CollisionLaw::one_minus_k_sc`]), which keeps its
    /// relative accuracy as K → 1 (ξ → ∞); for a number, 1 − K of the double K.
    #[inline]
    pub fn one_minus_k(&self) -> f64 {
        match self.law {
            CollisionLaw::Value(_) => 1.0 - self.k,
            law => law.one_minus_k_sc(self.sin_alpha, self.cos_alpha, self.rho),
        }
    }

    /// sin δ sin α = sin²(Θf/2) − sin²(Θ0/2), the denominator of the Carlson form.
    #[inline]
    pub fn sin_delta_sin_alpha(&self) -> f64 {
        self.sc_delta.s * self.sin_alpha
    }
}
/// K of `law` at contact angle `alpha` (and ρ), checked: a law's K must lie in (0, 1) at
/// this ξ, a value given as a number too (eq 1 bounds K by 1).
#[inline]
fn law_k(law: CollisionLaw, alpha: f64, rho: f64, xi: f64) -> Result<f64> {
    let k = law.k(alpha, rho);
    if !law.is_value() && !(k > 0.0) {
        // The law, not a number the user gave, is at fault: its K vanishes at this ξ.
        return Err(ParameterError::InvalidParameter {
            field: "xi",
            value: crate::numfmt::echo_f64(xi),
            reason: "the collision law gives no K > 0 at this xi (its contact angle alpha \
                     is too close to 90 degrees): use a larger xi, or give K as a number",
        });
    }
    check("K", k, k > 0.0, "collisional parameter must be > 0")?;
    if !law.is_value() && !(k < 1.0) {
        // A law such as c = 10 can exceed 1 at small ξ (eq 1 bounds K by 1).
        return Err(ParameterError::InvalidParameter {
            field: "K",
            value: format!(
                "{} (law {} at xi = {})",
                crate::numfmt::echo_f64(k),
                match law {
                    CollisionLaw::C(c) => format!("c={}", crate::numfmt::echo_f64(c)),
                    _ => law.to_string(),
                },
                crate::numfmt::echo_f64(xi)
            ),
            reason: "the collision law gives K >= 1 here (a collision cannot return more \
                     velocity than it receives): choose a law or coefficient with K < 1 \
                     at this xi",
        });
    }
    if law.is_value() {
        // A collision returns at most the tangential velocity it receives (eq 1).
        check(
            "K",
            k,
            k < 1.0,
            "collisional parameter must be < 1 (a collision cannot return more velocity \
             than it receives)",
        )?;
    }
    Ok(k)
}
