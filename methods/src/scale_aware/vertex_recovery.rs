//! Section 4.3, step two: the vertices from fixed normals, `(G^T G + lambda C) V = lambda C V*`
//! (eq 12), a `3#V x 3#V` system whose pattern never changes and whose values change with the
//! normals: the symbolic factorization is computed once per mesh, the numeric one when the normals
//! have moved (below), then back-substitutions.
//!
//! Lagged factorization ([`VertexRecovery::step`]). The paper's "factorized once" cannot hold in 3D:
//! `G` holds `l R(N, theta)`, so `G^T G` changes with the normals. But between outer iterations
//! the normals move little, and the held factor of an earlier `A_j = A(N_j)` is a good
//! preconditioner of the current `A = A(N)`. A lagged step solves `A y = b` by conjugate gradients
//! preconditioned by `A_j` from `y = x` (the current vertices) until the preconditioned residual
//! `sqrt(r^T A_j^-1 r)` is [`LAGGED_ACCURACY`] of the first: the exact step to about that fraction
//! of its length. Its fixed points are the exact step's (`y = x` iff `A x = b`), so Algorithm 1's
//! fixed points do not change.
//!
//! When to refactor ([`RefactorSchedule`]): a factorization costs `R` back-substitutions (estimated
//! from the symbolic factor, so the choice, and the result, do not depend on the machine's
//! timing), a lagged step as many back-substitutions as its conjugate gradients took, and these
//! grow as the normals move away from the factor's. The schedule refactors when the last lagged
//! step cost more than the mean cost per step since the factorization (`R` included): the rule
//! that minimizes the mean cost per step when step costs grow. Safeguards, each sending the step
//! to a fresh factorization and the exact solve: no factor held (or the handles changed), some
//! normal turned by more than `max_turn` since the factor, conjugate gradients not converged
//! within `R` back-substitutions (a refactorization would have been cheaper) or breaking down.
//!
//! History (docs/results.md, issues 52 and 63): the stationary iteration `y <- y + A_j^-1 (b - A y)`
//! with a turn test at 0.05 came first; on igea-134k it still refactored 84 times in 142 outer
//! iterations (170 of 275 s). Conjugate gradients converge in 2-3 back-substitutions where the
//! stationary iteration stops contracting, so the factor is held several times longer.

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
    /// Back-substitutions of the lagged steps (conjugate-gradient iterations plus one each).
    pub lagged_back_substitutions: usize,
}

/// The step-two system with its symbolic factorization and, for lagged steps, the last numeric one.
pub struct VertexRecovery {
    matrix: SparseColMat<usize, f64>,
    cholesky: SparseCholesky,
    /// `#F x 3` normals of the numeric factorization held by `cholesky`; empty when there is none.
    factored_normals: Vec<[f64; 3]>,
    /// `3 #V` storage of `b - A x`.
    residual: Vec<f64>,
    /// `3 #V` storage of a lagged step's iterate, its preconditioned residual, search direction
    /// and the direction's image.
    lagged: Vec<f64>,
    preconditioned: Mat<f64>,
    direction: Vec<f64>,
    image: Vec<f64>,
    schedule: RefactorSchedule,
}

impl VertexRecovery {
    /// Symbolic analysis of the pattern of `equations`' normal matrix.
    pub fn new(equations: &ScaleAwareEquations) -> Result<Self, SolverError> {
        let matrix = equations.normal_matrix_pattern();
        let n = matrix.nrows();
        let cholesky = SparseCholesky::analyze(matrix.as_ref())?;
        let schedule = RefactorSchedule::new(refactorization_cost(&cholesky));
        Ok(Self {
            cholesky,
            matrix,
            factored_normals: Vec::new(),
            residual: vec![0.0; n],
            lagged: vec![0.0; n],
            preconditioned: Mat::zeros(n, 1),
            direction: vec![0.0; n],
            image: vec![0.0; n],
            schedule,
        })
    }

    /// Forget the held factorization (the constraint diagonal changed: a new handle set).
    pub fn invalidate(&mut self) {
        self.factored_normals.clear();
        self.schedule.due = true;
    }

    /// Step two, lagged when it may be (module documentation): into `next` (`3#V x 1`, interleaved)
    /// the vertices for `#F x 3` `normals` from `3#V` interleaved `current` and `rhs` (`3#V x 1`,
    /// `lambda C V*`). A lagged step is taken when a factorization is held, no normal turned by
    /// more than `max_turn` (chord length) since it, the schedule does not ask for a new one, and
    /// conjugate gradients converge within a refactorization's cost; otherwise the matrix is
    /// refactored and the step is exact. `max_turn = 0` refactors every time.
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

        if max_turn > 0.0 && !self.schedule.due && largest_turn(&self.factored_normals, normals) <= max_turn {
            let t = std::time::Instant::now();
            let back_substitutions = self.lagged_solve(current, rhs, next);
            timings.back_substitution_s += t.elapsed().as_secs_f64();
            if let Some(count) = back_substitutions {
                timings.lagged_steps += 1;
                timings.lagged_back_substitutions += count;
                self.schedule.lagged_step(count);
                return Ok(());
            }
        }

        for i in 0..current.len() {
            next[(i, 0)] = rhs[(i, 0)];
        }
        self.refactor_and_solve(normals, next, timings)
    }

    /// Conjugate gradients on `A y = b` from `y = current`, preconditioned by the held factor
    /// `A_j`, into `next`: the number of back-substitutions once `sqrt(r^T A_j^-1 r)` is at most
    /// [`LAGGED_ACCURACY`] times its first value; `None` when that takes more back-substitutions
    /// than a refactorization costs, or the iteration breaks down (`A` not positive along a
    /// direction: rounding at a singular step).
    fn lagged_solve(&mut self, current: &[f64], rhs: MatRef<'_, f64>, next: &mut Mat<f64>) -> Option<usize> {
        let n = current.len();
        let limit = self.schedule.refactorization_cost.ceil() as usize;
        self.lagged.copy_from_slice(current);
        symmetric_residual(self.matrix.as_ref(), &self.lagged, rhs, &mut self.residual);
        let mut rz = self.precondition();
        let first = rz;
        if first == 0.0 {
            // A zero residual: `current` solves the system.
            for i in 0..n {
                next[(i, 0)] = self.lagged[i];
            }
            return Some(1);
        }
        if !(first > 0.0) {
            return None;
        }
        self.direction.copy_from_slice(self.preconditioned.col_as_slice(0));
        for back_substitutions in 1..=limit {
            symmetric_product(self.matrix.as_ref(), &self.direction, &mut self.image);
            let curvature = dot(&self.direction, &self.image);
            if !(curvature > 0.0) || !curvature.is_finite() {
                return None;
            }
            let alpha = rz / curvature;
            for i in 0..n {
                self.lagged[i] += alpha * self.direction[i];
                self.residual[i] -= alpha * self.image[i];
            }
            let rz_next = self.precondition();
            if rz_next <= LAGGED_ACCURACY * LAGGED_ACCURACY * first {
                for i in 0..n {
                    next[(i, 0)] = self.lagged[i];
                }
                return Some(back_substitutions + 1);
            }
            let beta = rz_next / rz;
            rz = rz_next;
            let z = self.preconditioned.col_as_slice(0);
            for i in 0..n {
                self.direction[i] = z[i] + beta * self.direction[i];
            }
        }
        None
    }

    /// `z = A_j^-1 r` into `preconditioned` for the held residual `r`; returns `r^T z`.
    fn precondition(&mut self) -> f64 {
        self.preconditioned.col_as_slice_mut(0).copy_from_slice(&self.residual);
        self.cholesky.solve_in_place(self.preconditioned.as_mut());
        dot(&self.residual, self.preconditioned.col_as_slice(0))
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
        self.schedule.refactored();
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
/// `residual` of length `n`, `rhs` `n x 1` ([`symmetric_product`], then the difference).
fn symmetric_residual(
    a: SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    rhs: MatRef<'_, f64>,
    residual: &mut [f64],
) {
    symmetric_product(a, x, residual);
    for (j, r) in residual.iter_mut().enumerate() {
        *r = rhs[(j, 0)] - *r;
    }
}

/// `image = A x` for a symmetric `A` stored with both triangles (`n x n`; `x`, `image` of length
/// `n`). Column `j` of `A` is its row `j`, so each entry is one column's dot product: no scatter,
/// and the sum order is fixed.
fn symmetric_product(a: SparseColMatRef<'_, usize, f64>, x: &[f64], image: &mut [f64]) {
    let (col_ptr, row_idx, values) = (a.col_ptr(), a.row_idx(), a.val());
    let row = |j: usize| -> f64 {
        let mut s = 0.0;
        for k in col_ptr[j]..col_ptr[j + 1] {
            s += values[k] * x[row_idx[k]];
        }
        s
    };
    if image.len() >= PARALLEL_MIN_ROWS {
        image.par_iter_mut().enumerate().for_each(|(j, r)| *r = row(j));
    } else {
        image.iter_mut().enumerate().for_each(|(j, r)| *r = row(j));
    }
}

/// `a . b` in a fixed order.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The cost of a numeric factorization in back-substitutions of the same factor, estimated from
/// its symbolic structure: `sum_j c_j^2` multiply-adds against `2 nnz(L)` for a solve, with the
/// factorization's dense kernels [`FACTORIZATION_SPEEDUP`] times faster per operation. At least 2.
fn refactorization_cost(cholesky: &SparseCholesky) -> f64 {
    let solve = 2.0 * cholesky.factor_nnz().max(1) as f64;
    (cholesky.factorization_work() / (FACTORIZATION_SPEEDUP * solve)).max(2.0)
}

/// Blocked (supernodal) factorization against a single-column triangular solve, operations per
/// second. Measured on this project's 2-core machine (docs/results.md, issue 63): the survey bar
/// 6.4 back-substitutions per factorization at `sum c^2 / nnz = 179`, the plane 5.8 at 262,
/// igea-134k 15 at 927: 14, 23 and 31; 20 is taken, between them (an error of 1.5x moves the
/// schedule's optimum little: the mean cost per step is flat near it).
const FACTORIZATION_SPEEDUP: f64 = 20.0;

/// When the held factorization is retired (module documentation): costs counted in
/// back-substitutions.
#[derive(Clone, Copy, Debug)]
struct RefactorSchedule {
    /// Cost of one factorization, `R`.
    refactorization_cost: f64,
    /// Cost and number of the steps since the last factorization, its own included.
    cost_since: f64,
    steps_since: usize,
    /// The next step refactors.
    due: bool,
}

impl RefactorSchedule {
    fn new(refactorization_cost: f64) -> Self {
        Self { refactorization_cost, cost_since: 0.0, steps_since: 0, due: true }
    }

    /// A step with a fresh factorization (and one back-substitution).
    fn refactored(&mut self) {
        self.cost_since = self.refactorization_cost + 1.0;
        self.steps_since = 1;
        self.due = false;
    }

    /// A lagged step of `back_substitutions`: refactor next when it cost more than the mean.
    fn lagged_step(&mut self, back_substitutions: usize) {
        let cost = back_substitutions as f64;
        self.cost_since += cost;
        self.steps_since += 1;
        self.due = cost * self.steps_since as f64 > self.cost_since;
    }
}

/// The preconditioned residual, relative to its first value, that accepts a lagged step. 1e-2 was
/// faster on the survey (solve 33.4 s against 42.2 s) but moved the plane's answer 2.9e-4 of the
/// diagonal from the exact path's, three times the tolerance (1e-3: 2.0e-5), and left the
/// dataset's flat alligator 10x farther from its fixed point at the cap (docs/results.md, issue 63).
pub const LAGGED_ACCURACY: f64 = 1e-3;

/// Below this many rows the residual is computed on one thread.
const PARALLEL_MIN_ROWS: usize = 12_000;

#[cfg(test)]
mod tests {
    use super::RefactorSchedule;

    #[test]
    fn the_schedule_refactors_once_a_lagged_step_costs_more_than_the_mean() {
        // R = 6: after the factorization the mean is 7 per step; steps of 3 lower it, and the
        // first step dearer than the mean so far makes the next step refactor.
        let mut s = RefactorSchedule::new(6.0);
        assert!(s.due, "nothing held yet");
        s.refactored();
        assert!(!s.due);
        for _ in 0..3 {
            s.lagged_step(3);
            assert!(!s.due, "3 is below the mean ({} over {})", s.cost_since, s.steps_since);
        }
        // Mean now (7 + 9) / 4 = 4; a step of 4 is not above it, one of 5 is.
        s.lagged_step(4);
        assert!(!s.due);
        s.lagged_step(5);
        assert!(s.due, "5 over a mean of {}", s.cost_since / s.steps_since as f64);
        s.refactored();
        assert!(!s.due && s.steps_since == 1 && s.cost_since == 7.0);
    }
}
