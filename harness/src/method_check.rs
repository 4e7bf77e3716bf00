//! `harness check-method NAME`: a method author's first command. It runs the whole protocol once
//! on a tiny built-in mesh (the procedural bar at about 300 vertices): start and `hello`,
//! `precompute`, a first `bind` (fixed end and twisted end) and `solve`, a second `bind` (one more
//! region held where the first solve left it) and `solve`, then `quit`, and says after each step
//! what is wrong in plain words (the harness's own reading of the answer: docs/protocol.md) or
//! what came back, with the times. Exit 0 when the method speaks the protocol.

use std::cell::RefCell;
use std::fmt::Write as _;
use std::time::Instant;

use meshes::shapes::{generate, ShapeKind, TestShape};
use meshes::{TriMesh, VertexStatus};
use methods::drive::{drive, Drive, DriveFailure, DrivePhase, DrivenStep, EditStep};
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
    let steps = match check_steps(&shape) {
        Ok(steps) => steps,
        Err(line) => {
            out.lines.push(line);
            return out;
        }
    };
    let started = Instant::now();
    let mut m = match method.create(None, 1, &methods::scale_aware::SolveMemo::default()) {
        Ok(m) => m,
        Err(e) => {
            out.lines.push(format!("FAIL  start and hello: {e}"));
            return out;
        }
    };
    let about = m.about().map_or(String::new(), |a| format!(" (about: {a})"));
    out.lines.push(format!("ok    start and hello: {}{about}", seconds(started.elapsed().as_secs_f64())));
    let drive = drive(m.as_mut(), &shape.mesh, &steps, &mut NoObserver);
    out.lines.extend(drive_lines(&shape.mesh, &steps, &drive));
    if drive.failure.is_some() {
        return out;
    }
    let t = Instant::now();
    drop(m);
    out.lines.push(format!("ok    quit: {}", seconds(t.elapsed().as_secs_f64())));
    out.passed = true;
    out
}

/// A step of the check: what it is called, its handle set, the tiny bar's shape (for the targets)
/// and the positions it started from (the previous step's answer: its handle residual).
struct CheckStep<'a> {
    what: &'static str,
    handles: HandleSet,
    shape: &'a TestShape,
    started_from: RefCell<Vec<[f64; 3]>>,
}

impl EditStep for CheckStep<'_> {
    fn handles(&self) -> &HandleSet {
        &self.handles
    }

    /// The handle's twisted end, the fixed end at rest, any other region held where it is.
    fn targets(&self, current: &[[f64; 3]]) -> Result<HandleTargets, methods::MethodError> {
        *self.started_from.borrow_mut() = current.to_vec();
        let mesh = &self.shape.mesh;
        let targets: Vec<[f64; 3]> = (self.handles.constrained())
            .map(|v| {
                let p = mesh.positions()[v as usize];
                match self.shape.selection[v as usize] {
                    VertexStatus::Handle => self.shape.transform.apply(p),
                    VertexStatus::Fixed => p,
                    _ => current.get(v as usize).copied().unwrap_or(p),
                }
            })
            .collect();
        HandleTargets::new(&self.handles, targets)
    }
}

/// Step 1: the survey's twist of the bar's end. Step 2: also hold the free vertex nearest the
/// middle where step 1 left it (a handle set changed mid-edit, as incremental editing does). Or
/// the line saying why the check's own handles are wrong.
fn check_steps(shape: &TestShape) -> Result<[CheckStep<'_>; 2], String> {
    let mesh = &shape.mesh;
    let of = |status: VertexStatus| -> Vec<u32> {
        (0..mesh.n_vertices() as u32).filter(|&v| shape.selection[v as usize] == status).collect()
    };
    let (fixed, handle) = (of(VertexStatus::Fixed), of(VertexStatus::Handle));
    let middle = nearest_free(mesh, &shape.selection);
    let step =
        |what: &'static str, regions: Vec<HandleRegion>| match HandleSet::new(regions, mesh.n_vertices()) {
            Ok(handles) => Ok(CheckStep { what, handles, shape, started_from: RefCell::new(Vec::new()) }),
            Err(e) => Err(format!("FAIL  {what}: the check's handles: {e}")),
        };
    Ok([
        step("first bind (2 regions) and solve", vec![region("fixed", &fixed), region("handle", &handle)])?,
        step(
            "second bind (3 regions) and solve",
            vec![region("fixed", &fixed), region("handle", &handle), region("middle", &[middle])],
        )?,
    ])
}

/// The check's lines for `drive`: its precompute, each step that completed and what failed.
fn drive_lines(mesh: &TriMesh, steps: &[CheckStep<'_>], drive: &Drive) -> Vec<String> {
    let size = format!("{} vertices, {} faces", mesh.n_vertices(), mesh.n_faces());
    let mut lines = Vec::new();
    if drive.precompute_s.is_finite() {
        lines.push(format!("ok    precompute ({size}): {}", seconds(drive.precompute_s)));
    }
    for (k, driven) in drive.steps.iter().enumerate() {
        // Where the step left the shape: where the next one started, or the drive's end.
        let after = steps.get(k + 1).map_or_else(|| drive.positions.clone(), |s| s.started_from.take());
        let residual =
            max_displacement_of_handles(&steps[k].handles, &driven.targets, &after) / mesh.bbox_diagonal();
        lines.push(step_line(steps[k].what, driven, residual));
    }
    if let Some(DriveFailure { phase, step, error }) = &drive.failure {
        let what = step.map_or("", |s| steps[s - 1].what);
        lines.push(match phase {
            DrivePhase::Precompute => format!("FAIL  precompute ({size}): {error}"),
            DrivePhase::Targets => format!("FAIL  {what}: the check's targets: {error}"),
            DrivePhase::BindHandles => format!("FAIL  {what}: bind: {error}"),
            DrivePhase::Solve => format!("FAIL  {what}: solve: {error}"),
            DrivePhase::Result => format!("FAIL  the answer: {error}"),
        });
    }
    lines
}

/// The largest distance of a constrained vertex of `positions` from its target.
fn max_displacement_of_handles(handles: &HandleSet, targets: &HandleTargets, positions: &[[f64; 3]]) -> f64 {
    (handles.constrained().zip(targets.positions()))
        .map(|(v, t)| meshes::vector::norm(meshes::vector::sub(positions[v as usize], *t)))
        .fold(0.0, f64::max)
}

/// `ok` and what step `what` did: its times, iterations, convergence and handle residual.
fn step_line(what: &str, driven: &DrivenStep, residual: f64) -> String {
    let summary = &driven.summary;
    let mut line =
        format!("ok    {what}: bind {}, solve {}", seconds(driven.bind_s), seconds(driven.solve_s));
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
    line
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
