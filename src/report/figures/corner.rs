//! Corner plots of posterior draws, after corner.py: the marginal histogram of each parameter
//! on the diagonal with its 16, 50 and 84 % quantiles and a "name = median ± error" title;
//! below it, each pair's smoothed two-dimensional histogram with the contours that enclose
//! 39.3 % and 86.5 % of the draws (the 1σ and 2σ regions of a two-dimensional normal) and the
//! draws outside the outer contour, thinned. The least-squares optimum is marked on every
//! panel. The SVG stays small whatever the number of draws: the density is a fixed grid of
//! cells and at most [`MAX_POINTS`] draws are drawn per panel.

use super::plot::{Axis, Figure, Item, LegendEntry, Panel, PALETTE};
use super::svg::{Mark, Stroke};
use super::FigureError;
use crate::fit::posterior::draws_column;
use crate::fit::summary::FitResult;

/// The pooled draws of one posterior.
#[derive(Debug, Clone, Default)]
pub struct CornerBlock {
    /// Heading (fit and series).
    pub title: String,
    /// Parameter names (as in the draws file, `draws_column`).
    pub names: Vec<String>,
    /// Draws per parameter (same length for every parameter).
    pub draws: Vec<Vec<f64>>,
    /// The least-squares optimum per parameter (NaN where unknown).
    pub optimum: Vec<f64>,
}

impl CornerBlock {
    /// The block of one posterior, if it kept draws.
    pub fn from_posterior(p: &FitResult) -> Option<CornerBlock> {
        let d = p.draws.as_ref()?;
        let draws: Vec<Vec<f64>> = (0..p.params.len())
            .map(|j| d.chains.iter().flatten().map(|x| x[j]).collect())
            .collect();
        if draws.first().is_none_or(|v| v.is_empty()) {
            return None;
        }
        let title = format!("{} [{}]", p.stats.fit, p.stats.series);
        Some(CornerBlock {
            title: if d.interrupted {
                format!("{title} (interrupted)")
            } else {
                title
            },
            names: p.params.iter().map(|r| draws_column(p, r)).collect(),
            draws,
            optimum: p
                .params
                .iter()
                .map(|r| r.lsq_value.unwrap_or(f64::NAN))
                .collect(),
        })
    }

    /// One block per posterior that kept draws.
    pub fn from_posteriors(posteriors: &[&FitResult]) -> Vec<CornerBlock> {
        posteriors
            .iter()
            .filter_map(|p| Self::from_posterior(p))
            .collect()
    }
}

/// Bins of the marginal histograms.
const BINS: usize = 36;
/// Cells per side of the two-dimensional histograms.
const CELLS: usize = 30;
/// Draws drawn as points per pair panel at most.
pub const MAX_POINTS: usize = 400;
/// Steps of shading of the two-dimensional density.
const SHADES: usize = 8;
/// Probability mass inside the 1σ and 2σ contours of a two-dimensional normal,
/// 1 − e^{−k²/2} for k = 1, 2.
pub(crate) const CONTOUR_MASS: [f64; 2] = [0.393_469_340_287_366_6, 0.864_664_716_763_387_3];

const DRAWS: &str = PALETTE[0];
const OPTIMUM: &str = PALETTE[1];

/// A parameter name as a label: Greek letters for λ and μ, trailing digits as subscripts
/// (`a1` → a₁, `lambda0` → λ₀), a series in brackets kept.
pub(crate) fn param_label(name: &str) -> String {
    let (base, tail) = match name.find('[') {
        Some(i) => (&name[..i], &name[i..]),
        None => (name, ""),
    };
    let digits = base.trim_end_matches(|c: char| c.is_ascii_digit());
    let sub = &base[digits.len()..];
    let greek = match digits {
        "lambda" => "λ",
        "mu" => "μ",
        "sigma" => "σ",
        "alpha" => "α",
        "delta" => "δ",
        "xi" => "ξ",
        other => other,
    };
    if sub.is_empty() {
        format!("{greek}{tail}")
    } else {
        format!("{greek}_{{{sub}}}{tail}")
    }
}

/// The q-quantile of sorted finite values (linear interpolation).
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = q * (sorted.len() - 1) as f64;
    let i = h.floor() as usize;
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + (h - i as f64) * (sorted[j] - sorted[i])
}

/// "value ± error" with the error to two significant digits and the value to the same
/// decimal place.
pub(crate) fn value_pm(value: f64, err: f64) -> String {
    if !(err.is_finite() && err > 0.0) {
        return crate::numfmt::fmt_sig(value, 4);
    }
    let dec = (1 - err.log10().floor() as i32).max(0) as usize;
    let s = format!("{value:.dec$} ± {err:.dec$}");
    s.replace('-', "\u{2212}")
}

/// The plotted range of a parameter: its 0.5–99.5 % quantiles (and the optimum), padded.
fn axis_range(sorted: &[f64], opt: f64) -> (f64, f64) {
    let mut lo = quantile(sorted, 0.005);
    let mut hi = quantile(sorted, 0.995);
    if opt.is_finite() {
        lo = lo.min(opt);
        hi = hi.max(opt);
    }
    if !(hi > lo) {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return (lo - d, hi + d);
    }
    let pad = 0.08 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Counts of (x, y) draws on a CELLS × CELLS grid over the ranges, and the same smoothed by a
/// Gaussian of one cell; index [j][i] (y row, x column).
type Grid2 = Vec<Vec<f64>>;

fn density(x: &[f64], y: &[f64], xr: (f64, f64), yr: (f64, f64)) -> (Grid2, Grid2) {
    let mut h = vec![vec![0.0; CELLS]; CELLS];
    for (&a, &b) in x.iter().zip(y) {
        let i = ((a - xr.0) / (xr.1 - xr.0) * CELLS as f64).floor();
        let j = ((b - yr.0) / (yr.1 - yr.0) * CELLS as f64).floor();
        if (0.0..CELLS as f64).contains(&i) && (0.0..CELLS as f64).contains(&j) {
            h[j as usize][i as usize] += 1.0;
        }
    }
    let k: Vec<f64> = (-2i32..=2).map(|d| (-0.5 * (d * d) as f64).exp()).collect();
    let blur = |src: &Vec<Vec<f64>>, along_x: bool| {
        let mut out = vec![vec![0.0; CELLS]; CELLS];
        for (j, row) in out.iter_mut().enumerate() {
            for (i, cell) in row.iter_mut().enumerate() {
                let mut s = 0.0;
                for (o, w) in k.iter().enumerate() {
                    let d = o as i64 - 2;
                    let (ii, jj) = if along_x {
                        (i as i64 + d, j as i64)
                    } else {
                        (i as i64, j as i64 + d)
                    };
                    if (0..CELLS as i64).contains(&ii) && (0..CELLS as i64).contains(&jj) {
                        s += w * src[jj as usize][ii as usize];
                    }
                }
                *cell = s;
            }
        }
        out
    };
    let smooth = blur(&blur(&h, true), false);
    (h, smooth)
}

/// The thresholds of the smoothed density `d` whose superlevel sets hold `CONTOUR_MASS` of
/// the draws counted in `h` (the smoothing gives the contours their shape; the counts, not the
/// smoothed mass, decide the level, so that the 1σ contour holds 39.3 % of the draws and not
/// the larger share a widened density would give it).
fn levels(h: &[Vec<f64>], d: &[Vec<f64>]) -> [f64; 2] {
    let mut v: Vec<(f64, f64)> = d
        .iter()
        .flatten()
        .zip(h.iter().flatten())
        .map(|(&a, &b)| (a, b))
        .collect();
    v.sort_by(|a, b| b.0.total_cmp(&a.0));
    let total: f64 = v.iter().map(|p| p.1).sum();
    let mut out = [f64::INFINITY; 2];
    for (k, m) in CONTOUR_MASS.iter().enumerate() {
        let mut acc = 0.0;
        for &(level, count) in &v {
            acc += count;
            if acc >= m * total {
                out[k] = level;
                break;
            }
        }
    }
    out
}

/// The contour of `d` at `level` by marching squares, as segments in data coordinates (the
/// grid padded with zeros so that contours close).
fn contour(d: &[Vec<f64>], level: f64, xr: (f64, f64), yr: (f64, f64)) -> Vec<[(f64, f64); 2]> {
    let n = CELLS as i64;
    let at = |i: i64, j: i64| -> f64 {
        if (0..n).contains(&i) && (0..n).contains(&j) {
            d[j as usize][i as usize]
        } else {
            0.0
        }
    };
    // Cell centre (i, j) in data coordinates.
    let cx = |i: f64| xr.0 + (i + 0.5) / CELLS as f64 * (xr.1 - xr.0);
    let cy = |j: f64| yr.0 + (j + 0.5) / CELLS as f64 * (yr.1 - yr.0);
    let mut segs = Vec::new();
    for j in -1..n {
        for i in -1..n {
            // Corners: 0 (i, j), 1 (i+1, j), 2 (i+1, j+1), 3 (i, j+1).
            let c = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let pos = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
            let mut cross = Vec::with_capacity(4);
            for e in 0..4 {
                let (a, b) = (e, (e + 1) % 4);
                if (c[a] >= level) != (c[b] >= level) {
                    let t = (level - c[a]) / (c[b] - c[a]);
                    let x = pos[a].0 + t * (pos[b].0 - pos[a].0);
                    let y = pos[a].1 + t * (pos[b].1 - pos[a].1);
                    cross.push((cx(i as f64 + x), cy(j as f64 + y)));
                }
            }
            for p in cross.chunks_exact(2) {
                segs.push([p[0], p[1]]);
            }
        }
    }
    segs
}

/// The corner plot of one block as a figure.
pub fn corner_figure(b: &CornerBlock) -> Figure {
    let n = b.names.len();
    let sorted: Vec<Vec<f64>> = b
        .draws
        .iter()
        .map(|d| {
            let mut s: Vec<f64> = d.iter().copied().filter(|v| v.is_finite()).collect();
            s.sort_by(|a, c| a.total_cmp(c));
            s
        })
        .collect();
    let opt = |k: usize| b.optimum.get(k).copied().unwrap_or(f64::NAN);
    let ranges: Vec<(f64, f64)> = (0..n).map(|k| axis_range(&sorted[k], opt(k))).collect();
    let labels: Vec<String> = b.names.iter().map(|s| param_label(s)).collect();
    let opt_stroke = Stroke::solid(OPTIMUM, 1.5);
    let q_stroke = Stroke::solid("#333333", 1.2).dashed("5 4");
    let mut panels: Vec<Option<Panel>> = Vec::new();
    for r in 0..n {
        for c in 0..n {
            if c > r {
                panels.push(None);
                continue;
            }
            let mut x = Axis::new(if r == n - 1 { &labels[c] } else { "" })
                .with_range(ranges[c].0, ranges[c].1);
            x.hide_tick_labels = r != n - 1;
            x.ticks = 3;
            let mut p = if r == c {
                diagonal(&sorted[c], ranges[c], &labels[c], x, &q_stroke)
            } else {
                let mut y = Axis::new(if c == 0 { &labels[r] } else { "" })
                    .with_range(ranges[r].0, ranges[r].1);
                y.hide_tick_labels = c != 0;
                y.ticks = 3;
                pair(&b.draws[c], &b.draws[r], ranges[c], ranges[r], x, y)
            };
            if opt(c).is_finite() {
                p.items.push(Item::VLine {
                    x: opt(c),
                    stroke: opt_stroke.clone(),
                });
            }
            if r != c && opt(r).is_finite() {
                p.items.push(Item::HLine {
                    y: opt(r),
                    stroke: opt_stroke.clone(),
                });
                p.items.push(Item::Points {
                    pts: vec![(opt(c), opt(r), f64::NAN, f64::NAN)],
                    colour: OPTIMUM.to_string(),
                    mark: Mark::Square,
                    radius: 4.0,
                    fill_opacity: 1.0,
                });
            }
            panels.push(Some(p));
        }
    }
    let mut f = Figure::new(&b.title, n, (210.0, 210.0), Vec::new());
    f.panels = panels;
    let draws: usize = b.draws.first().map_or(0, Vec::len);
    f.legend = vec![LegendEntry::patch(
        &format!("posterior ({draws} draws)"),
        DRAWS,
        0.5,
    )];
    if n > 1 {
        f.legend.push(LegendEntry::line(
            "1σ and 2σ contours",
            &Stroke::solid(DRAWS, 1.6),
        ));
    }
    f.legend.extend([
        LegendEntry::line("16, 50, 84 % quantiles", &q_stroke),
        LegendEntry::mark_line("least-squares optimum", Mark::Square, &opt_stroke),
    ]);
    f
}

/// A diagonal panel: the marginal histogram, its quantiles and a "name = value ± error"
/// title.
fn diagonal(s: &[f64], xr: (f64, f64), label: &str, x: Axis, q_stroke: &Stroke) -> Panel {
    let w = (xr.1 - xr.0) / BINS as f64;
    let mut counts = vec![0.0; BINS];
    for v in s {
        let k = ((v - xr.0) / w).floor();
        if (0.0..BINS as f64).contains(&k) {
            counts[k as usize] += 1.0;
        }
    }
    let peak = counts.iter().copied().fold(1.0, f64::max);
    let mut outline = vec![(xr.0, 0.0)];
    for (k, &h) in counts.iter().enumerate() {
        let a = xr.0 + k as f64 * w;
        outline.push((a, h / peak));
        outline.push((a + w, h / peak));
    }
    outline.push((xr.1, 0.0));
    let (q16, q50, q84) = (quantile(s, 0.16), quantile(s, 0.5), quantile(s, 0.84));
    let mut y = Axis::new("").with_range(0.0, 1.12);
    y.hide_tick_labels = true;
    y.ticks = 2;
    let mut p = Panel::new(
        &format!("{label} = {}", value_pm(q50, 0.5 * (q84 - q16))),
        x,
        y,
    );
    p.items.push(Item::Fill {
        pts: outline.clone(),
        colour: DRAWS.to_string(),
        opacity: 0.25,
    });
    p.curve(outline, Stroke::solid(DRAWS, 1.5));
    for q in [q16, q50, q84] {
        p.items.push(Item::VLine {
            x: q,
            stroke: q_stroke.clone(),
        });
    }
    p
}

/// A pair panel: shaded density, 1σ/2σ contours and the thinned draws outside them.
fn pair(x: &[f64], y: &[f64], xr: (f64, f64), yr: (f64, f64), xa: Axis, ya: Axis) -> Panel {
    let (h, d) = density(x, y, xr, yr);
    let lv = levels(&h, &d);
    let peak = d.iter().flatten().copied().fold(0.0, f64::max);
    let (dx, dy) = ((xr.1 - xr.0) / CELLS as f64, (yr.1 - yr.0) / CELLS as f64);
    // Cells inside the outer contour, shaded in SHADES steps of density; a run of cells of
    // one shade along x is one rectangle.
    let shade = |v: f64| -> Option<usize> {
        (peak > 0.0 && v >= lv[1])
            .then(|| ((v / peak * SHADES as f64).ceil() as usize).clamp(1, SHADES))
    };
    let mut rects = Vec::new();
    for (j, row) in d.iter().enumerate() {
        let mut i = 0;
        while i < CELLS {
            let Some(k) = shade(row[i]) else {
                i += 1;
                continue;
            };
            let start = i;
            while i < CELLS && shade(row[i]) == Some(k) {
                i += 1;
            }
            let (a, b) = (xr.0 + start as f64 * dx, yr.0 + j as f64 * dy);
            let e = xr.0 + i as f64 * dx;
            rects.push((a, e, b, b + dy, 0.12 + 0.5 * k as f64 / SHADES as f64));
        }
    }
    let mut p = Panel::new("", xa, ya);
    p.items.push(Item::Rects {
        rects,
        colour: DRAWS.to_string(),
    });
    // Draws outside the outer contour, thinned by an even stride.
    let cell = |a: f64, b: f64| -> Option<f64> {
        let i = ((a - xr.0) / dx).floor();
        let j = ((b - yr.0) / dy).floor();
        ((0.0..CELLS as f64).contains(&i) && (0.0..CELLS as f64).contains(&j))
            .then(|| d[j as usize][i as usize])
    };
    let outside: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .filter(|(a, b)| cell(**a, **b).is_some_and(|v| v < lv[1]))
        .map(|(a, b)| (*a, *b))
        .collect();
    let stride = outside.len().div_ceil(MAX_POINTS).max(1);
    p.items.push(Item::Dots {
        pts: outside.iter().step_by(stride).copied().collect(),
        colour: DRAWS.to_string(),
        radius: 1.3,
    });
    for l in lv {
        if l.is_finite() && l > 0.0 {
            p.items.push(Item::Segments {
                segs: contour(&d, l, xr, yr),
                stroke: Stroke::solid(DRAWS, 1.6),
            });
        }
    }
    p
}

impl CornerBlock {
    /// Corner plots of `blocks`, one under the other in one SVG document.
    pub fn svg(blocks: &[CornerBlock]) -> Result<String, FigureError> {
        let figs: Vec<Figure> = blocks.iter().map(corner_figure).collect();
        Ok(super::plot::stack_svg(&figs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_greek_with_subscripts() {
        assert_eq!(param_label("a1"), "a_{1}");
        assert_eq!(param_label("lambda0"), "λ_{0}");
        assert_eq!(param_label("mu"), "μ");
        assert_eq!(param_label("K[0.8]"), "K[0.8]");
    }

    #[test]
    fn value_pm_rounds_to_the_error() {
        assert_eq!(value_pm(0.190_43, 0.021_7), "0.190 ± 0.022");
        assert_eq!(value_pm(18.57, 3.2), "18.6 ± 3.2");
        assert_eq!(value_pm(-1.234, 0.5), "\u{2212}1.23 ± 0.50");
    }

    /// Draws from a standard bivariate normal: the cells inside the 1σ contour hold 39.3 % of
    /// them and those inside the 2σ contour 86.5 % (the masses of 1 − e^{−k²/2}).
    #[test]
    fn contour_levels_hold_their_mass() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let n = 40_000;
        let x: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut rng)).collect();
        let y: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut rng)).collect();
        let (xr, yr) = ((-4.5, 4.5), (-4.5, 4.5));
        let (h, d) = density(&x, &y, xr, yr);
        let lv = levels(&h, &d);
        let cw = 9.0 / CELLS as f64;
        for (k, want) in CONTOUR_MASS.iter().enumerate() {
            let inside = x
                .iter()
                .zip(&y)
                .filter(|(a, b)| {
                    let i = ((*a + 4.5) / cw).floor();
                    let j = ((*b + 4.5) / cw).floor();
                    (0.0..CELLS as f64).contains(&i)
                        && (0.0..CELLS as f64).contains(&j)
                        && d[j as usize][i as usize] >= lv[k]
                })
                .count() as f64
                / n as f64;
            // A level set is a union of whole cells: it holds the mass up to one cell's share
            // of draws on its edge.
            assert!((inside - want).abs() < 0.01, "{k}: {inside} vs {want}");
        }
        // The contour holding 1 − e^{−k²/2} of a standard bivariate normal is the circle of
        // radius k: every contour point within 0.1 + 0.1 k of it (a third of a cell, plus the
        // sampling noise of the tails).
        for (k, l) in lv.iter().enumerate() {
            let segs = contour(&d, *l, xr, yr);
            assert!(segs.len() > 20, "{k}: {} segments", segs.len());
            let r = (k + 1) as f64;
            for p in segs.iter().flatten() {
                let rad = (p.0 * p.0 + p.1 * p.1).sqrt();
                assert!(
                    (rad - r).abs() < 0.1 * r + 0.1,
                    "{k}: point at radius {rad}"
                );
            }
        }
    }
}
