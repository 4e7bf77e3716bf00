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
    /// Called by [`crate::drive::drive`] before the solve of edit step `step` (1-based), so that
    /// the iterations that follow can be told apart by step.
    fn on_edit_step(&mut self, _step: usize) {}

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
    /// Whether the estimated distance to the fixed point fell below the tolerance before the
    /// iteration limit ([`DistanceBound`]).
    pub converged: bool,
    /// Step of the last iteration.
    pub final_step: f64,
    /// Estimated distance of the answer to the method's fixed point over the rest bounding-box
    /// diagonal ([`DistanceBound`]; infinite while the steps do not contract, NaN where unknown:
    /// an external method that does not report it).
    pub distance: f64,
    /// An iterative method that did not say whether it converged (an external entry of
    /// `kind = "iterative"` whose answer has no `converged`): counted as finished, reported as
    /// "convergence unknown".
    pub convergence_unknown: bool,
}

/// How an iterative method stops: what a verdict on an unfinished solve quotes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stopping {
    /// The most iterations of one solve (`max_iterations`), if the method has a cap.
    pub max_iterations: Option<usize>,
    /// The bound on the estimated distance to the fixed point over the rest bounding-box diagonal
    /// ([`DistanceBound`]; `tolerance`), if the method has one.
    pub tolerance: Option<f64>,
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

    /// How its solve stops, from its parameters (their defaults included); `None` for a direct
    /// method or one that does not say.
    fn stopping(&self) -> Option<Stopping> {
        None
    }

    /// The Laplacian weights it runs with (`weights`), for a method of this crate; `None` for one
    /// that does not say (an external program).
    fn laplacian_weights(&self) -> Option<crate::operators::LaplacianWeights> {
        None
    }

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
    /// identical solve of another instance it shares a memo with (`scale_aware_ora` takes
    /// `scale_aware`'s: `registry::create_sharing`): its method and the seconds it took there. The
    /// wall time of `solve` does not include them; [`crate::drive::drive`] adds them, so that the
    /// reported time is that of the whole computation.
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

/// The iterations of one solve: indices `first..first + count`, stopping early once the estimated
/// distance to the fixed point ([`DistanceBound`]) falls below `tolerance` (relative to the rest
/// bounding-box diagonal).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Iterations {
    /// Index of the first iteration (`scale_aware` reports its initialization as iteration 0).
    pub first: usize,
    /// Most iterations to run (the method's `max_iterations`).
    pub count: usize,
    pub tolerance: f64,
}

/// Steps of history the contraction factor is estimated from ([`DistanceBound`]).
pub const CONTRACTION_WINDOW: usize = 4;

/// The contraction [`DistanceBound`] assumes where the steps show none (rounding, the first steps).
pub const SLOWEST_CONTRACTION: f64 = 0.999;

/// The stopping rule of every iterative solve: an a-posteriori bound on the distance of the
/// current iterate to the limit of its sequence, from the step sequence alone.
///
/// A sequence whose steps `s_k = |x_{k+1} - x_k|` shrink by a factor `rho < 1` per iteration has
/// `|x_{k+1} - x*| <= sum_{j > k} s_j = s_k rho / (1 - rho)`. `rho` is the largest ratio
/// `s_j / s_{j-1}` of the last [`CONTRACTION_WINDOW`] steps: a slow mode (contraction near 1)
/// shows as ratios near 1 and a bound many steps long, where a plain step test would stop. Until
/// the window is full, or while any step in it grew, the sequence has not shown a contraction and
/// the bound assumes the slowest one the rule resolves, [`SLOWEST_CONTRACTION`]: `999 x step`. So a
/// solve that starts at its fixed point (steps of rounding, which do not shrink) ends after one
/// step a thousandth of the tolerance, and an iteration whose steps grow does not end. A step of
/// exactly 0 is a fixed point (bound 0). The bound is exact for a
/// geometric sequence and a heuristic otherwise: a fast mode decaying over a still slower one can
/// hide the slow one for the window's length (the tests show the rule stopping within tolerance
/// where a step test stops hundreds of tolerances away).
#[derive(Clone, Debug)]
pub struct DistanceBound {
    tolerance: f64,
    /// The last `CONTRACTION_WINDOW + 1` steps, oldest first.
    steps: Vec<f64>,
    /// A lower estimate of the distance the iteration itself supplied for the step being recorded
    /// ([`DistanceBound::at_least`]); taken by the next [`DistanceBound::record`].
    floor: std::cell::Cell<f64>,
    /// A contraction factor the iteration measured itself for the step being recorded
    /// ([`DistanceBound::contraction_at_least`]); taken by the next [`DistanceBound::record`].
    contraction: std::cell::Cell<f64>,
}

impl DistanceBound {
    /// A rule that is met once the bound falls below `tolerance` (same units as the steps).
    pub fn new(tolerance: f64) -> Self {
        Self {
            tolerance,
            steps: Vec::with_capacity(CONTRACTION_WINDOW + 2),
            floor: std::cell::Cell::new(0.0),
            contraction: std::cell::Cell::new(0.0),
        }
    }

    /// The bound after a further step `step`, without recording it.
    pub fn distance_after(&self, step: f64) -> f64 {
        if step == 0.0 {
            return 0.0;
        }
        if !step.is_finite() {
            return f64::INFINITY;
        }
        let unresolved = step * SLOWEST_CONTRACTION / (1.0 - SLOWEST_CONTRACTION);
        if self.steps.len() < CONTRACTION_WINDOW {
            return unresolved;
        }
        let recent = &self.steps[self.steps.len() - CONTRACTION_WINDOW..];
        let mut rho: f64 = self.contraction.get();
        let mut previous = recent[0];
        for &s in recent[1..].iter().chain(std::iter::once(&step)) {
            rho = rho.max(if previous > 0.0 { s / previous } else { f64::INFINITY });
            previous = s;
        }
        if rho < 1.0 {
            step * rho / (1.0 - rho)
        } else {
            unresolved
        }
    }

    /// Whether a further step `step` would meet the rule (for an iteration that acts on it before
    /// the step is recorded, e.g. to return the plain image instead of an extrapolation).
    pub fn is_met_by(&self, step: f64) -> bool {
        self.distance_after(step) < self.tolerance
    }

    /// An estimate of the current iterate's distance to the fixed point that the iteration has
    /// from elsewhere than its steps (`arap`'s L-BFGS: its gradient over the least curvature it
    /// has seen): the next recorded distance is at least `distance`, so a step sequence that looks
    /// converged does not end a solve whose gradient says otherwise.
    pub fn at_least(&self, distance: f64) {
        self.floor.set(self.floor.get().max(distance));
    }

    /// A contraction factor of the plain map `T` the iteration measured itself (an accelerated
    /// iteration's secants `|T(x_k) - T(x_{k-1})| / |x_k - x_{k-1}|`): the next recorded bound
    /// uses at least this `rho`. An accelerated sequence's steps shrink faster than the plain map
    /// contracts, and `|x - x*| <= |T(x) - x| / (1 - L)` holds with the map's own `L`: from the
    /// step ratios alone, Anderson-accelerated `scale_aware` stopped 4e-4 to 1.2e-3 (RMS over the
    /// diagonal) from fixed points its bound put within 1e-4 (docs/results.md, issue 52).
    pub fn contraction_at_least(&self, rho: f64) {
        self.contraction.set(self.contraction.get().max(rho));
    }

    /// Record `step`; returns the bound after it (at least the floor set since the last record).
    pub fn record(&mut self, step: f64) -> f64 {
        let distance = self.distance_after(step).max(self.floor.replace(0.0));
        self.contraction.set(0.0);
        if self.steps.len() > CONTRACTION_WINDOW {
            self.steps.remove(0);
        }
        self.steps.push(step);
        distance
    }

    /// The tolerance the bound is compared with.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }
}

/// The loop of every iterative solve, full-space and reduced: for each iteration of `iterations`,
/// `iterate(state, iteration, rule)` does the iteration's work on `state` (the `#V x 3` positions
/// of a full-space method, the reduced coefficients of a reduced one, or the whole method) and
/// returns its step (largest displacement over the rest diagonal); `rule` says whether that step
/// will end the solve ([`DistanceBound::is_met_by`]). The driver times the work, records the step
/// in the stopping rule, reports it to `observer` with the current `#V x 3` shape on demand
/// (`shape(state)`, reconstructed only when the observer asks), and stops when the estimated
/// distance to the fixed point falls below the tolerance, when the observer asks, or after the
/// last iteration. An error of `iterate` ends the solve.
pub(crate) fn run_iterations<S: ?Sized>(
    iterations: Iterations,
    state: &mut S,
    mut iterate: impl FnMut(&mut S, usize, &DistanceBound) -> Result<f64, MethodError>,
    shape: impl Fn(&S) -> Vec<[f64; 3]>,
    observer: &mut dyn IterationObserver,
) -> Result<SolveSummary, MethodError> {
    let mut rule = DistanceBound::new(iterations.tolerance);
    let mut summary = SolveSummary {
        iterations: iterations.first,
        converged: false,
        final_step: f64::INFINITY,
        distance: f64::INFINITY,
        convergence_unknown: false,
    };
    for iteration in iterations.first..iterations.first + iterations.count {
        let start = std::time::Instant::now();
        let step = iterate(state, iteration, &rule)?;
        let distance = rule.record(step);
        let report = IterationReport { iteration, step, seconds: start.elapsed().as_secs_f64() };
        summary = SolveSummary {
            iterations: iteration + 1,
            converged: distance < iterations.tolerance,
            final_step: step,
            distance,
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

    /// `x <- rho x` from 1 (steps `(1 - rho) rho^k`, distance to 0 after step k `rho^(k+1)`), driven
    /// by `run_iterations` with `tolerance`; returns the distance of the answer to the fixed point.
    #[test]
    fn a_measured_contraction_lengthens_the_bound_of_fast_shrinking_steps() {
        // Steps shrinking tenfold (an accelerated sequence) bound the distance by step / 9; the
        // plain map's own contraction 0.99 says the iterate may be 99 steps away.
        let mut rule = DistanceBound::new(1e-3);
        for k in 0..CONTRACTION_WINDOW {
            rule.record(10f64.powi(-(k as i32)));
        }
        let step = 1e-4;
        assert!((rule.distance_after(step) - step * 0.1 / 0.9).abs() < 1e-15);
        assert!(rule.is_met_by(step));
        rule.contraction_at_least(0.99);
        assert!((rule.distance_after(step) - step * 99.0).abs() < 1e-12);
        assert!(!rule.is_met_by(step));
        // Taken by one record only.
        rule.record(step);
        assert!(rule.distance_after(step / 10.0) < 1e-3);
    }

    fn geometric_answer(rho: f64, tolerance: f64) -> (f64, SolveSummary) {
        let iterations = Iterations { first: 0, count: 1_000_000, tolerance };
        let mut x = 1.0_f64;
        let iterate = |x: &mut f64, _: usize, _: &DistanceBound| -> Result<f64, MethodError> {
            let next = rho * *x;
            let step = (*x - next).abs();
            *x = next;
            Ok(step)
        };
        let summary = run_iterations(iterations, &mut x, iterate, |_| Vec::new(), &mut NoObserver).unwrap();
        (x.abs(), summary)
    }

    #[test]
    fn the_stopping_rule_bounds_the_distance_to_the_fixed_point_of_a_slow_contraction() {
        // A step test at 1e-6 would stop with distance step * rho / (1 - rho) ~ 1e-3 here.
        for rho in [0.5, 0.9, 0.999] {
            let (distance, summary) = geometric_answer(rho, 1e-6);
            assert!(summary.converged, "rho {rho}: {summary:?}");
            assert!(distance < 1e-6, "rho {rho}: stopped {distance:e} from the fixed point");
            // Exact for a geometric sequence, so the estimate is the distance itself.
            assert!(
                (summary.distance - distance).abs() <= 1e-9 * distance.max(1e-300),
                "rho {rho}: {summary:?} vs {distance:e}"
            );
            // Not much further than needed: the first iterate within the tolerance.
            assert!(distance > rho * 1e-6, "rho {rho}: ran past the tolerance, {distance:e}");
        }
    }

    #[test]
    fn the_stopping_rule_is_not_met_while_steps_grow_or_before_the_window_is_full() {
        let mut rule = DistanceBound::new(1e-3);
        for step in [1e-5; CONTRACTION_WINDOW] {
            assert!(!rule.is_met_by(step), "met before the window was full");
            rule.record(step);
        }
        // Constant steps: no contraction shown, the bound assumes the slowest one (999 x step).
        assert!((rule.distance_after(1e-5) - 999.0 * 1e-5).abs() < 1e-12);
        assert!(!rule.is_met_by(2e-5), "growing steps");
        assert!(rule.is_met_by(1e-7), "a step of rounding, a thousandth of the tolerance");
        assert!(rule.is_met_by(0.0), "a zero step is a fixed point");
        let mut rule = DistanceBound::new(1e-3);
        for step in [8.0, 4.0, 2.0, 1.0] {
            rule.record(step);
        }
        assert_eq!(rule.distance_after(0.5), 0.5);
        // A floor from elsewhere (the gradient) holds for the next record only.
        rule.at_least(2.0);
        assert_eq!(rule.record(0.5), 2.0);
        assert_eq!(rule.record(0.25), 0.25);
    }
}
