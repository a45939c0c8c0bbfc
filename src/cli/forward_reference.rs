//! The row-at-a-time `forward` path as it was before streaming (whole table in memory, one
//! `Vec<String>` per output row through `csv::Writer`), kept only as the reference the
//! streaming path is tested against: the same bytes for every model and the same errors.

use super::{field_column, Args};
use crate::cli::{flag_error, CliError};
use fitbead::io::{fmt_f64, InputError};
use fitbead::models::auto::{Auto, AutoOutcome};
use fitbead::models::contact::{Contact, SpinRule, SteadyContact};
use fitbead::models::jaeger::Jaeger;
use fitbead::models::jan::Jan;
use fitbead::models::{regime_of, ForwardModel, JaegerBranch, Model, ModelKind, Outcome};
use fitbead::scene::ParameterError as Error;
use fitbead::scene::{CollisionLaw, Scene};
use rayon::prelude::*;

use super::{AUTO_COLUMNS, CONTACT_COLUMNS, OUTPUT_COLUMNS};
pub(super) use table::Table;

/// The table reader as it was (src/io/scenes.rs before streaming).
pub(super) mod table {

    use fitbead::io::InputError;
    use std::collections::HashMap;

    /// A CSV table read into memory: header, rows, line numbers.
    #[derive(Debug, Clone)]
    pub struct Table {
        /// Where it came from (for messages).
        pub source: String,
        /// Column names.
        pub headers: Vec<String>,
        /// Cells, row by row.
        pub rows: Vec<csv::StringRecord>,
        /// 1-based line number of each row.
        pub lines: Vec<u64>,
        index: HashMap<String, usize>,
    }

    impl Table {
        /// Parses CSV text. Fails on an empty input, a ragged row or a header without rows.
        pub fn parse(source: &str, text: &[u8]) -> Result<Table, InputError> {
            if text.iter().all(|b| b.is_ascii_whitespace()) {
                return Err(InputError::file(
                    source,
                    "file is empty: expected a header line",
                ));
            }
            let mut rdr = csv::ReaderBuilder::new()
                .has_headers(true)
                .trim(csv::Trim::All)
                .from_reader(text);
            let headers: Vec<String> = rdr
                .headers()
                .map_err(|e| InputError::file(source, format!("cannot read header: {e}")))?
                .iter()
                .map(|s| s.to_string())
                .collect();
            let mut index = HashMap::new();
            for (i, h) in headers.iter().enumerate() {
                if h.is_empty() {
                    return Err(InputError {
                        file: source.to_string(),
                        line: Some(1),
                        column: Some(format!("#{}", i + 1)),
                        value: Some(String::new()),
                        message: "empty column name".into(),
                    });
                }
                if index.insert(h.clone(), i).is_some() {
                    return Err(InputError::cell(source, 1, h, h, "duplicate column name"));
                }
            }
            let mut rows = Vec::new();
            let mut lines = Vec::new();
            let mut rec = csv::StringRecord::new();
            loop {
                match rdr.read_record(&mut rec) {
                    Ok(true) => {
                        let line = rec.position().map(|p| p.line()).unwrap_or(0);
                        if rec.len() == 1 && rec.get(0) == Some("") {
                            continue; // blank line
                        }
                        rows.push(rec.clone());
                        lines.push(line);
                    }
                    Ok(false) => break,
                    Err(e) => {
                        let line = e.position().map(|p| p.line());
                        return Err(InputError {
                            file: source.to_string(),
                            line,
                            column: None,
                            value: None,
                            message: format!("malformed CSV: {e}"),
                        });
                    }
                }
            }
            if rows.is_empty() {
                return Err(InputError::file(source, "no data rows after the header"));
            }
            Ok(Table {
                source: source.to_string(),
                headers,
                rows,
                lines,
                index,
            })
        }

        /// Index of a column, if present.
        pub fn col(&self, name: &str) -> Option<usize> {
            self.index.get(name).copied()
        }

        /// Index of a required column.
        pub fn require(&self, name: &str) -> Result<usize, InputError> {
            self.col(name).ok_or_else(|| InputError {
                file: self.source.clone(),
                line: Some(1),
                column: Some(name.to_string()),
                value: None,
                message: format!(
                    "missing required column (header has: {})",
                    self.headers.join(",")
                ),
            })
        }

        /// Raw text of a cell.
        pub fn cell(&self, row: usize, col: usize) -> &str {
            self.rows[row].get(col).unwrap_or("")
        }

        /// A finite number from a cell, or an error naming file, line, column and value.
        pub fn number(&self, row: usize, col: usize) -> Result<f64, InputError> {
            let s = self.cell(row, col);
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(_) => Err(self.err(row, col, "value must be a finite number")),
                Err(_) => Err(self.err(row, col, "not a number")),
            }
        }

        /// An optional number: empty cell or absent column gives `None`.
        pub fn opt_number(
            &self,
            row: usize,
            col: Option<usize>,
        ) -> Result<Option<f64>, InputError> {
            match col {
                Some(c) if !self.cell(row, c).is_empty() => self.number(row, c).map(Some),
                _ => Ok(None),
            }
        }

        /// An error at one cell.
        pub fn err(&self, row: usize, col: usize, message: impl Into<String>) -> InputError {
            InputError::cell(
                &self.source,
                self.lines[row],
                &self.headers[col],
                self.cell(row, col),
                message,
            )
        }
    }
}

struct Job {
    scene: Scene,
    model: Model,
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

/// The old `forward` on a parsed table, after the flags --model and --branch were read: the
/// output bytes, or the first error.
pub(super) fn forward_table(
    a: &Args,
    kind: ModelKind,
    branch: JaegerBranch,
    t: &Table,
) -> Result<Vec<u8>, CliError> {
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
        .map_err(|e: Error| flag_error("--spin", &a.spin, e.to_string()))?;
    if !(a.tol > 0.0 && a.tol < 1.0) {
        return Err(flag_error(
            "--tol",
            &a.tol.to_string(),
            "expected a relative tolerance in (0, 1)",
        ));
    }
    let flag_law: CollisionLaw =
        a.k.parse()
            .map_err(|e: Error| flag_error("--K", &a.k, e.to_string()))?;
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
        let scene = Scene::new(xi, d, rho, f, law).map_err(|e| scene_error(t, r, e, &cols))?;
        let model = match (kind, kind.contact_model()) {
            (ModelKind::Auto, _) => Model::Auto(Auto { tol: a.tol }),
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
                let paper = Jan::paper_fit(scene.alpha_rad());
                let lambda = t
                    .opt_number(r, c_lambda)?
                    .or(a.lambda)
                    .unwrap_or(paper.lambda);
                let mu = t.opt_number(r, c_mu)?.or(a.mu).unwrap_or(paper.mu);
                Model::Jan(Jan::new(lambda, mu).map_err(|e| scene_error(t, r, e, &cols))?)
            }
            _ => {
                let mut v = [0.0; 3];
                let flags = [a.a1, a.a2, a.a3];
                for i in 0..3 {
                    v[i] = match t.opt_number(r, c_a[i])?.or(flags[i]) {
                        Some(x) => x,
                        None => {
                            return Err(flag_error(
                                &format!("--a{}", i + 1),
                                "",
                                "jaeger needs a1, a2, a3 (flags or columns)",
                            ))
                        }
                    };
                }
                Model::Jaeger(
                    Jaeger::new(v[0], v[1], v[2], branch)
                        .map_err(|e| scene_error(t, r, e, &cols))?,
                )
            }
        };
        jobs.push(Job { scene, model });
    }
    // The auto choice travels with each outcome
    let evaluated: Vec<(Outcome, Option<ContactDetail>, Option<AutoOutcome>)> = jobs
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
                    None,
                )
            }
            Model::Auto(au) => {
                let r = au.choose(&j.scene);
                (r.outcome, None, Some(r))
            }
            m => (m.evaluate(&j.scene), None, None),
        })
        .collect();
    let mut outcomes = Vec::with_capacity(evaluated.len());
    let mut details = Vec::with_capacity(evaluated.len());
    let mut autos = Vec::with_capacity(evaluated.len());
    for (o, d, au) in evaluated {
        outcomes.push(o);
        details.push(d);
        autos.push(au);
    }
    render(t, &jobs, &outcomes, &details, &autos, kind).map_err(|e| CliError::Other(e.to_string()))
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
    autos: &[Option<AutoOutcome>],
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
    let auto = kind == ModelKind::Auto;
    if auto {
        header.extend(AUTO_COLUMNS.iter().map(|s| s.to_string()));
    }
    w.write_record(&header)?;
    let contact = !matches!(kind, ModelKind::Jan | ModelKind::Jaeger);
    let opt = |x: Option<f64>| x.map(fmt_f64).unwrap_or_default();
    for ((((rec, job), o), d), au) in t
        .rows
        .iter()
        .zip(jobs)
        .zip(outcomes)
        .zip(details)
        .zip(autos)
    {
        let mut out: Vec<String> = rec.iter().map(|s| s.to_string()).collect();
        let regime = regime_of(o).map(|r| r.to_string()).unwrap_or_default();
        match o {
            Ok(s) => {
                out.push(fmt_f64(s.mean_velocity));
                out.push(regime);
                out.push("ok".into());
                out.push(if contact {
                    fmt_f64(job.scene.k())
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
                    fmt_f64(job.scene.k())
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
        if auto {
            match au {
                Some(r) => {
                    out.push(r.choice.name().to_string());
                    out.push(r.reason.to_string());
                }
                None => out.extend([String::new(), String::new()]),
            }
        }
        w.write_record(&out)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}
