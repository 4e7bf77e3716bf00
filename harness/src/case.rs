//! Running one case (scenario x method) through the method's phases and measuring it.

use std::ops::ControlFlow;
use std::time::Instant;

use methods::{IterationObserver, IterationReport};
use serde::Serialize;

use crate::metrics::{angle_errors, handle_residual, RestAngles};
use crate::scenario::LoadedScenario;

/// One iteration as recorded for convergence curves.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct IterationRecord {
    pub iteration: usize,
    pub step: f64,
    pub seconds: f64,
}

/// Measurements of one case. Times are wall-clock seconds; the `*_over_diag` values are relative to
/// the rest bounding-box diagonal; angle errors are in degrees.
#[derive(Clone, Debug, Serialize)]
pub struct CaseResult {
    pub scenario: String,
    pub method: String,
    pub mesh_source: String,
    pub vertices: usize,
    pub faces: usize,
    pub precompute_s: f64,
    pub bind_s: f64,
    pub median_iteration_ms: f64,
    pub iterations: usize,
    pub solve_s: f64,
    pub total_s: f64,
    pub converged: bool,
    pub e_theta_deg: f64,
    pub e_phi_deg: f64,
    pub handle_residual_over_diag: f64,
    /// Filled in once the scenario's `arap` result is known.
    pub rms_to_arap_over_diag: Option<f64>,
    /// `ok`, or `failed: <reason>`.
    pub status: String,
    /// Method-specific phases (e.g. HIRM's t_e, t_b) in seconds.
    pub phase_timings: Vec<(String, f64)>,
    pub trace: Vec<IterationRecord>,
    #[serde(skip)]
    pub positions: Option<Vec<[f64; 3]>>,
}

struct Recorder(Vec<IterationRecord>);

impl IterationObserver for Recorder {
    fn on_iteration(&mut self, r: &IterationReport, _: &dyn Fn() -> Vec<[f64; 3]>) -> ControlFlow<()> {
        self.0.push(IterationRecord { iteration: r.iteration, step: r.step, seconds: r.seconds });
        ControlFlow::Continue(())
    }
}

/// Run `method` (with its parameter table) on `scenario`. A method error becomes a `failed` result;
/// it does not abort the run.
pub fn run_case(
    scenario: &LoadedScenario,
    rest_angles: &RestAngles,
    method: &str,
    params: &toml::Table,
) -> CaseResult {
    let mut result = CaseResult {
        scenario: scenario.spec.name.clone(),
        method: method.to_string(),
        mesh_source: scenario.mesh_source.clone(),
        vertices: scenario.mesh.n_vertices(),
        faces: scenario.mesh.n_faces(),
        precompute_s: f64::NAN,
        bind_s: f64::NAN,
        median_iteration_ms: f64::NAN,
        iterations: 0,
        solve_s: f64::NAN,
        total_s: f64::NAN,
        converged: false,
        e_theta_deg: f64::NAN,
        e_phi_deg: f64::NAN,
        handle_residual_over_diag: f64::NAN,
        rms_to_arap_over_diag: None,
        status: String::new(),
        phase_timings: Vec::new(),
        trace: Vec::new(),
        positions: None,
    };
    let mut recorder = Recorder(Vec::new());
    let outcome = (|| -> Result<(), methods::MethodError> {
        let mut m = methods::registry::create(method, params)?;
        let start = Instant::now();
        m.precompute(&scenario.mesh)?;
        result.precompute_s = start.elapsed().as_secs_f64();
        let t = Instant::now();
        m.bind_handles(&scenario.handles)?;
        result.bind_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let summary = m.solve(&scenario.targets, &mut recorder)?;
        let positions = m.positions();
        result.solve_s = t.elapsed().as_secs_f64();
        result.total_s = start.elapsed().as_secs_f64();
        result.iterations = summary.iterations;
        result.converged = summary.converged;
        result.phase_timings = m.phase_timings().into_iter().map(|(k, v)| (k.to_string(), v)).collect();
        if let Some(v) = positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(methods::MethodError::NonFinite {
                method: m.name(),
                vertex: v,
                iteration: summary.iterations,
            });
        }
        let diagonal = scenario.mesh.bbox_diagonal();
        let (e_theta, e_phi) = angle_errors(rest_angles, &scenario.mesh, &scenario.topology, &positions);
        result.e_theta_deg = e_theta;
        result.e_phi_deg = e_phi;
        result.handle_residual_over_diag =
            handle_residual(&scenario.handles, &scenario.targets, &positions, diagonal);
        result.positions = Some(positions);
        Ok(())
    })();
    result.trace = recorder.0;
    if !result.trace.is_empty() {
        let mut times: Vec<f64> = result.trace.iter().map(|r| r.seconds).collect();
        times.sort_by(f64::total_cmp);
        result.median_iteration_ms = 1e3 * times[times.len() / 2];
    }
    result.status = match outcome {
        Ok(()) => "ok".into(),
        Err(e) => format!("failed: {e}"),
    };
    result
}
