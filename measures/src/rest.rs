//! [`RestGeometry`]: what the measures compare a result with, computed once per rest mesh.

use meshes::geometry::{corner_angles, dihedral_angles, edge_lengths, face_areas, signed_volume};
use meshes::{Topology, TriMesh};

/// Geometry of the rest mesh the measures compare with, computed once per scenario.
pub struct RestGeometry {
    /// `#F x 3` corner angles (radians).
    pub(crate) corners: Vec<[f64; 3]>,
    /// One per interior edge, in [`Topology::interior_edges`] order (radians).
    pub(crate) dihedrals: Vec<f64>,
    /// `#F` face areas.
    pub(crate) areas: Vec<f64>,
    /// `#E` edge lengths, in [`Topology::edges`] order.
    pub(crate) lengths: Vec<f64>,
    /// Enclosed volume, for a closed mesh.
    pub(crate) volume: Option<f64>,
    /// Bounding-box diagonal.
    pub diagonal: f64,
    /// The reference's energy on this mesh (`None` where its Laplacian cannot be built), with the
    /// tufted intrinsic Delaunay weights whatever the methods run with: all `>= 0`, so the energy is
    /// never negative (the plain intrinsic Delaunay weights are negative on some boundary edges).
    pub(crate) arap_energy: Option<methods::arap::ArapEnergy>,
}

impl RestGeometry {
    /// The rest geometry of `mesh`.
    pub fn new(mesh: &TriMesh, topology: &Topology) -> Self {
        let (p, t) = (mesh.positions(), mesh.triangles());
        Self {
            corners: corner_angles(p, t),
            dihedrals: dihedral_angles(p, t, topology),
            areas: face_areas(p, t),
            lengths: edge_lengths(p, topology.edges()),
            volume: topology.is_closed().then(|| signed_volume(p, t)),
            diagonal: mesh.bbox_diagonal(),
            arap_energy: methods::arap::ArapEnergy::new(
                mesh,
                methods::operators::LaplacianWeights::TuftedDelaunay,
            )
            .ok(),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use meshes::shapes::{generate, ShapeKind};

    /// The survey-like shape `kind` and its rest geometry.
    pub(crate) fn shape(kind: ShapeKind) -> (TriMesh, Topology, RestGeometry) {
        let mesh = generate(kind, 1500).unwrap().mesh;
        let topology = Topology::new(&mesh).unwrap();
        let rest = RestGeometry::new(&mesh, &topology);
        (mesh, topology, rest)
    }
}
