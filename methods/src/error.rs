//! Errors of the methods crate.

use crate::linalg::sparse_cholesky::SolverError;

/// Everything a deformation method can report instead of a result.
#[derive(Debug, thiserror::Error)]
pub enum MethodError {
    #[error("unknown method `{name}`; known methods: {}", known.join(", "))]
    UnknownMethod { name: String, known: Vec<&'static str> },
    /// A parameter table that does not parse (an unknown key, a value of the wrong type).
    #[error("parameters of `{method}`: {message}")]
    Parameters { method: &'static str, message: String },
    /// Parameters that parse but break their rules: exactly the keys and values at fault
    /// ([`crate::params::ParamCheck`]), e.g. `arap: tolerance = NaN: must be a finite number >= 0`.
    #[error("{method}: {}", faults.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "))]
    InvalidParameters { method: &'static str, faults: Vec<InvalidParameter> },
    #[error("handle set: {0}")]
    Handles(String),
    #[error("handle targets: {0}")]
    Targets(String),
    #[error("`{method}`: {phase} called before {missing}")]
    Phase { method: &'static str, phase: &'static str, missing: &'static str },
    #[error(transparent)]
    Mesh(#[from] meshes::MeshError),
    // Not `#[from]`: that would also make it the error's source, and chains would print it twice.
    #[error("linear solver: {0}")]
    Solver(SolverError),
    #[error("`{method}`: the background precompute thread panicked")]
    Background { method: &'static str },
    #[error("intrinsic Delaunay triangulation: {0}")]
    IntrinsicDelaunay(crate::operators::IntrinsicDelaunayError),
    #[error("eigensolver: {0}")]
    Eigen(crate::linalg::spectral::EigenError),
    #[error("`{method}` produced a non-finite position at vertex {vertex} in iteration {iteration}")]
    NonFinite { method: &'static str, vertex: usize, iteration: usize },
    #[error("`{method}`'s result has a non-finite position at vertex {vertex}")]
    NonFiniteResult { method: String, vertex: usize },
    #[error("external method `{method}`: {message}")]
    External { method: String, message: String },
    /// A method's own dense system that should be positive definite by construction failed to
    /// factor: which matrix, and what makes it singular.
    #[error("`{method}`: {matrix} is not numerically positive definite: {reason}")]
    NotPositiveDefinite { method: &'static str, matrix: String, reason: String },
    #[error("`{method}` diverged: iteration {iteration} moved a vertex {step:.3e} bounding-box diagonals")]
    Diverged { method: &'static str, iteration: usize, step: f64 },
}

impl From<crate::operators::IntrinsicDelaunayError> for MethodError {
    fn from(e: crate::operators::IntrinsicDelaunayError) -> Self {
        MethodError::IntrinsicDelaunay(e)
    }
}

impl From<SolverError> for MethodError {
    fn from(e: SolverError) -> Self {
        MethodError::Solver(e)
    }
}

/// One rule that the values of some parameters break: each key with its value as given, and the
/// rule.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}: {rule}", values.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", "))]
pub struct InvalidParameter {
    /// The keys at fault with their values (one key for most rules; two for a rule between them).
    pub values: Vec<(&'static str, String)>,
    /// What the value must be (`must be >= 1`).
    pub rule: String,
}

impl InvalidParameter {
    /// The keys at fault.
    pub fn keys(&self) -> Vec<&'static str> {
        self.values.iter().map(|(k, _)| *k).collect()
    }
}
