//! External methods over the protocol, driven directly: a well-behaved toy method round-trips
//! positions bit for bit and reports its iterations; each way of breaking the protocol becomes an
//! error naming the request and quoting the program's stderr, and kills the program with whatever
//! it started. The toy is `tests/external/toy_method.py` (standard-library Python).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use meshes::shapes::{generate, ShapeKind};
use methods::external::{ExternalMethod, ExternalSpec};
use methods::{
    DeformationMethod, HandleRegion, HandleSet, HandleTargets, IterationObserver, IterationReport,
};

fn toy() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/external/toy_method.py")
}

fn spec(mode: &str, extra: &[&str], timeout: Duration) -> ExternalSpec {
    let mut args = vec![toy().to_string_lossy().into_owned(), mode.to_string()];
    args.extend(extra.iter().map(|s| s.to_string()));
    ExternalSpec {
        name: format!("toy-{mode}"),
        program: "python3".into(),
        args,
        working_dir: None,
        env: Vec::new(),
        timeout,
        params: serde_json::json!({}),
        stderr_log: None,
        iterative: false,
    }
}

/// A small bar with its bottom ring fixed and its top lifted by an awkward fraction.
fn edit() -> (meshes::TriMesh, HandleSet, HandleTargets) {
    let mesh = generate(ShapeKind::Bar, 800).unwrap().mesh;
    let n = mesh.n_vertices();
    let (lo, hi) = mesh.bbox();
    let z = |v: usize| (mesh.positions()[v][2] - lo[2]) / (hi[2] - lo[2]);
    let bottom: Vec<u32> = (0..n).filter(|&v| z(v) < 0.05).map(|v| v as u32).collect();
    let top: Vec<u32> = (0..n).filter(|&v| z(v) > 0.95).map(|v| v as u32).collect();
    let handles = HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: bottom },
            HandleRegion { name: "top".into(), vertices: top },
        ],
        n,
    )
    .unwrap();
    let targets: Vec<[f64; 3]> = handles
        .constrained()
        .map(|v| {
            let p = mesh.positions()[v as usize];
            if z(v as usize) > 0.5 {
                [p[0] + 1.0 / 3.0, p[1] * std::f64::consts::PI, p[2] + 0.1]
            } else {
                p
            }
        })
        .collect();
    let targets = HandleTargets::new(&handles, targets).unwrap();
    (mesh, handles, targets)
}

#[derive(Default)]
struct Reports(Vec<(IterationReport, bool)>);

impl IterationObserver for Reports {
    fn on_iteration(
        &mut self,
        report: &IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> std::ops::ControlFlow<()> {
        self.0.push((*report, shape.is_some()));
        std::ops::ControlFlow::Continue(())
    }
}

/// Run every phase of `mode`; the first error's text.
fn run(spec: ExternalSpec) -> Result<Box<dyn DeformationMethod>, String> {
    let (mesh, handles, targets) = edit();
    let mut method: Box<dyn DeformationMethod> =
        Box::new(ExternalMethod::start(spec).map_err(|e| e.to_string())?);
    method.precompute(&mesh).map_err(|e| e.to_string())?;
    method.bind_handles(&handles).map_err(|e| e.to_string())?;
    method.solve(&targets, &mut Reports::default()).map_err(|e| e.to_string())?;
    Ok(method)
}

fn error_of(mode: &str) -> String {
    match run(spec(mode, &[], Duration::from_secs(60))) {
        Ok(_) => panic!("{mode}: no error"),
        Err(e) => e,
    }
}

fn assert_all(text: &str, needles: &[&str]) {
    for n in needles {
        assert!(text.contains(n), "`{n}` not in: {text}");
    }
}

/// Whether process `pid` is running (a zombie, dead but not yet reaped by init, is not).
fn running(pid: u32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Ok(stat) => {
            let state = stat.rsplit_once(')').map(|(_, rest)| rest.trim_start().chars().next());
            !matches!(state, Some(Some('Z' | 'X')))
        }
        Err(_) => false,
    }
}

#[test]
fn a_well_behaved_method_round_trips_positions_exactly_and_reports_its_iterations() {
    let (mesh, handles, targets) = edit();
    let mut method = ExternalMethod::start(spec("ok", &[], Duration::from_secs(60))).unwrap();
    assert_eq!(method.name(), "toy-ok");
    assert_eq!(method.about().as_deref(), Some("toy ok"));
    let startup = method.startup_seconds().unwrap();
    assert!(startup > 0.0 && startup.is_finite(), "{startup}");
    method.precompute(&mesh).unwrap();
    method.bind_handles(&handles).unwrap();
    let mut reports = Reports::default();
    let summary = method.solve(&targets, &mut reports).unwrap();
    assert_eq!((summary.iterations, summary.converged), (3, true));
    assert_eq!(summary.final_step, 0.0);
    // The iterations arrive after the solve, without their shapes.
    assert_eq!(reports.0.len(), 3);
    assert!(reports.0.iter().all(|(_, shape)| !shape));
    assert_eq!(reports.0[1].0.step, 0.01);
    let positions = method.positions();
    for (v, t) in handles.constrained().zip(targets.positions()) {
        let p = positions[v as usize];
        assert!((0..3).all(|k| p[k].to_bits() == t[k].to_bits()), "vertex {v}: {p:?} != {t:?}");
    }
    let free = (0..mesh.n_vertices()).find(|&v| handles.region_of()[v] == methods::handles::FREE).unwrap();
    assert_eq!(positions[free], mesh.positions()[free]);
    assert!(method.phase_timings().iter().any(|(k, v)| k == "own_toy_precompute" && *v == 0.001));
}

#[test]
fn a_program_that_cannot_start_is_named() {
    let mut s = spec("ok", &[], Duration::from_secs(5));
    s.program = "/nonexistent/deformbench-method".into();
    let e = run(s).err().expect("no error");
    assert_all(&e, &["toy-ok", "/nonexistent/deformbench-method", "could not be started"]);
}

#[test]
fn a_program_that_exits_at_once_is_reported_with_its_status_and_stderr() {
    let e = error_of("exit-at-start");
    assert_all(&e, &["`hello`", "exit status: 7", "toy: giving up at once"]);
}

#[test]
fn a_crash_mid_case_is_reported_with_the_request_its_status_and_stderr() {
    let e = error_of("crash-in-solve");
    assert_all(
        &e,
        &["toy-crash-in-solve", "`solve`", "exit status: 3", "ZeroDivisionError: toy division by zero"],
    );
}

#[test]
fn a_line_that_is_not_an_answer_is_quoted() {
    let e = error_of("malformed");
    assert_all(&e, &["`precompute`", "not a protocol answer", "precomputed, thank you"]);
}

#[test]
fn the_wrong_number_of_positions_is_counted() {
    let (mesh, ..) = edit();
    let e = error_of("wrong-count");
    let expected =
        format!("answered {} positions for a mesh of {} vertices", mesh.n_vertices() - 1, mesh.n_vertices());
    assert_all(&e, &["`solve`", &expected]);
}

#[test]
fn a_nan_position_is_named() {
    let e = error_of("nan");
    assert_all(&e, &["`solve`", "non-finite number (NaN)"]);
}

#[test]
fn an_error_answer_is_passed_on() {
    let e = error_of("error");
    assert_all(&e, &["`bind`", "answered an error: toy: this handle set is not for me", "toy: bind"]);
}

#[test]
fn another_protocol_version_is_refused() {
    let e = error_of("old-protocol");
    assert_all(&e, &["`hello`", "version 0", "the harness speaks deformbench-method version 1"]);
}

#[test]
fn a_silent_program_times_out_and_is_killed_with_what_it_started() {
    for (mode, request) in [("hang", "`solve`"), ("ignore-stdin", "`precompute`")] {
        let dir = tempfile::tempdir().unwrap();
        let pid_file = dir.path().join("grandchild.pid");
        let start = Instant::now();
        let e = match run(spec(mode, &[pid_file.to_str().unwrap()], Duration::from_secs(3))) {
            Ok(_) => panic!("{mode}: no error"),
            Err(e) => e,
        };
        let waited = start.elapsed();
        assert_all(&e, &[request, "said nothing within its timeout of 3 s"]);
        assert!(waited < Duration::from_secs(20), "{mode}: {waited:?}");
        let pid: u32 = std::fs::read_to_string(&pid_file).unwrap().trim().parse().unwrap();
        // The kill is delivered at once; allow the kernel a moment to end the process.
        let deadline = Instant::now() + Duration::from_secs(2);
        while running(pid) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(!running(pid), "{mode}: grandchild {pid} outlived its method");
    }
}

#[test]
fn dropping_a_method_ends_its_process() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("logs/toy.stderr.txt");
    let mut s = spec("ok", &[], Duration::from_secs(60));
    s.stderr_log = Some(log.clone());
    let method = run(s).unwrap();
    drop(method);
    // The whole stderr is in the log, down to the `quit` the drop sent.
    let text = std::fs::read_to_string(&log).unwrap();
    assert_eq!(
        text.lines().collect::<Vec<_>>(),
        ["toy: hello", "toy: precompute", "toy: bind", "toy: solve", "toy: quit"]
    );
}
