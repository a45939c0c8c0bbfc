//! The SVG figures render: each is drawn by the command that makes it, rasterised with resvg
//! (an independent SVG renderer), and must be a non-trivial picture: ink on a fair part of
//! the canvas and several colours. The PNGs are left in the test's temporary directory
//! (`target/tmp/figures/`) for a look.

use std::path::{Path, PathBuf};

use crate::common::bin;

fn out_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("figures");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Rasterises `svg` to `png` and returns (width, height, fraction of non-white pixels,
/// number of distinct colours).
fn render(svg: &Path, png: &Path) -> (u32, u32, f64, usize) {
    let data = std::fs::read(svg).unwrap();
    let mut opt = resvg::usvg::Options::default();
    let db = opt.fontdb_mut();
    db.load_system_fonts();
    db.set_sans_serif_family("DejaVu Sans");
    let tree = resvg::usvg::Tree::from_data(&data, &opt).expect("valid SVG");
    let size = tree.size().to_int_size();
    let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pixmap.as_mut(),
    );
    pixmap.save_png(png).unwrap();
    let px = pixmap.pixels();
    let ink = px
        .iter()
        .filter(|p| !(p.red() > 250 && p.green() > 250 && p.blue() > 250))
        .count();
    let mut colours: Vec<u32> = px
        .iter()
        .map(|p| (p.red() as u32) << 16 | (p.green() as u32) << 8 | p.blue() as u32)
        .collect();
    colours.sort_unstable();
    colours.dedup();
    (
        size.width(),
        size.height(),
        ink as f64 / px.len() as f64,
        colours.len(),
    )
}

fn check(name: &str, args: &[&str]) {
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
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (w, h, ink, colours) = render(&svg, &dir.join(format!("{name}.png")));
    println!("{name}: {w}x{h} px, ink {ink:.3}, {colours} colours");
    assert!(w >= 400 && h >= 100, "{name}: {w}x{h}");
    assert!(ink > 0.02, "{name}: only {ink} of the canvas inked");
    assert!(colours > 8, "{name}: {colours} colours");
}

#[test]
fn corner_plot_renders() {
    check(
        "corner_jan",
        &["jan", "--method", "mcmc", "--min-ess", "200"],
    );
}

#[test]
fn k_plot_renders() {
    check("k_stick", &["k", "--model", "stick"]);
}

#[test]
fn report_figures_render() {
    let dir = out_dir().join("report");
    let out = bin()
        .args(["report", "--out-dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for name in ["velocity", "jan_linear", "k_final_velocity", "regime_map"] {
        let (w, h, ink, colours) = render(
            &dir.join(format!("{name}.svg")),
            &dir.join(format!("{name}.png")),
        );
        println!("report {name}: {w}x{h} px, ink {ink:.3}, {colours} colours");
        assert!(w >= 400 && h >= 300, "{name}: {w}x{h}");
        assert!(ink > 0.02, "{name}: only {ink} of the canvas inked");
        assert!(colours > 8, "{name}: {colours} colours");
    }
}

#[test]
fn bench_plot_renders() {
    check("bench_wp", &["bench", "--scenes", "40"]);
}
