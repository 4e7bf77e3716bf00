//! Where the project's files are and the environment variables that name inputs: the workspace
//! root (configs/ and reports/ live there), the survey data, the Python environment.

use std::path::{Path, PathBuf};

/// Environment variable naming the survey data directory (same as `--survey-dir`).
pub const SURVEY_DIR_ENV: &str = "DEFORM_SURVEY_DIR";

/// Environment variable naming the project's Python (the venv of `python/requirements.txt`, made
/// by `scripts/python-env`; set by `scripts/test`).
pub const PYTHON_ENV: &str = "DEFORMBENCH_PYTHON";

/// The workspace root (configs/ and reports/ live there), from the harness crate's location.
pub fn workspace_root() -> PathBuf {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    root.canonicalize().unwrap_or_else(|_| root.to_path_buf())
}

/// The project's Python code (`python/`): the scripts the harness runs and the requirements.
pub fn python_dir() -> PathBuf {
    workspace_root().join("python")
}
