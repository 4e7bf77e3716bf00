//! `scale_aware`: scale-aware shape manipulation (Liu, Wang, Liu & Liu 2014), and its optimal rigidity
//! approximation `scale_aware_ora`.
//!
//! The year: the paper's header says 2010 and a footnote 2013, both journal template text (it cites
//! work of 2014); its DOI, 10.1631/jzus.C1400122, is J. Zhejiang Univ.-Sci. C of 2014.
//!
//! Section 3: a mesh is represented by its scale-invariant measures `Omega` — triangle angles and
//! edge angles ([`scale_invariant_measures`]) — which determine it up to a similarity. With the
//! face normals `N` known, every corner gives the linear equation `e_{i+1} = l_i R_i e_i` (eq 1-2),
//! all corners together the scale-aware equations `G(Theta, N) V = 0` (eq 3,
//! [`scale_aware_equations`]); the edge angles constrain the normals (eq 4).
//!
//! Section 4, Algorithm 1: from an initial guess, alternate
//! - step one ([`gauss_map`]): the normals of the current shape are moved on the Gauss map towards
//!   the rest edge angles by local/global ARAP iterations on the normal pyramids (eq 7-11);
//! - step two: with the normals fixed, `min |G V|^2 + lambda sum_{j in C} |v_j - v_j*|^2` (eq 12,
//!   `lambda = 100`), i.e. `(G^T G + lambda C) V = lambda C V*`, a `3#V x 3#V` sparse system whose
//!   values change with the normals (the paper's "factorized once" cannot hold in 3D): the symbolic
//!   factorization is computed once in `precompute`, the numeric one only when the normals turned
//!   `refactor_turn` since the last or the lagged steps in between (conjugate gradients
//!   preconditioned by the held one) cost more than a refactorization would ([`vertex_recovery`];
//!   same fixed points).
//!
//! Section 5.2: the initial guess is linear Laplacian editing (Sorkine et al. 2004), here iteration
//! 0 of [`crate::laplacian`] from the current shape. Section 5.3 ([`optimal_rigidity`]):
//! `scale_aware_ora` rescales every triangle of the converged result to its rest area and stitches
//! them (eq 13-15).
//!
//! Decisions the paper leaves open (tested in `methods/tests/scale_aware.rs`):
//! - Iterations reported to the observer: iteration 0 is the initialization, 1.. are the outer
//!   iterations of Algorithm 1; `scale_aware_ora` reports the stitching as one more iteration.
//!   Convergence is Algorithm 1's: the fixed-point residual `|T(x) - x|` (the largest vertex move
//!   of a plain outer iteration) below `tolerance x bbox diagonal`; the stitching step does not
//!   count.
//! - At least three constrained vertices are required (section 4, "at least three"); fewer leave
//!   the similarity of `G` undetermined.
//! - Weights (`weights`, default `tufted_delaunay`): the only Laplacian of the method is that of
//!   the section 5.2 initialization (linear Laplacian editing), so the weights enter the initial
//!   guess only. Algorithm 1 itself has no cotangent Laplacian: step two's `G(Theta, N)` is built
//!   from corner angles, and step one's normal-pyramid weights are face areas ([`gauss_map`]).
//! - Every solve starts from the Laplacian initialization of the current shape, so a second edit
//!   step is handled like the first (`later_start = "previous_result"` starts a later one from the
//!   last result instead; measured no faster, docs/results.md issue 52).
//! - Acceleration. Algorithm 1 converges linearly and slowly: on the survey cactus the largest step
//!   is still 1e-3 of the diagonal after 50 plain outer iterations (E_phi 0.49 deg, 0.43 after
//!   300). The outer iteration is therefore Anderson-accelerated ([`crate::linalg::anderson`],
//!   depth 5 by default; `anderson_depth = 0` is the plain iteration). A converged `x` is a fixed
//!   point either way, and the convergence test uses the fixed-point residual `|T(x) - x|`, which
//!   is the plain step, with the plain map's secant contraction (the accelerated steps shrink
//!   faster than the map contracts; [`DistanceBound::contraction_at_least`]). Which fixed point a
//!   solve ends at can depend on the path: on the survey cylinder depth 10, or step-two solves
//!   lagged by one correction, end 1.2-1.4e-3 (RMS over the diagonal) from depth 5's fixed point,
//!   with E_phi within 0.01 deg; hence depth 5 and lagged steps solved to 0.1%. Step two by
//!   conjugate gradients ends the survey cylinder 2.3e-3 from the exact path's fixed point
//!   (e_iso 0.387 against 0.391, E_phi 1.027 deg against 1.025; docs/results.md issue 63).
//! - `scale_aware_ora` runs Algorithm 1 exactly as `scale_aware` does, so where a `scale_aware`
//!   instance sharing its [`SolveMemo`] has just solved the same inputs (the same rest mesh,
//!   parameters, handles, targets and start shape: a case of each on one scenario edit step), it
//!   takes that result ([`solve_memo`]) and only stitches; [`DeformationMethod::reused_solve`]
//!   reports the seconds of the solve it took, which the harness adds to its solve time. The
//!   iterations of the taken solve are reported again, with the iterates its observer asked for
//!   (the harness's angle errors of the trace), so that traces and counts are those of the
//!   computation. An observer that stops such a replay gets the taken solve's final shape.
//! - Step one's inner loop rarely meets `normal_tolerance` within `normal_sweeps`: the smooth
//!   rotation of the Gauss map that carries the bend is its slowest mode, and the outer iteration
//!   depends on it not converging (fully converged, step one would rotate the rest normals
//!   rigidly). Measured on the cactus, 10 inner iterations end at E_phi 0.55 deg, 20 at 0.49 and 60
//!   at 0.44 after 50 outer iterations, with slower outer convergence the more inner iterations;
//!   20 is the paper's upper figure and the default.

pub mod gauss_map;
pub mod optimal_rigidity;
pub mod scale_aware_equations;
pub mod scale_invariant_measures;
pub mod solve_memo;
pub mod vertex_recovery;

use std::ops::ControlFlow;
use std::time::Instant;

use faer::Mat;
use meshes::geometry::{face_areas, face_normals_into};
use meshes::{Topology, TriMesh};
use serde::Deserialize;

pub use crate::linalg::anderson::{self, AndersonAcceleration};
pub use gauss_map::{NormalPyramids, NormalUpdate, SpokeWeights};
pub use optimal_rigidity::{rescaled_triangles, Stitching};
pub use scale_aware_equations::ScaleAwareEquations;
pub use scale_invariant_measures::ScaleInvariantMeasures;
pub use solve_memo::SolveMemo;
pub use vertex_recovery::{RecoveryTimings, VertexRecovery};

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::laplacian::{LaplacianEditing, LaplacianParams};
use crate::laplacian_coordinates::DeltaFrame;
use crate::method::{
    max_displacement, move_to, require_phase, run_iterations, DeformationMethod, DistanceBound,
    IterationObserver, IterationReport, Iterations, NoObserver, Phase, ReusedSolve, SolveSummary,
};
use crate::operators::LaplacianWeights;
use crate::params::ParamCheck;
use crate::rotation_fit::Mat3;
use solve_memo::{Fingerprint, FingerprintBuilder, MemoizedSolve, RecordingObserver};

/// Outer iterations whose last step was below this fraction of the tolerance solve step two
/// exactly (refactoring). Without it the real armadillo stopped `unfinished` at its 200-iteration
/// cap with steps of 4.8e-7 of the diagonal, the lagged steps' error keeping the secant contraction
/// above 1; with it, `ok` after 188, 24 refactorizations (with the switch at 1x the tolerance: 121
/// refactorizations, the survey plane as slow as refactoring every time).
const EXACT_TAIL: f64 = 0.01;

/// Parameters of [`ScaleAware`] (configs/methods.toml, sections `[scale_aware]` and
/// `[scale_aware_ora]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ScaleAwareParams {
    /// `lambda` of eq 12, the soft handle-constraint weight (the paper: 100).
    pub constraint_weight: f64,
    /// Limit on the outer iterations of Algorithm 1 per solve.
    pub max_iterations: usize,
    /// Converged when the estimated distance to the fixed point (`crate::method::DistanceBound`
    /// over the fixed-point residuals `|T(x) - x|`) falls below `tolerance x bbox diagonal`.
    pub tolerance: f64,
    /// Local/global sweeps of step one per outer iteration (the paper: "usually 5–20"). Step one
    /// rarely meets `normal_tolerance`, so this count defines the map Algorithm 1 iterates, and so
    /// its fixed points (module documentation); formerly `normal_iterations`.
    #[serde(alias = "normal_iterations")]
    pub normal_sweeps: usize,
    /// Where a solve after the first starts Algorithm 1 ([`LaterStart`]).
    pub later_start: LaterStart,
    /// Spoke weights of step one's normal pyramids (eq 7-11; [`gauss_map::SpokeWeights`]).
    pub normal_weights: gauss_map::SpokeWeights,
    /// Step one stops once no normal moves by more than this (radians).
    pub normal_tolerance: f64,
    /// Soft-constraint weight `omega` of the Laplacian-editing initialization (section 5.2).
    pub initialization_omega: f64,
    /// Weights of the initialization's Laplacian (see the module documentation).
    pub weights: LaplacianWeights,
    /// Anderson acceleration depth (0: off).
    pub anderson_depth: usize,
    /// Step two refactors its matrix when some normal turned by more than this (chord length,
    /// about radians) since the held factorization, and otherwise takes a lagged step with it
    /// (conjugate gradients preconditioned by it, [`vertex_recovery`]; same fixed points). 0:
    /// refactor every outer iteration.
    pub refactor_turn: f64,
    /// Apply the optimal rigidity approximation (section 5.3) to the converged result.
    pub optimal_rigidity: bool,
}

impl ScaleAwareParams {
    /// Every key whose value breaks its rule, with that value ([`ParamCheck`]), for the method
    /// registered as `method`.
    pub fn validate(&self, method: &'static str) -> Result<(), MethodError> {
        ParamCheck::new()
            .number_above("constraint_weight", self.constraint_weight, 0.0)
            .count_at_least("max_iterations", self.max_iterations, 1)
            .number_at_least("tolerance", self.tolerance, 0.0)
            .count_at_least("normal_sweeps", self.normal_sweeps, 1)
            .number_at_least("normal_tolerance", self.normal_tolerance, 0.0)
            .number_above("initialization_omega", self.initialization_omega, 0.0)
            .count_at_most("anderson_depth", self.anderson_depth, anderson::MAX_DEPTH)
            .number_at_least("refactor_turn", self.refactor_turn, 0.0)
            .finish(method)
    }
}

impl Default for ScaleAwareParams {
    fn default() -> Self {
        Self {
            constraint_weight: 100.0,
            max_iterations: 200,
            tolerance: 1e-4,
            normal_sweeps: 20,
            normal_weights: gauss_map::SpokeWeights::default(),
            later_start: LaterStart::default(),
            normal_tolerance: 1e-4,
            initialization_omega: 1000.0,
            weights: LaplacianWeights::default(),
            optimal_rigidity: false,
            anderson_depth: 5,
            refactor_turn: 0.2,
        }
    }
}

/// The start of Algorithm 1 for an edit step after the first (`later_start`): the first solve always
/// starts from section 5.2's Laplacian editing of the rest shape.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LaterStart {
    /// Laplacian editing of the current shape (the last result), as the first solve.
    #[default]
    Laplacian,
    /// The last result itself (a warm start): the handles move to their new targets through the
    /// soft constraints of step two.
    PreviousResult,
}

/// Everything built from the rest mesh.
struct RestState {
    triangles: Vec<[u32; 3]>,
    equations: ScaleAwareEquations,
    pyramids: NormalPyramids,
    rest_areas: Vec<f64>,
    bbox_diagonal: f64,
    /// The rest mesh and the parameters of Algorithm 1, for [`solve_memo`].
    fingerprint: Fingerprint,
}

/// Everything built for one handle set.
struct BoundState {
    handles: HandleSet,
    /// `3 #V`: `lambda` on the coordinates of constrained vertices.
    constraint_diagonal: Vec<f64>,
    stitching: Option<Stitching>,
}

/// Accumulated phase times of the last solve, in seconds.
#[derive(Clone, Copy, Debug, Default)]
struct SolveTimings {
    initialization: f64,
    step_one_normals: f64,
    recovery: RecoveryTimings,
    stitching: f64,
    outer_iterations: usize,
    normal_iterations: usize,
}

/// Scale-aware shape manipulation; see the module documentation.
pub struct ScaleAware {
    name: &'static str,
    params: ScaleAwareParams,
    initialization: LaplacianEditing,
    rest: Option<RestState>,
    /// Step two's system (eq 12) and its factorization.
    recovery: Option<VertexRecovery>,
    bound: Option<BoundState>,
    current: Vec<[f64; 3]>,
    // Storage reused by every outer iteration.
    normals: Vec<[f64; 3]>,
    rotations: Vec<Mat3>,
    frames: Vec<Mat3>,
    rhs: Mat<f64>,
    /// `3#V x 1`: step two's result, interleaved.
    next: Mat<f64>,
    /// The last outer iterations' `x` and `T(x)` (interleaved, `3 #V`) and the secant
    /// contraction factors `|T(x_k) - T(x_{k-1})| / |x_k - x_{k-1}|` of the last few.
    previous_x: Vec<f64>,
    previous_image: Vec<f64>,
    secants: Vec<f64>,
    /// The last outer iteration's `|T(x) - x|` over the diagonal (infinite before the first).
    last_residual: f64,
    solution: Mat<f64>,
    flat_x: Vec<f64>,
    flat_g: Vec<f64>,
    flat_next: Vec<f64>,
    timings: SolveTimings,
    /// The solve the last `solve` took from `scale_aware` instead of computing it.
    reused: Option<ReusedSolve>,
    /// Where `scale_aware` keeps its solves and `scale_aware_ora` looks for them: this instance's
    /// own, or one it shares with others ([`ScaleAware::sharing`]).
    memo: SolveMemo,
    /// Whether a solve ran since `precompute` (`later_start`).
    solved_once: bool,
}

impl ScaleAware {
    /// A method registered as `name` with the given parameters and a memo of its own (it takes no
    /// solve it did not compute); call [`DeformationMethod::precompute`] next.
    pub fn new(name: &'static str, params: ScaleAwareParams) -> Result<Self, MethodError> {
        Self::sharing(name, params, SolveMemo::default())
    }

    /// [`ScaleAware::new`], keeping and looking up its solves in `memo`, which other instances may
    /// share: a `scale_aware_ora` instance takes the solve of a `scale_aware` one with the same memo
    /// where their inputs are identical ([`solve_memo`]).
    pub fn sharing(
        name: &'static str,
        params: ScaleAwareParams,
        memo: SolveMemo,
    ) -> Result<Self, MethodError> {
        // Before the initialization is built from `initialization_omega`, so a bad value is named
        // by its own key.
        params.validate(name)?;
        let initialization = LaplacianEditing::new(LaplacianParams {
            omega: params.initialization_omega,
            weights: params.weights,
            max_iterations: 1,
            tolerance: 0.0,
            // From the rest shape any frame gives delta_bar (R = I); from an earlier edit's result
            // (incremental scenarios) the frame matters, and its baselines were measured with this one.
            delta_frame: DeltaFrame::OneRing,
            ..LaplacianParams::default()
        })?;
        Ok(Self {
            name,
            params,
            initialization,
            rest: None,
            recovery: None,
            bound: None,
            current: Vec::new(),
            normals: Vec::new(),
            rotations: Vec::new(),
            frames: Vec::new(),
            rhs: Mat::zeros(0, 1),
            next: Mat::zeros(0, 1),
            previous_x: Vec::new(),
            previous_image: Vec::new(),
            secants: Vec::new(),
            last_residual: f64::INFINITY,
            solution: Mat::zeros(0, 3),
            flat_x: Vec::new(),
            flat_g: Vec::new(),
            flat_next: Vec::new(),
            timings: SolveTimings::default(),
            reused: None,
            memo,
            solved_once: false,
        })
    }

    /// Section 5.2: linear Laplacian editing from the current shape (iteration 0 of `laplacian`).
    fn initialize(&mut self, targets: &HandleTargets) -> Result<(), MethodError> {
        self.initialization.set_current_shape(&self.current);
        self.initialization.solve(targets, &mut NoObserver)?;
        self.current = self.initialization.positions();
        Ok(())
    }

    /// Step one (section 4.2): the normals of the current shape, moved towards the rest edge angles.
    fn update_normals(&mut self) {
        let rest = self.rest.as_ref().expect("precomputed");
        face_normals_into(&self.current, &rest.triangles, &mut self.normals);
        let update = rest.pyramids.update_normals(
            &mut self.normals,
            &mut self.rotations,
            &mut self.frames,
            self.params.normal_sweeps,
            self.params.normal_tolerance,
        );
        self.timings.normal_iterations += update.iterations;
    }

    /// Step two (section 4.3, eq 12): the positions for the current normals into `self.solution`
    /// (`#V x 3`).
    fn recover_vertices(&mut self, targets: &HandleTargets) -> Result<(), MethodError> {
        let rest = self.rest.as_ref().expect("precomputed");
        let bound = self.bound.as_ref().expect("bound");
        self.rhs.fill(0.0);
        let lambda = self.params.constraint_weight;
        for (v, target) in bound.handles.constrained().zip(targets.positions()) {
            for c in 0..3 {
                self.rhs[(3 * v as usize + c, 0)] = lambda * target[c];
            }
        }
        for (i, p) in self.current.iter().enumerate() {
            self.flat_x[3 * i..3 * i + 3].copy_from_slice(p);
        }
        self.recovery.as_mut().expect("precomputed").step(
            &rest.equations,
            &self.normals,
            &bound.constraint_diagonal,
            self.rhs.as_ref(),
            &self.flat_x,
            // Steps below EXACT_TAIL x tolerance are exact: the stopping rule's secants need `T`
            // itself, and a lagged step's error (5% of it) then exceeds their differences.
            if self.last_residual < EXACT_TAIL * self.params.tolerance {
                0.0
            } else {
                self.params.refactor_turn
            },
            &mut self.next,
            &mut self.timings.recovery,
        )?;
        for i in 0..self.current.len() {
            for c in 0..3 {
                self.solution[(i, c)] = self.next[(3 * i + c, 0)];
            }
        }
        Ok(())
    }

    /// The largest secant contraction factor of the plain map over the last
    /// [`crate::method::CONTRACTION_WINDOW`] outer iterations, with this one's `x` (`current`)
    /// and `T(x)` (`solution`); 0 before the second. What an accelerated iteration's stopping rule
    /// needs ([`DistanceBound::contraction_at_least`]).
    fn secant_contraction(&mut self) -> f64 {
        let n = self.current.len();
        let (mut dx, mut dg): (f64, f64) = (0.0, 0.0);
        let fresh = self.previous_x.len() != 3 * n;
        if fresh {
            self.previous_x.resize(3 * n, 0.0);
            self.previous_image.resize(3 * n, 0.0);
        }
        for i in 0..n {
            let (mut ex, mut eg) = (0.0, 0.0);
            for c in 0..3 {
                let (x, g) = (self.current[i][c], self.solution[(i, c)]);
                ex += (x - self.previous_x[3 * i + c]).powi(2);
                eg += (g - self.previous_image[3 * i + c]).powi(2);
                self.previous_x[3 * i + c] = x;
                self.previous_image[3 * i + c] = g;
            }
            dx = dx.max(ex);
            dg = dg.max(eg);
        }
        if fresh || !(dx > 0.0) {
            return 0.0;
        }
        if self.secants.len() == crate::method::CONTRACTION_WINDOW {
            self.secants.remove(0);
        }
        self.secants.push((dg / dx).sqrt());
        self.secants.iter().copied().fold(0.0, f64::max)
    }

    /// Replace `self.solution` (`T(x)`) by the Anderson-accelerated next iterate; `self.flat_x`
    /// holds `x` (interleaved), as step two left it.
    fn accelerate(&mut self, anderson: &mut AndersonAcceleration) {
        let n = self.current.len();
        for i in 0..n {
            for c in 0..3 {
                self.flat_g[3 * i + c] = self.solution[(i, c)];
            }
        }
        anderson.next(&self.flat_x, &self.flat_g, &mut self.flat_next);
        for i in 0..n {
            for c in 0..3 {
                self.solution[(i, c)] = self.flat_next[3 * i + c];
            }
        }
    }

    /// Algorithm 1 from the current shape: the initialization (iteration 0), then the outer
    /// iterations until converged or `max_iterations`.
    fn algorithm_one(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        self.timings = SolveTimings::default();
        self.previous_x.clear();
        self.last_residual = f64::INFINITY;
        self.previous_image.clear();
        self.secants.clear();
        let diagonal = self.rest.as_ref().expect("bound implies precomputed").bbox_diagonal;

        // Iteration 0: the initialization.
        let start = Instant::now();
        let before = self.current.clone();
        let warm = self.params.later_start == LaterStart::PreviousResult && self.solved_once;
        if !warm {
            self.initialize(targets)?;
        }
        self.solved_once = true;
        self.timings.initialization = start.elapsed().as_secs_f64();
        let step = max_displacement(&before, &self.current) / diagonal;
        let report = IterationReport { iteration: 0, step, seconds: self.timings.initialization };
        let current: &[[f64; 3]] = &self.current;
        let summary = SolveSummary {
            iterations: 1,
            converged: false,
            final_step: step,
            distance: f64::INFINITY,
            convergence_unknown: false,
        };
        if observer.on_iteration(&report, Some(&|| current.to_vec())) == ControlFlow::Break(()) {
            return Ok(summary);
        }

        // Algorithm 1: x <- T(x), T = step two after step one, optionally Anderson-accelerated.
        let mut anderson = AndersonAcceleration::new(self.params.anderson_depth, 3 * self.current.len());
        let iterations =
            Iterations { first: 1, count: self.params.max_iterations, tolerance: self.params.tolerance };
        let iterate = |m: &mut Self, iteration: usize, rule: &DistanceBound| -> Result<f64, MethodError> {
            let start = Instant::now();
            m.update_normals();
            m.timings.step_one_normals += start.elapsed().as_secs_f64();
            m.recover_vertices(targets)?;
            m.timings.outer_iterations += 1;
            // The fixed-point residual |T(x) - x| is the plain iteration's step.
            let residual = max_displacement_to(&m.current, m.solution.as_ref()) / diagonal;
            m.last_residual = residual;
            if m.params.anderson_depth > 0 {
                rule.contraction_at_least(m.secant_contraction());
            }
            if !rule.is_met_by(residual) && m.params.anderson_depth > 0 {
                m.accelerate(&mut anderson);
            }
            move_to(m.name, iteration, &mut m.current, m.solution.as_ref())?;
            Ok(residual)
        };
        run_iterations(iterations, self, iterate, |m| m.current.clone(), observer)
    }

    /// Stand in for Algorithm 1 with `taken`, an identical solve of `scale_aware`: its result, its
    /// phase times and its iteration reports (to `observer`, with the iterates that solve's observer
    /// asked for, and the last).
    ///
    /// The initialization is run again (one Laplacian solve, ~1% of Algorithm 1): the SVD warm
    /// starts it leaves, like step one's `frames` taken here, carry into the next edit step, which
    /// then gives the same bits as after a computed solve.
    fn take(
        &mut self,
        taken: &MemoizedSolve,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        self.initialize(targets)?;
        self.solved_once = true;
        self.current.clone_from(&taken.positions);
        self.frames.clone_from(&taken.frames);
        self.timings = taken.timings;
        self.reused =
            Some(ReusedSolve { from: crate::keys::method_name::SCALE_AWARE, seconds: taken.seconds });
        let last = taken.reports.len().saturating_sub(1);
        for (i, (report, iterate)) in taken.reports.iter().enumerate() {
            let iterate = match iterate {
                Some(iterate) => Some(iterate),
                None if i == last => Some(&taken.positions),
                None => None,
            };
            let shape = iterate.map(|iterate| move || iterate.clone());
            let shape = shape.as_ref().map(|s| s as &dyn Fn() -> Vec<[f64; 3]>);
            if observer.on_iteration(report, shape) == ControlFlow::Break(()) {
                return Ok(SolveSummary {
                    iterations: report.iteration + 1,
                    converged: false,
                    ..taken.summary
                });
            }
        }
        Ok(taken.summary)
    }

    /// Section 5.3: rescale every triangle to its rest area and stitch (eq 13-15).
    fn approximate_rigidity(&mut self, targets: &HandleTargets) -> Result<(), MethodError> {
        let rest = self.rest.as_ref().expect("precomputed");
        let bound = self.bound.as_mut().expect("bound");
        let stitching = bound.stitching.as_mut().expect("built at bind for the ORA variant");
        let rescaled = rescaled_triangles(&self.current, &rest.triangles, &rest.rest_areas);
        let stitched = stitching.stitch(&rescaled, targets.positions());
        for i in 0..self.current.len() {
            self.solution[(i, 0)] = stitched[(i, 0)];
            self.solution[(i, 1)] = stitched[(i, 1)];
            self.solution[(i, 2)] = stitched[(i, 2)];
        }
        Ok(())
    }
}

/// Largest distance between a row of `current` (`#V x 3`) and the same row of `next` (`#V x 3`).
fn max_displacement_to(current: &[[f64; 3]], next: faer::MatRef<'_, f64>) -> f64 {
    let mut d2: f64 = 0.0;
    for (i, p) in current.iter().enumerate() {
        let d = [next[(i, 0)] - p[0], next[(i, 1)] - p[1], next[(i, 2)] - p[2]];
        d2 = d2.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    d2.sqrt()
}

impl DeformationMethod for ScaleAware {
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

    fn precompute(&mut self, rest_mesh: &TriMesh) -> Result<(), MethodError> {
        let topology = Topology::new(rest_mesh)?;
        let (positions, triangles) = (rest_mesh.positions(), rest_mesh.triangles());
        let n = rest_mesh.n_vertices();
        let measures = ScaleInvariantMeasures::new(positions, triangles, &topology);
        let pyramids =
            NormalPyramids::new(positions, triangles, &measures.normals, self.params.normal_weights);
        let equations = ScaleAwareEquations::new(n, triangles, measures);
        self.recovery = Some(VertexRecovery::new(&equations)?);
        self.initialization.precompute(rest_mesh)?;
        // Everything of the parameters but the stitching enters Algorithm 1 (their `Debug` text:
        // floats print round-trip exact, so different values give different text).
        let algorithm_one = ScaleAwareParams { optimal_rigidity: false, ..self.params.clone() };
        let fingerprint = FingerprintBuilder::new()
            .positions(positions)
            .value(triangles)
            .value(&format!("{algorithm_one:?}"))
            .finish();
        self.rest = Some(RestState {
            fingerprint,
            triangles: triangles.to_vec(),
            equations,
            pyramids,
            rest_areas: face_areas(positions, triangles),
            bbox_diagonal: rest_mesh.bbox_diagonal(),
        });
        self.current = positions.to_vec();
        self.normals = vec![[0.0; 3]; triangles.len()];
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        self.rotations = vec![identity; n];
        self.frames = vec![identity; n];
        self.rhs = Mat::zeros(3 * n, 1);
        self.next = Mat::zeros(3 * n, 1);
        self.solution = Mat::zeros(n, 3);
        self.flat_x = vec![0.0; 3 * n];
        self.flat_g = vec![0.0; 3 * n];
        self.flat_next = vec![0.0; 3 * n];
        self.bound = None;
        self.solved_once = false;
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        let rest = require_phase(self.rest.as_ref(), self.name, Phase::BindHandles)?;
        handles.check_mesh_size(self.current.len())?;
        if handles.n_constrained() < 3 {
            return Err(MethodError::Handles(format!(
                "`{}` needs at least three constrained vertices (section 4); the set has {}",
                self.name,
                handles.n_constrained()
            )));
        }
        self.initialization.bind_handles(handles)?;
        let lambda = self.params.constraint_weight;
        let mut constraint_diagonal = vec![0.0; 3 * self.current.len()];
        for v in handles.constrained() {
            constraint_diagonal[3 * v as usize..3 * v as usize + 3].fill(lambda);
        }
        let stitching = if self.params.optimal_rigidity {
            let constrained: Vec<u32> = handles.constrained().collect();
            Some(Stitching::new(self.current.len(), &rest.triangles, &constrained, lambda)?)
        } else {
            None
        };
        self.bound = Some(BoundState { handles: handles.clone(), constraint_diagonal, stitching });
        if let Some(recovery) = self.recovery.as_mut() {
            recovery.invalidate();
        }
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let bound = require_phase(self.bound.as_ref(), self.name, Phase::Solve)?;
        targets.check_for(&bound.handles)?;
        let start = Instant::now();
        self.reused = None;
        let rest = self.rest.as_ref().expect("bound implies precomputed");
        let key = FingerprintBuilder::new()
            .value(&rest.fingerprint)
            .value(&bound.handles.constrained().collect::<Vec<u32>>())
            .positions(targets.positions())
            .positions(&self.current)
            .value(&rayon::current_num_threads())
            .finish();
        let taken = if self.params.optimal_rigidity { self.memo.find(key) } else { None };
        let summary = match taken {
            Some(taken) => self.take(&taken, targets, observer)?,
            None => {
                let mut recording =
                    RecordingObserver { inner: observer, reports: Vec::new(), stopped: false };
                let summary = self.algorithm_one(targets, &mut recording)?;
                if !self.params.optimal_rigidity && !recording.stopped {
                    let solve = MemoizedSolve {
                        positions: self.current.clone(),
                        summary,
                        reports: recording.reports,
                        timings: self.timings,
                        frames: self.frames.clone(),
                        seconds: start.elapsed().as_secs_f64(),
                    };
                    self.memo.store(key, solve);
                }
                summary
            }
        };
        if !self.params.optimal_rigidity {
            return Ok(summary);
        }
        let diagonal = self.rest.as_ref().expect("bound implies precomputed").bbox_diagonal;
        // The stitching step is no convergence test: a tolerance of infinity never fails it.
        let stitching = Iterations { first: summary.iterations, count: 1, tolerance: f64::INFINITY };
        let stitch = |m: &mut Self, iteration: usize, _: &DistanceBound| -> Result<f64, MethodError> {
            let start = Instant::now();
            m.approximate_rigidity(targets)?;
            let step = move_to(m.name, iteration, &mut m.current, m.solution.as_ref())? / diagonal;
            m.timings.stitching = start.elapsed().as_secs_f64();
            Ok(step)
        };
        let done = run_iterations(stitching, self, stitch, |m| m.current.clone(), observer)?;
        Ok(SolveSummary { iterations: done.iterations, converged: summary.converged, ..summary })
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }

    fn reused_solve(&self) -> Option<ReusedSolve> {
        self.reused.clone()
    }

    fn phase_timings(&self) -> Vec<(String, f64)> {
        let t = &self.timings;
        let mut phases = vec![
            (crate::keys::phase::INITIALIZATION_LAPLACIAN, t.initialization),
            (crate::keys::phase::STEP_ONE_NORMALS, t.step_one_normals),
            (crate::keys::phase::STEP_TWO_ASSEMBLY, t.recovery.assembly_s),
            (crate::keys::phase::STEP_TWO_REFACTORIZATION, t.recovery.refactorization_s),
            (crate::keys::phase::STEP_TWO_BACK_SUBSTITUTION, t.recovery.back_substitution_s),
        ];
        if self.params.optimal_rigidity {
            phases.push((crate::keys::phase::ORA_STITCHING, t.stitching));
        }
        crate::method::owned_names(phases)
    }

    fn model_statistics(&self) -> Vec<(String, f64)> {
        crate::method::owned_names(vec![
            (crate::keys::statistic::OUTER_ITERATIONS, self.timings.outer_iterations as f64),
            (crate::keys::statistic::NORMAL_ITERATIONS, self.timings.normal_iterations as f64),
            (crate::keys::statistic::REFACTORIZATIONS, self.timings.recovery.refactorizations as f64),
            (crate::keys::statistic::LAGGED_STEPS, self.timings.recovery.lagged_steps as f64),
            (
                crate::keys::statistic::LAGGED_BACK_SUBSTITUTIONS,
                self.timings.recovery.lagged_back_substitutions as f64,
            ),
        ])
    }
}
