//! The comparison of the rolling, stick/slip and general contact models in docs/ACCURACY.md
//! ("General contact model"): mean velocities on the paper's Fig. 7 scenes, and the collision law
//! fitted to the default data set under each model, with the phase sequences the contact model
//! finds.
//!
//!     cargo run --release --example contact_table

use fitbead::fit::builder::KLawFitter;
use fitbead::fit::data::Dataset;
use fitbead::fit::klaw::KLaw;
use fitbead::models::contact::Contact;
use fitbead::models::{ForwardModel, Model};
use fitbead::{CollisionLaw, Scene};
use std::collections::BTreeMap;

fn main() {
    let contact = Model::Contact(Contact::default());
    println!("Fig. 7 scenes (ρ = 0.4, f = 0.1, K = cos 2α + ½ sin²α sin 2α):\n");
    println!("| ξ | δ (°) | v̄ rolling | v̄ stickslip | v̄ contact | stickslip/rolling | contact/rolling | contact − stickslip | contact phases (change angles, °) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for &(xi, d) in &[(2.0, 5.73), (1.0, 11.53)] {
        let sc = Scene::new(xi, d, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
        let r = Model::Stick.evaluate(&sc).unwrap().mean_velocity;
        let s = Model::StickSlip.evaluate(&sc).unwrap().mean_velocity;
        let c = Contact::default().steady_state(&sc).unwrap();
        let cv = 2.0 * sc.sin_alpha() / c.run.time;
        println!(
            "| {xi} | {d} | {r:.6} | {s:.6} | {cv:.6} | {:.4} | {:.4} | {:+.2e} | {} ({}) |",
            s / r,
            cv / r,
            (cv - s) / s,
            c.run.phases,
            c.run
                .phases
                .changes()
                .iter()
                .map(|a| format!("{:.2}", a.to_degrees()))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let text = std::fs::read_to_string("data/default.csv").expect("data/default.csv");
    let mut rdr = csv::Reader::from_reader(text.as_bytes());
    let h = rdr.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let (cs, cx, cd, cv, cg) = (
        col("series"),
        col("xi"),
        col("delta_deg"),
        col("v"),
        col("sigma_v"),
    );
    let rows: Vec<_> = rdr
        .records()
        .map(|r| {
            let r = r.unwrap();
            let num = |i: usize| r[i].parse::<f64>().unwrap();
            (
                r[cs].to_string(),
                Scene::new(num(cx), num(cd), 0.4, 0.1, CollisionLaw::Value(0.5)).unwrap(),
                num(cv),
                Some(num(cg)),
            )
        })
        .collect();
    let data = Dataset::new(rows).unwrap();
    println!("\nDefault data (synthetic, made by stickslip with c = ½): K per series and law c fitted on v̄:\n");
    println!("| model | K ξ=0.8 | K ξ=1 | K ξ=1.6 | K ξ=2 | c (law K = cos 2α + c sin²α sin 2α) | χ² law c (36 points) |");
    println!("|---|---|---|---|---|---|---|");
    for (name, m) in [
        ("rolling", Model::Stick),
        ("stickslip", Model::StickSlip),
        ("contact", contact),
    ] {
        let free = KLawFitter::new(m, KLaw::FreePerSeries)
            .least_squares(false)
            .fit(&data)
            .unwrap();
        let law = KLawFitter::new(m, KLaw::C)
            .least_squares(false)
            .fit(&data)
            .unwrap();
        let ks: Vec<String> = free
            .params
            .iter()
            .map(|p| format!("{:.4} ± {:.4}", p.value, p.stderr.unwrap_or(f64::NAN)))
            .collect();
        let c = &law.params[0];
        println!(
            "| {name} | {} | {:.4} ± {:.4} | {:.2} |",
            ks.join(" | "),
            c.value,
            c.stderr.unwrap_or(f64::NAN),
            law.stats.chi2
        );
    }
    // Phase sequences of the contact model at each point's fitted law-c K.
    let law = KLawFitter::new(contact, KLaw::C)
        .least_squares(false)
        .fit(&data)
        .unwrap();
    let c = law.params[0].value;
    let mut seqs: BTreeMap<(String, String), usize> = BTreeMap::new();
    for p in &data.points {
        // Law c: K = cos 2α + c sin²α sin 2α.
        let a = p.scene.alpha_rad();
        let k = (2.0 * a).cos() + c * a.sin().powi(2) * (2.0 * a).sin();
        let sc = p.scene.with_k(k).unwrap();
        let seq = contact
            .evaluate(&sc)
            .map(|s| s.phases.to_string())
            .unwrap_or_else(|e| e.status().to_string());
        *seqs
            .entry((data.labels[p.series].clone(), seq))
            .or_default() += 1;
    }
    println!("\nContact-model phase sequences at the fitted law c (series: sequence × points):\n");
    for ((s, q), n) in seqs {
        println!("- ξ = {s}: {q} × {n}");
    }
}
