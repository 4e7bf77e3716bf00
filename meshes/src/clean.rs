//! Mesh cleaning: dropping unreferenced vertices (with the map back to the input's numbering),
//! finding exactly duplicated positions, and labelling connected components.
//!
//! Nothing here changes the input: a deformation runs on the cleaned mesh, and [`VertexMap`] carries
//! its results (and the input's per-vertex data, such as a selection) between the two numberings.

use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

/// Marker for "dropped" in [`VertexMap`]'s original-to-new table.
const DROPPED: u32 = u32::MAX;

/// The vertex numbering of a cleaned mesh against its input's: new vertex `i` is original vertex
/// `kept()[i]`, and `kept()` is increasing (the cleaned mesh keeps the input's vertex order).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VertexMap {
    kept: Vec<u32>,
    /// `#V_original` entries: the new index of each original vertex, or [`DROPPED`].
    new_of_original: Vec<u32>,
}

impl VertexMap {
    /// The map of a mesh with `n` vertices to itself.
    pub fn identity(n: usize) -> Self {
        let all: Vec<u32> = (0..n as u32).collect();
        Self { kept: all.clone(), new_of_original: all }
    }

    /// `#V_new` original indices, increasing: entry `i` is the original index of new vertex `i`.
    pub fn kept(&self) -> &[u32] {
        &self.kept
    }

    /// Number of vertices of the input, `#V_original`.
    pub fn n_original(&self) -> usize {
        self.new_of_original.len()
    }

    /// Number of vertices of the cleaned mesh, `#V_new`.
    pub fn n_kept(&self) -> usize {
        self.kept.len()
    }

    /// True when nothing was dropped (new and original numbering coincide).
    pub fn is_identity(&self) -> bool {
        self.kept.len() == self.new_of_original.len()
    }

    /// The original indices of the dropped vertices, increasing.
    pub fn dropped(&self) -> Vec<u32> {
        (0..self.new_of_original.len() as u32)
            .filter(|&v| self.new_of_original[v as usize] == DROPPED)
            .collect()
    }

    /// The new index of original vertex `original`; `None` when it was dropped or is out of range.
    pub fn new_index(&self, original: u32) -> Option<u32> {
        self.new_of_original.get(original as usize).copied().filter(|&i| i != DROPPED)
    }

    /// Positions of the cleaned mesh (`#V_new x 3`, e.g. a deformation result) back in the input's
    /// numbering (`#V_original x 3`): kept vertices at their new position, dropped ones at their
    /// position in `rest_original` (`#V_original x 3`, the input's rest positions).
    ///
    /// Fails with [`MeshError::LengthMismatch`] when either array has the wrong length.
    pub fn to_original(
        &self,
        positions_new: &[[f64; 3]],
        rest_original: &[[f64; 3]],
    ) -> Result<Vec<[f64; 3]>> {
        check_len("new positions", positions_new.len(), self.n_kept())?;
        check_len("rest positions", rest_original.len(), self.n_original())?;
        let mut out = rest_original.to_vec();
        for (&original, p) in self.kept.iter().zip(positions_new) {
            out[original as usize] = *p;
        }
        Ok(out)
    }

    /// A per-vertex array of the input (`#V_original` entries, e.g. a selection) restricted to the kept
    /// vertices, in the new numbering (`#V_new` entries).
    ///
    /// Fails with [`MeshError::LengthMismatch`] when `per_vertex_original` has other than
    /// `#V_original` entries.
    pub fn restrict<T: Copy>(&self, per_vertex_original: &[T]) -> Result<Vec<T>> {
        check_len("per-vertex array", per_vertex_original.len(), self.n_original())?;
        Ok(self.kept.iter().map(|&v| per_vertex_original[v as usize]).collect())
    }
}

fn check_len(what: &'static str, got: usize, expected: usize) -> Result<()> {
    if got == expected {
        Ok(())
    } else {
        Err(MeshError::LengthMismatch { what, got, expected })
    }
}

/// Remove the vertices no triangle references.
///
/// Input: a mesh of `#V_original` vertices. Output: the mesh of the `#V_new` referenced vertices, in
/// their input order, with the same triangles (in the same order, indices renumbered), and the
/// [`VertexMap`] between the numberings (the identity, and a plain copy of the mesh, when every
/// vertex is referenced).
pub fn drop_unreferenced(mesh: &TriMesh) -> (TriMesh, VertexMap) {
    let n = mesh.n_vertices();
    let mut new_of_original = vec![DROPPED; n];
    for t in mesh.triangles() {
        for &v in t {
            new_of_original[v as usize] = 0;
        }
    }
    let mut kept = Vec::with_capacity(n);
    for (v, slot) in new_of_original.iter_mut().enumerate() {
        if *slot != DROPPED {
            *slot = kept.len() as u32;
            kept.push(v as u32);
        }
    }
    let map = VertexMap { kept, new_of_original };
    if map.is_identity() {
        return (mesh.clone(), map);
    }
    let positions = map.kept.iter().map(|&v| mesh.positions()[v as usize]).collect();
    let triangles = mesh.triangles().iter().map(|t| t.map(|v| map.new_of_original[v as usize])).collect();
    // Cannot fail: the input had a face (so the output has vertices and faces), positions are copied
    // finite, and renumbering is injective on the referenced vertices (no index leaves range, no face
    // starts repeating a vertex).
    let cleaned = TriMesh::new(positions, triangles).expect("renumbering a valid mesh keeps it valid");
    (cleaned, map)
}

/// Pairs `(first, duplicate)` of vertices whose positions (`#V x 3`) are bit-identical: `first` is the
/// smallest index with that position and `duplicate` each later one, sorted by `(first, duplicate)`.
///
/// Bit-identical means what it says: `0.0` and `-0.0` differ, and positions that are merely close do
/// not count. The order comes from sorting, never from hash iteration, so it is reproducible.
pub fn exact_duplicate_vertices(positions: &[[f64; 3]]) -> Vec<(u32, u32)> {
    let mut order: Vec<([u64; 3], u32)> =
        positions.iter().enumerate().map(|(v, p)| (p.map(f64::to_bits), v as u32)).collect();
    order.sort_unstable();
    let mut pairs = Vec::new();
    for group in order.chunk_by(|a, b| a.0 == b.0) {
        let first = group[0].1;
        pairs.extend(group[1..].iter().map(|&(_, v)| (first, v)));
    }
    pairs.sort_unstable();
    pairs
}

/// Connected components of `#V = n_vertices` vertices joined by `#F x 3` `triangles` (two triangles
/// are connected when they share a vertex; a vertex no triangle uses is a component of its own).
///
/// Output: `#V` component ids and their count. Ids are numbered in order of each component's smallest
/// vertex index (vertex 0 is in component 0, the smallest vertex outside it in component 1, ...), so
/// the labelling is deterministic.
///
/// # Panics
/// When a triangle refers to a vertex `>= n_vertices` (impossible for a [`TriMesh`]).
pub fn connected_components(n_vertices: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, usize) {
    // Union-find with union by smaller root and path halving.
    let mut parent: Vec<u32> = (0..n_vertices as u32).collect();
    fn find(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            let grand = parent[parent[v as usize] as usize];
            parent[v as usize] = grand;
            v = grand;
        }
        v
    }
    for t in triangles {
        for &v in t {
            assert!((v as usize) < n_vertices, "triangle vertex {v} is out of range ({n_vertices} vertices)");
        }
        let a = find(&mut parent, t[0]);
        for &v in &t[1..] {
            let r = find(&mut parent, v);
            let a = find(&mut parent, a);
            if r != a {
                // The smaller index becomes the root, so a root is its component's smallest vertex.
                let (lo, hi) = if r < a { (r, a) } else { (a, r) };
                parent[hi as usize] = lo;
            }
        }
    }
    let mut ids = vec![u32::MAX; n_vertices];
    let mut count = 0usize;
    for v in 0..n_vertices as u32 {
        let root = find(&mut parent, v);
        if ids[root as usize] == u32::MAX {
            // Roots are the smallest vertex of their component, and are reached in increasing order.
            ids[root as usize] = count as u32;
            count += 1;
        }
        ids[v as usize] = ids[root as usize];
    }
    (ids, count)
}
