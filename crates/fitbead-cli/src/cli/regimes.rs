//! `fitbead regimes`: δ_m (eq 32) and δ_d (eq 31) per ξ, the bulk friction μ (eq 79) and the
//! critical ξ below which no steady regime exists.

use super::args::OutputArgs;
use super::values::LawText;
use super::{emit, values, CliError};
use fitbead::io::records::RegimeRecord;

/// Arguments of `fitbead regimes`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Collision law: a number, cos2a, adjusted, impact or c=VALUE.
    #[arg(long, default_value = "adjusted", value_parser = values::law_with_text)]
    pub law: LawText,
    /// Gyration parameter ρ.
    #[arg(long, default_value_t = 0.4, value_parser = values::non_negative)]
    pub rho: f64,
    /// Radius ratios ξ (comma-separated, or the flag repeated).
    #[arg(long, value_delimiter = ',', default_values_t = vec![0.8, 1.0, 1.6, 2.0],
          value_parser = values::radius_ratio)]
    pub xi: Vec<f64>,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
}

/// Runs `fitbead regimes`.
pub fn run(a: Args) -> Result<(), CliError> {
    let bytes = RegimeRecord::csv(&a.xi, a.law.law, &a.law.text, a.rho)?;
    emit(a.out.output.as_deref(), &bytes)
}
