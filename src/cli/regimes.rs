//! `fitbead regimes`: δ_m (eq 32) and δ_d (eq 31) per ξ, the bulk friction μ (eq 79) and the
//! critical ξ below which no steady regime exists.

use super::args::OutputArgs;
use super::values::LawText;
use super::{emit, values, CliError};
use crate::io::fmt_f64;
use crate::models::regimes::{
    alpha_of_xi, bulk_friction_law, critical_xi, delta_d_law, delta_m_law,
};

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
    let law = a.law.law;
    let xc = critical_xi(law, a.rho);
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::Other(e.to_string());
    w.write_record([
        "xi",
        "alpha_deg",
        "K",
        "delta_m_deg",
        "delta_d_deg",
        "mu_eq79",
        "steady_range",
        "critical_xi",
    ])
    .map_err(io)?;
    for &xi in &a.xi {
        let al = alpha_of_xi(xi);
        let k = law.k(al, a.rho);
        if !(k.is_finite() && k > 0.0 && k < 1.0) {
            return Err(super::flag_error(
                "--law",
                &a.law.text,
                format!(
                    "K = {} at xi = {}: a law's K must be in (0, 1) (a collision cannot return \
                     more velocity than it receives)",
                    crate::numfmt::echo_f64(k),
                    crate::numfmt::echo_f64(xi)
                ),
            ));
        }
        let (dm, dd) = (delta_m_law(al, law, a.rho), delta_d_law(al, law, a.rho));
        w.write_record([
            fmt_f64(xi),
            fmt_f64(al.to_degrees()),
            fmt_f64(k),
            fmt_f64(dm.to_degrees()),
            fmt_f64(dd.to_degrees()),
            fmt_f64(bulk_friction_law(al, law, a.rho)),
            (if dm < dd { "yes" } else { "no" }).to_string(),
            xc.map(fmt_f64).unwrap_or_default(),
        ])
        .map_err(io)?;
    }
    let bytes = w.into_inner().map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.out.output.as_deref(), &bytes)
}
