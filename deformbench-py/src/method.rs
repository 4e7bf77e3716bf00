//! `Method`: one deformation method on one rest mesh, in the papers' phases, as libigl's
//! `arap_precomputation` / `arap_solve`: the constructor precomputes, `bind` takes the handle set,
//! `solve` the handles' targets. The calls the harness's `drive` makes, on the same configuration,
//! so a result equals `harness run`'s to the last bit.

use std::sync::Mutex;
use std::time::Instant;

use methods::scale_aware::SolveMemo;
use methods::{DeformationMethod, HandleRegion, HandleSet, HandleTargets, NoObserver};
use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyTuple};

use crate::arrays;
use crate::configuration::catalog;
use crate::errors::{without_panic, DeformbenchError};

/// The handle set of the last `bind`: whether its first region is `fixed`, and how many handles.
struct BoundHandles {
    set: HandleSet,
    has_fixed: bool,
    n_handles: usize,
}

/// A deformation method precomputed on a rest mesh (see the type stub for the Python side).
#[pyclass(module = "deformbench")]
pub struct Method {
    /// In a mutex only to make the class `Sync`, as PyO3 asks: `&mut self` methods reach it
    /// without locking.
    method: Mutex<Box<dyn DeformationMethod>>,
    rest: Vec<[f64; 3]>,
    bound: Option<BoundHandles>,
    /// The method's name as given (a built-in method or a variant of `configs/methods.toml`).
    #[pyo3(get)]
    name: String,
    /// Iterations of the last solve (1 for a direct method).
    #[pyo3(get)]
    iterations: usize,
    /// Whether the last solve met its stopping rule (a direct method always does).
    #[pyo3(get)]
    converged: bool,
    /// Wall seconds of the precomputation, the last bind and the last solve.
    #[pyo3(get)]
    precompute_seconds: f64,
    #[pyo3(get)]
    bind_seconds: f64,
    #[pyo3(get)]
    solve_seconds: f64,
}

#[pymethods]
impl Method {
    /// Precompute method `name` on the rest mesh `V` (`#V x 3` float64) and `F` (`#F x 3` int),
    /// with `params` laid over the configuration's (`configs/methods.toml`).
    #[new]
    #[pyo3(signature = (name, V, F, **params))]
    #[allow(non_snake_case)]
    fn new(
        py: Python<'_>,
        name: &str,
        V: &Bound<'_, PyAny>,
        F: &Bound<'_, PyAny>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let rest = arrays::points("V", V)?;
        let triangles = arrays::faces("F", F, rest.len())?;
        let mut method = create(name, params)?;
        let mesh = meshes::TriMesh::new(rest.clone(), triangles)
            .map_err(|e| PyValueError::new_err(format!("V, F: {e}")))?;
        let start = Instant::now();
        py.allow_threads(|| {
            without_panic(&format!("{name}: precompute"), || {
                method
                    .precompute(&mesh)
                    .map_err(|e| DeformbenchError::new_err(format!("{name}: precompute: {e}")))
            })
        })?;
        Ok(Method {
            method: Mutex::new(method),
            rest,
            bound: None,
            name: name.to_string(),
            iterations: 0,
            converged: false,
            precompute_seconds: start.elapsed().as_secs_f64(),
            bind_seconds: 0.0,
            solve_seconds: 0.0,
        })
    }

    /// Bind the handle set: `fixed` (1-D int, held at their rest positions; may be empty) and
    /// `handles` (a list of 1-D int arrays, one region each, moved by `solve`'s targets).
    #[pyo3(signature = (fixed, handles = None))]
    fn bind(
        &mut self,
        py: Python<'_>,
        fixed: &Bound<'_, PyAny>,
        handles: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let n = self.rest.len();
        let fixed = arrays::vertex_list("fixed", fixed, n)?;
        let handles = match handles {
            Some(h) => arrays::vertex_lists("handles", h, n)?,
            None => Vec::new(),
        };
        let has_fixed = !fixed.is_empty();
        let n_handles = handles.len();
        let mut regions = Vec::with_capacity(n_handles + 1);
        if has_fixed {
            regions.push(HandleRegion { name: "fixed".into(), vertices: fixed });
        }
        for (i, vertices) in handles.into_iter().enumerate() {
            regions.push(HandleRegion { name: format!("handle {}", i + 1), vertices });
        }
        let set =
            HandleSet::new(regions, n).map_err(|e| PyValueError::new_err(format!("fixed, handles: {e}")))?;
        let (method, name) = (method_mut(&mut self.method), &self.name);
        let start = Instant::now();
        py.allow_threads(|| {
            without_panic(&format!("{name}: bind"), || {
                method.bind_handles(&set).map_err(|e| DeformbenchError::new_err(format!("{name}: bind: {e}")))
            })
        })?;
        self.bind_seconds = start.elapsed().as_secs_f64();
        self.bound = Some(BoundHandles { set, has_fixed, n_handles });
        Ok(())
    }

    /// Solve for `targets` (a list of `#h_i x 3` float64 arrays, where the vertices of
    /// `handles[i]` go, in their order); the fixed vertices stay at rest. Returns the `#V x 3`
    /// deformed positions.
    #[pyo3(signature = (targets = None))]
    fn solve<'py>(
        &mut self,
        py: Python<'py>,
        targets: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let Some(bound) = &self.bound else {
            return Err(DeformbenchError::new_err(format!(
                "{}: solve before bind: call bind(fixed, handles) first",
                self.name
            )));
        };
        let lists = match targets {
            Some(t) => arrays::point_lists("targets", t)?,
            None => Vec::new(),
        };
        let targets = handle_targets(bound, &self.rest, lists)?;
        let (method, name) = (method_mut(&mut self.method), &self.name);
        let start = Instant::now();
        let summary = py.allow_threads(|| {
            without_panic(&format!("{name}: solve"), || {
                method
                    .solve(&targets, &mut NoObserver)
                    .map_err(|e| DeformbenchError::new_err(format!("{name}: solve: {e}")))
            })
        })?;
        self.solve_seconds = start.elapsed().as_secs_f64();
        self.iterations = summary.iterations;
        self.converged = summary.converged;
        Ok(arrays::to_numpy(py, &method_mut(&mut self.method).positions()))
    }

    /// The `#V x 3` current positions (the rest mesh before the first solve).
    fn positions<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        arrays::to_numpy(py, &method_mut(&mut self.method).positions())
    }

    /// The method's own figures of its last solve (e.g. `arap`'s saddle test energies), by name.
    fn statistics(&mut self) -> Vec<(String, f64)> {
        method_mut(&mut self.method).model_statistics()
    }

    fn __repr__(&self) -> String {
        format!("deformbench.Method({:?}, #V={})", self.name, self.rest.len())
    }
}

/// The method behind its mutex (a panic caught mid-call leaves it poisoned, not unusable).
fn method_mut(method: &mut Mutex<Box<dyn DeformationMethod>>) -> &mut Box<dyn DeformationMethod> {
    method.get_mut().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The handle targets of `bound` from the `lists` of `solve` (one per handle), the fixed region at
/// `rest`.
fn handle_targets(
    bound: &BoundHandles,
    rest: &[[f64; 3]],
    lists: Vec<Vec<[f64; 3]>>,
) -> PyResult<HandleTargets> {
    if lists.len() != bound.n_handles {
        return Err(PyValueError::new_err(format!(
            "targets: {} arrays for {} handles (one #h_i x 3 array per handle of bind)",
            lists.len(),
            bound.n_handles
        )));
    }
    let regions = bound.set.regions();
    let handle_regions = if bound.has_fixed { &regions[1..] } else { regions };
    let mut positions = Vec::with_capacity(bound.set.n_constrained());
    if bound.has_fixed {
        positions.extend(regions[0].vertices.iter().map(|&v| rest[v as usize]));
    }
    for (i, (region, list)) in handle_regions.iter().zip(lists).enumerate() {
        if list.len() != region.vertices.len() {
            return Err(PyValueError::new_err(format!(
                "targets[{i}]: {} rows for the {} vertices of handles[{i}]",
                list.len(),
                region.vertices.len()
            )));
        }
        positions.extend(list);
    }
    HandleTargets::new(&bound.set, positions).map_err(|e| PyValueError::new_err(format!("targets: {e}")))
}

/// Method `name` of the configuration, `params` laid over its parameters.
fn create(name: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<Box<dyn DeformationMethod>> {
    let configured = catalog()?.find(name).map_err(DeformbenchError::new_err)?;
    let harness::config::Implementation::BuiltIn(entry) = &configured.implementation else {
        return Err(DeformbenchError::new_err(format!(
            "`{name}` is an external program ({}); run it with `harness run --method {name}`",
            configured.file.display()
        )));
    };
    let mut table = configured.params.clone();
    for (key, value) in params.into_iter().flat_map(|p| p.iter()) {
        let key: String = key.extract()?;
        let value = toml_value(&key, &value)?;
        table.insert(key, value);
    }
    without_panic(&format!("{name}: create"), || {
        (entry.create)(&table, &SolveMemo::default())
            .map_err(|e| DeformbenchError::new_err(format!("{name}: {e}")))
    })
}

/// A Python parameter value as the TOML value a configuration would give (`bool`, `int`, `float`,
/// `str`, lists and dicts of them).
fn toml_value(key: &str, value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(b) = value.downcast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if let Ok(i) = value.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(x) = value.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    if let Ok(s) = value.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value.try_iter()?.map(|item| toml_value(key, &item?)).collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if let Ok(dict) = value.downcast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in dict.iter() {
            table.insert(k.extract()?, toml_value(key, &v)?);
        }
        return Ok(toml::Value::Table(table));
    }
    Err(PyValueError::new_err(format!(
        "parameter `{key}`: a {} is not a configuration value (bool, int, float, str, list, dict)",
        value.get_type().name()?
    )))
}

/// The names `Method` takes: the built-in methods and the variants of the configuration.
#[pyfunction(name = "methods")]
pub fn method_names() -> PyResult<Vec<String>> {
    Ok(catalog()?
        .methods()
        .iter()
        .filter(|m| matches!(m.implementation, harness::config::Implementation::BuiltIn(_)))
        .map(|m| m.name.clone())
        .collect())
}
