//! Shared by the workspace tests: where the survey data and the cross-check Python are, and how to
//! call the reference scripts.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Set by `scripts/test`: missing data or Python is a failure, not a skip.
fn required() -> bool {
    std::env::var("DEFORMBENCH_REQUIRE_CROSSCHECK").is_ok_and(|v| v == "1")
}

fn unavailable(what: &str) -> Option<PathBuf> {
    if required() {
        panic!("{what} is required (DEFORMBENCH_REQUIRE_CROSSCHECK=1) but not available");
    }
    eprintln!("SKIPPED: {what} not available; run scripts/test to include this check");
    None
}

pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The directory named by the environment variable `var`, unless it is unset or empty. Data is
/// found only through the variables (`scripts/test` sets them from `../shared/` when that exists),
/// so a run with them unset is a run without the data, wherever the checkout lies.
fn data_dir_from(var: &str) -> Option<PathBuf> {
    std::env::var_os(var).filter(|v| !v.is_empty()).map(PathBuf::from)
}

/// The data directory named by `var` when it holds `marker`. Unset: `None` (a skip, also under
/// `scripts/test`: a fresh clone has no data, issue 60). Set but without `marker`: a failure under
/// `scripts/test` (the variable names data that is not there), a skip otherwise.
fn named_data_dir(var: &str, marker: &str, what: &str) -> Option<PathBuf> {
    match data_dir_from(var) {
        Some(dir) if dir.join(marker).is_file() => Some(dir),
        Some(dir) => unavailable(&format!("{what} ({var} = {}, which has no {marker})", dir.display())),
        None => {
            eprintln!("SKIPPED: {what} not named ({var} unset); this test needs the data");
            None
        }
    }
}

/// The survey data directory named by `$DEFORM_SURVEY_DIR`, for the tests about the survey's own
/// files. The cross-checks use [`survey_meshes`], which falls back to the look-alikes.
pub fn survey_dir() -> Option<PathBuf> {
    named_data_dir("DEFORM_SURVEY_DIR", "bar.off", "the survey data")
}

/// Where the four survey tests' files come from for the cross-checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurveySource {
    /// The Botsch–Sorkine files of `$DEFORM_SURVEY_DIR`.
    Survey,
    /// The procedural look-alikes (`meshes::shapes`) at the survey's sizes, written as the same
    /// `.off`/`.sel`/`.def` files: a fresh clone has no survey data, and the cross-checks still run.
    LookAlikes,
}

/// The four survey tests as files: `<name>.off`, `.sel`, `.def` in `dir` for `bar`, `cylinder`,
/// `cactus`, `plane`.
#[derive(Clone, Debug)]
pub struct SurveyMeshes {
    pub dir: PathBuf,
    pub source: SurveySource,
}

/// The survey files of `$DEFORM_SURVEY_DIR` when named, else the procedural look-alikes written once
/// per test process under cargo's `CARGO_TARGET_TMPDIR` (each file atomically; the shapes are
/// deterministic, so two processes write the same bytes). The cross-checks run on either with the
/// same tolerances; which one is printed.
pub fn survey_meshes() -> SurveyMeshes {
    // Named but wrong: a failure under scripts/test, else the look-alikes (with the skip message).
    if data_dir_from("DEFORM_SURVEY_DIR").is_some() {
        if let Some(dir) = named_data_dir("DEFORM_SURVEY_DIR", "bar.off", "the survey data") {
            eprintln!("cross-checks on the survey meshes of {}", dir.display());
            return SurveyMeshes { dir, source: SurveySource::Survey };
        }
    }
    static LOOK_ALIKES: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    let dir = LOOK_ALIKES.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("survey-look-alikes");
        std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for kind in meshes::shapes::ShapeKind::ALL {
            let shape = meshes::shapes::generate(kind, meshes::shapes::default_vertex_count(kind))
                .unwrap_or_else(|e| panic!("{kind}: {e}"));
            let name = kind.name();
            meshes::io::write_off(dir.join(format!("{name}.off")), &shape.mesh).unwrap();
            meshes::io::write_selection(dir.join(format!("{name}.sel")), &shape.selection).unwrap();
            meshes::io::write_transform(dir.join(format!("{name}.def")), &shape.transform).unwrap();
        }
        dir
    });
    eprintln!(
        "cross-checks on the procedural look-alikes in {} (DEFORM_SURVEY_DIR unset; same tolerances)",
        dir.display()
    );
    SurveyMeshes { dir: dir.clone(), source: SurveySource::LookAlikes }
}

/// The real-mesh directory named by `$DEFORM_REAL_MESHES_DIR` (the scenarios of `configs/real-meshes`
/// read it from there; `scripts/test` sets it to `../shared/real-meshes`).
pub fn real_meshes_dir() -> Option<PathBuf> {
    named_data_dir("DEFORM_REAL_MESHES_DIR", "decimated-knight.off", "the real meshes")
}

/// The real-mesh dataset named by `$DEFORM_DATASET_DIR` (79 meshes and their MANIFEST.csv; the
/// scenarios of `configs/dataset*` read it from there; `scripts/test` sets it to
/// `../shared/real-meshes/dataset`).
pub fn dataset_dir() -> Option<PathBuf> {
    named_data_dir("DEFORM_DATASET_DIR", "MANIFEST.csv", "the real-mesh dataset")
}

/// The cross-check interpreter: `$DEFORMBENCH_PYTHON` (set up by scripts/python-env).
pub fn python() -> Option<PathBuf> {
    match std::env::var_os("DEFORMBENCH_PYTHON") {
        Some(p) if Path::new(&p).exists() => Some(PathBuf::from(p)),
        _ => unavailable("the cross-check Python (DEFORMBENCH_PYTHON)"),
    }
}

/// Run `tests/crosscheck/igl_reference.py` with `args`; panics with its stderr on failure. Returns stdout.
pub fn igl_reference(python: &Path, args: &[&str]) -> String {
    run_script(python, "igl_reference.py", args)
}

/// Whitespace-separated numbers per non-empty line.
pub fn read_rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|x| x.parse().expect("number")).collect())
        .collect()
}

/// A survey test case: mesh, handle set and targets from its .off/.sel/.def.
pub fn survey_case(dir: &Path, name: &str) -> (meshes::TriMesh, methods::HandleSet, methods::HandleTargets) {
    let mesh = meshes::io::read_mesh(dir.join(format!("{name}.off"))).expect("mesh");
    let sel = meshes::io::read_selection(dir.join(format!("{name}.sel")), mesh.n_vertices()).expect("sel");
    let def = meshes::io::read_transform(dir.join(format!("{name}.def"))).expect("def");
    let (handles, targets) = harness::scenario::survey_edit(&mesh, &sel, &def).expect("edit");
    (mesh, handles, targets)
}

/// Run `tests/crosscheck/peers_reference.py` (pymeshlab/open3d references) with `args`; panics with its
/// stderr on failure. Returns stdout.
pub fn peers_reference(python: &Path, args: &[&str]) -> String {
    run_script(python, "peers_reference.py", args)
}

/// Run the harness's self-intersection check `python/self_intersection.py` on `meshes`; panics with
/// its stderr on failure. Returns stdout (`path,true|false` per mesh).
pub fn self_intersection_script(python: &Path, meshes: &[&str]) -> String {
    let path = workspace_root().join("python/self_intersection.py");
    let out = Command::new(python).arg(&path).args(meshes).output().expect("run python");
    assert!(out.status.success(), "self_intersection.py failed:\n{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("utf-8")
}

/// Run the cross-check script `tests/crosscheck/<script>` with `args`; panics with its stderr on
/// failure. Returns stdout.
fn run_script(python: &Path, script: &str, args: &[&str]) -> String {
    let path = workspace_root().join("tests/crosscheck").join(script);
    let out = Command::new(python).arg(&path).args(args).output().expect("run python");
    assert!(out.status.success(), "{script} {args:?} failed:\n{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("utf-8")
}

/// Total size in bytes of the files under `dir`, recursively.
pub fn directory_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| {
            let entry = entry.unwrap();
            let meta = entry.metadata().unwrap();
            if meta.is_dir() {
                directory_bytes(&entry.path())
            } else {
                meta.len()
            }
        })
        .sum()
}

/// The rows of a `results.csv` as column -> value maps.
pub fn csv_rows(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let headers = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| headers.iter().map(String::from).zip(r.unwrap().iter().map(String::from)).collect())
        .collect()
}

/// Column `key` of a CSV row as a number (panics naming it otherwise).
pub fn num(row: &std::collections::HashMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap_or_else(|_| panic!("{key} = {:?} is not a number", row[key]))
}

/// The fields of a `results.json` case that do not depend on timing: everything but the times.
pub fn timeless(case: &serde_json::Value) -> serde_json::Value {
    let mut c = case.clone();
    let object = c.as_object_mut().unwrap();
    for key in [
        "precompute_s",
        "bind_s",
        "median_iteration_ms",
        "solve_s",
        "total_s",
        "peak_memory_mib",
        "phase_timings",
        "overhead",
        "spread",
        "startup_s",
    ] {
        object.remove(key);
    }
    // Which method a solve was taken from stays; how long it took there is a timing.
    if let Some(reused) = object.get_mut("reused_solve").and_then(|r| r.as_object_mut()) {
        reused.remove("seconds");
    }
    for step in object.get_mut("steps").unwrap().as_array_mut().unwrap() {
        let step = step.as_object_mut().unwrap();
        for key in ["bind_s", "solve_s", "median_iteration_ms", "reused_solve_s", "phase_timings"] {
            step.remove(key);
        }
    }
    for record in object.get_mut("trace").unwrap().as_array_mut().unwrap() {
        record.as_object_mut().unwrap().remove("seconds");
    }
    c
}

/// Debian's headless Chromium: `$DEFORMBENCH_CHROMIUM`, else `/usr/bin/chromium` (installed by
/// `.ci/run`); a failure under `scripts/test` when missing, a skip otherwise.
pub fn chromium() -> Option<std::path::PathBuf> {
    let path = std::env::var_os("DEFORMBENCH_CHROMIUM")
        .map_or_else(|| std::path::PathBuf::from("/usr/bin/chromium"), std::path::PathBuf::from);
    if path.is_file() {
        return Some(path);
    }
    if std::env::var("DEFORMBENCH_REQUIRE_CROSSCHECK").is_ok_and(|v| v == "1") {
        panic!(
            "{} not found: install Debian's chromium (see .ci/run) or set DEFORMBENCH_CHROMIUM",
            path.display()
        );
    }
    eprintln!("SKIPPED: no Chromium at {}", path.display());
    None
}

/// Open `page` in headless Chromium and read the count its script writes into `#image-check`:
/// `(images loaded, images on the page)`.
pub fn images_loaded_in_chromium(chromium: &Path, page: &Path) -> (usize, usize) {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let (dom, stderr) = dump_dom(chromium, &url);
    let check = dom
        .split("<p id=\"image-check\"")
        .nth(1)
        .unwrap_or_else(|| panic!("no #image-check in the DOM; chromium said: {stderr}"));
    let attribute = |name: &str| -> usize {
        let value = check.split(&format!("{name}=\"")).nth(1).and_then(|v| v.split('"').next()).unwrap_or("");
        value
            .parse()
            .unwrap_or_else(|_| panic!("#image-check {name} = {value:?} (the page script did not run)"))
    };
    let broken = check.split("data-broken=\"").nth(1).and_then(|v| v.split('"').next()).unwrap_or("");
    assert!(broken.is_empty(), "images that did not load: {broken}");
    (attribute("data-loaded"), attribute("data-total"))
}

/// Chromium's flags for a headless run on this machine: no sandbox (root), no background
/// connections (the closed network refuses them), local files may load each other.
pub const HEADLESS: [&str; 8] = [
    "--headless",
    "--no-sandbox",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--allow-file-access-from-files",
];

/// The DOM of `url` after headless Chromium ran its scripts, and what Chromium said on stderr.
pub fn dump_dom(chromium: &Path, url: &str) -> (String, String) {
    let profile = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(chromium)
        .args(HEADLESS)
        .args(["--disable-gpu", "--virtual-time-budget=10000"])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg("--dump-dom")
        .arg(url)
        .output()
        .expect("run chromium");
    (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}
