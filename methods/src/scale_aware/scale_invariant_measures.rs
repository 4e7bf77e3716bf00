//! Section 3.1: the scale-invariant measures `Omega = {Theta, Phi}` of the rest mesh — triangle
//! (corner) angles and edge (dihedral) angles — with what the scale-aware equations derive from them.

use meshes::geometry::{corner_angles, dihedral_angles, face_normals};
use meshes::vector::{cross, dot, norm, sub};
use meshes::Topology;

use crate::operators::DEGENERATE_FACE_RATIO;

/// `Omega` of a mesh, plus the length ratios and normals the reconstruction uses.
///
/// Corner `k` of face `t = [t0, t1, t2]` is the cell corner of eq 1 with `v = t[k]`,
/// `v_i = t[k + 1]`, `v_{i+1} = t[k + 2]` (indices mod 3): counter-clockwise about the face normal,
/// so `e_{i+1}` is `e_i` rotated by `+theta` about `N` and scaled by `l`.
#[derive(Clone, Debug)]
pub struct ScaleInvariantMeasures {
    /// `#F x 3` triangle angles `theta` in radians (entry `k`: the angle at corner `k`).
    pub triangle_angles: Vec<[f64; 3]>,
    /// `#F x 3` length ratios `l = |e_{i+1}| / |e_i|` of eq 1 at each corner, i.e.
    /// `sin(angle at t[k+1]) / sin(angle at t[k+2])` by the law of sines; 0 on degenerate faces.
    pub length_ratios: Vec<[f64; 3]>,
    /// One edge angle `phi` per interior edge, in [`Topology::interior_edges`] order: the angle in
    /// radians between the normals of the two adjacent faces.
    pub edge_angles: Vec<f64>,
    /// `#F` unit face normals (the rest pyramids of step one; zero on degenerate faces).
    pub normals: Vec<[f64; 3]>,
    /// `#F`: whether the face is too thin to have angles ([`DEGENERATE_FACE_RATIO`]); such faces
    /// contribute no scale-aware equations.
    pub degenerate: Vec<bool>,
}

impl ScaleInvariantMeasures {
    /// The measures of `#V x 3` `positions` on `#F x 3` `triangles` with their `topology`.
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]], topology: &Topology) -> Self {
        let degenerate: Vec<bool> = triangles.iter().map(|t| is_degenerate(positions, t)).collect();
        let length_ratios = triangles
            .iter()
            .zip(&degenerate)
            .map(|(t, &bad)| {
                let p = t.map(|i| positions[i as usize]);
                std::array::from_fn(|k| {
                    if bad {
                        return 0.0;
                    }
                    // Equal to the ratio of sines on the rest triangle; the edge lengths are exact.
                    norm(sub(p[(k + 2) % 3], p[k])) / norm(sub(p[(k + 1) % 3], p[k]))
                })
            })
            .collect();
        Self {
            triangle_angles: corner_angles(positions, triangles),
            length_ratios,
            edge_angles: dihedral_angles(positions, triangles, topology),
            normals: face_normals(positions, triangles),
            degenerate,
        }
    }
}

/// Whether a face's doubled area is below [`DEGENERATE_FACE_RATIO`] of its longest squared edge.
fn is_degenerate(positions: &[[f64; 3]], t: &[u32; 3]) -> bool {
    let p = t.map(|i| positions[i as usize]);
    let e = [sub(p[1], p[0]), sub(p[2], p[1]), sub(p[0], p[2])];
    let longest2 = e.iter().map(|v| dot(*v, *v)).fold(0.0, f64::max);
    !(norm(cross(e[0], e[2])) > DEGENERATE_FACE_RATIO * longest2)
}
