//! The tufted intrinsic Delaunay Laplacian (Sharp & Crane 2020, "A Laplacian for Nonmanifold
//! Triangle Meshes", SGP; SC20), the cotangent Laplacian `robust-laplacian` and geometry-central's
//! `buildTuftedLaplacian` compute.
//!
//! The plain intrinsic Delaunay Laplacian ([`super::intrinsic_delaunay`]) flips interior edges only:
//! a boundary edge has one cotangent, negative when its opposite angle is obtuse, and no flip reaches
//! it (15 of 36 boundary edges of the lion bust); a non-manifold edge (three or more faces) has no
//! quadrilateral to flip in. SC20 (the section on the tufted cover) removes both limits:
//! - every face `f` becomes two faces of the cover, a front copy with the mesh's orientation and a
//!   back copy with the opposite one, on the same vertices;
//! - around each mesh edge `ij` the `k` faces that contain it are ordered by their angle about the
//!   edge, and each of the `k` wedges of space between two consecutive faces glues the two sheets
//!   that bound it (SC20: the faces are sorted around the edge and each glued to the next). A
//!   boundary edge (`k = 1`) glues a face's front to its own back; a manifold interior edge (`k = 2`)
//!   glues front to front and back to back; a non-manifold edge (`k >= 3`) is glued cyclically.
//!
//! The cover is a closed, oriented, edge-manifold triangulation (its vertices may be non-manifold,
//! which the halfedge arrays of [`IntrinsicTriangulation`] do not mind), with the mesh's metric; its
//! intrinsic Delaunay triangulation ([`IntrinsicTriangulation::flip_to_delaunay`]: every edge is now
//! interior, so every edge can be flipped) has only non-negative cotangent weights. The Laplacian is
//! the cover's cotangent Laplacian on the mesh's vertices, halved (`L = 1/2 L_cover`, as SC20 and
//! geometry-central's `buildTuftedLaplacian`): a closed manifold mesh's cover is two copies of the mesh, so on a closed
//! intrinsic Delaunay mesh this is [`super::cotan_laplacian`] exactly, and on any closed manifold
//! mesh it is the plain intrinsic Delaunay Laplacian. The lumped mass is the cover's, halved (it sums
//! to the mesh's area).
//!
//! The angular order needs the positions: for a face `(i, j, c)` its angle about `e = p_j - p_i` is
//! that of `p_c - p_i` in a plane orthogonal to `e`. The sheet facing increasing angle is the one
//! whose halfedge runs `i -> j` (the front copy if the face has `i -> j`, else the back copy): its
//! normal is `e x (p_c - p_i)`. The wedge between consecutive faces `f_m`, `f_{m+1}` thus glues
//! `f_m`'s `i -> j` halfedge to `f_{m+1}`'s `j -> i` halfedge. For `k <= 2` the order is irrelevant;
//! for `k >= 3` ties (coplanar faces on one side) are broken by face index (geometry-central also
//! sorts by this angle; the cross-check covers manifold meshes only).
//!
//! Intrinsic mollification (SC20's section of that name): lengths are replaced by `l + eps`, with the least
//! `eps >= 0` such that every triangle has `l_a + l_b - l_c >= delta`, `delta = factor x` the mean
//! edge length. **Decision**: we use it with robust-laplacian's default factor
//! [`MOLLIFY_FACTOR`] = 1e-5. On a mesh whose triangles all pass that margin (every survey and
//! procedural mesh) `eps = 0` and the lengths are untouched bit for bit, so the matrix is
//! robust-laplacian's with `mollify_factor = 0` to rounding; on a mesh with a (near-)zero-area
//! triangle it changes every length by at most `1e-5` of the mean edge length instead of refusing
//! the mesh ([`IntrinsicDelaunayError::DegenerateFace`]) or putting `inf` into the weights.
//! [`TuftedDelaunay::mollification`] reports `eps`.
//!
//! Rounding: the flip test leaves an edge with `cot a + cot b >= -1e-14` (a cocircular quad, where
//! both diagonals give the same Laplacian), so a halved weight can be `-1e-15`-ish rounding; those
//! entries are set to 0 and the diagonal rebuilt, so the returned `L` has no negative off-diagonal
//! entry at all. robust-laplacian flips only below `-1e-6` (geometry-central's `delaunayEPS`), so
//! it can keep weights in `[-5e-7, 0)` that we flip; where that happens the two differ in those
//! entries (none on the cross-checked meshes).

use faer::sparse::{SparseColMat, Triplet};
use meshes::vector::{cross, dot, norm, sub};

use super::intrinsic_delaunay::{edge_groups, halfedge_lengths, FLIP_TOLERANCE};
use super::{IntrinsicDelaunayError, IntrinsicTriangulation, MassKind};

/// SC20's relative mollification `delta / mean edge length`, robust-laplacian's default
/// `mollify_factor` (see the module documentation for the decision).
pub const MOLLIFY_FACTOR: f64 = 1e-5;

/// The tufted cover of a mesh flipped to intrinsic Delaunay, and the mesh's Laplacian and mass from it.
#[derive(Clone, Debug)]
pub struct TuftedDelaunay {
    cover: IntrinsicTriangulation,
    mollification: f64,
    non_manifold_edges: usize,
    /// Whether [`Self::cotan_laplacian`] sets the flip tolerance's rounding residue to 0 (only at
    /// the default tolerance; a looser one keeps its negative weights, as robust-laplacian does).
    clamp_residue: bool,
}

impl TuftedDelaunay {
    /// The tufted intrinsic Delaunay triangulation of `positions` (`#V x 3`) / `triangles`
    /// (`#F x 3`, any orientation, manifold or not, with boundary or not), mollified with
    /// `mollify_factor` (0: not at all; [`MOLLIFY_FACTOR`] by default). Fails on a face that repeats
    /// a vertex or refers to a missing one, on a face still degenerate after mollification (only
    /// with `mollify_factor = 0`), and if flipping does not end
    /// ([`IntrinsicDelaunayError::TooManyFlips`]).
    pub fn new(
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        mollify_factor: f64,
    ) -> Result<Self, IntrinsicDelaunayError> {
        Self::with_flip_tolerance(positions, triangles, mollify_factor, FLIP_TOLERANCE)
    }

    /// [`Self::new`] flipping only edges with `cot a + cot b < -flip_tolerance` (default 1e-14).
    /// For the cross-check: robust-laplacian (geometry-central's `flipToDelaunay`, `delaunayEPS =
    /// 1e-6` on the half-sum) is `flip_tolerance = 2e-6`, which leaves weights down to `-1e-6`.
    pub fn with_flip_tolerance(
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        mollify_factor: f64,
        flip_tolerance: f64,
    ) -> Result<Self, IntrinsicDelaunayError> {
        let n_faces = triangles.len();
        let mut mesh_length = halfedge_lengths(positions, triangles)?;
        let groups = edge_groups(triangles);
        for g in groups.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            if g[0].0 == g[0].1 {
                return Err(IntrinsicDelaunayError::DegenerateFace { face: g[0].2 / 3 });
            }
        }

        // Mollification over the mesh's triangles, delta relative to the mean over unique edges.
        let mut mollification = 0.0;
        if mollify_factor > 0.0 {
            let (mut sum, mut count) = (0.0, 0usize);
            for g in groups.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
                sum += mesh_length[g[0].2];
                count += 1;
            }
            let delta = mollify_factor * sum / count.max(1) as f64;
            for f in 0..n_faces {
                let l = [mesh_length[3 * f], mesh_length[3 * f + 1], mesh_length[3 * f + 2]];
                for k in 0..3 {
                    let eps = l[k] - l[(k + 1) % 3] - l[(k + 2) % 3] + delta;
                    mollification = f64::max(mollification, eps);
                }
            }
            if mollification > 0.0 {
                mesh_length.iter_mut().for_each(|l| *l += mollification);
            }
        }

        // Cover faces: front `f` = the mesh's, back `#F + f` = `(t0, t2, t1)`. The back copy of
        // front halfedge `3 f + k` (t_k -> t_{k+1}) is `3 (#F + f) + (2 - k)` (t_{k+1} -> t_k).
        let back = |h: usize| 3 * (n_faces + h / 3) + (2 - h % 3);
        let mut cover_triangles = triangles.to_vec();
        cover_triangles.extend(triangles.iter().map(|t| [t[0], t[2], t[1]]));
        let mut length = vec![0.0; 6 * n_faces];
        for h in 0..3 * n_faces {
            length[h] = mesh_length[h];
            length[back(h)] = mesh_length[h];
        }

        let mut twin = vec![usize::MAX; 6 * n_faces];
        let mut non_manifold_edges = 0;
        let mut around: Vec<(f64, usize, usize, usize)> = Vec::new();
        for g in groups.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let (i, j) = (g[0].0, g[0].1);
            // Per face: (angle about i -> j, face, its cover halfedge i -> j, its cover halfedge j -> i).
            around.clear();
            let (pi, e) = (positions[i as usize], sub(positions[j as usize], positions[i as usize]));
            let (u0, u1) = if g.len() > 2 { orthonormal_complement(e) } else { ([0.0; 3], [0.0; 3]) };
            for &(_, _, h) in g {
                let t = triangles[h / 3];
                let c = t[(h % 3 + 2) % 3];
                let v = sub(positions[c as usize], pi);
                let angle = if g.len() > 2 { dot(v, u1).atan2(dot(v, u0)) } else { 0.0 };
                let (up, down) = if t[h % 3] == i { (h, back(h)) } else { (back(h), h) };
                around.push((angle, h / 3, up, down));
            }
            if g.len() > 2 {
                non_manifold_edges += 1;
                around.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            }
            for m in 0..around.len() {
                let (up, down) = (around[m].2, around[(m + 1) % around.len()].3);
                twin[up] = down;
                twin[down] = up;
            }
        }

        let mut cover =
            IntrinsicTriangulation::from_halfedges(positions.len(), cover_triangles, twin, length)?;
        cover.flip_to_delaunay_with(flip_tolerance)?;
        Ok(Self { cover, mollification, non_manifold_edges, clamp_residue: flip_tolerance <= FLIP_TOLERANCE })
    }

    /// The cover flipped to intrinsic Delaunay: `2 #F` faces (front copies first), every edge
    /// interior; its edges' weights are twice the mesh Laplacian's share.
    pub fn cover(&self) -> &IntrinsicTriangulation {
        &self.cover
    }

    /// The `eps` added to every edge length by mollification (0 if none was needed).
    pub fn mollification(&self) -> f64 {
        self.mollification
    }

    /// Number of mesh edges with three or more faces.
    pub fn non_manifold_edges(&self) -> usize {
        self.non_manifold_edges
    }

    /// `#V x #V` tufted Laplacian `1/2 L_cover` with [`super::cotan_laplacian`]'s sign
    /// and layout (`L_ij >= 0` off the diagonal, exactly; `L_ii = -sum_j L_ij`; CSC, sorted rows).
    pub fn cotan_laplacian(&self) -> SparseColMat<usize, f64> {
        let cover = self.cover.cotan_laplacian();
        let n = cover.ncols();
        let (symbolic, values) = cover.parts();
        let mut entries = Vec::with_capacity(values.len());
        let mut diagonal = vec![0.0; n];
        for j in 0..n {
            for idx in symbolic.col_range(j) {
                let i = symbolic.row_idx()[idx];
                // The strict upper triangle, mirrored: the cover sums 4+ face terms per entry, in an
                // order that differs between (i, j) and (j, i) by an ulp; mirroring keeps L exactly
                // symmetric. Negative values are flip-tolerance rounding (module documentation).
                if i < j {
                    let w = 0.5 * if self.clamp_residue { values[idx].max(0.0) } else { values[idx] };
                    entries.push(Triplet::new(i, j, w));
                    entries.push(Triplet::new(j, i, w));
                    diagonal[i] -= w;
                    diagonal[j] -= w;
                }
            }
        }
        entries.extend(diagonal.iter().enumerate().map(|(i, &d)| Triplet::new(i, i, d)));
        SparseColMat::try_new_from_triplets(n, n, &entries).expect("indices come from a valid matrix")
    }

    /// `#V` lumped mass diagonal: the cover's ([`IntrinsicTriangulation::lumped_mass`]) halved; sums to
    /// the (mollified) mesh's area.
    pub fn lumped_mass(&self, kind: MassKind) -> Vec<f64> {
        let mut mass = self.cover.lumped_mass(kind);
        mass.iter_mut().for_each(|m| *m *= 0.5);
        mass
    }
}

/// Two unit vectors orthogonal to `e` and to each other, `(u0, u1 = e/|e| x u0)`: the plane the
/// angles about `e` are measured in (any `e != 0`).
fn orthonormal_complement(e: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let n = norm(e);
    let e = [e[0] / n, e[1] / n, e[2] / n];
    // The axis least aligned with e.
    let k = (0..3).min_by(|&a, &b| e[a].abs().total_cmp(&e[b].abs())).unwrap_or(0);
    let mut axis = [0.0; 3];
    axis[k] = 1.0;
    let u0 = cross(e, axis);
    let m = norm(u0);
    let u0 = [u0[0] / m, u0[1] / m, u0[2] / m];
    (u0, cross(e, u0))
}
