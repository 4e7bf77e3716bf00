//! Discrete differential operators on triangle meshes.
//!
//! Conventions follow libigl so the cross-checks compare like with like: [`cotan_laplacian`] is
//! libigl's `cotmatrix` (negative semi-definite, `L_ij = (cot a_ij + cot b_ij) / 2`), and
//! [`lumped_mass`] is libigl's `massmatrix` diagonal (Voronoi-hybrid or barycentric).
//! [`IntrinsicTriangulation::delaunay`] gives libigl's `intrinsic_delaunay_cotmatrix`,
//! [`TuftedDelaunay`] robust-laplacian's `mesh_laplacian` (Sharp & Crane 2020);
//! [`LaplacianWeights`] selects one of the four Laplacians for the methods.

mod clamped;
mod cotan;
pub mod intrinsic_delaunay;
mod mass;
pub mod tufted;

pub use clamped::clamped_cotan_laplacian;
pub use cotan::{cotan_laplacian, cotangent_weights, CotangentWeights};
pub use intrinsic_delaunay::{IntrinsicDelaunayError, IntrinsicEdge, IntrinsicTriangulation};
pub use mass::{corner_areas, lumped_mass, MassKind};
pub use tufted::{TuftedDelaunay, MOLLIFY_FACTOR};

use faer::sparse::SparseColMat;

/// Faces whose doubled area is below this fraction of their longest squared edge carry no
/// cotangent or mass: a zero-area triangle has no angles, and letting it in would put `inf`/NaN
/// into the operators. Valid survey meshes have ratios above 1e-2; the harness rejects degenerate
/// faces before this guard is ever reached.
pub const DEGENERATE_FACE_RATIO: f64 = 1e-12;

/// Which edge weights a method's Laplacian has (the `weights` parameter of `laplacian`, `arap`,
/// `isolines*`, `spectral_mhb`, `scale_aware*`, `hirm`; configs/methods.toml).
///
/// On meshes with obtuse triangles the cotangent weight of an edge whose opposite angles sum to
/// more than `pi` is negative; ARAP's local step then fits rotations to anti-aligned spokes and its
/// global step rewards stretching that edge, which crumples real scanned/decimated meshes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LaplacianWeights {
    /// `"cotan"`: the mesh's cotangent weights (Pinkall & Polthier 1993), libigl's `cotmatrix`; may
    /// be negative.
    Cotan,
    /// `"clamped"`: cotangent weights with the negative ones set to 0 ([`clamped_cotan_laplacian`]).
    Clamped,
    /// `"intrinsic_delaunay"`: the cotangent weights of the intrinsic Delaunay triangulation
    /// (Bobenko & Springborn 2007; [`IntrinsicTriangulation::delaunay`]), all `>= 0`, libigl's
    /// `intrinsic_delaunay_cotmatrix`. Equal to `cotan` on a Delaunay mesh. Interior edges only: a
    /// boundary edge keeps its one cotangent, negative opposite an obtuse angle; fails on
    /// non-manifold edges.
    IntrinsicDelaunay,
    /// `"tufted_delaunay"`: the tufted intrinsic Delaunay Laplacian (Sharp & Crane 2020,
    /// [`TuftedDelaunay`]; robust-laplacian's `mesh_laplacian`): the intrinsic Delaunay Laplacian of
    /// the tufted cover, halved. Every weight `>= 0`, boundary edges included; defined on
    /// non-manifold meshes; equal to `intrinsic_delaunay` on a closed manifold mesh and to `cotan`
    /// on a closed Delaunay one.
    TuftedDelaunay,
}

impl Default for LaplacianWeights {
    /// `TuftedDelaunay`, every method's default (configs/methods.toml says why).
    fn default() -> Self {
        LaplacianWeights::TuftedDelaunay
    }
}

impl LaplacianWeights {
    /// The name in configs and reports: `cotan`, `clamped`, `intrinsic_delaunay`, `tufted_delaunay`.
    pub fn name(self) -> &'static str {
        match self {
            LaplacianWeights::Cotan => "cotan",
            LaplacianWeights::Clamped => "clamped",
            LaplacianWeights::IntrinsicDelaunay => "intrinsic_delaunay",
            LaplacianWeights::TuftedDelaunay => "tufted_delaunay",
        }
    }
}

/// `#V x #V` Laplacian of `positions` (`#V x 3`) / `triangles` (`#F x 3`) with the given weights,
/// all with [`cotan_laplacian`]'s sign (`L_ij >= 0` off the diagonal for non-negative weights,
/// `L 1 = 0`) and CSC layout with sorted rows. Fails only for `IntrinsicDelaunay` on a degenerate or
/// non-manifold mesh, and for `TuftedDelaunay` on a face that repeats a vertex (its degenerate
/// faces are mollified with [`MOLLIFY_FACTOR`]).
pub fn laplacian(
    weights: LaplacianWeights,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> Result<SparseColMat<usize, f64>, IntrinsicDelaunayError> {
    Ok(match weights {
        LaplacianWeights::Cotan => cotan_laplacian(positions, triangles),
        LaplacianWeights::Clamped => clamped_cotan_laplacian(positions, triangles),
        LaplacianWeights::IntrinsicDelaunay => {
            IntrinsicTriangulation::delaunay(positions, triangles)?.cotan_laplacian()
        }
        LaplacianWeights::TuftedDelaunay => {
            TuftedDelaunay::new(positions, triangles, MOLLIFY_FACTOR)?.cotan_laplacian()
        }
    })
}

/// The stiffness matrix `K = -L` (`#V x #V`, same sparsity) of a Laplacian `laplacian` in
/// [`laplacian`]'s sign convention: symmetric positive semi-definite for non-negative weights, with
/// `K 1 = 0`. What the energies `x^T K x`, the ARAP system and the eigenproblem `K phi = lambda M phi`
/// are written with.
pub fn stiffness(mut laplacian: SparseColMat<usize, f64>) -> SparseColMat<usize, f64> {
    laplacian.val_mut().iter_mut().for_each(|v| *v = -*v);
    laplacian
}

/// `#V` lumped mass diagonal that goes with [`laplacian`] for these `weights`: the mesh's
/// [`lumped_mass`] for `Cotan` and `Clamped` (their mesh is the mesh), the intrinsic triangles' for
/// `IntrinsicDelaunay` (same total area, distributed over the intrinsic faces), the tufted cover's
/// halved for `TuftedDelaunay`.
pub fn lumped_mass_for(
    weights: LaplacianWeights,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    kind: MassKind,
) -> Result<Vec<f64>, IntrinsicDelaunayError> {
    Ok(match weights {
        LaplacianWeights::Cotan | LaplacianWeights::Clamped => lumped_mass(positions, triangles, kind),
        LaplacianWeights::IntrinsicDelaunay => {
            IntrinsicTriangulation::delaunay(positions, triangles)?.lumped_mass(kind)
        }
        LaplacianWeights::TuftedDelaunay => {
            TuftedDelaunay::new(positions, triangles, MOLLIFY_FACTOR)?.lumped_mass(kind)
        }
    })
}
