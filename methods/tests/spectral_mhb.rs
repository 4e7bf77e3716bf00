//! `spectral_mhb` against its paper: with a full basis the reduced system reproduces the unreduced
//! eq 14; the rest shape and rigid translations are reproduced exactly; clear errors and phase timings.

mod fixtures;

use faer::Mat;
use meshes::{AffineTransform, TriMesh};
use methods::operators::{cotan_laplacian, lumped_mass, MassKind};
use methods::spectral_mhb::{SpectralMhb, SpectralMhbParams};
use methods::{DeformationMethod, HandleSet, HandleTargets, NoObserver};

fn params(text: &str) -> SpectralMhbParams {
    toml::Value::Table(text.parse().unwrap()).try_into().unwrap()
}

/// The fixture's bar with its fixed and handle regions, and the handle region.
fn bar(vertices: usize) -> (TriMesh, HandleSet, Vec<u32>) {
    let bar = fixtures::bar(vertices);
    let handles = bar.handles();
    (bar.mesh, handles, bar.handle)
}

fn targets(mesh: &TriMesh, handles: &HandleSet, moved: &[u32], t: &AffineTransform) -> HandleTargets {
    let p = mesh.positions();
    let positions = handles
        .constrained()
        .map(|v| if moved.contains(&v) { t.apply(p[v as usize]) } else { p[v as usize] })
        .collect();
    HandleTargets::new(handles, positions).unwrap()
}

fn run(
    method: &mut SpectralMhb,
    mesh: &TriMesh,
    handles: &HandleSet,
    targets: &HandleTargets,
) -> Vec<[f64; 3]> {
    method.precompute(mesh).unwrap();
    method.bind_handles(handles).unwrap();
    method.solve(targets, &mut NoObserver).unwrap();
    method.positions()
}

#[test]
fn full_basis_reproduces_the_unreduced_lagrange_system_of_eq_14() {
    let (mesh, handles, handle) = bar(200);
    let n = mesh.n_vertices();
    let t =
        targets(&mesh, &handles, &handle, &AffineTransform::rotation_about([0.0, 0.0, 1.0], 0.6, [0.0; 3]));
    let mut method = SpectralMhb::new(params(&format!("bases = {n}\nconstraints = \"lagrange\""))).unwrap();
    run(&mut method, &mesh, &handles, &t);
    let ours: Vec<[f64; 3]> = method
        .smoothed_deformed()
        .iter()
        .zip(method.smoothed_rest())
        .map(|(a, b)| std::array::from_fn(|k| a[k] - b[k]))
        .collect();

    // Eq 14 directly: [A B; B^T 0] [d; gamma] = [0; d'], A = L_s M^-1 L_s (k_s = 0, k_b = 1).
    let (p, tris) = (mesh.positions(), mesh.triangles());
    let ls = cotan_laplacian(p, tris).to_dense();
    let m = lumped_mass(p, tris, MassKind::Voronoi);
    let a = &ls * Mat::from_fn(n, n, |i, j| ls[(i, j)] / m[i]);
    let constrained: Vec<u32> = handles.constrained().collect();
    let c = constrained.len();
    let kkt = Mat::from_fn(n + c, n + c, |i, j| match (i < n, j < n) {
        (true, true) => a[(i, j)],
        (true, false) => f64::from(constrained[j - n] as usize == i),
        (false, true) => f64::from(constrained[i - n] as usize == j),
        (false, false) => 0.0,
    });
    let rhs = Mat::from_fn(n + c, 3, |i, k| {
        if i < n {
            0.0
        } else {
            t.positions()[i - n][k] - p[constrained[i - n] as usize][k]
        }
    });
    let reference = faer::prelude::Solve::solve(&kkt.partial_piv_lu(), &rhs);
    let (mut err, mut size) = (0.0f64, 0.0f64);
    for i in 0..n {
        for k in 0..3 {
            err = err.max((ours[i][k] - reference[(i, k)]).abs());
            size = size.max(reference[(i, k)].abs());
        }
    }
    assert!(err <= 1e-6 * size, "reduced (m = n) vs eq 14: {err:e} of {size:e}");
}

#[test]
fn rest_shape_and_translations_are_reproduced() {
    let (mesh, handles, _) = bar(1500);
    let all: Vec<u32> = handles.constrained().collect();
    for details in ["deformation_transfer", "local_frames"] {
        for (name, transform) in [
            ("rest", AffineTransform::IDENTITY),
            ("translation", AffineTransform::translation([3.0, -2.0, 7.5])),
        ] {
            let mut method = SpectralMhb::new(params(&format!("details = \"{details}\""))).unwrap();
            let x = run(&mut method, &mesh, &handles, &targets(&mesh, &handles, &all, &transform));
            let expected: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| transform.apply(p)).collect();
            let d = methods::method::max_displacement(&x, &expected) / mesh.bbox_diagonal();
            assert!(d < 1e-8, "{details}, {name}: off by {d:e} x diagonal");
        }
    }
}

#[test]
fn lagrange_with_more_constraints_than_bases_is_a_clear_error() {
    let (mesh, handles, _) = bar(1500);
    let mut method = SpectralMhb::new(params("bases = 20\nconstraints = \"lagrange\"")).unwrap();
    method.precompute(&mesh).unwrap();
    let e = method.bind_handles(&handles).unwrap_err().to_string();
    assert!(e.contains("at most m = 20") && e.contains("penalty"), "{e}");
}

/// An eigensolver that does not converge is reported as such (not as a parameter error), with
/// the counts it reached.
#[test]
fn eigensolver_failure_is_an_eigensolver_error() {
    let (mesh, _, _) = bar(1500);
    let mut method = SpectralMhb::new(params("bases = 10\neigen_tolerance = 1e-300")).unwrap();
    let e = method.precompute(&mesh).unwrap_err();
    assert!(
        matches!(
            e,
            methods::MethodError::Eigen(methods::linalg::spectral::EigenError::NotConverged {
                wanted: 9,
                ..
            })
        ),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("eigensolver: did not converge"), "{e}");
}

#[test]
fn paper_phases_are_reported() {
    let (mesh, handles, handle) = bar(1500);
    let mut method = SpectralMhb::new(params("bases = 30")).unwrap();
    run(
        &mut method,
        &mesh,
        &handles,
        &targets(&mesh, &handles, &handle, &AffineTransform::translation([0.0, 4.0, 0.0])),
    );
    let timings = method.phase_timings();
    let names: Vec<&str> = timings.iter().map(|(n, _)| n.as_str()).collect();
    for phase in [
        "pt1_manifold_harmonics",
        "pt2_reduced_energy",
        "pt3_detail_system",
        "rt1_reduced_solve",
        "rt2_details",
    ] {
        assert!(names.contains(&phase), "{phase} missing from {names:?}");
    }
    assert_eq!(method.basis().ncols(), 30);
    assert!(method.positions().iter().all(|p| p.iter().all(|c| c.is_finite())));
}
