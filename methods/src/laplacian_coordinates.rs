//! Rotation-invariant Laplacian coordinates `delta(X)`, the nonlinear right-hand side of iterative
//! Laplacian editing (Au et al. 2007, eq 1-3): the Laplacian coordinates `delta_bar_i = (L X_base)_i`
//! of a base shape, turned at every vertex by the rotation its one-ring made from the base shape to
//! the current one, `delta_i(X) = R_i delta_bar_i`. The base shape is a fixed point (`R_i = I`).
//!
//! Decision (the paper leaves the update of `delta(X)` to the frameworks it cites [Au et al. 2006;
//! Huang et al. 2006]): `R_i` is the rotation closest to `sum_j (x_i - x_j)(x_bar_i - x_bar_j)^T`
//! over the one-ring (orthogonal Procrustes, ARAP's local step with uniform weights). Until issue 24
//! it was the frame of Lipman et al. 2005 (the vertex normal and one edge projected onto the
//! tangent plane): on scans with short, skinny edges that one edge turns the frame with every small
//! move of its two vertices, and the iteration never settled: on the 43K armadillo `isolines_t1`
//! bounced at steps of ~2e-3 of the diagonal to its cap. The fitted rotation averages the whole
//! one-ring, and `isolines_t1` converges there in 1309 iterations. (`laplacian` does not settle on
//! the armadillo with either encoding: its free left arm keeps swinging, configs/methods.toml.)
//!
//! Iterative Laplacian editing can have several fixed points where a free limb may swing, and
//! which one the iteration finds depends on `delta`'s encoding and on the path. Measured on the
//! 502-vertex knight under `laplacian` (Anderson): Lipman's frame 187 iterations, E_theta 4.39 deg;
//! this fit 621, 6.75 deg (the body turned further, no fold); Lipman's normal with a tangent fitted
//! to the projected one-ring: unfinished at 2000 (plain: 742 iterations to a folded 7.98 deg). On
//! the survey meshes the three agree to the gate's tolerances (cactus: one more folded edge).

use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, Par};
use meshes::vector::sub;
use meshes::Topology;

use crate::rotation_fit::{closest_rotation_warm, cross_covariance, Mat3, IDENTITY};

/// Base-shape Laplacian coordinates, the base one-rings, and per-vertex warm starts of the fit.
pub(crate) struct RotationInvariantCoordinates {
    /// One-rings in CSR: vertex `i` has `neighbors[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    neighbors: Vec<u32>,
    /// `x_bar_i - x_bar_j` of every one-ring edge, in the order of `neighbors`.
    base_edges: Vec<[f64; 3]>,
    /// `delta_bar_i = (L X_base)_i`, `#V x 3`.
    base_delta: Vec<[f64; 3]>,
    /// Right singular frames of the last fit per vertex (warm starts, see `closest_rotation_warm`).
    frames: Vec<Mat3>,
}

impl RotationInvariantCoordinates {
    /// `L X_base` (`laplacian`: `#V x #V`; `base`: `#V x 3`) and the one-rings of `topology` on
    /// `base`.
    pub(crate) fn new(
        base: &[[f64; 3]],
        topology: &Topology,
        laplacian: SparseColMatRef<'_, usize, f64>,
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
        let mut offsets = Vec::with_capacity(n + 1);
        let mut neighbors = Vec::new();
        let mut base_edges = Vec::new();
        offsets.push(0);
        for (i, x) in base.iter().enumerate() {
            for &j in topology.one_ring(i) {
                neighbors.push(j);
                base_edges.push(sub(*x, base[j as usize]));
            }
            offsets.push(neighbors.len());
        }
        Self {
            offsets,
            neighbors,
            base_edges,
            base_delta: (0..n).map(|i| [delta[(i, 0)], delta[(i, 1)], delta[(i, 2)]]).collect(),
            frames: vec![IDENTITY; n],
        }
    }

    /// `delta(X)` of the `#V x 3` positions `current` into the `#V x 3` matrix `out`. Isolated
    /// vertices (no one-ring) have `delta_bar = 0` and stay 0.
    pub(crate) fn evaluate(&mut self, current: &[[f64; 3]], mut out: MatMut<'_, f64>) {
        for (i, xi) in current.iter().enumerate() {
            let ring = self.offsets[i]..self.offsets[i + 1];
            let covariance = cross_covariance(
                ring.map(|s| (self.base_edges[s], sub(*xi, current[self.neighbors[s] as usize]))),
            );
            let r = closest_rotation_warm(&covariance, &mut self.frames[i]);
            let c = self.base_delta[i];
            for a in 0..3 {
                out[(i, a)] = r[a][0] * c[0] + r[a][1] * c[1] + r[a][2] * c[2];
            }
        }
    }
}
