//! Errors of the harness library; the CLI wraps them with `anyhow`.

use std::path::PathBuf;

/// What can stop the harness before or while running (bad input, I/O). A method that fails on a
/// case is not an error here: it becomes a `failed` row in the report.
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    #[error("{}: {message}", path.display())]
    Config { path: PathBuf, message: String },
    #[error("scenario `{scenario}`: {message}")]
    Scenario { scenario: String, message: String },
    #[error(transparent)]
    Mesh(#[from] meshes::MeshError),
    #[error(transparent)]
    Method(#[from] methods::MethodError),
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    #[error("{0}")]
    Report(String),
    /// A scenario whose estimated memory exceeds what the machine has available, refused before
    /// its mesh was loaded (`--force` runs it anyway).
    #[error(transparent)]
    Memory(#[from] Box<crate::memory::MemoryRefusal>),
}
