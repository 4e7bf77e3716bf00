//! `laplacian`: unreduced iterative Laplacian editing, the framework that Au et al. 2007 (section 3,
//! eq 1–3) and HIRM (section 4.4, eq 10) reduce.
//!
//! Minimize `|L X - delta(X)|^2 + omega^2 |Phi X - H|^2` (eq 1–2) by the inexact Gauss–Newton update
//! `X^{t+1} = (A^T A)^{-1} A^T b(X^t)` (eq 3), `A = [L; omega Phi]`, `A^T A = L^T L + omega^2 Phi^T Phi`
//! factored once per handle set.
//!
//! Decisions the paper leaves open (see also the tests):
//! - `L` is the cotangent Laplacian without mass normalization (libigl `cotmatrix`); eq 1 is
//!   invariant to the sign of `L`.
//! - `delta(X)` update: the rest Laplacian coordinates `delta_i = (L X_rest)_i` are stored in a local
//!   frame per vertex (area-weighted vertex normal `n_i`; tangent `t_i` = the edge to the lowest-index
//!   neighbour projected onto the tangent plane; `b_i = n_i x t_i`) and re-expressed in the frame of
//!   the current surface each iteration — the rotation-invariant encoding of Lipman et al. 2005, used
//!   by the iterative frameworks Au 2007 cites [Au et al. 2006; Huang et al. 2006]. The rest shape is a
//!   fixed point.
//! - `X^0` is the current shape (eq 3: "the current edited vertex positions"); from the rest shape
//!   iteration 0 therefore solves with the un-rotated `delta`, i.e. linear Laplacian editing
//!   (Lipman et al. 2004 / Sorkine et al. 2004 without their implicit transform).
//! - Phases: `precompute` builds `L`, `L^T L` and its symbolic factorization; `bind_handles` adds
//!   `omega^2 Phi^T Phi` (a diagonal, so the pattern and the symbolic factorization are reused) and
//!   factors numerically.

use std::time::Instant;

use faer::sparse::linalg::matmul::{sparse_dense_matmul, sparse_sparse_matmul};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Mat, Par};
use meshes::vector::{cross, dot, normalize_or_zero, scale, sub};
use meshes::{Topology, TriMesh};
use serde::Deserialize;

use crate::error::MethodError;
use crate::handles::{HandleSet, HandleTargets};
use crate::method::{finish_iteration, DeformationMethod, IterationObserver, SolveSummary};
use crate::operators::cotan_laplacian;
use crate::sparse_cholesky::{add_to_diagonal, SparseCholesky};

/// Parameters of [`LaplacianEditing`] (configs/methods.toml, section `[laplacian]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LaplacianParams {
    /// Soft-constraint weight `omega` of eq 2 (the paper: 1000).
    pub omega: f64,
    /// Iteration limit per solve.
    pub max_iterations: usize,
    /// Converged when the largest vertex step falls below `tolerance x bbox diagonal`.
    pub tolerance: f64,
}

impl Default for LaplacianParams {
    fn default() -> Self {
        Self { omega: 1000.0, max_iterations: 2000, tolerance: 1e-5 }
    }
}

/// Rest-state data: operator, rest Laplacian coordinates in local frames.
struct RestState {
    triangles: Vec<[u32; 3]>,
    laplacian: SparseColMat<usize, f64>,
    normal_matrix: SparseColMat<usize, f64>,
    /// Per vertex, the neighbour whose edge defines the tangent `t_i`.
    frame_neighbor: Vec<u32>,
    /// `delta_i` of the rest shape as `(n, t, b)` coefficients.
    frame_coefficients: Vec<[f64; 3]>,
    bbox_diagonal: f64,
}

/// Iterative Laplacian editing; see the module documentation.
pub struct LaplacianEditing {
    params: LaplacianParams,
    rest: Option<RestState>,
    cholesky: Option<SparseCholesky>,
    handles: Option<HandleSet>,
    current: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    delta: Mat<f64>,
    rhs: Mat<f64>,
}

impl LaplacianEditing {
    /// A method with the given parameters; call [`DeformationMethod::precompute`] next.
    pub fn new(params: LaplacianParams) -> Result<Self, MethodError> {
        if !(params.omega > 0.0) || params.max_iterations == 0 || !(params.tolerance >= 0.0) {
            return Err(MethodError::Parameters {
                method: "laplacian",
                message: "omega must be > 0, max_iterations >= 1, tolerance >= 0".into(),
            });
        }
        Ok(Self {
            params,
            rest: None,
            cholesky: None,
            handles: None,
            current: Vec::new(),
            normals: Vec::new(),
            delta: Mat::zeros(0, 3),
            rhs: Mat::zeros(0, 3),
        })
    }

    /// The current Laplacian coordinates `delta(X)` (`#V x 3`) into `self.delta`.
    fn update_delta(&mut self) {
        let rest = self.rest.as_ref().expect("precomputed");
        meshes::geometry::vertex_normals_into(&self.current, &rest.triangles, &mut self.normals);
        for i in 0..self.current.len() {
            let (n, t, b) = local_frame(&self.current, &self.normals, rest.frame_neighbor[i], i);
            let c = rest.frame_coefficients[i];
            for a in 0..3 {
                self.delta[(i, a)] = c[0] * n[a] + c[1] * t[a] + c[2] * b[a];
            }
        }
    }
}

/// Orthonormal frame `(n, t, b)` at vertex `i`: the vertex normal, the edge to `neighbor` projected onto
/// the tangent plane, and their cross product. Degenerate frames come out as zero vectors.
fn local_frame(
    positions: &[[f64; 3]],
    normals: &[[f64; 3]],
    neighbor: u32,
    i: usize,
) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let n = normals[i];
    let e = sub(positions[neighbor as usize], positions[i]);
    let t = normalize_or_zero(sub(e, scale(n, dot(e, n))));
    (n, t, cross(n, t))
}

impl DeformationMethod for LaplacianEditing {
    fn name(&self) -> &'static str {
        "laplacian"
    }

    fn precompute(&mut self, rest_mesh: &TriMesh) -> Result<(), MethodError> {
        let topology = Topology::new(rest_mesh)?;
        let positions = rest_mesh.positions();
        let n = rest_mesh.n_vertices();
        let laplacian = cotan_laplacian(positions, rest_mesh.triangles());
        // L is symmetric, so L^T L = L L. Rebuilt from triplets to get sorted columns.
        let product = sparse_sparse_matmul(laplacian.as_ref(), laplacian.as_ref(), 1.0, Par::Seq)
            .map_err(|e| MethodError::Solver(crate::sparse_cholesky::SolverError::Faer(format!("{e:?}"))))?;
        let normal_matrix = sorted(&product);
        self.cholesky = Some(SparseCholesky::analyze(normal_matrix.as_ref())?);

        let rest_positions = Mat::from_fn(n, 3, |i, a| positions[i][a]);
        let mut rest_delta = Mat::zeros(n, 3);
        sparse_dense_matmul(
            rest_delta.as_mut(),
            Accum::Replace,
            laplacian.as_ref(),
            rest_positions.as_ref(),
            1.0,
            Par::Seq,
        );
        let normals = meshes::geometry::vertex_normals(positions, rest_mesh.triangles());
        let mut frame_neighbor = Vec::with_capacity(n);
        let mut frame_coefficients = Vec::with_capacity(n);
        for i in 0..n {
            // Isolated vertices have no neighbour; they keep a zero delta.
            let neighbor = topology.one_ring(i).first().copied().unwrap_or(i as u32);
            let (nn, t, b) = local_frame(positions, &normals, neighbor, i);
            let d = [rest_delta[(i, 0)], rest_delta[(i, 1)], rest_delta[(i, 2)]];
            frame_neighbor.push(neighbor);
            frame_coefficients.push([dot(d, nn), dot(d, t), dot(d, b)]);
        }
        self.rest = Some(RestState {
            triangles: rest_mesh.triangles().to_vec(),
            laplacian,
            normal_matrix,
            frame_neighbor,
            frame_coefficients,
            bbox_diagonal: rest_mesh.bbox_diagonal(),
        });
        self.current = positions.to_vec();
        self.normals = vec![[0.0; 3]; n];
        self.delta = Mat::zeros(n, 3);
        self.rhs = Mat::zeros(n, 3);
        self.handles = None;
        Ok(())
    }

    fn bind_handles(&mut self, handles: &HandleSet) -> Result<(), MethodError> {
        let (Some(rest), Some(cholesky)) = (&self.rest, &mut self.cholesky) else {
            return Err(MethodError::Phase {
                method: "laplacian",
                phase: "bind_handles",
                missing: "precompute",
            });
        };
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
        if self.handles.is_none() {
            return Err(MethodError::Phase { method: "laplacian", phase: "solve", missing: "bind_handles" });
        }
        let w2 = self.params.omega * self.params.omega;
        let mut summary = SolveSummary { iterations: 0, converged: false, final_step: f64::INFINITY };
        for iteration in 0..self.params.max_iterations {
            let start = Instant::now();
            self.update_delta();
            let rest = self.rest.as_ref().expect("bound implies precomputed");
            let handles = self.handles.as_ref().expect("checked above");
            sparse_dense_matmul(
                self.rhs.as_mut(),
                Accum::Replace,
                rest.laplacian.as_ref(),
                self.delta.as_ref(),
                1.0,
                Par::Seq,
            );
            for (v, t) in handles.constrained().zip(targets.positions()) {
                for a in 0..3 {
                    self.rhs[(v as usize, a)] += w2 * t[a];
                }
            }
            self.cholesky.as_mut().expect("bound").solve_in_place(self.rhs.as_mut());
            let (done, stop) = finish_iteration(
                "laplacian",
                iteration,
                start,
                &mut self.current,
                self.rhs.as_ref(),
                rest.bbox_diagonal,
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
