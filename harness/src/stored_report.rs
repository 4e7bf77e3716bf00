//! A run's record on disk: `results.json` written and read back (a whole run or a part of one), and
//! the file stems of a case's files. The reports, `merge`, `compare` and the gate all read runs here.

use std::path::Path;

use serde::Serialize;

use crate::error::HarnessError;
use crate::provenance::Provenance;
use crate::record::CaseResult;
use crate::scenario::SkippedInput;
use crate::shard::Shard;

/// `name` with every character other than ASCII letters, digits, `-`, `_` and `.` replaced by `_`,
/// so it is one file name on every system.
pub fn file_name(name: &str) -> String {
    let cleaned: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() || "-_.".contains(c) { c } else { '_' }).collect();
    if cleaned.is_empty() || cleaned.chars().all(|c| c == '.') {
        format!("_{cleaned}")
    } else {
        cleaned
    }
}

/// The file stem of a case's files (`meshes/`, stderr logs): `<scenario>-<method>`, [`file_name`]d,
/// so a sweep point's `isolines[isolines=10]` becomes `isolines_isolines_10_`.
pub fn case_file_stem(scenario: &str, method: &str) -> String {
    format!("{}-{}", file_name(scenario), file_name(method))
}

#[derive(Serialize)]
struct JsonReport<'a> {
    generator: &'static str,
    data_source: &'a str,
    /// `K/N` in a partial report of `all --shard K/N`.
    #[serde(skip_serializing_if = "Option::is_none")]
    shard: Option<String>,
    units: &'static str,
    provenance: &'a Provenance,
    cases: &'a [CaseResult],
    /// Meshes of collections no case ran on, with the reason.
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    skipped: &'a [SkippedInput],
}

/// `results.json` contents: every CSV column plus method phase timings and per-iteration traces
/// (and the part, for a partial report).
pub fn render_json(
    results: &[CaseResult],
    data_source: &str,
    provenance: &Provenance,
    skipped: &[SkippedInput],
    shard: Option<Shard>,
) -> Result<Vec<u8>, HarnessError> {
    let report = JsonReport {
        generator: concat!("deformbench harness ", env!("CARGO_PKG_VERSION")),
        data_source,
        shard: shard.map(|s| s.to_string()),
        units: "times in seconds (median_iteration_ms in milliseconds); angles in degrees; *_over_diag relative to the rest bounding-box diagonal; e_area, e_length RMS log ratios; volume_change and folds fractions",
        provenance,
        cases: results,
        skipped,
    };
    // NaN is not JSON: serde_json writes it as null, which is what a missing value should be.
    serde_json::to_vec_pretty(&report).map_err(|e| HarnessError::Report(format!("JSON: {e}")))
}

/// A `results.json` read back.
pub struct StoredReport {
    pub cases: Vec<CaseResult>,
    pub data_source: String,
    /// The part, for a partial report.
    pub shard: Option<Shard>,
    /// Where and how it was made (none in a report of an older harness).
    pub provenance: Option<Provenance>,
    /// Meshes of collections no case ran on.
    pub skipped: Vec<SkippedInput>,
}

/// Read a `results.json` written by a run (or a shard of one).
pub fn read_results(path: &Path) -> Result<StoredReport, HarnessError> {
    #[derive(serde::Deserialize)]
    struct Stored {
        data_source: String,
        #[serde(default)]
        shard: Option<String>,
        #[serde(default)]
        provenance: Option<Provenance>,
        cases: Vec<CaseResult>,
        #[serde(default)]
        skipped: Vec<SkippedInput>,
    }
    let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
    let text = std::fs::read(path).map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
    let stored: Stored = serde_json::from_slice(&text)
        .map_err(|e| config(format!("not a results.json of this harness: {e}")))?;
    let shard =
        stored.shard.map(|s| s.parse::<Shard>()).transpose().map_err(|e| config(format!("shard: {e}")))?;
    Ok(StoredReport {
        cases: stored.cases,
        data_source: stored.data_source,
        shard,
        provenance: stored.provenance,
        skipped: stored.skipped,
    })
}
