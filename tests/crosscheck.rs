//! Cross-checks against libigl on the survey meshes (run by `scripts/test`, which installs the pinned
//! Python packages): operators to 1e-10 relative, ARAP to RMS distance <= 1e-3 of the bbox diagonal.

mod support;

use std::collections::HashMap;

use methods::operators::{cotan_laplacian, lumped_mass, MassKind};
use methods::NoObserver;
use support::{igl_reference, python, read_rows, survey_case, survey_dir};

const MESHES: [&str; 4] = ["cylinder", "bar", "cactus", "plane"];

/// Relative comparison of two sparse matrices given as maps: entries of at least 1e-4 of the largest
/// are compared relatively; smaller ones are sums of cotangents that cancel (near-right angles on the
/// grid-like plane), where either side's rounding is ~1e-16 of the terms, so they are compared
/// against the largest entry.
fn sparse_relative_error(ours: &HashMap<(usize, usize), f64>, theirs: &HashMap<(usize, usize), f64>) -> f64 {
    let scale = theirs.values().fold(0.0f64, |m, v| m.max(v.abs()));
    let keys: std::collections::HashSet<_> = ours.keys().chain(theirs.keys()).collect();
    keys.into_iter()
        .map(|k| {
            let a = ours.get(k).copied().unwrap_or(0.0);
            let b = theirs.get(k).copied().unwrap_or(0.0);
            (a - b).abs() / b.abs().max(1e-4 * scale)
        })
        .fold(0.0, f64::max)
}

#[test]
fn cotan_laplacian_and_mass_match_libigl() {
    let (Some(dir), Some(py)) = (survey_dir(), python()) else { return };
    for name in MESHES {
        let mesh_path = dir.join(format!("{name}.off"));
        let mesh = meshes::io::read_mesh(&mesh_path).unwrap();
        let out = tempfile::tempdir().unwrap();
        igl_reference(&py, &["operators", mesh_path.to_str().unwrap(), out.path().to_str().unwrap()]);

        let theirs: HashMap<(usize, usize), f64> = read_rows(&out.path().join("cotmatrix.txt"))
            .into_iter()
            .map(|r| ((r[0] as usize, r[1] as usize), r[2]))
            .collect();
        let l = cotan_laplacian(mesh.positions(), mesh.triangles());
        let (sym, val) = l.parts();
        let mut ours = HashMap::new();
        for j in 0..sym.ncols() {
            for idx in sym.col_range(j) {
                ours.insert((sym.row_idx()[idx], j), val[idx]);
            }
        }
        let err_l = sparse_relative_error(&ours, &theirs);
        println!("{name}: cotmatrix max relative error {err_l:.2e}");
        assert!(err_l <= 1e-10, "{name}: cotan Laplacian differs from igl::cotmatrix by {err_l:e}");

        for (kind, file) in
            [(MassKind::Voronoi, "mass_voronoi.txt"), (MassKind::Barycentric, "mass_barycentric.txt")]
        {
            let theirs: Vec<f64> = read_rows(&out.path().join(file)).into_iter().map(|r| r[0]).collect();
            let ours = lumped_mass(mesh.positions(), mesh.triangles(), kind);
            assert_eq!(ours.len(), theirs.len());
            let err = ours.iter().zip(&theirs).map(|(a, b)| (a - b).abs() / b.abs()).fold(0.0, f64::max);
            println!("{name}: {kind:?} mass max relative error {err:.2e}");
            assert!(err <= 1e-10, "{name}: {kind:?} mass differs from igl::massmatrix by {err:e}");
        }
    }
}

#[test]
fn arap_matches_libigl_arap_solve() {
    let (Some(dir), Some(py)) = (survey_dir(), python()) else { return };
    for name in ["cylinder", "bar", "cactus"] {
        let (mesh, handles, targets) = survey_case(&dir, name);
        let work = tempfile::tempdir().unwrap();
        let constraints = work.path().join("constraints.txt");
        let lines: String = handles
            .constrained()
            .zip(targets.positions())
            .map(|(v, t)| format!("{v} {:e} {:e} {:e}\n", t[0], t[1], t[2]))
            .collect();
        std::fs::write(&constraints, lines).unwrap();
        let mesh_path = dir.join(format!("{name}.off"));
        for iterations in [10usize, 100] {
            let out = work.path().join(format!("arap{iterations}.txt"));
            igl_reference(
                &py,
                &[
                    "arap",
                    mesh_path.to_str().unwrap(),
                    constraints.to_str().unwrap(),
                    &iterations.to_string(),
                    out.to_str().unwrap(),
                ],
            );
            let theirs: Vec<[f64; 3]> = read_rows(&out).into_iter().map(|r| [r[0], r[1], r[2]]).collect();
            let params: toml::Table =
                format!("max_iterations = {iterations}\ntolerance = 0.0").parse().unwrap();
            let mut arap = methods::registry::create("arap", &params).unwrap();
            arap.precompute(&mesh).unwrap();
            arap.bind_handles(&handles).unwrap();
            let summary = arap.solve(&targets, &mut NoObserver).unwrap();
            assert_eq!(summary.iterations, iterations);
            let ours = arap.positions();
            let rms = harness::metrics::rms_distance(&ours, &theirs, mesh.bbox_diagonal());
            println!("{name}: {iterations} iterations, RMS distance to libigl / bbox diagonal = {rms:.2e}");
            assert!(
                rms <= 1e-3,
                "{name}: arap after {iterations} iterations is {rms:e} x diagonal from libigl's"
            );
        }
    }
}

/// Largest sine of the principal angles between span(ours) and span(reference), both D-orthonormal
/// (`#V` rows), in the D inner product.
fn largest_angle_sine(ours: &faer::Mat<f64>, reference: &faer::Mat<f64>, mass: &[f64]) -> f64 {
    let n = ours.nrows();
    let d_ref = faer::Mat::from_fn(n, reference.ncols(), |i, j| mass[i] * reference[(i, j)]);
    let residual = ours - reference * (d_ref.transpose() * ours);
    let d_res = faer::Mat::from_fn(n, residual.ncols(), |i, j| mass[i] * residual[(i, j)]);
    let gram = residual.transpose() * &d_res;
    let top = gram.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
    top.last().copied().unwrap_or(0.0).max(0.0).sqrt()
}

#[test]
fn manifold_harmonics_match_scipy_eigsh() {
    let (Some(dir), Some(py)) = (survey_dir(), python()) else { return };
    // scipy computes a few more pairs so that a cluster cut at k is still compared with its full span.
    const EXTRA: usize = 8;
    for name in MESHES {
        let mesh_path = dir.join(format!("{name}.off"));
        let mesh = meshes::io::read_mesh(&mesh_path).unwrap();
        let mut stiffness = cotan_laplacian(mesh.positions(), mesh.triangles());
        stiffness.val_mut().iter_mut().for_each(|v| *v = -*v);
        let mass = lumped_mass(mesh.positions(), mesh.triangles(), MassKind::Barycentric);
        for k in [20usize, 100] {
            let work = tempfile::tempdir().unwrap();
            let out = work.path().join("eigs.txt");
            igl_reference(
                &py,
                &[
                    "eigs",
                    mesh_path.to_str().unwrap(),
                    &(k + EXTRA).to_string(),
                    out.to_str().unwrap(),
                    "--mass",
                    "barycentric",
                ],
            );
            let values: Vec<f64> = read_rows(&out).into_iter().map(|r| r[0]).collect();
            let rows = read_rows(&out.with_extension("txt.vectors"));
            let reference = faer::Mat::from_fn(rows.len(), k + EXTRA, |i, j| rows[i][j]);
            let ours = methods::spectral::smallest_eigenpairs(
                stiffness.as_ref(),
                &mass,
                &methods::spectral::EigenOptions::new(k),
            )
            .unwrap();
            assert_eq!(ours.constant_mode, Some(0), "{name}: constant mode not flagged");
            let scale = values[k - 1];
            let worst_value = (0..k)
                .map(|i| (ours.values[i] - values[i]).abs() / values[i].abs().max(1e-3 * scale))
                .fold(0.0, f64::max);
            // Clusters: eigenvalues closer than 1e-4 of the scale have ill-determined single vectors.
            let mut worst_angle = 0.0f64;
            let mut start = 0;
            for i in 1..=k {
                if i < k && (ours.values[i] - ours.values[i - 1]).abs() <= 1e-4 * scale {
                    continue;
                }
                let (lo, hi) = (ours.values[start] - 1e-4 * scale, ours.values[i - 1] + 1e-4 * scale);
                let span: Vec<usize> =
                    (0..k + EXTRA).filter(|&j| values[j] >= lo && values[j] <= hi).collect();
                let a = faer::Mat::from_fn(mass.len(), i - start, |r, c| ours.vectors[(r, start + c)]);
                let b = faer::Mat::from_fn(mass.len(), span.len(), |r, c| reference[(r, span[c])]);
                worst_angle = worst_angle.max(largest_angle_sine(&a, &b, &mass).asin());
                start = i;
            }
            println!(
                "{name}, k = {k}: eigenvalues max relative difference {worst_value:.2e}, largest principal angle {worst_angle:.2e}"
            );
            assert!(worst_value <= 1e-8, "{name}, k = {k}: eigenvalues differ from scipy by {worst_value:e}");
            assert!(worst_angle < 1e-6, "{name}, k = {k}: principal angle {worst_angle:e}");
        }
    }
}
