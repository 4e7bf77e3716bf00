//! The eigensolver against the dense oracle, and the properties the spectral module promises:
//! D-orthonormal eigenvectors, small residuals, the flagged constant mode, clusters of (near-)multiple
//! eigenvalues, determinism, clear errors; and the manifold harmonics transform.

use faer::Mat;
use meshes::shapes::{generate, ShapeKind};
use methods::linalg::spectral::{
    inverse_transform, smallest_eigenpairs, transform, EigenError, EigenOptions, Eigenpairs,
};
use methods::operators::{cotan_laplacian, lumped_mass, MassKind};

fn problem(kind: ShapeKind, vertices: usize) -> (faer::sparse::SparseColMat<usize, f64>, Vec<f64>) {
    let mesh = generate(kind, vertices).unwrap().mesh;
    let mut q = cotan_laplacian(mesh.positions(), mesh.triangles());
    q.val_mut().iter_mut().for_each(|v| *v = -*v);
    (q, lumped_mass(mesh.positions(), mesh.triangles(), MassKind::Barycentric))
}

fn krylov(count: usize) -> EigenOptions {
    let mut o = EigenOptions::new(count);
    o.dense_limit = 0;
    o
}

/// Largest sine of the principal angles between span(a) and span(b) in the D inner product
/// (both D-orthonormal, `b` spanning at least `a`'s dimension).
fn largest_angle_sine(a: &Mat<f64>, b: &Mat<f64>, mass: &[f64]) -> f64 {
    let n = a.nrows();
    let db = Mat::from_fn(n, b.ncols(), |i, j| mass[i] * b[(i, j)]);
    let coef = db.transpose() * a; // b^T D a
    let residual = a - b * &coef;
    let dr = Mat::from_fn(n, residual.ncols(), |i, j| mass[i] * residual[(i, j)]);
    let gram = residual.transpose() * &dr;
    let top = gram.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
    top.last().copied().unwrap_or(0.0).max(0.0).sqrt()
}

/// Groups of indices whose eigenvalues agree to `rel` (relative to the largest).
fn clusters(values: &[f64], rel: f64) -> Vec<std::ops::Range<usize>> {
    let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=values.len() {
        if i == values.len() || (values[i] - values[i - 1]).abs() > rel * scale {
            out.push(start..i);
            start = i;
        }
    }
    out
}

fn compare(ours: &Eigenpairs, reference: &Eigenpairs, mass: &[f64]) {
    let scale = reference.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (i, (a, b)) in ours.values.iter().zip(&reference.values).enumerate() {
        // Relative, except for the zero eigenvalue, which is compared against the spectrum's scale.
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-3 * scale), "eigenvalue {i}: {a} vs {b}");
    }
    let k = ours.values.len();
    // Near-multiple eigenvalues (relative gap < 1e-4) have ill-determined individual vectors:
    // compare their spans.
    for cluster in clusters(&reference.values, 1e-4) {
        if cluster.end >= k {
            break; // a cluster cut at k has no well-defined subspace
        }
        let a = Mat::from_fn(mass.len(), cluster.len(), |i, j| ours.vectors[(i, cluster.start + j)]);
        let b = Mat::from_fn(mass.len(), cluster.len(), |i, j| reference.vectors[(i, cluster.start + j)]);
        let s = largest_angle_sine(&a, &b, mass);
        assert!(s < 1e-7, "cluster {cluster:?}: principal angle sine {s:e}");
    }
}

#[test]
fn krylov_schur_matches_the_dense_solver() {
    for (kind, count) in [(ShapeKind::Bar, 30), (ShapeKind::Cylinder, 40), (ShapeKind::Cactus, 25)] {
        let (q, mass) = problem(kind, 1200);
        let mut dense = EigenOptions::new(count);
        dense.dense_limit = usize::MAX;
        let reference = smallest_eigenpairs(q.as_ref(), &mass, &dense).unwrap();
        let ours = smallest_eigenpairs(q.as_ref(), &mass, &krylov(count)).unwrap();
        assert!(
            ours.restarts > 0 || ours.operator_applications > 0,
            "{kind:?}: the Krylov path must have run"
        );
        compare(&ours, &reference, &mass);
    }
}

/// A stiffness without a null vector (`Q + D`, eigenvalues shifted by 1) is solved without
/// deflation; the deflated Laplacian's spectrum shifted by 1 must come out.
#[test]
fn stiffness_without_a_null_vector_is_solved_without_deflation() {
    let (q, mass) = problem(ShapeKind::Cactus, 1500);
    let shifted = methods::linalg::sparse_cholesky::add_to_diagonal(q.as_ref(), &mass);
    let count = 24;
    let laplacian = smallest_eigenpairs(q.as_ref(), &mass, &krylov(count)).unwrap();
    let ours = smallest_eigenpairs(shifted.as_ref(), &mass, &krylov(count)).unwrap();
    assert_eq!(ours.constant_mode, None, "lambda = 1 is not a null mode");
    let mut dense = EigenOptions::new(count);
    dense.dense_limit = usize::MAX;
    compare(&ours, &smallest_eigenpairs(shifted.as_ref(), &mass, &dense).unwrap(), &mass);
    for (a, b) in ours.values.iter().zip(&laplacian.values) {
        assert!((a - (b + 1.0)).abs() <= 1e-9 * a, "{a} vs {b} + 1");
    }
}

/// One eigenpair of a Laplacian is the deflated constant vector alone.
#[test]
fn the_constant_mode_alone_needs_no_krylov_iteration() {
    let (q, mass) = problem(ShapeKind::Bar, 1500);
    let pairs = smallest_eigenpairs(q.as_ref(), &mass, &krylov(1)).unwrap();
    assert_eq!((pairs.constant_mode, pairs.operator_applications), (Some(0), 0));
    let total: f64 = mass.iter().sum();
    assert!((0..mass.len()).all(|i| (pairs.vectors[(i, 0)] * total.sqrt() - 1.0).abs() < 1e-12));
}

#[test]
fn eigenvectors_are_d_orthonormal_with_small_residuals() {
    let (q, mass) = problem(ShapeKind::BumpyPlane, 3000);
    let pairs = smallest_eigenpairs(q.as_ref(), &mass, &krylov(50)).unwrap();
    let h = &pairs.vectors;
    let dh = Mat::from_fn(h.nrows(), h.ncols(), |i, j| mass[i] * h[(i, j)]);
    let gram = h.transpose() * &dh;
    for i in 0..gram.nrows() {
        for j in 0..gram.ncols() {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((gram[(i, j)] - want).abs() < 1e-10, "H^T D H ({i}, {j}) = {}", gram[(i, j)]);
        }
    }
    let qh = &q * h;
    let scale = pairs.values.last().unwrap();
    for j in 0..h.ncols() {
        let r = (0..h.nrows())
            .map(|i| (qh[(i, j)] - pairs.values[j] * mass[i] * h[(i, j)]).powi(2) / mass[i])
            .sum::<f64>();
        assert!(r.sqrt() <= 1e-8 * scale, "pair {j}: residual {:e}", r.sqrt());
    }
    assert!(pairs.values.windows(2).all(|w| w[0] <= w[1]), "eigenvalues not ascending");
}

#[test]
fn constant_mode_is_included_and_flagged() {
    for kind in [ShapeKind::Cylinder, ShapeKind::BumpyPlane] {
        let (q, mass) = problem(kind, 2000);
        let pairs = smallest_eigenpairs(q.as_ref(), &mass, &krylov(10)).unwrap();
        assert_eq!(pairs.constant_mode, Some(0), "{kind:?}");
        assert!(pairs.values[0].abs() < 1e-8 * pairs.values[9]);
        assert!(pairs.values[1] > 1e-6 * pairs.values[9], "{kind:?}: second eigenvalue should be positive");
    }
}

#[test]
fn near_multiple_eigenvalues_of_the_cylinder_are_resolved() {
    // The cylinder is nearly rotationally symmetric: its spectrum has pairs agreeing to ~1e-5.
    let (q, mass) = problem(ShapeKind::Cylinder, 2500);
    let pairs = smallest_eigenpairs(q.as_ref(), &mass, &krylov(24)).unwrap();
    let doubles = clusters(&pairs.values, 1e-4).iter().filter(|c| c.len() == 2).count();
    assert!(doubles >= 5, "expected several near-double eigenvalues, got {doubles}: {:?}", pairs.values);
    let mut dense = EigenOptions::new(24);
    dense.dense_limit = usize::MAX;
    compare(&pairs, &smallest_eigenpairs(q.as_ref(), &mass, &dense).unwrap(), &mass);
}

#[test]
fn same_seed_same_result() {
    let (q, mass) = problem(ShapeKind::Bar, 3000);
    let a = smallest_eigenpairs(q.as_ref(), &mass, &krylov(20)).unwrap();
    let b = smallest_eigenpairs(q.as_ref(), &mass, &krylov(20)).unwrap();
    assert_eq!(a.values, b.values);
    assert!(a.vectors == b.vectors, "eigenvectors differ between runs");
}

#[test]
fn bad_requests_are_errors() {
    let (q, mass) = problem(ShapeKind::Bar, 500);
    let n = mass.len();
    assert!(matches!(
        smallest_eigenpairs(q.as_ref(), &mass, &EigenOptions::new(0)),
        Err(EigenError::TooMany { .. })
    ));
    assert!(matches!(
        smallest_eigenpairs(q.as_ref(), &mass, &EigenOptions::new(n + 1)),
        Err(EigenError::TooMany { .. })
    ));
    let mut bad_mass = mass.clone();
    bad_mass[7] = 0.0;
    let e = smallest_eigenpairs(q.as_ref(), &bad_mass, &EigenOptions::new(5)).unwrap_err();
    assert!(e.to_string().contains("vertex 7"), "{e}");
    let mut limited = krylov(20);
    limited.max_restarts = 0;
    limited.basis_size = Some(40);
    limited.tolerance = 1e-15;
    assert!(matches!(smallest_eigenpairs(q.as_ref(), &mass, &limited), Err(EigenError::NotConverged { .. })));
}

#[test]
fn full_basis_transform_round_trips() {
    let (q, mass) = problem(ShapeKind::Cactus, 300);
    let n = mass.len();
    let pairs = smallest_eigenpairs(q.as_ref(), &mass, &EigenOptions::new(n)).unwrap();
    let signal = Mat::from_fn(n, 3, |i, j| ((i * 31 + j * 7) % 17) as f64 - 8.0);
    let back = inverse_transform(
        pairs.vectors.as_ref(),
        transform(pairs.vectors.as_ref(), &mass, signal.as_ref()).as_ref(),
    );
    let err = (0..n)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| (back[(i, j)] - signal[(i, j)]).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-9, "round trip error {err:e}");
    // Fewer bases low-pass filter: the constant part survives exactly.
    let constant = Mat::from_fn(n, 1, |_, _| 2.5);
    let few = Mat::from_fn(n, 10, |i, j| pairs.vectors[(i, j)]);
    let back = inverse_transform(few.as_ref(), transform(few.as_ref(), &mass, constant.as_ref()).as_ref());
    assert!((0..n).all(|i| (back[(i, 0)] - 2.5).abs() < 1e-9));
}
