//! Results across commits, what asv gives Python projects: a store of every recorded run
//! ([`store`]), timelines per scenario × method × measure in commit order with steps detected by a
//! piecewise-constant fit weighted by each point's noise ([`timeline`], [`steps`]) and named with
//! the commit that made them, a page of them ([`page`]), and the commands that fill the store from
//! the repository's own commits: `history run A..B` (a worktree, a build and a suite run per commit,
//! resumable) and `history find MEASURE` (bisect a step down to one commit) ([`collect`]).

pub mod collect;
pub mod git;
pub mod measures;
pub mod page;
pub mod run_record;
pub mod steps;
pub mod store;
pub mod timeline;

use std::path::{Path, PathBuf};

/// Where the store lives unless `--store` or [`STORE_ENV`] says otherwise, relative to the current
/// directory (not to the checkout the harness was built in: an installed harness, or one built in
/// another worktree, keeps the history of the project it is run in). `history/`, not reports/,
/// which a run replaces whole.
pub const DEFAULT_STORE: &str = "history/history.sqlite";

/// [`DEFAULT_STORE`] as a path.
pub fn default_store() -> PathBuf {
    PathBuf::from(DEFAULT_STORE)
}

/// The git repository whose commits `history run`, `find`, `show` and `forget` work on: `repo`
/// (`--repo`) when given, else the one holding the current directory; an error that says which,
/// and names `--repo`, when it is not in one.
pub fn repository(repo: Option<&Path>) -> Result<PathBuf, HistoryError> {
    match repo {
        Some(dir) => git::repository_root(dir).map_err(|e| {
            HistoryError::Usage(format!("--repo {}: not in a git repository ({e})", dir.display()))
        }),
        None => {
            let cwd = std::env::current_dir()
                .map_err(|e| HistoryError::Usage(format!("cannot read the current directory: {e}")))?;
            git::repository_root(&cwd).map_err(|e| {
                HistoryError::Usage(format!(
                    "the current directory {} is not in a git repository: run from a checkout of the \
                     project, or give --repo PATH ({e})",
                    cwd.display()
                ))
            })
        }
    }
}

/// Environment variable naming the store.
pub const STORE_ENV: &str = "DEFORMBENCH_HISTORY";

/// What can go wrong with the history.
#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    #[error("{}: not a usable history store: {detail}. It is left as it is: move it away, or give another --store", path.display())]
    Corrupt { path: PathBuf, detail: String },
    #[error("{}: cannot be the history store: {reason}; nothing was written", path.display())]
    Unusable { path: PathBuf, reason: String },
    #[error("{}: no history store here (`harness history record REPORTS` or `harness history run A..B` makes one)", path.display())]
    NoStore { path: PathBuf },
    #[error("{}: refused, this run would mix series: {}. Give --allow-mixed to keep it on timelines of its own", path.display(), conflicts.join("; "))]
    Mixed { path: PathBuf, conflicts: Vec<String> },
    #[error("{}: {error}", path.display())]
    Sqlite { path: PathBuf, error: rusqlite::Error },
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    #[error("{}: {message}", path.display())]
    Results { path: PathBuf, message: String },
    #[error("git: {0}")]
    Git(String),
    #[error("{0}")]
    Usage(String),
    #[error(transparent)]
    Report(#[from] crate::HarnessError),
}
