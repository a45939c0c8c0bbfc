//! `fitbead simulate`: the flags parsed into the library's [`SimulateSettings`], the CSV
//! that [`simulate`] makes written to `--output` or stdout.

use super::args::{ContactArgs, OutputArgs};
use super::values::{self, Numbers, SlopeRange};
use super::{emit, CliError};
use fitbead::models::contact::SpinRule;
use fitbead::models::{JaegerBranch, ModelKind};
use fitbead::pipeline::{RunError, SimulateSettings};
use fitbead::scene::CollisionLaw;
use std::sync::Arc;

/// Arguments of `fitbead simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Forward model that makes the data: stick, stick-approx, slip, slip-approx, stickslip,
    /// contact (with --v0: the bead-by-bead transient instead), jan (see --jan), jaeger (see
    /// --jaeger), md (molecular dynamics, see the md flags).
    #[arg(long, default_value = "stickslip", value_parser = values::choice::<ModelKind>())]
    pub model: ModelKind,
    /// Collision law: a number, cos2a, adjusted, impact or c=VALUE.
    #[arg(long, default_value = "adjusted", value_parser = values::law)]
    pub law: CollisionLaw,
    /// Radius ratios ξ of the series, comma-separated.
    #[arg(long, default_value = "0.8,1,1.6,2", value_parser = values::series)]
    pub series: Numbers,
    /// Points per series.
    #[arg(long, default_value_t = 9, value_parser = values::points)]
    pub points: usize,
    /// Relative noise: v = v_true (1 + noise · z), sigma_v = noise · v_true, z standard normal
    /// truncated to v > 0 (drawn again until the velocity is positive).
    #[arg(long, default_value_t = 0.02, value_parser = values::noise)]
    pub noise: f64,
    /// Standard uncertainty of the recorded slope, degrees: delta_deg = δ_true + σ_δ · z (z
    /// standard normal, truncated to (0, 90) degrees), the velocity made at δ_true; adds the
    /// columns sigma_delta_deg and delta_true_deg. 0: exact slopes, columns as without it.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = values::slope_sigma)]
    pub sigma_delta: f64,
    /// Seed of the random stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// ρ and f of rows without those columns.
    #[command(flatten)]
    pub contact: ContactArgs,
    /// Jan's global laws λ0,λ1,μ0,μ1 (λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α}) for
    /// --model jan [default: 0.063,4.96,0.0025,7.46, the paper's eqs 75–76]
    #[arg(long, value_parser = values::jan_laws)]
    pub jan: Option<[f64; 4]>,
    /// Jaeger's a1,a2,a3 (Jaeger units, eq 81) for --model jaeger, used for every series
    /// [default: the paper's Fig. 9 values of the series' ξ, for ξ = 0.8, 1, 1.6 or 2]
    #[arg(long, value_parser = values::jaeger_values)]
    pub jaeger: Option<[f64; 3]>,
    /// Branch of eq 84 for --model jaeger: upper or lower.
    #[arg(long, default_value = "upper", value_parser = values::choice::<JaegerBranch>())]
    pub branch: JaegerBranch,
    /// Slopes LO,HI in degrees: the range is cut to the model's steady range and the points
    /// spread over 5 %–95 % of it [default: the steady range; for jan and jaeger, whose steady
    /// range has no upper end, the onset to the onset + 12°]
    #[arg(long, value_parser = values::slope_range)]
    pub delta_range: Option<SlopeRange>,
    /// A design (CSV: series,xi,delta_deg,replicates, as `fitbead design` writes it): the
    /// data are made at exactly its slopes, `replicates` points at each, instead of spread
    /// over the steady range.
    #[arg(long, conflicts_with_all = ["series", "points", "delta_range", "v0"])]
    pub design: Option<std::path::PathBuf>,
    /// Where the result goes.
    #[command(flatten)]
    pub out: OutputArgs,
    /// --model contact only: launch speed Θ̇0 on the first bead (dimensionless, rolling
    /// launch). With it, simulate writes the bead-by-bead transient of one scene per ξ of
    /// --series at --delta-deg instead of synthetic measurements.
    #[arg(long, value_parser = values::launch_speed)]
    pub v0: Option<f64>,
    /// Slope of the --v0 transient, degrees.
    #[arg(long = "delta-deg")]
    pub delta_deg: Option<f64>,
    /// Spin rule of the collision for --model contact: roll, keep, factor=L or impact.
    #[arg(long, default_value = "roll", value_parser = values::spin)]
    pub spin: SpinRule,
    /// Molecular-dynamics settings (`--model md`).
    #[command(flatten)]
    pub md: super::forward::MdArgs,
}

/// Runs `fitbead simulate`.
pub fn run(a: Args) -> Result<(), CliError> {
    let kind = a.model;
    // The flags of one kind of run are read only for that run (the transient ignores the
    // steady-state flags, md the phenomenological models' flags).
    let steady = a.v0.is_none();
    let phenomenological = steady && kind != ModelKind::Md;
    let md = if steady && kind == ModelKind::Md {
        a.md.model()?
    } else {
        SimulateSettings::default().md
    };
    let (jan, jaeger, branch) = if phenomenological {
        (a.jan, a.jaeger, a.branch)
    } else {
        (None, None, JaegerBranch::Upper)
    };
    let range = a.delta_range.as_ref().filter(|_| steady);
    let settings = SimulateSettings {
        model: kind,
        law: a.law,
        series: a.series.0.clone(),
        points: a.points,
        noise: a.noise,
        sigma_delta: a.sigma_delta,
        seed: a.seed,
        rho: a.contact.rho(),
        f: a.contact.f(),
        jan,
        jaeger,
        branch,
        delta_range: range.map(|r| (r.lo, r.hi)),
        design: a.design.clone(),
        v0: a.v0,
        delta_deg: a.delta_deg,
        beads: a.md.beads,
        spin: a.spin,
        md,
        stop: Some(super::stop_flag()),
        progress: Some(super::forward::md_progress(0)),
        notes: Some(Arc::new(|n: &str| eprintln!("fitbead: note: {n}"))),
    };
    let bytes = settings.run().map_err(|e| match e {
        // The range as given on the command line.
        RunError::Input(mut ie) if ie.column.as_deref() == Some("--delta-range") => {
            ie.value = range.map(|r| r.text.clone());
            CliError::Input(ie)
        }
        e => CliError::from(e),
    })?;
    emit(a.out.output.as_deref(), &bytes)
}
