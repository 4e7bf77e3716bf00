//! Properties of the reference methods `laplacian` and `arap` that must hold on any mesh:
//! fixed points, rigid invariance, constraint satisfaction, incremental binding, determinism, and
//! clear errors for bad input.

mod fixtures;

use fixtures::Bar;
use meshes::{AffineTransform, TriMesh};
use methods::registry::create;
use methods::{HandleRegion, HandleSet, HandleTargets, MethodError, NoObserver};

const REFERENCE: [&str; 2] = ["laplacian", "arap"];

fn params(text: &str) -> toml::Table {
    text.parse().unwrap()
}

/// The fixture's bar at ~1.5K vertices, with its survey-style fixed and handle regions.
fn bar() -> Bar {
    fixtures::bar(1500)
}

fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    methods::method::max_displacement(a, b)
}

fn run(name: &str, p: &str, mesh: &TriMesh, handles: &HandleSet, targets: &HandleTargets) -> Vec<[f64; 3]> {
    let mut m = create(name, &params(p)).unwrap();
    m.precompute(mesh).unwrap();
    m.bind_handles(handles).unwrap();
    m.solve(targets, &mut NoObserver).unwrap();
    m.positions()
}

#[test]
fn rest_shape_is_a_fixed_point() {
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    let targets = bar.rest_targets(&handles);
    for name in REFERENCE {
        let x = run(name, "", mesh, &handles, &targets);
        let d = max_distance(&x, mesh.positions()) / mesh.bbox_diagonal();
        assert!(d < 1e-9, "{name}: rest shape moved by {d:e} x diagonal");
    }
}

#[test]
fn rigid_motion_of_all_handles_moves_the_mesh_rigidly() {
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    let rigid = AffineTransform::rotation_about([0.3, 1.0, 0.2], 0.5, [1.0, 2.0, 40.0])
        .compose(&AffineTransform::translation([3.0, -1.0, 2.0]));
    let targets = bar.targets_by(&handles, |_, p| rigid.apply(p));
    let expected: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| rigid.apply(p)).collect();
    for (name, p, tol) in [
        ("arap", "max_iterations = 300\ntolerance = 1e-10", 1e-6),
        ("laplacian", "max_iterations = 3000\ntolerance = 1e-10", 1e-4),
    ] {
        let x = run(name, p, mesh, &handles, &targets);
        let d = max_distance(&x, &expected) / mesh.bbox_diagonal();
        assert!(d < tol, "{name}: result is {d:e} x diagonal from the rigidly moved mesh");
    }
}

#[test]
fn handle_constraints_are_met() {
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    let twist = AffineTransform::rotation_about([0.0, 0.0, 1.0], 1.0, [0.0, 0.0, 0.0]);
    let targets = bar.handle_moved_by(&handles, &twist);
    let diag = mesh.bbox_diagonal();
    for (name, tol) in [("arap", 1e-9), ("laplacian", 1e-3)] {
        let x = run(name, "", mesh, &handles, &targets);
        let worst = handles
            .constrained()
            .zip(targets.positions())
            .map(|(v, t)| meshes::vector::norm(meshes::vector::sub(x[v as usize], *t)))
            .fold(0.0, f64::max)
            / diag;
        assert!(worst <= tol, "{name}: handle residual {worst:e} x diagonal");
    }
}

#[test]
fn rebinding_mid_edit_keeps_the_current_shape() {
    let bar = bar();
    let (mesh, handles, fixed, handle) = (&bar.mesh, bar.handles(), &bar.fixed, &bar.handle);
    let lift = AffineTransform::translation([0.0, 5.0, 0.0]);
    let targets = bar.handle_moved_by(&handles, &lift);
    for name in REFERENCE {
        let mut m = create(name, &toml::Table::new()).unwrap();
        m.precompute(mesh).unwrap();
        m.bind_handles(&handles).unwrap();
        m.solve(&targets, &mut NoObserver).unwrap();
        let before = m.positions();
        // Second step: a different handle set (the fixed region and every other handle vertex), held
        // where the first step left them. Binding must not move anything, and the solve starts from the
        // deformed shape, so the lifted end stays lifted (from the rest shape it would not).
        let half: Vec<u32> = handle.iter().copied().step_by(2).collect();
        let second = HandleSet::new(
            vec![
                HandleRegion { name: "fixed".into(), vertices: fixed.clone() },
                HandleRegion { name: "half".into(), vertices: half.clone() },
            ],
            mesh.n_vertices(),
        )
        .unwrap();
        m.bind_handles(&second).unwrap();
        assert_eq!(m.positions(), before, "{name}: binding changed the shape");
        let hold =
            HandleTargets::new(&second, second.constrained().map(|v| before[v as usize]).collect()).unwrap();
        m.solve(&hold, &mut NoObserver).unwrap();
        let after = m.positions();
        let lifted =
            handle.iter().map(|&v| after[v as usize][1] - mesh.positions()[v as usize][1]).sum::<f64>()
                / handle.len() as f64;
        assert!(lifted > 4.5, "{name}: second step forgot the first (mean lift {lifted} of 5)");
    }
}

#[test]
fn results_are_deterministic() {
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    let twist = AffineTransform::rotation_about([0.0, 0.0, 1.0], 2.0, [0.0, 0.0, 0.0]);
    let targets = bar.handle_moved_by(&handles, &twist);
    for name in REFERENCE {
        let a = run(name, "max_iterations = 20", mesh, &handles, &targets);
        let b = run(name, "max_iterations = 20", mesh, &handles, &targets);
        assert!(a == b, "{name}: two runs differ");
    }
}

#[test]
fn bad_handle_sets_are_rejected_with_their_element() {
    let n = 10;
    let region = |name: &str, v: &[u32]| HandleRegion { name: name.into(), vertices: v.to_vec() };
    let msg = |r: Result<HandleSet, MethodError>| r.unwrap_err().to_string();
    assert!(msg(HandleSet::new(vec![], n)).contains("no handle regions"));
    assert!(msg(HandleSet::new(vec![region("a", &[])], n)).contains("`a` has no vertices"));
    assert!(msg(HandleSet::new(vec![region("a", &[3, 10])], n)).contains("vertex 10 is out of range"));
    assert!(msg(HandleSet::new(vec![region("a", &[3, 3])], n)).contains("lists vertex 3 twice"));
    assert!(msg(HandleSet::new(vec![region("a", &[1, 2]), region("b", &[2])], n))
        .contains("vertex 2 is in both handle `a` and handle `b`"));
    let set = HandleSet::new(vec![region("a", &[1, 2])], n).unwrap();
    assert!(HandleTargets::new(&set, vec![[0.0; 3]]).unwrap_err().to_string().contains("1 targets for 2"));
    assert!(HandleTargets::new(&set, vec![[0.0; 3], [f64::NAN, 0.0, 0.0]])
        .unwrap_err()
        .to_string()
        .contains("vertex 2 is not finite"));
}

#[test]
fn unknown_methods_parameters_and_phase_order_are_errors() {
    let e = create("no_such_method", &toml::Table::new()).err().unwrap().to_string();
    assert!(e.contains("unknown method `no_such_method`") && e.contains("arap"), "{e}");
    let e = create("arap", &params("max_iteratons = 3")).err().unwrap().to_string();
    assert!(e.contains("max_iteratons"), "{e}");
    let e = create("laplacian", &params("omega = -1.0")).err().unwrap().to_string();
    assert!(e.contains("omega"), "{e}");
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    for name in REFERENCE {
        let mut m = create(name, &toml::Table::new()).unwrap();
        assert!(matches!(m.bind_handles(&handles), Err(MethodError::Phase { .. })));
        m.precompute(mesh).unwrap();
        let targets = bar.rest_targets(&handles);
        assert!(matches!(m.solve(&targets, &mut NoObserver), Err(MethodError::Phase { .. })));
        let other = HandleSet::new(vec![HandleRegion { name: "a".into(), vertices: vec![0] }], 5).unwrap();
        assert!(m.bind_handles(&other).is_err(), "{name}: handle set for another mesh accepted");
    }
}

/// Anderson-accelerated ARAP (Peng et al. 2018) converges to the plain iteration's fixed point on
/// the bar's survey-style edit: the plain iterates end at the accelerated result (after 12000
/// iterations, 7e-8 diagonals; after 1000 and 4000 they are still 0.1 diagonals away, on a plateau
/// where the plain step is already below 1e-6, so the plain stopping point is not the fixed point),
/// and the
/// accelerated solve needs far fewer iterations than the plain one to the same tolerance.
#[test]
fn anderson_arap_reaches_the_plain_fixed_point_in_fewer_iterations() {
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    let targets = bar.handle_moved_by(&handles, &bar.edit);
    // Weights pinned (issue 62): on this twist ARAP has more than one fixed point, and which one
    // the plain iteration falls into turns on rounding. With the tufted weights, equal to these to
    // 1e-16 on this closed bar, the plain iterates end 0.11 diagonals from Anderson's after 12,000
    // iterations: another minimum, not a slower path to the same one. What this test checks is the
    // acceleration to one fixed point, so it keeps the weights under which both reach the same.
    let run = |acceleration: &str, iterations: usize, tolerance: f64| {
        let text = format!(
            "solver = \"local_global\"\nmax_iterations = {iterations}\ntolerance = {tolerance:e}\nacceleration = \"{acceleration}\"\nstart = \"current\"\nweights = \"intrinsic_delaunay\""
        );
        let mut arap = create("arap", &params(&text)).unwrap();
        arap.precompute(mesh).unwrap();
        arap.bind_handles(&handles).unwrap();
        let summary = arap.solve(&targets, &mut NoObserver).unwrap();
        (summary, arap.positions())
    };
    let (accelerated, fixed_point) = run("anderson", 5000, 1e-9);
    assert!(accelerated.converged, "{accelerated:?}");
    let (plain, _) = run("none", 20000, 1e-6);
    let (accelerated_to_same, _) = run("anderson", 20000, 1e-6);
    assert!(plain.converged && accelerated_to_same.converged);
    assert!(
        4 * accelerated_to_same.iterations <= plain.iterations,
        "anderson {} vs plain {} iterations to 1e-6",
        accelerated_to_same.iterations,
        plain.iterations
    );
    let diagonal = mesh.bbox_diagonal();
    let distances: Vec<f64> = [1000, 4000, 12000]
        .iter()
        .map(|&k| max_distance(&run("none", k, 0.0).1, &fixed_point) / diagonal)
        .collect();
    assert!(
        distances[2] < 1e-5 && distances[2] < distances[0],
        "plain iterates after 1000, 4000, 12000 iterations are {distances:?} diagonals from the accelerated fixed point"
    );
}

#[test]
fn arap_started_by_transformation_propagation_converges_in_fewer_iterations() {
    let bar = bar();
    let (mesh, handles) = (&bar.mesh, bar.handles());
    let diagonal = mesh.bbox_diagonal();
    let solve = |start: &str, iterations: usize, targets: &HandleTargets| {
        let text = format!(
            "solver = \"local_global\"\nmax_iterations = {iterations}\ntolerance = 1e-9\nstart = \"{start}\""
        );
        let mut arap = create("arap", &params(&text)).unwrap();
        arap.precompute(mesh).unwrap();
        arap.bind_handles(&handles).unwrap();
        let summary = arap.solve(targets, &mut NoObserver).unwrap();
        (summary, arap.positions())
    };
    // The survey twist. The two starts may end in different local minima of the nonconvex energy
    // (on this 1.5K bar they do, 8% of the diagonal apart; at 50K they meet: docs/results.md,
    // "ARAP's start"), so only convergence and its cost are compared.
    let twist = bar.handle_moved_by(&handles, &bar.edit);
    let (from_rest, _) = solve("current", 20000, &twist);
    let (propagated, _) = solve("transformation_propagation", 20000, &twist);
    assert!(from_rest.converged && propagated.converged, "{from_rest:?} {propagated:?}");
    // The counts move by about 10% with the last bits of the rotation fit (propagated 517 and rest
    // 2190 with the Jacobi SVD, 563 and 2133 with Newton's fit; docs/results.md, issue 63), so the
    // test asks for 3x, within the documented 2-7x.
    assert!(
        3 * propagated.iterations <= from_rest.iterations,
        "propagated start {} iterations, rest start {}",
        propagated.iterations,
        from_rest.iterations
    );
    // Every handle moved by one rigid motion: the propagated rotations are that rotation everywhere
    // (weights summing to 1, blending that commutes with rotations), so the first global step is
    // already the answer.
    let rigid = AffineTransform::rotation_about([0.3, 1.0, 0.2], 2.5, [1.0, 2.0, 40.0])
        .compose(&AffineTransform::translation([3.0, -1.0, 2.0]));
    let targets = bar.targets_by(&handles, |_, p| rigid.apply(p));
    let expected: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| rigid.apply(p)).collect();
    let (_, first) = solve("transformation_propagation", 1, &targets);
    let d = max_distance(&first, &expected) / diagonal;
    assert!(d < 1e-9, "after one iteration the rigidly moved bar is {d:e} diagonals off");
}

/// Solves the bar's survey twist with arap's defaults and `extra` parameters; the summary, shape and
/// the method's statistics.
fn solve_with_statistics(
    bar: &Bar,
    targets: &HandleTargets,
    extra: &str,
) -> (methods::SolveSummary, Vec<[f64; 3]>, Vec<(String, f64)>) {
    let mut arap = create("arap", &params(extra)).unwrap();
    arap.precompute(&bar.mesh).unwrap();
    arap.bind_handles(&bar.handles()).unwrap();
    let summary = arap.solve(targets, &mut NoObserver).unwrap();
    (summary, arap.positions(), arap.model_statistics())
}

fn statistic(statistics: &[(String, f64)], key: &str) -> Option<f64> {
    statistics.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
}

/// Issue 51's finding: on the 1.5K bar's survey twist L-BFGS, whose iterates keep the bar's
/// symmetry, converges to a symmetric twist that is not a minimum (relative energy 8.47e-3; the
/// plain local/global iteration slides off it to 7.42e-3). The saddle test's perturbed second solve
/// must leave it for the lower energy and say so; without the test the symmetric answer stays.
#[test]
fn the_saddle_test_leaves_the_symmetric_twist_of_the_small_bar_for_a_lower_minimum() {
    use methods::keys::statistic::{SADDLE_TEST_FIRST_ENERGY, SADDLE_TEST_SECOND_KEPT};
    let bar = bar();
    let handles = bar.handles();
    let targets = bar.handle_moved_by(&handles, &bar.edit);
    let energy =
        methods::arap::ArapEnergy::new(&bar.mesh, methods::operators::LaplacianWeights::default()).unwrap();
    let (untested, symmetric, none) = solve_with_statistics(&bar, &targets, "saddle_perturbation = 0.0");
    let (tested, result, statistics) = solve_with_statistics(&bar, &targets, "");
    assert!(untested.converged && tested.converged, "{untested:?} {tested:?}");
    assert!(none.is_empty(), "no test, no statistics: {none:?}");
    let (e_symmetric, e_result) = (energy.relative_energy(&symmetric), energy.relative_energy(&result));
    eprintln!("symmetric answer {e_symmetric:.6e}, after the saddle test {e_result:.6e}, {statistics:?}");
    assert_eq!(statistic(&statistics, SADDLE_TEST_SECOND_KEPT), Some(1.0));
    let first = statistic(&statistics, SADDLE_TEST_FIRST_ENERGY).unwrap();
    assert!((first - e_symmetric).abs() <= 1e-9 * e_symmetric, "{first:e} vs {e_symmetric:e}");
    assert!(e_result < 0.95 * e_symmetric, "{e_result:e} is not below {e_symmetric:e}");
    assert!(tested.iterations > untested.iterations, "the second solve's iterations are counted");
}

/// Where the answer is a minimum (a 30° bend of the bar), the perturbed solve comes back to it, the
/// first answer is kept, and the result is bitwise that of a solve without the test.
#[test]
fn the_saddle_test_keeps_a_minimum_bitwise() {
    use methods::keys::statistic::SADDLE_TEST_SECOND_KEPT;
    let bar = bar();
    let handles = bar.handles();
    let bend = AffineTransform::rotation_about([1.0, 0.0, 0.0], 30f64.to_radians(), [0.0, 0.0, 0.0]);
    let targets = bar.handle_moved_by(&handles, &bend);
    let (_, without, _) = solve_with_statistics(&bar, &targets, "saddle_perturbation = 0.0");
    let (summary, with, statistics) = solve_with_statistics(&bar, &targets, "");
    assert!(summary.converged, "{summary:?}");
    assert_eq!(statistic(&statistics, SADDLE_TEST_SECOND_KEPT), Some(0.0), "{statistics:?}");
    assert_eq!(with, without);
}
