//! Rotation-invariant Laplacian coordinates `delta(X)` (Lipman et al. 2005), the nonlinear right-hand
//! side of iterative Laplacian editing (Au et al. 2007, eq 1-3): the Laplacian coordinates of a base
//! shape are stored in a local frame per vertex (area-weighted vertex normal `n_i`; tangent `t_i` = the
//! edge to the lowest-index neighbour projected onto the tangent plane; `b_i = n_i x t_i`) and
//! re-expressed in the frame of the current surface. The base shape is a fixed point.

use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, Par};
use meshes::vector::{cross, dot, normalize_or_zero, scale, sub};
use meshes::Topology;

/// Base-shape Laplacian coordinates in local frames, and the buffers to re-express them.
pub(crate) struct RotationInvariantCoordinates {
    triangles: Vec<[u32; 3]>,
    /// Per vertex, the neighbour whose edge defines the tangent `t_i`.
    frame_neighbor: Vec<u32>,
    /// `delta_i` of the base shape as `(n, t, b)` coefficients.
    frame_coefficients: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
}

impl RotationInvariantCoordinates {
    /// Encode `L X_base` (`laplacian`: `#V x #V`; `base`: `#V x 3`) in the local frames of `base`.
    pub(crate) fn new(
        base: &[[f64; 3]],
        triangles: &[[u32; 3]],
        topology: &Topology,
        laplacian: SparseColMatRef<'_, usize, f64>,
    ) -> Self {
        let n = base.len();
        let base_positions = Mat::from_fn(n, 3, |i, a| base[i][a]);
        let mut base_delta = Mat::zeros(n, 3);
        sparse_dense_matmul(
            base_delta.as_mut(),
            Accum::Replace,
            laplacian,
            base_positions.as_ref(),
            1.0,
            Par::Seq,
        );
        let normals = meshes::geometry::vertex_normals(base, triangles);
        let mut frame_neighbor = Vec::with_capacity(n);
        let mut frame_coefficients = Vec::with_capacity(n);
        for i in 0..n {
            // Isolated vertices have no neighbour; they keep a zero delta.
            let neighbor = topology.one_ring(i).first().copied().unwrap_or(i as u32);
            let (nn, t, b) = local_frame(base, &normals, neighbor, i);
            let d = [base_delta[(i, 0)], base_delta[(i, 1)], base_delta[(i, 2)]];
            frame_neighbor.push(neighbor);
            frame_coefficients.push([dot(d, nn), dot(d, t), dot(d, b)]);
        }
        Self { triangles: triangles.to_vec(), frame_neighbor, frame_coefficients, normals }
    }

    /// `delta(X)` of the `#V x 3` positions `current` into the `#V x 3` matrix `out`.
    pub(crate) fn evaluate(&mut self, current: &[[f64; 3]], mut out: MatMut<'_, f64>) {
        meshes::geometry::vertex_normals_into(current, &self.triangles, &mut self.normals);
        for i in 0..current.len() {
            let (n, t, b) = local_frame(current, &self.normals, self.frame_neighbor[i], i);
            let c = self.frame_coefficients[i];
            for a in 0..3 {
                out[(i, a)] = c[0] * n[a] + c[1] * t[a] + c[2] * b[a];
            }
        }
    }
}

/// Orthonormal frame `(n, t, b)` at vertex `i`: the vertex normal, the edge to `neighbor` projected onto
/// the tangent plane, and their cross product. Degenerate frames come out as zero vectors.
fn local_frame(
    positions: &[[f64; 3]],
    normals: &[[f64; 3]],
    neighbor: u32,
    i: usize,
) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let n = normals[i];
    let e = sub(positions[neighbor as usize], positions[i]);
    let t = normalize_or_zero(sub(e, scale(n, dot(e, n))));
    (n, t, cross(n, t))
}
