//! The orthographic camera of the figures and its framing rule.

use meshes::vector::{cross, dot, norm, normalize_or_zero, sub};

/// Direction from the scene towards the eye for every figure: front left (`-x`, `-y`), about 23
/// degrees above the horizon. Oblique, so that no survey edit happens in a plane seen edge-on; from the
/// front right instead, the survey plane's lifted ramp (normal ~ (-0.64, 0, 0.77)) is seen edge-on.
pub const VIEW_FROM: [f64; 3] = [-1.0, -1.5, 0.8];

/// The world direction drawn upwards in the figures (the survey meshes stand on `z`).
pub const VIEW_UP: [f64; 3] = [0.0, 0.0, 1.0];

/// Empty space left around the framed box, as a fraction of its projected size.
const MARGIN: f64 = 0.04;

/// An orthographic camera framing a box: maps world points to pixel coordinates of an image of any
/// size with the aspect ratio it was framed for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Unit view-plane axes (image right, image up) and the unit direction towards the eye.
    right: [f64; 3],
    up: [f64; 3],
    toward_eye: [f64; 3],
    /// View-plane coordinates of the image centre.
    center: [f64; 2],
    /// World length from the image centre to its top edge (> 0).
    half_height: f64,
    /// Image width over height the framing was computed for.
    aspect: f64,
}

impl Camera {
    /// A camera looking from `toward_eye` (towards the scene; need not be unit) with `up` drawn
    /// upwards, framing the box `lo..hi` in an image of `aspect` = width / height.
    ///
    /// Degenerate input still gives a usable camera: a zero or non-finite `toward_eye` becomes `+z`,
    /// an `up` parallel to it is replaced by another axis, a box with non-finite or inverted corners
    /// by the unit cube, a flat box is framed as if it had a small extent, a non-positive `aspect` is 1.
    pub fn framing(toward_eye: [f64; 3], up: [f64; 3], lo: [f64; 3], hi: [f64; 3], aspect: f64) -> Camera {
        let finite = |v: [f64; 3]| v.iter().all(|x| x.is_finite());
        let mut eye = if finite(toward_eye) { normalize_or_zero(toward_eye) } else { [0.0; 3] };
        if eye == [0.0; 3] {
            eye = [0.0, 0.0, 1.0];
        }
        // The first candidate not (nearly) parallel to the view direction gives the image's up.
        let candidates = [up, [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
        let right = candidates
            .iter()
            .filter(|u| finite(**u))
            .map(|u| cross(*u, eye))
            .find(|r| norm(*r) > 1e-6 * norm(eye))
            .map(normalize_or_zero)
            .unwrap_or([1.0, 0.0, 0.0]);
        let image_up = cross(eye, right);
        let (lo, hi) = if finite(lo) && finite(hi) && (0..3).all(|k| lo[k] <= hi[k]) {
            (lo, hi)
        } else {
            ([0.0; 3], [1.0; 3])
        };
        let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 };
        let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for corner in 0..8 {
            let p = std::array::from_fn(|k| if corner >> k & 1 == 0 { lo[k] } else { hi[k] });
            let q = [dot(p, right), dot(p, image_up)];
            for k in 0..2 {
                min[k] = min[k].min(q[k]);
                max[k] = max[k].max(q[k]);
            }
        }
        let half = [(max[0] - min[0]) / 2.0, (max[1] - min[1]) / 2.0];
        let diagonal = norm(sub(hi, lo));
        // A point or a segment seen end-on still needs a finite, non-zero zoom.
        let floor = if diagonal > 0.0 { 1e-3 * diagonal } else { 1.0 };
        let half_height = (half[1].max(half[0] / aspect) * (1.0 + MARGIN)).max(floor);
        Camera {
            right,
            up: image_up,
            toward_eye: eye,
            center: [(min[0] + max[0]) / 2.0, (min[1] + max[1]) / 2.0],
            half_height,
            aspect,
        }
    }

    /// The figure camera of a scenario: looking from [`VIEW_FROM`] with [`VIEW_UP`] up, framing the
    /// union of the bounding boxes of the `#V x 3` position arrays in `shapes` (the rest shape and
    /// every result; non-finite coordinates are ignored), for an image of `aspect` = width / height.
    pub fn for_shapes<'a>(shapes: impl IntoIterator<Item = &'a [[f64; 3]]>, aspect: f64) -> Camera {
        Camera::for_shapes_up(shapes, aspect, 2)
    }

    /// [`Camera::for_shapes`] for a scene standing on `up` (0: x, 1: y, 2: z) instead of `z`: the same
    /// view, turned by the cyclic permutation of the axes that takes `z` to `up` (a rotation, so the
    /// image is not mirrored).
    pub fn for_shapes_up<'a>(
        shapes: impl IntoIterator<Item = &'a [[f64; 3]]>,
        aspect: f64,
        up: usize,
    ) -> Camera {
        let (lo, hi) = union_bbox(shapes).unwrap_or(([0.0; 3], [1.0; 3]));
        let turn = |v: [f64; 3]| -> [f64; 3] {
            // z-up coordinates (a, b, c) as world coordinates with `up` in the role of z.
            match up {
                0 => [v[2], v[0], v[1]],
                1 => [v[1], v[2], v[0]],
                _ => v,
            }
        };
        Camera::framing(turn(VIEW_FROM), turn(VIEW_UP), lo, hi, aspect)
    }

    /// Unit direction from the scene towards the eye (the headlight's direction).
    pub fn toward_eye(&self) -> [f64; 3] {
        self.toward_eye
    }

    /// Unit world direction drawn upwards in the image.
    pub fn image_up(&self) -> [f64; 3] {
        self.up
    }

    /// Image width over height this camera was framed for.
    pub fn aspect(&self) -> f64 {
        self.aspect
    }

    /// `[x, y, depth]` of world point `p` in a `width x height` image: `x` right and `y` down in
    /// pixels (pixel `(i, j)` covers `[i, i + 1] x [j, j + 1]`), `depth` larger towards the eye.
    /// Non-finite for a non-finite `p`.
    pub fn project(&self, p: [f64; 3], width: u32, height: u32) -> [f64; 3] {
        let pixels_per_unit = height as f64 / (2.0 * self.half_height);
        let x = dot(p, self.right) - self.center[0];
        let y = dot(p, self.up) - self.center[1];
        [
            width as f64 / 2.0 + x * pixels_per_unit,
            height as f64 / 2.0 - y * pixels_per_unit,
            dot(p, self.toward_eye),
        ]
    }
}

/// Corners `(lo, hi)` of the box holding every finite point of all `shapes` (`#V x 3` position
/// arrays); a point with a non-finite coordinate is skipped. `None` when there is no such point.
pub fn union_bbox<'a>(shapes: impl IntoIterator<Item = &'a [[f64; 3]]>) -> Option<([f64; 3], [f64; 3])> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut any = false;
    for p in shapes.into_iter().flatten().filter(|p| p.iter().all(|x| x.is_finite())) {
        any = true;
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    any.then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshes::vector::scale;

    fn corners(lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
        (0..8).map(|c| std::array::from_fn(|k| if c >> k & 1 == 0 { lo[k] } else { hi[k] })).collect()
    }

    #[test]
    fn every_corner_of_the_framed_box_is_inside_the_image_and_the_box_fills_it() {
        let boxes = [
            ([-6.0, -6.0, 25.4], [6.0, 6.0, 100.0]),  // the survey bar
            ([0.0, 0.0, 0.0], [100.0, 100.0, 10.0]),  // the bumpy plane
            ([0.44, 0.25, 0.07], [0.56, 0.75, 0.89]), // the cactus
            ([-1.0, -1.0, 0.0], [6.2, 1.0, 12.0]),    // the bent cylinder
            ([2.0, 3.0, 4.0], [2.0, 3.0, 4.0]),       // a single point
        ];
        let views = [VIEW_FROM, [0.0, 0.0, 1.0], [0.0, 0.0, -3.0], [1.0, 0.0, 0.0], [-0.3, 2.0, -1.0]];
        for (lo, hi) in boxes {
            for view in views {
                for (width, height) in [(320, 320), (640, 200), (100, 400)] {
                    let camera = Camera::framing(view, VIEW_UP, lo, hi, width as f64 / height as f64);
                    let projected: Vec<[f64; 3]> =
                        corners(lo, hi).iter().map(|&p| camera.project(p, width, height)).collect();
                    for q in &projected {
                        assert!(
                            (0.0..=width as f64).contains(&q[0]) && (0.0..=height as f64).contains(&q[1]),
                            "box {lo:?}..{hi:?} from {view:?} in {width}x{height}: corner at {q:?}"
                        );
                    }
                    if lo == hi {
                        continue;
                    }
                    let span = |k: usize| {
                        projected.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max)
                            - projected.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min)
                    };
                    let fill = (span(0) / width as f64).max(span(1) / height as f64);
                    assert!(fill > 0.9, "box {lo:?}..{hi:?} from {view:?} fills only {fill} of the image");
                }
            }
        }
    }

    #[test]
    fn up_is_up_and_depth_grows_towards_the_eye() {
        let camera = Camera::framing(VIEW_FROM, VIEW_UP, [0.0; 3], [1.0; 3], 1.0);
        let low = camera.project([0.5, 0.5, 0.0], 100, 100);
        let high = camera.project([0.5, 0.5, 1.0], 100, 100);
        assert!(high[1] < low[1], "higher z must be higher in the image (smaller y)");
        let near = camera.project(scale(VIEW_FROM, 0.1), 100, 100);
        let far = camera.project(scale(VIEW_FROM, -0.1), 100, 100);
        assert!(near[2] > far[2]);
    }

    #[test]
    fn degenerate_input_gives_a_finite_camera() {
        let nan = [f64::NAN; 3];
        for camera in [
            Camera::framing(nan, nan, nan, nan, f64::NAN),
            Camera::framing([0.0; 3], [0.0; 3], [1.0; 3], [0.0; 3], 0.0),
            Camera::framing([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0; 3], [0.0; 3], 1.0),
            Camera::for_shapes([&[[f64::NAN, 0.0, 0.0]][..], &[]], 1.0),
        ] {
            let q = camera.project([0.3, 0.2, 0.1], 64, 64);
            assert!(q.iter().all(|x| x.is_finite()), "{camera:?}");
        }
        assert_eq!(union_bbox([&[[f64::NAN, 0.0, 0.0]][..]]), None);
        assert_eq!(
            union_bbox([&[[1.0, 2.0, 3.0], [f64::INFINITY, 0.0, 0.0]][..], &[[0.0, 5.0, -1.0]]]),
            Some(([0.0, 2.0, -1.0], [1.0, 5.0, 3.0]))
        );
    }
}
