//! Isolines of a piecewise-linear scalar field on a triangle mesh (Au et al. 2007, section 4.1): the
//! triangles an isoline crosses, with the segment it draws across each (`Gamma_ij` and `l_k`,
//! section 4.3). An isoline may consist of several loops; the reduced model treats all of them as
//! one rigid component, so the segments are kept as a set and not chained into loops.

/// A point on the edge `(a, b)` at `(1 - t) x_a + t x_b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgePoint {
    pub a: u32,
    pub b: u32,
    pub t: f64,
}

impl EdgePoint {
    /// The point on the given `#V x 3` positions.
    pub fn position(&self, positions: &[[f64; 3]]) -> [f64; 3] {
        let (pa, pb) = (positions[self.a as usize], positions[self.b as usize]);
        std::array::from_fn(|c| (1.0 - self.t) * pa[c] + self.t * pb[c])
    }

    /// The field interpolated at the point.
    pub fn value(&self, field: &[f64]) -> f64 {
        (1.0 - self.t) * field[self.a as usize] + self.t * field[self.b as usize]
    }
}

/// The segment of an isoline inside one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossedTriangle {
    /// Index of the triangle.
    pub triangle: u32,
    /// Where the isoline enters and leaves the triangle.
    pub ends: [EdgePoint; 2],
    /// Segment length on the rest mesh (`l_k`, eq 9's weight).
    pub length: f64,
}

/// Every triangle that the level set `field = level` crosses, in triangle order.
///
/// `positions`: `#V x 3`; `triangles`: `#F`; `field`: `#V` values. A vertex counts as above the level
/// when its value is `>= level`; a triangle is crossed when it has vertices on both sides, and its
/// segment joins the points where the two edges with one vertex on each side reach `level`.
pub fn trace_isoline(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    field: &[f64],
    level: f64,
) -> Vec<CrossedTriangle> {
    let mut out = Vec::new();
    for (f, tri) in triangles.iter().enumerate() {
        let above = tri.map(|v| field[v as usize] >= level);
        if above[0] == above[1] && above[1] == above[2] {
            continue;
        }
        let mut ends = [EdgePoint { a: 0, b: 0, t: 0.0 }; 2];
        let mut found = 0;
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            if above[e] != above[(e + 1) % 3] {
                let (fa, fb) = (field[a as usize], field[b as usize]);
                ends[found] = EdgePoint { a, b, t: ((level - fa) / (fb - fa)).clamp(0.0, 1.0) };
                found += 1;
            }
        }
        debug_assert_eq!(found, 2, "a triangle with vertices on both sides has two crossed edges");
        let (p, q) = (ends[0].position(positions), ends[1].position(positions));
        let length = meshes::vector::norm(meshes::vector::sub(p, q));
        out.push(CrossedTriangle { triangle: f as u32, ends, length });
    }
    out
}

/// At most `limit` of the crossed triangles, taken uniformly along the list (every `ceil(len /
/// limit)`-th one, starting with the first), as section 4.3 samples `Gamma_ij` down to a bound.
pub fn sample_uniformly(crossed: Vec<CrossedTriangle>, limit: usize) -> Vec<CrossedTriangle> {
    if crossed.len() <= limit {
        return crossed;
    }
    let stride = crossed.len().div_ceil(limit.max(1));
    crossed.into_iter().step_by(stride).collect()
}
