//! The SVG writer under every figure: coordinates kept to a hundredth of a pixel, text with
//! sub- and superscripts, and text measured with the advance widths of the font the document
//! names first (the embedded DejaVu Sans; the table is generated from the font file by
//! `scripts/font_metrics.py`).
//!
//! The figures are written here rather than through a plotting crate's SVG backend because
//! that backend (plotters') rounds every coordinate to a whole pixel, which draws smooth
//! curves as stairs, and lays text out without knowing its width, which lets labels and
//! legends overlap.

use super::metrics::{ADVANCE, ASCENT, DESCENT, UNITS_PER_EM};
use std::fmt::Write as _;

/// The font family list of every figure: the embedded font first, then look-alikes a viewer
/// may have.
pub(crate) const FONT_FAMILY: &str = "DejaVu Sans, Bitstream Vera Sans, Verdana, Arial, sans-serif";

/// A coordinate or length as written to the document: at most two decimals, no trailing
/// zeros.
pub fn num(x: f64) -> String {
    let h = (x * 100.0).round();
    // Hundredths below 2^50 in magnitude: r = h/100 is within far less than 0.005 of h/100,
    // so its two-decimal form is the digits of the integer h (written without the general
    // float formatter, which figures call hundreds of thousands of times).
    if h.abs() < (1u64 << 50) as f64 {
        let n = h as i64;
        let (q, m) = (n.unsigned_abs() / 100, n.unsigned_abs() % 100);
        let sign = if n < 0 { "-" } else { "" };
        return match m {
            0 => format!("{sign}{q}"),
            _ if m % 10 == 0 => format!("{sign}{q}.{}", m / 10),
            _ => format!("{sign}{q}.{m:02}"),
        };
    }
    num_formatted(x)
}

/// [`num`] through the float formatter (any `x`, NaN and infinities included).
fn num_formatted(x: f64) -> String {
    let r = (x * 100.0).round() / 100.0;
    let r = if r == 0.0 { 0.0 } else { r };
    let s = format!("{r:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Longest text a figure draws, in characters of its markup: a longer one (a legend or title
/// holding a huge series label) keeps its first characters and ends in `…`.
pub(crate) const MAX_TEXT_CHARS: usize = 120;

/// Escapes text for an SVG text node or attribute.
pub(crate) fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            _ => o.push(c),
        }
    }
    o
}

/// Vertical position of a run of text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shift {
    Base,
    Sub,
    Sup,
}

/// Size of sub- and superscripts relative to the text.
const SCRIPT: f64 = 0.72;

impl Shift {
    /// Baseline offset in units of the font size (SVG y grows downwards).
    fn offset(self) -> f64 {
        match self {
            Shift::Base => 0.0,
            Shift::Sub => 0.25,
            Shift::Sup => -0.38,
        }
    }
    fn scale(self) -> f64 {
        if self == Shift::Base {
            1.0
        } else {
            SCRIPT
        }
    }
}

/// Splits the label markup into runs: `_{…}` is a subscript, `^{…}` a superscript, anything
/// else plain text (a lone `_` or `^` not followed by `{` is kept as is).
fn runs(markup: &str) -> Vec<(Shift, String)> {
    let mut out: Vec<(Shift, String)> = Vec::new();
    let mut cur = String::new();
    let mut it = markup.chars().peekable();
    while let Some(c) = it.next() {
        let shift = match c {
            '_' => Shift::Sub,
            '^' => Shift::Sup,
            _ => {
                cur.push(c);
                continue;
            }
        };
        if it.peek() != Some(&'{') {
            cur.push(c);
            continue;
        }
        it.next();
        let mut inner = String::new();
        for d in it.by_ref() {
            if d == '}' {
                break;
            }
            inner.push(d);
        }
        if !cur.is_empty() {
            out.push((Shift::Base, std::mem::take(&mut cur)));
        }
        out.push((shift, inner));
    }
    if !cur.is_empty() {
        out.push((Shift::Base, cur));
    }
    out
}

/// Advance width of one character, em.
fn advance(c: char) -> f64 {
    let cp = c as u32;
    match ADVANCE.binary_search_by_key(&cp, |e| e.0) {
        Ok(i) => ADVANCE[i].1 as f64 / UNITS_PER_EM,
        // A character outside the embedded font: a wide glyph's width, to be safe.
        Err(_) => 0.8,
    }
}

/// Width in px of `markup` set at `size` px in the embedded font (kerning ignored: it only
/// narrows the text).
pub(crate) fn text_width(markup: &str, size: f64) -> f64 {
    runs(markup)
        .iter()
        .map(|(s, t)| t.chars().map(advance).sum::<f64>() * size * s.scale())
        .sum()
}

/// Whether `svg`, a document of [`Svg::finish`], is sized for print (its width in mm).
#[cfg(any(test, feature = "png"))]
pub(crate) fn print_sized(svg: &str) -> bool {
    svg.split_once('>')
        .is_some_and(|(root, _)| root.starts_with("<svg") && root.contains("mm\" height="))
}

/// Height in px above the baseline of text at `size` (the font's ascender; a superscript
/// reaches no higher).
pub(crate) fn ascent(size: f64) -> f64 {
    ASCENT / UNITS_PER_EM * size
}

/// Depth in px below the baseline of text at `size` (the font's descender, plus room for a
/// subscript).
pub(crate) fn descent(size: f64) -> f64 {
    -DESCENT / UNITS_PER_EM * size + 0.1 * size
}

/// Height in px of one line of text at `size`.
pub(crate) fn line_height(size: f64) -> f64 {
    ascent(size) + descent(size)
}

/// Horizontal anchor of a text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// x is the left end.
    Start,
    /// x is the middle.
    Middle,
    /// x is the right end.
    End,
}

/// A stroke: colour, width in px and an optional dash pattern (SVG `stroke-dasharray`).
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// Colour (`#rrggbb`).
    pub colour: String,
    /// Width, px.
    pub width: f64,
    /// Dash pattern, px (`None`: solid).
    pub dash: Option<&'static str>,
}

impl Stroke {
    /// A solid stroke.
    pub fn solid(colour: &str, width: f64) -> Self {
        Stroke {
            colour: colour.to_string(),
            width,
            dash: None,
        }
    }

    /// The same stroke dashed with `pattern`.
    pub fn dashed(mut self, pattern: &'static str) -> Self {
        self.dash = Some(pattern);
        self
    }

    fn attrs(&self) -> String {
        let mut s = format!(
            "fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\" \
             stroke-linecap=\"round\"",
            self.colour,
            num(self.width)
        );
        if let Some(d) = self.dash {
            let _ = write!(s, " stroke-dasharray=\"{d}\"");
        }
        s
    }
}

/// Marker shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// Circle.
    Circle,
    /// Square.
    Square,
    /// Triangle pointing up.
    Triangle,
    /// Diamond.
    Diamond,
    /// Triangle pointing down.
    TriangleDown,
    /// A plus-shaped cross (no fill).
    Cross,
}

/// The marker shapes in the order series take them.
pub const MARKS: [Mark; 5] = [
    Mark::Circle,
    Mark::Square,
    Mark::Triangle,
    Mark::Diamond,
    Mark::TriangleDown,
];

/// An SVG document being written.
#[derive(Debug)]
pub struct Svg {
    width: f64,
    height: f64,
    /// The document's printed width, mm (`None`: `width` CSS pixels).
    pub print_width_mm: Option<f64>,
    body: String,
    defs: String,
    ids: usize,
}

impl Svg {
    /// An empty document of `width` × `height` px on a white background.
    pub fn new(width: f64, height: f64) -> Self {
        Svg {
            width,
            height,
            print_width_mm: None,
            body: String::new(),
            defs: String::new(),
            ids: 0,
        }
    }

    /// Opens a group translated by (dx, dy); close it with [`Svg::end_group`].
    pub fn begin_translate(&mut self, dx: f64, dy: f64) {
        let _ = writeln!(
            self.body,
            "<g transform=\"translate({},{})\">",
            num(dx),
            num(dy)
        );
    }

    /// Opens a group clipped to a rectangle; close it with [`Svg::end_group`].
    pub fn begin_clip(&mut self, x: f64, y: f64, w: f64, h: f64) {
        self.ids += 1;
        let id = format!("clip{}", self.ids);
        let _ = writeln!(
            self.defs,
            "<clipPath id=\"{id}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>",
            num(x),
            num(y),
            num(w),
            num(h)
        );
        let _ = writeln!(self.body, "<g clip-path=\"url(#{id})\">");
    }

    /// Closes a group.
    pub fn end_group(&mut self) {
        self.body.push_str("</g>\n");
    }

    /// A polyline through `pts` (no point may be NaN).
    pub fn polyline(&mut self, pts: &[(f64, f64)], stroke: &Stroke) {
        if pts.len() < 2 {
            return;
        }
        let _ = writeln!(
            self.body,
            "<polyline points=\"{}\" {}/>",
            points_attr(pts),
            stroke.attrs()
        );
    }

    /// Separate straight segments, one path.
    pub fn segments(&mut self, segs: &[[(f64, f64); 2]], stroke: &Stroke) {
        if segs.is_empty() {
            return;
        }
        let mut d = String::new();
        for s in segs {
            let _ = write!(
                d,
                "M{} {}L{} {}",
                num(s[0].0),
                num(s[0].1),
                num(s[1].0),
                num(s[1].1)
            );
        }
        let _ = writeln!(self.body, "<path d=\"{d}\" {}/>", stroke.attrs());
    }

    /// Filled dots of radius `r`, one path.
    pub fn dots(&mut self, pts: &[(f64, f64)], r: f64, colour: &str) {
        let mut d = String::new();
        let (rs, ds) = (num(r), num(2.0 * r));
        for p in pts.iter().filter(|p| p.0.is_finite() && p.1.is_finite()) {
            let _ = write!(
                d,
                "M{} {}a{rs} {rs} 0 1 0 {ds} 0a{rs} {rs} 0 1 0 -{ds} 0",
                num(p.0 - r),
                num(p.1)
            );
        }
        if !d.is_empty() {
            let _ = writeln!(
                self.body,
                "<path d=\"{d}\" fill=\"{colour}\" stroke=\"none\"/>"
            );
        }
    }

    /// A filled polygon.
    pub fn polygon(&mut self, pts: &[(f64, f64)], fill: &str, opacity: f64) {
        if pts.len() < 3 {
            return;
        }
        let _ = writeln!(
            self.body,
            "<polygon points=\"{}\" fill=\"{fill}\" fill-opacity=\"{}\" stroke=\"none\"/>",
            points_attr(pts),
            num(opacity)
        );
    }

    /// A rectangle, filled and optionally outlined.
    pub fn rect(
        &mut self,
        (x, y, w, h): (f64, f64, f64, f64),
        fill: &str,
        opacity: f64,
        stroke: Option<&Stroke>,
    ) {
        let st = stroke.map_or("stroke=\"none\"".to_string(), |s| {
            s.attrs().replacen("fill=\"none\" ", "", 1)
        });
        let _ = writeln!(
            self.body,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{fill}\" \
             fill-opacity=\"{}\" {st}/>",
            num(x),
            num(y),
            num(w),
            num(h),
            num(opacity)
        );
    }

    /// A marker of radius `r` centred at (x, y): outlined in `colour`, filled with it at
    /// `fill_opacity`.
    pub fn marker(
        &mut self,
        mark: Mark,
        (x, y): (f64, f64),
        r: f64,
        colour: &str,
        fill_opacity: f64,
    ) {
        let style = format!(
            "fill=\"{colour}\" fill-opacity=\"{}\" stroke=\"{colour}\" stroke-width=\"1.5\"",
            num(fill_opacity)
        );
        let poly = |pts: &[(f64, f64)]| {
            let p: Vec<(f64, f64)> = pts.iter().map(|&(a, b)| (x + a * r, y + b * r)).collect();
            format!("<polygon points=\"{}\" {style}/>", points_attr(&p))
        };
        let s = match mark {
            Mark::Circle => format!(
                "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" {style}/>",
                num(x),
                num(y),
                num(r)
            ),
            Mark::Square => poly(&[(-0.85, -0.85), (0.85, -0.85), (0.85, 0.85), (-0.85, 0.85)]),
            Mark::Diamond => poly(&[(0.0, -1.2), (1.1, 0.0), (0.0, 1.2), (-1.1, 0.0)]),
            Mark::Triangle => poly(&[(0.0, -1.2), (1.1, 0.75), (-1.1, 0.75)]),
            Mark::TriangleDown => poly(&[(0.0, 1.2), (1.1, -0.75), (-1.1, -0.75)]),
            Mark::Cross => format!(
                "<path d=\"M{} {}H{}M{} {}V{}\" stroke=\"{colour}\" stroke-width=\"2.5\" \
                 fill=\"none\"/>",
                num(x - 1.3 * r),
                num(y),
                num(x + 1.3 * r),
                num(x),
                num(y - 1.3 * r),
                num(y + 1.3 * r)
            ),
        };
        self.body.push_str(&s);
        self.body.push('\n');
    }

    /// Text: `markup` (`text_width`'s sub- and superscripts) at `size` px with its
    /// baseline at (x, y), anchored by `anchor`, rotated by −90° about (x, y) when
    /// `vertical`.
    ///
    /// Every run of the markup is its own `tspan` with absolute positions computed from the
    /// embedded font's advance widths: one x per character (start-anchored) and the run's
    /// baseline y, so the drawing does not depend on how a renderer anchors text, shifts
    /// scripts, kerns or hints advances: resvg, cairosvg and browsers put every glyph at the
    /// same point. Spaces at either end of a run are left out of the document and kept as
    /// advance.
    #[allow(clippy::too_many_arguments)]
    pub fn text(
        &mut self,
        (x, y): (f64, f64),
        markup: &str,
        size: f64,
        anchor: Anchor,
        vertical: bool,
        colour: &str,
    ) {
        // A series label can be megabytes long (it is data): a figure shows its start.
        let clipped;
        let markup = match markup.char_indices().nth(MAX_TEXT_CHARS) {
            Some(_) => {
                let end = markup
                    .char_indices()
                    .nth(MAX_TEXT_CHARS - 1)
                    .map_or(markup.len(), |(i, _)| i);
                clipped = format!("{}…", &markup[..end]);
                clipped.as_str()
            }
            None => markup,
        };
        let width = text_width(markup, size);
        let x0 = match anchor {
            Anchor::Start => x,
            Anchor::Middle => x - width / 2.0,
            Anchor::End => x - width,
        };
        let rot = if vertical {
            format!(" transform=\"rotate(-90 {} {})\"", num(x), num(y))
        } else {
            String::new()
        };
        let _ = write!(
            self.body,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" fill=\"{colour}\"{rot}>",
            num(x0),
            num(y),
            num(size)
        );
        let mut at = x0;
        for (shift, t) in runs(markup) {
            let fs = size * shift.scale();
            // Each character at its own x: the advance widths decide every glyph's place, not
            // the renderer's hinting or kerning. Spaces are advance only (a renderer may
            // collapse or drop them), except one between words, kept for copied text.
            let mut xs = String::new();
            let mut chars = String::new();
            let mut prev_space = true;
            for c in t.chars() {
                let space = c == ' ';
                if !(space && prev_space) {
                    if !xs.is_empty() {
                        xs.push(' ');
                    }
                    xs.push_str(&num(at));
                    chars.push(c);
                }
                prev_space = space;
                at += advance(c) * fs;
            }
            if chars.ends_with(' ') {
                chars.pop();
                xs.truncate(xs.rfind(' ').unwrap_or(0));
            }
            if chars.is_empty() {
                continue;
            }
            let size_attr = if shift == Shift::Base {
                String::new()
            } else {
                format!(" font-size=\"{}\"", num(fs))
            };
            let _ = write!(
                self.body,
                "<tspan x=\"{xs}\" y=\"{}\"{size_attr}>{}</tspan>",
                num(y + shift.offset() * size),
                escape(&chars)
            );
        }
        self.body.push_str("</text>\n");
    }

    /// The finished document.
    pub fn finish(self) -> String {
        let mut s = String::with_capacity(self.body.len() + self.defs.len() + 400);
        // The printed size: px (CSS pixels), or the print width in mm with the height in
        // proportion; the drawing's own units (the viewBox) are px either way.
        let (pw, ph) = match self.print_width_mm {
            Some(mm) => (
                format!("{}mm", num(mm)),
                format!("{}mm", num(mm * self.height / self.width)),
            ),
            None => (num(self.width), num(self.height)),
        };
        let _ = writeln!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{pw}\" height=\"{ph}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"{FONT_FAMILY}\" \
             style=\"font-kerning:none\">",
            w = num(self.width),
            h = num(self.height)
        );
        if !self.defs.is_empty() {
            let _ = writeln!(s, "<defs>\n{}</defs>", self.defs);
        }
        let _ = writeln!(
            s,
            "<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>",
            num(self.width),
            num(self.height)
        );
        s.push_str(&self.body);
        s.push_str("</svg>\n");
        s
    }
}

fn points_attr(pts: &[(f64, f64)]) -> String {
    let mut s = String::with_capacity(pts.len() * 14);
    for (i, p) in pts.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{},{}", num(p.0), num(p.1));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_as_the_float_formatter_writes_them() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut xs = vec![
            0.0,
            -0.0,
            0.004,
            -0.004,
            0.005,
            -0.005,
            0.015,
            0.125,
            -0.125,
            1e-300,
            99.995,
            -99.995,
            1e12,
            -1e12,
            1.1259e13,
            1.1259e13 + 0.005,
            2e15,
            -3e17,
            1e300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
        ];
        for _ in 0..200_000 {
            let e = rng.random_range(-6.0..16.0);
            let x = rng.random_range(-1.0..1.0) * 10f64.powf(e);
            xs.push(x);
            // Values at and beside the halfway points of the hundredths.
            let h = (x * 100.0).trunc() + 0.5;
            xs.push(h / 100.0);
            xs.push(f64::from_bits((h / 100.0).to_bits() + 1));
        }
        for x in xs {
            assert_eq!(num(x), num_formatted(x), "{x:e}");
        }
    }

    #[test]
    fn numbers_keep_hundredths() {
        assert_eq!(num(12.345), "12.35");
        assert_eq!(num(12.3), "12.3");
        assert_eq!(num(12.0), "12");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(-3.5), "-3.5");
    }

    #[test]
    fn markup_splits_scripts() {
        let r = runs("v_{fit}^{2} a_b");
        assert_eq!(
            r,
            vec![
                (Shift::Base, "v".to_string()),
                (Shift::Sub, "fit".to_string()),
                (Shift::Sup, "2".to_string()),
                (Shift::Base, " a_b".to_string())
            ]
        );
    }

    #[test]
    fn widths_follow_the_font() {
        // DejaVu Sans: space 651, 'v' 1212 font units of 2048.
        let w = text_width("v v", 20.0);
        assert!((w - 20.0 * (1212.0 * 2.0 + 651.0) / 2048.0).abs() < 1e-9);
        // A subscript is set smaller.
        assert!(text_width("v_{v}", 20.0) < w);
        // The combining macron of v̄ takes no width.
        assert_eq!(text_width("v\u{304}", 10.0), text_width("v", 10.0));
    }

    #[test]
    fn text_is_escaped_and_scripted() {
        let mut s = Svg::new(10.0, 10.0);
        s.text((1.0, 2.0), "a<b_{1}", 14.0, Anchor::Start, false, "#000");
        let out = s.finish();
        // DejaVu Sans advances: a 1255, < 1716, b 1300 font units of 2048. The subscript
        // starts after "a<b", a quarter of the size (3.5 px) below the baseline, at 0.72 of
        // the size.
        let em = 14.0 / 2048.0;
        let xs = [1.0, 1.0 + 1255.0 * em, 1.0 + (1255.0 + 1716.0) * em];
        let sub = 1.0 + (1255.0 + 1716.0 + 1300.0) * em;
        assert!(out.contains(&format!(
            "<tspan x=\"{} {} {}\" y=\"2\">a&lt;b</tspan><tspan x=\"{}\" y=\"5.5\" \
             font-size=\"10.08\">1</tspan>",
            num(xs[0]),
            num(xs[1]),
            num(xs[2]),
            num(sub)
        )));
    }

    #[test]
    fn anchored_text_starts_where_its_width_puts_it() {
        let mut s = Svg::new(10.0, 10.0);
        s.text((100.0, 20.0), "v v", 20.0, Anchor::Middle, false, "#000");
        s.text((100.0, 40.0), " v  ", 20.0, Anchor::End, false, "#000");
        let out = s.finish();
        // v 1212, space 651 font units of 2048.
        let (v, sp) = (20.0 * 1212.0 / 2048.0, 20.0 * 651.0 / 2048.0);
        let x0 = 100.0 - (2.0 * v + sp) / 2.0;
        assert!(out.contains(&format!(
            "<tspan x=\"{} {} {}\" y=\"20\">v v</tspan>",
            num(x0),
            num(x0 + v),
            num(x0 + v + sp)
        )));
        // Spaces at the ends are advance, not text.
        let x1 = 100.0 - (3.0 * sp + v);
        assert!(out.contains(&format!("<tspan x=\"{}\" y=\"40\">v</tspan>", num(x1 + sp))));
        assert!(!out.contains("text-anchor"));
    }
}
