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
    HandleIndependentModel { model, system, kept: None, seconds: start.elapsed().as_secs_f64() }
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
