//! `fitbead klaw`: a law K(α) fitted to all series at once (law c, one K per series), and the
//! parameter-free impact law scored beside it.

use super::fitargs::FitArgs;
use super::values::{self, KModel};
use super::CliError;
use fitbead::fit::klaw::KLaw;
use fitbead::pipeline::FitCommand;

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
    a.io.fit(FitCommand::Klaw {
        model: a.model.kind(),
        law: a.law,
        tol: a.tol,
        skip_unsteady: a.skip_unsteady,
    })
}
