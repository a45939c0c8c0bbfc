//! Scenes tables for the molecular-dynamics model (`fitbead forward --model md`): every row's
//! scene and md settings (each setting a flag's value or the row's cell of the same name,
//! [`MdSetting::column`]), checked as the model needs them, and the table of the runs.
//! Unlike the closed-form models, md runs take seconds each, so the table is read whole and
//! the runs are the caller's to schedule.

use super::plan::{check_scene_cells, scene_error, setting_error};
use crate::io::scenes::Table;
use crate::io::InputError;
use crate::models::md::{Md, MdResult, MdSetting, MdSettings};
use crate::models::Regime;
use crate::numfmt::fmt_f64;
use crate::scene::ParameterError as Error;
use crate::scene::{CollisionLaw, Scene};

/// md output columns added to each row.
pub(crate) const MD_OUTPUT_COLUMNS: [&str; 29] = [
    "v",
    "regime",
    "status",
    "v_stderr",
    "v_m_s",
    "drift",
    "beads_passed",
    "stop_bead",
    "stop_theta_deg",
    "lift_offs_per_bead",
    "lift_off_theta_deg",
    "skipped_fraction",
    "flight_height_max",
    "flight_length_mean",
    "flight_length_max",
    "airborne_fraction",
    "contacts_per_bead",
    "bounces_per_contact",
    "diss_normal",
    "diss_tangential",
    "energy_error",
    "final_velocity",
    "initial_velocity",
    "K_eff",
    "dt",
    "contact_time",
    "steps",
    "step_check_rel",
    "message",
];

/// What every row of a table starts from: the model (a preset with its reduced-mass rule), the
/// settings given as flags, and ρ and f of rows without those cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MdTable {
    /// The preset the settings are laid over.
    pub md: Md,
    /// Settings given for every row (a row's cell wins).
    pub flags: MdSettings,
    /// ρ of rows without a `rho` cell.
    pub rho: f64,
    /// f of rows without an `f` cell (the md model does not use it; it is checked).
    pub f: f64,
}

/// The scene and md model of every row of `t`, or the first bad value: a cell located by line
/// and column, a flag (`--NAME`, [`MdSetting::flag`]) by its value. Every cell of the scene
/// columns is checked, whether md reads it or not (`check_scene_cells`).
pub fn md_jobs(t: &Table, base: &MdTable) -> Result<Vec<(Scene, Md)>, InputError> {
    let c_xi = t.require("xi")?;
    let c_d = t.require("delta_deg")?;
    let c_rho = t.col("rho");
    let cols: Vec<(MdSetting, usize)> = MdSetting::ALL
        .into_iter()
        .filter_map(|s| t.col(s.column()).map(|c| (s, c)))
        .collect();
    let mut jobs: Vec<(Scene, Md)> = Vec::with_capacity(t.rows.len());
    for r in 0..t.rows.len() {
        let xi = t.number(r, c_xi)?;
        let d = t.number(r, c_d)?;
        let rho = t.opt_number(r, c_rho)?.unwrap_or(base.rho);
        // K and f do not enter the md model: a placeholder K keeps Scene's validation quiet.
        let scene = Scene::new(xi, d, rho, base.f, CollisionLaw::Value(0.5)).map_err(|e| {
            scene_error(
                &t.row(r),
                e,
                &[("xi", Some(c_xi)), ("delta_deg", Some(c_d)), ("rho", c_rho)],
            )
        })?;
        let rho_error = |msg: String| match c_rho {
            Some(c) if !t.cell(r, c).is_empty() => t.err(r, c, msg),
            _ => setting_error("rho", &fmt_f64(rho), msg),
        };
        if !(rho > 0.0) {
            return Err(rho_error(
                "md needs rho > 0 (the bead's moment of inertia)".into(),
            ));
        }
        let mut given = base.flags;
        for &(s, c) in &cols {
            if let Some(x) = t.opt_number(r, Some(c))? {
                given.set(s, x);
            }
        }
        let err = |s: MdSetting, msg: String| -> InputError {
            match cols.iter().find(|(x, _)| *x == s) {
                Some(&(_, c)) if !t.cell(r, c).is_empty() => t.err(r, c, msg),
                _ => setting_error(
                    s.flag(),
                    &given.get(s).map(fmt_f64).unwrap_or_default(),
                    msg,
                ),
            }
        };
        let other = |e: &Error| InputError::file(super::plan::SETTINGS_ORIGIN, e.to_string());
        let md = given.apply(base.md).map_err(|(s, e)| match s {
            Some(s) => err(s, e.to_string()),
            None => other(&e),
        })?;
        md.check_scene(&scene).map_err(|e| match &e {
            Error::InvalidParameter { field: "rho", .. } => rho_error(e.to_string()),
            Error::InvalidParameter { field, .. } => match MdSetting::from_column(field) {
                Some(s) => err(s, e.to_string()),
                None => other(&e),
            },
            _ => other(&e),
        })?;
        check_scene_cells(&t.row(r), &|n| t.col(n))?;
        jobs.push((scene, md));
    }
    Ok(jobs)
}

/// The table of md runs: `t`'s columns (an input name that clashes with an output column
/// gets `in_`), then `MD_OUTPUT_COLUMNS` per row, from each row's run and, with a step
/// check, the relative change of v̄ at half the step.
pub fn md_csv(
    t: &Table,
    jobs: &[(Scene, Md)],
    results: &[(MdResult, Option<f64>)],
) -> csv::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::with_capacity(t.rows.len() * 400));
    let mut header =
        crate::io::pass_through_names(t.headers.iter().map(String::as_str), &MD_OUTPUT_COLUMNS);
    header.extend(MD_OUTPUT_COLUMNS.iter().map(|s| s.to_string()));
    w.write_record(&header)?;
    let opt = |x: Option<f64>| x.map(fmt_f64).unwrap_or_default();
    for ((rec, (scene, _)), (r, rel)) in t.rows.iter().zip(jobs).zip(results) {
        let mut out: Vec<String> = rec.iter().map(|s| s.to_string()).collect();
        let o = Md::outcome(scene, r);
        let moving = matches!(r.regime, Some(Regime::B) | Some(Regime::C));
        let deg = |x: Option<f64>| opt(x.map(f64::to_degrees));
        out.push(if moving {
            opt(r.mean_velocity)
        } else {
            String::new()
        });
        out.push(Regime::of(&o).map(|g| g.to_string()).unwrap_or_default());
        out.push(match &o {
            Ok(_) => "ok".into(),
            Err(e) => e.status().into(),
        });
        out.push(if moving { opt(r.stderr) } else { String::new() });
        out.push(if moving {
            opt(r.mean_velocity_si)
        } else {
            String::new()
        });
        out.push(opt(r.drift));
        out.push(r.beads_passed.to_string());
        out.push(r.stop.map(|s| s.bead.to_string()).unwrap_or_default());
        out.push(deg(r.stop.map(|s| s.angle)));
        let measured = r.mean_velocity.is_some();
        let m = |x: f64| if measured { fmt_f64(x) } else { String::new() };
        out.push(m(r.lift_offs_per_bead));
        out.push(deg(r.lift_off_angle));
        out.push(m(r.skipped_fraction));
        out.push(m(r.flight_height_max));
        out.push(opt(r.flight_length_mean));
        out.push(m(r.flight_length_max));
        out.push(m(r.airborne_fraction));
        out.push(m(r.contacts_per_bead));
        out.push(m(r.bounces_per_contact));
        out.push(m(r.dissipation_normal));
        out.push(m(r.dissipation_tangential));
        out.push(fmt_f64(r.energy_error));
        out.push(opt(r.final_velocity));
        out.push(opt(r.initial_velocity));
        out.push(opt(r.k_eff));
        out.push(fmt_f64(r.dt));
        out.push(fmt_f64(r.contact_time));
        out.push(r.steps.to_string());
        out.push(opt(*rel));
        out.push(match &o {
            Ok(_) => String::new(),
            Err(e) => match r.stop {
                Some(s) => format!("{e} (trapped after {} row beads)", s.bead),
                None => e.to_string(),
            },
        });
        w.write_record(&out)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}
