//! Refinement by subdivision: each level splits every triangle into four at its edge midpoints, so
//! a real shape can be brought to any size (issue 37: real meshes at a million vertices).
//!
//! Vertex order is kept: the `#V` vertices of the input come first, with their indices, then one new
//! vertex per edge in [`Topology::edges`] order. A level maps `#V, #E, #F` to `#V + #E, 2#E + 3#F,
//! 4#F`; the Euler characteristic, the boundary loops and the orientation are those of the input,
//! so a closed mesh stays closed and keeps its genus.
//!
//! Two schemes:
//! - [`Scheme::Loop`] (Loop 1987): new vertices at `3/8 (a + b) + 1/8 (c + d)` of an interior edge
//!   `ab` with opposite vertices `c, d`, old ones moved to `(1 - n beta) v + beta sum(ring)` with
//!   Loop's `beta(n) = (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n`. Boundaries follow the cubic B-spline
//!   rules (edge midpoint; `3/4 v + 1/8 (b0 + b1)` for a vertex between two boundary edges), so a hole
//!   keeps its rim. A vertex on more than two boundary edges (two rims meeting) stays where it is. The
//!   surface converges to a smooth one, like a finer scan of the same object; it lies slightly inside
//!   the input's convex parts.
//! - [`Scheme::Midpoint`]: new vertices at edge midpoints, old ones unmoved. The shape is exactly the
//!   input's (flat faces, the same bounding box), so selections in bounding-box coordinates pick the
//!   same region; only the sampling changes.

use crate::error::Result;
use crate::mesh::TriMesh;
use crate::topology::{Topology, NO_FACE};

/// How new and old vertices are placed (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scheme {
    /// Loop subdivision: smooth.
    #[default]
    Loop,
    /// Midpoint subdivision: the input's exact shape.
    Midpoint,
}

/// `mesh` subdivided `levels` times with `scheme`. The mesh must be an oriented manifold (its
/// [`Topology`] builds), else the error says which edge is not. `levels = 0` returns a copy.
pub fn refine(mesh: &TriMesh, levels: u32, scheme: Scheme) -> Result<TriMesh> {
    let mut current = mesh.clone();
    for _ in 0..levels {
        let topology = Topology::new(&current)?;
        current = subdivide_once(&current, &topology, scheme)?;
    }
    Ok(current)
}

/// One level of subdivision of `mesh` (with `topology` its adjacency): `#V + #E` vertices and
/// `4 #F` faces.
pub fn subdivide_once(mesh: &TriMesh, topology: &Topology, scheme: Scheme) -> Result<TriMesh> {
    let (p, t) = (mesh.positions(), mesh.triangles());
    let n = p.len();
    let edges = topology.edges();
    let mut positions = Vec::with_capacity(n + edges.len());
    positions.extend(match scheme {
        Scheme::Loop => loop_vertex_points(p, topology),
        Scheme::Midpoint => p.to_vec(),
    });
    for (e, &[a, b]) in edges.iter().enumerate() {
        let (a, b) = (p[a as usize], p[b as usize]);
        let faces = topology.edge_faces()[e];
        let point = match (scheme, faces[1] == NO_FACE) {
            (Scheme::Loop, false) => {
                let c = p[opposite(t, faces[0], edges[e]) as usize];
                let d = p[opposite(t, faces[1], edges[e]) as usize];
                std::array::from_fn(|k| 0.375 * (a[k] + b[k]) + 0.125 * (c[k] + d[k]))
            }
            _ => std::array::from_fn(|k| 0.5 * (a[k] + b[k])),
        };
        positions.push(point);
    }
    let edge_vertex = |f: usize, k: usize| (n + topology.face_edges()[f][k] as usize) as u32;
    let mut triangles = Vec::with_capacity(4 * t.len());
    for (f, &[a, b, c]) in t.iter().enumerate() {
        // face_edges()[f][k] is the edge opposite corner k.
        let (bc, ca, ab) = (edge_vertex(f, 0), edge_vertex(f, 1), edge_vertex(f, 2));
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    TriMesh::new(positions, triangles)
}

/// The vertex of face `f` of `t` that is not on `edge`.
fn opposite(t: &[[u32; 3]], f: u32, edge: [u32; 2]) -> u32 {
    let face = t[f as usize];
    face.into_iter().find(|v| !edge.contains(v)).unwrap_or(face[0])
}

/// Loop's new positions of the `#V` old vertices `p` (module doc).
fn loop_vertex_points(p: &[[f64; 3]], topology: &Topology) -> Vec<[f64; 3]> {
    // The boundary neighbours of each vertex: where there are exactly two, the B-spline rule holds.
    let mut rim: Vec<Vec<u32>> = vec![Vec::new(); p.len()];
    for (e, &[a, b]) in topology.edges().iter().enumerate() {
        if topology.edge_faces()[e][1] == NO_FACE {
            rim[a as usize].push(b);
            rim[b as usize].push(a);
        }
    }
    (0..p.len())
        .map(|v| {
            let x = p[v];
            match rim[v].as_slice() {
                [] => {
                    let ring = topology.one_ring(v);
                    if ring.is_empty() {
                        return x;
                    }
                    let m = ring.len() as f64;
                    let c = 0.375 + 0.25 * (2.0 * std::f64::consts::PI / m).cos();
                    let beta = (0.625 - c * c) / m;
                    std::array::from_fn(|k| {
                        (1.0 - m * beta) * x[k] + beta * ring.iter().map(|&j| p[j as usize][k]).sum::<f64>()
                    })
                }
                [b0, b1] => {
                    let (b0, b1) = (p[*b0 as usize], p[*b1 as usize]);
                    std::array::from_fn(|k| 0.75 * x[k] + 0.125 * (b0[k] + b1[k]))
                }
                _ => x,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{generate, ShapeKind};

    fn euler(mesh: &TriMesh, topology: &Topology) -> i64 {
        mesh.n_vertices() as i64 - topology.edges().len() as i64 + mesh.n_faces() as i64
    }

    #[test]
    fn each_level_gives_the_counts_and_keeps_topology() {
        let mut closed = 0;
        for kind in [ShapeKind::Bar, ShapeKind::Cylinder, ShapeKind::Cactus, ShapeKind::BumpyPlane] {
            let mesh = generate(kind, 600).unwrap().mesh;
            let topology = Topology::new(&mesh).unwrap();
            closed += topology.is_closed() as usize;
            for scheme in [Scheme::Loop, Scheme::Midpoint] {
                let (mut v, mut e, mut f) = (mesh.n_vertices(), topology.edges().len(), mesh.n_faces());
                for levels in 1..=2 {
                    let refined = refine(&mesh, levels, scheme).unwrap();
                    (v, e, f) = (v + e, 2 * e + 3 * f, 4 * f);
                    let rt = Topology::new(&refined).expect("an oriented manifold");
                    assert_eq!((refined.n_vertices(), rt.edges().len(), refined.n_faces()), (v, e, f));
                    assert_eq!(euler(&refined, &rt), euler(&mesh, &topology), "{kind:?} {scheme:?}");
                    assert_eq!(rt.is_closed(), topology.is_closed());
                    assert_eq!(rt.boundary_loops().len(), topology.boundary_loops().len());
                    refined.check_nondegenerate().unwrap();
                }
            }
        }
        assert!(closed > 0, "a closed shape among them");
    }

    #[test]
    fn midpoint_keeps_the_shape_and_loop_smooths_it_in_place() {
        let mesh = generate(ShapeKind::Cactus, 800).unwrap().mesh;
        let mid = refine(&mesh, 1, Scheme::Midpoint).unwrap();
        assert_eq!(&mid.positions()[..mesh.n_vertices()], mesh.positions(), "old vertices unmoved");
        assert_eq!(mid.bbox(), mesh.bbox());
        let area =
            |m: &TriMesh| crate::geometry::face_areas(m.positions(), m.triangles()).iter().sum::<f64>();
        assert!((area(&mid) - area(&mesh)).abs() < 1e-9 * area(&mesh), "the same surface");
        // Loop moves the surface inside a little: far less than the edge length away.
        let smooth = refine(&mesh, 1, Scheme::Loop).unwrap();
        let (lo, hi) = mesh.bbox();
        let (slo, shi) = smooth.bbox();
        let diagonal = mesh.bbox_diagonal();
        for k in 0..3 {
            assert!(slo[k] >= lo[k] - 1e-12 && shi[k] <= hi[k] + 1e-12, "inside the input's box");
            assert!(hi[k] - shi[k] < 0.05 * diagonal && slo[k] - lo[k] < 0.05 * diagonal);
        }
    }

    /// The boundary rules read the rim alone: moving every interior vertex moves no rim vertex.
    #[test]
    fn the_rim_is_refined_from_the_rim_alone() {
        let mesh = generate(ShapeKind::BumpyPlane, 900).unwrap().mesh;
        let topology = Topology::new(&mesh).unwrap();
        let mut on_rim = vec![false; mesh.n_vertices()];
        for &v in topology.boundary_loops().iter().flatten() {
            on_rim[v as usize] = true;
        }
        let lifted: Vec<[f64; 3]> = mesh
            .positions()
            .iter()
            .zip(&on_rim)
            .map(|(x, rim)| if *rim { *x } else { [x[0], x[1], x[2] + 1.0] })
            .collect();
        let a = refine(&mesh, 1, Scheme::Loop).unwrap();
        let b = refine(&mesh.with_positions(lifted).unwrap(), 1, Scheme::Loop).unwrap();
        let rim_edges = topology.edge_faces().iter().filter(|f| f[1] == NO_FACE).count();
        assert!(rim_edges > 0);
        for v in (0..mesh.n_vertices()).filter(|&v| on_rim[v]) {
            assert_eq!(a.positions()[v], b.positions()[v], "rim vertex {v}");
        }
        for (e, faces) in topology.edge_faces().iter().enumerate() {
            if faces[1] == NO_FACE {
                let v = mesh.n_vertices() + e;
                assert_eq!(a.positions()[v], b.positions()[v], "rim edge {e}");
            }
        }
    }

    #[test]
    fn a_non_manifold_input_is_an_error() {
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        )
        .unwrap();
        assert!(refine(&mesh, 1, Scheme::Loop).is_err());
        assert_eq!(refine(&mesh, 0, Scheme::Loop).unwrap().n_faces(), 3, "no level: a copy");
    }
}
