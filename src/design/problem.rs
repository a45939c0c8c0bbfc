//! The forward problem a design is made for: the fitted parameters, their guess, the mean
//! velocity v̄(ξ, δ; p) of each series, its gradient in p and its derivative in δ by central
//! differences, and the range of each parameter over which a slope stays steady.

use super::DesignError;
use crate::fit::jaeger::paper_values;
use crate::fit::jan::PAPER_GLOBAL;
use crate::models::jaeger::Jaeger;
use crate::models::jan::Jan;
use crate::models::regimes::{alpha_of_xi, bulk_friction_law, regime_b_interval};
use crate::models::{ForwardModel, JaegerBranch, Model, NotSteady};
use crate::numfmt::fmt_f64;
use crate::scene::{CollisionLaw, Scene};

/// Which parameters are fitted, and how v̄ depends on them.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Kind {
    /// K = cos 2α + c sin²α sin 2α under a contact model: p = (c).
    KLawC(Model),
    /// One K per series under a contact model: p = (K_1, …, K_S).
    KFree(Model),
    /// Jan's eq 74 at one ξ: p = (λ, μ).
    JanSeries,
    /// Jan's laws λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α} (the form of eqs 75–76):
    /// p = (λ0, λ1, μ0, μ1).
    JanGlobal,
    /// Jaeger's eqs 80–84 per series: p = (a1, a2, a3) of each series in turn.
    Jaeger(JaegerBranch),
}

/// The forward problem: the series, the parameters and their guess.
#[derive(Debug, Clone)]
pub(crate) struct Problem {
    pub kind: Kind,
    pub series: Vec<f64>,
    pub rho: f64,
    pub f: f64,
    pub names: Vec<String>,
    pub guess: Vec<f64>,
}

/// Relative step of the central differences (in units of max(|p|, `FD_FLOOR`)).
const FD_STEP: f64 = 1e-4;
/// Smallest scale of a parameter for its difference step.
const FD_FLOOR: f64 = 1e-3;
/// First step of the search for the end of a steady range, relative to max(|p|, 1).
const STEADY_STEP: f64 = 0.01;
/// Doublings of that step before a steady range counts as unbounded (a factor 2^40 ≈ 1e12).
const STEADY_DOUBLINGS: usize = 40;
/// Width of the bracket, relative to max(|p|, 1), at which a steady range's end is taken.
const STEADY_TOL: f64 = 1e-7;

impl Problem {
    /// The velocity of series `s` at slope `delta` (radians) under parameters `p`, or `None`
    /// where the model has no steady state there.
    pub fn velocity(&self, s: usize, delta: f64, p: &[f64]) -> Option<f64> {
        let xi = self.series[s];
        let (model, law) = self.model_at(s, p)?;
        let scene = Scene::from_radians(xi, delta, self.rho, self.f, law).ok()?;
        let v = model.evaluate(&scene).ok()?.mean_velocity;
        (v.is_finite() && v > 0.0).then_some(v)
    }

    /// The model and collision law of series `s` under parameters `p`.
    pub fn model_at(&self, s: usize, p: &[f64]) -> Option<(Model, CollisionLaw)> {
        let alpha = alpha_of_xi(self.series[s]);
        let any = CollisionLaw::Value(0.5);
        Some(match self.kind {
            Kind::KLawC(m) => (m, CollisionLaw::C(p[0])),
            Kind::KFree(m) => {
                let k = p[s];
                if !(k > 0.0 && k < 1.0) {
                    return None;
                }
                (m, CollisionLaw::Value(k))
            }
            Kind::JanSeries => (Model::Jan(Jan::new(p[0], p[1]).ok()?), any),
            Kind::JanGlobal => {
                let sa = alpha.sin();
                let (l, m) = (p[0] * (p[1] * sa).exp(), p[2] * (p[3] * sa).exp());
                (Model::Jan(Jan::new(l, m).ok()?), any)
            }
            Kind::Jaeger(b) => {
                let q = &p[3 * s..3 * s + 3];
                (Model::Jaeger(Jaeger::new(q[0], q[1], q[2], b).ok()?), any)
            }
        })
    }

    /// ∂v̄/∂p at (s, δ) and the guess, by central differences with steps
    /// h_j = 1e-4 · max(|p_j|, 1e-3); `None` where a step leaves the steady state.
    pub fn gradient(&self, s: usize, delta: f64) -> Option<Vec<f64>> {
        self.gradient_at(s, delta, &self.guess)
    }

    /// ∂v̄/∂p at (s, δ) and parameters `at`, with the steps of [`Problem::gradient`].
    pub fn gradient_at(&self, s: usize, delta: f64, at: &[f64]) -> Option<Vec<f64>> {
        self.differences(at, |j| self.touches(s, j), |p| self.velocity(s, delta, p))
    }

    /// ∂v̄/∂δ (per radian) of series `s` at slope `delta` (radians) and parameters `at`, by a
    /// central difference with step 1e-4 · δ; `None` where a step leaves the steady state.
    pub fn slope_derivative(&self, s: usize, delta: f64, at: &[f64]) -> Option<f64> {
        let h = FD_STEP * delta.abs().max(FD_FLOOR);
        let up = self.velocity(s, delta + h, at)?;
        let down = self.velocity(s, delta - h, at)?;
        Some((up - down) / (2.0 * h))
    }

    /// Whether the model of series `s` at slope `delta` under parameters `p` says the bead
    /// has no steady state (it stops, lifts off, runs away or its final-velocity map has no
    /// fixed point): false where it is steady, where `p` make no model or scene at all (K of
    /// a law outside (0, 1), Jan's λ ≤ 0, …) and where the model cannot tell
    /// ([`NotSteady::Invalid`]: v̄ out of the range of doubles, an approximation outside its
    /// validity).
    fn not_steady(&self, s: usize, delta: f64, p: &[f64]) -> bool {
        let Some((model, law)) = self.model_at(s, p) else {
            return false;
        };
        Scene::from_radians(self.series[s], delta, self.rho, self.f, law).is_ok_and(|scene| {
            matches!(model.evaluate(&scene), Err(e) if !matches!(e, NotSteady::Invalid { .. }))
        })
    }

    /// The range of parameter `j` over which series `s` at slope `delta` (radians) stays
    /// steady, the other parameters at the guess: the ends (low, high) of the interval around
    /// the guess, each `None` where the steady state holds to the end of the parameter's
    /// domain (or over 1e12 times its scale): an end is one where the model has no steady
    /// state (the bead stops or lifts off), not where the parameter leaves its domain or v̄
    /// leaves the range of numbers. Each end is bracketed by steps doubling from 1 % of max(|p_j|, 1) and found by
    /// bisection to 1e-7 of that scale. `None` where the guess itself is not steady there.
    pub fn steady_range(
        &self,
        s: usize,
        delta: f64,
        j: usize,
    ) -> Option<(Option<f64>, Option<f64>)> {
        let steady = |x: f64| {
            let mut p = self.guess.clone();
            p[j] = x;
            self.velocity(s, delta, &p).is_some()
        };
        let p0 = self.guess[j];
        if !steady(p0) {
            return None;
        }
        let scale = p0.abs().max(1.0);
        let end = |dir: f64| -> Option<f64> {
            let mut good = p0;
            let mut step = STEADY_STEP * scale;
            let mut bad = None;
            for _ in 0..=STEADY_DOUBLINGS {
                let x = p0 + dir * step;
                if !steady(x) {
                    bad = Some(x);
                    break;
                }
                good = x;
                step *= 2.0;
            }
            let mut bad = bad?;
            while (bad - good).abs() > STEADY_TOL * scale {
                let m = 0.5 * (good + bad);
                if steady(m) {
                    good = m;
                } else {
                    bad = m;
                }
            }
            let mut p = self.guess.clone();
            p[j] = bad;
            self.not_steady(s, delta, &p).then_some(good)
        };
        Some((end(-1.0), end(1.0)))
    }

    /// Central differences of `f` at `at` in the parameters `touches` selects (the others
    /// get 0); `None` where a step leaves `f`'s domain.
    fn differences(
        &self,
        at: &[f64],
        touches: impl Fn(usize) -> bool,
        f: impl Fn(&[f64]) -> Option<f64>,
    ) -> Option<Vec<f64>> {
        let mut p = at.to_vec();
        let mut g = vec![0.0; p.len()];
        for j in 0..p.len() {
            if !touches(j) {
                continue;
            }
            let h = FD_STEP * p[j].abs().max(FD_FLOOR);
            let p0 = p[j];
            p[j] = p0 + h;
            let up = f(&p);
            p[j] = p0 - h;
            let down = f(&p);
            p[j] = p0;
            g[j] = (up? - down?) / (2.0 * h);
        }
        Some(g)
    }

    /// The bulk friction μ of series `s` through the rolling model's eq 79,
    /// μ = (1 − K²) sin α / ((1 + K²) cos α + 2K), at the K the parameters `p` give that
    /// series (a K-law fit only; `None` for the other fits and where K is outside (0, 1)).
    pub fn mu(&self, s: usize, p: &[f64]) -> Option<f64> {
        let alpha = alpha_of_xi(self.series[s]);
        let law = match self.kind {
            Kind::KLawC(_) => CollisionLaw::C(p[0]),
            Kind::KFree(_) => CollisionLaw::Value(p[s]),
            _ => return None,
        };
        let k = law.k(alpha, self.rho);
        (k > 0.0 && k < 1.0).then(|| bulk_friction_law(alpha, law, self.rho))
    }

    /// ∂μ/∂p of series `s` (eq 79 through the law) at `at`, by central differences.
    pub fn mu_gradient(&self, s: usize, at: &[f64]) -> Option<Vec<f64>> {
        self.differences(at, |j| self.touches(s, j), |p| self.mu(s, p))
    }

    /// The names of the derived targets (μ of eq 79 per series) of a K-law fit: `mu` for
    /// one series, `mu of series 'xi=X'` for several; none for the other fits.
    pub fn mu_names(&self) -> Vec<String> {
        match self.kind {
            Kind::KLawC(_) | Kind::KFree(_) if self.series.len() == 1 => vec!["mu".into()],
            Kind::KLawC(_) | Kind::KFree(_) => self
                .series
                .iter()
                .map(|&x| format!("mu of series 'xi={}'", fmt_f64(x)))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Whether parameter `j` moves the velocities of series `s`.
    pub fn touches(&self, s: usize, j: usize) -> bool {
        match self.kind {
            Kind::KFree(_) => j == s,
            Kind::Jaeger(_) => j / 3 == s,
            _ => true,
        }
    }

    /// Regime B of series `s` at the guess (radians), cut to the onset + 12° for the models
    /// whose steady range has no upper end (Jan, Jaeger), as `simulate` does.
    pub fn regime_b(&self, s: usize) -> Option<(f64, f64)> {
        let (model, law) = self.model_at(s, &self.guess)?;
        let (lo, hi) = regime_b_interval(&model, self.series[s], self.rho, self.f, law)?;
        let open = matches!(model, Model::Jan(_) | Model::Jaeger(_));
        Some(if open {
            (lo, (lo + 12f64.to_radians()).min(hi))
        } else {
            (lo, hi)
        })
    }
}

/// The problem of fit `fit` under `model` with the collision law `law` (for the K-law fits:
/// `c=VALUE` fits c, a number K fits one K per series, both with the given guess).
pub(crate) fn problem(
    fit: super::DesignFit,
    model: Model,
    law: CollisionLaw,
    series: &[f64],
    rho: f64,
    f: f64,
    branch: JaegerBranch,
) -> Result<Problem, DesignError> {
    use super::DesignFit;
    let label = |xi: f64| format!("xi={}", fmt_f64(xi));
    let (kind, names, guess) = match fit {
        DesignFit::KLaw => match law {
            CollisionLaw::C(c) => (Kind::KLawC(model), vec!["c".to_string()], vec![c]),
            CollisionLaw::Value(k) => (
                Kind::KFree(model),
                series
                    .iter()
                    .map(|&x| format!("K of series '{}'", label(x)))
                    .collect(),
                vec![k; series.len()],
            ),
            other => {
                return Err(DesignError::new(
                    "law",
                    &other.to_string(),
                    "the K-law design needs the fitted law with its guess: c=VALUE (law c) \
                         or a number K (one K per series)",
                ))
            }
        },
        DesignFit::Jan if series.len() == 1 => {
            let j = Jan::paper_fit(alpha_of_xi(series[0]));
            (
                Kind::JanSeries,
                vec!["lambda".into(), "mu".into()],
                vec![j.lambda, j.mu],
            )
        }
        DesignFit::Jan => (
            Kind::JanGlobal,
            ["lambda0", "lambda1", "mu0", "mu1"]
                .map(String::from)
                .to_vec(),
            PAPER_GLOBAL.to_vec(),
        ),
        DesignFit::Jaeger => {
            let mut names = Vec::new();
            let mut guess = Vec::new();
            for &xi in series {
                let p = paper_values(xi).ok_or_else(|| {
                    DesignError::new(
                        "series",
                        &fmt_f64(xi),
                        "the paper gives Jaeger's a1, a2, a3 (the guess) for xi = 0.8, 1, 1.6, 2 \
                         only",
                    )
                })?;
                for (n, v) in ["a1", "a2", "a3"].iter().zip(p) {
                    names.push(if series.len() == 1 {
                        n.to_string()
                    } else {
                        format!("{n} of series '{}'", label(xi))
                    });
                    guess.push(v);
                }
            }
            (Kind::Jaeger(branch), names, guess)
        }
    };
    Ok(Problem {
        kind,
        series: series.to_vec(),
        rho,
        f,
        names,
        guess,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::DesignFit;

    fn jan(series: &[f64]) -> Problem {
        problem(
            DesignFit::Jan,
            Model::StickSlip,
            CollisionLaw::C(0.5),
            series,
            0.4,
            0.1,
            JaegerBranch::Upper,
        )
        .unwrap()
    }

    /// Jan's eq 74 at one ξ: v̄ = sqrt((2 sin α/λ)(sin δ − μ cos δ)) is steady exactly while
    /// μ < tan δ, for any λ > 0; μ ≥ 0 is the model's domain. dv̄/dδ = (sin α/λ)(cos δ +
    /// μ sin δ)/v̄, differentiated by hand.
    #[test]
    fn jan_steady_range_and_slope_derivative_in_closed_form() {
        let p = jan(&[1.0]);
        let (lambda, mu) = (p.guess[0], p.guess[1]);
        let sa = alpha_of_xi(1.0).sin();
        for deg in [6.5, 9.0, 15.0] {
            let d = f64::to_radians(deg);
            assert_eq!(p.steady_range(0, d, 0), Some((None, None)), "{deg}");
            let (lo, hi) = p.steady_range(0, d, 1).unwrap();
            assert_eq!(lo, None, "{deg}");
            let hi = hi.unwrap();
            assert!((hi - d.tan()).abs() < 1e-6, "{deg}: {hi} vs {}", d.tan());
            let v = p.velocity(0, d, &p.guess).unwrap();
            let want = sa / lambda * (d.cos() + mu * d.sin()) / v;
            let got = p.slope_derivative(0, d, &p.guess).unwrap();
            assert!((got / want - 1.0).abs() < 1e-6, "{deg}: {got} vs {want}");
        }
        // Below the onset (tan δ < μ) the guess itself is not steady.
        assert_eq!(p.steady_range(0, (0.5 * mu).atan(), 1), None);
    }

    /// Jan's laws across series: μ = μ0 e^{μ1 sin α} < tan δ bounds μ0 and μ1 above; λ0 and
    /// λ1 only scale v̄ (λ1 → ±∞ drives λ out of the range of doubles, not out of regime B).
    #[test]
    fn jan_laws_steady_ranges() {
        let p = jan(&[0.8, 1.0]);
        let (mu0, mu1) = (p.guess[2], p.guess[3]);
        let d = 12f64.to_radians();
        let sa = alpha_of_xi(0.8).sin();
        let r: Vec<_> = (0..4).map(|j| p.steady_range(0, d, j).unwrap()).collect();
        assert_eq!(r[0], (None, None));
        assert_eq!(r[1], (None, None));
        let mu0_max = d.tan() / (mu1 * sa).exp();
        let mu1_max = (d.tan() / mu0).ln() / sa;
        assert!(
            r[2].0.is_none() && (r[2].1.unwrap() - mu0_max).abs() < 1e-6,
            "{:?}",
            r[2]
        );
        assert!(
            r[3].0.is_none() && (r[3].1.unwrap() / mu1_max - 1.0).abs() < 1e-6,
            "{:?}",
            r[3]
        );
    }

    /// K law c under stick/slip at ξ = 0.8 and 9.6538° (the lower end of the c-optimal
    /// design's range): the c range found by bisection in c agrees with regime B found by the
    /// scan in δ (`regime_b_interval`): just inside either end, the slope lies in regime B of
    /// that c; just outside, it does not. The lower end lies above c = 0.45 (the bead stops
    /// there when c is 10 % below the guess).
    #[test]
    fn klaw_c_steady_range_matches_regime_b() {
        let p = problem(
            DesignFit::KLaw,
            Model::StickSlip,
            CollisionLaw::C(0.5),
            &[0.8],
            0.4,
            0.1,
            JaegerBranch::Upper,
        )
        .unwrap();
        let d = 9.6538f64.to_radians();
        let (lo, hi) = p.steady_range(0, d, 0).unwrap();
        let (lo, hi) = (lo.unwrap(), hi.unwrap());
        assert!(lo > 0.45 && lo < 0.5 && hi > 0.5, "{lo} {hi}");
        let inside = |c: f64| {
            regime_b_interval(&Model::StickSlip, 0.8, 0.4, 0.1, CollisionLaw::C(c))
                .is_some_and(|(a, b)| a < d && d < b)
        };
        for (end, dir) in [(lo, 1.0), (hi, -1.0)] {
            assert!(inside(end + dir * 1e-4), "{end}");
            assert!(!inside(end - dir * 1e-4), "{end}");
        }
    }
}
