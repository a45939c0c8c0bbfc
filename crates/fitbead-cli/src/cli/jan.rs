//! `fitbead jan`: Jan's λ and μ per series (eq 74, fitted on v̄) and the global laws
//! λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α} (form of eqs 75–76), beside the paper's values.

use super::fitargs::FitArgs;
use super::CliError;
use fitbead::pipeline::FitCommand;

/// Arguments of `fitbead jan`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input, output and interval flags.
    #[command(flatten)]
    pub io: FitArgs,
}

/// Runs `fitbead jan`.
pub fn run(a: Args) -> Result<(), CliError> {
    a.io.fit(FitCommand::Jan)
}
