//! Shift-invert block Krylov–Schur (thick-restart block Lanczos) for `Q h = lambda D h`.
//!
//! The operator `OP = (Q - sigma D)^{-1} D` is self-adjoint in the `D` inner product, with eigenvalues
//! `theta = 1 / (lambda - sigma)`: the smallest `lambda` become the largest, best separated `theta`.
//! With `sigma < 0` slightly, `Q - sigma D` is positive definite and is factored once by sparse
//! Cholesky; every application of `OP` is one multi-column back-substitution.
//!
//! The basis `V` is kept `D`-orthonormal by block classical Gram–Schmidt applied twice ("twice is
//! enough", Giraud et al. 2005), i.e. full reorthogonalization ([`super::block_gram_schmidt`]), so clusters of
//! (near-)multiple eigenvalues are resolved like any other. `H = V^T D OP V` is accumulated from the
//! projection coefficients, and `OP V_s = V_s H_s + V_r E` holds with `V_r` the last (residual) block.
//! Rayleigh–Ritz on `H_s` gives Ritz pairs `(theta_i, V_s y_i)` with residual norm `|E y_i|`; a
//! restart keeps the leading Ritz vectors and the residual block (Stewart 2001), so `H` becomes
//! diagonal plus the coupling row `E Y`.

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

use super::block_gram_schmidt::{column_norms, orthonormalize_block, project_out, Projector};
use super::random::SplitMix64;
use super::{EigenError, EigenOptions, Eigenpairs};
use crate::linalg::sparse_cholesky::{add_to_diagonal, SparseCholesky};

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
    // A constant null vector is known exactly: it is deflated rather than computed (see
    // `constant_null_vector`), and the Krylov method looks for the other `k` eigenpairs.
    let constant = constant_null_vector(stiffness, mass);
    let deflated = constant.as_ref().map_or(Mat::zeros(n, 0), |c| c.clone());
    let k = options.count - deflated.ncols();
    if k == 0 {
        return Ok(with_deflated(stiffness, &deflated, Vec::new(), deflated.clone(), 0, 0));
    }
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
    // Every solve below has `b >= 2` columns (a single column would read the same blocked copy).
    cholesky.keep_only_solves();

    let cap = basis + b;
    let mut v = Mat::<f64>::zeros(n, cap);
    let mut h = Mat::<f64>::zeros(cap, cap);
    let mut w = Mat::<f64>::zeros(n, b);
    let mut rng = SplitMix64::new(options.seed);
    {
        let mut start = Mat::from_fn(n, b, |_, _| rng.symmetric_unit());
        let norms = column_norms(start.as_ref(), mass);
        project_out(start.as_mut(), deflated.as_ref(), mass, 2);
        orthonormalize_block(
            start.as_mut(),
            &norms,
            v.as_ref().subcols(0, 0),
            deflated.as_ref(),
            mass,
            &mut rng,
        );
        v.as_mut().subcols_mut(0, b).copy_from(start.as_ref());
    }
    let mut current = b; // basis columns, the last block being the residual block
    let mut kept = 0; // leading Ritz vectors kept by the last restart
    let mut applications = 0usize;
    let mut projector = Projector::default();
    let mut checks = ConvergenceHistory::default();
    let mut restart_rows = Mat::<f64>::zeros(0, 0);

    let mut restart = 0;
    loop {
        loop {
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
            // The deflated vectors go first: OP maps their rounding-level components to ~1e8 times
            // the size of anything else.
            let bases = [
                deflated.as_ref(),
                v.as_ref().subcols(local, current - local),
                v.as_ref().subcols(0, current),
            ];
            let [_, c_local, c_full] =
                <[Mat<f64>; 3]>::try_from(projector.project_out_in_turn(w.as_mut(), &bases, mass))
                    .expect("one coefficient block per basis");
            let mut coefficients = c_full;
            let mut head = coefficients.as_mut().subrows_mut(local, current - local);
            head += c_local;
            h.as_mut().submatrix_mut(0, block, current, b).copy_from(coefficients.as_ref());
            let basis_so_far = v.as_ref().subcols(0, current);
            let r = orthonormalize_block(w.as_mut(), &norms, basis_so_far, deflated.as_ref(), mass, &mut rng);
            v.as_mut().subcols_mut(current, b).copy_from(w.as_ref());
            h.as_mut().submatrix_mut(current, block, b, b).copy_from(r.as_ref());
            current += b;
            if current - b == basis || checks.due(applications) {
                break;
            }
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
        let worst = (0..k).map(|t| residual(t) / (options.tolerance * theta[t].abs())).fold(0.0, f64::max);
        let converged = (0..k).take_while(|&t| residual(t) <= options.tolerance * theta[t].abs()).count();
        checks.record(applications, worst);
        if converged == k {
            // The factor is not needed any more: free it before the eigenvectors are allocated.
            drop(cholesky);
            let d = deflated.ncols();
            let mut vectors = Mat::<f64>::zeros(n, d + k);
            vectors.as_mut().subcols_mut(0, d).copy_from(deflated.as_ref());
            matmul(
                vectors.as_mut().subcols_mut(d, k),
                Accum::Replace,
                v.as_ref().subcols(0, s),
                y.as_ref().subcols(0, k),
                1.0,
                par,
            );
            let values = theta[..k].iter().map(|t| sigma + 1.0 / t).collect();
            return Ok(with_deflated(stiffness, &deflated, values, vectors, restart, applications));
        }
        if s < basis {
            // A check inside the cycle that came too early: extend the basis further.
            continue;
        }
        if restart == options.max_restarts {
            return Err(EigenError::NotConverged { converged, wanted: k, restarts: restart });
        }

        // Thick restart: keep the `keep` leading Ritz vectors and the residual block.
        // Keep about half of the unwanted part too; a multiple of `b` short of `basis`, so the next
        // cycle ends exactly at `basis` columns again.
        let keep = basis - b * ((basis - (k + (s - k) / 2)) / b).max(1);
        restart_in_place(v.as_mut(), s, y.as_ref().subcols(0, keep), &mut restart_rows);
        let (mut head, tail) = v.as_mut().split_at_col_mut(s);
        head.rb_mut().subcols_mut(keep, b).copy_from(tail.subcols(0, b));
        h.fill(0.0);
        for t in 0..keep {
            h[(t, t)] = theta[t];
        }
        h.as_mut().submatrix_mut(keep, 0, b, keep).copy_from(coupling.as_ref().subcols(0, keep));
        current = keep + b;
        kept = keep;
        restart += 1;
    }
}

/// Rows of the basis combined per block by [`restart_in_place`]: a `ROWS x keep` product fits in
/// the cache, and enough rows for faer's matrix-product kernels to run at full speed.
const RESTART_ROWS: usize = 2048;

/// The thick restart's `V[:, ..keep] = V[:, ..s] Y` (`Y`: `s x keep`, `keep <= s`) without a second
/// `#V x s` basis: a row of the product depends only on the same row of `V`, so row blocks are
/// multiplied into `rows` (a `RESTART_ROWS x keep` buffer, grown on first use) and copied back.
/// At 1M vertices and 204 columns this saves 1.6 GB.
fn restart_in_place(mut v: MatMut<'_, f64>, s: usize, y: MatRef<'_, f64>, rows: &mut Mat<f64>) {
    let (n, keep) = (v.nrows(), y.ncols());
    if rows.nrows() < RESTART_ROWS.min(n) || rows.ncols() < keep {
        *rows = Mat::zeros(RESTART_ROWS.min(n), keep);
    }
    for start in (0..n).step_by(RESTART_ROWS) {
        let m = RESTART_ROWS.min(n - start);
        let mut product = rows.as_mut().submatrix_mut(0, 0, m, keep);
        matmul(product.rb_mut(), Accum::Replace, v.rb().submatrix(start, 0, m, s), y, 1.0, Par::rayon(0));
        v.rb_mut().submatrix_mut(start, 0, m, keep).copy_from(product.rb());
    }
}

/// When to run Rayleigh–Ritz before the basis is full.
///
/// A convergence check costs a dense eigendecomposition of the projected matrix, about as much as
/// one more block of the basis near its full size, so checking after every block would double the
/// work; checking only when the basis is full wastes up to a whole cycle once the last Ritz pairs
/// are within reach (on the survey bar, k = 100: 44 of 344 operator applications). The largest
/// relative residual of the wanted Ritz pairs falls about geometrically with the number of
/// operator applications, across restarts too, so the last two checks predict when it will reach
/// the tolerance, and one check is placed there. It changes when the iteration stops, never its
/// iterates: a check does not modify the basis.
#[derive(Default)]
struct ConvergenceHistory {
    /// `(operator applications, largest residual / tolerance)` of the last two checks.
    last: [Option<(usize, f64)>; 2],
}

impl ConvergenceHistory {
    fn record(&mut self, applications: usize, worst: f64) {
        self.last = [self.last[1], Some((applications, worst))];
    }

    /// Whether the residuals are predicted to be below the tolerance after `applications`.
    fn due(&self, applications: usize) -> bool {
        let [Some((a1, r1)), Some((a2, r2))] = self.last else { return false };
        if !(r2 < r1 && r2 > 0.0 && a2 > a1) || applications <= a2 {
            return false;
        }
        // ln r falls by `rate` per application.
        let rate = (r1.ln() - r2.ln()) / (a2 - a1) as f64;
        applications as f64 >= a2 as f64 + r2.ln().max(0.0) / rate
    }
}

/// The `D`-normalized constant vector when it is a null vector of `stiffness` (every row sums to
/// zero up to rounding, as for a cotangent Laplacian), else `None`.
///
/// Deflating it is a matter of accuracy, not only of work: the shift-invert operator maps it to
/// `theta = 1 / |sigma|`, about `1e8` times the next eigenvalue's, and with it in the Krylov space
/// every product carries rounding of that size, above the tolerance of the largest wanted `lambda`.
fn constant_null_vector(stiffness: SparseColMatRef<'_, usize, f64>, mass: &[f64]) -> Option<Mat<f64>> {
    let (symbolic, values) = stiffness.parts();
    let mut row_sums = vec![0.0; mass.len()];
    let mut row_scale = vec![0.0f64; mass.len()];
    for j in 0..symbolic.ncols() {
        for idx in symbolic.col_range(j) {
            let i = symbolic.row_idx()[idx];
            row_sums[i] += values[idx];
            row_scale[i] = row_scale[i].max(values[idx].abs());
        }
    }
    let null = row_sums.iter().zip(&row_scale).all(|(s, m)| s.abs() <= 1e-12 * m.max(f64::MIN_POSITIVE));
    null.then(|| {
        let value = 1.0 / mass.iter().sum::<f64>().sqrt();
        Mat::from_fn(mass.len(), 1, |_, _| value)
    })
}

/// The eigenpairs from the Krylov `values` (ascending) and `vectors` (`#V x (d + k)`, the `d`
/// deflated null vectors in front), the deflated ones' eigenvalues their Rayleigh quotients (about 0).
fn with_deflated(
    stiffness: SparseColMatRef<'_, usize, f64>,
    deflated: &Mat<f64>,
    values: Vec<f64>,
    vectors: Mat<f64>,
    restarts: usize,
    operator_applications: usize,
) -> Eigenpairs {
    let d = deflated.ncols();
    debug_assert_eq!(vectors.ncols(), d + values.len());
    let rayleigh = (0..d).map(|j| {
        let x = deflated.col(j);
        let qx = stiffness * x;
        (0..x.nrows()).map(|i| x[i] * qx[i]).sum::<f64>()
    });
    let values = rayleigh.chain(values).collect();
    Eigenpairs { values, vectors, constant_mode: None, restarts, operator_applications }
}

fn diagonal(m: SparseColMatRef<'_, usize, f64>) -> Vec<f64> {
    let (symbolic, values) = m.parts();
    (0..symbolic.ncols())
        .map(|j| {
            symbolic.col_range(j).find(|&idx| symbolic.row_idx()[idx] == j).map_or(0.0, |idx| values[idx])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::ConvergenceHistory;

    #[test]
    fn a_check_is_due_where_the_residual_trend_reaches_the_tolerance() {
        let mut checks = ConvergenceHistory::default();
        assert!(!checks.due(1000), "no trend from no checks");
        checks.record(100, 1e6);
        assert!(!checks.due(1000), "no trend from one check");
        // 1e6 -> 1e2 in 40 applications: a factor 10 per 10, so 1e0 after 20 more.
        checks.record(140, 1e2);
        assert!(!checks.due(159));
        assert!(checks.due(160));
        // A residual that did not fall predicts nothing.
        checks.record(180, 1e3);
        assert!(!checks.due(10_000));
        // Below the tolerance already (a check that stopped short of convergence for another
        // reason): due at the next block.
        checks.record(200, 0.5);
        assert!(!checks.due(200));
        assert!(checks.due(201));
    }
}
