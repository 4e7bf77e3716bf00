//! Properties of `hirm` (Wu et al. 2015): the field selection rule (eq 1-2) on a mesh with a known
//! spectrum, the handle-independent interpolation (identity transforms reproduce the base shape), the
//! background precompute (same matrices as a synchronous one), incremental binding (a new handle set
//! starts from the current shape, which is a fixed point), and clear errors.

mod fixtures;

use meshes::TriMesh;
use methods::hirm::{handle_independent_model, propagation_fields, select_fields, Hirm, HirmParams};
use methods::operators::cotan_laplacian;
use methods::{DeformationMethod, HandleRegion, HandleSet, HandleTargets, MethodError, NoObserver};

/// Tolerance of the fixed-point tests, relative to the bounding-box diagonal (see
/// `rest_shape_is_a_fixed_point`).
const FIXED_POINT: f64 = 2e-6;

/// A flat `length x 1` strip, `cells` quads along and `cells / length` across, two triangles each.
fn strip(length: f64, cells: usize) -> TriMesh {
    let across = (cells as f64 / length).round() as usize;
    let (nx, ny) = (cells + 1, across + 1);
    let positions = (0..ny).flat_map(|j| {
        (0..nx).map(move |i| [length * i as f64 / cells as f64, j as f64 / across as f64, 0.0])
    });
    let id = |i: usize, j: usize| (j * nx + i) as u32;
    let triangles = (0..across)
        .flat_map(|j| {
            (0..cells).flat_map(move |i| {
                [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]]
            })
        })
        .collect();
    TriMesh::new(positions.collect(), triangles).unwrap()
}

/// The fixture's bar (~2K vertices) with its fixed and handle regions.
fn bar() -> (TriMesh, HandleSet) {
    let bar = fixtures::bar(2000);
    let handles = bar.handles();
    (bar.mesh, handles)
}

/// Targets: `fixed` where it is in `current`, `handle` moved by `offset`.
fn targets(handles: &HandleSet, current: &[[f64; 3]], offset: [f64; 3]) -> HandleTargets {
    let mut out = Vec::new();
    for region in handles.regions() {
        let d = if region.name == "handle" { offset } else { [0.0; 3] };
        out.extend(region.vertices.iter().map(|&v| {
            let p = current[v as usize];
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
        }));
    }
    HandleTargets::new(handles, out).unwrap()
}

#[test]
fn selection_rule_counts_scores_below_the_threshold() {
    // S_i = sqrt(lambda_i / lambda_2) = 1, 2, 3, 4.
    let values = [0.0, 1.0, 4.0, 9.0, 16.0];
    assert_eq!(select_fields(&values, 3.5), Some(3));
    assert_eq!(select_fields(&values, 2.0), Some(1));
    assert_eq!(select_fields(&values, 4.0), Some(3), "S_i < phi is strict");
    assert_eq!(select_fields(&values, 10.0), Some(4));
    assert_eq!(select_fields(&[0.0, 0.0, 1.0], 3.5), None, "lambda_2 = 0: disconnected");
}

#[test]
fn strip_selects_its_three_longitudinal_modes() {
    // Neumann modes of a 10 x 1 strip: lambda = pi^2 (m^2 / 100 + n^2). With n = 0 the scores are
    // m = 1, 2, 3, 4, ...; the first transverse mode scores 10. phi = 3.5 keeps m = 1, 2, 3.
    let mesh = strip(10.0, 100);
    let laplacian = cotan_laplacian(mesh.positions(), mesh.triangles());
    let fields = propagation_fields(mesh.positions(), mesh.triangles(), &laplacian, 3.5, 20, 7).unwrap();
    assert_eq!(fields.scores.len(), 3, "scores {:?}", fields.scores);
    for (m, s) in fields.scores.iter().enumerate() {
        assert!((s - (m + 1) as f64).abs() < 0.02 * (m + 1) as f64, "score {s} of mode {}", m + 1);
    }
    assert!(!fields.capped);
    for i in 0..3 {
        let col: Vec<f64> = (0..mesh.n_vertices()).map(|k| fields.fields[(k, i)]).collect();
        let (lo, hi) = col.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(lo.abs() < 1e-12 && (hi - 1.0).abs() < 1e-12, "field {i} spans [{lo}, {hi}]");
    }
    let total: f64 = fields.weights.iter().sum();
    assert!((total - 1.0).abs() < 1e-12 && fields.weights.iter().all(|w| *w >= 0.0));
    // The strip lies along x: the first (half-cosine) mode carries most of the geometry.
    assert!(
        fields.weights[0] > fields.weights[1] && fields.weights[0] > fields.weights[2],
        "{:?}",
        fields.weights
    );
}

#[test]
fn identity_transforms_reproduce_the_base_shape() {
    let (mesh, _) = bar();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&mesh).unwrap();
    let inputs = hirm.system_inputs().unwrap();
    // A base shape other than the rest mesh: W = W(X) interpolates whatever it is built on.
    let base: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [p[0] + 0.1 * p[2], 1.5 * p[1], p[2]]).collect();
    let built = handle_independent_model(&base, &inputs);
    let reproduced = built.model.positions(built.model.identity_transforms().as_ref());
    let error = methods::method::max_displacement(&reproduced, &base);
    assert!(error < 1e-12 * mesh.bbox_diagonal(), "W R_identity differs from X by {error}");
    // Every vertex's weights sum to 1 (eq 8 with normalized omega_bar).
    for k in 0..mesh.n_vertices() {
        let s: f64 = built.model.vertex_weights(k).iter().map(|(_, w)| w).sum();
        assert!((s - 1.0).abs() < 1e-12, "vertex {k}: weights sum to {s}");
    }
}

#[test]
fn background_precompute_gives_the_synchronous_matrices() {
    let (mesh, handles) = bar();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&mesh).unwrap();
    hirm.bind_handles(&handles).unwrap();
    let diagonal = mesh.bbox_diagonal();
    hirm.solve(&targets(&handles, mesh.positions(), [0.0, 0.1 * diagonal, 0.0]), &mut NoObserver).unwrap();
    // The solve started a worker on the deformed shape; compare its result with a synchronous build.
    let background = hirm.handle_independent().unwrap().unwrap();
    let synchronous = handle_independent_model(&hirm.positions(), &hirm.system_inputs().unwrap());
    assert_ne!(hirm.positions(), mesh.positions().to_vec(), "the solve moved the mesh");
    assert_eq!(background.system.smoothness_normal_matrix, synchronous.system.smoothness_normal_matrix);
    assert_eq!(background.system.laplacian_rhs, synchronous.system.laplacian_rhs);
    assert_eq!(background.model.base_delta(), synchronous.model.base_delta());
}

#[test]
fn rest_shape_is_a_fixed_point() {
    let (mesh, handles) = bar();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&mesh).unwrap();
    hirm.bind_handles(&handles).unwrap();
    let summary = hirm.solve(&targets(&handles, mesh.positions(), [0.0; 3]), &mut NoObserver).unwrap();
    let moved = methods::method::max_displacement(&hirm.positions(), mesh.positions());
    // Exact in exact arithmetic; U^T U couples omega^2 = 1e6 constraints with mu^2 = 1e-4
    // smoothness, and its factorization leaves ~1e-7 of the diagonal (isolines: 1e-10).
    assert!(moved < FIXED_POINT * mesh.bbox_diagonal(), "rest shape moved by {moved}");
    // Steps of rounding do not contract: the distance bound ends the solve at a step of a thousandth
    // of the tolerance (measured: 4-6 iterations at steps ~5e-9 of the diagonal).
    assert!(summary.converged && summary.iterations <= 8, "{summary:?}");
}

#[test]
fn second_handle_set_starts_from_the_current_shape() {
    let (mesh, handles) = bar();
    let diagonal = mesh.bbox_diagonal();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&mesh).unwrap();
    hirm.bind_handles(&handles).unwrap();
    hirm.solve(&targets(&handles, mesh.positions(), [0.15 * diagonal, 0.0, 0.0]), &mut NoObserver).unwrap();
    let first = hirm.positions();
    assert!(methods::method::max_displacement(&first, mesh.positions()) > 0.1 * diagonal);

    // Add a third handle: the free vertices nearest the middle of the bent bar.
    let middle_point = first.iter().fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
    let middle_point = middle_point.map(|c| c / first.len() as f64);
    let mut free: Vec<u32> =
        (0..mesh.n_vertices() as u32).filter(|&v| handles.region_of()[v as usize] == u32::MAX).collect();
    let distance = |v: &u32| methods::method::max_displacement(&[first[*v as usize]], &[middle_point]);
    free.sort_by(|a, b| distance(a).total_cmp(&distance(b)));
    let mut regions = handles.regions().to_vec();
    regions.push(HandleRegion { name: "middle".into(), vertices: free[..20].to_vec() });
    let second = HandleSet::new(regions, mesh.n_vertices()).unwrap();
    hirm.bind_handles(&second).unwrap();

    // Bound on the current shape: W R_identity is the first result, not the rest mesh.
    assert_eq!(hirm.positions(), first);
    let model = &hirm.bound_model().unwrap().model;
    let base = model.positions(model.identity_transforms().as_ref());
    assert!(methods::method::max_displacement(&base, &first) < 1e-12 * diagonal);
    // Holding every handle where it is keeps the shape: it is the new system's fixed point.
    hirm.solve(&targets(&second, &first, [0.0; 3]), &mut NoObserver).unwrap();
    let moved = methods::method::max_displacement(&hirm.positions(), &first);
    assert!(moved < FIXED_POINT * diagonal, "held shape moved by {moved}");
}

#[test]
fn bad_parameters_and_phases_are_errors() {
    let bad = [
        HirmParams { threshold: 1.0, ..HirmParams::default() },
        HirmParams { max_fields: 0, ..HirmParams::default() },
        HirmParams { isolines: 1, ..HirmParams::default() },
        HirmParams { mu: f64::NAN, ..HirmParams::default() },
        HirmParams { omega: 0.0, ..HirmParams::default() },
    ];
    for params in bad {
        assert!(matches!(Hirm::new(params), Err(MethodError::InvalidParameters { .. })));
    }
    let (mesh, handles) = bar();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    assert!(matches!(hirm.bind_handles(&handles), Err(MethodError::Phase { .. })));
    hirm.precompute(&mesh).unwrap();
    let t = targets(&handles, mesh.positions(), [0.0; 3]);
    assert!(matches!(hirm.solve(&t, &mut NoObserver), Err(MethodError::Phase { .. })));
    let small = HandleSet::new(vec![HandleRegion { name: "h".into(), vertices: vec![0] }], 10).unwrap();
    assert!(hirm.bind_handles(&small).is_err(), "a handle set for another mesh size");
}

/// The handle update of eq 26, accumulated in place on the lower triangle, against its definition
/// `T_1 + omega^2 sum_k (Phi W)_k^T (Phi W)_k` built row by row from the vertex weights; the
/// full-matrix variant (used by `isolines`) is the same matrix, symmetric.
#[test]
fn handle_update_adds_the_constraint_term_to_t1() {
    let (mesh, handles) = bar();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&mesh).unwrap();
    let built = handle_independent_model(mesh.positions(), &hirm.system_inputs().unwrap());
    let (model, system) = (&built.model, &built.system);
    let omega = 1000.0;
    let size = 4 * model.n_isolines();
    let mut expected = system.smoothness_normal_matrix.clone();
    // Rows of W act on the positions in the model's frame, (x - c) / l and 1.
    let frame = model.frame();
    for v in handles.constrained() {
        let x = mesh.positions()[v as usize];
        let x: [f64; 3] = std::array::from_fn(|a| (x[a] - frame.center[a]) / frame.length);
        let mut row = vec![0.0; size];
        for &(m, w) in model.vertex_weights(v as usize) {
            for (d, h) in [x[0], x[1], x[2], 1.0].into_iter().enumerate() {
                row[4 * m as usize + d] += w * h;
            }
        }
        for i in 0..size {
            for j in 0..size {
                expected[(i, j)] += omega * omega * row[i] * row[j];
            }
        }
    }
    let scale = expected.norm_max();
    let mut lower = faer::Mat::<f64>::from_fn(size, size, |_, _| f64::NAN);
    system.constrained_normal_matrix_lower_into(model, &handles, omega, lower.as_mut());
    let full = system.constrained_normal_matrix(model, &handles, omega);
    for j in 0..size {
        for i in j..size {
            assert!((lower[(i, j)] - expected[(i, j)]).abs() <= 1e-12 * scale, "lower ({i}, {j})");
        }
        for i in 0..size {
            assert!((full[(i, j)] - expected[(i, j)]).abs() <= 1e-12 * scale, "full ({i}, {j})");
        }
    }
}

/// Section 5's remedy: at least `min_fields` fields at precompute, and more when a handle set has
/// more regions than `fields_per_region x` the model's fields allow; the growth is its own phase.
#[test]
fn fields_grow_to_the_handle_count_and_at_least_min_fields_are_kept() {
    let (mesh, handles) = bar();
    let params = HirmParams { min_fields: 3, fields_per_region: 3.0, max_fields: 8, ..HirmParams::default() };
    let mut hirm = Hirm::new(params).unwrap();
    hirm.precompute(&mesh).unwrap();
    let n_field = |h: &Hirm| {
        h.model_statistics().iter().find(|(k, _)| *k == methods::keys::statistic::N_FIELD).unwrap().1
    };
    let selected = n_field(&hirm);
    assert!((3.0..6.0).contains(&selected), "min_fields 3, and the bar selects 5 by phi: {selected}");
    // Two regions x 3 = 6 fields: grown at this bind.
    hirm.bind_handles(&handles).unwrap();
    assert_eq!(n_field(&hirm), 6.0);
    assert!(
        hirm.phase_timings().iter().any(|(k, _)| *k == methods::keys::phase::T_G_FIELD_GROWTH),
        "{:?}",
        hirm.phase_timings()
    );
    let t = targets(&handles, &hirm.positions(), [0.0, 0.0, 0.1]);
    let summary = hirm.solve(&t, &mut NoObserver).unwrap();
    assert!(summary.converged, "{summary:?}");
    // Five regions would need 15 fields: capped at max_fields = 8.
    let n = mesh.n_vertices() as u32;
    let regions: Vec<HandleRegion> =
        (0..5).map(|r| HandleRegion { name: format!("r{r}"), vertices: vec![r * (n / 5)] }).collect();
    hirm.bind_handles(&HandleSet::new(regions, mesh.n_vertices()).unwrap()).unwrap();
    assert_eq!(n_field(&hirm), 8.0);
}

/// Incremental editing keeps the regions of the step before: the background worker adds their
/// constraint term, and the next bind adds only the new region's rows. The factor equals that of the
/// bind that builds the whole term (the same regions in another order take that path).
#[test]
fn a_bind_that_keeps_the_previous_regions_gives_the_whole_system() {
    let (mesh, handles) = bar();
    let n = mesh.n_vertices() as u32;
    let factor_of_second_bind = |reorder: bool| -> faer::Mat<f64> {
        let mut hirm = Hirm::new(HirmParams::default()).unwrap();
        hirm.precompute(&mesh).unwrap();
        hirm.bind_handles(&handles).unwrap();
        let t = targets(&handles, &hirm.positions(), [0.0, 0.0, 0.1]);
        hirm.solve(&t, &mut NoObserver).unwrap();
        let patch = HandleRegion { name: "patch".into(), vertices: vec![n / 2, n / 2 + 1] };
        let mut regions = handles.regions().to_vec();
        if reorder {
            regions.insert(0, patch);
        } else {
            regions.push(patch);
        }
        hirm.bind_handles(&HandleSet::new(regions, mesh.n_vertices()).unwrap()).unwrap();
        hirm.handle_update_factor().to_owned()
    };
    let (kept, whole) = (factor_of_second_bind(false), factor_of_second_bind(true));
    let size = kept.nrows();
    let mut largest = 0.0f64;
    let mut scale = 0.0f64;
    for j in 0..size {
        for i in j..size {
            largest = largest.max((kept[(i, j)] - whole[(i, j)]).abs());
            scale = scale.max(whole[(i, j)].abs());
        }
    }
    assert!(
        largest <= 1e-10 * scale,
        "kept-term factor differs from the whole build by {largest:e} (of {scale:e})"
    );
}

/// A flat mesh (z = 0 everywhere, like the dataset's 2D `alligator.obj`): `W` of eq 9 does not see
/// the out-of-plane row of the transforms, so `U^T U` of eq 26 had an exact null vector and the
/// handle update's factorization failed or passed by rounding (on `alligator.obj` it failed for
/// every edit). With the plane gauge it is definite, the rest shape is a fixed point, and the strip
/// bends out of its plane with its handles where they are asked to be.
#[test]
fn a_flat_mesh_binds_and_bends_out_of_its_plane() {
    let flat = strip(4.5, 45);
    let diagonal = flat.bbox_diagonal();
    let n = flat.n_vertices() as u32;
    let end = |from: f64, to: f64| -> Vec<u32> {
        (0..n).filter(|&v| (from..=to).contains(&flat.positions()[v as usize][0])).collect()
    };
    let handles = HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: end(0.0, 0.4) },
            HandleRegion { name: "handle".into(), vertices: end(4.1, 4.5) },
        ],
        flat.n_vertices(),
    )
    .unwrap();
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&flat).unwrap();
    // U^T U is definite well above the rounding (before the gauge: the smallest eigenvalue was
    // ~1e-18 of the largest, of either sign).
    let built = handle_independent_model(flat.positions(), &hirm.system_inputs().unwrap());
    assert!(built.plane_gauge_rhs.is_some(), "the flat strip is planar");
    let normal = built.system.constrained_normal_matrix(&built.model, &handles, 1000.0);
    let eigenvalues = normal.self_adjoint_eigen(faer::Side::Lower).unwrap().S().column_vector().to_owned();
    let (smallest, largest) = (eigenvalues[0], eigenvalues[eigenvalues.nrows() - 1]);
    assert!(smallest > 1e-14 * largest, "U^T U: smallest eigenvalue {smallest:e} of {largest:e}");

    hirm.bind_handles(&handles).unwrap();
    let summary = hirm.solve(&targets(&handles, flat.positions(), [0.0; 3]), &mut NoObserver).unwrap();
    let moved = methods::method::max_displacement(&hirm.positions(), flat.positions());
    assert!(moved < FIXED_POINT * diagonal, "rest shape moved by {moved}");
    // Steps of rounding do not contract: the distance bound ends the solve at a step of a thousandth
    // of the tolerance (measured: 4-6 iterations at steps ~5e-9 of the diagonal).
    assert!(summary.converged && summary.iterations <= 8, "{summary:?}");

    // The moved end turned 45 degrees about the y axis through its middle, out of the plane.
    let (c, s) = (std::f64::consts::FRAC_PI_4.cos(), std::f64::consts::FRAC_PI_4.sin());
    let rest = flat.positions();
    let turned: Vec<[f64; 3]> = handles
        .regions()
        .iter()
        .flat_map(|r| r.vertices.iter().map(move |&v| (r.name == "handle", rest[v as usize])))
        .map(|(moved, p)| if moved { [4.3 + c * (p[0] - 4.3), p[1], s * (p[0] - 4.3)] } else { p })
        .collect();
    let summary =
        hirm.solve(&HandleTargets::new(&handles, turned.clone()).unwrap(), &mut NoObserver).unwrap();
    assert!(summary.converged, "{summary:?}");
    let result = hirm.positions();
    let residual = handles
        .constrained()
        .zip(&turned)
        .map(|(v, t)| methods::method::max_displacement(&[result[v as usize]], &[*t]))
        .fold(0.0, f64::max);
    assert!(residual < 1e-4 * diagonal, "handle residual {:e} diagonals", residual / diagonal);
    // The free middle bends out of the plane like a thin plate: the cubic `z(x)` of least bending
    // that leaves the held end flat (x = 0.4) and meets the turned end's inner edge (x = 4.1) at its
    // height and 45 degree slope dips below the plane and comes back up, and the mean height of the
    // strip follows it to 0.1 (2% of the length).
    let (x0, x1) = (0.4, 4.1);
    let (z1, slope) = (s * (x1 - 4.3), 1.0);
    let length = x1 - x0;
    let b = (slope * length - 2.0 * z1) / length.powi(3);
    let a = (z1 - b * length.powi(3)) / (length * length);
    let cubic = |x: f64| a * (x - x0).powi(2) + b * (x - x0).powi(3);
    for x in [1.0, 2.0, 3.0, 4.0] {
        let near: Vec<usize> = (0..n as usize).filter(|&v| (rest[v][0] - x).abs() < 0.05).collect();
        let height = near.iter().map(|&v| result[v][2]).sum::<f64>() / near.len() as f64;
        assert!((height - cubic(x)).abs() < 0.1, "height {height} at x = {x}, thin plate {}", cubic(x));
    }
}
