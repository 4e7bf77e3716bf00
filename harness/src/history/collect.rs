//! Filling the store from the repository's commits.
//!
//! `history run`: for each commit, a worktree checked out at it (one, reused), the harness of that
//! commit built there (`cargo build --release`, its own target directory, reused across commits),
//! the suite run by that harness with `--no-check`, and its results.json recorded. Resumable: a
//! commit already recorded for the same request (suite arguments and machine) is skipped, one that
//! failed to build or run is skipped unless retried; a killed run loses only the commit it was on.
//!
//! `history find`: bisection of a step whose two sides are not parent and child: the commit
//! halfway along the first-parent line between them is run and recorded, the step found again,
//! until it lies between a commit and its parent.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::git;
use super::measures::Measure;
use super::run_record::read_run;
use super::store::{Failure, HistoryStore, Mixing, Recorded};
use super::timeline::{self, AttributedStep};
use super::HistoryError;

/// How each commit is run.
#[derive(Clone, Debug)]
pub struct CollectOptions {
    /// The repository (its commits are checked out from here).
    pub repo: PathBuf,
    /// Worktree, target directory, logs and kept results.json files.
    pub work_dir: PathBuf,
    /// Arguments after `harness all` (data, scenarios, threads, repetitions); `--quiet --no-check
    /// --reports DIR` are added.
    pub suite_args: Vec<String>,
    pub retry_failed: bool,
    pub mixing: Mixing,
}

impl CollectOptions {
    /// What makes two runs of one commit the same request: the suite arguments and this machine.
    pub fn request(&self) -> String {
        let machine = crate::provenance::Machine::read();
        format!(
            "all {} on {}, {} logical cores",
            self.suite_args.join(" "),
            machine.cpu_model,
            machine.logical_cores
        )
    }
}

/// What happened to one commit.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Recorded(Recorded),
    AlreadyRecorded,
    FailedBefore(String),
    Failed { stage: String, message: String },
}

/// Run and record each of `commits` in turn; `report` is told each commit's outcome as it ends.
pub fn run_commits(
    store: &mut HistoryStore,
    commits: &[String],
    options: &CollectOptions,
    mut report: impl FnMut(usize, &str, &Outcome),
) -> Result<Vec<Outcome>, HistoryError> {
    let request = options.request();
    let mut outcomes = Vec::new();
    for (i, sha) in commits.iter().enumerate() {
        let outcome = run_commit(store, sha, options, &request)?;
        report(i, sha, &outcome);
        outcomes.push(outcome);
    }
    Ok(outcomes)
}

/// Run and record the commit `sha` for `request` (see the module doc), unless it is recorded for
/// it already or failed before and is not to be retried. A build or run that fails is recorded as
/// the commit's failure and is an outcome, not an error.
fn run_commit(
    store: &mut HistoryStore,
    sha: &str,
    options: &CollectOptions,
    request: &str,
) -> Result<Outcome, HistoryError> {
    if let Some(outcome) = earlier_outcome(store, sha, options.retry_failed, request)? {
        return Ok(outcome);
    }
    let work = CommitWork::new(&options.work_dir, sha)?;
    let fail = |store: &HistoryStore, stage: &str, message: String| -> Result<Outcome, HistoryError> {
        let message = format!("{message} (log: {})", work.log.display());
        let failure = Failure { commit: sha.into(), request: request.into(), stage: stage.into(), message };
        store.record_failure(&failure)?;
        Ok(Outcome::Failed { stage: failure.stage, message: failure.message })
    };
    git::checkout_worktree(&options.repo, &work.worktree, sha)?;
    let log = std::fs::File::create(&work.log).map_err(io_error(&work.log))?;
    if let Err(message) = work.build(&log)? {
        return fail(store, "build", message);
    }
    let results = match work.run_suite(&options.suite_args, log)? {
        Ok(results) => results,
        Err(message) => return fail(store, "run", message),
    };
    let record = read_run(&results)?;
    if record.commit != sha {
        return fail(store, "run", format!("the run says it is of commit {}, not {sha}", record.commit));
    }
    std::fs::copy(&results, &work.kept).map_err(io_error(&work.kept))?;
    let recorded =
        store.record_request(&record, &work.kept.display().to_string(), options.mixing, Some(request))?;
    // The report's pictures and meshes are not kept: results.json is the record.
    let _ = std::fs::remove_dir_all(&work.reports);
    Ok(Outcome::Recorded(recorded))
}

/// What came of `sha` for `request` before: recorded already, or failed (unless `retry_failed`,
/// which clears the failure). `None`: it is to be run.
fn earlier_outcome(
    store: &mut HistoryStore,
    sha: &str,
    retry_failed: bool,
    request: &str,
) -> Result<Option<Outcome>, HistoryError> {
    if store.has_request(sha, request)? {
        return Ok(Some(Outcome::AlreadyRecorded));
    }
    if let Some(f) = store.failures()?.into_iter().find(|f| f.commit == sha && f.request == request) {
        if !retry_failed {
            return Ok(Some(Outcome::FailedBefore(format!("{}: {}", f.stage, f.message))));
        }
        store.clear_failure(sha, request)?;
    }
    Ok(None)
}

/// The error of the file operation on `path`.
fn io_error(path: &Path) -> impl Fn(std::io::Error) -> HistoryError {
    let path = path.to_path_buf();
    move |error| HistoryError::Io { path: path.clone(), error }
}

/// Where the work on one commit goes, under the work directory: the worktree and target directory
/// every commit shares, the commit's log, its report directory and its kept results.json.
struct CommitWork {
    worktree: PathBuf,
    target: PathBuf,
    log: PathBuf,
    reports: PathBuf,
    kept: PathBuf,
}

impl CommitWork {
    /// The work on `sha` under `work_dir`, whose `logs` and `results` directories are made.
    fn new(work_dir: &Path, sha: &str) -> Result<Self, HistoryError> {
        for dir in ["logs", "results"] {
            std::fs::create_dir_all(work_dir.join(dir)).map_err(io_error(&work_dir.join(dir)))?;
        }
        Ok(Self {
            worktree: work_dir.join("worktree"),
            target: work_dir.join("target"),
            log: work_dir.join("logs").join(format!("{sha}.log")),
            reports: work_dir.join("runs").join(sha),
            kept: work_dir.join("results").join(format!("{sha}.json")),
        })
    }

    /// Build the harness of the commit checked out in the worktree (`cargo build --release`, in the
    /// shared target directory), its output to `log`. `Ok(Err(why))`: the build failed.
    fn build(&self, log: &std::fs::File) -> Result<Result<(), String>, HistoryError> {
        let build = Command::new("cargo")
            .args(["build", "--release", "--quiet", "-p", "harness", "--bin", "harness"])
            .current_dir(&self.worktree)
            .env("CARGO_TARGET_DIR", &self.target)
            .stdout(log.try_clone().map_err(io_error(&self.log))?)
            .stderr(log.try_clone().map_err(io_error(&self.log))?)
            .status();
        Ok(match build {
            Ok(s) if s.success() => Ok(()),
            Ok(s) => Err(format!("cargo build exited with {s}")),
            Err(e) => Err(format!("cannot start cargo: {e}")),
        })
    }

    /// Run the suite with the commit's harness (`harness all`, `suite_args` and `--quiet --no-check`,
    /// into a fresh report directory), its output to `log`. The results.json it wrote, or
    /// `Ok(Err(why))`: it wrote none.
    fn run_suite(
        &self,
        suite_args: &[String],
        log: std::fs::File,
    ) -> Result<Result<PathBuf, String>, HistoryError> {
        let _ = std::fs::remove_dir_all(&self.reports);
        let binary = self.target.join("release/harness");
        let run = Command::new(&binary)
            .arg("all")
            .args(suite_args)
            .args(["--quiet", "--no-check", "--reports"])
            .arg(&self.reports)
            .current_dir(&self.worktree)
            .stdout(log.try_clone().map_err(io_error(&self.log))?)
            .stderr(log)
            .status();
        let results = self.reports.join("results.json");
        Ok(match run {
            // A run with failed cases exits non-zero and still wrote its record: failures are data.
            Ok(_) if results.is_file() => Ok(results),
            Ok(s) => Err(format!("`harness all` exited with {s} and wrote no results.json")),
            Err(e) => Err(format!("cannot start {}: {e}", binary.display())),
        })
    }
}

/// The case and measure `history find` bisects.
#[derive(Clone, Debug)]
pub struct FindTarget {
    pub measure: Measure,
    pub scenario: Option<String>,
    pub method: Option<String>,
}

/// What `history find` found: the step, and the commit that made it.
#[derive(Clone, Debug)]
pub struct Found {
    pub scenario: String,
    pub method: String,
    pub step: AttributedStep,
    pub commit: git::CommitInfo,
    /// Commits run on the way.
    pub runs: usize,
}

/// Bisect every step of `target`'s timelines that lies between two commits that are not parent
/// and child, until each is; `report` is told each commit run.
pub fn find(
    store: &mut HistoryStore,
    target: &FindTarget,
    options: &CollectOptions,
    mut report: impl FnMut(&str, &Outcome),
) -> Result<Vec<Found>, HistoryError> {
    let mut runs = 0;
    let mut tried: Vec<String> = Vec::new();
    loop {
        let history = timeline::build(store, &options.repo)?;
        let mut open = None;
        let mut found = Vec::new();
        for t in history.timelines.iter().filter(|t| {
            t.measure == target.measure
                && target.scenario.as_ref().is_none_or(|s| *s == t.scenario)
                && target.method.as_ref().is_none_or(|m| *m == t.method)
        }) {
            for s in &t.steps {
                match s.made_by {
                    Some(c) => found.push(Found {
                        scenario: t.scenario.clone(),
                        method: t.method.clone(),
                        step: s.clone(),
                        commit: history.commits[c].clone(),
                        runs,
                    }),
                    None => {
                        let line = git::between(
                            &options.repo,
                            &history.commits[s.from].sha,
                            &history.commits[s.to].sha,
                        )?;
                        let candidates: Vec<&String> = line[..line.len().saturating_sub(1)]
                            .iter()
                            .filter(|c| !tried.contains(c))
                            .collect();
                        if open.is_none() && !candidates.is_empty() {
                            open = Some(candidates[candidates.len() / 2].clone());
                        }
                    }
                }
            }
        }
        let Some(next) = open else {
            return Ok(found);
        };
        tried.push(next.clone());
        let outcome = run_commits(store, std::slice::from_ref(&next), options, |_, _, _| {})?.remove(0);
        runs += 1;
        report(&next, &outcome);
    }
}
