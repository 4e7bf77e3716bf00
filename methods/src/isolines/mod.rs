//! `isolines`: the handle-aware isolines reduced model (Au, Fu, Tai & Cohen-Or 2007) of iterative
//! Laplacian editing.
//!
//! Section 4.1: per handle a harmonic field ([`harmonic_fields`]) and `n_iso` isolines at
//! `s_j = (j - 1) / (n_iso - 1)` ([`crate::isoline_model::tracing`]); every isoline carries a 3x4 affine transform `r_ij`,
//! the reduced variables. Section 4.2: vertex positions `X = W_x R_x` interpolate the transforms
//! linearly between neighbouring isolines and blend the handles by their harmonic values
//! ([`crate::isoline_model::interpolation`]). Section 4.3: Laplacian coordinates `delta = W_delta R_delta` interpolate per
//! isoline rotations `r^_ij` fitted to the crossed triangles (eq 8-9), so that the iteration of eq 10
//! only touches the `n_tri` sampled crossed triangles:
//!
//! `R_x^{t+1} = (U^T U)^{-1} [(W_x^T L^T W_delta) R_delta^t + omega^2 W_x^T Phi^T H]`,
//! `U^T U = W_x^T L^T L W_x + omega^2 W_x^T Phi^T Phi W_x + beta^2 M^T M` (eq 5-6),
//!
//! separately for x, y and z. [`LaplacianCoordinates::Vertices`] is the paper's intermediate model
//! with vertex interpolation only (eq 6, Table 1's `t_1`): `delta(W_x R_x)` is evaluated on the whole
//! mesh every iteration.
//!
//! Decisions the paper leaves open (tested in `methods/tests/isolines.rs`):
//! - Base shape: the reduced model is built on the shape current at `bind_handles` ("a new
//!   deformation system is set for the new handles based on the most recently edited result",
//!   section 5); from the rest shape that is the rest mesh. `L` is the rest mesh's cotangent
//!   Laplacian; `delta_bar = L X_base`.
//! - Weights of `L` (`weights`, default `tufted_delaunay`): they enter the harmonic fields
//!   (`L phi = 0`; with non-negative weights the maximum principle keeps them in `[0, 1]`, so the
//!   isolines are well defined), the reduced system `W_x^T L^T L W_x`, its right-hand side
//!   `W_x^T L^T W_delta` and `delta_bar = L X_base`.
//! - Isoline sets: with two handles one set, on the field of the first handle (section 4.1); with
//!   one handle the model is a single rigid transform and is refused (a handle set needs a second,
//!   e.g. fixed, region). With three or more, one set per handle, blended by `phi_i` (section 4.2).
//! - The special isolines at 0 and 1 are traced at `1e-6` and `1 - 1e-6`, just off the handle
//!   regions, where the field first leaves its boundary value.
//! - Eq 9 with the normals alone is singular when the crossed triangles' normals are coplanar — every
//!   isoline that rings a bar or a cylinder. We fit `r^_ij` to the whole frame of each crossed
//!   triangle at the isoline: its normal (eq 9's term), the segment direction and their cross
//!   product, all weighted by `l_k^2`. The normal-equation matrix becomes `(sum l_k^2) I` and
//!   `r^_ij = sum_k l_k^2 F_k F_bar_k^T / sum_k l_k^2`; a rigid motion of the isoline is recovered
//!   exactly, as with eq 9 where it is invertible.
//! - `Gamma_ij` sampling: at most `max_crossed_triangles / #isolines` triangles per isoline, every
//!   `ceil(count / limit)`-th in triangle order. Soft constraints on every handle vertex (the
//!   four-vertex handle representation of Botsch & Kobbelt is not used: `omega^2 W_x^T Phi^T H` is
//!   formed once per solve at `O(#constrained)` cost, outside the iterations).
//! - Step size: the largest displacement of the vertices of the sampled triangles (the only
//!   positions the iteration computes), over the bounding-box diagonal.
//! - Acceleration (`acceleration`, default `anderson`): eq 10 is a fixed-point map on the
//!   transforms, `R <- T(R)`; Anderson acceleration extrapolates from its last `anderson_depth`
//!   steps ([`ReducedFixedPoint`]), `"none"` is the paper's plain iteration. The step that must fall
//!   below the tolerance is the plain one either way, so the fixed point does not move (tested).

pub mod harmonic_fields;

use std::time::Instant;

use faer::linalg::solvers::Llt;
use faer::{Mat, Side};
use meshes::{Topology, TriMesh};
use serde::Deserialize;

pub use harmonic_fields::harmonic_fields;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::isoline_model::{
    checked_positions, reduced_step, IsolineModel, ModelFrame, ReducedFixedPoint, ReducedIteration,
    ReducedSystem, RotationFit, SetBlend,
};
use crate::laplacian_coordinates::{DeltaFrame, RotationInvariantCoordinates};
use crate::linalg::anderson::{Acceleration, MAX_DEPTH};
use crate::method::{
    require_phase, run_iterations, DeformationMethod, DistanceBound, IterationObserver, Iterations, Phase,
    SolveSummary,
};
use crate::operators::{laplacian, LaplacianWeights};
use crate::params::ParamCheck;

/// How the Laplacian coordinates of eq 1 are evaluated in the reduced iteration.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum LaplacianCoordinates {
    /// Interpolated from the isoline rotations, `delta = W_delta R_delta` (section 4.3, eq 10):
    /// per-iteration work depends on `n_tri` only.
    Isolines,
    /// `delta(W_x R_x)` on the whole mesh (eq 6; Table 1's `t_1`): per-iteration work `O(#V)`.
    Vertices,
}

/// Parameters of [`Isolines`] (configs/methods.toml, sections `[isolines]` and
/// `[isolines_t1]`; the sweep points `isolines[isolines=10]` and others lay their values over `[isolines]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IsolinesParams {
    /// `n_iso`, isolines per handle (the paper: 20).
    pub isolines: usize,
    /// Upper bound on `n_tri`, the sampled crossed triangles of all isolines (section 4.3; the
    /// paper's bar uses 570).
    pub max_crossed_triangles: usize,
    /// Weight `beta` of the smoothness term (eq 5; the paper: 0.01).
    pub beta: f64,
    /// Soft handle-constraint weight `omega` (eq 6), as in `laplacian`.
    pub omega: f64,
    /// `isolines` (the paper's model) or `vertices` (the `t_1` variant).
    pub laplacian_coordinates: LaplacianCoordinates,
    /// Iteration limit per solve.
    pub max_iterations: usize,
    /// Converged when the estimated distance to the fixed point (`crate::method::DistanceBound`,
    /// from the step sequence) falls below `tolerance x bbox diagonal`.
    pub tolerance: f64,
    /// Weights of `L` (see the module documentation).
    pub weights: LaplacianWeights,
    /// `"anderson"` or `"none"` (eq 10 as the paper iterates it); see the module documentation.
    pub acceleration: Acceleration,
    /// Steps of history Anderson acceleration extrapolates from (at most 16).
    pub anderson_depth: usize,
    /// How `delta(X)` turns with the surface in the `vertices` variant ([`DeltaFrame`]).
    pub delta_frame: DeltaFrame,
}

impl IsolinesParams {
    /// Every key whose value breaks its rule, with that value ([`ParamCheck`]), for the method
    /// registered as `method`.
    pub fn validate(&self, method: &'static str) -> Result<(), MethodError> {
        ParamCheck::new()
            .count_at_least("isolines", self.isolines, 2)
            .count_at_least("max_crossed_triangles", self.max_crossed_triangles, 1)
            .number_at_least("beta", self.beta, 0.0)
            .number_above("omega", self.omega, 0.0)
            .count_at_least("max_iterations", self.max_iterations, 1)
            .number_at_least("tolerance", self.tolerance, 0.0)
            .count_at_most("anderson_depth", self.anderson_depth, MAX_DEPTH)
            .finish(method)
    }
}

impl Default for IsolinesParams {
    fn default() -> Self {
        Self {
            isolines: 20,
            max_crossed_triangles: 600,
            beta: 0.01,
            omega: 1000.0,
            laplacian_coordinates: LaplacianCoordinates::Isolines,
            max_iterations: 2000,
            tolerance: 1e-5,
            weights: LaplacianWeights::default(),
            acceleration: Acceleration::default(),
            anderson_depth: 5,
            delta_frame: DeltaFrame::default(),
        }
    }
}

/// Rest-mesh data kept between handle sets.
struct Rest {
    triangles: Vec<[u32; 3]>,
    topology: Topology,
    laplacian: faer::sparse::SparseColMat<usize, f64>,
    /// The frame the reduced transforms act in (unit-free smoothness, see `ModelFrame`).
    frame: ModelFrame,
    bbox_diagonal: f64,
}

/// Everything built by `bind_handles`.
struct Bound {
    model: IsolineModel,
    system: ReducedSystem,
    factor: Llt<f64>,
    handles: HandleSet,
    /// `t_1` variant only: `delta(X)` on the whole mesh.
    coordinates: Option<RotationInvariantCoordinates>,
}

/// The handle-aware isolines reduced model; see the module documentation.
pub struct Isolines {
    name: &'static str,
    params: IsolinesParams,
    rest: Option<Rest>,
    bound: Option<Bound>,
    /// `#V x 3` shape at the last bind or solve.
    current: Vec<[f64; 3]>,
    /// `4N x 3` reduced variables (per coordinate a column) of the current solve.
    reduced: Mat<f64>,
    timings: Vec<(&'static str, f64)>,
}

impl Isolines {
    /// A method registered as `name` with the given parameters.
    pub fn new(name: &'static str, params: IsolinesParams) -> Result<Self, MethodError> {
        params.validate(name)?;
        Ok(Self {
            name,
            params,
            rest: None,
            bound: None,
            current: Vec::new(),
            reduced: Mat::zeros(0, 3),
            timings: Vec::new(),
        })
    }

    /// The reduced model of the bound handle set (for tests and reports).
    pub fn model(&self) -> Option<&IsolineModel> {
        self.bound.as_ref().map(|b| &b.model)
    }
}

impl DeformationMethod for Isolines {
    fn name(&self) -> &str {
        self.name
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

    fn precompute(&mut self, rest: &TriMesh) -> Result<(), MethodError> {
        let start = Instant::now();
        let topology = Topology::new(rest)?;
        let laplacian = laplacian(self.params.weights, rest.positions(), rest.triangles())?;
        self.rest = Some(Rest {
            triangles: rest.triangles().to_vec(),
            topology,
            laplacian,
            frame: ModelFrame::of(rest.positions()),
            bbox_diagonal: rest.bbox_diagonal(),
        });
        self.bound = None;
        self.current = rest.positions().to_vec();
        self.timings = vec![(crate::keys::phase::PRECOMPUTE_LAPLACIAN, start.elapsed().as_secs_f64())];
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        let rest = require_phase(self.rest.as_ref(), self.name, Phase::BindHandles)?;
        handles.check_mesh_size(self.current.len())?;
        if handles.regions().len() < 2 {
            return Err(MethodError::Handles(format!(
                "`{}` needs at least two handle regions (e.g. a handle and the fixed region): one handle \
                 gives a constant harmonic field and no isolines",
                self.name
            )));
        }
        let t0 = Instant::now();
        let fields = harmonic_fields(rest.laplacian.as_ref(), handles)?;
        let t1 = Instant::now();
        // Two handles: one set on the first field (the second is its complement).
        let sets = if fields.ncols() == 2 { fields.as_ref().subcols(0, 1) } else { fields.as_ref() };
        let mut model = IsolineModel::new(
            rest.frame,
            &self.current,
            &rest.triangles,
            sets,
            &SetBlend::FieldValues,
            self.params.isolines,
            self.params.max_crossed_triangles,
        );
        let t2 = Instant::now();
        let system = ReducedSystem::new(
            &mut model,
            rest.laplacian.as_ref(),
            handles,
            self.params.omega,
            self.params.beta,
            self.params.laplacian_coordinates == LaplacianCoordinates::Isolines,
        );
        let factor = system.normal_matrix.as_ref().llt(Side::Lower).map_err(|_| {
            MethodError::Solver(crate::linalg::sparse_cholesky::SolverError::NotPositiveDefinite)
        })?;
        let coordinates = (self.params.laplacian_coordinates == LaplacianCoordinates::Vertices).then(|| {
            RotationInvariantCoordinates::new(
                &self.current,
                &rest.triangles,
                &rest.topology,
                rest.laplacian.as_ref(),
                self.params.delta_frame,
            )
        });
        let t3 = Instant::now();
        self.reduced = model.identity_transforms();
        self.timings.retain(|(k, _)| *k == crate::keys::phase::PRECOMPUTE_LAPLACIAN);
        self.timings.extend([
            (crate::keys::phase::BIND_HARMONIC_FIELDS, (t1 - t0).as_secs_f64()),
            (crate::keys::phase::BIND_ISOLINES, (t2 - t1).as_secs_f64()),
            (crate::keys::phase::BIND_REDUCED_SYSTEM, (t3 - t2).as_secs_f64()),
        ]);
        self.bound = Some(Bound { model, system, factor, handles: handles.clone(), coordinates });
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let name = self.name;
        let (rest, bound) = require_phase(self.rest.as_ref().zip(self.bound.as_mut()), name, Phase::Solve)?;
        targets.check_for(&bound.handles)?;
        let t0 = Instant::now();
        let constraint_rhs = bound.system.constraint_rhs(&bound.model, &bound.handles, targets);
        let mut probes = bound.model.probe_positions(self.reduced.as_ref());
        let mut delta =
            Mat::<f64>::zeros(if bound.coordinates.is_some() { self.current.len() } else { 0 }, 3);
        let setup = t0.elapsed().as_secs_f64();
        let tolerance = self.params.tolerance;
        let iterations = Iterations { first: 0, count: self.params.max_iterations, tolerance };
        let mut fixed_point = ReducedFixedPoint::new(
            self.params.acceleration,
            self.params.anderson_depth,
            self.reduced.nrows(),
        );
        let iterate = |reduced: &mut Mat<f64>,
                       iteration: usize,
                       rule: &DistanceBound|
         -> Result<f64, MethodError> {
            fixed_point.begin(reduced.as_ref());
            let mut rhs = constraint_rhs.clone();
            match &mut bound.coordinates {
                None => {
                    let rotations = bound.model.isoline_rotations(&probes, RotationFit::SegmentFrames);
                    rhs += &bound.system.laplacian_rhs * &rotations;
                }
                Some(coordinates) => {
                    let shape = bound.model.positions(reduced.as_ref());
                    coordinates.evaluate(&shape, delta.as_mut());
                    rhs += bound.system.laplacian_rhs_full(
                        &bound.model,
                        rest.laplacian.as_ref(),
                        delta.as_ref(),
                    );
                }
            }
            let it =
                ReducedIteration { method: name, iteration, model: &bound.model, factor: bound.factor.L() };
            let step = reduced_step(it, rhs, reduced, &mut probes, rest.bbox_diagonal)?;
            fixed_point.advance(name, iteration, &bound.model, reduced, &mut probes, rule.is_met_by(step))?;
            Ok(step)
        };
        let shape = |reduced: &Mat<f64>| bound.model.positions(reduced.as_ref());
        let summary = run_iterations(iterations, &mut self.reduced, iterate, shape, observer)?;
        if !summary.converged {
            fixed_point.end_unconverged(&mut self.reduced);
        }
        let t1 = Instant::now();
        self.current = checked_positions(name, &bound.model, self.reduced.as_ref(), summary.iterations)?;
        self.timings.retain(|(k, _)| !k.starts_with(crate::keys::phase::SOLVE_PREFIX));
        self.timings.extend([
            (crate::keys::phase::SOLVE_CONSTRAINT_RHS, setup),
            (crate::keys::phase::SOLVE_VERTEX_POSITIONS, t1.elapsed().as_secs_f64()),
        ]);
        Ok(summary)
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }

    fn phase_timings(&self) -> Vec<(String, f64)> {
        crate::method::owned_names(self.timings.clone())
    }

    fn model_statistics(&self) -> Vec<(String, f64)> {
        self.bound.as_ref().map_or_else(Vec::new, |b| {
            crate::method::owned_names(vec![
                (crate::keys::statistic::N_ISOLINES, b.model.n_isolines() as f64),
                (crate::keys::statistic::N_TRI, b.model.n_sampled_triangles() as f64),
            ])
        })
    }
}
