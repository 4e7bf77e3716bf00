//! Where the project's files are and the environment variables that name inputs.
//!
//! Nothing is found through the directory the binary was built in (issue 60): a run reads the
//! configuration of `--configs`, else `./configs` of the current directory (a checkout, or a
//! directory written by `harness configs export`), else the copy compiled into the binary (written
//! once per build to the user's cache, [`cache_dir`]); outputs default to the current directory
//! (`./reports`, `./history/history.sqlite`). The project files are the configuration
//! (`configs/`), the committed regression baselines (`reports/baselines/`) and the Python scripts
//! the harness and the peers run (`python/`, `external/`), kept in their checkout layout.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::error::HarnessError;

/// Environment variable naming the survey data directory (same as `--survey-dir`).
pub const SURVEY_DIR_ENV: &str = "DEFORM_SURVEY_DIR";

/// Environment variable naming the project's Python (the venv of `python/requirements.txt`, made
/// by `scripts/python-env`; set by `scripts/test`).
pub const PYTHON_ENV: &str = "DEFORMBENCH_PYTHON";

/// The default reports directory, relative to the current directory.
pub const DEFAULT_REPORTS_DIR: &str = "reports";

mod embedded {
    // `PROJECT_FILES: &[(&str, &[u8])]`, (path relative to the project root, contents), sorted;
    // written by build.rs.
    include!(concat!(env!("OUT_DIR"), "/project_files.rs"));
}

/// The project files compiled into this binary: (path relative to the project root, contents).
pub fn built_in_files() -> &'static [(&'static str, &'static [u8])] {
    embedded::PROJECT_FILES
}

/// Where a run's project files come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ProjectFiles {
    /// A directory with `configs/methods.toml` (the current directory when it has one).
    Directory(PathBuf),
    /// The copy compiled into the binary, written out to this directory ([`cache_dir`]).
    BuiltIn(PathBuf),
}

impl ProjectFiles {
    /// The project root: `configs/`, `reports/baselines/`, `python/` and `external/` are under it.
    pub fn root(&self) -> &Path {
        match self {
            ProjectFiles::Directory(root) | ProjectFiles::BuiltIn(root) => root,
        }
    }

    /// One line for people: which configuration a run reads.
    pub fn describe(&self) -> String {
        match self {
            ProjectFiles::Directory(root) => format!("configuration of {}", root.join("configs").display()),
            ProjectFiles::BuiltIn(_) => format!(
                "the configuration built into harness {} (no ./configs here; `harness configs export DIR` \
                 writes it out for editing)",
                env!("CARGO_PKG_VERSION")
            ),
        }
    }
}

/// Is `dir` a project root: does it hold `configs/methods.toml`?
pub fn is_project_root(dir: &Path) -> bool {
    dir.join("configs/methods.toml").is_file()
}

/// The project files of this process, found once: the current directory when it is a project root
/// ([`is_project_root`]), else the built-in copy. Fails only when neither is there and the copy
/// cannot be written (a full or read-only temporary directory).
pub fn project_files() -> Result<&'static ProjectFiles, HarnessError> {
    static FOUND: OnceLock<ProjectFiles> = OnceLock::new();
    if let Some(found) = FOUND.get() {
        return Ok(found);
    }
    let cwd = std::env::current_dir().ok().filter(|d| is_project_root(d));
    let found = match cwd {
        Some(dir) => ProjectFiles::Directory(dir.canonicalize().unwrap_or(dir)),
        None => ProjectFiles::BuiltIn(materialize_built_in()?),
    };
    Ok(FOUND.get_or_init(|| found))
}

/// The project root of this process ([`project_files`]).
pub fn project_root() -> Result<PathBuf, HarnessError> {
    project_files().map(|p| p.root().to_path_buf())
}

/// The project's Python code (`python/`): the scripts the harness runs and the requirements.
pub fn python_dir() -> Result<PathBuf, HarnessError> {
    project_root().map(|root| root.join("python"))
}

/// The default reports directory: `./reports` of the current directory.
pub fn default_reports_dir() -> PathBuf {
    current_dir_join(DEFAULT_REPORTS_DIR)
}

/// `relative` under the current directory, absolute when the current directory can be read.
pub fn current_dir_join(relative: impl AsRef<Path>) -> PathBuf {
    match std::env::current_dir() {
        Ok(cwd) => cwd.join(relative),
        Err(_) => relative.as_ref().to_path_buf(),
    }
}

/// Write the built-in project files to the user's cache (once per content: see [`cache_dir`]) and
/// return that directory. A copy whose files differ from the built-in ones (edited, or cut short by a
/// killed process) is written again; a new copy is written beside it and renamed into place, so
/// concurrent runs see a whole copy or none.
fn materialize_built_in() -> Result<PathBuf, HarnessError> {
    let dir = cache_dir();
    if copy_is_whole(&dir) {
        return Ok(dir);
    }
    let staging = staged_built_in(dir.parent().unwrap_or(Path::new(".")), ".staging-")?;
    if dir.exists() && !copy_is_whole(&dir) {
        // A damaged copy: replaced whole.
        std::fs::remove_dir_all(&dir).map_err(|e| HarnessError::Io { path: dir.clone(), error: e })?;
    }
    match std::fs::rename(staging.path(), &dir) {
        Ok(()) => {
            let _ = staging.keep();
            Ok(dir)
        }
        // Another run put its whole copy there first.
        Err(_) if copy_is_whole(&dir) => Ok(dir),
        Err(e) => Err(HarnessError::Io { path: dir, error: e }),
    }
}

/// Where the built-in project files are written out: `deformbench/project-<version>-<hash>` in
/// `$XDG_CACHE_HOME`, else `~/.cache`, else the temporary directory; the hash is of the files, so
/// each build writes its own copy once and runs reuse it (nothing accumulates, and a killed run
/// leaves nothing behind).
pub fn cache_dir() -> PathBuf {
    use sha2::{Digest, Sha256};
    let mut hash = Sha256::new();
    for (relative, contents) in built_in_files() {
        hash.update(relative.as_bytes());
        hash.update((contents.len() as u64).to_le_bytes());
        hash.update(contents);
    }
    let hex: String = hash.finalize().iter().take(8).map(|b| format!("{b:02x}")).collect();
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME").filter(|v| !v.is_empty()).map(|h| PathBuf::from(h).join(".cache"))
        })
        .unwrap_or_else(std::env::temp_dir);
    base.join("deformbench").join(format!("project-{}-{hex}", env!("CARGO_PKG_VERSION")))
}

/// Does `dir` hold every built-in file with its built-in contents?
fn copy_is_whole(dir: &Path) -> bool {
    built_in_files()
        .iter()
        .all(|(relative, contents)| std::fs::read(dir.join(relative)).is_ok_and(|b| b == *contents))
}

/// Write every built-in project file under `root` in the checkout layout. Returns how many.
fn write_built_in(root: &Path) -> Result<usize, HarnessError> {
    for (relative, contents) in built_in_files() {
        let path = root.join(relative);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| HarnessError::Io { path: parent.to_path_buf(), error: e })?;
        }
        std::fs::write(&path, contents).map_err(|e| HarnessError::Io { path: path.clone(), error: e })?;
    }
    Ok(built_in_files().len())
}

/// The built-in project files written whole into a new hidden directory `prefix…` inside `parent`
/// (created if missing), to be moved into place; removed when dropped.
fn staged_built_in(parent: &Path, prefix: &str) -> Result<tempfile::TempDir, HarnessError> {
    std::fs::create_dir_all(parent).map_err(|e| HarnessError::Io { path: parent.to_path_buf(), error: e })?;
    let staging = tempfile::Builder::new()
        .prefix(prefix)
        .tempdir_in(parent)
        .map_err(|e| HarnessError::Io { path: parent.to_path_buf(), error: e })?;
    write_built_in(staging.path())?;
    Ok(staging)
}

/// `harness configs export DIR`: write the built-in project files into `dir` (created if missing),
/// so that `harness` run from `dir` (or with `--configs DIR/configs`) reads them. Refuses, before
/// writing anything, when any of the files already exists there (naming it). Returns the paths
/// written.
pub fn export_built_in(dir: &Path) -> Result<Vec<PathBuf>, HarnessError> {
    let paths: Vec<PathBuf> = built_in_files().iter().map(|(relative, _)| dir.join(relative)).collect();
    if let Some(existing) = paths.iter().find(|p| p.exists()) {
        return Err(HarnessError::Config {
            path: existing.clone(),
            message: "exists already; export writes into a new or empty directory and overwrites nothing"
                .into(),
        });
    }
    // Written to a hidden staging directory inside `dir` and moved into place file by file only once
    // all were written, so a failure (a full disk) leaves no half-written file; the staging
    // directory is removed when it is dropped.
    let staging = staged_built_in(dir, ".deformbench-export-")?;
    for (relative, _) in built_in_files() {
        let (from, to) = (staging.path().join(relative), dir.join(relative));
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| HarnessError::Io { path: parent.to_path_buf(), error: e })?;
        }
        std::fs::rename(&from, &to).map_err(|e| HarnessError::Io { path: to.clone(), error: e })?;
    }
    Ok(paths)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The checkout this crate was compiled in, for unit tests that read its committed files.
    pub(crate) fn checkout_root() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    #[test]
    fn the_built_in_files_are_the_checkouts() {
        let root = checkout_root();
        let names: Vec<&str> = built_in_files().iter().map(|(p, _)| *p).collect();
        for needed in [
            "configs/methods.toml",
            "configs/verdicts.toml",
            "configs/scenarios/bar.toml",
            "reports/baselines/procedural.json",
            "python/self_intersection.py",
            "external/peers/libigl_arap.py",
        ] {
            assert!(names.contains(&needed), "{needed} is not built in: {names:?}");
        }
        for (relative, contents) in built_in_files() {
            let on_disk = std::fs::read(root.join(relative)).unwrap();
            assert_eq!(&on_disk[..], *contents, "{relative} differs from the checkout's");
        }
    }

    #[test]
    fn export_writes_every_file_and_overwrites_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let written = export_built_in(dir.path()).unwrap();
        assert_eq!(written.len(), built_in_files().len());
        assert!(is_project_root(dir.path()));
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(leftovers.is_empty(), "staging left behind: {leftovers:?}");
        let before = std::fs::read(dir.path().join("configs/methods.toml")).unwrap();
        std::fs::write(dir.path().join("configs/methods.toml"), "edited").unwrap();
        let e = export_built_in(dir.path()).unwrap_err().to_string();
        assert!(e.contains("exists already"), "{e}");
        assert_eq!(std::fs::read_to_string(dir.path().join("configs/methods.toml")).unwrap(), "edited");
        assert!(!before.is_empty());
    }
}
