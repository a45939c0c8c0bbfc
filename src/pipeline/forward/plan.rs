//! Scenes in, mean velocities out: the rows of a scenes table as typed scenes and models (a
//! column map, `SceneColumns`, and the settings rows fall back on, `ForwardSettings`),
//! evaluated and formatted as `fitbead forward`'s output records by a `ForwardPlan` that
//! `crate::io::stream::stream` runs over a table of any size.
//!
//! Input columns `xi`, `delta_deg` (required), `K` (a number or a law name), `rho`, `f`,
//! `lambda`, `mu` (Jan), `a1`, `a2`, `a3` (Jaeger) and `spin` (contact); an empty cell or an
//! absent column takes the setting. Every input cell passes through (trimmed), an input column
//! whose name is also an output column renamed `in_NAME` (see `pass_through_names`); then the
//! records' columns ([`output_columns`]).
//!
//! Settings are named in messages as the command line's flags (`--rho` of
//! `SETTINGS_ORIGIN`), since that is where they come from.

use crate::io::cells::Cells;
use crate::io::records::{columns, AutoRecord, ContactRecord, ForwardRecord};
use crate::io::scenes::{Row, TableReader};
use crate::io::stream::RowPlan;
use crate::io::InputError;
use crate::models::auto::Auto;
use crate::models::contact::{Contact, SpinRule};
use crate::models::jaeger::Jaeger;
use crate::models::jan::Jan;
use crate::models::{JaegerBranch, Model, ModelKind};
use crate::scene::ParameterError;
use crate::scene::{CollisionLaw, Scene};
use std::io::Read;

/// Every column a scenes table may have: the scene's, `SCENE_CELL_COLUMNS` and md's
/// settings; any other passes through ([`crate::io::scenes::check_columns`]).
pub(crate) fn scene_columns() -> Vec<&'static str> {
    let mut v = vec!["xi", "delta_deg"];
    v.extend(SCENE_CELL_COLUMNS);
    v.extend(crate::models::md::MdSetting::ALL.map(|s| s.column()));
    v.sort_unstable();
    v.dedup();
    v
}

/// The columns `forward` adds after the input's own under a model of `kind`, in order,
/// generated from the records: [`ForwardRecord`]'s (every model), then [`ContactRecord`]'s
/// (the contact model) or [`AutoRecord`]'s (auto).
pub(crate) fn output_columns(kind: ModelKind) -> Vec<&'static str> {
    let mut outputs = columns::<ForwardRecord>();
    if kind == ModelKind::Contact {
        outputs.extend(columns::<ContactRecord>());
    }
    if kind == ModelKind::Auto {
        outputs.extend(columns::<AutoRecord>());
    }
    outputs
}

pub(crate) use crate::io::{setting_error, SETTINGS_ORIGIN};

/// The values rows fall back on where their column is absent or their cell empty, and the
/// model to evaluate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForwardSettings {
    /// The model (every kind but md, which does not stream).
    pub kind: ModelKind,
    /// Collision law of rows without a `K` cell.
    pub law: CollisionLaw,
    /// ρ of rows without a `rho` cell.
    pub rho: f64,
    /// f of rows without an `f` cell.
    pub f: f64,
    /// Jan's λ of rows without a `lambda` cell (else the paper's eq 75 at the row's α).
    pub lambda: Option<f64>,
    /// Jan's μ of rows without a `mu` cell (else the paper's eq 76 at the row's α).
    pub mu: Option<f64>,
    /// Jaeger's a1, a2, a3 of rows without those cells (Jaeger needs all three).
    pub a: [Option<f64>; 3],
    /// Jaeger's root when there are two.
    pub branch: JaegerBranch,
    /// Spin rule of the contact model for rows without a `spin` cell.
    pub spin: SpinRule,
    /// Quadrature tolerance of the contact model; the target tolerance of `auto`.
    pub tol: f64,
}

impl Default for ForwardSettings {
    /// Stick, the adjusted law, ρ = 0.4, f = 0.1, Jan's and Jaeger's settings from the paper
    /// (Jaeger's none), the upper root, rolling restarts, tolerance 1e-14.
    fn default() -> Self {
        ForwardSettings {
            kind: ModelKind::Stick,
            law: CollisionLaw::Adjusted,
            rho: 0.4,
            f: 0.1,
            lambda: None,
            mu: None,
            a: [None; 3],
            branch: JaegerBranch::Upper,
            spin: SpinRule::Roll,
            tol: 1e-14,
        }
    }
}

/// Where the scene columns are in a table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct SceneColumns {
    /// `xi`.
    pub xi: usize,
    /// `delta_deg`.
    pub delta_deg: usize,
    /// `K`.
    pub k: Option<usize>,
    /// `rho`.
    pub rho: Option<usize>,
    /// `f`.
    pub f: Option<usize>,
    /// `lambda`.
    pub lambda: Option<usize>,
    /// `mu`.
    pub mu: Option<usize>,
    /// `a1`, `a2`, `a3`.
    pub a: [Option<usize>; 3],
    /// `spin`.
    pub spin: Option<usize>,
    /// The columns of `SCENE_CELL_COLUMNS` that the table has, with their names, in that
    /// order (checked on every row).
    pub cells: Vec<(&'static str, usize)>,
}

impl SceneColumns {
    /// The columns of `reader`'s header; `xi` and `delta_deg` are required.
    pub fn new<R: Read>(reader: &TableReader<R>) -> Result<Self, InputError> {
        Ok(SceneColumns {
            xi: reader.require("xi")?,
            delta_deg: reader.require("delta_deg")?,
            k: reader.col("K"),
            rho: reader.col("rho"),
            f: reader.col("f"),
            lambda: reader.col("lambda"),
            mu: reader.col("mu"),
            a: [reader.col("a1"), reader.col("a2"), reader.col("a3")],
            spin: reader.col("spin"),
            cells: SCENE_CELL_COLUMNS
                .into_iter()
                .filter_map(|n| reader.col(n).map(|c| (n, c)))
                .collect(),
        })
    }

    /// The scene parameters' columns by name, for locating an error.
    pub fn named(&self) -> [(&'static str, Option<usize>); 10] {
        [
            ("xi", Some(self.xi)),
            ("delta_deg", Some(self.delta_deg)),
            ("K", self.k),
            ("rho", self.rho),
            ("f", self.f),
            ("lambda", self.lambda),
            ("mu", self.mu),
            ("a1", self.a[0]),
            ("a2", self.a[1]),
            ("a3", self.a[2]),
        ]
    }

    /// The scene and model of one row, or the row's first bad value; what depends on ξ alone
    /// is taken from `like` when it has the row's ξ ([`Scene::new_like`]: the same scene to
    /// the last bit).
    pub fn read(
        &self,
        r: &Row<'_>,
        s: &ForwardSettings,
        like: Option<&Scene>,
    ) -> Result<(Scene, Model), InputError> {
        let xi = r.number(self.xi)?;
        let d = r.number(self.delta_deg)?;
        let law = match self.k {
            Some(c) if !r.cell(c).is_empty() => r
                .cell(c)
                .parse::<CollisionLaw>()
                .map_err(|e| r.err(c, e.to_string()))?,
            _ => s.law,
        };
        if let (CollisionLaw::Value(k), Some(c)) = (law, self.k) {
            if !k.is_finite() {
                return Err(r.err(c, "value must be a finite number"));
            }
        }
        let rho = r.opt_number(self.rho)?.unwrap_or(s.rho);
        let f = r.opt_number(self.f)?.unwrap_or(s.f);
        let named = self.named();
        let scene =
            Scene::new_like(like, xi, d, rho, f, law).map_err(|e| scene_error(r, e, &named))?;
        let model = match (s.kind, s.kind.contact_model()) {
            (ModelKind::Auto, _) => Model::Auto(Auto { tol: s.tol }),
            (ModelKind::Contact, _) => {
                let spin = match self.spin {
                    Some(c) if !r.cell(c).is_empty() => r
                        .cell(c)
                        .parse::<SpinRule>()
                        .map_err(|e| r.err(c, e.to_string()))?,
                    _ => s.spin,
                };
                Model::Contact(Contact { spin, tol: s.tol })
            }
            (_, Some(m)) => m,
            (ModelKind::Jan, None) => {
                let paper = Jan::paper_fit(scene.alpha_rad());
                let lambda = r
                    .opt_number(self.lambda)?
                    .or(s.lambda)
                    .unwrap_or(paper.lambda);
                let mu = r.opt_number(self.mu)?.or(s.mu).unwrap_or(paper.mu);
                Model::Jan(Jan::new(lambda, mu).map_err(|e| scene_error(r, e, &named))?)
            }
            _ => {
                let mut v = [0.0; 3];
                for (i, vi) in v.iter_mut().enumerate() {
                    *vi = match r.opt_number(self.a[i])?.or(s.a[i]) {
                        Some(x) => x,
                        None => {
                            return Err(setting_error(
                                &format!("a{}", i + 1),
                                "",
                                "jaeger needs a1, a2, a3 (flags or columns)",
                            ))
                        }
                    };
                }
                Model::Jaeger(
                    Jaeger::new(v[0], v[1], v[2], s.branch)
                        .map_err(|e| scene_error(r, e, &named))?,
                )
            }
        };
        check_cells(r, self.cells.iter().map(|&(n, c)| (n, Some(c))))?;
        Ok((scene, model))
    }
}

/// The scene columns every `forward` row may carry, whatever the model: each present cell of
/// them is checked ([`check_scene_cells`]), used by the model or not.
pub(crate) const SCENE_CELL_COLUMNS: [&str; 23] = [
    "K",
    "rho",
    "f",
    "lambda",
    "mu",
    "a1",
    "a2",
    "a3",
    "spin",
    "row_radius_m",
    "young_pa",
    "poisson",
    "density",
    "beta",
    "gamma_n",
    "gamma_s",
    "mu_c",
    "g",
    "beads",
    "transient",
    "blocks",
    "launch_velocity",
    "step_fraction",
];

/// Checks every non-empty cell of the scene columns of [`SCENE_CELL_COLUMNS`] that the row's
/// table has, as the model that uses it would (K a law name or a number in (0, 1), ρ, f ≥ 0,
/// λ > 0, μ ≥ 0, a1, a2 ≥ 0, a3 > 0, a spin rule, finite md settings, whole counts): a bad
/// cell is an error even when the chosen model does not read it. `col` finds a column.
pub(crate) fn check_scene_cells(
    r: &Row<'_>,
    col: &dyn Fn(&str) -> Option<usize>,
) -> Result<(), InputError> {
    check_cells(r, SCENE_CELL_COLUMNS.into_iter().map(|n| (n, col(n))))
}

/// [`check_scene_cells`] on the given (column name, column) pairs.
fn check_cells(
    r: &Row<'_>,
    cols: impl Iterator<Item = (&'static str, Option<usize>)>,
) -> Result<(), InputError> {
    for (name, c) in cols {
        let Some(c) = c else { continue };
        let cell = r.cell(c);
        if cell.is_empty() {
            continue;
        }
        let bad = |m: &str| Err(r.err(c, m.to_string()));
        match name {
            "K" => match cell.parse::<CollisionLaw>() {
                Err(e) => return Err(r.err(c, e.to_string())),
                Ok(CollisionLaw::Value(k)) if !k.is_finite() => {
                    return bad("value must be a finite number")
                }
                Ok(CollisionLaw::Value(k)) if !(k > 0.0 && k < 1.0) => {
                    return bad("collisional parameter must be in (0, 1)")
                }
                Ok(_) => {}
            },
            "spin" => {
                if let Err(e) = cell.parse::<SpinRule>() {
                    return Err(r.err(c, e.to_string()));
                }
            }
            _ => {
                let x = r.number(c)?;
                let ok = match name {
                    "rho" | "f" | "mu" | "a1" | "a2" | "gamma_n" | "gamma_s" | "mu_c" => x >= 0.0,
                    "lambda" | "a3" | "row_radius_m" | "young_pa" | "density" | "g" => x > 0.0,
                    "beads" | "transient" | "blocks" => x >= 0.0 && x.fract() == 0.0,
                    _ => true,
                };
                if !ok {
                    return bad(match name {
                        "beads" | "transient" | "blocks" => "must be a whole number",
                        "lambda" | "a3" | "row_radius_m" | "young_pa" | "density" | "g" => {
                            "must be > 0"
                        }
                        _ => "must be >= 0",
                    });
                }
            }
        }
    }
    Ok(())
}

fn field_column(field: &str) -> &str {
    match field {
        "delta" => "delta_deg",
        other => other,
    }
}

/// The error of a scene or model that `Scene::new` (or a model's constructor) refused for row
/// `r`: located at the offending cell when its column is among `cols` (name, index), else
/// about the setting it came from.
pub(crate) fn scene_error(
    r: &Row<'_>,
    e: ParameterError,
    cols: &[(&str, Option<usize>)],
) -> InputError {
    let field = match &e {
        ParameterError::InvalidParameter { field, .. } => field_column(field).to_string(),
        ParameterError::UnknownLaw(_) => "K".into(),
        ParameterError::UnknownSpinRule(_) => "spin".into(),
        ParameterError::UnknownModel(_) => "model".into(),
    };
    match cols.iter().find(|(n, _)| *n == field).and_then(|(_, c)| *c) {
        Some(c) => r.err(c, e.to_string()),
        None => InputError {
            file: SETTINGS_ORIGIN.into(),
            line: None,
            column: Some(format!("--{field}")),
            value: None,
            message: format!("{e} (line {} of {})", r.line, r.source),
        },
    }
}

/// `fitbead forward`'s rows as a [`RowPlan`]: each row's scene and model from its cells and
/// the settings, its outcome, and its output record (module docs).
#[derive(Debug, Clone)]
pub(crate) struct ForwardPlan {
    settings: ForwardSettings,
    cols: SceneColumns,
    headers: Vec<String>,
}

/// The settings of a forward run as a command line gives them: the collision law and the spin
/// rule as text (parsed by [`ForwardPlan::from_text`], errors naming `--K` and `--spin`), the
/// rest in `base` (whose `law` and `spin` are replaced).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg(test)]
pub(crate) struct ForwardText<'a> {
    /// The collision law: a number, `cos2a`, `adjusted`, `impact` or `c=VALUE`.
    pub k: &'a str,
    /// The spin rule: `roll`, `keep`, `factor=L` or `impact`.
    pub spin: &'a str,
    /// Everything else.
    pub base: ForwardSettings,
}

impl ForwardPlan {
    #[cfg(test)]
    /// The plan for a table with `reader`'s header and the settings `text`: the columns are
    /// checked first, then `--spin`, `--tol` (in (0, 1)) and `--K`, so that their errors come
    /// in that order.
    pub fn from_text<R: Read>(
        reader: &TableReader<R>,
        text: &ForwardText<'_>,
    ) -> Result<Self, InputError> {
        let cols = SceneColumns::new(reader)?;
        let spin = text
            .spin
            .parse()
            .map_err(|e: ParameterError| setting_error("spin", text.spin, e.to_string()))?;
        check_tol(text.base.tol)?;
        let law = text
            .k
            .parse()
            .map_err(|e: ParameterError| setting_error("K", text.k, e.to_string()))?;
        let settings = ForwardSettings {
            law,
            spin,
            ..text.base
        };
        Ok(ForwardPlan::new(reader, cols, settings))
    }

    /// The plan for a table with `reader`'s header and the settings `settings`: the columns
    /// are checked first, then the tolerance (in (0, 1)).
    pub fn checked<R: Read>(
        reader: &TableReader<R>,
        settings: ForwardSettings,
    ) -> Result<Self, InputError> {
        let cols = SceneColumns::new(reader)?;
        check_tol(settings.tol)?;
        Ok(ForwardPlan::new(reader, cols, settings))
    }

    /// The plan for a table with `reader`'s header and columns `cols`. The kind must not be
    /// md (it has its own, whole-table path).
    pub fn new<R: Read>(
        reader: &TableReader<R>,
        cols: SceneColumns,
        settings: ForwardSettings,
    ) -> Self {
        ForwardPlan {
            settings,
            cols,
            headers: reader.headers().to_vec(),
        }
    }
}

/// Refuses a tolerance outside (0, 1), as the setting `--tol`.
fn check_tol(tol: f64) -> Result<(), InputError> {
    if tol > 0.0 && tol < 1.0 {
        Ok(())
    } else {
        Err(setting_error(
            "tol",
            &tol.to_string(),
            "expected a relative tolerance in (0, 1)",
        ))
    }
}

/// A row ready to evaluate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Job {
    scene: Scene,
    model: Model,
}

impl RowPlan for ForwardPlan {
    type Ready = Job;
    type Ledger = ();
    type Note = ();
    /// The last scene read, whose quantities of ξ alone the next row of the same ξ reuses.
    type Scratch = Option<Scene>;

    fn header(&self, out: &mut Vec<u8>) {
        let mut w = Cells::new(out);
        let outputs = output_columns(self.settings.kind);
        let inputs = self.headers.iter().map(String::as_str);
        for name in crate::io::pass_through_names(inputs, &outputs) {
            w.text(&name);
        }
        for c in outputs {
            w.text(c);
        }
        w.end();
    }

    fn prepare(&self, row: &Row<'_>, last: &mut Option<Scene>) -> Result<Job, InputError> {
        let (scene, model) = self.cols.read(row, &self.settings, last.as_ref())?;
        *last = Some(scene);
        Ok(Job { scene, model })
    }

    fn write(&self, row: &Row<'_>, job: Job, _: &mut Option<Scene>, out: &mut Vec<u8>) {
        let (common, contact, auto) = ForwardRecord::evaluate(&job.scene, &job.model);
        let kind = self.settings.kind;
        let mut w = Cells::new(out);
        for i in 0..row.rec.len() {
            w.text(row.cell(i));
        }
        w.record(&common);
        if let (ModelKind::Contact, Some(c)) = (kind, &contact) {
            w.record(c);
        }
        if kind == ModelKind::Auto {
            w.record(&auto.unwrap_or_default());
        }
        w.end();
    }
}

#[cfg(test)]
mod tests {
    use super::output_columns;
    use crate::models::ModelKind;

    /// The output columns of `forward` as the documentation gives them
    /// (docs/GUIDE.md): a contract users' scripts read, here checked against the columns
    /// generated from the records.
    #[test]
    fn forward_columns_are_the_documented_contract() {
        let common = [
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
        let contact = [
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
        let auto = ["model_used", "reason"];
        assert_eq!(output_columns(ModelKind::Stick), common);
        assert_eq!(output_columns(ModelKind::Jaeger), common);
        assert_eq!(
            output_columns(ModelKind::Contact),
            [&common[..], &contact].concat()
        );
        assert_eq!(
            output_columns(ModelKind::Auto),
            [&common[..], &auto].concat()
        );
    }
}
