//! PNG rendering of the figures with resvg (feature `png`), with the embedded font only: text
//! renders the same on a machine with no system fonts, and nothing outside the crate decides
//! how a figure looks.

use super::FigureError;
use resvg::{tiny_skia, usvg};

/// The embedded font: a subset of DejaVu Sans 2.37 (Latin, Greek, combining marks, punctuation,
/// scripts and mathematical operators; licence in `assets/fonts/LICENSE-DejaVu.txt`).
pub(crate) const FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans-subset.ttf");

/// The family name of [`FONT`].
pub(crate) const FONT_NAME: &str = "DejaVu Sans";

/// Parsing options whose font database holds `FONT` alone, with every generic family
/// mapped to it.
pub fn options() -> usvg::Options<'static> {
    let mut opt = usvg::Options::default();
    let db = opt.fontdb_mut();
    db.load_font_data(FONT.to_vec());
    db.set_sans_serif_family(FONT_NAME);
    db.set_serif_family(FONT_NAME);
    db.set_monospace_family(FONT_NAME);
    opt.font_family = FONT_NAME.to_string();
    opt
}

/// Parses an SVG document with [`options`].
pub fn parse(svg: &str) -> Result<usvg::Tree, FigureError> {
    usvg::Tree::from_str(svg, &options())
        .map_err(|e| FigureError::Render(format!("not a valid SVG document: {e}")))
}

/// Renders an SVG document at `scale` (1: one pixel per SVG unit) on a white background to a
/// pixmap.
pub fn render_pixmap(svg: &str, scale: f32) -> Result<tiny_skia::Pixmap, FigureError> {
    let tree = parse(svg)?;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale)
        .ok_or_else(|| FigureError::Empty("empty figure".into()))?;
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).ok_or_else(|| {
        FigureError::Render(format!(
            "cannot allocate {}×{} px",
            size.width(),
            size.height()
        ))
    })?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap)
}

/// Renders an SVG document to PNG bytes at `scale`.
pub(crate) fn svg_to_png(svg: &str, scale: f32) -> Result<Vec<u8>, FigureError> {
    render_pixmap(svg, scale)?
        .encode_png()
        .map_err(|e| FigureError::Render(format!("cannot encode PNG: {e}")))
}

/// The pixel scale of the PNG files `fitbead report --format png` writes (2: sharp on a
/// high-density screen and in print at the figure's size).
pub(crate) const REPORT_SCALE: f32 = 2.0;

/// The pixel scale of the PNG files of figures sized for print (`--figure-width`): 300 dots per
/// inch of the printed width (the SVG's mm read at 96 px to the inch).
pub(crate) const PRINT_SCALE: f32 = 300.0 / 96.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_renders_with_the_embedded_font() {
        let svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"120\" height=\"40\">\
                   <text x=\"4\" y=\"28\" font-size=\"24\" font-family=\"sans-serif\">δ ξ α</text></svg>";
        let p = render_pixmap(svg, 1.0).unwrap();
        let ink = p.pixels().iter().filter(|c| c.red() < 128).count();
        assert!(ink > 50, "{ink} dark pixels");
    }
}
