//! Manifold harmonics (Rong, Cao & Guo 2008, section 3; Vallet & Lévy 2008): the smallest eigenpairs of
//! the generalized problem `Q h = lambda D h` (eq 5-6) with `Q = -L_s` the cotangent stiffness matrix
//! (positive semi-definite) and `D` a lumped mass, and the manifold harmonics transform (eq 7-8).
//!
//! [`smallest_eigenpairs`] solves it by shift-invert block Krylov–Schur (thick-restart block Lanczos)
//! in the `D` inner product ([`krylov_schur`]); all shift-invert solves reuse one sparse Cholesky
//! factorization of `Q - sigma D`. When `Q` annihilates constants (a Laplacian of a connected mesh
//! has exactly one such mode), the constant vector is deflated: returned as the first eigenpair and
//! kept out of the Krylov space. Small problems are solved densely ([`dense`]).

mod block_gram_schmidt;
mod dense;
mod krylov_schur;
mod random;
mod transform;

pub use transform::{inverse_transform, transform};

use faer::sparse::SparseColMatRef;
use faer::Mat;

use crate::linalg::sparse_cholesky::SolverError;

/// Options of [`smallest_eigenpairs`].
#[derive(Clone, Debug)]
pub struct EigenOptions {
    /// Number of eigenpairs wanted (the smallest eigenvalues, the constant mode included).
    pub count: usize,
    /// Converged when `|OP x - theta x|_D <= tolerance * theta` for the shift-invert operator
    /// `OP = (Q - sigma D)^{-1} D` and its Ritz pair `(theta, x)`.
    pub tolerance: f64,
    /// Vectors per block of the block Krylov method.
    pub block_size: usize,
    /// Size of the projected basis before a restart (default: `max(2 count, count + 4 block)`).
    pub basis_size: Option<usize>,
    /// Restart limit; exceeding it is [`EigenError::NotConverged`].
    pub max_restarts: usize,
    /// Seed of the start block; the same seed gives the same result.
    pub seed: u64,
    /// Problems with at most this many unknowns are solved densely.
    pub dense_limit: usize,
}

impl EigenOptions {
    /// Defaults for `count` eigenpairs.
    pub fn new(count: usize) -> Self {
        Self {
            count,
            tolerance: 1e-11,
            // Measured on the survey meshes: for few eigenpairs, pairs of vectors need ~30% fewer
            // operator applications than blocks of 4; for many, blocks of 4 stream the basis
            // through the orthogonalization at half the passes.
            block_size: if count <= 50 { 2 } else { 4 },
            basis_size: None,
            max_restarts: 300,
            seed: 0x5eed,
            dense_limit: 800,
        }
    }
}

/// Eigenpairs of `Q h = lambda D h`, eigenvalues ascending, eigenvectors `D`-orthonormal
/// (`H^T D H = I`).
#[derive(Clone, Debug)]
pub struct Eigenpairs {
    /// `k` eigenvalues, ascending.
    pub values: Vec<f64>,
    /// `#V x k` eigenvectors in the columns, in the order of `values`.
    pub vectors: Mat<f64>,
    /// Index of the constant mode (eigenvalue 0 with a constant eigenvector) when present.
    pub constant_mode: Option<usize>,
    /// Work done: restarts of the Krylov method (0 for the dense path).
    pub restarts: usize,
    /// Applications of the shift-invert operator, counted per vector.
    pub operator_applications: usize,
}

/// Failures of the eigensolver.
#[derive(Debug, thiserror::Error)]
pub enum EigenError {
    #[error("{count} eigenpairs requested of a problem of size {n}")]
    TooMany { count: usize, n: usize },
    #[error("invalid input: {0}")]
    Invalid(String),
    #[error("did not converge: {converged} of {wanted} eigenpairs after {restarts} restarts")]
    NotConverged { converged: usize, wanted: usize, restarts: usize },
    #[error("shift-invert factorization: {0}")]
    Solver(SolverError),
    #[error("dense eigendecomposition failed")]
    Dense,
}

/// The `options.count` smallest eigenpairs of `stiffness h = lambda diag(mass) h`.
///
/// `stiffness`: `#V x #V` symmetric positive semi-definite (e.g. `-L` of [`crate::operators::cotan_laplacian`]),
/// both triangles stored. `mass`: `#V` positive lumped masses.
pub fn smallest_eigenpairs(
    stiffness: SparseColMatRef<'_, usize, f64>,
    mass: &[f64],
    options: &EigenOptions,
) -> Result<Eigenpairs, EigenError> {
    let n = mass.len();
    if stiffness.nrows() != n || stiffness.ncols() != n {
        return Err(EigenError::Invalid(format!(
            "stiffness is {} x {}, mass has {n} entries",
            stiffness.nrows(),
            stiffness.ncols()
        )));
    }
    if let Some(i) = mass.iter().position(|m| !(*m > 0.0 && m.is_finite())) {
        return Err(EigenError::Invalid(format!("mass of vertex {i} is {}, not positive", mass[i])));
    }
    if stiffness.val().iter().any(|v| !v.is_finite()) {
        return Err(EigenError::Invalid("stiffness has non-finite entries".into()));
    }
    if options.count == 0 || options.count > n {
        return Err(EigenError::TooMany { count: options.count, n });
    }
    let mut pairs = if n <= options.dense_limit || options.count * 3 > n {
        dense::smallest_eigenpairs(stiffness, mass, options.count)?
    } else {
        krylov_schur::smallest_eigenpairs(stiffness, mass, options)?
    };
    pairs.constant_mode = find_constant_mode(&pairs, stiffness, mass);
    Ok(pairs)
}

/// The eigenpair with eigenvalue ~0 and a constant eigenvector, if any (one per connected component
/// would be a constant per component; only the globally constant one is flagged).
fn find_constant_mode(
    pairs: &Eigenpairs,
    stiffness: SparseColMatRef<'_, usize, f64>,
    mass: &[f64],
) -> Option<usize> {
    // The spectrum's scale: the largest eigenvalue found, or (when only a few near 0 were asked
    // for) the largest `Q_ii / D_ii`, of the order of the largest eigenvalue.
    let (symbolic, values) = stiffness.parts();
    let diagonal_scale = (0..symbolic.ncols())
        .flat_map(|j| symbolic.col_range(j).filter(move |&idx| symbolic.row_idx()[idx] == j))
        .map(|idx| values[idx].abs() / mass[symbolic.row_idx()[idx]])
        .fold(0.0f64, f64::max);
    let scale = pairs.values.iter().fold(diagonal_scale, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    let total: f64 = mass.iter().sum();
    let constant = 1.0 / total.sqrt(); // D-normalized constant vector
    (0..pairs.values.len()).find(|&j| {
        pairs.values[j].abs() <= 1e-8 * scale && {
            let col = pairs.vectors.col(j);
            (0..col.nrows()).all(|i| (col[i].abs() - constant).abs() <= 1e-6 * constant)
        }
    })
}
