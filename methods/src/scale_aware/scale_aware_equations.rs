//! Section 3.2: the scale-aware equations `G(Theta, N) V = 0` (eq 1-3) and the normal equations of
//! step two (eq 12), `(G^T G + lambda C) V = lambda C V*`.
//!
//! Unknowns are vertex-interleaved, `V = [x_0, y_0, z_0, x_1, ...]` (`3 #V`), because the rotations
//! `R_i` couple the coordinates. `G^T G` has a full 3x3 block for every pair of vertices that share a
//! face, so its pattern depends on the connectivity only: it is built once and only the values
//! change when the normals do (the symbolic factorization is reused across outer iterations).

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use meshes::vector::rotation_matrix;

use super::scale_invariant_measures::ScaleInvariantMeasures;
use crate::rotation_fit::Mat3;

/// The scale-aware equations of one mesh: its measures and the `3#V x 3#V` pattern of `G^T G`.
pub struct ScaleAwareEquations {
    triangles: Vec<[u32; 3]>,
    measures: ScaleInvariantMeasures,
    pattern: SymbolicSparseColMat<usize>,
    /// Per face, per local block `(a, b)` (index `3a + b`) and column coordinate `c`: the position
    /// in the value array of entry `(3 t[a], 3 t[b] + c)`; rows `3 t[a] + 1, + 2` follow it.
    block_slots: Vec<[[usize; 3]; 9]>,
    /// Position of each diagonal entry `(i, i)`, `3 #V`.
    diagonal_slots: Vec<usize>,
}

impl ScaleAwareEquations {
    /// Equations for `#F x 3` `triangles` on `n_vertices` vertices with the rest `measures`.
    pub fn new(n_vertices: usize, triangles: &[[u32; 3]], measures: ScaleInvariantMeasures) -> Self {
        let mut neighbours: Vec<Vec<u32>> = (0..n_vertices as u32).map(|i| vec![i]).collect();
        for t in triangles {
            for a in 0..3 {
                for b in 0..3 {
                    if a != b {
                        neighbours[t[a] as usize].push(t[b]);
                    }
                }
            }
        }
        for list in &mut neighbours {
            list.sort_unstable();
            list.dedup();
        }
        let n = 3 * n_vertices;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for list in &neighbours {
            for _c in 0..3 {
                row_idx.extend(
                    list.iter().flat_map(|&i| [3 * i as usize, 3 * i as usize + 1, 3 * i as usize + 2]),
                );
                col_ptr.push(row_idx.len());
            }
        }
        // Position of row 3i in column 3j + c.
        let slot = |i: u32, j: u32, c: usize| {
            let list = &neighbours[j as usize];
            let k = list.binary_search(&i).expect("i and j share a face");
            col_ptr[3 * j as usize + c] + 3 * k
        };
        let block_slots = triangles
            .iter()
            .map(|t| std::array::from_fn(|ab| std::array::from_fn(|c| slot(t[ab / 3], t[ab % 3], c))))
            .collect();
        let diagonal_slots = (0..n_vertices as u32)
            .flat_map(|j| (0..3).map(move |c| (j, c)))
            .map(|(j, c)| slot(j, j, c) + c)
            .collect();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Self { triangles: triangles.to_vec(), measures, pattern, block_slots, diagonal_slots }
    }

    /// The rest measures the equations were built from.
    pub fn measures(&self) -> &ScaleInvariantMeasures {
        &self.measures
    }

    /// A `3#V x 3#V` matrix with the pattern of `G^T G` and zero values, for
    /// [`ScaleAwareEquations::assemble_normal_matrix`] to fill.
    pub fn normal_matrix_pattern(&self) -> SparseColMat<usize, f64> {
        SparseColMat::new(self.pattern.clone(), vec![0.0; self.pattern.row_idx().len()])
    }

    /// The values of `G(Theta, normals)^T G(Theta, normals) + diag(constraint_diagonal)` into
    /// `values` (those of [`ScaleAwareEquations::normal_matrix_pattern`]); `normals` is `#F x 3`
    /// (unit), `constraint_diagonal` is `3 #V` (`lambda` on the coordinates of constrained vertices,
    /// eq 12).
    pub fn assemble_normal_matrix(
        &self,
        normals: &[[f64; 3]],
        constraint_diagonal: &[f64],
        values: &mut [f64],
    ) {
        values.fill(0.0);
        for (f, slots) in self.block_slots.iter().enumerate() {
            if self.measures.degenerate[f] {
                continue;
            }
            let mut blocks = [[[0.0; 3]; 3]; 9];
            for k in 0..3 {
                let coefficients = corner_coefficients(
                    normals[f],
                    self.measures.triangle_angles[f][k],
                    self.measures.length_ratios[f][k],
                );
                // Corner k has coefficients on local vertices k, k+1, k+2 (eq 2).
                for (p, cp) in coefficients.iter().enumerate() {
                    for (q, cq) in coefficients.iter().enumerate() {
                        let ab = 3 * ((k + p) % 3) + (k + q) % 3;
                        add_transpose_product(&mut blocks[ab], cp, cq);
                    }
                }
            }
            for (block, slot) in blocks.iter().zip(slots) {
                for c in 0..3 {
                    for r in 0..3 {
                        values[slot[c] + r] += block[r][c];
                    }
                }
            }
        }
        for (&s, &d) in self.diagonal_slots.iter().zip(constraint_diagonal) {
            values[s] += d;
        }
    }

    /// Residual `G(Theta, normals) V` of `#V x 3` `positions`: `#F x 3` corner residuals
    /// `e_{i+1} - l R_i e_i` (eq 1; zero on degenerate faces).
    pub fn residual(&self, normals: &[[f64; 3]], positions: &[[f64; 3]]) -> Vec<[[f64; 3]; 3]> {
        self.triangles
            .iter()
            .enumerate()
            .map(|(f, t)| {
                std::array::from_fn(|k| {
                    if self.measures.degenerate[f] {
                        return [0.0; 3];
                    }
                    let coefficients = corner_coefficients(
                        normals[f],
                        self.measures.triangle_angles[f][k],
                        self.measures.length_ratios[f][k],
                    );
                    let mut r = [0.0; 3];
                    for (p, cp) in coefficients.iter().enumerate() {
                        let x = positions[t[(k + p) % 3] as usize];
                        for (row, rr) in r.iter_mut().enumerate() {
                            *rr += cp[row][0] * x[0] + cp[row][1] * x[1] + cp[row][2] * x[2];
                        }
                    }
                    r
                })
            })
            .collect()
    }
}

/// The 3x3 coefficient blocks of eq 2 for one corner, on `v`, `v_i`, `v_{i+1}`:
/// `l R - I`, `-l R`, `I`, with `R` the rotation by `theta` about the unit `normal`.
fn corner_coefficients(normal: [f64; 3], theta: f64, l: f64) -> [Mat3; 3] {
    let r = rotation_matrix(normal, theta);
    let mut at_v = [[0.0; 3]; 3];
    let mut at_vi = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            at_v[i][j] = l * r[i][j] - if i == j { 1.0 } else { 0.0 };
            at_vi[i][j] = -l * r[i][j];
        }
    }
    [at_v, at_vi, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]]
}

/// `acc += a^T b` for 3x3 matrices.
fn add_transpose_product(acc: &mut Mat3, a: &Mat3, b: &Mat3) {
    for i in 0..3 {
        for j in 0..3 {
            acc[i][j] += a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j];
        }
    }
}
