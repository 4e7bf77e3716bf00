//! Z-buffer rasterization of triangles into per-pixel fragments (which face is visible, where in it),
//! shaded afterwards, so a shape is rasterized once for all its colourings.

use super::camera::Camera;

/// `face` of a pixel that no triangle covers.
const NO_FACE: u32 = u32::MAX;

/// Bits below the pixel in the fixed-point vertex coordinates. Edge functions are then exact integers,
/// so two triangles sharing an edge never both miss (a crack) or both cover (a seam) a pixel.
const SUBPIXEL_BITS: u32 = 8;

/// Largest projected coordinate, in pixels, of a vertex the rasterizer accepts; triangles with a
/// vertex further out are skipped. Keeps the fixed-point edge products within `i64`.
const MAX_COORD: f64 = (1u64 << 20) as f64;

/// The visible surface of a `width x height` image: per pixel the nearest face covering its centre
/// and the barycentric weights of that centre in it.
#[derive(Clone, Debug)]
pub struct Fragments {
    width: u32,
    height: u32,
    /// `width * height`, row-major from the top; larger is nearer the eye, `-inf` where empty.
    depth: Vec<f64>,
    face: Vec<u32>,
    barycentric: Vec<[f32; 3]>,
}

impl Fragments {
    /// An empty `width x height` image.
    pub fn new(width: u32, height: u32) -> Fragments {
        let n = width as usize * height as usize;
        Fragments {
            width,
            height,
            depth: vec![f64::NEG_INFINITY; n],
            face: vec![NO_FACE; n],
            barycentric: vec![[0.0; 3]; n],
        }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Face index and barycentric weights (of its corners 0, 1, 2) seen at pixel `(x, y)`; `None`
    /// for the background or outside the image.
    pub fn at(&self, x: u32, y: u32) -> Option<(u32, [f32; 3])> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = y as usize * self.width as usize + x as usize;
        (self.face[i] != NO_FACE).then(|| (self.face[i], self.barycentric[i]))
    }
}

/// Rasterize the `#F x 3` `triangles` of the `#V x 3` `positions`, seen by `camera`, into a
/// `width x height` image: a pixel is covered when its centre is inside a triangle (shared edges
/// belong to exactly one side), and keeps the nearest covering face (the first drawn on a tie).
///
/// Both orientations are drawn (no back-face culling). Skipped, never a panic: triangles with an
/// index beyond `positions`, a non-finite vertex, a vertex projected more than 2^20 pixels away, or
/// zero projected area.
pub fn rasterize(
    camera: &Camera,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    width: u32,
    height: u32,
) -> Fragments {
    let mut out = Fragments::new(width, height);
    if width == 0 || height == 0 {
        return out;
    }
    let one = 1i64 << SUBPIXEL_BITS;
    let projected: Vec<Option<([i64; 2], f64)>> = positions
        .iter()
        .map(|&p| {
            let [x, y, z] = camera.project(p, width, height);
            let ok = x.abs() <= MAX_COORD && y.abs() <= MAX_COORD && z.is_finite();
            ok.then(|| ([(x * one as f64).round() as i64, (y * one as f64).round() as i64], z))
        })
        .collect();
    for (f, tri) in triangles.iter().enumerate() {
        let corner = |k: usize| projected.get(tri[k] as usize).copied().flatten();
        let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else {
            continue;
        };
        let area2 = edge(a.0, b.0, c.0);
        if area2 == 0 {
            continue;
        }
        // Walk the corners counter-clockwise in edge-function terms; `order[k]` is the original corner.
        let (order, v) = if area2 > 0 { ([0, 1, 2], [a, b, c]) } else { ([0, 2, 1], [a, c, b]) };
        let area2 = area2.abs() as f64;
        let xs = v.map(|q| q.0[0]);
        let ys = v.map(|q| q.0[1]);
        // Pixel i's centre is at (i + 1/2) pixels: the pixels whose centres can lie in the triangle.
        let first = |lo: i64| (lo - one / 2).div_euclid(one).max(0);
        let last = |hi: i64, size: u32| ((hi - one / 2).div_euclid(one) + 1).min(size as i64 - 1);
        let (x0, x1) = (first(*xs.iter().min().unwrap()), last(*xs.iter().max().unwrap(), width));
        let (y0, y1) = (first(*ys.iter().min().unwrap()), last(*ys.iter().max().unwrap(), height));
        // Edge k is the one opposite corner k; a pixel centre exactly on it belongs to this triangle
        // only if the edge is owned (a consistent tie rule that gives each shared edge to one side).
        let edges = [(v[1].0, v[2].0), (v[2].0, v[0].0), (v[0].0, v[1].0)];
        let owned = edges.map(|(p, q)| {
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            dy > 0 || (dy == 0 && dx < 0)
        });
        for py in y0..=y1 {
            let cy = py * one + one / 2;
            for px in x0..=x1 {
                let centre = [px * one + one / 2, cy];
                let w = edges.map(|(p, q)| edge(p, q, centre));
                if (0..3).any(|k| w[k] < 0 || (w[k] == 0 && !owned[k])) {
                    continue;
                }
                let weights = w.map(|w| w as f64 / area2);
                let depth = weights[0] * v[0].1 + weights[1] * v[1].1 + weights[2] * v[2].1;
                let i = py as usize * width as usize + px as usize;
                if depth > out.depth[i] {
                    out.depth[i] = depth;
                    out.face[i] = f as u32;
                    let mut original = [0.0f32; 3];
                    for k in 0..3 {
                        original[order[k]] = weights[k] as f32;
                    }
                    out.barycentric[i] = original;
                }
            }
        }
    }
    out
}

/// Twice the signed area of `(a, b, p)`, exact: positive when `p` is left of `a -> b` in a y-down image
/// seen as y-up (the sign only has to be consistent).
fn edge(a: [i64; 2], b: [i64; 2], p: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Looking down `-z` at the square `[0, 1]^2` (z up to 1), x right and y up in the image.
    fn top_view() -> Camera {
        Camera::framing([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 1.0)
    }

    fn pixel_of(camera: &Camera, p: [f64; 3], size: u32) -> (u32, u32) {
        let q = camera.project(p, size, size);
        (q[0] as u32, q[1] as u32)
    }

    #[test]
    fn a_triangle_covers_its_centroid_and_not_the_pixels_outside_it() {
        let camera = top_view();
        let positions = [[0.1, 0.1, 0.0], [0.9, 0.1, 0.0], [0.1, 0.9, 0.0]];
        for triangles in [[[0, 1, 2]], [[0, 2, 1]]] {
            let frags = rasterize(&camera, &positions, &triangles, 64, 64);
            let (cx, cy) = pixel_of(&camera, [0.1 + 0.8 / 3.0, 0.1 + 0.8 / 3.0, 0.0], 64);
            let (face, w) = frags.at(cx, cy).expect("the centroid pixel is covered");
            assert_eq!(face, 0);
            assert!(w.iter().all(|w| (w - 1.0 / 3.0).abs() < 0.05), "{w:?}");
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            // Beyond the hypotenuse, and outside the triangle's box.
            for p in [[0.8, 0.8, 0.0], [0.05, 0.5, 0.0], [0.5, 0.05, 0.0]] {
                let (x, y) = pixel_of(&camera, p, 64);
                assert_eq!(frags.at(x, y), None, "{p:?} is outside the triangle");
            }
            // Vertex 1 is at the lower right: the weight of its corner is ~1 there.
            let (x, y) = pixel_of(&camera, [0.85, 0.12, 0.0], 64);
            let (_, w) = frags.at(x, y).unwrap();
            let corner = triangles[0].iter().position(|&v| v == 1).unwrap();
            assert!(w[corner] > 0.85, "{w:?}");
        }
    }

    #[test]
    fn the_z_buffer_keeps_the_nearer_of_two_overlapping_triangles_in_either_order() {
        let camera = top_view();
        let positions = [
            [0.1, 0.1, 0.2],
            [0.9, 0.1, 0.2],
            [0.5, 0.9, 0.2], // face 0, low
            [0.1, 0.1, 0.8],
            [0.9, 0.1, 0.8],
            [0.5, 0.9, 0.8], // face 1, high: nearer to an eye on +z
        ];
        let (x, y) = pixel_of(&camera, [0.5, 0.4, 0.0], 64);
        let frags = rasterize(&camera, &positions, &[[0, 1, 2], [3, 4, 5]], 64, 64);
        assert_eq!(frags.at(x, y).unwrap().0, 1);
        let frags = rasterize(&camera, &positions, &[[3, 4, 5], [0, 1, 2]], 64, 64);
        assert_eq!(frags.at(x, y).unwrap().0, 0, "face 0 of this list is the high one");
    }

    #[test]
    fn two_triangles_sharing_an_edge_cover_their_square_without_cracks() {
        let camera = top_view();
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let frags = rasterize(&camera, &positions, &[[0, 1, 2], [0, 2, 3]], 50, 50);
        let (x0, y1) = pixel_of(&camera, [0.0, 0.0, 0.0], 50);
        let (x1, y0) = pixel_of(&camera, [1.0, 1.0, 0.0], 50);
        let mut per_face = [0usize; 2];
        for y in y0 + 1..y1 {
            for x in x0 + 1..x1 {
                per_face[frags.at(x, y).expect("no crack inside the square").0 as usize] += 1;
            }
        }
        assert!(per_face[0].abs_diff(per_face[1]) <= (x1 - x0) as usize, "{per_face:?}");
    }

    #[test]
    fn bad_triangles_are_skipped_without_panicking() {
        let camera = top_view();
        let positions = [
            [0.1, 0.1, 0.0],
            [0.9, 0.1, 0.0],
            [0.5, 0.9, 0.0],
            [f64::NAN, 0.5, 0.0],
            [1e30, 0.5, 0.0],
            [0.5, 0.5, 0.0],
        ];
        let triangles = [[0, 1, 3], [0, 1, 4], [0, 1, 9], [0, 5, 5], [0, 0, 0], [0, 1, 2]];
        let frags = rasterize(&camera, &positions, &triangles, 32, 32);
        let (x, y) = pixel_of(&camera, [0.5, 0.4, 0.0], 32);
        assert_eq!(frags.at(x, y).unwrap().0, 5, "only the valid triangle is drawn");
        assert!(rasterize(&camera, &[], &[], 8, 8).at(4, 4).is_none());
        assert!(rasterize(&camera, &positions, &triangles, 0, 0).at(0, 0).is_none());
    }
}
