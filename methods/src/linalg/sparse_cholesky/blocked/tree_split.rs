//! Independent parts of the elimination tree, so that a triangular solve runs on several threads.
//!
//! Supernodes in different subtrees of the (supernodal) elimination tree touch disjoint rows,
//! except for the rows of their common ancestors. So the forest is cut into a *top* (the
//! ancestors, swept on one thread) and subtrees, and the subtrees are dealt to [`PARTS`] parts
//! of about equal work (the stored values they sweep). A part sweeps its subtrees on its own
//! thread; its forward updates of top rows go to its own copy of the top rows, which are added
//! to the top in part order before the top's sweep; backward, each part reads a copy of the
//! top's final rows. The workspace is laid out so that every part's rows and its copy of the
//! top are one contiguous region: part 0's columns, its copy of the top, part 1's columns, its
//! copy, ..., then the top's columns (a symmetric permutation of `L` that keeps it lower
//! triangular: every subtree precedes its ancestors).
//!
//! The split depends on the factor's structure only, never on the number of threads, so results
//! are bitwise the same on one thread or many. (On 2 cores, the 3-column solve of `arap` on
//! igea-2m was 39% of its time on one thread, docs/results.md issue 63.)

use std::ops::Range;

use super::{to_u32, BlockedFactor};

/// Parts the subtrees are dealt to. Fixed (not the thread count) so that results do not depend on
/// the machine; two suits the 2-core machines the suite is measured on.
pub(super) const PARTS: usize = 2;

/// Factors with fewer stored values than this are solved in one sweep. Below it the parts save
/// little: on the survey bar (275K values) a 3-column solve went from 0.22 to 0.19 ms, 2% of an
/// `arap` iteration, while on the plane (1.9M) it went from 2.4 to 1.3 ms
/// (`examples/cholesky_solve_timing`, 2 threads).
const MIN_VALUES: usize = 500_000;

/// A split is used when its estimated critical path (top plus largest part, in values swept) is at
/// most this fraction of the whole factor.
const MAX_CRITICAL_SHARE: f64 = 0.8;

/// Subtree expansions tried when looking for a balanced split.
const MAX_EXPANSIONS: usize = 512;

/// One part's supernodes and workspace rows.
#[derive(Clone, Debug)]
pub(super) struct Part {
    /// Its supernodes, in sweep order.
    pub supernodes: Range<usize>,
    /// Its workspace region: its columns, then from `scratch` its copy of the top rows.
    pub rows: Range<usize>,
    pub scratch: usize,
}

/// The layout of a split factor.
#[derive(Clone, Debug)]
pub(super) struct TreeSplit {
    pub parts: Vec<Part>,
    /// The top's supernodes and workspace rows (the last ones).
    pub top: Range<usize>,
    pub top_rows: Range<usize>,
}

/// Who sweeps a supernode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Owner {
    Part(usize),
    Top,
}

/// The supernodal elimination tree: the parent of supernode `s` is the supernode holding the
/// first (smallest) row of its pattern (`None` for a root).
fn parents(f: &BlockedFactor) -> Vec<Option<usize>> {
    let ns = f.n_supernodes();
    let mut supernode_of_col = vec![0u32; f.n];
    for s in 0..ns {
        for c in f.col_start[s]..f.col_end[s] {
            supernode_of_col[c as usize] = to_u32(s);
        }
    }
    (0..ns)
        .map(|s| {
            f.pattern[f.pattern_ptr[s]..f.pattern_ptr[s + 1]]
                .iter()
                .min()
                .map(|&i| supernode_of_col[i as usize] as usize)
        })
        .collect()
}

/// Deal `subtrees` (with their `weights`) to [`PARTS`] bins, heaviest first to the lightest bin
/// (ties to the lower index): the bin of each subtree and the heaviest bin's load.
fn deal(subtrees: &[usize], weights: &[f64]) -> (Vec<usize>, f64) {
    let mut order: Vec<usize> = (0..subtrees.len()).collect();
    order.sort_by(|&a, &b| {
        weights[subtrees[b]].total_cmp(&weights[subtrees[a]]).then(subtrees[a].cmp(&subtrees[b]))
    });
    let mut load = [0.0f64; PARTS];
    let mut bin = vec![0; subtrees.len()];
    for i in order {
        let lightest = (0..PARTS).min_by(|&a, &b| load[a].total_cmp(&load[b])).unwrap_or(0);
        load[lightest] += weights[subtrees[i]];
        bin[i] = lightest;
    }
    (bin, load.iter().copied().fold(0.0, f64::max))
}

/// The owner of every supernode of `f` (structure in faer's order, not yet split), or `None` when
/// no split pays ([`MIN_VALUES`], [`MAX_CRITICAL_SHARE`]).
///
/// Starting from the roots, the heaviest subtree is replaced by its children (its root joins the
/// top) while that can shorten the critical path, top plus heaviest bin after dealing the
/// subtrees; the best split seen is kept.
pub(super) fn choose(f: &BlockedFactor) -> Option<Vec<Owner>> {
    let ns = f.n_supernodes();
    let total = *f.value_ptr.last()?;
    if total < MIN_VALUES || ns < 2 {
        return None;
    }
    let parent = parents(f);
    let weight: Vec<f64> = (0..ns).map(|s| (f.value_ptr[s + 1] - f.value_ptr[s]) as f64).collect();
    let mut subtree = weight.clone();
    let mut children = vec![Vec::new(); ns];
    // Children precede their parents, so one ascending pass sums the subtrees.
    for s in 0..ns {
        if let Some(p) = parent[s] {
            debug_assert!(p > s, "the elimination tree is in topological order");
            subtree[p] += subtree[s];
            children[p].push(s);
        }
    }
    let mut subtrees: Vec<usize> = (0..ns).filter(|&s| parent[s].is_none()).collect();
    let mut top: Vec<usize> = Vec::new();
    let mut top_weight = 0.0;
    let mut best: Option<(f64, Vec<usize>, Vec<usize>, Vec<usize>)> = None;
    for _ in 0..MAX_EXPANSIONS {
        let (bin, heaviest_bin) = deal(&subtrees, &subtree);
        let critical = top_weight + heaviest_bin;
        if best.as_ref().is_none_or(|b| critical < b.0) {
            best = Some((critical, subtrees.clone(), bin, top.clone()));
        }
        let Some(at) = (0..subtrees.len()).filter(|&i| !children[subtrees[i]].is_empty()).max_by(|&a, &b| {
            subtree[subtrees[a]].total_cmp(&subtree[subtrees[b]]).then(subtrees[b].cmp(&subtrees[a]))
        }) else {
            break;
        };
        let s = subtrees.swap_remove(at);
        top.push(s);
        top_weight += weight[s];
        if top_weight >= best.as_ref().map_or(f64::INFINITY, |b| b.0) {
            break;
        }
        subtrees.extend(&children[s]);
    }
    let (critical, subtrees, bin, top) = best?;
    if critical > MAX_CRITICAL_SHARE * total as f64 {
        return None;
    }
    let mut owner: Vec<Option<Owner>> = vec![None; ns];
    for s in top {
        owner[s] = Some(Owner::Top);
    }
    for (&s, &b) in subtrees.iter().zip(&bin) {
        owner[s] = Some(Owner::Part(b));
    }
    // Parents come after their children: a descending pass hands every subtree its root's owner.
    for s in (0..ns).rev() {
        if owner[s].is_none() {
            owner[s] = owner[parent[s].expect("every root is a subtree or in the top")];
        }
    }
    Some(owner.into_iter().map(|o| o.expect("owner set")).collect())
}

impl BlockedFactor {
    /// Lay the factor out for the split `owner` ([`choose`]): supernodes reordered part by part,
    /// then the top, each in its original (topological) order; workspace rows as described in the
    /// module documentation; every pattern row renamed to its workspace row, where a part's
    /// supernodes see the top rows in the part's copy of them.
    pub(super) fn reorder(&mut self, owner: &[Owner]) {
        let ns = self.n_supernodes();
        let width = |s: usize| (self.col_end[s] - self.col_start[s]) as usize;
        let n_top: usize = (0..ns).filter(|&s| owner[s] == Owner::Top).map(width).sum();
        let mut order = Vec::with_capacity(ns);
        let mut start = vec![0usize; ns];
        let mut parts = Vec::with_capacity(PARTS);
        let mut row = 0;
        for p in 0..PARTS {
            let (first_supernode, first_row) = (order.len(), row);
            for s in (0..ns).filter(|&s| owner[s] == Owner::Part(p)) {
                order.push(s);
                start[s] = row;
                row += width(s);
            }
            let scratch = row;
            row += n_top;
            parts.push(Part { supernodes: first_supernode..order.len(), rows: first_row..row, scratch });
        }
        let (first_top, top_base) = (order.len(), row);
        for s in (0..ns).filter(|&s| owner[s] == Owner::Top) {
            order.push(s);
            start[s] = row;
            row += width(s);
        }
        let rows = row;
        // Workspace row of every column, and of every column's supernode owner.
        let mut position = vec![0u32; self.n];
        let mut col_owner = vec![Owner::Top; self.n];
        for s in 0..ns {
            for (j, c) in (self.col_start[s]..self.col_end[s]).enumerate() {
                position[c as usize] = to_u32(start[s] + j);
                col_owner[c as usize] = owner[s];
            }
        }

        let mut col_start = Vec::with_capacity(ns);
        let mut col_end = Vec::with_capacity(ns);
        let mut pattern_ptr = vec![0];
        let mut pattern = Vec::with_capacity(self.pattern.len());
        let mut value_ptr = vec![0];
        let mut faer_base = Vec::with_capacity(self.faer_base.len());
        let mut source = Vec::with_capacity(self.source.len());
        for &s in &order {
            col_start.push(to_u32(start[s]));
            col_end.push(to_u32(start[s] + width(s)));
            let scratch = match owner[s] {
                Owner::Part(p) => Some(parts[p].scratch),
                Owner::Top => None,
            };
            pattern.extend(self.pattern[self.pattern_ptr[s]..self.pattern_ptr[s + 1]].iter().map(|&i| {
                let (i_owner, at) = (col_owner[i as usize], position[i as usize] as usize);
                match scratch {
                    Some(scratch) if i_owner == Owner::Top => to_u32(scratch + at - top_base),
                    _ => {
                        // A row of another part would be written by two threads.
                        assert_eq!(i_owner, owner[s], "pattern rows are the supernode's ancestors");
                        to_u32(at)
                    }
                }
            }));
            pattern_ptr.push(pattern.len());
            let values = self.value_ptr[s]..self.value_ptr[s + 1];
            value_ptr.push(value_ptr.last().unwrap() + values.len());
            if let Some(&base) = self.faer_base.get(s) {
                faer_base.push(base);
            }
            if !self.source.is_empty() {
                source.extend_from_slice(&self.source[values]);
            }
        }
        self.col_start = col_start;
        self.col_end = col_end;
        self.pattern_ptr = pattern_ptr;
        self.pattern = pattern;
        self.value_ptr = value_ptr;
        self.faer_base = faer_base;
        self.source = source;
        self.position = position;
        self.rows = rows;
        self.split = Some(TreeSplit { parts, top: first_top..ns, top_rows: top_base..rows });
    }
}

impl TreeSplit {
    /// Stored values swept by each part and by the top.
    #[cfg(test)]
    pub(super) fn loads(&self, f: &BlockedFactor) -> (Vec<usize>, usize) {
        let values = |r: &Range<usize>| f.value_ptr[r.end] - f.value_ptr[r.start];
        (self.parts.iter().map(|p| values(&p.supernodes)).collect(), values(&self.top))
    }
}
