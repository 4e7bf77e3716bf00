//! Handle-driven harmonic fields (Au et al. 2007, section 4.1): for each handle `i`, `L phi_i = 0` on
//! the free vertices, `phi_i = 1` on handle `i` and `0` on every other handle (the survey's fixed
//! region is one of the handles). All fields share one factorization of the free-vertex block.
//!
//! The boundary values of all fields form a partition of unity, so by superposition the fields sum
//! to 1 at every vertex (the paper's footnote 1); with non-negative cotangent weights the discrete
//! maximum principle keeps each field in `[0, 1]`.

use faer::sparse::{SparseColMat, SparseColMatRef, Triplet};
use faer::Mat;

use crate::error::MethodError;
use crate::handles::{HandleSet, FREE};
use crate::linalg::sparse_cholesky::SparseCholesky;

/// `#V x #handles` harmonic fields, column `i` equal to 1 on handle `i` and 0 on the others.
///
/// `laplacian`: `#V x #V` cotangent Laplacian ([`crate::operators::cotan_laplacian`]).
/// Fails if a connected component has free vertices but no handle vertex (the Dirichlet problem is
/// then singular).
pub fn harmonic_fields(
    laplacian: SparseColMatRef<'_, usize, f64>,
    handles: &HandleSet,
) -> Result<Mat<f64>, MethodError> {
    let n = laplacian.nrows();
    handles.check_mesh_size(n)?;
    let n_handles = handles.regions().len();
    let region_of = handles.region_of();
    // Free vertices are renumbered 0..n_free.
    let mut free_index = vec![u32::MAX; n];
    let mut n_free = 0usize;
    for (v, &r) in region_of.iter().enumerate() {
        if r == FREE {
            free_index[v] = n_free as u32;
            n_free += 1;
        }
    }
    let mut fields = Mat::<f64>::zeros(n, n_handles);
    for (v, &r) in region_of.iter().enumerate() {
        if r != FREE {
            fields[(v, r as usize)] = 1.0;
        }
    }
    if n_free == 0 {
        return Ok(fields);
    }
    // -L_ff phi_f = L_fc phi_c, with -L_ff positive definite when every component is constrained.
    let (symbolic, values) = laplacian.parts();
    let mut entries = Vec::new();
    let mut rhs = Mat::<f64>::zeros(n_free, n_handles);
    for j in 0..n {
        for idx in symbolic.col_range(j) {
            let i = symbolic.row_idx()[idx];
            if free_index[i] == u32::MAX {
                continue;
            }
            let row = free_index[i] as usize;
            if free_index[j] != u32::MAX {
                entries.push(Triplet::new(row, free_index[j] as usize, -values[idx]));
            } else {
                rhs[(row, region_of[j] as usize)] += values[idx];
            }
        }
    }
    let system = SparseColMat::try_new_from_triplets(n_free, n_free, &entries).map_err(|e| {
        MethodError::Solver(crate::linalg::sparse_cholesky::SolverError::Faer(format!("{e:?}")))
    })?;
    let mut cholesky = SparseCholesky::new(system.as_ref()).map_err(|_| {
        MethodError::Handles(
            "harmonic fields: a connected part of the mesh has no handle vertex (the Laplace equation is singular there)"
                .into(),
        )
    })?;
    cholesky.solve_in_place(rhs.as_mut());
    for (v, &f) in free_index.iter().enumerate() {
        if f != u32::MAX {
            for i in 0..n_handles {
                fields[(v, i)] = rhs[(f as usize, i)];
            }
        }
    }
    Ok(fields)
}
