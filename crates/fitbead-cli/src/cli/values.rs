//! The values of the flags, parsed by clap: every flag whose value is one of fixed names is a
//! [`Choice`] read by [`choice`] (whole names, any case, surrounding spaces ignored),
//! and every number with a range of its own, list or text with a grammar has a value parser
//! here that refuses a bad value before any work. A refusal is a [`Refusal`]; `super::parse`
//! renders it in the project's form (`<command line>, flag '--NAME', value 'V': message`).

use clap::builder::{PossibleValue, TypedValueParser};
use clap::ValueEnum;
use fitbead::design::{Criterion, DesignFit};
use fitbead::fit::klaw::KLaw;
use fitbead::inverse::posterior::Prior;
use fitbead::models::contact::SpinRule;
use fitbead::models::md::ReducedMass;
use fitbead::models::{JaegerBranch, Model, ModelKind};
use fitbead::pipeline::ReportSettings;
use fitbead::scene::CollisionLaw;
use std::marker::PhantomData;

/// Why a flag's value is refused: the message, and the part of the value it is about when
/// that is not the whole value (one number of a list), shown as the value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Refusal {
    /// The part of the value refused; `None`: the whole value.
    pub part: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl Refusal {
    /// A refusal of the whole value.
    pub fn new(message: impl Into<String>) -> Self {
        Refusal {
            part: None,
            message: message.into(),
        }
    }

    /// A refusal of `part` of the value.
    fn of(part: &str, message: impl Into<String>) -> Self {
        Refusal {
            part: Some(part.to_string()),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Refusal {}

/// A flag's fixed names, in the order of the help, with the message for a name that is none of
/// them. The command line's own enums derive [`ValueEnum`] and take their names from it
/// ([`choice_of_value_enum`]); the library's enums are named here.
pub(crate) trait Choice: Clone + Send + Sync + 'static {
    /// Every value, in the order the help lists them.
    fn variants() -> &'static [Self];

    /// The value's name on the command line.
    fn possible(&self) -> PossibleValue;

    /// The message for `name`, which is none of the names.
    fn unknown(name: &str) -> String;
}

/// [`Choice::variants`] and [`Choice::possible`] of an enum that derives [`ValueEnum`].
macro_rules! choice_of_value_enum {
    () => {
        fn variants() -> &'static [Self] {
            <Self as clap::ValueEnum>::value_variants()
        }

        fn possible(&self) -> clap::builder::PossibleValue {
            clap::ValueEnum::to_possible_value(self).expect("every value is named")
        }
    };
}

/// The value parser of a [`Choice`]: a whole name in any case, spaces around it ignored; the
/// names are the flag's possible values in its help.
pub(crate) struct ChoiceParser<E>(PhantomData<fn() -> E>);

impl<E> Clone for ChoiceParser<E> {
    fn clone(&self) -> Self {
        ChoiceParser(PhantomData)
    }
}

/// The value of `E` named `s`: a whole name in any case, spaces around it ignored.
pub(crate) fn named<E: Choice>(s: &str) -> Option<E> {
    E::variants()
        .iter()
        .find(|v| v.possible().matches(s.trim(), true))
        .cloned()
}

/// The value parser of the choice `E`.
pub(crate) fn choice<E: Choice>() -> ChoiceParser<E> {
    ChoiceParser(PhantomData)
}

impl<E: Choice> TypedValueParser for ChoiceParser<E> {
    type Value = E;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<E, clap::Error> {
        let parse = |s: &str| named::<E>(s).ok_or_else(|| Refusal::new(E::unknown(s)));
        parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(E::variants().iter().map(Choice::possible)))
    }
}

/// The names of `E`, joined by `, `.
fn names<E: Choice>() -> String {
    E::variants()
        .iter()
        .map(|p| p.possible().get_name().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The command-line name of `value`.
pub(crate) fn name_of<E: Choice>(value: &E) -> String {
    value.possible().get_name().to_string()
}

impl Choice for ModelKind {
    fn variants() -> &'static [Self] {
        // The order of `Model::NAMES`.
        &[
            ModelKind::Stick,
            ModelKind::StickApprox,
            ModelKind::Slip,
            ModelKind::SlipApprox,
            ModelKind::StickSlip,
            ModelKind::Jan,
            ModelKind::Jaeger,
            ModelKind::Contact,
            ModelKind::Md,
            ModelKind::Auto,
        ]
    }

    fn possible(&self) -> PossibleValue {
        let i = Self::variants().iter().position(|k| k == self);
        PossibleValue::new(Model::NAMES[i.expect("every model is listed")])
    }

    fn unknown(_: &str) -> String {
        format!("unknown model; expected one of {}", Model::NAMES.join(", "))
    }
}

/// The models that `k` and `klaw` invert for K: the five contact models, and auto (chosen per
/// point among them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum KModel {
    // Pure rolling.
    Stick,
    // Pure rolling, approximated.
    StickApprox,
    // Slip.
    Slip,
    // Slip, approximated.
    SlipApprox,
    // Roll then slip.
    #[value(name = "stickslip")]
    StickSlip,
    // The general contact model.
    Contact,
    // Chosen per point.
    Auto,
}

impl KModel {
    /// The model kind.
    pub fn kind(self) -> ModelKind {
        match self {
            KModel::Stick => ModelKind::Stick,
            KModel::StickApprox => ModelKind::StickApprox,
            KModel::Slip => ModelKind::Slip,
            KModel::SlipApprox => ModelKind::SlipApprox,
            KModel::StickSlip => ModelKind::StickSlip,
            KModel::Contact => ModelKind::Contact,
            KModel::Auto => ModelKind::Auto,
        }
    }
}

impl Choice for KModel {
    choice_of_value_enum!();

    fn unknown(name: &str) -> String {
        match name.parse::<ModelKind>() {
            Ok(ModelKind::Md) => {
                "model md has no K inversion (its collisions come from the contact forces)".into()
            }
            _ => format!("expected one of {}", names::<KModel>()),
        }
    }
}

impl Choice for JaegerBranch {
    fn variants() -> &'static [Self] {
        &[JaegerBranch::Upper, JaegerBranch::Lower]
    }

    fn possible(&self) -> PossibleValue {
        PossibleValue::new(match self {
            JaegerBranch::Upper => "upper",
            JaegerBranch::Lower => "lower",
        })
    }

    fn unknown(_: &str) -> String {
        "expected upper or lower".into()
    }
}

impl Choice for KLaw {
    fn variants() -> &'static [Self] {
        &[KLaw::C, KLaw::Impact, KLaw::FreePerSeries]
    }

    fn possible(&self) -> PossibleValue {
        PossibleValue::new(self.name())
    }

    fn unknown(name: &str) -> String {
        name.parse::<KLaw>().err().unwrap_or_default()
    }
}

impl Choice for DesignFit {
    fn variants() -> &'static [Self] {
        &[DesignFit::KLaw, DesignFit::Jan, DesignFit::Jaeger]
    }

    fn possible(&self) -> PossibleValue {
        PossibleValue::new(match self {
            DesignFit::KLaw => "klaw",
            DesignFit::Jan => "jan",
            DesignFit::Jaeger => "jaeger",
        })
    }

    fn unknown(name: &str) -> String {
        name.parse::<DesignFit>().err().unwrap_or_default()
    }
}

impl Choice for Criterion {
    fn variants() -> &'static [Self] {
        &[Criterion::D, Criterion::C, Criterion::T]
    }

    fn possible(&self) -> PossibleValue {
        PossibleValue::new(match self {
            Criterion::D => "d",
            Criterion::C => "c",
            Criterion::T => "t",
        })
    }

    fn unknown(name: &str) -> String {
        name.parse::<Criterion>().err().unwrap_or_default()
    }
}

/// A figure format of `report --format`, one of [`ReportSettings::FORMATS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FigureFormat(pub &'static str);

impl Default for FigureFormat {
    /// SVG.
    fn default() -> Self {
        FigureFormat(ReportSettings::FORMATS[0])
    }
}

impl Choice for FigureFormat {
    fn variants() -> &'static [Self] {
        static ALL: std::sync::OnceLock<Vec<FigureFormat>> = std::sync::OnceLock::new();
        ALL.get_or_init(|| {
            ReportSettings::FORMATS
                .iter()
                .map(|f| FigureFormat(f))
                .collect()
        })
    }

    fn possible(&self) -> PossibleValue {
        PossibleValue::new(self.0)
    }

    fn unknown(name: &str) -> String {
        ReportSettings::check_format(name)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    }
}

impl Choice for ReducedMass {
    fn variants() -> &'static [Self] {
        &[ReducedMass::Pair, ReducedMass::Mobile]
    }

    fn possible(&self) -> PossibleValue {
        PossibleValue::new(match self {
            ReducedMass::Pair => "pair",
            ReducedMass::Mobile => "mobile",
        })
    }

    fn unknown(_: &str) -> String {
        "expected pair or mobile".into()
    }
}

/// The estimation method of the fit commands (`--method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum FitMethod {
    // Least squares.
    #[default]
    Lsq,
    // Posterior sampling.
    Mcmc,
}

impl Choice for FitMethod {
    choice_of_value_enum!();

    fn unknown(_: &str) -> String {
        "expected lsq or mcmc".into()
    }
}

/// The unit of the velocities on the report's figures (`--units`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum Units {
    // Units of sqrt(g (R + r)).
    #[default]
    Dimensionless,
    // m/s.
    Si,
}

impl Choice for Units {
    choice_of_value_enum!();

    fn unknown(_: &str) -> String {
        "expected dimensionless or si".into()
    }
}

/// The md parameter set (`--md-preset`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum MdPreset {
    // Ristow's set.
    #[default]
    Ristow,
    // Steel.
    Steel,
}

impl Choice for MdPreset {
    choice_of_value_enum!();

    fn unknown(_: &str) -> String {
        "expected ristow or steel".into()
    }
}

/// `s` as a number, or a refusal saying `message`.
fn number(s: &str, ok: impl Fn(f64) -> bool, message: &str) -> Result<f64, Refusal> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| ok(*x))
        .ok_or_else(|| Refusal::new(message))
}

/// `s` as a whole number, or a refusal saying `message`.
fn count(s: &str, ok: impl Fn(usize) -> bool, message: &str) -> Result<usize, Refusal> {
    s.trim()
        .parse::<usize>()
        .ok()
        .filter(|n| ok(*n))
        .ok_or_else(|| Refusal::new(message))
}

/// A finite number.
pub(crate) fn finite(s: &str) -> Result<f64, Refusal> {
    number(s, f64::is_finite, "not a finite number")
}

/// A finite number ≥ 0 (ρ, f, the minimum ESS).
pub(crate) fn non_negative(s: &str) -> Result<f64, Refusal> {
    number(
        s,
        |x| x.is_finite() && x >= 0.0,
        "must be a finite number >= 0",
    )
}

/// The standard uncertainty of a simulated slope, degrees: finite, ≥ 0 and < 90.
pub(crate) fn slope_sigma(s: &str) -> Result<f64, Refusal> {
    number(
        s,
        |x| x.is_finite() && (0.0..90.0).contains(&x),
        "must be a finite number of degrees >= 0 and < 90",
    )
}

/// The fraction of a design's range kept from each end: finite, ≥ 0 and < 0.5.
pub(crate) fn margin(s: &str) -> Result<f64, Refusal> {
    number(
        s,
        |x| x.is_finite() && (0.0..0.5).contains(&x),
        "expected a fraction of the range's width with 0 <= F < 0.5",
    )
}

/// Gravity g > 0, m/s².
pub(crate) fn gravity(s: &str) -> Result<f64, Refusal> {
    number(s, |x| x.is_finite() && x > 0.0, "g must be > 0")
}

/// The level of the intervals, in (0, 1).
pub(crate) fn level(s: &str) -> Result<f64, Refusal> {
    number(s, |x| x > 0.0 && x < 1.0, "must be in (0, 1), e.g. 0.95")
}

/// A relative tolerance, in (0, 1).
pub(crate) fn tolerance(s: &str) -> Result<f64, Refusal> {
    number(
        s,
        |x| x > 0.0 && x < 1.0,
        "expected a relative tolerance in (0, 1)",
    )
}

/// A radius ratio ξ > 0.
pub(crate) fn radius_ratio(s: &str) -> Result<f64, Refusal> {
    number(s, |x| x.is_finite() && x > 0.0, "radius ratio must be > 0")
}

/// The relative noise of simulated data, in [0, 0.5).
pub(crate) fn noise(s: &str) -> Result<f64, Refusal> {
    number(
        s,
        |x| x.is_finite() && (0.0..0.5).contains(&x),
        "must be in [0, 0.5)",
    )
}

/// The launch speed of a transient, finite and ≥ 0.
pub(crate) fn launch_speed(s: &str) -> Result<f64, Refusal> {
    number(
        s,
        |x| x.is_finite() && x >= 0.0,
        "expected a finite launch speed >= 0",
    )
}

/// A count ≥ 1 (MCMC steps, thinning).
pub(crate) fn at_least_one(s: &str) -> Result<usize, Refusal> {
    count(s, |n| n >= 1, "must be >= 1")
}

/// The MCMC walkers: even, at least 4 and at most the sampler's limit (that there are more
/// walkers than parameters is checked with the fit).
pub(crate) fn walkers(s: &str) -> Result<usize, Refusal> {
    const MAX_WALKERS: usize = fitbead::inverse::mcmc::McmcOptions::MAX_WALKERS;
    count(
        s,
        |w| w >= 4 && w % 2 == 0 && w <= MAX_WALKERS,
        &format!(
            "must be even, at least 4 (and more than the parameters) and at most {MAX_WALKERS}"
        ),
    )
}

/// The points per series of a simulation.
pub(crate) fn points(s: &str) -> Result<usize, Refusal> {
    const MAX_POINTS: usize = fitbead::pipeline::SimulateSettings::MAX_POINTS;
    count(
        s,
        |n| (1..=MAX_POINTS).contains(&n),
        &format!("expected 1 to {MAX_POINTS} points per series"),
    )
}

/// The scenes of the work-precision report.
pub(crate) fn scenes(s: &str) -> Result<usize, Refusal> {
    count(
        s,
        |n| (1..=1_000_000).contains(&n),
        "expected a number of scenes in 1..=1000000",
    )
}

/// A comma-separated list of finite numbers; a bad one is refused by itself.
pub(crate) fn numbers(s: &str) -> Result<Vec<f64>, Refusal> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| Refusal::of(t, "not a finite number"))
        })
        .collect()
}

/// A list of numbers given as one value (`1,2,3`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Numbers(pub Vec<f64>);

/// A comma-separated list of finite numbers, as one value ([`numbers`]).
pub(crate) fn number_list(s: &str) -> Result<Numbers, Refusal> {
    numbers(s).map(Numbers)
}

/// The radius ratios of a simulation's series: a list of numbers, each once (the rows of a
/// series are labelled by its ξ).
pub(crate) fn series(s: &str) -> Result<Numbers, Refusal> {
    let xs = numbers(s)?;
    for (j, x) in xs.iter().enumerate() {
        if let Some(i) = xs[..j].iter().position(|y| y == x) {
            let text = s.split(',').nth(j).unwrap_or_default().trim();
            return Err(Refusal::of(
                text,
                format!(
                    "xi {} is given twice (values {} and {}): each series needs its own xi",
                    fitbead::numfmt::fmt_f64(*x),
                    i + 1,
                    j + 1
                ),
            ));
        }
    }
    Ok(Numbers(xs))
}

/// Jan's global laws λ0,λ1,μ0,μ1.
pub(crate) fn jan_laws(s: &str) -> Result<[f64; 4], Refusal> {
    <[f64; 4]>::try_from(numbers(s)?)
        .map_err(|_| Refusal::new("expected four numbers lambda0,lambda1,mu0,mu1"))
}

/// Jaeger's a1,a2,a3.
pub(crate) fn jaeger_values(s: &str) -> Result<[f64; 3], Refusal> {
    <[f64; 3]>::try_from(numbers(s)?).map_err(|_| Refusal::new("expected three numbers a1,a2,a3"))
}

/// A range of slopes `LO,HI` in degrees, with its text as given.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SlopeRange {
    /// Lower end, degrees.
    pub lo: f64,
    /// Upper end, degrees.
    pub hi: f64,
    /// The flag's text.
    pub text: String,
}

/// `LO,HI` in degrees with LO < HI.
pub(crate) fn slope_range(s: &str) -> Result<SlopeRange, Refusal> {
    match numbers(s)?[..] {
        [lo, hi] if lo < hi => Ok(SlopeRange {
            lo,
            hi,
            text: s.to_string(),
        }),
        _ => Err(Refusal::new("expected LO,HI in degrees with LO < HI")),
    }
}

/// The noise of a design: a relative noise, or `abs=SIGMA` (absolute); the value and whether
/// it is absolute.
pub(crate) fn design_noise(s: &str) -> Result<(f64, bool), Refusal> {
    let (text, absolute) = match s.trim().strip_prefix("abs=") {
        Some(v) => (v, true),
        None => (s, false),
    };
    match numbers(text)?[..] {
        [x] => Ok((x, absolute)),
        _ => Err(Refusal::new("expected one number (relative) or abs=SIGMA")),
    }
}

/// A collision law: a number, cos2a, adjusted, impact or c=VALUE.
pub(crate) fn law(s: &str) -> Result<CollisionLaw, Refusal> {
    s.parse()
        .map_err(|e: fitbead::scene::ParameterError| Refusal::new(e.to_string()))
}

/// A collision law with its text as given.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LawText {
    /// The law.
    pub law: CollisionLaw,
    /// The flag's text.
    pub text: String,
}

/// A collision law ([`law`]) with its text.
pub(crate) fn law_with_text(s: &str) -> Result<LawText, Refusal> {
    law(s).map(|law| LawText {
        law,
        text: s.to_string(),
    })
}

/// A collision law, kept as its text (checked as [`law`]).
pub(crate) fn law_text(s: &str) -> Result<String, Refusal> {
    law(s).map(|_| s.to_string())
}

/// A spin rule: roll, keep, factor=L or impact.
pub(crate) fn spin(s: &str) -> Result<SpinRule, Refusal> {
    s.parse()
        .map_err(|e: fitbead::scene::ParameterError| Refusal::new(e.to_string()))
}

/// A spin rule, kept as its text (checked as [`spin`]).
pub(crate) fn spin_text(s: &str) -> Result<String, Refusal> {
    spin(s).map(|_| s.to_string())
}

/// A figure width (single, double or a width in mm), kept as its text.
pub(crate) fn figure_width(s: &str) -> Result<String, Refusal> {
    ReportSettings::check_figure_width(s)
        .map(|()| s.to_string())
        .map_err(|e| Refusal::new(e.to_string()))
}

/// A prior of a parameter named on the command line, with the flag's text.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NamedPrior {
    /// The parameter's name.
    pub name: String,
    /// The prior.
    pub prior: Prior,
    /// The flag's text.
    pub text: String,
}

/// `NAME=DIST` split at `at` (the position of the `=`).
fn named_prior(s: &str, at: Option<usize>, example: &str) -> Result<NamedPrior, Refusal> {
    let at = at.ok_or_else(|| Refusal::new(format!("expected NAME=DIST, e.g. {example}")))?;
    let prior: Prior = s[at + 1..].parse().map_err(Refusal::new)?;
    Ok(NamedPrior {
        name: s[..at].trim().to_string(),
        prior,
        text: s.to_string(),
    })
}

/// A prior of a fit's parameter, `NAME=DIST` (the name before the first `=`); the name is
/// checked against the fit's parameters by the command.
pub(crate) fn fit_prior(s: &str) -> Result<NamedPrior, Refusal> {
    named_prior(s, s.find('='), "c=normal(0.5,0.5)")
}

/// A prior of a design's parameter, `NAME=DIST`: the name may hold `=` (K of series 'xi=1'),
/// the distribution never does.
pub(crate) fn design_prior(s: &str) -> Result<NamedPrior, Refusal> {
    named_prior(s, s.rfind('='), "c=normal(0.5,0.1)")
}

/// `NAME=VALUE` of `--fix` and `--init`: the name before the last `=` (a series label of
/// `NAME[SERIES]` may hold one), a finite number after it; the name is checked against the
/// fit's parameters by the command.
pub(crate) fn named_value(s: &str) -> Result<(String, f64), Refusal> {
    let (name, value) = s
        .rsplit_once('=')
        .ok_or_else(|| Refusal::new("expected NAME=VALUE, e.g. a2=0"))?;
    let name = name.trim();
    if name.is_empty() {
        return Err(Refusal::new("expected NAME=VALUE, e.g. a2=0: no name"));
    }
    let v = number(
        value,
        f64::is_finite,
        "expected NAME=VALUE with a finite number",
    )?;
    Ok((name.to_string(), v))
}

/// `NAME=LO,HI` of `--bounds`: the name before the last `=`, two numbers with LO < HI after
/// it (`-inf` and `inf` leave a side open).
pub(crate) fn named_bounds(s: &str) -> Result<(String, (f64, f64)), Refusal> {
    let (name, range) = s
        .rsplit_once('=')
        .ok_or_else(|| Refusal::new("expected NAME=LO,HI, e.g. c=0.3,0.9"))?;
    let name = name.trim();
    let Some((lo, hi)) = range.split_once(',') else {
        return Err(Refusal::new("expected NAME=LO,HI, e.g. c=0.3,0.9"));
    };
    let bound = |t: &str| {
        t.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| !v.is_nan())
            .ok_or_else(|| Refusal::of(t.trim(), "not a number (-inf and inf allowed)"))
    };
    let (lo, hi) = (bound(lo)?, bound(hi)?);
    if name.is_empty() {
        return Err(Refusal::new("expected NAME=LO,HI, e.g. c=0.3,0.9: no name"));
    }
    if lo >= hi || lo == f64::INFINITY || hi == f64::NEG_INFINITY {
        return Err(Refusal::new("expected LO < HI"));
    }
    Ok((name.to_string(), (lo, hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_values_and_bounds() {
        assert_eq!(named_value("a2=0").unwrap(), ("a2".into(), 0.0));
        assert_eq!(
            named_value(" K[xi=1] = 0.5").unwrap(),
            ("K[xi=1]".into(), 0.5)
        );
        assert!(named_value("a2").is_err());
        assert!(named_value("a2=nan").is_err());
        assert!(named_value("=1").is_err());
        assert_eq!(named_bounds("c=0.3,0.9").unwrap(), ("c".into(), (0.3, 0.9)));
        assert_eq!(
            named_bounds("c=-inf,0.9").unwrap(),
            ("c".into(), (f64::NEG_INFINITY, 0.9))
        );
        assert!(named_bounds("c=0.9,0.3").is_err());
        assert!(named_bounds("c=0.3").is_err());
        assert!(named_bounds("c=x,1").unwrap_err().part.as_deref() == Some("x"));
    }

    #[test]
    fn choices_take_whole_names_in_any_case_and_spacing() {
        for (text, want) in [
            ("stick", ModelKind::Stick),
            (" Stick-Approx ", ModelKind::StickApprox),
            ("STICKSLIP", ModelKind::StickSlip),
            ("md", ModelKind::Md),
        ] {
            let got = named::<ModelKind>(text).unwrap();
            assert_eq!(got, want, "{text}");
            // The library reads the same names.
            assert_eq!(text.parse::<ModelKind>().unwrap(), want, "{text}");
        }
        assert!(named::<ModelKind>("stic").is_none());
        // Every name of the library's list is a possible value, in its order.
        let names: Vec<String> = ModelKind::variants().iter().map(name_of).collect();
        assert_eq!(names, Model::NAMES);
    }

    #[test]
    fn every_choice_reads_back_the_library_names() {
        for k in KLaw::variants() {
            assert_eq!(name_of(k).parse::<KLaw>().unwrap(), *k);
        }
        for k in DesignFit::variants() {
            assert_eq!(name_of(k).parse::<DesignFit>().unwrap(), *k);
        }
        for k in Criterion::variants() {
            assert_eq!(name_of(k).parse::<Criterion>().unwrap(), *k);
        }
        for k in FigureFormat::variants() {
            assert!(ReportSettings::check_format(&name_of(k)).is_ok());
        }
        for k in JaegerBranch::variants() {
            assert_eq!(name_of(k).parse::<JaegerBranch>().unwrap(), *k);
        }
        for k in KModel::variants() {
            assert_eq!(name_of(k).parse::<ModelKind>().unwrap(), k.kind());
        }
    }

    #[test]
    fn ranges_refuse_their_ends() {
        assert!(level("0").is_err() && level("1").is_err() && level("0.5").is_ok());
        assert!(tolerance("1").is_err() && tolerance("1e-10").is_ok());
        assert!(non_negative("-0.1").is_err() && non_negative("0").is_ok());
        assert!(non_negative("inf").is_err() && non_negative("NaN").is_err());
        assert!(gravity("0").is_err() && gravity("9.81").is_ok());
        assert!(noise("0.5").is_err() && noise("0").is_ok());
        assert!(points("0").is_err() && points("1000001").is_err() && points("1").is_ok());
        assert!(walkers("5").is_err() && walkers("2").is_err() && walkers("6").is_ok());
        assert!(scenes("0").is_err() && scenes("1000000").is_ok());
        assert!(at_least_one("0").is_err() && at_least_one("1").is_ok());
    }

    #[test]
    fn lists_refuse_the_bad_item_by_itself() {
        assert_eq!(
            numbers("1, x ,3"),
            Err(Refusal::of("x", "not a finite number"))
        );
        let e = series("1,2,1.0").unwrap_err();
        assert_eq!(e.part.as_deref(), Some("1.0"));
        assert!(e.message.contains("given twice (values 1 and 3)"), "{e}");
        assert!(jan_laws("1,2,3").is_err() && jan_laws("1,2,3,4").is_ok());
        assert!(slope_range("5,5").is_err());
        assert_eq!(slope_range(" 5,10").unwrap().text, " 5,10");
        assert_eq!(design_noise("abs=0.01"), Ok((0.01, true)));
        assert_eq!(design_noise("0.02"), Ok((0.02, false)));
        assert!(design_noise("1,2").is_err());
    }
}
