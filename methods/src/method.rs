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
    /// (reduced models reconstruct them, so call it only when needed); `None` where the iterate is
    /// out of reach (an external method reports its iterations after its solve).
    fn on_iteration(
        &mut self,
        report: &IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()>;
}

/// An observer that ignores everything.
pub struct NoObserver;

impl IterationObserver for NoObserver {
    fn on_iteration(
        &mut self,
        _: &IterationReport,
        _: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()> {
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
    /// An iterative method that did not say whether it converged (an external entry of
    /// `kind = "iterative"` whose answer has no `converged`): counted as finished, reported as
    /// "convergence unknown".
    pub convergence_unknown: bool,
}

/// A solve's part that was reused, not computed ([`DeformationMethod::reused_solve`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ReusedSolve {
    /// The method whose solve it was.
    pub from: &'static str,
    /// Wall seconds that solve took when it ran.
    pub seconds: f64,
}

/// A handle-based deformation method, driven through the phases the papers time separately:
///
/// 1. [`precompute`](Self::precompute): handle-independent work on the rest mesh;
/// 2. [`bind_handles`](Self::bind_handles): per handle set; may be called again mid-edit and keeps the
///    current deformed shape (incremental editing);
/// 3. [`solve`](Self::solve): iterate towards handle targets from the current shape.
pub trait DeformationMethod: Send {
    /// Name in configs and reports.
    fn name(&self) -> &str;

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
    fn phase_timings(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// Sizes describing a reduced model (e.g. HIRM's `n_field` and `n_t`, Au et al.'s `n_tri`),
    /// reported next to the timings. Counts, not seconds.
    fn model_statistics(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// Wall seconds spent starting the method before [`precompute`](Self::precompute) (an external
    /// program's start-up and handshake), kept out of the precompute time; `None` for a method that
    /// runs in this process.
    fn startup_seconds(&self) -> Option<f64> {
        None
    }

    /// What runs, in the method's words (an external program's library and version), if it says.
    fn about(&self) -> Option<String> {
        None
    }

    /// The part of the last [`solve`](Self::solve) that was not computed but taken from an earlier
    /// identical solve of another method in this process (`scale_aware_ora` takes `scale_aware`'s):
    /// its method and the seconds it took there. The wall time of `solve` does not include them; a
    /// timer of the solve adds them, so that the reported time is that of the whole computation.
    fn reused_solve(&self) -> Option<ReusedSolve> {
        None
    }

    /// End what the method holds outside this process (an external program and whatever it
    /// started) once its case is done; what could not be ended, in words for the case's status.
    fn end(&mut self) -> Vec<String> {
        Vec::new()
    }
}

/// The phases of a [`DeformationMethod`], in the order they are first called.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Precompute,
    BindHandles,
    Solve,
}

impl Phase {
    /// The trait method's name.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Precompute => "precompute",
            Phase::BindHandles => "bind_handles",
            Phase::Solve => "solve",
        }
    }

    /// The phase that must have run before this one (none before `precompute`).
    pub fn needs(self) -> Option<Phase> {
        match self {
            Phase::Precompute => None,
            Phase::BindHandles => Some(Phase::Precompute),
            Phase::Solve => Some(Phase::BindHandles),
        }
    }
}

/// The phase guard every method opens `bind_handles` and `solve` with: `state` (what `phase` needs
/// from the phase before it, `None` until that phase ran) or [`MethodError::Phase`] naming `method`,
/// `phase` and the phase it needs.
pub fn require_phase<T>(state: Option<T>, method: &'static str, phase: Phase) -> Result<T, MethodError> {
    state.ok_or(MethodError::Phase {
        method,
        phase: phase.name(),
        missing: phase.needs().map_or("nothing", Phase::name),
    })
}

/// Phase timings or statistics under their `&'static` keys ([`crate::keys`]) as the trait reports them.
pub(crate) fn owned_names(list: Vec<(&'static str, f64)>) -> Vec<(String, f64)> {
    list.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

/// Largest displacement between two `#V x 3` position arrays.
pub fn max_displacement(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter().zip(b).map(|(p, q)| meshes::vector::norm(meshes::vector::sub(*p, *q))).fold(0.0, f64::max)
}

/// The iterations of one solve: indices `first..first + count`, stopping early once a step falls
/// below `tolerance` (relative to the rest bounding-box diagonal).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Iterations {
    /// Index of the first iteration (`scale_aware` reports its initialization as iteration 0).
    pub first: usize,
    /// Most iterations to run (the method's `max_iterations`).
    pub count: usize,
    pub tolerance: f64,
}

/// The loop of every iterative solve, full-space and reduced: for each iteration of `iterations`,
/// `iterate(state, iteration)` does the iteration's work on `state` (the `#V x 3` positions of a
/// full-space method, the reduced coefficients of a reduced one, or the whole method) and returns
/// its step (largest displacement over the rest diagonal). The driver times the work, reports it to
/// `observer` with the current `#V x 3` shape on demand (`shape(state)`, reconstructed only when the
/// observer asks), and stops when the step falls below the tolerance, when the observer asks, or
/// after the last iteration. An error of `iterate` ends the solve.
pub(crate) fn run_iterations<S: ?Sized>(
    iterations: Iterations,
    state: &mut S,
    mut iterate: impl FnMut(&mut S, usize) -> Result<f64, MethodError>,
    shape: impl Fn(&S) -> Vec<[f64; 3]>,
    observer: &mut dyn IterationObserver,
) -> Result<SolveSummary, MethodError> {
    let mut summary = SolveSummary {
        iterations: iterations.first,
        converged: false,
        final_step: f64::INFINITY,
        convergence_unknown: false,
    };
    for iteration in iterations.first..iterations.first + iterations.count {
        let start = std::time::Instant::now();
        let step = iterate(state, iteration)?;
        let report = IterationReport { iteration, step, seconds: start.elapsed().as_secs_f64() };
        summary = SolveSummary {
            iterations: iteration + 1,
            converged: step < iterations.tolerance,
            final_step: step,
            convergence_unknown: false,
        };
        let state: &S = state;
        let flow = observer.on_iteration(&report, Some(&|| shape(state)));
        if summary.converged || flow.is_break() {
            break;
        }
    }
    Ok(summary)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_phase_guard_names_the_method_the_phase_and_the_phase_it_needs() {
        assert_eq!(require_phase(Some(3), "arap", Phase::Solve).unwrap(), 3);
        let error = require_phase::<()>(None, "arap", Phase::Solve).unwrap_err();
        assert_eq!(error.to_string(), "`arap`: solve called before bind_handles");
        let error = require_phase::<()>(None, "hirm", Phase::BindHandles).unwrap_err();
        assert_eq!(error.to_string(), "`hirm`: bind_handles called before precompute");
    }
}
