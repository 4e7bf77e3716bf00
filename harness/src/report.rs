//! Writing reports: `results.csv`, `results.json` and the result meshes (OFF and GLB) of every case.
//! Everything is rendered in memory first and each file is written atomically, so a failed run leaves
//! the previous reports intact.

use std::path::Path;

use serde::Serialize;

use crate::case::CaseResult;
use crate::error::HarnessError;
use crate::scenario::LoadedScenario;

/// CSV columns, with units in the names.
pub const CSV_COLUMNS: &[&str] = &[
    "scenario",
    "method",
    "mesh_source",
    "vertices",
    "faces",
    "precompute_s",
    "bind_s",
    "median_iteration_ms",
    "iterations",
    "solve_s",
    "total_s",
    "converged",
    "e_theta_deg",
    "e_phi_deg",
    "handle_residual_over_diag",
    "rms_to_arap_over_diag",
    "status",
];

#[derive(Serialize)]
struct JsonReport<'a> {
    generator: &'static str,
    data_source: &'a str,
    units: &'static str,
    cases: &'a [CaseResult],
}

/// `results.csv` contents.
pub fn render_csv(results: &[CaseResult]) -> Result<Vec<u8>, HarnessError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| HarnessError::Report(format!("CSV: {e}"));
    w.write_record(CSV_COLUMNS).map_err(err)?;
    let num = |v: f64| if v.is_nan() { String::new() } else { format!("{v:.6e}") };
    for r in results {
        w.write_record([
            r.scenario.clone(),
            r.method.clone(),
            r.mesh_source.clone(),
            r.vertices.to_string(),
            r.faces.to_string(),
            num(r.precompute_s),
            num(r.bind_s),
            num(r.median_iteration_ms),
            r.iterations.to_string(),
            num(r.solve_s),
            num(r.total_s),
            r.converged.to_string(),
            num(r.e_theta_deg),
            num(r.e_phi_deg),
            num(r.handle_residual_over_diag),
            r.rms_to_arap_over_diag.map(num).unwrap_or_default(),
            r.status.clone(),
        ])
        .map_err(err)?;
    }
    w.into_inner().map_err(|e| HarnessError::Report(format!("CSV: {e}")))
}

/// `results.json` contents: every CSV column plus method phase timings and per-iteration traces.
pub fn render_json(results: &[CaseResult], data_source: &str) -> Result<Vec<u8>, HarnessError> {
    let report = JsonReport {
        generator: concat!("deformbench harness ", env!("CARGO_PKG_VERSION")),
        data_source,
        units: "times in seconds (median_iteration_ms in milliseconds); angles in degrees; *_over_diag relative to the rest bounding-box diagonal",
        cases: results,
    };
    // NaN is not JSON: serde_json writes it as null, which is what a missing value should be.
    serde_json::to_vec_pretty(&report).map_err(|e| HarnessError::Report(format!("JSON: {e}")))
}

/// Write `results.csv`, `results.json` and `meshes/<scenario>-<method>.{off,glb}` under `dir`.
pub fn write_reports(
    dir: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
    data_source: &str,
) -> Result<(), HarnessError> {
    let csv = render_csv(results)?;
    let json = render_json(results, data_source)?;
    let mesh_dir = dir.join("meshes");
    std::fs::create_dir_all(&mesh_dir).map_err(|error| HarnessError::Io { path: mesh_dir.clone(), error })?;
    for r in results {
        let (Some(positions), Some(scenario)) =
            (&r.positions, scenarios.iter().find(|s| s.spec.name == r.scenario))
        else {
            continue;
        };
        let mesh = scenario.mesh.with_positions(positions.clone())?;
        let stem = format!("{}-{}", r.scenario, r.method);
        meshes::io::write_off(mesh_dir.join(format!("{stem}.off")), &mesh)?;
        meshes::io::write_glb(mesh_dir.join(format!("{stem}.glb")), &mesh, None)?;
    }
    write_bytes(&dir.join("results.json"), &json)?;
    write_bytes(&dir.join("results.csv"), &csv)?;
    Ok(())
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), HarnessError> {
    meshes::io::atomic_write(path, |w| w.write_all(bytes).map_err(meshes::MeshError::from))
        .map_err(HarnessError::from)
}
