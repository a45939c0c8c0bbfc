//! The report's text: report.md and the summary printed at the end of `fitbead report`.

use super::analysis::{sig3, Analysis};
use super::figures::FigureFormat;
use crate::fit::data::SiSeries;
use crate::fit::summary::ParamRow;
use crate::models::JaegerBranch;
use crate::numfmt::{fmt_f64, fmt_interval, fmt_sig, fmt_value_pm};

/// What report.md says besides the analysis: where the data came from and which figure files
/// were written.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportContext {
    /// How the data are named (a path, or the embedded data set's name).
    pub source: String,
    /// Whether the data are the shipped synthetic data set (data/default.csv), which is not a
    /// measurement: report.md then opens with a banner saying so.
    pub shipped_synthetic: bool,
    /// When the velocities were given in m/s: how each series was made dimensionless.
    pub si: Option<Vec<SiSeries>>,
    /// The format of the figure files (report.md links to them).
    pub figure_format: FigureFormat,
    /// The corner plots written (their SVG names, `corner_<fit>_<series>.svg`).
    pub corner_files: Vec<String>,
    /// What the input checks of the fit commands found and `report --keep-going` let pass
    /// (points left out of a model's fits, laws not fitted): report.md opens with them.
    pub input_warnings: Vec<String>,
    /// Unit mistakes the data look like, and fits whose misfit is absurd: report.md opens
    /// with them too.
    pub plausibility: Vec<String>,
    /// Fits whose χ² tail probability is below 0.001 with σ given
    /// ([`crate::fit::StatsRow::misfit_warning`]): named in the same section.
    pub misfits: Vec<String>,
}

/// The section report.md opens with when the data failed an input check (`--keep-going`),
/// look like a unit mistake, or are not described by a fit within their σ; empty otherwise.
fn warnings_section(ctx: &ReportContext) -> String {
    if ctx.input_warnings.is_empty() && ctx.plausibility.is_empty() && ctx.misfits.is_empty() {
        return String::new();
    }
    let mut m = String::from("## Warnings\n\n");
    if !ctx.input_warnings.is_empty() {
        m.push_str(
            "The data fail input checks that make the fit commands exit 2; this report was \
             written anyway (`--keep-going`), without what they leave out:\n\n",
        );
        for w in &ctx.input_warnings {
            m.push_str(&format!("- {}\n", one_line(w)));
        }
        m.push('\n');
    }
    if !ctx.plausibility.is_empty() {
        m.push_str(
            "The data read fine but look like a unit mistake (thresholds in docs/GUIDE.md, \
             \"Plausibility checks\"):\n\n",
        );
        for w in &ctx.plausibility {
            m.push_str(&format!("- {}\n", one_line(w)));
        }
        m.push('\n');
    }
    if !ctx.misfits.is_empty() {
        m.push_str(
            "These fits do not describe the data within their sigma_v (chi2 tail probability \
             below 0.001): their intervals assume the model holds and are too narrow:\n\n",
        );
        for w in &ctx.misfits {
            m.push_str(&format!("- {}\n", one_line(w)));
        }
        m.push('\n');
    }
    m
}

/// `s` as a Markdown table cell: `|` escaped (`\|`), every line break a space, cut as
/// [`one_line`] cuts. Series labels are data: one with `|` or a newline must not split or end
/// a row, and a huge one must not flood the page (the CSV tables keep it whole).
pub(crate) fn table_cell(s: &str) -> String {
    one_line(s).replace('|', "\\|")
}

/// `s` on one Markdown line (a list item, a paragraph): every line break (CR, LF or both) a
/// space; cut to 4,000 characters ([`crate::numfmt::clip`]).
pub fn one_line(s: &str) -> String {
    crate::numfmt::clip(s, 4000)
        .replace("\r\n", " ")
        .replace(['\r', '\n'], " ")
}

/// A parameter's name in the report's tables: qualified by series where a fit across series
/// has one per series (`K[1.6]`).
fn param_name(r: &ParamRow, fit_series: &str) -> String {
    if r.series == fit_series {
        r.parameter.clone()
    } else {
        format!("{}[{}]", r.parameter, crate::numfmt::clip(&r.series, 120))
    }
}

/// `value ± stderr` of a row (the posterior median ± sd for a posterior run).
fn value_pm(r: &ParamRow) -> String {
    fmt_value_pm(r.value, r.stderr)
}

/// The reported interval of a row with its method, or a dash.
fn interval_cell(r: &ParamRow) -> String {
    match r.interval() {
        (Some((lo, hi)), method) => format!("{} {method}", fmt_interval(lo, hi, r.stderr)),
        (None, _) => "—".into(),
    }
}

/// The report's opening table: every fitted parameter with its value ± standard error and its
/// interval, the paper's value where there is one, and a flag for a parameter on its bound.
fn parameter_table(an: &Analysis) -> String {
    let mut m = String::new();
    m.push_str("## Fitted parameters\n\n");
    m.push_str(&format!(
        "Every fitted parameter: value ± standard error{}, the {} % interval and how it was \
         obtained (profile likelihood, covariance or posterior), and the paper's value where it \
         gives one. Per-point fits and residuals: [residuals.csv](residuals.csv); correlations: \
         [correlations.csv](correlations.csv); every column: [params.csv](params.csv); each \
         fit's report: [Fit reports](#fit-reports) below.\n\n",
        if an.mcmc {
            " (posterior median ± standard deviation)"
        } else {
            ""
        },
        fmt_sig(100.0 * an.level, 6)
    ));
    m.push_str("| fit | series | parameter | value | interval | paper | note |\n");
    m.push_str("|---|---|---|---|---|---|---|\n");
    for f in an.fit_results() {
        for r in &f.params {
            let series = if r.series == f.stats.series {
                r.series.clone()
            } else {
                f.stats.series.clone()
            };
            let flagged = r.sensitivity.filter(|x| !x.diagnosis().is_empty());
            let note = if let Some(x) = flagged {
                format!(
                    "{} (power-scaling sensitivity to the prior {}, to the likelihood {})",
                    x.diagnosis(),
                    fmt_sig(x.prior, 2),
                    fmt_sig(x.likelihood, 2)
                )
            } else if r.at_bound {
                format!("on the bound {}", fmt_sig(bound_of(r), 4))
            } else if r.interval().0.is_none() {
                // Why there is no interval, in the words of the row's note.
                r.note
                    .split(". ")
                    .find(|s| s.contains("profile") || s.contains("not determined"))
                    .map_or("no interval".to_string(), |s| {
                        format!("no interval: {}", s.trim_end_matches('.'))
                    })
            } else if r.stderr.is_none() && !an.mcmc {
                if f.stats.note.contains("rank deficient") {
                    "no standard error (rank-deficient Jacobian)".to_string()
                } else {
                    "no standard error".to_string()
                }
            } else {
                String::new()
            };
            m.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} |\n",
                table_cell(&f.stats.fit),
                table_cell(&series),
                table_cell(&param_name(r, &f.stats.series)),
                value_pm(r),
                interval_cell(r),
                r.paper_value.map_or("—".into(), |v| fmt_sig(v, 4)),
                table_cell(&note),
            ));
        }
    }
    m.push('\n');
    let fits = an.fit_results();
    let bad: Vec<String> = fits
        .iter()
        .filter(|f| !f.converged())
        .map(|f| one_line(&format!("{} [{}]", f.stats.fit, f.stats.series)))
        .collect();
    if !bad.is_empty() {
        m.push_str(&format!(
            "**Not converged:** {} (their values are not an optimum; see the fit reports).\n\n",
            bad.join(", ")
        ));
    }
    m
}

/// The end of its box a parameter sits on.
fn bound_of(r: &ParamRow) -> f64 {
    if (r.value - r.bounds.0).abs() <= (r.value - r.bounds.1).abs() {
        r.bounds.0
    } else {
        r.bounds.1
    }
}

/// The Jaeger section: the fitted a1–a3 per series against the paper's Fig. 9, the branch, the
/// points in the bistable band (eq 90), and what a2 on its bound 0 means.
fn jaeger_section(an: &Analysis, ctx: &ReportContext) -> String {
    let mut m = String::new();
    m.push_str("## Jaeger's law (eqs 80–90)\n\n");
    m.push_str(&format!(
        "tan δ = a3 u² + a1/(1 + a2 u²) with Jaeger's velocity u (eq 81), fitted per series on \
         the branch of eq 84 named below; a1 is the friction at rest, a1/(1 + a2 u²) its decay \
         with speed and a3 u² the collisional drag. Figure: {} (Figs. 9–10).\n\n",
        figure_link(ctx, "jaeger.svg")
    ));
    m.push_str(
        "| series | ξ | a1 | a2 | a3 | χ²/dof | branch | a1·a2 > a3 (eq 82) | points in the \
         bistable band (eq 90) | paper a1, a2, a3 (Fig. 9) |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut on_bound = 0;
    let mut fitted = 0;
    for (s, f) in an.jaeger.series.iter().enumerate() {
        let Some(f) = f else { continue };
        fitted += 1;
        let p = &f.summary.params;
        let cell = |i: usize| p.get(i).map_or("—".to_string(), value_pm);
        if p.get(1).is_some_and(|r| r.at_bound && r.value == 0.0) {
            on_bound += 1;
        }
        let paper: Vec<String> = p
            .iter()
            .filter_map(|r| r.paper_value.map(|v| fmt_sig(v, 4)))
            .collect();
        m.push_str(&format!(
            "| {} | {} | {} | {} | {} | {}/{} | {} | {} | {} | {} |\n",
            table_cell(&an.data.labels[s]),
            fmt_f64(an.data.points[an.data.series_index(s)[0]].scene.xi),
            cell(0),
            cell(1),
            cell(2),
            sig3(f.summary.stats.chi2),
            f.summary.stats.dof,
            match f.branch {
                JaegerBranch::Upper => "upper",
                JaegerBranch::Lower => "lower",
            },
            if f.has_minimum { "yes" } else { "no" },
            f.bistable_points,
            if paper.is_empty() {
                "—".to_string()
            } else {
                paper.join(", ")
            }
        ));
    }
    m.push('\n');
    if on_bound > 0 {
        m.push_str(&format!(
            "**a2 sits on its bound 0 in {on_bound} of {fitted} series.** There the friction \
             term does not decay with speed: the law reduces to tan δ = a1 + a3 u², one branch, \
             no minimum of the resistance and no bistable band, and a1 is the slope below which \
             the bead stops. The data of those series do not call for velocity weakening. \
             Their fits report no covariance (the fit reports below say why), hence no \
             standard errors: read their profile-likelihood intervals instead, in which a2's \
             lower end is the bound itself.\n\n"
        ));
    }
    for n in &an.jaeger.notes {
        m.push_str(&format!("- {}\n", one_line(n)));
    }
    if !an.jaeger.notes.is_empty() {
        m.push('\n');
    }
    m
}

/// Every fit's one-screen report ([`crate::fit::summary::FitResult`]'s `Display`).
fn fit_reports(an: &Analysis) -> String {
    let mut m = String::from("## Fit reports\n\n");
    for f in an.fit_results() {
        m.push_str(&format!("```text\n{f}```\n\n"));
    }
    m
}

/// The report's figures of fixed name, with their captions: what each shows and the paper's
/// figure it corresponds to (the figures' own titles carry neither reference).
const FIGURES: [(&str, &str); 8] = [
    (
        "velocity.svg",
        "v̄ against δ per series with every fitted model (the paper's Figs. 2–3, 8, 9)",
    ),
    (
        "residuals.svg",
        "normalised residuals against δ, one panel per fit",
    ),
    (
        "jan_linear.svg",
        "v̄²/cos δ against tan δ with Jan's lines (the paper's Fig. 8)",
    ),
    (
        "jaeger.svg",
        "Jaeger's u against tan δ with both branches and the bistable band of eq 90 (the paper's Figs. 9–10)",
    ),
    (
        "k_final_velocity.svg",
        "K per point (eq 69, stick/slip) against the final velocity (the paper's Figs. 5–6)",
    ),
    (
        "k_alpha.svg",
        "K per point (eq 69) against α with the fitted laws and cos 2α",
    ),
    (
        "energy.svg",
        "the energy partition of every point: collision translation, collision spin, friction",
    ),
    (
        "regime_map.svg",
        "regions A, B, C between each contact model's limits against α, with the points (the paper's Fig. 4)",
    ),
];

/// A Markdown link to figure `svg_name` in the format the report writes (the PNG when it
/// writes PNG only).
fn figure_link(ctx: &ReportContext, svg_name: &str) -> String {
    let names = ctx.figure_format.names(svg_name);
    let shown: Vec<String> = names.iter().map(|n| format!("[{n}]({n})")).collect();
    shown.join(" / ")
}

/// The banner of a report on the shipped synthetic data.
const SYNTHETIC_BANNER: &str = "> **These data are synthetic.** They are fitbead's shipped data \
     set (data/default.csv), simulated with the stick/slip model, the paper's law \
     K = cos 2α + ½ sin²α sin 2α, ρ = 0.4, f = 0.1 and 2 % noise: the report shows what the fits \
     recover, not a property of real beads.\n\n";

/// How velocities given in m/s were made dimensionless, per series (empty for dimensionless
/// input).
fn si_units(p: &ReportContext) -> String {
    let mut m = String::new();
    if let Some(si) = &p.si {
        m.push_str(
            "Velocities were given in m/s (`v_m_s`, `sigma_v_m_s`) and made dimensionless by \
             v = v_m_s / sqrt(g R (1 + ξ)), R the row beads' radius (`R_m`); every fit works on \
             the dimensionless v (unit sqrt(g (R + r))). Per series:\n\n\
             | series | ξ | R (m) | g (m/s²) | unit sqrt(g R (1 + ξ)) (m/s) |\n|---|---|---|---|---|\n",
        );
        let range = |a: (f64, f64)| {
            if a.0 == a.1 {
                fmt_sig(a.0, 6)
            } else {
                format!("{} … {}", fmt_sig(a.0, 6), fmt_sig(a.1, 6))
            }
        };
        for s in si {
            m.push_str(&format!(
                "| {} | {} | {} | {} | {} |\n",
                table_cell(&s.series),
                fmt_f64(s.xi),
                range(s.r_m),
                range(s.g),
                range(s.unit_m_s)
            ));
        }
        m.push('\n');
    }
    m
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:+.1} %", 100.0 * x)
    } else {
        "n/a".into()
    }
}

/// The report's summary for the terminal: every fitted parameter, the bulk friction table
/// (Jan's μ against eq 79) and the models ranked by AIC, then where the files are (`dir`).
pub fn terminal_summary(an: &Analysis, dir: &str) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "Fitted parameters (value ± standard error, {} % interval)\n",
        fmt_sig(100.0 * an.level, 6)
    ));
    for f in an.fit_results() {
        for r in &f.params {
            s.push_str(&format!(
                "{:<31} {:<5} {:<8} {:>18}  {}{}\n",
                f.stats.fit,
                crate::numfmt::clip(&f.stats.series, 120),
                param_name(r, &f.stats.series),
                value_pm(r),
                interval_cell(r),
                if r.at_bound { "  (on its bound)" } else { "" }
            ));
        }
    }
    s.push('\n');
    s.push_str("Bulk friction: Jan's mu (fitted) against eq 79 at the fitted K\n");
    s.push_str(&format!(
        "{:<8} {:>6} {:>22} {:<22} {:>22} {:>9}  overlap\n",
        "series", "xi", "mu_jan [interval]", "K source", "mu_eq79 [interval]", "rel diff"
    ));
    for r in an.mu_rows() {
        s.push_str(&format!(
            "{:<8} {:>6} {:>22} {:<22} {:>22} {:>9}  {}\n",
            crate::numfmt::clip(&r.series, 120),
            fmt_f64(r.xi),
            format!(
                "{} [{}, {}]",
                sig3(r.mu_jan.0),
                sig3(r.mu_jan.1),
                sig3(r.mu_jan.2)
            ),
            r.k_source,
            format!(
                "{} [{}, {}]",
                sig3(r.mu_eq79.0),
                sig3(r.mu_eq79.1),
                sig3(r.mu_eq79.2)
            ),
            pct(r.rel_diff()),
            if r.overlap() { "yes" } else { "no" }
        ));
    }
    s.push_str("\nModels ranked by AIC (all points)\n");
    for (i, c) in an.candidates().iter().enumerate() {
        s.push_str(&format!(
            "{:>2}. {:<34} k={:<3} chi2={:<10} dAIC={:<9} dBIC={}\n",
            i + 1,
            c.name,
            c.k,
            sig3(c.chi2),
            sig3(c.delta_aic),
            sig3(c.delta_bic)
        ));
    }
    s.push_str(&format!("\nTables, figures and report.md in {}\n", dir));
    s
}

/// report.md: the data, the bulk friction against eq 79, the energy budgets, the regime map and
/// the model ranking, in Markdown; `source` names the data, `method` the estimation method.
pub fn markdown(an: &Analysis, ctx: &ReportContext, method: &str) -> String {
    let source = ctx.source.as_str();
    let d = &an.data;
    let mut m = String::new();
    let p0 = &d.points[0].scene;
    m.push_str("# fitbead report\n\n");
    if ctx.shipped_synthetic {
        m.push_str(SYNTHETIC_BANNER);
    }
    m.push_str(&warnings_section(ctx));
    m.push_str(&format!(
        "Data: `{source}`, {} points in {} series; rho = {}, f = {} (per row where given); \
         method `{method}`; intervals at level {}; sigma {}.\n\n",
        d.points.len(),
        d.labels.len(),
        fmt_f64(p0.rho()),
        fmt_f64(p0.f()),
        fmt_f64(an.level),
        if d.sigma == crate::inverse::SigmaKind::Absolute {
            "given on every row"
        } else {
            "not given (unit weights, scale estimated)"
        }
    ));
    m.push_str(&si_units(ctx));
    m.push_str(&parameter_table(an));
    m.push_str(&slopes_section(an));
    m.push_str(&bulk_friction_section(an));
    m.push_str(&energy_section(an));
    m.push_str(&regimes_section(an, ctx));
    m.push_str(&jaeger_section(an, ctx));
    m.push_str(&model_choice_section(an));
    m.push_str(&figures_section(ctx));
    m.push_str(&fit_reports(an));
    m
}

/// report.md's slopes measured with error (only when some point carries σ_δ > 0): how the fits
/// use them, and every point whose adjusted slope moved by more than
/// [`MOVED`](crate::fit::slopes::MOVED) σ_δ under each least-squares fit.
fn slopes_section(an: &Analysis) -> String {
    use crate::fit::slopes::MOVED;
    let sd: Vec<f64> = an
        .data
        .points
        .iter()
        .map(|p| p.sigma_delta.to_degrees())
        .filter(|s| *s > 0.0)
        .collect();
    if sd.is_empty() {
        return String::new();
    }
    let (lo, hi) = sd
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let mut m = String::from("## Slopes measured with error\n\n");
    m.push_str(&format!(
        "{} of {} points carry a slope uncertainty σ_δ ({}). ",
        sd.len(),
        an.data.points.len(),
        if lo == hi {
            format!("{}°", fmt_sig(lo, 3))
        } else {
            format!("{}° … {}°", fmt_sig(lo, 3), fmt_sig(hi, 3))
        }
    ));
    if an.mcmc {
        m.push_str(
            "Each point's likelihood is integrated over its true slope (a Gaussian around the \
             measured one, zero where the bead has no steady state), so the posteriors above, \
             and μ of eq 79 at their K, carry the slope errors.\n\n",
        );
        return m;
    }
    m.push_str(&format!(
        "The least-squares fits adjust each slope too, by orthogonal distance regression \
         (weighted by σ_δ, never outside the steady range), so the intervals above, and μ of \
         eq 79 at their K, carry the slope errors. Adjusted slopes: columns `delta_fit_deg` and \
         `delta_residual` = (δ_fit − δ)/σ_δ of [residuals.csv](residuals.csv).\n\n\
         Points whose adjusted slope moved by more than {} σ_δ:\n\n",
        fmt_f64(MOVED)
    ));
    let mut rows = String::new();
    for f in an.fit_results() {
        for p in &f.points {
            let (Some(fit), Some(r)) = (p.delta_fit_deg, p.delta_residual) else {
                continue;
            };
            if r.abs() > MOVED {
                rows.push_str(&format!(
                    "| {} | {} | {} | {} | {} |\n",
                    table_cell(&f.stats.fit),
                    table_cell(&p.series),
                    fmt_sig(p.delta_deg, 6),
                    fmt_sig(fit, 6),
                    fmt_sig(r, 3)
                ));
            }
        }
    }
    if rows.is_empty() {
        m.push_str("none.\n\n");
    } else {
        m.push_str("| fit | series | δ measured (°) | δ adjusted (°) | (δ_fit − δ)/σ_δ |\n");
        m.push_str("|---|---|---|---|---|\n");
        m.push_str(&rows);
        m.push('\n');
    }
    m
}

/// report.md's bulk friction: Jan's μ against eq 79 per K source, and against eq 76.
fn bulk_friction_section(an: &Analysis) -> String {
    let mut m = String::new();
    let rows = an.mu_rows();
    m.push_str("## Bulk friction: Jan's μ against eq 79\n\n");
    m.push_str(
        "Per series, μ fitted by Jan's model (eq 74) against the closed form eq 79, \
         μ = (1 − K²) sin α / ((1 + K²) cos α + 2K), at the K fitted under each contact model \
         (one K per series, and the K(α) law c), with K's interval carried through eq 79. \
         Table: [bulk_friction.csv](bulk_friction.csv).\n\n",
    );
    let mut sources: Vec<String> = rows.iter().map(|r| r.k_source.clone()).collect();
    sources.dedup();
    sources.sort();
    sources.dedup();
    m.push_str("| K source | rel. difference (eq 79 − Jan)/Jan, min … max | intervals overlap |\n|---|---|---|\n");
    for src in &sources {
        let sel: Vec<_> = rows.iter().filter(|r| &r.k_source == src).collect();
        let (lo, hi) = sel
            .iter()
            .map(|r| r.rel_diff())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let ov = sel.iter().filter(|r| r.overlap()).count();
        m.push_str(&format!(
            "| {src} | {} … {} | {ov} of {} series |\n",
            pct(lo),
            pct(hi),
            sel.len()
        ));
    }
    let all: Vec<f64> = rows.iter().map(|r| r.rel_diff().abs()).collect();
    let within = all.iter().filter(|x| **x <= 0.15).count();
    m.push_str(&format!(
        "\nThe paper claims eq 79 matches the fitted μ \"to within 15 %\"; here {within} of {} \
         comparisons are within 15 %.",
        all.len()
    ));
    if let Some(r) = rows.first() {
        let _ = r;
        let e76: Vec<f64> = rows
            .iter()
            .map(|r| (r.mu_eq79.0 - r.mu_eq76) / r.mu_eq76)
            .collect();
        let (lo, hi) = e76
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        m.push_str(&format!(
            " Against the paper's own fit eq 76 (μ = 0.0025 e^(7.46 sin α)), eq 79 at these K \
             differs by {} … {} (column `rel_diff_eq76`).",
            pct(lo),
            pct(hi)
        ));
    }
    m.push_str("\n\n");
    m
}

/// report.md's energy budgets: collision loss and friction work per contact model.
fn energy_section(an: &Analysis) -> String {
    let mut m = String::new();
    m.push_str("## Energy budget\n\n");
    m.push_str(
        "Collision loss (translation and spin) and friction work as fractions of the potential \
         drop 2 sin α sin δ per bead, at the K of each contact model's law-c fit, and Jan's \
         eq 77 ratio λ v̄² / (2 sin α sin δ). Table: [energy.csv](energy.csv).\n\n\
         | model | collision / potential drop | translational collision loss / potential drop |\n|---|---|---|\n",
    );
    for (name, c0, c1, t0, t1) in an.energy_ranges() {
        let t = if t0.is_finite() {
            format!("{} … {}", sig3(t0), sig3(t1))
        } else {
            "—".into()
        };
        m.push_str(&format!("| {name} | {} … {} | {t} |\n", sig3(c0), sig3(c1)));
    }
    m.push_str(
        "\nThe paper: 1 for rolling (eq 71), 0.74–0.94 for the translational loss under \
         stick/slip on Ristow's data, 0.24–0.78 for Jan's eq 77.\n\n",
    );
    m
}

/// report.md's regimes: the regime map and the regime of every point per contact model.
fn regimes_section(an: &Analysis, ctx: &ReportContext) -> String {
    let mut m = String::new();
    m.push_str("## Regimes\n\n");
    m.push_str(&format!(
        "δ_m (eq 32) and δ_d (eq 31) against α for the reference and fitted laws, with the \
         critical ξ below which no steady motion exists: [regime_map.csv](regime_map.csv); \
         the regime each contact model (at its law-c fit) assigns to every point: \
         [points.csv](points.csv); figure {}.\n\n",
        figure_link(ctx, "regime_map.svg")
    ));
    let reg = an.point_regimes();
    for (c, r) in an.contact.iter().zip(&reg) {
        let count = |g: &str| r.iter().filter(|x| x.as_str() == g).count();
        m.push_str(&format!(
            "- {}: {} points in regime B, {} in A, {} in C, {} other.\n",
            c.name,
            count("B"),
            count("A"),
            count("C"),
            r.len() - count("A") - count("B") - count("C")
        ));
    }
    m.push('\n');
    m
}

/// report.md's model choice: the ranking by AIC, what the data support and the fits' notes.
fn model_choice_section(an: &Analysis) -> String {
    let mut m = String::new();
    m.push_str("## Model choice\n\n");
    m.push_str(
        "χ² at the least-squares optimum, AIC and BIC (with σ given: AIC = χ² + 2k, BIC = χ² + \
         k ln n), ranked by AIC among the models fitted to every point. Table: \
         [models.csv](models.csv); χ², AIC, BIC and the AIC rank of every model within each \
         series (parameters shared across series counted whole): \
         [models_by_series.csv](models_by_series.csv).\n\n| rank | model | k | n | χ² | ΔAIC | ΔBIC | ΔWAIC | note |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (i, c) in an.candidates().iter().enumerate() {
        m.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            i + 1,
            c.name,
            c.k,
            c.n,
            sig3(c.chi2),
            sig3(c.delta_aic),
            sig3(c.delta_bic),
            c.delta_waic.map_or("—".to_string(), sig3),
            table_cell(&c.note)
        ));
    }
    if an.mcmc {
        m.push_str(
            "\nWAIC (Watanabe 2010, deviance scale) from the posterior draws of every fit \
             (per-series models: summed over the series); for a law with nothing fitted it is \
             χ². Columns `waic`, `delta_waic` of models.csv; p_waic and its standard error per \
             fit in stats.csv.\n",
        );
    }
    m.push_str(&format!(
        "\nWhat the data support (extra parameters count as supported when both AIC and BIC \
         drop by more than {}):\n\n",
        fmt_f64(crate::report::analysis::SUPPORT_THRESHOLD)
    ));
    for s in an.support_statements() {
        m.push_str(&format!("- {}\n", one_line(&s)));
    }
    let notes: Vec<&String> = an
        .contact
        .iter()
        .flat_map(|c| c.notes.iter())
        .chain(an.jan.notes.iter())
        .chain(an.jaeger.notes.iter())
        .collect();
    if !notes.is_empty() {
        m.push_str("\nNotes from the fits:\n\n");
        for n in notes {
            m.push_str(&format!("- {}\n", one_line(n)));
        }
    }
    m
}

/// report.md's list of figures and tables.
fn figures_section(ctx: &ReportContext) -> String {
    let mut m = String::new();
    m.push_str("\n## Figures\n\n");
    for (name, what) in FIGURES {
        m.push_str(&format!("- {}: {what}\n", figure_link(ctx, name)));
    }
    if !ctx.corner_files.is_empty() {
        let links: Vec<String> = ctx
            .corner_files
            .iter()
            .map(|n| figure_link(ctx, n))
            .collect();
        m.push_str(&format!(
            "- posterior corner plots, one per fit (marginals with 16/50/84 % quantiles, pair \
             densities with 1σ and 2σ contours, the least-squares optimum marked): {}\n",
            links.join(", ")
        ));
    }
    m.push_str(
        "\nEvery fit's parameters and statistics: [params.csv](params.csv), \
         [stats.csv](stats.csv); every point against every fit: [residuals.csv](residuals.csv); \
         every pair of parameters: [correlations.csv](correlations.csv).\n\n",
    );
    m
}
