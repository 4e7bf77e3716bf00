//! The bar: a 12 x 12 square prism along z, from z = 25.39 to z = 100, closed by a flat cap at the top
//! and open at the bottom, like the survey's `bar.off` (whose one boundary loop is its bottom rim).
//!
//! Matches the original's bounding box (the original's cap is flat up to 0.007 of noise), its side
//! sampling (rings of `4n` vertices, `n = 15` at the default resolution, quads split into right
//! isosceles triangles), its regions (fixed: the bottom 4.5 units; handle: the top 4.3 units and the
//! cap) and its 135 degree twist about the z axis. The cap is a regular grid whose diagonals point at
//! its centre, so the mesh has the twist's four-fold symmetry.

use super::{select, Builder, Generated};
use crate::error::Result;

/// Half the side of the square cross-section (centred on the z axis).
const HALF_WIDTH: f64 = 6.0;
/// z of the open bottom rim.
const Z_BOTTOM: f64 = 25.390625;
/// z of the top cap.
const Z_TOP: f64 = 100.0;
/// Vertices at or below this z are fixed: the original's fixed region ends at its ring z = 29.902.
const FIXED_MAX_Z: f64 = 29.95;
/// Vertices at or above this z are the handle: halfway between the original's last free ring
/// (z = 95.527) and first handle ring (z = 95.938).
const HANDLE_MIN_Z: f64 = 95.73;
/// `bar.def`: 135 degree rotation about the z axis (the file's six-digit numbers, kept verbatim).
#[allow(clippy::approx_constant)]
const TRANSFORM: [[f64; 4]; 4] = [
    [-0.707107, -0.707107, 0.0, 0.0],
    [0.707107, -0.707107, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Side resolution: `n` edges per side of the square, `m` rings from bottom to top.
struct Resolution {
    n: usize,
    m: usize,
}

impl Resolution {
    fn for_target(target: usize) -> Resolution {
        let length = Z_TOP - Z_BOTTOM;
        let width = 2.0 * HALF_WIDTH;
        // V = 4nm + (n-1)^2 with square side cells (m - 1 = n * length / width).
        let per_n2 = 4.0 * length / width + 1.0;
        let n = ((target as f64 / per_n2).sqrt().round() as usize).max(2);
        let h = width / n as f64;
        // Fit the ring count to the target exactly while keeping side cells within 0.8..1.25 of square.
        let m_for = |spacing: f64| length / spacing + 1.0;
        let cap = (n - 1) * (n - 1);
        let wanted = target.saturating_sub(cap) as f64 / (4 * n) as f64;
        let m = wanted.clamp(m_for(1.25 * h).ceil(), m_for(0.8 * h).floor()).round() as usize;
        Resolution { n, m: m.max(2) }
    }

    fn n_vertices(&self) -> usize {
        4 * self.n * self.m + (self.n - 1) * (self.n - 1)
    }
}

pub(super) fn generate(target: usize) -> Result<Generated> {
    let res = Resolution::for_target(target);
    let (n, m) = (res.n, res.m);
    let h = 2.0 * HALF_WIDTH / n as f64;
    let per_ring = 4 * n;
    let mut b = Builder::with_capacity(res.n_vertices());

    // Rings run counter-clockwise seen from +z, starting at the (-, -) corner.
    for j in 0..m {
        let z = Z_BOTTOM + (Z_TOP - Z_BOTTOM) * j as f64 / (m - 1) as f64;
        for i in 0..per_ring {
            let t = (i % n) as f64 * h;
            let [x, y] = match i / n {
                0 => [-HALF_WIDTH + t, -HALF_WIDTH],
                1 => [HALF_WIDTH, -HALF_WIDTH + t],
                2 => [HALF_WIDTH - t, HALF_WIDTH],
                _ => [-HALF_WIDTH, HALF_WIDTH - t],
            };
            b.positions.push([x, y, z]);
        }
    }
    let cap_base = b.positions.len();
    for q in 1..n {
        for p in 1..n {
            b.positions.push([-HALF_WIDTH + p as f64 * h, -HALF_WIDTH + q as f64 * h, Z_TOP]);
        }
    }
    b.next_index()?;

    for j in 0..m - 1 {
        let (lo, hi) = (j * per_ring, (j + 1) * per_ring);
        for i in 0..per_ring {
            let i1 = (i + 1) % per_ring;
            let [a0, a1, b0, b1] = [lo + i, lo + i1, hi + i, hi + i1].map(|v| v as u32);
            b.triangles.push([a0, a1, b0]);
            b.triangles.push([a1, b1, b0]);
        }
    }

    // Cap grid node (p, q), 0..=n each: on the rim it is a top-ring vertex, inside a cap vertex.
    let top = (m - 1) * per_ring;
    let node = |p: usize, q: usize| -> u32 {
        let v = if q == 0 {
            top + p
        } else if p == n {
            top + n + q
        } else if q == n {
            top + 2 * n + (n - p)
        } else if p == 0 {
            top + (3 * n + (n - q)) % per_ring
        } else {
            cap_base + (q - 1) * (n - 1) + (p - 1)
        };
        v as u32
    };
    let centre = n as f64 / 2.0;
    for q in 0..n {
        for p in 0..n {
            let [v00, v10, v11, v01] = [node(p, q), node(p + 1, q), node(p + 1, q + 1), node(p, q + 1)];
            // Diagonal through the cell's corner nearest the centre: the four quadrants are rotations of
            // each other, and no triangle has all three corners on the rim.
            if (p as f64 + 0.5 - centre) * (q as f64 + 0.5 - centre) > 0.0 {
                b.triangles.push([v00, v10, v11]);
                b.triangles.push([v00, v11, v01]);
            } else {
                b.triangles.push([v00, v10, v01]);
                b.triangles.push([v10, v11, v01]);
            }
        }
    }

    let selection = select(&b.positions, |p| p[2] <= FIXED_MAX_Z, |p| p[2] >= HANDLE_MIN_Z);
    Ok((b.into_mesh()?, selection, TRANSFORM))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_resolution_matches_the_original_sampling() {
        let res = Resolution::for_target(6084);
        assert_eq!(res.n, 15, "the original has 15 edges per side");
        assert!(res.n_vertices().abs_diff(6084) < 100, "{} vertices", res.n_vertices());
    }

    #[test]
    fn side_cells_stay_near_square() {
        for target in [100, 999, 6084, 50_000, 1_000_000] {
            let res = Resolution::for_target(target);
            let h = 2.0 * HALF_WIDTH / res.n as f64;
            let dz = (Z_TOP - Z_BOTTOM) / (res.m - 1) as f64;
            assert!((0.79..=1.26).contains(&(dz / h)), "target {target}: aspect {}", dz / h);
            let rel = res.n_vertices() as f64 / target as f64;
            assert!((0.85..=1.15).contains(&rel), "target {target}: {} vertices", res.n_vertices());
        }
    }
}
