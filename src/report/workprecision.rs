//! The work-precision engine behind `fitbead bench`: draws scenes across regime B, computes
//! cross-checked high-precision references once, then for every model and method variant
//! records the relative error of v̄ (median, 99th percentile, maximum over scenes) and the
//! time per evaluation (median, 99th percentile over scenes; single thread, each scene timed
//! over a batch of repeats). Writes a CSV and an SVG of log time against log error.

use crate::fit::k::{bracket, solve};
use crate::models::auto::Auto;
use crate::models::contact::{Contact, PhaseKind, SpinRule};
pub(crate) use crate::models::sample::{draw_scenes, Draw};
use crate::models::slip::SlipPhase;
use crate::models::{slip, stick, stickquad, stickslip, Model, Outcome, Phases};
use crate::progress::Interrupted;
use crate::record::to_csv;
use crate::report::figures::FigureError;
use crate::scene::Scene;
use crate::special::quad::{integrate, QuadOptions};
use serde::Serialize;
use std::hint::black_box;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Tolerances of the quadrature variants.
pub(crate) const TOLS: [f64; 6] = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14];
/// Tolerances tried for auto.
pub(crate) const AUTO_TOLS: [f64; 5] = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12];
/// Tolerances of the contact model in the K inversion rows.
const K_CONTACT_TOLS: [f64; 3] = [1e-6, 1e-10, 1e-14];
/// Scenes used for the K inversion rows (each inversion costs tens of forward evaluations).
pub(crate) const K_SCENES: usize = 100;

/// Bounds the references' cross-checks must meet (maximum relative disagreement of v̄).
pub(crate) const XCHECK_BOUNDS: [(&str, f64); 4] = [
    ("stick", 1e-13),
    ("slip", 1e-11),
    ("stickslip", 1e-11),
    ("contact", 1e-12),
];

fn v(o: &Outcome) -> Option<f64> {
    o.as_ref().ok().map(|s| s.mean_velocity)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Slip time by plain adaptive quadrature of the raw integrand 1/sqrt(Θ̇²) of eq 38 (no
/// substitution): the slip reference's independent cross-check.
fn slip_raw(scene: &Scene) -> Option<f64> {
    let l2 = slip::final_velocity_sq(scene).ok()?;
    if !(l2 > 0.0) || scene.sc_f.c - l2 < 0.0 {
        return None; // stops or lifts off at Θf (eq 30a): no steady slip contact
    }
    let w0sq = scene.k * scene.k * l2;
    let ph = SlipPhase::new(scene.theta_0, w0sq, scene.f);
    let r = integrate(
        |t: f64| {
            let g = ph.speed_sq(t);
            if g > 0.0 {
                1.0 / g.sqrt()
            } else {
                f64::INFINITY
            }
        },
        scene.theta_0,
        scene.theta_f,
        QuadOptions {
            rel_tol: 1e-15,
            abs_tol: 0.0,
            max_panels: 256,
        },
    );
    (r.value.is_finite() && r.value > 0.0).then(|| 2.0 * scene.sin_alpha / r.value)
}

/// The references of one scene.
#[derive(Debug, Clone, Copy)]
pub(crate) struct References {
    /// Stick, elliptic closed form.
    pub stick: Outcome,
    /// Stick by quadrature at 1e-15 (cross-check).
    pub stick_x: Outcome,
    /// Slip at 1e-14.
    pub slip: Outcome,
    /// Slip by raw quadrature (cross-check).
    pub slip_x: Option<f64>,
    /// Stick/slip at 1e-14.
    pub stickslip: Outcome,
    /// Contact model at 1e-14.
    pub contact: Outcome,
    /// Contact model at 1e-15 (cross-check).
    pub contact_x: Outcome,
    /// Where the physics reference (the best value of the general contact model's v̄) comes
    /// from.
    pub physics_source: PhysicsSource,
}

/// The physics reference of a scene: the general contact model's v̄ computed by the most
/// accurate path that describes its phase sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PhysicsSource {
    /// The contact model rolls throughout: the exact rolling closed form (cross-checked by
    /// quadrature). Near δ_m the contact model itself loses digits to cancellation in the
    /// squared top velocity, which the closed form computes without cancellation.
    Stick,
    /// The contact model rolls then slips (the paper's sequence): stick/slip at 1e-14
    /// (cross-checked against the contact model).
    StickSlip,
    /// Any other sequence, or no steady state: the contact model at 1e-14 (cross-checked at
    /// 1e-15).
    Contact,
}

impl References {
    /// Computes every reference of one scene.
    pub fn of(scene: &Scene) -> Self {
        let c = |tol| {
            Contact {
                spin: SpinRule::Roll,
                tol,
            }
            .evaluate(scene)
        };
        let mut r = References {
            stick: stick::steady(scene),
            stick_x: stickquad::steady_quad(scene, 1e-15),
            slip: slip::steady(scene),
            slip_x: slip_raw(scene),
            stickslip: stickslip::steady(scene),
            contact: c(1e-14),
            contact_x: c(1e-15),
            physics_source: PhysicsSource::Contact,
        };
        r.physics_source = match r.contact_sequence() {
            Some(Seq::Roll) if r.stick.is_ok() => PhysicsSource::Stick,
            Some(Seq::RollSlip) if r.stickslip.is_ok() => PhysicsSource::StickSlip,
            _ => PhysicsSource::Contact,
        };
        r
    }

    /// The physics reference: v̄ of the general contact model by the most accurate path.
    pub fn physics(&self) -> Outcome {
        match self.physics_source {
            PhysicsSource::Stick => self.stick,
            PhysicsSource::StickSlip => self.stickslip,
            PhysicsSource::Contact => self.contact,
        }
    }

    fn contact_sequence(&self) -> Option<Seq> {
        match &self.contact {
            Ok(s) => match s.phases {
                Phases::Sequence(p) => {
                    let k = p.kinds();
                    if k == [PhaseKind::Roll] {
                        Some(Seq::Roll)
                    } else if k == [PhaseKind::Roll, PhaseKind::Slip] {
                        Some(Seq::RollSlip)
                    } else {
                        Some(Seq::Other)
                    }
                }
                _ => Some(Seq::Other),
            },
            Err(_) => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Seq {
    Roll,
    RollSlip,
    Other,
}

/// Which reference a variant is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ref {
    Stick,
    Slip,
    StickSlip,
    /// The physics reference ([`References::physics`]).
    Physics,
}

fn reference(r: &References, which: Ref) -> Outcome {
    match which {
        Ref::Stick => r.stick,
        Ref::Slip => r.slip,
        Ref::StickSlip => r.stickslip,
        Ref::Physics => r.physics(),
    }
}

/// The value the reference variant itself is compared with (its cross-check).
fn cross(r: &References, which: Ref) -> Option<f64> {
    match which {
        Ref::Stick => v(&r.stick_x),
        Ref::Slip => r.slip_x,
        Ref::StickSlip => match r.contact_sequence() {
            Some(Seq::RollSlip) => v(&r.contact),
            Some(Seq::Roll) => v(&r.stick),
            _ => None,
        },
        Ref::Physics => match r.physics_source {
            PhysicsSource::Contact => v(&r.contact_x),
            _ => v(&r.physics()),
        },
    }
}

/// One model and method variant.
struct Variant {
    model: &'static str,
    method: &'static str,
    tol: Option<f64>,
    reference: Ref,
    is_ref: bool,
    eval: Box<dyn Fn(&Scene) -> Outcome>,
}

fn variants() -> Vec<Variant> {
    let mut v: Vec<Variant> = Vec::new();
    v.push(Variant {
        model: "stick",
        method: "elliptic",
        tol: None,
        reference: Ref::Stick,
        is_ref: true,
        eval: Box::new(stick::steady),
    });
    for &t in &TOLS {
        v.push(Variant {
            model: "stick",
            method: "quadrature",
            tol: Some(t),
            reference: Ref::Stick,
            is_ref: false,
            eval: Box::new(move |s| stickquad::steady_quad(s, t)),
        });
    }
    v.push(Variant {
        model: "stick-approx",
        method: "asinh-eq29",
        tol: None,
        reference: Ref::Stick,
        is_ref: false,
        eval: Box::new(stick::steady_approx),
    });
    for &t in &TOLS {
        v.push(Variant {
            model: "slip",
            method: "quadrature",
            tol: Some(t),
            reference: Ref::Slip,
            is_ref: t == 1e-14,
            eval: Box::new(move |s| slip::steady_tol(s, t)),
        });
    }
    v.push(Variant {
        model: "slip-approx",
        method: "elliptic-eq57",
        tol: None,
        reference: Ref::Slip,
        is_ref: false,
        eval: Box::new(slip::steady_approx),
    });
    for &t in &TOLS {
        v.push(Variant {
            model: "stickslip",
            method: "quadrature",
            tol: Some(t),
            reference: Ref::StickSlip,
            is_ref: t == 1e-14,
            eval: Box::new(move |s| stickslip::steady_tol(s, t)),
        });
    }
    for &t in &TOLS {
        v.push(Variant {
            model: "contact",
            method: "quadrature",
            tol: Some(t),
            reference: Ref::Physics,
            is_ref: t == 1e-14,
            eval: Box::new(move |s| {
                Contact {
                    spin: SpinRule::Roll,
                    tol: t,
                }
                .evaluate(s)
            }),
        });
    }
    for &t in &AUTO_TOLS {
        v.push(Variant {
            model: "auto",
            method: "auto",
            tol: Some(t),
            reference: Ref::Physics,
            is_ref: false,
            eval: Box::new(move |s| Auto { tol: t }.evaluate(s)),
        });
    }
    v
}

/// Time of one evaluation: a batch of repeats long enough to time (≥ 20 µs or 64 repeats).
fn time_one(f: &dyn Fn(&Scene) -> Outcome, s: &Scene, first: Duration) -> f64 {
    let target = 20_000.0;
    let one = first.as_nanos().max(1) as f64;
    let reps = ((target / one).ceil() as usize).clamp(1, 64);
    let t0 = Instant::now();
    for _ in 0..reps {
        black_box(f(black_box(s)).ok());
    }
    t0.elapsed().as_nanos() as f64 / reps as f64
}

/// One row of the work-precision table (`fitbead bench`): a method's relative errors against
/// the reference and its time per evaluation. Errors are written with four significant
/// digits, times in whole nanoseconds.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct WpRow {
    /// Model name.
    pub model: String,
    /// Method name.
    pub method: String,
    /// Tolerance (when the method has one).
    #[serde(rename = "tolerance")]
    pub tol: Option<f64>,
    /// Scenes counted (the reference steady, or the variant steady).
    pub scenes: usize,
    /// Median relative error.
    #[serde(serialize_with = "error_cell")]
    pub err_median: f64,
    /// 99th percentile of the relative error.
    #[serde(serialize_with = "error_cell")]
    pub err_p99: f64,
    /// Maximum relative error.
    #[serde(serialize_with = "error_cell")]
    pub err_max: f64,
    /// Median time per evaluation, ns.
    #[serde(serialize_with = "ns_cell")]
    pub ns_median: Option<f64>,
    /// 99th percentile of the time per evaluation, ns.
    #[serde(serialize_with = "ns_cell")]
    pub ns_p99: Option<f64>,
}

/// A relative error as its cell: four significant digits, `0`, `inf`, or empty for NaN.
fn error_cell<S: serde::Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    let x = *x;
    if x.is_nan() {
        s.serialize_none()
    } else if x.is_infinite() {
        s.serialize_str("inf")
    } else if x == 0.0 {
        s.serialize_str("0")
    } else {
        s.collect_str(&format_args!("{x:.3e}"))
    }
}

/// A time as its cell: whole nanoseconds, or empty.
fn ns_cell<S: serde::Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match x {
        Some(t) => s.collect_str(&format_args!("{t:.0}")),
        None => s.serialize_none(),
    }
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1;
    sorted[i]
}

fn sorted(mut x: Vec<f64>) -> Vec<f64> {
    x.sort_by(|a, b| a.total_cmp(b));
    x
}

fn row(model: &str, method: &str, tol: Option<f64>, errs: Vec<f64>, ns: Option<Vec<f64>>) -> WpRow {
    let e = sorted(errs);
    let t = ns.map(sorted);
    WpRow {
        model: model.into(),
        method: method.into(),
        tol,
        scenes: e.len(),
        err_median: quantile(&e, 0.5),
        err_p99: quantile(&e, 0.99),
        err_max: e.last().copied().unwrap_or(f64::NAN),
        ns_median: t.as_ref().map(|t| quantile(t, 0.5)),
        ns_p99: t.as_ref().map(|t| quantile(t, 0.99)),
    }
}

/// Error of a variant against a reference value: relative error when both are steady,
/// infinite when exactly one is, `None` when neither is (not counted).
fn error_of(o: &Outcome, r: Option<f64>, ref_ok: bool) -> Option<f64> {
    match (v(o), r) {
        (Some(a), Some(b)) => Some(rel(a, b)),
        (None, None) => None,
        (Some(_), None) if !ref_ok => Some(f64::INFINITY),
        (None, Some(_)) => Some(f64::INFINITY),
        _ => None,
    }
}

/// Everything the bench measures.
#[derive(Debug, Clone)]
pub(crate) struct BenchResult {
    /// The rows, in order.
    pub rows: Vec<WpRow>,
    /// Per auto tolerance: the cheapest single variant (by median time) that meets it on all
    /// scenes against the physics reference, with its median time.
    pub cheapest: Vec<(f64, Option<(String, f64)>)>,
    /// Which model auto used, counted over scenes at T = 1e-10: (stick, stickslip, contact).
    pub auto_mix: (usize, usize, usize),
}

impl BenchResult {
    /// The summary `fitbead bench` prints on stderr, one line each: every cross-check of the
    /// references against its bound (or that none of the `drawn` scenes falls in its domain),
    /// auto's median time beside the cheapest single method meeting each tolerance, and the
    /// models auto used.
    pub(crate) fn summary(&self, drawn: usize) -> String {
        use std::fmt::Write as _;
        let mut o = String::new();
        for r in self
            .rows
            .iter()
            .filter(|r| r.method.starts_with("crosscheck"))
        {
            let bound = XCHECK_BOUNDS
                .iter()
                .find(|b| b.0 == r.model)
                .map(|b| b.1)
                .unwrap_or(0.0);
            if r.scenes == 0 {
                let _ = writeln!(
                    o,
                    "reference {:<10} {:<42} scenes     0: no scenes: none of the {drawn} drawn \
                     falls in this check's domain (draw more with --scenes)",
                    r.model, r.method,
                );
                continue;
            }
            let _ = writeln!(
                o,
                "reference {:<10} {:<42} scenes {:>5}  max {:.2e}  median {:.2e}  bound {:.0e}: {}",
                r.model,
                r.method,
                r.scenes,
                r.err_max,
                r.err_median,
                bound,
                if r.err_max <= bound { "ok" } else { "FAILED" }
            );
        }
        for (t, best) in &self.cheapest {
            let auto = self
                .rows
                .iter()
                .find(|r| r.model == "auto" && r.tol == Some(*t))
                .and_then(|r| r.ns_median)
                .unwrap_or(f64::NAN);
            let _ = match best {
                Some((name, ns)) => writeln!(
                    o,
                    "auto at T = {t:e}: median {auto:.0} ns; cheapest single method meeting T on \
                     all scenes (vs physics reference): {name}, {ns:.0} ns"
                ),
                None => writeln!(
                    o,
                    "auto at T = {t:e}: median {auto:.0} ns; no single method meets T on all \
                     scenes"
                ),
            };
        }
        let _ = writeln!(
            o,
            "auto at T = 1e-10 used stick on {}, stickslip on {}, contact on {} scenes",
            self.auto_mix.0, self.auto_mix.1, self.auto_mix.2
        );
        o
    }
}

/// Runs the whole bench on `scenes` (single thread), stopping with [`Interrupted`] once `stop` is raised (polled before every
/// scene of every variant: a few milliseconds apart at most).
pub(crate) fn run_bench_until(
    scenes: &[(Scene, Draw)],
    stop: &AtomicBool,
) -> Result<BenchResult, Interrupted> {
    let check = || {
        if stop.load(Ordering::Relaxed) {
            Err(Interrupted)
        } else {
            Ok(())
        }
    };
    let mut refs: Vec<References> = Vec::with_capacity(scenes.len());
    for (s, _) in scenes {
        check()?;
        refs.push(References::of(s));
    }
    let mut rows = crosscheck_rows(&refs);
    let vs_contact = variant_rows(scenes, &refs, &check, &mut rows)?;
    let cheapest = cheapest_per_tolerance(&vs_contact);
    let mut mix = (0, 0, 0);
    for (s, _) in scenes {
        check()?;
        match (Auto { tol: 1e-10 }).choose(s).choice {
            crate::models::auto::Choice::Stick => mix.0 += 1,
            crate::models::auto::Choice::StickSlip => mix.1 += 1,
            crate::models::auto::Choice::Contact => mix.2 += 1,
        }
    }
    rows.extend(k_rows(scenes, &refs, &check)?);
    Ok(BenchResult {
        rows,
        cheapest,
        auto_mix: mix,
    })
}

/// The cross-checks of the references: each reference against an independent method, one
/// row per model.
fn crosscheck_rows(refs: &[References]) -> Vec<WpRow> {
    let mut rows = Vec::new();
    let mut xs: Vec<(&str, &str, Vec<f64>)> = vec![
        ("stick", "crosscheck:elliptic-vs-quadrature-1e-15", vec![]),
        ("slip", "crosscheck:1e-14-vs-raw-quadrature-1e-15", vec![]),
        (
            "stickslip",
            "crosscheck:1e-14-vs-contact-1e-14-on-roll>slip",
            vec![],
        ),
        (
            "contact",
            "crosscheck:1e-14-vs-1e-15-on-other-sequences",
            vec![],
        ),
    ];
    for r in refs {
        if let Some(e) = error_of(&r.stick, v(&r.stick_x), r.stick_x.is_ok()) {
            xs[0].2.push(e);
        }
        if let Some(e) = error_of(&r.slip, r.slip_x, r.slip_x.is_some()) {
            xs[1].2.push(e);
        }
        if r.contact_sequence() == Some(Seq::RollSlip) {
            if let Some(e) = error_of(&r.stickslip, v(&r.contact), true) {
                xs[2].2.push(e);
            }
        }
        if r.physics_source == PhysicsSource::Contact {
            if let Some(e) = error_of(&r.contact, v(&r.contact_x), r.contact_x.is_ok()) {
                xs[3].2.push(e);
            }
        }
    }
    for (m, meth, e) in xs {
        rows.push(row(m, meth, None, e, None));
    }
    rows
}

/// One variant's name, its largest error against the physics reference, its auto
/// tolerance (auto variants) and its median time.
type VsContact = (String, f64, Option<f64>, f64);

/// Every variant on every scene, timed, its row pushed onto `rows`; each variant against the
/// physics reference. `check` fails once the bench is stopped.
fn variant_rows(
    scenes: &[(Scene, Draw)],
    refs: &[References],
    check: &dyn Fn() -> Result<(), Interrupted>,
    rows: &mut Vec<WpRow>,
) -> Result<Vec<VsContact>, Interrupted> {
    let mut vs_contact: Vec<VsContact> = Vec::new();
    for var in variants() {
        let mut errs = Vec::new();
        let mut errs_c = Vec::new();
        let mut ns = Vec::new();
        for ((s, _), r) in scenes.iter().zip(refs) {
            check()?;
            let t0 = Instant::now();
            let o = (var.eval)(s);
            let first = t0.elapsed();
            ns.push(time_one(&*var.eval, s, first));
            let refo = reference(r, var.reference);
            let target = if var.is_ref {
                cross(r, var.reference).filter(|_| refo.is_ok())
            } else {
                v(&refo)
            };
            if var.is_ref && target.is_none() {
                // No independent value here: not counted.
            } else if let Some(e) = error_of(&o, target, refo.is_ok()) {
                errs.push(e);
            }
            let phys = r.physics();
            if let Some(e) = error_of(&o, v(&phys), phys.is_ok()) {
                errs_c.push(e);
            }
        }
        let rw = row(var.model, var.method, var.tol, errs, Some(ns));
        let max_c = errs_c.iter().fold(0.0f64, |a, &b| a.max(b));
        vs_contact.push((
            format!(
                "{}/{}{}",
                var.model,
                var.method,
                var.tol.map(|t| format!("@{t:e}")).unwrap_or_default()
            ),
            max_c,
            var.tol.filter(|_| var.model == "auto"),
            rw.ns_median.unwrap_or(f64::NAN),
        ));
        rows.push(rw);
    }
    Ok(vs_contact)
}

/// Per auto tolerance, the cheapest single variant (by median time) that meets it on all
/// scenes against the physics reference, with its median time.
fn cheapest_per_tolerance(vs_contact: &[VsContact]) -> Vec<(f64, Option<(String, f64)>)> {
    // Auto against the cheapest single method meeting T on all scenes.
    let mut cheapest = Vec::new();
    for &t in &AUTO_TOLS {
        let best = vs_contact
            .iter()
            .filter(|(name, max_c, auto_t, _)| {
                auto_t.is_none() && !name.starts_with("auto") && *max_c <= t
            })
            .min_by(|a, b| a.3.total_cmp(&b.3))
            .map(|(name, _, _, ns)| (name.clone(), *ns));
        cheapest.push((t, best));
    }
    cheapest
}

/// K inversion (eq 69) with each model: v from the model's own reference at the scene's
/// K; error |K̂ − K| / K, on the first `K_SCENES` scenes. `check` fails once the bench is
/// stopped.
fn k_rows(
    scenes: &[(Scene, Draw)],
    refs: &[References],
    check: &dyn Fn() -> Result<(), Interrupted>,
) -> Result<Vec<WpRow>, Interrupted> {
    let mut rows = Vec::new();
    let nk = scenes.len().min(K_SCENES);
    let mut kmodels: Vec<(&str, String, Option<f64>, Model)> = vec![
        ("k-stick", "brent-eq69".into(), None, Model::Stick),
        (
            "k-stick-approx",
            "brent-eq69".into(),
            None,
            Model::StickApprox,
        ),
        ("k-slip", "brent-eq69".into(), Some(1e-14), Model::Slip),
        (
            "k-slip-approx",
            "brent-eq69".into(),
            None,
            Model::SlipApprox,
        ),
        (
            "k-stickslip",
            "brent-eq69".into(),
            Some(1e-14),
            Model::StickSlip,
        ),
    ];
    for &t in &K_CONTACT_TOLS {
        kmodels.push((
            "k-contact",
            "brent-eq69".into(),
            Some(t),
            Model::Contact(Contact {
                spin: SpinRule::Roll,
                tol: t,
            }),
        ));
    }
    // The same inversions through `k::estimate`, which takes the launch-speed path
    // (src/fit/k/launch.rs) for stick and stick/slip where it applies.
    kmodels.push(("k-stick", "estimate-eq69".into(), None, Model::Stick));
    kmodels.push((
        "k-stickslip",
        "estimate-eq69".into(),
        Some(1e-14),
        Model::StickSlip,
    ));
    for (name, method, tol, model) in &kmodels {
        let mut errs = Vec::new();
        let mut ns = Vec::new();
        let by_estimate = method.starts_with("estimate");
        for ((s, _), r) in scenes.iter().take(nk).zip(refs) {
            check()?;
            let which = match model {
                Model::Stick | Model::StickApprox => Ref::Stick,
                Model::Slip | Model::SlipApprox => Ref::Slip,
                Model::StickSlip => Ref::StickSlip,
                _ => Ref::Physics,
            };
            let Some(vref) = v(&reference(r, which)) else {
                continue;
            };
            let t0 = Instant::now();
            let k = if by_estimate {
                crate::fit::k::estimate(model, s, vref, None).root
            } else {
                bracket(model, s).and_then(|br| solve(model, s, &br, vref))
            };
            ns.push(t0.elapsed().as_nanos() as f64);
            errs.push(match k {
                Ok(root) => rel(root.k, s.k),
                Err(_) => f64::INFINITY,
            });
        }
        rows.push(row(name, method, *tol, errs, Some(ns)));
    }
    Ok(rows)
}

/// The CSV of the rows (one [`WpRow`] record each).
pub(crate) fn render(rows: &[WpRow]) -> csv::Result<Vec<u8>> {
    to_csv(rows.iter().cloned())
}

/// Reads back the rows [`render`] wrote (a `bench --output` file), to re-plot measured rows
/// without measuring again. An empty error cell reads as NaN, `inf` as infinity.
#[cfg(any(test, feature = "bench-internals"))]
pub(crate) fn read_rows(csv_bytes: &[u8]) -> std::io::Result<Vec<WpRow>> {
    use std::io::Error;
    let mut r = csv::Reader::from_reader(csv_bytes);
    let h = r.headers().map_err(Error::other)?.clone();
    let columns = crate::record::columns::<WpRow>();
    if h.iter().collect::<Vec<_>>() != columns {
        return Err(Error::other(format!(
            "expected the columns {}",
            columns.join(",")
        )));
    }
    let num = |s: &str| -> std::io::Result<f64> {
        match s {
            "" => Ok(f64::NAN),
            "inf" => Ok(f64::INFINITY),
            _ => s
                .parse()
                .map_err(|_| Error::other(format!("not a number: {s:?}"))),
        }
    };
    let opt = |s: &str| -> std::io::Result<Option<f64>> {
        if s.is_empty() {
            Ok(None)
        } else {
            num(s).map(Some)
        }
    };
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(Error::other)?;
        rows.push(WpRow {
            model: rec[0].to_string(),
            method: rec[1].to_string(),
            tol: opt(&rec[2])?,
            scenes: rec[3]
                .parse()
                .map_err(|_| Error::other(format!("not a count: {:?}", &rec[3])))?,
            err_median: num(&rec[4])?,
            err_p99: num(&rec[5])?,
            err_max: num(&rec[6])?,
            ns_median: opt(&rec[7])?,
            ns_p99: opt(&rec[8])?,
        });
    }
    Ok(rows)
}

/// The work-precision diagram on log–log axes: median time per evaluation against maximum
/// relative error, one curve per model and method (its tolerances joined), single methods as
/// points, the legend outside the plot. A method that is invalid on some scenes (infinite
/// maximum error) is drawn at its median error and says so in its label; errors below 1e-17
/// are drawn at 1e-17.
pub(crate) fn plot(rows: &[WpRow], title: &str) -> Result<String, FigureError> {
    use super::figures::{series_style, Axis, Figure, LegendEntry, Panel, Stroke};
    let floor = 1e-17f64;
    // (row, error, time, drawn at the median error)
    let pts: Vec<(&WpRow, f64, f64, bool)> = rows
        .iter()
        .filter(|r| !r.method.starts_with("crosscheck") && !r.model.starts_with("k-"))
        .filter_map(|r| {
            let t = r.ns_median?;
            let (e, median) = if r.err_max.is_finite() {
                (r.err_max, false)
            } else {
                (r.err_median, true)
            };
            (e.is_finite() && t > 0.0).then(|| (r, e.max(floor), t, median))
        })
        .collect();
    let mut groups: Vec<(&str, &str)> = Vec::new();
    for p in &pts {
        let g = (p.0.model.as_str(), p.0.method.as_str());
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    let mut panel = Panel::new(
        "",
        Axis::log("maximum relative error of v\u{304} (below 10^{−17} drawn at 10^{−17})"),
        Axis::log("median time per evaluation (ns)"),
    );
    for (i, (m, meth)) in groups.iter().enumerate() {
        let (colour, mark) = series_style(i);
        let sel: Vec<(f64, f64, bool)> = pts
            .iter()
            .filter(|p| p.0.model == *m && p.0.method == *meth)
            .map(|p| (p.1, p.2, p.3))
            .collect();
        let mut label = if *meth == "auto" || *meth == "quadrature" {
            format!("{m} (tolerances)")
        } else {
            format!("{m} ({meth})")
        };
        if sel.iter().any(|p| p.2) {
            label.push_str(": median error, invalid on some scenes");
        }
        let stroke = Stroke::solid(colour, 2.0);
        panel.curve(sel.iter().map(|p| (p.0, p.1)).collect(), stroke.clone());
        panel.points(
            sel.iter().map(|p| (p.0, p.1, f64::NAN, f64::NAN)).collect(),
            colour,
            mark,
        );
        panel
            .legend
            .push(LegendEntry::mark_line(&label, mark, &stroke));
    }
    // Every entry outside the data: the legend goes to the figure.
    let legend = std::mem::take(&mut panel.legend);
    let mut f = Figure::new(title, 1, (640.0, 460.0), vec![panel]);
    f.legend = legend;
    Ok(f.to_svg())
}

#[cfg(test)]
mod tests {
    use super::{read_rows, render, WpRow};

    /// The columns of `fitbead bench`'s table as docs/GUIDE.md lists them (a contract),
    /// against the columns generated from the record.
    #[test]
    fn wp_columns_are_the_documented_contract() {
        assert_eq!(
            crate::record::columns::<WpRow>(),
            [
                "model",
                "method",
                "tolerance",
                "scenes",
                "err_median",
                "err_p99",
                "err_max",
                "ns_median",
                "ns_p99"
            ]
        );
    }

    /// The committed work-precision table reads back into rows that render to the same bytes
    /// (so `examples/wp_plot.rs` re-plots exactly the measured values).
    #[test]
    fn wp_table_reads_back_byte_for_byte() {
        let bytes =
            std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/wp.csv"))
                .unwrap();
        let rows = read_rows(&bytes).unwrap();
        assert!(rows.len() > 20);
        assert_eq!(render(&rows).unwrap(), bytes);
    }
}
