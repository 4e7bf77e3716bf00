//! Section 5.3: the optimal rigidity approximation (ORA). Every triangle of the scale-aware result
//! is scaled about its centroid back to its rest area (eq 13-14), and the scaled triangles are
//! stitched into one mesh by least squares on their edge vectors (eq 15, Igarashi et al. 2005).
//!
//! Decisions the paper leaves open:
//! - Eq 14 prints `c' + tau c'v`; we read `c'v` as the vector from the centroid to `v`, so
//!   `v^ = c' + tau (v - c')`.
//! - Eq 15 prints the same term twice; we read it as
//!   `sum_t sum_j |(v_{j+1} - v_j) - (v^_{j+1} - v^_j)|^2` over the unknown `v`, which is Igarashi's
//!   stitching step. The handles enter as in eq 12: `lambda sum_{j in C} |v_j - v_j*|^2`, so the
//!   system `K + lambda C` is the same for every solve and is factored when the handles are bound.
//! - A triangle that collapsed to zero area in the scale-aware result cannot be rescaled; it keeps
//!   its deformed shape (`tau = 1`).

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use meshes::geometry::triangle_area;
use meshes::vector::{add, scale, sub};

use crate::linalg::sparse_cholesky::{SolverError, SparseCholesky};

/// Eq 13-14: each triangle of `#V x 3` `positions` scaled about its centroid by
/// `tau_t = sqrt(Area_t / Area'_t)` so that its area equals `rest_areas[t]`; `#F` triangles of
/// three corners each.
pub fn rescaled_triangles(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    rest_areas: &[f64],
) -> Vec<[[f64; 3]; 3]> {
    triangles
        .iter()
        .zip(rest_areas)
        .map(|(t, &rest_area)| {
            let p = t.map(|i| positions[i as usize]);
            let centroid = scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
            let area = triangle_area(positions, t);
            let tau = if area > 0.0 && rest_area > 0.0 { (rest_area / area).sqrt() } else { 1.0 };
            p.map(|v| add(centroid, scale(sub(v, centroid), tau)))
        })
        .collect()
}

/// The stitching system of eq 15 with soft handle constraints, factored once per handle set.
pub struct Stitching {
    triangles: Vec<[u32; 3]>,
    constrained: Vec<u32>,
    weight: f64,
    cholesky: SparseCholesky,
    rhs: Mat<f64>,
}

impl Stitching {
    /// Factor `K + weight C` for `#F x 3` `triangles` on `n_vertices` vertices, `C` the indicator of
    /// the `constrained` vertices (`K`: each triangle edge contributes the graph-Laplacian stencil
    /// of `|x_j - x_i|^2`).
    pub fn new(
        n_vertices: usize,
        triangles: &[[u32; 3]],
        constrained: &[u32],
        weight: f64,
    ) -> Result<Self, SolverError> {
        let mut entries = Vec::with_capacity(12 * triangles.len() + constrained.len());
        for t in triangles {
            for j in 0..3 {
                let (a, b) = (t[j] as usize, t[(j + 1) % 3] as usize);
                entries.extend([
                    Triplet::new(a, a, 1.0),
                    Triplet::new(b, b, 1.0),
                    Triplet::new(a, b, -1.0),
                    Triplet::new(b, a, -1.0),
                ]);
            }
        }
        entries.extend(constrained.iter().map(|&v| Triplet::new(v as usize, v as usize, weight)));
        let matrix = SparseColMat::try_new_from_triplets(n_vertices, n_vertices, &entries)
            .map_err(|e| SolverError::Faer(format!("{e:?}")))?;
        Ok(Self {
            triangles: triangles.to_vec(),
            constrained: constrained.to_vec(),
            weight,
            cholesky: SparseCholesky::new(matrix.as_ref())?,
            rhs: Mat::zeros(n_vertices, 3),
        })
    }

    /// Eq 15: the `#V x 3` positions (one column per coordinate) that best fit the edge vectors of
    /// the `#F` `rescaled` triangles and the `targets` of the constrained vertices (in the order
    /// given to [`Stitching::new`]).
    pub fn stitch(&mut self, rescaled: &[[[f64; 3]; 3]], targets: &[[f64; 3]]) -> &Mat<f64> {
        self.rhs.fill(0.0);
        for (t, corners) in self.triangles.iter().zip(rescaled) {
            for j in 0..3 {
                let (a, b) = (t[j] as usize, t[(j + 1) % 3] as usize);
                let edge = sub(corners[(j + 1) % 3], corners[j]);
                for c in 0..3 {
                    self.rhs[(b, c)] += edge[c];
                    self.rhs[(a, c)] -= edge[c];
                }
            }
        }
        for (&v, target) in self.constrained.iter().zip(targets) {
            for c in 0..3 {
                self.rhs[(v as usize, c)] += self.weight * target[c];
            }
        }
        self.cholesky.solve_in_place(self.rhs.as_mut());
        &self.rhs
    }
}
