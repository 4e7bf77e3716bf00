//! The page's 3D view reads its meshes from small script files under `viewer/`, one per test's rest
//! mesh and one per case's result, loaded only when a case is opened: a page opened from disk may not
//! fetch files, but it may add a `<script src>`. Each file calls `deformbenchViewerData(name, data)`
//! with base64 little-endian arrays, kept small because a report holds one per case (the survey
//! run's `reports/` stays under 50 MB):
//! - `positions`: `#V x 3` u16, each coordinate quantized between the file's `lo` and `hi` corners
//!   (2^-16 of the extent: a few thousandths of a face's size on the survey meshes, far below what the view's
//!   colours resolve);
//! - `viewer/<test>.rest.js`: `positions`, `triangles` (`#F x 3`, u16 when `index_bytes` is 2,
//!   else u32), `roles` (`#V` u8: 0 free, 1 fixed, 2 handle, from the first edit step's regions);
//! - `viewer/<test>-<method>.js`: the result's `positions`, on the rest mesh's vertices.

use std::path::Path;

use crate::error::HarnessError;
use crate::record::CaseResult;
use crate::scenario::{LoadedScenario, Role};

/// Where the viewer's files go, relative to the report directory.
pub const VIEWER_DIR: &str = "viewer";

/// The `positions`, `lo` and `hi` fields of `positions` quantized to u16 per coordinate.
fn quantized(positions: &[[f64; 3]]) -> Vec<(&'static str, String)> {
    let (lo, hi) = meshes::geometry::bbox(positions);
    let bytes: Vec<u8> = positions
        .iter()
        .flat_map(|p| {
            (0..3).map(move |k| {
                let extent = hi[k] - lo[k];
                let t = if extent > 0.0 { (p[k] - lo[k]) / extent } else { 0.0 };
                (t * 65535.0).round() as u16
            })
        })
        .flat_map(u16::to_le_bytes)
        .collect();
    // serde_json writes a non-finite corner as null, never an error.
    let json = |v: [f64; 3]| serde_json::to_string(&v).expect("an array of numbers");
    vec![("positions", format!("\"{}\"", base64::encode(bytes))), ("lo", json(lo)), ("hi", json(hi))]
}

/// `deformbenchViewerData("name",{"key":value,…});` with each value already JSON.
fn script(name: &str, fields: &[(&str, String)]) -> String {
    let body = fields.iter().map(|(k, v)| format!("\"{k}\":{v}")).collect::<Vec<_>>().join(",");
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
        let short = mesh.n_vertices() <= u16::MAX as usize;
        let triangles: Vec<u8> = mesh
            .triangles()
            .iter()
            .flatten()
            .flat_map(|&i| if short { (i as u16).to_le_bytes().to_vec() } else { i.to_le_bytes().to_vec() })
            .collect();
        let rest_name = crate::stored_report::file_name(&scenario.spec.name);
        let mut fields = quantized(mesh.positions());
        fields.push(("triangles", format!("\"{}\"", base64::encode(triangles))));
        fields.push(("index_bytes", if short { "2" } else { "4" }.to_string()));
        fields.push(("roles", format!("\"{}\"", base64::encode(&roles))));
        let text = script(&format!("{rest_name}.rest"), &fields);
        write(&out.join(format!("{rest_name}.rest.js")), &text)?;
        for case in cases {
            let stem = crate::stored_report::case_file_stem(&case.scenario, &case.method);
            let positions = case.positions.as_ref().expect("filtered");
            write(&out.join(format!("{stem}.js")), &script(&stem, &quantized(positions)))?;
            written.push(stem);
        }
    }
    Ok(written)
}

fn write(path: &Path, text: &str) -> Result<(), HarnessError> {
    meshes::io::atomic_write(path, |w| w.write_all(text.as_bytes()).map_err(meshes::MeshError::from))?;
    Ok(())
}
