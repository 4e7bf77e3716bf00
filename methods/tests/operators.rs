//! Identities of the discrete operators, on procedural meshes.

use meshes::shapes::{generate, ShapeKind};
use methods::operators::{cotan_laplacian, laplacian, lumped_mass, stiffness, LaplacianWeights, MassKind};

fn dense_row_sums_and_asymmetry(l: &faer::sparse::SparseColMat<usize, f64>) -> (f64, f64) {
    let (sym, val) = l.parts();
    let n = sym.nrows();
    let mut row_sums = vec![0.0; n];
    let mut entries = std::collections::HashMap::new();
    for j in 0..n {
        for idx in sym.col_range(j) {
            let i = sym.row_idx()[idx];
            row_sums[i] += val[idx];
            entries.insert((i, j), val[idx]);
        }
    }
    let max_row = row_sums.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let asym = entries
        .iter()
        .map(|(&(i, j), v)| (v - entries.get(&(j, i)).copied().unwrap_or(0.0)).abs())
        .fold(0.0, f64::max);
    (max_row, asym)
}

#[test]
fn laplacian_annihilates_constants_and_is_symmetric() {
    for kind in [ShapeKind::Bar, ShapeKind::Cactus, ShapeKind::BumpyPlane] {
        let shape = generate(kind, 2000).unwrap();
        let l = cotan_laplacian(shape.mesh.positions(), shape.mesh.triangles());
        let scale = l.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (row, asym) = dense_row_sums_and_asymmetry(&l);
        assert!(row <= 1e-12 * scale, "{kind:?}: |L 1| = {row:e}");
        assert!(asym <= 1e-14 * scale, "{kind:?}: L not symmetric ({asym:e})");
        // -L is positive semi-definite: x^T (-L) x >= 0 on coordinates.
        let p = shape.mesh.positions();
        let (sym, val) = l.parts();
        for a in 0..3 {
            let mut q = 0.0;
            for j in 0..sym.ncols() {
                for idx in sym.col_range(j) {
                    q -= p[sym.row_idx()[idx]][a] * val[idx] * p[j][a];
                }
            }
            assert!(q >= 0.0, "{kind:?}: x^T(-L)x = {q}");
        }
    }
}

#[test]
fn stiffness_is_minus_the_laplacian_and_positive_semi_definite() {
    let shape = generate(ShapeKind::Cactus, 2000).unwrap();
    let (p, t) = (shape.mesh.positions(), shape.mesh.triangles());
    for weights in [LaplacianWeights::Cotan, LaplacianWeights::Clamped, LaplacianWeights::IntrinsicDelaunay] {
        let l = laplacian(weights, p, t).unwrap();
        let k = stiffness(l.clone());
        assert_eq!(k.parts().0.row_idx(), l.parts().0.row_idx(), "{weights:?}: same sparsity");
        assert!(k.val().iter().zip(l.val()).all(|(a, b)| *a == -*b), "{weights:?}: K = -L");
        let (sym, val) = k.parts();
        // x^T K x on a deterministic non-smooth vector (a hash of the index), not only on coordinates.
        let x: Vec<f64> = (0..sym.nrows()).map(|i| ((i * 2654435761) % 1000) as f64 / 1000.0 - 0.5).collect();
        let mut q = 0.0;
        for j in 0..sym.ncols() {
            for idx in sym.col_range(j) {
                let i = sym.row_idx()[idx];
                q += x[i] * val[idx] * x[j];
                if i == j {
                    assert!(val[idx] >= 0.0, "{weights:?}: K_{i}{i} = {}", val[idx]);
                }
            }
        }
        // Intrinsic Delaunay weights are non-negative, so its K is PSD for every x.
        if weights == LaplacianWeights::IntrinsicDelaunay {
            assert!(q >= 0.0, "{weights:?}: x^T K x = {q}");
        }
    }
}

#[test]
fn lumped_mass_sums_to_surface_area() {
    for kind in [ShapeKind::Bar, ShapeKind::Cylinder, ShapeKind::Cactus, ShapeKind::BumpyPlane] {
        let shape = generate(kind, 2000).unwrap();
        let (p, t) = (shape.mesh.positions(), shape.mesh.triangles());
        let area: f64 = meshes::geometry::face_areas(p, t).iter().sum();
        for mass_kind in [MassKind::Voronoi, MassKind::Barycentric] {
            let m = lumped_mass(p, t, mass_kind);
            let total: f64 = m.iter().sum();
            assert!((total - area).abs() <= 1e-12 * area, "{kind:?} {mass_kind:?}: {total} vs {area}");
            assert!(m.iter().all(|&x| x > 0.0), "{kind:?} {mass_kind:?}: non-positive mass");
        }
    }
}

#[test]
fn voronoi_mass_of_an_acute_triangle_is_the_circumcentric_split() {
    // Equilateral triangle: each corner gets a third.
    let s3 = 3f64.sqrt();
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, s3 / 2.0, 0.0]];
    let m = lumped_mass(&p, &[[0, 1, 2]], MassKind::Voronoi);
    let area = s3 / 4.0;
    for x in m {
        assert!((x - area / 3.0).abs() < 1e-15);
    }
    // Obtuse at corner 2: half the area there, a quarter at the others.
    let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.2, 0.0]];
    let m = lumped_mass(&p, &[[0, 1, 2]], MassKind::Voronoi);
    assert!((m[2] - 0.1).abs() < 1e-15 && (m[0] - 0.05).abs() < 1e-15 && (m[1] - 0.05).abs() < 1e-15);
}

#[test]
fn zero_area_triangles_do_not_produce_nan() {
    // A valid strip plus a collinear (zero-area) triangle and a needle with two coincident corners.
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 0.0, 0.0], // collinear with 0 and 1
        [1.0, 1.0, 0.0], // coincides with 3
    ];
    let t = vec![[0, 1, 2], [1, 3, 2], [0, 4, 1], [1, 5, 3]];
    let mesh = meshes::TriMesh::new(p, t).unwrap();
    assert!(mesh.check_nondegenerate().is_err(), "the harness must reject this mesh");
    let l = cotan_laplacian(mesh.positions(), mesh.triangles());
    assert!(l.val().iter().all(|v| v.is_finite()));
    let (row, asym) = dense_row_sums_and_asymmetry(&l);
    assert!(row < 1e-15 && asym == 0.0);
    for kind in [MassKind::Voronoi, MassKind::Barycentric] {
        let m = lumped_mass(mesh.positions(), mesh.triangles(), kind);
        assert!(m.iter().all(|v| v.is_finite()));
        assert!((m.iter().sum::<f64>() - 1.0).abs() < 1e-15, "only the two unit-area halves count");
    }
}
