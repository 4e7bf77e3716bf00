//! Rotation-invariant Laplacian coordinates `delta(X)`, the nonlinear right-hand side of iterative
//! Laplacian editing (Au et al. 2007, eq 1-3): the Laplacian coordinates `delta_bar_i = (L X_base)_i`
//! of a base shape, turned at every vertex by a rotation `R_i` that follows the surface from the
//! base shape to the current one, `delta_i(X) = R_i delta_bar_i`. The base shape is a fixed point
//! (`R_i = I`).
//!
//! The paper leaves the update of `delta(X)` to the frameworks it cites [Au et al. 2006; Huang et
//! al. 2006], which encode `delta` in local frames as Lipman et al. 2005 do. Two ways to get `R_i`
//! are implemented ([`DeltaFrame`], the `delta_frame` parameter of `laplacian` and `isolines*`):
//!
//! - [`DeltaFrame::NormalEdge`], Lipman et al. 2005 (the cited frameworks' choice, the default):
//!   the frame `(n_i, t_i, n_i x t_i)` of the area-weighted vertex normal and the edge to the
//!   first one-ring neighbour projected onto the tangent plane; `R_i` maps the base frame onto the
//!   current one.
//! - [`DeltaFrame::OneRing`]: the rotation closest to `sum_j (x_i - x_j)(x_bar_i - x_bar_j)^T` over
//!   the one-ring (orthogonal Procrustes, ARAP's local step with uniform weights).
//!
//! Why both (issue 35, measured; see configs/methods.toml): the one edge of Lipman's frame turns
//! with every small move of its two vertices, and on the 43K armadillo `isolines_t1` never settled
//! with it (steps of ~2e-3 of the diagonal to its cap, a collapsed torso), while the fitted
//! rotation averages the whole one-ring and converges there. But unreduced `laplacian` with the
//! fit crumples open scans (the dataset's face, mountain and africanhead: stopped at the 2000 cap,
//! steps 1e-2 to 3e-2 of the diagonal, 0.1-0.5% folded edges) where Lipman's frames converge in
//! 64-224 iterations. A likely loop: the fit reads the vertex's own position in every spoke
//! `x_i - x_j`, so a move of `x_i` turns `R_i` and with it `delta_i`, which moves `x_i` again;
//! Lipman's normal averages the faces around `x_i` and barely turns when it moves. The reduced
//! `isolines_t1` moves no single vertex on its own, and on the same open scans both frames give it
//! the same result.
//!
//! Iterative Laplacian editing can have several fixed points where a free limb may swing, and
//! which one the iteration finds depends on `delta`'s encoding and on the path. Measured on the
//! 502-vertex knight under `laplacian` (Anderson): Lipman's frame 187 iterations, E_theta 4.39 deg;
//! the one-ring fit 621, 6.75 deg (the body turned further, no fold).

use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, Par};
use meshes::vector::{cross, dot, normalize_or_zero, scale, sub};
use meshes::Topology;
use serde::Deserialize;

use crate::rotation_fit::{closest_rotation_warm, cross_covariance, Mat3, IDENTITY};

/// How each vertex's rotation `R_i` of `delta_bar_i` is found (see the module documentation).
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DeltaFrame {
    /// Lipman et al. 2005: vertex normal and one projected edge.
    #[default]
    NormalEdge,
    /// The rotation closest to the one-ring's spokes (orthogonal Procrustes).
    OneRing,
}

/// Base-shape Laplacian coordinates and what the chosen [`DeltaFrame`] needs to turn them.
pub(crate) struct RotationInvariantCoordinates {
    frame: DeltaFrame,
    /// `delta_bar_i = (L X_base)_i`, `#V x 3`.
    base_delta: Vec<[f64; 3]>,
    /// One-rings in CSR: vertex `i` has `neighbors[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    neighbors: Vec<u32>,
    /// [`DeltaFrame::OneRing`]: `x_bar_i - x_bar_j` of every one-ring edge, in the order of
    /// `neighbors`; the right singular frames of the last fit per vertex (warm starts, see
    /// `closest_rotation_warm`).
    base_edges: Vec<[f64; 3]>,
    singular_frames: Vec<Mat3>,
    /// [`DeltaFrame::NormalEdge`]: `#F x 3` triangles for the vertex normals, `delta_bar_i` as
    /// `(n, t, b)` coefficients in its base frame, and a `#V x 3` buffer of current normals.
    triangles: Vec<[u32; 3]>,
    frame_coefficients: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
}

impl RotationInvariantCoordinates {
    /// `L X_base` (`laplacian`: `#V x #V`; `base`: `#V x 3`, `triangles`: `#F x 3`) and the
    /// one-rings of `topology` on `base`, to be turned as `frame` says.
    pub(crate) fn new(
        base: &[[f64; 3]],
        triangles: &[[u32; 3]],
        topology: &Topology,
        laplacian: SparseColMatRef<'_, usize, f64>,
        frame: DeltaFrame,
    ) -> Self {
        let n = base.len();
        let base_positions = Mat::from_fn(n, 3, |i, a| base[i][a]);
        let mut delta = Mat::zeros(n, 3);
        sparse_dense_matmul(
            delta.as_mut(),
            Accum::Replace,
            laplacian,
            base_positions.as_ref(),
            1.0,
            Par::Seq,
        );
        let base_delta: Vec<[f64; 3]> =
            (0..n).map(|i| [delta[(i, 0)], delta[(i, 1)], delta[(i, 2)]]).collect();
        let mut offsets = Vec::with_capacity(n + 1);
        let mut neighbors = Vec::new();
        offsets.push(0);
        for i in 0..n {
            neighbors.extend_from_slice(topology.one_ring(i));
            offsets.push(neighbors.len());
        }
        let mut coordinates = Self {
            frame,
            base_delta,
            offsets,
            neighbors,
            base_edges: Vec::new(),
            singular_frames: Vec::new(),
            triangles: Vec::new(),
            frame_coefficients: Vec::new(),
            normals: Vec::new(),
        };
        match frame {
            DeltaFrame::OneRing => {
                coordinates.base_edges = (0..n)
                    .flat_map(|i| coordinates.ring(i).map(move |j| (i, j)))
                    .map(|(i, j)| sub(base[i], base[j]))
                    .collect();
                coordinates.singular_frames = vec![IDENTITY; n];
            }
            DeltaFrame::NormalEdge => {
                coordinates.triangles = triangles.to_vec();
                coordinates.normals = meshes::geometry::vertex_normals(base, triangles);
                coordinates.frame_coefficients = (0..n)
                    .map(|i| {
                        let (nn, t, b) = coordinates.local_frame(base, i);
                        let d = coordinates.base_delta[i];
                        [dot(d, nn), dot(d, t), dot(d, b)]
                    })
                    .collect();
            }
        }
        coordinates
    }

    /// The one-ring of vertex `i`.
    fn ring(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.neighbors[self.offsets[i]..self.offsets[i + 1]].iter().map(|&j| j as usize)
    }

    /// `delta(X)` of the `#V x 3` positions `current` into the `#V x 3` matrix `out`. Isolated
    /// vertices (no one-ring) have `delta_bar = 0` and stay 0.
    pub(crate) fn evaluate(&mut self, current: &[[f64; 3]], mut out: MatMut<'_, f64>) {
        match self.frame {
            DeltaFrame::OneRing => {
                for (i, xi) in current.iter().enumerate() {
                    let ring = self.offsets[i]..self.offsets[i + 1];
                    let covariance = cross_covariance(
                        ring.map(|s| (self.base_edges[s], sub(*xi, current[self.neighbors[s] as usize]))),
                    );
                    let r = closest_rotation_warm(&covariance, &mut self.singular_frames[i]);
                    let c = self.base_delta[i];
                    for a in 0..3 {
                        out[(i, a)] = r[a][0] * c[0] + r[a][1] * c[1] + r[a][2] * c[2];
                    }
                }
            }
            DeltaFrame::NormalEdge => {
                meshes::geometry::vertex_normals_into(current, &self.triangles, &mut self.normals);
                for i in 0..current.len() {
                    let (n, t, b) = self.local_frame(current, i);
                    let c = self.frame_coefficients[i];
                    for a in 0..3 {
                        out[(i, a)] = c[0] * n[a] + c[1] * t[a] + c[2] * b[a];
                    }
                }
            }
        }
    }

    /// Lipman's orthonormal frame `(n, t, b)` at vertex `i` of `positions` (`#V x 3`, with their
    /// normals in `self.normals`): the vertex normal, the edge to the first one-ring neighbour
    /// projected onto the tangent plane, and their cross product. Degenerate frames (an isolated
    /// vertex, an edge along the normal) come out as zero vectors.
    fn local_frame(&self, positions: &[[f64; 3]], i: usize) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let n = self.normals[i];
        let neighbor = self.ring(i).next().unwrap_or(i);
        let e = sub(positions[neighbor], positions[i]);
        let t = normalize_or_zero(sub(e, scale(n, dot(e, n))));
        (n, t, cross(n, t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operators::{laplacian, LaplacianWeights};
    use meshes::shapes::{generate, ShapeKind};

    /// `delta(X)` of both frames on a bar: the base shape gives `delta_bar`, and the base shape
    /// turned rigidly gives `delta_bar` turned by the same rotation (the encoding is
    /// rotation-invariant); both hold on a mesh with a boundary (the bumpy plane) too.
    #[test]
    fn both_frames_fix_the_base_shape_and_follow_a_rigid_turn() {
        for kind in [ShapeKind::Bar, ShapeKind::BumpyPlane] {
            let mesh = generate(kind, 800).unwrap().mesh;
            let topology = Topology::new(&mesh).unwrap();
            let (p, t) = (mesh.positions(), mesh.triangles());
            let l = laplacian(LaplacianWeights::Cotan, p, t).unwrap();
            let rotation =
                meshes::vector::rotation_matrix(meshes::vector::normalize_or_zero([1.0, -2.0, 0.5]), 1.1);
            let turn = |x: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|a| (0..3).map(|b| rotation[a][b] * x[b]).sum::<f64>() + 3.0)
            };
            let turned: Vec<[f64; 3]> = p.iter().map(|&x| turn(x)).collect();
            for frame in [DeltaFrame::NormalEdge, DeltaFrame::OneRing] {
                let mut coordinates = RotationInvariantCoordinates::new(p, t, &topology, l.as_ref(), frame);
                let scale =
                    coordinates.base_delta.iter().map(|d| meshes::vector::norm(*d)).fold(0.0, f64::max);
                let mut out = Mat::zeros(p.len(), 3);
                coordinates.evaluate(p, out.as_mut());
                let mut turned_out = Mat::zeros(p.len(), 3);
                coordinates.evaluate(&turned, turned_out.as_mut());
                for (i, d) in coordinates.base_delta.iter().enumerate() {
                    let expected: [f64; 3] =
                        std::array::from_fn(|a| (0..3).map(|b| rotation[a][b] * d[b]).sum::<f64>());
                    for a in 0..3 {
                        assert!(
                            (out[(i, a)] - d[a]).abs() <= 1e-9 * scale,
                            "{kind:?} {frame:?} rest, vertex {i}"
                        );
                        assert!(
                            (turned_out[(i, a)] - expected[a]).abs() <= 1e-9 * scale,
                            "{kind:?} {frame:?} turned, vertex {i}: {} vs {}",
                            turned_out[(i, a)],
                            expected[a]
                        );
                    }
                }
            }
        }
    }
}
