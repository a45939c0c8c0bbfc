//! The figures: SVG documents written by the crate's own engine (`svg` for the document
//! and its text, `plot` for axes, legends and grids of panels), the corner plots of
//! posteriors (`corner`), and the scatter figure of `fitbead k`. `png` (feature `png`)
//! renders any of them to PNG with resvg and the embedded font; feature `pdf` converts them to
//! PDF (svg2pdf over the same tree, the font embedded).
//!
//! Labels are markup: `_{…}` sets a subscript and `^{…}` a superscript; Greek letters and
//! symbols are Unicode. Every run of a label is written as a `tspan` at an absolute position
//! computed from the embedded font's advance widths (start-anchored, kerning off), so any
//! conforming renderer draws the same picture.
//! Every document names the font family list `FONT_FAMILY`, whose first member is the
//! embedded DejaVu Sans (`assets/fonts/`), whose advance widths the layout measures text with.

pub(crate) mod corner;
mod metrics;
#[cfg(feature = "pdf")]
mod pdf;
pub(crate) mod plot;
#[cfg(feature = "png")]
pub(crate) mod png;
pub(crate) mod svg;

pub use corner::CornerBlock;

/// Why a figure could not be drawn, rendered to PNG or converted to PDF. The message names the
/// figure where there are several.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FigureError {
    /// There is nothing to draw (the message says what is missing).
    #[error("{0}")]
    Empty(String),
    /// The SVG document could not be rendered or converted, or the format needs a crate
    /// feature (`png`, `pdf`) this build lacks.
    #[error("{0}")]
    Render(String),
    /// A figure setting (format, print width) that cannot be used.
    #[error("{0}")]
    Setting(String),
}
pub(crate) use plot::{
    coincide, Axis, ErrPoint, Figure, Item, LegendEntry, Panel, DASHES, PALETTE,
};
pub(crate) use svg::{Anchor, Mark, Stroke, MARKS};

/// One series of points with optional vertical error bars, and an optional horizontal
/// reference line drawn in the same colour.
#[derive(Debug, Clone, Default)]
pub(crate) struct PointSeries {
    /// Legend label (markup).
    pub label: String,
    /// (x, y, y_low, y_high) per point; y_low/y_high equal y when there is no interval.
    pub points: Vec<ErrPoint>,
    /// A horizontal reference line y = value, with its own legend label.
    pub reference: Option<(f64, String)>,
}

/// A scatter figure: title, axis labels, series.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scatter {
    /// Caption above the plot (markup).
    pub title: String,
    /// x-axis label (markup).
    pub x_label: String,
    /// y-axis label (markup).
    pub y_label: String,
    /// The data.
    pub series: Vec<PointSeries>,
}

/// Series `i`'s colour and marker.
pub(crate) fn series_style(i: usize) -> (&'static str, Mark) {
    (PALETTE[i % PALETTE.len()], MARKS[i % MARKS.len()])
}

/// The scatter figure as a panel: series `i` in [`series_style`]`(i)`, its reference line
/// dashed in the same colour.
pub(crate) fn scatter_panel(fig: &Scatter) -> Panel {
    let mut p = Panel::new("", Axis::new(&fig.x_label), Axis::new(&fig.y_label));
    for (i, s) in fig.series.iter().enumerate() {
        let (colour, mark) = series_style(i);
        p.points(s.points.clone(), colour, mark);
        p.legend.push(LegendEntry::mark(&s.label, mark, colour));
        if let Some((y, label)) = &s.reference {
            let st = Stroke::solid(colour, 1.5).dashed(DASHES[0]);
            p.items.push(Item::HLine {
                y: *y,
                stroke: st.clone(),
            });
            p.legend.push(LegendEntry::line(label, &st));
        }
    }
    p
}

/// Renders a scatter figure to an SVG document.
pub(crate) fn scatter_svg(fig: &Scatter) -> Result<String, FigureError> {
    Ok(Figure::new(&fig.title, 1, (720.0, 460.0), vec![scatter_panel(fig)]).to_svg())
}

/// The width a report's figures are printed at: a journal's column, both columns, or any width
/// in mm. The figures are laid out for it (see
/// [`Figure::print_width_mm`](plot::Figure::print_width_mm)): text never prints below 7 pt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FigureWidth {
    /// One column: 86 mm (8.6 cm, as the Physical Review journals).
    Single,
    /// Both columns: 178 mm (17.8 cm, as the Physical Review journals).
    Double,
    /// A width in mm, 40 to 500.
    Mm(f64),
}

impl FigureWidth {
    /// The width, mm.
    pub fn mm(self) -> f64 {
        match self {
            FigureWidth::Single => 86.0,
            FigureWidth::Double => 178.0,
            FigureWidth::Mm(w) => w,
        }
    }
}

impl std::str::FromStr for FigureWidth {
    type Err = FigureError;
    /// `single`, `double`, or a width in mm (`120`, or `120mm`).
    fn from_str(s: &str) -> Result<Self, FigureError> {
        let t = s.trim().to_ascii_lowercase();
        match t.as_str() {
            "single" => return Ok(FigureWidth::Single),
            "double" => return Ok(FigureWidth::Double),
            _ => {}
        }
        let mm: f64 = t.trim_end_matches("mm").trim().parse().map_err(|_| {
            FigureError::Setting(
                "must be single (86 mm), double (178 mm) or a width in mm".to_string(),
            )
        })?;
        if !(40.0..=500.0).contains(&mm) {
            return Err(FigureError::Setting(
                "a width in mm must be between 40 and 500".into(),
            ));
        }
        Ok(FigureWidth::Mm(mm))
    }
}

/// The file formats of a report's figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum FigureFormat {
    /// SVG only.
    #[default]
    Svg,
    /// PNG only (rendered from the SVG).
    Png,
    /// PDF only (converted from the SVG: vector, the font embedded, text selectable).
    Pdf,
    /// SVG and PNG.
    Both,
    /// SVG, PNG and PDF.
    All,
}

impl std::str::FromStr for FigureFormat {
    type Err = FigureError;
    fn from_str(s: &str) -> Result<Self, FigureError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "svg" => Ok(FigureFormat::Svg),
            "png" => Ok(FigureFormat::Png),
            "pdf" => Ok(FigureFormat::Pdf),
            "both" => Ok(FigureFormat::Both),
            "all" => Ok(FigureFormat::All),
            _ => Err(FigureError::Setting(
                "must be svg, png, pdf, both (svg and png) or all".into(),
            )),
        }
    }
}

impl FigureFormat {
    /// The extensions this format writes, in order.
    fn extensions(self) -> &'static [&'static str] {
        match self {
            FigureFormat::Svg => &["svg"],
            FigureFormat::Png => &["png"],
            FigureFormat::Pdf => &["pdf"],
            FigureFormat::Both => &["svg", "png"],
            FigureFormat::All => &["svg", "png", "pdf"],
        }
    }

    /// The file names a figure `NAME.svg` is written as.
    pub fn names(self, svg_name: &str) -> Vec<String> {
        let stem = svg_name.trim_end_matches(".svg");
        self.extensions()
            .iter()
            .map(|e| format!("{stem}.{e}"))
            .collect()
    }

    /// `files` (name, bytes) with every `*.svg` written in this format: kept, rendered to PNG
    /// (`png::svg_to_png` at `png::REPORT_SCALE`), converted to PDF, or several of these.
    /// Without the `png` or `pdf` feature such a format is an error.
    pub fn apply(
        self,
        files: Vec<(String, Vec<u8>)>,
    ) -> Result<Vec<(String, Vec<u8>)>, FigureError> {
        if self == FigureFormat::Svg {
            return Ok(files);
        }
        let mut out = Vec::with_capacity(files.len() * 3);
        for (name, bytes) in files {
            if !name.ends_with(".svg") {
                out.push((name, bytes));
                continue;
            }
            let stem = name.trim_end_matches(".svg").to_string();
            for ext in self.extensions() {
                let file = match *ext {
                    "png" => render_png(&name, &bytes)?,
                    "pdf" => render_pdf(&name, &bytes)?,
                    _ => bytes.clone(),
                };
                out.push((format!("{stem}.{ext}"), file));
            }
        }
        Ok(out)
    }
}

#[cfg(feature = "png")]
fn render_png(name: &str, svg: &[u8]) -> Result<Vec<u8>, FigureError> {
    let render = |e: &dyn std::fmt::Display| FigureError::Render(format!("{name}: {e}"));
    let text = std::str::from_utf8(svg).map_err(|e| render(&e))?;
    // A figure sized for print (width in mm) is rendered at 300 dots per inch.
    let scale = if svg::print_sized(text) {
        png::PRINT_SCALE
    } else {
        png::REPORT_SCALE
    };
    png::svg_to_png(text, scale).map_err(|e| render(&e))
}

#[cfg(not(feature = "png"))]
fn render_png(name: &str, _svg: &[u8]) -> Result<Vec<u8>, FigureError> {
    Err(FigureError::Render(format!(
        "{name}: PNG figures need the crate feature `png` (built without it)"
    )))
}

#[cfg(feature = "pdf")]
fn render_pdf(name: &str, svg: &[u8]) -> Result<Vec<u8>, FigureError> {
    let render = |e: &dyn std::fmt::Display| FigureError::Render(format!("{name}: {e}"));
    let text = std::str::from_utf8(svg).map_err(|e| render(&e))?;
    pdf::svg_to_pdf(text).map_err(|e| render(&e))
}

#[cfg(not(feature = "pdf"))]
fn render_pdf(name: &str, _svg: &[u8]) -> Result<Vec<u8>, FigureError> {
    Err(FigureError::Render(format!(
        "{name}: PDF figures need the crate feature `pdf` (built without it)"
    )))
}
