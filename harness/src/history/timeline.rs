//! Timelines from the store: per series, scenario, method and measure, one point per commit in the
//! repository's order (several runs of a commit: the median value, the widest spread), the fitted
//! levels and the steps between them, each named with the commit that made it when the commits on
//! either side are parent and child, else with the range to bisect (`history find`).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::git::{self, CommitInfo};
use super::measures::Measure;
use super::steps::{self, Observation};
use super::store::{HistoryStore, StoredRun};
use super::HistoryError;
use crate::record::CaseKey;

/// One point: a commit's value of the measure (or an uncommitted change's, [`CommitInfo::dirty`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// Index into [`History::commits`].
    pub commit: usize,
    pub value: f64,
    pub low: f64,
    pub high: f64,
    /// The noise it is weighed with ([`Measure::sigma`]).
    pub sigma: f64,
    /// The case's status in that commit's (last) run.
    pub status: String,
}

/// A step of a timeline, between two of its points.
#[derive(Clone, Debug, PartialEq)]
pub struct AttributedStep {
    /// Index into [`History::commits`] of the last point at the old level.
    pub from: usize,
    /// Index of the first point at the new level.
    pub to: usize,
    pub before: f64,
    pub after: f64,
    /// `after / before - 1`.
    pub relative: f64,
    /// The commit that made it: `to`, when it follows `from` ([`CommitInfo::follows`]: `from` is its
    /// first parent, or `to` is an uncommitted change of `from`).
    pub made_by: Option<usize>,
}

/// The timeline of one measure of one case in one series.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    pub series: String,
    pub scenario: String,
    pub method: String,
    pub measure: Measure,
    pub points: Vec<Point>,
    /// The fitted level of each point.
    pub fitted: Vec<f64>,
    pub steps: Vec<AttributedStep>,
}

/// Which case of which series a timeline follows.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct TimelineKey {
    pub series: String,
    pub case: CaseKey,
}

impl Timeline {
    /// The case of the series it follows.
    pub fn key(&self) -> TimelineKey {
        TimelineKey { series: self.series.clone(), case: CaseKey::new(&self.scenario, &self.method) }
    }
}

/// Every timeline of a store, over its commits.
#[derive(Clone, Debug)]
pub struct History {
    /// The stored commits in the repository's order (oldest first); runs of a dirty tree are
    /// points of their own, after their commit ([`CommitInfo::dirty`]).
    pub commits: Vec<CommitInfo>,
    /// Whether each commit changed method code ([`git::touches_methods`]) since the commit before it
    /// in `commits`; `None` where git cannot tell.
    pub method_change: Vec<Option<bool>>,
    pub series: Vec<String>,
    pub timelines: Vec<Timeline>,
    /// The cases whose verdict kind changed between consecutive commits.
    pub status_changes: Vec<StatusChange>,
}

/// A case whose verdict kind changed between two consecutive commits.
#[derive(Clone, Debug, PartialEq)]
pub struct StatusChange {
    pub series: String,
    pub scenario: String,
    pub method: String,
    pub from: usize,
    pub to: usize,
    pub before: String,
    pub after: String,
}

/// The kind of a status line (`ok`, `suspect`, `unfinished`, `failed`).
fn status_kind(status: &str) -> &str {
    status.split(':').next().unwrap_or(status).trim()
}

/// A point of the history: a commit, and the hash of the diff of a dirty tree (`None`: the
/// commit's own tree).
type PointKey = (String, Option<String>);

/// A case's measure in one series: (series, scenario, method, measure).
type CaseMeasure = (String, String, String, Measure);

/// A value as stored: (value, low, high, run id).
type StoredPoint = (f64, f64, f64, i64);

/// Build every timeline of `store`, ordering commits by `repo`'s history (by commit time where
/// git does not know them, then by record). Runs of one commit are one point, and runs of its tree
/// with an uncommitted change another for each change (its diff's hash), after the commit.
pub fn build(store: &HistoryStore, repo: &Path) -> Result<History, HistoryError> {
    let runs = store.runs()?;
    let shas = distinct(runs.iter().map(|r| r.commit.clone()));
    let infos = git::infos(repo, &shas);
    let keys = ordered_points(&runs, &infos, &git::topological_order(repo));
    let commits: Vec<CommitInfo> = keys.iter().map(|key| point_commit(key, &infos)).collect();
    let method_change = method_changes(repo, &commits);
    let statuses = store.statuses()?;
    let timelines: Vec<Timeline> = grouped_values(store, &runs, &keys)?
        .into_iter()
        .map(|(case, by_commit)| timeline(case, by_commit, &statuses, &commits))
        .collect();
    let mut series: Vec<String> = runs.iter().map(|r| r.series.clone()).collect();
    series.sort();
    series.dedup();
    let status_changes = status_changes(&timelines);
    Ok(History { commits, method_change, series, timelines, status_changes })
}

/// `items` without repeats, each where it first comes.
fn distinct<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut out = Vec::new();
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// The points of `runs` (in record order) in the repository's order: by `order` (git's
/// topological order), then by commit time (`infos`), a commit before its dirty trees, then by
/// first record.
fn ordered_points(
    runs: &[StoredRun],
    infos: &HashMap<String, CommitInfo>,
    order: &HashMap<String, usize>,
) -> Vec<PointKey> {
    let mut keys = distinct(runs.iter().map(|r| (r.commit.clone(), r.dirty.clone())));
    // Runs are in record order, so the first run of each key is its first record.
    let first_record: HashMap<PointKey, usize> =
        runs.iter().enumerate().rev().map(|(i, r)| ((r.commit.clone(), r.dirty.clone()), i)).collect();
    keys.sort_by_key(|k| {
        (
            order.get(&k.0).copied().unwrap_or(usize::MAX),
            infos.get(&k.0).map_or(i64::MAX, |i| i.time),
            k.1.is_some(),
            first_record[k],
        )
    });
    keys
}

/// The commit of the point `key` as git tells it (`infos`; a placeholder for a commit not in the
/// repository), with its dirty tree's diff hash.
fn point_commit((sha, dirty): &PointKey, infos: &HashMap<String, CommitInfo>) -> CommitInfo {
    let info = infos.get(sha).cloned().unwrap_or(CommitInfo {
        sha: sha.clone(),
        dirty: None,
        time: 0,
        date: String::new(),
        subject: "(not in this repository)".into(),
        parent: None,
    });
    CommitInfo { dirty: dirty.clone(), ..info }
}

/// Whether each of `commits` changed method code since the one before it (the first: since its
/// parent), as git in `repo` tells; `None` for an uncommitted change, whose files are not in git,
/// or where git cannot tell.
fn method_changes(repo: &Path, commits: &[CommitInfo]) -> Vec<Option<bool>> {
    commits
        .iter()
        .enumerate()
        .map(|(i, c)| {
            // Which files an uncommitted change touched is not in git.
            if c.dirty.is_some() {
                return None;
            }
            let before = if i == 0 { c.parent.clone()? } else { commits[i - 1].sha.clone() };
            git::changed_files(repo, &before, &c.sha).ok().map(|f| git::touches_methods(&f))
        })
        .collect()
}

/// The stored values of `store`, by case measure and then by point (its index in `keys`, the
/// points in order), each run's of `runs` under its own point.
fn grouped_values(
    store: &HistoryStore,
    runs: &[StoredRun],
    keys: &[PointKey],
) -> Result<BTreeMap<CaseMeasure, BTreeMap<usize, Vec<StoredPoint>>>, HistoryError> {
    let index: HashMap<&PointKey, usize> = keys.iter().enumerate().map(|(i, k)| (k, i)).collect();
    let run_of: HashMap<i64, (usize, &str)> = runs
        .iter()
        .map(|r| (r.id, (index[&(r.commit.clone(), r.dirty.clone())], r.series.as_str())))
        .collect();
    let mut grouped: BTreeMap<CaseMeasure, BTreeMap<usize, Vec<StoredPoint>>> = BTreeMap::new();
    for v in store.values()? {
        let (commit, series) = run_of[&v.run];
        grouped
            .entry((series.to_string(), v.scenario, v.method, v.measure))
            .or_default()
            .entry(commit)
            .or_default()
            .push((v.value, v.low, v.high, v.run));
    }
    Ok(grouped)
}

/// The timeline of `case` from its values at each point (`by_commit`): the points (`statuses`
/// gives each its case's status in its last run), their fitted levels, and the steps between
/// them, each attributed where the two `commits` on either side are parent and child.
fn timeline(
    case: CaseMeasure,
    by_commit: BTreeMap<usize, Vec<StoredPoint>>,
    statuses: &BTreeMap<(i64, String, String), String>,
    commits: &[CommitInfo],
) -> Timeline {
    let (series, scenario, method, measure) = case;
    let status_in =
        |run: i64| statuses.get(&(run, scenario.clone(), method.clone())).cloned().unwrap_or_default();
    let points: Vec<Point> =
        by_commit.into_iter().map(|(commit, values)| point(commit, values, measure, &status_in)).collect();
    let observations: Vec<Observation> =
        points.iter().map(|p| Observation { value: p.value, sigma: p.sigma }).collect();
    let fitted = fitted_levels(&observations);
    let steps = attributed_steps(&observations, &points, commits);
    Timeline { series, scenario, method, measure, points, fitted, steps }
}

/// The point at `commit` of `measure` from its stored `values` there (several runs: the median
/// value, the widest spread), weighed with the measure's noise; its status is its last run's, as
/// `status_in(run)` tells.
fn point(
    commit: usize,
    mut values: Vec<StoredPoint>,
    measure: Measure,
    status_in: &dyn Fn(i64) -> String,
) -> Point {
    values.sort_by(|a, b| a.0.total_cmp(&b.0));
    let value = values[values.len() / 2].0;
    let low = values.iter().map(|v| v.1).fold(f64::INFINITY, f64::min);
    let high = values.iter().map(|v| v.2).fold(f64::NEG_INFINITY, f64::max);
    let last_run = values.iter().map(|v| v.3).max().unwrap_or(0);
    Point { commit, value, low, high, sigma: measure.sigma(value, low, high), status: status_in(last_run) }
}

/// The fitted level of each of `observations` ([`steps::fit_levels`] with its default penalty).
fn fitted_levels(observations: &[Observation]) -> Vec<f64> {
    let levels = steps::fit_levels(observations, steps::default_penalty(observations.len()));
    let mut fitted = vec![0.0; observations.len()];
    for l in &levels {
        fitted[l.start..l.end].iter_mut().for_each(|f| *f = l.value);
    }
    fitted
}

/// The steps of `observations` (those of `points`), each between two of `commits`, attributed to
/// the later one when it follows the earlier ([`CommitInfo::follows`]).
fn attributed_steps(
    observations: &[Observation],
    points: &[Point],
    commits: &[CommitInfo],
) -> Vec<AttributedStep> {
    steps::detect_steps(observations)
        .into_iter()
        .map(|s| {
            let (from, to) = (points[s.at - 1].commit, points[s.at].commit);
            let adjacent = commits[to].follows(&commits[from]);
            AttributedStep {
                from,
                to,
                before: s.before,
                after: s.after,
                relative: s.relative_change(),
                made_by: adjacent.then_some(to),
            }
        })
        .collect()
}

/// Where a case's verdict kind changed between consecutive points (read off its iterations
/// timeline, which every finished or unfinished case has).
fn status_changes(timelines: &[Timeline]) -> Vec<StatusChange> {
    let mut out = Vec::new();
    for t in timelines.iter().filter(|t| t.measure == Measure::Iterations) {
        for w in t.points.windows(2) {
            if status_kind(&w[0].status) != status_kind(&w[1].status) {
                out.push(StatusChange {
                    series: t.series.clone(),
                    scenario: t.scenario.clone(),
                    method: t.method.clone(),
                    from: w[0].commit,
                    to: w[1].commit,
                    before: w[0].status.clone(),
                    after: w[1].status.clone(),
                });
            }
        }
    }
    out
}

impl History {
    /// The timelines of one case of one series, in [`Measure::all`] order.
    pub fn case(&self, key: &TimelineKey) -> Vec<&Timeline> {
        let mut found: Vec<&Timeline> = self.timelines.iter().filter(|t| t.key() == *key).collect();
        let all = Measure::all();
        found.sort_by_key(|t| all.iter().position(|m| *m == t.measure));
        found
    }

    /// The cases of every series, in order.
    pub fn cases(&self) -> Vec<TimelineKey> {
        let mut cases: Vec<TimelineKey> = self.timelines.iter().map(Timeline::key).collect();
        cases.dedup();
        cases
    }
}
