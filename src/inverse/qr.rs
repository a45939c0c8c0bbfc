//! The column-pivoted Householder QR factorisation J·P = Q·R of the solver's Jacobian, with the
//! work space kept for a whole run.
//!
//! [`PivotedQr::factor`] performs the operations of faer's `MatRef::col_piv_qr` followed by
//! `ColPivQr::compute_thin_Q` — faer's `qr_in_place` with column pivoting, the Householder
//! basis split from R as faer splits it, and the block Householder sequence applied to the
//! thin identity — in the same order, on matrices of the same shape and layout, so its R, P and
//! Q are those of faer to the bit (see the test below). The matrices, the permutation and the
//! scratch are allocated once per run instead of at every iteration.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::householder::{
    apply_block_householder_sequence_on_the_left_in_place_scratch,
    apply_block_householder_sequence_on_the_left_in_place_with_conj,
};
use faer::linalg::qr::col_pivoting::factor::{qr_in_place, qr_in_place_scratch};
use faer::linalg::qr::no_pivoting::factor::recommended_block_size;
use faer::{get_global_parallelism, Conj, Mat, MatRef};

/// Work space and result of the factorisation of an m × n matrix (m ≥ n ≥ 1).
pub(crate) struct PivotedQr {
    /// The matrix factored: R in its upper triangle after [`PivotedQr::factor`]'s
    /// factorisation, then the Householder basis (unit lower trapezoid).
    a: Mat<f64>,
    /// The block Householder coefficients.
    coeff: Mat<f64>,
    /// The column permutation: column j of J·P is column `fwd[j]` of J.
    fwd: Vec<usize>,
    bwd: Vec<usize>,
    /// The first n columns of Q.
    q: Mat<f64>,
    stack: MemBuffer,
}

impl std::fmt::Debug for PivotedQr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PivotedQr")
            .field("nrows", &self.a.nrows())
            .field("ncols", &self.a.ncols())
            .finish_non_exhaustive()
    }
}

/// A clone is fresh work space of the same shape: nothing in it is read before
/// [`PivotedQr::factor`] writes it.
impl Clone for PivotedQr {
    fn clone(&self) -> Self {
        PivotedQr::new(self.a.nrows(), self.a.ncols())
    }
}

impl PivotedQr {
    /// Work space for m × n matrices.
    pub fn new(m: usize, n: usize) -> Self {
        let block = recommended_block_size::<f64>(m, n);
        let par = get_global_parallelism();
        let req = StackReq::any_of(&[
            qr_in_place_scratch::<usize, f64>(m, n, block, par, Default::default()),
            apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(m, block, n),
        ]);
        PivotedQr {
            a: Mat::zeros(m, n),
            coeff: Mat::zeros(block, n),
            fwd: vec![0; n],
            bwd: vec![0; n],
            q: Mat::zeros(m, n),
            stack: MemBuffer::new(req),
        }
    }

    /// Factors `j` (m × n), then calls `with` with R (n × n, upper triangle; the strict lower
    /// triangle holds no part of it) and the permutation, then forms Q's first n columns.
    pub fn factor(&mut self, j: &Mat<f64>, with: impl FnOnce(MatRef<'_, f64>, &[usize])) {
        let (m, n) = (self.a.nrows(), self.a.ncols());
        let par = get_global_parallelism();
        for c in 0..n {
            self.a
                .col_as_slice_mut(c)
                .copy_from_slice(j.col_as_slice(c));
        }
        self.coeff.fill(0.0);
        qr_in_place(
            self.a.as_mut(),
            self.coeff.as_mut(),
            &mut self.fwd,
            &mut self.bwd,
            par,
            MemStack::new(&mut self.stack),
            Default::default(),
        );
        with(self.a.as_ref().get(..n, ..), &self.fwd);
        // The Householder basis: unit diagonal, nothing above it.
        for c in 0..n {
            let col = self.a.col_as_slice_mut(c);
            col[..c].fill(0.0);
            col[c] = 1.0;
        }
        self.q.fill(0.0);
        for c in 0..n.min(m) {
            self.q[(c, c)] = 1.0;
        }
        apply_block_householder_sequence_on_the_left_in_place_with_conj(
            self.a.as_ref(),
            self.coeff.as_ref(),
            Conj::No,
            self.q.as_mut(),
            par,
            MemStack::new(&mut self.stack),
        );
    }

    /// Column `c` of Q (after [`PivotedQr::factor`]).
    pub fn q_col(&self, c: usize) -> &[f64] {
        self.q.col_as_slice(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R, P and Q equal faer's `col_piv_qr` and `compute_thin_Q` bit for bit, on matrices with
    /// rank deficiency, zero columns and the shapes the fits use (n from 1 to 6, m from n to 60).
    #[test]
    fn same_bits_as_faer() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for n in 1..=6 {
            for m in [n, n + 1, 9, 36, 60] {
                if m < n {
                    continue;
                }
                let mut work = PivotedQr::new(m, n);
                for case in 0..4 {
                    let mut j = Mat::<f64>::from_fn(m, n, |i, k| {
                        next() * 10f64.powi((i + 3 * k) as i32 % 7 - 3)
                    });
                    if case == 1 && n > 1 {
                        // A column that is a multiple of another.
                        for i in 0..m {
                            j[(i, n - 1)] = 3.0 * j[(i, 0)];
                        }
                    }
                    if case == 2 {
                        // A column held fixed by a bound: zeroed.
                        for i in 0..m {
                            j[(i, n / 2)] = 0.0;
                        }
                    }
                    let qr = j.col_piv_qr();
                    let r = qr.thin_R();
                    let q = qr.compute_thin_Q();
                    let (fwd, _) = qr.P().arrays();
                    work.factor(&j, |rr, p| {
                        assert_eq!(p, fwd);
                        for c in 0..n {
                            for i in 0..=c {
                                assert_eq!(rr[(i, c)].to_bits(), r[(i, c)].to_bits());
                            }
                        }
                    });
                    for c in 0..n {
                        for i in 0..m {
                            assert_eq!(work.q_col(c)[i].to_bits(), q[(i, c)].to_bits());
                        }
                    }
                }
            }
        }
    }
}
