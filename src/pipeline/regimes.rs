//! `fitbead regimes`: δ_m (eq 32) and δ_d (eq 31) per ξ, the bulk friction μ (eq 79) and the
//! critical ξ of a collision law, as CSV.

use super::{setting_error, RunError};
use crate::io::records::{to_csv, RegimeRecord};
use crate::models::regimes::alpha_of_xi;
use crate::numfmt::echo_f64;
use crate::scene::CollisionLaw;

impl RegimeRecord {
    /// The CSV of `fitbead regimes`: the records of [`RegimeRecord::table`] for the ξ of `xi`
    /// under `law` with gyration parameter `rho`. A law whose K at some ξ is outside (0, 1)
    /// is refused as the setting `--law` of value `law_text` (the law as the user wrote it).
    pub fn csv(
        xi: &[f64],
        law: CollisionLaw,
        law_text: &str,
        rho: f64,
    ) -> Result<Vec<u8>, RunError> {
        for &x in xi {
            let k = law.k(alpha_of_xi(x), rho);
            if !(k.is_finite() && k > 0.0 && k < 1.0) {
                return Err(setting_error(
                    "--law",
                    law_text,
                    format!(
                        "K = {} at xi = {}: a law's K must be in (0, 1) (a collision cannot \
                         return more velocity than it receives)",
                        echo_f64(k),
                        echo_f64(x)
                    ),
                ));
            }
        }
        to_csv(Self::table(xi, law, rho)).map_err(|e| RunError::Failed(e.to_string()))
    }
}
