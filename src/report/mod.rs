//! Reports: the comparisons of `fitbead report` (`analysis`) and their posterior bands
//! (`bands`), the list of its fits (`fits`), its figures (`plots`, drawn with the engine
//! in [`figures`]), its text (`text`) and the work-precision engine of `fitbead bench`
//! ([`workprecision`]).

pub(crate) mod analysis;
pub(crate) mod bands;
pub mod figures;
pub(crate) mod fits;
pub(crate) mod plots;
pub(crate) mod text;
pub mod workprecision;

/// Longest file-name part made of a series label ([`file_stems`]), in bytes.
pub(crate) const STEM_BYTES: usize = 64;

/// File-name parts for series `labels` (in order): a label is data, never a path, so every
/// character outside `[A-Za-z0-9._-]` becomes `_` and the result is cut at `STEM_BYTES`; a
/// label that had to change and now shares its name with another label gets `-` and eight
/// hexadecimal digits of a hash of the label appended (stable: the same label gets the same
/// name whatever the other labels). A label already safe keeps its name.
pub(crate) fn file_stems(labels: &[String]) -> Vec<String> {
    let safe = |l: &str| -> String {
        let mut s: String = l
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        s.truncate(STEM_BYTES);
        if s.is_empty() || s.chars().all(|c| c == '.') {
            s = s.replace('.', "_");
            s.push('_');
        }
        s
    };
    let stems: Vec<String> = labels.iter().map(|l| safe(l)).collect();
    let mut out = stems.clone();
    for (i, l) in labels.iter().enumerate() {
        let shared = stems.iter().filter(|s| **s == stems[i]).count() > 1;
        if shared && *l != stems[i] {
            // FNV-1a, 32 bits.
            let h = l.bytes().fold(0x811c_9dc5_u32, |h, b| {
                (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
            });
            out[i] = format!("{}-{h:08x}", stems[i]);
        }
    }
    // Two changed labels of one hash (or one changed label equal to another's hashed name)
    // are told apart by their position.
    for i in 0..out.len() {
        if out[..i].contains(&out[i]) {
            out[i] = format!("{}-{}", out[i], i + 1);
        }
    }
    out
}

/// Every file of fixed name `fitbead report` may write in its directory (with `--format png`
/// or `both`, each figure `NAME.svg` also, or instead, as `NAME.png`; with `--method mcmc`, one
/// corner plot per posterior, `corner_<fit>_<series>.svg` with the fit named as in
/// `params.csv` and the series label made a safe file name by [`file_stems`]).
pub(crate) const REPORT_FILES: [&str; 19] = [
    "bulk_friction.csv",
    "energy.csv",
    "regime_map.csv",
    "points.csv",
    "models.csv",
    "models_by_series.csv",
    "params.csv",
    "stats.csv",
    "residuals.csv",
    "correlations.csv",
    "velocity.svg",
    "jan_linear.svg",
    "k_final_velocity.svg",
    "regime_map.svg",
    "jaeger.svg",
    "k_alpha.svg",
    "energy.svg",
    "residuals.svg",
    "report.md",
];

#[cfg(test)]
mod tests {
    use super::analysis::{EnergyRecord, MuRecord, RegimeMapRecord};
    use crate::record::columns;

    /// The columns of the report's record tables, a contract users' scripts read (as
    /// docs/GUIDE.md lists bulk_friction.csv's and the shipped fits/default/ has all three),
    /// against the columns generated from the records.
    #[test]
    fn report_table_columns_are_the_documented_contract() {
        assert_eq!(
            columns::<MuRecord>(),
            [
                "series",
                "xi",
                "mu_jan",
                "mu_jan_lo",
                "mu_jan_hi",
                "K_source",
                "K",
                "mu_eq79",
                "mu_eq79_lo",
                "mu_eq79_hi",
                "rel_diff",
                "intervals_overlap",
                "alpha_deg",
                "K_lo",
                "K_hi",
                "mu_eq76",
                "rel_diff_eq76",
                "level"
            ]
        );
        assert_eq!(
            columns::<EnergyRecord>(),
            [
                "series",
                "xi",
                "delta_deg",
                "v",
                "model",
                "K",
                "potential_drop",
                "collision_translation",
                "collision_spin",
                "collision",
                "friction",
                "closure",
                "status"
            ]
        );
        assert_eq!(
            columns::<RegimeMapRecord>(),
            [
                "law",
                "xi",
                "alpha_deg",
                "K",
                "delta_m_deg",
                "delta_d_deg",
                "critical_xi"
            ]
        );
    }

    #[test]
    fn series_labels_become_safe_unique_file_names() {
        let labels: Vec<String> = ["../../x/evil", "a|b\nc", "0.8", "a_b_c", "a/b/c", "", ".."]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let stems = super::file_stems(&labels);
        assert_eq!(stems[0], ".._.._x_evil");
        assert_eq!(stems[2], "0.8");
        assert_eq!(stems[3], "a_b_c", "a safe label keeps its name");
        for (l, st) in labels.iter().zip(&stems) {
            assert!(!st.is_empty() && st != "." && st != "..", "{l:?} -> {st:?}");
            assert!(
                st.chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-')),
                "{l:?} -> {st:?}"
            );
        }
        let mut unique = stems.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), stems.len(), "{stems:?}");
        // Stable: a label's name does not depend on the other labels.
        let again = super::file_stems(&[labels[4].clone(), labels[3].clone()]);
        assert_eq!(again[0], stems[4]);
    }
}
