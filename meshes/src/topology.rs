//! Adjacency of a triangle mesh: unique edges, edge -> faces, face -> edges, one-rings, boundary loops.
//! Building it checks that the mesh is an oriented 2-manifold (with boundary).

use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

/// Marker for "no face" on the missing side of a boundary edge.
pub const NO_FACE: u32 = u32::MAX;

/// Adjacency tables of a [`TriMesh`]. Edges are stored once as `[a, b]` with `a < b`, sorted.
#[derive(Clone, Debug)]
pub struct Topology {
    edges: Vec<[u32; 2]>,
    edge_faces: Vec<[u32; 2]>,
    face_edges: Vec<[u32; 3]>,
    ring_offsets: Vec<usize>,
    ring: Vec<u32>,
    boundary_loops: Vec<Vec<u32>>,
}

impl Topology {
    /// Build the adjacency of `mesh`. Fails with [`MeshError::NonManifoldEdge`] when an edge has more
    /// than two faces and [`MeshError::InconsistentOrientation`] when two faces traverse an edge in the
    /// same direction.
    pub fn new(mesh: &TriMesh) -> Result<Self> {
        let tris = mesh.triangles();
        // (min, max, face, corner opposite the edge, forward?) per half-edge.
        let mut half: Vec<(u32, u32, u32, u8, bool)> = Vec::with_capacity(3 * tris.len());
        for (f, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let a = t[(k + 1) % 3];
                let b = t[(k + 2) % 3];
                half.push((a.min(b), a.max(b), f as u32, k as u8, a < b));
            }
        }
        half.sort_unstable();
        let mut edges = Vec::with_capacity(half.len() / 2 + 1);
        let mut edge_faces = Vec::with_capacity(half.len() / 2 + 1);
        let mut face_edges = vec![[0u32; 3]; tris.len()];
        let mut i = 0;
        while i < half.len() {
            let (a, b) = (half[i].0, half[i].1);
            let mut j = i + 1;
            while j < half.len() && half[j].0 == a && half[j].1 == b {
                j += 1;
            }
            let group = &half[i..j];
            if group.len() > 2 {
                return Err(MeshError::NonManifoldEdge { a, b, faces: group.iter().map(|h| h.2).collect() });
            }
            if group.len() == 2 && group[0].4 == group[1].4 {
                return Err(MeshError::InconsistentOrientation { a, b, f0: group[0].2, f1: group[1].2 });
            }
            let e = edges.len() as u32;
            edges.push([a, b]);
            edge_faces.push([group[0].2, group.get(1).map_or(NO_FACE, |h| h.2)]);
            for h in group {
                face_edges[h.2 as usize][h.3 as usize] = e;
            }
            i = j;
        }

        let n = mesh.n_vertices();
        let mut degree = vec![0usize; n + 1];
        for &[a, b] in &edges {
            degree[a as usize + 1] += 1;
            degree[b as usize + 1] += 1;
        }
        for v in 0..n {
            degree[v + 1] += degree[v];
        }
        let ring_offsets = degree;
        let mut fill = ring_offsets.clone();
        let mut ring = vec![0u32; 2 * edges.len()];
        for &[a, b] in &edges {
            ring[fill[a as usize]] = b;
            fill[a as usize] += 1;
            ring[fill[b as usize]] = a;
            fill[b as usize] += 1;
        }
        for v in 0..n {
            ring[ring_offsets[v]..ring_offsets[v + 1]].sort_unstable();
        }

        let boundary_loops = boundary_loops(tris, &edges, &edge_faces, &face_edges);
        Ok(Self { edges, edge_faces, face_edges, ring_offsets, ring, boundary_loops })
    }

    /// `#E` unique edges `[a, b]` with `a < b`, sorted lexicographically.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// `#E` pairs of faces adjacent to each edge; the second is [`NO_FACE`] on the boundary.
    pub fn edge_faces(&self) -> &[[u32; 2]] {
        &self.edge_faces
    }

    /// `#F x 3`: entry `k` is the edge opposite corner `k` of the face.
    pub fn face_edges(&self) -> &[[u32; 3]] {
        &self.face_edges
    }

    /// Indices of the interior edges (two adjacent faces), ascending.
    pub fn interior_edges(&self) -> impl Iterator<Item = usize> + '_ {
        self.edge_faces.iter().enumerate().filter(|(_, f)| f[1] != NO_FACE).map(|(e, _)| e)
    }

    /// Sorted neighbours of vertex `v`.
    pub fn one_ring(&self, v: usize) -> &[u32] {
        &self.ring[self.ring_offsets[v]..self.ring_offsets[v + 1]]
    }

    /// Boundary loops, each a cycle of vertex indices in the faces' orientation; empty for a closed mesh.
    pub fn boundary_loops(&self) -> &[Vec<u32>] {
        &self.boundary_loops
    }

    /// True when every edge has two faces.
    pub fn is_closed(&self) -> bool {
        self.boundary_loops.is_empty()
    }
}

fn boundary_loops(
    tris: &[[u32; 3]],
    edges: &[[u32; 2]],
    edge_faces: &[[u32; 2]],
    face_edges: &[[u32; 3]],
) -> Vec<Vec<u32>> {
    // Directed boundary half-edges a -> b as the single adjacent face traverses them.
    let mut next: Vec<(u32, u32)> = Vec::new();
    for (e, ef) in edge_faces.iter().enumerate() {
        if ef[1] != NO_FACE {
            continue;
        }
        let f = ef[0] as usize;
        let k = face_edges[f].iter().position(|&x| x as usize == e).expect("face lists its edge");
        let a = tris[f][(k + 1) % 3];
        let b = tris[f][(k + 2) % 3];
        debug_assert!(edges[e] == [a.min(b), a.max(b)]);
        next.push((a, b));
    }
    next.sort_unstable();
    let mut used = vec![false; next.len()];
    let mut loops = Vec::new();
    for start in 0..next.len() {
        if used[start] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut cur = start;
        loop {
            used[cur] = true;
            cycle.push(next[cur].0);
            let b = next[cur].1;
            // First unused boundary half-edge leaving b (a vertex may touch two loops).
            let lo = next.partition_point(|h| h.0 < b);
            match (lo..next.len()).take_while(|&i| next[i].0 == b).find(|&i| !used[i]) {
                Some(i) => cur = i,
                None => break,
            }
        }
        loops.push(cycle);
    }
    loops
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles sharing the diagonal of the unit square.
    fn square() -> TriMesh {
        TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn square_adjacency() {
        let t = Topology::new(&square()).unwrap();
        assert_eq!(t.edges(), &[[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]);
        let diagonal = t.edges().iter().position(|e| *e == [0, 2]).unwrap();
        assert_eq!(t.edge_faces()[diagonal], [0, 1]);
        assert_eq!(t.interior_edges().collect::<Vec<_>>(), vec![diagonal]);
        assert_eq!(t.one_ring(0), &[1, 2, 3]);
        assert_eq!(t.one_ring(1), &[0, 2]);
        assert_eq!(t.boundary_loops(), &[vec![0, 1, 2, 3]]);
        // face_edges[f][k] is the edge opposite corner k.
        assert_eq!(t.edges()[t.face_edges()[0][1] as usize], [0, 2]);
        assert!(!t.is_closed());
    }

    #[test]
    fn tetrahedron_is_closed() {
        let m = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
        .unwrap();
        let t = Topology::new(&m).unwrap();
        assert!(t.is_closed());
        assert_eq!(t.interior_edges().count(), 6);
    }

    #[test]
    fn non_manifold_and_misoriented_meshes_are_rejected() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
        let fan = TriMesh::new(p.clone(), vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
        assert!(matches!(Topology::new(&fan), Err(MeshError::NonManifoldEdge { a: 0, b: 1, .. })));
        let flipped = TriMesh::new(p, vec![[0, 1, 2], [0, 1, 3]]).unwrap();
        assert!(matches!(
            Topology::new(&flipped),
            Err(MeshError::InconsistentOrientation { a: 0, b: 1, .. })
        ));
    }
}
