//! Procedural look-alikes of the four Botsch–Sorkine deformation-survey test shapes (bar, cylinder,
//! cactus, bumpy plane) at any resolution from about a hundred to twenty million vertices.
//!
//! Each look-alike reproduces what a deformation method sees of the original: its dimensions (bounding
//! box), whether it is open or closed, where its fixed and handle regions are (defined geometrically, so
//! they scale with the resolution) and the survey's handle transform (the `.def` numbers, verbatim).
//! Triangles are near-equilateral or right isosceles; the shapes are deterministic.

use std::fmt;
use std::str::FromStr;

use crate::edit::{AffineTransform, VertexStatus};
use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

mod bar;
mod bumpy_plane;
mod cactus;
mod cylinder;

/// Smallest accepted `target_vertices`: below it the shapes lose their fixed, free and handle regions.
pub const MIN_TARGET_VERTICES: usize = 100;

/// Largest accepted `target_vertices` (positions and triangles then take about 1.5 GB).
pub const MAX_TARGET_VERTICES: usize = 20_000_000;

/// One of the four survey test shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShapeKind {
    /// Square bar, open at the bottom, twisted by 135 degrees.
    Bar,
    /// Closed round cylinder, bent by 120 degrees.
    Cylinder,
    /// Closed cactus (trunk with two arms), top bent by 70 degrees.
    Cactus,
    /// Open plane with 13 bumps, one edge translated.
    BumpyPlane,
}

impl ShapeKind {
    /// All shapes, in the survey's order.
    pub const ALL: [ShapeKind; 4] =
        [ShapeKind::Bar, ShapeKind::Cylinder, ShapeKind::Cactus, ShapeKind::BumpyPlane];

    /// The shape's name, also the stem of the survey's files (`bar`, `cylinder`, `cactus`, `plane`).
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Bar => "bar",
            ShapeKind::Cylinder => "cylinder",
            ShapeKind::Cactus => "cactus",
            ShapeKind::BumpyPlane => "plane",
        }
    }
}

impl fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ShapeKind {
    type Err = MeshError;

    /// Parse a name of [`ShapeKind::name`], ignoring ASCII case.
    fn from_str(s: &str) -> Result<Self> {
        ShapeKind::ALL.into_iter().find(|k| k.name().eq_ignore_ascii_case(s.trim())).ok_or_else(|| {
            let names: Vec<&str> = ShapeKind::ALL.iter().map(|k| k.name()).collect();
            MeshError::Invalid(format!("unknown shape '{s}'; expected one of {}", names.join(", ")))
        })
    }
}

/// A generated test: mesh, per-vertex roles and the handle transform.
#[derive(Clone, Debug)]
pub struct TestShape {
    /// The rest shape.
    pub mesh: TriMesh,
    /// `#V` roles (fixed, free, handle).
    pub selection: Vec<VertexStatus>,
    /// The survey's handle transform for this shape.
    pub transform: AffineTransform,
    /// Human-readable provenance, e.g. `procedural bar (6084 vertices requested, 6080 generated)`.
    pub label: String,
}

/// Vertex count of the survey's original mesh of `kind`.
pub fn default_vertex_count(kind: ShapeKind) -> usize {
    match kind {
        ShapeKind::Bar => 6084,
        ShapeKind::Cylinder => 4802,
        ShapeKind::Cactus => 5261,
        ShapeKind::BumpyPlane => 40401,
    }
}

/// Generate the look-alike of `kind` with about `target_vertices` vertices (within 15%).
///
/// Fails with [`MeshError::Invalid`] when `target_vertices` is outside
/// [`MIN_TARGET_VERTICES`]`..=`[`MAX_TARGET_VERTICES`].
pub fn generate(kind: ShapeKind, target_vertices: usize) -> Result<TestShape> {
    if !(MIN_TARGET_VERTICES..=MAX_TARGET_VERTICES).contains(&target_vertices) {
        return Err(MeshError::Invalid(format!(
            "{kind}: target of {target_vertices} vertices is outside the supported range \
             {MIN_TARGET_VERTICES}..={MAX_TARGET_VERTICES}"
        )));
    }
    let (mesh, selection, rows) = match kind {
        ShapeKind::Bar => bar::generate(target_vertices)?,
        ShapeKind::Cylinder => cylinder::generate(target_vertices)?,
        ShapeKind::Cactus => cactus::generate(target_vertices)?,
        ShapeKind::BumpyPlane => bumpy_plane::generate(target_vertices)?,
    };
    let transform = AffineTransform::from_rows(rows)?;
    let label =
        format!("procedural {kind} ({target_vertices} vertices requested, {} generated)", mesh.n_vertices());
    Ok(TestShape { mesh, selection, transform, label })
}

/// What every generator returns: the mesh, its `#V` roles and the survey's transform rows.
type Generated = (TriMesh, Vec<VertexStatus>, [[f64; 4]; 4]);

/// A closed loop of vertices with a circular parameter per vertex, used to stitch consecutive loops of
/// a swept surface whose loops may have different vertex counts.
///
/// `params` increase strictly along the loop and span less than one turn; only differences modulo 1
/// matter, so two loops are matched by where they are around the sweep, not by index.
struct Ring {
    verts: Vec<u32>,
    params: Vec<f64>,
}

impl Ring {
    /// `n` vertices starting at index `first`, evenly spread with the first at parameter `offset / n`.
    fn uniform(first: u32, n: usize, offset: f64) -> Ring {
        let verts = (0..n as u32).map(|i| first + i).collect();
        let params = (0..n).map(|i| (i as f64 + offset) / n as f64).collect();
        Ring { verts, params }
    }
}

/// Positions and triangles under construction.
#[derive(Default)]
struct Builder {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Builder {
    fn with_capacity(n_vertices: usize) -> Builder {
        Builder { positions: Vec::with_capacity(n_vertices), triangles: Vec::with_capacity(2 * n_vertices) }
    }

    /// Index the next pushed vertex will get; fails when the mesh outgrows `u32` indices.
    fn next_index(&self) -> Result<u32> {
        u32::try_from(self.positions.len())
            .map_err(|_| MeshError::Invalid("shape has more vertices than u32 indices allow".into()))
    }

    /// Push a ring of `n` vertices at `position(param)` with evenly spread parameters.
    fn push_ring(&mut self, n: usize, offset: f64, position: impl Fn(f64) -> [f64; 3]) -> Result<Ring> {
        let ring = Ring::uniform(self.next_index()?, n, offset);
        self.positions.extend(ring.params.iter().map(|&t| position(t)));
        Ok(ring)
    }

    /// Triangulate the band between loops `a` and `b`. Faces are oriented like the quads
    /// `(a_i, a_i+1, b_j+1, b_j)`: when both loops run counter-clockwise about the sweep direction and
    /// `b` lies further along it, they point outward.
    ///
    /// Merges the two loops by parameter, always consuming the edge whose midpoint comes first, so
    /// loops of different counts give triangles spanning at most one edge of each loop.
    fn stitch(&mut self, a: &Ring, b: &Ring) {
        let (na, nb) = (a.verts.len(), b.verts.len());
        // A one-vertex loop is a pole: a fan, without the degenerate triangle the merge would add.
        if nb == 1 {
            self.triangles.extend((0..na).map(|i| [a.verts[i], a.verts[(i + 1) % na], b.verts[0]]));
            return;
        }
        if na == 1 {
            self.triangles.extend((0..nb).map(|j| [a.verts[0], b.verts[(j + 1) % nb], b.verts[j]]));
            return;
        }
        let circular = |d: f64| d - d.round();
        let a0 = a.params[0];
        let j0 = (0..nb)
            .min_by(|&x, &y| circular(b.params[x] - a0).abs().total_cmp(&circular(b.params[y] - a0).abs()))
            .unwrap_or(0);
        let shift = circular(b.params[j0] - a0);
        // Parameters unrolled past the loop's end, relative to a's first vertex.
        let pa = |i: usize| a.params[i % na] + (i / na) as f64 - a0;
        let pb = |j: usize| {
            let k = j0 + j;
            b.params[k % nb] + (k / nb) as f64 - b.params[j0] + shift
        };
        let (mut i, mut j) = (0, 0);
        while i < na || j < nb {
            let advance_a = j == nb || (i < na && pa(i) + pa(i + 1) <= pb(j) + pb(j + 1));
            let (ai, bj) = (a.verts[i % na], b.verts[(j0 + j) % nb]);
            if advance_a {
                self.triangles.push([ai, a.verts[(i + 1) % na], bj]);
                i += 1;
            } else {
                self.triangles.push([ai, b.verts[(j0 + j + 1) % nb], bj]);
                j += 1;
            }
        }
    }

    fn into_mesh(self) -> Result<TriMesh> {
        TriMesh::new(self.positions, self.triangles)
    }
}

/// Arclength table of a planar curve sampled densely, to place loops at even spacing along it.
struct ArcTable {
    points: Vec<[f64; 2]>,
    cumulative: Vec<f64>,
}

impl ArcTable {
    /// The polyline through `points` (at least one).
    fn new(points: Vec<[f64; 2]>) -> ArcTable {
        let mut cumulative = Vec::with_capacity(points.len());
        let mut total = 0.0;
        cumulative.push(0.0);
        for w in points.windows(2) {
            total += (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
            cumulative.push(total);
        }
        ArcTable { points, cumulative }
    }

    fn length(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// The point at arclength `s` (clamped to the curve).
    fn at(&self, s: f64) -> [f64; 2] {
        if self.points.len() < 2 {
            return self.points.first().copied().unwrap_or([0.0; 2]);
        }
        let k = self.cumulative.partition_point(|&c| c < s).clamp(1, self.points.len() - 1);
        let (c0, c1) = (self.cumulative[k - 1], self.cumulative[k]);
        let w = if c1 > c0 { ((s - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.0 };
        let (p, q) = (self.points[k - 1], self.points[k]);
        [p[0] + w * (q[0] - p[0]), p[1] + w * (q[1] - p[1])]
    }
}

/// Roles from two predicates on the position; a vertex matching both counts as fixed.
fn select(
    positions: &[[f64; 3]],
    fixed: impl Fn(&[f64; 3]) -> bool,
    handle: impl Fn(&[f64; 3]) -> bool,
) -> Vec<VertexStatus> {
    positions
        .iter()
        .map(|p| {
            if fixed(p) {
                VertexStatus::Fixed
            } else if handle(p) {
                VertexStatus::Handle
            } else {
                VertexStatus::Free
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::Topology;

    #[test]
    fn names_round_trip() {
        for kind in ShapeKind::ALL {
            assert_eq!(kind.to_string().parse::<ShapeKind>().ok(), Some(kind));
        }
        assert_eq!("PLANE".parse::<ShapeKind>().ok(), Some(ShapeKind::BumpyPlane));
        assert!("sphere".parse::<ShapeKind>().is_err());
    }

    #[test]
    fn targets_out_of_range_are_errors() {
        for kind in ShapeKind::ALL {
            assert!(generate(kind, MIN_TARGET_VERTICES - 1).is_err());
            assert!(generate(kind, 0).is_err());
            assert!(generate(kind, MAX_TARGET_VERTICES + 1).is_err());
        }
    }

    /// Stitching loops of very different counts, and poles, gives a closed, consistently oriented
    /// surface: a "sphere" of stacked rings.
    #[test]
    fn stitched_rings_close_up() {
        let counts = [1, 3, 7, 20, 9, 4, 1];
        let mut b = Builder::default();
        let mut rings = Vec::new();
        for (level, &n) in counts.iter().enumerate() {
            let z = level as f64 - 3.0;
            let r = (9.0 - z * z).max(0.0).sqrt();
            let ring = b
                .push_ring(n, 0.37 * level as f64, |t| {
                    let a = std::f64::consts::TAU * t;
                    [r * a.cos(), r * a.sin(), z]
                })
                .expect("small mesh");
            rings.push(ring);
        }
        for w in rings.windows(2) {
            b.stitch(&w[0], &w[1]);
        }
        let n_vertices: usize = counts.iter().sum();
        assert_eq!(b.triangles.len(), 2 * n_vertices - 4, "Euler characteristic 2");
        let mesh = b.into_mesh().expect("valid mesh");
        let topology = Topology::new(&mesh).expect("manifold and oriented");
        assert!(topology.is_closed());
        mesh.check_nondegenerate().expect("no zero-area faces");
    }

    #[test]
    fn arc_table_is_evenly_parameterized() {
        let table = ArcTable::new((0..=1000).map(|i| [0.003 * i as f64, 0.004 * i as f64]).collect());
        assert!((table.length() - 5.0).abs() < 1e-12);
        let p = table.at(2.5);
        assert!((p[0] - 1.5).abs() < 1e-12 && (p[1] - 2.0).abs() < 1e-12);
        assert_eq!(table.at(-1.0), [0.0, 0.0]);
        let end = table.at(9.0);
        assert!((end[0] - 3.0).abs() < 1e-12 && (end[1] - 4.0).abs() < 1e-12);
    }
}
