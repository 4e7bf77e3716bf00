//! Per-element geometry: face areas and normals, corner angles, dihedral angles, vertex normals.
//! Functions take positions and triangles separately so they apply to deformed positions as well.

use crate::topology::Topology;
use crate::vector::{angle_between, cross, norm, normalize_or_zero, sub};

/// Corners `(min, max)` of the axis-aligned bounding box of `#V x 3` positions (infinite for no
/// points).
pub fn bbox(positions: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Diagonal of the axis-aligned bounding box of `#V x 3` positions (0 for no points).
pub fn bbox_diagonal(positions: &[[f64; 3]]) -> f64 {
    if positions.is_empty() {
        return 0.0;
    }
    let (lo, hi) = bbox(positions);
    norm(sub(hi, lo))
}

/// Area of triangle `tri` of `positions`.
pub fn triangle_area(positions: &[[f64; 3]], tri: &[u32; 3]) -> f64 {
    let [a, b, c] = tri.map(|i| positions[i as usize]);
    0.5 * norm(cross(sub(b, a), sub(c, a)))
}

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
