//! The module's exception: every error of a method, a measure or a configuration, with the message
//! the command line prints for it. Bad arrays are `ValueError`s (module `arrays`).

pyo3::create_exception!(
    deformbench,
    DeformbenchError,
    pyo3::exceptions::PyException,
    "A method, measure or configuration error of deformbench (the command line's message)."
);

/// Run `f`, turning a panic into a [`DeformbenchError`] naming `what`: a panic must not cross into
/// Python (PyO3 would raise its `PanicException`, which `except Exception` does not catch).
pub fn without_panic<T>(what: &str, f: impl FnOnce() -> pyo3::PyResult<T>) -> pyo3::PyResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| panic.downcast_ref::<&str>().copied())
            .unwrap_or("(no message)");
        Err(DeformbenchError::new_err(format!("{what}: internal error (a bug; please report it): {message}")))
    })
}
