//! The manifold harmonics transform (Rong et al. 2008, eq 7) and its inverse (eq 8).

use faer::{Mat, MatRef, Par};

/// Eq 7: spectral coefficients `x~ = H^T D x` of the `#V x c` signal `x` (`c` coordinates) in the
/// `D`-orthonormal basis `H` (`#V x m`): an `m x c` matrix.
pub fn transform(basis: MatRef<'_, f64>, mass: &[f64], signal: MatRef<'_, f64>) -> Mat<f64> {
    let weighted = Mat::from_fn(signal.nrows(), signal.ncols(), |i, j| mass[i] * signal[(i, j)]);
    let mut out = Mat::zeros(basis.ncols(), signal.ncols());
    faer::linalg::matmul::matmul(
        out.as_mut(),
        faer::Accum::Replace,
        basis.transpose(),
        weighted.as_ref(),
        1.0,
        Par::Seq,
    );
    out
}

/// Eq 8: the `#V x c` signal `H x~` reconstructed from the first `m` coefficients (`m x c`).
pub fn inverse_transform(basis: MatRef<'_, f64>, coefficients: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::zeros(basis.nrows(), coefficients.ncols());
    faer::linalg::matmul::matmul(out.as_mut(), faer::Accum::Replace, basis, coefficients, 1.0, Par::Seq);
    out
}
