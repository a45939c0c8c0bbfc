//! SVG figures drawn with plotters' SVG backend (no font files needed: text is emitted as SVG
//! `<text>` elements and laid out by the viewer).

use crate::fit::posterior::draws_column;
use crate::fit::summary::FitResult;
use plotters::prelude::*;

/// One series of points with optional vertical error bars, and an optional horizontal
/// reference line drawn in the same colour.
#[derive(Debug, Clone, Default)]
pub struct PointSeries {
    /// Legend label.
    pub label: String,
    /// (x, y, y_low, y_high) per point; y_low/y_high equal y when there is no interval.
    pub points: Vec<(f64, f64, f64, f64)>,
    /// A horizontal reference line y = value, with its own legend label.
    pub reference: Option<(f64, String)>,
}

/// A scatter figure: title, axis labels, series.
#[derive(Debug, Clone, Default)]
pub struct Scatter {
    /// Caption above the plot.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// The data.
    pub series: Vec<PointSeries>,
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.05 };
    (lo - pad, hi + pad)
}

/// Renders the figure to an SVG document (800 × 560 px).
pub fn scatter_svg(fig: &Scatter) -> Result<String, String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (800, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let xs = fig.series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
        let ys = fig.series.iter().flat_map(|s| {
            s.points
                .iter()
                .flat_map(|p| [p.1, p.2, p.3])
                .chain(s.reference.iter().map(|r| r.0))
        });
        let (x0, x1) = range(xs);
        let (y0, y1) = range(ys.collect::<Vec<_>>().into_iter());
        let mut chart = ChartBuilder::on(&root)
            .caption(&fig.title, ("sans-serif", 20))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(&fig.x_label)
            .y_desc(&fig.y_label)
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, s) in fig.series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .map(|p| (p.0, p.1))
                .collect();
            chart
                .draw_series(
                    s.points
                        .iter()
                        .filter(|p| p.0.is_finite() && p.2.is_finite() && p.3.is_finite())
                        .filter(|p| p.3 > p.2)
                        .map(|p| PathElement::new(vec![(p.0, p.2), (p.0, p.3)], colour)),
                )
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(|e| e.to_string())?
                .label(s.label.clone())
                .legend(move |(x, y)| Circle::new((x, y), 4, colour.filled()));
            if let Some((y, label)) = &s.reference {
                chart
                    .draw_series(LineSeries::new(
                        vec![(x0, *y), (x1, *y)],
                        colour.stroke_width(1),
                    ))
                    .map_err(|e| e.to_string())?
                    .label(label.clone())
                    .legend(move |(x, yy)| PathElement::new(vec![(x, yy), (x + 16, yy)], colour));
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// The pooled draws of one posterior, for [`corner_svg`].
#[derive(Debug, Clone, Default)]
pub struct CornerBlock {
    /// Heading (fit and series).
    pub title: String,
    /// Parameter names.
    pub names: Vec<String>,
    /// Draws per parameter (same length for every parameter).
    pub draws: Vec<Vec<f64>>,
}

impl CornerBlock {
    /// One block per posterior that kept draws; parameters named as in the draws file
    /// ([`draws_column`]).
    pub fn from_posteriors(posteriors: &[&FitResult]) -> Vec<CornerBlock> {
        posteriors
            .iter()
            .filter_map(|p| {
                let d = p.draws.as_ref()?;
                let draws: Vec<Vec<f64>> = (0..p.params.len())
                    .map(|j| d.chains.iter().flatten().map(|x| x[j]).collect())
                    .collect();
                draws
                    .first()
                    .is_some_and(|v| !v.is_empty())
                    .then(|| CornerBlock {
                        title: if d.interrupted {
                            format!("{} [{}] (interrupted)", p.stats.fit, p.stats.series)
                        } else {
                            format!("{} [{}]", p.stats.fit, p.stats.series)
                        },
                        names: p.params.iter().map(|r| draws_column(p, r)).collect(),
                        draws,
                    })
            })
            .collect()
    }
}

/// Side of one corner-plot panel, px.
const PANEL: u32 = 190;
/// Height of a block's heading, px.
const HEADING: u32 = 30;
/// Histogram bins of the marginals.
const BINS: usize = 30;
/// Points drawn per scatter panel at most (an even stride through the draws).
const MAX_SCATTER: usize = 2000;

/// Renders corner plots (marginal histograms on the diagonal, pairwise scatter below it), one
/// block per posterior, stacked vertically in one SVG document.
pub fn corner_svg(blocks: &[CornerBlock]) -> Result<String, String> {
    let n_max = blocks
        .iter()
        .map(|b| b.names.len())
        .max()
        .unwrap_or(1)
        .max(1) as u32;
    let width = (n_max * PANEL).max(400) + 20;
    let height: u32 = blocks
        .iter()
        .map(|b| HEADING + b.names.len().max(1) as u32 * PANEL)
        .sum::<u32>()
        .max(100)
        + 10;
    let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let mut top = 5i32;
        for b in blocks {
            let n = b.names.len();
            root.draw(&Text::new(
                b.title.clone(),
                (12, top + 8),
                ("sans-serif", 16).into_font(),
            ))
            .map_err(e)?;
            top += HEADING as i32;
            let ranges: Vec<(f64, f64)> =
                b.draws.iter().map(|d| range(d.iter().copied())).collect();
            let len = b.draws.first().map_or(0, Vec::len);
            let stride = len.div_ceil(MAX_SCATTER).max(1);
            for r in 0..n {
                for c in 0..=r {
                    let area = root.clone().shrink(
                        (10 + c as u32 * PANEL, top as u32 + r as u32 * PANEL),
                        (PANEL, PANEL),
                    );
                    let (x0, x1) = ranges[c];
                    if r == c {
                        let w = (x1 - x0) / BINS as f64;
                        let mut counts = vec![0usize; BINS];
                        for v in b.draws[c].iter().filter(|v| v.is_finite()) {
                            let k = (((v - x0) / w) as usize).min(BINS - 1);
                            counts[k] += 1;
                        }
                        let peak = counts.iter().copied().max().unwrap_or(1).max(1) as f64;
                        let mut chart = ChartBuilder::on(&area)
                            .caption(&b.names[c], ("sans-serif", 14))
                            .margin(4)
                            .x_label_area_size(34)
                            .y_label_area_size(40)
                            .build_cartesian_2d(x0..x1, 0.0..1.05 * peak)
                            .map_err(e)?;
                        chart
                            .configure_mesh()
                            .disable_y_axis()
                            .disable_mesh()
                            .x_labels(3)
                            .label_style(("sans-serif", 10))
                            .draw()
                            .map_err(e)?;
                        chart
                            .draw_series(counts.iter().enumerate().map(|(k, &h)| {
                                let a = x0 + k as f64 * w;
                                Rectangle::new(
                                    [(a, 0.0), (a + w, h as f64)],
                                    BLUE.mix(0.5).filled(),
                                )
                            }))
                            .map_err(e)?;
                    } else {
                        let (y0, y1) = ranges[r];
                        let mut chart = ChartBuilder::on(&area)
                            .margin(4)
                            .x_label_area_size(34)
                            .y_label_area_size(40)
                            .build_cartesian_2d(x0..x1, y0..y1)
                            .map_err(e)?;
                        chart
                            .configure_mesh()
                            .disable_mesh()
                            .x_labels(3)
                            .y_labels(3)
                            .x_desc(b.names[c].as_str())
                            .y_desc(b.names[r].as_str())
                            .label_style(("sans-serif", 10))
                            .draw()
                            .map_err(e)?;
                        chart
                            .draw_series(
                                b.draws[c]
                                    .iter()
                                    .zip(&b.draws[r])
                                    .step_by(stride)
                                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                                    .map(|(&x, &y)| {
                                        Circle::new((x, y), 1, BLACK.mix(0.3).filled())
                                    }),
                            )
                            .map_err(e)?;
                    }
                }
            }
            top += (n.max(1) as u32 * PANEL) as i32;
        }
        root.present().map_err(e)?;
    }
    Ok(out)
}

/// One panel of a [`panels_svg`] figure: points with error bars and curves (a NaN y breaks a
/// curve).
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Caption of the panel.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Point series.
    pub points: Vec<PointSeries>,
    /// Curves: label and (x, y) samples.
    pub curves: Vec<(String, Vec<(f64, f64)>)>,
    /// Palette index of each curve (empty: one colour per curve); a curve whose colour
    /// repeats the previous curve's is drawn thin (e.g. δ_d beside δ_m of the same law).
    pub curve_colours: Vec<usize>,
}

/// Renders panels in a grid of `cols` columns (560 × 420 px each; a single panel 900 × 620)
/// under a common title.
pub fn panels_svg(title: &str, cols: usize, panels: &[Panel]) -> Result<String, String> {
    let cols = cols.max(1);
    let rows = panels.len().div_ceil(cols).max(1);
    let (pw, ph) = if panels.len() == 1 {
        (900u32, 620u32)
    } else {
        (560u32, 420u32)
    };
    let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (pw * cols as u32, ph * rows as u32 + 40))
            .into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(e)?;
        let areas = root.split_evenly((rows, cols));
        for (panel, area) in panels.iter().zip(areas) {
            let xs = panel
                .points
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0))
                .chain(panel.curves.iter().flat_map(|c| c.1.iter().map(|p| p.0)));
            let (x0, x1) = range(xs);
            let ys: Vec<f64> = panel
                .points
                .iter()
                .flat_map(|s| s.points.iter().flat_map(|p| [p.1, p.2, p.3]))
                .chain(panel.curves.iter().flat_map(|c| c.1.iter().map(|p| p.1)))
                .collect();
            let (y0, y1) = range(ys.into_iter());
            let mut chart = ChartBuilder::on(&area)
                .caption(&panel.title, ("sans-serif", 16))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(e)?;
            chart
                .configure_mesh()
                .x_desc(&panel.x_label)
                .y_desc(&panel.y_label)
                .label_style(("sans-serif", 12))
                .draw()
                .map_err(e)?;
            let mut colour_index = 0;
            for (ci, (label, pts)) in panel.curves.iter().enumerate() {
                let (pick, width) = match panel.curve_colours.get(ci) {
                    Some(&k) => {
                        let thin = ci > 0 && panel.curve_colours.get(ci - 1) == Some(&k);
                        colour_index = colour_index.max(k + 1);
                        (k, if thin { 1 } else { 2 })
                    }
                    None => {
                        colour_index += 1;
                        (colour_index - 1, 2)
                    }
                };
                let colour = Palette99::pick(pick).to_rgba();
                let mut first = true;
                for seg in pts
                    .split(|p| !(p.0.is_finite() && p.1.is_finite()))
                    .filter(|s| s.len() > 1)
                {
                    let s = chart
                        .draw_series(LineSeries::new(seg.to_vec(), colour.stroke_width(width)))
                        .map_err(e)?;
                    if first && !label.is_empty() {
                        s.label(label.clone()).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(width))
                        });
                        first = false;
                    }
                }
            }
            for s in &panel.points {
                let colour = Palette99::pick(colour_index).to_rgba();
                colour_index += 1;
                chart
                    .draw_series(
                        s.points
                            .iter()
                            .filter(|p| p.0.is_finite() && p.2.is_finite() && p.3 > p.2)
                            .map(|p| PathElement::new(vec![(p.0, p.2), (p.0, p.3)], colour)),
                    )
                    .map_err(e)?;
                chart
                    .draw_series(
                        s.points
                            .iter()
                            .filter(|p| p.0.is_finite() && p.1.is_finite())
                            .map(|p| Circle::new((p.0, p.1), 4, colour.filled())),
                    )
                    .map_err(e)?
                    .label(s.label.clone())
                    .legend(move |(x, y)| Circle::new((x, y), 4, colour.filled()));
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .label_font(("sans-serif", 11))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(e)?;
        }
        root.present().map_err(e)?;
    }
    Ok(out)
}
