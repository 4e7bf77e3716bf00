//! The interface every deformation method implements, in the phases the papers time separately.

use std::ops::ControlFlow;

use meshes::TriMesh;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};

/// What a method reports after each iteration of [`DeformationMethod::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationReport {
    /// 0-based iteration index within the current solve.
    pub iteration: usize,
    /// Step size: largest vertex (or reduced-variable) displacement of this iteration divided by the
    /// rest bounding-box diagonal. The convergence test compares it with the method's tolerance.
    pub step: f64,
    /// Wall time of the iteration's own work in seconds (the observer's time excluded).
    pub seconds: f64,
}

/// Receives per-iteration reports; may ask for the current shape or stop the solve.
pub trait IterationObserver {
    /// Called after every iteration. `shape` computes the current `#V x 3` positions on demand
    /// (reduced models reconstruct them, so call it only when needed).
    fn on_iteration(
        &mut self,
        report: &IterationReport,
        shape: &dyn Fn() -> Vec<[f64; 3]>,
    ) -> ControlFlow<()>;
}

/// An observer that ignores everything.
pub struct NoObserver;

impl IterationObserver for NoObserver {
    fn on_iteration(&mut self, _: &IterationReport, _: &dyn Fn() -> Vec<[f64; 3]>) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

/// Outcome of one [`DeformationMethod::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveSummary {
    /// Iterations performed.
    pub iterations: usize,
    /// Whether the step fell below the tolerance before the iteration limit.
    pub converged: bool,
    /// Step of the last iteration.
    pub final_step: f64,
}

/// A handle-based deformation method, driven through the phases the papers time separately:
///
/// 1. [`precompute`](Self::precompute): handle-independent work on the rest mesh;
/// 2. [`bind_handles`](Self::bind_handles): per handle set; may be called again mid-edit and keeps the
///    current deformed shape (incremental editing);
/// 3. [`solve`](Self::solve): iterate towards handle targets from the current shape.
pub trait DeformationMethod: Send {
    /// Registry name.
    fn name(&self) -> &'static str;

    /// Handle-independent precomputation on the rest mesh; resets the current shape to the rest shape.
    fn precompute(&mut self, rest: &TriMesh) -> Result<(), MethodError>;

    /// Bind a handle set (validated for the rest mesh's vertex count).
    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError>;

    /// Iterate from the current shape towards `targets` until converged or the iteration limit.
    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError>;

    /// Current deformed positions, `#V x 3`.
    fn positions(&self) -> Vec<[f64; 3]>;

    /// Method-specific phase timings in seconds (e.g. HIRM's t_e, t_b), reported next to the common ones.
    fn phase_timings(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }

    /// Sizes describing a reduced model (e.g. HIRM's `n_field` and `n_t`, Au et al.'s `n_tri`),
    /// reported next to the timings. Counts, not seconds.
    fn model_statistics(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}

/// Largest displacement between two `#V x 3` position arrays.
pub fn max_displacement(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter().zip(b).map(|(p, q)| meshes::vector::norm(meshes::vector::sub(*p, *q))).fold(0.0, f64::max)
}

/// The end of one iteration of a full-space method: move `current` (`#V x 3`) to the new iterate
/// `solution` (`#V x 3`, column per coordinate), check it, report the step (relative to `diagonal`)
/// and the time since `start` to `observer`. Returns the summary so far and whether to stop
/// (converged below `tolerance`, or the observer asked).
#[allow(clippy::too_many_arguments)]
pub(crate) fn finish_iteration(
    method: &'static str,
    iteration: usize,
    start: std::time::Instant,
    current: &mut [[f64; 3]],
    solution: faer::MatRef<'_, f64>,
    diagonal: f64,
    tolerance: f64,
    observer: &mut dyn IterationObserver,
) -> Result<(SolveSummary, bool), crate::MethodError> {
    let step = move_to(method, iteration, current, solution)? / diagonal;
    Ok(report_iteration(iteration, start, step, current, tolerance, observer))
}

/// Move `current` (`#V x 3`) to `solution` (`#V x 3`) after checking that it is finite; returns the
/// largest vertex displacement.
pub(crate) fn move_to(
    method: &'static str,
    iteration: usize,
    current: &mut [[f64; 3]],
    solution: faer::MatRef<'_, f64>,
) -> Result<f64, crate::MethodError> {
    let mut step2: f64 = 0.0;
    for (i, x) in current.iter_mut().enumerate() {
        let new = [solution[(i, 0)], solution[(i, 1)], solution[(i, 2)]];
        if new.iter().any(|c| !c.is_finite()) {
            return Err(crate::MethodError::NonFinite { method, vertex: i, iteration });
        }
        let d = meshes::vector::sub(new, *x);
        step2 = step2.max(meshes::vector::dot(d, d));
        *x = new;
    }
    Ok(step2.sqrt())
}

/// Report iteration `iteration` with its (relative) `step` and the time since `start` to
/// `observer`; returns the summary so far and whether to stop (`step < tolerance`, or the observer
/// asked).
pub(crate) fn report_iteration(
    iteration: usize,
    start: std::time::Instant,
    step: f64,
    current: &[[f64; 3]],
    tolerance: f64,
    observer: &mut dyn IterationObserver,
) -> (SolveSummary, bool) {
    let report = IterationReport { iteration, step, seconds: start.elapsed().as_secs_f64() };
    let summary = SolveSummary { iterations: iteration + 1, converged: step < tolerance, final_step: step };
    let flow = observer.on_iteration(&report, &|| current.to_vec());
    (summary, summary.converged || flow == ControlFlow::Break(()))
}
