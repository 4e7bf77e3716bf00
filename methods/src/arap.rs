//! `arap`: As-Rigid-As-Possible surface modeling (Sorkine & Alexa 2007), the suite's nonlinear reference.
//!
//! Energy (SA07 eq 3, "spokes"): `E(X) = sum_i sum_{j in N(i)} w_ij |(x_i - x_j) - R_i (p_i - p_j)|^2`
//! with cotangent weights `w_ij = (cot a_ij + cot b_ij) / 2` (libigl's `cotmatrix` entries; see
//! "Weights" below for the choice of triangulation), handle
//! vertices as hard constraints, alternating
//! - local step: `R_i` = closest rotation to `sum_j w_ij (x_i - x_j)(p_i - p_j)^T` (SA07 eq 5–6);
//! - global step: `-L X = b`, `b_i = sum_j w_ij / 2 (R_i + R_j)(p_i - p_j)` (SA07 eq 8–9), constrained
//!   rows eliminated.
//!
//! Weights (`weights`, [`LaplacianWeights`]; default `intrinsic_delaunay`). The energy's spokes are
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
//!   `e_ii = 0` and drops out.
//!
//! The initial guess is the current shape (the rest shape after `precompute`), as libigl's `arap_solve`
//! with `U = V`, so the two can be compared iteration for iteration.
//!
//! Phases: `precompute` builds the weights and the symbolic factorization of `-L`'s pattern;
//! `bind_handles` does the numeric factorization of `-L` with the constrained rows and columns replaced
//! by identity (same pattern, so the symbolic analysis is reused for any handle set); each iteration is
//! one local step, one right-hand side assembly and one back-substitution of 3 columns.

use std::time::Instant;

use faer::sparse::SparseColMat;
use faer::Mat;
use meshes::TriMesh;
use rayon::prelude::*;
use serde::Deserialize;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets, FREE};
use crate::linalg::sparse_cholesky::SparseCholesky;
use crate::method::{finish_iteration, DeformationMethod, IterationObserver, SolveSummary};
use crate::operators::{laplacian, LaplacianWeights};
use crate::rotation_fit::{closest_rotation_warm, Mat3};

/// Parameters of [`Arap`] (configs/methods.toml, section `[arap]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArapParams {
    /// Iteration limit per solve.
    pub max_iterations: usize,
    /// Converged when the largest vertex step falls below `tolerance x bbox diagonal`.
    pub tolerance: f64,
    /// Spokes, weights and global-step matrix (see the module documentation, "Weights").
    pub weights: LaplacianWeights,
}

impl Default for ArapParams {
    fn default() -> Self {
        Self { max_iterations: 1000, tolerance: 1e-5, weights: LaplacianWeights::default() }
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
    current: Vec<[f64; 3]>,
    rotations: Vec<Mat3>,
    /// Right singular vectors of each vertex's covariance, the warm start of the next local step.
    singular_frames: Vec<Mat3>,
    rhs_rows: Vec<[f64; 3]>,
    rhs: Mat<f64>,
}

impl Arap {
    /// A method with the given parameters; call [`DeformationMethod::precompute`] next.
    pub fn new(params: ArapParams) -> Result<Self, MethodError> {
        if params.max_iterations == 0 || !(params.tolerance >= 0.0) {
            return Err(MethodError::Parameters {
                method: "arap",
                message: "max_iterations must be >= 1 and tolerance >= 0".into(),
            });
        }
        Ok(Self {
            params,
            rest: Vec::new(),
            bbox_diagonal: 0.0,
            spokes: None,
            stiffness: None,
            cholesky: None,
            handles: None,
            current: Vec::new(),
            rotations: Vec::new(),
            singular_frames: Vec::new(),
            rhs_rows: Vec::new(),
            rhs: Mat::zeros(0, 3),
        })
    }

    /// The rotations `R_i` of the last local step (`#V`, row-major 3x3).
    pub fn rotations(&self) -> &[Mat3] {
        &self.rotations
    }

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
                *r = closest_rotation_warm(&cov, frame);
            },
        );
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
    fn name(&self) -> &'static str {
        "arap"
    }

    fn precompute(&mut self, rest: &TriMesh) -> Result<(), MethodError> {
        meshes::Topology::new(rest)?;
        let laplacian = laplacian(self.params.weights, rest.positions(), rest.triangles())?;
        let n = rest.n_vertices();
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
                    rest_edges.push(meshes::vector::sub(rest.positions()[i], rest.positions()[j]));
                }
            }
            offsets.push(neighbors.len());
        }
        let stiffness = {
            let mut k = laplacian;
            k.val_mut().iter_mut().for_each(|v| *v = -*v);
            k
        };
        self.cholesky = Some(SparseCholesky::analyze(stiffness.as_ref())?);
        self.stiffness = Some(stiffness);
        self.spokes = Some(Spokes { offsets, neighbors, weights, rest_edges });
        self.rest = rest.positions().to_vec();
        self.bbox_diagonal = rest.bbox_diagonal();
        self.current = self.rest.clone();
        self.rotations = vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; n];
        self.singular_frames = self.rotations.clone();
        self.rhs_rows = vec![[0.0; 3]; n];
        self.rhs = Mat::zeros(n, 3);
        self.handles = None;
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        let (Some(stiffness), Some(cholesky)) = (&self.stiffness, &mut self.cholesky) else {
            return Err(MethodError::Phase { method: "arap", phase: "bind_handles", missing: "precompute" });
        };
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
        self.handles = Some(handles.clone());
        Ok(())
    }

    fn solve(
        &mut self,
        targets: &HandleTargets,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let (Some(handles), Some(spokes), Some(cholesky)) = (&self.handles, &self.spokes, &mut self.cholesky)
        else {
            return Err(MethodError::Phase { method: "arap", phase: "solve", missing: "bind_handles" });
        };
        for (v, t) in handles.constrained().zip(targets.positions()) {
            self.current[v as usize] = *t;
        }
        let region_of = handles.region_of();
        let mut summary = SolveSummary { iterations: 0, converged: false, final_step: f64::INFINITY };
        for iteration in 0..self.params.max_iterations {
            let start = Instant::now();
            Self::local_step(spokes, &self.current, &mut self.rotations, &mut self.singular_frames);
            Self::assemble_rhs(
                spokes,
                &self.rotations,
                region_of,
                &self.current,
                &mut self.rhs_rows,
                &mut self.rhs,
            );
            cholesky.solve_in_place(self.rhs.as_mut());
            let (done, stop) = finish_iteration(
                "arap",
                iteration,
                start,
                &mut self.current,
                self.rhs.as_ref(),
                self.bbox_diagonal,
                self.params.tolerance,
                observer,
            )?;
            summary = done;
            if stop {
                break;
            }
        }
        Ok(summary)
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.current.clone()
    }
}
