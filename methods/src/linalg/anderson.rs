//! Anderson acceleration (type II; Walker & Ni 2011) of a fixed-point iteration `x <- T(x)`, as
//! Peng et al. 2018 use it for local/global geometry solvers: `arap`'s local/global map,
//! `scale_aware`'s Algorithm 1, and the Gauss-Newton-like iterations of Laplacian editing
//! (`laplacian`, and the reduced ones of `isolines*` and `hirm` on their transforms). It changes
//! the path, not the fixed points: a converged `x` has `T(x) = x` either way.
//!
//! Safeguard (on by default; [`AndersonAcceleration::with_residual_growth_limit`] for callers with
//! an energy to test, as `arap`): when the residual `|T(x) - x|` grows, the history is dropped and
//! the plain step `x <- T(x)` is taken (scale_aware's Algorithm 1 has no monotone energy).

use serde::Deserialize;

/// How a method drives its fixed-point iteration (`acceleration` in configs/methods.toml).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Acceleration {
    /// The plain iteration `x <- T(x)`, as the papers give it.
    None,
    /// Anderson acceleration over the last `anderson_depth` steps ([`AndersonAcceleration`]).
    #[default]
    Anderson,
}

/// Anderson's history is dropped when the plain residual more than doubles in one step, for every
/// iteration this crate accelerates except `scale_aware`'s (which drops it at any growth). The
/// energy test alone let `arap` on the bar wander to its 1000-iteration cap; dropping the history
/// at any growth held the cactus at 586 iterations. Survey, `arap` iterations to tolerance 1e-5 with
/// depth 7 (plain: cylinder 1182, bar 2417, cactus 1468, plane 2210): 280, 175, 239, 388.
pub const RESIDUAL_GROWTH_LIMIT: f64 = 2.0;

/// The iterate of a fixed-point iteration `x <- T(x)` moved on by its image, plainly or by
/// Anderson acceleration. The caller computes `g = T(x)` and judges the plain step `|g - x|`
/// against its tolerance (so the stopping test is the same either way), then calls
/// [`FixedPointIteration::advance`]. A converged step, or the plain iteration, takes `x <- g`; an
/// unconverged accelerated one extrapolates. When the solve ends unconverged the caller should
/// return the last `g` it computed, the iterate a plain iteration would have (it keeps `g`
/// anyway, so this does not copy it).
pub struct FixedPointIteration {
    anderson: Option<AndersonAcceleration>,
    next: Vec<f64>,
}

impl FixedPointIteration {
    /// For iterates of `dimension` entries: Anderson acceleration of depth `depth` (history dropped
    /// as [`RESIDUAL_GROWTH_LIMIT`] says) when `acceleration` asks for it and `depth > 0`, else the
    /// plain iteration.
    pub fn new(acceleration: Acceleration, depth: usize, dimension: usize) -> Self {
        let accelerated = acceleration == Acceleration::Anderson && depth > 0;
        Self {
            anderson: accelerated.then(|| {
                AndersonAcceleration::new(depth, dimension).with_residual_growth_limit(RESIDUAL_GROWTH_LIMIT)
            }),
            next: vec![0.0; if accelerated { dimension } else { 0 }],
        }
    }

    /// Whether steps are extrapolated.
    pub fn is_accelerated(&self) -> bool {
        self.anderson.is_some()
    }

    /// Move `x` on, given its image `g = T(x)` and whether the plain step `|g - x|` was below the
    /// tolerance; returns whether `x` is now other than `g` (an extrapolated iterate).
    pub fn advance(&mut self, x: &mut [f64], g: &[f64], converged: bool) -> bool {
        match &mut self.anderson {
            Some(anderson) if !converged => {
                anderson.next(x, g, &mut self.next);
                x.copy_from_slice(&self.next);
                true
            }
            _ => {
                x.copy_from_slice(g);
                false
            }
        }
    }
}

/// The last `depth` differences of images `Delta g` and residuals `Delta f`, in fixed storage.
pub struct AndersonAcceleration {
    depth: usize,
    /// Previous image `g = T(x)` and residual `f = g - x`; valid when `has_previous`.
    previous_g: Vec<f64>,
    previous_f: Vec<f64>,
    has_previous: bool,
    previous_residual_norm: f64,
    residual: Vec<f64>,
    /// Ring buffers of `depth` columns; `len` are valid, the newest at `(start + len - 1) % depth`.
    delta_g: Vec<Vec<f64>>,
    delta_f: Vec<Vec<f64>>,
    start: usize,
    len: usize,
    /// The history is dropped when the residual grows by more than this factor in one step.
    residual_growth_limit: f64,
}

impl AndersonAcceleration {
    /// Acceleration over the last `depth` steps for iterates of `dimension` entries (`depth = 0`:
    /// the plain iteration).
    pub fn new(depth: usize, dimension: usize) -> Self {
        Self {
            depth,
            previous_g: vec![0.0; dimension],
            previous_f: vec![0.0; dimension],
            has_previous: false,
            previous_residual_norm: f64::INFINITY,
            residual: vec![0.0; dimension],
            delta_g: vec![vec![0.0; dimension]; depth],
            delta_f: vec![vec![0.0; dimension]; depth],
            start: 0,
            len: 0,
            residual_growth_limit: 1.0,
        }
    }

    /// The same acceleration with the history dropped only when the residual grows by more than
    /// `limit` (>= 1) in one step: for a caller that also guards the iteration itself (Peng et al.
    /// 2018's energy test, `arap`), where a residual that rises a little is normal.
    pub fn with_residual_growth_limit(mut self, limit: f64) -> Self {
        self.residual_growth_limit = limit.max(1.0);
        self
    }

    /// Forget the history (the next step is a plain one).
    pub fn reset(&mut self) {
        self.has_previous = false;
        self.previous_residual_norm = f64::INFINITY;
        self.start = 0;
        self.len = 0;
    }

    /// The next iterate from the current one `x` and its image `g = T(x)`, into `next` (all of the
    /// dimension given to [`AndersonAcceleration::new`]).
    pub fn next(&mut self, x: &[f64], g: &[f64], next: &mut [f64]) {
        next.copy_from_slice(g);
        if self.depth == 0 {
            return;
        }
        for ((r, gi), xi) in self.residual.iter_mut().zip(g).zip(x) {
            *r = gi - xi;
        }
        let norm = self.residual.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm > self.residual_growth_limit * self.previous_residual_norm {
            self.reset();
        }
        if self.has_previous {
            let slot = if self.len < self.depth {
                self.len += 1;
                (self.start + self.len - 1) % self.depth
            } else {
                let oldest = self.start;
                self.start = (self.start + 1) % self.depth;
                oldest
            };
            for k in 0..g.len() {
                self.delta_g[slot][k] = g[k] - self.previous_g[k];
                self.delta_f[slot][k] = self.residual[k] - self.previous_f[k];
            }
        }
        self.previous_g.copy_from_slice(g);
        self.previous_f.copy_from_slice(&self.residual);
        self.has_previous = true;
        self.previous_residual_norm = norm;

        let m = self.len;
        if m == 0 {
            return;
        }
        // gamma = argmin |f - dF gamma| by the normal equations, slightly regularized.
        let column = |i: usize| (self.start + i) % self.depth;
        let mut a = [[0.0; MAX_DEPTH]; MAX_DEPTH];
        let mut b = [0.0; MAX_DEPTH];
        for i in 0..m {
            let fi = &self.delta_f[column(i)];
            for j in 0..=i {
                let d: f64 = fi.iter().zip(&self.delta_f[column(j)]).map(|(p, q)| p * q).sum();
                a[i][j] = d;
                a[j][i] = d;
            }
            b[i] = fi.iter().zip(&self.residual).map(|(p, q)| p * q).sum();
        }
        let trace: f64 = (0..m).map(|i| a[i][i]).sum();
        for (i, row) in a.iter_mut().enumerate().take(m) {
            row[i] += 1e-10 * trace + f64::MIN_POSITIVE;
        }
        if let Some(gamma) = solve_spd(&mut a, b, m) {
            for (i, weight) in gamma.iter().enumerate().take(m) {
                for (n, d) in next.iter_mut().zip(&self.delta_g[column(i)]) {
                    *n -= weight * d;
                }
            }
        }
    }
}

/// Largest supported depth.
pub const MAX_DEPTH: usize = 16;

/// Solve the small SPD system `a x = b` (leading `m x m` block) by Cholesky; `None` if not SPD.
fn solve_spd(
    a: &mut [[f64; MAX_DEPTH]; MAX_DEPTH],
    mut b: [f64; MAX_DEPTH],
    m: usize,
) -> Option<[f64; MAX_DEPTH]> {
    for j in 0..m {
        let d = a[j][j] - (0..j).map(|k| a[j][k] * a[j][k]).sum::<f64>();
        if !(d > 0.0) {
            return None;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..m {
            a[i][j] = (a[i][j] - (0..j).map(|k| a[i][k] * a[j][k]).sum::<f64>()) / d;
        }
    }
    for i in 0..m {
        b[i] = (b[i] - (0..i).map(|k| a[i][k] * b[k]).sum::<f64>()) / a[i][i];
    }
    for i in (0..m).rev() {
        b[i] = (b[i] - (i + 1..m).map(|k| a[k][i] * b[k]).sum::<f64>()) / a[i][i];
    }
    Some(b)
}
