//! Cross-checks against libigl on the survey meshes (run by `scripts/test`, which installs the pinned
//! Python packages; without `$DEFORM_SURVEY_DIR` on the procedural look-alikes at the survey's sizes,
//! written as the same files, with the same tolerances: `support::survey_meshes`): operators (also the intrinsic Delaunay Laplacian, on the real meshes too when
//! `$DEFORM_REAL_MESHES_DIR` is set; and the tufted Laplacian against robust-laplacian) to 1e-10 relative, ARAP to RMS distance <= 1e-3 of the bbox
//! diagonal.

mod support;

use std::collections::HashMap;

use methods::operators::{
    cotan_laplacian, lumped_mass, IntrinsicTriangulation, MassKind, TuftedDelaunay, MOLLIFY_FACTOR,
};
use methods::NoObserver;
use support::{igl_reference, python, read_rows, survey_case, survey_meshes};

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
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
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

/// Our stored entries of `l` as a map.
fn entry_map(l: &faer::sparse::SparseColMat<usize, f64>) -> HashMap<(usize, usize), f64> {
    let (sym, val) = l.parts();
    let mut map = HashMap::new();
    for j in 0..sym.ncols() {
        for idx in sym.col_range(j) {
            *map.entry((sym.row_idx()[idx], j)).or_insert(0.0) += val[idx];
        }
    }
    map
}

#[test]
fn intrinsic_delaunay_laplacian_matches_libigl() {
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    let mut paths: Vec<std::path::PathBuf> = MESHES.iter().map(|n| dir.join(format!("{n}.off"))).collect();
    // The real meshes only when named (scripts/test sets the variable).
    if let Some(real) = std::env::var_os("DEFORM_REAL_MESHES_DIR").and_then(|_| support::real_meshes_dir()) {
        paths.extend(["decimated-knight.off", "bunny.off"].map(|f| real.join(f)));
    }
    for mesh_path in paths {
        let mesh = meshes::io::read_mesh(&mesh_path).unwrap();
        let out = tempfile::tempdir().unwrap();
        igl_reference(
            &py,
            &["intrinsic_delaunay", mesh_path.to_str().unwrap(), out.path().to_str().unwrap()],
        );
        let theirs: HashMap<(usize, usize), f64> =
            read_rows(&out.path().join("intrinsic_delaunay_cotmatrix.txt"))
                .into_iter()
                .map(|r| ((r[0] as usize, r[1] as usize), r[2]))
                .collect();
        let t = IntrinsicTriangulation::delaunay(mesh.positions(), mesh.triangles()).unwrap();
        let ours = entry_map(&t.cotan_laplacian());
        let err = sparse_relative_error(&ours, &theirs);
        let name = mesh_path.file_name().unwrap().to_string_lossy();
        println!("{name}: {} flips, intrinsic_delaunay_cotmatrix max relative error {err:.2e}", t.flips());
        assert!(err <= 1e-10, "{name}: intrinsic Delaunay Laplacian differs from libigl's by {err:e}");
    }
}

/// The tufted Laplacian (our default weights) against robust-laplacian's `mesh_laplacian` with
/// `mollify_factor = 0` (Sharp & Crane 2020's implementation in geometry-central), on the survey
/// meshes (bar and plane are open), the real meshes and, with `$DEFORM_DATASET_DIR`, open dataset
/// meshes whose plain intrinsic Delaunay weights are negative on the boundary. No mesh here needs
/// mollification (ours reports `eps = 0`, so the default factor leaves the lengths as they are).
/// robust-laplacian leaves an edge unflipped while `(cot a + cot b) / 2 >= -1e-6` (geometry-central's
/// `delaunayEPS`), ours down to `-0.5e-14`: at its tolerance the matrices agree to rounding; at ours
/// they differ where robust-laplacian keeps small negative weights (the survey plane: 1388).
#[test]
fn tufted_laplacian_matches_robust_laplacian() {
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    let mut paths: Vec<std::path::PathBuf> = MESHES.iter().map(|n| dir.join(format!("{n}.off"))).collect();
    if let Some(real) = std::env::var_os("DEFORM_REAL_MESHES_DIR").and_then(|_| support::real_meshes_dir()) {
        paths.extend(["decimated-knight.off", "bunny.off"].map(|f| real.join(f)));
    }
    if let Some(dataset) = std::env::var_os("DEFORM_DATASET_DIR").and_then(|_| support::dataset_dir()) {
        paths.extend(["manysmallholes.obj", "alligator.obj", "africanhead.obj"].map(|f| dataset.join(f)));
    }
    for mesh_path in paths {
        let mesh = meshes::io::read_mesh(&mesh_path).unwrap();
        let out = tempfile::tempdir().unwrap();
        igl_reference(&py, &["tufted", mesh_path.to_str().unwrap(), out.path().to_str().unwrap()]);
        let theirs: HashMap<(usize, usize), f64> = read_rows(&out.path().join("tufted_laplacian.txt"))
            .into_iter()
            .map(|r| ((r[0] as usize, r[1] as usize), r[2]))
            .collect();
        let t = TuftedDelaunay::new(mesh.positions(), mesh.triangles(), MOLLIFY_FACTOR).unwrap();
        assert_eq!(t.mollification(), 0.0);
        let default = sparse_relative_error(&entry_map(&t.cotan_laplacian()), &theirs);
        // robust-laplacian flips only below its `delaunayEPS`: the same tolerance here.
        let same =
            TuftedDelaunay::with_flip_tolerance(mesh.positions(), mesh.triangles(), 0.0, 2e-6).unwrap();
        let err = sparse_relative_error(&entry_map(&same.cotan_laplacian()), &theirs);
        let name = mesh_path.file_name().unwrap().to_string_lossy();
        let scale = theirs.values().fold(0.0f64, |m, v| m.max(v.abs()));
        let their_negative = theirs.iter().filter(|(k, v)| k.0 != k.1 && **v < -1e-12 * scale).count();
        println!(
            "{name}: {} cover flips, tufted Laplacian max relative error {err:.2e} at robust-laplacian's \
             flip tolerance, {default:.2e} at ours (robust-laplacian weights below -1e-12 x largest: \
             {their_negative}, ours: 0)",
            t.cover().flips()
        );
        assert!(err <= 1e-10, "{name}: tufted Laplacian differs from robust-laplacian's by {err:e}");
        if their_negative == 0 {
            assert!(
                default <= 1e-10,
                "{name}: tufted Laplacian differs from robust-laplacian's by {default:e}"
            );
        }
        // The barycentric lumped mass of an intrinsic triangulation depends on how cocircular quads
        // are split, which the flip order decides (the cotan weights do not), so per vertex it is
        // only reported; the totals (the surface's area) agree.
        let theirs: Vec<f64> =
            read_rows(&out.path().join("tufted_mass.txt")).into_iter().map(|r| r[0]).collect();
        let ours = t.lumped_mass(MassKind::Barycentric);
        assert_eq!(ours.len(), theirs.len());
        let per_vertex = ours.iter().zip(&theirs).map(|(a, b)| (a - b).abs() / b.abs()).fold(0.0, f64::max);
        let (a, b) = (ours.iter().sum::<f64>(), theirs.iter().sum::<f64>());
        println!(
            "{name}: tufted mass: totals {:.1e} apart, per vertex up to {per_vertex:.1e}",
            (a - b).abs() / b
        );
        assert!((a - b).abs() <= 1e-10 * b, "{name}: tufted mass total {a} vs robust-laplacian's {b}");
    }
}

#[test]
fn arap_matches_libigl_arap_solve() {
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    for name in ["cylinder", "bar", "cactus"] {
        let case = ArapCase::new(&dir, name);
        for iterations in [10usize, 100] {
            let theirs = case.libigl_arap(&py, iterations);
            let ours = case.our_arap(iterations);
            let rms = harness::metrics::rms_distance(&ours, &theirs, case.mesh.bbox_diagonal());
            let exact = case.float64_arap(&py, iterations);
            let to_exact = max_vertex_distance(&ours, &exact) / case.mesh.bbox_diagonal();
            println!(
                "{name}: {iterations} iterations, RMS distance to libigl / bbox diagonal = {rms:.2e}, \
                 max distance to the float64 SPOKES reference {to_exact:.2e}"
            );
            assert!(
                rms <= 1e-3,
                "{name}: arap after {iterations} iterations is {rms:e} x diagonal from libigl's"
            );
            // The same iteration in double precision (igl_reference.py `arap_float64`): ours must
            // agree to rounding (measured <= 2.1e-12 on the survey meshes and the look-alikes), so what remains
            // against libigl is libigl's single-precision rotation fit.
            assert!(to_exact <= 1e-10, "{name}: {to_exact:e} x diagonal from the float64 reference");
        }
    }
}

/// A survey edit for the ARAP comparisons, with its constraints written in the `index x y z` format of
/// igl_reference.py `arap` and peers_reference.py `open3d_arap`, in a scratch directory.
struct ArapCase {
    mesh: meshes::TriMesh,
    handles: methods::HandleSet,
    targets: methods::HandleTargets,
    work: tempfile::TempDir,
    constraints: std::path::PathBuf,
    mesh_path: std::path::PathBuf,
}

impl ArapCase {
    fn new(dir: &std::path::Path, name: &str) -> Self {
        let (mesh, handles, targets) = survey_case(dir, name);
        let work = tempfile::tempdir().unwrap();
        let constraints = work.path().join("constraints.txt");
        let lines: String = handles
            .constrained()
            .zip(targets.positions())
            .map(|(v, t)| format!("{v} {:e} {:e} {:e}\n", t[0], t[1], t[2]))
            .collect();
        std::fs::write(&constraints, lines).unwrap();
        let mesh_path = dir.join(format!("{name}.off"));
        Self { mesh, handles, targets, work, constraints, mesh_path }
    }

    /// libigl's `arap_solve` after `iterations` iterations (igl_reference.py `arap`), `#V x 3`.
    fn libigl_arap(&self, python: &std::path::Path, iterations: usize) -> Vec<[f64; 3]> {
        self.reference_arap(python, "arap", iterations)
    }

    /// The same SPOKES iteration as libigl's in float64 numpy (igl_reference.py `arap_float64`),
    /// `#V x 3`.
    fn float64_arap(&self, python: &std::path::Path, iterations: usize) -> Vec<[f64; 3]> {
        self.reference_arap(python, "arap_float64", iterations)
    }

    /// igl_reference.py's ARAP `command` on this case after `iterations` iterations, `#V x 3`.
    fn reference_arap(&self, python: &std::path::Path, command: &str, iterations: usize) -> Vec<[f64; 3]> {
        let out = self.work.path().join(format!("{command}-{iterations}.txt"));
        igl_reference(
            python,
            &[
                command,
                self.mesh_path.to_str().unwrap(),
                self.constraints.to_str().unwrap(),
                &iterations.to_string(),
                out.to_str().unwrap(),
            ],
        );
        read_rows(&out).into_iter().map(|r| [r[0], r[1], r[2]]).collect()
    }

    /// Our `arap` after exactly `iterations` iterations (no early exit), from the rest shape.
    fn our_arap(&self, iterations: usize) -> Vec<[f64; 3]> {
        // libigl's arap uses the mesh's cotangent weights and the plain local/global iteration.
        let params: toml::Table = format!(
            "max_iterations = {iterations}\ntolerance = 0.0\nweights = \"cotan\"\nsolver = \"local_global\"\n\
             acceleration = \"none\"\nstart = \"current\""
        )
        .parse()
        .unwrap();
        let mut arap = methods::registry::create("arap", &params).unwrap();
        arap.precompute(&self.mesh).unwrap();
        arap.bind_handles(&self.handles).unwrap();
        let summary = arap.solve(&self.targets, &mut NoObserver).unwrap();
        assert_eq!(summary.iterations, iterations);
        arap.positions()
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
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
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
            let ours = methods::linalg::spectral::smallest_eigenpairs(
                stiffness.as_ref(),
                &mass,
                &methods::linalg::spectral::EigenOptions::new(k),
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

// ---------------------------------------------------------------------------------------------------
// Peer cross-checks with pymeshlab and open3d (tests/crosscheck/peers_reference.py).

use support::peers_reference;

/// Largest vertex distance between two `#V x 3` arrays.
fn max_vertex_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt())
        .fold(0.0, f64::max)
}

fn json_f64(v: &serde_json::Value, path: &[&str]) -> f64 {
    let mut cur = v;
    for key in path {
        cur = &cur[*key];
    }
    cur.as_f64().unwrap_or_else(|| panic!("no number at {path:?} in {v}"))
}

/// Our corner angles and face areas against pymeshlab's (per-face quality filters, evaluated by MeshLab
/// in double precision; see peers_reference.py `face_measures`). Both evaluate
/// atan2(|e1 x e2|, e1 . e2) and |e1 x e2| / 2 in f64, so they agree to rounding: measured max
/// |angle difference| 2.2e-16 rad (cactus; 0 on cylinder and bar, 1.1e-16 on plane), max relative
/// area difference 0 on all four. Bound 1e-12 (rad, relative): a few thousand ulps, far below any
/// real difference in formula, corner order or vertex indexing.
#[test]
fn peers_corner_angles_and_face_areas_match_pymeshlab() {
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    for name in MESHES {
        let mesh_path = dir.join(format!("{name}.off"));
        let mesh = meshes::io::read_mesh(&mesh_path).unwrap();
        let out = tempfile::tempdir().unwrap();
        peers_reference(&py, &["face_measures", mesh_path.to_str().unwrap(), out.path().to_str().unwrap()]);

        // Same faces, in the same order and with the same corner order, or nothing below is comparable.
        let faces: Vec<[u32; 3]> = read_rows(&out.path().join("faces.txt"))
            .into_iter()
            .map(|r| [r[0] as u32, r[1] as u32, r[2] as u32])
            .collect();
        assert_eq!(faces, mesh.triangles(), "{name}: pymeshlab's faces differ from the file's");

        let theirs_angles = read_rows(&out.path().join("angles.txt"));
        let theirs_areas: Vec<f64> =
            read_rows(&out.path().join("areas.txt")).into_iter().map(|r| r[0]).collect();
        let ours_angles = meshes::geometry::corner_angles(mesh.positions(), mesh.triangles());
        let ours_areas = meshes::geometry::face_areas(mesh.positions(), mesh.triangles());
        assert_eq!(theirs_angles.len(), ours_angles.len());
        assert_eq!(theirs_areas.len(), ours_areas.len());
        let angle_err = ours_angles
            .iter()
            .zip(&theirs_angles)
            .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0, f64::max);
        let area_err =
            ours_areas.iter().zip(&theirs_areas).map(|(a, b)| (a - b).abs() / b.abs()).fold(0.0, f64::max);
        println!("{name}: corner angles max abs difference {angle_err:.2e} rad, face areas max relative difference {area_err:.2e}");
        assert!(angle_err <= 1e-12, "{name}: corner angles differ from pymeshlab's by {angle_err:e} rad");
        assert!(area_err <= 1e-12, "{name}: face areas differ from pymeshlab's by {area_err:e} (relative)");
    }
}

/// Survey edits and iteration counts of the ARAP peer checks. The plane (40K vertices) only at 10
/// iterations: 100 would take libigl 12 s and open3d 26 s (0.26 s per open3d iteration).
const ARAP_CASES: [(&str, &[usize]); 4] =
    [("cylinder", &[10, 100]), ("bar", &[10, 100]), ("cactus", &[10, 100]), ("plane", &[10])];

/// Symmetric Hausdorff distance (pymeshlab) between our `arap` and libigl's SPOKES ARAP surfaces on the
/// survey edits, same constraints and iteration counts as `arap_matches_libigl_arap_solve`.
///
/// Measured (Hausdorff / bbox diagonal at 10 and 100 iterations): cylinder 2.9e-5, 4.4e-5; bar
/// 1.0e-5, 1.6e-5; cactus 5.4e-6, 3.5e-5; plane (10 only) 6.2e-4. The gap is libigl's: its rotation
/// fit is single precision (igl_reference.py's docstring) and grows over the iterations. On the plane's
/// flat one-rings the covariances are nearly rank 2, which the float SVD resolves worst: a
/// double-precision numpy SPOKES ARAP (written while setting this test up; it matches ours) is as far
/// from libigl there, 6.2e-4 max vertex distance / diagonal after 10 iterations (7.7e-3 after 100).
/// Bounds: 1e-4 of the diagonal (2.3x the largest figure) on the three 5-6K-vertex meshes, 1e-3 (the
/// RMS bound of the libigl test; 1.6x) on the plane. Also asserted: Hausdorff <= max vertex distance.
///
/// On the procedural look-alikes (no survey data, issue 60), measured: cylinder 4.2e-5, 2.5e-5; bar
/// 1.5e-4, 1.2e-5; cactus 7.4e-6, 6.4e-5; plane 6.2e-4. The bar after 10 iterations is the one figure
/// over 1e-4, at the bar's edges, and it is libigl's: the float64 numpy SPOKES iteration
/// (`arap_float64`) is 1.5e-4 from libigl there and 1.4e-13 from ours. So the bar of the look-alikes
/// gets the plane's 1e-3 (6.6x its figure); every other bound is the survey's.
#[test]
fn peers_arap_hausdorff_distance_to_libigl_arap_is_small() {
    let Some(py) = python() else { return };
    let support::SurveyMeshes { dir, source } = survey_meshes();
    for (name, iteration_counts) in ARAP_CASES {
        let case = ArapCase::new(&dir, name);
        let (mesh, work) = (&case.mesh, case.work.path());
        let diagonal = mesh.bbox_diagonal();
        for &iterations in iteration_counts {
            let theirs = case.libigl_arap(&py, iterations);
            let ours = case.our_arap(iterations);
            let ours_off = work.join(format!("ours{iterations}.off"));
            let theirs_off = work.join(format!("igl{iterations}.off"));
            meshes::io::write_off(&ours_off, &mesh.with_positions(ours.clone()).unwrap()).unwrap();
            meshes::io::write_off(&theirs_off, &mesh.with_positions(theirs.clone()).unwrap()).unwrap();
            let report: serde_json::Value = serde_json::from_str(&peers_reference(
                &py,
                &["hausdorff", ours_off.to_str().unwrap(), theirs_off.to_str().unwrap()],
            ))
            .unwrap();
            let hausdorff = json_f64(&report, &["hausdorff"]) / diagonal;
            let max_vertex = max_vertex_distance(&ours, &theirs) / diagonal;
            println!(
                "{name}: {iterations} iterations, Hausdorff(ours, libigl) / bbox diagonal = {hausdorff:.2e} (ours->libigl {:.2e}, libigl->ours {:.2e}), max vertex distance / diagonal = {max_vertex:.2e}",
                json_f64(&report, &["a_to_b", "max"]) / diagonal,
                json_f64(&report, &["b_to_a", "max"]) / diagonal,
            );
            // Same connectivity, so every point of one surface has a point of the other within the
            // largest vertex distance: pymeshlab's figure cannot exceed it (slack for its
            // single-precision rounding of the result).
            assert!(
                hausdorff <= max_vertex * (1.0 + 1e-6) + 1e-9,
                "{name}: Hausdorff {hausdorff:e} exceeds the max vertex distance {max_vertex:e}"
            );
            let look_alike_bar = name == "bar" && source == support::SurveySource::LookAlikes;
            let bound = if name == "plane" || look_alike_bar { 1e-3 } else { 1e-4 };
            assert!(
                hausdorff <= bound,
                "{name}: after {iterations} iterations ours is {hausdorff:e} x diagonal from libigl's surface"
            );
        }
    }
}

/// open3d's `deform_as_rigid_as_possible` (energy Spokes) against our `arap`, same constraints, same
/// iteration count, both from the rest shape.
///
/// open3d 0.20 (TriangleMeshDeformation.cpp) is SA07 spokes ARAP with two differences that cannot be
/// switched off from Python: (1) edge weights are the mean of the opposite cotangents clamped at 0, so
/// boundary edges get cot a instead of our cot a / 2, and negative weights become 0; (2) its first
/// local step sees the rest shape with the constrained vertices NOT yet moved (all rotations identity,
/// iteration 1 = plain Laplacian editing), where we (like libigl) move them to their targets first. A
/// numpy reimplementation with both changes reproduced open3d to 4e-13 x diagonal (max) over 1000
/// iterations on the cylinder; the same code with our weights and start reproduces ours (7e-13 after
/// 100). On the survey meshes: cylinder is closed with no negative weight (only (2) applies), cactus
/// has one clamped edge, bar 360 clamped and 60 boundary edges, plane 7744 and 800. ARAP converges
/// slowly, so (2) alone leaves the cylinder 1.3e-2 RMS apart after 1 iteration, 8.1e-3 after 10,
/// 6.3e-3 after 100, 1.8e-2 after 300 and 2.8e-4 after 1000: the two approach the same minimum, not
/// monotonically, and no iteration count affordable here makes them agree closely. Where the weights
/// differ the minima differ too (plane, 100 iterations, not run here for its 26 s: 2.1e-2 RMS).
///
/// Measured (RMS / diagonal, max / diagonal, RMS / our RMS displacement from rest), 10 | 100 iterations:
/// cylinder 8.1e-3, 3.5e-2, 0.020 | 6.3e-3, 1.9e-2, 0.016; bar 2.3e-3, 9.8e-3, 0.033 | 5.0e-4,
/// 2.1e-3, 0.006; cactus 7.3e-3, 3.5e-2, 0.041 | 1.2e-3, 3.7e-3, 0.008; plane (10 only) 4.7e-3,
/// 1.4e-2, 0.018. Asserted: open3d meets its constraints (measured <= 1.1e-15 x diagonal, bound 1e-12),
/// RMS <= 2e-2 x diagonal (2.5x the largest) and RMS <= 0.1 x our RMS displacement (2.4x the largest):
/// the two reproduce the same deformation to within a tenth of its size, not closer.
#[test]
fn peers_arap_agrees_with_open3d_arap() {
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    for (name, iteration_counts) in ARAP_CASES {
        let case = ArapCase::new(&dir, name);
        let (mesh, handles, targets) = (&case.mesh, &case.handles, &case.targets);
        let diagonal = mesh.bbox_diagonal();
        for &iterations in iteration_counts {
            let out = case.work.path().join(format!("open3d{iterations}.off"));
            peers_reference(
                &py,
                &[
                    "open3d_arap",
                    case.mesh_path.to_str().unwrap(),
                    case.constraints.to_str().unwrap(),
                    out.to_str().unwrap(),
                    "--iterations",
                    &iterations.to_string(),
                ],
            );
            let theirs = meshes::io::read_mesh(&out).unwrap();
            assert_eq!(theirs.triangles(), mesh.triangles());
            let theirs = theirs.positions();
            let ours = case.our_arap(iterations);
            let rms = harness::metrics::rms_distance(&ours, theirs, diagonal);
            let max = max_vertex_distance(&ours, theirs) / diagonal;
            let moved = harness::metrics::rms_distance(&ours, mesh.positions(), diagonal);
            let residual = harness::metrics::handle_residual(handles, targets, theirs, diagonal);
            println!(
                "{name}: {iterations} iterations, open3d vs ours / bbox diagonal: RMS {rms:.2e}, max {max:.2e}; RMS / our RMS displacement {:.3}; open3d handle residual {residual:.1e}",
                rms / moved
            );
            assert!(residual <= 1e-12, "{name}: open3d misses its constraints by {residual:e} x diagonal");
            assert!(rms <= 2e-2, "{name}, {iterations} iterations: RMS {rms:e} x diagonal");
            assert!(
                rms <= 0.1 * moved,
                "{name}, {iterations} iterations: RMS gap {rms:e} is more than 0.1 of the RMS displacement {moved:e}"
            );
        }
    }
}

/// open3d's `is_self_intersecting` through the harness's script (python/self_intersection.py): false on the four rest survey meshes, true on two triangles that
/// cross, false on the same two moved apart. (open3d tests all pairs of triangles: 25 s of this test's
/// ~28 s is the 80K-face plane.)
#[test]
fn peers_open3d_self_intersection_flags_only_the_crossing_mesh() {
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    let work = tempfile::tempdir().unwrap();
    // Two triangles with no shared vertex: the second pierces the first's interior along the segment
    // (0.5, 0.5, 0)-(1, 0.25, 0); moved 5 along x it is clear of it.
    let first = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
    let second = [[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.0, 0.25, 0.0]];
    let moved = second.map(|p| [p[0] + 5.0, p[1], p[2]]);
    let crossing_path = work.path().join("crossing.off");
    let apart_path = work.path().join("apart.off");
    for (path, other) in [(&crossing_path, second), (&apart_path, moved)] {
        let positions: Vec<[f64; 3]> = first.iter().chain(other.iter()).copied().collect();
        let mesh = meshes::TriMesh::new(positions, vec![[0, 1, 2], [3, 4, 5]]).unwrap();
        meshes::io::write_off(path, &mesh).unwrap();
    }
    let mut paths: Vec<std::path::PathBuf> = MESHES.iter().map(|n| dir.join(format!("{n}.off"))).collect();
    paths.push(crossing_path.clone());
    paths.push(apart_path.clone());
    let args: Vec<&str> = paths.iter().map(|p| p.to_str().unwrap()).collect();
    let out = support::self_intersection_script(&py, &args);
    let verdicts: HashMap<String, bool> = out
        .lines()
        .map(|line| {
            let (path, flag) = line.rsplit_once(',').unwrap_or_else(|| panic!("bad line {line:?}"));
            (
                path.to_string(),
                match flag {
                    "true" => true,
                    "false" => false,
                    _ => panic!("bad flag in {line:?}"),
                },
            )
        })
        .collect();
    assert_eq!(verdicts.len(), paths.len(), "one line per mesh expected:\n{out}");
    for path in &paths {
        let expected = *path == crossing_path;
        let got = verdicts[path.to_str().unwrap()];
        println!("{}: is_self_intersecting = {got}", path.file_name().unwrap().to_string_lossy());
        assert_eq!(got, expected, "{}: open3d is_self_intersecting = {got}", path.display());
    }
}

/// The area and volume measures of the harness (`e_area`, `volume_change`, issue 14) on survey
/// results against libigl's `doublearea` and pymeshlab's `get_geometric_measures`, on the same
/// result meshes: `laplacian` after 30 iterations (it shrinks the bent cylinder, so the figures are
/// far from 0). libigl sums the same cross products in f64: bound 1e-9 relative on `e_area`
/// (measured: at most 5e-16). MeshLab's volume agrees as closely (measured: 2e-14 absolute on
/// `volume_change` of the cylinder, 4e-15 on the cactus; bound 1e-9); its surface area does not
/// (measured 1.8e-8 to 2.7e-8 relative, single-precision accumulation; bound 1e-6, far below a change
/// any figure or gate would see). The bar is open: no volume on either side.
#[test]
fn peers_area_distortion_and_volume_change_match_libigl_and_pymeshlab() {
    use harness::metrics::{area_distortion, volume_change, RestGeometry};
    let Some(py) = python() else { return };
    let dir = survey_meshes().dir;
    for name in ["cylinder", "bar", "cactus"] {
        let (mesh, handles, targets) = survey_case(&dir, name);
        let params: toml::Table = "max_iterations = 30".parse().unwrap();
        let mut laplacian = methods::registry::create("laplacian", &params).unwrap();
        laplacian.precompute(&mesh).unwrap();
        laplacian.bind_handles(&handles).unwrap();
        laplacian.solve(&targets, &mut NoObserver).unwrap();
        let result = laplacian.positions();

        let work = tempfile::tempdir().unwrap();
        let rest_path = dir.join(format!("{name}.off"));
        let result_path = work.path().join(format!("{name}-laplacian.off"));
        meshes::io::write_off(&result_path, &mesh.with_positions(result.clone()).unwrap()).unwrap();
        let double_areas = |path: &std::path::Path, out: &str| -> Vec<f64> {
            let out = work.path().join(out);
            igl_reference(&py, &["doublearea", path.to_str().unwrap(), out.to_str().unwrap()]);
            read_rows(&out).into_iter().map(|r| r[0]).collect()
        };
        let (a0, a) = (double_areas(&rest_path, "rest.txt"), double_areas(&result_path, "result.txt"));
        assert_eq!((a0.len(), a.len()), (mesh.n_faces(), mesh.n_faces()));
        let theirs_e_area =
            (a0.iter().zip(&a).map(|(a0, a)| (a / a0).ln().powi(2)).sum::<f64>() / a.len() as f64).sqrt();

        let topology = meshes::Topology::new(&mesh).unwrap();
        let rest = RestGeometry::new(&mesh, &topology);
        let ours_e_area = area_distortion(&rest, &mesh, &result);
        let e_area_err = (ours_e_area - theirs_e_area).abs() / theirs_e_area;

        let measures = |path: &std::path::Path| -> serde_json::Value {
            serde_json::from_str(&peers_reference(&py, &["geometric_measures", path.to_str().unwrap()]))
                .unwrap()
        };
        let (m0, m) = (measures(&rest_path), measures(&result_path));
        let ours_area: f64 = meshes::geometry::face_areas(&result, mesh.triangles()).iter().sum();
        let area_err = (ours_area - json_f64(&m, &["surface_area"])).abs() / ours_area;
        let ours_volume = volume_change(&rest, &mesh, &result);
        println!(
            "{name}: e_area ours {ours_e_area:.6} libigl {theirs_e_area:.6} (rel diff {e_area_err:.1e}); \
             total area rel diff to pymeshlab {area_err:.1e}; volume_change ours {ours_volume:?}, pymeshlab \
             volumes {} -> {}",
            m0["mesh_volume"], m["mesh_volume"]
        );
        assert!(ours_e_area > 0.01, "{name}: the laplacian result should distort areas: {ours_e_area}");
        assert!(e_area_err <= 1e-9, "{name}: e_area {ours_e_area} against libigl's {theirs_e_area}");
        assert!(area_err <= 1e-6, "{name}: total area differs from pymeshlab's by {area_err:e} (relative)");
        match (ours_volume, m0["mesh_volume"].as_f64(), m["mesh_volume"].as_f64()) {
            (Some(ours), Some(v0), Some(v)) => {
                let theirs = (v - v0) / v0;
                println!("{name}: volume_change difference to pymeshlab {:.1e}", (ours - theirs).abs());
                assert!(
                    (ours - theirs).abs() <= 1e-9,
                    "{name}: volume_change {ours} against pymeshlab's {theirs}"
                );
            }
            (None, None, None) => assert!(!topology.is_closed(), "{name}"),
            other => {
                panic!("{name}: closed mesh by our topology {} but volumes {other:?}", topology.is_closed())
            }
        }
    }
}
