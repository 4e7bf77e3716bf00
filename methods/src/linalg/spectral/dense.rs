//! Dense generalized eigensolver for small problems and as a test oracle: with `S = D^{-1/2}`,
//! `Q h = lambda D h` becomes the standard problem `(S Q S) u = lambda u`, `h = S u`.

use faer::sparse::SparseColMatRef;
use faer::{Mat, Side};

use super::{EigenError, Eigenpairs};

pub fn smallest_eigenpairs(
    stiffness: SparseColMatRef<'_, usize, f64>,
    mass: &[f64],
    count: usize,
) -> Result<Eigenpairs, EigenError> {
    let n = mass.len();
    let s: Vec<f64> = mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let mut a = Mat::<f64>::zeros(n, n);
    let (symbolic, values) = stiffness.parts();
    for j in 0..n {
        for idx in symbolic.col_range(j) {
            let i = symbolic.row_idx()[idx];
            a[(i, j)] += s[i] * values[idx] * s[j];
        }
    }
    // Symmetrize against rounding in the input.
    let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let evd = a.self_adjoint_eigen(Side::Lower).map_err(|_| EigenError::Dense)?;
    let values: Vec<f64> = (0..count).map(|j| evd.S()[j]).collect();
    let u = evd.U();
    let vectors = Mat::from_fn(n, count, |i, j| s[i] * u[(i, j)]);
    Ok(Eigenpairs { values, vectors, constant_mode: None, restarts: 0, operator_applications: 0 })
}
