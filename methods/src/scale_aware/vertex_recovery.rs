//! Section 4.3, step two: the vertices from fixed normals, `(G^T G + lambda C) V = lambda C V*`
//! (eq 12), a `3#V x 3#V` system whose pattern never changes and whose values change with the
//! normals: the symbolic factorization is computed once per mesh, the numeric one when the normals
//! have moved (below), then back-substitutions.
//!
//! Lagged factorization ([`VertexRecovery::step`]). The paper's "factorized once" cannot hold in 3D:
//! `G` holds `l R(N, theta)`, so `G^T G` changes with the normals. But between outer iterations
//! the normals move little, and the held factor of an earlier `A_j = A(N_j)` is a good approximate
//! inverse of the current `A = A(N)`. A lagged step solves `A y = b` by the stationary iteration
//! `y <- y + A_j^{-1} (b - A y)` from `y = x` (the current vertices) until a correction is 5% of
//! the first, at most four corrections: it returns the exact step to about 5% of its length, and
//! its fixed points are the exact step's (`y = x` iff `A x = b`), so Algorithm 1's fixed points do
//! not change. Decision, measured on the survey tests (docs/results.md, issue 52): one correction
//! per outer iteration, accepted while the outer steps shrank, was faster on the cylinder and plane
//! but moved the path enough to end the cylinder at another fixed point 1.2e-3 away (Algorithm 1's
//! fixed points are not isolated there); the corrected step ends all four within 1e-4 of the
//! exact path's. Safeguards, each sending the step to a fresh factorization and the exact solve: no
//! factor held (or the handles changed), some normal turned by more than `max_turn` since the
//! factor, or the corrections stop halving or run out.
//!
//! (Reusing the last factorization as a conjugate-gradient preconditioner was measured and
//! dropped earlier: on the survey cactus and plane it needed 5–6 back-substitutions per outer
//! iteration, as dear as refactoring. The stationary iteration with the turn test refactors before
//! the factor is that stale.)

use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{Mat, MatRef};
use rayon::prelude::*;

use super::scale_aware_equations::ScaleAwareEquations;
use crate::linalg::sparse_cholesky::{SolverError, SparseCholesky};
use crate::method::max_displacement;

/// Time spent in step two during one `solve`, in seconds.
#[derive(Clone, Copy, Debug, Default)]
pub struct RecoveryTimings {
    pub assembly_s: f64,
    pub refactorization_s: f64,
    pub back_substitution_s: f64,
    /// Steps taken with a fresh factorization, and with a held one ([`VertexRecovery::step`]).
    pub refactorizations: usize,
    pub lagged_steps: usize,
}

/// The step-two system with its symbolic factorization and, for lagged steps, the last numeric one.
pub struct VertexRecovery {
    matrix: SparseColMat<usize, f64>,
    cholesky: SparseCholesky,
    /// `#F x 3` normals of the numeric factorization held by `cholesky`; empty when there is none.
    factored_normals: Vec<[f64; 3]>,
    /// `3 #V` storage of `b - A x`.
    residual: Vec<f64>,
    /// `3 #V` storage of a lagged step's iterate.
    lagged: Vec<f64>,
}

impl VertexRecovery {
    /// Symbolic analysis of the pattern of `equations`' normal matrix.
    pub fn new(equations: &ScaleAwareEquations) -> Result<Self, SolverError> {
        let matrix = equations.normal_matrix_pattern();
        let n = matrix.nrows();
        Ok(Self {
            cholesky: SparseCholesky::analyze(matrix.as_ref())?,
            matrix,
            factored_normals: Vec::new(),
            residual: vec![0.0; n],
            lagged: vec![0.0; n],
        })
    }

    /// Forget the held factorization (the constraint diagonal changed: a new handle set).
    pub fn invalidate(&mut self) {
        self.factored_normals.clear();
    }

    /// Step two, lagged when it may be (module documentation): into `next` (`3#V x 1`, interleaved)
    /// the vertices for `#F x 3` `normals` from `3#V` interleaved `current` and `rhs` (`3#V x 1`,
    /// `lambda C V*`). A lagged step is taken when a factorization is held, no normal turned by
    /// more than `max_turn` (chord length) since it, and its corrections converge; otherwise the
    /// matrix is refactored and the step is exact. `max_turn = 0` refactors every time.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        equations: &ScaleAwareEquations,
        normals: &[[f64; 3]],
        constraint_diagonal: &[f64],
        rhs: MatRef<'_, f64>,
        current: &[f64],
        max_turn: f64,
        next: &mut Mat<f64>,
        timings: &mut RecoveryTimings,
    ) -> Result<(), SolverError> {
        let t = std::time::Instant::now();
        equations.assemble_normal_matrix(normals, constraint_diagonal, self.matrix.val_mut());
        timings.assembly_s += t.elapsed().as_secs_f64();

        if max_turn > 0.0 && largest_turn(&self.factored_normals, normals) <= max_turn {
            let t = std::time::Instant::now();
            let accepted = self.lagged_solve(current, rhs, next);
            timings.back_substitution_s += t.elapsed().as_secs_f64();
            if accepted {
                timings.lagged_steps += 1;
                return Ok(());
            }
        }

        for i in 0..current.len() {
            next[(i, 0)] = rhs[(i, 0)];
        }
        self.refactor_and_solve(normals, next, timings)
    }

    /// The stationary iteration `y <- y + A_j^{-1} (b - A y)` from `y = current` with the held
    /// factor `A_j`, at most [`LAGGED_CORRECTIONS`] corrections, into `next`. Accepted (`true`)
    /// once a correction is at most [`LAGGED_ACCURACY`] times the first (the step is then about
    /// that close to the exact one); rejected when the corrections stop contracting or run out.
    fn lagged_solve(&mut self, current: &[f64], rhs: MatRef<'_, f64>, next: &mut Mat<f64>) -> bool {
        let n = current.len();
        self.lagged.copy_from_slice(current);
        let (mut first, mut last) = (0.0, f64::INFINITY);
        for k in 0..LAGGED_CORRECTIONS {
            symmetric_residual(self.matrix.as_ref(), &self.lagged, rhs, &mut self.residual);
            for i in 0..n {
                next[(i, 0)] = self.residual[i];
            }
            self.cholesky.solve_in_place(next.as_mut());
            let mut size: f64 = 0.0;
            for v in 0..n / 3 {
                let d = [next[(3 * v, 0)], next[(3 * v + 1, 0)], next[(3 * v + 2, 0)]];
                size = size.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            }
            let size = size.sqrt();
            for i in 0..n {
                self.lagged[i] += next[(i, 0)];
            }
            if k == 0 {
                first = size;
            } else if size > LAGGED_CONTRACTION * last {
                return false;
            }
            last = size;
            if size <= LAGGED_ACCURACY * first {
                break;
            }
        }
        if last > LAGGED_ACCURACY * first {
            return false;
        }
        for i in 0..n {
            next[(i, 0)] = self.lagged[i];
        }
        true
    }

    /// Solve eq 12 for `#F x 3` `normals` and the `3 #V` `constraint_diagonal`; `rhs_solution`
    /// (`3#V x 1`) holds `lambda C V*` on entry and the vertices (interleaved) on return.
    pub fn solve(
        &mut self,
        equations: &ScaleAwareEquations,
        normals: &[[f64; 3]],
        constraint_diagonal: &[f64],
        rhs_solution: &mut Mat<f64>,
        timings: &mut RecoveryTimings,
    ) -> Result<(), SolverError> {
        let t = std::time::Instant::now();
        equations.assemble_normal_matrix(normals, constraint_diagonal, self.matrix.val_mut());
        timings.assembly_s += t.elapsed().as_secs_f64();

        self.refactor_and_solve(normals, rhs_solution, timings)
    }

    /// Factor the assembled matrix (held for lagged steps, with the `#F x 3` `normals` it was
    /// built from) and solve it in place for `rhs_solution` (`3#V x 1`).
    fn refactor_and_solve(
        &mut self,
        normals: &[[f64; 3]],
        rhs_solution: &mut Mat<f64>,
        timings: &mut RecoveryTimings,
    ) -> Result<(), SolverError> {
        let t = std::time::Instant::now();
        self.cholesky.factorize(self.matrix.as_ref())?;
        self.factored_normals.clear();
        self.factored_normals.extend_from_slice(normals);
        timings.refactorization_s += t.elapsed().as_secs_f64();

        let t = std::time::Instant::now();
        self.cholesky.solve_in_place(rhs_solution.as_mut());
        timings.back_substitution_s += t.elapsed().as_secs_f64();
        timings.refactorizations += 1;
        Ok(())
    }
}

/// Largest chord `|a_f - b_f|` between the unit normals of `held` and `normals` (`#F x 3` each);
/// infinite when `held` is empty (no factorization).
fn largest_turn(held: &[[f64; 3]], normals: &[[f64; 3]]) -> f64 {
    if held.len() != normals.len() || held.is_empty() {
        return f64::INFINITY;
    }
    max_displacement(held, normals)
}

/// `residual = rhs - A x` for a symmetric `A` stored with both triangles (`n x n`), `x` and
/// `residual` of length `n`, `rhs` `n x 1`. Column `j` of `A` is its row `j`, so each entry is one
/// column's dot product: no scatter, and the sum order is fixed.
fn symmetric_residual(
    a: SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    rhs: MatRef<'_, f64>,
    residual: &mut [f64],
) {
    let (col_ptr, row_idx, values) = (a.col_ptr(), a.row_idx(), a.val());
    let row = |j: usize| -> f64 {
        let mut s = 0.0;
        for k in col_ptr[j]..col_ptr[j + 1] {
            s += values[k] * x[row_idx[k]];
        }
        rhs[(j, 0)] - s
    };
    if residual.len() >= PARALLEL_MIN_ROWS {
        residual.par_iter_mut().enumerate().for_each(|(j, r)| *r = row(j));
    } else {
        residual.iter_mut().enumerate().for_each(|(j, r)| *r = row(j));
    }
}

/// Most corrections of one lagged step, the accuracy that accepts it (last correction over the
/// first) and the contraction each correction must show over the one before.
pub const LAGGED_CORRECTIONS: usize = 4;
pub const LAGGED_ACCURACY: f64 = 0.05;
pub const LAGGED_CONTRACTION: f64 = 0.5;

/// Below this many rows the residual is computed on one thread.
const PARALLEL_MIN_ROWS: usize = 12_000;
