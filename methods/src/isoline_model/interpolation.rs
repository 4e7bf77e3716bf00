//! The reduced domain of Au et al. 2007 and its interpolation to the mesh (sections 4.1–4.3).
//!
//! [`IsolineModel`] holds the isolines (`N = #sets x n_iso`, numbered `m = set * n_iso + j`), the
//! two-level interpolation weights `w_{k,m}` of every vertex (section 4.2: linear between the two
//! isolines around `phi_{i,k}`, times the set weight of [`SetBlend`]: `phi_{i,k}` across handles, or
//! HIRM's constant `omega_bar_i`), and the sampled crossed triangles with their base frames. With the weights, `W_x[k, 4m + c] = w_{k,m} x_bar_k[c]` (homogeneous
//! `x_bar_k`, in the model's [`ModelFrame`]) and `W_delta[k, 3m + c] = w_{k,m} delta_bar_k[c]`; both
//! are applied row by row and never stored densely (`#V x 4N` would not fit for large meshes with
//! many handles).
//!
//! Decision (units): the transforms act on `x_bar_k = (x_k - c) / l`, the base positions in the
//! model's frame ([`ModelFrame`]: `c` the rest centroid, `l` the rest RMS radius), not on the mesh
//! coordinates. The smoothness term `beta^2 |M R|^2` (eq 5; HIRM's `mu`, eq 11-12) sums squared
//! differences of all 12 entries of neighbouring transforms: on mesh coordinates their linear parts
//! are unitless and their translations in mesh units, so the term's balance against the Laplacian
//! term changed with the mesh's units (`hirm` on the decimated knight in metres and millimetres:
//! E_theta 3.39 against 3.25 deg), and with its position (a translation `T` of the scene turns the translation
//! differences into `dt - dA T`). In the frame both parts are in units of `l`, every term of eq 5-6
//! scales with the square of the mesh's size, and results are invariant to scaling, translating and
//! rotating the scene. The transforms `R` are still the paper's affine maps, written in that frame.
//!
//! [`HandleIndependentSystem`] holds the parts of eq 10's matrices that do not depend on the handles
//! (`W_x^T L^T L W_x + beta^2 M^T M`, `W_x^T L^T W_delta`); [`ReducedSystem`] adds a handle set's
//! constraint term to give `U^T U` (`4N x 4N`) and the constraint right-hand side.

use faer::reborrow::ReborrowMut;
use faer::sparse::SparseColMatRef;
use faer::{Mat, MatMut, MatRef};

use meshes::vector::{cross, dot, normalize_or_zero, scale, sub};

use super::segment_frame;
use super::tracing::{sample_uniformly, trace_isoline, CrossedTriangle};
use crate::handles::{HandleSet, HandleTargets};
use crate::rotation_fit::{closest_rotation, singular_values, Mat3};

/// Offset of the special isolines from the boundary values 0 and 1 (see the module docs of
/// [`super`]).
const SPECIAL_LEVEL_OFFSET: f64 = 1e-6;

/// How the per-set interpolated transforms are blended into one per vertex (the second level of
/// the two-level interpolation). The weights of every vertex sum to 1.
#[derive(Clone, Debug, PartialEq)]
pub enum SetBlend {
    /// By the field values at the vertex, `phi_{i,k}` (Au et al. 2007, section 4.2; the harmonic
    /// fields of all handles sum to 1).
    FieldValues,
    /// By one constant weight per set (HIRM eq 8, the normalized importances `omega_bar_i`).
    PerSet(Vec<f64>),
}

/// The frame the reduced transforms act in (see the module docs): positions enter `W_x` as
/// `(x - center) / length`. Made from the rest mesh, so every model of one method shares it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelFrame {
    /// Centroid of the rest vertices.
    pub center: [f64; 3],
    /// RMS distance of the rest vertices from `center` (> 0).
    pub length: f64,
}

impl ModelFrame {
    /// The frame of the `#V x 3` rest positions `rest`: moves with the mesh under any rigid motion
    /// and scales with it. A degenerate (single-point) mesh gets length 1.
    pub fn of(rest: &[[f64; 3]]) -> Self {
        let n = rest.len().max(1) as f64;
        let mut center = [0.0; 3];
        for p in rest {
            for a in 0..3 {
                center[a] += p[a] / n;
            }
        }
        let mean_square = rest.iter().map(|p| dot(sub(*p, center), sub(*p, center))).sum::<f64>() / n;
        let length = mean_square.sqrt();
        Self { center, length: if length > 0.0 && length.is_finite() { length } else { 1.0 } }
    }

    /// `(x - center) / length` with the homogeneous 1.
    fn homogeneous(&self, x: [f64; 3]) -> [f64; 4] {
        let d = sub(x, self.center);
        [d[0] / self.length, d[1] / self.length, d[2] / self.length, 1.0]
    }
}

/// `sum_m w_m R_m^T h` (eq 4-5 and 7 for one vertex): the position of a vertex with weights
/// `weights` and homogeneous base position `h` under the `4N x 3` transforms `reduced`.
fn interpolate(weights: &[(u32, f64)], h: [f64; 4], reduced: MatRef<'_, f64>) -> [f64; 3] {
    let mut out = [0.0; 3];
    for &(m, w) in weights {
        let row = 4 * m as usize;
        for (a, o) in out.iter_mut().enumerate() {
            *o += w * (0..4).map(|c| reduced[(row + c, a)] * h[c]).sum::<f64>();
        }
    }
    out
}

/// One isoline `(set, j)` and its sampled crossed triangles.
#[derive(Clone, Debug)]
pub struct Isoline {
    /// Index of the harmonic field (isoline set) it belongs to.
    pub set: usize,
    /// `j`, 0-based: isovalue `j / (n_iso - 1)`.
    pub index: usize,
    /// `s_ij`, the isovalue of the interpolation.
    pub isovalue: f64,
    /// The level actually traced (the isovalue, or just inside `(0, 1)` for the special isolines).
    pub level: f64,
    /// Crossed triangles before sampling.
    pub crossed_total: usize,
    /// `Gamma_ij`: the sampled crossed triangles.
    pub crossed: Vec<CrossedTriangle>,
}

/// A sampled crossed triangle as the iteration uses it: its corners and segment ends as indices
/// into the probe vertices, the segment weight `l^2` and the base frame.
#[derive(Clone, Debug)]
struct Sample {
    isoline: u32,
    corners: [u32; 3],
    /// `(probe a, probe b, t)` of both segment ends.
    ends: [(u32, u32, f64); 2],
    weight: f64,
    base_frame: [[f64; 3]; 3],
    /// The corners minus their centroid and the scaled normal on the base shape (eq 17 of HIRM).
    base_points: [[f64; 3]; 4],
}

/// The isolines, the interpolation weights and the sampled crossed triangles; see the module docs.
pub struct IsolineModel {
    n_iso: usize,
    n_sets: usize,
    frame: ModelFrame,
    base: Vec<[f64; 3]>,
    /// `L x_bar` of the base shape, `#V`.
    base_delta: Vec<[f64; 3]>,
    /// CSR rows of `w_{k,m}`: vertex `k` has `entries[row_start[k]..row_start[k + 1]]`.
    row_start: Vec<usize>,
    entries: Vec<(u32, f64)>,
    isolines: Vec<Isoline>,
    /// Vertices of the sampled triangles.
    probes: Vec<u32>,
    /// The probes' rows of `W_x`, gathered when the model is built: `probe_entries[probe_row_start[i]..
    /// probe_row_start[i + 1]]` and `probe_homogeneous[i]` are probe `i`'s weights and homogeneous base
    /// position. An iteration reads these few contiguous KB instead of rows scattered over `#V`-sized
    /// arrays, which on a large mesh cost a cache and TLB miss each.
    probe_row_start: Vec<usize>,
    probe_entries: Vec<(u32, f64)>,
    probe_homogeneous: Vec<[f64; 4]>,
    samples: Vec<Sample>,
}

impl IsolineModel {
    /// Build the model on the `#V x 3` base shape `base` from `#V x #sets` scalar fields with values
    /// in `[0, 1]` (one isoline set per column): `n_iso` isolines per set, at most
    /// `max_crossed_triangles` sampled triangles in all, sets blended by `blend`, transforms acting in
    /// `frame`. `delta_bar = L X_base` is filled in by [`HandleIndependentSystem::new`], which has `L`.
    pub fn new(
        frame: ModelFrame,
        base: &[[f64; 3]],
        triangles: &[[u32; 3]],
        fields: MatRef<'_, f64>,
        blend: &SetBlend,
        n_iso: usize,
        max_crossed_triangles: usize,
    ) -> Self {
        let n = base.len();
        let n_sets = fields.ncols();
        assert!(n_sets >= 1 && n_iso >= 2, "at least one isoline set of two isolines");
        if let SetBlend::PerSet(weights) = blend {
            assert_eq!(weights.len(), n_sets, "one blending weight per isoline set");
        }
        let field = |k: usize, set: usize| fields[(k, set)].clamp(0.0, 1.0);
        let mut row_start = Vec::with_capacity(n + 1);
        let mut entries = Vec::with_capacity(2 * n * n_sets);
        row_start.push(0);
        for k in 0..n {
            for set in 0..n_sets {
                let set_weight = match blend {
                    _ if n_sets == 1 => 1.0,
                    SetBlend::FieldValues => field(k, set),
                    SetBlend::PerSet(weights) => weights[set],
                };
                if set_weight == 0.0 {
                    continue;
                }
                let position = field(k, set) * (n_iso - 1) as f64;
                let j = (position.floor() as usize).min(n_iso - 2);
                let alpha = position - j as f64;
                let m = (set * n_iso + j) as u32;
                entries.push((m, set_weight * (1.0 - alpha)));
                entries.push((m + 1, set_weight * alpha));
            }
            row_start.push(entries.len());
        }

        let per_isoline = (max_crossed_triangles / (n_sets * n_iso)).max(1);
        let mut isolines = Vec::with_capacity(n_sets * n_iso);
        let mut values = vec![0.0; n];
        for set in 0..n_sets {
            for (k, v) in values.iter_mut().enumerate() {
                *v = fields[(k, set)];
            }
            for j in 0..n_iso {
                let isovalue = j as f64 / (n_iso - 1) as f64;
                let level = isovalue.clamp(SPECIAL_LEVEL_OFFSET, 1.0 - SPECIAL_LEVEL_OFFSET);
                let crossed = trace_isoline(base, triangles, &values, level);
                let crossed_total = crossed.len();
                let crossed = sample_uniformly(crossed, per_isoline);
                isolines.push(Isoline { set, index: j, isovalue, level, crossed_total, crossed });
            }
        }

        let mut probe_of = vec![u32::MAX; n];
        let mut probes = Vec::new();
        let mut probe = |v: u32| {
            if probe_of[v as usize] == u32::MAX {
                probe_of[v as usize] = probes.len() as u32;
                probes.push(v);
            }
            probe_of[v as usize]
        };
        let mut samples = Vec::new();
        for (m, isoline) in isolines.iter().enumerate() {
            for c in &isoline.crossed {
                let tri = triangles[c.triangle as usize];
                let corners = tri.map(&mut probe);
                let ends = c.ends.map(|e| (probe(e.a), probe(e.b), e.t));
                let p = tri.map(|v| base[v as usize]);
                let (q0, q1) = (c.ends[0].position(base), c.ends[1].position(base));
                samples.push(Sample {
                    isoline: m as u32,
                    corners,
                    ends,
                    weight: c.length * c.length,
                    base_frame: segment_frame(p, q0, q1),
                    base_points: centered_points(p),
                });
            }
        }
        let mut probe_row_start = Vec::with_capacity(probes.len() + 1);
        let mut probe_entries = Vec::new();
        probe_row_start.push(0);
        for &v in &probes {
            probe_entries.extend_from_slice(&entries[row_start[v as usize]..row_start[v as usize + 1]]);
            probe_row_start.push(probe_entries.len());
        }
        let probe_homogeneous = probes.iter().map(|&v| frame.homogeneous(base[v as usize])).collect();
        Self {
            n_iso,
            n_sets,
            frame,
            base: base.to_vec(),
            base_delta: Vec::new(),
            row_start,
            entries,
            isolines,
            probes,
            probe_row_start,
            probe_entries,
            probe_homogeneous,
            samples,
        }
    }

    /// Number of isolines `N` (reduced variables: `4N` per coordinate for `R_x`, `3N` for `R_delta`).
    pub fn n_isolines(&self) -> usize {
        self.n_sets * self.n_iso
    }

    /// The isolines, `m = set * n_iso + j`.
    pub fn isolines(&self) -> &[Isoline] {
        &self.isolines
    }

    /// `n_tri`: sampled crossed triangles of all isolines.
    pub fn n_sampled_triangles(&self) -> usize {
        self.samples.len()
    }

    /// Interpolation weights `(m, w_{k,m})` of vertex `k` (they sum to 1).
    pub fn vertex_weights(&self, k: usize) -> &[(u32, f64)] {
        &self.entries[self.row_start[k]..self.row_start[k + 1]]
    }

    /// The `#V x 3` Laplacian coordinates of the base shape, `L X_base`.
    pub fn base_delta(&self) -> &[[f64; 3]] {
        &self.base_delta
    }

    /// The frame the transforms act in.
    pub fn frame(&self) -> ModelFrame {
        self.frame
    }

    /// The direction no row of `W_x` sees when the base shape is planar: the unit homogeneous
    /// `nu = (n, -n . x_bar_mean) / |..|` with `n` the normal of the base's best-fit plane in the
    /// model's frame, so that `nu . (x_bar_k, 1) = 0` for every vertex `k`. Then `W_x` maps every
    /// transform part `nu a^T` (`a` any 3-vector) to zero: the out-of-plane row of the transforms
    /// moves no vertex. `None` unless every vertex lies within `tolerance` of that plane, in units
    /// of the base's RMS distance from its centroid; `None` also for an empty or single-point base.
    pub fn plane_direction(&self, tolerance: f64) -> Option<[f64; 4]> {
        let n = self.base.len();
        if n == 0 {
            return None;
        }
        let points: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let h = self.homogeneous(k);
                [h[0], h[1], h[2]]
            })
            .collect();
        let mut mean = [0.0; 3];
        for p in &points {
            for a in 0..3 {
                mean[a] += p[a] / n as f64;
            }
        }
        let mut covariance = Mat::<f64>::zeros(3, 3);
        for p in &points {
            let d = sub(*p, mean);
            for a in 0..3 {
                for b in 0..3 {
                    covariance[(a, b)] += d[a] * d[b] / n as f64;
                }
            }
        }
        let radius = (0..3).map(|a| covariance[(a, a)]).sum::<f64>().sqrt();
        if !(radius > 0.0 && radius.is_finite()) {
            return None;
        }
        let evd = covariance.as_ref().self_adjoint_eigen(faer::Side::Lower).ok()?;
        let smallest = (0..3).min_by(|&i, &j| evd.S()[i].total_cmp(&evd.S()[j]))?;
        let normal = normalize_or_zero(std::array::from_fn(|a| evd.U()[(a, smallest)]));
        let offset = -dot(normal, mean);
        let distance = points.iter().map(|p| (dot(normal, *p) + offset).abs()).fold(0.0, f64::max);
        if !(distance <= tolerance * radius) || dot(normal, normal) == 0.0 {
            return None;
        }
        let norm = (1.0 + offset * offset).sqrt();
        Some([normal[0] / norm, normal[1] / norm, normal[2] / norm, offset / norm])
    }

    /// Row `k` of `W_x` before the isoline weights: `x_bar_k = (x_k - c) / l` and 1 (see
    /// [`ModelFrame`]).
    fn homogeneous(&self, k: usize) -> [f64; 4] {
        self.frame.homogeneous(self.base[k])
    }

    /// `R_x` (`4N x 3`, column per coordinate) of identity transforms: `W_x R_x = X_base`. In the
    /// model's frame the identity is `x = l x_bar + c`: linear part `l I`, translation `c`.
    pub fn identity_transforms(&self) -> Mat<f64> {
        let ModelFrame { center, length } = self.frame;
        Mat::from_fn(4 * self.n_isolines(), 3, |row, a| match row % 4 {
            3 => center[a],
            c if c == a => length,
            _ => 0.0,
        })
    }

    /// `R_delta` (`3N x 3`) of identity rotations: `W_delta R_delta = delta_bar`.
    pub fn identity_rotations(&self) -> Mat<f64> {
        Mat::from_fn(3 * self.n_isolines(), 3, |row, a| if row % 3 == a { 1.0 } else { 0.0 })
    }

    /// `(W_x R_x)_k`: vertex `k` under the reduced variables `reduced` (`4N x 3`).
    pub fn position(&self, k: usize, reduced: MatRef<'_, f64>) -> [f64; 3] {
        interpolate(self.vertex_weights(k), self.homogeneous(k), reduced)
    }

    /// `W_x R_x` for every vertex, `#V x 3`.
    pub fn positions(&self, reduced: MatRef<'_, f64>) -> Vec<[f64; 3]> {
        (0..self.base.len()).map(|k| self.position(k, reduced)).collect()
    }

    /// `(W_delta R_delta)_k` for the rotations `rotations` (`3N x 3`).
    pub fn interpolated_delta(&self, k: usize, rotations: MatRef<'_, f64>) -> [f64; 3] {
        let d = self.base_delta[k];
        let mut out = [0.0; 3];
        for &(m, w) in self.vertex_weights(k) {
            let row = 3 * m as usize;
            for (a, o) in out.iter_mut().enumerate() {
                *o += w * (0..3).map(|c| rotations[(row + c, a)] * d[c]).sum::<f64>();
            }
        }
        out
    }

    /// Positions of the vertices of the sampled triangles under `reduced` (`4N x 3`): all the
    /// iteration of eq 10 evaluates.
    pub fn probe_positions(&self, reduced: MatRef<'_, f64>) -> Vec<[f64; 3]> {
        (0..self.probes.len())
            .map(|i| {
                let weights = &self.probe_entries[self.probe_row_start[i]..self.probe_row_start[i + 1]];
                interpolate(weights, self.probe_homogeneous[i], reduced)
            })
            .collect()
    }

    /// The mesh vertex of probe `i` (the order of [`IsolineModel::probe_positions`]).
    pub fn probe_vertex(&self, i: usize) -> u32 {
        self.probes[i]
    }

    /// `R_delta` (`3N x 3`, the transpose of `r^_m` in rows `3m..3m + 3`): per isoline the rotation
    /// fitted to its sampled crossed triangles at the probe positions `probes` by `fit`. An isoline
    /// without sampled triangles takes the rotation of the nearest one in its set that has some.
    pub fn isoline_rotations(&self, probes: &[[f64; 3]], fit: RotationFit) -> Mat<f64> {
        let fitted = match fit {
            RotationFit::SegmentFrames => self.segment_frame_rotations(probes),
            RotationFit::ScaledOrthogonal => self.scaled_orthogonal_rotations(probes),
        };
        let n_isolines = self.n_isolines();
        let mut out = Mat::<f64>::zeros(3 * n_isolines, 3);
        for set in 0..self.n_sets {
            let range = set * self.n_iso..(set + 1) * self.n_iso;
            let with_fit: Vec<usize> = range.clone().filter(|&m| fitted[m].is_some()).collect();
            for m in range {
                let source = with_fit.iter().copied().min_by_key(|&f| f.abs_diff(m));
                for a in 0..3 {
                    for c in 0..3 {
                        out[(3 * m + c, a)] = match source {
                            Some(f) => fitted[f].expect("chosen among the fitted")[a][c],
                            None => f64::from(u8::from(a == c)),
                        };
                    }
                }
            }
        }
        out
    }

    /// Au et al. 2007 eq 8-9 with the frame completion of the module docs:
    /// `r^_m = sum_k l_k^2 F_k F_bar_k^T / sum_k l_k^2`; `None` for isolines without samples.
    fn segment_frame_rotations(&self, probes: &[[f64; 3]]) -> Vec<Option<Mat3>> {
        let n_isolines = self.n_isolines();
        let mut sums = vec![[[0.0f64; 3]; 3]; n_isolines];
        let mut weights = vec![0.0f64; n_isolines];
        for s in &self.samples {
            let p = s.corners.map(|c| probes[c as usize]);
            let end = |(a, b, t): (u32, u32, f64)| {
                let (pa, pb) = (probes[a as usize], probes[b as usize]);
                std::array::from_fn(|c| (1.0 - t) * pa[c] + t * pb[c])
            };
            let frame = segment_frame(p, end(s.ends[0]), end(s.ends[1]));
            let m = s.isoline as usize;
            for a in 0..3 {
                for c in 0..3 {
                    sums[m][a][c] +=
                        s.weight * (0..3).map(|col| frame[col][a] * s.base_frame[col][c]).sum::<f64>();
                }
            }
            weights[m] += s.weight;
        }
        sums.iter()
            .zip(&weights)
            .map(|(sum, &w)| (w > 0.0).then(|| sum.map(|row| row.map(|v| v / w))))
            .collect()
    }

    /// HIRM eq 17-19: `r~_m` is the least-squares map of the centered corners of the base triangles
    /// onto the current ones (eq 17), `r^_m = s_m orth(r~_m)` with `s_m = 3 / trace(Sigma)` of the
    /// SVD `r~_m = U Sigma V^T` (eq 18-19).
    ///
    /// Decision: each triangle also maps its unit normal, scaled by the RMS distance of its corners
    /// from the centroid, onto the current one. Without it eq 17 is singular for an isoline whose
    /// triangles are coplanar (a flat region); with it a rigid motion is still recovered exactly.
    fn scaled_orthogonal_rotations(&self, probes: &[[f64; 3]]) -> Vec<Option<Mat3>> {
        let n_isolines = self.n_isolines();
        // Per isoline: A = sum current base^T, B = sum base base^T (eq 17's normal equations).
        let mut cross_sums = vec![[[0.0f64; 3]; 3]; n_isolines];
        let mut base_sums = vec![[[0.0f64; 3]; 3]; n_isolines];
        for s in &self.samples {
            let current = centered_points(s.corners.map(|c| probes[c as usize]));
            let m = s.isoline as usize;
            for (q, p) in current.iter().zip(&s.base_points) {
                for a in 0..3 {
                    for c in 0..3 {
                        cross_sums[m][a][c] += q[a] * p[c];
                        base_sums[m][a][c] += p[a] * p[c];
                    }
                }
            }
        }
        cross_sums
            .iter()
            .zip(&base_sums)
            .map(|(a, b)| {
                let fit = matmul3(a, &inverse3(b)?);
                let singular_sum: f64 = singular_values(&fit).iter().sum();
                if !(singular_sum > 0.0 && singular_sum.is_finite()) {
                    return None;
                }
                let scale = 3.0 / singular_sum;
                Some(closest_rotation(&fit).map(|row| row.map(|v| scale * v)))
            })
            .collect()
    }

    /// `W_x` row `k`: `(column, value)` pairs.
    fn position_row(&self, k: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let h = self.homogeneous(k);
        self.vertex_weights(k)
            .iter()
            .flat_map(move |&(m, w)| (0..4).map(move |c| (4 * m as usize + c, w * h[c])))
    }

    /// The transforms `R` (`4N x 3`) whose `W_x R` is nearest to `target` (`#V x 3`) in least
    /// squares over every vertex: how well the reduced space can represent a shape at all. A tiny
    /// ridge (1e-12 of the largest diagonal entry) keeps transforms no vertex sees determined;
    /// `None` if the normal equations still cannot be factored.
    pub fn least_squares_fit(&self, target: &[[f64; 3]]) -> Option<Mat<f64>> {
        let size = 4 * self.n_isolines();
        let mut normal = Mat::<f64>::zeros(size, size);
        let mut rhs = Mat::<f64>::zeros(size, 3);
        for (k, t) in target.iter().enumerate() {
            let row: Vec<(usize, f64)> = self.position_row(k).collect();
            for &(p, vp) in &row {
                for &(q, vq) in &row {
                    normal[(p, q)] += vp * vq;
                }
                for a in 0..3 {
                    rhs[(p, a)] += vp * t[a];
                }
            }
        }
        let ridge = 1e-12 * (0..size).map(|i| normal[(i, i)]).fold(0.0, f64::max);
        for i in 0..size {
            normal[(i, i)] += ridge;
        }
        let llt = normal.llt(faer::Side::Lower).ok()?;
        Some(faer::linalg::solvers::Solve::solve(&llt, &rhs))
    }

    /// `W_delta` row `k`: `(column, value)` pairs.
    fn delta_row(&self, k: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let d = self.base_delta[k];
        self.vertex_weights(k)
            .iter()
            .flat_map(move |&(m, w)| (0..3).map(move |c| (3 * m as usize + c, w * d[c])))
    }
}

/// How [`IsolineModel::isoline_rotations`] fits one rotation per isoline to its crossed triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotationFit {
    /// Au et al. 2007 eq 8-9: the average of the segment frames' rotations (module docs of
    /// [`super`]).
    SegmentFrames,
    /// HIRM eq 17-19: least-squares map of the triangles' corners, its rotation by SVD, scaled by
    /// `3 / trace(Sigma)` to cancel the shrinking of linear interpolation.
    ScaledOrthogonal,
}

/// The three corners of a triangle minus their centroid, and its unit normal scaled by the RMS
/// distance of the corners from the centroid (zero for a degenerate triangle).
fn centered_points(p: [[f64; 3]; 3]) -> [[f64; 3]; 4] {
    let centroid: [f64; 3] = std::array::from_fn(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0);
    let offsets = p.map(|q| sub(q, centroid));
    let rms = (offsets.iter().map(|o| dot(*o, *o)).sum::<f64>() / 3.0).sqrt();
    let normal = normalize_or_zero(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    [offsets[0], offsets[1], offsets[2], scale(normal, rms)]
}

fn matmul3(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Inverse of a 3x3 matrix by cofactors; `None` when it is singular relative to its scale.
fn inverse3(m: &Mat3) -> Option<Mat3> {
    let cof = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det: f64 = (0..3).map(|j| m[0][j] * cof(0, j)).sum();
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    if !(det.abs() > 1e-12 * scale * scale * scale) {
        return None;
    }
    Some(std::array::from_fn(|i| std::array::from_fn(|j| cof(j, i) / det)))
}

/// The handle-independent part of eq 10's matrices (HIRM eq 23-25 calls them `T_1` and `T_2`):
/// they depend on the base shape and the isolines only, so HIRM computes them in the background and
/// a new handle set only adds its constraint term.
pub struct HandleIndependentSystem {
    /// `T_1 = W_x^T L^T L W_x + beta^2 M^T M`, `4N x 4N`.
    pub smoothness_normal_matrix: Mat<f64>,
    /// `W_x^T L^T W_delta`, `4N x 3N` (empty when `delta` is evaluated on the mesh, the `t_1`
    /// variant); `T_2 = W_x^T L^T W_delta R_delta`.
    pub laplacian_rhs: Mat<f64>,
}

impl HandleIndependentSystem {
    /// Build `T_1` and, when `interpolate_delta`, `W_x^T L^T W_delta`; also sets the model's
    /// `delta_bar = L X_base`. `laplacian`: the `#V x #V` cotangent Laplacian (symmetric).
    pub fn new(
        model: &mut IsolineModel,
        laplacian: SparseColMatRef<'_, usize, f64>,
        beta: f64,
        interpolate_delta: bool,
    ) -> Self {
        let n = model.base.len();
        let (symbolic, values) = laplacian.parts();
        model.base_delta = (0..n)
            .map(|r| {
                let mut d = [0.0; 3];
                for idx in symbolic.col_range(r) {
                    let k = symbolic.row_idx()[idx];
                    for a in 0..3 {
                        d[a] += values[idx] * model.base[k][a];
                    }
                }
                d
            })
            .collect();
        let size = 4 * model.n_isolines();
        let mut normal_matrix = Mat::<f64>::zeros(size, size);
        let mut laplacian_rhs =
            Mat::<f64>::zeros(size, if interpolate_delta { 3 * model.n_isolines() } else { 0 });
        // Row r of L W_x, accumulated densely over the touched columns.
        let mut row = vec![0.0; size];
        let mut is_touched = vec![false; size];
        let mut touched: Vec<usize> = Vec::new();
        for r in 0..n {
            for idx in symbolic.col_range(r) {
                let k = symbolic.row_idx()[idx];
                for (col, v) in model.position_row(k) {
                    if !is_touched[col] {
                        is_touched[col] = true;
                        touched.push(col);
                    }
                    row[col] += values[idx] * v;
                }
            }
            for &p in &touched {
                for &q in &touched {
                    normal_matrix[(p, q)] += row[p] * row[q];
                }
                if interpolate_delta {
                    for (col, v) in model.delta_row(r) {
                        laplacian_rhs[(p, col)] += row[p] * v;
                    }
                }
            }
            for &p in &touched {
                row[p] = 0.0;
                is_touched[p] = false;
            }
            touched.clear();
        }
        // Eq 5 (HIRM eq 12): r_{i,j} - r_{i,j+1} = 0, every entry of the 3x4 transforms (per
        // coordinate 4).
        let b2 = beta * beta;
        for set in 0..model.n_sets {
            for j in 0..model.n_iso - 1 {
                let m = set * model.n_iso + j;
                for c in 0..4 {
                    let (p, q) = (4 * m + c, 4 * (m + 1) + c);
                    normal_matrix[(p, p)] += b2;
                    normal_matrix[(q, q)] += b2;
                    normal_matrix[(p, q)] -= b2;
                    normal_matrix[(q, p)] -= b2;
                }
            }
        }
        Self { smoothness_normal_matrix: normal_matrix, laplacian_rhs }
    }

    /// `U^T U = T_1 + omega^2 (Phi W_x)^T (Phi W_x)` (eq 6; HIRM eq 26) for the constrained vertices
    /// of `handles`, `4N x 4N`, both triangles.
    pub fn constrained_normal_matrix(
        &self,
        model: &IsolineModel,
        handles: &HandleSet,
        omega: f64,
    ) -> Mat<f64> {
        let mut normal_matrix = self.smoothness_normal_matrix.clone();
        add_constraint_rows_lower(model, handles.constrained(), omega, normal_matrix.as_mut());
        let n = normal_matrix.nrows();
        for j in 0..n {
            for i in 0..j {
                normal_matrix[(i, j)] = normal_matrix[(j, i)];
            }
        }
        normal_matrix
    }

    /// The lower triangle of [`HandleIndependentSystem::constrained_normal_matrix`] into `out`
    /// (`4N x 4N`, overwritten; its strict upper triangle is left unspecified), for an in-place
    /// Cholesky factorization: HIRM's handle update (eq 26) without allocation.
    pub fn constrained_normal_matrix_lower_into(
        &self,
        model: &IsolineModel,
        handles: &HandleSet,
        omega: f64,
        mut out: MatMut<'_, f64>,
    ) {
        out.copy_from_triangular_lower(self.smoothness_normal_matrix.as_ref());
        add_constraint_rows_lower(model, handles.constrained(), omega, out);
    }
}

/// `out += omega^2 (Phi W_x)^T (Phi W_x)` over the rows of `vertices`, on the lower triangle of the
/// `4N x 4N` `out` (the `4 x 4` blocks on the diagonal are updated whole): the constraint term of
/// eq 26 added vertex by vertex, in the given order, so a matrix that already holds the term of some
/// regions grows to the same bits as one built whole.
///
/// Row `k` of `Phi W_x` is `w_k (x) (x_bar_k, 1)`: per isoline `m` of vertex `k`, 4 contiguous
/// columns. Only the blocks of isoline pairs `(p, q)` with `p >= q` are accumulated, 4 wide.
pub fn add_constraint_rows_lower(
    model: &IsolineModel,
    vertices: impl Iterator<Item = u32>,
    omega: f64,
    mut out: MatMut<'_, f64>,
) {
    let w2 = omega * omega;
    for v in vertices {
        let h = model.homogeneous(v as usize);
        let local = model.vertex_weights(v as usize);
        for &(mq, wq) in local {
            let q = 4 * mq as usize;
            for (d, hd) in h.iter().enumerate() {
                let column = out.rb_mut().col_mut(q + d).try_as_col_major_mut().expect("column-major output");
                let column = column.as_slice_mut();
                let s = w2 * wq * hd;
                for &(mp, wp) in local {
                    if mp < mq {
                        continue;
                    }
                    let f = s * wp;
                    let p = 4 * mp as usize;
                    // A fixed-size chunk: one bounds check and a 4-wide update.
                    let cell: &mut [f64; 4] =
                        (&mut column[p..p + 4]).try_into().expect("4 columns per isoline");
                    for (o, he) in cell.iter_mut().zip(&h) {
                        *o += f * he;
                    }
                }
            }
        }
    }
}

/// `omega^2 W_x^T Phi^T H` (`4N x 3`) for the targets `H` of the constrained vertices of `handles`.
pub fn constraint_rhs(
    model: &IsolineModel,
    handles: &HandleSet,
    targets: &HandleTargets,
    omega: f64,
) -> Mat<f64> {
    let w2 = omega * omega;
    let mut out = Mat::<f64>::zeros(4 * model.n_isolines(), 3);
    for (v, t) in handles.constrained().zip(targets.positions()) {
        for (p, value) in model.position_row(v as usize) {
            for a in 0..3 {
                out[(p, a)] += w2 * value * t[a];
            }
        }
    }
    out
}

/// The matrices of eq 10 for one handle set; see the module docs.
pub struct ReducedSystem {
    /// `U^T U`, `4N x 4N`.
    pub normal_matrix: Mat<f64>,
    /// `W_x^T L^T W_delta`, `4N x 3N` (empty when `delta` is evaluated on the mesh, the `t_1` variant).
    pub laplacian_rhs: Mat<f64>,
    omega: f64,
}

impl ReducedSystem {
    /// Build `U^T U = W_x^T L^T L W_x + omega^2 W_x^T Phi^T Phi W_x + beta^2 M^T M` and, when
    /// `interpolate_delta`, `W_x^T L^T W_delta`; also sets the model's `delta_bar = L X_base`.
    /// `laplacian`: the `#V x #V` cotangent Laplacian (symmetric).
    pub fn new(
        model: &mut IsolineModel,
        laplacian: SparseColMatRef<'_, usize, f64>,
        handles: &HandleSet,
        omega: f64,
        beta: f64,
        interpolate_delta: bool,
    ) -> Self {
        let independent = HandleIndependentSystem::new(model, laplacian, beta, interpolate_delta);
        let normal_matrix = independent.constrained_normal_matrix(model, handles, omega);
        Self { normal_matrix, laplacian_rhs: independent.laplacian_rhs, omega }
    }

    /// `omega^2 W_x^T Phi^T H` (`4N x 3`) for the targets `H` of the constrained vertices.
    pub fn constraint_rhs(
        &self,
        model: &IsolineModel,
        handles: &HandleSet,
        targets: &HandleTargets,
    ) -> Mat<f64> {
        constraint_rhs(model, handles, targets, self.omega)
    }

    /// `W_x^T L^T delta` (`4N x 3`) for `delta` evaluated on the mesh (`#V x 3`; the `t_1` variant).
    pub fn laplacian_rhs_full(
        &self,
        model: &IsolineModel,
        laplacian: SparseColMatRef<'_, usize, f64>,
        delta: MatRef<'_, f64>,
    ) -> Mat<f64> {
        let (symbolic, values) = laplacian.parts();
        let mut out = Mat::<f64>::zeros(4 * model.n_isolines(), 3);
        for k in 0..model.base.len() {
            // (L delta)_k, L symmetric.
            let mut y = [0.0; 3];
            for idx in symbolic.col_range(k) {
                let i = symbolic.row_idx()[idx];
                for a in 0..3 {
                    y[a] += values[idx] * delta[(i, a)];
                }
            }
            for (p, value) in model.position_row(k) {
                for a in 0..3 {
                    out[(p, a)] += value * y[a];
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gathered_probe_rows_give_every_probe_its_vertex_position_to_the_bit() {
        let shape = meshes::shapes::generate(meshes::shapes::ShapeKind::Bar, 1500).unwrap();
        let base = shape.mesh.positions().to_vec();
        let (lo, hi) = base.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
        // Two fields along the bar's length, one the complement of the other.
        let fields = Mat::from_fn(base.len(), 2, |k, set| {
            let t = (base[k][0] - lo) / (hi - lo);
            if set == 0 {
                t
            } else {
                1.0 - t
            }
        });
        let frame = ModelFrame::of(&base);
        let model = IsolineModel::new(
            frame,
            &base,
            shape.mesh.triangles(),
            fields.as_ref(),
            &SetBlend::PerSet(vec![0.5, 0.5]),
            8,
            200,
        );
        // Transforms away from the identity, so every weight and coordinate counts.
        let reduced =
            Mat::from_fn(4 * model.n_isolines(), 3, |r, a| ((r * 7 + a * 3) % 11) as f64 * 0.1 - 0.4);
        let probes = model.probe_positions(reduced.as_ref());
        assert!(probes.len() > 100, "{} probes", probes.len());
        for (i, p) in probes.iter().enumerate() {
            let v = model.probe_vertex(i) as usize;
            assert_eq!(
                p.map(f64::to_bits),
                model.position(v, reduced.as_ref()).map(f64::to_bits),
                "probe {i}"
            );
        }
    }

    /// A flat grid, tilted and moved away from the origin, with out-of-plane relief `relief`
    /// (relative to its size), and a model on it with one field along its length.
    fn tilted_grid_model(relief: f64) -> (IsolineModel, Vec<[f64; 3]>) {
        let (nx, ny) = (21, 11);
        let mut base = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (u, v) = (i as f64 / (nx - 1) as f64 * 2.0, j as f64 / (ny - 1) as f64);
                let w = relief * (7.0 * u).sin() * (5.0 * v).cos();
                // The (u, v, w) frame turned about (1, 1, 0) and moved to (10, -4, 3).
                base.push([
                    10.0 + 0.8 * u + 0.2 * v + 0.566 * w,
                    -4.0 + 0.2 * u + 0.8 * v - 0.566 * w,
                    3.0 - 0.566 * u + 0.566 * v + 0.6 * w,
                ]);
            }
        }
        let id = |i: usize, j: usize| (j * nx + i) as u32;
        let triangles: Vec<[u32; 3]> = (0..ny - 1)
            .flat_map(|j| {
                (0..nx - 1).flat_map(move |i| {
                    [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]]
                })
            })
            .collect();
        let fields = Mat::from_fn(base.len(), 1, |k, _| (k % nx) as f64 / (nx - 1) as f64);
        let frame = ModelFrame::of(&base);
        let model =
            IsolineModel::new(frame, &base, &triangles, fields.as_ref(), &SetBlend::PerSet(vec![1.0]), 6, 60);
        (model, base)
    }

    #[test]
    fn a_planar_base_has_a_direction_no_row_of_w_sees() {
        let (model, base) = tilted_grid_model(0.0);
        let nu = model.plane_direction(1e-6).expect("a planar grid");
        let norm = nu.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-12, "|nu| = {norm}");
        for k in 0..base.len() {
            let h = model.homogeneous(k);
            let seen: f64 = (0..4).map(|c| nu[c] * h[c]).sum();
            assert!(seen.abs() < 1e-12, "vertex {k}: nu . (x_bar, 1) = {seen:e}");
        }
        // So adding nu a^T to every transform moves no vertex.
        let identity = model.identity_transforms();
        let shifted =
            Mat::from_fn(identity.nrows(), 3, |r, a| identity[(r, a)] + [3.0, -2.0, 5.0][a] * nu[r % 4]);
        let moved = model.positions(shifted.as_ref());
        for (p, q) in moved.iter().zip(&base) {
            assert!(norm3(sub(*p, *q)) < 1e-11, "{p:?} against {q:?}");
        }
        // Relief within the tolerance is planar, beyond it not.
        assert!(tilted_grid_model(1e-9).0.plane_direction(1e-6).is_some());
        assert!(tilted_grid_model(1e-4).0.plane_direction(1e-6).is_none());
    }

    fn norm3(v: [f64; 3]) -> f64 {
        dot(v, v).sqrt()
    }
}
