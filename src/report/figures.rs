//! SVG figures drawn with plotters' SVG backend (no font files needed: text is emitted as SVG
//! `<text>` elements and laid out by the viewer).

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
