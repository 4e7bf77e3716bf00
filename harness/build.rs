//! Records the compiler, profile and git state of this build for the run provenance
//! (`harness/src/provenance.rs`; the git state by `src/provenance/git_state.rs`, included here),
//! and compiles the project's files into the binary (`harness/src/paths.rs`): the configuration
//! (`configs/`), the committed baselines (`reports/baselines/`), the Python scripts the harness
//! runs (`python/`, `external/`). An installed binary run where there is no `./configs` uses them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[path = "src/provenance/git_state.rs"]
mod git_state;

/// What the workspace's tracked sources are, relative to its root: a change under any of them can
/// change the checkout's git state, so the state is read again (`rerun-if-changed`).
const SOURCE_PATHS: [&str; 10] = [
    "Cargo.toml",
    "Cargo.lock",
    "meshes",
    "methods",
    "measures",
    "harness/src",
    "harness/Cargo.toml",
    "harness/build.rs",
    "tests",
    "scripts",
];

/// The directories of the workspace compiled in, relative to the workspace root.
const PROJECT_DIRS: [&str; 4] = ["configs", "reports/baselines", "python", "external"];

/// File kinds compiled in (no caches, no editor files).
const EXTENSIONS: [&str; 6] = ["toml", "csv", "json", "py", "txt", "md"];

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = std::process::Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=DEFORMBENCH_RUSTC_VERSION={version}");
    println!("cargo:rustc-env=DEFORMBENCH_PROFILE={}", std::env::var("PROFILE").unwrap_or_default());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=RUSTC");
    record_git_state();
    embed_project_files();
}

/// The git state of the checkout being built (commit, dirty, diff hash), for the provenance of
/// every run of this binary; read again when `HEAD` moves or a source changes.
fn record_git_state() {
    let root = Path::new(&std::env::var("CARGO_MANIFEST_DIR").unwrap()).join("..");
    let state = git_state::read(&root);
    println!("cargo:rustc-env=DEFORMBENCH_GIT_COMMIT={}", state.commit.unwrap_or_default());
    let dirty = state.dirty.map(|d| d.to_string()).unwrap_or_default();
    println!("cargo:rustc-env=DEFORMBENCH_GIT_DIRTY={dirty}");
    println!("cargo:rustc-env=DEFORMBENCH_GIT_DIFF_SHA256={}", state.diff_sha256.unwrap_or_default());
    // Only paths that exist: cargo reruns a build script on every build for a missing one (a
    // repository without packed refs, a source tree without tests/).
    let sources = SOURCE_PATHS.iter().map(|path| root.join(path));
    for file in git_state::head_files(&root).into_iter().chain(sources).filter(|f| f.exists()) {
        println!("cargo:rerun-if-changed={}", file.display());
    }
}

/// Writes `$OUT_DIR/project_files.rs`: `PROJECT_FILES`, a sorted `(relative path, bytes)` table.
fn embed_project_files() {
    let root = Path::new(&std::env::var("CARGO_MANIFEST_DIR").unwrap()).join("..");
    let mut files = Vec::new();
    for dir in PROJECT_DIRS {
        let dir = root.join(dir);
        // A directory is scanned for changes as a whole (cargo's rerun-if-changed on a directory).
        println!("cargo:rerun-if-changed={}", dir.display());
        collect(&dir, &mut files);
    }
    files.sort();
    let mut table = String::from("pub const PROJECT_FILES: &[(&str, &[u8])] = &[\n");
    for file in &files {
        let relative = file.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/");
        let absolute = file.canonicalize().unwrap();
        writeln!(table, "    ({relative:?}, include_bytes!({:?})),", absolute.to_string_lossy()).unwrap();
    }
    table.push_str("];\n");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap()).join("project_files.rs");
    std::fs::write(out, table).unwrap();
}

fn collect(dir: &Path, files: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || name == "__pycache__" {
            continue;
        }
        if path.is_dir() {
            collect(&path, files);
        } else if path.extension().is_some_and(|e| EXTENSIONS.contains(&e.to_string_lossy().as_ref())) {
            files.push(path);
        }
    }
}
