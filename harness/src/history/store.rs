//! The history store: one SQLite file (rusqlite, SQLite bundled) holding every recorded run with
//! its provenance, and per case its status and measures.
//!
//! - Recording is idempotent: a run is known by the SHA-256 of its results.json; the same run
//!   recorded again adds nothing.
//! - A series is one data source on one machine class ([`SeriesKey`]); a run of another series, or
//!   one whose data files differ from the store's under the same name, is refused unless asked
//!   ([`Mixing::Allow`]), and then kept on timelines of its own.
//! - Every write is one transaction: a run killed while recording leaves the store as it was.
//! - A file that is not a history store (another database, a truncated or corrupted file) is an
//!   error naming it, and is never written to.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rusqlite::{params, Connection, OpenFlags, OptionalExtension};

use super::measures::Measure;
use super::run_record::{RunRecord, SeriesKey};
use super::HistoryError;

/// SQLite's `application_id` of a history store: "DBHS".
const APPLICATION_ID: i64 = 0x4442_4853;
/// The schema's version (`user_version`).
const SCHEMA_VERSION: i64 = 1;

const SCHEMA: &str = "
CREATE TABLE runs (
    id INTEGER PRIMARY KEY,
    digest TEXT NOT NULL UNIQUE,
    git_commit TEXT NOT NULL,
    dirty INTEGER NOT NULL,
    started_utc TEXT NOT NULL,
    recorded_utc TEXT NOT NULL,
    data_source TEXT NOT NULL,
    machine_class TEXT NOT NULL,
    series TEXT NOT NULL,
    repetitions INTEGER NOT NULL,
    data_files TEXT NOT NULL,
    provenance TEXT NOT NULL,
    source TEXT NOT NULL,
    request TEXT
);
CREATE TABLE cases (
    run INTEGER NOT NULL REFERENCES runs(id),
    scenario TEXT NOT NULL,
    method TEXT NOT NULL,
    status TEXT NOT NULL,
    PRIMARY KEY (run, scenario, method)
);
CREATE TABLE measurements (
    run INTEGER NOT NULL REFERENCES runs(id),
    scenario TEXT NOT NULL,
    method TEXT NOT NULL,
    measure TEXT NOT NULL,
    value REAL NOT NULL,
    low REAL NOT NULL,
    high REAL NOT NULL,
    PRIMARY KEY (run, scenario, method, measure)
);
CREATE TABLE failures (
    git_commit TEXT NOT NULL,
    request TEXT NOT NULL,
    stage TEXT NOT NULL,
    message TEXT NOT NULL,
    recorded_utc TEXT NOT NULL,
    PRIMARY KEY (git_commit, request)
);
";

/// Whether a run of another series may join the store.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mixing {
    Refuse,
    /// Keep it, on timelines of its own.
    Allow,
}

/// What recording did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Recorded {
    Added {
        run: i64,
        cases: usize,
        measurements: usize,
    },
    /// This run (same results.json bytes) was already in the store.
    AlreadyThere {
        run: i64,
    },
}

/// A stored run, without its cases.
#[derive(Clone, Debug, PartialEq)]
pub struct StoredRun {
    pub id: i64,
    pub commit: String,
    /// `None` for a run of the commit's own tree; for a dirty tree the SHA-256 of its change
    /// ([`RunRecord::diff`], kept in the provenance), or `""` when the run did not record one.
    pub dirty: Option<String>,
    pub started_utc: String,
    pub series: String,
    pub repetitions: usize,
    pub source: String,
}

/// A stored measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct StoredValue {
    pub run: i64,
    pub scenario: String,
    pub method: String,
    pub measure: Measure,
    pub value: f64,
    pub low: f64,
    pub high: f64,
}

/// A commit whose build or run failed, kept so that a resumed `history run` does not retry it.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub commit: String,
    /// The `history run` request it failed in ([`super::collect::CollectOptions::request`]).
    pub request: String,
    pub stage: String,
    pub message: String,
}

pub struct HistoryStore {
    conn: Connection,
    path: PathBuf,
    /// What [`HistoryStore::open_or_create`] made (the file, or the first directory it made).
    made: Option<PathBuf>,
}

impl HistoryStore {
    /// Open the store at `path`, creating it (and its directory) if there is none. A path that
    /// cannot be a store (a directory, a directory that cannot be made, a file that cannot be
    /// created or written) is an error naming it and the reason, and leaves nothing behind.
    pub fn open_or_create(path: &Path) -> Result<HistoryStore, HistoryError> {
        let unusable = |reason: String| HistoryError::Unusable { path: path.to_path_buf(), reason };
        if path.is_dir() {
            return Err(unusable(
                "it is a directory (give the store's file, e.g. DIR/history.sqlite)".into(),
            ));
        }
        // What this call made, removed again if the store cannot be opened after all.
        let mut made: Option<PathBuf> = None;
        if !path.exists() {
            let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            if !dir.exists() {
                made = dir
                    .ancestors()
                    .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
                    .last()
                    .map(Path::to_path_buf);
                std::fs::create_dir_all(dir).map_err(|e| {
                    unusable(format!("cannot create directory {}: {}", dir.display(), io_reason(&e)))
                })?;
            } else if !dir.is_dir() {
                return Err(unusable(format!("{} is not a directory", dir.display())));
            }
            // Made here rather than by SQLite, whose error ("unable to open database file") does not
            // say why.
            std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(path)
                .map_err(|e| unusable(format!("cannot create it in {}: {}", dir.display(), io_reason(&e))))?;
            made.get_or_insert_with(|| path.to_path_buf());
        } else if let Err(e) = std::fs::OpenOptions::new().read(true).write(true).open(path) {
            return Err(unusable(format!("cannot open it for writing: {}", io_reason(&e))));
        }
        match Self::open_with(path, true) {
            Ok(store) => Ok(HistoryStore { made, ..store }),
            Err(e) => {
                if let Some(made) = made {
                    let _ = if made.is_dir() {
                        std::fs::remove_dir_all(&made)
                    } else {
                        std::fs::remove_file(&made)
                    };
                }
                Err(e)
            }
        }
    }

    /// Open the store at `path`; an error if there is none.
    pub fn open_existing(path: &Path) -> Result<HistoryStore, HistoryError> {
        if path.is_dir() {
            return Err(HistoryError::Unusable {
                path: path.to_path_buf(),
                reason: "it is a directory (give the store's file, e.g. DIR/history.sqlite)".into(),
            });
        }
        if !path.is_file() {
            return Err(HistoryError::NoStore { path: path.to_path_buf() });
        }
        Self::open_with(path, false)
    }

    fn open_with(path: &Path, create: bool) -> Result<HistoryStore, HistoryError> {
        let sql = |e: rusqlite::Error| HistoryError::Sqlite { path: path.to_path_buf(), error: e };
        let corrupt = |detail: String| HistoryError::Corrupt { path: path.to_path_buf(), detail };
        let mut flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        if create {
            flags |= OpenFlags::SQLITE_OPEN_CREATE;
        }
        let conn = Connection::open_with_flags(path, flags).map_err(sql)?;
        // Reading the header is where a file that is not a database shows itself.
        let application_id: i64 = conn
            .pragma_query_value(None, "application_id", |r| r.get(0))
            .map_err(|e| corrupt(e.to_string()))?;
        let tables: i64 = conn
            .query_row("SELECT count(*) FROM sqlite_master", [], |r| r.get(0))
            .map_err(|e| corrupt(e.to_string()))?;
        if application_id == 0 && tables == 0 {
            conn.execute_batch(&format!(
                "BEGIN; {SCHEMA} PRAGMA application_id = {APPLICATION_ID}; PRAGMA user_version = {SCHEMA_VERSION}; COMMIT;"
            ))
            .map_err(sql)?;
        } else if application_id != APPLICATION_ID {
            return Err(corrupt(format!(
                "a SQLite database of another program (application_id {application_id:#x}, {tables} schema entries)"
            )));
        }
        let version: i64 = conn.pragma_query_value(None, "user_version", |r| r.get(0)).map_err(sql)?;
        if version != SCHEMA_VERSION {
            return Err(corrupt(format!("schema version {version}; this harness reads {SCHEMA_VERSION}")));
        }
        let check: String =
            conn.query_row("PRAGMA quick_check", [], |r| r.get(0)).map_err(|e| corrupt(e.to_string()))?;
        if check != "ok" {
            return Err(corrupt(format!("SQLite's quick_check: {check}")));
        }
        conn.execute_batch("PRAGMA foreign_keys = ON;").map_err(sql)?;
        Ok(HistoryStore { conn, path: path.to_path_buf(), made: None })
    }

    fn sql(&self) -> impl Fn(rusqlite::Error) -> HistoryError + '_ {
        move |error| HistoryError::Sqlite { path: self.path.clone(), error }
    }

    /// Store `run` (read from `source`), unless it is there already.
    pub fn record(
        &mut self,
        run: &RunRecord,
        source: &str,
        mixing: Mixing,
    ) -> Result<Recorded, HistoryError> {
        self.record_request(run, source, mixing, None)
    }

    /// [`HistoryStore::record`] for a run that `history run` made for `request`.
    pub fn record_request(
        &mut self,
        run: &RunRecord,
        source: &str,
        mixing: Mixing,
        request: Option<&str>,
    ) -> Result<Recorded, HistoryError> {
        let path = self.path.clone();
        let sql = |error| HistoryError::Sqlite { path: path.clone(), error };
        let tx = self.conn.transaction().map_err(sql)?;
        let recorded = insert_run(&tx, &path, run, source, mixing, request)?;
        tx.commit().map_err(sql)?;
        Ok(recorded)
    }

    /// Store every one of `runs` (each with the file it was read from), or none of them: one
    /// transaction, in which each run is judged against the store and the runs before it (two runs
    /// of one call that would mix series are refused as one run would be). The first refusal is the
    /// error; it names the run's file.
    pub fn record_all(
        &mut self,
        runs: &[(&RunRecord, String)],
        mixing: Mixing,
    ) -> Result<Vec<Recorded>, HistoryError> {
        let path = self.path.clone();
        let sql = |error| HistoryError::Sqlite { path: path.clone(), error };
        let tx = self.conn.transaction().map_err(sql)?;
        let recorded = runs
            .iter()
            .map(|(run, source)| insert_run(&tx, &path, run, source, mixing, None))
            .collect::<Result<Vec<_>, _>>()?;
        tx.commit().map_err(sql)?;
        Ok(recorded)
    }

    /// Close the store, removing it (and the directories made for it) when this call to
    /// [`HistoryStore::open_or_create`] made it: for a command that ends in an error and must leave
    /// nothing behind.
    pub fn abandon(self) {
        let HistoryStore { conn, made, .. } = self;
        drop(conn);
        if let Some(made) = made {
            let _ = if made.is_dir() { std::fs::remove_dir_all(&made) } else { std::fs::remove_file(&made) };
        }
    }

    /// Every stored run, oldest record first.
    pub fn runs(&self) -> Result<Vec<StoredRun>, HistoryError> {
        let mut stmt = self
            .conn
            .prepare(
                "SELECT id, git_commit, started_utc, series, repetitions, source, dirty, provenance FROM runs ORDER BY id",
            )
            .map_err(self.sql())?;
        let rows = stmt
            .query_map([], |r| {
                let dirty = r.get::<_, bool>(6)?.then(|| {
                    let provenance: String = r.get(7).unwrap_or_default();
                    serde_json::from_str::<serde_json::Value>(&provenance)
                        .ok()
                        .and_then(|p| p["build"]["git_diff_sha256"].as_str().map(str::to_string))
                        .unwrap_or_default()
                });
                Ok(StoredRun {
                    id: r.get(0)?,
                    commit: r.get(1)?,
                    dirty,
                    started_utc: r.get(2)?,
                    series: r.get(3)?,
                    repetitions: r.get::<_, i64>(4)? as usize,
                    source: r.get(5)?,
                })
            })
            .map_err(self.sql())?
            .collect::<Result<Vec<_>, _>>()
            .map_err(self.sql())?;
        Ok(rows)
    }

    /// Every stored measurement (a measure this harness does not know is left out).
    pub fn values(&self) -> Result<Vec<StoredValue>, HistoryError> {
        let mut stmt = self
            .conn
            .prepare("SELECT run, scenario, method, measure, value, low, high FROM measurements ORDER BY run, scenario, method")
            .map_err(self.sql())?;
        let rows = stmt
            .query_map([], |r| {
                Ok((
                    r.get::<_, i64>(0)?,
                    r.get::<_, String>(1)?,
                    r.get::<_, String>(2)?,
                    r.get::<_, String>(3)?,
                    r.get(4)?,
                    r.get(5)?,
                    r.get(6)?,
                ))
            })
            .map_err(self.sql())?
            .collect::<Result<Vec<(i64, String, String, String, f64, f64, f64)>, _>>()
            .map_err(self.sql())?;
        Ok(rows
            .into_iter()
            .filter_map(|(run, scenario, method, key, value, low, high)| {
                Some(StoredValue {
                    run,
                    scenario,
                    method,
                    measure: Measure::from_key(&key)?,
                    value,
                    low,
                    high,
                })
            })
            .collect())
    }

    /// Each stored case's status: (run, scenario, method) -> status.
    pub fn statuses(&self) -> Result<BTreeMap<(i64, String, String), String>, HistoryError> {
        let mut stmt =
            self.conn.prepare("SELECT run, scenario, method, status FROM cases").map_err(self.sql())?;
        let rows = stmt
            .query_map([], |r| Ok(((r.get(0)?, r.get(1)?, r.get(2)?), r.get(3)?)))
            .map_err(self.sql())?
            .collect::<Result<BTreeMap<_, _>, _>>()
            .map_err(self.sql())?;
        Ok(rows)
    }

    /// Whether `history run` has recorded `commit` for `request` (resuming).
    pub fn has_request(&self, commit: &str, request: &str) -> Result<bool, HistoryError> {
        let n: i64 = self
            .conn
            .query_row(
                "SELECT count(*) FROM runs WHERE git_commit = ?1 AND request = ?2",
                params![commit, request],
                |r| r.get(0),
            )
            .map_err(self.sql())?;
        Ok(n > 0)
    }

    /// Remove every run of `commit` (a full hash) with its cases and values, and its failures: for a
    /// run spoiled by something outside it (a loaded machine), before running the commit again.
    /// Returns the runs removed.
    pub fn forget(&mut self, commit: &str) -> Result<usize, HistoryError> {
        Ok(self.forget_all(&[commit.to_string()])?[0])
    }

    /// [`HistoryStore::forget`] of each of `commits`, in one transaction; the runs removed of each.
    pub fn forget_all(&mut self, commits: &[String]) -> Result<Vec<usize>, HistoryError> {
        let path = self.path.clone();
        let sql = move |error| HistoryError::Sqlite { path: path.clone(), error };
        let tx = self.conn.transaction().map_err(&sql)?;
        let mut removed = Vec::new();
        for commit in commits {
            let runs = "SELECT id FROM runs WHERE git_commit = ?1";
            tx.execute(&format!("DELETE FROM measurements WHERE run IN ({runs})"), [commit]).map_err(&sql)?;
            tx.execute(&format!("DELETE FROM cases WHERE run IN ({runs})"), [commit]).map_err(&sql)?;
            removed.push(tx.execute("DELETE FROM runs WHERE git_commit = ?1", [commit]).map_err(&sql)?);
            tx.execute("DELETE FROM failures WHERE git_commit = ?1", [commit]).map_err(&sql)?;
        }
        tx.commit().map_err(&sql)?;
        Ok(removed)
    }

    /// Every commit the store holds runs or failures of: full hash -> (runs, failures).
    pub fn stored_commits(&self) -> Result<BTreeMap<String, (usize, usize)>, HistoryError> {
        let mut out: BTreeMap<String, (usize, usize)> = BTreeMap::new();
        for (table, failures) in [("runs", false), ("failures", true)] {
            let mut stmt = self
                .conn
                .prepare(&format!("SELECT git_commit, count(*) FROM {table} GROUP BY git_commit"))
                .map_err(self.sql())?;
            let rows = stmt
                .query_map([], |r| Ok((r.get::<_, String>(0)?, r.get::<_, i64>(1)? as usize)))
                .map_err(self.sql())?
                .collect::<Result<Vec<_>, _>>()
                .map_err(self.sql())?;
            for (commit, n) in rows {
                let entry = out.entry(commit).or_default();
                if failures {
                    entry.1 = n;
                } else {
                    entry.0 = n;
                }
            }
        }
        Ok(out)
    }

    /// Keep that `commit` failed at `stage` for its request (replacing an earlier failure).
    pub fn record_failure(&self, failure: &Failure) -> Result<(), HistoryError> {
        self.conn
            .execute(
                "INSERT OR REPLACE INTO failures (git_commit, request, stage, message, recorded_utc) VALUES (?1, ?2, ?3, ?4, ?5)",
                params![
                    failure.commit,
                    failure.request,
                    failure.stage,
                    failure.message,
                    crate::provenance::utc_timestamp(std::time::SystemTime::now())
                ],
            )
            .map_err(self.sql())?;
        Ok(())
    }

    /// Forget a failure (a retried commit).
    pub fn clear_failure(&self, commit: &str, request: &str) -> Result<(), HistoryError> {
        self.conn
            .execute("DELETE FROM failures WHERE git_commit = ?1 AND request = ?2", params![commit, request])
            .map_err(self.sql())?;
        Ok(())
    }

    pub fn failures(&self) -> Result<Vec<Failure>, HistoryError> {
        let mut stmt = self
            .conn
            .prepare("SELECT git_commit, request, stage, message FROM failures ORDER BY recorded_utc")
            .map_err(self.sql())?;
        let rows = stmt
            .query_map([], |r| {
                Ok(Failure { commit: r.get(0)?, request: r.get(1)?, stage: r.get(2)?, message: r.get(3)? })
            })
            .map_err(self.sql())?
            .collect::<Result<Vec<_>, _>>()
            .map_err(self.sql())?;
        Ok(rows)
    }
}

/// Insert `run` (read from `source`) through `conn` (a transaction), unless it is there already.
fn insert_run(
    conn: &Connection,
    path: &Path,
    run: &RunRecord,
    source: &str,
    mixing: Mixing,
    request: Option<&str>,
) -> Result<Recorded, HistoryError> {
    let sql = |error| HistoryError::Sqlite { path: path.to_path_buf(), error };
    if let Some(id) = conn
        .query_row("SELECT id FROM runs WHERE digest = ?1", [&run.digest], |r| r.get::<_, i64>(0))
        .optional()
        .map_err(sql)?
    {
        return Ok(Recorded::AlreadyThere { run: id });
    }
    let series = series_for(conn, path, run, source, mixing)?;
    conn.execute(
        "INSERT INTO runs (digest, git_commit, dirty, started_utc, recorded_utc, data_source, machine_class, series,
                           repetitions, data_files, provenance, source, request)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)",
        params![
            run.digest,
            run.commit,
            run.dirty,
            run.started_utc,
            crate::provenance::utc_timestamp(std::time::SystemTime::now()),
            run.series.data_source,
            run.series.machine_class,
            series,
            run.repetitions as i64,
            serde_json::to_string(&run.data_files).unwrap_or_default(),
            run.provenance,
            source,
            request,
        ],
    )
    .map_err(sql)?;
    let id = conn.last_insert_rowid();
    let mut measurements = 0;
    let mut case = conn
        .prepare("INSERT INTO cases (run, scenario, method, status) VALUES (?1, ?2, ?3, ?4)")
        .map_err(sql)?;
    let mut value = conn
        .prepare(
            "INSERT INTO measurements (run, scenario, method, measure, value, low, high)
             VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
        )
        .map_err(sql)?;
    for c in &run.cases {
        case.execute(params![id, c.scenario, c.method, c.status]).map_err(|e| HistoryError::Results {
            path: PathBuf::from(source),
            message: format!("case {} / {}: {e} (named twice?)", c.scenario, c.method),
        })?;
        for v in &c.values {
            value
                .execute(params![id, c.scenario, c.method, v.measure.key(), v.value, v.low, v.high])
                .map_err(sql)?;
            measurements += 1;
        }
    }
    Ok(Recorded::Added { run: id, cases: run.cases.len(), measurements })
}

/// The series `run` (read from `source`) joins: its own label, unless the store holds runs of
/// another series or other data files of the same name, which only [`Mixing::Allow`] lets in (then
/// on timelines of their own, the label saying why). A refusal names `source`.
fn series_for(
    conn: &Connection,
    path: &Path,
    run: &RunRecord,
    source: &str,
    mixing: Mixing,
) -> Result<String, HistoryError> {
    let sql = |error| HistoryError::Sqlite { path: path.to_path_buf(), error };
    let mut label = run.series.label();
    let mut stmt =
        conn.prepare("SELECT DISTINCT data_source, machine_class, data_files FROM runs").map_err(sql)?;
    let stored: Vec<(String, String, String)> = stmt
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))
        .map_err(sql)?
        .collect::<Result<_, _>>()
        .map_err(sql)?;
    let mut conflicts = Vec::new();
    for (data_source, machine_class, files) in &stored {
        let key = SeriesKey { data_source: data_source.clone(), machine_class: machine_class.clone() };
        if key != run.series {
            conflicts.push(format!("the store holds {}; this run is {}", key.label(), run.series.label()));
            continue;
        }
        let files: BTreeMap<String, String> =
            serde_json::from_str::<Vec<(String, String)>>(files).unwrap_or_default().into_iter().collect();
        for (name, sha) in &run.data_files {
            if files.get(name).is_some_and(|s| s != sha) {
                conflicts.push(format!(
                    "data file {name} differs from the store's ({} against {})",
                    &sha[..sha.len().min(12)],
                    &files[name][..files[name].len().min(12)]
                ));
                label = format!("{label}, other {name}");
            }
        }
    }
    conflicts.sort();
    conflicts.dedup();
    match (conflicts.is_empty(), mixing) {
        (true, _) | (false, Mixing::Allow) => Ok(label),
        (false, Mixing::Refuse) => Err(HistoryError::Mixed { path: PathBuf::from(source), conflicts }),
    }
}

/// An I/O error's reason in the words of a sentence (`permission denied (os error 13)`).
fn io_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    let mut chars = text.chars();
    match chars.next() {
        Some(first) => first.to_lowercase().chain(chars).collect(),
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::run_record::parse_run;

    fn run(commit: &str, cpu: &str, e_theta: f64) -> RunRecord {
        let json = format!(
            r#"{{"data_source":"survey","provenance":{{"machine":{{"cpu_model":"{cpu}","logical_cores":2,"memory_gib":23.4}},
            "build":{{"git_commit":"{commit}","git_dirty":false}},"run":{{"started_utc":"2026-12-06T00:00:00Z","threads":2,"jobs":1,"repetitions":1}},
            "inputs":[{{"path":"/d/bar.off","sha256":"22"}}]}},
            "cases":[{{"scenario":"bar","method":"arap","status":"ok","bind_s":1.0,"solve_s":3.0,"iterations":40,"e_theta_deg":{e_theta}}}]}}"#
        );
        parse_run(json.as_bytes()).unwrap()
    }

    fn count(store: &HistoryStore) -> (usize, usize) {
        (store.runs().unwrap().len(), store.values().unwrap().len())
    }

    #[test]
    fn recording_the_same_run_twice_adds_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.sqlite");
        let mut store = HistoryStore::open_or_create(&path).unwrap();
        let first = store.record(&run("aaa", "CPU", 1.5), "a", Mixing::Refuse).unwrap();
        assert!(matches!(first, Recorded::Added { cases: 1, measurements: 3, .. }), "{first:?}");
        let before = count(&store);
        drop(store);
        let mut store = HistoryStore::open_existing(&path).unwrap();
        assert!(matches!(
            store.record(&run("aaa", "CPU", 1.5), "a", Mixing::Refuse).unwrap(),
            Recorded::AlreadyThere { .. }
        ));
        assert_eq!(count(&store), before);
        store.record(&run("bbb", "CPU", 1.6), "b", Mixing::Refuse).unwrap();
        assert_eq!(count(&store).0, 2);
        assert_eq!(store.forget("aaa").unwrap(), 1);
        assert_eq!(count(&store), (1, 3), "the forgotten run's values stayed");
        assert!(matches!(
            store.record(&run("aaa", "CPU", 1.5), "a", Mixing::Refuse).unwrap(),
            Recorded::Added { .. }
        ));
    }

    #[test]
    fn another_machine_class_or_other_data_is_refused_unless_asked() {
        let dir = tempfile::tempdir().unwrap();
        let mut store = HistoryStore::open_or_create(&dir.path().join("h.sqlite")).unwrap();
        store.record(&run("aaa", "CPU", 1.5), "a", Mixing::Refuse).unwrap();
        let other = run("bbb", "Other CPU", 1.5);
        let e = store.record(&other, "b", Mixing::Refuse).unwrap_err().to_string();
        assert!(e.contains("Other CPU") && e.contains("--allow-mixed"), "{e}");
        let mut other_data = run("ccc", "CPU", 1.5);
        other_data.data_files[0].1 = "33".into();
        let e = store.record(&other_data, "c", Mixing::Refuse).unwrap_err().to_string();
        assert!(e.contains("bar.off"), "{e}");
        assert_eq!(count(&store).0, 1, "nothing of a refused run is stored");
        store.record(&other, "b", Mixing::Allow).unwrap();
        let series: Vec<String> = store.runs().unwrap().into_iter().map(|r| r.series).collect();
        assert_ne!(series[0], series[1], "a mixed-in run is a series of its own");
    }

    #[test]
    fn a_corrupted_or_foreign_file_is_an_error_and_left_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.sqlite");
        let mut store = HistoryStore::open_or_create(&path).unwrap();
        store.record(&run("aaa", "CPU", 1.5), "a", Mixing::Refuse).unwrap();
        drop(store);
        // A partial copy: the header survives, the pages after it do not.
        let bytes = std::fs::read(&path).unwrap();
        let truncated = dir.path().join("truncated.sqlite");
        std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
        let garbage = dir.path().join("garbage.sqlite");
        std::fs::write(&garbage, b"this is not a database, it is a text file that happens to be long enough")
            .unwrap();
        let foreign = dir.path().join("foreign.sqlite");
        Connection::open(&foreign)
            .unwrap()
            .execute_batch("CREATE TABLE t (x INTEGER); INSERT INTO t VALUES (1);")
            .unwrap();
        for bad in [&truncated, &garbage, &foreign] {
            let before = std::fs::read(bad).unwrap();
            let e =
                HistoryStore::open_or_create(bad).err().unwrap_or_else(|| panic!("{} opened", bad.display()));
            let message = e.to_string();
            assert!(matches!(e, HistoryError::Corrupt { .. }), "{}: {message}", bad.display());
            assert!(
                message.contains(&bad.display().to_string()) && message.contains("left as it is"),
                "{message}"
            );
            assert_eq!(std::fs::read(bad).unwrap(), before, "{} was written to", bad.display());
        }
        let missing = dir.path().join("missing.sqlite");
        assert!(matches!(HistoryStore::open_existing(&missing), Err(HistoryError::NoStore { .. })));
        assert!(!missing.exists());
    }
}
