//! The start of an ARAP solve by transformation propagation (Botsch & Sorkine 2008, section 3.1;
//! Zayer, Rössl, Karni & Seidel 2005): each handle region's rotation is propagated over the mesh by
//! harmonic weights, and one global step with those rotations gives the first iterate.
//!
//! Started from the rest shape, the local/global iteration has to carry a handle's rotation across
//! the whole free region one spoke at a time; the slow, smooth part of that is what the propagated
//! rotations supply at the cost of one multi-column back-substitution with the bound factor. Only
//! the first iterate changes, so the fixed points are the iteration's own; which of them a solve
//! ends in may change (the energy is not convex).
//!
//! Decisions (tested in `methods/tests/reference_methods.rs`):
//! - Region rotations: the rotation closest to the cross-covariance of each region's centred rest
//!   and target positions (Kabsch); a region whose rest positions span less than a plane (fewer than
//!   three vertices, or collinear) is given the identity.
//! - Weights: `w_r` harmonic (`L w_r = 0` on free vertices), 1 on region `r` and 0 on the other
//!   constrained vertices: a partition of unity, solved with ARAP's bound global-step factor.
//! - Blend: the normalized weighted sum of the regions' unit quaternions, each signed to the first
//!   region's hemisphere, so that a rigid motion of all targets rotates every blended rotation with it.

use faer::Mat;

use crate::handles::{HandleSet, HandleTargets, FREE};
use crate::linalg::sparse_cholesky::SparseCholesky;
use crate::rotation_fit::{
    closest_rotation, cross_covariance, quaternion_of, rotation_of, singular_values, Mat3, IDENTITY,
};

use super::Spokes;

/// Per region, the rotation best mapping its centred rest positions (`#V x 3`, all vertices) onto
/// its centred targets (in [`HandleSet::constrained`] order).
pub(super) fn region_rotations(rest: &[[f64; 3]], handles: &HandleSet, targets: &HandleTargets) -> Vec<Mat3> {
    let mut offset = 0;
    handles
        .regions()
        .iter()
        .map(|region| {
            let to = &targets.positions()[offset..offset + region.vertices.len()];
            offset += region.vertices.len();
            let from: Vec<[f64; 3]> = region.vertices.iter().map(|&v| rest[v as usize]).collect();
            let (cf, ct) = (centroid(&from), centroid(to));
            let centred = |p: &[f64; 3], c: &[f64; 3]| std::array::from_fn(|a| p[a] - c[a]);
            let spread = cross_covariance(from.iter().map(|p| (centred(p, &cf), centred(p, &cf))));
            let s = singular_values(&spread);
            if !(s[1] > 1e-12 * s[0]) {
                return IDENTITY;
            }
            closest_rotation(&cross_covariance(
                from.iter().zip(to).map(|(p, q)| (centred(p, &cf), centred(q, &ct))),
            ))
        })
        .collect()
}

/// `#V x #regions` harmonic weights: column `r` is 1 on region `r`, 0 on the other constrained
/// vertices and harmonic elsewhere. `cholesky` is the bound global-step factor (constrained rows
/// and columns identity), `spokes` the weights of `-L`'s off-diagonal entries.
pub(super) fn harmonic_weights(
    spokes: &Spokes,
    region_of: &[u32],
    n_regions: usize,
    cholesky: &mut SparseCholesky,
) -> Mat<f64> {
    let n = region_of.len();
    let mut w = Mat::<f64>::zeros(n, n_regions);
    for i in 0..n {
        if region_of[i] != FREE {
            w[(i, region_of[i] as usize)] = 1.0;
            continue;
        }
        // The constrained columns of -L moved to the right-hand side.
        for s in spokes.offsets[i]..spokes.offsets[i + 1] {
            let r = region_of[spokes.neighbors[s] as usize];
            if r != FREE {
                w[(i, r as usize)] += spokes.weights[s];
            }
        }
    }
    cholesky.solve_in_place(w.as_mut());
    w
}

/// Per vertex, the blend of `rotations` (one per region) by the row of `weights` (`#V x #regions`).
pub(super) fn blend(rotations: &[Mat3], weights: &Mat<f64>, out: &mut [Mat3]) {
    let first = quaternion_of(&rotations[0]);
    let quaternions: Vec<[f64; 4]> = rotations
        .iter()
        .map(|r| {
            let q = quaternion_of(r);
            let d: f64 = (0..4).map(|a| q[a] * first[a]).sum();
            if d < 0.0 {
                q.map(|c| -c)
            } else {
                q
            }
        })
        .collect();
    for (i, r) in out.iter_mut().enumerate() {
        let mut q = [0.0; 4];
        for (k, qk) in quaternions.iter().enumerate() {
            for a in 0..4 {
                q[a] += weights[(i, k)] * qk[a];
            }
        }
        let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        *r = if norm > 1e-12 { rotation_of(q.map(|c| c / norm)) } else { IDENTITY };
    }
}

fn centroid(p: &[[f64; 3]]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for q in p {
        for a in 0..3 {
            c[a] += q[a];
        }
    }
    c.map(|x| x / p.len().max(1) as f64)
}

#[cfg(test)]
mod tests {
    use meshes::AffineTransform;

    use super::{blend, region_rotations};
    use crate::arap::{Arap, ArapParams, ArapStart};
    use crate::handles::{HandleRegion, HandleSet, HandleTargets};
    use crate::method::DeformationMethod;
    use crate::rotation_fit::{quaternion_of, rotation_angle, rotation_of, Mat3, IDENTITY};

    fn rotation(axis: [f64; 3], angle: f64) -> Mat3 {
        let n = axis.iter().map(|c| c * c).sum::<f64>().sqrt();
        let h = 0.5 * angle;
        rotation_of([h.cos(), h.sin() * axis[0] / n, h.sin() * axis[1] / n, h.sin() * axis[2] / n])
    }

    #[test]
    fn blending_takes_the_shorter_arc_between_region_rotations() {
        // 0.5 and -2.5 rad about z are 3 rad apart one way and 3.28 the other: half way along the
        // shorter arc is -1 rad. The quaternions of the two lie in opposite hemispheres, so
        // without the sign alignment the blend would go the long way, to +2.14 rad.
        let rotations = [rotation([0.0, 0.0, 1.0], 0.5), rotation([0.0, 0.0, 1.0], -2.5)];
        let weights = faer::Mat::from_fn(3, 2, |i, j| [[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]][i][j]);
        let mut out = [[[0.0; 3]; 3]; 3];
        blend(&rotations, &weights, &mut out);
        let expected = [rotation([0.0, 0.0, 1.0], 0.5), rotation([0.0, 0.0, 1.0], -1.0), rotations[1]];
        for (got, want) in out.iter().zip(&expected) {
            for a in 0..3 {
                for b in 0..3 {
                    assert!((got[a][b] - want[a][b]).abs() < 1e-12, "{got:?} against {want:?}");
                }
            }
        }
    }

    #[test]
    fn quaternions_round_trip_rotations_of_every_angle() {
        for (axis, angle) in
            [([1.0, 0.0, 0.0], 0.3), ([0.0, 1.0, 1.0], 2.4), ([1.0, 2.0, -1.0], 3.1), ([0.0, 0.0, 1.0], 0.0)]
        {
            let r = rotation(axis, angle);
            assert!((rotation_angle(&r) - angle).abs() < 1e-12);
            let back = rotation_of(quaternion_of(&r));
            for a in 0..3 {
                for b in 0..3 {
                    assert!((back[a][b] - r[a][b]).abs() < 1e-14, "{axis:?} {angle}");
                }
            }
        }
    }
    fn distance(a: &Mat3, b: &Mat3) -> f64 {
        (0..3).flat_map(|i| (0..3).map(move |j| (a[i][j] - b[i][j]).abs())).fold(0.0, f64::max)
    }

    #[test]
    fn weights_are_a_partition_of_unity_and_blend_the_region_rotations() {
        let mesh = meshes::shapes::generate("bar".parse().unwrap(), 800).unwrap().mesh;
        let z: Vec<f64> = mesh.positions().iter().map(|p| p[2]).collect();
        let (lo, hi) = z.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        let slab = |from: f64, to: f64| -> Vec<u32> {
            (0..z.len() as u32)
                .filter(|&i| (from..=to).contains(&((z[i as usize] - lo) / (hi - lo))))
                .collect()
        };
        let handles = HandleSet::new(
            vec![
                HandleRegion { name: "fixed".into(), vertices: slab(0.0, 0.1) },
                HandleRegion { name: "handle".into(), vertices: slab(0.9, 1.0) },
            ],
            mesh.n_vertices(),
        )
        .unwrap();
        let params = ArapParams { start: ArapStart::TransformationPropagation, ..ArapParams::default() };
        let mut arap = Arap::new(params).unwrap();
        arap.precompute(&mesh).unwrap();
        arap.bind_handles(&handles).unwrap();
        let weights = arap.propagation_weights.as_ref().expect("computed at bind");
        let region_of = handles.region_of();
        for i in 0..mesh.n_vertices() {
            let (w0, w1) = (weights[(i, 0)], weights[(i, 1)]);
            assert!((w0 + w1 - 1.0).abs() < 1e-12, "vertex {i}: weights sum to {}", w0 + w1);
            assert!((-1e-12..=1.0 + 1e-12).contains(&w1), "vertex {i}: weight {w1} outside [0, 1]");
            if region_of[i] != crate::handles::FREE {
                assert_eq!(w1, f64::from(region_of[i]));
            }
        }
        // The handle turned by 2.4 rad about the bar's axis: each region's fitted rotation, and
        // blended rotations that grow from the fixed end to the handle.
        let turn = AffineTransform::rotation_about([0.0, 0.0, 1.0], 2.4, [0.5, 0.5, hi]);
        let targets: Vec<[f64; 3]> = handles
            .constrained()
            .map(|v| {
                let p = mesh.positions()[v as usize];
                if region_of[v as usize] == 1 {
                    turn.apply(p)
                } else {
                    p
                }
            })
            .collect();
        let targets = HandleTargets::new(&handles, targets).unwrap();
        let rotations = region_rotations(mesh.positions(), &handles, &targets);
        assert!(distance(&rotations[0], &IDENTITY) < 1e-12);
        assert!((rotation_angle(&rotations[1]) - 2.4).abs() < 1e-9);
        let mut blended = vec![IDENTITY; mesh.n_vertices()];
        blend(&rotations, weights, &mut blended);
        let mut by_height: Vec<(f64, f64)> =
            (0..mesh.n_vertices()).map(|i| (z[i], rotation_angle(&blended[i]))).collect();
        by_height.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(by_height.first().unwrap().1 < 1e-12 && (by_height.last().unwrap().1 - 2.4).abs() < 1e-9);
        let mid = by_height[by_height.len() / 2].1;
        assert!(0.5 < mid && mid < 1.9, "half way up the bar the blended angle is {mid}");
    }
}
