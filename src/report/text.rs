//! The report's text: report.md and the summary printed at the end of `fitbead report`.

use super::analysis::{sig3, Analysis};
use crate::numfmt::fmt_f64;

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:+.1} %", 100.0 * x)
    } else {
        "n/a".into()
    }
}

/// The report's summary for the terminal: the bulk friction table (Jan's μ against eq 79)
/// and the models ranked by AIC, then where the files are (`dir`).
pub fn terminal_summary(an: &Analysis, dir: &str) -> String {
    let mut s = String::new();
    s.push_str("Bulk friction: Jan's mu (fitted) against eq 79 at the fitted K\n");
    s.push_str(&format!(
        "{:<8} {:>6} {:>22} {:<22} {:>22} {:>9}  overlap\n",
        "series", "xi", "mu_jan [interval]", "K source", "mu_eq79 [interval]", "rel diff"
    ));
    for r in an.mu_rows() {
        s.push_str(&format!(
            "{:<8} {:>6} {:>22} {:<22} {:>22} {:>9}  {}\n",
            r.series,
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
pub fn markdown(an: &Analysis, source: &str, method: &str) -> String {
    let d = &an.data;
    let mut m = String::new();
    let p0 = &d.points[0].scene;
    m.push_str("# fitbead report\n\n");
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
    // Bulk friction.
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
    // Energy.
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
    // Regimes.
    m.push_str("## Regimes\n\n");
    m.push_str(
        "δ_m (eq 32) and δ_d (eq 31) against α for the reference and fitted laws, with the \
         critical ξ below which no steady motion exists: [regime_map.csv](regime_map.csv); \
         the regime each contact model (at its law-c fit) assigns to every point: \
         [points.csv](points.csv); figure [regime_map.svg](regime_map.svg).\n\n",
    );
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
    // Models.
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
            c.note
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
        m.push_str(&format!("- {s}\n"));
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
            m.push_str(&format!("- {n}\n"));
        }
    }
    m.push_str(
        "\n## Figures\n\n\
         - [velocity.svg](velocity.svg): v̄ against δ per series with every fitted model \
         (paper Figs. 2–3, 8, 9)\n\
         - [jan_linear.svg](jan_linear.svg): v̄²/cos δ against tan δ with Jan's lines (Fig. 8)\n\
         - [k_final_velocity.svg](k_final_velocity.svg): K per point (eq 69, stick/slip) \
         against the final velocity (Figs. 5–6)\n\
         - [regime_map.svg](regime_map.svg): δ_m and δ_d against α with the points (Fig. 4)\n",
    );
    if an.mcmc {
        m.push_str("- [corner.svg](corner.svg): posterior corner plots\n");
    }
    m.push_str(
        "\nEvery fit's parameters and statistics: [params.csv](params.csv), \
         [stats.csv](stats.csv).\n",
    );
    m
}
