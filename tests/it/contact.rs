//! The general contact model (docs/PHYSICS.md#general-contact-model): its limits (stick when no
//! slip can happen, the paper's stick/slip where its assumed sequence is the true one), the energy
//! balance per contact, and one contact against an independent time-stepping reference.

use fitbead::models::contact::{Contact, ContactEnd, Launch, PhaseKind, SpinRule};
use fitbead::models::{ForwardModel, Model, Phases};
use fitbead::scene::{CollisionLaw, Scene};

use crate::common::bin;

fn scene(xi: f64, delta_deg: f64, rho: f64, f: f64, law: CollisionLaw) -> Scene {
    Scene::new(xi, delta_deg, rho, f, law).unwrap()
}

/// Slopes across the stick model's regime B (δ_m, δ_d) of a scene, `n` of them, ends excluded.
fn slopes_in_b(xi: f64, rho: f64, f: f64, law: CollisionLaw, n: usize) -> Vec<f64> {
    let ok = |d: f64| Model::Stick.evaluate(&scene(xi, d, rho, f, law)).is_ok();
    let grid: Vec<f64> = (1..400).map(|i| i as f64 * 0.2).collect();
    let b: Vec<f64> = grid.into_iter().filter(|&d| ok(d)).collect();
    if b.len() < 2 {
        return vec![];
    }
    let (lo, hi) = (b[0], b[b.len() - 1]);
    (1..=n)
        .map(|i| lo + (hi - lo) * i as f64 / (n + 1) as f64)
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// When f is so large that rolling never needs more friction than f N (Θ_G ≥ Θf), the contact
/// is pure rolling: the model equals `stick` (required: ≤ 1e-12 relative).
#[test]
fn reduces_to_stick_when_no_slip_can_happen() {
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for &xi in &[0.8, 1.0, 1.6, 2.0, 5.0] {
        for &rho in &[0.4, 0.5, 1.0] {
            let law = CollisionLaw::Adjusted;
            for d in slopes_in_b(xi, rho, 50.0, law, 7) {
                let sc = scene(xi, d, rho, 50.0, law);
                let st = Model::Stick.evaluate(&sc).unwrap();
                let c = Contact::default().evaluate(&sc).unwrap();
                assert_eq!(c.phases.to_string(), "roll", "xi {xi} rho {rho} d {d}");
                worst = worst.max(rel(c.mean_velocity, st.mean_velocity));
                worst = worst.max(rel(c.final_velocity, st.final_velocity));
                n += 1;
            }
        }
    }
    println!("contact vs stick, {n} scenes with f = 50: max relative difference {worst:.2e}");
    assert!(n >= 60);
    assert!(worst <= 1e-12, "worst {worst:e}");
}

/// Where the true sequence is the paper's (roll, then one forward slip after Θ_G, or pure
/// rolling), the contact model equals the paper's stick/slip model (≤ 1e-12 relative).
#[test]
fn reduces_to_stickslip_where_its_sequence_is_the_true_one() {
    let mut worst: f64 = 0.0;
    let mut n_rollslip = 0;
    let mut n_other = 0;
    for &xi in &[1.6, 2.0, 3.0, 5.0, 10.0] {
        for &f in &[0.1, 0.2, 0.3, 0.5] {
            let law = CollisionLaw::Adjusted;
            for d in slopes_in_b(xi, 0.4, f, law, 8) {
                let sc = scene(xi, d, 0.4, f, law);
                let Ok(c) = Contact::default().evaluate(&sc) else {
                    continue;
                };
                let seq = c.phases.to_string();
                if seq != "roll>slip" && seq != "roll" {
                    n_other += 1;
                    continue;
                }
                let ss = Model::StickSlip.evaluate(&sc).unwrap();
                let same_phases = matches!(
                    (ss.phases, seq.as_str()),
                    (Phases::RollSlip, "roll>slip") | (Phases::Roll, "roll")
                );
                assert!(same_phases, "xi {xi} f {f} d {d}: {seq} vs {}", ss.phases);
                worst = worst.max(rel(c.mean_velocity, ss.mean_velocity));
                worst = worst.max(rel(c.final_velocity, ss.final_velocity));
                if seq == "roll>slip" {
                    n_rollslip += 1;
                }
            }
        }
    }
    println!(
        "contact vs stickslip: {n_rollslip} roll>slip scenes, max relative difference \
         {worst:.2e} ({n_other} scenes with another sequence skipped)"
    );
    assert!(n_rollslip >= 20, "{n_rollslip}");
    assert!(worst <= 1e-12, "worst {worst:e}");
}

/// On ordinary scenes (ρ = 0.4, f = 0.1, ξ = 1) Θ0 < −Θ_G: the contact starts with a backward
/// slip (the caveat of docs/PHYSICS.md#stickslip), and the stick/slip model is then not exact.
#[test]
fn ordinary_scenes_start_with_a_backward_slip() {
    let sc = scene(1.0, 12.0, 0.4, 0.1, CollisionLaw::Adjusted);
    let c = Contact::default().steady_state(&sc).unwrap();
    assert_eq!(
        c.run.phases.kinds(),
        &[PhaseKind::BackSlip, PhaseKind::Roll, PhaseKind::Slip]
    );
    let ch = c.run.phases.changes();
    // Backward slip ends before the top, forward slip starts after it near Θ_G ≈ 15°.
    assert!(ch[0] < 0.0 && ch[0] > sc.theta_0_rad(), "{ch:?}");
    assert!(
        ch[1].to_degrees() > 14.0 && ch[1].to_degrees() < 17.0,
        "{ch:?}"
    );
    let ss = Model::StickSlip.evaluate(&sc).unwrap();
    assert!(rel(2.0 * sc.sin_alpha() / c.run.time, ss.mean_velocity) > 1e-6);
}

/// Potential drop per bead = collision loss (translation + spin) + friction work, to 1e-12
/// relative, for every spin rule, over scenes with every phase sequence the model finds.
#[test]
fn energy_balance_closes_per_contact() {
    let mut worst: f64 = 0.0;
    let mut seqs = std::collections::BTreeSet::new();
    let mut n = 0;
    for rule in [
        SpinRule::Roll,
        SpinRule::Keep,
        SpinRule::Impact,
        SpinRule::Factor(0.5),
    ] {
        for &xi in &[0.8, 1.0, 2.0, 5.0] {
            for &f in &[0.0, 0.05, 0.1, 0.3, 2.0] {
                for d in slopes_in_b(xi, 0.4, f, CollisionLaw::Adjusted, 4) {
                    let sc = scene(xi, d, 0.4, f, CollisionLaw::Adjusted);
                    let model = Contact {
                        spin: rule,
                        tol: 1e-14,
                    };
                    let Ok(s) = model.steady_state(&sc) else {
                        continue;
                    };
                    let e = s.energy(&sc);
                    worst = worst.max(e.closure().abs());
                    seqs.insert(s.run.phases.to_string());
                    n += 1;
                }
            }
        }
    }
    println!("energy closure over {n} steady contacts: max {worst:.2e}; sequences {seqs:?}");
    assert!(n >= 200, "{n}");
    assert!(seqs.len() >= 4, "{seqs:?}");
    assert!(worst <= 1e-12, "worst {worst:e}");
}

/// An independent reference: the equations of motion (docs/PHYSICS.md#general-contact-model)
/// integrated in time by classical RK4 with a fixed small step, the events (stick → slip, slip →
/// stick, collision) located by bisection on the step length. Nothing of the model's closed forms
/// is used.
struct Reference {
    rho: f64,
    f: f64,
    theta_f: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Roll,
    Slip(f64),
}

impl Reference {
    fn deriv(&self, m: Mode, y: [f64; 4]) -> [f64; 4] {
        // y = (θ, θ̇, w = ω/ε, friction work)
        let (th, thd, w) = (y[0], y[1], y[2]);
        match m {
            Mode::Roll => {
                let a = th.sin() / (1.0 + self.rho);
                [thd, a, a, 0.0]
            }
            Mode::Slip(sg) => {
                let n = th.cos() - thd * thd;
                let t = sg * self.f * n;
                [thd, th.sin() - t, t / self.rho, t * (thd - w)]
            }
        }
    }
    fn rk4(&self, m: Mode, y: [f64; 4], h: f64) -> [f64; 4] {
        let add = |a: [f64; 4], b: [f64; 4], s: f64| {
            [
                a[0] + s * b[0],
                a[1] + s * b[1],
                a[2] + s * b[2],
                a[3] + s * b[3],
            ]
        };
        let k1 = self.deriv(m, y);
        let k2 = self.deriv(m, add(y, k1, h / 2.0));
        let k3 = self.deriv(m, add(y, k2, h / 2.0));
        let k4 = self.deriv(m, add(y, k3, h));
        let mut o = y;
        for i in 0..4 {
            o[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        o
    }
    /// Event function of a mode (changes sign at the event) and of the collision.
    fn events(&self, m: Mode, y: [f64; 4]) -> [f64; 2] {
        let (th, thd, w) = (y[0], y[1], y[2]);
        let n = th.cos() - thd * thd;
        let e = match m {
            Mode::Roll => self.f * n - (self.rho * th.sin() / (1.0 + self.rho)).abs(),
            Mode::Slip(sg) => sg * (thd - w),
        };
        [e, self.theta_f - th]
    }
    fn mode_at(&self, y: [f64; 4]) -> Mode {
        let n = y[0].cos() - y[1] * y[1];
        let tr = self.rho * y[0].sin() / (1.0 + self.rho);
        if tr > self.f * n {
            Mode::Slip(1.0)
        } else if tr < -self.f * n {
            Mode::Slip(-1.0)
        } else {
            Mode::Roll
        }
    }
    /// Runs one contact from (Θ0, Θ̇0, rolling spin); (Θ̇f, ωf/ε, time, friction work, modes).
    fn run(&self, theta0: f64, v0: f64, h: f64) -> (f64, f64, f64, f64, Vec<Mode>) {
        let mut y = [theta0, v0, v0, 0.0];
        let mut t = 0.0;
        let mut m = self.mode_at(y);
        let mut modes = vec![m];
        loop {
            let y1 = self.rk4(m, y, h);
            let e0 = self.events(m, y);
            let e1 = self.events(m, y1);
            let hit = (0..2).find(|&i| e0[i] > 0.0 && e1[i] <= 0.0);
            match hit {
                None => {
                    y = y1;
                    t += h;
                }
                Some(_) => {
                    // Bisection on the step length to the first event.
                    let (mut lo, mut hi) = (0.0, h);
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + hi);
                        if mid == lo || mid == hi {
                            break;
                        }
                        let e = self.events(m, self.rk4(m, y, mid));
                        if e.iter().zip(&e0).any(|(a, b)| *b > 0.0 && *a <= 0.0) {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    y = self.rk4(m, y, hi);
                    t += hi;
                    if self.events(m, y)[1] <= 0.0 {
                        return (y[1], y[2], t, y[3], modes);
                    }
                    // Phase change: slip → stick makes the spin roll exactly.
                    if let Mode::Slip(_) = m {
                        y[2] = y[1];
                        m = self.mode_at(y);
                    } else {
                        let tr = self.rho * y[0].sin() / (1.0 + self.rho);
                        m = Mode::Slip(tr.signum());
                    }
                    modes.push(m);
                }
            }
        }
    }
}

#[test]
fn one_contact_matches_a_time_stepping_reference() {
    // Ordinary scene (backslip > roll > slip) and a steeper one, launched rolling.
    for &(xi, d, f, v0) in &[
        (1.0, 12.0, 0.1, 0.47),
        (1.0, 12.0, 0.1, 0.35),
        (2.0, 5.73, 0.1, 0.40),
        (0.8, 12.0, 0.2, 0.45),
    ] {
        let sc = scene(xi, d, 0.4, f, CollisionLaw::Adjusted);
        let r = Contact::default().run(
            &sc,
            Launch {
                theta_dot: v0,
                spin: v0,
            },
        );
        let ContactEnd::Collision { theta_dot, spin } = r.end else {
            panic!("{:?}", r.end)
        };
        let reference = Reference {
            rho: 0.4,
            f,
            theta_f: sc.theta_f_rad(),
        };
        let (rv, rw, rt, rwork, modes) = reference.run(sc.theta_0_rad(), v0, 2e-4);
        let (rv2, _, rt2, _, _) = reference.run(sc.theta_0_rad(), v0, 4e-4);
        // The reference's own error, from halving its step (RK4: error ∝ h⁴).
        let own = (rv - rv2).abs().max((rt - rt2).abs());
        println!(
            "xi {xi} d {d} f {f} v0 {v0}: {} | dv {:.1e} dw {:.1e} dt {:.1e} dW {:.1e} \
             (reference's own change on halving the step {own:.1e})",
            r.phases,
            theta_dot - rv,
            spin - rw,
            r.time - rt,
            r.friction_work - rwork
        );
        assert_eq!(
            r.phases.kinds().len(),
            modes.len(),
            "{} {modes:?}",
            r.phases
        );
        assert!(own < 1e-10, "reference not converged: {own:e}");
        assert!((theta_dot - rv).abs() < 1e-9, "{theta_dot} vs {rv}");
        assert!((spin - rw).abs() < 1e-9, "{spin} vs {rw}");
        assert!((r.time - rt).abs() < 1e-9, "{} vs {rt}", r.time);
        assert!((r.friction_work - rwork).abs() < 1e-9);
    }
}

/// §5.2.2: the mean velocity does not depend on the initial velocity — transients from
/// different launches settle on the same steady contact, which the direct solve finds.
#[test]
fn transients_settle_on_the_steady_state() {
    let sc = scene(1.0, 12.0, 0.4, 0.1, CollisionLaw::Adjusted);
    let model = Contact::default();
    let st = model.steady_state(&sc).unwrap();
    for v0 in [0.3, 0.4, 0.5] {
        let tr = model.transient(
            &sc,
            Launch {
                theta_dot: v0,
                spin: v0,
            },
            80,
        );
        assert_eq!(tr.len(), 80);
        let (l, _) = tr[79];
        assert!(
            (l.theta_dot - st.launch.theta_dot).abs() < 1e-12,
            "{v0}: {} vs {}",
            l.theta_dot,
            st.launch.theta_dot
        );
    }
    // Too slow a launch stops on the first bead (regime A behaviour), too fast lifts off.
    let slow = model.transient(
        &sc,
        Launch {
            theta_dot: 0.1,
            spin: 0.1,
        },
        10,
    );
    assert_eq!(slow.len(), 1);
    assert!(matches!(
        slow[0].1.end,
        ContactEnd::Failed(fitbead::models::NotSteady::Stops { .. })
    ));
}

/// The impact rule fixes K = (cos 2α + ρ)/(1+ρ) for a bead rolling in; with no slip possible
/// it is the stick model with the impact law.
#[test]
fn impact_rule_is_the_impact_law_when_rolling() {
    for &(xi, d) in &[(1.0, 10.0), (2.0, 5.0), (0.8, 13.0)] {
        let sc = scene(xi, d, 0.4, 50.0, CollisionLaw::Value(0.3));
        let st = Model::Stick
            .evaluate(&scene(xi, d, 0.4, 50.0, CollisionLaw::Impact))
            .unwrap();
        let c = Contact {
            spin: SpinRule::Impact,
            tol: 1e-14,
        }
        .evaluate(&sc)
        .unwrap();
        assert!(rel(c.mean_velocity, st.mean_velocity) < 1e-12);
    }
}

/// `forward --model contact`: the phase columns and the energy closure on every row; a bad
/// spin rule exits 2 naming the flag; `simulate --model contact --v0` writes one row per bead.
#[test]
fn cli_forward_and_transient() {
    let out = bin()
        .args([
            "forward",
            "--model",
            "contact",
            "--xi",
            "1",
            "--delta-deg",
            "12",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let h = r.headers().unwrap().clone();
    for c in [
        "v",
        "regime",
        "status",
        "phase_sequence",
        "phase_change_deg",
        "friction_work_frac",
        "energy_closure",
        "spin_rule",
    ] {
        assert!(h.iter().any(|x| x == c), "missing column {c}");
    }
    let row = r.records().next().unwrap().unwrap();
    let get = |n: &str| row[h.iter().position(|x| x == n).unwrap()].to_string();
    assert_eq!(get("phase_sequence"), "backslip>roll>slip");
    assert!(get("energy_closure").parse::<f64>().unwrap().abs() < 1e-12);

    let bad = bin()
        .args([
            "forward",
            "--model",
            "contact",
            "--xi",
            "1",
            "--delta-deg",
            "12",
            "--spin",
            "sideways",
        ])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--spin"));

    let tr = bin()
        .args([
            "simulate",
            "--model",
            "contact",
            "--v0",
            "0.4",
            "--beads",
            "7",
            "--delta-deg",
            "12",
            "--series",
            "1,2",
        ])
        .output()
        .unwrap();
    assert!(tr.status.success());
    let text = String::from_utf8(tr.stdout).unwrap();
    assert_eq!(text.lines().count(), 1 + 2 * 7);
    assert!(text
        .lines()
        .next()
        .unwrap()
        .starts_with("xi,delta_deg,bead,initial_velocity"));
}

/// `simulate --model contact --spin RULE` makes its synthetic data under that rule: each row's
/// v_true equals the library's contact model with the same rule at the row's scene (and differs
/// from the default rule's); an unknown rule, or a rule other than `roll` for a model without
/// spin rules, exits 2 naming `--spin`.
#[test]
fn simulate_uses_the_spin_rule_and_refuses_one_it_cannot_use() {
    let run = |spin: &str| {
        let out = bin()
            .args([
                "simulate", "--model", "contact", "--series", "1", "--points", "3", "--spin", spin,
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let rows: Vec<(f64, f64)> = r
            .records()
            .map(|x| {
                let x = x.unwrap();
                (x[2].parse().unwrap(), x[5].parse().unwrap())
            })
            .collect();
        rows
    };
    for (name, rule) in [
        ("keep", SpinRule::Keep),
        ("factor=0.5", SpinRule::Factor(0.5)),
    ] {
        let model = Model::Contact(Contact {
            spin: rule,
            ..Contact::default()
        });
        let roll = run("roll");
        let rows = run(name);
        assert_eq!(rows.len(), 3);
        for ((d, v_true), (d_roll, v_roll)) in rows.iter().zip(&roll) {
            let sc = Scene::new(1.0, *d, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
            assert_eq!(
                *v_true,
                model.evaluate(&sc).unwrap().mean_velocity,
                "{name} at {d}"
            );
            let sc_roll = Scene::new(1.0, *d_roll, 0.4, 0.1, CollisionLaw::Adjusted).unwrap();
            let roll_model = Model::Contact(Contact::default());
            assert_eq!(
                *v_roll,
                roll_model.evaluate(&sc_roll).unwrap().mean_velocity
            );
            assert_ne!(v_true, v_roll, "{name}: the rule must change the data");
        }
    }
    for args in [
        ["--model", "contact", "--spin", "reset"],
        ["--model", "stickslip", "--spin", "keep"],
    ] {
        let out = bin().arg("simulate").args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("'--spin'"), "{args:?}: {err}");
        assert!(out.stdout.is_empty());
    }
}
