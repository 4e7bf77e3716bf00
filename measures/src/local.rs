//! What each face and each one-ring did, rest to result, computed once per result
//! ([`crate::Evaluation`] holds them): a face's stretches, the singular values of its deformation
//! gradient ([`face_stretches`], read by [`crate::size`]); a one-ring's turn, the angle of its
//! closest rotation ([`one_ring_turns`], read by [`crate::turn`]).

use meshes::vector::{cross, dot, norm, sub};
use meshes::Topology;
use methods::rotation_fit::{closest_rotation, cross_covariance, rotation_angle};

/// Per face of `triangles` (`#F x 3`), the singular values `[σ_max, σ_min]` of the deformation
/// gradient that maps its `rest` triangle onto its `result` triangle (both `#V x 3`): the largest
/// and smallest factor by which it stretched a direction in its plane. `σ_max σ_min` is its area
/// factor; both are 1 for a rigid motion and `s` for a uniform scaling by `s`. `None` for a rest
/// face of zero area (it has no plane).
pub fn face_stretches(
    rest: &[[f64; 3]],
    result: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> Vec<Option<[f64; 2]>> {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| v as usize);
            let (e1, e2) = (sub(rest[b], rest[a]), sub(rest[c], rest[a]));
            let (f1, f2) = (sub(result[b], result[a]), sub(result[c], result[a]));
            // The rest triangle in an orthonormal frame of its plane: R = [[x1, x2], [0, y2]].
            let x1 = norm(e1);
            let twice_area = norm(cross(e1, e2));
            if !(x1 > 0.0 && twice_area > 0.0) {
                return None;
            }
            let x2 = dot(e1, e2) / x1;
            let y2 = twice_area / x1;
            // J = F R⁻¹ with R⁻¹ = [[1/x1, -x2/(x1 y2)], [0, 1/y2]]; its columns:
            let j1 = f1.map(|v| v / x1);
            let j2: [f64; 3] = std::array::from_fn(|k| (f2[k] - f1[k] * x2 / x1) / y2);
            // Singular values from JᵀJ = [[p, q], [q, r]].
            let (p, q, r) = (dot(j1, j1), dot(j1, j2), dot(j2, j2));
            let half_trace = 0.5 * (p + r);
            let root = (0.25 * (p - r) * (p - r) + q * q).sqrt();
            let largest = (half_trace + root).sqrt();
            // σ_min from the determinant, which keeps its digits where σ_min ≪ σ_max.
            let smallest = if largest > 0.0 { norm(cross(j1, j2)) / largest } else { 0.0 };
            Some([largest, smallest])
        })
        .collect()
}

/// Per vertex, the angle (radians) of the rotation closest to
/// `sum_j (x_i - x_j)(x0_i - x0_j)^T` over its one-ring: how far its neighbourhood turned from
/// `rest` to `result` (both `#V x 3`). An isolated vertex turns 0.
pub fn one_ring_turns(rest: &[[f64; 3]], result: &[[f64; 3]], topology: &Topology) -> Vec<f64> {
    (0..rest.len())
        .map(|i| {
            let ring = topology.one_ring(i);
            if ring.is_empty() {
                return 0.0;
            }
            let pairs =
                ring.iter().map(|&j| (sub(rest[i], rest[j as usize]), sub(result[i], result[j as usize])));
            rotation_angle(&closest_rotation(&cross_covariance(pairs)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.5, 1.5, 0.0]], vec![[0, 1, 2]])
    }

    #[test]
    fn a_face_stretches_by_the_singular_values_of_its_gradient() {
        let (rest, faces) = triangle();
        // A rotation about z by 0.7 and a translation: both 1.
        let (c, s) = (0.7f64.cos(), 0.7f64.sin());
        let turned: Vec<[f64; 3]> =
            rest.iter().map(|p| [c * p[0] - s * p[1] + 3.0, s * p[0] + c * p[1], 1.0]).collect();
        let [l, m] = face_stretches(&rest, &turned, &faces)[0].unwrap();
        assert!((l - 1.0).abs() < 1e-12 && (m - 1.0).abs() < 1e-12, "{l} {m}");
        // x scaled by 3, y by 0.5 (the rest plane): 3 and 0.5.
        let squeezed: Vec<[f64; 3]> = rest.iter().map(|p| [3.0 * p[0], 0.5 * p[1], 0.0]).collect();
        let [l, m] = face_stretches(&rest, &squeezed, &faces)[0].unwrap();
        assert!((l - 3.0).abs() < 1e-12 && (m - 0.5).abs() < 1e-12, "{l} {m}");
        // A collapsed result: σ_min 0; a collapsed rest face: none.
        let flat: Vec<[f64; 3]> = rest.iter().map(|p| [p[0], 0.0, 0.0]).collect();
        assert_eq!(face_stretches(&rest, &flat, &faces)[0].unwrap()[1], 0.0);
        assert_eq!(face_stretches(&flat, &rest, &faces)[0], None);
    }
}
