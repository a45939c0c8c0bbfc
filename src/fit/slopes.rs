//! Slopes measured with error: the fits' way to orthogonal distance regression
//! ([`crate::inverse::odr`]). When some point carries σ_δ > 0 (column `sigma_delta_deg`, or
//! `--sigma-delta`), a least-squares fit of `klaw`, `jan` or `jaeger` is refitted from its
//! Levenberg–Marquardt optimum by ODR, with the slope δ as the input that carries error:
//!
//! S(β, δ̂) = Σ_i [ ((v_i − v̄_i(δ̂_i; β))/σ_v,i)² + ((δ̂_i − δ_i)/σ_δ,i)² ].
//!
//! χ² is S, the covariance ODRPACK's (the effective variance σ_v² + (∂v̄/∂δ)² σ_δ² at the
//! adjusted slopes), and the profile intervals profile S minimised over the slopes at each
//! parameter value. A point whose slope is exact (σ_δ = 0) keeps it. An adjusted slope never
//! leaves the point's steady range: a trial step that would take one out is rejected.

use super::data::Dataset;
use super::posterior;
use super::summary::{self, FitResult, Solved};
use crate::inverse::posterior::Method;
use crate::inverse::{
    CurveModel, Fit, Infeasible, LsqOptions, Odr, OdrFit, OdrModel, OdrProblem, Residuals,
    SigmaKind,
};
use crate::numfmt::fmt_sig;

/// A [`CurveModel`] fit whose abscissa of point i is built from the point's slope by `at`:
/// the ODR model of `jan` and `jaeger`.
pub(crate) struct SlopeCurve<'a, X, M> {
    /// The least-squares model.
    pub model: &'a M,
    /// The abscissae at the measured slopes.
    pub base: &'a [X],
    /// The abscissa of a point (its measured one) at slope δ (radians).
    pub at: fn(&X, f64) -> X,
}

impl<X, M: CurveModel<X>> OdrModel for SlopeCurve<'_, X, M> {
    fn n_params(&self) -> usize {
        self.model.n_params()
    }
    fn n_points(&self) -> usize {
        self.base.len()
    }
    fn value(&self, i: usize, delta: f64, p: &[f64]) -> Result<f64, Infeasible> {
        if !(delta > 0.0 && delta < std::f64::consts::FRAC_PI_2) {
            return Err(Infeasible);
        }
        self.model.value(&(self.at)(&self.base[i], delta), p)
    }
}

/// The ODR refit of a least-squares fit: the problem (for the profiles) and the fit.
pub(crate) struct SlopeFit<M> {
    pub problem: OdrProblem<M>,
    pub odr: OdrFit,
    /// The options of the fit (the least-squares fit's, its box dropped unless kept).
    pub options: LsqOptions,
}

impl<M: OdrModel + Sync> SlopeFit<M> {
    /// The ODR fit of `model` to the points `index` of `data` (in the model's order), started
    /// from the least-squares optimum `lm`, with the options of that fit (`bounds` false drops
    /// its box: the box of a law is where every point is steady at its measured slope, and the
    /// adjusted slopes have their own). `None` when no point of `index` carries σ_δ.
    pub fn new(
        model: M,
        data: &Dataset,
        index: &[usize],
        lm: &Fit,
        opts: &LsqOptions,
        bounds: bool,
    ) -> Option<Result<Self, String>> {
        if !index.iter().any(|&i| data.points[i].sigma_delta > 0.0) {
            return None;
        }
        let pts = index.iter().map(|&i| &data.points[i]);
        let x = pts.clone().map(|p| p.scene.delta).collect();
        let y = pts.clone().map(|p| p.v).collect();
        let sx = pts.clone().map(|p| p.sigma_delta).collect();
        let sy = (data.sigma == SigmaKind::Absolute).then(|| pts.map(|p| p.sigma).collect());
        let opts = if bounds {
            opts.clone()
        } else {
            LsqOptions {
                lower: None,
                upper: None,
                ..opts.clone()
            }
        };
        Some(
            OdrProblem::new(model, x, y, sx, sy, &lm.params, &opts)
                .and_then(|problem| {
                    let (odr, problem) = Odr::fit_keep(problem.started_at_optimum(), &opts)?;
                    Ok(SlopeFit {
                        problem,
                        odr,
                        options: opts.clone(),
                    })
                })
                .map_err(|e| e.to_string()),
        )
    }

    /// The corrections δ̂ − δ of the fit.
    pub fn corrections(&self, data: &Dataset, index: &[usize]) -> Vec<f64> {
        index
            .iter()
            .zip(&self.odr.x_fit)
            .map(|(&i, x)| x - data.points[i].scene.delta)
            .collect()
    }
}

/// Marks `summary` as an ODR fit and gives its points (`index` of `data`, in order) their
/// adjusted slopes and slope residuals; the statistics' note names the points whose slope
/// moved by more than 2σ_δ.
pub(crate) fn attach(summary: &mut FitResult, odr: &OdrFit, data: &Dataset, index: &[usize]) {
    summary.stats.slope_errors = true;
    let mut moved = Vec::new();
    for ((pt, &i), (x, rx)) in summary
        .points
        .iter_mut()
        .zip(index)
        .zip(odr.x_fit.iter().zip(&odr.x_residuals))
    {
        pt.delta_fit_deg = Some(x.to_degrees());
        pt.delta_residual = (data.points[i].sigma_delta > 0.0).then_some(*rx);
        if rx.abs() > MOVED {
            moved.push(format!(
                "'{}' {} deg -> {} deg ({} sigma_delta)",
                crate::numfmt::clip(&pt.series, crate::numfmt::ECHO_CHARS),
                fmt_sig(pt.delta_deg, 6),
                fmt_sig(x.to_degrees(), 6),
                fmt_sig(*rx, 3)
            ));
        }
    }
    if !moved.is_empty() {
        let note = format!(
            "{} point(s) whose adjusted slope moved by more than {MOVED} sigma_delta: {}",
            moved.len(),
            moved.join("; ")
        );
        summary.stats.note = summary::join(&summary.stats.note, &note);
    }
}

/// How far an adjusted slope may move, in σ_δ, before the fit's note names its point.
pub(crate) const MOVED: f64 = 2.0;

/// The summary of a least-squares fit (`solved`, of the points `index` of `data`) refitted by
/// ODR on `model` when those points carry slope errors, with its points, their adjusted
/// slopes, and profiles of the ODR objective when `method` asks for profiles; `None` when
/// they carry none, or for a posterior run. `bounds`: keep the least-squares box (see
/// [`SlopeFit::new`]). A refit the solver refuses keeps the least-squares estimate, with a
/// note saying why.
pub(crate) fn summarise<R: Residuals + ?Sized, M: OdrModel + Sync>(
    method: &Method,
    solved: &Solved<'_, R>,
    model: M,
    data: &Dataset,
    index: &[usize],
    bounds: bool,
) -> Option<FitResult> {
    let profile = match method {
        Method::Lsq { profile, .. } => *profile,
        Method::Mcmc(_) => false,
    };
    let sf = match SlopeFit::new(model, data, index, solved.fit, solved.options, bounds)? {
        Ok(sf) => sf,
        Err(e) => {
            let mut s = summary::summarise(*solved, profile);
            s.stats.note = summary::join(
                &s.stats.note,
                &format!("orthogonal distance regression refused ({e}): slopes taken as exact"),
            );
            s.attach_points(data, index);
            return Some(s);
        }
    };
    let opts = &sf.options;
    let mut s = if let Method::Mcmc(_) = method {
        let integrated = Integrated::new(sf.problem.model(), data, index);
        posterior::summarise_with(
            method,
            Solved {
                name: solved.name,
                series: solved.series,
                specs: solved.specs,
                problem: &integrated,
                fit: &sf.odr.fit,
                level: solved.level,
                options: opts,
                distinct: solved.distinct,
                observed_norm: solved.observed_norm,
            },
        )
    } else {
        let reduced = sf
            .problem
            .reduced(&sf.odr.fit.params, sf.corrections(data, index));
        summary::summarise(
            Solved {
                name: solved.name,
                series: solved.series,
                specs: solved.specs,
                problem: &reduced,
                fit: &sf.odr.fit,
                level: solved.level,
                options: opts,
                distinct: solved.distinct,
                observed_norm: solved.observed_norm,
            },
            profile,
        )
    };
    s.attach_points(data, index);
    attach(&mut s, &sf.odr, data, index);
    Some(s)
}

/// Why `method` cannot fit `data`, if it cannot: a posterior run on slopes that carry errors
/// when the velocities carry no σ, or with the scatter's scale sampled (the likelihood
/// integrated over the slopes has σ_v inside the integral, so a common scale of σ_v does not
/// factor out of it as the sampler's scale assumes).
pub(crate) fn unsupported(method: &Method, data: &Dataset) -> Option<String> {
    let Method::Mcmc(settings) = method else {
        return None;
    };
    let scaled = data.sigma == SigmaKind::Relative || settings.fit_scatter;
    (data.has_slope_errors() && scaled).then(|| {
        "posterior sampling with slope errors (sigma_delta_deg or --sigma-delta) needs \
         absolute velocity errors (sigma_v) and no fitted scatter (--fit-scatter): the \
         likelihood integrated over each slope does not factor a common scale out; use \
         --method lsq (orthogonal distance regression), or give sigma_v"
            .into()
    })
}

/// Nodes of the quadrature over each point's true slope in a posterior run, centred on the
/// integrand ([`Integrated`]).
pub(crate) const SLOPE_NODES: usize = 5;

/// Nodes of the quadrature centred on the measured slope, where the model has no steady state
/// or no slope there ([`Integrated`]).
pub(crate) const SLOPE_NODES_PLAIN: usize = 12;

/// Step factor of the central difference of v̄ in δ, ε^{1/3}.
const STEP: f64 = 6.055454452393343e-6;

/// Gauss–Hermite nodes t_k and weights w_k for E[g(Z)] ≈ Σ w_k g(t_k), Z standard normal
/// (probabilists' Hermite polynomials), by Golub & Welsch (Math. Comp. 23, 1969): the nodes
/// are the eigenvalues of the symmetric tridiagonal Jacobi matrix with off-diagonal √k, the
/// weights the squared first components of its unit eigenvectors.
pub(crate) fn hermite(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut j = nalgebra::DMatrix::<f64>::zeros(n, n);
    for k in 1..n {
        let b = (k as f64).sqrt();
        j[(k, k - 1)] = b;
        j[(k - 1, k)] = b;
    }
    let e = j.symmetric_eigen();
    let mut pairs: Vec<(f64, f64)> = (0..n)
        .map(|k| (e.eigenvalues[k], e.eigenvectors[(0, k)].powi(2)))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs.into_iter().unzip()
}

/// The likelihood of each point integrated over its true slope, as residuals of a posterior:
/// p(v_i | β) = ∫ N(v_i; v̄_i(δ̂; β), σ_v,i) N(δ̂; δ_i, σ_δ,i) dδ̂, the integrand 0 where the
/// point has no steady state. Residual i is r_i = √(−2 ln(σ_v,i √(2π) p(v_i | β))) ≥ 0, so
/// that −½ Σ r_i² is the log-likelihood up to a constant, as the posterior reads its problem;
/// with σ_δ,i = 0 it is the ordinary (v_i − v̄_i)/σ_v,i. Infeasible where some point has no
/// steady state at any node.
///
/// The quadrature is Gauss–Hermite centred on the integrand (importance sampling by a
/// Gaussian, in the manner of adaptive Gauss–Hermite quadrature: Q. Liu & D. A. Pierce,
/// Biometrika 81, 1994): with v̄ linearised at the measured slope, v̄ ≈ v̄_i + g (δ̂ − δ_i)
/// (g by a central difference), the integrand is the Gaussian N(δ̂; m, s) times a constant,
/// with s² = σ_δ² σ_v² / (σ_v² + g² σ_δ²) and m = δ_i + σ_δ² g (v_i − v̄_i) / (σ_v² + g² σ_δ²)
/// (the effective variance of the orthogonal distance fit). The integral is then
/// Σ_k w_k N(δ̂_k; δ_i, σ_δ) L(δ̂_k) / N(δ̂_k; m, s) at δ̂_k = m + s t_k over [`SLOPE_NODES`]
/// nodes: exact where v̄ is linear, and a smooth function of β, since the nodes follow the
/// integrand's peak (uncentred nodes, fixed around δ_i, let the log-likelihood of a steep
/// point jump by a large fraction of a unit as its peak passes between them). Where the
/// measured slope has no steady state at β, or no difference there, the nodes are the plain
/// ones around δ_i ([`SLOPE_NODES_PLAIN`]).
pub(crate) struct Integrated<M> {
    model: M,
    x: Vec<f64>,
    y: Vec<f64>,
    sy: Vec<f64>,
    sx: Vec<f64>,
    /// Gauss–Hermite nodes and log weights, centred and plain.
    centred: (Vec<f64>, Vec<f64>),
    plain: (Vec<f64>, Vec<f64>),
}

/// The nodes and log weights of the probabilists' Gauss–Hermite rule on `n` nodes.
fn rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (nodes, weights) = hermite(n);
    (nodes, weights.iter().map(|w| w.ln()).collect())
}

impl<M: OdrModel> Integrated<M> {
    /// The integrated likelihood of `model` on the points `index` of `data` (σ_v absolute).
    pub fn new(model: M, data: &Dataset, index: &[usize]) -> Self {
        let pts = || index.iter().map(|&i| &data.points[i]);
        Integrated {
            model,
            x: pts().map(|p| p.scene.delta).collect(),
            y: pts().map(|p| p.v).collect(),
            sy: pts().map(|p| p.sigma).collect(),
            sx: pts().map(|p| p.sigma_delta).collect(),
            centred: rule(SLOPE_NODES),
            plain: rule(SLOPE_NODES_PLAIN),
        }
    }

    /// As [`Integrated::new`], with `centred` nodes centred on the integrand (none: the plain
    /// nodes everywhere) and `plain` nodes around the measured slope.
    #[cfg(test)]
    pub fn with_rules(
        model: M,
        data: &Dataset,
        index: &[usize],
        centred: usize,
        plain: usize,
    ) -> Self {
        let mut s = Self::new(model, data, index);
        s.centred = if centred == 0 {
            (Vec::new(), Vec::new())
        } else {
            rule(centred)
        };
        s.plain = rule(plain);
        s
    }

    /// The centre m and width s of point i's quadrature at β (struct docs), or `None` where
    /// the measured slope has no steady state or no difference.
    fn centre(&self, i: usize, p: &[f64]) -> Option<(f64, f64)> {
        let (x, sx, sy) = (self.x[i], self.sx[i], self.sy[i]);
        let value = |d: f64| self.model.value(i, d, p).ok().filter(|v| v.is_finite());
        let f0 = value(x)?;
        let h = STEP * x.abs().max(sx);
        let g = match (value(x + h), value(x - h)) {
            (Some(u), Some(d)) => (u - d) / (2.0 * h),
            (Some(u), None) => (u - f0) / h,
            (None, Some(d)) => (f0 - d) / h,
            (None, None) => return None,
        };
        let e = sy * sy + g * g * sx * sx;
        let (m, s) = (x + sx * sx * g * (self.y[i] - f0) / e, sx * sy / e.sqrt());
        (m.is_finite() && s > 0.0 && s.is_finite()).then_some((m, s))
    }

    /// ln(σ_v √(2π) p(v_i | β)) of point i (σ_δ,i > 0) on the nodes centred at m with width s
    /// (struct docs); −∞ where no node has a steady state.
    fn ln_likelihood(
        &self,
        i: usize,
        p: &[f64],
        (m, s): (f64, f64),
        (nodes, ln_weights): &(Vec<f64>, Vec<f64>),
    ) -> f64 {
        let (x, sx, sy) = (self.x[i], self.sx[i], self.sy[i]);
        let shift = (s / sx).ln();
        let terms: Vec<f64> = nodes
            .iter()
            .zip(ln_weights)
            .map(|(t, lw)| {
                let d = m + s * t;
                match self.model.value(i, d, p) {
                    Ok(f) if f.is_finite() => {
                        let (zv, zx) = ((self.y[i] - f) / sy, (d - x) / sx);
                        lw + shift - 0.5 * (zv * zv + zx * zx - t * t)
                    }
                    _ => f64::NEG_INFINITY,
                }
            })
            .collect();
        let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if top == f64::NEG_INFINITY {
            return top;
        }
        top + terms.iter().map(|t| (t - top).exp()).sum::<f64>().ln()
    }
}

impl<M: OdrModel> Residuals for Integrated<M> {
    fn n_params(&self) -> usize {
        self.model.n_params()
    }
    fn n_residuals(&self) -> usize {
        self.y.len()
    }
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        for (i, out) in out.iter_mut().enumerate() {
            if self.sx[i] == 0.0 {
                *out = (self.y[i] - self.model.value(i, self.x[i], p)?) / self.sy[i];
                continue;
            }
            let ln_l = match self.centre(i, p).filter(|_| !self.centred.0.is_empty()) {
                Some(c) => self.ln_likelihood(i, p, c, &self.centred),
                None => self.ln_likelihood(i, p, (self.x[i], self.sx[i]), &self.plain),
            };
            if ln_l == f64::NEG_INFINITY {
                return Err(Infeasible);
            }
            *out = (-2.0 * ln_l).max(0.0).sqrt();
        }
        Ok(())
    }
}
