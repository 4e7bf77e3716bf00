//! Per-element geometry: face areas and normals, corner angles, dihedral angles, vertex normals.
//! Functions take positions and triangles separately so they apply to deformed positions as well.

pub use crate::primitives::{bbox, bbox_diagonal, triangle_area};
use crate::topology::Topology;
use crate::vector::{angle_between, cross, norm, normalize_or_zero, sub};

/// `#F` face areas.
pub fn face_areas(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<f64> {
    triangles.iter().map(|t| triangle_area(positions, t)).collect()
}

/// `#F` unit face normals (right-hand rule on the corner order); zero for a zero-area face.
pub fn face_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]; triangles.len()];
    face_normals_into(positions, triangles, &mut out);
    out
}

/// [`face_normals`] into a preallocated `#F x 3` buffer (no allocation; for iteration loops).
pub fn face_normals_into(positions: &[[f64; 3]], triangles: &[[u32; 3]], out: &mut [[f64; 3]]) {
    for (n, t) in out.iter_mut().zip(triangles) {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        *n = normalize_or_zero(cross(sub(b, a), sub(c, a)));
    }
}

/// `#V` unit vertex normals, the area-weighted mean of the adjacent face normals.
pub fn vertex_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0f64; 3]; positions.len()];
    vertex_normals_into(positions, triangles, &mut out);
    out
}

/// `#F x 3` interior angles in radians; entry `k` is the angle at corner `k`.
pub fn corner_angles(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| positions[i as usize]);
            std::array::from_fn(|k| {
                let o = p[k];
                angle_between(sub(p[(k + 1) % 3], o), sub(p[(k + 2) % 3], o))
            })
        })
        .collect()
}

/// One angle per interior edge of `topology` (in [`Topology::interior_edges`] order): the angle in
/// radians between the unit normals of the two adjacent faces, in `[0, pi]` (0 where the surface is flat).
pub fn dihedral_angles(positions: &[[f64; 3]], triangles: &[[u32; 3]], topology: &Topology) -> Vec<f64> {
    let normals = face_normals(positions, triangles);
    topology
        .interior_edges()
        .map(|e| {
            let [f0, f1] = topology.edge_faces()[e];
            angle_between(normals[f0 as usize], normals[f1 as usize])
        })
        .collect()
}

/// [`vertex_normals`] into a preallocated `#V x 3` buffer (no allocation; for iteration loops).
pub fn vertex_normals_into(positions: &[[f64; 3]], triangles: &[[u32; 3]], out: &mut [[f64; 3]]) {
    out.iter_mut().for_each(|n| *n = [0.0; 3]);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n2 = cross(sub(b, a), sub(c, a));
        for &i in t {
            let o = &mut out[i as usize];
            o[0] += n2[0];
            o[1] += n2[1];
            o[2] += n2[2];
        }
    }
    out.iter_mut().for_each(|n| *n = normalize_or_zero(*n));
}

/// `#E` lengths of the edges `edges` (pairs of vertex indices into `positions`).
pub fn edge_lengths(positions: &[[f64; 3]], edges: &[[u32; 2]]) -> Vec<f64> {
    edges.iter().map(|[a, b]| norm(sub(positions[*b as usize], positions[*a as usize]))).collect()
}

/// Signed volume enclosed by the `#F x 3` `triangles` of `#V x 3` `positions`:
/// `1/6 sum_f (a - c) . ((b - c) x (d - c))` over faces `f = (a, b, d)` with `c` the centroid of the
/// vertices, positive when the faces are oriented outwards (right-hand rule). Meaningful for a closed
/// surface only; subtracting the centroid keeps it exact for meshes far from the origin.
pub fn signed_volume(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64 {
    if positions.is_empty() {
        return 0.0;
    }
    let n = positions.len() as f64;
    let c: [f64; 3] = std::array::from_fn(|k| positions.iter().map(|p| p[k]).sum::<f64>() / n);
    triangles
        .iter()
        .map(|t| {
            let [a, b, d] = t.map(|i| sub(positions[i as usize], c));
            crate::vector::dot(a, cross(b, d))
        })
        .sum::<f64>()
        / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit tetrahedron (outward faces), moved far from the origin.
    fn tetrahedron(offset: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let p = p.iter().map(|v| v.map(|c| c + offset)).collect();
        (p, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    }

    #[test]
    fn signed_volume_of_a_tetrahedron_far_from_the_origin() {
        for offset in [0.0, 1e6] {
            let (p, t) = tetrahedron(offset);
            let v = signed_volume(&p, &t);
            assert!((v - 1.0 / 6.0).abs() < 1e-12, "offset {offset}: {v}");
            let flipped: Vec<[u32; 3]> = t.iter().map(|f| [f[0], f[2], f[1]]).collect();
            assert!((signed_volume(&p, &flipped) + 1.0 / 6.0).abs() < 1e-12, "inward faces: negative");
        }
        assert_eq!(signed_volume(&[], &[]), 0.0);
    }

    #[test]
    fn edge_lengths_in_edge_order() {
        let (p, _) = tetrahedron(0.0);
        let l = edge_lengths(&p, &[[0, 1], [1, 2], [3, 0]]);
        assert_eq!(l[0], 1.0);
        assert!((l[1] - 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(l[2], 1.0);
    }
}
