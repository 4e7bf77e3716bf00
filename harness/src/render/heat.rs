//! The per-vertex angle error of a result (where `E_theta` comes from) and its colour scale.

use meshes::geometry::{corner_angles, triangle_area};

/// Top of the heat colour scale, in degrees: larger errors get the top colour. The same for every
/// image, so colours compare across methods and scenarios.
pub const HEAT_MAX_DEG: f64 = 10.0;

/// Stops of the heat scale at `0, 0.2, ...` of [`HEAT_MAX_DEG`]: dark blue through light blue,
/// yellow and orange to dark red (ColorBrewer's RdYlBu reversed, its near-white middle dropped so
/// no value disappears into the white background); lightness rises then falls, hue changes steadily.
const HEAT_STOPS: [(f64, [f64; 3]); 6] = [
    (0.0, [0.192, 0.212, 0.584]),
    (0.2, [0.271, 0.459, 0.706]),
    (0.4, [0.455, 0.678, 0.820]),
    (0.6, [0.996, 0.878, 0.565]),
    (0.8, [0.957, 0.427, 0.263]),
    (1.0, [0.647, 0.0, 0.149]),
];

/// Colour of a vertex without a value.
const NO_VALUE: [f64; 3] = [0.6, 0.6, 0.6];

/// Colour (sRGB in `[0, 1]`) of `degrees` on the fixed scale `0..`[`HEAT_MAX_DEG`], clamped at both
/// ends; grey for NaN.
pub fn heat_color(degrees: f64) -> [f64; 3] {
    if degrees.is_nan() {
        return NO_VALUE;
    }
    let t = (degrees / HEAT_MAX_DEG).clamp(0.0, 1.0);
    let i = HEAT_STOPS.iter().position(|(s, _)| *s >= t).unwrap_or(HEAT_STOPS.len() - 1).max(1);
    let ((s0, c0), (s1, c1)) = (HEAT_STOPS[i - 1], HEAT_STOPS[i]);
    let u = ((t - s0) / (s1 - s0)).clamp(0.0, 1.0);
    std::array::from_fn(|k| c0[k] + u * (c1[k] - c0[k]))
}

/// `#V` per-vertex angle errors in degrees of the `#V x 3` `result` against the `#V x 3` `rest`
/// positions on the `#F x 3` `triangles`: per vertex, the root mean square over its triangle corners
/// of (rest corner angle - result corner angle). The per-vertex breakdown of `E_theta`
/// ([`crate::metrics::angle_errors`]): 0 for rigid motions and uniform scalings.
///
/// Triangles with zero area or a non-finite vertex in either shape are skipped; a vertex without a
/// remaining corner gets NaN. All NaN (no panic) when the arrays differ in length or a triangle
/// indexes beyond them.
pub fn vertex_angle_errors(rest: &[[f64; 3]], result: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<f64> {
    let n = rest.len();
    if result.len() != n || triangles.iter().flatten().any(|&i| i as usize >= n) {
        return vec![f64::NAN; n.max(result.len())];
    }
    let usable = |p: &[[f64; 3]], t: &[u32; 3]| {
        t.iter().all(|&i| p[i as usize].iter().all(|x| x.is_finite())) && triangle_area(p, t) > 0.0
    };
    let rest_angles = corner_angles(rest, triangles);
    let result_angles = corner_angles(result, triangles);
    let mut sum = vec![0.0f64; n];
    let mut count = vec![0u32; n];
    for (f, t) in triangles.iter().enumerate() {
        if !(usable(rest, t) && usable(result, t)) {
            continue;
        }
        for k in 0..3 {
            let d = rest_angles[f][k] - result_angles[f][k];
            sum[t[k] as usize] += d * d;
            count[t[k] as usize] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| if c == 0 { f64::NAN } else { (s / c as f64).sqrt().to_degrees() })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshes::shapes::{generate, ShapeKind};
    use meshes::AffineTransform;

    fn errors_after(f: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<f64> {
        let mesh = generate(ShapeKind::Cylinder, 800).unwrap().mesh;
        let moved: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| f(p)).collect();
        vertex_angle_errors(mesh.positions(), &moved, mesh.triangles())
    }

    #[test]
    fn zero_for_the_rest_shape_and_a_similarity_positive_for_a_shear() {
        let max = |e: &[f64]| e.iter().copied().fold(0.0f64, f64::max);
        let rest = errors_after(|p| p);
        assert!(rest.iter().all(|e| *e == 0.0), "rest: max {}", max(&rest));
        let rotation = AffineTransform::rotation_about([0.3, -1.0, 2.0], 1.1, [0.5, 0.2, 4.0]);
        let similar = errors_after(|p| {
            let q = rotation.apply(p);
            [2.5 * q[0] + 1.0, 2.5 * q[1] - 3.0, 2.5 * q[2]]
        });
        assert!(similar.iter().all(|e| e.abs() < 1e-6), "scaled + rotated: max {}", max(&similar));
        let sheared = errors_after(|p| [p[0] + 0.5 * p[2], p[1], p[2]]);
        // The caps (z constant) only slide in their plane; the side's corners change.
        let changed = sheared.iter().filter(|e| **e > 0.1).count();
        assert!(changed > sheared.len() / 2, "{changed} of {} vertices changed", sheared.len());
        assert!(max(&sheared) > 1.0, "sheared: max {}", max(&sheared));
    }

    #[test]
    fn degenerate_input_gives_nan_not_a_panic() {
        let rest = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
        // Face 1 has zero area (collinear), so vertex 3 has no corner left.
        let e = vertex_angle_errors(&rest, &rest, &[[0, 1, 2], [0, 1, 3]]);
        assert_eq!(e[..3], [0.0; 3]);
        assert!(e[3].is_nan());
        let mut moved = rest;
        moved[2] = [f64::NAN; 3];
        let e = vertex_angle_errors(&rest, &moved, &[[0, 1, 2]]);
        assert!(e.iter().all(|v| v.is_nan()));
        assert!(vertex_angle_errors(&rest, &rest[..2], &[[0, 1, 2]]).iter().all(|v| v.is_nan()));
        assert!(vertex_angle_errors(&rest, &rest, &[[0, 1, 9]]).iter().all(|v| v.is_nan()));
        assert!(vertex_angle_errors(&[], &[], &[]).is_empty());
    }

    #[test]
    fn the_scale_runs_from_blue_to_red_and_clamps() {
        let blue = heat_color(0.0);
        let red = heat_color(HEAT_MAX_DEG);
        assert!(blue[2] > blue[0] && red[0] > red[2]);
        assert_eq!(heat_color(-5.0), blue);
        assert_eq!(heat_color(1e9), red);
        assert_eq!(heat_color(f64::INFINITY), red);
        let middle = heat_color(0.6 * HEAT_MAX_DEG);
        assert!(middle[0] > 0.9 && middle[1] > 0.8, "yellow in the upper middle: {middle:?}");
        assert_eq!(heat_color(f64::NAN), NO_VALUE);
    }
}
