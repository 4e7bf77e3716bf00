//! The cotangent Laplacian (Pinkall & Polthier 1993; Meyer et al. 2003).

use faer::sparse::{SparseColMat, Triplet};
use meshes::vector::{cross, dot, norm, sub};

use super::DEGENERATE_FACE_RATIO;

/// Per-face cotangent half-weights: entry `k` of face `f` is `cot(angle at corner k) / 2`, the weight
/// face `f` contributes to the edge opposite corner `k` (libigl's `cotmatrix_entries`).
pub type CotangentWeights = Vec<[f64; 3]>;

/// `#F x 3` cotangent half-weights of `positions` / `triangles`; zero for faces caught by
/// [`DEGENERATE_FACE_RATIO`].
pub fn cotangent_weights(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> CotangentWeights {
    triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| positions[i as usize]);
            let e = [sub(p[2], p[1]), sub(p[0], p[2]), sub(p[1], p[0])]; // e[k] opposite corner k
            let double_area = norm(cross(e[0], e[1]));
            let longest2 = e.iter().map(|v| dot(*v, *v)).fold(0.0, f64::max);
            if !(double_area > DEGENERATE_FACE_RATIO * longest2) {
                return [0.0; 3];
            }
            // cot(corner k) = (u . v) / |u x v| with u, v the edges leaving corner k, and |u x v| = 2A.
            std::array::from_fn(|k| {
                let u = e[(k + 2) % 3];
                let v = e[(k + 1) % 3];
                -dot(u, v) / double_area * 0.5
            })
        })
        .collect()
}

/// `#V x #V` cotangent Laplacian `L` of the mesh: `L_ij = (cot a_ij + cot b_ij) / 2` for each edge,
/// `L_ii = -sum_j L_ij`, so `L 1 = 0` and `-L` is positive semi-definite (libigl's `cotmatrix`).
/// Rows and columns are sorted (CSC), duplicates summed.
pub fn cotan_laplacian(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> SparseColMat<usize, f64> {
    laplacian_from_corner_weights(positions.len(), triangles, &cotangent_weights(positions, triangles))
}

/// The `n x n` Laplacian of `#F x 3` `triangles` whose corner `k` of face `f` carries the weight
/// `weights[f][k]` of the opposite edge: `L_ij` = sum of the weights of the edges between `i` and
/// `j` (parallel edges summed), `L_ii = -sum_j L_ij`, CSC with sorted rows. A self-edge (`i == j`)
/// adds `c + c - c - c = 0` to `L_ii`. Panics on an index `>= n` (callers hold validated meshes).
pub(super) fn laplacian_from_corner_weights(
    n: usize,
    triangles: &[[u32; 3]],
    weights: &[[f64; 3]],
) -> SparseColMat<usize, f64> {
    let mut entries = Vec::with_capacity(12 * triangles.len());
    for (t, w) in triangles.iter().zip(weights) {
        for k in 0..3 {
            let i = t[(k + 1) % 3] as usize;
            let j = t[(k + 2) % 3] as usize;
            let c = w[k];
            entries.push(Triplet::new(i, j, c));
            entries.push(Triplet::new(j, i, c));
            entries.push(Triplet::new(i, i, -c));
            entries.push(Triplet::new(j, j, -c));
        }
    }
    SparseColMat::try_new_from_triplets(n, n, &entries)
        .expect("indices are in range by the mesh's invariants")
}
