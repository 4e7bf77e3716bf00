//! The cylinder: radius 1 around the z axis, from z = 0 to z = 12, closed by flat caps, like the
//! survey's `cylinder.off`.
//!
//! Matches the original's bounding box, its closed topology, its regions (fixed: z <= 0.55 with the
//! bottom cap; handle: z >= 11.45 with the top cap) and its 120 degree bend. The sampling differs on
//! purpose: the original has aligned rings of 40 (right triangles of aspect 1.6) and caps that are
//! fans of 9 degree slivers, which would get thinner with resolution. Here side rings are staggered
//! by half a step with spacing `sqrt(3)/2` of the ring's edge (equilateral triangles), and the caps are
//! concentric rings whose counts grow with their radius (about six around the centre).

use std::f64::consts::{PI, TAU};

use super::{select, Builder, Generated};
use crate::error::Result;

const RADIUS: f64 = 1.0;
const LENGTH: f64 = 12.0;
/// Halfway between the original's last fixed ring (z = 0.504) and first free ring (z = 0.605).
const FIXED_MAX_Z: f64 = 0.5546;
/// Halfway between the original's last free ring (z = 11.395) and first handle ring (z = 11.496).
const HANDLE_MIN_Z: f64 = 11.4454;
/// `cylinder.def`: 120 degree rotation about an axis parallel to y, bending the top over.
const TRANSFORM: [[f64; 4]; 4] = [
    [-0.5, 0.0, -0.866025, 5.196152],
    [0.0, 1.0, 0.0, 0.0],
    [0.866025, 0.0, -0.5, 9.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `k` vertices per side ring, `m` side rings, `c` cap ring steps from the centre to the rim.
struct Resolution {
    k: usize,
    m: usize,
    c: usize,
}

impl Resolution {
    fn for_k(k: usize, target: usize) -> Resolution {
        let row = (3f64.sqrt() / 2.0) * TAU * RADIUS / k as f64;
        let c = ((RADIUS / row).round() as usize).max(1);
        let mut res = Resolution { k, m: 2, c };
        // Fit the ring count to the target while keeping rows within 0.8..1.25 of equilateral.
        let m_for = |spacing: f64| LENGTH / spacing + 1.0;
        let wanted = target.saturating_sub(2 * res.cap_vertices()) as f64 / k as f64;
        res.m = (wanted.clamp(m_for(1.25 * row).ceil(), m_for(0.8 * row).floor()).round() as usize).max(2);
        res
    }

    fn for_target(target: usize) -> Resolution {
        // Side k^2 * LENGTH / (sqrt(3) pi R) plus two caps of about k^2 / (2 sqrt(3) pi) each.
        let per_k2 = (LENGTH / RADIUS + 1.0) / (3f64.sqrt() * PI);
        let k0 = ((target as f64 / per_k2).sqrt().round() as usize).max(6);
        (k0.saturating_sub(2).max(6)..=k0 + 2)
            .map(|k| Resolution::for_k(k, target))
            .min_by_key(|r| r.n_vertices().abs_diff(target))
            .unwrap_or_else(|| Resolution::for_k(k0, target))
    }

    /// Vertex count of cap ring `l` (`1..c`), proportional to its radius.
    fn cap_ring(&self, l: usize) -> usize {
        ((self.k * l) as f64 / self.c as f64).round().max(3.0) as usize
    }

    fn cap_vertices(&self) -> usize {
        1 + (1..self.c).map(|l| self.cap_ring(l)).sum::<usize>()
    }

    fn n_vertices(&self) -> usize {
        self.k * self.m + 2 * self.cap_vertices()
    }
}

pub(super) fn generate(target: usize) -> Result<Generated> {
    let res = Resolution::for_target(target);
    let mut b = Builder::with_capacity(res.n_vertices());
    let circle = |r: f64, z: f64| move |t: f64| [r * (TAU * t).cos(), r * (TAU * t).sin(), z];

    // One sweep from the bottom centre out over the bottom cap, up the side and in over the top cap;
    // every ring runs counter-clockwise about +z, which orients all faces outward.
    let mut rings = Vec::with_capacity(2 * res.c + res.m);
    rings.push(b.push_ring(1, 0.0, circle(0.0, 0.0))?);
    for l in 1..res.c {
        let r = RADIUS * l as f64 / res.c as f64;
        rings.push(b.push_ring(res.cap_ring(l), 0.5 * (l % 2) as f64, circle(r, 0.0))?);
    }
    for j in 0..res.m {
        let z = LENGTH * j as f64 / (res.m - 1) as f64;
        rings.push(b.push_ring(res.k, 0.5 * (j % 2) as f64, circle(RADIUS, z))?);
    }
    for l in (1..res.c).rev() {
        let r = RADIUS * l as f64 / res.c as f64;
        rings.push(b.push_ring(res.cap_ring(l), 0.5 * (l % 2) as f64, circle(r, LENGTH))?);
    }
    rings.push(b.push_ring(1, 0.0, circle(0.0, LENGTH))?);
    for w in rings.windows(2) {
        b.stitch(&w[0], &w[1]);
    }

    let selection = select(&b.positions, |p| p[2] <= FIXED_MAX_Z, |p| p[2] >= HANDLE_MIN_Z);
    Ok((b.into_mesh()?, selection, TRANSFORM))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_hit_the_target() {
        for target in [100, 1000, 4802, 50_000, 1_000_000] {
            let res = Resolution::for_target(target);
            let rel = res.n_vertices() as f64 / target as f64;
            assert!((0.9..=1.1).contains(&rel), "target {target}: {} vertices", res.n_vertices());
            assert!(res.cap_ring(1) <= 8, "target {target}: {} vertices around the pole", res.cap_ring(1));
        }
    }
}
