//! `scripts/fetch-dataset` offline: a small mirror in a temporary directory
//! (`<mirror>/<owner>/<repo>/<commit>/<path>`, read through a file:// base URL) with an OBJ kept as it
//! is, an OBJ to strip to its `v`/`f` lines and a binary OFF to convert. The files arrive with the
//! right bytes, the manifest is copied beside them, a second run finds them present, and a tampered
//! or missing source fails the run naming the file and leaving nothing behind. With the shared
//! dataset at hand, its stored files serve as the mirror of every row that must match byte for byte.

mod support;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// Kept as it is ("original file, unchanged").
const PLAIN: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n";

/// To be stripped ("OBJ stripped to v/f"): comments, groups, materials, normals, texture
/// coordinates, `v/vt/vn` face entries, a relative index, a CRLF line.
const TO_STRIP: &str = "# exported by hand\nmtllib tetra.mtl\no tetra\n\
    v 0.000000 0.000000 0.000000\nv 1.000000 0.000000 0.000000\nvt 0.5 0.5\nv 0 1 0\r\n\
    vn 0 0 1\nv  0.0  0.0  1e-3\ns off\nusemtl red\n\
    f 1/1/1 2/1/1 3/1/1\nf 1//1 3//1 -1//1\nf 1/1 4/1 2/1\nf 2 4 3\n";

/// What stripping TO_STRIP gives: coordinates as shortest round-trip doubles, vertex indices only.
const STRIPPED: &str =
    "v 0.0 0.0 0.0\nv 1.0 0.0 0.0\nv 0.0 1.0 0.0\nv 0.0 0.0 0.001\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n";

/// What converting `binary_off()` gives: float32 coordinates printed with `%.9g`.
const FROM_BINARY_OFF: &str = "v 0 0 0\nv 2 0 0\nv 0 2 0\nv 0.5 0.5 1\nf 1 2 3\nf 1 4 2\nf 2 4 3\nf 3 4 1\n";

const PLAIN_COMMIT: &str = "0123456789abcdef0123456789abcdef01234567";
const STRIP_COMMIT: &str = "89abcdef0123456789abcdef0123456789abcdef";
const OFF_COMMIT: &str = "fedcba9876543210fedcba9876543210fedcba98";

/// A binary OFF as pmp-library writes it: little-endian counts, float32 positions, `n i j k` faces.
fn binary_off() -> Vec<u8> {
    let mut bytes = b"OFF BINARY\n".to_vec();
    for count in [4u32, 4, 0] {
        bytes.extend(count.to_le_bytes());
    }
    for coordinate in [0f32, 0., 0., 2., 0., 0., 0., 2., 0., 0.5, 0.5, 1.] {
        bytes.extend(coordinate.to_le_bytes());
    }
    for face in [[0u32, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]] {
        bytes.extend(3u32.to_le_bytes());
        for index in face {
            bytes.extend(index.to_le_bytes());
        }
    }
    bytes
}

/// SHA-256 (hex) of `bytes`, by python3's hashlib (the root package has no hashing dependency).
fn sha256_hex(bytes: &[u8]) -> String {
    let mut child = Command::new("python3")
        .args(["-c", "import hashlib, sys; print(hashlib.sha256(sys.stdin.buffer.read()).hexdigest())"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("python3 on PATH");
    child.stdin.take().unwrap().write_all(bytes).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    String::from_utf8(out.stdout).unwrap().trim().to_string()
}

/// Write `bytes` to `<mirror>/<repo>/<commit>/<path>`.
fn put(mirror: &Path, repo: &str, commit: &str, path: &str, bytes: &[u8]) -> PathBuf {
    let file = mirror.join(repo).join(commit).join(path);
    std::fs::create_dir_all(file.parent().unwrap()).unwrap();
    std::fs::write(&file, bytes).unwrap();
    file
}

/// The test's mirror and manifest. The binary OFF's row carries a SHA-256 that its conversion does
/// not give (with the right counts), as a source whose converted bytes differ from the stored copy's.
struct Fixture {
    tmp: tempfile::TempDir,
    mirror: PathBuf,
    manifest: PathBuf,
    plain_source: PathBuf,
    strip_source: PathBuf,
}

fn fixture() -> Fixture {
    let tmp = tempfile::tempdir().unwrap();
    let mirror = tmp.path().join("mirror");
    let plain_source = put(&mirror, "someone/meshes", PLAIN_COMMIT, "models/plain.obj", PLAIN.as_bytes());
    // A space in the path: the URL is percent-encoded and must still find the file.
    let strip_source =
        put(&mirror, "other/data", STRIP_COMMIT, "obj/tetra/tetra source.obj", TO_STRIP.as_bytes());
    put(&mirror, "third/repo", OFF_COMMIT, "off/wedge.off", &binary_off());
    let manifest = tmp.path().join("manifest.csv");
    let rows = [
        format!(
            "plain.obj,4,4,someone/meshes,models/plain.obj,{PLAIN_COMMIT},MIT,{},\"original file, unchanged\"",
            sha256_hex(PLAIN.as_bytes())
        ),
        format!(
            "tetra.obj,4,4,other/data,obj/tetra/tetra source.obj,{STRIP_COMMIT},CC BY 4.0,{},OBJ stripped to v/f",
            sha256_hex(STRIPPED.as_bytes())
        ),
        format!(
            "wedge.obj,4,4,third/repo,off/wedge.off,{OFF_COMMIT},unknown,{},binary OFF converted to OBJ",
            "0".repeat(64)
        ),
    ];
    let header = "file,vertices,faces,source_repo,source_path,source_commit,license,sha256,conversion";
    std::fs::write(&manifest, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
    Fixture { tmp, mirror, manifest, plain_source, strip_source }
}

/// `python3 scripts/fetch-dataset <out> <args>`.
fn fetch(out: &Path, args: &[&str]) -> Output {
    let script = support::workspace_root().join("scripts/fetch-dataset");
    Command::new("python3").arg(script).arg(out).args(args).output().expect("python3 on PATH")
}

/// `fetch` with the fixture's manifest and mirror.
fn fetch_from(f: &Fixture, out: &Path, extra: &[&str]) -> Output {
    let base_url = format!("file://{}", f.mirror.display());
    let mut args = vec!["--manifest", f.manifest.to_str().unwrap(), "--base-url", &base_url];
    args.extend_from_slice(extra);
    fetch(out, &args)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn fetches_strips_converts_and_then_finds_the_files_present() {
    let f = fixture();
    let out = f.tmp.path().join("dataset");
    let run = fetch_from(&f, &out, &[]);
    let (stdout, stderr) = (text(&run.stdout), text(&run.stderr));
    assert!(run.status.success(), "first run failed:\n{stdout}\n{stderr}");
    assert_eq!(std::fs::read_to_string(out.join("plain.obj")).unwrap(), PLAIN);
    assert_eq!(std::fs::read_to_string(out.join("tetra.obj")).unwrap(), STRIPPED);
    assert_eq!(std::fs::read_to_string(out.join("wedge.obj")).unwrap(), FROM_BINARY_OFF);
    assert_eq!(std::fs::read(out.join("MANIFEST.csv")).unwrap(), std::fs::read(&f.manifest).unwrap());
    assert_eq!(listing(&out), ["MANIFEST.csv", "plain.obj", "tetra.obj", "wedge.obj"], "stray files");
    assert!(
        stdout.contains("fetch-dataset: 2 fetched, 0 already present, 1 converted with differing bytes, 0 skipped, 0 failed"),
        "{stdout}"
    );
    assert!(
        stderr.contains("warning: wedge.obj: converted, counts match")
            && stderr.contains("bytes differ from the manifest's copy"),
        "{stderr}"
    );

    let again = fetch_from(&f, &out, &[]);
    let stdout = text(&again.stdout);
    assert!(again.status.success(), "second run failed:\n{stdout}\n{}", text(&again.stderr));
    assert!(stdout.contains("already present: plain.obj") && stdout.contains("already present: tetra.obj"));
    assert!(
        stdout.contains("fetch-dataset: 0 fetched, 2 already present, 1 converted with differing bytes"),
        "{stdout}"
    );
    assert_eq!(std::fs::read_to_string(out.join("tetra.obj")).unwrap(), STRIPPED);
}

#[test]
fn only_fetches_the_named_files() {
    let f = fixture();
    let out = f.tmp.path().join("dataset");
    let run = fetch_from(&f, &out, &["--only", "tetra", "--jobs", "1"]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(listing(&out), ["MANIFEST.csv", "tetra.obj"]);
    assert!(text(&run.stdout).contains("1 fetched, 0 already present, 0 converted with differing bytes"));
}

#[test]
fn a_tampered_or_missing_source_fails_the_run_and_leaves_nothing_behind() {
    let f = fixture();
    std::fs::write(&f.plain_source, format!("{PLAIN}# tampered\n")).unwrap();
    std::fs::remove_file(&f.strip_source).unwrap();
    let out = f.tmp.path().join("dataset");
    let run = fetch_from(&f, &out, &[]);
    let stderr = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    let plain_url = format!("file://{}/someone/meshes/{PLAIN_COMMIT}/models/plain.obj", f.mirror.display());
    assert!(
        stderr
            .lines()
            .any(|l| l.contains("plain.obj") && l.contains("SHA-256 mismatch") && l.contains(&plain_url)),
        "{stderr}"
    );
    assert!(
        stderr.lines().any(|l| l.contains("tetra.obj")
            && l.contains("download failed")
            && l.contains("tetra%20source.obj")),
        "{stderr}"
    );
    assert!(stderr.contains("fetch-dataset: failed: plain.obj, tetra.obj"), "{stderr}");
    // Every file is tried: the converted one still arrives; the failed ones leave no file, partial or not.
    assert_eq!(listing(&out), ["MANIFEST.csv", "wedge.obj"]);
    assert!(text(&run.stdout)
        .contains("0 fetched, 0 already present, 1 converted with differing bytes, 0 skipped, 2 failed"));
}

/// The shared dataset (`$DEFORM_REAL_MESHES_DIR/dataset`, else `../shared/real-meshes/dataset`).
fn shared_dataset() -> Option<PathBuf> {
    let real_meshes = std::env::var_os("DEFORM_REAL_MESHES_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| support::workspace_root().join("../shared/real-meshes"));
    let dir = real_meshes.join("dataset");
    if dir.join("MANIFEST.csv").is_file() {
        Some(dir)
    } else {
        eprintln!("SKIPPED: no shared dataset at {}", dir.display());
        None
    }
}

/// With the stored files as their own sources, the project's manifest (a copy of the shared one)
/// fetches every "original file, unchanged" row and every "OBJ stripped to v/f" row with the
/// manifest's SHA-256: the stripping rule gives back the stored bytes.
#[test]
fn the_stored_dataset_as_mirror_gives_back_every_file_that_must_match() {
    let Some(shared) = shared_dataset() else { return };
    let manifest = support::workspace_root().join("configs/dataset/MANIFEST.csv");
    assert_eq!(
        std::fs::read(&manifest).unwrap(),
        std::fs::read(shared.join("MANIFEST.csv")).unwrap(),
        "configs/dataset/MANIFEST.csv is not a copy of the shared one"
    );
    let tmp = tempfile::tempdir().unwrap();
    let mirror = tmp.path().join("mirror");
    let mut names = Vec::new();
    for row in support::csv_rows(&manifest) {
        if !["original file, unchanged", "OBJ stripped to v/f"].contains(&row["conversion"].as_str()) {
            continue;
        }
        let source = mirror.join(&row["source_repo"]).join(&row["source_commit"]).join(&row["source_path"]);
        std::fs::create_dir_all(source.parent().unwrap()).unwrap();
        std::os::unix::fs::symlink(shared.join(&row["file"]), &source).unwrap();
        names.push(row["file"].clone());
    }
    assert_eq!(names.len(), 62, "35 original + 27 stripped rows");
    let out = tmp.path().join("dataset");
    let base_url = format!("file://{}", mirror.display());
    let mut args = vec!["--base-url", base_url.as_str(), "--jobs", "2", "--only"];
    args.extend(names.iter().map(String::as_str));
    let run = fetch(&out, &args);
    let stdout = text(&run.stdout);
    assert!(run.status.success(), "{stdout}\n{}", text(&run.stderr));
    assert!(stdout.contains("fetch-dataset: 62 fetched, 0 already present"), "{stdout}");
    for name in &names {
        assert_eq!(
            std::fs::read(out.join(name)).unwrap(),
            std::fs::read(shared.join(name)).unwrap(),
            "{name} differs from the stored copy"
        );
    }
}
