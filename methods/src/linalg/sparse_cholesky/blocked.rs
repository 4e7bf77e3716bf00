//! The Cholesky factor `L` (in the fill-reducing ordering) re-laid out for fast multi-column
//! triangular solves.
//!
//! `L` is stored as a sequence of supernodes: column ranges `c0..c1` (width `w`) sharing one row
//! pattern `P` below the diagonal block. Faer's supernodal factors keep faer's supernodes; a
//! simplicial factor is split into fundamental supernodes (runs of consecutive columns with nested
//! patterns, often of width 1), so neither layout stores zeros beyond faer's own. Per supernode the
//! values are the packed lower triangle of the `w x w` diagonal block (row-major: row `j` holds
//! entries `0..=j`) followed by the `|P| x w` off-diagonal block, also row-major.
//!
//! The values are those of `L = M D` with `M` unit lower triangular and `D = diag(L)`: `M` off the
//! diagonal and `1 / L_jj^2` on it. `A = M D^2 M^T` is then solved by a unit lower sweep, a
//! scaling and a unit upper sweep, with no division and no scaling on the sweeps' dependency
//! chains (results agree with the `L L^T` solve up to rounding).
//!
//! The right-hand sides live in a row-major `n x K` workspace, so every stored entry drives one
//! contiguous `K`-wide multiply-add. The off-diagonal block of a supernode is applied in blocks of
//! `LB` of its columns held in registers while streaming its rows, so each right-hand-side row of
//! the pattern is read and written once per block. Kernels are const-generic in `K` so they
//! vectorize; on x86-64 CPUs with AVX2 and FMA a copy compiled for those features is selected at
//! run time (once per factor, so a given process gets bitwise reproducible results).
//!
//! A large factor is split into parts of its elimination tree that are swept on separate threads,
//! its columns placed in the workspace part by part ([`tree_split`]); a supernode's rows are then
//! its workspace rows, not its columns in faer's order ([`BlockedFactor::position`]).

// The kernels address lanes and block rows by index on purpose (fixed-size arrays the compiler
// keeps in vector registers).
#![allow(clippy::needless_range_loop)]

mod tree_split;

use std::ops::Range;

use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use rayon::prelude::*;
use tree_split::TreeSplit;

#[cfg(target_arch = "x86_64")]
use crate::linalg::row_major::Fused;
use crate::linalg::row_major::{combine, fma_available, reduce, row, row_mut, MulAdd, Separate};

/// Rows of a supernode's off-diagonal block transposed together by [`scale_supernode`]: a tile of
/// `TILE x w` values stays in cache while the `w` source columns stream through it.
const TILE: usize = 64;

/// One supernode of a supernodal factor into the blocked layout: `source` is faer's column-major
/// `(w + p) x w` block (the `w x w` diagonal block on top of the `p` pattern rows); `block` receives
/// the packed row-major diagonal block and the row-major `p x w` off-diagonal block, scaled to
/// `M = L D^-1` with `1 / L_jj^2` on the diagonal. `recip` is scratch.
fn scale_supernode(source: &[f64], w: usize, p: usize, block: &mut [f64], recip: &mut Vec<f64>) {
    let nrows = w + p;
    recip.clear();
    recip.extend((0..w).map(|j| source[j * nrows + j].recip()));
    let (diag, below) = block.split_at_mut(w * (w + 1) / 2);
    for i in 0..w {
        let row = &mut diag[i * (i + 1) / 2..][..i + 1];
        for j in 0..i {
            row[j] = source[j * nrows + i] * recip[j];
        }
        row[i] = recip[i] * recip[i];
    }
    for r0 in (0..p).step_by(TILE) {
        let rows = TILE.min(p - r0);
        let tile = &mut below[r0 * w..(r0 + rows) * w];
        for j in 0..w {
            let column = &source[j * nrows + w + r0..][..rows];
            let r = recip[j];
            for (k, &v) in column.iter().enumerate() {
                tile[k * w + j] = v * r;
            }
        }
    }
}

/// Layout of `L` plus where its values come from in faer's value array (a gather map for a
/// simplicial factor, block offsets for a supernodal one).
#[derive(Debug, Default)]
pub(super) struct BlockedFactor {
    n: usize,
    /// Rows of the workspace a solve runs in: `n`, plus the parts' copies of the top rows when the
    /// elimination tree is split ([`TreeSplit`]).
    rows: usize,
    /// Workspace row of each supernode's first column, and one past its last.
    col_start: Vec<u32>,
    col_end: Vec<u32>,
    /// Start of each supernode's row pattern in `pattern`, then the total.
    pattern_ptr: Vec<usize>,
    /// Off-diagonal-block row indices of all supernodes.
    pattern: Vec<u32>,
    /// Start of each supernode's values in `values`, then the total.
    value_ptr: Vec<usize>,
    values: Vec<f64>,
    /// `values[t] = faer_values[source[t]]` (simplicial factors; empty for supernodal ones).
    source: Vec<usize>,
    /// Supernodal factors: where each supernode's column-major block starts in faer's values.
    faer_base: Vec<usize>,
    /// Use the AVX2 + FMA kernels.
    fused: bool,
    /// Independent parts of the elimination tree swept on separate threads, if it pays.
    split: Option<TreeSplit>,
    /// Workspace row of each column of `L` in faer's (fill-reducing) order.
    position: Vec<u32>,
}

impl BlockedFactor {
    /// Structure of the factor described by faer's symbolic Cholesky (no values yet).
    pub(super) fn new(raw: &SymbolicCholeskyRaw<usize>) -> Self {
        let mut f = BlockedFactor { fused: fma_available(), ..Default::default() };
        match raw {
            SymbolicCholeskyRaw::Supernodal(sym) => {
                f.n = sym.nrows();
                let ns = sym.n_supernodes();
                let val_ptr = sym.col_ptr_for_val();
                f.col_start.reserve(ns + 1);
                f.value_ptr.push(0);
                f.pattern_ptr.push(0);
                f.faer_base.reserve(ns);
                let mut len = 0;
                for s in 0..ns {
                    let c0 = sym.supernode_begin()[s];
                    let w = sym.supernode_end()[s] - c0;
                    let pattern = sym.supernode(s).pattern();
                    f.col_start.push(to_u32(c0));
                    f.pattern.extend(pattern.iter().map(|&i| to_u32(i)));
                    f.faer_base.push(val_ptr[s]);
                    len += w * (w + 1) / 2 + pattern.len() * w;
                    f.pattern_ptr.push(f.pattern.len());
                    f.value_ptr.push(len);
                }
            }
            SymbolicCholeskyRaw::Simplicial(sym) => {
                f.n = sym.nrows();
                let n = f.n;
                let col_ptr = sym.col_ptr();
                let row_idx = sym.row_idx();
                // Faer's entries of each column sorted by row (the diagonal first).
                let mut sorted: Vec<usize> = (0..row_idx.len()).collect();
                for j in 0..n {
                    let range = col_ptr[j]..col_ptr[j + 1];
                    sorted[range.clone()].sort_unstable_by_key(|&t| row_idx[t]);
                    assert!(
                        !range.is_empty() && row_idx[sorted[range.start]] == j,
                        "simplicial Cholesky column {j} lacks its diagonal"
                    );
                }
                let rows = |j: usize| sorted[col_ptr[j]..col_ptr[j + 1]].iter().map(|&t| row_idx[t]);
                f.value_ptr.push(0);
                f.pattern_ptr.push(0);
                f.source.reserve(row_idx.len());
                let mut c0 = 0;
                while c0 < n {
                    // Grow the supernode while column c1 - 1's rows below its diagonal are column c1's rows.
                    let mut c1 = c0 + 1;
                    while c1 < n && rows(c1 - 1).skip(1).eq(rows(c1)) {
                        c1 += 1;
                    }
                    let w = c1 - c0;
                    f.col_start.push(to_u32(c0));
                    f.pattern.extend(rows(c1 - 1).skip(1).map(to_u32));
                    let p = f.pattern.len() - f.pattern_ptr.last().unwrap();
                    // Column c0 + j holds rows c0 + j..c1 (offsets 0..w - j), then the pattern.
                    let at = |i: usize, j: usize| sorted[col_ptr[c0 + j] + i - j];
                    for i in 0..w {
                        f.source.extend((0..=i).map(|j| at(i, j)));
                    }
                    for r in 0..p {
                        f.source.extend((0..w).map(|j| at(w + r, j)));
                    }
                    f.pattern_ptr.push(f.pattern.len());
                    f.value_ptr.push(f.source.len());
                    c0 = c1;
                }
            }
        }
        f.col_end = f.col_start.iter().skip(1).copied().chain([to_u32(f.n)]).collect();
        f.rows = f.n;
        f.position = (0..f.n).map(to_u32).collect();
        f.values = vec![0.0; *f.value_ptr.last().expect("value_ptr starts with 0")];
        if let Some(owner) = tree_split::choose(&f) {
            f.reorder(&owner);
        }
        f
    }

    /// Rows of the workspace [`BlockedFactor::solve_row_major`] runs in (at least the order `n`).
    pub(super) fn rows(&self) -> usize {
        self.rows
    }

    /// Workspace row of column `c` of `L` (faer's fill-reducing order).
    pub(super) fn position(&self, c: usize) -> usize {
        self.position[c] as usize
    }

    /// Supernode `s`: its first and one-past-last workspace rows, its pattern, and its diagonal
    /// and off-diagonal values.
    #[inline(always)]
    fn supernode(&self, s: usize) -> (usize, usize, &[u32], &[f64], &[f64]) {
        let (c0, c1) = (self.col_start[s] as usize, self.col_end[s] as usize);
        let w = c1 - c0;
        let pattern = &self.pattern[self.pattern_ptr[s]..self.pattern_ptr[s + 1]];
        let (diag, below) = self.values[self.value_ptr[s]..self.value_ptr[s + 1]].split_at(w * (w + 1) / 2);
        (c0, c1, pattern, diag, below)
    }

    /// Take the numeric values of faer's factor (laid out as described by the symbolic structure
    /// this was built from), in the scaled form described in the module documentation.
    pub(super) fn set_values(&mut self, faer_values: &[f64]) {
        if self.faer_base.is_empty() {
            for (v, &t) in self.values.iter_mut().zip(&self.source) {
                *v = faer_values[t];
            }
        }
        // M = L D^-1 below the diagonal, 1 / L_jj^2 on it.
        let mut recip = Vec::new();
        for s in 0..self.n_supernodes() {
            let w = (self.col_end[s] - self.col_start[s]) as usize;
            let block = &mut self.values[self.value_ptr[s]..self.value_ptr[s + 1]];
            if let Some(&base) = self.faer_base.get(s) {
                // Faer's column-major `nrows x w` block, entry (i, j) at base + j * nrows + i:
                // transposed and scaled in one pass (the same products as the gather below).
                let p = self.pattern_ptr[s + 1] - self.pattern_ptr[s];
                let source = &faer_values[base..base + (w + p) * w];
                scale_supernode(source, w, p, block, &mut recip);
                continue;
            }
            let (diag, below) = block.split_at_mut(w * (w + 1) / 2);
            recip.clear();
            recip.extend((0..w).map(|j| diag[j * (j + 1) / 2 + j].recip()));
            for i in 0..w {
                let row = &mut diag[i * (i + 1) / 2..][..i + 1];
                for (v, r) in row[..i].iter_mut().zip(&recip) {
                    *v *= r;
                }
                row[i] = recip[i] * recip[i];
            }
            for row in below.chunks_exact_mut(w) {
                for (v, r) in row.iter_mut().zip(&recip) {
                    *v *= r;
                }
            }
        }
    }

    pub(super) fn n_supernodes(&self) -> usize {
        self.col_start.len()
    }

    /// Use the portable kernels even where AVX2 and FMA are available.
    #[cfg(test)]
    pub(super) fn disable_fma(&mut self) {
        self.fused = false;
    }

    /// Stored values swept by each part and by the top of the tree split, if the factor is split.
    #[cfg(test)]
    pub(super) fn split_loads(&self) -> Option<(Vec<usize>, usize)> {
        self.split.as_ref().map(|split| split.loads(self))
    }

    /// Stored values of the factor in this layout.
    #[cfg(test)]
    pub(super) fn n_values(&self) -> usize {
        self.values.len()
    }

    /// Width of the widest supernode.
    #[cfg(test)]
    pub(super) fn max_supernode_width(&self) -> usize {
        self.col_start.iter().zip(&self.col_end).map(|(a, b)| (b - a) as usize).max().unwrap_or(0)
    }

    /// Solve `L L^T X = B` in place for a row-major `rows() x k` block `x` (`x[r * k + j]`), the
    /// right-hand side of column `c` of `L` in row `position(c)` (the other rows are workspace), `k`
    /// one of 1, 2, 4, 8, 16 (pad other widths with zero columns).
    pub(super) fn solve_row_major(&self, x: &mut [f64], k: usize) {
        assert_eq!(x.len(), self.rows * k);
        // Per width: accumulator sets of the dense row combinations (`NA`) and column block of the
        // off-diagonal updates (`LB`), so that enough independent vector accumulators are in flight.
        match k {
            1 => self.solve_k::<1, 8, 16>(x),
            2 => self.solve_k::<2, 8, 16>(x),
            4 => self.solve_k::<4, 4, 8>(x),
            8 => self.solve_k::<8, 2, 4>(x),
            16 => self.solve_k::<16, 1, 2>(x),
            _ => panic!("unsupported block width {k}"),
        }
    }

    /// The forward sweep, then the backward one; with a [`TreeSplit`], its parts on rayon threads
    /// and the top on this one (see [`tree_split`]).
    fn solve_k<const K: usize, const NA: usize, const LB: usize>(&self, x: &mut [f64]) {
        let Some(split) = &self.split else {
            let all = 0..self.n_supernodes();
            self.sweep::<K, NA, LB>(Sweep::Forward, all.clone(), x, 0);
            self.sweep::<K, NA, LB>(Sweep::Backward, all, x, 0);
            return;
        };
        let top_base = split.top_rows.start;
        let (body, top) = x.split_at_mut(top_base * K);
        let mut regions: Vec<(&tree_split::Part, &mut [f64])> = Vec::with_capacity(split.parts.len());
        let mut rest = body;
        for part in &split.parts {
            let (region, after) = std::mem::take(&mut rest).split_at_mut(part.rows.len() * K);
            regions.push((part, region));
            rest = after;
        }
        // Forward: each part sweeps its subtrees, sending its updates of the top rows to its own
        // copy of them (zeroed first); the copies are added in part order, so the result does not
        // depend on the number of threads.
        regions.par_iter_mut().for_each(|(part, region)| {
            region[(part.scratch - part.rows.start) * K..].fill(0.0);
            self.sweep::<K, NA, LB>(Sweep::Forward, part.supernodes.clone(), region, part.rows.start);
        });
        for (part, region) in &regions {
            for (t, u) in top.iter_mut().zip(&region[(part.scratch - part.rows.start) * K..]) {
                *t += u;
            }
        }
        self.sweep::<K, NA, LB>(Sweep::Forward, split.top.clone(), top, top_base);
        // Backward: the top first, then each part with a copy of the top rows' final values.
        self.sweep::<K, NA, LB>(Sweep::Backward, split.top.clone(), top, top_base);
        let top: &[f64] = top;
        regions.par_iter_mut().for_each(|(part, region)| {
            region[(part.scratch - part.rows.start) * K..].copy_from_slice(top);
            self.sweep::<K, NA, LB>(Sweep::Backward, part.supernodes.clone(), region, part.rows.start);
        });
    }

    /// One sweep over `supernodes` (in order forward, in reverse backward) on `region`, the
    /// workspace rows from `base` on; every row the supernodes touch lies in it.
    fn sweep<const K: usize, const NA: usize, const LB: usize>(
        &self,
        direction: Sweep,
        supernodes: Range<usize>,
        region: &mut [f64],
        base: usize,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.fused {
            // SAFETY: `fused` is only set when the CPU supports AVX2 and FMA.
            unsafe { sweep_avx2_fma::<K, NA, LB>(self, direction, supernodes, region, base) };
            return;
        }
        #[cfg(not(target_arch = "x86_64"))]
        debug_assert!(!self.fused);
        sweep::<K, NA, LB, Separate>(self, direction, supernodes, region, base);
    }
}

/// Direction of a triangular sweep: `M z = b` column by column, or `M^T x = y` in reverse.
#[derive(Clone, Copy, Debug)]
enum Sweep {
    Forward,
    Backward,
}

/// Width of the workspace block used for `k` right-hand-side columns (`1 <= k <= 16`).
pub(super) fn padded_width(k: usize) -> usize {
    debug_assert!((1..=16).contains(&k));
    k.next_power_of_two()
}

fn to_u32(i: usize) -> u32 {
    u32::try_from(i).expect("matrix order exceeds u32 indices")
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn sweep_avx2_fma<const K: usize, const NA: usize, const LB: usize>(
    f: &BlockedFactor,
    direction: Sweep,
    supernodes: Range<usize>,
    region: &mut [f64],
    base: usize,
) {
    sweep::<K, NA, LB, Fused>(f, direction, supernodes, region, base);
}

/// `sum_r coef[r] * x[rows[r] - offset, :]`, like [`combine`](crate::linalg::row_major::combine) but gathering the rows of `x`.
#[inline(always)]
fn gather_combine<const K: usize, const NA: usize, M: MulAdd>(
    coef: &[f64],
    rows: &[u32],
    offset: usize,
    x: &[f64],
) -> [f64; K] {
    let mut acc = [[0.0; K]; NA];
    let cs = coef.chunks_exact(NA);
    let rs = rows.chunks_exact(NA);
    let (c_rest, r_rest) = (cs.remainder(), rs.remainder());
    for (c, r) in cs.zip(rs) {
        for u in 0..NA {
            let xr = row::<K>(x, r[u] as usize - offset);
            for q in 0..K {
                acc[u][q] = M::mul_add(acc[u][q], c[u], xr[q]);
            }
        }
    }
    for u in 0..NA {
        if u < c_rest.len() {
            let xr = row::<K>(x, r_rest[u] as usize - offset);
            for q in 0..K {
                acc[u][q] = M::mul_add(acc[u][q], c_rest[u], xr[q]);
            }
        }
    }
    reduce(acc)
}

/// `top[l, :] -= sum_r below[r, l] * x[pattern[r] - offset, :]` for the columns `l` of `l0..` in
/// blocks of `LB` (accumulated in registers across the rows); returns the first column not done.
#[inline(always)]
fn transposed_update<const K: usize, const LB: usize, M: MulAdd>(
    pattern: &[u32],
    below: &[f64],
    w: usize,
    x: &[f64],
    offset: usize,
    top: &mut [f64],
    mut l0: usize,
) -> usize {
    while l0 + LB <= w {
        let mut acc = [[0.0; K]; LB];
        for (&i, lrow) in pattern.iter().zip(below.chunks_exact(w)) {
            let xi = row::<K>(x, i as usize - offset);
            let lr = &lrow[l0..l0 + LB];
            for u in 0..LB {
                for q in 0..K {
                    acc[u][q] = M::mul_add(acc[u][q], lr[u], xi[q]);
                }
            }
        }
        for (u, a) in acc.iter().enumerate() {
            let t = row_mut::<K>(top, l0 + u);
            for q in 0..K {
                t[q] -= a[q];
            }
        }
        l0 += LB;
    }
    l0
}

/// `x[pattern[r] - offset, :] -= sum_l below[r, l] * top[l, :]` for the columns `l` of `l0..` in
/// blocks of `LB` (whose rows of `top` stay in registers across the rows `r`); returns the first
/// column not done.
#[inline(always)]
fn below_update<const K: usize, const LB: usize, M: MulAdd>(
    pattern: &[u32],
    below: &[f64],
    w: usize,
    x: &mut [f64],
    offset: usize,
    top: &[f64],
    mut l0: usize,
) -> usize {
    while l0 + LB <= w {
        let mut t = [[0.0; K]; LB];
        for (u, tu) in t.iter_mut().enumerate() {
            *tu = *row::<K>(top, l0 + u);
        }
        for (&i, lrow) in pattern.iter().zip(below.chunks_exact(w)) {
            let lr = &lrow[l0..l0 + LB];
            let xi = row_mut::<K>(x, i as usize - offset);
            let mut acc = *xi;
            for u in 0..LB {
                for q in 0..K {
                    acc[q] = M::mul_add(acc[q], -lr[u], t[u][q]);
                }
            }
            *xi = acc;
        }
        l0 += LB;
    }
    l0
}

/// One supernode's part of the forward sweep: `M z = b` on its rows, the update of the pattern rows,
/// then `y = D^-2 z` on its rows.
#[inline(always)]
fn forward_supernode<const K: usize, const NA: usize, const LB: usize, M: MulAdd>(
    c1: usize,
    pattern: &[u32],
    diag: &[f64],
    below: &[f64],
    top: &mut [f64],
    tail: &mut [f64],
) {
    let w = top.len() / K;
    if w == 1 {
        let z = row_mut::<K>(top, 0);
        for (&i, &l) in pattern.iter().zip(below) {
            let xi = row_mut::<K>(tail, i as usize - c1);
            for q in 0..K {
                xi[q] = M::mul_add(xi[q], -l, z[q]);
            }
        }
        for v in z {
            *v *= diag[0];
        }
        return;
    }
    // Unit lower-triangular solve on the diagonal block, by rows; the contribution of row j - 1
    // comes last so that a single multiply-add lies on the dependency chain.
    let mut off = 1;
    for j in 1..w {
        let lrow = &diag[off..off + j];
        off += j + 1;
        let (before, rest) = top.split_at_mut(j * K);
        let sum = combine::<K, NA, M>(&lrow[..j - 1], &before[..(j - 1) * K]);
        let prev = row::<K>(before, j - 1);
        let xj = row_mut::<K>(rest, 0);
        for q in 0..K {
            xj[q] = M::mul_add(xj[q] - sum[q], -lrow[j - 1], prev[q]);
        }
    }
    // Pattern rows: x[i, :] -= M[i, c0..c1] z[c0..c1, :].
    if K >= 4 {
        let top = &*top;
        let mut l0 = below_update::<K, LB, M>(pattern, below, w, tail, c1, top, 0);
        if 8 < LB {
            l0 = below_update::<K, 8, M>(pattern, below, w, tail, c1, top, l0);
        }
        if 4 < LB {
            l0 = below_update::<K, 4, M>(pattern, below, w, tail, c1, top, l0);
        }
        if 2 < LB {
            l0 = below_update::<K, 2, M>(pattern, below, w, tail, c1, top, l0);
        }
        below_update::<K, 1, M>(pattern, below, w, tail, c1, top, l0);
    } else {
        // Too narrow to fill vector registers across K: dot products along the rows instead.
        for (&i, lrow) in pattern.iter().zip(below.chunks_exact(w)) {
            let sum = combine::<K, NA, M>(lrow, top);
            let xi = row_mut::<K>(tail, i as usize - c1);
            for q in 0..K {
                xi[q] -= sum[q];
            }
        }
    }
    for (j, xj) in top.chunks_exact_mut(K).enumerate() {
        let scale = diag[j * (j + 1) / 2 + j];
        for v in xj {
            *v *= scale;
        }
    }
}

/// One supernode's part of the backward sweep: `M^T x = y` on its rows, given the final values of
/// its pattern rows.
#[inline(always)]
fn backward_supernode<const K: usize, const NA: usize, const LB: usize, M: MulAdd>(
    c1: usize,
    pattern: &[u32],
    diag: &[f64],
    below: &[f64],
    top: &mut [f64],
    tail: &[f64],
) {
    let w = top.len() / K;
    if w == 1 {
        let sum = gather_combine::<K, NA, M>(below, pattern, c1, tail);
        let xt = row_mut::<K>(top, 0);
        for q in 0..K {
            xt[q] -= sum[q];
        }
        return;
    }
    // x[c0..c1, :] -= M[P, c0..c1]^T x[P, :], in column blocks of LB, then narrower ones.
    let mut l0 = transposed_update::<K, LB, M>(pattern, below, w, tail, c1, top, 0);
    if 16 < LB {
        l0 = transposed_update::<K, 16, M>(pattern, below, w, tail, c1, top, l0);
    }
    if 8 < LB {
        l0 = transposed_update::<K, 8, M>(pattern, below, w, tail, c1, top, l0);
    }
    if 4 < LB {
        l0 = transposed_update::<K, 4, M>(pattern, below, w, tail, c1, top, l0);
    }
    if 2 < LB {
        l0 = transposed_update::<K, 2, M>(pattern, below, w, tail, c1, top, l0);
    }
    transposed_update::<K, 1, M>(pattern, below, w, tail, c1, top, l0);
    // Unit upper-triangular solve with the diagonal block's transpose, by columns of M (strided in
    // the packed rows); the contribution of row j + 1 comes last, as in the forward sweep.
    for j in (0..w - 1).rev() {
        let (before, after) = top.split_at_mut((j + 1) * K);
        let mut acc = [[0.0; K]; NA];
        let mut l = j + 2;
        while l + NA <= w {
            for (u, a) in acc.iter_mut().enumerate() {
                let m = diag[(l + u) * (l + u + 1) / 2 + j];
                let xl = row::<K>(after, l + u - j - 1);
                for q in 0..K {
                    a[q] = M::mul_add(a[q], m, xl[q]);
                }
            }
            l += NA;
        }
        for (u, a) in acc.iter_mut().enumerate() {
            if l + u < w {
                let m = diag[(l + u) * (l + u + 1) / 2 + j];
                let xl = row::<K>(after, l + u - j - 1);
                for q in 0..K {
                    a[q] = M::mul_add(a[q], m, xl[q]);
                }
            }
        }
        let sum = reduce(acc);
        let m = diag[(j + 1) * (j + 2) / 2 + j];
        let next = row::<K>(after, 0);
        let xj = row_mut::<K>(before, j);
        for q in 0..K {
            xj[q] = M::mul_add(xj[q] - sum[q], -m, next[q]);
        }
    }
}

#[inline(always)]
fn sweep<const K: usize, const NA: usize, const LB: usize, M: MulAdd>(
    f: &BlockedFactor,
    direction: Sweep,
    supernodes: Range<usize>,
    x: &mut [f64],
    base: usize,
) {
    match direction {
        Sweep::Forward => {
            for s in supernodes {
                let (c0, c1, pattern, diag, below) = f.supernode(s);
                let (top, tail) = rows_and_below::<K>(x, c0, c1, base);
                forward_supernode::<K, NA, LB, M>(c1, pattern, diag, below, top, tail);
            }
        }
        Sweep::Backward => {
            for s in supernodes.rev() {
                let (c0, c1, pattern, diag, below) = f.supernode(s);
                let (top, tail) = rows_and_below::<K>(x, c0, c1, base);
                backward_supernode::<K, NA, LB, M>(c1, pattern, diag, below, top, tail);
            }
        }
    }
}

/// Rows `c0..c1` of the row-major block `x` (`K` wide, holding workspace rows from `base` on), and
/// the rows after them.
#[inline(always)]
fn rows_and_below<const K: usize>(
    x: &mut [f64],
    c0: usize,
    c1: usize,
    base: usize,
) -> (&mut [f64], &mut [f64]) {
    let (head, tail) = x.split_at_mut((c1 - base) * K);
    (&mut head[(c0 - base) * K..], tail)
}
