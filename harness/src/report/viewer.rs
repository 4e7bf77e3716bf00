//! The page's 3D view reads its meshes from small script files under `viewer/`, one per test's rest
//! mesh and one per case's result, loaded only when a case is opened: a page opened from disk may not
//! fetch files, but it may add a `<script src>`. Each file calls `deformbenchViewerData(name, data)`
//! with base64 little-endian arrays:
//! - `viewer/<test>.rest.js`: `positions` (`#V x 3` f32), `triangles` (`#F x 3` u32), `roles`
//!   (`#V` u8: 0 free, 1 fixed, 2 handle, from the first edit step's regions);
//! - `viewer/<test>-<method>.js`: `positions` of the result (`#V x 3` f32), on the rest mesh's
//!   vertices.

use std::path::Path;

use crate::case::CaseResult;
use crate::error::HarnessError;
use crate::scenario::{LoadedScenario, Role};

/// Where the viewer's files go, relative to the report directory.
pub const VIEWER_DIR: &str = "viewer";

fn f32_base64(positions: &[[f64; 3]]) -> String {
    let bytes: Vec<u8> = positions.iter().flatten().flat_map(|v| (*v as f32).to_le_bytes()).collect();
    base64::encode(bytes)
}

fn script(name: &str, fields: &[(&str, String)]) -> String {
    let body = fields.iter().map(|(k, v)| format!("\"{k}\":\"{v}\"")).collect::<Vec<_>>().join(",");
    format!("deformbenchViewerData({},{{{body}}});\n", serde_json::Value::String(name.to_string()))
}

/// Write the rest mesh of every scenario with a result and every result of `results` that
/// `writes(scenario)` allows; returns the case stems written (`<test>-<method>`).
pub fn write_viewer_data(
    dir: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
    writes: impl Fn(&LoadedScenario) -> bool,
) -> Result<Vec<String>, HarnessError> {
    let out = dir.join(VIEWER_DIR);
    std::fs::create_dir_all(&out).map_err(|error| HarnessError::Io { path: out.clone(), error })?;
    let mut written = Vec::new();
    for scenario in scenarios.iter().filter(|s| writes(s)) {
        let cases: Vec<&CaseResult> =
            results.iter().filter(|r| r.scenario == scenario.spec.name && r.positions.is_some()).collect();
        if cases.is_empty() {
            continue;
        }
        let mesh = &scenario.mesh;
        let mut roles = vec![0u8; mesh.n_vertices()];
        let step = &scenario.steps[0];
        for (region, role) in step.handles.regions().iter().zip(&step.roles) {
            for &v in &region.vertices {
                roles[v as usize] = match role {
                    Role::Fixed => 1,
                    Role::Handle => 2,
                    Role::Free => 0,
                };
            }
        }
        let triangles: Vec<u8> = mesh.triangles().iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
        let rest_name = crate::report::file_name(&scenario.spec.name);
        let text = script(
            &format!("{rest_name}.rest"),
            &[
                ("positions", f32_base64(mesh.positions())),
                ("triangles", base64::encode(triangles)),
                ("roles", base64::encode(&roles)),
            ],
        );
        write(&out.join(format!("{rest_name}.rest.js")), &text)?;
        for case in cases {
            let stem = crate::report::case_file_stem(&case.scenario, &case.method);
            let positions = case.positions.as_ref().expect("filtered");
            write(&out.join(format!("{stem}.js")), &script(&stem, &[("positions", f32_base64(positions))]))?;
            written.push(stem);
        }
    }
    Ok(written)
}

fn write(path: &Path, text: &str) -> Result<(), HarnessError> {
    meshes::io::atomic_write(path, |w| w.write_all(text.as_bytes()).map_err(meshes::MeshError::from))?;
    Ok(())
}
