//! Section 4.2, step one: updating the face normals on the Gauss map so that they meet the edge
//! angles (eq 4), by local/global as-rigid-as-possible iterations on the pyramids `P_v` (eq 7-11).
//!
//! The pyramid of vertex `v` has one spoke `O N_f` per face `f` around `v`. Local phase (eq 7-8):
//! `R_v` is the rotation closest to `S_v = sum_f w_vf N'_f N_f^T` (current times rest spoke).
//! Global phase (eq 9-11): every normal becomes the weighted mean of its three rotated rest
//! normals, `N'_f = sum_{v in f} w_vf R_v N_f / sum_{v in f} w_vf`, normalized to the sphere.
//!
//! Decisions the paper leaves open:
//! - Weights ([`SpokeWeights`], `normal_weights`). The paper asks for "cotangent weights" (eq 7)
//!   on spokes that are face normals, which have no edge of their own, and eq 11 prints equal
//!   thirds. By default we weight the spoke of face `f` at `v` by the Voronoi area of corner
//!   `(v, f)` (Meyer et al. 2003: `(|e_1|^2 cot + |e_2|^2 cot) / 8`, the obtuse rule on obtuse
//!   triangles) — the cotangent formula for the surface area the normal stands for, so the energy
//!   is consistent on non-uniform meshes. `cotan` reads eq 7 literally: the spoke's share of the
//!   cotangent weights of the two edges of `f` at `v`, `(cot beta + cot gamma) / 2` with `beta`,
//!   `gamma` the angles of `f` at its other corners (clamped at 0: an obtuse corner would make it
//!   negative, and a negative weight turns the Procrustes fit away from the spoke); `uniform` is
//!   eq 11's 1/3 (weight 1 per spoke).
//! - Eq 8 prints `S_v = sum w e e^T`; the ARAP cross-covariance it cites is `sum w e' e^T`.
//! - The inner loop starts from the normals of the current shape and stops when no normal moves by
//!   more than `tolerance` (radians, chord length) or after `max_iterations`.
//! - A normal whose weighted mean vanishes (rotations in opposition) keeps its previous value.

use rayon::prelude::*;

use meshes::vector::{norm, scale, sub};

use crate::operators::{corner_areas, MassKind};
use crate::rotation_fit::{closest_rotation_warm, Mat3};

/// The weight of the spoke of face `f` in the pyramid of its corner `v` (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpokeWeights {
    /// The Voronoi area of the corner (Meyer et al. 2003).
    #[default]
    Voronoi,
    /// Eq 7 read literally: half the cotangents of `f`'s angles at its other two corners, >= 0.
    Cotan,
    /// Eq 11: every spoke alike.
    Uniform,
}

/// `#F x 3` spoke weights of every corner of `triangles` (on `positions`).
fn spoke_weights(positions: &[[f64; 3]], triangles: &[[u32; 3]], kind: SpokeWeights) -> Vec<[f64; 3]> {
    match kind {
        SpokeWeights::Voronoi => corner_areas(positions, triangles, MassKind::Voronoi),
        SpokeWeights::Uniform => vec![[1.0; 3]; triangles.len()],
        SpokeWeights::Cotan => triangles
            .iter()
            .map(|t| {
                let p = t.map(|v| positions[v as usize]);
                let cot = |k: usize| {
                    let (a, b) = (sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
                    let c = meshes::vector::cross(a, b);
                    let s = norm(c);
                    if s > 0.0 {
                        meshes::vector::dot(a, b) / s
                    } else {
                        0.0
                    }
                };
                let cots = [cot(0), cot(1), cot(2)];
                std::array::from_fn(|k| (0.5 * (cots[(k + 1) % 3] + cots[(k + 2) % 3])).max(0.0))
            })
            .collect(),
    }
}

/// Below this many faces the phases run on one thread (rayon's split costs more than it saves).
const PARALLEL_MIN_FACES: usize = 4_000;

/// The rest pyramids of every vertex (CSR over the faces around each vertex).
pub struct NormalPyramids {
    triangles: Vec<[u32; 3]>,
    /// `#V + 1` offsets into `faces` / `weights`.
    offsets: Vec<usize>,
    faces: Vec<u32>,
    weights: Vec<f64>,
    /// `#F x 3` spoke weight of face `f` at its corner `k`.
    corner_weights: Vec<[f64; 3]>,
    /// `#F` rest unit normals.
    rest_normals: Vec<[f64; 3]>,
}

/// Outcome of [`NormalPyramids::update_normals`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalUpdate {
    /// Local/global iterations performed.
    pub iterations: usize,
    /// Largest normal change of the last iteration.
    pub last_change: f64,
}

impl NormalPyramids {
    /// Pyramids of the rest mesh (`#V x 3` `positions`, `#F x 3` `triangles`, `#F` unit
    /// `rest_normals`) with spoke weights of kind `weights`.
    pub fn new(
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        rest_normals: &[[f64; 3]],
        weights: SpokeWeights,
    ) -> Self {
        let corner_weights = spoke_weights(positions, triangles, weights);
        let mut offsets = vec![0usize; positions.len() + 1];
        for t in triangles {
            for &v in t {
                offsets[v as usize + 1] += 1;
            }
        }
        for i in 0..positions.len() {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut faces = vec![0u32; offsets[positions.len()]];
        let mut weights = vec![0.0; faces.len()];
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let slot = &mut fill[t[k] as usize];
                faces[*slot] = f as u32;
                weights[*slot] = corner_weights[f][k];
                *slot += 1;
            }
        }
        Self {
            triangles: triangles.to_vec(),
            offsets,
            faces,
            weights,
            corner_weights,
            rest_normals: rest_normals.to_vec(),
        }
    }

    /// Number of vertices (pyramids).
    pub fn n_vertices(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Step one: update the `#F x 3` unit `normals` in place (on entry: the current shape's normals;
    /// zero rows allowed for degenerate faces) by at most `max_iterations` local/global iterations,
    /// stopping once no normal moves by more than `tolerance`. `rotations` (`#V`, the `R_v` of eq 7)
    /// and `frames` (`#V`, warm starts of the SVD) are reused storage; `frames` carries over between
    /// calls. Every returned normal has unit length (or is the unchanged zero of a degenerate face
    /// whose rotated spokes cancel).
    pub fn update_normals(
        &self,
        normals: &mut [[f64; 3]],
        rotations: &mut [Mat3],
        frames: &mut [Mat3],
        max_iterations: usize,
        tolerance: f64,
    ) -> NormalUpdate {
        let mut update = NormalUpdate { iterations: 0, last_change: 0.0 };
        let parallel = self.triangles.len() >= PARALLEL_MIN_FACES;
        for iteration in 0..max_iterations {
            // Local phase (eq 7-8).
            let local = |(v, (r, frame)): (usize, (&mut Mat3, &mut Mat3))| {
                let mut s = [[0.0; 3]; 3];
                for idx in self.offsets[v]..self.offsets[v + 1] {
                    let f = self.faces[idx] as usize;
                    let (current, rest, w) = (normals[f], self.rest_normals[f], self.weights[idx]);
                    for i in 0..3 {
                        for j in 0..3 {
                            s[i][j] += w * current[i] * rest[j];
                        }
                    }
                }
                *r = closest_rotation_warm(&s, frame);
            };
            if parallel {
                rotations.par_iter_mut().zip(frames.par_iter_mut()).enumerate().for_each(local);
            } else {
                rotations.iter_mut().zip(frames.iter_mut()).enumerate().for_each(local);
            }
            // Global phase (eq 9-11).
            let rotations: &[Mat3] = rotations;
            let global = |(f, normal): (usize, &mut [f64; 3])| -> f64 {
                let rest = self.rest_normals[f];
                let mut sum = [0.0; 3];
                for k in 0..3 {
                    let r = &rotations[self.triangles[f][k] as usize];
                    let w = self.corner_weights[f][k];
                    for (i, s) in sum.iter_mut().enumerate() {
                        *s += w * (r[i][0] * rest[0] + r[i][1] * rest[1] + r[i][2] * rest[2]);
                    }
                }
                let length = norm(sum);
                if !(length > 0.0) || !length.is_finite() {
                    return 0.0;
                }
                let new = scale(sum, 1.0 / length);
                let change = norm(sub(new, *normal));
                *normal = new;
                change
            };
            let change = if parallel {
                normals.par_iter_mut().enumerate().map(global).reduce(|| 0.0, f64::max)
            } else {
                normals.iter_mut().enumerate().map(global).fold(0.0, f64::max)
            };
            update = NormalUpdate { iterations: iteration + 1, last_change: change };
            if change <= tolerance {
                break;
            }
        }
        update
    }

    /// The `#F` rest normals.
    pub fn rest_normals(&self) -> &[[f64; 3]] {
        &self.rest_normals
    }
}
