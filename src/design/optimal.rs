//! Approximate designs over a grid of candidate slopes and their rounding to whole points:
//! the multiplicative algorithm (D and c criteria), the Atkinson–Fedorov iteration (T
//! criterion) and the efficient rounding of Pukelsheim & Rieder (1992).
//!
//! Every design here is stratified: the candidates fall into strata (one per series) and the
//! weights of stratum s add up to its budget n_s (points per series). The Kiefer–Wolfowitz
//! equivalence conditions then hold stratum by stratum: at the optimum, the sensitivity ψ_j of
//! each candidate (d_j = g_jᵀ M⁻¹ g_j for D, (cᵀ M⁻¹ g_j)² for c, the squared distance of the
//! two models' curves for T) is at most its stratum's weighted mean λ_s = Σ_{j∈s} w_j ψ_j / n_s,
//! with equality on the support. The largest ψ_j/λ_s − 1 is the design's equivalence gap.

use nalgebra::{DMatrix, DVector};

/// One candidate point: its series, slope (radians), scaled gradient g = (∂v̄/∂p)/σ and that
/// σ (in the design's units; +∞ where the point tells nothing).
#[derive(Debug, Clone)]
pub(crate) struct Cand {
    pub series: usize,
    pub delta: f64,
    pub g: Vec<f64>,
    pub sigma: f64,
}

/// An approximate design: weights, each candidate's sensitivity divided by its stratum's λ_s,
/// and the equivalence gap reached.
#[derive(Debug, Clone)]
pub(crate) struct Approx {
    pub w: Vec<f64>,
    pub sens: Vec<f64>,
    pub gap: f64,
}

/// The information matrix M = Σ_j w_j g_j g_jᵀ.
pub(crate) fn information(cands: &[Cand], w: &[f64], p: usize) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(p, p);
    for (c, &wj) in cands.iter().zip(w) {
        if wj == 0.0 {
            continue;
        }
        let g = DVector::from_column_slice(&c.g);
        m += wj * &g * g.transpose();
    }
    m
}

/// M⁻¹ of a positive semi-definite M, scaled to a unit diagonal and lifted by a ridge of
/// 1e-10 so that a singular M (a c-optimal design may support fewer points than parameters)
/// still inverts.
fn inverse(m: &DMatrix<f64>) -> DMatrix<f64> {
    let p = m.nrows();
    let d: Vec<f64> = (0..p)
        .map(|i| {
            let x = m[(i, i)];
            if x > 0.0 {
                1.0 / x.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let dm = DMatrix::from_diagonal(&DVector::from_vec(d));
    let a = &dm * m * &dm + DMatrix::identity(p, p) * 1e-10;
    let ai = a
        .cholesky()
        .map(|c| c.inverse())
        .unwrap_or_else(|| DMatrix::identity(p, p) * 1e10);
    &dm * ai * &dm
}

/// The variance of each parameter under information M (the diagonal of its pseudo-inverse),
/// `None` for a parameter M does not determine (its unit vector not in M's range). M is
/// scaled to a unit diagonal first; eigenvalues below 1e-10 of the largest count as zero.
pub(crate) fn variances(m: &DMatrix<f64>) -> Vec<Option<f64>> {
    let p = m.nrows();
    let diag: Vec<f64> = (0..p).map(|i| m[(i, i)]).collect();
    let d: Vec<f64> = diag
        .iter()
        .map(|&x| if x > 0.0 { 1.0 / x.sqrt() } else { 0.0 })
        .collect();
    let dm = DMatrix::from_diagonal(&DVector::from_vec(d.clone()));
    let a = &dm * m * &dm;
    let e = a.symmetric_eigen();
    let top = e.eigenvalues.iter().cloned().fold(0.0, f64::max);
    (0..p)
        .map(|k| {
            if !(diag[k] > 0.0 && top > 0.0) {
                return None;
            }
            let (mut var, mut null) = (0.0, 0.0);
            for i in 0..p {
                let u = e.eigenvectors[(k, i)];
                if e.eigenvalues[i] > 1e-10 * top {
                    var += u * u / e.eigenvalues[i];
                } else {
                    null += u * u;
                }
            }
            (null < 1e-8).then_some(var * d[k] * d[k])
        })
        .collect()
}

/// One draw of the parameters (the guess, for a locally optimal design): the candidates with
/// their scaled gradients there (zero where the model has no steady state at that draw), and
/// the gradient c of the c criterion's target there.
#[derive(Debug, Clone)]
pub(crate) struct Draw {
    pub cands: Vec<Cand>,
    pub c: Vec<f64>,
}

/// The optimality criterion of the multiplicative algorithm, averaged over the draws.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Crit {
    /// E[log det M].
    D,
    /// −E[cᵀ M⁻¹ c]: the variance of the target cᵀp.
    C,
}

/// Most iterations of the multiplicative algorithm.
const MAX_ITER: usize = 5000;
/// Equivalence gap at which the iteration stops.
const GAP_TOL: f64 = 1e-4;

/// The stratified multiplicative algorithm (Titterington 1976, Silvey, Titterington & Torsney
/// 1978): w_j ← w_j (ψ_j/λ_s)^r within each stratum s, renormalised to n_s, with r = 1 for D
/// (where the update keeps the budget by itself) and r = ½ for c (Fellman's square-root
/// update, which keeps the c iteration from oscillating). ψ_j is the derivative of the
/// criterion in w_j, averaged over the draws: E[g_jᵀ M⁻¹ g_j] for D, E[(cᵀ M⁻¹ g_j)²] for c.
/// Starts from equal weights.
pub(crate) fn multiplicative(
    draws: &[Draw],
    strata: &[Vec<usize>],
    budgets: &[f64],
    p: usize,
    crit: Crit,
) -> Approx {
    let n_cand = draws[0].cands.len();
    let mut w = vec![0.0; n_cand];
    for (st, &n) in strata.iter().zip(budgets) {
        for &j in st {
            w[j] = n / st.len() as f64;
        }
    }
    let mut sens = vec![0.0; n_cand];
    let mut gap = f64::INFINITY;
    let nd = draws.len() as f64;
    let gs: Vec<Vec<DVector<f64>>> = draws
        .iter()
        .map(|d| {
            d.cands
                .iter()
                .map(|c| DVector::from_column_slice(&c.g))
                .collect()
        })
        .collect();
    // ψ of every candidate at one draw.
    let psi = |i: usize, w: &[f64]| -> Vec<f64> {
        let d = &draws[i];
        let mi = inverse(&information(&d.cands, w, p));
        let c = DVector::from_column_slice(&d.c);
        let mut h = DVector::zeros(p);
        gs[i]
            .iter()
            .map(|g| {
                mi.mul_to(g, &mut h);
                match crit {
                    Crit::D => g.dot(&h),
                    Crit::C => {
                        let x = c.dot(&h);
                        x * x
                    }
                }
            })
            .collect()
    };
    for _ in 0..MAX_ITER {
        let per_draw: Vec<Vec<f64>> = if draws.len() == 1 {
            vec![psi(0, &w)]
        } else {
            use rayon::prelude::*;
            (0..draws.len())
                .into_par_iter()
                .map(|i| psi(i, &w))
                .collect()
        };
        sens.iter_mut().for_each(|x| *x = 0.0);
        for v in &per_draw {
            for (x, y) in sens.iter_mut().zip(v) {
                *x += y;
            }
        }
        sens.iter_mut().for_each(|x| *x /= nd);
        gap = normalise(strata, budgets, &w, &mut sens);
        if gap < GAP_TOL {
            break;
        }
        let r = match crit {
            Crit::D => 1.0,
            Crit::C => 0.5,
        };
        for (st, &n) in strata.iter().zip(budgets) {
            let sum: f64 = st.iter().map(|&j| w[j] * sens[j].powf(r)).sum();
            // A series that carries no information on the criterion (the target is another
            // series' own parameter) keeps its weights.
            if sum > 0.0 {
                for &j in st {
                    w[j] *= sens[j].powf(r) * n / sum;
                }
            }
        }
    }
    Approx { w, sens, gap }
}

/// Loss of a draw whose information leaves the criterion undefined (M singular for D, the
/// target undetermined for c): larger than any defined loss, so that a design with fewer such
/// draws is always better.
const UNDEFINED_LOSS: f64 = 1e30;

/// The averaged criterion of an exact design with `n[j]` points at candidate j, as a loss:
/// E[−log det M] (D) or E[cᵀ M⁺ c] (c), each draw where it is undefined counting
/// [`UNDEFINED_LOSS`].
fn exact_loss(draws: &[Draw], n: &[usize], p: usize, crit: Crit) -> f64 {
    let support: Vec<usize> = (0..n.len()).filter(|&j| n[j] > 0).collect();
    let mut sum = 0.0;
    for d in draws {
        let mut m = DMatrix::zeros(p, p);
        for &j in &support {
            let g = DVector::from_column_slice(&d.cands[j].g);
            m += n[j] as f64 * &g * g.transpose();
        }
        sum += match crit {
            Crit::D => match m.cholesky() {
                Some(ch) => -2.0 * ch.l().diagonal().iter().map(|x| x.ln()).sum::<f64>(),
                None => UNDEFINED_LOSS,
            },
            Crit::C => variance_of(&m, &d.c).unwrap_or(UNDEFINED_LOSS),
        };
    }
    sum / draws.len() as f64
}

/// Most sweeps of [`exchange`].
const EXCHANGE_SWEEPS: usize = 20;

/// Point exchange on an exact design (Fedorov 1972) under the criterion averaged over the
/// draws: each sweep moves the one point, from a support slope to any candidate of the same
/// stratum, that lowers [`exact_loss`] the most, until no move lowers it by more than 1e-9
/// of itself (at most 20 sweeps). A Bayesian design's approximate weights spread over a band
/// of slopes, which the rounding merges into one slope; the exchange restores the hedge the
/// draws need. Returns the design as (candidate, replicates) per stratum.
pub(crate) fn exchange(
    draws: &[Draw],
    strata: &[Vec<usize>],
    design: &[Vec<(usize, usize)>],
    p: usize,
    crit: Crit,
) -> Vec<Vec<(usize, usize)>> {
    use rayon::prelude::*;
    let mut n = vec![0usize; draws[0].cands.len()];
    for &(j, k) in design.iter().flatten() {
        n[j] = k;
    }
    let mut loss = exact_loss(draws, &n, p, crit);
    for _ in 0..EXCHANGE_SWEEPS {
        let moves: Vec<(usize, usize)> = strata
            .iter()
            .flat_map(|st| {
                let from: Vec<usize> = st.iter().copied().filter(|&j| n[j] > 0).collect();
                from.into_iter().flat_map(move |a| {
                    st.iter()
                        .copied()
                        .filter(move |&b| b != a)
                        .map(move |b| (a, b))
                })
            })
            .collect();
        let best = moves
            .par_iter()
            .map(|&(a, b)| {
                let mut m = n.clone();
                m[a] -= 1;
                m[b] += 1;
                (exact_loss(draws, &m, p, crit), a, b)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold(None, |acc: Option<(f64, usize, usize)>, x| match acc {
                Some(y) if y.0 <= x.0 => Some(y),
                _ => Some(x),
            });
        match best {
            Some((l, a, b)) if l < loss - 1e-9 * loss.abs() => {
                n[a] -= 1;
                n[b] += 1;
                loss = l;
            }
            _ => break,
        }
    }
    strata
        .iter()
        .map(|st| {
            st.iter()
                .filter(|&&j| n[j] > 0)
                .map(|&j| (j, n[j]))
                .collect()
        })
        .collect()
}

/// The variance cᵀ M⁺ c of the estimate of cᵀp under information M, `None` where M does not
/// determine it (c not in M's range), scaled and thresholded as in [`variances`].
pub(crate) fn variance_of(m: &DMatrix<f64>, c: &[f64]) -> Option<f64> {
    let p = m.nrows();
    let diag: Vec<f64> = (0..p).map(|i| m[(i, i)]).collect();
    let d: Vec<f64> = diag
        .iter()
        .map(|&x| if x > 0.0 { 1.0 / x.sqrt() } else { 0.0 })
        .collect();
    // A direction M knows nothing of must carry no weight in c.
    if (0..p).any(|i| d[i] == 0.0 && c[i] != 0.0) {
        return None;
    }
    let dm = DMatrix::from_diagonal(&DVector::from_vec(d.clone()));
    let a = &dm * m * &dm;
    let e = a.symmetric_eigen();
    let top = e.eigenvalues.iter().cloned().fold(0.0, f64::max);
    if !(top > 0.0) {
        return None;
    }
    // M⁺ = D A⁺ D with A = D M D, so cᵀ M⁺ c = (Dc)ᵀ A⁺ (Dc).
    let cs: Vec<f64> = (0..p).map(|i| c[i] * d[i]).collect();
    let norm: f64 = cs.iter().map(|x| x * x).sum();
    let (mut var, mut null) = (0.0, 0.0);
    for i in 0..p {
        let u: f64 = (0..p).map(|k| e.eigenvectors[(k, i)] * cs[k]).sum();
        if e.eigenvalues[i] > 1e-10 * top {
            var += u * u / e.eigenvalues[i];
        } else {
            null += u * u;
        }
    }
    (null < 1e-8 * norm).then_some(var)
}

/// Divides each sensitivity by its stratum's λ_s = Σ w_j ψ_j / n_s; returns the largest
/// ψ_j/λ_s − 1 (the equivalence gap).
fn normalise(strata: &[Vec<usize>], budgets: &[f64], w: &[f64], sens: &mut [f64]) -> f64 {
    let mut gap: f64 = 0.0;
    for (st, &n) in strata.iter().zip(budgets) {
        let lambda: f64 = st.iter().map(|&j| w[j] * sens[j]).sum::<f64>() / n;
        for &j in st {
            sens[j] = if lambda > 0.0 { sens[j] / lambda } else { 0.0 };
            gap = gap.max(sens[j] - 1.0);
        }
    }
    gap
}

/// The Atkinson–Fedorov iteration for T-optimality (Atkinson & Fedorov 1975): at step k the
/// rival model is fitted to the true model's curve under the current weights (`fit`), the
/// squared distances ψ_j of the two curves (divided by σ²) are computed at that fit (`psi`),
/// and each stratum moves a step α_k = 1/(k + 1) of its budget to its candidate of largest
/// ψ_j (a Fedorov–Wynn vertex step). Starts from `start`.
pub(crate) fn t_optimal(
    strata: &[Vec<usize>],
    budgets: &[f64],
    start: Vec<f64>,
    steps: usize,
    mut fit: impl FnMut(&[f64]) -> Option<Vec<f64>>,
) -> Option<Approx> {
    let mut w = start;
    let mut sens = fit(&w)?;
    for k in 1..=steps {
        let alpha = 1.0 / (k as f64 + 1.0);
        for (st, &n) in strata.iter().zip(budgets) {
            let best = *st
                .iter()
                .max_by(|&&a, &&b| sens[a].total_cmp(&sens[b]))
                .expect("a stratum has candidates");
            for &j in st {
                w[j] *= 1.0 - alpha;
                if w[j] < 1e-9 * n {
                    w[j] = 0.0;
                }
            }
            w[best] += alpha * n;
        }
        sens = fit(&w)?;
    }
    let gap = normalise(strata, budgets, &w, &mut sens);
    Some(Approx { w, sens, gap })
}

/// The exact design of each stratum: the runs of neighbouring candidates of one series
/// (`series`: the series of each candidate) that carry weight (above 1e-3 of the stratum's
/// largest) each become one support point, at the candidate of
/// the run with the largest sensitivity and with the run's weight; the heaviest n_s of them
/// are kept and rounded to n_s points by efficient rounding (Pukelsheim & Rieder 1992):
/// m_i = ⌈(n − ℓ/2) w_i⌉, then points are added where m_i/w_i is smallest, or taken away
/// where (m_i − 1)/w_i is largest, until they add up to n. Returns (candidate, replicates).
pub(crate) fn round(
    strata: &[Vec<usize>],
    budgets: &[usize],
    a: &Approx,
    series: &[usize],
) -> Vec<Vec<(usize, usize)>> {
    strata
        .iter()
        .zip(budgets)
        .map(|(st, &n)| {
            let top = st.iter().map(|&j| a.w[j]).fold(0.0, f64::max);
            if !(top > 0.0) || st.iter().all(|&j| !(a.sens[j] > 0.0)) {
                return spread(st, n);
            }
            let mut runs: Vec<(usize, f64)> = Vec::new();
            let mut open = false;
            let mut prev: Option<usize> = None;
            for &j in st {
                // A run never spans two series.
                if prev.is_some_and(|q| series[q] != series[j]) {
                    open = false;
                }
                prev = Some(j);
                if a.w[j] > 1e-3 * top {
                    if open {
                        let last = runs.last_mut().expect("an open run");
                        last.1 += a.w[j];
                        if a.sens[j] > a.sens[last.0] {
                            last.0 = j;
                        }
                    } else {
                        runs.push((j, a.w[j]));
                    }
                    open = true;
                } else {
                    open = false;
                }
            }
            runs.sort_by(|x, y| y.1.total_cmp(&x.1));
            runs.truncate(n);
            let sum: f64 = runs.iter().map(|r| r.1).sum();
            let w: Vec<f64> = runs.iter().map(|r| r.1 / sum).collect();
            let mut m = efficient_rounding(&w, n);
            let mut out: Vec<(usize, usize)> = runs
                .iter()
                .zip(m.drain(..))
                .filter(|(_, k)| *k > 0)
                .map(|(r, k)| (r.0, k))
                .collect();
            out.sort_by_key(|x| x.0);
            out
        })
        .collect()
}

/// n points spread evenly over a stratum's candidates (for a stratum whose slopes carry no
/// information on the criterion).
fn spread(st: &[usize], n: usize) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for i in 0..n {
        let k = if n == 1 {
            st.len() / 2
        } else {
            (i * (st.len() - 1) + (n - 1) / 2) / (n - 1)
        };
        match out.last_mut() {
            Some(last) if last.0 == st[k] => last.1 += 1,
            _ => out.push((st[k], 1)),
        }
    }
    out
}

/// Efficient rounding of the weights `w` (adding up to 1, at most `n` of them) to `n` points.
pub(crate) fn efficient_rounding(w: &[f64], n: usize) -> Vec<usize> {
    let l = w.len() as f64;
    let q = n as f64 - 0.5 * l;
    let mut m: Vec<usize> = w
        .iter()
        .map(|&x| (q * x).ceil().max(0.0) as usize)
        .collect();
    loop {
        let total: usize = m.iter().sum();
        if total == n {
            return m;
        }
        if total < n {
            let j = (0..w.len())
                .min_by(|&a, &b| (m[a] as f64 / w[a]).total_cmp(&(m[b] as f64 / w[b])))
                .expect("weights");
            m[j] += 1;
        } else {
            let j = (0..w.len())
                .filter(|&i| m[i] > 0)
                .max_by(|&a, &b| ((m[a] - 1) as f64 / w[a]).total_cmp(&((m[b] - 1) as f64 / w[b])))
                .expect("a positive count");
            m[j] -= 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule worked by hand: weights (1/6, 1/3, 1/2) and n = 7 give q = 7 − 3/2 = 5.5,
    /// ⌈5.5/6⌉ = 1, ⌈5.5/3⌉ = 2, ⌈5.5/2⌉ = 3: 6 points; the seventh goes where m/w is
    /// smallest (1·6 = 2·3 = 3·2 = 6, a tie, taken at the first index): (2, 2, 3).
    #[test]
    fn efficient_rounding_by_hand() {
        assert_eq!(
            efficient_rounding(&[1.0 / 6.0, 1.0 / 3.0, 0.5], 7),
            vec![2, 2, 3]
        );
        assert_eq!(efficient_rounding(&[1.0], 9), vec![9]);
        assert_eq!(efficient_rounding(&[0.5, 0.5], 9).iter().sum::<usize>(), 9);
    }

    /// The straight line y = a + b x on [−1, 1]: the D-optimal design is half the weight at
    /// each end (a textbook result, e.g. Atkinson, Donev & Tobias 2007, §9.2), and the
    /// c-optimal design for the slope b is the same.
    #[test]
    fn line_designs_put_the_points_at_the_ends() {
        let cands: Vec<Cand> = (0..101)
            .map(|i| {
                let x = -1.0 + 2.0 * i as f64 / 100.0;
                Cand {
                    series: 0,
                    delta: x,
                    g: vec![1.0, x],
                    sigma: 1.0,
                }
            })
            .collect();
        let strata = vec![(0..101).collect::<Vec<_>>()];
        let series = vec![0; 101];
        for crit in [Crit::D, Crit::C] {
            let a = multiplicative(&one(cands.clone(), 2, 1), &strata, &[10.0], 2, crit);
            let r = round(&strata, &[10], &a, &series);
            assert_eq!(r[0], vec![(0, 5), (100, 5)], "{crit:?}");
        }
    }

    /// A quadratic y = a + b x + c x² on [−1, 1]: D-optimal at −1, 0, 1 with weight 1/3 each
    /// (Atkinson, Donev & Tobias 2007, §11.2); 9 points round to 3 each.
    #[test]
    fn quadratic_d_design() {
        let cands: Vec<Cand> = (0..101)
            .map(|i| {
                let x = -1.0 + 2.0 * i as f64 / 100.0;
                Cand {
                    series: 0,
                    delta: x,
                    g: vec![1.0, x, x * x],
                    sigma: 1.0,
                }
            })
            .collect();
        let strata = vec![(0..101).collect::<Vec<_>>()];
        let a = multiplicative(&one(cands, 3, 0), &strata, &[9.0], 3, Crit::D);
        let r = round(&strata, &[9], &a, &[0; 101]);
        assert_eq!(r[0], vec![(0, 3), (50, 3), (100, 3)]);
    }

    /// Two series with a line each (parameters a1, b1 and a2, b2): the c-optimal design for
    /// b1 puts series 1 at its ends and leaves series 2, which says nothing about b1, evenly
    /// spread.
    #[test]
    fn a_series_without_information_is_spread() {
        let mut cands = Vec::new();
        for s in 0..2 {
            for i in 0..11 {
                let x = -1.0 + 2.0 * i as f64 / 10.0;
                let mut g = vec![0.0; 4];
                g[2 * s] = 1.0;
                g[2 * s + 1] = x;
                cands.push(Cand {
                    series: s,
                    delta: x,
                    g,
                    sigma: 1.0,
                });
            }
        }
        let strata = vec![(0..11).collect::<Vec<_>>(), (11..22).collect()];
        let series: Vec<usize> = cands.iter().map(|c| c.series).collect();
        let a = multiplicative(&one(cands, 4, 1), &strata, &[4.0, 3.0], 4, Crit::C);
        let r = round(&strata, &[4, 3], &a, &series);
        assert_eq!(r[0], vec![(0, 2), (10, 2)]);
        assert_eq!(r[1], vec![(11, 1), (16, 1), (21, 1)]);
    }

    /// The same two lines under one budget of 8 points over both series, D-optimal for all
    /// four parameters: each line needs both ends, and by symmetry the four ends share the
    /// points equally (det M = (n1 n2)² under ends-only designs is largest at n1 = n2), 2 each;
    /// the two ends that meet at the series boundary (candidates 10 and 11) stay two points.
    #[test]
    fn one_budget_over_two_series() {
        let mut cands = Vec::new();
        for s in 0..2 {
            for i in 0..11 {
                let x = -1.0 + 2.0 * i as f64 / 10.0;
                let mut g = vec![0.0; 4];
                g[2 * s] = 1.0;
                g[2 * s + 1] = x;
                cands.push(Cand {
                    series: s,
                    delta: x,
                    g,
                    sigma: 1.0,
                });
            }
        }
        let series: Vec<usize> = cands.iter().map(|c| c.series).collect();
        let strata = vec![(0..22).collect::<Vec<_>>()];
        let a = multiplicative(&one(cands, 4, 0), &strata, &[8.0], 4, Crit::D);
        let r = round(&strata, &[8], &a, &series);
        assert_eq!(r[0], vec![(0, 2), (10, 2), (11, 2), (21, 2)]);
    }

    /// The variance of a combination by hand: M = diag(4, 1) gives Var(p1 + p2) = 1/4 + 1 and
    /// Var(3 p1) = 9/4; M = [[2, 1], [1, 1]] has M⁻¹ = [[1, −1], [−1, 2]], so Var(p1 + p2) =
    /// 1 − 2 + 2 = 1; M = diag(4, 0) determines p1 (1/4) but not p1 + p2.
    #[test]
    fn variance_of_a_combination_by_hand() {
        let m = DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 1.0]));
        assert!((variance_of(&m, &[1.0, 1.0]).unwrap() - 1.25).abs() < 1e-12);
        assert!((variance_of(&m, &[3.0, 0.0]).unwrap() - 2.25).abs() < 1e-12);
        let m = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 1.0]);
        assert!((variance_of(&m, &[1.0, 1.0]).unwrap() - 1.0).abs() < 1e-12);
        let m = DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 0.0]));
        assert!((variance_of(&m, &[1.0, 0.0]).unwrap() - 0.25).abs() < 1e-12);
        assert_eq!(variance_of(&m, &[1.0, 1.0]), None);
    }

    /// Two draws of a line's slope parameter where only the intercept's sensitivity differs
    /// average to the criterion of each: a design is D-optimal for the average of two equal
    /// draws exactly when it is for one of them (ends of the interval, as above).
    #[test]
    fn two_equal_draws_give_the_local_design() {
        let cands: Vec<Cand> = (0..21)
            .map(|i| {
                let x = -1.0 + 2.0 * i as f64 / 20.0;
                Cand {
                    series: 0,
                    delta: x,
                    g: vec![1.0, x],
                    sigma: 1.0,
                }
            })
            .collect();
        let strata = vec![(0..21).collect::<Vec<_>>()];
        let mut draws = one(cands.clone(), 2, 1);
        draws.extend(one(cands, 2, 1));
        let a = multiplicative(&draws, &strata, &[6.0], 2, Crit::D);
        let r = round(&strata, &[6], &a, &[0; 21]);
        assert_eq!(r[0], vec![(0, 3), (20, 3)]);
    }

    /// Point exchange by hand: a line through the origin, y = b x on [0, 1] (g = x), where
    /// Var(b̂) = 1/Σ n_j x_j² is least with every point at x = 1; started with all 4 points at
    /// x = 0.5, the exchange moves them there one by one (each move lowers the loss).
    #[test]
    fn exchange_moves_points_to_the_optimum() {
        let cands: Vec<Cand> = (0..11)
            .map(|i| {
                let x = i as f64 / 10.0;
                Cand {
                    series: 0,
                    delta: x,
                    g: vec![x],
                    sigma: 1.0,
                }
            })
            .collect();
        let strata = vec![(0..11).collect::<Vec<_>>()];
        for crit in [Crit::D, Crit::C] {
            let r = exchange(&one(cands.clone(), 1, 0), &strata, &[vec![(5, 4)]], 1, crit);
            assert_eq!(r[0], vec![(10, 4)], "{crit:?}");
        }
    }

    /// One draw of `cands` with the c criterion's vector the unit vector of parameter `k`.
    fn one(cands: Vec<Cand>, p: usize, k: usize) -> Vec<Draw> {
        let mut c = vec![0.0; p];
        c[k] = 1.0;
        vec![Draw { cands, c }]
    }
}
