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

fn run_commit(
    store: &mut HistoryStore,
    sha: &str,
    options: &CollectOptions,
    request: &str,
) -> Result<Outcome, HistoryError> {
    if store.has_request(sha, request)? {
        return Ok(Outcome::AlreadyRecorded);
    }
    if let Some(f) = store.failures()?.into_iter().find(|f| f.commit == sha && f.request == request) {
        if !options.retry_failed {
            return Ok(Outcome::FailedBefore(format!("{}: {}", f.stage, f.message)));
        }
        store.clear_failure(sha, request)?;
    }
    let work = &options.work_dir;
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |error| HistoryError::Io { path: path.clone(), error }
    };
    for dir in ["logs", "results"] {
        std::fs::create_dir_all(work.join(dir)).map_err(io(&work.join(dir)))?;
    }
    let worktree = work.join("worktree");
    let target = work.join("target");
    let log_path = work.join("logs").join(format!("{sha}.log"));
    let fail = |store: &HistoryStore, stage: &str, message: String| -> Result<Outcome, HistoryError> {
        let message = format!("{message} (log: {})", log_path.display());
        store.record_failure(&Failure {
            commit: sha.to_string(),
            request: request.to_string(),
            stage: stage.into(),
            message: message.clone(),
        })?;
        Ok(Outcome::Failed { stage: stage.into(), message })
    };
    git::checkout_worktree(&options.repo, &worktree, sha)?;
    let log = std::fs::File::create(&log_path).map_err(io(&log_path))?;
    let build = Command::new("cargo")
        .args(["build", "--release", "--quiet", "-p", "harness", "--bin", "harness"])
        .current_dir(&worktree)
        .env("CARGO_TARGET_DIR", &target)
        .stdout(log.try_clone().map_err(io(&log_path))?)
        .stderr(log.try_clone().map_err(io(&log_path))?)
        .status();
    match build {
        Ok(s) if s.success() => {}
        Ok(s) => return fail(store, "build", format!("cargo build exited with {s}")),
        Err(e) => return fail(store, "build", format!("cannot start cargo: {e}")),
    }
    let reports = work.join("runs").join(sha);
    let _ = std::fs::remove_dir_all(&reports);
    let binary = target.join("release/harness");
    let run = Command::new(&binary)
        .arg("all")
        .args(&options.suite_args)
        .args(["--quiet", "--no-check", "--reports"])
        .arg(&reports)
        .current_dir(&worktree)
        .stdout(log.try_clone().map_err(io(&log_path))?)
        .stderr(log)
        .status();
    let results = reports.join("results.json");
    match run {
        // A run with failed cases exits non-zero and still wrote its record: failures are data.
        Ok(_) if results.is_file() => {}
        Ok(s) => {
            return fail(store, "run", format!("`harness all` exited with {s} and wrote no results.json"))
        }
        Err(e) => return fail(store, "run", format!("cannot start {}: {e}", binary.display())),
    }
    let record = read_run(&results)?;
    if record.commit != sha {
        return fail(store, "run", format!("the run says it is of commit {}, not {sha}", record.commit));
    }
    let kept = work.join("results").join(format!("{sha}.json"));
    std::fs::copy(&results, &kept).map_err(io(&kept))?;
    let recorded =
        store.record_request(&record, &kept.display().to_string(), options.mixing, Some(request))?;
    // The report's pictures and meshes are not kept: results.json is the record.
    let _ = std::fs::remove_dir_all(&reports);
    Ok(Outcome::Recorded(recorded))
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
