//! Limited-memory BFGS directions (Nocedal & Wright 2006, Algorithm 7.4, the two-loop recursion)
//! with a caller-supplied initial inverse Hessian: `arap`'s quasi-Newton solver uses the factored
//! global-step matrix there (Liu, Bouaziz & Kavan 2017), so that with an empty memory the
//! direction is the local/global step.
//!
//! Dot products are summed over fixed chunks in order, so a direction does not depend on the
//! number of threads.

use rayon::prelude::*;

/// Entries per chunk of a parallel dot product (fixed, so sums are reproducible).
const CHUNK: usize = 4096;

/// The last `memory` curvature pairs `(s, y)` of an L-BFGS iteration, in fixed storage.
pub struct Lbfgs {
    memory: usize,
    s: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    /// `1 / (y_i^T s_i)` of each stored pair.
    rho: Vec<f64>,
    alpha: Vec<f64>,
    /// Ring buffer: `len` valid pairs, the oldest at `start`.
    start: usize,
    len: usize,
}

impl Lbfgs {
    /// Storage for `memory` pairs of vectors of `dimension` entries (`memory = 0`: the direction
    /// is always the initial inverse Hessian's).
    pub fn new(memory: usize, dimension: usize) -> Self {
        Self {
            memory,
            s: vec![vec![0.0; dimension]; memory],
            y: vec![vec![0.0; dimension]; memory],
            rho: vec![0.0; memory],
            alpha: vec![0.0; memory],
            start: 0,
            len: 0,
        }
    }

    /// Forget the curvature pairs.
    pub fn reset(&mut self) {
        self.start = 0;
        self.len = 0;
    }

    /// Pairs held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no pair is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Keep the pair `s = x_{k+1} - x_k`, `y = g_{k+1} - g_k` (the oldest is dropped when full).
    /// A pair without positive curvature (`y^T s <= 1e-12 |s| |y|`, a nonconvex stretch of the
    /// energy) is skipped, so the implied inverse Hessian stays positive definite; returns whether
    /// it was kept.
    pub fn push(&mut self, s: &[f64], y: &[f64]) -> bool {
        if self.memory == 0 {
            return false;
        }
        let sy = dot(s, y);
        if !(sy > 1e-12 * dot(s, s).sqrt() * dot(y, y).sqrt()) {
            return false;
        }
        let slot = if self.len < self.memory {
            self.len += 1;
            (self.start + self.len - 1) % self.memory
        } else {
            let slot = self.start;
            self.start = (self.start + 1) % self.memory;
            slot
        };
        self.s[slot].copy_from_slice(s);
        self.y[slot].copy_from_slice(y);
        self.rho[slot] = 1.0 / sy;
        true
    }

    /// The quasi-Newton direction `d = -H g` for `gradient` into `direction`, where `H` is the
    /// L-BFGS inverse Hessian built on `apply_initial_inverse` (which replaces its argument `q`
    /// by `H_0 q`).
    pub fn direction(
        &mut self,
        gradient: &[f64],
        direction: &mut [f64],
        mut apply_initial_inverse: impl FnMut(&mut [f64]),
    ) {
        direction.copy_from_slice(gradient);
        for k in (0..self.len).rev() {
            let i = (self.start + k) % self.memory;
            let a = self.rho[i] * dot(&self.s[i], direction);
            self.alpha[i] = a;
            axpy(-a, &self.y[i], direction);
        }
        apply_initial_inverse(direction);
        for k in 0..self.len {
            let i = (self.start + k) % self.memory;
            let b = self.rho[i] * dot(&self.y[i], direction);
            axpy(self.alpha[i] - b, &self.s[i], direction);
        }
        direction.par_iter_mut().with_min_len(CHUNK).for_each(|d| *d = -*d);
    }
}

/// `a^T b`, summed over fixed chunks in order.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let partial: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>())
        .collect();
    partial.iter().sum()
}

/// `y += a x`.
fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    y.par_chunks_mut(CHUNK).zip(x.par_chunks(CHUNK)).for_each(|(y, x)| {
        for (yi, xi) in y.iter_mut().zip(x) {
            *yi += a * xi;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Minimizing `1/2 x^T A x - b^T x` with exact line searches, L-BFGS with memory >= n ends in
    /// n steps (BFGS is exact on quadratics); with memory 0 and `H_0 = A^-1` it is one step.
    #[test]
    fn lbfgs_minimizes_a_quadratic_in_n_exact_line_searches() {
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let b = [1.0, -2.0, 0.5];
        let grad = |x: &[f64]| -> Vec<f64> {
            (0..3).map(|i| (0..3).map(|j| a[i][j] * x[j]).sum::<f64>() - b[i]).collect()
        };
        let mut lbfgs = Lbfgs::new(5, 3);
        let mut x = vec![0.0; 3];
        let mut g = grad(&x);
        let mut d = vec![0.0; 3];
        for _ in 0..3 {
            lbfgs.direction(&g, &mut d, |_| {});
            // Exact step along d: alpha = -g.d / d.A.d.
            let ad: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[i][j] * d[j]).sum()).collect();
            let alpha = -dot(&g, &d) / dot(&d, &ad);
            let s: Vec<f64> = d.iter().map(|v| alpha * v).collect();
            x.iter_mut().zip(&s).for_each(|(x, s)| *x += s);
            let g_new = grad(&x);
            let y: Vec<f64> = g_new.iter().zip(&g).map(|(a, b)| a - b).collect();
            assert!(lbfgs.push(&s, &y));
            g = g_new;
        }
        assert!(dot(&g, &g).sqrt() < 1e-12, "gradient {g:?} after 3 steps");
    }

    #[test]
    fn without_pairs_the_direction_is_the_initial_inverse_hessians() {
        let mut lbfgs = Lbfgs::new(3, 2);
        let mut d = vec![0.0; 2];
        lbfgs.direction(&[2.0, -4.0], &mut d, |q| q.iter_mut().for_each(|v| *v *= 0.5));
        assert_eq!(d, vec![-1.0, 2.0]);
        // A pair of negative curvature is not kept.
        assert!(!lbfgs.push(&[1.0, 0.0], &[-1.0, 0.0]));
        assert!(lbfgs.is_empty());
    }
}
