//! The quality-regression gate: the committed `reports/baseline.json` holds `E_theta` and `E_phi` of
//! every (scenario, method) of a survey run; [`check`] compares a run against it and names every
//! metric that got worse beyond the tolerance, every case that failed or produced a non-finite
//! metric, and every baseline case the run lacks. Improvements pass (and are listed, so the
//! baseline can be renewed on purpose with `harness baseline`).

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::case::CaseResult;
use crate::error::HarnessError;

/// A metric is worse when it exceeds the baseline by more than both bounds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerance {
    /// Relative to the baseline value (0.02: 2%).
    pub relative: f64,
    /// In degrees.
    pub absolute_deg: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Self { relative: 0.02, absolute_deg: 0.01 }
    }
}

/// One (scenario, method) of the baseline; angles in degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BaselineCase {
    pub scenario: String,
    pub method: String,
    /// `survey` or `procedural look-alike` (the `mesh_source` column): a run of the same case on
    /// other data is not compared.
    pub mesh_source: String,
    pub e_theta_deg: f64,
    pub e_phi_deg: f64,
}

/// Contents of `reports/baseline.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    pub tolerance: Tolerance,
    pub cases: Vec<BaselineCase>,
}

/// The metrics the gate compares.
pub const METRICS: [&str; 2] = ["e_theta_deg", "e_phi_deg"];

fn metric(case: &CaseResult, name: &str) -> f64 {
    match name {
        "e_theta_deg" => case.e_theta_deg,
        _ => case.e_phi_deg,
    }
}

fn baseline_metric(case: &BaselineCase, name: &str) -> f64 {
    match name {
        "e_theta_deg" => case.e_theta_deg,
        _ => case.e_phi_deg,
    }
}

/// What the gate found about one case.
#[derive(Clone, Debug, PartialEq)]
pub enum Finding {
    /// Worse than the baseline beyond the tolerance.
    Worse { scenario: String, method: String, metric: &'static str, baseline: f64, current: f64 },
    /// The case did not run to a result.
    Failed { scenario: String, method: String, status: String },
    /// The case ran but a metric is NaN or infinite.
    NonFinite { scenario: String, method: String, metric: &'static str },
    /// In the baseline, absent from the run.
    Missing { scenario: String, method: String },
    /// Better than the baseline beyond the tolerance (not a failure).
    Better { scenario: String, method: String, metric: &'static str, baseline: f64, current: f64 },
}

impl Finding {
    /// Whether this finding fails the gate.
    pub fn is_regression(&self) -> bool {
        !matches!(self, Finding::Better { .. })
    }
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Finding::Worse { scenario, method, metric, baseline, current } => write!(
                f,
                "worse: {scenario} / {method} / {metric}: {current:.4} against baseline {baseline:.4} (+{:.1}%)",
                100.0 * (current - baseline) / baseline.abs().max(f64::MIN_POSITIVE)
            ),
            Finding::Failed { scenario, method, status } => write!(f, "failed: {scenario} / {method}: {status}"),
            Finding::NonFinite { scenario, method, metric } => {
                write!(f, "non-finite: {scenario} / {method} / {metric}")
            }
            Finding::Missing { scenario, method } => write!(f, "missing: {scenario} / {method} (in the baseline, not in the run)"),
            Finding::Better { scenario, method, metric, baseline, current } => {
                write!(f, "better: {scenario} / {method} / {metric}: {current:.4} against baseline {baseline:.4}")
            }
        }
    }
}

/// A baseline from the cases of a run that have a result (failed cases are left out).
pub fn baseline_from(results: &[CaseResult]) -> Baseline {
    Baseline {
        tolerance: Tolerance::default(),
        cases: results
            .iter()
            .filter(|r| r.status == "ok" && r.e_theta_deg.is_finite() && r.e_phi_deg.is_finite())
            .map(|r| BaselineCase {
                scenario: r.scenario.clone(),
                method: r.method.clone(),
                mesh_source: r.mesh_source.clone(),
                e_theta_deg: r.e_theta_deg,
                e_phi_deg: r.e_phi_deg,
            })
            .collect(),
    }
}

/// The cases of `results` measured on other data than the same case of `baseline` (by
/// `mesh_source`), as `scenario / method (run's source, baseline's source)`; a comparison across
/// data sources means nothing.
pub fn foreign_cases(baseline: &Baseline, results: &[CaseResult]) -> Vec<String> {
    results
        .iter()
        .filter_map(|r| {
            let b = baseline.cases.iter().find(|b| b.scenario == r.scenario && b.method == r.method)?;
            (b.mesh_source != r.mesh_source).then(|| {
                format!("{} / {} ({}, baseline: {})", r.scenario, r.method, r.mesh_source, b.mesh_source)
            })
        })
        .collect()
}

/// Compare `results` with `baseline`: every failed or non-finite case of the run, every baseline
/// case the run lacks, every metric worse (or better) beyond the tolerance. In run order, then
/// baseline order for the missing ones.
pub fn check(baseline: &Baseline, results: &[CaseResult]) -> Vec<Finding> {
    let mut findings = Vec::new();
    for r in results {
        let (scenario, method) = (r.scenario.clone(), r.method.clone());
        if r.status != "ok" {
            findings.push(Finding::Failed { scenario, method, status: r.status.clone() });
            continue;
        }
        let reference = baseline.cases.iter().find(|b| b.scenario == r.scenario && b.method == r.method);
        for name in METRICS {
            let current = metric(r, name);
            if !current.is_finite() {
                findings.push(Finding::NonFinite {
                    scenario: scenario.clone(),
                    method: method.clone(),
                    metric: name,
                });
                continue;
            }
            let Some(reference) = reference else { continue };
            let base = baseline_metric(reference, name);
            let allowed = (baseline.tolerance.relative * base.abs()).max(baseline.tolerance.absolute_deg);
            let (scenario, method) = (scenario.clone(), method.clone());
            if current - base > allowed {
                findings.push(Finding::Worse { scenario, method, metric: name, baseline: base, current });
            } else if base - current > allowed {
                findings.push(Finding::Better { scenario, method, metric: name, baseline: base, current });
            }
        }
    }
    for b in &baseline.cases {
        if !results.iter().any(|r| r.scenario == b.scenario && r.method == b.method) {
            findings.push(Finding::Missing { scenario: b.scenario.clone(), method: b.method.clone() });
        }
    }
    findings
}

/// Read a baseline file.
pub fn read_baseline(path: &Path) -> Result<Baseline, HarnessError> {
    let text = std::fs::read(path).map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
    serde_json::from_slice(&text).map_err(|e| HarnessError::Config {
        path: path.to_path_buf(),
        message: format!("not a baseline: {e}"),
    })
}

/// Write a baseline file atomically.
pub fn write_baseline(path: &Path, baseline: &Baseline) -> Result<(), HarnessError> {
    let bytes =
        serde_json::to_vec_pretty(baseline).map_err(|e| HarnessError::Report(format!("JSON: {e}")))?;
    meshes::io::atomic_write(path, |w| w.write_all(&bytes).map_err(meshes::MeshError::from))?;
    Ok(())
}

/// The cases and data source of a `results.json` written by a run.
pub fn read_results(path: &Path) -> Result<(Vec<CaseResult>, String), HarnessError> {
    #[derive(Deserialize)]
    struct Stored {
        data_source: String,
        cases: Vec<CaseResult>,
    }
    let text = std::fs::read(path).map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
    let stored: Stored = serde_json::from_slice(&text).map_err(|e| HarnessError::Config {
        path: path.to_path_buf(),
        message: format!("not a results.json of this harness: {e}"),
    })?;
    Ok((stored.cases, stored.data_source))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(scenario: &str, method: &str, e_theta: f64, e_phi: f64, status: &str) -> CaseResult {
        let json = serde_json::json!({
            "scenario": scenario, "method": method, "mesh_source": "survey", "vertices": 10, "faces": 16,
            "precompute_s": 0.0, "bind_s": 0.0, "median_iteration_ms": 0.0, "iterations": 1, "solve_s": 0.0,
            "total_s": 0.0, "converged": true, "e_theta_deg": e_theta, "e_phi_deg": e_phi,
            "handle_residual_over_diag": 0.0, "rms_to_arap_over_diag": null, "status": status,
            "phase_timings": [], "statistics": [], "steps": [], "trace": []
        });
        serde_json::from_value(json).unwrap()
    }

    fn baseline() -> Baseline {
        baseline_from(&[
            case("bar", "arap", 2.0, 5.0, "ok"),
            case("bar", "laplacian", 7.0, 2.0, "ok"),
            case("cactus", "arap", 0.1, 0.2, "ok"),
        ])
    }

    #[test]
    fn identical_results_pass() {
        let run = [
            case("bar", "arap", 2.0, 5.0, "ok"),
            case("bar", "laplacian", 7.0, 2.0, "ok"),
            case("cactus", "arap", 0.1, 0.2, "ok"),
        ];
        assert!(check(&baseline(), &run).is_empty());
    }

    #[test]
    fn worse_beyond_both_bounds_is_named() {
        // bar/arap E_theta +3% (beyond 2% and 0.01 deg); bar/laplacian E_phi +1.5% (within 2%);
        // cactus/arap E_theta +0.009 deg (9% but within the absolute 0.01 deg).
        let run = [
            case("bar", "arap", 2.06, 5.0, "ok"),
            case("bar", "laplacian", 7.0, 2.03, "ok"),
            case("cactus", "arap", 0.109, 0.2, "ok"),
        ];
        let findings = check(&baseline(), &run);
        assert_eq!(findings.len(), 1, "{findings:?}");
        assert!(findings[0].is_regression());
        let text = findings[0].to_string();
        assert!(text.contains("bar / arap / e_theta_deg"), "{text}");
    }

    #[test]
    fn failures_non_finite_and_missing_cases_are_regressions() {
        let run = [
            case("bar", "arap", 2.0, f64::NAN, "ok"),
            case("bar", "laplacian", f64::NAN, f64::NAN, "failed: solver"),
        ];
        let findings = check(&baseline(), &run);
        let texts: Vec<String> = findings.iter().map(|f| f.to_string()).collect();
        assert!(findings.iter().all(Finding::is_regression), "{texts:?}");
        assert!(texts.iter().any(|t| t.starts_with("non-finite: bar / arap / e_phi_deg")), "{texts:?}");
        assert!(texts.iter().any(|t| t.starts_with("failed: bar / laplacian: failed: solver")), "{texts:?}");
        assert!(texts.iter().any(|t| t.starts_with("missing: cactus / arap")), "{texts:?}");
    }

    #[test]
    fn improvements_pass_but_are_listed() {
        let run = [
            case("bar", "arap", 1.0, 5.0, "ok"),
            case("bar", "laplacian", 7.0, 2.0, "ok"),
            case("cactus", "arap", 0.1, 0.2, "ok"),
        ];
        let findings = check(&baseline(), &run);
        assert_eq!(findings.len(), 1);
        assert!(!findings[0].is_regression());
    }

    #[test]
    fn baseline_round_trips_through_json() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("baseline.json");
        write_baseline(&path, &baseline()).unwrap();
        assert_eq!(read_baseline(&path).unwrap(), baseline());
        std::fs::write(&path, "{ not json").unwrap();
        let err = read_baseline(&path).unwrap_err().to_string();
        assert!(err.contains("baseline.json") && err.contains("not a baseline"), "{err}");
    }
}
