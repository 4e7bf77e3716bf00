//! A Python object as a deformation method in the harness's process (`deformbench.run`): the
//! protocol's phases as Python calls, so the code of an external method (docs/protocol.md) runs
//! unchanged in-process:
//! - an object with `precompute(V, F)`, `bind(regions)` and `solve(constrained, targets)` (as
//!   `external/example/harmonic_displacement.py`'s class), or a class of such objects (one new
//!   instance per case);
//! - or a function `f(V, F, constrained, targets)`, a direct method called at solve.
//!
//! `solve` (or `f`) returns the `#V x 3` positions, or the protocol's answer as a dict
//! (`positions`, and optionally `iterations`, `converged`). Arrays are numpy: `V` `#V x 3`
//! float64, `F` `#F x 3` int64, each region and `constrained` 1-D int64, `targets` `#b x 3`.

use meshes::TriMesh;
use methods::{DeformationMethod, HandleSet, HandleTargets, IterationObserver, MethodError, SolveSummary};
use numpy::ndarray::Array1;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use crate::arrays;

/// What the user's Python object is.
enum Shape {
    /// An object with the three phases.
    Phased(Py<PyAny>),
    /// A function of `(V, F, constrained, targets)`.
    Function(Py<PyAny>),
}

/// What a `solve` answered: the positions, and what it said of its iterations.
struct Answer {
    positions: Vec<[f64; 3]>,
    iterations: Option<usize>,
    converged: Option<bool>,
}

/// The user's object behind [`DeformationMethod`].
pub struct PythonMethod {
    name: String,
    shape: Shape,
    rest: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    constrained: Vec<u32>,
    current: Vec<[f64; 3]>,
}

impl PythonMethod {
    /// The method `name` of `object` (a phased object, a class of them, or a function); a class
    /// is instantiated here, so each case gets its own.
    pub fn new(name: &str, object: &Py<PyAny>) -> Result<Self, MethodError> {
        Python::with_gil(|py| {
            let object = object.bind(py);
            let shape = if object.is_instance_of::<PyType>() {
                Shape::Phased(object.call0().map_err(|e| error(name, "creating an instance", e))?.unbind())
            } else if object.hasattr("solve").unwrap_or(false) {
                Shape::Phased(object.clone().unbind())
            } else {
                Shape::Function(object.clone().unbind())
            };
            Ok(PythonMethod {
                name: name.to_string(),
                shape,
                rest: Vec::new(),
                faces: Vec::new(),
                constrained: Vec::new(),
                current: Vec::new(),
            })
        })
    }

    /// The positions of a `solve` answer: an array, or a dict with `positions` (and
    /// `iterations`, `converged`).
    fn read_answer(&self, answer: &Bound<'_, PyAny>) -> Result<Answer, MethodError> {
        let fail = |e: PyErr| error(&self.name, "solve's answer", e);
        let (positions, iterations, converged) = match answer.downcast::<PyDict>() {
            Ok(dict) => {
                let positions =
                    dict.get_item("positions").map_err(fail)?.ok_or_else(|| MethodError::External {
                        method: self.name.clone(),
                        message: "solve's answer has no `positions`".into(),
                    })?;
                // The optional entries, converted when present.
                fn entry<'py, T: FromPyObject<'py>>(
                    dict: &Bound<'py, PyDict>,
                    key: &str,
                ) -> PyResult<Option<T>> {
                    dict.get_item(key)?.map(|value| value.extract()).transpose()
                }
                (positions, entry(dict, "iterations").map_err(fail)?, entry(dict, "converged").map_err(fail)?)
            }
            Err(_) => (answer.clone(), None, None),
        };
        let positions = arrays::points("positions", &positions).map_err(fail)?;
        if positions.len() != self.rest.len() {
            return Err(MethodError::External {
                method: self.name.clone(),
                message: format!(
                    "solve returned {} positions for {} vertices",
                    positions.len(),
                    self.rest.len()
                ),
            });
        }
        Ok(Answer { positions, iterations, converged })
    }
}

/// A Python exception raised in `phase` of method `name`, as the method's error (with its
/// traceback's last line: the exception's type and message).
fn error(name: &str, phase: &str, e: PyErr) -> MethodError {
    let message = Python::with_gil(|py| {
        let kind = e.get_type(py).name().map(|n| n.to_string()).unwrap_or_else(|_| "Exception".into());
        format!("{phase}: {kind}: {}", e.value(py))
    });
    MethodError::External { method: name.to_string(), message }
}

/// A 1-D int64 numpy array of vertex indices.
fn index_array<'py>(py: Python<'py>, indices: &[u32]) -> Bound<'py, PyAny> {
    Array1::from_iter(indices.iter().map(|&v| v as i64)).into_pyarray(py).into_any()
}

impl DeformationMethod for PythonMethod {
    fn name(&self) -> &str {
        &self.name
    }

    fn precompute(&mut self, rest: &TriMesh) -> Result<(), MethodError> {
        self.rest = rest.positions().to_vec();
        self.faces = rest.triangles().to_vec();
        self.current = self.rest.clone();
        Python::with_gil(|py| match &self.shape {
            Shape::Phased(object) => {
                let (v, f) = (arrays::to_numpy(py, &self.rest), arrays::faces_to_numpy(py, &self.faces));
                object
                    .call_method1(py, "precompute", (v, f))
                    .map_err(|e| error(&self.name, "precompute", e))?;
                Ok(())
            }
            Shape::Function(_) => Ok(()),
        })
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        self.constrained = handles.constrained().collect();
        Python::with_gil(|py| match &self.shape {
            Shape::Phased(object) => {
                let regions: Vec<Bound<'_, PyAny>> =
                    handles.regions().iter().map(|r| index_array(py, &r.vertices)).collect();
                object.call_method1(py, "bind", (regions,)).map_err(|e| error(&self.name, "bind", e))?;
                Ok(())
            }
            Shape::Function(_) => Ok(()),
        })
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        _observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let Answer { positions, iterations, converged } = Python::with_gil(|py| {
            let constrained = index_array(py, &self.constrained);
            let targets = arrays::to_numpy(py, targets.positions());
            let answer = match &self.shape {
                Shape::Phased(object) => object.call_method1(py, "solve", (constrained, targets)),
                Shape::Function(f) => {
                    let (v, faces) =
                        (arrays::to_numpy(py, &self.rest), arrays::faces_to_numpy(py, &self.faces));
                    f.call1(py, (v, faces, constrained, targets))
                }
            }
            .map_err(|e| error(&self.name, "solve", e))?;
            self.read_answer(answer.bind(py))
        })?;
        self.current = positions;
        // A direct method unless it says (one iteration, converged), as the example external
        // method answers through the protocol.
        Ok(SolveSummary {
            iterations: iterations.unwrap_or(1),
            converged: converged.unwrap_or(true),
            final_step: f64::NAN,
            distance: 0.0,
            convergence_unknown: false,
        })
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }
}
