//! `fitbead klaw`: a law K(α) fitted to all series at once (law c, one K per series), and the
//! parameter-free impact law scored beside it.

use super::fitargs::{FitArgs, LsqPlot};
use super::k::{model_of, prose_model_name};
use super::values::{self, KModel};
use super::CliError;
use crate::fit::k::auto::{self as kauto, KChoice};
use crate::fit::k::unsteady_points;
use crate::fit::klaw::{fit_law, fit_law_in, KLaw, KLawContext, KLawError};
use crate::fit::posterior::Method;
use crate::io::fmt_f64;
use crate::io::measurements::locate_point;
use crate::models::Model;
use crate::pipeline::law_error;
use crate::report::bands::Curve;
use rayon::prelude::*;

/// Arguments of `fitbead klaw`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Contact model: stick, stick-approx, slip, slip-approx, stickslip, contact, or auto (the
    /// most general model any point needs at its stick K; see --tol).
    #[arg(long, value_parser = values::choice::<KModel>())]
    pub model: KModel,
    /// The law: c (K = cos 2α + c sin²α sin 2α), impact (K = (cos 2α + ρ)/(1 + ρ), scored
    /// only) or free-per-series (one K per series). The impact law is always scored as well.
    #[arg(long, default_value = "c", value_parser = values::choice::<KLaw>())]
    pub law: KLaw,
    /// Leave out (and list on stderr) the points that no K can make steady under the model,
    /// instead of stopping with an error.
    #[arg(long)]
    pub skip_unsteady: bool,
    /// Input, output and interval flags.
    #[command(flatten)]
    pub io: FitArgs,
    /// With --model auto: the target relative tolerance T on v.
    #[arg(long, default_value = "1e-10", value_parser = values::tolerance)]
    pub tol: f64,
}

/// Runs `fitbead klaw`.
pub fn run(a: Args) -> Result<(), CliError> {
    // The model is chosen once the data are read
    let (mut model, auto) = model_of(a.model, a.tol);
    let law = a.law;
    // The handler goes in before the data are read: a signal while a large file is read and
    // checked raises the flag (polled from the first bracket on) instead of killing the
    // process with no exit code.
    super::stop_flag();
    let (t, _rows, ds) = a.io.read()?;
    let names: &[&str] = match law {
        KLaw::C => &["c"],
        KLaw::FreePerSeries => &["K"],
        KLaw::Impact => &[],
    };
    let choice = a.io.method(names)?;
    // Per point at its stick K (eq 69), then the most
    // general model any point needs, for all points.
    let mut auto_note = String::new();
    if let Some(au) = &auto {
        let choices: Vec<KChoice> = ds
            .points
            .par_iter()
            .map(|p| kauto::choose(au, &p.scene, p.v))
            .collect();
        let (c, n) = kauto::most_general(&choices);
        model = choices
            .iter()
            .find(|k| k.choice == c)
            .map(|k| k.model)
            .unwrap_or(Model::Stick);
        auto_note = format!(
            "auto (T = {}): model_used {} for all points, the most general any point needs \
             (per point at its stick K: stick {}, stickslip {}, contact {})",
            fmt_f64(au.tol),
            c.name(),
            n[0],
            n[1],
            n[2]
        );
        eprintln!("fitbead klaw: {auto_note}");
    }
    if law == KLaw::Impact && matches!(choice.method, Method::Mcmc(_)) {
        return Err(super::flag_error(
            "--method",
            "mcmc",
            "the impact law has no parameter to sample; use --law c or free-per-series",
        ));
    }
    // Points that no K makes steady: an error naming them, or left out with --skip-unsteady.
    let unsteady = unsteady_points(&[model], &ds, Some(&super::stop_flag()));
    if super::stop_requested() {
        return Err(CliError::Interrupted);
    }
    let all = ds.clone();
    let locate = |d: &crate::fit::data::Dataset, i: usize| locate_point(&t, d, i);
    let describe = |i: usize, why: &str| format!("{}: {why}", locate(&all, i));
    let mut skipped_note = String::new();
    let (ds, orig) = if unsteady.is_empty() {
        let n = ds.points.len();
        (ds, (0..n).collect::<Vec<_>>())
    } else if a.skip_unsteady {
        for (i, why) in &unsteady {
            eprintln!("fitbead klaw: left out: {}", describe(*i, why));
        }
        skipped_note = format!(
            "{} point(s) with no steady state for any K left out (--skip-unsteady)",
            unsteady.len()
        );
        let out: std::collections::HashSet<usize> = unsteady.iter().map(|u| u.0).collect();
        ds.filter(|i| !out.contains(&i))
    } else {
        let (i, why) = &unsteady[0];
        return Err(CliError::Other(format!(
            "{} (and {} more such point(s)); no K of the {} model makes this point steady: \
             use another model, or --skip-unsteady to leave such points out",
            describe(*i, why),
            unsteady.len() - 1,
            a.model.name()
        )));
    };
    if ds.points.is_empty() {
        return Err(CliError::Other("klaw: no point is left to fit".to_string()));
    }
    let fail = |e: KLawError| {
        CliError::Other(format!(
            "klaw: {}",
            law_error(&e, &|i| locate(&all, orig[i]))
        ))
    };
    let interrupted = |e: CliError| {
        if super::stop_requested() {
            CliError::Interrupted
        } else {
            e
        }
    };
    // A least-squares fit shows its model evaluations on a terminal once it has run for a
    // couple of seconds; a posterior run shows the sampler's steps instead.
    let context = KLawContext {
        progress: match choice.method {
            Method::Lsq { .. } => super::delayed_progress_bar("model evaluations"),
            Method::Mcmc(_) => None,
        },
        ..KLawContext::default()
    };
    let main = fit_law_in(model, &ds, law, a.io.level.level(), &choice.method, context)
        .map_err(|e| interrupted(fail(e)))?;
    let mut fits = vec![main.summary];
    if law != KLaw::Impact {
        let imp = fit_law(model, &ds, KLaw::Impact, a.io.level.level(), false)
            .map_err(|e| interrupted(fail(e)))?;
        fits.push(imp.summary);
    }
    if !auto_note.is_empty() {
        skipped_note = if skipped_note.is_empty() {
            auto_note
        } else {
            format!("{auto_note}; {skipped_note}")
        };
    }
    if !skipped_note.is_empty() {
        for s in fits.iter_mut().map(|f| &mut f.stats) {
            s.note = if s.note.is_empty() {
                skipped_note.clone()
            } else {
                format!("{}; {skipped_note}", s.note)
            };
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
    let title = format!(
        "K(α) laws under the {} model, fitted on v\u{304}",
        prose_model_name(a.model)
    );
    let plot = LsqPlot {
        title: &title,
        data: &ds,
        curves: &curves,
    };
    a.io.write(&fits.iter().collect::<Vec<_>>(), &plot)
}
