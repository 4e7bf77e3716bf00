//! Driving a method through an edit: [`DeformationMethod::precompute`] once on the rest mesh, then
//! per edit step [`DeformationMethod::bind_handles`] and [`DeformationMethod::solve`], timing each
//! phase the papers time separately. The harness's cases, their repetitions and `check-method`
//! all run a method through [`drive`]; a user's program can too.
//!
//! Timings exclude the observer's own work (the harness measures iterates inside its observer)
//! and include what a method took from an identical earlier solve instead of computing it
//! ([`DeformationMethod::reused_solve`]), so that they are the whole computation's.

use std::ops::ControlFlow;
use std::time::Instant;

use meshes::TriMesh;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::method::{DeformationMethod, IterationObserver, IterationReport, ReusedSolve, SolveSummary};

/// One edit step: a handle set and where its constrained vertices go.
pub trait EditStep {
    /// The handle set bound at this step (the fixed region counts as one of its regions).
    fn handles(&self) -> &HandleSet;

    /// The targets of [`Self::handles`]' constrained vertices, given the method's current
    /// `#V x 3` positions (an incremental edit moves a region on from where the last step left it).
    fn targets(&self, current: &[[f64; 3]]) -> Result<HandleTargets, MethodError>;
}

/// The phase of a drive that failed ([`DriveFailure`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrivePhase {
    Precompute,
    /// The step's own targets (the edit, not the method, was at fault).
    Targets,
    BindHandles,
    Solve,
    /// The final positions: a non-finite coordinate.
    Result,
}

/// Why a drive stopped before its end: the phase, its 1-based edit step (none for precompute and
/// the result) and the method's error.
#[derive(Debug)]
pub struct DriveFailure {
    pub phase: DrivePhase,
    pub step: Option<usize>,
    pub error: MethodError,
}

/// One edit step as driven.
#[derive(Clone, Debug)]
pub struct DrivenStep {
    /// Wall seconds of `bind_handles`.
    pub bind_s: f64,
    /// Wall seconds of `solve`, the observer's work excluded and the reused part included.
    pub solve_s: f64,
    pub summary: SolveSummary,
    /// The part of the solve taken from an earlier identical one, if any.
    pub reused: Option<ReusedSolve>,
    /// The targets solved for, one per constrained vertex in [`HandleSet::constrained`] order.
    pub targets: HandleTargets,
    /// Every iteration's report, in order.
    pub iterations: Vec<IterationReport>,
    /// The method's phase timings after this step ([`DeformationMethod::phase_timings`]).
    pub phase_timings: Vec<(String, f64)>,
}

/// What [`drive`] measured. On a failure, everything up to the failing phase.
#[derive(Debug)]
pub struct Drive {
    /// Wall seconds of `precompute` (NaN if it failed).
    pub precompute_s: f64,
    /// The steps that completed, in order.
    pub steps: Vec<DrivenStep>,
    /// Wall seconds from the start of `precompute` to the end of the last step, the observer's
    /// work excluded and reused solves included.
    pub total_s: f64,
    /// Wall seconds the observer spent in its callbacks.
    pub observer_s: f64,
    /// The method's `#V x 3` positions at the end (empty if precompute failed).
    pub positions: Vec<[f64; 3]>,
    /// The method's model statistics at the end ([`DeformationMethod::model_statistics`]).
    pub statistics: Vec<(String, f64)>,
    /// Why it stopped early, if it did.
    pub failure: Option<DriveFailure>,
}

impl Drive {
    /// Iterations over every completed step.
    pub fn iterations(&self) -> usize {
        self.steps.iter().map(|s| s.summary.iterations).sum()
    }

    /// Seconds taken from earlier identical solves over every completed step.
    pub fn reused_s(&self) -> f64 {
        self.steps.iter().filter_map(|s| s.reused.as_ref()).map(|r| r.seconds).sum()
    }
}

/// Run `method` through `steps` on `rest`: precompute, then bind and solve each step in order,
/// `observer` told of each step ([`IterationObserver::on_edit_step`]) and iteration.
///
/// # Inputs
/// - `method`: a fresh instance (precompute resets it to the rest shape).
/// - `rest`: the rest mesh, `#V` vertices.
/// - `steps`: at least one edit step, each with a handle set of `#V` vertices.
///
/// # Outputs
/// The timings, each step's summary, targets and iterations, and the final `#V x 3` positions
/// (checked finite); on a method error, what completed before it and the failure.
pub fn drive<S: EditStep>(
    method: &mut dyn DeformationMethod,
    rest: &TriMesh,
    steps: &[S],
    observer: &mut dyn IterationObserver,
) -> Drive {
    let mut timed = TimedObserver { inner: observer, seconds: 0.0, iterations: Vec::new() };
    let mut drive = Drive {
        precompute_s: f64::NAN,
        steps: Vec::with_capacity(steps.len()),
        total_s: f64::NAN,
        observer_s: 0.0,
        positions: Vec::new(),
        statistics: Vec::new(),
        failure: None,
    };
    let start = Instant::now();
    if let Err(error) = method.precompute(rest) {
        drive.failure = Some(DriveFailure { phase: DrivePhase::Precompute, step: None, error });
        return drive;
    }
    drive.precompute_s = start.elapsed().as_secs_f64();
    for (i, step) in steps.iter().enumerate() {
        match drive_step(method, step, i + 1, &mut timed) {
            Ok(driven) => drive.steps.push(driven),
            Err(failure) => {
                drive.failure = Some(failure);
                break;
            }
        }
    }
    drive.observer_s = timed.seconds;
    drive.total_s = start.elapsed().as_secs_f64() - timed.seconds + drive.reused_s();
    drive.positions = method.positions();
    drive.statistics = method.model_statistics();
    if drive.failure.is_none() {
        drive.failure = non_finite(method.name(), &drive.positions);
    }
    drive
}

/// Bind and solve edit step `number` (1-based) of a method already precomputed.
fn drive_step(
    method: &mut dyn DeformationMethod,
    step: &impl EditStep,
    number: usize,
    observer: &mut TimedObserver<'_>,
) -> Result<DrivenStep, DriveFailure> {
    let fail = |phase| move |error| DriveFailure { phase, step: Some(number), error };
    let targets = step.targets(&method.positions()).map_err(fail(DrivePhase::Targets))?;
    let t = Instant::now();
    method.bind_handles(step.handles()).map_err(fail(DrivePhase::BindHandles))?;
    let bind_s = t.elapsed().as_secs_f64();
    observer.inner.on_edit_step(number);
    let observed_before = observer.seconds;
    let t = Instant::now();
    let summary = method.solve(&targets, observer).map_err(fail(DrivePhase::Solve))?;
    let reused = method.reused_solve();
    let solve_s = t.elapsed().as_secs_f64() - (observer.seconds - observed_before)
        + reused.as_ref().map_or(0.0, |r| r.seconds);
    Ok(DrivenStep {
        bind_s,
        solve_s,
        summary,
        reused,
        targets,
        iterations: std::mem::take(&mut observer.iterations),
        phase_timings: method.phase_timings(),
    })
}

/// [`MethodError::NonFiniteResult`] at the first vertex of `positions` with a non-finite coordinate.
fn non_finite(method: &str, positions: &[[f64; 3]]) -> Option<DriveFailure> {
    let vertex = positions.iter().position(|p| p.iter().any(|c| !c.is_finite()))?;
    Some(DriveFailure {
        phase: DrivePhase::Result,
        step: None,
        error: MethodError::NonFiniteResult { method: method.to_string(), vertex },
    })
}

/// The drive's observer around the caller's: keeps every report and times the caller's callbacks.
struct TimedObserver<'a> {
    inner: &'a mut dyn IterationObserver,
    seconds: f64,
    iterations: Vec<IterationReport>,
}

impl IterationObserver for TimedObserver<'_> {
    fn on_iteration(
        &mut self,
        report: &IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()> {
        self.iterations.push(*report);
        let t = Instant::now();
        let flow = self.inner.on_iteration(report, shape);
        self.seconds += t.elapsed().as_secs_f64();
        flow
    }
}

/// An edit step given by its handle set and fixed targets (they do not depend on the current shape).
pub struct FixedStep {
    pub handles: HandleSet,
    pub targets: Vec<[f64; 3]>,
}

impl EditStep for FixedStep {
    fn handles(&self) -> &HandleSet {
        &self.handles
    }

    fn targets(&self, _: &[[f64; 3]]) -> Result<HandleTargets, MethodError> {
        HandleTargets::new(&self.handles, self.targets.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::handles::HandleRegion;
    use crate::method::NoObserver;
    use meshes::shapes::{generate, ShapeKind};
    use meshes::VertexStatus;

    /// The survey's bar twist at about 300 vertices, as one fixed step.
    fn bar_twist() -> (TriMesh, FixedStep) {
        let shape = generate(ShapeKind::Bar, 300).unwrap();
        let of = |status| -> Vec<u32> {
            (0..shape.mesh.n_vertices() as u32).filter(|&v| shape.selection[v as usize] == status).collect()
        };
        let regions = vec![
            HandleRegion { name: "fixed".into(), vertices: of(VertexStatus::Fixed) },
            HandleRegion { name: "handle".into(), vertices: of(VertexStatus::Handle) },
        ];
        let handles = HandleSet::new(regions, shape.mesh.n_vertices()).unwrap();
        let targets = handles
            .constrained()
            .map(|v| {
                let p = shape.mesh.positions()[v as usize];
                match shape.selection[v as usize] {
                    VertexStatus::Handle => shape.transform.apply(p),
                    _ => p,
                }
            })
            .collect();
        (shape.mesh, FixedStep { handles, targets })
    }

    #[test]
    fn a_drive_gives_the_positions_of_the_phases_called_by_hand() {
        let (mesh, step) = bar_twist();
        let mut by_hand = crate::registry::create("laplacian", &toml::Table::new()).unwrap();
        by_hand.precompute(&mesh).unwrap();
        by_hand.bind_handles(&step.handles).unwrap();
        let summary = by_hand.solve(&step.targets(&[]).unwrap(), &mut NoObserver).unwrap();

        let mut driven = crate::registry::create("laplacian", &toml::Table::new()).unwrap();
        let drive = drive(driven.as_mut(), &mesh, std::slice::from_ref(&step), &mut NoObserver);
        assert!(drive.failure.is_none(), "{:?}", drive.failure);
        assert_eq!(drive.steps.len(), 1);
        assert_eq!(drive.steps[0].summary, summary);
        assert_eq!(drive.steps[0].iterations.len(), summary.iterations);
        assert_eq!(drive.iterations(), summary.iterations);
        let bits = |p: &[[f64; 3]]| p.iter().flatten().map(|c| c.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&drive.positions), bits(&by_hand.positions()));
        assert!(drive.precompute_s >= 0.0 && drive.total_s >= drive.precompute_s);
    }

    #[test]
    fn a_failing_step_names_its_phase_and_step_and_keeps_what_came_before() {
        let (mesh, step) = bar_twist();
        // A handle set of another mesh's size: the second step's bind fails.
        let other =
            HandleSet::new(vec![HandleRegion { name: "h".into(), vertices: vec![0] }], mesh.n_vertices() + 1)
                .unwrap();
        let wrong = FixedStep { handles: other, targets: vec![[0.0; 3]] };
        let steps = [step, wrong];
        let mut m = crate::registry::create("laplacian", &toml::Table::new()).unwrap();
        let drive = drive(m.as_mut(), &mesh, &steps, &mut NoObserver);
        let failure = drive.failure.as_ref().expect("the second step fails");
        assert_eq!((failure.phase, failure.step), (DrivePhase::BindHandles, Some(2)), "{failure:?}");
        assert_eq!(drive.steps.len(), 1);
        assert_eq!(drive.positions.len(), mesh.n_vertices());
    }

    #[test]
    fn the_observer_hears_each_edit_step_before_its_iterations() {
        struct Heard(Vec<(usize, usize)>, usize);
        impl IterationObserver for Heard {
            fn on_edit_step(&mut self, step: usize) {
                self.1 = step;
            }
            fn on_iteration(
                &mut self,
                r: &IterationReport,
                _: Option<&dyn Fn() -> Vec<[f64; 3]>>,
            ) -> ControlFlow<()> {
                self.0.push((self.1, r.iteration));
                ControlFlow::Continue(())
            }
        }
        let (mesh, step) = bar_twist();
        let again = FixedStep { handles: step.handles.clone(), targets: step.targets.clone() };
        let mut m = crate::registry::create("laplacian", &toml::Table::new()).unwrap();
        let mut heard = Heard(Vec::new(), 0);
        let drive = drive(m.as_mut(), &mesh, &[step, again], &mut heard);
        assert!(drive.failure.is_none());
        let first = drive.steps[0].summary.iterations;
        assert_eq!(heard.0.len(), drive.iterations());
        assert!(
            heard.0[..first].iter().all(|(s, _)| *s == 1) && heard.0[first..].iter().all(|(s, _)| *s == 2)
        );
    }
}
