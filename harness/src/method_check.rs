//! `harness check-method NAME`: a method author's first command. It runs the whole protocol once
//! on a tiny built-in mesh (the procedural bar at about 300 vertices): start and `hello`,
//! `precompute`, a first `bind` (fixed end and twisted end) and `solve`, a second `bind` (one more
//! region held where the first solve left it) and `solve`, then `quit`, and says after each step
//! what is wrong in plain words (the harness's own reading of the answer: docs/protocol.md) or
//! what came back, with the times. Exit 0 when the method speaks the protocol.

use std::fmt::Write as _;
use std::time::Instant;

use meshes::shapes::{generate, ShapeKind};
use meshes::{TriMesh, VertexStatus};
use methods::{HandleRegion, HandleSet, HandleTargets, NoObserver};

use crate::config::ConfiguredMethod;

/// Vertices of the tiny bar the check runs on.
pub const CHECK_VERTICES: usize = 300;

/// What the check found: a line per step (`ok` or what went wrong) and whether every step passed.
#[derive(Debug, Default)]
pub struct MethodCheck {
    pub lines: Vec<String>,
    pub passed: bool,
}

/// Run the protocol check of `method` (see the module doc).
pub fn check(method: &ConfiguredMethod) -> MethodCheck {
    let mut out = MethodCheck { lines: Vec::new(), passed: false };
    if let Some(why) = &method.unavailable {
        out.lines.push(format!("FAIL  entry: `{}` cannot run here: {why}", method.name));
        return out;
    }
    let shape = match generate(ShapeKind::Bar, CHECK_VERTICES) {
        Ok(shape) => shape,
        Err(e) => {
            out.lines.push(format!("FAIL  the check's mesh: {e}"));
            return out;
        }
    };
    let mesh = &shape.mesh;
    let of = |status: VertexStatus| -> Vec<u32> {
        (0..mesh.n_vertices() as u32).filter(|&v| shape.selection[v as usize] == status).collect()
    };
    let (fixed, handle) = (of(VertexStatus::Fixed), of(VertexStatus::Handle));
    let diagonal = mesh.bbox_diagonal();

    let started = Instant::now();
    let mut m = match method.create(None, 1) {
        Ok(m) => m,
        Err(e) => {
            out.lines.push(format!("FAIL  start and hello: {e}"));
            return out;
        }
    };
    let about = m.about().map_or(String::new(), |a| format!(" (about: {a})"));
    out.lines.push(format!("ok    start and hello: {}{about}", seconds(started.elapsed().as_secs_f64())));

    let t = Instant::now();
    if let Err(e) = m.precompute(mesh) {
        out.lines.push(format!(
            "FAIL  precompute ({} vertices, {} faces): {e}",
            mesh.n_vertices(),
            mesh.n_faces()
        ));
        return out;
    }
    out.lines.push(format!(
        "ok    precompute ({} vertices, {} faces): {}",
        mesh.n_vertices(),
        mesh.n_faces(),
        seconds(t.elapsed().as_secs_f64())
    ));

    // Step 1: the survey's twist of the bar's end. Step 2: also hold the free vertex nearest the
    // middle where step 1 left it (a handle set changed mid-edit, as incremental editing does).
    let middle = nearest_free(mesh, &shape.selection);
    let steps: [(&str, Vec<HandleRegion>); 2] = [
        ("first bind (2 regions) and solve", vec![region("fixed", &fixed), region("handle", &handle)]),
        (
            "second bind (3 regions) and solve",
            vec![region("fixed", &fixed), region("handle", &handle), region("middle", &[middle])],
        ),
    ];
    for (what, regions) in steps {
        let current = m.positions();
        let handles = match HandleSet::new(regions, mesh.n_vertices()) {
            Ok(h) => h,
            Err(e) => {
                out.lines.push(format!("FAIL  {what}: the check's handles: {e}"));
                return out;
            }
        };
        let targets: Vec<[f64; 3]> = handles
            .constrained()
            .map(|v| {
                let p = mesh.positions()[v as usize];
                match shape.selection[v as usize] {
                    VertexStatus::Handle => shape.transform.apply(p),
                    VertexStatus::Fixed => p,
                    _ => current.get(v as usize).copied().unwrap_or(p),
                }
            })
            .collect();
        let targets = match HandleTargets::new(&handles, targets) {
            Ok(t) => t,
            Err(e) => {
                out.lines.push(format!("FAIL  {what}: the check's targets: {e}"));
                return out;
            }
        };
        let t = Instant::now();
        if let Err(e) = m.bind_handles(&handles) {
            out.lines.push(format!("FAIL  {what}: bind: {e}"));
            return out;
        }
        let bind_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let summary = match m.solve(&targets, &mut NoObserver) {
            Ok(s) => s,
            Err(e) => {
                out.lines.push(format!("FAIL  {what}: solve: {e}"));
                return out;
            }
        };
        let solve_s = t.elapsed().as_secs_f64();
        let positions = m.positions();
        let residual = handles
            .constrained()
            .zip(targets.positions())
            .map(|(v, t)| meshes::vector::norm(meshes::vector::sub(positions[v as usize], *t)))
            .fold(0.0, f64::max)
            / diagonal;
        let mut line = format!("ok    {what}: bind {}, solve {}", seconds(bind_s), seconds(solve_s));
        let _ = write!(line, "; {} iteration(s)", summary.iterations);
        let _ = write!(
            line,
            "; converged: {}",
            if summary.convergence_unknown {
                "not said (an iterative entry: its cases are `suspect: convergence unknown`)".to_string()
            } else {
                summary.converged.to_string()
            }
        );
        let _ = write!(line, "; handles off their targets by {residual:.1e} of the diagonal");
        out.lines.push(line);
    }
    let t = Instant::now();
    drop(m);
    out.lines.push(format!("ok    quit: {}", seconds(t.elapsed().as_secs_f64())));
    out.passed = true;
    out
}

fn region(name: &str, vertices: &[u32]) -> HandleRegion {
    HandleRegion { name: name.to_string(), vertices: vertices.to_vec() }
}

/// The free vertex nearest the middle of the bounding box.
fn nearest_free(mesh: &TriMesh, selection: &[VertexStatus]) -> u32 {
    let (lo, hi) = mesh.bbox();
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    (0..mesh.n_vertices())
        .filter(|&v| selection[v] == VertexStatus::Free)
        .min_by(|&a, &b| {
            let d = |v: usize| meshes::vector::norm(meshes::vector::sub(mesh.positions()[v], centre));
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(0) as u32
}

fn seconds(s: f64) -> String {
    if s < 1.0 {
        format!("{:.1} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}
