//! Timelines from the store: per series, scenario, method and measure, one point per commit in the
//! repository's order (several runs of a commit: the median value, the widest spread), the fitted
//! levels and the steps between them, each named with the commit that made it when the commits on
//! either side are parent and child, else with the range to bisect (`history find`).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::git::{self, CommitInfo};
use super::measures::Measure;
use super::steps::{self, Observation};
use super::store::HistoryStore;
use super::HistoryError;

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

/// Build every timeline of `store`, ordering commits by `repo`'s history (by commit time where
/// git does not know them, then by record). Runs of one commit are one point, and runs of its tree
/// with an uncommitted change another for each change (its diff's hash), after the commit.
pub fn build(store: &HistoryStore, repo: &Path) -> Result<History, HistoryError> {
    let runs = store.runs()?;
    // A point: (commit, diff of a dirty tree).
    type PointKey = (String, Option<String>);
    let mut shas: Vec<String> = Vec::new();
    let mut keys: Vec<PointKey> = Vec::new();
    for r in &runs {
        if !shas.contains(&r.commit) {
            shas.push(r.commit.clone());
        }
        let key = (r.commit.clone(), r.dirty.clone());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let infos = git::infos(repo, &shas);
    let order = git::topological_order(repo);
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
    let commits: Vec<CommitInfo> = keys
        .iter()
        .map(|(s, dirty)| {
            let info = infos.get(s).cloned().unwrap_or(CommitInfo {
                sha: s.clone(),
                dirty: None,
                time: 0,
                date: String::new(),
                subject: "(not in this repository)".into(),
                parent: None,
            });
            CommitInfo { dirty: dirty.clone(), ..info }
        })
        .collect();
    let index: HashMap<&PointKey, usize> = keys.iter().enumerate().map(|(i, k)| (k, i)).collect();
    let method_change: Vec<Option<bool>> = commits
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
        .collect();

    let run_of: HashMap<i64, (usize, &str)> = runs
        .iter()
        .map(|r| (r.id, (index[&(r.commit.clone(), r.dirty.clone())], r.series.as_str())))
        .collect();
    let statuses = store.statuses()?;
    // (series, scenario, method, measure) -> commit -> values (value, low, high, run id)
    type Key = (String, String, String, Measure);
    let mut grouped: BTreeMap<Key, BTreeMap<usize, Vec<(f64, f64, f64, i64)>>> = BTreeMap::new();
    for v in store.values()? {
        let (commit, series) = run_of[&v.run];
        grouped
            .entry((series.to_string(), v.scenario, v.method, v.measure))
            .or_default()
            .entry(commit)
            .or_default()
            .push((v.value, v.low, v.high, v.run));
    }
    let mut timelines = Vec::new();
    for ((series, scenario, method, measure), by_commit) in grouped {
        let points: Vec<Point> = by_commit
            .into_iter()
            .map(|(commit, mut values)| {
                values.sort_by(|a, b| a.0.total_cmp(&b.0));
                let value = values[values.len() / 2].0;
                let low = values.iter().map(|v| v.1).fold(f64::INFINITY, f64::min);
                let high = values.iter().map(|v| v.2).fold(f64::NEG_INFINITY, f64::max);
                let last_run = values.iter().map(|v| v.3).max().unwrap_or(0);
                let status =
                    statuses.get(&(last_run, scenario.clone(), method.clone())).cloned().unwrap_or_default();
                Point { commit, value, low, high, sigma: measure.sigma(value, low, high), status }
            })
            .collect();
        let observations: Vec<Observation> =
            points.iter().map(|p| Observation { value: p.value, sigma: p.sigma }).collect();
        let levels = steps::fit_levels(&observations, steps::default_penalty(points.len()));
        let mut fitted = vec![0.0; points.len()];
        for l in &levels {
            fitted[l.start..l.end].iter_mut().for_each(|f| *f = l.value);
        }
        let steps = steps::detect_steps(&observations)
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
            .collect();
        timelines.push(Timeline { series, scenario, method, measure, points, fitted, steps });
    }
    let mut series: Vec<String> = runs.iter().map(|r| r.series.clone()).collect();
    series.sort();
    series.dedup();
    let status_changes = status_changes(&timelines);
    Ok(History { commits, method_change, series, timelines, status_changes })
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
    pub fn case(&self, series: &str, scenario: &str, method: &str) -> Vec<&Timeline> {
        let mut found: Vec<&Timeline> = self
            .timelines
            .iter()
            .filter(|t| t.series == series && t.scenario == scenario && t.method == method)
            .collect();
        let all = Measure::all();
        found.sort_by_key(|t| all.iter().position(|m| *m == t.measure));
        found
    }

    /// The (series, scenario, method) cases, in order.
    pub fn cases(&self) -> Vec<(String, String, String)> {
        let mut cases: Vec<(String, String, String)> =
            self.timelines.iter().map(|t| (t.series.clone(), t.scenario.clone(), t.method.clone())).collect();
        cases.dedup();
        cases
    }
}
