//! `fitbead klaw`: a law K(α) fitted to all series at once (law c, one K per series) under a
//! contact model or the model auto chooses, and the parameter-free impact law scored beside
//! it.

use super::fit_run::FitRun;
use super::{law_error, setting_error, RunError};
use crate::fit::data::Dataset;
use crate::fit::k::auto::{self as kauto, KChoice};
use crate::fit::k::unsteady_points;
use crate::fit::klaw::{fit_law, fit_law_in, KLaw, KLawContext, KLawError};
use crate::inverse::posterior::Method;
use crate::io::fmt_f64;
use crate::io::measurements::{locate_point, MeasurementFile};
use crate::models::auto::Auto;
use crate::models::{Model, ModelKind};
use crate::progress::Progress;
use crate::report::bands::Curve;
use rayon::prelude::*;

/// The settings of [`super::FitCommand::Klaw`].
pub(crate) struct KlawSettings {
    pub model: ModelKind,
    pub law: KLaw,
    pub tol: f64,
    pub skip_unsteady: bool,
}

/// The command-line name of a model kind (`stickslip`, `stick-approx`, …).
fn model_name(kind: ModelKind) -> &'static str {
    match kind {
        ModelKind::StickSlip => "stickslip",
        k => k.prose_name(),
    }
}

/// The model auto chooses for every point of `ds`: the most general model any point needs at
/// its stick K (eq 69), with the note that says so.
fn auto_model(au: &Auto, ds: &Dataset) -> (Model, String) {
    let choices: Vec<KChoice> = ds
        .points
        .par_iter()
        .map(|p| kauto::choose(au, &p.scene, p.v))
        .collect();
    let (c, n) = kauto::most_general(&choices);
    let model = choices
        .iter()
        .find(|k| k.choice == c)
        .map(|k| k.model)
        .unwrap_or(Model::Stick);
    let note = format!(
        "auto (T = {}): model_used {} for all points, the most general any point needs \
         (per point at its stick K: stick {}, stickslip {}, contact {})",
        fmt_f64(au.tol),
        c.name(),
        n[0],
        n[1],
        n[2]
    );
    (model, note)
}

/// Fits the law of `s` to the data of `file` ([`super::FitCommand::Klaw`]).
pub(crate) fn run(
    s: &KlawSettings,
    file: &MeasurementFile,
    method: &Method,
    level: f64,
    progress: Option<Progress>,
    note: &mut dyn FnMut(&str),
) -> Result<FitRun, RunError> {
    let (t, ds) = (&file.table, &file.dataset);
    let mut notes: Vec<String> = Vec::new();
    let model = match s.model {
        ModelKind::Auto => {
            let (m, auto_note) = auto_model(&Auto { tol: s.tol }, ds);
            note(&auto_note);
            notes.push(auto_note);
            m
        }
        kind => kind.contact_model().ok_or_else(|| {
            setting_error(
                "--model",
                model_name(kind),
                "expected one of stick, stick-approx, slip, slip-approx, stickslip, contact, \
                 auto",
            )
        })?,
    };
    let law = s.law;
    if law == KLaw::Impact && matches!(method, Method::Mcmc(_)) {
        return Err(setting_error(
            "--method",
            "mcmc",
            "the impact law has no parameter to sample; use --law c or free-per-series",
        ));
    }
    // Points that no K makes steady: an error naming them, or left out.
    let unsteady = unsteady_points(&[model], ds, method.stop().map(|s| &**s));
    if method.stopped() {
        return Err(RunError::Interrupted);
    }
    let locate = |d: &Dataset, i: usize| locate_point(t, d, i);
    let describe = |i: usize, why: &str| format!("{}: {why}", locate(ds, i));
    let (fitted, orig) = if unsteady.is_empty() {
        (ds.clone(), (0..ds.points.len()).collect::<Vec<_>>())
    } else if s.skip_unsteady {
        for (i, why) in &unsteady {
            note(&format!("left out: {}", describe(*i, why)));
        }
        notes.push(format!(
            "{} point(s) with no steady state for any K left out (--skip-unsteady)",
            unsteady.len()
        ));
        let out: std::collections::HashSet<usize> = unsteady.iter().map(|u| u.0).collect();
        ds.clone().filter(|i| !out.contains(&i))
    } else {
        let (i, why) = &unsteady[0];
        return Err(RunError::Failed(format!(
            "{} (and {} more such point(s)); no K of the {} model makes this point steady: \
             use another model, or --skip-unsteady to leave such points out",
            describe(*i, why),
            unsteady.len() - 1,
            model_name(s.model)
        )));
    };
    if fitted.points.is_empty() {
        return Err(RunError::Failed(
            "klaw: no point is left to fit".to_string(),
        ));
    }
    let fail = |e: KLawError| {
        if let KLawError::Setting {
            flag,
            value,
            reason,
        } = e
        {
            return setting_error(&flag, &value, reason);
        }
        if method.stopped() {
            RunError::Interrupted
        } else {
            RunError::Failed(format!("klaw: {}", law_error(&e, &|i| locate(ds, orig[i]))))
        }
    };
    let context = KLawContext {
        progress,
        ..KLawContext::default()
    };
    let main = fit_law_in(model, &fitted, law, level, method, context).map_err(fail)?;
    let mut fits = vec![main.summary];
    if law != KLaw::Impact {
        let imp = fit_law(model, &fitted, KLaw::Impact, level, false).map_err(fail)?;
        fits.push(imp.summary);
    }
    if !notes.is_empty() {
        let joined = notes.join("; ");
        for st in fits.iter_mut().map(|f| &mut f.stats) {
            st.note = crate::fit::summary::join(&st.note, &joined);
        }
    }
    let main_curve = match law {
        KLaw::C => Curve::LawC(model),
        KLaw::FreePerSeries => Curve::FreeK(model),
        KLaw::Impact => Curve::Impact(model),
    };
    let curves: Vec<Curve> = std::iter::once(main_curve)
        .chain((law != KLaw::Impact).then_some(Curve::Impact(model)))
        .collect();
    Ok(FitRun {
        fits,
        title: format!(
            "K(α) laws under the {} model, fitted on v\u{304}",
            s.model.prose_name()
        ),
        data: fitted,
        curves,
    })
}
