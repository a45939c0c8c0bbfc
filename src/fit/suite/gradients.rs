//! The analytic gradients of the fitted curves (Jan's per-series and global energy balance,
//! Jaeger's law on each root of eq 84) against central differences.

use crate::fit::jaeger::JaegerModel;
use crate::fit::jan::{JanGlobal, JanSeries};
use crate::inverse::CurveModel;
use crate::models::JaegerBranch;

/// The analytic gradients of Jan's and Jaeger's models against central differences (step
/// 1e-6 relative; agreement to 1e-6 relative is what a second-order difference can show).
#[test]
fn analytic_gradients_match_central_differences() {
    fn check<X, M: CurveModel<X>>(m: &M, x: &X, p: &[f64]) {
        let mut g = vec![0.0; p.len()];
        m.gradient(x, p, &mut g).unwrap().unwrap();
        for k in 0..p.len() {
            let h = 1e-6 * p[k].abs().max(1e-3);
            let (mut pp, mut pm) = (p.to_vec(), p.to_vec());
            pp[k] += h;
            pm[k] -= h;
            let d = (m.value(x, &pp).unwrap() - m.value(x, &pm).unwrap()) / (2.0 * h);
            assert!(
                (d - g[k]).abs() <= 1e-6 * g[k].abs().max(1e-8),
                "parameter {k}: analytic {} vs difference {d}",
                g[k]
            );
        }
    }
    for d in [7.3f64, 12.0, 20.0] {
        let (sd, cd) = d.to_radians().sin_cos();
        let x = (0.5, sd, cd);
        check(&JanSeries, &x, &[0.6, 0.1]);
        check(&JanGlobal, &x, &[0.063, 4.96, 0.0025, 7.46]);
        let (t, eps) = (sd / cd, 2.0);
        for branch in [JaegerBranch::Upper, JaegerBranch::Lower] {
            // ξ = 1 values of Fig. 9: 7.3° lies in the bistable band (tan δ in (0.1235, 0.131),
            // eq 90: two roots, the branches differ); at 12° and 20° there is one root.
            check(&JaegerModel(branch), &(t, cd, eps), &[0.131, 18.57, 1.41]);
        }
    }
}
