//! The numerics the methods share, which import only each other and faer: Anderson acceleration
//! of fixed-point iterations ([`anderson`], `arap` and `scale_aware`), limited-memory BFGS
//! directions ([`lbfgs`], `arap`'s quasi-Newton solver), the sparse Cholesky
//! factorization and its blocked variant ([`sparse_cholesky`]), the symmetric eigensolvers
//! ([`spectral`]: Krylov–Schur with shift-invert, dense), and row-major dense storage for hot loops.

pub mod anderson;
pub mod lbfgs;
pub(crate) mod row_major;
pub mod sparse_cholesky;
pub mod spectral;
