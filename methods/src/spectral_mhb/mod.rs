//! `spectral_mhb`: spectral mesh deformation (Rong, Cao & Guo 2008).
//!
//! Pipeline (the paper's section 1, steps 1–4), with the paper's timing names:
//! 1. PT1 — manifold harmonics bases `H` (`#V x m`): the `m` smallest eigenpairs of `Q h = lambda D h`
//!    (eq 5-6; `Q = -L_s`, `D` the barycentric lumped mass `D_ii = sum |t| / 3`), see [`crate::linalg::spectral`].
//! 2. The smoothed model `p~ = H H^T D p` (inverse MHT of the first `m` coefficients, eq 7-8).
//! 3. PT2 — the reduced energy `S = H^T A H` of the thin-shell energy (eq 9-13), `A` from
//!    `L = M^{-1} L_s` (eq 13, `M` the Voronoi areas): `A = -k_s L + k_b L^2`.
//!    Bind — the reduced constraint system (eq 15); RT1 — solve it for the spectral displacement
//!    `d~` (`m x 3`); the smoothed model deforms to `p~ + H d~`.
//! 4. PT3 — the detail-transfer system; RT2 — add the details back (section 4.4): deformation
//!    transfer (default) or local frames.
//!
//! Decisions the paper leaves open (tested in `tests/spectral_mhb.rs`):
//! - Weights (`weights`, default `tufted_delaunay`): `L_s` of the bases (eq 5), of the energy
//!   (eq 13) and of the deformation-transfer Poisson system, and with it the masses `D` and `M`, which
//!   for `intrinsic_delaunay` and `tufted_delaunay` are the intrinsic triangles' ([`crate::operators::lumped_mass_for`]).
//!   Not the deformation-transfer Poisson system: its right-hand side is built from gradients on
//!   the mesh's triangles, and `G^T A G` of those is exactly the mesh's cotangent `-L`, which keeps
//!   the rest shape a fixed point of the detail transfer; it always uses `cotan`.
//! - Energy form: `S = H^T (M A) H` with `M A = -k_s L_s + k_b L_s M^{-1} L_s`, the Galerkin projection
//!   of the discrete energy whose Euler–Lagrange equation is eq 13 (symmetric, so the reduced
//!   problems are symmetric). Under hard constraints eq 14 has the same solution `d` with `A` or
//!   `M A` (the multipliers absorb `M`), so with `m = n` this reproduces eq 14 exactly.
//! - `k_s`, `k_b` are not given in the paper: defaults `k_s = 0`, `k_b = 1` (pure bending, the thin
//!   plate of Botsch & Sorkine 2008), configurable.
//! - Constraints: eq 15's Lagrange system (`constraints = "lagrange"`) has `m + n'` unknowns and is
//!   singular once the `n'` constrained vertices outnumber the `m` bases — the survey tests constrain
//!   600–3400 vertices against `m = 100`. The default `constraints = "penalty"` therefore solves the
//!   least-squares form `(S + w^2 H_C^T H_C) d~ = w^2 H_C^T d'` (`m x m`, Cholesky at bind), with
//!   `w^2 = constraint_weight * tr(S) / tr(H_C^T H_C)` so the weight is scale-free. The constraint
//!   displacement is `d' = p' - p` (the paper writes both signs; the reading notes fix this one).
//! - Translation after deformation transfer: the Poisson solve fixes positions up to a translation;
//!   it is chosen so the constrained vertices are at their targets on average.

mod deformation_transfer;
mod local_frames;

use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::{Llt, PartialPivLu};
use faer::prelude::Solve;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::{Accum, Mat, Par, Side};
use meshes::TriMesh;
use serde::Deserialize;

pub use deformation_transfer::DeformationTransfer;
pub use local_frames::LocalFrameDetails;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::linalg::spectral::{smallest_eigenpairs, EigenOptions};
use crate::method::{
    require_phase, DeformationMethod, IterationObserver, IterationReport, Phase, SolveSummary,
};
use crate::operators::{laplacian, lumped_mass_for, LaplacianWeights, MassKind};
use crate::params::ParamCheck;

/// How the handle constraints enter the reduced system.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ConstraintMode {
    /// Eq 15, hard constraints by Lagrange multipliers (needs `n' <= m`).
    Lagrange,
    /// Weighted least squares in the reduced space (any number of constrained vertices).
    Penalty,
}

/// How details are added back (section 4.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DetailTransfer {
    /// Deformation transfer with the face normal as fourth vertex (Botsch et al. 2006).
    DeformationTransfer,
    /// Detail vectors in per-vertex local frames.
    LocalFrames,
}

/// Parameters of [`SpectralMhb`] (configs/methods.toml, section `[spectral_mhb]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpectralMhbParams {
    /// Number of manifold harmonics bases `m` (the paper: 100).
    pub bases: usize,
    /// Stretching stiffness `k_s` of eq 9-13.
    pub stretching: f64,
    /// Bending stiffness `k_b` of eq 9-13.
    pub bending: f64,
    pub constraints: ConstraintMode,
    /// Relative weight of the constraints in `penalty` mode (scale-free, see the module docs).
    pub constraint_weight: f64,
    pub details: DetailTransfer,
    /// Relative residual tolerance of the eigensolver.
    pub eigen_tolerance: f64,
    /// Seed of the eigensolver's start block.
    pub seed: u64,
    /// Weights of `L_s` and the matching masses (see the module documentation).
    pub weights: LaplacianWeights,
}

impl SpectralMhbParams {
    /// Every key whose value breaks its rule, with that value ([`ParamCheck`]).
    pub fn validate(&self) -> Result<(), MethodError> {
        let (s, b) = (self.stretching, self.bending);
        ParamCheck::new()
            .count_at_least("bases", self.bases, 1)
            .number_at_least("stretching", s, 0.0)
            .number_at_least("bending", b, 0.0)
            // Both 0 leave the reduced energy without a term (only when each is itself valid).
            .joint_rule(&[("stretching", s), ("bending", b)], !(s == 0.0 && b == 0.0), "must not both be 0")
            .number_above("constraint_weight", self.constraint_weight, 0.0)
            .number_above("eigen_tolerance", self.eigen_tolerance, 0.0)
            .finish(crate::keys::method_name::SPECTRAL_MHB)
    }
}

impl Default for SpectralMhbParams {
    fn default() -> Self {
        Self {
            bases: 100,
            stretching: 0.0,
            bending: 1.0,
            constraints: ConstraintMode::Penalty,
            constraint_weight: 10.0,
            details: DetailTransfer::DeformationTransfer,
            eigen_tolerance: 1e-10,
            seed: 0x5eed,
            weights: LaplacianWeights::default(),
        }
    }
}

enum Details {
    Transfer(DeformationTransfer),
    Frames(LocalFrameDetails),
}

enum ReducedSystem {
    Penalty { cholesky: Llt<f64>, weight2: f64 },
    Lagrange { lu: PartialPivLu<f64> },
}

struct Bound {
    /// The bound set; a solve's targets must be made for it.
    handles: HandleSet,
    constrained: Vec<u32>,
    /// `H_C`: the rows of `H` at the constrained vertices (`n' x m`).
    basis_rows: Mat<f64>,
    system: ReducedSystem,
}

/// Spectral mesh deformation; see the module documentation.
pub struct SpectralMhb {
    params: SpectralMhbParams,
    rest: Vec<[f64; 3]>,
    bbox_diagonal: f64,
    /// `H`, `#V x m`, `D`-orthonormal.
    basis: Mat<f64>,
    smoothed_rest: Vec<[f64; 3]>,
    /// `S = H^T (M A) H`, `m x m`.
    reduced_energy: Mat<f64>,
    details: Option<Details>,
    bound: Option<Bound>,
    current: Vec<[f64; 3]>,
    smoothed_deformed: Vec<[f64; 3]>,
    timings: Vec<(&'static str, f64)>,
}

impl SpectralMhb {
    /// A method with the given parameters; call [`DeformationMethod::precompute`] next.
    pub fn new(params: SpectralMhbParams) -> Result<Self, MethodError> {
        params.validate()?;
        Ok(Self {
            params,
            rest: Vec::new(),
            bbox_diagonal: 0.0,
            basis: Mat::zeros(0, 0),
            smoothed_rest: Vec::new(),
            reduced_energy: Mat::zeros(0, 0),
            details: None,
            bound: None,
            current: Vec::new(),
            smoothed_deformed: Vec::new(),
            timings: Vec::new(),
        })
    }

    /// `H`, the `#V x m` manifold harmonics bases.
    pub fn basis(&self) -> &Mat<f64> {
        &self.basis
    }

    /// The smoothed rest model `H H^T D p` (`#V x 3`).
    pub fn smoothed_rest(&self) -> &[[f64; 3]] {
        &self.smoothed_rest
    }

    /// The deformed smoothed model `p~ + H d~` of the last solve (`#V x 3`).
    pub fn smoothed_deformed(&self) -> &[[f64; 3]] {
        &self.smoothed_deformed
    }

    fn set_timing(&mut self, name: &'static str, seconds: f64) {
        match self.timings.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = seconds,
            None => self.timings.push((name, seconds)),
        }
    }
}

/// Columns of `H` per block of [`reduced_energy`].
const ENERGY_BLOCK: usize = 16;

/// PT2: the reduced energy `S = H^T (-k_s L_s + k_b L_s M^{-1} L_s) H` (`m x m`, symmetrized) of the
/// `#V x m` bases `H` (`M`: `#V` Voronoi masses).
///
/// Computed for blocks of [`ENERGY_BLOCK`] columns of `H` at a time, so the three `#V x m` products
/// of the operator never exist whole (at 1M vertices and m = 100: 0.4 GB of blocks beside `H`
/// against 3.2 GB); every column is computed with the same operations in the same order as the
/// whole products would be, so `S` is bitwise the same.
fn reduced_energy(
    laplacian: &faer::sparse::SparseColMat<usize, f64>,
    voronoi: &[f64],
    basis: faer::MatRef<'_, f64>,
    stretching: f64,
    bending: f64,
) -> Mat<f64> {
    let (n, m) = (basis.nrows(), basis.ncols());
    let width = ENERGY_BLOCK.min(m);
    let mut ls_h = Mat::<f64>::zeros(n, width);
    let mut minv_ls_h = Mat::<f64>::zeros(n, width);
    let mut energy_h = Mat::<f64>::zeros(n, width);
    let mut s = Mat::<f64>::zeros(m, m);
    for first in (0..m).step_by(width) {
        let w = width.min(m - first);
        let h = basis.subcols(first, w);
        let mut ls_h = ls_h.as_mut().subcols_mut(0, w);
        let mut minv_ls_h = minv_ls_h.as_mut().subcols_mut(0, w);
        let mut energy_h = energy_h.as_mut().subcols_mut(0, w);
        sparse_dense_matmul(ls_h.rb_mut(), Accum::Replace, laplacian.as_ref(), h, 1.0, Par::Seq);
        for j in 0..w {
            for i in 0..n {
                minv_ls_h[(i, j)] = ls_h[(i, j)] / voronoi[i];
            }
        }
        sparse_dense_matmul(
            energy_h.rb_mut(),
            Accum::Replace,
            laplacian.as_ref(),
            minv_ls_h.rb(),
            bending,
            Par::Seq,
        );
        for j in 0..w {
            for i in 0..n {
                energy_h[(i, j)] += -stretching * ls_h[(i, j)];
            }
        }
        matmul(
            s.as_mut().subcols_mut(first, w),
            Accum::Replace,
            basis.transpose(),
            energy_h.rb(),
            1.0,
            Par::rayon(0),
        );
    }
    Mat::from_fn(m, m, |i, j| 0.5 * (s[(i, j)] + s[(j, i)]))
}

fn to_mat(p: &[[f64; 3]]) -> Mat<f64> {
    Mat::from_fn(p.len(), 3, |i, a| p[i][a])
}

fn to_rows(m: &Mat<f64>) -> Vec<[f64; 3]> {
    (0..m.nrows()).map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]]).collect()
}

impl DeformationMethod for SpectralMhb {
    fn name(&self) -> &str {
        "spectral_mhb"
    }

    fn laplacian_weights(&self) -> Option<crate::operators::LaplacianWeights> {
        Some(self.params.weights)
    }

    fn precompute(&mut self, rest: &TriMesh) -> Result<(), MethodError> {
        meshes::Topology::new(rest)?;
        let (p, tris) = (rest.positions(), rest.triangles());
        let n = rest.n_vertices();
        self.timings.clear();

        // PT1: manifold harmonics bases. `L_s` is kept for PT2 only, then freed with the masses.
        let start = Instant::now();
        let laplacian = laplacian(self.params.weights, p, tris)?;
        let mhb_mass = lumped_mass_for(self.params.weights, p, tris, MassKind::Barycentric)?;
        let m = self.params.bases.min(n);
        let mut options = EigenOptions::new(m);
        options.tolerance = self.params.eigen_tolerance;
        options.seed = self.params.seed;
        let stiffness = crate::operators::stiffness(laplacian.clone());
        let pairs =
            smallest_eigenpairs(stiffness.as_ref(), &mhb_mass, &options).map_err(MethodError::Eigen)?;
        drop(stiffness);
        self.basis = pairs.vectors;
        self.set_timing(crate::keys::phase::PT1_MANIFOLD_HARMONICS, start.elapsed().as_secs_f64());

        // The smoothed model (eq 7-8).
        let coefficients =
            crate::linalg::spectral::transform(self.basis.as_ref(), &mhb_mass, to_mat(p).as_ref());
        self.smoothed_rest =
            to_rows(&crate::linalg::spectral::inverse_transform(self.basis.as_ref(), coefficients.as_ref()));

        // PT2: S = H^T (-k_s L_s + k_b L_s M^{-1} L_s) H.
        let start = Instant::now();
        let voronoi = lumped_mass_for(self.params.weights, p, tris, MassKind::Voronoi)?;
        self.reduced_energy = reduced_energy(
            &laplacian,
            &voronoi,
            self.basis.as_ref(),
            self.params.stretching,
            self.params.bending,
        );
        drop(laplacian);
        self.set_timing(crate::keys::phase::PT2_REDUCED_ENERGY, start.elapsed().as_secs_f64());

        // PT3: the detail system.
        let start = Instant::now();
        self.details = Some(match self.params.details {
            DetailTransfer::DeformationTransfer => {
                // The mesh's own -L (see the module documentation): G^T A G of the mesh gradients.
                let poisson = crate::operators::stiffness(crate::operators::cotan_laplacian(p, tris));
                Details::Transfer(DeformationTransfer::new(p, &self.smoothed_rest, tris, &poisson)?)
            }
            DetailTransfer::LocalFrames => {
                Details::Frames(LocalFrameDetails::new(p, &self.smoothed_rest, tris))
            }
        });
        self.set_timing(crate::keys::phase::PT3_DETAIL_SYSTEM, start.elapsed().as_secs_f64());

        self.rest = p.to_vec();
        self.bbox_diagonal = rest.bbox_diagonal();
        self.current = self.rest.clone();
        self.smoothed_deformed = self.smoothed_rest.clone();
        self.bound = None;
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        require_phase(self.details.as_ref(), "spectral_mhb", Phase::BindHandles)?;
        handles.check_mesh_size(self.rest.len())?;
        let start = Instant::now();
        let constrained: Vec<u32> = handles.constrained().collect();
        let m = self.basis.ncols();
        let nc = constrained.len();
        let basis_rows = Mat::from_fn(nc, m, |r, j| self.basis[(constrained[r] as usize, j)]);
        let s = &self.reduced_energy;
        let system = match self.params.constraints {
            ConstraintMode::Penalty => {
                let mut gram = Mat::<f64>::zeros(m, m);
                matmul(
                    gram.as_mut(),
                    Accum::Replace,
                    basis_rows.transpose(),
                    basis_rows.as_ref(),
                    1.0,
                    Par::Seq,
                );
                let trace_s: f64 = (0..m).map(|i| s[(i, i)]).sum();
                let trace_c: f64 = (0..m).map(|i| gram[(i, i)]).sum();
                let weight2 = self.params.constraint_weight * trace_s.max(f64::MIN_POSITIVE) / trace_c;
                let system = Mat::from_fn(m, m, |i, j| s[(i, j)] + weight2 * gram[(i, j)]);
                let cholesky = system.llt(Side::Lower).map_err(|_| {
                    MethodError::Handles(
                        "the reduced system is singular: the handles do not pin the bases down".into(),
                    )
                })?;
                ReducedSystem::Penalty { cholesky, weight2 }
            }
            ConstraintMode::Lagrange => {
                if nc > m {
                    return Err(MethodError::Handles(format!(
                        "constraints = \"lagrange\" (eq 15) needs at most m = {m} constrained vertices, got {nc}; use constraints = \"penalty\""
                    )));
                }
                let kkt = Mat::from_fn(m + nc, m + nc, |i, j| match (i < m, j < m) {
                    (true, true) => s[(i, j)],
                    (true, false) => basis_rows[(j - m, i)],
                    (false, true) => basis_rows[(i - m, j)],
                    (false, false) => 0.0,
                });
                ReducedSystem::Lagrange { lu: kkt.partial_piv_lu() }
            }
        };
        self.bound = Some(Bound { handles: handles.clone(), constrained, basis_rows, system });
        self.set_timing(crate::keys::phase::BIND_REDUCED_SYSTEM, start.elapsed().as_secs_f64());
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let bound = require_phase(self.bound.as_ref(), "spectral_mhb", Phase::Solve)?;
        targets.check_for(&bound.handles)?;
        let start = Instant::now();
        let m = self.basis.ncols();
        let nc = bound.constrained.len();
        // d' = p' - p at the constrained vertices.
        let displacement = Mat::from_fn(nc, 3, |r, a| {
            targets.positions()[r][a] - self.rest[bound.constrained[r] as usize][a]
        });

        // RT1: the reduced solve for d~ (m x 3).
        let t = Instant::now();
        let (spectral, rhs_seconds) = match &bound.system {
            ReducedSystem::Penalty { cholesky, weight2 } => {
                let mut rhs = Mat::<f64>::zeros(m, 3);
                matmul(
                    rhs.as_mut(),
                    Accum::Replace,
                    bound.basis_rows.transpose(),
                    displacement.as_ref(),
                    *weight2,
                    Par::Seq,
                );
                let rhs_seconds = t.elapsed().as_secs_f64();
                (cholesky.solve(&rhs), rhs_seconds)
            }
            ReducedSystem::Lagrange { lu } => {
                let rhs = Mat::from_fn(m + nc, 3, |i, a| if i < m { 0.0 } else { displacement[(i - m, a)] });
                let rhs_seconds = t.elapsed().as_secs_f64();
                let full = lu.solve(&rhs);
                (Mat::from_fn(m, 3, |i, a| full[(i, a)]), rhs_seconds)
            }
        };
        let rt1 = t.elapsed().as_secs_f64() - rhs_seconds;

        // RT2: the deformed smoothed model, then the details.
        let t = Instant::now();
        let displacement_field =
            crate::linalg::spectral::inverse_transform(self.basis.as_ref(), spectral.as_ref());
        self.smoothed_deformed = (0..self.rest.len())
            .map(|i| std::array::from_fn(|a| self.smoothed_rest[i][a] + displacement_field[(i, a)]))
            .collect();
        let inverse_mht = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let constrained = bound.constrained.clone();
        let result = match self.details.as_mut().expect("bound implies precomputed") {
            Details::Transfer(transfer) => {
                // Without constraints in a component, follow the smoothed deformation plus rest details.
                let fallback: Vec<[f64; 3]> = (0..self.rest.len())
                    .map(|i| {
                        std::array::from_fn(|a| {
                            self.smoothed_deformed[i][a] + self.rest[i][a] - self.smoothed_rest[i][a]
                        })
                    })
                    .collect();
                transfer.transfer(&self.smoothed_deformed, &constrained, targets.positions(), &fallback)
            }
            Details::Frames(frames) => frames.transfer(&self.smoothed_deformed),
        };
        let details = t.elapsed().as_secs_f64();
        if let Some(vertex) = result.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(MethodError::NonFinite { method: "spectral_mhb", vertex, iteration: 0 });
        }
        let step = crate::method::max_displacement(&result, &self.current) / self.bbox_diagonal;
        self.current = result;
        self.set_timing(crate::keys::phase::RT1_CONSTRAINT_RHS, rhs_seconds);
        self.set_timing(crate::keys::phase::RT1_REDUCED_SOLVE, rt1);
        self.set_timing(crate::keys::phase::RT2_INVERSE_MHT, inverse_mht);
        self.set_timing(crate::keys::phase::RT2_DETAILS, details);
        let report = IterationReport { iteration: 0, step, seconds: start.elapsed().as_secs_f64() };
        let current = &self.current;
        let _ = observer.on_iteration(&report, Some(&|| current.clone()));
        // A direct solve: the answer is the fixed point.
        Ok(SolveSummary {
            iterations: 1,
            converged: true,
            final_step: step,
            distance: 0.0,
            convergence_unknown: false,
        })
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }

    fn phase_timings(&self) -> Vec<(String, f64)> {
        crate::method::owned_names(self.timings.clone())
    }
}

#[cfg(test)]
mod tests {
    use faer::Mat;

    use super::reduced_energy;
    use crate::operators::{cotan_laplacian, lumped_mass, MassKind};

    #[test]
    fn reduced_energy_is_the_projection_of_the_thin_shell_operator() {
        let mesh = meshes::shapes::generate("bar".parse().unwrap(), 300).unwrap().mesh;
        let (p, tris) = (mesh.positions(), mesh.triangles());
        let n = mesh.n_vertices();
        let ls = cotan_laplacian(p, tris);
        let voronoi = lumped_mass(p, tris, MassKind::Voronoi);
        let h = Mat::from_fn(n, 7, |i, j| ((i * 37 + j * 101) % 17) as f64 / 8.0 - 1.0);
        let dense = ls.to_dense();
        let minv_ls = Mat::from_fn(n, n, |i, j| dense[(i, j)] / voronoi[i]);
        for (k_s, k_b) in [(0.0, 1.0), (1.0, 0.0), (0.3, 2.0)] {
            let operator = &dense * &minv_ls * k_b - &dense * k_s;
            let reference = h.transpose() * &operator * &h;
            let ours = reduced_energy(&ls, &voronoi, h.as_ref(), k_s, k_b);
            let scale = reference.norm_max();
            let err = (&ours - &reference).norm_max();
            assert!(err <= 1e-12 * scale, "k_s = {k_s}, k_b = {k_b}: {err:e} of {scale:e}");
            assert!(ours == ours.transpose().to_owned(), "S is symmetric");
        }
    }
}
