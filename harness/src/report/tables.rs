//! Writing reports: `results.csv`, `results.json` (rendered by [`crate::stored_report`]),
//! `convergence.csv`, the handle-update tables and the result meshes (OFF and GLB) of every case.
//! Each file is rendered in memory first and written atomically; the whole directory is swapped in
//! at the end of a run ([`crate::staged_dir`]), so a failed run leaves the previous reports intact.

use std::path::Path;

use super::document::{Document, Table, Text};
use crate::error::HarnessError;
use crate::metrics::METRICS;
use crate::provenance::Provenance;
use crate::record::CaseResult;
use crate::scenario::{LoadedScenario, SkippedInput};
use crate::shard::Shard;
use methods::registry::Table1Side;

/// The CSV columns before the metrics, with units in the names.
const CASE_COLUMNS: &[&str] = &[
    "scenario",
    "method",
    "origin",
    "mesh_source",
    "vertices",
    "faces",
    "laplacian_weights",
    "startup_s",
    "precompute_s",
    "bind_s",
    "median_iteration_ms",
    "iterations",
    "solve_s",
    "total_s",
    "converged",
    "fixed_point_distance",
    "repetitions",
    "precompute_s_min",
    "precompute_s_max",
    "bind_s_min",
    "bind_s_max",
    "solve_s_min",
    "solve_s_max",
    "total_s_min",
    "total_s_max",
    "median_iteration_ms_min",
    "median_iteration_ms_max",
    "startup_s_min",
    "startup_s_max",
    "peak_memory_mib",
    "reused_solve_s",
];

/// The CSV columns after the metrics.
const VERDICT_COLUMNS: &[&str] =
    &["largest_move_over_diag", "largest_handle_move_over_diag", "self_intersecting", "status"];

/// Every column of `results.csv`: the case, every metric of [`METRICS`] by key, the verdict.
pub fn csv_columns() -> Vec<&'static str> {
    CASE_COLUMNS
        .iter()
        .copied()
        .chain(METRICS.iter().map(|s| s.key))
        .chain(VERDICT_COLUMNS.iter().copied())
        .collect()
}

/// A CSV number: empty for NaN (a missing value), else 7 significant digits.
fn num(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        format!("{v:.6e}")
    }
}

/// `results.csv` contents.
pub fn render_csv(results: &[CaseResult]) -> Result<Vec<u8>, HarnessError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| HarnessError::Report(format!("CSV: {e}"));
    w.write_record(csv_columns()).map_err(err)?;
    for r in results {
        let mut row = vec![
            r.scenario.clone(),
            r.method.clone(),
            r.origin.label().to_string(),
            r.mesh_source.clone(),
            r.vertices.to_string(),
            r.faces.to_string(),
            r.laplacian_weights.clone(),
            num(r.startup_s),
            num(r.precompute_s),
            num(r.bind_s),
            num(r.median_iteration_ms),
            r.iterations.to_string(),
            num(r.solve_s),
            num(r.total_s),
            if r.convergence_unknown { "unknown".to_string() } else { r.converged.to_string() },
            num(r.fixed_point_distance),
        ];
        let spread = r.spread.unwrap_or_default();
        row.push(spread.repetitions.to_string());
        for s in [
            spread.precompute_s,
            spread.bind_s,
            spread.solve_s,
            spread.total_s,
            spread.median_iteration_ms,
            spread.startup_s,
        ] {
            let (min, max) = if r.spread.is_some() { (s.min, s.max) } else { (f64::NAN, f64::NAN) };
            row.extend([num(min), num(max)]);
        }
        row.push(num(r.peak_memory_mib));
        row.push(r.reused_solve.as_ref().map(|reused| num(reused.seconds)).unwrap_or_default());
        row.extend(METRICS.iter().map(|s| r.quality.get(s.metric).map(num).unwrap_or_default()));
        row.extend([
            num(r.largest_move_over_diag),
            num(r.largest_handle_move_over_diag),
            r.self_intersecting.map(|b| b.to_string()).unwrap_or_default(),
            r.status.to_string(),
        ]);
        w.write_record(row).map_err(err)?;
    }
    w.into_inner().map_err(|e| HarnessError::Report(format!("CSV: {e}")))
}

/// Columns of `handle_updates.csv`: one row per (scenario, method, edit step).
pub const HANDLE_UPDATE_COLUMNS: &[&str] = &[
    "scenario",
    "method",
    "step",
    "handles",
    "constrained_vertices",
    "bind_ms",
    "t_h_ms",
    "background_wait_ms",
    "t_b_ms",
    "t_e_ms",
    "median_iteration_ms",
    "iterations",
];

fn phase(record: &[(String, f64)], name: &str) -> Option<f64> {
    record.iter().find(|(k, _)| k == name).map(|(_, v)| *v)
}

/// `handle_updates.csv` contents: the handle-set update time of every step of every case, with
/// HIRM's phases (Wu et al. 2015, Table 1: `t_e`, `t_b`, `t_h`; `t_i` is the median iteration).
pub fn render_handle_updates(results: &[CaseResult]) -> Result<Vec<u8>, HarnessError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| HarnessError::Report(format!("CSV: {e}"));
    w.write_record(HANDLE_UPDATE_COLUMNS).map_err(err)?;
    let ms =
        |v: Option<f64>| v.filter(|v| !v.is_nan()).map(|v| format!("{:.4}", 1e3 * v)).unwrap_or_default();
    for r in results {
        for s in &r.steps {
            w.write_record([
                r.scenario.clone(),
                r.method.clone(),
                s.step.to_string(),
                s.handles.to_string(),
                s.constrained_vertices.to_string(),
                ms(Some(s.bind_s)),
                ms(phase(&s.phase_timings, methods::keys::phase::T_H_HANDLE_UPDATE)),
                ms(phase(&s.phase_timings, methods::keys::phase::BIND_BACKGROUND_WAIT)),
                ms(phase(&s.phase_timings, methods::keys::phase::T_B_BACKGROUND_PRECOMPUTE)),
                ms(phase(&s.phase_timings, methods::keys::phase::T_E_PROPAGATION_FIELDS)),
                ms(Some(s.median_iteration_ms / 1e3)),
                s.iterations.to_string(),
            ])
            .map_err(err)?;
        }
    }
    w.into_inner().map_err(|e| HarnessError::Report(format!("CSV: {e}")))
}

/// The two sides of HIRM's Table 1 ([`methods::registry::Table1Side`]): the handle-independent
/// model and the one rebuilt per handle set (`hirm` and `isolines`).
fn table1_methods() -> (&'static str, &'static str) {
    let name = |side| methods::registry::table1_method(side).map_or("-", |m| m.name);
    (name(Table1Side::HandleIndependent), name(Table1Side::Rebuilt))
}

/// HIRM's Table 1 for every scenario that runs both of its sides: per step the number of handles,
/// the handle-independent model's update `t_h` against the rebuild of the other (its whole
/// `bind_handles`), their ratio `P`, and both per-iteration times. No rows: no scenario ran both.
pub fn table1(results: &[CaseResult]) -> Table {
    let (hirm, isolines) = table1_methods();
    let mut titles: Vec<String> = [
        "scenario",
        "step",
        "n_h",
        "n_field",
        "n_t",
        "t_e (s)",
        "t_b (s)",
        "t_h (ms)",
        "rebuild (ms)",
        "P (%)",
    ]
    .map(String::from)
    .to_vec();
    titles.extend([format!("t_i {hirm} (ms)"), format!("t_i {isolines} (ms)")]);
    let mut table = Table::new(titles).captioned(format!(
        "t_h: {hirm}'s handle update (eq 26 and the factorization); rebuild: the whole bind of {isolines} \
         (harmonic fields, isolines, reduced system). P = t_h / rebuild. t_i: median iteration."
    ));
    let side = |r: &CaseResult| methods::registry::table1_side(&r.method);
    let index = crate::record::CaseIndex::new(results);
    for hirm in results.iter().filter(|r| side(r) == Some(Table1Side::HandleIndependent)) {
        let Some(isolines) = index.of_scenario(&hirm.scenario).find(|r| side(r) == Some(Table1Side::Rebuilt))
        else {
            continue;
        };
        for (h, i) in hirm.steps.iter().zip(&isolines.steps) {
            table.push_row(table1_row(hirm, h, i));
        }
    }
    table
}

/// One step of Table 1: `hirm`'s step `h` against the rebuild's step `i`.
fn table1_row(
    hirm: &CaseResult,
    h: &crate::record::StepRecord,
    i: &crate::record::StepRecord,
) -> Vec<String> {
    use methods::keys::{phase as key, statistic};
    let stat = |name: &str| phase(&hirm.statistics, name).map_or("-".to_string(), |v| format!("{v}"));
    let timing = |name: &str| phase(&h.phase_timings, name).unwrap_or(f64::NAN);
    let t_h = timing(key::T_H_HANDLE_UPDATE);
    vec![
        hirm.scenario.clone(),
        h.step.to_string(),
        h.handles.to_string(),
        stat(statistic::N_FIELD),
        stat(statistic::N_T),
        format!("{:.3}", timing(key::T_E_PROPAGATION_FIELDS)),
        format!("{:.3}", timing(key::T_B_BACKGROUND_PRECOMPUTE)),
        format!("{:.2}", 1e3 * t_h),
        format!("{:.2}", 1e3 * i.bind_s),
        format!("{:.1}", 100.0 * t_h / i.bind_s),
        format!("{:.3}", h.median_iteration_ms),
        format!("{:.3}", i.median_iteration_ms),
    ]
}

/// `table1.md`: [`table1`] under its title.
pub fn table1_document(table: &Table) -> Document {
    let (hirm, isolines) = table1_methods();
    let mut document = Document::default();
    document.heading(
        1,
        Text::plain("Handle-set update: ")
            .then_code(hirm)
            .then(" against the ")
            .then_code(isolines)
            .then(" rebuild (Wu et al. 2015, Table 1)"),
    );
    document.table(table.clone());
    document
}

/// `convergence.csv` contents: one row per iteration of every case (the scale-aware paper's Fig. 6
/// curves), with the angle errors where the harness evaluated them (see
/// [`crate::record::records_quality`]; empty otherwise).
pub fn render_convergence(results: &[CaseResult]) -> Result<Vec<u8>, HarnessError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| HarnessError::Report(format!("CSV: {e}"));
    w.write_record([
        "scenario",
        "method",
        "edit_step",
        "iteration",
        "step",
        "seconds",
        "e_theta_deg",
        "e_phi_deg",
    ])
    .map_err(err)?;
    let opt = |v: Option<f64>| v.map(num).unwrap_or_default();
    for r in results {
        for t in &r.trace {
            w.write_record([
                r.scenario.clone(),
                r.method.clone(),
                t.edit_step.to_string(),
                t.iteration.to_string(),
                num(t.step),
                num(t.seconds),
                opt(t.e_theta_deg),
                opt(t.e_phi_deg),
            ])
            .map_err(err)?;
        }
    }
    w.into_inner().map_err(|e| HarnessError::Report(format!("CSV: {e}")))
}

/// The file format of the result meshes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum MeshFormat {
    /// Binary glTF (`.glb`, f32 positions): small, opens in any viewer.
    #[default]
    Glb,
    /// OFF (`.off`, shortest round-trip decimals): exact, what the survey tools and libigl read.
    Off,
    /// Both.
    Both,
}

impl MeshFormat {
    fn writes_glb(self) -> bool {
        matches!(self, MeshFormat::Glb | MeshFormat::Both)
    }
    fn writes_off(self) -> bool {
        matches!(self, MeshFormat::Off | MeshFormat::Both)
    }
}

/// Which result meshes a report writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshOutput {
    pub format: MeshFormat,
    /// Also the scenarios with `result_meshes = false` (the resolution sweeps: 200K-vertex bars
    /// nobody opens, most of the bytes of a report).
    pub every_scenario: bool,
}

/// Write `results.csv`, `results.json`, `convergence.csv`, `handle_updates.csv`, `table1.md`,
/// `peers.md` (`peers`: our ARAP against libigl's, [`super::peer_comparison::document`]; none when
/// empty) and
/// the result meshes `meshes/<scenario>-<method>.{glb,off}` that `meshes` asks for under `dir`.
pub fn write_reports(
    dir: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
    data_source: &str,
    provenance: &Provenance,
    skipped: &[SkippedInput],
    peers: &Document,
    meshes: &MeshOutput,
) -> Result<(), HarnessError> {
    let csv = render_csv(results)?;
    let json = crate::stored_report::render_json(results, data_source, provenance, skipped, None)?;
    write_meshes(dir, results, scenarios, meshes)?;
    write_bytes(&dir.join("convergence.csv"), &render_convergence(results)?)?;
    write_bytes(&dir.join("handle_updates.csv"), &render_handle_updates(results)?)?;
    table1_document(&table1(results)).write_markdown(&dir.join("table1.md"))?;
    if !peers.is_empty() {
        peers.write_markdown(&dir.join("peers.md"))?;
    }
    write_bytes(&dir.join("results.json"), &json)?;
    write_bytes(&dir.join("results.csv"), &csv)?;
    Ok(())
}

/// `results.json` with `shard` and every result mesh as OFF under `dir`: what `merge` needs of one
/// part (OFF because merge measures the shapes again, and GLB's f32 positions would move them).
pub fn write_partial(
    dir: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
    data_source: &str,
    provenance: &Provenance,
    skipped: &[SkippedInput],
    shard: Shard,
) -> Result<(), HarnessError> {
    let json = crate::stored_report::render_json(results, data_source, provenance, skipped, Some(shard))?;
    let every_mesh = MeshOutput { format: MeshFormat::Off, every_scenario: true };
    write_meshes(dir, results, scenarios, &every_mesh)?;
    write_bytes(&dir.join("results.json"), &json)
}

/// `meshes/<scenario>-<method>.{glb,off}` of every case with a result that `output` covers, in the
/// input's vertex order.
fn write_meshes(
    dir: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
    output: &MeshOutput,
) -> Result<(), HarnessError> {
    let mesh_dir = dir.join("meshes");
    std::fs::create_dir_all(&mesh_dir).map_err(|error| HarnessError::Io { path: mesh_dir.clone(), error })?;
    for r in results {
        let (Some(positions), Some(scenario)) =
            (&r.positions, scenarios.iter().find(|s| s.spec.name == r.scenario))
        else {
            continue;
        };
        if !(output.every_scenario || scenario.writes_result_meshes()) {
            continue;
        }
        // In the input file's vertex order, so per-vertex data of the input still applies.
        let mesh = scenario.in_input_order(positions)?;
        let stem = crate::stored_report::case_file_stem(&r.scenario, &r.method);
        if output.format.writes_off() {
            meshes::io::write_off(mesh_dir.join(format!("{stem}.off")), &mesh)?;
        }
        if output.format.writes_glb() {
            meshes::io::write_glb(mesh_dir.join(format!("{stem}.glb")), &mesh, None)?;
        }
    }
    Ok(())
}

/// Write `compare.md` and `compare.html` of `comparison` under `dir`.
pub fn write_comparison(dir: &Path, comparison: &crate::comparison::Comparison) -> Result<(), HarnessError> {
    std::fs::create_dir_all(dir).map_err(|error| HarnessError::Io { path: dir.to_path_buf(), error })?;
    write_bytes(&dir.join("compare.md"), super::run_comparison::render_markdown(comparison).as_bytes())?;
    write_bytes(&dir.join("compare.html"), super::run_comparison::render_html(comparison).as_bytes())
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), HarnessError> {
    meshes::io::atomic_write(path, |w| w.write_all(bytes).map_err(meshes::MeshError::from))
        .map_err(HarnessError::from)
}
