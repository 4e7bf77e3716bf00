//! A thin layer over faer's sparse Cholesky: symbolic analysis once per sparsity pattern, numeric
//! factorization whenever the values change, back-substitution with preallocated workspace.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky};
use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

/// Failures of the sparse solver layer.
#[derive(Debug, thiserror::Error)]
pub enum SolverError {
    #[error("matrix is not square: {nrows} x {ncols}")]
    NotSquare { nrows: usize, ncols: usize },
    #[error("sparsity pattern differs from the one analysed (symbolic factorization cannot be reused)")]
    PatternMismatch,
    #[error("matrix is not numerically positive definite (is every connected component constrained?)")]
    NotPositiveDefinite,
    #[error("sparse factorization failed: {0}")]
    Faer(String),
}

/// Sparse `L L^T` factorization of a symmetric positive definite `n x n` matrix.
///
/// Phases as in libigl's `min_quad_with_fixed`: [`SparseCholesky::analyze`] (fill-reducing ordering,
/// elimination tree, supernodes; pattern only), [`SparseCholesky::factorize`] (numeric values; may be
/// called again with new values on the same pattern), [`SparseCholesky::solve_in_place`].
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    factorized: bool,
    workspace: MemBuffer,
    workspace_cols: usize,
    par: Par,
}

impl SparseCholesky {
    /// Symbolic analysis of the pattern of `matrix` (`n x n`, both triangles stored; the lower one is read).
    pub fn analyze(matrix: SparseColMatRef<'_, usize, f64>) -> Result<Self, SolverError> {
        if matrix.nrows() != matrix.ncols() {
            return Err(SolverError::NotSquare { nrows: matrix.nrows(), ncols: matrix.ncols() });
        }
        let symbolic = factorize_symbolic_cholesky(
            matrix.symbolic(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| SolverError::Faer(format!("{e:?}")))?;
        let values = vec![0.0; symbolic.len_val()];
        let par = Par::Seq;
        Ok(Self {
            col_ptr: matrix.symbolic().col_ptr().to_vec(),
            row_idx: matrix.symbolic().row_idx().to_vec(),
            symbolic,
            values,
            factorized: false,
            workspace: MemBuffer::new(StackReq::EMPTY),
            workspace_cols: 0,
            par,
        })
    }

    /// Analyse and factorize `matrix` in one call.
    pub fn new(matrix: SparseColMatRef<'_, usize, f64>) -> Result<Self, SolverError> {
        let mut chol = Self::analyze(matrix)?;
        chol.factorize(matrix)?;
        Ok(chol)
    }

    /// Order of the matrix.
    pub fn dim(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Numeric factorization of `matrix`, which must have the analysed pattern.
    pub fn factorize(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), SolverError> {
        if matrix.symbolic().col_ptr() != self.col_ptr.as_slice()
            || matrix.symbolic().row_idx() != self.row_idx.as_slice()
        {
            return Err(SolverError::PatternMismatch);
        }
        if matrix.val().iter().any(|v| !v.is_finite()) {
            return Err(SolverError::NotPositiveDefinite);
        }
        self.factorized = false;
        let scratch = self.symbolic.factorize_numeric_llt_scratch::<f64>(self.par, Default::default());
        let mut buffer = MemBuffer::new(scratch);
        self.symbolic
            .factorize_numeric_llt::<f64>(
                &mut self.values,
                matrix,
                Side::Lower,
                LltRegularization::default(),
                self.par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|_| SolverError::NotPositiveDefinite)?;
        self.factorized = true;
        Ok(())
    }

    /// Solve `A X = B` in place for the `n x k` right-hand sides `rhs`. Workspace is allocated on the
    /// first call for `k` columns and reused afterwards.
    ///
    /// # Panics
    /// If called before a successful [`SparseCholesky::factorize`] or with the wrong number of rows
    /// (programming errors, not input errors).
    pub fn solve_in_place(&mut self, rhs: MatMut<'_, f64>) {
        assert!(self.factorized, "solve before factorize");
        assert_eq!(rhs.nrows(), self.dim());
        let k = rhs.ncols();
        if k > self.workspace_cols {
            self.workspace = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(k, self.par));
            self.workspace_cols = k;
        }
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(&mut self.workspace),
        );
    }

    /// Number of stored entries of the factor (fill-in indicator).
    pub fn factor_nnz(&self) -> usize {
        self.values.len()
    }
}

/// `A + diag(d)` for a matrix `A` whose pattern contains the diagonal; the pattern is unchanged, so a
/// symbolic factorization of `A` can be reused.
pub fn add_to_diagonal(a: SparseColMatRef<'_, usize, f64>, d: &[f64]) -> SparseColMat<usize, f64> {
    let symbolic = a.symbolic();
    let mut values = a.val().to_vec();
    for j in 0..symbolic.ncols() {
        let range = symbolic.col_range(j);
        let rows = &symbolic.row_idx()[range.clone()];
        let pos = rows.binary_search(&j).expect("pattern contains the diagonal");
        values[range.start + pos] += d[j];
    }
    let pattern = faer::sparse::SymbolicSparseColMat::new_checked(
        symbolic.nrows(),
        symbolic.ncols(),
        symbolic.col_ptr().to_vec(),
        None,
        symbolic.row_idx().to_vec(),
    );
    SparseColMat::new(pattern, values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// 1D Laplacian plus `shift` on the diagonal: tridiagonal, SPD for `shift > 0`.
    fn tridiagonal(n: usize, shift: f64) -> SparseColMat<usize, f64> {
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, 2.0 + shift));
            if i + 1 < n {
                t.push(Triplet::new(i, i + 1, -1.0));
                t.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    fn residual(a: &SparseColMat<usize, f64>, x: &faer::Mat<f64>, b: &faer::Mat<f64>) -> f64 {
        let ax = a * x;
        (0..b.nrows())
            .flat_map(|i| (0..b.ncols()).map(move |j| (i, j)))
            .map(|(i, j)| (ax[(i, j)] - b[(i, j)]).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn symbolic_analysis_is_reused_across_numeric_factorizations() {
        let n = 200;
        let b = faer::Mat::from_fn(n, 3, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
        let mut chol = SparseCholesky::analyze(tridiagonal(n, 0.1).as_ref()).unwrap();
        for shift in [0.1, 1.0, 10.0] {
            let a = tridiagonal(n, shift);
            chol.factorize(a.as_ref()).unwrap();
            let mut x = b.clone();
            chol.solve_in_place(x.as_mut());
            assert!(residual(&a, &x, &b) < 1e-10, "shift {shift}");
        }
    }

    #[test]
    fn other_pattern_and_indefinite_matrices_are_errors() {
        let mut chol = SparseCholesky::analyze(tridiagonal(10, 1.0).as_ref()).unwrap();
        assert!(matches!(chol.factorize(tridiagonal(11, 1.0).as_ref()), Err(SolverError::PatternMismatch)));
        assert!(matches!(
            chol.factorize(tridiagonal(10, -3.0).as_ref()),
            Err(SolverError::NotPositiveDefinite)
        ));
        let mut nan = tridiagonal(10, 1.0);
        nan.val_mut()[0] = f64::NAN;
        assert!(matches!(chol.factorize(nan.as_ref()), Err(SolverError::NotPositiveDefinite)));
    }

    #[test]
    fn adding_to_the_diagonal_keeps_the_pattern() {
        let a = tridiagonal(5, 0.0);
        let b = add_to_diagonal(a.as_ref(), &[1.0, 0.0, 2.0, 0.0, 3.0]);
        assert_eq!(a.symbolic().row_idx(), b.symbolic().row_idx());
        assert_eq!(b[(0, 0)], 3.0);
        assert_eq!(b[(2, 2)], 4.0);
        assert_eq!(b[(1, 1)], 2.0);
    }
}
