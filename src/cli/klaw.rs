//! `fitbead klaw`: a law K(α) fitted to all series at once (law c, one K per series), and the
//! parameter-free impact law scored beside it.

use super::fitargs::FitArgs;
use super::k::parse_model;
use super::CliError;
use crate::fit::klaw::{fit_law, KLaw};

/// Arguments of `fitbead klaw`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Contact model: stick, slip or stickslip (stick-approx and slip-approx work too).
    #[arg(long)]
    pub model: String,
    /// The law: c (K = cos 2α + c sin²α sin 2α), impact (K = (cos 2α + ρ)/(1 + ρ), scored
    /// only) or free-per-series (one K per series). The impact law is always scored as well.
    #[arg(long, default_value = "c")]
    pub law: String,
    /// Input, output and interval flags.
    #[command(flatten)]
    pub io: FitArgs,
}

/// Runs `fitbead klaw`.
pub fn run(a: Args) -> Result<(), CliError> {
    let model = parse_model(&a.model)?;
    let law: KLaw = a
        .law
        .parse()
        .map_err(|e: String| super::flag_error("--law", &a.law, e))?;
    let (_t, _rows, ds) = a.io.read()?;
    let fail = |e: crate::fit::klaw::KLawError| CliError::Other(format!("klaw: {e}"));
    let main = fit_law(model, &ds, law, a.io.level, !a.io.no_profile).map_err(fail)?;
    let mut stats = vec![main.summary.stats.clone()];
    if law != KLaw::Impact {
        let imp = fit_law(model, &ds, KLaw::Impact, a.io.level, false).map_err(fail)?;
        stats.push(imp.summary.stats);
    }
    a.io.write(&main.summary.params, &stats)
}
