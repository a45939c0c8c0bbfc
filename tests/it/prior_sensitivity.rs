//! The power-scaling prior-sensitivity check of every posterior (the statistic itself is
//! tested against a conjugate normal's closed form in `inverse::mcmc::sensitivity`): a flat
//! prior gives exactly zero prior sensitivity, a tight prior away from the data is flagged,
//! and on the shipped data Jaeger's a2 at ξ = 0.8 (a half-normal prior over a direction the
//! nine points hardly constrain) is flagged in the fit report, the parameter record and its note.

use fitbead::fit::builder::{JaegerFitter, KLawFitter};
use fitbead::fit::klaw::KLaw;
use fitbead::fit::posterior::{McmcSettings, Prior};
use fitbead::io::records::ParamRecord;
use fitbead::{Dataset, Model};

fn settings(seed: u64, priors: &[(&str, &str)]) -> McmcSettings {
    let mut s = McmcSettings::seeded(seed);
    s.options.min_ess = 400.0;
    s.priors = priors
        .iter()
        .map(|(n, p)| (n.to_string(), p.parse::<Prior>().unwrap()))
        .collect();
    s
}

#[test]
fn a_flat_prior_has_no_prior_sensitivity_and_a_tight_distant_prior_is_flagged() {
    let data = Dataset::default_data();
    let flat = KLawFitter::new(Model::Stick, KLaw::C)
        .mcmc(settings(3, &[]))
        .fit(&data)
        .unwrap();
    let c = &flat.params[0];
    let s = c.sensitivity.expect("a posterior run has a sensitivity");
    assert_eq!(s.prior, 0.0, "flat prior: power-scaling it changes nothing");
    assert!(s.likelihood > 0.05, "the data decide c: {s:?}");
    assert_eq!(s.diagnosis(), "");
    assert!(!c.note.contains("prior-"), "{}", c.note);
    // The least-squares c is 0.683 ± 0.004; a prior N(0.60, 0.01) sits 8 of its standard
    // errors away and pulls the posterior.
    let tight = KLawFitter::new(Model::Stick, KLaw::C)
        .mcmc(settings(3, &[("c", "normal(0.60,0.01)")]))
        .fit(&data)
        .unwrap();
    let t = tight.params[0].sensitivity.unwrap();
    assert!(t.prior >= 0.05, "{t:?}");
    assert_eq!(t.diagnosis(), "prior-data conflict");
    let rec = ParamRecord::from(&tight.params[0]);
    assert_eq!(rec.prior_diagnosis, "prior-data conflict");
    assert_eq!(rec.prior_sensitivity, Some(t.prior));
    assert!(
        tight.to_string().contains("c: prior-data conflict"),
        "{tight}"
    );
}

#[test]
fn jaeger_a2_at_xi_0_8_is_flagged_and_its_notes_are_the_posteriors() {
    let data = Dataset::default_data();
    let set = JaegerFitter::new()
        .mcmc(settings(1, &[]))
        .fit(&data)
        .unwrap();
    let f = set
        .fits
        .iter()
        .find(|f| f.stats.series == "0.8")
        .expect("a Jaeger fit at 0.8");
    let a2 = f.params.iter().find(|p| p.parameter == "a2").unwrap();
    let s = a2.sensitivity.unwrap();
    assert!(s.prior >= 0.05, "{s:?}");
    assert_ne!(s.diagnosis(), "");
    assert!(a2.note.contains(s.diagnosis()), "{}", a2.note);
    // The least-squares a2 at 0.8 is on its bound 0; the posterior median is not, and the
    // row no longer says so.
    assert_eq!(a2.lsq_value, Some(0.0));
    assert!(a2.value > 0.0 && !a2.at_bound);
    assert!(!a2.note.contains("on a bound"), "{}", a2.note);
    assert!(f.to_string().contains(&format!("a2: {}", s.diagnosis())));
    // On the better-determined series the prior does not matter.
    for f in set
        .fits
        .iter()
        .filter(|f| f.stats.series == "1.6" || f.stats.series == "2")
    {
        for p in &f.params {
            assert!(
                p.sensitivity.unwrap().prior < 0.05,
                "{} {}",
                f.stats.series,
                p.parameter
            );
        }
    }
}
