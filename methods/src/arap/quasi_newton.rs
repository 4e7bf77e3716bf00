//! `solver = "lbfgs"`: the ARAP energy minimized by L-BFGS whose initial Hessian is the global-step
//! matrix already factored (Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods for real-time
//! simulation of hyperelastic materials", section 4: projective dynamics' Laplacian as `H_0`).
//!
//! With the rotations at their local-step optimum, `E(X) = min_R E(X, R)` has the gradient
//! `dE/dX = 4 (K X - b(R))` on the free vertices (envelope theorem; `K = -L`, `b` of SA07 eq 8-9),
//! so the local/global step `X <- K^-1 b(R) = X - K^-1 (K X - b)` is L-BFGS with an empty memory
//! and unit step: the two solvers share the energy and the fixed points (stationary points of
//! `E`), and a kept pair of curvature information is what lets L-BFGS cross the bar's slow
//! bending mode, along which `E`'s Hessian is far below `K`.
//!
//! Scaling (Oren & Luenberger, in `K`'s metric): `H_0 = c K` with `c = s^T y / s^T K s` of the
//! newest pair, the secant curvature along the last step relative to `K`'s, clamped to
//! `[lbfgs_scale_floor, 1]` (`E`'s Hessian is below `4 K`, so `c <= 1`). Unclamped, `c` fell to
//! 0.007 on the bumpy plane and the line search halved most steps; with floor 0.5 the survey's
//! iterations to a 1e-5 distance bound fell from 398/164/154/612 (unscaled, `c = 1`) to
//! 325/142/118/472 (bar/cactus/cylinder/plane; docs/results.md, issue 51).
//!
//! Each iteration: the direction (two-loop recursion, one back-substitution of 3 columns), then a
//! backtracking Armijo line search on `E` (one local step and one energy per trial; the first
//! trial, unit step, is accepted almost always), then the gradient at the accepted point. A
//! direction that is not a descent direction, or whose line search fails, drops the memory and
//! takes the local/global step, which never raises the energy.
//!
//! Stopping (issue 51): the step sequence's distance bound ([`DistanceBound`]) and, once that is
//! met, the gradient: `|K^-1 grad E|` (the plain local/global step, largest vertex, over the
//! diagonal) divided by the least secant curvature `c` seen in the solve, `d = |K^-1 g| / c_min`, the
//! distance a Newton step would take if the Hessian were `c_min K` (exact for a quadratic whose
//! Hessian is `c_min K` along the gradient). Why both: on the bumpy plane the steps shrink smoothly
//! for ~80 iterations while a slow mode (curvature relative to `K` ~5e-5) keeps the iterate 4e-4
//! diagonals away, and the step bound alone stopped there; with the gradient the survey plane ends
//! 1.3e-5 (max) from its 1e-12 fixed point at tolerance 1e-5 (746 iterations instead of 472).
//! `c_min` is an estimate (the slowest mode may not have been sampled yet), so this is a
//! heuristic bound, measured rather than proved (docs/results.md, issue 51). It costs one
//! back-substitution per iteration in which the step bound is met.
//!
//! Energy differences below `1e-12 E` are rounding (the energy is a sum of `#V` terms): the
//! Armijo test allows them, so that the line search does not shrink steps near the minimum on
//! noise (Peng et al.'s energy test in the Anderson solver has the same allowance).

use super::{Arap, Spokes};
use crate::error::MethodError;
use crate::handles::FREE;
use crate::linalg::lbfgs::{dot, Lbfgs};
use crate::linalg::sparse_cholesky::SparseCholesky;
use crate::method::{run_iterations, DistanceBound, IterationObserver, Iterations, SolveSummary};
use crate::rotation_fit::Mat3;
use faer::Mat;
use rayon::prelude::*;

/// Armijo's sufficient-decrease constant and the line search's most halvings.
const ARMIJO: f64 = 1e-4;
const MAX_HALVINGS: usize = 20;
/// Relative energy change that is rounding, not descent (see the module documentation).
pub(super) const ENERGY_NOISE: f64 = 1e-12;

/// Buffers of one L-BFGS solve, `3 #V` entries each (vertex-major `x, y, z`).
pub(super) struct QuasiNewton<'a> {
    pub spokes: &'a Spokes,
    pub region_of: &'a [u32],
    pub cholesky: &'a mut SparseCholesky,
    pub rotations: &'a mut Vec<Mat3>,
    pub frames: &'a mut Vec<Mat3>,
    pub vertex_energies: &'a mut Vec<f64>,
    pub rhs: &'a mut Mat<f64>,
    pub memory: usize,
    /// Least `c` of `H_0 = c K` (see [`QuasiNewton::solve`]).
    pub scale_floor: f64,
    pub diagonal: f64,
}

/// `(K v)_i` for free `i` (constrained entries of `v` are 0), 0 for constrained vertices: the
/// global-step matrix applied to a vertex-major `3 #V` vector.
fn stiffness_times(spokes: &Spokes, region_of: &[u32], v: &[f64], out: &mut [[f64; 3]]) {
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
        *o = [0.0; 3];
        if region_of[i] != FREE {
            return;
        }
        for s in spokes.offsets[i]..spokes.offsets[i + 1] {
            let j = spokes.neighbors[s] as usize;
            let w = spokes.weights[s];
            for a in 0..3 {
                o[a] += w * (v[3 * i + a] - v[3 * j + a]);
            }
        }
    });
}

/// `(K X - b(R))_i` for free `i`, 0 for constrained vertices: a quarter of `dE/dX`, `#V x 3`.
fn gradient(spokes: &Spokes, region_of: &[u32], x: &[[f64; 3]], rotations: &[Mat3], out: &mut [[f64; 3]]) {
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, g)| {
        *g = [0.0; 3];
        if region_of[i] != FREE {
            return;
        }
        let (xi, ri) = (x[i], &rotations[i]);
        for s in spokes.offsets[i]..spokes.offsets[i + 1] {
            let j = spokes.neighbors[s] as usize;
            let (xj, rj, e, w) = (x[j], &rotations[j], spokes.rest_edges[s], spokes.weights[s]);
            for a in 0..3 {
                let rotated = 0.5
                    * ((ri[a][0] + rj[a][0]) * e[0]
                        + (ri[a][1] + rj[a][1]) * e[1]
                        + (ri[a][2] + rj[a][2]) * e[2]);
                g[a] += w * ((xi[a] - xj[a]) - rotated);
            }
        }
    });
}

impl QuasiNewton<'_> {
    /// Local step at `x` and a quarter of the energy there (the scale of [`gradient`]).
    fn rotations_and_energy(&mut self, x: &[[f64; 3]]) -> f64 {
        Arap::local_step(self.spokes, x, self.rotations, self.frames);
        0.25 * Arap::energy(self.spokes, x, self.rotations, self.vertex_energies)
    }

    /// `q <- K^-1 q / scale` on `3 #V` vertex-major entries (constrained rows of `q` are 0 and
    /// stay 0).
    fn apply_inverse_stiffness(cholesky: &mut SparseCholesky, rhs: &mut Mat<f64>, scale: f64, q: &mut [f64]) {
        let n = rhs.nrows();
        for i in 0..n {
            for a in 0..3 {
                rhs[(i, a)] = q[3 * i + a];
            }
        }
        cholesky.solve_in_place(rhs.as_mut());
        for i in 0..n {
            for a in 0..3 {
                q[3 * i + a] = rhs[(i, a)] / scale;
            }
        }
    }

    /// Minimize the energy from `current` (`#V x 3`, constrained vertices at their targets) until
    /// the stopping rule of `iterations` holds; `current` ends at the last iterate.
    pub fn solve(
        mut self,
        iterations: Iterations,
        current: &mut Vec<[f64; 3]>,
        observer: &mut dyn IterationObserver,
    ) -> Result<SolveSummary, MethodError> {
        let n = current.len();
        let mut lbfgs = Lbfgs::new(self.memory, 3 * n);
        let mut g = vec![[0.0; 3]; n];
        let mut g_new = vec![[0.0; 3]; n];
        let mut d = vec![0.0; 3 * n];
        let mut trial = vec![[0.0; 3]; n];
        let mut ks = vec![[0.0; 3]; n];
        let mut scale = 1.0;
        let mut s = vec![0.0; 3 * n];
        let mut y = vec![0.0; 3 * n];
        let mut energy = self.rotations_and_energy(current);
        // The least unclamped secant curvature `s'y / s'Ks` of the solve so far.
        let mut least_curvature: f64 = 1.0;
        let mut plain_step = vec![0.0; 3 * n];
        gradient(self.spokes, self.region_of, current, self.rotations, &mut g);
        let iterate =
            |x: &mut Vec<[f64; 3]>, iteration: usize, rule: &DistanceBound| -> Result<f64, MethodError> {
                let (cholesky, rhs) = (&mut *self.cholesky, &mut *self.rhs);
                lbfgs.direction(g.as_flattened(), &mut d, |q| {
                    Self::apply_inverse_stiffness(cholesky, rhs, scale, q)
                });
                let mut slope = dot(g.as_flattened(), &d);
                if !(slope < 0.0) && !lbfgs.is_empty() {
                    lbfgs.reset();
                    lbfgs.direction(g.as_flattened(), &mut d, |q| {
                        Self::apply_inverse_stiffness(cholesky, rhs, scale, q)
                    });
                    slope = dot(g.as_flattened(), &d);
                }
                let mut alpha = 1.0;
                let mut accepted = None;
                for _ in 0..=MAX_HALVINGS {
                    for ((t, xi), di) in trial.iter_mut().zip(x.iter()).zip(d.chunks_exact(3)) {
                        *t = [xi[0] + alpha * di[0], xi[1] + alpha * di[1], xi[2] + alpha * di[2]];
                    }
                    let e = self.rotations_and_energy(&trial);
                    if e - energy <= ARMIJO * alpha * slope + ENERGY_NOISE * energy.abs() {
                        accepted = Some(e);
                        break;
                    }
                    alpha *= 0.5;
                }
                let e = match accepted {
                    Some(e) => e,
                    None => {
                        // No descent found along d: the local/global step (never raises E).
                        lbfgs.reset();
                        scale = 1.0;
                        let (cholesky, rhs) = (&mut *self.cholesky, &mut *self.rhs);
                        lbfgs.direction(g.as_flattened(), &mut d, |q| {
                            Self::apply_inverse_stiffness(cholesky, rhs, 1.0, q)
                        });
                        for ((t, xi), di) in trial.iter_mut().zip(x.iter()).zip(d.chunks_exact(3)) {
                            *t = [xi[0] + di[0], xi[1] + di[1], xi[2] + di[2]];
                        }
                        self.rotations_and_energy(&trial)
                    }
                };
                if let Some(i) = trial.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                    return Err(MethodError::NonFinite { method: "arap", vertex: i, iteration });
                }
                gradient(self.spokes, self.region_of, &trial, self.rotations, &mut g_new);
                let mut step2: f64 = 0.0;
                for i in 0..n {
                    let mut m2 = 0.0;
                    for a in 0..3 {
                        let k = 3 * i + a;
                        s[k] = trial[i][a] - x[i][a];
                        y[k] = g_new[i][a] - g[i][a];
                        m2 += s[k] * s[k];
                    }
                    step2 = step2.max(m2);
                }
                if lbfgs.push(&s, &y) {
                    // H_0 = c K with c = s^T y / s^T K s, the secant's curvature along s relative to K's
                    // (Oren-Luenberger scaling in K's metric; c <= 1 where E's Hessian is below K).
                    stiffness_times(self.spokes, self.region_of, &s, &mut ks);
                    let c = dot(&s, &y) / dot(&s, ks.as_flattened());
                    if c.is_finite() && c > 0.0 {
                        scale = c.clamp(self.scale_floor, 1.0);
                        least_curvature = least_curvature.min(c);
                    }
                }
                std::mem::swap(x, &mut trial);
                std::mem::swap(&mut g, &mut g_new);
                energy = e;
                let step = step2.sqrt() / self.diagonal;
                if rule.is_met_by(step) {
                    // The steps look converged; ask the gradient too (see the module documentation).
                    plain_step.copy_from_slice(g.as_flattened());
                    let (cholesky, rhs) = (&mut *self.cholesky, &mut *self.rhs);
                    Self::apply_inverse_stiffness(cholesky, rhs, 1.0, &mut plain_step);
                    let largest = plain_step
                        .chunks_exact(3)
                        .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
                        .fold(0.0, f64::max);
                    rule.at_least(largest / self.diagonal / least_curvature);
                }
                Ok(step)
            };
        run_iterations(iterations, current, iterate, |x| x.clone(), observer)
    }
}
