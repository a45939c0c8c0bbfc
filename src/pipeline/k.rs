//! Measurements in, K out: `fitbead k`'s rows as a `KPlan` that
//! `crate::io::stream::stream` runs over a table of any size. Each row is read and checked as
//! [`crate::io::measurements`] reads a whole file (the series check in input order, keeping one
//! entry per series), inverted (eq 69: [`crate::fit::k::estimate()`]) and written as one
//! record of `COLUMNS`, `EXTRA_COLUMNS`, `AUTO_COLUMNS` (auto only), then the input's
//! other columns (trimmed; a name clashing with an output column renamed `in_NAME`).

use crate::fit::k::auto::{self as kauto, KChoice};
use crate::fit::k::slope::estimate_with_slope;
use crate::fit::k::KEstimate;
use crate::io::cells::{Cells, Repeat};
use crate::io::measurements::{
    Implausible, Measured, MeasurementColumns, MeasurementDefaults, Plausibility, PlausiblePoint,
    SeriesLedger, StopSlopes,
};
use crate::io::records::{columns, AutoRecord, KRecord, SigmaKRecord};
use crate::io::scenes::{Header, Row};
use crate::io::stream::RowPlan;
use crate::io::InputError;
use crate::last::Last;
use crate::models::auto::Auto;
use crate::models::Model;
use crate::numfmt::fmt_f64;
use crate::report::figures::{scatter_svg, PointSeries, Scatter};
use crate::scene::{CollisionLaw, Scene};
use serde::Serialize;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The measurement's own columns, first in a K row: series, ξ, δ (as written), v, σ and the
/// model's name.
#[derive(Debug, Clone, Default, Serialize)]
struct KInput<'a> {
    series: &'a str,
    xi: f64,
    delta_deg: &'a str,
    v: f64,
    sigma_v: Option<f64>,
    model: &'a str,
}

/// The columns of a K row in order, generated from the records: the measurement's own
/// (`KInput`), [`KRecord`]'s, [`SigmaKRecord`]'s when rows carry slope errors (`slopes`), and
/// [`AutoRecord`]'s when `auto`; the input's other columns follow them.
pub(crate) fn output_columns(auto: bool, slopes: bool) -> Vec<&'static str> {
    let mut v = columns::<KInput>();
    v.extend(columns::<KRecord>());
    if slopes {
        v.extend(columns::<SigmaKRecord>());
    }
    if auto {
        v.extend(columns::<AutoRecord>());
    }
    v
}

/// Rows per chunk of a K stream ([`crate::io::stream::StreamOptions::chunk_rows`]), a quarter of
/// the engine's [`crate::io::stream::CHUNK_ROWS`]: what `fitbead k` writes to a stream before a
/// bad row is whole chunks of this many rows (the memory the stream uses does not depend on
/// it).
pub(crate) const CHUNK_ROWS: usize = 8 * 1024;

/// Input columns that have their own output column.
const INPUT_OWN: [&str; 5] = ["series", "xi", "delta_deg", "v", "sigma_v"];

/// How to invert the rows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct KSettings {
    /// The model every row is inverted with (ignored with `auto`).
    pub model: Model,
    /// Per row the model chosen at the row's stick K (eq 69 under stick first).
    pub auto: Option<Auto>,
    /// The text of the `model` column.
    pub model_name: String,
    /// Keep each inverted row's point (final velocity, K and its interval, per series) for
    /// [`KLedger::plot_svg`]; memory then grows with the rows.
    pub plot: bool,
}

/// What a stream of K rows keeps across rows: one entry per series for the ξ check, and the
/// points of the plot when [`KSettings::plot`] asks for them.
#[derive(Debug, Clone, Default)]
pub(crate) struct KLedger {
    series: SeriesLedger,
    plausibility: Option<Plausibility>,
    labels: HashMap<String, usize>,
    plot: Vec<PointSeries>,
}

/// What consecutive rows of one task share when they have the same ξ and ρ (rows of a
/// series usually follow each other): the three named laws' K, the text of ξ and of those K,
/// and the last scene read (whose quantities of ξ alone the next row of the same ξ reuses).
#[derive(Debug, Clone)]
pub(crate) struct KScratch {
    scene: Option<Scene>,
    /// K of cos 2α, the adjusted law and the impact law, for the last (ξ, ρ).
    laws: Last<(u64, u64), [f64; 3]>,
    /// The text of ξ.
    input: Repeat,
    /// The text of the three laws' K.
    record: Repeat,
    /// The plausibility checks' slope limits of the last ξ and ρ.
    slopes: StopSlopes,
}

impl Default for KScratch {
    fn default() -> Self {
        KScratch {
            scene: None,
            laws: Last::default(),
            input: Repeat::new::<KInput>(&["xi"]),
            record: Repeat::new::<KRecord>(&["K_cos2a", "K_adjusted", "K_impact"]),
            slopes: StopSlopes::default(),
        }
    }
}

impl KScratch {
    /// K of cos 2α, the adjusted law and the impact law at `s`'s ξ and ρ.
    fn laws(&mut self, s: &Scene) -> [f64; 3] {
        let (alpha, rho) = (s.alpha_rad(), s.rho());
        *self
            .laws
            .get((s.xi().to_bits(), s.rho().to_bits()), |laws| {
                *laws = [
                    CollisionLaw::Cos2a,
                    CollisionLaw::Adjusted,
                    CollisionLaw::Impact,
                ]
                .map(|l| l.k(alpha, rho));
            })
    }
}

/// What a written row hands on, in input order: what the series and plausibility checks need
/// of it, and its point on the plot.
#[derive(Debug, Clone, Copy)]
pub(crate) struct KNote {
    point: PlausiblePoint,
    plot: Option<PlotNote>,
}

/// A row's point on the plot: final velocity, K, K_lo, K_hi, and K = cos 2α at its ξ.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlotNote {
    point: (f64, f64, f64, f64),
    cos2a: f64,
}

impl KLedger {
    /// A ledger that also looks for unit mistakes ([`Plausibility`]) in a table with
    /// `header`.
    pub fn checking(header: &impl Header) -> Self {
        KLedger {
            plausibility: Some(Plausibility::new(header)),
            ..KLedger::default()
        }
    }

    /// The unit-mistake warnings of the rows so far (none unless made by
    /// [`KLedger::checking`]).
    pub fn warnings(&self) -> Vec<Implausible> {
        self.plausibility
            .as_ref()
            .map(Plausibility::warnings)
            .unwrap_or_default()
    }

    /// K against the steady final velocity, one colour per series (series label, or ξ where
    /// there is none), with each series' K = cos 2α line (the paper's Fig. 5), as SVG.
    pub fn plot_svg(
        &self,
        model_name: &str,
    ) -> Result<String, crate::report::figures::FigureError> {
        scatter_svg(&Scatter {
            title: format!("K per measurement (eq 69), {model_name} model"),
            x_label: "steady final velocity v_{f} / √(g(R + r))".into(),
            y_label: "K".into(),
            series: self.plot.clone(),
        })
    }
}

/// `fitbead k`'s rows as a [`RowPlan`] (module docs).
#[derive(Debug, Clone)]
pub(crate) struct KPlan {
    settings: KSettings,
    cols: MeasurementColumns,
    headers: Vec<String>,
    /// Input columns passed through, in order.
    pass: Vec<usize>,
    /// The plausibility checks have the velocity ratios they take: the rows need not compute
    /// the rolling model's v̄ for them (raised in input order by [`RowPlan::record`]; a row
    /// that computes it before it sees the flag only spends the time).
    ratios_full: Arc<AtomicBool>,
}

impl KPlan {
    /// The plan for a table with `header`, checking its columns and `defaults` as
    /// [`MeasurementColumns::new`] does.
    pub fn new(
        header: &impl Header,
        defaults: &MeasurementDefaults,
        settings: KSettings,
    ) -> Result<Self, InputError> {
        let cols = MeasurementColumns::new(header, defaults)?;
        let headers = header.headers().to_vec();
        let pass = (0..headers.len())
            .filter(|&i| !INPUT_OWN.iter().any(|n| header.col(n) == Some(i)))
            .collect();
        Ok(KPlan {
            settings,
            cols,
            headers,
            pass,
            ratios_full: Arc::default(),
        })
    }

    fn own_columns(&self) -> impl Iterator<Item = &'static str> + '_ {
        output_columns(self.settings.auto.is_some(), self.cols.has_slope_errors()).into_iter()
    }

    /// Inverts one measurement with the settings' model, or the one auto chooses for it,
    /// with σ_K where rows carry slope errors ([`crate::fit::k::slope`]).
    pub fn invert(&self, m: &Measured) -> (KEstimate, Option<KChoice>, Option<f64>) {
        if self.cols.has_slope_errors() {
            return estimate_with_slope(
                &self.settings.model,
                self.settings.auto.as_ref(),
                &m.scene,
                m.v,
                m.sigma_v,
                m.sigma_delta,
            );
        }
        let (e, choice) = kauto::estimate_with(
            &self.settings.model,
            self.settings.auto.as_ref(),
            &m.scene,
            m.v,
            m.sigma_v,
        );
        (e, choice, None)
    }
}

impl RowPlan for KPlan {
    type Ready = Measured;
    type Ledger = KLedger;
    type Note = KNote;
    type Scratch = KScratch;

    fn header(&self, out: &mut Vec<u8>) {
        let mut w = Cells::new(out);
        for c in self.own_columns() {
            w.text(c);
        }
        let own: Vec<&str> = self.own_columns().collect();
        let pass = self.pass.iter().map(|&i| self.headers[i].as_str());
        for name in crate::io::pass_through_names(pass, &own) {
            w.text(&name);
        }
        w.end();
    }

    fn prepare(&self, row: &Row<'_>, cache: &mut KScratch) -> Result<Measured, InputError> {
        let m = self.cols.read_like(row, cache.scene.as_ref())?;
        cache.scene = Some(m.scene);
        Ok(m)
    }

    fn write(&self, row: &Row<'_>, m: Measured, cache: &mut KScratch, out: &mut Vec<u8>) -> KNote {
        let (e, choice, sigma_k) = self.invert(&m);
        let s = &m.scene;
        let laws = cache.laws(s);
        let mut w = Cells::new(out);
        w.record_repeating(
            &KInput {
                series: self.cols.series(row),
                xi: s.xi(),
                delta_deg: row.cell(self.cols.delta_deg()),
                v: m.v,
                sigma_v: m.sigma_v,
                model: &self.settings.model_name,
            },
            &mut cache.input,
        );
        w.record_repeating(&KRecord::new(&e, laws), &mut cache.record);
        if self.cols.has_slope_errors() {
            w.record(&SigmaKRecord { sigma_k });
        }
        if self.settings.auto.is_some() {
            w.record(&choice.map(AutoRecord::of_choice).unwrap_or_default());
        }
        for &c in &self.pass {
            w.text(row.cell(c));
        }
        w.end();
        let root = e.root.as_ref().ok();
        let plot = match (self.settings.plot, root) {
            (true, Some(r)) => Some(PlotNote {
                point: (
                    r.steady.final_velocity,
                    r.k,
                    e.k_lo.unwrap_or(r.k),
                    e.k_hi.unwrap_or(r.k),
                ),
                cos2a: laws[0],
            }),
            _ => None,
        };
        KNote {
            point: PlausiblePoint::new(
                &m,
                &mut cache.slopes,
                !self.ratios_full.load(Ordering::Relaxed),
            ),
            plot,
        }
    }

    fn record(&self, ledger: &mut KLedger, row: &Row<'_>, note: KNote) -> Result<(), InputError> {
        self.cols
            .check_series(&mut ledger.series, row, note.point.xi)?;
        if let Some(p) = &mut ledger.plausibility {
            p.add_point(row, &note.point);
            if p.has_all_ratios() {
                self.ratios_full.store(true, Ordering::Relaxed);
            }
        }
        let Some(n) = note.plot else { return Ok(()) };
        let series = self.cols.series(row);
        let label = if series.is_empty() {
            // The row passed its checks: its ξ reads back as a number.
            let xi = row.number(self.cols.xi()).unwrap_or(f64::NAN);
            format!("ξ = {}", fmt_f64(xi))
        } else {
            format!("series {series}")
        };
        let i = match ledger.labels.get(&label) {
            Some(&i) => i,
            None => {
                ledger.plot.push(PointSeries {
                    label: label.clone(),
                    points: Vec::new(),
                    reference: Some((n.cos2a, format!("K = cos 2α = {:.4}", n.cos2a))),
                });
                ledger.labels.insert(label, ledger.plot.len() - 1);
                ledger.plot.len() - 1
            }
        };
        ledger.plot[i].points.push(n.point);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::output_columns;

    /// The output columns of `k` as the documentation gives them (docs/GUIDE.md): a contract
    /// users' scripts read, here checked against the columns generated from the records.
    #[test]
    fn k_columns_are_the_documented_contract() {
        let auto = ["model_used", "reason"];
        let k = [
            "series",
            "xi",
            "delta_deg",
            "v",
            "sigma_v",
            "model",
            "K",
            "K_lo",
            "K_hi",
            "dv_dK",
            "final_velocity",
            "theta_G_deg",
            "K_cos2a",
            "K_adjusted",
            "K_impact",
            "regime",
            "status",
            "iterations",
            "K_min",
            "K_max",
            "lower_limit",
            "upper_limit",
            "message",
        ];
        assert_eq!(output_columns(false, false), k);
        assert_eq!(output_columns(true, false), [&k[..], &auto].concat());
        assert_eq!(
            output_columns(true, true),
            [&k[..], &["sigma_K"], &auto].concat()
        );
    }
}
