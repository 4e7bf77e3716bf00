//! numpy arrays in and out, in libigl's conventions: `#V x 3` float64 positions, `#F x 3` integer
//! faces, 1-D integer vertex lists. Every bad array is a `ValueError` that names the argument and
//! its first bad element (`V[12, 1] is nan`), never a panic.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `a` as a numpy array of `dtype` (lists and other array-likes are converted, as
/// `numpy.asarray` does); `name` is the argument's name for the error.
fn as_array<'py>(name: &str, a: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let numpy = a.py().import("numpy")?;
    numpy
        .call_method1("ascontiguousarray", (a, dtype))
        .map_err(|e| PyValueError::new_err(format!("{name}: cannot be read as a {dtype} array: {e}")))
}

/// The shape of an array-like, for messages.
fn shape_of(a: &Bound<'_, PyAny>) -> String {
    a.getattr("shape").and_then(|s| s.str()).map(|s| s.to_string()).unwrap_or_else(|_| "?".into())
}

/// `#N x 3` float64 rows of `a` (argument `name`): finite values only.
pub fn points(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Vec<[f64; 3]>> {
    let array = as_array(name, a, "float64")?;
    let array = array.downcast::<PyArray2<f64>>().map_err(|_| {
        PyValueError::new_err(format!("{name}: expected a #N x 3 array, got shape {}", shape_of(&array)))
    })?;
    if array.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected a #N x 3 array, got shape {}",
            shape_of(array.as_any())
        )));
    }
    let view = array.readonly();
    let view = view.as_array();
    let mut rows = Vec::with_capacity(view.nrows());
    for (i, row) in view.outer_iter().enumerate() {
        let p = [row[0], row[1], row[2]];
        if let Some(c) = p.iter().position(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!("{name}[{i}, {c}] is {} (not finite)", p[c])));
        }
        rows.push(p);
    }
    Ok(rows)
}

/// Integer values of `a` (argument `name`) of any integer dtype, row-major, with its shape.
fn integers(name: &str, a: &Bound<'_, PyAny>) -> PyResult<(Vec<i64>, Vec<usize>)> {
    let numpy = a.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (a,))
        .map_err(|e| PyValueError::new_err(format!("{name}: cannot be read as an array: {e}")))?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    let size: usize = array.getattr("size")?.extract()?;
    // An empty list reads as float64 (numpy's default): it is an empty index list.
    if !matches!(kind.as_str(), "i" | "u") && size > 0 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected integer vertex indices, got dtype kind `{kind}` (cast with .astype(int) \
             if the values are whole)"
        )));
    }
    let array = numpy.call_method1("ascontiguousarray", (array, "int64"))?;
    let array = array.downcast::<PyArrayDyn<i64>>()?;
    let shape = array.shape().to_vec();
    let values = array.readonly();
    Ok((values.as_slice()?.to_vec(), shape))
}

/// `index` (element `at` of argument `name`) as a vertex index below `n_vertices`.
fn vertex(name: &str, at: &str, index: i64, n_vertices: usize) -> PyResult<u32> {
    if index < 0 || index as u64 >= n_vertices as u64 {
        return Err(PyValueError::new_err(format!(
            "{name}{at} = {index} is out of range (V has {n_vertices} rows)"
        )));
    }
    Ok(index as u32)
}

/// `#F x 3` faces of `a` (argument `name`), indices below `n_vertices`.
pub fn faces(name: &str, a: &Bound<'_, PyAny>, n_vertices: usize) -> PyResult<Vec<[u32; 3]>> {
    let (flat, shape) = integers(name, a)?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected a #F x 3 integer array, got shape {shape:?}"
        )));
    }
    flat.chunks_exact(3)
        .enumerate()
        .map(|(f, t)| {
            let at = |c: usize| format!("[{f}, {c}]");
            Ok([
                vertex(name, &at(0), t[0], n_vertices)?,
                vertex(name, &at(1), t[1], n_vertices)?,
                vertex(name, &at(2), t[2], n_vertices)?,
            ])
        })
        .collect()
}

/// A 1-D list of vertex indices (argument `name`) below `n_vertices`.
pub fn vertex_list(name: &str, a: &Bound<'_, PyAny>, n_vertices: usize) -> PyResult<Vec<u32>> {
    let (flat, shape) = integers(name, a)?;
    if shape.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected a 1-D integer array, got shape {shape:?}"
        )));
    }
    flat.iter().enumerate().map(|(i, &v)| vertex(name, &format!("[{i}]"), v, n_vertices)).collect()
}

/// A sequence of vertex lists (argument `name`, one per handle).
pub fn vertex_lists(name: &str, a: &Bound<'_, PyAny>, n_vertices: usize) -> PyResult<Vec<Vec<u32>>> {
    sequence(name, a)?
        .iter()
        .enumerate()
        .map(|(i, item)| vertex_list(&format!("{name}[{i}]"), item, n_vertices))
        .collect()
}

/// A sequence of `#h_i x 3` position arrays (argument `name`, one per handle).
pub fn point_lists(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<[f64; 3]>>> {
    sequence(name, a)?.iter().enumerate().map(|(i, item)| points(&format!("{name}[{i}]"), item)).collect()
}

/// The items of a list or tuple (a single array is refused: which handle would it be?).
fn sequence<'py>(name: &str, a: &Bound<'py, PyAny>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if a.hasattr("shape")? {
        return Err(PyValueError::new_err(format!(
            "{name}: expected a list with one array per handle, got one array of shape {}",
            shape_of(a)
        )));
    }
    a.try_iter()
        .map_err(|_| PyValueError::new_err(format!("{name}: expected a list with one array per handle")))?
        .collect()
}

/// `rows` as a new `#N x 3` float64 numpy array.
pub fn to_numpy<'py>(py: Python<'py>, rows: &[[f64; 3]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), 3), flat).expect("#N x 3").into_pyarray(py)
}

/// `rows` (faces) as a new `#F x 3` int64 numpy array.
pub fn faces_to_numpy<'py>(py: Python<'py>, rows: &[[u32; 3]]) -> Bound<'py, PyArray2<i64>> {
    let flat: Vec<i64> = rows.iter().flatten().map(|&v| v as i64).collect();
    Array2::from_shape_vec((rows.len(), 3), flat).expect("#F x 3").into_pyarray(py)
}
