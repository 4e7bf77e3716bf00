//! A deformation method in another program, in any language: one more [`DeformationMethod`], driven
//! through the same phases as the built-in ones over the line protocol of [`protocol`].
//!
//! One process per case: [`ExternalMethod::start`] starts it and says `hello` (timed apart as the
//! start-up), `precompute`, `bind_handles` and `solve` each become one request, timed by the caller
//! like any method's phase, and the process keeps its state between the edit steps of a scenario.
//! Whatever goes wrong — the program cannot start, exits, answers garbage, the wrong number of
//! vertices, a non-finite position, or nothing within its timeout — becomes a
//! [`MethodError::External`] naming the request and quoting the last lines of its stderr, and the
//! process group is killed at once. Dropping the method asks the program to quit and kills whatever
//! is left of its group, so nothing outlives a case.

pub mod process;
pub mod protocol;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use meshes::TriMesh;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::method::{
    require_phase, DeformationMethod, IterationObserver, IterationReport, Phase, SolveSummary,
};
use process::MethodProcess;
use protocol::{Answer, Request};

/// The default timeout of one request: generous, for a slow method on a large mesh; a method entry
/// sets its own with `timeout_s`.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(600);

/// How to run one external method: everything resolved (variables expanded, paths absolute).
#[derive(Clone, Debug)]
pub struct ExternalSpec {
    /// The method's name in configs and reports.
    pub name: String,
    /// The program and its arguments.
    pub program: String,
    pub args: Vec<String>,
    /// Where it runs (default: the harness's working directory).
    pub working_dir: Option<PathBuf>,
    /// Added to its environment.
    pub env: Vec<(String, String)>,
    /// Longest wait for one answer.
    pub timeout: Duration,
    /// Its parameters, sent untouched in `hello`.
    pub params: serde_json::Value,
    /// Where its stderr is written (none: kept only for error messages).
    pub stderr_log: Option<PathBuf>,
    /// Whether it iterates (`kind = "iterative"`): then a solve without `converged` is reported as
    /// "convergence unknown"; a direct method's solve is finished by definition.
    pub iterative: bool,
}

/// A running external method.
pub struct ExternalMethod {
    spec: ExternalSpec,
    process: MethodProcess,
    /// Wall seconds from starting the process to its answer to `hello`.
    startup_s: f64,
    /// The program's `about`, if it said one.
    about: Option<String>,
    n_vertices: usize,
    /// The last result (`#V x 3`); the rest shape after `precompute`.
    current: Vec<[f64; 3]>,
    /// Constrained vertices of the bound handle set, in the order their targets come.
    constrained: Vec<u32>,
    /// The method's own timings (`own_<name>`), latest answer per name.
    own_timings: Vec<(String, f64)>,
    statistics: Vec<(String, f64)>,
}

impl ExternalMethod {
    /// Start the program of `spec` and greet it. Errors: it cannot start, or does not answer
    /// `hello` with this protocol and version.
    pub fn start(spec: ExternalSpec) -> Result<Self, MethodError> {
        let start = Instant::now();
        let process = MethodProcess::start(
            &spec.program,
            &spec.args,
            spec.working_dir.as_ref(),
            &spec.env,
            spec.stderr_log.as_ref(),
        )
        .map_err(|fault| MethodError::External {
            method: spec.name.clone(),
            message: format!("`{}` {fault}", spec.program),
        })?;
        let mut method = ExternalMethod {
            spec,
            process,
            startup_s: 0.0,
            about: None,
            n_vertices: 0,
            current: Vec::new(),
            constrained: Vec::new(),
            own_timings: Vec::new(),
            statistics: Vec::new(),
        };
        let params = method.spec.params.clone();
        let name = method.spec.name.clone();
        let hello = Request::Hello {
            protocol: protocol::PROTOCOL,
            version: protocol::VERSION,
            method: &name,
            params: &params,
        };
        let answer = method.call("hello", &hello)?;
        if answer.protocol.as_deref() != Some(protocol::PROTOCOL) || answer.version != Some(protocol::VERSION)
        {
            return Err(method.fail(
                "hello",
                format!(
                    "speaks {} version {}, the harness speaks {} version {}",
                    answer.protocol.as_deref().unwrap_or("<no protocol>"),
                    answer.version.map_or("<none>".to_string(), |v| v.to_string()),
                    protocol::PROTOCOL,
                    protocol::VERSION
                ),
            ));
        }
        method.about = answer.about;
        method.startup_s = start.elapsed().as_secs_f64();
        Ok(method)
    }

    /// Send `request` (named `what` in errors) and read its answer; any fault or an `ok: false`
    /// answer kills the process and becomes an error.
    fn call(&mut self, what: &str, request: &Request<'_>) -> Result<Answer, MethodError> {
        let line = match self.process.request(protocol::encode(request), self.spec.timeout) {
            Ok(line) => line,
            Err(fault) => return Err(self.fail(what, fault.to_string())),
        };
        let answer = protocol::decode(&line).map_err(|message| self.fail(what, message))?;
        if !answer.ok {
            let error = answer.error.clone().unwrap_or_else(|| "no error message".to_string());
            return Err(self.fail(what, format!("answered an error: {error}")));
        }
        for (name, seconds) in &answer.timings {
            let key = format!("own_{name}");
            match self.own_timings.iter_mut().find(|(k, _)| *k == key) {
                Some(entry) => entry.1 = *seconds,
                None => self.own_timings.push((key, *seconds)),
            }
        }
        for (name, value) in &answer.statistics {
            match self.statistics.iter_mut().find(|(k, _)| k == name) {
                Some(entry) => entry.1 = *value,
                None => self.statistics.push((name.clone(), *value)),
            }
        }
        Ok(answer)
    }

    /// Kill the process and describe what happened during request `what`, with the last lines of
    /// its stderr.
    fn fail(&mut self, what: &str, message: String) -> MethodError {
        self.process.kill();
        let tail = self.process.stderr_tail();
        let stderr = if tail.is_empty() {
            "its stderr is empty".to_string()
        } else {
            format!("last lines of its stderr: {}", tail.join(" | "))
        };
        MethodError::External {
            method: self.spec.name.clone(),
            message: format!("`{what}`: {message}; {stderr}"),
        }
    }

    /// Check a `solve` answer's positions: `#V` of them, all finite.
    fn check_positions(&mut self, positions: Option<Vec<[f64; 3]>>) -> Result<Vec<[f64; 3]>, MethodError> {
        let Some(positions) = positions else {
            return Err(self.fail("solve", "answered without `positions`".into()));
        };
        if positions.len() != self.n_vertices {
            let message =
                format!("answered {} positions for a mesh of {} vertices", positions.len(), self.n_vertices);
            return Err(self.fail("solve", message));
        }
        if let Some(v) = positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(self.fail("solve", format!("answered a non-finite position at vertex {v}")));
        }
        Ok(positions)
    }
}

impl DeformationMethod for ExternalMethod {
    fn name(&self) -> &str {
        &self.spec.name
    }

    /// Its `max_iterations` (an integer) and `tolerance` (a float) parameters, where its entry
    /// gives them: the program's own stopping rule is its business, these are only quoted.
    fn stopping(&self) -> Option<crate::method::Stopping> {
        let max_iterations =
            self.spec.params.get("max_iterations").and_then(|v| v.as_u64()).map(|c| c as usize);
        let tolerance = self.spec.params.get("tolerance").filter(|v| v.is_f64()).and_then(|v| v.as_f64());
        (max_iterations.is_some() || tolerance.is_some())
            .then_some(crate::method::Stopping { max_iterations, tolerance })
    }

    fn precompute(&mut self, rest: &TriMesh) -> Result<(), MethodError> {
        self.call(
            "precompute",
            &Request::Precompute { vertices: rest.positions(), faces: rest.triangles() },
        )?;
        self.n_vertices = rest.n_vertices();
        self.current = rest.positions().to_vec();
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        require_phase((!self.current.is_empty()).then_some(()), "external", Phase::BindHandles)?;
        handles.check_mesh_size(self.n_vertices)?;
        let regions: Vec<&[u32]> = handles.regions().iter().map(|r| &r.vertices[..]).collect();
        self.call("bind", &Request::Bind { regions })?;
        self.constrained = handles.constrained().collect();
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        if targets.positions().len() != self.constrained.len() {
            return Err(MethodError::Targets(format!(
                "{} targets for {} constrained vertices",
                targets.positions().len(),
                self.constrained.len()
            )));
        }
        let constrained = std::mem::take(&mut self.constrained);
        let answer =
            self.call("solve", &Request::Solve { constrained: &constrained, targets: targets.positions() });
        self.constrained = constrained;
        let answer = answer?;
        self.current = self.check_positions(answer.positions)?;
        // The method's iterates stay in its process: the observer gets each iteration's step and
        // time, not its shape.
        for (iteration, entry) in answer.trace.iter().enumerate() {
            let report = IterationReport { iteration, step: entry.step, seconds: entry.seconds };
            let _ = observer.on_iteration(&report, None);
        }
        let iterations = answer.iterations.unwrap_or(answer.trace.len());
        let final_step = answer.final_step.or(answer.trace.last().map(|t| t.step)).unwrap_or(f64::NAN);
        // A direct method has nothing to report; an iterative one that says nothing cannot be told
        // from one that stopped early, and is reported so.
        Ok(SolveSummary {
            iterations,
            converged: answer.converged.unwrap_or(true),
            final_step,
            distance: answer.distance.unwrap_or(if self.spec.iterative { f64::NAN } else { 0.0 }),
            convergence_unknown: self.spec.iterative && answer.converged.is_none(),
        })
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }

    fn phase_timings(&self) -> Vec<(String, f64)> {
        self.own_timings.clone()
    }

    fn model_statistics(&self) -> Vec<(String, f64)> {
        self.statistics.clone()
    }

    fn startup_seconds(&self) -> Option<f64> {
        Some(self.startup_s)
    }

    fn about(&self) -> Option<String> {
        self.about.clone()
    }

    fn end(&mut self) -> Vec<String> {
        self.process.finish(protocol::encode(&Request::Quit));
        let escaped = self.process.escaped();
        if !escaped.killed.is_empty() {
            eprintln!(
                "warning: method `{}`: killed {} process(es) it started that had left its process group (pids {:?})",
                self.spec.name,
                escaped.killed.len(),
                escaped.killed
            );
        }
        if escaped.alive.is_empty() {
            Vec::new()
        } else {
            vec![format!("left processes running: {:?} outlived SIGKILL", escaped.alive)]
        }
    }
}

impl Drop for ExternalMethod {
    fn drop(&mut self) {
        // After `end` (the case's), a no-op; a method dropped on an error path ends here.
        self.process.finish(protocol::encode(&Request::Quit));
    }
}
