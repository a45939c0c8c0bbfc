//! `fitbead forward`: mean velocity, regime and diagnostics of each scene under one model.

use super::{emit, read_input, CliError};
use crate::error::Error;
use crate::io::scenes::Table;
use crate::io::{fmt_f64, InputError};
use crate::models::contact::{Contact, SpinRule, SteadyContact};
use crate::models::jaeger::Jaeger;
use crate::models::jan::Jan;
use crate::models::{regime_of, ForwardModel, JaegerBranch, Model, ModelKind, Outcome};
use crate::scene::{CollisionLaw, Scene};
use rayon::prelude::*;
use std::path::PathBuf;

/// Arguments of `fitbead forward`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Forward model: stick, stick-approx, slip, slip-approx, stickslip, jan, jaeger.
    #[arg(long)]
    pub model: String,
    /// Scenes CSV with columns xi,delta_deg[,K,rho,f] (K a number or a law name); extra columns
    /// pass through. Without --input and --xi: the embedded default data set.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Output CSV (written atomically); stdout when absent.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Radius ratio ξ = r/R of a single scene.
    #[arg(long)]
    pub xi: Option<f64>,
    /// Slope δ of a single scene, degrees.
    #[arg(long = "delta-deg")]
    pub delta_deg: Option<f64>,
    /// Collisional parameter: a number, cos2a, adjusted, impact or c=VALUE (default for rows
    /// without a K column).
    #[arg(long = "K", default_value = "adjusted")]
    pub k: String,
    /// Gyration parameter ρ (2/5 sphere, 1/2 cylinder), for rows without a rho column.
    #[arg(long, default_value_t = 0.4)]
    pub rho: f64,
    /// Coulomb friction coefficient f, for rows without an f column.
    #[arg(long, default_value_t = 0.1)]
    pub f: f64,
    /// Jan's λ (eq 74); default: the paper's fit eq 75 at each row's α.
    #[arg(long)]
    pub lambda: Option<f64>,
    /// Jan's μ (eq 74); default: the paper's fit eq 76 at each row's α.
    #[arg(long)]
    pub mu: Option<f64>,
    /// Jaeger's a1 (eq 83).
    #[arg(long)]
    pub a1: Option<f64>,
    /// Jaeger's a2 (eq 83).
    #[arg(long)]
    pub a2: Option<f64>,
    /// Jaeger's a3 (eq 83).
    #[arg(long)]
    pub a3: Option<f64>,
    /// Jaeger root when there are two: upper (default) or lower.
    #[arg(long, default_value = "upper")]
    pub branch: String,
    /// Spin rule of the collision for --model contact: roll (rolling restarts, the paper's
    /// choice), keep (spin unchanged), factor=L (ω0 = L ωf, eq 63) or impact (no-slip impact
    /// conserving angular momentum about the new contact point; K is then not used). A `spin`
    /// column overrides it per row.
    #[arg(long, default_value = "roll")]
    pub spin: String,
    /// Relative tolerance of the contact model's quadratures (time and spin during slip).
    #[arg(long, default_value_t = 1e-14)]
    pub tol: f64,
}

/// Columns added after [`OUTPUT_COLUMNS`] by --model contact.
pub const CONTACT_COLUMNS: [&str; 10] = [
    "phase_sequence",
    "phase_change_deg",
    "initial_spin",
    "final_spin",
    "beads",
    "collision_translation_frac",
    "collision_spin_frac",
    "friction_work_frac",
    "energy_closure",
    "spin_rule",
];

/// Output columns added to each row.
pub const OUTPUT_COLUMNS: [&str; 12] = [
    "v",
    "regime",
    "status",
    "K_used",
    "final_velocity",
    "initial_velocity",
    "contact_time",
    "theta_G_deg",
    "map_slope",
    "other_fixed_point",
    "phases",
    "message",
];

struct Job {
    scene: Scene,
    model: Model,
}

fn field_column(field: &str) -> &str {
    match field {
        "delta" => "delta_deg",
        other => other,
    }
}

fn scene_error(t: &Table, row: usize, e: Error, cols: &[(&str, Option<usize>)]) -> InputError {
    let field = match &e {
        Error::InvalidParameter { field, .. } => field_column(field).to_string(),
        Error::UnknownLaw(_) => "K".into(),
        Error::UnknownModel(_) => "model".into(),
    };
    match cols.iter().find(|(n, _)| *n == field).and_then(|(_, c)| *c) {
        Some(c) => t.err(row, c, e.to_string()),
        None => InputError {
            file: "<command line>".into(),
            line: None,
            column: Some(format!("--{field}")),
            value: None,
            message: format!("{e} (line {} of {})", t.lines[row], t.source),
        },
    }
}

/// Runs `fitbead forward`.
pub fn run(a: Args) -> Result<(), CliError> {
    let kind: ModelKind = a.model.parse().map_err(|_| {
        super::flag_error(
            "--model",
            &a.model,
            format!("unknown model; expected one of {}", Model::NAMES.join(", ")),
        )
    })?;
    let branch = match a.branch.as_str() {
        "upper" => JaegerBranch::Upper,
        "lower" => JaegerBranch::Lower,
        b => return Err(super::flag_error("--branch", b, "expected upper or lower")),
    };
    let (source, text) = if let (Some(xi), Some(d)) = (a.xi, a.delta_deg) {
        (
            "<command line>".to_string(),
            format!("xi,delta_deg\n{},{}\n", fmt_f64(xi), fmt_f64(d)).into_bytes(),
        )
    } else if a.xi.is_some() || a.delta_deg.is_some() {
        return Err(super::flag_error(
            "--xi/--delta-deg",
            "",
            "a single scene needs both --xi and --delta-deg",
        ));
    } else {
        read_input(a.input.as_deref())?
    };
    let t = Table::parse(&source, &text)?;
    let c_xi = t.require("xi")?;
    let c_d = t.require("delta_deg")?;
    let c_k = t.col("K");
    let c_rho = t.col("rho");
    let c_f = t.col("f");
    let c_lambda = t.col("lambda");
    let c_mu = t.col("mu");
    let c_a = [t.col("a1"), t.col("a2"), t.col("a3")];
    let c_spin = t.col("spin");
    let flag_spin: SpinRule = a
        .spin
        .parse()
        .map_err(|e: Error| super::flag_error("--spin", &a.spin, e.to_string()))?;
    if !(a.tol > 0.0 && a.tol < 1.0) {
        return Err(super::flag_error(
            "--tol",
            &a.tol.to_string(),
            "expected a relative tolerance in (0, 1)",
        ));
    }
    let flag_law: CollisionLaw =
        a.k.parse()
            .map_err(|e: Error| super::flag_error("--K", &a.k, e.to_string()))?;
    let cols = [
        ("xi", Some(c_xi)),
        ("delta_deg", Some(c_d)),
        ("K", c_k),
        ("rho", c_rho),
        ("f", c_f),
        ("lambda", c_lambda),
        ("mu", c_mu),
        ("a1", c_a[0]),
        ("a2", c_a[1]),
        ("a3", c_a[2]),
    ];
    let mut jobs = Vec::with_capacity(t.rows.len());
    for r in 0..t.rows.len() {
        let xi = t.number(r, c_xi)?;
        let d = t.number(r, c_d)?;
        let law = match c_k {
            Some(c) if !t.cell(r, c).is_empty() => t
                .cell(r, c)
                .parse::<CollisionLaw>()
                .map_err(|e| t.err(r, c, e.to_string()))?,
            _ => flag_law,
        };
        if let (CollisionLaw::Value(k), Some(c)) = (law, c_k) {
            if !k.is_finite() {
                return Err(t.err(r, c, "value must be a finite number").into());
            }
        }
        let rho = t.opt_number(r, c_rho)?.unwrap_or(a.rho);
        let f = t.opt_number(r, c_f)?.unwrap_or(a.f);
        let scene = Scene::new(xi, d, rho, f, law).map_err(|e| scene_error(&t, r, e, &cols))?;
        let model = match (kind, kind.contact_model()) {
            (ModelKind::Contact, _) => {
                let spin = match c_spin {
                    Some(c) if !t.cell(r, c).is_empty() => t
                        .cell(r, c)
                        .parse::<SpinRule>()
                        .map_err(|e| t.err(r, c, e.to_string()))?,
                    _ => flag_spin,
                };
                Model::Contact(Contact { spin, tol: a.tol })
            }
            (_, Some(m)) => m,
            (ModelKind::Jan, None) => {
                let paper = Jan::paper_fit(scene.alpha);
                let lambda = t
                    .opt_number(r, c_lambda)?
                    .or(a.lambda)
                    .unwrap_or(paper.lambda);
                let mu = t.opt_number(r, c_mu)?.or(a.mu).unwrap_or(paper.mu);
                Model::Jan(Jan::new(lambda, mu).map_err(|e| scene_error(&t, r, e, &cols))?)
            }
            _ => {
                let mut v = [0.0; 3];
                let flags = [a.a1, a.a2, a.a3];
                for i in 0..3 {
                    v[i] = match t.opt_number(r, c_a[i])?.or(flags[i]) {
                        Some(x) => x,
                        None => {
                            return Err(super::flag_error(
                                &format!("--a{}", i + 1),
                                "",
                                "jaeger needs a1, a2, a3 (flags or columns)",
                            ))
                        }
                    };
                }
                Model::Jaeger(
                    Jaeger::new(v[0], v[1], v[2], branch)
                        .map_err(|e| scene_error(&t, r, e, &cols))?,
                )
            }
        };
        jobs.push(Job { scene, model });
    }
    let (outcomes, details): (Vec<Outcome>, Vec<Option<ContactDetail>>) = jobs
        .par_iter()
        .map(|j| match j.model {
            Model::Contact(c) => {
                let r = c.steady_state(&j.scene);
                (
                    Contact::outcome(&j.scene, &r),
                    Some(ContactDetail {
                        rule: c.spin,
                        steady: r.ok(),
                    }),
                )
            }
            m => (m.evaluate(&j.scene), None),
        })
        .unzip();
    let bytes =
        render(&t, &jobs, &outcomes, &details, kind).map_err(|e| CliError::Other(e.to_string()))?;
    emit(a.output.as_deref(), &bytes)
}

/// What the contact model adds to a row.
struct ContactDetail {
    rule: SpinRule,
    steady: Option<SteadyContact>,
}

fn contact_cells(job: &Job, d: &ContactDetail) -> Vec<String> {
    let Some(s) = &d.steady else {
        let mut v = vec![String::new(); CONTACT_COLUMNS.len() - 1];
        v.push(d.rule.to_string());
        return v;
    };
    let e = s.energy(&job.scene);
    let p = e.potential_drop;
    vec![
        s.run.phases.to_string(),
        s.run.phases.changes_deg(),
        fmt_f64(s.launch.spin),
        fmt_f64(s.final_spin),
        s.beads.to_string(),
        fmt_f64(e.collision_translation / p),
        fmt_f64(e.collision_spin / p),
        fmt_f64(e.friction_work / p),
        fmt_f64(e.closure()),
        d.rule.to_string(),
    ]
}

fn render(
    t: &Table,
    jobs: &[Job],
    outcomes: &[Outcome],
    details: &[Option<ContactDetail>],
    kind: ModelKind,
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::with_capacity(t.rows.len() * 160));
    let general = kind == ModelKind::Contact;
    let mut header: Vec<String> = t
        .headers
        .iter()
        .map(|h| {
            if OUTPUT_COLUMNS.contains(&h.as_str())
                || general && CONTACT_COLUMNS.contains(&h.as_str())
            {
                format!("in_{h}")
            } else {
                h.clone()
            }
        })
        .collect();
    header.extend(OUTPUT_COLUMNS.iter().map(|s| s.to_string()));
    if general {
        header.extend(CONTACT_COLUMNS.iter().map(|s| s.to_string()));
    }
    w.write_record(&header)?;
    let contact = !matches!(kind, ModelKind::Jan | ModelKind::Jaeger);
    let opt = |x: Option<f64>| x.map(fmt_f64).unwrap_or_default();
    for (((rec, job), o), d) in t.rows.iter().zip(jobs).zip(outcomes).zip(details) {
        let mut out: Vec<String> = rec.iter().map(|s| s.to_string()).collect();
        let regime = regime_of(o).map(|r| r.to_string()).unwrap_or_default();
        match o {
            Ok(s) => {
                out.push(fmt_f64(s.mean_velocity));
                out.push(regime);
                out.push("ok".into());
                out.push(if contact {
                    fmt_f64(job.scene.k)
                } else {
                    String::new()
                });
                if contact {
                    out.push(fmt_f64(s.final_velocity));
                    out.push(fmt_f64(s.initial_velocity));
                } else {
                    out.push(String::new());
                    out.push(String::new());
                }
                out.push(fmt_f64(s.contact_time));
                out.push(opt(s.theta_g.map(f64::to_degrees)));
                out.push(opt(s.map_slope));
                out.push(opt(s.other_fixed_point));
                out.push(s.phases.to_string());
                out.push(if s.other_fixed_point.is_some() {
                    if contact {
                        "bistable: another fixed point of the final-velocity map".into()
                    } else {
                        "two positive roots (eq 84): bistable band".into()
                    }
                } else {
                    String::new()
                });
            }
            Err(e) => {
                out.push(String::new());
                out.push(regime);
                out.push(e.status().into());
                out.push(if contact {
                    fmt_f64(job.scene.k)
                } else {
                    String::new()
                });
                for _ in 0..7 {
                    out.push(String::new());
                }
                out.push(e.to_string());
            }
        }
        if let (true, Some(d)) = (general, d) {
            out.extend(contact_cells(job, d));
        }
        w.write_record(&out)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}
