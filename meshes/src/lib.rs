//! Triangle meshes for deformbench: the [`TriMesh`] type and its validation, adjacency
//! ([`Topology`]), per-element geometry, cleaning ([`clean`]: unreferenced vertices, duplicates,
//! components), file I/O (OFF, OBJ, PLY, glTF/GLB, the survey `.sel`/`.def` edits, libigl `.dmat`,
//! vertex-id lists) and procedural look-alikes of the four Botsch–Sorkine test shapes.

pub mod clean;
pub mod edit;
pub mod error;
pub mod geometry;
pub mod io;
pub mod mesh;
pub mod shapes;
pub mod topology;
pub mod vector;

pub use clean::VertexMap;
pub use edit::{AffineTransform, VertexStatus};
pub use error::{MeshError, Result};
pub use mesh::TriMesh;
pub use topology::{Topology, NO_FACE};
