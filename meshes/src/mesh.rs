//! The triangle mesh type: `#V x 3` f64 positions and `#F x 3` u32 triangles, validated on construction.

use crate::error::{MeshError, Result};

/// A validated triangle mesh.
///
/// Invariants established by [`TriMesh::new`]: at least one vertex and one face, every coordinate
/// finite, every index in range, no face repeating a vertex. Manifoldness and orientation are checked
/// by [`crate::Topology::new`]; zero-area faces by [`TriMesh::check_nondegenerate`] (kept separate so
/// operators can be exercised on degenerate input, which they must survive without NaN).
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Build a mesh from `#V` positions and `#F` triangles (counter-clockwise seen from outside).
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        if positions.is_empty() {
            return Err(MeshError::Empty("vertices"));
        }
        if triangles.is_empty() {
            return Err(MeshError::Empty("faces"));
        }
        check_finite(&positions)?;
        let n = positions.len();
        for (f, t) in triangles.iter().enumerate() {
            for &i in t {
                if i as usize >= n {
                    return Err(MeshError::IndexOutOfRange { face: f, index: i as u64, n_vertices: n });
                }
            }
            if t[0] == t[1] || t[0] == t[2] {
                return Err(MeshError::RepeatedVertex { face: f, vertex: t[0] });
            }
            if t[1] == t[2] {
                return Err(MeshError::RepeatedVertex { face: f, vertex: t[1] });
            }
        }
        Ok(Self { positions, triangles })
    }

    /// Number of vertices `#V`.
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces `#F`.
    pub fn n_faces(&self) -> usize {
        self.triangles.len()
    }

    /// `#V` positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// `#F` triangles, vertex indices counter-clockwise.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The same connectivity with other positions (`#V x 3`), e.g. a deformation result.
    pub fn with_positions(&self, positions: Vec<[f64; 3]>) -> Result<Self> {
        if positions.len() != self.positions.len() {
            return Err(MeshError::LengthMismatch {
                what: "position array",
                got: positions.len(),
                expected: self.positions.len(),
            });
        }
        check_finite(&positions)?;
        Ok(Self { positions, triangles: self.triangles.clone() })
    }

    /// Corners `(min, max)` of the axis-aligned bounding box.
    pub fn bbox(&self) -> ([f64; 3], [f64; 3]) {
        crate::primitives::bbox(&self.positions)
    }

    /// Diagonal length of the axis-aligned bounding box.
    pub fn bbox_diagonal(&self) -> f64 {
        crate::primitives::bbox_diagonal(&self.positions)
    }

    /// Reject faces whose area is at most `1e-12 x (bbox diagonal)^2`: they have no normal and no angles.
    pub fn check_nondegenerate(&self) -> Result<()> {
        let d = self.bbox_diagonal();
        let threshold = 1e-12 * d * d;
        for (f, t) in self.triangles.iter().enumerate() {
            let area = crate::primitives::triangle_area(&self.positions, t);
            if !(area > threshold) {
                return Err(MeshError::DegenerateFace { face: f, area });
            }
        }
        Ok(())
    }
}

fn check_finite(positions: &[[f64; 3]]) -> Result<()> {
    for (v, p) in positions.iter().enumerate() {
        for (axis, &value) in p.iter().enumerate() {
            if !value.is_finite() {
                return Err(MeshError::NonFiniteCoordinate { vertex: v, axis, value });
            }
        }
    }
    Ok(())
}
