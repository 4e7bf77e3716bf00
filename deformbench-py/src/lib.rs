//! deformbench from Python: the methods of the four papers and the references, the measures and
//! the verdicts, on numpy arrays in libigl's conventions (`#V x 3` float64 positions, `#F x 3`
//! integer faces). The same library code the harness runs, on the same configuration, so a
//! result equals the command line's to the last bit. The Python side is documented in
//! `deformbench.pyi` beside this crate's Cargo.toml (the type stub the wheel carries).

mod arrays;
mod configuration;
mod errors;
mod judgement;
mod method;
mod python_method;
mod run;
mod scenario;

use pyo3::prelude::*;

/// The Python module `deformbench`.
#[pymodule]
fn deformbench(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("DeformbenchError", m.py().get_type::<errors::DeformbenchError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<method::Method>()?;
    m.add_class::<scenario::Scenario>()?;
    m.add_function(wrap_pyfunction!(method::method_names, m)?)?;
    m.add_function(wrap_pyfunction!(judgement::measure, m)?)?;
    m.add_function(wrap_pyfunction!(judgement::judge, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::load_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_suite, m)?)?;
    Ok(())
}
