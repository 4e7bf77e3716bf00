//! `measures` and `verdict`: a result judged by the harness's own measures
//! ([`measures::evaluate`], [`measures::judge`]) from any program's arrays.

use measures::{Metric, Quality};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays;
use crate::configuration::verdict_rules;
use crate::errors::without_panic;

/// The arrays of an edit, checked and converted: rest, faces, result, fixed, handles, targets,
/// reference.
struct Edit {
    rest: Vec<[f64; 3]>,
    faces: Vec<[usize; 3]>,
    result: Vec<[f64; 3]>,
    fixed: Vec<usize>,
    handles: Vec<Vec<usize>>,
    targets: Vec<Vec<[f64; 3]>>,
    reference: Option<Vec<[f64; 3]>>,
}

impl Edit {
    #[allow(clippy::too_many_arguments)]
    fn read(
        v0: &Bound<'_, PyAny>,
        f: &Bound<'_, PyAny>,
        v1: &Bound<'_, PyAny>,
        fixed: Option<&Bound<'_, PyAny>>,
        handles: Option<&Bound<'_, PyAny>>,
        targets: Option<&Bound<'_, PyAny>>,
        reference: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Edit> {
        let rest = arrays::points("V0", v0)?;
        let n = rest.len();
        let widen = |list: Vec<u32>| list.into_iter().map(|v| v as usize).collect::<Vec<usize>>();
        let faces = arrays::faces("F", f, n)?.into_iter().map(|t| t.map(|v| v as usize)).collect();
        let result = arrays::points("V1", v1)?;
        if result.len() != n {
            return Err(PyValueError::new_err(format!("V1: {} rows, V0 has {n}", result.len())));
        }
        let fixed =
            fixed.map(|a| arrays::vertex_list("fixed", a, n)).transpose()?.map(widen).unwrap_or_default();
        let handles: Vec<Vec<usize>> = match handles {
            Some(h) => arrays::vertex_lists("handles", h, n)?.into_iter().map(widen).collect(),
            None => Vec::new(),
        };
        let targets = match targets {
            Some(t) => arrays::point_lists("targets", t)?,
            None => Vec::new(),
        };
        let reference = reference.map(|r| arrays::points("reference", r)).transpose()?;
        Ok(Edit { rest, faces, result, fixed, handles, targets, reference })
    }

    /// `what` (`f` on the arrays) with the GIL released; an error of the measures (arrays that do
    /// not fit together) as a `ValueError`, a panic as a [`crate::errors::DeformbenchError`].
    fn compute<T: Send>(
        &self,
        py: Python<'_>,
        what: &str,
        f: impl FnOnce(&Edit) -> Result<T, measures::MeasuresError> + Send,
    ) -> PyResult<T> {
        py.allow_threads(|| {
            without_panic(what, || f(self).map_err(|err| PyValueError::new_err(err.to_string())))
        })
    }
}

/// Every measure of the metrics table by its column name (`None` where it does not apply).
fn quality_dict<'py>(py: Python<'py>, quality: &Quality) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for metric in Metric::ALL {
        dict.set_item(metric.key(), quality.get(metric))?;
    }
    Ok(dict)
}

/// Measure the result `V1` of an edit of the rest mesh `V0`, `F` (see the type stub).
#[pyfunction(name = "measures")]
#[pyo3(signature = (V0, F, V1, fixed = None, handles = None, targets = None, reference = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn measure<'py>(
    py: Python<'py>,
    V0: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    V1: &Bound<'py, PyAny>,
    fixed: Option<&Bound<'py, PyAny>>,
    handles: Option<&Bound<'py, PyAny>>,
    targets: Option<&Bound<'py, PyAny>>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let e = Edit::read(V0, F, V1, fixed, handles, targets, reference)?;
    let quality = e.compute(py, "measures", |e| {
        measures::evaluate(
            &e.rest,
            &e.faces,
            &e.result,
            &e.fixed,
            &e.handles,
            &e.targets,
            e.reference.as_deref(),
        )
    })?;
    quality_dict(py, &quality)
}

/// Measure and judge the result `V1` (see the type stub): `{"status", "reasons", "measures"}`.
#[pyfunction(name = "verdict")]
#[pyo3(signature = (V0, F, V1, fixed = None, handles = None, targets = None, reference = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn judge<'py>(
    py: Python<'py>,
    V0: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    V1: &Bound<'py, PyAny>,
    fixed: Option<&Bound<'py, PyAny>>,
    handles: Option<&Bound<'py, PyAny>>,
    targets: Option<&Bound<'py, PyAny>>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let rules = verdict_rules()?;
    let e = Edit::read(V0, F, V1, fixed, handles, targets, reference)?;
    let judgement = e.compute(py, "verdict", |e| {
        let (rest, faces, result) = (&e.rest, &e.faces, &e.result);
        measures::judge(rules, rest, faces, result, &e.fixed, &e.handles, &e.targets, e.reference.as_deref())
    })?;
    let dict = PyDict::new(py);
    dict.set_item("status", if judgement.reasons.is_empty() { "ok" } else { "suspect" })?;
    dict.set_item("reasons", judgement.reasons.clone())?;
    dict.set_item("measures", quality_dict(py, &judgement.quality)?)?;
    Ok(dict)
}
