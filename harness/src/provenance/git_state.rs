//! The state of a git checkout: its commit, whether tracked files differ from it, and the hash of
//! the difference. Read by the build script (`harness/build.rs`, which compiles the state of the
//! checkout the binary is built from into it) and by nothing that runs later, so that a run
//! records the build, not whatever the checkout holds by then. Depends on `std` and `sha2` only,
//! as the build script includes this file.

use std::path::Path;

/// Commit, dirtiness and diff hash of a checkout; `None` where git cannot say (no git, no
/// checkout).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GitState {
    /// `git rev-parse HEAD`.
    pub commit: Option<String>,
    /// Whether tracked files differ from `commit` (`git status --untracked-files=no`).
    pub dirty: Option<bool>,
    /// When dirty: [`diff_sha256`].
    pub diff_sha256: Option<String>,
}

/// The state of the checkout at `repo`.
pub fn read(repo: &Path) -> GitState {
    let commit = git(repo, &["rev-parse", "HEAD"]);
    let dirty = commit
        .as_ref()
        .and_then(|_| git(repo, &["status", "--porcelain", "--untracked-files=no"]))
        .map(|status| !status.is_empty());
    let diff_sha256 = if dirty == Some(true) { diff_sha256(repo) } else { None };
    GitState { commit, dirty, diff_sha256 }
}

/// The files whose change can change [`read`]'s answer besides the tracked files themselves: the
/// `HEAD` file, the branch it names and the packed refs (absolute paths; empty without git).
pub fn head_files(repo: &Path) -> Vec<std::path::PathBuf> {
    let mut names = vec!["HEAD".to_string(), "packed-refs".to_string()];
    names.extend(git(repo, &["symbolic-ref", "-q", "HEAD"]));
    names
        .iter()
        .filter_map(|name| git(repo, &["rev-parse", "--path-format=absolute", "--git-path", name]))
        .map(std::path::PathBuf::from)
        .collect()
}

/// The SHA-256 (hex) of the uncommitted change of the git checkout at `repo`: the bytes of `git diff
/// HEAD --binary`, staged and unstaged changes of tracked files, with the options that the user's
/// git configuration could change fixed (no external diff, textconv, colour or renames, `a/` and
/// `b/` prefixes). Decision: untracked files are not part of it, as they are not of `dirty`
/// (`git status --untracked-files=no`): reports, logs and scratch files in a checkout would make
/// every run a state of its own. A new source file counts once it is added (`git add -N` is
/// enough). `None` when git cannot say.
pub fn diff_sha256(repo: &Path) -> Option<String> {
    use sha2::Digest;
    let out = std::process::Command::new("git")
        .arg("-C")
        .arg(repo)
        .args([
            "diff",
            "HEAD",
            "--binary",
            "--no-ext-diff",
            "--no-textconv",
            "--no-color",
            "--no-renames",
            "--src-prefix=a/",
            "--dst-prefix=b/",
        ])
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    Some(sha2::Sha256::digest(&out.stdout).iter().map(|b| format!("{b:02x}")).collect())
}

/// `git -C repo args...`'s trimmed output, if it ran and succeeded.
fn git(repo: &Path, args: &[&str]) -> Option<String> {
    std::process::Command::new("git")
        .arg("-C")
        .arg(repo)
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}
