//! The cactus: a vertical trunk with two arms that leave it sideways and bend upward, closed, like the
//! survey's `cactus.off` (a remeshed sculpted model).
//!
//! Built from the original's measurements: the trunk is a surface of revolution of radius 0.0606 about
//! the vertical axis through (0.5, 0.5185), from z = 0.069 (a flat base with a rounded edge) to
//! z = 0.892 (a half-ellipsoid dome). The arms lie in the plane x = 0.5: each is an elliptic tube
//! (0.031 across, 0.0285 in the plane) that leaves the trunk slightly upward, bends up along a circular
//! arc, rises vertically and ends in a rounded tip; the -y arm joins around z = 0.51 and reaches out to
//! y = 0.254, the +y arm joins around z = 0.62 and reaches out to y = 0.746, both tips at z = 0.855,
//! which follows the original's silhouette. Where an arm joins, trunk quads are removed (an octagon),
//! the trunk around the opening is warped so its rim is an ellipse, and a fillet (a Hermite blend
//! leaving the trunk almost tangentially) flares from the rim into the arm's first section.
//!
//! Matches the original's bounding box, closed genus-0 topology, volume (1% less at the default
//! resolution), regions (fixed: the trunk's base, z <= 0.152; handle: the trunk's top, z >= 0.7965,
//! not the arm tips at the same height) and its 70 degree bend. The trunk and arms are sampled by aligned rings (right isosceles
//! triangles), with fewer vertices per ring towards the poles; the original is an isotropic remesh.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::{select, ArcTable, Builder, Generated, Ring};
use crate::error::{MeshError, Result};
use crate::vector::{add, dot, norm, normalize_or_zero, scale, sub};

/// Trunk axis (x, y).
const AXIS: [f64; 2] = [0.50005, 0.5185];
const TRUNK_RADIUS: f64 = 0.06063;
const Z_BOTTOM: f64 = 0.06887;
const Z_TOP: f64 = 0.89169;
/// Semi-axes (horizontal, vertical) of the rounded edge of the base.
const BASE_ROUNDING: [f64; 2] = [0.015, 0.05];
/// Height of the half-ellipsoid dome that closes the trunk.
const DOME_HEIGHT: f64 = 0.074;
/// Semi-axes of an arm's cross-section: across its plane (x) and within it.
const ARM_RADII: [f64; 2] = [0.031, 0.0285];
/// Height of the half-ellipsoid that rounds an arm's tip.
const TIP_HEIGHT: f64 = 0.03;
/// Arc width and height of the opening in the trunk where an arm joins.
const JOINT_SIZE: [f64; 2] = [0.08, 0.09];
/// The warp fades out at this many half-sizes from the opening's centre.
const WARP_REACH: f64 = 2.5;
/// The arm's first cross-section is this far outside the trunk's surface (measured along the arm).
const JOINT_REACH: f64 = 0.035;
/// Angle (radians) between the trunk's surface and the fillet where it leaves the opening's rim: less
/// than a right angle makes a flared joint instead of a crease.
const FILLET_ANGLE: f64 = 0.2;
/// Vertices at or below this z are fixed: between the original's highest fixed (0.1532) and lowest
/// free (0.1506) vertices, whose boundary is not quite level.
const FIXED_MAX_Z: f64 = 0.152;
/// Trunk vertices at or above this z are the handle: halfway between the original's lowest handle
/// vertex (0.7932) and highest free trunk vertex (0.7999), a boundary not quite level either.
const HANDLE_MIN_Z: f64 = 0.7965;
/// `cactus.def`: about 70 degrees of rotation of the top, bending it sideways.
const TRANSFORM: [[f64; 4]; 4] = [
    [0.999641, 0.021031, 0.016579, -0.019322],
    [-0.022776, 0.342021, 0.939416, -0.134331],
    [0.014087, -0.939457, 0.342378, 0.821073],
    [0.0, 0.0, 0.0, 1.0],
];
/// Surface area (about 0.45) over the vertex count gives the squared edge length of a right
/// isosceles sampling; the first build corrects the estimate.
const AREA: f64 = 0.45;
/// Samples per quarter ellipse of the profile curves (arclength tables; far finer than any ring step).
const CURVE_SAMPLES: usize = 1024;

/// An arm: its centreline starts on the trunk axis at height `z_start`, runs straight towards `side`
/// (the sign of y) at `elevation` radians above the horizontal for `straight`, bends up along a
/// circular arc of radius `bend` until vertical, and rises until its rounded tip reaches z = `tip`.
struct Arm {
    side: f64,
    z_start: f64,
    elevation: f64,
    straight: f64,
    bend: f64,
    tip: f64,
}

/// The -y arm leaves the trunk at 15 degrees around z = 0.505 and is vertical from z = 0.644 at
/// y = 0.2823; the +y arm leaves at 30 degrees around z = 0.62 and is vertical from z = 0.76 at
/// y = 0.7175 (fitted to the original's silhouette in the plane x = 0.5).
const ARMS: [Arm; 2] = [
    Arm { side: -1.0, z_start: 0.489, elevation: PI / 12.0, straight: 0.153, bend: 0.1195, tip: 0.85472 },
    Arm { side: 1.0, z_start: 0.587, elevation: PI / 6.0, straight: 0.172, bend: 0.1, tip: 0.85528 },
];

/// Centreline frame: point, unit tangent `d`, unit normal `n` in the arm's plane; the section's other
/// axis is `n x d`, the same for the whole arm.
struct Frame {
    point: [f64; 3],
    d: [f64; 3],
    n: [f64; 3],
}

impl Arm {
    /// Arclength where the vertical part starts.
    fn vertical_start(&self) -> f64 {
        self.straight + self.bend * (FRAC_PI_2 - self.elevation)
    }

    /// Arclength where the tip's rounding starts.
    fn tube_end(&self) -> f64 {
        let (sin, cos) = self.elevation.sin_cos();
        let z_vertical = self.z_start + self.straight * sin + self.bend * cos;
        self.vertical_start() + (self.tip - TIP_HEIGHT - z_vertical)
    }

    /// Arclength where the centreline leaves the trunk.
    fn exit(&self) -> f64 {
        TRUNK_RADIUS / self.elevation.cos()
    }

    /// `n x d`: across the arm's plane, `-side` along x.
    fn across(&self) -> [f64; 3] {
        [-self.side, 0.0, 0.0]
    }

    fn frame(&self, s: f64) -> Frame {
        let [x, y] = AXIS;
        let (sin0, cos0) = self.elevation.sin_cos();
        // Direction angle along the bend, clamped to the straight parts before and after it.
        let psi = (self.elevation + (s - self.straight) / self.bend).clamp(self.elevation, FRAC_PI_2);
        let (sin, cos) = psi.sin_cos();
        let along = s.min(self.straight);
        let after = (s - self.vertical_start()).max(0.0);
        let horizontal = along * cos0 + self.bend * (sin - sin0);
        let vertical = along * sin0 + self.bend * (cos0 - cos) + after;
        Frame {
            point: [x, y + self.side * horizontal, self.z_start + vertical],
            d: [0.0, self.side * cos, sin],
            n: [0.0, -self.side * sin, cos],
        }
    }

    /// Point of the section at `s` with angle `2 pi t` from the `across` axis towards `n`, its radii
    /// scaled by `shrink`, lifted by `lift` along the tangent.
    fn section_point(&self, frame: &Frame, t: f64, shrink: f64, lift: f64) -> [f64; 3] {
        let (sin, cos) = (TAU * t).sin_cos();
        let radial = add(scale(self.across(), ARM_RADII[0] * cos), scale(frame.n, ARM_RADII[1] * sin));
        add(add(frame.point, scale(radial, shrink)), scale(frame.d, lift))
    }
}

/// Opening in the trunk where an arm joins: the quads between rings `rows[0]..=rows[1]` and columns
/// `cols[0]..=cols[1]` are removed, and the trunk around it is warped so that the rim is an ellipse.
struct Joint {
    rows: [usize; 2],
    cols: [usize; 2],
    /// Angle about the trunk axis and height of the opening's centre.
    centre: [f64; 2],
    /// Half the rectangle's size before warping: arc width and height.
    half: [f64; 2],
}

impl Joint {
    /// Coordinates of the trunk point at `angle`, height `z` relative to the centre, in units of the
    /// half sizes: the rim is the square with max-norm 1.
    fn local(&self, angle: f64, z: f64) -> [f64; 2] {
        let mut da = (angle - self.centre[0]).rem_euclid(TAU);
        if da > PI {
            da -= TAU;
        }
        [TRUNK_RADIUS * da / self.half[0], (z - self.centre[1]) / self.half[1]]
    }

    /// Gauge of the rim in local coordinates: 1 on the rim (a rectangle, or an octagon when its corners
    /// are cut), growing linearly outward along every ray from the centre.
    fn gauge(&self, [u, v]: [f64; 2]) -> f64 {
        let box_norm = u.abs().max(v.abs());
        if !self.chamfered() {
            return box_norm;
        }
        // In quad units the cut is the 45 degree line one quad in from the corner.
        let [a, b] = [(self.cols[1] - self.cols[0]) as f64, (self.rows[1] - self.rows[0]) as f64];
        box_norm.max((u.abs() * a + v.abs() * b) / (a + b - 2.0))
    }

    /// Where the trunk point at `(angle, z)` moves: radially from the centre so that the rim becomes an
    /// ellipse and the trunk beyond it follows, fading out smoothly at `WARP_REACH` times the rim's
    /// size. An elliptic rim lets the fillet blend into the trunk without visible corners.
    fn warp(&self, angle: f64, z: f64) -> [f64; 2] {
        let [u, v] = self.local(angle, z);
        let gauge = self.gauge([u, v]);
        if !(gauge > 0.0 && gauge < WARP_REACH) {
            return [angle, z];
        }
        let rounded = gauge / u.hypot(v);
        let fade = ((gauge - 1.0) / (WARP_REACH - 1.0)).clamp(0.0, 1.0);
        let fade = fade * fade * (3.0 - 2.0 * fade);
        let f = rounded * (1.0 - fade) + fade;
        [self.centre[0] + f * u * self.half[0] / TRUNK_RADIUS, self.centre[1] + f * v * self.half[1]]
    }

    /// Vertex `(i, j)` is strictly inside the opening (not created).
    fn removes_vertex(&self, i: usize, j: usize) -> bool {
        self.rows[0] < j && j < self.rows[1] && self.cols[0] < i && i < self.cols[1]
    }

    /// Corners are cut off (when the opening is at least two quads each way), so the rim is an
    /// octagon: rounding it then distorts the trunk much less than rounding a rectangle.
    fn chamfered(&self) -> bool {
        self.rows[1] - self.rows[0] >= 2 && self.cols[1] - self.cols[0] >= 2
    }

    /// What is left of the quad between rings `j`, `j + 1` and columns `i`, `i + 1`.
    fn quad_part(&self, i: usize, j: usize) -> QuadPart {
        let ([ja, jb], [ia, ib]) = (self.rows, self.cols);
        if !(ja <= j && j < jb && ia <= i && i < ib) {
            return QuadPart::Whole;
        }
        if !self.chamfered() {
            return QuadPart::Removed;
        }
        match (i == ia, i + 1 == ib, j == ja, j + 1 == jb) {
            (true, _, true, _) => QuadPart::Corner(0),
            (_, true, true, _) => QuadPart::Corner(1),
            (_, true, _, true) => QuadPart::Corner(2),
            (true, _, _, true) => QuadPart::Corner(3),
            _ => QuadPart::Removed,
        }
    }

    /// The rim as `(column, ring)` pairs, counter-clockwise seen from outside (so the fillet's faces
    /// point outward): up the column of larger angle, back along the upper ring, down, and along the
    /// lower ring, skipping the cut corners.
    fn rim(&self) -> Vec<(usize, usize)> {
        let ([ja, jb], [ia, ib]) = (self.rows, self.cols);
        let cut = usize::from(self.chamfered());
        let mut rim = Vec::with_capacity(2 * (jb - ja + ib - ia));
        rim.extend((ja + cut..jb).map(|j| (ib, j)));
        rim.extend((ia + 1..=ib - cut).rev().map(|i| (i, jb)));
        rim.extend((ja + 1..=jb - cut).rev().map(|j| (ia, j)));
        rim.extend((ia + cut..ib).map(|i| (i, ja)));
        rim
    }
}

/// What an opening leaves of a trunk quad.
enum QuadPart {
    Whole,
    Removed,
    /// Only the triangle at quad corner `c` (counter-clockwise from the lower ring's first vertex).
    Corner(usize),
}

/// Trunk profile `(r, z)` from the bottom pole to the top pole.
fn trunk_profile() -> ArcTable {
    let [fr, fz] = BASE_ROUNDING;
    let r = TRUNK_RADIUS;
    let dome_base = Z_TOP - DOME_HEIGHT;
    let mut points = Vec::with_capacity(2 * CURVE_SAMPLES + 2);
    points.push([0.0, Z_BOTTOM]);
    for k in 0..=CURVE_SAMPLES {
        let a = FRAC_PI_2 * k as f64 / CURVE_SAMPLES as f64;
        points.push([r - fr + fr * a.sin(), Z_BOTTOM + fz - fz * a.cos()]);
    }
    for k in 0..CURVE_SAMPLES {
        let a = FRAC_PI_2 * k as f64 / CURVE_SAMPLES as f64;
        points.push([r * a.cos(), dome_base + DOME_HEIGHT * a.sin()]);
    }
    points.push([0.0, Z_TOP]);
    ArcTable::new(points)
}

/// Ring count for a loop of radius `r` on a surface whose full loops of radius `full` have `k`.
fn ring_count(k: usize, r: f64, full: f64) -> usize {
    ((k as f64 * r / full).round() as usize).clamp(3, k)
}

/// Build the cactus with edges of about `h`.
fn build(h: f64) -> Result<Builder> {
    let profile = trunk_profile();
    let n_rings = ((profile.length() / h).round() as usize).max(6);
    let k = ((TAU * TRUNK_RADIUS / h).round() as usize).max(6);
    let samples: Vec<[f64; 2]> =
        (0..=n_rings).map(|j| profile.at(profile.length() * j as f64 / n_rings as f64)).collect();
    let counts: Vec<usize> = samples
        .iter()
        .enumerate()
        .map(|(j, &[r, _])| if j == 0 || j == n_rings { 1 } else { ring_count(k, r, TRUNK_RADIUS) })
        .collect();

    let joints = ARMS
        .iter()
        .map(|arm| {
            let nearest = |z: f64| {
                (0..=n_rings).min_by(|&a, &b| (samples[a][1] - z).abs().total_cmp(&(samples[b][1] - z).abs()))
            };
            let z_exit = arm.frame(arm.exit()).point[2];
            let (lo, hi) = (z_exit - JOINT_SIZE[1] / 2.0, z_exit + JOINT_SIZE[1] / 2.0);
            let (Some(ja), Some(jb)) = (nearest(lo), nearest(hi)) else {
                return Err(MeshError::Invalid("cactus: trunk has no rings".into()));
            };
            let jb = jb.max(ja + 1);
            if (ja..=jb).any(|j| counts[j] != k) {
                return Err(MeshError::Invalid(format!(
                    "cactus: arm joint rings {ja}..={jb} leave the trunk's cylindrical part"
                )));
            }
            let step = TAU * TRUNK_RADIUS / k as f64;
            let width = ((JOINT_SIZE[0] / step).round() as usize).clamp(1, k / 2 - 1);
            let centre = if arm.side > 0.0 { 0.25 } else { 0.75 } * k as f64;
            let ia = (centre - width as f64 / 2.0).round() as usize;
            let [za, zb] = [samples[ja][1], samples[jb][1]];
            Ok(Joint {
                rows: [ja, jb],
                cols: [ia, ia + width],
                centre: [TAU * (2 * ia + width) as f64 / (2 * k) as f64, (za + zb) / 2.0],
                half: [step * width as f64 / 2.0, (zb - za) / 2.0],
            })
        })
        .collect::<Result<Vec<Joint>>>()?;

    let mut b = Builder::with_capacity((AREA / (h * h)) as usize + 64);
    let [ax, ay] = AXIS;
    // Trunk rings, counter-clockwise about +z from +x; vertices inside an opening are not created.
    let mut trunk: Vec<Ring> = Vec::with_capacity(n_rings + 1);
    for (j, (&[r, z], &n)) in samples.iter().zip(&counts).enumerate() {
        let mut ring = Ring { verts: Vec::with_capacity(n), params: Vec::with_capacity(n) };
        for i in 0..n {
            let t = i as f64 / n as f64;
            let removed = joints.iter().any(|jt| jt.removes_vertex(i, j));
            ring.verts.push(if removed { u32::MAX } else { b.next_index()? });
            ring.params.push(t);
            if !removed {
                let mut at = [TAU * t, z];
                // Only the cylindrical part is warped (every opening lies well inside it).
                if n == k {
                    for joint in &joints {
                        at = joint.warp(at[0], at[1]);
                    }
                }
                b.positions.push([ax + r * at[0].cos(), ay + r * at[0].sin(), at[1]]);
            }
        }
        trunk.push(ring);
    }
    for j in 0..n_rings {
        let (lo, hi) = (&trunk[j], &trunk[j + 1]);
        if counts[j] != k || counts[j + 1] != k {
            b.stitch(lo, hi);
            continue;
        }
        // Bands of the cylindrical part are quads, minus the openings; each is split along its shorter
        // diagonal, which only differs from the usual one where the warp has sheared the quad.
        for i in 0..k {
            let i1 = (i + 1) % k;
            let [a0, a1, b0, b1] = [lo.verts[i], lo.verts[i1], hi.verts[i], hi.verts[i1]];
            let part = joints.iter().map(|jt| jt.quad_part(i, j)).find(|p| !matches!(p, QuadPart::Whole));
            match part {
                Some(QuadPart::Removed) => continue,
                Some(QuadPart::Corner(c)) => {
                    let quad = [a0, a1, b1, b0];
                    b.triangles.push([quad[c], quad[(c + 1) % 4], quad[(c + 3) % 4]]);
                    continue;
                }
                _ => {}
            }
            let length = |p: u32, q: u32| norm(sub(b.positions[p as usize], b.positions[q as usize]));
            if length(a0, b1) < 0.98 * length(a1, b0) {
                b.triangles.push([a0, a1, b1]);
                b.triangles.push([a0, b1, b0]);
            } else {
                b.triangles.push([a0, a1, b0]);
                b.triangles.push([a1, b1, b0]);
            }
        }
    }

    for (arm, joint) in ARMS.iter().zip(&joints) {
        build_arm(&mut b, arm, joint, &trunk, &samples, k, h)?;
    }
    Ok(b)
}

/// Add the fillet, tube and tip of `arm`, starting from the rim of its opening in the trunk.
fn build_arm(
    b: &mut Builder,
    arm: &Arm,
    joint: &Joint,
    trunk: &[Ring],
    samples: &[[f64; 2]],
    k: usize,
    h: f64,
) -> Result<()> {
    let rim = joint.rim();
    // Parameters by angle about the opening's centre (in half-size units, so the elliptic rim matches
    // the elliptic sections angle for angle): zero on the `across` axis, the trunk's tangent there.
    let mut params: Vec<f64> = Vec::with_capacity(rim.len());
    for &(i, j) in &rim {
        let [u, v] = joint.local(TAU * i as f64 / k as f64, samples[j][1]);
        let mut t = v.atan2(u) / TAU;
        if let Some(&last) = params.last() {
            t += (last - t).ceil().max(0.0);
        }
        params.push(t);
    }
    let rim_ring = Ring { verts: rim.iter().map(|&(i, j)| trunk[j].verts[i]).collect(), params };
    let rim_points: Vec<[f64; 3]> = rim_ring.verts.iter().map(|&v| b.positions[v as usize]).collect();
    let rim_params = rim_ring.params.clone();

    let [ax, ay] = AXIS;
    let [angle, z_centre] = joint.centre;
    let opening_centre = [ax + TRUNK_RADIUS * angle.cos(), ay + TRUNK_RADIUS * angle.sin(), z_centre];
    let k_arm = ((PI * (ARM_RADII[0] + ARM_RADII[1]) / h).round() as usize).max(4);
    let step = PI * (ARM_RADII[0] + ARM_RADII[1]) / k_arm as f64;
    let s_start = arm.exit() + JOINT_REACH;
    let start = arm.frame(s_start);

    // Fillet: cubic Hermite from the rim point (leaving at FILLET_ANGLE to the trunk, towards the
    // opening's centre) to the same-parameter point of the first section (along the arm).
    let fillet_point = |t: f64, u: f64| -> [f64; 3] {
        let rim_point = loop_point(&rim_params, &rim_points, t);
        let section = arm.section_point(&start, t, 1.0, 0.0);
        let radial = normalize_or_zero([rim_point[0] - ax, rim_point[1] - ay, 0.0]);
        let to_centre = sub(opening_centre, rim_point);
        let inward = normalize_or_zero(sub(to_centre, scale(radial, dot(to_centre, radial))));
        let chord = norm(sub(section, rim_point));
        let t0 = scale(add(scale(inward, FILLET_ANGLE.cos()), scale(radial, FILLET_ANGLE.sin())), chord);
        let t1 = scale(start.d, chord);
        let (u2, u3) = (u * u, u * u * u);
        let terms = [
            (2.0 * u3 - 3.0 * u2 + 1.0, rim_point),
            (u3 - 2.0 * u2 + u, t0),
            (-2.0 * u3 + 3.0 * u2, section),
            (u3 - u2, t1),
        ];
        terms.iter().fold([0.0; 3], |acc, &(w, p)| add(acc, scale(p, w)))
    };
    let n_fillet = ((norm(sub(start.point, opening_centre)) / h).round() as usize).max(1);
    let mut prev = rim_ring;
    for l in 1..n_fillet {
        let u = l as f64 / n_fillet as f64;
        let count = (prev.verts.len() as f64
            + (k_arm as f64 - prev.verts.len() as f64) / (n_fillet - l + 1) as f64)
            .round()
            .max(3.0) as usize;
        let ring = b.push_ring(count, 0.5 * (l % 2) as f64, |t| fillet_point(t, u))?;
        b.stitch(&prev, &ring);
        prev = ring;
    }

    // Tube from the first section to the tip, sections about one edge apart.
    let n_tube = (((arm.tube_end() - s_start) / step).round() as usize).max(1);
    for l in 0..=n_tube {
        let s = s_start + (arm.tube_end() - s_start) * l as f64 / n_tube as f64;
        let frame = arm.frame(s);
        let ring = b.push_ring(k_arm, 0.0, |t| arm.section_point(&frame, t, 1.0, 0.0))?;
        b.stitch(&prev, &ring);
        prev = ring;
    }

    // Tip: half-ellipsoid, loops shrinking with the mean section radius to a pole.
    let end = arm.frame(arm.tube_end());
    let mean_radius = (ARM_RADII[0] + ARM_RADII[1]) / 2.0;
    let meridian = ArcTable::new(
        (0..=CURVE_SAMPLES)
            .map(|q| {
                let a = FRAC_PI_2 * q as f64 / CURVE_SAMPLES as f64;
                [mean_radius * a.cos(), TIP_HEIGHT * a.sin()]
            })
            .collect(),
    );
    let n_tip = ((meridian.length() / step).round() as usize).max(1);
    for l in 1..=n_tip {
        let [r, lift] = meridian.at(meridian.length() * l as f64 / n_tip as f64);
        let ring = if l == n_tip {
            b.push_ring(1, 0.0, |_| arm.section_point(&end, 0.0, 0.0, TIP_HEIGHT))?
        } else {
            let shrink = r / mean_radius;
            b.push_ring(ring_count(k_arm, r, mean_radius), 0.0, |t| arm.section_point(&end, t, shrink, lift))?
        };
        b.stitch(&prev, &ring);
        prev = ring;
    }
    Ok(())
}

/// Point at parameter `t` on the closed polyline `points` with increasing loop parameters `params`
/// (spanning less than one turn).
fn loop_point(params: &[f64], points: &[[f64; 3]], t: f64) -> [f64; 3] {
    let n = params.len();
    let p0 = params[0];
    let x = (t - p0).rem_euclid(1.0);
    let k = params.partition_point(|&p| p - p0 <= x).clamp(1, n);
    let (lo, hi) = (params[k - 1] - p0, if k == n { 1.0 } else { params[k] - p0 });
    let w = if hi > lo { ((x - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.0 };
    let (a, c) = (points[k - 1], points[k % n]);
    add(a, scale(sub(c, a), w))
}

pub(super) fn generate(target: usize) -> Result<Generated> {
    let mut h = (AREA / target as f64).sqrt();
    let mut best = build(h)?;
    // The area estimate is rough at small sizes (poles, fillets): rescale the edge length until the
    // count is within 3%, keeping the best attempt.
    for _ in 0..3 {
        let ratio = best.positions.len() as f64 / target as f64;
        if (ratio - 1.0).abs() < 0.03 {
            break;
        }
        h *= ratio.sqrt();
        let next = build(h)?;
        if next.positions.len().abs_diff(target) >= best.positions.len().abs_diff(target) {
            break;
        }
        best = next;
    }
    let [ax, ay] = AXIS;
    let in_trunk = |p: &[f64; 3]| (p[0] - ax).hypot(p[1] - ay) < 2.0 * TRUNK_RADIUS;
    let selection = select(&best.positions, |p| p[2] <= FIXED_MAX_Z, |p| p[2] >= HANDLE_MIN_Z && in_trunk(p));
    Ok((best.into_mesh()?, selection, TRANSFORM))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arms_reach_the_originals_extent() {
        let [left, right] = &ARMS;
        let outer = |arm: &Arm| arm.frame(arm.tube_end()).point[1] + arm.side * ARM_RADII[1];
        assert!((outer(left) - 0.2538).abs() < 1e-3, "{}", outer(left));
        assert!((outer(right) - 0.7460).abs() < 1e-3, "{}", outer(right));
        for arm in &ARMS {
            let top = arm.frame(arm.tube_end()).point[2] + TIP_HEIGHT;
            assert!((top - arm.tip).abs() < 1e-12);
            // The centreline is continuous and unit speed through the bend.
            let ds = 1e-6;
            for s in [arm.straight, arm.vertical_start(), 0.5 * (arm.straight + arm.vertical_start())] {
                let (p, q) = (arm.frame(s - ds).point, arm.frame(s + ds).point);
                assert!((norm(sub(q, p)) / (2.0 * ds) - 1.0).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn loop_point_interpolates_and_wraps() {
        let params = [-0.25, 0.0, 0.25, 0.5];
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(loop_point(&params, &points, 0.125), [1.0, 0.5, 0.0]);
        assert_eq!(loop_point(&params, &points, 0.625), [0.0, 0.5, 0.0]);
        assert_eq!(loop_point(&params, &points, 1.0), [1.0, 0.0, 0.0]);
    }
}
