//! The comparisons of `fitbead report`: every model of the paper fitted to one data set, the
//! bulk friction of Jan's model against the closed form eq 79, the energy budgets, the regime
//! map and the model ranking. Tables are CSV bytes; nothing here touches files.

use crate::fit::data::Dataset;
use crate::fit::jaeger::{fit_jaeger_with, JaegerFits};
use crate::fit::jan::{fit_jan_with, JanFits};
use crate::fit::k::bracket;
use crate::fit::klaw::{fit_law_with, KLaw, KLawError, KLawFit, KLawProblem};
use crate::fit::posterior::{Method, SharedProgress};
use crate::fit::summary::{FitResult, ParamRow};
use crate::inverse::{CurveModel as _, Residuals, SigmaKind};
use crate::models::energy;
use crate::models::regimes::{bulk_friction, critical_xi, delta_d_law, delta_m_law};
use crate::models::{ForwardModel, JaegerBranch, Model, Regime};
use crate::numfmt::fmt_f64;
use crate::record::to_csv;
use crate::scene::CollisionLaw;
use rayon::prelude::*;
use serde::Serialize;

/// The two collision models whose K is fitted: pure rolling (the paper's stick model) and
/// stick/slip.
const CONTACT: [(Model, &str); 2] = [(Model::Stick, "rolling"), (Model::StickSlip, "stickslip")];

/// ΔAIC (and ΔBIC) above which extra parameters count as supported by the data (the usual
/// rule of thumb: a difference below 2 is not worth a parameter).
pub(crate) const SUPPORT_THRESHOLD: f64 = 2.0;

/// The laws fitted under one contact model, on the points that model can make steady.
pub struct ContactFits {
    /// Model.
    pub model: Model,
    /// Name in the tables (`rolling`, `stickslip`).
    pub name: &'static str,
    /// The points used (indices into the full data set) and their data set.
    pub used: Vec<usize>,
    /// Their data set.
    pub data: Dataset,
    /// Law c.
    pub law_c: Option<KLawFit>,
    /// One K per series.
    pub free: Option<KLawFit>,
    /// χ² of K = cos 2α (the smooth collision, law c with c = 0) and of the impact law, with
    /// the number of points that have no steady state under each (χ² = ∞ then).
    pub cos2a_chi2: (f64, usize),
    /// χ² and unsteady count of the impact law.
    pub impact_chi2: (f64, usize),
    /// Energy partition of every used point at the K of the law-c fit (`None` where there is
    /// no fit or no steady state); computed once, read by the energy table and its ranges.
    pub energy: Vec<Option<energy::EnergyPartition>>,
    /// Why a fit is missing.
    pub notes: Vec<String>,
    /// The K(α) laws (c, or one K per series) that could not be fitted, with why (also among
    /// `notes`): what makes `klaw` exit 2. Point indices in the errors are into `data`.
    pub law_failures: Vec<(KLaw, KLawError)>,
}

/// Everything the report computes.
pub struct Analysis {
    /// The data.
    pub data: Dataset,
    /// Interval level.
    pub level: f64,
    /// Whether the fits were sampled (MCMC).
    pub mcmc: bool,
    /// Rolling and stick/slip fits.
    pub contact: Vec<ContactFits>,
    /// Jan's fits.
    pub jan: JanFits,
    /// Jaeger's fits (upper branch).
    pub jaeger: JaegerFits,
    /// The width the report's figures are printed at, mm (`None`, as [`analyse`] leaves it:
    /// their natural size); see [`Figure::print_width_mm`](crate::report::figures::plot::Figure::print_width_mm).
    pub print_width_mm: Option<f64>,
}

fn chi2_at(problem: &KLawProblem<'_>, p: &[f64], m: usize) -> (f64, usize) {
    let mut r = vec![0.0; m];
    match problem.residuals(p, &mut r) {
        Ok(()) => (r.iter().map(|x| x * x).sum(), 0),
        Err(_) => {
            let data_points = (0..m).filter(|&i| !problem.point_is_steady(i, p)).count();
            (f64::INFINITY, data_points)
        }
    }
}

/// Posterior draws the report keeps per fit at most, once the fit's summary is made from all
/// of them: enough for its plots (a corner plot's 30 × 30 density grid and 36-bin marginals) and
/// for [`super::bands`], which uses at most 1000. The fit commands' `--draws` keep every draw.
pub const REPORT_DRAWS: usize = 10_000;

/// Fits every model to `data` by `method` at `level`.
///
/// The fits are independent and run concurrently (rayon); each is reproducible on its own
/// (the sampler's streams depend on the seed only), so the analysis is the same whatever the
/// number of threads. Under MCMC a progress sink receives the events of one fit at a time
/// (the first to start holds it until it finishes, then the next fit still running to report
/// takes it over), and each posterior keeps at most [`REPORT_DRAWS`] draws.
pub fn analyse(data: &Dataset, level: f64, method: &Method) -> Analysis {
    let shared = SharedProgress::of(method);
    let (contact, (jan, jaeger)) = rayon::join(
        || {
            CONTACT
                .par_iter()
                .map(|&(model, name)| contact_fits(data, model, name, level, &shared.method()))
                .collect::<Vec<_>>()
        },
        || {
            rayon::join(
                || {
                    let mut j = fit_jan_with(data, level, &shared.method());
                    for f in j.series.iter_mut().flatten().chain(j.global.iter_mut()) {
                        thin_draws(f);
                    }
                    j
                },
                || {
                    let mut j = fit_jaeger_with(data, JaegerBranch::Upper, level, &shared.method());
                    for f in j.series.iter_mut().flatten() {
                        thin_draws(&mut f.summary);
                    }
                    j
                },
            )
        },
    );
    Analysis {
        data: data.clone(),
        level,
        mcmc: matches!(method, Method::Mcmc(_)),
        contact,
        jan,
        jaeger,
        print_width_mm: None,
    }
}

fn thin_draws(f: &mut FitResult) {
    if let Some(d) = f.draws.as_mut() {
        d.thin_to(REPORT_DRAWS);
    }
}

/// The laws of one contact model fitted on the points it can make steady.
fn contact_fits(
    data: &Dataset,
    model: Model,
    name: &'static str,
    level: f64,
    method: &Method,
) -> ContactFits {
    // Once the stop flag is up, the per-point work is skipped (each fit then ends at once):
    // the caller, who raised it, does not use a stopped analysis beyond its posteriors.
    let keep: Vec<bool> = data
        .points
        .par_iter()
        .map(|p| !method.stopped() && bracket(&model, &p.scene).is_ok())
        .collect();
    let (sub, used) = data.filter(|i| keep[i]);
    let mut notes = Vec::new();
    let dropped = data.points.len() - used.len();
    if dropped > 0 {
        notes.push(format!(
            "{dropped} point(s) have no steady state for any K under the {name} model and \
             are left out of its fits"
        ));
    }
    let fit = |law: KLaw| {
        fit_law_with(model, &sub, law, level, method).map(|mut f| {
            thin_draws(&mut f.summary);
            f
        })
    };
    let (law_c, free) = rayon::join(|| fit(KLaw::C), || fit(KLaw::FreePerSeries));
    let mut law_failures = Vec::new();
    let mut keep_fit = |law: KLaw, r: Result<KLawFit, _>| match r {
        Ok(f) => Some(f),
        Err(e) => {
            law_failures.push((law, e));
            None
        }
    };
    let law_c = keep_fit(KLaw::C, law_c);
    let free = keep_fit(KLaw::FreePerSeries, free);
    notes.extend(
        law_failures
            .iter()
            .map(|(law, e)| format!("{name} law {}: {e}", law.name())),
    );
    let m = sub.points.len();
    let stop = method.stop().cloned();
    let cos2a_chi2 = KLawProblem::new_until(model, &sub, KLaw::C, stop.clone())
        .map(|p| chi2_at(&p, &[0.0], m))
        .unwrap_or((f64::INFINITY, m));
    let impact_chi2 = KLawProblem::new_until(model, &sub, KLaw::Impact, stop)
        .map(|p| chi2_at(&p, &[], m))
        .unwrap_or((f64::INFINITY, m));
    let energy = match &law_c {
        Some(f) => sub
            .points
            .par_iter()
            .zip(&f.k)
            .map(|(p, &k)| {
                if method.stopped() {
                    return None;
                }
                let sc = p.scene.with_k(k).ok()?;
                let st = model.evaluate(&sc).ok()?;
                match model {
                    Model::Stick => Some(energy::rolling(&sc, &st)),
                    _ => energy::stickslip(&sc, &st).ok(),
                }
            })
            .collect(),
        None => vec![None; sub.points.len()],
    };
    ContactFits {
        model,
        name,
        used,
        data: sub,
        law_c,
        free,
        cos2a_chi2,
        impact_chi2,
        energy,
        notes,
        law_failures,
    }
}

/// The reported interval of a row, or the value itself when there is none.
pub(crate) fn interval(r: &ParamRow) -> (f64, f64) {
    r.interval().0.unwrap_or((r.value, r.value))
}

/// The least-squares value of a row (the optimum also under MCMC).
pub(crate) fn lsq(r: &ParamRow) -> f64 {
    r.lsq_value.unwrap_or(r.value)
}

pub(crate) fn k_of_c(alpha: f64, c: f64) -> f64 {
    let (s2a, c2a) = (2.0 * alpha).sin_cos();
    let sa = alpha.sin();
    c2a + c * sa * sa * s2a
}

/// A number for the model tables: `inf` where a model cannot make a point steady.
fn num(x: f64) -> String {
    if x == f64::INFINITY {
        "inf".into()
    } else {
        fmt_f64(x)
    }
}

/// One row of the bulk-friction table.
#[derive(Debug, Clone)]
pub struct MuRow {
    /// Series label.
    pub series: String,
    /// ξ of the series.
    pub xi: f64,
    /// α (radians).
    pub alpha: f64,
    /// Jan's μ of the series and its interval.
    pub mu_jan: (f64, f64, f64),
    /// Which fitted K (`rolling-free`, `rolling-law-c`, `stickslip-free`, …).
    pub k_source: String,
    /// K and its interval.
    pub k: (f64, f64, f64),
    /// μ of eq 79 at that K, and its interval (K's interval mapped through eq 79).
    pub mu_eq79: (f64, f64, f64),
    /// The paper's eq 76 at this α.
    pub mu_eq76: f64,
}

impl MuRow {
    /// (μ_eq79 − μ_Jan)/μ_Jan.
    pub fn rel_diff(&self) -> f64 {
        (self.mu_eq79.0 - self.mu_jan.0) / self.mu_jan.0
    }
    /// Whether the two intervals share a point.
    pub fn overlap(&self) -> bool {
        self.mu_eq79.1 <= self.mu_jan.2 && self.mu_jan.1 <= self.mu_eq79.2
    }
}

/// One row of bulk_friction.csv: Jan's μ of a series against eq 79's μ at one fitted K, with
/// their intervals, and the paper's eq 76.
#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct MuRecord {
    series: String,
    xi: f64,
    mu_jan: f64,
    mu_jan_lo: f64,
    mu_jan_hi: f64,
    #[serde(rename = "K_source")]
    k_source: String,
    #[serde(rename = "K")]
    k: f64,
    mu_eq79: f64,
    mu_eq79_lo: f64,
    mu_eq79_hi: f64,
    rel_diff: f64,
    intervals_overlap: bool,
    alpha_deg: f64,
    #[serde(rename = "K_lo")]
    k_lo: f64,
    #[serde(rename = "K_hi")]
    k_hi: f64,
    mu_eq76: f64,
    rel_diff_eq76: f64,
    level: f64,
}

impl MuRecord {
    /// The record of `r`, whose intervals are at confidence `level`.
    fn new(r: &MuRow, level: f64) -> Self {
        MuRecord {
            series: r.series.clone(),
            xi: r.xi,
            mu_jan: r.mu_jan.0,
            mu_jan_lo: r.mu_jan.1,
            mu_jan_hi: r.mu_jan.2,
            k_source: r.k_source.clone(),
            k: r.k.0,
            mu_eq79: r.mu_eq79.0,
            mu_eq79_lo: r.mu_eq79.1,
            mu_eq79_hi: r.mu_eq79.2,
            rel_diff: r.rel_diff(),
            intervals_overlap: r.overlap(),
            alpha_deg: r.alpha.to_degrees(),
            k_lo: r.k.1,
            k_hi: r.k.2,
            mu_eq76: r.mu_eq76,
            rel_diff_eq76: (r.mu_eq79.0 - r.mu_eq76) / r.mu_eq76,
            level,
        }
    }
}

/// One row of energy.csv: a point's energy budget under a contact model at the K of its law-c
/// fit (fractions of the potential drop 2 sin α sin δ), or Jan's eq 77 ratio.
#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct EnergyRecord {
    series: String,
    xi: f64,
    delta_deg: f64,
    v: f64,
    model: String,
    #[serde(rename = "K")]
    k: Option<f64>,
    potential_drop: Option<f64>,
    collision_translation: Option<f64>,
    collision_spin: Option<f64>,
    collision: Option<f64>,
    friction: Option<f64>,
    closure: Option<f64>,
    status: &'static str,
}

/// One row of regime_map.csv: δ_m (eq 32) and δ_d (eq 31) of a law at one ξ, and the law's
/// critical ξ.
#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct RegimeMapRecord {
    law: String,
    xi: f64,
    alpha_deg: f64,
    #[serde(rename = "K")]
    k: f64,
    delta_m_deg: f64,
    delta_d_deg: f64,
    critical_xi: Option<f64>,
}

/// Δ AIC, Δ BIC and Δ WAIC of every candidate to the best of those fitted to all `n_all`
/// points, and the candidates ranked by AIC, those fitted to fewer points last.
fn rank_candidates(out: &mut [Candidate], n_all: usize) {
    let best_aic = out
        .iter()
        .filter(|c| c.n == n_all)
        .map(|c| c.aic)
        .fold(f64::INFINITY, f64::min);
    let best_bic = out
        .iter()
        .filter(|c| c.n == n_all)
        .map(|c| c.bic)
        .fold(f64::INFINITY, f64::min);
    let best_waic = out
        .iter()
        .filter(|c| c.n == n_all)
        .filter_map(|c| c.waic)
        .fold(f64::INFINITY, f64::min);
    for c in out.iter_mut() {
        c.delta_aic = c.aic - best_aic;
        c.delta_bic = c.bic - best_bic;
        c.delta_waic = c.waic.map(|w| w - best_waic);
    }
    out.sort_by(|a, b| {
        (a.n != n_all)
            .cmp(&(b.n != n_all))
            .then(a.aic.total_cmp(&b.aic))
    });
}

/// One row of the per-series model table before its criteria: series, model, n_points,
/// chi2, n_params, and whether the parameters are shared across series.
type SeriesRecord = (String, String, usize, f64, usize, bool);

impl Analysis {
    /// The bulk-friction comparison: per series with a Jan fit, per fitted K.
    pub fn mu_rows(&self) -> Vec<MuRow> {
        let mut out = Vec::new();
        for (s, label) in self.data.labels.iter().enumerate() {
            let Some(jan) = &self.jan.series[s] else {
                continue;
            };
            let Some(mu) = jan.params.iter().find(|r| r.parameter == "mu") else {
                continue;
            };
            let p0 = self.data.series(s).next().expect("a series has points");
            let (xi, alpha) = (p0.scene.xi, p0.scene.alpha);
            let (lo, hi) = interval(mu);
            let mu_jan = (mu.value, lo, hi);
            for c in &self.contact {
                let mut ks: Vec<(String, (f64, f64, f64))> = Vec::new();
                if let Some(f) = &c.free {
                    if let Some(r) = f.summary.params.iter().find(|r| r.series == *label) {
                        let (a, b) = interval(r);
                        ks.push((format!("{}-free-K", c.name), (r.value, a, b)));
                    }
                }
                if let Some(f) = &c.law_c {
                    if let Some(r) = f.summary.params.first() {
                        let (a, b) = interval(r);
                        // K rises with c (sin²α sin 2α > 0).
                        ks.push((
                            format!("{}-law-c", c.name),
                            (k_of_c(alpha, r.value), k_of_c(alpha, a), k_of_c(alpha, b)),
                        ));
                    }
                }
                for (src, k) in ks {
                    let m = [k.1, k.2].map(|kk| bulk_friction(alpha, kk));
                    out.push(MuRow {
                        series: label.clone(),
                        xi,
                        alpha,
                        mu_jan,
                        k_source: src,
                        k,
                        mu_eq79: (bulk_friction(alpha, k.0), m[0].min(m[1]), m[0].max(m[1])),
                        mu_eq76: 0.0025 * (7.46 * alpha.sin()).exp(),
                    });
                }
            }
        }
        out
    }

    /// The bulk-friction table as CSV, one [`MuRecord`] per row.
    pub fn mu_csv(&self) -> csv::Result<Vec<u8>> {
        to_csv(self.mu_rows().iter().map(|r| MuRecord::new(r, self.level)))
    }

    /// Energy budget per point: rolling and stick/slip at the K of their law-c fits, and
    /// Jan's eq 77 ratio with the series' λ. Fractions of the potential drop 2 sin α sin δ.
    pub fn energy_csv(&self) -> csv::Result<Vec<u8>> {
        let mut rows = Vec::new();
        for c in &self.contact {
            let Some(f) = &c.law_c else { continue };
            for ((p, &k), part) in c.data.points.iter().zip(&f.k).zip(&c.energy) {
                let mut r = EnergyRecord {
                    series: c.data.labels[p.series].clone(),
                    xi: p.scene.xi,
                    delta_deg: p.scene.delta_deg(),
                    v: p.v,
                    model: c.name.to_string(),
                    k: Some(k),
                    status: "not-steady",
                    ..EnergyRecord::default()
                };
                if let Some(e) = part {
                    let d = e.potential_drop;
                    r.potential_drop = Some(d);
                    r.collision_translation = Some(e.collision_translation / d);
                    r.collision_spin = Some(e.collision_spin / d);
                    r.collision = Some(e.collision_fraction());
                    r.friction = Some(e.friction_work / d);
                    r.closure = Some(e.closure());
                    r.status = "ok";
                }
                rows.push(r);
            }
        }
        for (s, p, d, ratio) in self.jan_eq77() {
            rows.push(EnergyRecord {
                series: self.data.labels[s].clone(),
                xi: p.scene.xi,
                delta_deg: p.scene.delta_deg(),
                v: p.v,
                model: "jan-eq77".into(),
                potential_drop: Some(d),
                collision: Some(ratio),
                friction: Some(1.0 - ratio),
                status: "ok",
                ..EnergyRecord::default()
            });
        }
        to_csv(rows)
    }

    /// Jan's eq 77 per point of every fitted series: (series, point, potential drop
    /// 2 sin α sin δ, collision loss / potential drop = λ v̄² / (2 sin α sin δ)).
    fn jan_eq77(&self) -> Vec<(usize, &crate::fit::data::Point, f64, f64)> {
        let mut out = Vec::new();
        for (s, fit) in self.jan.series.iter().enumerate() {
            let Some(l) = fit
                .as_ref()
                .and_then(|f| f.params.iter().find(|r| r.parameter == "lambda"))
            else {
                continue;
            };
            for p in self.data.series(s) {
                let d = 2.0 * p.scene.sin_alpha * p.scene.delta.sin();
                out.push((s, p, d, l.value * p.v * p.v / d));
            }
        }
        out
    }

    /// Per model: (name, min and max of collision loss / potential drop, min and max of the
    /// translational collision loss / potential drop; NaN for Jan).
    pub fn energy_ranges(&self) -> Vec<(String, f64, f64, f64, f64)> {
        let span = |v: &mut dyn Iterator<Item = f64>| {
            v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            })
        };
        let mut out = Vec::new();
        for c in self.contact.iter().filter(|c| c.law_c.is_some()) {
            let parts: Vec<_> = c.energy.iter().flatten().collect();
            let (c0, c1) = span(&mut parts.iter().map(|e| e.collision_fraction()));
            let (t0, t1) = span(
                &mut parts
                    .iter()
                    .map(|e| e.collision_translation / e.potential_drop),
            );
            out.push((c.name.to_string(), c0, c1, t0, t1));
        }
        let (j0, j1) = span(&mut self.jan_eq77().into_iter().map(|r| r.3));
        if j0.is_finite() {
            out.push(("jan-eq77".into(), j0, j1, f64::NAN, f64::NAN));
        }
        out
    }

    /// The laws of the regime map: name and law.
    pub(crate) fn map_laws(&self) -> Vec<(String, CollisionLaw)> {
        let mut laws = vec![
            ("cos2a".to_string(), CollisionLaw::Cos2a),
            ("paper-adjusted".to_string(), CollisionLaw::Adjusted),
            ("impact".to_string(), CollisionLaw::Impact),
        ];
        for c in &self.contact {
            if let Some(r) = c.law_c.as_ref().and_then(|f| f.summary.params.first()) {
                laws.push((
                    format!("{}-law-c (c = {:.4})", c.name, lsq(r)),
                    CollisionLaw::C(lsq(r)),
                ));
            }
        }
        laws
    }

    pub(crate) fn rho(&self) -> f64 {
        self.data.points.first().map_or(0.4, |p| p.scene.rho)
    }

    /// δ_m (eq 32) and δ_d (eq 31) against ξ (and α) for the reference and fitted laws, and
    /// the critical ξ of each law.
    pub fn regime_map_csv(&self) -> csv::Result<Vec<u8>> {
        let rho = self.rho();
        let mut rows = Vec::new();
        for (name, law) in self.map_laws() {
            let crit = critical_xi(law, rho);
            for i in 0..=80 {
                let xi = 0.5 * 40f64.powf(i as f64 / 80.0);
                let a = crate::models::regimes::alpha_of_xi(xi);
                rows.push(RegimeMapRecord {
                    law: name.clone(),
                    xi,
                    alpha_deg: a.to_degrees(),
                    k: law.k(a, rho),
                    delta_m_deg: delta_m_law(a, law, rho).to_degrees(),
                    delta_d_deg: delta_d_law(a, law, rho).to_degrees(),
                    critical_xi: crit,
                });
            }
        }
        to_csv(rows)
    }

    /// The regime each contact model (at its law-c fit) assigns to every data point.
    pub fn point_regimes(&self) -> Vec<Vec<String>> {
        self.contact
            .iter()
            .map(|c| {
                let cval = c
                    .law_c
                    .as_ref()
                    .and_then(|f| f.summary.params.first())
                    .map(lsq);
                self.data
                    .points
                    .par_iter()
                    .map(|p| {
                        let Some(cv) = cval else {
                            return "no-fit".to_string();
                        };
                        let k = k_of_c(p.scene.alpha, cv);
                        match p.scene.with_k(k) {
                            Ok(sc) => match Regime::of(&c.model.evaluate(&sc)) {
                                Some(Regime::A) => "A".into(),
                                Some(Regime::B) => "B".into(),
                                Some(Regime::C) => "C".into(),
                                None => "invalid".into(),
                            },
                            Err(_) => "invalid".into(),
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// Points with the regime each model assigns them.
    pub fn points_csv(&self) -> csv::Result<Vec<u8>> {
        let reg = self.point_regimes();
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut h = vec![
            "series".to_string(),
            "xi".into(),
            "alpha_deg".into(),
            "delta_deg".into(),
            "v".into(),
            "sigma_v".into(),
        ];
        for c in &self.contact {
            h.push(format!("regime_{}", c.name));
        }
        w.write_record(&h)?;
        for (i, p) in self.data.points.iter().enumerate() {
            let mut r = vec![
                self.data.labels[p.series].clone(),
                fmt_f64(p.scene.xi),
                fmt_f64(p.scene.alpha.to_degrees()),
                fmt_f64(p.scene.delta_deg()),
                fmt_f64(p.v),
                if self.data.sigma == SigmaKind::Absolute {
                    fmt_f64(p.sigma)
                } else {
                    String::new()
                },
            ];
            for rg in &reg {
                r.push(rg[i].clone());
            }
            w.write_record(&r)?;
        }
        w.into_inner().map_err(|e| e.into_error().into())
    }

    /// The model-choice table: every candidate with χ², parameters, AIC, BIC, Δ to the best,
    /// and rank by AIC.
    pub fn candidates(&self) -> Vec<Candidate> {
        let n_all = self.data.points.len();
        let mut out = self.contact_candidates(n_all);
        let sum_fits = |fits: Vec<&FitResult>, k_each: usize| {
            let chi2: f64 = fits.iter().map(|f| f.stats.chi2).sum();
            let n: usize = fits.iter().map(|f| f.stats.n_points).sum();
            (chi2, k_each * fits.len(), n)
        };
        let jan_series: Vec<&FitResult> = self.jan.series.iter().flatten().collect();
        if !jan_series.is_empty() {
            let w = waic_sum(jan_series.iter().copied());
            let (chi2, k, n) = sum_fits(jan_series, 2);
            let note = if n < n_all {
                format!("{n} of {n_all} points (series with < 3 points not fitted)")
            } else {
                String::new()
            };
            let mut cand = Candidate::new(
                "jan lambda, mu per series".into(),
                k,
                n,
                chi2,
                self.data.sigma,
                note,
            );
            cand.waic = w;
            out.push(cand);
        }
        if let Some(g) = &self.jan.global {
            let mut cand = Candidate::new(
                "jan global laws (eqs 75-76 form)".into(),
                4,
                g.stats.n_points,
                g.stats.chi2,
                self.data.sigma,
                String::new(),
            );
            cand.waic = waic_sum([g]);
            out.push(cand);
        }
        let jaeger: Vec<&FitResult> = self
            .jaeger
            .series
            .iter()
            .flatten()
            .map(|f| &f.summary)
            .collect();
        if !jaeger.is_empty() {
            let w = waic_sum(jaeger.iter().copied());
            let (chi2, k, n) = sum_fits(jaeger, 3);
            let note = if n < n_all {
                format!("{n} of {n_all} points (series with < 4 points not fitted)")
            } else {
                String::new()
            };
            let mut cand = Candidate::new(
                "jaeger a1, a2, a3 per series".into(),
                k,
                n,
                chi2,
                self.data.sigma,
                note,
            );
            cand.waic = w;
            out.push(cand);
        }
        rank_candidates(&mut out, n_all);
        out
    }

    /// The model-choice candidates of the contact models: K = cos 2α and K = impact (nothing
    /// fitted), law c and free K per series, each on the points its model keeps of `n_all`.
    fn contact_candidates(&self, n_all: usize) -> Vec<Candidate> {
        let mut out = Vec::new();
        for c in &self.contact {
            let n = c.data.points.len();
            let note = if n < n_all {
                format!("{} of {n_all} points (the others cannot be steady)", n)
            } else {
                String::new()
            };
            let mcmc = self.mcmc;
            let sigma = self.data.sigma;
            let mut push = |name: String, k: usize, chi2: f64, extra: String, waic: Option<f64>| {
                let mut cand = Candidate::new(name, k, n, chi2, sigma, {
                    [note.clone(), extra]
                        .into_iter()
                        .filter(|s| !s.is_empty())
                        .collect::<Vec<_>>()
                        .join("; ")
                });
                // A law with nothing fitted has no posterior spread: WAIC = χ² (σ given).
                cand.waic = if k == 0 {
                    (mcmc && sigma == SigmaKind::Absolute).then_some(chi2)
                } else {
                    waic
                };
                out.push(cand)
            };
            let unsteady = |u: usize| {
                if u > 0 {
                    format!("{u} point(s) not steady under this law")
                } else {
                    String::new()
                }
            };
            push(
                format!("{} K=cos2a", c.name),
                0,
                c.cos2a_chi2.0,
                unsteady(c.cos2a_chi2.1),
                None,
            );
            push(
                format!("{} K=impact", c.name),
                0,
                c.impact_chi2.0,
                unsteady(c.impact_chi2.1),
                None,
            );
            if let Some(f) = &c.law_c {
                push(
                    format!("{} law c", c.name),
                    1,
                    f.summary.stats.chi2,
                    String::new(),
                    waic_sum([&f.summary]),
                );
            }
            if let Some(f) = &c.free {
                push(
                    format!("{} free K per series", c.name),
                    f.summary.stats.n_params,
                    f.summary.stats.chi2,
                    String::new(),
                    waic_sum([&f.summary]),
                );
            }
        }
        out
    }

    /// χ² and points per series of every contact-model candidate (K = cos 2α, K = impact,
    /// law c, free K per series), by candidate name; ∞ where a point of the series has no
    /// steady state under the candidate.
    fn contact_chi2_by_series(&self) -> Vec<(String, Vec<(usize, f64)>)> {
        let mut rows: Vec<(String, Vec<(usize, f64)>)> = Vec::new();
        let per_point = |c: &ContactFits, k: &(dyn Fn(usize) -> f64 + Sync)| -> Vec<(usize, f64)> {
            let r: Vec<(usize, f64)> = c
                .data
                .points
                .par_iter()
                .enumerate()
                .map(|(i, p)| {
                    let v = p
                        .scene
                        .with_k(k(i))
                        .ok()
                        .and_then(|sc| c.model.evaluate(&sc).ok())
                        .map_or(f64::INFINITY, |st| {
                            ((p.v - st.mean_velocity) / p.sigma).powi(2)
                        });
                    (p.series, v)
                })
                .collect();
            let mut acc = vec![(0usize, 0.0); c.data.labels.len()];
            for (s, v) in r {
                acc[s].0 += 1;
                acc[s].1 += v;
            }
            acc
        };
        for c in &self.contact {
            let pts = &c.data.points;
            let rho = |i: usize| pts[i].scene.rho;
            let alpha = |i: usize| pts[i].scene.alpha;
            rows.push((
                format!("{} K=cos2a", c.name),
                per_point(c, &|i| k_of_c(alpha(i), 0.0)),
            ));
            rows.push((
                format!("{} K=impact", c.name),
                per_point(c, &|i| CollisionLaw::Impact.k(alpha(i), rho(i))),
            ));
            if let Some(f) = &c.law_c {
                rows.push((format!("{} law c", c.name), per_point(c, &|i| f.k[i])));
            }
            if let Some(f) = &c.free {
                rows.push((
                    format!("{} free K per series", c.name),
                    per_point(c, &|i| f.k[i]),
                ));
            }
        }
        rows
    }

    /// The records of [`Analysis::models_by_series_csv`], every candidate per series.
    fn series_records(&self) -> Vec<SeriesRecord> {
        let ns = self.data.labels.len();
        let rows = self.contact_chi2_by_series();
        // Series labels of a contact model's subset map back to the full data by name.
        // (series, model, n_points, chi2, n_params, shared)
        let mut recs: Vec<SeriesRecord> = Vec::new();
        for c in &self.contact {
            for (name, acc) in rows.iter().filter(|r| r.0.starts_with(c.name)) {
                let (k, shared) = if name.ends_with("law c") {
                    (1, true)
                } else if name.ends_with("free K per series") {
                    (1, false)
                } else {
                    (0, false)
                };
                for (j, (n, chi2)) in acc.iter().enumerate() {
                    recs.push((c.data.labels[j].clone(), name.clone(), *n, *chi2, k, shared));
                }
            }
        }
        for s in 0..ns {
            let label = &self.data.labels[s];
            if let Some(f) = &self.jan.series[s] {
                recs.push((
                    label.clone(),
                    "jan lambda, mu per series".into(),
                    f.stats.n_points,
                    f.stats.chi2,
                    2,
                    false,
                ));
            }
            if let Some(g) = &self.jan.global {
                let p: Vec<f64> = g.params.iter().take(4).map(lsq).collect();
                let (mut n, mut chi2) = (0usize, 0.0);
                for q in self.data.series(s) {
                    let x = (q.scene.sin_alpha, q.scene.delta.sin(), q.scene.delta.cos());
                    n += 1;
                    chi2 += crate::fit::jan::JanGlobal
                        .value(&x, &p)
                        .map_or(f64::INFINITY, |v| ((q.v - v) / q.sigma).powi(2));
                }
                recs.push((
                    label.clone(),
                    "jan global laws (eqs 75-76 form)".into(),
                    n,
                    chi2,
                    4,
                    true,
                ));
            }
            if let Some(f) = &self.jaeger.series[s] {
                recs.push((
                    label.clone(),
                    "jaeger a1, a2, a3 per series".into(),
                    f.summary.stats.n_points,
                    f.summary.stats.chi2,
                    3,
                    false,
                ));
            }
        }
        recs
    }

    /// χ², AIC and BIC per series of every candidate (at the least-squares optimum; ∞ where a
    /// point of the series has no steady state under the candidate), as CSV: series, model,
    /// n_points, chi2, then n_params (the parameters the series' fit uses), shared_params (yes
    /// when they are fitted across all series, as law c and Jan's global laws: the per-series
    /// AIC then charges each series the whole shared count, a conservative convention), aic,
    /// bic, delta_aic, delta_bic and rank (by AIC) within the series.
    pub fn models_by_series_csv(&self) -> csv::Result<Vec<u8>> {
        let recs = self.series_records();
        let cands: Vec<Candidate> = recs
            .iter()
            .map(|r| Candidate::new(r.1.clone(), r.4, r.2, r.3, self.data.sigma, String::new()))
            .collect();
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record([
            "series",
            "model",
            "n_points",
            "chi2",
            "n_params",
            "shared_params",
            "aic",
            "bic",
            "delta_aic",
            "delta_bic",
            "rank",
        ])?;
        for (r, c) in recs.iter().zip(&cands) {
            let same: Vec<&Candidate> = recs
                .iter()
                .zip(&cands)
                .filter(|(q, _)| q.0 == r.0)
                .map(|(_, c)| c)
                .collect();
            let best_aic = same.iter().map(|c| c.aic).fold(f64::INFINITY, f64::min);
            let best_bic = same.iter().map(|c| c.bic).fold(f64::INFINITY, f64::min);
            let rank = 1 + same.iter().filter(|o| o.aic < c.aic).count();
            let delta = |x: f64, best: f64| {
                if x.is_finite() && best.is_finite() {
                    num(x - best)
                } else {
                    num(f64::INFINITY)
                }
            };
            w.write_record([
                r.0.clone(),
                r.1.clone(),
                r.2.to_string(),
                num(r.3),
                r.4.to_string(),
                if r.5 { "yes" } else { "no" }.to_string(),
                num(c.aic),
                num(c.bic),
                delta(c.aic, best_aic),
                delta(c.bic, best_bic),
                rank.to_string(),
            ])?;
        }
        w.into_inner().map_err(|e| e.into_error().into())
    }

    /// The model-choice table as CSV.
    pub fn models_csv(&self) -> csv::Result<Vec<u8>> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record([
            "rank",
            "model",
            "n_params",
            "n_points",
            "chi2",
            "aic",
            "bic",
            "delta_aic",
            "delta_bic",
            "note",
            "waic",
            "delta_waic",
        ])?;
        for (i, c) in self.candidates().iter().enumerate() {
            w.write_record([
                (i + 1).to_string(),
                c.name.clone(),
                c.k.to_string(),
                c.n.to_string(),
                num(c.chi2),
                num(c.aic),
                num(c.bic),
                num(c.delta_aic),
                num(c.delta_bic),
                c.note.clone(),
                c.waic.map(num).unwrap_or_default(),
                c.delta_waic.map(num).unwrap_or_default(),
            ])?;
        }
        w.into_inner().map_err(|e| e.into_error().into())
    }

    /// Sentences on which extra parameters the data support (ΔAIC and ΔBIC both beyond
    /// `SUPPORT_THRESHOLD`).
    pub fn support_statements(&self) -> Vec<String> {
        let cands = self.candidates();
        let get = |name: &str| cands.iter().find(|c| c.name == name);
        let mut out = Vec::new();
        let mut compare = |simple: &str, rich: &str, what: &str| {
            if let (Some(a), Some(b)) = (get(simple), get(rich)) {
                if a.n != b.n || !b.aic.is_finite() {
                    return;
                }
                if !a.aic.is_finite() {
                    out.push(format!(
                        "{what}: required — `{simple}` cannot make every point steady ({}), `{rich}` can.",
                        a.note
                    ));
                    return;
                }
                let (da, db) = (a.aic - b.aic, a.bic - b.bic);
                let verdict = if da > SUPPORT_THRESHOLD && db > SUPPORT_THRESHOLD {
                    "supported"
                } else if da < -SUPPORT_THRESHOLD && db < -SUPPORT_THRESHOLD {
                    "not supported (the simpler model is better)"
                } else {
                    "not clearly supported"
                };
                out.push(format!(
                    "{what}: {verdict} — `{rich}` ({}) against `{simple}` ({}): AIC {}, BIC {}.",
                    parameter_count(b.k),
                    parameter_count(a.k),
                    lower_by(da),
                    lower_by(db)
                ));
            }
        };
        for c in CONTACT.map(|c| c.1) {
            compare(
                &format!("{c} K=cos2a"),
                &format!("{c} law c"),
                &format!("{c}: the coefficient c of the K(α) law"),
            );
            compare(
                &format!("{c} law c"),
                &format!("{c} free K per series"),
                &format!("{c}: one K per series instead of the law"),
            );
        }
        compare(
            "jan global laws (eqs 75-76 form)",
            "jan lambda, mu per series",
            "Jan: λ and μ per series instead of the global laws",
        );
        compare(
            "rolling law c",
            "stickslip law c",
            "stick/slip instead of rolling (same single parameter c; f given)",
        );
        out
    }

    /// Posterior blocks for the corner plot (MCMC only).
    pub fn posteriors(&self) -> Vec<&FitResult> {
        self.each_fit()
            .into_iter()
            .map(|(_, f)| f)
            .filter(|s| s.draws.is_some())
            .collect()
    }

    /// The parameter rows of every fit (the `--output` format of the fit commands).
    pub fn params(&self) -> Vec<ParamRow> {
        let mut v = Vec::new();
        for c in &self.contact {
            for f in c.law_c.iter().chain(c.free.iter()) {
                for r in &f.summary.params {
                    let mut r = r.clone();
                    r.fit = format!("{}-{}", c.name, r.fit);
                    v.push(r);
                }
            }
        }
        for s in self
            .jan
            .series
            .iter()
            .flatten()
            .chain(self.jan.global.iter())
        {
            v.extend(s.params.iter().cloned());
        }
        for f in self.jaeger.series.iter().flatten() {
            v.extend(f.summary.params.iter().cloned());
        }
        v
    }
}

/// One candidate model of the ranking.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// Name.
    pub name: String,
    /// Fitted parameters.
    pub k: usize,
    /// Points.
    pub n: usize,
    /// χ² at the least-squares optimum.
    pub chi2: f64,
    /// AIC.
    pub aic: f64,
    /// BIC.
    pub bic: f64,
    /// AIC minus the best AIC among candidates on all points.
    pub delta_aic: f64,
    /// BIC minus the best BIC.
    pub delta_bic: f64,
    /// WAIC (posterior runs only; the sum over the fits of a per-series model; χ² for a
    /// parameter-free law with σ given).
    pub waic: Option<f64>,
    /// WAIC minus the best WAIC.
    pub delta_waic: Option<f64>,
    /// Remarks.
    pub note: String,
}

impl Candidate {
    /// AIC and BIC with the conventions of the fits ([`crate::inverse::Fit::aic`]): with σ
    /// given, −2 ln L = χ² up to a constant, AIC = χ² + 2k, BIC = χ² + k ln n; with unit
    /// weights the scale is one more parameter, −2 ln L = n (ln(2π χ²/n) + 1).
    fn new(name: String, k: usize, n: usize, chi2: f64, sigma: SigmaKind, note: String) -> Self {
        let nf = n as f64;
        let (m2ll, keff) = match sigma {
            SigmaKind::Absolute => (chi2, k as f64),
            SigmaKind::Relative => (
                nf * ((2.0 * std::f64::consts::PI * chi2 / nf).ln() + 1.0),
                k as f64 + 1.0,
            ),
        };
        let (aic, bic) = if chi2.is_finite() {
            (m2ll + 2.0 * keff, m2ll + keff * nf.ln())
        } else {
            (f64::INFINITY, f64::INFINITY)
        };
        Candidate {
            name,
            k,
            n,
            chi2,
            aic,
            bic,
            delta_aic: f64::NAN,
            delta_bic: f64::NAN,
            waic: None,
            delta_waic: None,
            note,
        }
    }
}

/// The summed WAIC of posterior fits, if every one has it.
fn waic_sum<'a>(fits: impl IntoIterator<Item = &'a FitResult>) -> Option<f64> {
    let mut total = 0.0;
    let mut any = false;
    for f in fits {
        total += f.stats.mcmc.as_ref()?.waic?.0;
        any = true;
    }
    any.then_some(total)
}

/// Three significant digits (report tables and messages).
pub(crate) fn sig3(x: f64) -> String {
    crate::numfmt::fmt_sig(x, 3)
}

/// "1 parameter", "2 parameters".
fn parameter_count(k: usize) -> String {
    format!("{k} parameter{}", if k == 1 { "" } else { "s" })
}

/// A criterion's difference (simpler minus richer) as "lower by d" or "higher by |d|".
fn lower_by(d: f64) -> String {
    if d < 0.0 {
        format!("higher by {}", sig3(-d))
    } else {
        format!("lower by {}", sig3(d))
    }
}
