//! The isoline reduced model shared by `isolines` (Au et al. 2007) and `hirm` (Wu et al. 2015):
//! isolines traced on scalar fields ([`tracing`]), one 3x4 transform per isoline interpolated to
//! the vertices and the Laplacian coordinates ([`interpolation`]: `X = W_x R_x`,
//! `delta = W_delta R_delta`), the handle-independent and constrained reduced systems, and the
//! end of one reduced iteration (solve, move the sampled triangles, check; the loop around it is
//! [`crate::method::run_iterations`]).
//!
//! What the two methods differ in stays with them: where the fields come from (harmonic fields
//! per handle, Laplacian eigenvectors), how the sets are blended ([`SetBlend`]) and how isoline
//! rotations are fitted ([`RotationFit`]).

pub mod interpolation;
pub mod tracing;

use faer::{Mat, MatRef};
use meshes::vector::{cross, dot, normalize_or_zero, scale, sub};

pub use interpolation::{
    add_constraint_rows_lower, constraint_rhs, HandleIndependentSystem, IsolineModel, ModelFrame,
    ReducedSystem, RotationFit, SetBlend,
};

use crate::error::MethodError;
use crate::linalg::anderson::{Acceleration, FixedPointIteration};

/// What [`reduced_step`] needs to know of the iteration and the bound model.
pub(crate) struct ReducedIteration<'a> {
    pub method: &'static str,
    /// 0-based index within the solve.
    pub iteration: usize,
    pub model: &'a IsolineModel,
    /// `L` of `U^T U = L L^T` (lower triangle; the strict upper one is not read).
    pub factor: MatRef<'a, f64>,
}

/// A step (largest vertex displacement of one iteration, in rest bbox diagonals) beyond which a
/// reduced solve has diverged. The first iteration moves from the start to the targets and may be
/// as long as the edit; every later one only relaxes the shape towards its rotations, by a small
/// fraction of the model. An iteration that moves a vertex by the size of the whole model is a
/// runaway (as `hirm` on a 43K-vertex scan, which ended 29 diagonals away), not a relaxation.
pub(crate) const DIVERGED_STEP: f64 = 1.0;

/// `Err(Diverged)` when iteration `iteration` (0-based) of `method` made a step beyond
/// [`DIVERGED_STEP`] (the first iteration is exempt).
pub(crate) fn check_divergence(method: &'static str, iteration: usize, step: f64) -> Result<(), MethodError> {
    if iteration >= 1 && step > DIVERGED_STEP {
        return Err(MethodError::Diverged { method, iteration, step });
    }
    Ok(())
}

/// The end of one iteration of an isoline reduced model (Au et al. 2007 eq 10, HIRM eq 20): solve
/// `U^T U R = rhs` (`4N x 3`) into `reduced`, move the probe vertices (`probes`, the sampled
/// triangles' corners) and check them. Returns the step: the largest probe displacement over
/// `diagonal`. Errors: a non-finite probe, or a divergent step ([`check_divergence`]).
pub(crate) fn reduced_step(
    it: ReducedIteration<'_>,
    mut rhs: Mat<f64>,
    reduced: &mut Mat<f64>,
    probes: &mut Vec<[f64; 3]>,
    diagonal: f64,
) -> Result<f64, MethodError> {
    faer::linalg::cholesky::llt::solve::solve_in_place_with_conj(
        it.factor,
        faer::Conj::No,
        rhs.as_mut(),
        faer::Par::Seq,
        faer::dyn_stack::MemStack::new(&mut []),
    );
    *reduced = rhs;
    let next = it.model.probe_positions(reduced.as_ref());
    if let Some(i) = next.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        let vertex = it.model.probe_vertex(i) as usize;
        return Err(MethodError::NonFinite { method: it.method, vertex, iteration: it.iteration });
    }
    let step = crate::method::max_displacement(probes, &next) / diagonal;
    check_divergence(it.method, it.iteration, step)?;
    *probes = next;
    Ok(step)
}

/// The reduced iteration `R <- T(R)` (eq 10; HIRM eq 20) as a fixed-point iteration on the `4N x 3`
/// transforms, plain or Anderson-accelerated ([`FixedPointIteration`]). The step that converges
/// is the plain one (the probes' displacement from `R` to `T(R)`), so acceleration changes the path,
/// not the fixed point. Per-iteration cost `O(N)` plus one more probe evaluation: still independent
/// of `#V`.
pub(crate) struct ReducedFixedPoint {
    iteration: FixedPointIteration,
    /// `R` before the step and `T(R)`, flattened column by column (`g` is the last image, which an
    /// unconverged solve returns).
    x: Vec<f64>,
    g: Vec<f64>,
}

impl ReducedFixedPoint {
    /// For `reduced` transforms of `rows x 3`.
    pub fn new(acceleration: Acceleration, depth: usize, rows: usize) -> Self {
        let dimension = 3 * rows;
        let iteration = FixedPointIteration::new(acceleration, depth, dimension);
        let buffers = if iteration.is_accelerated() { dimension } else { 0 };
        Self { iteration, x: vec![0.0; buffers], g: vec![0.0; buffers] }
    }

    /// Keep `R` (call before the step).
    pub fn begin(&mut self, reduced: MatRef<'_, f64>) {
        if self.iteration.is_accelerated() {
            flatten(reduced, &mut self.x);
        }
    }

    /// After the step left `T(R)` in `reduced` and its probes in `probes`: move on to the next
    /// iterate (extrapolated unless `converged`) and its probes. Errors: a non-finite probe of an
    /// extrapolated iterate.
    pub fn advance(
        &mut self,
        method: &'static str,
        iteration: usize,
        model: &IsolineModel,
        reduced: &mut Mat<f64>,
        probes: &mut Vec<[f64; 3]>,
        converged: bool,
    ) -> Result<(), MethodError> {
        if !self.iteration.is_accelerated() {
            return Ok(());
        }
        flatten(reduced.as_ref(), &mut self.g);
        if self.iteration.advance(&mut self.x, &self.g, converged) {
            unflatten(&self.x, reduced.as_mut());
            let next = model.probe_positions(reduced.as_ref());
            if let Some(i) = next.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(MethodError::NonFinite {
                    method,
                    vertex: model.probe_vertex(i) as usize,
                    iteration,
                });
            }
            *probes = next;
        }
        Ok(())
    }

    /// After a solve that ended unconverged: the last `T(R)` into `reduced` (not an extrapolation).
    pub fn end_unconverged(&self, reduced: &mut Mat<f64>) {
        if self.iteration.is_accelerated() {
            unflatten(&self.g, reduced.as_mut());
        }
    }
}

fn flatten(m: MatRef<'_, f64>, out: &mut [f64]) {
    let rows = m.nrows();
    for j in 0..m.ncols() {
        for i in 0..rows {
            out[j * rows + i] = m[(i, j)];
        }
    }
}

fn unflatten(values: &[f64], mut m: faer::MatMut<'_, f64>) {
    let rows = m.nrows();
    for j in 0..m.ncols() {
        for i in 0..rows {
            m[(i, j)] = values[j * rows + i];
        }
    }
}

/// `W_x R_x` for every vertex (`#V x 3`), or the first non-finite vertex as an error.
pub(crate) fn checked_positions(
    method: &'static str,
    model: &IsolineModel,
    reduced: MatRef<'_, f64>,
    iterations: usize,
) -> Result<Vec<[f64; 3]>, MethodError> {
    let positions = model.positions(reduced);
    match positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        Some(vertex) => Err(MethodError::NonFinite { method, vertex, iteration: iterations }),
        None => Ok(positions),
    }
}

/// Orthonormal frame (normal, segment direction, their cross product) of a crossed triangle with
/// corners `p` and the isoline segment from `q0` to `q1`, as the columns of a 3x3 matrix.
pub(crate) fn segment_frame(p: [[f64; 3]; 3], q0: [f64; 3], q1: [f64; 3]) -> [[f64; 3]; 3] {
    let normal = normalize_or_zero(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    let along = sub(q1, q0);
    // Remove any normal component rounding left, so the frame stays orthonormal.
    let along = normalize_or_zero(sub(along, scale(normal, dot(along, normal))));
    [normal, along, cross(normal, along)]
}

#[cfg(test)]
mod divergence_tests {
    use super::*;

    #[test]
    fn a_runaway_step_after_the_first_iteration_is_a_divergence_error() {
        assert!(check_divergence("hirm", 0, 5.0).is_ok(), "the first iteration moves to the targets");
        assert!(check_divergence("hirm", 7, 0.5).is_ok());
        let e = check_divergence("hirm", 7, 29.0).unwrap_err();
        assert!(matches!(e, MethodError::Diverged { method: "hirm", iteration: 7, .. }));
        assert!(e.to_string().contains("`hirm` diverged: iteration 7"), "{e}");
    }
}
