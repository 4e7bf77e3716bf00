//! Geometry of bare position slices that [`crate::TriMesh`] needs to validate itself: the bounding
//! box, its diagonal and one triangle's area. Kept apart from [`crate::geometry`], which also has
//! measures over [`crate::Topology`], so that `mesh` does not depend on `topology` (which depends on
//! `mesh`). Re-exported by [`crate::geometry`], the public path.

use crate::vector::{cross, norm, sub};

/// Corners `(min, max)` of the axis-aligned bounding box of `#V x 3` positions (infinite for no
/// points).
pub fn bbox(positions: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Diagonal of the axis-aligned bounding box of `#V x 3` positions (0 for no points).
pub fn bbox_diagonal(positions: &[[f64; 3]]) -> f64 {
    if positions.is_empty() {
        return 0.0;
    }
    let (lo, hi) = bbox(positions);
    norm(sub(hi, lo))
}

/// Area of triangle `tri` of `positions`.
pub fn triangle_area(positions: &[[f64; 3]], tri: &[u32; 3]) -> f64 {
    let [a, b, c] = tri.map(|i| positions[i as usize]);
    0.5 * norm(cross(sub(b, a), sub(c, a)))
}
