//! What several test files of `methods` need: the entries of a sparse matrix, a dense copy, and
//! deterministic noise. Each test binary uses a part of it.
#![allow(dead_code)]

use faer::sparse::SparseColMat;

/// `(i, j, value)` of every stored entry.
pub fn entries(l: &SparseColMat<usize, f64>) -> Vec<(usize, usize, f64)> {
    let (s, v) = l.parts();
    (0..s.ncols()).flat_map(|j| s.col_range(j).map(move |idx| (s.row_idx()[idx], j, v[idx]))).collect()
}

/// `l` as a dense `#rows x #cols` matrix (repeated entries summed).
pub fn dense(l: &SparseColMat<usize, f64>) -> Vec<Vec<f64>> {
    let mut d = vec![vec![0.0; l.ncols()]; l.nrows()];
    for (i, j, v) in entries(l) {
        d[i][j] += v;
    }
    d
}

/// Deterministic pseudo-random numbers in `[-1, 1)` (splitmix64).
pub fn noise(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}
