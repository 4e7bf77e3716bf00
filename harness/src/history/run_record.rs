//! A run's `results.json` as the rows the history keeps: its provenance (commit, machine, data) and
//! per case its status and [`Measure`]s. Read leniently, field by field, so that the results of
//! every earlier commit of the harness read too (fields were added over time; none was renamed).

use std::path::Path;

use serde_json::Value;
use sha2::{Digest, Sha256};

use super::measures::Measure;
use super::HistoryError;

/// One run, ready to store.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// SHA-256 of the results.json bytes: the run's identity (recording it again adds nothing).
    pub digest: String,
    /// `git rev-parse HEAD` of the harness that ran.
    pub commit: String,
    /// Whether its tree differed from the commit.
    pub dirty: bool,
    /// When dirty, the SHA-256 of the uncommitted change (`provenance.build.git_diff_sha256`, from
    /// issue 60 on; `None` before): runs of one commit with other changes are other points.
    pub diff: Option<String>,
    pub started_utc: String,
    /// What a series must share to be one timeline: data source and machine class.
    pub series: SeriesKey,
    /// The run's data files (meshes, selections, edits; not the configs, which are the commit's
    /// code): file name and SHA-256, sorted by name.
    pub data_files: Vec<(String, String)>,
    pub repetitions: usize,
    /// The whole provenance, as JSON.
    pub provenance: String,
    pub cases: Vec<CaseRow>,
}

/// What runs must share for their values to be one timeline.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SeriesKey {
    /// [`data_source_kind`] of results.json's `data_source`.
    pub data_source: String,
    /// CPU model, logical cores, memory, threads and jobs: timings of two classes do not compare.
    pub machine_class: String,
}

impl SeriesKey {
    /// One line for people.
    pub fn label(&self) -> String {
        format!("{} data on {}", self.data_source, self.machine_class)
    }
}

/// One (scenario, method) of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseRow {
    pub scenario: String,
    pub method: String,
    /// `ok`, `suspect: ...`, `unfinished: ...`, `failed: ...`.
    pub status: String,
    pub values: Vec<MeasureValue>,
}

/// A measure's value with its spread over the `--repeat` rounds (`low == high == value` without).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasureValue {
    pub measure: Measure,
    pub value: f64,
    pub low: f64,
    pub high: f64,
}

/// Extensions of files that are the commit's code, not data: left out of the data files.
const CONFIG_EXTENSIONS: [&str; 3] = ["toml", "json", "csv"];

/// Read `path` (a report directory or its results.json).
pub fn read_run(path: &Path) -> Result<RunRecord, HistoryError> {
    let file = if path.is_dir() { path.join("results.json") } else { path.to_path_buf() };
    let bytes = std::fs::read(&file).map_err(|error| HistoryError::Io { path: file.clone(), error })?;
    parse_run(&bytes).map_err(|message| HistoryError::Results { path: file, message })
}

/// The record of results.json `bytes`; the error says what is missing.
pub fn parse_run(bytes: &[u8]) -> Result<RunRecord, String> {
    let root: Value = serde_json::from_slice(bytes).map_err(|e| format!("not JSON: {e}"))?;
    if let Some(shard) = root.get("shard").and_then(Value::as_str) {
        return Err(format!("a partial report (part {shard}): record the merged report"));
    }
    let data_source =
        text(&root, "data_source").ok_or("no data_source: not a results.json of deformbench")?;
    let provenance =
        root.get("provenance").ok_or("no provenance (written by harness versions from issue 22 on)")?;
    let build = provenance.get("build").ok_or("provenance without build")?;
    let commit = text(build, "git_commit")
        .ok_or("provenance.build.git_commit is missing: not run from a git checkout")?;
    let dirty = build.get("git_dirty").and_then(Value::as_bool).unwrap_or(false);
    let diff = text(build, "git_diff_sha256").filter(|_| dirty);
    let machine = provenance.get("machine").ok_or("provenance without machine")?;
    let run = provenance.get("run").ok_or("provenance without run")?;
    let count = |v: &Value, key: &str| v.get(key).and_then(Value::as_u64).unwrap_or(0) as usize;
    let machine_class = format!(
        "{}, {} logical cores, {:.0} GiB; {} thread(s), {} job(s)",
        text(machine, "cpu_model").unwrap_or_else(|| "unknown CPU".into()),
        count(machine, "logical_cores"),
        machine.get("memory_gib").and_then(Value::as_f64).unwrap_or(0.0),
        count(run, "threads"),
        count(run, "jobs"),
    );
    let cases = root.get("cases").and_then(Value::as_array).ok_or("no cases")?;
    let cases = cases
        .iter()
        .enumerate()
        .map(|(i, c)| case_row(c).map_err(|m| format!("case {i}: {m}")))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(RunRecord {
        digest: hex(&Sha256::digest(bytes)),
        commit,
        dirty,
        diff,
        started_utc: text(run, "started_utc").unwrap_or_default(),
        series: SeriesKey { data_source: data_source_kind(&data_source), machine_class },
        data_files: data_files(provenance.get("inputs")),
        repetitions: count(run, "repetitions").max(1),
        provenance: provenance.to_string(),
        cases,
    })
}

/// The point of a timeline a run of `commit` belongs to, for people: the commit's first `digits`
/// hex digits, and for a run of a dirty tree `+dirty:` and the first 6 of its diff's hash
/// (`abc1234+dirty:1a2b3c`; `+dirty` alone when the run did not record one). Runs of one commit
/// with the same change are one point; with another change, or none, another.
pub fn point_label(commit: &str, digits: usize, dirty: Option<&str>) -> String {
    let commit = &commit[..commit.len().min(digits)];
    match dirty {
        None => commit.to_string(),
        Some("") => format!("{commit}+dirty"),
        Some(diff) => format!("{commit}+dirty:{}", &diff[..diff.len().min(6)]),
    }
}

/// What data a run read, from results.json's `data_source` line ("survey data from DIR for 8
/// scenario(s), procedural look-alikes for 3"): `survey` when a survey directory was given, else
/// `procedural look-alikes`, else `mesh files`. The directory and the counts are left out: the
/// same survey elsewhere is the same data (its files' hashes say so), and a commit that adds a
/// scenario does not start another series.
pub fn data_source_kind(line: &str) -> String {
    if line.contains("survey data from") {
        "survey".to_string()
    } else if line.contains("procedural look-alikes") {
        "procedural look-alikes".to_string()
    } else if line.contains("mesh files") {
        "mesh files".to_string()
    } else {
        line.to_string()
    }
}

fn text(v: &Value, key: &str) -> Option<String> {
    v.get(key).and_then(Value::as_str).map(str::to_string)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The data inputs as (file name, SHA-256), sorted (the directory the data was read from is not
/// part of it: the same files elsewhere are the same data).
fn data_files(inputs: Option<&Value>) -> Vec<(String, String)> {
    let Some(inputs) = inputs.and_then(Value::as_array) else { return Vec::new() };
    let mut files: Vec<(String, String)> = inputs
        .iter()
        .filter_map(|i| Some((text(i, "path")?, text(i, "sha256")?)))
        .filter(|(path, _)| {
            let ext = Path::new(path).extension().and_then(|e| e.to_str()).unwrap_or("");
            !CONFIG_EXTENSIONS.contains(&ext)
        })
        .map(|(path, sha)| {
            let name = Path::new(&path).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or(path);
            (name, sha)
        })
        .collect();
    files.sort();
    files.dedup();
    files
}

/// A number of the case (`null` and absent: NaN).
fn number(case: &Value, key: &str) -> f64 {
    case.get(key).and_then(Value::as_f64).unwrap_or(f64::NAN)
}

/// The `min`/`max` of a timed phase's spread, if the run had rounds.
fn spread(case: &Value, key: &str) -> Option<(f64, f64)> {
    let s = case.get("spread")?.get(key)?;
    Some((s.get("min")?.as_f64()?, s.get("max")?.as_f64()?))
}

fn case_row(case: &Value) -> Result<CaseRow, String> {
    let scenario = text(case, "scenario").ok_or("no scenario")?;
    let method = text(case, "method").ok_or("no method")?;
    let status = text(case, "status").unwrap_or_else(|| "unknown".into());
    let edits = case.get("steps").and_then(Value::as_array).map_or(1, |s| s.len().max(1)) as f64;
    let mut values = Vec::new();
    let mut push = |measure: Measure, value: f64, range: Option<(f64, f64)>| {
        if value.is_finite() {
            let (low, high) = range.filter(|(l, h)| l.is_finite() && h.is_finite()).unwrap_or((value, value));
            values.push(MeasureValue { measure, value, low, high });
        }
    };
    let per_edit = (number(case, "bind_s") + number(case, "solve_s")) / edits;
    let per_edit_range = spread(case, "bind_s")
        .zip(spread(case, "solve_s"))
        .map(|((bl, bh), (sl, sh))| ((bl + sl) / edits, (bh + sh) / edits));
    push(Measure::TimePerEdit, per_edit, per_edit_range);
    push(Measure::Precompute, number(case, "precompute_s"), spread(case, "precompute_s"));
    push(Measure::Iterations, number(case, "iterations"), None);
    push(Measure::PeakMemory, number(case, "peak_memory_mib"), None);
    for m in Measure::all() {
        if let Measure::Quality(metric) = m {
            push(m, number(case, metric.key()), None);
        }
    }
    Ok(CaseRow { scenario, method, status, values })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_json(cases: &str) -> String {
        format!(
            r#"{{"data_source":"survey","provenance":{{"machine":{{"cpu_model":"CPU X","logical_cores":2,"memory_gib":23.4}},
            "build":{{"git_commit":"abc","git_dirty":false}},"run":{{"started_utc":"2026-12-06T00:00:00Z","threads":2,"jobs":1,"repetitions":3}},
            "inputs":[{{"path":"/a/configs/methods.toml","sha256":"11"}},{{"path":"/d/bar.off","sha256":"22"}}]}},"cases":[{cases}]}}"#
        )
    }

    #[test]
    fn a_case_gives_its_time_per_edit_with_the_spread_and_its_measures() {
        let json = run_json(
            r#"{"scenario":"bar","method":"arap","status":"ok","bind_s":1.0,"solve_s":3.0,"precompute_s":0.5,
               "iterations":40,"peak_memory_mib":12.0,"e_theta_deg":1.5,"e_phi_deg":null,"steps":[{},{}],
               "spread":{"bind_s":{"min":0.5,"max":1.5},"solve_s":{"min":2.5,"max":3.5}}}"#,
        );
        let run = parse_run(json.as_bytes()).unwrap();
        assert_eq!(run.commit, "abc");
        assert_eq!(run.repetitions, 3);
        let case = &run.cases[0];
        let per_edit = case.values.iter().find(|v| v.measure == Measure::TimePerEdit).unwrap();
        assert_eq!((per_edit.value, per_edit.low, per_edit.high), (2.0, 1.5, 2.5));
        let keys: Vec<&str> = case.values.iter().map(|v| v.measure.key()).collect();
        assert!(keys.contains(&"e_theta_deg") && !keys.contains(&"e_phi_deg"), "{keys:?}");
        assert!(run.series.machine_class.contains("CPU X") && run.series.machine_class.contains("2 thread"));
    }

    #[test]
    fn the_data_files_leave_out_the_configs_and_the_directory() {
        let a = parse_run(run_json("").as_bytes()).unwrap();
        assert_eq!(a.data_files, vec![("bar.off".to_string(), "22".to_string())]);
        let moved = run_json("").replace("/d/bar.off", "/elsewhere/bar.off").replace("\"11\"", "\"99\"");
        assert_eq!(parse_run(moved.as_bytes()).unwrap().data_files, a.data_files);
    }

    #[test]
    fn the_data_source_is_its_kind_without_directory_or_counts() {
        let a =
            data_source_kind("survey data from /a/survey for 8 scenario(s), procedural look-alikes for 3");
        assert_eq!(
            a,
            data_source_kind("survey data from /elsewhere for 9 scenario(s), procedural look-alikes for 3")
        );
        assert_eq!(a, "survey");
        assert_eq!(data_source_kind("procedural look-alikes of the survey shapes"), "procedural look-alikes");
        assert_eq!(data_source_kind("mesh files named by the scenarios"), "mesh files");
    }

    #[test]
    fn a_partial_report_or_a_foreign_file_is_refused_with_the_reason() {
        let partial = run_json("").replacen('{', r#"{"shard":"1/2","#, 1);
        assert!(parse_run(partial.as_bytes()).unwrap_err().contains("partial"));
        assert!(parse_run(b"{\"cases\":[]}").unwrap_err().contains("data_source"));
        assert!(parse_run(b"not json").unwrap_err().contains("not JSON"));
    }
}
