//! Block Gram–Schmidt in the `D` inner product `<x, y>_D = x^T diag(mass) y`, the orthogonalization
//! of the block Krylov–Schur eigensolver.
//!
//! [`project_out`] is `W <- W - V (V^T D W)` for a tall `#V x m` basis `V` and a thin `#V x b` block
//! `W`. It reads `V` twice per pass and does two flops per entry read, so it is bound by memory
//! bandwidth: a general matrix product (which packs `V` before multiplying) spends as long copying
//! `V` as multiplying with it. The kernels here stream the columns of `V` once per product instead,
//! with `W` (and `D W`) kept row-major in chunks of [`ROWS`] rows that stay in L1, every row of the
//! block one `K`-wide vector (`K` = `b` padded to a power of two). The two halves of the work run on
//! two threads: the columns of `V` for `V^T D W`, the rows of `W` for the update, so every result
//! entry is computed by one thread in a fixed order and results do not depend on scheduling.

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};

use super::random::SplitMix64;
#[cfg(target_arch = "x86_64")]
use crate::linalg::row_major::Fused;
use crate::linalg::row_major::{combine, fma_available, row_mut, MulAdd, Separate};

/// Rows of `W` processed together: a `ROWS x K` row-major chunk (8 KiB for `K = 4`) stays in L1
/// while the columns of `V` stream past it.
const ROWS: usize = 256;

/// Below this many entries of `V` (`#V x m`) one thread does the whole product.
const PARALLEL_MIN_ENTRIES: usize = 1 << 20;

/// `<a_i, b_j>_D` for columns `i` of `a` and `j` of `b`.
pub(super) fn d_dot(a: MatRef<'_, f64>, i: usize, b: MatRef<'_, f64>, j: usize, mass: &[f64]) -> f64 {
    let (a, b) = (a.col(i), b.col(j));
    (0..mass.len()).map(|r| mass[r] * a[r] * b[r]).sum()
}

/// `D`-norms of the columns of `w`.
pub(super) fn column_norms(w: MatRef<'_, f64>, mass: &[f64]) -> Vec<f64> {
    (0..w.ncols()).map(|j| d_dot(w, j, w, j, mass).sqrt()).collect()
}

/// `W <- W - V (V^T D W)`, `passes` times, for `W` (`#V x b`) and `V` (`#V x m`, unit row stride);
/// returns the accumulated coefficients `V^T D W` (`m x b`). Allocates its workspace; the hot
/// loop of the eigensolver uses a [`Projector`] instead.
pub(super) fn project_out(w: MatMut<'_, f64>, v: MatRef<'_, f64>, mass: &[f64], passes: usize) -> Mat<f64> {
    Projector::default().project_out(w, v, mass, passes)
}

/// [`project_out`] with its row-major workspace (two `#V x K` blocks) kept between calls.
#[derive(Default)]
pub(super) struct Projector {
    rows: Vec<f64>,
    weighted: Vec<f64>,
}

impl Projector {
    /// See [`project_out`].
    pub(super) fn project_out(
        &mut self,
        w: MatMut<'_, f64>,
        v: MatRef<'_, f64>,
        mass: &[f64],
        passes: usize,
    ) -> Mat<f64> {
        let mut total = Mat::<f64>::zeros(v.ncols(), w.ncols());
        for c in self.project_out_in_turn(w, &vec![v; passes], mass) {
            total += c;
        }
        total
    }

    /// `W <- W - V_t (V_t^T D W)` for the bases `V_t` (`#V x m_t`, unit row stride) in turn, with
    /// `W` kept in the row-major workspace throughout; returns every pass's coefficients
    /// (`m_t x b`).
    pub(super) fn project_out_in_turn(
        &mut self,
        w: MatMut<'_, f64>,
        bases: &[MatRef<'_, f64>],
        mass: &[f64],
    ) -> Vec<Mat<f64>> {
        let b = w.ncols();
        if b == 0 || bases.iter().all(|v| v.ncols() == 0) {
            return bases.iter().map(|v| Mat::zeros(v.ncols(), b)).collect();
        }
        let fused = fma_available();
        match b.next_power_of_two() {
            1 => self.project_out_k::<1>(w, bases, mass, fused),
            2 => self.project_out_k::<2>(w, bases, mass, fused),
            4 => self.project_out_k::<4>(w, bases, mass, fused),
            8 => self.project_out_k::<8>(w, bases, mass, fused),
            16 => self.project_out_k::<16>(w, bases, mass, fused),
            _ => project_out_general(w, bases, mass),
        }
    }

    /// [`Projector::project_out_in_turn`] with `W` held row-major, `K` columns wide (`b <= K`,
    /// padded with zeros).
    fn project_out_k<const K: usize>(
        &mut self,
        mut w: MatMut<'_, f64>,
        bases: &[MatRef<'_, f64>],
        mass: &[f64],
        fused: bool,
    ) -> Vec<Mat<f64>> {
        let (n, b) = (w.nrows(), w.ncols());
        let (rows, weighted) = (&mut self.rows, &mut self.weighted);
        rows.resize(n * K, 0.0);
        weighted.resize(n * K, 0.0);
        let (rows, weighted) = (&mut rows[..n * K], &mut weighted[..n * K]);
        for j in 0..K {
            match w.rb().col(j.min(b - 1)).try_as_col_major() {
                Some(col) if j < b => {
                    for (x, &y) in rows.chunks_exact_mut(K).zip(col.as_slice()) {
                        x[j] = y;
                    }
                }
                _ if j < b => (0..n).for_each(|i| rows[i * K + j] = w[(i, j)]),
                _ => rows.chunks_exact_mut(K).for_each(|x| x[j] = 0.0),
            }
        }
        let mut out = Vec::with_capacity(bases.len());
        for v in bases {
            let m = v.ncols();
            let columns: Vec<&[f64]> = (0..m)
                .map(|p| v.col(p).try_as_col_major().expect("basis with unit row stride").as_slice())
                .collect();
            let mut coefficients = vec![[0.0; K]; m];
            if m > 0 {
                for (i, (dw, w)) in weighted.chunks_exact_mut(K).zip(rows.chunks_exact(K)).enumerate() {
                    for q in 0..K {
                        dw[q] = mass[i] * w[q];
                    }
                }
                let parallel = n * m >= PARALLEL_MIN_ENTRIES && rayon::current_num_threads() > 1;
                pass::<K>(&columns, weighted, rows, &mut coefficients, parallel, fused);
            }
            out.push(Mat::from_fn(m, b, |p, j| coefficients[p][j]));
        }
        for j in 0..b {
            match w.rb_mut().col_mut(j).try_as_col_major_mut() {
                Some(col) => {
                    for (y, x) in col.as_slice_mut().iter_mut().zip(rows.chunks_exact(K)) {
                        *y = x[j];
                    }
                }
                None => (0..n).for_each(|i| w[(i, j)] = rows[i * K + j]),
            }
        }
        out
    }
}

/// [`Projector::project_out_in_turn`] by general matrix products, for blocks wider than 16
/// columns.
fn project_out_general(mut w: MatMut<'_, f64>, bases: &[MatRef<'_, f64>], mass: &[f64]) -> Vec<Mat<f64>> {
    bases
        .iter()
        .map(|v| {
            let mut c = Mat::<f64>::zeros(v.ncols(), w.ncols());
            let dw = Mat::from_fn(w.nrows(), w.ncols(), |i, j| mass[i] * w[(i, j)]);
            matmul(c.as_mut(), Accum::Replace, v.transpose(), dw.as_ref(), 1.0, Par::rayon(0));
            matmul(w.rb_mut(), Accum::Add, v, c.as_ref(), -1.0, Par::rayon(0));
            c
        })
        .collect()
}

/// One classical Gram–Schmidt pass: `coefficients = V^T (D W)`, then `W -= V coefficients`.
fn pass<const K: usize>(
    columns: &[&[f64]],
    weighted: &[f64],
    rows: &mut [f64],
    coefficients: &mut [[f64; K]],
    parallel: bool,
    fused: bool,
) {
    if parallel {
        let half = columns.len().div_ceil(2);
        let (c_left, c_right) = coefficients.split_at_mut(half);
        rayon::join(
            || transpose_product::<K>(&columns[..half], weighted, c_left, fused),
            || transpose_product::<K>(&columns[half..], weighted, c_right, fused),
        );
        let n = rows.len() / K;
        let split = (n.div_ceil(2).div_ceil(ROWS) * ROWS).min(n);
        let (top, bottom) = rows.split_at_mut(split * K);
        let coefficients = &*coefficients;
        rayon::join(
            || subtract_product::<K>(columns, coefficients, top, 0, fused),
            || subtract_product::<K>(columns, coefficients, bottom, split, fused),
        );
    } else {
        transpose_product::<K>(columns, weighted, coefficients, fused);
        subtract_product::<K>(columns, coefficients, rows, 0, fused);
    }
}

// The kernels are dispatched one by one (not from a caller compiled with the features) because
// closures, such as those handed to `rayon::join`, do not inherit target features.

fn transpose_product<const K: usize>(columns: &[&[f64]], x: &[f64], c: &mut [[f64; K]], fused: bool) {
    #[cfg(target_arch = "x86_64")]
    if fused {
        // SAFETY: `fused` is only set when the CPU supports AVX2 and FMA.
        unsafe { transpose_product_avx2_fma::<K>(columns, x, c) };
        return;
    }
    debug_assert!(!fused);
    transpose_product_kernel::<K, Separate>(columns, x, c);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn transpose_product_avx2_fma<const K: usize>(columns: &[&[f64]], x: &[f64], c: &mut [[f64; K]]) {
    transpose_product_kernel::<K, Fused>(columns, x, c);
}

fn subtract_product<const K: usize>(
    columns: &[&[f64]],
    c: &[[f64; K]],
    rows: &mut [f64],
    offset: usize,
    fused: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if fused {
        // SAFETY: `fused` is only set when the CPU supports AVX2 and FMA.
        unsafe { subtract_product_avx2_fma::<K>(columns, c, rows, offset) };
        return;
    }
    debug_assert!(!fused);
    subtract_product_kernel::<K, Separate>(columns, c, rows, offset);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn subtract_product_avx2_fma<const K: usize>(
    columns: &[&[f64]],
    c: &[[f64; K]],
    rows: &mut [f64],
    offset: usize,
) {
    subtract_product_kernel::<K, Fused>(columns, c, rows, offset);
}

/// `c[p, :] = columns[p]^T x` for the row-major `n x K` block `x`, summed chunk by chunk of
/// [`ROWS`] rows in a fixed order.
#[inline(always)]
fn transpose_product_kernel<const K: usize, M: MulAdd>(columns: &[&[f64]], x: &[f64], c: &mut [[f64; K]]) {
    c.iter_mut().for_each(|c| *c = [0.0; K]);
    let n = x.len() / K;
    for r0 in (0..n).step_by(ROWS) {
        let r1 = (r0 + ROWS).min(n);
        let chunk = &x[r0 * K..r1 * K];
        for (column, c) in columns.iter().zip(c.iter_mut()) {
            let part = combine::<K, 4, M>(&column[r0..r1], chunk);
            for q in 0..K {
                c[q] += part[q];
            }
        }
    }
}

/// `rows[i, :] -= sum_p columns[p][offset + i] c[p, :]` for the row-major block `rows` that
/// starts at row `offset` of the columns; four columns at a time, their coefficients in registers.
#[inline(always)]
fn subtract_product_kernel<const K: usize, M: MulAdd>(
    columns: &[&[f64]],
    c: &[[f64; K]],
    rows: &mut [f64],
    offset: usize,
) {
    const LB: usize = 4;
    let n = rows.len() / K;
    for r0 in (0..n).step_by(ROWS) {
        let r1 = (r0 + ROWS).min(n);
        let chunk = &mut rows[r0 * K..r1 * K];
        let (a, b) = (offset + r0, offset + r1);
        let mut p = 0;
        while p + LB <= columns.len() {
            let t: [[f64; K]; LB] = std::array::from_fn(|u| c[p + u]);
            let cols: [&[f64]; LB] = std::array::from_fn(|u| &columns[p + u][a..b]);
            for i in 0..r1 - r0 {
                let x = row_mut::<K>(chunk, i);
                let mut acc = *x;
                for u in 0..LB {
                    for q in 0..K {
                        acc[q] = M::mul_add(acc[q], -cols[u][i], t[u][q]);
                    }
                }
                *x = acc;
            }
            p += LB;
        }
        for (column, t) in columns[p..].iter().zip(&c[p..]) {
            let col = &column[a..b];
            for i in 0..r1 - r0 {
                let x = row_mut::<K>(chunk, i);
                for q in 0..K {
                    x[q] = M::mul_add(x[q], -col[i], t[q]);
                }
            }
        }
    }
}

/// `D`-orthonormalize the columns of `W` (already orthogonal to `basis`) by modified Gram–Schmidt
/// applied twice, returning the upper triangular `R` with `W_in = W_out R`. A column that vanishes
/// (below 1e-10 of its norm before projection, `norms`) means the Krylov space became invariant; it
/// is replaced by a random vector orthogonal to everything (`basis`, the `deflated` vectors and the
/// block's other columns), with a zero in `R`.
pub(super) fn orthonormalize_block(
    mut w: MatMut<'_, f64>,
    norms: &[f64],
    basis: MatRef<'_, f64>,
    deflated: MatRef<'_, f64>,
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
            project_out(w.rb_mut().subcols_mut(c, 1), deflated, mass, 2);
            project_out(w.rb_mut().subcols_mut(c, 1), basis, mass, 2);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn sum(blocks: Vec<Mat<f64>>) -> Mat<f64> {
        blocks.into_iter().reduce(|a, b| a + b).expect("at least one pass")
    }

    fn block(n: usize, k: usize, seed: u64) -> Mat<f64> {
        let mut rng = SplitMix64::new(seed);
        Mat::from_fn(n, k, |_, _| rng.symmetric_unit())
    }

    /// The streaming kernels against `W - V (V^T D W)` by faer's matrix products, for every
    /// supported width, both kernel variants, sizes that leave partial row chunks and column groups,
    /// and on both sides of the parallel threshold.
    #[test]
    fn project_out_matches_general_products() {
        for (n, m) in [(1000, 7), (3001, 45), (5000, 30)] {
            let v = block(n, m, 1);
            let mass: Vec<f64> = (0..n).map(|i| 0.5 + (i % 7) as f64 * 0.1).collect();
            for b in [1, 2, 3, 4, 5, 8, 11, 16, 20] {
                let w = block(n, b, 2);
                let mut expected = w.clone();
                let c_expected =
                    sum(project_out_general(expected.as_mut(), &[v.as_ref(), v.as_ref()], &mass));
                let mut p = Projector::default();
                for fused in [false, fma_available()] {
                    let mut ours = w.clone();
                    let c = match b.next_power_of_two() {
                        1 => p.project_out_k::<1>(ours.as_mut(), &[v.as_ref(), v.as_ref()], &mass, fused),
                        2 => p.project_out_k::<2>(ours.as_mut(), &[v.as_ref(), v.as_ref()], &mass, fused),
                        4 => p.project_out_k::<4>(ours.as_mut(), &[v.as_ref(), v.as_ref()], &mass, fused),
                        8 => p.project_out_k::<8>(ours.as_mut(), &[v.as_ref(), v.as_ref()], &mass, fused),
                        16 => p.project_out_k::<16>(ours.as_mut(), &[v.as_ref(), v.as_ref()], &mass, fused),
                        _ => project_out_general(ours.as_mut(), &[v.as_ref(), v.as_ref()], &mass),
                    };
                    let c = sum(c);
                    let dw = (&ours - &expected).norm_max() / expected.norm_max();
                    let dc = (&c - &c_expected).norm_max() / c_expected.norm_max();
                    assert!(dw < 1e-12 && dc < 1e-12, "n {n} m {m} b {b} fused {fused}: {dw:e} {dc:e}");
                }
            }
        }
    }

    #[test]
    fn projection_is_reproducible() {
        let (n, m, b) = (4000, 60, 4);
        let v = block(n, m, 3);
        let mass = vec![1.5; n];
        let w = block(n, b, 4);
        let (mut x, mut y) = (w.clone(), w.clone());
        let cx = project_out(x.as_mut(), v.as_ref(), &mass, 1);
        let cy = project_out(y.as_mut(), v.as_ref(), &mass, 1);
        assert!(x == y && cx == cy);
    }
}
