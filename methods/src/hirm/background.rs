//! The handle-independent system of HIRM (Wu et al. 2015, section 4.5, eq 22-25) and the worker
//! thread that recomputes it from the current shape after every edit step.
//!
//! On a base shape `X`: the isolines of the (fixed) propagation fields and the interpolation
//! `W = W(X)` (eq 22), `T_1 = U^^T U^` with `U^ = [L W; mu M]` (eq 23-24), and `W^T L^T W_sigma`,
//! which gives `T_2 = W^T L^T W_sigma R_sigma(X)` (eq 25) for any isoline rotations `R_sigma`.
//! Binding a handle set then only adds `(Phi W)^T (Phi W)` (eq 26).
//!
//! Incremental editing keeps the regions of the step before (they are held where they are), so the
//! worker also adds their constraint term to `T_1` ([`KeptConstraints`]): a bind that keeps them adds
//! only the rows of its new regions (the same sum, in the same order, as the whole term).

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

use faer::sparse::SparseColMat;
use faer::Mat;

use crate::error::MethodError;
use crate::handles::{HandleRegion, HandleSet};
use crate::isoline_model::{
    add_constraint_rows_lower, HandleIndependentSystem, IsolineModel, ModelFrame, SetBlend,
};

/// What the handle-independent system is built from besides the base shape: fixed for a rest mesh.
pub struct SystemInputs {
    /// The rest mesh's frame the transforms act in (unit-free `mu`, see `ModelFrame`).
    pub frame: ModelFrame,
    pub triangles: Vec<[u32; 3]>,
    /// `#V x n_field` propagation fields in `[0, 1]`.
    pub fields: Mat<f64>,
    /// `omega_bar_i`, one per field.
    pub weights: Vec<f64>,
    /// `#V x #V` Laplacian of the rest mesh (with the method's `weights`).
    pub laplacian: SparseColMat<usize, f64>,
    /// `n_iso`, isolines per field.
    pub isolines: usize,
    /// Upper bound on the sampled crossed triangles of all isolines.
    pub max_crossed_triangles: usize,
    /// `mu` of eq 11.
    pub mu: f64,
}

/// The reduced model and its handle-independent matrices on one base shape.
pub struct HandleIndependentModel {
    pub model: IsolineModel,
    pub system: HandleIndependentSystem,
    /// `T_1` plus the constraint term of the previous handle set's regions, when the worker was told
    /// them.
    pub kept: Option<KeptConstraints>,
    /// Wall time of [`handle_independent_model`] (HIRM's `t_b`), the kept term included.
    pub seconds: f64,
    /// `kappa g g^T R_identity` (`4N x 3`) of the plane gauge (`fix_plane_gauge`) when the base
    /// shape is planar: added to the right-hand side of eq 27 by every solve on this model.
    pub plane_gauge_rhs: Option<Mat<f64>>,
}

/// `T_1 + omega^2 (Phi W)^T (Phi W)` over the constrained vertices of `regions` (lower triangle,
/// `4N x 4N`): the start of every later handle set that keeps those regions.
pub struct KeptConstraints {
    pub regions: Vec<HandleRegion>,
    pub omega: f64,
    pub lower: Mat<f64>,
}

impl KeptConstraints {
    /// Whether `handles` starts with exactly these regions (same names and vertices, in order) with
    /// the same `omega`: then its constraint term is this one plus the rows of its other regions.
    pub fn is_prefix_of(&self, handles: &HandleSet, omega: f64) -> bool {
        self.omega == omega
            && handles.regions().len() >= self.regions.len()
            && handles.regions()[..self.regions.len()] == self.regions[..]
    }
}

/// Eq 22-25 on the `#V x 3` base shape `base`, synchronously.
pub fn handle_independent_model(base: &[[f64; 3]], inputs: &SystemInputs) -> HandleIndependentModel {
    let start = Instant::now();
    let (model, mut system) = field_gauged_system(base, inputs);
    let plane_gauge_rhs = fix_plane_gauge(&mut system.smoothness_normal_matrix, &model);
    HandleIndependentModel {
        model,
        system,
        kept: None,
        seconds: start.elapsed().as_secs_f64(),
        plane_gauge_rhs,
    }
}

/// The isoline model of the `#V x 3` base shape `base` and its system (eq 22-25) with the field
/// gauge, before the plane gauge.
fn field_gauged_system(base: &[[f64; 3]], inputs: &SystemInputs) -> (IsolineModel, HandleIndependentSystem) {
    let mut model = IsolineModel::new(
        inputs.frame,
        base,
        &inputs.triangles,
        inputs.fields.as_ref(),
        &SetBlend::PerSet(inputs.weights.clone()),
        inputs.isolines,
        inputs.max_crossed_triangles,
    );
    let mut system = HandleIndependentSystem::new(&mut model, inputs.laplacian.as_ref(), inputs.mu, true);
    fix_field_gauge(&mut system.smoothness_normal_matrix, inputs.fields.ncols(), inputs.isolines);
    (model, system)
}

/// [`handle_independent_model`] and, for `kept` (the regions of the handle set before, and `omega`),
/// their constraint term on `T_1`.
pub fn handle_independent_model_keeping(
    base: &[[f64; 3]],
    inputs: &SystemInputs,
    kept: Option<(Vec<HandleRegion>, f64)>,
) -> HandleIndependentModel {
    let start = Instant::now();
    let mut out = handle_independent_model(base, inputs);
    if let Some((regions, omega)) = kept {
        let size = out.system.smoothness_normal_matrix.nrows();
        let mut lower = Mat::<f64>::zeros(size, size);
        lower.copy_from_triangular_lower(out.system.smoothness_normal_matrix.as_ref());
        let vertices = regions.iter().flat_map(|r| r.vertices.iter().copied());
        add_constraint_rows_lower(&out.model, vertices, omega, lower.as_mut());
        out.kept = Some(KeptConstraints { regions, omega, lower });
    }
    out.seconds = start.elapsed().as_secs_f64();
    out
}

/// Make `T_1` definite up to a common translation by fixing the gauge of the per-field blend.
///
/// With constant blending weights (eq 8), adding a constant affine map `c_i` to every transform of
/// field `i`, with `sum_i omega_bar_i c_i = 0`, leaves `X = W R` unchanged: eq 11 has a null space of
/// `4 (n_field - 1)` dimensions per coordinate, and `U^T U` of eq 15 is singular. We add
/// `kappa sum_{i >= 2} |mean_j r_ij - mean_j r_1j|^2`: every `R` has a gauge-equivalent one with this
/// term zero (solve for the `c_i`), so the minimizing `X` is unchanged, while the matrix becomes
/// positive definite once handles fix the translation. `kappa` = the mean diagonal of `T_1`, to keep
/// the conditioning of the matrix.
fn fix_field_gauge(normal_matrix: &mut Mat<f64>, n_field: usize, n_iso: usize) {
    let size = normal_matrix.nrows();
    debug_assert_eq!(size, 4 * n_field * n_iso);
    let kappa = (0..size).map(|i| normal_matrix[(i, i)]).sum::<f64>() / size as f64;
    let w = kappa / (n_iso * n_iso) as f64;
    for field in 1..n_field {
        for c in 0..4 {
            // g = (sum_j e_{4(field n_iso + j) + c} - sum_j e_{4 j + c}) / n_iso; add kappa g g^T.
            let entry = |set: usize, j: usize| (4 * (set * n_iso + j) + c, if set == 0 { -1.0 } else { 1.0 });
            for (p, sp) in (0..n_iso).map(|j| entry(0, j)).chain((0..n_iso).map(|j| entry(field, j))) {
                for (q, sq) in (0..n_iso).map(|j| entry(0, j)).chain((0..n_iso).map(|j| entry(field, j))) {
                    normal_matrix[(p, q)] += w * sp * sq;
                }
            }
        }
    }
}

/// Largest distance of a vertex from the base shape's best-fit plane, in RMS radii of the base,
/// at which `fix_plane_gauge` treats the base as planar.
///
/// Decision, measured on `alligator.obj` (a planar 2D mesh, z = 0) with both ends held: with
/// relief of `t` RMS radii added out of the plane, the smallest eigenvalue of `U^T U` (eq 26,
/// largest 3.2e8) is 7e-7 at `t = 1e-6` and 7e-9 at `1e-7`, and below `t = 3e-8` it is lost in
/// the rounding (|lambda| ~ 3e-10): the factorization then passes or fails by luck (it failed at
/// `t = 0` and `1e-12`, and for the mesh tilted by 30 deg at `1e-12`). 1e-6 keeps a factor 30
/// from that. On such a base the gauge only restricts the transforms' part `nu a^T`, which moves a
/// vertex by its distance from the plane (at most `t` radii) times `|a|`. A flat 4.5 x 1 strip
/// bent out of its plane (the test of `tests/hirm.rs`) with relief 1e-2 to 1e-5 (no gauge) and
/// 1e-6, 1e-7 (gauge) ends 2.4e-3 to 4.8e-3 diagonals from the flat one, with no trend in the
/// relief: that is the intrinsic Delaunay ties and isoline sampling of the regular grid, not a jump
/// at the tolerance.
pub const PLANAR_TOLERANCE: f64 = 1e-6;

/// Make `T_1` definite when the base shape is planar, by holding the common out-of-plane row of
/// the transforms at the identity's.
///
/// `W` of eq 9 applies each transform to the homogeneous base position `(x_bar_k, 1)`. When every
/// vertex of the base lies in one plane, these span only a 3-dimensional subspace of the 4
/// homogeneous coordinates, with normal `nu` ([`IsolineModel::plane_direction`]), and `W` maps the
/// part `nu a^T` of every transform to zero: `|L W R - sigma|^2` of eq 11 and the handle term of
/// eq 13 do not see it, the smoothness term `mu^2 |M R|^2` (eq 12) only asks it to be equal along
/// each field, and the field gauge ([`fix_field_gauge`]) equal across fields. The vector
/// `R = (nu, nu, ..., nu) a^T` is left: `U^T U` of eq 14-15 (eq 26) is singular however the
/// handles are placed, and its Cholesky factorization fails or passes by rounding (the failure of
/// `alligator.obj`, a flat 2D mesh: smallest eigenvalue -2.5e-10 against a largest of 3.2e8, the
/// eigenvector all in the z-row, equal over the 120 isolines).
///
/// Like the field gauge this changes no position: we add `kappa |g^T (R - R_identity)|^2` with the
/// unit `g = (nu, ..., nu) / sqrt(N)`; every `R` has a gauge-equivalent one (subtract
/// `(nu, ..., nu) a^T`, which `W` does not see) with this term zero, so the minimizing `X = W R`
/// is unchanged, while the matrix becomes positive definite. Decision: the row is held at the
/// identity's (`R_identity`, which reproduces the base), not at zero, so a base that is planar
/// only to [`PLANAR_TOLERANCE`] keeps its relief and stays a fixed point of eq 20. `kappa` = the
/// mean diagonal of `T_1` (as in [`fix_field_gauge`]). Returns the right-hand side term
/// `kappa g g^T R_identity` (`4N x 3`) to add to eq 27, or `None` (nothing added) for a base
/// that is not planar.
fn fix_plane_gauge(normal_matrix: &mut Mat<f64>, model: &IsolineModel) -> Option<Mat<f64>> {
    let nu = model.plane_direction(PLANAR_TOLERANCE)?;
    let size = normal_matrix.nrows();
    let n_isolines = model.n_isolines();
    debug_assert_eq!(size, 4 * n_isolines);
    let kappa = (0..size).map(|i| normal_matrix[(i, i)]).sum::<f64>() / size as f64;
    let g = |row: usize| nu[row % 4] / (n_isolines as f64).sqrt();
    for q in 0..size {
        for p in 0..size {
            normal_matrix[(p, q)] += kappa * g(p) * g(q);
        }
    }
    // kappa g (g^T R_identity), one column per coordinate.
    let identity = model.identity_transforms();
    let projection: Vec<f64> = (0..3).map(|a| (0..size).map(|r| g(r) * identity[(r, a)]).sum()).collect();
    Some(Mat::from_fn(size, 3, |r, a| kappa * g(r) * projection[a]))
}

/// [`handle_independent_model`] running on a worker thread.
pub struct BackgroundPrecompute {
    worker: JoinHandle<HandleIndependentModel>,
}

impl BackgroundPrecompute {
    /// Start computing the system of `base` (`#V x 3`, moved to the worker), with the constraint
    /// term of the `kept` regions (see [`handle_independent_model_keeping`]).
    pub fn start(
        base: Vec<[f64; 3]>,
        inputs: Arc<SystemInputs>,
        kept: Option<(Vec<HandleRegion>, f64)>,
    ) -> Self {
        let worker = std::thread::spawn(move || handle_independent_model_keeping(&base, &inputs, kept));
        Self { worker }
    }

    /// Wait for the result.
    pub fn finish(self) -> Result<HandleIndependentModel, MethodError> {
        self.worker.join().map_err(|_| MethodError::Background { method: "hirm" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hirm::{Hirm, HirmParams};
    use crate::DeformationMethod;

    /// `T_1` of `base` with the field gauge only (what [`handle_independent_model`] builds before
    /// the plane gauge).
    fn field_gauged(base: &[[f64; 3]], inputs: &SystemInputs) -> (IsolineModel, Mat<f64>) {
        let (model, system) = field_gauged_system(base, inputs);
        (model, system.smoothness_normal_matrix)
    }

    fn inputs_of(mesh: &meshes::TriMesh) -> Arc<SystemInputs> {
        let mut hirm = Hirm::new(HirmParams::default()).unwrap();
        hirm.precompute(mesh).unwrap();
        hirm.system_inputs().unwrap()
    }

    /// The plane gauge adds `kappa g g^T` and `kappa g g^T R_identity`: its term
    /// `kappa |g^T (R - R_identity)|^2` is zero at the identity transforms, so the base shape stays
    /// the fixed point; and nothing is added for a base that is not planar.
    #[test]
    fn the_plane_gauge_holds_the_out_of_plane_row_at_the_identity_and_only_on_planar_bases() {
        let (nx, ny) = (31, 9);
        let positions: Vec<[f64; 3]> =
            (0..ny).flat_map(|j| (0..nx).map(move |i| [i as f64 * 0.1, j as f64 * 0.1, 0.0])).collect();
        let id = |i: usize, j: usize| (j * nx + i) as u32;
        let triangles: Vec<[u32; 3]> = (0..ny - 1)
            .flat_map(|j| {
                (0..nx - 1).flat_map(move |i| {
                    [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]]
                })
            })
            .collect();
        let flat = meshes::TriMesh::new(positions, triangles).unwrap();
        let inputs = inputs_of(&flat);
        let (model, before) = field_gauged(flat.positions(), &inputs);
        let mut after = before.clone();
        let rhs = fix_plane_gauge(&mut after, &model).expect("a flat grid is planar");
        let added = &after - &before;
        let at_identity = &added * model.identity_transforms();
        let scale = rhs.norm_max();
        assert!(scale > 0.0);
        assert!((&at_identity - &rhs).norm_max() <= 1e-12 * scale, "gauge term not zero at the identity");
        // Rank one along (nu, ..., nu) with nu = e_z here: only the z rows of the transforms.
        for p in 0..added.nrows() {
            for q in 0..added.ncols() {
                if p % 4 != 2 || q % 4 != 2 {
                    assert_eq!(added[(p, q)], 0.0, "({p}, {q})");
                }
            }
        }
        let built = handle_independent_model(flat.positions(), &inputs);
        assert_eq!(built.system.smoothness_normal_matrix, after);
        assert_eq!(built.plane_gauge_rhs.as_ref(), Some(&rhs));

        // The same grid, bent out of its plane: no gauge, T_1 as before.
        let bent: Vec<[f64; 3]> = flat.positions().iter().map(|p| [p[0], p[1], 0.1 * p[0] * p[0]]).collect();
        let built = handle_independent_model(&bent, &inputs);
        assert!(built.plane_gauge_rhs.is_none());
        assert_eq!(built.system.smoothness_normal_matrix, field_gauged(&bent, &inputs).1);
    }
}
