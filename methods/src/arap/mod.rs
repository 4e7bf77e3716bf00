//! `arap`: As-Rigid-As-Possible surface modeling (Sorkine & Alexa 2007), the suite's nonlinear reference.
//!
//! Energy (SA07 eq 3, "spokes"): `E(X) = sum_i sum_{j in N(i)} w_ij |(x_i - x_j) - R_i (p_i - p_j)|^2`
//! with cotangent weights `w_ij = (cot a_ij + cot b_ij) / 2` (libigl's `cotmatrix` entries; see
//! "Weights" below for the choice of triangulation), handle
//! vertices as hard constraints, alternating
//! - local step: `R_i` = closest rotation to `sum_j w_ij (x_i - x_j)(p_i - p_j)^T` (SA07 eq 5-6);
//! - global step: `-L X = b`, `b_i = sum_j w_ij / 2 (R_i + R_j)(p_i - p_j)` (SA07 eq 8-9), constrained
//!   rows eliminated.
//!
//! Weights (`weights`, [`LaplacianWeights`]; default `tufted_delaunay`). The energy's spokes are
//! the vertex pairs the chosen Laplacian couples, with `w_ij = L_ij`, and the global-step matrix is
//! that same `-L`:
//! - `cotan` is SA07 as published (and libigl's `arap`); on obtuse triangles `w_ij < 0` makes the
//!   energy reward stretching those spokes and the local step fit rotations to flipped spokes.
//! - `clamped`: the mesh's spokes with negative weights set to 0.
//! - `intrinsic_delaunay`: the spokes are the edges of the intrinsic Delaunay triangulation, all
//!   `w_ij >= 0`. Most are mesh edges; a flipped edge joins the two far corners of a pair of mesh
//!   triangles, and its spoke is the chord `p_i - p_j` between them (the rest vector whose rigid
//!   motion the energy measures; a rigid motion of the whole mesh still has zero energy). The
//!   alternative — mesh-edge spokes weighted by the intrinsic `L_ij` of their vertex pair, 0 for
//!   flipped-away edges — would leave `b(R = I) != -L P`, so the rest shape would not be a fixed
//!   point of its own global step. With spokes = `L`'s pattern, `b(R = I) = -L P` exactly, and with
//!   non-negative weights the rest covariance `sum_j w_ij e_ij e_ij^T` is positive semi-definite, so
//!   the local step returns `R = I` at rest (identity targets give zero motion; tested in
//!   `methods/tests/weights.rs`). Parallel intrinsic edges are summed in `L`; a self-edge has
//!   `e_ii = 0` and drops out. Boundary edges are never flipped, so a boundary edge opposite an
//!   obtuse angle keeps a negative weight (and the energy can be negative on open meshes).
//! - `tufted_delaunay` (default): the same with the tufted cover's intrinsic Delaunay edges (Sharp &
//!   Crane 2020, [`crate::operators::TuftedDelaunay`]): every `w_ij >= 0`, boundary edges included,
//!   so the energy is a sum of non-negative terms on every mesh.
//!
//! The initial guess (`start`): `"current"`, the current shape (the rest shape after `precompute`), as
//! libigl's `arap_solve` with `U = V`, so the two can be compared iteration for iteration
//! (`acceleration = "none"`); or `"transformation_propagation"`, one global step with the handles'
//! rotations propagated by harmonic weights ([`transformation_propagation`]; the weights are
//! computed at bind). Either way the iteration and its fixed points are SA07's, but the energy is
//! not convex and the two starts can end in different local minima (the procedural bar at 1.5K and
//! 6K vertices: 3-8% of the diagonal apart; at 50K the same one), so the default stays libigl's.
//!
//! Acceleration (`acceleration`, default `anderson`): the local/global iteration is the fixed-point
//! map `X <- G(X)` (local step on `X`, then the global solve), and Anderson acceleration (Peng, Deng,
//! Zhang, Geng, Qin & Liu 2018; depth `anderson_depth`) extrapolates from the last
//! steps. Their safeguard keeps the energy monotone: when the accelerated iterate's energy (with its
//! own local-step rotations) exceeds the previous iterate's, it is replaced by the plain image
//! `G(X_prev)` and the history is dropped. Convergence is judged on the plain steps `|G(X) - X|`
//! (their distance bound, [`DistanceBound`]; the quantity the plain iteration reports), and a converged solve returns `G(X)`, the global
//! solution for the last rotations. The fixed points are those of the plain iteration.
//!
//! Phases: `precompute` builds the weights and the symbolic factorization of `-L`'s pattern;
//! `bind_handles` does the numeric factorization of `-L` with the constrained rows and columns replaced
//! by identity (same pattern, so the symbolic analysis is reused for any handle set); each iteration is
//! one local step, one right-hand side assembly and one back-substitution of 3 columns.

mod quasi_newton;
pub mod saddle_test;
mod transformation_propagation;

use faer::sparse::SparseColMat;
use faer::Mat;
use meshes::TriMesh;
use rayon::prelude::*;
use serde::Deserialize;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets, FREE};
use crate::linalg::anderson::{Acceleration, AndersonAcceleration, RESIDUAL_GROWTH_LIMIT};
use crate::linalg::sparse_cholesky::SparseCholesky;
use crate::method::{
    move_to, require_phase, run_iterations, DeformationMethod, DistanceBound, IterationObserver, Iterations,
    Phase, SolveSummary,
};
use crate::operators::{laplacian, LaplacianWeights};
use crate::params::ParamCheck;
use crate::rotation_fit::{closest_rotation_near, Mat3};

/// Parameters of [`Arap`] (configs/methods.toml, section `[arap]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArapParams {
    /// Iteration limit per solve. 2000: the 1M bar and igea 2.1M need about 1,500 and 1,600
    /// (docs/results.md, issue 63); every survey, real-mesh and dataset case far fewer.
    pub max_iterations: usize,
    /// Converged when the estimated distance to the fixed point (`crate::method::DistanceBound`,
    /// from the step sequence) falls below `tolerance x bbox diagonal`.
    pub tolerance: f64,
    /// Spokes, weights and global-step matrix (see the module documentation, "Weights").
    pub weights: LaplacianWeights,
    /// `"anderson"` (Peng et al. 2018) or `"none"` (the plain local/global iteration, libigl's).
    pub acceleration: Acceleration,
    /// Steps of history Anderson acceleration extrapolates from (`m` of Peng et al.; at most 16).
    pub anderson_depth: usize,
    /// The first iterate of every solve (see the module documentation).
    pub start: ArapStart,
    /// `"lbfgs"` (quasi-Newton on the ARAP energy, [`quasi_newton`]) or `"local_global"` (SA07's
    /// alternation, accelerated as `acceleration` says). The same energy and fixed points.
    pub solver: ArapSolver,
    /// Curvature pairs L-BFGS keeps (`m` of Liu et al. 2017).
    pub lbfgs_memory: usize,
    /// Least scale `c` of L-BFGS's initial Hessian `c K` (in `(0, 1]`; see [`quasi_newton`]).
    pub lbfgs_scale_floor: f64,
    /// Size, times the bounding-box diagonal, of the smooth perturbation of a converged answer that
    /// a second solve starts from ([`saddle_test`]); 0: no saddle test.
    pub saddle_perturbation: f64,
}

/// How an ARAP solve minimizes the energy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArapSolver {
    /// L-BFGS with the factored global-step matrix as initial Hessian (Liu, Bouaziz & Kavan 2017).
    #[default]
    Lbfgs,
    /// The local/global iteration of SA07 (libigl's `arap_solve`), optionally Anderson-accelerated.
    LocalGlobal,
}

/// The first iterate of an ARAP solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArapStart {
    /// The current shape with the constrained vertices moved to their targets.
    #[default]
    Current,
    /// One global step with the handles' rotations propagated by harmonic weights.
    TransformationPropagation,
}

impl ArapParams {
    /// Every key whose value breaks its rule, with that value ([`ParamCheck`]).
    pub fn validate(&self) -> Result<(), MethodError> {
        ParamCheck::new()
            .count_at_least("max_iterations", self.max_iterations, 1)
            .number_at_least("tolerance", self.tolerance, 0.0)
            .count_at_most("anderson_depth", self.anderson_depth, crate::linalg::anderson::MAX_DEPTH)
            .count_at_most("lbfgs_memory", self.lbfgs_memory, 64)
            .number_in_half_open("lbfgs_scale_floor", self.lbfgs_scale_floor, 0.0, 1.0)
            .number_at_least("saddle_perturbation", self.saddle_perturbation, 0.0)
            .finish(crate::keys::method_name::ARAP)
    }
}

impl Default for ArapParams {
    fn default() -> Self {
        Self {
            max_iterations: 2000,
            tolerance: 1e-5,
            weights: LaplacianWeights::default(),
            acceleration: Acceleration::default(),
            anderson_depth: 7,
            start: ArapStart::default(),
            solver: ArapSolver::default(),
            lbfgs_memory: 8,
            lbfgs_scale_floor: 0.5,
            saddle_perturbation: 1e-3,
        }
    }
}

/// Rest-state data of ARAP: per-vertex spokes (CSR) with weights and rest edge vectors.
struct Spokes {
    offsets: Vec<usize>,
    neighbors: Vec<u32>,
    weights: Vec<f64>,
    rest_edges: Vec<[f64; 3]>,
}

/// As-Rigid-As-Possible surface modeling; see the module documentation.
pub struct Arap {
    params: ArapParams,
    rest: Vec<[f64; 3]>,
    bbox_diagonal: f64,
    spokes: Option<Spokes>,
    /// `-L`, the global-step matrix before constraints.
    stiffness: Option<SparseColMat<usize, f64>>,
    cholesky: Option<SparseCholesky>,
    handles: Option<HandleSet>,
    /// `#V x #regions` harmonic weights of the bound handles (`start = "transformation_propagation"`).
    propagation_weights: Option<Mat<f64>>,
    current: Vec<[f64; 3]>,
    rotations: Vec<Mat3>,
    /// Right singular vectors of each vertex's covariance, the warm start of the next local step.
    singular_frames: Vec<Mat3>,
    rhs_rows: Vec<[f64; 3]>,
    rhs: Mat<f64>,
    /// `G(X)` of the current iterate and the accelerated next iterate, `#V x 3` each.
    image: Vec<[f64; 3]>,
    next: Vec<[f64; 3]>,
    /// Per-vertex energies, summed in vertex order (deterministic).
    vertex_energies: Vec<f64>,
    /// `sum w |e|^2` at rest, the scale of the relative energies the saddle test compares.
    rest_dirichlet: f64,
    /// The last solve's saddle test, if it ran.
    saddle_test: Option<saddle_test::SaddleTest>,
}

impl Spokes {
    /// The spokes of `laplacian`'s off-diagonal pattern at `rest` (`#V x 3`) positions.
    fn new(laplacian: &SparseColMat<usize, f64>, rest: &[[f64; 3]]) -> Self {
        let n = rest.len();
        let (symbolic, values) = laplacian.parts();
        let mut offsets = Vec::with_capacity(n + 1);
        let mut neighbors = Vec::new();
        let mut weights = Vec::new();
        let mut rest_edges = Vec::new();
        offsets.push(0);
        // L is symmetric, so column i lists row i's neighbours: the spokes of vertex i.
        for i in 0..n {
            for idx in symbolic.col_range(i) {
                let j = symbolic.row_idx()[idx];
                if j != i {
                    neighbors.push(j as u32);
                    weights.push(values[idx]);
                    rest_edges.push(meshes::vector::sub(rest[i], rest[j]));
                }
            }
            offsets.push(neighbors.len());
        }
        Self { offsets, neighbors, weights, rest_edges }
    }
}

/// The ARAP energy of any shape on a rest mesh (SA07 eq 3 with the rotations of the local step),
/// relative to the rest shape's Dirichlet energy `sum_ij w_ij |p_i - p_j|^2`: dimensionless, 0 for
/// a rigid motion, the same for a uniformly scaled copy of the problem. The harness records it for
/// every result, so that a method that reached a lower ARAP energy than the reference shows.
pub struct ArapEnergy {
    spokes: Spokes,
    rest_dirichlet: f64,
}

impl ArapEnergy {
    /// The energy with `weights` on `rest`.
    pub fn new(rest: &TriMesh, weights: LaplacianWeights) -> Result<Self, MethodError> {
        let laplacian = laplacian(weights, rest.positions(), rest.triangles())?;
        let spokes = Spokes::new(&laplacian, rest.positions());
        let rest_dirichlet =
            spokes.weights.iter().zip(&spokes.rest_edges).map(|(w, e)| w * meshes::vector::dot(*e, *e)).sum();
        Ok(Self { spokes, rest_dirichlet })
    }

    /// `E(X) / sum w |e|^2` for `#V x 3` positions `x` on the rest connectivity.
    pub fn relative_energy(&self, x: &[[f64; 3]]) -> f64 {
        let n = x.len();
        let mut rotations = vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; n];
        let mut frames = rotations.clone();
        let mut per_vertex = vec![0.0; n];
        Arap::local_step(&self.spokes, x, &mut rotations, &mut frames);
        Arap::energy(&self.spokes, x, &rotations, &mut per_vertex) / self.rest_dirichlet
    }
}

impl Arap {
    /// A method with the given parameters; call [`DeformationMethod::precompute`] next.
    pub fn new(params: ArapParams) -> Result<Self, MethodError> {
        params.validate()?;
        Ok(Self {
            params,
            rest: Vec::new(),
            bbox_diagonal: 0.0,
            spokes: None,
            stiffness: None,
            cholesky: None,
            handles: None,
            propagation_weights: None,
            current: Vec::new(),
            rotations: Vec::new(),
            singular_frames: Vec::new(),
            rhs_rows: Vec::new(),
            rhs: Mat::zeros(0, 3),
            image: Vec::new(),
            next: Vec::new(),
            vertex_energies: Vec::new(),
            rest_dirichlet: 0.0,
            saddle_test: None,
        })
    }

    /// The rotations `R_i` of the last local step (`#V`, row-major 3x3).
    pub fn rotations(&self) -> &[Mat3] {
        &self.rotations
    }

    /// SA07's local step (eq 5-6): into `rotations` (`#V`; on entry the last fit, where each fit
    /// starts) the rotation best mapping each rest one-ring to `current`'s (`#V x 3`); `frames`
    /// (`#V`) are the warm singular frames of the SVD fallback.
    fn local_step(spokes: &Spokes, current: &[[f64; 3]], rotations: &mut [Mat3], frames: &mut [Mat3]) {
        rotations.par_iter_mut().zip(frames.par_iter_mut()).enumerate().with_min_len(256).for_each(
            |(i, (r, frame))| {
                let xi = current[i];
                let mut cov = [[0.0; 3]; 3];
                for s in spokes.offsets[i]..spokes.offsets[i + 1] {
                    let xj = current[spokes.neighbors[s] as usize];
                    let w = spokes.weights[s];
                    let d = [w * (xi[0] - xj[0]), w * (xi[1] - xj[1]), w * (xi[2] - xj[2])];
                    let e = spokes.rest_edges[s];
                    for a in 0..3 {
                        for b in 0..3 {
                            cov[a][b] += d[a] * e[b];
                        }
                    }
                }
                // The last rotation is a close start for Newton's fit; the Jacobi SVD from the
                // last singular frame answers where Newton does not converge.
                let previous = *r;
                *r = closest_rotation_near(&cov, &previous, frame);
            },
        );
    }

    /// SA07 eq 3 at `current` with `rotations`: `sum_i sum_j w_ij |(x_i - x_j) - R_i (p_i - p_j)|^2`,
    /// per vertex into `per_vertex` (in parallel), summed in vertex order.
    fn energy(spokes: &Spokes, current: &[[f64; 3]], rotations: &[Mat3], per_vertex: &mut [f64]) -> f64 {
        per_vertex.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, out)| {
            let (xi, r) = (current[i], &rotations[i]);
            let mut sum = 0.0;
            for s in spokes.offsets[i]..spokes.offsets[i + 1] {
                let xj = current[spokes.neighbors[s] as usize];
                let e = spokes.rest_edges[s];
                for a in 0..3 {
                    let d = (xi[a] - xj[a]) - (r[a][0] * e[0] + r[a][1] * e[1] + r[a][2] * e[2]);
                    sum += spokes.weights[s] * d * d;
                }
            }
            *out = sum;
        });
        per_vertex.iter().sum()
    }

    /// Global-step right-hand side, `#V x 3`: constrained rows hold their targets; free rows hold
    /// `b_i + sum_{j constrained} w_ij x_j` (the constrained columns moved to the right).
    fn assemble_rhs(
        spokes: &Spokes,
        rotations: &[Mat3],
        region_of: &[u32],
        current: &[[f64; 3]],
        rows: &mut [[f64; 3]],
        rhs: &mut Mat<f64>,
    ) {
        rows.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, row)| {
            if region_of[i] != FREE {
                *row = current[i];
                return;
            }
            let ri = &rotations[i];
            let mut b = [0.0; 3];
            for s in spokes.offsets[i]..spokes.offsets[i + 1] {
                let j = spokes.neighbors[s] as usize;
                let rj = &rotations[j];
                let e = spokes.rest_edges[s];
                let hw = 0.5 * spokes.weights[s];
                for a in 0..3 {
                    b[a] += hw
                        * ((ri[a][0] + rj[a][0]) * e[0]
                            + (ri[a][1] + rj[a][1]) * e[1]
                            + (ri[a][2] + rj[a][2]) * e[2]);
                }
                if region_of[j] != FREE {
                    let w = spokes.weights[s];
                    for a in 0..3 {
                        b[a] += w * current[j][a];
                    }
                }
            }
            *row = b;
        });
        for (i, b) in rows.iter().enumerate() {
            for a in 0..3 {
                rhs[(i, a)] = b[a];
            }
        }
    }
}

impl DeformationMethod for Arap {
    fn name(&self) -> &str {
        "arap"
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
        meshes::Topology::new(rest)?;
        let laplacian = laplacian(self.params.weights, rest.positions(), rest.triangles())?;
        let n = rest.n_vertices();
        let spokes = Spokes::new(&laplacian, rest.positions());
        let stiffness = crate::operators::stiffness(laplacian);
        self.cholesky = Some(SparseCholesky::analyze(stiffness.as_ref())?);
        self.stiffness = Some(stiffness);
        self.rest_dirichlet =
            spokes.weights.iter().zip(&spokes.rest_edges).map(|(w, e)| w * meshes::vector::dot(*e, *e)).sum();
        self.spokes = Some(spokes);
        self.rest = rest.positions().to_vec();
        self.bbox_diagonal = rest.bbox_diagonal();
        self.current = self.rest.clone();
        self.rotations = vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; n];
        self.singular_frames = self.rotations.clone();
        self.rhs_rows = vec![[0.0; 3]; n];
        self.rhs = Mat::zeros(n, 3);
        self.image = vec![[0.0; 3]; n];
        self.next = vec![[0.0; 3]; n];
        self.vertex_energies = vec![0.0; n];
        self.handles = None;
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        let (stiffness, cholesky) =
            require_phase(self.stiffness.as_ref().zip(self.cholesky.as_mut()), "arap", Phase::BindHandles)?;
        handles.check_mesh_size(self.rest.len())?;
        // Constrained rows and columns become identity; the pattern stays that of -L.
        let region_of = handles.region_of();
        let mut system = stiffness.clone();
        let (symbolic, values) = system.parts_mut();
        for j in 0..symbolic.ncols() {
            for idx in symbolic.col_range(j) {
                let i = symbolic.row_idx()[idx];
                if region_of[i] != FREE || region_of[j] != FREE {
                    values[idx] = if i == j { 1.0 } else { 0.0 };
                }
            }
        }
        cholesky.factorize(system.as_ref())?;
        self.propagation_weights = match (self.params.start, &self.spokes) {
            (ArapStart::TransformationPropagation, Some(spokes)) => {
                Some(transformation_propagation::harmonic_weights(
                    spokes,
                    region_of,
                    handles.regions().len(),
                    cholesky,
                ))
            }
            _ => None,
        };
        self.handles = Some(handles.clone());
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let ((handles, spokes), cholesky) = require_phase(
            self.handles.as_ref().zip(self.spokes.as_ref()).zip(self.cholesky.as_mut()),
            "arap",
            Phase::Solve,
        )?;
        targets.check_for(handles)?;
        for (v, t) in handles.constrained().zip(targets.positions()) {
            self.current[v as usize] = *t;
        }
        let region_of = handles.region_of();
        if let Some(weights) = &self.propagation_weights {
            let rotations = transformation_propagation::region_rotations(&self.rest, handles, targets);
            transformation_propagation::blend(&rotations, weights, &mut self.rotations);
            Self::assemble_rhs(
                spokes,
                &self.rotations,
                region_of,
                &self.current,
                &mut self.rhs_rows,
                &mut self.rhs,
            );
            cholesky.solve_in_place(self.rhs.as_mut());
            move_to("arap", 0, &mut self.current, self.rhs.as_ref())?;
        }
        let iterations =
            Iterations { first: 0, count: self.params.max_iterations, tolerance: self.params.tolerance };
        let first = self.minimize(iterations, observer)?;
        self.saddle_test = None;
        if self.params.saddle_perturbation > 0.0 && first.converged {
            return self.test_for_saddle(first, observer);
        }
        Ok(first)
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }

    fn model_statistics(&self) -> Vec<(String, f64)> {
        use crate::keys::statistic;
        match self.saddle_test {
            Some(t) => vec![
                (statistic::SADDLE_TEST_FIRST_ENERGY.into(), t.first_energy),
                (statistic::SADDLE_TEST_SECOND_ENERGY.into(), t.second_energy),
                (statistic::SADDLE_TEST_SECOND_KEPT.into(), f64::from(u8::from(t.second_kept))),
            ],
            None => Vec::new(),
        }
    }
}

impl Arap {
    /// The relative ARAP energy of `self.current` (local step included; rotations left in
    /// `self.rotations`).
    fn current_energy(&mut self) -> f64 {
        let Some(spokes) = self.spokes.as_ref() else { return f64::NAN };
        Self::local_step(spokes, &self.current, &mut self.rotations, &mut self.singular_frames);
        Self::energy(spokes, &self.current, &self.rotations, &mut self.vertex_energies)
            / self.rest_dirichlet.max(f64::MIN_POSITIVE)
    }

    /// The saddle test after the converged solve `first` ([`saddle_test`]): perturb, solve again,
    /// keep the lower energy.
    fn test_for_saddle(
        &mut self,
        first: SolveSummary,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let region_of = match &self.handles {
            Some(h) => h.region_of().to_vec(),
            None => return Ok(first),
        };
        let answer = self.current.clone();
        let first_energy = self.current_energy();
        let amplitude = self.params.saddle_perturbation * self.bbox_diagonal;
        saddle_test::perturb(&mut self.current, &region_of, amplitude, self.bbox_diagonal);
        let iterations = Iterations {
            first: first.iterations,
            count: self.params.max_iterations,
            tolerance: self.params.tolerance,
        };
        let second = self.minimize(iterations, observer)?;
        let second_energy = if second.converged { self.current_energy() } else { f64::INFINITY };
        let outcome = saddle_test::SaddleTest::judge(first_energy, second_energy);
        self.saddle_test = Some(outcome);
        if outcome.second_kept {
            return Ok(second);
        }
        self.current = answer;
        // The perturbed solve left its own rotations: fit them to the kept answer again, so that the
        // next edit step starts from the first answer's rotations.
        self.current_energy();
        Ok(SolveSummary { iterations: second.iterations, ..first })
    }

    /// Minimize from `self.current` with the configured solver until `iterations`' rule holds.
    fn minimize(
        &mut self,
        iterations: Iterations,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let ((handles, spokes), cholesky) = require_phase(
            self.handles.as_ref().zip(self.spokes.as_ref()).zip(self.cholesky.as_mut()),
            "arap",
            Phase::Solve,
        )?;
        let region_of = handles.region_of();
        let diagonal = self.bbox_diagonal;
        if self.params.solver == ArapSolver::Lbfgs {
            let solver = quasi_newton::QuasiNewton {
                spokes,
                region_of,
                cholesky,
                rotations: &mut self.rotations,
                frames: &mut self.singular_frames,
                vertex_energies: &mut self.vertex_energies,
                rhs: &mut self.rhs,
                memory: self.params.lbfgs_memory,
                scale_floor: self.params.lbfgs_scale_floor,
                diagonal,
            };
            return solver.solve(iterations, &mut self.current, observer);
        }
        let accelerated =
            self.params.acceleration == Acceleration::Anderson && self.params.anderson_depth > 0;
        let mut anderson = AndersonAcceleration::new(
            if accelerated { self.params.anderson_depth } else { 0 },
            if accelerated { 3 * self.current.len() } else { 0 },
        )
        .with_residual_growth_limit(RESIDUAL_GROWTH_LIMIT);
        let mut previous_energy = f64::INFINITY;
        let mut has_image = false;
        // The state is the iterate X; the closure holds the rest of the method's buffers.
        let iterate = |current: &mut Vec<[f64; 3]>,
                       iteration: usize,
                       rule: &DistanceBound|
         -> Result<f64, MethodError> {
            Self::local_step(spokes, current, &mut self.rotations, &mut self.singular_frames);
            if accelerated {
                // Peng et al.'s safeguard: an extrapolated iterate must not raise the energy.
                let energy = Self::energy(spokes, current, &self.rotations, &mut self.vertex_energies);
                let energy = if energy > previous_energy && has_image {
                    current.copy_from_slice(&self.image);
                    anderson.reset();
                    Self::local_step(spokes, current, &mut self.rotations, &mut self.singular_frames);
                    Self::energy(spokes, current, &self.rotations, &mut self.vertex_energies)
                } else {
                    energy
                };
                previous_energy = energy;
            }
            Self::assemble_rhs(
                spokes,
                &self.rotations,
                region_of,
                current,
                &mut self.rhs_rows,
                &mut self.rhs,
            );
            cholesky.solve_in_place(self.rhs.as_mut());
            // G(X) into `image`: checked, and the plain step |G(X) - X| judged.
            self.image.copy_from_slice(current);
            let step = move_to("arap", iteration, &mut self.image, self.rhs.as_ref())? / diagonal;
            has_image = true;
            if accelerated && !rule.is_met_by(step) {
                anderson.next(
                    current.as_flattened(),
                    self.image.as_flattened(),
                    self.next.as_flattened_mut(),
                );
                std::mem::swap(current, &mut self.next);
            } else {
                current.copy_from_slice(&self.image);
            }
            Ok(step)
        };
        let summary = run_iterations(iterations, &mut self.current, iterate, |x| x.clone(), observer)?;
        if accelerated && !summary.converged && has_image {
            // Stopped at the cap or by the observer: return the last global solution.
            self.current.copy_from_slice(&self.image);
        }
        Ok(summary)
    }
}
