//! The clamped cotangent Laplacian: the cotangent Laplacian with its negative couplings removed.
//!
//! A common fix for obtuse triangles (e.g. libigl users and Jacobson's ARAP notes): every
//! off-diagonal weight `(cot a_ij + cot b_ij) / 2 < 0` is set to 0 and the diagonal rebuilt from the
//! remaining ones. Unlike the intrinsic Delaunay Laplacian ([`super::intrinsic_delaunay`]) it no
//! longer converges to the Laplace–Beltrami operator and loses linear precision (`L x != 0` for a
//! linear function `x` on a flat mesh with clamped edges), but keeps the mesh's connectivity.

use faer::sparse::{SparseColMat, Triplet};

use super::cotan_laplacian;

/// `#V x #V` Laplacian with `L_ij = max(0, C_ij)` for `i != j`, `C` the [`cotan_laplacian`] of
/// `positions` (`#V x 3`) / `triangles` (`#F x 3`) (the weight of the edge, both faces summed), and
/// `L_ii = -sum_j L_ij`. Same sign and layout as [`cotan_laplacian`]; clamped entries are kept as
/// explicit zeros so the sparsity pattern is the mesh's.
pub fn clamped_cotan_laplacian(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> SparseColMat<usize, f64> {
    let cotan = cotan_laplacian(positions, triangles);
    let n = cotan.nrows();
    let (symbolic, values) = cotan.parts();
    let mut entries = Vec::with_capacity(values.len());
    let mut diagonal = vec![0.0; n];
    for j in 0..n {
        for idx in symbolic.col_range(j) {
            let i = symbolic.row_idx()[idx];
            if i != j {
                let w = values[idx].max(0.0);
                entries.push(Triplet::new(i, j, w));
                diagonal[j] -= w;
            }
        }
    }
    entries.extend(diagonal.iter().enumerate().map(|(i, &d)| Triplet::new(i, i, d)));
    SparseColMat::try_new_from_triplets(n, n, &entries).expect("indices come from a valid matrix")
}
