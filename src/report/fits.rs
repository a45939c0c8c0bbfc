//! Every fit the report makes, named as in params.csv and stats.csv: the list that residuals.csv,
//! correlations.csv, the parameter table and the fit reports of report.md are made from.

use super::analysis::Analysis;
use super::bands::PosteriorBands;
use crate::fit::summary::FitResult;

/// A copy of `f` without its draws (the report's tables need the summaries only), named `name`
/// on the statistics and on every parameter row.
fn named(f: &FitResult, name: &str) -> FitResult {
    let mut stats = f.stats.clone();
    stats.fit = name.to_string();
    FitResult {
        params: f
            .params
            .iter()
            .map(|r| {
                let mut r = r.clone();
                r.fit = name.to_string();
                r
            })
            .collect(),
        stats,
        draws: None,
        correlation: f.correlation.clone(),
        residuals: f.residuals.clone(),
        points: f.points.clone(),
    }
}

impl Analysis {
    /// Every fit of the report in the order of params.csv, with its name there: per contact
    /// model its K(α) law c and its one-K-per-series fit (`rolling-klaw-c`, …), then Jan's
    /// per-series and global fits, then Jaeger's per-series fits (a per-series model names
    /// each of its fits alike).
    pub fn each_fit(&self) -> Vec<(String, &FitResult)> {
        let mut v = Vec::new();
        for c in &self.contact {
            for f in c.law_c.iter().chain(c.free.iter()) {
                v.push((format!("{}-{}", c.name, f.summary.stats.fit), &f.summary));
            }
        }
        let jan = self
            .jan
            .series
            .iter()
            .flatten()
            .chain(self.jan.global.iter());
        v.extend(jan.map(|f| (f.stats.fit.clone(), f)));
        let jaeger = self.jaeger.series.iter().flatten().map(|f| &f.summary);
        v.extend(jaeger.map(|f| (f.stats.fit.clone(), f)));
        v
    }

    /// [`Analysis::fit_results`] with, for a posterior run, every point's fitted v̄ replaced by
    /// its posterior median (`medians`, from
    /// [`posterior_bands_until`](super::bands::posterior_bands_until)), and its residuals recomputed from
    /// it: v − v̄, divided by σ (without σ, by the scatter sqrt(χ²/dof) of the fit).
    pub fn fit_results_at(&self, medians: Option<&PosteriorBands>) -> Vec<FitResult> {
        let mut fits = self.fit_results();
        let Some(b) = medians else { return fits };
        for f in fits.iter_mut() {
            let scatter = f.stats.reduced_chi2.sqrt();
            for p in f.points.iter_mut() {
                let m = b.points.iter().find(|m| {
                    m.fit == f.stats.fit && m.series == p.series && m.delta_deg == p.delta_deg
                });
                if let Some(m) = m {
                    p.v_fit = m.v_median;
                    p.residual = p.v - m.v_median;
                    p.normalised_residual = p.residual / p.sigma_v.unwrap_or(scatter);
                }
            }
        }
        fits
    }

    /// Every fit of the report, in the order of params.csv: per contact model its K(α) law c
    /// and its one-K-per-series fit (named `rolling-klaw-c`, `stickslip-klaw-free-per-series`,
    /// …), then Jan's per-series and global fits, then Jaeger's per-series fits. The copies
    /// carry no draws.
    pub fn fit_results(&self) -> Vec<FitResult> {
        self.each_fit()
            .into_iter()
            .map(|(name, f)| named(f, &name))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use crate::fit::data::Dataset;
    use crate::report::analysis::analyse;

    /// The names and parameters of the fits list agree with params.csv's rows, one for one.
    #[test]
    fn fit_results_name_the_rows_of_params_csv() {
        let data = Dataset::default_data();
        let an = analyse(&data, 0.95, &crate::fit::posterior::Method::lsq(false));
        let from_fits: Vec<(String, String, String)> = an
            .fit_results()
            .iter()
            .flat_map(|f| {
                f.params
                    .iter()
                    .map(|r| (r.fit.clone(), r.series.clone(), r.parameter.clone()))
            })
            .collect();
        let from_params: Vec<(String, String, String)> = an
            .params()
            .iter()
            .map(|r| (r.fit.clone(), r.series.clone(), r.parameter.clone()))
            .collect();
        assert_eq!(from_fits, from_params);
        assert!(an
            .fit_results()
            .iter()
            .all(|f| f.params.iter().all(|r| r.fit == f.stats.fit)));
    }
}
