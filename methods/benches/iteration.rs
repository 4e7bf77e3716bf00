//! Per-iteration time of every registered method on the survey meshes (`DEFORM_SURVEY_DIR`, default
//! `../shared/deformation-survey`), or on the procedural look-alikes when the data is absent.
//!
//! Each method is precomputed and bound once; the measured routine is one `solve` call limited to a
//! single iteration (tolerance 0), continuing from the previous iterate, i.e. exactly the work the
//! harness reports as one iteration; a direct method (`spectral_mhb`) is timed for its whole solve.
//! `scripts/bench-vs-libigl` runs this next to libigl's ARAP; `scripts/test` runs it once in test
//! mode (`cargo bench -- --test`) so it keeps working.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use meshes::shapes::{generate, ShapeKind};
use meshes::{AffineTransform, TriMesh, VertexStatus};
use methods::{HandleRegion, HandleSet, HandleTargets, NoObserver};

const TESTS: [&str; 4] = ["cylinder", "bar", "cactus", "plane"];

fn survey_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("DEFORM_SURVEY_DIR").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/deformation-survey"))
    });
    dir.join("bar.off").is_file().then_some(dir)
}

fn load(name: &str) -> (String, TriMesh, Vec<VertexStatus>, AffineTransform) {
    if let Some(dir) = survey_dir() {
        let mesh = meshes::io::read_mesh(dir.join(format!("{name}.off"))).expect("survey mesh");
        let sel =
            meshes::io::read_selection(dir.join(format!("{name}.sel")), mesh.n_vertices()).expect("sel");
        let def = meshes::io::read_transform(dir.join(format!("{name}.def"))).expect("def");
        (name.to_string(), mesh, sel, def)
    } else {
        let kind: ShapeKind = name.parse().expect("shape name");
        let shape = generate(kind, meshes::shapes::default_vertex_count(kind)).expect("procedural shape");
        (format!("{name}-procedural"), shape.mesh, shape.selection, shape.transform)
    }
}

fn edit(mesh: &TriMesh, sel: &[VertexStatus], def: &AffineTransform) -> (HandleSet, HandleTargets) {
    let fixed = meshes::edit::vertices_with_status(sel, VertexStatus::Fixed);
    let handle = meshes::edit::vertices_with_status(sel, VertexStatus::Handle);
    let p = mesh.positions();
    let mut targets: Vec<[f64; 3]> = fixed.iter().map(|&v| p[v as usize]).collect();
    targets.extend(handle.iter().map(|&v| def.apply(p[v as usize])));
    let handles = HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: fixed },
            HandleRegion { name: "handle".into(), vertices: handle },
        ],
        mesh.n_vertices(),
    )
    .expect("handles");
    let targets = HandleTargets::new(&handles, targets).expect("targets");
    (handles, targets)
}

fn per_iteration(c: &mut Criterion) {
    let mut group = c.benchmark_group("iteration");
    group.sample_size(30);
    let one_iteration: toml::Table = "max_iterations = 1\ntolerance = 0.0".parse().expect("toml");
    for name in TESTS {
        let (label, mesh, sel, def) = load(name);
        let (handles, targets) = edit(&mesh, &sel, &def);
        for entry in methods::registry::METHODS {
            let mut params = if entry.iterative { one_iteration.clone() } else { toml::Table::new() };
            if entry.name == "arap" {
                // The transformation-propagation start is once per solve, not per iteration, and
                // libigl's arap_solve (scripts/bench-vs-libigl) starts from the current shape.
                params.insert("start".into(), "current".into());
            }
            let mut method = (entry.create)(&params, &Default::default()).expect("method");
            method.precompute(&mesh).expect("precompute");
            method.bind_handles(&handles).expect("bind");
            group.bench_function(BenchmarkId::new(entry.name, &label), |b| {
                b.iter(|| method.solve(&targets, &mut NoObserver).expect("solve"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, per_iteration);
criterion_main!(benches);
