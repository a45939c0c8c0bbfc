//! The Levenberg–Marquardt parameter and the damped least-squares subproblem (Moré 1978, §§3–5;
//! the algorithms `lmpar` and `qrsolv` of MINPACK-1).
//!
//! Given the QR factorisation with column pivoting J·P = Q·R of the Jacobian (done with faer by
//! the caller), the diagonal scaling D and the trust-region radius Δ, [`lm_step`] finds λ ≥ 0 and
//! the step x solving
//!
//! ```text
//!     min ‖ [J; √λ·D] x − [f; 0] ‖   with   ‖D x‖ ≈ Δ   (|‖Dx‖ − Δ| ≤ 0.1 Δ), or λ = 0 if the
//!                                                       Gauss–Newton step is already inside,
//! ```
//!
//! by the Hebden/Moré safeguarded Newton iteration on φ(λ) = ‖D x(λ)‖ − Δ. Each trial λ needs the
//! QR factorisation of the augmented, scaled matrix [R; √λ·Pᵀ D P]: since R is already
//! triangular only the n rows of the diagonal are eliminated, by Givens rotations (`qrsolv`),
//! in O(n²) per row — the normal equations are never formed.
//!
//! The matrices here are tiny (n × n with n the number of free parameters), stored column-major
//! in plain slices: `r[i + j * n]`.

// Index loops mirror the subscripts of the published algorithm (MINPACK-1).
#![allow(clippy::needless_range_loop)]

/// Workspace and result of one subproblem solve.
#[derive(Debug, Clone)]
pub(crate) struct Subproblem {
    n: usize,
    /// On entry (in [`lm_step`]) the upper triangle holds R; the strict lower triangle is
    /// overwritten with Sᵀ, the triangular factor of the augmented system, whose diagonal is
    /// `sdiag`.
    pub r: Vec<f64>,
    /// Diagonal of S.
    pub sdiag: Vec<f64>,
    /// The step (to be negated by the caller: it solves J x ≈ f).
    pub x: Vec<f64>,
    wa1: Vec<f64>,
    wa2: Vec<f64>,
    wa: Vec<f64>,
}

fn enorm(v: &[f64]) -> f64 {
    // Scaled two-norm: no overflow or underflow for any finite entries.
    let amax = v.iter().fold(0.0f64, |a, &x| a.max(x.abs()));
    if amax == 0.0 || !amax.is_finite() {
        return amax;
    }
    let s: f64 = v.iter().map(|&x| (x / amax) * (x / amax)).sum();
    amax * s.sqrt()
}

pub(crate) fn norm2(v: &[f64]) -> f64 {
    enorm(v)
}

impl Subproblem {
    pub fn new(n: usize) -> Self {
        Subproblem {
            n,
            r: vec![0.0; n * n],
            sdiag: vec![0.0; n],
            x: vec![0.0; n],
            wa1: vec![0.0; n],
            wa2: vec![0.0; n],
            wa: vec![0.0; n],
        }
    }

    #[inline]
    fn at(&self, i: usize, j: usize) -> f64 {
        self.r[i + j * self.n]
    }

    /// `qrsolv`: solves min ‖[R·Pᵀ; D] x − [qtb; 0]‖ given R (upper triangle of `self.r`),
    /// the pivot `ipvt` (column j of J·P is column `ipvt[j]` of J) and the diagonal `diag` of D
    /// (already multiplied by √λ). Leaves Sᵀ in the strict lower triangle of `r` and diag(S) in
    /// `sdiag`; the upper triangle of R is preserved.
    fn qrsolv(&mut self, ipvt: &[usize], diag: &[f64], qtb: &[f64]) {
        let n = self.n;
        // Copy R and Qᵀb; save the diagonal of R in x.
        for j in 0..n {
            for i in j..n {
                self.r[i + j * n] = self.r[j + i * n];
            }
            self.x[j] = self.r[j + j * n];
            self.wa[j] = qtb[j];
        }
        // Eliminate the diagonal matrix D with Givens rotations.
        for j in 0..n {
            let l = ipvt[j];
            if diag[l] != 0.0 {
                for k in j..n {
                    self.sdiag[k] = 0.0;
                }
                self.sdiag[j] = diag[l];
                // The rotations that eliminate this row of D change only one element of
                // (Qᵀb, 0) beyond the first n, which starts at zero.
                let mut qtbpj = 0.0;
                for k in j..n {
                    if self.sdiag[k] == 0.0 {
                        continue;
                    }
                    let rkk = self.r[k + k * n];
                    let (cos, sin) = if rkk.abs() < self.sdiag[k].abs() {
                        let cotan = rkk / self.sdiag[k];
                        let sin = 0.5 / (0.25 + 0.25 * cotan * cotan).sqrt();
                        (sin * cotan, sin)
                    } else {
                        let tan = self.sdiag[k] / rkk;
                        let cos = 0.5 / (0.25 + 0.25 * tan * tan).sqrt();
                        (cos, cos * tan)
                    };
                    self.r[k + k * n] = cos * rkk + sin * self.sdiag[k];
                    let temp = cos * self.wa[k] + sin * qtbpj;
                    qtbpj = -sin * self.wa[k] + cos * qtbpj;
                    self.wa[k] = temp;
                    for i in (k + 1)..n {
                        let rik = self.r[i + k * n];
                        let temp = cos * rik + sin * self.sdiag[i];
                        self.sdiag[i] = -sin * rik + cos * self.sdiag[i];
                        self.r[i + k * n] = temp;
                    }
                }
            }
            // Store the diagonal of S and restore the diagonal of R.
            self.sdiag[j] = self.r[j + j * n];
            self.r[j + j * n] = self.x[j];
        }
        // Solve S z = wa; least-squares solution if S is singular.
        let mut nsing = n;
        for j in 0..n {
            if self.sdiag[j] == 0.0 && nsing == n {
                nsing = j;
            }
            if nsing < n {
                self.wa[j] = 0.0;
            }
        }
        for j in (0..nsing).rev() {
            let mut sum = 0.0;
            for i in (j + 1)..nsing {
                sum += self.r[i + j * n] * self.wa[i];
            }
            self.wa[j] = (self.wa[j] - sum) / self.sdiag[j];
        }
        for j in 0..n {
            self.x[ipvt[j]] = self.wa[j];
        }
    }

    /// `lmpar`: the Levenberg–Marquardt parameter for radius `delta`, starting from the guess
    /// `par` (the previous iteration's). Returns the new λ; the step is left in `self.x`
    /// (it solves J x ≈ f, so the caller moves by −x).
    pub fn lm_step(
        &mut self,
        ipvt: &[usize],
        diag: &[f64],
        qtb: &[f64],
        delta: f64,
        par: f64,
    ) -> f64 {
        let n = self.n;
        let dwarf = f64::MIN_POSITIVE;
        let mut par = par;

        let nsing = self.gauss_newton_direction(ipvt, qtb);

        // Accept the Gauss–Newton step if it is inside (or close to) the trust region.
        for j in 0..n {
            self.wa2[j] = diag[j] * self.x[j];
        }
        let mut dxnorm = enorm(&self.wa2);
        let mut fp = dxnorm - delta;
        if fp <= 0.1 * delta {
            // Leave the factor Sᵀ undefined: the caller does not use it when λ = 0.
            return 0.0;
        }

        // Lower bound parl on λ (zero if R is singular).
        let mut parl = if nsing >= n {
            self.lower_bound(ipvt, diag, dxnorm, fp, delta)
        } else {
            0.0
        };

        // Upper bound paru.
        let gnorm = self.scaled_gradient_norm(ipvt, diag, qtb);
        let mut paru = gnorm / delta;
        if paru == 0.0 {
            paru = dwarf / delta.min(0.1);
        }

        // Start inside [parl, paru].
        par = par.max(parl).min(paru);
        if par == 0.0 {
            par = gnorm / dxnorm;
        }

        let mut iter = 0;
        loop {
            iter += 1;
            if par == 0.0 {
                par = dwarf.max(0.001 * paru);
            }
            let sq = par.sqrt();
            let scaled: Vec<f64> = diag.iter().map(|&d| sq * d).collect();
            self.qrsolv(ipvt, &scaled, qtb);
            for j in 0..n {
                self.wa2[j] = diag[j] * self.x[j];
            }
            dxnorm = enorm(&self.wa2);
            let temp = fp;
            fp = dxnorm - delta;

            // Stop when ‖Dx‖ is within 10 % of Δ, or when parl = 0 and φ increases through
            // negative values (the root is at λ = 0 from the right), or after 10 iterations.
            if fp.abs() <= 0.1 * delta || (parl == 0.0 && fp <= temp && temp < 0.0) || iter == 10 {
                break;
            }

            // Newton correction.
            for j in 0..n {
                let l = ipvt[j];
                self.wa1[j] = diag[l] * (self.wa2[l] / dxnorm);
            }
            for j in 0..n {
                self.wa1[j] /= self.sdiag[j];
                let temp = self.wa1[j];
                for i in (j + 1)..n {
                    self.wa1[i] -= self.r[i + j * n] * temp;
                }
            }
            let temp = enorm(&self.wa1);
            let parc = ((fp / delta) / temp) / temp;

            if fp > 0.0 {
                parl = parl.max(par);
            }
            if fp < 0.0 {
                paru = paru.min(par);
            }
            par = parl.max(par + parc);
            if !par.is_finite() {
                par = parl;
            }
        }
        par
    }

    /// The Gauss–Newton direction into `x` (the least-squares solution when R is rank
    /// deficient: the components from the first zero on R's diagonal on are zero); the rank
    /// found, `nsing`.
    fn gauss_newton_direction(&mut self, ipvt: &[usize], qtb: &[f64]) -> usize {
        let n = self.n;
        let mut nsing = n;
        for j in 0..n {
            self.wa1[j] = qtb[j];
            if self.at(j, j) == 0.0 && nsing == n {
                nsing = j;
            }
            if nsing < n {
                self.wa1[j] = 0.0;
            }
        }
        for j in (0..nsing).rev() {
            self.wa1[j] /= self.at(j, j);
            let temp = self.wa1[j];
            for i in 0..j {
                self.wa1[i] -= self.at(i, j) * temp;
            }
        }
        for j in 0..n {
            self.x[ipvt[j]] = self.wa1[j];
        }
        nsing
    }

    /// MINPACK's lower bound parl on λ for a full-rank R, from the Gauss–Newton step's scaled
    /// norm `dxnorm` (its scaled components in `wa2`) and φ = `fp` at λ = 0; 0 where it is
    /// not finite.
    fn lower_bound(
        &mut self,
        ipvt: &[usize],
        diag: &[f64],
        dxnorm: f64,
        fp: f64,
        delta: f64,
    ) -> f64 {
        let n = self.n;
        for j in 0..n {
            let l = ipvt[j];
            self.wa1[j] = diag[l] * (self.wa2[l] / dxnorm);
        }
        for j in 0..n {
            let mut sum = 0.0;
            for i in 0..j {
                sum += self.at(i, j) * self.wa1[i];
            }
            self.wa1[j] = (self.wa1[j] - sum) / self.at(j, j);
        }
        let temp = enorm(&self.wa1);
        let parl = ((fp / delta) / temp) / temp;
        if parl.is_finite() {
            parl
        } else {
            0.0
        }
    }

    /// ‖D⁻¹ (QR)ᵀ Qᵀb‖, the norm of the scaled gradient, whose ratio to Δ is MINPACK's upper
    /// bound paru on λ.
    fn scaled_gradient_norm(&mut self, ipvt: &[usize], diag: &[f64], qtb: &[f64]) -> f64 {
        for j in 0..self.n {
            let mut sum = 0.0;
            for i in 0..=j {
                sum += self.at(i, j) * qtb[i];
            }
            let l = ipvt[j];
            self.wa1[j] = sum / diag[l];
        }
        enorm(&self.wa1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The subproblem solution must satisfy the normal equations of the damped problem
    /// (RᵀR + λ D²) x = Rᵀ qtb, with R here already in pivoted order (identity pivot).
    #[test]
    fn step_satisfies_damped_normal_equations() {
        let n = 3;
        let mut sp = Subproblem::new(n);
        // Upper-triangular R, column-major.
        let r = [2.0, 0.0, 0.0, 1.0, 3.0, 0.0, -0.5, 0.25, 0.7];
        sp.r.copy_from_slice(&r);
        let ipvt = [0, 1, 2];
        let diag = [1.0, 2.0, 0.5];
        let qtb = [1.0, -2.0, 3.0];
        let delta = 0.3;
        let par = sp.lm_step(&ipvt, &diag, &qtb, delta, 0.0);
        assert!(par > 0.0);
        let x = sp.x.clone();
        // ‖D x‖ ≈ Δ within 10 %.
        let dx: Vec<f64> = (0..n).map(|j| diag[j] * x[j]).collect();
        assert!((enorm(&dx) - delta).abs() <= 0.1 * delta);
        // (RᵀR + λD²) x − Rᵀ qtb = 0
        let rr = |i: usize, j: usize| if i <= j { r[i + j * n] } else { 0.0 };
        for k in 0..n {
            let mut lhs = par * diag[k] * diag[k] * x[k];
            let mut rhs = 0.0;
            for i in 0..n {
                let mut rx = 0.0;
                for j in 0..n {
                    rx += rr(i, j) * x[j];
                }
                lhs += rr(i, k) * rx;
                rhs += rr(i, k) * qtb[i];
            }
            assert!((lhs - rhs).abs() < 1e-12, "{lhs} vs {rhs}");
        }
    }
}
