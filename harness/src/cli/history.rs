//! `harness history`: record runs, fill the store from commits, show timelines, bisect a step.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Subcommand};

use crate::history::collect::{self, CollectOptions, FindTarget, Outcome};
use crate::history::measures::Measure;
use crate::history::store::{HistoryStore, Mixing, Recorded};
use crate::history::{self, git, page, run_record, timeline};
use crate::paths::SURVEY_DIR_ENV;

#[derive(Subcommand)]
pub(super) enum HistoryCommand {
    /// Store runs (report directories or results.json files) with their provenance; a run already
    /// stored adds nothing.
    Record {
        #[arg(required = true)]
        reports: Vec<PathBuf>,
        #[command(flatten)]
        store: StoreArgs,
        /// Keep a run of another data source or machine class (or other data files) on timelines of
        /// its own instead of refusing it.
        #[arg(long)]
        allow_mixed: bool,
        /// Record a run made from a tree that differed from its commit.
        #[arg(long)]
        allow_dirty: bool,
    },
    /// For each commit of the revisions (`A..B` is git's: after A up to B on the first-parent line;
    /// a name is one commit): check it out in a worktree, build its harness, run the suite, record.
    /// Resumable: commits recorded for the same arguments are skipped.
    Run {
        /// Revisions: `A..B` ranges and single commits.
        #[arg(required = true)]
        revisions: Vec<String>,
        /// Run N commits evenly spread over the revisions (the first and last among them); N >= 1.
        #[arg(long, value_parser = at_least_one)]
        steps: Option<u32>,
        #[command(flatten)]
        store: StoreArgs,
        #[command(flatten)]
        suite: SuiteArgs,
    },
    /// Remove every run of the commits from the store (a run spoiled by a loaded machine, say),
    /// so that `history run` runs them again.
    Forget {
        #[arg(required = true)]
        commits: Vec<String>,
        #[command(flatten)]
        store: StoreArgs,
        /// The git checkout the commits are named in [default: the repository of the current
        /// directory; without one, a commit is found by its hash's first digits among the stored].
        #[arg(long)]
        repo: Option<PathBuf>,
    },
    /// Write the history page: timelines per scenario × method (PNG), steps named with commits.
    Show {
        #[command(flatten)]
        store: StoreArgs,
        /// Where index.html, steps.md and plots/ go [default: history/page next to the store].
        #[arg(long)]
        out: Option<PathBuf>,
        /// The git checkout whose history orders the commits [default: the repository of the current
        /// directory].
        #[arg(long)]
        repo: Option<PathBuf>,
    },
    /// Bisect the steps of MEASURE (e.g. iterations, peak_memory_mib, e_theta_deg) that lie between
    /// two recorded commits that are not parent and child, running the commits between, until
    /// each is named with the commit that made it.
    Find {
        measure: String,
        #[arg(long)]
        scenario: Option<String>,
        #[arg(long)]
        method: Option<String>,
        #[command(flatten)]
        store: StoreArgs,
        #[command(flatten)]
        suite: SuiteArgs,
    },
}

#[derive(Args, Clone)]
pub(super) struct StoreArgs {
    /// The history store [env: DEFORMBENCH_HISTORY] [default: ./history/history.sqlite, relative to
    /// the current directory].
    #[arg(long)]
    store: Option<PathBuf>,
}

impl StoreArgs {
    fn path(&self) -> PathBuf {
        self.store
            .clone()
            .or_else(|| super::path_from_env(history::STORE_ENV))
            .unwrap_or_else(history::default_store)
    }
}

#[derive(Args, Clone)]
pub(super) struct SuiteArgs {
    /// The survey's .off/.sel/.def files [env: DEFORM_SURVEY_DIR]; without it the procedural
    /// look-alikes.
    #[arg(long)]
    survey_dir: Option<PathBuf>,
    /// Scenario directory, relative to each commit's checkout (e.g. configs/real-meshes).
    #[arg(long)]
    scenarios: Option<PathBuf>,
    /// Worker threads of every method (1 or more).
    #[arg(long, default_value_t = 2, value_parser = at_least_one)]
    threads: u32,
    /// Rounds of each case (1 or more): their spread is the band of the time timelines.
    #[arg(long, default_value_t = 3, value_parser = at_least_one)]
    repeat: u32,
    /// Worktree, build and logs [default: history/work next to the store].
    #[arg(long)]
    work_dir: Option<PathBuf>,
    /// The git checkout whose commits are run [default: the repository of the current directory].
    #[arg(long)]
    repo: Option<PathBuf>,
    /// Retry commits that failed to build or run before.
    #[arg(long)]
    retry_failed: bool,
    /// Keep a run of another series on timelines of its own instead of refusing it.
    #[arg(long)]
    allow_mixed: bool,
}

/// A count of the history commands, which 0 would make meaningless (`--steps 0` ran every commit,
/// `--repeat 0` no round, `--threads 0` no worker): refused by clap, exit 2.
fn at_least_one(text: &str) -> Result<u32, String> {
    match text.parse::<u32>() {
        Ok(0) => Err("0 is not allowed here: give 1 or more".to_string()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("{e}: give a whole number, 1 or more")),
    }
}

impl SuiteArgs {
    fn options(&self, store: &std::path::Path) -> anyhow::Result<CollectOptions> {
        let repo = history::repository(self.repo.as_deref())?;
        let mut suite_args = vec![
            "--threads".to_string(),
            self.threads.to_string(),
            "--repeat".into(),
            self.repeat.to_string(),
            "--jobs".into(),
            "1".into(),
        ];
        let survey = self.survey_dir.clone().or_else(|| super::path_from_env(SURVEY_DIR_ENV));
        if let Some(dir) = survey {
            let dir =
                dir.canonicalize().map_err(|e| anyhow::anyhow!("--survey-dir {}: {e}", dir.display()))?;
            suite_args.extend(["--survey-dir".to_string(), dir.display().to_string()]);
        }
        if let Some(s) = &self.scenarios {
            suite_args.extend(["--scenarios".to_string(), s.display().to_string()]);
        }
        let work_dir = self
            .work_dir
            .clone()
            .unwrap_or_else(|| store.parent().unwrap_or(std::path::Path::new(".")).join("work"));
        Ok(CollectOptions {
            repo,
            work_dir,
            suite_args,
            retry_failed: self.retry_failed,
            mixing: if self.allow_mixed { Mixing::Allow } else { Mixing::Refuse },
        })
    }
}

fn print_outcome(label: &str, outcome: &Outcome) {
    match outcome {
        Outcome::Recorded(Recorded::Added { cases, measurements, .. }) => {
            println!("{label}: recorded ({cases} cases, {measurements} values)")
        }
        Outcome::Recorded(Recorded::AlreadyThere { .. }) | Outcome::AlreadyRecorded => {
            println!("{label}: already recorded")
        }
        Outcome::FailedBefore(why) => {
            println!("{label}: skipped, failed before ({why}; --retry-failed runs it again)")
        }
        Outcome::Failed { stage, message } => println!("{label}: {stage} failed: {message}"),
    }
}

/// The stored commit `name` means for `history forget`: git's reading of it in `repo`, else the one
/// stored hash that begins with it; an error naming it when the store holds no runs (nor failures)
/// of it.
fn forget_target(
    name: &str,
    repo: Option<&Path>,
    stored: &BTreeMap<String, (usize, usize)>,
    store: &Path,
) -> anyhow::Result<String> {
    if let Some(sha) = repo.and_then(|r| git::resolve(r, name).ok()) {
        anyhow::ensure!(
            stored.contains_key(&sha),
            "{name} ({}): no runs of it are stored in {}; nothing removed",
            &sha[..sha.len().min(12)],
            store.display()
        );
        return Ok(sha);
    }
    let prefix = name.to_ascii_lowercase();
    let matches: Vec<&String> = if prefix.len() >= 4 && prefix.chars().all(|c| c.is_ascii_hexdigit()) {
        stored.keys().filter(|k| k.starts_with(&prefix)).collect()
    } else {
        Vec::new()
    };
    match matches[..] {
        [one] => Ok(one.clone()),
        [] => anyhow::bail!(
            "{name}: no runs of it are stored in {}{}; nothing removed",
            store.display(),
            match repo {
                Some(r) => format!(", and it is not a commit of {}", r.display()),
                None => " (and no git repository here to read it in; --repo names one)".to_string(),
            }
        ),
        _ => anyhow::bail!(
            "{name}: the hashes of {} stored commits begin with it; give more digits; nothing removed",
            matches.len()
        ),
    }
}

pub(super) fn run(command: HistoryCommand) -> anyhow::Result<ExitCode> {
    match command {
        HistoryCommand::Record { reports, store, allow_mixed, allow_dirty } => {
            let mixing = if allow_mixed { Mixing::Allow } else { Mixing::Refuse };
            record(&reports, &store.path(), mixing, allow_dirty)
        }
        HistoryCommand::Run { revisions, steps, store, suite } => {
            run_revisions(&revisions, steps, &store, &suite)
        }
        HistoryCommand::Forget { commits, store, repo } => forget(&commits, &store.path(), repo),
        HistoryCommand::Show { store, out, repo } => show(&store.path(), out, repo.as_deref()),
        HistoryCommand::Find { measure, scenario, method, store, suite } => {
            find(&measure, scenario, method, &store.path(), &suite)
        }
    }
}

/// `history record`: store the runs of `reports` (report directories or results.json files) in the
/// store at `path`, all or none; a run of a dirty tree only with `allow_dirty`.
fn record(reports: &[PathBuf], path: &Path, mixing: Mixing, allow_dirty: bool) -> anyhow::Result<ExitCode> {
    // Every run is read and checked before the store is touched: a bad file records nothing.
    let runs = reports.iter().map(|r| run_record::read_run(r)).collect::<Result<Vec<_>, _>>()?;
    if let Some((r, _)) = reports.iter().zip(&runs).find(|(_, run)| run.dirty && !allow_dirty) {
        anyhow::bail!(
            "{}: made from a tree that differed from its commit (git_dirty); its values belong to no commit. --allow-dirty records it as a point of its own (the commit, +dirty: and its diff's hash)",
            r.display()
        );
    }
    let mut history = HistoryStore::open_or_create(path)?;
    // All or nothing: one transaction, in which each run is also judged against the runs
    // before it in this call.
    let sources: Vec<(&run_record::RunRecord, String)> =
        runs.iter().zip(reports).map(|(run, r)| (run, r.display().to_string())).collect();
    let outcomes = match history.record_all(&sources, mixing) {
        Ok(outcomes) => outcomes,
        Err(e) => {
            history.abandon();
            return Err(
                anyhow::Error::new(e).context(format!("nothing of the {} run(s) was recorded", runs.len()))
            );
        }
    };
    for ((r, run), outcome) in reports.iter().zip(&runs).zip(outcomes) {
        let point = run_record::point_label(&run.commit, 12, run.diff.as_deref().or(run.dirty.then_some("")));
        let label = format!("{} ({point})", r.display());
        print_outcome(&label, &Outcome::Recorded(outcome));
    }
    println!("store: {}", path.display());
    Ok(ExitCode::SUCCESS)
}

/// `history run`: run and record each commit of `revisions` (`steps` of them, evenly spread, when
/// given) in the store of `store`, with the suite `suite`. Exits with the failed-case code when a
/// commit failed to build or run.
fn run_revisions(
    revisions: &[String],
    steps: Option<u32>,
    store: &StoreArgs,
    suite: &SuiteArgs,
) -> anyhow::Result<ExitCode> {
    let path = store.path();
    let options = suite.options(&path)?;
    let mut commits = git::expand(&options.repo, revisions)?;
    if let Some(n) = steps {
        commits = git::thin(&commits, n as usize);
    }
    let mut history = HistoryStore::open_or_create(&path)?;
    println!("{} commit(s) to run: {}", commits.len(), options.request());
    let total = commits.len();
    let outcomes = collect::run_commits(&mut history, &commits, &options, |i, sha, outcome| {
        print_outcome(&format!("[{}/{total}] {}", i + 1, &sha[..12]), outcome)
    })?;
    let failed = outcomes.iter().filter(|o| matches!(o, Outcome::Failed { .. })).count();
    println!("store: {}", path.display());
    Ok(if failed > 0 { ExitCode::from(super::EXIT_CASE_FAILED) } else { ExitCode::SUCCESS })
}

/// `history forget`: remove every run of `commits` (named in `repo`, or by their first digits
/// among the stored) from the store at `path`; nothing when one of them names no stored commit.
fn forget(commits: &[String], path: &Path, repo: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    let mut history = HistoryStore::open_existing(path)?;
    // Without a repository a commit is still found among the stored by its first digits.
    let repo = match repo {
        Some(dir) => Some(history::repository(Some(&dir))?),
        None => history::repository(None).ok(),
    };
    let stored = history.stored_commits()?;
    // Every name is resolved and checked first: one that names no stored commit removes
    // nothing, not even the runs of the others.
    let shas = commits
        .iter()
        .map(|c| forget_target(c, repo.as_deref(), &stored, path))
        .collect::<anyhow::Result<Vec<_>>>()?;
    for (c, n) in commits.iter().zip(history.forget_all(&shas)?) {
        println!("{c}: {n} run(s) removed");
    }
    Ok(ExitCode::SUCCESS)
}

/// `history show`: write the history page of the store at `path` to `out` (default: `page` next to
/// the store), commits in the order of `repo`'s history, and print its steps.
fn show(path: &Path, out: Option<PathBuf>, repo: Option<&Path>) -> anyhow::Result<ExitCode> {
    let history_store = HistoryStore::open_existing(path)?;
    let repo = history::repository(repo)?;
    let built = timeline::build(&history_store, &repo)?;
    let out = out.unwrap_or_else(|| path.parent().unwrap_or(std::path::Path::new(".")).join("page"));
    let index = page::write_page(&out, &built, path)?;
    let steps = page::all_steps(&built);
    println!(
        "{}, {} timelines, {} step(s){}",
        page::points_text(&built),
        built.timelines.len(),
        steps.len(),
        if steps.is_empty() { "" } else { ":" }
    );
    for (t, s) in steps {
        println!("  {}", page::step_line(&built, t, s));
    }
    println!("history page: {}", index.display());
    Ok(ExitCode::SUCCESS)
}

/// `history find`: bisect the steps of the measure named `measure` (of `scenario` and `method`
/// when given) in the store at `path`, running commits with the suite `suite`, and print the
/// commit that made each.
fn find(
    measure: &str,
    scenario: Option<String>,
    method: Option<String>,
    path: &Path,
    suite: &SuiteArgs,
) -> anyhow::Result<ExitCode> {
    let measure = Measure::from_key(measure).ok_or_else(|| {
        let keys: Vec<&str> = Measure::all().into_iter().map(Measure::key).collect();
        anyhow::anyhow!("unknown measure `{measure}`; one of {}", keys.join(", "))
    })?;
    let options = suite.options(path)?;
    let mut history_store = HistoryStore::open_existing(path)?;
    let target = FindTarget { measure, scenario, method };
    let found = collect::find(&mut history_store, &target, &options, |sha, outcome| {
        print_outcome(&format!("bisect {}", &sha[..12]), outcome)
    })?;
    if found.is_empty() {
        println!("no step of {} found", measure.key());
    }
    for f in &found {
        println!(
            "{} / {} {}: {:.4} -> {:.4} ({:+.1}%), made by {} {} ({} commit(s) run)",
            f.scenario,
            f.method,
            measure.key(),
            f.step.before,
            f.step.after,
            100.0 * f.step.relative,
            f.commit.label(),
            page::short_subject(&f.commit.subject),
            f.runs
        );
    }
    Ok(ExitCode::SUCCESS)
}
