//! Shift-invert block Krylov–Schur (thick-restart block Lanczos) for `Q h = lambda D h`.
//!
//! The operator `OP = (Q - sigma D)^{-1} D` is self-adjoint in the `D` inner product, with eigenvalues
//! `theta = 1 / (lambda - sigma)`: the smallest `lambda` become the largest, best separated `theta`.
//! With `sigma < 0` slightly, `Q - sigma D` is positive definite and is factored once by sparse
//! Cholesky; every application of `OP` is one multi-column back-substitution.
//!
//! The basis `V` is kept `D`-orthonormal by block classical Gram–Schmidt applied twice ("twice is
//! enough", Giraud et al. 2005), i.e. full reorthogonalization with BLAS-3 products, so clusters of
//! (near-)multiple eigenvalues are resolved like any other. `H = V^T D OP V` is accumulated from the
//! projection coefficients, and `OP V_s = V_s H_s + V_r E` holds with `V_r` the last (residual) block.
//! Rayleigh–Ritz on `H_s` gives Ritz pairs `(theta_i, V_s y_i)` with residual norm `|E y_i|`; a
//! restart keeps the leading Ritz vectors and the residual block (Stewart 2001), so `H` becomes
//! diagonal plus the coupling row `E Y`.

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

use super::random::SplitMix64;
use super::{EigenError, EigenOptions, Eigenpairs};
use crate::sparse_cholesky::{add_to_diagonal, SparseCholesky};

/// Relative size of the shift: `sigma = -SHIFT * (upper bound of the spectrum)`. Small enough that the
/// wanted eigenvalues are well separated after inversion, large enough to keep `Q - sigma D` safely
/// positive definite (condition number about `1 / SHIFT`).
const SHIFT: f64 = 1e-8;

pub fn smallest_eigenpairs(
    stiffness: SparseColMatRef<'_, usize, f64>,
    mass: &[f64],
    options: &EigenOptions,
) -> Result<Eigenpairs, EigenError> {
    let n = mass.len();
    let k = options.count;
    let b = options.block_size.clamp(1, 64);
    // A multiple of the block size, so that every cycle ends exactly at `basis` columns.
    let basis = options.basis_size.unwrap_or((2 * k).max(k + 4 * b)).max(k + 2 * b).div_ceil(b) * b;
    if basis + b > n {
        return Err(EigenError::TooMany { count: k, n });
    }
    let par = Par::rayon(0);

    // Gershgorin: lambda_max <= max_i 2 Q_ii / D_ii for a diagonally dominant-by-rows Laplacian.
    let upper = diagonal(stiffness).iter().zip(mass).map(|(q, d)| 2.0 * q / d).fold(0.0, f64::max);
    if !(upper > 0.0) {
        return Err(EigenError::Invalid("stiffness has no positive diagonal entry".into()));
    }
    let sigma = -SHIFT * upper;
    let shifted_mass: Vec<f64> = mass.iter().map(|d| -sigma * d).collect();
    let mut cholesky = SparseCholesky::new(add_to_diagonal(stiffness, &shifted_mass).as_ref())
        .map_err(EigenError::Solver)?;

    let cap = basis + b;
    let mut v = Mat::<f64>::zeros(n, cap);
    let mut h = Mat::<f64>::zeros(cap, cap);
    let mut w = Mat::<f64>::zeros(n, b);
    let mut rng = SplitMix64::new(options.seed);
    {
        let mut start = Mat::from_fn(n, b, |_, _| rng.symmetric_unit());
        let norms = column_norms(start.as_ref(), mass);
        orthonormalize_block(start.as_mut(), &norms, v.as_ref().subcols(0, 0), mass, &mut rng);
        v.as_mut().subcols_mut(0, b).copy_from(start.as_ref());
    }
    let mut current = b; // basis columns, the last block being the residual block
    let mut kept = 0; // leading Ritz vectors kept by the last restart
    let mut applications = 0usize;

    for restart in 0..=options.max_restarts {
        while current - b < basis {
            let block = current - b;
            // W = OP V_block.
            for j in 0..b {
                for i in 0..n {
                    w[(i, j)] = mass[i] * v[(i, block + j)];
                }
            }
            cholesky.solve_in_place(w.as_mut());
            applications += b;
            let norms = column_norms(w.as_ref(), mass);
            // In exact arithmetic OP V_block only has components along the previous and the current
            // block (and, right after a restart, the kept Ritz vectors): project those out first, then
            // reorthogonalize once against the whole basis to remove what rounding put elsewhere.
            let local = if block == kept { 0 } else { block.saturating_sub(b) };
            let mut coefficients = Mat::<f64>::zeros(current, b);
            let c = project_out(w.as_mut(), v.as_ref().subcols(local, current - local), mass, par, 1);
            coefficients.as_mut().subrows_mut(local, current - local).copy_from(c.as_ref());
            coefficients += project_out(w.as_mut(), v.as_ref().subcols(0, current), mass, par, 1);
            h.as_mut().submatrix_mut(0, block, current, b).copy_from(coefficients.as_ref());
            let r = orthonormalize_block(w.as_mut(), &norms, v.as_ref().subcols(0, current), mass, &mut rng);
            v.as_mut().subcols_mut(current, b).copy_from(w.as_ref());
            h.as_mut().submatrix_mut(current, block, b, b).copy_from(r.as_ref());
            current += b;
        }
        let s = current - b;

        // Rayleigh–Ritz on the symmetric projection (upper triangle is authoritative).
        let hs = Mat::from_fn(s, s, |i, j| if i <= j { h[(i, j)] } else { h[(j, i)] });
        let evd = hs.self_adjoint_eigen(Side::Upper).map_err(|_| EigenError::Dense)?;
        let theta: Vec<f64> = (0..s).map(|t| evd.S()[s - 1 - t]).collect();
        let y = Mat::from_fn(s, s, |i, t| evd.U()[(i, s - 1 - t)]);
        let mut coupling = Mat::<f64>::zeros(b, s);
        matmul(
            coupling.as_mut(),
            Accum::Replace,
            h.as_ref().submatrix(s, 0, b, s),
            y.as_ref(),
            1.0,
            Par::Seq,
        );
        let residual = |t: usize| (0..b).map(|i| coupling[(i, t)] * coupling[(i, t)]).sum::<f64>().sqrt();
        let converged = (0..k).take_while(|&t| residual(t) <= options.tolerance * theta[t].abs()).count();
        if converged == k {
            let mut vectors = Mat::<f64>::zeros(n, k);
            matmul(
                vectors.as_mut(),
                Accum::Replace,
                v.as_ref().subcols(0, s),
                y.as_ref().subcols(0, k),
                1.0,
                par,
            );
            let values = theta[..k].iter().map(|t| sigma + 1.0 / t).collect();
            return Ok(Eigenpairs {
                values,
                vectors,
                constant_mode: None,
                restarts: restart,
                operator_applications: applications,
            });
        }
        if restart == options.max_restarts {
            return Err(EigenError::NotConverged { converged, wanted: k, restarts: restart });
        }

        // Thick restart: keep the `keep` leading Ritz vectors and the residual block.
        // Keep about half of the unwanted part too; a multiple of `b` short of `basis`, so the next
        // cycle ends exactly at `basis` columns again.
        let keep = basis - b * ((basis - (k + (s - k) / 2)) / b).max(1);
        let mut ritz = Mat::<f64>::zeros(n, keep);
        matmul(
            ritz.as_mut(),
            Accum::Replace,
            v.as_ref().subcols(0, s),
            y.as_ref().subcols(0, keep),
            1.0,
            par,
        );
        v.as_mut().subcols_mut(0, keep).copy_from(ritz.as_ref());
        for j in 0..b {
            for i in 0..n {
                v[(i, keep + j)] = v[(i, s + j)];
            }
        }
        h.fill(0.0);
        for t in 0..keep {
            h[(t, t)] = theta[t];
        }
        h.as_mut().submatrix_mut(keep, 0, b, keep).copy_from(coupling.as_ref().subcols(0, keep));
        current = keep + b;
        kept = keep;
    }
    unreachable!("the loop returns on its last restart")
}

fn diagonal(m: SparseColMatRef<'_, usize, f64>) -> Vec<f64> {
    let (symbolic, values) = m.parts();
    (0..symbolic.ncols())
        .map(|j| {
            symbolic.col_range(j).find(|&idx| symbolic.row_idx()[idx] == j).map_or(0.0, |idx| values[idx])
        })
        .collect()
}

fn d_dot(a: MatRef<'_, f64>, i: usize, b: MatRef<'_, f64>, j: usize, mass: &[f64]) -> f64 {
    let (a, b) = (a.col(i), b.col(j));
    (0..mass.len()).map(|r| mass[r] * a[r] * b[r]).sum()
}

fn column_norms(w: MatRef<'_, f64>, mass: &[f64]) -> Vec<f64> {
    (0..w.ncols()).map(|j| d_dot(w, j, w, j, mass).sqrt()).collect()
}

/// `W <- W - V (V^T D W)`, `passes` times; returns the accumulated coefficients (V's columns x b).
fn project_out(
    mut w: MatMut<'_, f64>,
    v: MatRef<'_, f64>,
    mass: &[f64],
    par: Par,
    passes: usize,
) -> Mat<f64> {
    let mut total = Mat::<f64>::zeros(v.ncols(), w.ncols());
    if v.ncols() == 0 {
        return total;
    }
    let mut dw = Mat::<f64>::zeros(w.nrows(), w.ncols());
    let mut c = Mat::<f64>::zeros(v.ncols(), w.ncols());
    for _pass in 0..passes {
        for j in 0..w.ncols() {
            for i in 0..w.nrows() {
                dw[(i, j)] = mass[i] * w[(i, j)];
            }
        }
        matmul(c.as_mut(), Accum::Replace, v.transpose(), dw.as_ref(), 1.0, par);
        matmul(w.rb_mut(), Accum::Add, v, c.as_ref(), -1.0, par);
        total += &c;
    }
    total
}

/// `D`-orthonormalize the columns of `W` (already orthogonal to `basis`) by modified Gram–Schmidt
/// applied twice, returning the upper triangular `R` with `W_in = W_out R`. A column that vanishes
/// (below 1e-10 of its norm before projection, `norms`) means the Krylov space became invariant; it
/// is replaced by a random vector orthogonal to everything, with a zero in `R`.
fn orthonormalize_block(
    mut w: MatMut<'_, f64>,
    norms: &[f64],
    basis: MatRef<'_, f64>,
    mass: &[f64],
    rng: &mut SplitMix64,
) -> Mat<f64> {
    let b = w.ncols();
    let mut r = Mat::<f64>::zeros(b, b);
    for c in 0..b {
        for _pass in 0..2 {
            for q in 0..c {
                let coef = d_dot(w.rb(), q, w.rb(), c, mass);
                r[(q, c)] += coef;
                for i in 0..w.nrows() {
                    let wq = w[(i, q)];
                    w[(i, c)] -= coef * wq;
                }
            }
        }
        let norm = d_dot(w.rb(), c, w.rb(), c, mass).sqrt();
        if norm > 1e-10 * norms[c] && norm > 0.0 {
            r[(c, c)] = norm;
            for i in 0..w.nrows() {
                w[(i, c)] /= norm;
            }
            continue;
        }
        // Invariant subspace found: continue with a fresh direction.
        loop {
            for i in 0..w.nrows() {
                w[(i, c)] = rng.symmetric_unit();
            }
            let before = d_dot(w.rb(), c, w.rb(), c, mass).sqrt();
            project_out(w.rb_mut().subcols_mut(c, 1), basis, mass, Par::Seq, 2);
            for _pass in 0..2 {
                for q in 0..c {
                    let coef = d_dot(w.rb(), q, w.rb(), c, mass);
                    for i in 0..w.nrows() {
                        let wq = w[(i, q)];
                        w[(i, c)] -= coef * wq;
                    }
                }
            }
            let norm = d_dot(w.rb(), c, w.rb(), c, mass).sqrt();
            if norm > 1e-6 * before {
                for i in 0..w.nrows() {
                    w[(i, c)] /= norm;
                }
                break;
            }
        }
    }
    r
}
