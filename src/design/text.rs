//! What `fitbead design` prints and writes of a design: its CSV and its summary.

use super::{Criterion, DesignResult, DesignSettings};
use crate::numfmt::{fmt_f64, fmt_sig};

impl DesignResult {
    /// The design as `fitbead design` writes it: CSV `series,xi,delta_deg,replicates`.
    pub fn csv(&self) -> csv::Result<Vec<u8>> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(["series", "xi", "delta_deg", "replicates"])?;
        for row in &self.rows {
            w.write_record([
                row.series.clone(),
                fmt_f64(row.xi),
                fmt_f64(row.delta_deg),
                row.replicates.to_string(),
            ])?;
        }
        w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
    }

    /// The summary `fitbead design` prints: the design of `s`, the predicted standard errors
    /// and the efficiency of evenly spaced slopes.
    pub fn summary(&self, s: &DesignSettings) -> String {
        summary(s, self)
    }
}

/// The summary: the design, the predicted standard errors and the efficiency.
fn summary(s: &DesignSettings, r: &DesignResult) -> String {
    use std::fmt::Write as _;
    let mut o = String::new();
    let crit = match s.criterion {
        Criterion::D => "D-optimal".to_string(),
        Criterion::C => format!("c-optimal for {}", r.target.as_deref().unwrap_or("")),
        Criterion::T => "T-optimal (model discrimination)".to_string(),
    };
    let budget = match s.total {
        None => format!("{} points per series", s.points),
        Some(n) => format!("{n} points in all (shared out by the design)"),
    };
    let slope_error = if s.sigma_delta > 0.0 {
        format!(
            ", slope error sigma_delta {} deg (effective variance)",
            fmt_sig(s.sigma_delta, 3)
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        o,
        "design: {crit}, {budget}, noise {}{}{slope_error}",
        fmt_sig(s.noise, 3),
        if s.noise_absolute {
            " (absolute)"
        } else {
            " (relative)"
        }
    );
    if let Some((n, redrawn)) = r.bayes {
        let priors: Vec<String> = s.priors.iter().map(|(n, p)| format!("{n}={p}")).collect();
        let _ = writeln!(
            o,
            "Bayesian design: the criterion averaged over {n} prior draws (seed {}; {}); {redrawn} \
             draws redrawn (a series without a steady slope in its range); standard errors are \
             root mean variances over the draws",
            s.seed,
            priors.join(", ")
        );
    }
    for (k, xi) in s.series.iter().enumerate() {
        let (lo, hi) = r.ranges[k];
        let slopes: Vec<String> = r
            .rows
            .iter()
            .filter(|row| row.xi == *xi)
            .map(|row| format!("{} deg x{}", fmt_f64(row.delta_deg), row.replicates))
            .collect();
        let slopes = if slopes.is_empty() {
            vec!["no points".to_string()]
        } else {
            slopes
        };
        let _ = writeln!(
            o,
            "  xi {}: range {}-{} deg: {}",
            fmt_f64(*xi),
            fmt_sig(lo, 5),
            fmt_sig(hi, 5),
            slopes.join(", ")
        );
    }
    steady_lines(&mut o, r);
    let _ = writeln!(
        o,
        "predicted standard errors (design / evenly spaced slopes):"
    );
    let se = |x: Option<f64>| x.map_or("not determined".to_string(), |v| fmt_sig(v, 3));
    for e in &r.errors {
        let _ = writeln!(
            o,
            "  {} = {}: {} / {}",
            e.name,
            fmt_sig(e.guess, 6),
            se(e.design),
            se(e.even)
        );
    }
    let eff = fmt_sig(r.efficiency, 3);
    match s.criterion {
        Criterion::D => {
            let _ = writeln!(o, "D-efficiency of evenly spaced slopes: {eff}");
        }
        Criterion::C => {
            let _ = writeln!(
                o,
                "efficiency of evenly spaced slopes (variance ratio): {eff}; SE ratio even/design: {}",
                fmt_sig(r.efficiency.recip().sqrt(), 3)
            );
        }
        Criterion::T => {
            if let (Some((td, te)), Some((nd, ne))) = (r.discrimination, r.points_needed) {
                let _ = writeln!(
                    o,
                    "discrimination T = min chi2 of the rival fitted to the model: design {} / \
                     evenly spaced {} (efficiency {eff})",
                    fmt_sig(td, 4),
                    fmt_sig(te, 4)
                );
                let n = |x: f64| {
                    if x.is_finite() {
                        format!("{x}")
                    } else {
                        "never".to_string()
                    }
                };
                let _ = writeln!(
                    o,
                    "points in all for power 0.8 at significance 0.05: design {} / evenly \
                     spaced {}",
                    n(nd),
                    n(ne)
                );
            }
        }
    }
    let _ = writeln!(o, "equivalence gap: {}", fmt_sig(r.gap, 2));
    o
}

/// Per chosen slope, the range of each parameter over which it stays steady, the others at
/// the guess.
fn steady_lines(o: &mut String, r: &DesignResult) {
    use std::fmt::Write as _;
    if r.steady.iter().all(Vec::is_empty) {
        return;
    }
    let _ = writeln!(
        o,
        "per chosen slope, the range of each parameter (the others at the guess) over which it \
         stays steady (regime B):"
    );
    for (row, ranges) in r.rows.iter().zip(&r.steady) {
        let ranges: Vec<String> = ranges
            .iter()
            .map(|(name, lo, hi)| {
                let g = |x: f64| fmt_sig(x, 4);
                match (lo, hi) {
                    (Some(a), Some(b)) => format!("{name} {} to {}", g(*a), g(*b)),
                    (Some(a), None) => format!("{name} >= {}", g(*a)),
                    (None, Some(b)) => format!("{name} <= {}", g(*b)),
                    (None, None) => format!("{name} any"),
                }
            })
            .collect();
        let _ = writeln!(
            o,
            "  xi {} at {} deg: {}",
            fmt_f64(row.xi),
            fmt_f64(row.delta_deg),
            ranges.join("; ")
        );
    }
}
