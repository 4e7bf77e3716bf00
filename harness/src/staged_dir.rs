//! A report directory replaced whole. A run writes into a staging directory beside its target
//! (`.<name>.staging-<pid>`) and swaps it in at the end, so a run killed or failed at any moment
//! leaves the old report or the new one, never files of both. On Linux the swap is one
//! `renameat2(RENAME_EXCHANGE)`; elsewhere it is two renames, and a kill between them leaves the
//! target missing (the old report waits beside it) for that instant.
//!
//! What a report directory holds besides a run ([`RUN_OUTPUTS`] names a run's entries; everything
//! else: the committed `baselines/`, a `comparison/`, a user's own files) is carried into the new
//! one, hard-linked. A run's entries of an older run are not: a report directory is one run.

use std::path::{Path, PathBuf};

use crate::error::HarnessError;

/// Every entry a run writes at the top of its report directory: the tables, the page and the
/// folders of meshes, plots, figures, the 3D view's files and external methods' stderr logs.
pub const RUN_OUTPUTS: &[&str] = &[
    "index.html",
    "results.json",
    "results.csv",
    "convergence.csv",
    "handle_updates.csv",
    "table1.md",
    "peers.md",
    "pareto.md",
    "dataset.md",
    "size-series.md",
    "meshes",
    "plots",
    "figures",
    "viewer",
    "logs",
];

/// A staging directory that becomes `target` on [`StagedDir::publish`], and is removed, leaving
/// `target` as it was, when dropped unpublished.
#[derive(Debug)]
pub struct StagedDir {
    /// The report directory as named.
    target: PathBuf,
    /// What is swapped: `target`, or where it leads when it is a symbolic link (the link stays).
    swapped: PathBuf,
    staging: PathBuf,
    published: bool,
}

impl StagedDir {
    /// An empty staging directory beside `target` (created with its parent when missing). Staging
    /// directories of `target` left by runs that were killed are removed first. Errors: `target`
    /// is a file, or the parent cannot be written.
    pub fn begin(target: &Path) -> Result<StagedDir, HarnessError> {
        if target.exists() && !target.is_dir() {
            return Err(HarnessError::Config {
                path: target.to_path_buf(),
                message: "--reports names a file; it must be a directory (or not exist yet)".into(),
            });
        }
        let swapped = if target.is_symlink() {
            std::fs::canonicalize(target).map_err(io(target))?
        } else {
            target.to_path_buf()
        };
        let parent = match swapped.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        // Checked before the run, not found when publishing after every case ran: the report
        // directory (its old entries are swapped out and removed) and the directory the staging
        // one is made in, or the nearest one that exists.
        let existing = |p: &Path| p.ancestors().find(|a| a.exists()).map(Path::to_path_buf);
        let checked = [swapped.is_dir().then(|| swapped.clone()), existing(&parent)];
        if let Some(locked) = checked.into_iter().flatten().find(|d| !writable(d)) {
            let what = if locked == swapped {
                "the report directory cannot be written".to_string()
            } else {
                format!("cannot be written, and the report directory {} is made in it", target.display())
            };
            return Err(HarnessError::Config {
                path: locked,
                message: format!(
                    "{what}: the run could not publish its report, so nothing was run (give --reports \
                     another directory, or make this one writable)"
                ),
            });
        }
        std::fs::create_dir_all(&parent).map_err(io(&parent))?;
        let prefix = staging_prefix(&swapped);
        remove_abandoned(&parent, &prefix);
        let staging = parent.join(format!("{prefix}{}", std::process::id()));
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(io(&staging))?;
        }
        std::fs::create_dir(&staging).map_err(io(&staging))?;
        Ok(StagedDir { target: target.to_path_buf(), swapped, staging, published: false })
    }

    /// Where the run writes its report.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The report directory this one replaces.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Carry what `target` holds besides a run into the staging directory, swap the two, and
    /// remove the old report.
    pub fn publish(mut self) -> Result<(), HarnessError> {
        if self.swapped.is_dir() {
            for entry in std::fs::read_dir(&self.swapped).map_err(io(&self.swapped))? {
                let entry = entry.map_err(io(&self.swapped))?;
                let name = entry.file_name();
                let kept = self.staging.join(&name);
                if RUN_OUTPUTS.iter().any(|o| name == *o) || kept.exists() {
                    continue;
                }
                link_tree(&entry.path(), &kept).map_err(io(&entry.path()))?;
            }
            swap(&self.staging, &self.swapped).map_err(io(&self.swapped))?;
            // The staging path now holds the old report.
            std::fs::remove_dir_all(&self.staging).map_err(io(&self.staging))?;
        } else {
            std::fs::rename(&self.staging, &self.swapped).map_err(io(&self.swapped))?;
        }
        self.published = true;
        Ok(())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.published {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// Whether this process may create and remove entries in the directory `dir` (`access(2)`, which
/// also sees a read-only mount and the immutable flag, even for root).
#[cfg(target_os = "linux")]
fn writable(dir: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(path) = std::ffi::CString::new(dir.as_os_str().as_bytes()) else { return false };
    // SAFETY: a NUL-terminated path that outlives the call; access reads nothing else.
    unsafe { libc::access(path.as_ptr(), libc::W_OK | libc::X_OK) == 0 }
}

/// Whether the directory `dir` is not marked read-only.
#[cfg(not(target_os = "linux"))]
fn writable(dir: &Path) -> bool {
    std::fs::metadata(dir).is_ok_and(|m| !m.permissions().readonly())
}

/// The error of an I/O operation on `path`.
fn io(path: &Path) -> impl FnOnce(std::io::Error) -> HarnessError + '_ {
    move |error| HarnessError::Io { path: path.to_path_buf(), error }
}

/// `.<name>.staging-`: the start of the staging directories of `target`.
fn staging_prefix(target: &Path) -> String {
    let name = target.file_name().map_or_else(|| "reports".into(), |n| n.to_string_lossy().into_owned());
    format!(".{name}.staging-")
}

/// Remove the staging directories under `parent` whose process (the number after `prefix`) is no
/// longer running: what a killed run left.
fn remove_abandoned(parent: &Path, prefix: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(pid) = name.strip_prefix(prefix).and_then(|p| p.parse::<u32>().ok()) else { continue };
        if pid != std::process::id() && !process_is_running(pid) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

#[cfg(target_os = "linux")]
fn process_is_running(pid: u32) -> bool {
    Path::new(&format!("/proc/{pid}")).exists()
}

#[cfg(not(target_os = "linux"))]
fn process_is_running(_: u32) -> bool {
    // Without /proc a staging directory's owner cannot be told dead; leave it.
    true
}

/// `from` recreated at `to`: directories made, files hard-linked (copied where a link cannot be
/// made), symbolic links recreated.
fn link_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    let meta = std::fs::symlink_metadata(from)?;
    if meta.is_dir() {
        std::fs::create_dir(to)?;
        for entry in std::fs::read_dir(from)? {
            let entry = entry?;
            link_tree(&entry.path(), &to.join(entry.file_name()))?;
        }
        return Ok(());
    }
    #[cfg(unix)]
    if meta.file_type().is_symlink() {
        return std::os::unix::fs::symlink(std::fs::read_link(from)?, to);
    }
    std::fs::hard_link(from, to).or_else(|_| std::fs::copy(from, to).map(|_| ()))
}

/// Exchange the directories `a` and `b` in one step.
#[cfg(target_os = "linux")]
fn swap(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (ca, cb) = (c(a)?, c(b)?);
    // SAFETY: two NUL-terminated paths that outlive the call; renameat2 reads nothing else.
    let rc = unsafe {
        libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE)
    };
    if rc == 0 {
        return Ok(());
    }
    let error = std::io::Error::last_os_error();
    // A filesystem without RENAME_EXCHANGE: the two renames below.
    if matches!(error.raw_os_error(), Some(libc::EINVAL) | Some(libc::ENOSYS)) {
        return swap_by_renames(a, b);
    }
    Err(error)
}

#[cfg(not(target_os = "linux"))]
fn swap(a: &Path, b: &Path) -> std::io::Result<()> {
    swap_by_renames(a, b)
}

/// `b` aside, `a` to `b`, the old `b` to `a`: a swap with a moment where `b` is missing.
fn swap_by_renames(a: &Path, b: &Path) -> std::io::Result<()> {
    let mut aside = a.as_os_str().to_owned();
    aside.push(".old");
    let aside = PathBuf::from(aside);
    std::fs::rename(b, &aside)?;
    std::fs::rename(a, b)?;
    std::fs::rename(&aside, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(path: &Path, text: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }

    fn read(path: &Path) -> String {
        std::fs::read_to_string(path).unwrap()
    }

    #[test]
    fn publishing_replaces_the_run_and_keeps_what_is_not_a_run() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("reports");
        write(&target.join("index.html"), "old page");
        write(&target.join("peers.md"), "old peers");
        write(&target.join("meshes/a.glb"), "old mesh");
        write(&target.join("baselines/survey.json"), "baseline");
        write(&target.join("notes.txt"), "mine");
        let staged = StagedDir::begin(&target).unwrap();
        write(&staged.path().join("index.html"), "new page");
        write(&staged.path().join("meshes/b.glb"), "new mesh");
        // Until published the old report is untouched.
        assert_eq!(read(&target.join("index.html")), "old page");
        staged.publish().unwrap();
        assert_eq!(read(&target.join("index.html")), "new page");
        assert_eq!(read(&target.join("meshes/b.glb")), "new mesh");
        assert!(!target.join("meshes/a.glb").exists(), "an older run's entries do not survive");
        assert!(!target.join("peers.md").exists(), "an older run's entries do not survive");
        assert_eq!(read(&target.join("baselines/survey.json")), "baseline");
        assert_eq!(read(&target.join("notes.txt")), "mine");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left, vec![std::ffi::OsString::from("reports")], "no staging directory left");
    }

    #[test]
    fn an_unpublished_run_leaves_the_old_report_and_no_staging() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out");
        write(&target.join("index.html"), "old page");
        let staged = StagedDir::begin(&target).unwrap();
        write(&staged.path().join("index.html"), "half a page");
        drop(staged);
        assert_eq!(read(&target.join("index.html")), "old page");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // A first run: the target appears only when published.
        let fresh = dir.path().join("fresh");
        let staged = StagedDir::begin(&fresh).unwrap();
        write(&staged.path().join("index.html"), "page");
        assert!(!fresh.exists());
        staged.publish().unwrap();
        assert_eq!(read(&fresh.join("index.html")), "page");
    }

    #[test]
    fn a_killed_runs_staging_is_removed_and_a_file_target_refused() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("reports");
        // No process has this number (above Linux's pid_max).
        let abandoned = dir.path().join(format!("{}{}", staging_prefix(&target), 4_194_304 + 7));
        write(&abandoned.join("index.html"), "killed");
        let staged = StagedDir::begin(&target).unwrap();
        assert!(!abandoned.exists());
        drop(staged);
        let file = dir.path().join("a-file");
        std::fs::write(&file, "x").unwrap();
        let error = StagedDir::begin(&file).unwrap_err().to_string();
        assert!(error.contains("names a file"), "{error}");
    }
}
