//! Issue 60: the harness works as an installed tool. Run from an empty directory it reads the
//! configuration built into the binary (one copy in the user's cache), writes `./reports` there and
//! nothing in the checkout it was built from; `configs export` writes the configuration out and
//! a run from there reads it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::SystemTime;

/// The checkout this test binary was built from.
fn checkout() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").canonicalize().unwrap()
}

/// `harness ARGS` with the working directory `cwd`, the cache `cache` (`XDG_CACHE_HOME`) and an
/// empty `TMPDIR` of its own (returned, to see that the run leaves nothing there); no survey data
/// or method files from the environment.
fn harness_in(cwd: &Path, cache: &Path, args: &[&str]) -> (Output, tempfile::TempDir) {
    let tmp = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(args)
        .current_dir(cwd)
        .env("TMPDIR", tmp.path())
        .env("XDG_CACHE_HOME", cache)
        .env_remove("DEFORM_SURVEY_DIR")
        .env_remove("DEFORMBENCH_METHODS")
        .env_remove("DEFORMBENCH_HISTORY")
        .output()
        .unwrap();
    (out, tmp)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Every path under `dir` with its modification time, skipping `target/` and `.git/`.
fn mtimes(dir: &Path) -> Vec<(PathBuf, SystemTime)> {
    fn walk(dir: &Path, out: &mut Vec<(PathBuf, SystemTime)>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            let name = entry.file_name();
            if name == "target" || name == ".git" || name == ".venv" {
                continue;
            }
            out.push((path.clone(), entry.metadata().unwrap().modified().unwrap()));
            if entry.file_type().unwrap().is_dir() {
                walk(&path, out);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, &mut out);
    out.sort();
    out
}

fn git_status(dir: &Path) -> Option<String> {
    let out = Command::new("git").arg("-C").arg(dir).args(["status", "--porcelain"]).output().ok()?;
    out.status.success().then(|| text(&out.stdout))
}

#[test]
fn a_run_from_an_empty_directory_writes_only_there() {
    let checkout = checkout();
    let (status_before, mtimes_before) = (git_status(&checkout), mtimes(&checkout.join("reports")));
    let configs_before = mtimes(&checkout.join("configs"));
    let (empty, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let bar = ["run", "--scenario", "bar", "--method", "laplacian", "--quiet"];
    let (out, tmp) = harness_in(empty.path(), cache.path(), &bar);
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "exit {:?}\n{stderr}\n{}", out.status, text(&out.stdout));
    assert!(
        stderr.contains("configuration built into harness"),
        "the built-in configuration is not named:\n{stderr}"
    );
    let reports = empty.path().join("reports");
    for file in ["results.json", "results.csv", "index.html"] {
        assert!(reports.join(file).is_file(), "{file} not written in ./reports");
    }
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(reports.join("results.json")).unwrap()).unwrap();
    assert_eq!(results["cases"][0]["mesh_source"], "procedural look-alike");
    // Only ./reports appeared where the run started, nothing in TMPDIR, and one copy of the built-in
    // configuration in the cache, which a second run reuses.
    let here: Vec<_> = std::fs::read_dir(empty.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(here, vec![std::ffi::OsString::from("reports")]);
    let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
    let copies = || -> Vec<PathBuf> {
        std::fs::read_dir(cache.path().join("deformbench")).unwrap().map(|e| e.unwrap().path()).collect()
    };
    let first = copies();
    assert_eq!(first.len(), 1, "{first:?}");
    // An edited copy is written again before it is used.
    let methods = first[0].join("configs/methods.toml");
    std::fs::write(&methods, "not toml [").unwrap();
    let (again, _tmp) = harness_in(empty.path(), cache.path(), &bar);
    assert!(again.status.success(), "{}", text(&again.stderr));
    assert_eq!(copies(), first);
    assert_eq!(
        std::fs::read(&methods).unwrap(),
        std::fs::read(checkout.join("configs/methods.toml")).unwrap()
    );
    // The checkout it was built from is untouched.
    assert_eq!(git_status(&checkout), status_before, "git status of {} changed", checkout.display());
    assert_eq!(mtimes(&checkout.join("reports")), mtimes_before, "the checkout's reports/ was written");
    assert_eq!(mtimes(&checkout.join("configs")), configs_before, "the checkout's configs/ was written");
}

#[test]
fn list_and_export_work_without_a_checkout_and_an_exported_configuration_is_read() {
    let (empty, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let (out, _tmp) = harness_in(empty.path(), cache.path(), &["list"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("arap"), "{}", text(&out.stdout));

    let (out, _tmp) = harness_in(empty.path(), cache.path(), &["configs", "export", "mine"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mine = empty.path().join("mine");
    for file in [
        "configs/methods.toml",
        "configs/scenarios/bar.toml",
        "reports/baselines/procedural.json",
        "python/self_intersection.py",
        "external/peers/libigl_arap.py",
    ] {
        assert_eq!(
            std::fs::read(mine.join(file)).unwrap(),
            std::fs::read(checkout().join(file)).unwrap(),
            "{file} exported differs from the checkout's"
        );
    }
    // Exporting again overwrites nothing and says which file is in the way (exit 2).
    let (again, _tmp) = harness_in(empty.path(), cache.path(), &["configs", "export", "mine"]);
    assert_eq!(again.status.code(), Some(2));
    assert!(text(&again.stderr).contains("exists already"), "{}", text(&again.stderr));

    // From the exported directory its ./configs is read (`list` names the file it read).
    let (out, _tmp) = harness_in(&mine, cache.path(), &["list"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(!text(&out.stderr).contains("built into"), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout)
            .contains(&mine.join("configs/methods.toml").canonicalize().unwrap().display().to_string()),
        "list does not name the exported methods.toml:\n{}",
        text(&out.stdout)
    );
}
