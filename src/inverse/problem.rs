//! A least-squares problem as argmin sees it: [`LeastSquares`] holds a [`Residuals`] problem with
//! its box and start, and implements argmin's [`Operator`] and [`Jacobian`] (the residual vector
//! and its Jacobian) and [`CostFunction`] and [`Gradient`] (χ² and its gradient) on nalgebra's
//! `DVector`/`DMatrix`, so that any argmin solver can run on a bead fit, and fitbead's
//! Levenberg–Marquardt solver ([`super::lm::LevenbergMarquardt`]) runs under argmin's
//! `Executor`.
//!
//! Infeasible points (the model's own [`Infeasible`], a non-finite residual, or a point outside
//! the box) are an error of [`Operator::apply`] and [`Jacobian::jacobian`], and a cost of +∞ for
//! [`CostFunction::cost`], so that derivative-free solvers step back from them; the
//! Levenberg–Marquardt solver never sees them as errors (they are rejected steps).

use argmin::core::{CostFunction, Error, Gradient, Jacobian, Operator};
use faer::{Mat, MatMut};
use nalgebra::{DMatrix, DVector};

use super::lmpar::norm2;
use super::lsq::{validate, Infeasible, LsqError, LsqOptions, Residuals, Setup};

/// A [`Residuals`] problem with its box bounds, typical magnitudes and starting point: the
/// problem type of [`super::lm::LevenbergMarquardt`], and an argmin problem for every other
/// solver.
///
/// ```
/// use argmin::core::{CostFunction, Operator};
/// use fitbead::inverse::{Infeasible, LeastSquares, LsqOptions, CurveModel, WeightedData};
/// use nalgebra::DVector;
/// struct Line;
/// impl CurveModel<f64> for Line {
///     fn n_params(&self) -> usize { 2 }
///     fn value(&self, x: &f64, p: &[f64]) -> Result<f64, Infeasible> { Ok(p[0] + p[1] * x) }
/// }
/// let data = WeightedData::new(Line, vec![0.0, 1.0, 2.0], vec![1.0, 3.0, 5.0], None).unwrap();
/// let ls = LeastSquares::new(data, &[0.0, 0.0], &LsqOptions::default()).unwrap();
/// let p = DVector::from_vec(vec![1.0, 2.0]);
/// assert_eq!(ls.apply(&p).unwrap().norm(), 0.0);
/// assert_eq!(ls.cost(&p).unwrap(), 0.0);
/// ```
#[derive(Debug, Clone)]
pub struct LeastSquares<R> {
    pub(crate) problem: R,
    pub(crate) setup: Setup,
}

/// A least-squares problem as the solver's iteration sees it: the residuals behind a trait
/// object, with the box and typical magnitudes. The iteration ([`super::lm`]), the finite
/// differences ([`Evaluator`]) and the covariance are compiled once for every problem type;
/// only the residual and Jacobian evaluations are the problem's own code.
#[derive(Clone, Copy)]
pub(crate) struct View<'a> {
    pub problem: &'a dyn Residuals,
    pub setup: &'a Setup,
}

impl<R: Residuals> LeastSquares<R> {
    /// The problem as the solver's iteration sees it.
    pub(crate) fn view(&self) -> View<'_> {
        View {
            problem: &self.problem,
            setup: &self.setup,
        }
    }

    /// Checks `start` and the bounds and typical magnitudes of `opts` against `problem` (the
    /// same checks as [`super::fit`]); the start is projected onto the box.
    pub fn new(problem: R, start: &[f64], opts: &LsqOptions) -> Result<Self, LsqError> {
        let setup = validate(&problem, start, opts)?;
        Ok(LeastSquares { problem, setup })
    }

    /// The residual problem.
    pub fn residuals_problem(&self) -> &R {
        &self.problem
    }

    /// The starting point, projected onto the box.
    pub fn start(&self) -> &[f64] {
        &self.setup.start
    }

    /// Lower bounds (−∞ where there is none).
    pub fn lower(&self) -> &[f64] {
        &self.setup.lower
    }

    /// Upper bounds (+∞ where there is none).
    pub fn upper(&self) -> &[f64] {
        &self.setup.upper
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.problem.n_params()
    }

    /// Number of residuals.
    pub fn n_residuals(&self) -> usize {
        self.problem.n_residuals()
    }

    /// True when `p` has n entries, all finite and inside the box.
    fn admissible(&self, p: &[f64]) -> bool {
        p.len() == self.n_params()
            && p.iter()
                .zip(self.setup.lower.iter().zip(&self.setup.upper))
                .all(|(v, (lo, hi))| v.is_finite() && v >= lo && v <= hi)
    }

    /// The residuals at `p`, or [`Infeasible`] (outside the box, the model's own verdict, or a
    /// non-finite residual).
    fn residual_vector(&self, p: &[f64]) -> Result<Vec<f64>, Infeasible> {
        if !self.admissible(p) {
            return Err(Infeasible);
        }
        let mut out = vec![0.0; self.n_residuals()];
        self.problem.residuals(p, &mut out)?;
        if out.iter().all(|v| v.is_finite()) {
            Ok(out)
        } else {
            Err(Infeasible)
        }
    }

    /// The residuals and the Jacobian at `p` (analytic, or the solver's finite differences).
    fn residuals_and_jacobian(&self, p: &[f64]) -> Result<(Vec<f64>, Mat<f64>), Infeasible> {
        let f = self.residual_vector(p)?;
        let mut ev = Evaluator::new(self.n_residuals(), self.n_params());
        let mut jac = Mat::<f64>::zeros(ev.m, ev.n);
        if ev.jacobian(self.view(), p, &f, &mut jac) {
            Ok((f, jac))
        } else {
            Err(Infeasible)
        }
    }
}

impl<R: Residuals> Operator for LeastSquares<R> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;

    /// The m weighted residuals; an error at an infeasible point.
    fn apply(&self, p: &Self::Param) -> Result<Self::Output, Error> {
        Ok(DVector::from_vec(self.residual_vector(p.as_slice())?))
    }
}

impl<R: Residuals> Jacobian for LeastSquares<R> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;

    /// The m × n Jacobian of the residuals; an error at an infeasible point.
    fn jacobian(&self, p: &Self::Param) -> Result<Self::Jacobian, Error> {
        let (_, jac) = self.residuals_and_jacobian(p.as_slice())?;
        Ok(DMatrix::from_fn(jac.nrows(), jac.ncols(), |i, j| {
            jac[(i, j)]
        }))
    }
}

impl<R: Residuals> CostFunction for LeastSquares<R> {
    type Param = DVector<f64>;
    type Output = f64;

    /// χ² = Σ rᵢ², or +∞ at an infeasible point.
    fn cost(&self, p: &Self::Param) -> Result<Self::Output, Error> {
        Ok(match self.residual_vector(p.as_slice()) {
            Ok(r) => norm2(&r).powi(2),
            Err(Infeasible) => f64::INFINITY,
        })
    }
}

impl<R: Residuals> Gradient for LeastSquares<R> {
    type Param = DVector<f64>;
    type Gradient = DVector<f64>;

    /// ∇χ² = 2 Jᵀ r; an error at an infeasible point.
    fn gradient(&self, p: &Self::Param) -> Result<Self::Gradient, Error> {
        let (f, jac) = self.residuals_and_jacobian(p.as_slice())?;
        Ok(DVector::from_fn(jac.ncols(), |j, _| {
            2.0 * (0..jac.nrows()).map(|i| jac[(i, j)] * f[i]).sum::<f64>()
        }))
    }
}

/// Any argmin problem giving residuals ([`Operator`] from `DVector<f64>` to `DVector<f64>`)
/// and their Jacobian ([`Jacobian`], a `DMatrix<f64>`) seen as fitbead's [`Residuals`], so
/// that fitbead's bounded Levenberg–Marquardt ([`super::fit`]) fits it. An error of either
/// method, a result of the wrong shape, or a non-finite entry is an [`Infeasible`] point (a
/// rejected step).
///
/// ```
/// use argmin::core::{Error, Jacobian, Operator};
/// use fitbead::inverse::{fit, ArgminResiduals, LsqOptions};
/// use nalgebra::{DMatrix, DVector};
/// /// r_i = y_i − a e^(−b x_i) at x = 0, 1, …, 7.
/// struct Decay(Vec<f64>);
/// impl Operator for Decay {
///     type Param = DVector<f64>;
///     type Output = DVector<f64>;
///     fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
///         Ok(DVector::from_fn(self.0.len(), |i, _| self.0[i] - p[0] * (-p[1] * i as f64).exp()))
///     }
/// }
/// impl Jacobian for Decay {
///     type Param = DVector<f64>;
///     type Jacobian = DMatrix<f64>;
///     fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
///         Ok(DMatrix::from_fn(self.0.len(), 2, |i, j| {
///             let (x, e) = (i as f64, (-p[1] * i as f64).exp());
///             if j == 0 { -e } else { p[0] * x * e }
///         }))
///     }
/// }
/// let y = (0..8).map(|i| 2.0 * (-0.3 * i as f64).exp()).collect();
/// let f = fit(&ArgminResiduals::new(Decay(y), 2, 8), &[1.0, 1.0], &LsqOptions::default())
///     .unwrap();
/// assert!((f.params[0] - 2.0).abs() < 1e-12 && (f.params[1] - 0.3).abs() < 1e-12);
/// ```
#[derive(Debug, Clone)]
pub struct ArgminResiduals<P> {
    problem: P,
    n_params: usize,
    n_residuals: usize,
}

impl<P> ArgminResiduals<P> {
    /// `problem`, of `n_params` parameters and `n_residuals` residuals.
    pub fn new(problem: P, n_params: usize, n_residuals: usize) -> Self {
        ArgminResiduals {
            problem,
            n_params,
            n_residuals,
        }
    }

    /// The argmin problem.
    pub fn inner(&self) -> &P {
        &self.problem
    }

    /// The argmin problem, given back.
    pub fn into_inner(self) -> P {
        self.problem
    }
}

impl<P> Residuals for ArgminResiduals<P>
where
    P: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    fn n_params(&self) -> usize {
        self.n_params
    }

    fn n_residuals(&self) -> usize {
        self.n_residuals
    }

    /// [`Operator::apply`] at `p`.
    fn residuals(&self, p: &[f64], out: &mut [f64]) -> Result<(), Infeasible> {
        let r = self
            .problem
            .apply(&DVector::from_column_slice(p))
            .map_err(|_| Infeasible)?;
        if r.len() != out.len() {
            return Err(Infeasible);
        }
        out.copy_from_slice(r.as_slice());
        Ok(())
    }

    /// [`Jacobian::jacobian`] at `p`.
    fn jacobian(&self, p: &[f64], mut out: MatMut<'_, f64>) -> Option<Result<(), Infeasible>> {
        let jac = match self.problem.jacobian(&DVector::from_column_slice(p)) {
            Ok(j) => j,
            Err(_) => return Some(Err(Infeasible)),
        };
        if jac.nrows() != out.nrows() || jac.ncols() != out.ncols() {
            return Some(Err(Infeasible));
        }
        for j in 0..jac.ncols() {
            for i in 0..jac.nrows() {
                out[(i, j)] = jac[(i, j)];
            }
        }
        Some(Ok(()))
    }
}

/// Residual and Jacobian evaluation with counting, finiteness checks and finite differences
/// (central, h = ε^{1/3}·max(|p|, typical); second-order one-sided next to a bound or an
/// infeasible point). It owns its work space and counts; the problem is passed to each call.
#[derive(Debug, Clone)]
pub(crate) struct Evaluator {
    pub m: usize,
    pub n: usize,
    pub nfev: usize,
    pub njev: usize,
    /// Analytic Jacobian evaluations (of `njev`).
    pub analytic: usize,
    /// Whether the last Jacobian came by finite differences.
    pub differenced: bool,
    /// Work space of the finite differences (m, m and n), allocated by the first of them.
    work: Vec<f64>,
    work2: Vec<f64>,
    xp: Vec<f64>,
}

impl Evaluator {
    pub fn new(m: usize, n: usize) -> Self {
        Evaluator {
            m,
            n,
            nfev: 0,
            njev: 0,
            analytic: 0,
            differenced: false,
            work: Vec::new(),
            work2: Vec::new(),
            xp: Vec::new(),
        }
    }

    /// Residuals at `x`; false if infeasible or not finite.
    pub fn residuals(&mut self, ls: View<'_>, x: &[f64], out: &mut [f64]) -> bool {
        self.nfev += 1;
        match ls.problem.residuals(x, out) {
            Ok(()) => out.iter().all(|v| v.is_finite()),
            Err(Infeasible) => false,
        }
    }

    /// Jacobian at `x` (where the residuals are `f`); false if it cannot be formed.
    pub fn jacobian(&mut self, ls: View<'_>, x: &[f64], f: &[f64], jac: &mut Mat<f64>) -> bool {
        self.njev += 1;
        self.differenced = false;
        let analytic = ls.problem.jacobian(x, jac.as_mut());
        if analytic.is_some() {
            self.analytic += 1;
        }
        match analytic {
            Some(Ok(())) => {
                for j in 0..self.n {
                    for i in 0..self.m {
                        if !jac[(i, j)].is_finite() {
                            return false;
                        }
                    }
                }
                true
            }
            Some(Err(Infeasible)) => false,
            None => {
                self.differenced = true;
                self.differences(ls, x, f, jac)
                    && (0..self.n).all(|j| (0..self.m).all(|i| jac[(i, j)].is_finite()))
            }
        }
    }

    /// Evaluates at x with component j replaced by v (within bounds); the residuals go to
    /// `work` (`second = false`) or `work2`.
    fn probe(&mut self, ls: View<'_>, x: &[f64], j: usize, v: f64, second: bool) -> bool {
        if !(v >= ls.setup.lower[j] && v <= ls.setup.upper[j]) {
            return false;
        }
        self.xp.copy_from_slice(x);
        self.xp[j] = v;
        let xp = std::mem::take(&mut self.xp);
        let mut out = std::mem::take(if second {
            &mut self.work2
        } else {
            &mut self.work
        });
        let ok = self.residuals(ls, &xp, &mut out);
        self.xp = xp;
        if second {
            self.work2 = out;
        } else {
            self.work = out;
        }
        ok
    }

    fn differences(&mut self, ls: View<'_>, x: &[f64], f: &[f64], jac: &mut Mat<f64>) -> bool {
        if self.xp.len() != self.n {
            self.work = vec![0.0; self.m];
            self.work2 = vec![0.0; self.m];
            self.xp = vec![0.0; self.n];
        }
        let eta = f64::EPSILON.cbrt();
        for j in 0..self.n {
            let xj = x[j];
            let (room_up, room_dn) = (ls.setup.upper[j] - xj, xj - ls.setup.lower[j]);
            if !(room_up > 0.0 || room_dn > 0.0) {
                // A parameter held fixed by its bounds: it cannot move.
                for i in 0..self.m {
                    jac[(i, j)] = 0.0;
                }
                continue;
            }
            let mut h0 = eta * xj.abs().max(ls.setup.typical[j]);
            if room_up < h0 && room_dn < h0 {
                // A box narrower than the step: difference across the wider side.
                h0 = room_up.max(room_dn);
            }
            // The divisors below are the differences of the points actually used.
            let up = xj + h0;
            let dn = xj - h0;
            let ok_up = self.probe(ls, x, j, up, false);
            let ok_dn = self.probe(ls, x, j, dn, true);
            if ok_up && ok_dn {
                let h = up - dn;
                for i in 0..self.m {
                    jac[(i, j)] = (self.work[i] - self.work2[i]) / h;
                }
                continue;
            }
            // One-sided, second order if the second point is available, else first order.
            let (sign, h) = if ok_up {
                (1.0, up - xj)
            } else if ok_dn {
                // Move the backward residuals into `work`.
                std::mem::swap(&mut self.work, &mut self.work2);
                (-1.0, xj - dn)
            } else {
                return false;
            };
            let far = xj + sign * 2.0 * h;
            if self.probe(ls, x, j, far, true) {
                for i in 0..self.m {
                    jac[(i, j)] =
                        sign * (4.0 * self.work[i] - 3.0 * f[i] - self.work2[i]) / (2.0 * h);
                }
            } else {
                for i in 0..self.m {
                    jac[(i, j)] = sign * (self.work[i] - f[i]) / h;
                }
            }
        }
        true
    }
}
