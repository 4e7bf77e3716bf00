//! A thin layer over faer's sparse Cholesky: symbolic analysis once per sparsity pattern, numeric
//! factorization whenever the values change, back-substitution with preallocated workspace.
//!
//! The back-substitution of several right-hand sides does not go through faer: on the first such
//! solve after a numeric factorization the factor is copied into a supernodal layout
//! (`blocked::BlockedFactor`) with row-major blocks, and the right-hand sides are solved in a
//! permuted row-major workspace (see that module). For several right-hand-side columns this is
//! several times faster than faer's column-major supernodal solve. A single column is solved by
//! faer on the factor as it is: the copy costs about what it saves (`scale_aware`, one solve per
//! factorization on the survey plane: 1.0 s of copies against 0.15 s of slower solves).

mod blocked;

use blocked::BlockedFactor;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{MatMut, MatRef, Par, Side};

/// Right-hand-side columns solved together; wider blocks are split into chunks of this many.
const CHUNK: usize = 16;

/// From this many right-hand-side columns on, two column halves are solved on two threads.
const PARALLEL_MIN_COLS: usize = 16;

/// faer picks the supernodal factorization when its flops per factor entry exceed 40 times this
/// (its default is 1). Cotangent Laplacians of the survey meshes have ratios of 20–50 and factor
/// 1.2–1.7x faster supernodally (numeric phase of `-L + 1e-6 M`, best of 10: bar 9.5 ms simplicial
/// against 5.5 ms supernodal, cylinder 4.0 against 3.0, cactus 4.8 against 4.1); chains and other
/// thin patterns stay simplicial.
const SUPERNODAL_THRESHOLD: SupernodalThreshold = SupernodalThreshold(0.25);

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
    /// The factor re-laid out for the multi-column triangular solves, built from `values` on the first
    /// such solve after a factorization (`blocked_current`).
    blocked: BlockedFactor,
    blocked_current: bool,
    /// Workspace of faer's single-column solve.
    single_scratch: MemBuffer,
    /// Row-major permuted right-hand sides, `blocked.rows() x padded_width(min(k, CHUNK))`.
    workspace: Vec<f64>,
    /// The same for the second thread of a parallel solve.
    workspace_parallel: Vec<f64>,
    /// Inverse of the fill-reducing permutation (identity without one).
    perm_inv: Vec<usize>,
    par: Par,
    /// Workspace of the numeric factorization, allocated once: a fresh one per factorization cost
    /// `scale_aware` 6% of its time in page faults and zeroing on the survey plane.
    factor_scratch: MemBuffer,
    /// [`SparseCholesky::keep_only_solves`] freed `values` and the workspaces; the blocked copy
    /// is current and serves every solve.
    solves_only: bool,
}

impl SparseCholesky {
    /// Symbolic analysis of the pattern of `matrix` (`n x n`, both triangles stored; the lower one is read).
    pub fn analyze(matrix: SparseColMatRef<'_, usize, f64>) -> Result<Self, SolverError> {
        Self::analyze_with(matrix, SUPERNODAL_THRESHOLD)
    }

    /// [`SparseCholesky::analyze`] with the choice between simplicial and supernodal factorization
    /// made by `threshold`.
    fn analyze_with(
        matrix: SparseColMatRef<'_, usize, f64>,
        threshold: SupernodalThreshold,
    ) -> Result<Self, SolverError> {
        if matrix.nrows() != matrix.ncols() {
            return Err(SolverError::NotSquare { nrows: matrix.nrows(), ncols: matrix.ncols() });
        }
        let symbolic = factorize_symbolic_cholesky(
            matrix.symbolic(),
            Side::Lower,
            Default::default(),
            CholeskySymbolicParams { supernodal_flop_ratio_threshold: threshold, ..Default::default() },
        )
        .map_err(|e| SolverError::Faer(format!("{e:?}")))?;
        let values = vec![0.0; symbolic.len_val()];
        let par = Par::Seq;
        let blocked = BlockedFactor::new(symbolic.raw());
        // Workspace row of every row of the matrix: the fill-reducing permutation, then the
        // blocked layout's own placement of the factor's columns.
        let perm_inv = match symbolic.perm() {
            Some(perm) => perm.arrays().1.iter().map(|&c| blocked.position(c)).collect(),
            None => (0..symbolic.nrows()).map(|c| blocked.position(c)).collect(),
        };
        let factor_scratch =
            MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        let single_scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Ok(Self {
            factor_scratch,
            single_scratch,
            blocked_current: false,
            col_ptr: matrix.symbolic().col_ptr().to_vec(),
            row_idx: matrix.symbolic().row_idx().to_vec(),
            blocked,
            symbolic,
            values,
            factorized: false,
            workspace: Vec::new(),
            workspace_parallel: Vec::new(),
            perm_inv,
            par,
            solves_only: false,
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
        if self.solves_only {
            self.values = vec![0.0; self.symbolic.len_val()];
            self.factor_scratch = MemBuffer::new(
                self.symbolic.factorize_numeric_llt_scratch::<f64>(self.par, Default::default()),
            );
            self.single_scratch = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            self.solves_only = false;
        }
        self.symbolic
            .factorize_numeric_llt::<f64>(
                &mut self.values,
                matrix,
                Side::Lower,
                LltRegularization::default(),
                self.par,
                MemStack::new(&mut self.factor_scratch),
                Default::default(),
            )
            .map_err(|_| SolverError::NotPositiveDefinite)?;
        self.blocked_current = false;
        self.factorized = true;
        Ok(())
    }

    /// Solve `A X = B` in place for the `n x k` right-hand sides `rhs`. Workspace is allocated on the
    /// first call for `k` columns (an `n x 16` block at most) and reused afterwards.
    ///
    /// A single column is solved by faer on the factor as it is. Several columns are solved
    /// together on the blocked copy of the factor (built on the first such solve after a
    /// factorization), in chunks of up to 16, so they cost much less than as many single solves.
    /// From 16 columns on, two halves of the columns are solved on two rayon threads; a large
    /// factor is also split into parts of its elimination tree swept on separate threads
    /// (`blocked::tree_split`). The result for given inputs is bitwise reproducible: it depends on
    /// `k` and the matrix, not on the number of threads or their scheduling.
    ///
    /// # Panics
    /// If called before a successful [`SparseCholesky::factorize`] or with the wrong number of rows
    /// (programming errors, not input errors).
    pub fn solve_in_place(&mut self, rhs: MatMut<'_, f64>) {
        assert!(self.factorized, "solve before factorize");
        assert_eq!(rhs.nrows(), self.dim());
        let n = self.dim();
        let k = rhs.ncols();
        if n == 0 || k == 0 {
            return;
        }
        if k == 1 && !self.solves_only {
            // One column: faer's solve on the factor as it is. The blocked layout's copy of the
            // factor costs as much as a solve and pays off only over several columns.
            use faer::sparse::linalg::cholesky::LltRef;
            LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
                faer::Conj::No,
                rhs,
                Par::Seq,
                MemStack::new(&mut self.single_scratch),
            );
            return;
        }
        if !self.blocked_current {
            self.blocked.set_values(&self.values);
            self.blocked_current = true;
        }
        if k >= PARALLEL_MIN_COLS {
            // Two independent column halves on two threads, each with its own workspace; halved on
            // one thread too, so that the result does not depend on the thread count.
            let (left, right) = rhs.split_at_col_mut(k.div_ceil(2));
            let (blocked, perm_inv) = (&self.blocked, self.perm_inv.as_slice());
            let (ws_left, ws_right) = (&mut self.workspace, &mut self.workspace_parallel);
            rayon::join(
                || solve_columns(blocked, perm_inv, ws_left, left),
                || solve_columns(blocked, perm_inv, ws_right, right),
            );
        } else {
            solve_columns(&self.blocked, &self.perm_inv, &mut self.workspace, rhs);
        }
    }

    /// Multiply-adds of one numeric factorization, `sum_j c_j^2` over the factor's column counts
    /// `c_j` (diagonal included), from the symbolic analysis alone.
    pub fn factorization_work(&self) -> f64 {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sym) => (0..sym.n_supernodes())
                .map(|s| {
                    let w = sym.supernode_end()[s] - sym.supernode_begin()[s];
                    let p = sym.supernode(s).pattern().len();
                    (1..=w).map(|c| ((c + p) as f64).powi(2)).sum::<f64>()
                })
                .sum(),
            SymbolicCholeskyRaw::Simplicial(sym) => {
                sym.col_ptr().windows(2).map(|w| ((w[1] - w[0]) as f64).powi(2)).sum()
            }
        }
    }

    /// Number of stored entries of the factor (fill-in indicator).
    pub fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Keep only what multi-column solves read: builds the blocked copy of the factor, then frees
    /// faer's column-major factor and the factorization's workspace. For a factorization that
    /// serves many solves and is never redone (a 1M-vertex shift-invert factor: 104M entries, 0.8 GB
    /// of values each way, plus the workspace), this halves what it holds; the results of
    /// multi-column solves do not change. Afterwards a single column is solved on the blocked copy
    /// too, and a later [`SparseCholesky::factorize`] allocates again what it needs.
    pub fn keep_only_solves(&mut self) {
        assert!(self.factorized, "keep_only_solves before factorize");
        if !self.blocked_current {
            self.blocked.set_values(&self.values);
            self.blocked_current = true;
        }
        self.values = Vec::new();
        self.factor_scratch = MemBuffer::new(faer::dyn_stack::StackReq::EMPTY);
        self.single_scratch = MemBuffer::new(faer::dyn_stack::StackReq::EMPTY);
        self.solves_only = true;
    }
}

/// Solve in place for the columns of `rhs`, in chunks of at most [`CHUNK`] columns, each padded
/// to a supported block width in the row-major `workspace` (grown on demand).
fn solve_columns(
    blocked: &BlockedFactor,
    perm_inv: &[usize],
    workspace: &mut Vec<f64>,
    mut rhs: MatMut<'_, f64>,
) {
    let rows = blocked.rows();
    let k = rhs.ncols();
    let width = blocked::padded_width(k.min(CHUNK));
    if workspace.len() < rows * width {
        workspace.resize(rows * width, 0.0);
    }
    for c in (0..k).step_by(CHUNK) {
        let kc = CHUNK.min(k - c);
        let width = blocked::padded_width(kc);
        let x = &mut workspace[..rows * width];
        let mut block = rhs.rb_mut().subcols_mut(c, kc);
        macro_rules! run {
            ($w:literal) => {{
                load_permuted::<$w>(block.rb(), perm_inv, x);
                blocked.solve_row_major(x, $w);
                store_permuted::<$w>(x, perm_inv, block.rb_mut());
            }};
        }
        match width {
            1 => run!(1),
            2 => run!(2),
            4 => run!(4),
            8 => run!(8),
            16 => run!(16),
            _ => unreachable!("padded widths are powers of two up to CHUNK"),
        }
    }
}

/// Row `inv[p]` of the row-major `rows x W` block `x` is row `p` of `b` (`b.ncols() <= W`), padded with
/// zeros: `x = P b` for the fill-reducing permutation `P` with inverse `inv`.
fn load_permuted<const W: usize>(b: MatRef<'_, f64>, inv: &[usize], x: &mut [f64]) {
    let k = b.ncols();
    let mut cols: [&[f64]; W] = [&[]; W];
    let contiguous = b.col_iter().zip(&mut cols).all(|(col, slot)| match col.try_as_col_major() {
        Some(col) => {
            *slot = col.as_slice();
            true
        }
        None => false,
    });
    if contiguous {
        for (p, &i) in inv.iter().enumerate() {
            let row: &mut [f64; W] = (&mut x[i * W..i * W + W]).try_into().unwrap();
            for (j, v) in row.iter_mut().enumerate() {
                *v = if j < k { cols[j][p] } else { 0.0 };
            }
        }
    } else {
        for (p, &i) in inv.iter().enumerate() {
            let row: &mut [f64; W] = (&mut x[i * W..i * W + W]).try_into().unwrap();
            for (j, v) in row.iter_mut().enumerate() {
                *v = if j < k { b[(p, j)] } else { 0.0 };
            }
        }
    }
}

/// Row `p` of `b` is row `inv[p]` of `x` (the inverse of [`load_permuted`]).
fn store_permuted<const W: usize>(x: &[f64], inv: &[usize], mut b: MatMut<'_, f64>) {
    let k = b.ncols();
    if b.row_stride() == 1 {
        let mut cols: [&mut [f64]; W] = std::array::from_fn(|_| &mut [][..]);
        for (col, slot) in b.col_iter_mut().zip(&mut cols) {
            *slot = col.try_as_col_major_mut().expect("unit row stride").as_slice_mut();
        }
        for (p, &i) in inv.iter().enumerate() {
            let row: &[f64; W] = x[i * W..i * W + W].try_into().unwrap();
            for (col, &v) in cols[..k].iter_mut().zip(row) {
                col[p] = v;
            }
        }
    } else {
        for (p, &i) in inv.iter().enumerate() {
            for j in 0..k {
                b[(p, j)] = x[i * W + j];
            }
        }
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

    /// Weighted graph Laplacian of an `m^dim` grid (nearest neighbours; weights vary irregularly in
    /// [1, 1.9]) plus `shift` on the diagonal: SPD for `shift > 0`.
    fn grid(m: usize, dim: u32, shift: f64) -> SparseColMat<usize, f64> {
        let n = m.pow(dim);
        let mut t = Vec::new();
        let mut diag = vec![shift; n];
        for a in 0..n {
            for axis in 0..dim {
                let stride = m.pow(axis);
                if (a / stride) % m + 1 < m {
                    let b = a + stride;
                    let w = 1.0 + ((a * 7919 + b * 104729) % 10) as f64 / 10.0;
                    t.push(Triplet::new(a, b, -w));
                    t.push(Triplet::new(b, a, -w));
                    diag[a] += w;
                    diag[b] += w;
                }
            }
        }
        t.extend(diag.iter().enumerate().map(|(i, &d)| Triplet::new(i, i, d)));
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

    /// Right-hand sides with entries in [-1, 1), different in every column.
    fn rhs(n: usize, k: usize) -> faer::Mat<f64> {
        faer::Mat::from_fn(n, k, |i, j| ((i * 7919 + j * 104729 + i * j) % 1000) as f64 / 500.0 - 1.0)
    }

    /// faer's own supernodal/simplicial solve with the same factor.
    fn faer_solve(chol: &SparseCholesky, b: &faer::Mat<f64>) -> faer::Mat<f64> {
        use faer::sparse::linalg::cholesky::LltRef;
        let mut x = b.clone();
        let mut stack = MemBuffer::new(chol.symbolic.solve_in_place_scratch::<f64>(b.ncols(), Par::Seq));
        LltRef::new(&chol.symbolic, &chol.values).solve_in_place_with_conj(
            faer::Conj::No,
            x.as_mut(),
            Par::Seq,
            MemStack::new(&mut stack),
        );
        x
    }

    /// Largest over the columns of `max_i |x_ij - y_ij| / max_i |y_ij|`.
    fn relative_difference(x: &faer::Mat<f64>, y: &faer::Mat<f64>) -> f64 {
        (0..y.ncols())
            .map(|j| {
                let (x, y) = (x.col(j), y.col(j));
                let diff = (0..y.nrows()).map(|i| (x[i] - y[i]).abs()).fold(0.0, f64::max);
                diff / (0..y.nrows()).map(|i| y[i].abs()).fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    }

    fn is_supernodal(chol: &SparseCholesky) -> bool {
        matches!(chol.symbolic.raw(), faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(_))
    }

    /// Our solve against faer's for several widths, including chunked and two-thread ones, with
    /// the kernels this CPU uses and with the portable ones.
    fn check_against_faer(a: &SparseColMat<usize, f64>, threshold: SupernodalThreshold) {
        for portable in [false, true] {
            let mut chol = SparseCholesky::analyze_with(a.as_ref(), threshold).unwrap();
            chol.factorize(a.as_ref()).unwrap();
            if portable {
                chol.blocked.disable_fma();
            }
            for k in [1, 2, 3, 4, 5, 8, 13, 16, 17, 32] {
                let b = rhs(a.nrows(), k);
                let mut x = b.clone();
                chol.solve_in_place(x.as_mut());
                let diff = relative_difference(&x, &faer_solve(&chol, &b));
                assert!(diff <= 1e-12, "k = {k}: relative difference {diff:e}");
                assert!(residual(a, &x, &b) < 1e-8, "k = {k}");
            }
        }
    }

    #[test]
    fn both_solve_paths_use_the_latest_factorization() {
        // One column goes through faer, several through the blocked copy built on first use.
        let (a1, a2) = (grid(40, 2, 0.01), grid(40, 2, 0.5));
        let mut chol = SparseCholesky::new(a1.as_ref()).unwrap();
        let mut x = rhs(a1.nrows(), 3);
        chol.solve_in_place(x.as_mut());
        chol.factorize(a2.as_ref()).unwrap();
        for k in [1, 3] {
            let b = rhs(a2.nrows(), k);
            let mut x = b.clone();
            chol.solve_in_place(x.as_mut());
            assert!(residual(&a2, &x, &b) < 1e-10, "k = {k}: solved with a stale factor");
        }
    }

    #[test]
    fn supernodal_factors_solve_like_faer() {
        // The first is split into parts of its elimination tree, the second not.
        for a in [grid(150, 2, 0.01), grid(16, 3, 0.01)] {
            assert!(is_supernodal(&SparseCholesky::analyze(a.as_ref()).unwrap()));
            check_against_faer(&a, SUPERNODAL_THRESHOLD);
        }
    }

    #[test]
    fn simplicial_factors_solve_like_faer() {
        // Columns merged into wide fundamental supernodes (a grid, supernodal by default, forced
        // simplicial), and a factor of (almost) single columns (simplicial by default).
        let grid = grid(100, 2, 0.01);
        let chol =
            SparseCholesky::analyze_with(grid.as_ref(), SupernodalThreshold::FORCE_SIMPLICIAL).unwrap();
        assert!(!is_supernodal(&chol) && chol.blocked.max_supernode_width() > 16);
        check_against_faer(&grid, SupernodalThreshold::FORCE_SIMPLICIAL);
        let tri = tridiagonal(1000, 0.01);
        let chol = SparseCholesky::analyze(tri.as_ref()).unwrap();
        assert!(!is_supernodal(&chol) && chol.blocked.n_supernodes() > 900);
        check_against_faer(&tri, SUPERNODAL_THRESHOLD);
    }

    #[test]
    fn keeping_only_solves_frees_the_factor_and_changes_no_result() {
        for (a, threshold) in [
            (grid(60, 2, 0.01), SUPERNODAL_THRESHOLD),
            (grid(40, 2, 0.01), SupernodalThreshold::FORCE_SIMPLICIAL),
        ] {
            let mut full = SparseCholesky::analyze_with(a.as_ref(), threshold).unwrap();
            full.factorize(a.as_ref()).unwrap();
            let mut kept = SparseCholesky::analyze_with(a.as_ref(), threshold).unwrap();
            kept.factorize(a.as_ref()).unwrap();
            kept.keep_only_solves();
            assert!(kept.values.is_empty(), "the column-major factor is freed");
            assert_eq!(kept.factor_nnz(), full.factor_nnz());
            // Several columns: bitwise the solve of the full factor. One column: the blocked path.
            for k in [3, 4, 16] {
                let b = rhs(a.nrows(), k);
                let (mut x, mut y) = (b.clone(), b.clone());
                full.solve_in_place(x.as_mut());
                kept.solve_in_place(y.as_mut());
                assert!(x == y, "k = {k}: results differ");
            }
            let b = rhs(a.nrows(), 1);
            let mut x = b.clone();
            kept.solve_in_place(x.as_mut());
            assert!(residual(&a, &x, &b) < 1e-10);
            // A new factorization allocates again and is the one solved with.
            let a2 = grid(if threshold == SUPERNODAL_THRESHOLD { 60 } else { 40 }, 2, 0.5);
            kept.factorize(a2.as_ref()).unwrap();
            for k in [1, 3] {
                let b = rhs(a2.nrows(), k);
                let mut x = b.clone();
                kept.solve_in_place(x.as_mut());
                assert!(residual(&a2, &x, &b) < 1e-10, "k = {k}: solved with a stale factor");
            }
        }
    }

    #[test]
    fn strided_right_hand_sides_and_repeated_solves_give_identical_results() {
        let a = grid(30, 2, 0.1);
        let n = a.nrows();
        let mut chol = SparseCholesky::new(a.as_ref()).unwrap();
        let b = rhs(n, 3);
        let mut x = b.clone();
        chol.solve_in_place(x.as_mut());
        let mut again = b.clone();
        chol.solve_in_place(again.as_mut());
        assert!(x == again);
        // Columns of a wider matrix (column stride > n) and a transposed view (row stride != 1).
        let mut wide = faer::Mat::<f64>::zeros(n + 5, 7);
        wide.as_mut().submatrix_mut(2, 1, n, 3).copy_from(&b);
        chol.solve_in_place(wide.as_mut().submatrix_mut(2, 1, n, 3));
        assert!(wide.as_ref().submatrix(2, 1, n, 3) == x.as_ref());
        let mut transposed = b.transpose().to_owned();
        chol.solve_in_place(transposed.as_mut().transpose_mut());
        assert!(transposed.transpose() == x.as_ref());
        // No columns: nothing to do.
        chol.solve_in_place(faer::Mat::<f64>::zeros(n, 0).as_mut());
    }

    /// Large factors are split into parts of the elimination tree solved on two threads
    /// (`blocked::tree_split`): the parts carry most of the work, and the solve is bitwise the same
    /// on one thread as on two.
    #[test]
    fn split_factors_solve_alike_on_one_thread_and_two() {
        for (a, threshold) in [
            (grid(150, 2, 0.01), SUPERNODAL_THRESHOLD),
            (grid(22, 3, 0.01), SUPERNODAL_THRESHOLD),
            (grid(160, 2, 0.01), SupernodalThreshold::FORCE_SIMPLICIAL),
        ] {
            let mut chol = SparseCholesky::analyze_with(a.as_ref(), threshold).unwrap();
            chol.factorize(a.as_ref()).unwrap();
            let (parts, top) = chol.blocked.split_loads().expect("a factor this large is split");
            let total = chol.blocked.n_values();
            let largest = *parts.iter().max().unwrap();
            eprintln!("n {} values {total}: parts {parts:?}, top {top}", a.nrows());
            assert_eq!(parts.iter().sum::<usize>() + top, total);
            assert!(
                (top + largest) as f64 <= 0.8 * total as f64,
                "critical path {} of {total}",
                top + largest
            );
            for k in [1, 3, 16] {
                let b = rhs(a.nrows(), k);
                let solve_on = |threads: usize, chol: &mut SparseCholesky| {
                    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                    let mut x = b.clone();
                    pool.install(|| chol.solve_in_place(x.as_mut()));
                    x
                };
                let one = solve_on(1, &mut chol);
                let two = solve_on(2, &mut chol);
                assert!(one == two, "k = {k}: one thread and two differ");
                assert!(residual(&a, &two, &b) < 1e-8, "k = {k}");
            }
        }
    }
}
