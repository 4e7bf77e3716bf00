//! The configuration a Python program reads: the same as the command line's from the same
//! directory (`./configs` when the current directory has one, else the copy built into the module;
//! [`harness::paths::project_files`]), so that `Method("hirm", ...)` has the parameters
//! `harness run --method hirm` has.

use std::path::PathBuf;
use std::sync::OnceLock;

use harness::config::MethodCatalog;
use measures::VerdictRules;

use crate::errors::DeformbenchError;

/// The configuration directory (`configs/`) of this process.
pub fn configs_dir() -> Result<PathBuf, String> {
    let files = harness::paths::project_files().map_err(|e| e.to_string())?;
    Ok(files.root().join("configs"))
}

/// Every method of `configs/methods.toml` (built-in, variants, external), read once.
pub fn catalog() -> pyo3::PyResult<&'static MethodCatalog> {
    static CATALOG: OnceLock<Result<MethodCatalog, String>> = OnceLock::new();
    read_once(&CATALOG, |dir| MethodCatalog::load(&dir.join("methods.toml")).map_err(|e| e.to_string()))
}

/// The verdict rules of `configs/verdicts.toml`, read once.
pub fn verdict_rules() -> pyo3::PyResult<&'static VerdictRules> {
    static RULES: OnceLock<Result<VerdictRules, String>> = OnceLock::new();
    read_once(&RULES, |dir| VerdictRules::load(&dir.join("verdicts.toml")).map_err(|e| e.to_string()))
}

/// The value `cell` holds, read from the configuration directory by `read` on first use; a failed
/// read is kept too (the files do not change under a running process) and raised each time.
fn read_once<T>(
    cell: &'static OnceLock<Result<T, String>>,
    read: impl FnOnce(&std::path::Path) -> Result<T, String>,
) -> pyo3::PyResult<&'static T> {
    cell.get_or_init(|| read(&configs_dir()?)).as_ref().map_err(|e| DeformbenchError::new_err(e.clone()))
}
