//! Properties of `scale_aware` (Liu, Wang, Liu & Liu 2014): the rest mesh solves its own scale-aware
//! equations, the equations and the method are invariant to similarities (a scaled and rotated copy
//! given as constraints is reproduced), step one keeps unit normals and leaves rest normals alone,
//! the optimal rigidity approximation restores every triangle's rest area before stitching, the
//! Anderson acceleration finds the plain iteration's fixed point, and bad input gives errors.

use meshes::geometry::{face_areas, face_normals};
use meshes::shapes::{generate, ShapeKind};
use meshes::vector::{norm, sub};
use meshes::{Topology, TriMesh, VertexStatus};
use methods::scale_aware::{
    rescaled_triangles, AndersonAcceleration, LaterStart, NormalPyramids, ScaleAware, ScaleAwareEquations,
    ScaleAwareParams, ScaleInvariantMeasures, SolveMemo,
};
use methods::{DeformationMethod, HandleRegion, HandleSet, HandleTargets, MethodError, NoObserver};

/// Procedural cylinder (~800 vertices) with its fixed and handle regions.
fn cylinder() -> (TriMesh, HandleSet) {
    cylinder_of(800)
}

/// Procedural cylinder of about `vertices` vertices with its fixed and handle regions.
fn cylinder_of(vertices: usize) -> (TriMesh, HandleSet) {
    let shape = generate(ShapeKind::Cylinder, vertices).unwrap();
    let region = |name: &str, status| HandleRegion {
        name: name.into(),
        vertices: meshes::edit::vertices_with_status(&shape.selection, status),
    };
    let regions = vec![region("fixed", VertexStatus::Fixed), region("handle", VertexStatus::Handle)];
    let handles = HandleSet::new(regions, shape.mesh.n_vertices()).unwrap();
    (shape.mesh, handles)
}

fn equations(mesh: &TriMesh) -> ScaleAwareEquations {
    let topology = Topology::new(mesh).unwrap();
    let measures = ScaleInvariantMeasures::new(mesh.positions(), mesh.triangles(), &topology);
    ScaleAwareEquations::new(mesh.n_vertices(), mesh.triangles(), measures)
}

/// `|G V| / |edges|`: the corner residuals relative to the edge vectors they compare.
fn relative_residual(
    equations: &ScaleAwareEquations,
    normals: &[[f64; 3]],
    mesh: &TriMesh,
    v: &[[f64; 3]],
) -> f64 {
    let residual: f64 = equations.residual(normals, v).iter().flatten().flatten().map(|r| r * r).sum();
    let edges: f64 = mesh
        .triangles()
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .map(|(a, b)| norm(sub(v[a as usize], v[b as usize])).powi(2))
        .sum();
    (residual / edges).sqrt()
}

/// `p -> scale * R p + shift` with `R` the rotation by `angle` about the unit `axis`.
fn similarity(p: [f64; 3], scale: f64, axis: [f64; 3], angle: f64, shift: [f64; 3]) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let d = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
    let cross =
        [axis[1] * p[2] - axis[2] * p[1], axis[2] * p[0] - axis[0] * p[2], axis[0] * p[1] - axis[1] * p[0]];
    std::array::from_fn(|i| scale * (c * p[i] + s * cross[i] + (1.0 - c) * d * axis[i]) + shift[i])
}

fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter().zip(b).map(|(p, q)| norm(sub(*p, *q))).fold(0.0, f64::max)
}

fn targets_from(handles: &HandleSet, positions: &[[f64; 3]]) -> HandleTargets {
    HandleTargets::new(handles, handles.constrained().map(|v| positions[v as usize]).collect()).unwrap()
}

#[test]
fn rest_mesh_solves_its_scale_aware_equations() {
    let (mesh, _) = cylinder();
    let eqs = equations(&mesh);
    let normals = face_normals(mesh.positions(), mesh.triangles());
    let r = relative_residual(&eqs, &normals, &mesh, mesh.positions());
    assert!(r < 1e-10, "|G(Theta, N_rest) V_rest| / |edges| = {r:e}");
    // The equations are not trivially satisfied: the rest shape with a flipped normal field is not a
    // solution (rotations by -theta).
    let flipped: Vec<[f64; 3]> = normals.iter().map(|n| n.map(|c| -c)).collect();
    assert!(relative_residual(&eqs, &flipped, &mesh, mesh.positions()) > 0.1);
}

#[test]
fn equations_are_invariant_to_similarities() {
    let (mesh, _) = cylinder();
    let eqs = equations(&mesh);
    let axis = [0.48, 0.6, 0.64];
    let copy: Vec<[f64; 3]> =
        mesh.positions().iter().map(|&p| similarity(p, 2.5, axis, 0.9, [0.3, -1.0, 2.0])).collect();
    let normals = face_normals(&copy, mesh.triangles());
    let r = relative_residual(&eqs, &normals, &mesh, &copy);
    assert!(r < 1e-10, "|G(Theta, N_copy) V_copy| / |edges| = {r:e}");
}

#[test]
fn rest_shape_is_a_fixed_point_of_the_method() {
    let (mesh, handles) = cylinder();
    let mut m = ScaleAware::new("scale_aware", ScaleAwareParams::default()).unwrap();
    m.precompute(&mesh).unwrap();
    m.bind_handles(&handles).unwrap();
    let summary = m.solve(&targets_from(&handles, mesh.positions()), &mut NoObserver).unwrap();
    assert!(summary.converged);
    let d = max_distance(&m.positions(), mesh.positions()) / mesh.bbox_diagonal();
    assert!(d < 1e-9, "rest shape moved by {d:e} x diagonal");
}

#[test]
fn constraints_from_a_scaled_and_rotated_copy_reproduce_the_copy() {
    let (mesh, handles) = cylinder();
    let copy: Vec<[f64; 3]> =
        mesh.positions().iter().map(|&p| similarity(p, 1.6, [0.0, 0.6, 0.8], 0.5, [0.2, 0.1, 0.0])).collect();
    let params = ScaleAwareParams { tolerance: 1e-10, max_iterations: 300, ..Default::default() };
    let mut m = ScaleAware::new("scale_aware", params).unwrap();
    m.precompute(&mesh).unwrap();
    m.bind_handles(&handles).unwrap();
    let summary = m.solve(&targets_from(&handles, &copy), &mut NoObserver).unwrap();
    assert!(summary.converged, "{summary:?}");
    // The Laplacian initialization is far from the copy; Algorithm 1 has to get there.
    let diagonal = 1.6 * mesh.bbox_diagonal();
    let d = max_distance(&m.positions(), &copy) / diagonal;
    assert!(d < 1e-6, "result is {d:e} x diagonal from the similar copy");
}

#[test]
fn step_one_keeps_unit_normals_and_rest_normals() {
    let (mesh, _) = cylinder();
    let rest_normals = face_normals(mesh.positions(), mesh.triangles());
    let pyramids = NormalPyramids::new(mesh.positions(), mesh.triangles(), &rest_normals, Default::default());
    let n = mesh.n_vertices();
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (mut rotations, mut frames) = (vec![identity; n], vec![identity; n]);

    // Rest normals: every pyramid is already rigid, nothing moves.
    let mut normals = rest_normals.clone();
    let update = pyramids.update_normals(&mut normals, &mut rotations, &mut frames, 20, 1e-12);
    assert_eq!(update.iterations, 1);
    assert!(max_distance(&normals, &rest_normals) < 1e-12);

    // Normals of a bent copy: updated normals stay on the unit sphere.
    let bent: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [p[0] + 0.8 * p[2] * p[2], p[1], p[2]]).collect();
    let mut normals = face_normals(&bent, mesh.triangles());
    let before = normals.clone();
    let update = pyramids.update_normals(&mut normals, &mut rotations, &mut frames, 10, 0.0);
    assert_eq!(update.iterations, 10);
    let defect = normals.iter().map(|n| (norm(*n) - 1.0).abs()).fold(0.0, f64::max);
    assert!(defect < 1e-12, "| |N| - 1 | up to {defect:e}");
    assert!(max_distance(&normals, &before) > 1e-3, "step one changed nothing on a bent shape");
}

#[test]
fn ora_rescales_every_triangle_to_its_rest_area() {
    let (mesh, _) = cylinder();
    let rest_areas = face_areas(mesh.positions(), mesh.triangles());
    // A non-uniform deformation: stretch along z, squash along x.
    let deformed: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [0.5 * p[0], p[1], 1.0 * p[2] * (1.0 + p[2])]).collect();
    let rescaled = rescaled_triangles(&deformed, mesh.triangles(), &rest_areas);
    for (f, (corners, &rest)) in rescaled.iter().zip(&rest_areas).enumerate() {
        let area =
            0.5 * norm(meshes::vector::cross(sub(corners[1], corners[0]), sub(corners[2], corners[0])));
        assert!((area - rest).abs() <= 1e-6 * rest, "face {f}: area {area} vs rest {rest}");
    }
}

#[test]
fn ora_variant_runs_and_stays_near_the_handles() {
    let (mesh, handles) = cylinder();
    let bent: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [p[0] + 0.3 * p[2] * p[2], p[1], p[2]]).collect();
    let params = ScaleAwareParams { optimal_rigidity: true, ..Default::default() };
    let mut m = ScaleAware::new("scale_aware_ora", params).unwrap();
    m.precompute(&mesh).unwrap();
    m.bind_handles(&handles).unwrap();
    let targets = targets_from(&handles, &bent);
    m.solve(&targets, &mut NoObserver).unwrap();
    let result = m.positions();
    let residual = handles
        .constrained()
        .zip(targets.positions())
        .map(|(v, t)| norm(sub(result[v as usize], *t)))
        .fold(0.0, f64::max);
    assert!(residual < 1e-2 * mesh.bbox_diagonal(), "handle residual {residual}");
    assert!(m.phase_timings().iter().any(|(k, _)| *k == methods::keys::phase::ORA_STITCHING));
}

/// Records every iteration report, and the iterate of the first three.
struct Reports(Vec<(methods::IterationReport, Option<Vec<[f64; 3]>>)>);

impl methods::IterationObserver for Reports {
    fn on_iteration(
        &mut self,
        report: &methods::IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> std::ops::ControlFlow<()> {
        let iterate = if report.iteration < 3 { shape.map(|shape| shape()) } else { None };
        self.0.push((*report, iterate));
        std::ops::ControlFlow::Continue(())
    }
}

#[test]
fn ora_takes_an_identical_scale_aware_solve_and_gives_the_same_result() {
    let (mesh, handles) = cylinder_of(640);
    let bent: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [p[0] + 0.2 * p[2] * p[2], p[1], p[2]]).collect();
    let targets = targets_from(&handles, &bent);
    // The instances of this test share one memo; an instance with a memo of its own takes nothing.
    let shared = SolveMemo::default();
    let run_with = |params: ScaleAwareParams, name: &'static str, memo: &SolveMemo| {
        let mut m = ScaleAware::sharing(name, params, memo.clone()).unwrap();
        m.precompute(&mesh).unwrap();
        m.bind_handles(&handles).unwrap();
        let mut reports = Reports(Vec::new());
        let summary = m.solve(&targets, &mut reports).unwrap();
        (m, summary, reports.0)
    };
    let run = |params: ScaleAwareParams, name: &'static str| run_with(params, name, &shared);
    // A second edit step from the (stitched) result: no solve of it is stored, so it is computed.
    let second_step = |m: &mut ScaleAware| {
        let further =
            targets_from(&handles, &bent.iter().map(|p| [p[0], p[1] + 0.1 * p[2], p[2]]).collect::<Vec<_>>());
        m.solve(&further, &mut NoObserver).unwrap();
        assert_eq!(m.reused_solve(), None);
        m.positions()
    };
    let ora = ScaleAwareParams { optimal_rigidity: true, ..Default::default() };
    let (mut computed, computed_summary, computed_reports) = run(ora.clone(), "scale_aware_ora");
    assert_eq!(computed.reused_solve(), None, "nothing to take yet");
    let (plain, plain_summary, _) = run(ScaleAwareParams::default(), "scale_aware");
    assert_eq!(plain.reused_solve(), None, "scale_aware never takes a solve");
    assert_eq!(plain_summary.iterations + 1, computed_summary.iterations, "ORA adds one stitching step");
    let (mut taken, taken_summary, taken_reports) = run(ora.clone(), "scale_aware_ora");
    let reused = taken.reused_solve().expect("the scale_aware solve of the same inputs is taken");
    assert_eq!(reused.from, "scale_aware");
    assert!(reused.seconds > 0.0);
    assert_eq!(taken.positions(), computed.positions(), "taking the solve changes no bit of the result");
    assert_eq!(taken_summary, computed_summary);
    assert_eq!(taken_reports.len(), computed_reports.len());
    for ((t, t_iterate), (c, c_iterate)) in taken_reports.iter().zip(&computed_reports) {
        assert_eq!((t.iteration, t.step), (c.iteration, c.step));
        assert_eq!(t_iterate, c_iterate, "iteration {}: the iterate the observer asked for", t.iteration);
    }
    assert!(taken_reports[1].1.is_some(), "the iterates asked for are replayed");
    assert!(max_distance(&plain.positions(), &taken.positions()) > 0.0, "the stitching moved the result");
    assert_eq!(second_step(&mut taken), second_step(&mut computed), "nor that of the next edit step");
    let (alone, _, _) = run_with(ora.clone(), "scale_aware_ora", &SolveMemo::default());
    assert_eq!(alone.reused_solve(), None, "a memo of its own holds no other instance's solve");

    // Another constraint weight: a solve of other inputs is not taken.
    let (other, _, _) = run(ScaleAwareParams { constraint_weight: 50.0, ..ora }, "scale_aware_ora");
    assert_eq!(other.reused_solve(), None, "another lambda is another solve");
}

/// The solve of a bend of the procedural cylinder with `params`, to a tight tolerance: the result
/// and the step-two statistics (refactorizations, lagged steps).
fn tight_bend(params: ScaleAwareParams) -> (Vec<[f64; 3]>, f64, f64, f64) {
    let (mesh, handles) = cylinder();
    let bent: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [p[0] + 0.3 * p[2] * p[2], p[1], p[2]]).collect();
    let params = ScaleAwareParams { tolerance: 1e-10, max_iterations: 3000, ..params };
    let mut m = ScaleAware::new("scale_aware", params).unwrap();
    m.precompute(&mesh).unwrap();
    m.bind_handles(&handles).unwrap();
    let summary = m.solve(&targets_from(&handles, &bent), &mut NoObserver).unwrap();
    assert!(summary.converged, "{summary:?}");
    let statistic = |key: &str| m.model_statistics().iter().find(|(k, _)| k == key).unwrap().1;
    let (refactorizations, lagged) = (
        statistic(methods::keys::statistic::REFACTORIZATIONS),
        statistic(methods::keys::statistic::LAGGED_STEPS),
    );
    (m.positions(), mesh.bbox_diagonal(), refactorizations, lagged)
}

#[test]
fn lagged_factorization_meets_the_refactor_every_iteration_fixed_point() {
    // The plain iteration (no Anderson: one path per map), step two exact every time or lagged.
    let plain = ScaleAwareParams { anderson_depth: 0, ..Default::default() };
    let (exact, diagonal, exact_factors, exact_lagged) =
        tight_bend(ScaleAwareParams { refactor_turn: 0.0, ..plain.clone() });
    let (lagged, _, lagged_factors, lagged_steps) =
        tight_bend(ScaleAwareParams { refactor_turn: 0.1, ..plain });
    assert_eq!(exact_lagged, 0.0, "refactor_turn = 0 refactors every time");
    assert!(exact_factors > 10.0);
    assert!(
        lagged_steps > 2.0 * lagged_factors,
        "{lagged_factors} factorizations, {lagged_steps} lagged steps"
    );
    let d = max_distance(&exact, &lagged) / diagonal;
    assert!(d < 1e-7, "the lagged path ends {d:.2e} of the diagonal from the exact path's fixed point");
}

#[test]
fn an_accelerated_solve_stops_within_its_tolerance_of_the_limit_of_its_path() {
    // The same solve stopped by the default tolerance and run on to 1e-10: the first must be within
    // its 1e-4 of the diagonal of the second (the stopping rule takes the plain map's secant
    // contraction; from the accelerated steps alone it stopped 1.4e-3 away here).
    let params = ScaleAwareParams { refactor_turn: 0.0, ..Default::default() };
    let (limit, diagonal, _, _) = tight_bend(params.clone());
    let (mesh, handles) = cylinder();
    let bent: Vec<[f64; 3]> =
        mesh.positions().iter().map(|p| [p[0] + 0.3 * p[2] * p[2], p[1], p[2]]).collect();
    let mut m = ScaleAware::new("scale_aware", params).unwrap();
    m.precompute(&mesh).unwrap();
    m.bind_handles(&handles).unwrap();
    let summary = m.solve(&targets_from(&handles, &bent), &mut NoObserver).unwrap();
    assert!(summary.converged);
    let d = max_distance(&m.positions(), &limit) / diagonal;
    assert!(d < 1e-4, "stopped {d:.2e} of the diagonal from the limit ({summary:?})");
}

#[test]
fn a_later_solve_starts_from_the_last_result_or_from_its_laplacian_editing() {
    // A second solve of the same targets: from the last result (a warm start) iteration 0 does
    // not move the shape; from Laplacian editing of it (the default) it does.
    let first_step = |later_start| {
        let (mesh, handles) = cylinder();
        let bent: Vec<[f64; 3]> =
            mesh.positions().iter().map(|p| [p[0] + 0.3 * p[2] * p[2], p[1], p[2]]).collect();
        let params = ScaleAwareParams { later_start, ..Default::default() };
        let mut m = ScaleAware::new("scale_aware", params).unwrap();
        m.precompute(&mesh).unwrap();
        m.bind_handles(&handles).unwrap();
        let targets = targets_from(&handles, &bent);
        m.solve(&targets, &mut NoObserver).unwrap();
        let mut reports = Reports(Vec::new());
        m.solve(&targets, &mut reports).unwrap();
        reports.0[0].0.step
    };
    assert_eq!(first_step(LaterStart::PreviousResult), 0.0);
    assert!(first_step(LaterStart::Laplacian) > 1e-4);
}

#[test]
fn anderson_acceleration_finds_the_fixed_point_sooner() {
    // T(x) = A x + b with a slow contraction A = diag(0.99, 0.5, 0.9): fixed point b_i / (1 - a_i).
    let a = [0.99, 0.5, 0.9];
    let b = [1.0, 2.0, -1.0];
    let fixed: Vec<f64> = (0..3).map(|i| b[i] / (1.0 - a[i])).collect();
    let iterate = |depth: usize| {
        let mut aa = AndersonAcceleration::new(depth, 3);
        let mut x = vec![0.0; 3];
        for k in 0..200 {
            let g: Vec<f64> = (0..3).map(|i| a[i] * x[i] + b[i]).collect();
            if (0..3).all(|i| (g[i] - x[i]).abs() < 1e-10) {
                return (k, x);
            }
            let mut next = vec![0.0; 3];
            aa.next(&x, &g, &mut next);
            x = next;
        }
        (200, x)
    };
    let (plain_steps, _) = iterate(0);
    let (steps, x) = iterate(3);
    assert_eq!(plain_steps, 200, "the plain iteration needs thousands of steps here");
    assert!(steps < 20, "Anderson took {steps} steps");
    for i in 0..3 {
        assert!((x[i] - fixed[i]).abs() < 1e-8 * fixed[i].abs().max(1.0), "x = {x:?}, fixed point {fixed:?}");
    }
}

#[test]
fn bad_parameters_handle_sets_and_phase_order_are_errors() {
    let bad = ScaleAwareParams { constraint_weight: f64::NAN, ..Default::default() };
    assert!(matches!(ScaleAware::new("scale_aware", bad), Err(MethodError::InvalidParameters { .. })));
    let bad = ScaleAwareParams { anderson_depth: 100, ..Default::default() };
    assert!(matches!(ScaleAware::new("scale_aware", bad), Err(MethodError::InvalidParameters { .. })));

    let (mesh, handles) = cylinder();
    let mut m = ScaleAware::new("scale_aware", ScaleAwareParams::default()).unwrap();
    assert!(matches!(m.bind_handles(&handles), Err(MethodError::Phase { .. })));
    m.precompute(&mesh).unwrap();
    let targets = targets_from(&handles, mesh.positions());
    assert!(matches!(m.solve(&targets, &mut NoObserver), Err(MethodError::Phase { .. })));
    let two = HandleSet::new(
        vec![
            HandleRegion { name: "a".into(), vertices: vec![0] },
            HandleRegion { name: "b".into(), vertices: vec![1] },
        ],
        mesh.n_vertices(),
    )
    .unwrap();
    let err = m.bind_handles(&two).unwrap_err().to_string();
    assert!(err.contains("at least three constrained vertices"), "{err}");
}
