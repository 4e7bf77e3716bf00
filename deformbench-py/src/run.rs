//! `deformbench.run`: scenarios × methods through the harness's own runner ([`harness::suite::run`]
//! and [`harness::pipeline::publish`], what `harness run` calls), with Python objects among the
//! methods ([`crate::python_method`]): judged, timed and reported like an external method, into
//! the same reports directory; the rows of its `results.json` are returned.

use std::path::PathBuf;
use std::sync::Arc;

use harness::config::ProvidedMethod;
use harness::pipeline::{GateRequest, PublishOptions};
use harness::report::{MeshFormat, MeshOutput};
use harness::staged_dir::StagedDir;
use harness::suite::SuiteOptions;
use methods::{DeformationMethod, MethodError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::configuration::configs_dir;
use crate::errors::{without_panic, DeformbenchError};
use crate::python_method::PythonMethod;

/// Run `scenarios` (names of `configs/scenarios/` or scenario files) with `methods` (names, Python
/// objects, or `(name, object)` pairs) and write the reports to `reports`; returns the rows of
/// `results.json` (see the type stub).
#[pyfunction(name = "run")]
#[pyo3(signature = (scenarios, methods, reports = None, survey_dir = None, threads = None, repeat = 1, mesh_format = "glb"))]
#[allow(clippy::too_many_arguments)]
pub fn run_suite(
    py: Python<'_>,
    scenarios: Vec<String>,
    methods: &Bound<'_, PyAny>,
    reports: Option<PathBuf>,
    survey_dir: Option<PathBuf>,
    threads: Option<usize>,
    repeat: usize,
    mesh_format: &str,
) -> PyResult<PyObject> {
    let (names, provided) = method_list(methods)?;
    let format = match mesh_format {
        "glb" => MeshFormat::Glb,
        "off" => MeshFormat::Off,
        "both" => MeshFormat::Both,
        other => {
            return Err(PyValueError::new_err(format!(
                "mesh_format = {other:?}: \"glb\", \"off\" or \"both\""
            )))
        }
    };
    if repeat == 0 {
        return Err(PyValueError::new_err("repeat = 0: at least 1"));
    }
    let reports = reports.unwrap_or_else(harness::paths::default_reports_dir);
    let options = SuiteOptions {
        configs_dir: configs_dir().map_err(DeformbenchError::new_err)?,
        scenarios_dir: None,
        reports_dir: reports.clone(),
        survey_dir: survey_dir
            .or_else(|| std::env::var_os(harness::paths::SURVEY_DIR_ENV).map(PathBuf::from)),
        scenarios,
        methods: names,
        peers: None,
        sweeps: None,
        method_files: Vec::new(),
        python: std::env::var_os(harness::paths::PYTHON_ENV).map(PathBuf::from),
        threads: threads.unwrap_or_else(|| harness::threads::default_threads(1)),
        // One case at a time: a Python object given as an instance serves every case.
        jobs: 1,
        repetitions: repeat,
        command_line: vec!["deformbench.run".to_string()],
        progress: false,
        force: false,
        provided,
    };
    let publish = PublishOptions { peer_python: None, meshes: MeshOutput { format, every_scenario: false } };
    py.allow_threads(|| without_panic("run", || run_and_publish(&options, &publish)))?;
    let text = std::fs::read_to_string(reports.join("results.json"))
        .map_err(|e| DeformbenchError::new_err(format!("{}: {e}", reports.join("results.json").display())))?;
    let json = py.import("json")?.call_method1("loads", (text,))?;
    Ok(json.get_item("cases")?.unbind())
}

/// The suite run of `options`, published into its reports directory (staged, swapped in whole).
fn run_and_publish(options: &SuiteOptions, publish: &PublishOptions) -> PyResult<()> {
    let fail = |e: harness::HarnessError| DeformbenchError::new_err(e.to_string());
    let staging = StagedDir::begin(&options.reports_dir).map_err(fail)?;
    let mut staged = options.clone();
    staged.reports_dir = staging.path().to_path_buf();
    let mut run = harness::suite::run(&staged).map_err(fail)?;
    let pool = harness::threads::pool(options.threads).map_err(fail)?;
    let gate = GateRequest::Skip("deformbench.run covers chosen scenarios and methods".to_string());
    pool.install(|| harness::pipeline::publish(&staged, &mut run, publish, gate)).map_err(fail)?;
    staging.publish().map_err(fail)
}

/// The names of `methods` for the run, and the Python objects among them as methods in-process.
fn method_list(methods: &Bound<'_, PyAny>) -> PyResult<(Vec<String>, Vec<ProvidedMethod>)> {
    let (mut names, mut provided) = (Vec::new(), Vec::new());
    for item in methods.try_iter()? {
        let item = item?;
        if let Ok(name) = item.extract::<String>() {
            names.push(name);
            continue;
        }
        let (name, object) = match item.extract::<(String, Bound<'_, PyAny>)>() {
            Ok(pair) => pair,
            Err(_) => (python_name(&item)?, item),
        };
        let kind = if object.hasattr("solve")? || object.is_instance_of::<pyo3::types::PyType>() {
            "phased: precompute, bind, solve"
        } else if object.is_callable() {
            "a function of (V, F, constrained, targets)"
        } else {
            return Err(PyValueError::new_err(format!(
                "methods: `{name}` is neither a method name, an object with precompute/bind/solve, nor a function"
            )));
        };
        let object: Py<PyAny> = object.unbind();
        let own = name.clone();
        let create = Arc::new(move || -> Result<Box<dyn DeformationMethod>, MethodError> {
            Ok(Box::new(PythonMethod::new(&own, &object)?))
        });
        provided.push(ProvidedMethod {
            name: name.clone(),
            summary: format!("a Python method in-process ({kind})"),
            create,
        });
        names.push(name);
    }
    Ok((names, provided))
}

/// The name of a Python method object: its `name` attribute, else its `__name__` (a function or
/// class), else its class's.
fn python_name(object: &Bound<'_, PyAny>) -> PyResult<String> {
    for attribute in ["name", "__name__"] {
        if let Ok(name) = object.getattr(attribute).and_then(|n| n.extract::<String>()) {
            return Ok(name);
        }
    }
    object.get_type().name()?.extract()
}
