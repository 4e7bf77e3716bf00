//! Running one case (scenario x method) through the method's phases and measuring it into its
//! record ([`crate::record::CaseResult`]).

use std::ops::ControlFlow;
use std::time::Instant;

use crate::config::{ConfiguredMethod, Origin};
use crate::metrics::{
    angle_errors, asked_scale, asked_turn, evaluate_on, largest_displacement, Bends, RestGeometry,
};
use crate::record::{
    records_quality, CaseResult, IterationRecord, ReusedSolveRecord, Spread, StepRecord, TimingSpread,
};
use crate::scenario::LoadedScenario;
use crate::step_trend::StepTrend;
use crate::verdict::{Motion, Status, Unfinished, VerdictRules};
use methods::{IterationObserver, IterationReport};

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

/// The seconds of every iteration of a repetition (which records nothing else).
struct IterationClock(Vec<f64>);

impl IterationObserver for IterationClock {
    fn on_iteration(
        &mut self,
        r: &IterationReport,
        _: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()> {
        self.0.push(r.seconds);
        ControlFlow::Continue(())
    }
}

/// Median, min and max of `values` (not empty).
fn median_spread(mut values: Vec<f64>) -> (f64, Spread) {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let median = if n % 2 == 1 { values[n / 2] } else { 0.5 * (values[n / 2 - 1] + values[n / 2]) };
    (median, Spread { min: values[0], max: values[n - 1] })
}

/// One more repetition of `method` on `scenario` (a round of `--repeat`): a fresh instance through
/// every edit step, observed only for its iteration times; its timings and final `#V x 3` positions.
pub(crate) fn repetition(
    scenario: &LoadedScenario,
    method: &ConfiguredMethod,
    threads: usize,
) -> Result<(Timings, Vec<[f64; 3]>), methods::MethodError> {
    let mut m = method.create(None, threads)?;
    let startup_s = m.startup_seconds().unwrap_or(f64::NAN);
    let mut clock = IterationClock(Vec::new());
    let start = Instant::now();
    m.precompute(&scenario.mesh)?;
    let precompute_s = start.elapsed().as_secs_f64();
    let (mut first_bind_s, mut solve_s, mut reused_s) = (f64::NAN, 0.0, 0.0);
    for step in &scenario.steps {
        let targets = step.targets(&m.positions())?;
        let t = Instant::now();
        m.bind_handles(&step.handles)?;
        if first_bind_s.is_nan() {
            first_bind_s = t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        m.solve(&targets, &mut clock)?;
        solve_s += t.elapsed().as_secs_f64();
        reused_s += m.reused_solve().map_or(0.0, |r| r.seconds);
    }
    solve_s += reused_s;
    let total_s = start.elapsed().as_secs_f64() + reused_s;
    let median_iteration_ms = median_of_seconds_ms(clock.0);
    Ok((
        Timings { startup_s, precompute_s, bind_s: first_bind_s, median_iteration_ms, solve_s, total_s },
        m.positions(),
    ))
}

/// Records every iteration, with the angle errors of the iterate where [`records_quality`] says so.
struct Recorder<'a> {
    scenario: &'a LoadedScenario,
    rest: &'a RestGeometry,
    trace: Vec<IterationRecord>,
    /// 1-based edit step being solved.
    edit_step: usize,
    /// Wall time spent evaluating the angle errors, excluded from the reported solve times.
    quality_s: f64,
}

impl IterationObserver for Recorder<'_> {
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

/// The result the distances to the reference method (`arap`) are measured against.
#[derive(Clone, Copy, Debug)]
pub enum Reference<'a> {
    /// This case is the reference (its distances are 0).
    Itself,
    /// The reference's `#V x 3` result on the same scenario, and whether it finished (ok or
    /// suspect: not an iterate stopped at its cap).
    Of { positions: &'a [[f64; 3]], finished: bool },
    /// No reference result (not run, or failed).
    Missing,
}

/// How the cases of a run are run.
#[derive(Clone, Copy, Debug)]
pub struct CaseSettings {
    /// Worker threads (the pool the case runs in; an external method's thread variables).
    pub threads: usize,
    /// Measure the peak memory ([`crate::memory`]): only when one case runs at a time.
    pub measure_memory: bool,
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
    settings: CaseSettings,
    rules: &VerdictRules,
    reference: Reference<'_>,
) -> CaseResult {
    let CaseSettings { threads, measure_memory } = settings;
    let params = &method.params;
    let mut result = CaseResult::empty(
        &scenario.spec.name,
        &method.name,
        &scenario.mesh_source,
        scenario.mesh.n_vertices(),
        scenario.mesh.n_faces(),
    );
    result.origin = method.origin;
    result.member = scenario.member.clone();
    result.series = scenario.spec.series.clone();
    result.sweeps = method.sweeps.clone();
    result.laplacian_weights = match method.origin {
        Origin::BuiltIn => laplacian_weights(params),
        Origin::External | Origin::Peer => String::new(),
    };
    let mut recorder = Recorder { scenario, rest, trace: Vec::new(), edit_step: 0, quality_s: 0.0 };
    let mut unfinished = Vec::new();
    let cap = params.get("max_iterations").and_then(toml::Value::as_integer).map(|c| c as usize);
    let tolerance = params.get("tolerance").and_then(toml::Value::as_float);
    let outcome = (|| -> Result<Vec<String>, methods::MethodError> {
        let memory =
            (measure_memory && method.origin == Origin::BuiltIn).then(crate::memory::start_peak).flatten();
        let mut m = method.create(stderr_log, threads)?;
        result.startup_s = m.startup_seconds().unwrap_or(f64::NAN);
        result.about = m.about();
        let start = Instant::now();
        m.precompute(&scenario.mesh)?;
        result.precompute_s = start.elapsed().as_secs_f64();
        let mut solve_s = 0.0;
        let mut final_edit = None;
        let mut largest_handle_move = 0.0f64;
        for (i, step) in scenario.steps.iter().enumerate() {
            let targets = step.targets(&m.positions())?;
            for (v, t) in step.handles.constrained().zip(targets.positions()) {
                let d = meshes::vector::norm(meshes::vector::sub(*t, scenario.mesh.positions()[v as usize]));
                largest_handle_move = largest_handle_move.max(d);
            }
            let t = Instant::now();
            m.bind_handles(&step.handles)?;
            let bind_s = t.elapsed().as_secs_f64();
            let first_iteration = recorder.trace.len();
            recorder.edit_step = i + 1;
            let quality_before = recorder.quality_s;
            let t = Instant::now();
            let summary = m.solve(&targets, &mut recorder)?;
            let reused = m.reused_solve();
            let reused_solve_s = reused.as_ref().map_or(0.0, |r| r.seconds);
            let step_solve_s =
                t.elapsed().as_secs_f64() - (recorder.quality_s - quality_before) + reused_solve_s;
            solve_s += step_solve_s;
            if let Some(r) = reused {
                let record = result
                    .reused_solve
                    .get_or_insert(ReusedSolveRecord { from: r.from.to_string(), seconds: 0.0 });
                record.seconds += r.seconds;
            }
            result.iterations += summary.iterations;
            result.convergence_unknown |= summary.convergence_unknown;
            if !summary.converged {
                unfinished.push(Unfinished {
                    step: i + 1,
                    steps: scenario.steps.len(),
                    iterations: summary.iterations,
                    cap,
                    last_step: summary.final_step,
                    distance: summary.distance,
                    tolerance,
                    trend: tolerance.and_then(|t| {
                        let steps: Vec<f64> =
                            recorder.trace[first_iteration..].iter().map(|r| r.step).collect();
                        StepTrend::of(&steps, t).map(|trend| trend.with_distance(summary.distance, t))
                    }),
                });
            }
            result.steps.push(StepRecord {
                step: i + 1,
                handles: step.handles.regions().len(),
                constrained_vertices: step.handles.n_constrained(),
                bind_s,
                solve_s: step_solve_s,
                iterations: summary.iterations,
                converged: summary.converged,
                final_step: summary.final_step,
                fixed_point_distance: summary.distance,
                median_iteration_ms: median_ms(&recorder.trace[first_iteration..]),
                reused_solve_s,
                phase_timings: m.phase_timings(),
            });
            final_edit = Some((step, targets));
        }
        result.converged = result.steps.iter().all(|s| s.converged);
        result.fixed_point_distance = result.steps.iter().map(|s| s.fixed_point_distance).fold(0.0, nan_max);
        let positions = m.positions();
        result.bind_s = result.steps.first().map_or(f64::NAN, |s| s.bind_s);
        result.solve_s = solve_s;
        let reused_s = result.reused_solve.as_ref().map_or(0.0, |r| r.seconds);
        result.total_s = start.elapsed().as_secs_f64() - recorder.quality_s + reused_s;
        result.peak_memory_mib = crate::memory::peak_since(memory).unwrap_or(f64::NAN);
        result.phase_timings = m.phase_timings();
        result.statistics = m.model_statistics();
        let (step, targets) = final_edit.expect("a scenario has at least one step");
        if let Some(v) = positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(methods::MethodError::NonFiniteResult { method: m.name().to_string(), vertex: v });
        }
        let evaluation_start = Instant::now();
        let (reference, reference_finished) = match reference {
            // Its own verdict does not wait for itself; its turn against itself is 0.
            Reference::Itself => (Some(&positions[..]), true),
            Reference::Of { positions, finished } => (Some(positions), finished),
            Reference::Missing => (None, false),
        };
        result.quality = evaluate_on(
            rest,
            &scenario.mesh,
            &scenario.topology,
            &positions,
            (&step.handles, &targets),
            reference,
        );
        result.largest_move_over_diag =
            largest_displacement(scenario.mesh.positions(), &positions) / rest.diagonal;
        result.largest_handle_move_over_diag = largest_handle_move / rest.diagonal;
        let motion = Motion {
            largest_move: result.largest_move_over_diag,
            largest_handle_move: result.largest_handle_move_over_diag,
            asked_turn_deg: asked_turn(scenario.mesh.positions(), &step.handles, &targets, Bends::FromHeld)
                .to_degrees(),
            asked_scale: asked_scale(scenario.mesh.positions(), &step.handles, &targets),
            reference_finished,
        };
        let mut reasons = rules.reasons(&result.quality, motion);
        // A process that outlived its case is the case's to say (the token kill missed it).
        reasons.extend(m.end());
        if result.convergence_unknown {
            reasons.push(CONVERGENCE_UNKNOWN.to_string());
        }
        result.positions = Some(positions);
        result.overhead.evaluation_s = evaluation_start.elapsed().as_secs_f64();
        Ok(reasons)
    })();
    result.median_iteration_ms = median_ms(&recorder.trace);
    result.trace = recorder.trace;
    result.overhead.trace_quality_s = recorder.quality_s;
    result.status = match outcome {
        Ok(reasons) => Status::judge(&unfinished, reasons),
        Err(e) => Status::Failed(e.to_string()),
    };
    result
}

/// The larger of `a` and `b`, NaN if either is (an unknown distance stays unknown).
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Fold the later repetitions of a case (rounds 2..N of `--repeat N`, from [`repetition`]) into
/// `result`, its first: the timings become medians with their spread; a repetition whose result is
/// not bitwise the first's, or that failed, makes the case `non-deterministic` (`diagonal`: the rest
/// bounding-box diagonal, to say how far apart).
pub(crate) fn add_repetitions(
    result: &mut CaseResult,
    diagonal: f64,
    later: Vec<Result<(Timings, Vec<[f64; 3]>), methods::MethodError>>,
) {
    let first = Timings {
        startup_s: result.startup_s,
        precompute_s: result.precompute_s,
        bind_s: result.bind_s,
        median_iteration_ms: result.median_iteration_ms,
        solve_s: result.solve_s,
        total_s: result.total_s,
    };
    let mut timings = vec![first];
    let mut reasons = Vec::new();
    for (k, again) in (2..).zip(later) {
        match again {
            Ok((t, positions)) => {
                timings.push(t);
                let reference = result.positions.as_deref().unwrap_or_default();
                let same = positions.len() == reference.len()
                    && positions
                        .iter()
                        .flatten()
                        .zip(reference.iter().flatten())
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                if !same && !reasons.iter().any(|r: &String| r.starts_with("non-deterministic")) {
                    let apart = largest_displacement(reference, &positions) / diagonal;
                    reasons.push(format!(
                        "non-deterministic: repetition {k}'s result differs from the first (up to {apart:.1e} of the diagonal)"
                    ));
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
    (result.precompute_s, result.bind_s, result.solve_s, result.total_s) =
        (precompute_s, bind_s, solve_s, total_s);
    (result.median_iteration_ms, result.startup_s) = (median_iteration_ms, startup_s);
    result.spread = Some(TimingSpread {
        repetitions: timings.len(),
        precompute_s: precompute,
        bind_s: bind,
        solve_s: solve,
        total_s: total,
        median_iteration_ms: iteration,
        startup_s: startup,
    });
    result.status.add_reasons(reasons);
}

/// The `weights` of a method's parameter table, else the shared default (every method's).
fn laplacian_weights(params: &toml::Table) -> String {
    match params.get("weights").and_then(|v| v.as_str()) {
        Some(name) => name.to_string(),
        None => methods::operators::LaplacianWeights::default().name().to_string(),
    }
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
