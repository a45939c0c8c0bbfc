//! The figures render: each is drawn by the command that makes it, rasterised with resvg and
//! the embedded font alone (as on a machine without system fonts), and checked as a person
//! would look at it: ink on a fair part of the canvas, the colours of its series present, and
//! no text overlapping another text (the boxes of the laid-out text elements, from usvg's
//! tree, are pairwise disjoint). The PNGs are left in `target/tmp/figures/` for a look.

use std::path::{Path, PathBuf};

use fitbead::report::figures::CornerBlock;
use resvg::{tiny_skia, usvg};

/// The figures' series colours, in order (Okabe–Ito, then black and brown), as
/// `report::figures::plot` declares them.
const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#8C564B",
];

/// Every file of fixed name `fitbead report` writes (docs/GUIDE.md, "report"): the files of
/// the library's report of the shipped data by least squares (which has no corner plots), as
/// `fitbead::pipeline::report` names them.
fn report_files() -> &'static [String] {
    static FILES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    FILES.get_or_init(|| {
        use fitbead::io::measurements::{MeasurementDefaults, MeasurementFile};
        let data = MeasurementFile::parse(
            "default.csv",
            include_bytes!("../../data/default.csv"),
            &MeasurementDefaults::default(),
        )
        .unwrap();
        let settings = fitbead::pipeline::ReportSettings::default();
        let out = settings.run(&data, None).unwrap();
        out.files.into_iter().map(|(name, _)| name).collect()
    })
}

/// Parses an SVG document with the font the figures embed (assets/fonts) as the only font,
/// every generic family mapped to it, as the PNG renderer of the figures does.
fn parse(svg: &str) -> Result<usvg::Tree, String> {
    const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");
    let mut opt = usvg::Options::default();
    let db = opt.fontdb_mut();
    db.load_font_data(FONT.to_vec());
    for set in [
        usvg::fontdb::Database::set_sans_serif_family,
        usvg::fontdb::Database::set_serif_family,
        usvg::fontdb::Database::set_monospace_family,
    ] {
        set(db, "DejaVu Sans");
    }
    opt.font_family = "DejaVu Sans".to_string();
    usvg::Tree::from_str(svg, &opt).map_err(|e| e.to_string())
}

/// `svg` drawn at `scale` on a white background.
fn render_pixmap(svg: &str, scale: f32) -> Result<tiny_skia::Pixmap, String> {
    let tree = parse(svg)?;
    let size = tree.size().to_int_size().scale_by(scale).ok_or("empty")?;
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("too large")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap)
}

use crate::common::{bin, stderr};

fn out_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("figures");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every text element's box in canvas coordinates, with its text.
fn text_boxes(g: &usvg::Group, out: &mut Vec<(String, usvg::Rect)>) {
    for n in g.children() {
        match n {
            usvg::Node::Group(g) => text_boxes(g, out),
            usvg::Node::Text(t) => {
                let s: String = t.chunks().iter().map(|c| c.text()).collect();
                out.push((s, t.abs_bounding_box()));
            }
            _ => {}
        }
    }
}

/// The pairs of texts whose boxes overlap by more than `slack` px both ways.
fn overlapping_texts(svg: &str, slack: f32) -> Vec<String> {
    let tree = parse(svg).unwrap();
    let mut boxes = Vec::new();
    text_boxes(tree.root(), &mut boxes);
    assert!(!boxes.is_empty(), "no text laid out");
    let mut bad = Vec::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            let (a, b) = (&boxes[i].1, &boxes[j].1);
            let dx = a.right().min(b.right()) - a.left().max(b.left());
            let dy = a.bottom().min(b.bottom()) - a.top().max(b.top());
            if dx > slack && dy > slack {
                bad.push(format!(
                    "{:?} {:?} / {:?} {:?}",
                    boxes[i].0, a, boxes[j].0, b
                ));
            }
        }
    }
    bad
}

/// The sRGB triple of `#rrggbb`, laid at `opacity` over white.
fn rgb(hex: &str, opacity: f64) -> [u8; 3] {
    let v = u32::from_str_radix(hex.trim_start_matches('#'), 16).unwrap();
    let c = [(v >> 16) as u8, (v >> 8) as u8, v as u8];
    c.map(|x| (opacity * x as f64 + (1.0 - opacity) * 255.0).round() as u8)
}

struct Look {
    width: u32,
    height: u32,
    ink: f64,
    colours: usize,
}

/// Renders `svg` to `png` and checks it: ink, the `expected` colours (each on at least 20
/// pixels, within 6 per channel), no overlapping text.
fn look(name: &str, svg: &str, png: &Path, expected: &[[u8; 3]]) -> Look {
    let pixmap = render_pixmap(svg, 1.0).unwrap();
    pixmap.save_png(png).unwrap();
    let px = pixmap.pixels();
    let ink = px
        .iter()
        .filter(|p| !(p.red() > 250 && p.green() > 250 && p.blue() > 250))
        .count() as f64
        / px.len() as f64;
    let mut colours: Vec<u32> = px
        .iter()
        .map(|p| (p.red() as u32) << 16 | (p.green() as u32) << 8 | p.blue() as u32)
        .collect();
    colours.sort_unstable();
    colours.dedup();
    for c in expected {
        let n = px
            .iter()
            .filter(|p| {
                (p.red() as i32 - c[0] as i32).abs() <= 6
                    && (p.green() as i32 - c[1] as i32).abs() <= 6
                    && (p.blue() as i32 - c[2] as i32).abs() <= 6
            })
            .count();
        assert!(n >= 20, "{name}: colour {c:?} on {n} pixels");
    }
    let bad = overlapping_texts(svg, 0.5);
    assert!(bad.is_empty(), "{name}: texts overlap:\n{}", bad.join("\n"));
    let l = Look {
        width: pixmap.width(),
        height: pixmap.height(),
        ink,
        colours: colours.len(),
    };
    println!(
        "{name}: {}x{} px, ink {:.3}, {} colours",
        l.width, l.height, l.ink, l.colours
    );
    assert!(ink > 0.02, "{name}: only {ink} of the canvas inked");
    assert!(l.colours > 8, "{name}: {} colours", l.colours);
    l
}

fn check(name: &str, args: &[&str], expected: &[[u8; 3]]) {
    let dir = out_dir();
    let svg = dir.join(format!("{name}.svg"));
    let csv = dir.join(format!("{name}.csv"));
    let out = bin()
        .args(args)
        .arg("--plot")
        .arg(&svg)
        .arg("--output")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{name}: {}", stderr(&out));
    let text = std::fs::read_to_string(&svg).unwrap();
    let l = look(name, &text, &dir.join(format!("{name}.png")), expected);
    assert!(
        l.width >= 400 && l.height >= 100,
        "{name}: {}x{}",
        l.width,
        l.height
    );
}

/// Under MCMC, `--plot corner.svg` writes one corner plot per fit and series,
/// corner_FIT_SERIES.svg beside it.
#[test]
fn corner_plot_renders() {
    let dir = out_dir().join("corner_jan");
    std::fs::create_dir_all(&dir).unwrap();
    let out = bin()
        .args(["jan", "--method", "mcmc", "--min-ess", "200", "--plot"])
        .arg(dir.join("corner.svg"))
        .arg("--output")
        .arg(dir.join("jan.csv"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!dir.join("corner.svg").exists());
    for series in ["0.8", "1", "1.6", "2"] {
        let f = dir.join(format!("corner_jan-series_{series}.svg"));
        assert!(f.exists(), "{} missing", f.display());
    }
    let text = std::fs::read_to_string(dir.join("corner_jan-global_all.svg")).unwrap();
    let l = look(
        "corner_jan_global",
        &text,
        &out_dir().join("corner_jan_global.png"),
        &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
    );
    assert!(l.width >= 400 && l.height >= 100);
}

/// Under least squares, `--plot` draws the data, the fitted curves and their confidence
/// bands: every fit's colour and the band's shade are on the canvas.
#[test]
fn lsq_fit_plots_render() {
    check(
        "lsq_jan",
        &["jan"],
        &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
    );
    check(
        "lsq_klaw",
        &["klaw", "--model", "stickslip"],
        &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
    );
    check("lsq_jaeger", &["jaeger"], &[rgb(PALETTE[0], 1.0)]);
}

/// A corner plot of 20 000 correlated normal draws: contours, quantiles and titles render
/// without overlapping text, and the document stays small (density cells and at most
/// `MAX_POINTS` draws per panel, not one circle per draw).
#[test]
fn corner_plot_of_many_draws_stays_small() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let n = 20_000;
    let z: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            let a: f64 = StandardNormal.sample(&mut rng);
            let b: f64 = StandardNormal.sample(&mut rng);
            let c: f64 = StandardNormal.sample(&mut rng);
            [
                0.19 + 0.02 * a,
                18.0 + 3.0 * (0.8 * a + 0.6 * b),
                1.3 + 0.1 * c,
            ]
        })
        .collect();
    let block = CornerBlock {
        title: "jaeger [1]".into(),
        names: vec!["a1".into(), "a2".into(), "a3".into()],
        draws: (0..3).map(|k| z.iter().map(|d| d[k]).collect()).collect(),
        optimum: vec![0.19, 18.0, 1.3],
    };
    let svg = CornerBlock::svg(&[block]).unwrap();
    assert!(svg.len() < 400_000, "{} bytes", svg.len());
    // The axis label a₁: a subscript 1 set smaller (0.72 of 16 px), at its own position.
    assert!(svg.contains(">a</tspan><tspan x=\""));
    assert!(svg.contains("font-size=\"11.52\">1</tspan>"));
    let l = look(
        "corner_synthetic",
        &svg,
        &out_dir().join("corner_synthetic.png"),
        &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
    );
    assert!(l.width >= 600 && l.height >= 600);
    // One parameter, and four with long names (one K per series).
    for names in [vec!["c"], vec!["K[0.8]", "K[1]", "K[1.6]", "K[2]"]] {
        let n = names.len();
        let block = CornerBlock {
            title: "stick/slip, K per series".into(),
            names: names.iter().map(|s| s.to_string()).collect(),
            draws: (0..n)
                .map(|k| {
                    z.iter()
                        .map(|d| 0.5 + 0.1 * k as f64 + 0.01 * d[k % 3])
                        .collect()
                })
                .collect(),
            optimum: (0..n).map(|k| 0.5 + 0.1 * k as f64).collect(),
        };
        let svg = CornerBlock::svg(&[block]).unwrap();
        look(
            &format!("corner_synthetic_{n}"),
            &svg,
            &out_dir().join(format!("corner_synthetic_{n}.png")),
            &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
        );
    }
}

#[test]
fn k_plot_renders() {
    check(
        "k_stick",
        &["k", "--model", "stick"],
        &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
    );
}

/// The report's figures and the colours each must show.
fn report_figures() -> Vec<(&'static str, Vec<[u8; 3]>)> {
    let series: Vec<[u8; 3]> = PALETTE[..4].iter().map(|c| rgb(c, 1.0)).collect();
    vec![
        ("velocity", series.clone()),
        ("jan_linear", series.clone()),
        ("k_final_velocity", series.clone()),
        ("k_alpha", series.clone()),
        ("residuals", series),
        (
            "regime_map",
            vec![
                rgb("#000000", 1.0),
                rgb("#56B4E9", 0.22),
                rgb("#009E73", 0.22),
                rgb("#E69F00", 0.22),
            ],
        ),
        ("jaeger", vec![rgb(PALETTE[3], 1.0), rgb("#000000", 1.0)]),
        (
            "energy",
            vec![
                rgb(PALETTE[0], 1.0),
                rgb(PALETTE[4], 1.0),
                rgb(PALETTE[2], 1.0),
            ],
        ),
    ]
}

#[test]
fn report_figures_render() {
    let dir = out_dir().join("report");
    let out = bin()
        .args(["report", "--out-dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let figs = report_figures();
    // Every figure the report lists is checked here.
    let listed: Vec<&str> = report_files()
        .iter()
        .filter_map(|f| f.strip_suffix(".svg"))
        .collect();
    let mut names: Vec<&str> = figs.iter().map(|f| f.0).collect();
    names.sort_unstable();
    let mut want = listed.clone();
    want.sort_unstable();
    assert_eq!(names, want);
    for (name, colours) in figs {
        let svg = std::fs::read_to_string(dir.join(format!("{name}.svg"))).unwrap();
        // The embedded font named first.
        assert!(svg.contains("font-family=\"DejaVu Sans,"), "{name}");
        // Curves at sub-pixel coordinates (no stairs): most polyline coordinates are not
        // whole pixels.
        let coords: Vec<&str> = svg
            .split("<polyline points=\"")
            .skip(1)
            .flat_map(|p| p.split('"').next().unwrap().split([' ', ',']))
            .collect();
        let whole = coords.iter().filter(|c| !c.contains('.')).count();
        assert!(
            (whole as f64) < 0.5 * coords.len() as f64,
            "{name}: {whole} of {} coordinates whole",
            coords.len()
        );
        let l = look(
            &format!("report {name}"),
            &svg,
            &dir.join(format!("{name}.png")),
            &colours,
        );
        assert!(
            l.width >= 400 && l.height >= 300,
            "{name}: {}x{}",
            l.width,
            l.height
        );
    }
    // No text smaller than 14 px.
    for (name, _) in report_figures() {
        let svg = std::fs::read_to_string(dir.join(format!("{name}.svg"))).unwrap();
        for part in svg.split("<text ").skip(1) {
            let size: f64 = part
                .split("font-size=\"")
                .nth(1)
                .and_then(|s| s.split('"').next())
                .and_then(|s| s.parse().ok())
                .unwrap();
            assert!(size >= 14.0, "{name}: text at {size} px");
        }
    }
}

/// `--format png` writes a PNG, twice the SVG's size, for every figure and no SVG; `both`
/// writes both; anything else is refused with exit 2.
#[test]
fn report_format_png_and_both() {
    let base = out_dir().join("report_png");
    let _ = std::fs::remove_dir_all(&base);
    for fmt in ["png", "both"] {
        let dir = base.join(fmt);
        let out = bin()
            .args(["report", "--format", fmt, "--out-dir"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        for f in report_files() {
            let Some(stem) = f.strip_suffix(".svg") else {
                assert!(dir.join(f).exists(), "{fmt}: {f}");
                continue;
            };
            let png = std::fs::read(dir.join(format!("{stem}.png"))).unwrap();
            assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{fmt}: {stem}");
            let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
            assert_eq!(dir.join(f).exists(), fmt == "both", "{fmt}: {f}");
            if fmt == "both" {
                let svg = std::fs::read_to_string(dir.join(f)).unwrap();
                let sw = parse(&svg).unwrap().size().width();
                assert_eq!(w, (2.0 * sw).round() as u32, "{stem}");
            }
        }
    }
    let out = bin()
        .args(["report", "--format", "gif", "--out-dir"])
        .arg(base.join("gif"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--format"), "{}", stderr(&out));
    assert!(!base.join("gif").exists());
}

#[test]
fn bench_plot_renders() {
    check(
        "bench_wp",
        &["bench", "--scenes", "40"],
        &[rgb(PALETTE[0], 1.0), rgb(PALETTE[1], 1.0)],
    );
}

/// The overlap check sees overlapping text (and not text side by side).
#[test]
fn overlap_check_sees_overlapping_text() {
    let doc = |x2: f64| {
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"300\" height=\"60\">\
             <text x=\"10\" y=\"30\" font-size=\"16\">slope δ</text>\
             <text x=\"{x2}\" y=\"34\" font-size=\"16\">K</text></svg>"
        )
    };
    assert_eq!(overlapping_texts(&doc(40.0), 0.5).len(), 1);
    assert!(overlapping_texts(&doc(150.0), 0.5).is_empty());
}
