//! The frame a scenario's selections and edits are written in (`frame` in a scenario file): the
//! rest mesh's bounding box as it lies (`"bbox"`, the default), or its principal axes
//! (`"principal"`), so that one scenario file means the same edit on every mesh of a collection,
//! however each was posed when it was saved (issue 36).
//!
//! The principal frame of a mesh: origin at its area-weighted centroid; axes the eigenvectors of
//! the area-weighted covariance of its face centroids, longest extent first (`x`), then `y`, `z`.
//! Sign rule: each axis points to where the surface has its longer tail (the third moment of the
//! face centroids along it, area-weighted, is positive). The frame is orthonormal but may be
//! left-handed: a mirrored mesh gets the mirrored frame, so the same file gives the mirrored edit
//! and the mirrored result. A mesh symmetric about an axis has no such tail along it (the eigen
//! solver's sign is kept), and one whose two extents are equal has no preferred axes in their
//! plane: such meshes get a valid but arbitrary frame.
//!
//! In the principal frame, `[0, 1]^3` box coordinates span the mesh's box along those axes,
//! rotation axes and translations are along them, and diagonals are that box's diagonal.

use meshes::{AffineTransform, TriMesh};
use methods::rotation_fit::symmetric_eigen3;
use serde::Deserialize;

use super::Motion;

/// Which frame a scenario's selections and edits are written in.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Frame {
    /// The rest mesh's coordinates as they are in its file.
    #[default]
    Bbox,
    /// The rest mesh's principal axes (see the module documentation).
    Principal,
}

/// A rigid map (rotation or rotation with reflection, and translation) from a mesh's coordinates
/// to its principal frame, and back.
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipalFrame {
    /// World to frame: `x' = R (x - c)`.
    pub to_frame: AffineTransform,
    /// Frame to world: `x = R^T x' + c`.
    pub to_world: AffineTransform,
}

impl PrincipalFrame {
    /// The principal frame of `mesh` (see the module documentation).
    pub fn of(mesh: &TriMesh) -> Self {
        let (p, t) = (mesh.positions(), mesh.triangles());
        let areas = meshes::geometry::face_areas(p, t);
        let centroids: Vec<[f64; 3]> = t
            .iter()
            .map(|f| {
                std::array::from_fn(|a| {
                    (p[f[0] as usize][a] + p[f[1] as usize][a] + p[f[2] as usize][a]) / 3.0
                })
            })
            .collect();
        let total: f64 = areas.iter().sum();
        // Uniform weights when every face is degenerate (checked meshes have none).
        let weight = |i: usize| if total > 0.0 { areas[i] / total } else { 1.0 / areas.len() as f64 };
        let mut c = [0.0; 3];
        for (i, x) in centroids.iter().enumerate() {
            for a in 0..3 {
                c[a] += weight(i) * x[a];
            }
        }
        let mut covariance = [[0.0; 3]; 3];
        for (i, x) in centroids.iter().enumerate() {
            for a in 0..3 {
                for b in 0..3 {
                    covariance[a][b] += weight(i) * (x[a] - c[a]) * (x[b] - c[b]);
                }
            }
        }
        let (values, vectors) = symmetric_eigen3(covariance);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
        let mut rows = [[0.0; 3]; 3];
        for (k, &j) in order.iter().enumerate() {
            let mut axis = [vectors[0][j], vectors[1][j], vectors[2][j]];
            let skew: f64 = centroids
                .iter()
                .enumerate()
                .map(|(i, x)| weight(i) * (0..3).map(|a| (x[a] - c[a]) * axis[a]).sum::<f64>().powi(3))
                .sum();
            if skew < 0.0 {
                axis = axis.map(|v| -v);
            }
            rows[k] = axis;
        }
        let shift: [f64; 3] = std::array::from_fn(|k| -(0..3).map(|a| rows[k][a] * c[a]).sum::<f64>());
        let to_frame = AffineTransform::from_rows(std::array::from_fn(|k| {
            if k < 3 {
                [rows[k][0], rows[k][1], rows[k][2], shift[k]]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        }))
        .expect("finite rows");
        let to_world = AffineTransform::from_rows(std::array::from_fn(|k| {
            if k < 3 {
                [rows[0][k], rows[1][k], rows[2][k], c[k]]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        }))
        .expect("finite rows");
        Self { to_frame, to_world }
    }

    /// `mesh` with its positions in this frame (same triangles, same vertex order).
    pub fn pose(&self, mesh: &TriMesh) -> TriMesh {
        let positions = mesh.positions().iter().map(|&x| self.to_frame.apply(x)).collect();
        TriMesh::new(positions, mesh.triangles().to_vec()).expect("a rigid map keeps a valid mesh valid")
    }

    /// A motion written in this frame as the same motion of the mesh where it lies:
    /// `to_world * T * to_frame` for a transform, the offset turned back for a translation.
    pub fn to_world(&self, motion: &Motion) -> Motion {
        match motion {
            Motion::Hold => Motion::Hold,
            Motion::Transform(t) => Motion::Transform(self.to_world.compose(t).compose(&self.to_frame)),
            Motion::Translate(d) => {
                let r = self.to_world.rows();
                Motion::Translate(std::array::from_fn(|a| (0..3).map(|k| r[a][k] * d[k]).sum()))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshes::shapes::{generate, ShapeKind};

    /// `mesh` moved by `f` (a rigid map, possibly a reflection; a reflection reverses the triangles
    /// so the moved mesh keeps outward normals).
    fn moved(mesh: &TriMesh, f: impl Fn([f64; 3]) -> [f64; 3], reflect: bool) -> TriMesh {
        let positions = mesh.positions().iter().map(|&x| f(x)).collect();
        let triangles =
            mesh.triangles().iter().map(|t| if reflect { [t[0], t[2], t[1]] } else { *t }).collect();
        TriMesh::new(positions, triangles).unwrap()
    }

    /// The same mesh posed by its principal frame lands at the same positions whether it was
    /// saved turned, moved or mirrored: selections in box coordinates pick the same vertices.
    #[test]
    fn a_turned_or_mirrored_mesh_is_posed_the_same() {
        let mesh = generate(ShapeKind::Cactus, 3000).unwrap().mesh;
        let posed = PrincipalFrame::of(&mesh).pose(&mesh);
        let turn = AffineTransform::rotation_about([0.3, -1.0, 0.7], 2.1, [0.0; 3])
            .compose(&AffineTransform::translation([5.0, -3.0, 40.0]));
        let cases = [
            ("turned", moved(&mesh, |x| turn.apply(x), false)),
            ("mirrored", moved(&mesh, |x| [-x[0], x[1], x[2]], true)),
            ("turned and mirrored", moved(&mesh, |x| turn.apply([x[0], -x[1], x[2]]), true)),
        ];
        let scale = mesh.bbox_diagonal();
        for (what, other) in cases {
            let again = PrincipalFrame::of(&other).pose(&other);
            let apart = posed
                .positions()
                .iter()
                .zip(again.positions())
                .map(|(a, b)| meshes::vector::norm(meshes::vector::sub(*a, *b)))
                .fold(0.0, f64::max);
            assert!(apart <= 1e-9 * scale, "{what}: posed {apart:e} apart");
        }
    }

    /// A motion written in the frame, taken back to the world, does to each world point what it
    /// does to that point in the frame.
    #[test]
    fn motions_go_back_to_the_world() {
        let mesh = generate(ShapeKind::Cactus, 3000).unwrap().mesh;
        let frame = PrincipalFrame::of(&mesh);
        let t = AffineTransform::rotation_about([0.0, 0.0, 1.0], 0.5, [1.0, 2.0, 3.0])
            .compose(&AffineTransform::translation([0.1, 0.2, 0.3]));
        let (Motion::Transform(w), Motion::Translate(d)) = (
            frame.to_world(&Motion::Transform(t.clone())),
            frame.to_world(&Motion::Translate([1.0, 2.0, 3.0])),
        ) else {
            panic!("kinds are kept");
        };
        for &x in mesh.positions().iter().step_by(97) {
            let expected = frame.to_world.apply(t.apply(frame.to_frame.apply(x)));
            let got = w.apply(x);
            assert!(meshes::vector::norm(meshes::vector::sub(got, expected)) < 1e-9);
            let shifted = frame
                .to_world
                .apply(std::array::from_fn(|a| frame.to_frame.apply(x)[a] + [1.0, 2.0, 3.0][a]));
            let moved = [x[0] + d[0], x[1] + d[1], x[2] + d[2]];
            assert!(meshes::vector::norm(meshes::vector::sub(moved, shifted)) < 1e-9);
        }
        assert_eq!(frame.to_world(&Motion::Hold), Motion::Hold);
    }
}
