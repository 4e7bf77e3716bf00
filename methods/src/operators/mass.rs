//! Lumped (diagonal) mass matrices.

use meshes::vector::{cross, dot, norm, sub};

use super::DEGENERATE_FACE_RATIO;

/// How a face's area is distributed to its corners.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MassKind {
    /// One third of the area to each corner.
    Barycentric,
    /// Voronoi areas (Meyer et al. 2003), with the obtuse-triangle rule: half the area to the obtuse
    /// corner and a quarter to the others. libigl's default `MASSMATRIX_TYPE_VORONOI`.
    Voronoi,
}

/// `#V` diagonal of the lumped mass matrix; it sums to the surface area (degenerate faces, caught by
/// [`DEGENERATE_FACE_RATIO`], contribute nothing).
pub fn lumped_mass(positions: &[[f64; 3]], triangles: &[[u32; 3]], kind: MassKind) -> Vec<f64> {
    let mut mass = vec![0.0; positions.len()];
    for (t, corner) in triangles.iter().zip(corner_areas(positions, triangles, kind)) {
        for k in 0..3 {
            mass[t[k] as usize] += corner[k];
        }
    }
    mass
}

/// `#F x 3` share of each face's area at each of its corners (entry `k`: corner `k`); each row sums
/// to the face area, zero for faces caught by [`DEGENERATE_FACE_RATIO`].
pub fn corner_areas(positions: &[[f64; 3]], triangles: &[[u32; 3]], kind: MassKind) -> Vec<[f64; 3]> {
    triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| positions[i as usize]);
            let e = [sub(p[2], p[1]), sub(p[0], p[2]), sub(p[1], p[0])]; // e[k] opposite corner k
            let l2 = e.map(|v| dot(v, v));
            let double_area = norm(cross(e[0], e[1]));
            if !(double_area > DEGENERATE_FACE_RATIO * l2.iter().fold(0.0, |a: f64, &b| a.max(b))) {
                return [0.0; 3];
            }
            let area = 0.5 * double_area;
            match kind {
                MassKind::Barycentric => [area / 3.0; 3],
                MassKind::Voronoi => voronoi_corner_areas(e, l2, double_area, area),
            }
        })
        .collect()
}

fn voronoi_corner_areas(e: [[f64; 3]; 3], l2: [f64; 3], double_area: f64, area: f64) -> [f64; 3] {
    // cos(corner k) < 0  <=>  l2[k] > l2[k+1] + l2[k+2]; the obtuse rule takes precedence.
    for k in 0..3 {
        if l2[k] > l2[(k + 1) % 3] + l2[(k + 2) % 3] {
            let mut c = [0.25 * area; 3];
            c[k] = 0.5 * area;
            return c;
        }
    }
    let cot: [f64; 3] = std::array::from_fn(|k| -dot(e[(k + 2) % 3], e[(k + 1) % 3]) / double_area);
    // Voronoi area of corner k: (|e_{k+1}|^2 cot_{k+1} + |e_{k+2}|^2 cot_{k+2}) / 8.
    std::array::from_fn(|k| {
        let a = (k + 1) % 3;
        let b = (k + 2) % 3;
        (l2[a] * cot[a] + l2[b] * cot[b]) / 8.0
    })
}
