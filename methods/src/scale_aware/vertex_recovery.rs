//! Section 4.3, step two: the vertices from fixed normals, `(G^T G + lambda C) V = lambda C V*`
//! (eq 12), a `3#V x 3#V` system whose pattern never changes and whose values change with the
//! normals: the symbolic factorization is computed once per mesh, the numeric one every outer
//! iteration, then one back-substitution.
//!
//! (Reusing the last factorization as a conjugate-gradient preconditioner instead was measured and
//! dropped: on the survey cactus and plane it needed 5–6 back-substitutions per outer iteration,
//! which cost as much as refactoring.)

use faer::sparse::SparseColMat;
use faer::Mat;

use super::scale_aware_equations::ScaleAwareEquations;
use crate::linalg::sparse_cholesky::{SolverError, SparseCholesky};

/// Time spent in step two during one `solve`, in seconds.
#[derive(Clone, Copy, Debug, Default)]
pub struct RecoveryTimings {
    pub assembly_s: f64,
    pub refactorization_s: f64,
    pub back_substitution_s: f64,
}

/// The step-two system with its symbolic factorization.
pub struct VertexRecovery {
    matrix: SparseColMat<usize, f64>,
    cholesky: SparseCholesky,
}

impl VertexRecovery {
    /// Symbolic analysis of the pattern of `equations`' normal matrix.
    pub fn new(equations: &ScaleAwareEquations) -> Result<Self, SolverError> {
        let matrix = equations.normal_matrix_pattern();
        Ok(Self { cholesky: SparseCholesky::analyze(matrix.as_ref())?, matrix })
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

        let t = std::time::Instant::now();
        self.cholesky.factorize(self.matrix.as_ref())?;
        timings.refactorization_s += t.elapsed().as_secs_f64();

        let t = std::time::Instant::now();
        self.cholesky.solve_in_place(rhs_solution.as_mut());
        timings.back_substitution_s += t.elapsed().as_secs_f64();
        Ok(())
    }
}
