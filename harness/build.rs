//! Records the compiler and profile of this build for the run provenance (`harness/src/provenance.rs`),
//! and compiles the project's files into the binary (`harness/src/paths.rs`): the configuration
//! (`configs/`), the committed baselines (`reports/baselines/`), the Python scripts the harness
//! runs (`python/`, `external/`). An installed binary run where there is no `./configs` uses them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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
    embed_project_files();
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
