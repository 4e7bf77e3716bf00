//! Adding details back by deformation transfer (Botsch, Sumner, Pauly & Gross 2006; Rong et al. 2008,
//! section 4.4): the deformation gradient of every smoothed triangle, with the scaled face normal as
//! fourth vertex (Sumner & Popović 2004), is applied to the gradients of the detailed triangle, and the
//! detailed positions are the least-squares (Poisson) solution
//! `min sum_t A_t sum_c |grad_t x'_c - T_t^c|^2`, i.e. `-L_s X' = b` with `b_i = sum_t A_t T_t grad phi_i`.
//!
//! `-L_s` does not depend on the handles: it is factored once (PT3) with one vertex per connected
//! component pinned (the system is singular up to a translation per component and `b` is
//! compatible, so pinning is exact); each solve is one back-substitution (RT2). The free translation
//! is then chosen so the constrained vertices are, on average, at their targets.

use faer::sparse::SparseColMat;
use faer::Mat;
use meshes::vector::{cross, dot, norm, scale, sub};

use crate::error::MethodError;
use crate::linalg::sparse_cholesky::SparseCholesky;
use crate::rotation_fit::Mat3;

/// Precomputed detail-transfer system of a rest mesh.
pub struct DeformationTransfer {
    triangles: Vec<[u32; 3]>,
    /// Per face: area and the three hat-function gradients of the detailed rest triangle.
    gradients: Vec<(f64, [[f64; 3]; 3])>,
    /// Per face: inverse of `[e1, e2, n]` of the smoothed rest triangle (`None`: degenerate).
    source_frames_inverse: Vec<Option<Mat3>>,
    component_of: Vec<u32>,
    pinned: Vec<bool>,
    cholesky: SparseCholesky,
    rhs: Mat<f64>,
}

impl DeformationTransfer {
    /// PT3: gradients of the detailed rest mesh `rest` (`#V x 3`), frames of the smoothed rest mesh
    /// `smoothed` (`#V x 3`), and the pinned factorization of `stiffness = -L_s` (`#V x #V`).
    pub fn new(
        rest: &[[f64; 3]],
        smoothed: &[[f64; 3]],
        triangles: &[[u32; 3]],
        stiffness: &SparseColMat<usize, f64>,
    ) -> Result<Self, MethodError> {
        let n = rest.len();
        let component_of = connected_components(stiffness);
        let mut pinned = vec![false; n];
        let mut seen = vec![false; n];
        for v in 0..n {
            let c = component_of[v] as usize;
            if !seen[c] {
                seen[c] = true;
                pinned[v] = true;
            }
        }
        let mut system = stiffness.clone();
        let (symbolic, values) = system.parts_mut();
        for j in 0..symbolic.ncols() {
            for idx in symbolic.col_range(j) {
                let i = symbolic.row_idx()[idx];
                if pinned[i] || pinned[j] {
                    values[idx] = if i == j { 1.0 } else { 0.0 };
                }
            }
        }
        let mut cholesky = SparseCholesky::new(system.as_ref())?;
        // Every RT2 solve has three columns: the blocked copy of the factor is all it reads.
        cholesky.keep_only_solves();
        let gradients = triangles.iter().map(|t| hat_gradients(rest, t)).collect();
        let source_frames_inverse = triangles.iter().map(|t| invert(&frame(smoothed, t))).collect();
        Ok(Self {
            triangles: triangles.to_vec(),
            gradients,
            source_frames_inverse,
            component_of,
            pinned,
            cholesky,
            rhs: Mat::zeros(n, 3),
        })
    }

    /// RT2: detailed positions (`#V x 3`) following the smoothed model from its rest shape to
    /// `smoothed_deformed` (`#V x 3`); `constrained` / `targets` fix the free translation.
    pub fn transfer(
        &mut self,
        smoothed_deformed: &[[f64; 3]],
        constrained: &[u32],
        targets: &[[f64; 3]],
        fallback: &[[f64; 3]],
    ) -> Vec<[f64; 3]> {
        let n = smoothed_deformed.len();
        self.rhs.fill(0.0);
        for (f, t) in self.triangles.iter().enumerate() {
            // A degenerate smoothed triangle carries no deformation information: identity.
            let deformation = match &self.source_frames_inverse[f] {
                Some(inverse) => matmul(&frame(smoothed_deformed, t), inverse),
                None => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            };
            let (area, grads) = &self.gradients[f];
            for k in 0..3 {
                let g = mul(&deformation, grads[k]);
                for c in 0..3 {
                    self.rhs[(t[k] as usize, c)] += area * g[c];
                }
            }
        }
        // Pinned rows (identity): their value is the translation reference, 0 here.
        for v in 0..n {
            if self.pinned[v] {
                for c in 0..3 {
                    self.rhs[(v, c)] = 0.0;
                }
            }
        }
        self.cholesky.solve_in_place(self.rhs.as_mut());
        let mut x: Vec<[f64; 3]> =
            (0..n).map(|i| [self.rhs[(i, 0)], self.rhs[(i, 1)], self.rhs[(i, 2)]]).collect();
        self.fix_translation(&mut x, constrained, targets, fallback);
        x
    }

    /// Per component: mean offset to the constrained targets, or (no constraint in the component) to
    /// `fallback` (`#V x 3`, e.g. the smoothed deformation plus rest details).
    fn fix_translation(
        &self,
        x: &mut [[f64; 3]],
        constrained: &[u32],
        targets: &[[f64; 3]],
        fallback: &[[f64; 3]],
    ) {
        let n_components = self.component_of.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
        let mut sum = vec![[0.0; 3]; n_components];
        let mut count = vec![0usize; n_components];
        for (&v, t) in constrained.iter().zip(targets) {
            let c = self.component_of[v as usize] as usize;
            let d = sub(*t, x[v as usize]);
            for a in 0..3 {
                sum[c][a] += d[a];
            }
            count[c] += 1;
        }
        for v in 0..x.len() {
            let c = self.component_of[v] as usize;
            if count[c] == 0 {
                let d = sub(fallback[v], x[v]);
                for a in 0..3 {
                    sum[c][a] += d[a];
                }
            }
        }
        let mut size = vec![0usize; n_components];
        for &c in &self.component_of {
            size[c as usize] += 1;
        }
        for v in 0..x.len() {
            let c = self.component_of[v] as usize;
            let k = if count[c] > 0 { count[c] } else { size[c] } as f64;
            for a in 0..3 {
                x[v][a] += sum[c][a] / k;
            }
        }
    }
}

/// `[e1, e2, n]` (columns) of triangle `t`, with `n = (e1 x e2) / sqrt(|e1 x e2|)` so that it scales
/// like an edge (Sumner & Popović 2004).
fn frame(p: &[[f64; 3]], t: &[u32; 3]) -> Mat3 {
    let [a, b, c] = t.map(|i| p[i as usize]);
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let n2 = cross(e1, e2);
    let len = norm(n2);
    let n = if len > 0.0 { scale(n2, 1.0 / len.sqrt()) } else { [0.0; 3] };
    [[e1[0], e2[0], n[0]], [e1[1], e2[1], n[1]], [e1[2], e2[2], n[2]]]
}

/// Area and hat-function gradients `grad phi_k` of triangle `t`: `grad phi_k = n x e_k / (2A)` with
/// `e_k` the edge opposite corner `k`, counter-clockwise.
fn hat_gradients(p: &[[f64; 3]], t: &[u32; 3]) -> (f64, [[f64; 3]; 3]) {
    let q = t.map(|i| p[i as usize]);
    let n2 = cross(sub(q[1], q[0]), sub(q[2], q[0]));
    let double_area = norm(n2);
    if !(double_area > 0.0) {
        return (0.0, [[0.0; 3]; 3]);
    }
    let n = scale(n2, 1.0 / double_area);
    let grads = std::array::from_fn(|k| {
        let e = sub(q[(k + 2) % 3], q[(k + 1) % 3]);
        scale(cross(n, e), 1.0 / double_area)
    });
    (0.5 * double_area, grads)
}

fn invert(m: &Mat3) -> Option<Mat3> {
    let c0 = [m[0][0], m[1][0], m[2][0]];
    let c1 = [m[0][1], m[1][1], m[2][1]];
    let c2 = [m[0][2], m[1][2], m[2][2]];
    let det = dot(c0, cross(c1, c2));
    let size = norm(c0) * norm(c1) * norm(c2);
    if !(det.abs() > 1e-12 * size) || !det.is_finite() {
        return None;
    }
    // Rows of the inverse are the cross products of the columns, divided by det.
    let r0 = cross(c1, c2);
    let r1 = cross(c2, c0);
    let r2 = cross(c0, c1);
    Some([scale(r0, 1.0 / det), scale(r1, 1.0 / det), scale(r2, 1.0 / det)])
}

fn matmul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

fn mul(m: &Mat3, x: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2])
}

/// Connected component label per vertex of the graph of a symmetric sparse matrix.
fn connected_components(m: &SparseColMat<usize, f64>) -> Vec<u32> {
    let n = m.nrows();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    let symbolic = m.symbolic();
    for j in 0..n {
        for &i in &symbolic.row_idx()[symbolic.col_range(j)] {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut label = vec![u32::MAX; n];
    let mut next = 0u32;
    let mut out = vec![0u32; n];
    for v in 0..n {
        let r = root(&mut parent, v);
        if label[r] == u32::MAX {
            label[r] = next;
            next += 1;
        }
        out[v] = label[r];
    }
    out
}
