//! The figures of `fitbead report`, drawn from an [`Analysis`] with the figure engine
//! ([`super::figures`]): velocity, Jan's linearised plot, K per point against the final
//! velocity and against α, the regime map, Jaeger's plane, the energy partition, the
//! residuals and one corner plot per posterior.

use super::analysis::{k_of_c, lsq, Analysis};
use super::bands::{lsq_band, Curve, PosteriorBands};
use super::figures::corner::{corner_figure, CornerBlock};
use super::figures::{
    coincide, scatter_panel, series_style, Anchor, Axis, Figure, Item, LegendEntry, Mark, Panel,
    PointSeries, Scatter, Stroke, DASHES, PALETTE,
};
use super::figures::{ErrPoint, FigureError};
use crate::design::{DesignResult, DesignSettings};
use crate::fit::data::Dataset;
use crate::fit::jaeger::{paper_values, JaegerModel};
use crate::fit::jan::velocity as jan_velocity;
use crate::fit::k::estimate;
use crate::fit::summary::FitResult;
use crate::inverse::{CurveModel as _, SigmaKind};
use crate::models::regimes::{
    alpha_of_xi, critical_xi, delta_d_law, delta_m_law, regime_b_interval,
};
use crate::models::{ForwardModel, JaegerBranch, Model};
use crate::numfmt::{fmt_f64, fmt_sig};
use crate::scene::CollisionLaw;
use rayon::prelude::*;

/// K per point for the figures: (final velocity, α in degrees, K, K_lo, K_hi).
type KPoint = (f64, f64, f64, f64, f64);

/// v̄ in its units.
const V_LABEL: &str = "mean velocity v\u{304} / √(g(R + r))";
/// δ in degrees.
const DELTA_LABEL: &str = "slope δ (°)";
/// Size of one panel's plot area in a grid of panels, px.
const GRID_PLOT: (f64, f64) = (430.0, 300.0);
/// Size of a single panel's plot area, px.
const SINGLE_PLOT: (f64, f64) = (720.0, 470.0);
/// Colour of the data where models take the palette.
const DATA: &str = "#000000";
/// Spacing in α (degrees) of a series' points on the K(α) figure.
const SPREAD: f64 = 0.2;
/// Light grey of reference curves.
const REFERENCE: &str = "#7f7f7f";

/// A number for a label: four significant digits, true minus sign.
fn g4(x: f64) -> String {
    fmt_sig(x, 4).replace('-', "\u{2212}")
}

/// The fits behind [`VELOCITY_MODELS`], named as in params.csv (their posterior bands).
const VELOCITY_FITS: [&str; 4] = ["rolling-klaw-c", "stickslip-klaw-c", "jan-series", "jaeger"];

/// The models of the velocity figure, in drawing order: name in the legend and colour.
const VELOCITY_MODELS: [(&str, &str); 4] = [
    ("rolling, law c", PALETTE[0]),
    ("stick/slip, law c", PALETTE[1]),
    ("Jan (eq 74)", PALETTE[2]),
    ("Jaeger (eqs 83–84)", PALETTE[3]),
];

impl Analysis {
    /// `f` as an SVG document at the report's print width ([`Analysis::print_width_mm`]).
    fn render(&self, mut f: Figure) -> String {
        f.print_width_mm = self.print_width_mm;
        f.to_svg()
    }

    /// "ξ = 0.8" for a series whose label is its ξ, else "series L (ξ = …)", a label over 24
    /// characters cut to its first 23 and `…` so that the title fits its panel.
    fn series_title(&self, s: usize) -> String {
        let label = &self.data.labels[s];
        let xi = self.data.series(s).next().map_or(f64::NAN, |p| p.scene.xi);
        if label.parse::<f64>().ok() == Some(xi) {
            format!("ξ = {label}")
        } else if label.chars().count() > 24 {
            let short: String = label.chars().take(23).collect();
            format!("series {short}… (ξ = {})", g4(xi))
        } else {
            format!("series {label} (ξ = {})", g4(xi))
        }
    }

    /// One legend entry per series in its [`series_style`], its title followed by `suffix`.
    fn series_legend(&self, suffix: &str) -> Vec<LegendEntry> {
        (0..self.data.labels.len())
            .map(|s| {
                let (c, m) = series_style(s);
                LegendEntry::mark(&format!("{}{suffix}", self.series_title(s)), m, c)
            })
            .collect()
    }

    /// Series `s`'s points as (x, y, y ∓ σ) through `f`, which maps (point, v) to (x, y);
    /// the bar is σ mapped the same way (none without absolute σ).
    fn series_points(
        &self,
        s: usize,
        f: impl Fn(&crate::fit::data::Point, f64) -> (f64, f64),
    ) -> Vec<(f64, f64, f64, f64)> {
        self.data
            .series(s)
            .map(|p| {
                let (x, y) = f(p, p.v);
                if self.data.sigma == SigmaKind::Absolute {
                    let lo = f(p, p.v - p.sigma).1;
                    let hi = f(p, p.v + p.sigma).1;
                    (x, y, lo.min(hi), lo.max(hi))
                } else {
                    (x, y, y, y)
                }
            })
            .collect()
    }

    /// The fitted v̄(δ) of each velocity model for series `s` on `grid` (radians), as
    /// (δ in degrees, v̄) with NaN where a model has no steady state.
    fn model_curves(&self, s: usize, grid: &[f64]) -> [Vec<(f64, f64)>; 4] {
        let s0 = self
            .data
            .series(s)
            .next()
            .expect("a series has points")
            .scene;
        let none = || grid.iter().map(|&d| (d.to_degrees(), f64::NAN)).collect();
        let contact = |i: usize| -> Vec<(f64, f64)> {
            let Some(c) = self.contact.get(i) else {
                return none();
            };
            let Some(r) = c.law_c.as_ref().and_then(|f| f.summary.params.first()) else {
                return none();
            };
            let k = k_of_c(s0.alpha, lsq(r));
            grid.par_iter()
                .map(|&d| {
                    let v = crate::scene::Scene::from_radians(
                        s0.xi,
                        d,
                        s0.rho,
                        s0.f,
                        CollisionLaw::Value(k),
                    )
                    .ok()
                    .and_then(|sc| c.model.evaluate(&sc).ok())
                    .map_or(f64::NAN, |st| st.mean_velocity);
                    (d.to_degrees(), v)
                })
                .collect()
        };
        let jan = match &self.jan.series[s] {
            Some(j) => {
                let (l, m) = (lsq(&j.params[0]), lsq(&j.params[1]));
                grid.iter()
                    .map(|&d| {
                        let v = jan_velocity(&(s0.sin_alpha, d.sin(), d.cos()), l, m)
                            .map_or(f64::NAN, |r| r.0);
                        (d.to_degrees(), v)
                    })
                    .collect()
            }
            None => none(),
        };
        let jaeger = match &self.jaeger.series[s] {
            Some(j) => {
                let p: Vec<f64> = j.summary.params.iter().take(3).map(lsq).collect();
                let model = JaegerModel(JaegerBranch::Upper);
                grid.iter()
                    .map(|&d| {
                        let v = model
                            .value(&(d.tan(), d.cos(), s0.eps), &p)
                            .unwrap_or(f64::NAN);
                        (d.to_degrees(), v)
                    })
                    .collect()
            }
            None => none(),
        };
        [contact(0), contact(1), jan, jaeger]
    }

    /// Figure: v̄ against δ per series with every fitted model (the paper's Figs. 2–3, 8
    /// and 9). A model whose curve lies on an earlier one is dashed, and its legend entry
    /// says on which. With `bands`, for a posterior run, each model's 90 % posterior
    /// band of v̄(δ) (from [`posterior_bands_until`](super::bands::posterior_bands_until): the 5 % and 95 %
    /// quantiles of the model's v̄ over the draws) shaded under its curve; with `units_m_s`
    /// (per series, in the order of [`Dataset::labels`](crate::fit::data::Dataset::labels),
    /// the velocity unit sqrt(g R (1 + ξ)) in m/s of velocities given in m/s), in m/s.
    pub fn velocity_figure_with(
        &self,
        bands: Option<&PosteriorBands>,
        units_m_s: Option<&[f64]>,
    ) -> Result<String, FigureError> {
        let unit = |s: usize| units_m_s.and_then(|u| u.get(s).copied()).unwrap_or(1.0);
        let v_label = if units_m_s.is_some() {
            "mean velocity v\u{304} (m/s)"
        } else {
            V_LABEL
        };
        if let Some(b) = bands.filter(|b| {
            b.bands
                .iter()
                .any(|x| VELOCITY_FITS.contains(&x.fit.as_str()))
        }) {
            return Ok(self.velocity_posterior_figure(b, &unit, v_label));
        }
        let mut panels = Vec::new();
        let mut curves_by_panel = Vec::new();
        for s in 0..self.data.labels.len() {
            let ds: Vec<f64> = self.data.series(s).map(|p| p.scene.delta).collect();
            let u = unit(s);
            let curves = self.model_curves(s, &delta_grid(&ds));
            curves_by_panel.push(curves.map(|c| {
                c.into_iter()
                    .map(|(d, v)| (d, v * u))
                    .collect::<Vec<(f64, f64)>>()
            }));
            let mut p = Panel::new(
                &self.series_title(s),
                Axis::new(DELTA_LABEL),
                Axis::new(v_label),
            );
            p.points(
                self.series_points(s, |q, v| (q.scene.delta_deg(), v * u)),
                DATA,
                Mark::Circle,
            );
            panels.push(p);
        }
        let on = coinciding(&curves_by_panel);
        let mut legend = vec![LegendEntry::mark(
            if self.data.sigma == SigmaKind::Absolute {
                "data (bars: ±σ)"
            } else {
                "data"
            },
            Mark::Circle,
            DATA,
        )];
        let mut dash_count = 0;
        let mut banded = false;
        for (m, (name, colour)) in VELOCITY_MODELS.iter().enumerate() {
            if curves_by_panel
                .iter()
                .all(|cs| cs[m].iter().all(|p| !p.1.is_finite()))
            {
                continue;
            }
            let mut stroke = Stroke::solid(colour, 2.2);
            let mut label = name.to_string();
            if let Some(&(a, _)) = on[m].first() {
                stroke = stroke.dashed(DASHES[dash_count % DASHES.len()]);
                dash_count += 1;
                let n = on[m].len();
                let which = if n == curves_by_panel.len() {
                    "in every series".to_string()
                } else {
                    let ls: Vec<String> = on[m]
                        .iter()
                        .map(|&(_, s)| self.data.labels[s].clone())
                        .collect();
                    format!("for ξ = {}", ls.join(", "))
                };
                label = format!(
                    "{label}, dashed: on {}'s curve {which}",
                    VELOCITY_MODELS[a].0.split([',', ' ']).next().unwrap_or("")
                );
            }
            for (s, (p, cs)) in panels.iter_mut().zip(&curves_by_panel).enumerate() {
                if let Some(b) = bands.and_then(|b| {
                    b.bands
                        .iter()
                        .find(|b| b.fit == VELOCITY_FITS[m] && b.series == self.data.labels[s])
                }) {
                    let pts: Vec<(f64, f64, f64)> = b
                        .delta_deg
                        .iter()
                        .zip(b.q05.iter().zip(&b.q95))
                        .filter(|(_, (lo, hi))| lo.is_finite() && hi.is_finite())
                        .map(|(&d, (&lo, &hi))| (d, lo * unit(s), hi * unit(s)))
                        .collect();
                    if pts.len() > 1 {
                        p.band(pts, colour, 0.18);
                        banded = true;
                    }
                }
                p.curve(cs[m].clone(), stroke.clone());
            }
            legend.push(LegendEntry::line(&label, &stroke));
        }
        if banded {
            legend.push(LegendEntry::patch(
                "shaded: 90 % posterior band of v\u{304}(δ) (5–95 % of the draws)",
                "#808080",
                0.3,
            ));
        }
        let mut f = Figure::new(
            "Mean velocity against slope: data and fitted models",
            2,
            GRID_PLOT,
            panels,
        );
        f.legend = legend;
        Ok(self.render(f))
    }

    /// The velocity figure of a posterior run: one row of panels per model (in its colour),
    /// one column per series; each panel the data, the model's posterior-median v̄(δ) and its
    /// 90 % posterior band, so that models whose curves nearly coincide stay apart.
    fn velocity_posterior_figure(
        &self,
        bands: &PosteriorBands,
        unit: &dyn Fn(usize) -> f64,
        v_label: &str,
    ) -> String {
        let n = self.data.labels.len();
        let mut panels = Vec::new();
        let mut legend = vec![LegendEntry::mark(
            if self.data.sigma == SigmaKind::Absolute {
                "data (bars: ±σ)"
            } else {
                "data"
            },
            Mark::Circle,
            DATA,
        )];
        for (m, (name, colour)) in VELOCITY_MODELS.iter().enumerate() {
            let of_model: Vec<_> = bands
                .bands
                .iter()
                .filter(|b| b.fit == VELOCITY_FITS[m])
                .collect();
            if of_model.is_empty() {
                continue;
            }
            legend.push(LegendEntry::line(
                &format!("{name}: posterior median"),
                &Stroke::solid(colour, 2.2),
            ));
            for s in 0..n {
                let u = unit(s);
                let mut p = Panel::new(
                    &format!("{name}, {}", self.series_title(s)),
                    Axis::new(DELTA_LABEL),
                    Axis::new(v_label),
                );
                if let Some(b) = of_model.iter().find(|b| b.series == self.data.labels[s]) {
                    let band: Vec<(f64, f64, f64)> = b
                        .delta_deg
                        .iter()
                        .zip(b.q05.iter().zip(&b.q95))
                        .filter(|(_, (lo, hi))| lo.is_finite() && hi.is_finite())
                        .map(|(&d, (&lo, &hi))| (d, lo * u, hi * u))
                        .collect();
                    if band.len() > 1 {
                        p.band(band, colour, 0.25);
                    }
                    let median: Vec<(f64, f64)> = b
                        .delta_deg
                        .iter()
                        .zip(&b.q50)
                        .map(|(&d, &v)| (d, v * u))
                        .collect();
                    p.curve(median, Stroke::solid(colour, 2.2));
                }
                p.points(
                    self.series_points(s, |q, v| (q.scene.delta_deg(), v * u)),
                    DATA,
                    Mark::Circle,
                );
                panels.push(p);
            }
        }
        legend.push(LegendEntry::patch(
            "shaded: 90 % posterior band of v\u{304}(δ) (5–95 % of the draws)",
            "#808080",
            0.3,
        ));
        let mut f = Figure::new(
            "Mean velocity against slope: posterior of each model",
            n.max(1),
            (300.0, 210.0),
            panels,
        );
        f.legend = legend;
        self.render(f)
    }

    /// Figure: v̄²/cos δ against tan δ with Jan's straight lines (the paper's Fig. 8), each
    /// series' points and line in one colour; with `units_m_s` (per series, as for
    /// [`Analysis::velocity_figure_with`]) v̄² in m²/s².
    pub fn jan_figure(&self, units_m_s: Option<&[f64]>) -> Result<String, FigureError> {
        let unit = |s: usize| units_m_s.and_then(|u| u.get(s).copied()).unwrap_or(1.0);
        let y_label = if units_m_s.is_some() {
            "v\u{304}^{2} / cos δ  (m^{2}/s^{2})"
        } else {
            "v\u{304}^{2} / cos δ  (units of g(R + r))"
        };
        let mut p = Panel::new("", Axis::new("tan δ"), Axis::new(y_label));
        for s in 0..self.data.labels.len() {
            let (colour, mark) = series_style(s);
            let u2 = unit(s) * unit(s);
            let pts = self.series_points(s, |q, v| {
                (q.scene.delta.tan(), u2 * v * v / q.scene.delta.cos())
            });
            let stroke = Stroke::solid(colour, 2.0);
            if let Some(j) = &self.jan.series[s] {
                let (l, m) = (lsq(&j.params[0]), lsq(&j.params[1]));
                let sa = self.data.series(s).next().expect("points").scene.sin_alpha;
                let t1 = pts.iter().map(|q| q.0).fold(f64::NEG_INFINITY, f64::max) * 1.04;
                // v̄²/cos δ = (2 sin α/λ)(tan δ − μ): a straight line from tan δ = μ (eq 74).
                p.curve(
                    vec![(m, 0.0), (t1, u2 * 2.0 * sa / l * (t1 - m))],
                    stroke.clone(),
                );
                p.legend.push(LegendEntry::mark_line(
                    &format!("{}: data, Jan's line", self.series_title(s)),
                    mark,
                    &stroke,
                ));
            } else {
                p.legend
                    .push(LegendEntry::mark(&self.series_title(s), mark, colour));
            }
            p.points(pts, colour, mark);
        }
        Ok(self.render(Figure::new(
            "Jan's linearised plot: straight lines from tan δ = μ",
            1,
            SINGLE_PLOT,
            vec![p],
        )))
    }

    /// K per point (eq 69) under `model`, per series in the order of the slopes: (final
    /// velocity, α in degrees, K, K_lo, K_hi).
    fn k_points(&self, model: Model) -> Vec<Vec<KPoint>> {
        (0..self.data.labels.len())
            .map(|s| {
                let mut pts: Vec<_> = self.data.series(s).collect();
                pts.sort_by(|a, b| a.scene.delta.total_cmp(&b.scene.delta));
                pts.par_iter()
                    .filter_map(|p| {
                        let sg = (self.data.sigma == SigmaKind::Absolute).then_some(p.sigma);
                        let e = estimate(&model, &p.scene, p.v, sg);
                        let r = e.root.as_ref().ok()?;
                        Some((
                            r.steady.final_velocity,
                            p.scene.alpha.to_degrees(),
                            r.k,
                            e.k_lo.unwrap_or(r.k),
                            e.k_hi.unwrap_or(r.k),
                        ))
                    })
                    .collect()
            })
            .collect()
    }

    /// Figure: K per point (eq 69, stick/slip) against the steady final velocity (the
    /// paper's Figs. 5–6), with each series' K = cos 2α; with `units_m_s` (per series, as
    /// for [`Analysis::velocity_figure_with`]) the velocity in m/s.
    pub fn k_figure(&self, units_m_s: Option<&[f64]>) -> Result<String, FigureError> {
        let unit = |s: usize| units_m_s.and_then(|u| u.get(s).copied()).unwrap_or(1.0);
        let ks = self.k_points(Model::StickSlip);
        let series = ks
            .iter()
            .enumerate()
            .map(|(s, pts)| {
                let p0 = self.data.series(s).next().expect("points").scene;
                let c2 = CollisionLaw::Cos2a.k(p0.alpha, p0.rho);
                PointSeries {
                    label: self.series_title(s),
                    points: pts.iter().map(|q| (q.0 * unit(s), q.2, q.3, q.4)).collect(),
                    reference: Some((c2, format!("K = cos 2α = {c2:.4}"))),
                }
            })
            .collect();
        let fig = Scatter {
            title: "K per measurement (eq 69), stick/slip model".into(),
            x_label: if units_m_s.is_some() {
                "steady final velocity v_{f} (m/s)".into()
            } else {
                "steady final velocity v_{f} / √(g(R + r))".into()
            },
            y_label: "K".into(),
            series,
        };
        Ok(self.render(Figure::new(
            &fig.title,
            1,
            SINGLE_PLOT,
            vec![scatter_panel(&fig)],
        )))
    }

    /// Figure: K per point (eq 69) against α under each contact model, with its fitted law c,
    /// its per-series K and K = cos 2α.
    pub fn k_alpha_figure(&self) -> Result<String, FigureError> {
        let alphas: Vec<f64> = self.data.points.iter().map(|p| p.scene.alpha).collect();
        let a0 = alphas.iter().copied().fold(f64::INFINITY, f64::min);
        let a1 = alphas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let pad = 0.15 * (a1 - a0).max(2f64.to_radians());
        let grid: Vec<f64> = (0..=120)
            .map(|i| (a0 - pad).max(1e-3) + (a1 - a0 + 2.0 * pad) * i as f64 / 120.0)
            .collect();
        let rho = self.rho();
        let cos2a: Vec<(f64, f64)> = grid
            .iter()
            .map(|&a| (a.to_degrees(), CollisionLaw::Cos2a.k(a, rho)))
            .collect();
        let cos_stroke = Stroke::solid(REFERENCE, 1.8).dashed(DASHES[0]);
        let mut legend = self.series_legend(": K per point");
        legend.push(LegendEntry::line("K = cos 2α", &cos_stroke));
        let law_stroke = Stroke::solid("#000000", 2.2);
        legend.push(LegendEntry::line(
            "fitted law c: K = cos 2α + c sin^{2}α sin 2α",
            &law_stroke,
        ));
        let mut panels = Vec::new();
        for c in &self.contact {
            let ks = self.k_points(c.model);
            let law = c.law_c.as_ref().and_then(|f| f.summary.params.first());
            let title = match law {
                Some(r) => format!("{} model (c = {})", model_title(c.name), g4(lsq(r))),
                None => format!("{} model", model_title(c.name)),
            };
            let mut p = Panel::new(&title, Axis::new("contact angle α (°)"), Axis::new("K"));
            p.curve(cos2a.clone(), cos_stroke.clone());
            if let Some(r) = law {
                let cv = lsq(r);
                p.curve(
                    grid.iter()
                        .map(|&a| (a.to_degrees(), k_of_c(a, cv)))
                        .collect(),
                    law_stroke.clone(),
                );
            }
            for (s, pts) in ks.iter().enumerate() {
                let (colour, mark) = series_style(s);
                // The points of a series share α: spread by slope, SPREAD° apart.
                let mid = (pts.len() as f64 - 1.0) / 2.0;
                p.points(
                    pts.iter()
                        .enumerate()
                        .map(|(i, q)| (q.1 + (i as f64 - mid) * SPREAD, q.2, q.3, q.4))
                        .collect(),
                    colour,
                    mark,
                );
            }
            panels.push(p);
        }
        let mut f = Figure::new(
            "K per measurement (eq 69) against the contact angle, with the K(α) laws",
            2,
            GRID_PLOT,
            panels,
        );
        f.legend = legend;
        f.notes.push(format!(
            "The points of a series share one α: they are spread {SPREAD}° apart in the order \
             of their slopes."
        ));
        Ok(self.render(f))
    }

    /// Figure: the regime map (the paper's Fig. 4), one panel per contact model at its
    /// law-c fit: regions A (the bead stops), B (steady) and C (no steady motion: lift-off)
    /// shaded between the model's own limits — δ_m (eq 32) and δ_d (eq 31) for rolling, the
    /// ends of the steady interval found by scanning the model for stick/slip — the critical
    /// ξ marked, and the points by the regime the model assigns them.
    pub fn regime_figure(&self) -> Result<String, FigureError> {
        let rho = self.rho();
        let f = self.data.points.first().map_or(0.1, |p| p.scene.f);
        let n = 48;
        let xis: Vec<f64> = (0..=n)
            .map(|i| 0.5 * 40f64.powf(i as f64 / n as f64))
            .collect();
        let reg = self.point_regimes();
        let mut panels = Vec::new();
        for (ci, c) in self.contact.iter().enumerate() {
            let Some(cv) = c
                .law_c
                .as_ref()
                .and_then(|f| f.summary.params.first())
                .map(lsq)
            else {
                continue;
            };
            let law = CollisionLaw::C(cv);
            // (α in degrees, lower limit, upper limit) in degrees; NaN where no steady range.
            let (limits, crit): (Vec<(f64, f64, f64)>, Option<f64>) = match c.model {
                Model::Stick => {
                    let crit = critical_xi(law, rho);
                    let mut grid = xis.clone();
                    grid.extend(crit);
                    grid.sort_by(f64::total_cmp);
                    (
                        grid.iter()
                            .map(|&xi| {
                                let a = alpha_of_xi(xi);
                                (
                                    a.to_degrees(),
                                    delta_m_law(a, law, rho).to_degrees(),
                                    delta_d_law(a, law, rho).to_degrees(),
                                )
                            })
                            .collect(),
                        crit,
                    )
                }
                model => scanned_limits(&model, &xis, rho, f, law),
            };
            let mut p = Panel::new(
                &format!("{} model, law c (c = {})", model_title(c.name), g4(cv)),
                Axis::new("contact angle α (°)"),
                Axis::new(DELTA_LABEL),
            );
            let data_alpha: Vec<f64> = self
                .data
                .points
                .iter()
                .map(|q| q.scene.alpha.to_degrees())
                .collect();
            shade_regimes(&mut p, &limits, crit, c.model == Model::Stick, &data_alpha);
            if c.model == Model::Stick {
                // The paper's adjusted law, for reference.
                let adj = CollisionLaw::Adjusted;
                let st = Stroke::solid(REFERENCE, 1.5).dashed(DASHES[1]);
                for lim in [delta_m_law, delta_d_law] {
                    p.curve(
                        xis.iter()
                            .map(|&xi| {
                                let a = alpha_of_xi(xi);
                                (a.to_degrees(), lim(a, adj, rho).to_degrees())
                            })
                            .collect(),
                        st.clone(),
                    );
                }
            }
            if let Some(r) = reg.get(ci) {
                for (g, mark, colour) in [
                    ("A", Mark::TriangleDown, PALETTE[0]),
                    ("B", Mark::Circle, DATA),
                    ("C", Mark::Triangle, PALETTE[1]),
                    ("invalid", Mark::Diamond, PALETTE[3]),
                ] {
                    let pts: Vec<_> = self
                        .data
                        .points
                        .iter()
                        .zip(r)
                        .filter(|(_, x)| x.as_str() == g)
                        .map(|(q, _)| {
                            let (a, d) = (q.scene.alpha.to_degrees(), q.scene.delta_deg());
                            (a, d, d, d)
                        })
                        .collect();
                    if !pts.is_empty() {
                        p.points(pts, colour, mark);
                        let what = if g == "invalid" {
                            "data with no regime".to_string()
                        } else {
                            format!("data in regime {g}")
                        };
                        p.legend.push(LegendEntry::mark(&what, mark, colour));
                    }
                }
            }
            panels.push(p);
        }
        let mut fig = Figure::new(
            "Regime map: A stops, B steady, C no steady motion",
            2,
            (470.0, 400.0),
            panels,
        );
        fig.legend = regime_legend();
        Ok(self.render(fig))
    }

    /// Figure: Jaeger's plane (the paper's Figs. 9–10): Jaeger's velocity u against tan δ per
    /// series, with the fitted law (eq 83) on both branches of eq 84 and its bistable band
    /// (eq 90), and the paper's Fig. 9 law where ξ is one of its series.
    pub fn jaeger_figure(&self) -> Result<String, FigureError> {
        let fit_stroke = Stroke::solid(PALETTE[3], 2.2);
        let lower_stroke = Stroke::solid(PALETTE[3], 2.2).dashed(DASHES[0]);
        let paper_stroke = Stroke::solid(REFERENCE, 1.6).dashed(DASHES[1]);
        let (mut any_paper, mut any_lower) = (false, false);
        let mut panels = Vec::new();
        for s in 0..self.data.labels.len() {
            let p0 = self.data.series(s).next().expect("points").scene;
            // u = v̄ sqrt(ε/(2 cos δ)) (eq 81 in the paper's units).
            let pts = self.series_points(s, |q, v| {
                (
                    q.scene.delta.tan(),
                    v * (q.scene.eps / (2.0 * q.scene.delta.cos())).sqrt(),
                )
            });
            let umax = pts.iter().map(|q| q.3.max(q.1)).fold(0.0, f64::max) * 1.15;
            let mut p = Panel::new(
                &self.series_title(s),
                Axis::new("tan δ"),
                Axis::new("Jaeger's velocity u = v / √(2gr cos δ)"),
            );
            // tan δ from the data's least to 1.2 times their largest (curves beyond are cut).
            let t0 = pts.iter().map(|q| q.0).fold(f64::INFINITY, f64::min);
            let t1 = pts.iter().map(|q| q.0).fold(f64::NEG_INFINITY, f64::max);
            let mut lo = t0;
            if let Some(j) = &self.jaeger.series[s] {
                let a: Vec<f64> = j.summary.params.iter().take(3).map(lsq).collect();
                lo = lo.min(a[0].min(t0));
                any_lower |= jaeger_law(
                    &mut p,
                    [a[0], a[1], a[2]],
                    umax,
                    &fit_stroke,
                    &lower_stroke,
                    true,
                );
            }
            if let Some(pv) = paper_values(p0.xi) {
                any_paper = true;
                lo = lo.min(pv[0]);
                jaeger_law(&mut p, pv, umax, &paper_stroke, &paper_stroke, false);
            }
            p.x.range = Some((lo - 0.06 * (t1 - lo), t1 + 0.2 * (t1 - lo)));
            p.y.range = Some((0.0, umax));
            p.points(pts, DATA, Mark::Circle);
            panels.push(p);
        }
        let mut f = Figure::new(
            "Jaeger's law tan δ = a_{3}u^{2} + a_{1}/(1 + a_{2}u^{2})",
            2,
            GRID_PLOT,
            panels,
        );
        f.legend = vec![
            LegendEntry::mark("data", Mark::Circle, DATA),
            LegendEntry::line("fit, upper branch of eq 84", &fit_stroke),
        ];
        if any_lower {
            f.legend.extend([
                LegendEntry::line("fit, lower branch", &lower_stroke),
                LegendEntry::patch("bistable band of the fit (eq 90)", PALETTE[3], 0.15),
            ]);
        } else {
            f.notes.push(
                "No fit has a bistable band: each has a_{1}a_{2} ≤ a_{3} (eq 82), one branch only."
                    .into(),
            );
        }
        if any_paper {
            f.legend.push(LegendEntry::line(
                "the paper's Fig. 9 values",
                &paper_stroke,
            ));
        }
        Ok(self.render(f))
    }

    /// Figure: the energy partition of every point under each contact model at its law-c
    /// fit: collision loss in translation and in spin and friction work, as fractions of the
    /// potential drop 2 sin α sin δ (the data of `energy.csv`), stacked per point.
    pub fn energy_figure(&self) -> Result<String, FigureError> {
        let parts = [
            ("collision, translation", PALETTE[0]),
            ("collision, spin", PALETTE[4]),
            ("friction work", PALETTE[2]),
        ];
        let mut panels = Vec::new();
        for c in self.contact.iter().filter(|c| c.law_c.is_some()) {
            for s in 0..c.data.labels.len() {
                let pts: Vec<(f64, [f64; 3])> = c
                    .data
                    .points
                    .iter()
                    .zip(&c.energy)
                    .filter(|(p, _)| p.series == s)
                    .filter_map(|(p, e)| {
                        let e = e.as_ref()?;
                        let d = e.potential_drop;
                        Some((
                            p.scene.delta_deg(),
                            [
                                e.collision_translation / d,
                                e.collision_spin / d,
                                e.friction_work / d,
                            ],
                        ))
                    })
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let mut ds: Vec<f64> = pts.iter().map(|p| p.0).collect();
                ds.sort_by(f64::total_cmp);
                let gap = ds
                    .windows(2)
                    .map(|w| w[1] - w[0])
                    .filter(|g| *g > 0.0)
                    .fold(f64::INFINITY, f64::min);
                let half = if gap.is_finite() { 0.35 * gap } else { 0.2 };
                // The contact model's data keep the full data's series labels.
                let full = self
                    .data
                    .labels
                    .iter()
                    .position(|l| *l == c.data.labels[s])
                    .unwrap_or(s);
                let mut p = Panel::new(
                    &format!("{}, {}", model_title(c.name), self.series_title(full)),
                    Axis::new(DELTA_LABEL),
                    Axis::new("fraction of 2 sin α sin δ").with_range(0.0, 1.08),
                );
                for (k, (_, colour)) in parts.iter().enumerate() {
                    let rects = pts
                        .iter()
                        .map(|(d, f)| {
                            let base: f64 = f[..k].iter().sum();
                            (d - half, d + half, base, base + f[k], 1.0)
                        })
                        .collect();
                    p.items.push(Item::Rects {
                        rects,
                        colour: colour.to_string(),
                    });
                }
                panels.push(p);
            }
        }
        let mut f = Figure::new(
            "Energy partition per point at each model's law-c fit (§4.6, eqs 70–72)",
            4,
            (250.0, 210.0),
            panels,
        );
        // One y axis per row: the panels right of the first share it.
        f.share_y = true;
        f.legend = parts
            .iter()
            .map(|(l, c)| LegendEntry::patch(l, c, 1.0))
            .collect();
        // The friction share is too thin to read off the bars: say how large it gets.
        let shares: Vec<String> = self
            .contact
            .iter()
            .filter_map(|c| {
                let m = c
                    .energy
                    .iter()
                    .flatten()
                    .map(|e| e.friction_work / e.potential_drop)
                    .fold(f64::NEG_INFINITY, f64::max);
                m.is_finite()
                    .then(|| format!("{} {} %", model_title(c.name), fmt_sig(100.0 * m, 2)))
            })
            .collect();
        if !shares.is_empty() {
            f.notes.push(format!(
                "Largest friction work, as a share of the potential drop: {}.",
                shares.join(", ")
            ));
        }
        Ok(self.render(f))
    }

    /// The fits of the report with their names as in `params.csv`: (name, fits) where a
    /// per-series model has one fit per series.
    pub fn named_fits(&self) -> Vec<(String, Vec<&FitResult>)> {
        let mut out: Vec<(String, Vec<&FitResult>)> = Vec::new();
        for (name, f) in self.each_fit() {
            match out.last_mut() {
                Some(g) if g.0 == name => g.1.push(f),
                _ => out.push((name, vec![f])),
            }
        }
        out
    }

    /// Figure: normalised residuals (v − v̄_fit)/σ against δ, one panel per fit, points
    /// coloured by series, with the ±2 lines, of `fits` as [`Analysis::fit_results`] or
    /// [`Analysis::fit_results_at`] give them (under a posterior run, residuals at the
    /// posterior medians); fits of one name make one panel.
    pub fn residuals_figure_with(&self, fits: &[FitResult]) -> Result<String, FigureError> {
        let mut groups: Vec<(String, Vec<&FitResult>)> = Vec::new();
        for f in fits {
            match groups.iter_mut().find(|g| g.0 == f.stats.fit) {
                Some(g) => g.1.push(f),
                None => groups.push((f.stats.fit.clone(), vec![f])),
            }
        }
        let mut panels = Vec::new();
        for (name, fits) in groups {
            let chi2: f64 = fits.iter().map(|f| f.stats.chi2).sum();
            let mut p = Panel::new(
                &format!("{} (χ^{{2}} = {})", fit_title(&name), fmt_sig(chi2, 3)),
                Axis::new(DELTA_LABEL),
                Axis::new("(v − v\u{304}_{fit}) / σ"),
            );
            let all: Vec<f64> = fits
                .iter()
                .flat_map(|f| f.points.iter().map(|q| q.normalised_residual.abs()))
                .filter(|v| v.is_finite())
                .collect();
            let lim = all.iter().copied().fold(2.5, f64::max) * 1.1;
            p.y.range = Some((-lim, lim));
            p.items.push(Item::HLine {
                y: 0.0,
                stroke: Stroke::solid(REFERENCE, 1.2),
            });
            for y in [-2.0, 2.0] {
                p.items.push(Item::HLine {
                    y,
                    stroke: Stroke::solid(REFERENCE, 1.2).dashed(DASHES[0]),
                });
            }
            for (s, label) in self.data.labels.iter().enumerate() {
                let (colour, mark) = series_style(s);
                let pts: Vec<_> = fits
                    .iter()
                    .flat_map(|f| f.points.iter())
                    .filter(|q| q.series == *label)
                    .map(|q| {
                        let r = q.normalised_residual;
                        (q.delta_deg, r, r, r)
                    })
                    .collect();
                if !pts.is_empty() {
                    p.points(pts, colour, mark);
                }
            }
            panels.push(p);
        }
        let mut f = Figure::new(
            "Normalised residuals against slope, one panel per fit",
            3,
            (330.0, 220.0),
            panels,
        );
        f.legend = self.series_legend("");
        f.legend.push(LegendEntry::line(
            "±2",
            &Stroke::solid(REFERENCE, 1.2).dashed(DASHES[0]),
        ));
        Ok(self.render(f))
    }

    /// One corner plot per posterior: (file name `corner_<fit>_<series>.svg` with the fit
    /// named as in `params.csv` and the series label made a safe, unique file name by
    /// [`super::file_stems`], SVG). Empty without posteriors.
    pub fn corner_figures(&self) -> Vec<(String, String)> {
        let stems = super::file_stems(&self.data.labels);
        let stem = |series: &str| -> String {
            match self.data.labels.iter().position(|l| l == series) {
                Some(i) => stems[i].clone(),
                None => super::file_stems(&[series.to_string()]).remove(0),
            }
        };
        // Drawn side by side (a corner of one K per series has hundreds of panels), in the
        // order of the fits.
        let named = self.named_fits();
        let all: Vec<(&str, &FitResult)> = named
            .iter()
            .flat_map(|(name, fits)| fits.iter().map(move |f| (name.as_str(), *f)))
            .collect();
        all.par_iter()
            .filter_map(|&(name, f)| {
                let mut b = CornerBlock::from_posterior(f)?;
                b.title = fit_title(name).replace(", per series", "");
                if f.stats.series != "all" {
                    b.title.push_str(&format!(", series {}", f.stats.series));
                }
                if f.draws.as_ref().is_some_and(|d| d.interrupted) {
                    b.title.push_str(" (interrupted)");
                }
                Some((
                    format!("corner_{name}_{}.svg", stem(&f.stats.series)),
                    self.render(corner_figure(&b)),
                ))
            })
            .collect()
    }
}

/// "rolling" → "Rolling", "stickslip" → "Stick/slip".
fn model_title(name: &str) -> &'static str {
    match name {
        "rolling" => "Rolling",
        "stickslip" => "Stick/slip",
        _ => "Contact",
    }
}

/// A fit's name from `params.csv` for a title.
fn fit_title(name: &str) -> String {
    let s = name
        .replace("rolling-", "rolling, ")
        .replace("stickslip-", "stick/slip, ")
        .replace("klaw-c", "law c")
        .replace("klaw-free-per-series", "K per series")
        .replace("jan-series", "Jan, λ and μ per series")
        .replace("jan-global", "Jan, global laws");
    if s == "jaeger" {
        "Jaeger, per series".into()
    } else {
        s
    }
}

/// Colours of the regions of the regime map.
const REGION: [(&str, &str); 4] = [
    ("A: the bead stops", "#56B4E9"),
    ("B: steady motion", "#009E73"),
    ("C: no steady motion (lift-off)", "#E69F00"),
    ("no steady slope", "#999999"),
];

fn regime_legend() -> Vec<LegendEntry> {
    let mut l: Vec<LegendEntry> = REGION
        .iter()
        .map(|(t, c)| LegendEntry::patch(t, c, 0.22))
        .collect();
    l.push(LegendEntry::line(
        "limits of the model at its fit",
        &Stroke::solid("#000000", 2.0),
    ));
    l.push(LegendEntry::line(
        "critical ξ_{c}",
        &Stroke::solid("#000000", 1.5).dashed(DASHES[2]),
    ));
    l.push(LegendEntry::line(
        "rolling limits, the paper's adjusted K(α)",
        &Stroke::solid(REFERENCE, 1.5).dashed(DASHES[1]),
    ));
    l
}

/// Shades regions A, B, C between `limits` (α°, lower δ°, upper δ°) and marks the critical
/// ξ; `crossing` when the limits are curves that cross (rolling's δ_m and δ_d, drawn over
/// the whole range) rather than ends of a steady interval (NaN where there is none). The
/// region letters keep away from the α (degrees) in `avoid`.
fn shade_regimes(
    p: &mut Panel,
    limits: &[(f64, f64, f64)],
    crit: Option<f64>,
    crossing: bool,
    avoid: &[f64],
) {
    let top = limits
        .iter()
        .flat_map(|l| [l.1, l.2])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
        * 1.25;
    let a_lo = limits.iter().map(|l| l.0).fold(f64::INFINITY, f64::min);
    let a_hi = limits.iter().map(|l| l.0).fold(f64::NEG_INFINITY, f64::max);
    p.x.range = Some((a_lo, a_hi));
    p.y.range = Some((0.0, top));
    let steady: Vec<&(f64, f64, f64)> = limits
        .iter()
        .filter(|l| l.1.is_finite() && l.2.is_finite() && l.1 <= l.2 + 1e-9)
        .collect();
    let region = |k: usize, pts: Vec<(f64, f64)>| Item::Fill {
        pts,
        colour: REGION[k].1.to_string(),
        opacity: 0.22,
    };
    if steady.len() >= 2 {
        let mut a: Vec<(f64, f64)> = steady.iter().map(|l| (l.0, l.1)).collect();
        a.push((steady[steady.len() - 1].0, 0.0));
        a.push((steady[0].0, 0.0));
        let mut b: Vec<(f64, f64)> = steady.iter().map(|l| (l.0, l.1)).collect();
        b.extend(steady.iter().rev().map(|l| (l.0, l.2)));
        let mut c: Vec<(f64, f64)> = steady.iter().map(|l| (l.0, l.2)).collect();
        c.push((steady[steady.len() - 1].0, top));
        c.push((steady[0].0, top));
        p.items.push(region(0, a));
        p.items.push(region(1, b));
        p.items.push(region(2, c));
        // Each letter where its region is tallest, inside the inner 80 % of the steady
        // range and, where possible, 2.5° or more from the data's α.
        let (s0, s1) = (steady[0].0, steady[steady.len() - 1].0);
        let inner: Vec<&(f64, f64, f64)> = steady
            .iter()
            .copied()
            .filter(|l| (l.0 - s0).abs() >= 0.1 * (s1 - s0).abs())
            .filter(|l| (l.0 - s1).abs() >= 0.1 * (s1 - s0).abs())
            .collect();
        let clear = |l: &&(f64, f64, f64)| avoid.iter().all(|a| (a - l.0).abs() >= 2.5);
        let by = |f: &dyn Fn(&(f64, f64, f64)) -> f64| -> (f64, f64, f64) {
            let best = |it: &mut dyn Iterator<Item = &&(f64, f64, f64)>| {
                it.max_by(|a, b| f(a).total_cmp(&f(b))).map(|l| **l)
            };
            best(&mut inner.iter().filter(|l| clear(l)))
                .or_else(|| best(&mut inner.iter()))
                .unwrap_or(*steady[steady.len() / 2])
        };
        let a = by(&|l| l.1);
        let b = by(&|l| l.2 - l.1);
        let c = by(&|l| top - l.2);
        for (x, y, t) in [
            (a.0, 0.4 * a.1, "A"),
            (b.0, 0.5 * (b.1 + b.2), "B"),
            (c.0, 0.5 * (c.2 + top), "C"),
        ] {
            p.items.push(Item::Text {
                at: (x, y),
                text: t.into(),
                anchor: Anchor::Middle,
                colour: "#000000".into(),
            });
        }
    }
    // Where no slope is steady (α above the critical one).
    if let Some(xc) = crit {
        let ac = alpha_of_xi(xc).to_degrees();
        if ac < a_hi {
            p.items.push(region(
                3,
                vec![(ac, 0.0), (a_hi, 0.0), (a_hi, top), (ac, top)],
            ));
        }
        p.items.push(Item::VLine {
            x: ac,
            stroke: Stroke::solid("#000000", 1.5).dashed(DASHES[2]),
        });
        p.items.push(Item::Text {
            at: (ac, 0.93 * top),
            // Two spaces of advance keep the label clear of its own line on either side.
            text: format!("  ξ_{{c}} = {}  ", g4(xc)),
            anchor: if ac > 0.5 * (a_lo + a_hi) {
                Anchor::End
            } else {
                Anchor::Start
            },
            colour: "#000000".into(),
        });
    }
    let lim = Stroke::solid("#000000", 2.0);
    if crossing {
        p.curve(limits.iter().map(|l| (l.0, l.1)).collect(), lim.clone());
        p.curve(limits.iter().map(|l| (l.0, l.2)).collect(), lim);
    } else {
        p.curve(steady.iter().map(|l| (l.0, l.1)).collect(), lim.clone());
        p.curve(steady.iter().map(|l| (l.0, l.2)).collect(), lim);
    }
}

/// The steady interval of a model scanned at each ξ ([`regime_b_interval`]), as (α°, lower
/// δ°, upper δ°) with NaN where there is none, and the critical ξ: the smallest ξ with a
/// steady interval, refined by bisection between the grid's last ξ without and first with.
fn scanned_limits(
    model: &Model,
    xis: &[f64],
    rho: f64,
    f: f64,
    law: CollisionLaw,
) -> (Vec<(f64, f64, f64)>, Option<f64>) {
    let lims: Vec<(f64, f64, f64)> = xis
        .par_iter()
        .map(|&xi| {
            let a = alpha_of_xi(xi).to_degrees();
            match regime_b_interval(model, xi, rho, f, law) {
                Some((lo, hi)) => (a, lo.to_degrees(), hi.to_degrees()),
                None => (a, f64::NAN, f64::NAN),
            }
        })
        .collect();
    let first = lims.iter().position(|l| l.1.is_finite());
    let crit = match first {
        Some(0) | None => None,
        Some(i) => {
            let (mut lo, mut hi) = (xis[i - 1].ln(), xis[i].ln());
            for _ in 0..10 {
                let m = 0.5 * (lo + hi);
                if regime_b_interval(model, m.exp(), rho, f, law).is_some() {
                    hi = m;
                } else {
                    lo = m;
                }
            }
            Some(hi.exp())
        }
    };
    // The steady interval at the critical ξ closes the shaded regions there.
    let mut lims = lims;
    if let Some(xc) = crit {
        if let Some((lo, hi)) = regime_b_interval(model, xc, rho, f, law) {
            let a = alpha_of_xi(xc).to_degrees();
            lims.push((a, lo.to_degrees(), hi.to_degrees()));
            lims.sort_by(|p, q| q.0.total_cmp(&p.0));
        }
    }
    (lims, crit)
}

/// Jaeger's law with coefficients `a` in Jaeger's plane: tan δ(u) (eq 83) drawn as u against
/// tan δ, split at the minimum of tan δ(u) into the upper (`upper`) and lower (`lower`)
/// branches of eq 84, and, when `band`, the bistable band of eq 90 shaded. Returns whether the law has a lower branch.
fn jaeger_law(
    p: &mut Panel,
    a: [f64; 3],
    umax: f64,
    upper: &Stroke,
    lower: &Stroke,
    band: bool,
) -> bool {
    let [a1, a2, a3] = a;
    let t = |u: f64| a3 * u * u + a1 / (1.0 + a2 * u * u);
    // d tan δ/du = 0 at u*² = (sqrt(a1 a2/a3) − 1)/a2 when a1 a2 > a3 (eq 82).
    let ustar = if a2 > 0.0 && a1 * a2 > a3 {
        (((a1 * a2 / a3).sqrt() - 1.0) / a2).sqrt()
    } else {
        0.0
    };
    let n = 200;
    let sample = |u0: f64, u1: f64| -> Vec<(f64, f64)> {
        (0..=n)
            .map(|i| {
                let u = u0 + (u1 - u0) * i as f64 / n as f64;
                (t(u), u)
            })
            .collect()
    };
    if ustar > 0.0 {
        if band {
            let (t0, t1) = (t(ustar), a1);
            p.items.push(Item::Fill {
                pts: vec![(t0, 0.0), (t1, 0.0), (t1, umax), (t0, umax)],
                colour: PALETTE[3].to_string(),
                opacity: 0.15,
            });
        }
        p.curve(sample(0.0, ustar), lower.clone());
    }
    p.curve(sample(ustar, umax), upper.clone());
    ustar > 0.0
}

/// Figure of least-squares fits (`fitbead klaw`, `jan` and `jaeger` with `--plot`): one panel
/// per series, v̄ against δ: the data with their σ bars, each fit's curve at the optimum and
/// its confidence band at the fit's level by the delta method (the covariance at the
/// optimum; see `bands::lsq_band`). Fits are told apart by colour and named by their
/// params.csv name; a fit without a covariance is drawn without a band.
pub fn lsq_fit_figure(
    title: &str,
    data: &Dataset,
    fits: &[(&FitResult, Curve)],
) -> Result<String, FigureError> {
    let mut names: Vec<&str> = Vec::new();
    for (f, _) in fits {
        if !names.contains(&f.stats.fit.as_str()) {
            names.push(&f.stats.fit);
        }
    }
    let level = fits
        .iter()
        .find_map(|(f, _)| f.params.first().map(|r| r.level))
        .unwrap_or(0.95);
    let mut panels = Vec::new();
    let mut notes = Vec::new();
    for (s, label) in data.labels.iter().enumerate() {
        let pts: Vec<&crate::fit::data::Point> = data.series(s).collect();
        let Some(first) = pts.first() else { continue };
        let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
            (a.0.min(p.scene.delta), a.1.max(p.scene.delta))
        });
        let pad = 0.08 * (hi - lo).max(1f64.to_radians());
        let grid: Vec<f64> = (0..=100)
            .map(|i| (lo - pad).max(1e-4) + (hi - lo + 2.0 * pad) * i as f64 / 100.0)
            .collect();
        let xi = first.scene.xi;
        let title = if label.parse::<f64>().ok() == Some(xi) {
            format!("ξ = {label}")
        } else {
            format!("series {label} (ξ = {})", g4(xi))
        };
        let mut p = Panel::new(&title, Axis::new(DELTA_LABEL), Axis::new(V_LABEL));
        for (f, curve) in fits {
            let Some(b) = lsq_band(f, *curve, data, s, &grid) else {
                continue;
            };
            let k = names.iter().position(|n| *n == f.stats.fit).unwrap_or(0);
            let colour = PALETTE[k % PALETTE.len()];
            let band: Vec<(f64, f64, f64)> = (0..b.delta_deg.len())
                .filter(|&i| b.lo[i].is_finite() && b.hi[i].is_finite())
                .map(|i| (b.delta_deg[i], b.lo[i], b.hi[i]))
                .collect();
            if band.len() > 1 {
                p.band(band, colour, 0.22);
            } else if !f.params.is_empty() {
                notes.push(format!(
                    "{title}: {} has no band (no covariance at the optimum)",
                    f.stats.fit
                ));
            }
            let line: Vec<(f64, f64)> = b.delta_deg.iter().copied().zip(b.v).collect();
            p.curve(line, Stroke::solid(colour, 2.0));
        }
        let data_pts: Vec<ErrPoint> = pts
            .iter()
            .map(|q| {
                let (x, y) = (q.scene.delta_deg(), q.v);
                if data.sigma == SigmaKind::Absolute {
                    (x, y, y - q.sigma, y + q.sigma)
                } else {
                    (x, y, y, y)
                }
            })
            .collect();
        p.points(data_pts, DATA, Mark::Circle);
        panels.push(p);
    }
    if panels.is_empty() {
        return Err(FigureError::Empty("no series to draw".to_string()));
    }
    let cols = panels.len().min(2);
    let mut f = Figure::new(title, cols, GRID_PLOT, panels);
    f.notes = notes;
    f.legend
        .push(LegendEntry::mark("data (± σ)", Mark::Circle, DATA));
    for (k, n) in names.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        f.legend
            .push(LegendEntry::line(n, &Stroke::solid(colour, 2.0)));
    }
    f.legend.push(LegendEntry::patch(
        &format!(
            "{} % confidence band (delta method)",
            fmt_sig(100.0 * level, 3)
        ),
        REFERENCE,
        0.3,
    ));
    Ok(f.to_svg())
}

/// 161 slopes (radians) across the measured slopes `ds` of a series, a tenth of their range
/// (at least 1°) beyond either end, none below 1e-4.
fn delta_grid(ds: &[f64]) -> Vec<f64> {
    let d0 = ds.iter().copied().fold(f64::INFINITY, f64::min);
    let d1 = ds.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let pad = 0.1 * (d1 - d0).max(1f64.to_radians());
    (0..=160)
        .map(|i| (d0 - pad).max(1e-4) + (d1 - d0 + 2.0 * pad) * i as f64 / 160.0)
        .collect()
}

/// Which of the four velocity models' curves lies on an earlier one, and in which series:
/// per model, (the earlier model, the series), the curves of every series given by panel.
fn coinciding(curves_by_panel: &[[Vec<(f64, f64)>; 4]]) -> Vec<Vec<(usize, usize)>> {
    let mut on: Vec<Vec<(usize, usize)>> = vec![Vec::new(); 4];
    for (s, cs) in curves_by_panel.iter().enumerate() {
        let ys = cs.iter().flatten().map(|p| p.1).filter(|v| v.is_finite());
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let tol = 0.006 * (hi - lo).max(1e-12);
        for b in 1..4 {
            if let Some(a) = (0..b).find(|&a| coincide(&cs[a], &cs[b], tol)) {
                on[b].push((a, s));
            }
        }
    }
    on
}

impl DesignResult {
    /// The figure of `fitbead design --plot` (SVG): per series, the sensitivity of every
    /// candidate slope, the chosen slopes marked.
    pub fn figure_svg(&self, settings: &DesignSettings) -> String {
        design_figure(settings, self).to_svg()
    }
}

/// The figure: per series, the sensitivity of every candidate slope with the chosen ones
/// marked (marker height: the sensitivity there; the label the replicates).
pub(crate) fn design_figure(s: &DesignSettings, r: &DesignResult) -> Figure {
    let mut panels = Vec::new();
    for (k, xi) in s.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let mut p = Panel::new(
            &format!("ξ = {}", fmt_f64(*xi)),
            Axis::new("slope δ (deg)"),
            Axis::new(&r.sensitivity_label),
        );
        let curve = &r.sensitivity[k];
        p.curve(curve.clone(), Stroke::solid(colour, 2.0));
        // Each slope of a design marked at the sensitivity of the nearest candidate.
        let on_curve = |rows: &[crate::design::DesignRow]| -> Vec<(f64, f64, f64, f64)> {
            rows.iter()
                .filter(|row| row.xi == *xi)
                .map(|row| {
                    let y = curve
                        .iter()
                        .min_by(|a, b| {
                            (a.0 - row.delta_deg)
                                .abs()
                                .total_cmp(&(b.0 - row.delta_deg).abs())
                        })
                        .map_or(f64::NAN, |c| c.1);
                    (row.delta_deg, y, y, y)
                })
                .collect()
        };
        let chosen = on_curve(&r.rows);
        for row in r.rows.iter().filter(|row| row.xi == *xi) {
            p.items.push(Item::VLine {
                x: row.delta_deg,
                stroke: Stroke::solid("#808080", 1.0).dashed("4 3"),
            });
        }
        p.items.push(Item::HLine {
            y: 1.0,
            stroke: Stroke::solid("#404040", 1.0).dashed("2 3"),
        });
        p.points(chosen, colour, Mark::Circle);
        p.points(on_curve(&r.even), "#808080", Mark::Cross);
        panels.push(p);
    }
    let cols = if panels.len() > 2 { 2 } else { panels.len() };
    let mut f = Figure::new(
        "Where to measure: sensitivity per slope",
        cols,
        (380.0, 240.0),
        panels,
    );
    f.legend = vec![
        LegendEntry::mark("design slopes", Mark::Circle, "#404040"),
        LegendEntry::mark("evenly spaced slopes", Mark::Cross, "#808080"),
    ];
    f.legend.push(LegendEntry::line(
        "equivalence bound (1 on the design)",
        &Stroke::solid("#404040", 1.0).dashed("2 3"),
    ));
    f.notes = s
        .series
        .iter()
        .map(|xi| {
            let at: Vec<String> = r
                .rows
                .iter()
                .filter(|row| row.xi == *xi)
                .map(|row| format!("{}° ×{}", fmt_f64(row.delta_deg), row.replicates))
                .collect();
            format!("design at ξ = {}: {}", fmt_f64(*xi), at.join(", "))
        })
        .collect();
    f
}

#[cfg(test)]
mod tests {
    use crate::fit::data::Dataset;
    use crate::inverse::posterior::Method;
    use crate::report::analysis::analyse;
    use crate::report::bands::{Band, PosteriorBands};

    /// A posterior band under a model's curve in the velocity figure is drawn in that model's
    /// colour (Jaeger's, #CC79A7, at the band's opacity 0.18 over white), under the data,
    /// with its legend entry.
    #[test]
    fn velocity_band_renders_under_the_curve() {
        let ds = Dataset::default_data();
        let an = analyse(&ds, 0.95, &Method::lsq(false));
        let delta_deg: Vec<f64> = (0..=20).map(|i| 11.0 + 2.5 * i as f64 / 20.0).collect();
        let line =
            |a: f64| -> Vec<f64> { delta_deg.iter().map(|d| a + 0.03 * (d - 11.0)).collect() };
        let bands = PosteriorBands {
            bands: vec![Band {
                fit: "jaeger".into(),
                series: ds.labels[0].clone(),
                xi: 0.8,
                q05: line(0.30),
                q50: line(0.32),
                q95: line(0.34),
                delta_deg: delta_deg.clone(),
                draws: 1000,
            }],
            points: Vec::new(),
        };
        let svg = an.velocity_figure_with(Some(&bands), None).unwrap();
        assert!(svg.contains("posterior band"));
        let band = svg.find("fill-opacity=\"0.25\"").expect("a band");
        let first_marker = svg.find("<circle").expect("markers");
        assert!(band < first_marker, "the band is drawn under the data");
        #[cfg(feature = "png")]
        {
            // #CC79A7 = (204, 121, 167) at opacity 0.18 over white, and at full opacity.
            let pixmap = crate::report::figures::png::render_pixmap(&svg, 1.0).unwrap();
            let mix = |c: f64| (0.18 * c + 0.82 * 255.0_f64).round() as i32;
            for want in [[mix(204.0), mix(121.0), mix(167.0)], [204, 121, 167]] {
                let n = pixmap
                    .pixels()
                    .iter()
                    .filter(|p| {
                        (p.red() as i32 - want[0]).abs() <= 6
                            && (p.green() as i32 - want[1]).abs() <= 6
                            && (p.blue() as i32 - want[2]).abs() <= 6
                    })
                    .count();
                assert!(n >= 20, "colour {want:?} on {n} pixels");
            }
        }
    }
}
