//! Axes, legends and grids of panels: the one layout engine every figure is drawn with.
//!
//! A [`Figure`] is a grid of [`Panel`]s (a cell may be empty, as above a corner plot's
//! diagonal) under a title, with an optional legend shared by the panels to the right of the
//! grid. A panel holds [`Item`]s in data coordinates on linear or log₁₀ axes, a light major
//! grid, and its own legend, set in the first empty corner of the plot area or, when the data
//! leave none, outside to the right. Every text is measured (`text_width`) so
//! that margins fit their labels and no two texts overlap.

use super::svg::{ascent, descent, line_height, text_width, Anchor, Mark, Stroke, Svg};

/// Colours of series and models (Okabe & Ito's colour-blind-safe set, with brown for an
/// eighth), in the order they are handed out.
pub const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#8C564B",
];

/// Text sizes, px.
pub(crate) const TICK_SIZE: f64 = 14.0;
/// Axis labels and legend entries.
pub(crate) const LABEL_SIZE: f64 = 16.0;
/// Panel titles.
pub(crate) const PANEL_TITLE_SIZE: f64 = 17.0;
/// Figure titles.
pub(crate) const TITLE_SIZE: f64 = 20.0;
/// Legend entries.
pub(crate) const LEGEND_SIZE: f64 = 14.0;

const GRID: &str = "#e3e3e3";
const FRAME: &str = "#404040";
const INK: &str = "#222222";
const TICK_LEN: f64 = 5.0;
const GAP: f64 = 6.0;
const SWATCH: f64 = 30.0;

/// Scale of an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Linear.
    #[default]
    Linear,
    /// Logarithmic (base 10); values ≤ 0 are left out.
    Log,
}

/// One axis: label, scale, and optionally a fixed range.
#[derive(Debug, Clone, Default)]
pub struct Axis {
    /// Label (markup: `_{…}` subscript, `^{…}` superscript).
    pub label: String,
    /// Scale.
    pub scale: Scale,
    /// Fixed range (data units); `None`: the data's, padded.
    pub range: Option<(f64, f64)>,
    /// Leave the tick labels out (the ticks and grid stay), as inside a corner plot.
    pub hide_tick_labels: bool,
    /// Number of ticks to aim at (0: from the axis length).
    pub ticks: usize,
}

impl Axis {
    /// A linear axis with `label`.
    pub fn new(label: &str) -> Self {
        Axis {
            label: label.to_string(),
            ..Axis::default()
        }
    }

    /// A log₁₀ axis with `label`.
    pub fn log(label: &str) -> Self {
        Axis {
            label: label.to_string(),
            scale: Scale::Log,
            ..Axis::default()
        }
    }

    /// The same axis with a fixed range.
    pub fn with_range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }

    fn to_lin(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => v,
            Scale::Log if v > 0.0 => v.log10(),
            Scale::Log => f64::NAN,
        }
    }
}

/// A point with an optional vertical error bar: (x, y, y_low, y_high); no bar when
/// y_low = y_high = y or either is NaN.
pub type ErrPoint = (f64, f64, f64, f64);

/// What a panel draws, in data coordinates.
#[derive(Debug, Clone)]
pub enum Item {
    /// A curve; a NaN coordinate breaks it.
    Curve {
        /// Samples.
        pts: Vec<(f64, f64)>,
        /// Stroke.
        stroke: Stroke,
    },
    /// Straight segments (contours).
    Segments {
        /// Segments.
        segs: Vec<[(f64, f64); 2]>,
        /// Stroke.
        stroke: Stroke,
    },
    /// Markers with error bars (caps on, drawn over the markers).
    Points {
        /// Points.
        pts: Vec<ErrPoint>,
        /// Colour of markers and bars.
        colour: String,
        /// Shape.
        mark: Mark,
        /// Radius, px.
        radius: f64,
        /// Opacity of the marker's fill (its outline is opaque).
        fill_opacity: f64,
    },
    /// Small filled dots, many of them (one path in the document).
    Dots {
        /// Centres.
        pts: Vec<(f64, f64)>,
        /// Colour.
        colour: String,
        /// Radius, px.
        radius: f64,
    },
    /// A shaded band between two curves over x: (x, y_low, y_high) samples (a posterior
    /// band under a curve, say).
    Band {
        /// Samples.
        pts: Vec<(f64, f64, f64)>,
        /// Colour.
        colour: String,
        /// Opacity.
        opacity: f64,
    },
    /// A filled polygon (a shaded region).
    Fill {
        /// Corners.
        pts: Vec<(f64, f64)>,
        /// Colour.
        colour: String,
        /// Opacity.
        opacity: f64,
    },
    /// Filled rectangles (x0, x1, y0, y1) of one colour, each with its own opacity
    /// (histograms).
    Rects {
        /// Rectangles and opacities.
        rects: Vec<(f64, f64, f64, f64, f64)>,
        /// Colour.
        colour: String,
    },
    /// A horizontal line across the panel.
    HLine {
        /// Height.
        y: f64,
        /// Stroke.
        stroke: Stroke,
    },
    /// A vertical line across the panel.
    VLine {
        /// Position.
        x: f64,
        /// Stroke.
        stroke: Stroke,
    },
    /// A text in the data (its box keeps the legend away).
    Text {
        /// Anchor point.
        at: (f64, f64),
        /// Markup.
        text: String,
        /// Anchor.
        anchor: Anchor,
        /// Colour.
        colour: String,
    },
}

/// What a legend entry shows beside its label.
#[derive(Debug, Clone, Default)]
pub struct Swatch {
    /// A line sample.
    pub line: Option<Stroke>,
    /// A marker.
    pub mark: Option<(Mark, String)>,
    /// A filled patch (colour, opacity).
    pub patch: Option<(String, f64)>,
}

/// A legend entry.
#[derive(Debug, Clone)]
pub struct LegendEntry {
    /// What it shows.
    pub swatch: Swatch,
    /// Label (markup).
    pub label: String,
}

impl LegendEntry {
    /// An entry for a curve.
    pub fn line(label: &str, stroke: &Stroke) -> Self {
        LegendEntry {
            swatch: Swatch {
                line: Some(stroke.clone()),
                ..Swatch::default()
            },
            label: label.to_string(),
        }
    }

    /// An entry for markers.
    pub fn mark(label: &str, mark: Mark, colour: &str) -> Self {
        LegendEntry {
            swatch: Swatch {
                mark: Some((mark, colour.to_string())),
                ..Swatch::default()
            },
            label: label.to_string(),
        }
    }

    /// An entry for markers joined by (or fitted with) a curve of the same colour.
    pub fn mark_line(label: &str, mark: Mark, stroke: &Stroke) -> Self {
        LegendEntry {
            swatch: Swatch {
                line: Some(stroke.clone()),
                mark: Some((mark, stroke.colour.clone())),
                patch: None,
            },
            label: label.to_string(),
        }
    }

    /// An entry for a shaded region.
    pub fn patch(label: &str, colour: &str, opacity: f64) -> Self {
        LegendEntry {
            swatch: Swatch {
                patch: Some((colour.to_string(), opacity)),
                ..Swatch::default()
            },
            label: label.to_string(),
        }
    }
}

/// One set of axes.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Title above the plot area (markup; empty: none).
    pub title: String,
    /// x axis.
    pub x: Axis,
    /// y axis.
    pub y: Axis,
    /// Content: shading (bands, fills, rectangles) first, then lines, then dots and markers
    /// with their error bars, then texts, each kind in the order given.
    pub items: Vec<Item>,
    /// The panel's own legend.
    pub legend: Vec<LegendEntry>,
}

impl Panel {
    /// A panel with title and axes.
    pub fn new(title: &str, x: Axis, y: Axis) -> Self {
        Panel {
            title: title.to_string(),
            x,
            y,
            ..Panel::default()
        }
    }

    /// Adds a curve.
    pub fn curve(&mut self, pts: Vec<(f64, f64)>, stroke: Stroke) {
        self.items.push(Item::Curve { pts, stroke });
    }

    /// Adds markers with error bars in `colour`.
    pub fn points(&mut self, pts: Vec<ErrPoint>, colour: &str, mark: Mark) {
        self.items.push(Item::Points {
            pts,
            colour: colour.to_string(),
            mark,
            radius: 4.5,
            fill_opacity: 0.35,
        });
    }

    /// Adds a shaded band (x, y_low, y_high), to sit under a curve.
    pub fn band(&mut self, pts: Vec<(f64, f64, f64)>, colour: &str, opacity: f64) {
        self.items.push(Item::Band {
            pts,
            colour: colour.to_string(),
            opacity,
        });
    }

    /// Data range of one axis over every item, on the axis's linear scale (log₁₀ for a log
    /// axis).
    fn data_range(&self, axis: &Axis, pick_x: bool) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut add = |v: f64| {
            let v = axis.to_lin(v);
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        };
        for it in &self.items {
            match it {
                Item::Curve { pts, .. } | Item::Fill { pts, .. } | Item::Dots { pts, .. } => {
                    for p in pts {
                        add(if pick_x { p.0 } else { p.1 });
                    }
                }
                Item::Segments { segs, .. } => {
                    for s in segs.iter().flatten() {
                        add(if pick_x { s.0 } else { s.1 });
                    }
                }
                Item::Points { pts, .. } => {
                    for p in pts {
                        if pick_x {
                            add(p.0);
                        } else {
                            add(p.1);
                            add(p.2);
                            add(p.3);
                        }
                    }
                }
                Item::Band { pts, .. } => {
                    for p in pts {
                        if pick_x {
                            add(p.0);
                        } else {
                            add(p.1);
                            add(p.2);
                        }
                    }
                }
                Item::Rects { rects, .. } => {
                    for r in rects {
                        if pick_x {
                            add(r.0);
                            add(r.1);
                        } else {
                            add(r.2);
                            add(r.3);
                        }
                    }
                }
                Item::HLine { y, .. } if !pick_x => add(*y),
                Item::VLine { x, .. } if pick_x => add(*x),
                _ => {}
            }
        }
        if !lo.is_finite() {
            return (0.0, 1.0);
        }
        if hi - lo < 1e-12 * lo.abs().max(1e-300) {
            let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
            return (lo - d, hi + d);
        }
        let pad = 0.04 * (hi - lo);
        (lo - pad, hi + pad)
    }

    fn range(&self, axis: &Axis, pick_x: bool) -> (f64, f64) {
        match axis.range {
            Some((a, b)) => (axis.to_lin(a), axis.to_lin(b)),
            None => self.data_range(axis, pick_x),
        }
    }
}

/// Tick positions (linear scale of the axis) and their labels.
fn ticks(axis: &Axis, lo: f64, hi: f64, target: usize) -> Vec<(f64, String)> {
    let target = if axis.ticks > 0 { axis.ticks } else { target }.max(2);
    if axis.scale == Scale::Log {
        let (a, b) = (lo.ceil() as i64, hi.floor() as i64);
        if b - a >= 2 {
            let step = (((b - a) as f64 / target as f64).ceil() as i64).max(1);
            return (a..=b)
                .filter(|k| (k - a) % step == 0)
                .map(|k| (k as f64, format!("10^{{{}}}", minus(&k.to_string()))))
                .collect();
        }
        // Less than two decades: 1, 2, 5 times powers of ten, written out.
        let mut out = Vec::new();
        for k in (lo.floor() as i64)..=(hi.ceil() as i64) {
            for m in [1.0, 2.0, 5.0] {
                let v = m * 10f64.powi(k as i32);
                let l = v.log10();
                if l >= lo - 1e-9 && l <= hi + 1e-9 {
                    out.push((l, linear_label(v, 10f64.powi(k as i32))));
                }
            }
        }
        return out;
    }
    let span = hi - lo;
    let raw = span / target as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= target as f64 + 0.5)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil();
    let mut out = Vec::new();
    let mut i = 0.0;
    loop {
        let v = (first + i) * step;
        if v > hi + 1e-9 * span {
            break;
        }
        let v = if v.abs() < 1e-12 * span { 0.0 } else { v };
        out.push((v, linear_label(v, step)));
        i += 1.0;
    }
    out
}

/// A tick label with the decimals `step` needs, and a true minus sign.
fn linear_label(v: f64, step: f64) -> String {
    let dec = (-(step.log10() + 1e-9).floor()).max(0.0) as usize;
    let dec = if (step * 10f64.powi(dec as i32)).fract().abs() > 1e-6 {
        dec + 1
    } else {
        dec
    };
    minus(&format!("{v:.dec$}"))
}

fn minus(s: &str) -> String {
    if s.trim_start_matches(['-', '0', '.']).is_empty() {
        return s.trim_start_matches('-').to_string();
    }
    s.replace('-', "\u{2212}")
}

/// A panel's layout: ranges, ticks and the room its labels take.
struct Layout {
    xr: (f64, f64),
    yr: (f64, f64),
    xt: Vec<(f64, String)>,
    yt: Vec<(f64, String)>,
    /// Room left of the plot area for tick labels and the y label.
    left: f64,
    /// Room below for tick labels and the x label.
    bottom: f64,
    /// Room above for the title.
    top: f64,
}

impl Layout {
    fn new(p: &Panel, w: f64, h: f64) -> Self {
        let xr = p.range(&p.x, true);
        let yr = p.range(&p.y, false);
        // Fewer x ticks until their labels leave room between them.
        let mut n = ((w / 90.0).round() as usize).max(2);
        let xt = loop {
            let t = ticks(&p.x, xr.0, xr.1, n);
            let widest = t
                .iter()
                .map(|l| text_width(&l.1, TICK_SIZE))
                .fold(0.0, f64::max);
            let spacing = w / (t.len().max(2) - 1) as f64 * 0.999;
            if widest + 12.0 < spacing || n <= 2 {
                break t;
            }
            n -= 1;
        };
        let yt = ticks(&p.y, yr.0, yr.1, ((h / 55.0).round() as usize).max(2));
        let ytw = if p.y.hide_tick_labels {
            0.0
        } else {
            yt.iter()
                .map(|l| text_width(&l.1, TICK_SIZE))
                .fold(0.0, f64::max)
        };
        let ylab = if p.y.label.is_empty() {
            0.0
        } else {
            line_height(LABEL_SIZE) + GAP
        };
        let xtick = if p.x.hide_tick_labels {
            0.0
        } else {
            line_height(TICK_SIZE)
        };
        let xlab = if p.x.label.is_empty() {
            0.0
        } else {
            line_height(LABEL_SIZE) + GAP
        };
        let top = if p.title.is_empty() {
            GAP
        } else {
            line_height(PANEL_TITLE_SIZE) + GAP
        };
        Layout {
            xr,
            yr,
            xt,
            yt,
            left: TICK_LEN + GAP + ytw + GAP + ylab,
            bottom: TICK_LEN + 3.0 + xtick + xlab + GAP,
            top,
        }
    }
}

/// Maps data to pixels inside a plot area.
#[derive(Debug, Clone, Copy)]
struct Frame {
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
    xr: (f64, f64),
    yr: (f64, f64),
    xs: Scale,
    ys: Scale,
}

impl Frame {
    fn px(&self, v: f64) -> f64 {
        let v = if self.xs == Scale::Log {
            if v > 0.0 {
                v.log10()
            } else {
                f64::NAN
            }
        } else {
            v
        };
        self.x0 + (v - self.xr.0) / (self.xr.1 - self.xr.0) * self.w
    }
    fn py(&self, v: f64) -> f64 {
        let v = if self.ys == Scale::Log {
            if v > 0.0 {
                v.log10()
            } else {
                f64::NAN
            }
        } else {
            v
        };
        self.y0 + self.h - (v - self.yr.0) / (self.yr.1 - self.yr.0) * self.h
    }
    fn p(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (self.px(x), self.py(y))
    }
}

/// Size of a legend box (w, h) for `entries`.
fn legend_size(entries: &[LegendEntry]) -> (f64, f64) {
    let w = entries
        .iter()
        .map(|e| text_width(&e.label, LEGEND_SIZE))
        .fold(0.0, f64::max);
    let row = line_height(LEGEND_SIZE) + 4.0;
    (
        SWATCH + 3.0 * GAP + w + GAP,
        entries.len() as f64 * row + 2.0 * GAP - 4.0,
    )
}

/// Draws a legend box with its top-left corner at (x, y).
fn draw_legend(svg: &mut Svg, entries: &[LegendEntry], x: f64, y: f64) {
    let (w, h) = legend_size(entries);
    svg.rect(
        (x, y, w, h),
        "#ffffff",
        0.92,
        Some(&Stroke::solid("#b0b0b0", 1.0)),
    );
    let row = line_height(LEGEND_SIZE) + 4.0;
    for (i, e) in entries.iter().enumerate() {
        let top = y + GAP + i as f64 * row;
        let mid = top + line_height(LEGEND_SIZE) / 2.0;
        let sx = x + GAP;
        if let Some((c, o)) = &e.swatch.patch {
            svg.rect((sx, mid - 6.0, SWATCH, 12.0), c, *o, None);
        }
        if let Some(s) = &e.swatch.line {
            svg.polyline(&[(sx, mid), (sx + SWATCH, mid)], s);
        }
        if let Some((m, c)) = &e.swatch.mark {
            svg.marker(*m, (sx + SWATCH / 2.0, mid), 4.5, c, 0.35);
        }
        svg.text(
            (sx + SWATCH + 2.0 * GAP, top + ascent(LEGEND_SIZE)),
            &e.label,
            LEGEND_SIZE,
            Anchor::Start,
            false,
            INK,
        );
    }
}

/// Cells of a coarse occupancy grid over a plot area.
struct Occupancy {
    cell: f64,
    nx: usize,
    ny: usize,
    full: Vec<bool>,
}

impl Occupancy {
    fn new(w: f64, h: f64) -> Self {
        let cell = 4.0;
        let nx = (w / cell).ceil() as usize + 1;
        let ny = (h / cell).ceil() as usize + 1;
        Occupancy {
            cell,
            nx,
            ny,
            full: vec![false; nx * ny],
        }
    }
    /// Marks a disc of radius `r` around (x, y) (plot-area pixels).
    fn mark(&mut self, x: f64, y: f64, r: f64) {
        if !(x.is_finite() && y.is_finite()) {
            return;
        }
        let c = self.cell;
        let i0 = ((x - r) / c).floor().max(0.0);
        let i1 = ((x + r) / c).floor().min(self.nx as f64 - 1.0);
        let j0 = ((y - r) / c).floor().max(0.0);
        let j1 = ((y + r) / c).floor().min(self.ny as f64 - 1.0);
        if i1 < i0 || j1 < j0 {
            return;
        }
        for j in j0 as usize..=j1 as usize {
            for i in i0 as usize..=i1 as usize {
                self.full[j * self.nx + i] = true;
            }
        }
    }
    /// Marks a segment, sampled every half cell.
    fn segment(&mut self, a: (f64, f64), b: (f64, f64), r: f64) {
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        if !len.is_finite() {
            return;
        }
        let n = (len / (self.cell / 2.0)).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            self.mark(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), r);
        }
    }
    /// Whether a box (plot-area pixels) touches a marked cell.
    fn any(&self, x: f64, y: f64, w: f64, h: f64) -> bool {
        let c = self.cell;
        let i0 = (x / c).floor().max(0.0) as usize;
        let i1 = (((x + w) / c).floor().max(0.0) as usize).min(self.nx - 1);
        let j0 = (y / c).floor().max(0.0) as usize;
        let j1 = (((y + h) / c).floor().max(0.0) as usize).min(self.ny - 1);
        (j0..=j1).any(|j| (i0..=i1).any(|i| self.full[j * self.nx + i]))
    }
}

impl Panel {
    /// Occupancy of the plot area by curves, points, lines and texts (not by shading).
    fn occupancy(&self, f: &Frame) -> Occupancy {
        let mut o = Occupancy::new(f.w, f.h);
        let loc = |p: (f64, f64)| (f.px(p.0) - f.x0, f.py(p.1) - f.y0);
        for it in &self.items {
            match it {
                Item::Curve { pts, .. } => {
                    for w in pts.windows(2) {
                        o.segment(loc(w[0]), loc(w[1]), 3.0);
                    }
                }
                Item::Segments { segs, .. } => {
                    for s in segs {
                        o.segment(loc(s[0]), loc(s[1]), 3.0);
                    }
                }
                Item::Dots { pts, radius, .. } => {
                    for &p in pts {
                        let c = loc(p);
                        o.mark(c.0, c.1, radius + 1.0);
                    }
                }
                Item::Points { pts, radius, .. } => {
                    for p in pts {
                        let c = loc((p.0, p.1));
                        o.mark(c.0, c.1, radius + 3.0);
                        if p.2.is_finite() && p.3.is_finite() {
                            o.segment(loc((p.0, p.2)), loc((p.0, p.3)), 5.0);
                        }
                    }
                }
                Item::HLine { y, .. } => {
                    let py = f.py(*y) - f.y0;
                    o.segment((0.0, py), (f.w, py), 3.0);
                }
                Item::VLine { x, .. } => {
                    let px = f.px(*x) - f.x0;
                    o.segment((px, 0.0), (px, f.h), 3.0);
                }
                Item::Text {
                    at, text, anchor, ..
                } => {
                    let (x, y) = loc(*at);
                    let w = text_width(text, TICK_SIZE);
                    let x0 = match anchor {
                        Anchor::Start => x,
                        Anchor::Middle => x - w / 2.0,
                        Anchor::End => x - w,
                    };
                    let mut yy = y - ascent(TICK_SIZE);
                    while yy < y + descent(TICK_SIZE) {
                        o.segment((x0, yy), (x0 + w, yy), 3.0);
                        yy += 2.0;
                    }
                }
                _ => {}
            }
        }
        o
    }

    /// Where the legend goes: inside the plot area at (x, y) (offsets from its top-left
    /// corner) when a corner is free of data, else `None` (outside).
    fn legend_spot(&self, f: &Frame) -> Option<(f64, f64)> {
        if self.legend.is_empty() {
            return None;
        }
        let (w, h) = legend_size(&self.legend);
        let inset = 8.0;
        if w + 2.0 * inset > f.w || h + 2.0 * inset > f.h {
            return None;
        }
        let o = self.occupancy(f);
        let (l, r) = (inset, f.w - w - inset);
        let (t, b) = (inset, f.h - h - inset);
        let c = (f.w - w) / 2.0;
        [(r, t), (l, t), (r, b), (l, b), (c, t), (c, b)]
            .into_iter()
            .find(|&(x, y)| !o.any(x - 2.0, y - 2.0, w + 4.0, h + 4.0))
    }

    /// Draws the panel with its plot area at (x0, y0), size w × h; `legend_out` is where an
    /// outside legend goes (left edge x, top y).
    fn draw(&self, svg: &mut Svg, lay: &Layout, f: Frame, legend_out: (f64, f64)) {
        self.draw_grid(svg, lay, &f);
        svg.begin_clip(f.x0, f.y0, f.w, f.h);
        // Shading first, then lines, then points, then texts.
        self.draw_shading(svg, &f);
        self.draw_lines(svg, &f);
        self.draw_marks(svg, &f);
        svg.end_group();
        self.draw_texts(svg, &f);
        self.draw_axes(svg, lay, &f);
        match self.legend_spot(&f) {
            Some((x, y)) => draw_legend(svg, &self.legend, f.x0 + x, f.y0 + y),
            None if !self.legend.is_empty() => {
                draw_legend(svg, &self.legend, legend_out.0, legend_out.1)
            }
            None => {}
        }
    }

    /// The grid lines at the ticks.
    fn draw_grid(&self, svg: &mut Svg, lay: &Layout, f: &Frame) {
        let grid = Stroke::solid(GRID, 1.0);
        for (v, _) in &lay.xt {
            let x = f.x0 + (v - f.xr.0) / (f.xr.1 - f.xr.0) * f.w;
            svg.polyline(&[(x, f.y0), (x, f.y0 + f.h)], &grid);
        }
        for (v, _) in &lay.yt {
            let y = f.y0 + f.h - (v - f.yr.0) / (f.yr.1 - f.yr.0) * f.h;
            svg.polyline(&[(f.x0, y), (f.x0 + f.w, y)], &grid);
        }
    }

    /// The shading: bands, fills and rectangles.
    fn draw_shading(&self, svg: &mut Svg, f: &Frame) {
        for it in &self.items {
            match it {
                Item::Band {
                    pts,
                    colour,
                    opacity,
                } => {
                    for seg in pts
                        .split(|p| !(p.0.is_finite() && p.1.is_finite() && p.2.is_finite()))
                        .filter(|s| s.len() > 1)
                    {
                        let mut poly: Vec<(f64, f64)> =
                            seg.iter().map(|p| f.p((p.0, p.2))).collect();
                        poly.extend(seg.iter().rev().map(|p| f.p((p.0, p.1))));
                        svg.polygon(&poly, colour, *opacity);
                    }
                }
                Item::Fill {
                    pts,
                    colour,
                    opacity,
                } => {
                    let poly: Vec<(f64, f64)> = pts.iter().map(|&p| f.p(p)).collect();
                    svg.polygon(&poly, colour, *opacity);
                }
                Item::Rects { rects, colour } => {
                    for r in rects {
                        let (a, b) = (f.px(r.0), f.px(r.1));
                        let (c, d) = (f.py(r.3), f.py(r.2));
                        svg.rect((a, c, b - a, d - c), colour, r.4, None);
                    }
                }
                _ => {}
            }
        }
    }

    /// The lines: curves, segments and horizontal and vertical lines.
    fn draw_lines(&self, svg: &mut Svg, f: &Frame) {
        for it in &self.items {
            match it {
                Item::Curve { pts, stroke } => {
                    let px: Vec<(f64, f64)> = pts.iter().map(|&p| f.p(p)).collect();
                    for seg in px
                        .split(|p| !(p.0.is_finite() && p.1.is_finite()))
                        .filter(|s| s.len() > 1)
                    {
                        svg.polyline(seg, stroke);
                    }
                }
                Item::Segments { segs, stroke } => {
                    let px: Vec<[(f64, f64); 2]> =
                        segs.iter().map(|s| [f.p(s[0]), f.p(s[1])]).collect();
                    svg.segments(&px, stroke);
                }
                Item::HLine { y, stroke } => {
                    let py = f.py(*y);
                    if py.is_finite() {
                        svg.polyline(&[(f.x0, py), (f.x0 + f.w, py)], stroke);
                    }
                }
                Item::VLine { x, stroke } => {
                    let px = f.px(*x);
                    if px.is_finite() {
                        svg.polyline(&[(px, f.y0), (px, f.y0 + f.h)], stroke);
                    }
                }
                _ => {}
            }
        }
    }

    /// The marks: dots, then points with their error bars.
    fn draw_marks(&self, svg: &mut Svg, f: &Frame) {
        for it in &self.items {
            if let Item::Dots {
                pts,
                colour,
                radius,
            } = it
            {
                let px: Vec<(f64, f64)> = pts.iter().map(|&p| f.p(p)).collect();
                svg.dots(&px, *radius, colour);
            }
        }
        for it in &self.items {
            if let Item::Points {
                pts,
                colour,
                mark,
                radius,
                fill_opacity,
            } = it
            {
                let bar = Stroke::solid(colour, 1.6);
                for p in pts {
                    let c = f.p((p.0, p.1));
                    if c.0.is_finite() && c.1.is_finite() {
                        svg.marker(*mark, c, *radius, colour, *fill_opacity);
                    }
                }
                for p in pts {
                    let (x, lo, hi) = (f.px(p.0), f.py(p.2), f.py(p.3));
                    if x.is_finite() && lo.is_finite() && hi.is_finite() && (lo - hi).abs() > 0.5 {
                        let cap = 4.0;
                        svg.segments(
                            &[
                                [(x, lo), (x, hi)],
                                [(x - cap, lo), (x + cap, lo)],
                                [(x - cap, hi), (x + cap, hi)],
                            ],
                            &bar,
                        );
                    }
                }
            }
        }
    }

    /// The texts placed in data coordinates.
    fn draw_texts(&self, svg: &mut Svg, f: &Frame) {
        for it in &self.items {
            if let Item::Text {
                at,
                text,
                anchor,
                colour,
            } = it
            {
                svg.text(f.p(*at), text, TICK_SIZE, *anchor, false, colour);
            }
        }
    }

    /// The frame, the ticks and their labels, the axis labels and the title.
    fn draw_axes(&self, svg: &mut Svg, lay: &Layout, f: &Frame) {
        svg.rect(
            (f.x0, f.y0, f.w, f.h),
            "none",
            0.0,
            Some(&Stroke::solid(FRAME, 1.0)),
        );
        let tick = Stroke::solid(FRAME, 1.0);
        for (v, l) in &lay.xt {
            let x = f.x0 + (v - f.xr.0) / (f.xr.1 - f.xr.0) * f.w;
            svg.polyline(&[(x, f.y0 + f.h), (x, f.y0 + f.h + TICK_LEN)], &tick);
            if !self.x.hide_tick_labels {
                let y = f.y0 + f.h + TICK_LEN + 3.0 + ascent(TICK_SIZE);
                svg.text((x, y), l, TICK_SIZE, Anchor::Middle, false, INK);
            }
        }
        for (v, l) in &lay.yt {
            let y = f.y0 + f.h - (v - f.yr.0) / (f.yr.1 - f.yr.0) * f.h;
            svg.polyline(&[(f.x0 - TICK_LEN, y), (f.x0, y)], &tick);
            if !self.y.hide_tick_labels {
                let base = y + ascent(TICK_SIZE) * 0.36;
                svg.text(
                    (f.x0 - TICK_LEN - GAP, base),
                    l,
                    TICK_SIZE,
                    Anchor::End,
                    false,
                    INK,
                );
            }
        }
        if !self.x.label.is_empty() {
            let y = f.y0 + f.h + lay.bottom - GAP - descent(LABEL_SIZE);
            svg.text(
                (f.x0 + f.w / 2.0, y),
                &self.x.label,
                LABEL_SIZE,
                Anchor::Middle,
                false,
                INK,
            );
        }
        if !self.y.label.is_empty() {
            let x = f.x0 - lay.left + ascent(LABEL_SIZE);
            svg.text(
                (x, f.y0 + f.h / 2.0),
                &self.y.label,
                LABEL_SIZE,
                Anchor::Middle,
                true,
                INK,
            );
        }
        if !self.title.is_empty() {
            svg.text(
                (f.x0 + f.w / 2.0, f.y0 - GAP - descent(PANEL_TITLE_SIZE)),
                &self.title,
                PANEL_TITLE_SIZE,
                Anchor::Middle,
                false,
                INK,
            );
        }
    }
}

/// A grid of panels under a title, with an optional shared legend to the right.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Title (markup; empty: none).
    pub title: String,
    /// Columns of the grid.
    pub cols: usize,
    /// Size of every plot area (w, h), px.
    pub plot: (f64, f64),
    /// Panels, row by row; `None` leaves a cell empty.
    pub panels: Vec<Option<Panel>>,
    /// The legend shared by the panels.
    pub legend: Vec<LegendEntry>,
    /// Lines of small print under the grid (markup).
    pub notes: Vec<String>,
    /// The width the figure is printed at, mm (`None`: its natural size, a px to the CSS
    /// pixel). The figure is then laid out ([`Figure::fitted`]) no wider than lets its
    /// smallest text, [`TICK_SIZE`] px, print at [`MIN_PRINT_PT`] or larger, and its SVG
    /// document is sized in mm.
    pub print_width_mm: Option<f64>,
    /// The panels of a row share the y axis of its first panel: the others draw neither its
    /// label nor its tick labels (their ranges must be the same).
    pub share_y: bool,
    /// The shared legend under the grid (set by [`Figure::fitted`]).
    legend_below: bool,
}

/// The smallest text size of a figure printed at its [`Figure::print_width_mm`], pt.
pub const MIN_PRINT_PT: f64 = 7.0;

/// The narrowest plot area a figure is shrunk to, px.
const MIN_PLOT: f64 = 150.0;

/// The narrowest plot area a grid keeps its columns for when shrunk, px.
const COMFORTABLE_PLOT: f64 = 170.0;

impl Figure {
    /// A figure of `panels` in `cols` columns with plot areas of `plot` px.
    pub fn new(title: &str, cols: usize, plot: (f64, f64), panels: Vec<Panel>) -> Self {
        Figure {
            title: title.to_string(),
            cols: cols.max(1),
            plot,
            panels: panels.into_iter().map(Some).collect(),
            legend: Vec::new(),
            notes: Vec::new(),
            print_width_mm: None,
            share_y: false,
            legend_below: false,
        }
    }

    /// Width and height of the figure, whole px.
    pub fn size(&self) -> (f64, f64) {
        let g = self.fitted().grid();
        (g.width.ceil(), g.height.ceil())
    }

    /// The widest layout, px, whose [`TICK_SIZE`] text prints at [`MIN_PRINT_PT`] or larger
    /// when the figure is `print_mm` wide.
    pub fn max_layout_width(print_mm: f64) -> f64 {
        print_mm * TICK_SIZE / (MIN_PRINT_PT * 25.4 / 72.0)
    }

    /// The figure laid out for its [`Figure::print_width_mm`]: a grid without empty cells first
    /// loses columns, then its plot areas narrow (their aspect kept, down to [`MIN_PLOT`]
    /// px); the shared legend moves under the grid, and the title and notes are broken into
    /// lines at spaces. Without a maximum, or when the figure fits, the figure as it is.
    pub fn fitted(&self) -> Figure {
        let mut f = self.clone();
        f.print_width_mm = None;
        if let Some(max) = self.print_width_mm {
            f.fit_within(Figure::max_layout_width(max).floor());
        }
        f.apply_share_y();
        f
    }

    /// With [`Figure::share_y`]: the y labels and tick labels of every panel but the first of
    /// each row removed (and the flag cleared).
    fn apply_share_y(&mut self) {
        if !self.share_y {
            return;
        }
        self.share_y = false;
        let cols = self.cols;
        for (i, p) in self.panels.iter_mut().enumerate() {
            if let Some(p) = p.as_mut().filter(|_| i % cols != 0) {
                p.y.label.clear();
                p.y.hide_tick_labels = true;
            }
        }
    }

    /// Lays the figure out again within `max` px (see [`Figure::fitted`]).
    fn fit_within(&mut self, max: f64) {
        let f = self;
        f.title = wrap(&f.title, TITLE_SIZE, max - 4.0 * GAP);
        f.notes = f
            .notes
            .iter()
            .flat_map(|n| {
                wrap(n, LEGEND_SIZE, max - 4.0 * GAP)
                    .split('\n')
                    .map(str::to_string)
                    .collect::<Vec<_>>()
            })
            .collect();
        if f.grid().width <= max {
            return;
        }
        f.legend_below = true;
        // The most columns whose plot areas stay at least COMFORTABLE_PLOT px wide (one column
        // when none does; a grid with empty cells, a corner plot, keeps its columns).
        let reflow = f.panels.iter().all(Option::is_some);
        let (w0, h0) = f.plot;
        let shrunk = |f: &Figure| -> f64 {
            let mut g = f.clone();
            g.apply_share_y();
            for _ in 0..4 {
                let width = g.grid().width;
                if width <= max || g.plot.0 <= MIN_PLOT {
                    break;
                }
                // The width is the columns' plot areas plus margins that do not scale with them.
                let fixed = width - g.cols as f64 * g.plot.0;
                let w = ((max - fixed) / g.cols as f64).clamp(MIN_PLOT, g.plot.0);
                g.plot = (w, h0);
            }
            g.plot.0
        };
        while reflow && f.cols > 1 && shrunk(f) < COMFORTABLE_PLOT.min(w0) {
            f.cols -= 1;
        }
        let w = shrunk(f);
        // The aspect kept, but never shorter than the longest y label needs.
        let y_label = f
            .panels
            .iter()
            .flatten()
            .map(|p| text_width(&p.y.label, LABEL_SIZE) + 2.0 * GAP)
            .fold(0.0, f64::max);
        f.plot = (w, (h0 * w / w0).max(y_label.min(h0)));
    }

    /// Panels whose legend cannot sit inside widen their column on the right (or, with the
    /// legends below, deepen their row): `right` and `bottom` grow, per column and row, given
    /// the panels' layouts `lays` and the columns' `left` margins.
    fn make_room_for_legends(
        &self,
        lays: &[Option<Layout>],
        left: &[f64],
        right: &mut [f64],
        bottom: &mut [f64],
    ) {
        let (w, h) = self.plot;
        let cols = self.cols;
        for (i, (p, l)) in self.panels.iter().zip(lays).enumerate() {
            let (Some(p), Some(l)) = (p, l) else { continue };
            if p.legend.is_empty() {
                continue;
            }
            let f = Frame {
                x0: 0.0,
                y0: 0.0,
                w,
                h,
                xr: l.xr,
                yr: l.yr,
                xs: p.x.scale,
                ys: p.y.scale,
            };
            if p.legend_spot(&f).is_none() {
                let (r, c) = (i / cols, i % cols);
                let (lw, lh) = legend_size(&p.legend);
                if self.legend_below {
                    bottom[r] = bottom[r].max(l.bottom + lh + 2.0 * GAP);
                    right[c] = right[c].max(lw + GAP - left[c] - w);
                } else {
                    right[c] = right[c].max(lw + 3.0 * GAP);
                }
            }
        }
    }

    fn grid(&self) -> Grid {
        let (w, h) = self.plot;
        let cols = self.cols;
        let rows = self.panels.len().div_ceil(cols).max(1);
        let lays: Vec<Option<Layout>> = self
            .panels
            .iter()
            .map(|p| p.as_ref().map(|p| Layout::new(p, w, h)))
            .collect();
        let mut left = vec![0.0f64; cols];
        let mut right = vec![GAP * 2.0; cols];
        let mut top = vec![0.0f64; rows];
        let mut bottom = vec![0.0f64; rows];
        for (i, l) in lays.iter().enumerate() {
            let (r, c) = (i / cols, i % cols);
            if let Some(l) = l {
                left[c] = left[c].max(l.left);
                top[r] = top[r].max(l.top);
                bottom[r] = bottom[r].max(l.bottom);
            }
        }
        self.make_room_for_legends(&lays, &left, &mut right, &mut bottom);
        let title_h = if self.title.is_empty() {
            GAP
        } else {
            self.title.lines().count() as f64 * line_height(TITLE_SIZE) + 2.0 * GAP
        };
        let mut xs = vec![GAP; cols];
        let mut x = GAP;
        for c in 0..cols {
            xs[c] = x + left[c];
            x += left[c] + w + right[c];
        }
        let mut ys = vec![0.0; rows];
        let mut y = title_h;
        for r in 0..rows {
            ys[r] = y + top[r];
            y += top[r] + h + bottom[r];
        }
        let grid_w = x;
        let (lw, lh) = if self.legend.is_empty() {
            (0.0, 0.0)
        } else {
            legend_size(&self.legend)
        };
        let notes_h = self.notes.len() as f64 * (line_height(LEGEND_SIZE) + 2.0);
        let notes_w = self
            .notes
            .iter()
            .map(|n| text_width(n, LEGEND_SIZE) + 4.0 * GAP)
            .fold(0.0, f64::max);
        // The shared legend goes into empty cells when it fits there — those that end the last
        // row, or those that end the first (above a corner plot's diagonal) — else to the
        // right of the grid.
        let used_last = self.panels.len() - (rows - 1) * cols;
        let used_first = cols
            - self.panels[..cols.min(self.panels.len())]
                .iter()
                .rev()
                .take_while(|p| p.is_none())
                .count();
        let cells = |row: usize, used: usize| -> Option<(f64, f64, f64, f64)> {
            (used > 0 && used < cols).then(|| {
                let x0 = xs[used] - left[used];
                (
                    x0 + 2.0 * GAP,
                    ys[row],
                    grid_w - x0 - 2.0 * GAP,
                    h + bottom[row],
                )
            })
        };
        let fits = |c: Option<(f64, f64, f64, f64)>| {
            c.filter(|&(_, _, aw, ah)| lw + GAP <= aw && lh <= ah)
                .map(|c| (c.0, c.1))
        };
        let legend_at = if lw > 0.0 {
            fits(cells(rows - 1, used_last)).or_else(|| fits(cells(0, used_first)))
        } else {
            Some((0.0, 0.0))
        };
        let title_w = self
            .title
            .lines()
            .map(|l| text_width(l, TITLE_SIZE) + 4.0 * GAP)
            .fold(0.0, f64::max);
        let (legend_at, width, notes_y) = match legend_at {
            // Under the grid, the notes under it.
            None if self.legend_below => (
                (2.0 * GAP, y + GAP),
                (grid_w + GAP).max(lw + 4.0 * GAP),
                y + lh + 2.0 * GAP,
            ),
            None => ((grid_w + GAP, ys[0]), grid_w + lw + 3.0 * GAP, y),
            Some(at) => (at, grid_w + GAP, y),
        };
        let width = width.max(notes_w).max(title_w);
        let height = (notes_y + notes_h + GAP).max(title_h + lh + 2.0 * GAP);
        Grid {
            lays,
            xs,
            ys,
            legend_at,
            notes_y,
            width,
            height,
        }
    }

    /// Draws the figure with its top-left corner at (x, y) of `svg`.
    pub fn draw(&self, svg: &mut Svg, x: f64, y: f64) {
        if self.print_width_mm.is_some() || self.share_y {
            return self.fitted().draw(svg, x, y);
        }
        let g = self.grid();
        let (w, h) = self.plot;
        svg.begin_translate(x, y);
        for (k, line) in self.title.lines().enumerate() {
            svg.text(
                (
                    g.width / 2.0,
                    GAP + ascent(TITLE_SIZE) + k as f64 * line_height(TITLE_SIZE),
                ),
                line,
                TITLE_SIZE,
                Anchor::Middle,
                false,
                INK,
            );
        }
        for (i, (p, l)) in self.panels.iter().zip(&g.lays).enumerate() {
            let (Some(p), Some(l)) = (p, l) else { continue };
            let (r, c) = (i / self.cols, i % self.cols);
            let f = Frame {
                x0: g.xs[c],
                y0: g.ys[r],
                w,
                h,
                xr: l.xr,
                yr: l.yr,
                xs: p.x.scale,
                ys: p.y.scale,
            };
            let legend_out = if self.legend_below {
                (g.xs[c] - l.left + GAP, g.ys[r] + h + l.bottom + GAP)
            } else {
                (g.xs[c] + w + 2.0 * GAP, g.ys[r])
            };
            p.draw(svg, l, f, legend_out);
        }
        if !self.legend.is_empty() {
            draw_legend(svg, &self.legend, g.legend_at.0, g.legend_at.1);
        }
        for (k, n) in self.notes.iter().enumerate() {
            let yy =
                g.notes_y + (k as f64) * (line_height(LEGEND_SIZE) + 2.0) + ascent(LEGEND_SIZE);
            svg.text((2.0 * GAP, yy), n, LEGEND_SIZE, Anchor::Start, false, INK);
        }
        svg.end_group();
    }

    /// The figure as an SVG document.
    pub fn to_svg(&self) -> String {
        let (w, h) = self.size();
        let mut svg = Svg::new(w, h);
        svg.print_width_mm = self.print_width_mm;
        self.draw(&mut svg, 0.0, 0.0);
        svg.finish()
    }
}

/// `markup` broken into lines (joined by '\n') at spaces outside `{…}` groups, each line at
/// most `max` px wide at `size` where a break allows.
fn wrap(markup: &str, size: f64, max: f64) -> String {
    if text_width(markup, size) <= max {
        return markup.to_string();
    }
    let mut words = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (i, c) in markup.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ' ' if depth == 0 => {
                words.push(&markup[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    words.push(&markup[start..]);
    let greedy = |limit: f64| {
        let mut lines: Vec<String> = Vec::new();
        for w in &words {
            match lines.last_mut() {
                Some(l) if text_width(&format!("{l} {w}"), size) <= limit => {
                    l.push(' ');
                    l.push_str(w);
                }
                _ => lines.push(w.to_string()),
            }
        }
        lines
    };
    // As few lines as the greedy fill at `max`, of about equal widths.
    let n = greedy(max).len();
    let mut limit = text_width(markup, size) / n as f64;
    while limit < max && greedy(limit).len() > n {
        limit *= 1.05;
    }
    greedy(limit.min(max)).join("\n")
}

/// Figures one under the other in one document.
pub fn stack_svg(figs: &[Figure]) -> String {
    let sizes: Vec<(f64, f64)> = figs.iter().map(Figure::size).collect();
    let w = sizes.iter().map(|s| s.0).fold(100.0, f64::max);
    let h: f64 = sizes.iter().map(|s| s.1).sum::<f64>().max(100.0);
    let mut svg = Svg::new(w, h);
    svg.print_width_mm = figs.iter().find_map(|f| f.print_width_mm);
    let mut y = 0.0;
    for (f, s) in figs.iter().zip(&sizes) {
        f.draw(&mut svg, 0.0, y);
        y += s.1;
    }
    svg.finish()
}

struct Grid {
    lays: Vec<Option<Layout>>,
    xs: Vec<f64>,
    ys: Vec<f64>,
    legend_at: (f64, f64),
    /// Top of the notes.
    notes_y: f64,
    width: f64,
    height: f64,
}

/// Dash patterns for curves that lie on an earlier one, in turn.
pub const DASHES: [&str; 3] = ["9 6", "3 5", "12 4 3 4"];

/// Whether curve `b` lies on curve `a` within `tol` (data units of y) over at least 90 % of
/// the x where both are defined (a linearly interpolated at b's samples).
pub fn coincide(a: &[(f64, f64)], b: &[(f64, f64)], tol: f64) -> bool {
    let at = |x: f64| -> Option<f64> {
        a.windows(2).find_map(|w| {
            let (p, q) = (w[0], w[1]);
            let inside = (p.0 <= x && x <= q.0) || (q.0 <= x && x <= p.0);
            if !(inside && p.1.is_finite() && q.1.is_finite()) {
                return None;
            }
            let t = if q.0 == p.0 {
                0.0
            } else {
                (x - p.0) / (q.0 - p.0)
            };
            Some(p.1 + t * (q.1 - p.1))
        })
    };
    let (mut both, mut close) = (0usize, 0usize);
    for &(x, y) in b.iter().filter(|p| p.1.is_finite()) {
        if let Some(ya) = at(x) {
            both += 1;
            if (ya - y).abs() <= tol {
                close += 1;
            }
        }
    }
    both >= 2 && close as f64 >= 0.9 * both as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_round() {
        let t = ticks(&Axis::new("x"), 0.13, 0.87, 5);
        let v: Vec<&str> = t.iter().map(|p| p.1.as_str()).collect();
        assert_eq!(v, ["0.2", "0.4", "0.6", "0.8"]);
        let t = ticks(&Axis::new("x"), -2.2, 2.2, 5);
        assert_eq!(t[0].1, "\u{2212}2");
        assert!(t.iter().any(|p| p.1 == "0"));
    }

    #[test]
    fn short_log_ranges_get_written_out_ticks() {
        let t = ticks(&Axis::log("x"), 1.7, 3.75, 6);
        let v: Vec<&str> = t.iter().map(|p| p.1.as_str()).collect();
        assert_eq!(v, ["100", "200", "500", "1000", "2000", "5000"]);
    }

    #[test]
    fn log_ticks_are_decades() {
        let t = ticks(&Axis::log("x"), -3.2, 1.1, 6);
        let v: Vec<&str> = t.iter().map(|p| p.1.as_str()).collect();
        assert_eq!(
            v,
            [
                "10^{\u{2212}3}",
                "10^{\u{2212}2}",
                "10^{\u{2212}1}",
                "10^{0}",
                "10^{1}"
            ]
        );
    }

    #[test]
    fn coincident_curves_are_found() {
        let a: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, (i as f64).sqrt())).collect();
        let b: Vec<(f64, f64)> = a
            .iter()
            .map(|p| (p.0 + 0.5, (p.0 + 0.5).sqrt() + 1e-3))
            .collect();
        assert!(coincide(&a, &b, 0.01));
        let c: Vec<(f64, f64)> = a.iter().map(|p| (p.0, p.1 + 0.5)).collect();
        assert!(!coincide(&a, &c, 0.01));
    }
}
