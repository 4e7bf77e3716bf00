//! Shading the rasterized surface: Lambert with ambient under a raised headlight, coloured by vertex
//! role or by a per-vertex scalar on the heat scale, supersampled.

use meshes::vector::{add, cross, dot, normalize_or_zero, scale, sub};

use super::camera::Camera;
use super::canvas::RgbImage;
use super::heat::{area_color, heat_color};
use super::raster::rasterize;

/// Samples per pixel along each axis: images are rasterized this many times larger and averaged
/// down, which anti-aliases silhouettes and the thin triangles of fine meshes.
pub const SUPERSAMPLING: u32 = 2;

/// Background of the rendered cells.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];

/// A corner uses its vertex's normal unless that deviates from the face's by more than this angle
/// (cosine of ~35 degrees): the bar's right-angled edges stay sharp, curved surfaces look smooth.
const CREASE_COS: f64 = 0.82;

/// How far above the eye the headlight sits: its direction is `toward_eye + LIGHT_RAISE * image_up`.
const LIGHT_RAISE: f64 = 0.5;

/// Fraction of the light that does not depend on the surface orientation, for role and heat colours.
/// Heat colours get more, so that their values stay readable on surfaces seen at grazing angles.
const AMBIENT_ROLES: f64 = 0.25;
const AMBIENT_HEAT: f64 = 0.5;

/// What a vertex is in the edit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexRole {
    Free,
    Fixed,
    Handle,
}

impl VertexRole {
    /// Base colour (sRGB in `[0, 1]`): fixed blue, handle orange, free light grey.
    pub fn color(self) -> [f64; 3] {
        match self {
            VertexRole::Free => [0.86, 0.86, 0.86],
            VertexRole::Fixed => [0.20, 0.42, 0.80],
            VertexRole::Handle => [0.96, 0.50, 0.10],
        }
    }
}

/// How to colour a surface.
#[derive(Clone, Copy, Debug)]
pub enum Paint<'a> {
    /// `#V` roles; each pixel takes the role of the nearest corner of its face, so region borders
    /// stay crisp instead of blending.
    Roles(&'a [VertexRole]),
    /// `#V` values in degrees, interpolated across faces and mapped by [`heat_color`]; faces with a
    /// NaN corner take the nearest corner's value, and NaN (no value) is drawn grey.
    Heat(&'a [f64]),
    /// `#V` log area ratios, interpolated like [`Paint::Heat`] and mapped by [`area_color`].
    Area(&'a [f64]),
}

/// Render the `#F x 3` `triangles` of the `#V x 3` `positions` seen by `camera` into one
/// `width x height` image per entry of `paints` (rasterized once, shaded per paint), white
/// background. A paint whose array is shorter than `#V` colours the missing vertices as free / NaN.
pub fn render(
    camera: &Camera,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    width: u32,
    height: u32,
    paints: &[Paint],
) -> Vec<RgbImage> {
    let (sw, sh) = (width.saturating_mul(SUPERSAMPLING), height.saturating_mul(SUPERSAMPLING));
    let fragments = rasterize(camera, positions, triangles, sw, sh);
    let normals = corner_normals(positions, triangles);
    let eye = camera.toward_eye();
    // The headlight, raised above the eye so that surfaces facing up (the plane seen at a low
    // angle) are not darker than walls seen head-on.
    let light = normalize_or_zero(add(eye, scale(camera.image_up(), LIGHT_RAISE)));
    paints
        .iter()
        .map(|paint| {
            let mut sum = vec![[0.0f64; 3]; width as usize * height as usize];
            for sy in 0..sh {
                for sx in 0..sw {
                    let color = match fragments.at(sx, sy) {
                        None => BACKGROUND.map(|c| c as f64 / 255.0),
                        Some((f, w)) => {
                            let f = f as usize;
                            let (n, face_normal) = &normals[f];
                            let mut normal = [0.0; 3];
                            for k in 0..3 {
                                for d in 0..3 {
                                    normal[d] += w[k] as f64 * n[k][d];
                                }
                            }
                            let normal = match normalize_or_zero(normal) {
                                [0.0, 0.0, 0.0] => *face_normal,
                                n => n,
                            };
                            // Two-sided: the side facing the eye is the one lit.
                            let normal = if dot(normal, eye) < 0.0 { scale(normal, -1.0) } else { normal };
                            let lambert = dot(normal, light).max(0.0);
                            let (base, ambient) = surface_color(paint, triangles[f], w);
                            base.map(|c| c * (ambient + (1.0 - ambient) * lambert))
                        }
                    };
                    let i = (sy / SUPERSAMPLING) as usize * width as usize + (sx / SUPERSAMPLING) as usize;
                    for d in 0..3 {
                        sum[i][d] += color[d];
                    }
                }
            }
            let mut image = RgbImage::filled(width, height, BACKGROUND);
            let samples = (SUPERSAMPLING * SUPERSAMPLING) as f64;
            for (i, s) in sum.iter().enumerate() {
                let c = s.map(|v| (255.0 * v / samples).round().clamp(0.0, 255.0) as u8);
                image.set_pixel(i as u32 % width, i as u32 / width, c);
            }
            image
        })
        .collect()
}

/// Base colour and ambient fraction at barycentric weights `w` of the face with corners `tri`.
fn surface_color(paint: &Paint, tri: [u32; 3], w: [f32; 3]) -> ([f64; 3], f64) {
    let nearest = (0..3).fold(0, |best, k| if w[k] > w[best] { k } else { best });
    match paint {
        Paint::Roles(roles) => {
            let role = roles.get(tri[nearest] as usize).copied().unwrap_or(VertexRole::Free);
            (role.color(), AMBIENT_ROLES)
        }
        Paint::Heat(values) | Paint::Area(values) => {
            let value = |k: usize| values.get(tri[k] as usize).copied().unwrap_or(f64::NAN);
            let corners = [value(0), value(1), value(2)];
            let v = if corners.iter().all(|v| v.is_finite()) {
                (0..3).map(|k| w[k] as f64 * corners[k]).sum()
            } else {
                corners[nearest]
            };
            let color = if matches!(paint, Paint::Area(_)) { area_color(v) } else { heat_color(v) };
            (color, AMBIENT_HEAT)
        }
    }
}

/// Per face: the normals of its three corners and its own unit normal (zero for a face with zero
/// area or a non-finite or missing vertex). Corner normals are the area-weighted vertex normals,
/// or the face normal across a crease ([`CREASE_COS`]).
fn corner_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<([[f64; 3]; 3], [f64; 3])> {
    let corners = |t: &[u32; 3]| {
        let p = t.map(|i| positions.get(i as usize).copied().unwrap_or([f64::NAN; 3]));
        p.iter().flatten().all(|x| x.is_finite()).then_some(p)
    };
    // Twice the area times the unit normal, so sums over faces are area-weighted.
    let scaled: Vec<[f64; 3]> = triangles
        .iter()
        .map(|t| match corners(t) {
            Some([a, b, c]) => {
                let n = cross(sub(b, a), sub(c, a));
                if n.iter().all(|x| x.is_finite()) {
                    n
                } else {
                    [0.0; 3]
                }
            }
            None => [0.0; 3],
        })
        .collect();
    let mut vertex = vec![[0.0f64; 3]; positions.len()];
    for (t, n) in triangles.iter().zip(&scaled) {
        for &i in t {
            if let Some(v) = vertex.get_mut(i as usize) {
                for d in 0..3 {
                    v[d] += n[d];
                }
            }
        }
    }
    let vertex: Vec<[f64; 3]> = vertex.into_iter().map(normalize_or_zero).collect();
    triangles
        .iter()
        .zip(&scaled)
        .map(|(t, n)| {
            let face = normalize_or_zero(*n);
            let corner = t.map(|i| match vertex.get(i as usize) {
                Some(v) if dot(*v, face) >= CREASE_COS => *v,
                _ => face,
            });
            (corner, face)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn top_view() -> Camera {
        Camera::framing([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0; 3], [1.0, 1.0, 0.0], 1.0)
    }

    /// Light on a surface facing the eye: the light is `LIGHT_RAISE` above the eye direction.
    fn lit(ambient: f64) -> f64 {
        ambient + (1.0 - ambient) / (1.0 + LIGHT_RAISE * LIGHT_RAISE).sqrt()
    }

    #[test]
    fn roles_colour_their_regions_and_back_faces_are_lit_like_front_faces() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let roles = [VertexRole::Fixed, VertexRole::Free, VertexRole::Handle, VertexRole::Free];
        let front = [[0, 1, 2], [0, 2, 3]];
        let back = [[0, 2, 1], [0, 3, 2]];
        let camera = top_view();
        let images: Vec<RgbImage> = [front, back]
            .iter()
            .map(|t| render(&camera, &positions, t, 40, 40, &[Paint::Roles(&roles)]).remove(0))
            .collect();
        assert_eq!(images[0], images[1], "two-sided lighting");
        // Facing the eye, lit by the raised headlight: the base colour times the light.
        let px = |x: f64, y: f64| images[0].pixel((x * 40.0) as u32, ((1.0 - y) * 40.0) as u32).unwrap();
        let expect = |role: VertexRole| role.color().map(|c| (255.0 * c * lit(AMBIENT_ROLES)).round() as u8);
        assert_eq!(px(0.1, 0.1), expect(VertexRole::Fixed));
        assert_eq!(px(0.9, 0.9), expect(VertexRole::Handle));
        assert_eq!(px(0.9, 0.1), expect(VertexRole::Free));
    }

    #[test]
    fn heat_values_are_interpolated_and_nan_is_grey_not_a_panic() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [f64::NAN, 0.0, 0.0]];
        let values = [0.0, 10.0, 0.0, 5.0];
        // The second face has a NaN vertex, the third an index beyond the positions: both skipped.
        let camera = top_view();
        let [image] = <[RgbImage; 1]>::try_from(render(
            &camera,
            &positions,
            &[[0, 1, 2], [1, 3, 2], [0, 1, 7]],
            40,
            40,
            &[Paint::Heat(&values)],
        ))
        .unwrap();
        // Near corners 0 (0 degrees: blue) and 1 (10 degrees: red).
        let low = image.pixel(1, 38).unwrap();
        let high = image.pixel(37, 38).unwrap();
        assert!(low[2] > 2 * low[0] && high[0] > 2 * high[2], "blue to red: {low:?} -> {high:?}");
        let [short] =
            <[RgbImage; 1]>::try_from(render(&camera, &positions, &[[0, 1, 2]], 8, 8, &[Paint::Heat(&[])]))
                .unwrap();
        let grey = heat_color(f64::NAN).map(|c| (255.0 * c * lit(AMBIENT_HEAT)).round() as u8);
        assert_eq!(short.pixel(1, 6), Some(grey));
    }
}
