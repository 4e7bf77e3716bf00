//! Triangle meshes for deformbench: the [`TriMesh`] type and its validation, adjacency
//! ([`Topology`]), per-element geometry, cleaning ([`clean`]: unreferenced vertices, duplicates,
//! components), file I/O (OFF, OBJ, PLY, glTF/GLB, the survey `.sel`/`.def` edits, libigl `.dmat`,
//! vertex-id lists) and procedural look-alikes of the four Botsch–Sorkine test shapes.
//!
//! Modules in dependency order, each using only modules above it (in parentheses), so imports form
//! no loop:
//! - [`error`]: [`MeshError`] and [`Result`].
//! - [`vector`]: `[f64; 3]` arithmetic.
//! - `primitives` (private; re-exported by [`geometry`]): bounding box, triangle area (vector).
//! - [`mesh`]: [`TriMesh`] and its validation (error, primitives).
//! - [`topology`]: [`Topology`], adjacency and the oriented-manifold check (error, mesh).
//! - [`geometry`]: areas, normals, angles, volume; dihedral angles (vector, primitives, topology).
//! - [`edit`]: vertex status and the affine handle transform of a survey edit (error, vector).
//! - [`clean`]: unreferenced vertices, duplicates, components (error, mesh).
//! - [`repair`]: opt-in repair of zero-area and repeated faces, non-manifold edges and orientation
//!   (error, mesh, primitives).
//! - [`subdivision`]: refinement by Loop or midpoint subdivision (error, mesh, topology).
//! - [`shapes`]: procedural look-alikes of the survey shapes (error, vector, mesh, edit).
//! - [`io`]: mesh and edit file formats (error, mesh, geometry, edit).

pub mod clean;
pub mod edit;
pub mod error;
pub mod geometry;
pub mod io;
pub mod mesh;
mod primitives;
pub mod repair;
pub mod shapes;
pub mod subdivision;
pub mod topology;
pub mod vector;

pub use clean::VertexMap;
pub use edit::{AffineTransform, VertexStatus};
pub use error::{MeshError, Result};
pub use mesh::TriMesh;
pub use topology::{Topology, NO_FACE};
