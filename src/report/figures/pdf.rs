//! PDF rendering of the figures (feature `pdf`): svg2pdf over the same usvg tree resvg draws
//! for the PNG files, with the embedded font subset into the file, so the PDF is vector, its
//! text selectable, and it looks like the PNG.

use super::png::parse;
use super::FigureError;

/// The resolution at which SVG px become PDF points: 96 px to the inch, the CSS pixel, so that
/// a document sized in mm prints at that size.
const PX_PER_INCH: f32 = 96.0;

/// Converts an SVG document to PDF bytes: one page the size of the document.
pub(crate) fn svg_to_pdf(svg: &str) -> Result<Vec<u8>, FigureError> {
    let tree = parse(svg)?;
    svg2pdf::to_pdf(
        &tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions { dpi: PX_PER_INCH },
    )
    .map_err(|e| FigureError::Render(format!("cannot convert to PDF: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_figure_becomes_a_pdf_with_the_font_embedded() {
        let mut s = crate::report::figures::svg::Svg::new(200.0, 50.0);
        s.text(
            (10.0, 30.0),
            "ξ_{c} = 1.5",
            14.0,
            crate::report::figures::Anchor::Start,
            false,
            "#000",
        );
        let pdf = svg_to_pdf(&s.finish()).unwrap();
        assert!(pdf.starts_with(b"%PDF-"));
        let text = String::from_utf8_lossy(&pdf);
        // The text is set in the embedded font (a subset, named with a tag prefix), with a
        // ToUnicode map that makes it selectable.
        assert!(text.contains("DejaVuSans"), "no DejaVu Sans font object");
        assert!(text.contains("/FontFile2"), "font not embedded");
        assert!(text.contains("/ToUnicode"), "no ToUnicode map");
        // 200 × 50 px at 96 px per inch: 150 × 37.5 pt.
        assert!(text.contains("/MediaBox [0 0 150 37.5]"), "page size");
    }
}
