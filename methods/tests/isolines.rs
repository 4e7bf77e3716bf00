//! Properties of the `isolines` reduced model (Au et al. 2007): harmonic fields (range, partition of
//! unity), traced isolines (segment ends on the level), the interpolation matrices (identity transforms
//! reproduce the base shape and its Laplacian coordinates), fixed points and clear errors.

mod fixtures;

use meshes::{AffineTransform, TriMesh};
use methods::isoline_model::tracing::trace_isoline;
use methods::isolines::{harmonic_fields, Isolines, IsolinesParams, LaplacianCoordinates};
use methods::operators::cotan_laplacian;
use methods::{DeformationMethod, HandleSet, HandleTargets, MethodError, NoObserver};

/// The fixture's bar (~2K vertices) with its fixed and handle regions, and optionally a third
/// handle: the free vertices at 45–50% of the bar's length (a ring in its middle).
fn bar(three_handles: bool) -> (TriMesh, HandleSet) {
    let bar = fixtures::bar(2000);
    let handles = if three_handles { bar.three_handles() } else { bar.handles() };
    (bar.mesh, handles)
}

fn method(params: IsolinesParams) -> Isolines {
    Isolines::new("isolines", params).unwrap()
}

fn bound(mesh: &TriMesh, handles: &HandleSet, params: IsolinesParams) -> Isolines {
    let mut m = method(params);
    m.precompute(mesh).unwrap();
    m.bind_handles(handles).unwrap();
    m
}

fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    methods::method::max_displacement(a, b)
}

#[test]
fn harmonic_fields_lie_in_the_unit_interval_and_sum_to_one() {
    for three in [false, true] {
        let (mesh, handles) = bar(three);
        let l = cotan_laplacian(mesh.positions(), mesh.triangles());
        let fields = harmonic_fields(l.as_ref(), &handles).unwrap();
        assert_eq!(fields.ncols(), handles.regions().len());
        for k in 0..fields.nrows() {
            let sum: f64 = (0..fields.ncols()).map(|i| fields[(k, i)]).sum();
            assert!((sum - 1.0).abs() < 1e-9, "vertex {k}: fields sum to {sum}");
            for i in 0..fields.ncols() {
                let f = fields[(k, i)];
                assert!((-1e-9..=1.0 + 1e-9).contains(&f), "vertex {k}, field {i}: {f}");
            }
        }
        // Boundary values: 1 on the own handle, 0 on the others.
        for (i, region) in handles.regions().iter().enumerate() {
            for &v in &region.vertices {
                for j in 0..fields.ncols() {
                    assert_eq!(fields[(v as usize, j)], f64::from(u8::from(i == j)));
                }
            }
        }
    }
}

#[test]
fn traced_segments_end_on_their_level() {
    let (mesh, handles) = bar(false);
    let l = cotan_laplacian(mesh.positions(), mesh.triangles());
    let fields = harmonic_fields(l.as_ref(), &handles).unwrap();
    let field: Vec<f64> = (0..fields.nrows()).map(|k| fields[(k, 0)]).collect();
    for level in [1e-6, 0.05, 0.5, 0.73, 1.0 - 1e-6] {
        let crossed = trace_isoline(mesh.positions(), mesh.triangles(), &field, level);
        assert!(!crossed.is_empty(), "level {level}: no crossed triangle");
        for c in &crossed {
            let tri = mesh.triangles()[c.triangle as usize];
            for end in c.ends {
                assert!(tri.contains(&end.a) && tri.contains(&end.b), "segment end off its triangle");
                assert!(
                    (end.value(&field) - level).abs() <= 1e-12,
                    "end at {} for level {level}",
                    end.value(&field)
                );
            }
            assert!(c.length > 0.0);
        }
    }
    // The model's isolines: every sampled segment ends on the traced level, which is the isovalue
    // except for the two special isolines just inside (0, 1).
    let m = bound(&mesh, &handles, IsolinesParams::default());
    let model = m.model().unwrap();
    assert_eq!(model.n_isolines(), 20, "two handles: one set of n_iso isolines");
    for iso in model.isolines() {
        assert!((iso.level - iso.isovalue).abs() <= 1e-6 + 1e-15);
        assert!(!iso.crossed.is_empty(), "isoline {} has no crossed triangle", iso.index);
        for c in &iso.crossed {
            for end in c.ends {
                assert!((end.value(&field) - iso.level).abs() <= 1e-12);
            }
        }
    }
    assert!(model.n_sampled_triangles() <= IsolinesParams::default().max_crossed_triangles);
}

#[test]
fn identity_transforms_reproduce_the_base_shape_and_its_laplacian_coordinates() {
    for three in [false, true] {
        let (mesh, handles) = bar(three);
        let m = bound(&mesh, &handles, IsolinesParams::default());
        let model = m.model().unwrap();
        if three {
            assert_eq!(model.n_isolines(), 3 * 20, "three handles: one set per handle");
        }
        let scale = mesh.bbox_diagonal();
        let x = model.positions(model.identity_transforms().as_ref());
        assert!(max_distance(&x, mesh.positions()) <= 1e-12 * scale, "W_x R_identity != X");
        let l = cotan_laplacian(mesh.positions(), mesh.triangles());
        let rotations = model.identity_rotations();
        let delta_scale = model.base_delta().iter().map(|d| meshes::vector::norm(*d)).fold(0.0, f64::max);
        for k in 0..mesh.n_vertices() {
            let d = model.interpolated_delta(k, rotations.as_ref());
            // delta_bar itself is L X.
            let mut lx = [0.0; 3];
            let (symbolic, values) = l.parts();
            for idx in symbolic.col_range(k) {
                let i = symbolic.row_idx()[idx];
                for a in 0..3 {
                    lx[a] += values[idx] * mesh.positions()[i][a];
                }
            }
            for a in 0..3 {
                assert!((d[a] - lx[a]).abs() <= 1e-12 * delta_scale, "vertex {k}: W_delta R_identity != L X");
            }
        }
        for (k, w) in (0..mesh.n_vertices()).map(|k| (k, model.vertex_weights(k))) {
            let sum: f64 = w.iter().map(|(_, w)| w).sum();
            assert!((sum - 1.0).abs() < 1e-9, "vertex {k}: weights sum to {sum}");
        }
    }
}

#[test]
fn rest_shape_is_a_fixed_point_of_both_variants() {
    let (mesh, handles) = bar(true);
    let targets =
        HandleTargets::new(&handles, handles.constrained().map(|v| mesh.positions()[v as usize]).collect())
            .unwrap();
    for coordinates in [LaplacianCoordinates::Isolines, LaplacianCoordinates::Vertices] {
        let mut m = bound(
            &mesh,
            &handles,
            IsolinesParams { laplacian_coordinates: coordinates, ..Default::default() },
        );
        let summary = m.solve(&targets, &mut NoObserver).unwrap();
        let d = max_distance(&m.positions(), mesh.positions()) / mesh.bbox_diagonal();
        assert!(d < 1e-9, "{coordinates:?}: rest shape moved by {d:e} x diagonal");
        assert!(summary.converged && summary.iterations <= 2, "{coordinates:?}: {summary:?}");
    }
}

#[test]
fn a_rigid_motion_of_all_handles_moves_the_mesh_rigidly() {
    // Every handle moved by one rigid motion: the isoline frames all rotate alike, so the
    // interpolated Laplacian coordinates are the rotated rest ones and the rigid copy solves eq 10.
    let (mesh, handles) = bar(true);
    let motion = AffineTransform::rotation_about([0.3, 1.0, 0.2], 0.7, [1.0, 2.0, 3.0])
        .compose(&AffineTransform::translation([5.0, -2.0, 1.0]));
    let targets = HandleTargets::new(
        &handles,
        handles.constrained().map(|v| motion.apply(mesh.positions()[v as usize])).collect(),
    )
    .unwrap();
    let params = IsolinesParams { tolerance: 1e-12, max_iterations: 5000, ..Default::default() };
    let mut m = bound(&mesh, &handles, params);
    let summary = m.solve(&targets, &mut NoObserver).unwrap();
    assert!(summary.converged, "{summary:?}");
    let expected: Vec<[f64; 3]> = mesh.positions().iter().map(|p| motion.apply(*p)).collect();
    let d = max_distance(&m.positions(), &expected) / mesh.bbox_diagonal();
    assert!(d < 1e-9, "rigid motion reproduced to {d:e} x diagonal ({summary:?})");
}

#[test]
fn bad_parameters_and_handle_sets_are_errors() {
    for (bad, key) in [
        (IsolinesParams { isolines: 1, ..Default::default() }, "isolines"),
        (IsolinesParams { max_crossed_triangles: 0, ..Default::default() }, "max_crossed_triangles"),
        (IsolinesParams { omega: 0.0, ..Default::default() }, "omega"),
        (IsolinesParams { beta: f64::NAN, ..Default::default() }, "beta"),
    ] {
        match Isolines::new("isolines", bad) {
            Err(MethodError::InvalidParameters { faults, .. }) => assert_eq!(faults[0].keys(), [key]),
            other => panic!("{key}: {:?}", other.err()),
        }
    }
    let (mesh, handles) = bar(false);
    let mut m = method(IsolinesParams::default());
    assert!(matches!(m.bind_handles(&handles), Err(MethodError::Phase { .. })));
    m.precompute(&mesh).unwrap();
    let one = HandleSet::new(vec![handles.regions()[1].clone()], mesh.n_vertices()).unwrap();
    let err = m.bind_handles(&one).unwrap_err();
    assert!(err.to_string().contains("at least two handle regions"), "{err}");
    let other_size = HandleSet::new(vec![handles.regions()[1].clone()], mesh.n_vertices() + 1).unwrap();
    assert!(matches!(m.bind_handles(&other_size), Err(MethodError::Handles(_))));
}
