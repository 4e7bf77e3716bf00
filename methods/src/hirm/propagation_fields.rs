//! Propagation fields (Wu et al. 2015, section 4.1) and their blending weights (section 4.3).
//!
//! The fields are the first non-constant eigenvectors of the Laplacian of the rest mesh,
//! `Q e = lambda D e` with `Q = -L` and the barycentric lumped mass `D` (the manifold harmonics of
//! [`crate::linalg::spectral`]), selected by the score `S_i = sqrt(lambda_i / lambda_2) < phi` (eq 1-2).
//!
//! Decisions:
//! - Eigenvectors are `D`-orthonormal, so the spectral coefficients of eq 7 are the manifold
//!   harmonics transform `xi_i = X^T D e_i` (the paper writes `X . e_i` for an orthonormal basis).
//! - For isoline sampling each field is rescaled affinely to `[0, 1]` (min to 0, max to 1); the
//!   weights use the unscaled eigenvectors.

use faer::sparse::SparseColMat;
use faer::Mat;

use crate::error::MethodError;
use crate::linalg::spectral::{smallest_eigenpairs, transform, EigenOptions};
use crate::operators::{lumped_mass, MassKind};

/// The selected fields of a rest mesh.
#[derive(Clone, Debug)]
pub struct PropagationFields {
    /// The eigenvalues computed to make the selection, ascending, `lambda_1 = 0` first.
    pub eigenvalues: Vec<f64>,
    /// `S_i` of the selected fields `e_2 .. e_{n_field + 1}`.
    pub scores: Vec<f64>,
    /// `#V x n_field`: the selected eigenvectors rescaled to `[0, 1]`.
    pub fields: Mat<f64>,
    /// `omega_bar_i` (eq 7-8), `n_field` weights summing to 1.
    pub weights: Vec<f64>,
    /// Whether more eigenvectors than `max_fields` had scores below the threshold.
    pub capped: bool,
}

/// Eq 1-2: the number of eigenvectors `e_2, e_3, ...` with `S_i = sqrt(lambda_i / lambda_2) <
/// threshold`, for `eigenvalues` ascending with the constant mode's `lambda_1 = 0` first. At least
/// 1 (`S_2 = 1`) when `threshold > 1`. `None` when `lambda_2` is not positive (a disconnected mesh).
pub fn select_fields(eigenvalues: &[f64], threshold: f64) -> Option<usize> {
    let lambda_2 = *eigenvalues.get(1)?;
    if !(lambda_2 > 0.0) {
        return None;
    }
    Some(eigenvalues[1..].iter().take_while(|&&l| (l / lambda_2).sqrt() < threshold).count())
}

/// The propagation fields of the rest mesh (`#V x 3` positions, triangles, and its `#V x #V`
/// cotangent Laplacian `laplacian`, barycentric mass): eigenpairs are computed in growing batches
/// until one scores at or above `threshold`, or `max_fields` fields are found. `seed` seeds the
/// eigensolver's start vectors.
pub fn propagation_fields(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    laplacian: &SparseColMat<usize, f64>,
    threshold: f64,
    max_fields: usize,
    seed: u64,
) -> Result<PropagationFields, MethodError> {
    let mass = lumped_mass(positions, triangles, MassKind::Barycentric);
    propagation_fields_at_least(positions, &mass, laplacian, threshold, 1, max_fields, seed)
}

/// [`propagation_fields`] with at least `min_fields` fields (capped by `max_fields` and the mesh
/// size), the next eigenvectors in order when fewer score below `threshold`: the remedy of Wu et
/// al.'s section 5 for handles too close for the selected fields to tell apart.
/// `mass` is the `#V` lumped mass that goes with `laplacian`.
pub fn propagation_fields_at_least(
    positions: &[[f64; 3]],
    mass: &[f64],
    laplacian: &SparseColMat<usize, f64>,
    threshold: f64,
    min_fields: usize,
    max_fields: usize,
    seed: u64,
) -> Result<PropagationFields, MethodError> {
    let n = positions.len();
    let stiffness = crate::operators::stiffness(laplacian.clone());
    let wanted = (max_fields + 1).min(n);
    let floor = (min_fields.min(max_fields) + 1).min(n);
    let mut count = 16.max(floor).min(wanted);
    let pairs = loop {
        let mut options = EigenOptions::new(count);
        options.seed = seed;
        let pairs = smallest_eigenpairs(stiffness.as_ref(), mass, &options).map_err(MethodError::Eigen)?;
        let selected = select_fields(&pairs.values, threshold).ok_or_else(|| {
            MethodError::Mesh(meshes::MeshError::Invalid(format!(
                "second Laplacian eigenvalue {:e} is not positive: the mesh is not connected",
                pairs.values.get(1).copied().unwrap_or(f64::NAN)
            )))
        })?;
        if (selected + 1 < count && count >= floor) || count == wanted {
            break pairs;
        }
        count = (2 * count).min(wanted);
    };
    let available = select_fields(&pairs.values, threshold).expect("checked in the loop");
    let n_field = available.max(min_fields).min(max_fields).min(pairs.values.len() - 1);
    let lambda_2 = pairs.values[1];
    let scores = pairs.values[1..=n_field].iter().map(|l| (l / lambda_2).sqrt()).collect();
    let selected = pairs.vectors.as_ref().subcols(1, n_field);
    let ranges: Vec<(f64, f64)> = (0..n_field)
        .map(|i| {
            let col = selected.col(i);
            (0..n).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| (lo.min(col[r]), hi.max(col[r])))
        })
        .collect();
    let fields =
        Mat::from_fn(n, n_field, |k, i| (selected[(k, i)] - ranges[i].0) / (ranges[i].1 - ranges[i].0));
    // Eq 7: omega_i = |(xi_x,i, xi_y,i, xi_z,i)|, normalized to sum 1 (eq 8).
    let x = Mat::from_fn(n, 3, |k, a| positions[k][a]);
    let xi = transform(selected, mass, x.as_ref());
    let importance: Vec<f64> =
        (0..n_field).map(|i| (0..3).map(|a| xi[(i, a)] * xi[(i, a)]).sum::<f64>().sqrt()).collect();
    let total: f64 = importance.iter().sum();
    if !(total > 0.0) {
        return Err(MethodError::Mesh(meshes::MeshError::Invalid(
            "the propagation fields have zero spectral coefficients".into(),
        )));
    }
    let weights = importance.iter().map(|w| w / total).collect();
    Ok(PropagationFields {
        eigenvalues: pairs.values,
        scores,
        fields,
        weights,
        capped: available > max_fields,
    })
}
