//! `laplacian`: unreduced iterative Laplacian editing, the framework that Au et al. 2007 (section 3,
//! eq 1-3) and HIRM (section 4.4, eq 10) reduce.
//!
//! Minimize `|L X - delta(X)|^2 + omega^2 |Phi X - H|^2` (eq 1-2) by the inexact Gauss–Newton update
//! `X^{t+1} = (A^T A)^{-1} A^T b(X^t)` (eq 3), `A = [L; omega Phi]`, `A^T A = L^T L + omega^2 Phi^T Phi`
//! factored once per handle set.
//!
//! Decisions the paper leaves open (see also the tests):
//! - `L` is a cotangent Laplacian without mass normalization (libigl `cotmatrix`); eq 1 is
//!   invariant to the sign of `L`. The weights (`weights`, default `tufted_delaunay`) enter
//!   everything `L` does: the rest coordinates `delta = L X_rest`, the normal matrix `L^T L` and the
//!   right-hand side `L^T delta(X)`; the rest shape stays a fixed point for any weights since both
//!   sides use the same `L`.
//! - `delta(X)` update: the rest Laplacian coordinates `delta_i = (L X_rest)_i` turned with the
//!   surface, in Lipman et al. 2005's local frames by default (`delta_frame`,
//!   [`crate::laplacian_coordinates`], where both frames and why each is used are written down).
//!   The rest shape is a fixed point.
//! - `X^0` is the current shape (eq 3: "the current edited vertex positions"); from the rest shape
//!   iteration 0 therefore solves with the un-rotated `delta`, i.e. linear Laplacian editing
//!   (Lipman et al. 2004 / Sorkine et al. 2004 without their implicit transform).
//! - Phases: `precompute` builds `L`, `L^T L` and its symbolic factorization; `bind_handles` adds
//!   `omega^2 Phi^T Phi` (a diagonal, so the pattern and the symbolic factorization are reused) and
//!   factors numerically.
//! - Acceleration (`acceleration`, default `anderson`): eq 3 is the fixed-point map
//!   `X <- G(X) = (A^T A)^{-1} A^T b(X)`; Anderson acceleration (depth `anderson_depth`,
//!   [`crate::linalg::anderson`]) extrapolates from its last steps. The stopping rule reads the plain
//!   steps `|G(X) - X|` either way (their distance bound, [`DistanceBound`]), so the fixed point is
//!   the same (tested); `"none"` is the paper's
//!   iteration. Why: the plain iteration contracts slowly where a long limb has to turn (the survey
//!   cactus took 916 plain iterations, 169 accelerated). The armadillo does not settle either way: its
//!   free left arm keeps swinging (configs/methods.toml).

use faer::sparse::linalg::matmul::{sparse_dense_matmul, sparse_sparse_matmul};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Mat, Par};
use meshes::{Topology, TriMesh};
use serde::Deserialize;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::laplacian_coordinates::{DeltaFrame, RotationInvariantCoordinates};
use crate::linalg::anderson::{Acceleration, FixedPointIteration, MAX_DEPTH};
use crate::linalg::sparse_cholesky::{add_to_diagonal, SparseCholesky};
use crate::method::{
    move_to, require_phase, run_iterations, DeformationMethod, DistanceBound, IterationObserver, Iterations,
    Phase, SolveSummary,
};
use crate::operators::{laplacian, LaplacianWeights};
use crate::params::ParamCheck;

/// Parameters of [`LaplacianEditing`] (configs/methods.toml, section `[laplacian]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LaplacianParams {
    /// Soft-constraint weight `omega` of eq 2 (the paper: 1000).
    pub omega: f64,
    /// Iteration limit per solve.
    pub max_iterations: usize,
    /// Converged when the estimated distance to the fixed point (`crate::method::DistanceBound`,
    /// from the step sequence) falls below `tolerance x bbox diagonal`.
    pub tolerance: f64,
    /// Weights of `L` (see the module documentation).
    pub weights: LaplacianWeights,
    /// `"anderson"` or `"none"` (eq 3 as the paper iterates it); see the module documentation.
    pub acceleration: Acceleration,
    /// Steps of history Anderson acceleration extrapolates from (at most 16).
    pub anderson_depth: usize,
    /// How `delta(X)` turns with the surface ([`DeltaFrame`]).
    pub delta_frame: DeltaFrame,
}

impl LaplacianParams {
    /// Every key whose value breaks its rule, with that value ([`ParamCheck`]).
    pub fn validate(&self) -> Result<(), MethodError> {
        ParamCheck::new()
            .number_above("omega", self.omega, 0.0)
            .count_at_least("max_iterations", self.max_iterations, 1)
            .number_at_least("tolerance", self.tolerance, 0.0)
            .count_at_most("anderson_depth", self.anderson_depth, MAX_DEPTH)
            .finish(crate::keys::method_name::LAPLACIAN)
    }
}

impl Default for LaplacianParams {
    fn default() -> Self {
        Self {
            omega: 1000.0,
            max_iterations: 2000,
            tolerance: 1e-5,
            weights: LaplacianWeights::default(),
            acceleration: Acceleration::default(),
            anderson_depth: 5,
            delta_frame: DeltaFrame::default(),
        }
    }
}

/// Rest-state data: operator, rest Laplacian coordinates and one-rings.
struct RestState {
    laplacian: SparseColMat<usize, f64>,
    normal_matrix: SparseColMat<usize, f64>,
    coordinates: RotationInvariantCoordinates,
    bbox_diagonal: f64,
}

/// Iterative Laplacian editing; see the module documentation.
pub struct LaplacianEditing {
    params: LaplacianParams,
    rest: Option<RestState>,
    cholesky: Option<SparseCholesky>,
    handles: Option<HandleSet>,
    current: Vec<[f64; 3]>,
    /// `G(X)` of the current iterate, `#V x 3`.
    image: Vec<[f64; 3]>,
    delta: Mat<f64>,
    rhs: Mat<f64>,
}

impl LaplacianEditing {
    /// A method with the given parameters; call [`DeformationMethod::precompute`] next.
    pub fn new(params: LaplacianParams) -> Result<Self, MethodError> {
        params.validate()?;
        Ok(Self {
            params,
            rest: None,
            cholesky: None,
            handles: None,
            current: Vec::new(),
            image: Vec::new(),
            delta: Mat::zeros(0, 3),
            rhs: Mat::zeros(0, 3),
        })
    }

    /// Make `positions` (`#V x 3`) the current shape, the start of the next solve (for methods that
    /// use a Laplacian-editing step as their initialization).
    pub(crate) fn set_current_shape(&mut self, positions: &[[f64; 3]]) {
        self.current.clear();
        self.current.extend_from_slice(positions);
    }

    /// The current Laplacian coordinates `delta(X)` (`#V x 3`) into `self.delta`.
    fn update_delta(&mut self) {
        let rest = self.rest.as_mut().expect("precomputed");
        rest.coordinates.evaluate(&self.current, self.delta.as_mut());
    }
}

impl DeformationMethod for LaplacianEditing {
    fn name(&self) -> &str {
        "laplacian"
    }

    fn stopping(&self) -> Option<crate::method::Stopping> {
        Some(crate::method::Stopping {
            max_iterations: Some(self.params.max_iterations),
            tolerance: Some(self.params.tolerance),
        })
    }

    fn laplacian_weights(&self) -> Option<crate::operators::LaplacianWeights> {
        Some(self.params.weights)
    }

    fn precompute(&mut self, rest_mesh: &TriMesh) -> Result<(), MethodError> {
        let topology = Topology::new(rest_mesh)?;
        let positions = rest_mesh.positions();
        let n = rest_mesh.n_vertices();
        let laplacian = laplacian(self.params.weights, positions, rest_mesh.triangles())?;
        // L is symmetric, so L^T L = L L. Rebuilt from triplets to get sorted columns.
        let product =
            sparse_sparse_matmul(laplacian.as_ref(), laplacian.as_ref(), 1.0, Par::Seq).map_err(|e| {
                MethodError::Solver(crate::linalg::sparse_cholesky::SolverError::Faer(format!("{e:?}")))
            })?;
        let normal_matrix = sorted(&product);
        self.cholesky = Some(SparseCholesky::analyze(normal_matrix.as_ref())?);

        let coordinates = RotationInvariantCoordinates::new(
            positions,
            rest_mesh.triangles(),
            &topology,
            laplacian.as_ref(),
            self.params.delta_frame,
        );
        self.rest = Some(RestState {
            laplacian,
            normal_matrix,
            coordinates,
            bbox_diagonal: rest_mesh.bbox_diagonal(),
        });
        self.current = positions.to_vec();
        self.image = positions.to_vec();
        self.delta = Mat::zeros(n, 3);
        self.rhs = Mat::zeros(n, 3);
        self.handles = None;
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        let (rest, cholesky) =
            require_phase(self.rest.as_ref().zip(self.cholesky.as_mut()), "laplacian", Phase::BindHandles)?;
        handles.check_mesh_size(self.current.len())?;
        let mut diagonal = vec![0.0; self.current.len()];
        let w2 = self.params.omega * self.params.omega;
        for v in handles.constrained() {
            diagonal[v as usize] = w2;
        }
        cholesky.factorize(add_to_diagonal(rest.normal_matrix.as_ref(), &diagonal).as_ref())?;
        self.handles = Some(handles.clone());
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let handles = require_phase(self.handles.as_ref(), "laplacian", Phase::Solve)?;
        targets.check_for(handles)?;
        let w2 = self.params.omega * self.params.omega;
        let tolerance = self.params.tolerance;
        let iterations = Iterations { first: 0, count: self.params.max_iterations, tolerance };
        let mut fixed_point = FixedPointIteration::new(
            self.params.acceleration,
            self.params.anderson_depth,
            3 * self.current.len(),
        );
        let iterate = |m: &mut Self, iteration: usize, rule: &DistanceBound| -> Result<f64, MethodError> {
            m.update_delta();
            let rest = m.rest.as_ref().expect("bound implies precomputed");
            let handles = m.handles.as_ref().expect("checked above");
            sparse_dense_matmul(
                m.rhs.as_mut(),
                Accum::Replace,
                rest.laplacian.as_ref(),
                m.delta.as_ref(),
                1.0,
                Par::Seq,
            );
            for (v, t) in handles.constrained().zip(targets.positions()) {
                for a in 0..3 {
                    m.rhs[(v as usize, a)] += w2 * t[a];
                }
            }
            m.cholesky.as_mut().expect("bound").solve_in_place(m.rhs.as_mut());
            // G(X) into `image`, checked; the plain step |G(X) - X| is what converges.
            m.image.copy_from_slice(&m.current);
            let step = move_to("laplacian", iteration, &mut m.image, m.rhs.as_ref())? / rest.bbox_diagonal;
            fixed_point.advance(m.current.as_flattened_mut(), m.image.as_flattened(), rule.is_met_by(step));
            Ok(step)
        };
        let summary = run_iterations(iterations, self, iterate, |m| m.current.clone(), observer)?;
        if !summary.converged && fixed_point.is_accelerated() {
            // Stopped unconverged: the last G(X), not an extrapolated iterate.
            self.current.copy_from_slice(&self.image);
        }
        Ok(summary)
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }
}

/// A copy of `m` with the row indices of every column sorted.
fn sorted(m: &SparseColMat<usize, f64>) -> SparseColMat<usize, f64> {
    let (symbolic, values) = m.parts();
    let mut entries = Vec::with_capacity(values.len());
    for j in 0..symbolic.ncols() {
        for idx in symbolic.col_range(j) {
            entries.push(Triplet::new(symbolic.row_idx()[idx], j, values[idx]));
        }
    }
    SparseColMat::try_new_from_triplets(symbolic.nrows(), symbolic.ncols(), &entries)
        .expect("indices come from a valid matrix")
}
