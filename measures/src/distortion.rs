//! How the shape itself changed, rest to result: corner and dihedral angles (the scale-aware
//! paper's errors, Liu et al. 2014, sec. 5.1; blind to uniform scaling and to folds), face areas,
//! edge lengths, total area, enclosed volume and folded edges.

use meshes::geometry::{corner_angles, dihedral_angles, edge_lengths, face_areas, signed_volume};
use meshes::{Topology, TriMesh};

use crate::rest::RestGeometry;
use crate::statistics::rms;

/// `#F x 3` corner angles and the dihedral angles of the interior edges of a result (radians).
pub struct ResultAngles {
    corners: Vec<[f64; 3]>,
    dihedrals: Vec<f64>,
}

impl ResultAngles {
    /// The angles of the `#V x 3` `result` on the connectivity of `mesh`.
    pub fn new(mesh: &TriMesh, topology: &Topology, result: &[[f64; 3]]) -> Self {
        Self {
            corners: corner_angles(result, mesh.triangles()),
            dihedrals: dihedral_angles(result, mesh.triangles(), topology),
        }
    }

    /// `(E_theta, E_phi)` in degrees against `rest` (see [`angle_errors`]).
    pub(crate) fn errors(&self, rest: &RestGeometry) -> (f64, f64) {
        let e_theta =
            rms(rest.corners.iter().flatten().zip(self.corners.iter().flatten()).map(|(a, b)| a - b));
        let e_phi = rms(rest.dihedrals.iter().zip(&self.dihedrals).map(|(a, b)| a - b));
        (e_theta.to_degrees(), e_phi.to_degrees())
    }

    /// The fraction of interior edges folded against `rest` (see [`folds`]).
    pub(crate) fn folded_fraction(&self, rest: &RestGeometry) -> f64 {
        let folded =
            rest.dihedrals.iter().zip(&self.dihedrals).filter(|(a, b)| (*a - *b).abs() > FOLD_ANGLE).count();
        if self.dihedrals.is_empty() {
            0.0
        } else {
            folded as f64 / self.dihedrals.len() as f64
        }
    }
}

/// `(E_theta, E_phi)` in degrees for `#V x 3` result positions on the rest connectivity:
/// `E_theta = sqrt(mean over all triangle corners of (theta_rest - theta)^2)`, `E_phi` likewise over
/// the dihedral angles of all interior edges (the angle between the two adjacent face normals).
/// Both are 0 for rigid motions and uniform scalings.
pub fn angle_errors(
    rest: &RestGeometry,
    mesh: &TriMesh,
    topology: &Topology,
    result: &[[f64; 3]],
) -> (f64, f64) {
    ResultAngles::new(mesh, topology, result).errors(rest)
}

/// `e_area = sqrt(mean_f ln(A_f / A_f⁰)²)` over the faces of positive rest area (a rest face of zero
/// area has no ratio; meshes are checked non-degenerate on load, so none is left out there). A
/// result face of zero area gives infinity: a collapsed face is infinitely distorted.
pub fn area_distortion(rest: &RestGeometry, mesh: &TriMesh, result: &[[f64; 3]]) -> f64 {
    let areas = face_areas(result, mesh.triangles());
    rms(rest.areas.iter().zip(&areas).filter(|(a0, _)| **a0 > 0.0).map(|(a0, a)| (a / a0).ln()))
}

/// `e_length = sqrt(mean_e ln(ℓ_e / ℓ_e⁰)²)` over the edges of positive rest length.
pub fn length_distortion(rest: &RestGeometry, topology: &Topology, result: &[[f64; 3]]) -> f64 {
    let lengths = edge_lengths(result, topology.edges());
    rms(rest.lengths.iter().zip(&lengths).filter(|(l0, _)| **l0 > 0.0).map(|(l0, l)| (l / l0).ln()))
}

/// `(A - A⁰) / A⁰` of the total surface area of the `#V x 3` `result` against the rest mesh.
pub fn area_change(rest: &RestGeometry, mesh: &TriMesh, result: &[[f64; 3]]) -> f64 {
    let a0: f64 = rest.areas.iter().sum();
    let a: f64 = face_areas(result, mesh.triangles()).iter().sum();
    (a - a0) / a0
}

/// `(V - V⁰) / V⁰` of the signed enclosed volume; `None` for an open mesh or a rest volume that is
/// round-off (below `1e-12 x diagonal³`).
pub fn volume_change(rest: &RestGeometry, mesh: &TriMesh, result: &[[f64; 3]]) -> Option<f64> {
    let v0 = rest.volume?;
    if v0.abs() <= 1e-12 * rest.diagonal.powi(3) {
        return None;
    }
    Some((signed_volume(result, mesh.triangles()) - v0) / v0)
}

/// Dihedral angle change (radians) beyond which an interior edge counts as folded: its two faces
/// turned against each other by more than a right angle. A smooth deformation of a mesh bends an edge
/// by a few degrees; 90° is reached only where a sheet doubles back over itself.
pub const FOLD_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

/// Fraction of interior edges whose dihedral angle changed by more than [`FOLD_ANGLE`] (0 for a mesh
/// without interior edges).
pub fn folds(rest: &RestGeometry, mesh: &TriMesh, topology: &Topology, result: &[[f64; 3]]) -> f64 {
    ResultAngles::new(mesh, topology, result).folded_fraction(rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat strip of `2 n` triangles along x (`n + 1` columns of two vertices), folded flat at
    /// each column of `fold_at`: the strip walks along x and turns back there (the turned part a
    /// little shorter so no vertex meets another). Each fold turns the faces on one side of the
    /// column's edge over, a dihedral change of 180 degrees; no other edge bends.
    fn strip(n: usize, fold_at: &[usize]) -> Vec<[f64; 3]> {
        let mut x = 0.0;
        let mut step = 1.0;
        let mut out = Vec::with_capacity(2 * (n + 1));
        for i in 0..=n {
            if i > 0 {
                x += step;
            }
            out.push([x, 0.0, 0.0]);
            out.push([x, 1.0, 0.0]);
            if fold_at.contains(&i) {
                step = -0.9 * step;
            }
        }
        out
    }

    fn strip_triangles(n: usize) -> Vec<[u32; 3]> {
        (0..n as u32)
            .flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 1], [2 * i + 1, 2 * i + 2, 2 * i + 3]])
            .collect()
    }

    #[test]
    fn folds_counts_the_edges_of_a_fold_made_by_construction() {
        let n = 10;
        let mesh = TriMesh::new(strip(n, &[]), strip_triangles(n)).unwrap();
        let topology = Topology::new(&mesh).unwrap();
        let rest = RestGeometry::new(&mesh, &topology);
        let interior = topology.interior_edges().count();
        assert_eq!(interior, 2 * n - 1);
        assert_eq!(folds(&rest, &mesh, &topology, mesh.positions()), 0.0);
        let f = folds(&rest, &mesh, &topology, &strip(n, &[4]));
        assert!((f - 1.0 / interior as f64).abs() < 1e-12, "one fold: folds {f}, interior edges {interior}");
        let f = folds(&rest, &mesh, &topology, &strip(n, &[3, 7]));
        assert!((f - 2.0 / interior as f64).abs() < 1e-12, "a Z: folds {f}, interior edges {interior}");
        // A bend by less than a right angle is no fold.
        let bent: Vec<[f64; 3]> = mesh
            .positions()
            .iter()
            .map(|p| if p[0] > 5.0 { [5.0 + 0.5 * (p[0] - 5.0), p[1], 0.8 * (p[0] - 5.0)] } else { *p })
            .collect();
        assert_eq!(folds(&rest, &mesh, &topology, &bent), 0.0);
    }
}
