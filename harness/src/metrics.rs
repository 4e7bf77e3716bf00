//! Quality metrics of a deformation result (scale-aware paper, section 5.1), in degrees.

use meshes::geometry::{corner_angles, dihedral_angles};
use meshes::vector::{norm, sub};
use meshes::{Topology, TriMesh};
use methods::{HandleSet, HandleTargets};

/// Angles of the rest mesh, computed once per scenario.
pub struct RestAngles {
    corners: Vec<[f64; 3]>,
    dihedrals: Vec<f64>,
}

impl RestAngles {
    /// Corner and dihedral angles of `mesh` (radians).
    pub fn new(mesh: &TriMesh, topology: &Topology) -> Self {
        Self {
            corners: corner_angles(mesh.positions(), mesh.triangles()),
            dihedrals: dihedral_angles(mesh.positions(), mesh.triangles(), topology),
        }
    }
}

/// `(E_theta, E_phi)` in degrees for `#V x 3` result positions on the rest connectivity:
/// `E_theta = sqrt(mean over all triangle corners of (theta_rest - theta)^2)`, `E_phi` likewise over
/// the dihedral angles of all interior edges (the angle between the two adjacent face normals).
/// Both are 0 for rigid motions and uniform scalings.
pub fn angle_errors(
    rest: &RestAngles,
    mesh: &TriMesh,
    topology: &Topology,
    result: &[[f64; 3]],
) -> (f64, f64) {
    let corners = corner_angles(result, mesh.triangles());
    let e_theta = rms(rest.corners.iter().flatten().zip(corners.iter().flatten()).map(|(a, b)| a - b));
    let dihedrals = dihedral_angles(result, mesh.triangles(), topology);
    let e_phi = rms(rest.dihedrals.iter().zip(&dihedrals).map(|(a, b)| a - b));
    (e_theta.to_degrees(), e_phi.to_degrees())
}

/// Largest distance of a constrained vertex from its target, divided by `diagonal`.
pub fn handle_residual(
    handles: &HandleSet,
    targets: &HandleTargets,
    result: &[[f64; 3]],
    diagonal: f64,
) -> f64 {
    handles
        .constrained()
        .zip(targets.positions())
        .map(|(v, t)| norm(sub(result[v as usize], *t)))
        .fold(0.0, f64::max)
        / diagonal
}

/// Root-mean-square vertex distance between two `#V x 3` position arrays, divided by `diagonal`.
pub fn rms_distance(a: &[[f64; 3]], b: &[[f64; 3]], diagonal: f64) -> f64 {
    rms(a.iter().zip(b).map(|(p, q)| norm(sub(*p, *q)))) / diagonal
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| (s + v * v, c + 1));
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshes::shapes::{generate, ShapeKind};
    use meshes::AffineTransform;

    fn errors_after(kind: ShapeKind, f: impl Fn([f64; 3]) -> [f64; 3]) -> (f64, f64) {
        let mesh = generate(kind, 1500).unwrap().mesh;
        let topology = Topology::new(&mesh).unwrap();
        let rest = RestAngles::new(&mesh, &topology);
        let moved: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| f(p)).collect();
        angle_errors(&rest, &mesh, &topology, &moved)
    }

    #[test]
    fn rigid_motions_and_uniform_scalings_have_zero_angle_error() {
        let rigid = AffineTransform::rotation_about([1.0, -2.0, 0.5], 2.3, [0.3, 0.1, 7.0])
            .compose(&AffineTransform::translation([10.0, -4.0, 3.0]));
        for kind in [ShapeKind::Bar, ShapeKind::Cactus, ShapeKind::BumpyPlane] {
            let (t, p) = errors_after(kind, |x| rigid.apply(x));
            assert!(t < 1e-9 && p < 1e-9, "{kind:?} rigid: E_theta {t}, E_phi {p}");
            let (t, p) = errors_after(kind, |x| [3.7 * x[0], 3.7 * x[1], 3.7 * x[2]]);
            assert!(t < 1e-9 && p < 1e-9, "{kind:?} scaling: E_theta {t}, E_phi {p}");
        }
    }

    #[test]
    fn non_uniform_scaling_and_bending_are_measured() {
        let (t, p) = errors_after(ShapeKind::Bar, |x| [2.0 * x[0], x[1], x[2]]);
        assert!(t > 1.0 && p < 1e-9, "stretching a box changes corner angles, not its flat faces: {t}, {p}");
        // Bending the plane about the y axis changes dihedral angles, and near-isometrically keeps corners.
        let (t, p) = errors_after(ShapeKind::BumpyPlane, |x| {
            let r = 200.0;
            let a = x[0] / r;
            [(r + x[2]) * a.sin(), x[1], (r + x[2]) * a.cos()]
        });
        assert!(p > 0.05 && t < p * 10.0, "bend: E_theta {t}, E_phi {p}");
    }

    #[test]
    fn residual_and_rms_distance() {
        let a = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let b = vec![[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]];
        assert!((rms_distance(&a, &b, 2.0) - (2.0f64).sqrt() / 2.0).abs() < 1e-15);
        let handles =
            HandleSet::new(vec![methods::HandleRegion { name: "h".into(), vertices: vec![1] }], 2).unwrap();
        let targets = HandleTargets::new(&handles, vec![[1.0, 0.5, 0.0]]).unwrap();
        assert!((handle_residual(&handles, &targets, &b, 3.0) - 0.5).abs() < 1e-15);
    }
}
