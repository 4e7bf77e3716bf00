//! The per-vertex angle error of a result (where `E_theta` comes from), the per-vertex area
//! distortion (where `e_area` comes from), and their colour scales.

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
    interpolate(&HEAT_STOPS, degrees / HEAT_MAX_DEG)
}

/// The colour at `t` of the piecewise-linear scale through `stops` (ascending), clamped to its ends.
fn interpolate(stops: &[(f64, [f64; 3])], t: f64) -> [f64; 3] {
    let t = t.clamp(stops[0].0, stops[stops.len() - 1].0);
    let i = stops.iter().position(|(s, _)| *s >= t).unwrap_or(stops.len() - 1).max(1);
    let ((s0, c0), (s1, c1)) = (stops[i - 1], stops[i]);
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

/// End of the area-distortion colour scale, as `|ln(A / A⁰)|`: `ln 2`, an area halved or doubled.
/// The same for every image.
pub const AREA_MAX_LOG: f64 = std::f64::consts::LN_2;

/// Stops of the diverging area scale at `-1, -0.5, 0, 0.5, 1` of [`AREA_MAX_LOG`]: shrinking dark
/// to light blue, unchanged light grey (not white, so it stays visible on the background), growing
/// light to dark red (ColorBrewer's RdBu).
const AREA_STOPS: [(f64, [f64; 3]); 5] = [
    (-1.0, [0.129, 0.400, 0.675]),
    (-0.5, [0.573, 0.773, 0.871]),
    (0.0, [0.86, 0.86, 0.86]),
    (0.5, [0.957, 0.647, 0.510]),
    (1.0, [0.698, 0.094, 0.169]),
];

/// Colour (sRGB in `[0, 1]`) of the log area ratio `ln(A / A⁰)` on the fixed scale
/// `±`[`AREA_MAX_LOG`], clamped at both ends; grey for NaN.
pub fn area_color(log_ratio: f64) -> [f64; 3] {
    if log_ratio.is_nan() {
        return NO_VALUE;
    }
    interpolate(&AREA_STOPS, log_ratio / AREA_MAX_LOG)
}

/// `#V` per-vertex area distortion of the `#V x 3` `result` against the `#V x 3` `rest` positions:
/// `ln(sum of the adjacent face areas / the same sum at rest)`, the one-ring's log area ratio
/// (`2 ln s` for a uniform scaling by `s`, 0 for rigid motions). A vertex whose one-ring has no rest
/// area, or a non-finite result area, gets NaN; all NaN (no panic) for mismatched input.
pub fn vertex_area_distortion(rest: &[[f64; 3]], result: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<f64> {
    let n = rest.len();
    if result.len() != n || triangles.iter().flatten().any(|&i| i as usize >= n) {
        return vec![f64::NAN; n.max(result.len())];
    }
    let mut sums = vec![[0.0f64; 2]; n];
    for t in triangles {
        let (a0, a) = (triangle_area(rest, t), triangle_area(result, t));
        for &v in t {
            sums[v as usize][0] += a0;
            sums[v as usize][1] += a;
        }
    }
    sums.iter().map(|[a0, a]| if *a0 > 0.0 && a.is_finite() { (a / a0).ln() } else { f64::NAN }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_distortion_is_the_log_ratio_and_the_scale_diverges() {
        let rest = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let doubled: Vec<[f64; 3]> = rest.iter().map(|p| p.map(|c| c * 2f64.sqrt())).collect();
        let d = vertex_area_distortion(&rest, &doubled, &[[0, 1, 2]]);
        assert!(d.iter().all(|v| (v - 2f64.ln()).abs() < 1e-12), "{d:?}");
        let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12);
        assert!(near(area_color(AREA_MAX_LOG), AREA_STOPS[4].1));
        assert!(near(area_color(-10.0), AREA_STOPS[0].1));
        assert!(near(area_color(0.0), AREA_STOPS[2].1));
        assert_eq!(area_color(f64::NAN), NO_VALUE);
        assert!(vertex_area_distortion(&rest, &rest[..2], &[[0, 1, 2]]).iter().all(|v| v.is_nan()));
    }
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
