//! Errors of the measures crate: a verdict rules file that cannot be read or is wrong, and inputs
//! to [`crate::evaluate`] that do not fit together.

use std::path::PathBuf;

/// What keeps a measure or a verdict from being computed.
#[derive(Debug, thiserror::Error)]
pub enum MeasuresError {
    /// A rules file ([`crate::verdict::VerdictRules::load`]) that cannot be read.
    #[error("{}: {error}", path.display())]
    Read { path: PathBuf, error: std::io::Error },
    /// A rules file that does not parse, or a rule whose value breaks its condition.
    #[error("{}: {message}", path.display())]
    Rules { path: PathBuf, message: String },
    /// Rest positions and faces that make no mesh (an empty array, an index out of range, a
    /// repeated corner, a non-manifold edge).
    #[error(transparent)]
    Mesh(#[from] meshes::MeshError),
    /// Handle regions or targets that do not fit the mesh or each other.
    #[error(transparent)]
    Handles(#[from] methods::MethodError),
    /// An array of the wrong size: which, and the size it should have.
    #[error("{0}")]
    Size(String),
}
