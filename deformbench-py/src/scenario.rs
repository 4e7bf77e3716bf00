//! `load_scenario`: a scenario file of `configs/scenarios/` (or a user's) as arrays, loaded as the
//! harness loads it ([`harness::scenario::ScenarioSpec::load`]): the mesh, and per edit step its
//! fixed vertices, its handles and their targets.

use std::path::PathBuf;

use harness::scenario::{DataSource, LoadedScenario, Role};
use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays;
use crate::errors::DeformbenchError;

/// A loaded scenario (see the type stub).
#[pyclass(module = "deformbench", frozen)]
pub struct Scenario {
    loaded: LoadedScenario,
    /// Its name (`bar`; `<collection>-<mesh>` for a member of a collection).
    #[pyo3(get)]
    name: String,
    /// `survey`, `procedural look-alike` or `file`.
    #[pyo3(get)]
    mesh_source: String,
}

#[pymethods]
impl Scenario {
    /// `#V x 3` rest positions.
    #[getter(V)]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        arrays::to_numpy(py, self.loaded.mesh.positions())
    }

    /// `#F x 3` faces.
    #[getter(F)]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<i64>> {
        arrays::faces_to_numpy(py, self.loaded.mesh.triangles())
    }

    /// The number of edit steps.
    #[getter]
    fn n_steps(&self) -> usize {
        self.loaded.steps.len()
    }

    /// The vertices held at step `step` (its fixed regions, in order), as `Method.bind`'s `fixed`.
    #[pyo3(signature = (step = 0))]
    fn fixed(&self, step: usize) -> PyResult<Vec<u32>> {
        Ok(self.regions_of(step, Role::Fixed)?.into_iter().flatten().collect())
    }

    /// The handle regions of step `step`, in order, as `Method.bind`'s `handles`.
    #[pyo3(signature = (step = 0))]
    fn handles(&self, step: usize) -> PyResult<Vec<Vec<u32>>> {
        self.regions_of(step, Role::Handle)
    }

    /// Where the handles of step `step` go from the `#V x 3` shape `current` the step starts from
    /// (default: the rest mesh), as `Method.solve`'s `targets`: one `#h_i x 3` array per handle.
    #[pyo3(signature = (step = 0, current = None))]
    fn targets<'py>(
        &self,
        py: Python<'py>,
        step: usize,
        current: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Vec<Bound<'py, PyArray2<f64>>>> {
        let loaded = self.step(step)?;
        let current = match current {
            Some(c) => arrays::points("current", c)?,
            None => self.loaded.mesh.positions().to_vec(),
        };
        if current.len() != self.loaded.mesh.n_vertices() {
            return Err(PyValueError::new_err(format!(
                "current: {} rows, the mesh has {}",
                current.len(),
                self.loaded.mesh.n_vertices()
            )));
        }
        let targets = loaded.targets(&current).map_err(|e| DeformbenchError::new_err(e.to_string()))?;
        let mut positions = targets.positions();
        let mut out = Vec::new();
        for (region, role) in loaded.handles.regions().iter().zip(&loaded.roles) {
            let (mine, rest) = positions.split_at(region.vertices.len());
            positions = rest;
            if *role == Role::Handle {
                out.push(arrays::to_numpy(py, mine));
            }
        }
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!(
            "deformbench.Scenario({:?}, #V={}, {} step(s), {})",
            self.name,
            self.loaded.mesh.n_vertices(),
            self.loaded.steps.len(),
            self.mesh_source
        )
    }
}

impl Scenario {
    fn step(&self, step: usize) -> PyResult<&harness::scenario::LoadedStep> {
        self.loaded.steps.get(step).ok_or_else(|| {
            PyValueError::new_err(format!(
                "step {step}: the scenario has {} step(s)",
                self.loaded.steps.len()
            ))
        })
    }

    /// The vertex lists of the regions of `step` with `role`, in order.
    fn regions_of(&self, step: usize, role: Role) -> PyResult<Vec<Vec<u32>>> {
        let loaded = self.step(step)?;
        Ok(loaded
            .handles
            .regions()
            .iter()
            .zip(&loaded.roles)
            .filter(|(_, r)| **r == role)
            .map(|(region, _)| region.vertices.clone())
            .collect())
    }
}

/// `path` itself when it is a file, else the file of the configuration's scenario named `path`
/// (its `name`, as `harness run --scenario` matches it: `bar` is `configs/scenarios/bar.toml`).
fn scenario_file(path: PathBuf) -> PyResult<PathBuf> {
    if path.exists() {
        return Ok(path);
    }
    let dir = crate::configuration::configs_dir().map_err(DeformbenchError::new_err)?.join("scenarios");
    let specs = harness::scenario::load_specs(&dir).map_err(|e| DeformbenchError::new_err(e.to_string()))?;
    let name = path.to_string_lossy();
    if let Some(spec) = specs.iter().find(|s| s.name == name) {
        return Ok(spec.path.clone());
    }
    let known: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
    Err(DeformbenchError::new_err(format!(
        "{name}: no such file, nor a scenario of {}{} (known: {})",
        dir.display(),
        harness::error::did_you_mean(&name, known.iter().copied()),
        known.join(", ")
    )))
}

/// Load the scenario file `path` (or the configuration's scenario of that name) on the survey data
/// of `survey_dir` (default: the `DEFORM_SURVEY_DIR` environment variable), else on its
/// procedural look-alike.
#[pyfunction]
#[pyo3(signature = (path, survey_dir = None))]
pub fn load_scenario(py: Python<'_>, path: PathBuf, survey_dir: Option<PathBuf>) -> PyResult<Scenario> {
    let survey_dir =
        survey_dir.or_else(|| std::env::var_os(harness::paths::SURVEY_DIR_ENV).map(PathBuf::from));
    let source = match survey_dir {
        Some(dir) => DataSource::Survey(dir),
        None => DataSource::Procedural,
    };
    let error = |e: harness::HarnessError| DeformbenchError::new_err(e.to_string());
    let path = scenario_file(path)?;
    let spec = harness::scenario::load_spec(&path).map_err(error)?;
    let mut loaded = py.allow_threads(|| spec.load(&source)).map_err(error)?.scenarios;
    if loaded.len() != 1 {
        return Err(DeformbenchError::new_err(format!(
            "{}: a collection of {} meshes; load_scenario takes a single-mesh scenario",
            path.display(),
            loaded.len()
        )));
    }
    let loaded = loaded.remove(0);
    Ok(Scenario { name: loaded.spec.name.clone(), mesh_source: loaded.mesh_source.clone(), loaded })
}
