//! Molecular dynamics of the bead on the row: Ristow, Riguidel & Bideau's soft-contact
//! simulation (J. Phys. I France 4 (1994) 1161), as the paper describes it in §5.3 (eqs 91–92).
//!
//! # The simulation
//!
//! Plane motion (2-D) of the mobile bead — radius r, mass m, moment of inertia ρ m r² — over
//! an infinite row of fixed, touching beads of radius R whose line is inclined at δ. The row is
//! periodic (bead k has its centre at 2R·k on the row's line): contacts are found from the
//! bead's position when it overlaps a row bead and forgotten when it leaves, so memory does not
//! grow with the run. Forces on the mobile bead at each contact (eq 91), with overlap
//! d = R + r − |centre distance|, unit normal n (row bead → mobile bead) and tangent t:
//!
//! - normal: F_n = max(0, k_n d^β + γ_n m_eff v_approach) — never attractive;
//! - tangential: F_t = −γ_s m_eff v_slip, v_slip = v·t − r ω the slip velocity of the contact
//!   point (the row beads do not spin), optionally capped by Coulomb, |F_t| ≤ μ_c F_n
//!   (Ristow had no cap);
//! - m_eff = m M/(m + M) (eq 92), M the mass of a row bead of the same material (the row beads
//!   are held fixed); [`ReducedMass::Mobile`] uses m_eff = m instead.
//!
//! **Reading of k_n.** The paper quotes k_n = 10⁷ Pa and calls it a Young's modulus. With β =
//! 3/2 the consistent reading, implemented here, is Hertz's law
//! k_n d^β = (4/3) E* R_eff^{2−β} d^β with E = 10⁷ Pa, E* = E/(2(1−ν²)) (two beads of the same
//! material, Poisson ratio ν), R_eff = R r/(R + r) (for β = 3/2 this is (4/3) E* √R_eff d^{3/2}).
//!
//! **Units.** Parameters are SI ([`MdParams`]). The simulation itself runs in the paper's
//! dimensionless units (docs/PHYSICS.md#geometry-and-units): length R + r, time sqrt((R+r)/g), mass
//! m; velocities in the results are in units sqrt(g (R + r)) like every other model's, with the SI
//! value beside.
//!
//! **Integration.** Velocity Verlet, the velocity-dependent forces evaluated at the predicted
//! velocity v + a dt. The step is `step_fraction` (default 1/100) of the Hertz contact time at
//! the impact speed sqrt(g (R+r)) (or of the half period of the loaded contact if shorter),
//! and small enough that the damping rates are resolved (dt · rate ≤ 0.1). The energy balance
//! closes to second order in dt (tests/it/md.rs).
//!
//! **Run.** The bead is launched on the top of a row bead (Θ = 0) rolling at `launch_velocity`,
//! and followed for `beads` row beads; the first `transient` are discarded and the mean velocity
//! v̄ (along the row, units sqrt(g(R+r))) is measured over the rest, with its standard error
//! from `blocks` block averages. Regimes: A when the bead is trapped (its mechanical energy is
//! below the top of the next row bead, so it can never pass it), C when the bead jumps: it
//! flies over at least 5 % of the window's row beads without touching them, or on at least half
//! of them it lifts off a sustained contact (a flight that is not the rebound of an impact,
//! eq 30a's N = 0), or it runs away (less than 90 % of the potential energy released over the
//! window is dissipated: the kinetic energy grows); B otherwise.

use super::{NotSteady, Outcome, Phases, Regime, Steady};
use crate::scene::{CollisionLaw, Scene};
use crate::scene::{ParameterError as Error, ParameterResult as Result};
use nalgebra::Vector2;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, Ordering};

/// How the reduced mass m_eff of eq 92 is formed for a contact with a (fixed) row bead.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReducedMass {
    /// m_eff = m M/(m + M) (eq 92), M the mass of a row bead of the same density: the pair's
    /// reduced mass, though the row bead does not move. At ξ = 1, m_eff = m/2.
    Pair,
    /// m_eff = m: the row beads as infinitely heavy.
    Mobile,
}

/// Material and contact parameters, SI units. [`MdParams::ristow`] is the default set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MdParams {
    /// Radius R of the row beads, m. Ristow's: 0.25 cm (the paper's "0.25 mm" conflicts with
    /// the measured 4–14 cm/s).
    pub row_radius: f64,
    /// Young's modulus E, Pa (Ristow's k_n read as E: 10⁷ Pa).
    pub young: f64,
    /// Poisson ratio ν (0.3, steel).
    pub poisson: f64,
    /// Density of both beads, kg/m³ (7850, steel).
    pub density: f64,
    /// Exponent β of the elastic normal force k_n d^β (1.5, Hertz).
    pub beta: f64,
    /// Normal damping γ_n, s⁻¹ (1000 s⁻¹; the paper quotes e ≈ 0.7).
    pub gamma_n: f64,
    /// Tangential damping γ_s, s⁻¹ (100 s⁻¹).
    pub gamma_s: f64,
    /// Coulomb cap μ_c on the tangential force, |F_t| ≤ μ_c F_n; `None` (Ristow) for no cap.
    pub coulomb: Option<f64>,
    /// Gravity g, m/s².
    pub g: f64,
    /// Reduced mass rule (eq 92).
    pub reduced_mass: ReducedMass,
}

impl Default for MdParams {
    fn default() -> Self {
        Self::ristow()
    }
}

fn invalid(field: &'static str, value: f64, reason: &'static str) -> Error {
    Error::InvalidParameter {
        field,
        value: crate::numfmt::echo_f64(value),
        reason,
    }
}

fn check(field: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<()> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(invalid(field, value, reason))
    }
}

impl MdParams {
    /// Ristow's parameters (§5.3): k_n = 10⁷ read as E (Pa), β = 1.5, γ_n = 1000 s⁻¹,
    /// γ_s = 100 s⁻¹, no Coulomb cap; steel beads (ν = 0.3, 7850 kg/m³) of R = 2.5 mm,
    /// g = 9.81 m/s², m_eff of eq 92.
    pub const fn ristow() -> Self {
        MdParams {
            row_radius: 2.5e-3,
            young: 1e7,
            poisson: 0.3,
            density: 7850.0,
            beta: 1.5,
            gamma_n: 1000.0,
            gamma_s: 100.0,
            coulomb: None,
            g: 9.81,
            reduced_mass: ReducedMass::Pair,
        }
    }

    /// Steel: Ristow's set with E = 2.1·10¹¹ Pa (about 2·10⁴ times his k_n, as the paper
    /// notes), everything else unchanged.
    pub const fn steel() -> Self {
        let mut p = Self::ristow();
        p.young = 2.1e11;
        p
    }

    /// Checks every parameter's domain.
    pub fn validate(&self) -> Result<()> {
        check(
            "row_radius_m",
            self.row_radius,
            self.row_radius > 0.0,
            "must be > 0",
        )?;
        check("young_pa", self.young, self.young > 0.0, "must be > 0")?;
        check(
            "poisson",
            self.poisson,
            self.poisson > -1.0 && self.poisson < 0.5,
            "must be in (-1, 0.5)",
        )?;
        check("density", self.density, self.density > 0.0, "must be > 0")?;
        check(
            "beta",
            self.beta,
            self.beta >= 1.0 && self.beta <= 3.0,
            "must be in [1, 3]",
        )?;
        check("gamma_n", self.gamma_n, self.gamma_n >= 0.0, "must be >= 0")?;
        check("gamma_s", self.gamma_s, self.gamma_s >= 0.0, "must be >= 0")?;
        if let Some(mu) = self.coulomb {
            check("mu_c", mu, mu >= 0.0, "must be >= 0")?;
        }
        check("g", self.g, self.g > 0.0, "must be > 0")?;
        Ok(())
    }

    /// Effective modulus E* = E/(2(1−ν²)) of two beads of the same material, Pa.
    pub fn effective_modulus(&self) -> f64 {
        self.young / (2.0 * (1.0 - self.poisson * self.poisson))
    }

    /// The normal stiffness k_n of eq 91 in N/m^β: (4/3) E* R_eff^{2−β}, R_eff = R r/(R+r)
    /// (Hertz at β = 3/2).
    pub fn stiffness(&self, xi: f64) -> f64 {
        let r_eff = self.row_radius * xi / (1.0 + xi);
        4.0 / 3.0 * self.effective_modulus() * r_eff.powf(2.0 - self.beta)
    }

    /// Mass m of the mobile bead (a sphere of radius ξR), kg.
    pub fn mobile_mass(&self, xi: f64) -> f64 {
        let r = xi * self.row_radius;
        self.density * 4.0 / 3.0 * PI * r * r * r
    }

    /// m_eff/m (eq 92): 1/(1 + ξ³) for [`ReducedMass::Pair`], 1 for [`ReducedMass::Mobile`].
    pub fn reduced_mass_ratio(&self, xi: f64) -> f64 {
        match self.reduced_mass {
            ReducedMass::Pair => 1.0 / (1.0 + xi * xi * xi),
            ReducedMass::Mobile => 1.0,
        }
    }

    /// Length unit R + r, m.
    pub fn length_unit(&self, xi: f64) -> f64 {
        self.row_radius * (1.0 + xi)
    }

    /// Velocity unit sqrt(g (R + r)), m/s.
    pub fn velocity_unit(&self, xi: f64) -> f64 {
        (self.g * self.length_unit(xi)).sqrt()
    }

    /// Time unit sqrt((R + r)/g), s.
    pub fn time_unit(&self, xi: f64) -> f64 {
        (self.length_unit(xi) / self.g).sqrt()
    }

    /// The rolling-limit set used to check the simulation against the rolling model with the impact
    /// law (docs/PHYSICS.md#collision-laws): Young's modulus `young`, everything else as Ristow's,
    /// and the damping scaled with the contact time t_c at sqrt(g(R+r)) so that the normal contact
    /// is over-damped (γ_n m_eff/m = 30/t_c: no rebound, e = 0) and slip dies out within the impact
    /// (γ_s m_eff/m (1 + 1/ρ) = 30/t_c). As `young` → ∞ the impact becomes instantaneous and the
    /// bead rolls without slip.
    pub fn rolling_limit(young: f64, xi: f64, rho: f64) -> Self {
        let mut p = Self::ristow();
        p.young = young;
        let tc = p.contact_time(xi, p.velocity_unit(xi));
        let mu = p.reduced_mass_ratio(xi);
        p.gamma_n = 30.0 / (mu * tc);
        p.gamma_s = 30.0 / (mu * tc * (1.0 + 1.0 / rho));
        p
    }

    /// Coefficient of normal restitution e of a head-on impact at `speed` (m/s) on a row
    /// bead, without gravity: the ratio of rebound to impact speed, integrated with 20,000 steps
    /// per contact time (1 − e is the fraction of the speed the normal damping takes).
    pub fn normal_restitution(&self, xi: f64, speed: f64) -> f64 {
        let m = self.mobile_mass(xi);
        let k = self.stiffness(xi);
        let damp = self.gamma_n * self.reduced_mass_ratio(xi);
        let dt = self.contact_time(xi, speed) / 20_000.0;
        let (mut d, mut v) = (0.0f64, speed);
        for _ in 0..10_000_000 {
            let f = (k / m * d.max(0.0).powf(self.beta) + damp * v).max(0.0);
            let vh = v - 0.5 * f * dt;
            d += vh * dt;
            let f2 = (k / m * d.max(0.0).powf(self.beta) + damp * (vh - 0.5 * f * dt)).max(0.0);
            v = vh - 0.5 * f2 * dt;
            if d <= 0.0 {
                return (-v / speed).max(0.0);
            }
        }
        0.0
    }

    /// Elastic (undamped) contact time of a normal impact at `speed` m/s on a row bead, s:
    /// t_c = 2 (d_max/v) ∫₀¹ du/√(1 − u^{β+1}), d_max = ((β+1) m v²/(2 k_n))^{1/(β+1)}
    /// (2.943 d_max/v for Hertz).
    pub fn contact_time(&self, xi: f64, speed: f64) -> f64 {
        let m = self.mobile_mass(xi);
        let k = self.stiffness(xi);
        let b1 = self.beta + 1.0;
        let dmax = (b1 * m * speed * speed / (2.0 * k)).powf(1.0 / b1);
        2.0 * dmax / speed * impact_integral(self.beta)
    }
}

/// ∫₀¹ du/√(1 − u^{p}) with p = β + 1: √π Γ(1 + 1/p)/Γ(1/2 + 1/p).
fn impact_integral(beta: f64) -> f64 {
    use statrs::function::gamma::ln_gamma;
    let p = beta + 1.0;
    PI.sqrt() * (ln_gamma(1.0 + 1.0 / p) - ln_gamma(0.5 + 1.0 / p)).exp()
}

/// How long to run and how to measure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MdRunConfig {
    /// Row beads travelled in all (400: Ristow's row).
    pub beads: usize,
    /// Row beads discarded as the transient before measuring (100).
    pub transient: usize,
    /// Blocks for the standard error of the mean velocity (10).
    pub blocks: usize,
    /// Launch speed on the top of the first row bead, rolling, units sqrt(g(R+r)) (0.1).
    pub launch_velocity: f64,
    /// Time step as a fraction of the contact time (1/100: halving it then changes v̄ by
    /// less than 1e-3 relative; 1/50 does not quite, at ξ = 1, δ = 11°).
    pub step_fraction: f64,
    /// Give up (status `invalid`) when the run takes longer than this many time units
    /// sqrt((R+r)/g) per row bead on average, or stays this long on one bead (200).
    pub max_time_per_bead: f64,
}

impl Default for MdRunConfig {
    fn default() -> Self {
        MdRunConfig {
            beads: 400,
            transient: 100,
            blocks: 10,
            launch_velocity: 0.1,
            step_fraction: 1.0 / 100.0,
            max_time_per_bead: 200.0,
        }
    }
}

impl MdRunConfig {
    /// Checks the run settings.
    pub fn validate(&self) -> Result<()> {
        let b = self.beads as f64;
        check(
            "beads",
            b,
            self.beads >= 2 && self.beads <= 1_000_000,
            "must be in [2, 1000000]",
        )?;
        check(
            "transient",
            self.transient as f64,
            self.transient < self.beads,
            "must be smaller than beads",
        )?;
        check(
            "blocks",
            self.blocks as f64,
            self.blocks >= 2 && self.blocks <= self.beads - self.transient,
            "must be >= 2 and at most beads - transient",
        )?;
        check(
            "launch_velocity",
            self.launch_velocity,
            self.launch_velocity >= 0.0,
            "must be >= 0",
        )?;
        check(
            "step_fraction",
            self.step_fraction,
            self.step_fraction >= 1e-4 && self.step_fraction <= 0.5,
            "must be in [1e-4, 0.5]",
        )?;
        check(
            "max_time_per_bead",
            self.max_time_per_bead,
            self.max_time_per_bead > 0.0,
            "must be > 0",
        )?;
        Ok(())
    }
}

/// A setting of the md model a caller may give (a flag, a column of a scenes table), named
/// as its column and as the `field` of the [`crate::scene::ParameterError`] that refuses it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum MdSetting {
    /// `row_radius_m`: radius R of the row beads, m.
    RowRadius,
    /// `young_pa`: Young's modulus E, Pa.
    Young,
    /// `poisson`: Poisson ratio.
    Poisson,
    /// `density`: bead density, kg/m³.
    Density,
    /// `beta`: exponent β of the normal force k_n d^β.
    Beta,
    /// `gamma_n`: normal damping, 1/s.
    GammaN,
    /// `gamma_s`: tangential damping, 1/s.
    GammaS,
    /// `mu_c`: Coulomb cap on the tangential force.
    Coulomb,
    /// `g`: gravity, m/s².
    Gravity,
    /// `beads`: row beads travelled (a whole number).
    Beads,
    /// `transient`: row beads discarded as transient (a whole number).
    Transient,
    /// `blocks`: blocks for the standard error of v̄ (a whole number).
    Blocks,
    /// `launch_velocity`: launch speed on the first row bead, units sqrt(g (R + r)).
    LaunchVelocity,
    /// `step_fraction`: time step as a fraction of the contact time.
    StepFraction,
}

impl MdSetting {
    /// Every setting, in the order of the scenes table's documentation.
    pub const ALL: [MdSetting; 14] = [
        MdSetting::RowRadius,
        MdSetting::Young,
        MdSetting::Poisson,
        MdSetting::Density,
        MdSetting::Beta,
        MdSetting::GammaN,
        MdSetting::GammaS,
        MdSetting::Coulomb,
        MdSetting::Gravity,
        MdSetting::Beads,
        MdSetting::Transient,
        MdSetting::Blocks,
        MdSetting::LaunchVelocity,
        MdSetting::StepFraction,
    ];

    /// Its column name (and error field).
    pub fn column(self) -> &'static str {
        match self {
            MdSetting::RowRadius => "row_radius_m",
            MdSetting::Young => "young_pa",
            MdSetting::Poisson => "poisson",
            MdSetting::Density => "density",
            MdSetting::Beta => "beta",
            MdSetting::GammaN => "gamma_n",
            MdSetting::GammaS => "gamma_s",
            MdSetting::Coulomb => "mu_c",
            MdSetting::Gravity => "g",
            MdSetting::Beads => "beads",
            MdSetting::Transient => "transient",
            MdSetting::Blocks => "blocks",
            MdSetting::LaunchVelocity => "launch_velocity",
            MdSetting::StepFraction => "step_fraction",
        }
    }

    /// Its name as a command-line flag, without the leading `--`: the column with `-` for
    /// `_`, except `coulomb` (`mu_c`) and `md-g` (`g`).
    pub fn flag(self) -> &'static str {
        match self {
            MdSetting::RowRadius => "row-radius-m",
            MdSetting::Young => "young-pa",
            MdSetting::Poisson => "poisson",
            MdSetting::Density => "density",
            MdSetting::Beta => "beta",
            MdSetting::GammaN => "gamma-n",
            MdSetting::GammaS => "gamma-s",
            MdSetting::Coulomb => "coulomb",
            MdSetting::Gravity => "md-g",
            MdSetting::Beads => "beads",
            MdSetting::Transient => "transient",
            MdSetting::Blocks => "blocks",
            MdSetting::LaunchVelocity => "launch-velocity",
            MdSetting::StepFraction => "step-fraction",
        }
    }

    /// The setting whose column (or error field) is `name`.
    pub fn from_column(name: &str) -> Option<MdSetting> {
        MdSetting::ALL.into_iter().find(|s| s.column() == name)
    }
}

/// Values given for some md settings, laid over a preset by [`MdSettings::apply_flags`]; a setting
/// left `None` keeps the preset's value. Counts are held as numbers so that a value such as
/// 2.5 can be refused with the setting named.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MdSettings {
    /// Radius R of the row beads, m.
    pub row_radius_m: Option<f64>,
    /// Young's modulus E, Pa.
    pub young_pa: Option<f64>,
    /// Poisson ratio.
    pub poisson: Option<f64>,
    /// Bead density, kg/m³.
    pub density: Option<f64>,
    /// Exponent β of the normal force.
    pub beta: Option<f64>,
    /// Normal damping γ_n, 1/s.
    pub gamma_n: Option<f64>,
    /// Tangential damping γ_s, 1/s.
    pub gamma_s: Option<f64>,
    /// Coulomb cap μ_c on the tangential force.
    pub mu_c: Option<f64>,
    /// Gravity, m/s².
    pub g: Option<f64>,
    /// Row beads travelled.
    pub beads: Option<f64>,
    /// Row beads discarded as transient.
    pub transient: Option<f64>,
    /// Blocks for the standard error of v̄.
    pub blocks: Option<f64>,
    /// Launch speed on the first row bead, units sqrt(g (R + r)).
    pub launch_velocity: Option<f64>,
    /// Time step as a fraction of the contact time.
    pub step_fraction: Option<f64>,
}

impl MdSettings {
    /// The value given for `s`.
    pub(crate) fn get(&self, s: MdSetting) -> Option<f64> {
        *self.slot(s)
    }

    /// Gives `s` the value `x`.
    pub(crate) fn set(&mut self, s: MdSetting, x: f64) {
        *self.slot_mut(s) = Some(x);
    }

    fn slot(&self, s: MdSetting) -> &Option<f64> {
        match s {
            MdSetting::RowRadius => &self.row_radius_m,
            MdSetting::Young => &self.young_pa,
            MdSetting::Poisson => &self.poisson,
            MdSetting::Density => &self.density,
            MdSetting::Beta => &self.beta,
            MdSetting::GammaN => &self.gamma_n,
            MdSetting::GammaS => &self.gamma_s,
            MdSetting::Coulomb => &self.mu_c,
            MdSetting::Gravity => &self.g,
            MdSetting::Beads => &self.beads,
            MdSetting::Transient => &self.transient,
            MdSetting::Blocks => &self.blocks,
            MdSetting::LaunchVelocity => &self.launch_velocity,
            MdSetting::StepFraction => &self.step_fraction,
        }
    }

    fn slot_mut(&mut self, s: MdSetting) -> &mut Option<f64> {
        match s {
            MdSetting::RowRadius => &mut self.row_radius_m,
            MdSetting::Young => &mut self.young_pa,
            MdSetting::Poisson => &mut self.poisson,
            MdSetting::Density => &mut self.density,
            MdSetting::Beta => &mut self.beta,
            MdSetting::GammaN => &mut self.gamma_n,
            MdSetting::GammaS => &mut self.gamma_s,
            MdSetting::Coulomb => &mut self.mu_c,
            MdSetting::Gravity => &mut self.g,
            MdSetting::Beads => &mut self.beads,
            MdSetting::Transient => &mut self.transient,
            MdSetting::Blocks => &mut self.blocks,
            MdSetting::LaunchVelocity => &mut self.launch_velocity,
            MdSetting::StepFraction => &mut self.step_fraction,
        }
    }

    /// `base` with the values given here, validated ([`Md::validate`]); a refusal names the
    /// setting at fault when it is one of these (a count must be a whole number ≤ 1e9).
    pub(crate) fn apply(&self, base: Md) -> std::result::Result<Md, (Option<MdSetting>, Error)> {
        let Md {
            mut params,
            mut config,
        } = base;
        for s in MdSetting::ALL {
            let Some(x) = self.get(s) else { continue };
            let count = || {
                if x.is_finite() && x >= 0.0 && x.fract() == 0.0 && x <= 1e9 {
                    Ok(x as usize)
                } else {
                    Err((
                        Some(s),
                        Error::InvalidParameter {
                            field: s.column(),
                            value: crate::numfmt::echo_f64(x),
                            reason: "must be a whole number",
                        },
                    ))
                }
            };
            match s {
                MdSetting::RowRadius => params.row_radius = x,
                MdSetting::Young => params.young = x,
                MdSetting::Poisson => params.poisson = x,
                MdSetting::Density => params.density = x,
                MdSetting::Beta => params.beta = x,
                MdSetting::GammaN => params.gamma_n = x,
                MdSetting::GammaS => params.gamma_s = x,
                MdSetting::Coulomb => params.coulomb = Some(x),
                MdSetting::Gravity => params.g = x,
                MdSetting::Beads => config.beads = count()?,
                MdSetting::Transient => config.transient = count()?,
                MdSetting::Blocks => config.blocks = count()?,
                MdSetting::LaunchVelocity => config.launch_velocity = x,
                MdSetting::StepFraction => config.step_fraction = x,
            }
        }
        let md = Md { params, config };
        md.validate().map_err(|e| {
            let s = match &e {
                Error::InvalidParameter { field, .. } => MdSetting::from_column(field),
                _ => None,
            };
            (s, e)
        })?;
        Ok(md)
    }
}

/// The molecular-dynamics forward model: parameters and run settings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Md {
    /// Material and contact parameters (SI).
    pub params: MdParams,
    /// Run length and measurement.
    pub config: MdRunConfig,
}

/// Where a trapped bead (regime A) stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MdStop {
    /// Row beads passed before it was trapped.
    pub bead: u64,
    /// Highest angle Θ (radians, on the row bead it could not pass) reached on the last climb.
    pub angle: f64,
    /// Time (units sqrt((R+r)/g)) at which the trap was detected.
    pub time: f64,
}

/// Why a run ended without a measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MdFailure {
    /// The time budget (`max_time_per_bead`) ran out.
    TimeLimit,
    /// The scene is outside the model's domain (ρ = 0: no moment of inertia).
    NoInertia,
    /// The scene or the parameters are outside the model's domain ([`Md::check_scene`]): the
    /// time step would collapse.
    OutsideDomain,
    /// The caller's stop flag was raised.
    Interrupted,
    /// One time step carried the bead past more than a row bead, or its position left the
    /// finite numbers: the step is too long for the speeds reached.
    StepTooLong,
}

/// Smallest gyration parameter ρ the md model accepts. A bead's moment of inertia is ρ m r²
/// with ρ = 2/5 for a homogeneous sphere, 1/2 for a cylinder, 2/3 for a thin shell; ρ → 0 is
/// a point mass, whose spin relaxes at the rate γ_s (1 + 1/ρ) and would need an ever smaller
/// time step.
pub(crate) const MIN_RHO: f64 = 0.01;

/// Largest factor by which the damping rates may shrink the time step below the contact-time
/// step (`step_fraction` × contact time): beyond it the run's cost grows without bound as
/// ρ → 0 or γ → ∞, and the scene is refused ([`Md::check_scene`]).
pub(crate) const MAX_STEP_SHRINK: f64 = 100.0;

/// Most time steps one md run may take. A run gives up after `max_time_per_bead` times
/// (`beads` plus one) time units, so its step bounds its steps: `step_fraction` of the Hertz
/// contact time, which shrinks as (m/k_n)^{1/(β+1)}, as E^{-0.4} and as the bead's mass^{0.4}
/// for β = 3/2. Settings whose bound exceeds this are refused ([`Md::check_scene`]) instead of
/// running for ever. Ristow's set with the default run is bounded by about 1.3·10⁸ steps
/// (3·10¹⁰ for 10⁵ beads), the steel set by about 7·10⁹; a run that moves on takes some 200
/// times fewer steps than its bound.
pub(crate) const MAX_MD_STEPS: f64 = 1e12;

/// Why settings over [`MAX_MD_STEPS`] are refused (the field named is the setting whose
/// default value would lower the bound most).
const TOO_MANY_STEPS: &str = "md: these settings allow a run of more than 1e12 time steps \
    (the step is step_fraction of the Hertz contact time, which shrinks with a stiffer, \
    smaller or lighter bead; the run lasts at most 200 time units per row bead): bring this \
    setting closer to its default";

/// Everything one simulation measures. Velocities in units sqrt(g (R+r)), lengths in units
/// R + r unless named otherwise, times in sqrt((R+r)/g); dissipation as fractions of the
/// potential energy released over the measurement window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MdResult {
    /// Regime A (trapped), B (steady) or C (lift-off); `None` when the run failed.
    pub regime: Option<Regime>,
    /// Why the run failed, if it did.
    pub failure: Option<MdFailure>,
    /// Mean velocity along the row over the window, v̄ = distance/time (eq 10's v̄).
    pub mean_velocity: Option<f64>,
    /// Standard error of v̄ from block averages.
    pub stderr: Option<f64>,
    /// v̄ in m/s.
    pub mean_velocity_si: Option<f64>,
    /// (v̄ of the window's second half − first half)/v̄: a transient not yet over shows here.
    pub drift: Option<f64>,
    /// Row beads passed.
    pub beads_passed: u64,
    /// Where the bead stopped (regime A).
    pub stop: Option<MdStop>,
    /// Lift-off flights (flights that are not the rebound of an impact) per row bead.
    pub lift_offs_per_bead: f64,
    /// Mean angle Θ (radians) on the row bead left at the start of the lift-off flights.
    pub lift_off_angle: Option<f64>,
    /// The bead gains kinetic energy over the window: less than 90 % of the potential energy
    /// released is dissipated (regime C, runaway).
    pub runaway: bool,
    /// Fraction of the window's row beads flown over without a touch.
    pub skipped_fraction: f64,
    /// Mean angle Θ (radians) on the row bead left at the start of the flights that skip a
    /// row bead.
    pub jump_angle: Option<f64>,
    /// Largest gap between the bead and the row in any flight of the window (units R+r).
    pub flight_height_max: f64,
    /// Mean length of the lift-off flights along the row (row-bead spacings 2R).
    pub flight_length_mean: Option<f64>,
    /// Longest flight of the window along the row (row-bead spacings 2R).
    pub flight_length_max: f64,
    /// Fraction of the window's time with no contact at all.
    pub airborne_fraction: f64,
    /// Contact episodes (a contact begins) per row bead passed.
    pub contacts_per_bead: f64,
    /// Contact episodes per row bead touched: 1 without bounces.
    pub bounces_per_contact: f64,
    /// Energy dissipated by the normal damping / potential energy released (window).
    pub dissipation_normal: f64,
    /// Energy dissipated by the tangential force / potential energy released (window).
    pub dissipation_tangential: f64,
    /// max over the run of |E(t) + D(t) − E(0)| / D(end): E kinetic + potential (gravity and
    /// elastic), D dissipated.
    pub energy_error: f64,
    /// Mean speed of the centre when the bead first touches the next row bead.
    pub final_velocity: Option<f64>,
    /// Mean speed of the centre at the end of that impact's compression (old contact gone, no
    /// more approach to the new bead).
    pub initial_velocity: Option<f64>,
    /// Mean ratio of the two: the simulation's own collisional parameter K (eq 1).
    pub k_eff: Option<f64>,
    /// Time step (units sqrt((R+r)/g)).
    pub dt: f64,
    /// Contact time used to choose the step (units sqrt((R+r)/g)).
    pub contact_time: f64,
    /// Steps taken.
    pub steps: u64,
    /// Simulated time.
    pub time: f64,
}

/// Dimensionless constants of one scene.
#[derive(Debug, Clone, Copy)]
struct Nd {
    s: f64,
    rhat: f64,
    rho: f64,
    inv_inertia_r: f64,
    kn: f64,
    beta: f64,
    gn: f64,
    gs: f64,
    mu_c: f64,
    sin_d: f64,
    cos_d: f64,
    /// Gravity per unit m g along (downslope, normal): (sin δ, −cos δ).
    gravity: Vector2<f64>,
    static_overlap: f64,
    tc: f64,
    dt: f64,
}

const MAXC: usize = 8;

#[derive(Debug, Clone, Copy)]
struct Eval {
    /// Acceleration of the centre.
    a: Vector2<f64>,
    aw: f64,
    p_n: f64,
    p_t: f64,
    u_el: f64,
    n: usize,
    idx: [i64; MAXC],
}

impl Nd {
    fn new(p: &MdParams, c: &MdRunConfig, scene: &Scene, dt_scale: f64) -> Nd {
        let xi = scene.xi;
        let l = p.length_unit(xi);
        let m = p.mobile_mass(xi);
        let mu = p.reduced_mass_ratio(xi);
        let tu = p.time_unit(xi);
        let kn = p.stiffness(xi) * l.powf(p.beta) / (m * p.g);
        let gn = p.gamma_n * tu * mu;
        let gs = p.gamma_s * tu * mu;
        let rhat = xi / (1.0 + xi);
        let rho = scene.rho;
        let static_overlap = (1.0 / kn).powf(1.0 / p.beta);
        // Contact time: impact at speed 1 (sqrt(g(R+r))) or the half period of the loaded
        // contact, whichever is shorter.
        let tc_impact = p.contact_time(xi, p.velocity_unit(xi)) / tu;
        let omega_static = (p.beta / static_overlap).sqrt();
        let tc = tc_impact.min(PI / omega_static);
        let rate = gn.max(gs * (1.0 + 1.0 / rho));
        let dt_contact = c.step_fraction * tc;
        let mut dt = dt_contact;
        if rate > 0.0 {
            dt = dt.min(0.1 / rate);
        }
        // The damping may shrink the step by MAX_STEP_SHRINK at most (Md::check_scene refuses
        // the rest): the step never collapses.
        dt = dt.max(dt_contact / MAX_STEP_SHRINK);
        Nd {
            s: 2.0 * scene.sin_alpha,
            rhat,
            rho,
            inv_inertia_r: 1.0 / (rho * rhat),
            kn,
            beta: p.beta,
            gn,
            gs,
            mu_c: p.coulomb.unwrap_or(f64::INFINITY),
            sin_d: scene.sc_delta.s,
            cos_d: scene.sc_delta.c,
            gravity: Vector2::new(scene.sc_delta.s, -scene.sc_delta.c),
            static_overlap,
            tc,
            dt: dt * dt_scale,
        }
    }

    #[inline]
    fn pow_beta(&self, d: f64) -> f64 {
        if self.beta == 1.5 {
            d * d.sqrt()
        } else {
            d.powf(self.beta)
        }
    }

    /// Accelerations (per unit mass, units g), dissipated powers and elastic energy at a
    /// state; the contacts found (absolute row indices, ascending).
    #[inline(always)]
    fn eval(&self, cell: i64, pos: Vector2<f64>, v: Vector2<f64>, w: f64) -> Eval {
        // Accumulated in locals, the result built once at the end.
        let mut acc = self.gravity;
        let (mut aw, mut p_n, mut p_t, mut u_el) = (0.0, 0.0, 0.0, 0.0);
        let mut found = 0;
        let mut idx = [0; MAXC];
        if pos.y >= 1.0 {
            return Eval {
                a: acc,
                aw,
                p_n,
                p_t,
                u_el,
                n: found,
                idx,
            };
        }
        let lo = ((pos.x - 1.0) / self.s).ceil() as i64;
        let hi = ((pos.x + 1.0) / self.s).floor() as i64;
        for k in lo..=hi {
            // From the centre of row bead k to the mobile bead's.
            let d = Vector2::new(pos.x - k as f64 * self.s, pos.y);
            let d2 = d.norm_squared();
            if d2 >= 1.0 {
                continue;
            }
            let dist = d2.sqrt();
            let ov = 1.0 - dist;
            let n = d / dist;
            let t = Vector2::new(-n.y, n.x);
            // Eq 91, normal row: elastic k_n d^β plus damping on the approach velocity,
            // never attractive.
            let vapp = -v.dot(&n);
            let fe = self.kn * self.pow_beta(ov);
            let fnn = (fe + self.gn * vapp).max(0.0);
            // Eq 91, tangential row: viscous on the slip velocity (spins of both beads; the
            // row beads' is zero), optionally capped by Coulomb.
            let slip = v.dot(&t) - self.rhat * w;
            let mut ft = -self.gs * slip;
            let cap = self.mu_c * fnn;
            if ft.abs() > cap {
                ft = cap.copysign(ft);
            }
            acc += n * fnn + t * ft;
            aw -= ft * self.inv_inertia_r;
            p_n += (fnn - fe) * vapp;
            p_t -= ft * slip;
            u_el += fe * ov / (self.beta + 1.0);
            if found < MAXC {
                idx[found] = cell + k;
                found += 1;
            }
        }
        Eval {
            a: acc,
            aw,
            p_n,
            p_t,
            u_el,
            n: found,
            idx,
        }
    }
}

#[derive(Debug, Default, Clone, Copy)]
struct Window {
    episodes: u64,
    distinct: u64,
    lift_offs: u64,
    jumps: u64,
    jump_angle_sum: f64,
    lift_angle_sum: f64,
    lift_len_sum: f64,
    height_max: f64,
    len_max: f64,
    airborne_time: f64,
    vf_sum: f64,
    vi_sum: f64,
    k_sum: f64,
    n_impacts: u64,
}

impl Md {
    /// Ristow's parameters with the default run.
    pub fn ristow() -> Self {
        Md::default()
    }

    /// Checks parameters and run settings.
    pub fn validate(&self) -> Result<()> {
        self.params.validate()?;
        self.config.validate()
    }

    /// Checks that `scene` is inside the model's domain with these parameters: ρ ≥
    /// `MIN_RHO`, and damping rates that shrink the time step by at most a factor
    /// `MAX_STEP_SHRINK` (100) below the contact-time step (the normal rate γ_n m_eff/m and the
    /// spin relaxation rate γ_s m_eff/m (1 + 1/ρ), in units sqrt(g/(R+r)), each times the
    /// step, at most 0.1). The error names the field to change.
    pub fn check_scene(&self, scene: &Scene) -> Result<()> {
        let rho = scene.rho;
        if !(rho >= MIN_RHO) {
            return Err(Error::InvalidParameter {
                field: "rho",
                value: rho.to_string(),
                reason: "md needs rho >= 0.01 (a bead's moment of inertia rho m r^2: 0.4 for a \
                         sphere, 0.5 for a cylinder; as rho -> 0 the spin's relaxation needs an \
                         ever smaller time step)",
            });
        }
        let xi = scene.xi;
        // Each check names the setting that, put back to its default value alone, passes
        // it (the first in the order given), so that the message blames what the user set.
        let blame = |order: &[MdSetting], ok: &dyn Fn(&Md) -> bool, reason: &'static str| {
            let (field, value) = self.culprit(order, ok);
            Err(invalid(field.column(), value, reason))
        };
        let material = [
            MdSetting::Young,
            MdSetting::RowRadius,
            MdSetting::Density,
            MdSetting::Gravity,
            MdSetting::Poisson,
            MdSetting::Beta,
            MdSetting::StepFraction,
        ];
        let contact_ok = |m: &Md| {
            let nd = Nd::new(&m.params, &m.config, scene, 1.0);
            let dt = m.config.step_fraction * nd.tc;
            dt > 0.0 && dt.is_finite() && nd.static_overlap.is_finite()
        };
        if !contact_ok(self) {
            return blame(
                &material,
                &contact_ok,
                "md: the contact time is not a positive number at these parameters",
            );
        }
        // Gravity must not press the bead into the row by a sizeable part of its radius: the
        // Hertz contact would no longer hold it up, and the run would sink or race through
        // the row.
        let overlap_ok = |m: &Md| Nd::new(&m.params, &m.config, scene, 1.0).static_overlap < 0.5;
        if !overlap_ok(self) {
            return blame(
                &material,
                &overlap_ok,
                "md: under its own weight the bead would sink into the row by half of R + r or \
                 more (the contact is too soft for the gravity, the beads' size and density): \
                 bring this setting closer to its default",
            );
        }
        let damping = |m: &Md| {
            let p = &m.params;
            let nd = Nd::new(p, &m.config, scene, 1.0);
            let dt_contact = m.config.step_fraction * nd.tc;
            let tu = p.time_unit(xi);
            let mu = p.reduced_mass_ratio(xi);
            (
                p.gamma_n * tu * mu * dt_contact,
                p.gamma_s * tu * mu * dt_contact,
            )
        };
        let normal_ok = |m: &Md| damping(m).0 <= 0.1 * MAX_STEP_SHRINK;
        if !normal_ok(self) {
            let mut order = vec![MdSetting::GammaN];
            order.extend(material);
            return blame(
                &order,
                &normal_ok,
                "md: the normal damping is so fast that it needs a time step over 100 times \
                 smaller than the contact time's: lower gamma_n",
            );
        }
        let spin_ok = |m: &Md| damping(m).1 * (1.0 + 1.0 / rho) <= 0.1 * MAX_STEP_SHRINK;
        if !spin_ok(self) {
            let mut order = vec![MdSetting::GammaS];
            order.extend(material);
            return blame(
                &order,
                &spin_ok,
                "md: the spin relaxation rate gamma_s (1 + 1/rho) is so fast that it needs a \
                 time step over 100 times smaller than the contact time's: lower gamma_s or \
                 raise rho",
            );
        }
        // The launch must not carry the bead past a row bead in one step.
        let launch_ok = |m: &Md| {
            let nd = Nd::new(&m.params, &m.config, scene, 1.0);
            m.config.launch_velocity * nd.dt <= 0.1 * nd.s
        };
        if !launch_ok(self) {
            let mut order = vec![MdSetting::LaunchVelocity];
            order.extend(material);
            return blame(
                &order,
                &launch_ok,
                "md: the launch speed would carry the bead over more than a tenth of a row \
                 bead in one time step: lower launch_velocity",
            );
        }
        if !(self.step_bound(scene) <= MAX_MD_STEPS) {
            let (field, value) = self.costliest_setting(scene);
            return Err(invalid(field.column(), value, TOO_MANY_STEPS));
        }
        Ok(())
    }

    /// Most time steps a run of `scene` may take (`MAX_MD_STEPS`): its longest simulated
    /// time, `max_time_per_bead` × (`beads` + 1), over the step.
    pub fn step_bound(&self, scene: &Scene) -> f64 {
        let nd = Nd::new(&self.params, &self.config, scene, 1.0);
        self.config.max_time_per_bead * (self.config.beads as f64 + 1.0) / nd.dt
    }

    /// These settings with `s` put back to its value in [`Md::default`].
    fn with_default(&self, s: MdSetting) -> Md {
        let (d, mut m) = (Md::default(), *self);
        match s {
            MdSetting::RowRadius => m.params.row_radius = d.params.row_radius,
            MdSetting::Young => m.params.young = d.params.young,
            MdSetting::Poisson => m.params.poisson = d.params.poisson,
            MdSetting::Density => m.params.density = d.params.density,
            MdSetting::Beta => m.params.beta = d.params.beta,
            MdSetting::GammaN => m.params.gamma_n = d.params.gamma_n,
            MdSetting::GammaS => m.params.gamma_s = d.params.gamma_s,
            MdSetting::Coulomb => m.params.coulomb = d.params.coulomb,
            MdSetting::Gravity => m.params.g = d.params.g,
            MdSetting::Beads => m.config.beads = d.config.beads,
            MdSetting::Transient => m.config.transient = d.config.transient,
            MdSetting::Blocks => m.config.blocks = d.config.blocks,
            MdSetting::LaunchVelocity => m.config.launch_velocity = d.config.launch_velocity,
            MdSetting::StepFraction => m.config.step_fraction = d.config.step_fraction,
        }
        m
    }

    /// The value of setting `s` here.
    fn value_of(&self, s: MdSetting) -> f64 {
        let (p, c) = (&self.params, &self.config);
        match s {
            MdSetting::RowRadius => p.row_radius,
            MdSetting::Young => p.young,
            MdSetting::Poisson => p.poisson,
            MdSetting::Density => p.density,
            MdSetting::Beta => p.beta,
            MdSetting::GammaN => p.gamma_n,
            MdSetting::GammaS => p.gamma_s,
            MdSetting::Coulomb => p.coulomb.unwrap_or(f64::INFINITY),
            MdSetting::Gravity => p.g,
            MdSetting::Beads => c.beads as f64,
            MdSetting::Transient => c.transient as f64,
            MdSetting::Blocks => c.blocks as f64,
            MdSetting::LaunchVelocity => c.launch_velocity,
            MdSetting::StepFraction => c.step_fraction,
        }
    }

    /// The first setting of `order` that, put back to its value in [`Md::default`] alone,
    /// makes `ok` hold, with its value here; else the first of `order` that differs from its
    /// default (else the first of `order`).
    fn culprit(&self, order: &[MdSetting], ok: &dyn Fn(&Md) -> bool) -> (MdSetting, f64) {
        let d = Md::default();
        let first = order.first().copied().unwrap_or(MdSetting::Young);
        let s = order
            .iter()
            .copied()
            .find(|&s| ok(&self.with_default(s)))
            .or_else(|| {
                order
                    .iter()
                    .copied()
                    .find(|&s| self.value_of(s).to_bits() != d.value_of(s).to_bits())
            })
            .unwrap_or(first);
        (s, self.value_of(s))
    }

    /// The setting that, put back to its value in [`Md::default`], lowers
    /// [`Md::step_bound`] most, with its value here.
    fn costliest_setting(&self, scene: &Scene) -> (MdSetting, f64) {
        let candidates = [
            MdSetting::Young,
            MdSetting::Density,
            MdSetting::RowRadius,
            MdSetting::Gravity,
            MdSetting::Poisson,
            MdSetting::Beta,
            MdSetting::StepFraction,
            MdSetting::Beads,
        ];
        let bound_without = |s: MdSetting| {
            let b = self.with_default(s).step_bound(scene);
            if b.is_nan() {
                f64::INFINITY
            } else {
                b
            }
        };
        let s = candidates
            .into_iter()
            .map(|s| (bound_without(s), s))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(MdSetting::Young, |(_, s)| s);
        (s, self.value_of(s))
    }

    /// Simulates one scene (ξ, δ, ρ; K and f of the scene are not used). `dt_scale`
    /// multiplies the automatic step (1 normally; ½ for the step check). `progress` is called
    /// with 1 each time the bead passes a row bead. A scene outside the domain of
    /// [`Md::check_scene`] fails at once ([`MdFailure::OutsideDomain`]).
    pub fn simulate(
        &self,
        scene: &Scene,
        dt_scale: f64,
        progress: Option<&(dyn Fn(u64) + Sync)>,
    ) -> MdResult {
        self.simulate_until(scene, dt_scale, progress, None)
    }

    /// As [`Md::simulate`], stopping early ([`MdFailure::Interrupted`]) once `stop` is
    /// raised; the flag is polled every few thousand steps (well under a millisecond apart).
    pub fn simulate_until(
        &self,
        scene: &Scene,
        dt_scale: f64,
        progress: Option<&(dyn Fn(u64) + Sync)>,
        stop: Option<&AtomicBool>,
    ) -> MdResult {
        let nd = Nd::new(&self.params, &self.config, scene, dt_scale);
        let mut res = MdResult {
            regime: None,
            failure: None,
            mean_velocity: None,
            stderr: None,
            mean_velocity_si: None,
            drift: None,
            beads_passed: 0,
            stop: None,
            lift_offs_per_bead: 0.0,
            lift_off_angle: None,
            runaway: false,
            skipped_fraction: 0.0,
            jump_angle: None,
            flight_height_max: 0.0,
            flight_length_mean: None,
            flight_length_max: 0.0,
            airborne_fraction: 0.0,
            contacts_per_bead: 0.0,
            bounces_per_contact: 0.0,
            dissipation_normal: 0.0,
            dissipation_tangential: 0.0,
            energy_error: 0.0,
            final_velocity: None,
            initial_velocity: None,
            k_eff: None,
            dt: nd.dt,
            contact_time: nd.tc,
            steps: 0,
            time: 0.0,
        };
        if !(scene.rho > 0.0) {
            res.failure = Some(MdFailure::NoInertia);
            return res;
        }
        if self.check_scene(scene).is_err() {
            res.failure = Some(MdFailure::OutsideDomain);
            return res;
        }
        run(&nd, &self.config, scene, &mut res, progress, stop);
        if let Some(v) = res.mean_velocity {
            res.mean_velocity_si = Some(v * self.params.velocity_unit(scene.xi));
        }
        res
    }

    /// Runs at the automatic step and at half of it; returns the first run and the relative
    /// change of v̄, |v̄(dt/2) − v̄(dt)|/v̄(dt) (`None` unless both runs measured a velocity).
    pub fn simulate_checked(&self, scene: &Scene) -> (MdResult, Option<f64>) {
        let (a, b) = rayon::join(
            || self.simulate(scene, 1.0, None),
            || self.simulate(scene, 0.5, None),
        );
        let rel = match (a.mean_velocity, b.mean_velocity) {
            (Some(x), Some(y)) => Some(((y - x) / x).abs()),
            _ => None,
        };
        (a, rel)
    }

    /// Maps a result to the common [`Outcome`]: B → [`Steady`] (mean, final and initial
    /// velocities, time per row bead τ = 2 sin α/v̄, eq 10), A → `Stops`, C → `LiftOff`,
    /// failures → `Invalid`.
    pub fn outcome(scene: &Scene, r: &MdResult) -> Outcome {
        match (r.regime, r.failure) {
            (_, Some(MdFailure::NoInertia)) => Err(NotSteady::Invalid {
                reason: "md needs rho > 0 (the bead's moment of inertia)",
            }),
            (_, Some(MdFailure::TimeLimit)) => Err(NotSteady::Invalid {
                reason: "md: time limit reached before the run's length",
            }),
            (_, Some(MdFailure::OutsideDomain)) => Err(NotSteady::Invalid {
                reason: "md: outside the model's domain (rho >= 0.01; damping rates that keep \
                         the time step within 100 times the contact time's)",
            }),
            (_, Some(MdFailure::Interrupted)) => Err(NotSteady::Invalid {
                reason: "md: interrupted",
            }),
            (_, Some(MdFailure::StepTooLong)) => Err(NotSteady::Invalid {
                reason: "md: one time step carried the bead past more than a row bead (the \
                         speeds reached outrun the step; lower step_fraction)",
            }),
            (Some(Regime::A), _) => Err(NotSteady::Stops {
                angle: r.stop.map(|s| s.angle).unwrap_or(scene.theta_0),
            }),
            (Some(Regime::C), _) => match r.lift_off_angle.or(r.jump_angle) {
                Some(angle) => Err(NotSteady::LiftOff { angle }),
                None => Err(NotSteady::Runaway),
            },
            (Some(Regime::B), _) => match r.mean_velocity {
                Some(v) if v > 0.0 => {
                    let mut s = Steady::basic(
                        v,
                        r.final_velocity.unwrap_or(v),
                        r.initial_velocity.unwrap_or(v),
                        2.0 * scene.sin_alpha / v,
                    );
                    s.phases = Phases::None;
                    Ok(s)
                }
                _ => Err(NotSteady::Invalid {
                    reason: "md: no mean velocity measured",
                }),
            },
            (None, None) => Err(NotSteady::Invalid {
                reason: "md: run ended without a regime",
            }),
        }
    }
}

impl super::ForwardModel for Md {
    fn name(&self) -> &'static str {
        "md"
    }

    fn evaluate(&self, scene: &Scene) -> Outcome {
        if self.validate().is_err() {
            return Err(NotSteady::Invalid {
                reason: "md: invalid parameters",
            });
        }
        let r = self.simulate(scene, 1.0, None);
        Md::outcome(scene, &r)
    }
}

/// Mechanical energy per unit m g (R+r): kinetic (translation and spin) + gravity + elastic.
#[inline]
fn energy(nd: &Nd, xabs: f64, y: f64, v: Vector2<f64>, w: f64, u_el: f64) -> f64 {
    0.5 * v.norm_squared()
        + 0.5 * nd.rho * nd.rhat * nd.rhat * w * w
        + (-nd.sin_d * xabs + nd.cos_d * y)
        + u_el
}

/// Steps between two looks at the stop flag.
const STOP_POLL: u64 = 4096;

/// One md run from the launch to the end of the measurement window (or a trap, a time
/// limit or the stop flag), in two stages: the integration, then the measurement over the
/// window; `res` receives both.
fn run(
    nd: &Nd,
    c: &MdRunConfig,
    scene: &Scene,
    res: &mut MdResult,
    progress: Option<&(dyn Fn(u64) + Sync)>,
    stop: Option<&AtomicBool>,
) {
    let it = integrate(nd, c, scene, res, progress, stop);
    res.time = it.t;
    res.energy_error = if it.d_n + it.d_t > 0.0 {
        it.err_max / (it.d_n + it.d_t)
    } else {
        it.err_max
    };
    if res.regime.is_some() || res.failure.is_some() {
        return;
    }
    measure(nd, c, res, &it);
}

/// Where the integration of an md run ended, and what it recorded for the measurement.
struct Integrated {
    /// Time reached.
    t: f64,
    /// Absolute x of the centre reached.
    xabs: f64,
    /// Energy dissipated by normal damping.
    d_n: f64,
    /// Energy dissipated by tangential friction and damping.
    d_t: f64,
    /// Largest energy-balance error.
    err_max: f64,
    /// Crossing times of X = k s.
    crossings: Vec<f64>,
    /// (X, D_n, D_t) where the measurement window began, if it did.
    win_start: Option<(f64, f64, f64)>,
    /// The counts over the window.
    win: Window,
}

/// The contact and flight bookkeeping of an md run: the row beads touched, the impact
/// awaiting its speed after the first touch, the flight under way, and the counts over the
/// measurement window.
struct Bookkeeping {
    /// Row spacing.
    s: f64,
    /// Slope.
    delta: f64,
    /// Time step.
    dt: f64,
    /// How long a contact lasts before leaving it counts as a lift-off.
    sustained: f64,
    max_touched: i64,
    last_contact_start: f64,
    last_lost: i64,
    /// (new bead, speed at first touch).
    pending: Option<(i64, f64)>,
    in_flight: bool,
    flight_x0: f64,
    flight_liftoff: bool,
    flight_angle: f64,
    flight_hmax: f64,
    /// The counts over the window.
    win: Window,
}

impl Bookkeeping {
    /// The bookkeeping at the launch, with the contacts `e` at the centre's absolute x `xabs`.
    fn new(nd: &Nd, delta: f64, e: &Eval, xabs: f64) -> Self {
        let mut max_touched: i64 = -1;
        for &k in &e.idx[..e.n] {
            max_touched = max_touched.max(k);
        }
        Bookkeeping {
            s: nd.s,
            delta,
            dt: nd.dt,
            sustained: 5.0 * nd.tc,
            max_touched,
            last_contact_start: -f64::INFINITY,
            last_lost: 0,
            pending: None,
            in_flight: e.n == 0,
            flight_x0: xabs,
            flight_liftoff: false,
            flight_angle: 0.0,
            flight_hmax: 0.0,
            win: Window::default(),
        }
    }

    /// Contacts that began and ended in the step from `e` to `en` (at time `t`, velocity
    /// `v`); whether the bead jumped a row bead onto a new one.
    #[inline]
    fn contacts(&mut self, e: &Eval, en: &Eval, t: f64, v: Vector2<f64>, in_window: bool) -> bool {
        let win = &mut self.win;
        let mut jumped = false;
        if en.n > 0 || e.n > 0 {
            for &k in &en.idx[..en.n] {
                if !e.idx[..e.n].contains(&k) {
                    self.last_contact_start = t;
                    if in_window {
                        win.episodes += 1;
                    }
                    if k > self.max_touched {
                        if in_window {
                            win.distinct += 1;
                            jumped = k > self.max_touched + 1;
                        }
                        self.max_touched = k;
                        self.pending = Some((k, v.norm()));
                    }
                }
            }
            for &k in &e.idx[..e.n] {
                if !en.idx[..en.n].contains(&k) {
                    self.last_lost = k;
                }
            }
        }
        jumped
    }

    /// The impact on a new row bead, once the bead stops approaching it: its speeds before
    /// and after.
    #[inline]
    fn rebound(
        &mut self,
        en: &Eval,
        xabs: f64,
        pos: Vector2<f64>,
        v: Vector2<f64>,
        in_window: bool,
    ) {
        let (s, win) = (self.s, &mut self.win);
        if let Some((k, vf)) = self.pending {
            let old = en.idx[..en.n].iter().any(|&j| j < k);
            let vapp = -v.dot(&Vector2::new(xabs - k as f64 * s, pos.y));
            if !old && vapp <= 0.0 {
                if in_window && vf > 0.0 {
                    let vi = v.norm();
                    win.vf_sum += vf;
                    win.vi_sum += vi;
                    win.k_sum += vi / vf;
                    win.n_impacts += 1;
                }
                self.pending = None;
            }
        }
    }

    /// Flights: one begins when the last contact ends, and ends (counted as a jump, a
    /// lift-off or neither) at the next contact.
    #[inline]
    fn flight(
        &mut self,
        en: &Eval,
        t: f64,
        xabs: f64,
        pos: Vector2<f64>,
        jumped: bool,
        in_window: bool,
    ) {
        let (s, delta, dt) = (self.s, self.delta, self.dt);
        let win = &mut self.win;
        if en.n == 0 {
            if !self.in_flight {
                self.in_flight = true;
                self.flight_x0 = xabs;
                self.flight_hmax = 0.0;
                let dx = xabs - self.last_lost as f64 * s;
                self.flight_angle = dx.atan2(pos.y) + delta;
                // Lift-off (eq 30a): leaving a sustained contact in the second half of its arc
                // (Θ > (Θ0 + Θf)/2 = δ); a rebound leaves soon after an impact, near Θ0.
                self.flight_liftoff =
                    t - self.last_contact_start > self.sustained && self.flight_angle > delta;
            }
            let d0 = pos.norm();
            let d1 = Vector2::new(pos.x - s, pos.y).norm();
            self.flight_hmax = self.flight_hmax.max(d0.min(d1) - 1.0);
            if in_window {
                win.airborne_time += dt;
            }
        } else if self.in_flight {
            self.in_flight = false;
            if in_window {
                let len = (xabs - self.flight_x0) / s;
                win.height_max = win.height_max.max(self.flight_hmax);
                win.len_max = win.len_max.max(len);
                if jumped {
                    win.jumps += 1;
                    win.jump_angle_sum += self.flight_angle;
                }
                if self.flight_liftoff {
                    win.lift_offs += 1;
                    win.lift_angle_sum += self.flight_angle;
                    win.lift_len_sum += len;
                }
            }
        }
    }
}

/// Brings the centre's x back into its row bead's cell [0, `s`) after a step, moving `cell`
/// along. A step that carried the bead past more than a row bead (or out of the numbers) is
/// beyond the integration: `false`, and the run ends there instead of walking the cells one
/// by one.
#[inline]
fn advance_cell(pos: &mut Vector2<f64>, cell: &mut i64, s: f64) -> bool {
    if !(pos.x.abs() < 2.0 * s && pos.y.is_finite()) {
        return false;
    }
    while pos.x >= s {
        pos.x -= s;
        *cell += 1;
    }
    while pos.x < 0.0 {
        pos.x += s;
        *cell -= 1;
    }
    true
}

/// The launch of an md run: on the top of row bead 0 (φ = −δ from the row's normal, Θ = 0),
/// sunk by the static overlap, rolling downslope at the speed `v0`. The centre's abscissa,
/// its row bead, its position relative to that bead (x in [0, s)), its velocity and its spin.
fn launch(nd: &Nd, v0: f64, delta: f64) -> (f64, i64, Vector2<f64>, Vector2<f64>, f64) {
    let s = nd.s;
    let phi = -delta;
    let rad = 1.0 - nd.static_overlap;
    let xabs = rad * phi.sin();
    let cell = (xabs / s).floor() as i64;
    let pos = Vector2::new(xabs - cell as f64 * s, rad * phi.cos());
    let v = Vector2::new(v0 * phi.cos(), -v0 * phi.sin());
    (xabs, cell, pos, v, -v0 / nd.rhat)
}

/// The trap test of an md run (regime A): only below δ = α is there a top to stop at.
struct Trap {
    /// Whether the slope has tops the bead can stop below (δ < α, and the margin smaller
    /// than their depth).
    possible: bool,
    /// The energy margin below a top that counts as trapped.
    margin: f64,
    /// δ, rad.
    delta: f64,
    /// Row-bead spacing.
    s: f64,
    /// The highest position upslope of the next top since the last crossing (x; −∞ after a
    /// crossing), and its height.
    climb_x: f64,
    climb_y: f64,
}

impl Trap {
    fn new(nd: &Nd, delta: f64, alpha: f64) -> Self {
        let depth = 1.0 - (delta - alpha).cos();
        let margin = 0.05 * depth + 2.0 * nd.static_overlap;
        Trap {
            possible: delta < alpha && margin < depth,
            margin,
            delta,
            s: nd.s,
            climb_x: f64::NEG_INFINITY,
            climb_y: 1.0,
        }
    }

    /// The stop angle when the energy `etot` is below the top of row bead `cell` + 1 while
    /// the bead (at `xabs`, height `y`) is still upslope of that top.
    fn trapped(&mut self, nd: &Nd, cell: i64, xabs: f64, y: f64, etot: f64) -> Option<f64> {
        if !self.possible {
            return None;
        }
        let s = self.s;
        let k1 = (cell + 1) as f64;
        let x_top = k1 * s - nd.sin_d;
        if xabs >= x_top {
            return None;
        }
        if xabs > self.climb_x {
            self.climb_x = xabs;
            self.climb_y = y;
        }
        let v_top = 1.0 - nd.sin_d * s * k1;
        (etot < v_top - self.margin)
            .then(|| (self.climb_x - k1 * s).atan2(self.climb_y) + self.delta)
    }
}

/// Integrates an md run by velocity Verlet from the launch until the bead has crossed the
/// last row bead of the window, is trapped (regime A, recorded in `res`), runs past the
/// time limit or sees the stop flag (recorded in `res.failure`).
fn integrate(
    nd: &Nd,
    c: &MdRunConfig,
    scene: &Scene,
    res: &mut MdResult,
    progress: Option<&(dyn Fn(u64) + Sync)>,
    stop: Option<&AtomicBool>,
) -> Integrated {
    let s = nd.s;
    let dt = nd.dt;
    let alpha = scene.alpha;
    let delta = scene.delta;
    // The centre relative to row bead `cell` (x in [0, s)), its velocity and its spin.
    let (mut xabs, mut cell, mut pos, mut v, mut w) = launch(nd, c.launch_velocity, delta);
    let mut t = 0.0;
    let mut e = nd.eval(cell, pos, v, w);
    let e0 = energy(nd, xabs, pos.y, v, w, e.u_el);
    let (mut d_n, mut d_t) = (0.0, 0.0);
    let mut err_max: f64 = 0.0;

    // Crossing times of X = k s, k = 0..=beads.
    let nb = c.beads;
    let mut crossings: Vec<f64> = Vec::with_capacity(nb + 1);
    let mut next_cross: i64 = 0; // next row index whose crossing is awaited
    let mut win_start: Option<(f64, f64, f64)> = None; // (X, D_n, D_t)

    // Contact bookkeeping.
    let mut book = Bookkeeping::new(nd, delta, &e, xabs);

    let mut trap = Trap::new(nd, delta, alpha);
    let mut last_progress_t = 0.0;
    let t_max = c.max_time_per_bead * (nb as f64 + 1.0);

    loop {
        // Velocity Verlet, damping at the predicted velocity.
        let (x_old, cell_old) = (pos.x, cell);
        let h = v + e.a * (0.5 * dt);
        let hw = w + 0.5 * dt * e.aw;
        pos += h * dt;
        if !advance_cell(&mut pos, &mut cell, s) {
            res.failure = Some(MdFailure::StepTooLong);
            break;
        }
        let pv = h + e.a * (0.5 * dt);
        let pw = hw + 0.5 * dt * e.aw;
        let en = nd.eval(cell, pos, pv, pw);
        v = h + en.a * (0.5 * dt);
        w = hw + 0.5 * dt * en.aw;
        d_n += 0.5 * dt * (e.p_n + en.p_n);
        d_t += 0.5 * dt * (e.p_t + en.p_t);
        t += dt;
        res.steps += 1;
        xabs = cell as f64 * s + pos.x;
        let etot = energy(nd, xabs, pos.y, v, w, en.u_el);
        err_max = err_max.max((etot + d_n + d_t - e0).abs());
        let in_window = win_start.is_some();

        // Contacts that began and ended in this step, impacts and flights.
        let jumped = book.contacts(&e, &en, t, v, in_window);
        book.rebound(&en, xabs, pos, v, in_window);
        book.flight(&en, t, xabs, pos, jumped, in_window);

        // Crossings of row-bead centres.
        if cell > cell_old && cell >= next_cross {
            // Crossed X = cell·s during this step (one cell per step at most in practice).
            let x_prev_abs = cell_old as f64 * s + x_old;
            let frac = ((next_cross as f64 * s - x_prev_abs) / (xabs - x_prev_abs)).clamp(0.0, 1.0);
            let tc = t - dt + frac * dt;
            while next_cross <= cell {
                crossings.push(tc);
                if crossings.len() == c.transient + 1 {
                    win_start = Some((xabs, d_n, d_t));
                }
                next_cross += 1;
                if let Some(p) = progress {
                    p(1);
                }
            }
            last_progress_t = t;
            trap.climb_x = f64::NEG_INFINITY;
            res.beads_passed = crossings.len().saturating_sub(1) as u64;
            if crossings.len() > nb {
                break;
            }
        }
        e = en;

        if let Some(angle) = trap.trapped(nd, cell, xabs, pos.y, etot) {
            res.stop = Some(MdStop {
                bead: crossings.len().saturating_sub(1) as u64,
                angle,
                time: t,
            });
            res.regime = Some(Regime::A);
            break;
        }
        if t > t_max || t - last_progress_t > c.max_time_per_bead {
            res.failure = Some(MdFailure::TimeLimit);
            break;
        }
        if res.steps.is_multiple_of(STOP_POLL) && stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
            res.failure = Some(MdFailure::Interrupted);
            break;
        }
    }
    Integrated {
        t,
        xabs,
        d_n,
        d_t,
        err_max,
        crossings,
        win_start,
        win: book.win,
    }
}

/// The measurement over the window of a run that crossed it: the mean velocity and its
/// standard error from blocks, the drift, the dissipation, and the contact and flight
/// statistics; then the regime.
fn measure(nd: &Nd, c: &MdRunConfig, res: &mut MdResult, it: &Integrated) {
    let s = nd.s;
    let nb = c.beads;
    let (xabs, d_n, d_t, win) = (it.xabs, it.d_n, it.d_t, &it.win);
    let crossings = &it.crossings;
    // Measurement over the window.
    let Some((x_w0, dn0, dt0)) = it.win_start else {
        res.failure = Some(MdFailure::TimeLimit);
        return;
    };
    let nwin = nb - c.transient;
    let times = &crossings[c.transient..=nb];
    let total = times[nwin] - times[0];
    let v = nwin as f64 * s / total;
    let nblk = c.blocks;
    let vb: Vec<f64> = (0..nblk)
        .map(|b| {
            let i0 = b * nwin / nblk;
            let i1 = (b + 1) * nwin / nblk;
            (i1 - i0) as f64 * s / (times[i1] - times[i0])
        })
        .collect();
    let mean_b = vb.iter().sum::<f64>() / nblk as f64;
    let var = vb.iter().map(|u| (u - mean_b) * (u - mean_b)).sum::<f64>() / (nblk - 1) as f64;
    res.mean_velocity = Some(v);
    res.stderr = Some((var / nblk as f64).sqrt());
    let half = nwin / 2;
    let v1 = half as f64 * s / (times[half] - times[0]);
    let v2 = (nwin - half) as f64 * s / (times[nwin] - times[half]);
    res.drift = Some((v2 - v1) / v);
    let drop = nd.sin_d * (xabs - x_w0);
    if drop > 0.0 {
        res.dissipation_normal = (d_n - dn0) / drop;
        res.dissipation_tangential = (d_t - dt0) / drop;
    }
    let nw = nwin as f64;
    res.contacts_per_bead = win.episodes as f64 / nw;
    res.bounces_per_contact = if win.distinct > 0 {
        win.episodes as f64 / win.distinct as f64
    } else {
        0.0
    };
    res.lift_offs_per_bead = win.lift_offs as f64 / nw;
    if win.lift_offs > 0 {
        res.lift_off_angle = Some(win.lift_angle_sum / win.lift_offs as f64);
        res.flight_length_mean = Some(win.lift_len_sum / win.lift_offs as f64);
    }
    res.skipped_fraction = (nw - win.distinct as f64).max(0.0) / nw;
    if win.jumps > 0 {
        res.jump_angle = Some(win.jump_angle_sum / win.jumps as f64);
    }
    res.flight_height_max = win.height_max;
    res.flight_length_max = win.len_max;
    res.airborne_fraction = win.airborne_time / total;
    if win.n_impacts > 0 {
        let n = win.n_impacts as f64;
        res.final_velocity = Some(win.vf_sum / n);
        res.initial_velocity = Some(win.vi_sum / n);
        res.k_eff = Some(win.k_sum / n);
    }
    res.runaway = res.dissipation_normal + res.dissipation_tangential < 0.9;
    res.regime = Some(
        if res.lift_offs_per_bead >= 0.5 || res.skipped_fraction >= 0.05 || res.runaway {
            Regime::C
        } else {
            Regime::B
        },
    );
}

/// The md scan of slopes for regime B: every 0.5° from 0.5° to 45°.
pub(crate) const MD_SCAN_STEP_DEG: f64 = 0.5;
pub(crate) const MD_SCAN_POINTS: usize = 90;
/// Bisection steps refining each end of the md regime B range (0.5°/2⁷ ≈ 0.004°).
pub(crate) const MD_REFINE: usize = 7;
/// How many times a hole in regime B may narrow the md range before `simulate` gives up.
pub(crate) const MD_NARROW: usize = 8;

/// The slopes (degrees) where the md model is in regime B at this ξ: the longest run of the
/// 0.5° scan (slopes in parallel), each end refined by bisection; its runs stopped early once
/// `stop` is raised (the result is then meaningless: the caller checks the flag).
pub(crate) fn regime_b_interval_until(
    md: &Md,
    xi: f64,
    rho: f64,
    tick: &(dyn Fn() + Sync),
    stop: Option<&AtomicBool>,
) -> std::result::Result<Option<(f64, f64)>, Error> {
    use crate::models::Regime;
    use rayon::prelude::*;
    let is_b = |d: f64| -> std::result::Result<bool, Error> {
        let sc = Scene::new(xi, d, rho, 0.1, CollisionLaw::Value(0.5))?;
        md.check_scene(&sc)?;
        let r = md.simulate_until(&sc, 1.0, None, stop);
        tick();
        Ok(r.regime == Some(Regime::B))
    };
    let grid: Vec<f64> = (1..=MD_SCAN_POINTS)
        .map(|i| MD_SCAN_STEP_DEG * i as f64)
        .collect();
    let flags: Vec<bool> = grid
        .par_iter()
        .map(|&d| is_b(d))
        .collect::<std::result::Result<_, _>>()?;
    let Some(best) = crate::models::regimes::longest_run(&flags) else {
        return Ok(None);
    };
    let bisect = |mut good: f64, mut bad: f64| -> std::result::Result<f64, Error> {
        for _ in 0..MD_REFINE {
            let m = 0.5 * (good + bad);
            if is_b(m)? {
                good = m
            } else {
                bad = m
            }
        }
        Ok(good)
    };
    let lo_good = grid[best.0];
    let hi_good = grid[best.1 - 1];
    let (lo, hi) = rayon::join(
        || {
            if best.0 == 0 {
                Ok(lo_good)
            } else {
                bisect(lo_good, grid[best.0 - 1])
            }
        },
        || {
            if best.1 >= grid.len() {
                Ok(hi_good)
            } else {
                bisect(hi_good, grid[best.1])
            }
        },
    );
    Ok(Some((lo?, hi?)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hertz_integral_matches_known_constant() {
        // Hertz: t_c = 2.9432 d_max / v, i.e. ∫₀¹ du/√(1−u^{5/2}) = 1.4716.
        assert!((2.0 * impact_integral(1.5) - 2.9432).abs() < 1e-4);
        // Linear spring: ∫₀¹ du/√(1−u²) = π/2.
        assert!((impact_integral(1.0) - PI / 2.0).abs() < 1e-12);
    }

    /// A scene outside the md model's domain (ρ → 0) fails at once, its time step never shrunk
    /// below the contact-time step over `MAX_STEP_SHRINK`.
    #[test]
    fn md_time_step_cannot_collapse() {
        use std::time::{Duration, Instant};
        let md = Md::ristow();
        for rho in [1e-4, 1e-6, 1e-300] {
            let sc = Scene::new(1.6, 6.0, rho, 0.1, CollisionLaw::Value(0.5)).unwrap();
            assert!(md.check_scene(&sc).is_err(), "rho {rho}");
            let t0 = Instant::now();
            let r = md.simulate(&sc, 1.0, None);
            assert_eq!(r.failure, Some(MdFailure::OutsideDomain), "rho {rho}");
            assert!(t0.elapsed() < Duration::from_millis(100));
            assert!(
                r.dt >= md.config.step_fraction * r.contact_time / MAX_STEP_SHRINK * (1.0 - 1e-12),
                "rho {rho}: dt {} contact time {}",
                r.dt,
                r.contact_time
            );
        }
        // At Ristow's ρ = 0.4 the step is the contact-time step or the damping's, unchanged.
        let sc = Scene::new(1.6, 6.0, 0.4, 0.1, CollisionLaw::Value(0.5)).unwrap();
        assert!(md.check_scene(&sc).is_ok());
    }
}
