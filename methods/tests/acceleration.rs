//! Anderson acceleration of the Laplacian-editing iterations (`laplacian`, `isolines`,
//! `isolines_t1`, `hirm`; `arap`'s is tested in reference_methods.rs) changes the path, not the
//! fixed point: run to a tight tolerance, the accelerated and the plain iteration end at the same
//! shape, and the accelerated one gets there in fewer iterations.

mod fixtures;

use methods::method::max_displacement;
use methods::registry::{self, create};
use methods::{NoObserver, SolveSummary};

/// `name` with its configs/methods.toml parameters, but `acceleration` ("anderson" or "none") and
/// run to `tolerance`, on the fixture bar's twist (1.5K vertices): its summary and shape.
fn run(name: &str, acceleration: &str, tolerance: f64) -> (SolveSummary, Vec<[f64; 3]>) {
    let bar = fixtures::bar(1500);
    let handles = bar.handles();
    let targets = bar.handle_moved_by(&handles, &bar.edit);
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs/methods.toml");
    let config: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
    let mut params = config[name].as_table().unwrap().clone();
    params.insert("max_iterations".into(), 20000.into());
    params.insert("tolerance".into(), tolerance.into());
    params.insert("acceleration".into(), acceleration.into());
    let mut m = create(name, &params).unwrap();
    m.precompute(&bar.mesh).unwrap();
    m.bind_handles(&handles).unwrap();
    let summary = m.solve(&targets, &mut NoObserver).unwrap();
    (summary, m.positions())
}

#[test]
fn acceleration_reaches_the_plain_fixed_point() {
    let diagonal = fixtures::bar(1500).mesh.bbox_diagonal();
    let mut failures = Vec::new();
    // hirm's plain iteration jitters at steps of 2-3e-8 diagonals (20000 iterations), so it is run
    // to 1e-7.
    let methods = [
        (registry::LAPLACIAN, 1e-10),
        (registry::ISOLINES, 1e-10),
        (registry::ISOLINES_T1, 1e-10),
        (registry::HIRM, 1e-7),
    ];
    for (name, tolerance) in methods {
        let (plain, plain_shape) = run(name, "none", tolerance);
        let (accelerated, accelerated_shape) = run(name, "anderson", tolerance);
        let apart = max_displacement(&plain_shape, &accelerated_shape) / diagonal;
        eprintln!(
            "{name:<12} plain {} iterations, anderson {} iterations, {apart:.1e} diagonals apart",
            plain.iterations, accelerated.iterations
        );
        // Both stop at a step below the tolerance; what is left of a contracting iteration after
        // such a step is a few (measured: 5) tolerances, far below 100.
        if !(plain.converged && accelerated.converged && apart < 100.0 * tolerance) {
            failures.push(format!("{name}: {plain:?} {accelerated:?}, {apart:e} apart"));
        }
        if accelerated.iterations > plain.iterations {
            failures.push(format!(
                "{name}: anderson took {} iterations, plain {}",
                accelerated.iterations, plain.iterations
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
