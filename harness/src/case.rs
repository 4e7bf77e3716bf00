//! Running one case (scenario x method) through the method's phases and measuring it into its
//! record ([`crate::record::CaseResult`]).

use std::ops::ControlFlow;
use std::time::Instant;

use crate::config::{ConfiguredMethod, Origin};
use crate::metrics::{angle_errors, largest_displacement, Quality, RestGeometry};
use crate::record::{
    records_quality, CaseResult, IterationRecord, MeasurementTime, ReusedSolveRecord, Spread, StepRecord,
    TimingSpread,
};
use crate::scenario::{LoadedScenario, LoadedStep};
use crate::step_trend::StepTrend;
pub use crate::verdict::Reference;
use crate::verdict::{Status, Unfinished, VerdictRules};
use methods::drive::{drive, Drive, DrivenStep, EditStep};
use methods::{HandleSet, HandleTargets, IterationObserver, IterationReport, NoObserver, Stopping};

/// The reason a case of an iterative method that did not report its convergence is `suspect`.
pub const CONVERGENCE_UNKNOWN: &str =
    "convergence unknown: an iterative method that did not say whether its solve converged";

/// The timed phases of one repetition of a case.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Timings {
    startup_s: f64,
    precompute_s: f64,
    bind_s: f64,
    median_iteration_ms: f64,
    solve_s: f64,
    total_s: f64,
}

/// Median, min and max of `values` (not empty).
fn median_spread(mut values: Vec<f64>) -> (f64, Spread) {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let median = if n % 2 == 1 { values[n / 2] } else { 0.5 * (values[n / 2 - 1] + values[n / 2]) };
    (median, Spread { min: values[0], max: values[n - 1] })
}

/// A scenario's edit step as [`methods::drive`] takes it.
impl EditStep for LoadedStep {
    fn handles(&self) -> &HandleSet {
        &self.handles
    }

    fn targets(&self, current: &[[f64; 3]]) -> Result<HandleTargets, methods::MethodError> {
        LoadedStep::targets(self, current)
    }
}

/// One more repetition of `method` on `scenario` (a round of `--repeat`): a fresh instance through
/// every edit step, observed only by the drive; its timings and final `#V x 3` positions.
pub(crate) fn repetition(
    scenario: &LoadedScenario,
    method: &ConfiguredMethod,
    settings: CaseSettings<'_>,
) -> Result<(Timings, Vec<[f64; 3]>), methods::MethodError> {
    let mut m = method.create(None, settings.threads, settings.solves)?;
    let startup_s = m.startup_seconds().unwrap_or(f64::NAN);
    let drive = drive(m.as_mut(), &scenario.mesh, &scenario.steps, &mut NoObserver);
    if let Some(failure) = drive.failure {
        return Err(failure.error);
    }
    let seconds = drive.steps.iter().flat_map(|s| &s.iterations).map(|r| r.seconds).collect();
    let timings = Timings {
        startup_s,
        precompute_s: drive.precompute_s,
        bind_s: drive.steps.first().map_or(f64::NAN, |s| s.bind_s),
        median_iteration_ms: median_of_seconds_ms(seconds),
        solve_s: drive.steps.iter().map(|s| s.solve_s).sum(),
        total_s: drive.total_s,
    };
    Ok((timings, drive.positions))
}

/// Records every iteration, with the angle errors of the iterate where [`records_quality`] says so.
/// The drive excludes the time spent here from the solve times.
struct Recorder<'a> {
    scenario: &'a LoadedScenario,
    rest: &'a RestGeometry,
    trace: Vec<IterationRecord>,
    /// 1-based edit step being solved.
    edit_step: usize,
    /// Wall time spent evaluating the angle errors.
    quality_s: f64,
}

impl IterationObserver for Recorder<'_> {
    fn on_edit_step(&mut self, step: usize) {
        self.edit_step = step;
    }

    fn on_iteration(
        &mut self,
        r: &IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()> {
        let mut record = IterationRecord {
            edit_step: self.edit_step,
            iteration: r.iteration,
            step: r.step,
            seconds: r.seconds,
            e_theta_deg: None,
            e_phi_deg: None,
        };
        if let (true, Some(shape)) = (records_quality(r.iteration), shape) {
            let t = Instant::now();
            let (e_theta, e_phi) =
                angle_errors(self.rest, &self.scenario.mesh, &self.scenario.topology, &shape());
            record.e_theta_deg = Some(e_theta);
            record.e_phi_deg = Some(e_phi);
            self.quality_s += t.elapsed().as_secs_f64();
        }
        self.trace.push(record);
        ControlFlow::Continue(())
    }
}

/// How the cases of a run are run.
#[derive(Clone, Copy, Debug)]
pub struct CaseSettings<'a> {
    /// Worker threads (the pool the case runs in; an external method's thread variables).
    pub threads: usize,
    /// Measure the peak memory ([`crate::memory`]): only when one case runs at a time.
    pub measure_memory: bool,
    /// The run's memo of solves, shared by its cases' instances ([`ConfiguredMethod::create`]).
    pub solves: &'a methods::scale_aware::SolveMemo,
}

/// What the method instance said of itself once started.
struct Started {
    startup_s: f64,
    about: Option<String>,
    stopping: Option<Stopping>,
    weights: Option<methods::operators::LaplacianWeights>,
}

/// The measures of a finished drive and the reasons it is suspect.
struct Judged {
    quality: Quality,
    largest_move_over_diag: f64,
    largest_handle_move_over_diag: f64,
    reasons: Vec<String>,
    evaluation_s: f64,
}

/// Run `method` on `scenario` (a fresh instance; an external method's stderr goes to `stderr_log`),
/// as `settings` say, measure the result against `rest` (the scenario's rest geometry) and
/// `reference`, and judge it by `rules`. A method error becomes a `failed` result; it does not abort
/// the run.
pub fn run_case(
    scenario: &LoadedScenario,
    rest: &RestGeometry,
    method: &ConfiguredMethod,
    stderr_log: Option<std::path::PathBuf>,
    settings: CaseSettings<'_>,
    rules: &VerdictRules,
    reference: Reference<'_>,
) -> CaseResult {
    let memory = (settings.measure_memory && method.origin == Origin::BuiltIn)
        .then(crate::memory::start_peak)
        .flatten();
    let mut instance = match method.create(stderr_log, settings.threads, settings.solves) {
        Ok(m) => m,
        Err(e) => {
            return CaseRecord { scenario, method, started: None, drive: None, trace: Vec::new() }.failed(e)
        }
    };
    let started = Started {
        startup_s: instance.startup_seconds().unwrap_or(f64::NAN),
        about: instance.about(),
        stopping: instance.stopping(),
        weights: instance.laplacian_weights(),
    };
    let mut recorder = Recorder { scenario, rest, trace: Vec::new(), edit_step: 0, quality_s: 0.0 };
    let drive = drive(instance.as_mut(), &scenario.mesh, &scenario.steps, &mut recorder);
    let peak_memory_mib = crate::memory::peak_since(memory).unwrap_or(f64::NAN);
    let trace_quality_s = recorder.quality_s;
    let unfinished = unfinished_steps(&drive, started.stopping, scenario.steps.len());
    let judged = match &drive.failure {
        None => Ok(judge(scenario, rest, &drive, instance.as_mut(), rules, reference)),
        Some(failure) => Err(failure.error.to_string()),
    };
    let record =
        CaseRecord { scenario, method, started: Some(started), drive: Some(drive), trace: recorder.trace };
    record.build(peak_memory_mib, trace_quality_s, judged, &unfinished)
}

/// The unfinished steps of `drive` (not converged), quoting the method's `stopping` rule.
fn unfinished_steps(drive: &Drive, stopping: Option<Stopping>, steps: usize) -> Vec<Unfinished> {
    let cap = stopping.and_then(|s| s.max_iterations);
    let tolerance = stopping.and_then(|s| s.tolerance);
    (1..)
        .zip(&drive.steps)
        .filter(|(_, s)| !s.summary.converged)
        .map(|(step, s)| Unfinished {
            step,
            steps,
            iterations: s.summary.iterations,
            cap,
            last_step: s.summary.final_step,
            distance: s.summary.distance,
            tolerance,
            trend: tolerance.and_then(|t| {
                let sizes: Vec<f64> = s.iterations.iter().map(|r| r.step).collect();
                StepTrend::of(&sizes, t).map(|trend| trend.with_distance(s.summary.distance, t))
            }),
        })
        .collect()
}

/// Measure the final shape of a finished `drive` and say why it is suspect, if it is: the rules'
/// reasons, what the method could not end (`instance`'s [`methods::DeformationMethod::end`]) and an
/// unknown convergence.
fn judge(
    scenario: &LoadedScenario,
    rest: &RestGeometry,
    drive: &Drive,
    instance: &mut dyn methods::DeformationMethod,
    rules: &VerdictRules,
    reference: Reference<'_>,
) -> Judged {
    let start = Instant::now();
    let steps: Vec<(&HandleSet, &HandleTargets)> = scenario
        .steps
        .iter()
        .zip(&drive.steps)
        .map(|(step, driven)| (&step.handles, &driven.targets))
        .collect();
    let measures::Judgement { quality, motion, mut reasons } = measures::judge_on(
        rules,
        rest,
        &scenario.mesh,
        &scenario.topology,
        &drive.positions,
        &steps,
        reference,
    );
    // A process that outlived its case is the case's to say (the token kill missed it).
    reasons.extend(instance.end());
    if drive.steps.iter().any(|s| s.summary.convergence_unknown) {
        reasons.push(CONVERGENCE_UNKNOWN.to_string());
    }
    Judged {
        quality,
        largest_move_over_diag: motion.largest_move,
        largest_handle_move_over_diag: motion.largest_handle_move,
        reasons,
        evaluation_s: start.elapsed().as_secs_f64(),
    }
}

/// What a case's record is built from: who it is, what the instance said, the drive (its final
/// positions move into the record) and its trace.
struct CaseRecord<'a> {
    scenario: &'a LoadedScenario,
    method: &'a ConfiguredMethod,
    started: Option<Started>,
    drive: Option<Drive>,
    trace: Vec<IterationRecord>,
}

impl CaseRecord<'_> {
    /// The record of a case whose method did not start.
    fn failed(self, error: methods::MethodError) -> CaseResult {
        self.build(f64::NAN, 0.0, Err(error.to_string()), &[])
    }

    /// The case's record: `judged` is the final shape's measures or the error that stopped the
    /// case. The totals of a drive that ran every step are kept even when its result is refused
    /// (non-finite), as the steps of a failed one are.
    fn build(
        self,
        peak_memory_mib: f64,
        trace_quality_s: f64,
        judged: Result<Judged, String>,
        unfinished: &[Unfinished],
    ) -> CaseResult {
        let (scenario, method) = (self.scenario, self.method);
        let mut owned = self.drive;
        let positions = owned.as_mut().map(|d| std::mem::take(&mut d.positions));
        let drive = owned.as_ref();
        let ran_every_step = drive.is_some_and(|d| d.steps.len() == scenario.steps.len());
        let every_step = |value: f64| if ran_every_step { value } else { f64::NAN };
        let steps: &[DrivenStep] = drive.map_or(&[], |d| &d.steps);
        let started = self.started.as_ref();
        let laplacian_weights = match method.origin {
            Origin::BuiltIn => started.and_then(|s| s.weights).unwrap_or_default().name().to_string(),
            Origin::External | Origin::Peer => String::new(),
        };
        let (status, judged) = match judged {
            Ok(judged) => (Status::judge(unfinished, judged.reasons.clone()), Some(judged)),
            Err(error) => (Status::Failed(error), None),
        };
        CaseResult {
            scenario: scenario.spec.name.clone(),
            method: method.name.clone(),
            origin: method.origin,
            about: started.and_then(|s| s.about.clone()),
            mesh_source: scenario.mesh_source.clone(),
            member: scenario.member.clone(),
            series: scenario.spec.series.clone(),
            vertices: scenario.mesh.n_vertices(),
            faces: scenario.mesh.n_faces(),
            laplacian_weights,
            sweeps: method.sweeps.clone(),
            startup_s: started.map_or(f64::NAN, |s| s.startup_s),
            precompute_s: drive.map_or(f64::NAN, |d| d.precompute_s),
            bind_s: every_step(steps.first().map_or(f64::NAN, |s| s.bind_s)),
            median_iteration_ms: median_ms(&self.trace),
            iterations: steps.iter().map(|s| s.summary.iterations).sum(),
            solve_s: every_step(steps.iter().map(|s| s.solve_s).sum()),
            total_s: every_step(drive.map_or(f64::NAN, |d| d.total_s)),
            peak_memory_mib: every_step(peak_memory_mib),
            converged: ran_every_step && steps.iter().all(|s| s.summary.converged),
            fixed_point_distance: every_step(steps.iter().map(|s| s.summary.distance).fold(0.0, nan_max)),
            convergence_unknown: steps.iter().any(|s| s.summary.convergence_unknown),
            quality: judged.as_ref().map(|j| j.quality.clone()).unwrap_or_default(),
            largest_move_over_diag: judged.as_ref().map_or(f64::NAN, |j| j.largest_move_over_diag),
            largest_handle_move_over_diag: judged
                .as_ref()
                .map_or(f64::NAN, |j| j.largest_handle_move_over_diag),
            self_intersecting: None,
            status,
            phase_timings: match (ran_every_step, steps.last()) {
                (true, Some(last)) => last.phase_timings.clone(),
                _ => Vec::new(),
            },
            statistics: drive.filter(|_| ran_every_step).map_or_else(Vec::new, |d| d.statistics.clone()),
            reused_solve: reused_solve(steps),
            steps: step_records(steps, scenario),
            trace: self.trace,
            overhead: MeasurementTime {
                trace_quality_s,
                evaluation_s: judged.as_ref().map_or(0.0, |j| j.evaluation_s),
            },
            spread: None,
            positions: positions.filter(|_| judged.is_some()),
        }
    }
}

/// The solves `steps` took from another method's, summed, if any.
fn reused_solve(steps: &[DrivenStep]) -> Option<ReusedSolveRecord> {
    let from = steps.iter().find_map(|s| s.reused.as_ref())?.from.to_string();
    let seconds = steps.iter().filter_map(|s| s.reused.as_ref()).map(|r| r.seconds).fold(0.0, |a, b| a + b);
    Some(ReusedSolveRecord { from, seconds })
}

/// The records of the driven `steps` of `scenario`.
fn step_records(steps: &[DrivenStep], scenario: &LoadedScenario) -> Vec<StepRecord> {
    (1..)
        .zip(steps.iter().zip(&scenario.steps))
        .map(|(step, (driven, loaded))| StepRecord {
            step,
            handles: loaded.handles.regions().len(),
            constrained_vertices: loaded.handles.n_constrained(),
            bind_s: driven.bind_s,
            solve_s: driven.solve_s,
            iterations: driven.summary.iterations,
            converged: driven.summary.converged,
            final_step: driven.summary.final_step,
            fixed_point_distance: driven.summary.distance,
            median_iteration_ms: median_of_seconds_ms(driven.iterations.iter().map(|r| r.seconds).collect()),
            reused_solve_s: driven.reused.as_ref().map_or(0.0, |r| r.seconds),
            phase_timings: driven.phase_timings.clone(),
        })
        .collect()
}

/// The larger of `a` and `b`, NaN if either is (an unknown distance stays unknown).
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// `first`, the first repetition's record of a case, with its later repetitions (rounds 2..N of
/// `--repeat N`, from [`repetition`]) folded in: the timings become medians with their spread; a
/// repetition whose result is not bitwise the first's, or that failed, makes the case
/// `non-deterministic` (`diagonal`: the rest bounding-box diagonal, to say how far apart).
pub(crate) fn with_repetitions(
    first: CaseResult,
    diagonal: f64,
    later: Vec<Result<(Timings, Vec<[f64; 3]>), methods::MethodError>>,
) -> CaseResult {
    let mut timings = vec![Timings {
        startup_s: first.startup_s,
        precompute_s: first.precompute_s,
        bind_s: first.bind_s,
        median_iteration_ms: first.median_iteration_ms,
        solve_s: first.solve_s,
        total_s: first.total_s,
    }];
    let mut reasons = Vec::new();
    for (k, again) in (2..).zip(later) {
        match again {
            Ok((t, positions)) => {
                timings.push(t);
                let reference = first.positions.as_deref().unwrap_or_default();
                if let Some(apart) = apart(reference, &positions, diagonal) {
                    if !reasons.iter().any(|r: &String| r.starts_with("non-deterministic")) {
                        reasons.push(format!(
                            "non-deterministic: repetition {k}'s result differs from the first (up to {apart:.1e} of the diagonal)"
                        ));
                    }
                }
            }
            Err(e) => reasons.push(format!("non-deterministic: repetition {k} failed: {e}")),
        }
    }
    let spread = |f: fn(&Timings) -> f64| median_spread(timings.iter().map(f).collect());
    let (precompute_s, precompute) = spread(|t| t.precompute_s);
    let (bind_s, bind) = spread(|t| t.bind_s);
    let (solve_s, solve) = spread(|t| t.solve_s);
    let (total_s, total) = spread(|t| t.total_s);
    let (median_iteration_ms, iteration) = spread(|t| t.median_iteration_ms);
    let (startup_s, startup) = spread(|t| t.startup_s);
    let spread = TimingSpread {
        repetitions: timings.len(),
        precompute_s: precompute,
        bind_s: bind,
        solve_s: solve,
        total_s: total,
        median_iteration_ms: iteration,
        startup_s: startup,
    };
    let mut status = first.status.clone();
    status.add_reasons(reasons);
    CaseResult {
        precompute_s,
        bind_s,
        solve_s,
        total_s,
        median_iteration_ms,
        startup_s,
        spread: Some(spread),
        status,
        ..first
    }
}

/// How far apart `a` and `b` are over `diagonal` when they are not bitwise equal (`None` if they are).
fn apart(a: &[[f64; 3]], b: &[[f64; 3]], diagonal: f64) -> Option<f64> {
    let same = a.len() == b.len()
        && a.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| x.to_bits() == y.to_bits());
    (!same).then(|| largest_displacement(a, b) / diagonal)
}

/// Median iteration time in milliseconds (NaN for none).
fn median_ms(trace: &[IterationRecord]) -> f64 {
    median_of_seconds_ms(trace.iter().map(|r| r.seconds).collect())
}

/// The median of iteration `times` (seconds; the upper middle of an even count) in milliseconds;
/// NaN for none. The first round ([`median_ms`]) and the later ones ([`repetition`]) share it.
fn median_of_seconds_ms(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times.get(times.len() / 2).map_or(f64::NAN, |t| 1e3 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median_spread(vec![3.0, 1.0, 2.0]), (2.0, Spread { min: 1.0, max: 3.0 }));
        assert_eq!(median_spread(vec![4.0, 1.0, 2.0, 3.0]), (2.5, Spread { min: 1.0, max: 4.0 }));
        assert_eq!(median_spread(vec![5.0]), (5.0, Spread { min: 5.0, max: 5.0 }));
    }
}
