//! The K inversion at the ends of its bracket: no false "jumps" on the models whose v̄(K) is
//! continuous, K against independent mpmath references within 1e-15 … 1e-2 (relative) of
//! each end, one rule for K_lo/K_hi on above-range rows whichever path solves them, and a
//! velocity below the slowest steady motion double precision can represent called
//! below-range.
//!
//! References: tests/reference/k_edge_refs.csv, made by tests/reference/k_edge_refs.py
//! (mpmath: the bracket ends from their closed forms, v̄ by quadrature at 40 digits, K_ref
//! solving v̄(K_ref) = v exactly; every row rechecked at 60 digits by other routes).

use crate::fit::k::search::estimate_in_k;
use crate::fit::k::{bracket, estimate, KFailure};
use crate::models::{ForwardModel, Model};
use crate::scene::{CollisionLaw, Scene};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::reference_table;

fn model_of(name: &str) -> Model {
    match name {
        "stick" => Model::Stick,
        "stick-approx" => Model::StickApprox,
        "slip" => Model::Slip,
        "slip-approx" => Model::SlipApprox,
        "stickslip" => Model::StickSlip,
        _ => panic!("unknown model {name}"),
    }
}

fn is_jump(e: &crate::fit::k::KEstimate) -> bool {
    let root_jump = matches!(&e.root, Err(KFailure::Invalid(m)) if m.contains("jumps"));
    root_jump || e.notes.iter().any(|n| n.contains("jumps"))
}

#[test]
fn k_near_either_bracket_end_matches_mpmath_to_1e_13() {
    let (h, rows) = reference_table("k_edge_refs.csv");
    let c = |n: &str| h.iter().position(|x| x == n).unwrap();
    let num = |r: &[String], n: &str| r[c(n)].parse::<f64>().unwrap();
    let (mut worst_k, mut worst_end) = (0.0f64, 0.0f64);
    for r in &rows {
        let model = model_of(&r[c("model")]);
        let scene = Scene::new(
            num(r, "xi"),
            num(r, "delta_deg"),
            num(r, "rho"),
            num(r, "f"),
            CollisionLaw::Adjusted,
        )
        .unwrap();
        let what = format!(
            "{} xi {} delta {} {} end, offset {}",
            r[c("model")],
            r[c("xi")],
            r[c("delta_deg")],
            r[c("side")],
            r[c("rel_offset")]
        );
        let br = bracket(&model, &scene).unwrap_or_else(|e| panic!("{what}: no bracket: {e}"));
        let (k_min, k_max) = (num(r, "K_min"), num(r, "K_max"));
        let end_err = (br.lo - k_min).abs().max((br.hi - k_max).abs());
        assert!(
            end_err <= 1e-13,
            "{what}: bracket [{}, {}] vs mpmath [{k_min}, {k_max}]",
            br.lo,
            br.hi
        );
        worst_end = worst_end.max(end_err);
        let e = estimate(&model, &scene, num(r, "v"), None);
        let k = e.k().unwrap_or_else(|f| panic!("{what}: no K: {f}"));
        let err = (k - num(r, "K_ref")).abs();
        assert!(
            err <= 1e-13,
            "{what}: K {k} vs mpmath {}: {err:e}",
            r[c("K_ref")]
        );
        worst_k = worst_k.max(err);
    }
    println!(
        "k_edge_refs: {} rows, largest |K - K_ref| {worst_k:.2e}, largest bracket-end error {worst_end:.2e}",
        rows.len()
    );
    assert!(rows.len() >= 500);
}

/// A random scene over ξ ∈ [0.5, 12] (log-uniform), δ ∈ [0.2°, 35°], ρ 0.4 or 0.5 and f
/// log-uniform in [0.01, 1], as `scripts/gen_measurements.py` draws them.
pub(super) fn random_scene(rng: &mut ChaCha8Rng) -> Scene {
    let xi = (rng.random_range(0.5f64.ln()..12f64.ln())).exp();
    let d = rng.random_range(0.2..35.0);
    let rho = if rng.random_bool(0.5) { 0.4 } else { 0.5 };
    let f = (rng.random_range(0.01f64.ln()..0.0)).exp();
    Scene::new(xi, d, rho, f, CollisionLaw::Adjusted).unwrap()
}

/// One random row: v log-uniform in [0.02, 2] on half the rows; on the other half v̄ at a K
/// within ε ∈ [1e-15, 1e-2] (log-uniform, relative) of a bracket end, and then the inverse
/// must return that K (a round trip) to 1e-13.
fn row_is_clean(model: &Model, seed: u64) -> Result<(), String> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let scene = random_scene(&mut rng);
    let sigma = Some(rng.random_range(0.005..0.1));
    let near_end = rng.random_bool(0.5);
    let eps = (rng.random_range(1e-15f64.ln()..1e-2f64.ln())).exp();
    let upper = rng.random_bool(0.5);
    let v_random = (rng.random_range(0.02f64.ln()..2f64.ln())).exp();
    let (v, k_true) = if near_end {
        let Ok(br) = bracket(model, &scene) else {
            return Ok(());
        };
        let k = if upper {
            br.hi * (1.0 - eps)
        } else if br.lo > 0.0 {
            br.lo * (1.0 + eps)
        } else {
            eps * br.hi
        };
        match scene.with_k(k).ok().map(|s| model.evaluate(&s)) {
            Some(Ok(st)) => (st.mean_velocity, Some(k)),
            _ => return Ok(()),
        }
    } else {
        (v_random, None)
    };
    let e = estimate(model, &scene, v, sigma.map(|s| s * v));
    if is_jump(&e) {
        return Err(format!(
            "{model:?} xi {} delta {} rho {} f {} v {v}: {:?} {:?}",
            scene.xi(),
            scene.delta_deg(),
            scene.rho(),
            scene.f(),
            e.root.as_ref().map(|r| r.k),
            e.notes
        ));
    }
    if let Some(k) = k_true {
        match e.k() {
            Ok(got) if (got - k).abs() <= 1e-13 => {}
            other => {
                return Err(format!(
                    "{model:?} xi {} delta {} v {v}: K {other:?}, expected {k} (offset {eps:e}, {} end)",
                    scene.xi(),
                    scene.delta_deg(),
                    if upper { "upper" } else { "lower" }
                ))
            }
        }
    }
    Ok(())
}

#[test]
fn no_false_jumps_on_a_million_rows_of_the_continuous_models() {
    // 1,000,000 rows in all; fewer for the slip models, whose quadratures cost more.
    let plan = [
        (Model::Stick, 400_000u64),
        (Model::StickApprox, 400_000),
        (Model::Slip, 100_000),
        (Model::SlipApprox, 100_000),
    ];
    for (i, (model, rows)) in plan.iter().enumerate() {
        let bad: Vec<String> = (0..*rows)
            .into_par_iter()
            .filter_map(|j| row_is_clean(model, (i as u64) << 32 | j).err())
            .collect();
        println!("{model:?}: {rows} rows, {} faults", bad.len());
        assert!(
            bad.is_empty(),
            "{} faults, the first: {:?}",
            bad.len(),
            &bad[..bad.len().min(5)]
        );
    }
}

#[test]
fn above_range_rows_get_the_same_interval_on_either_path() {
    // Stick at ξ = 1, δ = 12°: the launch-speed path applies (Θ0 < 0).
    let scene = Scene::new(1.0, 12.0, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
    let br = bracket(&Model::Stick, &scene).unwrap();
    let v = br.v_hi * 1.01;
    let sigma = 0.05 * v;
    let e = estimate(&Model::Stick, &scene, v, Some(sigma));
    let g = estimate_in_k(&Model::Stick, &scene, v, Some(sigma));
    assert_eq!(e.root, Err(KFailure::AboveRange));
    // v − σ is inside the range: K_lo is its root; v + σ above it: K_hi the range's end. The
    // launch path's range ends at lift-off itself, the search's 4 ulp below it (its top is
    // tested just inside): the two tops agree to 16 ulp, the roots to 1e-12.
    let k_lo = e.k_lo.expect("K_lo of an above-range row");
    assert!(k_lo > br.lo && k_lo < br.hi, "{k_lo}");
    let top = e.bracket.expect("the launch path's bracket").hi;
    assert_eq!(e.k_hi, Some(top));
    assert_eq!(g.k_hi, Some(br.hi));
    assert!(
        (top - br.hi).abs() <= 16.0 * f64::EPSILON * top,
        "{top} vs {}",
        br.hi
    );
    assert!(
        (k_lo - g.k_lo.unwrap()).abs() <= 1e-12,
        "{k_lo} vs {:?}",
        g.k_lo
    );
    assert_eq!(e.notes, g.notes);
}

#[test]
fn a_velocity_below_the_slowest_representable_motion_is_below_range() {
    for xi in [0.8, 1.0, 1.6, 2.0] {
        let scene = Scene::new(xi, 7.5, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
        for v in [1e-300, 1e-30, 1e-5] {
            let e = estimate(&Model::Stick, &scene, v, None);
            assert_eq!(
                e.root,
                Err(KFailure::BelowRange),
                "xi {xi} v {v}: {:?}",
                e.root
            );
            assert!(
                e.notes.iter().any(|n| n.contains("double precision")),
                "xi {xi} v {v}: {:?}",
                e.notes
            );
        }
    }
}
