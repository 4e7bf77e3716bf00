//! Distances between position arrays: of the constrained vertices from their targets, of a result
//! from another (the reference's) or from its rest positions.

use meshes::vector::{norm, sub};
use methods::{HandleSet, HandleTargets};

use crate::statistics::rms;

/// Largest distance of a constrained vertex from its target, divided by `diagonal`.
pub fn handle_residual(
    handles: &HandleSet,
    targets: &HandleTargets,
    result: &[[f64; 3]],
    diagonal: f64,
) -> f64 {
    handles
        .constrained()
        .zip(targets.positions())
        .map(|(v, t)| norm(sub(result[v as usize], *t)))
        .fold(0.0, f64::max)
        / diagonal
}

/// Root-mean-square vertex distance between two `#V x 3` position arrays, divided by `diagonal`.
pub fn rms_distance(a: &[[f64; 3]], b: &[[f64; 3]], diagonal: f64) -> f64 {
    rms(a.iter().zip(b).map(|(p, q)| norm(sub(*p, *q)))) / diagonal
}

/// Largest vertex distance between two `#V x 3` position arrays, divided by `diagonal` (NaN if a
/// distance is NaN).
pub fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]], diagonal: f64) -> f64 {
    a.iter().zip(b).map(|(p, q)| norm(sub(*p, *q))).fold(0.0, |m: f64, d| {
        if d.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(d)
        }
    }) / diagonal
}

/// Largest distance of any vertex of the `#V x 3` `result` from its rest position.
pub fn largest_displacement(rest: &[[f64; 3]], result: &[[f64; 3]]) -> f64 {
    max_distance(rest, result, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn residual_and_distances() {
        let a = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let b = vec![[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]];
        assert!((rms_distance(&a, &b, 2.0) - (2.0f64).sqrt() / 2.0).abs() < 1e-15);
        assert!((max_distance(&a, &b, 2.0) - 1.0).abs() < 1e-15);
        assert!(max_distance(&a, &[[f64::NAN; 3], [1.0, 0.0, 0.0]], 1.0).is_nan());
        let handles =
            HandleSet::new(vec![methods::HandleRegion { name: "h".into(), vertices: vec![1] }], 2).unwrap();
        let targets = HandleTargets::new(&handles, vec![[1.0, 0.5, 0.0]]).unwrap();
        assert!((handle_residual(&handles, &targets, &b, 3.0) - 0.5).abs() < 1e-15);
    }
}
