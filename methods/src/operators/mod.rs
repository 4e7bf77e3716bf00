//! Discrete differential operators on triangle meshes.
//!
//! Conventions follow libigl so the cross-checks compare like with like: [`cotan_laplacian`] is
//! libigl's `cotmatrix` (negative semi-definite, `L_ij = (cot a_ij + cot b_ij) / 2`), and
//! [`lumped_mass`] is libigl's `massmatrix` diagonal (Voronoi-hybrid or barycentric).

mod cotan;
mod mass;

pub use cotan::{cotan_laplacian, cotangent_weights, CotangentWeights};
pub use mass::{corner_areas, lumped_mass, MassKind};

/// Faces whose doubled area is below this fraction of their longest squared edge carry no
/// cotangent or mass: a zero-area triangle has no angles, and letting it in would put `inf`/NaN
/// into the operators. Valid survey meshes have ratios above 1e-2; the harness rejects degenerate
/// faces before this guard is ever reached.
pub const DEGENERATE_FACE_RATIO: f64 = 1e-12;
