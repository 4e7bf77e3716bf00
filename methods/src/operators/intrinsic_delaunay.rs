//! The intrinsic Delaunay triangulation and its cotangent Laplacian (Bobenko & Springborn 2007;
//! Fisher et al. 2007; Sharp, Soliman & Crane 2019 "Navigating intrinsic triangulations"; libigl's
//! `intrinsic_delaunay_cotmatrix`).
//!
//! The mesh's vertices and its metric (the edge lengths of the polyhedral surface) stay as they are;
//! only the connectivity changes. Any interior edge whose cotangent weight `(cot a + cot b) / 2` is
//! negative (opposite angles summing to more than `pi`) is flipped to the other diagonal of the
//! quadrilateral its two triangles form, laid out flat in the plane; its length there is the length
//! of a geodesic on the surface. Flipping until no such edge remains gives the intrinsic Delaunay
//! triangulation, whose cotangent weights are all non-negative, so its Laplacian obeys the discrete
//! maximum principle and `-L` is a positive semi-definite M-matrix-like operator with no negative
//! couplings. Boundary edges are never flipped.
//!
//! After flips an intrinsic triangulation can have several edges between the same two vertices, or an
//! edge from a vertex to itself, so connectivity is kept in halfedge arrays (`3 f + k` is the
//! halfedge of face `f` from corner `k` to corner `k + 1`, `twin` its opposite) rather than keyed by
//! vertex pairs; the Laplacian sums the weights of parallel edges, and a self-edge contributes
//! nothing (`u_i - u_i = 0`).
//!
//! Termination and determinism: a FIFO queue initially holds the interior edges in order of their
//! first appearance in the face list; each flip of an edge with a negative weight strictly decreases
//! the Dirichlet energy of the piecewise-linear interpolant of a fixed function (Rippa 1990; BS07),
//! so no triangulation repeats. To keep rounding from flipping cocircular quads back and forth, an edge
//! is flipped only if `cot a + cot b < -FLIP_TOLERANCE` (1e-14). The number of flips is capped at
//! `100 x #E` ([`IntrinsicDelaunayError::TooManyFlips`]).

use std::collections::VecDeque;

use faer::sparse::SparseColMat;
use meshes::vector::{norm, sub};

use super::{MassKind, DEGENERATE_FACE_RATIO};

/// An edge is flipped when `cot a + cot b` is below minus this (cotangents are dimensionless).
/// Exactly cocircular quads (the right triangles of grid-like meshes) have `|cot a + cot b| ~ 1e-16`
/// from rounding and are left alone (flipping them changes nothing: the Laplacian of a Delaunay
/// triangulation does not depend on how cocircular quads are split). Measured against libigl on the
/// survey plane: 1e-12 leaves nearly cocircular quads unflipped that libigl flips (3e-10 relative
/// difference on small entries), 1e-14 agrees to 2e-12, 0 flips the cylinder's rounding noise
/// (1158 flips instead of 0).
pub(super) const FLIP_TOLERANCE: f64 = 1e-14;

/// Flip budget per edge (see the module documentation).
const FLIPS_PER_EDGE: usize = 100;

const NONE: usize = usize::MAX;

/// Why no intrinsic Delaunay triangulation was built.
#[derive(Debug, thiserror::Error)]
pub enum IntrinsicDelaunayError {
    #[error("face {face} is degenerate (doubled area below {DEGENERATE_FACE_RATIO:e} x its longest squared edge): it has no intrinsic metric")]
    DegenerateFace { face: usize },
    #[error("face {face} refers to vertex {vertex}, but the mesh has {n_vertices} vertices")]
    VertexOutOfRange { face: usize, vertex: u32, n_vertices: usize },
    #[error("edge ({a}, {b}) is shared by more than two faces, or by two faces with the same orientation")]
    NonManifoldEdge { a: u32, b: u32 },
    #[error("no intrinsic Delaunay triangulation after {flips} edge flips (limit {FLIPS_PER_EDGE} x #E)")]
    TooManyFlips { flips: usize },
}

/// An intrinsic triangulation of a mesh's vertices: `#F` faces (same count as the mesh, Euler's
/// formula is kept by flips) with per-corner vertex indices and per-edge intrinsic lengths.
#[derive(Clone, Debug)]
pub struct IntrinsicTriangulation {
    n_vertices: usize,
    /// `#F x 3` vertex indices; a face may repeat a vertex (self-edges).
    triangles: Vec<[u32; 3]>,
    /// `3 #F`: twin of each halfedge, `NONE` on the boundary.
    twin: Vec<usize>,
    /// `3 #F`: intrinsic length of each halfedge's edge (equal on twins).
    length: Vec<f64>,
    flips: usize,
}

/// One edge of an intrinsic triangulation and its cotangent weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntrinsicEdge {
    /// Endpoints, `a <= b` (equal for a self-edge).
    pub a: u32,
    pub b: u32,
    /// Intrinsic length.
    pub length: f64,
    /// `(cot a + cot b) / 2` (one term on the boundary); `>= -0.5e-14` for interior edges
    /// after [`IntrinsicTriangulation::delaunay`].
    pub weight: f64,
}

impl IntrinsicTriangulation {
    /// The mesh itself as an intrinsic triangulation (`positions`: `#V x 3`, `triangles`: `#F x 3`,
    /// consistently oriented, manifold), edge lengths from the positions, no flips.
    pub fn from_mesh(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, IntrinsicDelaunayError> {
        let length = halfedge_lengths(positions, triangles)?;
        // Twins by sorting halfedges on their unordered vertex pair (deterministic, no hashing).
        let mut twin = vec![NONE; 3 * triangles.len()];
        for group in edge_groups(triangles).chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let (a, b) = (group[0].0, group[0].1);
            match group {
                [_] => {}
                [(_, _, h0), (_, _, h1)] => {
                    let tail = |h: usize| triangles[h / 3][h % 3];
                    if tail(*h0) == tail(*h1) || a == b {
                        return Err(IntrinsicDelaunayError::NonManifoldEdge { a, b });
                    }
                    twin[*h0] = *h1;
                    twin[*h1] = *h0;
                }
                _ => return Err(IntrinsicDelaunayError::NonManifoldEdge { a, b }),
            }
        }
        Self::from_halfedges(positions.len(), triangles.to_vec(), twin, length)
    }

    /// An intrinsic triangulation given by its halfedge arrays (`3 f + k` the halfedge of face `f`
    /// from corner `k` to `k + 1`): `#F x 3` `triangles`, `3 #F` `twin` (`usize::MAX` on the
    /// boundary; twins run in opposite directions) and `3 #F` `length` (equal on twins). Fails on a
    /// face below [`DEGENERATE_FACE_RATIO`].
    pub(super) fn from_halfedges(
        n_vertices: usize,
        triangles: Vec<[u32; 3]>,
        twin: Vec<usize>,
        length: Vec<f64>,
    ) -> Result<Self, IntrinsicDelaunayError> {
        for face in 0..triangles.len() {
            let l = [length[3 * face], length[3 * face + 1], length[3 * face + 2]];
            // Halfedge k runs from corner k to corner k + 1, so it is opposite corner k + 2.
            let opposite = [l[1], l[2], l[0]];
            if !(2.0 * triangle_area(opposite)
                > DEGENERATE_FACE_RATIO * l.iter().fold(0.0f64, |m, &x| m.max(x * x)))
            {
                return Err(IntrinsicDelaunayError::DegenerateFace { face });
            }
        }
        Ok(Self { n_vertices, triangles, twin, length, flips: 0 })
    }

    /// The intrinsic Delaunay triangulation of the mesh (`#V x 3` positions, `#F x 3` triangles):
    /// [`Self::from_mesh`], then flips until every interior edge has `cot a + cot b >= -1e-14`.
    pub fn delaunay(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, IntrinsicDelaunayError> {
        let mut t = Self::from_mesh(positions, triangles)?;
        t.flip_to_delaunay()?;
        Ok(t)
    }

    /// `#F x 3` vertex indices of the intrinsic faces (orientation of the mesh kept).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// `#F x 3` intrinsic edge lengths, entry `k` the edge opposite corner `k` (libigl's
    /// `l_intrinsic` convention).
    pub fn edge_lengths(&self) -> Vec<[f64; 3]> {
        (0..self.triangles.len()).map(|f| self.opposite_lengths(f)).collect()
    }

    /// Number of flips [`Self::delaunay`] made.
    pub fn flips(&self) -> usize {
        self.flips
    }

    /// `#F` intrinsic triangle areas (Heron); they sum to the mesh's surface area.
    pub fn face_areas(&self) -> Vec<f64> {
        (0..self.triangles.len()).map(|f| triangle_area(self.opposite_lengths(f))).collect()
    }

    /// `#F x 3` cotangent half-weights, entry `k` of face `f` `cot(corner k) / 2` (as
    /// [`super::cotangent_weights`], on intrinsic lengths).
    pub fn cotangent_weights(&self) -> Vec<[f64; 3]> {
        (0..self.triangles.len()).map(|f| half_cotangents(self.opposite_lengths(f))).collect()
    }

    /// Every edge once (interior edges from their first halfedge in face order), with its weight.
    pub fn edges(&self) -> Vec<IntrinsicEdge> {
        let half = self.cotangent_weights();
        (0..self.twin.len())
            .filter(|&h| self.twin[h] == NONE || h < self.twin[h])
            .map(|h| {
                let (a, b) = (self.tail(h), self.head(h));
                let mut weight = half[h / 3][(h % 3 + 2) % 3];
                if self.twin[h] != NONE {
                    let t = self.twin[h];
                    weight += half[t / 3][(t % 3 + 2) % 3];
                }
                IntrinsicEdge { a: a.min(b), b: a.max(b), length: self.length[h], weight }
            })
            .collect()
    }

    /// `#V x #V` cotangent Laplacian of the intrinsic triangulation, with the sign and layout of
    /// [`super::cotan_laplacian`]: `L_ij` = sum of the weights of the edges between `i` and `j`
    /// (parallel edges summed), `L_ii = -sum_j L_ij`, CSC with sorted rows.
    pub fn cotan_laplacian(&self) -> SparseColMat<usize, f64> {
        super::cotan::laplacian_from_corner_weights(
            self.n_vertices,
            &self.triangles,
            &self.cotangent_weights(),
        )
    }

    /// `#V` diagonal of the lumped mass matrix on the intrinsic triangles (as [`super::lumped_mass`]:
    /// barycentric thirds, or Voronoi areas with the obtuse-triangle rule; after Delaunay flips
    /// obtuse triangles remain only next to the boundary). Sums to the surface area.
    pub fn lumped_mass(&self, kind: MassKind) -> Vec<f64> {
        let mut mass = vec![0.0; self.n_vertices];
        for (f, t) in self.triangles.iter().enumerate() {
            let l = self.opposite_lengths(f);
            let area = triangle_area(l);
            let corners = match kind {
                MassKind::Barycentric => [area / 3.0; 3],
                MassKind::Voronoi => voronoi_corner_areas(l, area),
            };
            for k in 0..3 {
                mass[t[k] as usize] += corners[k];
            }
        }
        mass
    }

    fn tail(&self, h: usize) -> u32 {
        self.triangles[h / 3][h % 3]
    }

    fn head(&self, h: usize) -> u32 {
        self.triangles[h / 3][(h % 3 + 1) % 3]
    }

    /// Lengths of face `f` opposite corners 0, 1, 2.
    fn opposite_lengths(&self, f: usize) -> [f64; 3] {
        [self.length[3 * f + 1], self.length[3 * f + 2], self.length[3 * f]]
    }

    /// `cot` of the corner opposite halfedge `h` in its face.
    fn opposite_cot(&self, h: usize) -> f64 {
        let f = h / 3;
        2.0 * half_cotangents(self.opposite_lengths(f))[(h % 3 + 2) % 3]
    }

    fn flip_to_delaunay(&mut self) -> Result<(), IntrinsicDelaunayError> {
        self.flip_to_delaunay_with(FLIP_TOLERANCE)
    }

    /// Flip every interior edge with `cot a + cot b < -tolerance` (see the module documentation).
    pub(super) fn flip_to_delaunay_with(&mut self, tolerance: f64) -> Result<(), IntrinsicDelaunayError> {
        let n_halfedges = self.twin.len();
        // Edge ids: one per twin pair / boundary halfedge. A flip keeps the flipped edge's id, and the
        // other four edges keep theirs while their halfedges change slots.
        let mut edge_of = vec![NONE; n_halfedges];
        let mut n_edges = 0;
        let mut queue = VecDeque::new();
        for h in 0..n_halfedges {
            if edge_of[h] == NONE {
                edge_of[h] = n_edges;
                if self.twin[h] != NONE {
                    edge_of[self.twin[h]] = n_edges;
                }
                n_edges += 1;
            }
        }
        let mut halfedge_of = vec![NONE; n_edges];
        for h in (0..n_halfedges).rev() {
            halfedge_of[edge_of[h]] = h;
        }
        let mut queued = vec![false; n_edges];
        for (e, &h) in halfedge_of.iter().enumerate() {
            if self.twin[h] != NONE {
                queue.push_back(e);
                queued[e] = true;
            }
        }
        let limit = FLIPS_PER_EDGE * n_edges;
        while let Some(e) = queue.pop_front() {
            queued[e] = false;
            let h = halfedge_of[e];
            let t = self.twin[h];
            if self.opposite_cot(h) + self.opposite_cot(t) >= -tolerance {
                continue;
            }
            if self.flips >= limit {
                return Err(IntrinsicDelaunayError::TooManyFlips { flips: self.flips });
            }
            let moved = self.flip(h, &mut edge_of, &mut halfedge_of);
            self.flips += 1;
            for m in moved {
                let e = edge_of[m];
                if self.twin[m] != NONE && !queued[e] {
                    queued[e] = true;
                    queue.push_back(e);
                }
            }
        }
        Ok(())
    }

    /// Flip the interior edge of halfedge `h` (`a -> b`, faces `(a, b, c)` and `(b, a, d)`) to `c - d`;
    /// the faces become `(c, d, b)` and `(d, c, a)`. Returns the new halfedges of the quad's four
    /// sides, whose edges may have become non-Delaunay.
    fn flip(&mut self, h: usize, edge_of: &mut [usize], halfedge_of: &mut [usize]) -> [usize; 4] {
        let t = self.twin[h];
        let (f0, f1) = (h / 3, t / 3);
        let next = |x: usize| 3 * (x / 3) + (x % 3 + 1) % 3;
        let (h1, t1) = (next(h), next(t));
        let (h2, t2) = (next(h1), next(t1));
        let (a, b, c, d) = (self.tail(h), self.head(h), self.tail(h2), self.tail(t2));
        let (l_ab, l_bc, l_ca, l_ad, l_db) =
            (self.length[h], self.length[h1], self.length[h2], self.length[t1], self.length[t2]);
        let l_cd = flipped_length(l_ab, l_bc, l_ca, l_ad, l_db);

        // Old side halfedge -> its slot after the flip: b->c and d->b end in f0, c->a and a->d in f1.
        let (n_b_c, n_d_b, n_c_a, n_a_d) = (3 * f0 + 2, 3 * f0 + 1, 3 * f1 + 1, 3 * f1 + 2);
        let sides = [(h1, n_b_c, l_bc), (t2, n_d_b, l_db), (h2, n_c_a, l_ca), (t1, n_a_d, l_ad)];
        let slot = |x: usize| sides.iter().find(|s| s.0 == x).map_or(x, |s| s.1);
        let outer: Vec<(usize, usize, usize, f64)> =
            sides.iter().map(|&(old, new, l)| (new, self.twin[old], edge_of[old], l)).collect();
        let flipped_edge = edge_of[h];

        self.triangles[f0] = [c, d, b];
        self.triangles[f1] = [d, c, a];
        let (n_c_d, n_d_c) = (3 * f0, 3 * f1);
        self.twin[n_c_d] = n_d_c;
        self.twin[n_d_c] = n_c_d;
        self.length[n_c_d] = l_cd;
        self.length[n_d_c] = l_cd;
        edge_of[n_c_d] = flipped_edge;
        edge_of[n_d_c] = flipped_edge;
        halfedge_of[flipped_edge] = n_c_d;
        for &(new, old_twin, edge, l) in &outer {
            self.length[new] = l;
            edge_of[new] = edge;
            halfedge_of[edge] = new;
            if old_twin == NONE {
                self.twin[new] = NONE;
            } else {
                // The twin may itself be a side of the quad (a vertex of degree 2 or less).
                let tw = slot(old_twin);
                self.twin[new] = tw;
                self.twin[tw] = new;
            }
        }
        [n_b_c, n_d_b, n_c_a, n_a_d]
    }
}

/// `3 #F` halfedge lengths (`3 f + k`: corner `k` to `k + 1`) of `triangles` (`#F x 3`) on
/// `positions` (`#V x 3`); fails on an out-of-range vertex.
pub(super) fn halfedge_lengths(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> Result<Vec<f64>, IntrinsicDelaunayError> {
    let n_vertices = positions.len();
    let mut length = Vec::with_capacity(3 * triangles.len());
    for (face, t) in triangles.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&v| v as usize >= n_vertices) {
            return Err(IntrinsicDelaunayError::VertexOutOfRange { face, vertex, n_vertices });
        }
        length
            .extend((0..3).map(|k| norm(sub(positions[t[(k + 1) % 3] as usize], positions[t[k] as usize]))));
    }
    Ok(length)
}

/// `3 #F` entries `(min, max, halfedge)`, one per halfedge of `triangles` keyed by its unordered
/// vertex pair, sorted: the halfedges of one mesh edge are consecutive (deterministic, no hashing).
pub(super) fn edge_groups(triangles: &[[u32; 3]]) -> Vec<(u32, u32, usize)> {
    let mut keys: Vec<(u32, u32, usize)> = (0..3 * triangles.len())
        .map(|h| {
            let (a, b) = (triangles[h / 3][h % 3], triangles[h / 3][(h % 3 + 1) % 3]);
            (a.min(b), a.max(b), h)
        })
        .collect();
    keys.sort_unstable();
    keys
}

/// Length of the diagonal `c - d` of the quad made by triangles `(a, b, c)` and `(b, a, d)` laid out
/// flat on either side of `a - b` (SSC19 section 3.2: a 2D layout by the law of cosines).
fn flipped_length(l_ab: f64, l_bc: f64, l_ca: f64, l_ad: f64, l_db: f64) -> f64 {
    // a at the origin, b on the positive x axis, c above, d below.
    let cx = (l_ab * l_ab + l_ca * l_ca - l_bc * l_bc) / (2.0 * l_ab);
    let cy = (l_ca * l_ca - cx * cx).max(0.0).sqrt();
    let dx = (l_ab * l_ab + l_ad * l_ad - l_db * l_db) / (2.0 * l_ab);
    let dy = -(l_ad * l_ad - dx * dx).max(0.0).sqrt();
    ((cx - dx).powi(2) + (cy - dy).powi(2)).sqrt()
}

/// Area of the triangle with side lengths `l` (Heron, in the form of Kahan 2014 that is accurate for
/// needle-like triangles); 0 if the lengths violate the triangle inequality.
pub(super) fn triangle_area(l: [f64; 3]) -> f64 {
    let mut s = l;
    s.sort_by(|x, y| y.total_cmp(x)); // a >= b >= c
    let [a, b, c] = s;
    let p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    0.25 * p.max(0.0).sqrt()
}

/// `cot(corner k) / 2` of the triangle with side `l[k]` opposite corner `k`:
/// `cot = (l_{k+1}^2 + l_{k+2}^2 - l_k^2) / (4 A)`. Zero for a zero-area triangle.
fn half_cotangents(l: [f64; 3]) -> [f64; 3] {
    let area = triangle_area(l);
    if !(area > 0.0) {
        return [0.0; 3];
    }
    let l2 = l.map(|x| x * x);
    std::array::from_fn(|k| (l2[(k + 1) % 3] + l2[(k + 2) % 3] - l2[k]) / (8.0 * area))
}

/// Voronoi corner areas (Meyer et al. 2003) of the triangle with side `l[k]` opposite corner `k`,
/// with the obtuse rule of [`super::mass`]: half the area to an obtuse corner, a quarter to the others.
fn voronoi_corner_areas(l: [f64; 3], area: f64) -> [f64; 3] {
    let l2 = l.map(|x| x * x);
    for k in 0..3 {
        if l2[k] > l2[(k + 1) % 3] + l2[(k + 2) % 3] {
            let mut c = [0.25 * area; 3];
            c[k] = 0.5 * area;
            return c;
        }
    }
    let half_cot = half_cotangents(l);
    std::array::from_fn(|k| {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        (l2[a] * half_cot[a] + l2[b] * half_cot[b]) / 4.0
    })
}
