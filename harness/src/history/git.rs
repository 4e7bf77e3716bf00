//! What the history asks of git: commits in order, their subjects and first parents, the files
//! they touched, and a worktree to build a commit in.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use super::HistoryError;

/// Run `git -C repo args`; its stdout, or an error with its stderr.
pub fn git(repo: &Path, args: &[&str]) -> Result<String, HistoryError> {
    let out = Command::new("git")
        .arg("-C")
        .arg(repo)
        .args(args)
        .output()
        .map_err(|e| HistoryError::Git(format!("cannot start git: {e}")))?;
    if !out.status.success() {
        return Err(HistoryError::Git(format!(
            "`git {}` in {}: {}",
            args.join(" "),
            repo.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The full hash of `rev`.
pub fn resolve(repo: &Path, rev: &str) -> Result<String, HistoryError> {
    Ok(git(repo, &["rev-parse", "--verify", "--quiet", &format!("{rev}^{{commit}}")])
        .map_err(|_| HistoryError::Git(format!("`{rev}` is not a commit of {}", repo.display())))?
        .trim()
        .to_string())
}

/// The commits of `specs`, oldest first, each once: `A..B` is git's (the first-parent line from B
/// back to, not including, A), anything else one commit.
pub fn expand(repo: &Path, specs: &[String]) -> Result<Vec<String>, HistoryError> {
    let mut commits: Vec<String> = Vec::new();
    for spec in specs {
        let found = match spec.split_once("..") {
            Some((a, b)) => {
                let range = format!(
                    "{}..{}",
                    resolve(repo, a)?,
                    resolve(repo, if b.is_empty() { "HEAD" } else { b })?
                );
                git(repo, &["rev-list", "--first-parent", "--reverse", &range])?
                    .lines()
                    .map(str::to_string)
                    .collect()
            }
            None => vec![resolve(repo, spec)?],
        };
        for c in found {
            if !commits.contains(&c) {
                commits.push(c);
            }
        }
    }
    if commits.is_empty() {
        return Err(HistoryError::Usage(format!("{} names no commit", specs.join(" "))));
    }
    Ok(commits)
}

/// `n` of `commits` evenly spaced, the first and the last among them (all of them if `n` is at
/// least their number).
pub fn thin(commits: &[String], n: usize) -> Vec<String> {
    if n >= commits.len() || n == 0 {
        return commits.to_vec();
    }
    if n == 1 {
        return vec![commits[commits.len() - 1].clone()];
    }
    let mut picked: Vec<String> = Vec::new();
    for k in 0..n {
        let i = (k * (commits.len() - 1) + (n - 1) / 2) / (n - 1);
        if !picked.contains(&commits[i]) {
            picked.push(commits[i].clone());
        }
    }
    picked
}

/// What the history shows of a commit, or of an uncommitted change of it (a point of the
/// timelines: runs of a dirty tree are points of their own, [`CommitInfo::dirty`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CommitInfo {
    pub sha: String,
    /// `None`: the commit as committed. `Some(hash)`: runs of its tree with an uncommitted change,
    /// the SHA-256 of that change (`""` when the runs did not record one).
    pub dirty: Option<String>,
    /// Committer time, seconds since the epoch.
    pub time: i64,
    pub date: String,
    pub subject: String,
    /// First parent's full hash (none for a root commit).
    pub parent: Option<String>,
}

impl CommitInfo {
    pub fn short(&self) -> &str {
        &self.sha[..self.sha.len().min(7)]
    }

    /// The point for people: the short hash, with `+dirty:1a2b3c` for an uncommitted change
    /// ([`super::run_record::point_label`]).
    pub fn label(&self) -> String {
        super::run_record::point_label(&self.sha, 7, self.dirty.as_deref())
    }

    /// Whether `self` comes right after `before`, so that a step between them is `self`'s doing:
    /// a commit after its first parent as committed, or an uncommitted change after its own commit
    /// as committed. (A commit after an uncommitted change of its parent is not: the step could be
    /// the change's.)
    pub fn follows(&self, before: &CommitInfo) -> bool {
        if before.dirty.is_some() {
            return false;
        }
        match self.dirty {
            None => self.parent.as_deref() == Some(before.sha.as_str()),
            Some(_) => self.sha == before.sha,
        }
    }
}

/// Subjects, times and first parents of `shas` (those git knows).
pub fn infos(repo: &Path, shas: &[String]) -> HashMap<String, CommitInfo> {
    let mut out = HashMap::new();
    for sha in shas {
        let Ok(text) = git(repo, &["show", "-s", "--format=%H%x00%ct%x00%cs%x00%P%x00%s", sha]) else {
            continue;
        };
        let fields: Vec<&str> = text.trim_end_matches('\n').splitn(5, '\0').collect();
        if fields.len() == 5 {
            out.insert(
                sha.clone(),
                CommitInfo {
                    sha: fields[0].to_string(),
                    dirty: None,
                    time: fields[1].parse().unwrap_or(0),
                    date: fields[2].to_string(),
                    parent: fields[3].split_whitespace().next().map(str::to_string),
                    subject: fields[4].to_string(),
                },
            );
        }
    }
    out
}

/// Each commit's place in the repository's topological order (oldest first), for every commit
/// reachable from a ref; empty where git cannot tell.
pub fn topological_order(repo: &Path) -> HashMap<String, usize> {
    git(repo, &["rev-list", "--topo-order", "--reverse", "--all"])
        .map(|text| text.lines().enumerate().map(|(i, sha)| (sha.to_string(), i)).collect())
        .unwrap_or_default()
}

/// The first-parent line from `a` (exclusive) to `b` (inclusive), oldest first.
pub fn between(repo: &Path, a: &str, b: &str) -> Result<Vec<String>, HistoryError> {
    Ok(git(repo, &["rev-list", "--first-parent", "--reverse", &format!("{a}..{b}")])?
        .lines()
        .map(str::to_string)
        .collect())
}

/// The files changed from `a` to `b`.
pub fn changed_files(repo: &Path, a: &str, b: &str) -> Result<Vec<String>, HistoryError> {
    Ok(git(repo, &["diff", "--name-only", a, b])?.lines().map(str::to_string).collect())
}

/// Whether a change to `files` can change what a method computes: the methods crate's code, the
/// method parameters (configs/methods.toml) or the dependency versions (Cargo.lock).
pub fn touches_methods(files: &[String]) -> bool {
    files.iter().any(|f| f.starts_with("methods/src/") || f == "configs/methods.toml" || f == "Cargo.lock")
}

/// The top of the git checkout that holds `dir`.
pub fn repository_root(dir: &Path) -> Result<PathBuf, HistoryError> {
    Ok(PathBuf::from(git(dir, &["rev-parse", "--show-toplevel"])?.trim()))
}

/// A detached worktree of `repo` at `dir`, checked out at `sha` (made on first use, reused after;
/// files a run left are not tracked and stay).
pub fn checkout_worktree(repo: &Path, dir: &Path, sha: &str) -> Result<(), HistoryError> {
    if dir.join(".git").exists() {
        git(dir, &["checkout", "--quiet", "--detach", "--force", sha])?;
    } else {
        let _ = git(repo, &["worktree", "prune"]);
        git(repo, &["worktree", "add", "--quiet", "--detach", "--force", &dir.display().to_string(), sha])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_both_ends_and_spaces_the_rest() {
        let commits: Vec<String> = (0..10).map(|i| i.to_string()).collect();
        assert_eq!(thin(&commits, 4), vec!["0", "3", "6", "9"]);
        assert_eq!(thin(&commits, 2), vec!["0", "9"]);
        assert_eq!(thin(&commits, 20), commits);
    }

    #[test]
    fn method_code_configs_and_the_lock_file_touch_methods() {
        assert!(touches_methods(&["methods/src/arap.rs".into()]));
        assert!(touches_methods(&["configs/methods.toml".into()]));
        assert!(!touches_methods(&["harness/src/report/html.rs".into(), "docs/results.md".into()]));
    }
}
