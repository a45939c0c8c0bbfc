//! `fitbead jaeger`: Jaeger's a1, a2, a3 per series (Jaeger units, eq 81), the branch used and
//! the points in the bistable band (eq 90), beside the paper's Fig. 9 values.

use super::fitargs::FitArgs;
use super::CliError;
use fitbead::models::JaegerBranch;
use fitbead::pipeline::FitCommand;

/// Arguments of `fitbead jaeger`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Root of eq 84 to fit where there are two: upper or lower.
    #[arg(long, default_value = "upper", value_parser = super::values::choice::<JaegerBranch>())]
    pub branch: JaegerBranch,
    /// Input, output and interval flags.
    #[command(flatten)]
    pub io: FitArgs,
}

/// Runs `fitbead jaeger`.
pub fn run(a: Args) -> Result<(), CliError> {
    a.io.fit(FitCommand::Jaeger { branch: a.branch })
}
