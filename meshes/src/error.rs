//! Errors of the mesh crate. Every variant names the element (vertex, face, edge, line) it is about;
//! [`MeshError::InFile`] adds the file so a user can find the offending element.

use std::path::PathBuf;

/// Everything that can go wrong when building, validating, reading or writing a mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// An error that happened while reading or writing `path`.
    #[error("{}: {error}", path.display())]
    InFile { path: PathBuf, error: Box<MeshError> },
    /// A text file could not be parsed at `line` (1-based).
    #[error("line {line}: {message}")]
    Syntax { line: usize, message: String },
    /// A file ended before everything its header announced was read.
    #[error("unexpected end of file: {expected}")]
    Truncated { expected: String },
    /// An operating-system I/O error.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A binary or third-party format reported an error.
    #[error("{0}")]
    Format(String),
    /// The mesh has no vertices or no faces.
    #[error("mesh has no {0}")]
    Empty(&'static str),
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex}: coordinate {axis} is {value}, not a finite number")]
    NonFiniteCoordinate { vertex: usize, axis: usize, value: f64 },
    /// A face refers to a vertex that does not exist.
    #[error("face {face}: vertex index {index} is out of range (the mesh has {n_vertices} vertices)")]
    IndexOutOfRange { face: usize, index: u64, n_vertices: usize },
    /// A face is not a triangle.
    #[error("face {face}: has {corners} corners; only triangles are supported")]
    NotATriangle { face: usize, corners: usize },
    /// A polygon face (OBJ, PLY) cannot be fan-triangulated: it has fewer than 3 corners, or one of
    /// its fan triangles would use a vertex twice. `face` is 0-based, in file order.
    #[error("face {face}: a polygon of {corners} corners that cannot be triangulated: {reason}")]
    Untriangulable { face: usize, corners: usize, reason: String },
    /// A face uses the same vertex twice.
    #[error("face {face}: repeats vertex {vertex}")]
    RepeatedVertex { face: usize, vertex: u32 },
    /// An edge is shared by more than two faces.
    #[error("edge ({a}, {b}) is non-manifold: shared by faces {faces:?}")]
    NonManifoldEdge { a: u32, b: u32, faces: Vec<u32> },
    /// Two faces traverse an edge in the same direction.
    #[error("edge ({a}, {b}) is traversed in the same direction by faces {f0} and {f1} (inconsistent orientation)")]
    InconsistentOrientation { a: u32, b: u32, f0: u32, f1: u32 },
    /// A face has (numerically) zero area.
    #[error("face {face}: zero area ({area:e}); degenerate triangles are not accepted")]
    DegenerateFace { face: usize, area: f64 },
    /// A per-vertex array does not match the mesh.
    #[error("{what} has {got} entries but the mesh has {expected} vertices")]
    LengthMismatch { what: &'static str, got: usize, expected: usize },
    /// A value is outside what a format allows.
    #[error("{0}")]
    Invalid(String),
}

impl MeshError {
    /// Attach the file `path` to this error (idempotent: a file is named once).
    pub fn in_file(self, path: impl Into<PathBuf>) -> MeshError {
        match self {
            e @ MeshError::InFile { .. } => e,
            e => MeshError::InFile { path: path.into(), error: Box::new(e) },
        }
    }
}

/// Result alias of the mesh crate.
pub type Result<T, E = MeshError> = std::result::Result<T, E>;
